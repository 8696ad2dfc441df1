"""C firmware on the bench: the C driver (``supi3.c``) and a firmware's C sources, built with cffi and run against
the model (guide: docs/sdk-firmware-c.md).

Ref: IBS SUPI 3 OPC UM E rev. 05, 3.4 (µP interface), 3.4.14 (synchronization), 3.6.2 (/StatErr, /ModAck).

:func:`build` compiles the driver and the firmware with the project's strict flags (:data:`STRICT_FLAGS`) into
object files, then links them into a cffi extension module (API mode, ``ffi.set_source`` + ``ffi.compile``) kept
in a cache folder under a hash of the sources, headers, flags and compiler. API mode rather than ABI mode
(``ffi.dlopen``) because the C compiler then checks our declarations of ``supi3_config_t`` and the entry points
against the real headers (a header change fails the build instead of corrupting memory), and because its
``extern "Python"`` callbacks need no run-time generated trampolines (faster, and allowed where writable
executable memory is not). It needs the Python headers, which a C toolchain for Python has.

:class:`CFirmware` is a :class:`supi3.sdk.bench.Firmware` whose ``setup``, ``isr`` and ``loop`` call the C entry
points ``fw_setup``, ``fw_isr`` and ``fw_loop`` (the board contract of ``examples/fw_board.h``). The C driver's
transport callbacks call the bench transport, so every byte the C firmware clocks advances bus time exactly as the
Python driver's would; ``/StatErr``, ``/ModAck`` and the peripheral's data are the board's (``fw_board_t``).

An exception raised in a callback (a strict model's ``InconsistentDataError``, ``ReconfigurationError``, ...) is
caught there, the callback returns an error to C, and every later callback fails at once without touching the
bus; when the C entry point returns, that exception is raised again (same object) with a note naming the entry
point and the access in flight: ``in fw_isr(): command 4Dh (write SET), data byte (sent 85h)``.
"""

from __future__ import annotations

import atexit
import contextlib
import hashlib
import importlib.util
import io
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import tempfile
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from types import ModuleType
from typing import Any, Final

from supi3 import sdk
from supi3.checks import check_int
from supi3.errors import ArgumentError, Supi3Error
from supi3.regmap import REGISTER_MAP, AccessDirection, CommandByte, RegisterMapError, decode_command, encode_command
from supi3.sdk.bench import BenchTransport, Firmware
from supi3.sdk.driver import Supi3Driver, Transport
from supi3.sdk.transports import ModelTransport
from supi3.spi.upif import Phase

__all__ = [
    "EXAMPLES_DIR",
    "STRICT_FLAGS",
    "CFirmware",
    "CFirmwareError",
    "CompilerNotFoundError",
    "NativeBuildError",
    "NativeLibrary",
    "build",
    "default_cache_dir",
    "describe_command",
    "example",
    "find_compiler",
    "toolchain_missing",
]

EXAMPLES_DIR: Final[Path] = sdk.SDK_DIR / "examples"
"""The example firmware (``*.c``) and the board contract ``fw_board.h``."""
STRICT_FLAGS: Final[tuple[str, ...]] = (*sdk.CFLAGS, "-Werror")
"""Flags the driver and the firmware are compiled with: C99, all warnings, pedantic, warnings are errors."""
CACHE_ENV: Final[str] = "SUPI3_NATIVE_CACHE"
"""Environment variable naming the build cache folder (default ``$XDG_CACHE_HOME/supi3/native``)."""
CALLBACK_FAILED: Final[int] = -1
"""What a callback returns to C after it caught an exception (the C driver reports ``SUPI3_E_TRANSPORT``)."""
NOT_WIRED: Final[int] = -6
"""What a board callback returns when the transport has no such pin (``SUPI3_E_UNSUPPORTED``): the C driver then
works as with a NULL callback, its state kept (FW-21; a transport's ``set_sas_init`` returning ``False``, a pin read
returning ``None``)."""

_CDEF: Final[str] = """
typedef int (*supi3_xfer_fn)(void *user, uint8_t tx, uint8_t *rx, int s_r);
typedef void (*supi3_delay_us_fn)(void *user, uint32_t us);
typedef int (*supi3_read_pin_fn)(void *user, int *level);
typedef int (*supi3_write_pin_fn)(void *user, int level);
typedef struct {
    supi3_xfer_fn xfer;
    supi3_delay_us_fn delay_us;
    supi3_read_pin_fn read_irq;
    supi3_read_pin_fn read_cd;
    supi3_write_pin_fn set_sas_init;
    void *user;
    uint32_t frame_gap_us;
    supi3_read_pin_fn read_io;
} supi3_config_t;
typedef struct { ...; } supi3_t;
int supi3_init(supi3_t *ctx, const supi3_config_t *cfg);
int supi3_read(supi3_t *ctx, uint8_t addr, uint8_t *value);
int supi3_write(supi3_t *ctx, uint8_t addr, uint8_t value);
const char *supi3_strerror(int err);

typedef struct fw_board {
    uint8_t inputs[4];
    uint8_t outputs[4];
    uint8_t fault;
    uint8_t command;
    uint32_t cycles;
    int error;
    void *user;
    void (*delay_us)(void *user, uint32_t us);
    int (*set_stat_err)(void *user, int active);
    int (*mod_ack_seen)(void *user, int *seen);
} fw_board_t;
void fw_setup(supi3_t *chip, fw_board_t *board);
void fw_isr(supi3_t *chip, fw_board_t *board);
void fw_loop(supi3_t *chip, fw_board_t *board);
int fw_entry_points(void);

extern "Python" int supi3_native_xfer(void *, uint8_t, uint8_t *, int);
extern "Python" void supi3_native_delay_us(void *, uint32_t);
extern "Python" int supi3_native_read_irq(void *, int *);
extern "Python" int supi3_native_read_cd(void *, int *);
extern "Python" int supi3_native_read_io(void *, int *);
extern "Python" int supi3_native_set_sas_init(void *, int);
extern "Python" int supi3_native_set_stat_err(void *, int);
extern "Python" int supi3_native_mod_ack_seen(void *, int *);
"""
# The glue the cffi module adds (compiled with the host's default flags, not the strict ones: it includes
# Python.h). The entry points are weak so that a firmware may leave out fw_isr and fw_loop (and a driver-only
# library all three); fw_entry_points() tells which exist (GCC and Clang on ELF and Mach-O).
_GLUE: Final[str] = """
#include "supi3.h"
#include "fw_board.h"
void fw_setup(supi3_t *chip, fw_board_t *board) __attribute__((weak));
void fw_isr(supi3_t *chip, fw_board_t *board) __attribute__((weak));
void fw_loop(supi3_t *chip, fw_board_t *board) __attribute__((weak));
static int fw_entry_points(void)
{
    return (fw_setup != NULL ? 1 : 0) | (fw_isr != NULL ? 2 : 0) | (fw_loop != NULL ? 4 : 0);
}
"""
_HAS_SETUP, _HAS_ISR, _HAS_LOOP = 1, 2, 4
Sources = str | Path | Iterable[str | Path]
"""One ``.c`` file or several."""
_COMPILERS: Final[tuple[str, ...]] = ("cc", "gcc", "clang")
_MACRO: Final = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


class NativeBuildError(Supi3Error, RuntimeError):
    """The C sources did not compile or link (the compiler's messages are in the text)."""


class CompilerNotFoundError(NativeBuildError):
    """No C compiler: ``$CC`` is unset or not found, and neither are ``cc``, ``gcc`` nor ``clang``."""


class CFirmwareError(Supi3Error, RuntimeError):
    """The C firmware reported a driver error in ``board->error`` (not caused by a Python exception)."""


def find_compiler() -> str:
    """The C compiler: ``$CC`` if set (its first word), else the first of ``cc``, ``gcc``, ``clang`` on the PATH.

    Raises
    ------
    CompilerNotFoundError
        If there is none.
    """
    wanted = os.environ.get("CC", "").split()
    names = wanted[:1] or list(_COMPILERS)
    for name in names:
        found = shutil.which(name)
        if found is not None:
            return found
    raise CompilerNotFoundError(f"no C compiler found: tried {', '.join(names)} (set CC or install gcc); "
                                "C firmware needs one")  # fmt: skip


def example(name: str) -> Path:
    """The example firmware ``name`` (``"digital_io"`` or ``"digital_io.c"``) under :data:`EXAMPLES_DIR`."""
    path = EXAMPLES_DIR / (name if name.endswith(".c") else f"{name}.c")
    if not path.is_file():
        known = ", ".join(sorted(p.stem for p in EXAMPLES_DIR.glob("*.c")))
        raise ArgumentError("name", name, f"name must be an example firmware ({known}), not {name!r}")
    return path


def describe_command(byte: int) -> str:
    """A command byte in the manual's words (3.4.4, Table 3-10): ``describe_command(0x81) == "command 81h (read
    OUT1)"``."""
    try:
        command = decode_command(byte)
    except RegisterMapError:
        return f"byte {byte:02X}h (not a command: reserved bits set)"
    return f"command {byte:02X}h ({_access(command)})"


def _access(command: CommandByte) -> str:
    if command.block_transfer:
        return "block transfer"
    parts = []
    for flag, direction in ((command.rd, AccessDirection.READ), (command.wr, AccessDirection.WRITE)):
        if flag:
            register = REGISTER_MAP.port(command.address, direction).register
            parts.append(f"{direction.value} {register.name if register is not None else 'nothing'}")
    return ", ".join(parts) if parts else f"no access, address {command.address}"


# ------------------------------------------------------------------------------------------------------------
# Building
# ------------------------------------------------------------------------------------------------------------


class NativeLibrary:
    """A built driver + firmware: the cffi module's ``ffi`` and ``lib``, and which entry points the firmware has.

    Made by :func:`build`: each is a private copy of the built module, so the firmware's static variables start
    at zero (as at power-up) and are not shared with another :class:`CFirmware`.
    """

    def __init__(self, module: ModuleType, path: Path) -> None:
        self.path = path
        self.ffi: Any = module.ffi
        self.lib: Any = module.lib
        entry_points = int(self.lib.fw_entry_points())
        self.has_setup = bool(entry_points & _HAS_SETUP)
        self.has_isr = bool(entry_points & _HAS_ISR)
        self.has_loop = bool(entry_points & _HAS_LOOP)
        self._register_callbacks()

    def _register_callbacks(self) -> None:
        ffi = self.ffi
        from_handle = ffi.from_handle

        def register(name: str, method: Callable[..., int | None], error: int | None) -> None:
            def callback(user: Any, *args: Any) -> int | None:
                return method(from_handle(user), *args)

            ffi.def_extern(name=f"supi3_native_{name}", error=error)(callback)

        def xfer(user: Any, tx: int, rx: Any, s_r: int) -> int:
            """The hot path, one byte: inline, no method call and no ``*args`` (issue #13's speed, round 10)."""
            firmware: CFirmware = from_handle(user)
            if firmware._error is not None:
                return CALLBACK_FAILED
            protocol = firmware._protocol
            phase = protocol.phase if protocol is not None else None
            try:
                rx[0] = firmware._xfer_to(tx, s_r != 0)  # FW-28: the C int as a bool without a builtin call
            except BaseException as error:
                return firmware._fail(error, firmware._describe_byte(tx, phase))
            return 0

        ffi.def_extern(name="supi3_native_xfer", error=CALLBACK_FAILED)(xfer)
        register("delay_us", CFirmware._delay_us, None)
        register("read_irq", CFirmware._read_irq, CALLBACK_FAILED)
        register("read_cd", CFirmware._read_cd, CALLBACK_FAILED)
        register("read_io", CFirmware._read_io, CALLBACK_FAILED)
        register("set_sas_init", CFirmware._set_sas_init, CALLBACK_FAILED)
        register("set_stat_err", CFirmware._set_stat_err, CALLBACK_FAILED)
        register("mod_ack_seen", CFirmware._mod_ack_seen, CALLBACK_FAILED)


_COPIES: list[Path] = []  # the folder of this process's private copies, made on first use


def default_cache_dir() -> Path:
    """``$SUPI3_NATIVE_CACHE``, else ``$XDG_CACHE_HOME/supi3/native`` (``~/.cache/supi3/native``)."""
    if os.environ.get(CACHE_ENV):
        return Path(os.environ[CACHE_ENV])
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "supi3" / "native"


def _sources(sources: Sources) -> tuple[Path, ...]:
    if isinstance(sources, str | Path):
        sources = (sources,)
    paths = []
    for source in sources:
        if not isinstance(source, str | Path) or not Path(source).is_file() or Path(source).suffix != ".c":
            raise ArgumentError("sources", source, f"sources must be paths of existing .c files, not {source!r}")
        paths.append(Path(source).resolve())
    return tuple(paths)


def build(sources: Sources = (), *, include_dirs: Iterable[str | Path] = (), defines: Mapping[str, str] | None = None,
          cache_dir: str | Path | None = None) -> NativeLibrary:  # fmt: skip
    """Build (or take from the cache) the C driver plus the firmware ``sources`` as one cffi module, and load a
    private copy of it (:class:`NativeLibrary`).

    Parameters
    ----------
    sources:
        The firmware's ``.c`` file or files (none: the driver alone). ``fw_board.h`` and ``supi3.h`` are on the include
        path.
    include_dirs:
        Further include folders of the firmware.
    defines:
        Preprocessor macros for every source, ``{"FW_MODE": "SUPI3_MODE_INTEL"}`` is ``-DFW_MODE=SUPI3_MODE_INTEL``.
    cache_dir:
        Where built modules are kept (default :func:`default_cache_dir`); a module is rebuilt when a source, a
        header, a flag or the compiler changes. Builds in parallel processes are safe (each builds in a
        temporary folder and renames its result into place).

    Raises
    ------
    CompilerNotFoundError
        If there is no C compiler.
    NativeBuildError
        If a source does not compile under :data:`STRICT_FLAGS` or the module does not link.
    """
    firmware = _sources(sources)
    includes = (sdk.include_dir(), EXAMPLES_DIR, *(Path(d).resolve() for d in include_dirs))
    flags = (*STRICT_FLAGS, *_defines(defines))
    compiler = find_compiler()
    c_files = (*sdk.sources(), *firmware)
    # A source's own folder is searched first by #include "...": its headers count too. Folders of the sources
    # themselves do not (NC-8): the same firmware written to two temporary folders is one build.
    folders = dict.fromkeys((*includes, *(source.parent for source in firmware)))
    headers = [h for d in folders for h in sorted(Path(d).glob("*.h"))]
    digest = hashlib.sha256()
    for part in (compiler, sys.version, _cffi().__version__, _CDEF, _GLUE, *flags, *map(str, includes)):
        digest.update(part.encode() + b"\0")
    for path in (*c_files, *headers):
        digest.update(path.name.encode() + b"\0" + path.read_bytes() + b"\0")
    name = f"_supi3_native_{digest.hexdigest()[:20]}"
    folder = Path(cache_dir) if cache_dir is not None else default_cache_dir()
    target = folder / f"{name}{sysconfig.get_config_var('EXT_SUFFIX')}"
    if not target.is_file():
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryDirectory(dir=folder, prefix=f"{name}.") as work:
            built = _compile(compiler, flags, name, (c_files, includes), Path(work))
            os.replace(built, target)
    return NativeLibrary(_load_copy(target, name), target)


def _load_copy(target: Path, name: str) -> ModuleType:
    """Load a private copy of the module: a shared library loaded twice from one path is one image, and the
    firmware's static variables would be shared by every CFirmware of the process."""
    if not _COPIES:
        _COPIES.append(Path(tempfile.mkdtemp(prefix="supi3-native-")))
        atexit.register(shutil.rmtree, _COPIES[0], True)
    handle, copy = tempfile.mkstemp(dir=_COPIES[0], prefix=f"{name}.", suffix=target.name[len(name):])
    os.close(handle)
    shutil.copyfile(target, copy)
    spec = importlib.util.spec_from_file_location(name, copy)
    if spec is None or spec.loader is None:  # cannot happen for an extension module path
        raise NativeBuildError(f"cannot load {target}")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _cffi() -> Any:
    try:
        import cffi  # type: ignore[import-untyped]  # the sdk extra; no type information
    except ImportError as error:
        raise NativeBuildError("cffi is not installed: C firmware needs the sdk extra (pip install supi3[sdk])") \
            from error
    return cffi


def toolchain_missing() -> str | None:
    """Why C firmware cannot be built here (no cffi, no setuptools for cffi's compile step, no C compiler), or
    ``None`` if it can: a test's skip reason."""
    try:
        _cffi()
        find_compiler()
    except NativeBuildError as error:
        return str(error)
    if importlib.util.find_spec("setuptools") is None:
        return "setuptools is not installed: cffi compiles C firmware with it (pip install setuptools)"
    headers = Path(sysconfig.get_paths()["include"]) / "Python.h"
    if not headers.is_file():
        return f"the Python headers are missing ({headers}): cffi's glue needs them (apt install python3-dev)"
    return None


def _defines(defines: Mapping[str, str] | None) -> tuple[str, ...]:
    if defines is None:
        return ()
    if not isinstance(defines, Mapping):
        raise ArgumentError("defines", defines, f"defines must be a mapping of macro names to values, not {defines!r}")
    for macro, value in defines.items():
        if not isinstance(macro, str) or _MACRO.fullmatch(macro) is None or not isinstance(value, str):
            raise ArgumentError("defines", defines, f"defines must map C identifiers to strings, not {macro!r}: "
                                f"{value!r}")  # fmt: skip
    return tuple(f"-D{macro}={value}" for macro, value in sorted(defines.items()))


def _compile(compiler: str, flags: tuple[str, ...], name: str, files: tuple[tuple[Path, ...], tuple[Path, ...]],
             work: Path) -> Path:  # fmt: skip
    c_files, includes = files
    objects = []
    for k, source in enumerate(c_files):
        obj = work / f"{k}_{source.stem}.o"
        command = [compiler, *flags, "-fPIC", "-c", *(f"-I{d}" for d in includes), str(source), "-o", str(obj)]
        result = subprocess.run(command, capture_output=True, text=True, check=False)
        if result.returncode != 0:
            raise NativeBuildError(f"{source.name} does not compile with {' '.join(flags)}:\n{result.stderr}")
        objects.append(str(obj))
    ffi = _cffi().FFI()
    ffi.cdef(_CDEF)
    ffi.set_source(name, _GLUE, include_dirs=[str(d) for d in includes], extra_objects=objects)
    log = io.StringIO()
    try:
        with contextlib.redirect_stdout(log), contextlib.redirect_stderr(log):
            return Path(ffi.compile(tmpdir=str(work), verbose=False))
    except Exception as error:  # setuptools' CompileError / LinkError, cffi's VerificationError
        raise NativeBuildError(f"the cffi module does not build: {error}\n{log.getvalue()}") from error


# ------------------------------------------------------------------------------------------------------------
# The firmware on the bench
# ------------------------------------------------------------------------------------------------------------


class CFirmware(Firmware):
    """A C firmware (``fw_setup``, ``fw_isr``, ``fw_loop`` of ``fw_board.h``) as a bench :class:`Firmware`.

    Parameters
    ----------
    sources:
        The firmware's ``.c`` file(s), e.g. ``native.example("digital_io")``; built by :func:`build`.
    include_dirs, defines, cache_dir:
        Passed to :func:`build`; the examples take ``defines={"FW_MODE": "SUPI3_MODE_INTEL"}`` for the Intel mode.
    frame_gap_us:
        ``supi3_config_t.frame_gap_us`` of the C driver (the bench's ``frame_gap_us`` is the Python driver's).

    Attributes
    ----------
    library:
        The :class:`NativeLibrary`; ``library.ffi`` and ``library.lib`` reach every C symbol.
    board:
        The ``fw_board_t`` (cffi struct): tests write ``board.inputs`` and ``board.fault`` and read
        ``board.outputs``, ``board.cycles``, ``board.command``, ``board.error``.
    context:
        The C driver's ``supi3_t``.

    The object is a ``CFirmware`` whose class has a ``loop`` exactly when the firmware defines ``fw_loop`` (the
    bench runs a main loop only for firmware that has one). :meth:`setup` makes the driver context on the
    transport of the driver the bench passes (any :class:`~supi3.sdk.driver.Transport`; /StatErr and /ModAck
    need the bench's). After an entry point returns, an exception a callback caught is raised again with a note
    (PEP 678), else a driver error the firmware kept in ``board->error`` raises :class:`CFirmwareError`; either
    way ``board->error`` is set back to 0, so that each failure is raised once.
    """

    library: NativeLibrary
    _xfer_to: Callable[[int, bool], int]  # the transport's xfer, from attach()

    def __new__(cls, sources: Sources, **options: Any) -> CFirmware:
        """Pick :class:`_LoopingCFirmware` when the firmware has a main loop."""
        library = build(sources, include_dirs=options.get("include_dirs", ()), defines=options.get("defines"),
                        cache_dir=options.get("cache_dir"))  # fmt: skip
        chosen = _LoopingCFirmware if library.has_loop and cls is CFirmware else cls
        instance: CFirmware = super().__new__(chosen)
        instance.library = library
        return instance

    def __init__(self, sources: Sources, *, include_dirs: Iterable[str | Path] = (),
                 defines: Mapping[str, str] | None = None, cache_dir: str | Path | None = None,
                 frame_gap_us: int = 0) -> None:  # fmt: skip
        del sources, include_dirs, defines, cache_dir  # used by __new__
        library: NativeLibrary = self.library
        if not library.has_setup:
            raise NativeBuildError("the firmware must define fw_setup(supi3_t *, fw_board_t *) (fw_board.h)")
        frame_gap_us = check_int("frame_gap_us", frame_gap_us, 0, 0xFFFF_FFFF, "supi3_config_t.frame_gap_us")
        ffi, lib = library.ffi, library.lib
        self._handle = ffi.new_handle(self)
        self.context: Any = ffi.new("supi3_t *")
        self.board: Any = ffi.new("fw_board_t *")
        self.board.user = self._handle
        self.board.delay_us = lib.supi3_native_delay_us
        self.board.set_stat_err = lib.supi3_native_set_stat_err
        self.board.mod_ack_seen = lib.supi3_native_mod_ack_seen
        self._config: Any = ffi.new("supi3_config_t *")
        config = self._config
        config.xfer = lib.supi3_native_xfer
        config.delay_us = lib.supi3_native_delay_us
        config.user = self._handle
        config.frame_gap_us = frame_gap_us
        self._entries = {name: getattr(lib, name) for name in ("fw_setup", "fw_isr", "fw_loop")
                         if getattr(library, f"has_{name[3:]}")}  # fmt: skip
        self.transport: Transport | None = None
        self._protocol: Any = None
        self._error: BaseException | None = None
        self._where = ""
        self._mod_ack_seen_until = 0

    # -- the entry points --------------------------------------------------------------------------------------

    def attach(self, transport: Transport) -> None:
        """Make the C driver's context on ``transport`` (``supi3_init``); :meth:`setup` does it with the bench's."""
        if not isinstance(transport, Transport):
            raise ArgumentError("transport", transport, f"transport must be a supi3.sdk.driver.Transport, not "
                                f"{transport!r}")  # fmt: skip
        self.transport = transport
        self._xfer_to = transport.xfer
        self._protocol = transport.protocol if isinstance(transport, ModelTransport) else None
        lib, config = self.library.lib, self._config
        # A pin the transport does not wire is a NULL callback, as supi3.h wants: the driver then works without it.
        # The status pins are read once to find out; SAS_INIT is not driven for that: wired if the class has it.
        ffi_null = self.library.ffi.NULL
        config.read_irq = lib.supi3_native_read_irq if transport.read_irq() is not None else ffi_null
        config.read_cd = lib.supi3_native_read_cd if transport.read_cd() is not None else ffi_null
        config.read_io = lib.supi3_native_read_io if transport.read_io() is not None else ffi_null
        sas_wired = type(transport).set_sas_init is not Transport.set_sas_init
        config.set_sas_init = lib.supi3_native_set_sas_init if sas_wired else ffi_null
        err = int(lib.supi3_init(self.context, config))
        if err != 0:  # cannot happen: the config has an xfer
            raise CFirmwareError(f"supi3_init() failed: {self._strerror(err)}")

    def setup(self, drv: Supi3Driver) -> None:
        """Power-up: :meth:`attach` to ``drv.transport``, then ``fw_setup``."""
        self.attach(drv.transport)
        self.call("fw_setup")

    def isr(self, drv: Supi3Driver) -> None:
        """``fw_isr`` (if the firmware has one)."""
        del drv
        if "fw_isr" in self._entries:
            self.call("fw_isr")

    def call(self, entry: str) -> None:
        """Call the C entry point ``entry`` (``"fw_setup"``, ``"fw_isr"``, ``"fw_loop"``) and raise what failed in
        it: the exception a callback caught (with a note), else :class:`CFirmwareError` for ``board->error``."""
        function = self._entries.get(entry)
        if function is None:
            raise ArgumentError("entry", entry, f"entry must be one of the firmware's entry points "
                                f"({', '.join(self._entries)}), not {entry!r}")  # fmt: skip
        if self.transport is None:
            raise CFirmwareError(f"{entry}() before setup(): attach the firmware to a transport first")
        function(self.context, self.board)
        error = self._error
        code, self.board.error = self.board.error, 0  # each failure is raised once
        if error is not None:
            self._error = None
            error.add_note(f"in {entry}(): {self._where}")
            raise error
        if code != 0:
            raise CFirmwareError(f"{entry}() reported driver error {code}: {self._strerror(code)}")

    def _strerror(self, err: int) -> str:
        return str(self.library.ffi.string(self.library.lib.supi3_strerror(err)).decode())

    # -- the callbacks (called from C through NativeLibrary) ---------------------------------------------------

    def _fail(self, error: BaseException, where: str) -> int:
        if self._error is None:
            self._error = error
            self._where = where
        return CALLBACK_FAILED

    def _describe_byte(self, tx: int, phase: Phase | None) -> str:
        if phase is Phase.INIT:
            return f"initialization byte {tx:02X}h"
        if phase is Phase.COMMAND:
            return describe_command(tx)
        command = self._protocol.command if phase in (Phase.DATA, Phase.BLOCK) else None
        if isinstance(command, CommandByte):
            byte = encode_command(command.address, rd=command.rd, wr=command.wr)
            return f"{describe_command(byte)}, data byte (sent {tx:02X}h)"
        return f"byte {tx:02X}h"

    def _delay_us(self, us: int) -> None:
        if self._error is None:
            try:
                self._transport().delay_us(us)
            except BaseException as error:
                self._fail(error, f"delay_us({us})")

    def _pin(self, level: Any, read: Callable[[], int | None], name: str) -> int:
        if self._error is not None:
            return CALLBACK_FAILED
        try:
            value = read()
            if value is None:
                return NOT_WIRED
            level[0] = value
        except BaseException as error:
            return self._fail(error, f"reading {name}")
        return 0

    def _read_irq(self, level: Any) -> int:
        return self._pin(level, self._transport().read_irq, "/IRQ (read_irq)")

    def _read_cd(self, level: Any) -> int:
        return self._pin(level, self._transport().read_cd, "C/D (read_cd)")

    def _read_io(self, level: Any) -> int:
        return self._pin(level, self._transport().read_io, "the I/O access pin (read_io)")

    def _set_sas_init(self, level: int) -> int:
        if self._error is not None:
            return CALLBACK_FAILED
        try:
            return 0 if self._transport().set_sas_init(level) else NOT_WIRED
        except BaseException as error:
            return self._fail(error, f"set_sas_init({level})")

    def _set_stat_err(self, active: int) -> int:
        if self._error is not None:
            return CALLBACK_FAILED
        transport = self._transport()
        if not isinstance(transport, BenchTransport):
            return NOT_WIRED
        try:
            transport.bench.set_stat_err(bool(active))
        except BaseException as error:
            return self._fail(error, f"set_stat_err({active})")
        return 0

    def _mod_ack_seen(self, seen: Any) -> int:
        """The board's edge latch on /ModAck: a pulse started since the last call (3.6.2; decision in
        docs/sdk-firmware-c.md: the 375 ns pulse is too short to poll)."""
        if self._error is not None:
            return CALLBACK_FAILED
        transport = self._transport()
        if not isinstance(transport, BenchTransport):
            return NOT_WIRED
        try:
            bench = transport.bench
            bench.advance(bench.now)
            until = bench.chip.mod_ack_until
            seen[0] = until != self._mod_ack_seen_until
            self._mod_ack_seen_until = until
        except BaseException as error:
            return self._fail(error, "reading /ModAck (mod_ack_seen)")
        return 0

    def _transport(self) -> Transport:
        transport = self.transport
        if transport is None:  # cannot happen: call() checks it before any C code runs
            raise CFirmwareError("the firmware is not attached to a transport")
        return transport


class _LoopingCFirmware(CFirmware):
    """A :class:`CFirmware` with ``fw_loop``: the bench runs it as the main loop."""

    def loop(self, drv: Supi3Driver) -> None:
        """One pass of ``fw_loop``."""
        del drv
        self.call("fw_loop")

"""Build a firmware for the emulated board with the Zig toolchain from PyPI (``ziglang``): one command.

:func:`build` compiles the SDK's C driver (``supi3.c``), the board port (``board/board.c``, ``board/startup.c``)
and the firmware's sources for a Cortex-M0 or -M3 and links them with ``board/board.ld``:

    python -m ziglang cc -target thumb-freestanding-eabi -mcpu=cortex_m3 -ffreestanding -nostdlib
        -std=c99 -Wall -Wextra -pedantic -Werror -Os -g -Wl,--entry=Reset_Handler -T board.ld
        -I<sdk include> -I<sdk examples> -I<board> board/startup.c board/board.c src/supi3.c FIRMWARE.c -o OUT.elf

From the shell: ``supi3 firmware build FIRMWARE.c -o OUT.elf [--cpu cortex_m0] [-D NAME=VALUE]`` (guide:
docs/firmware-in-the-loop.md).
"""

from __future__ import annotations

import importlib.util
import re
import subprocess
import sys
from collections.abc import Iterable, Mapping, Sequence
from os import PathLike
from pathlib import Path
from typing import Final

from supi3 import sdk
from supi3.checks import check_bool, fail
from supi3.errors import ArgumentError, Supi3Error
from supi3.mcu.core import check_cpu

__all__ = [
    "BOARD_DIR",
    "FLAGS",
    "MACRO_NAME",
    "SOURCE_SUFFIXES",
    "BuildError",
    "build",
    "build_command",
    "toolchain_missing",
]

BOARD_DIR: Final[Path] = sdk.SDK_DIR / "board"
"""The board port: ``board.h``, ``board.c``, ``startup.c``, ``board.ld``."""
FLAGS: Final[tuple[str, ...]] = ("-target", "thumb-freestanding-eabi", "-ffreestanding", "-nostdlib",
                                 *sdk.CFLAGS, "-Werror", "-Os", "-g", "-Wl,--entry=Reset_Handler")  # fmt: skip
"""Flags of every firmware build besides ``-mcpu`` and the paths: the SDK's strict C99 flags, no library."""
MACRO_NAME: Final[re.Pattern[str]] = re.compile(r"[A-Za-z_][A-Za-z0-9_]*", re.ASCII)
"""A macro name of ``defines``: a C identifier."""
_DEFINES: Final[str] = "a mapping of C identifiers to one-line str values"
"""What ``defines`` must be (its error's words)."""
SOURCE_SUFFIXES: Final[tuple[str, ...]] = (".c", ".S", ".h")
"""Suffixes ``output`` may not have: the ELF would replace a source (``-o a.c a.c``; MCU-48)."""


class BuildError(Supi3Error, RuntimeError):
    """The firmware did not compile or link, or there is no ziglang.

    Attributes
    ----------
    summary:
        What failed, one line.
    output:
        The compiler's messages, lines as it wrote them ("" if none); the text of the error is the summary and them.
    """

    def __init__(self, summary: str, output: str = "") -> None:
        self.summary = summary
        self.output = output
        super().__init__(f"{summary}:\n{output}" if output else summary)

    def __reduce__(self) -> tuple[object, ...]:
        return (type(self), (self.summary, self.output))


def toolchain_missing() -> str | None:
    """Why firmware cannot be built here (``ziglang`` not installed), or ``None``: a test's skip reason."""
    if importlib.util.find_spec("ziglang") is None:
        return "ziglang is not installed: firmware builds need the firmware extra (pip install supi3[firmware])"
    return None


def build_command(sources: Sequence[str | Path], output: str | Path, *, cpu: str = "cortex_m3",
                  defines: Mapping[str, str] | None = None, include_dirs: Iterable[str | Path] = (),
                  compiler_rt: bool = False, port: bool = True) -> list[str]:  # fmt: skip
    """The command line :func:`build` runs (see the module's docstring).

    Raises
    ------
    ArgumentError
        ``cpu`` not one of the board's; ``sources`` not existing .c or .S files; ``output`` a folder, in a folder
        that does not exist, a source or a .c, .S or .h file (MCU-48); ``defines`` not a mapping of C identifiers to
        one-line str values; ``include_dirs`` not existing folders; ``compiler_rt`` or ``port`` not a bool.
    """
    check_cpu(cpu)
    if isinstance(sources, str | bytes) or not isinstance(sources, Sequence) or not sources \
            or not all(isinstance(s, str | PathLike) for s in sources):  # fmt: skip
        raise fail("sources", "a non-empty sequence of paths of .c or .S files", sources)
    paths = [Path(s) for s in sources]
    for path in paths:
        if not path.is_file() or path.suffix not in (".c", ".S"):
            raise ArgumentError("sources", path, f"sources must be paths of existing .c or .S files, not {str(path)!r}")
    # the compiler cannot write into a folder that does not exist, nor over a folder: refused here, not blamed on the
    # firmware ("does not build")
    if not isinstance(output, str | PathLike) or Path(output).suffix in SOURCE_SUFFIXES or Path(output).is_dir() \
            or not Path(output).parent.is_dir() \
            or any(Path(output).resolve() == path.resolve() for path in paths):  # fmt: skip
        raise fail("output", "a path of the ELF file to write, in an existing folder, neither a folder, one of the "
                   "sources nor a .c, .S or .h file (MCU-48)", output)
    if defines is not None and not isinstance(defines, Mapping):
        raise fail("defines", _DEFINES, defines)
    for name, value in (defines or {}).items():
        # a newline ends the macro (the compiler's -Werror refuses it only after a run)
        if not isinstance(name, str) or not MACRO_NAME.fullmatch(name) or not isinstance(value, str) \
                or any(c in value for c in "\r\n\0"):  # fmt: skip
            raise fail("defines", _DEFINES, {name: value})
    if isinstance(include_dirs, str | bytes) or not isinstance(include_dirs, Iterable):
        raise fail("include_dirs", "an iterable of existing folder paths", include_dirs)
    folders = list(include_dirs)
    for folder in folders:  # the compiler ignores a -I folder that does not exist
        if not isinstance(folder, str | PathLike) or not Path(folder).is_dir():
            raise fail("include_dirs", "an iterable of existing folder paths", folder)
    check_bool("compiler_rt", compiler_rt)
    check_bool("port", port)
    includes = (sdk.include_dir(), sdk.SDK_DIR / "examples", BOARD_DIR, *(Path(d) for d in folders))
    macros = [f"-D{name}={value}" for name, value in sorted((defines or {}).items())]
    library = (BOARD_DIR / "startup.c", BOARD_DIR / "board.c", *sdk.sources()) if port else ()
    return [sys.executable, "-m", "ziglang", "cc", f"-mcpu={cpu}", *FLAGS, *(["-lcompiler_rt"] if compiler_rt else []),
            "-T", str(BOARD_DIR / "board.ld"), *macros, *(f"-I{d}" for d in includes), *map(str, library),
            *map(str, paths), "-o", str(output)]  # fmt: skip


def build(sources: str | Path | Sequence[str | Path], output: str | Path, *, cpu: str = "cortex_m3",
          defines: Mapping[str, str] | None = None, include_dirs: Iterable[str | Path] = (),
          compiler_rt: bool = False, port: bool = True) -> Path:  # fmt: skip
    """Build the firmware ``sources`` (the ``fw_setup``/``fw_isr``/``fw_loop`` of ``examples/fw_board.h``) with the
    C driver and the board port into the ELF ``output`` for ``cpu`` (``"cortex_m3"`` or ``"cortex_m0"``).

    ``compiler_rt`` links the toolchain's run-time library, for firmware that needs more helpers than
    ``startup.c`` has (its first build compiles it: about 15 s). ``port=False`` links ``sources`` (C or assembly
    with their own vector table) alone with ``board.ld``: no driver, no board port. Returns ``output``.

    Raises
    ------
    BuildError
        If ziglang is missing or the sources do not compile under :data:`FLAGS`.
    ArgumentError
        Bad arguments (:func:`build_command`), before the compiler runs.
    """
    missing = toolchain_missing()
    if missing is not None:
        raise BuildError(missing)
    files = [sources] if isinstance(sources, str | PathLike) else sources
    command = build_command(files, output, cpu=cpu, defines=defines, include_dirs=include_dirs,
                            compiler_rt=compiler_rt, port=port)  # fmt: skip
    result = subprocess.run(command, capture_output=True, text=True, check=False)
    if result.returncode != 0:
        raise BuildError(f"the firmware does not build for {cpu}", result.stderr)
    return Path(output)

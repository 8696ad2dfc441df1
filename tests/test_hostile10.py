"""The firmware SDK as a hostile firmware developer drives it (round 10): the Python driver and the C driver, one API.

docs/sdk.md promises one API shape: ``supi3_read`` is ``Supi3Driver.read``, each C error code a Python exception
(docs/sdk-api.md). Here both drivers run the same history of calls (any order: before initialize, after a refused
call, after a transport failure, SAS_INIT with and without the pin, a pin that fails) against the same scripted
board, and must return the same code, the same values, send the same frames and read the same pins. The C driver is
built strictly (``-Wall -Wextra -Werror -pedantic``) and loaded with ctypes; a callback that raises ``OSError``
is a failing callback (return -1), a pin the board does not wire is a NULL callback.

Also: the model's direct path (``Transport.direct``) against the frames after a strict-mode violation on SET; the
pytest plugin's marker firmware handed to a second test (FW-17); ELF files whose segments the file does not hold
(MCU-47).
"""

from __future__ import annotations

import ctypes
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import test_sdk_c_model
from supi3.config import decode
from supi3.model.registers import ReconfigurationError, RegisterFile
from supi3.regmap import REGISTER_MAP, SET, AccessDirection, Register
from supi3.sdk.driver import (
    AsyncSupi3Driver,
    AsyncTransport,
    DriverError,
    ErrorCode,
    IoWindowTimeoutError,
    Mode,
    Supi3Driver,
    Transport,
)
from supi3.sdk.transports import ModelTransport
from test_sdk_c_model import DELAY, OPTICAL_FIELDS, READ_PIN, WRITE_PIN, XFER, Config, Optical

pytest_plugins = ["pytester"]
lib = test_sdk_c_model.lib
"""The fixture: the C driver built strictly, loaded with ctypes (with ``supi3_config_t`` and ``supi3_optical_t``, as
tests/test_sdk_c_model.py has them)."""

NULL, WIRED, SAYS_UNWIRED = 0, 1, 2
"""How a board has each pin (C/D, /IRQ, I/O, SAS_INIT): no callback (``False`` too), wired (``True`` too), or a
callback that says the board does not wire it (FW-21: C returns ``SUPI3_E_UNSUPPORTED``; Python's transport returns
``None`` or ``False``, as for no pin)."""
Wired = tuple[int, int, int, int]


class Scripted(Transport):
    """A board whose chip answers from a script: received bytes and pin levels cycle through their lists; the
    ``fail``-th callback (counted over all of them) raises ``OSError``. Every callback is logged."""

    def __init__(self, rx: list[int], levels: list[int], fail: frozenset[int], wired: Wired):
        self.rx, self.levels, self.fail = rx, levels, fail
        self.wired = wired
        self.cd_wired, self.irq_wired, self.io_wired, self.sas_wired = (pin == WIRED for pin in wired)
        self.log: list[tuple[object, ...]] = []
        self._rx = self._level = 0

    def _count(self, *entry: object) -> None:
        self.log.append(entry)
        if len(self.log) - 1 in self.fail:
            raise OSError(f"callback {len(self.log) - 1} failed")

    def _next_level(self) -> int:
        self._level += 1
        return self.levels[(self._level - 1) % len(self.levels)]

    def delay_us(self, us: float) -> None:
        self.log.append(("delay", float(us)))

    def xfer(self, tx: int, s_r: bool) -> int:
        self._count("xfer", tx, s_r)
        self._rx += 1
        return self.rx[(self._rx - 1) % len(self.rx)]

    def read_cd(self) -> int | None:
        if not self.cd_wired:
            return None
        self._count("cd")
        return self._next_level()

    def read_irq(self) -> int | None:
        if not self.irq_wired:
            return None
        self._count("irq")
        return self._next_level()

    def read_io(self) -> int | None:
        if not self.io_wired:
            return None
        self._count("io")
        return self._next_level()

    def set_sas_init(self, level: int) -> bool:
        if not self.sas_wired:
            return False
        self._count("sas", level)
        return True


class CDriver:
    """The C driver on a :class:`Scripted` board: each call returns (code, value) as the Python driver's would."""

    def __init__(self, lib: ctypes.CDLL, board: Scripted, frame_gap_us: int = 0) -> None:
        self.lib, self.board = lib, board

        def guard(call: Callable[[], int | None], store: Any = None) -> int:
            try:
                value = call()
            except OSError:
                return -1
            if store is not None:
                store[0] = value
            return 0

        def pin(kind: Any, how: int, callback: Callable[..., int]) -> Any:
            """A wired pin's callback, NULL, or one that says "not wired" (FW-21)."""
            return kind(callback) if how == WIRED else kind(lambda *_: UNSUPPORTED) if how == SAYS_UNWIRED else kind()

        cd, irq, io, sas = board.wired
        self._callbacks = (
            XFER(lambda _u, tx, rx, s_r: guard(lambda: board.xfer(tx, bool(s_r)), rx)),
            DELAY(lambda _u, us: board.delay_us(us)),
            pin(READ_PIN, irq, lambda _u, level: guard(board.read_irq, level)),
            pin(READ_PIN, cd, lambda _u, level: guard(board.read_cd, level)),
            pin(WRITE_PIN, sas, lambda _u, level: guard(lambda: board.set_sas_init(level) and None)),
        )  # fmt: skip
        self._io = pin(READ_PIN, io, lambda _u, level: guard(board.read_io, level))
        self.cfg = Config(*self._callbacks, None, frame_gap_us, self._io)
        self.ctx = ctypes.create_string_buffer(256)
        assert lib.supi3_init(self.ctx, ctypes.byref(self.cfg)) == 0

    def run(self, op: tuple[Any, ...]) -> tuple[object, object]:
        lib, ctx, u8 = self.lib, self.ctx, ctypes.c_uint8
        value = u8(0)
        name = op[0]
        if name == "initialize":
            mode = 2 if type(op[1]) is not Mode else 0 if op[1] is Mode.MOTOROLA else 1  # "intel" is no Mode
            return lib.supi3_initialize(ctx, ctypes.c_int(mode)), None
        if name == "sas_init":
            return lib.supi3_sas_init(ctx), None
        if name == "read":
            rc = lib.supi3_read(ctx, u8(op[1]), ctypes.byref(value))
            return rc, value.value if rc == 0 else None
        if name == "write":
            return lib.supi3_write(ctx, u8(op[1]), u8(op[2])), None
        if name == "exchange":
            rc = lib.supi3_exchange(ctx, u8(op[1]), u8(op[2]), ctypes.byref(value))
            return rc, value.value if rc == 0 else None
        if name == "block":
            data, rd, wr = op[1], op[2], op[3]
            out = (u8 * 4)()
            rc = lib.supi3_block_transfer(ctx, ctypes.c_int(rd), ctypes.c_int(wr), out if rd else None,
                                          (u8 * 4)(*data), ctypes.c_size_t(len(data)))  # fmt: skip
            return rc, (bytes(out[: len(data)]) if rd else b"") if rc == 0 else None
        if name == "configure":
            return lib.supi3_configure(ctx, u8(op[1]), u8(op[2])), None
        if name == "irq_service":
            rc = lib.supi3_irq_service(ctx, ctypes.byref(value))
            return rc, value.value if rc in (0, -7) else None
        if name == "irq_enable":
            return lib.supi3_irq_enable(ctx, u8(op[1])), None
        if name == "poll":
            rc = lib.supi3_poll_io_window(ctx, ctypes.c_uint32(op[1]), ctypes.byref(value))
            return rc, value.value if rc in (0, -7) else None
        if name == "alarm":
            return lib.supi3_processor_alarm(ctx, u8(op[1])), None
        if name == "pcmd":
            rc = lib.supi3_processor_command(ctx, ctypes.byref(value))
            return rc, value.value if rc == 0 else None
        assert name == "optical"
        status = Optical()
        rc = lib.supi3_optical_status(ctx, ctypes.byref(status))
        return rc, tuple(getattr(status, f) for f in OPTICAL_FIELDS) if rc == 0 else None


class AsyncScripted(AsyncTransport):
    """A :class:`Scripted` board behind the async driver (every callback answers at once)."""

    def __init__(self, board: Scripted) -> None:
        self.board = board

    async def xfer(self, tx: int, s_r: bool) -> int:
        return self.board.xfer(tx, s_r)

    async def delay_us(self, us: float) -> None:
        self.board.delay_us(us)

    async def read_cd(self) -> int | None:
        return self.board.read_cd()

    async def read_irq(self) -> int | None:
        return self.board.read_irq()

    async def read_io(self) -> int | None:
        return self.board.read_io()

    async def set_sas_init(self, level: int) -> bool:
        return self.board.set_sas_init(level)


class Awaited:
    """The async driver's calls run to their end at once (its transport never waits): the sync driver's shape."""

    def __init__(self, drv: AsyncSupi3Driver) -> None:
        self.drv = drv

    def __getattr__(self, name: str) -> Callable[..., object]:
        call = getattr(self.drv, name)

        def run(*args: object, **kwargs: object) -> object:
            coroutine = call(*args, **kwargs)
            try:
                coroutine.send(None)
            except StopIteration as stop:
                return stop.value
            raise AssertionError("the async driver waited")  # pragma: no cover

        return run


def register(address: int, direction: AccessDirection) -> Register:
    """The register an access of ``direction`` at ``address`` reaches (Table 3-10)."""
    found = REGISTER_MAP.port(address, direction).register
    assert found is not None
    return found


def py_run(drv: Any, op: tuple[Any, ...]) -> tuple[object, object]:
    """The same call on the Python driver (sync, or async through :class:`Awaited`): (the C code of its exception
    or 0, the value)."""
    name = op[0]
    calls: dict[str, Callable[[], object]] = {
        "initialize": lambda: drv.initialize(op[1]),
        "sas_init": drv.sas_init,
        "read": lambda: drv.read(register(op[1], AccessDirection.READ)),
        "write": lambda: drv.write(register(op[1], AccessDirection.WRITE), op[2]),
        "exchange": lambda: drv.exchange(register(op[1], AccessDirection.READ), op[2]),
        "block": lambda: drv.block_transfer(op[1], read=bool(op[2]), write=bool(op[3])),
        "configure": lambda: drv.configure(op[1], op[2]),
        "irq_service": lambda: int(drv.irq_service()),
        "irq_enable": lambda: drv.irq_enable(op[1]),
        "poll": lambda: int(drv.poll_io_window(op[1])),
        "alarm": lambda: drv.processor_alarm(op[1]),
        "pcmd": drv.processor_command,
        "optical": lambda: tuple(vars(drv.optical_status()).values()),
    }
    try:
        return 0, calls[name]()
    except IoWindowTimeoutError as error:
        return int(error.code), int(error.events)
    except DriverError as error:
        return int(error.code), None


READABLE = [a for a in range(15) if REGISTER_MAP.port(a, AccessDirection.READ).register is not None]
WRITABLE = [a for a in range(15) if REGISTER_MAP.port(a, AccessDirection.WRITE).register is not None]
BOTH = sorted(set(READABLE) & set(WRITABLE))
BYTE = st.integers(0, 255)
WIRINGS = (NULL, WIRED, SAYS_UNWIRED)
UNSUPPORTED = int(ErrorCode.E_UNSUPPORTED)
"""``SUPI3_E_UNSUPPORTED``: what a C pin callback returns to say the board does not wire the pin (FW-21)."""
OPS = st.one_of(
    st.tuples(st.just("initialize"), st.sampled_from([*Mode, "intel"])),  # a mode that is none: SUPI3_E_ARG
    st.tuples(st.just("sas_init")),
    st.tuples(st.just("read"), st.sampled_from(READABLE)),
    st.tuples(st.just("write"), st.sampled_from(WRITABLE), BYTE),
    st.tuples(st.just("exchange"), st.sampled_from(BOTH), BYTE),
    st.tuples(st.just("block"), st.binary(min_size=1, max_size=4), st.integers(0, 1), st.integers(0, 1)),
    st.tuples(st.just("configure"), st.sampled_from([0x82, 0x83, 0x85, 0x87, 0xC3, 0x00]), BYTE),
    st.tuples(st.just("irq_service")),
    st.tuples(st.just("irq_enable"), BYTE),
    st.tuples(st.just("poll"), st.integers(0, 4)),
    st.tuples(st.just("alarm"), BYTE),
    st.tuples(st.just("pcmd")),
    st.tuples(st.just("optical")),
)


def _parity(lib: ctypes.CDLL, rx: list[int], levels: list[int], fail: frozenset[int],
            wired: Wired, ops: list[tuple[Any, ...]], gap: int = 0) -> None:  # fmt: skip
    py_board, async_board, c_board = (Scripted(rx, levels, fail, wired) for _ in range(3))
    drivers = (Supi3Driver(py_board, frame_gap_us=gap),
               Awaited(AsyncSupi3Driver(AsyncScripted(async_board), frame_gap_us=gap)))  # fmt: skip
    c = CDriver(lib, c_board, gap)
    for k, op in enumerate(ops):
        expected = c.run(op)
        for drv, board in zip(drivers, (py_board, async_board), strict=True):
            try:
                py = py_run(drv, op)
            except OSError as error:  # not a driver error: the Python driver let the board's failure through
                py = (f"raw {type(error).__name__}", None)
            assert py == expected, (k, op, type(drv).__name__, board.log, c_board.log)
            assert board.log == c_board.log, (k, op, type(drv).__name__)


@settings(max_examples=300)
@given(rx=st.lists(BYTE, min_size=1, max_size=6), levels=st.lists(st.integers(0, 1), min_size=1, max_size=6),
       fail=st.frozensets(st.integers(0, 40), max_size=3), wired=st.tuples(*[st.sampled_from(WIRINGS)] * 4),
       ops=st.lists(OPS, max_size=14), gap=st.sampled_from([0, 3]))  # fmt: skip
def test_c_and_python_drivers_agree_on_any_history(lib: ctypes.CDLL, rx: list[int], levels: list[int],
                                                   fail: frozenset[int], wired: Wired,
                                                   ops: list[tuple[Any, ...]], gap: int) -> None:  # fmt: skip
    """FW-16: every call of any history, on any scripted board, gives the same code, value, frames and pin reads
    in the C driver, the Python driver and the async Python driver, with and without a frame gap; each pin wired,
    without a callback, or with one that says "not wired" (FW-21), /IRQ staying low over IRQ_EVT reads (FW-22)."""
    _parity(lib, rx, levels, fail, wired, ops, gap)


M = Mode.MOTOROLA
U = SAYS_UNWIRED
CASES: dict[str, tuple[list[int], list[int], frozenset[int], Wired, list[tuple[Any, ...]]]] = {
    # sas_init without the pin is refused (SUPI3_E_UNSUPPORTED) and leaves the driver initialized
    "refused sas_init keeps the mode": ([0], [0], frozenset(), (False,) * 4, [("initialize", M), ("sas_init",),
                                                                              ("read", 0)]),
    # a pin callback that fails is SUPI3_E_TRANSPORT, not the board's own exception
    "failing /IRQ pin": ([0], [0], frozenset({1}), (False, True, False, False), [("initialize", M),
                                                                                ("irq_service",)]),
    "failing C/D pin": ([0], [0], frozenset({0}), (True, False, False, False), [("initialize", M)]),
    "failing I/O pin": ([0], [1], frozenset({1}), (False, False, True, False), [("initialize", M), ("poll", 2)]),
    "failing SAS_INIT pin": ([0], [0], frozenset({1}), (False, False, False, True), [("initialize", M),
                                                                                    ("sas_init",), ("read", 0)]),
    # before initialize, a block of a bad length is SUPI3_E_NOT_INIT in both (the state is checked first)
    "block before initialize": ([0], [0], frozenset(), (False,) * 4, [("block", b"\0", 1, 1)]),
    # a write of SET that failed leaves SET unknown: any block length 2..4 may follow
    "SET lost in a failed write": ([0], [0], frozenset({5}), (False,) * 4,
                                   [("initialize", M), ("write", SET.address, 0x82), ("initialize", M),
                                    ("write", SET.address, 0x83), ("initialize", M), ("block", b"\0\0", 1, 1)]),
    # a mode that is none is SUPI3_E_ARG and leaves the driver initialized
    "bad mode": ([0], [0], frozenset(), (False,) * 4, [("initialize", M), ("initialize", "intel"), ("read", 0)]),
    # irq_service returns the byte read, D7 (the I/O access status, RM-7, RM-8) too, in both
    "irq_service with D7 set": ([0xC4], [0], frozenset(), (False,) * 4, [("initialize", M), ("irq_service",)]),
    # FW-21: a SAS_INIT callback that says "not wired" is SUPI3_E_UNSUPPORTED, the mode kept (was SUPI3_E_TRANSPORT
    # and the mode lost in C), as the Python driver's UnsupportedError
    "sas_init callback says not wired": ([0], [0], frozenset(), (0, 0, 0, U), [("initialize", M), ("sas_init",),
                                                                             ("read", 0)]),
    # FW-21: pin callbacks that say "not wired" work as NULL ones (the C driver used to report a transport error)
    "C/D callback says not wired": ([0], [0], frozenset(), (U, 0, 0, 0), [("initialize", M), ("read", 0)]),
    "/IRQ callback says not wired": ([0x90], [0], frozenset(), (0, U, 0, 0), [("initialize", M), ("irq_service",)]),
    "I/O callback says not wired": ([0x00], [0], frozenset(), (0, 0, U, 0), [("initialize", M), ("poll", 2)]),
    # FW-22: /IRQ low after the read (an event came during it): read again until high; stuck low: SUPI3_E_TIMEOUT
    "event during the IRQ_EVT read": ([0x10, 0x40], [0, 0, 1], frozenset(), (0, 1, 0, 0),
                                      [("initialize", M), ("irq_service",), ("read", 0)]),
    "/IRQ stuck low": ([0x10], [0], frozenset(), (0, 1, 0, 0), [("initialize", M), ("irq_service",), ("read", 0)]),
}


@pytest.mark.parametrize("case", list(CASES), ids=list(CASES))
def test_c_and_python_drivers_agree_on_the_histories_that_differed(lib: ctypes.CDLL, case: str) -> None:
    _parity(lib, *CASES[case])


class Slow(ModelTransport):
    """The model without the direct path (a subclass that changes how a frame goes)."""

    def xfer(self, tx: int, s_r: bool) -> int:
        return super().xfer(tx, s_r)


def test_a_refused_write_of_set_leaves_the_driver_with_the_chips_set_on_both_paths() -> None:
    """FW-16 (6): a strict model raises ReconfigurationError after a write of SET while the bus runs; the chip holds the
    new SET, and so does the driver, whether the access went through the model's direct path or frame by frame."""
    lengths = []
    for cls in (ModelTransport, Slow):
        t = cls(RegisterFile(decode("10011", "1110"), strict=True))
        drv = Supi3Driver(t)
        drv.initialize(Mode.MOTOROLA)
        drv.configure(0x82, 0x01)  # 1 byte: no block transfer
        t.registers.set_bus_running(True)
        with pytest.raises(ReconfigurationError):
            drv.write(SET, 0x83)  # 1 word
        assert t.registers.value("SET") == 0x83
        lengths.append(len(drv.block_transfer(b"\x12\x34")))
    assert lengths == [2, 2]



# ------------------------------------------------------------------------------------------------------------
# The pytest plugin: one firmware object per test (FW-17)
# ------------------------------------------------------------------------------------------------------------

SHARED_FIRMWARE_TEST = '''
import pytest
from supi3.regmap import OUT0
from supi3.sdk.bench import Firmware
from supi3.sdk.driver import Irq, Mode


class Dio(Firmware):
    def __init__(self):
        self.out = None

    def setup(self, drv):
        drv.initialize(Mode.MOTOROLA)
        drv.configure(0x82, 0x01)
        drv.irq_enable(Irq.VALID)

    def isr(self, drv):
        if drv.irq_service() & Irq.VALID:
            self.out = drv.read(OUT0)


@pytest.mark.parametrize("value", [0x5A, 0xA5])
@pytest.mark.supi3(firmware=Dio())
def test_shared(supi3_bench, supi3_master, value):
    assert supi3_bench.firmware.out is None  # a fresh firmware at power-up
    supi3_bench.run(3)
    supi3_master.set_outputs(1, bytes([value]))
    supi3_bench.run(3)
    assert supi3_bench.firmware.out == value


@pytest.mark.parametrize("value", [1, 2])
@pytest.mark.supi3(firmware=Dio)
def test_a_class(supi3_bench, value):
    pass


@pytest.mark.parametrize("value", [pytest.param(v, marks=pytest.mark.supi3(firmware=Dio())) for v in (1, 2)])
def test_one_each(supi3_bench, supi3_master, value):
    assert supi3_bench.firmware.out is None
    supi3_bench.run(3)
    supi3_master.set_outputs(1, bytes([value]))
    supi3_bench.run(3)
    assert supi3_bench.firmware.out == value
'''


def test_a_marker_firmware_that_ran_in_an_earlier_test_is_refused_by_name(pytester: pytest.Pytester) -> None:
    """A firmware object keeps its state (Python attributes; a C firmware's statics and ``fw_board_t``): the
    marker's object handed to a second test (parametrize, a class or module mark) would start there with the first
    test's outputs. The second test is an error naming the first; ``pytest.param(marks=...)`` gives each its own.
    A firmware class in the marker is Bench's own error in every test, not "already ran"."""
    pytester.makepyfile(test_firmware=SHARED_FIRMWARE_TEST)
    result = pytester.runpytest("--strict-markers", "-p", "no:cacheprovider")
    result.assert_outcomes(passed=3, errors=3)
    result.stdout.fnmatch_lines(["*firmware object already ran in test_firmware.py::test_shared?90?*one per test*"])
    errors = [line for line in result.stdout.lines if line.startswith("E ")]  # the tracebacks' own lines: the short
    # summary's lines are cut to the terminal's width, but not where the CI variable is set
    assert sum("DriverArgumentError: firmware must be a supi3.sdk.bench.Firmware" in line for line in errors) == 2


# ------------------------------------------------------------------------------------------------------------
# An ELF file cut short: a segment the file does not hold (MCU-47)
# ------------------------------------------------------------------------------------------------------------


def test_an_elf_whose_segment_runs_past_its_end_is_a_named_error(tmp_path: Path,
                                                                  capsys: pytest.CaptureFixture[str]) -> None:
    """An ELF without section headers (stripped, or made by objcopy) cut short in the middle of a segment: before,
    the loader took the bytes that were there and the firmware ran with the rest of the segment missing."""
    pytest.importorskip("elftools")
    from supi3.cli import main
    from supi3.errors import ArgumentError
    from supi3.mcu.core import FirmwareImage
    from test_mcu_hostile import LOOP, firmware

    whole = firmware(LOOP + bytes(64))
    path = tmp_path / "cut.elf"
    path.write_bytes(whole[:-40])
    with pytest.raises(ArgumentError, match=r"path must be an ELF file that holds its segments, not .*cut.elf "
                                            r"\(the segment at 0x8000000 has 130 bytes in the file, 90 there\)"):
        FirmwareImage.load(path)
    assert main(["firmware", "run", str(path)]) == 2
    assert "holds its segments" in capsys.readouterr().err
    path.write_bytes(whole)
    assert FirmwareImage.load(path).segments[0][1] == whole[-130:]


# ------------------------------------------------------------------------------------------------------------
# supi3 firmware build: the output never overwrites a source (MCU-48)
# ------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("output", ["a.c", "b.c", "board.S", "fw.h", None, 3])
def test_a_build_output_that_is_a_source_file_is_refused_and_writes_nothing(tmp_path: Path, output: object,
                                                                            capsys: pytest.CaptureFixture[str]) -> None:
    """``supi3 firmware build -o a.c a.c`` (or ``-o a.c b.c``, "build both" with the -o forgotten) replaced the
    source a.c with the ELF; ``build(sources, None)`` wrote a file named "None"."""
    from supi3.cli import main
    from supi3.errors import ArgumentError
    from supi3.mcu import build as mcu_build

    text = "void fw_setup(void *chip, void *board) { (void)chip; (void)board; }\n"
    for name in ("a.c", "b.c"):
        (tmp_path / name).write_text(text, encoding="utf-8")
    sources = [tmp_path / "a.c"]
    target = output if not isinstance(output, str) else tmp_path / output
    with pytest.raises(ArgumentError, match=r"output must be a path of the ELF file to write"):
        mcu_build.build_command(sources, target)  # type: ignore[arg-type]
    if isinstance(output, str):
        assert main(["firmware", "build", "-o", str(target), str(tmp_path / "a.c")]) == 2
        assert "output must be a path of the ELF file to write" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.c", "b.c"]
    assert all((tmp_path / name).read_text(encoding="utf-8") == text for name in ("a.c", "b.c"))


# ------------------------------------------------------------------------------------------------------------
# SpidevTransport: a refused construction opens no device (FW-16)
# ------------------------------------------------------------------------------------------------------------


class CountingSpiDev:
    """A stand-in for ``spidev.SpiDev`` that counts the devices left open."""

    open_devices = 0

    def __init__(self) -> None:
        self.mode, self.lsbfirst, self.max_speed_hz = 0, False, 0

    def open(self, bus: int, device: int) -> None:
        del bus, device
        CountingSpiDev.open_devices += 1

    def close(self) -> None:
        CountingSpiDev.open_devices -= 1


class CountingSpidevModule:
    SpiDev = CountingSpiDev


@pytest.mark.parametrize(("args", "options", "message"), [
    ((0, 0), {"speed_hz": 0}, r"speed_hz must be an integer from 1"),
    ((0, 0), {"speed_hz": 1.5e6}, r"speed_hz must be an integer"),
    ((-1, 0), {}, r"bus must be an integer >= 0"),
    ((0, "0"), {}, r"device must be an integer >= 0"),
])  # fmt: skip
def test_a_refused_spidev_transport_leaves_no_device_open(args: tuple[object, object], options: dict[str, Any],
                                                          message: str) -> None:
    """Before, ``speed_hz`` was checked after the device was opened: a refused transport kept /dev/spidevB.D open."""
    from supi3.errors import ArgumentError
    from supi3.sdk.transports import SpidevTransport

    CountingSpiDev.open_devices = 0
    with pytest.raises(ArgumentError, match=message):
        SpidevTransport(*args, spidev_module=CountingSpidevModule, **options)  # type: ignore[arg-type]
    assert CountingSpiDev.open_devices == 0

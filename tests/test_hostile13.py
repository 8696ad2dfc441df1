"""Hostile inputs, orders and histories against the public entries no earlier round attacked (a user's review,
round 13): the firmware bench's run rules (:mod:`supi3.sdk.bench`: ``Bench.run_for``, ``Bench.last_end``), the
emulated board's runs (``supi3.mcu.board.Board.run``/``run_for``), the Python driver's transports
(:class:`~supi3.sdk.driver.Transport` answers, :mod:`supi3.sdk.transports`, :mod:`supi3.sdk.pins`), the firmware
build (:func:`supi3.mcu.build.build_command`: defines, include folders, flags, the output path) and the register
map's layouts (:mod:`supi3.regmap.core`: ``Field.extract``/``insert``, ``RegisterMap.port``/``cleared_by``).

Every bad input is refused by name (which argument, which rule, which value) and changes nothing; a bus time past
A26's maximum is refused before the run (it ran for ever). Over any history of runs, timed runs, bus-time steps,
master outputs, ring faults, resets and firmware writes the bench's clock never goes back and ``run(n)`` finishes
exactly ``n`` cycles (FW-19, MCU-55); over any history of driver calls, refused calls, SAS_INIT pulses and bench runs
the Python driver leaves the chip waiting for a command and reads back what it wrote (3.4.3, FW-16).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.errors import ArgumentError, Supi3Error
from supi3.interbus import wire
from supi3.interbus.device import PlainDevice
from supi3.interbus.ring import BitFlip, DeadLine, Truncate
from supi3.mcu import build as mcu_build
from supi3.model.chip import Supi3
from supi3.regmap import ID, IN0, REGISTER_MAP, SET
from supi3.regmap.core import AccessDirection, RegisterMapError, Reset
from supi3.sdk.bench import START_WAIT_S, Bench, Firmware, MasterStart, ServeWait, default_config
from supi3.sdk.driver import (
    DriverArgumentError,
    DriverError,
    Irq,
    Mode,
    Supi3Driver,
    Transport,
    TransportError,
    put_u16,
)
from supi3.sdk.examples.digital import DigitalIo
from supi3.sdk.pins import PinTransport
from supi3.sdk.transports import ModelTransport, SpidevTransport
from supi3.top import Supi3Chip

pytest_plugins = ["pytester"]

# ---------------------------------------------------------------------------------------------------------------
# The firmware bench (supi3.sdk.bench)
# ---------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("seconds", [2 * wire.MAX_BUS_TIME_S, 1e30, float(2**80)])
def test_bench_run_for_past_the_bus_time_maximum_is_refused_not_run_for_ever(seconds: float) -> None:
    """Defect: ``Bench.run_for`` checked only that ``seconds`` is finite: 1e30 s ran cycle after cycle for ever (A26
    bounds bus time; ``run`` and ``advance`` refuse past it)."""
    bench = Bench()
    with pytest.raises(ArgumentError, match=r"seconds .* past 1048576 s \(A26"):
        bench.run_for(seconds)
    assert (bench.now, bench.cycles) == (0.0, 0)


@pytest.mark.parametrize("began", [math.nan, math.inf, "0", None, True])
def test_bench_last_end_refuses_what_is_no_bus_time(began: object) -> None:
    """Defect: ``Bench.last_end`` returned NaN, a string or None given back as the bus time a run's last cycle ended
    (a wait counted from it never ends, or breaks later)."""
    bench = Bench()
    with pytest.raises(ArgumentError, match=r"began must be a finite number >= 0"):
        bench.last_end(began)  # type: ignore[arg-type]


class _Loop(DigitalIo):
    """The digital I/O example with a main loop that waits."""

    def loop(self, drv: Supi3Driver) -> None:
        drv.transport.delay_us(20)


BENCH_STEPS = st.lists(st.tuples(st.sampled_from(["run", "run_for", "out", "flip", "dead", "trunc", "clear", "reset",
                                                  "in", "advance"]), st.integers(0, 0xFFFF)),
                       min_size=1, max_size=25)  # fmt: skip


@settings(max_examples=60, deadline=None)
@given(steps=BENCH_STEPS, firmware=st.sampled_from([None, DigitalIo, _Loop]), others=st.integers(0, 2),
       cycle_time=st.sampled_from([None, 300e-6]), bit_rate=st.sampled_from([500_000, 2_000_000]))  # fmt: skip
def test_history_bench_clock_never_goes_back_and_run_n_runs_n_cycles(
    steps: list[tuple[str, int]], firmware: type[Firmware] | None, others: int, cycle_time: float | None,
    bit_rate: int,
) -> None:  # fmt: skip
    """Over any history of runs, timed runs, bus-time steps, master outputs, ring faults (bit flips, dead lines,
    truncations), fault clearing, Alarm Stops and firmware writes: the clock and the ring's never go back,
    ``run(n)`` finishes exactly ``n`` master cycles (MCU-55, FW-19) after the one a timed run left under way (MCU-76),
    ``run_for(s)`` moves the clock at least ``s`` and finishes a cycle if ``s`` is 2 ms or more (a run's hold has
    ended),
    cycles start in order, and the master goes on once the faults are cleared (not stuck)."""
    bench = Bench(firmware=None if firmware is None else firmware(), bit_rate=bit_rate, cycle_time_s=cycle_time,
                  others=[PlainDevice(0x02, 1) for _ in range(others)], strict=False)  # fmt: skip
    bench.power_up()
    if firmware is None:
        bench.driver.initialize(Mode.MOTOROLA)
        bench.driver.configure(0x83, 0x01)
    positions = 2 + others
    for action, value in steps:
        now, cycles, ring_now = bench.now, bench.cycles, bench.ring.now
        if action == "run":
            under_way = bench.under_way  # MCU-76: a cycle a run_for or an advance left under way ends first
            bench.run(value % 5)
            assert bench.cycles == cycles + under_way + value % 5
        elif action == "run_for":  # up to 4 ms: at least one whole cycle from 2 ms on (the master is not held)
            bench.run_for(value % 4000 * 1e-6)
            assert bench.now >= now + value % 4000 * 1e-6
            assert bench.cycles > cycles or value % 4000 < 2000
        elif action == "out" and bench.master.config and bench.master.entry(1).data_bytes == 2:
            bench.master.set_outputs(1, put_u16(value))
        elif action == "flip":
            bench.ring.inject(BitFlip(1 + value % positions, value % 40, 1 + value % 3))
        elif action == "dead":
            bench.ring.inject(DeadLine(1 + value % positions, 1 + value % 3))
        elif action == "trunc":
            bench.ring.inject(Truncate(1 + value % positions, value % 3, 1 + value % 2))
        elif action == "clear":
            bench.ring.clear_faults()
        elif action == "reset":
            bench.master.alarm_stop()
        elif action == "in":
            bench.driver.write(IN0, value & 0xFF)
        elif action == "advance":
            bench.advance(bench.now + value % 500 * 1e-6)
        assert bench.now >= now
        assert bench.ring.now >= ring_now
        assert bench.cycles >= cycles
        starts = [timing.start for timing in bench.timeline]
        assert starts == sorted(starts)
    bench.ring.clear_faults()
    cycles, under_way = bench.cycles, bench.under_way
    bench.run(4)
    assert bench.cycles == cycles + under_way + 4


DRIVER_STEPS = st.lists(st.tuples(st.sampled_from(["id", "in", "exchange", "block", "irq", "poll", "sas", "run",
                                                   "run_for", "bad_byte", "bad_register", "bad_block", "bad_mask",
                                                   "bad_mode"]), st.integers(0, 0xFF)),
                        min_size=1, max_size=30)  # fmt: skip

_REFUSED: dict[str, Callable[[Supi3Driver], object]] = {
    "bad_byte": lambda drv: drv.write(SET, 256),
    "bad_register": lambda drv: drv.read("ID"),  # type: ignore[arg-type]
    "bad_block": lambda drv: drv.block_transfer(b"\0" * 3),
    "bad_mask": lambda drv: drv.irq_enable(0x80),
    "bad_mode": lambda drv: drv.initialize("MOTOROLA"),  # type: ignore[arg-type]
}


@settings(max_examples=80, deadline=None)
@given(steps=DRIVER_STEPS, bit_rate=st.sampled_from([500_000, 2_000_000]), gap=st.sampled_from([0.0, 3.0]),
       mode=st.sampled_from(list(Mode)))  # fmt: skip
def test_history_driver_on_the_bench_leaves_the_chip_waiting_for_a_command(steps: list[tuple[str, int]],
                                                                           bit_rate: int, gap: float,
                                                                           mode: Mode) -> None:  # fmt: skip
    """Over any history of driver calls on the bench (register and block accesses, interrupt service, polls of the
    I/O window, SAS_INIT and a new initialization), calls the driver refuses, rule violations the strict chip raises
    (a data access in the latch phase) and bench runs between: after each call the chip waits for a command byte
    (C/D = 0, 3.4.3), the driver is initialized and reads back the ID it last wrote (FW-16: nothing half sent), in
    either interface type."""
    bench = Bench(bit_rate=bit_rate, frame_gap_us=gap, mode=mode)
    drv = bench.driver
    drv.initialize(mode)
    drv.configure(0x83, 0x01)
    drv.irq_enable(Irq.VALID)
    bench.run(3)
    id_code = 0x01
    for action, value in steps:
        try:
            if action == "id":  # during bus operation a ReconfigurationError, the write taken (UP-36)
                id_code = value
                drv.write(ID, value)
            elif action == "in":
                drv.write(IN0, value)
            elif action == "exchange":
                drv.exchange(IN0, value)
            elif action == "block":
                drv.block_transfer(bytes([value, value ^ 0xFF]))
            elif action == "irq":
                drv.irq_service()
            elif action == "poll":
                drv.poll_io_window(1 + value % 4)
            elif action == "sas":
                drv.sas_init()
                drv.initialize(mode)
            elif action == "run":
                bench.run(value % 3)
            elif action == "run_for":
                bench.run_for(value * 2e-6)
            else:
                with pytest.raises(DriverArgumentError):
                    _REFUSED[action](drv)
        except TransportError:
            raise
        except (DriverError, Supi3Error):  # a poll that timed out, a data access in the latch phase, no exchange in
            # Intel mode
            pass
        assert bench.transport.read_cd() == 0
        assert drv.initialized
        assert drv.read(ID) == id_code


# ---------------------------------------------------------------------------------------------------------------
# The Python driver's transports (supi3.sdk.driver, supi3.sdk.transports, supi3.sdk.pins)
# ---------------------------------------------------------------------------------------------------------------


class _Answers(Transport):
    """A board whose SPI controller answers ``rx`` to every frame and whose pins read ``level``."""

    def __init__(self, rx: object, level: object = 0) -> None:
        self.rx = rx
        self.level = level

    def xfer(self, tx: int, s_r: bool) -> int:
        del tx, s_r
        return self.rx  # type: ignore[return-value]

    def read_cd(self) -> int | None:
        return self.level  # type: ignore[return-value]

    def read_irq(self) -> int | None:
        return self.level  # type: ignore[return-value]

    def read_io(self) -> int | None:
        return self.level  # type: ignore[return-value]


@pytest.mark.parametrize("rx", [0x100, -1, None, "A", 1.0, True])
def test_driver_refuses_a_transport_answer_that_is_no_byte(rx: object) -> None:
    """Defect: the driver handed whatever ``Transport.xfer`` returned back as the register's value (300, None,
    'A'); a frame reads one byte (FW-26: FFh when undriven). Now a :class:`TransportError` naming the value, and the
    driver forgets its initialization as for any transport failure."""
    drv = Supi3Driver(_Answers(0x00))
    drv.initialize(Mode.MOTOROLA)
    drv.transport.rx = rx  # type: ignore[attr-defined]
    with pytest.raises(TransportError, match=r"xfer returned .*, not a byte 0 to 255 \(FW-26"):
        drv.read(SET)
    assert not drv.initialized


@pytest.mark.parametrize("level", [2, -1, "0", 0.5])
@pytest.mark.parametrize("call", ["initialize", "irq_service", "poll_io_window"])
def test_driver_refuses_a_pin_level_that_is_no_level(level: object, call: str) -> None:
    """Defect: the driver took any truthy pin reading as 1 ('0', 2, 0.5): a C/D that read '0' said "data expected"
    and ``initialize`` blamed the chip (NotReadyError); an /IRQ of 2 read as high. A pin reads 0, 1 or None (not
    wired): anything else is a :class:`TransportError` naming the pin and the value."""
    drv = Supi3Driver(_Answers(0x00))
    if call != "initialize":
        drv.initialize(Mode.MOTOROLA)
    drv.transport.level = level  # type: ignore[attr-defined]
    calls: dict[str, Callable[[], object]] = {"initialize": lambda: drv.initialize(Mode.MOTOROLA),
                                              "irq_service": drv.irq_service,
                                              "poll_io_window": lambda: drv.poll_io_window(2)}  # fmt: skip
    with pytest.raises(TransportError, match=r"read_(cd|irq|io) returned .*, not 0, 1 or None"):
        calls[call]()


class _FakeSpidev:
    """A stand-in for the ``spidev`` module: one device that answers ``rx``."""

    rx = 0x00

    class SpiDev:
        def open(self, bus: int, device: int) -> None:
            del bus, device

        def xfer(self, data: list[int]) -> list[int]:
            return [_FakeSpidev.rx for _ in data]

        def close(self) -> None:
            pass


def _spidev(**pins: object) -> SpidevTransport:
    return SpidevTransport(0, 0, spidev_module=_FakeSpidev, **pins)  # type: ignore[arg-type]


BAD_SPIDEV: list[tuple[str, Callable[[], object], str]] = [
    ("delay -1", lambda: _spidev().delay_us(-1), r"us must be a finite number >= 0.0, not -1"),
    ("delay NaN", lambda: _spidev().delay_us(math.nan), r"us must be a finite number >= 0.0, not nan"),
    ("delay str", lambda: _spidev().delay_us("5"), r"us must be a finite number >= 0.0, not '5'"),  # type: ignore[arg-type]
    ("tx 256", lambda: _spidev().xfer(256, True), r"tx must be an integer from 0 to 255 \(one byte"),
    ("tx str", lambda: _spidev().xfer("A", True), r"tx must be an integer from 0 to 255"),  # type: ignore[arg-type]
    ("sas 5", lambda: _spidev(set_sas_init=print).set_sas_init(5),
     r"level must be an integer from 0 to 1, not 5"),
    ("sas True", lambda: _spidev(set_sas_init=print).set_sas_init(True),
     r"level must be an integer from 0 to 1, not True"),
    ("speed 7 MHz", lambda: _spidev(speed_hz=7_000_000), r"speed_hz must be an integer from 1 to 5988023 \(Table 3-7"),
]


@pytest.mark.parametrize(("case", "call", "match"), BAD_SPIDEV, ids=[case for case, _, _ in BAD_SPIDEV])
def test_spidev_transport_refuses_by_name(case: str, call: Callable[[], object], match: str) -> None:
    """Defect: ``SpidevTransport`` passed a negative, NaN or text delay to ``time.sleep`` (a ValueError or TypeError
    traceback), a level 5 to the SAS_INIT GPIO, a ``tx`` of 256 to the controller, and took an SCLK no Table 3-7
    row allows (at most 6 MHz, t0 at 2 Mbit/s: the chip misreads every byte). ``ModelTransport`` already refused a
    SAS_INIT level that is not 0 or 1."""
    del case
    with pytest.raises(ArgumentError, match=match):
        call()


@pytest.mark.parametrize("level", ["x", 2, 0.5])
def test_spidev_transport_pin_reading_no_level_is_a_transport_error(level: object) -> None:
    """Defect: a GPIO callable that read 'x' raised ``int('x')``'s ValueError through the driver (which passes any
    other exception unchanged); 2 passed as a level. Now a :class:`TransportError` naming the pin."""
    transport = _spidev(read_cd=lambda: level)
    with pytest.raises(TransportError, match=r"read_cd returned .*, not 0, 1 or None"):
        transport.read_cd()


def test_spidev_transport_answer_past_a_byte_is_a_transport_error() -> None:
    """Defect: an answer of 999 from the controller came back as the register's value."""
    transport = _spidev()
    _FakeSpidev.rx = 999
    try:
        with pytest.raises(TransportError, match=r"xfer returned 999, not a byte 0 to 255"):
            Supi3Driver(transport).initialize(Mode.MOTOROLA)
    finally:
        _FakeSpidev.rx = 0x00


@pytest.mark.parametrize("level", ["x", 2, -1, True])
def test_pin_transport_set_sas_init_refuses_what_is_no_level(level: object) -> None:
    """Defect: ``PinTransport.set_sas_init`` pulsed SAS_INIT for any truthy level ('x', -1, 2), as
    ``ModelTransport`` refuses by name."""
    transport = PinTransport(Supi3Chip(default_config()), Mode.MOTOROLA)
    cycle = transport.port.cycle
    with pytest.raises(ArgumentError, match=r"level must be an integer from 0 to 1"):
        transport.set_sas_init(level)  # type: ignore[arg-type]
    assert transport.port.cycle == cycle  # no pulse


@pytest.mark.parametrize("us", [math.nan, -1.0, "1"])
def test_model_transport_delay_refuses_what_is_no_time(us: object) -> None:
    """Defect: the bare model's ``delay_us`` (the base class's: no time passes) took NaN, -1 and '1' silently,
    where the bench's transport refuses them: a test that ran on the bare model broke on the bench."""
    transport = ModelTransport(Supi3(default_config()))
    with pytest.raises(ArgumentError, match=r"us must be a finite number >= 0.0"):
        transport.delay_us(us)  # type: ignore[arg-type]


# ---------------------------------------------------------------------------------------------------------------
# The firmware build (supi3.mcu.build)
# ---------------------------------------------------------------------------------------------------------------


@pytest.fixture
def source(tmp_path: Path) -> Path:
    path = tmp_path / "fw.c"
    path.write_text("void fw_setup(void) {}\n")
    return path


BAD_BUILD: list[tuple[str, dict[str, object], str]] = [
    ("defines list", {"defines": [("A", "1")]}, r"defines must be a mapping of C identifiers to one-line str values"),
    ("defines str", {"defines": "A=1"}, r"defines must be a mapping"),
    ("define newline", {"defines": {"A": "1\n#error x"}}, r"defines must be a mapping .* one-line"),
    ("include int", {"include_dirs": [5]}, r"include_dirs must be an iterable of existing folder paths"),
    ("include missing", {"include_dirs": ["/no/such/folder"]}, r"include_dirs must be .*existing folder"),
    ("include file", {"include_dirs": [__file__]}, r"include_dirs must be .*existing folder"),
    ("compiler_rt str", {"compiler_rt": "no"}, r"compiler_rt must be True or False, not 'no'"),
    ("port int", {"port": 0}, r"port must be True or False, not 0"),
]


@pytest.mark.parametrize(("case", "options", "match"), BAD_BUILD, ids=[case for case, _, _ in BAD_BUILD])
def test_build_command_refuses_by_name(source: Path, tmp_path: Path, case: str, options: dict[str, object],
                                       match: str) -> None:  # fmt: skip
    """Defect: ``build``/``build_command`` raised AttributeError for ``defines`` that are no mapping, TypeError
    for an include folder 5, passed a folder that does not exist to the compiler (silently ignored), took ``'no'``
    as ``compiler_rt=True`` and 0 as ``port=False``, and ran the compiler on a define with a newline (refused only
    by -Werror, as "the firmware does not build")."""
    del case
    with pytest.raises(ArgumentError, match=match):
        mcu_build.build_command([source], tmp_path / "fw.elf", **options)  # type: ignore[arg-type]


@pytest.mark.parametrize("where", ["missing folder", "a folder", "empty"])
def test_build_refuses_an_output_it_cannot_write_before_the_compiler(source: Path, tmp_path: Path,
                                                                     where: str) -> None:  # fmt: skip
    """Defect: ``build`` ran the compiler on an output in a folder that does not exist, on a folder or on '' and
    then blamed the firmware ("the firmware does not build": a BuildError); the CLI refuses these up front."""
    output = {"missing folder": tmp_path / "no" / "fw.elf", "a folder": tmp_path, "empty": ""}[where]
    with pytest.raises(ArgumentError, match=r"output must be a path of the ELF file to write"):
        mcu_build.build_command([source], output)  # type: ignore[arg-type]


# ---------------------------------------------------------------------------------------------------------------
# The register map's layouts (supi3.regmap.core)
# ---------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("byte", [0x100, -1, "1", 1.0, True])
def test_field_extract_and_insert_refuse_what_is_no_byte(byte: object) -> None:
    """Defect: ``Field.extract`` and ``Field.insert`` masked a byte of 0x100 or -1 silently (a 9-bit value read as
    its field) and raised TypeError for '1'; ``ByteLayout.decode`` refused them by name."""
    field = SET.base_fields[0]
    with pytest.raises(RegisterMapError, match=r"is not a byte|must be an integer"):
        field.extract(byte)  # type: ignore[arg-type]
    with pytest.raises(RegisterMapError, match=r"is not a byte|must be an integer"):
        field.insert(byte, 0)  # type: ignore[arg-type]


def test_register_map_port_names_the_direction_not_the_address() -> None:
    """Defect: ``RegisterMap.port(3, 'sideways')`` said "address 3 is outside the 16-byte area": the address is
    fine, the direction is not one."""
    with pytest.raises(RegisterMapError, match=r"direction must be one of write, read, not 'sideways'"):
        REGISTER_MAP.port(3, "sideways")  # type: ignore[arg-type]
    with pytest.raises(RegisterMapError, match=r"address 16 is outside the 16-byte area"):
        REGISTER_MAP.port(16, AccessDirection.READ)
    assert REGISTER_MAP.port(12, AccessDirection.WRITE).register is ID


@pytest.mark.parametrize("reset", ["power", None, 1])
def test_register_map_cleared_by_refuses_what_is_no_reset(reset: object) -> None:
    """Defect: ``RegisterMap.cleared_by('power')`` answered () (no register cleared) instead of naming the bad
    reset: a test asking which registers a reset clears passed for a typo."""
    with pytest.raises(RegisterMapError, match=r"reset must be one of power-up, .*, not"):
        REGISTER_MAP.cleared_by(reset)  # type: ignore[arg-type]
    assert REGISTER_MAP.cleared_by(Reset.POWER_UP)


# ---------------------------------------------------------------------------------------------------------------
# The emulated board's runs (supi3.mcu.board.Board)
# ---------------------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def digital_io(tmp_path_factory: pytest.TempPathFactory) -> Path:
    missing = mcu_build.toolchain_missing()
    if missing is not None:
        pytest.skip(missing)
    from supi3.sdk import native

    return mcu_build.build(native.example("digital_io"), tmp_path_factory.mktemp("hostile13") / "digital_io.elf")


@pytest.mark.parametrize("fidelity", ["transaction", "pin"])
@pytest.mark.parametrize("call", ["run_for", "run"])
def test_board_runs_past_the_bus_time_maximum_are_refused_not_run_for_ever(digital_io: Path, fidelity: str,
                                                                          call: str) -> None:  # fmt: skip
    """Defect: ``Board.run_for(1e30)`` and ``Board.run(2**60)`` checked only the type and sign: they ran the core
    and the bus for ever (A26 bounds bus time; the firmware bench's ``run`` refuses so many cycles)."""
    from supi3.mcu.board import Board

    board = Board(digital_io, fidelity=fidelity)
    runs: dict[str, Callable[[], None]] = {"run_for": lambda: board.run_for(1e30), "run": lambda: board.run(2**60)}
    run = runs[call]
    with pytest.raises(ArgumentError, match=r"(seconds|cycles) .* past 1048576 s \(A26"):
        run()
    assert board.cycles == 0


# ---------------------------------------------------------------------------------------------------------------
# The pytest plugin (supi3.sdk.pytest_plugin)
# ---------------------------------------------------------------------------------------------------------------

MARKERS_TEST = """
import pytest

pytestmark = pytest.mark.supi3(cycle_time_s=300e-6)


@pytest.mark.supi3(bit_rate=2_000_000, strict=True)
class TestAtTwoMegabit:
    @pytest.mark.supi3(strict=False)
    def test_the_class_and_module_markers_still_count(self, supi3_bench):
        assert supi3_bench.config.bit_rate == 2_000_000
        assert supi3_bench.cycle_time_s == 300e-6
        assert supi3_bench.registers.violations.strict is False


@pytest.mark.supi3(3)
class TestPositional:
    @pytest.mark.supi3(strict=False)
    def test_a_class_marker_s_positional_argument_is_refused(self, supi3_bench):
        pass
"""


def test_plugin_markers_of_test_class_and_module_add_up(pytester: pytest.Pytester) -> None:
    """Defect: ``supi3_bench`` read the closest ``supi3`` marker only: a test's ``strict=False`` silently dropped its
    class's ``bit_rate=2_000_000`` and its module's cycle time (the test ran at 500 kbit/s, back to back); a class
    marker's positional argument went unchecked. Now the markers add up, the closest keyword winning (UP-46)."""
    pytester.makepyfile(test_markers=MARKERS_TEST)
    result = pytester.runpytest("--strict-markers", "-p", "no:cacheprovider")
    result.assert_outcomes(passed=1, errors=1)
    result.stdout.fnmatch_lines(["*keyword arguments of Bench only*not (3,)*"])


class _Nested(DigitalIo):
    """A firmware whose ``where`` (setup, isr or loop) runs the bench it runs on."""

    def __init__(self, where: str, call: str) -> None:
        super().__init__()
        self.where, self.call = where, call
        self.bench: Bench | None = None
        self.refused: list[str] = []

    def _nest(self, where: str) -> None:
        if where == self.where and self.bench is not None:
            try:
                self.bench.run(1) if self.call == "run" else self.bench.run_for(1e-4)
            except Supi3Error as error:
                self.refused.append(str(error))

    def setup(self, drv: Supi3Driver) -> None:
        super().setup(drv)
        self._nest("setup")

    def isr(self, drv: Supi3Driver) -> None:
        super().isr(drv)
        self._nest("isr")

    def loop(self, drv: Supi3Driver) -> None:
        drv.transport.delay_us(20)
        self._nest("loop")


@pytest.mark.parametrize("call", ["run", "run_for"])
@pytest.mark.parametrize("where", ["setup", "isr", "loop"])
def test_bench_run_from_inside_the_firmware_is_refused(where: str, call: str) -> None:
    """Defect: a firmware's service routine that called ``bench.run(1)`` nested a run in the run: the inner run's
    hold and resume cut the outer one's (``run(3)`` and the inner ``run(1)`` made 3 cycles in all, FW-19), and a
    main loop that called ``bench.run_for`` recursed until RecursionError. The bench runs the firmware; the firmware
    does not run the bench: a :class:`BenchError` naming the call and the firmware's method, and the outer run
    still runs exactly its cycles."""
    firmware = _Nested(where, call)
    bench = Bench(firmware=firmware)
    firmware.bench = bench
    bench.run(3)
    assert bench.cycles == 3
    assert firmware.refused
    assert all(f"Bench.{call}() called from the firmware's {where}()" in text for text in firmware.refused)


def test_cli_firmware_build_names_a_define_with_a_line_break(source: Path, tmp_path: Path,
                                                             capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    """Defect: ``supi3 firmware build -D 'A=1<newline>#error x'`` ran the compiler, whose -Werror refused the macro
    ("the firmware does not build"); now the -D option is named before any work, one line, exit status 2."""
    from supi3 import cli

    assert cli.main(["firmware", "build", str(source), "-o", str(tmp_path / "fw.elf"), "-D", "A=1\n#error x"]) == 2
    err = capsys.readouterr().err
    assert "-D must be NAME or NAME=VALUE with a C identifier NAME and a one-line VALUE" in err
    assert not (tmp_path / "fw.elf").exists()


def test_run_firmware_refuses_a_firmware_that_is_no_path(digital_io: Path) -> None:
    """Defect: ``run_firmware(FirmwareImage.load(...))`` (the ``Board`` takes an image) ran the whole power-up, then
    raised ``Path(image)``'s TypeError building the report; now an ArgumentError naming ``firmware`` first."""
    from supi3.mcu.core import FirmwareImage
    from supi3.mcu.session import run_firmware

    with pytest.raises(ArgumentError, match=r"firmware must be a path of an ELF file \(str or os.PathLike\), not "):
        run_firmware(FirmwareImage.load(digital_io))  # type: ignore[arg-type]


def test_fw_board_inputs_refuse_more_than_the_terminals(digital_io: Path) -> None:
    """Defect: ``board.fw_board.inputs = 5 bytes`` wrote the first four and dropped the fifth without a word (the
    firmware's ``inputs[FW_DATA_BYTES]`` holds 4); now an ArgumentError, the terminals unchanged."""
    from supi3.mcu.board import Board

    board = Board(digital_io)
    fw_board = board.fw_board
    assert fw_board is not None
    fw_board.inputs = b"\x12\x34"
    with pytest.raises(ArgumentError, match=r"inputs must be at most 4 bytes"):
        fw_board.inputs = b"\x01\x02\x03\x04\x05"
    assert fw_board.inputs == b"\x12\x34\x00\x00"


def test_bench_timing_rules_refuse_what_is_no_bus_time() -> None:
    """Defect: ``MasterStart.due(nan)`` and ``ServeWait.over(nan)`` answered False (a master that never starts, a
    wait that never ends), ``CycleTiming.at('3')`` raised TypeError and ``at(-1)`` gave a time before the cycle."""
    start, wait = MasterStart(), ServeWait(500_000)
    wait.begin(1e-3)
    with pytest.raises(ArgumentError, match=r"now must be a number >= 0.0, not nan"):
        start.due(math.nan)
    with pytest.raises(ArgumentError, match=r"now must be a number >= 0.0, not nan"):
        wait.over(math.nan)
    assert start.due(START_WAIT_S) and not wait.over(0.0) and wait.over(math.inf)
    bench = Bench()
    bench.run(1)
    timing = bench.timeline[0]
    for bit in ("3", -1, 1.0):
        with pytest.raises(ArgumentError, match=r"bit must be an integer >= 0"):
            timing.at(bit)  # type: ignore[arg-type]
    assert timing.at(0) > timing.start


@pytest.mark.parametrize("fidelity", ["transaction", "pin"])
def test_a_bit_rate_beside_a_config_of_another_rate_is_refused_not_ignored(digital_io: Path, fidelity: str) -> None:
    """Defect (found by this round, fixed by the lead): ``Bench(config=<2 Mbit/s>, bit_rate=500_000)`` and the same on
    ``Board`` ran at the config's rate and dropped ``bit_rate`` in silence. The config's CLK_CONF straps the rate
    (Table 1-7): a second, different rate is refused by name; the same rate, or either alone, is taken."""
    from supi3.mcu.board import Board

    fast = default_config(2_000_000)
    with pytest.raises(DriverArgumentError, match=r"bit_rate 500000 is not the config's 2000000 bit/s"):
        Bench(config=fast, bit_rate=500_000)
    with pytest.raises(DriverArgumentError, match=r"bit_rate 500000 is not the config's 2000000 bit/s"):
        Board(digital_io, config=fast, bit_rate=500_000, fidelity=fidelity)
    assert Bench(config=fast, bit_rate=2_000_000).config.bit_rate == 2_000_000
    assert Bench(config=fast).config.bit_rate == 2_000_000
    assert Bench(bit_rate=2_000_000).config.bit_rate == 2_000_000
    assert Bench().config.bit_rate == 500_000
    assert Board(digital_io, config=fast, fidelity=fidelity).config.bit_rate == 2_000_000
    assert Board(digital_io, fidelity=fidelity).config.bit_rate == 500_000


@pytest.mark.parametrize(("name", "make"), [
    ("frame_gap_us", lambda bench: Supi3Driver(bench.transport, frame_gap_us=2.0**32)),
    ("max_polls", lambda bench: bench.driver.poll_io_window(2**32)),
])  # fmt: skip
def test_driver_ranges_are_the_c_drivers(name: str, make: Callable[[Bench], object]) -> None:
    """Defect (found by this round, fixed by the lead): the Python driver took any ``frame_gap_us`` and ``max_polls``
    where the C driver's are ``uint32_t`` (``supi3.h``): one API shape, one range; past it is refused by name,
    nothing sent."""
    bench = Bench()
    with pytest.raises(DriverArgumentError, match=rf"{name} must be .*4294967295"):
        make(bench)


def test_register_map_render_to_a_directory_is_refused_by_name(tmp_path: Path) -> None:
    """Defect (found by this round, fixed by the lead): ``render('md', out=<a directory>)`` rendered, then failed with
    Python's ``IsADirectoryError``; it is a ``RegisterMapError`` naming ``out`` before the render."""
    from supi3.regmap.export import render

    with pytest.raises(RegisterMapError, match=r"format 'md' writes a file: out .* is a directory"):
        render("md", out=tmp_path)


def test_pin_transport_delay_past_the_bus_time_maximum_is_refused_by_name() -> None:
    """Defect (found by this round, fixed by the lead): ``PinTransport.delay_us(1e30)`` failed in numpy (a clock
    count past int64); a delay past the bus time's maximum (A26) is refused by name, no clock run."""
    transport = PinTransport(Supi3Chip(default_config()), Mode.MOTOROLA)
    cycle = transport.port.cycle
    with pytest.raises(ArgumentError, match=r"us must be a finite number from 0"):
        transport.delay_us(1e30)
    assert transport.port.cycle == cycle

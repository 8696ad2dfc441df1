"""The transaction-level chip (Supi3) and its register file as a hostile user calls them (issue #8, parts 5 and 7):
every public entry with wrong types, ranges and call orders gets the project's named error ("X must be ..., not
...") and changes nothing; an inconsistent-data violation (3.4.14) names the clock and the time of the access."""

from __future__ import annotations

import copy
import math
import pickle
from collections.abc import Callable

import pytest

from supi3.config import decode
from supi3.errors import ArgumentError
from supi3.interbus.wire import Cycle
from supi3.model.chip import ChipArgumentError, ChipError, Supi3, VoltageMonitor, clocks
from supi3.model.registers import (
    InconsistentDataError,
    RegisterArgumentError,
    RegisterFile,
    RegisterFileError,
)
from supi3.regmap import IN1, OUT0, REGISTER_MAP, SET
from supi3.spi.master import SoftMaster
from supi3.spi.slave_pins import SlavePins
from supi3.spi.upif import Mode, UpInterface
from supi3.tables import CLOCK_HZ
from supi3.top import Supi3Chip
from support import fields

RB_UP = decode("10011", "1110")  # RB, Init-µP
RB_IO = decode("10000")  # RB, 8 IN/8 OUT: one byte each way (the demo device)
DATA, ID = Cycle.DATA, Cycle.ID
SET_2_WORDS = 0x85


# ------------------------------------------------------------------------------------------------------------
# Part 7: InconsistentDataError names the clock and the time
# ------------------------------------------------------------------------------------------------------------


def test_inconsistent_data_names_the_transaction_level_time() -> None:
    """3.4.14: the access overlapped the latch phase. Today the error gives neither clock nor time."""
    chip = Supi3(RB_UP, strict=False)
    up = UpInterface(chip)
    assert up.initialize(Mode.MOTOROLA)
    up.write(SET, SET_2_WORDS)
    chip.poll(0.0123)
    chip.set_latch_phase(True)
    up.read(OUT0)
    [violation] = chip.registers.violations.records  # type: ignore[union-attr]
    assert isinstance(violation, InconsistentDataError)
    assert violation.clock == clocks(0.0123) == 393_600
    assert violation.time_s == pytest.approx(0.0123)
    assert str(violation) == ("inconsistent data: OUT0 read during the latch phase at clock 393600 (t = 0.0123 s) "
                              "(3.4.14)")
    strict = Supi3(RB_UP)
    fw = UpInterface(strict)
    assert fw.initialize(Mode.INTEL)
    strict.load(DATA, 2e-3)
    strict.set_latch_phase(True)
    with pytest.raises(InconsistentDataError, match=r"IN1 write during the latch phase at clock 64000 \(t = 0.002 s\)"):
        fw.write(IN1, 7)
    assert fw.registers.value("IN1") == 7  # the access still happened (UP-19)


def test_inconsistent_data_names_the_pin_level_cycle() -> None:
    """At pin level the clock is the cycle at which the chip reads the register (/SS falling, UP-18), when the
    register file is given the pin model's cycle counter as its clock."""
    registers = RegisterFile(RB_UP, strict=False)
    pins = SlavePins(registers)
    registers.use_clock(lambda: pins.cycle)
    master = SoftMaster(pins, Mode.MOTOROLA, record=False)
    master.byte(Mode.MOTOROLA.init_byte)
    master.byte(0x4D)
    master.byte(SET_2_WORDS)
    master.byte(0x80)  # read OUT0: the data byte follows
    registers.set_latch_phase(True)
    start = pins.cycle
    master.byte(0)
    master.byte(0)  # the data byte is processed when /SS rises, at the start of this byte's gap
    [violation] = registers.violations.records
    assert isinstance(violation, InconsistentDataError)
    assert violation.clock is not None and start <= violation.clock <= pins.cycle
    assert violation.time_s == violation.clock / CLOCK_HZ
    assert f"at clock {violation.clock} (t = " in str(violation)


def test_inconsistent_data_names_the_whole_chip_cycle() -> None:
    """The whole chip at pin level (Supi3Chip installs the core's cycle counter as the clock source; the µP
    interface ticks after the core's step, so the cycle being clocked is ``core.cycle - 1``): the violation names
    the exact clock edge of the read: the /SS fall's first cycle + 2, the second synchroniser flop (UP-13) and the
    read at /SS falling (UP-18)."""
    half, sclk, ss_n, mosi, mfp7 = 8, 1 << 4, 1 << 5, 1 << 6, 1 << 7
    idle = sclk | ss_n | mfp7
    whole = Supi3Chip(decode("10011", "1110", clk_conf="11"), strict=False)
    registers = whole.chip.registers
    assert registers is not None

    def tick(mfp: int) -> None:
        whole.step({"do1": 1, "di2": 0, "rbst_ext": 0, "mfp_in": mfp, "stat_err_n": 1, "resu_n": 1, "vmon_ok": 1,
                    "from_exr": 0})

    def spi(byte: int) -> int:
        """One Motorola byte; returns the first cycle with /SS low."""
        selected = idle & ~ss_n
        fall = whole.core.cycle
        for _ in range(half):
            tick(selected)
        for i in range(8):
            bit = mosi if (byte >> (7 - i)) & 1 else 0
            for _ in range(half):
                tick((selected & ~sclk & ~mosi) | bit)
            for _ in range(half):
                tick(selected | bit)
        for k in range(3 * half):  # SCLK high until /SS may rise, then the gap
            tick(idle if k >= half else selected)
        return fall

    for _ in range(300):
        tick(idle)
    for byte in (Mode.MOTOROLA.init_byte, 0x4D, SET_2_WORDS, 0x80):  # initialize, SET, then read OUT0
        spi(byte)
    whole.chip.set_latch_phase(True)
    fall = spi(0)
    [violation] = registers.violations.records
    assert isinstance(violation, InconsistentDataError)
    assert violation.clock == fall + 2
    assert violation.time_s == (fall + 2) / CLOCK_HZ


def test_inconsistent_data_without_a_clock_says_so_and_pickles() -> None:
    registers = RegisterFile(RB_UP, strict=False)
    registers.set_latch_phase(True)
    registers.cpu_read(2)
    [violation] = registers.violations.records
    assert isinstance(violation, InconsistentDataError)
    assert violation.clock is None and violation.time_s is None
    assert "at an unknown time (no clock source)" in str(violation)
    again = pickle.loads(pickle.dumps(InconsistentDataError("3.4.14", "inconsistent data: OUT0 read", 32)))
    assert (again.clock, again.time_s, str(again)) == (32, 1e-6, "inconsistent data: OUT0 read at clock 32 "
                                                                  "(t = 1e-06 s) (3.4.14)")


# ------------------------------------------------------------------------------------------------------------
# Part 5: the hostile table
# ------------------------------------------------------------------------------------------------------------


def chip_state(chip: Supi3) -> object:
    """Every attribute of the chip (copied) and of its register file; the µP modes' data path cache made fresh first,
    as any call that asks for the data length leaves it (tests/test_cycle_caches.py holds it to the configuration)."""
    if chip.registers is not None:
        chip._data_path()
    own = {k: copy.copy(v) for k, v in fields(chip).items() if k != "registers"}
    return own, None if chip.registers is None else registers_state(chip.registers)


def registers_state(registers: RegisterFile) -> object:
    return (tuple(registers.value(r.name) for r in REGISTER_MAP.registers), registers.configured,
            registers.latch_phase, registers.bus_running, registers.io_access, len(registers.violations.records))


def _up_chip() -> Supi3:
    chip = Supi3(RB_UP)
    assert chip.registers is not None
    chip.registers.cpu_write(13, SET_2_WORDS)
    return chip


C = ChipArgumentError
CHIP_SETUPS: dict[str, Callable[[], Supi3]] = {"io": lambda: Supi3(RB_IO), "up": _up_chip}
CHIP_HOSTILE: list[tuple[str, str, Callable[[Supi3], object], str]] = [
    ("set_io_access(1)", "io", lambda c: c.set_io_access(1), r"^busy must be True or False, not 1$"),  # type: ignore
    ("set_latch_phase(None)", "up", lambda c: c.set_latch_phase(None), r"^active must be True or False"),  # type: ignore
    ("set_mfp_inputs(10000h)", "io", lambda c: c.set_mfp_inputs(0x10000),
     r"^levels must be an integer from 0 to 65535 \(MFP\[15..0\]\), not 65536$"),
    ("set_mfp_inputs(-1)", "io", lambda c: c.set_mfp_inputs(-1), r"^levels must be"),
    ("set_mfp_inputs(1.0)", "io", lambda c: c.set_mfp_inputs(1.0), r"^levels must be .*, not 1\.0$"),  # type: ignore
    ("set_stat_err(1, 0)", "io", lambda c: c.set_stat_err(1, 0.0), r"^active must be True or False"),  # type: ignore
    ("set_stat_err(True, -1)", "io", lambda c: c.set_stat_err(True, -1.0), r"^now must be a finite number >= 0"),
    ("set_stat_err(True, nan)", "io", lambda c: c.set_stat_err(True, math.nan), r"^now must be .*, not nan$"),
    ("set_inputs(256)", "io", lambda c: c.set_inputs(256), r"^word must be an integer from 0 to 255 \(the IN data"),
    ("set_inputs('1')", "io", lambda c: c.set_inputs("1"), r"^word must be"),  # type: ignore
    ("poll(inf)", "io", lambda c: c.poll(math.inf),
     r"^now must be a finite number >= 0 \(bus time in seconds since power-up\), not inf$"),
    ("poll(nan)", "up", lambda c: c.poll(math.nan), r"^now must be a finite number"),
    ("poll('1')", "io", lambda c: c.poll("1"), r"^now must be .*, not '1'$"),  # type: ignore
    ("poll(True)", "io", lambda c: c.poll(True), r"^now must be .*, not True$"),
    ("reset(-1)", "up", lambda c: c.reset(-1.0), r"^now must be a finite number >= 0"),
    ("load(DATA, inf)", "io", lambda c: c.load(DATA, math.inf), r"^now must be"),
    ("load(DATA, -1)", "io", lambda c: c.load(DATA, -1.0), r"^now must be"),
    ("load('data', 0)", "io", lambda c: c.load("data", 0.0), r"^cycle must be Cycle.ID or Cycle.DATA, not 'data'$"),  # type: ignore
    ("load(DATA, '0')", "io", lambda c: c.load(DATA, "0"), r"^now must be"),  # type: ignore
    ("latch(DATA, 5 bytes)", "io", lambda c: c.latch(DATA, b"\x01" * 5, 1e-3),
     r"^received must be 1 byte \(the OUT data of the data cycle\), not b'\\x01"),
    ("latch(DATA, 5 bytes) up", "up", lambda c: c.latch(DATA, b"\x01" * 5, 1e-3), r"^received must be 4 bytes"),
    ("latch(DATA, 'x')", "io", lambda c: c.latch(DATA, "x", 1e-3), r"^received must be 1 byte"),  # type: ignore
    ("latch(DATA, b'', 0)", "io", lambda c: c.latch(DATA, b"", 0.0), r"^received must be 1 byte"),
    ("latch(DATA, True)", "io", lambda c: c.latch(DATA, b"\x01", True), r"^now must be .*, not True$"),
    ("latch(ID, 1 byte)", "up", lambda c: c.latch(ID, b"\x01", 1e-3),
     r"^received must be 2 bytes \(the command word of the id cycle\)"),
    ("latch(None, ...)", "io", lambda c: c.latch(None, b"\x01", 1e-3), r"^cycle must be Cycle.ID or Cycle.DATA"),  # type: ignore
    ("discard(DATA, 1, 0)", "io", lambda c: c.discard(DATA, 1, 0.0), r"^local_error must be True or False"),  # type: ignore
    ("discard(DATA, False, nan)", "up", lambda c: c.discard(DATA, False, math.nan), r"^now must be"),
    ("load_at(DATA, -1)", "io", lambda c: c.load_at(DATA, -1),
     r"^clk must be an integer >= 0 \(32 MHz clock periods since power-up\), not -1$"),
    ("load_at(DATA, 1.5)", "up", lambda c: c.load_at(DATA, 1.5), r"^clk must be"),  # type: ignore
    ("latch_at(DATA, b'', 0)", "io", lambda c: c.latch_at(DATA, b"", 0), r"^received must be 1 byte"),
    ("latch_at(DATA, bytearray)", "io", lambda c: c.latch_at(DATA, [1], 0), r"^received must be 1 byte"),  # type: ignore
    ("discard_at(ID, False, None)", "io", lambda c: c.discard_at(ID, False, None), r"^clk must be"),  # type: ignore
    ("reset_at(True)", "up", lambda c: c.reset_at(True), r"^clk must be .*, not True$"),
]


@pytest.mark.parametrize(("setup", "call", "message"), [row[1:] for row in CHIP_HOSTILE],
                         ids=[row[0] for row in CHIP_HOSTILE])
def test_chip_refuses_by_name_and_changes_nothing(setup: str, call: Callable[[Supi3], object], message: str) -> None:
    chip = CHIP_SETUPS[setup]()
    before = chip_state(chip)
    with pytest.raises(ChipArgumentError, match=message) as raised:
        call(chip)
    assert isinstance(raised.value, ArgumentError) and isinstance(raised.value, ChipError)
    assert chip_state(chip) == before


@pytest.mark.parametrize(("args", "message"), [
    (("10000",), r"^config must be a DeviceConfig \(supi3.config.decode\) or None, not '10000'$"),
    ((RB_IO, "yes"), r"^strict must be True or False, not 'yes'$"),
])
def test_chip_constructor_checks_its_arguments(args: tuple[object, ...], message: str) -> None:
    config, *rest = args
    with pytest.raises(ChipArgumentError, match=message):
        Supi3(config, strict=rest[0]) if rest else Supi3(config)  # type: ignore[arg-type]


@pytest.mark.parametrize("bad", ["5V", math.nan, None, True])
def test_voltage_monitor_checks_the_voltage(bad: object) -> None:
    monitor = VoltageMonitor()
    with pytest.raises(ChipArgumentError, match=r"^vcc must be a finite number \(the supply voltage in volts\)"):
        monitor.sense(bad)  # type: ignore[arg-type]
    assert monitor.ok is False


@pytest.mark.parametrize("bad", [math.inf, -math.inf, math.nan, -1.0, "0", None, True])
def test_clocks_refuses_what_has_no_clock_count(bad: object) -> None:
    with pytest.raises(ChipArgumentError, match=r"^now must be a finite number >= 0"):
        clocks(bad)  # type: ignore[arg-type]


def test_valid_values_of_other_types_still_pass() -> None:
    """The checks refuse wrong types, not valid numbers of another type: ints as seconds, numpy values."""
    np = pytest.importorskip("numpy")
    chip = Supi3(RB_IO)
    chip.poll(1)
    chip.set_mfp_inputs(np.uint16(3))
    assert chip.load(DATA, np.float64(0.5)) == chip.load(DATA, 0.5)
    chip.latch(DATA, bytearray(b"\x81"), 0.6)  # type: ignore[arg-type]
    assert chip.out_word == 0x81
    chip.set_io_access(np.bool_(True))
    assert chip.io_access is True


R = RegisterArgumentError
REGISTER_HOSTILE: list[tuple[str, Callable[[RegisterFile], object], str]] = [
    ("cpu_read(True)", lambda r: r.cpu_read(True),
     r"^address must be an integer from 0 to 15 \(A3..0, 3.4.7\), not True$"),
    ("cpu_read(16)", lambda r: r.cpu_read(16), r"^address must be an integer from 0 to 15"),
    ("cpu_read(4)", lambda r: r.cpu_read(4), r"^address must be a readable register, not 4: address 4 has no read"),
    ("cpu_read(15)", lambda r: r.cpu_read(15), r"^address must be a readable register, not 15"),
    ("cpu_write(0, 256)", lambda r: r.cpu_write(0, 256), r"^data byte must be an integer from 0 to 255 \(8 bits\)"),
    ("cpu_write(0, True)", lambda r: r.cpu_write(0, True), r"^data byte must be .*, not True$"),
    ("cpu_write(5, 0)", lambda r: r.cpu_write(5, 0), r"^address must be a writable register, not 5"),
    ("cpu_write(1.0, 0)", lambda r: r.cpu_write(1.0, 0), r"^address must be"),  # type: ignore[arg-type]
    ("set_latch_phase(1)", lambda r: r.set_latch_phase(1), r"^active must be True or False, not 1$"),  # type: ignore
    ("set_bus_running(None)", lambda r: r.set_bus_running(None), r"^running must be True or False"),  # type: ignore
    ("set_io_access('yes')", lambda r: r.set_io_access("yes"), r"^busy must be True or False"),  # type: ignore
    ("latch(5 bytes)", lambda r: r.latch(b"\x00" * 5),
     r"^out must be 4 bytes \(the OUT bytes of the cycle: latch needs 4 OUT bytes for 32 data bits, 3.4.8\)"),
    ("latch('abcd')", lambda r: r.latch("abcd"), r"^out must be 4 bytes .*, not 'abcd'$"),  # type: ignore[arg-type]
    ("latch([1, 2, 3, 4])", lambda r: r.latch([1, 2, 3, 4]), r"^out must be 4 bytes"),  # type: ignore[arg-type]
    ("event('valid')", lambda r: r.event("valid"), r"^source must be one of \[.*\] \(Table 3-13\), not 'valid'"),
    ("event(3)", lambda r: r.event(3), r"^source must be one of"),  # type: ignore[arg-type]
    ("processor_command(256)", lambda r: r.processor_command(256), r"^processor command must be .* \(3.4.9\), not 256"),
    ("processor_command(True)", lambda r: r.processor_command(True), r"^processor command must be"),
    ("set_optical('SET', 0)", lambda r: r.set_optical("SET", 0), r"^register must be one of .*: 'SET' is not an opt"),
    ("set_optical('POWER_IN', 70h)", lambda r: r.set_optical("POWER_IN", 0x70), r"^value must set only bits"),
    ("set_optical(.., 1.5)", lambda r: r.set_optical("LENGTH_OUT", 1.5), r"^value must be an integer"),  # type: ignore
    ("value('NOPE')", lambda r: r.value("NOPE"), r"^register must be a name of REGISTER_MAP .*, not 'NOPE'"),
    ("value(12)", lambda r: r.value(12), r"^register must be a name"),  # type: ignore[arg-type]
    ("use_clock(5)", lambda r: r.use_clock(5), r"^source must be a callable"),  # type: ignore[arg-type]
]


@pytest.mark.parametrize(("call", "message"), [row[1:] for row in REGISTER_HOSTILE],
                         ids=[row[0] for row in REGISTER_HOSTILE])
def test_register_file_refuses_by_name_and_changes_nothing(call: Callable[[RegisterFile], object],
                                                           message: str) -> None:
    registers = RegisterFile(RB_UP)
    registers.cpu_write(13, SET_2_WORDS)
    before = registers_state(registers)
    with pytest.raises(RegisterArgumentError, match=message) as raised:
        call(registers)
    assert isinstance(raised.value, ArgumentError) and isinstance(raised.value, RegisterFileError)
    assert registers_state(registers) == before


@pytest.mark.parametrize(("args", "kwargs", "message"), [
    (("10011",), {}, r"^config must be a DeviceConfig \(supi3.config.decode\), not '10011'$"),
    ((RB_UP,), {"strict": 1}, r"^strict must be True or False, not 1$"),
    ((RB_IO,), {}, r"^config must be an Init-µP mode \(Tables 2-4 to 2-7\), not 'RB, 8 IN/8 OUT': that is not a"),
])
def test_register_file_constructor_checks_its_arguments(args: tuple[object, ...], kwargs: dict[str, object],
                                                        message: str) -> None:
    with pytest.raises(RegisterArgumentError, match=message):
        RegisterFile(*args, **kwargs)  # type: ignore[arg-type]


def test_every_named_error_pickles_with_its_message_and_attributes() -> None:
    """Errors cross process boundaries (pytest-xdist, multiprocessing): each of these modules' errors survives."""
    from supi3.spi import upif

    errors: list[Exception] = [
        ChipArgumentError("now", math.inf, "now must be a finite number >= 0, not inf"),
        RegisterArgumentError("address", 16, "address must be an integer from 0 to 15, not 16"),
        upif.UpifArgumentError("mosi", 256, "mosi must be an integer from 0 to 255, not 256"),
        upif.NotInitializedError("read"),
        upif.InterfaceDisabledError("write"),
        upif.UninitializedAccessError("3.4.3", "interface not initialized: 4Dh taken as a faulty initialization byte"),
        upif.InterruptedCommandError("3.4.3", "initialize(): C/D = 1"),
        upif.ModeLockedError("3.4.3", "initialize(Mode.INTEL): already initialized in Motorola mode"),
        upif.ProtocolViolationError("3.4.2", "incomplete byte"),
        InconsistentDataError("3.4.14", "inconsistent data: IN0 write during the latch phase", 7),
    ]
    for error in errors:
        again = pickle.loads(pickle.dumps(error))
        assert type(again) is type(error) and str(again) == str(error) and vars(again) == vars(error)


def test_violation_log_checks_its_arguments() -> None:
    from supi3.model.registers import ViolationLog

    with pytest.raises(ArgumentError, match=r"^strict must be True or False, not 1$"):
        ViolationLog(1)  # type: ignore[arg-type]
    log = ViolationLog(strict=False)
    with pytest.raises(RegisterArgumentError, match=r"^violation must be an InterfaceViolationError, not 'late'$"):
        log.report("late")  # type: ignore[arg-type]
    assert log.records == []

"""The firmware interface after misuse (issue #8, parts 3 and 5): wrong arguments, wrong call orders and protocol
violations, tried as a hostile user would. A refused call sends nothing and changes nothing; a register access
that completes leaves the interface in a documented state (docs/upif.md "Firmware API after misuse", UP-25 to
UP-29); nothing ends in a bare builtin error, nor (under ``python -O``) in a silent ``None``."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest
from hypothesis import strategies as st
from hypothesis.stateful import RuleBasedStateMachine, initialize, invariant, rule

import supi3
from supi3.config import decode
from supi3.errors import ArgumentError
from supi3.model.chip import Supi3
from supi3.model.registers import InterfaceViolationError, RegisterFile
from supi3.regmap import ID, IN0, IRQ_EVT, OUT0, OUT1, REGISTER_MAP, SET
from supi3.spi.upif import (
    ACCESS_END_PHASES,
    C_D_COMMAND,
    InterfaceDisabledError,
    InterruptedCommandError,
    Mode,
    ModeLockedError,
    NotInitializedError,
    Phase,
    ProtocolViolationError,
    UninitializedAccessError,
    UpifArgumentError,
    UpifProtocol,
    UpifUsageError,
    UpInterface,
)

RB_UP = decode("10011", "1110")  # RB, Init-µP (Table 2-6)
SET_2_WORDS = 0x85  # /PCP = 1, CL = 101: 4 bytes (Table 3-12)
State = tuple[object, ...]


def chip(mode: Mode | None = None, *, strict: bool = True, set_value: int | None = SET_2_WORDS) -> UpInterface:
    up = UpInterface(RegisterFile(RB_UP, strict=strict))
    if mode is not None:
        assert up.initialize(mode)
        if set_value is not None:
            up.write(SET, set_value)
    return up


def state(up: UpInterface) -> State:
    """Everything a call could change: the protocol, the registers (without side effects) and the violation log."""
    p, r = up.protocol, up.registers
    return (p.mode, p.phase, p.command, p.last_rx, p._slots, p._frame,
            tuple(r.value(x.name) for x in REGISTER_MAP.registers), r.configured, r.latch_phase, r.bus_running,
            r.io_access, len(r.violations.records))


# ------------------------------------------------------------------------------------------------------------
# Before initialization (3.4.3)
# ------------------------------------------------------------------------------------------------------------

CALLS_THAT_RETURN_DATA: dict[str, Callable[[UpInterface], object]] = {
    "read": lambda up: up.read(0),
    "exchange": lambda up: up.exchange(0, 0x11),
    "block transfer": lambda up: up.block_transfer(b"\x00" * 4),
}


@pytest.mark.parametrize("strict", [True, False])
@pytest.mark.parametrize("what", list(CALLS_THAT_RETURN_DATA))
def test_access_that_returns_data_before_initialize_is_refused_by_name(what: str, strict: bool) -> None:
    """3.4.3: the chip expects its initialization byte first and drives nothing before it (3.4.1), so a read
    cannot complete: a named error says what to do, and nothing goes out (UP-25). Today: a bare assert."""
    up = chip(strict=strict)
    before = state(up)
    with pytest.raises(NotInitializedError, match=rf"^{what}: interface not initialized; call initialize\("):
        CALLS_THAT_RETURN_DATA[what](up)
    assert state(up) == before
    assert up.initialize(Mode.INTEL)  # the chip never saw a byte: still a first initialization


def test_refusals_hold_under_python_minus_o() -> None:
    """No API check is an ``assert``: under ``python -O`` read() before initialize() still raises by name."""
    code = (
        "from supi3.config import decode\n"
        "from supi3.model.registers import RegisterFile\n"
        "from supi3.spi.upif import UpInterface\n"
        "up = UpInterface(RegisterFile(decode('10011', '1110')))\n"
        "for call in (lambda: up.read(0), lambda: up.block_transfer(b''), lambda: up.read(True)):\n"
        "    try:\n"
        "        print(repr(call()))\n"
        "    except Exception as error:\n"
        "        print(type(error).__name__)\n"
    )
    source = Path(supi3.__file__).resolve().parents[1]  # the supi3 under test
    done = subprocess.run([sys.executable, "-O", "-c", code], capture_output=True, text=True, check=True,
                          env={"PYTHONPATH": str(source)})
    assert done.stdout.split() == ["NotInitializedError", "NotInitializedError", "UpifArgumentError"]


def test_write_before_initialize_is_reported_strict() -> None:
    """3.4.3: the command byte 4Dh is taken as a faulty initialization byte and the interface disables itself.
    That is the chip's behaviour and stays; strict mode raises the named violation after the bytes went out."""
    up = chip()
    with pytest.raises(UninitializedAccessError) as raised:
        up.write(SET, 0x82)
    assert str(raised.value) == ("interface not initialized: 4Dh taken as a faulty initialization byte; SAS_INIT "
                                 "needed (3.4.3)")
    assert isinstance(raised.value, ProtocolViolationError)
    assert up.protocol.phase is Phase.DISABLED
    assert up.registers.value("SET") == 0
    with pytest.raises(InterfaceDisabledError, match="SAS_INIT"):
        up.read(SET)
    with pytest.raises(InterfaceDisabledError, match="SAS_INIT"):
        up.write(SET, 0x82)
    up.sas_init()
    assert up.initialize(Mode.MOTOROLA)
    up.write(SET, 0x82)
    assert up.read(SET) == 0x82


def test_write_before_initialize_is_recorded_lenient() -> None:
    up = chip(strict=False)
    up.write(IN0, 0x12)
    [violation] = up.registers.violations.records
    assert isinstance(violation, UninitializedAccessError)
    assert violation.detail == "interface not initialized: 40h taken as a faulty initialization byte; SAS_INIT needed"
    assert up.protocol.phase is Phase.DISABLED
    assert up.registers.value("IN0") == 0


# ------------------------------------------------------------------------------------------------------------
# Mid-transaction errors
# ------------------------------------------------------------------------------------------------------------


def test_bad_value_is_refused_before_the_command_byte() -> None:
    """Today write(0, 300) sends 40h, then raises, and every later read() fails with "needs the command phase"."""
    up = chip(Mode.MOTOROLA)
    before = state(up)
    with pytest.raises(UpifArgumentError, match=r"^value must be an integer from 0 to 255 \(a data byte, 3\.4\.4\), "
                                                r"not 300$") as raised:
        up.write(0, 300)
    assert isinstance(raised.value, ArgumentError) and isinstance(raised.value, UpifUsageError)
    assert state(up) == before
    up.write(IN0, 0x12)
    assert up.registers.value("IN0") == 0x12
    assert up.read(IRQ_EVT) == 0


def test_strict_violation_inside_a_block_transfer_leaves_the_command_phase() -> None:
    """3.4.6: a block transfer below one word is reported; strict mode raises after the whole block, so the
    interface is ready for the next command (UP-28)."""
    up = chip(Mode.MOTOROLA, set_value=0x82)  # 1 byte
    with pytest.raises(ProtocolViolationError, match="1 word"):
        up.block_transfer(b"\x5a")
    assert up.c_d == C_D_COMMAND and up.protocol.phase is Phase.COMMAND
    assert up.registers.value("IN0") == 0x5A
    assert up.read(SET) == 0x82


def test_strict_inconsistent_read_completes_the_access() -> None:
    up = chip(Mode.INTEL)
    up.registers.set_latch_phase(True)
    with pytest.raises(InterfaceViolationError, match="latch phase"):
        up.read(OUT0)
    assert up.protocol.phase is Phase.COMMAND
    up.registers.set_latch_phase(False)
    assert up.read(OUT0) == 0


@pytest.mark.parametrize("mode", list(Mode))
def test_initialize_after_a_reset_in_the_middle_of_a_command_is_reported(mode: Mode) -> None:
    """3.4.3: a µP reset between command 4Dh and its data byte; re-running the init sequence sends the init byte,
    which the chip takes as the data byte: SET is overwritten. Today: silent, and initialize() returns True."""
    up = chip(mode, set_value=0x82)
    up.transfer(0x4D, s_r=True)  # write SET ... and the µP resets here
    with pytest.raises(InterruptedCommandError) as raised:
        up.initialize(mode)
    code = mode.init_byte
    assert raised.value.detail == (
        f"initialize(): C/D = 1 before the initialization byte, the µP was reset in the middle of a command: "
        f"{code:02X}h was taken as the data byte of command 4Dh, written to SET; SAS_INIT before initialize() after "
        "a µP reset")
    assert up.registers.value("SET") == code
    assert up.protocol.phase is Phase.COMMAND and up.protocol.mode is mode
    up.write(SET, 0x82)
    assert up.read(SET) == 0x82
    lenient = chip(mode, strict=False, set_value=0x82)
    lenient.transfer(0x4D, s_r=True)
    assert lenient.initialize(mode) is False  # not a first initialization: the chip was not reset
    assert [type(v) for v in lenient.registers.violations.records] == [InterruptedCommandError]


def test_initialize_in_the_middle_of_an_intel_read_raises_the_interruption_first() -> None:
    """The init byte goes out with S/R = 1 where the pending read wants S/R = 0 (Table 3-9, also reported): strict
    mode raises the interruption, the cause the firmware must fix."""
    up = chip(Mode.INTEL)
    up.transfer(0x8E, s_r=True)  # read the event register ... and the µP resets here
    with pytest.raises(InterruptedCommandError, match=r"81h was taken as the data byte of command 8Eh; SAS_INIT"):
        up.initialize(Mode.INTEL)
    assert [type(v) for v in up.registers.violations.records] == [InterruptedCommandError, ProtocolViolationError]
    assert up.protocol.phase is Phase.COMMAND


def test_initialize_in_the_middle_of_a_block_transfer_is_reported() -> None:
    up = chip(Mode.MOTOROLA, strict=False)
    up.transfer(0xCF)
    up.transfer(0x11)
    assert up.initialize(Mode.MOTOROLA) is False
    [violation] = up.registers.violations.records
    assert "00h was taken as the next byte of a block transfer" in violation.detail
    with pytest.raises(UpifUsageError, match=r"phase block, 2 block byte\(s\) left"):
        up.read(OUT0)
    up.transfer(0)
    up.transfer(0)
    assert up.read(OUT1) == 0


@pytest.mark.parametrize("mode", list(Mode))
def test_initialize_with_the_other_mode_is_reported(mode: Mode) -> None:
    """3.4.3: "Once this access mode has been set it can only be changed by a hardware reset or SAS_INIT". The
    chip takes the other mode's byte as a command; the firmware would now talk the wrong protocol."""
    other = Mode.INTEL if mode is Mode.MOTOROLA else Mode.MOTOROLA
    up = chip(mode, set_value=0x82)
    with pytest.raises(ModeLockedError) as raised:
        up.initialize(other)
    assert raised.value.detail == (
        f"initialize(Mode.{other.name}): the interface is already initialized in {mode.name.capitalize()} mode, "
        f"which only a power-up reset or SAS_INIT changes; {other.init_byte:02X}h was taken as a command")
    assert up.protocol.mode is mode and up.protocol.phase is Phase.COMMAND
    assert up.read(SET) == 0x82
    assert up.initialize(mode) is False  # the same mode again: no violation
    up.sas_init()
    assert up.initialize(other) is True
    lenient = chip(mode, strict=False)
    assert lenient.initialize(other) is False
    assert [type(v) for v in lenient.registers.violations.records] == [ModeLockedError]


def test_disabled_interface_refuses_initialize_without_sending() -> None:
    up = chip(strict=False)
    up.transfer(0x42)
    before = state(up)
    with pytest.raises(InterfaceDisabledError, match="disabled"):
        up.initialize(Mode.MOTOROLA)
    assert state(up) == before


# ------------------------------------------------------------------------------------------------------------
# Construction
# ------------------------------------------------------------------------------------------------------------


def test_interface_refuses_a_chip_without_a_microprocessor_mode() -> None:
    pin_strapped = Supi3(decode("10011", "0001"))
    assert pin_strapped.registers is None
    none = r"Init-µP mode .*, not None \(NoneType\): Supi3.registers is None outside"
    with pytest.raises(UpifArgumentError, match=none):
        UpInterface(pin_strapped.registers)  # type: ignore[arg-type]
    with pytest.raises(UpifArgumentError, match=rf"not a Supi3 in mode '{pin_strapped.config.function}' \(Table 2-6\)"):
        UpInterface(pin_strapped)
    with pytest.raises(UpifArgumentError, match=r"^registers must be .*, not 'RB'$"):
        UpInterface("RB")  # type: ignore[arg-type]
    with pytest.raises(UpifArgumentError, match="registers must be"):
        UpifProtocol(None)  # type: ignore[arg-type]
    up_chip = Supi3(RB_UP)
    up = UpInterface(up_chip)
    assert up.registers is up_chip.registers


# ------------------------------------------------------------------------------------------------------------
# The hostile table: every public entry with wrong types, ranges and call orders
# ------------------------------------------------------------------------------------------------------------

Setup = Callable[[], UpInterface]
SETUPS: dict[str, Setup] = {
    "fresh": lambda: chip(),
    "motorola": lambda: chip(Mode.MOTOROLA),
    "intel": lambda: chip(Mode.INTEL),
    "mid-command": lambda: _mid_command(),
    "disabled": lambda: _disabled(),
}


def _mid_command() -> UpInterface:
    up = chip(Mode.MOTOROLA)
    up.transfer(0x4C)
    return up


def _disabled() -> UpInterface:
    up = chip()
    up.transfer(0x42)
    return up


def _open_frame(up: UpInterface) -> UpifProtocol:
    up.protocol.begin(True)
    return up.protocol


A = UpifArgumentError
HOSTILE: list[tuple[str, str, Callable[[UpInterface], object], type[Exception], str]] = [
    # read / write / exchange: addresses 0..14 (A3..0; 15 is the block transfer), data bytes
    ("read(True)", "motorola", lambda up: up.read(True), A, r"^address must be an integer from 0 to 14 .*not True$"),
    ("read(-1)", "motorola", lambda up: up.read(-1), A, r"^address must be an integer from 0 to 14"),
    ("read(15)", "motorola", lambda up: up.read(15), A, r"15 starts a block transfer: use block_transfer\(\).*not 15"),
    ("read(1.0)", "motorola", lambda up: up.read(1.0), A, r"not 1\.0$"),  # type: ignore[arg-type]
    ("read('0')", "intel", lambda up: up.read("0"), A, r"not '0'$"),  # type: ignore[arg-type]
    ("read(None)", "intel", lambda up: up.read(None), A, r"not None \(NoneType\)$"),  # type: ignore[arg-type]
    ("write(0, 256)", "motorola", lambda up: up.write(0, 256), A, r"^value must be an integer from 0 to 255"),
    ("write(0, -1)", "intel", lambda up: up.write(0, -1), A, r"^value must be .*, not -1$"),
    ("write(0, True)", "motorola", lambda up: up.write(0, True), A, r"^value must be .*, not True$"),
    ("write(15, 0)", "motorola", lambda up: up.write(15, 0), A, r"^address must be"),
    ("write('13', 82h)", "motorola", lambda up: up.write("13", 0x82), A, r"^address must be"),  # type: ignore[arg-type]
    ("write(0, 1.0)", "intel", lambda up: up.write(0, 1.0), A, r"^value must be"),  # type: ignore[arg-type]
    ("write(0, 300) fresh", "fresh", lambda up: up.write(0, 300), A, r"^value must be"),
    ("exchange(0, 300)", "motorola", lambda up: up.exchange(0, 300), A, r"^value must be"),
    ("exchange(15, 0)", "motorola", lambda up: up.exchange(15, 0), A, r"^address must be"),
    ("exchange in Intel", "intel", lambda up: up.exchange(0, 0), UpifUsageError, r"needs Motorola mode \(3\.4\.4\)"),
    # block transfer: bytes of the block length (3.4.6), bool RD/WR
    ("block('abcd')", "motorola", lambda up: up.block_transfer("abcd"), A,  # type: ignore[arg-type]
     r"^in_data must be bytes, not 'abcd'$"),
    ("block(3 bytes)", "intel", lambda up: up.block_transfer(b"\x00" * 3), A,
     r"^in_data must be 4 bytes, the block length \(the configured data length, 3\.4\.6\), not b'\\x00\\x00\\x00'"),
    ("block(read=1)", "intel", lambda up: up.block_transfer(b"\x00" * 4, read=1), A,  # type: ignore[arg-type]
     r"^read must be True or False, not 1$"),
    ("block(write=None)", "intel", lambda up: up.block_transfer(b"\x00" * 4, write=None), A,  # type: ignore[arg-type]
     r"^write must be True or False, not None \(NoneType\)$"),
    # raw bytes
    ("transfer(256)", "motorola", lambda up: up.transfer(256), A, r"^mosi must be an integer from 0 to 255"),
    ("transfer(True)", "fresh", lambda up: up.transfer(True), A, r"^mosi must be"),
    ("transfer(s_r=1)", "intel", lambda up: up.transfer(0, s_r=1), A, r"^s_r must be True or False, not 1$"),  # type: ignore[arg-type]
    ("transfer Intel no s_r", "intel", lambda up: up.transfer(0), UpifUsageError, r"give s_r"),
    ("transfer in a frame", "motorola", lambda up: (_open_frame(up), up.transfer(0)), UpifUsageError, "inside a frame"),
    # initialization (Table 3-8)
    ("initialize('motorola')", "fresh", lambda up: up.initialize("motorola"), A,  # type: ignore[arg-type]
     r"^mode must be Mode.MOTOROLA or Mode.INTEL \(Table 3-8\), not 'motorola'$"),
    ("initialize(None)", "fresh", lambda up: up.initialize(None), A, r"^mode must be"),  # type: ignore[arg-type]
    ("initialize(0)", "motorola", lambda up: up.initialize(0), A, r"^mode must be"),  # type: ignore[arg-type]
    ("initialize disabled", "disabled", lambda up: up.initialize(Mode.INTEL), InterfaceDisabledError, "SAS_INIT it"),
    # call orders
    ("read fresh", "fresh", lambda up: up.read(0), NotInitializedError, r"^read: interface not initialized"),
    ("exchange fresh", "fresh", lambda up: up.exchange(0, 0), NotInitializedError, r"^exchange: interface not"),
    ("block fresh", "fresh", lambda up: up.block_transfer(b""), NotInitializedError, r"^block transfer: interface"),
    ("read disabled", "disabled", lambda up: up.read(0), InterfaceDisabledError, "disabled by a faulty init"),
    ("write disabled", "disabled", lambda up: up.write(0, 1), InterfaceDisabledError, "disabled by a faulty init"),
    ("block disabled", "disabled", lambda up: up.block_transfer(b""), InterfaceDisabledError, "disabled"),
    ("read mid-command", "mid-command", lambda up: up.read(0), UpifUsageError, r"needs the command phase: C/D = 1"),
    ("write mid-command", "mid-command", lambda up: up.write(0, 1), UpifUsageError, "needs the command phase"),
    ("block mid-command", "mid-command", lambda up: up.block_transfer(b"\x00" * 4), UpifUsageError, "command phase"),
    ("read in a frame", "motorola", lambda up: (_open_frame(up), up.read(0)), UpifUsageError, "inside a frame"),
    ("initialize in a frame", "motorola", lambda up: (_open_frame(up), up.initialize(Mode.MOTOROLA)), UpifUsageError,
     "inside a frame"),
    # the protocol machine (driven by the pin level)
    ("begin(1)", "motorola", lambda up: up.protocol.begin(1), A, r"^s_r must be True or False, not 1$"),  # type: ignore[arg-type]
    ("begin(None)", "fresh", lambda up: up.protocol.begin(None), A, r"^s_r must be"),  # type: ignore[arg-type]
    ("end(256)", "motorola", lambda up: _open_frame(up).end(256), A, r"^rx must be an integer from 0 to 255"),
    ("end('x')", "intel", lambda up: _open_frame(up).end("x"), A, r"^rx must be"),  # type: ignore[arg-type]
    ("end() without begin", "motorola", lambda up: up.protocol.end(0), UpifUsageError, r"without begin\(\)"),
    ("begin() twice", "motorola", lambda up: _open_frame(up).begin(True), UpifUsageError, "inside a frame"),
    ("abort(8)", "motorola", lambda up: _open_frame(up).abort(8), A, r"^bits must be .* not 8: a complete byte ends"),
    ("abort(-1)", "motorola", lambda up: _open_frame(up).abort(-1), A, r"^bits must be an integer >= 0"),
    ("abort(True)", "motorola", lambda up: _open_frame(up).abort(True), A, r"^bits must be"),
    ("abort() without begin", "motorola", lambda up: up.protocol.abort(3), UpifUsageError, r"without begin\(\)"),
]


@pytest.mark.parametrize(("setup", "call", "error", "message"), [row[1:] for row in HOSTILE],
                         ids=[row[0] for row in HOSTILE])
def test_hostile_calls_are_refused_by_name_and_change_nothing(
    setup: str, call: Callable[[UpInterface], object], error: type[Exception], message: str
) -> None:
    """Each public entry of UpInterface and UpifProtocol, given a wrong type, range or call order: the project's
    named error with its "X must be ..., not ..." message, and the interface exactly as before (an open frame the
    row itself began stays open)."""
    up = SETUPS[setup]()
    before = state(up)
    with pytest.raises(error, match=message) as raised:
        call(up)
    assert isinstance(raised.value, UpifUsageError)  # never a bare builtin error
    after = state(up)
    if up.protocol.in_frame:  # rows that began a frame themselves: all but the open frame is as before
        assert after[:5] == before[:5] and after[6:] == before[6:]
    else:
        assert after == before


# ------------------------------------------------------------------------------------------------------------
# Histories: any sequence of good and bad calls
# ------------------------------------------------------------------------------------------------------------

JUNK = st.one_of(st.none(), st.booleans(), st.floats(allow_nan=True), st.text(max_size=2), st.integers(-300, 300),
                 st.binary(max_size=5))


class InterfaceHistory(RuleBasedStateMachine):
    """Random histories of initialization, accesses, block transfers, raw bytes, resets, SAS_INIT, latch phases and
    bad calls. A refused call changes nothing; a register access ends in the command phase (or disabled); after
    any history, SAS_INIT and initialize() give a working interface."""

    strict = True

    def __init__(self) -> None:
        super().__init__()
        self.up = UpInterface(RegisterFile(RB_UP, strict=self.strict))

    @initialize()
    def start(self) -> None:
        self.up.registers.violations.records.clear()

    def _call(self, call: Callable[[], object], access: bool) -> None:
        before = state(self.up)
        refused = raised = False
        try:
            call()
        except UpifUsageError:  # UpifArgumentError, NotInitializedError, InterfaceDisabledError, call orders
            refused = True
        except InterfaceViolationError:
            raised = True
        if refused:
            assert state(self.up) == before  # a refused call sent nothing and changed nothing
            return
        assert self.strict or not raised
        if access:
            assert self.up.protocol.phase in ACCESS_END_PHASES

    @rule(mode=st.sampled_from(Mode))
    def init(self, mode: Mode) -> None:
        self._call(lambda: self.up.initialize(mode), access=True)

    @rule(address=st.integers(0, 14))
    def read(self, address: int) -> None:
        self._call(lambda: self.up.read(address), access=True)

    @rule(address=st.integers(0, 14), value=st.integers(0, 255))
    def write(self, address: int, value: int) -> None:
        self._call(lambda: self.up.write(address, value), access=True)

    @rule(address=st.integers(0, 14), value=st.integers(0, 255))
    def exchange(self, address: int, value: int) -> None:
        self._call(lambda: self.up.exchange(address, value), access=True)

    @rule(data=st.binary(max_size=5), rd=st.booleans(), wr=st.booleans())
    def block(self, data: bytes, rd: bool, wr: bool) -> None:
        self._call(lambda: self.up.block_transfer(data, read=rd, write=wr), access=True)

    @rule(byte=st.integers(0, 255), s_r=st.booleans())
    def raw(self, byte: int, s_r: bool) -> None:
        self._call(lambda: self.up.transfer(byte, s_r=s_r), access=False)

    @rule(junk=JUNK, which=st.sampled_from(["read", "write", "exchange", "block", "transfer", "initialize"]))
    def bad_call(self, junk: object, which: str) -> None:
        up = self.up
        calls: dict[str, Callable[[], object]] = {
            "read": lambda: up.read(junk),  # type: ignore[arg-type]
            "write": lambda: up.write(0, junk),  # type: ignore[arg-type]
            "exchange": lambda: up.exchange(junk, 0),  # type: ignore[arg-type]
            "block": lambda: up.block_transfer(junk),  # type: ignore[arg-type]
            "transfer": lambda: up.transfer(junk),  # type: ignore[arg-type]
            "initialize": lambda: up.initialize(junk),  # type: ignore[arg-type]
        }
        self._call(calls[which], access=False)

    @rule()
    def sas_init(self) -> None:
        self.up.sas_init()
        assert self.up.protocol.phase is Phase.INIT

    @rule()
    def power_up(self) -> None:
        self.up.power_up_reset()

    @rule(active=st.booleans())
    def latch_phase(self, active: bool) -> None:
        self.up.registers.set_latch_phase(active)

    @invariant()
    def documented_state(self) -> None:
        protocol = self.up.protocol
        assert protocol.phase in Phase and not protocol.in_frame
        assert (protocol.mode is None) == (protocol.phase in (Phase.INIT, Phase.DISABLED))

    def teardown(self) -> None:
        up = self.up
        up.registers.set_latch_phase(False)
        up.sas_init()
        assert up.initialize(Mode.MOTOROLA)
        up.write(ID, 0x5A)
        assert up.read(ID) == 0x5A


class LenientInterfaceHistory(InterfaceHistory):
    strict = False


TestInterfaceHistory = InterfaceHistory.TestCase
TestLenientInterfaceHistory = LenientInterfaceHistory.TestCase

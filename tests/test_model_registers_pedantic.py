"""Pedantic mode (issue #10, UP-30 to UP-38): legal but suspicious µP accesses are reported as
``SuspiciousAccessError`` through the violations log, each kind exactly where it applies (every address × direction
in each state), nothing without pedantic mode, strict raising after the access took effect."""

from __future__ import annotations

import functools
import itertools
import pickle
import re
from collections.abc import Callable
from pathlib import Path

import pytest

from supi3.config import decode
from supi3.errors import ArgumentError
from supi3.model.chip import Supi3
from supi3.model.registers import (
    SUSPICIOUS_ACCESSES,
    InterfaceViolationError,
    ReconfigurationError,
    RegisterFile,
    SuspiciousAccessError,
)
from supi3.regmap import BLOCK_ADDRESS, IRQ_EN, SET, AccessDirection
from supi3.spi.upif import Mode, Phase, UpInterface
from supi3.top import Supi3Chip

RB_UP = decode("10011", "1110")  # RB, Init-µP (Table 2-6)
R, W = AccessDirection.READ, AccessDirection.WRITE
IO_2_WORDS = 0x85  # /PCP = 1, CL = 101: I/O device, 4 bytes (Table 3-12)
PCP_2_WORDS = 0x05  # /PCP = 0, CL = 101: PCP device, 4 bytes
IO_1_BYTE = 0x82  # 3.4.5: I/O device, 1 byte
EXTREG_16_WORDS = 0x40 | 0b10010  # ExtReg = 1, 16 words (Table 3-11)
ACCESSES = [(address, direction) for address in range(BLOCK_ADDRESS) for direction in (R, W)]
Access = tuple[int, AccessDirection]

# Table 3-10 typed out, the oracle of every test below: writes to 6 and 8-11 have no register ("-"), 8-11 are read
# registers; 4 and 5 are reserved both ways, 6 is reserved for reads (3.4.7).
RESERVED_AND_READ_ONLY: dict[Access, set[str]] = {
    (4, W): {"UP-32"}, (5, W): {"UP-32"}, (6, W): {"UP-32"},
    (8, W): {"UP-31"}, (9, W): {"UP-31"}, (10, W): {"UP-31"}, (11, W): {"UP-31"},
    (4, R): {"UP-33"}, (5, R): {"UP-33"}, (6, R): {"UP-33"},
}  # fmt: skip


def interface(mode: Mode, set_value: int | None = IO_2_WORDS, *, latched: bool = True, strict: bool = False,
              pedantic: bool = True, id_written: bool = False) -> UpInterface:
    """An initialized interface, configured with ``set_value`` (none if ``None``), after one valid data cycle if
    ``latched``; the set-up itself reports nothing."""
    registers = RegisterFile(RB_UP, strict=strict, pedantic=pedantic)
    up = UpInterface(registers)
    assert up.initialize(mode)
    with registers.pedantic_paused():
        if set_value is not None:
            up.write(SET, set_value)
        if id_written:
            up.write(12, 0x03)
    if latched and registers.internal_data_path:
        registers.latch(bytes(registers.data_bytes()))
    assert not registers.violations.records
    return up


def access(up: UpInterface, address: int, direction: AccessDirection, value: int) -> None:
    if direction is R:
        up.read(address)
    else:
        up.write(address, value)


def suspicious(up: UpInterface) -> list[SuspiciousAccessError]:
    """The suspicious accesses recorded, checked to be all the records."""
    records = up.registers.violations.records
    assert all(isinstance(r, SuspiciousAccessError) for r in records)
    return [r for r in records if isinstance(r, SuspiciousAccessError)]


def reports(up: UpInterface, address: int, direction: AccessDirection, value: int) -> set[str]:
    """The decision IDs of the suspicious accesses one access reports (lenient mode)."""
    records = up.registers.violations.records
    before = len(records)
    access(up, address, direction, value)
    return {r.kind.decision for r in records[before:] if isinstance(r, SuspiciousAccessError)}


def every_access(make: Callable[[], UpInterface], value: int | Callable[[int], int] = 0) -> dict[Access, set[str]]:
    """What each address × direction reports, each on a fresh interface from ``make``; only non-empty entries."""
    found = {}
    for address, direction in ACCESSES:
        byte = value(address) if callable(value) else value
        kinds = reports(make(), address, direction, byte)
        if kinds:
            found[(address, direction)] = kinds
    return found


def test_every_kind_is_one_row_with_a_decision_recorded_in_the_assumptions() -> None:
    decisions = [kind.decision for kind in SUSPICIOUS_ACCESSES]
    assert decisions == [f"UP-{n}" for n in range(31, 39)]
    text = (Path(__file__).parents[1] / "docs" / "assumptions" / "upif.md").read_text(encoding="utf-8")
    for kind in SUSPICIOUS_ACCESSES:
        assert re.search(rf"^## {kind.decision} ", text, re.MULTILINE), kind


@pytest.mark.parametrize("mode", list(Mode))
def test_reserved_and_read_only_addresses_only_in_a_clean_state(mode: Mode) -> None:
    """UP-31, UP-32, UP-33: configured once (SET, ID), data within the length, after a data cycle."""
    found = every_access(lambda: interface(mode, id_written=True))
    assert found == {**RESERVED_AND_READ_ONLY, (12, W): {"UP-36"}, (13, W): {"UP-36"}}


@pytest.mark.parametrize("mode", list(Mode))
def test_reserved_bits(mode: Mode) -> None:
    """UP-34: FFh sets SET bit 5 and IRQ_EN bit 7 (RM-4, RM-7); every other write register has 8 bits. A PCP
    device, so that the PCP interrupt bits are no suspicion of their own."""
    assert interface(mode, PCP_2_WORDS).registers.pcp_device
    found = every_access(lambda: interface(mode, PCP_2_WORDS), 0xFF)
    assert found == {**RESERVED_AND_READ_ONLY, (13, W): {"UP-34", "UP-36"}, (14, W): {"UP-34"}}


@pytest.mark.parametrize("mode", list(Mode))
@pytest.mark.parametrize(("set_value", "inside"), [(IO_1_BYTE, 1), (0x03, 2), (IO_2_WORDS, 4), (None, 0),
                                                   (EXTREG_16_WORDS, 0)])
def test_data_registers_outside_the_data_length(mode: Mode, set_value: int | None, inside: int) -> None:
    """UP-35: IN k written and OUT k read with k >= the configured bytes (3.4.8, 3.4.11); all of them before SET
    and with ExtReg = 1 (the internal registers are not in the data path)."""
    found = every_access(lambda: interface(mode, set_value))
    outside = {(k, d): {"UP-35"} for k in range(inside, 4) for d in (R, W)}
    rewritten = {} if set_value is None else {(13, W): {"UP-36"}}  # SET configured already (UP-36)
    assert found == {**RESERVED_AND_READ_ONLY, **outside, **rewritten}


@pytest.mark.parametrize("mode", list(Mode))
def test_configuration_written_again(mode: Mode) -> None:
    """UP-36: SET and ID are written once, during initialization (3.4.3, 3.4.10, 3.4.11); SAS_INIT keeps them, so
    a rewrite after SAS_INIT is suspicious too; after power-up it is the first configuration again."""
    first = every_access(lambda: interface(mode, None))
    assert first == {**RESERVED_AND_READ_ONLY, **{(k, d): {"UP-35"} for k in range(4) for d in (R, W)}}
    up = interface(mode, IO_2_WORDS, id_written=True)
    assert reports(up, 13, W, IO_2_WORDS) == {"UP-36"}
    assert reports(up, 12, W, 0x03) == {"UP-36"}
    up.sas_init()
    assert up.initialize(mode)
    assert reports(up, 13, W, IO_2_WORDS) == {"UP-36"}
    up.power_up_reset()
    assert up.initialize(mode)
    assert reports(up, 13, W, IO_2_WORDS) == set()
    assert reports(up, 12, W, 0x03) == set()


def test_a_set_value_that_was_not_applied_is_no_configuration() -> None:
    up = interface(Mode.MOTOROLA, None)
    up.write(SET, 0x06)  # CL = 110: reserved, not applied (UP-20)
    assert reports(up, 13, W, IO_2_WORDS) == set()
    assert reports(up, 13, W, IO_2_WORDS) == {"UP-36"}


def test_rewrite_during_bus_operation_is_a_reconfiguration_error_only() -> None:
    up = interface(Mode.MOTOROLA, IO_2_WORDS, id_written=True)
    up.registers.set_bus_running(True)
    records = up.registers.violations.records
    up.write(SET, IO_2_WORDS)
    up.write(12, 0x03)
    assert [type(r) for r in records] == [ReconfigurationError, ReconfigurationError]


@pytest.mark.parametrize("mode", list(Mode))
@pytest.mark.parametrize(("set_value", "suspicious"), [(IO_2_WORDS, True), (IO_1_BYTE, True), (PCP_2_WORDS, False),
                                                       (EXTREG_16_WORDS, False), (None, False)])
def test_pcp_interrupts_on_an_io_device(mode: Mode, set_value: int | None, suspicious: bool) -> None:
    """UP-37: IRQ_EN with PCP receive or PCP send (D1, D0) on an I/O device (/PCP = 1, ExtReg = 0; 3.4.11, Table
    3-13); not on a PCP device, with ExtReg = 1 (/PCP has no meaning) or before SET."""
    for value in range(0x80):
        kinds = reports(interface(mode, set_value), IRQ_EN.address, W, value)
        assert kinds == ({"UP-37"} if suspicious and value & 0x03 else set()), value


@pytest.mark.parametrize("mode", list(Mode))
def test_out_read_before_the_first_valid_data_cycle(mode: Mode) -> None:
    """UP-38: OUT k inside the data length read before a valid data cycle latched OUT data (Table 3-13, 3.4.14);
    again after an INTERBUS reset, which clears OUT (3.4.7)."""
    found = every_access(lambda: interface(mode, IO_2_WORDS, latched=False, id_written=True))
    before = {(k, R): {"UP-38"} for k in range(4)}
    assert found == {**RESERVED_AND_READ_ONLY, **before, (12, W): {"UP-36"}, (13, W): {"UP-36"}}
    up = interface(mode, IO_2_WORDS)
    assert reports(up, 0, R, 0) == set()
    up.registers.interbus_reset()
    assert reports(up, 0, R, 0) == {"UP-38"}


@pytest.mark.parametrize("mode", list(Mode))
def test_exchange_and_raw_bytes_report_through_the_protocol(mode: Mode) -> None:
    """The reports come from the register file and the protocol, so every path (``transfer``, the pin level) gives
    them: a raw read of reserved address 5, and in Motorola mode one exchange reporting both directions."""
    up = interface(mode)
    intel = mode is Mode.INTEL
    up.transfer(0x85, s_r=True)
    assert up.transfer(0, s_r=False if intel else None) == 0x85  # the command byte is read back (3.4.4)
    assert [(r.kind.decision, r.address, r.direction, r.value) for r in suspicious(up)] == [("UP-33", 5, R, 0x85)]
    if not intel:
        up.registers.violations.records.clear()
        up.exchange(4, 0x11)
        assert [(r.kind.decision, r.direction) for r in suspicious(up)] == [("UP-33", R), ("UP-32", W)]


@pytest.mark.parametrize("mode", list(Mode))
@pytest.mark.parametrize("set_value", [IO_1_BYTE, IO_2_WORDS, PCP_2_WORDS, None, EXTREG_16_WORDS])
def test_without_pedantic_mode_nothing_is_reported(mode: Mode, set_value: int | None) -> None:
    for value, latched in itertools.product((0x00, 0xFF), (False, True)):
        make = functools.partial(interface, mode, set_value, latched=latched, pedantic=False)
        assert every_access(make, value) == {}


def test_strict_mode_raises_after_the_access_took_effect() -> None:
    up = interface(Mode.MOTOROLA, IO_1_BYTE, strict=True)
    message = r"UP-34.*90h written to address 14 \(IRQ_EN\): bits 80h are reserved, stored 10h"
    with pytest.raises(SuspiciousAccessError, match=message) as caught:
        up.write(IRQ_EN, 0x90)
    assert caught.value.kind.decision == "UP-34"
    assert up.registers.value("IRQ_EN") == 0x10  # stored without the reserved bit
    assert up.protocol.phase is Phase.COMMAND
    with pytest.raises(SuspiciousAccessError, match=r"UP-35"):
        up.write(3, 0x5A)
    assert up.registers.value("IN3") == 0x5A
    with pytest.raises(SuspiciousAccessError, match=r"UP-35"):
        up.registers.cpu_write(2, 0x6B)  # the register file alone: after the store as well
    assert up.registers.value("IN2") == 0x6B
    up.registers.event("VALID")
    assert up.read(14) & 0x10  # an unsuspicious read still works and clears its events
    assert up.registers.irq_n == 1


def test_lenient_mode_records_with_address_register_and_value() -> None:
    up = interface(Mode.INTEL, IO_1_BYTE)
    up.write(9, 0x12)
    up.read(2)
    first, second = suspicious(up)
    assert isinstance(first, InterfaceViolationError)
    assert str(first) == ("pedantic UP-31, write to a read-only address (no write register: no effect): 12h written to "
                          "address 9 (read-only, LENGTH_BRANCH): no effect (3.4.7, Table 3-10)")
    assert (first.address, first.direction, first.value, first.rule) == (9, W, 0x12, "3.4.7, Table 3-10")
    assert "00h read from address 2 (OUT2)" in str(second)
    assert "the data length is 8 bits = 1 byte(s) (SET 82h)" in str(second)
    copy = pickle.loads(pickle.dumps(second))
    assert (type(copy), str(copy), copy.kind) == (SuspiciousAccessError, str(second), second.kind)


@pytest.mark.parametrize("mode", list(Mode))
def test_initialize_is_not_suspicious(mode: Mode) -> None:
    """A re-initialization completes with a no-op data byte (Intel: a read of OUT1 outside a 1-byte length, before
    any data cycle): the procedure of 3.4.3, not the firmware's access (UP-30)."""
    up = interface(mode, IO_1_BYTE, latched=False, strict=True)
    assert not up.initialize(mode)
    assert not up.registers.violations.records
    assert up.registers.pedantic


@pytest.mark.parametrize("hostile", ["yes", 1, None, 0.0])
def test_hostile_pedantic_arguments_are_refused_by_name(hostile: object) -> None:
    makers: list[Callable[[], object]] = [
        lambda: RegisterFile(RB_UP, pedantic=hostile),  # type: ignore[arg-type]
        lambda: Supi3(RB_UP, pedantic=hostile),  # type: ignore[arg-type]
        lambda: Supi3Chip(RB_UP, pedantic=hostile),  # type: ignore[arg-type]
    ]
    for make in makers:
        with pytest.raises(ArgumentError, match=r"^pedantic must be True or False"):
            make()


def test_ignored_access_refuses_what_the_chip_does_not_ignore() -> None:
    registers = RegisterFile(RB_UP, pedantic=True)
    with pytest.raises(ArgumentError, match="address must be one whose write access the chip ignores"):
        registers.ignored_access(3, W, 0)
    with pytest.raises(ArgumentError, match=r"^direction must be an AccessDirection"):
        registers.ignored_access(4, "write", 0)  # type: ignore[arg-type]
    with pytest.raises(ArgumentError, match=r"^value must be"):
        registers.ignored_access(4, W, 256)


def test_the_flag_passes_through_the_chip_models() -> None:
    assert Supi3(RB_UP, pedantic=True).registers.pedantic  # type: ignore[union-attr]
    assert not Supi3(RB_UP).registers.pedantic  # type: ignore[union-attr]
    chip = Supi3Chip(RB_UP, strict=False, pedantic=True)
    assert chip.chip.registers is not None and chip.chip.registers.pedantic
    assert Supi3(decode("10011", "0001"), pedantic=True).registers is None  # no µP interface: ignored

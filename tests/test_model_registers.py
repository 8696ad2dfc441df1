"""The µP-visible register file (3.4.7 - 3.4.14): access semantics, resets, interrupts, configuration by software,
the core interface and its violations."""

from __future__ import annotations

import pytest

from supi3.config import DeviceConfig, decode
from supi3.model.registers import (
    InconsistentDataError,
    ReconfigurationError,
    RegisterFile,
    RegisterFileError,
    SetRegisterError,
)
from supi3.regmap import INTERRUPT_SOURCES, REGISTER_MAP, Access, AccessDirection, Reset, encode_command
from supi3.tables import UP_NOT_READY_ID_CODES

RB_UP = decode("10011", "1110")  # RB, Init-µP: µP_Not_Ready 38h (Table 2-6)
LBD_OR_UP = decode("11111", "1110")  # LBD-OR, Init-µP: µP_Not_Ready 68h (Table 2-5)
SOURCE_BIT = {s.name: s.bit for s in INTERRUPT_SOURCES}
SET_IO_1_BYTE = 0x82  # 3.4.5: I/O device, abbreviated length 1 byte
SET_PCP_1_WORD = 0x03  # /PCP = 0, CL = 011 (1 word)
SET_IO_2_WORDS = 0x85  # /PCP = 1, CL = 101 (2 words)


def regs(config: DeviceConfig = RB_UP, *, strict: bool = True) -> RegisterFile:
    return RegisterFile(config, strict=strict)


def test_rejects_non_up_modes() -> None:
    with pytest.raises(RegisterFileError, match="not a serial µP interface mode"):
        RegisterFile(decode("10011", "0001"))


@pytest.mark.parametrize("config", [RB_UP, LBD_OR_UP])
def test_unconfigured_device_reports_up_not_ready_and_length_zero(config: DeviceConfig) -> None:
    r = regs(config)
    assert not r.configured
    assert r.bus_id_register() == config.id_code
    assert config.id_code in UP_NOT_READY_ID_CODES
    assert r.data_bits() == 0
    assert r.in_bytes() == b""


def test_manual_example_configuration() -> None:
    """3.4.5: 82h to SET (I/O device, 1 byte), 01h to ID (digital output): the master sees 0901h."""
    r = regs()
    r.cpu_write(13, SET_IO_1_BYTE)
    r.cpu_write(12, 0x01)
    assert r.configured
    assert r.data_bits() == 8
    assert r.bus_id_register() == 0x0901
    assert r.cpu_read(13) == SET_IO_1_BYTE
    assert r.cpu_read(12) == 0x01
    assert not r.pcp_device


def test_set_with_extreg_gives_the_full_length_code() -> None:
    r = regs()
    r.cpu_write(13, 0x40 | 0b10010)  # ExtReg, 16 words (Table 3-11)
    assert r.data_bits() == 256
    assert r.bus_id_register() >> 8 == 0b10010
    assert not r.internal_data_path
    with pytest.raises(RegisterFileError, match="ExtReg"):
        r.in_bytes()


@pytest.mark.parametrize("value", [0x06, 0x07, 0x40 | 0b01010, 0x40 | 0b11000])
@pytest.mark.parametrize("before", [SET_IO_1_BYTE, SET_PCP_1_WORD, 0x40 | 0b10010])
def test_a_reserved_set_code_after_a_configuration_leaves_none(value: int, before: int) -> None:
    """UP-20, UP-40: the configuration is the stored SET's: a reserved code written after an applied one leaves the
    device unconfigured (the µP_Not_Ready ID and length, no data), and an applicable one configures it again."""
    r = regs(strict=False)
    unconfigured = r.bus_id_register()
    r.cpu_write(13, before)
    assert r.configured
    r.cpu_write(13, value)
    assert (r.configured, r.bus_id_register(), r.data_bits(), r.pcp_device) == (False, unconfigured, 0, False)
    assert r.cpu_read(13) == value
    r.cpu_write(13, before)
    assert r.configured and r.bus_id_register() != unconfigured


@pytest.mark.parametrize("value", [0x06, 0x07, 0x40 | 0b01010, 0x40 | 0b11000])
def test_reserved_set_codes_are_stored_but_not_applied(value: int) -> None:
    r = regs(strict=False)
    r.cpu_write(13, value)
    assert isinstance(r.violations.records[-1], SetRegisterError)
    assert r.cpu_read(13) == value
    assert not r.configured
    with pytest.raises(SetRegisterError):
        regs().cpu_write(13, value)


@pytest.mark.parametrize("address", REGISTER_MAP.addresses)
def test_every_address_read_and_write(address: int) -> None:
    """Table 3-10 and RM-9: what a read and a write of each address do."""
    r = regs()
    write = REGISTER_MAP.port(address, AccessDirection.WRITE)
    read = REGISTER_MAP.port(address, AccessDirection.READ)
    if write.access in (Access.RESERVED_IGNORED, Access.BLOCK_TRANSFER):
        with pytest.raises(RegisterFileError):
            r.cpu_write(address, 0x55)
        with pytest.raises(RegisterFileError):
            r.cpu_read(address)
        return
    before = {reg.name: r.value(reg.name) for reg in REGISTER_MAP.registers}
    r.cpu_write(address, 0x45)
    after = {reg.name: r.value(reg.name) for reg in REGISTER_MAP.registers}
    changed = {name for name in before if before[name] != after[name]}
    if write.access is Access.NO_EFFECT:
        assert changed == set()
    else:
        assert write.register is not None
        assert changed == {write.register.name}
        assert after[write.register.name] == 0x45 & write.register.mask
    value = r.cpu_read(address)
    if read.access is Access.RESERVED_ZERO:
        assert value == 0
    elif read.register is not None and read.register is write.register:
        assert value == 0x45 & read.register.mask  # ID, SET read back (3.4.11)
    else:
        assert read.register is not None
        assert value == r.value(read.register.name) == 0  # IN bytes cannot be read back (3.4.8)


@pytest.mark.parametrize("reset", list(Reset))
def test_resets_clear_what_the_map_says(reset: Reset) -> None:
    r = regs()
    r.cpu_write(13, SET_IO_2_WORDS)
    r.cpu_write(12, 0x03)
    r.cpu_write(14, 0x7F)
    r.cpu_write(7, 0xA5)
    for address in range(4):
        r.cpu_write(address, 0x10 + address)
    r.latch(b"\x01\x02\x03\x04")
    for name in ("LENGTH_OUT", "LENGTH_BRANCH", "POWER_IN", "POWER_OUT_BRANCH"):
        r.set_optical(name, 0x81)
    r.processor_command(0x11)
    r.event("VALID")
    {Reset.POWER_UP: r.power_up_reset, Reset.INTERBUS: r.interbus_reset, Reset.SAS_INIT: r.sas_init}[reset]()
    cleared = {reg.name for reg in REGISTER_MAP.cleared_by(reset)}
    for reg in REGISTER_MAP.registers:
        if reg.name in cleared:
            assert r.value(reg.name) == 0, reg.name
        else:
            assert r.value(reg.name) != 0, reg.name
    assert r.configured == (reset is not Reset.POWER_UP)


def test_interbus_reset_raises_its_event() -> None:
    r = regs()
    r.cpu_write(14, 1 << SOURCE_BIT["IB_RESET"])
    r.interbus_reset()
    assert r.irq_n == 0
    assert r.cpu_read(14) == 1 << SOURCE_BIT["IB_RESET"]
    assert r.irq_n == 1


@pytest.mark.parametrize("source", [s.name for s in INTERRUPT_SOURCES])
def test_interrupt_enable_event_and_read_clear(source: str) -> None:
    """3.4.14: enabled event -> bit set and /IRQ low; reading 14 clears it and releases /IRQ; the I/O access bit
    D7 is live and survives the read (RM-8)."""
    r = regs()
    r.event(source)
    assert r.irq_n == 1 and r.value("IRQ_EVT") == 0  # disabled: not latched (UP-15)
    r.cpu_write(14, 1 << SOURCE_BIT[source])
    r.set_io_access(True)
    r.event(source)
    assert r.irq_n == 0
    assert r.cpu_read(14) == 0x80 | 1 << SOURCE_BIT[source]
    assert r.irq_n == 1
    assert r.cpu_read(14) == 0x80
    r.set_io_access(False)
    assert r.cpu_read(14) == 0


def test_interrupts_work_with_data_length_zero() -> None:
    r = regs()
    r.cpu_write(14, 1 << SOURCE_BIT["VALID"])
    assert r.data_bits() == 0
    assert r.latch(b"") == b""
    r.event("VALID")
    assert r.irq_n == 0


def test_disabling_a_source_keeps_a_pending_event() -> None:
    r = regs()
    r.cpu_write(14, 0x10)
    r.event("VALID")
    r.cpu_write(14, 0)
    assert r.irq_n == 0


def test_unknown_source() -> None:
    with pytest.raises(RegisterFileError, match="no interrupt source"):
        regs().event("NOPE")


def test_latch_exchanges_data_msb_first_and_io_device_keeps_in_bytes() -> None:
    r = regs()
    r.cpu_write(13, SET_IO_2_WORDS)
    for address, value in enumerate(b"\x11\x22\x33\x44"):
        r.cpu_write(address, value)
    assert r.in_bytes() == b"\x11\x22\x33\x44"
    assert r.latch(b"\xa1\xa2\xa3\xa4") == b"\x11\x22\x33\x44"
    assert [r.cpu_read(a) for a in range(4)] == [0xA1, 0xA2, 0xA3, 0xA4]
    assert r.in_bytes() == b"\x11\x22\x33\x44"  # /PCP = 1: sent every cycle


def test_pcp_device_erases_in_bytes_0_and_1_after_transfer() -> None:
    """3.4.11: with /PCP = 0, IN bytes 0 and 1 are erased after their contents were transferred."""
    r = regs()
    r.cpu_write(13, SET_PCP_1_WORD)
    assert r.pcp_device
    r.cpu_write(0, 0x12)
    r.cpu_write(1, 0x34)
    r.cpu_write(2, 0x56)
    assert r.latch(b"\x00\x00") == b"\x12\x34"
    assert r.in_bytes() == b"\x00\x00"
    assert r.value("IN2") == 0x56


def test_latch_needs_the_configured_length() -> None:
    r = regs()
    r.cpu_write(13, SET_IO_1_BYTE)
    with pytest.raises(RegisterFileError, match="needs 1 OUT bytes"):
        r.latch(b"\x00\x00")


@pytest.mark.parametrize("address", [0, 3])
def test_data_access_during_latch_phase_is_inconsistent(address: int) -> None:
    """3.4.14: an access that overlaps the latch phase may give inconsistent data."""
    r = regs(strict=False)
    r.set_latch_phase(True)
    r.cpu_write(address, 1)
    r.cpu_read(address)
    r.cpu_read(14)  # not a data register
    assert [type(v) for v in r.violations.records] == [InconsistentDataError] * 2
    assert r.value(f"IN{address}") == 1  # the access still happens
    r.set_latch_phase(False)
    r.cpu_read(address)
    assert len(r.violations.records) == 2
    strict = regs()
    strict.set_latch_phase(True)
    with pytest.raises(InconsistentDataError, match="inconsistent data"):
        strict.cpu_read(address)


@pytest.mark.parametrize("address", [12, 13])
def test_reconfiguration_during_bus_operation(address: int) -> None:
    r = regs(strict=False)
    r.cpu_write(13, SET_IO_1_BYTE)
    r.set_bus_running(True)
    r.cpu_write(address, 0x85)
    assert isinstance(r.violations.records[-1], ReconfigurationError)
    assert r.cpu_read(address) == 0x85  # applied, as the chip would
    strict = regs()
    strict.set_bus_running(True)
    with pytest.raises(ReconfigurationError, match="during bus operation"):
        strict.cpu_write(address, 0x82)


def test_management_channel() -> None:
    r = regs()
    r.cpu_write(14, 1 << SOURCE_BIT["PCMD"])
    r.processor_command(0x5C)
    assert r.irq_n == 0
    assert r.cpu_read(7) == 0x5C
    r.cpu_write(7, 0xC5)
    assert r.processor_alarm == 0xC5
    with pytest.raises(RegisterFileError):
        r.processor_command(256)


def test_optical_registers() -> None:
    r = regs()
    r.set_optical("LENGTH_OUT", 0xC5)
    assert r.cpu_read(8) == 0xC5
    with pytest.raises(RegisterFileError, match="outside"):
        r.set_optical("POWER_IN", 0x70)
    with pytest.raises(RegisterFileError, match="not an optical register"):
        r.set_optical("SET", 0)


@pytest.mark.parametrize("bad", [-1, 16, True, "3"])
def test_bad_addresses(bad: object) -> None:
    with pytest.raises(RegisterFileError, match="address must be"):
        regs().cpu_read(bad)  # type: ignore[arg-type]


def test_bad_value_and_register_name() -> None:
    with pytest.raises(RegisterFileError):
        regs().cpu_write(0, 256)
    with pytest.raises(RegisterFileError):
        regs().value("NOPE")
    assert encode_command(13, wr=True) == 0x4D

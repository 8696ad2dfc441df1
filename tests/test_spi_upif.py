"""The serial µP interface protocol at the byte level (3.4.3 - 3.4.7): the manual's examples, every address,
reserved addresses, faulty initialization, block transfer, Intel S/R, SAS_INIT and resets at random points."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from supi3.config import decode
from supi3.model.registers import RegisterFile
from supi3.regmap import ID, IN0, IN2, IRQ_EN, IRQ_EVT, OUT0, REGISTER_MAP, SET, Access, AccessDirection, encode_command
from supi3.spi.upif import (
    C_D_COMMAND,
    C_D_DATA,
    Mode,
    Phase,
    ProtocolViolationError,
    UpifArgumentError,
    UpifUsageError,
    UpInterface,
)

RB_UP = decode("10011", "1110")


def chip(mode: Mode | None = None, *, strict: bool = True, set_value: int | None = None) -> UpInterface:
    up = UpInterface(RegisterFile(RB_UP, strict=strict))
    if mode is not None:
        assert up.initialize(mode)
    if set_value is not None:
        up.write(SET, set_value)
    return up


def test_manual_initialization_example_intel() -> None:
    """3.4.5, Figs. 3-9 to 3-11: 81h, then 4Dh 82h (SET), then 4Ch 01h (ID)."""
    up = chip()
    assert up.c_d == C_D_COMMAND  # ready for initialization (3.4.3)
    assert up.transfer(0x81) is None
    assert up.protocol.mode is Mode.INTEL
    assert up.c_d == C_D_COMMAND  # command status twice: first initialization
    for command, data in ((0x4D, 0x82), (0x4C, 0x01)):
        up.transfer(command, s_r=True)
        assert up.c_d == C_D_DATA
        up.transfer(data, s_r=True)
        assert up.c_d == C_D_COMMAND
    assert up.registers.bus_id_register() == 0x0901
    assert up.read(SET) == 0x82
    assert up.read(ID) == 0x01


def test_motorola_initialization_and_full_duplex() -> None:
    up = chip()
    assert up.transfer(0x00) is None
    assert up.protocol.mode is Mode.MOTOROLA
    up.write(SET, 0x85)  # 2 words
    up.registers.latch(b"\x0a\x0b\x0c\x0d")
    assert up.exchange(IN2, 0x77) == 0x0C
    assert up.registers.value("IN2") == 0x77


@pytest.mark.parametrize("mode", list(Mode))
def test_first_init_signature_after_a_microprocessor_reset(mode: Mode) -> None:
    """3.4.3: only a freshly reset chip shows the command status twice; an initialized one takes the byte as a
    command, which initialize() completes with a no-op data byte."""
    up = chip(mode, set_value=0x82)
    up.registers.latch(b"\x42")
    assert up.initialize(mode) is False
    assert up.c_d == C_D_COMMAND
    assert up.read(SET) == 0x82
    up.sas_init()
    assert up.initialize(mode) is True
    assert up.read(SET) == 0x82  # SAS_INIT keeps SET and ID (3.4.3)


@pytest.mark.parametrize("bad", [0x01, 0x80, 0xFF, 0x42, 0x7E])
def test_faulty_initialization_byte_disables_until_sas_init(bad: int) -> None:
    up = chip()
    up.transfer(bad)
    assert up.protocol.phase is Phase.DISABLED
    assert up.c_d == C_D_DATA
    for byte in (0x00, 0x81, 0x4D, 0x82):
        assert up.transfer(byte, s_r=True) is None
    assert up.registers.value("SET") == 0
    with pytest.raises(UpifUsageError, match="disabled"):
        up.initialize(Mode.MOTOROLA)
    up.sas_init()
    assert up.initialize(Mode.MOTOROLA)
    up.power_up_reset()
    up.transfer(bad)
    up.power_up_reset()
    assert up.initialize(Mode.INTEL)


@pytest.mark.parametrize("mode", list(Mode))
@pytest.mark.parametrize("address", [4, 5])
def test_reserved_addresses_ignore_the_data_access(mode: Mode, address: int) -> None:
    """3.4.4, 3.4.7: the data access is ignored, the command byte is read back, a command follows."""
    up = chip(mode, set_value=0x85)
    before = {r.name: up.registers.value(r.name) for r in REGISTER_MAP.registers}
    for rd, wr in ((True, False), (False, True), (True, True)):
        command = encode_command(address, rd=rd, wr=wr)
        up.transfer(command, s_r=True)
        assert up.c_d == C_D_DATA
        assert up.transfer(0xEE, s_r=False) == command
        assert up.c_d == C_D_COMMAND
    assert before == {r.name: up.registers.value(r.name) for r in REGISTER_MAP.registers}
    assert up.registers.violations.records == []


@pytest.mark.parametrize("mode", list(Mode))
@pytest.mark.parametrize("address", [a for a in REGISTER_MAP.addresses if a not in (4, 5, 15)])
def test_every_address_through_the_interface(mode: Mode, address: int) -> None:
    """Table 3-10: one command byte and one data byte per access; the result equals the register file's."""
    up = chip(mode, set_value=0x85)
    reference = RegisterFile(RB_UP)
    reference.cpu_write(13, 0x85)
    up.write(address, 0x45)
    reference.cpu_write(address, 0x45)
    assert up.read(address) == reference.cpu_read(address)
    assert up.c_d == C_D_COMMAND
    write = REGISTER_MAP.port(address, AccessDirection.WRITE)
    if write.access is Access.NO_EFFECT:
        assert up.registers.value("IN0") == 0


@pytest.mark.parametrize("mode", list(Mode))
def test_data_byte_without_read_echoes_the_command_byte(mode: Mode) -> None:
    up = chip(mode)
    up.transfer(0x4C, s_r=True)
    echo = up.transfer(0x99, s_r=True)
    assert echo == (0x4C if mode is Mode.MOTOROLA else None)
    assert up.registers.value("ID") == 0x99


def test_intel_block_transfer_example() -> None:
    """3.4.6, Fig. 3-12: a 24-bit output device; 8Fh then the three bytes 14h 56h 78h: 4 accesses, not 6."""
    up = chip(Mode.INTEL, set_value=0x84)  # /PCP = 1, CL = 100: 3 bytes
    up.registers.latch(b"\x14\x56\x78")
    assert up.transfer(0x8F, s_r=True) is None
    received = [up.transfer(0, s_r=False) for _ in range(3)]
    assert received == [0x14, 0x56, 0x78]
    assert up.c_d == C_D_COMMAND
    assert up.registers.violations.records == []


def test_intel_block_transfer_reads_then_writes() -> None:
    up = chip(Mode.INTEL, set_value=0x85)
    up.registers.latch(b"\x01\x02\x03\x04")
    assert up.block_transfer(b"\xa1\xa2\xa3\xa4") == b"\x01\x02\x03\x04"
    assert up.registers.in_bytes() == b"\xa1\xa2\xa3\xa4"
    assert up.block_transfer(b"\x00" * 4, read=False) == b""
    assert up.registers.in_bytes() == b"\x00" * 4


def test_motorola_block_transfer_is_simultaneous_whatever_rd_and_wr() -> None:
    up = chip(Mode.MOTOROLA, set_value=0x85)
    up.registers.latch(b"\x01\x02\x03\x04")
    assert up.block_transfer(b"\xa1\xa2\xa3\xa4") == b"\x01\x02\x03\x04"
    up.transfer(encode_command(15), s_r=True)  # RD = WR = 0: still a block transfer (3.4.6)
    assert [up.transfer(b) for b in b"\x55\x66\x77\x88"] == [0x01, 0x02, 0x03, 0x04]
    assert up.registers.in_bytes() == b"\x55\x66\x77\x88"
    assert up.c_d == C_D_COMMAND


@pytest.mark.parametrize(("set_value", "count"), [(0x80, 0), (0x81, 1), (0x82, 1)])
def test_block_transfer_below_one_word(set_value: int, count: int) -> None:
    """3.4.6 allows data lengths >= 1 word; below that it is reported and covers the whole bytes (UP-10)."""
    up = chip(Mode.MOTOROLA, strict=False, set_value=set_value)
    up.transfer(0xCF)
    assert isinstance(up.registers.violations.records[-1], ProtocolViolationError)
    for _ in range(count):
        assert up.c_d == C_D_DATA
        up.transfer(0x11)
    assert up.c_d == C_D_COMMAND
    strict = chip(Mode.MOTOROLA, set_value=set_value)
    with pytest.raises(ProtocolViolationError, match="1 word"):
        strict.transfer(0xCF)


def test_block_transfer_with_external_registers_has_no_data_bytes() -> None:
    up = chip(Mode.MOTOROLA, strict=False, set_value=0x40 | 0b00010)
    up.transfer(0xCF)
    assert up.c_d == C_D_COMMAND
    assert "ExtReg" in str(up.registers.violations.records[-1])


def test_intel_s_r_against_the_command() -> None:
    up = chip(Mode.INTEL, strict=False)
    up.transfer(encode_command(ID.address, wr=True), s_r=True)
    assert up.transfer(0x33, s_r=False) == encode_command(ID.address, wr=True)  # chip drives the echo, no write
    assert up.registers.value("ID") == 0
    up.transfer(encode_command(ID.address, rd=True), s_r=True)
    assert up.transfer(0x33, s_r=True) is None
    up.transfer(0x00, s_r=False)  # a command byte the chip sends: ignored
    assert up.c_d == C_D_COMMAND
    assert [v.rule for v in up.registers.violations.records] == ["Table 3-9"] * 3
    up.transfer(encode_command(ID.address, rd=True, wr=True), s_r=True)  # both bits: S/R decides (3.4.4)
    up.transfer(0x21, s_r=True)
    assert up.registers.value("ID") == 0x21
    with pytest.raises(UpifUsageError, match="s_r"):
        up.transfer(0x00)


def test_reserved_command_bits_are_ignored_and_reported() -> None:
    up = chip(Mode.MOTOROLA, strict=False)
    up.transfer(0x4D | 0x30)
    up.transfer(0x82)
    assert up.registers.value("SET") == 0x82
    assert isinstance(up.registers.violations.records[0], ProtocolViolationError)


def test_api_contract() -> None:
    up = chip(Mode.MOTOROLA, strict=False)
    with pytest.raises(UpifUsageError):
        up.transfer(256)
    up.transfer(0x4D)
    with pytest.raises(UpifUsageError, match="command phase"):
        up.read(0)
    up.transfer(0x82)
    with pytest.raises(UpifUsageError, match="did not end the block"):
        up.block_transfer(b"")
    intel = chip(Mode.INTEL)
    with pytest.raises(UpifUsageError, match="Motorola"):
        intel.exchange(0, 0)
    with pytest.raises(UpifUsageError):
        intel.protocol.end(0)


def test_registers_as_addresses() -> None:
    """read/write/exchange take a register of supi3.regmap as well as its address, if it is reached that way."""
    up = chip(Mode.MOTOROLA)
    up.write(SET, 0x82)
    up.write(ID, 0x01)
    assert up.read(SET) == up.read(13) == 0x82
    assert up.exchange(ID, 0x01) == 0x01
    up.write(IRQ_EN, 0x01)
    assert up.read(IRQ_EVT) == 0
    refused = (lambda: up.write(IRQ_EVT, 0), lambda: up.read(IRQ_EN), lambda: up.read(IN0), lambda: up.write(OUT0, 0))
    for call in refused:
        with pytest.raises(UpifArgumentError, match=r"is not (written|read) at address"):
            call()


_OPS = st.lists(
    st.one_of(
        st.tuples(st.just("byte"), st.integers(0, 255), st.booleans()),
        st.tuples(st.just("sas_init"), st.just(0), st.just(False)),
        st.tuples(st.just("power_up"), st.just(0), st.just(False)),
        st.tuples(st.just("interbus_reset"), st.just(0), st.just(False)),
    ),
    max_size=40,
)


@given(_OPS)
def test_resets_at_random_points(ops: list[tuple[str, int, bool]]) -> None:
    """Whatever bytes came before, SAS_INIT brings back the init phase with SET and ID kept, power-up clears
    everything, an INTERBUS reset clears only the data."""
    up = chip(strict=False)
    for kind, value, s_r in ops:
        if kind == "byte":
            up.transfer(value, s_r=s_r)
        elif kind == "sas_init":
            kept = up.registers.value("SET"), up.registers.value("ID")
            up.sas_init()
            assert up.protocol.phase is Phase.INIT and up.c_d == C_D_COMMAND
            assert (up.registers.value("SET"), up.registers.value("ID")) == kept
        elif kind == "power_up":
            up.power_up_reset()
            assert all(up.registers.value(r.name) == 0 for r in REGISTER_MAP.registers)
            assert up.protocol.phase is Phase.INIT
        else:
            phase = up.protocol.phase
            up.registers.interbus_reset()
            assert up.protocol.phase is phase
            assert all(up.registers.value(f"IN{n}") == up.registers.value(f"OUT{n}") == 0 for n in range(4))
    up.sas_init()
    assert up.initialize(Mode.MOTOROLA)
    up.write(ID, 0x5A)
    assert up.read(ID) == 0x5A

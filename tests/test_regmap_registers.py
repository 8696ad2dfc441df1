"""The register map declaration: Table 3-10, the manual's examples, resets, accesses and the checked-in outputs."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from supi3 import regmap, tables
from supi3.errors import Supi3Error
from supi3.regmap import (
    CHECKED_IN,
    COMMAND_BYTE,
    INIT_BYTE,
    INTERRUPT_SOURCES,
    REGISTER_MAP,
    Access,
    AccessDirection,
    ByteLayout,
    Field,
    Port,
    Register,
    RegisterMap,
    RegisterMapError,
    Reset,
    decode_command,
    decode_set,
    encode_command,
    render,
)

ROOT = Path(__file__).resolve().parents[1]
BYTES = st.integers(0, 0xFF)

# ------------------------------------------------------------------------------------------------------------
# Generated files in the repository
# ------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(("fmt", "path"), CHECKED_IN.items())
def test_checked_in_file_is_current(fmt: str, path: Path) -> None:
    assert (ROOT / path).read_text(encoding="utf-8") == render(fmt), (
        f"{path} is stale: run python -m supi3.regmap --write-checked-in"
    )


# ------------------------------------------------------------------------------------------------------------
# Table 3-10: every address, both directions
# ------------------------------------------------------------------------------------------------------------


def test_every_address_has_one_write_and_one_read_port() -> None:
    keys = [(p.address, p.direction) for p in REGISTER_MAP.ports]
    assert sorted(keys) == sorted((a, d) for a in range(16) for d in AccessDirection)
    assert list(REGISTER_MAP.addresses) == list(range(16))


@pytest.mark.parametrize("row", tables.ADDRESS_MAP, ids=lambda r: str(r.address))
def test_port_titles_are_table_3_10(row: tables.AddressRow) -> None:
    assert REGISTER_MAP.port(row.address, AccessDirection.WRITE).title == (row.write or "-")
    assert REGISTER_MAP.port(row.address, AccessDirection.READ).title == row.read


EXPECTED_ACCESS = {
    **dict.fromkeys(range(4), (Access.W, Access.R)),
    4: (Access.RESERVED_IGNORED, Access.RESERVED_IGNORED),
    5: (Access.RESERVED_IGNORED, Access.RESERVED_IGNORED),
    6: (Access.NO_EFFECT, Access.RESERVED_ZERO),
    7: (Access.W, Access.R),
    **dict.fromkeys(range(8, 12), (Access.NO_EFFECT, Access.R)),
    12: (Access.W, Access.R),
    13: (Access.W, Access.R),
    14: (Access.W, Access.RC),
    15: (Access.BLOCK_TRANSFER, Access.BLOCK_TRANSFER),
}


@pytest.mark.parametrize("address", range(16))
def test_access_semantics(address: int) -> None:
    write, read = (REGISTER_MAP.port(address, d) for d in (AccessDirection.WRITE, AccessDirection.READ))
    assert (write.access, read.access) == EXPECTED_ACCESS[address]
    shared = write.register is not None and write.register is read.register
    assert shared == (address in (12, 13)), "only ID and SET read back what was written (3.4.11)"


def test_register_names_and_lookup() -> None:
    assert [r.name for r in REGISTER_MAP.registers] == [
        "IN0",
        "OUT0",
        "IN1",
        "OUT1",
        "IN2",
        "OUT2",
        "IN3",
        "OUT3",
        "ALARM",
        "PCMD",
        "LENGTH_OUT",
        "LENGTH_BRANCH",
        "POWER_IN",
        "POWER_OUT_BRANCH",
        "ID",
        "SET",
        "IRQ_EN",
        "IRQ_EVT",
    ]
    assert REGISTER_MAP.register("SET") is REGISTER_MAP.port(13, AccessDirection.WRITE).register
    with pytest.raises(RegisterMapError, match="no register 'NOPE'"):
        REGISTER_MAP.register("NOPE")
    with pytest.raises(RegisterMapError, match="outside the 16-byte area"):
        REGISTER_MAP.port(16, AccessDirection.READ)


def test_only_the_event_register_clears_on_read() -> None:
    masks = {(p.address, p.direction): p.clear_on_read_mask for p in REGISTER_MAP.ports if p.clear_on_read_mask}
    assert masks == {(14, AccessDirection.READ): 0x7F}, "events clear, the live I/O access bit D7 does not"


# ------------------------------------------------------------------------------------------------------------
# Resets (3.4.7)
# ------------------------------------------------------------------------------------------------------------


def test_every_reset_value_is_zero() -> None:
    assert all(r.reset == 0 for r in REGISTER_MAP.registers)


def test_reset_classes() -> None:
    data = {f"{d}{n}" for d in ("IN", "OUT") for n in range(4)}
    assert {r.name for r in REGISTER_MAP.cleared_by(Reset.POWER_UP)} == {r.name for r in REGISTER_MAP.registers}
    assert {r.name for r in REGISTER_MAP.cleared_by(Reset.INTERBUS)} == data
    assert REGISTER_MAP.cleared_by(Reset.SAS_INIT) == ()


# ------------------------------------------------------------------------------------------------------------
# The manual's examples, decoded through the declaration
# ------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("byte", "rd", "wr", "address", "block"),
    [
        (0x4D, False, True, 13, False),  # Fig. 3-10: write the SET register
        (0x4C, False, True, 12, False),  # Fig. 3-11: write the ID code register
        (0xCF, True, True, 15, True),  # 3.4.6: block transfer
        (0x8F, True, False, 15, True),  # Fig. 3-12: Intel block transfer of a 24-bit output device
    ],
)
def test_manual_command_bytes(byte: int, rd: bool, wr: bool, address: int, block: bool) -> None:
    command = decode_command(byte)
    assert (command.rd, command.wr, command.address, command.block_transfer) == (rd, wr, address, block)
    assert encode_command(address, rd=rd, wr=wr) == byte


def test_every_register_is_a_name_of_the_package() -> None:
    """``from supi3.regmap import SET`` gives the declared register, as ``SUPI3_SET_ADDR`` names it in C."""
    for register in REGISTER_MAP.registers:
        assert getattr(regmap, register.name) is register
        assert register.name in regmap.__all__
    assert regmap.BLOCK_ADDRESS == tables.BLOCK_TRANSFER_COMMAND & COMMAND_BYTE.field("A").mask == 15


def test_manual_command_targets() -> None:
    write = AccessDirection.WRITE
    assert REGISTER_MAP.port(decode_command(0x4D).address, write).register is REGISTER_MAP.register("SET")
    assert REGISTER_MAP.port(decode_command(0x4C).address, write).register is REGISTER_MAP.register("ID")
    assert COMMAND_BYTE.constant("BLOCK_TRANSFER").value == tables.BLOCK_TRANSFER_COMMAND == 0xCF


def test_set_82h_is_an_io_device_of_one_byte() -> None:
    config = decode_set(0x82)
    assert config.pcp_n and not config.extreg
    assert REGISTER_MAP.register("SET").field("CL").extract(0x82) == 0b010
    assert config.length.code == "01001" and config.length.text == "1 byte" and config.length.bits == 8
    set_register = REGISTER_MAP.register("SET")
    assert set_register.encode(PCP_N=1, CL=set_register.field("CL").value("LEN_1_BYTE").value) == 0x82


def test_set_with_external_registers_takes_the_full_length_code() -> None:
    config = decode_set(REGISTER_MAP.register("SET").encode(EXTREG=1, LENGTH_CODE=0b10010))
    assert config.extreg and config.length.text == "16 words"


@pytest.mark.parametrize("byte", range(256))
def test_set_decodes_every_byte_but_reserved_cl(byte: int) -> None:
    set_register = REGISTER_MAP.register("SET")
    reserved = not set_register.field("EXTREG").extract(byte) and set_register.field("CL").extract(byte) >= 0b110
    if reserved:
        with pytest.raises(RegisterMapError, match="reserved"):
            decode_set(byte)
    else:
        assert decode_set(byte).length.code in {lc.code for lc in tables.LENGTH_CODES}


@pytest.mark.parametrize("abbreviated", tables.ABBREVIATED_LENGTHS, ids=lambda a: a.cl)
def test_every_cl_code_follows_table_3_12(abbreviated: tables.AbbreviatedLength) -> None:
    assert decode_set(int(abbreviated.cl, 2)).length.code == abbreviated.length_code


def test_init_byte_values() -> None:
    assert INIT_BYTE.constant("INTEL").value == tables.INIT_BYTE_INTEL
    assert INIT_BYTE.constant("MOTOROLA").value == tables.INIT_BYTE_MOTOROLA
    assert INIT_BYTE.decode(0x81) == {"MODE_MSB": 1, "MODE_LSB": 1}
    assert INIT_BYTE.decode(0x00) == {"MODE_MSB": 0, "MODE_LSB": 0}


def test_interrupt_bits() -> None:
    enable, event = REGISTER_MAP.register("IRQ_EN"), REGISTER_MAP.register("IRQ_EVT")
    assert enable.field("VALID").lsb == event.field("VALID").lsb == 4  # 3.4.14
    assert event.field("IO_ACCESS").lsb == 7 and event.field("IO_ACCESS").access is Access.R  # Table 3-5
    assert sorted(s.bit for s in INTERRUPT_SOURCES) == list(range(7))
    for source in INTERRUPT_SOURCES:
        assert enable.field(source.name).mask == event.field(source.name).mask == 1 << source.bit


def test_optical_registers() -> None:
    for name in ("LENGTH_OUT", "LENGTH_BRANCH"):
        register = REGISTER_MAP.register(name)
        assert register.decode(0xFF) == {"LENGTH": 63, "MEDIUM": 1, "ENABLE": 1}  # Table 1-5: 63 = 400 m..20 km
        assert register.field("MEDIUM").value("GLASS").value == 1
    assert REGISTER_MAP.register("POWER_IN").decode(0x8F) == {"LEVEL": 15, "ENABLE": 1}
    assert REGISTER_MAP.register("POWER_OUT_BRANCH").decode(0xF1) == {"OUT_LEVEL": 1, "BRANCH_LEVEL": 15}


# ------------------------------------------------------------------------------------------------------------
# The vocabulary: fields, layouts, validation
# ------------------------------------------------------------------------------------------------------------


@given(byte=BYTES)
def test_decode_encode_round_trip(byte: int) -> None:
    for layout in (*REGISTER_MAP.registers, COMMAND_BYTE, INIT_BYTE):
        assert layout.encode(**layout.decode(byte)) == byte & layout.mask


@given(byte=BYTES, value=st.integers(0, 0x3F))
def test_field_insert_extract(byte: int, value: int) -> None:
    length = REGISTER_MAP.register("LENGTH_OUT").field("LENGTH")
    updated = length.insert(byte, value)
    assert length.extract(updated) == value and updated & ~length.mask == byte & ~length.mask


def test_command_byte_rejects_reserved_bits_and_bad_addresses() -> None:
    with pytest.raises(RegisterMapError, match="reserved bits 30h"):
        decode_command(0x7D)
    with pytest.raises(RegisterMapError, match="does not fit"):
        encode_command(16, wr=True)
    with pytest.raises(RegisterMapError, match="not a byte"):
        decode_command(0x100)


def test_declaration_errors_are_supi3_errors() -> None:
    assert issubclass(RegisterMapError, Supi3Error)
    with pytest.raises(RegisterMapError, match="do not fit in a byte"):
        Field("X", 6, 3)
    with pytest.raises(RegisterMapError, match="overlaps"):
        ByteLayout(name="L", title="t", ref="r", fields=(Field("A", 0, 4), Field("B", 3, 2)))
    with pytest.raises(RegisterMapError, match="not inside"):
        ByteLayout(name="L", title="t", ref="r", fields=(Field("A", 0, 2), Field("B", 1, 2, overlays="A")))
    with pytest.raises(RegisterMapError, match="needs more than"):
        Field("X", 0, 1, values=(REGISTER_MAP.register("SET").field("CL").values[-1],))
    register = Register(name="R", title="t", ref="r", address=1, cleared_by=frozenset())
    with pytest.raises(RegisterMapError, match="is at 1, not 2"):
        Port(2, AccessDirection.READ, Access.R, "t", register)
    with pytest.raises(RegisterMapError, match="not a write access"):
        Port(1, AccessDirection.WRITE, Access.RC, "t", register)
    with pytest.raises(RegisterMapError, match="exactly one write port"):
        RegisterMap(4, REGISTER_MAP.ports[:-1], COMMAND_BYTE, INIT_BYTE)
    renamed = [p if p.register is None or p.register.name != "ID"
               else dataclasses.replace(p, register=dataclasses.replace(p.register, name="SET"))
               for p in REGISTER_MAP.ports]  # fmt: skip
    with pytest.raises(RegisterMapError, match="two registers called 'SET'"):
        RegisterMap(4, tuple(renamed), COMMAND_BYTE, INIT_BYTE)
    with pytest.raises(RegisterMapError, match=r"no register \['SET'\]"):
        REGISTER_MAP.register(["SET"])  # type: ignore[arg-type]

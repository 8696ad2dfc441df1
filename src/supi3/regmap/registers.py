"""The SUPI 3 OPC serial µP interface, declared once: the 16-address map, its registers, the interface bytes.

Ref: IBS SUPI 3 OPC UM E rev. 05, 3.4.3-3.4.14, Tables 3-8 and 3-10 to 3-13. The bit layouts of the manual's
missing figures (3-8, 3-14 to 3-20) are project decisions: each is one named constant below and one entry of
``docs/assumptions/regmap.md``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from functools import cache
from typing import Final

from supi3.regmap.core import (
    Access,
    AccessDirection,
    Assumption,
    ByteLayout,
    Enumerator,
    Field,
    Port,
    Register,
    RegisterMap,
    RegisterMapError,
    Reset,
    integer,
)
from supi3.tables import (
    ABBREVIATED_LENGTHS,
    ADDRESS_MAP,
    BLOCK_TRANSFER_COMMAND,
    INIT_BYTE_INTEL,
    INIT_BYTE_MOTOROLA,
    LENGTH_CODE_BY_VALUE,
    LengthCode,
)

# ------------------------------------------------------------------------------------------------------------
# Decisions (docs/assumptions/regmap.md): one constant each
# ------------------------------------------------------------------------------------------------------------

ADDRESS_BITS: Final[int] = 4
"""A3..0 address 16 bytes (3.4.7)."""

COMMAND_RD_BIT: Final[int] = 7
"""Command byte RD bit: 8Fh is the Intel block-transfer command of a 24-bit *output* device (Fig. 3-12)."""
COMMAND_WR_BIT: Final[int] = 6
"""Command byte WR bit: 4Dh writes address 13 (Fig. 3-10), 4Ch writes address 12 (Fig. 3-11)."""
COMMAND_ADDRESS_LSB: Final[int] = 0
"""Command byte A3..0 in bits 3..0: 4Dh -> 13, 4Ch -> 12, CFh and 8Fh -> 15."""

INIT_MODE_BITS: Final[tuple[int, int]] = (7, 0)
"""The mode bit of the initialization byte, reflected into the MSB and the LSB (Table 3-8: 81h = Intel)."""

SET_PCP_N_BIT: Final[int] = 7
"""SET /PCP bit: 82h is "an I/O device" (Fig. 3-10), so the bit set in 82h beside CL = 010 is /PCP."""
SET_EXTREG_BIT: Final[int] = 6
"""SET ExtReg bit: 0 in 82h, which uses the abbreviated code; placed beside /PCP, bit 5 left reserved."""
SET_LENGTH_LSB: Final[int] = 0
"""SET length code ID12..8 in bits 4..0 (ExtReg = 1), CL2..0 in bits 2..0 (ExtReg = 0): 82h has CL = 010."""
SET_LENGTH_WIDTH: Final[int] = 5
SET_CL_WIDTH: Final[int] = 3

OPTICAL_LENGTH_WIDTH: Final[int] = 6
"""Reads 8/9: the measured length, 0..62 and 63 = 400 m to 20 km (Table 1-5), in bits 5..0."""
OPTICAL_MEDIUM_BIT: Final[int] = 6
"""Reads 8/9: optical medium bit (0 polymer fibre, 1 glass fibre) above the length (3.4.12, Fig. 3-16)."""
OPTICAL_ENABLE_BIT: Final[int] = 7
"""Reads 8/9/10: enable status of the optical regulation (3.4.12, 3.4.13) in the MSB."""
POWER_LEVEL_WIDTH: Final[int] = 4
"""Power levels 1..15 of 15 (1.6.1, Fig. 1-10) need 4 bits."""
POWER_OUT_LSB: Final[int] = 0
"""Read 11: outgoing-interface power level in the low nibble (the outgoing interface has the lower length
register, 8), the branch power level in the high nibble; no enable bit fits (Fig. 3-18)."""
POWER_BRANCH_LSB: Final[int] = 4

IO_ACCESS_BIT: Final[int] = 7
"""Interrupt event D7: the I/O access (polling) bit, also on MFP1 (3.4.14, Table 3-5)."""


@dataclass(frozen=True)
class InterruptSource:
    """An interrupt source: one bit, the same in the enable (write 14) and the event register (read 14)."""

    name: str
    bit: int
    doc: str


INTERRUPT_SOURCES: Final[tuple[InterruptSource, ...]] = (
    InterruptSource("PCMD", 6, "Processor command: a management message arrived from the master (3.4.9)."),
    InterruptSource("INVALID", 5, "Invalid data cycle: data is from the last valid cycle; rewrite IN (Table 3-13)."),
    InterruptSource("VALID", 4, "Valid data cycle ended: OUT data can be read, IN data written (Table 3-13, 3.4.14)."),
    InterruptSource("ID_CYCLE", 3, "ID cycle ended: write IN data for the first data cycle (Table 3-13)."),
    InterruptSource("IB_RESET", 2, "INTERBUS reset, or layer-2 watchdog reset of process data (Table 3-13)."),
    InterruptSource("PCP_RX", 1, "PCP receive: a new communication word can be read (Table 3-13)."),
    InterruptSource("PCP_TX", 0, "PCP send: a new communication word can be written (Table 3-13)."),
)
"""Table 3-13 in manual order from D5 down to D0, with D4 = valid data cycle fixed by 3.4.14; the processor
command interrupt of 3.4.9 takes D6, just below the I/O access bit D7."""

# References to the decisions above (and to UP-n of docs/assumptions/upif.md), for every generated output: the C
# header names them beside each macro that rests on one.
RM_1: Final[Assumption] = Assumption("RM-1", "command byte RD = bit 7, WR = bit 6, A3..0 = bits 3..0")
RM_2: Final[Assumption] = Assumption("RM-2", "the command byte with A = 15 itself starts the block transfer")
RM_3: Final[Assumption] = Assumption("RM-3", "init byte mode bit reflected into bits 7 and 0")
RM_4: Final[Assumption] = Assumption("RM-4", "SET /PCP = bit 7, ExtReg = bit 6, ID12..8 = bits 4..0, CL = bits 2..0")
RM_5: Final[Assumption] = Assumption("RM-5", "reads 8/9 LENGTH = bits 5..0, MEDIUM = bit 6, ENABLE = bit 7")
RM_6: Final[Assumption] = Assumption(
    "RM-6", "read 10 LEVEL = bits 3..0, ENABLE = bit 7; read 11 OUT_LEVEL = bits 3..0, BRANCH_LEVEL = bits 7..4"
)
RM_7: Final[Assumption] = Assumption("RM-7", "interrupt bits D6..D0 = PCMD, INVALID, VALID, ID, RESET, PCP RX, PCP TX")
RM_8: Final[Assumption] = Assumption("RM-8", "I/O access bit D7 is live and not cleared by reading")
UP_21: Final[Assumption] = Assumption("UP-21", "sub-byte data lengths use the low bits of byte 0")

DATA_RESETS: Final[frozenset[Reset]] = frozenset({Reset.POWER_UP, Reset.INTERBUS})
"""IN/OUT data registers are cleared by power-up reset and by INTERBUS reset (3.4.7, Table 3-13)."""
OTHER_RESETS: Final[frozenset[Reset]] = frozenset({Reset.POWER_UP})
"""Every other register is cleared by power-up reset only (3.4.7)."""

# ------------------------------------------------------------------------------------------------------------
# Layouts
# ------------------------------------------------------------------------------------------------------------


def _bit(
    name: str, bit: int, doc: str, values: tuple[Enumerator, ...] = (), assumptions: tuple[Assumption, ...] = ()
) -> Field:
    return Field(name, bit, 1, doc, values=values, assumptions=assumptions)


def _title(address: int, direction: AccessDirection) -> str:
    """The manual's name of one cell of Table 3-10, "-" where the table has none."""
    row = ADDRESS_MAP[address]
    text = row.write if direction is AccessDirection.WRITE else row.read
    return text or "-"


def _length_name(text: str) -> str:
    """An identifier for a Table 3-12 length: "4 bits (1 nibble)" -> "LEN_4_BITS"."""
    return "LEN_" + re.sub(r"\W+", "_", text.split(" (")[0]).upper()


COMMAND_BYTE: Final[ByteLayout] = ByteLayout(
    name="CMD",
    title="Command byte",
    ref="3.4.4, 3.4.6, Fig. 3-8, Figs. 3-10 to 3-12",
    doc="First byte of every access: direction of the following data access and its address. With address 15 "
    "it starts a block transfer; RD and WR then have no meaning (3.4.6). Bits 5..4 are reserved (write 0).",
    fields=(
        _bit(
            "RD",
            COMMAND_RD_BIT,
            "The data access reads from the SUPI 3 (Motorola: both bits = full duplex).",
            assumptions=(RM_1,),
        ),
        _bit(
            "WR",
            COMMAND_WR_BIT,
            "The data access writes to the SUPI 3 (Motorola: both bits = full duplex).",
            assumptions=(RM_1,),
        ),
        Field(
            "A",
            COMMAND_ADDRESS_LSB,
            ADDRESS_BITS,
            "Binary address A3..0 of the following data access.",
            assumptions=(RM_1,),
        ),
    ),
    constants=(
        Enumerator(
            "BLOCK_TRANSFER", BLOCK_TRANSFER_COMMAND, "Start a block transfer (3.4.6): RD, WR, A = 15.", (RM_1, RM_2)
        ),
    ),
)
"""The command byte (3.4.4): not addressable, but firmware builds it for every access."""

INIT_BYTE: Final[ByteLayout] = ByteLayout(
    name="INIT",
    title="Initialization byte",
    ref="3.4.3, Table 3-8",
    doc="First byte after power-up or SAS_INIT. The mode bit is reflected into MSB and LSB so that either "
    "bit order reads it; any other value is ignored and disables data transmission until power-up reset or "
    "SAS_INIT.",
    fields=tuple(
        _bit(f"MODE_{end}", bit, "Mode bit: 0 = SPI (Motorola), 1 = Intel.", assumptions=(RM_3,))
        for end, bit in zip(("MSB", "LSB"), INIT_MODE_BITS, strict=True)
    ),
    constants=(
        Enumerator("MOTOROLA", INIT_BYTE_MOTOROLA, "SPI interface (Motorola).", (RM_3,)),
        Enumerator("INTEL", INIT_BYTE_INTEL, "Synchronous serial interface (Intel).", (RM_3,)),
    ),
)
"""The initialization byte (Table 3-8)."""


def _data_register(
    name: str,
    address: int,
    direction: AccessDirection,
    resets: frozenset[Reset],
    ref: str,
    doc: str = "",
    assumptions: tuple[Assumption, ...] = (),
) -> Register:
    return Register(
        name=name,
        title=_title(address, direction),
        ref=ref,
        doc=doc,
        address=address,
        cleared_by=resets,
        fields=(Field("DATA", 0, 8, "Data byte.", assumptions=assumptions),),
    )


_DATA_DOC: Final[str] = (
    "Address 0 holds the most significant byte, address 3 the least; IN bytes cannot be read back (3.4.8)."
)

_BYTE_0: Final[dict[int, tuple[Assumption, ...]]] = {0: (UP_21,)}
"""Byte 0 also carries the data of a 2-bit or nibble length, in its low bits (UP-21)."""
IN_BYTES: Final[tuple[Register, ...]] = tuple(
    _data_register(f"IN{n}", n, AccessDirection.WRITE, DATA_RESETS, "3.4.8", _DATA_DOC, _BYTE_0.get(n, ()))
    for n in range(4)
)
OUT_BYTES: Final[tuple[Register, ...]] = tuple(
    _data_register(f"OUT{n}", n, AccessDirection.READ, DATA_RESETS, "3.4.8", _DATA_DOC, _BYTE_0.get(n, ()))
    for n in range(4)
)
IN0, IN1, IN2, IN3 = IN_BYTES
OUT0, OUT1, OUT2, OUT3 = OUT_BYTES
_MANAGEMENT_DOC: Final[str] = "Management channel (firmware 4.0 or later), reserved for future applications (3.4.9)."
ALARM: Final[Register] = _data_register("ALARM", 7, AccessDirection.WRITE, OTHER_RESETS, "3.4.9", _MANAGEMENT_DOC)
PCMD: Final[Register] = _data_register("PCMD", 7, AccessDirection.READ, OTHER_RESETS, "3.4.9", _MANAGEMENT_DOC)

_MEDIUM_VALUES: Final[tuple[Enumerator, ...]] = (
    Enumerator("POLYMER", 0, "Polymer fibre (length resolution 12 m)."),
    Enumerator("GLASS", 1, "Glass fibre (length resolution 200 m)."),
)
_ENABLE_DOC: Final[str] = (
    "Enable status: 1 = optical initialization detected a regulated device; 0 = it did not, or the interface "
    "is not in use."
)


def _length_register(name: str, address: int) -> Register:
    return Register(
        name=name,
        title=_title(address, AccessDirection.READ),
        ref="3.4.12, Fig. 3-16, Table 1-5",
        address=address,
        cleared_by=OTHER_RESETS,
        fields=(
            Field(
                "LENGTH",
                0,
                OPTICAL_LENGTH_WIDTH,
                "Measured path length: 0..62, 63 = 400 m to 20 km.",
                assumptions=(RM_5,),
            ),
            _bit("MEDIUM", OPTICAL_MEDIUM_BIT, "Optical medium.", _MEDIUM_VALUES, (RM_5,)),
            _bit("ENABLE", OPTICAL_ENABLE_BIT, _ENABLE_DOC, assumptions=(RM_5,)),
        ),
    )


LENGTH_OUT: Final[Register] = _length_register("LENGTH_OUT", 8)
LENGTH_BRANCH: Final[Register] = _length_register("LENGTH_BRANCH", 9)
_LEVEL_DOC: Final[str] = "Transmit power level, 1..15 of 15."
POWER_IN: Final[Register] = Register(
    name="POWER_IN",
    title=_title(10, AccessDirection.READ),
    ref="3.4.13, Fig. 3-17",
    address=10,
    cleared_by=OTHER_RESETS,
    fields=(
        Field("LEVEL", 0, POWER_LEVEL_WIDTH, _LEVEL_DOC, assumptions=(RM_6,)),
        _bit("ENABLE", OPTICAL_ENABLE_BIT, _ENABLE_DOC, assumptions=(RM_6,)),
    ),
)
POWER_OUT_BRANCH: Final[Register] = Register(
    name="POWER_OUT_BRANCH",
    title=_title(11, AccessDirection.READ),
    ref="3.4.13, Fig. 3-18",
    address=11,
    cleared_by=OTHER_RESETS,
    doc="Enable statuses of these interfaces are in LENGTH_OUT and LENGTH_BRANCH.",
    fields=(
        Field("OUT_LEVEL", POWER_OUT_LSB, POWER_LEVEL_WIDTH, "Outgoing interface: " + _LEVEL_DOC, assumptions=(RM_6,)),
        Field("BRANCH_LEVEL", POWER_BRANCH_LSB, POWER_LEVEL_WIDTH, "Bus branch: " + _LEVEL_DOC, assumptions=(RM_6,)),
    ),
)
ID: Final[Register] = Register(
    name="ID",
    title=_title(12, AccessDirection.WRITE),
    ref="3.4.10, 3.4.3, Table A-3",
    address=12,
    cleared_by=OTHER_RESETS,
    doc="Written during initialization, read back unchanged (3.4.11). Until SET is written INTERBUS sees the "
    "µP_Not_Ready code of C[4..0] instead (3.4.1).",
    fields=(Field("CODE", 0, 8, "ID code (INTERBUS Club ID code specification, Table A-3)."),),
)
SET: Final[Register] = Register(
    name="SET",
    title=_title(13, AccessDirection.WRITE),
    ref="3.4.11, Figs. 3-14 and 3-15, Tables 3-11 and 3-12",
    address=13,
    cleared_by=OTHER_RESETS,
    doc="Device type and data length, written during initialization only and read back unchanged. 82h = I/O "
    "device of 1 byte (3.4.5). Bit 5 is reserved (write 0).",
    fields=(
        _bit(
            "PCP_N",
            SET_PCP_N_BIT,
            "/PCP: 1 = I/O device (IN bytes 0, 1 sent every cycle); 0 = PCP device (IN "
            "bytes 0, 1 erased after transfer). No meaning when EXTREG = 1.",
            assumptions=(RM_4,),
        ),
        _bit(
            "EXTREG",
            SET_EXTREG_BIT,
            "1 = external register expansion, complete length code in LENGTH_CODE; 0 = abbreviated length code in CL.",
            assumptions=(RM_4,),
        ),
        Field(
            "LENGTH_CODE",
            SET_LENGTH_LSB,
            SET_LENGTH_WIDTH,
            "ID12..8, the complete length code of Table 3-11 (EXTREG = 1).",
            assumptions=(RM_4,),
        ),
        Field(
            "CL",
            SET_LENGTH_LSB,
            SET_CL_WIDTH,
            "CL2..0, the abbreviated length code of Table 3-12 (EXTREG = 0); 110 and 111 are reserved.",
            overlays="LENGTH_CODE",
            values=tuple(Enumerator(_length_name(a.text), int(a.cl, 2), a.text) for a in ABBREVIATED_LENGTHS),
            assumptions=(RM_4,),
        ),
    ),
)
IRQ_EN: Final[Register] = Register(
    name="IRQ_EN",
    title=_title(14, AccessDirection.WRITE),
    ref="3.4.14, Fig. 3-19, Table 3-13",
    address=14,
    cleared_by=OTHER_RESETS,
    doc="1 enables the interrupt source of the same bit in IRQ_EVT. Bit 7 is reserved (write 0).",
    fields=tuple(_bit(s.name, s.bit, s.doc, assumptions=(RM_7,)) for s in INTERRUPT_SOURCES),
)
IRQ_EVT: Final[Register] = Register(
    name="IRQ_EVT",
    title=_title(14, AccessDirection.READ),
    ref="3.4.14, Fig. 3-20, Table 3-13",
    address=14,
    cleared_by=OTHER_RESETS,
    doc="A set bit is a pending event; /IRQ (MFP3) is low while one is pending. Reading clears "
    "the events and releases /IRQ.",
    fields=(
        Field(
            "IO_ACCESS",
            IO_ACCESS_BIT,
            1,
            "I/O access (polling) bit, live and not cleared by reading, also on MFP1: 1 = no access now; 0 = "
            "the data registers may be accessed for the next 30 bit periods (Fig. 3-22).",
            access=Access.R,
            assumptions=(RM_7, RM_8),
        ),
        *(_bit(s.name, s.bit, s.doc, assumptions=(RM_7,)) for s in INTERRUPT_SOURCES),
    ),
)

# ------------------------------------------------------------------------------------------------------------
# The map: Table 3-10, one port per address and direction
# ------------------------------------------------------------------------------------------------------------


def _port(address: int, direction: AccessDirection, access: Access, register: Register | None = None) -> Port:
    return Port(address, direction, access, _title(address, direction), register)


def _ports() -> tuple[Port, ...]:
    w, r = AccessDirection.WRITE, AccessDirection.READ
    by_address: dict[int, tuple[Port, Port]] = {
        **{n: (_port(n, w, Access.W, IN_BYTES[n]), _port(n, r, Access.R, OUT_BYTES[n])) for n in range(4)},
        **{n: (_port(n, w, Access.RESERVED_IGNORED), _port(n, r, Access.RESERVED_IGNORED)) for n in (4, 5)},
        6: (_port(6, w, Access.NO_EFFECT), _port(6, r, Access.RESERVED_ZERO)),
        7: (_port(7, w, Access.W, ALARM), _port(7, r, Access.R, PCMD)),
        **{
            reg.address: (_port(reg.address, w, Access.NO_EFFECT), _port(reg.address, r, Access.R, reg))
            for reg in (LENGTH_OUT, LENGTH_BRANCH, POWER_IN, POWER_OUT_BRANCH)
        },
        **{
            reg.address: (_port(reg.address, w, Access.W, reg), _port(reg.address, r, Access.R, reg))
            for reg in (ID, SET)
        },
        14: (_port(14, w, Access.W, IRQ_EN), _port(14, r, Access.RC, IRQ_EVT)),
        15: (_port(15, w, Access.BLOCK_TRANSFER), _port(15, r, Access.BLOCK_TRANSFER)),
    }
    return tuple(p for address in sorted(by_address) for p in by_address[address])


REGISTER_MAP: Final[RegisterMap] = RegisterMap(ADDRESS_BITS, _ports(), COMMAND_BYTE, INIT_BYTE)
"""The serial µP interface of the SUPI 3 OPC (Table 3-10): import this, never a copy of it."""

BLOCK_ADDRESS: Final[int] = next(
    p.address for p in REGISTER_MAP.ports if p.access is Access.BLOCK_TRANSFER and p.direction is AccessDirection.WRITE
)
"""The address whose command byte starts a block transfer (15, 3.4.6), as :data:`REGISTER_MAP` declares it."""

# ------------------------------------------------------------------------------------------------------------
# Decoding the interface bytes and the SET register
# ------------------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class CommandByte:
    """A decoded command byte (3.4.4)."""

    rd: bool
    wr: bool
    address: int

    @property
    def block_transfer(self) -> bool:
        """Address 15 starts a block transfer whatever RD and WR say (3.4.6)."""
        return REGISTER_MAP.port(self.address, AccessDirection.WRITE).access is Access.BLOCK_TRANSFER


def encode_command(address: int, *, rd: bool = False, wr: bool = False) -> int:
    """Build a command byte: ``encode_command(13, wr=True) == 0x4D`` (Fig. 3-10).

    Raises
    ------
    RegisterMapError
        If ``address`` is no integer from 0 to 15, or ``rd`` or ``wr`` is no bool.
    """
    for name, flag in (("rd", rd), ("wr", wr)):
        if not isinstance(flag, bool):
            raise RegisterMapError(f"{name} must be True or False, not {flag!r:.40}")
    return _encode_command(integer("field A", address), rd, wr)


@cache  # a pure function of 64 possible arguments, on the µP interface's hot path: checked before, so 1 is no True
def _encode_command(address: int, rd: bool, wr: bool) -> int:
    return COMMAND_BYTE.encode(RD=int(rd), WR=int(wr), A=address)


def decode_command(byte: int) -> CommandByte:
    """Split a command byte into RD, WR and the address A3..0 (3.4.4).

    Raises
    ------
    RegisterMapError
        If ``byte`` is not a byte (an integer from 0 to 255) or sets a reserved bit (5 or 4).
    """
    return _decode_command(integer("CMD", byte))


@cache  # a pure function of a byte, on the µP interface's hot path: checked before, so True is no byte
def _decode_command(byte: int) -> CommandByte:
    fields = COMMAND_BYTE.decode(byte)
    if byte & ~COMMAND_BYTE.mask:
        raise RegisterMapError(f"command byte {byte:02X}h sets reserved bits {byte & ~COMMAND_BYTE.mask:02X}h")
    return CommandByte(bool(fields["RD"]), bool(fields["WR"]), fields["A"])


@dataclass(frozen=True)
class SetConfig:
    """A decoded SET register (3.4.11)."""

    pcp_n: bool
    """/PCP: ``True`` for an I/O device, ``False`` for a PCP device (meaningless with ``extreg``)."""
    extreg: bool
    length: LengthCode
    """The complete length code (Table 3-11); the abbreviated code already decoded by Table 3-12."""


_CL_TO_LENGTH: Final[dict[int, int]] = {int(a.cl, 2): int(a.length_code, 2) for a in ABBREVIATED_LENGTHS}


def decode_set(byte: int) -> SetConfig:
    """Decode a SET register value: ``decode_set(0x82)`` is an I/O device of 1 byte (3.4.5, Table 3-12).

    Raises
    ------
    RegisterMapError
        If ``byte`` is not a byte, or has ExtReg = 0 and a reserved CL code (110, 111: no row in Table 3-12).
    """
    fields = SET.decode(byte)
    extreg = bool(fields["EXTREG"])
    if extreg:
        code = fields["LENGTH_CODE"]
    else:
        cl = SET.field("CL").extract(byte)
        if cl not in _CL_TO_LENGTH:
            raise RegisterMapError(f"SET {byte:02X}h: CL = {cl:03b} is reserved (Table 3-12)")
        code = _CL_TO_LENGTH[cl]
    return SetConfig(bool(fields["PCP_N"]), extreg, LENGTH_CODE_BY_VALUE[code])

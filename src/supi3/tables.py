"""The SUPI 3 OPC user manual's tables as data (IBS SUPI 3 OPC UM E, revision 05, 04/2009).

This module is the single place where the manual's tables live. Everything else in supi3 (the configuration
decoder, the register map, the model, the RTL, the SDK headers and the documentation) is derived from it.
Each table carries the manual's table number; where the manual's figures are missing and the project had to
decide, the decision is recorded in ``docs/assumptions.md`` and kept as one named constant here or in the
module that owns it.

Bit strings are written MSB first, exactly as the manual prints them (``"01011"`` is C4=0, C3=1, ..., C0=1).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum
from typing import Final

from supi3.errors import ConfigurationError

# ----------------------------------------------------------------------------------------------------------------
# Operating modes: Tables 2-4, 2-5, 2-6 and 2-7
# ----------------------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ModeRow:
    """One row of an operating-mode table (Tables 2-4 to 2-7).

    ``mfp`` is MFP[15..12] as printed, or ``None`` where the row says "See Table 3-2" (MFP[15..12] are then
    I/O pins, not configuration inputs) or, in Table 2-7, where MFP[15..12] are bus-terminal signals (Table 2-8).
    ``length_code`` is the "Data length (ID12..8)" column and ``function`` the manual's function text.
    """

    table: str
    c: str
    mfp: str | None
    length_code: str
    id_code: int
    function: str


MODE_ROWS: Final[tuple[ModeRow, ...]] = (
    ModeRow("2-4", "01000", None, "01001", 0xBF, "LB-MR, 8 IN/OUT"),
    ModeRow("2-4", "01001", None, "00001", 0xBE, "LB-MR, 16 IN"),
    ModeRow("2-4", "01010", None, "00001", 0xBD, "LB-MR, 16 OUT"),
    ModeRow("2-4", "01011", "0000", "01101", 0xBF, "LB-MR, 2 IN/OUT"),
    ModeRow("2-4", "01011", "0001", "01101", 0xBE, "LB-MR, 2 IN"),
    ModeRow("2-4", "01011", "0010", "01101", 0xBD, "LB-MR, 2 OUT"),
    ModeRow("2-4", "01011", "0011", "01000", 0xBF, "LB-MR, 4 IN/OUT"),
    ModeRow("2-4", "01011", "0100", "01000", 0xBE, "LB-MR, 4 IN"),
    ModeRow("2-4", "01011", "0101", "01000", 0xBD, "LB-MR, 4 OUT"),
    ModeRow("2-4", "01011", "0110", "01001", 0xBE, "LB-MR, 8 IN"),
    ModeRow("2-4", "01011", "0111", "01001", 0xBD, "LB-MR, 8 OUT"),
    ModeRow("2-4", "01011", "1000", "00001", 0x7F, "LB-MR, SPI 16 IN/OUT"),
    ModeRow("2-4", "01011", "1001", "00001", 0x7D, "LB-MR, SPI 16 OUT"),
    ModeRow("2-4", "01011", "1010", "00001", 0x7E, "LB-MR, SPI 16 IN"),
    ModeRow("2-4", "01011", "1011", "00010", 0x7F, "LB-MR, SPI 32 IN/OUT"),
    ModeRow("2-4", "01011", "1100", "00010", 0x7E, "LB-MR, SPI 32 IN"),
    ModeRow("2-4", "01011", "1101", "00010", 0x7D, "LB-MR, SPI 32 OUT"),
    ModeRow("2-4", "01011", "1110", "00000", 0x78, "LB-MR, Init-µP"),
    ModeRow("2-5", "11000", None, "01001", 0xBF, "LBD-MR, 8 IN/8 OUT"),
    ModeRow("2-5", "11001", None, "00001", 0xBE, "LBD-MR, 16 IN"),
    ModeRow("2-5", "11010", None, "00001", 0xBD, "LBD-MR, 16 OUT"),
    ModeRow("2-5", "11011", "0000", "01101", 0xBF, "LBD-MR, 2 IN/2 OUT"),
    ModeRow("2-5", "11011", "0001", "01101", 0xBE, "LBD-MR, 2 IN"),
    ModeRow("2-5", "11011", "0010", "01101", 0xBD, "LBD-MR, 2 OUT"),
    ModeRow("2-5", "11011", "0011", "01000", 0xBF, "LBD-MR, 4 IN/4 OUT"),
    ModeRow("2-5", "11011", "0100", "01000", 0xBE, "LBD-MR, 4 IN"),
    ModeRow("2-5", "11011", "0101", "01000", 0xBD, "LBD-MR, 4 OUT"),
    ModeRow("2-5", "11011", "0110", "01001", 0xBE, "LBD-MR, 8 IN"),
    ModeRow("2-5", "11011", "0111", "01001", 0xBD, "LBD-MR, 8 OUT"),
    ModeRow("2-5", "11011", "1000", "00001", 0x7F, "LBD-MR, SPI 16 IN/16 OUT"),
    ModeRow("2-5", "11011", "1001", "00001", 0x7D, "LBD-MR, SPI 16 OUT"),
    ModeRow("2-5", "11011", "1010", "00001", 0x7E, "LBD-MR, SPI 16 IN"),
    ModeRow("2-5", "11011", "1011", "00010", 0x7F, "LBD-MR, SPI 32 IN/32 OUT"),
    ModeRow("2-5", "11011", "1100", "00010", 0x7E, "LBD-MR, SPI 32 IN"),
    ModeRow("2-5", "11011", "1101", "00010", 0x7D, "LBD-MR, SPI 32 OUT"),
    ModeRow("2-5", "11011", "1110", "00000", 0x78, "LBD-MR, Init-µP"),
    ModeRow("2-5", "11100", None, "01001", 0xB3, "LBD-OR, 8 IN/8 OUT"),
    ModeRow("2-5", "11101", None, "00001", 0xB2, "LBD-OR, 16 IN"),
    ModeRow("2-5", "11110", None, "00001", 0xB1, "LBD-OR, 16 OUT"),
    ModeRow("2-5", "11111", "0000", "01101", 0xB3, "LBD-OR, 2 IN/2 OUT"),
    ModeRow("2-5", "11111", "0001", "01101", 0xB2, "LBD-OR, 2 IN"),
    ModeRow("2-5", "11111", "0010", "01101", 0xB1, "LBD-OR, 2 OUT"),
    ModeRow("2-5", "11111", "0011", "01000", 0xB3, "LBD-OR, 4 IN/4 OUT"),
    ModeRow("2-5", "11111", "0100", "01000", 0xB2, "LBD-OR, 4 IN"),
    ModeRow("2-5", "11111", "0101", "01000", 0xB1, "LBD-OR, 4 OUT"),
    ModeRow("2-5", "11111", "0110", "01001", 0xB2, "LBD-OR, 8 IN"),
    ModeRow("2-5", "11111", "0111", "01001", 0xB1, "LBD-OR, 8 OUT"),
    ModeRow("2-5", "11111", "1000", "00001", 0x73, "LBD-OR, SPI 16 IN/16 OUT"),
    ModeRow("2-5", "11111", "1001", "00001", 0x72, "LBD-OR, SPI 16 IN"),
    ModeRow("2-5", "11111", "1010", "00001", 0x71, "LBD-OR, SPI 16 OUT"),
    ModeRow("2-5", "11111", "1011", "00010", 0x73, "LBD-OR, SPI 32 IN/32 OUT"),
    ModeRow("2-5", "11111", "1100", "00010", 0x72, "LBD-OR, SPI 32 IN"),
    ModeRow("2-5", "11111", "1101", "00010", 0x71, "LBD-OR, SPI 32 OUT"),
    ModeRow("2-5", "11111", "1110", "00000", 0x68, "LBD-OR, Init-µP"),
    ModeRow("2-6", "10000", None, "01001", 0x03, "RB, 8 IN/8 OUT"),
    ModeRow("2-6", "10001", None, "00001", 0x02, "RB, 16 IN"),
    ModeRow("2-6", "10010", None, "00001", 0x01, "RB, 16 OUT"),
    ModeRow("2-6", "10011", "0000", "01101", 0x03, "RB, 2 IN/2 OUT"),
    ModeRow("2-6", "10011", "0001", "01101", 0x02, "RB, 2 IN"),
    ModeRow("2-6", "10011", "0010", "01101", 0x01, "RB, 2 OUT"),
    ModeRow("2-6", "10011", "0011", "01000", 0x03, "RB, 4 IN/4 OUT"),
    ModeRow("2-6", "10011", "0100", "01000", 0x02, "RB, 4 IN"),
    ModeRow("2-6", "10011", "0101", "01000", 0x01, "RB, 4 OUT"),
    ModeRow("2-6", "10011", "0110", "01001", 0x02, "RB, 8 IN"),
    ModeRow("2-6", "10011", "0111", "01001", 0x01, "RB, 8 OUT"),
    ModeRow("2-6", "10011", "1000", "00001", 0x33, "RB, SPI 16 IN/16 OUT"),
    ModeRow("2-6", "10011", "1001", "00001", 0x31, "RB, SPI 16 OUT"),
    ModeRow("2-6", "10011", "1010", "00001", 0x32, "RB, SPI 16 IN"),
    ModeRow("2-6", "10011", "1011", "00010", 0x33, "RB, SPI 32 IN/32 OUT"),
    ModeRow("2-6", "10011", "1100", "00010", 0x32, "RB, SPI 32 IN"),
    ModeRow("2-6", "10011", "1101", "00010", 0x31, "RB, SPI 32 OUT"),
    ModeRow("2-6", "10011", "1110", "00000", 0x38, "RB, Init-µP"),
    ModeRow("2-7", "00000", None, "00000", 0x0C, "BK-RB (Remote bus)"),
    ModeRow("2-7", "00001", None, "00000", 0x08, "BK-LB (Local bus)"),
    ModeRow("2-7", "00010", None, "00000", 0x04, "BK-LBD (Local bus with diagnostics)"),
    ModeRow("2-7", "00011", None, "00000", 0x38, "BK-RB, Init-µP"),
    ModeRow("2-7", "00100", None, "00000", 0x38, "BK-LB, Init-µP"),
)
"""Every row of Tables 2-4 (LB-MR), 2-5 (LBD-MR, LBD-OR), 2-6 (RB) and 2-7 (bus terminal), in manual order."""

MODE_TABLE_TITLES: Final[dict[str, str]] = {
    "2-4": "Local bus operating modes without device-oriented diagnostics",
    "2-5": "Local bus operating modes with device-oriented diagnostics",
    "2-6": "Remote bus operating modes",
    "2-7": "Bus terminal operating modes",
}

# ----------------------------------------------------------------------------------------------------------------
# Length codes: Table 3-11 (repeated as Table A-5) and the abbreviated code of Table 3-12
# ----------------------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class LengthCode:
    """One row of Table 3-11 / A-5: a 5-bit length code ID12..ID8 and the data length it stands for."""

    code: str
    text: str
    """The manual's wording ("2 words", "1 nibble", "Reserved")."""
    bits: int | None
    """Data length in bits, ``None`` for a reserved code."""
    firmware: str | None
    """Minimum INTERBUS master firmware version that supports the length, where the table gives one."""


def _lc(code: str, text: str, bits: int | None, firmware: str | None = None) -> LengthCode:
    return LengthCode(code, text, bits, firmware)


LENGTH_CODES: Final[tuple[LengthCode, ...]] = (
    _lc("00000", "0 words", 0),
    _lc("00001", "1 word", 16),
    _lc("00010", "2 words", 32),
    _lc("00011", "3 words", 48),
    _lc("00100", "4 words", 64),
    _lc("00101", "5 words", 80),
    _lc("00110", "8 words", 128),
    _lc("00111", "9 words", 144),
    _lc("01000", "1 nibble", 4, "4.0"),
    _lc("01001", "1 byte", 8, "4.0"),
    _lc("01010", "Reserved", None),
    _lc("01011", "3 bytes", 24, "4.0"),
    _lc("01100", "Reserved", None),
    _lc("01101", "2 bits", 2, "4.40"),
    _lc("01110", "6 words", 96, "3.2"),
    _lc("01111", "7 words", 112, "3.2"),
    _lc("10000", "Reserved", None),
    _lc("10001", "26 words", 416, "3.7"),
    _lc("10010", "16 words", 256, "3.2"),
    _lc("10011", "24 words", 384, "3.2"),
    _lc("10100", "32 words", 512, "3.2"),
    _lc("10101", "10 words", 160, "3.2"),
    _lc("10110", "12 words", 192, "3.2"),
    _lc("10111", "14 words", 224, "3.2"),
    # Table 3-11's last row is "1 1 x x x Reserved": the eight codes 11000..11111.
    *(_lc(f"11{low:03b}", "Reserved", None) for low in range(8)),
)
"""All 32 five-bit length codes of Table 3-11 (identical to Table A-5), in code order."""

LENGTH_CODE_BY_VALUE: Final[dict[int, LengthCode]] = {int(lc.code, 2): lc for lc in LENGTH_CODES}


@dataclass(frozen=True)
class AbbreviatedLength:
    """One row of Table 3-12: the 3-bit code CL2..CL0 of the SET register and the length code it decodes to."""

    cl: str
    text: str
    length_code: str


ABBREVIATED_LENGTHS: Final[tuple[AbbreviatedLength, ...]] = (
    AbbreviatedLength("000", "0 bits", "00000"),
    AbbreviatedLength("001", "4 bits (1 nibble)", "01000"),
    AbbreviatedLength("010", "1 byte", "01001"),
    AbbreviatedLength("011", "1 word", "00001"),
    AbbreviatedLength("100", "3 bytes", "01011"),
    AbbreviatedLength("101", "2 words", "00010"),
)
"""Table 3-12. CL codes 110 and 111 have no row: they are rejected as reserved."""

# ----------------------------------------------------------------------------------------------------------------
# ID codes: Table A-3
# ----------------------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class IdCode:
    """One row of Table A-3 (extract from the INTERBUS Club ID code specification)."""

    group: str
    description: str
    abbreviation: str
    code: int
    note: str = ""
    """"*)" firmware 4.0 or later, "**)" controller boards of Generation 4.5 or later."""


_RB_DIGITAL = "Remote bus device (digital)"
_RB_ANALOG = "Remote bus device (analog)"
_RB_PCP = "Remote bus devices with parameter channel"
_LB_DIGITAL = "Local bus device (digital)"
_LB_ANALOG = "Local bus device (analog)"
_LB_PCP = "Local bus devices with parameter channel"
_BK = "Bus terminal modules (BK)"

ID_CODES: Final[tuple[IdCode, ...]] = (
    IdCode(_BK, "BK with 2-wire local bus branch", "BK-LB", 0x08),
    IdCode(_BK, "BK with 2-wire local bus branch and device-orientated diagnostics", "BK-LBD", 0x04),
    IdCode(_BK, "BK with 2-wire remote bus branch", "BK-RB", 0x0C),
    IdCode(_RB_DIGITAL, "Digital output modules", "DO", 0x01),
    IdCode(_RB_DIGITAL, "Digital input modules", "DI", 0x02),
    IdCode(_RB_DIGITAL, "Digital input/output modules", "DIO", 0x03),
    IdCode(_RB_DIGITAL, "Profile-compliant digital output modules", "PROFILE DO", 0x0D),
    IdCode(_RB_DIGITAL, "Profile-compliant digital input modules", "PROFILE DI", 0x0E),
    IdCode(_RB_DIGITAL, "Profile-compliant digital input/output modules", "PROFILE DIO", 0x2F),
    IdCode(_RB_DIGITAL, "ISO valve manifolds", "ISO valve manifolds", 0x05),
    IdCode(_RB_ANALOG, "Analog output modules", "AO", 0x31),
    IdCode(_RB_ANALOG, "Analog input modules", "AI", 0x32),
    IdCode(_RB_ANALOG, "Analog input/output modules", "AIO", 0x33),
    IdCode(_RB_ANALOG, "Profile-compliant analog output modules", "PROFILE AO", 0x35),
    IdCode(_RB_ANALOG, "Profile-compliant analog input modules", "PROFILE AI", 0x3A),
    IdCode(_RB_ANALOG, "Profile-compliant analog input/output modules", "PROFILE AIO", 0x3B),
    IdCode(_RB_ANALOG, "ENCOM with input data", "ENCOM", 0x36),
    IdCode(_RB_ANALOG, "ENCOM with input and output data", "ENCOM", 0x37),
    IdCode(_RB_PCP, "Modules with parameter channel (2 PCP words)", "Parameter channel", 0xF0, "*)"),
    IdCode(_RB_PCP, "Modules with parameter channel (4 PCP words)", "Parameter channel", 0xF1, "*)"),
    IdCode(_RB_PCP, "Modules with parameter channel (1 PCP word)", "Parameter channel", 0xF3),
    IdCode(_RB_PCP, "DRIVECOM (2 PCP words)", "DRIVECOM", 0xE0, "*)"),
    IdCode(_RB_PCP, "DRIVECOM (4 PCP words)", "DRIVECOM", 0xE1, "*)"),
    IdCode(_RB_PCP, "DRIVECOM (1 PCP word)", "DRIVECOM", 0xE3),
    IdCode(_RB_PCP, "ENCOM (2 PCP words)", "ENCOM", 0xF4, "*)"),
    IdCode(_RB_PCP, "ENCOM (4 PCP words)", "ENCOM", 0xF5, "*)"),
    IdCode(_RB_PCP, "ENCOM (1 PCP word)", "ENCOM", 0xF7),
    IdCode(_RB_PCP, "Profile-compliant modules (2 PCP words)", "Profile PA channel", 0xE4, "*)"),
    IdCode(_RB_PCP, "Profile-compliant modules (4 PCP words)", "Profile PA channel", 0xE5, "*)"),
    IdCode(_RB_PCP, "Profile-compliant module (1 PCP word)", "Profile PA channel", 0xE7),
    IdCode(_RB_PCP, '"µP_Not_Ready" (with register latching) remote bus', "Special", 0x38, "*)"),
    IdCode(_RB_PCP, '"µP_Not_Ready" (for re-initialization) remote bus', "Special", 0x3C, "*)"),
    IdCode(_LB_DIGITAL, "Digital output modules", "DO", 0xBD),
    IdCode(_LB_DIGITAL, "Digital input modules", "DI", 0xBE),
    IdCode(_LB_DIGITAL, "Digital input/output modules", "DIO", 0xBF),
    IdCode(_LB_DIGITAL, "Digital INTERBUS Loop output modules", "IBS Loop DO", 0xB1),
    IdCode(_LB_DIGITAL, "Digital INTERBUS Loop input modules", "IBS Loop DI", 0xB2),
    IdCode(_LB_DIGITAL, "Digital INTERBUS Loop input/output modules", "IBS Loop DIO", 0xB3),
    IdCode(_LB_DIGITAL, "Profile-compliant digital output modules", "PROFILE DO", 0xB5),
    IdCode(_LB_DIGITAL, "Profile-compliant digital input modules", "PROFILE DI", 0xB6),
    IdCode(_LB_DIGITAL, "Profile-compliant digital input/output modules", "PROFILE DIO", 0xB7),
    IdCode(_LB_DIGITAL, "Wrenching controllers", "Wrench. contr.", 0xBB),
    IdCode(_LB_ANALOG, "Analog output modules", "AO", 0x7D),
    IdCode(_LB_ANALOG, "Analog output modules with alarm inputs", "AIO²", 0x5B, "**)"),
    IdCode(_LB_ANALOG, "Analog input modules", "AI", 0x7E),
    IdCode(_LB_ANALOG, "Analog input modules with configuration outputs", "AI²O", 0x5F, "**)"),
    IdCode(_LB_ANALOG, "Analog input/output modules", "AIO", 0x7F),
    IdCode(
        _LB_ANALOG,
        "Analog input and output modules with alarm inputs and configuration outputs",
        "AI²O²",
        0x53,
        "**)",
    ),
    IdCode(_LB_ANALOG, "Analog INTERBUS Loop output modules", "IBS Loop AO", 0x71),
    IdCode(_LB_ANALOG, "Analog INTERBUS Loop output modules with alarm inputs", "IBS Loop AIO²", 0x6B, "**)"),
    IdCode(_LB_ANALOG, "Analog INTERBUS Loop input modules", "IBS Loop AI", 0x72),
    IdCode(
        _LB_ANALOG,
        "Analog INTERBUS Loop input modules with configuration outputs",
        "IBS Loop AI²O",
        0x6F,
        "**)",
    ),
    IdCode(_LB_ANALOG, "Analog INTERBUS Loop input and output modules", "IBS Loop AIO", 0x73),
    IdCode(
        _LB_ANALOG,
        "Analog INTERBUS Loop input and Loop output modules with alarm inputs and configuration outputs",
        "IBS Loop AI²O²",
        0x63,
        "**)",
    ),
    IdCode(_LB_ANALOG, "Profile-compliant analog output modules", "PROFILE AO", 0x79),
    IdCode(_LB_ANALOG, "Profile-compliant analog input modules", "PROFILE AI", 0x7A),
    IdCode(_LB_ANALOG, "Profile-compliant analog input/output modules", "PROFILE AIO", 0x7B),
    IdCode(_LB_ANALOG, "ENCOM with input data", "ENCOM", 0x66),
    IdCode(_LB_ANALOG, "ENCOM with input and output data", "ENCOM", 0x67),
    IdCode(_LB_PCP, "Modules with parameter channel (2 PCP words)", "Parameter channel", 0xDC, "*)"),
    IdCode(_LB_PCP, "Modules with parameter channel (4 PCP words)", "Parameter channel", 0xDD, "*)"),
    IdCode(_LB_PCP, "Modules with parameter channel (1 PCP word)", "Parameter channel", 0xDF),
    IdCode(_LB_PCP, "DRIVECOM (2 PCP words)", "DRIVECOM", 0xC0, "*)"),
    IdCode(_LB_PCP, "DRIVECOM (4 PCP words)", "DRIVECOM", 0xC1, "*)"),
    IdCode(_LB_PCP, "DRIVECOM (1 PCP word)", "DRIVECOM", 0xC3),
    IdCode(_LB_PCP, "ENCOM (2 PCP words)", "ENCOM", 0xD4, "*)"),
    IdCode(_LB_PCP, "ENCOM (4 PCP words)", "ENCOM", 0xD5, "*)"),
    IdCode(_LB_PCP, "ENCOM (1 PCP word)", "ENCOM", 0xD7),
    IdCode(_LB_PCP, "Profile-compliant modules (2 PCP words)", "Profile PA channel", 0xD8, "*)"),
    IdCode(_LB_PCP, "Profile-compliant modules (4 PCP words)", "Profile PA channel", 0xD9, "*)"),
    IdCode(_LB_PCP, "Profile-compliant module (1 PCP word)", "Profile PA channel", 0xDB),
    IdCode(_LB_PCP, '"µP_Not_Ready" (with register latching), local bus', "Special", 0x78, "*)"),
    IdCode(_LB_PCP, '"µP_Not_Ready" (for re-initialization) local bus', "Special", 0x6C, "*)"),
    IdCode(_LB_PCP, '"µP_Not_Ready" (for re-initialization), Loop', "Special", 0x68, "*)"),
)
"""Every row of Table A-3, in manual order. Some codes appear in two groups (remote and local bus)."""

ID_CODE_VALUES: Final[frozenset[int]] = frozenset(row.code for row in ID_CODES)

UP_NOT_READY_ID_CODES: Final[frozenset[int]] = frozenset(
    row.code for row in ID_CODES if row.description.startswith('"µP_Not_Ready"')
)
"""The µP_Not_Ready codes of Table A-3 (38h, 3Ch, 78h, 6Ch, 68h): reported until software writes SET (3.4.1)."""

# ----------------------------------------------------------------------------------------------------------------
# MFP assignments: Tables 3-1, 3-2, 3-3, 3-5, 3-6 and 2-8
# ----------------------------------------------------------------------------------------------------------------


class PinDirection(StrEnum):
    """Direction of a pin seen from the chip."""

    IN = "in"
    OUT = "out"
    INOUT = "inout"


@dataclass(frozen=True)
class PinFunction:
    """What one MFP pin does in one operating mode."""

    pin: int
    signal: str
    direction: PinDirection
    meaning: str = ""


def _io_pins(first_pin: int, prefix: str, first_bit: int, count: int) -> tuple[PinFunction, ...]:
    direction = PinDirection.IN if prefix == "In" else PinDirection.OUT
    return tuple(PinFunction(first_pin + k, f"{prefix}{first_bit + k}", direction) for k in range(count))


BINARY_IO_MFP: Final[dict[str, tuple[PinFunction, ...]]] = {
    # Table 3-1: modes with configuration expansion (MFP[15..12] carry C[8..5]).
    "2 IN": _io_pins(0, "In", 0, 2),
    "2 OUT": _io_pins(0, "Out", 0, 2),
    "2 IN/2 OUT": _io_pins(0, "In", 0, 2) + _io_pins(8, "Out", 0, 2),
    "4 IN": _io_pins(0, "In", 0, 4),
    "4 OUT": _io_pins(0, "Out", 0, 4),
    "4 IN/4 OUT": _io_pins(0, "In", 0, 4) + _io_pins(8, "Out", 0, 4),
    "8 IN": _io_pins(0, "In", 0, 8),
    "8 OUT": _io_pins(0, "Out", 0, 8),
    # Table 3-2: modes without configuration expansion (all sixteen MFPs are data pins).
    "8 IN/8 OUT": _io_pins(0, "In", 0, 8) + _io_pins(8, "Out", 0, 8),
    "16 IN": _io_pins(0, "In", 0, 16),
    "16 OUT": _io_pins(0, "Out", 0, 16),
}
"""MFP pin functions of the binary I/O modes, Table 3-1 (first eight) and Table 3-2 (last three).

Pins without an entry are unused inputs ("-" in Table 3-1); MFP[15..12] are configuration inputs in the
Table 3-1 modes."""

BINARY_IO_TABLE: Final[dict[str, str]] = {mode: ("3-2" if mode in {"8 IN/8 OUT", "16 IN", "16 OUT"} else "3-1")
                                          for mode in BINARY_IO_MFP}

SPI_MASTER_MFP: Final[tuple[PinFunction, ...]] = (
    PinFunction(0, "GND", PinDirection.IN, "Does not serve any function"),
    PinFunction(1, "GND", PinDirection.IN, "Does not serve any function"),
    PinFunction(2, "GND", PinDirection.IN, "Does not serve any function"),
    PinFunction(3, "/Conv", PinDirection.OUT, "Latch (output)"),
    PinFunction(4, "SCLK", PinDirection.OUT, "Clock (output) 1 MHz at 500 kbaud, 4 MHz at 2 Mbaud"),
    PinFunction(5, "/SS", PinDirection.OUT, "Slave select (output)"),
    PinFunction(6, "SerIn", PinDirection.IN, "Data (input)"),
    PinFunction(7, "SerOut", PinDirection.OUT, "Data (output)"),
    *(PinFunction(pin, "GND", PinDirection.IN, "Does not serve any function") for pin in range(8, 12)),
)
"""Table 3-3: MFP pins of the SPI master mode (MFP[15..12] are configuration inputs)."""

UP_MOTOROLA_MFP: Final[tuple[PinFunction, ...]] = (
    PinFunction(0, "SAS_INIT", PinDirection.IN, "Initialization of the serial interface (active high)"),
    PinFunction(1, "I/O", PinDirection.OUT,
                "I/O access (polling) bit (corresponds to bit D7 in the interrupt event register (rel. addr. 14)"),
    PinFunction(2, "C/D", PinDirection.OUT, "Command/Data status: next byte is a command (0) or data (1)"),
    PinFunction(3, "/IRQ", PinDirection.OUT, "Interrupt Request"),
    PinFunction(4, "SCLK", PinDirection.IN, "Clock input (1.5 MHz maximum at 500 kbps, 6 MHz maximum at 2 Mbps)"),
    PinFunction(5, "/SS", PinDirection.IN, "Slave Select"),
    PinFunction(6, "SerIN", PinDirection.IN, "Serial input (MOSI: Master Out Slave In)"),
    PinFunction(7, "SerOUT", PinDirection.OUT, "Serial output (MISO: Master In Slave Out)"),
)
"""Table 3-5: MFP pins of the serial µP interface in SPI (Motorola) mode."""

UP_INTEL_MFP: Final[tuple[PinFunction, ...]] = (
    PinFunction(0, "SAS_INIT", PinDirection.IN, "Initialization of the serial interface (active high)"),
    PinFunction(1, "I/O", PinDirection.OUT,
                "I/O access (polling) bit (corresponds to bit D7 in the interrupt event register)"),
    PinFunction(2, "C/D", PinDirection.OUT, "Command/Data status: next byte is a command (1) or data (0)"),
    PinFunction(3, "/IRQ", PinDirection.OUT, "Interrupt Request"),
    PinFunction(4, "SCLK", PinDirection.IN, "Clock input (1.5 MHz maximum at 500 kbps, 6 MHz maximum at 2 Mbps)"),
    PinFunction(5, "/SS", PinDirection.IN, "Slave Select"),
    PinFunction(6, "Ser_IN/OUT", PinDirection.INOUT, "Bidirectional data line"),
    PinFunction(7, "S/R", PinDirection.IN, "Data direction: 1 = the processor sends, 0 = the processor receives"),
)
"""Table 3-6: MFP pins of the serial µP interface in Intel mode. MFP7 is an input in both modes, which is why
the chip can leave it an input after every hardware reset until the mode is known (3.4.3)."""

BUS_TERMINAL_MFP: Final[tuple[PinFunction, ...]] = (
    PinFunction(8, "FO3", PinDirection.OUT, "Initialization diagnostics, optical fiber interface in "
                '"READY" bus status or MAU warning in "RUN" bus status.'),
    PinFunction(9, "DO3_CU", PinDirection.OUT, "Branch data output (copper)"),
    PinFunction(10, "DI3", PinDirection.IN, "Branch data input"),
    PinFunction(11, "LBST", PinDirection.IN, "Alarm input for local bus connector"),
    PinFunction(12, "CONF", PinDirection.IN, '"Reconfigure Request" control input'),
    PinFunction(13, "ERROR", PinDirection.OUT, '"Error" diagnostic LED'),
    PinFunction(14, "LBDA", PinDirection.OUT, '"LD" (Local bus Disabled) diagnostic LED'),
    PinFunction(15, "ALARM", PinDirection.OUT, "Alarm output"),
)
"""Table 2-8: MFP[15..8] in the bus terminal modes; MFP[7..0] are the µP interface in the Init-µP modes only."""

# ----------------------------------------------------------------------------------------------------------------
# Pins: Tables 1-2, 1-3 and 1-4
# ----------------------------------------------------------------------------------------------------------------

TQFP64_PINS: Final[tuple[str, ...]] = (
    "Vcc", "DO1", "CUR_LIM", "CLK_IN", "OSC_OUT", "C4", "C3", "C2", "C1", "C0", "IB_DIAG",
    "DIAG_CONF", "DIAG1", "DIAG2", "DCLK_OUT", "GND", "Vcc", "DO2_AN", "GND", "DO2_CU", "DI2", "CLK_CONF0",
    "CLK_CONF1", "EN_FDDL", "/ResU", "TST", "/StatErr", "/ModAck", "/ResReg (RC)", "LaOuD", "/LaInD", "GND",
    "Vcc", "FromExR", "ToExR", "ClkExR", "RBST_EXT", "MFP15", "MFP14", "MFP13", "MFP12", "MFP11", "MFP10",
    "MFP9", "MFP8", "GND", "DO3_AN", "GND", "Vcc", "RF0", "RF1", "MFP7", "MFP6", "MFP5", "MFP4", "MFP3",
    "MFP2", "MFP1", "MFP0", "Vcc", "DI1_CU", "GND", "DI1_AN", "GND",
)  # fmt: skip
"""Table 1-2: pin names of the TQFP 64 housing (SUPI 3 OPC), pin 1 first."""

TQFP44_PINS: Final[tuple[str, ...]] = (
    "Vcc", "DO1", "CLK_IN", "OSC_OUT", "C3", "C2", "C1", "C0", "IB_DIAG", "DCLK_OUT", "GND", "Vcc",
    "DO2_CU", "DI2", "CLK_CONF0", "CLK_CONF1", "GND", "/ResU", "TST", "/StatErr", "/ModAck", "GND", "Vcc",
    "RBST_EXT", "MFP15", "MFP14", "MFP13", "MFP12", "MFP11", "MFP10", "MFP9", "MFP8", "GND", "Vcc", "MFP7",
    "MFP6", "MFP5", "MFP4", "MFP3", "MFP2", "MFP1", "MFP0", "DI1_CU", "GND",
)  # fmt: skip
"""Table 1-3: pin names of the TQFP 44 housing (SUPI 3 LS), pin 1 first."""

CELL_TYPES: Final[dict[str, str]] = {
    "CI": "CMOS input",
    "CIp": "CMOS input with pull-up",
    "STC": "CMOS Schmitt trigger input",
    "STCp": "CMOS Schmitt trigger input with pull-up",
    "B2": "Driver output 2 mA",
    "B4": "Driver output 4 mA",
    "B8": "Driver output 8 mA",
    "BD4": "Bidirectional with TTL Schmitt trigger input without pull-up and 4 mA driver output",
    "AN60": "DAC current output 60 mA",
    "OD8": "8 mA open drain output",
    "OSC": "Oscillator cell output",
    "PAS": "Passive external components",
}
"""Cell types of Table 1-4 (the manual prints "Clp"/"Clp" for CIp: an OCR confusion of I and l)."""


@dataclass(frozen=True)
class PinDescription:
    """One row of Table 1-4. ``cell`` is ``None`` for supply pins; the flags say which housing has the pin."""

    designation: str
    meaning: str
    cell: str | None
    tqfp64: bool
    tqfp44: bool


def _pd(designation: str, meaning: str, cell: str | None, tqfp44: bool = True) -> PinDescription:
    return PinDescription(designation, meaning, cell, True, tqfp44)


PIN_DESCRIPTIONS: Final[tuple[PinDescription, ...]] = (
    _pd("CLK_IN", "Oscillator input", "CI"),
    _pd("OSC_OUT", "Oscillator output", "OSC"),
    _pd("DCLK_OUT", "Data clock output (500 kbps/2 Mbps)", "B8"),
    _pd("CLK_CONF[1..0]", "PLL/clock cell configuration", "CI"),
    _pd("C4", "Operating mode configuration", "CIp", tqfp44=False),
    _pd("C[3..0]", "Operating mode configuration", "CI"),
    _pd("RF[1..0]", "Optical regulation configuration", "CIp", tqfp44=False),
    _pd("RBST_EXT", "Optical regulation configuration (or alarm input if an outgoing interface is used)", "STC"),
    _pd("MFP[15..0]", "Multi-function pins", "BD4"),
    _pd("DO1", "Input: Data line OUT forward", "STC"),
    _pd("DI1_CU", "Output: Data line OUT digital return for copper", "B4"),
    _pd("DI1_AN", "Output: Data line OUT analog return for optical fiber", "AN60", tqfp44=False),
    _pd("DI2", "Input: Data line IN return", "STC"),
    _pd("DO2_CU", "Output: Data line OUT digital forward for copper", "B4"),
    _pd("DO2_AN", "Output: Data line OUT analog forward for optical fiber", "AN60", tqfp44=False),
    _pd("DO3_AN", "Output: Data line OUT analog forward branch for optical fiber", "AN60", tqfp44=False),
    _pd("/LaInD", "Latch signal for input data", "B4", tqfp44=False),
    _pd("LaOuD", "Latch signal for output data", "B4", tqfp44=False),
    _pd("ClkExR", "Clock for external data registers", "B4", tqfp44=False),
    _pd("ToExR", "Data output for external data registers without internal SUPI 3 OPC registers", "B2",
        tqfp44=False),
    _pd("FromExR", "Data input for external data registers", "STC", tqfp44=False),
    _pd("/StatErr", '"Module error" alarm input', "STCp"),
    _pd("/ModAck", "Acknowledgment output for detected module error", "B2"),
    _pd("/ResReg (RC)", "Reset external register (or RC LED)", "B4", tqfp44=False),
    _pd("DIAG_CONF", "Configuration of diagnostic outputs", "CIp", tqfp44=False),
    _pd("DIAG1", '"BA" or "FO1 IN" alarm output', "B4", tqfp44=False),
    _pd("DIAG2", '"RBDA" or "FO2 OUT" alarm output', "B4", tqfp44=False),
    _pd("IB_DIAG", "Diagnostic output (limited)", "B4"),
    _pd("CUR_LIM", "Control current setting", "PAS", tqfp44=False),
    _pd("TST", "Test input, hard-wire to GND", "CI"),
    _pd("EN_FDDL", "Reserved, hard-wire to GND", "CI", tqfp44=False),
    _pd("/ResU", "Initialization reset (input and output)", "OD8"),
    _pd("Vcc", "Voltage supply +5 V", None),
    _pd("GND", "Ground", None),
)
"""Every row of Table 1-4, in manual order."""

# ----------------------------------------------------------------------------------------------------------------
# Clock: Tables 1-6 and 1-7
# ----------------------------------------------------------------------------------------------------------------

CLOCK_HZ: Final[int] = 32_000_000
"""The crystal or oscillator frequency, 32 MHz ±100 ppm (1.7.1)."""

CLOCK_PPM: Final[int] = 100


@dataclass(frozen=True)
class ClockTiming:
    """One row of Table 1-6 (clock timing), times in ns."""

    designation: str
    name: str
    symbol: str
    minimum: float
    typical: float
    maximum: float


CLOCK_TIMING: Final[tuple[ClockTiming, ...]] = (
    ClockTiming("a", "Clock period", "t_c", 31.25, 31.25, 31.25),
    ClockTiming("b", "Pulse width high", "t_pH", 12.5, 15.625, 18.75),
    ClockTiming("c", "Pulse width low", "t_pL", 12.5, 15.625, 18.75),
)
"""Table 1-6. The period tolerance row (-3.125 ps / +3.125 ps) is ±100 ppm of 31.25 ns."""

CLOCK_PERIOD_TOLERANCE_PS: Final[float] = 3.125


@dataclass(frozen=True)
class ClockConf:
    """One row of Table 1-7. ``bit_rate`` is ``None`` for the reserved row (CLK_CONF0 = 0)."""

    clk_conf1: str
    clk_conf0: str
    clock_source: str
    bit_rate: int | None


CLOCK_CONFIGURATIONS: Final[tuple[ClockConf, ...]] = (
    ClockConf("0", "1", "Quartz, 32 MHz", 500_000),
    ClockConf("1", "1", "Quartz, 32 MHz", 2_000_000),
    ClockConf("X", "0", "Reserved", None),
)
"""Table 1-7: CLK_CONF[1..0] and the INTERBUS data rate."""

BIT_RATES: Final[tuple[int, ...]] = tuple(row.bit_rate for row in CLOCK_CONFIGURATIONS if row.bit_rate)


def clk_conf_for(bit_rate: int) -> str:
    """CLK_CONF[1..0], MSB first, that selects ``bit_rate`` (Table 1-7): ``"01"`` 500 kbit/s, ``"11"`` 2 Mbit/s."""
    for row in CLOCK_CONFIGURATIONS:
        # Exact type: the reserved row's None, a float 2e6 or True must not select a row.
        if row.bit_rate is not None and type(bit_rate) is int and row.bit_rate == bit_rate:
            return row.clk_conf1 + row.clk_conf0
    raise ConfigurationError("CLK_CONF[1..0]", f"{bit_rate!r} bit/s", "Table 1-7", f"the data rates are {BIT_RATES}")


# ----------------------------------------------------------------------------------------------------------------
# Bus connector recognition and regulation: Tables 2-2 and 2-9
# ----------------------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class RfMode:
    """One row of Table 2-2, with the LBST function of Table 2-9 for the same RF[1..0]."""

    rf: str
    rbst_ext: str
    function: str
    lbst_function: str
    optical_regulation: bool
    medium: str


RF_MODES: Final[tuple[RfMode, ...]] = (
    RfMode("10", "Controlled", "Bus connector recognition via pin",
           "LBST via external signal (as IBS SUPI 3)", False, "copper"),
    RfMode("11", "0", "Automatic bus connector recognition, only copper interface; bit distortion monitoring",
           "Copper interface, possible to switch off (LBST=0)", False, "copper"),
    RfMode("00", "0", "Automatic bus connector recognition, regulation function with 3 dB power reserve, "
           "fiber optic interface only; bit distortion monitoring",
           "Automatic bus connector recognition: Optical fiber interface, possible to switch on (LBST=1)",
           True, "fiber optic"),
    RfMode("01", "0", "Optical power diagnostics, fiber optic interface only: fixed transmit power, MAU warning "
           "when the reserve falls (1.6.2; this row is decision OPT-2)",
           "Automatic bus connector recognition: Optical fiber interface, possible to switch on (LBST=1)",
           False, "fiber optic"),
)  # fmt: skip
"""Tables 2-2 and 2-9, and RF[1..0] = 01, which neither table lists: the optical power diagnostics mode of 1.6.2
("alternatively ... operated with optical power diagnostics"), the only mode 1.6 names without a pin pattern and the
only pattern without a mode (OPT-2, ``docs/assumptions/optical.md``)."""

# ----------------------------------------------------------------------------------------------------------------
# Diagnostics: Tables 3-16 to 3-19
# ----------------------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class DiagConf:
    """One row of Table 3-16."""

    diag_conf: int
    kind: str
    diag1: str
    diag2: str


DIAG_CONFIGURATIONS: Final[tuple[DiagConf, ...]] = (
    DiagConf(0, "Complete diagnostics", "BA", "RD"),
    DiagConf(1, "Limited diagnostics", "FO1", "FO2"),
)
"""Table 3-16: DIAG_CONF selects what DIAG1 and DIAG2 show."""

FIBER_OPTIC_DIAGNOSTICS: Final[tuple[tuple[str, str, str], ...]] = (
    ("FO1", "DIAG1", "Incoming"),
    ("FO2", "DIAG2", "Outgoing"),
    ("FO3", "MFP8", "Branch"),
)
"""Table 3-17: (signal, pin, interface). State 0: initialization OK, no MAU warning (master in READY);
state 1: the same in RUN. FO3 exists on bus terminal modules only."""

LIMITED_DIAGNOSTICS: Final[tuple[tuple[str, float | None, str], ...]] = (
    ("No light", None, "No supply"),
    ("Steady light", None, "Supply OK, module function error-free, bus active"),
    ("Flashing slowly (0.5 Hz)", 0.5, "Supply OK, bus not active"),
    ("Flashing quickly (2 Hz)", 2.0, "Supply OK, peripheral fault (/StatErr)"),
    ("Flashing very quickly (4 Hz)", 4.0, "Supply OK, module has detected a line interrupt ahead on the local bus"),
)
"""Table 3-18: IB_DIAG pin state (with its flash frequency in Hz) and its cause."""

COMPLETE_DIAGNOSTICS: Final[tuple[tuple[str, str, str, str], ...]] = (
    ("UL", "/ResU", "Voltage monitoring", "Green"),
    ("RC (CC)", "/ResReg", "Remote bus Check (cable check)", "Green"),
    ("BA", "DIAG1", "Bus Active", "Green"),
    ("RD", "DIAG2", "Remote bus Disabled", "Yellow"),
    ("LD", "MFP14", "Branch disabled (bus terminal module only)", "Yellow"),
    ("E", "MFP13", "Error in connected branch (bus terminal module only)", "Red"),
)
"""Table 3-19: (signal, pin, diagnostics, LED colour)."""

# ----------------------------------------------------------------------------------------------------------------
# Timing: Tables 3-4, 3-7 and 3-15 (Table 1-6 is with the clock above)
# ----------------------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class TimingParameter:
    """One timing parameter. ``minimum``/``maximum`` are expressions as the manual prints them (in units of
    ``t0``, ``t_Bit_IBS``, ``TCLK`` or ns); :mod:`supi3.timing` evaluates them for a bit rate."""

    symbol: str
    explanation: str
    minimum: str | None
    maximum: str | None


SPI_MASTER_TIMING: Final[tuple[TimingParameter, ...]] = (
    TimingParameter("t0", "Clock period", "0.5 * t_Bit_IBS", None),
    TimingParameter("t1", "Negative edge of /SS before positive edge of SCLK", "t0", None),
    TimingParameter("t2", "Positive edge of /SS after positive edge of SCLK", "t0", None),
    TimingParameter("t3", "SerOUT data valid after positive edge of SCLK", "0.5 * t0", None),
    TimingParameter("t4", "SerIN data valid before positive edge of SCLK (setup)", "100 ns", None),
    TimingParameter("t5", "SerIN data valid after positive edge of SCLK (hold)", "50 ns", None),
    TimingParameter("t6", "Negative edge of /Conv after positive edge of /SS", "t0", None),
    TimingParameter("t7", "Duration of /Conv conversion signal", "t0", None),
    TimingParameter("t8", "Duration of /SS signal (n: number of bytes)", "9 * n * t0", None),
    TimingParameter("t9", "Pause between LOW byte and HIGH byte", "2 * t0", None),
    TimingParameter("t10", "Pause between Read /SS and Write /SS", "50.5 * t0", None),
    TimingParameter("t11", "SerOUT data item D15 valid before the first positive edge of SCLK", "0.5 * t0", None),
    TimingParameter("t12", "SerOUT data valid before positive edge of SCLK", "0.5 * t0", None),
)
"""Table 3-4: SPI master times (t_Bit_IBS = 2 µs at 500 kbaud, 0.5 µs at 2 Mbaud)."""

TCLK_PER_BIT: Final[int] = 16
"""TCLK = t_Bit_IBS / 16 (Table 3-7): the µP interface's internal reference clock runs at 16 times the bit rate."""

UP_INTERFACE_TIMING: Final[tuple[TimingParameter, ...]] = (
    TimingParameter("TCLK", "Internal reference clock period", f"1/{TCLK_PER_BIT} * t_Bit_IBS", None),
    TimingParameter("t0", "Clock period (1.5 MHz at 500 kbaud, 6 MHz at 2 Mbaud)", "667 ns | 167 ns", None),
    TimingParameter("t1", "Negative edge of /SS before first negative edge of SCLK", "1 * TCLK", None),
    TimingParameter("t2", "Positive edge of /SS after last positive edge of SCLK", "3 * TCLK", None),
    TimingParameter("t3", "SerOUT data (n) valid after positive edge of SCLK (n)", "2 * TCLK + 10 ns", None),
    TimingParameter("t4", "SerIN data valid before positive edge of SCLK (setup)", "100 ns", None),
    TimingParameter("t5", "SerIN data valid after positive edge of SCLK (hold)", "50 ns", None),
    TimingParameter("t6", "Change in the status signal after positive edge of /SS", "2 * TCLK", "3 * TCLK"),
    TimingParameter("t7", "SerOUT data valid after negative edge of /SS", None, "3 * TCLK"),
    TimingParameter("t8", "Negative edge of /SS after change of C/D", "TCLK", None),
    TimingParameter("t9", "SerOUT data (n) valid after positive edge of SCLK (n-1)", None, "3 * TCLK"),
    TimingParameter("t10", "S/R valid before negative edge of /SS", "0 ns", None),
    TimingParameter("t11", "Status change of S/R after positive edge of /SS", "0 ns", None),
    TimingParameter("t_SAS_INIT", "High pulse to initialize the serial interface", "250 ns", None),
)
"""Table 3-7: times of the synchronous serial interface (Intel and Motorola). ``t0`` lists the value at
500 kbit/s, then at 2 Mbit/s."""

REGISTER_EXPANSION_TIMING: Final[tuple[TimingParameter, ...]] = (
    TimingParameter("t0", "ClkExR period length", "t_Bit_IBS", None),
    TimingParameter("t1", "Data valid before positive edge of ClkExR", "0.25 * t0", None),
    TimingParameter("t2", "Data valid after positive edge of ClkExR", "0.75 * t0", None),
    TimingParameter("t3", "Data valid before positive edge of ClkExR (setup)", "0.25 * t0 + 100 ns", None),
    TimingParameter("t4", "Data valid before positive edge of ClkExR (hold)", None, "0.25 * t0 - 50 ns"),
    TimingParameter("t5", "/LaInD pulse length", "4 * t0", None),
    TimingParameter("t6", "LaOuD pulse length", "4 * t0", None),
    TimingParameter("t7", "/LaInD valid after negative edge of LaOuD", "5 * t0", None),
    TimingParameter("t8", "/ResReg (RC) pulse length", "4 * t0", None),
)
"""Table 3-15: serial register expansion interface times. The symbol column is missing from the text copy;
t0..t8 number the rows in manual order (see docs/assumptions.md)."""

STATERR_FILTER_S: Final[float] = 0.200
"""/StatErr input filter time t3 = 200 ms (3.6.2)."""

STATERR_FILTER_TOLERANCE: Final[float] = 0.315
"""±31.5 % on the /StatErr filter (3.6.2)."""

IO_ACCESS_WINDOW_BITS: Final[int] = 30
"""After the I/O access bit falls, the data registers may be accessed for 30 bit periods (3.4.14, Fig. 3-22)."""

CPU_ACCESS_TELEGRAM_BITS: Final[int] = 13
CPU_ACCESS_OVERHEAD_BYTES: Final[int] = 5
"""3.4.14: T = 13 * (5 + n) * t_Bit, n = data bytes in the whole network."""

WATCHDOG_TIMEOUTS_S: Final[tuple[float | None, ...]] = (0.050, 0.200, 1.000, None)
"""Layer-2 monitoring times settable by the master (Table 3-13, INTERBUS reset): 50 ms, 200 ms, 1000 ms, off."""

RESREG_PULSE_NS: Final[int] = 375
"""/ResReg single pulse on a watchdog reset of process data (Table 3-13)."""

RESREG_PULSE_CLOCKS: Final[int] = RESREG_PULSE_NS * CLOCK_HZ // 1_000_000_000
"""The /ResReg pulse in clocks: 375 ns at 32 MHz is exactly 12 (3.4.14, Table 3-13, INTERBUS reset: "A single pulse
of 375 ns is generated"). The one definition of the width: the models (``supi3.model.chip``) and the RTL
(``supi3.rtl.core``) use it."""

VOLTAGE_MONITOR_HIGH_V: Final[float] = 4.5
VOLTAGE_MONITOR_LOW_V: Final[float] = 3.9
RESET_MIN_S: Final[float] = 4e-6
"""Reset unit (1.7.2): high above 4.5 V, low below 3.9 V, reset at least 4 µs."""

# ----------------------------------------------------------------------------------------------------------------
# Optical path length: Table 1-5 and the formula of 1.6.1
# ----------------------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class OpticalLengthRange:
    """One row of Table 1-5. Lengths in metres; ``resolution_m`` is (typical, worst case) or ``None``."""

    min_m: float
    max_m: float
    resolution_m: tuple[float, float] | None
    values: tuple[int, int]
    bit_rate: int


OPTICAL_LENGTH_RANGES: Final[tuple[OpticalLengthRange, ...]] = (
    OpticalLengthRange(0, 400, (24, 48), (0, 62), 500_000),
    OpticalLengthRange(400, 20_000, None, (63, 63), 500_000),
    OpticalLengthRange(0, 400, (6, 12), (0, 62), 2_000_000),
    OpticalLengthRange(400, 20_000, None, (63, 63), 2_000_000),
)
"""Table 1-5: length of the transmission path."""

LIGHT_RUNTIME_S_PER_M: Final[float] = 5e-9
"""t = 5 ns/m, the runtime constant of the 1.6.1 length formula L = n / (f * t)."""

LENGTH_TIMER_CLOCKS_PER_BIT: Final[int] = 16
"""The length timer runs at 16 times the bit rate: 1.6.1 gives f = 8 MHz for 500 kbit/s."""

# ----------------------------------------------------------------------------------------------------------------
# Address map: Table 3-10
# ----------------------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class AddressRow:
    """One row of Table 3-10: what a write and what a read reach at a relative address. ``None`` is "-"."""

    address: int
    write: str | None
    read: str


ADDRESS_MAP: Final[tuple[AddressRow, ...]] = (
    AddressRow(0, "INTERBUS IN byte 0", "INTERBUS OUT byte 0"),
    AddressRow(1, "INTERBUS IN byte 1", "INTERBUS OUT byte 1"),
    AddressRow(2, "INTERBUS IN byte 2", "INTERBUS OUT byte 2"),
    AddressRow(3, "INTERBUS IN byte 3", "INTERBUS OUT byte 3"),
    AddressRow(4, "Reserved", "Reserved"),
    AddressRow(5, "Reserved", "Reserved"),
    AddressRow(6, None, "Reserved"),
    AddressRow(7, "Processor alarm register", "Processor command register"),
    AddressRow(8, None, "Length of the outgoing interface"),
    AddressRow(9, None, "Length of the bus branch"),
    AddressRow(10, None, "Power level of the incoming interface, enable"),
    AddressRow(11, None, "Power level of the branch and the outgoing interface"),
    AddressRow(12, "ID code", "ID code"),
    AddressRow(13, "SET register", "SET register"),
    AddressRow(14, "Interrupt enable", "Interrupt event"),
    AddressRow(15, "Block transfer", "Block transfer"),
)
"""Table 3-10: the 16-byte address area of the serial µP interface."""

INIT_BYTE_MOTOROLA: Final[int] = 0x00
INIT_BYTE_INTEL: Final[int] = 0x81
"""Table 3-8: initialization byte values (bit-reflected, so either bit order reads the same)."""

BLOCK_TRANSFER_COMMAND: Final[int] = 0xCF
"""3.4.6: a write with CFh to address 15 activates block transfer."""

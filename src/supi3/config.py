"""Pin-strap decoding: from C[4..0], MFP[15..12], RF[1..0], CLK_CONF[1..0] and DIAG_CONF to a device configuration.

The decoder reads only the tables of :mod:`supi3.tables` (Tables 1-4, 1-7, 2-2, 2-4 to 2-7, 3-1 to 3-6, 3-11,
3-16). Every combination those tables do not allow raises :class:`~supi3.errors.ConfigurationError` naming the
pins, the value and the table that rules it out.

Pins of cell type CIp (C4, RF[1..0], DIAG_CONF; Table 1-4) have pull-ups: passing ``None`` for them means "left
open", which reads as 1. On the SUPI 3 LS these pins do not exist (Table 1-4, TQFP 44 column): C4 is fixed at 1
(Tables 2-4 to 2-6, footnote), RF and DIAG_CONF must be ``None``.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass
from enum import StrEnum
from functools import cache

from supi3 import tables
from supi3.checks import check_instance, describe, fail
from supi3.errors import ConfigurationError
from supi3.tables import PinDirection, PinFunction


class Variant(StrEnum):
    """Chip variant (Table 1-1): SUPI 3 OPC in TQFP 64, SUPI 3 LS in TQFP 44."""

    OPC = "opc"
    LS = "ls"


class Interface(StrEnum):
    """INTERBUS interface type, as the mode tables abbreviate it (Tables 2-4 to 2-7)."""

    RB = "RB"
    LB_MR = "LB-MR"
    LBD_MR = "LBD-MR"
    LBD_OR = "LBD-OR"
    BK_RB = "BK-RB"
    BK_LB = "BK-LB"
    BK_LBD = "BK-LBD"

    @property
    def is_bus_terminal(self) -> bool:
        """True for the bus terminal module interfaces of Table 2-7."""
        return self.value.startswith("BK")


class MfpKind(StrEnum):
    """What the MFP application interface does (3.1)."""

    BINARY_IO = "binary-io"
    SPI_MASTER = "spi-master"
    INIT_UP = "init-up"
    NONE = "none"
    """Bus terminal module without µP interface (Table 2-7, first three rows)."""


class DataDirection(StrEnum):
    """Direction of the process data, seen from the bus master: IN reaches the master, OUT leaves it."""

    IN = "in"
    OUT = "out"
    IN_OUT = "in/out"
    NONE = "none"


@dataclass(frozen=True)
class MfpMode:
    """The MFP mode selected by a mode-table row.

    ``width`` is the number of process-data bits per direction on the MFPs (binary I/O) or per SPI transfer
    (SPI master); it is 0 for the µP interface and the plain bus terminal, whose data length is not set by pins.
    """

    kind: MfpKind
    direction: DataDirection
    width: int

    @property
    def name(self) -> str:
        """The mode as Tables 3-1/3-2 name it ("4 IN/4 OUT", "SPI 16 IN", "Init-µP")."""
        if self.kind is MfpKind.INIT_UP:
            return "Init-µP"
        if self.kind is MfpKind.NONE:
            return "none"
        prefix = "SPI " if self.kind is MfpKind.SPI_MASTER else ""
        if self.direction is DataDirection.IN_OUT:
            return f"{prefix}{self.width} IN/{self.width} OUT"
        return f"{prefix}{self.width} {self.direction.value.upper()}"


@dataclass(frozen=True)
class Straps:
    """The configuration pins as bit strings, MSB first. ``None`` means the pin is open (CIp pull-up) or absent."""

    c: str
    mfp: str | None = None
    rf: str | None = None
    clk_conf: str = "01"
    diag_conf: str | None = None
    variant: Variant = Variant.OPC


@dataclass(frozen=True)
class DeviceConfig:
    """An immutable device configuration decoded from pin straps.

    Attributes mirror what the manual's tables state for one row; ``function`` is the manual's function text
    and ``table`` the table it comes from.
    """

    variant: Variant
    interface: Interface
    mfp_mode: MfpMode
    length_code: int
    id_code: int
    bit_rate: int
    rf_mode: tables.RfMode | None
    """Table 2-2 row; ``None`` on the SUPI 3 LS (no RF pins, copper only)."""
    diagnostics: tables.DiagConf | None
    """Table 3-16 row; ``None`` on the SUPI 3 LS (no DIAG_CONF, only IB_DIAG)."""
    function: str
    table: str

    @property
    def data_bits(self) -> int:
        """Data length in bits per direction (Table 3-11). 0 for Init-µP modes until software writes SET."""
        bits = tables.LENGTH_CODE_BY_VALUE[self.length_code].bits
        assert bits is not None  # mode tables use no reserved length code (tested)
        return bits

    @property
    def data_bytes(self) -> int:
        """Data length rounded up to whole bytes."""
        return (self.data_bits + 7) // 8

    @property
    def optical_regulation(self) -> bool:
        """True when RF[1..0] = 00 selects optical power regulation (Table 2-2, 1.6)."""
        return self.rf_mode is not None and self.rf_mode.optical_regulation

    @property
    def mfp_pins(self) -> tuple[PinFunction, ...]:
        """Functions of the assigned MFP pins after reset; unlisted MFPs are unused inputs (3.1)."""
        return _mfp_pins(self.interface, self.mfp_mode)

    @property
    def in_bits(self) -> tuple[tuple[int, int], ...]:
        """(data bit k, MFP pin) of every ``In<k>`` of a binary I/O mode (Tables 3-1, 3-2; bit k of the IN word,
        byte 0 most significant, 3.2); empty in the other modes."""
        return self._io_bits("In")

    @property
    def out_bits(self) -> tuple[tuple[int, int], ...]:
        """(data bit k, MFP pin) of every ``Out<k>`` of a binary I/O mode (Tables 3-1, 3-2); empty otherwise."""
        return self._io_bits("Out")

    def _io_bits(self, prefix: str) -> tuple[tuple[int, int], ...]:
        if self.mfp_mode.kind is not MfpKind.BINARY_IO:
            return ()
        return tuple((int(p.signal[len(prefix):]), p.pin) for p in self.mfp_pins if p.signal.startswith(prefix))

    @property
    def mfp_output_mask(self) -> int:
        """Bit n set when MFPn is driven by the chip after reset."""
        return sum(1 << p.pin for p in self.mfp_pins if p.direction is PinDirection.OUT)

    @property
    def package_pins(self) -> tuple[str, ...]:
        """Pin names of the housing, pin 1 first (Table 1-2 for the OPC, Table 1-3 for the LS)."""
        return tables.TQFP44_PINS if self.variant is Variant.LS else tables.TQFP64_PINS

    def straps(self) -> Straps:
        """The pin straps that select this configuration (inverse of :func:`decode`)."""
        row = _row_for(self.interface, self.mfp_mode)
        return Straps(
            c=row.c,
            mfp=row.mfp,
            rf=self.rf_mode.rf if self.rf_mode is not None else None,
            clk_conf=tables.clk_conf_for(self.bit_rate),
            diag_conf=str(self.diagnostics.diag_conf) if self.diagnostics is not None else None,
            variant=self.variant,
        )

    def as_dict(self) -> dict[str, object]:
        """A JSON-ready summary (the keys of ``supi3 decode --json``)."""
        return {
            "variant": self.variant.value,
            "interface": self.interface.value,
            "mfp_mode": self.mfp_mode.name,
            "mfp_kind": self.mfp_mode.kind.value,
            "direction": self.mfp_mode.direction.value,
            "id_code": f"{self.id_code:02X}",
            "length_code": f"{self.length_code:05b}",
            "data_bits": self.data_bits,
            "data_bytes": self.data_bytes,
            "bit_rate": self.bit_rate,
            "optical_regulation": self.optical_regulation,
            "rf_function": self.rf_mode.function if self.rf_mode else None,
            "diagnostics": self.diagnostics.kind if self.diagnostics else "IB_DIAG only (SUPI 3 LS)",
            "function": self.function,
            "table": f"Table {self.table}",
            "mfp_output_mask": f"{self.mfp_output_mask:04X}",
        }


# ------------------------------------------------------------------------------------------------------------
# Parsing the mode tables' function text
# ------------------------------------------------------------------------------------------------------------

_FUNCTION = re.compile(
    r"^(?P<iface>BK-RB|BK-LBD|BK-LB|LBD-MR|LBD-OR|LB-MR|RB)"
    r"(?:, (?:(?P<up>Init-µP)|(?P<spi>SPI )?(?P<w>\d+) (?P<dir>IN/(?:\d+ )?OUT|IN|OUT))| \(.*\))$"
)


def parse_function(function: str) -> tuple[Interface, MfpMode]:
    """Split a mode table's function text ("LBD-OR, SPI 16 IN/16 OUT") into interface and MFP mode.

    Raises
    ------
    ArgumentError
        ``function`` not a str, or not a function text of Tables 2-4 to 2-7 (an ``ArgumentError`` is a
        ``ValueError``).
    """
    m = _FUNCTION.match(function) if isinstance(function, str) else None
    if m is None:
        raise fail("function", "a mode table's function text such as 'LBD-OR, SPI 16 IN/16 OUT'", function,
                   "Tables 2-4 to 2-7")
    interface = Interface(m["iface"])
    if m["up"]:
        return interface, MfpMode(MfpKind.INIT_UP, DataDirection.NONE, 0)
    if m["w"] is None:
        return interface, MfpMode(MfpKind.NONE, DataDirection.NONE, 0)
    direction = {"IN": DataDirection.IN, "OUT": DataDirection.OUT}.get(m["dir"], DataDirection.IN_OUT)
    kind = MfpKind.SPI_MASTER if m["spi"] else MfpKind.BINARY_IO
    return interface, MfpMode(kind, direction, int(m["w"]))


@cache
def _rows_by_mode() -> dict[tuple[Interface, MfpMode], tables.ModeRow]:
    return {parse_function(row.function): row for row in tables.MODE_ROWS}


def _row_for(interface: Interface, mode: MfpMode) -> tables.ModeRow:
    return _rows_by_mode()[(interface, mode)]


def _up_reset_pins() -> tuple[PinFunction, ...]:
    """µP interface pins before the initialization byte: where Tables 3-5 and 3-6 agree, their function;
    elsewhere an input (MFP7 is preconfigured as input after each hardware reset, 3.4.3)."""
    pins = []
    for mot, intel in zip(tables.UP_MOTOROLA_MFP, tables.UP_INTEL_MFP, strict=True):
        if mot.signal == intel.signal and mot.direction is intel.direction:
            pins.append(mot)
        else:
            pins.append(PinFunction(mot.pin, f"{mot.signal} | {intel.signal}", PinDirection.IN,
                                    "input until the initialization byte selects Motorola or Intel (3.4.3)"))
    return tuple(pins)


def _mfp_pins(interface: Interface, mode: MfpMode) -> tuple[PinFunction, ...]:
    pins: tuple[PinFunction, ...] = ()
    if mode.kind is MfpKind.BINARY_IO:
        pins = tables.BINARY_IO_MFP[mode.name]
    elif mode.kind is MfpKind.SPI_MASTER:
        pins = tables.SPI_MASTER_MFP
    elif mode.kind is MfpKind.INIT_UP:
        pins = _up_reset_pins()
    if interface.is_bus_terminal:
        pins = pins + tables.BUS_TERMINAL_MFP
    elif not (mode.kind is MfpKind.BINARY_IO and tables.BINARY_IO_TABLE[mode.name] == "3-2"):
        # Configuration expansion: MFP[15..12] carry C[8..5] (Table 3-1 heading, Tables 2-4 to 2-6).
        pins = pins + tuple(PinFunction(p, f"C{p - 7}", PinDirection.IN, "configuration expansion")
                            for p in range(12, 16))
    return tuple(sorted(pins, key=lambda p: p.pin))


# ------------------------------------------------------------------------------------------------------------
# Decoding
# ------------------------------------------------------------------------------------------------------------


def _bits(name: str, value: str | int | None, width: int) -> str | None:
    """Normalise a pin value to a ``width``-character bit string, MSB first."""
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int | str):
        raise ConfigurationError(name, describe(value), "input format", f"expected {width} bits as a string or int")
    if isinstance(value, int):
        if not 0 <= value < (1 << width):
            raise ConfigurationError(name, describe(value), "input format", f"does not fit in {width} bits")
        return format(value, f"0{width}b")
    text = value.strip().removeprefix("0b")
    if len(text) != width or set(text) - {"0", "1"}:
        raise ConfigurationError(name, describe(value), "input format", f"expected exactly {width} binary digits")
    return text


def _required(name: str, value: str | int | None, width: int) -> str:
    bits = _bits(name, value, width)
    if bits is None:
        raise ConfigurationError(name, "not given", "input format", "these pins have no pull-up and must be given")
    return bits


@cache
def _mode_rows_by_straps() -> dict[tuple[str, str | None], tables.ModeRow]:
    return {(row.c, row.mfp): row for row in tables.MODE_ROWS}


def _expansion_c() -> frozenset[str]:
    return frozenset(row.c for row in tables.MODE_ROWS if row.mfp is not None)


def _decode_mode(c: str, mfp: str | None, variant: Variant) -> tables.ModeRow:
    if variant is Variant.LS and c[0] == "0":
        raise ConfigurationError("C4", "0", "Tables 2-4 to 2-6, footnote *; Table 1-4",
                                 "C4 is set to 1 in the SUPI 3 LS and cannot be configured "
                                 "(no LB-MR or bus terminal modes on the LS)")
    if c in _expansion_c():
        if mfp is None:
            raise ConfigurationError("MFP[15..12]", "not given", f"Table {_table_of(c)}",
                                     f"C[4..0] = {c} selects a mode with configuration expansion: "
                                     "MFP[15..12] must be strapped")
        row = _mode_rows_by_straps().get((c, mfp))
        if row is None:
            raise ConfigurationError("MFP[15..12]", mfp, f"Table {_table_of(c)}",
                                     f"no operating mode for C[4..0] = {c} with this MFP pattern")
        return row
    row = _mode_rows_by_straps().get((c, None))
    if row is None:
        raise ConfigurationError("C[4..0]", c, "Tables 2-4 to 2-7", "no operating mode has this pattern")
    if mfp is not None:
        reason = "bus terminal signals (Table 2-8)" if row.table == "2-7" else "process data pins (Table 3-2)"
        raise ConfigurationError("MFP[15..12]", mfp, f"Table {row.table}",
                                 f"in mode {row.function!r} MFP[15..12] are {reason}, not configuration inputs; "
                                 "leave mfp unset")
    return row


def _table_of(c: str) -> str:
    return next(row.table for row in tables.MODE_ROWS if row.c == c)


def _decode_clock(clk_conf: str) -> int:
    for row in tables.CLOCK_CONFIGURATIONS:
        if row.clk_conf0 == clk_conf[1] and row.clk_conf1 in ("X", clk_conf[0]):
            if row.bit_rate is None:
                raise ConfigurationError("CLK_CONF[1..0]", clk_conf, "Table 1-7",
                                         "CLK_CONF0 = 0 is reserved")
            return row.bit_rate
    raise AssertionError("Table 1-7 covers every CLK_CONF value")  # pragma: no cover


def _decode_rf(rf: str | None, variant: Variant) -> tables.RfMode | None:
    if variant is Variant.LS:
        if rf is not None:
            raise ConfigurationError("RF[1..0]", rf, "Table 1-4; 1.6",
                                     "the SUPI 3 LS has no RF pins and no optical regulation")
        return None
    rf = "11" if rf is None else rf  # CIp pull-ups (Table 1-4)
    # Every 2-bit pattern has a row: Tables 2-2 and 2-9, and 01 for optical diagnostics (OPT-2).
    return next(row for row in tables.RF_MODES if row.rf == rf)


def _decode_diag(diag_conf: str | None, variant: Variant) -> tables.DiagConf | None:
    if variant is Variant.LS:
        if diag_conf is not None:
            raise ConfigurationError("DIAG_CONF", diag_conf, "Table 1-4; Table 3-16",
                                     "the SUPI 3 LS has no DIAG_CONF pin (IB_DIAG only)")
        return None
    value = 1 if diag_conf is None else int(diag_conf)  # CIp pull-up (Table 1-4)
    return next(row for row in tables.DIAG_CONFIGURATIONS if row.diag_conf == value)


def decode(
    c: str | int,
    mfp: str | int | None = None,
    rf: str | int | None = None,
    clk_conf: str | int = "01",
    diag_conf: str | int | None = None,
    variant: Variant | str = Variant.OPC,
) -> DeviceConfig:
    """Decode pin straps into a :class:`DeviceConfig`.

    Parameters
    ----------
    c:
        C[4..0], five bits MSB first (``"10011"`` or ``0b10011``).
    mfp:
        MFP[15..12], only for the modes with configuration expansion (C[3..0] = 1011 or 1111, Tables 2-4 to
        2-6); ``None`` otherwise.
    rf:
        RF[1..0] (Table 2-2); ``None`` = open (pull-up, 11) on the OPC; must be ``None`` on the LS.
    clk_conf:
        CLK_CONF[1..0] (Table 1-7).
    diag_conf:
        DIAG_CONF (Table 3-16); ``None`` = open (pull-up, 1) on the OPC; must be ``None`` on the LS.
    variant:
        ``"opc"`` or ``"ls"`` (Table 1-1).

    Raises
    ------
    ConfigurationError
        For every combination the manual's tables do not allow.
    """
    try:
        variant = Variant(variant)
    except ValueError:
        raise ConfigurationError("variant", repr(variant), "Table 1-1", "expected 'opc' or 'ls'") from None
    c_bits = _required("C[4..0]", c, 5)
    clk_bits = _required("CLK_CONF[1..0]", clk_conf, 2)
    row = _decode_mode(c_bits, _bits("MFP[15..12]", mfp, 4), variant)
    interface, mode = parse_function(row.function)
    return DeviceConfig(
        variant=variant,
        interface=interface,
        mfp_mode=mode,
        length_code=int(row.length_code, 2),
        id_code=row.id_code,
        bit_rate=_decode_clock(clk_bits),
        rf_mode=_decode_rf(_bits("RF[1..0]", rf, 2), variant),
        diagnostics=_decode_diag(_bits("DIAG_CONF", diag_conf, 1), variant),
        function=row.function,
        table=row.table,
    )


def decode_straps(straps: Straps) -> DeviceConfig:
    """:func:`decode` applied to a :class:`Straps` record.

    Raises
    ------
    ArgumentError
        ``straps`` not a :class:`Straps`.
    """
    check_instance("straps", straps, Straps)
    return decode(straps.c, straps.mfp, straps.rf, straps.clk_conf, straps.diag_conf, straps.variant)


def mode_rows(variant: Variant | str = Variant.OPC, interface: Interface | str | None = None
              ) -> Iterator[tables.ModeRow]:
    """The mode-table rows available on a variant, optionally for one interface, in manual order.

    Raises
    ------
    ArgumentError
        ``variant`` not a :class:`Variant` or its value, ``interface`` neither ``None`` nor an :class:`Interface` or its
        value; raised by the call, not at the first row taken.
    """
    variant = Variant(_member("variant", variant, Variant, "Table 1-1"))
    wanted = Interface(_member("interface", interface, Interface, "Tables 2-4 to 2-7")) if interface is not None \
        else None
    return _rows_of(variant, wanted)


def _member(name: str, value: object, kind: type[StrEnum], limit: str) -> str:
    """``value`` if it is a member of ``kind`` or a member's value (a str), else the named error."""
    if isinstance(value, str) and value in {member.value for member in kind}:
        return value
    raise fail(name, f"one of {', '.join(repr(member.value) for member in kind)}", value, limit)


def _rows_of(variant: Variant, wanted: Interface | None) -> Iterator[tables.ModeRow]:
    for row in tables.MODE_ROWS:
        if variant is Variant.LS and row.c[0] == "0":
            continue
        if wanted is None or parse_function(row.function)[0] is wanted:
            yield row

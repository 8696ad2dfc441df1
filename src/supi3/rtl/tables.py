"""The strap decode tables of the RTL core, generated at elaboration from the spec layer alone.

Every mode comes from :data:`supi3.tables.MODE_ROWS` through :func:`supi3.config.decode`, and every per-mode
quantity the RTL needs is derived from that configuration, the manual's tables (:mod:`supi3.tables`) and the wire
format (:mod:`supi3.interbus.wire`): ID register, data length, MFP output enables, the MFP in/out maps in line order
(docs/interbus.md, "Frame"; Tables 3-1 and 3-2), the timing per bit rate (Table 1-7) and the RF/DIAG_CONF flags
(Tables 2-2, 3-16). Nothing is read off the model: the model (``model.pins.Supi3Pins``) derives the same
quantities on its own, and ``tests/test_rtl_tables.py`` compares the two derivations for every strap combination
(the lockstep then compares the two implementations built on them).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cache, cached_property
from typing import Final

from supi3.checks import check_instance, check_int, fail
from supi3.config import DataDirection, DeviceConfig, Interface, MfpKind, Variant, decode, mode_rows
from supi3.diagnostics import watches_line_interrupt
from supi3.errors import ConfigurationError
from supi3.interbus import wire
from supi3.pinout import C_BITS, CLK_CONF_BITS, DIAG_CONF_BITS, EXPANSION_BITS, MFP_PINS, RF_BITS, SYNC_STAGES
from supi3.regmap.core import BYTE_BITS
from supi3.tables import (
    BIT_RATES,
    CLOCK_HZ,
    RESET_MIN_S,
    RESREG_PULSE_CLOCKS,
    STATERR_FILTER_S,
    WATCHDOG_TIMEOUTS_S,
)
from supi3.terminal import TerminalMode

__all__ = [
    "CLK_CONF_BITS",
    "C_BITS",
    "DIAG_CONF_BITS",
    "EXPANSION_BITS",
    "IDLE_TIMEOUT_CLOCKS",
    "MFP_PINS",
    "MODACK_PULSE_CLOCKS",
    "RESET_STRETCH_CLOCKS",
    "RESREG_PULSE_CLOCKS",
    "RF_BITS",
    "STATERR_FILTER_CLOCKS",
    "WATCHDOG_CLOCKS",
    "ClockEntry",
    "CoreTables",
    "ModeEntry",
    "SerialMode",
    "check_variant",
    "clock_entry",
    "complete_diagnostics",
    "core_tables",
    "line_position",
    "mode_entry",
    "rbst_by_pin",
    "serial_mode",
]

STATERR_FILTER_CLOCKS: Final = round(STATERR_FILTER_S * CLOCK_HZ)
"""/StatErr must stay low this many clocks (200 ms, 3.6.2) before the peripheral fault is latched."""
MODACK_PULSE_CLOCKS: Final = RESREG_PULSE_CLOCKS
"""/ModAck pulse on Quit Peripheral Error: the manual gives no width; the chip's other single pulse (375 ns,
Table 3-13) is used (docs/assumptions/model.md M3)."""
WATCHDOG_CLOCKS: Final[tuple[int | None, ...]] = tuple(
    None if t is None else round(t * CLOCK_HZ) for t in WATCHDOG_TIMEOUTS_S
)
"""Layer-2 watchdog times in clocks, indexed by the command word's watchdog code, ``None`` for off (Table 3-13)."""
RESET_STRETCH_CLOCKS: Final = round(RESET_MIN_S * CLOCK_HZ)
"""The internal reset lasts 128 clocks (4 µs, 1.7.2) after its last source went away (M2)."""
IDLE_TIMEOUT_CLOCKS: Final = round(wire.IDLE_TIMEOUT_S * CLOCK_HZ)
"""A line without a telegram start for 20 ms is an INTERBUS reset (docs/interbus.md A13), once per silence."""

RBST_EXT_CONTROLLED: Final = "Controlled"
"""Table 2-2's RBST_EXT column in the row where the pin tells whether a device follows (RF = 10)."""
DIAG1_BA: Final = "BA"
"""Table 3-16's DIAG1 column in the row of complete diagnostics (DIAG_CONF = 0): DIAG1 shows BA."""


@dataclass(frozen=True)
class ModeEntry:
    """What one operating-mode row (Tables 2-4 to 2-7) sets in the chip core.

    Attributes
    ----------
    pattern:
        C[4..0] then MFP[15..12], MSB first, ``-`` where MFP[15..12] are not straps (Amaranth ``Case`` pattern).
    id_register:
        Bits 12..0 of the ID register: length code and ID code (Tables 3-11, A-3); the core adds bits 15..13.
    data_bytes:
        Bytes the chip occupies on the line in a data cycle (Table 3-11, docs/interbus.md A15).
    mfp_oe:
        MFP output enables after reset (Tables 3-1 to 3-6, 2-8).
    in_pins:
        For each bit of the shift register in line order (bit 0 goes out first), the MFP pin it is loaded from at
        the start of a data cycle, or ``None`` (loaded with 0).
    out_bits:
        For each MFP pin, the shift-register bit it takes at the latch of a data cycle, or ``None`` (driven 0).
    init_up:
        An Init-µP mode: the model has a register file, which gives the ID register and the data from the serial
        µP interface (``supi3.top``); ``id_register`` and ``data_bytes`` are then its µP_Not_Ready values.
    """

    pattern: str
    id_register: int
    data_bytes: int
    mfp_oe: int
    in_pins: tuple[int | None, ...]
    out_bits: tuple[int | None, ...]
    init_up: bool

    @property
    def io_map(self) -> tuple[tuple[int | None, ...], tuple[int | None, ...]]:
        """The MFP maps alone: rows with equal maps share one branch of the load and latch multiplexers."""
        return self.in_pins, self.out_bits


@dataclass(frozen=True)
class SerialMode:
    """What an SPI master row (Tables 2-4 to 2-6, SM-1) sets in the serial I/O block: direction and bits."""

    direction: DataDirection
    bits: int


@dataclass(frozen=True)
class ClockEntry:
    """One usable CLK_CONF[1..0] value (Table 1-7) and the timing the model derives from its bit rate."""

    clk_conf: int
    rate: int
    """The bit rate's index in :data:`supi3.tables.BIT_RATES`."""
    clocks_per_bit: int
    forward_delay: int
    """Clocks from a bit's first synchronised edge to its repetition on DO2 (docs/interbus.md A10)."""
    reset_run: int
    """Clocks of start level that make an INTERBUS reset (docs/interbus.md A12)."""


@dataclass(frozen=True)
class CoreTables:
    """Everything the RTL core decodes from its strap ports, for one chip variant."""

    variant: Variant
    modes: tuple[ModeEntry, ...]
    serial: tuple[SerialMode | None, ...]
    """For each mode, the SPI master direction and width, or ``None`` (not an SPI master mode)."""
    clocks: tuple[ClockEntry, ...]
    rbst_by_pin: tuple[int, ...]
    """RF[1..0] values that select bus connector recognition via RBST_EXT (Table 2-2)."""
    complete_diagnostics: tuple[int, ...]
    """DIAG_CONF values that select complete diagnostics, DIAG1 = BA (Table 3-16)."""
    diagnostics: tuple[tuple[bool, TerminalMode], ...]
    """For each mode, (it raises the line interrupt ahead, its bus terminal interface or NONE): ``supi3.diagnostics``
    (DG-3), ``supi3.terminal`` (Tables 2-7, 2-8)."""
    lines: tuple[tuple[bool, bool], ...]
    """For each mode, (an LBD mode: the counter telegram blocks run on the forward line, LBD-MR: on the return line
    too), Table 2-5 (BK-34)."""

    @property
    def io_maps(self) -> tuple[tuple[tuple[int | None, ...], tuple[int | None, ...]], ...]:
        """The distinct MFP maps, in first-use order."""
        return tuple(dict.fromkeys(mode.io_map for mode in self.modes))

    @cached_property
    def strap_modes(self) -> tuple[int | None, ...]:
        """For every value of the mode straps C[4..0] and MFP[15..12] (C in the upper bits), the index of the first
        mode whose :attr:`ModeEntry.pattern` it matches, or ``None`` (reserved): the address decode of the strap
        ROM (docs/rtl.md, round 4: a lookup by the strap value synthesises smaller than one case per row)."""
        width = C_BITS + EXPANSION_BITS
        found: list[int | None] = []
        for value in range(1 << width):
            bits = _bits(value, width)
            matches = (k for k, mode in enumerate(self.modes)
                       if all(p in ("-", b) for p, b in zip(mode.pattern, bits, strict=True)))  # fmt: skip
            found.append(next(matches, None))
        return tuple(found)

    @property
    def register_bits(self) -> int:
        """Width of the frame shift register: the widest data register (SPI 32) or the ID register."""
        return 8 * max(2, *(mode.data_bytes for mode in self.modes))


def _bits(value: int, width: int) -> str:
    return format(value, f"0{width}b")


def line_position(word_bit: int, n: int) -> int:
    """The shift-register position (line order, 0 goes out first) of bit ``word_bit`` of an ``n``-byte data word:
    byte 0, the most significant, first (docs/interbus.md "Frame", 3.4.8), each byte LSB first or MSB first as
    :data:`supi3.interbus.wire.DATA_LSB_FIRST` says.

    Raises
    ------
    ArgumentError
        ``n`` not an integer >= 1, ``word_bit`` not a bit of the word (0 to ``8 n - 1``).
    """
    n = check_int("n", n, 1, limit="bytes in the data word")
    byte, k = divmod(check_int("word_bit", word_bit, 0, 8 * n - 1, limit=f"a bit of the {n}-byte word"), 8)
    return 8 * (n - 1 - byte) + (k if wire.DATA_LSB_FIRST else 7 - k)


def _io_bit(signal: str, prefix: str) -> int | None:
    """The data bit of an MFP signal ``In<k>``/``Out<k>`` (Tables 3-1, 3-2), ``None`` for other signals."""
    rest = signal[len(prefix) :]
    return int(rest) if signal.startswith(prefix) and rest.isdigit() else None


def mode_entry(config: DeviceConfig) -> ModeEntry:
    """What the straps of ``config`` set in the core, from the manual's tables alone.

    The ID register is the straps' length and ID code (Table 3-11; in Init-µP modes the µP_Not_Ready code, 3.4.1);
    the data length is the length code's (:func:`supi3.interbus.wire.data_bytes`); the MFP maps are the
    ``In<k>``/``Out<k>`` signals of the binary I/O modes (Tables 3-1, 3-2), placed in line order; the output
    enables are the pins the mode drives (Tables 3-1 to 3-6, 2-8).
    """
    check_instance("config", config, DeviceConfig)
    n = wire.data_bytes(config.length_code)
    binary = config.mfp_mode.kind is MfpKind.BINARY_IO
    in_pins: list[int | None] = [None] * (8 * n)
    out_bits: list[int | None] = [None] * MFP_PINS
    for function in config.mfp_pins if binary else ():
        if (bit := _io_bit(function.signal, "In")) is not None:
            in_pins[line_position(bit, n)] = function.pin
        elif (bit := _io_bit(function.signal, "Out")) is not None:
            out_bits[function.pin] = line_position(bit, n)
    straps = config.straps()
    pattern = straps.c + (straps.mfp if straps.mfp is not None else "-" * EXPANSION_BITS)
    id_register = (config.length_code << BYTE_BITS) | config.id_code
    init_up = config.mfp_mode.kind is MfpKind.INIT_UP
    return ModeEntry(pattern, id_register, n, config.mfp_output_mask, tuple(in_pins), tuple(out_bits), init_up)


def clock_entry(clk_conf: int, config: DeviceConfig) -> ClockEntry:
    """The timing of the bit rate ``config`` selects through CLK_CONF = ``clk_conf`` (Table 1-7): the bit period
    (1.7.1), the repeater delay (docs/interbus.md A10, less the synchroniser's stages, M8) and the reset run
    (A12, M11)."""
    check_int("clk_conf", clk_conf, 0, (1 << CLK_CONF_BITS) - 1, limit="CLK_CONF, Table 1-7")
    check_instance("config", config, DeviceConfig)
    cpb = wire.clocks_per_bit(config.bit_rate)
    forward_delay = wire.REPEATER_DELAY_BITS * cpb - SYNC_STAGES
    return ClockEntry(clk_conf, BIT_RATES.index(config.bit_rate), cpb, forward_delay, wire.RESET_DETECT_BITS * cpb)


def serial_mode(config: DeviceConfig) -> SerialMode | None:
    """The serial I/O of ``config``'s MFP mode (SM-1: the "SPI" rows), or ``None``."""
    check_instance("config", config, DeviceConfig)
    mode = config.mfp_mode
    return SerialMode(mode.direction, mode.width) if mode.kind is MfpKind.SPI_MASTER else None


def rbst_by_pin(config: DeviceConfig) -> bool:
    """A following device is told by RBST_EXT (the row of Table 2-2 where RBST_EXT is "Controlled"), not
    recognised on DI2 (M5)."""
    check_instance("config", config, DeviceConfig)
    return config.rf_mode is not None and config.rf_mode.rbst_ext == RBST_EXT_CONTROLLED


def complete_diagnostics(config: DeviceConfig) -> bool:
    """DIAG1 shows BA: complete diagnostics (Table 3-16)."""
    check_instance("config", config, DeviceConfig)
    return config.diagnostics is not None and config.diagnostics.diag1 == DIAG1_BA


def _values(width: int, make: Callable[[str], DeviceConfig]) -> list[tuple[int, DeviceConfig]]:
    """Every value of a ``width``-bit strap for which ``make(bits)`` decodes, with its configuration."""
    found = []
    for value in range(1 << width):
        try:
            found.append((value, make(_bits(value, width))))
        except ConfigurationError:
            continue
    return found


@cache
def check_variant(variant: object) -> Variant:
    """``variant`` as a :class:`~supi3.config.Variant`: a member or its value, ``"opc"`` or ``"ls"`` (Table 1-1).

    Raises
    ------
    ArgumentError
        Anything else ("variant must be one of 'opc', 'ls' (Table 1-1), not ...").
    """
    if isinstance(variant, str) and variant in {member.value for member in Variant}:
        return Variant(variant)
    raise fail("variant", f"one of {', '.join(repr(member.value) for member in Variant)}", variant, "Table 1-1")


def core_tables(variant: Variant | str = Variant.OPC) -> CoreTables:
    """The strap decode tables of ``variant`` (computed once per variant).

    The clock, RF and DIAG_CONF entries are probed on the variant's first mode row; they do not depend on the mode.
    """
    variant = check_variant(variant)
    rows = list(mode_rows(variant))
    configs = [decode(row.c, row.mfp, variant=variant) for row in rows]
    modes = tuple(mode_entry(config) for config in configs)
    serial = tuple(serial_mode(config) for config in configs)
    first = rows[0]
    clocks = []
    for value, config in _values(CLK_CONF_BITS, lambda b: decode(first.c, first.mfp, clk_conf=b, variant=variant)):
        clocks.append(clock_entry(value, config))
    if variant is Variant.LS:  # no RF and DIAG_CONF pins (Table 1-4): what the LS's configuration says
        ls = decode(first.c, first.mfp, variant=variant)
        rbst = tuple(range(1 << RF_BITS)) if rbst_by_pin(ls) else ()
        complete = tuple(range(1 << DIAG_CONF_BITS)) if complete_diagnostics(ls) else ()
    else:
        rf = _values(RF_BITS, lambda b: decode(first.c, first.mfp, rf=b, variant=variant))
        diag = _values(DIAG_CONF_BITS, lambda b: decode(first.c, first.mfp, diag_conf=b, variant=variant))
        rbst = tuple(value for value, config in rf if rbst_by_pin(config))
        complete = tuple(value for value, config in diag if complete_diagnostics(config))
    diagnostics = tuple((watches_line_interrupt(config), TerminalMode.of(config.interface.value)) for config in configs)
    lbd = (Interface.LBD_MR, Interface.LBD_OR)
    lines = tuple((config.interface in lbd, config.interface is Interface.LBD_MR) for config in configs)
    return CoreTables(variant, modes, serial, tuple(clocks), rbst, complete, diagnostics, lines)

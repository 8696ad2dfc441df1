"""The strap decode tables of the RTL core, generated at elaboration from the manual's tables and the model.

Nothing here is typed in: every mode comes from :data:`supi3.tables.MODE_ROWS` through :func:`supi3.config.decode`,
and every per-mode quantity the RTL needs is read off the cycle-accurate model built for that configuration
(:class:`supi3.model.pins.Supi3Pins` and its :class:`~supi3.model.chip.Supi3`). The MFP maps are found by probing the
model's public bus interface (``load_at``/``latch_at``) one pin and one register bit at a time, so the RTL moves
exactly the bits the model moves, in the model's line order (docs/interbus.md, "Frame"; Tables 3-1 and 3-2).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from typing import Final

from supi3.checks import fail
from supi3.config import DeviceConfig, Straps, Variant, decode, mode_rows
from supi3.errors import ConfigurationError
from supi3.interbus.wire import Cycle
from supi3.model.pins import Supi3Pins
from supi3.tables import BIT_RATES, DIAG_CONFIGURATIONS, MODE_ROWS, RF_MODES

MFP_PINS: Final = next(pin.width for pin in Supi3Pins.inputs if pin.name == "mfp_in")
"""MFP[15..0] (Table 1-4)."""

C_BITS: Final = len(MODE_ROWS[0].c)
"""C[4..0] (Tables 2-4 to 2-7)."""

RF_BITS: Final = len(RF_MODES[0].rf)
"""RF[1..0] (Table 2-2)."""

CLK_CONF_BITS: Final = len(Straps("").clk_conf)
"""CLK_CONF[1..0] (Table 1-7)."""

DIAG_CONF_BITS: Final = len(str(DIAG_CONFIGURATIONS[0].diag_conf))
"""DIAG_CONF (Table 3-16), one pin."""

EXPANSION_BITS: Final = next(len(row.mfp) for row in MODE_ROWS if row.mfp is not None)
"""MFP[15..12]: the configuration expansion C[8..5] in the modes of Table 3-1 (Tables 2-4 to 2-6)."""


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
        µP interface (:mod:`supi3.model.top`); ``id_register`` and ``data_bytes`` are then its µP_Not_Ready values.
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
    clocks: tuple[ClockEntry, ...]
    rbst_by_pin: tuple[int, ...]
    """RF[1..0] values that select bus connector recognition via RBST_EXT (Table 2-2)."""
    complete_diagnostics: tuple[int, ...]
    """DIAG_CONF values that select complete diagnostics, DIAG1 = BA (Table 3-16)."""

    @property
    def io_maps(self) -> tuple[tuple[tuple[int | None, ...], tuple[int | None, ...]], ...]:
        """The distinct MFP maps, in first-use order."""
        return tuple(dict.fromkeys(mode.io_map for mode in self.modes))

    @property
    def register_bits(self) -> int:
        """Width of the frame shift register: the widest data register (SPI 32) or the ID register."""
        return 8 * max(2, *(mode.data_bytes for mode in self.modes))


def _bits(value: int, width: int) -> str:
    return format(value, f"0{width}b")


def _probe_mode(config: DeviceConfig) -> ModeEntry:
    pins = Supi3Pins(config)
    chip = pins.chip
    id_register = chip.id_register()  # fresh chip: management bits 15..13 are 0
    n = chip.data_bytes()
    in_pins: list[int | None] = [None] * (8 * n)
    for pin in range(MFP_PINS):
        chip.set_mfp_inputs(1 << pin)
        register = int.from_bytes(chip.load_at(Cycle.DATA, 0), "little")  # the pin model's register order
        if register:
            in_pins[register.bit_length() - 1] = pin
    out_bits: list[int | None] = [None] * MFP_PINS
    for bit in range(8 * n):
        chip.latch_at(Cycle.DATA, (1 << bit).to_bytes(n, "little"), 0)
        if chip.mfp_outputs:
            out_bits[chip.mfp_outputs.bit_length() - 1] = bit
    straps = config.straps()
    pattern = straps.c + (straps.mfp if straps.mfp is not None else "-" * EXPANSION_BITS)
    init_up = chip.registers is not None
    return ModeEntry(pattern, id_register, n, pins.mfp_oe, tuple(in_pins), tuple(out_bits), init_up)


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
    modes = tuple(_probe_mode(decode(row.c, row.mfp, variant=variant)) for row in rows)
    first = rows[0]
    clocks = []
    for value, config in _values(CLK_CONF_BITS, lambda b: decode(first.c, first.mfp, clk_conf=b, variant=variant)):
        pins = Supi3Pins(config)
        rate = BIT_RATES.index(config.bit_rate)
        clocks.append(ClockEntry(value, rate, pins.cpb, pins.forward_delay, pins.reset_run))
    if variant is Variant.LS:  # no RF and DIAG_CONF pins (Table 1-4): the model's defaults for the LS
        ls = Supi3Pins(decode(first.c, first.mfp, variant=variant))
        rbst = tuple(range(1 << RF_BITS)) if ls.rbst_by_pin else ()
        complete = tuple(range(1 << DIAG_CONF_BITS)) if ls.complete_diagnostics else ()
    else:
        rf = _values(RF_BITS, lambda b: decode(first.c, first.mfp, rf=b, variant=variant))
        diag = _values(DIAG_CONF_BITS, lambda b: decode(first.c, first.mfp, diag_conf=b, variant=variant))
        rbst = tuple(value for value, config in rf if Supi3Pins(config).rbst_by_pin)
        complete = tuple(value for value, config in diag if Supi3Pins(config).complete_diagnostics)
    return CoreTables(variant, modes, tuple(clocks), rbst, complete)

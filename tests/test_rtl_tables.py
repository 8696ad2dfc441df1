"""The RTL's elaboration tables and port lists come from the spec layer; the model derives the same on its own.

``supi3.rtl.tables`` and ``supi3.rtl.upif`` build their tables from ``supi3.tables``, ``supi3.config`` and
``supi3.interbus.wire`` only, and ``supi3.pinout`` declares the ports; nothing is read off the model. Here, for every
valid strap combination, (1) what the RTL's strap decode selects equals the spec derivation, and (2) the model, probed
through its public interface, agrees with it: two independent derivations compared. The lockstep tests then compare
the two implementations built on them.
"""

from __future__ import annotations

import itertools
import re
from dataclasses import asdict
from functools import cache
from pathlib import Path

import pytest

from supi3 import pinout
from supi3 import top as model_top
from supi3.config import DeviceConfig, Interface, Variant, decode
from supi3.errors import ConfigurationError
from supi3.interbus.wire import Cycle
from supi3.model import chip as model_chip
from supi3.model import pins as model_pins
from supi3.model.pins import Supi3Pins
from supi3.rtl import tables as rtl_tables
from supi3.rtl.tables import (
    ClockEntry,
    CoreTables,
    ModeEntry,
    clock_entry,
    complete_diagnostics,
    core_tables,
    mode_entry,
    rbst_by_pin,
)
from supi3.rtl.upif import upif_tables
from supi3.spi import block_pins, slave_pins
from supi3.spi import upif as spi_upif
from supi3.tables import BIT_RATES

VARIANTS = list(Variant)
LBD_INTERFACES = (Interface.LBD_MR, Interface.LBD_OR)
"""The local bus with counter telegrams, Table 2-5: the chip runs the counter telegram blocks (BK-34)."""
RTL_SOURCES = Path(rtl_tables.__file__).parent


def _strap_values(width: int) -> list[str]:
    return [format(value, f"0{width}b") for value in range(1 << width)]


@cache
def valid_combinations(variant: Variant) -> tuple[tuple[str, str | None, str | None, str, str | None], ...]:
    """Every (C, MFP[15..12], RF, CLK_CONF, DIAG_CONF) that decodes on ``variant``; MFP only where it is a strap,
    RF and DIAG_CONF absent on the LS (Table 1-4)."""
    optional = variant is Variant.OPC
    rfs: list[str | None] = [*_strap_values(pinout.RF_BITS)] if optional else [None]
    diags: list[str | None] = [*_strap_values(pinout.DIAG_CONF_BITS)] if optional else [None]
    found = []
    for c in _strap_values(pinout.C_BITS):
        mfps: list[str | None] = [None, *_strap_values(pinout.EXPANSION_BITS)]
        for mfp, rf, clk, diag in itertools.product(mfps, rfs, _strap_values(pinout.CLK_CONF_BITS), diags):
            try:
                config = decode(c, mfp, rf=rf, clk_conf=clk, diag_conf=diag, variant=variant)
            except ConfigurationError:
                continue
            if (config.straps().mfp is None) == (mfp is None):
                found.append((c, mfp, rf, clk, diag))
    return tuple(found)


def _config(variant: Variant, combination: tuple[str, str | None, str | None, str, str | None]) -> DeviceConfig:
    c, mfp, rf, clk, diag = combination
    return decode(c, mfp, rf=rf, clk_conf=clk, diag_conf=diag, variant=variant)


def _matches(pattern: str, bits: str) -> bool:
    return all(p in ("-", b) for p, b in zip(pattern, bits, strict=True))


def rtl_decode(tables: CoreTables, combination: tuple[str, str | None, str | None, str, str | None]) -> tuple[
        ModeEntry | None, ClockEntry, bool, bool]:  # fmt: skip
    """What the RTL's strap decode selects for ``combination``: the mode row of the strap ROM's entry for C[4..0]
    and MFP[15..12] (:attr:`CoreTables.strap_modes`), the clock row of CLK_CONF or the first (reserved values), the
    flags."""
    c, mfp, rf, clk, diag = combination
    index = tables.strap_modes[int(c + (mfp if mfp is not None else "0" * pinout.EXPANSION_BITS), 2)]
    mode = None if index is None else tables.modes[index]
    clock = next((entry for entry in tables.clocks if entry.clk_conf == int(clk, 2)), tables.clocks[0])
    rbst = int(rf or "0", 2) in tables.rbst_by_pin
    complete = int(diag or "0", 2) in tables.complete_diagnostics
    return mode, clock, rbst, complete


def model_mode(config: DeviceConfig) -> ModeEntry:
    """The mode entry read off the model: its ID register and data length, MFP enables, and the MFP maps found by
    probing ``load_at``/``latch_at`` one pin and one register bit at a time (the register in line order)."""
    pins = Supi3Pins(config)
    chip = pins.chip
    id_register = chip.id_register()  # fresh chip: management bits 15..13 are 0
    n = chip.data_bytes()
    in_pins: list[int | None] = [None] * (8 * n)
    for pin in range(pinout.MFP_PINS):
        chip.set_mfp_inputs(1 << pin)
        register = int.from_bytes(chip.load_at(Cycle.DATA, 0), "little")
        if register:
            in_pins[register.bit_length() - 1] = pin
    out_bits: list[int | None] = [None] * pinout.MFP_PINS
    for bit in range(8 * n):
        chip.latch_at(Cycle.DATA, (1 << bit).to_bytes(n, "little"), 0)
        if chip.mfp_outputs:
            out_bits[chip.mfp_outputs.bit_length() - 1] = bit
    straps = config.straps()
    pattern = straps.c + (straps.mfp if straps.mfp is not None else "-" * pinout.EXPANSION_BITS)
    init_up = chip.registers is not None
    return ModeEntry(pattern, id_register, n, pins.mfp_oe, tuple(in_pins), tuple(out_bits), init_up)


@pytest.mark.parametrize("variant", VARIANTS)
def test_rtl_decode_equals_spec_derivation(variant: Variant) -> None:
    tables = core_tables(variant)
    combinations = valid_combinations(variant)
    assert len({combination[0] for combination in combinations}) > 1
    for combination in combinations:
        config = _config(variant, combination)
        mode, clock, rbst, complete = rtl_decode(tables, combination)
        assert mode == mode_entry(config), combination
        lines = tables.lines[tables.modes.index(mode)]
        assert lines == (config.interface in LBD_INTERFACES, config.interface is Interface.LBD_MR), combination
        assert clock == clock_entry(int(combination[3], 2), config), combination
        assert (rbst, complete) == (rbst_by_pin(config), complete_diagnostics(config)), combination


@pytest.mark.parametrize("variant", VARIANTS)
def test_strap_rom_selects_the_first_matching_row(variant: Variant) -> None:
    """Every value of C[4..0] and MFP[15..12] addresses the first mode row whose pattern it matches (the order of
    Tables 2-4 to 2-7), or no mode; every row is reached."""
    tables = core_tables(variant)
    width = pinout.C_BITS + pinout.EXPANSION_BITS
    assert len(tables.strap_modes) == 1 << width
    for value, index in enumerate(tables.strap_modes):
        bits = format(value, f"0{width}b")
        matching = [k for k, mode in enumerate(tables.modes) if _matches(mode.pattern, bits)]
        assert index == (matching[0] if matching else None), bits
    assert set(tables.strap_modes) - {None} == set(range(len(tables.modes)))


@pytest.mark.parametrize("variant", VARIANTS)
def test_model_agrees_with_spec_derivation(variant: Variant) -> None:
    for combination in valid_combinations(variant):
        config = _config(variant, combination)
        pins = Supi3Pins(config)
        assert model_mode(config) == mode_entry(config), combination
        clock = clock_entry(int(combination[3], 2), config)
        assert (clock.clocks_per_bit, clock.forward_delay, clock.reset_run) == (
            pins.cpb, pins.forward_delay, pins.reset_run), combination  # fmt: skip
        assert BIT_RATES[clock.rate] == config.bit_rate
        assert (rbst_by_pin(config), complete_diagnostics(config)) == (
            pins.rbst_by_pin, pins.complete_diagnostics), combination  # fmt: skip


def test_model_agrees_with_spec_constants() -> None:
    """The clock counts and pin-level decisions the RTL takes from the spec layer are the model's."""
    assert rtl_tables.STATERR_FILTER_CLOCKS == model_chip.STATERR_FILTER_CLOCKS
    assert rtl_tables.MODACK_PULSE_CLOCKS == model_chip.MODACK_PULSE_CLOCKS
    assert rtl_tables.RESREG_PULSE_CLOCKS == model_chip.RESREG_PULSE_CLOCKS
    assert rtl_tables.WATCHDOG_CLOCKS == model_chip.WATCHDOG_CLOCKS
    assert rtl_tables.RESET_STRETCH_CLOCKS == model_pins.RESET_STRETCH_CLOCKS
    assert rtl_tables.IDLE_TIMEOUT_CLOCKS == model_pins.IDLE_TIMEOUT_CLOCKS
    assert (pinout.C_D_COMMAND, pinout.C_D_DATA) == (spi_upif.C_D_COMMAND, spi_upif.C_D_DATA)


def test_model_agrees_with_pin_declaration() -> None:
    """The model's pin lists are the declaration's (the RTL's ports are built from the declaration)."""
    assert tuple(Supi3Pins.inputs) == pinout.CORE_INPUTS
    assert tuple(Supi3Pins.outputs) == pinout.CORE_OUTPUTS
    assert tuple(model_pins.IDLE_INPUTS) == pinout.CORE_IDLE
    assert asdict(slave_pins.PinsIn()) == pinout.UP_INPUT_IDLE
    declared = tuple(name for base in pinout.UP_OUTPUT_NAMES for name in (base, base + "_oe"))
    assert declared == slave_pins.OUTPUT_PINS
    assert (model_top.UP_INPUTS, model_top.UP_OUTPUTS, model_top.UP_PINS) == (
        pinout.UP_INPUTS, pinout.UP_OUTPUTS, pinout.UP_PINS)  # fmt: skip
    assert tuple(block_pins.UpifBlockPins.inputs) == pinout.UP_BLOCK_INPUTS
    assert tuple(block_pins.UpifBlockPins.outputs) == pinout.UP_BLOCK_OUTPUTS


def test_upif_tables_agree_with_model() -> None:
    """The µP block's output delay per bit rate (Table 3-7, UP-14) and its outputs after reset, derived from the
    spec layer, are what the model shows."""
    tables = upif_tables()
    assert tables.output_delay == tuple(block_pins.block_model(rate).output_delay for rate in BIT_RATES)
    for rate in BIT_RATES:
        assert tables.reset_outputs == asdict(block_pins.block_model(rate).tick(slave_pins.PinsIn()))


def test_rtl_imports_nothing_from_the_model() -> None:
    """Issue #9, part 2: the RTL modules import neither supi3.model nor supi3.spi (the lockstep adapters that do are
    supi3.verif.straps)."""
    for path in sorted(RTL_SOURCES.glob("*.py")):
        assert not re.search(r"supi3\.(model|spi)\b", path.read_text(encoding="utf-8")), path.name

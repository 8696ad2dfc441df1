"""The diagnostic outputs at pin level (supi3.model.blocks.outputs) and the transaction-level LED view
(Supi3.diagnostic_outputs) on shared scenarios: manual 3.6.1 (Tables 3-16 to 3-19), Table 2-8; DG-1 to DG-8
(docs/assumptions/diagnostics.md)."""

from __future__ import annotations

import numpy as np
import pytest

from supi3.config import DeviceConfig, decode
from supi3.diagnostics import DiagnosticOutputs, IbDiag, LedInputs, ib_diag_level
from supi3.interbus import wire
from supi3.interbus.wire import BranchControl, Cycle
from supi3.model.chip import STATERR_FILTER_CLOCKS, ChipArgumentError, Supi3
from supi3.model.pins import IDLE_TIMEOUT_CLOCKS, Supi3Pins
from supi3.optical.regulation import Interface, Response
from support import IDLE, STATERR_LATEST, Columns, CoreScript, assert_run_matches_step, quiet_inputs

SILENCE_BITS = round(wire.IDLE_TIMEOUT_S * 2_000_000) + 1000
"""Bit periods of a silent line at 2 Mbit/s (CLK_CONF = 11) that pass the idle time-out (A13)."""


def config(c: str = "10000", diag_conf: int = 0) -> DeviceConfig:
    return decode(c, clk_conf="11", diag_conf=diag_conf)


def agrees(pins: Supi3Pins, out: Columns, view: DiagnosticOutputs) -> None:
    """The pins in the last cycle of ``out`` show ``view`` (the chip's LED view then)."""
    c = pins.cycle - 1
    last = {name: int(trace[-1]) for name, trace in out.items()}
    assert (last["diag1"], last["diag2"]) == (view.diag1, view.diag2)
    assert last["res_reg_n"] == int(view.rc)
    assert last["ib_diag"] == ib_diag_level(view.ib_diag, c)
    if pins.config.interface.is_bus_terminal:  # Table 2-8; other modes' MFPs carry data
        assert last["mfp_out"] & 0xE100 == view.mfp
    else:
        assert view.mfp == 0
    assert last["resu_drive"] == int(not view.ul)


def tl_chip(cfg: DeviceConfig, *, active: bool = True) -> Supi3:
    """A transaction-level chip after the master's reset and, if ``active``, one latched data cycle."""
    chip = Supi3(cfg)
    chip.reset(0.001)
    if active:
        chip.load(Cycle.DATA, 0.002)
        chip.latch(Cycle.DATA, bytes(chip.data_bytes()), 0.002)
    return chip


def silent_script(cfg: DeviceConfig) -> CoreScript:
    return CoreScript(cfg, np.random.default_rng(1)).bring_up().data_cycle().line(np.ones(SILENCE_BITS, np.uint8))


@pytest.mark.parametrize("diag_conf", [0, 1])
def test_bus_active_and_not_active(diag_conf: int) -> None:
    cfg = config(diag_conf=diag_conf)
    pins = Supi3Pins(cfg)
    out = pins.run(CoreScript(cfg).bring_up().columns())
    view = pins.chip.diagnostic_outputs
    assert view == tl_chip(cfg, active=False).diagnostic_outputs
    assert (view.ib_diag, view.ba, view.rc, view.diag1) == (IbDiag.SLOW, False, True, 0)
    agrees(pins, out, view)
    out = pins.run(CoreScript(cfg, np.random.default_rng(2)).data_cycle().columns())
    view = pins.chip.diagnostic_outputs
    assert view == tl_chip(cfg).diagnostic_outputs
    assert (view.ib_diag, view.ba, view.diag1) == (IbDiag.STEADY, True, int(diag_conf == 0))
    agrees(pins, out, view)


def test_flashing_states_seen_at_later_cycles() -> None:
    # M6, DG-2: the pins flash from the free-running divider; output_values() looks ahead without running there.
    cfg = config("01000")
    pins = Supi3Pins(cfg)
    pins.run(CoreScript(cfg).bring_up().columns())
    assert pins.chip.diagnostic_outputs.ib_diag is IbDiag.SLOW
    for state in (IbDiag.SLOW, IbDiag.VERY_FAST):
        if state is IbDiag.VERY_FAST:
            pins.chip.line_timeout_at(pins.cycle)  # as the receiver calls it (the bus was not active: no interrupt)
            assert not pins.chip.line_interrupt
            pins.chip.reset_at(pins.cycle)
            pins.chip.latch_at(Cycle.DATA, bytes(pins.chip.data_bytes()), pins.cycle)
            pins.chip.line_timeout_at(pins.cycle)
        assert pins.chip.diagnostic_outputs.ib_diag is state
        bits = state.divider_bits
        assert bits is not None
        half = 1 << (bits - 1)
        levels = [pins.output_values(c, 0)["ib_diag"] for c in (2 * half - 1, 2 * half, 3 * half - 1, 3 * half)]
        assert levels == [0, 1, 1, 0]


@pytest.mark.slow
def test_peripheral_fault_flashes_fast() -> None:
    cfg = config()
    inputs = CoreScript(cfg).bring_up().data_cycle().columns()
    n = STATERR_FILTER_CLOCKS + 400_000
    tail = quiet_inputs(n)
    tail["do1"][:] = np.resize(wire.levels_to_samples(IDLE, cfg.bit_rate), n)  # status telegrams: no time-out
    inputs = {name: np.concatenate([inputs[name], tail[name]]) for name in inputs}
    inputs["stat_err_n"][:] = 0
    pins = Supi3Pins(cfg)
    out = pins.run(inputs)
    view = pins.chip.diagnostic_outputs
    assert view.ib_diag is IbDiag.FAST and view.ba
    agrees(pins, out, view)
    chip = tl_chip(cfg)
    chip.set_stat_err(True, 0.0)
    chip.poll((STATERR_LATEST + 1) / 32e6)  # M24: on the time base's ticks
    assert chip.diagnostic_outputs == view


@pytest.mark.parametrize("c", ["01000", "11000", "10000", "00000"])
def test_idle_timeout(c: str) -> None:
    # DG-3, DG-4: the silent line turns RC off (/ResReg low) in every mode; in the local bus modes (LB, LBD) a line
    # that falls silent while the bus is active is the line interrupt ahead (IB_DIAG 4 Hz).
    cfg = config(c)
    pins = Supi3Pins(cfg)
    out = pins.run(silent_script(cfg).columns())
    chip = pins.chip
    local = cfg.interface.value.startswith("LB")
    assert chip.line_silent and chip.line_interrupt == local
    view = chip.diagnostic_outputs
    assert view.ib_diag is (IbDiag.VERY_FAST if local else IbDiag.SLOW) and not view.rc
    agrees(pins, out, view)
    tl = tl_chip(cfg)
    tl.line_timeout(0.03)
    assert tl.diagnostic_outputs == view
    # /ResReg low from the cycle after the time-out's edge (M3) to the end of the silence.
    low = np.flatnonzero(out["res_reg_n"] == 0)
    assert low[-1] == len(out["res_reg_n"]) - 1 and len(low) >= len(out["res_reg_n"]) - low[0]
    # Heard again: the master's reset pattern clears both (at both fidelities).
    out = pins.run(CoreScript(cfg).bring_up().columns())
    tl.reset(0.04)
    assert not chip.line_silent and not chip.line_interrupt
    assert chip.diagnostic_outputs == tl.diagnostic_outputs
    agrees(pins, out, chip.diagnostic_outputs)


def test_line_interrupt_clears_at_the_next_cycle_end() -> None:
    cfg = config("01000")
    tl = tl_chip(cfg)
    tl.line_timeout(0.03)
    assert tl.line_interrupt and tl.diagnostic_outputs.ib_diag is IbDiag.VERY_FAST
    tl.load(Cycle.DATA, 0.031)  # a frame begins: not yet heard (the ring kernel's shortcut is off while silent)
    assert tl.line_silent
    tl.discard(Cycle.DATA, False, 0.032)
    assert not tl.line_silent and not tl.line_interrupt
    assert tl.diagnostic_outputs.ib_diag is IbDiag.SLOW  # reset by the time-out: the bus is not active
    tl.load(Cycle.DATA, 0.033)
    tl.latch(Cycle.DATA, bytes(tl.data_bytes()), 0.033)
    assert tl.diagnostic_outputs.ib_diag is IbDiag.STEADY


def test_no_line_interrupt_when_the_bus_was_not_active() -> None:
    cfg = config("01000")
    tl = tl_chip(cfg, active=False)
    tl.line_timeout(0.03)
    assert tl.line_silent and not tl.line_interrupt


@pytest.mark.slow
def test_line_timeout_step_and_run_agree() -> None:
    cfg = config("01000")
    inputs = silent_script(cfg).bring_up().data_cycle().columns()
    n = len(inputs["do1"])
    assert n > IDLE_TIMEOUT_CLOCKS
    assert_run_matches_step(Supi3Pins(cfg), Supi3Pins(cfg), inputs, [0.3, 0.5, 0.97])


@pytest.mark.parametrize("diag_conf", [0, 1])
@pytest.mark.parametrize("c", ["00000", "00100", "10000"])
def test_led_inputs_reach_the_pins(c: str, diag_conf: int) -> None:
    # Table 3-16: FO1/FO2 on DIAG1/DIAG2 with limited diagnostics, RD on DIAG2 with complete; Table 2-8: a bus
    # terminal module's ALARM, LD, E, FO3 on MFP15, 14, 13, 8 whatever DIAG_CONF (DG-6).
    # FO1..FO3 come from the optical block (OPT-8): FO1 and FO3 lit, in READY by a fallback, in RUN by a MAU warning.
    # At pin level the core's block does it, from its line side (OPT-26); at transaction level the chip's optical API.
    cfg = decode(c, clk_conf="11", diag_conf=diag_conf, rf="00")
    pins = Supi3Pins(cfg)
    script = CoreScript(cfg).line(IDLE, present=0b101).line(wire.reset_levels(1)).line(IDLE)
    pins.run(script.response(Interface.IN, Response.NONE).response(Interface.BRANCH, Response.NONE).inputs())
    leds = LedInputs(ld=True, e=False, alarm=True)
    pins.chip.set_led_inputs(leds)

    def alarm_and_ld(chip: Supi3) -> None:
        if chip.bus_terminal is not None:  # LD: the master switched the branch off (BK-11); ALARM set (BK-12)
            chip.bus_terminal.command(BranchControl.OFF, acknowledge=False, alarm=True)

    def light_fo1_and_fo3(chip: Supi3) -> None:
        alarm_and_ld(chip)
        bk = chip.bus_terminal is not None  # only a BK has the branch interface (OPT-55)
        chip.optical_start((True, False, bk))
        response = Response.NOT_DETECTED if chip.bus_active else Response.NONE
        for interface in (Interface.IN, Interface.BRANCH)[: 1 + bk]:
            chip.optical_init_response(interface, response)

    alarm_and_ld(pins.chip)
    out = pins.run(quiet_inputs(50))
    view = pins.chip.diagnostic_outputs
    agrees(pins, out, view)
    stepped = pins.step({name: int(trace[0]) for name, trace in quiet_inputs(1).items()})
    assert (stepped["diag1"], stepped["diag2"]) == ((0, 1) if diag_conf == 0 else (1, 0))
    if cfg.interface.is_bus_terminal:
        assert (stepped["mfp_out"] & 0xE100, stepped["mfp_oe"] & 0xE100) == (0xC100, 0xE100)
    assert view.fo == (True, False, cfg.interface.is_bus_terminal)
    tl = tl_chip(cfg, active=False)
    tl.set_led_inputs(leds)
    light_fo1_and_fo3(tl)
    assert tl.diagnostic_outputs == view


def test_set_led_inputs_is_checked() -> None:
    with pytest.raises(ChipArgumentError, match="leds must be a LedInputs"):
        Supi3(config()).set_led_inputs((True, False, True))  # type: ignore[arg-type]

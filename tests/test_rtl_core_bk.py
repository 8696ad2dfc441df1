"""The bus terminal block inside the chip core (manual 2.4, Tables 2-7, 2-8; BK-5, BK-8, BK-11, BK-12, BK-20): the
pin-level model (supi3.model.pins, whose chip keeps the BK state of supi3.model.bus_terminal) and the RTL core
(supi3.rtl.core with supi3.rtl.terminal) on the same scenarios, every pin every clock: CONF from MFP12 (no edge at
power-up, edges between frames and inside them: ATTN in the CNTR word), the status request answered with the branch
status byte, the quit bit, branch control (LD on MFP14), the ALARM output (MFP15), INTERBUS resets. The branch's data
routing (DI3/DO3) is not in the core yet: no closure by the extended function at pin level (docs/bus-terminal.md).
"""

from __future__ import annotations

import numpy as np
import pytest

from supi3.config import decode
from supi3.interbus import wire
from supi3.interbus.wire import BranchControl
from supi3.model.pins import Supi3Pins
from supi3.terminal import CONF_PIN, LBST_PIN
from supi3.verif import Lockstep
from support import BK_STRAPS, Columns, CoreScript, assert_run_matches_step

CONF, LBST = 1 << CONF_PIN, 1 << LBST_PIN
LD_PIN, E_PIN, ALARM_PIN = 14, 13, 15  # Table 2-8


def scenario(interface: str, rf: str, seed: int) -> CoreScript:
    """CONF high from power-up, then low and high again between frames (and at random in data cycles), status
    requests, the quit bit, branch off and on, the ALARM output, an INTERBUS reset, random MFP inputs."""
    config = decode(BK_STRAPS[interface], rf=rf, clk_conf="11")
    script = CoreScript(config, np.random.default_rng(seed))
    script.pins["mfp_in"] = CONF | LBST
    script.bring_up().id_cycle(wire.command_word(alarm_request=True), mfp_in=CONF | LBST)
    script.id_cycle(wire.command_word(branch=BranchControl.OFF, alarm_output=True), mfp_in=LBST)
    script.id_cycle(wire.command_word(alarm_request=True), mfp_in=CONF | LBST)  # edge: request, ATTN
    script.id_cycle(wire.command_word(quit_peripheral_error=True, branch=BranchControl.ON_EXTENDED), mfp_in=LBST)
    script.id_cycle(wire.command_word(alarm_request=True, alarm_output=False))
    script.data_cycle().data_cycle().line(wire.reset_levels(1), mfp_in=CONF).line(IDLE_SHORT, mfp_in=0)
    return script.id_cycle(wire.command_word(alarm_request=True)).id_cycle(wire.command_word()).data_cycle()


IDLE_SHORT = wire.status_levels(wire.Cycle.DATA, False, 2)
CASES = [("BK-RB", "10", 1), ("BK-LB", "11", 2), ("BK-LBD", "00", 3)]


def model(script: CoreScript) -> tuple[Supi3Pins, Columns]:
    pins = Supi3Pins(script.config)
    return pins, pins.run(script.columns())


@pytest.mark.parametrize(("interface", "rf", "seed"), CASES)
def test_model_reaches_the_bk_states(interface: str, rf: str, seed: int) -> None:
    """The scenario at pin level: ALARM and LD were driven, the status byte was sent, the request was acknowledged
    and a second one (after the reset, where CONF rose again) waits; step() and run() agree."""
    script = scenario(interface, rf, seed)
    pins, out = model(script)
    terminal = pins.chip.bus_terminal
    assert terminal is not None and terminal.conf_request and not terminal.extended and terminal.switched_on
    assert np.any(out["mfp_out"] >> ALARM_PIN & 1) and np.any(out["mfp_out"] >> LD_PIN & 1)
    assert not out["mfp_out"][-1] >> ALARM_PIN & 1 and not out["mfp_out"][-1] >> LD_PIN & 1
    assert pins.chip.attention
    columns = script.columns()
    assert_run_matches_step(Supi3Pins(script.config), Supi3Pins(script.config), columns, [0.31, 0.62])


def test_conf_high_at_power_up_is_no_request() -> None:
    script = CoreScript(decode(BK_STRAPS["BK-LB"], clk_conf="11"))
    script.pins["mfp_in"] = CONF
    pins, _ = model(script.bring_up())
    assert pins.chip.bus_terminal is not None and not pins.chip.bus_terminal.conf_request
    assert not pins.chip.attention


def test_a_short_conf_pulse_between_line_events_counts() -> None:
    """A CONF pulse of 3 clocks in the middle of a bit (no line sample there) is an edge for step() and run()
    alike: run() visits CONF changes of a BK (BK-8)."""
    script = CoreScript(decode(BK_STRAPS["BK-RB"], clk_conf="11")).bring_up()
    columns = script.line(IDLE_SHORT).columns()
    n = len(columns["do1"])
    for start in (n - 200, n - 117, n - 41):
        columns["mfp_in"][start : start + 3] = CONF
        stepped = assert_run_matches_step(Supi3Pins(script.config), Supi3Pins(script.config), columns, [0.5])
        assert stepped is not None
        pins = Supi3Pins(script.config)
        pins.run(columns)
        assert pins.chip.bus_terminal is not None and pins.chip.bus_terminal.conf_request and pins.chip.attention
        columns["mfp_in"][:] = 0


@pytest.mark.parametrize(("interface", "rf", "seed"), CASES)
def test_rtl_core_matches(bench: Lockstep, interface: str, rf: str, seed: int) -> None:
    bench.run_batch(scenario(interface, rf, seed).stimulus())


@pytest.fixture(scope="session")
def bench(core_bench: Lockstep) -> Lockstep:
    return core_bench  # tests/conftest.py: one build, shared with tests/test_rtl_core.py

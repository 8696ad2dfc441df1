"""RD and counter telegrams in the RTL chip core (``supi3.rtl.core``: ``OutputsRtl``, ``ReceiverRtl``,
``FrameEngineRtl``) against the pin model, every pin every clock (the ``core_bench`` Verilator build of
tests/conftest.py, batch path) and the outputs block alone on Amaranth's simulator: DIAG2 = RD, the following device
not recognised (manual 3.6.1, Tables 3-16, 3-19; DG-5), and counter telegrams taken as such by the frame engine and
the idle time-out (2.2.2, Table 3-18's 4 Hz; BK-36, DG-9)."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from amaranth.sim import Simulator

from supi3 import tables
from supi3.config import DeviceConfig, decode
from supi3.interbus import wire
from supi3.interbus.wire import Cycle, Frame
from supi3.model.pins import IDLE_TIMEOUT_CLOCKS, Supi3Pins
from supi3.pinout import IB_DIAG_DIVIDER_BITS
from supi3.rtl.core import OutputsRtl
from supi3.verif import Lockstep
from support import IDLE, LOOPBACK, CoreScript, counter_levels, counters_in_reset

FAST = tables.clk_conf_for(2_000_000)
MODES = {"LB-MR": "01000", "LBD-MR": "11000", "LBD-OR": "11100", "RB": "10000", "BK-RB": "00000"}
"""One mode row of each of Tables 2-4 (LB), 2-5 (LBD-MR, LBD-OR), 2-6 (RB) and 2-7 (BK)."""


@pytest.fixture(scope="module")
def bench(core_bench: Lockstep) -> Lockstep:
    return core_bench  # tests/conftest.py: one build per session


def _config(mode: str, rf: str = "11", diag_conf: int = 0) -> DeviceConfig:
    return decode(MODES[mode], rf=rf, clk_conf=FAST, diag_conf=diag_conf)


@pytest.mark.slow
@pytest.mark.parametrize("rf", ["11", "10"])
@pytest.mark.parametrize("mode", list(MODES))
def test_rd_in_lockstep(bench: Lockstep, mode: str, rf: str) -> None:
    # DG-5, both DIAG_CONF: no following device (RD lit), one appears during a data cycle (DI2 high or RBST_EXT),
    # goes away (RF = 10: RD lit again; else the recognition stays), with traffic; RTL and model every clock.
    for diag_conf in (0, 1):
        script = CoreScript(_config(mode, rf, diag_conf), np.random.default_rng(31)).bring_up().data_cycle()
        script.line(IDLE, rbst_ext=1).data_cycle(di2=1).line(IDLE, rbst_ext=0, di2=0).data_cycle()
        bench.run_batch(script.stimulus())


@pytest.mark.slow
@pytest.mark.parametrize("mode", ["LBD-MR", "LBD-OR", "LB-MR"])
def test_counter_telegrams_through_the_frame_engine(bench: Lockstep, mode: str) -> None:
    # BK-36: counter telegrams between frames, after a check sequence waiting for its latch telegrams, and inside a
    # frame cut by a break (then the frame's); a data cycle after them; LB-MR takes them as out-of-place telegrams.
    config = _config(mode)
    counters = np.tile(counter_levels(5, 33), 3)
    levels = wire.cycle_levels(Frame.build(Cycle.DATA, LOOPBACK + bytes(config.data_bytes)), 1, True)
    script = CoreScript(config, np.random.default_rng(32)).bring_up().data_cycle().line(counters)
    script.line(levels[: len(levels) // 2]).line(counters).line(wire.reset_levels(1)).line(IDLE).data_cycle()
    bench.run_batch(script.stimulus())


@pytest.mark.slow
def test_idle_timeout_through_counter_telegrams(bench: Lockstep) -> None:
    # DG-9: counter telegrams after a latched data cycle do not restart the 20 ms idle time-out: /ResReg goes low
    # (RC off, DG-4) at the same clock in RTL and model, the chip resets with no line interrupt ahead; then the
    # master's reset pattern. (500 kbit/s: a quarter of the samples to visit; the IB_DIAG pattern it makes is the
    # outputs block's ``counted``, below, and the model's, tests/test_model_pins_rd.py.)
    config = decode(MODES["LBD-OR"], clk_conf=tables.clk_conf_for(500_000), diag_conf=0)
    cpb = wire.clocks_per_bit(config.bit_rate)
    script = CoreScript(config, np.random.default_rng(33)).bring_up().data_cycle()
    start = len(script.columns()["do1"])
    script.line(np.tile(counter_levels(4, 33), (IDLE_TIMEOUT_CLOCKS // cpb + 100) // 33))
    pins = Supi3Pins(config)
    out = pins.run(script.columns())
    low = np.flatnonzero(out["res_reg_n"] == 0)
    assert low.size and start < low[0] < start + IDLE_TIMEOUT_CLOCKS + 64 * cpb
    assert pins.chip.line_silent and not pins.chip.line_interrupt and not pins.chip.bus_active
    bench.run_batch(script.line(wire.reset_levels(1)).line(IDLE).data_cycle().stimulus())


@pytest.mark.slow
def test_idle_timeout_through_counter_telegrams_in_an_interbus_reset(bench: Lockstep) -> None:
    # DG-9 in an INTERBUS reset (the line held at start level, then only counter telegrams, no status telegram to end
    # the reset): the frame engine's ``counter`` takes them there too, so the time-out runs from the held line and
    # /ResReg goes low at the same clock in RTL and model; then the master's reset pattern and a data cycle.
    config = decode(MODES["LBD-OR"], clk_conf=tables.clk_conf_for(500_000), diag_conf=0)
    script, start = counters_in_reset(config, np.random.default_rng(34))
    out = Supi3Pins(config).run(script.columns())
    assert np.flatnonzero(out["res_reg_n"][start:] == 0)[0] <= IDLE_TIMEOUT_CLOCKS
    bench.run_batch(script.line(wire.reset_levels(1)).line(IDLE).data_cycle().stimulus())


def test_outputs_block_takes_no_line_interrupt_after_counter_telegrams() -> None:
    # DG-9 in OutputsRtl alone: a latched cycle, then the idle time-out with and without ``counted``; IB_DIAG at a
    # divider value where 4 Hz is off and 0.5 Hz lit.
    dut = OutputsRtl(max(IB_DIAG_DIVIDER_BITS.values()))
    seen: list[int] = []
    divider = 1 << (IB_DIAG_DIVIDER_BITS["very_fast"] - 1)

    async def bench(ctx: Any) -> None:
        ctx.set(dut.stat_err_n_s, 1)
        ctx.set(dut.local_bus, 1)
        ctx.set(dut.divider, divider)
        for counted in (1, 0):
            ctx.set(dut.frame.latch_data, 1)
            await ctx.tick()
            ctx.set(dut.frame.latch_data, 0)
            ctx.set(dut.idle_timeout, 1)
            ctx.set(dut.frame.clear, 1)
            ctx.set(dut.counted, counted)
            await ctx.tick()
            ctx.set(dut.idle_timeout, 0)
            ctx.set(dut.frame.clear, 0)
            seen.append(ctx.get(dut.ib_diag))
            ctx.set(dut.ended, 1)  # the line heard again
            await ctx.tick()
            ctx.set(dut.ended, 0)

    simulator = Simulator(dut)
    simulator.add_clock(1 / 32e6)
    simulator.add_testbench(bench)
    simulator.run()
    assert seen == [1, 0]  # counted: bus not active (lit); silent: line interrupt ahead (off in this half)

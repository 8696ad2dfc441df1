"""The RTL's diagnostic outputs (the outputs block ``OutputsRtl`` of supi3.rtl.core) against the model chip's LED view
(Supi3.diagnostic_outputs, supi3.diagnostics): manual 3.6.1 (Tables 3-16 to 3-19), Table 2-8, DG-1 to DG-8.

On Amaranth's own simulator, the block alone: random sequences of the frame engine's events (latch, reset pattern,
discard, idle time-out), of the LED inputs (in the core FO1..FO3 come from the optical block, the others are tied to 0
until the bus terminal logic drives them), and of the IB_DIAG divider, applied to the block and to a transaction-level
chip alike. The whole core runs the same outputs in the lockstep (tests/test_rtl_core.py:
``test_diagnostics_by_diag_conf``, ``test_idle_timeout_diagnostics``).
"""

from __future__ import annotations

from typing import Any

import pytest
from amaranth.sim import Simulator
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.config import decode
from supi3.diagnostics import LedInputs, diagnostic_outputs, ib_diag_level, is_complete, watches_line_interrupt
from supi3.interbus.wire import Cycle
from supi3.model.chip import Supi3
from supi3.pinout import IB_DIAG_DIVIDER_BITS
from supi3.rtl.core import OutputsRtl

EVENTS = ("none", "latch", "pattern", "discard", "timeout", "timeout_discard")
"""What the frame engine and the receiver tell the block in one clock (and the chip call it stands for)."""
DIVIDER_BITS = max(IB_DIAG_DIVIDER_BITS.values())

Step = tuple[str, LedInputs, int]


def run(c: str, diag_conf: int, steps: list[Step]) -> None:
    """Apply ``steps`` (event, LED inputs, divider) to the block and to a chip of ``C[4..0] = c``; after each clock
    DIAG1, DIAG2, IB_DIAG, /ResReg and the MFP LEDs must show the chip's LED view."""
    config = decode(c, clk_conf="11", diag_conf=diag_conf)
    chip = Supi3(config)
    dut = OutputsRtl(DIVIDER_BITS)
    failures: list[str] = []

    async def bench(ctx: Any) -> None:
        ctx.set(dut.stat_err_n_s, 1)
        ctx.set(dut.complete_diag, int(is_complete(config)))
        ctx.set(dut.local_bus, int(watches_line_interrupt(config)))
        ctx.set(dut.bus_terminal, int(config.interface.is_bus_terminal))
        for clk, (event, leds, divider) in enumerate(steps):
            f = dut.frame
            ctx.set(f.latch_data, int(event == "latch"))
            ctx.set(f.clear, int(event in {"pattern", "timeout", "timeout_discard"}))
            ctx.set(dut.idle_timeout, int(event.startswith("timeout")))
            ctx.set(dut.ended, int(event in {"latch", "discard", "timeout_discard"}))  # a cycle ended at the chip
            ctx.set(dut.fo, sum(int(v) << i for i, v in enumerate(leds.fo)))
            for name in ("ld", "e", "alarm"):
                ctx.set(getattr(dut, name), int(getattr(leds, name)))
            ctx.set(dut.divider, divider)
            if event == "latch":
                chip.latch_at(Cycle.DATA, bytes(chip.data_bytes()), clk)
            elif event == "pattern":
                chip.reset_at(clk)
            elif event in {"discard", "timeout_discard"}:
                chip.discard_at(Cycle.DATA, False, clk)
            if event.startswith("timeout"):
                chip.line_timeout_at(clk)
            await ctx.tick()
            ctx.set(f.latch_data, 0)
            ctx.set(f.clear, 0)
            ctx.set(dut.idle_timeout, 0)
            ctx.set(dut.ended, 0)
            # The block maps its LED inputs as the spec does; the chip's own view takes FO, LD and E from its optical
            # and bus terminal state (OPT-8, BK-11), so the expected view is the spec's function of the same inputs.
            view = diagnostic_outputs(config, supply_ok=True, line_heard=not chip.line_silent,
                                      bus_active=chip.bus_active, peripheral_fault=chip.pf,
                                      line_interrupt=chip.line_interrupt, following=chip.following,
                                      leds=leds)  # fmt: skip
            got = (ctx.get(dut.diag1), ctx.get(dut.diag2), ctx.get(dut.ib_diag), ctx.get(dut.res_reg_n),
                   ctx.get(dut.mfp_diag))  # fmt: skip
            want = (view.diag1, view.diag2, ib_diag_level(view.ib_diag, divider), int(view.rc), view.mfp)
            if got != want:
                failures.append(f"clock {clk} after {event}: RTL {got}, model {want} ({view})")
                return

    simulator = Simulator(dut)
    simulator.add_clock(1 / 32e6)
    simulator.add_testbench(bench)
    simulator.run()
    assert not failures, failures[0]


leds_strategy = st.builds(
    LedInputs, fo=st.tuples(st.booleans(), st.booleans(), st.booleans()), ld=st.booleans(),
    e=st.booleans(), alarm=st.booleans(),
)  # fmt: skip
steps_strategy = st.lists(
    st.tuples(st.sampled_from(EVENTS), leds_strategy, st.integers(0, (1 << DIVIDER_BITS) - 1)), min_size=1,
    max_size=25,
)  # fmt: skip


@pytest.mark.slow
@settings(max_examples=25, deadline=None)
@given(c=st.sampled_from(["01000", "11000", "10000", "00000", "00100"]), diag_conf=st.integers(0, 1),
       steps=steps_strategy)  # fmt: skip
def test_random_events_agree_with_the_model_chip(c: str, diag_conf: int, steps: list[Step]) -> None:
    run(c, diag_conf, steps)


@pytest.mark.parametrize("c", ["01000", "10000"])
def test_line_interrupt_and_its_clearing(c: str) -> None:
    # DG-3: active bus, silent line: 4 Hz (LB only; the divider's bit 22 set: off); a discarded cycle clears it;
    # again, the reset pattern clears it; a time-out without an active bus raises none.
    off = 1 << (IB_DIAG_DIVIDER_BITS["very_fast"] - 1)
    none = LedInputs()
    steps: list[Step] = [("latch", none, 0), ("timeout_discard", none, off), ("none", none, off),
                         ("discard", none, off), ("latch", none, 0), ("timeout", none, off), ("pattern", none, off),
                         ("timeout", none, off), ("none", none, 0)]  # fmt: skip
    run(c, 0, steps)

"""Lockstep on Amaranth's own Python simulator: no external tools, and a speed reference for the other paths.

The same convention as the cocotb path: per cycle, inputs are set, the settled outputs are compared with the model's
step, then the clock ticks. Amaranth's simulator starts from the signals' initial values, which is the state after
the ``sync`` reset, so no reset cycle is run.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import numpy as np
from amaranth.sim import Simulator

from supi3.pinlevel import ModelFactory, recent_events
from supi3.verif.layout import WORD, Stimulus, WordLayout, model_trace, stimulus_array
from supi3.verif.report import LockstepResult, raise_mismatch
from supi3.verif.rtl import DesignFactory, LockstepTop

__all__ = ["run_amaranth_sim"]


def run_amaranth_sim(
    design_factory: DesignFactory,
    model_factory: ModelFactory,
    stimulus: Stimulus,
    *,
    vcd_dir: Path | None = None,
    max_cycles: int | None = None,
    window: int = 64,
) -> LockstepResult:
    """Per-cycle lockstep of a design and a model under :class:`amaranth.sim.Simulator`.

    Parameters
    ----------
    design_factory, model_factory, stimulus, max_cycles, window:
        As for :class:`~supi3.verif.lockstep.Lockstep` and its ``run``.
    vcd_dir:
        Where to write the mismatch waveform; none is written when ``None``.

    Raises
    ------
    LockstepMismatchError
        On the first differing output.
    """
    model = model_factory()
    layout = WordLayout.of(model)
    array = stimulus_array(stimulus, layout.inputs, max_cycles)
    top = LockstepTop(design_factory(), layout)
    names = layout.input_names
    input_rows = layout.input_words(array)[:, : layout.in_words].tolist()
    history: list[tuple[int, ...]] = []
    found: list[int] = []

    async def testbench(ctx: Any) -> None:
        model.reset()
        step = model.step
        values = layout.output_values
        matches = layout.matches
        for cycle, (row, words) in enumerate(zip(array.tolist(), input_rows, strict=True)):
            for port, word in zip(top.in_words, words, strict=True):
                ctx.set(port, word)
            expected = values(step(dict(zip(names, row, strict=True))))
            actual = sum(ctx.get(port) << (WORD * index) for index, port in enumerate(top.out_words))
            history.append(layout.unpack_outputs(actual))
            if len(history) > window:
                del history[0]
            if not matches(expected, actual):
                signal_index = layout.first_difference(expected, history[-1])
                assert signal_index is not None, "matches() and first_difference() agree"
                found.extend((cycle, signal_index))
                return
            await ctx.tick()

    simulator = Simulator(top)
    simulator.add_clock(1e-6)
    simulator.add_testbench(testbench)
    start = time.perf_counter()
    simulator.run()
    seconds = time.perf_counter() - start
    if found:
        cycle, signal_index = found
        first = cycle + 1 - len(history)
        replay = model_factory()
        expected_window = model_trace(replay, array[: cycle + 1], layout)[first:]
        raise raise_mismatch(
            layout,
            array,
            cycle,
            signal_index,
            recent_events(replay),
            expected_window,
            np.array(history, dtype=np.uint64),
            vcd_dir,
            "amaranth-sim",
        )
    return LockstepResult(array.shape[0], seconds, "amaranth-sim", "amaranth")

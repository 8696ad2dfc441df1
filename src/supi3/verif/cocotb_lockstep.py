"""The per-cycle lockstep loop as a cocotb coroutine, for the harness's own testbench and for other cocotb tests.

Runs inside the simulator process. The DUT is the packed top-level (:class:`~supi3.verif.rtl.LockstepTop`): ports
``clk``, ``rst``, input words ``lsi<n>`` and output words ``lso<n>``.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import Any

from cocotb.clock import Clock
from cocotb.triggers import FallingEdge

from supi3.verif.layout import WORD, Layout, Trace, model_trace
from supi3.verif.pinmodel import PinModel, recent_events
from supi3.verif.report import MismatchRecord, Outcome
from supi3.verif.vcd import CYCLE_NS

__all__ = ["lockstep"]


async def lockstep(dut: Any, model: PinModel, stimulus: Trace, *, reset_cycles: int = 1, window: int = 64) -> Outcome:
    """Clock the DUT and the model together and compare every output signal on every cycle.

    Timing per cycle ``n`` (see :mod:`supi3.verif.pinmodel`): at the falling clock edge the inputs of cycle ``n`` are
    written to the DUT and given to the model's ``step``; the rising edge ending the cycle updates both, and the top
    level holds the DUT's outputs of cycle ``n`` (``lsq``), which are compared at the next falling edge. One wait
    per cycle. Before cycle 0 the ``sync`` reset is held for
    ``reset_cycles`` rising edges with all inputs at 0, and the model is reset.

    Parameters
    ----------
    dut:
        The cocotb handle of the packed top-level.
    model:
        A fresh model.
    stimulus:
        Input values ``(cycles, inputs)`` in the model's input order.
    reset_cycles:
        Rising edges with reset asserted before cycle 0.
    window:
        Cycles of history kept for the mismatch waveform.

    Returns
    -------
    Outcome
        Cycles compared, time taken, and the first mismatch if there was one (the loop stops there).
    """
    layout = Layout.of(model)
    in_port = dut.lsi if layout.in_words else None
    held_port = dut.lsq
    falling = FallingEdge(dut.clk)

    dut.rst.value = 1
    if in_port is not None:
        in_port.value = 0
    Clock(dut.clk, CYCLE_NS, unit="ns").start(start_high=False)
    for _ in range(reset_cycles):
        await falling
    model.reset()

    step = model.step
    names = layout.input_names
    output_values = layout.output_values
    matches = layout.matches
    # A model with a bulk run() (an event-driven model) computes every expected output before the simulation
    # starts, so the per-cycle loop only drives, waits and compares; the stimulus is fixed, so this is the same.
    ahead = model_trace(model, stimulus, layout).tolist() if callable(getattr(model, "run", None)) else None
    history = [0] * window
    packed_inputs = [
        sum(word << (WORD * index) for index, word in enumerate(row)) for row in layout.input_words(stimulus).tolist()
    ]
    rows = stimulus.tolist()
    cycles = len(rows)
    expected: Sequence[int] = ()
    start = time.perf_counter()
    # One wait per cycle: at the falling edge in cycle n the inputs of cycle n are written; the outputs of cycle n
    # (settled with those inputs, before the edge ending it) are read from the held word at the next falling edge.
    for cycle in range(cycles + 1):
        if cycle:
            await falling
            actual = held_port.value.to_unsigned()
            previous = cycle - 1
            history[previous % window] = actual
            if not matches(expected, actual):
                seconds = time.perf_counter() - start
                signal = layout.first_difference(expected, layout.unpack_outputs(actual))
                assert signal is not None, "matches() and first_difference() agree"
                first = max(0, previous + 1 - window)
                if ahead is not None:  # replay up to the mismatch, so the bus events end there
                    model_trace(model, stimulus[: previous + 1], layout)
                record = MismatchRecord(
                    previous, signal, recent_events(model), [history[k % window] for k in range(first, previous + 1)]
                )
                return Outcome(previous + 1, seconds, record)
        else:
            dut.rst.value = 0
        if cycle < cycles:
            if in_port is not None and (cycle == 0 or packed_inputs[cycle] != packed_inputs[cycle - 1]):
                in_port.value = packed_inputs[cycle]  # a write only when an input changes: most cycles have none
            if ahead is not None:
                expected = ahead[cycle]
            else:
                expected = output_values(step(dict(zip(names, rows[cycle], strict=True))))
    return Outcome(stimulus.shape[0], time.perf_counter() - start)

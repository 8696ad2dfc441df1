"""The per-cycle lockstep loop as a cocotb coroutine, for the harness's own testbench and for other cocotb tests.

Runs inside the simulator process. The DUT is the packed top-level with its comparator
(:class:`~supi3.verif.rtl.LockstepTop` built with a ``window``): ports ``clk``, ``rst``, input words ``stim_word<n>``,
expected output words ``expected_word<n>``, and the comparator's ``mismatch``, ``cycle_count`` and ``history``.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import FallingEdge, Timer

from supi3.pinlevel import PinModel, PinSpecError, check_cycles, recent_events
from supi3.verif.layout import Stimulus, WordLayout, model_columns, model_trace, stimulus_array
from supi3.verif.report import MismatchRecord, Outcome
from supi3.verif.vcd import CYCLE_NS

__all__ = ["POLL_CYCLES", "lockstep"]

POLL_CYCLES = 1024
"""Cycles between two reads of the comparator's mismatch flag: how far the simulation may run past a mismatch."""


async def lockstep(
    dut: Any, model: PinModel, stimulus: Stimulus, *, reset_cycles: int = 0, window: int = 64
) -> Outcome:
    """Clock the DUT and the model together; the top's comparator checks every output signal on every cycle.

    Timing per cycle ``n`` (see :mod:`supi3.pinlevel`): at the falling clock edge the inputs of cycle ``n`` and
    the model's outputs for cycle ``n`` are written to the DUT (each word only when it changes); the rising edge
    ending the cycle updates the design and compares its outputs with the expected words. One wait per cycle and
    no read: the mismatch flag is read every :data:`POLL_CYCLES` cycles and at the end. Before cycle 0 the ``sync``
    reset is held for ``reset_cycles`` rising edges with all inputs at 0 (by default none: the design starts from its
    initial values, M23), and the model is reset.

    Parameters
    ----------
    dut:
        The cocotb handle of the packed top-level.
    model:
        A fresh model.
    stimulus:
        Input values ``(cycles, inputs)`` in the model's input order, or per-cycle dicts
        (:func:`~supi3.verif.layout.stimulus_array`).
    reset_cycles:
        Rising edges with reset asserted before cycle 0 (0: none, the design starts from its initial values).
    window:
        The comparator's history: cycles of the RTL's outputs kept for the mismatch waveform (the top's build
        parameter).

    Returns
    -------
    Outcome
        Cycles compared, time taken, and the first mismatch if there was one (the loop stops soon after it).

    Raises
    ------
    PinSpecError
        ``reset_cycles`` not an integer from 0 or ``window`` not one from 1, or a stimulus
        :func:`~supi3.verif.layout.stimulus_array` refuses (before the clock starts).
    """
    reset_cycles = check_cycles("reset_cycles", reset_cycles, 0)
    window = check_cycles("window", window, 1)
    layout = WordLayout.of(model)
    stimulus = stimulus_array(stimulus, layout.inputs)  # checked before the clock starts
    in_ports = [getattr(dut, f"stim_word{index}") for index in range(layout.in_words)]
    expected_ports = [getattr(dut, f"expected_word{index}") for index in range(layout.out_words)]
    flag = dut.mismatch
    falling = FallingEdge(dut.clk)
    # After the first falling edge, a timer of one period lands on each next one: the same instants, and cocotb
    # resumes a timer faster than an edge trigger (by 2-15 %, measured).
    period = Timer(CYCLE_NS, unit="ns")

    if reset_cycles:  # else cycle 0 writes every port (one write per port and step)
        dut.rst.value = 1
        for port in (*in_ports, *expected_ports):
            port.value = 0
    Clock(dut.clk, CYCLE_NS, unit="ns").start(start_high=False)
    for _ in range(reset_cycles):
        await falling
    model.reset()

    in_words = layout.input_words(stimulus)[:, : len(in_ports)]
    # A model with a bulk run() (an event-driven model) computes every expected output before the simulation
    # starts, so the per-cycle loop only drives and waits; the stimulus is fixed, so this is the same.
    ahead = callable(getattr(model, "run", None))
    if ahead:
        expected_words = layout.pack_columns(model_columns(model, stimulus, layout))
        in_words = np.concatenate([in_words, expected_words], axis=1)
    in_rows = in_words.tolist()
    step, names, values, pack = model.step, layout.input_names, layout.output_values, layout.pack_outputs
    rows = stimulus.tolist()
    cycles = len(rows)
    ports = [*in_ports, *expected_ports]
    written: list[int | None] = [None] * len(ports)
    if not cycles:
        return Outcome(0, 0.0)
    start = time.perf_counter()
    dut.rst.value = 0
    for cycle in range(cycles):
        if cycle:
            await period
            if not cycle % POLL_CYCLES and flag.value:
                break
        if ahead:
            words = in_rows[cycle]
        else:
            try:
                expected = pack(values(step(dict(zip(names, rows[cycle], strict=True)))))
            except PinSpecError as error:
                raise PinSpecError(f"cycle {cycle}: {error}") from None
            words = in_rows[cycle] + expected
        if words != written:
            for index, word in enumerate(words):
                if word != written[index]:
                    ports[index].value = word  # a write only when a word changes: most cycles have none
            written = words
    await period  # the edge ending the last cycle written has compared it
    seconds = time.perf_counter() - start
    if not flag.value:
        return Outcome(cycles, seconds)
    mismatch = dut.cycle_count.value.to_unsigned() - 1
    expected_trace = model_trace(model, stimulus[: mismatch + 1], layout)  # a replay: the events end there too
    first = max(0, mismatch + 1 - window)
    actual = [dut.history[cycle % window].value.to_unsigned() for cycle in range(first, mismatch + 1)]
    signal = layout.first_difference(expected_trace[-1].tolist(), layout.unpack_outputs(actual[-1]))
    assert signal is not None, "the comparator and first_difference() agree"
    return Outcome(mismatch + 1, seconds, MismatchRecord(mismatch, signal, recent_events(model), actual))

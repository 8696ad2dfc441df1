"""Waveform of the cycles around a mismatch: inputs, the model's outputs and the RTL's outputs, side by side."""

from __future__ import annotations

from pathlib import Path

from vcd import VCDWriter

from supi3.verif.layout import CycleMatrix, WordLayout

__all__ = ["CYCLE_NS", "write_window"]

CYCLE_NS = 10
"""Clock period drawn in the waveform, in ns. Cycle ``n`` starts (rising edge) at ``n * CYCLE_NS`` ns."""


def write_window(
    path: Path, layout: WordLayout, first_cycle: int, inputs: CycleMatrix, expected: CycleMatrix, actual: CycleMatrix,
    mismatch_cycle: int
) -> Path:
    """Write a VCD of a window of cycles.

    Scopes: ``inputs`` (input pins), ``model`` and ``rtl`` (every compared output signal), and ``harness`` with
    ``clk``, ``cycle`` (the cycle number) and ``mismatch`` (1 during the first mismatching cycle).

    Parameters
    ----------
    path:
        Where to write; parent directories are created.
    layout:
        The model's pin layout.
    first_cycle:
        The cycle number of the window's first row.
    inputs, expected, actual:
        Rows of the window: input pins ``(cycles, inputs)``, model outputs and RTL outputs ``(cycles, signals)``.
    mismatch_cycle:
        The cycle marked in ``harness.mismatch``.

    Returns
    -------
    Path
        ``path``.
    """
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", encoding="ascii") as stream, VCDWriter(stream, timescale="1 ns", date="today") as writer:
        clk = writer.register_var("harness", "clk", "wire", size=1, init=0)
        cycle = writer.register_var("harness", "cycle", "integer", size=32, init=first_cycle)
        flag = writer.register_var("harness", "mismatch", "wire", size=1, init=0)
        in_vars = [writer.register_var("inputs", f.name, "wire", size=f.width) for f in layout.in_fields]
        model_vars = [writer.register_var("model", f.name, "wire", size=f.width) for f in layout.out_fields]
        rtl_vars = [writer.register_var("rtl", f.name, "wire", size=f.width) for f in layout.out_fields]
        for row in range(inputs.shape[0]):
            number = first_cycle + row
            time = number * CYCLE_NS
            writer.change(clk, time, 1)
            writer.change(cycle, time, number)
            writer.change(flag, time, int(number == mismatch_cycle))
            for variables, fields, values in (
                (in_vars, layout.in_fields, inputs),
                (model_vars, layout.out_fields, expected),
                (rtl_vars, layout.out_fields, actual),
            ):
                for variable, field, value in zip(variables, fields, values[row].tolist(), strict=True):
                    writer.change(variable, time, value & field.mask)
            writer.change(clk, time + CYCLE_NS // 2, 0)
        writer.change(clk, (first_cycle + inputs.shape[0]) * CYCLE_NS, 1)
    return path

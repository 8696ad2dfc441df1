"""Outcome of a lockstep run, and turning a recorded mismatch into a :class:`LockstepMismatchError` with a waveform."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from supi3.pinlevel import PinSpecError
from supi3.verif.errors import LockstepMismatchError
from supi3.verif.layout import CycleMatrix, WordLayout
from supi3.verif.vcd import write_window

__all__ = ["LockstepResult", "MismatchRecord", "Outcome", "raise_mismatch", "window_trace"]


@dataclass(frozen=True)
class LockstepResult:
    """A lockstep run that found no mismatch.

    Attributes
    ----------
    cycles:
        Cycles compared (after reset).
    seconds:
        Wall-clock time of the comparison itself: simulation, model and compare, without build and start-up.
    path:
        ``"per-cycle"`` or ``"batch"``.
    simulator:
        The simulator used.
    """

    cycles: int
    seconds: float
    path: str
    simulator: str

    @property
    def rate(self) -> float:
        """Compared cycles per second."""
        return self.cycles / self.seconds if self.seconds > 0 else float("inf")


@dataclass(frozen=True)
class MismatchRecord:
    """The first mismatch as the simulator side saw it.

    Attributes
    ----------
    cycle:
        Cycle of the mismatch.
    signal:
        Index of the first differing signal in :attr:`WordLayout.out_fields`.
    events:
        The model's recent bus events at that cycle.
    actual:
        The RTL's packed outputs (see :meth:`WordLayout.unpack_outputs`) of the window's cycles, ending at ``cycle``.
    """

    cycle: int
    signal: int
    events: list[str]
    actual: list[int] = field(default_factory=list)


@dataclass(frozen=True)
class Outcome:
    """What the simulator process hands back: cycles run, comparison time, the mismatch if any, and the error that
    stopped the run if one did (a model that broke a pin rule)."""

    cycles: int
    seconds: float
    mismatch: MismatchRecord | None = None
    error: PinSpecError | None = None


def raise_mismatch(
    layout: WordLayout,
    stimulus: CycleMatrix,
    cycle: int,
    signal: int,
    events: list[str],
    expected: CycleMatrix,
    actual: CycleMatrix,
    vcd_dir: Path | None,
    path: str,
) -> LockstepMismatchError:
    """Build the :class:`LockstepMismatchError` of a mismatch, writing the window's VCD into ``vcd_dir`` if given.

    ``expected`` and ``actual`` are the output traces of the window ending at ``cycle`` (shape ``(window, signals)``).
    """
    first = cycle + 1 - expected.shape[0]
    vcd = None
    if vcd_dir is not None:
        vcd = write_window(
            vcd_dir / f"mismatch-{path}-cycle{cycle}.vcd",
            layout,
            first,
            stimulus[first : cycle + 1],
            expected,
            actual,
            cycle,
        )
    return LockstepMismatchError(
        cycle=cycle,
        pin=layout.out_fields[signal].name,
        expected=int(expected[-1, signal]),
        actual=int(actual[-1, signal]),
        events=events,
        vcd=vcd,
        path=path,
    )


def window_trace(layout: WordLayout, rows: list[tuple[int, ...]]) -> CycleMatrix:
    """Per-cycle output values of a window as a trace ``(window, signals)``."""
    return np.array(rows, dtype=np.uint64).reshape(len(rows), len(layout.out_fields))

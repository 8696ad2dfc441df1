"""Errors of the lockstep harness."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from supi3.errors import Supi3Error

__all__ = ["LockstepError", "LockstepMismatchError", "SimulationError", "SimulatorUnavailableError"]


class LockstepError(Supi3Error):
    """Base class of the harness's errors."""


class SimulatorUnavailableError(LockstepError):
    """The requested simulator is not installed (tests skip on this)."""


class SimulationError(LockstepError):
    """Building or running the simulation failed for a reason other than a mismatch; ``log`` names the log file."""

    def __init__(self, message: str, log: Path | None = None) -> None:
        self.log = log
        super().__init__(message if log is None else f"{message} (log: {log})")


class LockstepMismatchError(LockstepError, AssertionError):
    """The RTL's output differs from the model's.

    Attributes
    ----------
    cycle:
        The first cycle (0 = first cycle after reset) on which an output differs.
    pin:
        The first differing output signal of that cycle, in the model's output order (``<pin>_oe`` for an enable).
    expected:
        The model's value.
    actual:
        The RTL's value.
    events:
        The model's last bus events at that cycle, oldest first.
    vcd:
        The waveform of the cycles before and at the mismatch (inputs, model and RTL outputs), or ``None``.
    path:
        Which harness path found it: ``"per-cycle"`` or ``"batch"``.
    """

    def __init__(
        self,
        cycle: int,
        pin: str,
        expected: int,
        actual: int,
        events: Sequence[str] = (),
        vcd: Path | None = None,
        path: str = "per-cycle",
    ) -> None:
        self.cycle = cycle
        self.pin = pin
        self.expected = expected
        self.actual = actual
        self.events = list(events)
        self.vcd = vcd
        self.path = path
        lines = [f"cycle {cycle}: output {pin!r} expected {expected:#x} (model), got {actual:#x} (RTL) [{path}]"]
        if self.events:
            lines.append("model's last bus events:")
            lines.extend(f"  {event}" for event in self.events)
        if vcd is not None:
            lines.append(f"waveform: {vcd}")
        super().__init__("\n".join(lines))

    def __reduce__(self) -> tuple[type[LockstepMismatchError], tuple[int, str, int, int, list[str], Path | None, str]]:
        return (type(self), (self.cycle, self.pin, self.expected, self.actual, self.events, self.vcd, self.path))

"""Verification kit: the lockstep harness comparing a pin-level model (:mod:`supi3.pinlevel`) with RTL, and the
timing checkers of Tables 3-4 and 3-15 on pin traces (:mod:`supi3.verif.timing`).

See ``docs/verification.md``. The cocotb coroutine lives in :mod:`supi3.verif.cocotb_lockstep` (imported only inside
a simulator), the per-cycle path's cocotb test module in :mod:`supi3.verif.testbenches`, the example design and model
in :mod:`supi3.verif.example`.
"""

from typing import TYPE_CHECKING

from supi3.pinlevel import EventLog, Pin, PinModel, PinSpecError, recent_events
from supi3.verif.errors import LockstepError, LockstepMismatchError, SimulationError, SimulatorUnavailableError
from supi3.verif.layout import Stimulus, WordLayout, first_mismatch, model_trace, stimulus_array
from supi3.verif.report import LockstepResult
from supi3.verif.timing import TimingViolation, TraceTimingError, check_expansion, check_serial_io, raise_first

if TYPE_CHECKING:
    from supi3.verif.lockstep import Lockstep, react, run_lockstep, run_lockstep_batch

_HEAVY = {"Lockstep", "react", "run_lockstep", "run_lockstep_batch"}
"""Names from :mod:`supi3.verif.lockstep`, which needs Amaranth (the ``rtl`` extra): imported on first use, so
that the models, which use only the pin protocol, run on the base install."""


def __getattr__(name: str) -> object:
    if name in _HEAVY:
        from supi3.verif import lockstep

        return getattr(lockstep, name)
    raise AttributeError(f"module 'supi3.verif' has no attribute {name!r}")


__all__ = [
    "EventLog",
    "Lockstep",
    "LockstepError",
    "LockstepMismatchError",
    "LockstepResult",
    "Pin",
    "PinModel",
    "PinSpecError",
    "SimulationError",
    "SimulatorUnavailableError",
    "Stimulus",
    "TimingViolation",
    "TraceTimingError",
    "WordLayout",
    "check_expansion",
    "check_serial_io",
    "first_mismatch",
    "model_trace",
    "raise_first",
    "react",
    "recent_events",
    "run_lockstep",
    "run_lockstep_batch",
    "stimulus_array",
]

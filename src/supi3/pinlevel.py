"""Pin-level primitives shared by the model, the RTL and the verification kit: :class:`Pin`, :class:`EventLog` and the
synchronous pin-model protocol (:class:`PinModel`) that the lockstep harness compares against RTL.

It imports nothing of the project but :mod:`supi3.errors`, so that the pin declarations (:mod:`supi3.pinout`), the
model and the verification kit (:mod:`supi3.verif`) can all stand on it (docs/architecture.md).

Convention
----------
A pin model is a synchronous machine clocked at the chip clock. Cycle ``n`` is the time between rising clock edge
``n`` and rising clock edge ``n + 1``; cycle 0 is the first cycle after reset. During every cycle:

1. the input pins take the values given for cycle ``n`` (they are stable for the whole cycle);
2. the output pins are observed, after the inputs have settled: an output may depend on the state (registered
   outputs, or combinational logic from state) and, combinationally, on the inputs of the same cycle;
3. the rising edge at the end of the cycle updates the state from the state and the inputs of cycle ``n``.

:meth:`PinModel.step` does all three for one cycle: it takes the inputs of cycle ``n``, returns the outputs seen
during cycle ``n`` and leaves the model in the state of cycle ``n + 1``. An Amaranth design whose ``sync`` domain
follows the same clock matches it exactly, whatever mix of registered and combinational outputs it has.

Reset: :meth:`PinModel.reset` puts the model in the state that the design has after its ``sync`` domain reset; the
harness asserts that reset before cycle 0 and does not compare outputs while it is asserted.

Tri-state outputs: an output :class:`Pin` with ``tristate=True`` named ``d`` has a second, one-bit output ``d_oe``
(its output enable). ``d_oe`` is compared on every cycle; ``d`` only on cycles where ``d_oe`` is 1, so a model may
return any value for a pin it does not drive.
"""

from __future__ import annotations

import numbers
from collections import deque
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Final, Protocol, runtime_checkable

from supi3.checks import describe
from supi3.errors import Supi3Error

SYNC_STAGES: Final = 2
"""Every asynchronous input passes two flip-flops before use (M1). Here, at the bottom of the layers, so that the bus
models (:mod:`supi3.interbus`, whose package :mod:`supi3.pinout` imports) can use it too; :mod:`supi3.pinout` names it
with the other pin facts."""

__all__ = [
    "OE_SUFFIX",
    "EventLog",
    "ModelFactory",
    "Pin",
    "PinModel",
    "PinSpecError",
    "check_cycles",
    "compared_signals",
    "recent_events",
]


class PinSpecError(Supi3Error, ValueError):
    """A pin list, a design's ports or a stimulus that do not fit together."""


def check_cycles(name: str, value: object, lo: int) -> int:
    """``value`` as a count of clock cycles from ``lo`` (a lockstep's ``reset_cycles`` from 0, M23; its ``window`` from
    1): Python and numpy integers pass, ``bool``, floats and strings do not (:class:`PinSpecError`)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or int(value) < lo:
        raise PinSpecError(f"{name} must be an integer from {lo}, not {value!r}")
    return int(value)


OE_SUFFIX = "_oe"
"""Suffix of the output-enable signal of a tri-state output pin."""


@dataclass(frozen=True)
class Pin:
    """One pin of a pin model: a name, a width in bits, and (outputs only) whether it has an output enable.

    Parameters
    ----------
    name:
        A Python identifier; the design exposes the pin as an attribute of the same name.
    width:
        Bits, 1 to 64.
    tristate:
        Output pins only: the pin has an output enable named ``<name>_oe`` (one bit), and its value is compared only
        while the enable is 1.
    """

    name: str
    width: int = 1
    tristate: bool = False

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.isidentifier():
            raise PinSpecError(f"pin name must be a Python identifier, not {self.name!r}")
        if isinstance(self.width, bool) or not isinstance(self.width, int) or not 1 <= self.width <= 64:
            raise PinSpecError(f"pin {self.name!r}: width must be an integer from 1 to 64, not {self.width!r}")
        if not isinstance(self.tristate, bool):
            raise PinSpecError(f"pin {self.name!r}: tristate must be True or False, not {self.tristate!r}")

    @property
    def mask(self) -> int:
        """All ones over the pin's width."""
        return (1 << self.width) - 1


@runtime_checkable
class PinModel(Protocol):
    """What the harness needs from a cycle-accurate Python model (see the module docstring for the timing).

    ``inputs`` and ``outputs`` may be plain class attributes (tuples of :class:`Pin`).
    """

    @property
    def inputs(self) -> Sequence[Pin]:
        """The input pins, in a fixed order (the column order of array stimulus)."""
        ...

    @property
    def outputs(self) -> Sequence[Pin]:
        """The output pins, in the order they are compared within a cycle."""
        ...

    def reset(self) -> None:
        """Return to the state right after reset; the next :meth:`step` is cycle 0."""

    def step(self, inputs: Mapping[str, int]) -> Mapping[str, int]:
        """Run one clock cycle.

        Parameters
        ----------
        inputs:
            A value for every input pin, for this cycle.

        Returns
        -------
        Mapping[str, int]
            A value for every output pin observed during this cycle, and ``<name>_oe`` for every tri-state pin.
        """
        ...


ModelFactory = Callable[[], PinModel]
"""Returns a fresh model."""


class EventLog:
    """A bounded log of a model's recent bus events, for mismatch reports.

    A model keeps one and returns :meth:`recent` from a ``recent_events()`` method; the harness prints those lines
    when the RTL disagrees with the model. Events are formatted only when read, so logging costs little per cycle.

    Parameters
    ----------
    depth:
        How many events to keep; older ones are dropped.
    """

    def __init__(self, depth: int = 32) -> None:
        if isinstance(depth, bool) or not isinstance(depth, int) or depth < 1:
            raise PinSpecError(f"event log depth must be a positive integer, not {depth!r}")
        self._events: deque[tuple[int, str, tuple[object, ...]]] = deque(maxlen=depth)

    def add(self, cycle: int, message: str, *args: object) -> None:
        """Record that ``message.format(*args)`` happened at ``cycle``."""
        self._events.append((cycle, message, args))

    def clear(self) -> None:
        """Forget every event (call from the model's ``reset``)."""
        self._events.clear()

    def recent(self) -> list[str]:
        """The kept events, oldest first, as ``"cycle <n>: <message>"``."""
        return [f"cycle {cycle}: {message.format(*args)}" for cycle, message, args in self._events]

    def __len__(self) -> int:
        return len(self._events)


def recent_events(model: object) -> list[str]:
    """The model's recent bus events, oldest first, or an empty list when it keeps none.

    A model opts in by defining ``recent_events() -> Sequence[str]``.

    Raises
    ------
    PinSpecError
        ``recent_events()`` returned no sequence of lines (None, a number, one str: UP-48; a str was printed a
        character a line, a number raised TypeError inside the mismatch report).
    """
    method = getattr(model, "recent_events", None)
    if not callable(method):
        return []
    events = method()
    if isinstance(events, str | bytes) or not isinstance(events, Iterable):
        raise PinSpecError(f"{type(model).__name__}.recent_events() must return a sequence of str (the model's recent "
                           f"bus events, oldest first), not {describe(events)}")  # fmt: skip
    return [str(event) for event in events]


def compared_signals(outputs: Sequence[Pin]) -> list[tuple[str, int, str | None]]:
    """The output signals in comparison order: ``(name, width, enable)`` with ``enable`` the name of the output
    enable that gates the comparison, or ``None``. A tri-state pin's enable comes right before its value."""
    signals: list[tuple[str, int, str | None]] = []
    for pin in outputs:
        if pin.tristate:
            signals.append((pin.name + OE_SUFFIX, 1, None))
            signals.append((pin.name, pin.width, pin.name + OE_SUFFIX))
        else:
            signals.append((pin.name, pin.width, None))
    return signals

"""The counter telegram block at pin level: one line direction of a chip in an LBD mode (manual 2.2.2, Table 2-5),
a synchronous machine with the ports of :data:`~supi3.lbd.COUNTER_INPUTS` and
:data:`~supi3.lbd.COUNTER_OUTPUTS`.

Every decision per bit period is :func:`supi3.lbd.counter_step` (the model restates none); this block
adds the clock timing the RTL counterpart :mod:`supi3.rtl.counter` shares, and which
``tests/test_verif_lockstep_counter.py`` holds it to cycle by cycle (docs/interbus.md "Counter telegram", BK-33).

What happens at the clock edge ending a cycle, from that cycle's inputs (:mod:`supi3.pinlevel`):

1. The bit grid: ``phase`` is the clock within the current bit period. Between telegrams (the spec state's
   ``bit`` is :data:`~supi3.lbd.IDLE_BIT`), unless a start level is already waiting for its sample,
   a ``line`` at the start level makes this cycle the first of a bit period (phase 0), as the chip's receiver
   begins a telegram (M7). Otherwise the grid runs on, one bit period every ``cpb`` clocks, idle or not.
2. At phase :func:`~supi3.lbd.sample_phase` (mid-bit) the line is sampled: ``counter_step`` gives the
   new state and the bit period's ``out``/``drive``, pushed into the output queue with the countdown
   :func:`~supi3.lbd.send_countdown` (the newest of
   :data:`~supi3.lbd.OUTPUT_SLOTS` entries are kept), and ``seen`` for the next cycle.

Outputs during a cycle come from the state: ``out`` and ``drive`` from the newest queue entry whose countdown is
1..``cpb`` (the chip transmitter's rule, M8: the bit is sent ``REPEATER_DELAY_BITS`` after it began on the pin), the
idle level and 0 when that entry has run out or none has begun; ``seen`` is 1 in the cycle after a counter
telegram's stop bit was sampled; ``count`` is the spec state's ``counted``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Final

from supi3.checks import check_bits
from supi3.errors import ArgumentError
from supi3.interbus import wire
from supi3.lbd import (
    COUNTER_INPUTS,
    COUNTER_OUTPUTS,
    IDLE_BIT,
    OUTPUT_SLOTS,
    CounterState,
    clocks_per_bit,
    counter_step,
    sample_phase,
    send_countdown,
)
from supi3.pinlevel import Pin

__all__ = ["CounterBlock"]

_NAMES: Final = frozenset(pin.name for pin in COUNTER_INPUTS)
_CPB: Final = (clocks_per_bit(0), clocks_per_bit(1))
"""Clocks per bit by the ``fast`` input."""
_SAMPLE: Final = tuple(sample_phase(cpb) for cpb in _CPB)
_COUNTDOWN: Final = tuple(send_countdown(cpb) for cpb in _CPB)
_IDLE_OUT: Final = wire.IDLE_LEVEL
"""A queue value (level in bit 0, drive in bit 1) for an idle line the block does not drive."""


class CounterBlock:
    """The counter telegram block as a pin model (:class:`supi3.pinlevel.PinModel`); see the module docstring.

    Attributes
    ----------
    state:
        The spec state (:class:`~supi3.lbd.CounterState`) for the cycle to come.
    cycle:
        Clock cycles since reset.
    """

    inputs: Sequence[Pin] = COUNTER_INPUTS
    outputs: Sequence[Pin] = COUNTER_OUTPUTS

    __slots__ = ("cycle", "pending", "phase", "queue", "seen", "state")

    def __init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        """The state after the ``sync`` reset: idle, nothing sent, the grid at phase 0."""
        self.cycle = 0
        self.state = CounterState()
        self.phase = 0
        """The clock within the current bit period."""
        self.pending = False
        """A start level restarted the grid and waits for its mid-bit sample."""
        self.queue: list[tuple[int, int]] = []
        """(the cycle its countdown reaches 0, level | drive << 1) of the last samples, oldest first."""
        self.seen = 0

    def _line(self, cpb: int) -> int:
        """The queue's value for the current cycle (the transmitter's rule, M8)."""
        c = self.cycle
        for end, value in reversed(self.queue):
            left = end - c
            if left <= cpb:
                return value if left > 0 else _IDLE_OUT
        return _IDLE_OUT

    def step(self, inputs: Mapping[str, int]) -> dict[str, int]:
        """Run one clock cycle (see :mod:`supi3.pinlevel` and the module docstring).

        Raises
        ------
        ArgumentError
            ``inputs`` not a mapping of exactly the input pins to 0 or 1; nothing changes.
        """
        try:
            line, fast = inputs["line"], inputs["fast"]
            fast_path = type(line) is int and type(fast) is int and not (line | fast) >> 1 and len(inputs) == 2
        except Exception:  # anything a broken mapping raises: the checks below name the problem
            fast_path = False
        if not fast_path:
            if not isinstance(inputs, Mapping) or inputs.keys() != _NAMES:
                raise ArgumentError("inputs", inputs, "inputs must be a mapping of exactly the pins "
                                    f"{', '.join(pin.name for pin in COUNTER_INPUTS)} to 0 or 1, not {inputs!r:.80}")
            line, fast = (check_bits(f"pin {name!r}", inputs[name], 1) for name in ("line", "fast"))
        cpb = _CPB[fast]
        value = self._line(cpb)
        outputs = {"out": value & 1, "drive": value >> 1, "seen": self.seen, "count": self.state.counted}
        phase = self.phase
        if self.state.bit == IDLE_BIT and not self.pending and line == wire.START_LEVEL:
            phase, self.pending = 0, True
        self.seen = 0
        if phase == _SAMPLE[fast]:
            self.state, sent = counter_step(self.state, line)
            self.pending = False
            self.seen = sent.seen
            self.queue.append((self.cycle + 1 + _COUNTDOWN[fast], sent.out | sent.drive << 1))
            if len(self.queue) > OUTPUT_SLOTS:
                del self.queue[0]
        self.phase = 0 if phase >= cpb - 1 else phase + 1
        self.cycle += 1
        return outputs

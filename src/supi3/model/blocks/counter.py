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
telegram's stop bit was sampled or the generator began on a silent line (``count`` 0 then, BK-58); ``count`` is the
spec state's ``counted``.

In the chip core (:class:`LineCounters`, M17: ``supi3.model.pins.Supi3Pins`` in the LBD modes) the same block is
clocked by :meth:`CounterBlock.clock`, replayed over a ``run()`` by :meth:`CounterBlock.advance` (only the cycles
where something happens) with the core's power-up resets (:meth:`CounterBlock.power_up`), and its line is rendered
from the queue (:meth:`CounterBlock.render`).
"""

from __future__ import annotations

from bisect import bisect_left
from collections.abc import Mapping, Sequence
from functools import lru_cache
from typing import Final

import numpy as np
import numpy.typing as npt

from supi3.checks import check_bits, check_bool, check_instance
from supi3.config import DeviceConfig, Interface
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
from supi3.model.blocks.transmitter import render_bits
from supi3.pinlevel import Pin
from supi3.pinout import SYNC_STAGES
from supi3.tables import BIT_RATES

__all__ = ["CounterBlock", "LineCounters"]

_NAMES: Final = frozenset(pin.name for pin in COUNTER_INPUTS)
_CPB: Final = (clocks_per_bit(0), clocks_per_bit(1))
"""Clocks per bit by the ``fast`` input."""
_SAMPLE: Final = tuple(sample_phase(cpb) for cpb in _CPB)
_COUNTDOWN: Final = tuple(send_countdown(cpb) for cpb in _CPB)
_IDLE_OUT: Final = wire.IDLE_LEVEL
"""A queue value (level in bit 0, drive in bit 1) for an idle line the block does not drive."""
_step: Final = lru_cache(maxsize=1 << 14)(counter_step)
"""``counter_step``, remembered: a line visits few states (plain ints, hashable), and ``run()`` of a chip replays
its blocks over every bit period (M17)."""


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

    def value(self, c: int, fast: int) -> int:
        """The queue's value (``out | drive << 1``) for cycle ``c`` (the transmitter's rule, M8)."""
        cpb = _CPB[fast]
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
        value = self.value(self.cycle, fast)
        outputs = {"out": value & 1, "drive": value >> 1, "seen": self.seen, "count": self.state.counted}
        self.clock(line, fast)
        if len(self.queue) > OUTPUT_SLOTS:
            del self.queue[0]
        return outputs

    def clock(self, line: int, fast: int) -> None:
        """The clock edge ending the current cycle (:attr:`cycle`) with the inputs ``line`` and ``fast`` (0 or 1,
        unchecked): :meth:`step` without the outputs and without dropping the oldest queue entries beyond
        :data:`~supi3.lbd.OUTPUT_SLOTS` (they never show: a chip keeps them to render a run, :meth:`render`)."""
        cpb = _CPB[fast]
        phase = self.phase
        if self.state.bit == IDLE_BIT and not self.pending and line == wire.START_LEVEL:
            phase, self.pending = 0, True
        self.seen = 0
        if phase == _SAMPLE[fast]:
            self.state, sent = _step(self.state, line)
            self.pending = False
            self.seen = sent.seen
            self.queue.append((self.cycle + 1 + _COUNTDOWN[fast], sent.out | sent.drive << 1))
        self.phase = 0 if phase >= cpb - 1 else phase + 1
        self.cycle += 1

    def advance(self, line: npt.NDArray[np.int64], c0: int, stop: int, fast: int) -> None:
        """:meth:`clock` for every cycle from :attr:`cycle` to ``stop - 1``, ``line[c - c0]`` being cycle ``c``'s
        input (``fast`` fixed), visiting only the cycles where a start level restarts the grid or the line is
        sampled, and taking the samples of an idle line between telegrams in one go: the same state and line out
        (:meth:`render`) as clocking each cycle. Nothing happens if :attr:`cycle` >= ``stop``."""
        cpb, half = _CPB[fast], _SAMPLE[fast]
        c = self.cycle
        if c >= stop:
            return
        starts = (np.flatnonzero(line[c - c0 : stop - c0] == wire.START_LEVEL) + c).tolist()
        k = 0
        while c < stop:
            phase = self.phase
            if phase >= cpb:  # left by a change of ``fast``: one clock brings it back into the bit period
                self.clock(int(line[c - c0]), fast)
                c += 1
                continue
            event = c + (half - phase) % cpb
            if self.state.bit == IDLE_BIT and not self.pending:
                k = bisect_left(starts, c, k)
                restart = starts[k] if k < len(starts) else stop
                if event < restart:  # samples of the idle line before the next start level (or the end)
                    self._idle_samples(event, (restart - 1 - event) // cpb + 1, fast)
                    c = self.cycle
                    continue
                if restart < stop:
                    event = restart
            if event >= stop:
                event = stop
            if event > c:  # the cycles between: the phase runs on, nothing else changes
                self.phase = (phase + event - c) % cpb
                self.seen = 0
                self.cycle = event
            if event == stop:
                return
            self.clock(int(line[event - c0]), fast)
            c = event + 1

    def _idle_samples(self, first: int, count: int, fast: int) -> None:
        """The samples of an idle line between telegrams at cycles ``first``, ``first + cpb``, ... (``count`` of
        them), as :meth:`clock` takes them; entries of the idle level not driven are not queued (the line is idle
        where no entry is, and a sample of the idle line comes a whole bit period after the one before, so its
        entry cuts none short)."""
        cpb, countdown = _CPB[fast], 1 + _COUNTDOWN[fast]
        state, queue, seen = self.state, self.queue, 0
        for s in range(first, first + count * cpb, cpb):
            state, sent = _step(state, wire.IDLE_LEVEL)
            if sent.out != wire.IDLE_LEVEL or sent.drive:
                queue.append((s + countdown, sent.out | sent.drive << 1))
            seen = sent.seen
        self.state, self.seen = state, seen
        self.cycle = first + (count - 1) * cpb + 1
        self.phase = _SAMPLE[fast] + 1

    def power_up(self, now: int, run_from: int, fast: int) -> None:
        """A chip's power-up reset in cycle ``now`` (``fast`` fixed): the state after reset from the next cycle,
        the bits not yet begun dropped and the line idle from the next cycle; the block is clocked again from cycle
        ``run_from`` (:attr:`cycle`; the cycles between are not clocked)."""
        cpb = _CPB[fast]
        keep = [entry for entry in self.queue if entry[0] - cpb <= now]  # a run renders them (render)
        self.reset()
        self.queue = [*keep, (now + 1 + cpb, _IDLE_OUT)]
        self.cycle = run_from

    def render(self, c0: int, n: int, fast: int) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]]:
        """``out`` and ``drive`` over cycles ``c0`` to ``c0 + n - 1`` (``fast`` fixed), as :meth:`step` gives them,
        from the queue; then the queue is cut to the entries that can still show."""
        cpb = _CPB[fast]
        values = render_bits([(end - cpb, value) for end, value in self.queue], cpb, c0, n)
        del self.queue[:-OUTPUT_SLOTS]
        return values & 1, values >> 1


class LineCounters:
    """The counter blocks of a chip core in an LBD mode (Table 2-5; docs/rtl.md "Counter telegram block"): one on
    the forward line, and in LBD-MR one on the return line. Their clocked logic runs where the core's logic runs
    (``Supi3Pins``: from the end of the reset stretch) and the power-up reset clears it (M2), as the RTL gates them.

    * Forward: ``line`` is the synchronised DO1 (the receiver's); DO2 is the block's ``out`` while its ``drive`` is
      1, else the transmitter's (M8: both send a bit ``REPEATER_DELAY_BITS`` after it began on DO1).
    * Return (LBD-MR): ``line`` is the return line's source (DI2 when a device follows, else the chip's own DO2,
      M5) through a synchroniser of ``SYNC_STAGES`` flip-flops that always runs (M1); DI1 is the block's ``out``:
      the return line is repeated ``REPEATER_DELAY_BITS`` later (M17).

    Parameters
    ----------
    fast:
        The bit rate strap: 1 at 2 Mbit/s, 0 at 500 kbit/s.
    looped:
        LBD-MR: a block on the return line too.

    Raises
    ------
    ArgumentError
        ``fast`` not 0 or 1, ``looped`` not a bool.
    """

    __slots__ = ("back", "fast", "forward", "pipe")

    def __init__(self, fast: int, looped: bool) -> None:
        self.fast = check_bits("fast", fast, 1)
        self.forward = CounterBlock()
        self.back = CounterBlock() if check_bool("looped", looped) else None
        self.reset()

    @classmethod
    def of(cls, config: DeviceConfig) -> LineCounters | None:
        """The counter blocks of a chip of ``config``: ``None`` outside the LBD modes (Table 2-5)."""
        if check_instance("config", config, DeviceConfig).interface not in (Interface.LBD_MR, Interface.LBD_OR):
            return None
        return cls(int(config.bit_rate == max(BIT_RATES)), config.interface is Interface.LBD_MR)

    def _blocks(self) -> tuple[CounterBlock, ...]:
        return (self.forward,) if self.back is None else (self.forward, self.back)

    def reset(self) -> None:
        """The ``sync`` reset: both blocks, the return line's synchroniser at the idle level."""
        for block in self._blocks():
            block.reset()
        self.pipe = [wire.IDLE_LEVEL] * SYNC_STAGES
        """The return line synchroniser's stages, newest first."""

    def power_up(self, now: int, run_from: int) -> None:
        """The power-up reset in cycle ``now``; the logic runs again from ``run_from`` (``CounterBlock.power_up``)."""
        for block in self._blocks():
            block.power_up(now, run_from, self.fast)

    def do2(self, c: int, sent: int) -> int:
        """DO2 in cycle ``c``, the transmitter sending ``sent``."""
        value = self.forward.value(c, self.fast)
        return value & 1 if value >> 1 else sent

    def show(self, c: int, outputs: dict[str, int], di2: int, next_present: bool) -> int:
        """Set ``do2`` and ``di1`` of cycle ``c`` in that cycle's ``outputs`` (``do2``: the transmitter's; ``di2``:
        the input; ``next_present``: M5's switch); return the return line's source in that cycle."""
        do2 = outputs["do2"] = self.do2(c, outputs["do2"])
        source = di2 if next_present else do2
        outputs["di1"] = source if self.back is None else self.back.value(c, self.fast) & 1
        return source

    def clock(self, source: int, line: int | None) -> None:
        """The clock edge ending a cycle of ``Supi3Pins.step`` (``source``: :meth:`show`'s): the synchroniser
        always, the blocks with the synchronised DO1 ``line`` if the logic runs (else ``line`` is ``None``)."""
        synced = self.pipe[-1]
        self.pipe = [source, *self.pipe[:-1]]
        if line is not None:
            self.forward.clock(line, self.fast)
            if self.back is not None:
                self.back.clock(synced, self.fast)
        for block in self._blocks():
            del block.queue[:-OUTPUT_SLOTS]

    def _replay(self, block: CounterBlock, line: npt.NDArray[np.int64], c0: int,
                power_ups: Sequence[tuple[int, int]]) -> npt.NDArray[np.int64]:
        """Clock ``block`` over a run of ``len(line)`` cycles from ``c0`` (``line``: its synchronised input) with
        the run's power-up resets ``(cycle, logic runs from)``; its ``out | drive << 1`` over the run."""
        n = len(line)
        for at, run_from in power_ups:
            block.advance(line, c0, at, self.fast)
            block.power_up(at, run_from, self.fast)
        block.advance(line, c0, c0 + n, self.fast)
        out, drive = block.render(c0, n, self.fast)
        return out | drive << 1

    def forward_run(self, line: npt.NDArray[np.int64], c0: int, power_ups: Sequence[tuple[int, int]],
                    sent: npt.NDArray[np.int64]) -> npt.NDArray[np.int64]:
        """DO2 over a run of ``Supi3Pins.run_forward`` from ``c0``: ``line`` the synchronised DO1, ``power_ups``
        the run's power-up resets, ``sent`` the transmitter's DO2."""
        values = self._replay(self.forward, line, c0, power_ups)
        return np.where(values >> 1, values & 1, sent)

    def return_run(self, source: npt.NDArray[np.int64], c0: int,
                   power_ups: Sequence[tuple[int, int]]) -> npt.NDArray[np.int64]:
        """DI1 over the same run, from the return line's source ``source`` (M5's switch of DI2 and DO2)."""
        if self.back is None:
            return source
        full = np.concatenate([np.asarray(self.pipe[::-1], dtype=np.int64), source])
        self.pipe = [int(v) for v in full[::-1][:SYNC_STAGES]]
        return self._replay(self.back, full[: len(source)], c0, power_ups) & 1

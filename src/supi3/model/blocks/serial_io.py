"""Serial I/O (SPI master mode): MFP3 /Conv, MFP4 SCLK, MFP5 /SS and MFP7 SerOut driven, SerIn (MFP6) sampled.

Manual: 3.3 (serial I/O, SPI master mode), Table 3-3 (the MFP pins), Table 3-4 (times t0 to t12), Figures 3-1 to 3-3
(input, output and input/output sequences). What the pins do in each cycle of a sequence is the executable spec
:mod:`supi3.serial_io` (:func:`~supi3.serial_io.sequence`, :meth:`~supi3.serial_io.SerialSequence.levels`);
this block places the sequences in time and takes SerIn in. Decisions: SM-1 to SM-11 of
``docs/assumptions/serial-io.md``:

* a sequence starts on the cycle after the edge that latches a valid data cycle; a latch while a clear sequence
  runs waits, one deep, the newest OUT word winning (SM-2); one while a data sequence runs abandons it and starts
  anew (SM-12: INTERBUS cycles never ask it);
* SerIn bit ``j`` is the level of the cycle before SCLK rises, taken through the synchroniser at the tick of cycle
  ``S + frame.sample(j) + SYNC_STAGES``; with a device attached to the chip
  (:meth:`supi3.model.chip.Supi3.attach_serial`) the device's answer in that cycle instead (SM-5, SM-10);
* the IN word read is taken over (``Supi3.in_word``) on the edge ending the sequence's last cycle (SM-6);
* an INTERBUS reset or a watchdog reset of process data at edge ``R`` aborts the sequence, drops a waiting one and,
  with OUT data, starts the clear sequence at ``R + 1`` (SM-9); a power-up reset idles the pins (SM-8).

RTL counterpart: :mod:`supi3.rtl.serial_io` (``SerialIo``).

The block keeps the pins as a list of breakpoints (cycle, levels) instead of counters, so that
:meth:`supi3.model.pins.Supi3Pins.run` visits only its sample and exchange ticks (:attr:`SerialIo.due`) and renders
the pin trace between them (:meth:`SerialIo.render`); a device attached to the chip is clocked at every breakpoint
whose levels differ from the last it saw, when the block catches up with time (:meth:`SerialIo.feed`).
"""

from __future__ import annotations

from bisect import bisect_left, bisect_right
from functools import lru_cache
from typing import TYPE_CHECKING

import numpy as np

from supi3.checks import check_bits
from supi3.model.blocks.transmitter import NEVER, PinTrace
from supi3.pinout import SYNC_STAGES
from supi3.serial_io import IDLE, Levels, SerialDevice, SerialSequence

if TYPE_CHECKING:
    from supi3.model.chip import Supi3

SER_IN_PIN = 6
"""SerIn is MFP6 (Table 3-3)."""
IDLE_MFP = IDLE.mfp()


@lru_cache(maxsize=256)
def _profile(seq: SerialSequence, word: int) -> tuple[tuple[int, Levels], ...]:
    """The cycles of ``seq`` (writing ``word``) at which the pins change, with their new levels: the first cycle,
    every change inside, and ``seq.length`` (idle again)."""
    # Every level change happens at a frame's ends, a slot's start, SCLK rise or end, or the /Conv pulse's ends; the
    # levels there come from the spec, so nothing of the schedule is restated here (tested against render()).
    candidates = {0, seq.length}
    for frame in seq.frames:
        candidates |= {frame.start, frame.end}
        for j in range(frame.bits):
            candidates |= {frame.slot(j), frame.rising(j), frame.slot(j) + frame.t0}
    if seq.conv is not None:
        candidates |= set(seq.conv)
    changes: list[tuple[int, Levels]] = []
    last = IDLE
    for k in sorted(candidates):
        levels = seq.levels(k, word)
        if k == 0 or levels != last:
            changes.append((k, levels))
            last = levels
    return tuple(changes)


class SerialIo:
    """The SPI master of the chip core: the pins of the running sequence and the IN word it reads.

    Parameters
    ----------
    chip:
        The bus behaviour: gives the sequences (``spi_sequences``), the OUT word at each latch
        (``start``) and the attached device (``serial_device``), and takes the IN word read (``in_word``).

    Attributes
    ----------
    due:
        The next tick (edge ending that cycle) at which the block acts: a SerIn sample or the exchange; ``NEVER``
        when no sequence runs.
    keep_from:
        Keep the breakpoints from this cycle on (the first cycle of a run, whose trace is rendered from them);
        ``NEVER`` outside a run.
    """

    __slots__ = (
        "_answer", "_clearing", "_cycles", "_device", "_end", "_feed_i", "_given", "_j", "_lag", "_levels", "_mfp",
        "_pending", "_read", "_samples", "_word", "chip", "clear_sequence", "due", "keep_from", "sequence",
    )  # fmt: skip

    def __init__(self, chip: Supi3) -> None:
        assert chip.spi_sequences is not None  # Supi3Pins makes this block in the SPI master modes only
        self.chip = chip
        self.sequence, self.clear_sequence = chip.spi_sequences
        self.keep_from = NEVER
        self.reset()

    def reset(self) -> None:
        """After the ``sync`` reset: idle pins, nothing fed to a device yet."""
        self._cycles: list[int] = []
        self._levels: list[Levels] = []
        self._mfp: list[int] = []
        self._feed_i = 0
        self._given = IDLE
        self._answer = 0
        self._device: SerialDevice | None = None
        self._stop()

    def _stop(self) -> None:
        self._pending: int | None = None
        self._clearing = False  # the running sequence is a clear sequence
        self._samples: list[int] = []
        self._read = False
        self._j = 0
        self._word = 0
        self._lag = 0
        self._end = NEVER
        self.due = NEVER

    @property
    def running(self) -> bool:
        """A sequence runs (its exchange tick has not come yet)."""
        return self._end != NEVER

    # ------------------------------------------------------------------------------------------------------------
    # Events from the chip and the core
    # ------------------------------------------------------------------------------------------------------------

    def power_up(self, c: int) -> None:
        """Power-up reset at the edge ending cycle ``c``: the sequence stops, the pins idle from ``c + 1`` (SM-8)."""
        self._cut(c)
        self._stop()

    def start(self, c: int, word: int) -> None:
        """A valid data cycle latched ``word`` (the OUT word) at the edge ending cycle ``c`` (SM-2, SM-12)."""
        if self.running:
            if self._clearing:
                self._pending = word  # one deep: the newest OUT word wins
                return
            self.power_up(c)  # a data sequence is abandoned, nothing taken over (SM-12)
        self._begin(c + 1, self.sequence, word)

    def clear(self, c: int) -> None:
        """INTERBUS reset or watchdog reset of process data at the edge ending cycle ``c`` (SM-9): abort, drop the
        waiting word, and with OUT data write zeros from ``c + 1``."""
        self.power_up(c)
        if self.clear_sequence is not None:
            self._begin(c + 1, self.clear_sequence, 0)
            self._clearing = True

    def clock(self, c: int, mfp_in: int) -> None:
        """The tick ending cycle ``c`` = :attr:`due`, with the synchronised MFP inputs ``mfp_in``."""
        if self._j < len(self._samples):
            if self._lag:
                bit = (mfp_in >> SER_IN_PIN) & 1
            else:
                self.feed(c)
                bit = self._answer
            self._word = (self._word << 1) | bit
            self._j += 1
            self.due = self._samples[self._j] if self._j < len(self._samples) else self._end
            return
        # The exchange with the INTERBUS registers (the third step of 3.3.1, SM-6).
        if self._read:
            self.chip.in_word = self._word
        pending = self._pending
        self._stop()
        if pending is not None:
            self._begin(c + 1, self.sequence, pending)

    def _begin(self, s: int, seq: SerialSequence, word: int) -> None:
        """Run ``seq`` writing ``word`` from cycle ``s``."""
        self._trim(min(s - 1, self.keep_from))
        for k, levels in _profile(seq, word):
            self._cycles.append(s + k)
            self._levels.append(levels)
            self._mfp.append(levels.mfp())
        read = seq.read
        self._read = read is not None
        # Through the synchroniser from the pin, or the device's answer in the sample cycle itself (SM-5).
        self._lag = SYNC_STAGES if self.chip.serial_device is None else 0
        self._samples = [] if read is None else [s + read.sample(j) + self._lag for j in range(read.bits)]
        self._end = s + seq.length - 1
        self._j = 0
        self._word = 0
        self.due = self._samples[0] if self._samples else self._end

    def _cut(self, c: int) -> None:
        """The pins idle from cycle ``c + 1``: drop the breakpoints after ``c``."""
        i = bisect_right(self._cycles, c)
        del self._cycles[i:], self._levels[i:], self._mfp[i:]
        self._feed_i = min(self._feed_i, i)
        if self._levels and self._levels[-1] != IDLE:
            self._cycles.append(c + 1)
            self._levels.append(IDLE)
            self._mfp.append(IDLE_MFP)

    def _trim(self, keep: int) -> None:
        """Forget the breakpoints before the last one at or before cycle ``keep`` (already fed to the device)."""
        drop = min(bisect_right(self._cycles, keep) - 1, self._feed_i)
        if drop > 0:
            del self._cycles[:drop], self._levels[:drop], self._mfp[:drop]
            self._feed_i -= drop

    # ------------------------------------------------------------------------------------------------------------
    # The pins
    # ------------------------------------------------------------------------------------------------------------

    def mfp(self, c: int) -> int:
        """MFP3, 4, 5 and 7 in cycle ``c`` (from the cycle of the last event on: the block's state decides)."""
        i = bisect_right(self._cycles, c) - 1
        return IDLE_MFP if i < 0 else self._mfp[i]

    def render(self, c0: int, n: int) -> PinTrace:
        """MFP3, 4, 5 and 7 over cycles ``c0`` to ``c0 + n - 1`` (the breakpoints since :attr:`keep_from`)."""
        cycles = self._cycles
        lo, hi = bisect_right(cycles, c0), bisect_left(cycles, c0 + n)
        starts = np.array([c0, *cycles[lo:hi]], dtype=np.int64) - c0
        values = np.array([self.mfp(c0), *self._mfp[lo:hi]], dtype=np.int64)
        # Breakpoints of one cycle (a sequence ending where the next begins): the later one holds, the earlier none.
        return np.repeat(values, np.diff(np.append(starts, n)))

    def feed(self, upto: int) -> None:
        """Clock the device attached to the chip with every change of the pins up to cycle ``upto``: it answers on
        SerIn (:meth:`supi3.serial_io.SerialDevice.clock`)."""
        cycles = self._cycles
        i = self._feed_i
        n = len(cycles)
        device = self.chip.serial_device
        if device is not self._device:
            self._device = device
            self._answer = 0
        if i >= n or cycles[i] > upto:
            return
        while i < n and cycles[i] <= upto:
            if i + 1 < n and cycles[i + 1] == cycles[i]:
                i += 1  # the next sequence begins in this cycle: its levels hold
                continue
            levels = self._levels[i]
            i += 1
            if levels != self._given:
                self._given = levels
                if device is not None:
                    self._answer = _ser_in(device.clock(levels))
        self._feed_i = i


def _ser_in(level: object) -> int:
    """A device's SerIn answer, checked (0 or 1)."""
    if type(level) is int and level in (0, 1):
        return level
    return check_bits("SerialDevice.clock()", level, 1, "the SerIn level")

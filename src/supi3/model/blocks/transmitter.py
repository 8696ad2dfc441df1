"""Transmitter and repeater: the forward line out (DO2) and the return line (DI2 -> DI1).

Manual: Table 1-4 (DO2_CU, DI1_CU, DI2, RBST_EXT), Table 2-2 (RF = 10: a following device is told by RBST_EXT),
2.1.1 (bus connector recognition). INTERBUS (``/work/shared/reference/interbus-layer2.md`` "Topology and physics",
``docs/interbus.md``): every device repeats the forward line after a fixed delay, sending its own bits in place of
the ones it takes; the last device of the ring loops the forward line back onto the return line. Decisions: M5 (the
following device), M8 (the repeater's delay), ``docs/model.md``.

RTL counterpart: the ``transmitter`` block of :mod:`supi3.rtl.core` (``Transmitter``: the bits in flight with their
countdowns, the ERR pair rewrite, the return line switch).
"""

from __future__ import annotations

from itertools import chain
from typing import Final

import numpy as np
import numpy.typing as npt

from supi3.interbus import wire

PinTrace = npt.NDArray[np.int64]

NEVER: Final = 1 << 62
"""A cycle that never comes (no event due)."""


class Transmitter:
    """The bits on their way out on DO2, and whether a device follows on the return line.

    Parameters
    ----------
    cpb:
        Clocks per bit at the configured bit rate.
    forward_delay:
        Clocks from a bit's mid-bit sample to its first clock on DO2, plus cpb/2 (M8).
    rbst_by_pin:
        A following device is told by RBST_EXT (RF = 10, Table 2-2), not recognised on DI2 (M5).

    Attributes
    ----------
    bits:
        ``(first cycle, level)`` of every bit sent, oldest first (at least the last eight: a bit lasts ``cpb``
        clocks or until the next one begins, the line idles in between).
    next_present:
        A following device was recognised: the return line passes DI2 through, else loops DO2 back (M5).
    """

    __slots__ = ("bits", "cpb", "delay", "next_present", "rbst_by_pin")

    def __init__(self, cpb: int, forward_delay: int, rbst_by_pin: bool) -> None:
        self.cpb = cpb
        self.delay = forward_delay - cpb // 2
        """Clocks from a bit's mid-bit sample to its first clock on DO2."""
        self.rbst_by_pin = rbst_by_pin
        self.reset()

    def reset(self) -> None:
        """After the ``sync`` reset: nothing sent yet."""
        self.bits: list[tuple[int, int]] = []
        self.next_present = False

    def power_up(self, now: int) -> None:
        """Power-up reset in cycle ``now``: drop the bits not yet begun, idle the line from the next cycle, forget
        the following device."""
        self.bits = [*(entry for entry in self.bits if entry[0] <= now), (now + 1, wire.IDLE_LEVEL)]
        self.next_present = False

    def repeat(self, c: int, level: int) -> None:
        """Send ``level`` for the bit sampled mid-bit in cycle ``c``: it begins REPEATER_DELAY_BITS after the bit
        began on the line (docs/interbus.md)."""
        self.bits.append((c + self.delay, level))

    def settle_err(self, err: int) -> None:
        """Set the ERR pair (CNTR bits 14 and 15, the last two data bits sent before the stop bit, still in the
        transmitter) to ``err``."""
        bits = self.bits
        stop = bits.pop()
        err_bit, nerr_bit = bits.pop(), bits.pop()
        bits += [(nerr_bit[0], 1 - err), (err_bit[0], err), stop]

    def trim(self) -> None:
        """Forget all but the last eight bits (enough for :meth:`level` and :meth:`settle_err`)."""
        if len(self.bits) > 8:
            del self.bits[:-8]

    def level(self, c: int) -> int:
        """DO2 in cycle ``c``: the last bit whose bit period covers ``c``, else the idle level."""
        cpb = self.cpb
        for start, bit in reversed(self.bits):
            if start <= c:
                return bit if c < start + cpb else wire.IDLE_LEVEL
        return wire.IDLE_LEVEL

    def render(self, c0: int, n: int) -> PinTrace:
        """DO2 over cycles ``c0`` to ``c0 + n - 1``, from :attr:`bits` (as :meth:`level` reads it)."""
        return render_bits(self.bits, self.cpb, c0, n)

    def return_line(
        self,
        start: tuple[int, bool, int],
        power_ups: list[tuple[int, int]],
        seen: npt.NDArray[np.int64],
        di2: npt.NDArray[np.int64],
        do2: npt.NDArray[np.int64],
    ) -> PinTrace:
        """DI1 over a run of ``len(do2)`` cycles, and :attr:`next_present` after it.

        ``start`` is (the run's first cycle, :attr:`next_present` then, the first cycle the logic ran from then);
        ``power_ups`` the (cycle, logic runs from) of each power-up reset in the run; ``seen`` what recognition
        reads in each cycle (the synchronised RBST_EXT with RF = 10, else the synchronised DI2). Recognition is
        updated at every clock edge where the logic runs: with RF = 10 it is RBST_EXT, otherwise it latches the
        first high level seen on DI2; power-up clears it.
        """
        c0, value, run_from = start
        n = len(do2)
        state = np.empty(n + 1, dtype=bool)  # state[t]: what the outputs of cycle c0 + t see
        state[0] = value
        t = 0
        for at, new_run_from in [*power_ups, (c0 + n, run_from)]:
            end = at - c0
            if end > t:
                active = np.arange(c0 + t, c0 + end) >= run_from
                level = seen[t:end] != 0
                if self.rbst_by_pin:
                    values = np.where(active, level, value)
                else:
                    values = np.logical_or.accumulate(level & active) | value
                state[t + 1 : end + 1] = values
                value = bool(values[-1])
            if end < n:
                value = False
                run_from = new_run_from
                state[end + 1] = False
                t = end + 1
        self.next_present = value
        return np.where(state[:n], di2, do2).astype(np.int64)


def render_bits(bits: list[tuple[int, int]], cpb: int, c0: int, n: int) -> PinTrace:
    """A line over cycles ``c0`` to ``c0 + n - 1`` from ``(first cycle, value)`` entries in order of their first
    cycles: each value lasts ``cpb`` clocks or until the next entry begins, the idle level in between
    (:meth:`Transmitter.level`; the counter block's queue, :mod:`supi3.model.blocks.counter`)."""
    if not bits:
        return np.full(n, wire.IDLE_LEVEL, dtype=np.int64)
    # Runs of (gap, bit) levels, repeated over their lengths, are the trace.
    sent = np.fromiter(chain.from_iterable(bits), dtype=np.int64, count=2 * len(bits)).reshape(-1, 2)
    bit_starts, values = sent[:, 0], sent[:, 1]
    ends = np.minimum(bit_starts + cpb, np.append(bit_starts[1:], NEVER))
    lo = np.clip(bit_starts - c0, 0, n)
    hi = np.maximum(np.clip(ends - c0, 0, n), lo)
    gaps = lo - np.append(0, hi[:-1])
    levels = np.column_stack([np.full(len(values), wire.IDLE_LEVEL), values]).ravel()
    runs = np.column_stack([gaps, hi - lo]).ravel()
    return np.append(np.repeat(levels, runs), np.full(n - int(hi[-1]), wire.IDLE_LEVEL, dtype=np.int64))

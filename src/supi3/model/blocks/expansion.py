"""Serial register expansion: ClkExR, ToExR, LaOuD and /LaInD, and FromExR taken in place of the data register.

Manual: 3.5 (Tables 3-14, 3-15, Figures 3-23, 3-24) and 3.4.11 (ExtReg in the SET register). The schedule is the
spec's (:mod:`supi3.expansion`: :func:`~supi3.expansion.clock_high`, :func:`~supi3.expansion.end_pulses`); the
decisions RX-1 to RX-10 are in ``docs/assumptions/expansion.md``. What a cycle end or a reset does to the chip is
:class:`supi3.model.chip.Supi3`, which tells this block (its expansion driver) when the pins must move.

RTL counterpart: :mod:`supi3.rtl.expansion`.

In a data cycle with ExtReg = 1 the data path (:class:`~supi3.model.blocks.datapath.DataPath`) shifts every data
bit through :meth:`Expansion.shift`: at the receiver's sample tick the chip takes FromExR (the synchronised pin, or
the attached chain's answer) as the bit to send on, shows the received bit on ToExR from the next cycle and pulses
ClkExR (RX-2, RX-3). The block keeps the pin changes it scheduled as a sorted list of ``(cycle, signal, level)``
events, so that :meth:`~supi3.model.pins.Supi3Pins.run` renders them between visited cycles and an attached
:class:`~supi3.expansion.ExternalRegisters` is clocked at every change, in order (:meth:`Expansion.values`,
:meth:`Expansion.render`, :meth:`Expansion.tell`).
"""

from __future__ import annotations

from bisect import insort
from dataclasses import astuple
from typing import TYPE_CHECKING, Final

import numpy as np

from supi3.expansion import (
    IDLE,
    PULSE_T0,
    ExpansionLevels,
    ExternalRegisters,
    clock_high,
    end_pulses,
)
from supi3.interbus import wire
from supi3.model.blocks.transmitter import PinTrace
from supi3.pinout import SYNC_STAGES
from supi3.serial_io import PERIPHERAL_DELAY_CLOCKS

if TYPE_CHECKING:
    from supi3.model.chip import Supi3

OUTPUT_NAMES: Final = ("clk_exr", "to_exr", "la_ou_d", "la_in_d_n")
"""The block's output pins (Table 3-14; /ResReg is the outputs block's, from ``Supi3.resreg_until``)."""
_CLK, _TO, _LAOU, _LAIN, _RES = range(5)
IDLE_LEVELS: Final[tuple[int, ...]] = astuple(IDLE)
"""The five levels of :class:`~supi3.expansion.ExpansionLevels` after power-up and with ExtReg = 0 (RX-6)."""
ANSWER_LAG: Final = PERIPHERAL_DELAY_CLOCKS + SYNC_STAGES
"""A chain's answer to a change at cycle ``ch`` is on FromExR from ``ch + 2`` (``PERIPHERAL_DELAY_CLOCKS``, SM-10)
and reaches the logic through the synchroniser (M1): the tick of cycle ``c`` uses the answer to the last change at
or before ``c - 4``."""
OVERRUN: Final = "EXPANSION_OVERRUN"
"""The event counted in ``Supi3.events`` when a data cycle's first ClkExR rise comes before the end pulses of the
previous cycle are over (RX-4)."""
_TRIM: Final = 256
"""Events kept before the older ones are dropped."""
_KEEP_ANSWERS: Final = 16
"""A chain's answers kept when the older ones are dropped: more than the changes within :data:`ANSWER_LAG`."""


def lead_clocks(cpb: int) -> int:
    """Clocks from the start of a frame on the line to its first ClkExR rise, minus those from the end of the cycle
    before it (the master's end of its last stop bit) to the first clock of its end pulses: a frame begins
    ``lead_clocks`` after the previous cycle's pulses began at the earliest without an overrun (RX-4,
    ``docs/assumptions/expansion.md``). The first data bit (``wire.POS_DATA``) is sampled mid-bit, the pulses begin
    after the mid-bit sample of the last stop bit, half a bit before its end: (POS_DATA + 1) bits plus the quarter
    bit of :func:`~supi3.expansion.clock_high`."""
    return (wire.POS_DATA + 1) * cpb + clock_high(cpb)[0]


def overrun_gap_clocks(latched_data: bool, cpb: int) -> int:
    """Idle clocks the master must leave between the end of a cycle (``latched_data``: a latched data cycle) and
    the start of the next frame so that the frame's first ClkExR rise comes after the end pulses (RX-4): 7.75 bit
    periods after a latched data cycle, none after any other end."""
    return max(0, end_pulses(latched_data, cpb).length - lead_clocks(cpb))


class Expansion:
    """The register expansion's pins at cycle level.

    Parameters
    ----------
    chip:
        The bus behaviour: whether ExtReg = 1 (``chip.expansion``), the attached chain (``chip.expansion_chain``),
        and the overrun event.
    cpb:
        Clocks per bit at the configured bit rate.

    Attributes
    ----------
    from_exr:
        The synchronised FromExR level of the cycle being ticked (set by :class:`~supi3.model.pins.Supi3Pins`).
    """

    __slots__ = (
        "_answers", "_chain", "_events", "_free", "_high", "_shown", "_shown_at", "_shown_levels", "_told",
        "_told_levels", "chip", "cpb", "first", "from_exr",
    )  # fmt: skip

    def __init__(self, chip: Supi3, cpb: int) -> None:
        self.chip = chip
        self.cpb = cpb
        self._high = clock_high(cpb)
        self.sync_reset()

    def sync_reset(self) -> None:
        """After the ``sync`` reset (cycle 0): idle pins, nothing scheduled, the chain's answers forgotten."""
        self.from_exr = 0
        self._events: list[tuple[int, int, int]] = []
        self._shown_levels = list(IDLE_LEVELS)
        self._told_levels = list(IDLE_LEVELS)
        self._shown = self._told = 0
        self._shown_at = dict(zip(OUTPUT_NAMES, IDLE_LEVELS, strict=False))
        self._chain: ExternalRegisters | None = None
        self._answers: list[tuple[int, int]] = []
        self._free = 0
        self.first = False

    def power_up(self, c: int) -> None:
        """Power-up reset in cycle ``c``: pending changes dropped, every pin idle from the next cycle (RX-6)."""
        events = self._events = [event for event in self._events if event[0] <= c]  # sorted: cursors stay valid
        levels = list(self._shown_levels)
        for _, signal, level in events[self._shown :]:
            levels[signal] = level
        # Only the pins not idle already: a power-up held for many cycles (vmon_ok low) schedules nothing more.
        for signal, (now, idle) in enumerate(zip(levels, IDLE_LEVELS, strict=True)):
            if now != idle:
                insort(events, (c + 1, signal, idle))
        self._free = 0
        self.first = False

    # ------------------------------------------------------------------------------------------------------------
    # What the chip does (called by the data path and by Supi3)
    # ------------------------------------------------------------------------------------------------------------

    def begin(self) -> None:
        """A data frame with ExtReg = 1 began: its first data bit is checked against the end pulses (RX-4)."""
        self.first = True

    def shift(self, level: int, c: int) -> int:
        """Data bit received at ``level``, sampled at the tick of cycle ``c``: the bit sent in its place (FromExR);
        ToExR shows ``level`` and ClkExR pulses from the next cycle (RX-2, RX-3)."""
        out = self._from_exr(c)
        start = c + 1
        rise, fall = self._high
        if self.first:
            self.first = False
            if start + rise < self._free:
                self.chip._count(OVERRUN)
        events = self._events
        insort(events, (start, _TO, level))
        insort(events, (start + rise, _CLK, 1))
        insort(events, (start + fall, _CLK, 0))
        return out

    def end(self, clk: int, latched_data: bool) -> None:
        """The cycle ended (latched or discarded) at the edge ending cycle ``clk``: the end pulses from the next
        cycle (RX-4)."""
        pulses = end_pulses(latched_data, self.cpb)
        start = clk + 1
        events = self._events
        if pulses.la_ou_d is not None:
            insort(events, (start + pulses.la_ou_d[0], _LAOU, 1))
            insort(events, (start + pulses.la_ou_d[1], _LAOU, 0))
        insort(events, (start + pulses.la_in_d_n[0], _LAIN, 0))
        insort(events, (start + pulses.la_in_d_n[1], _LAIN, 1))
        self._free = max(self._free, start + pulses.length)

    def reset(self, clk: int) -> None:
        """INTERBUS or watchdog reset at the edge ending cycle ``clk``: /ResReg low for 4 t0 from the next cycle,
        as the outputs block shows it from ``Supi3.resreg_until`` (RX-5); told to the chain like the other pins."""
        insort(self._events, (clk + 1, _RES, 0))
        insort(self._events, (clk + 1 + PULSE_T0 * self.cpb, _RES, 1))

    # ------------------------------------------------------------------------------------------------------------
    # The chain: clocked at every change, in order; its answer read through the synchroniser
    # ------------------------------------------------------------------------------------------------------------

    def tell(self, until: int) -> None:
        """Clock the attached chain with every change up to cycle ``until`` not told yet (nothing without a
        chain)."""
        chain = self.chip.expansion_chain
        if chain is not self._chain:  # attached, replaced or detached: a new chain starts from the pins now
            self._chain = chain
            self._answers = []
            if chain is not None:
                self._answers.append((-1, chain.clock(ExpansionLevels(*self._told_levels))))
        events, k, levels = self._events, self._told, self._told_levels
        if chain is None:
            while k < len(events) and events[k][0] <= until:
                levels[events[k][1]] = events[k][2]
                k += 1
            self._told = k
            self._trim()
            return
        answers = self._answers
        while k < len(events) and events[k][0] <= until:
            at = events[k][0]
            while k < len(events) and events[k][0] == at:
                levels[events[k][1]] = events[k][2]
                k += 1
            answers.append((at, chain.clock(ExpansionLevels(*levels))))
        self._told = k
        self._trim()

    def _from_exr(self, c: int) -> int:
        """FromExR as the logic sees it at the tick of cycle ``c`` (the chain's answer when one is attached)."""
        self.tell(c - ANSWER_LAG)
        answers = self._answers
        if self._chain is None:
            return self.from_exr
        level = answers[0][1]
        for at, answer in answers:
            if at > c - ANSWER_LAG:
                break
            level = answer
        return level

    def _trim(self) -> None:
        done = min(self._shown, self._told)
        if done > _TRIM:
            del self._events[:done]
            self._shown -= done
            self._told -= done
        if len(self._answers) > _TRIM:
            del self._answers[: len(self._answers) - _KEEP_ANSWERS]

    # ------------------------------------------------------------------------------------------------------------
    # The pins
    # ------------------------------------------------------------------------------------------------------------

    def values(self, c: int) -> dict[str, int]:
        """The block's output pins during cycle ``c`` (the current cycle or later); the chain is told up to it."""
        events, k = self._events, self._shown
        if k < len(events) and events[k][0] <= c:
            levels = self._shown_levels
            while k < len(events) and events[k][0] <= c:
                levels[events[k][1]] = events[k][2]
                k += 1
            self._shown = k
            self._shown_at = dict(zip(OUTPUT_NAMES, levels, strict=False))
            self.tell(c)
        return self._shown_at

    def peek(self, c: int) -> dict[str, int]:
        """:meth:`values` of cycle ``c`` without moving the block (nothing told to the chain)."""
        events, k = self._events, self._shown
        levels = list(self._shown_levels)
        while k < len(events) and events[k][0] <= c:
            levels[events[k][1]] = events[k][2]
            k += 1
        return dict(zip(OUTPUT_NAMES, levels, strict=False))

    def render(self, c0: int, n: int) -> dict[str, PinTrace]:
        """The block's output traces over cycles ``c0`` to ``c0 + n - 1``, as :meth:`values` gives them; the chain is
        told up to the last of them."""
        events, k = self._events, self._shown
        levels = self._shown_levels
        starts: list[list[int]] = [[0] for _ in OUTPUT_NAMES]
        values: list[list[int]] = [[level] for level in levels[: len(OUTPUT_NAMES)]]
        while k < len(events) and events[k][0] < c0 + n:
            at, signal, level = events[k]
            levels[signal] = level
            if signal < len(OUTPUT_NAMES):
                starts[signal].append(max(at - c0, 0))
                values[signal].append(level)
            k += 1
        self._shown = k
        self._shown_at = dict(zip(OUTPUT_NAMES, levels, strict=False))
        self.tell(c0 + n - 1)
        traces: dict[str, PinTrace] = {}
        for name, first, seen in zip(OUTPUT_NAMES, starts, values, strict=True):
            if len(first) == 1:
                traces[name] = np.full(n, seen[0], dtype=np.int64)
                continue
            lengths = np.diff(np.append(np.asarray(first, dtype=np.int64), n))
            traces[name] = np.repeat(np.asarray(seen, dtype=np.int64), lengths)
        return traces

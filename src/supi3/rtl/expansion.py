"""Serial register expansion (manual 3.5) in Amaranth: ClkExR, ToExR, LaOuD and /LaInD from counters.

:class:`ExpansionRtl` drives the expansion pins of the SUPI 3 OPC as :mod:`supi3.expansion` schedules them (Tables
3-14, 3-15, Figures 3-23, 3-24; decisions RX-1 to RX-7 of ``docs/assumptions/expansion.md``). Its constants come
from :func:`supi3.expansion.clock_high` and :func:`~supi3.expansion.end_pulses` for every bit rate at
elaboration. /ResReg (RX-5: ``PULSE_T0`` bit periods on an INTERBUS reset and a watchdog reset with ExtReg = 1) is
the outputs block's pulse counter, which also times the 375 ns pulse without expansion (``supi3.rtl.core``).

* ``ext`` (the SET register's ExtReg, RX-1) decides, at each frame's ``load``, whether the frame's data bits go
  through the external chain (``has_data``: the length code gives data bytes): a data cycle's (not an ID cycle's)
  ``shift`` then puts the received ``level`` on
  ToExR from the next cycle, with ClkExR high ``clock_high(cpb)`` cycles after that (RX-3), and the bit the chip
  sends in its place is ``from_exr`` (FromExR after the core's synchroniser, ``send``; RX-2).
* ``ended`` (a cycle's latch or discard) with ``ext`` starts the end pulses from the next cycle, LaOuD only if
  ``latched`` (a valid data cycle, RX-4); a newer end restarts them. ``overrun`` is 1 in the cycle a data cycle's
  first ClkExR rises while they run.
* Without ``ext`` nothing starts: after power-up every pin shows :data:`supi3.expansion.IDLE` (RX-6, RX-7); what
  runs when ExtReg is cleared runs to its end, and ToExR keeps its last bit, as in the model.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Final

from amaranth.hdl import Module, Mux, Signal, Value
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from supi3 import expansion as spec
from supi3.interbus import wire
from supi3.tables import BIT_RATES

__all__ = ["PIN_NAMES", "ExpansionRtl"]

PIN_NAMES: Final = ("clk_exr", "to_exr", "la_ou_d", "la_in_d_n")
"""The outputs of :class:`supi3.expansion.ExpansionLevels` this block drives, as ports of the same names."""


def _in_bits(pulses: spec.EndPulses, cpb: int) -> spec.EndPulses:
    """``pulses`` in bit periods of ``cpb`` clocks: each edge must fall on a whole bit period (Table 3-15 gives them
    in t_Bit, RX-4)."""

    def bits(clocks: int) -> int:
        if clocks % cpb:
            raise ValueError(f"an end pulse edge must fall on a whole bit period, not at {clocks} clocks (cpb = {cpb})")
        return clocks // cpb

    def window(edges: tuple[int, int]) -> tuple[int, int]:
        return bits(edges[0]), bits(edges[1])

    la_ou_d = None if pulses.la_ou_d is None else window(pulses.la_ou_d)
    return replace(pulses, la_ou_d=la_ou_d, la_in_d_n=window(pulses.la_in_d_n))


class ExpansionRtl(wiring.Component):
    """The register expansion block (block ``expansion``).

    Ports: ``ext``, ``has_data``, ``rate`` (index into :data:`supi3.tables.BIT_RATES`), ``load``, ``load_id``,
    ``shift``, ``level``, ``ended``, ``latched``, ``from_exr`` in; the pins :data:`PIN_NAMES`, ``active`` (this
    frame's data go through the chain), ``send`` (the bit to send in place of the internal register's) and
    ``overrun`` out.
    """

    def __init__(self) -> None:
        self.cpbs = tuple(wire.clocks_per_bit(bit_rate) for bit_rate in BIT_RATES)
        members: dict[str, object] = {
            "ext": In(1), "has_data": In(1), "rate": In(range(len(BIT_RATES))), "load": In(1), "load_id": In(1),
            "shift": In(1), "level": In(1), "ended": In(1), "latched": In(1), "from_exr": In(1),
            "active": Out(1), "send": Out(1), "overrun": Out(1),
        }  # fmt: skip
        members.update({name: Out(1, init=getattr(spec.IDLE, name)) for name in PIN_NAMES})
        super().__init__(members)

    def elaborate(self, _platform: object) -> Module:
        m = Module()
        sync, comb = m.d.sync, m.d.comb
        # each counter as wide as its longest run at any bit rate; the end pulses in whole bit periods
        clk_range = range(max(spec.clock_high(cpb)[1] for cpb in self.cpbs) + 1)
        pulses = {cpb: {data: _in_bits(spec.end_pulses(data, cpb), cpb) for data in (True, False)} for cpb in self.cpbs}
        count_range = range(max(p.length for by_data in pulses.values() for p in by_data.values()) + 1)

        # The bit rate's constants (Table 3-15) ---------------------------------------------------------------
        # What is read only while a counter runs (``clk_run``, ``end_run``, which have their reset) or after the
        # frame's load that sets it (``first_bit``, read under ``active``) is set where it starts: no reset.
        latched_end = Signal(reset_less=True)  # the last cycle end was a valid data cycle's latch: LaOuD, /LaInD
        clk_first, clk_end = Signal(clk_range), Signal(clk_range)
        ou_end, in_first, in_end, ends = (Signal(count_range, name=n) for n in ("ou_end", "in_first", "in_end", "ends"))
        last_clock = Signal(range(max(self.cpbs)))  # the bit period's last clock
        with m.Switch(self.rate):
            for rate, cpb in enumerate(self.cpbs):
                with m.Case(rate):
                    first, end = spec.clock_high(cpb)
                    data, other = pulses[cpb][True], pulses[cpb][False]
                    if data.la_ou_d is None or data.la_ou_d[0] != 0 or other.la_ou_d is not None:
                        raise ValueError("LaOuD must begin at a latched data cycle's end and only there (RX-4)")
                    comb += [clk_first.eq(first), clk_end.eq(end), last_clock.eq(cpb - 1)]
                    comb += [
                        ou_end.eq(data.la_ou_d[1]),
                        in_first.eq(Mux(latched_end, data.la_in_d_n[0], other.la_in_d_n[0])),
                        in_end.eq(Mux(latched_end, data.la_in_d_n[1], other.la_in_d_n[1])),
                        ends.eq(Mux(latched_end, data.length, other.length)),
                    ]

        # Data path through the chain (RX-2, RX-3) ------------------------------------------------------------
        active = self.active
        with m.If(self.load):
            sync += active.eq(self.ext & self.has_data & ~self.load_id)
        comb += self.send.eq(self.from_exr)
        to_exr = Signal(init=spec.IDLE.to_exr)
        clk_run = Signal()
        clk_count = Signal(clk_range, reset_less=True)
        first_bit = Signal(reset_less=True)  # no bit of this data cycle has gone out yet
        rises = Signal()  # this clock bit's ClkExR rises
        with m.If(self.load):
            sync += first_bit.eq(1)
        with m.If(clk_run):
            sync += clk_count.eq(clk_count + 1)
            with m.If(clk_count + 1 == clk_end):
                sync += clk_run.eq(0)
        with m.If(active & self.shift):
            sync += [to_exr.eq(self.level), clk_run.eq(1), clk_count.eq(0), first_bit.eq(0)]
        clk_exr = clk_run & (clk_count >= clk_first)

        # End pulses (RX-4) and /ResReg (RX-5) ----------------------------------------------------------------
        end_run = Signal()
        end_count = Signal(count_range, reset_less=True)  # whole bit periods since the end pulses began
        end_clock = Signal.like(last_clock, reset_less=True)  # clock within the bit period
        with m.If(end_run):
            sync += end_clock.eq(end_clock + 1)
            with m.If(end_clock == last_clock):
                sync += [end_clock.eq(0), end_count.eq(end_count + 1)]
                with m.If(end_count + 1 == ends):
                    sync += end_run.eq(0)
        with m.If(self.ext & self.ended):
            sync += [end_run.eq(1), end_count.eq(0), end_clock.eq(0), latched_end.eq(self.latched)]
        first_rise = Signal(reset_less=True)  # the data cycle's first ClkExR clock bit
        with m.If(active & self.shift):
            sync += first_rise.eq(first_bit)
        comb += rises.eq(clk_run & (clk_count == clk_first))
        comb += self.overrun.eq(rises & first_rise & end_run)

        levels: dict[str, Value] = {
            "clk_exr": clk_exr,
            "to_exr": to_exr,
            "la_ou_d": end_run & latched_end & (end_count < ou_end),
            "la_in_d_n": ~(end_run & (end_count >= in_first) & (end_count < in_end)),
        }
        comb += [getattr(self, name).eq(level) for name, level in levels.items()]
        return m

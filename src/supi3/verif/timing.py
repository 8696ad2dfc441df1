"""Timing checkers on pin traces: SPI master times (Table 3-4, manual 3.3.2) and serial register expansion times
(Table 3-15, manual 3.5).

Ref: IBS SUPI 3 OPC UM E rev. 05, 3.3.2 (Table 3-4, Figures 3-1 to 3-3) and 3.5 (Table 3-15, Figure 3-23). A
checker takes whole traces at the chip clock (numpy arrays of 32 MHz samples, as :meth:`supi3.top.Supi3Pins.run`
returns them) and returns every row missed, each as a :class:`TimingViolation` naming the table, the row's symbol
and explanation, the measured and the required value, the clock and the time. The limits are Table 3-4's and
Table 3-15's rows evaluated by :func:`supi3.timing.timing_table` for the bit rate; nothing here repeats a number.

The checkers measure; they do not compare with the schedules that generate the waveforms
(:mod:`supi3.serial_io`, :mod:`supi3.expansion`). Sample ``i`` of a trace is the level during clock ``i``; an
edge is at the start of the first clock showing the new level, and a time is the number of clocks between two such
first clocks divided by the clock frequency. How each row is measured where the manual's text is short is decided
in ``docs/assumptions/timing-checkers.md`` (TC-1 to TC-9).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Final

import numpy as np
import numpy.typing as npt

from supi3 import tables
from supi3.checks import check_choice, check_instance, check_int, check_trace, fail
from supi3.errors import Supi3Error
from supi3.timing import timing_table

__all__ = [
    "EXPANSION_PINS",
    "SAMPLE_POINT_ROW",
    "TimingViolation",
    "TraceTimingError",
    "check_expansion",
    "check_serial_io",
    "raise_first",
]

_EPSILON_S: Final = 1e-12
"""Tolerance of the comparisons (the evaluated limits are floats; 0.25 t0 + 100 ns is not a whole clock)."""

Trace = npt.NDArray[np.integer]
"""A trace as the checkers hold it (int64 after the argument checks)."""


def _mfp_pin(signal: str) -> int:
    return next(row.pin for row in tables.SPI_MASTER_MFP if row.signal == signal)


_CONV: Final = _mfp_pin("/Conv")
_SCLK: Final = _mfp_pin("SCLK")
_SS: Final = _mfp_pin("/SS")
_SER_OUT: Final = _mfp_pin("SerOut")
"""The MFP bits of Table 3-3 the serial I/O drives."""

EXPANSION_PINS: Final = ("clk_exr", "to_exr", "la_ou_d", "la_in_d_n", "res_reg_n")
"""The chip's register-expansion outputs (Table 3-14) :func:`check_expansion` reads from its ``traces``."""

SAMPLE_POINT_ROW: Final = "t1"
"""TC-8: the chip samples FromExR when ToExR changes, Table 3-15 t1 (0.25 t0) before the ClkExR rise; a FromExR
change before that point is judged by t3 (setup), one at or after it by t4 (hold)."""


@dataclass(frozen=True)
class TimingViolation:
    """One row of Table 3-4 or 3-15 missed on a trace.

    Attributes
    ----------
    table:
        ``"3-4"`` or ``"3-15"``.
    symbol:
        The row's symbol (``"t0"`` to ``"t12"``).
    explanation:
        The row's explanation, as the manual words it.
    measured_s:
        The time measured, in seconds (negative where the second edge came first, TC-6).
    required_s:
        The limit the row gives for the bit rate, in seconds.
    maximum:
        ``required_s`` is a maximum (Table 3-15 t4), else a minimum.
    clock:
        The clock at which the violation is seen: the later of the two edges measured (plus the checker's
        ``first_clock``).
    """

    table: str
    symbol: str
    explanation: str
    measured_s: float
    required_s: float
    maximum: bool
    clock: int

    @property
    def time_s(self) -> float:
        """:attr:`clock` in seconds at the chip clock (32 MHz)."""
        return self.clock / tables.CLOCK_HZ

    def __str__(self) -> str:
        bound = "<=" if self.maximum else ">="
        return (f"Table {self.table} {self.symbol} ({self.explanation}): measured {self.measured_s * 1e9:.2f} ns, "
                f"required {bound} {self.required_s * 1e9:.2f} ns at clock {self.clock} ({self.time_s * 1e6:.2f} µs)")


class TraceTimingError(Supi3Error, AssertionError):
    """A trace missed a timing table's row (raised by :func:`raise_first`).

    Attributes
    ----------
    violation:
        The first violation (lowest clock).
    violations:
        Every violation, by clock.
    """

    def __init__(self, violations: Sequence[TimingViolation]) -> None:
        self.violations = tuple(violations)
        self.violation = self.violations[0]
        more = len(self.violations) - 1
        super().__init__(str(self.violation) + (f" (and {more} more)" if more else ""))

    def __reduce__(self) -> tuple[type[TraceTimingError], tuple[tuple[TimingViolation, ...]]]:
        return type(self), (self.violations,)


def raise_first(violations: Iterable[TimingViolation]) -> None:
    """Raise :class:`TraceTimingError` for the first of ``violations`` (by clock) if there is any.

    Raises
    ------
    ArgumentError
        ``violations`` not an iterable (a string included), or an item of it not a :class:`TimingViolation`.
    TraceTimingError
        ``violations`` is not empty.
    """
    if isinstance(violations, str | bytes) or not isinstance(violations, Iterable):
        raise fail("violations", "an iterable of TimingViolation", violations)
    found = [check_instance("violation", v, TimingViolation) for v in violations]
    if found:
        raise TraceTimingError(sorted(found, key=lambda v: v.clock))


# ----------------------------------------------------------------------------------------------------------------
# Measuring
# ----------------------------------------------------------------------------------------------------------------

_EMPTY: Final = np.zeros(0, dtype=np.int64)


class _Rows:
    """One table evaluated for a bit rate, and the violations found so far."""

    def __init__(self, table: str, bit_rate: int, n_bytes: int, first_clock: int) -> None:
        self.table = table
        self.rows = {row.symbol: row for row in timing_table(table, bit_rate, n_bytes)}
        self.order = {symbol: k for k, symbol in enumerate(self.rows)}
        self.first_clock = first_clock
        self.found: list[TimingViolation] = []

    def minimum_s(self, symbol: str) -> float:
        value = self.rows[symbol].minimum_s
        assert value is not None, symbol
        return value

    def _add(self, symbol: str, clocks: Trace, at: Trace, bad: npt.NDArray[np.bool_], limit: float,
             maximum: bool) -> None:  # fmt: skip
        explanation = self.rows[symbol].explanation
        for measured, clock in zip(clocks[bad].tolist(), at[bad].tolist(), strict=True):
            self.found.append(TimingViolation(self.table, symbol, explanation, measured / tables.CLOCK_HZ, limit,
                                              maximum, clock + self.first_clock))

    def at_least(self, symbol: str, clocks: Trace, at: Trace) -> None:
        """Report every ``clocks[i]`` (measured up to clock ``at[i]``) below the row's minimum."""
        limit = self.minimum_s(symbol)
        self._add(symbol, clocks, at, clocks / tables.CLOCK_HZ + _EPSILON_S < limit, limit, False)

    def at_most(self, symbol: str, clocks: Trace, at: Trace) -> None:
        """Report every ``clocks[i]`` (measured up to clock ``at[i]``) above the row's maximum."""
        limit = self.rows[symbol].maximum_s
        assert limit is not None, symbol
        self._add(symbol, clocks, at, clocks / tables.CLOCK_HZ - _EPSILON_S > limit, limit, True)

    def result(self) -> list[TimingViolation]:
        return sorted(self.found, key=lambda v: (v.clock, self.order[v.symbol]))


def _changes(x: Trace) -> Trace:
    """The clocks whose level differs from the clock before (TC-1: clock 0 has no edge)."""
    return np.flatnonzero(x[1:] != x[:-1]) + 1


def _rises(x: Trace) -> Trace:
    return np.flatnonzero((x[1:] == 1) & (x[:-1] == 0)) + 1


def _pulses(x: Trace, active: int) -> tuple[Trace, Trace]:
    """(starts, ends) of the pulses at level ``active`` that start inside the trace (TC-1); the end is the first
    clock back at the other level, ``len(x)`` for a pulse still running at the trace's end."""
    edges = _changes(x)
    starts = edges[x[edges] == active]
    ends = edges[x[edges] != active]
    if ends.size and (not starts.size or ends[0] < starts[0]):
        ends = ends[1:]
    if ends.size < starts.size:
        ends = np.append(ends, len(x))
    return starts, ends


def _setup(changes: Trace, edges: Trace) -> tuple[Trace, Trace]:
    """For each edge with a change at or before it: (clocks since the last such change, the edge's clock)."""
    last = np.searchsorted(changes, edges, side="right") - 1
    has = last >= 0
    return edges[has] - changes[last[has]], edges[has]


def _hold(changes: Trace, edges: Trace) -> tuple[Trace, Trace]:
    """For each change after an edge: (clocks since the last edge before it, the change's clock)."""
    last = np.searchsorted(edges, changes, side="left") - 1
    has = last >= 0
    return changes[has] - edges[last[has]], changes[has]


def _after_pulse(events: Trace, starts: Trace, ends: Trace) -> tuple[Trace, Trace]:
    """For each event after a pulse started: (clocks from that pulse's end to the event, negative while the pulse
    still runs at the event (TC-6), the event's clock)."""
    last = np.searchsorted(starts, events, side="right") - 1
    has = last >= 0
    return events[has] - ends[last[has]], events[has]


def _traces(traces: object, names: Sequence[str], width: int) -> list[Trace]:
    if not isinstance(traces, Mapping):
        raise fail("traces", "a mapping of pin name to trace", traces)
    missing = [name for name in names if name not in traces]
    if missing:
        raise fail("traces", f"a mapping with the traces {', '.join(map(repr, names))} (without "
                             f"{', '.join(map(repr, missing))})", traces)
    found = [check_trace(f"traces[{name!r}]", traces[name], width) for name in names]
    return [_same_length(f"traces[{name!r}]", trace, len(found[0]), names[0])
            for name, trace in zip(names, found, strict=True)]


def _same_length(name: str, trace: Trace, length: int, reference: str) -> Trace:
    if len(trace) != length:
        raise fail(name, f"as long as {reference!r} ({length} clocks)", f"{len(trace)} clocks")
    return trace.astype(np.int64, copy=False)


def _input(name: str, trace: object, length: int, reference: str) -> Trace | None:
    if trace is None:
        return None
    return _same_length(name, check_trace(name, trace, 1), length, reference)


# ----------------------------------------------------------------------------------------------------------------
# Table 3-4: SPI master
# ----------------------------------------------------------------------------------------------------------------


def check_serial_io(traces: Mapping[str, object], *, bit_rate: int, bits: int, ser_in: object = None,
                    first_clock: int = 0) -> list[TimingViolation]:  # fmt: skip
    """Every Table 3-4 row the SPI master's pins miss in ``traces["mfp_out"]`` (3.3.2), by clock.

    A frame is a /SS low pulse; the SCLK rises in it (one in the clock /SS rises included) are its bits, counted
    from the first: rise ``i`` follows rise ``i - 1`` by t0 within a byte and by t9 (rising to rising) where a byte
    starts (``i`` a multiple of 8, TC-2). t1: /SS fall to the first rise; t2: the last rise to /SS rise; t8: /SS low
    (``n = bits / 8`` bytes, TC-3). SerOut: the last change at or before each rise at least t11 (first rise of a
    frame) or t12 (the others) before it, each change at least t3 after the rise before it; in every frame (TC-4).
    A frame after which /Conv falls before the next /SS fall is a write frame, any other a read frame (TC-5); t10:
    a read frame's /SS rise to the next frame's /SS fall when that is a write frame. SerIn (``ser_in``, MFP6 as a
    0/1 trace, optional): setup t4 and hold t5 around the rises of read frames. /Conv: t6 from the last /SS rise to
    its fall (negative if /SS is low then, TC-6), t7 its width.

    Parameters
    ----------
    traces:
        Pin traces by name; ``"mfp_out"`` (16-bit MFP levels) is read, other names are ignored.
    bit_rate:
        The INTERBUS bit rate (Table 1-7) the limits are evaluated for.
    bits:
        16 or 32, the transfer width of the mode (Tables 2-4 to 2-6); t8 takes ``n = bits / 8``.
    ser_in:
        SerIn levels (0/1), as long as ``mfp_out``, or None (t4 and t5 not checked).
    first_clock:
        The chip clock of sample 0 (reported clocks and times count from it).

    Raises
    ------
    ArgumentError
        A bit rate not of Table 1-7, ``bits`` not 16 or 32, a missing or malformed trace, traces of different
        lengths, ``first_clock`` not an integer >= 0.
    """
    check_choice("bit_rate", bit_rate, tables.BIT_RATES, "Table 1-7")
    check_choice("bits", bits, (16, 32), "Tables 2-4 to 2-6")
    first_clock = check_int("first_clock", first_clock, 0)
    (mfp,) = _traces(traces, ("mfp_out",), 16)
    serial_in = _input("ser_in", ser_in, len(mfp), "mfp_out")
    rows = _Rows("3-4", bit_rate, bits // 8, first_clock)
    length = len(mfp)
    conv, sclk, ss, ser_out = ((mfp >> pin) & 1 for pin in (_CONV, _SCLK, _SS, _SER_OUT))

    falls, ends = _pulses(ss, 0)
    rises = _rises(sclk)
    frame = np.searchsorted(falls, rises, side="right") - 1
    inside = frame >= 0
    inside[inside] = rises[inside] <= ends[frame[inside]]
    rises, frame = rises[inside], frame[inside]
    first = np.ones(rises.size, dtype=bool)
    first[1:] = frame[1:] != frame[:-1]
    last = np.ones(rises.size, dtype=bool)
    last[:-1] = first[1:]
    index = np.arange(rises.size) - np.searchsorted(frame, frame, side="left")

    rows.at_least("t1", rises[first] - falls[frame[first]], rises[first])
    later = ~first
    gaps = np.diff(rises)[later[1:]] if rises.size else _EMPTY
    byte_start = index[later] % 8 == 0
    rows.at_least("t0", gaps[~byte_start], rises[later][~byte_start])
    rows.at_least("t9", gaps[byte_start], rises[later][byte_start])
    closing = ends[frame[last]]
    done = closing < length
    rows.at_least("t2", closing[done] - rises[last][done], closing[done])
    ended = ends < length
    rows.at_least("t8", ends[ended] - falls[ended], ends[ended])

    out_changes = _changes(ser_out)
    for symbol, which in (("t11", first), ("t12", ~first)):
        rows.at_least(symbol, *_setup(out_changes, rises[which]))
    rows.at_least("t3", *_hold(out_changes, rises))

    conv_falls, conv_ends = _pulses(conv, 0)
    next_falls = np.append(falls[1:], length)[: falls.size]
    write = ended & (np.searchsorted(conv_falls, next_falls) > np.searchsorted(conv_falls, ends))
    read = ~write
    pair = read[:-1] & write[1:]
    rows.at_least("t10", falls[1:][pair] - ends[:-1][pair], falls[1:][pair])
    if serial_in is not None:
        sampled = rises[read[frame]]
        in_changes = _changes(serial_in)
        rows.at_least("t4", *_setup(in_changes, sampled))
        rows.at_least("t5", *_hold(in_changes, sampled))
    rows.at_least("t6", *_after_pulse(conv_falls, falls, ends))
    width = conv_ends < length
    rows.at_least("t7", conv_ends[width] - conv_falls[width], conv_ends[width])
    return rows.result()


# ----------------------------------------------------------------------------------------------------------------
# Table 3-15: serial register expansion
# ----------------------------------------------------------------------------------------------------------------


def check_expansion(traces: Mapping[str, object], *, bit_rate: int, from_exr: object = None,
                    first_clock: int = 0) -> list[TimingViolation]:  # fmt: skip
    """Every Table 3-15 row the register-expansion pins miss in ``traces`` (3.5), by clock.

    t0: ClkExR rise to rise. t1: the last ToExR change at or before each ClkExR rise at least t1 before it; t2:
    each ToExR change at least t2 after the rise before it. FromExR (``from_exr``, optional): a change at ``d``
    before the next ClkExR rise is judged against the sampling point t1 before the rise (TC-8): before it
    (``d`` > t1) it needs ``d`` >= t3 (setup), at or after it ``d`` <= t4 (hold, a maximum). t5: /LaInD low width;
    t6: LaOuD high width; t7: each /LaInD fall at least t7 after the end of the last LaOuD pulse (negative while
    LaOuD is high, TC-6); t8: /ResReg low width (TC-9: traces with expansion selected).

    Parameters
    ----------
    traces:
        Pin traces by name: :data:`EXPANSION_PINS` (0/1 each) are read, other names ignored.
    bit_rate:
        The INTERBUS bit rate (Table 1-7) the limits are evaluated for.
    from_exr:
        FromExR levels (0/1), as long as the outputs, or None (t3 and t4 not checked).
    first_clock:
        The chip clock of sample 0 (reported clocks and times count from it).

    Raises
    ------
    ArgumentError
        A bit rate not of Table 1-7, a missing or malformed trace, traces of different lengths, ``first_clock`` not
        an integer >= 0.
    """
    check_choice("bit_rate", bit_rate, tables.BIT_RATES, "Table 1-7")
    first_clock = check_int("first_clock", first_clock, 0)
    clk, to_exr, la_ou_d, la_in_d_n, res_reg_n = _traces(traces, EXPANSION_PINS, 1)
    serial_in = _input("from_exr", from_exr, len(clk), EXPANSION_PINS[0])
    rows = _Rows("3-15", bit_rate, 1, first_clock)
    length = len(clk)

    rises = _rises(clk)
    rows.at_least("t0", np.diff(rises), rises[1:])
    out_changes = _changes(to_exr)
    rows.at_least("t1", *_setup(out_changes, rises))
    rows.at_least("t2", *_hold(out_changes, rises))
    if serial_in is not None:
        in_changes = _changes(serial_in)
        following = np.searchsorted(rises, in_changes, side="left")
        has = following < rises.size
        before, at = rises[following[has]] - in_changes[has], in_changes[has]
        setup = before / tables.CLOCK_HZ > rows.minimum_s(SAMPLE_POINT_ROW) + _EPSILON_S
        rows.at_least("t3", before[setup], at[setup])
        rows.at_most("t4", before[~setup], at[~setup])

    for symbol, trace, active in (("t5", la_in_d_n, 0), ("t6", la_ou_d, 1), ("t8", res_reg_n, 0)):
        starts, ends = _pulses(trace, active)
        done = ends < length
        rows.at_least(symbol, ends[done] - starts[done], ends[done])
    in_falls, _ = _pulses(la_in_d_n, 0)
    rows.at_least("t7", *_after_pulse(in_falls, *_pulses(la_ou_d, 1)))
    return rows.result()

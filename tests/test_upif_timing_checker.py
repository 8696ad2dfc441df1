"""The Table 3-7 checker (:class:`supi3.spi.slave_pins.TimingChecker`) against generated waveforms.

IBS SUPI 3 OPC UM E rev. 05, 3.4.2, Table 3-7 ("Times for the synchronous serial interface (Intel and Motorola)").
The rows that limit the µP's signals are checked: t0 (SCLK period), t1, t2, t4 (setup), t5 (hold), t8 (/SS fall
after C/D changed), t10 (S/R valid before /SS falls), t11 (S/R changes after /SS rose) and t_SAS_INIT. TCLK is the
time base; t3, t6, t7 and t9 are the chip's own output timings (tests/test_upif_pins.py).

Hypothesis builds waveforms, at chip-clock resolution, whose every edge meets its limit exactly; one variant moves a
single edge by one clock so that exactly one limit is missed. The exact waveforms must pass without a report; each
variant must be reported, under its parameter's name and nothing else.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.config import decode
from supi3.model.registers import InterfaceViolationError, RegisterFile
from supi3.spi.slave_pins import PinsIn, PinsOut, SlavePins, TimingChecker, TimingViolationError
from supi3.tables import CLOCK_HZ
from supi3.timing import timing_table

RATES = (500_000, 2_000_000)
CHECKED = ("t0", "t1", "t2", "t4", "t5", "t8", "t10", "t11", "t_SAS_INIT")
"""The rows of Table 3-7 that limit the µP's signals."""
PINS = ("sas_init", "sclk", "ss_n", "mfp6", "mfp7", "c_d")


def minimum(rate: int, symbol: str) -> float:
    row = next(t for t in timing_table("3-7", rate) if t.symbol == symbol)
    assert row.minimum_s is not None
    return row.minimum_s


def clocks(rate: int, symbol: str) -> int:
    """The fewest whole clocks that meet ``symbol``'s minimum."""
    return math.ceil(minimum(rate, symbol) * CLOCK_HZ - 1e-6)


def test_every_row_is_either_checked_or_an_output_timing() -> None:
    symbols = {t.symbol for t in timing_table("3-7", 500_000)}
    assert symbols == {*CHECKED, "TCLK", "t3", "t6", "t7", "t9"}
    assert [clocks(500_000, s) for s in CHECKED] == [22, 4, 12, 4, 2, 4, 0, 0, 8]
    assert [clocks(2_000_000, s) for s in CHECKED] == [6, 1, 3, 4, 2, 1, 0, 0, 8]


@dataclass
class Wave:
    """Pin changes by cycle; later changes of a pin at the same cycle win."""

    changes: dict[str, dict[int, int]] = field(default_factory=lambda: {name: {} for name in PINS})

    def set(self, cycle: int, pin: str, value: int) -> None:
        assert cycle >= 1, cycle
        self.changes[pin][cycle] = value

    def rows(self, n: int) -> list[dict[str, int]]:
        level = {"sas_init": 0, "sclk": 1, "ss_n": 1, "mfp6": 0, "mfp7": 1, "c_d": 0}
        out = []
        for cycle in range(n):
            for pin in PINS:
                level[pin] = self.changes[pin].get(cycle, level[pin])
            out.append(dict(level))
        return out


@dataclass(frozen=True)
class Frame:
    bits: tuple[int, ...]
    s_r: int
    """Intel: the S/R level of this frame."""
    setup_exact: bool
    """Data changes exactly t4 before the rising edge (else exactly t5 after the one before)."""
    high: int
    """SCLK high time inside a period, clocks (the low time is the rest of t0)."""
    c_d_change: int | None
    """Clocks after /SS rose at which C/D changes (t6: 2 to 3 TCLK), or None."""
    gap: int
    """Without a C/D change: clocks from /SS rising to the next fall."""


@dataclass(frozen=True)
class Violation:
    symbol: str | None
    frame: int
    bit: int
    variant: int


def build(rate: int, intel: bool, frames: list[Frame], violation: Violation) -> tuple[list[dict[str, int]], int]:
    """The waveform: SAS_INIT, a C/D change, then the frames; returns the rows and the cycle count."""
    n = {symbol: clocks(rate, symbol) for symbol in CHECKED}
    wave = Wave()

    def missed(symbol: str, frame: int = -1) -> bool:
        return violation.symbol == symbol and frame in (violation.frame, -1)

    sas_rise = 5
    sas_fall = sas_rise + n["t_SAS_INIT"] - missed("t_SAS_INIT")
    wave.set(sas_rise, "sas_init", 1)
    wave.set(sas_fall, "sas_init", 0)
    c_d = 1
    wave.set(sas_fall + 3, "c_d", c_d)
    next_fall = sas_fall + 3 + n["t8"]
    s_r, data, previous_rise = 1, 0, 0
    for k, frame in enumerate(frames):
        fall = next_fall - int(missed("t8", k) and next_fall - 1 > previous_rise)
        wave.set(fall, "ss_n", 0)
        if intel and frame.s_r != s_r:
            # The new S/R level arrives with the /SS fall (t10 = 0) unless it came with the last rise (t11 = 0).
            at = fall + 1 if missed("t10", k) else fall if violation.variant % 2 or k == 0 else previous_rise
            wave.set(at, "mfp7", frame.s_r)
            s_r = frame.s_r
        first = fall + n["t1"]
        falls = [first + i * n["t0"] for i in range(8)]
        rises = [f + frame.high for f in falls]
        if missed("t0", k):
            rises[violation.bit] -= 1  # rising to rising edge one clock short
        if missed("t1", k):
            falls[0] -= 1
        for i in range(8):
            wave.set(falls[i], "sclk", 0)
            wave.set(rises[i], "sclk", 1)
            bit = frame.bits[i]
            if bit == data:
                continue
            at = rises[i] - n["t4"] if i == 0 or frame.setup_exact else rises[i - 1] + n["t5"]
            if missed("t4", k) and i == violation.bit:
                at = rises[i] - n["t4"] + 1
            if missed("t5", k) and i == violation.bit:
                at = rises[i - 1] + n["t5"] - 1
            wave.set(at, "mfp6", bit)
            data = bit
        rise = rises[7] + n["t2"] - missed("t2", k)
        wave.set(rise, "ss_n", 1)
        if intel and missed("t11", k):
            s_r = 1 - s_r
            wave.set(rise - 1, "mfp7", s_r)
        previous_rise = rise
        if frame.c_d_change is None:
            next_fall = rise + frame.gap
        else:
            change = rise + frame.c_d_change
            c_d = 1 - c_d
            wave.set(change, "c_d", c_d)
            next_fall = change + n["t8"]
    end = next_fall + 20
    return wave.rows(end), end


def check(rate: int, intel: bool, rows: list[dict[str, int]]) -> list[InterfaceViolationError]:
    found: list[InterfaceViolationError] = []
    checker = TimingChecker(rate, CLOCK_HZ, found.append)
    for cycle, row in enumerate(rows):
        pins = PinsIn(row["sas_init"], row["sclk"], row["ss_n"], row["mfp6"], row["mfp7"])
        out = PinsOut(io=0, io_oe=1, c_d=row["c_d"], c_d_oe=1, irq_n=1, irq_n_oe=1, mfp6=0, mfp6_oe=0, mfp7=0,
                      mfp7_oe=0)  # fmt: skip
        checker.check(cycle, pins, out, intel)
    return found


@st.composite
def scenarios(draw: st.DrawFn) -> tuple[int, bool, list[Frame], Violation]:
    rate = draw(st.sampled_from(RATES))
    intel = draw(st.booleans())
    t0 = clocks(rate, "t0")
    tclk = CLOCK_HZ // (16 * rate)
    count = draw(st.integers(1, 3))
    frames = [
        Frame(
            bits=tuple(draw(st.lists(st.integers(0, 1), min_size=8, max_size=8))),
            s_r=draw(st.integers(0, 1)),
            setup_exact=draw(st.booleans()),
            high=draw(st.integers(2, t0 - 2)),
            c_d_change=draw(st.none() | st.integers(2 * tclk, 3 * tclk)),
            gap=draw(st.integers(1, 30)),
        )
        for _ in range(count)
    ]
    symbols = [None, *(s for s in CHECKED if intel or s not in ("t10", "t11"))]
    symbol = draw(st.sampled_from(symbols))
    k = draw(st.integers(0, count - 1))
    bit = draw(st.integers(1, 7)) if symbol in ("t0", "t5") else draw(st.integers(0, 7))
    variant = draw(st.integers(0, 1))
    frame = frames[k]
    bits = list(frame.bits)
    previous = 0 if k == 0 and bit == 0 else (frames[k - 1].bits[7] if bit == 0 else bits[bit - 1])
    if symbol in ("t4", "t5"):
        bits[bit] = 1 - previous  # the violated edge is a data change
    if symbol == "t0":
        bits[bit] = previous  # no data change in the shortened period (t4 and t5 stay met)
    s_r = frame.s_r
    if symbol == "t10":
        s_r = 1 - (frames[k - 1].s_r if k else 1)  # S/R changes for this frame
    c_d_change = frame.c_d_change
    if symbol == "t8" and k > 0 and frames[k - 1].c_d_change is None:
        frames[k - 1] = replace(frames[k - 1], c_d_change=2 * tclk)
    frames[k] = replace(frame, bits=tuple(bits), s_r=s_r, c_d_change=c_d_change)
    return rate, intel, frames, Violation(symbol, k, bit, variant)


@settings(max_examples=400)
@given(scenarios())
def test_exact_waveforms_pass_and_one_clock_short_is_named(scenario: tuple[int, bool, list[Frame], Violation]) -> None:
    rate, intel, frames, violation = scenario
    rows, _ = build(rate, intel, frames, violation)
    found = check(rate, intel, rows)
    assert all(isinstance(v, TimingViolationError) for v in found)
    names = {v.parameter for v in found if isinstance(v, TimingViolationError)}
    expected = set() if violation.symbol is None else {violation.symbol}
    assert names == expected, (violation, [str(v) for v in found])
    for v in found:
        assert isinstance(v, TimingViolationError)
        assert v.required_s == minimum(rate, v.parameter)
        assert v.measured_s is None or v.measured_s < v.required_s
        assert f"Table 3-7 {v.parameter}" in str(v)


# ----------------------------------------------------------------------------------------------------------------
# Through the chip: /SS falling again before C/D has settled (t6, t8)
# ----------------------------------------------------------------------------------------------------------------


class Driver:
    """A µP on the pins of a real :class:`SlavePins` (Motorola, SCLK idling high)."""

    def __init__(self, rate: str) -> None:
        self.chip = SlavePins(RegisterFile(decode("10011", "1110", clk_conf=rate), strict=False))
        self.pins = PinsIn()
        self.outputs: list[PinsOut] = []

    def run(self, cycles: int, **changes: int) -> None:
        self.pins = PinsIn(**{**self.pins.__dict__, **changes})
        for _ in range(cycles):
            self.outputs.append(self.chip.tick(self.pins))

    def byte(self, value: int, gap: int) -> int:
        """One frame (MSB first), /SS high for ``gap`` clocks after it; returns the cycle /SS rose."""
        self.run(40, ss_n=0)
        for i in range(8):
            self.run(20, sclk=0, mfp6=(value >> (7 - i)) & 1)
            self.run(20, sclk=1)
        self.run(40)
        rose = len(self.outputs)
        self.run(gap, ss_n=1)
        return rose

    def timing(self) -> list[str]:
        return [v.parameter for v in self.chip.registers.violations.records if isinstance(v, TimingViolationError)]


COMMAND = 0x4C
"""A command byte after which the interface expects a data byte (C/D changes)."""


def _c_d_settles(rate: str) -> int:
    """Clocks from /SS rising after :data:`COMMAND` to C/D changing (t6: 2 to 3 TCLK)."""
    m = Driver(rate)
    m.byte(0x00, 40)  # the initialization byte (Motorola)
    rose = m.byte(COMMAND, 40)
    before = m.outputs[rose - 1].c_d
    return next(k for k, out in enumerate(m.outputs[rose:]) if out.c_d != before)


@pytest.mark.parametrize("rate", ["01", "11"])
def test_ss_falling_before_c_d_settled_is_t8(rate: str) -> None:
    tclk = CLOCK_HZ // (16 * decode("10011", "1110", clk_conf=rate).bit_rate)
    settle = _c_d_settles(rate)
    assert 2 * tclk <= settle <= 3 * tclk  # t6
    for gap in range(1, settle + tclk):
        m = Driver(rate)
        m.byte(0x00, 40)
        m.byte(COMMAND, gap)  # a command with a data byte to follow: C/D changes t6 after /SS rose
        m.run(40, ss_n=0)
        m.run(40, ss_n=1)
        assert m.timing() == ["t8"], (gap, m.timing())
    m = Driver(rate)
    m.byte(0x00, 40)
    m.byte(COMMAND, settle + tclk)
    m.run(40, ss_n=0)
    assert m.timing() == []


def test_sclk_rising_with_ss_is_t2() -> None:
    checker_rows = [{"sas_init": 0, "sclk": 1, "ss_n": 1, "mfp6": 0, "mfp7": 1, "c_d": 0} for _ in range(200)]
    for cycle in range(10, 59):
        checker_rows[cycle]["ss_n"] = 0
    for cycle in range(30, 59):
        checker_rows[cycle]["sclk"] = 0
    found = check(2_000_000, False, checker_rows)  # SCLK and /SS rise together in cycle 59
    assert [v.parameter for v in found if isinstance(v, TimingViolationError)] == ["t2"]

"""The trace timing checkers of :mod:`supi3.verif.timing`: Table 3-4 (SPI master, 3.3.2) and Table 3-15 (serial
register expansion, 3.5).

The good waveforms are the spec's own: :func:`supi3.spi.serial_io.render` of the sequences and
:func:`supi3.expansion.clock_high` / :func:`~supi3.expansion.end_pulses`, so a clean check also proves the spec meets
the tables at both bit rates. Hypothesis strings such pieces together with every gap at its limit (SerIn and FromExR
changes exactly at their setup or hold limit), and one variant moves a single edge by one clock so that exactly one
row is missed: the exact waveform must pass, the variant must be reported under that row's symbol and no other.
"""

from __future__ import annotations

import itertools
import math
import pickle
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3 import expansion
from supi3.config import DataDirection
from supi3.errors import ArgumentError
from supi3.interbus import wire
from supi3.spi import serial_io
from supi3.tables import CLOCK_HZ
from supi3.timing import EvaluatedTiming, timing_table
from supi3.verif import TimingViolation, TraceTimingError, check_expansion, check_serial_io, raise_first

RATES = (500_000, 2_000_000)
MODES = (DataDirection.IN, DataDirection.OUT, DataDirection.IN_OUT)
Array = npt.NDArray[np.int64]


def row(table: str, rate: int, symbol: str, bits: int = 16) -> EvaluatedTiming:
    return next(t for t in timing_table(table, rate, bits // 8) if t.symbol == symbol)


def at_least(table: str, rate: int, symbol: str, bits: int = 16) -> int:
    """The fewest whole clocks that meet the row's minimum."""
    minimum = row(table, rate, symbol, bits).minimum_s
    assert minimum is not None
    return math.ceil(minimum * CLOCK_HZ - 1e-6)


def at_most(table: str, rate: int, symbol: str) -> int:
    """The most whole clocks that meet the row's maximum."""
    maximum = row(table, rate, symbol).maximum_s
    assert maximum is not None
    return math.floor(maximum * CLOCK_HZ + 1e-6)


def test_limits_in_clocks() -> None:
    """The rows the waveforms below sit on, in 32 MHz clocks (t10 = 50.5 t0 is not whole: 404 and 1616)."""
    assert [at_least("3-4", r, "t0") for r in RATES] == [32, 8]
    assert [at_least("3-4", r, "t10") for r in RATES] == [1616, 404]
    assert [at_least("3-4", r, s) for r in RATES for s in ("t4", "t5")] == [4, 2, 4, 2]
    assert [at_least("3-4", 2_000_000, "t8", bits) for bits in (16, 32)] == [144, 288]
    assert [at_least("3-15", r, "t3") for r in RATES] == [20, 8]
    assert [at_most("3-15", r, "t4") for r in RATES] == [14, 2]


# ----------------------------------------------------------------------------------------------------------------
# Table 3-4: waveforms from serial_io.render
# ----------------------------------------------------------------------------------------------------------------

SPI_ROWS = tuple(f"t{k}" for k in range(13))


@dataclass
class SpiWave:
    """MFP3..MFP7 by clock, and where the frames of the rendered pieces sit."""

    conv: list[int] = field(default_factory=list)
    sclk: list[int] = field(default_factory=list)
    ss: list[int] = field(default_factory=list)
    out: list[int] = field(default_factory=list)
    frames: list[tuple[int, serial_io.SerialFrame, int]] = field(default_factory=list)
    """(offset, frame, word): the frame's cycles are offset + its own; word is SerOut's (write) or SerIn's (read)."""
    convs: list[tuple[int, int]] = field(default_factory=list)

    def idle(self, cycles: int) -> None:
        self.add(serial_io.IDLE, cycles)

    def add(self, levels: serial_io.Levels, cycles: int = 1) -> None:
        self.conv += [levels.conv_n] * cycles
        self.sclk += [levels.sclk] * cycles
        self.ss += [levels.ss_n] * cycles
        self.out += [levels.ser_out] * cycles

    def piece(self, seq: serial_io.SerialSequence, word: int) -> None:
        offset = len(self.ss)
        for levels in serial_io.render(seq, word if seq.write else 0):
            self.add(levels)
        self.frames += [(offset, frame, word) for frame in seq.frames]
        if seq.conv is not None:
            self.convs.append((offset + seq.conv[0], offset + seq.conv[1]))

    def arrays(self) -> tuple[Array, Array, Array, Array]:
        def array(levels: list[int]) -> Array:
            return np.array(levels, dtype=np.int64)

        return array(self.conv), array(self.sclk), array(self.ss), array(self.out)


def mfp(conv: Array, sclk: Array, ss: Array, out: Array) -> Array:
    bit = serial_io.Levels
    return (conv * bit(1, 0, 0, 0).mfp() + sclk * bit(0, 1, 0, 0).mfp() + ss * bit(0, 0, 1, 0).mfp()
            + out * bit(0, 0, 0, 1).mfp())


def frame_rises(sclk: Array, offset: int, frame: serial_io.SerialFrame) -> list[int]:
    """The SCLK rises of a frame as the (possibly mutated) trace has them."""
    fall, end = offset + frame.start, offset + frame.end
    return [c for c in range(fall + 1, end + 1) if sclk[c] and not sclk[c - 1]]


def ser_in_trace(rate: int, sclk: Array, wave: SpiWave, setup_exact: list[bool],
                 moved: tuple[int, int, int] | None) -> Array:  # fmt: skip
    """SerIn for the read frames: bit j changes exactly t4 before rise j or exactly t5 after rise j - 1; back to 0
    exactly t5 after the last rise. ``moved`` = (frame, bit, clocks): that change moved by clocks."""
    setup, hold = at_least("3-4", rate, "t4"), at_least("3-4", rate, "t5")
    level = np.zeros(len(sclk), dtype=np.int64)
    for k, (offset, frame, word) in enumerate(wave.frames):
        if frame.write:
            continue
        rises = frame_rises(sclk, offset, frame)
        bits = [(word >> (frame.bits - 1 - j)) & 1 for j in range(len(rises))]
        for j, rise in enumerate(rises):
            at = rise - setup if j == 0 or setup_exact[k % len(setup_exact)] else rises[j - 1] + hold
            if moved is not None and moved[:2] == (k, j):
                at += moved[2]
            level[at:] = bits[j]
        level[rises[-1] + hold:] = 0
    return level


@st.composite
def spi_scenarios(draw: st.DrawFn) -> tuple[int, int, list[tuple[str, int]], str | None, int, int, int]:
    """(rate, bits, pieces, symbol, piece, bit, choice): pieces are ("read" | "write", word)."""
    rate = draw(st.sampled_from(RATES))
    bits = draw(st.sampled_from((16, 32)))
    directions = draw(st.lists(st.sampled_from(MODES), min_size=1, max_size=3))
    symbol = draw(st.sampled_from((None, *SPI_ROWS)))
    directions.append(DataDirection.IN_OUT)  # every row has a frame to miss it in
    words = st.integers(0, (1 << bits) - 1)
    pieces: list[tuple[str, int]] = []
    for direction in directions:
        if direction is not DataDirection.OUT:
            pieces.append(("read", draw(words)))
        if direction is not DataDirection.IN:
            pieces.append(("write", draw(words)))
    kinds = {"t3": "write", "t6": "write", "t7": "write", "t11": "write", "t12": "write", "t4": "read",
             "t5": "read", "t10": "write"}
    if symbol == "t10":
        candidates = [k for k in range(1, len(pieces)) if pieces[k][0] == "write" and pieces[k - 1][0] == "read"]
    else:
        candidates = [k for k, (kind, _) in enumerate(pieces) if kinds.get(symbol or "", kind) == kind]
    piece = draw(st.sampled_from(candidates))
    if symbol in ("t0",):
        bit = draw(st.sampled_from([j for j in range(1, bits) if j % 8]))
    elif symbol == "t9":
        bit = draw(st.sampled_from(range(8, bits, 8)))
    elif symbol in ("t3", "t5", "t12"):
        bit = draw(st.sampled_from([j for j in range(1, bits) if j % 8 or symbol != "t3"]))
    elif symbol == "t4":
        bit = draw(st.integers(0, bits - 1))
    else:
        bit = 0
    choice = draw(st.integers(0, 1 << 16))
    return rate, bits, pieces, symbol, piece, bit, choice


def force_bit(word: int, bits: int, j: int, value: int) -> int:
    shift = bits - 1 - j
    return (word & ~(1 << shift)) | (value << shift)


def bit_of(word: int, bits: int, j: int) -> int:
    return (word >> (bits - 1 - j)) & 1 if j >= 0 else 0


def build_spi(rate: int, bits: int, pieces: list[tuple[str, int]], symbol: str | None, target: int, j: int,
              choice: int) -> tuple[Array, Array]:  # fmt: skip
    """mfp_out and SerIn of the pieces, every limit met exactly, with ``symbol`` missed by one clock."""
    pieces = list(pieces)
    kind, word = pieces[target]
    # A moved SCLK rise must not move a data change with it; a moved data change must be a change.
    if symbol in ("t0", "t9", "t1") and kind == "write":
        word = force_bit(word, bits, j, bit_of(word, bits, j - 1))
    if symbol in ("t3", "t12", "t11", "t4", "t5"):
        word = force_bit(word, bits, j, 1 - bit_of(word, bits, j - 1))
    pieces[target] = (kind, word)
    wave = SpiWave()
    wave.idle(3)
    t10 = at_least("3-4", rate, "t10", bits)
    for k, (kind, word) in enumerate(pieces):
        if k and kind == "write" and pieces[k - 1][0] == "read":
            wave.idle(t10 - (symbol == "t10" and k == target))
        elif k:
            wave.idle(1 + (choice >> k) % 20)
        direction = DataDirection.IN if kind == "read" else DataDirection.OUT
        wave.piece(serial_io.sequence(direction, bits, rate), word)
    wave.idle(40)
    conv, sclk, ss, out = wave.arrays()
    offset, frame, _ = wave.frames[target]  # one frame per piece
    t0 = frame.t0
    moved = None
    if symbol in ("t0", "t9", "t1"):
        sclk[offset + frame.rising(j) - 1] = 1
    elif symbol == "t2":
        sclk[offset + frame.rising(bits - 1)] = 0
    elif symbol == "t8":
        last = offset + frame.rising(bits - 1)
        sclk[last:last + t0 // 2] = 0
        ss[offset + frame.end - 1] = 1
    elif symbol == "t3":
        out[offset + frame.slot(j) - 1] = 1 - out[offset + frame.slot(j) - 1]
    elif symbol in ("t11", "t12"):
        out[offset + frame.slot(j)] = 1 - out[offset + frame.slot(j)]
    elif symbol in ("t6", "t7"):
        first, end = wave.convs[sum(1 for _, f, _ in wave.frames[:target] if f.write)]
        if symbol == "t6":
            conv[first - 1] = 0
        else:
            conv[end - 1] = 1
    elif symbol == "t4":
        moved = (target, j, 1)
    elif symbol == "t5":
        moved = (target, j, -1)
    setup_exact = [bool((choice >> k) & 1) for k in range(len(pieces))]
    if symbol == "t4":
        setup_exact[target] = True
    if symbol == "t5":
        setup_exact[target] = False
    return mfp(conv, sclk, ss, out), ser_in_trace(rate, sclk, wave, setup_exact, moved)


@pytest.mark.slow
@settings(max_examples=300, deadline=None)
@given(spi_scenarios())
def test_serial_io_exact_waveforms_pass_and_one_clock_short_is_named(
        scenario: tuple[int, int, list[tuple[str, int]], str | None, int, int, int]) -> None:
    rate, bits, pieces, symbol, target, j, choice = scenario
    mfp_out, ser_in = build_spi(rate, bits, pieces, symbol, target, j, choice)
    found = check_serial_io({"mfp_out": mfp_out}, bit_rate=rate, bits=bits, ser_in=ser_in)
    expected = [] if symbol is None else [symbol]
    assert [v.symbol for v in found] == expected, [str(v) for v in found]
    for v in found:
        assert v.table == "3-4"
        assert v.required_s == row("3-4", rate, v.symbol, bits).minimum_s
        assert v.measured_s < v.required_s
        assert v.required_s - v.measured_s <= 1 / CLOCK_HZ + 1e-12  # one clock short
        assert str(v).startswith(f"Table 3-4 {v.symbol} (")


@pytest.mark.parametrize("symbol", [None, *SPI_ROWS])
@pytest.mark.parametrize("rate", RATES)
def test_serial_io_each_row_once_per_rate(rate: int, symbol: str | None) -> None:
    """The property's cases, one per row (fast tier): a 32-bit IN/OUT sequence and a 16-bit OUT one."""
    bits = 32
    pieces = [("read", 0x8421_F00F), ("write", 0xA5C3_0F96)]
    target = 0 if symbol in ("t4", "t5") else 1
    j = {"t0": 5, "t9": 16, "t3": 3, "t12": 9, "t4": 12, "t5": 13}.get(symbol or "", 0)
    mfp_out, ser_in = build_spi(rate, bits, pieces, symbol, target, j, 12345)
    found = check_serial_io({"mfp_out": mfp_out}, bit_rate=rate, bits=bits, ser_in=ser_in)
    assert [v.symbol for v in found] == ([] if symbol is None else [symbol]), [str(v) for v in found]


def device_ser_in(mfp_out: Array, word_bits: list[int]) -> Array:
    """A 74HCT165-style answer, PERIPHERAL_DELAY_CLOCKS after the edges: the first bit after /SS falls, the next
    after each SCLK rise; 0 while /SS is high."""
    delay = serial_io.PERIPHERAL_DELAY_CLOCKS
    ss = (mfp_out >> 5) & 1
    sclk = (mfp_out >> 4) & 1
    level = np.zeros(len(mfp_out), dtype=np.int64)
    bits = itertools.cycle(word_bits)
    current = 0
    for c in range(1, len(mfp_out) - delay):
        if ss[c] and not ss[c - 1]:
            current = 0
        elif (not ss[c] and ss[c - 1]) or (not ss[c] and sclk[c] and not sclk[c - 1]):
            current = next(bits)
        level[c + delay] = current
    return level


@pytest.mark.parametrize("bits", [16, 32])
@pytest.mark.parametrize("direction", MODES)
@pytest.mark.parametrize("rate", RATES)
def test_the_spec_meets_table_3_4(rate: int, direction: DataDirection, bits: int) -> None:
    """Every mode's sequence (and the clear sequence after a reset, SM-9) back to back, with a device answering
    SerIn PERIPHERAL_DELAY_CLOCKS after each edge (SM-10): no row of Table 3-4 missed."""
    wave = SpiWave()
    wave.idle(2)
    for word in (0, (1 << bits) - 1, 0x5A5A_A5A5 & ((1 << bits) - 1)):
        wave.piece(serial_io.sequence(direction, bits, rate), word)
        wave.idle(1)
    clear = serial_io.clear_sequence(direction, bits, rate)
    if clear is not None:
        wave.piece(clear, 0)
    wave.idle(10)
    mfp_out = mfp(*wave.arrays())
    ser_in = device_ser_in(mfp_out, [1, 0, 0, 1, 1, 1, 0, 1, 0])
    assert check_serial_io({"mfp_out": mfp_out}, bit_rate=rate, bits=bits, ser_in=ser_in) == []


@pytest.mark.parametrize("rate", RATES)
def test_the_spec_t10_margin(rate: int) -> None:
    """The only row the spec does not meet exactly: t10 = 51 t0 (SM-7) against 50.5 t0, half a t0 to spare."""
    seq = serial_io.sequence(DataDirection.IN_OUT, 16, rate)
    read, write = seq.frames
    t0 = serial_io.t0_clocks(rate)
    assert write.start - read.end == at_least("3-4", rate, "t10") + t0 // 2


# ----------------------------------------------------------------------------------------------------------------
# Table 3-15: waveforms from expansion.clock_high and expansion.end_pulses
# ----------------------------------------------------------------------------------------------------------------

EXPANSION_ROWS = tuple(f"t{k}" for k in range(9))


@dataclass
class ExpCycle:
    data: bytes
    gaps: tuple[int, ...]
    """Bit periods between bytes (0: back to back)."""
    latched: bool
    from_exr: bytes


def build_expansion(rate: int, cycles: list[ExpCycle], symbol: str | None, target: int, k: int,
                    setup_exact: bool) -> tuple[dict[str, Array], Array]:  # fmt: skip
    """The pins of the cycles, each followed by its end pulses and a /ResReg pulse at the end; every limit met
    exactly, ``symbol`` missed by one clock in cycle ``target`` (bit ``k``)."""
    cpb = wire.clocks_per_bit(rate)
    high = expansion.clock_high(cpb)
    setup, hold = at_least("3-15", rate, "t3"), at_most("3-15", rate, "t4")
    pulses = [expansion.end_pulses(c.latched, cpb) for c in cycles]
    total = 10 + sum(8 * len(c.data) * cpb + sum(c.gaps) * cpb + cpb + p.length + 5
                     for c, p in zip(cycles, pulses, strict=True))
    total += 8 * cpb
    pins = {name: np.zeros(total, dtype=np.int64) for name in ("clk_exr", "to_exr", "la_ou_d", "la_in_d_n",
                                                                "res_reg_n")}
    pins["la_in_d_n"][:] = 1
    pins["res_reg_n"][:] = 1
    from_exr = np.zeros(total, dtype=np.int64)
    cursor = 10
    for n, (cycle, ends) in enumerate(zip(cycles, pulses, strict=True)):
        here = n == target
        starts: list[int] = []
        for b in range(len(cycle.data)):
            if b:
                cursor += cycle.gaps[b - 1] * cpb
            starts += range(cursor, cursor + 8 * cpb, cpb)
            cursor += 8 * cpb
        bits = [(byte >> (7 - i)) & 1 for byte in cycle.data for i in range(8)]
        rises = [s + high[0] for s in starts]
        if here and symbol == "t0":
            rises[k] -= 1
        for s, r in zip(starts, rises, strict=True):
            pins["clk_exr"][r:s + high[1]] = 1
        for i, s in enumerate(starts):
            at = s + (here and symbol == "t1" and i == k) - (here and symbol == "t2" and i == k)
            pins["to_exr"][at:] = bits[i]
        if starts:
            pins["to_exr"][starts[-1] + cpb:] = 0
        answer = [(byte >> (7 - i)) & 1 for byte in cycle.from_exr for i in range(8)]
        for i, r in enumerate(rises):
            at = r - setup if i == 0 or setup_exact else rises[i - 1] - hold
            if here and i == k:
                at += 1 if symbol == "t3" else -1 if symbol == "t4" else 0
            from_exr[at:] = answer[i]
        if rises:
            from_exr[rises[-1] - hold:] = 0
        end = cursor + cpb
        if ends.la_ou_d is not None:
            first, last = end + ends.la_ou_d[0], end + ends.la_ou_d[1] - (here and symbol == "t6")
            pins["la_ou_d"][first:last] = 1
        first = end + ends.la_in_d_n[0] - (here and symbol == "t7")
        last = end + ends.la_in_d_n[1] - (here and symbol == "t5")
        pins["la_in_d_n"][first:last] = 0
        cursor = end + ends.length + 5
    width = expansion.PULSE_T0 * cpb - (symbol == "t8")
    pins["res_reg_n"][cursor:cursor + width] = 0
    return pins, from_exr


@st.composite
def expansion_scenarios(draw: st.DrawFn) -> tuple[int, list[ExpCycle], str | None, int, int, bool]:
    rate = draw(st.sampled_from(RATES))
    symbol = draw(st.sampled_from((None, *EXPANSION_ROWS)))
    count = draw(st.integers(1, 3))
    cycles = []
    for _ in range(count):
        size = draw(st.integers(0 if symbol is None else 1, 4))
        cycles.append(ExpCycle(data=draw(st.binary(min_size=size, max_size=size)),
                               gaps=tuple(draw(st.lists(st.integers(0, 5), min_size=3, max_size=3))),
                               latched=draw(st.booleans()),
                               from_exr=draw(st.binary(min_size=size, max_size=size))))
    target = draw(st.integers(0, count - 1))
    cycle = cycles[target]
    k = draw(st.integers(0 if symbol == "t1" else 1, 8 * len(cycle.data) - 1)) if cycle.data else 0
    if symbol in ("t0", "t2") and cycle.data:
        k = draw(st.sampled_from([i for i in range(1, 8 * len(cycle.data)) if i % 8]))
    return rate, cycles, symbol, target, k, draw(st.booleans())


def prepare(cycles: list[ExpCycle], symbol: str | None, target: int, k: int) -> None:
    """Make the bits around the edge a mutation moves fit it: a moved ClkExR rise moves no ToExR change with it,
    a moved ToExR or FromExR change is a change; LaOuD exists where t6 or t7 is missed."""
    cycle = cycles[target]
    if symbol in ("t6", "t7"):
        cycle.latched = True
    line = [(b >> (7 - i)) & 1 for b in cycle.data for i in range(8)]
    answer = [(b >> (7 - i)) & 1 for b in cycle.from_exr for i in range(8)]
    if symbol == "t0":
        line[k] = line[k - 1]
    if symbol in ("t1", "t2"):
        line[k] = 1 - (line[k - 1] if k else 0)
    if symbol in ("t3", "t4"):
        answer[k] = 1 - (answer[k - 1] if k else 0)
    cycle.data = _pack(line)
    cycle.from_exr = _pack(answer)


def _pack(bits: list[int]) -> bytes:
    return bytes(int("".join(map(str, bits[i:i + 8])), 2) for i in range(0, len(bits), 8))


def expansion_case(scenario: tuple[int, list[ExpCycle], str | None, int, int, bool]) -> None:
    rate, cycles, symbol, target, k, setup_exact = scenario
    prepare(cycles, symbol, target, k)
    setup_exact = {"t3": True, "t4": False}.get(symbol or "", setup_exact)
    pins, from_exr = build_expansion(rate, cycles, symbol, target, k, setup_exact)
    found = check_expansion(pins, bit_rate=rate, from_exr=from_exr)
    assert [v.symbol for v in found] == ([] if symbol is None else [symbol]), [str(v) for v in found]
    for v in found:
        assert v.table == "3-15"
        limits = row("3-15", rate, v.symbol)
        assert v.maximum == (v.symbol == "t4")
        assert v.required_s == (limits.maximum_s if v.maximum else limits.minimum_s)
        assert abs(v.measured_s - v.required_s) <= 1 / CLOCK_HZ + 1e-12


@pytest.mark.slow
@settings(max_examples=300, deadline=None)
@given(expansion_scenarios())
def test_expansion_exact_waveforms_pass_and_one_clock_short_is_named(
        scenario: tuple[int, list[ExpCycle], str | None, int, int, bool]) -> None:
    expansion_case(scenario)


@pytest.mark.parametrize("symbol", [None, *EXPANSION_ROWS])
@pytest.mark.parametrize("rate", RATES)
def test_expansion_each_row_once_per_rate(rate: int, symbol: str | None) -> None:
    """The property's cases, one per row (fast tier); also the spec's pulses and ClkExR meet Table 3-15."""
    cycles = [ExpCycle(bytes([0x14, 0x56, 0x78]), (0, 5, 0), True, bytes([0x78, 0xA5, 0x0F])),
              ExpCycle(b"", (0, 0, 0), False, b""),
              ExpCycle(bytes([0x5A, 0x3C]), (3, 0, 0), True, bytes([0xC3, 0x96]))]
    k = {"t0": 9, "t1": 1, "t2": 3, "t3": 5, "t4": 6}.get(symbol or "", 0)
    expansion_case((rate, cycles, symbol, 0, k, True))


# ----------------------------------------------------------------------------------------------------------------
# Reports and arguments
# ----------------------------------------------------------------------------------------------------------------


def test_a_violation_reads_like_the_table_3_7_checker() -> None:
    v = TimingViolation("3-4", "t1", row("3-4", 2_000_000, "t1").explanation, 7 / CLOCK_HZ,
                        250e-9, False, 1234)
    assert str(v) == ("Table 3-4 t1 (Negative edge of /SS before positive edge of SCLK): measured 218.75 ns, "
                      "required >= 250.00 ns at clock 1234 (38.56 µs)")
    assert v.time_s == 1234 / CLOCK_HZ


def test_clock_and_time_count_from_first_clock() -> None:
    mfp_out, _ = build_spi(2_000_000, 16, [("write", 0xFFFF)], "t1", 0, 0, 0)
    (v,) = check_serial_io({"mfp_out": mfp_out}, bit_rate=2_000_000, bits=16)
    (w,) = check_serial_io({"mfp_out": mfp_out}, bit_rate=2_000_000, bits=16, first_clock=1000)
    assert w.clock == v.clock + 1000
    assert v.measured_s == 7 / CLOCK_HZ
    assert "required >= 250.00 ns" in str(v)
    # The later edge: the early SCLK rise.
    assert mfp_out[v.clock] >> 4 & 1 and not mfp_out[v.clock - 1] >> 4 & 1


def test_raise_first() -> None:
    raise_first([])
    a = TimingViolation("3-15", "t4", "x", 3e-9, 2e-9, True, 50)
    b = TimingViolation("3-15", "t1", "y", 1e-9, 2e-9, False, 7)
    with pytest.raises(TraceTimingError) as info:
        raise_first([a, b])
    assert info.value.violation == b
    assert str(info.value) == f"{b} (and 1 more)"
    assert "required <= 2.00 ns" in str(a)
    copy = pickle.loads(pickle.dumps(info.value))
    assert copy.violations == (b, a)
    with pytest.raises(ArgumentError, match="violation must be a TimingViolation"):
        raise_first(["t1"])  # type: ignore[list-item]


def test_a_trace_starting_inside_a_pulse_is_measured_from_its_first_edge() -> None:
    """TC-1: a pulse already running at sample 0 and one still running at the end have no width to check."""
    mfp_out, _ = build_spi(2_000_000, 16, [("write", 0x1234)], None, 0, 0, 0)
    cut = int(np.flatnonzero((mfp_out >> 5) & 1 == 0)[3])
    assert check_serial_io({"mfp_out": mfp_out[cut:]}, bit_rate=2_000_000, bits=16) == []
    assert check_serial_io({"mfp_out": mfp_out[:cut]}, bit_rate=2_000_000, bits=16) == []


GOOD = {"mfp_out": np.zeros(4, dtype=np.int64)}
GOOD_EXP = {name: np.zeros(4, dtype=np.int64) for name in ("clk_exr", "to_exr", "la_ou_d", "la_in_d_n",
                                                           "res_reg_n")}


@pytest.mark.parametrize(("call", "message"), [
    (lambda: check_serial_io(GOOD, bit_rate=1_000_000, bits=16), "bit_rate must be one of"),
    (lambda: check_serial_io(GOOD, bit_rate=500_000, bits=24), "bits must be one of 16, 32"),
    (lambda: check_serial_io(GOOD, bit_rate=500_000, bits=True), "bits must be one of"),
    (lambda: check_serial_io([1, 2], bit_rate=500_000, bits=16), "traces must be a mapping"),  # type: ignore[arg-type]
    (lambda: check_serial_io({}, bit_rate=500_000, bits=16), "traces must be a mapping with the traces 'mfp_out'"),
    (lambda: check_serial_io({"mfp_out": [1 << 16]}, bit_rate=500_000, bits=16), r"traces\['mfp_out'\]\[0\] must"),
    (lambda: check_serial_io({"mfp_out": [0.5]}, bit_rate=500_000, bits=16), r"traces\['mfp_out'\] must be a 1-D"),
    (lambda: check_serial_io(GOOD, bit_rate=500_000, bits=16, ser_in=[0, 1, 2, 0]), r"ser_in\[2\] must"),
    (lambda: check_serial_io(GOOD, bit_rate=500_000, bits=16, ser_in=[0, 1]), "ser_in must be as long as 'mfp_out'"),
    (lambda: check_serial_io(GOOD, bit_rate=500_000, bits=16, first_clock=-1), "first_clock must be an integer"),
    (lambda: check_expansion(GOOD, bit_rate=500_000), "without 'clk_exr', 'to_exr'"),
    (lambda: check_expansion({**GOOD_EXP, "to_exr": np.zeros(3, dtype=np.int64)}, bit_rate=500_000),
     r"traces\['to_exr'\] must be as long as 'clk_exr' \(4 clocks\)"),
    (lambda: check_expansion({**GOOD_EXP, "la_ou_d": [0, 2, 0, 0]}, bit_rate=500_000), r"traces\['la_ou_d'\]\[1\]"),
    (lambda: check_expansion(GOOD_EXP, bit_rate=500_000, from_exr="0101"), "from_exr must be a 1-D"),
    (lambda: check_expansion(GOOD_EXP, bit_rate="500k"), "bit_rate must be one of"),  # type: ignore[arg-type]
])  # fmt: skip
def test_hostile_arguments_give_named_errors(call: object, message: str) -> None:
    assert callable(call)
    with pytest.raises(ArgumentError, match=message):
        call()


def test_conv_inside_a_frame_is_t6_measured_negative() -> None:
    """TC-6: /Conv falling while /SS is still low is the worst t6, measured to the frame's /SS rise."""
    rate = 2_000_000
    wave = SpiWave()
    wave.idle(3)
    wave.piece(serial_io.sequence(DataDirection.OUT, 16, rate), 0x0F0F)
    wave.idle(20)
    conv, sclk, ss, out = wave.arrays()
    (offset, frame, _), ((first, end),) = wave.frames[0], wave.convs
    conv[first:end] = 1
    conv[offset + 20:offset + 28] = 0
    found = check_serial_io({"mfp_out": mfp(conv, sclk, ss, out), "other": [5]}, bit_rate=rate, bits=16)
    assert [(v.symbol, v.clock) for v in found] == [("t6", offset + 20)]
    assert found[0].measured_s == (offset + 20 - (offset + frame.end)) / CLOCK_HZ < 0


def test_la_in_d_falling_while_la_ou_d_is_high_is_t7_measured_negative() -> None:
    rate = 500_000
    cpb = wire.clocks_per_bit(rate)
    ends = expansion.end_pulses(True, cpb)
    assert ends.la_ou_d is not None
    pins = {name: np.zeros(20 * cpb, dtype=np.uint8) for name in ("clk_exr", "to_exr", "la_ou_d", "res_reg_n")}
    pins["res_reg_n"][:] = 1
    pins["la_ou_d"][10 + ends.la_ou_d[0]:10 + ends.la_ou_d[1]] = 1
    la_in = np.ones(20 * cpb, dtype=np.uint8)
    fall = 10 + ends.la_ou_d[1] - 3
    la_in[fall:fall + expansion.PULSE_T0 * cpb] = 0
    found = check_expansion({**pins, "la_in_d_n": la_in}, bit_rate=rate)
    assert [(v.symbol, v.measured_s * CLOCK_HZ) for v in found] == [("t7", -3)]


@pytest.mark.parametrize("length", [0, 1, 2])
def test_short_traces_have_nothing_to_measure(length: int) -> None:
    idle = np.full(length, serial_io.IDLE.mfp(), dtype=np.int64)
    assert check_serial_io({"mfp_out": idle}, bit_rate=500_000, bits=32, ser_in=[1] * length) == []
    pins = {name: [1] * length for name in ("clk_exr", "to_exr", "la_ou_d", "la_in_d_n", "res_reg_n")}
    assert check_expansion(pins, bit_rate=2_000_000, from_exr=[0] * length) == []


@pytest.mark.parametrize("latched", [False, True])
@pytest.mark.parametrize("rate", RATES)
def test_the_spec_meets_table_3_15(rate: int, latched: bool) -> None:
    """Data cycles of 0 to 4 bytes as the wire sends them (8 data bits of each 13-bit telegram, 5 bits between
    bytes), ClkExR from expansion.clock_high, the end pulses from expansion.end_pulses, /ResReg 4 t0: no row of
    Table 3-15 missed, with a chain answering FromExR exactly at its setup or its hold limit."""
    cycles = [ExpCycle(bytes(range(0x11, 0x11 + 0x22 * n, 0x22)), (5, 5, 5), latched, bytes(range(n)))
              for n in range(5)]
    for setup_exact in (False, True):
        pins, from_exr = build_expansion(rate, cycles, None, 0, 0, setup_exact)
        assert check_expansion(pins, bit_rate=rate, from_exr=from_exr) == []

"""The serial I/O block in Amaranth (supi3.rtl.serial_io) against the spec's schedule (supi3.serial_io).

Manual 3.3 (Tables 3-3, 3-4, Figures 3-1 to 3-3) and SM-1 to SM-9 of docs/assumptions/serial-io.md: the pins equal
``serial_io.render`` cycle for cycle for every direction, width and bit rate and meet Table 3-4
(supi3.verif.timing); SerIn, read through the core's
synchroniser (SYNC_STAGES), lands in the IN word at the sample cycles; a reset aborts and runs the clear sequence;
a start while the clear sequence runs waits (SM-2), one while a data sequence runs begins anew (SM-12). On
Amaranth's own simulator (no external tools).
"""

from __future__ import annotations

import itertools
import random
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pytest
from amaranth.sim import Simulator

from supi3 import serial_io
from supi3.config import DataDirection, MfpKind, Variant, decode, mode_rows
from supi3.interbus import wire
from supi3.pinout import SYNC_STAGES
from supi3.rtl.serial_io import DIRECTIONS, MFP_BITS, SER_IN_PIN, WIDTHS, SerialIoRtl, _in_slots, _schedules
from supi3.serial_io import IDLE, Levels
from supi3.tables import BIT_RATES
from supi3.verif.timing import check_serial_io

MODES = [
    pytest.param(*mode, marks=pytest.mark.slow)
    if mode[0] is DataDirection.IN_OUT and mode[2] == min(BIT_RATES)
    else pytest.param(*mode)
    for mode in itertools.product(DIRECTIONS, WIDTHS, BIT_RATES)
]
"""Every SPI master mode at both bit rates; the longest sequences (IN/OUT at 500 kbit/s, > 1 s each) are slow."""


@dataclass
class Run:
    """One simulation of the block in a mode: per cycle the inputs given and the levels and IN word seen."""

    direction: DataDirection
    bits: int
    bit_rate: int
    ser_in: list[int] = field(default_factory=list)
    """SerIn on the pin, per cycle (the block sees it SYNC_STAGES cycles later)."""
    levels: list[Levels] = field(default_factory=list)
    in_words: list[int] = field(default_factory=list)


def simulate(direction: DataDirection, bits: int, bit_rate: int, script: Callable[[Run], Iterator[dict[str, int]]],
             seed: int = 0) -> Run:  # fmt: skip
    """Run ``script`` (per cycle: the strobes ``start``/``out_word``/``reset`` to give) with a random SerIn trace."""
    dut = SerialIoRtl()
    run = Run(direction, bits, bit_rate)
    rng = random.Random(seed)

    async def bench(ctx: Any) -> None:
        ctx.set(dut.direction, DIRECTIONS.index(direction))
        ctx.set(dut.wide, WIDTHS.index(bits))
        ctx.set(dut.rate, BIT_RATES.index(bit_rate))
        for strobes in script(run):
            run.ser_in.append(rng.getrandbits(1))
            synchronised = run.ser_in[-1 - SYNC_STAGES] if len(run.ser_in) > SYNC_STAGES else 0
            ctx.set(dut.ser_in, synchronised)
            for name in ("start", "out_word", "reset"):
                ctx.set(getattr(dut, name), strobes.get(name, 0))
            levels = Levels(*(ctx.get(getattr(dut, name)) for name in ("conv_n", "sclk", "ss_n", "ser_out")))
            assert ctx.get(dut.mfp) == levels.mfp()
            run.levels.append(levels)
            run.in_words.append(ctx.get(dut.in_word))
            await ctx.tick()

    simulator = Simulator(dut)
    simulator.add_clock(1 / 32e6)
    simulator.add_testbench(bench)
    simulator.run()
    return run


def quiet(n: int) -> Iterator[dict[str, int]]:
    yield from ({} for _ in range(n))


def expected_in(run: Run, first: int, seq: serial_io.SerialSequence) -> int:
    """The IN word a sequence starting at cycle ``first`` reads: SerIn of the cycle before each SCLK rise (SM-5)."""
    frame = seq.read
    assert frame is not None
    word = 0
    for j in range(frame.bits):
        word = (word << 1) | run.ser_in[first + frame.sample(j)]
    return word


def test_pins_and_constants_come_from_the_spec() -> None:
    """Table 3-3: /Conv MFP3, SCLK MFP4, /SS MFP5, SerOut MFP7 driven, SerIn MFP6."""
    assert MFP_BITS == {"conv_n": 3, "sclk": 4, "ss_n": 5, "ser_out": 7}
    assert SER_IN_PIN == 6


@pytest.mark.parametrize(("direction", "bits", "bit_rate"), MODES)
def test_sequence_levels_and_in_word_equal_the_spec(direction: DataDirection, bits: int, bit_rate: int) -> None:
    """Two sequences back to back with random OUT words: every cycle's pins are ``render()``'s, idle before and
    between; the IN word is 0 until the first sequence's last edge, then the SerIn read at the sample cycles."""
    seq = serial_io.sequence(direction, bits, bit_rate)
    rng = random.Random(bits + bit_rate)
    words = [rng.getrandbits(bits) for _ in range(2)]
    gap = 5

    def script(_run: Run) -> Iterator[dict[str, int]]:
        yield from quiet(3)
        yield {"start": 1, "out_word": words[0]}  # latched at cycle 3: the sequence begins at cycle 4
        yield from quiet(seq.length + gap - 1)
        yield {"start": 1, "out_word": words[1]}
        yield from quiet(seq.length + gap)

    run = simulate(direction, bits, bit_rate, script)
    firsts = [4, 4 + seq.length + gap]
    want = [IDLE] * len(run.levels)
    for first, word in zip(firsts, words, strict=True):
        want[first : first + seq.length] = serial_io.render(seq, word)
    assert run.levels == want
    mfp = np.array([levels.mfp() for levels in run.levels], dtype=np.int64)
    assert check_serial_io({"mfp_out": mfp}, bit_rate=bit_rate, bits=bits) == []  # Table 3-4 on the RTL's trace
    if seq.read is None:
        assert set(run.in_words) == {0}
        return
    for first in firsts:
        end = first + seq.length
        assert run.in_words[end] == expected_in(run, first, seq)
        assert run.in_words[end - 1] == (0 if first == firsts[0] else expected_in(run, firsts[0], seq))


@pytest.mark.parametrize(("direction", "bits", "bit_rate"), MODES)
def test_reset_aborts_and_runs_the_clear_sequence(direction: DataDirection, bits: int, bit_rate: int) -> None:
    """SM-9: a reset in the middle of a sequence: from the next cycle the clear sequence (a write frame of zeros and
    /Conv) in OUT and IN/OUT modes, idle in IN mode; the IN word read before is cleared."""
    seq = serial_io.sequence(direction, bits, bit_rate)
    clear = serial_io.clear_sequence(direction, bits, bit_rate)
    word = (1 << bits) - 1
    reset_at = 4 + seq.length + 2 + seq.length // 2

    def script(_run: Run) -> Iterator[dict[str, int]]:
        yield from quiet(3)
        yield {"start": 1, "out_word": word}
        yield from quiet(seq.length + 1)
        yield {"start": 1, "out_word": word}
        yield from quiet(seq.length // 2)
        yield {"reset": 1}
        yield from quiet(seq.length + 4)

    run = simulate(direction, bits, bit_rate, script, seed=1)
    tail = [*(serial_io.render(clear, 0) if clear is not None else []), IDLE]
    assert run.levels[reset_at + 1 : reset_at + 1 + len(tail)] == tail
    assert run.levels[reset_at] == seq.levels(seq.length // 2, word)
    assert set(run.in_words[reset_at + 1 :]) == {0}
    if seq.read is not None:
        assert run.in_words[reset_at] == expected_in(run, 4, seq)


@pytest.mark.parametrize("direction", DIRECTIONS)
def test_start_while_a_data_sequence_runs_begins_anew(direction: DataDirection) -> None:
    """SM-12: a start while a data sequence runs abandons it (its IN word is not taken over) and begins the new one
    on the next cycle; two at once: the newer; INTERBUS cycles never ask it (below)."""
    bits, bit_rate = WIDTHS[0], BIT_RATES[-1]
    seq = serial_io.sequence(direction, bits, bit_rate)
    words = [0xA5C3, 0x1234, 0xFEDC]

    def script(_run: Run) -> Iterator[dict[str, int]]:
        yield {"start": 1, "out_word": words[0]}
        yield from quiet(seq.length - 2)  # the first sequence's last cycle is the next: still running
        yield {"start": 1, "out_word": words[1]}
        yield {"start": 1, "out_word": words[2]}
        yield from quiet(seq.length + 1)

    run = simulate(direction, bits, bit_rate, script, seed=2)
    cut = seq.length - 1  # cycles of the first sequence run
    want = [IDLE, *serial_io.render(seq, words[0])[:cut], serial_io.render(seq, words[1])[0],
            *serial_io.render(seq, words[2])]  # fmt: skip
    assert run.levels[: len(want) + 1] == [*want, IDLE]
    assert set(run.in_words[: len(want)]) == {0}  # nothing taken over before the last sequence's end
    if seq.read is not None:
        assert run.in_words[len(want)] == expected_in(run, 2 + cut, seq)


@pytest.mark.parametrize("direction", [DataDirection.OUT, DataDirection.IN_OUT])
def test_start_while_the_clear_sequence_runs_waits_newest_wins(direction: DataDirection) -> None:
    """SM-2, SM-9: two starts while a reset's clear sequence runs (a watchdog reset just before a data cycle's
    latch): the newer word's sequence begins on the cycle after the clear sequence ends; the older is dropped."""
    bits, bit_rate = WIDTHS[1], BIT_RATES[-1]
    seq = serial_io.sequence(direction, bits, bit_rate)
    clear = serial_io.clear_sequence(direction, bits, bit_rate)
    assert clear is not None
    words = [0xA5C3_0F0F, 0x1234_5678, 0xFEDC_BA98]

    def script(_run: Run) -> Iterator[dict[str, int]]:
        yield {"reset": 1}
        yield from quiet(9)
        yield {"start": 1, "out_word": words[1]}
        yield {"start": 1, "out_word": words[2]}
        yield from quiet(clear.length + seq.length)

    run = simulate(direction, bits, bit_rate, script, seed=3)
    want = [IDLE, *serial_io.render(clear, 0), *serial_io.render(seq, words[2])]
    assert run.levels[: len(want) + 1] == [*want, IDLE]
    if seq.read is not None:
        assert run.in_words[len(want)] == expected_in(run, 1 + clear.length, seq)


def test_interbus_cycles_never_start_while_a_data_sequence_runs() -> None:
    """SM-12: every data sequence (every direction, width, bit rate) ends within the shortest time between two
    valid data cycles' latches, the frame of the loopback word, the chip's data bytes and the check sequence; a
    schedule that outlasted it is refused at elaboration, named."""
    for variant in Variant:  # the chip's data bytes in every SPI master row are the word's (the frame's share)
        for row in mode_rows(variant):
            config = decode(row.c, row.mfp, variant=variant)
            if config.mfp_mode is not None and config.mfp_mode.kind is MfpKind.SPI_MASTER:
                assert config.data_bytes == config.mfp_mode.width // 8
    for direction, bits, bit_rate in itertools.product(DIRECTIONS, WIDTHS, BIT_RATES):
        gap = serial_io.shortest_latch_gap(bits, bit_rate)
        assert gap == wire.frame_bits(wire.LOOPBACK_BYTES + bits // 8) * wire.clocks_per_bit(bit_rate)
        assert serial_io.sequence(direction, bits, bit_rate).length <= gap
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(serial_io, "shortest_latch_gap", lambda _bits, _bit_rate: 100)
        with pytest.raises(ValueError, match=r"must end within 100 clocks.*\(SM-12\)"):
            SerialIoRtl()


def test_a_start_at_the_reset_edge_wins() -> None:
    """The core applies a data cycle's latch after the watchdog's clearing at one edge: the new sequence runs."""
    bits, bit_rate = WIDTHS[0], BIT_RATES[-1]
    seq = serial_io.sequence(DataDirection.OUT, bits, bit_rate)

    def script(_run: Run) -> Iterator[dict[str, int]]:
        yield {"start": 1, "reset": 1, "out_word": 0x8001}
        yield from quiet(seq.length + 1)

    run = simulate(DataDirection.OUT, bits, bit_rate, script)
    assert run.levels == [IDLE, *serial_io.render(seq, 0x8001), IDLE]


def test_sequence_constants_are_whole_t0() -> None:
    """The block counts a sequence in t0 slots: every schedule's offsets are whole t0 (SM-3, SM-7, Table 3-4 t6, t7),
    and a schedule with an offset between slots, or a /Conv pulse before its last slot, is refused at elaboration,
    named."""
    for (_, _, rate), seq in _schedules().items():
        if seq is None:
            continue
        t0 = serial_io.t0_clocks(BIT_RATES[rate])
        slots = _in_slots(seq, t0)
        assert slots.length * t0 == seq.length
        for frame, got in ((seq.read, slots.read), (seq.write, slots.write)):
            assert got == (None if frame is None else (frame.start // t0, frame.end // t0))
            assert frame is None or (frame.start % t0, frame.end % t0) == (0, 0)
        assert slots.conv == (None if seq.conv is None else (seq.conv[0] // t0, seq.conv[1] // t0))
    seq = serial_io.sequence(DataDirection.OUT, WIDTHS[0], BIT_RATES[-1])
    t0 = serial_io.t0_clocks(BIT_RATES[-1])
    shifted = serial_io.SerialSequence(seq.frames, seq.conv, seq.length + 1)
    with pytest.raises(ValueError, match=f"length must fall on a whole t0, not at {seq.length + 1} clocks"):
        _in_slots(shifted, t0)
    assert seq.conv is not None  # the block shows /Conv in the sequence's last slot: a pulse elsewhere is refused
    longer = serial_io.SerialSequence(seq.frames, seq.conv, seq.length + t0)
    with pytest.raises(ValueError, match=r"/Conv pulse must be its last t0, not slots \(19, 20\) of 21"):
        _in_slots(longer, t0)

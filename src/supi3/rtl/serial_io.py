"""Serial I/O (SPI master mode, manual 3.3) in Amaranth: the access sequence on MFP3..MFP7, from counters.

:class:`SerialIoRtl` drives /Conv, SCLK, /SS and SerOut exactly as :func:`supi3.serial_io.sequence` schedules
them (Tables 3-3, 3-4, Figures 3-1 to 3-3; decisions SM-1 to SM-9 of ``docs/assumptions/serial-io.md``), and reads
SerIn into the IN word. Nothing is stored as a waveform: a sequence counter ``slot`` of t0 slots places the frames
and the /Conv pulse (their offsets, whole t0 all, are constants taken from the spec's
:class:`~supi3.serial_io.SerialSequence` for every direction, width and bit rate at elaboration), and the
counters ``sub`` (clock within a t0), ``within`` (slot within a byte of nine slots) and ``lead`` (the half t0
before a frame's first slot) give SCLK, the SerOut shifts and the sample points.

* ``start`` (the core's latch of a valid data cycle) with ``out_word``: a sequence begins on the next cycle (SM-2).
  While a clear sequence runs the word waits (one deep, the newest wins) and its sequence begins on the cycle after
  the clear sequence ends; a start while a data sequence runs abandons it (nothing taken over) and begins anew
  (SM-12), which INTERBUS cycles never ask: two valid data cycles' latches are a whole frame apart, longer than
  every sequence (:func:`~supi3.serial_io.shortest_latch_gap`, checked at elaboration).
* ``reset`` (INTERBUS reset or watchdog reset of process data): the running sequence is aborted, a waiting one
  dropped, the IN word cleared, and the clear sequence of the mode (:func:`~supi3.serial_io.clear_sequence`,
  none in input mode) begins on the next cycle (SM-9). A ``start`` at the same edge wins (the core applies a latch
  after the watchdog's clearing).
* ``ser_in`` is SerIn after the core's synchroniser: bit ``j`` of a read frame is taken at the edge ending cycle
  ``sample(j) + SYNC_STAGES`` of the frame (SM-5); the IN word read is taken over at the edge ending the sequence's
  last cycle (SM-6).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from dataclasses import dataclass
from typing import Final

from amaranth.hdl import Cat, Module, Mux, Signal, Value
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from supi3 import serial_io as spec
from supi3.checks import check_int
from supi3.config import DataDirection
from supi3.pinout import SYNC_STAGES
from supi3.tables import BIT_RATES, SPI_MASTER_MFP

__all__ = ["DIRECTIONS", "MFP_BITS", "SER_IN_PIN", "WIDTHS", "WORD_BITS", "SerialIoRtl", "schedule"]

DIRECTIONS: Final = (DataDirection.IN, DataDirection.OUT, DataDirection.IN_OUT)
"""The SPI master directions (SM-1), in the order of the ``direction`` port's values."""
WIDTHS: Final = (16, 32)
"""Bits per transfer (Tables 2-4 to 2-6), in the order of the ``wide`` port's values."""
WORD_BITS: Final = max(WIDTHS)
"""Width of the OUT and IN word ports (a 16-bit word in the low bits)."""
_CLEAR: Final = len(DIRECTIONS)
"""Sequence kinds: a direction's sequence (0..2) or its clear sequence (``_CLEAR`` + direction)."""


def _mfp_bit(**level: int) -> int:
    """The MFP bit of the one pin set in ``level`` (the rest at 0), by :meth:`supi3.serial_io.Levels.mfp`."""
    levels = spec.Levels(**{"conv_n": 0, "sclk": 0, "ss_n": 0, "ser_out": 0, **level})
    return levels.mfp().bit_length() - 1


MFP_BITS: Final = {name: _mfp_bit(**{name: 1}) for name in ("conv_n", "sclk", "ss_n", "ser_out")}
"""The MFP bit of each driven level (Table 3-3: /Conv MFP3, SCLK MFP4, /SS MFP5, SerOut MFP7)."""
SER_IN_PIN: Final = next(function.pin for function in SPI_MASTER_MFP if function.signal == "SerIn")
"""SerIn's MFP pin (Table 3-3: MFP6)."""


def schedule(kind: int, bits: int, bit_rate: int) -> spec.SerialSequence | None:
    """The spec's sequence of a kind: direction ``DIRECTIONS[kind]``, or that direction's clear sequence for
    ``kind >= len(DIRECTIONS)`` (None in input mode).

    Raises
    ------
    ArgumentError
        ``kind`` not from 0 to ``2 * len(DIRECTIONS) - 1`` (a negative kind took a direction from the end), ``bits``
        or ``bit_rate`` not of Tables 2-4 to 2-6 and 1-7.
    """
    kind = check_int("kind", kind, 0, 2 * _CLEAR - 1, limit="a direction or its clear sequence")
    if kind < _CLEAR:
        return spec.sequence(DIRECTIONS[kind], bits, bit_rate)
    return spec.clear_sequence(DIRECTIONS[kind - _CLEAR], bits, bit_rate)


def _schedules() -> dict[tuple[int, int, int], spec.SerialSequence | None]:
    """Every (kind, width index, rate index) with its sequence."""
    return {
        (kind, wide, rate): schedule(kind, bits, bit_rate)
        for kind, (wide, bits), (rate, bit_rate) in itertools.product(
            range(2 * _CLEAR), enumerate(WIDTHS), enumerate(BIT_RATES)
        )
    }


@dataclass(frozen=True)
class _Slots:
    """A sequence's constants in t0 slots from its first cycle: its length and each frame's and /Conv's first and
    end slot (None where it has none)."""

    length: int
    read: tuple[int, int] | None
    write: tuple[int, int] | None
    conv: tuple[int, int] | None


def _in_slots(seq: spec.SerialSequence, t0: int) -> _Slots:
    """``seq``'s offsets in t0: each must be a whole number of t0 (frames start on whole t0, SM-3; t10 in whole t0,
    SM-7; /Conv after whole t0, Table 3-4 t6, t7)."""

    def slots(name: str, first: int, end: int) -> tuple[int, int]:
        for clocks in (first, end):
            if clocks % t0:
                raise ValueError(f"a sequence's {name} must fall on a whole t0, not at {clocks} clocks (t0 = {t0})")
        return first // t0, end // t0

    def frame(name: str, frame: spec.SerialFrame | None) -> tuple[int, int] | None:
        return None if frame is None else slots(name, frame.start, frame.end)

    length = slots("length", 0, seq.length)[1]
    conv = None if seq.conv is None else slots("/Conv pulse", *seq.conv)
    if conv is not None and conv != (length - 1, length):  # the block shows /Conv in the last slot (Table 3-4 t7)
        raise ValueError(f"a sequence's /Conv pulse must be its last t0, not slots {conv} of {length}")
    return _Slots(length, frame("read frame", seq.read), frame("write frame", seq.write), conv)


class SerialIoRtl(wiring.Component):
    """The serial I/O block of the SPI master modes (block ``serial_io``).

    Ports: ``start``, ``out_word`` (MSB first: D15 or D31 first, SM-4), ``reset``, ``ser_in`` (synchronised) and the
    mode (``direction``: index into :data:`DIRECTIONS`; ``wide``: 32 bits; ``rate``: index into
    :data:`supi3.tables.BIT_RATES`) in; the pin levels ``conv_n``, ``sclk``, ``ss_n``, ``ser_out``, the same as MFP
    bits (``mfp``, :data:`MFP_BITS`), ``in_word`` and ``busy`` out. The mode must be static (straps).
    """

    def __init__(self) -> None:
        self.schedules = _schedules()
        self.t0s = tuple(spec.t0_clocks(bit_rate) for bit_rate in BIT_RATES)
        for t0 in self.t0s:
            if t0 // 2 + SYNC_STAGES - 1 >= t0:
                raise ValueError(f"a SerIn sample needs SYNC_STAGES < t0/2 + 1, not t0 = {t0}")
        self.slots = {key: _in_slots(seq, self.t0s[key[2]]) for key, seq in self.schedules.items() if seq is not None}
        self.longest = max(constants.length for constants in self.slots.values())
        for (kind, wide, rate), seq in self.schedules.items():
            gap = spec.shortest_latch_gap(WIDTHS[wide], BIT_RATES[rate])
            if kind < _CLEAR and seq is not None and seq.length > gap:
                self._MustUse__silence = True  # rejected, never elaborated: no "created but never used" warning
                raise ValueError(f"a data sequence of {seq.length} clocks must end within {gap} clocks, the shortest "
                                 "time between two valid data cycles' latches (SM-12)")  # fmt: skip
        super().__init__({
            "start": In(1), "out_word": In(WORD_BITS), "reset": In(1), "ser_in": In(1),
            "direction": In(range(len(DIRECTIONS))), "wide": In(1), "rate": In(range(len(BIT_RATES))),
            "conv_n": Out(1, init=spec.IDLE.conv_n), "sclk": Out(1, init=spec.IDLE.sclk),
            "ss_n": Out(1, init=spec.IDLE.ss_n), "ser_out": Out(1, init=spec.IDLE.ser_out),
            "mfp": Out(max(MFP_BITS.values()) + 1, init=spec.IDLE.mfp()),
            "in_word": Out(WORD_BITS), "busy": Out(1),
        })  # fmt: skip

    def elaborate(self, _platform: object) -> Module:
        m = Module()
        sync, comb = m.d.sync, m.d.comb
        slot_range = range(self.longest + 1)

        # The running sequence's constants in t0 slots (from the spec's schedule) ------------------------------
        busy = self.busy
        # The sequence's kind and counters are read only while ``busy`` (which has its reset) and set where a
        # sequence begins: no reset.
        kind = Signal(range(2 * _CLEAR), reset_less=True)
        # Each case compares the slot count with its own constants (a few gates each) and only the 1-bit results
        # are chosen by the case: no multiplexed slot constants and no comparators between two signals.
        slot = Signal(slot_range, reset_less=True)
        read_on, conv_on = Signal(), Signal()
        reading, writing = Signal(), Signal()  # the slot is in the read frame, in the write frame
        final = Signal()  # the slot is the sequence's last
        write_next = Signal()  # the write frame follows a read frame and begins with the next slot
        cases: dict[_Slots, list[int]] = {}
        for (kind_value, wide, rate), constants in self.slots.items():
            cases.setdefault(constants, []).append(kind_value | (wide << len(kind)) | (rate << (len(kind) + 1)))
        with m.Switch(Cat(kind, self.wide, self.rate)):
            for constants, patterns in cases.items():
                with m.Case(*patterns):
                    comb += final.eq(slot == constants.length - 1)
                    if constants.write is not None and constants.write[0] > 0:
                        comb += write_next.eq(slot == constants.write[0] - 1)
                    comb += [conv_on.eq(constants.conv is not None), read_on.eq(constants.read is not None)]
                    for frame, window in ((constants.read, reading), (constants.write, writing)):
                        if frame is not None:
                            comb += window.eq((slot >= frame[0]) & (slot < frame[1]))
        # Sequences a reset starts: the clear sequence of this mode's direction, if it has one.
        has_clear = Signal()
        with m.Switch(self.direction):
            for direction in range(_CLEAR):
                with m.Case(direction):
                    comb += has_clear.eq(schedule(_CLEAR + direction, WIDTHS[0], BIT_RATES[0]) is not None)

        def per_t0(pick: Callable[[int], int | Value]) -> Value:
            """``pick(t0)`` at the ``rate`` port's t0: a constant, or a compare with one, per rate."""
            result = Value.cast(pick(self.t0s[0]))
            for rate, t0 in enumerate(self.t0s[1:], 1):
                result = Mux(self.rate == rate, pick(t0), result)
            return result

        # Counters ---------------------------------------------------------------------------------------------
        # Every frame and /Conv edge of a sequence falls on a whole t0 from its first cycle (``_in_slots``), so the
        # sequence counter counts t0 slots: ``slot`` steps at the clock ending each t0 of the sequence. ``sub``
        # is (clocks since the sequence began + t0/2) mod t0 throughout (every sequence and frame starts it at
        # t0/2 and each begins on a whole t0), so that clock is the one with ``sub == t0/2 - 1``.
        sub = Signal(range(max(self.t0s)), reset_less=True)  # clock within a t0, 0 at a bit slot's first cycle
        slot_ends = per_t0(lambda t0: sub == (t0 >> 1) - 1)
        lead = Signal(reset_less=True)  # the half t0 between /SS falling and the first slot
        within = Signal(range(spec.BYTE_SLOTS), reset_less=True)  # slot within a byte: bits 0..7, then the pause slot
        pause = within == spec.BYTE_SLOTS - 1
        in_read = busy & reading
        in_write = busy & writing
        in_frame = in_read | in_write
        high = per_t0(lambda t0: sub >= (t0 >> 1))
        # The shift registers are written before they are read: every start loads ``out_shift`` (a clear sequence
        # sends 0s whatever it holds, ``clearing``, and leaves it alone), a read frame shifts a whole word into
        # ``in_shift`` (a 16-bit word's upper half is left out when taken over): no reset, no clear. A 16-bit word
        # is sent from bit 15 (the bits above are not sent), so the OUT word is loaded as it comes. A start while a
        # clear sequence runs waits in ``out_shift`` (``pending``; the newest wins), one while a data sequence runs
        # abandons it (SM-12): no second word register.
        out_shift = Signal(WORD_BITS, reset_less=True)
        in_shift = Signal(WORD_BITS, reset_less=True)
        pending = Signal()
        clearing = kind >= _CLEAR
        frame_probe = spec.SerialFrame(0, WIDTHS[0], False, max(self.t0s))
        sample_after = frame_probe.sample(0) + SYNC_STAGES - frame_probe.rising(0)  # clocks after SCLK rose

        levels = {
            "conv_n": ~(busy & conv_on & final),
            "sclk": in_frame & ~lead & ~pause & high,
            "ss_n": ~in_frame,
            "ser_out": in_write & ~lead & ~clearing & Mux(self.wide, out_shift[-1], out_shift[WIDTHS[0] - 1]),
        }
        comb += [getattr(self, name).eq(level) for name, level in levels.items()]
        comb += self.mfp.eq(sum((level << MFP_BITS[name] for name, level in levels.items()), Value.cast(0)))

        def frame_begins() -> list[Value]:
            """The slot counters as they stand in a frame's first cycle: in the lead half t0."""
            return [sub.eq(per_t0(lambda t0: t0 >> 1)), lead.eq(1), within.eq(0)]

        last = busy & slot_ends & final
        with m.If(busy):
            with m.If(slot_ends):
                sync += slot.eq(slot + 1)
            with m.If(per_t0(lambda t0: sub == t0 - 1)):
                sync += sub.eq(0)
                with m.If(lead):
                    sync += lead.eq(0)
                with m.Else():
                    sync += within.eq(Mux(pause, 0, within + 1))
                    with m.If(in_write & ~clearing & (within != spec.BYTE_SLOTS - 2)):  # the next slot: bit j > 0
                        sync += out_shift.eq(out_shift << 1)
            with m.Else():
                sync += sub.eq(sub + 1)
            with m.If(in_read & ~lead & ~pause & per_t0(lambda t0: sub == (t0 >> 1) + sample_after)):
                sync += in_shift.eq(Cat(self.ser_in, in_shift[:-1]))
            with m.If(write_next & slot_ends):
                sync += frame_begins()
        with m.If(last):
            sync += busy.eq(0)
            with m.If(read_on):
                sync += self.in_word.eq(Mux(self.wide, in_shift, in_shift[: WIDTHS[0]]))

        # Start, waiting start, reset (SM-2, SM-9, SM-12) -------------------------------------------------------
        free = ~busy | ~clearing | last | self.reset  # a running data sequence is abandoned (SM-12)
        go = (self.start | (pending & ~self.reset)) & free
        with m.If(self.start):
            sync += out_shift.eq(self.out_word)
        with m.If(self.start & ~free):
            sync += pending.eq(1)
        with m.If(self.reset):
            sync += [
                busy.eq(has_clear),
                kind.eq(_CLEAR + self.direction),
                slot.eq(0),
                pending.eq(0),
                self.in_word.eq(0),
                *frame_begins(),
            ]
        with m.If(go):
            sync += [
                busy.eq(1),
                kind.eq(self.direction),
                slot.eq(0),
                pending.eq(0),
                *frame_begins(),
            ]
        return m

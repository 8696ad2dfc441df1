"""Serial I/O (SPI master mode, manual 3.3): the chip's access sequence on MFP3..MFP7, clock by clock.

The one definition of what the chip drives in the SPI master modes of Tables 2-4 to 2-6 (pins of Table 3-3, times of
Table 3-4, Figures 3-1 to 3-3). The pin-level model (:mod:`supi3.model.blocks.serial_io`), the RTL
(:mod:`supi3.rtl.serial_io`), the transaction-level chip and the figures all derive from these functions; the
Table 3-4 checker (:mod:`supi3.verif.timing`) does not: it measures traces against the table on its own. The
decisions where the manual is silent or garbled are SM-1 to SM-10 of ``docs/assumptions/serial-io.md``.

A *sequence* starts on the clock after the edge at which a valid data cycle is latched (SM-2). Offsets below are
clock cycles from the sequence's first cycle; the pins hold the given levels during that cycle.

* **Frame** (SM-3, SM-4): /SS low for ``9 * n * t0`` (t8, ``n`` bytes: 2 or 4, one /SS over the whole 16 or 32
  bits); bit ``j`` (MSB first, D15 or D31 first: t11) has a slot of ``t0`` starting ``t0/2 + (j + j // 8) * t0``
  after /SS fell; SCLK is low in the slot's first half and high in its second (idle low: the first rising edge is
  ``t0`` after /SS falls, t1; the last is ``t0`` before /SS rises, t2); one slot is left out between bytes (t9 =
  2 t0 from rising edge to rising edge). SerOut changes at slot starts (t3, t11, t12 = t0/2) and is 0 outside
  write frames.
* **Sample** (SM-5): SerIn is taken at each rising SCLK edge: the level it had in the cycle before SCLK rose.
* **Sequence** (SM-6): input mode: one read frame. Output mode: one write frame, then /Conv low for ``t0`` starting
  ``t0`` after /SS rose (t6, t7). Input/output mode: read frame, pause of :data:`PAUSE_T0` t0 (t10), write frame,
  /Conv. The IN word read is taken over on the sequence's last clock edge (the third step of 3.3.1).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final, Protocol, runtime_checkable

from supi3.checks import check_bits, check_bool, check_choice, check_instance, check_int, fail
from supi3.config import DataDirection
from supi3.interbus import wire
from supi3.tables import BIT_RATES

__all__ = [
    "IDLE",
    "PAUSE_T0",
    "WIRING",
    "Levels",
    "SerialDevice",
    "SerialFrame",
    "SerialSequence",
    "Wire",
    "clear_sequence",
    "sequence",
    "shortest_latch_gap",
    "t0_clocks",
]

PAUSE_T0: Final = 51
"""t10, Read /SS to Write /SS, in t0: Table 3-4 prints "50.5 * t0"; whole t0 keep SCLK's phase (SM-7)."""
CONV_DELAY_T0: Final = 1
"""t6: /Conv falls t0 after /SS rose (Table 3-4 minimum)."""
CONV_WIDTH_T0: Final = 1
"""t7: /Conv is low for t0 (Table 3-4 minimum)."""
BYTE_SLOTS: Final = 9
"""t8 = 9 * n * t0: eight bit slots and one pause slot per byte (t9 = 2 t0 between the bytes' rising edges)."""


@dataclass(frozen=True)
class Levels:
    """MFP3..MFP7 driven by the chip in one cycle (Table 3-3); SerIn (MFP6) is the chip's input."""

    conv_n: int
    sclk: int
    ss_n: int
    ser_out: int

    def __post_init__(self) -> None:
        check_levels(self)

    def mfp(self) -> int:
        """The levels as MFP bits: /Conv MFP3, SCLK MFP4, /SS MFP5, SerOut MFP7."""
        return (self.conv_n << 3) | (self.sclk << 4) | (self.ss_n << 5) | (self.ser_out << 7)


def check_levels(levels: object) -> None:
    """Every field of the dataclass ``levels`` must be a pin level, 0 or 1 (:class:`Levels`, and the register
    expansion's ``ExpansionLevels``)."""
    for name, level in vars(levels).items():
        if type(level) is not int or level >> 1 or level < 0:
            # a numpy level is stored as the int it is, so that every level of a frozen dataclass is a plain int
            object.__setattr__(levels, name, check_bits(f"{type(levels).__name__}.{name}", level, 1))


IDLE: Final = Levels(conv_n=1, sclk=0, ss_n=1, ser_out=0)
"""Between sequences, after power-up and during the reset stretch (SM-8)."""
MFP_MASK: Final = Levels(1, 1, 1, 1).mfp()
"""The MFP bits the serial I/O drives (MFP3, 4, 5, 7)."""


PERIPHERAL_DELAY_CLOCKS: Final = 2
"""A device's SerIn answers an edge of the chip's pins 2 clocks (62.5 ns) later, within Table 3-4's hold time t5
(50 ns) and well inside half an SCLK period (SM-10). A device attached to the chip model
(:meth:`supi3.model.chip.Supi3.attach_serial`) therefore shows, at each sample, its answer to every edge before that
SCLK rise."""


@runtime_checkable
class SerialDevice(Protocol):
    """What hangs on the serial I/O bus (3.3.1: shift registers, ADCs, DACs), at either fidelity.

    The transaction level calls :meth:`frame` and :meth:`convert` once per /SS frame and /Conv pulse; the pin level
    calls :meth:`clock` at every cycle in which the chip's MFP3..MFP7 change. A device is driven at one fidelity.
    """

    @property
    def drives_ser_in(self) -> bool:
        """The device's serial output is wired to the chip's SerIn (at most one device on a bus)."""

    def frame(self, ser_out: int, bits: int) -> int:
        """One /SS frame of ``bits`` SCLK pulses writing ``ser_out`` MSB first (0 in read frames); returns the bits
        the device put on SerIn, MSB first (0 if it does not drive SerIn)."""

    def convert(self) -> None:
        """A /Conv pulse (output mode: the DAC converts, the output register takes the shifted word)."""

    def clock(self, levels: Levels) -> int:
        """The chip's pins changed to ``levels``; returns the SerIn level the device drives from then on."""


@dataclass(frozen=True)
class Wire:
    """How one pin of Table 3-3 meets the peripherals the serial I/O is made for (3.3.1: ADCs, DACs, 74HCT165 input
    and 74HCT594 output shift registers), as the models of :mod:`supi3.peripherals` expect it (SM-12)."""

    mfp: int
    signal: str
    inputs: str
    """What input peripherals (IN data) connect here; empty if none."""
    outputs: str
    """What output peripherals (OUT data) connect here; empty if none."""


WIRING: Final[tuple[Wire, ...]] = (
    Wire(3, "/Conv", "", "DAC /LDAC (output takes the word at the fall); 74HCT594 ST_CP (storage at the rise)"),
    Wire(4, "SCLK", "ADC SCLK; 74HCT165 CP", "DAC SCLK; 74HCT594 SH_CP"),
    Wire(5, "/SS", "ADC /CS (samples at the fall); 74HCT165 /PL through an inverter (captures at the fall)",
         "DAC /CS"),
    Wire(6, "SerIn", "ADC DOUT; 74HCT165 Q7 of the first chip (DS of the last to GND)", ""),
    Wire(7, "SerOut", "", "DAC DIN; 74HCT594 DS of the first chip"),
)  # fmt: skip
"""Peripheral wiring of the SPI master pins (Table 3-3); MFP0-2 and MFP8-11 go to GND (3.3.1 note)."""


def t0_clocks(bit_rate: int) -> int:
    """t0 = t_Bit_IBS / 2 in 32 MHz clocks (Table 3-4): 32 at 500 kbit/s (1 MHz SCLK), 8 at 2 Mbit/s (4 MHz)."""
    check_choice("bit_rate", bit_rate, BIT_RATES, limit="Table 1-7")
    return wire.clocks_per_bit(bit_rate) // 2


def shortest_latch_gap(bits: int, bit_rate: int) -> int:
    """Clocks between the latches of two valid data cycles of a chip in an SPI master mode with ``bits`` (16 or 32)
    per transfer at ``bit_rate``, at the least (SM-12): the second cycle's whole frame passes the chip between them
    (its telegrams follow the first one's latch telegrams on the ring), with the loopback word, at least the chip's
    own ``bits // 8`` data bytes (the OUT word's, SM-4) and the check sequence (``wire.frame_bits``)."""
    check_choice("bits", bits, (16, 32), limit="Tables 2-4 to 2-6")
    check_choice("bit_rate", bit_rate, BIT_RATES, limit="Table 1-7")
    return wire.frame_bits(wire.LOOPBACK_BYTES + bits // 8) * wire.clocks_per_bit(bit_rate)


@dataclass(frozen=True)
class SerialFrame:
    """One /SS frame of a sequence: its first cycle (offset), its bit count and whether it writes SerOut."""

    start: int
    bits: int
    write: bool
    t0: int

    def __post_init__(self) -> None:
        check_int("start", self.start, 0)
        check_choice("bits", self.bits, (16, 32), limit="Tables 2-4 to 2-6")
        check_bool("write", self.write)
        check_choice("t0", self.t0, tuple(t0_clocks(rate) for rate in BIT_RATES), limit="Table 3-4: 0.5 t_Bit_IBS")

    def _bit(self, j: int) -> int:
        if type(j) is not int or not 0 <= j < self.bits:
            check_int("j", j, 0, self.bits - 1, limit=f"a bit of the {self.bits}-bit frame")
        return j

    @property
    def length(self) -> int:
        """Cycles with /SS low: 9 * n * t0 (t8)."""
        return BYTE_SLOTS * (self.bits // 8) * self.t0

    @property
    def end(self) -> int:
        """The first cycle after the frame (/SS high again)."""
        return self.start + self.length

    def slot(self, j: int) -> int:
        """The first cycle of bit ``j``'s slot (SCLK low half; SerOut changes here)."""
        j = self._bit(j)
        return self.start + self.t0 // 2 + (j + j // 8) * self.t0

    def rising(self, j: int) -> int:
        """The first SCLK-high cycle of bit ``j`` (its rising edge is at the start of this cycle)."""
        return self.slot(j) + self.t0 // 2

    def sample(self, j: int) -> int:
        """The cycle whose SerIn level is bit ``j`` of a read frame: the last before SCLK rises (SM-5)."""
        return self.rising(j) - 1


@dataclass(frozen=True)
class SerialSequence:
    """The frames and /Conv pulse of one sequence, and its length in cycles."""

    frames: tuple[SerialFrame, ...]
    conv: tuple[int, int] | None
    """(first, end) cycles of the /Conv low pulse, or None (input mode)."""
    length: int
    """Cycles of the sequence; the IN word read is taken over on the edge ending cycle ``length - 1``."""

    def __post_init__(self) -> None:
        if type(self.frames) is not tuple or not self.frames or not all(
                isinstance(frame, SerialFrame) for frame in self.frames):  # fmt: skip
            raise fail("frames", "a non-empty tuple of SerialFrame", self.frames)
        if self.conv is not None and (type(self.conv) is not tuple or len(self.conv) != 2
                                      or not all(type(c) is int for c in self.conv)
                                      or not 0 <= self.conv[0] < self.conv[1] <= self.length):
            raise fail("conv", f"None or the (first, end) cycles of the /Conv pulse, 0 <= first < end <= length "
                               f"{self.length!r}", self.conv)
        ends = max(frame.end for frame in self.frames)
        check_int("length", self.length, max(1, ends), limit="the sequence holds its frames")

    @property
    def read(self) -> SerialFrame | None:
        """The read frame, if any."""
        return next((f for f in self.frames if not f.write), None)

    @property
    def write(self) -> SerialFrame | None:
        """The write frame, if any."""
        return next((f for f in self.frames if f.write), None)

    def levels(self, k: int, out_word: int) -> Levels:
        """The pins in cycle ``k`` of the sequence, writing ``out_word`` (IDLE outside ``0 <= k < length``)."""
        if type(k) is not int:
            check_int("k", k)
        bits = self.frames[0].bits
        if type(out_word) is not int or out_word < 0 or out_word >> bits:
            check_bits("out_word", out_word, bits)
        conv = 0 if self.conv is not None and self.conv[0] <= k < self.conv[1] else 1
        for frame in self.frames:
            if frame.start <= k < frame.end:
                j = _bit_at(frame, k)
                sclk = int(j is not None and frame.rising(j) <= k < frame.slot(j) + frame.t0)
                out = 0
                if frame.write and k >= frame.slot(0):
                    last = j if j is not None else _last_bit_before(frame, k)
                    out = (out_word >> (frame.bits - 1 - last)) & 1
                return Levels(conv_n=conv, sclk=sclk, ss_n=0, ser_out=out)
        return Levels(conv_n=conv, sclk=0, ss_n=1, ser_out=0)


def _bit_at(frame: SerialFrame, k: int) -> int | None:
    """The bit whose slot holds cycle ``k`` of ``frame``, or None (before the first slot or in a pause slot)."""
    rel = k - frame.start - frame.t0 // 2
    if rel < 0:
        return None
    slot = rel // frame.t0
    byte, within = divmod(slot, BYTE_SLOTS)
    return None if within == 8 or 8 * byte + within >= frame.bits else 8 * byte + within


def _last_bit_before(frame: SerialFrame, k: int) -> int:
    rel = k - frame.start - frame.t0 // 2
    slot = rel // frame.t0
    byte, within = divmod(slot, BYTE_SLOTS)
    return min(8 * byte + min(within, 7), frame.bits - 1)


def sequence(direction: DataDirection, bits: int, bit_rate: int) -> SerialSequence:
    """The sequence after a valid data cycle in the SPI master mode ``direction`` with ``bits`` (16 or 32) per
    transfer at ``bit_rate`` (3.3.1, Figures 3-1 to 3-3)."""
    check_choice("direction", direction, (DataDirection.IN, DataDirection.OUT, DataDirection.IN_OUT))
    check_choice("bits", bits, (16, 32), limit="Tables 2-4 to 2-6")
    t0 = t0_clocks(bit_rate)
    if direction is DataDirection.IN:
        frame = SerialFrame(0, bits, False, t0)
        return SerialSequence((frame,), None, frame.end)
    read: tuple[SerialFrame, ...] = ()
    start = 0
    if direction is DataDirection.IN_OUT:
        read = (SerialFrame(0, bits, False, t0),)
        start = read[0].end + PAUSE_T0 * t0
    return _with_write(read, start, bits, t0)


def clear_sequence(direction: DataDirection, bits: int, bit_rate: int) -> SerialSequence | None:
    """After an INTERBUS reset or a watchdog reset of process data: a write frame of zeros and /Conv in the modes
    with OUT data, so the peripherals' outputs follow the cleared OUT register (SM-9); None in input mode."""
    if direction is DataDirection.IN:
        check_choice("bits", bits, (16, 32), limit="Tables 2-4 to 2-6")
        t0_clocks(bit_rate)
        return None
    check_choice("direction", direction, (DataDirection.OUT, DataDirection.IN_OUT))
    check_choice("bits", bits, (16, 32), limit="Tables 2-4 to 2-6")
    return _with_write((), 0, bits, t0_clocks(bit_rate))


def _with_write(read: tuple[SerialFrame, ...], start: int, bits: int, t0: int) -> SerialSequence:
    write = SerialFrame(start, bits, True, t0)
    conv = write.end + CONV_DELAY_T0 * t0
    return SerialSequence((*read, write), (conv, conv + CONV_WIDTH_T0 * t0), conv + CONV_WIDTH_T0 * t0)


def render(seq: SerialSequence, out_word: int) -> list[Levels]:
    """Every cycle of ``seq`` writing ``out_word`` (for figures and tests; the model computes cycles on demand)."""
    check_instance("seq", seq, SerialSequence)
    check_bits("out_word", out_word, seq.frames[0].bits)
    return [seq.levels(k, out_word) for k in range(seq.length)]

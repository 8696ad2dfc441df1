"""Every redrawn timing figure of the manual: the serial µP interface's (:mod:`supi3.spi.figures`), the serial I/O's
(SPI master mode, 3.3.2: Figures 3-1 to 3-3) and the serial register expansion's (3.5: Figure 3-23), written by
:func:`write_figures` (``supi3 figures``, see ``docs/figures.md``).

The serial I/O and expansion figures come from pin traces of a :class:`~supi3.model.pins.Supi3Pins` in a
:class:`~supi3.model.pinring.PinRing`, started and given one data cycle by a :class:`~supi3.interbus.master.Master`,
with peripherals attached: :mod:`supi3.peripherals.serial` in a 16-bit SPI master mode
(:meth:`supi3.model.chip.Supi3.attach_serial`), an IBS SRE 1 chain (:class:`supi3.peripherals.sre.Sre1`) with
ExtReg = 1 (:meth:`supi3.model.chip.Supi3.attach_expansion`). SerIn and FromExR are inputs the chip asks its device
for (SM-5, RX-3): the figure's level is the device's answers to the chip's pin changes, kept as the chip clocked it,
each on the line :data:`~supi3.serial_io.PERIPHERAL_DELAY_CLOCKS` after its cause (SM-10) and checked to give, at
the chip's samples, the data the chip took. Every trace drawn is checked against its table first (Table 3-4:
:func:`supi3.verif.timing.check_serial_io`, Table 3-15: :func:`~supi3.verif.timing.check_expansion`): a figure
never shows a waveform breaking its table.

This module sits beside :mod:`supi3.spi.figures` (not in it) because it uses the verification kit, which imports
the whole chip, which imports :mod:`supi3.spi`.
"""

from __future__ import annotations

import json
from bisect import bisect_left, bisect_right
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Final

import numpy as np
import numpy.typing as npt

from supi3 import tables
from supi3.checks import check_bool, check_instance
from supi3.config import DataDirection, DeviceConfig, MfpKind, decode
from supi3.errors import Supi3Error
from supi3.expansion import ExpansionLevels, ExternalRegisters
from supi3.interbus.master import Master
from supi3.interbus.wire import LOOPBACK_BYTES_ON_LINE
from supi3.model.pinring import PinRing
from supi3.model.pins import Supi3Pins
from supi3.peripherals.serial import SerialBus, ShiftIn, ShiftOut, SpiAdc, SpiDac
from supi3.peripherals.sre import Sre1
from supi3.pinout import SYNC_STAGES
from supi3.regmap import ID, SET
from supi3.serial_io import (
    IDLE,
    MFP_MASK,
    PAUSE_T0,
    PERIPHERAL_DELAY_CLOCKS,
    Levels,
    SerialDevice,
    SerialSequence,
    render,
)
from supi3.spi.figures import FIGURES, GAP, ID_DIGITAL_OUTPUT, Figure, render_svg, wave_string, wavedrom_module
from supi3.spi.master import SpiTrace, write_spi_vcd
from supi3.tables import CLOCK_HZ, clk_conf_for
from supi3.verif.timing import EXPANSION_PINS, check_expansion, check_serial_io, raise_first

__all__ = [
    "ALL_FIGURES",
    "EXPANSION_FIGURES",
    "SERIAL_IO_FIGURES",
    "ExpansionTrace",
    "FigureTraceError",
    "SerialIoTrace",
    "expansion_wavejson",
    "serial_io_wavejson",
    "write_figures",
]


# ------------------------------------------------------------------------------------------------------------
# Serial I/O (SPI master mode, 3.3.2): Figures 3-1 to 3-3, redrawn from pin-level ring traces
# ------------------------------------------------------------------------------------------------------------

TRACE_BIT_RATE: Final = 2_000_000
"""Bit rate of the serial I/O and expansion figures: t0 = 250 ns = 8 chip clocks, SCLK 4 MHz (Tables 3-3, 3-4);
ClkExR 2 MHz (Table 3-15)."""
SERIAL_IO_C: Final = "10011"
"""C4..0 of the serial I/O figures' chip: remote bus device (the "RB, SPI 16 ..." rows of Table 2-6)."""
SERIAL_IO_OUT: Final = b"\x3c\x96"
"""The OUT data the master sends in the serial I/O figures' data cycle (any word; not the manual's)."""
SERIAL_IO_IN: Final = 0xA55A
"""What the input devices hold (ADC code, 74HCT165 inputs) in the serial I/O figures (any word)."""
POWER_UP_S: Final = 0.0002
"""Idle line before the master starts: longer than the chip's power-up reset stretch."""
MARGIN_COLUMNS: Final = 2
"""Idle columns drawn before /SS falls and after the sequence ends."""
PAUSE_COLUMNS: Final = 2
"""Columns of the t10 pause (input/output mode) drawn on each side of its gap."""

Trace = npt.NDArray[np.int64]


class FigureTraceError(Supi3Error, AssertionError):
    """A model trace does not show what its figure draws (the spec's sequence, the SerIn the chip read)."""


class _Recorder:
    """A serial device passing every call to ``device`` that keeps, in call order, the pins of each pin-level
    :meth:`clock` call (as MFP bits) and the SerIn level the device answered."""

    def __init__(self, device: SerialDevice) -> None:
        self.device = device
        self.answers: list[tuple[int, int]] = []

    @property
    def drives_ser_in(self) -> bool:
        """As the device."""
        return self.device.drives_ser_in

    def frame(self, ser_out: int, bits: int) -> int:
        """The device's frame (transaction level; not used by the figures)."""
        return self.device.frame(ser_out, bits)

    def convert(self) -> None:
        """The device's /Conv pulse (transaction level; not used by the figures)."""
        self.device.convert()

    def clock(self, levels: Levels) -> int:
        """The device's answer to ``levels``, kept."""
        answer = self.device.clock(levels)
        self.answers.append((levels.mfp(), answer))
        return answer


def _answered(pins: Trace, answers: Sequence[tuple[int, int]], delay: int) -> Trace:
    """An input over a whole trace from the answers of the device driving it: the chip clocks its device with its
    pins (coded as one integer per cycle in ``pins``) at every change, so the answers, with repeated pins merged, pair
    one to one with the changes of ``pins`` and each is on the line ``delay`` clocks after its change (SM-10). An
    answer to the pins before the first change (given when the device was attached) holds from the start, else 0.

    Raises
    ------
    FigureTraceError
        The answers do not pair with the changes of the trace, or differ for unchanged pins.
    """
    told: list[tuple[int, int]] = []
    for code, answer in answers:
        if told and told[-1][0] == code:
            if told[-1][1] != answer:
                raise FigureTraceError(f"the device answered {told[-1][1]}, then {answer} to unchanged pins {code:#x}")
            continue
        told.append((code, answer))
    initial = told.pop(0)[1] if told and told[0][0] == int(pins[0]) else 0
    changes = np.flatnonzero(np.diff(pins)) + 1
    if [code for code, _ in told] != [int(pins[c]) for c in changes]:
        raise FigureTraceError(f"the device saw {len(told)} pin changes, the trace has {len(changes)} others")
    starts = np.array([0, *(changes + delay)], dtype=np.int64)
    values = np.array([initial, *(answer for _, answer in told)], dtype=np.int64)
    return values[np.searchsorted(starts, np.arange(len(pins)), side="right") - 1]


@dataclass(frozen=True)
class SerialIoTrace:
    """One SPI master sequence (3.3.2) cut from the pin trace of a chip in a ring, with the SerIn levels its
    devices drove."""

    config: DeviceConfig
    sequence: SerialSequence
    """The sequence of the mode (:func:`supi3.serial_io.sequence`)."""
    devices: tuple[SerialDevice, ...]
    """The devices on the bus, after the sequence."""
    start: int
    """The chip clock of index 0."""
    first: int
    """The index of the sequence's first cycle (the clock after the data cycle's latch, SM-2)."""
    mfp_out: Trace
    """MFP3, 4, 5 and 7 as driven (the other MFP bits masked)."""
    ser_in: Trace
    """SerIn (MFP6): what the devices drove, 0 or 1."""
    out_word: int
    """The OUT word written (the data cycle's OUT data, SM-4)."""
    in_word: int
    """The IN word the chip took over at the sequence's end (SM-6); 0 without a read frame."""

    def at(self, k: int) -> int:
        """The index of cycle ``k`` of the sequence."""
        return self.first + k


def _serial_io_trace(direction: DataDirection, *devices: SerialDevice) -> SerialIoTrace:
    """A chip in the 16-bit SPI master mode ``direction`` with ``devices`` attached, started by a master and given
    one data cycle; the trace around the sequence after its latch, checked against Table 3-4 and the spec.

    Raises
    ------
    TraceTimingError
        The chip's trace breaks a row of Table 3-4 (:func:`supi3.verif.timing.check_serial_io`).
    FigureTraceError
        The master's cycles fail, or the trace is not the spec's sequence, or SerIn at the samples is not the word
        the chip read.
    """
    config = next(
        c for c in (decode(r.c, r.mfp, clk_conf=clk_conf_for(TRACE_BIT_RATE)) for r in tables.MODE_ROWS
                    if r.c == SERIAL_IO_C)
        if c.mfp_mode.kind is MfpKind.SPI_MASTER and c.mfp_mode.direction is direction and c.mfp_mode.width == 16
    )
    pins = Supi3Pins(config)
    recorder = _Recorder(SerialBus(*devices))
    pins.chip.attach_serial(recorder)
    ring = PinRing([pins], record=True)
    ring.idle(POWER_UP_S)
    master = Master(ring, locate=False)
    started = master.start()
    master.set_outputs(1, SERIAL_IO_OUT)
    cycle_from = ring.cycle
    data = master.data_cycle()
    if not (started.ok and data.ok):
        raise FigureTraceError(f"the master's cycles failed: {started}, {data}")
    assert pins.chip.spi_sequences is not None  # an SPI master mode
    seq = pins.chip.spi_sequences[0]
    step = seq.frames[0].t0 // 2
    ring.idle(2 * seq.length / CLOCK_HZ)  # longer than the sequence and the margin after it
    traced = ring.recorded()[0]
    mfp_out = traced["mfp_out"] & MFP_MASK
    ser_in = _answered(mfp_out, recorder.answers, PERIPHERAL_DELAY_CLOCKS)
    raise_first(check_serial_io({"mfp_out": mfp_out}, bit_rate=config.bit_rate, bits=16, ser_in=ser_in))
    s = cycle_from + int(np.flatnonzero(mfp_out[cycle_from:] != IDLE.mfp())[0])
    out_word = int.from_bytes(SERIAL_IO_OUT, "big")
    expected = np.array([levels.mfp() for levels in render(seq, out_word)], dtype=np.int64)
    if not np.array_equal(mfp_out[s : s + seq.length], expected):
        raise FigureTraceError(f"the pins from clock {s} are not the sequence writing {out_word:04X}h")
    read = seq.read
    word = 0
    for j in range(read.bits if read is not None else 0):
        assert read is not None
        word = (word << 1) | int(ser_in[s + read.sample(j)])
    if word != pins.chip.in_word:
        raise FigureTraceError(f"SerIn at the samples is {word:04X}h, the chip read {pins.chip.in_word:04X}h")
    c0 = s - MARGIN_COLUMNS * step
    window = slice(c0, s + seq.length + MARGIN_COLUMNS * step)
    if window.stop > len(mfp_out):
        raise FigureTraceError(f"the trace ends at clock {len(mfp_out)}, before the figure's end {window.stop}")
    return SerialIoTrace(config, seq, devices, c0, s - c0, mfp_out[window], ser_in[window], out_word,
                         pins.chip.in_word)


def _columns(length: int, step: int, cut: range) -> list[int | None]:
    """The last clock of each column of ``step`` clocks over ``length`` clocks; the columns whose last clock is in
    ``cut`` make one gap (None)."""
    columns: list[int | None] = []
    for c in range(step - 1, length, step):
        if c not in cut:
            columns.append(c)
        elif columns[-1] is not None:
            columns.append(None)
    return columns


def _level_lane(name: str, columns: Sequence[int | None], level: Callable[[int], str]) -> dict[str, object]:
    """A lane of levels: ``level(c)`` per column (its last clock ``c``), the gap as ``|``."""
    return {"name": name, "wave": wave_string([GAP if c is None else level(c) for c in columns], lambda _: False)}


def _node(columns: Sequence[int | None], marks: dict[int, str]) -> str:
    """A lane's ``node`` string: ``marks[c]`` at the column whose last clock is ``c``."""
    return "".join(marks.get(c, ".") if c is not None else "." for c in columns)


def _bit_lane(name: str, columns: Sequence[int | None], key: Callable[[int], object],
              label: Callable[[int], str]) -> dict[str, object]:  # fmt: skip
    """A lane of named segments: ``key(c)`` per column, an int a segment named ``label(key)``, ``"z"`` none."""
    keys = [GAP if c is None else key(c) for c in columns]
    labels: list[str] = []
    previous: object = None
    for k in keys:
        if k is GAP:
            continue
        if k != previous and isinstance(k, int):
            labels.append(label(k))
        previous = k
    return {"name": name, "wave": wave_string(keys, lambda k: isinstance(k, int)), "data": labels}


def serial_io_wavejson(trace: SerialIoTrace, title: str) -> dict[str, object]:
    """The WaveJSON of a serial I/O sequence: one column per half SCLK period (t0 / 2), each showing the pins in its
    last clock (for SerIn the one the chip samples before a rising SCLK edge, SM-5), the t10 pause cut to a gap.

    Lanes /SS, SCLK, SerOut, SerIn and /Conv (MFP5, 4, 7, 6, 3); SerIn is drawn in read frames only (``x``
    elsewhere: not sampled). Below them the bit names D15..D0 (t11: D15 first) of SerOut where the chip drives
    each and of SerIn up to the sample that takes each.

    Raises
    ------
    ArgumentError
        ``trace`` not a :class:`SerialIoTrace`, ``title`` not a str.
    """
    check_instance("trace", trace, SerialIoTrace)
    check_instance("title", title, str, "a str")
    seq = trace.sequence
    bits = seq.frames[0].bits
    step = seq.frames[0].t0 // 2
    read, write = seq.read, seq.write
    cut = (range(trace.at(read.end + PAUSE_COLUMNS * step), trace.at(write.start - PAUSE_COLUMNS * step))
           if read is not None and write is not None else range(0))
    columns = _columns(len(trace.mfp_out), step, cut)

    def pin(number: int) -> Callable[[int], str]:
        return lambda c: str((int(trace.mfp_out[c]) >> number) & 1)

    def ser_in(c: int) -> str:
        return str(int(trace.ser_in[c])) if read is not None and trace.at(read.start) <= c < trace.at(read.end) else "x"

    def name(j: int) -> str:
        return f"D{bits - 1 - j}"

    ss = _level_lane("/SS (MFP5)", columns, pin(5))
    edges: list[str] = []
    if read is not None and write is not None:  # t10 from the read frame's /SS rise to the write frame's /SS fall
        ss["node"] = _node(columns, {trace.at(read.end) + step - 1: "a", trace.at(write.start) + step - 1: "b"})
        edges.append(f"a<->b t10 = {PAUSE_T0} t0")
    signal: list[object] = [ss, _level_lane("SCLK (MFP4)", columns, pin(4)),
                            _level_lane("SerOut (MFP7)", columns, pin(7))]
    if write is not None:  # bit j from its slot's start to the next slot's (t3, t11, t12)
        slots = [trace.at(write.slot(j)) for j in range(bits)]
        end = trace.at(write.end)
        signal.append(_bit_lane("SerOut bit", columns,
                                lambda c: bisect_right(slots, c) - 1 if slots[0] <= c < end else "z", name))
    signal.append(_level_lane("SerIn (MFP6)", columns, ser_in))
    if read is not None:  # bit j after the sample of bit j - 1, up to its own (SM-5)
        samples = [trace.at(read.sample(j)) for j in range(bits)]
        signal.append(_bit_lane("SerIn bit", columns,
                                lambda c: bisect_left(samples, c) if trace.at(read.start) <= c <= samples[-1] else "z",
                                name))
    signal.append(_level_lane("/Conv (MFP3)", columns, pin(3)))
    config = trace.config
    t0_ns = 2 * step * 1e9 / CLOCK_HZ
    words = [f"OUT word {trace.out_word:04X}h" if write is not None else "",
             f"IN word read {trace.in_word:04X}h" if read is not None else ""]
    foot = (f"SUPI 3 model trace ({config.function}, {config.bit_rate // 1000} kbit/s, t0 = {t0_ns:.0f} ns, SCLK "
            f"{1e3 / t0_ns:.0f} MHz; {', '.join(w for w in words if w)}; "
            f"{', '.join(map(repr, trace.devices))}); one column = {step} chip clocks = {step * 1e9 / CLOCK_HZ:.0f} ns"
            + ("; gap: most of the t10 pause left out" if cut else ""))
    wavejson: dict[str, object] = {"signal": signal, "head": {"text": title}, "foot": {"text": foot}}
    if edges:
        wavejson["edge"] = edges
    return wavejson


def _adc() -> SpiAdc:
    adc = SpiAdc(16)
    adc.set_input(SERIAL_IO_IN)
    return adc


def _shift_in() -> ShiftIn:
    chain = ShiftIn(2)
    chain.set_inputs(SERIAL_IO_IN)
    return chain


SERIAL_IO_FIGURES: Final[tuple[Figure[SerialIoTrace], ...]] = (
    Figure("fig3-1", "Figure 3-1 Serial input mode timing",
           f"SPI 16 IN with a 16-bit SPI ADC on SerIn: one read frame after a data cycle; the ADC's code "
           f"{SERIAL_IO_IN:04X}h enters D15 first and is the IN data of the next data cycle.",
           lambda: _serial_io_trace(DataDirection.IN, _adc()), serial_io_wavejson),
    Figure("fig3-2", "Figure 3-2 Serial output mode timing",
           f"SPI 16 OUT with a 16-bit SPI DAC: the data cycle's OUT word {SERIAL_IO_OUT.hex().upper()}h leaves on "
           f"SerOut D15 first in one write frame; /Conv loads the DAC after /SS rose (t6, t7).",
           lambda: _serial_io_trace(DataDirection.OUT, SpiDac(16)), serial_io_wavejson),
    Figure("fig3-3", "Figure 3-3 Input/output mode timing",
           f"SPI 16 IN/OUT with 74HCT165 and 74HCT594 chains: read frame ({SERIAL_IO_IN:04X}h in), the t10 pause "
           f"(cut), write frame ({SERIAL_IO_OUT.hex().upper()}h out), /Conv stores the outputs.",
           lambda: _serial_io_trace(DataDirection.IN_OUT, _shift_in(), ShiftOut(2)), serial_io_wavejson),
)
"""The serial I/O figures (3.3.2), in the manual's order."""


# ------------------------------------------------------------------------------------------------------------
# Serial register expansion (3.5): Figure 3-23, redrawn from a pin-level ring trace
# ------------------------------------------------------------------------------------------------------------

EXPANSION_STRAPS: Final[tuple[str, str]] = ("10011", "1110")
"""C4..0 and MFP15..12 of the expansion figure's chip: remote bus device, Init-µP (ExtReg is a SET bit, 3.4.11)."""
EXPANSION_OUT: Final = b"\x14\x56\x78"
"""The OUT data of the expansion figure's data cycle: the manual's example of Figure 3-24."""
EXPANSION_IN: Final = b"\xa1\xb2\xc3"
"""The chain's input registers, bytes 0..2 from ToExR (any)."""
EXPANSION_GAP_BITS: Final = 10
"""Idle bits the master leaves before and after the data cycle: more than the 7.75 after a latched data cycle that
keep its first ClkExR rise after the end pulses before it (RX-4)."""
SHOWN_BITS: Final = 8
"""The data cycle's last bits drawn (its last byte)."""


def _expansion_code(levels: ExpansionLevels) -> int:
    """The expansion outputs as one integer: bit ``i`` is pin ``EXPANSION_PINS[i]``."""
    return sum(getattr(levels, name) << i for i, name in enumerate(EXPANSION_PINS))


class _ChainRecorder:
    """External registers passing every call to ``chain`` that keep, in call order, the pins of each pin-level
    :meth:`clock` call (:func:`_expansion_code`) and the FromExR level the chain answered."""

    def __init__(self, chain: ExternalRegisters) -> None:
        self.registers = chain
        self.answers: list[tuple[int, int]] = []

    @property
    def length(self) -> int:
        """As the chain."""
        return self.registers.length

    def chain(self) -> bytes:
        """The chain's contents (transaction level; not used by the figures)."""
        return self.registers.chain()

    def shift_cycle(self, received: bytes) -> None:
        """A data cycle shifted through (transaction level; not used by the figures)."""
        self.registers.shift_cycle(received)

    def take_outputs(self) -> None:
        """LaOuD (transaction level; not used by the figures)."""
        self.registers.take_outputs()

    def load_inputs(self) -> None:
        """/LaInD (transaction level; not used by the figures)."""
        self.registers.load_inputs()

    def clear(self) -> None:
        """/ResReg (transaction level; not used by the figures)."""
        self.registers.clear()

    def clock(self, levels: ExpansionLevels) -> int:
        """The chain's answer to ``levels``, kept."""
        answer = self.registers.clock(levels)
        self.answers.append((_expansion_code(levels), answer))
        return answer


@dataclass(frozen=True)
class ExpansionTrace:
    """The end of a data cycle with ExtReg = 1 (3.5) cut from the pin trace of a chip in a ring: its last
    :data:`SHOWN_BITS` data bits and the end pulses, with the FromExR levels the chain drove."""

    config: DeviceConfig
    chain: Sre1
    """The external registers, after the cycle."""
    start: int
    """The chip clock of index 0."""
    pins: dict[str, Trace]
    """ClkExR, ToExR, FromExR (what the chain drove), LaOuD and /LaInD by pin name."""
    rises: tuple[int, ...]
    """The indexes of the ClkExR rises of the bits drawn."""
    samples: tuple[int, ...]
    """The indexes of the ticks at which the chip takes FromExR for the bits drawn (RX-3)."""
    cut: range
    """The indexes left out: from after the last ClkExR pulse to before LaOuD."""
    pulses: tuple[int, int, int, int]
    """The indexes of LaOuD's rise and fall and /LaInD's fall and rise."""
    out_byte: int
    """The byte on ToExR in the bits drawn (the data cycle's last, LSB first)."""
    in_byte: int
    """The byte the chip took from FromExR in the bits drawn (the loopback word's last, shifted through the chain)."""


def _edges(trace: Trace, rising: bool) -> Trace:
    """The indexes where ``trace`` rises (or falls)."""
    return np.flatnonzero(np.diff(trace) == (1 if rising else -1)) + 1


def _expansion_trace() -> ExpansionTrace:
    """A chip with ExtReg = 1 and an IBS SRE 1 chain of 3 bytes, started by a master and given one data cycle with
    the manual's OUT data; the trace around the cycle's end, checked against Table 3-15 and the data moved.

    Raises
    ------
    TraceTimingError
        The chip's trace breaks a row of Table 3-15 (:func:`supi3.verif.timing.check_expansion`).
    FigureTraceError
        The master's cycles fail, the end pulses overrun, or the bits on ToExR and FromExR are not the data moved.
    """
    config = decode(*EXPANSION_STRAPS, clk_conf=clk_conf_for(TRACE_BIT_RATE))
    pins = Supi3Pins(config)
    registers = pins.chip.registers
    assert registers is not None  # an Init-µP mode
    code = next(int(lc.code, 2) for lc in tables.LENGTH_CODES if lc.bits == 8 * len(EXPANSION_OUT))
    registers.cpu_write(SET.address, SET.encode(EXTREG=1, LENGTH_CODE=code))
    registers.cpu_write(ID.address, ID_DIGITAL_OUTPUT)
    chain = Sre1(len(EXPANSION_OUT))
    chain.set_inputs(EXPANSION_IN)
    recorder = _ChainRecorder(chain)
    pins.chip.attach_expansion(recorder)
    ring = PinRing([pins], record=True)
    ring.idle(POWER_UP_S)
    master = Master(ring, locate=False)
    started = master.start()
    ring.idle(EXPANSION_GAP_BITS / ring.bit_rate)
    master.set_outputs(1, EXPANSION_OUT)
    cycle_from = ring.cycle
    data = master.data_cycle()
    ring.idle(2 * EXPANSION_GAP_BITS / ring.bit_rate)  # the end pulses last 13 t0 after the latch
    if not (started.ok and data.ok) or pins.chip.events["EXPANSION_OVERRUN"]:
        raise FigureTraceError(f"the master's cycles failed or overran: {started}, {data}, {pins.chip.events}")
    traced = ring.recorded()[0]
    codes = sum(traced[name] << i for i, name in enumerate(EXPANSION_PINS))
    assert isinstance(codes, np.ndarray)
    from_exr = _answered(codes, recorder.answers, PERIPHERAL_DELAY_CLOCKS)
    raise_first(check_expansion(traced, bit_rate=config.bit_rate, from_exr=from_exr))
    cpb = ring.cpb
    rises = _edges(traced["clk_exr"][cycle_from:], True) + cycle_from
    samples = rises - cpb // 4 - 1  # the tick before ToExR shows the bit (RX-3)
    # The bits the chip sent on ToExR (the loopback word, then the OUT data) and took from FromExR (the chain's
    # contents: the IN data the master got, then the loopback word shifted through), LSB first (Figure 3-24; the
    # tick's FromExR is the pin's level through the synchroniser).
    sent = np.packbits(traced["to_exr"][rises].astype(np.uint8), bitorder="little").tobytes()
    taken = np.packbits(from_exr[samples - SYNC_STAGES].astype(np.uint8), bitorder="little").tobytes()
    if sent != LOOPBACK_BYTES_ON_LINE + EXPANSION_OUT or taken != master.inputs(1) + LOOPBACK_BYTES_ON_LINE:
        raise FigureTraceError(f"ToExR carried {sent.hex()}, FromExR gave {taken.hex()}")
    (la_ou_rise,) = _edges(traced["la_ou_d"][cycle_from:], True) + cycle_from
    (la_ou_fall,) = _edges(traced["la_ou_d"][cycle_from:], False) + cycle_from
    (la_in_fall,) = _edges(traced["la_in_d_n"][cycle_from:], False) + cycle_from
    (la_in_rise,) = _edges(traced["la_in_d_n"][cycle_from:], True) + cycle_from
    step = cpb // 4
    c0 = int(rises[-SHOWN_BITS]) - cpb // 4 - MARGIN_COLUMNS * step
    stop = int(la_in_rise) + MARGIN_COLUMNS * step
    if stop > len(codes):
        raise FigureTraceError(f"the trace ends at clock {len(codes)}, before the figure's end {stop}")
    window = {name: traced[name][c0:stop] for name in ("clk_exr", "to_exr", "la_ou_d", "la_in_d_n")}
    window["from_exr"] = from_exr[c0:stop]
    cut = range(int(rises[-1]) + 3 * step + MARGIN_COLUMNS * step - c0, int(la_ou_rise) - MARGIN_COLUMNS * step - c0)
    return ExpansionTrace(
        config, chain, c0, window, tuple(int(r) - c0 for r in rises[-SHOWN_BITS:]),
        tuple(int(s) - c0 for s in samples[-SHOWN_BITS:]), cut,
        (int(la_ou_rise) - c0, int(la_ou_fall) - c0, int(la_in_fall) - c0, int(la_in_rise) - c0),
        EXPANSION_OUT[-1], taken[-1],
    )


def expansion_wavejson(trace: ExpansionTrace, title: str) -> dict[str, object]:
    """The WaveJSON of the end of a data cycle with register expansion: one column per quarter ClkExR period (a
    quarter bit), each showing the pins in its last clock, the time between the last ClkExR pulse and LaOuD cut to
    a gap.

    Lanes ClkExR, ToExR, FromExR, LaOuD and /LaInD (Table 3-14); under ToExR the names of the bits it carries (the
    data cycle's last byte, D0 first: LSB first, Figure 3-24) from the first clock it shows each; under FromExR the
    bits the chip takes, each after the sample of the bit before up to its own (RX-3). Arrows: t6 (LaOuD high), t7
    (LaOuD fall to /LaInD fall) and t5 (/LaInD low) of Table 3-15.

    Raises
    ------
    ArgumentError
        ``trace`` not an :class:`ExpansionTrace`, ``title`` not a str.
    """
    check_instance("trace", trace, ExpansionTrace)
    check_instance("title", title, str, "a str")
    step = (trace.rises[1] - trace.rises[0]) // 4  # ClkExR's period is a bit (Table 3-15 t0)
    length = len(trace.pins["clk_exr"])
    columns = _columns(length, step, trace.cut)
    shows = [r - step for r in trace.rises]  # ToExR shows bit k a quarter bit before its rise
    after = trace.rises[-1] + 3 * step

    def name(k: int) -> str:
        return f"D{k}"

    def pin(signal: str) -> Callable[[int], str]:
        return lambda c: str(int(trace.pins[signal][c]))

    la_ou_d = _level_lane("LaOuD", columns, pin("la_ou_d"))
    la_in_d_n = _level_lane("/LaInD", columns, pin("la_in_d_n"))
    rise, fall, low, high = (edge + step - 1 for edge in trace.pulses)  # the columns each edge starts
    la_ou_d["node"] = _node(columns, {rise: "a", fall: "b"})
    la_in_d_n["node"] = _node(columns, {low: "c", high: "d"})
    signal = [
        _level_lane("ClkExR", columns, pin("clk_exr")),
        _level_lane("ToExR", columns, pin("to_exr")),
        _bit_lane("ToExR bit", columns, lambda c: bisect_right(shows, c) - 1 if shows[0] <= c < after else "z", name),
        _level_lane("FromExR", columns, pin("from_exr")),
        _bit_lane("FromExR bit", columns,
                  lambda c: bisect_left(trace.samples, c) if c <= trace.samples[-1] else "z", name),
        la_ou_d,
        la_in_d_n,
    ]
    config = trace.config
    foot = (f"SUPI 3 model trace ({config.function}, {config.bit_rate // 1000} kbit/s, ExtReg = 1, "
            f"{trace.chain!r}); ToExR {trace.out_byte:02X}h and FromExR {trace.in_byte:02X}h LSB first; one column "
            f"= {step} chip clocks = {step * 1e9 / CLOCK_HZ:.0f} ns; gap: from the last ClkExR pulse to LaOuD")
    return {"signal": signal, "edge": ["a<->b t6", "b<->c t7", "c<->d t5"], "head": {"text": title},
            "foot": {"text": foot}}


EXPANSION_FIGURES: Final[tuple[Figure[ExpansionTrace], ...]] = (
    Figure("fig3-23", "Figure 3-23 Serial register expansion interface timing",
           "ExtReg = 1 with an IBS SRE 1 chain of 3 bytes: the end of the data cycle carrying 14h 56h 78h (Figure "
           "3-24's example); its last byte 78h leaves on ToExR LSB first, a ClkExR pulse per bit, while FromExR "
           "gives the chip the loopback word's last byte 5Ah, back from the chain; after the latch LaOuD (the "
           "outputs take 78h 56h 14h), then /LaInD (the chain loads the inputs).",
           _expansion_trace, expansion_wavejson),
)
"""The register expansion figure (3.5)."""
ALL_FIGURES: Final[tuple[Figure[SpiTrace] | Figure[SerialIoTrace] | Figure[ExpansionTrace], ...]] = (
    *SERIAL_IO_FIGURES, *FIGURES, *EXPANSION_FIGURES)
"""Every redrawn figure, in the manual's order (what :func:`write_figures` writes)."""


def write_figures(out: Path, *, vcd: bool = False) -> list[Path]:
    """Write ``<name>.json`` (WaveJSON) and ``<name>.svg`` for every figure of :data:`FIGURES` into ``out``, and
    ``<name>.vcd`` too if ``vcd``; return the paths written. ``supi3 figures`` runs it.

    Raises
    ------
    ModuleNotFoundError
        When ``wavedrom`` (the ``docs`` extra) is not installed; checked before anything is written.
    ArgumentError
        ``out`` not a :class:`~pathlib.Path`, ``vcd`` not a bool (checked before anything is written).
    """
    check_instance("out", out, Path, "a pathlib.Path")
    check_bool("vcd", vcd)
    wavedrom_module()
    out.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []
    for figure in ALL_FIGURES:
        trace, wavejson = figure.wavejson()
        json_path = out / f"{figure.name}.json"
        json_path.write_text(json.dumps(wavejson, indent=2, ensure_ascii=False) + "\n", encoding="utf-8")
        svg_path = out / f"{figure.name}.svg"
        svg_path.write_text(render_svg(wavejson) + "\n", encoding="utf-8")
        written += [json_path, svg_path]
        if vcd and isinstance(trace, SpiTrace):
            written.append(write_spi_vcd(out / f"{figure.name}.vcd", trace))
    return written

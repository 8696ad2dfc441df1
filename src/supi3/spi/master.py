"""A software µP on the serial µP interface's pins: a bus-functional model of the SPI master, and its traces.

:class:`SoftMaster` drives :class:`~supi3.spi.slave_pins.SlavePins` (or a :class:`PinPort` such as
:class:`supi3.top.ChipPort`) pin by pin at the chip clock, within Table 3-7 (IBS SUPI 3 OPC UM E rev. 05, 3.4.2):
SCLK idles high, the µP changes its data on falling edges and both sides sample on rising edges (UP-5), one byte per
/SS low period (UP-7); the edges are placed by :class:`MasterTiming`. Every pin of every cycle can be recorded in
a :class:`SpiTrace`, which can be

* decoded back into bytes from the pins alone (:func:`decode_bytes`),
* written as a VCD (:func:`write_spi_vcd`),
* drawn as a timing diagram (:mod:`supi3.spi.figures`, which needs the ``docs`` extra for SVG).

This module needs only the base install (numpy, pyvcd).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Final, Protocol, runtime_checkable

from vcd import VCDWriter

from supi3 import tables
from supi3.checks import check_bits, check_bool, check_instance, check_int, check_real, fail
from supi3.model.registers import RegisterFile
from supi3.model.vcd import CLOCK_PS
from supi3.spi.slave_pins import INPUT_PINS, OUTPUT_PINS, PinsIn, PinsOut, SlavePins
from supi3.spi.upif import Mode, UpifUsageError
from supi3.timing import limit

__all__ = [
    "DecodedByte",
    "MasterTiming",
    "PinPort",
    "SoftMaster",
    "SpiTrace",
    "decode_bytes",
    "write_spi_vcd",
]

_EPSILON: Final[float] = 1e-6
"""Tolerance (in clock cycles) when rounding Table 3-7's times up to whole chip clocks."""

_LEAST_CLOCKS: Final[dict[str, int]] = {"low": 1, "high": 1, "lead": 0, "trail": 1, "gap": 1}
"""The fewest clocks each :class:`MasterTiming` field may hold and still make a byte (UP-45)."""
_LEAST_WHY: Final[dict[str, str]] = {
    "low": "SCLK low for a whole clock", "high": "SCLK high for a whole clock",
    "lead": "a count of clocks", "trail": "the eighth SCLK rise before /SS rises",
    "gap": "/SS high between bytes, UP-7",
}
"""Why each field has its floor, as the error quotes it."""


# ------------------------------------------------------------------------------------------------------------
# The software µP
# ------------------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class MasterTiming:
    """How a software µP places its edges, in chip-clock cycles.

    A byte is: /SS high for ``gap`` cycles (S/R takes its new level in the first of them), /SS low, ``lead``
    cycles later the first SCLK fall, eight SCLK periods of ``low`` + ``high`` cycles (the µP changes its data
    at each fall), except that after the eighth rise SCLK stays high and /SS rises ``trail`` cycles later.
    """

    low: int
    """SCLK low phase: the µP's data setup before the rising edge (t4)."""
    high: int
    """SCLK high phase: the µP's data hold after the rising edge (t5)."""
    lead: int
    """/SS fall to the first SCLK fall: t1, and t7 (the chip's first bit valid) before the first rise."""
    trail: int
    """Last SCLK rise to /SS rise: t2."""
    gap: int
    """/SS high between bytes: t6 (maximum, C/D settles) plus t8 (C/D stable before /SS falls)."""

    def __post_init__(self) -> None:
        # A timing may break Table 3-7 on purpose (a test of the chip's checks), but it must still be a byte: each
        # SCLK phase and the trail at least one clock, /SS high for at least one clock between bytes (UP-7).
        for name, lowest in _LEAST_CLOCKS.items():
            object.__setattr__(self, name, check_int(name, getattr(self, name), lowest, limit=_LEAST_WHY[name]))

    @property
    def period(self) -> int:
        """The SCLK period in chip clocks (t0)."""
        return self.low + self.high

    @classmethod
    def fastest(cls, bit_rate: int, *, sclk_hz: float | None = None,
                clock_hz: int = tables.CLOCK_HZ) -> MasterTiming:
        """The shortest timing within Table 3-7 at ``bit_rate``, at ``sclk_hz`` (default: the table's maximum,
        t0) rounded down to a whole number of chip clocks per period.

        Raises
        ------
        UpifUsageError
            If ``sclk_hz`` is faster than t0 allows.
        ArgumentError
            ``sclk_hz`` not a finite number >= 1, ``clock_hz`` not an integer >= 1.
        """

        clock_hz = check_int("clock_hz", clock_hz, 1, limit="chip clock in Hz")
        if sclk_hz is not None:
            sclk_hz = check_real("sclk_hz", sclk_hz, 1.0, limit="SCLK frequency in Hz")

        def cycles(seconds: float) -> int:
            return math.ceil(seconds * clock_hz - _EPSILON)

        def minimum(symbol: str) -> float:
            return limit("3-7", symbol, bit_rate)

        def maximum(symbol: str) -> float:
            return limit("3-7", symbol, bit_rate, maximum=True)

        shortest = cycles(minimum("t0"))
        period = shortest if sclk_hz is None else cycles(1 / sclk_hz)
        if period < shortest:
            raise UpifUsageError(f"SCLK {sclk_hz} Hz is faster than t0 = {minimum('t0') * 1e9:.0f} ns allows "
                                 f"at {bit_rate} bit/s (Table 3-7)")
        low = max(period - period // 2, cycles(minimum("t4")))
        high = max(period - low, cycles(minimum("t5")))
        return cls(low=low, high=high, lead=max(cycles(minimum("t1")), cycles(maximum("t7")) - low),
                   trail=cycles(minimum("t2")), gap=cycles(maximum("t6") + minimum("t8")))

    def aligned(self) -> MasterTiming:
        """The same timing with ``lead``, ``trail`` and ``gap`` rounded up to whole half periods, so that every
        edge of the µP falls on the grid that :func:`~supi3.spi.figures.to_wavejson` samples (needs
        ``low == high``)."""
        if self.low != self.high:
            raise UpifUsageError(f"aligned timing needs a symmetric SCLK, not low {self.low} / high {self.high}")
        half = self.low
        return replace(self, lead=-(-self.lead // half) * half, trail=-(-self.trail // half) * half,
                       gap=-(-self.gap // half) * half)


@dataclass
class SpiTrace:
    """Every pin of a stretch of consecutive chip-clock cycles, as a software µP and the chip drove them."""

    mode: Mode
    """The µP's interface type: the bit order on the wire (the initialization byte reads the same both ways)."""
    timing: MasterTiming
    clock_hz: int
    bit_rate: int
    first_cycle: int = 0
    """The chip cycle of the first recorded cycle."""
    inputs: list[PinsIn] = field(default_factory=list)
    outputs: list[PinsOut] = field(default_factory=list)
    mosi_oe: list[int] = field(default_factory=list)
    """1 while the µP drives MFP6 (always in Motorola mode; in Intel mode while /SS is low and S/R = 1)."""

    def __post_init__(self) -> None:
        check_instance("mode", self.mode, Mode, "a supi3.spi.upif.Mode")
        check_instance("timing", self.timing, MasterTiming)
        check_int("clock_hz", self.clock_hz, 1)
        check_int("bit_rate", self.bit_rate, 1)
        check_int("first_cycle", self.first_cycle, 0)
        lists = {"inputs": self.inputs, "outputs": self.outputs, "mosi_oe": self.mosi_oe}
        for name, items in lists.items():
            check_instance(name, items, list, "a list, one item per cycle")
        if not len(self.inputs) == len(self.outputs) == len(self.mosi_oe):
            raise fail("outputs", f"one item per cycle of inputs ({len(self.inputs)}), as mosi_oe",
                       f"{len(self.outputs)} outputs and {len(self.mosi_oe)} mosi_oe")

    def __len__(self) -> int:
        return len(self.inputs)

    def _cycle(self, k: int) -> int:
        """``k`` as an index of a recorded cycle (0 to ``len - 1``), else the named error."""
        if type(k) is int and 0 <= k < len(self.inputs):
            return k
        return check_int("k", k, 0, len(self.inputs) - 1, limit="a recorded cycle")

    def window(self, start: int, stop: int | None = None) -> SpiTrace:
        """The cycles ``start`` to ``stop`` (indices into this trace, as a slice takes them) as a trace of their own.

        Raises
        ------
        ArgumentError
            ``start`` not an integer, ``stop`` neither an integer nor ``None``.
        """
        start = check_int("start", start)
        if stop is not None:
            stop = check_int("stop", stop)
        return replace(self, first_cycle=self.first_cycle + start, inputs=self.inputs[start:stop],
                       outputs=self.outputs[start:stop], mosi_oe=self.mosi_oe[start:stop])

    def mfp6_line(self, k: int) -> str:
        """The level on MFP6 in cycle ``k``: ``"0"``/``"1"``, ``"z"`` if nobody drives, ``"x"`` if both do."""
        k = self._cycle(k)
        chip, mosi = self.outputs[k].mfp6_oe, self.mosi_oe[k]
        if chip and mosi:
            return "x"
        if chip:
            return str(self.outputs[k].mfp6)
        return str(self.inputs[k].mfp6) if mosi else "z"

    def mfp7_line(self, k: int) -> str:
        """The level on MFP7 in cycle ``k``: the chip's SerOUT (Motorola) or the µP's S/R (Intel)."""
        k = self._cycle(k)
        if self.outputs[k].mfp7_oe:
            return str(self.outputs[k].mfp7)
        return str(self.inputs[k].mfp7) if self.mode is Mode.INTEL else "z"


@runtime_checkable
class PinPort(Protocol):
    """Pins :class:`SoftMaster` drives besides :class:`SlavePins`: the whole chip's, :class:`supi3.top.ChipPort`."""

    @property
    def registers(self) -> RegisterFile:
        """The chip's register file."""

    @property
    def clock_hz(self) -> int:
        """The chip clock."""

    @property
    def cycle(self) -> int:
        """The chip's clock cycles since reset."""

    def run(self, pins: PinsIn, cycles: int) -> list[PinsOut]:
        """Hold the µP's ``pins`` for ``cycles`` cycles; the µP interface's outputs of each."""


class SoftMaster:
    """A software µP on the pins of :class:`SlavePins` or of the whole chip (:class:`~supi3.top.Supi3Chip`
    through a :class:`~supi3.top.ChipPort`), one chip clock at a time.

    Parameters
    ----------
    chip:
        The pin-level model it drives: :class:`SlavePins`, or a :class:`PinPort` such as ``ChipPort(Supi3Chip(...))``
        (the whole chip's MFP pins; its other input pins held or fed by the port).
    mode:
        The µP's interface type (bit order: Intel LSB first, Motorola MSB first; UP-6).
    timing:
        Edge placement; default :meth:`MasterTiming.fastest` at the chip's bit rate.
    record:
        Keep every cycle's pins for :meth:`trace` (off for benchmarks).

    Raises
    ------
    ArgumentError
        ``chip`` neither a :class:`SlavePins` nor a :class:`PinPort`, ``mode`` not a :class:`Mode`, ``timing`` not a
        :class:`MasterTiming` or ``None``, ``record`` not a bool.
    """

    def __init__(self, chip: SlavePins | PinPort, mode: Mode, timing: MasterTiming | None = None, *,
                 record: bool = True) -> None:
        if not isinstance(chip, SlavePins | PinPort):
            raise fail("chip", "a SlavePins or a PinPort (such as supi3.top.ChipPort)", chip)
        check_instance("mode", mode, Mode, "a supi3.spi.upif.Mode")
        if timing is not None:
            check_instance("timing", timing, MasterTiming, "a MasterTiming or None")
        check_bool("record", record)
        bit_rate = chip.registers.config.bit_rate
        self.chip = chip
        """What the master drives: the interface's pins (:class:`SlavePins` or a :class:`PinPort`)."""
        self.mode = mode
        self._last: PinsOut | None = None
        self.timing = timing or MasterTiming.fastest(bit_rate, clock_hz=chip.clock_hz)
        self._pins = PinsIn()
        self._mosi_oe = int(mode is Mode.MOTOROLA)
        self._trace: SpiTrace | None = (
            SpiTrace(mode, self.timing, chip.clock_hz, bit_rate, first_cycle=chip.cycle) if record else None
        )

    @property
    def cycle(self) -> int:
        """The chip cycle the next :meth:`run` starts with."""
        return self.chip.cycle

    def run(self, cycles: int, **changes: int) -> list[PinsOut]:
        """Apply ``changes`` (pin names of :class:`PinsIn`) and hold the pins for ``cycles`` cycles; return the
        outputs of those cycles (the first is what the µP sees right at its edge).

        Raises
        ------
        ArgumentError
            ``cycles`` not an integer >= 0, a name not a pin of :class:`PinsIn` or a level not 0 or 1 (nothing
            changes).
        """
        check_int("cycles", cycles, 0)
        for name in changes:
            if name not in INPUT_PINS:
                raise fail("pin", f"one of {', '.join(INPUT_PINS)}", name)
        self._pins = replace(self._pins, **changes)
        chip = self.chip
        outputs = [chip.tick(self._pins) for _ in range(cycles)] if isinstance(chip, SlavePins) \
            else chip.run(self._pins, cycles)
        if outputs:
            self._last = outputs[-1]
        if self._trace is not None:
            self._trace.inputs.extend([self._pins] * cycles)
            self._trace.outputs.extend(outputs)
            self._trace.mosi_oe.extend([self._mosi_oe] * cycles)
        return outputs

    @property
    def outputs(self) -> PinsOut:
        """The chip's µP interface outputs in the last cycle run: C/D (MFP2), /IRQ (MFP3), the I/O bit (MFP1) and
        the serial data outputs, with their enables, as the µP reads them now.

        Raises
        ------
        UpifUsageError
            No cycle ran yet.
        """
        if self._last is None:
            raise UpifUsageError("no cycle ran yet: run() the master first")
        return self._last

    @property
    def c_d(self) -> int:
        """The C/D level (MFP2) in the last cycle: 0 = command or initialization byte next, 1 = data byte."""
        return self.outputs.c_d

    @property
    def irq_n(self) -> int:
        """The /IRQ level (MFP3) in the last cycle: 0 while an interrupt event is pending (3.4.14)."""
        return self.outputs.irq_n

    @property
    def io(self) -> int:
        """The I/O access bit (MFP1) in the last cycle: 1 while the data registers must not be accessed (3.4.14)."""
        return self.outputs.io

    def pulse_sas_init(self, cycles: int | None = None) -> None:
        """SAS_INIT (MFP0) high for ``cycles`` clocks, default the shortest Table 3-7 allows (t_SAS_INIT), then low
        again: the interface expects an initialization byte, the registers keep their values (3.4.3). /SS is
        high meanwhile (a frame in progress ends).

        Raises
        ------
        ArgumentError
            ``cycles`` not an integer >= 1.
        """
        shortest = math.ceil(limit("3-7", "t_SAS_INIT", self.chip.registers.config.bit_rate) * self.chip.clock_hz
                             - _EPSILON)
        self.run(shortest if cycles is None else check_int("cycles", cycles, 1), ss_n=1, sas_init=1)
        self.run(1, sas_init=0)

    def deselect(self, *, s_r: bool | None = None) -> None:
        """/SS high (it rises now if it was low) for the gap between bytes; in Intel mode S/R takes ``s_r`` in
        the same cycle (t10, t11) and the µP releases Ser_IN/OUT.

        Raises
        ------
        ArgumentError
            ``s_r`` neither a bool nor ``None``.
        """
        if s_r is not None:
            check_bool("s_r", s_r)
        self._mosi_oe = int(self.mode is Mode.MOTOROLA)
        level = self._pins.mfp7 if s_r is None or self.mode is Mode.MOTOROLA else int(s_r)
        self.run(self.timing.gap, ss_n=1, mfp7=level)

    def byte(self, mosi: int = 0, *, s_r: bool = True) -> int | None:
        """One byte: :meth:`deselect` (the gap), /SS low, 8 SCLK periods, SCLK high until /SS may rise.

        /SS rises, and the chip processes the byte, at the start of the next byte's gap or of :meth:`deselect`.

        Parameters
        ----------
        mosi:
            The byte the µP shifts out: on SerIN in Motorola mode, on Ser_IN/OUT in Intel mode with ``s_r``.
        s_r:
            Intel mode: the S/R level (Table 3-9; ``False``: the µP receives and leaves Ser_IN/OUT to the chip).

        Returns
        -------
        int | None
            The byte the µP sampled from the chip at the rising edges (SerOUT, or Ser_IN/OUT with S/R = 0),
            ``None`` if the chip did not drive at all eight.

        Raises
        ------
        ArgumentError
            ``mosi`` not a byte (0 to 255), ``s_r`` not a bool (nothing is sent).
        """
        mosi = check_bits("mosi", mosi, 8, "one byte per /SS low period, UP-7")
        check_bool("s_r", s_r)
        t = self.timing
        intel = self.mode is Mode.INTEL
        sends = not intel or s_r
        self.deselect(s_r=s_r)
        self._mosi_oe = int(sends)
        self.run(t.lead, ss_n=0)
        received: int | None = 0
        for i in range(8):
            shift = i if self.mode.lsb_first else 7 - i
            self.run(t.low, sclk=0, mfp6=(mosi >> shift) & 1 if sends else self._pins.mfp6)
            [out] = self.run(1, sclk=1)
            driven, bit = (out.mfp6_oe, out.mfp6) if intel else (out.mfp7_oe, out.mfp7)
            received = received | bit << shift if driven and received is not None else None
            self.run((t.high if i < 7 else t.trail) - 1)
        return received

    def trace(self) -> SpiTrace:
        """Everything recorded since the master was made."""
        if self._trace is None:
            raise UpifUsageError("this master was made with record=False")
        return self._trace


# ------------------------------------------------------------------------------------------------------------
# Reading a trace
# ------------------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class DecodedByte:
    """One /SS low period of a trace, read from the pins alone."""

    start: int
    """Index of the first cycle with /SS low."""
    stop: int
    """Index of the cycle in which /SS rose."""
    c_d: int
    """C/D when /SS fell: what the chip expected (0 command or initialization byte, 1 data; UP-2)."""
    s_r: int | None
    """S/R when /SS fell (Intel mode), else ``None``."""
    edges: int
    """Rising SCLK edges while /SS was low (8 in a valid frame)."""
    to_chip: int | None
    """The byte on SerIN (Ser_IN/OUT driven by the µP) at the first eight rising edges, ``None`` if not driven."""
    from_chip: int | None
    """The byte the chip drove on SerOUT (Ser_IN/OUT) at those edges, ``None`` if it did not drive at all."""


def _assemble(bits: Sequence[int | None], lsb_first: bool) -> int | None:
    if len(bits) < 8 or None in bits[:8]:
        return None
    value = 0
    for i, bit in enumerate(bits[:8]):
        assert bit is not None
        value |= bit << (i if lsb_first else 7 - i)
    return value


def decode_bytes(trace: SpiTrace) -> list[DecodedByte]:
    """Every complete /SS low period of ``trace`` (a /SS fall and the following rise), sampled at the rising
    SCLK edges as the µP and the chip sample them (UP-5, UP-6).

    Raises
    ------
    ArgumentError
        ``trace`` not a :class:`SpiTrace`.
    """
    check_instance("trace", trace, SpiTrace)
    intel = trace.mode is Mode.INTEL
    found: list[DecodedByte] = []
    start: int | None = None
    rises: list[int] = []
    for k in range(1, len(trace)):
        prev, pins = trace.inputs[k - 1], trace.inputs[k]
        if prev.ss_n and not pins.ss_n:
            start, rises = k, []
        elif start is not None and not pins.ss_n and pins.sclk and not prev.sclk:
            rises.append(k)
        elif start is not None and pins.ss_n and not prev.ss_n:
            to_chip: list[int | None] = []
            from_chip: list[int | None] = []
            for r in rises:
                out = trace.outputs[r]
                chip_oe, chip_bit = (out.mfp6_oe, out.mfp6) if intel else (out.mfp7_oe, out.mfp7)
                to_chip.append(trace.inputs[r].mfp6 if trace.mosi_oe[r] and not out.mfp6_oe else None)
                from_chip.append(chip_bit if chip_oe else None)
            found.append(DecodedByte(
                start=start, stop=k, c_d=trace.outputs[start].c_d,
                s_r=trace.inputs[start].mfp7 if intel else None, edges=len(rises),
                to_chip=_assemble(to_chip, trace.mode.lsb_first),
                from_chip=_assemble(from_chip, trace.mode.lsb_first),
            ))
            start = None
    return found


# ------------------------------------------------------------------------------------------------------------
# VCD
# ------------------------------------------------------------------------------------------------------------


def write_spi_vcd(path: Path, trace: SpiTrace) -> Path:
    """Write every pin of ``trace`` to ``path`` as a VCD (time step one 32 MHz clock, only changes written).

    Scopes: ``upif.up`` the µP's pins (:data:`~supi3.spi.slave_pins.INPUT_PINS` plus ``mosi_oe``), ``upif.chip``
    the chip's outputs and enables (:data:`~supi3.spi.slave_pins.OUTPUT_PINS`), ``upif.line`` the resolved
    levels of MFP6 and MFP7 (``z`` undriven, ``x`` driven by both).

    Raises
    ------
    ArgumentError
        ``path`` not a :class:`~pathlib.Path`, ``trace`` not a :class:`SpiTrace` or without a cycle (nothing is
        written).
    """
    check_instance("path", path, Path, "a pathlib.Path")
    check_instance("trace", trace, SpiTrace)
    if not len(trace):
        raise fail("trace", "a trace of at least one cycle", trace)
    probes: list[tuple[str, str, Callable[[int], int | str]]] = [
        *(("upif.up", name, lambda k, name=name: int(getattr(trace.inputs[k], name))) for name in INPUT_PINS),
        ("upif.up", "mosi_oe", lambda k: trace.mosi_oe[k]),
        *(("upif.chip", name, lambda k, name=name: int(getattr(trace.outputs[k], name))) for name in OUTPUT_PINS),
        ("upif.line", "mfp6", trace.mfp6_line),
        ("upif.line", "mfp7", trace.mfp7_line),
    ]
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", encoding="ascii") as stream, VCDWriter(stream, timescale="1 ps", date="") as writer:
        variables = [(writer.register_var(scope, name, "wire", size=1, init=probe(0)), probe)
                     for scope, name, probe in probes]
        last = [probe(0) for _, probe in variables]
        for k in range(1, len(trace)):
            for i, (var, probe) in enumerate(variables):
                value = probe(k)
                if value != last[i]:
                    writer.change(var, k * CLOCK_PS, value)
                    last[i] = value
    return path

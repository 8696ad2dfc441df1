"""The whole chip at pin level: the INTERBUS core and, in the Init-µP modes, the serial µP interface.

:class:`Supi3Chip` joins :class:`~supi3.model.pins.Supi3Pins` (the INTERBUS core) and
:class:`~supi3.spi.slave_pins.SlavePins` (the serial µP interface of 3.4) through the one register file both
use: the interface reads and writes it on the µP's accesses, the core latches OUT data into it, takes IN data
from it, and raises its interrupt events, I/O access bit and latch phase (docs/upif.md, "Register file").

MFP[7..0] are the µP interface's pins in the Init-µP modes (Tables 3-5 and 3-6): SAS_INIT on MFP0, I/O on
MFP1, C/D on MFP2, /IRQ on MFP3, SCLK on MFP4, /SS on MFP5, SerIN or Ser_IN/OUT on MFP6, SerOUT or S/R on MFP7.
MFP[15..8] stay with the core (bus terminal signals in BK modes). While the core is in reset (it drives
``resu_drive``, or a power-up reset begins at this clock edge), the µP interface is held in reset too (docs/model.md
M2).
"""

from __future__ import annotations

from collections import deque
from collections.abc import Mapping, Sequence
from typing import Final

import numpy as np
import numpy.typing as npt

from supi3 import pinout
from supi3.checks import check_bits, check_bool, check_instance, check_int, check_trace, fail
from supi3.config import DeviceConfig
from supi3.model.chip import STATERR_FILTER_CLOCKS, Supi3
from supi3.model.pins import PinTrace, Supi3Pins, split_optical_traces
from supi3.model.registers import RegisterFile
from supi3.pinlevel import OE_SUFFIX, Pin
from supi3.spi.slave_pins import QUIET_FOREVER, PinsIn, PinsOut, SlavePins
from supi3.spi.upif import UpifUsageError

UP_INPUTS: Final = pinout.UP_INPUTS
"""The MFP pin of each input of the µP interface (:class:`PinsIn` field, Tables 3-5 and 3-6)."""
UP_OUTPUTS: Final = pinout.UP_OUTPUTS
"""The MFP pin of each output of the µP interface (:class:`PinsOut` field; its enable is ``<field>_oe``)."""
UP_PINS: Final = pinout.UP_PINS
"""MFP[7..0]: the µP interface's pins in the Init-µP modes."""


def up_pin_inputs(mfp: int) -> PinsIn:
    """The µP interface's inputs from the MFP[15..0] input levels."""
    mfp = check_bits("mfp", mfp, 16)
    return PinsIn(**{name: (mfp >> pin) & 1 for name, pin in UP_INPUTS.items()})


def up_pin_outputs(up: PinsOut) -> tuple[int, int]:
    """The MFP levels (undriven bits 0) and output enables of the µP interface's outputs ``up``."""
    check_instance("up", up, PinsOut)
    enables = sum(getattr(up, name + OE_SUFFIX) << pin for name, pin in UP_OUTPUTS.items())
    levels = sum(getattr(up, name) << pin for name, pin in UP_OUTPUTS.items())
    return levels & enables, enables


def up_input_levels(pins: PinsIn) -> int:
    """The MFP levels of the µP interface's inputs ``pins`` (the other MFP bits 0): the inverse of
    :func:`up_pin_inputs`."""
    check_instance("pins", pins, PinsIn)
    return sum(getattr(pins, name) << pin for name, pin in UP_INPUTS.items())


def up_outputs_of(mfp_out: int, mfp_oe: int) -> PinsOut:
    """The µP interface's outputs as the MFP output levels and enables show them (an undriven output reads 0, as
    :func:`up_pin_outputs` gives it): the inverse of :func:`up_pin_outputs`."""
    mfp_out, mfp_oe = check_bits("mfp_out", mfp_out, 16), check_bits("mfp_oe", mfp_oe, 16)
    levels = {name: (mfp_out >> pin) & 1 for name, pin in UP_OUTPUTS.items()}
    enables = {name + OE_SUFFIX: (mfp_oe >> pin) & 1 for name, pin in UP_OUTPUTS.items()}
    return PinsOut(**levels, **enables)


class Supi3Chip:
    """One SUPI 3 chip, every pin, one 32 MHz clock per :meth:`step` (the convention of
    :mod:`supi3.pinlevel`), or many per :meth:`run`.

    Parameters
    ----------
    config:
        The pin straps.
    strict:
        µP interface rule violations (Table 3-7 timing, protocol, reconfiguration, inconsistent data) raise
        (``True``) or are recorded in ``registers.violations`` (``False``).
    pedantic:
        Also report suspicious µP accesses (:class:`~supi3.model.chip.Supi3`).
    stat_err_filter:
        The /StatErr filter in clocks (:class:`~supi3.model.chip.Supi3`: 200 ms by default, shorter only in tests).

    Attributes
    ----------
    core:
        The INTERBUS core (:class:`~supi3.model.pins.Supi3Pins`).
    upif:
        The serial µP interface (:class:`~supi3.spi.slave_pins.SlavePins`) in the Init-µP modes, else ``None``.

    Notes
    -----
    :meth:`run` is event-driven in every mode. The core and the µP interface meet only in the register file, and
    the core changes it only at the clock edges its scheduler visits (:meth:`Supi3Pins.run`, ``before``): before
    each, the µP interface catches up to that cycle, clock by clock where its pins move
    (:meth:`SlavePins.tick`; also through stretches shorter than :data:`HOLD_FROM`) and in one step where they hold
    (:meth:`SlavePins.hold`); when it already rests on pins that hold past that cycle, the catch-up is one
    :meth:`SlavePins.rests`. Within one cycle the core clocks first, as in :meth:`step`, so the two agree cycle for
    cycle (tested).
    """

    inputs: Sequence[Pin] = Supi3Pins.inputs
    outputs: Sequence[Pin] = Supi3Pins.outputs

    def __init__(self, config: DeviceConfig, *, strict: bool = True, pedantic: bool = False,
                 stat_err_filter: int = STATERR_FILTER_CLOCKS) -> None:  # fmt: skip
        check_instance("config", config, DeviceConfig)
        check_bool("strict", strict)
        self.core = Supi3Pins(config, Supi3(config, strict=strict, pedantic=pedantic, stat_err_filter=stat_err_filter))
        registers = self.core.chip.registers
        self.upif = SlavePins(registers) if registers is not None else None
        self._up_cycle = 0  # the cycle the µP interface clocks (UP-19: violations name it)
        self._pins_in: dict[int, PinsIn] = {}
        if registers is not None:
            registers.use_clock(lambda: self._up_cycle)

    @property
    def config(self) -> DeviceConfig:
        """The pin straps."""
        return self.core.config

    @property
    def chip(self) -> Supi3:
        """The bus behaviour (and, in µP modes, ``chip.registers``)."""
        return self.core.chip

    @property
    def cycle(self) -> int:
        """Clock cycles since reset."""
        return self.core.cycle

    @property
    def branch_in_path(self) -> bool:
        """A BK's branch is in the data path in the current cycle (:attr:`Supi3Pins.branch_in_path`)."""
        return self.core.branch_in_path

    def reset(self) -> None:
        """The state after the ``sync`` reset."""
        self.core.reset()
        if self.upif is not None:
            self.upif.reset()

    def _up_inputs(self, mfp: int) -> PinsIn:
        """:func:`up_pin_inputs` of MFP levels, each combination made once."""
        key = mfp & _UP_INPUT_MASK
        pins = self._pins_in.get(key)
        if pins is None:
            pins = self._pins_in[key] = up_pin_inputs(key)
        return pins

    def _tick_up(self, upif: SlavePins, pins: PinsIn) -> PinsOut:
        """One cycle of the µP interface, after the core's clock edge of the same cycle: held in reset with the
        core (M2)."""
        self._up_cycle = self.core.cycle - 1
        out = upif.tick(pins)
        core = self.core
        if core.holding or core.cycle - 1 < core.run_from:  # resu_drive during the cycle just run
            upif.reset()
        return out

    def step(self, inputs: Mapping[str, int]) -> dict[str, int]:
        """Run one clock cycle.

        Raises
        ------
        ArgumentError
            As :meth:`Supi3Pins.step`: a pin missing or unknown, or a level out of its pin's width (nothing changes).
        """
        out = self.core.step(inputs)
        upif = self.upif
        if upif is None:
            return out
        levels, enables = _up_levels(self._tick_up(upif, self._up_inputs(int(inputs["mfp_in"]))))
        out["mfp_out"] = (out["mfp_out"] & ~UP_PINS) | levels
        out["mfp_oe"] = (out["mfp_oe"] & ~UP_PINS) | enables
        return out

    def run(self, inputs: Mapping[str, Sequence[int] | npt.NDArray[np.generic]]) -> dict[str, PinTrace]:
        """Run as many clock cycles as the input traces are long, event-driven (see the class notes); the same
        outputs, state and violation records as :meth:`step` once per cycle.

        Raises
        ------
        ArgumentError
            As :meth:`Supi3Pins.run` (:func:`~supi3.model.pins.input_traces`); nothing changes.
        InterfaceViolationError
            In strict mode, the first violation of the µP interface's rules, once every cycle ran (:meth:`step`
            raises it at the end of its cycle).
        """
        return self._run(inputs, forward_only=False)

    def run_forward(self, inputs: Mapping[str, Sequence[int] | npt.NDArray[np.generic]]) -> dict[str, PinTrace]:
        """:meth:`run` without ``di1`` (:meth:`Supi3Pins.run_forward`), for a ring (:class:`~supi3.model.pinring.
        PinRing`), which then gets ``di1`` from :meth:`return_line`."""
        return self._run(inputs, forward_only=True)

    def return_line(self, di2: PinTrace, do2: PinTrace) -> PinTrace:
        """``di1`` over the last :meth:`run_forward` (:meth:`Supi3Pins.return_line`; the µP interface has no part
        in the return line)."""
        return self.core.return_line(di2, do2)

    def _run(self, inputs: Mapping[str, Sequence[int] | npt.NDArray[np.generic]], forward_only: bool
             ) -> dict[str, PinTrace]:  # fmt: skip
        upif = self.upif
        run = self.core.run_forward if forward_only else self.core.run
        if upif is None:
            return run(inputs)
        core, optical = split_optical_traces(inputs)  # every trace checked before the first cycle runs
        traces = {**core, **optical}
        catch_up = _CatchUp(self, upif, traces["mfp_in"])
        with upif.registers.violations.deferred():
            out = run(traces, before=catch_up)
            catch_up(len(traces["mfp_in"]))
        levels, enables = catch_up.render()
        out["mfp_out"] = (out["mfp_out"] & ~UP_PINS) | levels
        out["mfp_oe"] = (out["mfp_oe"] & ~UP_PINS) | enables
        return out


_UP_INPUT_MASK: Final = sum(1 << pin for pin in UP_INPUTS.values())
HOLD_FROM: Final = 4
""":meth:`Supi3Chip.run` ticks the µP interface (:meth:`SlavePins.tick`) through a stretch of held pins shorter than
this many cycles instead of holding it (:meth:`SlavePins.hold`): a hold that does not find the interface resting costs
about as much as this many ticks (bench/bench_chip.py; both give the same outputs and state)."""
_LEVELS: dict[PinsOut, tuple[int, int]] = {}
""":func:`up_pin_outputs` of every µP interface output combination seen (at most 2**10)."""


def _up_levels(up: PinsOut) -> tuple[int, int]:
    """:func:`up_pin_outputs`, each combination computed once."""
    levels = _LEVELS.get(up)
    if levels is None:
        levels = _LEVELS[up] = up_pin_outputs(up)
    return levels


class _CatchUp:
    """The µP interface's side of one :meth:`Supi3Chip.run`: called with a trace index ``stop``, it runs the
    interface's cycles up to ``stop`` (exclusive), holding where its pins and synchronisers rest, and records its
    outputs where they change."""

    def __init__(self, chip: Supi3Chip, upif: SlavePins, mfp: npt.NDArray[np.integer]) -> None:
        self.chip = chip
        self.upif = upif
        self.c0 = chip.core.cycle
        self.n = len(mfp)
        keys = np.asarray(mfp, dtype=np.int64) & _UP_INPUT_MASK
        # The pieces in which the µP interface's pins hold: where each ends, and its pins.
        starts = np.flatnonzero(np.diff(keys, prepend=-1))
        self.ends = [*starts[1:].tolist(), len(keys)]
        self.pins = [chip._up_inputs(key) for key in keys[starts].tolist()]
        self.k = 0
        self.done = 0
        self.outputs: list[tuple[int, PinsOut | None]] = [(0, None)]  # then the output of cycle 0 and each change

    def __call__(self, stop: int) -> None:
        t = self.done
        if t >= stop:
            return
        chip, upif, ends, outputs, c0, k = self.chip, self.upif, self.ends, self.outputs, self.c0, self.k
        # The core's state is that after its last clock edge before ``stop``, for every cycle from ``t`` on: the µP
        # interface is held in reset with the core (M2) while it holds or until its reset stretch ends.
        core = chip.core
        holding, run_from = core.holding, core.run_from
        # The common call: the interface rests on pins that hold until ``stop`` (ends[k] > t then) and shows the
        # outputs last recorded (a run's first cycle records its outputs: t > 0).
        if t and stop <= ends[k] and not holding and c0 + t >= run_from and upif.rests(self.pins[k], stop - t):
            chip._up_cycle = c0 + t  # as the hold below would leave it
            self.done = stop
            return
        while t < stop:
            while ends[k] <= t:
                k += 1
            end = ends[k] if ends[k] < stop else stop
            pins = self.pins[k]
            # Hold where no edge acts as long as the pins hold; a short stretch costs less ticked (bench/bench_chip.py),
            # and so do the quiet cycles before an edge that acts.
            ticks = end - t
            if ticks >= HOLD_FROM:
                quiet = 0 if holding or c0 + t < run_from else upif.quiet(pins)
                if quiet == QUIET_FOREVER:
                    chip._up_cycle = c0 + t  # a violation names the cycle (UP-19)
                    for i, out in upif.hold(pins, ticks):
                        if out is not outputs[-1][1]:
                            outputs.append((t + i, out))
                    t = end
                    continue
                ticks = quiet + 1
            # The core has run its edge of these cycles already: clock the µP interface's as step() does.
            for u in range(t, t + ticks):
                chip._up_cycle = c0 + u
                out = upif.tick(pins)
                if holding or c0 + u < run_from:
                    upif.reset()
                if out is not outputs[-1][1]:
                    outputs.append((u, out))
            t += ticks
        self.done, self.k = t, k

    def render(self) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]]:
        """The µP interface's MFP levels and output enables over the run."""
        n = self.n
        outputs = self.outputs[1:]
        starts = np.array([t for t, _ in outputs] + [n], dtype=np.int64)
        table = np.array([_up_levels(out) for _, out in outputs if out is not None], dtype=np.int64).reshape(-1, 2)
        lengths = np.diff(starts)
        return np.repeat(table[:, 0], lengths), np.repeat(table[:, 1], lengths)


UP_REST: Final = up_input_levels(PinsIn())
"""MFP[7..0] with the µP's pins at rest: SCLK and /SS high, MFP7 high, SAS_INIT and MFP6 low (:class:`PinsIn`)."""

QUIET_BOARD: Final[dict[str, int]] = {"do1": 1, "di2": 0, "rbst_ext": 0, "mfp_in": UP_REST, "stat_err_n": 1,
                                      "resu_n": 1, "vmon_ok": 1, "from_exr": 0}  # fmt: skip
"""The whole chip's inputs on a quiet board: the INTERBUS forward line idle (high, docs/interbus.md), no device
following, no /StatErr, /ResU released, power good, FromExR grounded; the µP's pins at rest (:data:`UP_REST`), the
other MFP pins low."""


STEP_BELOW: Final = 64
""":meth:`ChipPort.run` steps holds shorter than this cycle by cycle: a :meth:`Supi3Chip.run` call costs about as much
as this many :meth:`Supi3Chip.step` calls (both give the same outputs)."""


class ChipPort:
    """The serial µP interface's pins on the whole chip (:class:`~supi3.top.Supi3Chip` in an Init-µP mode): what
    :class:`~supi3.spi.master.SoftMaster` drives (``SoftMaster(ChipPort(chip), mode)``).

    The µP's pins go to MFP0 (SAS_INIT), MFP4 (SCLK), MFP5 (/SS), MFP6 (SerIN or Ser_IN/OUT) and MFP7 (S/R in
    Intel mode), Tables 3-5 and 3-6; every other input pin holds its level in :attr:`inputs` (MFP bits outside
    MFP[7..0] included), except the forward line ``do1``, which takes the samples queued by :meth:`feed` while there
    are any. Each :meth:`run` is one event-driven :meth:`Supi3Chip.run`, or :meth:`Supi3Chip.step` per cycle for a hold
shorter than :data:`STEP_BELOW` cycles.

    Parameters
    ----------
    chip:
        The whole chip, in an Init-µP mode.
    inputs:
        Levels of input pins to hold instead of :data:`QUIET_BOARD`'s (names of ``Supi3Chip.inputs``).

    Attributes
    ----------
    inputs:
        The held levels of every input pin (the µP's MFP bits are taken from the µP instead).
    last:
        Every output pin in the last cycle run (empty before the first).

    Raises
    ------
    ArgumentError
        ``chip`` not a :class:`Supi3Chip`, an input name unknown or a level out of its pin's width.
    UpifUsageError
        The chip is not in an Init-µP mode (it has no µP interface).
    """

    def __init__(self, chip: Supi3Chip, **inputs: int) -> None:
        check_instance("chip", chip, Supi3Chip)
        if chip.upif is None:
            raise UpifUsageError(f"the chip's MFP mode {chip.config.mfp_mode.kind.name} has no serial µP interface "
                                 "(Init-µP modes only, Tables 3-5 and 3-6)")
        widths = {pin.name: pin.width for pin in Supi3Chip.inputs}
        for name, level in inputs.items():
            if name not in widths:
                raise fail("inputs", f"input pin names of the chip ({', '.join(widths)})", name)
            inputs[name] = check_bits(f"pin {name!r}", level, widths[name])
        self.chip = chip
        self.upif: SlavePins = chip.upif
        self.inputs = {**QUIET_BOARD, **inputs}
        self.last: dict[str, int] = {}
        self._line: deque[int] = deque()
        self._outputs: dict[tuple[int, int], PinsOut] = {}

    @property
    def registers(self) -> RegisterFile:
        """The chip's register file."""
        return self.upif.registers

    @property
    def clock_hz(self) -> int:
        """The chip clock."""
        return self.upif.clock_hz

    @property
    def cycle(self) -> int:
        """The chip's clock cycles since reset."""
        return self.chip.cycle

    def feed(self, samples: Sequence[int] | npt.NDArray[np.integer]) -> None:
        """Queue forward-line samples (one per clock, 0 or 1) for ``do1``; they go in while the µP works, then
        ``do1`` holds ``inputs["do1"]`` again.

        Raises
        ------
        ArgumentError
            ``samples`` not a 1-D sequence of 0/1 integers (nothing is queued).
        """
        self._line.extend(check_trace("samples", samples, 1).tolist())

    @property
    def queued(self) -> int:
        """Forward-line samples fed and not yet sent."""
        return len(self._line)

    def run(self, pins: PinsIn, cycles: int) -> list[PinsOut]:
        """Hold the µP's ``pins`` for ``cycles`` clock cycles; return the µP interface's outputs of each cycle.

        Raises
        ------
        ArgumentError
            ``pins`` not a :class:`PinsIn`, ``cycles`` not an integer >= 0.
        """
        check_instance("pins", pins, PinsIn)
        check_int("cycles", cycles, 0)
        if not cycles:
            return []
        mfp = (self.inputs["mfp_in"] & ~UP_PINS) | up_input_levels(pins)
        line = [self._line.popleft() for _ in range(min(cycles, len(self._line)))]
        if cycles < STEP_BELOW:
            row = {**self.inputs, "mfp_in": mfp}
            rows = []
            for t in range(cycles):
                row["do1"] = line[t] if t < len(line) else self.inputs["do1"]
                rows.append(self.chip.step(row))
            self.last = rows[-1]
            levels = [(out["mfp_out"], out["mfp_oe"]) for out in rows]
        else:
            traces = {name: np.full(cycles, level, dtype=np.int64) for name, level in self.inputs.items()}
            traces["mfp_in"][:] = mfp
            traces["do1"][: len(line)] = line
            outs = self.chip.run(traces)
            self.last = {name: int(trace[-1]) for name, trace in outs.items()}
            levels = list(zip(outs["mfp_out"].tolist(), outs["mfp_oe"].tolist(), strict=True))
        cache = self._outputs
        result = []
        for key in levels:
            up = cache.get(key)
            if up is None:
                up = cache[key] = up_outputs_of(*key)
            result.append(up)
        return result

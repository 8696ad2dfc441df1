"""The serial µP interface at pin level: a synchronous machine clocked at the 32 MHz chip clock.

Ref: IBS SUPI 3 OPC UM E rev. 05, 3.4.1 - 3.4.3, Tables 3-5 to 3-7. This is the reference the Amaranth RTL of the
interface matches pin for pin. The protocol itself is :class:`supi3.spi.upif.UpifProtocol`; this module adds
the input synchronisers, the shift registers, the output pipeline and the timing checks of Table 3-7 around it.
The cycle-exact behaviour is specified in ``docs/upif.md`` ("Pin level"); in short, for cycle ``n``:

1. :meth:`SlavePins.tick` takes the input pins of cycle ``n`` (stable for the whole cycle) and returns the
   outputs seen during cycle ``n``; they depend on the state only (no combinational path from an input);
2. the clock edge ending cycle ``n`` updates the state from the state and the inputs of cycle ``n``.

Every input passes a 2-flop synchroniser (``s1``, ``s2``); edges are detected between ``s2`` and a third flop
``s3``. Outputs are the state decoded, delayed by ``output_delay`` = 2 * (clocks per TCLK) - 2 cycles, so that an
output changes 2 TCLK (to 2 TCLK + 1 clock) after the input edge that caused it, as Table 3-7's t3, t6, t7 and t9
require.
"""

from __future__ import annotations

import math
import sys
from collections import deque
from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass, fields
from typing import Final, NoReturn

from supi3 import tables
from supi3.checks import check_bits, check_bool, check_choice, check_instance, check_int, fail
from supi3.errors import ArgumentError
from supi3.model.registers import InterfaceViolationError, RegisterFile
from supi3.spi.upif import Mode, UpifProtocol, UpifUsageError
from supi3.timing import timing_table

__all__ = [
    "C_D_SETTLES_WITHIN",
    "INPUT_PINS",
    "OUTPUT_PINS",
    "QUIET_FOREVER",
    "SYNC_STAGES",
    "PinsIn",
    "PinsOut",
    "SlavePins",
    "TimingChecker",
    "TimingViolationError",
    "reaction_clocks",
    "shorter_than",
]

_EPSILON_S: Final[float] = 1e-12
"""Tolerance of the timing comparisons (the table's limits are floats)."""
SYNC_STAGES: Final[int] = 3
"""Clocks from an input's change at the pins (cycle ``n``) to the decoded state that shows it (after the edge ending
cycle ``n + 2``): the synchroniser's two flops, then the edge that acts."""


def reaction_clocks(bit_rate: int, clock_hz: int = tables.CLOCK_HZ) -> int:
    """Chip clocks from the cycle an input changes at the pins to the first cycle the outputs show its effect:
    :data:`SYNC_STAGES`, then the output pipeline (``SlavePins.output_delay``): 2 TCLK + 1 clock (UP-14); e.g. SerOUT
    released after /SS rose (MCU-74)."""
    return SYNC_STAGES + 2 * (clock_hz // (tables.TCLK_PER_BIT * bit_rate)) - 2


def shorter_than(clocks: int, clock_hz: int, minimum_s: float) -> bool:
    """Whether ``clocks`` chip clocks measure less than ``minimum_s``, within the timing checks' tolerance (the rule
    of :class:`TimingChecker`)."""
    return clocks / clock_hz + _EPSILON_S < minimum_s


class TimingViolationError(InterfaceViolationError):
    """A Table 3-7 timing requirement on the µP's signals was not met.

    Attributes
    ----------
    parameter:
        The Table 3-7 symbol (``"t1"``, ``"t_SAS_INIT"``, ...).
    measured_s:
        The measured time in seconds, or ``None`` when the signal changed inside a forbidden window (t11).
    required_s:
        The minimum the table requires.
    cycle:
        The chip-clock cycle at which the violation was seen.
    """

    def __init__(self, parameter: str, explanation: str, measured_s: float | None, required_s: float,
                 cycle: int) -> None:
        self.parameter = parameter
        self.measured_s = measured_s
        self.required_s = required_s
        self.cycle = cycle
        measured = "inside the forbidden window" if measured_s is None else f"measured {measured_s * 1e9:.2f} ns"
        super().__init__(f"Table 3-7 {parameter}",
                         f"{parameter} ({explanation}): {measured}, required >= {required_s * 1e9:.2f} ns "
                         f"at cycle {cycle}")


@dataclass(frozen=True)
class PinsIn:
    """The input pins of one cycle (Tables 3-5, 3-6), each 0 or 1. The defaults are the idle levels."""

    sas_init: int = 0
    """MFP0, SAS_INIT (active high)."""
    sclk: int = 1
    """MFP4, SCLK; idles high (UP-5)."""
    ss_n: int = 1
    """MFP5, /SS."""
    mfp6: int = 0
    """MFP6 as seen from outside: SerIN (Motorola) or the µP's level on Ser_IN/OUT (Intel). While the chip drives
    MFP6 (``mfp6_oe``), the chip reads its own output instead."""
    mfp7: int = 1
    """MFP7 as an input: S/R in Intel mode (Table 3-9); not used in Motorola mode (there it is SerOUT)."""

    def __post_init__(self) -> None:
        a, b, c, d, e = self.sas_init, self.sclk, self.ss_n, self.mfp6, self.mfp7
        if not (int is type(a) is type(b) is type(c) is type(d) is type(e) and not (a | b | c | d | e) >> 1):
            _check_levels(self)


@dataclass(frozen=True)
class PinsOut:
    """The output pins of one cycle, each with its output enable (``*_oe``, 1 = driven)."""

    io: int
    """MFP1, the I/O access bit (D7 of read 14)."""
    io_oe: int
    c_d: int
    """MFP2, C/D: 0 = command (or initialization) byte next, 1 = data byte next."""
    c_d_oe: int
    irq_n: int
    """MFP3, /IRQ."""
    irq_n_oe: int
    mfp6: int
    """MFP6, Ser_IN/OUT driven by the chip (Intel mode, S/R = 0)."""
    mfp6_oe: int
    mfp7: int
    """MFP7, SerOUT (Motorola mode)."""
    mfp7_oe: int

    def __post_init__(self) -> None:
        a, b, c, d, e = self.io, self.io_oe, self.c_d, self.c_d_oe, self.irq_n
        f, g, h, i, j = self.irq_n_oe, self.mfp6, self.mfp6_oe, self.mfp7, self.mfp7_oe
        if not (int is type(a) is type(b) is type(c) is type(d) is type(e) is type(f) is type(g) is type(h)
                is type(i) is type(j) and not (a | b | c | d | e | f | g | h | i | j) >> 1):
            _check_levels(self)


def _check_levels(pins: PinsIn | PinsOut) -> None:
    """Every field of ``pins`` a level, 0 or 1 (numpy integers become ``int``), else a named error."""
    for item in fields(pins):
        value = check_bits(f"pin {item.name!r}", getattr(pins, item.name), 1)
        object.__setattr__(pins, item.name, value)


INPUT_PINS: Final[tuple[str, ...]] = tuple(f.name for f in fields(PinsIn))
"""Input pin names, in :class:`PinsIn` order (the lockstep harness's column order)."""
OUTPUT_PINS: Final[tuple[str, ...]] = tuple(f.name for f in fields(PinsOut))
"""Output signal names, enables included, in :class:`PinsOut` order."""


@dataclass(slots=True)
class _Sync:
    """A 2-flop synchroniser plus the edge-detect flop: s1 <= pin, s2 <= s1, s3 <= s2 at every clock edge."""

    s1: int
    s2: int
    s3: int

    @property
    def rose(self) -> bool:
        return self.s2 == 1 and self.s3 == 0

    @property
    def fell(self) -> bool:
        return self.s2 == 0 and self.s3 == 1

    def clock(self, pin: int) -> None:
        self.s1, self.s2, self.s3 = pin, self.s1, self.s2

    def hold(self, pin: int, edges: int) -> None:
        """``edges`` clock edges with ``pin`` held."""
        if edges >= 3:
            self.s1 = self.s2 = self.s3 = pin
        elif edges == 2:
            self.s1, self.s2, self.s3 = pin, pin, self.s1
        elif edges == 1:
            self.clock(pin)


C_D_SETTLES_WITHIN: Final[str] = "t6"
"""After /SS rises, C/D may still change until the maximum of this Table 3-7 row (3 TCLK); a C/D change in that
window that comes after /SS fell again is a t8 violation: the µP read a stale C/D (docs/assumptions/model.md M14)."""


class TimingChecker:
    """Table 3-7's limits on the µP's signals, checked on the raw pins at chip-clock resolution.

    Ref: IBS SUPI 3 OPC UM E rev. 05, 3.4.2, Table 3-7. Every row that limits the µP's signals is checked (the rules
    are in docs/assumptions/model.md M14; measured = clocks / ``clock_hz`` between the first cycles showing the two
    changes):

    * t0, the SCLK period: rising to rising edge while /SS is low (the chip acts on rising edges only; UP-23);
    * t1: /SS fall to the frame's first SCLK fall; t2: the frame's last SCLK rise to the /SS rise (an SCLK rise in
      the cycle /SS rises counts as the frame's);
    * t4 (setup) and t5 (hold): a SerIN change against SCLK rises while /SS is low (not while the chip drives MFP6);
    * t8: /SS falls at least TCLK after C/D changed; and C/D must have settled: a C/D change up to t6's maximum
      after /SS rose (:data:`C_D_SETTLES_WITHIN`) that comes after /SS fell again is reported too, measured
      negative (the fall came first);
    * t10 and t11 (Intel, S/R on MFP7 may change only while /SS is high or in the cycle of either /SS edge): an S/R
      change while /SS is low before the frame's first SCLK fall is t10 (S/R became valid after /SS fell; measured
      negative), a later one t11 (it changed before /SS rose; measured ``None``);
    * t_SAS_INIT: the SAS_INIT high pulse width.

    t3, t6, t7 and t9 limit the chip's own outputs (guaranteed by docs/assumptions/upif.md UP-14, tested there).

    Parameters
    ----------
    bit_rate:
        The INTERBUS bit rate (bit/s) the limits are evaluated for.
    clock_hz:
        The chip clock, the resolution of the measurement.
    report:
        Called with each :class:`TimingViolationError`.
    """

    def __init__(self, bit_rate: int, clock_hz: int, report: Callable[[InterfaceViolationError], None]) -> None:
        check_choice("bit_rate", bit_rate, tables.BIT_RATES, "Table 1-7")
        check_int("clock_hz", clock_hz, 1)
        if not callable(report):
            raise fail("report", "a callable", report)
        self._limits = {t.symbol: t for t in timing_table("3-7", bit_rate)}
        settle = self._limits[C_D_SETTLES_WITHIN].maximum_s
        assert settle is not None
        self._settle = math.ceil(settle * clock_hz - _EPSILON_S * clock_hz)
        self._clock_hz = clock_hz
        self._report = report
        self.reset()

    def reset(self) -> None:
        """Forget every edge seen (the state after a power-up reset)."""
        self._pins = PinsIn()
        self._c_d: int | None = None
        self._last_c_d: int | None = None
        self._ss_fall: int | None = None
        self._ss_rise: int | None = None
        self._first_sclk_fall: int | None = None
        self._last_rise: int | None = None
        self._last_data: int | None = None
        self._sas_rise: int | None = None

    @property
    def last_pins(self) -> PinsIn:
        """The inputs of the last cycle checked (the idle levels after :meth:`reset`)."""
        return self._pins

    def _violation(self, symbol: str, cycle: int, clocks: int | None, note: str = "") -> None:
        limit = self._limits[symbol]
        assert limit.minimum_s is not None
        measured = None if clocks is None else clocks / self._clock_hz
        self._report(TimingViolationError(symbol, limit.explanation + note, measured, limit.minimum_s, cycle))

    def _require(self, symbol: str, cycle: int, since: int | None) -> None:
        """Report ``symbol`` if less than its minimum elapsed from cycle ``since`` to ``cycle``."""
        if since is None:
            return
        limit = self._limits[symbol]
        assert limit.minimum_s is not None
        if shorter_than(cycle - since, self._clock_hz, limit.minimum_s):
            self._violation(symbol, cycle, cycle - since)

    def check(self, cycle: int, pins: PinsIn, out: PinsOut, intel: bool) -> None:
        """Check the inputs of ``cycle`` against those of the cycle before; ``out`` are the outputs of ``cycle``.

        Raises
        ------
        ArgumentError
            ``cycle`` not an integer >= 0, ``pins`` not a :class:`PinsIn`, ``out`` not a :class:`PinsOut`, ``intel``
            not a bool; nothing changes.
        """
        if not (type(cycle) is int and cycle >= 0 and type(pins) is PinsIn and type(out) is PinsOut
                and type(intel) is bool):
            check_int("cycle", cycle, 0)
            check_instance("pins", pins, PinsIn)
            check_instance("out", out, PinsOut)
            check_bool("intel", intel)
        prev, self._pins = self._pins, pins
        fell, rose = prev.ss_n and not pins.ss_n, pins.ss_n and not prev.ss_n
        low = not pins.ss_n
        in_frame = low or rose  # an SCLK edge in the cycle /SS rises still belongs to the frame
        if self._c_d is not None and out.c_d != self._c_d:
            self._last_c_d = cycle
            stale = self._ss_rise is not None and cycle - self._ss_rise <= self._settle
            if stale and low and self._ss_fall is not None and self._ss_rise is not None \
                    and self._ss_rise < self._ss_fall < cycle:
                self._violation("t8", cycle, self._ss_fall - cycle, " (/SS fell before C/D changed)")
        self._c_d = out.c_d
        if fell:
            self._require("t8", cycle, self._last_c_d)
            self._ss_fall, self._first_sclk_fall, self._last_rise = cycle, None, None
        if pins.mfp6 != prev.mfp6 and not out.mfp6_oe:
            if low:
                self._require("t5", cycle, self._last_rise)
            self._last_data = cycle
        if in_frame and prev.sclk and not pins.sclk and self._first_sclk_fall is None:
            self._first_sclk_fall = cycle
            self._require("t1", cycle, self._ss_fall)
        if in_frame and pins.sclk and not prev.sclk:
            self._require("t0", cycle, self._last_rise)
            if not out.mfp6_oe:
                self._require("t4", cycle, self._last_data)
            self._last_rise = cycle
        if intel and low and not fell and pins.mfp7 != prev.mfp7:
            if self._first_sclk_fall is None or self._first_sclk_fall == cycle:
                since = self._ss_fall if self._ss_fall is not None else cycle
                self._violation("t10", cycle, since - cycle, " (S/R changed after /SS fell)")
            else:
                self._violation("t11", cycle, None, " (S/R changed while /SS low)")
        if rose:
            self._require("t2", cycle, self._last_rise)
            self._ss_rise = cycle
        if pins.sas_init and not prev.sas_init:
            self._sas_rise = cycle
        if prev.sas_init and not pins.sas_init:
            self._require("t_SAS_INIT", cycle, self._sas_rise)


QUIET_FOREVER: Final[int] = sys.maxsize
""":meth:`SlavePins.quiet` when no clock edge will act as long as the inputs hold."""

_DECODED: dict[tuple[int, ...], PinsOut] = {}
"""Every output combination :meth:`SlavePins._decode` has produced (PinsOut field order)."""


def _bad_names(inputs: object) -> NoReturn:
    """Raise the named error for a mapping that does not name exactly :data:`INPUT_PINS`."""
    if not isinstance(inputs, Mapping):
        raise fail("inputs", "a mapping of pin name to level", inputs)
    missing = [name for name in INPUT_PINS if name not in inputs]
    unknown = [name for name in inputs if name not in INPUT_PINS]
    problems = [f"without {', '.join(map(repr, missing))}" if missing else "",
                f"with {', '.join(map(repr, unknown))}, no such pin" if unknown else ""]  # fmt: skip
    raise ArgumentError("inputs", inputs, f"inputs must name exactly the pins {', '.join(INPUT_PINS)}, not "
                                          + "; ".join(problem for problem in problems if problem))


class SlavePins:
    """The serial µP interface pins of the SUPI 3 OPC as a synchronous machine at the chip clock.

    Parameters
    ----------
    registers:
        The chip's register file (its configuration gives the bit rate, its violation log strict or lenient).
    clock_hz:
        The chip clock (Table 1-6: 32 MHz); it must be a whole multiple of TCLK = 16 * bit rate.

    Notes
    -----
    The model starts in the state after a power-up reset (:meth:`reset`). Timing violations of the µP's signals
    (Table 3-7) and protocol violations are reported to ``registers.violations``; in strict mode the first one
    is raised at the end of the :meth:`tick` in which it was seen, after the state was updated.
    """

    def __init__(self, registers: RegisterFile, *, clock_hz: int = tables.CLOCK_HZ) -> None:
        check_instance("registers", registers, RegisterFile)
        check_int("clock_hz", clock_hz, 1)
        bit_rate = registers.config.bit_rate
        if clock_hz % (tables.TCLK_PER_BIT * bit_rate):
            raise UpifUsageError(
                f"clock {clock_hz} Hz is not a multiple of TCLK = {tables.TCLK_PER_BIT} * {bit_rate} Hz"
            )
        self.protocol = UpifProtocol(registers)
        self.clocks_per_tclk = clock_hz // (tables.TCLK_PER_BIT * bit_rate)
        """Chip clocks per TCLK: 4 at 500 kbit/s, 1 at 2 Mbit/s."""
        self.output_delay = reaction_clocks(bit_rate, clock_hz) - SYNC_STAGES
        """Output pipeline stages after the decoded state (UP-14): 6 at 500 kbit/s, 0 at 2 Mbit/s."""
        self.clock_hz = clock_hz
        self._checker = TimingChecker(bit_rate, clock_hz, registers.violations.report)
        self.reset()

    @property
    def registers(self) -> RegisterFile:
        """The register file behind the interface."""
        return self.protocol.registers

    def reset(self) -> None:
        """Power-up reset: registers, protocol, synchronisers (to the idle levels), shift registers, pipeline."""
        self.protocol.power_up_reset()
        self.cycle = 0
        """The number of the next cycle (0 right after reset)."""
        idle = PinsIn()
        self._ss = _Sync(idle.ss_n, idle.ss_n, idle.ss_n)
        self._sclk = _Sync(idle.sclk, idle.sclk, idle.sclk)
        self._sas = _Sync(idle.sas_init, idle.sas_init, idle.sas_init)
        self._data = _Sync(idle.mfp6, idle.mfp6, idle.mfp6)
        self._s_r = _Sync(idle.mfp7, idle.mfp7, idle.mfp7)
        self._clear_frame()
        self._checker.reset()
        self._pipeline: deque[PinsOut] = deque([self._decode()] * (self.output_delay + 1))
        self._resting: PinsOut | None = None
        """Set by :meth:`hold` once the pipeline and MFP6's synchroniser settled on these decoded outputs."""

    def _clear_frame(self) -> None:
        self._bits = 0
        self._rx = 0
        self._tx: int | None = None

    def tick(self, pins: PinsIn) -> PinsOut:
        """Run one chip-clock cycle: return the outputs of this cycle, then clock the state with ``pins``.

        Raises
        ------
        ArgumentError
            ``pins`` is not a :class:`PinsIn` (nothing changes).
        TimingViolationError, ProtocolViolationError, ReconfigurationError, InconsistentDataError
            In strict mode, after the cycle completed.
        """
        if type(pins) is not PinsIn:
            check_instance("pins", pins, PinsIn)
        pipeline = self._pipeline
        out = pipeline[0]
        self._resting = None
        log = self.protocol.registers.violations
        log.hold()  # a deferred() block without the with statement's cost (it runs once per cycle)
        try:
            self._checker.check(self.cycle, pins, out, self.protocol.mode is Mode.INTEL)
            last = pipeline[-1]
            registers = self.protocol.registers
            # An edge that acts on nothing leaves the state as last decoded; the core may have moved the register
            # file's part of it (the same test as rests()).
            if self._edge(pins, out) or last.io != registers.io_access or last.irq_n != registers.irq_n:
                last = self._decode()
            pipeline.popleft()
            pipeline.append(last)
            self.cycle += 1
        except BaseException:
            log.release(failed=True)
            raise
        log.release()
        return out

    def quiet(self, pins: PinsIn) -> int:
        """How many cycles from this one :meth:`hold` may run with ``pins`` held: those whose clock edge detects
        nothing (no /SS or SCLK edge between the second and third flop of its synchroniser, SAS_INIT's second flop
        low), :data:`QUIET_FOREVER` once the synchronisers hold ``pins`` and SAS_INIT is low, 0 if this cycle's
        edge acts (:meth:`tick` it).

        Raises
        ------
        ArgumentError
            ``pins`` is not a :class:`PinsIn`.
        """
        if type(pins) is not PinsIn:
            check_instance("pins", pins, PinsIn)
        if self._resting is not None and self._checker.last_pins is pins:
            return QUIET_FOREVER
        ss, sclk, sas = self._ss, self._sclk, self._sas
        # The edge j cycles from now sees s2 = (s2, s1, pin, pin, ...) and s3 = (s3, s2, s1, pin, ...).
        for j, (ss2, ss3, sclk2, sclk3, sas2) in enumerate((
                (ss.s2, ss.s3, sclk.s2, sclk.s3, sas.s2), (ss.s1, ss.s2, sclk.s1, sclk.s2, sas.s1),
                (pins.ss_n, ss.s1, pins.sclk, sclk.s1, pins.sas_init))):  # fmt: skip
            if ss2 != ss3 or sclk2 != sclk3 or sas2:
                return j
        return QUIET_FOREVER

    def hold(self, pins: PinsIn, cycles: int) -> list[tuple[int, PinsOut]]:
        """Run ``cycles`` cycles with ``pins`` held, while the register file does not change: the same as
        ``cycles`` calls of :meth:`tick` (the same outputs, checks and state), at a cost independent of ``cycles``.

        The event-driven whole chip (:meth:`supi3.top.Supi3Chip.run`) uses it between the cycles where the core
        changes the register file. ``cycles`` must not exceed :meth:`quiet`: then no clock edge detects anything,
        the synchronisers only shift ``pins`` in, and the state after each edge decodes to the same outputs, which
        leave the pipeline ``output_delay`` + 1 cycles later. The timing checker sees ``pins`` in the first cycle,
        as :meth:`tick` would, and afterwards only where an output changes (elsewhere it sees the same pins and C/D).

        Returns
        -------
        list[tuple[int, PinsOut]]
            The outputs at each change, as (index of the cycle among the ``cycles``, outputs); the first at 0.

        Raises
        ------
        ArgumentError
            ``pins`` not a :class:`PinsIn` or ``cycles`` not an integer >= 1 (nothing changes).
        UpifUsageError
            ``cycles`` more than :meth:`quiet` (nothing changes).
        TimingViolationError
            In strict mode, after the cycles completed.
        """
        if type(cycles) is not int or cycles < 1:
            check_int("cycles", cycles, 1)
        if self.rests(pins, cycles):
            assert self._resting is not None
            return [(0, self._resting)]
        quiet = self.quiet(pins)
        if cycles > quiet:
            raise UpifUsageError(f"hold() of {cycles} cycles: the clock edge {quiet} cycles from now acts "
                                 "(SlavePins.quiet); tick() it")
        decoded = self._decode()
        pipeline = self._pipeline
        line = [*pipeline, decoded]  # the outputs of cycles 0, 1, ...; the last one holds from then on
        changes: list[tuple[int, PinsOut]] = []
        intel = self.protocol.mode is Mode.INTEL
        with self.registers.violations.deferred():
            for i, out in enumerate(line[:cycles]):
                if not changes or out is not changes[-1][1]:
                    self._checker.check(self.cycle + i, pins, out, intel)
                    changes.append((i, out))
            self._ss.hold(pins.ss_n, cycles)
            self._sclk.hold(pins.sclk, cycles)
            self._sas.hold(pins.sas_init, cycles)
            self._s_r.hold(pins.mfp7, cycles)
            for i in range(max(cycles - 3, 0), cycles):  # MFP6's synchroniser takes the pad, driven or not
                out = line[min(i, len(pipeline))]
                self._data.clock(out.mfp6 if out.mfp6_oe else pins.mfp6)
            self._pipeline = deque((line[:-1] + line[-1:] * min(cycles, len(pipeline)))[-len(pipeline):])
            self.cycle += cycles
        # Once every stage shows the decoded outputs, holding on only counts cycles (until tick() or reset()).
        self._resting = decoded if cycles >= len(pipeline) + 3 else None
        return changes

    def rests(self, pins: PinsIn, cycles: int) -> bool:
        """:meth:`hold`'s constant-cost case, for callers that hold often (the whole chip's run() between the
        core's events): if the interface rests on ``pins`` (the ``pins`` object itself was held last, long enough for
        the pipeline and the synchronisers to take it, and the register file still decodes to the outputs shown),
        run the ``cycles`` (an integer >= 1, not checked) and return ``True``: the outputs are those shown; else
        change nothing and return ``False``."""
        resting, registers = self._resting, self.protocol.registers
        if (resting is not None and self._checker.last_pins is pins and registers.io_access == resting.io
                and registers.irq_n == resting.irq_n):  # the rest of _decode() moves only with tick()
            self.cycle += cycles  # the pipeline and the synchronisers already hold what they would take
            return True
        return False

    def step(self, inputs: Mapping[str, int]) -> dict[str, int]:
        """:meth:`tick` with pins by name (the lockstep harness's ``PinModel.step``; names in
        :data:`INPUT_PINS` and :data:`OUTPUT_PINS`).

        Raises
        ------
        ArgumentError
            ``inputs`` does not name exactly :data:`INPUT_PINS`, or a level is not 0 or 1 (nothing changes).
        """
        if not isinstance(inputs, Mapping) or len(inputs) != len(INPUT_PINS) \
                or any(name not in inputs for name in INPUT_PINS):
            _bad_names(inputs)
        return asdict(self.tick(PinsIn(**inputs)))

    def _edge(self, pins: PinsIn, out: PinsOut) -> bool:
        """The clock edge ending this cycle: act on the edges the synchronised signals show, then clock the
        synchronisers; ``False`` if it acted on nothing (the state :meth:`_decode` reads did not change). Order
        within one edge: SAS_INIT, /SS falling, SCLK rising, /SS rising."""
        protocol = self.protocol
        ss, sclk, sas, data, s_r = self._ss, self._sclk, self._sas, self._data, self._s_r
        acts = bool(sas.s2) or ss.s2 != ss.s3 or sclk.s2 != sclk.s3
        if sas.s2:
            protocol.sas_init()
            self._clear_frame()
        elif acts:  # else no edge to act on (the common case at pin level)
            if ss.fell:
                self._clear_frame()
                self._tx = protocol.begin(bool(s_r.s2))
            if protocol.in_frame and not ss.s2 and sclk.rose:
                self._shift_in(data.s2)
            if protocol.in_frame and ss.rose:
                if self._bits == 8:
                    protocol.end(self._rx)
                else:
                    protocol.abort(self._bits)
                self._clear_frame()
        ss.clock(pins.ss_n)
        sclk.clock(pins.sclk)
        sas.clock(pins.sas_init)
        data.clock(out.mfp6 if out.mfp6_oe else pins.mfp6)
        s_r.clock(pins.mfp7)
        return acts

    def _shift_in(self, bit: int) -> None:
        """One SCLK rising edge: take ``bit`` into the receive register in the mode's bit order (UP-6)."""
        if self._bits < 8:
            if self.protocol.lsb_first:
                self._rx |= bit << self._bits
            else:
                self._rx = (self._rx << 1) | bit
        self._bits += 1

    def _decode(self) -> PinsOut:
        """The outputs as a function of the state (before the output pipeline)."""
        protocol = self.protocol
        registers = protocol.registers
        tx = self._tx
        # PinsOut is frozen: equal outputs share one checked instance (at most 2**10), built once.
        if tx is None or not protocol.in_frame:  # MFP6 and MFP7 not driven
            key: tuple[int, ...] = (int(registers.io_access), 1, protocol.c_d, 1, registers.irq_n, 1, 0, 0, 0, 0)
        else:
            index = min(self._bits, 7)
            bit = (tx >> (index if protocol.lsb_first else 7 - index)) & 1
            intel = protocol.mode is Mode.INTEL
            motorola = protocol.mode is Mode.MOTOROLA
            key = (int(registers.io_access), 1, protocol.c_d, 1, registers.irq_n, 1, bit if intel else 0, int(intel),
                   bit if motorola else 0, int(motorola))  # fmt: skip
        out = _DECODED.get(key)
        if out is None:
            out = _DECODED[key] = PinsOut(*key)
        return out

"""The pin-level whole chip on the emulated board: ``Board(..., fidelity="pin")``.

Ref: IBS SUPI 3 OPC UM E rev. 05, 3.4.2 (frames), Table 3-7 (the µP's timing, checked by the chip's own
:class:`supi3.spi.slave_pins.TimingChecker`), Tables 3-5 and 3-6 (the µP pins on MFP[7..0]), 3.4.14 (/IRQ, I/O);
RM0008 25.3.3 (the SPI master's clock phase and polarity); decisions MCU-14 to MCU-17 in docs/assumptions/mcu.md.

:class:`LockstepRing` is the :class:`~supi3.model.pinring.PinRing` of one :class:`~supi3.top.Supi3Chip` whose µP
pins the board drives, clocked in step with the core. The master's calls queue their line samples on ``do1``;
:attr:`LockstepRing.runner` (the board) then runs the firmware until the chip has clocked them, and the chip runs
lazily behind the core: up to the core's time at each peripheral access (:meth:`LockstepRing.sync`). GPIO writes and
SPI1's edges (SCLK, MOSI, from the peripheral's own baud-rate divider) are pin changes at chip clocks
(:meth:`LockstepRing.drive`, :meth:`LockstepRing.spi_byte`), MISO is sampled from the chip's SerOUT at the SPI's
sampling edges, and every violation the chip finds is handed on with the firmware's place when it made the edge
that broke the rule (:class:`Cause`).
"""

from __future__ import annotations

import copy
import heapq
import itertools
import math
import numbers
from collections import deque
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Final

import numpy as np
import numpy.typing as npt

from supi3.checks import check_bits, check_bool, check_choice, check_int, check_real, check_trace, fail
from supi3.interbus import wire
from supi3.mcu.core import Frame
from supi3.mcu.stm32 import CR1_CPHA, CR1_CPOL, CR1_LSBFIRST
from supi3.model.pinring import PinBranch, PinChip, PinRing
from supi3.model.registers import InterfaceViolationError
from supi3.pinout import UP_INPUTS, UP_OUTPUTS
from supi3.tables import CLOCK_HZ
from supi3.top import QUIET_BOARD, STEP_BELOW, Supi3Chip

__all__ = ["MCU_LINES", "MISO_PULL_UP", "SYNC_S", "Cause", "LockstepRing", "Sample", "chip_clock", "mcu_lines",
           "released", "ss_high_byte"]

SYNC_S: Final[float] = 1e-6
"""MCU-14: while the core runs (not asleep), the chip catches up with it at least this often of bus time, so an edge
of /IRQ (or /ModAck) is taken at most this much after it; a sleeping core wakes at the chip clock of the edge."""
MISO_PULL_UP: Final[int] = 1
"""MCU-6: MISO reads high while the chip drives no SerOUT (MFP7)."""
IRQ_BIT: Final[int] = UP_OUTPUTS["irq_n"]
CD_BIT: Final[int] = UP_OUTPUTS["c_d"]
IO_BIT: Final[int] = UP_OUTPUTS["io"]
SEROUT_BIT: Final[int] = UP_OUTPUTS["mfp7"]
SCLK_BIT: Final[int] = UP_INPUTS["sclk"]
MOSI_BIT: Final[int] = UP_INPUTS["mfp6"]
SS_BIT: Final[int] = UP_INPUTS["ss_n"]
SAS_INIT_BIT: Final[int] = UP_INPUTS["sas_init"]
SR_BIT: Final[int] = UP_INPUTS["mfp7"]
SER_IN_OUT_BIT: Final[int] = UP_OUTPUTS["mfp6"]
MCU_LINES: Final[dict[str, tuple[str, int, int | None]]] = {
    "pa0_irq_n": ("mfp_out", IRQ_BIT, 1), "pa1_c_d": ("mfp_out", CD_BIT, 1), "pa2_io": ("mfp_out", IO_BIT, 1),
    "pa3_sas_init": ("mfp_in", SAS_INIT_BIT, None), "pa4_ss_n": ("mfp_in", SS_BIT, None),
    "pa5_sck": ("mfp_in", SCLK_BIT, None), "pa6_miso": ("mfp_out", SEROUT_BIT, MISO_PULL_UP),
    "pa7_mosi": ("mfp_in", MOSI_BIT, None), "pa8_stat_err_n": ("stat_err_n", 0, None),
    "pb1_mod_ack_n": ("mod_ack_n", 0, None),
}  # fmt: skip
"""The MCU's lines of board.h (``BOARD_PIN_*``, SPI1 on PA5 to PA7), each the chip pin it is wired to: (trace, bit,
the level while the chip drives it not, ``None`` for the MCU's outputs and the chip's plain outputs)."""
INTEL_LINES: Final[dict[str, tuple[str, int, int | None]]] = {
    **MCU_LINES, "pa6_miso": ("mfp_out", SER_IN_OUT_BIT, None), "pb0_s_r": ("mfp_in", SR_BIT, None),
}  # fmt: skip
"""The Intel board's lines (MCU-18): MISO on Ser_IN/OUT (MFP6: the chip's level while it drives, else MOSI's through
the resistor), S/R from PB0 to MFP7."""
_WATCHED: Final[tuple[str, ...]] = ("di1", "mfp_out", "mfp_oe", "mod_ack_n")
"""The outputs the board reads: the return line, the µP interface's pins, /ModAck."""
LOOK_AHEAD_FROM: Final[int] = 256
"""MCU-21: a sleeping core's wait for /IRQ or /ModAck of at least this many chip clocks is looked ahead on a copy of
the chip (:meth:`LockstepRing.sync` with ``until_edge``); a shorter one is stepped clock by clock. The copy costs
about as much as 60 clock steps, each run of the chip in one piece about as much as :data:`~supi3.top.STEP_BELOW`."""
RECENT: Final[int] = 256
"""Pin changes kept to name the cause of a violation the chip finds later."""
SS_HIGH_RULE: Final[str] = "3.4.2"
"""The rule a byte clocked with /SS high breaks (:func:`ss_high_byte`)."""


def ss_high_byte(tx: int) -> InterfaceViolationError:
    """The board's lint of a byte ``tx`` SPI1 clocks while /SS is high, at either fidelity (MCU-63): the chip ignores
    SCLK while it is not selected (3.4.2, Table 3-5), so no chip rule is broken, but the firmware has most likely
    forgotten /SS.

    Raises
    ------
    ArgumentError
        ``tx`` not SPI1's data frame: an integer of 16 bits at most (RM0008 25.3.3, DFF).
    """
    tx = check_bits("tx", tx, 16, "SPI1's data frame, 8 or 16 bits (RM0008 25.3.3)")
    return InterfaceViolationError(SS_HIGH_RULE, f"byte {tx:02X}h clocked with /SS high: the chip ignores it")


def chip_clock(cycles: int, cpu_hz: float) -> int:
    """The chip clocks run when a core of ``cpu_hz`` is at cycle ``cycles``: those that began at or before it (a read
    then sees the outputs of the clock running; a write acts from the next clock, MCU-15); a pin the board drives
    from core cycle ``cycles`` changes at the chip's pins in this clock.

    Raises
    ------
    ArgumentError
        ``cycles`` not an integer from 0, or ``cpu_hz`` not a finite number above 0 (UP-48: 0 divided by zero, a
        negative cycle gave clock 0, before the first).
    """
    if type(cycles) is not int or cycles < 0 or type(cpu_hz) is not float or not 0.0 < cpu_hz < math.inf:
        check_int("cycles", cycles, 0)
        if check_real("cpu_hz", cpu_hz, 0.0) == 0.0:
            raise fail("cpu_hz", "a core clock above 0 Hz", cpu_hz)
    return math.floor(cycles * CLOCK_HZ / cpu_hz + 1e-9) + 1


def released(word: int, bits: int, sampled: int, lsb_first: bool) -> int:
    """What SPI1 receives of ``word`` (``bits`` bits, as its data register holds them) when the chip drives MISO for
    the first ``sampled`` sampling edges only and releases it then (/SS rose, MCU-74): those bits of ``word``, and
    MISO's pull-up (:data:`MISO_PULL_UP`, MCU-6) for the rest, as :meth:`LockstepRing.spi_byte` samples the pins.

    Raises
    ------
    ArgumentError
        ``bits`` not 8 or 16 (DFF), ``word`` not of ``bits`` bits, ``sampled`` not 0 to ``bits``, ``lsb_first`` not a
        bool (UP-48: 9 sampled edges of 8 raised a negative shift count, or gave -256 LSB first).
    """
    bits = check_choice("bits", bits, (8, 16))
    check_bits("word", word, bits, "SPI1's data register (RM0008 25.3.3)")
    check_int("sampled", sampled, 0, bits, "the transfer's sampling edges")
    check_bool("lsb_first", lsb_first)
    late = (1 << bits) - (1 << sampled) if lsb_first else (1 << (bits - sampled)) - 1  # the bits sampled after
    return word | late  # MISO_PULL_UP: they read 1


@dataclass(frozen=True)
class Cause:
    """Where the firmware was when it made a pin change: its program counter, function and call stack."""

    pc: int
    function: str | None
    backtrace: tuple[Frame, ...]


@dataclass
class Sample:
    """MISO of one SPI transfer: the chip clocks at which SPI1 samples it, the bits seen so far."""

    cycles: list[int]
    lsb_first: bool
    bits: dict[int, int]


class LockstepRing(PinRing):
    """The master's line through one whole chip whose µP pins the firmware drives, in step with the core, and on
    through the pin-level chips behind it (``others``).

    Parameters
    ----------
    chip:
        The chip (an Init-µP mode).
    cpu_hz:
        The core clock: core cycle ``c`` is bus time ``c / cpu_hz``.
    where:
        The firmware's place now (:class:`Cause`), called at each pin change.
    record:
        Keep every pin trace for :func:`supi3.model.vcd.write_vcd`.
    intel:
        The Intel board (MCU-18): SPI1 samples MISO on Ser_IN/OUT (MFP6), MOSI's level where the chip drives it not;
        else on SerOUT (MFP7), pulled up.
    others:
        Further pin-level chips behind the chip, ring positions 2, 3, ... (as :class:`PinRing` takes them:
        :class:`~supi3.model.pins.Supi3Pins` or :class:`~supi3.top.Supi3Chip` objects and :class:`PinBranch` trees);
        each piece of the chip's run then runs them as :class:`PinRing` runs a ring (MCU-23).

    Attributes
    ----------
    runner:
        ``runner(k)`` runs the firmware until the chip has clocked ``k`` cycles (set by the board).
    on_edge:
        ``on_edge(name, level, cycle)``: /IRQ (``"irq_n"``) or /ModAck (``"mod_ack_n"``) changed in chip clock
        ``cycle``.
    on_violation:
        ``on_violation(error, cycle, cause)``: the chip found a violation in clock ``cycle``, caused by the pin
        change of ``cause`` (``None``: no change of the firmware's before it).
    last:
        The outputs the board reads (:data:`_WATCHED`: the return line, the MFP levels and enables, /ModAck) in the
        last clock run.
    irq_n, mod_ack_n:
        /IRQ (MFP3) and /ModAck in the last clock run.
    """

    def __init__(self, chip: Supi3Chip, cpu_hz: float, where: Callable[[], Cause], *, record: bool = False,
                 intel: bool = False, others: Sequence[PinChip | PinBranch] = ()) -> None:  # fmt: skip
        super().__init__([chip, *others], record)
        self.miso = SER_IN_OUT_BIT if intel else SEROUT_BIT
        self.chip = chip
        self.cpu_hz = cpu_hz
        self.where = where
        self.runner: Callable[[int], None] = self._catch_up
        self.on_edge: Callable[[str, int, int], None] = _no_edge
        self.on_violation: Callable[[InterfaceViolationError, int, Cause | None], None] = _no_violation
        self.inputs = dict(QUIET_BOARD)
        self._ss_n = self.inputs["mfp_in"] >> SS_BIT & 1  # /SS as the board drives it last (pulled up, MCU-6)
        self.last: dict[str, int] = {"mfp_out": 0, "mfp_oe": 0, "mod_ack_n": 1}
        self.irq_n = 1
        self.mod_ack_n = 1
        self._line: deque[int] = deque()
        self._events: list[tuple[int, int, str, int, int, Cause]] = []  # (cycle, order, pin, bit, level, cause)
        self._order = 0
        self._recent: deque[tuple[int, Cause]] = deque(maxlen=RECENT)
        self._samples: dict[int, list[Sample]] = {}
        self._di1: list[npt.NDArray[np.int64]] = []

    # -- time --------------------------------------------------------------------------------------------------

    def clock_of(self, cycles: int) -> int:
        """:func:`chip_clock` of ``cycles`` on this board's core clock."""
        return chip_clock(cycles, self.cpu_hz)

    def core_cycle(self, clock: int) -> int:
        """The first core cycle at or after the start of chip clock ``clock``."""
        return math.ceil(clock * self.cpu_hz / CLOCK_HZ - 1e-9)

    # -- the Bus protocol's line ----------------------------------------------------------------------------------

    def run_samples(self, samples: npt.NDArray[np.uint8]) -> None:
        """Queue ``samples`` on ``do1`` and run the firmware (:attr:`runner`) until the chip has clocked them."""
        self._line.extend(check_trace("samples", samples, 1).tolist())
        self.runner(self.cycle + len(self._line))
        self.returned = np.concatenate([self.returned, *(d.astype(np.uint8) for d in self._di1)])
        self._di1.clear()

    def _catch_up(self, clock: int) -> None:
        """The runner until the board sets its own: the chip alone."""
        self.sync(clock)

    # -- the devices behind the chip ------------------------------------------------------------------------------

    def set_input(self, position: int, pin: str, value: int) -> None:
        """:meth:`PinRing.set_input` for a device behind the board's chip (ring position 2 on, MCU-23); the board's
        chip's inputs are the board's wiring (:attr:`inputs`, driven by the firmware's GPIO and SPI1).

        Raises
        ------
        ArgumentError
            ``position`` 1 (the board's chip), else as :meth:`PinRing.set_input`; nothing changes.
        """
        self._behind(position)
        super().set_input(position, pin, value)

    def cut(self, position: int, forward: bool, *, branch: bool = False) -> None:
        """:meth:`PinRing.cut` of a line into a device behind the board's chip (ring position 2 on, MCU-23); the
        board's chip runs in step with the core on the master's line, whose lines are not cut.

        Raises
        ------
        ArgumentError
            ``position`` 1 (the board's chip), else as :meth:`PinRing.cut`; nothing changes.
        """
        self._behind(position)
        super().cut(position, forward, branch=branch)

    def _behind(self, position: object) -> None:
        """Refuse ring position 1, the board's chip, which :meth:`_clock` runs apart from the ring's inputs and cuts
        (any other position :class:`PinRing` checks)."""
        if not isinstance(position, bool) and isinstance(position, numbers.Integral) and position == 1:
            raise fail("position", f"a device behind the board's chip (from 2; this ring has {len(self.devices) - 1} "
                       "behind it, MCU-23): the board's chip's pins are the board's (LockstepRing.inputs)", position)

    # -- the µP's pins ---------------------------------------------------------------------------------------------

    def drive(self, cycles: int, pin: str, bit: int, level: int, cause: Cause | None = None) -> None:
        """The board drives input ``pin`` (bit ``bit`` of ``mfp_in``, or a one-bit pin with ``bit`` 0) to ``level``
        from core cycle ``cycles`` on."""
        clock = max(self.clock_of(cycles), self.cycle)
        if pin == "mfp_in" and bit == SS_BIT:
            self._ss_n = level
        self._order += 1
        heapq.heappush(self._events, (clock, self._order, pin, bit, level, self.where() if cause is None else cause))

    def spi_byte(self, tx: int, bits: int, start: int, period: int, cr1: int) -> Callable[[], int]:
        """:class:`~supi3.mcu.stm32.SpiWire`: SPI1's edges of one transfer as pin changes (RM0008 25.3.3 and MCU-8:
        SCLK idles at CPOL, bit ``k``'s leading edge half a period after ``start + k * period``, its trailing edge at
        ``start + (k + 1) * period``; MOSI changes on the leading edge with CPHA = 1, half a period before it with
        CPHA = 0, MISO is sampled on the other edge); returns what reads the received word once the chip has run past
        its last sample (MCU-16). A transfer that starts with /SS high is reported as :func:`ss_high_byte` (MCU-63);
        its edges still reach the chip, which ignores them."""
        cause = self.where()
        lsb = bool(cr1 & CR1_LSBFIRST)
        cpol, cpha = int(bool(cr1 & CR1_CPOL)), int(bool(cr1 & CR1_CPHA))
        half = period // 2
        out = [(tx >> (k if lsb else bits - 1 - k)) & 1 for k in range(bits)]
        self.drive(start, "mfp_in", SCLK_BIT, cpol, cause)
        sample_at = []
        for k in range(bits):
            lead, trail = start + k * period + half, start + (k + 1) * period
            self.drive(lead if cpha else lead - half, "mfp_in", MOSI_BIT, out[k], cause)
            self.drive(lead, "mfp_in", SCLK_BIT, 1 - cpol, cause)
            self.drive(trail, "mfp_in", SCLK_BIT, cpol, cause)
            sample_at.append(self.clock_of(trail if cpha else lead) - 1)
        sample = Sample(sample_at, lsb, {})
        for clock in sample_at:
            self._samples.setdefault(clock, []).append(sample)
        if self._ss_n:  # the edges are queued first: a strict log's raise leaves the transfer whole
            self._lint(ss_high_byte(tx), self.clock_of(start), cause)
        return lambda: self._miso(sample)

    def _lint(self, error: InterfaceViolationError, clock: int, cause: Cause) -> None:
        """A rule the board checks itself, not the chip: into the chip's violation log (strict mode raises it) and
        handed on as the chip's findings are."""
        registers = self.chip.core.chip.registers
        assert registers is not None
        try:
            registers.violations.report(error)
        finally:
            self.on_violation(error, clock, cause)

    def _miso(self, sample: Sample) -> int:
        self.sync(sample.cycles[-1] + 1)
        bits = [sample.bits.get(clock, MISO_PULL_UP) for clock in sample.cycles]
        n = len(bits)
        return sum(bit << (k if sample.lsb_first else n - 1 - k) for k, bit in enumerate(bits))

    @property
    def c_d(self) -> int:
        """C/D (MFP2) in the last clock run."""
        return self.last["mfp_out"] >> CD_BIT & 1

    @property
    def io(self) -> int:
        """The I/O access bit (MFP1) in the last clock run."""
        return self.last["mfp_out"] >> IO_BIT & 1

    # -- running the chip -------------------------------------------------------------------------------------------

    def sync(self, clock: int, *, until_edge: bool = False) -> int:
        """Run the chip until it has clocked ``clock`` cycles (``until_edge``: or until /IRQ or /ModAck changed, clock
        by clock or, from :data:`LOOK_AHEAD_FROM` clocks, found on a copy of the chip: MCU-21); return the clocks run
        so far. The line idles high once the samples queued are used up."""
        log = self.chip.core.chip.registers
        assert log is not None
        violations = log.violations
        while self.cycle < clock:
            events = self._events
            while events and events[0][0] <= self.cycle:
                at, _, pin, bit, level, cause = heapq.heappop(events)
                old = self.inputs[pin]
                self.inputs[pin] = (old & ~(1 << bit)) | (level << bit)
                if self.inputs[pin] != old:
                    self._recent.append((at, cause))
            end = min(clock, events[0][0]) if events else clock
            before = len(violations.records)
            start = self.cycle
            try:
                with violations.deferred():
                    edge = self._clock(end - start, until_edge)
            finally:
                for error in violations.records[before:]:
                    self._blame(error, start)
            if edge:
                break
        return self.cycle

    def sync_to_core(self, cycles: int) -> int:
        """:meth:`sync` up to core cycle ``cycles`` (:meth:`clock_of`)."""
        return self.sync(self.clock_of(cycles))

    def _blame(self, error: InterfaceViolationError, start: int) -> None:
        """A violation found while the inputs held from clock ``start``: the pin change there caused it (a piece
        ends at every change; the chip's µP interface counts its own cycles, so the error's clock is not used)."""
        cause = next((c for at, c in reversed(self._recent) if at <= start), None)
        self.on_violation(error, start, cause)

    def _clock(self, n: int, until_edge: bool) -> bool:
        """Run ``n`` clocks with the inputs held (but ``do1``); whether it stopped early at an edge. A long wait for
        an edge (from :data:`LOOK_AHEAD_FROM` clocks) runs to it in one piece (:meth:`_edge_ahead`, MCU-21)."""
        if len(self.tree) > 1:
            return self._clock_ring(n, until_edge)
        chip, line, idle = self.chip, self._line, self.inputs["do1"]
        start = self.cycle
        edge = False
        if until_edge and n >= LOOK_AHEAD_FROM:
            n, edge = self._edge_ahead(n)
            until_edge = False
        if n < STEP_BELOW or until_edge:
            row = dict(self.inputs)
            do1, outs = [], []
            irq_n, mod_ack_n = self.irq_n, self.mod_ack_n
            for _ in range(n):
                row["do1"] = level = line.popleft() if line else idle
                out = chip.step(row)
                do1.append(level)
                outs.append(out)
                if until_edge and ((out["mfp_out"] >> IRQ_BIT & 1) != irq_n or out["mod_ack_n"] != mod_ack_n):
                    edge = True
                    break
            names = outs[0] if self.record else _WATCHED
            traces = {name: np.array([out[name] for out in outs], dtype=np.int64) for name in names}
            traces["do1"] = np.array(do1, dtype=np.int64)
            if self.record:
                traces.update({name: np.full(len(do1), row[name], dtype=np.int64) for name in row if name != "do1"})
        else:
            traces = self._held(n, [line.popleft() for _ in range(min(n, len(line)))])
            traces.update(chip.run(traces))
        self._after(start, traces)
        return edge

    def _clock_ring(self, n: int, until_edge: bool) -> bool:
        """:meth:`_clock` with devices behind the chip (MCU-23): the piece runs as :class:`PinRing` runs a ring, the
        chip forward (its logic does not depend on DI2), the devices behind it on its DO2, then the return line from
        the last back to the chip's DI1; a wait for an edge is found on a copy of the chip first, whatever its
        length (:meth:`_edge_ahead`), since the piece cannot stop inside."""
        start, line = self.cycle, self._line
        edge = False
        if until_edge:
            n, edge = self._edge_ahead(n)
        traces = self._held(n, [line.popleft() for _ in range(min(n, len(line)))])
        traces.update(self.chip.run_forward(traces))
        chunk: dict[int, dict[str, npt.NDArray[np.int64]]] | None = {} if self.record else None
        _, sent = self._forward(self.tree[1:], 2, traces["do2"], chunk)
        traces["di2"] = self._back(sent, np.zeros(n, dtype=np.int64), chunk)
        traces["di1"] = self.chip.return_line(traces["di2"], traces["do2"])
        self._after(start, traces, None if chunk is None else [chunk[k] for k in range(2, len(self.devices) + 1)])
        return edge

    def _held(self, n: int, line: list[int]) -> dict[str, npt.NDArray[np.int64]]:
        """The input traces of ``n`` clocks with the inputs held, ``do1`` from ``line`` then idle."""
        traces = {name: np.full(n, level, dtype=np.int64) for name, level in self.inputs.items()}
        traces["do1"][: len(line)] = line
        return traces

    def _edge_ahead(self, n: int) -> tuple[int, bool]:
        """MCU-21: of the next ``n`` clocks (the inputs held), those up to and with the first in which /IRQ or
        /ModAck changes, and whether one does: found on a copy of the chip run through them in one piece
        (:meth:`Supi3Chip.run` visits only the cycles where something is due; the same outputs as clock by clock),
        so the chip itself then runs to the edge in one piece too instead of clock by clock."""
        log = self.chip.core.chip.registers
        assert log is not None
        probe = copy.deepcopy(self.chip, {id(log.violations.records): []})  # the copy's findings are not kept
        out = probe.run(self._held(n, list(itertools.islice(self._line, n))))
        changed = ((out["mfp_out"] >> IRQ_BIT & 1) != self.irq_n) | (out["mod_ack_n"] != self.mod_ack_n)
        edges = np.flatnonzero(changed)
        return (n, False) if not len(edges) else (int(edges[0]) + 1, True)

    def _after(self, start: int, traces: dict[str, npt.NDArray[np.int64]],
               behind: list[dict[str, npt.NDArray[np.int64]]] | None = None) -> None:  # fmt: skip
        """The chip ran ``traces`` from clock ``start`` (``behind``: the pins of the devices behind it, recorded)."""
        n = len(traces["do1"])
        self.cycle = start + n
        self._di1.append(traces["di1"])
        if self.record:
            self._chunks.append([traces, *(behind or ())])
        self.last = {name: int(traces[name][-1]) for name in _WATCHED}
        for clock in [c for c in self._samples if start <= c < start + n]:
            k = clock - start
            bit = self.miso
            if traces["mfp_oe"][k] >> bit & 1:
                level = traces["mfp_out"][k] >> bit & 1
            else:  # Intel: MOSI's level through the resistor; Motorola: the pull-up
                level = self.inputs["mfp_in"] >> bit & 1 if bit == SER_IN_OUT_BIT else MISO_PULL_UP
            for sample in self._samples.pop(clock):
                sample.bits[clock] = int(level)
        for name, levels, now in (("irq_n", traces["mfp_out"] >> IRQ_BIT & 1, self.irq_n),
                                  ("mod_ack_n", traces["mod_ack_n"], self.mod_ack_n)):  # fmt: skip
            if levels[-1] == now and not np.any(levels != now):
                continue
            changes = np.flatnonzero(np.diff(levels, prepend=now))
            for k in changes.tolist():
                self.on_edge(name, int(levels[k]), start + k)
            setattr(self, name, int(levels[-1]))

    def status_telegram(self) -> None:
        """One idle status telegram on the line (the master waiting between its calls)."""
        self.run_levels(wire.status_levels(wire.Cycle.DATA, False, 1))


_TRACES: Final[frozenset[str]] = frozenset({"mfp_oe", *(trace for trace, _, _ in INTEL_LINES.values())})
"""The pin traces :func:`mcu_lines` reads (INTEL_LINES holds MCU_LINES' traces)."""


def mcu_lines(traces: dict[str, npt.NDArray[np.int64]], *, intel: bool = False) -> dict[str, npt.NDArray[np.int64]]:
    """The MCU's lines (:data:`MCU_LINES`, the Intel board's :data:`INTEL_LINES`) from the recorded pin traces of
    its chip."""
    if not isinstance(traces, Mapping) or not traces.keys() >= _TRACES:
        shown = sorted(traces) if isinstance(traces, Mapping) else traces
        raise fail("traces", f"a chip's recorded pin traces ({', '.join(sorted(_TRACES))} at least)", shown)
    lines = {}
    for name, (trace, bit, undriven) in (INTEL_LINES if check_bool("intel", intel) else MCU_LINES).items():
        level = traces[trace] >> bit & 1
        if trace == "mfp_out":
            fallback = traces["mfp_in"] >> bit & 1 if undriven is None else undriven
            level = np.where(traces["mfp_oe"] >> bit & 1, level, fallback)
        lines[name] = level
    return lines


def _no_edge(name: str, level: int, cycle: int) -> None:
    del name, level, cycle


def _no_violation(error: InterfaceViolationError, cycle: int, cause: Cause | None) -> None:
    del error, cycle, cause

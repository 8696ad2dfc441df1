"""A ring of SUPI 3 OPC chips joined by fibre cables: optical initialization, online regulation, faults, diagnostics.

:class:`OpticalRing` is an INTERBUS :class:`~supi3.interbus.ring.Bus` (a master drives it like any ring): a
transaction-level :class:`~supi3.interbus.ring.Ring` of :class:`~supi3.model.chip.Supi3` chips whose lines are the
fibres of :class:`~supi3.optical.link.FibreLink` cables. It is the line side of every chip's optical block (the
chip TL API of issue 12, OPT-20 onward): it turns the link physics at the current bus time into the block's inputs,
and the light that no longer gets through into ring faults the master locates.

* **INTERBUS reset** (:meth:`OpticalRing.reset`, 1.6 "Behavior on a reset"): the chips reset (every transmitter off),
  then initialization runs cable by cable down the ring (1.6.1): the forward fibre first (the upstream chip's
  outgoing interface), then the downstream chip sees the end of the reset (``optical_start``) and its incoming
  interface regulates the return fibre. Each step takes
  :data:`~supi3.optical.regulation.INIT_STEP_BITS` bit periods on the ring's clock; the partner's response is
  "pattern detected" ("Light off") when the test at the reserve arrives, "Light on" when it does not, and none when
  the partner is not regulated (the master, a copper or diagnostics-mode chip). The length timer of each outgoing
  interface gets the cable's runtime (:meth:`~supi3.optical.link.FibreLink.timer_count`). The master waits: bus time
  moves on until the last chip is initialized (OPT-46).
* **Online regulation** (1.6.2): every :data:`~supi3.optical.regulation.REPEAT_CYCLES` data cycles, each
  regulated transmitter's two tests (at the reserve and one level further) are sent at the current bus time and
  acknowledged over the other fibre; in optical diagnostics mode the receiver evaluates them (OPT-7).
* **Faults** (OPT-47): before every cycle a cable whose light does not get through at the current levels
  (:attr:`~supi3.optical.link.LightState.DARK`) is a :class:`~supi3.interbus.ring.DeadLine` on its line; a
  marginal one gets bit errors at its bit-error rate (seeded). Cable *k* enters ring position *k*, so its faults are
  on line *k*, where the master's location puts them.
* **Diagnostics**: MAU warning changes are reported (:attr:`OpticalRing.reports`, 1.6.3), every path's levels are
  kept over time (:attr:`OpticalRing.history`), and :func:`diagnostic_table` is the master's optical diagnostic
  table of Figure 1-10, read from registers 8 to 11 (3.4.12, 3.4.13).
"""

from __future__ import annotations

import random
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Final, Protocol, runtime_checkable

from supi3.checks import check_bool, check_instance, check_int, check_real, fail
from supi3.config import DeviceConfig
from supi3.interbus import wire
from supi3.interbus.link import Device
from supi3.interbus.master import Master
from supi3.interbus.ring import BitFlip, DeadLine, Ring, Transfer
from supi3.interbus.wire import Cycle
from supi3.optical.length import Medium, length_m
from supi3.optical.link import Direction, FibreLink, LightState
from supi3.optical.regulation import (
    INIT_STEP_BITS,
    MAX_LEVEL,
    REPEAT_CYCLES,
    Interface,
    OpticalMode,
    OpticalStatus,
    Phase,
    Response,
    registers,
)
from supi3.regmap.registers import (
    OPTICAL_LENGTH_WIDTH,
    OPTICAL_MEDIUM_BIT,
    POWER_LEVEL_WIDTH,
    POWER_OUT_LSB,
)

__all__ = ["MauReport", "OpticalChip", "OpticalRing", "PathRow", "PathSample", "diagnostic_table", "format_table"]


@runtime_checkable
class OpticalChip(Device, Protocol):
    """What the ring needs from a chip: the INTERBUS device protocol and the optical block's transaction-level API
    (issue 12), as :class:`supi3.model.chip.Supi3` offers them. (A protocol rather than the class: the model package
    imports :mod:`supi3.optical`, so :mod:`supi3.optical` must not import the model package back.)"""

    @property
    def config(self) -> DeviceConfig:
        """The chip's pin straps (its bit rate)."""
        ...

    @property
    def optical(self) -> OpticalStatus:
        """The optical block's status."""
        ...

    @property
    def optical_mode(self) -> OpticalMode:
        """What RF[1..0] selects."""
        ...

    def optical_start(self, present: tuple[bool, bool, bool], now: float | None = None) -> None:
        """The end of the INTERBUS reset reached the chip at bus time ``now``."""
        ...

    def optical_init_response(self, interface: Interface, response: Response) -> None:
        """One initialization step's response."""
        ...

    def optical_length(self, interface: Interface, count: int, medium: Medium) -> None:
        """The length timer's result."""
        ...

    def optical_test(self, interface: Interface, ack1: bool, ack2: bool) -> None:
        """One online test's result."""
        ...

_TX: Final = (Interface.OUT, Interface.IN)
"""The transmitting interface of each :class:`~supi3.optical.link.Direction`: the upstream chip's OUT sends the
forward fibre, the downstream chip's IN the return fibre."""
_RX: Final = (Interface.IN, Interface.OUT)
"""The receiving interface of each direction."""


@dataclass(frozen=True)
class MauReport:
    """A MAU warning that came on or went off (1.6.3), as the master is told of it.

    ``ring_position`` is the chip's, ``interface`` the one the warning belongs to (MAUWH = IN, MAUWR = OUT).
    """

    time_s: float
    ring_position: int
    interface: Interface
    on: bool


@dataclass(frozen=True)
class PathSample:
    """A cable's state at one bus time: the levels of its two transmitters and the light at their receivers (dBm,
    ``-inf`` without light). A level is that of a transmitter that is not regulated, too (15 for the master)."""

    time_s: float
    forward_level: int
    return_level: int
    forward_dbm: float
    return_dbm: float


@dataclass(frozen=True)
class PathRow:
    """One line of the optical diagnostic table (Figure 1-10)."""

    path: str
    forward_quality: str
    return_quality: str
    forward_level: int
    return_level: int
    length_m: float
    medium: Medium

    def cells(self) -> tuple[str, ...]:
        """The row as the table prints it."""
        medium = "glass" if self.medium is Medium.GLASS else "polymer"
        return (self.path, self.forward_quality, self.return_quality, f"{self.forward_level} (of {MAX_LEVEL})",
                f"{self.return_level} (of {MAX_LEVEL})", f"{self.length_m:g}m", medium)  # fmt: skip


class OpticalRing:
    """A master's ring of SUPI 3 chips joined by fibre cables (a :class:`~supi3.interbus.ring.Bus`).

    Parameters
    ----------
    chips:
        The chips in ring order (ring position 1 next to the master); they share one bit rate.
    links:
        One per chip: ``links[k - 1]`` is the cable entering ring position *k* (from the master for *k* = 1, which is
        not a regulated device), ``None`` for copper.
    seed:
        Seed of the bit errors on marginal fibres.
    record:
        See :class:`~supi3.interbus.ring.Ring`.

    Attributes
    ----------
    ring:
        The transaction-level ring underneath; its faults are the fibres' (set before every cycle).
    reports:
        MAU warning changes, oldest first.
    history:
        Per cable (index *k* - 1), a :class:`PathSample` after every initialization and online test round.
    """

    closes_early: Final = True
    """See :attr:`supi3.interbus.ring.Ring.closes_early`."""
    direct_return_line: Final = True
    """See :attr:`supi3.interbus.ring.Ring.direct_return_line`."""

    def __init__(self, chips: Sequence[OpticalChip], links: Sequence[FibreLink | None], *, seed: int = 0,
                 record: bool = False) -> None:  # fmt: skip
        if isinstance(chips, (str, bytes)) or not isinstance(chips, Sequence) or not chips:
            raise fail("chips", "a non-empty sequence of Supi3 chips", chips)
        for k, chip in enumerate(chips, 1):
            if not isinstance(chip, OpticalChip):
                raise fail(f"chip at ring position {k}", "a chip with an optical block (a Supi3)", chip)
        rates = {chip.config.bit_rate for chip in chips}
        if len(rates) != 1:
            raise fail("chips", "chips of one bit rate", sorted(rates))
        if isinstance(links, (str, bytes)) or not isinstance(links, Sequence) or len(links) != len(chips):
            raise fail("links", f"a sequence of {len(chips)} FibreLink or None (one per chip)", links)
        for k, cable in enumerate(links, 1):
            if cable is not None:
                check_instance(f"link into ring position {k}", cable, FibreLink, "a FibreLink or None")
        self.chips: list[OpticalChip] = list(chips)
        self.links: list[FibreLink | None] = list(links)
        self.ring = Ring(self.chips, bit_rate=rates.pop(), record=check_bool("record", record))
        self._random = random.Random(check_int("seed", seed))
        self.reports: list[MauReport] = []
        self.history: list[list[PathSample]] = [[] for _ in self.links]
        self._data_cycles = 0
        self._mau = [tuple(tx.mau for tx in chip.optical.transmitters) for chip in self.chips]

    # -- the Bus protocol ------------------------------------------------------------------------------------------

    @property
    def now(self) -> float:
        """Bus time in seconds."""
        return self.ring.now

    @property
    def bit_rate(self) -> int:
        """The ring's bit rate."""
        return self.ring.bit_rate

    def transfer(self, cycle: Cycle, data: bytes, close_after: int | None = None) -> Transfer:
        """See :meth:`supi3.interbus.ring.Ring.transfer`; the fibres' faults at the current bus time come first."""
        check_instance("cycle", cycle, Cycle)
        self._faults(wire.frame_bits(len(data)))
        return self.ring.transfer(cycle, data, close_after)

    def finish(self, transfer: Transfer, latch: bool) -> None:
        """See :meth:`supi3.interbus.ring.Ring.finish`; every :data:`~supi3.optical.regulation.REPEAT_CYCLES` data
        cycles over the whole ring, an online test round."""
        self.ring.finish(transfer, latch)
        if transfer.cycle is Cycle.DATA and transfer.devices == len(self.chips):
            self._data_cycles += 1
            if self._data_cycles % REPEAT_CYCLES == 0:
                self._test_round(transfer.reached)

    def reset(self) -> None:
        """An INTERBUS reset (Alarm Stop), then the optical initialization of every cable the reset reached; the
        bus time moves on until it is done (the master waits, 1.6)."""
        self._faults(0)
        self.ring.reset()
        self._initialize()

    def idle(self, seconds: float) -> None:
        """See :meth:`supi3.interbus.ring.Ring.idle`."""
        seconds = check_real("seconds", seconds, 0.0)
        self._faults(0)
        self.ring.idle(seconds)

    # -- parties and physics ---------------------------------------------------------------------------------------

    def _ends(self, k: int) -> tuple[OpticalChip | None, OpticalChip]:
        """Cable *k*'s upstream chip (``None``: the master) and downstream chip."""
        return (self.chips[k - 2] if k > 1 else None), self.chips[k - 1]

    def _party(self, k: int, direction: Direction) -> tuple[OpticalChip | None, OpticalChip | None]:
        """The transmitting and the receiving chip of ``direction`` on cable *k* (``None``: the master)."""
        up, down = self._ends(k)
        return (up, down) if direction is Direction.FORWARD else (down, up)

    def _level(self, k: int, direction: Direction) -> int:
        """The level the transmitter of ``direction`` on cable *k* sends at (the master's: maximum)."""
        tx, _ = self._party(k, direction)
        return MAX_LEVEL if tx is None else tx.optical[_TX[direction]].level

    def _state(self, k: int, cable: FibreLink, direction: Direction, t: float) -> LightState:
        return cable.state(direction, self._level(k, direction), t)

    def _faults(self, frame_bits: int) -> None:
        """The ring's faults from the fibres at the current bus time (OPT-47): a dark cable is a dead line, a
        marginal one hits a frame of ``frame_bits`` bits with one bit error at its bit-error rate."""
        self.ring.clear_faults()
        t = self.now
        for k, cable in enumerate(self.links, 1):
            if cable is None:
                continue
            states = [self._state(k, cable, d, t) for d in Direction]
            if LightState.DARK in states:
                self.ring.inject(DeadLine(k))
            elif frame_bits and LightState.MARGINAL in states:
                clean = 1.0
                for d in Direction:
                    clean *= (1 - cable.bit_error_rate(d, self._level(k, d), t)) ** frame_bits
                if self._random.random() >= clean:
                    self.ring.inject(BitFlip(k, self._random.randrange(frame_bits)))

    # -- initialization (1.6.1) ------------------------------------------------------------------------------------

    def _initialize(self) -> None:
        """Initialization cable by cable after the reset (1.6.1, OPT-46); bus time moves to its end."""
        t = self.now
        dead = self._first_dead()
        for k, cable in enumerate(self.links, 1):
            if dead is not None and k >= dead:
                break  # the reset did not get here; these chips wait for the silent-line timeout
            up, down = self._ends(k)
            if cable is not None and up is not None:
                t = self._init_direction(k, cable, Direction.FORWARD, t)
                if up.optical[Interface.OUT].phase is not Phase.OFF and all(
                        self._state(k, cable, d, t) is not LightState.DARK for d in Direction):
                    up.optical_length(Interface.OUT, cable.timer_count(self.bit_rate), cable.medium)
            next_cable = self.links[k] if k < len(self.links) else None
            # The end of the reset reaches the chip's incoming interface at t.
            down.optical_start((cable is not None, next_cable is not None, False), t)
            if cable is not None:
                t = self._init_direction(k, cable, Direction.RETURN, t)
        self.ring.idle(t - self.now)
        self._record()

    def _first_dead(self) -> int | None:
        t = self.now
        for k, cable in enumerate(self.links, 1):
            if cable is not None and any(self._state(k, cable, d, t) is LightState.DARK for d in Direction):
                return k
        return None

    def _init_direction(self, k: int, cable: FibreLink, direction: Direction, t: float) -> float:
        """Initialize the transmitter of ``direction`` on cable *k* from bus time ``t``; the time it ends."""
        tx, rx = self._party(k, direction)
        if tx is None:
            return t
        interface = _TX[direction]
        step = INIT_STEP_BITS / self.bit_rate
        other = Direction(1 - direction)
        while tx.optical[interface].phase is Phase.INIT:
            level = tx.optical[interface].level
            if not self._regulated_partner(rx):
                response = Response.NONE
            elif cable.detected(direction, level, 1, t) or self._state(k, cable, other, t) is LightState.DARK:
                response = Response.DETECTED  # "Light off": the pattern arrived, or no light comes back at all
            else:
                response = Response.NOT_DETECTED  # "Light on"
            t += step
            tx.poll(t)  # the chip's own 6 ms budget may end here (OPT-20)
            tx.optical_init_response(interface, response)
        return t

    @staticmethod
    def _regulated_partner(rx: OpticalChip | None) -> bool:
        """A partner answers regulation patterns: a chip in regulation mode (1.6.1); the master does not."""
        return rx is not None and rx.optical_mode is OpticalMode.REGULATION

    # -- online regulation (1.6.2) ---------------------------------------------------------------------------------

    def _test_round(self, reached: int) -> None:
        """One online test of every regulated transmitter on the cables the cycle reached; then the MAU reports
        and a sample of every path."""
        t = self.now
        for k, cable in enumerate(self.links, 1):
            if cable is None or k > reached:
                continue
            for direction in Direction:
                tx, rx = self._party(k, direction)
                level = self._level(k, direction)
                ack1 = cable.detected(direction, level, 1, t)
                ack2 = cable.detected(direction, level, 2, t)
                other = Direction(1 - direction)
                if tx is not None and tx.optical[_TX[direction]].phase is Phase.ONLINE:
                    if self._state(k, cable, other, t) is not LightState.DARK:  # the acknowledgement comes back
                        tx.optical_test(_TX[direction], ack1, ack2)
                elif (tx is not None and rx is not None and tx.optical[_TX[direction]].phase is Phase.DIAGNOSTIC
                      and rx.optical[_RX[direction]].phase is Phase.DIAGNOSTIC):  # fmt: skip
                    rx.optical_test(_RX[direction], ack1, ack2)  # OPT-7: the receiving interface's warning
        self._record()

    def _record(self) -> None:
        """MAU warning changes into :attr:`reports`; a :class:`PathSample` of every cable into :attr:`history`."""
        t = self.now
        for position, chip in enumerate(self.chips, 1):
            mau = tuple(tx.mau for tx in chip.optical.transmitters)
            for interface in Interface:
                if mau[interface] != self._mau[position - 1][interface]:
                    self.reports.append(MauReport(t, position, interface, mau[interface]))
            self._mau[position - 1] = mau
        for k, cable in enumerate(self.links, 1):
            if cable is None:
                continue
            levels = [self._level(k, d) for d in Direction]
            self.history[k - 1].append(PathSample(
                t, levels[0], levels[1], cable.received_dbm(Direction.FORWARD, levels[0], 0, t),
                cable.received_dbm(Direction.RETURN, levels[1], 0, t)))

    def dark(self, k: int) -> bool:
        """Cable *k* carries no light now in one of its fibres (the master finds a dead line *k*)."""
        k = check_int("k", k, 1, len(self.links))
        cable = self.links[k - 1]
        return cable is not None and any(self._state(k, cable, d, self.now) is LightState.DARK for d in Direction)


# --------------------------------------------------------------------------------------------------------------------
# The master's optical diagnostic table (Figure 1-10)
# --------------------------------------------------------------------------------------------------------------------


def _quality(ring: OpticalRing, k: int, direction: Direction) -> str:
    """What the master shows for one direction of cable *k*: from the enable status and the MAU warnings."""
    if ring.dark(k):
        return "interrupted"
    tx, rx = ring._party(k, direction)
    sender = tx.optical[_TX[direction]] if tx is not None else None
    receiver = rx.optical[_RX[direction]] if rx is not None else None
    if sender is None or sender.phase in (Phase.OFF, Phase.FIXED):
        return "unregulated"
    if sender.phase is Phase.INIT:
        return "initializing"
    if sender.phase is Phase.DIAGNOSTIC:
        if receiver is None or receiver.phase is not Phase.DIAGNOSTIC:
            return "unmonitored"
        return "MAU warning" if receiver.mau else "normal"
    return "MAU warning" if sender.mau else "optimal"


def _number(master: Master | None, position: int) -> str:
    config = master.config if master is not None else None
    if config is not None and position <= len(config):
        return config[position - 1].number
    return f"{position}.0"


def diagnostic_table(ring: OpticalRing, master: Master | None = None) -> list[PathRow]:
    """The optical diagnostic table of Figure 1-10: one row per fibre cable between two chips, as the master reads
    it from registers 8 to 11 of the upstream chip (forward level, length, medium) and register 10 of the downstream
    chip (return level; 3.4.12, 3.4.13), with each direction's quality from the MAU warnings and enable status.
    Devices are named by the master's configuration (``"1.0<->2.0"``), by ring position without one."""
    check_instance("ring", ring, OpticalRing)
    if master is not None:
        check_instance("master", master, Master, "a Master or None")
    rows = []
    level_mask = (1 << POWER_LEVEL_WIDTH) - 1
    for k in range(2, len(ring.links) + 1):
        if ring.links[k - 1] is None:
            continue
        up, down = ring.chips[k - 2], ring.chips[k - 1]
        read8, _, _, read11 = registers(up.optical)
        read10 = registers(down.optical)[2]
        medium = Medium(read8 >> OPTICAL_MEDIUM_BIT & 1)
        rows.append(PathRow(
            f"{_number(master, k - 1)}<->{_number(master, k)}", _quality(ring, k, Direction.FORWARD),
            _quality(ring, k, Direction.RETURN), read11 >> POWER_OUT_LSB & level_mask, read10 & level_mask,
            length_m(read8 & ((1 << OPTICAL_LENGTH_WIDTH) - 1), medium), medium))
    return rows


def format_table(rows: Sequence[PathRow]) -> list[str]:
    """The table as lines of text, with a header (Figure 1-10's columns)."""
    header = ("Path", "Forward path", "Return path", "PFor", "PReturn", "Dist.", "Medium")
    cells = [header, *(check_instance("row", row, PathRow).cells() for row in rows)]
    widths = [max(len(row[i]) for row in cells) for i in range(len(header))]
    return ["  ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)).rstrip() for row in cells]

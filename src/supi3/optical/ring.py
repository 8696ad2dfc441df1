"""A ring of SUPI 3 OPC chips joined by fibre cables: optical initialization, online regulation, faults, diagnostics.

:class:`OpticalRing` is an INTERBUS :class:`~supi3.interbus.ring.Bus` (a master drives it like any ring): a
transaction-level :class:`~supi3.interbus.ring.Ring` of :class:`~supi3.model.chip.Supi3` chips whose lines are the
fibres of :class:`~supi3.optical.link.FibreLink` cables. It is the line side of every chip's optical block (its
transaction-level API, OPT-20 onward): it turns the link physics at the current bus time into the block's inputs,
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
* **Faults** (OPT-47, OPT-58): before every cycle a fibre whose light does not get through at the current levels
  (:attr:`~supi3.optical.link.LightState.DARK`) is a break of the line it carries: the forward fibre of cable *k* a
  :class:`~supi3.interbus.ring.DeadLine` into the device at position *k*, its return fibre the return line out of
  that device (a :class:`~supi3.interbus.ring.ReturnBreak` of the device before it, BK-59, or for the first cable
  the return line N + 1 into the master): the devices behind it still hear every frame, and the master's segment
  search fails first when the ring is closed after *k*. A marginal cable gets bit errors at its bit-error rate
  (seeded).
* **Trees** (OPT-54): the chips may hold :class:`~supi3.interbus.ring.Branch` items; a bus terminal module's branch
  interface sends the cable into its branch's first device, its outgoing interface the cable into the device after
  the branch. A dark return fibre in a branch with return lines is the branch's return line into the upstream device
  too, so the counter telegram of an LBD branch names the exact fibre; in an LBD-OR branch the return fibres carry
  the loop back from its last device to the BK, so a dark one is the break of the BK's DI3 (OPT-59); cables out of
  the data path carry no faults and no tests.
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
from supi3.interbus.ring import BitFlip, Branch, BranchKind, DeadLine, ReturnBreak, Ring, Transfer, check_transfer
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
from supi3.regmap import LENGTH_BRANCH, LENGTH_OUT, POWER_IN, POWER_OUT_BRANCH

__all__ = ["MauReport", "OpticalChip", "OpticalRing", "PathRow", "PathSample", "diagnostic_table", "format_table"]


@runtime_checkable
class OpticalChip(Device, Protocol):
    """What the ring needs from a chip: the INTERBUS device protocol and the optical block's transaction-level API,
    as :class:`supi3.model.chip.Supi3` offers them. (A protocol rather than the class: the model package
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

    @property
    def terminal_interface(self) -> str | None:
        """The bus terminal interface of Table 2-7 (``None``: no BK)."""
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

    def __post_init__(self) -> None:
        for name in ("path", "forward_quality", "return_quality"):
            check_instance(name, getattr(self, name), str, "a str")
        for name in ("forward_level", "return_level"):
            check_int(name, getattr(self, name), 0, MAX_LEVEL, "a power level of reads 10 and 11, 3.4.13")
        check_real("length_m", self.length_m, 0.0)
        check_instance("medium", self.medium, Medium)

    def cells(self) -> tuple[str, ...]:
        """The row as the table prints it."""
        medium = "glass" if self.medium is Medium.GLASS else "polymer"
        return (self.path, self.forward_quality, self.return_quality, f"{self.forward_level} (of {MAX_LEVEL})",
                f"{self.return_level} (of {MAX_LEVEL})", f"{self.length_m:g}m", medium)  # fmt: skip


@dataclass(frozen=True, eq=False)
class _Cable:
    """Cable *k* (``index`` = *k* - 1 into :attr:`OpticalRing.links`): the upstream chip (``None``: the master)
    sends the forward fibre from ``interface`` (OUT, or BRANCH for a BK's branch) into the downstream chip's incoming
    interface. ``kind`` is the branch the downstream chip belongs to (``None``: the remote bus of the master)."""

    index: int
    upstream: OpticalChip | None
    interface: Interface
    downstream: OpticalChip
    link: FibreLink | None
    kind: BranchKind | None


@dataclass(frozen=True)
class _Break:
    """A dark fibre as a ring fault: ``fault`` numbered by the data path now; a :class:`ReturnBreak` also by the
    physical position of the device it enters (``physical``, ``Ring.cut``'s numbering; 0 for a dead line) and whether
    it is that BK's branch return input (``branch``)."""

    fault: DeadLine | ReturnBreak
    physical: int
    branch: bool


def _walk(items: Sequence[OpticalChip | Branch], upstream: OpticalChip | None, interface: Interface,
          kind: BranchKind | None, cables: list[_Cable], links: Sequence[FibreLink | None]) -> None:  # fmt: skip
    """The cables of a tree in walk order: into every device from the one before it (its BK's branch for the first
    device of a branch, a BK's outgoing interface for the device after its branch)."""
    for item in items:
        device = item.terminal if isinstance(item, Branch) else item
        if not isinstance(device, OpticalChip):
            raise fail(f"device {len(cables) + 1}", "a chip with an optical block (a Supi3)", device)
        if len(cables) >= len(links):
            raise fail("links", "one FibreLink or None per device of the tree", links)
        cables.append(_Cable(len(cables), upstream, interface, device, links[len(cables)], kind))
        if isinstance(item, Branch):
            _walk(item.devices, device, Interface.BRANCH, item.kind, cables, links)  # type: ignore[arg-type]
        upstream, interface = device, Interface.OUT


def _count(items: Sequence[object]) -> int:
    return sum(1 + _count(item.devices) if isinstance(item, Branch) else 1 for item in items)


class OpticalRing:
    """A master's ring of SUPI 3 chips joined by fibre cables (a :class:`~supi3.interbus.ring.Bus`), possibly a tree.

    Parameters
    ----------
    chips:
        The chips in ring order (ring position 1 next to the master); a :class:`~supi3.interbus.ring.Branch` stands
        for a bus terminal module and its branch (a tree, docs/interbus.md "Tree"). They share one bit rate.
    links:
        One per chip in the tree's walk order (a BK, its branch's devices, then on; in a ring without branches ring
        order): ``links[k - 1]`` is the cable entering chip *k* (from the master for the first; from its BK's branch
        interface for a branch's first device, from a BK's outgoing interface for the device after its branch),
        ``None`` for copper.
    seed:
        Seed of the bit errors on marginal fibres.
    record:
        See :class:`~supi3.interbus.ring.Ring`.

    Attributes
    ----------
    ring:
        The transaction-level ring underneath; its faults are the fibres' (set before every cycle).
    chips:
        Every chip in the tree's walk order (``links[k - 1]`` enters ``chips[k - 1]``).
    reports:
        MAU warning changes, oldest first.
    history:
        Per cable (index *k* - 1), a :class:`PathSample` after every initialization and online test round.
    """

    closes_early: Final = True
    """See :attr:`supi3.interbus.ring.Ring.closes_early`."""
    direct_return_line: Final = True
    """See :attr:`supi3.interbus.ring.Ring.direct_return_line`."""

    def __init__(self, chips: Sequence[OpticalChip | Branch], links: Sequence[FibreLink | None], *, seed: int = 0,
                 record: bool = False) -> None:  # fmt: skip
        if isinstance(chips, (str, bytes)) or not isinstance(chips, Sequence) or not chips:
            raise fail("chips", "a non-empty sequence of Supi3 chips and branches", chips)
        for k, chip in enumerate(chips, 1):
            if not isinstance(chip, (OpticalChip, Branch)):
                raise fail(f"chip at ring position {k}", "a chip with an optical block (a Supi3) or a Branch", chip)
        n = _count(chips)
        if isinstance(links, (str, bytes)) or not isinstance(links, Sequence) or len(links) != n:
            raise fail("links", f"a sequence of {n} FibreLink or None (one per chip)", links)
        for k, cable in enumerate(links, 1):
            if cable is not None:
                check_instance(f"link into chip {k}", cable, FibreLink, "a FibreLink or None")
                if any(cable is other for other in links[: k - 1]):
                    raise fail(f"link into chip {k}", "a FibreLink of its own (one cable is one place in the "
                               "ring: an event on it would hit both places)", cable)
        self._cables: list[_Cable] = []
        _walk(chips, None, Interface.OUT, None, self._cables, links)
        self.chips: list[OpticalChip] = [c.downstream for c in self._cables]
        rates = {chip.config.bit_rate for chip in self.chips}
        if len(rates) != 1:
            raise fail("chips", "chips of one bit rate", sorted(rates))
        self.links: list[FibreLink | None] = list(links)
        seed = check_int("seed", seed)  # before the ring takes the chips (UP-47: a refused ring takes none)
        self.ring = Ring(list(chips), bit_rate=rates.pop(), record=check_bool("record", record))
        self._random = random.Random(seed)
        self.reports: list[MauReport] = []
        self.history: list[list[PathSample]] = [[] for _ in self.links]
        self._data_cycles = 0
        self._into = {id(c.downstream): c for c in self._cables}
        self._physical = {id(chip): k for k, chip in enumerate(self.chips, 1)}
        self._out: dict[tuple[int, Interface], _Cable] = {
            (id(c.upstream), c.interface): c for c in self._cables if c.upstream is not None}
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
        data, close_after = check_transfer(cycle, data, close_after)  # before the fibres draw their bit errors
        wire.check_bus_time("cycle", cycle, self.ring.now)
        self._faults(wire.frame_bits(len(data)))
        return self.ring.transfer(cycle, data, close_after)

    def finish(self, transfer: Transfer, latch: bool) -> None:
        """See :meth:`supi3.interbus.ring.Ring.finish`; every :data:`~supi3.optical.regulation.REPEAT_CYCLES` data
        cycles over the whole ring, an online test round."""
        devices = len(self.ring.devices)
        self.ring.finish(transfer, latch)
        if transfer.cycle is Cycle.DATA and transfer.devices == devices:
            self._data_cycles += 1
            if self._data_cycles % REPEAT_CYCLES == 0:
                self._test_round(transfer.reached)

    def reset(self) -> None:
        """An INTERBUS reset (Alarm Stop), then the optical initialization of every cable the reset reached; the
        bus time moves on until it is done (the master waits, 1.6)."""
        wire.check_bus_time("reset", "INTERBUS reset", self.ring.now)
        self._faults(0)
        self.ring.reset()
        self._initialize()

    def idle(self, seconds: float) -> None:
        """See :meth:`supi3.interbus.ring.Ring.idle`."""
        seconds = check_real("seconds", seconds, 0.0)
        wire.check_bus_time("seconds", seconds, self.ring.now, seconds)
        self._faults(0)
        self.ring.idle(seconds)

    # -- parties and physics ---------------------------------------------------------------------------------------

    def _positions(self) -> dict[int, int]:
        """Ring position (1..N) of every chip in the data path now, by ``id``."""
        return {id(d): k for k, d in enumerate(self.ring.devices, 1)}

    def _party(self, k: int, direction: Direction) -> tuple[OpticalChip | None, OpticalChip | None]:
        """The transmitting and the receiving chip of ``direction`` on cable *k* (``None``: the master)."""
        cable = self._cables[k - 1]
        up, down = cable.upstream, cable.downstream
        return (up, down) if direction is Direction.FORWARD else (down, up)

    def _tx_interface(self, k: int, direction: Direction) -> Interface:
        """The interface that sends ``direction`` on cable *k*."""
        return self._cables[k - 1].interface if direction is Direction.FORWARD else Interface.IN

    def _level(self, k: int, direction: Direction) -> int:
        """The level the transmitter of ``direction`` on cable *k* sends at (the master's: maximum)."""
        tx, _ = self._party(k, direction)
        return MAX_LEVEL if tx is None else tx.optical[self._tx_interface(k, direction)].level

    def _state(self, k: int, cable: FibreLink, direction: Direction, t: float) -> LightState:
        return cable.state(direction, self._level(k, direction), t)

    def _line(self, cable: _Cable, direction: Direction, at: dict[int, int]) -> _Break:
        """The ring fault of a dark fibre of ``cable`` (OPT-47, OPT-54, OPT-58): the forward fibre is the line into
        the downstream chip; the return fibre is the return line out of the downstream chip: into the master (line
        N + 1) for the first cable of the remote bus, into the BK's branch return input (DI3) for a branch's first
        cable, else into the upstream chip from the one behind it (the return input ``Ring.cut`` breaks, BK-59); in an
        LBD-OR branch the loop back to its BK: the BK's DI3 for every cable of the branch (OPT-59)."""
        down = at[id(cable.downstream)]
        if direction is Direction.FORWARD:
            return _Break(DeadLine(down), 0, False)
        while cable.kind is BranchKind.LBD_OR and cable.interface is not Interface.BRANCH:
            cable = self._into[id(cable.upstream)]  # up the branch to its first cable, sent by the BK
        if cable.upstream is None:
            return _Break(DeadLine(len(at) + 1), 0, False)
        return _Break(ReturnBreak(at[id(cable.upstream)]), self._physical[id(cable.upstream)],
                      cable.interface is Interface.BRANCH)  # fmt: skip

    def _in_path(self, cable: _Cable, at: dict[int, int]) -> bool:
        return cable.link is not None and id(cable.downstream) in at and (
            cable.upstream is None or id(cable.upstream) in at)  # fmt: skip

    def _breaks(self, t: float) -> list[_Break]:
        """The ring faults of every dark fibre in the data path at bus time ``t``."""
        at = self._positions()
        found: list[_Break] = []
        for cable in self._cables:
            if not self._in_path(cable, at):
                continue
            assert cable.link is not None
            for d in Direction:
                if self._state(cable.index + 1, cable.link, d, t) is LightState.DARK:
                    found.append(self._line(cable, d, at))
        return found

    def _faults(self, frame_bits: int) -> None:
        """The ring's faults from the fibres at the current bus time (OPT-47): a dark fibre is a dead line or a
        broken return line (OPT-54, OPT-58), a marginal cable hits a frame of ``frame_bits`` bits with one bit error
        at its bit-error rate."""
        self.ring.clear_faults()
        t = self.now
        for found in dict.fromkeys(self._breaks(t)):
            if isinstance(found.fault, ReturnBreak):  # by the physical position: a BK's two return inputs (BK-52)
                self.ring.cut(found.physical, False, branch=found.branch)
            else:
                self.ring.inject(found.fault)
        if not frame_bits:
            return
        at = self._positions()
        for cable in self._cables:
            if not self._in_path(cable, at):
                continue
            assert cable.link is not None
            k = cable.index + 1
            states = [self._state(k, cable.link, d, t) for d in Direction]
            if LightState.DARK not in states and LightState.MARGINAL in states:
                clean = 1.0
                for d in Direction:
                    clean *= (1 - cable.link.bit_error_rate(d, self._level(k, d), t)) ** frame_bits
                if self._random.random() >= clean:
                    self.ring.inject(BitFlip(at[id(cable.downstream)], self._random.randrange(frame_bits)))

    # -- initialization (1.6.1) ------------------------------------------------------------------------------------

    def _reach(self) -> int:
        """How many positions of the data path the reset reaches: those before the first dead line, all of a
        branch whose return line is broken (the ring's reading, BK-10; a return line of the remote bus outside
        branches stops nothing, BK-59)."""
        reach = len(self.ring.devices)
        spans = self.ring.spans
        for found in self._breaks(self.now):
            k = found.fault.segment
            if isinstance(found.fault, DeadLine):
                reach = min(reach, k - 1)
                continue
            inner = [bk + size for bk, size, _ in spans if (bk == k if found.branch else bk < k <= bk + size)]
            if inner:
                reach = min(reach, inner[-1])
        return reach

    def _initialize(self) -> None:
        """Initialization cable by cable down the data path after the reset (1.6.1, OPT-46); a BK initializes its
        branch and outgoing interfaces right after its incoming one (OPT-54); bus time moves to its end."""
        t = self.now
        reach = self._reach()
        at = self._positions()
        done: set[int] = set()
        for down in self.ring.devices[:reach]:
            cable = self._into[id(down)]
            if cable.index not in done:
                t = self._forward(cable, t)
            chip = cable.downstream
            out = self._out.get((id(chip), Interface.OUT))
            branch = self._out.get((id(chip), Interface.BRANCH))
            present = (cable.link is not None, out is not None and out.link is not None,
                       branch is not None and branch.link is not None and id(branch.downstream) in at)  # fmt: skip
            chip.optical_start(present, t)  # the end of the reset reaches the chip's incoming interface at t
            if cable.link is not None:
                t = self._init_direction(cable.index + 1, cable.link, Direction.RETURN, t)
            if chip.terminal_interface is not None:
                for later in (branch, out):
                    if later is not None and id(later.downstream) in at and at[id(later.downstream)] <= reach:
                        t = self._forward(later, t)
                        done.add(later.index)
        self.ring.idle(t - self.now)
        self._record()

    def _forward(self, cable: _Cable, t: float) -> float:
        """Initialize the forward fibre of ``cable`` from ``t`` and measure its length; the time it ends."""
        up, link, k = cable.upstream, cable.link, cable.index + 1
        if link is None or up is None:
            return t
        t = self._init_direction(k, link, Direction.FORWARD, t)
        if up.optical[cable.interface].phase is not Phase.OFF and all(
                self._state(k, link, d, t) is not LightState.DARK for d in Direction):  # fmt: skip
            up.optical_length(cable.interface, link.timer_count(self.bit_rate), link.medium)
        return t

    def _init_direction(self, k: int, cable: FibreLink, direction: Direction, t: float) -> float:
        """Initialize the transmitter of ``direction`` on cable *k* from bus time ``t``; the time it ends."""
        tx, rx = self._party(k, direction)
        if tx is None:
            return t
        interface = self._tx_interface(k, direction)
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
        at = self._positions()
        for c in self._cables:
            cable = c.link
            if cable is None or not self._in_path(c, at) or at[id(c.downstream)] > reached:
                continue
            k = c.index + 1
            for direction in Direction:
                tx, rx = self._party(k, direction)
                sends, hears = self._tx_interface(k, direction), self._tx_interface(k, Direction(1 - direction))
                level = self._level(k, direction)
                ack1 = cable.detected(direction, level, 1, t)
                ack2 = cable.detected(direction, level, 2, t)
                other = Direction(1 - direction)
                if tx is not None and tx.optical[sends].phase is Phase.ONLINE:
                    if self._state(k, cable, other, t) is not LightState.DARK:  # the acknowledgement comes back
                        tx.optical_test(sends, ack1, ack2)
                elif (tx is not None and rx is not None and tx.optical[sends].phase is Phase.DIAGNOSTIC
                      and rx.optical[hears].phase is Phase.DIAGNOSTIC):  # fmt: skip
                    rx.optical_test(hears, ack1, ack2)  # OPT-7: the receiving interface's warning
        self._record()

    def _record(self) -> None:
        """MAU warning changes into :attr:`reports` (at the chip's ring position; a chip out of the data path is not
        reported); a :class:`PathSample` of every cable into :attr:`history`."""
        t = self.now
        at = self._positions()
        for index, chip in enumerate(self.chips):
            mau = tuple(tx.mau for tx in chip.optical.transmitters)
            for interface in Interface:
                if mau[interface] != self._mau[index][interface] and id(chip) in at:
                    self.reports.append(MauReport(t, at[id(chip)], interface, mau[interface]))
            self._mau[index] = mau
        for k, cable in enumerate(self.links, 1):
            if cable is None:
                continue
            levels = [self._level(k, d) for d in Direction]
            self.history[k - 1].append(PathSample(
                t, levels[0], levels[1], cable.received_dbm(Direction.FORWARD, levels[0], 0, t),
                cable.received_dbm(Direction.RETURN, levels[1], 0, t)))

    def dark(self, k: int) -> bool:
        """Cable *k* carries no light now in one of its fibres (the master's segment search fails first when the ring
        is closed after the device it enters: OPT-47, OPT-58)."""
        k = check_int("k", k, 1, len(self.links))
        cable = self.links[k - 1]
        return cable is not None and any(self._state(k, cable, d, self.now) is LightState.DARK for d in Direction)

    def ends(self, k: int) -> tuple[int, int] | None:
        """The ring positions cable *k* joins now: its upstream chip's (0: the master) and its downstream chip's;
        ``None`` while the cable is out of the data path."""
        cable = self._cables[check_int("k", k, 1, len(self.links)) - 1]
        at = self._positions()
        down = at.get(id(cable.downstream))
        up = 0 if cable.upstream is None else at.get(id(cable.upstream))
        return None if down is None or up is None else (up, down)


# --------------------------------------------------------------------------------------------------------------------
# The master's optical diagnostic table (Figure 1-10)
# --------------------------------------------------------------------------------------------------------------------


def _quality(ring: OpticalRing, k: int, direction: Direction) -> str:
    """What the master shows for one direction of cable *k*: from the enable status and the MAU warnings."""
    if ring.dark(k):
        return "interrupted"
    tx, rx = ring._party(k, direction)
    sender = tx.optical[ring._tx_interface(k, direction)] if tx is not None else None
    receiver = rx.optical[ring._tx_interface(k, Direction(1 - direction))] if rx is not None else None
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
    """The optical diagnostic table of Figure 1-10: one row per fibre cable between two chips in the data path, in
    ring order, as the master reads it from the upstream chip's registers 8 or 9 (length and medium of its outgoing
    or branch interface) and 11 (their levels), and register 10 of the downstream chip (return level; 3.4.12,
    3.4.13), with each direction's quality from the MAU warnings and enable status. Devices are named by the master's
    configuration (``"1.0<->2.0"``, a BK's branch ``"3.0<->3.1"``; ``master`` must be the one driving ``ring``), by
    ring position without one."""
    check_instance("ring", ring, OpticalRing)
    if master is not None and check_instance("master", master, Master, "a Master or None").ring is not ring:
        raise fail("master", "the Master of this ring or None (its configuration names the devices)", master)
    rows = []
    at = ring._positions()
    for cable in sorted(ring._cables, key=lambda c: at.get(id(c.downstream), 0)):
        up = cable.upstream
        if up is None or not ring._in_path(cable, at):
            continue
        k = cable.index + 1
        branch = cable.interface is Interface.BRANCH
        read8, read9, _, read11 = registers(up.optical)
        path = LENGTH_BRANCH.decode(read9) if branch else LENGTH_OUT.decode(read8)
        levels = POWER_OUT_BRANCH.decode(read11)
        back = POWER_IN.decode(registers(cable.downstream.optical)[2])
        medium = Medium(path["MEDIUM"])
        rows.append(PathRow(
            f"{_number(master, at[id(up)])}<->{_number(master, at[id(cable.downstream)])}",
            _quality(ring, k, Direction.FORWARD), _quality(ring, k, Direction.RETURN),
            levels["BRANCH_LEVEL" if branch else "OUT_LEVEL"], back["LEVEL"],
            length_m(path["LENGTH"], medium), medium))  # fmt: skip
    return rows


def format_table(rows: Sequence[PathRow]) -> list[str]:
    """The table as lines of text, with a header (Figure 1-10's columns).

    Raises
    ------
    ArgumentError
        ``rows`` is not a sequence of :class:`PathRow`.
    """
    if isinstance(rows, (str, bytes)) or not isinstance(rows, Sequence):
        raise fail("rows", "a sequence of PathRow (diagnostic_table's)", rows)
    header = ("Path", "Forward path", "Return path", "PFor", "PReturn", "Dist.", "Medium")
    cells = [header, *(check_instance("row", row, PathRow).cells() for row in rows)]
    widths = [max(len(row[i]) for row in cells) for i in range(len(header))]
    return ["  ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)).rstrip() for row in cells]

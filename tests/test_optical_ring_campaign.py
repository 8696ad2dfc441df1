"""The optical fault campaign (issue 12, "Reliability"): random fibre events (bends, drift, pulled connectors and
reconnects, return fibres going dark and back: OPT-58) on a fibre-linked ring over many cycles, a plain ring and a
tree with a bus terminal module and a local bus (LBD-MR, LBD-OR or LB-MR; 2.4, 2.2.2; OPT-54). Every break is
located at the right position (the exact line in an LBD branch, BK-7; a return line at the device driving it, or
the return line into the master); no lost or corrupted process data is ever latched; regulation never oscillates
(1.6.2, 1.6.3's hysteresis); the master ends up knowing every MAU warning (OPT-52). Seeded (the conftest's
hypothesis profile); the long runs are marked slow, quick ones are not."""

from __future__ import annotations

import itertools
import random
from dataclasses import dataclass

import pytest
from hypothesis import Phase, example, given, settings
from hypothesis import strategies as st

from supi3.config import decode
from supi3.interbus import wire
from supi3.interbus.master import Master
from supi3.interbus.ring import Branch, BranchKind, ErrorKind, Fault, Transfer
from supi3.interbus.wire import Cycle
from supi3.model.chip import Supi3
from supi3.optical.link import Ageing, Bend, Direction, Event, FibreLink, Pull, Temperature
from supi3.optical.regulation import MAX_LEVEL, Interface
from supi3.optical.ring import OpticalRing
from supi3.terminal import LBST_PIN
from support import BK_STRAPS

N = 5
"""Chips of the plain ring."""
BK_AT, BRANCH = 3, 3
"""The tree: two chips, a BK at ring position 3 with 3 branch devices (BK-LBD with LBD-MR or LBD-OR, BK-LB with LB-MR),
one chip behind: 7 chips."""
BRANCH_STRAPS = {BranchKind.LBD_MR: "11000", BranchKind.LBD_OR: "11100", BranchKind.LOCAL: "01000"}
"""C[4..0] of the branch devices of each kind (Tables 2-4, 2-5: 8 IN/OUT)."""
DARK_DB = 60.0
"""A bend no light gets through (OPT-44): a fibre dark for the bend's time."""
QUIET = 40
"""Cycles after the last event in which the master learns every MAU warning (OPT-52)."""


@dataclass
class Scenario:
    """The ring (``kind``: ``None`` a plain ring of N chips, else the tree's branch kind), cable lengths (POF, one per
    chip) and events: (cable 1.., event)."""

    kind: BranchKind | None
    lengths: list[float]
    events: list[tuple[int, Event]]

    @property
    def chips(self) -> int:
        return N if self.kind is None else BK_AT + BRANCH + 1


def _event(draw: st.DrawFn, tick: float, cycles: int) -> Event:
    start = draw(st.integers(0, cycles)) * tick
    duration = draw(st.integers(1, cycles // 3)) * tick
    # a pull is a cable break and its repair; a dark return fibre a return-line break and its repair (OPT-58)
    kind = draw(st.sampled_from(["bend", "pull", "ageing", "dark return"]))
    if kind == "bend":
        return Bend(start, duration, draw(st.sampled_from([1.0, 2.5, 4.0, 6.0, 9.0, 14.0])),
                    draw(st.sampled_from([None, Direction.FORWARD, Direction.RETURN])))  # fmt: skip
    if kind == "pull":
        return Pull(start, duration)
    if kind == "dark return":
        return Bend(start, duration, DARK_DB, Direction.RETURN)
    return Ageing(start, draw(st.sampled_from([20.0, 60.0])), limit_db=draw(st.sampled_from([1.0, 3.0])))


@st.composite
def scenarios(draw: st.DrawFn, cycles: int, kinds: tuple[BranchKind | None, ...] = (None,)) -> Scenario:
    kind = draw(st.sampled_from(kinds))
    n = N if kind is None else BK_AT + BRANCH + 1
    tick = wire.cycle_bits(n, n) / 500_000
    lengths = [float(draw(st.integers(5, 75))) for _ in range(n)]
    count = draw(st.integers(1, 6))
    return Scenario(kind, lengths, [(draw(st.integers(1, n)), _event(draw, tick, cycles)) for _ in range(count)])


def _build(scenario: Scenario, seed: int) -> tuple[OpticalRing, list[Supi3]]:
    """The ring, and its chips that carry process data, in ring order."""
    def chip(straps: str = "10000") -> Supi3:
        return Supi3(decode(straps, rf="00"))

    cables = [FibreLink(m) for m in scenario.lengths]
    if scenario.kind is None:
        chips = [chip() for _ in range(N)]
        return OpticalRing(chips, cables, seed=seed), chips
    branch = [chip(BRANCH_STRAPS[scenario.kind]) for _ in range(BRANCH)]
    outer = [chip() for _ in range(BK_AT)]
    bk = chip(BK_STRAPS[scenario.kind.terminal])
    bk.set_mfp_inputs(1 << LBST_PIN)  # the branch is there (LBST, Table 2-9)
    tree: list[Supi3 | Branch] = [*outer[:-1], Branch(bk, branch, scenario.kind), outer[-1]]
    return OpticalRing(tree, cables, seed=seed), [*outer[:-1], *branch, outer[-1]]


Break = tuple[str, int, bool]
"""A fault the fibres put on the ring, as the ring got it: ``("DeadLine", line, False)``, ``("BitFlip", line, False)``
or ``("ReturnBreak", p, branch)``, the return input into ring position p (``branch``: the BK's DI3 there)."""


def _cable_faults(ring: OpticalRing, kind: BranchKind | None, k: int) -> tuple[int, int, set[Break], Break | None]:
    """Cable *k*'s ends (ring positions), the break of its forward fibre and that of its return fibre (OPT-47,
    OPT-58: the return line into the master, line N + 1, for the first cable; in an LBD-OR branch the BK's DI3 for
    every cable of the branch, OPT-59)."""
    ends = ring.ends(k)
    assert ends is not None
    up, down = ends
    forward: Break = ("DeadLine", down, False)
    if up == 0:
        back: Break | None = ("DeadLine", len(ring.ring.devices) + 1, False)
    elif kind is BranchKind.LBD_OR and BK_AT < down <= BK_AT + BRANCH:
        back = ("ReturnBreak", BK_AT, True)
    else:
        back = ("ReturnBreak", up, kind is not None and up == BK_AT and down == BK_AT + 1)
    return up, down, {forward, *([] if back is None else [back])}, back


def _driver(ring: OpticalRing, position: int, branch: bool) -> int:
    """The ring position of the device that drives the return input into ``position`` (``branch``: its DI3): the
    segment search fails first when the ring is closed after it (BK-10, BK-59)."""
    if branch:
        return position + 1
    return position + 1 + sum(size for bk, size, _ in ring.ring.spans if bk == position)


def _boundaries(events: list[Event]) -> list[float]:
    """Bus times where the physics jumps or a drift starts or stops (on any cable: a dark cable cuts the chips
    behind it off, and they reset)."""
    times = []
    for event in events:
        if isinstance(event, Bend | Pull):
            times += [event.start_s, event.start_s + (event.duration_s or 0.0)]
        elif isinstance(event, Ageing):
            times += [event.start_s, event.start_s + event.limit_db / event.rate_db_per_s]
    return times


def _campaign(scenario: Scenario, cycles: int, seed: int) -> None:
    rng = random.Random(seed)
    ring, chips = _build(scenario, seed)
    cables = ring.links
    positions = [ring.ring.devices.index(chip) + 1 for chip in chips]
    master = Master(ring)
    assert master.start().ok
    t0 = ring.now
    for k, event in scenario.events:  # times relative to the end of the start-up
        shifted: Event
        if isinstance(event, Bend):
            shifted = Bend(t0 + event.start_s, event.duration_s, event.loss_db, event.direction)
        elif isinstance(event, Pull):
            shifted = Pull(t0 + event.start_s, event.duration_s)
        else:
            assert isinstance(event, Ageing)
            shifted = Ageing(t0 + event.start_s, event.rate_db_per_s, event.limit_db)
        link = cables[k - 1]
        assert link is not None
        link.add(shifted)
    events = [e for cable in cables if cable is not None for e in cable.events]
    lines = [_cable_faults(ring, scenario.kind, k) for k in range(1, len(cables) + 1)]

    injected: list[Break] = []  # every break the fibres put on the ring during a cycle
    pending: list[Break] = []
    per_transfer: list[frozenset[Break]] = []  # the breaks each transfer of the cycle met
    inject, cut, transfer = ring.ring.inject, ring.ring.cut, ring.ring.transfer

    def spy_inject(fault: Fault) -> None:
        injected.append((type(fault).__name__, fault.segment, False))
        pending.append(injected[-1])
        inject(fault)

    def spy_cut(position: int, forward: bool, *, branch: bool = False) -> None:
        assert not forward  # the optical ring cuts return lines only (by the physical position, OPT-58)
        device = ring.chips[position - 1]
        injected.append(("ReturnBreak", next(k for k, d in enumerate(ring.ring.devices, 1) if d is device), branch))
        pending.append(injected[-1])
        cut(position, forward, branch=branch)

    def spy_transfer(cycle: Cycle, data: bytes, close_after: int | None = None) -> Transfer:
        per_transfer.append(frozenset(pending))
        pending.clear()
        return transfer(cycle, data, close_after)

    ring.ring.inject = spy_inject  # type: ignore[method-assign]
    ring.ring.cut = spy_cut  # type: ignore[method-assign]
    ring.ring.transfer = spy_transfer  # type: ignore[method-assign]
    restarts = [t0]
    failed = False
    n = len(chips)
    latched = [0] * n
    end = max(_boundaries(events), default=0.0)
    quiet = 0
    for cycle in itertools.count():
        if cycle >= cycles:  # then on until the physics is still and the master has had its quiet cycles
            quiet = quiet + 1 if ring.now > end and not failed else 0
            if quiet > QUIET or cycle > 4 * cycles:
                break
        sent = [rng.randrange(256) for _ in range(n)]
        for k, at in enumerate(positions if master.config is not None else []):  # none after a failed restart
            master.set_outputs(at, bytes([sent[k]]))
        inputs = [rng.randrange(256) for _ in range(n)]
        for chip, value in zip(chips, inputs, strict=True):
            chip.set_mfp_inputs(value)
        injected.clear()
        pending.clear()
        per_transfer.clear()
        configured = master.config is not None  # else the cycle is a discovery, which locates nothing
        result = master.cycle()
        # -- no lost or corrupted process data is ever latched
        for k, chip in enumerate(chips):
            if result.ok and result.cycle is Cycle.DATA:
                assert chip.out_word == sent[k]
                assert master.inputs(positions[k]) == bytes([inputs[k]])
            else:
                assert chip.out_word in (latched[k], 0)  # unchanged, or cleared by a reset
            latched[k] = chip.out_word
        # -- every break is located at the right position: while the same faults hold all through the cycle and its
        #    segment search, on a line they broke (a broken return line: by the counter telegram at its position in an
        #    LBD branch, by the segment search at the device driving it); while they change (a fibre going dark or
        #    coming back during the search, a marginal fibre's random bit errors hitting some probes and missing
        #    others) the probes closed at or behind a broken line fail, so the search lands on one or behind it
        steady = len(set(per_transfer)) == 1
        allowed = {(s, False) for kind, s, _ in injected if kind != "ReturnBreak"}  # dead lines, bit errors
        for kind, p, branch in injected:
            if kind == "ReturnBreak":
                allowed |= {(p, True), (_driver(ring, p, branch), False)}
        for d in result.diagnostics:
            if d.location is None or d.kind in (ErrorKind.PERIPHERAL_FAULT, ErrorKind.WATCHDOG, ErrorKind.MAU_WARNING):
                continue
            behind = not steady and not d.return_line and any(d.location >= s for _, s, _ in injected)
            assert (d.location, d.return_line) in allowed or behind, (d, injected)
        met = set(per_transfer)
        if configured and not result.ok and len(met) == 1 and (faults := met.pop()):
            # the same breaks of one cable all through the cycle and its search: located exactly (OPT-54, OPT-58,
            # BK-7): a pulled connector by its forward line (in an LBD-MR branch the count names the return line)
            for up, down, breaks, back in lines:
                if faults <= breaks:
                    counted = scenario.kind is not None and scenario.kind.diagnostics and BK_AT < down <= BK_AT + BRANCH
                    # the count names the broken return line: in an LBD-OR branch the BK's DI3 (OPT-59)
                    where = (back[1], True) if back is not None and back in faults and counted else (down, False)
                    if faults == {back} and up == 0:
                        where = (len(ring.ring.devices) + 1, False)  # the return line into the master
                    assert [(d.location, d.return_line) for d in result.diagnostics] == [where], (result, faults)
                    assert result.diagnostics[0].kind is ErrorKind.DEAD_LINE
        if not result.ok:
            failed = True
        elif failed and not any(ring.dark(k) for k in range(1, len(cables) + 1)):
            restarts.append(ring.now)  # repaired: the master restarts the bus (a marginal fibre may fail it)
            failed = not master.start().ok
    # -- regulation never oscillates: between jumps of the physics (anywhere) and the restarts, each transmitter's
    #    level never falls after it rose (it may still be settling down when an ageing drift, whose loss only grows,
    #    begins to push it up again); a MAU warning comes on at MAX only
    # -- the master knows every MAU warning on (OPT-52), once the physics is still and the ring runs
    assert quiet <= QUIET or master.mau_warnings == {
        k: mau for k, chip in enumerate(ring.ring.devices, 1)
        if any(mau := tuple(tx.mau for tx in chip.optical.transmitters))}  # type: ignore[attr-defined]
    for k in range(1, len(cables) + 1):
        cuts = sorted([*_boundaries(events), *restarts, ring.now + 1.0])
        samples = ring.history[k - 1]
        for attr in ("forward_level", "return_level"):
            for low, high in itertools.pairwise(cuts):
                levels = [getattr(s, attr) for s in samples if low < s.time_s < high]
                steps = [b - a for a, b in itertools.pairwise(levels) if b != a]
                assert not any(a > 0 > b for a, b in itertools.combinations(steps, 2)), (k, attr, low, levels)
    for report in ring.reports:
        if report.on:
            if report.interface is Interface.IN:
                k, attr = next(k for k, (_, down, _, _) in enumerate(lines, 1) if down == report.ring_position), \
                    "return_level"
            else:  # the branch interface feeds the BK's next position, the outgoing interface the one after it
                sent_to = [k for k, (up, _, _, _) in enumerate(lines, 1) if up == report.ring_position]
                k, attr = sent_to[report.interface is Interface.OUT and len(sent_to) > 1], "forward_level"
            sample = next(s for s in ring.history[k - 1] if s.time_s == report.time_s)
            assert getattr(sample, attr) == MAX_LEVEL


SEARCH_BEHIND_BIT_ERRORS = Scenario(BranchKind.LOCAL, [63.0, 68.0, 41.0, 58.0, 27.0, 18.0, 47.0], [
    (2, Bend(0.086944, 0.015048, DARK_DB, Direction.RETURN)), (6, Ageing(0.246202, 60.0, limit_db=3.0)),
    (4, Bend(0.331056, 0.086526, 2.5)), (3, Bend(0.0, 0.023826, 6.0, Direction.FORWARD)), (2, Pull(0.0, 0.003344)),
])  # fmt: skip
"""Found by a soak of 200 random histories: right after the pull, the marginal forward fibre of cable 3 flips bits in
the probes closed after 6 and not in those closed after 4 and 5, so the segment search names 6, behind the line the
bit errors are on."""
SEARCH_BEHIND_A_NEW_BREAK = Scenario(BranchKind.LBD_MR, [72.0, 58.0, 8.0, 26.0, 47.0, 53.0, 18.0], [
    (1, Bend(0.012958, 0.173888, DARK_DB, Direction.RETURN)), (6, Pull(0.173888, 0.15884)),
    (1, Bend(0.0, 0.000418, 1.0, Direction.FORWARD)), (7, Pull(0.288002, 0.023826)), (6, Bend(0.068552, 0.03135, 2.5)),
    (4, Pull(0.0, 0.055176)),
])  # fmt: skip
"""Found by the same soak: the first cable's return fibre dark (nothing comes back, every probe closed early passes,
OPT-58), then cable 6 pulled while the segment search has passed position 6: the probe closed after 7 fails, twice,
and the search names 7, behind the new break."""
SETTLING_INTO_A_DRIFT = Scenario(None, [26.0, 13.0, 70.0, 62.0, 8.0], [
    (1, Ageing(0.368836, 20.0, limit_db=1.0)), (1, Pull(0.134248, 0.019376)), (5, Ageing(0.191338, 60.0, limit_db=1.0)),
    (1, Ageing(0.011072, 20.0, limit_db=1.0)), (3, Ageing(0.232166, 60.0, limit_db=3.0)),
])  # fmt: skip
"""Found by the same soak (seed 1111): after the restart cable 5's forward transmitter still settles down (2 -> 1)
when its ageing begins, which then pushes it up again (1 -> 2) within the same drift: no oscillation (the earlier
check, one direction only between jumps, failed it on main too)."""

BIT_ERRORS_INTO_AN_LBD_OR_BRANCH = Scenario(BranchKind.LBD_OR, [15.0, 61.0, 59.0, 58.0, 56.0, 27.0, 13.0], [
    (7, Ageing(0.159676, 60.0, limit_db=1.0)), (2, Pull(0.01463, 0.103246)),
    (4, Bend(0.103664, 0.028424, 6.0, Direction.FORWARD)), (4, Bend(0.015884, 0.159676, 6.0, Direction.FORWARD)),
    (6, Pull(0.588962, 0.159676)),
])  # fmt: skip
"""Found by a soak (seed 61570, issue 12): cable 4's bent forward fibre flips bits on the line into the LBD-OR branch's
first device (position 4); the segment search names 4 and the BK, with no interrupt to count, reads 0, which the
master took for a break of its own return input (position 3, BK-7): the count locates only an interrupt (BK-62)."""


def _dark_returns(kind: BranchKind | None, cables: tuple[int, ...]) -> Scenario:
    """Cables 20 m long whose return fibres go dark one after another, 40 cycle times each, 60 apart (OPT-58)."""
    n = N if kind is None else BK_AT + BRANCH + 1
    tick = wire.cycle_bits(n, n) / 500_000
    return Scenario(kind, [20.0] * n, [(k, Bend(60 * i * tick, 40 * tick, DARK_DB, Direction.RETURN))
                                       for i, k in enumerate(cables, 1)])  # fmt: skip


# No shrinking: an example of hundreds of cycles shrinks for minutes; a failure prints its example whole.
@settings(max_examples=4, deadline=None, phases=(Phase.explicit, Phase.generate))
@given(scenarios(cycles=300), st.integers(0, 2**16))
@example(_dark_returns(None, (1, 3, 5)), 0)  # into the master, between chips 2 and 3, into chip 4
def test_campaign_quick(scenario: Scenario, seed: int) -> None:
    _campaign(scenario, 300, seed)


@pytest.mark.slow
@settings(max_examples=8, deadline=None, phases=(Phase.explicit, Phase.generate))
@given(scenarios(cycles=1500), st.integers(0, 2**16))
@example(SETTLING_INTO_A_DRIFT, 1111)
def test_campaign_long(scenario: Scenario, seed: int) -> None:
    _campaign(scenario, 1500, seed)


TREES = (BranchKind.LBD_MR, BranchKind.LBD_OR, BranchKind.LOCAL)


@settings(max_examples=4, deadline=None, phases=(Phase.explicit, Phase.generate))
@given(scenarios(cycles=300, kinds=TREES), st.integers(0, 2**16))
@example(_dark_returns(BranchKind.LOCAL, (3, 4, 5, 7)), 0)  # before the BK, its DI3, in the branch, into the BK
@example(_dark_returns(BranchKind.LBD_MR, (4, 6, 7)), 0)  # the count names the return line (BK-7)
@example(BIT_ERRORS_INTO_AN_LBD_OR_BRANCH, 61570)  # bit errors are no interrupt: the count is not asked (BK-62)
def test_tree_campaign_quick(scenario: Scenario, seed: int) -> None:
    _campaign(scenario, 300, seed)


@pytest.mark.slow
@settings(max_examples=8, deadline=None, phases=(Phase.explicit, Phase.generate))
@given(scenarios(cycles=1500, kinds=TREES), st.integers(0, 2**16))
@example(SEARCH_BEHIND_BIT_ERRORS, 36428)
@example(SEARCH_BEHIND_A_NEW_BREAK, 14483)
def test_tree_campaign_long(scenario: Scenario, seed: int) -> None:
    _campaign(scenario, 1500, seed)


@settings(max_examples=5, deadline=None)
@given(st.lists(st.integers(3, 75), min_size=N, max_size=N), st.floats(0.0, 20.0), st.floats(0.01, 0.2))
def test_constant_path_settles_within_one_level(lengths: list[int], swing_k: float, period_s: float) -> None:
    """Without events a path keeps its level; with a temperature swing of less than 1 dB peak to peak (20 K at
    -0.02 dB/K) it moves by one level at most (1.6.2: 3-point regulation)."""
    chips = [Supi3(decode("10000", rf="00")) for _ in range(N)]
    cables = [FibreLink(float(m), events=(Temperature(0.0, swing_k, period_s),)) for m in lengths]
    ring = OpticalRing(chips, cables)
    master = Master(ring)
    assert master.start().ok
    for _ in range(300):
        assert master.cycle().ok
    for history in ring.history[1:]:
        for attr in ("forward_level", "return_level"):
            levels = {getattr(s, attr) for s in history[1:]}  # after the initialization's sample
            assert max(levels) - min(levels) <= 1, (attr, levels)
    assert ring.reports == []  # no MAU warning: the reserve is there all the time

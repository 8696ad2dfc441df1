"""Branch recognition of a bus terminal module at both fidelities (manual 2.1.1, Table 2-2, Tables 2-7 to 2-9;
BK-37, BK-41..BK-43): for BK-RB, BK-LB and BK-LBD, every row of Table 2-9 (RF = 00, 01, 10, 11 with LBST = 0 and 1)
with the branch empty (nothing attached: DI3 pulled up) and populated (one device), a master on the pin-level ring
(:class:`~supi3.model.pinring.PinRing` with :class:`~supi3.model.pinring.PinBranch`) and one on the transaction-level
ring (:class:`~supi3.interbus.ring.Ring` with :class:`~supi3.interbus.ring.Branch`) of the same tree see the same
thing: whether the start succeeds and the diagnostics it reports, the configuration (numbers, ID codes, data
lengths), the process data IN, and every chip's RD, LD and E LEDs. A branch present by LBST with nothing attached
breaks the ring at both (BK-43); an empty branch that needs a device's answer (RF = 11, or fibre with LBST = 0) is
not present and the ring runs through the BK. The transaction-level BK recognises its branch by the pin level's rule
(BK-48): a break of the branch's loop before the master's first start and after it, in every branch kind, and any
history of breaks (by physical position, BK-52), repairs, starts, cycles, branch commands and the BK's power-up give the
same recognition and the same master's view of every start and cycle at both fidelities; a branch joining within a
cycle loses that cycle's frame at both (BK-54); behind a break in an LBD branch the master reports a dead line at both,
and the BK keeps the same count (BK-49).
"""

from __future__ import annotations

from collections.abc import Callable

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from supi3.errors import ArgumentError
from supi3.interbus import wire
from supi3.interbus.master import CycleResult, Master
from supi3.interbus.ring import (
    Branch,
    BranchKind,
    DeadLine,
    ErrorKind,
    Fault,
    ReturnBreak,
    Ring,
    join_error,
    lbd_count,
)
from supi3.interbus.wire import Cycle
from supi3.model.chip import Supi3
from supi3.model.pinring import PinBranch, PinRing
from supi3.model.pins import Supi3Pins
from supi3.terminal import RF_CODES, branch_present
from support import REPAIR_IDLE_TELEGRAMS
from test_model_pinring_tree import INPUTS, LBST, ROWS, _bk, _config, nested_pin, nested_tl, view

KINDS = [BranchKind.REMOTE, BranchKind.LOCAL, BranchKind.LBD_MR]
"""BK-RB, BK-LB and BK-LBD (Table 2-7)."""
CYCLES = 4
"""Master cycles after the start, each compared."""


def tl_ring(kind: BranchKind, rf: str, lbst: bool, m: int) -> tuple[Ring, list[Supi3]]:
    """RB device, BK (``rf``, ``lbst``) with ``m`` branch devices of ``kind``, RB device; and every chip in physical
    order."""
    bk = Supi3(_bk(kind, rf))
    bk.set_mfp_inputs(LBST if lbst else 0)
    first, last = Supi3(_config(ROWS[BranchKind.REMOTE])), Supi3(_config(ROWS[BranchKind.REMOTE]))
    branch = [Supi3(_config(ROWS[kind])) for _ in range(m)]
    for chip, value in zip([first, *branch, last], [0x5A, *INPUTS], strict=False):
        chip.set_mfp_inputs(value)
    return Ring([first, Branch(bk, branch, kind), last], bit_rate=2_000_000), [first, bk, *branch, last]


def pin_ring(kind: BranchKind, rf: str, lbst: bool, m: int) -> tuple[PinRing, list[Supi3]]:
    """The pin-level twin of :func:`tl_ring`."""
    chips = [Supi3Pins(_config(ROWS[kind])) for _ in range(m)]
    ring = PinRing([Supi3Pins(_config(ROWS[BranchKind.REMOTE])), PinBranch(Supi3Pins(_bk(kind, rf)), chips, kind),
                    Supi3Pins(_config(ROWS[BranchKind.REMOTE]))])  # fmt: skip
    ring.set_input(2, "mfp_in", LBST if lbst else 0)
    ring.set_input(2, "rbst_ext", 1)  # RF = 10: the board tells the BK that a device follows on its remote bus (M5)
    for position, value in zip([1, *range(3, m + 4)], [0x5A, *INPUTS], strict=False):
        ring.set_input(position, "mfp_in", value)
    return ring, [pins.chip for pins in ring.devices]


View = tuple[list[tuple[str, int, int]], list[bytes]]
Leds = list[tuple[bool, bool, bool]]
Where = tuple[list[tuple[int | None, str | None]], list[int]]
Step = tuple[bool, list[object], View | None, Leds, Where]


def history(ring: Ring | PinRing, chips: list[Supi3],
            change: tuple[Callable[[], bool], int] | None = None, cycles: int = CYCLES) -> list[Step]:
    """Start a master on ``ring`` and cycle it: per step, whether it latched, the diagnostics' kinds, the master's
    view (configuration and process data IN, ``None`` without a configuration), every chip's RD, LD and E (DG-5,
    BK-11), and where: each diagnostic's location and device, every BK's status byte (BK-5: its count, BK-6), for
    ``cycles`` cycles; ``change`` (a callable, step) is called before that step and its result is added to the
    step's kinds."""
    master = Master(ring, locate=False, max_devices=8)
    steps: list[Step] = []
    for k in range(cycles + 1):
        extra: list[object] = []
        if change is not None and change[1] == k:
            extra.append(change[0]())
        result = master.start() if k == 0 else master.cycle()
        leds = [(leds.rd, leds.ld, leds.e) for leds in (chip.diagnostic_outputs for chip in chips)]
        seen = view(master) if master.config is not None else None
        where = ([(d.location, d.device) for d in result.diagnostics],
                 [chip.bus_terminal.state.status for chip in chips if chip.bus_terminal is not None])  # fmt: skip
        steps.append((result.ok, [*extra, *(d.kind for d in result.diagnostics)], seen, leds, where))
    return steps


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("rf", RF_CODES)
def test_every_row_of_table_2_9_is_the_same_at_both_fidelities(kind: BranchKind, rf: str) -> None:
    """LBST 0/1 x empty/populated: the start, every cycle after it and every chip's RD/LD/E agree; a branch present
    without a device's answer (RF = 10 or fibre with LBST = 1, nothing attached) breaks the ring at both (the master
    reports a dead line), an empty branch that needs the answer is left out at both, a populated branch present by
    Table 2-9 joins the data path at both (BK-41, BK-43)."""
    for lbst in (False, True):
        for m in (0, 1):
            tl = history(*tl_ring(kind, rf, lbst, m))
            pin = history(*pin_ring(kind, rf, lbst, m))
            assert pin == tl, (lbst, m)
            present = branch_present(rf, lbst, m > 0)
            ok, _, seen, leds, _ = tl[-1]
            if present and m == 0:
                assert not tl[0][0] and tl[0][1] == [ErrorKind.DEAD_LINE] and seen is None
            else:
                assert tl[0][0] and ok and seen is not None and len(seen[0]) == 3 + (m if present else 0)
                assert leds[1][1:] == (False, False)  # the BK's LD and E dark


Cut = tuple[Fault, tuple[int, bool, bool]]
"""A break at both fidelities: the transaction-level fault and the pin-level ``PinRing.cut`` (position, forward,
branch)."""


def cuts(kind: BranchKind) -> list[Cut]:
    """Every break of the loop from a BK (position 2) through its two branch devices (3, 4) back to its DI3: the
    forward lines into the branch devices, the return line from the second (a branch with return lines), the BK's own
    return input (BK-10, BK-40)."""
    found: list[Cut] = [(DeadLine(3), (3, True, False)), (DeadLine(4), (4, True, False))]
    if kind is not BranchKind.LBD_OR:
        found.append((ReturnBreak(3), (3, False, False)))
    return [*found, (ReturnBreak(2), (2, False, True))]


def connected(ring: PinRing) -> bool:
    """The pin-level BK's (position 2) ``connected`` (BK-37)."""
    bk = ring.devices[1]
    assert isinstance(bk, Supi3Pins)
    return bk.branch_connected


def assert_lbd_break(kind: BranchKind, cut: Cut, steps: list[Step]) -> None:
    """BK-49: behind a break in an LBD branch the master reports a dead line, never a CNTR error (the counter
    telegrams that reach it are no frame), not located (``locate=False``), while the BK keeps the count that gives the
    break's line (BK-6, BK-7: ``ring.lbd_count`` of two branch devices; none for a break of its own return input)."""
    fault, _ = cut
    device = fault.segment - 2  # the branch's devices are ring positions 3 and 4
    forward, back = ({device}, set()) if isinstance(fault, DeadLine) else (set(), {device})
    failed = [(kinds, where) for ok, kinds, _, _, where in steps if not ok]
    assert failed and all(ErrorKind.DEAD_LINE in kinds and ErrorKind.CNTR not in kinds for kinds, _ in failed), cut
    assert all(location is None and number is None for _, where in failed for location, number in where[0]), cut
    expected = lbd_count(kind, 2, forward, back) or 0
    assert steps[-1][4][1][0] & wire.COUNTER_MAX == expected, (cut, steps[-1][4])


def cut_history(kind: BranchKind, rf: str, lbst: bool, cut: Cut, at: int) -> tuple[list[Step], list[Step]]:
    """:func:`history` of the transaction-level and the pin-level tree (two branch devices) with ``cut`` made before
    step ``at`` (0: before the master's first start), up to two cycles after it; after each step the BK's recognition
    (``branch_recognised``, ``branch_connected``) must agree."""
    fault, (position, forward, branch) = cut
    tl, tl_chips = tl_ring(kind, rf, lbst, 2)
    pin, pin_chips = pin_ring(kind, rf, lbst, 2)

    def tl_cut() -> bool:
        tl.inject(fault)
        return tl_chips[1].branch_recognised

    def pin_cut() -> bool:
        pin.cut(position, forward, branch=branch)
        return connected(pin)

    return history(tl, tl_chips, (tl_cut, at), at + 2), history(pin, pin_chips, (pin_cut, at), at + 2)


@pytest.mark.parametrize("kind", [*KINDS, BranchKind.LBD_OR])
@pytest.mark.parametrize(("rf", "lbst"), [("11", True), pytest.param("00", False, marks=pytest.mark.slow)])
def test_a_branch_cut_before_or_after_the_first_start_is_the_same_at_both_fidelities(
        kind: BranchKind, rf: str, lbst: bool) -> None:
    """BK-37, BK-48, every branch kind, the rows of Table 2-9 that need a device's answer (copper RF = 11 with
    LBST = 1, fibre with LBST = 0): a break of the branch's loop before the master's first start leaves a branch with
    return lines (BK-RB, BK-LB) unrecognised at both fidelities, and the ring runs through the BK; an LBD branch is
    recognised by its devices' counter telegrams (BK-30) unless the BK's own return input is broken, and the master
    then finds the break. A break after the start meets the latched recognition: the master finds the break at both.
    Every step (start and cycles: result, diagnostics, configuration, process data, LEDs) is the same."""
    for cut in cuts(kind):
        for at in (0, 1):
            tl, pin = cut_history(kind, rf, lbst, cut, at)
            assert tl == pin, (cut, at)
            own_return = isinstance(cut[0], ReturnBreak) and cut[0].segment == 2
            answered = at == 1 or (kind.diagnostics and not own_return)
            ok, _, seen, _, _ = tl[0]
            if at == 0 and not answered:
                assert ok and seen is not None and len(seen[0]) == 3 and tl[-1][0], cut
            else:
                assert not all(step[0] for step in tl[at:]), (cut, at)
                if kind.diagnostics:
                    assert_lbd_break(kind, cut, tl)


Op = tuple[str, int]
OPS = st.one_of(st.tuples(st.sampled_from(["start", "cycle", "repair", "off", "on", "power"]), st.just(0)),
                st.tuples(st.just("cut"), st.integers(0, 3)))
"""A history's steps: the master's start (an INTERBUS reset and its ID cycles) or one cycle, a break of the branch's
loop (an index into :func:`cuts`, made by the physical position, also while the branch is out of the data path,
BK-52), every break repaired (index 0: while the master sends idle telegrams; 1: just before the next run), the branch
switched off or on by the master (BK-4), the BK's power-up reset (BK-48)."""
POWER_DOWN_S = 4 * wire.STATUS_TELEGRAM_BITS / 2_000_000
"""How long the BK's /ResU is held low in a power-up step."""
REPAIR_IDLE_S = REPAIR_IDLE_TELEGRAMS * wire.STATUS_TELEGRAM_BITS / 2_000_000
"""Idle after a repair (M21): a repaired line takes up a telegram in flight at the repair point, and behind a break in
an LBD branch a device that sends a counter telegram drops the telegram beginning then and the one chained to it
(BK-30, M16); idle telegrams take that, not the next frame's head."""
FIRST_IDLE_TELEGRAMS: dict[BranchKind, int] = {BranchKind.REMOTE: 0, BranchKind.LOCAL: 0, BranchKind.LBD_MR: 9,
                                               BranchKind.LBD_OR: 9}
"""Idle status telegrams before a history's first step, every chip powered up at the ring's first clock (M22, M25:
``Ring.power_up`` at transaction level), per branch kind: the least from which the histories of
``bench/wake_tree_sweep.py initial`` agree (M25's limits; BK-RB and BK-LB 5 before BK-64; before M25: 9 for every
kind, 20 before that)."""
BRING_UP_TELEGRAMS = 5
"""Idle status telegrams after the first clock by which every BK of these trees has its branch's answer (M25: BK-RB's
322 clocks at 2 Mbit/s): a history that breaks the loop after the bring-up waits them."""
POWER_IDLE_TELEGRAMS: dict[BranchKind, int] = {BranchKind.REMOTE: 2, BranchKind.LOCAL: 0, BranchKind.LBD_MR: 6,
                                               BranchKind.LBD_OR: 6}
"""Idle status telegrams after the BK's power-up step (/ResU released, ``Ring.power_up`` at transaction level: M25
follows the BK's wake-up and its branch's answer), per branch kind: the least from which the histories of
``bench/wake_tree_sweep.py power`` agree (M25's limits, LBD-MR's the longest; BK-RB's M25's limit 6; BK-RB and
BK-LB 3 before M28, M29 and BK-64; before M25: 6 for every kind, 20 before that)."""
TELEGRAM_S = wire.STATUS_TELEGRAM_BITS / 2_000_000


Seen = tuple[Cycle, bool, list[tuple[ErrorKind | None, int | None, str | None]], View | None] | None
Record = tuple[str, int, bool, Seen]
"""A step of :func:`recognition_history` at one fidelity: the step, the BK's recognition, what the master saw."""


def recognition_history(kind: BranchKind, row: tuple[str, bool], ops: list[Op], first_idle_s: float | None = None,
                        power_idle_s: float | None = None) -> list[tuple[Record, Record]]:
    """Run ``ops`` (:data:`OPS`) on the transaction-level and the pin-level tree of two branch devices of ``kind``
    (``row``: RF and LBST, Table 2-9) with a master on each, after ``first_idle_s`` of idle and with ``power_idle_s``
    after each power-up step (M22, M25; ``None``: :data:`FIRST_IDLE_TELEGRAMS`, :data:`POWER_IDLE_TELEGRAMS` of
    ``kind``); per step, at each fidelity, the BK's recognition (``branch_recognised``, ``connected``) and what the
    master saw (:func:`seen`)."""
    first_idle_s = FIRST_IDLE_TELEGRAMS[kind] * TELEGRAM_S if first_idle_s is None else first_idle_s
    power_idle_s = POWER_IDLE_TELEGRAMS[kind] * TELEGRAM_S if power_idle_s is None else power_idle_s
    tl, tl_chips = tl_ring(kind, *row, 2)
    pin, _ = pin_ring(kind, *row, 2)
    for position in range(1, len(tl_chips) + 1):  # powered up at the first clock, as the pin level's chips (M22, M25)
        tl.power_up(position)
    for ring in (tl, pin):
        ring.idle(first_idle_s)
    masters = [Master(tl, locate=False, max_devices=8), Master(pin, locate=False, max_devices=8)]
    breaks = cuts(kind)
    steps: list[tuple[Record, Record]] = []
    for name, index in ops:
        results: list[CycleResult | None] = [None, None]
        if name == "cycle" and any(master.config is None for master in masters):
            # Without a configuration a master starts again (an INTERBUS reset), as this history always did; a discovery
            # ID cycle over chips that took no reset since their power-up (it failed at pin level, BK-54's limit 2) is
            # compared on flat rings since M19, M20 (tests/test_model_pinring_powerup.py).
            name = "start"
        if name in ("start", "cycle"):
            results = [master.start() if name == "start" else master.cycle() for master in masters]
        elif name in ("off", "on") and all(m.config is not None and len(m.config) > 1 for m in masters):
            for master in masters:
                master.switch_branch(2, name == "on")
        elif name == "repair":
            tl.clear_faults()
            pin.cuts.clear()
            pin.branch_cuts.clear()
            if not index:  # while the master sends idle telegrams, not under the next frame (BK-54's limit)
                tl.idle(REPAIR_IDLE_S)
                pin.idle(REPAIR_IDLE_S)
        elif name == "cut" and index < len(breaks):
            _, (position, forward, branch) = breaks[index]
            tl.cut(position, forward, branch=branch)
            pin.cut(position, forward, branch=branch)
        elif name == "power":
            tl.idle(POWER_DOWN_S)
            tl.power_up(2, down=tl.now - POWER_DOWN_S)  # M25: the BK's wake-up and its branch's answer followed (M26)
            tl.idle(power_idle_s)
            pin.set_input(2, "resu_n", 0)
            pin.idle(POWER_DOWN_S)
            pin.set_input(2, "resu_n", 1)
            pin.idle(power_idle_s)
        # A branch that joins the data path in a cycle's run joins within its frame (BK-54): the cycle fails at both
        # fidelities, with the error of the first repaired line of its loop (BK-56), compared too.
        steps.append(((name, index, tl_chips[1].branch_recognised, seen(masters[0], results[0])),
                      (name, index, connected(pin), seen(masters[1], results[1]))))  # fmt: skip
    return steps


def seen(master: Master, result: CycleResult | None) -> Seen:
    """The master's view after a step: the cycle's kind, success and diagnostics (kind, location, device), the
    configuration and the IN data."""
    if result is None:
        return None
    return (result.cycle, result.ok, [(d.kind, d.location, d.device) for d in result.diagnostics],
            view(master) if master.config is not None else None)  # fmt: skip


@settings(max_examples=12, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(kind=st.sampled_from([*KINDS, BranchKind.LBD_OR]),
       row=st.sampled_from([("11", True), ("00", False), ("10", False), ("10", True)]),
       ops=st.lists(OPS, min_size=1, max_size=7))
def test_the_recognition_follows_any_history_the_same_at_both_fidelities(
        kind: BranchKind, row: tuple[str, bool], ops: list[Op]) -> None:
    """BK-37, BK-48, BK-52, BK-54: breaks (by physical position, also while the branch is out of the data path),
    repairs, starts (INTERBUS resets), cycles, branch commands and the BK's power-up in any order leave the
    transaction-level BK's ``branch_recognised`` equal to the pin-level BK's ``connected`` after every step, and the
    master sees every start and cycle alike (a branch joining within a cycle fails it at both)."""
    for tl, pin in recognition_history(kind, row, ops):
        assert tl == pin


JOIN_ERRORS: dict[Fault, ErrorKind] = {DeadLine(3): ErrorKind.TRANSMISSION, DeadLine(4): ErrorKind.TELEGRAM}
"""BK-56, measured at pin level: the error of the cycle a branch of two devices joins within, by the one line of its
loop repaired before that cycle's run: the first device's forward input, the second's; any other (a return line) is a
dead line."""


@pytest.mark.parametrize("kind", [*KINDS, BranchKind.LBD_OR])
def test_a_branch_joining_within_a_cycle_fails_that_cycle_at_both_fidelities(kind: BranchKind) -> None:
    """BK-54, BK-56: every break that keeps a branch unrecognised (BK-48: a loop with return lines broken anywhere, an
    LBD branch's BK's own return input), made after the BK's power-up, leaves the branch out at the master's start;
    repaired after the start, the branch answers in the next cycle's run and joins the data path within its frame at
    both fidelities: that cycle fails at both with the same error (:data:`JOIN_ERRORS`: where the pin-level BK switched,
    given by the repaired line), not located, and every cycle after it is the same (the master meets the longer ring:
    the loopback word left out: a configuration error, then data cycles on it, BK-45, A25)."""
    for index, (fault, (_, _, branch)) in enumerate(cuts(kind)):
        if kind.diagnostics and not branch:
            continue  # the LBD branch's devices answer behind a break with counter telegrams (BK-30)
        ops: list[Op] = [("cut", index), ("power", 0), ("start", 0), ("cycle", 0), ("repair", 1),
                         *[("cycle", 0)] * 4]  # fmt: skip
        steps = recognition_history(kind, ("11", True), ops,
                                    max(FIRST_IDLE_TELEGRAMS[kind], BRING_UP_TELEGRAMS) * TELEGRAM_S)
        assert [tl for tl, _ in steps] == [pin for _, pin in steps], index
        recognised = [tl[2] for tl, _ in steps]
        assert recognised == [True] + [False] * 4 + [True] * 4, index  # the bring-up; power-up
        start, joined = steps[2][0][3], steps[5][0][3]
        assert start is not None and start[1] and start[3] is not None and len(start[3][0]) == 3, index  # through BK
        error = JOIN_ERRORS.get(fault, ErrorKind.DEAD_LINE)
        assert joined is not None and not joined[1] and joined[2] == [(error, None, None)], index
        # The longer ring after it: the loopback word left out, the rescan finds it without location too (A25),
        # a configuration error, then the master runs on the longer ring.
        first, last = steps[6][0][3], steps[-1][0][3]
        assert first is not None and [d[0] for d in first[2]] == [ErrorKind.CONFIGURATION], index
        assert last is not None and last[1] and last[3] is not None and len(last[3][0]) > 3, index


def test_the_transaction_level_loses_the_frame_a_branch_joins_within() -> None:
    """BK-54 at transaction level: the cycle in whose run a branch is recognised delivers its frame as far as the
    joining branch (its devices hear it) and nothing behind its BK: a dead line behind the branch, the devices after it
    keep what they had; the next cycle runs over the longer ring."""
    for forward, error in ((False, ErrorKind.DEAD_LINE), (True, ErrorKind.TRANSMISSION)):
        ring, chips = tl_ring(BranchKind.LOCAL, "11", True, 2)
        ring.cut(3, forward)
        master = Master(ring, locate=False, max_devices=8)
        assert master.start().ok and not chips[1].branch_recognised and master.config is not None
        assert len(master.config) == 3
        ring.clear_faults()
        transfer = ring.transfer(Cycle.DATA, bytes(wire.LOOPBACK_BYTES + 2))
        assert chips[1].branch_recognised and transfer.reached == 4 and transfer.spliced
        assert [span[:2] for span in ring.spans] == [(2, 2)]
        # BK-56: the repaired line gives the error; a cut frame comes back with its CNTR's ERR set.
        assert (transfer.returned is None) == (error is ErrorKind.DEAD_LINE)
        assert transfer.flags.error == (error is ErrorKind.TRANSMISSION) and transfer.receiver_error is None


LOOP_REPAIRS = [(BranchKind.LOCAL, (0, 1)), (BranchKind.REMOTE, (1, 2)), (BranchKind.LOCAL, (2, 3)),
                (BranchKind.LBD_OR, (0, 2)), (BranchKind.LBD_OR, (1, 2)), (BranchKind.LBD_MR, (0, 3))]  # fmt: skip
"""Two breaks of a loop (indices into :func:`cuts`) repaired together before the cycle the branch joins within."""


@pytest.mark.parametrize(("kind", "pair"), LOOP_REPAIRS)
def test_a_branch_joining_after_two_repairs_fails_with_the_first_repaired_line_s_error(
        kind: BranchKind, pair: tuple[int, int]) -> None:
    """BK-56: with two lines of the loop repaired together, the first along the loop (forward inputs first, then the
    return lines to DI3) gives the error at both fidelities: a forward input by :data:`JOIN_ERRORS`, a return line a
    dead line; in an LBD-MR branch always a dead line (its return repeaters' counter telegrams reach DI3 first)."""
    ops: list[Op] = [*[("cut", index) for index in pair], ("power", 0), ("start", 0), ("cycle", 0), ("repair", 1),
                     ("cycle", 0), ("cycle", 0)]  # fmt: skip
    steps = recognition_history(kind, ("11", True), ops)
    assert [tl for tl, _ in steps] == [pin for _, pin in steps]
    first = cuts(kind)[min(pair)][0]
    error = ErrorKind.DEAD_LINE if kind is BranchKind.LBD_MR else JOIN_ERRORS.get(first, ErrorKind.DEAD_LINE)
    joined = steps[len(pair) + 4][0][3]
    assert joined is not None and not joined[1] and joined[2] == [(error, None, None)]


def test_join_error_refuses_bad_input_by_name() -> None:
    """BK-56's rule (``ring.join_error``) names a bad argument."""
    with pytest.raises(ArgumentError, match=r"^kind must be"):
        join_error("BK-RB", 0)  # type: ignore[arg-type]
    with pytest.raises(ArgumentError, match=r"^first_forward must be"):
        join_error(BranchKind.REMOTE, -1)
    assert [join_error(kind, None) for kind in BranchKind] == [ErrorKind.DEAD_LINE] * len(BranchKind)


def test_the_recognition_stays_through_resets_and_breaks_until_the_power_up() -> None:
    """BK-48 (BK-37's clearing rule): recognised at the master's start, a BK-LB branch stays recognised through a
    break, INTERBUS resets and the branch switched off; the BK's power-up reset forgets it, and with the loop broken
    the next start leaves the branch out (the ring runs through the BK)."""
    ring, chips = tl_ring(BranchKind.LOCAL, "11", True, 2)
    master = Master(ring, locate=False, max_devices=8)
    assert not chips[1].branch_recognised
    assert master.start().ok and chips[1].branch_recognised and master.config is not None and len(master.config) == 5
    ring.inject(DeadLine(4))
    assert not master.start().ok and chips[1].branch_recognised
    chips[1].power_up()
    assert not chips[1].branch_recognised
    assert master.start().ok and not chips[1].branch_recognised and len(master.config) == 3


@pytest.mark.parametrize("at", [0, 1])
def test_a_nested_branch_cut_is_the_same_at_both_fidelities(at: int) -> None:
    """BK-48 in Figure 1-10's nesting (RB device, BK-RB (RB device, BK-LB (LB-MR device)), RB device): a break of the
    inner branch's loop before the first start leaves the inner branch out and the outer one in (the inner BK, not in
    the data path, sends its own stream on DO2); a break of the outer branch's forward line leaves both out (the inner
    BK hears nothing); after the start both are recognised and the master finds the break. The same steps and both
    BKs' recognition at both fidelities."""
    cases: list[Cut] = [(DeadLine(5), (5, True, False)), (ReturnBreak(4), (4, False, True)),
                        (DeadLine(3), (3, True, False))]  # fmt: skip
    for fault, (position, forward, branch) in cases:
        tl, pin = nested_tl(), nested_pin()
        tl_chips = [chip for chip in tl.devices if isinstance(chip, Supi3)]
        pin_chips = [pins.chip for pins in pin.devices]

        def tl_cut(ring: Ring = tl, made: Fault = fault) -> bool:
            ring.inject(made)
            return False

        def pin_cut(ring: PinRing = pin, cut: tuple[int, bool, bool] = (position, forward, branch)) -> bool:
            ring.cut(cut[0], cut[1], branch=cut[2])
            return False

        steps = history(tl, tl_chips, (tl_cut, at), at + 1), history(pin, pin_chips, (pin_cut, at), at + 1)
        assert steps[0] == steps[1], (fault, at)
        bks = [pin.devices[k] for k in (1, 3)]
        assert all(isinstance(bk, Supi3Pins) for bk in bks)
        recognised = [tl_chips[k].branch_recognised for k in (1, 3)]
        assert recognised == [bk.branch_connected for bk in bks if isinstance(bk, Supi3Pins)], (fault, at)
        assert recognised == ([True, True] if at else [False, False] if position == 3 else [True, False]), fault

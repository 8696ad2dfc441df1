"""A dark return fibre of the fibre-linked ring (supi3.optical.ring.OpticalRing; manual 1.6.1, 2.1, 2.2, Figure 1-10;
OPT-47, OPT-58, BK-59): the return fibre of a cable is the return line out of its downstream chip, so a return fibre
going dark is a return-line break at that position, and a master sees on the optical ring what it sees on the
pin-level ring (supi3.model.pinring.PinRing) with that return input cut: every cycle's kind, success and diagnostics,
every chip's LEDs, OUT data and valid data cycles, before and after the repair, in flat rings and trees."""

from __future__ import annotations

from collections.abc import Callable, Sequence

import pytest

from supi3 import tables
from supi3.config import DeviceConfig, decode
from supi3.diagnostics import IbDiag
from supi3.interbus import wire
from supi3.interbus.master import CycleResult, Master
from supi3.interbus.ring import Branch, BranchKind, Bus, ErrorKind, Ring
from supi3.interbus.wire import Cycle
from supi3.model.chip import Supi3
from supi3.model.pinring import PinBranch, PinRing
from supi3.model.pins import Supi3Pins
from supi3.optical.link import Bend, Direction, FibreLink
from supi3.optical.ring import OpticalRing
from supi3.terminal import LBST_PIN
from support import BK_STRAPS, REPAIR_IDLE_TELEGRAMS
from test_model_pinring_tree import ROWS, chip_views, line_break

FAST = tables.clk_conf_for(2_000_000)
DARK_DB = 60.0
"""A bend that no light gets through (OPT-44)."""
TREE_RETURNS = {2: (1, False), 3: (2, True), 4: (3, False), 5: (2, False)}
"""The tree RB device, BK with 2 branch devices, RB device: the return fibre of cable *k* (2..5) as ``PinRing.cut``'s
``position`` and ``branch``: into the RB device from the BK, the BK's DI3 (the branch's first cable), into the first
branch device from the second, into the BK from the RB device behind its branch (sent by its outgoing interface)."""


def _config(row: str) -> DeviceConfig:
    found = next(r for r in tables.MODE_ROWS if r.function == row)
    return decode(found.c, found.mfp, rf="00", clk_conf=FAST)


def _flat(n: int) -> tuple[OpticalRing, PinRing]:
    """``n`` RB chips in optical regulation mode (RF = 00) joined by 10 m polymer fibre, and their pin-level twins
    (whose optical line side is quiet), reading 10h, 20h, ... on their MFP inputs."""
    config = _config(ROWS[BranchKind.REMOTE])
    tl, pin = [Supi3(config) for _ in range(n)], PinRing([Supi3Pins(config) for _ in range(n)])
    for k, chip in enumerate(tl, 1):
        chip.set_mfp_inputs(0x10 * k)
        pin.set_input(k, "mfp_in", 0x10 * k)
    return OpticalRing(tl, [FibreLink(10.0) for _ in tl]), pin


def _tree(kind: BranchKind) -> tuple[OpticalRing, PinRing]:
    """RB chip, BK with 2 branch chips of ``kind``, RB chip (LBST = 1), all in optical regulation mode, at both
    fidelities as :func:`_flat`."""
    remote, inner = _config(ROWS[BranchKind.REMOTE]), _config(ROWS[kind])
    bk = decode(BK_STRAPS[kind.terminal], rf="00", clk_conf=FAST)
    configs = [remote, bk, inner, inner, remote]
    inputs = [0x5A, 1 << LBST_PIN, 0x11, 0x22, 0x33]
    tl = [Supi3(c) for c in configs]
    pins = [Supi3Pins(c) for c in configs]
    pin = PinRing([pins[0], PinBranch(pins[1], pins[2:4], kind), pins[4]])
    for k, (chip, value) in enumerate(zip(tl, inputs, strict=True), 1):
        chip.set_mfp_inputs(value)
        pin.set_input(k, "mfp_in", value)
    ring = OpticalRing([tl[0], Branch(tl[1], tl[2:4], kind), tl[4]], [FibreLink(10.0) for _ in tl])
    return ring, pin


def _settle(ring: Bus) -> None:
    """Idle telegrams before a break: the last cycle's latch telegrams reach every chip first (at pin level they are
    still on their way through a branch's loop when the master's cycle ends; M21's window, not the break's)."""
    ring.idle(REPAIR_IDLE_TELEGRAMS * wire.STATUS_TELEGRAM_BITS / ring.bit_rate)


def _dark(ring: OpticalRing, k: int, locate: bool) -> list[object]:
    """:func:`~test_model_pinring_tree.line_break` with the return fibre of cable ``k`` going dark (a bend no light
    gets through, from the bus time of the cut) and back (the bend ends at the repair)."""
    link = ring.links[k - 1]
    assert link is not None

    def cut() -> None:
        _settle(ring)
        link.add(Bend(ring.now, None, DARK_DB, Direction.RETURN))

    def repair() -> None:
        bend = link.events.pop()
        assert isinstance(bend, Bend)
        link.add(Bend(bend.start_s, ring.now - bend.start_s, DARK_DB, Direction.RETURN))

    return line_break(ring, lambda: ring.ring.devices, locate, cut, repair)


def _cut(ring: PinRing | Ring, position: int, branch: bool, forward: bool = False) -> list[object]:
    """:func:`~test_model_pinring_tree.line_break` with the return input into ``position`` cut (``branch``: the BK's
    DI3 there; ``forward`` at N + 1: the return line into the master, BK-61) after :func:`_settle`, the twin of
    :func:`_dark`."""

    def cut() -> None:
        _settle(ring)
        ring.cut(position, forward, branch=branch)

    def repair() -> None:
        if isinstance(ring, Ring):
            ring.clear_faults()
        else:
            ring.cuts.clear()
            ring.branch_cuts.clear()

    return line_break(ring, lambda: ring.devices, False, cut, repair)


@pytest.mark.parametrize("n", [2, 3])
def test_a_dark_return_fibre_is_a_return_break_at_both_fidelities(n: int) -> None:
    """OPT-58: in a flat ring the return fibre of cable k >= 2 going dark is the return input into chip k - 1 cut
    (BK-59): with ``locate=False`` the master sees the same at both fidelities: one failed data cycle after another,
    a dead line not located, the chips behind the break hearing every frame but latching nothing (OUT data and the
    valid count stay), every chip's RC lit and IB_DIAG steady (no line interrupt ahead, DG-3); repaired, the same
    cycles again. The transaction level's segment search fails first when the ring is closed after chip k, the chip
    at the cable's far end (before, a dead line into chip k: the chips behind it heard nothing)."""
    for k in range(2, n + 1):
        ring, pin = _flat(n)
        seen = _dark(ring, k, False)
        assert seen == _cut(pin, k - 1, False), k
        assert seen[2] == (Cycle.DATA, False, [(ErrorKind.DEAD_LINE, None, None, "no telegram came back", False)])
        leds = seen[5]
        assert isinstance(leds, list) and all(chip[0] and chip[6] is IbDiag.STEADY for chip in leds)
        assert [chip[8] for chip in leds] == [1] * n  # the one data cycle before the break
        located = _dark(_flat(n)[0], k, True)[2]
        assert located == (Cycle.DATA, False, [(ErrorKind.DEAD_LINE, k, f"{k}.0", "no telegram came back; "
                           f"segment search: the ring fails when closed after position {k}", False)])  # fmt: skip


SLOW = pytest.mark.slow
"""The longer cases: the return fibres of a BK-LB tree but its DI3 (the same lines as in a BK-LBD tree, compared in
the quick runs), a return fibre dark through the reset beyond a branch."""


@pytest.mark.parametrize(("kind", "k"), [
    *((BranchKind.LBD_MR, k) for k in sorted(TREE_RETURNS)), (BranchKind.LOCAL, 3),
    pytest.param(BranchKind.LOCAL, 4, marks=SLOW), pytest.param(BranchKind.LOCAL, 2, marks=SLOW),
    pytest.param(BranchKind.LOCAL, 5, marks=SLOW),
])  # fmt: skip
def test_a_dark_return_fibre_in_a_tree_is_a_return_break_at_both_fidelities(kind: BranchKind, k: int) -> None:
    """OPT-58, OPT-54, BK-59: every return fibre of the tree RB, BK, 2 branch chips, RB: on the remote bus (before
    the BK, and from the RB chip behind the branch into the BK's outgoing interface) and in the branch (into the
    BK's DI3, between the branch chips) the master sees the same at both fidelities with ``locate=False``; the
    transaction level's search locates the cable's far end, in an LBD-MR branch the BK's count names the return line
    into the cable's near end (BK-7)."""
    ring, pin = _tree(kind)
    seen = _dark(ring, k, False)
    assert seen == _cut(pin, *TREE_RETURNS[k])
    assert isinstance(seen[2], tuple) and seen[2][2][0][0] is ErrorKind.DEAD_LINE
    leds = seen[5]
    assert isinstance(leds, list) and [chip[8] for chip in leds] == [1] * 5
    ring, _ = _tree(kind)
    located = _dark(ring, k, True)[2]
    ends = ring.ends(k)
    assert ends is not None and isinstance(located, tuple)
    in_branch = kind is BranchKind.LBD_MR and k in (3, 4)
    assert [(d[1], d[4]) for d in located[2]] == [(ends[0], True) if in_branch else (ends[1], False)]


@pytest.mark.parametrize("k", [3, pytest.param(4, marks=SLOW)])
def test_a_dark_return_fibre_in_an_lbd_or_branch_is_the_bks_di3_at_both_fidelities(k: int) -> None:
    """OPT-59: an LBD-OR branch's return fibres carry the loop back from its last chip to the BK (each OR chip passes
    its DI2 on to DI1, the last loops its DO2 back: the first chip's DI1 is the last chip's DO2, M5), so a dark one,
    into the first branch chip or into the second, is the BK's DI3 broken: the master sees what it sees on the
    pin-level ring with ``cut(2, False, branch=True)``, every chip hearing every frame; the transaction level's count
    0 names the return line into the BK (BK-7). Before, the dead forward line into the cable's far end."""
    ring, pin = _tree(BranchKind.LBD_OR)
    seen = _dark(ring, k, False)
    assert seen == _cut(pin, 2, True)
    assert isinstance(seen[2], tuple) and seen[2][2][0][0] is ErrorKind.DEAD_LINE
    leds = seen[5]
    assert isinstance(leds, list) and [chip[8] for chip in leds] == [1] * 5
    located = _dark(_tree(BranchKind.LBD_OR)[0], k, True)[2]
    assert isinstance(located, tuple) and [(d[1], d[4]) for d in located[2]] == [(2, True)]


@pytest.mark.parametrize("n", [1, 3])
def test_the_first_return_fibre_is_the_return_line_into_the_master(n: int) -> None:
    """OPT-58, BK-61: the return fibre of cable 1 carries the return line into the master (line N + 1): every chip
    hears the frames and latches nothing, the master gets nothing back, as with the pin-level ring's and the plain
    transaction-level ring's ``cut(N + 1, True)``; the optical ring's segment search names the return line (before,
    a dead line into chip 1: no chip heard anything)."""
    ring, pin = _flat(n)
    seen = _dark(ring, 1, False)
    assert seen == _cut(pin, n + 1, False, forward=True)
    tl = [Supi3(_config(ROWS[BranchKind.REMOTE])) for _ in range(n)]
    for k, chip in enumerate(tl, 1):
        chip.set_mfp_inputs(0x10 * k)
    assert seen == _cut(Ring(tl, bit_rate=2_000_000), n + 1, False, forward=True)
    assert seen[2] == (Cycle.DATA, False, [(ErrorKind.DEAD_LINE, None, None, "no telegram came back", False)])
    leds = seen[5]
    assert isinstance(leds, list) and [chip[8] for chip in leds] == [1] * n
    located = _dark(_flat(n)[0], 1, True)[2]
    assert located == (Cycle.DATA, False, [(ErrorKind.DEAD_LINE, n + 1, None, "no telegram came back; segment "
                                            "search: the return line", False)])  # fmt: skip


def _restarts(ring: Bus, devices: Callable[[], Sequence[object]], cut: Callable[[], None],
              repair: Callable[[], None]) -> list[object]:  # fmt: skip
    """What a master sees when a line is broken from before its start: two starts (an INTERBUS reset, the optical
    initialization on the optical ring) each with a cycle, every chip's LEDs, OUT data and valid count; then the
    repair, a start and two cycles, and the chips again."""
    master = Master(ring, locate=False, max_devices=8)
    cut()
    seen: list[object] = []

    def record(result: CycleResult) -> None:
        seen.append((result.cycle, result.ok, [(d.kind, d.location, d.detail) for d in result.diagnostics]))

    for _ in range(2):
        record(master.start())
        record(master.cycle())
    seen.append(chip_views(ring, devices()))
    repair()
    record(master.start())
    for _ in range(2):
        record(master.cycle())
    seen.append(chip_views(ring, devices()))
    return seen


@pytest.mark.parametrize(("kind", "k"), [
    (None, 2), (BranchKind.LOCAL, 3), pytest.param(BranchKind.LOCAL, 5, marks=SLOW),
    pytest.param(BranchKind.LBD_MR, 4, marks=SLOW),
])  # fmt: skip
def test_a_return_fibre_dark_through_the_reset_is_the_same_at_both_fidelities(kind: BranchKind | None, k: int) -> None:
    """OPT-58: a return fibre dark from before the master's start: the INTERBUS reset reaches every chip (a return line
    of the remote bus stops nothing, BK-59; one of a branch stops it behind that branch, BK-10, the optical ring's
    initialization with it), the starts fail alike at both fidelities, the chips show the same; repaired, the start
    and the cycles pass alike. Cases: a flat ring's, the BK-LB branch's DI3 and the return line into the BK from the
    chip behind its branch, a return line inside an LBD-MR branch."""
    ring, pin = _flat(3) if kind is None else _tree(kind)
    link = ring.links[k - 1]
    assert link is not None
    position, branch = (k - 1, False) if kind is None else TREE_RETURNS[k]

    def repair() -> None:
        pin.cuts.clear()
        pin.branch_cuts.clear()

    seen = _restarts(ring, lambda: ring.ring.devices, lambda: link.add(Bend(0.0, None, DARK_DB, Direction.RETURN)),
                     link.events.clear)  # fmt: skip
    assert seen == _restarts(pin, lambda: pin.devices, lambda: pin.cut(position, False, branch=branch), repair)
    assert not any(result[1] for result in seen[:4])  # type: ignore[index]
    assert all(result[1] for result in seen[5:8])  # type: ignore[index]

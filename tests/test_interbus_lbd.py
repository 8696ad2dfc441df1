"""Device-oriented local-bus diagnostics (manual 2.2.2): the counter telegram (wire, docs/interbus.md "Counter
telegram"), the count a BK receives behind a break (ring.lbd_count) and its inverse (ring.lbd_position), and the
master locating every break in an LBD branch exactly, over random trees and histories of breaks, clears, branch
switching and resets (docs/assumptions/bus-terminal.md BK-5..BK-7)."""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3 import tables
from supi3.config import decode
from supi3.errors import ArgumentError
from supi3.interbus import wire
from supi3.interbus.device import PlainDevice
from supi3.interbus.errors import InterbusError
from supi3.interbus.link import Device
from supi3.interbus.master import Master
from supi3.interbus.ring import (
    BitFlip,
    Branch,
    BranchKind,
    DeadLine,
    ErrorKind,
    ReturnBreak,
    Ring,
    lbd_count,
    lbd_position,
    return_repeaters,
)
from supi3.interbus.wire import Cycle
from supi3.model.chip import Supi3
from support import terminal

RECOVERY_CYCLES = 12
"""A master on a healthy tree latches data cycles again within this many cycles (a switch or a reconfiguration
costs up to four ID cycles: the command, the discovery, the status request and its answer)."""

# -- the counter telegram ------------------------------------------------------------------------------------------


def test_counter_telegram_round_trips_every_count_and_is_a_data_telegram() -> None:
    for count in range(1, wire.COUNTER_MAX + 1):
        word = wire.counter_telegram(count)
        assert wire.decode_counter_telegram(word) == count
        telegram = wire.decode_telegram(word, wire.DATA_TELEGRAM_BITS)
        assert (telegram.cycle, telegram.check, telegram.data) == (Cycle.ID, True, 0x80 | count)


def test_counter_telegram_is_told_from_every_other_data_telegram() -> None:
    counters = {wire.counter_telegram(c) for c in range(1, wire.COUNTER_MAX + 1)} | {
        wire.data_telegram(wire.COUNTER_SATURATED_MARK | c, Cycle.ID, True) for c in range(wire.COUNTER_MAX + 1)
    }  # saturated counts (BK-31)
    for byte, cycle, check in itertools.product(range(256), Cycle, (False, True)):
        word = wire.data_telegram(byte, cycle, check)
        assert (wire.decode_counter_telegram(word) is not None) == (word in counters)
    assert wire.decode_counter_telegram(wire.status_telegram(Cycle.ID, True)) is None
    assert wire.decode_counter_telegram(wire.counter_telegram(5) & ~(1 << 12)) is None  # stop bit lost


def test_count_on_starts_at_one_increments_and_saturates() -> None:
    word = wire.count_on(None)
    assert wire.decode_counter_telegram(word) == 1
    for expected in range(2, wire.COUNTER_MAX + 3):
        word = wire.count_on(word)
        assert wire.decode_counter_telegram(word) == min(expected, wire.COUNTER_MAX)
    with pytest.raises(InterbusError, match="counter telegrams only"):
        wire.count_on(wire.data_telegram(0x12, Cycle.DATA, False))


def test_branch_status_byte_round_trips_exhaustively() -> None:
    for conf, closed, count in itertools.product((False, True), (False, True), range(wire.COUNTER_MAX + 1)):
        assert wire.decode_bk_status(wire.bk_status(conf, closed, count)) == wire.BkStatus(conf, closed, count)


@pytest.mark.parametrize(("call", "name"), [
    (lambda: wire.counter_telegram(0), "count"),
    (lambda: wire.counter_telegram(64), "count"),
    (lambda: wire.counter_telegram(True), "count"),
    (lambda: wire.counter_telegram("3"), "count"),  # type: ignore[arg-type]
    (lambda: wire.decode_counter_telegram(1 << 13), "word"),
    (lambda: wire.decode_counter_telegram(-1), "word"),
    (lambda: wire.bk_status(1, False, 0), "conf_request"),  # type: ignore[arg-type]
    (lambda: wire.bk_status(False, None, 0), "closed"),  # type: ignore[arg-type]
    (lambda: wire.bk_status(False, False, 64), "count"),
    (lambda: wire.decode_bk_status(256), "byte"),
    (lambda: wire.command_word(branch=2), "branch"),  # type: ignore[arg-type]
    (lambda: lbd_position(BranchKind.LOCAL, 3, 1), "kind"),
    (lambda: lbd_position("LBD-MR", 3, 1), "kind"),  # type: ignore[arg-type]
    (lambda: lbd_position(BranchKind.LBD_MR, -1, 1), "devices"),
    (lambda: lbd_position(BranchKind.LBD_MR, 3, 64), "count"),
    (lambda: lbd_count(BranchKind.REMOTE, 3, set(), set()), "kind"),
    (lambda: lbd_count(BranchKind.LBD_MR, 3.0, set(), set()), "devices"),  # type: ignore[arg-type]
    (lambda: lbd_count(BranchKind.LBD_MR, 3, 2, set()), "forward"),  # type: ignore[arg-type]
    (lambda: lbd_count(BranchKind.LBD_MR, 3, {4}, set()), "forward device"),
    (lambda: lbd_count(BranchKind.LBD_MR, 3, {0}, set()), "forward device"),
    (lambda: lbd_count(BranchKind.LBD_OR, 3, set(), {-1}), "back device"),
    (lambda: ReturnBreak(0), "segment"),
    (lambda: ReturnBreak(2, cycles=0), "cycles"),
])  # fmt: skip
def test_counter_entries_refuse_wrong_types_and_ranges(call: object, name: str) -> None:
    with pytest.raises(ArgumentError, match=rf"^{name} must be"):
        call()  # type: ignore[operator]


def test_branch_control_round_trips_in_the_command_word() -> None:
    for control in wire.BranchControl:
        word = wire.command_word(1, True, None, True, control)
        assert wire.decode_command_word(word) == wire.CommandWord(1, True, None, True, control)


# -- count and position ----------------------------------------------------------------------------------------------


def single_breaks(kind: BranchKind, m: int) -> list[tuple[int, bool]]:
    """Every line of an LBD branch of ``m`` devices: (device k, return line), k = 0 for the BK's return input."""
    back = range(m) if kind is BranchKind.LBD_MR else range(1)
    return [(k, False) for k in range(1, m + 1)] + [(k, True) for k in back]


@pytest.mark.parametrize("kind", [BranchKind.LBD_MR, BranchKind.LBD_OR])
def test_every_single_break_gives_a_count_that_locates_it(kind: BranchKind) -> None:
    for m in range(1, 32 if kind is BranchKind.LBD_MR else 63):
        counts = []
        for k, back in single_breaks(kind, m):
            count = lbd_count(kind, m, set() if back else {k}, {k} if back else set())
            counts.append(count)
            assert lbd_position(kind, m, 0 if count is None else count) == (k, back)
        assert len(set(counts)) == len(counts)


def test_counts_follow_the_principle_of_2_2_2() -> None:
    # MR, 3 devices, break before device 2: devices 2, 3 forward, then 3, 2, 1 on the looped return line
    assert lbd_count(BranchKind.LBD_MR, 3, {2}, set()) == 5
    assert lbd_count(BranchKind.LBD_OR, 3, {2}, set()) == 2  # OR: devices 2, 3 forward only
    assert lbd_count(BranchKind.LBD_MR, 3, set(), {1}) == 1  # return line from device 2 into device 1
    assert lbd_count(BranchKind.LBD_MR, 3, set(), set()) is None
    assert lbd_count(BranchKind.LBD_MR, 3, {1, 3}, {0}) is None  # the BK's own return input: nothing arrives
    assert lbd_count(BranchKind.LBD_MR, 3, {1, 3}, {2}) == 2  # the last break on the path wins
    assert lbd_count(BranchKind.LBD_OR, 63, {1}, set()) == wire.COUNTER_MAX  # saturated ...
    assert lbd_position(BranchKind.LBD_OR, 63, wire.COUNTER_MAX) is None  # ... locates nothing
    assert lbd_position(BranchKind.LBD_MR, 3, 3) is None  # the loop inside device 3 is no line
    assert lbd_position(BranchKind.LBD_MR, 3, 7) is None
    assert lbd_position(BranchKind.LBD_OR, 3, 4) is None


# -- the master over random trees and histories ----------------------------------------------------------------------

CODES = {BranchKind.LBD_MR: 0xBF, BranchKind.LBD_OR: 0xB3, BranchKind.LOCAL: 0xBE, BranchKind.REMOTE: 0x03}


@dataclass
class Tree:
    ring: Ring
    master: Master
    lbd: dict[int, tuple[BranchKind, int]]
    """id() of each LBD branch device and BK -> its kind and its place in the branch (0: the BK)."""


@st.composite
def trees(draw: st.DrawFn) -> Tree:
    items: list[Device | Branch] = [PlainDevice(0x03, 0b01001)]
    lbd: dict[int, tuple[BranchKind, int]] = {}
    for _ in range(draw(st.integers(0, 3))):
        kind = draw(st.sampled_from([BranchKind.LBD_MR, BranchKind.LBD_OR, BranchKind.LOCAL]))
        bk = terminal("BK-LB" if kind is BranchKind.LOCAL else "BK-LBD")
        devices = [PlainDevice(CODES[kind], draw(st.sampled_from([0b01101, 0b01001, 0b00001])))
                   for _ in range(draw(st.integers(0, 6)))]  # fmt: skip
        if kind is not BranchKind.LOCAL:
            lbd[id(bk)] = (kind, 0)
            lbd.update({id(d): (kind, k) for k, d in enumerate(devices, 1)})
        items.append(Branch(bk, devices, kind))
        if draw(st.booleans()):
            items.append(PlainDevice(0x02, 0b01001))
    ring = Ring(items)
    master = Master(ring)
    master.start()
    return Tree(ring, master, lbd)


def healthy(tree: Tree) -> None:
    """The master latches a data cycle on a table that matches the ring within RECOVERY_CYCLES: never stuck."""
    for _ in range(RECOVERY_CYCLES):
        result = tree.master.cycle()
        if result.ok and result.cycle is Cycle.DATA:
            assert tree.master.config is not None and len(tree.master.config) == len(tree.ring.devices)
            return
    raise AssertionError(f"stuck: {tree.master.diagnostics[-3:]}")


def expected(tree: Tree, fault: DeadLine | ReturnBreak) -> tuple[int, bool]:
    """Where a single break must be reported: its own line in an LBD branch (the counter telegram); elsewhere where
    the segment search finds it (a forward line: its own; a return line of a branch without the counter: the
    first position whose probe crosses it)."""
    devices = tree.ring.devices
    if fault.segment > len(devices):
        return fault.segment, False
    place = tree.lbd.get(id(devices[fault.segment - 1]))
    if isinstance(fault, DeadLine):
        return fault.segment, False
    return (fault.segment, True) if place is not None else (fault.segment + 1, False)


def breaks(tree: Tree) -> list[DeadLine | ReturnBreak]:
    """Every line of the ring now that a single break can hit."""
    found: list[DeadLine | ReturnBreak] = [DeadLine(k) for k in range(1, len(tree.ring.devices) + 2)]
    for at, size, kind in tree.ring.spans:
        found.append(ReturnBreak(at))
        if kind is not BranchKind.LBD_OR:
            found += [ReturnBreak(at + k) for k in range(1, size)]
    return found


@settings(max_examples=40)
@given(trees(), st.data())
def test_every_break_is_located_exactly_after_any_history(tree: Tree, data: st.DataObject) -> None:
    healthy(tree)
    for _ in range(data.draw(st.integers(1, 8), label="events")):
        event = data.draw(st.sampled_from(["break", "break", "switch", "reset"]), label="event")
        bks = [k for k, d in enumerate(tree.ring.devices, 1) if getattr(d, "terminal_interface", None)]
        if event == "switch" and bks:
            at = data.draw(st.sampled_from(bks), label="bk")
            tree.master.switch_branch(at, data.draw(st.booleans(), label="on"))
        elif event == "reset":
            tree.master.start()
        elif event == "break":
            fault = data.draw(st.sampled_from(breaks(tree)), label="fault")
            tree.ring.inject(fault)
            where = expected(tree, fault)
            result = tree.master.cycle()
            assert not result.ok
            found = result.diagnostics[0]
            assert (found.location, found.return_line) == where, found
            again = tree.master.cycle()  # the same break, once more: the same place
            assert (again.diagnostics[0].location, again.diagnostics[0].return_line) == where
            tree.ring.clear_faults()
        healthy(tree)


@settings(max_examples=15)
@given(st.sampled_from([BranchKind.LBD_MR, BranchKind.LBD_OR]), st.integers(1, 6), st.data())
def test_two_breaks_one_after_the_other_in_one_branch_each_located(kind: BranchKind, m: int,
                                                                   data: st.DataObject) -> None:  # fmt: skip
    """The review's history: a break, cleared, then another in the same branch: the BK's count is the new one."""
    bk = terminal("BK-LBD")
    ring = Ring([PlainDevice(0x03, 0b01001), Branch(bk, [PlainDevice(CODES[kind], 0b01001) for _ in range(m)],
                                                    kind), PlainDevice(0x02, 0b01001)])  # fmt: skip
    tree = Tree(ring, Master(ring), {id(d): (kind, 0) for d in ring.devices[1:-1]})
    tree.master.start()
    healthy(tree)
    inside = [f for f in breaks(tree) if 3 <= f.segment <= 2 + m or isinstance(f, ReturnBreak)]
    for fault in data.draw(st.lists(st.sampled_from(inside), min_size=2, max_size=4), label="faults"):
        tree.ring.inject(fault)
        found = tree.master.cycle().diagnostics[0]
        assert (found.location, found.return_line) == expected(tree, fault)
        tree.ring.clear_faults()
        healthy(tree)


def test_a_count_that_disagrees_with_the_search_locates_nothing() -> None:
    """Two breaks in one LBD-MR branch: the search finds the first, the count tells the last: not located."""
    bk = terminal("BK-LBD")
    ring = Ring([Branch(bk, [PlainDevice(0xBF, 0b01001) for _ in range(4)], BranchKind.LBD_MR)])
    master = Master(ring)
    master.start()
    ring.inject(DeadLine(3))
    ring.inject(ReturnBreak(4))
    found = master.cycle().diagnostics[0]
    assert found.location is None and "fits no break" in found.detail


def branch_tree(kind: BranchKind, m: int) -> Tree:
    """The smallest tree around a branch: a remote bus device, the BK with ``m`` devices of ``kind``, another one."""
    bk = terminal(kind.terminal)
    devices = [PlainDevice(CODES[kind], 0b01001) for _ in range(m)]
    ring = Ring([PlainDevice(0x03, 0b01001), Branch(bk, devices, kind), PlainDevice(0x02, 0b01001)])
    lbd = {id(d): (kind, k) for k, d in enumerate([bk, *devices])} if kind.diagnostics else {}
    tree = Tree(ring, Master(ring), lbd)
    tree.master.start()
    healthy(tree)
    return tree


@pytest.mark.parametrize("kind", [BranchKind.LBD_OR, BranchKind.LBD_MR])
@pytest.mark.parametrize("m", [1, 3])
def test_bit_errors_into_an_lbd_branchs_first_device_are_its_forward_line(kind: BranchKind, m: int) -> None:
    """Issue 12 (BK-62): bit errors on the forward line into the first device of an LBD branch (line 3 here) come
    back as a transmission error; the segment search fails first at 3 and the BK, with no interrupt to count, reads
    0, which also fits a break of its own return input (BK-7). Before, the master trusted the count and reported
    "the return line into the BK" (position 2); the count locates only an interrupt (2.2.2), so the forward line
    into device 3 stands. The break of the BK's return input itself still reads as such (a dead line)."""
    tree = branch_tree(kind, m)
    tree.ring.inject(BitFlip(3, 40, None))
    found = tree.master.cycle().diagnostics[0]
    assert (found.kind, found.location, found.device, found.return_line) == (ErrorKind.TRANSMISSION, 3, "2.1", False)
    assert "counted" not in found.detail, found.detail
    tree.ring.clear_faults()
    healthy(tree)
    tree.ring.inject(ReturnBreak(2))
    found = tree.master.cycle().diagnostics[0]
    assert (found.kind, found.location, found.return_line) == (ErrorKind.DEAD_LINE, 2, True)
    assert "counted 0" in found.detail


def located_faults(tree: Tree) -> st.SearchStrategy[BitFlip | DeadLine | ReturnBreak]:
    """A fault of the tree now: bit errors on any forward line (the return line into the master too) at any bit
    period of the frame, or a break of any line."""
    n = len(tree.ring.devices)
    flips = st.builds(BitFlip, st.integers(1, n + 1), st.integers(0, wire.cycle_bits(2 * n, n)), st.none())
    return st.one_of(flips, st.sampled_from(breaks(tree)))


@settings(max_examples=100, deadline=None, derandomize=True)
@given(st.sampled_from(list(BranchKind)), st.integers(1, 4), st.data())
def test_every_bit_error_or_break_in_every_branch_kind_is_located_on_its_line(kind: BranchKind, m: int,
                                                                              data: st.DataObject) -> None:  # fmt: skip
    """BK-7, BK-62 over histories of faults in one tree of every branch kind (BK-RB, BK-LB, LBD-MR, LBD-OR): bit
    errors are located at the forward line they hit (the count of an LBD branch is not asked), a break on its own
    line (LBD: by the count) or, on a return line without the counter, at the first probe that crosses it."""
    tree = branch_tree(kind, m)
    for _ in range(data.draw(st.integers(1, 5), label="faults")):
        fault = data.draw(located_faults(tree), label="fault")
        tree.ring.inject(fault)
        result = tree.master.cycle()
        if isinstance(fault, BitFlip) and result.ok:  # a bit period no receiver checks
            tree.ring.clear_faults()
            continue
        where = (fault.segment, False) if isinstance(fault, BitFlip) else expected(tree, fault)
        found = result.diagnostics[0]
        assert not result.ok and (found.location, found.return_line) == where, (fault, found)
        tree.ring.clear_faults()
        healthy(tree)


LOOP_EDITS = st.lists(st.tuples(st.integers(0, 3), st.sampled_from(["LBD-MR", "LBD-OR", "plain"])), max_size=6)


@settings(max_examples=20, deadline=None, derandomize=True)
@given(LOOP_EDITS)
def test_the_ring_delay_counts_lbd_mr_chips_over_edits_of_a_plain_ring(edits: list[tuple[int, str]]) -> None:
    """BK-55: a transaction-level cycle takes ``wire.cycle_bits`` with the ring's LBD-MR chips as return repeaters
    (``ring.return_repeaters``, ``Transfer.return_repeaters``), also after a plain ring's devices are replaced in place
    (the count is cached for the data path and taken again when it holds other devices)."""
    def device(kind: str) -> Device:
        if kind == "plain":
            return PlainDevice(0xBF, 0b01001)
        row = next(r for r in tables.MODE_ROWS if r.function == f"{kind}, 8 IN/8 OUT")
        return Supi3(decode(row.c, row.mfp, clk_conf=tables.clk_conf_for(2_000_000)))

    ring = Ring([device("LBD-MR") for _ in range(4)], bit_rate=2_000_000)
    data = bytes(wire.LOOPBACK_BYTES + 4)
    for at, kind in [(0, "LBD-MR"), *edits]:
        ring.devices[at] = device(kind)
        start = ring.now
        transfer = ring.transfer(Cycle.DATA, data)
        ring.finish(transfer, False)
        loops = return_repeaters(ring.devices)
        assert transfer.return_repeaters == loops == sum(isinstance(d, Supi3) and d.config.interface.value == "LBD-MR"
                                                         for d in ring.devices)  # fmt: skip
        assert round((ring.now - start) * ring.bit_rate) == wire.cycle_bits(4, 4, loops)

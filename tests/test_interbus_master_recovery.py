"""Issue #8, parts 1 and 2: the master recovers from ring changes, locates errors right or not at all, and keeps
its diagnostics bounded. Scenarios from the issue, then properties over histories of faults, changes and resets.
Issue #12: a master without error location finds a ring shortened by a BK's closure or lengthened by a reset (A25)
and runs again on it, over any history of a tree.
"""

from __future__ import annotations

import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from supi3 import tables
from supi3.config import MfpKind, decode
from supi3.interbus import wire
from supi3.interbus.device import PlainDevice
from supi3.interbus.errors import InterbusError
from supi3.interbus.link import Device
from supi3.interbus.master import CycleResult, Master
from supi3.interbus.ring import BitFlip, BranchKind, CorruptLoopback, DeadLine, ErrorKind, Fault, Ring, Truncate
from supi3.interbus.wire import Cycle
from supi3.model.chip import Supi3
from supi3.model.pinring import PinRing
from supi3.model.pins import Supi3Pins
from test_model_pinring_tree import CASES, SILENCE, pin_tree, tl_tree

USABLE_LENGTHS = [int(row.code, 2) for row in tables.LENGTH_CODES if row.bits is not None]
ID_CODE_VALUES = sorted({row.code for row in tables.ID_CODES})
BINARY = [r for r in tables.MODE_ROWS if decode(r.c, r.mfp).mfp_mode.kind is MfpKind.BINARY_IO]
RECOVERY_CYCLES = 4
"""A master on a healthy ring is latching data cycles again within this many cycles of any history."""


def started(devices: list[Device], **options: bool | int) -> tuple[Ring, Master]:
    ring = Ring(devices)
    master = Master(ring, **options)  # type: ignore[arg-type]
    assert master.start().ok
    return ring, master


def plain(*specs: tuple[int, int]) -> list[Device]:
    return [PlainDevice(i, length) for i, length in specs]


def distinct(n: int) -> list[Device]:
    return plain(*[(0x01 + k, 0b01001) for k in range(n)])


def healthy(master: Master) -> int:
    """Cycles until a data cycle is latched (fails the test beyond RECOVERY_CYCLES)."""
    for k in range(1, RECOVERY_CYCLES + 1):
        result = master.cycle()
        if result.ok and result.cycle is Cycle.DATA:
            return k
    raise AssertionError(f"stuck: no data cycle latched in {RECOVERY_CYCLES} cycles: {master.diagnostics[-3:]}")


# -- part 1: ring changes ------------------------------------------------------------------------------------------


def test_up_chip_changing_its_length_is_a_configuration_error_then_rediscovered() -> None:
    chip = Supi3(decode("10011", "1110"), strict=False)  # RB, Init-µP
    assert chip.registers is not None
    _, master = started([PlainDevice(0xBF, 1), chip])
    chip.registers.cpu_write(13, 0x82)
    chip.registers.cpu_write(12, 0x01)
    assert master.start().ok and master.cycle().ok
    chip.registers.cpu_write(13, 0x83)  # 2 bytes now, while the bus runs
    result = master.cycle()
    (diagnostic,) = result.diagnostics
    assert diagnostic.kind is ErrorKind.CONFIGURATION and diagnostic.location == 2
    assert master.config is None
    healthy(master)
    assert master.entry(2).data_bytes == 2


@pytest.mark.parametrize(("change", "where"), [("remove", 1), ("remove", 2), ("remove", 4), ("insert", 1),
                                                ("insert", 3), ("insert", 5)])  # fmt: skip
def test_a_device_removed_or_inserted_is_a_configuration_error_at_its_position(change: str, where: int) -> None:
    ring, master = started(distinct(4))
    assert master.cycle().ok
    if change == "remove":
        del ring.devices[where - 1]
    else:
        ring.devices.insert(where - 1, PlainDevice(0x40, 0b01001))
    result = master.cycle()
    (diagnostic,) = result.diagnostics
    assert diagnostic.kind is ErrorKind.CONFIGURATION
    assert diagnostic.location == where
    assert "configuration changed" in diagnostic.detail
    healthy(master)
    assert master.config is not None and len(master.config) == len(ring.devices)


def test_removing_one_of_identical_devices_names_the_first_position_that_differs() -> None:
    ring, master = started(plain(*[(0xBF, 1)] * 4))
    del ring.devices[1]
    (diagnostic,) = master.cycle().diagnostics
    assert diagnostic.kind is ErrorKind.CONFIGURATION and diagnostic.location == 4  # position 4 is gone


def test_without_rediscover_the_master_waits_for_start() -> None:
    ring, master = started(distinct(3), rediscover=False)
    del ring.devices[2]
    (diagnostic,) = master.cycle().diagnostics
    assert diagnostic.kind is ErrorKind.CONFIGURATION and diagnostic.location == 3
    assert master.stopped and master.config is None
    with pytest.raises(InterbusError, match="waits for start"):
        master.cycle()
    assert master.start().ok and not master.stopped
    healthy(master)


def test_a_changed_id_code_at_same_length_is_found_in_the_next_id_cycle() -> None:
    ring, master = started(distinct(3))
    ring.devices[1] = PlainDevice(0x70, 0b01001)
    master.set_watchdog(None)
    (diagnostic,) = master.cycle().diagnostics
    assert diagnostic.kind is ErrorKind.CONFIGURATION and diagnostic.location == 2
    healthy(master)


@pytest.mark.parametrize("change", ["remove", "insert"])
def test_without_location_a_device_removed_or_inserted_is_found_then_rediscovered(change: str) -> None:
    """A25: fewer devices put the loopback word of the ID cycle over the table out of place, more leave it out (the
    discovery-sized rescan then finds the count); both a configuration error at the first position that differs,
    then data cycles on the new ring, with ``locate=False``."""
    ring, master = started(distinct(4), locate=False)
    if change == "remove":
        del ring.devices[2]
    else:
        ring.devices.insert(2, PlainDevice(0x40, 0b01001))
    kinds = [d.kind for _ in range(3) for d in master.cycle().diagnostics]
    assert kinds[-1] is ErrorKind.CONFIGURATION and master.diagnostics[-1].location == 3
    healthy(master)
    assert master.config is not None and len(master.config) == len(ring.devices)


def test_without_location_a_corrupted_loopback_word_is_no_configuration_error() -> None:
    """A25: a loopback word missing while the ring keeps its length (a sender's fault, CRC good) is reported as it
    is, not located, and the table stays."""
    ring, master = started(distinct(3), locate=False)
    ring.inject(CorruptLoopback(2, 0x1234, None))
    kinds = {d.kind for _ in range(4) for d in master.cycle().diagnostics}
    assert kinds == {ErrorKind.LOOPBACK} and master.config is not None and len(master.config) == 3
    ring.clear_faults()
    healthy(master)


def closed(kind: BranchKind, m: int, **options: bool) -> tuple[Ring, Master, list[ErrorKind]]:
    """The tree of ``kind`` with ``m`` branch devices, the branch switched on with the extended function (BK-3) and
    its last device's forward line cut, then cycles until the BK closed the branch (BK-50) and 3 more; the
    diagnostic kinds seen."""
    ring = tl_tree(kind, m, silence=SILENCE)
    master = Master(ring, max_devices=8, **options)
    assert master.start().ok
    master.switch_branch(2, True, extended=True)
    healthy(master)
    ring.cut(2 + m, True)
    bk = ring.devices[1]
    assert isinstance(bk, Supi3)
    kinds: list[ErrorKind] = []
    after = 0
    while after < 3 and len(kinds) < 40 and not master.stopped:
        kinds += [d.kind for d in master.cycle().diagnostics]
        after += bool(bk.bus_terminal is not None and bk.bus_terminal.closures)
    return ring, master, kinds


@pytest.mark.parametrize(("kind", "m"), CASES[:4])
def test_without_location_a_master_runs_on_after_a_bk_closed_its_branch(kind: BranchKind, m: int) -> None:
    """Issue #12 (BK-45, A25): a BK that closes its silent branch (2.4) shortens the ring; the master without error
    location reads the loopback word after fewer ID registers, a configuration error at the BK's branch, rediscovers
    (A19) and runs data cycles on the shorter ring, then reads the BK's report."""
    ring, master, kinds = closed(kind, m, locate=False)
    assert ErrorKind.CONFIGURATION in kinds
    healthy(master)
    assert master.config is not None and len(master.config) == 3
    for _ in range(3):
        master.cycle()
    assert ErrorKind.BRANCH_CLOSED in [d.kind for d in master.diagnostics]
    ring.clear_faults()
    ring.reset()  # the reset switches the branch on again (BK-9): a longer ring than the table, found by the rescan
    kinds = [d.kind for _ in range(2) for d in master.cycle().diagnostics]
    assert kinds[-1] is ErrorKind.CONFIGURATION
    healthy(master)
    assert len(master.config) == 3 + m


def test_without_rediscover_a_closure_waits_for_start() -> None:
    """A19, A25: with ``rediscover=False`` the closure's configuration error stops the master until ``start()``."""
    _, master, kinds = closed(BranchKind.LOCAL, 2, locate=False, rediscover=False)
    assert ErrorKind.CONFIGURATION in kinds and master.stopped
    with pytest.raises(InterbusError, match="waits for start"):
        master.cycle()
    master.start()  # the reset switches the branch on again (BK-9), into the cut: the ring carries no frame
    assert not master.stopped


SETTLE_CYCLES = 16
"""After a tree's last change a master without location runs data cycles again within this many cycles, if a
fresh master (no reset) can run on that ring: the closure (``SILENCE``, about 3 cycles) and its rediscovery."""

TREE_OPS = ["off", "on", "ext", "start", "reset", "cut", "di3", "ret", "repair", "wait"]
TREE_STEPS = st.lists(
    st.tuples(st.sampled_from(TREE_OPS), st.integers(3, 4), st.integers(0, 3)), min_size=1, max_size=6
)


def run_tree(ring: Ring | PinRing, master: Master, steps: list[tuple[str, int, int]]) -> list[CycleResult]:
    """``steps`` on the tree: ``off``, ``on``, ``ext`` (``switch_branch``, if the table has the BK's entry),
    ``start``, ``reset`` (``ring.reset()`` alone: the BK switches its branch on again, BK-9), ``cut`` (the forward line
    into physical position ``k``), ``di3`` (the BK's branch return input), ``ret`` (a remote bus return line next to
    the BK), ``repair`` (every break), ``wait`` (nothing); each followed by its number of cycles, then
    ``SETTLE_CYCLES`` cycles. Returns every cycle's result."""
    seen: list[CycleResult] = []
    for op, k, cycles in steps:
        if op == "start":
            seen.append(master.start())
        elif op == "reset":
            ring.reset()
        elif op == "cut":
            ring.cut(k, True)
        elif op == "di3":
            ring.cut(2, False, branch=True)
        elif op == "ret":
            ring.cut(k - 2, False)
        elif op == "repair":
            if isinstance(ring, Ring):
                ring.clear_faults()
            else:
                ring.cuts.clear()
        elif op != "wait" and master.config is not None and len(master.config) > 1 and master.config[1].data_bytes == 0:
            master.switch_branch(2, op != "off", extended=op == "ext")
        seen += [master.cycle() for _ in range(cycles)]
    return seen + [master.cycle() for _ in range(SETTLE_CYCLES)]


def passes_data(results: list[CycleResult]) -> bool:
    return any(r.ok and r.cycle is Cycle.DATA for r in results)


@settings(max_examples=100, deadline=None)  # about 0.07 s an example
@given(st.sampled_from(CASES), TREE_STEPS)
@example((BranchKind.LOCAL, 2), [("ext", 3, 3), ("cut", 4, 0)])  # issue #12: the closure, a shorter ring
@example((BranchKind.LBD_MR, 1), [("off", 3, 3), ("reset", 3, 0)])  # the reset switches the branch on: longer
@example((BranchKind.LBD_OR, 1), [("ext", 3, 1), ("cut", 3, 3), ("wait", 3, 3), ("repair", 3, 1), ("reset", 3, 0)])
def test_without_location_a_master_is_never_stuck_after_any_tree_history(
    case: tuple[BranchKind, int], steps: list[tuple[str, int, int]]
) -> None:
    """Issue #12 (A25): over any history of branch switches (with and without the extended function), INTERBUS
    resets, starts, cuts (in the branch, of the BK's DI3, of a remote bus return line), repairs and the closures they
    bring, a master with ``locate=False`` and ``rediscover=True`` is never stuck: once the tree stops changing it
    latches data cycles within ``SETTLE_CYCLES`` on whatever ring is left, whenever a fresh master (no reset) can,
    and with the same configuration."""
    kind, m = case
    ring = tl_tree(kind, m, silence=SILENCE)
    master = Master(ring, locate=False, max_devices=8)
    assert master.start().ok
    ours = run_tree(ring, master, [(op, min(k, 2 + m), cycles) for op, k, cycles in steps])[-SETTLE_CYCLES:]
    fresh = Master(ring, locate=False, max_devices=8)
    if not passes_data([fresh.cycle() for _ in range(SETTLE_CYCLES)]):
        return  # the ring carries no frame: nothing to run on
    assert passes_data(ours), [d.kind for r in ours for d in r.diagnostics]
    assert master.cycle().ok and master.config == fresh.config


PIN_HISTORIES = [
    ((BranchKind.LBD_MR, 1), [("off", 3, 3), ("reset", 3, 0)]),
    pytest.param((BranchKind.LBD_MR, 2), [("ext", 3, 3), ("cut", 4, 3), ("off", 3, 2), ("on", 3, 3)],
                 marks=pytest.mark.slow),
]  # fmt: skip
"""Histories of the property above run at both fidelities (about 5 s each: the pin level is slow); the quick tier
keeps the longer ring after a reset, ``test_model_pinring_tree`` the closure, its repair and a reset (BK-45)."""


@pytest.mark.parametrize(("case", "steps"), PIN_HISTORIES)
def test_without_location_a_master_runs_on_alike_at_both_fidelities(
    case: tuple[BranchKind, int], steps: list[tuple[str, int, int]]
) -> None:
    """Issue #12 (A25): a sample of the histories above at the pin level (``PinRing``): every cycle's success and
    diagnostics (kind, location, device) as at transaction level, and data cycles latched at the end."""
    kind, m = case
    seen = []
    for ring in (tl_tree(kind, m, silence=SILENCE), pin_tree(kind, m, silence=SILENCE)):
        master = Master(ring, locate=False, max_devices=8)
        results = [master.start(), *run_tree(ring, master, steps)]
        seen.append([(r.cycle, r.ok, [(d.kind, d.location, d.device) for d in r.diagnostics]) for r in results])
        assert passes_data(results[-3:])
    assert seen[0] == seen[1]


# -- part 2: error locations ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("between", ["cycle", "data_cycle"])
def test_a_te_bit_left_from_an_earlier_fault_is_not_blamed(between: str) -> None:
    ring, master = started(plain(*[(0xBF, 1)] * 4))
    ring.inject(BitFlip(3, 5, cycles=None))
    assert master.data_cycle().diagnostics[0].location == 3
    ring.clear_faults()
    assert getattr(master, between)().ok
    ring.inject(CorruptLoopback(1, 0x1234))
    assert master.cycle().diagnostics[0].location is None  # one cycle only: gone before the search
    ring.inject(BitFlip(4, 5))
    assert master.cycle().diagnostics[0].location == 4  # the fault of this cycle, read from its TE bit


def test_a_te_bit_left_by_a_persistent_truncation_is_not_blamed() -> None:
    ring, master = started(plain(*[(0xBF, 1)] * 2))
    ring.inject(Truncate(1, 0, None))
    assert master.cycle().diagnostics[0].location == 1
    ring.clear_faults()
    assert master.cycle().ok
    ring.inject(Truncate(2, 0, 1))
    assert master.cycle().diagnostics[0].location == 2


def test_a_fault_that_goes_away_during_the_search_is_not_located() -> None:
    ring, master = started(plain(*[(0xBF, 1)] * 2))
    ring.inject(Truncate(1, 0, cycles=2))
    (diagnostic,) = master.cycle().diagnostics
    assert diagnostic.location is None and "went away" in diagnostic.detail


@pytest.mark.parametrize("fault", [DeadLine(4), CorruptLoopback(4, 0, None), Truncate(4, 0, None)])
def test_return_line_faults_are_located_at_n_plus_1(fault: Fault) -> None:
    ring, master = started(plain(*[(0xBF, 1)] * 3))
    ring.inject(fault)
    (diagnostic,) = master.cycle().diagnostics
    assert diagnostic.location == 4 and diagnostic.device is None


def test_pin_level_persistent_fault_is_recorded_not_located() -> None:
    chips = [Supi3Pins(decode(BINARY[0].c, BINARY[0].mfp, clk_conf="11")) for _ in range(3)]
    ring = PinRing(chips)
    ring.idle(0.0002)
    master = Master(ring, max_devices=4)
    assert master.start().ok and master.cycle().ok
    ring.set_input(2, "vmon_ok", 0)
    result = master.cycle()
    assert not result.ok and master.diagnostics == list(result.diagnostics)
    assert result.diagnostics[0].location is None
    ring.set_input(2, "vmon_ok", 1)
    for _ in range(RECOVERY_CYCLES):
        if master.cycle().ok:
            break
    assert all(d.location is None for d in master.diagnostics)
    healthy(master)


def test_diagnostics_are_bounded_and_can_be_cleared() -> None:
    ring, master = started(plain(*[(0xBF, 1)] * 2), max_diagnostics=5)
    ring.inject(DeadLine(2))
    for _ in range(12):
        master.cycle()
    assert len(master.diagnostics) == 5 and master.dropped_diagnostics == 7
    master.clear_diagnostics()
    assert master.diagnostics == [] and master.dropped_diagnostics == 0


# -- properties over histories -------------------------------------------------------------------------------------


def _faults(n: int, persistent: bool) -> st.SearchStrategy[Fault]:
    segments = st.integers(1, n + 1)
    cycles = st.none() if persistent else st.integers(1, 4)
    return st.one_of(
        st.builds(BitFlip, segments, st.integers(0, 13 * (2 * n + 6) - 1), cycles),
        st.builds(Truncate, segments, st.integers(0, 2 * n + 1), cycles),
        st.builds(CorruptLoopback, segments, st.integers(0, 0xFFFF).filter(lambda v: v != wire.LOOPBACK_WORD), cycles),
        st.builds(DeadLine, segments, cycles),
    )


def _device(draw: st.DrawFn) -> Device:
    if draw(st.integers(0, 9)) == 0:
        return Supi3(decode("10000"))
    return PlainDevice(draw(st.sampled_from(ID_CODE_VALUES)), draw(st.sampled_from(USABLE_LENGTHS)))


def _spec(device: Device) -> tuple[int, int]:
    """(ID code, length code) of a device of these tests."""
    if isinstance(device, PlainDevice):
        return device.id_code, device.length_code
    assert isinstance(device, Supi3)
    return device.config.id_code, device.config.length_code


@st.composite
def histories(draw: st.DrawFn) -> tuple[Ring, Master, list[str]]:
    """A started master after a random history of faults, ring changes, resets and cycles; the ring is then
    cleared of faults, and the master has recovered and read the ring's configuration."""
    n = draw(st.integers(1, 64), label="devices")
    ring, master = started([_device(draw) for _ in range(n)])
    log: list[str] = []
    for _ in range(draw(st.integers(0, 6))):
        step = draw(st.sampled_from(["fault", "fault", "persistent", "cycles", "data", "clear", "change", "reset"]))
        n = len(ring.devices)
        if step in ("fault", "persistent"):
            ring.inject(draw(_faults(n, step == "persistent")))
        elif step == "change":
            how = draw(st.sampled_from(["remove", "insert", "length"]))
            at = draw(st.integers(0, n - 1))
            if how == "remove" and n > 1:
                del ring.devices[at]
            elif how == "insert" and n < 64:
                ring.devices.insert(at, _device(draw))
            else:
                ring.devices[at] = PlainDevice(_spec(ring.devices[at])[0], draw(st.sampled_from(USABLE_LENGTHS)))
        elif step == "clear":
            ring.clear_faults()
        elif step == "reset":
            master.start()
        elif step == "data" and master.config is not None:
            master.data_cycle()
        for _ in range(draw(st.integers(0 if step != "cycles" else 1, 3))):
            master.cycle()
        log.append(step)
    ring.clear_faults()
    master.set_watchdog(None)  # an ID cycle, so the table matches the ring (a data cycle misses some changes)
    healthy(master)
    return ring, master, log


@settings(max_examples=60, deadline=None)
@given(histories(), st.data())
def test_after_any_history_a_persistent_fault_is_located_at_its_line(
    history: tuple[Ring, Master, list[str]], data: st.DataObject
) -> None:
    ring, master, _ = history
    fault = data.draw(_faults(len(ring.devices), persistent=True), label="fault")
    ring.inject(fault)
    result = master.cycle()
    for diagnostic in result.diagnostics:
        if diagnostic.code is None:
            assert diagnostic.location == fault.segment, diagnostic
    ring.clear_faults()
    healthy(master)


@settings(max_examples=60, deadline=None)
@given(histories(), st.data())
def test_after_any_history_a_transient_fault_is_located_right_or_not_at_all(
    history: tuple[Ring, Master, list[str]], data: st.DataObject
) -> None:
    ring, master, _ = history
    fault = data.draw(_faults(len(ring.devices), persistent=False), label="fault")
    ring.inject(fault)
    result = master.cycle()
    for diagnostic in result.diagnostics:
        if diagnostic.code is None:
            assert diagnostic.location in (fault.segment, None), diagnostic
    ring.clear_faults()
    healthy(master)


@settings(max_examples=40, deadline=None)
@given(histories(), st.data())
def test_after_any_history_a_ring_change_is_a_configuration_error_at_the_first_difference(
    history: tuple[Ring, Master, list[str]], data: st.DataObject
) -> None:
    ring, master, _ = history
    assert master.config is not None
    before = [(e.id_code, e.length_code) for e in master.config]
    n = len(ring.devices)
    how = data.draw(st.sampled_from(["remove", "insert", "length"]) if n > 1 else st.sampled_from(["insert", "length"]))
    at = data.draw(st.integers(0, n - 1))
    if how == "remove":
        del ring.devices[at]
    elif how == "insert":
        ring.devices.insert(at, PlainDevice(data.draw(st.sampled_from(ID_CODE_VALUES)), 0b01001))
    else:
        old = _spec(ring.devices[at])[1]
        length = data.draw(st.sampled_from([c for c in USABLE_LENGTHS if wire.data_bytes(c) != wire.data_bytes(old)]))
        ring.devices[at] = PlainDevice(0x03, length)
    after = [_spec(d) for d in ring.devices]
    first = next((k for k, (a, b) in enumerate(zip(before, after, strict=False), 1) if a != b),
                 min(len(before), len(after)) + 1)  # fmt: skip
    if sum(wire.data_bytes(c) for _, c in after) == sum(wire.data_bytes(c) for _, c in before):
        master.set_watchdog(None)  # a data cycle cannot see this change: the next cycle is an ID cycle
    result = master.cycle()
    assert not result.ok
    (diagnostic,) = result.diagnostics
    assert diagnostic.kind is ErrorKind.CONFIGURATION and diagnostic.location == first
    healthy(master)
    assert master.config is not None
    assert [(e.id_code, e.length_code) for e in master.config] == after

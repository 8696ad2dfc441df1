"""Issue #8, parts 1 and 2: the master recovers from ring changes, locates errors right or not at all, and keeps
its diagnostics bounded. Scenarios from the issue, then properties over histories of faults, changes and resets.
"""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3 import tables
from supi3.config import MfpKind, decode
from supi3.interbus import wire
from supi3.interbus.device import PlainDevice
from supi3.interbus.errors import InterbusError
from supi3.interbus.link import Device
from supi3.interbus.master import Master
from supi3.interbus.ring import BitFlip, CorruptLoopback, DeadLine, ErrorKind, Fault, Ring, Truncate
from supi3.interbus.wire import Cycle
from supi3.model.chip import Supi3
from supi3.model.pinring import PinRing
from supi3.model.pins import Supi3Pins

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

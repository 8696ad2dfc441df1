"""INTERBUS master and ring of PlainDevices: configuration, process data, errors, watchdog, services."""

from __future__ import annotations

import random

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.interbus import wire
from supi3.interbus.device import PlainDevice
from supi3.interbus.errors import InterbusError
from supi3.interbus.master import (
    ALARM_STOP,
    CONTROL_DEVICE_FUNCTION,
    MSG_PERIPHERAL_FAULT,
    MSG_WATCHDOG,
    InterfaceType,
    Master,
    interface_type,
)
from supi3.interbus.ring import BitFlip, CorruptLoopback, DeadLine, ErrorKind, Ring, Truncate
from supi3.interbus.wire import Cycle, Frame
from supi3.tables import BIT_RATES, ID_CODES, LENGTH_CODES

USABLE_LENGTHS = [int(row.code, 2) for row in LENGTH_CODES if row.bits is not None]
ID_CODE_VALUES = sorted({row.code for row in ID_CODES})

device_specs = st.tuples(st.sampled_from(ID_CODE_VALUES), st.sampled_from(USABLE_LENGTHS))
rings = st.lists(device_specs, min_size=1, max_size=10)


def build(specs: list[tuple[int, int]], bit_rate: int = 500_000, record: bool = False) -> tuple[Ring, Master]:
    """A started master on a ring of PlainDevices with seeded, distinct IN data."""
    devices = [PlainDevice(id_code, length_code) for id_code, length_code in specs]
    ring = Ring(devices, bit_rate=bit_rate, record=record)
    master = Master(ring)
    assert master.start().ok
    fill(ring, master, random.Random(len(specs)))
    return ring, master


def fill(ring: Ring, master: Master, rng: random.Random) -> None:
    """Random IN data in every device and OUT data in the master."""
    for k, device in enumerate(ring.devices, 1):
        assert isinstance(device, PlainDevice)
        device.set_inputs(rng.randbytes(device.size))
        master.set_outputs(k, rng.randbytes(device.size))


def plain(ring: Ring) -> list[PlainDevice]:
    devices = [d for d in ring.devices if isinstance(d, PlainDevice)]
    assert len(devices) == len(ring.devices)
    return devices


def assert_exchanged(ring: Ring, master: Master) -> None:
    for k, device in enumerate(plain(ring), 1):
        assert device.outputs == master.outputs(k)
        assert master.inputs(k) == device.inputs


# -- configuration -----------------------------------------------------------------------------------------------


@settings(max_examples=60)
@given(rings)
def test_id_cycle_builds_the_configuration_table(specs: list[tuple[int, int]]) -> None:
    _, master = build(specs)
    assert master.config is not None
    segment, position = 0, 0
    for k, (entry, (id_code, length_code)) in enumerate(zip(master.config, specs, strict=True), 1):
        assert (entry.ring_position, entry.id_code, entry.length_code) == (k, id_code, length_code)
        assert entry.data_bytes == wire.data_bytes(length_code)
        assert entry.interface is interface_type(id_code)
        if entry.interface is InterfaceType.LOCAL_BUS:
            position += 1
        else:
            segment, position = segment + 1, 0
        assert entry.number == f"{segment}.{position}"
        assert entry.id_row is not None and entry.id_row.code == id_code


def test_interface_types_and_numbering() -> None:
    specs = [(0x0C, 0), (0xBF, 0b01001), (0xBE, 1), (0x03, 2), (0x7F, 1)]
    _, master = build(specs)
    assert master.config is not None
    assert [e.number for e in master.config] == ["1.0", "1.1", "1.2", "2.0", "2.1"]
    assert [e.interface for e in master.config] == [
        InterfaceType.BUS_TERMINAL,
        InterfaceType.LOCAL_BUS,
        InterfaceType.LOCAL_BUS,
        InterfaceType.REMOTE_BUS,
        InterfaceType.LOCAL_BUS,
    ]
    assert master.entry("2.1").ring_position == 5
    assert interface_type(0x99) is InterfaceType.UNKNOWN


def test_up_not_ready_devices_are_flagged() -> None:
    _, master = build([(0x78, 0), (0xBF, 1)])
    assert master.config is not None
    assert [e.not_ready for e in master.config] == [True, False]


# -- process data ------------------------------------------------------------------------------------------------


@settings(max_examples=60)
@given(rings, st.sampled_from(BIT_RATES), st.randoms(use_true_random=False))
def test_data_cycles_move_the_right_bytes(specs: list[tuple[int, int]], bit_rate: int, rng: random.Random) -> None:
    ring, master = build(specs, bit_rate)
    for _ in range(3):
        fill(ring, master, rng)
        before = ring.now
        assert master.cycle().ok
        assert_exchanged(ring, master)
        data = sum(d.size for d in plain(ring))
        assert ring.now - before == pytest.approx(wire.cycle_bits(data, len(specs)) / bit_rate)


@settings(max_examples=30)
@given(rings)
def test_bit_level_agrees_with_transaction_level(specs: list[tuple[int, int]]) -> None:
    """Every line's frame, serialised to line levels and received again, is the transaction-level frame."""
    ring, master = build(specs, record=True)
    for cycle in (master.data_cycle, master.id_cycle):
        assert cycle().ok
        assert [t.segment for t in ring.trace] == list(range(1, len(specs) + 2))
        for trace in ring.trace:
            assert trace.error is None and trace.received == trace.sent
            assert trace.sent.crc == wire.crc16(trace.sent.data)
            assert trace.sent.cntr == wire.CNTR_CLEAR
            levels = wire.frame_levels(trace.sent)
            assert wire.frame_from_telegrams(wire.parse_levels(levels)) == trace.sent
    first = ring.trace[0].sent
    assert first == Frame.build(Cycle.ID, first.data)


def test_short_and_zero_length_devices() -> None:
    ring, master = build([(0x0C, 0), (0xBF, 0b01101), (0xBF, 0b01000), (0x0C, 0)])
    master.set_outputs(2, b"\x03")
    assert master.data_cycle().ok
    assert plain(ring)[1].outputs == b"\x03"
    assert master.outputs(1) == b""


# -- errors ------------------------------------------------------------------------------------------------------


def snapshot(ring: Ring, master: Master) -> tuple[list[bytes], list[bytes]]:
    return [d.outputs for d in plain(ring)], [master.inputs(k) for k in range(1, len(ring.devices) + 1)]


def fault_case(data: st.DataObject, specs: list[tuple[int, int]]) -> tuple[Ring, Master, int]:
    ring, master = build(specs)
    assert master.data_cycle().ok
    fill(ring, master, random.Random(7))
    return ring, master, data.draw(st.integers(1, len(specs) + 1), label="segment")


@settings(max_examples=80)
@given(rings, st.data())
def test_a_bit_flip_is_never_latched_and_is_located(specs: list[tuple[int, int]], data: st.DataObject) -> None:
    ring, master, segment = fault_case(data, specs)
    total = wire.LOOPBACK_BYTES + sum(d.size for d in plain(ring))
    bit = data.draw(st.integers(0, wire.frame_bits(total) - 1), label="bit")
    before = snapshot(ring, master)
    ring.inject(BitFlip(segment, bit))
    result = master.data_cycle()
    assert not result.ok
    assert snapshot(ring, master) == before
    (diagnostic,) = result.diagnostics
    assert diagnostic.location == segment
    assert master.data_cycle().ok
    assert_exchanged(ring, master)


@settings(max_examples=40)
@given(rings, st.data())
def test_truncation_is_never_latched_and_is_located(specs: list[tuple[int, int]], data: st.DataObject) -> None:
    ring, master, segment = fault_case(data, specs)
    total = wire.LOOPBACK_BYTES + sum(d.size for d in plain(ring))
    keep = data.draw(st.integers(0, total - 1), label="keep")
    before = snapshot(ring, master)
    ring.inject(Truncate(segment, keep))
    result = master.data_cycle()
    assert not result.ok and snapshot(ring, master) == before
    assert result.diagnostics[0].location == segment


@settings(max_examples=40)
@given(rings, st.data())
def test_wrong_loopback_is_never_latched_and_is_located(specs: list[tuple[int, int]], data: st.DataObject) -> None:
    ring, master, segment = fault_case(data, specs)
    value = data.draw(st.integers(0, 0xFFFF).filter(lambda v: v != wire.LOOPBACK_WORD), label="value")
    before = snapshot(ring, master)
    ring.inject(CorruptLoopback(segment, value, cycles=None))
    result = master.data_cycle()
    assert not result.ok and snapshot(ring, master) == before
    (diagnostic,) = result.diagnostics
    assert diagnostic.kind is ErrorKind.LOOPBACK
    # A CRC-consistent fault is found by the segment search; closing after the last position leaves the return
    # line out, so a fault there is located at N + 1 (it read as N before issue #8, a wrong position).
    assert diagnostic.location == segment


def test_transient_wrong_loopback_is_reported_unlocated() -> None:
    ring, master = build([(0xBF, 1)] * 3)
    ring.inject(CorruptLoopback(2, 0x1234))
    result = master.data_cycle()
    assert not result.ok and result.diagnostics[0].location is None


@settings(max_examples=40)
@given(rings, st.data())
def test_dead_line_is_never_latched_and_is_located(specs: list[tuple[int, int]], data: st.DataObject) -> None:
    ring, master, segment = fault_case(data, specs)
    before = snapshot(ring, master)
    ring.inject(DeadLine(segment))
    result = master.data_cycle()
    assert not result.ok and snapshot(ring, master) == before
    (diagnostic,) = result.diagnostics
    assert diagnostic.kind is ErrorKind.DEAD_LINE
    assert diagnostic.location == segment  # N + 1 (the return line) read as N before issue #8
    if segment <= len(specs):
        assert diagnostic.device == master.entry(diagnostic.location).number
    else:
        assert diagnostic.device is None
    ring.clear_faults()
    assert master.data_cycle().ok


def test_devices_behind_a_dead_line_reset_after_the_idle_timeout() -> None:
    ring, master = build([(0xBF, 1)] * 4)
    assert master.data_cycle().ok
    ring.inject(DeadLine(3))
    start = ring.now
    while ring.now - start < 2 * wire.IDLE_TIMEOUT_S:
        assert not master.data_cycle().ok
    devices = plain(ring)
    assert [d.resets for d in devices] == [1, 1, 2, 2]  # one reset each from start(), one from the silence
    for device in devices[2:]:
        assert device.outputs == bytes(device.size)
        assert device.last_reset_s is not None
        assert device.last_reset_s - start < wire.IDLE_TIMEOUT_S + 0.01


def test_return_line_errors_are_located_without_a_search() -> None:
    ring, master = build([(0xBF, 1)] * 3)
    ring.inject(BitFlip(4, 13 * 3 + wire.POS_DATA))
    result = master.data_cycle()
    assert result.diagnostics[0].location == 4
    assert result.diagnostics[0].kind is ErrorKind.CRC
    assert result.diagnostics[0].device is None


def test_configuration_change_is_found() -> None:
    ring, master = build([(0xBF, 1), (0xBE, 1)])
    ring.devices[1] = PlainDevice(0xBD, 1)
    master.set_watchdog(None)
    result = master.cycle()
    assert result.cycle is Cycle.ID and not result.ok
    assert result.diagnostics[0].kind is ErrorKind.CONFIGURATION and result.diagnostics[0].location == 2
    assert master.config is None
    assert master.cycle().ok and master.config is not None


# -- watchdog, peripheral fault, Alarm Stop ----------------------------------------------------------------------


@pytest.mark.parametrize("timeout", [0.05, 0.2, 1.0])
def test_watchdog_resets_process_data_and_reports_0c6bh(timeout: float) -> None:
    ring, master = build([(0xBF, 1), (0x03, 2)])
    master.set_watchdog(timeout)
    assert master.cycle().cycle is Cycle.ID
    assert all(d.watchdog.timeout_s == timeout for d in plain(ring))
    assert master.cycle().cycle is Cycle.DATA
    ring.idle(timeout * 0.9)
    assert master.cycle().ok
    assert all(d.watchdog_resets == 0 for d in plain(ring))
    ring.idle(timeout * 1.1)
    assert all(d.watchdog_resets == 1 and d.outputs == bytes(d.size) for d in plain(ring))
    assert master.cycle().cycle is Cycle.DATA
    result = master.cycle()
    assert result.cycle is Cycle.ID
    assert [(d.code, d.location) for d in result.diagnostics] == [(MSG_WATCHDOG, 1), (MSG_WATCHDOG, 2)]


def test_watchdog_off_never_expires() -> None:
    ring, master = build([(0xBF, 1)])
    master.set_watchdog(None)
    assert master.cycle().ok
    ring.idle(5.0)
    assert plain(ring)[0].watchdog_resets == 0
    with pytest.raises(InterbusError, match="Table 3-13"):
        master.set_watchdog(0.1)


def test_peripheral_fault_reports_0bb1h_and_quit_pulses_modack() -> None:
    ring, master = build([(0x0C, 0), (0xBF, 1), (0xBE, 1)])
    device = plain(ring)[2]
    device.set_peripheral_fault(True)
    assert master.cycle().cycle is Cycle.DATA
    result = master.cycle()
    assert result.cycle is Cycle.ID
    assert [(d.code, d.location, d.device) for d in result.diagnostics] == [(MSG_PERIPHERAL_FAULT, 3, "1.2")]
    for _ in range(3):
        assert master.cycle().cycle is Cycle.DATA
    device.set_peripheral_fault(False)
    master.quit_peripheral_error("1.2")
    assert master.cycle().cycle is Cycle.ID
    assert device.mod_ack_pulses == 1
    assert device.management() == 0
    assert [d.code for d in master.diagnostics] == [MSG_PERIPHERAL_FAULT]
    assert master.services == [ALARM_STOP, CONTROL_DEVICE_FUNCTION]


def test_alarm_stop_clears_process_data() -> None:
    ring, master = build([(0xBF, 1), (0x03, 2)])
    assert master.data_cycle().ok
    assert any(d.outputs != bytes(d.size) for d in plain(ring))
    master.alarm_stop()
    assert all(d.outputs == bytes(d.size) and d.inputs == bytes(d.size) for d in plain(ring))
    assert master.config is None
    with pytest.raises(InterbusError, match="no configuration"):
        master.data_cycle()
    assert master.cycle().cycle is Cycle.ID and master.config is not None
    assert all(master.outputs(k) == bytes(len(master.outputs(k))) for k in (1, 2))


# -- API rules ---------------------------------------------------------------------------------------------------


def test_api_rules() -> None:
    ring, master = build([(0xBF, 1)])
    with pytest.raises(InterbusError, match="takes 2 bytes"):
        master.set_outputs(1, b"\x00")
    with pytest.raises(InterbusError, match="no such device"):
        master.inputs(2)
    with pytest.raises(InterbusError, match="Table 3-11"):
        PlainDevice(0xBF, 0b01010)
    with pytest.raises(InterbusError, match="line must be"):
        ring.inject(BitFlip(3, 0))
    with pytest.raises(InterbusError, match="Table 1-7"):
        Ring([], bit_rate=1)

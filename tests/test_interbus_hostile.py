"""Issue #8, part 5: every public entry of the INTERBUS layer (master, ring, faults, devices, wire) refuses wrong
types, ranges and orders with a named error of this project, "X must be ..., not ...", never a bare builtin error.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable

import numpy as np
import pytest

from supi3.errors import ArgumentError, Supi3Error
from supi3.interbus import wire
from supi3.interbus.device import Layer2Watchdog, PlainDevice
from supi3.interbus.errors import InterbusError
from supi3.interbus.master import Master
from supi3.interbus.ring import BitFlip, CorruptLoopback, DeadLine, Ring, Truncate
from supi3.interbus.wire import Cycle, Frame


def _started(n: int = 2) -> tuple[Ring, Master]:
    ring = Ring([PlainDevice(0xBF, 1) for _ in range(n)])
    master = Master(ring)
    assert master.start().ok
    return ring, master


def _ring() -> Ring:
    return _started()[0]


def _master() -> Master:
    return _started()[1]


def _device() -> PlainDevice:
    return PlainDevice(0xBF, 1)


# (call, argument named in the message); every call must raise ArgumentError "<name> must be ..., not ...".
HOSTILE: list[tuple[str, Callable[[], object], str]] = [
    # Master
    ("Master(None)", lambda: Master(None), "ring"),  # type: ignore[arg-type]
    ("Master(max_devices=1.5)", lambda: Master(_ring(), max_devices=1.5), "max_devices"),  # type: ignore[arg-type]
    ("Master(max_devices=0)", lambda: Master(_ring(), max_devices=0), "max_devices"),
    ("Master(max_devices=513)", lambda: Master(_ring(), max_devices=513), "max_devices"),
    ("Master(locate=1)", lambda: Master(_ring(), locate=1), "locate"),  # type: ignore[arg-type]
    ("Master(rediscover='no')", lambda: Master(_ring(), rediscover="no"), "rediscover"),  # type: ignore[arg-type]
    ("Master(max_diagnostics=-1)", lambda: Master(_ring(), max_diagnostics=-1), "max_diagnostics"),
    ("set_outputs(1, None)", lambda: _master().set_outputs(1, None), "data"),  # type: ignore[arg-type]
    ("set_outputs(1, 'ab')", lambda: _master().set_outputs(1, "ab"), "data"),  # type: ignore[arg-type]
    ("set_outputs(1.0, b'')", lambda: _master().set_outputs(1.0, b"\0\0"), "position"),  # type: ignore[arg-type]
    ("set_outputs(0, ...)", lambda: _master().set_outputs(0, b"\0\0"), "position"),
    ("inputs(None)", lambda: _master().inputs(None), "position"),  # type: ignore[arg-type]
    ("outputs(-1)", lambda: _master().outputs(-1), "position"),
    ("entry(True)", lambda: _master().entry(True), "position"),
    ("set_watchdog('1')", lambda: _master().set_watchdog("1"), "timeout_s"),  # type: ignore[arg-type]
    ("set_watchdog(nan)", lambda: _master().set_watchdog(math.nan), "timeout_s"),
    ("processor_command(1, 256)", lambda: _master().processor_command(1, 256), "value"),
    ("processor_command(1, None)", lambda: _master().processor_command(1, None), "value"),  # type: ignore[arg-type]
    ("quit_peripheral_error([])", lambda: _master().quit_peripheral_error([]), "position"),  # type: ignore[arg-type]
    ("request_processor_alarm(2.5)", lambda: _master().request_processor_alarm(2.5), "position"),  # type: ignore[arg-type]
    # Ring
    ("Ring([])", lambda: Ring([]), "devices"),
    ("Ring(None)", lambda: Ring(None), "devices"),  # type: ignore[arg-type]
    ("Ring('ab')", lambda: Ring("ab"), "devices"),  # type: ignore[arg-type]
    ("Ring([1])", lambda: Ring([1]), "device at ring position 1"),  # type: ignore[list-item]
    ("Ring(513 devices)", lambda: Ring([_device() for _ in range(513)]), "devices"),
    ("Ring(bit_rate='fast')", lambda: Ring([_device()], bit_rate="fast"), "bit_rate"),  # type: ignore[arg-type]
    ("Ring(record=1)", lambda: Ring([_device()], record=1), "record"),  # type: ignore[arg-type]
    ("inject('x')", lambda: _ring().inject("x"), "fault"),  # type: ignore[arg-type]
    ("inject(None)", lambda: _ring().inject(None), "fault"),  # type: ignore[arg-type]
    ("idle(nan)", lambda: _ring().idle(math.nan), "seconds"),
    ("idle(inf)", lambda: _ring().idle(math.inf), "seconds"),
    ("idle(-1)", lambda: _ring().idle(-1.0), "seconds"),
    ("idle('1')", lambda: _ring().idle("1"), "seconds"),  # type: ignore[arg-type]
    ("transfer('id', ...)", lambda: _ring().transfer("id", b""), "cycle"),  # type: ignore[arg-type]
    ("transfer(close_after=-1)", lambda: _ring().transfer(Cycle.ID, b"", -1), "close_after"),
    ("transfer(close_after=1.0)", lambda: _ring().transfer(Cycle.ID, b"", 1.0), "close_after"),  # type: ignore[arg-type]
    # Faults
    ("BitFlip('1', 0)", lambda: BitFlip("1", 0), "segment"),  # type: ignore[arg-type]
    ("BitFlip(0, 0)", lambda: BitFlip(0, 0), "segment"),
    ("BitFlip(1, -1)", lambda: BitFlip(1, -1), "bit"),
    ("BitFlip(1, 0, 0)", lambda: BitFlip(1, 0, 0), "cycles"),
    ("BitFlip(1, 0, 1.5)", lambda: BitFlip(1, 0, 1.5), "cycles"),  # type: ignore[arg-type]
    ("Truncate(1, None)", lambda: Truncate(1, None), "keep"),  # type: ignore[arg-type]
    ("Truncate(514, 0)", lambda: Truncate(514, 0), "segment"),
    ("CorruptLoopback(1, 0x10000)", lambda: CorruptLoopback(1, 0x10000), "value"),
    ("CorruptLoopback(1, -1)", lambda: CorruptLoopback(1, -1), "value"),
    ("DeadLine(True)", lambda: DeadLine(True), "segment"),
    ("DeadLine(1, -2)", lambda: DeadLine(1, -2), "cycles"),
    # Devices
    ("PlainDevice('BF', 1)", lambda: PlainDevice("BF", 1), "id_code"),  # type: ignore[arg-type]
    ("PlainDevice(256, 1)", lambda: PlainDevice(256, 1), "id_code"),
    ("PlainDevice(1, 32)", lambda: PlainDevice(1, 32), "length_code"),
    ("PlainDevice(1, None)", lambda: PlainDevice(1, None), "length_code"),  # type: ignore[arg-type]
    ("set_inputs(None)", lambda: _device().set_inputs(None), "data"),  # type: ignore[arg-type]
    ("set_peripheral_fault(1)", lambda: _device().set_peripheral_fault(1), "active"),  # type: ignore[arg-type]
    ("load('data', 0)", lambda: _device().load("data", 0.0), "cycle"),  # type: ignore[arg-type]
    ("load(DATA, 'now')", lambda: _device().load(Cycle.DATA, "now"), "now"),  # type: ignore[arg-type]
    ("latch(DATA, None, 0)", lambda: _device().latch(Cycle.DATA, None, 0.0), "received"),  # type: ignore[arg-type]
    ("latch(DATA, bytearray(3), 0)", lambda: _device().latch(Cycle.DATA, bytearray(3), 0.0), "received"),  # type: ignore[arg-type]
    ("latch(ID, b'', nan)", lambda: _device().latch(Cycle.ID, b"\0\0", math.nan), "now"),
    ("discard(DATA, 1, 0)", lambda: _device().discard(Cycle.DATA, 1, 0.0), "local_error"),  # type: ignore[arg-type]
    ("reset(-1)", lambda: _device().reset(-1.0), "now"),
    ("poll(None)", lambda: _device().poll(None), "now"),  # type: ignore[arg-type]
    ("Layer2Watchdog.configure(4, 0)", lambda: Layer2Watchdog().configure(4, 0.0), "code"),
    ("Layer2Watchdog.kick('x')", lambda: Layer2Watchdog().kick("x"), "now"),  # type: ignore[arg-type]
    ("Layer2Watchdog.expired(nan)", lambda: Layer2Watchdog().expired(math.nan), "now"),
    # wire
    ("data_telegram(256, ...)", lambda: wire.data_telegram(256, Cycle.DATA, False), "byte"),
    ("data_telegram(1.0, ...)", lambda: wire.data_telegram(1.0, Cycle.DATA, False), "byte"),  # type: ignore[arg-type]
    ("data_telegram(1, 'id', ...)", lambda: wire.data_telegram(1, "id", False), "cycle"),  # type: ignore[arg-type]
    ("data_telegram(1, ID, 0)", lambda: wire.data_telegram(1, Cycle.ID, 0), "check"),  # type: ignore[arg-type]
    ("status_telegram(None, True)", lambda: wire.status_telegram(None, True), "cycle"),  # type: ignore[arg-type]
    ("decode_telegram(0, 7)", lambda: wire.decode_telegram(0, 7), "length"),
    ("decode_telegram(-1, 13)", lambda: wire.decode_telegram(-1, 13), "word"),
    ("decode_telegram('0', 13)", lambda: wire.decode_telegram("0", 13), "word"),  # type: ignore[arg-type]
    ("word_bytes(0x10000)", lambda: wire.word_bytes(0x10000), "word"),
    ("word_bytes(None)", lambda: wire.word_bytes(None), "word"),  # type: ignore[arg-type]
    ("word_from_bytes(b'a')", lambda: wire.word_from_bytes(b"a"), "data"),
    ("word_from_bytes(12)", lambda: wire.word_from_bytes(12), "data"),  # type: ignore[arg-type]
    ("data_bytes('1')", lambda: wire.data_bytes("1"), "length_code"),  # type: ignore[arg-type]
    ("data_bytes(32)", lambda: wire.data_bytes(32), "length_code"),
    ("id_register(1, 1, 'x')", lambda: wire.id_register(1, 1, "x"), "management"),  # type: ignore[arg-type]
    ("command_word(4)", lambda: wire.command_word(4), "watchdog_code"),
    ("command_word(None, 1)", lambda: wire.command_word(None, 1), "quit_peripheral_error"),  # type: ignore[arg-type]
    ("command_word(None, False, 300)", lambda: wire.command_word(None, False, 300), "processor_command"),
    ("command_word(alarm_request=None)", lambda: wire.command_word(alarm_request=None), "alarm_request"),  # type: ignore[arg-type]
    ("decode_command_word(-1)", lambda: wire.decode_command_word(-1), "word"),
    ("crc_update_bit(0, 2)", lambda: wire.crc_update_bit(0, 2), "bit"),
    ("crc_update_bit(0x10000, 0)", lambda: wire.crc_update_bit(0x10000, 0), "crc"),
    ("crc16('abc')", lambda: wire.crc16("abc"), "data"),  # type: ignore[arg-type]
    ("crc16(b'', -1)", lambda: wire.crc16(b"", -1), "init"),
    ("cntr_word(1, 0)", lambda: wire.cntr_word(1, 0), "attention"),  # type: ignore[arg-type]
    ("decode_cntr(1.5)", lambda: wire.decode_cntr(1.5), "word"),  # type: ignore[arg-type]
    ("forward_cntr(0, None, False)", lambda: wire.forward_cntr(0, None, False), "local_error"),  # type: ignore[arg-type]
    ("forward_cntr(-5, False, False)", lambda: wire.forward_cntr(-5, False, False), "word"),
    ("Frame('id', b'', 0, 0)", lambda: Frame("id", b"", 0, 0), "cycle"),  # type: ignore[arg-type]
    ("Frame(ID, 'ab', 0, 0)", lambda: Frame(Cycle.ID, "ab", 0, 0), "data"),  # type: ignore[arg-type]
    ("Frame(ID, b'', -1, 0)", lambda: Frame(Cycle.ID, b"", -1, 0), "crc"),
    ("Frame.build(ID, None)", lambda: Frame.build(Cycle.ID, None), "data"),  # type: ignore[arg-type]
    ("Frame.build(ID, b'', 1 << 16)", lambda: Frame.build(Cycle.ID, b"", 1 << 16), "cntr"),
    ("frame_bits(-1)", lambda: wire.frame_bits(-1), "data_len"),
    ("locate_bit(None, 0)", lambda: wire.locate_bit(None, 0), "frame"),  # type: ignore[arg-type]
    ("locate_bit(frame, -1)", lambda: wire.locate_bit(Frame.build(Cycle.ID, b""), -1), "bit"),
    ("frame_from_telegrams(None)", lambda: wire.frame_from_telegrams(None), "telegrams"),  # type: ignore[arg-type]
    ("frame_from_telegrams([1])", lambda: wire.frame_from_telegrams([1]), "telegram"),  # type: ignore[list-item]
    ("ring_delay_status_telegrams(513)", lambda: wire.ring_delay_status_telegrams(513), "devices"),
    ("cycle_bits(-1, 1)", lambda: wire.cycle_bits(-1, 1), "data_bytes"),
    ("cycle_bits(0, 1.5)", lambda: wire.cycle_bits(0, 1.5), "devices"),  # type: ignore[arg-type]
    ("reset_bits(-1)", lambda: wire.reset_bits(-1), "devices"),
    ("cycle_bits(0, 2, 3)", lambda: wire.cycle_bits(0, 2, 3), "return_repeaters"),  # BK-55: at most one a device
    ("reset_bits(2, -1)", lambda: wire.reset_bits(2, -1), "return_repeaters"),
    ("check_bit_rate('500k')", lambda: wire.check_bit_rate("500k"), "bit_rate"),  # type: ignore[arg-type]
    ("clocks_per_bit(None)", lambda: wire.clocks_per_bit(None), "bit_rate"),  # type: ignore[arg-type]
    ("telegram_levels([1 << 13], 13)", lambda: wire.telegram_levels([1 << 13], 13), "words"),
    ("telegram_levels([-1], 13)", lambda: wire.telegram_levels([-1], 13), "words"),
    ("telegram_levels('ab', 13)", lambda: wire.telegram_levels("ab", 13), "words"),  # type: ignore[arg-type]
    ("telegram_levels([1], 0)", lambda: wire.telegram_levels([1], 0), "length"),
    ("frame_levels(b'')", lambda: wire.frame_levels(b""), "frame"),  # type: ignore[arg-type]
    ("status_levels(ID, False, -1)", lambda: wire.status_levels(Cycle.ID, False, -1), "count"),
    ("status_levels('id', False, 1)", lambda: wire.status_levels("id", False, 1), "cycle"),  # type: ignore[arg-type]
    ("cycle_levels(None, 1, True)", lambda: wire.cycle_levels(None, 1, True), "frame"),  # type: ignore[arg-type]
    ("cycle_levels(frame, 1, 'yes')", lambda: wire.cycle_levels(Frame.build(Cycle.ID, b""), 1, "yes"), "latch"),  # type: ignore[arg-type]
    ("reset_levels(None)", lambda: wire.reset_levels(None), "devices"),  # type: ignore[arg-type]
    ("parse_levels([0, 2])", lambda: wire.parse_levels([0, 2]), "levels"),
    ("parse_levels(None)", lambda: wire.parse_levels(None), "levels"),  # type: ignore[arg-type]
    ("parse_levels(['a'])", lambda: wire.parse_levels(["a"]), "levels"),  # type: ignore[list-item]
    ("levels_to_samples([1], 3)", lambda: wire.levels_to_samples([1], 3), "bit_rate"),
    ("levels_to_samples([[1]], 500000)", lambda: wire.levels_to_samples([[1]], 500_000), "levels"),  # type: ignore[list-item]
    ("samples_to_levels([1], 500000, 64)", lambda: wire.samples_to_levels([1], 500_000, 64), "phase"),
    ("samples_to_levels(np.array([0.5]), ...)", lambda: wire.samples_to_levels(np.array([0.5]), 500_000), "samples"),
    ("frames_from_levels(3)", lambda: wire.frames_from_levels(3), "levels"),  # type: ignore[arg-type]
]


@pytest.mark.parametrize(("call", "name"), [(c, n) for _, c, n in HOSTILE], ids=[label for label, _, _ in HOSTILE])
def test_every_public_entry_refuses_wrong_arguments_by_name(call: Callable[[], object], name: str) -> None:
    with pytest.raises(Supi3Error) as caught:
        call()
    assert isinstance(caught.value, ArgumentError), repr(caught.value)
    assert caught.value.name == name
    assert re.match(rf"{re.escape(name)} must be .+, not .+", str(caught.value)), str(caught.value)


def test_the_ring_size_names_the_manuals_limit() -> None:
    with pytest.raises(InterbusError, match="512"):
        Ring([PlainDevice(0xBF, 0) for _ in range(513)])
    ring, master = _started(1)
    ring.devices.extend(PlainDevice(0xBF, 0) for _ in range(512))
    with pytest.raises(InterbusError, match="at most 512 devices"):
        master.start()


def test_orders_refused_by_name() -> None:
    ring = Ring([PlainDevice(0xBF, 1)])
    master = Master(ring)
    for call in (lambda: master.data_cycle(), lambda: master.set_outputs(1, b"\0"), lambda: master.inputs(1)):
        with pytest.raises(InterbusError, match="no configuration"):
            call()
    with pytest.raises(InterbusError, match="line must be"):
        ring.inject(BitFlip(3, 0))

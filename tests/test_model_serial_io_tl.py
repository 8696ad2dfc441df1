"""Serial I/O (SPI master mode, manual 3.3) at transaction level: Supi3.attach_serial (checked, refused outside the SPI
master modes), the whole sequence on the device at each latch (SM-11), the clear sequence on resets (SM-9), and the
transaction level and the pin level agreeing on shared scenarios through a real master."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3 import serial_io as sio
from supi3 import tables
from supi3.config import DataDirection, MfpKind, decode
from supi3.interbus import wire
from supi3.interbus.master import Master
from supi3.interbus.ring import Ring
from supi3.interbus.wire import Cycle
from supi3.model.chip import ChipArgumentError, ChipError, SerialModeError, Supi3
from supi3.model.pinring import PinRing
from supi3.model.pins import Supi3Pins
from supi3.peripherals.serial import SerialBus, ShiftIn, ShiftOut, SpiAdc, SpiDac
from support import WATCHDOG_LATEST, EchoDevice

SPI_ROWS = [r for r in tables.MODE_ROWS if decode(r.c, r.mfp).mfp_mode.kind is MfpKind.SPI_MASTER]
OTHER_ROWS = [r for r in tables.MODE_ROWS if decode(r.c, r.mfp).mfp_mode.kind is not MfpKind.SPI_MASTER]
FAST = tables.clk_conf_for(2_000_000)


def _chip(row: tables.ModeRow) -> tuple[Supi3, EchoDevice]:
    chip = Supi3(decode(row.c, row.mfp, clk_conf=FAST))
    device = EchoDevice(chip.config.mfp_mode.width, 0x1234)
    chip.attach_serial(device)
    return chip, device


# ------------------------------------------------------------------------------------------------------------
# attach_serial: refused outside the SPI master modes, checked argument
# ------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("row", OTHER_ROWS, ids=[f"{r.c}-{r.mfp or 'x'}" for r in OTHER_ROWS])
def test_attach_is_refused_outside_spi_master_modes(row: tables.ModeRow) -> None:
    chip = Supi3(decode(row.c, row.mfp))
    with pytest.raises(SerialModeError, match=r"attach_serial needs an SPI master mode .*, not '"):
        chip.attach_serial(EchoDevice(16))
    with pytest.raises(SerialModeError):
        chip.attach_serial(None)
    assert chip.spi_sequences is None and chip.serial_device is None


class _NoConvert:
    drives_ser_in = True

    def frame(self, ser_out: int, bits: int) -> int:  # noqa: ARG002 - a stub
        return 0

    def clock(self, levels: sio.Levels) -> int:  # noqa: ARG002 - a stub
        return 0


@pytest.mark.parametrize("device", [1, "device", object(), EchoDevice, _NoConvert(), [EchoDevice(16)]])
def test_attach_takes_a_serial_device_or_none(device: object) -> None:
    chip = Supi3(decode(SPI_ROWS[0].c, SPI_ROWS[0].mfp))
    with pytest.raises(ChipArgumentError, match=r"device must be a SerialDevice \(supi3.serial_io\) or None, "):
        chip.attach_serial(device)  # type: ignore[arg-type]
    assert chip.serial_device is None


def test_set_inputs_is_refused_while_a_device_provides_them() -> None:
    chip, _ = _chip(SPI_ROWS[0])
    with pytest.raises(SerialModeError, match="set_inputs is refused while a serial device is attached"):
        chip.set_inputs(0x5555)
    assert isinstance(SerialModeError("x"), ChipError)
    chip.attach_serial(None)  # detached: the IN word is the user's again
    chip.set_inputs(0x5555)
    assert chip.load_at(Cycle.DATA, 10) == b"\x55\x55"


def test_device_answer_wider_than_the_frame_is_a_named_error() -> None:
    chip, device = _chip(next(r for r in SPI_ROWS if decode(r.c, r.mfp).mfp_mode.width == 16))
    device.value = 1 << 16
    with pytest.raises(ChipArgumentError, match=r"SerialDevice.frame\(\) must be"):
        chip.latch_at(Cycle.DATA, b"\x00\x00", 100)


# ------------------------------------------------------------------------------------------------------------
# SM-11: the sequence at the latch; SM-9: resets
# ------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("row", SPI_ROWS, ids=[f"{r.c}-{r.mfp}" for r in SPI_ROWS])
def test_latch_runs_the_sequence_on_the_device(row: tables.ModeRow) -> None:
    chip, device = _chip(row)
    direction, width = chip.config.mfp_mode.direction, chip.config.mfp_mode.width
    out = bytes(range(0xA1, 0xA1 + chip.data_bytes()))
    assert chip.load_at(Cycle.DATA, 10) == bytes(chip.data_bytes())  # nothing read yet (SM-6)
    chip.latch(Cycle.DATA, out, 1e-4)  # through the ring's kernel: the device takes the slow path
    chip.discard_at(Cycle.DATA, False, 6000)  # no latch: no sequence
    chip.latch_at(Cycle.ID, b"\x00\x00", 7000)  # ID cycles start none either (SM-2)
    read = [("frame", 0, width)]
    write = [("frame", int.from_bytes(out, "big"), width), ("convert",)]
    expected = {DataDirection.IN: read, DataDirection.OUT: write, DataDirection.IN_OUT: read + write}
    assert device.record == expected[direction]
    words = 0x1234 if direction is not DataDirection.OUT else 0
    assert chip.in_word == words
    assert chip.load_at(Cycle.DATA, 8000) == words.to_bytes(chip.data_bytes(), "big")


@pytest.mark.parametrize("row", SPI_ROWS, ids=[f"{r.c}-{r.mfp}" for r in SPI_ROWS])
def test_resets_write_zeros_to_the_outputs(row: tables.ModeRow) -> None:
    chip, device = _chip(row)
    width = chip.config.mfp_mode.width
    chip.latch_at(Cycle.DATA, b"\xff" * chip.data_bytes(), 100)
    device.record.clear()
    chip.reset_at(200)
    cleared = [] if chip.config.mfp_mode.direction is DataDirection.IN else [("frame", 0, width), ("convert",)]
    assert device.record == cleared and chip.in_word == 0
    # The layer-2 watchdog's expiry resets process data too (3.4.14).
    chip.latch_at(Cycle.ID, wire.word_bytes(wire.command_word(0)), 300)  # watchdog code 0: 50 ms
    chip.latch_at(Cycle.DATA, b"\x0f" * chip.data_bytes(), 400)
    device.record.clear()
    chip.poll((400 + WATCHDOG_LATEST + 1) / tables.CLOCK_HZ)  # M24: on the time base's ticks
    assert chip.events["WATCHDOG"] == 1
    assert device.record == cleared and chip.in_word == 0


# ------------------------------------------------------------------------------------------------------------
# Transaction level == pin level through a real master
# ------------------------------------------------------------------------------------------------------------


@settings(max_examples=15, deadline=None)
@given(
    rows=st.lists(st.sampled_from(SPI_ROWS), min_size=1, max_size=2),
    cycles=st.lists(st.tuples(st.binary(min_size=4, max_size=4), st.integers(0, 2**32 - 1)), min_size=1,
                    max_size=3),
)
def test_transaction_and_pin_level_agree(rows: list[tables.ModeRow], cycles: list[tuple[bytes, int]]) -> None:
    configs = [decode(r.c, r.mfp, clk_conf=FAST) for r in rows]
    tl_chips = [Supi3(c) for c in configs]
    pin_chips = [Supi3Pins(c) for c in configs]
    devices = [[EchoDevice(c.mfp_mode.width) for c in configs] for _ in "ab"]
    for chip, device in zip([*tl_chips, *(p.chip for p in pin_chips)], [*devices[0], *devices[1]], strict=True):
        chip.attach_serial(device)
    tl_ring, pin_ring = Ring(list(tl_chips), bit_rate=2_000_000), PinRing(pin_chips)
    pin_ring.idle(0.0002)  # power-up reset stretch
    masters = [Master(tl_ring, locate=False, max_devices=4), Master(pin_ring, locate=False, max_devices=4)]
    for master in masters:
        assert master.start().ok
    for out, value in cycles:
        for k, config in enumerate(configs, start=1):
            for fidelity in devices:
                fidelity[k - 1].value = value & ((1 << config.mfp_mode.width) - 1)
            for master in masters:
                master.set_outputs(k, out[: config.data_bytes])
        assert masters[0].data_cycle().ok and masters[1].data_cycle().ok
        # The pin level reads the inputs after the latch: leave the sequence time before the next data cycle (the TL
        # runs it at the latch).
        pin_ring.idle(0.0001)
        for k in range(1, len(rows) + 1):
            assert masters[0].inputs(k) == masters[1].inputs(k)
    assert masters[0].data_cycle().ok and masters[1].data_cycle().ok
    pin_ring.idle(0.0001)
    for k in range(1, len(rows) + 1):
        assert masters[0].inputs(k) == masters[1].inputs(k)
    assert [d.record for d in devices[0]] == [d.record for d in devices[1]]
    assert [c.in_word for c in tl_chips] == [p.chip.in_word for p in pin_chips]


@pytest.mark.parametrize("row", [r for r in SPI_ROWS if decode(r.c, r.mfp).mfp_mode.direction is DataDirection.IN_OUT],
                         ids=lambda r: f"{r.c}-{r.mfp}")
def test_analog_and_digital_io_end_to_end_at_both_fidelities(row: tables.ModeRow) -> None:
    # A user's device: an ADC and a DAC (or a 74HCT165 and a 74HCT594 chain) behind an IN/OUT chip; values move from
    # the master to the DAC output and from the ADC input to the master, at transaction and at pin level.
    config = decode(row.c, row.mfp, clk_conf=FAST)
    width = config.mfp_mode.width
    for analog in (True, False):
        tl, pins = Supi3(config), Supi3Pins(config)
        ends: list[tuple[SpiAdc | ShiftIn, SpiDac | ShiftOut]] = [
            (SpiAdc(width), SpiDac(width)) if analog else (ShiftIn(width // 8), ShiftOut(width // 8)) for _ in "ab"
        ]
        tl.attach_serial(SerialBus(*ends[0]))
        pins.chip.attach_serial(SerialBus(*ends[1]))
        pin_ring = PinRing([pins])
        pin_ring.idle(0.0002)
        masters = [Master(Ring([tl], bit_rate=2_000_000), locate=False), Master(pin_ring, locate=False)]
        for master in masters:
            assert master.start().ok
        for value in (0x1234, (1 << width) - 1, 0x8001):
            for source, _ in ends:
                if isinstance(source, SpiAdc):
                    source.set_input(value)
                else:
                    source.set_inputs(value)
            for master in masters:
                master.set_outputs(1, (value ^ 0xFF).to_bytes(config.data_bytes, "big"))
                assert master.data_cycle().ok
            pin_ring.idle(0.0001)
            for master in masters:
                assert master.data_cycle().ok  # carries the word read after the cycle before
                assert master.inputs(1) == value.to_bytes(config.data_bytes, "big")
            pin_ring.idle(0.0001)
            for _, sink in ends:
                assert (sink.output if isinstance(sink, SpiDac) else sink.outputs) == value ^ 0xFF

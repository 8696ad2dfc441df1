"""The SUPI 3 chip at transaction level on the INTERBUS ring: every binary I/O mode, the µP modes' software
configuration, /StatErr and 0BB1h, the layer-2 watchdog and 0C6Bh, Alarm Stop, and corrupted cycles."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3 import tables
from supi3.config import DeviceConfig, MfpKind, decode
from supi3.interbus import wire
from supi3.interbus.errors import InterbusError
from supi3.interbus.master import Master
from supi3.interbus.ring import BitFlip, CorruptLoopback, Ring, Truncate
from supi3.model.chip import STATERR_FILTER_CLOCKS, WATCHDOG_CLOCKS, Supi3
from supi3.pinout import TIME_BASE_BITS, time_base_ticks

BINARY_ROWS = [r for r in tables.MODE_ROWS if decode(r.c, r.mfp).mfp_mode.kind is MfpKind.BINARY_IO]


def _expected_in(config: DeviceConfig, mfp: int) -> bytes:
    """IN data from the MFP levels by Tables 3-1/3-2: In<k> on pin p is bit k (3.2)."""
    word = sum(((mfp >> p.pin) & 1) << int(p.signal[2:]) for p in config.mfp_pins if p.signal.startswith("In"))
    return word.to_bytes(config.data_bytes, "big")


def _expected_mfp(config: DeviceConfig, out: bytes) -> int:
    word = int.from_bytes(out, "big")
    return sum(((word >> int(p.signal[3:])) & 1) << p.pin for p in config.mfp_pins if p.signal.startswith("Out"))


def _ring(*chips: Supi3) -> tuple[Ring, Master]:
    ring = Ring(list(chips))
    master = Master(ring)
    assert master.start().ok
    return ring, master


def test_binary_io_modes_are_44_rows() -> None:
    assert len(BINARY_ROWS) == 44


@pytest.mark.parametrize("row", BINARY_ROWS, ids=lambda r: r.function)
def test_every_binary_io_mode_exchanges_process_data(row: tables.ModeRow) -> None:
    config = decode(row.c, row.mfp)
    chip = Supi3(config)
    _, master = _ring(chip)
    entry = master.entry(1)
    assert (entry.id_code, entry.length_code) == (config.id_code, config.length_code)
    width = config.mfp_mode.width
    for mfp, out in ((0xA5C3, 0x5A3C), (0x3C5A, 0xC3A5), (0xFFFF, 0x0000)):
        out_bytes = (out & ((1 << 8 * config.data_bytes) - 1)).to_bytes(config.data_bytes, "big")
        chip.set_mfp_inputs(mfp)
        master.set_outputs(1, out_bytes)
        assert master.data_cycle().ok
        assert master.inputs(1) == _expected_in(config, mfp)
        # Only the OUT bits of Tables 3-1/3-2 reach pins; their count is the mode's OUT width.
        assert chip.mfp_outputs == _expected_mfp(config, out_bytes)
        assert bin(chip.mfp_outputs | ~config.mfp_output_mask & 0xFFFF).count("1") <= 16
    expected_outputs = width if "OUT" in config.mfp_mode.name else 0
    assert bin(config.mfp_output_mask).count("1") == expected_outputs


def test_up_mode_reports_not_ready_until_software_writes_set() -> None:
    chip = Supi3(decode("10011", "1110"))  # RB, Init-µP
    assert chip.registers is not None
    _, master = _ring(chip)
    assert master.entry(1).id_code == 0x38 and master.entry(1).length_code == 0
    # 3.4.5: SET = 82h (I/O device, 1 byte), ID = 01h (digital output device).
    chip.registers.cpu_write(13, 0x82)
    chip.registers.cpu_write(12, 0x01)
    master.start()
    assert (master.entry(1).id_code, master.entry(1).length_code) == (0x01, 0b01001)
    chip.registers.cpu_write(14, 0x10)  # enable the valid-data-cycle interrupt (3.4.14)
    chip.registers.cpu_write(0, 0x77)
    master.set_outputs(1, b"\x99")
    assert master.data_cycle().ok
    assert master.inputs(1) == b"\x77"
    assert chip.registers.irq_n == 0
    assert chip.registers.cpu_read(0) == 0x99
    assert chip.registers.cpu_read(14) & 0x10
    assert chip.registers.irq_n == 1


def test_stat_err_filter_then_0bb1_then_quit() -> None:
    chip = Supi3(decode("10000"))
    ring, master = _ring(chip)
    chip.set_stat_err(True, ring.now)
    ring.idle(0.150)
    master.cycle()
    assert not chip.pf  # 150 ms < 200 ms filter (3.6.2)
    ring.idle(0.060)
    master.cycle()
    assert chip.pf
    master.cycle()  # ATTN -> ID cycle -> message
    assert any(d.code == 0x0BB1 for d in master.diagnostics)
    chip.set_stat_err(False, ring.now)
    master.quit_peripheral_error(1)
    master.cycle()
    assert chip.events["MODACK"] == 1 and not chip.pf


def test_filter_constant_is_200_ms_of_32_mhz_clocks() -> None:
    assert STATERR_FILTER_CLOCKS == 6_400_000


TICK = 1 << TIME_BASE_BITS


@settings(max_examples=40, derandomize=True)
@given(start=st.integers(0, 4 * TICK), end=st.integers(0, 3 * TICK))
def test_the_filter_latches_on_the_time_base(start: int, end: int) -> None:
    """M24, 3.6.2: /StatErr low from any clock latches the fault at a tick's edge (a clock whose count's low 15 bits
    are all ones), never before 200 ms low and at most two ticks later (inside the ±31.5 %); released a clock before,
    nothing latches."""
    chip = Supi3()
    chip.set_stat_err(True, start / tables.CLOCK_HZ)
    latch = chip.due  # the first clock that sees the fault
    assert (latch - 1) % TICK == TICK - 1
    assert STATERR_FILTER_CLOCKS <= latch - start <= time_base_ticks(STATERR_FILTER_CLOCKS) * TICK
    chip.poll((latch - 1) / tables.CLOCK_HZ)
    assert not chip.pf
    released = Supi3()
    released.set_stat_err(True, start / tables.CLOCK_HZ)
    released.set_stat_err(False, (latch - 1) / tables.CLOCK_HZ)
    released.poll((latch + end) / tables.CLOCK_HZ)
    assert not released.pf
    chip.poll((latch + end) / tables.CLOCK_HZ)
    assert chip.pf


@settings(max_examples=30, derandomize=True)
@given(code=st.sampled_from([0, 1, 2]), arm=st.integers(1000, 3 * TICK))
def test_the_watchdog_fires_on_the_time_base(code: int, arm: int) -> None:
    """M24, Table 3-13: the watchdog armed by a data cycle's latch at any clock fires at a tick, never before the
    preset time and at most two ticks after it; a data cycle before then restarts it."""
    timeout = WATCHDOG_CLOCKS[code]
    assert timeout is not None
    chip = Supi3(decode("10000"))
    chip.latch_at(wire.Cycle.ID, wire.word_bytes(wire.command_word(code)), 100)
    chip.latch_at(wire.Cycle.DATA, b"\x0f" * chip.data_bytes(), arm)
    deadline = chip.due
    assert deadline % TICK == TICK - 1
    assert timeout <= deadline - arm <= time_base_ticks(timeout) * TICK
    chip.poll((deadline - 1) / tables.CLOCK_HZ)
    assert chip.events["WATCHDOG"] == 0
    chip.latch_at(wire.Cycle.DATA, b"\x0f" * chip.data_bytes(), deadline - 1)  # a valid cycle just in time
    assert chip.due > deadline and chip.events["WATCHDOG"] == 0
    chip.poll(chip.due / tables.CLOCK_HZ)
    assert chip.events["WATCHDOG"] == 1


@pytest.mark.parametrize("timeout", [0.05, 0.2, 1.0])
def test_watchdog_resets_process_data_and_reports_0c6b(timeout: float) -> None:
    chip = Supi3(decode("10000"))
    ring, master = _ring(chip)
    master.set_watchdog(timeout)
    master.set_outputs(1, b"\x81")
    for _ in range(3):
        master.cycle()
    assert chip.mfp_outputs == 0x8100
    ring.idle(timeout * 0.9)
    master.data_cycle()  # a valid cycle restarts the watchdog
    ring.idle(timeout * 0.9)
    assert chip.mfp_outputs == 0x8100 and not chip.wd
    ring.idle(timeout * 0.2)
    ring.idle(0)
    assert chip.wd and chip.mfp_outputs == 0 and chip.events["WATCHDOG"] == 1
    master.cycle()
    master.cycle()
    assert any(d.code == 0x0C6B for d in master.diagnostics)


def test_alarm_stop_clears_process_data() -> None:
    chip = Supi3(decode("10000"))
    _, master = _ring(chip)
    master.set_outputs(1, b"\xff")
    master.data_cycle()
    assert chip.mfp_outputs == 0xFF00
    resets = chip.events["IB_RESET"]
    master.alarm_stop()
    assert chip.mfp_outputs == 0 and chip.events["IB_RESET"] == resets + 1


@settings(max_examples=60)
@given(
    modes=st.lists(st.sampled_from(BINARY_ROWS), min_size=1, max_size=4),
    fault=st.integers(0, 2),
    where=st.integers(0, 10_000),
    data=st.binary(min_size=8, max_size=8),
)
def test_corrupted_cycles_never_change_outputs(modes: list[tables.ModeRow], fault: int, where: int,
                                               data: bytes) -> None:
    chips = [Supi3(decode(r.c, r.mfp)) for r in modes]
    ring, master = _ring(*chips)
    for k, chip in enumerate(chips, start=1):
        master.set_outputs(k, data[: chip.data_bytes()])
    assert master.data_cycle().ok
    before = [chip.mfp_outputs for chip in chips]
    invalid = [chip.events["INVALID"] for chip in chips]
    segment = where % (len(chips) + 1) + 1
    frame_bits = wire.frame_bits(wire.LOOPBACK_BYTES + sum(c.data_bytes() for c in chips))
    injected = (BitFlip(segment, where % frame_bits), Truncate(segment, where % 3),
                CorruptLoopback(segment, 0x1234))[fault]
    ring.inject(injected)
    for k, chip in enumerate(chips, start=1):
        master.set_outputs(k, bytes(b ^ 0xFF for b in data[: chip.data_bytes()]))
    result = master.data_cycle()
    if not result.ok:
        # Nothing is lost: a failed cycle leaves every output as the last valid cycle set it (Table 3-13).
        assert [chip.mfp_outputs for chip in chips] == before
        assert all(chip.events["INVALID"] > n for chip, n in zip(chips, invalid, strict=True))


def test_management_channel_processor_command_and_alarm() -> None:
    chip = Supi3(decode("10011", "1110"))  # RB, Init-µP
    assert chip.registers is not None
    chip.registers.cpu_write(13, 0x82)
    chip.registers.cpu_write(12, 0x01)
    _, master = _ring(chip)
    chip.registers.cpu_write(14, 0x40)  # enable the processor command interrupt (D6)
    master.processor_command(1, 0xC3)
    assert master.cycle().cycle is wire.Cycle.ID  # pending management traffic makes the next cycle an ID cycle
    assert chip.registers.cpu_read(7) == 0xC3  # 3.4.9: the master's message in the processor command register
    assert chip.registers.irq_n == 0 and chip.registers.cpu_read(14) & 0x40
    chip.registers.cpu_write(7, 0x5A)  # the processor alarm for the master
    master.request_processor_alarm("1.0")
    assert master.cycle().ok and 1 not in master.processor_alarms
    assert master.cycle().ok and master.processor_alarms[1] == 0x5A
    # The alarm took the ID code's place once; the configuration is still the same afterwards.
    assert master.cycle().cycle is wire.Cycle.DATA and master.entry(1).id_code == 0x01
    assert master.id_cycle().ok


def test_command_word_round_trip() -> None:
    for pcmd in (None, 0x00, 0xA5):
        for alarm in (False, True):
            word = wire.command_word(1, True, pcmd, alarm)
            assert wire.decode_command_word(word) == wire.CommandWord(1, True, pcmd, alarm)
    with pytest.raises(InterbusError, match="one byte"):
        wire.command_word(processor_command=0x100)

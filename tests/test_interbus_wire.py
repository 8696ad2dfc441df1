"""INTERBUS wire format: telegrams, words, CRC, CNTR, frames, line levels, timing (docs/interbus.md)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.interbus import wire
from supi3.interbus.errors import InterbusError, TelegramError
from supi3.interbus.wire import Cycle, Frame, LineReset, Telegram
from supi3.tables import BIT_RATES, CLOCK_HZ, LENGTH_CODES, WATCHDOG_TIMEOUTS_S, LengthCode

cycles = st.sampled_from(list(Cycle))


@settings(max_examples=200)
@given(st.integers(0, 255), cycles, st.booleans())
def test_data_telegram_round_trip(byte: int, cycle: Cycle, check: bool) -> None:
    word = wire.data_telegram(byte, cycle, check)
    assert word >> wire.DATA_TELEGRAM_BITS == 0
    assert wire.decode_telegram(word, wire.DATA_TELEGRAM_BITS) == Telegram(cycle, check, byte)


@pytest.mark.parametrize("cycle", list(Cycle))
@pytest.mark.parametrize("check", [False, True])
def test_status_telegram_round_trip(cycle: Cycle, check: bool) -> None:
    word = wire.status_telegram(cycle, check)
    assert wire.decode_telegram(word, wire.STATUS_TELEGRAM_BITS) == Telegram(cycle, check, None)


def test_every_single_bit_error_in_a_telegram_is_seen() -> None:
    """Exhaustive: a flipped start, type or stop bit raises; any other flip changes exactly one field."""
    for cycle in Cycle:
        for check in (False, True):
            for byte in range(256):
                sent = Telegram(cycle, check, byte)
                word = wire.data_telegram(byte, cycle, check)
                for bit in range(wire.DATA_TELEGRAM_BITS):
                    flipped = word ^ (1 << bit)
                    if bit in (wire.POS_START, wire.POS_TYPE, wire.DATA_TELEGRAM_BITS - 1):
                        with pytest.raises(TelegramError) as caught:
                            wire.decode_telegram(flipped, wire.DATA_TELEGRAM_BITS)
                        assert caught.value.bit == bit
                        continue
                    got = wire.decode_telegram(flipped, wire.DATA_TELEGRAM_BITS)
                    assert sum(a != b for a, b in zip(got, sent, strict=True)) == 1


def test_data_telegram_rejects_non_bytes() -> None:
    with pytest.raises(InterbusError, match=r"0\.\.255"):
        wire.data_telegram(256, Cycle.DATA, False)


@given(st.integers(0, 0xFFFF))
def test_word_round_trip(word: int) -> None:
    assert wire.word_from_bytes(wire.word_bytes(word)) == word


def test_words_go_low_byte_first() -> None:
    assert wire.word_bytes(0x1234) == b"\x34\x12"


@pytest.mark.parametrize("row", LENGTH_CODES, ids=lambda r: r.code)
def test_data_bytes_of_every_length_code(row: LengthCode) -> None:
    code, bits = int(row.code, 2), row.bits
    if bits is None:
        with pytest.raises(InterbusError, match="Table 3-11"):
            wire.data_bytes(code)
    else:
        assert wire.data_bytes(code) == math.ceil(bits / 8)


def test_loopback_word_cannot_be_an_id_register() -> None:
    """Its length-code field is reserved (Table 3-11), so no device shifts it out in an ID cycle."""
    with pytest.raises(InterbusError):
        wire.data_bytes((wire.LOOPBACK_WORD >> 8) & 0x1F)


def test_command_words_round_trip() -> None:
    for code in [None, *range(len(WATCHDOG_TIMEOUTS_S))]:
        for quit_error in (False, True):
            command = wire.decode_command_word(wire.command_word(code, quit_error))
            assert command == wire.CommandWord(code, quit_error)
    assert wire.command_word() == 0


def test_id_register_layout() -> None:
    assert wire.id_register(0xBF, 0b01001, 1 << wire.MGMT_PF_BIT) == 0x2000 | 0x0900 | 0xBF
    with pytest.raises(InterbusError, match="management"):
        wire.id_register(0xBF, 1, 1)


# -- CRC ---------------------------------------------------------------------------------------------------------


def test_crc_catalogue_vectors() -> None:
    """CRC-16/IBM-SDLC (X-25) check value from the CRC catalogue, and the empty message."""
    assert wire.crc16(b"123456789") == 0x906E
    assert wire.crc16(b"") == 0x0000


@given(st.binary(max_size=64))
def test_crc_table_matches_the_bit_serial_register(data: bytes) -> None:
    crc = wire.CRC_INIT
    for byte in data:
        for i in range(8):
            crc = wire.crc_update_bit(crc, (byte >> (i if wire.CRC_REFIN else 7 - i)) & 1)
    if wire.CRC_REFOUT:
        crc = int(f"{crc:016b}"[::-1], 2)
    assert wire.crc16(data) == crc ^ wire.CRC_XOROUT


def test_crc_detects_every_single_and_double_bit_error() -> None:
    """Exhaustive over every bit position (and every pair) of frames up to 8 bytes."""
    for length in range(1, 9):
        data = bytes((17 * i + length) & 0xFF for i in range(length))
        good = wire.crc16(data)
        value = int.from_bytes(data, "little")
        bits = 8 * length
        for i in range(bits):
            for j in range(i, bits):
                flipped = value ^ (1 << i) ^ ((1 << j) if j != i else 0)
                assert wire.crc16(flipped.to_bytes(length, "little")) != good, (length, i, j)


# -- CNTR --------------------------------------------------------------------------------------------------------


def test_every_single_bit_error_makes_cntr_illegal() -> None:
    for attention in (False, True):
        for error in (False, True):
            word = wire.cntr_word(attention, error)
            assert wire.decode_cntr(word) == (attention, error)
            for bit in range(16):
                assert wire.decode_cntr(word ^ (1 << bit)) is None


def test_forward_cntr() -> None:
    clear = wire.CNTR_CLEAR
    assert wire.forward_cntr(clear, False, False) == (clear, False)
    assert wire.forward_cntr(clear, True, False) == (wire.cntr_word(False, True), False)
    assert wire.forward_cntr(clear, False, True) == (wire.cntr_word(True, False), False)
    assert wire.forward_cntr(wire.cntr_word(True, True), False, False) == (wire.cntr_word(True, True), False)
    assert wire.forward_cntr(clear ^ 1 << 7, False, False) == (wire.cntr_word(True, True), True)


# -- frames and line levels --------------------------------------------------------------------------------------

frames = st.builds(
    Frame,
    cycles,
    st.binary(min_size=2, max_size=40),
    st.integers(0, 0xFFFF),
    st.integers(0, 0xFFFF),
)


@settings(max_examples=100)
@given(frames)
def test_frame_levels_round_trip(frame: Frame) -> None:
    levels = wire.frame_levels(frame)
    assert len(levels) == frame.bit_count() == wire.DATA_TELEGRAM_BITS * (len(frame.data) + 4)
    assert wire.frame_from_telegrams(wire.parse_levels(levels)) == frame


@settings(max_examples=50)
@given(frames, st.integers(0, 600), st.booleans(), st.sampled_from(BIT_RATES))
def test_cycle_levels_and_pin_samples_round_trip(frame: Frame, devices: int, latch: bool, bit_rate: int) -> None:
    levels = wire.cycle_levels(frame, devices, latch)
    assert len(levels) == wire.cycle_bits(len(frame.data) - wire.LOOPBACK_BYTES, devices)
    samples = wire.levels_to_samples(levels, bit_rate)
    assert len(samples) == len(levels) * CLOCK_HZ // bit_rate
    assert np.array_equal(wire.samples_to_levels(samples, bit_rate), levels)
    telegrams = wire.parse_levels(levels)
    assert wire.frame_from_telegrams(telegrams) == frame
    tail = telegrams[len(frame.data) + wire.CHECK_TELEGRAMS :]
    assert all(t.data is None for t in tail if isinstance(t, Telegram))
    latches = [t for t in tail if isinstance(t, Telegram) and t.check]
    assert len(latches) == (wire.LATCH_STATUS_TELEGRAMS if latch else 0)


def test_clocks_per_bit() -> None:
    assert [wire.clocks_per_bit(rate) for rate in (500_000, 2_000_000)] == [64, 16]
    with pytest.raises(InterbusError, match="Table 1-7"):
        wire.clocks_per_bit(1_000_000)


def test_reset_is_longer_than_any_low_run_in_legal_traffic() -> None:
    longest = 0
    words = [(wire.data_telegram(b, c, k), wire.DATA_TELEGRAM_BITS) for b in range(256) for c in Cycle
             for k in (False, True)]  # fmt: skip
    words += [(wire.status_telegram(c, k), wire.STATUS_TELEGRAM_BITS) for c in Cycle for k in (False, True)]
    for word, length in words:
        run = 0
        for bit in range(length):
            run = run + 1 if (word >> bit) & 1 == wire.START_LEVEL else 0
            longest = max(longest, run)
    assert longest < wire.RESET_DETECT_BITS
    received = wire.parse_levels(wire.reset_levels(8))
    assert received[0] == LineReset(0)
    assert all(isinstance(t, Telegram) and t.data is None and not t.check for t in received[1:])
    assert len(wire.reset_levels(8)) == wire.reset_bits(8)


def test_parse_levels_names_the_bad_bit() -> None:
    levels = wire.frame_levels(Frame.build(Cycle.DATA, b"\x01\x02"))
    levels[wire.DATA_TELEGRAM_BITS + wire.DATA_TELEGRAM_BITS - 1] ^= 1
    with pytest.raises(TelegramError, match="stop bit") as caught:
        wire.parse_levels(levels)
    assert caught.value.bit == 2 * wire.DATA_TELEGRAM_BITS - 1


def test_frame_from_telegrams_rejects_short_check() -> None:
    telegrams = wire.parse_levels(wire.frame_levels(Frame.build(Cycle.ID, b"\x01\x02"))[: -wire.DATA_TELEGRAM_BITS])
    with pytest.raises(InterbusError, match="check sequence"):
        wire.frame_from_telegrams(telegrams)


# -- timing ------------------------------------------------------------------------------------------------------


@given(st.integers(0, 1024), st.integers(0, 512), st.data())
def test_cycle_bits(data_bytes: int, devices: int, data: st.DataObject) -> None:
    loops = data.draw(st.integers(0, devices))  # LBD-MR devices among them, each a second repeater (BK-55)
    bits = wire.cycle_bits(data_bytes, devices, loops)
    # The frame is Beckhoff's 13 x (6 + N); the rest is whole status telegrams covering the ring delay.
    rest = bits - 13 * (6 + data_bytes)
    assert rest % wire.STATUS_TELEGRAM_BITS == 0
    delay = (devices + loops) * wire.REPEATER_DELAY_BITS
    assert rest >= delay + wire.STATUS_TELEGRAM_BITS * wire.LATCH_STATUS_TELEGRAMS
    # no status telegram more than needed
    assert rest - wire.STATUS_TELEGRAM_BITS < delay + wire.STATUS_TELEGRAM_BITS * (
        wire.LATCH_STATUS_TELEGRAMS + wire.TURNAROUND_STATUS_TELEGRAMS)  # fmt: skip
    assert bits == wire.cycle_phases(data_bytes, devices, loops).total_bits
    assert wire.reset_bits(devices, loops) - wire.reset_bits(devices) == bits - wire.cycle_bits(data_bytes, devices)
    # The manual's CPU access window after the latch, 13 x (5 + n) bit periods (3.4.14), fits in one cycle.
    assert bits >= 13 * (5 + data_bytes)


def test_frames_from_levels_finds_every_frame() -> None:
    first = wire.Frame.build(wire.Cycle.ID, wire.LOOPBACK_BYTES_ON_LINE + b"\x01\x02")
    second = wire.Frame.build(wire.Cycle.DATA, wire.LOOPBACK_BYTES_ON_LINE + b"\xa5")
    idle = wire.status_levels(wire.Cycle.DATA, False, 3)
    levels = np.concatenate([idle, wire.reset_levels(1), wire.frame_levels(first), idle, wire.frame_levels(second)])
    assert wire.frames_from_levels(levels) == [first, second]


def test_a_receiver_skips_counter_telegrams_between_frames() -> None:
    """BK-49: a master's receiver takes an ID check telegram while no frame runs as a counter telegram (BK-6, BK-36)
    and skips it, every byte alike: counter telegrams alone are no frame, and frames between them are found whole;
    inside a frame an ID check telegram is the frame's check sequence, and a data-cycle check telegram always opens a
    frame."""
    counters = wire.telegram_levels([wire.data_telegram(b, Cycle.ID, True) for b in range(256)],
                                    wire.DATA_TELEGRAM_BITS)  # fmt: skip
    assert all(wire.is_counter_telegram(t) for t in wire.parse_levels(counters) if isinstance(t, Telegram))
    assert wire.decode_counter_telegram(wire.counter_telegram(5)) == 5
    assert wire.frames_from_levels(counters) == []
    with pytest.raises(InterbusError, match="check sequence"):
        wire.frame_from_telegrams(wire.parse_levels(counters))
    first = wire.Frame.build(wire.Cycle.ID, wire.LOOPBACK_BYTES_ON_LINE + b"\x01\x02")
    second = wire.Frame.build(wire.Cycle.DATA, b"")
    levels = np.concatenate([counters, wire.frame_levels(first), counters, wire.frame_levels(second), counters])
    assert wire.frames_from_levels(levels) == [first, second]
    assert wire.frame_from_telegrams(wire.parse_levels(levels)) == first
    assert not wire.is_counter_telegram(wire.decode_telegram(wire.status_telegram(Cycle.ID, True),
                                                             wire.STATUS_TELEGRAM_BITS))  # fmt: skip

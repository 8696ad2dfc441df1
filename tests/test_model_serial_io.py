"""Serial I/O (SPI master mode, manual 3.3) at pin level: in every SPI master mode of Tables 2-4 to 2-6 at both bit
rates the MFP pins follow the spec's sequence (supi3.serial_io) from the cycle after each latch (SM-2), SerIn is
read at the sample cycles (SM-5) and loaded by the next data cycle (SM-6), resets run the clear sequence (SM-9), and
step() and run() agree cycle for cycle."""

from __future__ import annotations

import re

import numpy as np
import numpy.typing as npt
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3 import serial_io as sio
from supi3 import tables
from supi3.config import DataDirection, DeviceConfig, MfpKind, decode
from supi3.errors import ArgumentError
from supi3.interbus import wire
from supi3.interbus.wire import Cycle, Frame
from supi3.model.pins import RESET_STRETCH_CLOCKS, Supi3Pins
from supi3.verif.timing import check_serial_io
from support import EchoDevice, assert_run_matches_step, quiet_inputs

SPI_ROWS = [r for r in tables.MODE_ROWS if decode(r.c, r.mfp).mfp_mode.kind is MfpKind.SPI_MASTER]
RATES = [tables.clk_conf_for(500_000), tables.clk_conf_for(2_000_000)]
FAST = RATES[1]
CASES = [(row, clk) for row in SPI_ROWS for clk in RATES]
IDLE = wire.status_levels(Cycle.DATA, False, 20)
"""Idle telegrams: 100 bit periods, longer than the longest sequence (62.5 bit periods)."""
IDLE_MFP = sio.IDLE.mfp()
SER_IN = 1 << 6

Trace = npt.NDArray[np.int64]


def _config(row: tables.ModeRow, clk: str = FAST) -> DeviceConfig:
    return decode(row.c, row.mfp, clk_conf=clk)


def _sequences(config: DeviceConfig) -> tuple[sio.SerialSequence, sio.SerialSequence | None]:
    mode = config.mfp_mode
    return (sio.sequence(mode.direction, mode.width, config.bit_rate),
            sio.clear_sequence(mode.direction, mode.width, config.bit_rate))  # fmt: skip


def _line(outs: list[bytes], *, reset_after_first: bool = False) -> npt.NDArray[np.uint8]:
    """Master levels: an INTERBUS reset, an ID cycle, a data cycle per OUT word with idle after each."""
    lw = wire.LOOPBACK_BYTES_ON_LINE
    parts = [IDLE, wire.reset_levels(1), IDLE,
             wire.cycle_levels(Frame.build(Cycle.ID, lw + wire.word_bytes(wire.command_word(0))), 1, True), IDLE]
    for k, out in enumerate(outs):
        parts.append(wire.cycle_levels(Frame.build(Cycle.DATA, lw + out), 1, True))
        parts.append(wire.reset_levels(1) if reset_after_first and k == 0 else IDLE)
    return np.concatenate(parts)


def _inputs(config: DeviceConfig, levels: npt.NDArray[np.uint8], mfp_in: Trace | None = None) -> dict[str, Trace]:
    do1 = wire.levels_to_samples(levels, config.bit_rate).astype(np.int64)
    inputs = quiet_inputs(len(do1))
    inputs["do1"] = do1
    if mfp_in is not None:
        inputs["mfp_in"] = mfp_in[: len(do1)]
    return inputs


def _events(model: Supi3Pins, pattern: str) -> list[tuple[int, str]]:
    """(cycle, first group) of each logged event matching ``pattern``."""
    found = []
    for line in model.log.recent():
        m = re.fullmatch(rf"cycle (\d+): {pattern}", line)
        if m:
            found.append((int(m.group(1)), m.group(2) if m.re.groups > 1 else ""))
    return found


def _overlay(trace: Trace, start: int, seq: sio.SerialSequence, word: int, stop: int | None = None) -> None:
    """Write ``seq``'s pins from ``start`` into ``trace`` (idle after it, or cut at ``stop``)."""
    levels = np.array([lv.mfp() for lv in sio.render(seq, word)], dtype=np.int64)
    end = start + seq.length if stop is None else min(stop, start + seq.length)
    trace[start:end] = levels[: end - start]
    trace[end:] = IDLE_MFP


def _read_word(seq: sio.SerialSequence, start: int, ser_in: Trace) -> int:
    """The word a read frame starting at ``start`` takes from the raw MFP input trace (SM-5)."""
    frame = seq.read
    assert frame is not None
    word = 0
    for j in range(frame.bits):
        word = (word << 1) | int((ser_in[start + frame.sample(j)] >> 6) & 1)
    return word


# ------------------------------------------------------------------------------------------------------------
# Every SPI master mode at both bit rates: pins and IN data
# ------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(("row", "clk"), CASES, ids=[f"{r.c}-{r.mfp}-{clk}" for r, clk in CASES])
def test_pins_follow_the_sequence_and_serin_is_read_at_the_samples(row: tables.ModeRow, clk: str) -> None:
    config = _config(row, clk)
    seq, clear = _sequences(config)
    rng = np.random.default_rng(CASES.index((row, clk)))
    outs = [bytes(rng.integers(0, 256, config.data_bytes).tolist()) for _ in range(3)]
    levels = _line(outs)
    n = len(wire.levels_to_samples(levels, config.bit_rate))
    mfp_in = np.repeat(rng.integers(0, 1 << 16, n // 5 + 1), 5)[:n]  # SerIn and the unused MFPs change often
    model = Supi3Pins(config)
    traces = model.run(_inputs(config, levels, mfp_in))
    (reset, _), = _events(model, "INTERBUS reset detected")
    latches = _events(model, r"data cycle latched: ([0-9a-f]*)")
    loads = [load for load in _events(model, r"data cycle: load ([0-9a-f]*)") if load[0] > reset]
    assert [bytes.fromhex(h) for _, h in latches] == outs
    expected = np.full(n, IDLE_MFP, dtype=np.int64)
    if clear is not None:  # SM-9: the reset writes zeros in the modes with OUT data
        _overlay(expected, reset + 1, clear, 0)
    for latch, out in latches:
        _overlay(expected, latch + 1, seq, int(out, 16))  # SM-2: from the cycle after the latch
    bad = np.flatnonzero(traces["mfp_out"] != expected)
    assert not bad.size, f"mfp_out differs first at cycle {bad[0]}: {traces['mfp_out'][bad[0]]:#x}"
    assert (traces["mfp_oe"] == sio.MFP_MASK).all()
    # Every Table 3-4 row holds on the trace (the checker measures it on its own, supi3.verif.timing).
    assert check_serial_io(traces, bit_rate=config.bit_rate, bits=config.mfp_mode.width) == []
    # SM-5, SM-6: the word read after data cycle k is what data cycle k + 1 loads; 0 after the reset.
    words = [_read_word(seq, latch + 1, mfp_in) if seq.read is not None else 0 for latch, _ in latches]
    assert [int(h, 16) for _, h in loads] == [0, *words[:-1]]
    assert model.chip.in_word == words[-1]


def test_mfp_pins_idle_through_power_up() -> None:
    config = _config(SPI_ROWS[0])
    model = Supi3Pins(config)
    traces = model.run(quiet_inputs(RESET_STRETCH_CLOCKS + 50))
    assert (traces["mfp_out"] == IDLE_MFP).all() and IDLE_MFP == 0x28  # /SS and /Conv high, SCLK, SerOut low


# ------------------------------------------------------------------------------------------------------------
# A device attached to the chip (Supi3.attach_serial)
# ------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("row", SPI_ROWS, ids=[f"{r.c}-{r.mfp}" for r in SPI_ROWS])
def test_device_is_clocked_by_the_pins_and_answers_on_serin(row: tables.ModeRow) -> None:
    config = _config(row)
    seq, clear = _sequences(config)
    width = config.mfp_mode.width
    rng = np.random.default_rng(SPI_ROWS.index(row))
    outs = [bytes(rng.integers(0, 256, config.data_bytes).tolist()) for _ in range(2)]
    model = Supi3Pins(config)
    device = EchoDevice(width, int(rng.integers(0, 1 << width)))
    model.chip.attach_serial(device)
    levels = _line(outs)
    model.run(_inputs(config, levels, np.full(len(wire.levels_to_samples(levels, config.bit_rate)), SER_IN)))
    writes = [("frame", int.from_bytes(out, "big"), width) for out in outs]
    cleared = [] if clear is None else [("frame", 0, width), ("convert",)]
    if config.mfp_mode.direction is DataDirection.IN:
        assert device.record == [("frame", 0, width)] * 2
    elif config.mfp_mode.direction is DataDirection.OUT:
        assert device.record == [*cleared, writes[0], ("convert",), writes[1], ("convert",)]
    else:
        assert device.record == [*cleared, ("frame", 0, width), writes[0], ("convert",),
                                 ("frame", 0, width), writes[1], ("convert",)]  # fmt: skip
    # The device's word, not the MFP6 pin (held high here), is what was read.
    assert model.chip.in_word == (device.value if seq.read is not None else 0)


def test_device_answer_must_be_a_level() -> None:
    config = _config(SPI_ROWS[0])  # IN/OUT: a read frame
    model = Supi3Pins(config)

    class Floating(EchoDevice):
        def clock(self, levels: sio.Levels) -> int:
            super().clock(levels)
            return 2

    model.chip.attach_serial(Floating(16))
    with pytest.raises(ArgumentError, match=r"SerialDevice.clock\(\) must be"):
        model.run(_inputs(config, _line([b"\x00\x00"])))


# ------------------------------------------------------------------------------------------------------------
# SM-2, SM-12: a latch while a sequence runs; SM-9: resets abort it
# ------------------------------------------------------------------------------------------------------------


_WRITING = [r for r in SPI_ROWS if _config(r).mfp_mode.direction is not DataDirection.IN]
"""The SPI master rows with OUT data (a clear sequence after a reset, SM-9)."""


def _after_power_up(config: DeviceConfig) -> Supi3Pins:
    model = Supi3Pins(config)
    model.run(quiet_inputs(RESET_STRETCH_CLOCKS + 10))
    return model


@pytest.mark.parametrize("row", SPI_ROWS[:6], ids=[f"{r.c}-{r.mfp}" for r in SPI_ROWS[:6]])
def test_latch_during_a_data_sequence_begins_anew(row: tables.ModeRow) -> None:
    """SM-12: a latch while a data sequence runs abandons it (nothing taken over) and begins anew; two at one
    edge: the newer (INTERBUS cycles never ask it: tests/test_rtl_serial_io.py)."""
    config = _config(row)
    seq, _ = _sequences(config)
    model = _after_power_up(config)
    chip = model.chip
    nbytes = config.data_bytes
    chip.latch_at(Cycle.DATA, b"\x81" * nbytes, model.cycle - 1)  # the edge that ended the last cycle run
    first = model.run({**quiet_inputs(10), "mfp_in": np.full(10, SER_IN)})
    chip.latch_at(Cycle.DATA, b"\x42" * nbytes, model.cycle - 1)  # abandons the running sequence
    chip.latch_at(Cycle.DATA, b"\x3c" * nbytes, model.cycle - 1)  # and this one the one not yet begun
    second = model.run(quiet_inputs(seq.length + 40))
    expected = np.full(seq.length + 50, IDLE_MFP, dtype=np.int64)
    _overlay(expected, 0, seq, int.from_bytes(b"\x81" * nbytes, "big"), stop=10)
    _overlay(expected, 10, seq, int.from_bytes(b"\x3c" * nbytes, "big"))
    assert np.array_equal(np.concatenate([first["mfp_out"], second["mfp_out"]]), expected)
    assert chip.in_word == 0  # the first read frame was abandoned, the last read the idle MFP6 (0)


@pytest.mark.parametrize("row", _WRITING[:4], ids=[f"{r.c}-{r.mfp}" for r in _WRITING[:4]])
def test_latch_during_the_clear_sequence_waits_and_the_newest_word_wins(row: tables.ModeRow) -> None:
    """SM-2, SM-9: a watchdog reset of process data, then two latches while its clear sequence runs: the newer
    word's sequence begins on the cycle after the clear sequence ends."""
    config = _config(row)
    seq, clear = _sequences(config)
    assert clear is not None
    model = _after_power_up(config)
    chip = model.chip
    chip._deadline = model.cycle - 1  # the layer-2 watchdog's expiry resets process data (3.4.14)
    chip._reschedule()
    chip._advance(model.cycle - 1)
    assert chip.events["WATCHDOG"] == 1
    first = model.run(quiet_inputs(10))
    nbytes = config.data_bytes
    chip.latch_at(Cycle.DATA, b"\x42" * nbytes, model.cycle - 1)  # waits
    chip.latch_at(Cycle.DATA, b"\x3c" * nbytes, model.cycle - 1)  # replaces the waiting word
    second = model.run(quiet_inputs(clear.length + seq.length + 30))
    expected = np.full(clear.length + seq.length + 40, IDLE_MFP, dtype=np.int64)
    _overlay(expected, 0, clear, 0)
    _overlay(expected, clear.length, seq, int.from_bytes(b"\x3c" * nbytes, "big"))
    assert np.array_equal(np.concatenate([first["mfp_out"], second["mfp_out"]]), expected)


@pytest.mark.parametrize("row", SPI_ROWS, ids=[f"{r.c}-{r.mfp}" for r in SPI_ROWS])
@pytest.mark.parametrize("how", ["interbus", "watchdog"])
def test_reset_in_a_sequence_aborts_it_and_clears(row: tables.ModeRow, how: str) -> None:
    config = _config(row)
    seq, clear = _sequences(config)
    model = _after_power_up(config)
    chip = model.chip
    start = model.cycle
    chip.latch_at(Cycle.DATA, b"\xff" * config.data_bytes, start - 1)
    cut = seq.length // 2
    first = model.run({**quiet_inputs(cut), "mfp_in": np.full(cut, SER_IN)})
    if how == "interbus":
        chip.reset_at(model.cycle - 1)
    else:  # the layer-2 watchdog's expiry resets process data (3.4.14)
        chip._deadline = model.cycle - 1
        chip._reschedule()
        chip._advance(model.cycle - 1)
        assert chip.events["WATCHDOG"] == 1
    rest = 2 * seq.length
    second = model.run({**quiet_inputs(rest), "mfp_in": np.full(rest, SER_IN)})
    expected = np.full(cut + rest, IDLE_MFP, dtype=np.int64)
    _overlay(expected, 0, seq, int.from_bytes(b"\xff" * config.data_bytes, "big"), stop=cut)
    if clear is not None:
        _overlay(expected, cut, clear, 0)
    assert np.array_equal(np.concatenate([first["mfp_out"], second["mfp_out"]]), expected)
    assert chip.in_word == 0  # the read frame was aborted: nothing taken over


def test_interbus_reset_on_the_line_in_the_longest_sequence() -> None:
    row = next(r for r in SPI_ROWS if _config(r).function == "RB, SPI 32 IN/32 OUT")
    config = _config(row)
    seq, clear = _sequences(config)
    assert clear is not None
    model = Supi3Pins(config)
    levels = _line([b"\x12\x34\x56\x78", b"\x9a\xbc\xde\xf0"], reset_after_first=True)
    traces = model.run(_inputs(config, levels, np.full(len(wire.levels_to_samples(levels, config.bit_rate)), SER_IN)))
    (reset1, _), (reset2, _) = _events(model, "INTERBUS reset detected")
    (latch1, _), (latch2, _) = _events(model, r"data cycle latched: ([0-9a-f]*)")
    assert latch1 < reset2 < latch1 + seq.length  # the reset comes inside the first sequence
    expected = np.full(len(traces["mfp_out"]), IDLE_MFP, dtype=np.int64)
    _overlay(expected, reset1 + 1, clear, 0)
    _overlay(expected, latch1 + 1, seq, 0x12345678, stop=reset2 + 1)
    _overlay(expected, reset2 + 1, clear, 0)
    _overlay(expected, latch2 + 1, seq, 0x9ABCDEF0)
    assert np.array_equal(traces["mfp_out"], expected)
    # The aborted read frame left the IN word 0: the second data cycle loaded zeros.
    assert _events(model, r"data cycle: load ([0-9a-f]*)")[-1][1] == "00000000"


# ------------------------------------------------------------------------------------------------------------
# step() == run()
# ------------------------------------------------------------------------------------------------------------


@settings(max_examples=10, deadline=None)
@given(
    row=st.sampled_from(SPI_ROWS),
    outs=st.lists(st.binary(min_size=4, max_size=4), min_size=1, max_size=3),
    seed=st.integers(0, 2**32 - 1),
    resu_at=st.one_of(st.none(), st.integers(0, 30_000)),
    device=st.booleans(),
    cuts=st.lists(st.floats(0, 1), max_size=3),
)
def test_step_and_run_agree_cycle_for_cycle(row: tables.ModeRow, outs: list[bytes], seed: int,
                                            resu_at: int | None, device: bool, cuts: list[float]) -> None:
    config = _config(row)
    levels = _line([out[: config.data_bytes] for out in outs])
    n = len(wire.levels_to_samples(levels, config.bit_rate))
    rng = np.random.default_rng(seed)
    inputs = _inputs(config, levels, np.repeat(rng.integers(0, 1 << 16, n // 3 + 1), 3)[:n])
    if resu_at is not None:
        inputs["resu_n"][resu_at : resu_at + 40] = 0
    stepped, bulk = Supi3Pins(config), Supi3Pins(config)
    value = int(rng.integers(0, 1 << config.mfp_mode.width))
    devices = [EchoDevice(config.mfp_mode.width, value) for _ in "ab"]
    if device:
        stepped.chip.attach_serial(devices[0])
        bulk.chip.attach_serial(devices[1])
    assert_run_matches_step(stepped, bulk, inputs, cuts)
    assert stepped.chip.in_word == bulk.chip.in_word
    assert devices[0].record == devices[1].record

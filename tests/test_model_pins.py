"""The cycle-accurate pin-level model: step() and run() agree cycle for cycle; the transaction level and the pin
level agree on shared scenarios; line timing; resets, corrupted telegrams and silence at pin level."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3 import tables
from supi3.config import DeviceConfig, MfpKind, decode
from supi3.interbus import wire
from supi3.interbus.master import Master
from supi3.interbus.ring import Ring
from supi3.interbus.wire import Cycle, Frame
from supi3.model.chip import Supi3
from supi3.model.pinring import PinRing
from supi3.model.pins import IDLE_TIMEOUT_CLOCKS, RESET_STRETCH_CLOCKS, SYNC_STAGES, Supi3Pins
from support import assert_run_matches_step

FAST = tables.clk_conf_for(2_000_000)  # CLK_CONF: 2 Mbit/s, 16 clocks per bit, keeps pin-level tests short
BINARY = [r for r in tables.MODE_ROWS if decode(r.c, r.mfp).mfp_mode.kind is MfpKind.BINARY_IO]
IDLE = wire.status_levels(Cycle.DATA, False, 20)


def _config(row: tables.ModeRow, clk: str = FAST) -> DeviceConfig:
    return decode(row.c, row.mfp, clk_conf=clk)


def _traffic(out: bytes, latch: bool = True) -> npt.NDArray[np.uint8]:
    """Master levels: reset, an ID cycle, a data cycle with ``out``, idle (one device)."""
    lw = wire.LOOPBACK_BYTES_ON_LINE
    return np.concatenate([
        IDLE, wire.reset_levels(1), IDLE,
        wire.cycle_levels(Frame.build(Cycle.ID, lw + wire.word_bytes(wire.command_word(0))), 1, True), IDLE,
        wire.cycle_levels(Frame.build(Cycle.DATA, lw + out), 1, latch), IDLE,
    ])  # fmt: skip


def _inputs(do1: npt.NDArray[np.int64], **pins: npt.NDArray[np.int64] | int) -> dict[str, npt.NDArray[np.int64]]:
    n = len(do1)
    base: dict[str, npt.NDArray[np.int64] | int] = {"di2": 0, "rbst_ext": 0, "mfp_in": 0, "stat_err_n": 1,
                                                    "resu_n": 1, "vmon_ok": 1, "from_exr": 0}
    base.update(pins)
    traces = {name: np.broadcast_to(np.asarray(v, dtype=np.int64), (n,)).copy() for name, v in base.items()}
    traces["do1"] = do1
    return traces


# ------------------------------------------------------------------------------------------------------------
# step() == run()
# ------------------------------------------------------------------------------------------------------------


@pytest.mark.slow
@settings(max_examples=25, deadline=None)
@given(
    row=st.sampled_from(BINARY),
    out=st.binary(min_size=2, max_size=2),
    seed=st.integers(0, 2**32 - 1),
    flips=st.integers(0, 6),
    latch=st.booleans(),
    resu_at=st.one_of(st.none(), st.integers(0, 12_000)),
    stat_at=st.one_of(st.none(), st.integers(0, 12_000)),
)
def test_step_and_run_agree_cycle_for_cycle(row: tables.ModeRow, out: bytes, seed: int, flips: int, latch: bool,
                                            resu_at: int | None, stat_at: int | None) -> None:
    config = _config(row)
    do1 = wire.levels_to_samples(_traffic(out[: config.data_bytes], latch), config.bit_rate).astype(np.int64)
    n = len(do1)
    rng = np.random.default_rng(seed)
    do1[rng.integers(0, n, flips)] ^= 1
    resu = np.ones(n, dtype=np.int64)
    if resu_at is not None:
        resu[resu_at : resu_at + 40] = 0
    stat = np.ones(n, dtype=np.int64)
    if stat_at is not None:
        stat[stat_at:] = 0
    mfp = np.repeat(rng.integers(0, 1 << 16, n // 700 + 1), 700)[:n]
    di2 = np.where(np.arange(n) > 3000, rng.integers(0, 2, n), 0)
    inputs = _inputs(do1, resu_n=resu, stat_err_n=stat, mfp_in=mfp, di2=di2)
    stepped, bulk = Supi3Pins(config), Supi3Pins(config)
    assert_run_matches_step(stepped, bulk, inputs, [1 / 3])
    assert stepped.chip.events == bulk.chip.events
    assert stepped.chip.id_register() == bulk.chip.id_register()
    assert stepped.chip.mfp_outputs == bulk.chip.mfp_outputs


@pytest.mark.slow
@settings(max_examples=30, deadline=None)
@given(
    runs=st.lists(st.tuples(st.integers(0, 1), st.integers(1, 3 * wire.RESET_DETECT_BITS * 16)), max_size=60),
    cuts=st.lists(st.floats(0, 1), max_size=6),
    resu_at=st.one_of(st.none(), st.integers(0, 20_000)),
)
def test_step_and_run_agree_on_any_line(runs: list[tuple[int, int]], cuts: list[float], resu_at: int | None) -> None:
    """Any line (runs of either level, some long enough or nearly long enough for an INTERBUS reset) between
    telegrams of a real cycle, run() cut into pieces anywhere: run() skips line changes inside telegrams and
    restores where a run of start level began (the reset detector), which must be exactly what step() sees."""
    config = _config(BINARY[0])
    cpb = wire.clocks_per_bit(config.bit_rate)
    noise = np.concatenate([np.full(length, level, dtype=np.int64) for level, length in runs] or [np.ones(0, np.int64)])
    traffic = wire.levels_to_samples(_traffic(b"\x5a"), config.bit_rate).astype(np.int64)
    do1 = np.concatenate([traffic[: len(traffic) // 2], noise, traffic[len(traffic) // 2 :], noise[::-1]])
    n = len(do1)
    resu = np.ones(n, dtype=np.int64)
    if resu_at is not None:
        resu[resu_at : resu_at + 3 * cpb] = 0
    inputs = _inputs(do1, resu_n=resu)
    stepped, bulk = Supi3Pins(config), Supi3Pins(config)
    assert_run_matches_step(stepped, bulk, inputs, cuts)
    assert stepped.chip.events == bulk.chip.events
    assert stepped.log.recent() == bulk.log.recent()


# ------------------------------------------------------------------------------------------------------------
# Line timing
# ------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("clk", [tables.clk_conf_for(r) for r in tables.BIT_RATES])
def test_repeater_delay_is_three_bit_periods(clk: str) -> None:
    config = decode("10000", clk_conf=clk)
    model = Supi3Pins(config)
    do1 = wire.levels_to_samples(np.concatenate([IDLE, wire.status_levels(Cycle.DATA, True, 4), IDLE]),
                                 config.bit_rate).astype(np.int64)
    do2 = model.run(_inputs(do1))["do2"]
    cpb = wire.clocks_per_bit(config.bit_rate)
    start = 10 * wire.STATUS_TELEGRAM_BITS * cpb  # the receiver is in step with the telegrams by now
    edges_in = np.flatnonzero(np.diff(do1[start:]) != 0)
    edges_out = np.flatnonzero(np.diff(do2[start:]) != 0)
    delay = wire.REPEATER_DELAY_BITS * cpb
    later = [e for e in edges_out.tolist() if e >= delay]
    assert len(later) >= 8
    assert set(later) <= {e + delay for e in edges_in.tolist()}


def test_data_clock_and_reset_stretch() -> None:
    config = decode("10000")
    trace = Supi3Pins(config).run(_inputs(np.ones(400, dtype=np.int64)))
    assert trace["resu_drive"][:RESET_STRETCH_CLOCKS].all() and not trace["resu_drive"][RESET_STRETCH_CLOCKS:].any()
    assert trace["dclk_out"][:64].tolist() == [1] * 32 + [0] * 32  # 500 kbit/s data clock (Table 1-4)


# ------------------------------------------------------------------------------------------------------------
# Pin level agrees with the transaction level on shared scenarios
# ------------------------------------------------------------------------------------------------------------


def _compare(tl: list[Supi3], pins: list[Supi3Pins]) -> None:
    for a, b in zip(tl, pins, strict=True):
        assert a.mfp_outputs == b.chip.mfp_outputs
        assert a.id_register() == b.chip.id_register()
        assert a.events == b.chip.events


@settings(max_examples=15, deadline=None)
@given(
    rows=st.lists(st.sampled_from(BINARY), min_size=1, max_size=3),
    cycles=st.lists(st.tuples(st.binary(min_size=6, max_size=6), st.integers(0, 0xFFFF)), min_size=1,
                    max_size=3),
)
def test_transaction_and_pin_level_agree(rows: list[tables.ModeRow], cycles: list[tuple[bytes, int]]) -> None:
    configs = [_config(r) for r in rows]
    tl_chips = [Supi3(c) for c in configs]
    pin_chips = [Supi3Pins(c) for c in configs]
    tl_ring, pin_ring = Ring(list(tl_chips), bit_rate=2_000_000), PinRing(pin_chips)
    pin_ring.idle(0.0002)  # power-up reset stretch
    masters = [Master(tl_ring, locate=False, max_devices=4), Master(pin_ring, locate=False, max_devices=4)]
    for master in masters:
        assert master.start().ok
    assert masters[0].config == masters[1].config
    pin_ring.settle()
    _compare(tl_chips, pin_chips)
    for out, mfp in cycles:
        for k, chip in enumerate(tl_chips, start=1):
            chip.set_mfp_inputs(mfp)
            pin_ring.set_input(k, "mfp_in", mfp)
            for master in masters:
                master.set_outputs(k, out[: chip.data_bytes()])
        results = [master.data_cycle() for master in masters]
        assert results[0].ok and results[1].ok
        pin_ring.settle()
        for k in range(1, len(rows) + 1):
            assert masters[0].inputs(k) == masters[1].inputs(k)
        _compare(tl_chips, pin_chips)


# ------------------------------------------------------------------------------------------------------------
# Reliability at pin level
# ------------------------------------------------------------------------------------------------------------


@settings(max_examples=25, deadline=None)
@given(row=st.sampled_from(BINARY), out=st.binary(min_size=2, max_size=2), bits=st.lists(st.integers(0, 10**6),
                                                                                       min_size=1, max_size=3))
def test_corrupted_data_cycle_never_latches(row: tables.ModeRow, out: bytes, bits: list[int]) -> None:
    config = _config(row)
    model = Supi3Pins(config)
    first = wire.levels_to_samples(_traffic(out[: config.data_bytes]), config.bit_rate).astype(np.int64)
    model.run(_inputs(first))
    latched = (model.chip.mfp_outputs, model.chip.out_word)
    valid = model.chip.events["VALID"]
    lw = wire.LOOPBACK_BYTES_ON_LINE
    new = bytes(b ^ 0xFF for b in out[: config.data_bytes])
    frame = Frame.build(Cycle.DATA, lw + new)
    levels = np.concatenate([wire.frame_levels(frame), wire.status_levels(Cycle.DATA, False, 2)])
    for bit in bits:
        levels[bit % wire.frame_bits(len(frame.data))] ^= 1  # corrupt the frame only, then a proper latch
    levels = np.concatenate([levels, wire.status_levels(Cycle.DATA, True, 2), IDLE])
    model.run(_inputs(wire.levels_to_samples(levels, config.bit_rate).astype(np.int64)))
    if model.chip.events["VALID"] > valid:
        # Only possible if the flips cancelled out in every check: the data latched is then the master's.
        assert model.chip.out_word == int.from_bytes(new, "big")
    else:
        assert (model.chip.mfp_outputs, model.chip.out_word) == latched


def test_reset_pattern_in_the_middle_of_a_cycle_clears_data() -> None:
    config = _config(BINARY[0])
    model = Supi3Pins(config)
    model.run(_inputs(wire.levels_to_samples(_traffic(b"\xff"), config.bit_rate).astype(np.int64)))
    assert model.chip.out_word == 0xFF
    frame = wire.frame_levels(Frame.build(Cycle.DATA, wire.LOOPBACK_BYTES_ON_LINE + b"\x00"))
    levels = np.concatenate([frame[:40], wire.reset_levels(1), IDLE])
    model.run(_inputs(wire.levels_to_samples(levels, config.bit_rate).astype(np.int64)))
    assert model.chip.out_word == 0 and model.chip.mfp_outputs == 0
    assert model.chip.events["IB_RESET"] == 2 and model.chip.events["VALID"] == 1


def test_silent_line_is_an_interbus_reset_after_20_ms() -> None:
    config = decode("10000", clk_conf=FAST)
    model = Supi3Pins(config)
    n = RESET_STRETCH_CLOCKS + IDLE_TIMEOUT_CLOCKS + 10
    model.run(_inputs(np.ones(n - 20, dtype=np.int64)))
    assert model.chip.events["IB_RESET"] == 0
    model.run(_inputs(np.ones(20, dtype=np.int64)))
    assert model.chip.events["IB_RESET"] == 1


def test_resu_low_holds_the_chip_in_reset() -> None:
    config = decode("10000", clk_conf=FAST)
    model = Supi3Pins(config)
    n = 2000
    resu = np.ones(n, dtype=np.int64)
    resu[500:900] = 0
    trace = model.run(_inputs(np.ones(n, dtype=np.int64), resu_n=resu))
    drive = np.flatnonzero(trace["resu_drive"])
    # The chip pulls /ResU low while the reset lasts and for the 4 µs stretch after it (1.7.2).
    assert drive.max() == 900 + SYNC_STAGES + RESET_STRETCH_CLOCKS - 1


def test_voltage_monitor_hysteresis() -> None:
    from supi3.model.chip import VoltageMonitor

    monitor = VoltageMonitor()
    ramp = [0.0, 3.0, 4.4, 4.6, 4.2, 3.95, 3.85, 4.4, 4.51, 5.0]
    assert [monitor.sense(v) for v in ramp] == [False, False, False, True, True, True, False, False, True, True]


def test_io_access_bit_covers_check_sequence_and_latch_phase(monkeypatch: pytest.MonkeyPatch) -> None:
    config = decode("10000", clk_conf=FAST)
    model = Supi3Pins(config)
    seen: list[tuple[str, bool, int]] = []
    original_io, original_latch = model.chip.set_io_access, model.chip.set_latch_phase

    def io(busy: bool) -> None:
        seen.append(("io", busy, model.cycle))
        original_io(busy)

    def latch(on: bool) -> None:
        seen.append(("latch", on, model.cycle))
        original_latch(on)

    monkeypatch.setattr(model.chip, "set_io_access", io)
    monkeypatch.setattr(model.chip, "set_latch_phase", latch)
    model.run(_inputs(wire.levels_to_samples(_traffic(b"\x42"), config.bit_rate).astype(np.int64)))
    assert [(kind, on) for kind, on, _ in seen] == [("io", True), ("latch", True), ("latch", False), ("io", False)]
    cpb = wire.clocks_per_bit(config.bit_rate)
    io_set, latch_start = seen[0][2], seen[1][2]
    # 3.4.14: once the bit reads 0 the registers may be accessed for 30 bit periods before the latch phase.
    assert latch_start - io_set >= 30 * cpb
    assert not model.chip.io_access and model.chip.out_word == 0x42

"""The RTL chip core (supi3.rtl.core) against the cycle-accurate model (supi3.model.pins), every pin every clock.

One Verilator build of the core serves every operating mode: the straps are ports, driven as constants by the
stimulus (supi3.verif.straps). Short scenarios run on the batch path through the harness; the two long ones (the
200 ms /StatErr filter and the 50 ms watchdog) replay through the same Verilator build against the model's fast
``run()``, chunk by chunk. Line stimulus is built with supi3.interbus.wire (docs/interbus.md).
"""

from __future__ import annotations

import functools
import subprocess
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.config import DeviceConfig, MfpKind, Variant, decode, mode_rows
from supi3.interbus import wire
from supi3.interbus.wire import Cycle, Frame
from supi3.model.chip import STATERR_FILTER_CLOCKS, WATCHDOG_CLOCKS
from supi3.model.pins import IB_DIAG_DIVIDER_BITS, Supi3Pins
from supi3.rtl.core import Supi3Core, verilog
from supi3.tables import RF_MODES, ModeRow
from supi3.verif import Lockstep, first_mismatch
from supi3.verif.amaranth_sim import run_amaranth_sim
from supi3.verif.straps import StrapPins, strap_stimulus
from support import CORE_INPUTS, IDLE, LOOPBACK, WATCHDOG_LATEST, Columns, CoreScript, pulses, quiet_inputs

OPC_ROWS = list(mode_rows(Variant.OPC))
BINARY_ROWS = [row for row in OPC_ROWS if decode(row.c, row.mfp).mfp_mode.kind is MfpKind.BINARY_IO]
RF_VALUES = [mode.rf for mode in RF_MODES]


def fast_config(c: str = "10000", mfp: str | None = None) -> DeviceConfig:
    return decode(c, mfp, clk_conf="11")


@pytest.fixture(scope="session")
def bench(core_bench: Lockstep) -> Lockstep:
    return core_bench  # tests/conftest.py: one build, shared with tests/test_verif_lockstep_serial.py


@pytest.fixture(scope="session")
def bench_ls(bench: Lockstep) -> Lockstep:
    lockstep = Lockstep(
        functools.partial(Supi3Core, "ls"), functools.partial(StrapPins, "ls"), build_dir=bench.build_dir
    )
    lockstep.prepare(simulators=())
    return lockstep


# Model fix ----------------------------------------------------------------------------------------------------------


@pytest.mark.slow
def test_model_staterr_filter_restarts_after_power_up() -> None:
    # /StatErr low for 1200 clocks, released while a power-up reset holds the chip: no fault may latch later (the
    # model used to keep the level across the power-up and time the 200 ms filter from clock 0).
    n = STATERR_FILTER_CLOCKS + 100_000
    inputs = quiet_inputs(n)
    inputs["stat_err_n"][1000:2200] = 0
    inputs["resu_n"][2000:2500] = 0
    model = Supi3Pins(fast_config())
    model.run(inputs)
    assert not model.chip.pf


# Elaboration and export ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("variant", ["opc", "ls"])
def test_verilog_has_the_model_pins_and_straps(variant: str) -> None:
    text = verilog(variant)
    assert "module supi3_core" in text
    for pin in (*StrapPins.inputs, *StrapPins.outputs):
        assert f" {pin.name}" in text


# Every operating mode -----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("row", OPC_ROWS, ids=[f"{row.c}-{row.mfp or 'x'}" for row in OPC_ROWS])
def test_every_mode(bench: Lockstep, row: ModeRow) -> None:
    index = OPC_ROWS.index(row)
    c, mfp = row.c, row.mfp
    config = decode(
        c, mfp, rf=RF_VALUES[index % len(RF_VALUES)], clk_conf="01" if index % 7 == 0 else "11", diag_conf=index % 2
    )
    rng = np.random.default_rng(index)
    script = CoreScript(config, rng).bring_up()
    script.id_cycle(wire.command_word(index % len(WATCHDOG_CLOCKS), quit_peripheral_error=bool(index % 2)))
    script.data_cycle(rbst_ext=1).data_cycle(extra=1).data_cycle(latch=False, di2=1, rbst_ext=0).data_cycle()
    bench.run_batch(script.stimulus())


@pytest.mark.parametrize("c", ["10000", "10011", "11001", "11111"])
def test_ls_variant(bench_ls: Lockstep, c: str) -> None:
    rows = [row for row in mode_rows(Variant.LS) if row.c == c]
    for k, row in enumerate(rows[:: max(1, len(rows) // 3)]):
        config = decode(row.c, row.mfp, clk_conf="11", variant=Variant.LS)
        script = CoreScript(config, np.random.default_rng(k)).bring_up().id_cycle(wire.command_word(1))
        bench_ls.run_batch(script.data_cycle().data_cycle(extra=2, di2=1).stimulus())


# Random data, MFP inputs, bit errors, resets ------------------------------------------------------------------------


@settings(max_examples=30, deadline=None)
@given(
    row=st.sampled_from(BINARY_ROWS),
    seed=st.integers(0, 2**32 - 1),
    cycles=st.lists(
        st.tuples(st.booleans(), st.integers(0, 3), st.integers(0, 3), st.booleans()), min_size=2, max_size=5
    ),
)
def test_random_cycles_and_bit_errors(
    bench: Lockstep, row: ModeRow, seed: int, cycles: list[tuple[bool, int, int, bool]]
) -> None:
    config = fast_config(row.c, row.mfp)
    script = CoreScript(config, np.random.default_rng(seed)).bring_up()
    for is_id, extra, flips, latch in cycles:
        if is_id:
            code = int(script.rng.integers(0, len(WATCHDOG_CLOCKS)))
            script.id_cycle(wire.command_word(code, bool(script.rng.integers(0, 2))), flips=flips, latch=latch)
        else:
            script.data_cycle(extra=extra, flips=flips, latch=latch)
    bench.run_batch(script.stimulus())


@settings(max_examples=20, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    how=st.sampled_from(["line", "resu_n", "vmon_ok"]),
    at=st.floats(0, 1),
    hold=st.integers(1, 400),
)
def test_reset_in_the_middle_of_a_cycle(bench: Lockstep, seed: int, how: str, at: float, hold: int) -> None:
    config = fast_config("10000")
    script = CoreScript(config, np.random.default_rng(seed)).bring_up().id_cycle(wire.command_word(2)).data_cycle()
    levels = wire.cycle_levels(Frame.build(Cycle.DATA, LOOPBACK + b"\x5a"), 1, True)
    script.line(levels[: int(at * len(levels))])
    if how == "line":
        script.line(wire.reset_levels(1)).line(IDLE)
    else:
        script.line(np.ones(hold, dtype=np.uint8), **{how: 0}).line(IDLE, **{how: 1}).bring_up()
    bench.run_batch(script.id_cycle(wire.command_word()).data_cycle().data_cycle().stimulus())


@pytest.mark.parametrize("seed", range(3))
def test_the_start_from_any_input_levels(bench: Lockstep, seed: int) -> None:
    # M23: no reset edge before cycle 0, the synchronisers, the clock count and the power-up stretch without reset:
    # the RTL starts from its initial values as the model from reset(). Random levels on every input for the first
    # clocks (a power failure, the start level, /StatErr low among them; MFP[15..12] stay the straps) reach the
    # synchronisers' last stage at the same clocks in both; then the chip comes up and runs a cycle.
    rng = np.random.default_rng(60 + seed)
    config = fast_config("10000")
    stimulus = CoreScript(config, rng).bring_up().id_cycle(wire.command_word(2)).data_cycle().stimulus()
    first = int(rng.integers(1, 8))
    for column, name in enumerate(CORE_INPUTS):
        stimulus[:first, column] = rng.integers(0, 0x1000 if name == "mfp_in" else 2, first)
    bench.run_batch(stimulus)


def test_staterr_short_and_quit(bench: Lockstep) -> None:
    script = CoreScript(fast_config("10000"), np.random.default_rng(5)).bring_up()
    script.data_cycle(stat_err_n=0).id_cycle(wire.command_word(quit_peripheral_error=True))
    script.data_cycle(stat_err_n=1).id_cycle(wire.command_word(quit_peripheral_error=True)).data_cycle()
    bench.run_batch(script.stimulus())


def test_following_device_and_rbst(bench: Lockstep) -> None:
    for rf in RF_VALUES:
        config = decode("10000", rf=rf, clk_conf="11", diag_conf=0)
        script = CoreScript(config, np.random.default_rng(9)).bring_up().data_cycle()
        script.line(IDLE, rbst_ext=1).data_cycle(di2=1).line(IDLE, rbst_ext=0, di2=0).data_cycle()
        bench.run_batch(script.stimulus())


# Other paths --------------------------------------------------------------------------------------------------------


def test_per_cycle_path(bench: Lockstep) -> None:
    script = CoreScript(fast_config("11011", "0011"), np.random.default_rng(3)).bring_up()
    result = bench.run(script.id_cycle(wire.command_word(1)).data_cycle().stimulus())
    assert result.cycles > 5000


def test_amaranth_simulator_path() -> None:
    script = CoreScript(fast_config("10000"), np.random.default_rng(4)).line(IDLE).line(wire.reset_levels(1))
    result = run_amaranth_sim(
        functools.partial(Supi3Core, "opc"), functools.partial(StrapPins, "opc"), script.stimulus(), max_cycles=1500
    )
    assert result.cycles == 1500


# Long scenarios: batch replay chunk by chunk against the model's run() ------------------------------------------------


def _chunks(n: int, size: int = 1 << 20) -> Iterator[slice]:
    for start in range(0, n, size):
        yield slice(start, min(n, start + size))


def long_lockstep(bench: Lockstep, config: DeviceConfig, inputs: Columns, directory: Path) -> Columns:
    """Replay ``inputs`` through the batch executable and compare with ``Supi3Pins(config).run``; return the
    (matching) model outputs. The RTL replays in its own process while the model runs here, as
    :meth:`~supi3.verif.Lockstep.run_batch` does (millions of clocks each)."""
    n = len(inputs["do1"])
    layout = bench.layout
    source, sink = directory / "inputs.bin", directory / "outputs.bin"
    with source.open("wb") as stream:
        for part in _chunks(n):
            block = np.stack([inputs[name][part] for name in CORE_INPUTS], axis=1)
            stream.write(layout.input_words(strap_stimulus(config, block)).astype("<u4").tobytes())
    command = [str(bench.batch_executable()), str(source), str(sink), str(n), str(bench.reset_cycles)]
    process = subprocess.Popen(command)
    try:
        expected = Supi3Pins(config).run(inputs)
    finally:
        status = process.wait()
    if status != 0:
        raise subprocess.CalledProcessError(status, command)
    words = np.fromfile(sink, dtype="<u4").reshape(n, layout.out_words)
    for part in _chunks(n):
        actual = layout.output_trace(words[part])
        model = np.stack([expected[name][part] for name in layout.output_names], axis=1).astype(np.uint64)
        found = first_mismatch(layout, model, actual)
        if found is not None:
            cycle, signal = found
            name = layout.output_names[signal]
            pytest.fail(
                f"cycle {part.start + cycle}: {name} expected {model[cycle, signal]}, RTL {actual[cycle, signal]}"
            )
    return expected


def test_staterr_filter_and_quit(bench: Lockstep, tmp_path: Path) -> None:
    # /StatErr low from the start, a power-up reset in between (the filter restarts), the fault latched after 200 ms,
    # shown in the ID register and on IB_DIAG (fast flashing from clock 2**23), then Quit Peripheral Error twice.
    config = fast_config("10000")
    start = CoreScript(config).bring_up().id_cycle(wire.command_word()).data_cycle().columns()
    flash = 1 << (IB_DIAG_DIVIDER_BITS["fast"] - 1)
    idle = quiet_inputs(flash + 50_000 - len(start["do1"]))
    idle["resu_n"][300_000:300_100] = 0
    end = CoreScript(config).bring_up().id_cycle(wire.command_word(quit_peripheral_error=True), stat_err_n=0)
    end.line(IDLE, stat_err_n=1).id_cycle(wire.command_word(quit_peripheral_error=True)).id_cycle(0)
    parts = [start, idle, end.columns()]
    inputs = {name: np.concatenate([part[name] for part in parts]) for name in CORE_INPUTS}
    inputs["stat_err_n"][1000 : len(start["do1"]) + len(idle["do1"])] = 0
    long_lockstep(bench, config, inputs, tmp_path)


def test_watchdog_expiry(bench: Lockstep, tmp_path: Path) -> None:
    # Watchdog 50 ms, one latched data cycle, then only idle status telegrams (no idle time-out) past the deadline:
    # process data reset, /ResReg pulse, WD reported in the next ID cycle.
    config = fast_config("10000")
    script = CoreScript(config, np.random.default_rng(8)).bring_up().id_cycle(wire.command_word(0)).data_cycle()
    telegrams = WATCHDOG_LATEST // (wire.STATUS_TELEGRAM_BITS * wire.clocks_per_bit(config.bit_rate))
    script.line(wire.status_levels(Cycle.DATA, False, telegrams + 100)).id_cycle(wire.command_word())
    expected = long_lockstep(bench, config, script.columns(), tmp_path)
    assert [length for _, length in pulses(expected["res_reg_n"])] == [12]  # 375 ns (Table 3-13), RTL alike


def test_watchdog_expiry_clears_the_serial_outputs(bench: Lockstep, tmp_path: Path) -> None:
    # SPI master mode (RB, SPI 16 OUT, Table 2-6): the watchdog's reset of process data runs the clear sequence (a
    # write frame of zeros and /Conv, SM-9) in the RTL as in the model; /SS frames: the INTERBUS reset's clear
    # sequence, the data cycle's write, the watchdog's clear sequence.
    config = fast_config("10011", "1001")
    script = CoreScript(config, np.random.default_rng(9)).bring_up().id_cycle(wire.command_word(0)).data_cycle()
    telegrams = WATCHDOG_LATEST // (wire.STATUS_TELEGRAM_BITS * wire.clocks_per_bit(config.bit_rate))
    script.line(wire.status_levels(Cycle.DATA, False, telegrams + 100))
    expected = long_lockstep(bench, config, script.columns(), tmp_path)
    ss_n = (expected["mfp_out"] >> 5) & 1
    assert np.count_nonzero(np.diff(ss_n) == -1) == 3


def test_mod_ack_pulse_width(bench: Lockstep, tmp_path: Path) -> None:
    # Quit Peripheral Error twice: /ModAck pulses 12 clocks each time (M3: the 375 ns of Table 3-13), RTL alike.
    config = fast_config("10000")
    script = CoreScript(config, np.random.default_rng(12)).bring_up()
    script.id_cycle(wire.command_word(quit_peripheral_error=True)).data_cycle()
    script.id_cycle(wire.command_word(quit_peripheral_error=True))
    expected = long_lockstep(bench, config, script.columns(), tmp_path)
    assert [length for _, length in pulses(expected["mod_ack_n"])] == [12, 12]


# Diagnostic outputs (3.6.1, Tables 3-16 to 3-19, 2-8; docs/assumptions/diagnostics.md) --------------------------------


@pytest.mark.parametrize("c", ["01000", "11100", "10000", "00000", "00100"])
@pytest.mark.parametrize("diag_conf", [0, 1])
def test_diagnostics_by_diag_conf(bench: Lockstep, c: str, diag_conf: int) -> None:
    # DIAG1/DIAG2 (BA/RD or FO1/FO2), IB_DIAG, /ResReg and a bus terminal module's MFP LEDs in LB, LBD, RB and BK
    # modes, through a reset pattern in the middle of a frame and a discarded cycle.
    config = decode(c, clk_conf="11", diag_conf=diag_conf)
    script = CoreScript(config, np.random.default_rng(21)).bring_up().data_cycle().id_cycle(wire.command_word(1))
    levels = wire.cycle_levels(Frame.build(Cycle.DATA, LOOPBACK + b"\x5a"), 1, True)
    script.line(levels[: len(levels) // 2]).line(wire.reset_levels(1)).line(IDLE)
    bench.run_batch(script.data_cycle(latch=False).data_cycle().stimulus())


def test_idle_timeout_diagnostics(bench: Lockstep, tmp_path: Path) -> None:
    # DG-3, DG-4: the line falls silent after a latched data cycle: /ResReg low (RC off) from the idle time-out
    # until the master's reset pattern; in the LB mode IB_DIAG flashes at 4 Hz (low from clock 2**22); RTL alike.
    # (8 M clocks: one mode only. The remote bus's slow flashing instead is in test_model_pins_diag.py and, for the
    # RTL block, test_rtl_diag.py.)
    config = fast_config("01000")
    script = CoreScript(config, np.random.default_rng(22)).bring_up().data_cycle()
    start = len(script.columns()["do1"])
    silence = (1 << IB_DIAG_DIVIDER_BITS["very_fast"]) - start
    script.line(np.ones(silence // wire.clocks_per_bit(config.bit_rate), dtype=np.uint8))
    end = len(script.columns()["do1"])
    expected = long_lockstep(bench, config, script.bring_up().data_cycle().columns(), tmp_path)
    timeout = np.flatnonzero(expected["res_reg_n"] == 0)
    assert timeout.size and timeout[0] > start and timeout[-1] >= end  # low over the rest of the silence
    flash = expected["ib_diag"][timeout[0] : end]
    half = 1 << (IB_DIAG_DIVIDER_BITS["very_fast"] - 1)
    assert not flash[half - timeout[0] :].any()
    assert expected["ib_diag"][-1] == 1  # the bus active again: steady

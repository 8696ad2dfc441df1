"""A bus terminal module's branch data lines in the pin-level chip core (supi3.model.pins.Supi3Pins with
supi3.model.blocks.terminal.BranchLines; manual 2.4, Tables 2-7, 2-8, 2-9; BK-1, BK-2, BK-37): while the branch is
in the data path DO3 (MFP9) carries what the chip would send on DO2 and DO2 repeats the synchronised DI3 (MFP10);
otherwise DO2 is the transmitter's, and DO3 carries the same stream while the interface is live (BK-42: the branch
would be present were a device answering) and idles else. A device answers on the branch once DI3 was at the start
level (BK-37: a pulled-up DI3 never is). Held
against the same scenario without a branch (the chip's logic does not read DI3 beyond this), step() equals run(), and
the RTL core in lockstep (tests/test_rtl_core_branch.py).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.config import decode
from supi3.errors import ArgumentError
from supi3.interbus import wire
from supi3.interbus.wire import BranchControl
from supi3.model.blocks.terminal import ReturnWatch
from supi3.model.bus_terminal import BusTerminal
from supi3.model.pins import Supi3Pins
from supi3.pinout import SYNC_STAGES
from supi3.terminal import BRANCH_SILENCE_CLOCKS, BRANCH_SILENCE_S, DI3_PIN, DO3_PIN, LBST_PIN, branch_present
from support import BK_STRAPS, Columns, CoreScript, assert_run_matches_step
from test_model_pins_recognition import close_loop, line_problems, settled

LBST = 1 << LBST_PIN
LD_PIN = 14  # Table 2-8: LBDA, "local bus disabled"
BRANCH_DELAY = 37
"""Clocks a branch of repeaters takes from DO3 back to DI3 in these scenarios (any will do: DI3 is stimulus)."""


def scenario(interface: str, rf: str, seed: int) -> tuple[CoreScript, Columns]:
    """Frames with the branch on, switched off, on again, an INTERBUS reset; the MFP inputs with LBST high but
    during one data cycle; DI3 at rest (1: nothing attached, the pull-up of BK-41) for the first third, then a device
    returning what DO3 sends (``close_loop`` of tests/test_model_pins_recognition.py). Returns the script and its
    columns with DI3 in."""
    config = decode(BK_STRAPS[interface], rf=rf, clk_conf="11")
    script = CoreScript(config, np.random.default_rng(seed))
    script.pins["mfp_in"] = LBST
    script.bring_up().id_cycle(wire.command_word()).data_cycle(mfp_in=LBST)
    script.id_cycle(wire.command_word(branch=BranchControl.OFF), mfp_in=LBST).data_cycle(mfp_in=LBST)
    script.id_cycle(wire.command_word(branch=BranchControl.ON), mfp_in=LBST).data_cycle(mfp_in=0)
    script.data_cycle(mfp_in=LBST).line(wire.reset_levels(1)).line(wire.status_levels(wire.Cycle.DATA, False, 4))
    script.id_cycle(wire.command_word(), mfp_in=LBST).data_cycle(mfp_in=LBST)
    columns = script.inputs()
    n = len(columns["do1"])
    columns, _ = close_loop(config, columns, np.arange(n) >= n // 3)
    script.parts = [columns]
    return script, script.columns()


CASES = [("BK-RB", "10", 1), ("BK-LB", "11", 2), ("BK-LBD", "00", 3), ("BK-LB", "01", 4)]
"""Every row of Table 2-9 (the RTL lockstep runs them all; the model's step-by-step check the two with recognition)."""


def synced(trace: np.ndarray) -> np.ndarray:
    """What the core's synchroniser gives in each cycle (M1): the input ``SYNC_STAGES`` clocks before, 0 at first."""
    return np.concatenate([np.zeros(SYNC_STAGES, dtype=np.int64), trace[:-SYNC_STAGES]])


@pytest.mark.parametrize(("interface", "rf", "seed"), CASES[1:3])
def test_the_branch_takes_the_data_path(interface: str, rf: str, seed: int) -> None:
    """Against the same scenario with DI3 at rest and LBST low (no branch by Table 2-9): where the branch is in the
    data path (Table 2-9 with LBST and a start level seen on DI3 since the core runs, not switched off: LD dark) DO2
    is the synchronised DI3; elsewhere DO2 is the other run's. DO3 is the other run's DO2 where the interface is
    live (Table 2-9 as if a device answered, LD dark; BK-42), else idle. Each switches between telegrams (BK-47):
    within ``SWITCH_WINDOW`` of a change, idling between the two. All happen, and step() equals run()."""
    _, columns = scenario(interface, rf, seed)
    silent = {**columns, "mfp_in": columns["mfp_in"] & ~LBST | 1 << DI3_PIN}  # never present (Table 2-9)
    pins = Supi3Pins(decode(BK_STRAPS[interface], rf=rf, clk_conf="11"))
    out = assert_run_matches_step(pins, Supi3Pins(pins.config), columns, [0.3, 0.71])
    reference = Supi3Pins(pins.config).run(silent)
    mfp = synced(columns["mfp_in"])
    di3 = mfp >> DI3_PIN & 1
    running = out["resu_drive"] == 0  # no power-up reset after the first: the logic runs from its end on
    seen = np.logical_or.accumulate((di3 == wire.START_LEVEL) & running)
    connected = np.concatenate([[False], seen[:-1]])
    table = np.array([[branch_present(rf, bool(lbst), bool(c)) for c in (0, 1)] for lbst in (0, 1)])
    opened = out["mfp_out"] >> LD_PIN & 1 == 0
    on = table[mfp >> LBST_PIN & 1, connected.astype(np.int64)] & opened
    live = table[mfp >> LBST_PIN & 1, 1] & opened
    assert on.any() and (~on).any() and (live & ~on).any() and (~live).any()
    do3 = out["mfp_out"] >> DO3_PIN & 1
    assert not line_problems(out["do2"], do3, reference["do2"], di3, live, on, pins.cpb)
    assert (~settled(on, pins.cpb)).any()
    assert np.array_equal(out["mfp_out"] & ~(1 << DO3_PIN), reference["mfp_out"] & ~(1 << DO3_PIN))
    np.testing.assert_array_equal(out["di1"], out["do2"])  # no following device: the loop-back takes DO2 (M5)


E_PIN = 13  # Table 2-8: ERROR, "error in connected branch" (BK-11)
COUNT = 5
COUNTER_GAP_BITS = 20
"""Idle bit periods after each counter telegram, as behind a break (BK-30: one every 33 bit periods); twice that
before the first, so that a telegram cut by the break leaves no frame open (BK-32)."""


def count_scenario(rf: str, seed: int) -> tuple[CoreScript, list[int]]:
    """BK-LBD: frames with DI3 repeating the forward line (the master's telegrams back); then status requests while
    DI3 brings counter telegrams of :data:`COUNT` (a break in the branch, BK-6); then DI3 repeating again. Returns the
    script (DI3 in) and the cycles where the three stretches begin."""
    config = decode(BK_STRAPS["BK-LBD"], rf=rf, clk_conf="11")
    script = CoreScript(config, np.random.default_rng(seed))
    script.pins["mfp_in"] = LBST
    script.bring_up().id_cycle(wire.command_word()).data_cycle(mfp_in=LBST)
    script.id_cycle(wire.command_word(alarm_request=True), mfp_in=LBST).id_cycle(wire.command_word(), mfp_in=LBST)
    broken = len(script.columns()["do1"])
    script.id_cycle(wire.command_word(alarm_request=True), mfp_in=LBST).id_cycle(wire.command_word(), mfp_in=LBST)
    mended = len(script.columns()["do1"])
    script.data_cycle(mfp_in=LBST).id_cycle(wire.command_word(alarm_request=True), mfp_in=LBST)
    script.id_cycle(wire.command_word(), mfp_in=LBST)
    columns = script.inputs()
    n = len(columns["do1"])
    di3 = np.ones(n, dtype=np.int64)
    di3[BRANCH_DELAY:] = columns["do1"][: n - BRANCH_DELAY]
    levels = np.concatenate([wire.telegram_levels([wire.counter_telegram(COUNT)], wire.DATA_TELEGRAM_BITS),
                             np.ones(COUNTER_GAP_BITS, dtype=np.uint8)])  # fmt: skip
    samples = wire.levels_to_samples(levels, config.bit_rate).astype(np.int64)
    span = mended - broken
    quiet = wire.levels_to_samples(np.ones(2 * COUNTER_GAP_BITS, dtype=np.uint8), config.bit_rate)  # BK-32's flag
    di3[broken:mended] = np.concatenate([quiet, np.tile(samples, span // len(samples) + 1)])[:span]
    columns["mfp_in"] = columns["mfp_in"] & ~(1 << DI3_PIN) | di3 << DI3_PIN
    script.parts = [columns]
    return script, [broken, mended]


COUNT_CASES = [("00", 5), ("10", 6)]


@pytest.mark.parametrize(("rf", "seed"), COUNT_CASES[:1])
def test_the_bk_counts_on_di3(rf: str, seed: int) -> None:
    """BK-39, BK-38: the counter block on DI3 gives the BK its count (E lit, the count in the BK state) while the
    counter telegrams come; the master's telegrams back on DI3 clear it (E dark again); step() equals run()."""
    script, (broken, mended) = count_scenario(rf, seed)
    columns = script.columns()
    pins = Supi3Pins(script.config)
    out = assert_run_matches_step(pins, Supi3Pins(script.config), columns, [0.4, 0.55, 0.8])
    e = out["mfp_out"] >> E_PIN & 1
    assert not e[:broken].any() and e[broken:mended].any() and not e[-1]
    lit = np.flatnonzero(e)
    assert lit[-1] - lit[0] + 1 == len(lit) and lit[-1] < mended + 20 * pins.cpb  # one stretch, ended by traffic
    bulk = Supi3Pins(script.config)
    bulk.run({name: trace[:mended] for name, trace in columns.items()})
    assert bulk.chip.bus_terminal is not None and bulk.chip.bus_terminal.count == COUNT
    # TL == pin: the transaction-level BK given the same stretches ends in the same state.
    tl = BusTerminal("BK-LBD", rf)
    tl.inputs(LBST)
    tl.command(BranchControl.NONE, False)
    tl.returned(True, None, 0.0, 0.001)
    tl.returned(False, COUNT, 0.001, 0.002)
    assert bulk.chip.bus_terminal.state == tl.state


SHORT_SILENCE = 3000
"""A silence limit in clocks for the model alone (BK-3's 10 ms is 320,000: the RTL lockstep runs that one)."""


def silence_scenario(limit_frames: int, seed: int, extra: int = 0, shift: int = 0) -> tuple[CoreScript, int]:
    """BK-LB, RF = 10, LBST high: the extended function switched on; frames with DI3 repeating the forward line; then
    DI3 silent at the idle level for ``limit_frames`` data cycles (each ``extra`` bytes longer than the BK's, after
    ``shift`` bit periods of idle line: the silence runs out at another point of a cycle); a status request and the
    branch switched on again. Returns the script (DI3 in) and the cycle DI3 falls silent."""
    config = decode(BK_STRAPS["BK-LB"], rf="10", clk_conf="11")
    script = CoreScript(config, np.random.default_rng(seed))
    script.pins["mfp_in"] = LBST
    script.bring_up().id_cycle(wire.command_word(branch=BranchControl.ON_EXTENDED), mfp_in=LBST)
    script.data_cycle(mfp_in=LBST).data_cycle(mfp_in=LBST).data_cycle(mfp_in=LBST)
    silent = len(script.columns()["do1"])
    if shift:
        script.line(np.ones(shift, dtype=np.uint8))
    for _ in range(limit_frames):
        script.data_cycle(extra, mfp_in=LBST)
    script.id_cycle(wire.command_word(alarm_request=True), mfp_in=LBST).id_cycle(wire.command_word(), mfp_in=LBST)
    script.id_cycle(wire.command_word(branch=BranchControl.ON, quit_peripheral_error=True), mfp_in=LBST)
    columns = script.inputs()
    n = len(columns["do1"])
    di3 = np.ones(n, dtype=np.int64)
    di3[BRANCH_DELAY:silent] = columns["do1"][: silent - BRANCH_DELAY]
    columns["mfp_in"] = columns["mfp_in"] & ~(1 << DI3_PIN) | di3 << DI3_PIN
    script.parts = [columns]
    return script, silent


def frame_ends(pins: Supi3Pins, columns: Columns) -> npt.NDArray[np.int64]:
    """The cycles of ``columns`` whose edge completes a frame's check sequence in the frame engine of ``pins``
    (``frame_end`` of the BK, BK-50), stepped."""
    names = list(columns)
    checks = []
    for values in zip(*(columns[name].tolist() for name in names), strict=True):
        checks.append(pins._frame.checks)
        pins.step(dict(zip(names, values, strict=True)))
    checks.append(pins._frame.checks)
    return np.flatnonzero(np.diff(checks))


def test_the_extended_function_closes_a_silent_branch() -> None:
    """BK-3, BK-20, BK-38, BK-50 at pin level: while the master's telegrams come back the branch stays open; silent,
    the silence restarts at the first frame's end after the last telegram back and the BK closes the branch at the
    first frame's end by which it has lasted the limit (LD lit, DO2 the transmitter's again, the report and ATTN
    waiting); the master's command switching it on reopens it; step() equals run()."""
    script, silent = silence_scenario(4, 7)
    columns = script.columns()

    def make() -> Supi3Pins:
        return Supi3Pins(script.config, branch_silence=SHORT_SILENCE)

    pins = make()
    out = assert_run_matches_step(pins, make(), columns, [0.35, 0.6, 0.9])
    ld = out["mfp_out"] >> LD_PIN & 1
    lit = np.flatnonzero(ld)
    # The last status telegram's stop bit is sampled mid-bit on the synchronised DI3, the watch strobes one clock
    # later (BK-38): the return line was heard; the next frame's end restarts the silence, the first frame's end
    # SHORT_SILENCE clocks or more after that closes the branch, LD shows from the next clock.
    heard = silent + BRANCH_DELAY + SYNC_STAGES - pins.cpb // 2 + 1
    ends = frame_ends(make(), columns)
    restart = ends[ends > heard][0]
    closing = ends[ends >= restart + SHORT_SILENCE][0]
    assert closing > restart + SHORT_SILENCE  # the silence ran out between two frames' ends: it waited
    assert lit.size and lit[0] == closing + 1
    assert not ld[-1] and lit[-1] - lit[0] + 1 == len(lit)
    closed = out["do2"][lit[0] : lit[-1]]
    assert closed.any()  # the transmitter's again, not the silent DI3's idle level only
    terminal = pins.chip.bus_terminal
    assert terminal is not None and terminal.closures == 1 and not terminal.closed
    bulk = make()
    bulk.run({name: trace[: lit[0] + 1] for name, trace in columns.items()})
    assert bulk.chip.bus_terminal is not None and bulk.chip.bus_terminal.closed_report and bulk.chip.attention
    # TL == pin: the transaction-level BK through the same operations ends in the same state.
    tl = BusTerminal("BK-LB", "10")
    tl.inputs(LBST)
    tl.command(BranchControl.ON_EXTENDED, False)
    tl.returned(True, None, 0.0, 0.001, 0.0005)
    tl.returned(False, None, 0.001, 0.002, 0.0015)
    assert tl.returned(False, None, 0.002, 0.002 + BRANCH_SILENCE_S, 0.0015 + BRANCH_SILENCE_S)
    assert bulk.chip.bus_terminal.state == tl.state


@pytest.mark.parametrize("limit", [0, -1, BRANCH_SILENCE_CLOCKS + 1, 2.5, "3000", None])
def test_a_bad_silence_limit_is_named(limit: object) -> None:
    with pytest.raises(ArgumentError, match="branch_silence must be"):
        Supi3Pins(decode(BK_STRAPS["BK-LB"], clk_conf="11"), branch_silence=limit)  # type: ignore[arg-type]


@settings(max_examples=60, deadline=None, derandomize=True)
@given(st.lists(st.tuples(st.integers(0, 1), st.integers(1, 40)), min_size=1, max_size=60), st.integers(0, 400),
       st.sampled_from([16, 64]))  # fmt: skip
def test_the_watch_scans_as_it_clocks(runs: list[tuple[int, int]], split: int, cpb: int) -> None:
    """BK-47's telegram grid on a run (``ReturnWatch.scan``, telegram by telegram) is the clock-by-clock watch's
    (``ReturnWatch.clock``): ``busy`` before each clock and the state after, on any line (glitches, start bits read
    idle, telegrams cut at the end), continued from any state (the line split anywhere)."""
    line = np.repeat([level for level, _ in runs], [length for _, length in runs]).astype(np.int64)
    split = min(split, len(line))
    stepped, scanned = ReturnWatch(), ReturnWatch()
    busy = []
    for level in line.tolist():
        busy.append(stepped.busy)
        stepped.clock(level, cpb)
    got = np.concatenate([scanned.scan(line[:split], cpb), scanned.scan(line[split:], cpb)])
    np.testing.assert_array_equal(got, busy)
    assert (scanned.bit, scanned.data) == (stepped.bit, stepped.data)
    assert scanned.bit < 0 or scanned.phase == stepped.phase

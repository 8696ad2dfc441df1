"""The cycles of a chip's wake-up window that the transaction level follows by the chip's own core and the master's
receiver (M28, M29 of docs/assumptions/model.md, BK-64 of docs/assumptions/bus-terminal.md; manual 1.7.2, 2.4):
a woken chip off the telegram grid opens a frame at a misread telegram inside the master's frame and sends its own
bits there (M19: any whole status telegram puts its frame engine on the grid), the master assembles a frame from the
data telegrams that came back alone (status telegrams among them dropped), a woken BK's branch present without an
answer joins nothing, and a break made after a woken BK's start level passed it does not stop that answer. Each case
failed before (issue #12, M25's limit 2, M22's limit 4, the recognition histories' waits).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.errors import ArgumentError
from supi3.interbus import wire
from supi3.interbus.ring import BranchKind, ErrorKind
from supi3.interbus.wake import wake_return
from supi3.interbus.wire import Cycle, Frame, Telegram
from supi3.model.chip import Supi3
from supi3.model.pins import Supi3Pins
from test_model_pinring_powerup import RATES, _config, both
from test_model_pinring_recognition import TELEGRAM_S, recognition_history
from test_model_pinring_tree import CASES
from test_model_pinring_tree_powerup import after_power_up, trees


@pytest.mark.parametrize("kind", [BranchKind.REMOTE, BranchKind.LBD_OR])
@pytest.mark.parametrize("k", [0, 1])
def test_a_woken_chip_that_opens_a_frame_inside_the_master_s_fails_it_alike(kind: BranchKind, k: int) -> None:
    """M28 (M25's limit 2): the device behind a BK-RB or LBD-OR branch woken right before a cycle at 2 Mbit/s; off
    the grid it reads a status telegram inside the frame, then opens a frame at a misread data telegram and sends its
    register's bits in the frame's last check telegram: the master gets 3 of 4 check telegrams and a telegram error,
    a dead line at both fidelities (before: ``LOOPBACK`` at transaction level, the frame repeated whole)."""
    m = next(m for case, m in CASES if case is kind)
    tl, pin = trees(kind, m, 2_000_000)
    seen = after_power_up(tl, m + 3, k)
    assert seen == after_power_up(pin, m + 3, k)
    assert seen[0][1] == [ErrorKind.DEAD_LINE]


@pytest.mark.parametrize(("rate", "wake", "phase"), [(500_000, 0, 2), (2_000_000, 1, 1)])
def test_the_master_assembles_a_frame_from_its_data_telegrams_at_both_fidelities(rate: int, wake: int,
                                                                                 phase: int) -> None:
    """M29 (M22's limit 4): the third of three chips powered up ``phase`` bit periods into an idle status telegram:
    what comes back in the first data cycle holds a data telegram, status telegrams, the check telegrams; the pin
    level's master assembles a frame of the data telegrams (a telegram error: ``TELEGRAM``), and so does the
    transaction level's now (``wire.returned_frame``; before, the status telegrams broke the frame: a dead line)."""
    tl, pin = both(rate, 3, True, [("power", 3)], wake, phase)
    assert tl == pin
    assert tl[1] == (Cycle.DATA, False, [(ErrorKind.TELEGRAM, None, None, None)])


def test_returned_frame_takes_the_data_telegrams() -> None:
    """``wire.returned_frame``: status telegrams and line resets among the data telegrams are dropped; no opening
    telegram, no frame; bad input named."""
    frame = Frame.build(Cycle.DATA, b"\x5a\x3c\x11")
    telegrams = wire.parse_levels(wire.frame_levels(frame))
    status = Telegram(Cycle.DATA, False, None)
    assert wire.returned_frame([status, telegrams[0], status, *telegrams[1:]]) == frame
    assert wire.returned_frame([status, status]) is None
    with pytest.raises(ArgumentError, match="telegrams"):
        wire.returned_frame(b"\x00")  # type: ignore[arg-type]


def test_a_woken_chip_s_core_is_followed_only_where_its_line_alone_decides() -> None:
    """M28: ``Supi3.woken_output`` runs the chip's core over a forward line from its power-up (silent until its
    stretch ends and its receiver begins a telegram, M12); a BK or an LBD chip gives ``None``; ``wake_return``
    refuses chips of indices not woken."""
    chip = Supi3(_config(2_000_000))
    chip.set_mfp_inputs(0x33)
    levels = np.concatenate([wire.status_levels(Cycle.DATA, False, 2),
                             wire.frame_levels(Frame.build(Cycle.DATA, b"\x5a\x3c\x81")), wire.status_levels(
                                 Cycle.DATA, False, 4)])  # fmt: skip
    do1 = wire.levels_to_samples(levels, 2_000_000).astype(np.int64)[37:]  # woken inside a telegram
    out = chip.woken_output(do1)
    assert out is not None and out[:128].min() == wire.IDLE_LEVEL and out.min() == wire.START_LEVEL
    n = len(do1)
    quiet = {"di2": 0, "rbst_ext": 0, "mfp_in": 0x33, "stat_err_n": 1, "resu_n": 1, "vmon_ok": 1, "from_exr": 0}
    pins = Supi3Pins(_config(2_000_000)).run_forward(
        {"do1": do1, **{name: np.full(n, value, dtype=np.int64) for name, value in quiet.items()}})
    assert np.array_equal(out, pins["do2"])  # the same blocks as the pin-level core
    for kind, index in ((BranchKind.REMOTE, 1), (BranchKind.LBD_OR, 2)):  # the BK; the LBD-OR branch's device
        device = trees(kind, 1, 2_000_000)[0].devices[index]
        assert isinstance(device, Supi3) and device.woken_output(np.ones(64, dtype=np.int64)) is None
    frame = Frame.build(Cycle.DATA, b"\x5a\x3c")
    with pytest.raises(ArgumentError, match="chips"):
        wake_return(2_000_000, 2, {0: 128}, 0, frame, None, {1: chip})


POWER = [("start", 0), ("power", 0), ("cycle", 0), ("cycle", 0), ("cycle", 0)]
OFF_POWER = [("start", 0), ("off", 0), ("power", 0), ("cycle", 0), ("on", 0), ("cycle", 0), ("cycle", 0)]
CUT_FIRST = [("cut", 0), ("start", 0), ("repair", 0), ("cycle", 0)]


@pytest.mark.parametrize(("ops", "rf", "initial"), [(POWER, "10", False), (OFF_POWER, "10", False),
                                                    (CUT_FIRST, "11", True)])  # fmt: skip
def test_a_woken_bk_s_branch_answers_alike(ops: list[tuple[str, int]], rf: str, initial: bool) -> None:
    """BK-64 in the recognition histories (BK-RB, LBST = 1): with RF = 10 the branch is in the data path without an
    answer, so the woken BK's DO2 repeats DI3 from its wake-up and its answer joins nothing (before: the transaction
    level lost the cycle with ``TRANSMISSION``, 1 and 2 idle telegrams after the power-up); every chip powered up at the
    first clock (RF = 11) and the branch's first line cut 3 or 4 idle telegrams later, the BK's start level has passed
    the line: its branch answers, recognised at both (before: at pin level only)."""
    for k in (3, 4) if initial else (1, 2):
        first, power = (k, 20) if initial else (20, k)
        for tl, pin in recognition_history(BranchKind.REMOTE, (rf, True), ops, first * TELEGRAM_S,
                                           power * TELEGRAM_S):
            assert tl == pin, k


@settings(max_examples=8, deadline=None, derandomize=True)  # about 1 s an example: pin level is slow
@given(st.sampled_from(RATES), st.integers(1, 3), st.booleans(),
       st.lists(st.tuples(st.sampled_from(["power", "cut", "repair", "wait"]), st.integers(1, 3)), min_size=1,
                max_size=3),
       st.integers(0, 7), st.integers(1, 4))
def test_power_ups_off_the_telegram_grid_and_cuts_fail_alike(rate: int, chips: int, start: bool,
                                                             ops: list[tuple[str, int]], wake: int, phase: int) -> None:
    """M22's limits 3 and 4, M29: any history of power-ups released ``phase`` bit periods into an idle status
    telegram, cuts and repairs of a flat ring, ``wake`` idle telegrams after each power-up: every cycle alike at both
    fidelities (``bench/wake_flat_sweep.py phase`` and ``faults`` sweep them exhaustively)."""
    tl, pin = both(rate, chips, start, ops, wake, phase)
    assert tl == pin


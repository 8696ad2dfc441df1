"""A bus terminal module's branch data lines in the RTL core (supi3.rtl.core.Supi3Core; manual 2.4, Tables 2-7,
2-8, 2-9; BK-1, BK-37): the scenarios of tests/test_model_pins_branch.py (DI3 silent, then repeating the forward
line; the branch switched off and on; LBST low for a data cycle; an INTERBUS reset) in lockstep with the pin-level
model, every pin every clock: DO3 on MFP9 (while live, BK-42), DO2 repeating DI3, the loop-back, `connected` from the
first start level on DI3 (BK-37), also over histories of attaching and detaching the branch's device; and in BK-LBD
the count from counter telegrams on DI3, cleared by the master's telegrams back (the status byte, E); the extended
function closing a branch silent for 10 ms.
"""

from __future__ import annotations

import numpy as np
import pytest

from supi3.interbus import wire
from supi3.model.pins import Supi3Pins
from supi3.pinout import SYNC_STAGES
from supi3.terminal import BRANCH_SILENCE_CLOCKS
from supi3.verif import Lockstep
from support import CoreScript
from test_model_pins_branch import (
    BRANCH_DELAY,
    CASES,
    COUNT_CASES,
    LD_PIN,
    count_scenario,
    scenario,
    silence_scenario,
)
from test_model_pins_recognition import FIXED, RANDOM_SEEDS, close_loop, history, random_history


@pytest.mark.parametrize(("interface", "rf", "seed"), CASES)
def test_rtl_core_matches(bench: Lockstep, interface: str, rf: str, seed: int) -> None:
    script, _ = scenario(interface, rf, seed)
    bench.run_batch(script.stimulus())


@pytest.mark.parametrize(("interface", "rf", "ops"), [*FIXED, *map(random_history, RANDOM_SEEDS)])
def test_rtl_core_recognises_as_the_model(bench: Lockstep, interface: str, rf: str, ops: list[tuple[str, int]]) -> None:
    """BK-37, BK-42: histories of attaching and detaching the branch's device (DI3 its answer or the pull-up), LBST
    changes, INTERBUS and power-up resets: ``connected`` from the first start level on DI3, DO3 while live, DO2 in
    the data path, every pin every clock (the DI3 the model's loop gave, tests/test_model_pins_recognition.py)."""
    config, columns, device = history(interface, rf, ops)
    closed, _ = close_loop(config, columns, device)
    script = CoreScript(config)
    script.parts = [closed]
    bench.run_batch(script.stimulus())


@pytest.mark.parametrize(("rf", "seed"), COUNT_CASES)
def test_rtl_core_counts(bench: Lockstep, rf: str, seed: int) -> None:
    """BK-LBD: the counter block on DI3 and the return watch give the BK its count and clear it (BK-38, BK-39)."""
    script, _ = count_scenario(rf, seed)
    bench.run_batch(script.stimulus())


@pytest.mark.slow
@pytest.mark.parametrize("extra", [0, 1])
def test_rtl_core_closes_a_silent_branch(bench: Lockstep, extra: int) -> None:
    """BK-3 with its 10 ms (320,000 clocks): the extended function closes the silent branch in the RTL core at the
    model's clock (LD, ATTN, the status byte's bit 6), and the master's command reopens it. With frames one byte
    longer (``extra``) the silence runs out within a frame and the closure waits for its end (BK-50; measured with
    the model: 331 clocks later than without the wait), in the RTL core too."""
    script, silent = silence_scenario(BRANCH_SILENCE_CLOCKS // 2000 + 3, 8, extra)
    bench.run_batch(script.stimulus())
    out = Supi3Pins(script.config).run(script.columns())
    assert (out["mfp_out"][silent + BRANCH_SILENCE_CLOCKS + 100 :] >> LD_PIN & 1).any()


FIRST_TELEGRAM_SHIFT = 127
"""Idle bit periods before the silent frames of :func:`silence_scenario` that make BK-3's 10 ms run out while the BK's
transmitter repeats the first data telegram of a frame its frame engine does not hold yet (found with the model; the
test checks it)."""


@pytest.mark.slow
def test_rtl_core_closure_waits_for_a_frame_whose_first_telegram_is_under_way(bench: Lockstep) -> None:
    """BK-50 with its 10 ms (the core's limit, no second build): the silence runs out while the receiver is in the
    first data telegram of a frame and the transmitter repeats it already (the receiver's ``repeating``), before the
    frame engine takes the frame: the closure waits for the frame's end in the RTL core as in the model, every pin
    every clock, so the frame is not cut at its head."""
    script, silent = silence_scenario(BRANCH_SILENCE_CLOCKS // 2000 + 3, 8, shift=FIRST_TELEGRAM_SHIFT)
    columns = script.columns()
    model = Supi3Pins(script.config)
    due = silent + BRANCH_DELAY + SYNC_STAGES - model.cpb // 2 + 1 + BRANCH_SILENCE_CLOCKS
    model.run({name: trace[:due] for name, trace in columns.items()})
    assert model._receiver.repeating_data and not model._frame.framing  # the case: the frame's first telegram
    bench.run_batch(script.stimulus())
    out = Supi3Pins(script.config).run(columns)
    lit = np.flatnonzero(out["mfp_out"] >> LD_PIN & 1)
    assert lit.size and lit[0] > due + wire.DATA_TELEGRAM_BITS * model.cpb  # closed after the frame, not at due


@pytest.fixture(scope="session")
def bench(core_bench: Lockstep) -> Lockstep:
    return core_bench  # tests/conftest.py: one build, shared with tests/test_rtl_core.py

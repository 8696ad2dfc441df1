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

from supi3.model.pins import Supi3Pins
from supi3.terminal import BRANCH_SILENCE_CLOCKS
from supi3.verif import Lockstep
from support import CoreScript
from test_model_pins_branch import (
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


SHIFT = 127
"""Idle bit periods before the silent frames of :func:`silence_scenario` that move BK-3's 10 ms to another point of a
cycle (before BK-50's rule, into the first data telegram of a frame)."""


@pytest.mark.slow
@pytest.mark.parametrize(("extra", "shift"), [(0, 0), (1, 0), (0, SHIFT)])
def test_rtl_core_closes_a_silent_branch(bench: Lockstep, extra: int, shift: int) -> None:
    """BK-3 with its 10 ms (320,000 clocks): the extended function closes the silent branch in the RTL core at the
    model's clock (LD, ATTN, the status byte's bit 6), at the end of a frame (BK-50: the edge completes the frame
    engine's check sequence), and the master's command reopens it. Frames one byte longer (``extra``) or the silent
    frames ``shift`` idle bit periods later put the silence's end at other points of a cycle."""
    script, silent = silence_scenario(BRANCH_SILENCE_CLOCKS // 2000 + 3, 8, extra, shift)
    bench.run_batch(script.stimulus())
    columns = script.columns()
    out = Supi3Pins(script.config).run(columns)
    lit = np.flatnonzero(out["mfp_out"] >> LD_PIN & 1)
    assert lit.size and lit[0] > silent + BRANCH_SILENCE_CLOCKS
    model = Supi3Pins(script.config)
    model.run({name: trace[: lit[0] - 1] for name, trace in columns.items()})
    checks = model._frame.checks
    model.run({name: trace[lit[0] - 1 : lit[0]] for name, trace in columns.items()})
    assert model._frame.checks == checks + 1  # the edge that closed the branch ended a frame's check sequence


@pytest.fixture(scope="session")
def bench(core_bench: Lockstep) -> Lockstep:
    return core_bench  # tests/conftest.py: one build, shared with tests/test_rtl_core.py

"""Lockstep of the optical block's RTL (supi3.rtl.optical.OpticalRtl) against its pin model
(supi3.model.blocks.optical.OpticalBlock), every output every clock, on Amaranth's simulator
(supi3.verif.amaranth_sim; issue 12).

Directed cases for every transition of manual 1.6 (13 steps, "Light on" at the first step at MAX -> MAU, NONE ->
FIXED, the 6 ms timeout, DECREASE_AFTER, the MAU hysteresis, optical diagnostics, lengths at both bit rates and
media, INTERBUS resets, the unused codes of OPT-23), each also checked to reach the state it is about; and random
strobes (hypothesis, the seeded profile of tests/conftest.py) in every mode, at both bit rates, with INTERBUS resets
in the middle.
"""

from __future__ import annotations

import inspect

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.model.blocks.optical import OpticalBlock
from supi3.optical.regulation import (
    INIT_MAX_STEPS,
    INIT_TIME_LIMIT_CLOCKS,
    MAX_LEVEL,
    Interface,
    OpticalMode,
    Phase,
    Response,
    Transmitter,
)
from supi3.rtl.optical import OpticalRtl
from supi3.verif.amaranth_sim import run_amaranth_sim
from support import OpticalScript, run_optical

IN, OUT, BRANCH = Interface.IN, Interface.OUT, Interface.BRANCH
REG, DIAG = OpticalMode.REGULATION, OpticalMode.DIAGNOSTIC


def lockstep(script: OpticalScript) -> OpticalBlock:
    """The script on the RTL and the model, compared every clock; the model after it."""
    rows = script.rows
    assert run_amaranth_sim(OpticalRtl, OpticalBlock, rows).cycles == len(rows)
    return run_optical(rows)[0]


def initialize(script: OpticalScript, interface: Interface, lowerings: int) -> OpticalScript:
    for _ in range(lowerings):
        script.response(interface, Response.DETECTED)
    return script.response(interface, Response.NOT_DETECTED)


def test_thirteen_steps() -> None:
    """1.6.1: 13 lowerings end the initialization at level 2; the others fall back on NONE."""
    script = OpticalScript(REG).reset()
    for _ in range(INIT_MAX_STEPS):
        script.response(OUT, Response.DETECTED).idle(2)
    block = lockstep(script.response(IN, Response.NONE).response(BRANCH, Response.NONE).idle(3))
    assert block.status[OUT] == Transmitter(Phase.ONLINE, MAX_LEVEL - INIT_MAX_STEPS)
    assert block.status[IN] == block.status[BRANCH] == Transmitter(Phase.FIXED)


def test_light_on_at_the_first_step_warns() -> None:
    """1.6.3: "Light on" at MAX gives MAU at once; FO in READY (FIXED) and RUN (MAU)."""
    script = OpticalScript(REG).reset().response(BRANCH, Response.NOT_DETECTED).response(IN, Response.NONE)
    block = lockstep(script.idle(2, run=1).idle(2))
    assert block.status[BRANCH] == Transmitter(Phase.ONLINE, MAX_LEVEL, mau=True)


def test_decrease_after_and_hysteresis_at_both_edges() -> None:
    """1.6.2, OPT-6, 1.6.3: passes lower every DECREASE_AFTER tests; MAU on at 14 -> 15, off at 14 -> 13; the level
    saturates at both ends."""
    script = initialize(OpticalScript(REG, present=0b001).reset(), IN, 2)
    script.test(IN, False, True).test(IN, False, False)  # 14 -> 15 (MAU), stays 15
    for _ in range(4):
        script.test(IN, True, True)  # 15 -> 14 -> 13: MAU off at 13
    script.test(IN, True, False).test(IN, True, True)
    block = lockstep(script.idle(2))
    assert block.status[IN] == Transmitter(Phase.ONLINE, MAX_LEVEL - 2, passes=1)
    script = initialize(OpticalScript(REG, present=0b010).reset(), OUT, INIT_MAX_STEPS - 1)
    for _ in range(2 * MAX_LEVEL):
        script.test(OUT, True, True)
    block = lockstep(script.idle(2))
    assert block.status[OUT].level == 1


def test_diagnostics_mode() -> None:
    """1.6.2, OPT-7, OPT-22: tests move the warning of interfaces in use only."""
    script = OpticalScript(DIAG, present=0b110).reset()
    script.test(OUT, False, True).test(BRANCH, True, False).test(IN, False, False).test(BRANCH, False, False)
    block = lockstep(script.test(BRANCH, True, True).idle(2, run=1))
    assert [tx.mau for tx in block.status.transmitters] == [False, True, False]


@pytest.mark.parametrize("fast", [0, 1])
def test_lengths_media_and_resets(fast: int) -> None:
    """1.6.1, OPT-1, OPT-21, OPT-24: both paths, both media; a reset stops the running timer and keeps the lengths;
    mode 3 is off and resp 3 no response (OPT-23)."""
    script = OpticalScript(REG, fast=fast).reset().length(OUT, 517, 1).length(BRANCH, 93, 0)
    measured = run_optical(script.rows)[0].status.length
    script.idle(len_start=0b100).reset().idle(4, len_stop=0b100).response(IN, 3)
    block = lockstep(script)
    assert block.status.length == measured
    assert 0 not in measured
    assert block.status[IN].phase is Phase.INIT
    block = lockstep(OpticalScript(3, fast=fast).reset().length(OUT, 100).idle())
    assert block.status.length == (0, 0)


@pytest.mark.parametrize("fast", [0, 1])
def test_one_timer_for_both_paths(fast: int) -> None:
    """OPT-57: one timer measures the outgoing interface or the branch: both started at one edge measure the
    outgoing interface (the branch's stop does nothing), a start of the other path abandons the running measurement
    (the first path's stop then does nothing), a start at the edge of a stop measures anew."""
    script = OpticalScript(REG, fast=fast, medium=0b110).reset().length(OUT, 517, 1).length(BRANCH, 1_093, 1)
    measured = run_optical(script.rows)[0].status.length
    script.idle(len_start=0b110).idle(300).idle(len_stop=0b100)  # the branch's stop: not its measurement
    assert run_optical(script.rows)[0].status.length == measured
    script.idle(len_start=0b100).idle(80).idle(len_stop=0b010)  # the outgoing interface's was abandoned
    assert run_optical(script.rows)[0].status.length == measured
    script.idle(len_stop=0b100, len_start=0b010).idle(600).idle(len_stop=0b010)
    block = lockstep(script.idle(2))
    assert block.status.length[0] != measured[0]  # 601 clocks against 517: one more count of 64 clocks
    assert block.status.length[1] != measured[1]  # 82 clocks against 1,093: fewer counts


def test_long_lengths_read_as_the_top_code() -> None:
    """OPT-24: the RTL timer's 12 bits of clocks wrap at 4,096; a stop just before the wrap (the branch, polymer) and
    one just after it (the outgoing interface, glass, which reads 63 only from 4,032 clocks at 2 Mbit/s) read as the
    model's saturating count does, and a start at the edge of such a stop clears the wrap (a short length after)."""
    script = OpticalScript(REG, fast=1, medium=0b010).reset().idle(len_start=0b100).idle(4_093)
    script.idle(len_stop=0b100, len_start=0b010).idle(4_095).idle(len_stop=0b010, len_start=0b010).idle(40)
    assert run_optical(script.rows)[0].status.length == (63, 63)
    block = lockstep(script.idle(len_stop=0b010).idle(2))
    assert block.status.length == (0, 63)


@pytest.mark.parametrize("limit", [1, 2, 300])
def test_initialization_timeout(limit: int) -> None:
    """OPT-5, OPT-56: the incoming interface's budget runs out ``time_limit`` clocks after the start, the branch's
    ``time_limit`` clocks after that. Both sides are elaborated with a short budget here (the full 192,000 clocks
    take minutes on Amaranth's simulator); the model block's own tests run the full INIT_TIME_LIMIT_CLOCKS, and the
    RTL's default is checked below."""
    script = OpticalScript(REG, present=0b101).reset().response(IN, Response.DETECTED)
    rows = script.idle(2 * limit + 2).rows
    assert run_amaranth_sim(lambda: OpticalRtl(limit), lambda: OpticalBlock(limit), rows).cycles == len(rows)
    block = OpticalBlock(limit)
    phases = []
    for row in rows:
        block.step(row)
        phases.append((block.status[IN].phase, block.status[BRANCH].phase))
    assert block.status[BRANCH].phase is Phase.FIXED
    assert block.status[IN].phase is Phase.FIXED
    fixed_in = next(k for k, p in enumerate(phases) if p[0] is Phase.FIXED)
    fixed_branch = next(k for k, p in enumerate(phases) if p[1] is Phase.FIXED)
    assert fixed_branch - fixed_in == limit  # the branch's own budget, from the incoming one's end
    default = inspect.signature(OpticalRtl).parameters["time_limit"].default
    assert default == OpticalBlock().time_limit == INIT_TIME_LIMIT_CLOCKS


# Random strobes -------------------------------------------------------------------------------------------------

STROBE = st.fixed_dictionaries({
    "resp_valid": st.integers(0, 7), "resp": st.integers(0, 63), "test_valid": st.integers(0, 7),
    "ack1": st.integers(0, 7), "ack2": st.integers(0, 7), "len_start": st.integers(0, 7),
    "len_stop": st.integers(0, 7), "run": st.integers(0, 1),
})  # fmt: skip
EVENT = st.one_of(
    st.tuples(st.just("strobe"), STROBE),
    st.tuples(st.just("response"), st.sampled_from(list(Interface)), st.sampled_from([1, 1, 1, 2, 0])),
    st.tuples(st.just("idle"), st.integers(1, 40)),
    st.tuples(st.just("reset"), st.integers(1, 4), st.integers(0, 7), st.integers(0, 7)),
)


SEGMENT = st.tuples(st.integers(0, 3), st.integers(0, 1), st.integers(0, 7), st.integers(0, 7),
                    st.lists(EVENT, min_size=3, max_size=30))
"""An INTERBUS reset with a mode, bit rate, interfaces in use and media (static out of reset, so they change only
inside the reset), then random events."""


def random_script(segments: list[tuple[int, int, int, int, list[tuple[object, ...]]]]) -> OpticalScript:
    script = OpticalScript(0)
    for mode, fast, present, medium, events in segments:
        script.static |= {"mode": mode, "fast": fast, "present": present, "medium": medium}
        script.reset()
        for event in events:
            name, *args = event
            if name == "strobe":
                strobes = args[0]
                assert isinstance(strobes, dict)
                script.idle(**strobes)
            elif name == "response":
                interface, response = args
                assert isinstance(interface, Interface) and isinstance(response, int)
                script.response(interface, response)
            elif name == "idle":
                cycles = args[0]
                assert isinstance(cycles, int)
                script.idle(cycles)
            else:
                cycles, script.static["present"], script.static["medium"] = args  # type: ignore[assignment]
                assert isinstance(cycles, int)
                script.reset(cycles)
    return script


@settings(max_examples=3)
@given(segments=st.lists(SEGMENT, min_size=4, max_size=8))
def test_random_strobes(segments: list[tuple[int, int, int, int, list[tuple[object, ...]]]]) -> None:
    """Any mix of strobes, responses, idle stretches and INTERBUS resets (with new interfaces and media), in every
    mode at both bit rates: the RTL equals the model on every output, every clock."""
    lockstep(random_script(segments))


@pytest.mark.slow
@settings(max_examples=8)
@given(segments=st.lists(SEGMENT, min_size=4, max_size=8))
def test_random_strobes_more(segments: list[tuple[int, int, int, int, list[tuple[object, ...]]]]) -> None:
    """:func:`test_random_strobes` on about three times as many examples, with longer histories."""
    lockstep(random_script(segments))


@settings(max_examples=3)
@given(segments=st.lists(SEGMENT, min_size=4, max_size=8), limit=st.integers(1, 12))
def test_random_strobes_with_short_budgets(segments: list[tuple[int, int, int, int, list[tuple[object, ...]]]],
                                           limit: int) -> None:  # fmt: skip
    """:func:`test_random_strobes` with a budget of a few clocks, so that the budgets of the interfaces run out one
    after the other among responses and resets (OPT-56): the RTL equals the model on every output, every clock."""
    rows = random_script(segments).rows
    assert run_amaranth_sim(lambda: OpticalRtl(limit), lambda: OpticalBlock(limit), rows).cycles == len(rows)

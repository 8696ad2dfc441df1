"""The bus terminal module's spec (supi3.terminal): every transition over every state of a small space (all flags,
counts 0, 1, 63) and every input, checked against the rules of manual 2.4, Tables 2-8 and 2-9 and the decisions
BK-2..BK-12 of docs/assumptions/bus-terminal.md; and the public entries against hostile input."""

from __future__ import annotations

import itertools
from dataclasses import replace

import pytest

from supi3.errors import ArgumentError
from supi3.interbus import wire
from supi3.interbus.wire import BranchControl
from supi3.model.blocks.terminal import TerminalBlock
from supi3.model.bus_terminal import BusTerminal
from supi3.tables import CLOCK_HZ
from supi3.terminal import (
    BLOCK_INPUTS,
    BLOCK_OUTPUTS,
    BRANCH_SILENCE_CLOCKS,
    BRANCH_SILENCE_S,
    RF_CODES,
    Terminal,
    TerminalMode,
    branch_present,
    command,
    conf_level,
    enabled,
    live,
    power_up,
    received,
    reset,
    restarts_silence,
    rf_code,
    rf_of,
    silence,
    watching,
)
from support import bad

IDLE = {pin.name: 0 for pin in BLOCK_INPUTS}
FLAGS = ("conf", "switched_on", "extended", "closed", "closed_report", "conf_request", "alarm")
COUNTS = (0, 1, wire.COUNTER_MAX)
STATES = [
    Terminal(**dict(zip(FLAGS, flags, strict=True)), count=count)
    for flags in itertools.product((False, True), repeat=len(FLAGS)) for count in COUNTS
]  # fmt: skip
"""Every combination of the flags, with no count, the first and the saturated one: 384 states."""


def test_the_state_space_is_complete_and_distinct() -> None:
    assert len(set(STATES)) == 2 ** len(FLAGS) * len(COUNTS) == 384


def test_silence_is_10_ms_in_clocks() -> None:
    """BK-3: 10 ms at the 32 MHz chip clock."""
    assert BRANCH_SILENCE_CLOCKS == 320_000 == round(BRANCH_SILENCE_S * CLOCK_HZ)


def test_power_up_takes_the_conf_level_without_an_edge() -> None:
    for conf in (False, True):
        state = power_up(conf)
        assert state == Terminal(conf=conf) and not state.attention and state.status == 0
        assert conf_level(state, conf) == state


@pytest.mark.parametrize("conf", [False, True])
def test_conf_every_state(conf: bool) -> None:
    """2.4, BK-8: only a positive edge raises the request; a falling edge or a steady level keeps it as it is."""
    for state in STATES:
        after = conf_level(state, conf)
        rising = conf and not state.conf
        assert after == replace(state, conf=conf, conf_request=state.conf_request or rising)


@pytest.mark.parametrize("branch", list(BranchControl))
@pytest.mark.parametrize("acknowledge", [False, True])
@pytest.mark.parametrize("alarm", [None, False, True])
def test_command_every_state(branch: BranchControl, acknowledge: bool, alarm: bool | None) -> None:
    """BK-4 branch control, BK-8 acknowledgement, BK-12 ALARM output; CONF level and count untouched."""
    for state in STATES:
        after = command(state, branch, acknowledge, alarm)
        assert (after.conf, after.count) == (state.conf, state.count)
        assert after.alarm is (state.alarm if alarm is None else alarm)
        if branch is BranchControl.NONE:
            assert (after.switched_on, after.extended, after.closed) == (state.switched_on, state.extended,
                                                                         state.closed)  # fmt: skip
        elif branch is BranchControl.OFF:
            assert (after.switched_on, after.extended, after.closed) == (False, state.extended, state.closed)
        else:
            assert (after.switched_on, after.extended, after.closed) == (True, branch is BranchControl.ON_EXTENDED,
                                                                         False)  # fmt: skip
        assert restarts_silence(branch) is (branch in (BranchControl.ON, BranchControl.ON_EXTENDED))
        if acknowledge:
            assert not after.conf_request and not after.closed_report and not after.attention
        else:
            assert (after.conf_request, after.closed_report) == (state.conf_request, state.closed_report)


def test_silence_every_state() -> None:
    """BK-3: only a watching BK (extended, switched on, not closed) closes its branch, with the report."""
    closing = 0
    for state in STATES:
        after = silence(state)
        if state.extended and state.switched_on and not state.closed:
            assert watching(state)
            assert after == replace(state, closed=True, closed_report=True)
            assert after.attention and after.ld and after.e and not watching(after)
            closing += 1
        else:
            assert not watching(state) and after == state
    assert closing == len(STATES) // 8


@pytest.mark.parametrize("count", range(wire.COUNTER_MAX + 1))
def test_received_every_state(count: int) -> None:
    """BK-6: the last count received is kept, 0 for the master's own telegrams; it shows in the status byte."""
    for state in STATES:
        after = received(state, count)
        assert after == replace(state, count=count)
        assert wire.decode_bk_status(after.status) == wire.BkStatus(state.conf_request, state.closed_report, count)


def test_reset_every_state() -> None:
    """BK-9: everything the master set or the BK did is undone; CONF level and waiting request stay."""
    for state in STATES:
        after = reset(state)
        assert after == Terminal(conf=state.conf, conf_request=state.conf_request)
        assert after.attention is state.conf_request and not after.ld and not after.e and not after.alarm


def test_outputs_every_state() -> None:
    """BK-5 status byte, ATTN, BK-11 LEDs."""
    for state in STATES:
        assert state.status == wire.bk_status(state.conf_request, state.closed_report, state.count)
        assert state.attention is (state.conf_request or state.closed_report)
        assert state.ld is (state.closed or not state.switched_on)
        assert state.e is (state.closed or state.count > 0)


@pytest.mark.parametrize(("rf", "lbst", "connected"), list(itertools.product([*RF_CODES, None], [False, True],
                                                                        [False, True])))  # fmt: skip
def test_enabled_every_state(rf: str | None, lbst: bool, connected: bool) -> None:
    """Table 2-9 (BK-2) and the branch state: present, switched on, not closed."""
    present = {"10": lbst, "11": connected and lbst, None: connected and lbst}.get(rf, connected or lbst)
    assert branch_present(rf, lbst, connected) is present
    for state in STATES:
        assert enabled(state, rf, lbst, connected) is (present and state.switched_on and not state.closed)


@pytest.mark.parametrize(("rf", "lbst"), list(itertools.product([*RF_CODES, None], [False, True])))
def test_live_every_state(rf: str | None, lbst: bool) -> None:
    """BK-42: the interface sends while the branch is open and Table 2-9 would make it present were a device
    answering: not with RF = 10 and LBST = 0 (no recognition), nor with RF = 11 and LBST = 0 (switched off)."""
    sends = lbst or rf in ("00", "01")
    for state in STATES:
        assert live(state, rf, lbst) is (sends and state.switched_on and not state.closed)


def test_rf_and_mode_codes() -> None:
    assert [rf_of(rf_code(rf)) for rf in RF_CODES] == list(RF_CODES)
    assert rf_code(None) == rf_code("11") == 3
    assert [TerminalMode.of(name) for name in ("BK-RB", "BK-LB", "BK-LBD", "RB", None)] == [
        TerminalMode.RB, TerminalMode.LB, TerminalMode.LBD, TerminalMode.NONE, TerminalMode.NONE]  # fmt: skip


def test_ports_have_distinct_names() -> None:
    names = [pin.name for pin in (*BLOCK_INPUTS, *BLOCK_OUTPUTS)]
    assert len(names) == len(set(names))
    assert {pin.name: pin.width for pin in BLOCK_INPUTS}["count"] == wire.COUNTER_MAX.bit_length()
    assert {pin.name: pin.width for pin in BLOCK_OUTPUTS}["status"] == 8


def test_the_transaction_level_follows_the_spec() -> None:
    """BusTerminal's state is the spec's value, changed by the spec's transitions only."""
    tl = BusTerminal("BK-LBD", "00")
    assert tl.state == Terminal()
    tl.command(BranchControl.ON_EXTENDED, False, True)
    assert tl.state == command(Terminal(), BranchControl.ON_EXTENDED, False, True)
    assert not tl.returned(False, 5, 0.0, 0.001, 0.0005)  # the silence starts at this frame's end (BK-50)
    assert tl.returned(False, 5, 0.001, 0.001 + BRANCH_SILENCE_S, 0.0005 + BRANCH_SILENCE_S)
    assert tl.state == silence(received(command(Terminal(), BranchControl.ON_EXTENDED, False, True), 5))
    tl.reset()
    assert tl.state == Terminal() and tl.closures == 1



def test_the_transaction_level_judges_the_silence_at_the_ends_of_frames() -> None:
    """BK-3, BK-50 at transaction level, as the pin level's timer (``silence_edge``): the silence restarts at the
    first frame's end after the master's telegrams came back (a stretch with traffic, a command switching the branch
    on), counts also over time no stretch was reported (the BK not reached) and closes the branch at the first
    frame's end by which it has lasted the limit, to the clock; a stretch without a frame (an idle master) closes
    nothing; ``silence`` (in clocks, 100 µs here) shortens it."""
    limit = CLOCK_HZ // 10_000
    tl = BusTerminal("BK-LBD", "00", silence=limit)
    assert tl.silence_s == limit / CLOCK_HZ == 1e-4
    tl.command(BranchControl.ON_EXTENDED, False)
    assert not tl.returned(True, None, 0.0, 0.001, 0.0005)
    assert not tl.returned(False, None, 0.001, 0.00151, 0.0015)  # the silence starts at this frame's end
    assert not tl.returned(False, None, 0.00151, 0.00155)  # no frame: an idle master closes nothing
    assert not tl.returned(False, None, 0.00155, 0.0016, 0.0015 + (limit - 1) / CLOCK_HZ)  # a clock short
    assert tl.returned(False, None, 0.0016, 0.0017, 0.0015 + limit / CLOCK_HZ) and tl.closed
    tl.command(BranchControl.ON_EXTENDED, False)
    assert not tl.returned(False, None, 0.0017, 0.0018, 0.00175) and not tl.closed  # restarts here
    assert not tl.returned(True, None, 0.0018, 0.0019, 0.00185)  # heard: restarts at the next frame's end
    assert not tl.returned(False, None, 0.0019, 0.0020, 0.00195)
    assert tl.returned(False, None, 0.0020, 0.0021, 0.00195 + limit / CLOCK_HZ) and tl.closures == 2


HOSTILE = [
    (lambda: conf_level(bad(None), True), "state"),
    (lambda: conf_level(Terminal(), bad(1)), "conf"),
    (lambda: power_up(bad("1")), "conf"),
    (lambda: command(Terminal(), bad(2), False), "branch"),
    (lambda: command(Terminal(), BranchControl.ON, bad(0)), "acknowledge"),
    (lambda: command(Terminal(), BranchControl.ON, False, bad(1)), "alarm"),
    (lambda: received(Terminal(), 64), "count"),
    (lambda: received(Terminal(), bad(True)), "count"),
    (lambda: received(Terminal(), -1), "count"),
    (lambda: silence(bad(object())), "state"),
    (lambda: reset(bad({})), "state"),
    (lambda: watching(bad(None)), "state"),
    (lambda: enabled(Terminal(), "2", True, True), "rf"),
    (lambda: enabled(Terminal(), "10", bad(None), True), "lbst"),
    (lambda: branch_present("10", True, bad(1.0)), "connected"),
    (lambda: restarts_silence(bad(3)), "branch"),
    (lambda: rf_code(bad(3)), "rf"),
    (lambda: rf_of(4), "rf"),
    (lambda: Terminal(count=64), "count"),
    (lambda: Terminal(closed=bad(1)), "closed"),
    (lambda: BusTerminal("BK-LB", bad("12")), "rf"),
    (lambda: BusTerminal("BK-LB", None).returned(False, 64, 0.0, 1.0), "count"),
    (lambda: BusTerminal("BK-LB", None).returned(False, None, 0.0, 1.0, 1.5), "frame_end"),
    (lambda: setattr(BusTerminal("BK-LB", None), "conf_request", bad(1)), "conf_request"),
    (lambda: TerminalBlock(0), "time_limit"),
    (lambda: TerminalBlock(BRANCH_SILENCE_CLOCKS + 1), "time_limit"),
    (lambda: TerminalBlock(bad(1.0)), "time_limit"),
    (lambda: TerminalBlock().step(bad({})), "inputs"),
    (lambda: TerminalBlock().step(IDLE | {"count": 64}), "pin 'count'"),
    (lambda: TerminalBlock().step(IDLE | {"mode": bad(True)}), "pin 'mode'"),
    (lambda: TerminalBlock().step(IDLE | {"extra": 0}), "inputs"),
]


@pytest.mark.parametrize(("call", "name"), HOSTILE)
def test_hostile_inputs_are_named_errors(call: object, name: str) -> None:
    assert callable(call)
    with pytest.raises(ArgumentError, match=rf"^{name} must be"):
        call()


def test_a_refused_step_changes_nothing() -> None:
    block = TerminalBlock(3)
    block.step(IDLE | {"mode": TerminalMode.LBD, "conf": 1})
    before = (block.state, block.timer, block.cycle)
    with pytest.raises(ArgumentError):
        block.step(IDLE | {"mode": TerminalMode.LBD, "conf": 2})
    assert (block.state, block.timer, block.cycle) == before

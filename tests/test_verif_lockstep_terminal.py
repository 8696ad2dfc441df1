"""Lockstep of the bus terminal block's RTL (supi3.rtl.terminal.TerminalRtl) against its pin model
(supi3.model.blocks.terminal.TerminalBlock), every output every clock, on Amaranth's simulator
(supi3.verif.amaranth_sim; manual 2.4, Tables 2-8, 2-9, BK-2..BK-12, BK-20).

Directed cases for every transition (CONF edges, every branch control in every RF mode of Table 2-9, the
acknowledgement, the extended function's closure after the silence, traffic restarting the silence, counter
telegrams, INTERBUS resets in the middle, the ALARM output, a chip that is no BK), each also checked to reach the
state it is about; the same scenario on the transaction level (BusTerminal) ends in the same state; and random
strobes (hypothesis, the seeded profile of tests/conftest.py) in every BK mode and RF code, with resets in the middle.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.interbus import wire
from supi3.interbus.wire import BranchControl, Cycle
from supi3.lbd import clocks_per_bit
from supi3.model.blocks.terminal import ReturnWatch, TerminalBlock
from supi3.model.bus_terminal import BRANCH_SILENCE_S, CONF_PIN, LBST_PIN, BusTerminal
from supi3.pinlevel import Pin
from supi3.rtl.counter import CounterRtl
from supi3.rtl.terminal import ReturnWatchRtl, TerminalRtl
from supi3.tables import BIT_RATES, CLOCK_HZ
from supi3.terminal import BLOCK_INPUTS, BRANCH_SILENCE_CLOCKS, RF_CODES, Terminal, TerminalMode
from supi3.verif.amaranth_sim import run_amaranth_sim

INPUTS = [pin.name for pin in BLOCK_INPUTS]
LIMIT = 12
"""A short silence, elaborated on both sides (the full 320,000 clocks are the default, checked below)."""
OFF, ON, ON_EXT = BranchControl.OFF, BranchControl.ON, BranchControl.ON_EXTENDED


class TerminalScript:
    """Per-cycle inputs of the bus terminal block (``BLOCK_INPUTS``), built call by call: levels (``mode``, ``rf``,
    ``conf``, ``lbst``, ``connected``) on every row until changed, strobes one cycle wide. It starts with
    the power-up cycle (the block takes the CONF level at its edge, BK-20)."""

    def __init__(self, mode: int = TerminalMode.LBD, *, rf: int = 3, lbst: int = 1, connected: int = 1,
                 conf: int = 0) -> None:  # fmt: skip
        self.levels = {"mode": int(mode), "rf": rf, "lbst": lbst, "connected": connected, "conf": conf}
        self.rows: list[dict[str, int]] = []
        self.idle()

    def idle(self, n: int = 1, **pins: int) -> TerminalScript:
        """``n`` cycles with the levels and ``pins``; the other inputs 0."""
        row = dict.fromkeys(INPUTS, 0) | self.levels | pins
        self.rows.extend([row] * n)
        return self

    def set(self, **levels: int) -> TerminalScript:
        """New levels from the next cycle on, and one cycle with them."""
        self.levels |= levels
        return self.idle()

    def reset(self, n: int = 3) -> TerminalScript:
        return self.idle(n, ib_reset=1).idle()

    def command(self, branch: BranchControl = BranchControl.NONE, ack: bool = False,
                alarm: bool | None = None) -> TerminalScript:  # fmt: skip
        return self.idle(cmd_valid=1, branch=branch.value, ack=int(ack), alarm_set=int(alarm is not None),
                         alarm_on=int(bool(alarm)))  # fmt: skip

    def back(self, n: int = 1) -> TerminalScript:
        """The master's telegrams come back on the branch return line, ``n`` cycles in a row."""
        return self.idle(n, ret_valid=1)

    def counter(self, count: int) -> TerminalScript:
        return self.idle(cnt_valid=1, count=count)

    def frame(self, **pins: int) -> TerminalScript:
        """A cycle whose edge ends a frame's check sequence (``frame_end``, BK-50), with ``pins``."""
        return self.idle(frame_end=1, **pins)


def lockstep(script: TerminalScript, limit: int = LIMIT) -> tuple[TerminalBlock, list[dict[str, int]]]:
    """The script on the RTL and the model, compared every clock; the model after it and its outputs."""
    rows = script.rows
    assert run_amaranth_sim(lambda: TerminalRtl(limit), lambda: TerminalBlock(limit), rows).cycles == len(rows)
    block = TerminalBlock(limit)
    return block, [block.step(row) for row in rows]


def test_conf_edges_and_acknowledge() -> None:
    """2.4, BK-8: CONF high at power-up is no edge; a positive edge raises the request (ATTN, status bit 7), also
    inside a reset, where it stays; the quit bit clears it; a falling edge does nothing."""
    script = TerminalScript(conf=1).idle(3)
    block, out = lockstep(script)
    assert block.state == Terminal(conf=True) and not out[-1]["attention"]
    script.set(conf=0).idle(2).set(conf=1).idle(2)
    block, out = lockstep(script)
    assert block.state.conf_request and out[-1]["attention"] and out[-1]["status"] >> wire.BK_STATUS_CONF_BIT
    script.command(ack=True).idle(2).idle(ib_reset=1).set(conf=0).idle(ib_reset=1).set(conf=1).idle(ib_reset=1)
    block, out = lockstep(script.reset().idle(2))
    assert block.state == Terminal(conf=True, conf_request=True) and out[-1]["status"] == 0x80


@pytest.mark.parametrize("rf", range(len(RF_CODES)))
def test_every_branch_control_in_every_rf_mode(rf: int) -> None:
    """BK-4 and Table 2-9 (BK-2): ``enabled`` follows LBST and the answering device as RF says, and the master's
    control; LD is lit while the branch is switched off (BK-11)."""
    script = TerminalScript(rf=rf, lbst=0, connected=0).idle(2)
    for lbst, connected in ((0, 1), (1, 0), (1, 1), (0, 0)):
        script.set(lbst=lbst, connected=connected)
        for branch in (OFF, BranchControl.NONE, ON, OFF, ON_EXT, BranchControl.NONE):
            script.command(branch).idle()
    block, out = lockstep(script.set(lbst=1, connected=1))
    assert block.state.extended and block.state.switched_on
    assert out[-1]["enabled"] == int(RF_CODES[rf] in ("10", "11", "00", "01")) == out[-1]["live"]
    assert any(row["ld"] for row in out) and not out[-1]["ld"]
    assert any(row["live"] and not row["enabled"] for row in out) == (RF_CODES[rf] != "10")  # BK-42: probing


def test_extended_closure_after_the_silence() -> None:
    """BK-3, BK-50: switched on with the extended function, the branch silent from a frame's end to one the limit
    later is closed by the BK at that frame's end: closed report, ATTN, LD and E; the acknowledgement ends the report,
    not the closure; switching it on opens it."""
    block, out = lockstep(TerminalScript().command(ON_EXT).frame().idle(LIMIT - 2).frame().idle(2))
    assert not block.state.closed and not any(row["closed"] for row in out)  # a clock short
    script = TerminalScript().command(ON_EXT).frame().idle(LIMIT - 1).frame().idle()
    block, out = lockstep(script)
    assert block.state == Terminal(extended=True, closed=True, closed_report=True)
    assert [row["closed"] for row in out].index(1) == 3 + LIMIT  # power-up, command, frame, LIMIT clocks
    assert out[-1] | {"status": 0} == {"enabled": 0, "live": 0, "status": 0, "attention": 1, "ld": 1, "e": 1,
                                       "alarm": 0, "closed": 1}  # fmt: skip
    assert wire.decode_bk_status(out[-1]["status"]) == wire.BkStatus(False, True, 0)
    block, out = lockstep(script.command(ack=True).idle(3))
    assert block.state.closed and not block.state.closed_report and not out[-1]["attention"]
    block, out = lockstep(script.command(ON).idle(3 * LIMIT))
    assert block.state == Terminal() and out[-1]["enabled"]


def test_a_closure_comes_only_at_the_end_of_a_frame() -> None:
    """BK-50: the silence restarts at the first frame's end after the return line was heard and closes the branch
    only at a frame's end (``frame_end``), the first by which it has lasted the limit, however long after; without
    frames (a master that idles) nothing closes, the timer holds; the master's telegram back before that frame's
    end, or in its clock, restarts the silence at the next one instead."""
    for wait in (0, 1, 3 * LIMIT):
        script = TerminalScript().command(ON_EXT).frame().idle(LIMIT - 1 + wait).frame().idle(2)
        block, out = lockstep(script)
        assert block.state.closed and block.state.closed_report
        assert [row["closed"] for row in out].index(1) == 3 + LIMIT + wait
    for heard in ({"ret_valid": 1}, {"frame_end": 1, "ret_valid": 1}):  # before the frame's end, in its clock
        script = TerminalScript().command(ON_EXT).frame().idle(LIMIT + 3).idle(**heard)
        block, out = lockstep(script.frame().idle(LIMIT - 2).frame().idle(2))  # restarted at the first of these
        assert not block.state.closed and not any(row["closed"] for row in out)
        block, out = lockstep(script.frame().idle())
        assert block.state.closed


def test_traffic_restarts_the_silence_and_counter_telegrams_do_not() -> None:
    """BK-3: the master's telegrams back restart the silence; counter telegrams (BK-6) do not; nor does a branch
    switched off or absent count as watched (BK-20)."""
    script = TerminalScript().command(ON_EXT).frame()
    for _ in range(4):
        script.idle(LIMIT - 2).back().frame()
    block, _ = lockstep(script)
    assert not block.state.closed
    script.command(OFF).idle(3 * LIMIT).command(ON_EXT).set(lbst=0).idle(3 * LIMIT).set(lbst=1)
    block, _ = lockstep(script)
    assert not block.state.closed and block.state.extended
    script.back().frame().idle(LIMIT - 1).frame(cmd_valid=1, branch=OFF.value)  # off at the closure's edge
    block, _ = lockstep(script)
    assert block.state == Terminal(switched_on=False, extended=True)
    script.command(ON_EXT).frame()
    for count in (3, 4, 5):
        script.idle(3).counter(count)
    block, out = lockstep(script.idle(LIMIT).frame().idle())
    assert block.state.closed and block.state.count == 5
    assert wire.decode_bk_status(out[-1]["status"]) == wire.BkStatus(False, True, 5)


def test_counts_and_the_e_led() -> None:
    """BK-6, BK-11: the last count is kept and shown (E lit); the master's telegrams back clear it; a counter
    telegram and a telegram of the master in the same clock keep the count; a reset forgets it (BK-9)."""
    script = TerminalScript().counter(7).idle(2)
    block, out = lockstep(script)
    assert block.state.count == 7 and out[-1]["e"] and out[-1]["status"] == 7
    block, out = lockstep(script.back().idle())
    assert block.state.count == 0 and not out[-1]["e"]
    block, out = lockstep(script.idle(cnt_valid=1, count=wire.COUNTER_MAX, ret_valid=1).idle())
    assert block.state.count == wire.COUNTER_MAX
    block, out = lockstep(script.reset())
    assert block.state.count == 0


def test_resets_in_the_middle_and_the_alarm_output() -> None:
    """BK-9, BK-12: a reset reopens a closed branch, switches the extended function and the ALARM output off and
    keeps a waiting request; strobes inside the reset are ignored; the silence starts anew."""
    script = TerminalScript().command(alarm=True).set(conf=1).command(ON_EXT).frame().idle(LIMIT).frame().idle()
    block, out = lockstep(script)
    assert block.state.closed and block.state.alarm and out[-1]["alarm"] and block.state.conf_request
    script.idle(ib_reset=1, cmd_valid=1, branch=OFF.value, alarm_set=1, alarm_on=1).idle(ib_reset=1, cnt_valid=1,
                                                                                      count=9)  # fmt: skip
    block, out = lockstep(script.idle())
    assert block.state == Terminal(conf=True, conf_request=True) and out[-1]["enabled"] and not out[-1]["alarm"]
    script.command(ON_EXT).frame().idle(LIMIT - 3).reset(2).command(ON_EXT).frame(cmd_valid=1).idle(LIMIT - 2)
    block, _ = lockstep(script.frame().idle())  # the reset restarted the silence at the frame after it
    assert not block.state.closed
    block, _ = lockstep(script.command(alarm=False).frame().idle(2))
    assert block.state.closed and not block.state.alarm


def test_a_chip_that_is_no_bus_terminal_module() -> None:
    """Mode NONE: outputs all 0 whatever the inputs, the state stays at power-up."""
    script = TerminalScript(TerminalMode.NONE, conf=1).idle(2).set(conf=0).set(conf=1).command(OFF, alarm=True)
    block, out = lockstep(script.counter(4).command(ON_EXT).idle(2 * LIMIT))
    assert block.state == Terminal() and not any(any(row.values()) for row in out)


@pytest.mark.parametrize("limit", [1, 2, 300])
def test_silence_limits(limit: int) -> None:
    """BK-3, BK-50: the branch closes at a frame's end ``limit`` edges after the one that restarted the silence; the
    RTL's and the model's default is the spec's 10 ms."""
    script = TerminalScript().command(ON_EXT).frame().idle(limit - 1).frame().idle()
    _, out = lockstep(script, limit)
    assert [row["closed"] for row in out].index(1) == 3 + limit
    default = inspect.signature(TerminalRtl).parameters["time_limit"].default
    assert default == TerminalBlock().time_limit == BRANCH_SILENCE_CLOCKS


def test_transaction_level_reaches_the_same_state() -> None:
    """One scenario at both fidelities (BusTerminal with the TL's MFP levels and bus seconds; the block with its
    strobes and clocks): the same Terminal state after each step."""
    tl = BusTerminal("BK-LBD", "00")
    script = TerminalScript(rf=0)
    block = TerminalBlock(LIMIT)
    steps: list[tuple[Any, Any]] = [
        (lambda: tl.inputs(1 << LBST_PIN), lambda: script.set(lbst=1)),
        (lambda: tl.inputs(1 << LBST_PIN | 1 << CONF_PIN), lambda: script.set(conf=1)),
        (lambda: tl.command(ON_EXT, False, True), lambda: script.command(ON_EXT, alarm=True)),
        (lambda: tl.returned(True, None, 0.0, 0.001), lambda: script.back()),
        (lambda: tl.returned(False, 4, 0.002, 0.003, 0.0025), lambda: script.counter(4).frame()),
        (lambda: tl.returned(False, 4, 0.003, 0.003 + BRANCH_SILENCE_S, 0.0025 + BRANCH_SILENCE_S),
         lambda: script.idle(LIMIT - 1).frame()),
        (lambda: tl.command(BranchControl.NONE, True), lambda: script.command(ack=True)),
        (lambda: tl.reset(), lambda: script.reset()),
        (lambda: tl.command(OFF, False), lambda: script.command(OFF)),
    ]
    for at_tl, at_pin in steps:
        at_tl()
        start = len(script.rows)
        at_pin()
        for row in script.rows[start:]:
            block.step(row)
        assert block.state == tl.state
    assert block.state == Terminal(conf=True, switched_on=False)
    assert tl.closures == 1


# Random strobes -------------------------------------------------------------------------------------------------

STROBE = st.fixed_dictionaries({
    "cmd_valid": st.integers(0, 1), "branch": st.integers(0, 3), "ack": st.integers(0, 1),
    "alarm_set": st.integers(0, 1), "alarm_on": st.integers(0, 1), "ret_valid": st.sampled_from([0, 0, 0, 1]),
    "cnt_valid": st.integers(0, 1), "count": st.integers(0, wire.COUNTER_MAX),
    "ib_reset": st.sampled_from([0] * 7 + [1]), "frame_end": st.sampled_from([0, 0, 1]),
})  # fmt: skip
EVENT = st.one_of(
    st.tuples(st.just("strobe"), STROBE),
    st.tuples(st.just("levels"), st.integers(0, 1), st.integers(0, 1), st.integers(0, 1)),
    st.tuples(st.just("command"), st.sampled_from(list(BranchControl))),
    st.tuples(st.just("idle"), st.sampled_from([1, 2, LIMIT - 2, LIMIT - 1, LIMIT, 3 * LIMIT])),
)
RUN = st.tuples(st.sampled_from(list(TerminalMode)), st.integers(0, 3), st.lists(EVENT, min_size=5, max_size=40))
"""A BK mode and an RF code (static), then random events."""


def random_script(run: tuple[TerminalMode, int, list[tuple[Any, ...]]]) -> TerminalScript:
    mode, rf, events = run
    script = TerminalScript(mode, rf=rf)
    for name, *args in events:
        if name == "strobe":
            script.idle(**args[0])
        elif name == "levels":
            conf, lbst, connected = args
            script.set(conf=conf, lbst=lbst, connected=connected)
        elif name == "command":
            script.command(args[0])
        else:
            script.idle(args[0])
    return script


@settings(max_examples=25)
@given(run=RUN)
def test_random_strobes(run: tuple[TerminalMode, int, list[tuple[Any, ...]]]) -> None:
    """Any mix of strobes, level changes, commands, idle stretches and INTERBUS resets, in every mode and RF code:
    the RTL equals the model on every output, every clock."""
    lockstep(random_script(run))


STRETCH = st.tuples(st.integers(4, 40), st.one_of(st.none(), st.integers(1, 1000)), st.booleans(), st.booleans())
"""A stretch of the master's traffic: its length in clocks, where its frame ends at the BK (a fraction of the length;
``None``: no frame, the master idles), whether the master's telegrams came back (before and after the frame), and
whether the master switches the branch on with the extended function at its end."""


@settings(max_examples=60, derandomize=True)
@given(st.integers(1, 60), st.lists(STRETCH, min_size=1, max_size=30))
def test_the_transaction_level_closes_at_the_block_s_clock(limit: int,
                                                           stretches: list[tuple[int, int | None, bool, bool]]) -> None:
    """BK-50 at both fidelities, to the clock: over any history of stretches with or without a frame, with or without
    the master's telegrams back, and commands switching the branch on again, the transaction-level BK (bus seconds,
    the frames' ends given) and the block (a clock per row: ``frame_end`` at the frame's end, ``ret_valid`` before
    and after it) close the branch after the same stretches and end every stretch in the same state."""
    tl = BusTerminal("BK-LBD", "00", silence=limit)
    block = TerminalBlock(limit)
    script = TerminalScript(rf=0).command(ON_EXT)
    tl.inputs(1 << LBST_PIN)
    tl.command(ON_EXT, False)
    for row in script.rows:
        block.step(row)
    for length, frame, traffic, command in stretches:
        start = len(script.rows)
        end = frame and 1 + frame * (length - 3) // 1000  # inside, apart from the telegrams back
        rows = [dict.fromkeys(INPUTS, 0) | script.levels for _ in range(length)]
        if end:
            rows[end]["frame_end"] = 1
        if traffic:
            rows[0]["ret_valid"] = rows[-1]["ret_valid"] = 1
        if command:
            rows[-1] |= {"ret_valid": 0, "cmd_valid": 1, "branch": ON_EXT.value}
        script.rows.extend(rows)
        for row in rows:
            block.step(row)
        tl.returned(traffic, None, start / CLOCK_HZ, (start + length) / CLOCK_HZ,
                    None if not end else (start + end) / CLOCK_HZ)  # fmt: skip
        if command:
            tl.command(ON_EXT, False)
        assert block.state == tl.state


# The return watch (BK-38) ----------------------------------------------------------------------------------------


class _Watch:
    """``ReturnWatch`` behind ``ReturnWatchRtl``'s ports (``line``, ``fast`` in; ``seen``, ``busy`` out, as they
    stand before each clock edge) for the lockstep."""

    inputs: Sequence[Pin] = (Pin("line"), Pin("fast"))
    outputs: Sequence[Pin] = (Pin("seen"), Pin("busy"))

    def __init__(self) -> None:
        self.watch = ReturnWatch()

    def reset(self) -> None:
        self.watch.reset()

    def step(self, row: Mapping[str, int]) -> dict[str, int]:
        strobe, busy = (pin.name for pin in self.outputs)
        out = {strobe: self.watch.seen, busy: int(self.watch.busy)}
        self.watch.clock(row["line"], clocks_per_bit(row["fast"]))
        return out


class _CounterWatch(_Watch):
    """``ReturnWatch`` behind the watch ports of ``CounterRtl(watch=True)`` (``returned``, ``busy``; its ``chain``
    left at 0: the BK's return watch on DI3 in the core, ``CounterLinesRtl``'s return block outside LBD-MR)."""

    outputs: Sequence[Pin] = (Pin("returned"), Pin("busy"))


_PIECE = st.one_of(
    st.tuples(st.sampled_from(list(Cycle)), st.booleans(), st.integers(1, 3)).map(
        lambda a: ("status", a[2], wire.status_levels(*a))),
    st.tuples(st.integers(0, 0xFF), st.sampled_from(list(Cycle)), st.booleans()).map(
        lambda a: ("data", 0, wire.telegram_levels([wire.data_telegram(*a)], wire.DATA_TELEGRAM_BITS))),
    st.tuples(st.sampled_from([wire.START_LEVEL, wire.IDLE_LEVEL]), st.integers(1, 40)).map(
        lambda a: ("clocks", 0, np.full(a[1], a[0], dtype=np.uint8))),  # glitches, skews off the grid, a held line
)
"""Pieces of a return line: status telegrams (with how many), data telegrams (counter telegrams among them), and
levels held for some clocks."""

_WATCHES: dict[str, tuple[Callable[[], Any], type[_Watch]]] = {
    "ReturnWatchRtl": (ReturnWatchRtl, _Watch),
    "CounterRtl(watch=True)": (lambda: CounterRtl(watch=True), _CounterWatch),
}
"""The RTL watches: the one on the transmitter's line and the counter block that is the one on DI3."""


@pytest.mark.parametrize("design", list(_WATCHES))
@settings(max_examples=4, deadline=None)
@given(fast=st.integers(0, 1), pieces=st.lists(_PIECE, min_size=4, max_size=8))
def test_the_return_watch_follows_its_model_every_clock(design: str, fast: int,
                                                        pieces: list[tuple[str, int, Any]]) -> None:  # fmt: skip
    """``ReturnWatchRtl`` (its bit grid's constants per rate, its counters without reset) and the watch ports of
    ``CounterRtl(watch=True)`` with ``chain`` 0 equal ``ReturnWatch`` on the strobe and ``busy`` every clock at both
    bit rates: status and data telegrams (counter telegrams among them), glitches, stop bits at the start level, skews
    off the bit grid, a line held at either level; with whole telegrams only, every status telegram is seen and no
    data telegram."""
    factory, model_class = _WATCHES[design]
    rate = BIT_RATES[fast]
    line = np.concatenate([*(wire.levels_to_samples(levels, rate) if kind != "clocks" else levels
                             for kind, _, levels in pieces), np.ones(2 * clocks_per_bit(fast), dtype=np.uint8)])
    rows = [{"line": int(level), "fast": fast} for level in line]
    assert run_amaranth_sim(factory, model_class, rows).cycles == len(rows)
    if all(kind != "clocks" for kind, _, _ in pieces):
        model = _Watch()
        assert sum(model.step(row)["seen"] for row in rows) == sum(n for _, n, _ in pieces)


@pytest.mark.parametrize("design", list(_WATCHES))
@pytest.mark.parametrize("fast", [0, 1])
def test_a_stop_bit_at_the_start_level_ends_the_watched_telegram(design: str, fast: int) -> None:
    """A status telegram whose stop bit is sampled at the start level is not seen and ends there (the watch keeps no
    M16, BK-38): ``busy`` falls for a clock and the next clock's start level restarts the grid, so the status
    telegram chained to it (its start bit the first one's stop bit) is not found on its grid; both RTL watches
    follow the model every clock, the counter block's with ``chain`` 0."""
    factory, model_class = _WATCHES[design]
    rate = BIT_RATES[fast]
    status = wire.status_levels(Cycle.DATA, False, 1)
    chained = np.concatenate([status[:-1], status])  # the first stop bit replaced by the second's start bit
    line = np.concatenate([np.ones(3, dtype=np.uint8), wire.levels_to_samples(chained, rate),
                           np.ones(2 * clocks_per_bit(fast), dtype=np.uint8)])  # fmt: skip
    rows = [{"line": int(level), "fast": fast} for level in line]
    assert run_amaranth_sim(factory, model_class, rows).cycles == len(rows)
    model = _Watch()
    busy = [model.step(row)["busy"] for row in rows]
    stop = 3 + (wire.STATUS_TELEGRAM_BITS - 1) * clocks_per_bit(fast) + clocks_per_bit(fast) // 2
    assert busy[stop] == 1 and busy[stop + 1] == 0 and busy[stop + 2] == 1

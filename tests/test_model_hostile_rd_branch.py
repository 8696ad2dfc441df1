"""This session's model entries against a hostile user (round 2): RD and the following device (``Supi3.set_following``,
``supi3.diagnostics.remote_bus_disabled``, ``diagnostic_outputs(following=)``, the ``Ring``'s wiring, DG-5), the idle
time-out (``Supi3.line_timeout``/``line_timeout_at``, DG-9), a BK's branch lines (``Supi3Pins(branch_silence=)``,
``BranchLines``, ``ReturnWatchRtl``/``CounterLinesRtl``; BK-37..39). Bad input gets a named error ("X must be ...,
not ..."), never a traceback or a silent guess; properties hold over histories (hypothesis, the seeded profile of
conftest), not single scenarios."""

from __future__ import annotations

import itertools
from collections.abc import Callable

import numpy as np
import pytest
from amaranth.hdl import Fragment
from hypothesis import example, given, settings
from hypothesis import strategies as st

from supi3.config import decode
from supi3.diagnostics import LedInputs, diagnostic_outputs, remote_bus_disabled
from supi3.errors import ArgumentError
from supi3.interbus import wire
from supi3.interbus.ring import Branch, BranchKind, Ring
from supi3.interbus.wire import BranchControl
from supi3.model.blocks.terminal import BranchLines
from supi3.model.bus_terminal import BusTerminal
from supi3.model.chip import ChipArgumentError, Supi3
from supi3.model.pins import Supi3Pins
from supi3.rtl.counter import CounterLinesRtl, CounterRtl, check_watched_modes
from supi3.rtl.terminal import ReturnWatchRtl
from supi3.terminal import BRANCH_SILENCE_CLOCKS, CONF_PIN, DI3_PIN, LBST_PIN, Terminal, TerminalMode
from support import BK_STRAPS, Columns, CoreScript, bad, quiet_inputs, terminal

NOT_BOOLS: list[object] = [0, 1, None, "yes", 1.0, np.int64(1)]
"""Values a bool parameter must refuse: ``0``/``1`` are not a guess at False/True."""

# -- bad input: a named error ---------------------------------------------------------------------------------------

_CHIP = decode("10000", diag_conf=0)
_LEDS = {"supply_ok": True, "line_heard": True, "bus_active": True, "peripheral_fault": False,
         "line_interrupt": False, "following": True, "leds": LedInputs()}  # fmt: skip

BAD_CALLS: list[tuple[str, Callable[[], object], type[Exception], str]] = [
    *((f"set_following({v!r})", lambda v=v: Supi3(_CHIP).set_following(bad(v)), ChipArgumentError,
       "present must be True or False") for v in NOT_BOOLS),
    *((f"remote_bus_disabled({v!r})", lambda v=v: remote_bus_disabled(bad(v)), ArgumentError,
       "following must be True or False") for v in NOT_BOOLS),
    *((f"diagnostic_outputs(following={v!r})", lambda v=v: diagnostic_outputs(_CHIP, **{**_LEDS, "following": v}),
       ArgumentError, "following must be True or False") for v in NOT_BOOLS),
    *((f"line_timeout(now={v!r})", lambda v=v: Supi3(_CHIP).line_timeout(bad(v)), ChipArgumentError,
       "now must be a finite number >= 0") for v in [-1.0, float("nan"), float("inf"), "1", True, None]),
    *((f"line_timeout(counted={v!r})", lambda v=v: Supi3(_CHIP).line_timeout(1.0, bad(v)), ChipArgumentError,
       "counted must be True or False") for v in NOT_BOOLS),
    *((f"line_timeout_at(clk={v!r})", lambda v=v: Supi3(_CHIP).line_timeout_at(bad(v)), ChipArgumentError,
       "clk must be an integer >= 0") for v in [-1, 1.5, True, "7", None]),
    # line_timeout_at took any counted as truthy: "no" skipped the line interrupt (DG-9) on a guess
    *((f"line_timeout_at(counted={v!r})", lambda v=v: Supi3(_CHIP).line_timeout_at(10, bad(v)), ChipArgumentError,
       "counted must be True or False") for v in NOT_BOOLS),
    *((f"Supi3Pins(branch_silence={v!r})", lambda v=v: Supi3Pins(terminal("BK-LB").config, branch_silence=bad(v)),
       ArgumentError, "branch_silence must be an integer from 1 to 320000")
      for v in [0, -1, BRANCH_SILENCE_CLOCKS + 1, 1.5, True, "10", None]),
    # BK-3: the transaction level's silence is shortened the same way, checked by the same rule
    *((f"Supi3(branch_silence={v!r})", lambda v=v: Supi3(terminal("BK-LB").config, branch_silence=bad(v)),
       ChipArgumentError, "branch_silence must be an integer from 1 to 320000")
      for v in [0, -1, BRANCH_SILENCE_CLOCKS + 1, 1.5, True, "10", None]),
    *((f"BusTerminal(silence={v!r})", lambda v=v: BusTerminal("BK-LB", "11", bad(v)), ArgumentError,
       "silence must be an integer from 1 to 320000") for v in [0, BRANCH_SILENCE_CLOCKS + 1, 2.0, True]),
    *((f"BranchLines(time_limit={v!r})", lambda v=v: BranchLines("11", 64, False, bad(v)), ArgumentError,
       "time_limit must be an integer from 1 to 320000") for v in [0, -1, BRANCH_SILENCE_CLOCKS + 1, 2.0, True]),
    *((f"BranchLines(rf={v!r})", lambda v=v: BranchLines(bad(v), 64, False), ArgumentError, "rf must be one of")
      for v in ["xx", 11, "1", b"11"]),
    # BranchLines took any cpb (0, 3, "64": a watch that never samples) and any lbd as truthy
    *((f"BranchLines(cpb={v!r})", lambda v=v: BranchLines("11", bad(v), False), ArgumentError,
       "cpb must be one of 64, 16") for v in [0, 3, 32, -64, "64", 64.0, None]),
    *((f"BranchLines(lbd={v!r})", lambda v=v: BranchLines("11", 64, bad(v)), ArgumentError, "lbd must be True or False")
      for v in NOT_BOOLS),
]


@pytest.mark.parametrize(("call", "error", "match"), [c[1:] for c in BAD_CALLS], ids=[c[0] for c in BAD_CALLS])
def test_bad_input_is_named(call: Callable[[], object], error: type[Exception], match: str) -> None:
    with pytest.raises(error, match=match) as info:
        call()
    assert ", not " in str(info.value)


def test_a_missing_following_is_a_type_error_not_a_default() -> None:
    # following has no default: a caller that forgets it does not get RD guessed
    with pytest.raises(TypeError, match="following"):
        diagnostic_outputs(_CHIP, **{k: v for k, v in _LEDS.items() if k != "following"})  # type: ignore[arg-type]


def test_a_refused_call_changes_nothing() -> None:
    chip = Supi3(_CHIP)
    before = (chip.following, chip.revision, chip.line_silent)
    calls: list[Callable[[], None]] = [lambda: chip.set_following(bad(1)), lambda: chip.line_timeout_at(10, bad("no")),
                                       lambda: chip.line_timeout(-1.0), lambda: chip.line_timeout(1.0, bad(None))]
    for call in calls:
        with pytest.raises(ChipArgumentError):
            call()
    assert (chip.following, chip.revision, chip.line_silent) == before


def test_the_rtl_blocks_elaborate() -> None:
    # the watch (its bit grid per rate: no width to choose) and the counter lines that hold it
    Fragment.get(ReturnWatchRtl(), None)
    Fragment.get(CounterLinesRtl(), None)
    # the counter block as the watch on DI3 (its ``watch`` ports) and with the count taken with ``seen``: a flag
    # that is no bool is named
    Fragment.get(CounterRtl(watch=True, strobed_count=True), None)
    for flag in ("watch", "strobed_count", "shared_clock"):
        with pytest.raises(ArgumentError, match=f"{flag} must be True or False"):
            CounterRtl(**{flag: 1})  # type: ignore[arg-type]
    # a mode table with a row that is LBD-MR and a BK is refused at elaboration (the return block watches DI3 there)
    with pytest.raises(ValueError, match="mode row 1 is LBD-MR and a bus terminal module"):
        check_watched_modes([(False, False), (True, True)], [TerminalMode.NONE, TerminalMode.LBD])
    check_watched_modes([(True, True), (False, False)], [TerminalMode.NONE, TerminalMode.LBD])


# -- the Ring's following-device wiring (DG-5) ----------------------------------------------------------------------

@pytest.mark.parametrize("shape", ["", "B", "P", "PB", "BP", "BB", "PBPB", "B0", "PB0P"])
def test_the_ring_lights_rd_on_the_last_of_the_ring_and_of_each_branch(shape: str) -> None:
    # Every small ring shape: P a plain chip, B a BK with two branch chips, B0 a BK with an empty branch. RD is lit
    # exactly on the last item of the ring and on the last chip of each branch (a BK's own RD: what follows its
    # branch on the remote bus), also after the branch is switched off (the wiring is physical).
    items: list[Supi3 | Branch] = []
    expected: dict[Supi3, bool] = {}
    tokens = shape.replace("B0", "Z")
    for k, token in enumerate(tokens):
        last = k == len(tokens) - 1
        if token == "P":
            chip = Supi3(_CHIP)
            items.append(chip)
            expected[chip] = last
            continue
        bk = terminal("BK-LB")
        devices = [] if token == "Z" else [Supi3(decode("01000", diag_conf=0)) for _ in range(2)]
        items.append(Branch(bk, devices, BranchKind.LOCAL))
        expected[bk] = last
        expected.update({d: j == len(devices) - 1 for j, d in enumerate(devices)})
    if not items:
        with pytest.raises(ArgumentError):
            Ring(items)
        return
    Ring(items)
    assert {chip: chip.diagnostic_outputs.rd for chip in expected} == expected
    assert all(chip.following is not rd for chip, rd in expected.items())
    for chip in expected:  # what the chip's own life does (power-up, resets, time-outs) keeps the wiring
        chip.power_up()
        chip.reset(0.001)
        chip.line_timeout(0.002)
    assert {chip: chip.diagnostic_outputs.rd for chip in expected} == expected


# -- histories at pin level -----------------------------------------------------------------------------------------

_SEGMENT = st.tuples(st.sampled_from(["quiet", "follow", "power_up", "vmon", "reset", "follow_off"]),
                     st.integers(1, 100))
"""A stretch of the board: nothing, DI2/RBST_EXT high (a following device), /ResU pulled low (power-up), the supply
dipping, the start level long enough for an INTERBUS reset, a following device going away."""


def _history(segments: list[tuple[str, int]], reset_run: int) -> Columns:
    parts: list[Columns] = []
    following = 0
    for kind, n in segments:
        if kind == "reset":
            n += reset_run
        part = quiet_inputs(n)
        following = {"follow": 1, "follow_off": 0}.get(kind, following)
        part["di2"][:] = part["rbst_ext"][:] = following
        if kind == "power_up":
            part["resu_n"][:] = 0
        elif kind == "vmon":
            part["vmon_ok"][:] = 0
        elif kind == "reset":
            part["do1"][:] = 0
        parts.append(part)
    return {name: np.concatenate([p[name] for p in parts]) for name in parts[0]}


@settings(max_examples=12)
@given(rf=st.sampled_from(["11", "10"]), segments=st.lists(_SEGMENT, min_size=1, max_size=5),
       cuts=st.lists(st.floats(0.05, 0.95), max_size=3))  # fmt: skip
def test_rd_is_not_following_over_any_history(rf: str, segments: list[tuple[str, int]], cuts: list[float]) -> None:
    # Any sequence of power-ups, supply dips, INTERBUS resets and DI2/RBST_EXT changes: step() == run() cycle for
    # cycle, run() cut anywhere; RD (DIAG2, complete diagnostics) is always the negation of the chip's recognition
    # as the outputs of the cycle show it (the register after the previous edge), and the transaction-level view
    # agrees (DG-5).
    config = decode("10000", rf=rf, diag_conf=0)
    stepped, bulk = Supi3Pins(config), Supi3Pins(config)
    inputs = _history(segments, stepped.reset_run)
    names, n = list(inputs), len(inputs["do1"])
    rows, recognised = [], [stepped.chip.following]
    for values in zip(*(inputs[name].tolist() for name in names), strict=True):
        rows.append(stepped.step(dict(zip(names, values, strict=True))))
        recognised.append(stepped.chip.following)
    bounds = sorted({0, n, *(int(n * cut) for cut in cuts)})
    pieces = [bulk.run({k: v[a:b] for k, v in inputs.items()}) for a, b in itertools.pairwise(bounds)]
    for name in rows[0]:
        got = np.concatenate([piece[name] for piece in pieces])
        want = np.array([row[name] for row in rows])
        assert np.array_equal(got, want), (name, np.flatnonzero(got != want)[:3], segments)
    rd = np.array([row["diag2"] for row in rows])
    assert np.array_equal(rd, np.logical_not(recognised[:-1]).astype(np.int64)), (segments,)
    assert bulk.chip.following == stepped.chip.following
    assert bulk.chip.diagnostic_outputs.rd == (not bulk.chip.following)


# -- a BK's branch over any history ---------------------------------------------------------------------------------

LBST, CONF = 1 << LBST_PIN, 1 << CONF_PIN
LD_PIN, E_PIN = 14, 13  # Table 2-8: LBDA ("local bus disabled"), ERROR
SILENCE = 1500
"""The branch silence limit in clocks for these histories (BK-3's 10 ms is 320,000; ``branch_silence``)."""
BRANCH_DELAY = 37
"""Clocks from DO3 back to DI3 through the branch (any will do: DI3 is stimulus)."""

_BK_EVENT = st.one_of(
    st.tuples(st.just("command"), st.sampled_from(list(BranchControl)), st.booleans()),
    st.tuples(st.just("data"), st.integers(1, 3), st.booleans()),
    st.tuples(st.just("conf"), st.booleans(), st.booleans()),
)
"""A latched command (branch control, acknowledge), data cycles with DI3 repeating or silent, CONF set or cleared."""


def _bk_history(events: list[tuple[str, object, bool]], seed: int) -> Columns:
    script = CoreScript(decode(BK_STRAPS["BK-LB"], rf="10", clk_conf="11"), np.random.default_rng(seed))
    mfp = LBST
    script.pins["mfp_in"] = mfp
    script.bring_up()
    silent: list[tuple[int, int]] = []
    for kind, value, flag in events:
        start = len(script.columns()["do1"])
        if kind == "command":
            assert isinstance(value, BranchControl)
            script.id_cycle(wire.command_word(branch=value, quit_peripheral_error=flag), mfp_in=mfp)
        elif kind == "data":
            assert isinstance(value, int)
            for _ in range(value):
                script.data_cycle(mfp_in=mfp)
            if flag:
                silent.append((start, len(script.columns()["do1"])))
        else:
            mfp = mfp | CONF if value else mfp & ~CONF
            script.pins["mfp_in"] = mfp
            script.strobe(mfp_in=mfp)
    columns = script.inputs()
    n = len(columns["do1"])
    di3 = np.ones(n, dtype=np.int64)
    di3[BRANCH_DELAY:] = columns["do1"][: n - BRANCH_DELAY]
    for a, b in silent:
        di3[a:b] = wire.IDLE_LEVEL
    columns["mfp_in"] = columns["mfp_in"] & ~(1 << DI3_PIN) | di3 << DI3_PIN
    return columns


@pytest.mark.slow  # about 6 s: every clock stepped
@settings(max_examples=4)
@example(events=[("command", BranchControl.ON_EXTENDED, False), ("data", 3, True), ("conf", True, False),
                 ("command", BranchControl.ON, True)], seed=1, cuts=[0.5])  # closed by the silence, then reopened
@given(events=st.lists(_BK_EVENT, min_size=1, max_size=6), seed=st.integers(0, 9),
       cuts=st.lists(st.floats(0.05, 0.95), max_size=2))  # fmt: skip
def test_the_bk_state_and_its_leds_agree_over_any_history(events: list[tuple[str, object, bool]], seed: int,
                                                          cuts: list[float]) -> None:  # fmt: skip
    # Any sequence of branch commands (on, off, on with the extended function, none; acknowledged or not), CONF
    # edges and DI3 silences (some longer than the short limit: the extended function closes the branch, BK-3):
    # step() == run() cycle for cycle; in every cycle LD and E on the pins are those of the BK state held after the
    # previous edge (BK-11), and run() ends in the same state as step().
    columns = _bk_history(events, seed)
    config = decode(BK_STRAPS["BK-LB"], rf="10", clk_conf="11")
    stepped, bulk = Supi3Pins(config, branch_silence=SILENCE), Supi3Pins(config, branch_silence=SILENCE)
    def state() -> Terminal:  # a power-up makes the chip's BK anew
        assert stepped.chip.bus_terminal is not None
        return stepped.chip.bus_terminal.state

    names, n = list(columns), len(columns["do1"])
    rows, states = [], [state()]
    for values in zip(*(columns[name].tolist() for name in names), strict=True):
        rows.append(stepped.step(dict(zip(names, values, strict=True))))
        states.append(state())
    bounds = sorted({0, n, *(int(n * cut) for cut in cuts)})
    pieces = [bulk.run({k: v[a:b] for k, v in columns.items()}) for a, b in itertools.pairwise(bounds)]
    for name in rows[0]:
        got = np.concatenate([piece[name] for piece in pieces])
        want = np.array([row[name] for row in rows])
        assert np.array_equal(got, want), (name, np.flatnonzero(got != want)[:3], events)
    mfp_out = np.array([row["mfp_out"] for row in rows])
    assert np.array_equal(mfp_out >> LD_PIN & 1, [int(s.ld) for s in states[:-1]]), events
    assert np.array_equal(mfp_out >> E_PIN & 1, [int(s.e) for s in states[:-1]]), events
    assert bulk.chip.bus_terminal is not None and bulk.chip.bus_terminal.state == state()

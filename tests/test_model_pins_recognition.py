"""A bus terminal module recognises its branch by a device's answer on DI3 (manual 2.1.1, Tables 2-2, 2-8, 2-9;
BK-37, BK-41, BK-42): over any history of attaching and detaching the branch's device, LBST changes, INTERBUS resets
and power-up resets, the pin-level BK (:class:`~supi3.model.pins.Supi3Pins`) follows the reading every clock:

* ``connected`` latches the first start level (0) of the synchronised DI3 at a clock edge where the core's logic
  runs, and a power-up reset clears it (BK-37); a pulled-up DI3 with nothing attached never shows one (BK-41);
* DO3 (MFP9) carries the DO2 of a chip without branch (the same straps, DI3 at rest, LBST low) while the interface is
  live (BK-42: the branch open and present by Table 2-9 were a device answering) and idles else; DO2 repeats the
  synchronised DI3 while the branch is in the data path (Table 2-9 with ``connected``) and is that chip's else;
  each line switches between telegrams, within ``SWITCH_WINDOW`` of a change and idle meanwhile (BK-47).

The attached device answers as a following protocol chip does: it returns what DO3 sends, a repeater's delay later;
detached, DI3 reads the pull-up. run() equals step() on them, and the RTL core runs them in lockstep
(tests/test_rtl_core_branch.py).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.config import DeviceConfig, decode
from supi3.interbus import wire
from supi3.interbus.wire import BranchControl, Cycle
from supi3.model.pins import Supi3Pins
from supi3.pinout import SYNC_STAGES
from supi3.terminal import BRANCH_DRAIN_BITS, DI3_PIN, DO3_PIN, LBST_PIN, RF_CODES, TERMINAL_INTERFACES, branch_present
from support import BK_STRAPS, Columns, CoreScript, assert_run_matches_step

ANSWER_DELAY = 3 * 16 + 5
"""Clocks from DO3 back to DI3 through the attached device (a repeater's 3 bit periods at 2 Mbit/s, and a little)."""
POWER_DOWN_BITS = 3
"""Bit periods of a power-up reset (/ResU held low)."""

Op = tuple[str, int]
OPS = st.one_of(
    st.tuples(st.sampled_from(["attach", "detach", "reset", "power"]), st.just(0)),
    st.tuples(st.just("lbst"), st.integers(0, 1)),
    st.tuples(st.just("idle"), st.integers(1, 12)),
    st.tuples(st.just("switch"), st.sampled_from([control.value for control in BranchControl][1:])),
)  # fmt: skip
"""One step of a history: attach or detach the branch's device, an INTERBUS reset, a power-up reset, LBST to a level,
idle status telegrams, or a latched ID cycle whose command word switches the branch (BK-4: off, on, on extended)."""


def history(interface: str, rf: str, ops: Sequence[Op]) -> tuple[DeviceConfig, Columns, np.ndarray]:
    """The master's line and the board's pins of a history (each step followed by two idle status telegrams), and
    whether the device is attached in each clock. DI3 is filled in by :func:`close_loop`."""
    config = decode(BK_STRAPS[interface], rf=rf, clk_conf="11")
    script = CoreScript(config)
    script.pins["mfp_in"] = 1 << LBST_PIN
    script.bring_up()
    attached, marks = False, [(0, False)]
    for op, value in ops:
        start = sum(len(part["do1"]) for part in script.parts)
        if op in ("attach", "detach"):
            attached = op == "attach"
            marks.append((start, attached))
        elif op == "lbst":
            script.pins["mfp_in"] = value << LBST_PIN
        elif op == "reset":
            script.line(wire.reset_levels(1))
        elif op == "switch":
            script.id_cycle(wire.command_word(branch=BranchControl(value)))
        elif op == "power":
            script.line(np.ones(POWER_DOWN_BITS, dtype=np.uint8), resu_n=0).line(np.ones(1, np.uint8), resu_n=1)
        script.line(wire.status_levels(Cycle.DATA, False, value if op == "idle" else 2))
    columns = script.inputs()
    n = len(columns["do1"])
    device = np.zeros(n, dtype=bool)
    for (start, on), (end, _) in zip(marks, [*marks[1:], (n, False)], strict=True):
        device[start:end] = on
    return config, columns, device


SWITCH_WINDOW = 2 * wire.DATA_TELEGRAM_BITS + BRANCH_DRAIN_BITS + 2
"""Bit periods after a change of the BK state within which a branch line has switched (BK-47): up to a telegram to
leave the old line (DI3 once drained), up to a telegram to take the new one."""


def settled(change: np.ndarray, cpb: int, sent: np.ndarray | None = None) -> np.ndarray:
    """The cycles at least :data:`SWITCH_WINDOW` bit periods after the last change of the boolean trace ``change``
    and after the end of an INTERBUS reset (a start level held, A12) on ``sent``: a line waits for the end of it."""
    moved = np.zeros(len(change), dtype=bool)
    moved[1:] = change[1:] != change[:-1]
    if sent is not None:
        low = sent == wire.START_LEVEL
        ends = np.flatnonzero(low[:-1] & ~low[1:]) + 1
        began = np.maximum.accumulate(np.where(low & ~np.concatenate([[False], low[:-1]]), np.arange(len(low)), 0))
        moved[ends[ends - began[ends - 1] > wire.RESET_DETECT_BITS * cpb]] = True
        moved |= low & (np.arange(len(low)) - began > wire.RESET_DETECT_BITS * cpb)
    last = np.maximum.accumulate(np.where(moved, np.arange(len(change)), -SWITCH_WINDOW * cpb))
    return np.arange(len(change)) - last >= SWITCH_WINDOW * cpb


def line_problems(do2: np.ndarray, do3: np.ndarray, alone: np.ndarray, di3: np.ndarray, live: np.ndarray,
                  on: np.ndarray, cpb: int) -> list[str]:
    """BK-42, BK-47 on a BK's lines: DO3 is ``alone`` (the DO2 of a chip without branch) where the interface is
    ``live``, else idle; DO2 is the synchronised ``di3`` where the branch is ``on`` (in the data path), else
    ``alone``; exactly so from :data:`SWITCH_WINDOW` after a change, and within it one of the two or idle (the lines
    switch between telegrams)."""
    problems = []
    for name, line, want, sources in (("DO3", do3, np.where(live, alone, wire.IDLE_LEVEL), [alone]),
                                      ("DO2", do2, np.where(on, di3, alone), [di3, alone])):
        steady = settled(live if name == "DO3" else on, cpb, alone)
        wrong = np.flatnonzero(steady & (line != want)).tolist()
        stray = np.flatnonzero((line != wire.IDLE_LEVEL) & ~np.logical_or.reduce([line == s for s in sources]))
        problems += [f"{t}: {name} {line[t]}, want {want[t]}" for t in [*wrong[:3], *stray[:3].tolist()]]
    return problems


def close_loop(config: DeviceConfig, columns: Columns, device: np.ndarray) -> tuple[Columns, list[str]]:
    """Step a BK through ``columns`` with DI3 from the attached device (DO3 ``ANSWER_DELAY`` clocks before) or the
    pull-up, checking the reading every clock; the columns with DI3 filled in, and the rule violations found."""
    pins = Supi3Pins(config)
    n = len(columns["do1"])
    mfp = columns["mfp_in"].copy()
    alone = Supi3Pins(config).run({**columns, "mfp_in": mfp & ~(1 << LBST_PIN) | 1 << DI3_PIN})["do2"]
    do3 = np.ones(n, dtype=np.int64)
    do2 = np.ones(n, dtype=np.int64)
    live = np.zeros(n, dtype=bool)
    on = np.zeros(n, dtype=bool)
    di3s = np.ones(n, dtype=np.int64)
    names = [name for name in columns if name in {pin.name for pin in Supi3Pins.inputs}]
    connected = False
    table = np.array([[branch_present(_rf(config), bool(lbst), bool(c)) for c in (0, 1)] for lbst in (0, 1)])
    problems: list[str] = []
    for t in range(n):
        answer = int(do3[t - ANSWER_DELAY]) if device[t] and t >= ANSWER_DELAY else wire.IDLE_LEVEL
        mfp[t] = mfp[t] & ~(1 << DI3_PIN) | answer << DI3_PIN
        synced = int(mfp[t - SYNC_STAGES]) if t >= SYNC_STAGES else 0
        di3, lbst = synced >> DI3_PIN & 1, synced >> LBST_PIN & 1
        terminal = pins.chip.bus_terminal
        opened = terminal is not None and terminal.state.switched_on and not terminal.state.closed
        out = pins.step({name: int(columns[name][t]) if name != "mfp_in" else int(mfp[t]) for name in names})
        do3[t], do2[t], di3s[t] = out["mfp_out"] >> DO3_PIN & 1, out["do2"], di3
        running = pins.run_from <= t  # a power-up reset sends the transmitter's line on DO2 and idles DO3
        live[t], on[t] = running and opened and table[lbst, 1], running and opened and table[lbst, int(connected)]
        connected = (connected or di3 == wire.START_LEVEL) if running else False
        assert pins._branch is not None
        if pins._branch.connected != connected:
            problems.append(f"{t}: connected {pins._branch.connected}, the reading says {connected}")
    problems += line_problems(do2, do3, alone, di3s, live, on, pins.cpb)
    return {**columns, "mfp_in": mfp}, problems


def _rf(config: DeviceConfig) -> str:
    """The RF straps of a chip (Table 2-2)."""
    assert config.rf_mode is not None
    return config.rf_mode.rf


def random_history(seed: int) -> tuple[str, str, list[Op]]:
    """A BK interface, RF straps and 8 steps drawn from ``seed`` (the RTL lockstep's random histories)."""
    rng = np.random.default_rng(seed)
    kinds = ["attach", "detach", "reset", "power", "lbst", "idle", "switch"]
    ops: list[Op] = []
    for kind in rng.choice(kinds, 8).tolist():
        value = int(rng.integers(0, 2)) if kind == "lbst" else int(rng.integers(1, 13)) if kind == "idle" \
            else int(rng.integers(1, 4)) if kind == "switch" else 0
        ops.append((kind, value))
    return str(rng.choice(TERMINAL_INTERFACES)), str(rng.choice(RF_CODES)), ops


OFF, ON, EXTENDED = (control.value for control in BranchControl if control is not BranchControl.NONE)
FIXED: list[tuple[str, str, list[Op]]] = [
    ("BK-LB", "11", [("attach", 0), ("idle", 4), ("lbst", 0), ("detach", 0), ("reset", 0), ("attach", 0),
                     ("lbst", 1), ("idle", 3), ("power", 0), ("idle", 6)]),
    ("BK-LBD", "00", [("lbst", 0), ("idle", 3), ("attach", 0), ("idle", 3), ("detach", 0), ("power", 0),
                      ("lbst", 1), ("reset", 0)]),
    ("BK-LB", "11", [("attach", 0), ("idle", 2), ("switch", OFF), ("idle", 1), ("switch", EXTENDED), ("switch", OFF),
                     ("switch", ON), ("reset", 0), ("switch", OFF), ("reset", 0), ("idle", 2)]),
]  # fmt: skip
"""Histories the RTL core runs in lockstep too (every step of the reading on each), with :func:`random_history`'s."""


RANDOM_SEEDS = range(4)


@settings(max_examples=12, deadline=None, derandomize=True)
@given(st.sampled_from(TERMINAL_INTERFACES), st.sampled_from(RF_CODES), st.lists(OPS, min_size=1, max_size=8))
def test_the_bk_follows_the_reading_over_any_history(interface: str, rf: str, ops: list[Op]) -> None:
    """The reading every clock of any history; run() in pieces equals step() on it."""
    config, columns, device = history(interface, rf, ops)
    closed, problems = close_loop(config, columns, device)
    assert not problems, problems[:5]
    assert_run_matches_step(Supi3Pins(config), Supi3Pins(config), closed, [0.5])


def test_fixed_histories_recognise_and_forget() -> None:
    """The histories the RTL core also runs: the reading holds, the device answers only while attached (in the fixed
    ones DI3 shows start levels; never while detached), and run() in pieces equals step()."""
    for k, (interface, rf, ops) in enumerate([*FIXED, *map(random_history, RANDOM_SEEDS)]):
        config, columns, device = history(interface, rf, ops)
        closed, problems = close_loop(config, columns, device)
        assert not problems, problems[:5]
        di3 = closed["mfp_in"] >> DI3_PIN & 1
        assert (di3[~device] == wire.IDLE_LEVEL).all() and ((di3 == wire.START_LEVEL).any() or k >= len(FIXED))
        assert_run_matches_step(Supi3Pins(config), Supi3Pins(config), closed, [0.37, 0.61])

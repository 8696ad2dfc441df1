"""A bus terminal module recognises its branch by a device's answer on DI3 (manual 2.1.1, Tables 2-2, 2-8, 2-9;
BK-37, BK-41, BK-42): over any history of attaching and detaching the branch's device, LBST changes, INTERBUS resets
and power-up resets, the pin-level BK (:class:`~supi3.model.pins.Supi3Pins`) follows the reading every clock:

* ``connected`` latches the first start level (0) of the synchronised DI3 at a clock edge where the core's logic
  runs, and a power-up reset clears it (BK-37); a pulled-up DI3 with nothing attached never shows one (BK-41);
* DO3 (MFP9) carries the DO2 of a chip without branch (the same straps, DI3 at rest, LBST low) while the interface is
  live (BK-42: the branch open and present by Table 2-9 were a device answering) and idles else; DO2 repeats the
  synchronised DI3 while the branch is in the data path (Table 2-9 with ``connected``) and is that chip's else.

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
from supi3.interbus.wire import Cycle
from supi3.model.pins import Supi3Pins
from supi3.pinout import SYNC_STAGES
from supi3.terminal import DI3_PIN, DO3_PIN, LBST_PIN, RF_CODES, TERMINAL_INTERFACES, branch_present
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
)  # fmt: skip
"""One step of a history: attach or detach the branch's device, an INTERBUS reset, a power-up reset, LBST to a level,
or idle status telegrams."""


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
        elif op == "power":
            script.line(np.ones(POWER_DOWN_BITS, dtype=np.uint8), resu_n=0).line(np.ones(1, np.uint8), resu_n=1)
        script.line(wire.status_levels(Cycle.DATA, False, value if op == "idle" else 2))
    columns = script.inputs()
    n = len(columns["do1"])
    device = np.zeros(n, dtype=bool)
    for (start, on), (end, _) in zip(marks, [*marks[1:], (n, False)], strict=True):
        device[start:end] = on
    return config, columns, device


def close_loop(config: DeviceConfig, columns: Columns, device: np.ndarray) -> tuple[Columns, list[str]]:
    """Step a BK through ``columns`` with DI3 from the attached device (DO3 ``ANSWER_DELAY`` clocks before) or the
    pull-up, checking the reading every clock; the columns with DI3 filled in, and the rule violations found."""
    pins = Supi3Pins(config)
    n = len(columns["do1"])
    mfp = columns["mfp_in"].copy()
    alone = Supi3Pins(config).run({**columns, "mfp_in": mfp & ~(1 << LBST_PIN) | 1 << DI3_PIN})["do2"]
    do3 = np.ones(n, dtype=np.int64)
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
        do3[t] = out["mfp_out"] >> DO3_PIN & 1
        live, on = opened and table[lbst, 1], opened and table[lbst, int(connected)]
        if do3[t] != (alone[t] if live else wire.IDLE_LEVEL):
            problems.append(f"{t}: DO3 {do3[t]}, live {live}")
        if out["do2"] != (di3 if on else alone[t]):
            problems.append(f"{t}: DO2 {out['do2']}, in the data path {on}")
        connected = (connected or di3 == wire.START_LEVEL) if pins.run_from <= t else False
        assert pins._branch is not None
        if pins._branch.connected != connected:
            problems.append(f"{t}: connected {pins._branch.connected}, the reading says {connected}")
    return {**columns, "mfp_in": mfp}, problems


def _rf(config: DeviceConfig) -> str:
    """The RF straps of a chip (Table 2-2)."""
    assert config.rf_mode is not None
    return config.rf_mode.rf


def random_history(seed: int) -> tuple[str, str, list[Op]]:
    """A BK interface, RF straps and 8 steps drawn from ``seed`` (the RTL lockstep's random histories)."""
    rng = np.random.default_rng(seed)
    kinds = ["attach", "detach", "reset", "power", "lbst", "idle"]
    ops: list[Op] = []
    for kind in rng.choice(kinds, 8).tolist():
        value = int(rng.integers(0, 2)) if kind == "lbst" else int(rng.integers(1, 13)) if kind == "idle" else 0
        ops.append((kind, value))
    return str(rng.choice(TERMINAL_INTERFACES)), str(rng.choice(RF_CODES)), ops


FIXED: list[tuple[str, str, list[Op]]] = [
    ("BK-LB", "11", [("attach", 0), ("idle", 4), ("lbst", 0), ("detach", 0), ("reset", 0), ("attach", 0),
                     ("lbst", 1), ("idle", 3), ("power", 0), ("idle", 6)]),
    ("BK-LBD", "00", [("lbst", 0), ("idle", 3), ("attach", 0), ("idle", 3), ("detach", 0), ("power", 0),
                      ("lbst", 1), ("reset", 0)]),
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

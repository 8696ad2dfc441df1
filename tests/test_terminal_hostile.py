"""Hostile arguments to the bus terminal module's public entries (supi3.terminal, the pin block
supi3.model.blocks.terminal.TerminalBlock, the RTL supi3.rtl.terminal.TerminalRtl): a named ArgumentError
"X must be ..., not ..." (supi3.checks), never a traceback or a silent guess; and, over random input histories of the
block, the branch is never in the data path while the master has switched it off or the BK has closed it (manual
2.4, Table 2-9, BK-3, BK-4)."""

from __future__ import annotations

import re
from collections.abc import Callable

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3 import terminal as bk
from supi3.errors import ArgumentError
from supi3.interbus.wire import BranchControl
from supi3.model.blocks.terminal import TerminalBlock
from supi3.rtl.terminal import TerminalRtl
from supi3.terminal import BLOCK_INPUTS, Terminal, TerminalMode
from support import bad

S = Terminal()
QUIET = {pin.name: 0 for pin in BLOCK_INPUTS}
BAD_LIMITS = [0, -1, True, 1.5, "5", None, bk.BRANCH_SILENCE_CLOCKS + 1, 10**30]
BAD_FLAGS = [1, 0, None, "1", 1.0]
BAD_COUNTS = [True, -1, 64, 1.0, None, "3", np.float64(3)]

CASES: list[tuple[str, Callable[[], object], str]] = [
    *((f"TerminalBlock({t!r})", lambda t=t: TerminalBlock(t), "time_limit") for t in BAD_LIMITS),
    *((f"TerminalRtl({t!r})", lambda t=t: TerminalRtl(t), "time_limit") for t in BAD_LIMITS),
    *((f"branch_present lbst={v!r}", lambda v=v: bk.branch_present("10", v, True), "lbst") for v in BAD_FLAGS),
    *((f"branch_present connected={v!r}", lambda v=v: bk.branch_present("11", True, v), "connected")
      for v in BAD_FLAGS),
    *((f"rf_code({v!r})", lambda v=v: bk.rf_code(v), "rf") for v in ["12", 3, b"10", "", "1 0"]),
    *((f"rf_of({v!r})", lambda v=v: bk.rf_of(v), "rf") for v in [4, -1, True, 1.0, "1", None]),
    *((f"received({c!r})", lambda c=c: bk.received(S, c), "count") for c in BAD_COUNTS),
    *((f"Terminal(count={c!r})", lambda c=c: Terminal(count=c), "count") for c in BAD_COUNTS),
    *((f"Terminal(conf={v!r})", lambda v=v: Terminal(conf=v), "conf") for v in BAD_FLAGS),
    *((f"TerminalMode.of({v!r})", lambda v=v: TerminalMode.of(v), "interface") for v in [3, b"BK-RB", 1.0]),
    ("command branch int", lambda: bk.command(S, bad(1), False), "branch"),
    ("command acknowledge int", lambda: bk.command(S, BranchControl.OFF, bad(1)), "acknowledge"),
    ("command alarm int", lambda: bk.command(S, BranchControl.OFF, False, bad(1)), "alarm"),
    ("command state None", lambda: bk.command(bad(None), BranchControl.OFF, False), "state"),
    ("enabled state dict", lambda: bk.enabled(bad({}), "10", True, True), "state"),
    ("silence state None", lambda: bk.silence(bad(None)), "state"),
    ("watching state tuple", lambda: bk.watching(bad(())), "state"),
    ("reset state str", lambda: bk.reset(bad("S")), "state"),
    ("power_up 1", lambda: bk.power_up(bad(1)), "conf"),
    ("conf_level None", lambda: bk.conf_level(S, bad(None)), "conf"),
    ("restarts_silence 2", lambda: bk.restarts_silence(bad(2)), "branch"),
    ("step mode 4", lambda: TerminalBlock(5).step({**QUIET, "mode": 4}), "pin 'mode'"),
    ("step mode True", lambda: TerminalBlock(5).step({**QUIET, "mode": True}), "pin 'mode'"),
    ("step count 64", lambda: TerminalBlock(5).step({**QUIET, "mode": 1, "count": 64}), "pin 'count'"),
    ("step lbst None", lambda: TerminalBlock(5).step({**QUIET, "lbst": bad(None)}), "pin 'lbst'"),
    ("step rf -1", lambda: TerminalBlock(5).step({**QUIET, "rf": -1}), "pin 'rf'"),
    ("step conf 1.0", lambda: TerminalBlock(5).step({**QUIET, "conf": bad(1.0)}), "pin 'conf'"),
    ("step a pin missing", lambda: TerminalBlock(5).step({"mode": 1}), "inputs"),
    ("step an extra pin", lambda: TerminalBlock(5).step({**QUIET, "x": 0}), "inputs"),
    ("step None", lambda: TerminalBlock(5).step(bad(None)), "inputs"),
]


@pytest.mark.parametrize(("call", "name"), [(call, name) for _, call, name in CASES], ids=[c[0] for c in CASES])
def test_hostile_arguments_give_named_errors(call: Callable[[], object], name: str) -> None:
    with pytest.raises(ArgumentError, match=rf"^{re.escape(name)} must be .*, not ") as caught:
        call()
    assert caught.value.name == name


def test_numpy_integers_pass_as_integers() -> None:
    """numpy integers are integers (supi3.checks): accepted wherever an int is, never refused as a wrong type."""
    assert TerminalBlock(bad(np.int64(5))).time_limit == 5
    assert bk.rf_of(bad(np.int64(1))) == "01" and bk.received(S, bad(np.int16(3))).count == 3


def test_a_refused_step_changes_nothing() -> None:
    block = TerminalBlock(5)
    block.step({**QUIET, "mode": 1})
    block.step({**QUIET, "mode": 1, "cmd_valid": 1, "branch": BranchControl.OFF.value})
    before = (block.state, block.timer, block.cycle)
    with pytest.raises(ArgumentError):
        block.step({**QUIET, "mode": 1, "cmd_valid": 1, "branch": 4})
    assert (block.state, block.timer, block.cycle) == before


ROWS = st.fixed_dictionaries(
    {pin.name: st.integers(0, (1 << pin.width) - 1) for pin in BLOCK_INPUTS if pin.name != "mode"}
    | {"mode": st.sampled_from([1, 2, 3, 3, 0])}
)


@settings(max_examples=60)
@given(st.lists(ROWS, min_size=1, max_size=60), st.integers(1, 4))
def test_the_branch_is_never_enabled_while_switched_off_or_closed(rows: list[dict[str, int]], limit: int) -> None:
    """Any history of block inputs (every pin random, strobes and resets included, a short silence limit so the
    extended function closes branches): ``enabled`` is 1 only while the state before the cycle has the branch
    switched on and not closed, and then LD (MFP14) is off (BK-4, BK-3, BK-11); outside a BK mode every output
    is 0."""
    block = TerminalBlock(limit)
    for row in rows:
        state = block.state
        out = block.step(row)
        if row["mode"] == TerminalMode.NONE:
            assert not any(out.values())
        elif out["enabled"]:
            assert state.switched_on and not state.closed and not out["ld"]
        assert 0 <= out["status"] <= 0xFF and block.timer < limit

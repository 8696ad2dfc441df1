"""Hostile inputs and histories against the last session's tree, branch and diagnostic entries and issue 12's chip
optics (a user's review, round 6): the tree helpers :func:`supi3.interbus.ring.terminal_positions` and
:func:`~supi3.interbus.ring.return_inputs` (BK-52), :meth:`~supi3.interbus.ring.Ring.cut` histories (3.4.14),
:mod:`supi3.diagnostics` (Tables 3-16, 2-8), :meth:`supi3.terminal.TerminalMode.of` (Table 2-7), ``bench/
closure_sweep.py`` (BK-50, BK-3), and the chip's transaction-level optical API on a chip without a branch interface
(OPT-55) or whose optical block runs at pin level (OPT-26).

Every bad input is refused by name (which argument, which rule, which value) and changes nothing; an optical history
with refused calls in it ends where the same history without them ends; a cycle broken by a cut latches nothing.
"""

from __future__ import annotations

import itertools
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.config import Interface as ConfigInterface
from supi3.config import decode
from supi3.diagnostics import bus_terminal_mfp, diag_pins
from supi3.errors import ArgumentError
from supi3.interbus.master import Master
from supi3.interbus.ring import Branch, BranchKind, Ring, return_inputs, terminal_positions
from supi3.model.chip import ChipArgumentError, ChipError, Supi3
from supi3.model.pins import Supi3Pins
from supi3.optical.length import Medium
from supi3.optical.regulation import Interface, Response
from supi3.terminal import BRANCH_SILENCE_CLOCKS, TerminalMode
from support import BK_STRAPS, bad
from test_model_pinring_tree import tl_tree

ROOT = Path(__file__).resolve().parent.parent


def small_tree() -> list[Supi3 | Branch]:
    """An RB device, a BK-LBD with two LBD-MR devices, an RB device: BK at 2, return inputs at 1, 2 and 3."""
    return [Supi3(decode("10000")), Branch(Supi3(decode(BK_STRAPS["BK-LBD"])),
                                           [Supi3(decode("11000")), Supi3(decode("11000"))], BranchKind.LBD_MR),
            Supi3(decode("10000"))]  # fmt: skip


# The tree helpers (BK-52) ----------------------------------------------------------------------------------------


def test_tree_helpers_on_a_good_tree() -> None:
    tree = small_tree()
    assert terminal_positions(tree) == {2}
    assert terminal_positions(tree, 5) == {6}
    assert return_inputs(tree) == {1, 2, 3}
    assert return_inputs(tree, returns=False) == {3}


FIRST = "first must be an integer from 1 to 512"
TREE_CALLS: list[tuple[str, Callable[[], object], str]] = [
    ("positions None", lambda: terminal_positions(bad(None)), "items must be a sequence of devices"),
    ("positions int", lambda: terminal_positions(bad(3)), "items must be a sequence of devices"),
    ("positions str", lambda: terminal_positions(bad("ab")), "items must be a sequence of devices"),
    ("positions of ints", lambda: terminal_positions(bad([1, 2])), "items must be a sequence of devices"),
    ("positions first 0", lambda: terminal_positions(small_tree(), 0), FIRST),
    ("positions first True", lambda: terminal_positions(small_tree(), True), FIRST),
    ("positions first str", lambda: terminal_positions(small_tree(), bad("1")), FIRST),
    ("positions first float", lambda: terminal_positions(small_tree(), bad(1.0)), FIRST),
    ("inputs None", lambda: return_inputs(bad(None)), "items must be a sequence of devices"),
    ("inputs tuple of str", lambda: return_inputs(bad(("a",))), "items must be a sequence of devices"),
    ("inputs first -1", lambda: return_inputs(small_tree(), -1), FIRST),
    ("inputs first 513", lambda: return_inputs(small_tree(), 513), FIRST),
    ("inputs returns int", lambda: return_inputs(small_tree(), 1, bad(1)), "returns must be True or False"),
    ("inputs returns None", lambda: return_inputs(small_tree(), 1, bad(None)), "returns must be True or False"),
]  # fmt: skip


@pytest.mark.parametrize(("call", "message"), [c[1:] for c in TREE_CALLS], ids=[c[0] for c in TREE_CALLS])
def test_tree_helpers_refuse_by_name(call: Callable[[], object], message: str) -> None:
    """Found in round 6: a wrong ``items`` was a TypeError traceback, a ``first`` of 0, -1 or True a silent guess."""
    with pytest.raises(ArgumentError, match=message):
        call()


# supi3.diagnostics (Tables 3-16, 2-8) ------------------------------------------------------------------------------


@pytest.mark.parametrize("complete", [False, True])
@pytest.mark.parametrize("index", range(1, 5))
@pytest.mark.parametrize("value", [None, 1, "1", 0.0])
def test_diag_pins_checks_the_levels_not_shown(complete: bool, index: int, value: object) -> None:
    """Found in round 6: with complete diagnostics FO1/FO2 were not checked (nor BA/RD without): a garbage level was
    a silent guess. Every level is refused by name whatever DIAG_CONF shows."""
    args: list[object] = [complete, True, False, True, False]
    args[index] = value
    name = ("complete", "ba", "rd", "fo1", "fo2")[index]
    with pytest.raises(ArgumentError, match=f"{name} must be"):
        diag_pins(*args)  # type: ignore[arg-type]


def test_diag_pins_every_level() -> None:
    """Table 3-16 over all 32 inputs: BA/RD with complete diagnostics, FO1/FO2 without."""
    for bits in range(32):
        complete, ba, rd, fo1, fo2 = (bool(bits >> k & 1) for k in range(5))
        assert diag_pins(complete, ba, rd, fo1, fo2) == ((int(ba), int(rd)) if complete else (int(fo1), int(fo2)))


@pytest.mark.parametrize("bus_terminal", [False, True])
@pytest.mark.parametrize("index", range(1, 5))
def test_bus_terminal_mfp_checks_the_levels_on_every_chip(bus_terminal: bool, index: int) -> None:
    """Found in round 6: on a chip that is no BK the four levels were not checked at all (0 for any garbage)."""
    args: list[object] = [bus_terminal, False, False, False, False]
    args[index] = "yes"
    name = ("bus_terminal", "alarm", "ld", "e", "fo3")[index]
    with pytest.raises(ArgumentError, match=f"{name} must be"):
        bus_terminal_mfp(*args)  # type: ignore[arg-type]
    assert bus_terminal_mfp(False, True, True, True, True) == 0
    assert bus_terminal_mfp(True, True, True, True, True) == 0xE100


# supi3.terminal (Table 2-7) -------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["BK_RB", "bk-rb", "BK-RB ", "", "none", "BK-LBD-MR"])
def test_terminal_mode_refuses_a_name_that_is_no_interface(name: str) -> None:
    """Found in round 6: a misspelt interface ("BK_RB", "bk-rb") was silently no BK (:attr:`TerminalMode.NONE`)."""
    with pytest.raises(ArgumentError, match=r"interface must be one of 'RB', .* \(supi3.config.Interface\)"):
        TerminalMode.of(name)


def test_terminal_mode_of_every_interface() -> None:
    """Table 2-7: the three BK interfaces have their modes; every other interface of the chip, and None, none."""
    modes = {interface: TerminalMode.of(interface.value) for interface in ConfigInterface}
    assert {i.value: m for i, m in modes.items() if m is not TerminalMode.NONE} == {
        "BK-RB": TerminalMode.RB, "BK-LB": TerminalMode.LB, "BK-LBD": TerminalMode.LBD}  # fmt: skip
    assert TerminalMode.of(None) is TerminalMode.NONE


# bench/closure_sweep.py ------------------------------------------------------------------------------------------


def test_closure_sweep_refuses_a_silence_above_bk3() -> None:
    """Found in round 6: a stop above BK-3's 10 ms (320,000 clocks) ran into the chip's refusal as a traceback; the
    script now refuses it on the command line (exit 2, one line naming the limit) before any run."""
    done = subprocess.run([sys.executable, str(ROOT / "bench" / "closure_sweep.py"),
                           "--stop", str(BRANCH_SILENCE_CLOCKS + 1)], capture_output=True,
                          text=True, timeout=120, cwd=ROOT, check=False)  # fmt: skip
    assert done.returncode == 2
    assert "Traceback" not in done.stderr
    assert f"must be at most {BRANCH_SILENCE_CLOCKS} clocks" in done.stderr.splitlines()[-1]
    assert done.stdout == ""


# The chip's optical API: no branch outside the BK modes (OPT-55), none at pin level (OPT-26) ------------------------


def test_pin_level_chip_refuses_the_transaction_level_optics() -> None:
    """Found in round 6: ``Supi3Pins(...).chip.optical_start`` put the chip in a hold and a 6 ms budget of its own
    while its pin-level block stayed off (the two apart, silently). Each call is refused by name; nothing changes."""
    pins = Supi3Pins(decode("10011", "1110", rf="00", clk_conf="11"))
    chip = pins.chip
    calls: list[Callable[[], None]] = [
        lambda: chip.optical_start((True, True, False), 0.0),
        lambda: chip.optical_init_response(Interface.OUT, Response.DETECTED),
        chip.optical_init_timeout,
        lambda: chip.optical_length(Interface.OUT, 40, Medium.POLYMER),
        lambda: chip.optical_test(Interface.IN, False, False),
    ]
    before = (chip.optical, chip.optical_holding, chip.due)
    for call in calls:
        with pytest.raises(ChipError, match=r"pin-level chip \(Supi3Pins, OPT-26\)"):
            call()
        assert (chip.optical, chip.optical_holding, chip.due) == before


OPTICAL_CALLS = st.one_of(
    st.tuples(st.just("start"), st.tuples(st.booleans(), st.booleans(), st.booleans())),
    st.tuples(st.just("response"), st.sampled_from(list(Interface)), st.sampled_from(list(Response))),
    st.tuples(st.just("test"), st.sampled_from(list(Interface)), st.booleans(), st.booleans()),
    st.tuples(st.just("length"), st.sampled_from([Interface.OUT, Interface.BRANCH]), st.integers(0, 3000)),
    st.tuples(st.just("timeout")),
    st.tuples(st.just("wait"), st.floats(0.0, 8e-3)),
)


def apply(chip: Supi3, name: object, args: list[object], now: float) -> None:
    """One call of an optical history at bus time ``now``."""
    if name == "start":
        chip.optical_start(bad(args[0]), now)
    elif name == "response":
        chip.optical_init_response(bad(args[0]), bad(args[1]))
    elif name == "test":
        chip.optical_test(bad(args[0]), bad(args[1]), bad(args[2]))
    elif name == "length":
        chip.optical_length(bad(args[0]), bad(args[1]), Medium.POLYMER)
    elif name == "timeout":
        chip.optical_init_timeout()
    else:
        chip.poll(now + bad(args[0]))


@settings(max_examples=60, derandomize=True, deadline=None)
@given(c=st.sampled_from(["10000", "11000", "01000"]), history=st.lists(OPTICAL_CALLS, max_size=25))
def test_refused_branch_calls_leave_no_trace(c: str, history: list[tuple[object, ...]]) -> None:
    """OPT-55 over histories: on a chip without a branch interface every start with the branch in use and every
    branch length is refused by name; the chip ends as a twin given the same history without those calls (status,
    hold, budget, ATTN)."""
    chip, twin = Supi3(decode(c, rf="00")), Supi3(decode(c, rf="00"))
    now = 0.0
    for name, *args in history:
        refused = (name == "start" and args[0][2]) or (name == "length" and args[0] is Interface.BRANCH)  # type: ignore[index]
        if refused:
            with pytest.raises(ChipArgumentError, match="OPT-55"):
                apply(chip, name, args, now)
        else:
            apply(chip, name, args, now)
            apply(twin, name, args, now)
        if name == "wait":
            now += args[0]  # type: ignore[operator]
        assert (chip.optical, chip.optical_holding, chip.due, chip.attention) == (
            twin.optical, twin.optical_holding, twin.due, twin.attention)  # fmt: skip
        assert chip.optical[Interface.BRANCH].phase.value == "off"
        assert chip.optical.length[1] == 0


# Ring.cut histories: a broken cycle latches nothing (BK-52) ------------------------------------------------------


def latched(ring: Ring) -> list[tuple[int, bool]]:
    """Every chip's OUT data and bus active, in ring order."""
    chips = [d for d in ring.devices if isinstance(d, Supi3)]
    assert len(chips) == len(ring.devices)
    return [(chip.out_word, chip.bus_active) for chip in chips]


@pytest.mark.parametrize("kind", list(BranchKind))
def test_a_cycle_broken_by_any_cut_latches_nothing(kind: BranchKind) -> None:
    """Every line :meth:`~supi3.interbus.ring.Ring.cut` accepts in a tree (RB device, BK with 3 devices of ``kind``,
    RB device; forward lines, the return line into the master at N + 1 (BK-61), return inputs, the BK's branch return
    input), cut after three good cycles: the cycle that fails changes no device's OUT data or bus active (3.4.14: data
    are taken over only after a valid check sequence); the lines it refuses are refused by name."""
    failed = 0
    for position, forward, branch in itertools.product(range(1, 9), (True, False), (False, True)):
        ring = tl_tree(kind, 3)
        master = Master(ring)
        assert master.start().ok
        for _ in range(3):
            assert master.cycle().ok
        tree = ring._tree
        if not forward and position not in (terminal_positions(tree) if branch else return_inputs(tree)):
            with pytest.raises(ArgumentError, match="position must be"):
                ring.cut(position, forward, branch=branch)
            continue
        if (forward and branch) or position > len(ring.devices) + forward:
            with pytest.raises(ArgumentError, match="position must be"):
                ring.cut(position, forward, branch=branch)
            continue
        ring.cut(position, forward, branch=branch)
        before = latched(ring)
        for entry in master.config or ():
            master.set_outputs(entry.number, b"\xa5" * entry.data_bytes)
        if not master.cycle().ok:
            failed += 1
            assert latched(ring) == before, (position, forward, branch)
    assert failed >= 5

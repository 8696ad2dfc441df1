"""Hostile inputs against the public entries added on 2026-12-02 (a user's review, round 8): the shared time base's
:func:`supi3.pinout.time_base_ticks` and :func:`~supi3.pinout.time_base_end` (M24), the lockstep's ``reset_cycles``
and ``window`` (:class:`supi3.verif.lockstep.Lockstep`, :func:`supi3.verif.cocotb_lockstep.lockstep`, M23), a tree's
data path :func:`supi3.interbus.wake.path_lags` and the ``lags`` of :func:`~supi3.interbus.wake.wake_window` (M25), and
``bench/wake_tree_sweep.py``'s command line; and what held: :meth:`Ring.cut <supi3.interbus.ring.Ring.cut>` at N + 1
and N + 2 (BK-61), a bad SET after a good one (UP-40), ``bench/wake_flat_sweep.py``'s command line.

Every bad input is refused by name (which argument, which rule, which value).
"""

from __future__ import annotations

import asyncio
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from supi3.config import decode
from supi3.errors import ArgumentError
from supi3.interbus.ring import Ring
from supi3.interbus.wake import path_lags, wake_window
from supi3.model.chip import Supi3
from supi3.model.registers import RegisterFile, SetRegisterError
from supi3.pinlevel import PinSpecError
from supi3.pinout import TIME_BASE_BITS, time_base_end, time_base_ticks
from supi3.regmap import SET
from supi3.verif.cocotb_lockstep import lockstep
from supi3.verif.lockstep import Lockstep
from support import bad

ROOT = Path(__file__).resolve().parent.parent

# -- the shared time base (M24) ---------------------------------------------------------------------------------------


@pytest.mark.parametrize(("call", "name"), [
    (lambda: time_base_ticks(bad(0)), "clocks"),
    (lambda: time_base_ticks(bad(-5)), "clocks"),
    (lambda: time_base_ticks(bad(True)), "clocks"),
    (lambda: time_base_ticks(bad(2.5)), "clocks"),
    (lambda: time_base_ticks(bad("3")), "clocks"),
    (lambda: time_base_ticks(bad(None)), "clocks"),
    (lambda: time_base_ticks(5, bad(-1)), "bits"),
    (lambda: time_base_ticks(5, bad(True)), "bits"),
    (lambda: time_base_ticks(5, bad(2.0)), "bits"),
    (lambda: time_base_end(bad(-3), 5), "start"),
    (lambda: time_base_end(bad(1.5), 5), "start"),
    (lambda: time_base_end(bad(None), 5), "start"),
    (lambda: time_base_end(0, bad(0)), "clocks"),
])  # fmt: skip
def test_the_time_base_refuses_what_is_no_count_of_clocks(call: object, name: str) -> None:
    """Found in round 8: ``time_base_ticks(0)``, ``(-5)`` and ``(True)`` gave 1 tick, ``(2.5)`` 2.0 ticks,
    ``time_base_end(-3, 5)`` clock 32767 and ``time_base_end(1.5, 5)`` 65535.0; a negative ``bits`` ended in a
    ValueError (negative shift count), a string or ``None`` in a TypeError."""
    assert callable(call)
    with pytest.raises(ArgumentError, match=rf"^{name} must be an integer >= \d \(M24\)"):
        call()


def test_the_time_base_takes_numpy_integers_as_ints() -> None:
    """Every count from 1 to two periods at a small base agrees with its numpy twin, and ``end`` is a tick's clock."""
    for clocks in range(1, 17):
        assert time_base_ticks(bad(np.int64(clocks)), bad(np.int8(3))) == time_base_ticks(clocks, 3)
        end = time_base_end(bad(np.uint16(5)), bad(np.int32(clocks)), 3)
        assert type(end) is int and end % 8 == 7 and end - 5 + 1 >= clocks
    assert time_base_ticks(1 << TIME_BASE_BITS) == 2


# -- the lockstep's reset (M23) ---------------------------------------------------------------------------------------

BAD_CYCLES = [({"reset_cycles": -1}, "reset_cycles"), ({"reset_cycles": True}, "reset_cycles"),
              ({"reset_cycles": 1.0}, "reset_cycles"), ({"window": True}, "window"), ({"window": 2.5}, "window"),
              ({"window": None}, "window"), ({"window": 0}, "window")]  # fmt: skip


@pytest.mark.parametrize(("kwargs", "name"), BAD_CYCLES)
def test_lockstep_refuses_cycles_that_are_no_count(kwargs: dict[str, object], name: str) -> None:
    """Found in round 8: ``Lockstep(window=True)`` and ``window=2.5`` were taken (the comparator's build parameter),
    ``window=None`` ended in a TypeError, and a numpy ``reset_cycles`` was refused while a numpy ``window`` passed;
    the cocotb lockstep took ``reset_cycles=-1`` (reset asserted, no edge) and ended ``1.5`` in a TypeError after the
    clock started."""
    with pytest.raises(PinSpecError, match=rf"^{name} must be an integer from [01], not "):
        Lockstep(bad(None), bad(None), **bad(kwargs))
    with pytest.raises(PinSpecError, match=rf"^{name} must be an integer from [01], not "):
        asyncio.run(lockstep(None, bad(None), np.zeros((1, 1), np.uint8), **bad(kwargs)))


# -- a tree's data path (M25) -----------------------------------------------------------------------------------------


@pytest.mark.parametrize(("branches", "rule"), [
    (None, "a sequence of"),
    (5, "a sequence of"),
    ([(0, 2, 0), (0, 2, 0)], "one branch a BK, nested or disjoint"),
    ([(0, 3, 0), (1, 4, 0)], "one branch a BK, nested or disjoint"),
    ([(1, 4, 0), (0, 3, 0)], "one branch a BK, nested or disjoint"),
])  # fmt: skip
def test_path_lags_refuses_branches_that_are_no_tree(branches: object, rule: str) -> None:
    """Found in round 8: ``branches=None`` or an int ended in a TypeError (not iterable); one BK's branch given twice
    added its return line twice, and crossing branches (no tree) were summed silently."""
    with pytest.raises(ArgumentError, match=rf"^branches must be {rule}.*\(M25\)"):
        path_lags(500_000, 5, bad(branches))


def test_path_lags_takes_nested_and_disjoint_branches_in_any_order() -> None:
    """A tree's branches nest or lie side by side; their order does not matter."""
    for branches in ([(0, 4, 1), (1, 3, 0)], [(0, 2, 0), (2, 5, 1)]):
        assert path_lags(500_000, 5, branches) == path_lags(500_000, 5, branches[::-1])


def test_wake_window_refuses_lags_before_the_master_s_line() -> None:
    """Found in round 8: ``lags=[-10, 5, 9]`` (a chip's input before the master's line) gave a window."""
    with pytest.raises(ArgumentError, match=r"^lags must be 3 increasing integer clocks from 0 .*\[-10, 5, 9\]"):
        wake_window(500_000, 2, {0: 0}, bad([-10, 5, 9]))
    assert wake_window(500_000, 2, {0: 0}, path_lags(500_000, 2)) == wake_window(500_000, 2, {0: 0})


# -- what held: the return line into the master (BK-61) and a bad SET after a good one (UP-40) -----------------------


def test_a_cut_past_the_return_line_into_the_master_is_refused() -> None:
    """``cut(N + 1, True)`` is the return line into the master (BK-61); N + 1 backwards or as a branch, and N + 2,
    are no line of the ring."""
    ring = Ring([Supi3(decode("10011", "1110")) for _ in range(2)], bit_rate=500_000)
    for position, forward, branch in [(4, True, False), (3, False, False), (3, True, True)]:
        with pytest.raises(ArgumentError, match=r"^position must be an integer from 1 to [23] "):
            ring.cut(position, forward, branch=branch)
    ring.cut(bad(np.int64(3)), True)


def test_a_bad_set_after_a_good_one_leaves_the_device_unconfigured_until_the_next_good_one() -> None:
    """UP-40: each reserved SET (Tables 3-11, 3-12) after a good one drops the configuration (ID 38h, no data), the next
    good one restores it; SET reads back as written."""
    registers = RegisterFile(decode("10011", "1110"), strict=False)
    for value in (0x86, 0x87, 0xCA):
        registers.cpu_write(SET.address, 0x85)
        assert (registers.configured, registers.data_bits(), registers.bus_id_register()) == (True, 32, 0x200)
        assert registers.latch(bytes(4)) == bytes(4)
        registers.cpu_write(SET.address, value)
        assert isinstance(registers.violations.records[-1], SetRegisterError)
        assert (registers.configured, registers.data_bits(), registers.bus_id_register()) == (False, 0, 0x38)
        assert (registers.in_bytes(), registers.latch(b""), registers.cpu_read(SET.address)) == (b"", b"", value)


# -- the benches' command lines ---------------------------------------------------------------------------------------


@pytest.mark.parametrize(("script", "argv", "message"), [
    ("wake_tree_sweep.py", ["trace", "--position", "0"], "--position must be a physical position from 1 to 6"),
    ("wake_tree_sweep.py", ["trace", "--devices", "1", "--position", "5"], "from 1 to 4 (--devices 1), not 5"),
    ("wake_tree_sweep.py", ["window", "--pos", "2"], "--position is for trace only, not window"),
    ("wake_tree_sweep.py", ["trace", "--max-k=3"], "--max-k is for initial and power only, not trace"),
    ("wake_tree_sweep.py", ["initial", "--rate", "500000"], "--rate is for window and trace only, not initial"),
    ("wake_flat_sweep.py", ["sideways"], "argument sweep: invalid choice: 'sideways'"),
])  # fmt: skip
def test_the_wake_sweeps_refuse_a_bad_command_line(script: str, argv: list[str], message: str) -> None:
    """Found in round 8: ``trace --position 0`` (or past the tree) ended in a traceback (exit 1) after the tree's idle
    telegrams, and ``window --position 2`` swept the window for a minute ignoring the option."""
    done = subprocess.run([sys.executable, str(ROOT / "bench" / script), *argv], capture_output=True, text=True,
                          cwd=ROOT, timeout=120, check=False)  # fmt: skip
    last = done.stderr.splitlines()[-1]
    assert (done.returncode, done.stdout, "Traceback" in done.stderr) == (2, "", False) and message in last, done.stderr

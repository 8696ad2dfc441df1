"""Hostile inputs and histories against what round 5 added (the lead's review of ``d47ba9f..6b33f0f``):
``PinRing.cut(..., branch=True)`` and ``Transfer.devices`` of a pin-level tree (BK-1, BK-10), ``stat_err_filter`` on
``Supi3``, ``Supi3Chip`` and ``Board`` (3.6.2, MCU-24), ``Board(fidelity="pin", others=...)`` and its ring (MCU-23),
``run_firmware``'s ``devices`` at pin level, ``Bench.advance`` and ``Bench``'s ``others``, ``ViolationLog.hold`` and
``release``, ``PinRing.idle``'s memory over a long idle, ``bench/bench_side.py``'s command line and
``bench/bench_mypyc.py``'s markers and command line (MCU-42).

Every bad input is refused by name (which argument, which rule, which value) and changes nothing; over any history of
branch switching, DI3 cuts, repairs and INTERBUS resets the pin-level tree gives the master what the transaction-level
tree gives it; the /StatErr filter latches a peripheral fault after the same number of clocks at both fidelities.
"""

from __future__ import annotations

import importlib
import math
import subprocess
import sys
import tracemalloc
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.config import decode
from supi3.errors import ArgumentError
from supi3.interbus import wire
from supi3.interbus.master import Master
from supi3.interbus.ring import BranchKind, DeadLine, ReturnBreak, Ring
from supi3.interbus.wire import Cycle
from supi3.mcu import build as mcu_build
from supi3.mcu.board import Board
from supi3.mcu.session import RING_DEVICE_STRAPS, run_firmware
from supi3.model.chip import STATERR_FILTER_CLOCKS, Supi3
from supi3.model.pinring import IDLE_PIECE_TELEGRAMS, PinRing
from supi3.model.pins import Supi3Pins
from supi3.model.registers import InterfaceViolationError, RegisterFileError, ViolationLog
from supi3.sdk import native
from supi3.sdk.bench import Bench
from supi3.tables import CLOCK_HZ, clk_conf_for
from supi3.top import Supi3Chip
from support import assert_run_matches_step, quiet_inputs
from test_model_pinring_tree import RECOVERY, counted, pin_tree, tl_tree, view

ROOT = Path(__file__).resolve().parents[1]
TOOLCHAIN = mcu_build.toolchain_missing()
needs_toolchain = pytest.mark.skipif(TOOLCHAIN is not None, reason=str(TOOLCHAIN))
"""The tests that build firmware for the emulated board."""


@pytest.fixture(scope="module")
def digital_io(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The digital 16/16 example for the Cortex-M3, built once per module."""
    return mcu_build.build(native.example("digital_io"), tmp_path_factory.mktemp("hostile3") / "digital_io.elf")


# -- PinRing.cut(branch=True) -------------------------------------------------------------------------------------

CUTS = [
    # (position, forward, branch): the error's start
    ((2, True, True), r"position must be the ring position of a BK with a branch \(\[2\]\), with forward=False"),
    ((1, False, True), r"position must be the ring position of a BK with a branch \(\[2\]\)"),
    ((3, False, True), r"position must be the ring position of a BK with a branch \(\[2\]\)"),
    ((5, False, True), r"position must be the ring position of a BK with a branch \(\[2\]\)"),
    ((0, False, True), r"position must be an integer from 1 to 5 \(a chip of the ring\), not 0"),
    ((6, False, True), r"position must be an integer from 1 to 5 \(a chip of the ring\), not 6"),
    ((-1, False, True), r"position must be an integer from 1 to 5 \(a chip of the ring\), not -1"),
    ((True, False, True), r"position must be an integer from 1 to 5 \(a chip of the ring\), not True"),
    ((2.0, False, True), r"position must be an integer from 1 to 5 \(a chip of the ring\), not 2.0"),
    (("2", False, True), r"position must be an integer from 1 to 5 \(a chip of the ring\), not '2'"),
    ((2, 0, True), r"forward must be True or False, not 0"),
    ((2, None, True), r"forward must be True or False, not None"),
    ((2, False, 1), r"branch must be True or False, not 1"),
    ((2, False, "yes"), r"branch must be True or False, not 'yes'"),
    ((2, False, None), r"branch must be True or False, not None"),
]


@pytest.mark.parametrize(("args", "message"), CUTS)
def test_a_bad_cut_is_refused_by_name_and_cuts_nothing(args: tuple[object, object, object], message: str) -> None:
    """BK-10: only a BK with a branch (ring position 2 of this tree) has a DI3 to break, and only as a return input
    (``forward`` False); a wrong type or range names the argument and the value; nothing is cut."""
    ring = pin_tree(BranchKind.LOCAL, 2)
    with pytest.raises(ArgumentError, match=f"^{message}"):
        ring.cut(*args[:2], branch=args[2])  # type: ignore[arg-type]
    assert ring.cuts == set() and ring.branch_cuts == set()


def test_a_cut_twice_is_one_cut_and_a_numpy_position_is_an_integer() -> None:
    """Cutting the same line twice is the same broken line; a numpy integer is a position like an int."""
    ring = pin_tree(BranchKind.LOCAL, 2)
    ring.cut(np.int64(2), False, branch=True)  # type: ignore[arg-type]
    ring.cut(2, False, branch=True)
    ring.cut(np.int32(3), True)  # type: ignore[arg-type]
    ring.cut(3, True)
    assert ring.branch_cuts == {2} and ring.cuts == {(3, True)}


def _apply(ring: Ring | PinRing, master: Master, step: str) -> bool | None:
    """One step of a history on either fidelity; ``False``: the transaction level cannot take it with the branch
    off (no return line enters the BK then; its faults name data-path positions, the pin level's physical ones)."""
    if step in ("on", "off"):
        master.switch_branch(2, step == "on")
    elif step == "repair":
        if isinstance(ring, Ring):
            ring.clear_faults()
        else:
            ring.branch_cuts.clear()
            ring.cuts.clear()
    elif step == "reset":
        return master.start().ok
    elif isinstance(ring, Ring):
        bk = ring.devices[1]
        assert isinstance(bk, Supi3)
        if not bk.branch_enabled(True):
            return False
        ring.inject(ReturnBreak(2) if step == "cut DI3" else DeadLine(int(step[-1])))
    else:
        ring.cut(2, False, branch=True) if step == "cut DI3" else ring.cut(int(step[-1]), True)
    return None


def _settled(master: Master) -> bool:
    """Whether a data cycle latches within the recovery the master gets (a switch garbles a telegram at pin level)."""
    for _ in range(RECOVERY):
        result = master.cycle()
        if result.ok and result.cycle is Cycle.DATA:
            return True
    return False


@settings(max_examples=10, deadline=None, derandomize=True)
@given(kind=st.sampled_from([BranchKind.REMOTE, BranchKind.LOCAL, BranchKind.LBD_OR]),
       steps=st.lists(st.sampled_from(["on", "off", "cut DI3", "cut 3", "cut 4", "repair", "reset"]), min_size=1,
                      max_size=5))  # fmt: skip
def test_any_history_of_switches_di3_cuts_repairs_and_resets_is_the_same_at_both_fidelities(
    kind: BranchKind, steps: list[str]
) -> None:
    """BK-1, BK-10: after each step of any history (branch on, off, the BK's DI3 cut, the forward line into the
    branch's device or into the remote bus device behind the BK cut, all repaired, an INTERBUS reset with the
    master's start) the master on the pin-level tree and on the transaction-level tree gets the same verdict (a
    data cycle latches within the recovery or not), counts the same chips in the data path (``Transfer.devices``)
    and reads the same configuration and process data; a corrupted cycle latches nothing the other level lacks."""
    seen = []
    skipped: set[int] = set()
    for ring in (tl_tree(kind, 1), pin_tree(kind, 1)):
        master = Master(ring, locate=False, max_devices=8)
        counts = counted(ring)
        assert master.start().ok
        trace: list[object] = []
        for index, step in enumerate(steps):
            if index in skipped or _apply(ring, master, step) is False:
                skipped.add(index)
                trace.append(("refused", step))
                continue
            ok = _settled(master)
            trace.append((step, ok, counts[-1] if ok else None, view(master) if ok else None))
        seen.append(trace)
    assert seen[0] == seen[1]


# -- stat_err_filter (3.6.2, MCU-24) -------------------------------------------------------------------------------

BAD_FILTERS = [0, -1, True, 1.5, "x", None, STATERR_FILTER_CLOCKS + 1, 10**30, float(STATERR_FILTER_CLOCKS)]


@pytest.mark.parametrize("value", BAD_FILTERS, ids=repr)
def test_a_bad_stat_err_filter_is_refused_by_name(value: object) -> None:
    """The filter is an integer number of clocks from 1 to 200 ms (6,400,000): a bool, a float (even a whole one),
    a string, zero, negative or longer values are refused by name with the value, on the chip, the whole chip."""
    config = decode("10000")
    wanted = rf"^stat_err_filter must be an integer from 1 to {STATERR_FILTER_CLOCKS} \("
    with pytest.raises(ArgumentError, match=wanted):
        Supi3(stat_err_filter=value)  # type: ignore[arg-type]
    with pytest.raises(ArgumentError, match=wanted):
        Supi3Chip(config, stat_err_filter=value)  # type: ignore[arg-type]


@needs_toolchain
@pytest.mark.parametrize("value", [*BAD_FILTERS, 5, STATERR_FILTER_CLOCKS - 1], ids=repr)
def test_a_boards_bad_stat_err_filter_is_refused_by_name(digital_io: Path, value: object) -> None:
    """The board refuses the same values at pin level, and at transaction level any but the 200 ms default: a float
    6400000.0 too, which passed before (compared equal)."""
    if value in (5, STATERR_FILTER_CLOCKS - 1) and not isinstance(value, float):
        Board(digital_io, fidelity="pin", stat_err_filter=value)
    else:
        with pytest.raises(ArgumentError, match=r"^stat_err_filter must be an integer from 1 to "):
            Board(digital_io, fidelity="pin", stat_err_filter=value)  # type: ignore[arg-type]
    with pytest.raises(ArgumentError, match=r"^stat_err_filter must be "):
        Board(digital_io, stat_err_filter=value)  # type: ignore[arg-type]


def _pin_latches(filter_clocks: int, low: int) -> bool:
    chip = Supi3Pins(decode("10000"), Supi3(decode("10000"), stat_err_filter=filter_clocks))
    chip.run(quiet_inputs(4000))
    pulse = quiet_inputs(low)
    pulse["stat_err_n"][:] = 0
    chip.run(pulse)
    chip.run(quiet_inputs(50))
    return chip.chip.pf


def _tl_latches(filter_clocks: int, low: int) -> bool:
    chip = Supi3(stat_err_filter=filter_clocks)
    start = 1e-3
    chip.set_stat_err(True, start)
    chip.set_stat_err(False, start + low / CLOCK_HZ)
    chip.set_stat_err(False, start + (low + 50) / CLOCK_HZ)
    return chip.pf


@pytest.mark.parametrize("filter_clocks", [1, 2, 7, 100])
def test_the_filter_latches_after_the_same_clocks_at_both_fidelities(filter_clocks: int) -> None:
    """3.6.2: /StatErr low for one clock less than the filter latches nothing, for the filter time latches the
    peripheral fault, the same at transaction and pin level for any filter length (the pin level's synchroniser
    is in its own time base: the pulse is counted from the chip's first low clock)."""
    for low in (filter_clocks - 1, filter_clocks):
        if low < 1:
            continue
        expected = low >= filter_clocks
        assert (_tl_latches(filter_clocks, low), _pin_latches(filter_clocks, low)) == (expected, expected)


@pytest.mark.parametrize("filter_clocks", [1, 3, 50])
def test_a_short_filter_steps_as_it_runs(filter_clocks: int) -> None:
    """MCU-24: with a short filter the pin level's ``run`` (which jumps to the chip's ``due``, the filter's expiry
    among them) gives every output of ``step`` clock by clock, for a pulse as long as the filter and one a clock
    shorter, cut into pieces anywhere."""
    config = decode("10000")
    inputs = quiet_inputs(3000)
    inputs["stat_err_n"][1000 : 1000 + filter_clocks] = 0
    inputs["stat_err_n"][2000 : 2000 + filter_clocks - 1] = 0
    chips = [Supi3Pins(config, Supi3(config, stat_err_filter=filter_clocks)) for _ in range(2)]
    assert_run_matches_step(chips[0], chips[1], inputs, [0.1, 0.34, 0.5, 0.6667, 0.9])
    assert chips[0].chip.pf and chips[1].chip.pf


# -- the board's ring and run_firmware's devices (MCU-23) ----------------------------------------------------------


@needs_toolchain
def test_a_boards_ring_refuses_the_boards_chip_and_takes_the_devices_behind_it(digital_io: Path) -> None:
    """The board's chip runs on the board's wiring (``LockstepRing.inputs``) in step with the core: a cut of its
    lines or an input set at ring position 1 was accepted and had no effect; now both are refused by name and
    change nothing. The devices behind it (position 2 on) take both as in any ``PinRing``."""
    config = decode(*RING_DEVICE_STRAPS, clk_conf=clk_conf_for(500_000))
    for others in ([], [Supi3Pins(config)]):
        ring = Board(digital_io, fidelity="pin", others=others).ring
        before = dict(ring.inputs)
        for method, args in ((ring.cut, (1, True)), (ring.cut, (np.int64(1), False)),
                             (ring.set_input, (1, "stat_err_n", 0)), (ring.set_input, (1, "mfp_in", 0xFF))):
            with pytest.raises(ArgumentError, match=r"^position must be a device behind the board's chip \(from 2; "
                                                    rf"this ring has {len(others)} behind it, MCU-23\)"):
                method(*args)
        with pytest.raises(ArgumentError, match=r"^position must be an integer from 1 to"):
            ring.cut(True, True)
        assert ring.cuts == set() and ring.inputs == before
    ring.cut(2, True)
    ring.set_input(2, "mfp_in", 0xA55A)
    assert ring.cuts == {(2, True)}


@needs_toolchain
@settings(max_examples=6, deadline=None, derandomize=True)
@given(steps=st.lists(st.sampled_from([("run", 0), ("run", 1), ("run", 2), ("for", 0.0), ("for", 400e-6),
                                       ("for", 800e-6)]), min_size=1, max_size=4))  # fmt: skip
def test_any_history_of_run_and_run_for_counts_the_same_at_both_fidelities(
    digital_io: Path, steps: list[tuple[str, float]]
) -> None:
    """MCU-22: after the power-up, any sequence of ``run(k)`` and ``run_for`` of whole cycle times (a master cycle
    every 400 µs) gives the same master cycles and EXTI0 handler entries after every call at both fidelities, the
    same firmware cycles after every ``run`` (which serves the last handler; ``run_for`` may end inside it, 13 µs
    later at one fidelity than at the other), and bus times that stay within two status telegrams of each other
    (20 µs at 500 kbit/s: ``run`` ends once the handler is served, on the line's telegram grid at pin level; no drift
    over the history)."""
    seen = []
    for fidelity in ("transaction", "pin"):
        board = Board(digital_io, fidelity=fidelity, cycle_time_s=400e-6)
        board.run(3)
        fw = board.fw_board
        assert fw is not None
        base = (board.now, board.cycles, board.interrupts, fw.cycles)
        trace = []
        for kind, value in [*steps, ("run", 0)]:
            if kind == "run":
                board.run(int(value))
            else:
                board.run_for(value)
            served = fw.cycles - base[3] if kind == "run" else None  # run_for does not wait for the last handler
            trace.append((board.cycles - base[1], board.interrupts - base[2], served, board.now - base[0]))
        assert board.violations == []
        seen.append(trace)
    for tl, pin in zip(*seen, strict=True):
        assert tl[:3] == pin[:3] and tl[3] == pytest.approx(pin[3], abs=2 * wire.STATUS_TELEGRAM_BITS / 500_000)


@needs_toolchain
@pytest.mark.parametrize("devices", [0, 5, -1, "x", True, 4.0, None], ids=repr)
def test_run_firmware_refuses_a_pin_level_ring_it_cannot_run(digital_io: Path, devices: object) -> None:
    """MCU-23: at pin level 1 to 4 chips (``MAX_PIN_DEVICES``), an integer: anything else by name."""
    with pytest.raises(ArgumentError, match=r"^devices must be an integer from 1 to 4 \(at pin level, MCU-23\)"):
        run_firmware(digital_io, fidelity="pin", devices=devices)  # type: ignore[arg-type]


@needs_toolchain
@pytest.mark.parametrize("others", [None, "ab", 5], ids=repr)
def test_a_transaction_level_boards_others_must_be_a_sequence(digital_io: Path, others: object) -> None:
    """``others`` not a sequence: refused by name on the board at either fidelity (at transaction level through
    :class:`Bench`; None raised a bare TypeError from unpacking before)."""
    with pytest.raises(ArgumentError, match=r"^others must be a sequence of the devices behind the chip"):
        Board(digital_io, others=others)  # type: ignore[arg-type]
    with pytest.raises(ArgumentError, match=r"^others must be pin-level chips at pin level"):
        Board(digital_io, fidelity="pin", others=others)  # type: ignore[arg-type]


# -- Bench.advance and Bench's others ---------------------------------------------------------------------------


@pytest.mark.parametrize("until", [math.nan, math.inf, -math.inf, "1", None, True, np.bool_(True)], ids=repr)
def test_bench_advance_refuses_a_time_that_is_not_a_finite_number(until: object) -> None:
    """``Bench.advance`` takes a finite number of seconds: NaN ran nothing silently, infinity never returned, a string
    or None raised a bare TypeError; now each is refused by name and the clock stays where it was."""
    bench = Bench()
    bench.advance(0.5e-3)
    before = (bench.now, bench.cycles)
    with pytest.raises(ArgumentError, match=r"^until must be a finite number, not "):
        bench.advance(until)  # type: ignore[arg-type]
    assert (bench.now, bench.cycles) == before


def test_bench_advance_takes_integers_and_never_goes_back() -> None:
    """An integer time is a time; an earlier one leaves the clock where it is (\"not backwards\")."""
    bench = Bench()
    bench.advance(np.float64(1e-3))
    bench.advance(0)
    assert bench.now == 1e-3
    bench.advance(np.int64(0))  # type: ignore[arg-type]
    assert bench.now == 1e-3


@pytest.mark.parametrize("others", [None, "ab", b"x", 5], ids=repr)
def test_bench_refuses_others_that_are_not_a_sequence(others: object) -> None:
    with pytest.raises(ArgumentError, match=r"^others must be a sequence of the devices behind the chip"):
        Bench(others=others)  # type: ignore[arg-type]


# -- ViolationLog.hold / release ----------------------------------------------------------------------------------


def test_a_release_without_a_hold_is_refused_and_strict_mode_still_raises() -> None:
    """``ViolationLog.release`` without its ``hold`` took the depth below zero, after which strict mode held every
    violation for ever (never raised); now it is a RegisterFileError and the log is as before. Over a history of
    nested holds, releases and reports, a violation raises exactly when the outermost block is left (not if it
    failed), and every violation is in ``records``."""
    log = ViolationLog(True)
    with pytest.raises(RegisterFileError, match=r"^ViolationLog.release\(\) without a hold\(\)"):
        log.release()
    with pytest.raises(InterfaceViolationError, match="first"):
        log.report(InterfaceViolationError("3.4.2", "first"))
    log.hold()
    log.hold()
    log.report(InterfaceViolationError("3.4.2", "second"))
    log.release()  # inner: held
    with pytest.raises(InterfaceViolationError, match="second"):
        log.release()
    log.hold()
    log.report(InterfaceViolationError("3.4.2", "third"))
    log.release(failed=True)  # an exception left the block: it wins, the violation stays recorded
    with pytest.raises(RegisterFileError):
        log.release()
    assert [str(v) for v in log.records] == ["first (3.4.2)", "second (3.4.2)", "third (3.4.2)"]


# -- PinRing.idle in pieces ------------------------------------------------------------------------------------


@pytest.mark.parametrize("kind", [BranchKind.LOCAL, BranchKind.LBD_MR])
def test_a_long_idle_runs_in_pieces_with_the_same_pins_and_bounded_memory(kind: BranchKind) -> None:
    """``PinRing.idle`` runs its status telegrams :data:`IDLE_PIECE_TELEGRAMS` at a time: every chip's every pin,
    the clock and the return line are those of one run of them all, through a tree with a BK-LBD's counter block
    too; and the memory an idle takes no longer grows with its length (20 ms peaked at 168 MB in one run)."""
    rings = [pin_tree(kind, 1), pin_tree(kind, 1)]
    for ring in rings:
        ring.record = True
        Master(ring, locate=False, max_devices=8).start()
    count = 3 * IDLE_PIECE_TELEGRAMS + 5
    rings[0].idle(count * wire.STATUS_TELEGRAM_BITS / rings[0].bit_rate)
    rings[1].run_levels(wire.status_levels(Cycle.DATA, False, count))
    assert rings[0].cycle == rings[1].cycle and rings[0].returned_from + len(rings[0].returned) == rings[1].cycle
    for one, other in zip(rings[0].recorded(), rings[1].recorded(), strict=True):
        assert one.keys() == other.keys() and all(np.array_equal(one[name], other[name]) for name in one)
    ring = PinRing([Supi3Pins(decode("10000"))])
    tracemalloc.start()
    try:
        ring.idle(20e-3)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert ring.now == pytest.approx(20e-3, abs=wire.STATUS_TELEGRAM_BITS / ring.bit_rate)
    assert peak < 32e6


# -- bench/bench_side.py ----------------------------------------------------------------------------------------


@pytest.mark.parametrize(("argv", "status", "message"), [
    (["--rounds", "0"], 2, "--rounds must be at least 1, not 0"),
    (["--rounds", "-3"], 2, "--rounds must be at least 1, not -3"),
    (["--rounds", "x"], 2, "invalid int value: 'x'"),
    (["--cases", "nope"], 2, "unknown case(s) ['nope']"),
    (["--rounds", "1", "--cases", "ring512", "--against", "/nonexistent/src"], 1,
     "/nonexistent/src holds no supi3 package"),
    (["--rounds", "1", "--cases", "ring512", "--tree", "/nonexistent/src"], 1,
     "/nonexistent/src holds no supi3 package"),
])  # fmt: skip
def test_bench_side_refuses_a_bad_command_line(argv: list[str], status: int, message: str) -> None:
    """No round (an IndexError after the firmware builds before) and a tree without supi3 (this tree measured twice,
    silently, when ``supi3`` was importable from elsewhere) stop with one line, before any measurement."""
    done = subprocess.run([sys.executable, str(ROOT / "bench" / "bench_side.py"), *argv], capture_output=True,
                          text=True, cwd=ROOT, timeout=120, check=False)  # fmt: skip
    assert (done.returncode, message in done.stderr, "Traceback" in done.stderr) == (status, True, False), done.stderr


def test_bench_side_names_a_tree_too_old_for_its_cases(tmp_path: Path) -> None:
    """``--against`` a tree whose supi3 lacks a module the cases import: one line naming the tree and the module,
    no traceback."""
    (tmp_path / "supi3").mkdir()
    (tmp_path / "supi3" / "__init__.py").write_text("")
    done = subprocess.run([sys.executable, str(ROOT / "bench" / "bench_side.py"), "--rounds", "1", "--cases", "ring512",
                           "--against", str(tmp_path)], capture_output=True, text=True, cwd=ROOT, timeout=120,
                          check=False)  # fmt: skip
    assert done.returncode == 1 and "Traceback" not in done.stderr
    assert f"bench_side.py: {tmp_path}: No module named 'supi3." in done.stderr


# -- bench/bench_mypyc.py (MCU-42) ------------------------------------------------------------------------------


def test_bench_mypyc_marks_the_exception_classes_and_the_subclassed_ones_only() -> None:
    """The scratch copy's markers: mypyc's ``native_class=False`` on each exception class (two builtin bases are not
    implemented), ``allow_interpreted_subclasses`` on the classes named, nothing else changed but the import."""
    sys.path.insert(0, str(ROOT / "bench"))
    try:
        tool: Any = importlib.import_module("bench_mypyc")
    finally:
        sys.path.remove(str(ROOT / "bench"))
    source = ("from __future__ import annotations\n\n\nclass LinkError(Supi3Error, RuntimeError):\n    pass\n\n\n"
              "class Firmware:\n    pass\n\n\nclass Other(Base):\n    error: LinkError\n")  # fmt: skip
    assert tool.mark(source, ("Firmware",)) == (
        "from __future__ import annotations\n\nfrom mypy_extensions import mypyc_attr\n\n\n"
        "@mypyc_attr(native_class=False)\nclass LinkError(Supi3Error, RuntimeError):\n    pass\n\n\n"
        "@mypyc_attr(allow_interpreted_subclasses=True)\nclass Firmware:\n    pass\n\n\n"
        "class Other(Base):\n    error: LinkError\n")  # fmt: skip


def test_bench_mypyc_names_a_module_that_is_not_there() -> None:
    """A module to compile that the tree does not hold: one line naming it, before any compiler runs."""
    done = subprocess.run([sys.executable, str(ROOT / "bench" / "bench_mypyc.py"), "--modules", "supi3/nope.py"],
                          capture_output=True, text=True, cwd=ROOT, timeout=120, check=False)  # fmt: skip
    assert done.returncode == 1 and "Traceback" not in done.stderr
    assert "bench_mypyc.py: no module supi3/nope.py in " in done.stderr

"""Hostile inputs and histories against issue 12's optical and diagnostic parts (a user's review, round 5):
the fibre-link events of :mod:`supi3.optical.link` (1.6.1, OPT-45), the transmitter states of
:mod:`supi3.optical.regulation` (1.6.1-1.6.3), the ``supi3 optical`` and ``supi3 timing --optical-count`` command
lines (OPT-1), and the chip's transaction-level optical API (:meth:`supi3.model.chip.Supi3.optical_start`).

Every bad input is refused by name (which argument, which rule, which value); a state no history reaches cannot be
built by hand; every history of online tests keeps 1.6.3's hysteresis; one timer count means one length wherever a
user converts it.
"""

from __future__ import annotations

import argparse
import itertools
import json
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3 import demo, timing
from supi3.cli import main, positive_integer
from supi3.config import decode
from supi3.errors import ArgumentError
from supi3.interbus.master import Master
from supi3.model.blocks.optical import OpticalBlock
from supi3.model.chip import Supi3
from supi3.optical import length
from supi3.optical.link import Ageing, Bend, Direction, FibreLink, Pull, Temperature
from supi3.optical.regulation import (
    BLOCK_INPUTS,
    DECREASE_AFTER,
    INIT_MAX_STEPS,
    MAX_LEVEL,
    MIN_LEVEL,
    Interface,
    OpticalMode,
    Phase,
    Response,
    Transmitter,
    apply_test,
    fo_lit,
    init_response,
    init_timeout,
    start,
)
from supi3.optical.ring import OpticalRing, diagnostic_table
from supi3.sdk.driver import DriverArgumentError, OpticalStatus
from support import bad

# -- fibre-link events: loss(direction, t) is a public entry (OPT-45) -------------------------------------------------

EVENTS = [Bend(0.0, 1.0, 2.0), Bend(0.0, None, 2.0, Direction.FORWARD), Pull(0.0, 1.0),
          Ageing(0.0, 1.0, direction=Direction.RETURN), Temperature(0.0, 5.0, 1.0)]  # fmt: skip


@pytest.mark.parametrize("event", EVENTS, ids=lambda e: type(e).__name__)
@pytest.mark.parametrize(("direction", "t", "name"), [
    (0, 0.5, "direction"), ("forward", 0.5, "direction"), (None, 0.5, "direction"),
    (Direction.FORWARD, math.nan, "t"), (Direction.FORWARD, -1.0, "t"), (Direction.FORWARD, "0.5", "t"),
    (Direction.FORWARD, math.inf, "t"), (Direction.FORWARD, True, "t"),
])  # fmt: skip
def test_event_loss_refuses_a_bad_direction_or_time(event: object, direction: object, t: object, name: str) -> None:
    # Before: Bend.loss(0, ...) counted an int as a direction, Ageing.loss("x", ...) took any direction, a NaN time
    # was "not yet" and a string time a TypeError deep inside.
    with pytest.raises(ArgumentError, match=rf"^{name} must be"):
        event.loss(bad(direction), bad(t))  # type: ignore[attr-defined]


# -- transmitter states: only those a history reaches (1.6.1-1.6.3) -------------------------------------------------


def _reached() -> set[Transmitter]:
    """Every transmitter state some history of start, responses, timeouts and online tests reaches (breadth first;
    the space is small)."""
    seen = {start(mode, present) for mode in OpticalMode for present in (False, True)}
    todo = list(seen)
    while todo:
        tx = todo.pop()
        after = [init_response(tx, r) for r in Response] + [init_timeout(tx)]
        after += [apply_test(tx, a1, a2) for a1, a2 in itertools.product((False, True), repeat=2)]
        for new in after:
            if new not in seen:
                seen.add(new)
                todo.append(new)
    return seen


def test_transmitter_accepts_exactly_the_reachable_states() -> None:
    # Before: Transmitter(Phase.OFF, mau=True) lit FO in RUN for an interface not in use, Transmitter(Phase.FIXED, 3)
    # showed level 3 for "an unregulated transmitter at maximum power" (1.6.1), INIT at level 15 after 5 lowerings...
    reached = _reached()
    shapes = {(tx.phase, tx.level, tx.steps, tx.passes, tx.mau) for tx in reached}
    built = 0
    for phase, level, steps, passes, mau in itertools.product(Phase, range(MIN_LEVEL, MAX_LEVEL + 1),
                                                              range(INIT_MAX_STEPS + 1), range(DECREASE_AFTER),
                                                              (False, True)):  # fmt: skip
        if (phase, level, steps, passes, mau) not in shapes:
            with pytest.raises(ArgumentError, match=r"^(level|steps|passes|mau) must be"):
                Transmitter(phase, level, steps, passes, mau)
            continue
        built += 1
        assert Transmitter(phase, level, steps, passes, mau) in reached
    assert built == len(reached)


@pytest.mark.parametrize(("kwargs", "name"), [
    ({"phase": Phase.OFF, "mau": True}, "mau"),
    ({"phase": Phase.FIXED, "level": 3}, "level"),
    ({"phase": Phase.DIAGNOSTIC, "level": 14}, "level"),
    ({"phase": Phase.INIT, "steps": 5}, "level"),
    ({"phase": Phase.ONLINE, "steps": 2, "level": 13}, "steps"),
    ({"phase": Phase.FIXED, "passes": 1}, "passes"),
    ({"phase": Phase.ONLINE, "level": 9, "mau": True}, "mau"),
])  # fmt: skip
def test_unreachable_transmitter_states_are_refused_by_name(kwargs: dict[str, object], name: str) -> None:
    with pytest.raises(ArgumentError, match=rf"^{name} must be .*\(1\.6|^{name} must be .*OPT-6"):
        Transmitter(**kwargs)  # type: ignore[arg-type]


@given(st.lists(st.tuples(st.booleans(), st.booleans()), max_size=80), st.integers(MIN_LEVEL, MAX_LEVEL))
def test_mau_warning_follows_the_level_history_of_1_6_3(tests: list[tuple[bool, bool]], first_light_on: int) -> None:
    """Over any history of online tests the warning is exactly 1.6.3's hysteresis of the level path: on after the
    step MAX-1 -> MAX (or a failed test at MAX), off after the step MAX-1 -> MAX-2, unchanged otherwise; FO in RUN
    shows it (Table 3-17)."""
    tx = start(OpticalMode.REGULATION, True)
    while tx.phase is Phase.INIT and tx.level > max(first_light_on, MAX_LEVEL - INIT_MAX_STEPS + 1):
        tx = init_response(tx, Response.DETECTED)
    tx = init_response(tx, Response.NOT_DETECTED)
    warned = tx.mau
    for ack1, ack2 in tests:
        new = apply_test(tx, ack1, ack2)
        assert abs(new.level - tx.level) <= 1
        if (tx.level, new.level) == (MAX_LEVEL - 1, MAX_LEVEL) or (tx.level == MAX_LEVEL and not ack1):
            warned = True
        elif (tx.level, new.level) == (MAX_LEVEL - 1, MAX_LEVEL - 2):
            warned = False
        assert new.mau is warned and fo_lit(new, True) is warned
        tx = new


# -- the command line: supi3 optical and supi3 timing --optical-count (OPT-1) ----------------------------------------


def _cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    try:
        code = main(list(argv))
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else 1
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize(("argv", "expect"), [
    # Before: the register's MEDIUM bit silently overrode an explicit --medium.
    (["--register", "0x18", "--medium", "glass"], "--medium is not for --register"),
    (["--register", "0x58", "--medium", "polymer"], "--medium is not for --register"),
    # Before: --bit-rate was ignored, even when it was no bit rate at all, unless --count was given.
    (["--code", "3", "--bit-rate", "9"], "--bit-rate is for --count only"),
    (["--metres", "5", "--bit-rate", "2M"], "--bit-rate is for --count only"),
    (["--register", "0x18", "--bit-rate", "500k"], "--bit-rate is for --count only"),
    # Before: the error named the library's argument (one_way_m), not the option.
    (["--metres", "20000.5"], "--metres must be a finite number from 0.0 to 20000.0"),
    (["--count", "12", "--bit-rate", "1M"], "--bit-rate must be 500k or 2M"),
    (["--count", "99999999999999999999"], "--count must be an integer from 0 to 1600"),
])  # fmt: skip
def test_optical_command_refuses_options_it_would_ignore(capsys: pytest.CaptureFixture[str], argv: list[str],
                                                         expect: str) -> None:
    code, out, err = _cli(capsys, "optical", *argv)
    assert code == 2 and out == "" and err.count("\n") == 1 and expect in err


@pytest.mark.parametrize("bit_rate", [500_000, 2_000_000], ids=["500k", "2M"])
def test_one_timer_count_means_one_length_in_both_commands(capsys: pytest.CaptureFixture[str],
                                                           bit_rate: int) -> None:
    """``supi3 timing --optical-count n`` (L = n / (f t), forward and return, 1.6.1) and ``supi3 optical --count n``
    (the one-way code, OPT-1) take the same timer results, up to a 20 km path there and back: half of timing's L
    lies in the range of optical's code. Before: timing refused every n above 63 as "Table 1-5" (the code's range),
    so the 2 Mbit/s count of a 387.5 m path (124) had a length in one command and none in the other."""
    rate = "2M" if bit_rate == 2_000_000 else "500k"
    most = length.timer_count(length.MAX_PATH_M, bit_rate)
    assert timing.max_optical_count(bit_rate) == most
    for n in sorted({0, 1, 31, 32, 63, 64, 124, 125, 127, 128, most - 1, most}):
        code, out, err = _cli(capsys, "timing", "--bit-rate", rate, "--optical-count", str(n), "--json")
        assert code == 0 and err == "", err
        there_and_back = json.loads(out)["optical_length_m"]
        code, out, err = _cli(capsys, "optical", "--count", str(n), "--bit-rate", rate, "--json")
        assert code == 0 and err == "", err
        data = json.loads(out)
        assert data["one_way_m_from"] <= there_and_back / 2 <= data["one_way_m_below"]
        assert data["code"] == length.length_code(there_and_back / 2, length.Medium.POLYMER)
    code, _, err = _cli(capsys, "timing", "--bit-rate", rate, "--optical-count", str(most + 1))
    assert code == 2 and f"--optical-count must be an integer from 0 to {most}" in err
    code, _, err = _cli(capsys, "optical", "--count", str(most + 1), "--bit-rate", rate)
    assert code == 2 and f"--count must be an integer from 0 to {most}" in err


# -- the Python SDK: OpticalStatus.decode (3.4.12, 3.4.13) ------------------------------------------------------------


@pytest.mark.parametrize("raw", [b"", b"\0\0\0", b"\0" * 5, "abcd", [1, 2, 3, 4], None, 0x01020304])
def test_optical_status_decode_takes_exactly_the_four_bytes_of_reads_8_to_11(raw: object) -> None:
    # Before: 3 bytes were an IndexError, a str a TypeError, 5 bytes and a list of ints decoded silently.
    with pytest.raises(DriverArgumentError, match=r"^raw must be"):
        OpticalStatus.decode(bad(raw))
    assert OpticalStatus.decode(bad(bytearray(b"\x58\xbf\x8f\x3c"))) == OpticalStatus(24, 1, 0, 63, 0, 1, 15, 1, 12, 3)


# -- the master's optical diagnostic table (Figure 1-10) --------------------------------------------------------------


def _optical_ring(n: int) -> OpticalRing:
    return OpticalRing([Supi3(decode("10000", rf="00")) for _ in range(n)], [FibreLink(20.0) for _ in range(n)])


def test_diagnostic_table_refuses_the_master_of_another_ring() -> None:
    # Before: the other master's configuration named this ring's devices silently (a 3-chip ring's table with the
    # device numbers of a 5-chip ring's master).
    ring, other = _optical_ring(3), _optical_ring(5)
    master, stranger = Master(ring), Master(other)
    assert master.start().ok and stranger.start().ok
    with pytest.raises(ArgumentError, match=r"^master must be the Master of this ring"):
        diagnostic_table(ring, stranger)
    assert [row.path for row in diagnostic_table(ring, master)] == ["1.0<->2.0", "2.0<->3.0"]


# -- demo --optical from Python -------------------------------------------------------------------------------------


@pytest.mark.parametrize("plot", ["power.html", 3, b"power.html"])
def test_optical_demo_refuses_a_plot_that_is_no_path_before_the_run(plot: object) -> None:
    # Before: the whole run went by, then an AttributeError ('str' object has no attribute 'write_text').
    lines = demo.run_optical(5, bad(plot))
    with pytest.raises(ArgumentError, match=r"^plot must be a pathlib.Path or None"):
        next(lines)


def test_optical_ring_refuses_one_cable_in_two_places() -> None:
    # Before: the same FibreLink entering chips 1 and 3 was taken; a connector pulled on "cable 1" broke both.
    chips = [Supi3(decode("10000", rf="00")) for _ in range(3)]
    cable = FibreLink(20.0)
    with pytest.raises(ArgumentError, match=r"^link into chip 3 must be a FibreLink of its own"):
        OpticalRing(chips, [cable, FibreLink(20.0), cable])
    OpticalRing(chips, [cable, None, None])  # copper (None) may repeat


@pytest.mark.parametrize("bit_rate", [500_000, 2_000_000])
def test_optical_range_takes_what_the_length_functions_take(bit_rate: int) -> None:
    # Before: 20 km, which length_code, timer_count and FibreLink take (Table 1-5's "to 20 km"), was "outside Table
    # 1-5"; a string was a TypeError and True a length of 1 m.
    for metres in (0.0, 393.7, 400.0, 12_345.0, length.MAX_PATH_M):  # 393.75 m to 400 m reads 63 (OPT-1)
        row = timing.optical_range(metres, bit_rate)
        assert row.values == ((0, 62) if metres < 400 else (63, 63))
        assert length.length_code(metres, length.Medium.POLYMER) in range(row.values[0], row.values[1] + 1)
    for value in ("5", None, True, math.nan):
        with pytest.raises(ArgumentError, match=r"^length_m must be a number"):
            timing.optical_range(bad(value), bit_rate)
    with pytest.raises(timing.TimingError, match="Table 1-5"):
        timing.optical_range(length.MAX_PATH_M + 0.5, bit_rate)


# -- histories of resets, power-ups, fibre events and cycles on a fibre ring (1.6, 1.6.1) ----------------------------

_OPS = st.lists(st.one_of(
    st.just(("cycle",)), st.just(("start",)), st.tuples(st.just("power"), st.integers(0, 2)),
    st.tuples(st.just("bend"), st.integers(0, 2), st.sampled_from([2.0, 6.0, 12.0]), st.sampled_from([1e-3, 5e-3])),
    st.tuples(st.just("pull"), st.integers(0, 2), st.sampled_from([1e-3, 30e-3])),
), min_size=1, max_size=25)  # fmt: skip


def _assert_recognised_and_measured(ring: OpticalRing, chips: list[Supi3], links: list[FibreLink]) -> None:
    for k, chip in enumerate(chips):
        phases = [tx.phase for tx in chip.optical.transmitters]
        assert phases == [Phase.FIXED if k == 0 else Phase.ONLINE, Phase.ONLINE if k + 1 < len(chips) else Phase.OFF,
                          Phase.OFF]  # fmt: skip
        if k + 1 < len(chips):
            cable = links[k + 1]
            assert chip.optical.length[0] == length.timer_code(cable.timer_count(ring.bit_rate), ring.bit_rate,
                                                               cable.medium)  # fmt: skip


@settings(max_examples=60, deadline=None)
@given(_OPS, st.lists(st.sampled_from([3.0, 12.5, 20.0, 47.0, 70.0]), min_size=3, max_size=3))
def test_every_clean_reset_recognises_and_measures_every_cable(ops: list[tuple[object, ...]],
                                                               metres: list[float]) -> None:
    """1.6: "automatic interface recognition after every reset"; 1.6.1: initialization ends (none left
    initializing) with every regulated partner online, the master's partner and the unused outgoing interface
    unregulated, and every outgoing interface's length measured anew (OPT-1, OPT-21), whatever came before: power-ups
    (lengths forgotten), pulled connectors and bends (a failed start), cycles. Checked after every reset whose
    window no event touched, and after a last one once every event is over."""
    chips = [Supi3(decode("10000", rf="00")) for _ in metres]
    links = [FibreLink(m) for m in metres]
    ring = OpticalRing(chips, links)
    master = Master(ring)
    events: list[Bend | Pull] = []
    for op in ops:
        if op[0] == "cycle":
            master.cycle()
        elif op[0] == "power":
            chips[int(op[1])].power_up()  # type: ignore[call-overload]
        elif op[0] == "bend":
            events.append(Bend(ring.now, float(op[3]), float(op[2])))  # type: ignore[arg-type]
            links[int(op[1])].add(events[-1])  # type: ignore[call-overload]
        elif op[0] == "pull":
            events.append(Pull(ring.now, float(op[2])))  # type: ignore[arg-type]
            links[int(op[1])].add(events[-1])  # type: ignore[call-overload]
        else:
            t0 = ring.now
            ok = master.start().ok
            if not any(e.start_s <= ring.now and (e.duration_s is None or e.start_s + e.duration_s > t0)
                       for e in events):  # fmt: skip
                assert ok
                _assert_recognised_and_measured(ring, chips, links)
    ring.idle(0.04)  # every event is over (the longest, a pull, lasts 30 ms)
    assert master.start().ok
    _assert_recognised_and_measured(ring, chips, links)


# -- the optical block at pin level: quiet() (OPT-24, OPT-25) ---------------------------------------------------------


@pytest.mark.parametrize(("n", "pins", "name"), [
    ("5", {}, "n"), (5.5, {}, "n"), (True, {}, "n"), (-1, {}, "n"), (5, None, "inputs"),
    (5, {"resp_valid": 1, "resp": 1}, "resp_valid"), (5, {"test_valid": 2}, "test_valid"),
    (5, {"len_start": 2}, "len_start"), (5, {"len_stop": 4}, "len_stop"),
    (5, {"run": 1, "test_valid": 1}, "test_valid"),
])  # fmt: skip
def test_optical_block_quiet_refuses_what_is_not_quiet(n: object, pins: dict[str, int] | None, name: str) -> None:
    # Before: a string n was a TypeError, 5.5 and True were taken as clocks, a missing input a KeyError, and a
    # strobe held through quiet() was applied at edges the method's contract says do not change the state.
    block = OpticalBlock()
    values = {pin.name: 0 for pin in BLOCK_INPUTS} | {"mode": 1, "present": 0b111}
    block.quiet(3, values | {"ib_reset": 1})
    block.quiet(1, values)
    before = block.status
    given = None if pins is None else values | pins
    with pytest.raises(ArgumentError, match=rf"^{name}"):
        block.quiet(bad(n), bad(given))
    assert block.status is before


@pytest.mark.parametrize("call", ["poll", "reset", "optical_start"])
def test_a_chip_s_clock_never_goes_back(call: str) -> None:
    """A bus call stamped before the chip's last one (``poll(1.0)``, then ``optical_start(..., 0.5)``) leaves the
    chip's clock where it was: the 6 ms budget (OPT-5) then counts from the chip's clock, not from a time that has
    passed (before, the clock went back to 0.5 s)."""
    chip = Supi3(decode("10000", rf="00"))
    chip.poll(1.0)
    before = chip._clock()
    {"poll": lambda: chip.poll(0.5), "reset": lambda: chip.reset(0.5),
     "optical_start": lambda: chip.optical_start((True, True, False), 0.5)}[call]()  # fmt: skip
    assert chip._clock() == before
    if call == "optical_start":
        assert chip.optical_holding
        chip.poll(1.0 + 5e-3)  # 5 ms after the chip's clock, 4.5 ms after the stamp: within the budget
        assert chip.optical_holding
        chip.poll(1.0 + 7e-3)  # 7 ms: the incoming interface's 6 ms ran out (OPT-5); the outgoing one's (OPT-56) run
        assert chip.optical[Interface.IN].phase is Phase.FIXED and chip.optical_holding
        chip.poll(1.0 + 13e-3)  # and ran out too
        assert not chip.optical_holding


@pytest.mark.parametrize("text", ["0", "-3", "x", "1e3", "1_000", " 5", "1.5", ""])
def test_positive_integer_refuses_what_is_no_count(text: str) -> None:
    """``supi3.cli.positive_integer``, the argparse type of the bench scripts' counts and steps: a named usage error,
    never a traceback (``closure_sweep.py --step 0`` used to end in range()'s ValueError)."""
    with pytest.raises(argparse.ArgumentTypeError, match="must be"):
        positive_integer(text)


def test_positive_integer_takes_counts() -> None:
    assert [positive_integer(t) for t in ("1", "250", "13750")] == [1, 250, 13_750]

"""The regulation rules (supi3.optical.regulation): manual 1.6.1 (initialization), 1.6.2 (online regulation,
optical diagnostics), 1.6.3 (MAU warning hysteresis), Table 3-17/2-8 (FO LEDs), 3.4.12/3.4.13 (reads 8 to 11);
decisions OPT-2..OPT-12. Every state and input of the small spaces, and properties over random histories."""

from __future__ import annotations

import itertools

import pytest
from hypothesis import given
from hypothesis import strategies as st

from supi3.errors import ArgumentError
from supi3.optical.length import Medium
from supi3.optical.regulation import (
    DECREASE_AFTER,
    INIT_MAX_STEPS,
    INIT_STEP_BITS,
    INIT_TIME_LIMIT_CLOCKS,
    INIT_TIME_LIMIT_S,
    MAX_LEVEL,
    MIN_LEVEL,
    Interface,
    OpticalMode,
    OpticalStatus,
    Phase,
    Response,
    Transmitter,
    diagnostic_mau,
    fo_lit,
    init_response,
    init_timeout,
    length_timer_enable_every,
    mau_after,
    online_test,
    probe_power_db,
    registers,
    start,
)
from supi3.regmap import LENGTH_BRANCH, LENGTH_OUT, POWER_IN, POWER_OUT_BRANCH
from supi3.tables import BIT_RATES
from support import bad

LEVELS = range(MIN_LEVEL, MAX_LEVEL + 1)


def all_transmitters() -> list[Transmitter]:
    """Every reachable state: each phase, level, step count, pass count and warning that Transmitter accepts (it
    refuses the states no history reaches, tests/test_hostile5.py)."""
    states = []
    for phase, level, steps, passes, mau in itertools.product(Phase, LEVELS, range(INIT_MAX_STEPS + 1),
                                                              range(DECREASE_AFTER), (False, True)):  # fmt: skip
        try:
            states.append(Transmitter(phase, level, steps, passes, mau))
        except ArgumentError:
            continue
    return states


def test_start_by_mode_and_presence() -> None:
    for mode, present in itertools.product(OpticalMode, (False, True)):
        tx = start(mode, present)
        expected = {OpticalMode.REGULATION: Phase.INIT, OpticalMode.DIAGNOSTIC: Phase.DIAGNOSTIC}.get(mode, Phase.OFF)
        assert tx == Transmitter(expected if present else Phase.OFF)
        assert tx.level == MAX_LEVEL and not tx.mau and not tx.enable


def test_initialization_from_max_lowers_until_the_first_light_on() -> None:
    # 1.6.1: reduced until the first negative response, then increased by one and started up.
    for first_negative in range(MAX_LEVEL, MAX_LEVEL - INIT_MAX_STEPS, -1):
        tx = start(OpticalMode.REGULATION, True)
        while tx.phase is Phase.INIT and tx.level > first_negative:
            tx = init_response(tx, Response.DETECTED)
        tx = init_response(tx, Response.NOT_DETECTED)
        assert tx.phase is Phase.ONLINE and tx.enable
        assert tx.level == min(MAX_LEVEL, first_negative + 1)
        assert tx.mau == (first_negative >= MAX_LEVEL - 1)  # at MAX the reserve is not ensured (1.6.3)


def test_initialization_ends_after_13_lowerings() -> None:
    tx = start(OpticalMode.REGULATION, True)
    for step in range(INIT_MAX_STEPS):
        assert tx.phase is Phase.INIT and tx.steps == step
        tx = init_response(tx, Response.DETECTED)
    assert tx == Transmitter(Phase.ONLINE, MAX_LEVEL - INIT_MAX_STEPS)


def test_no_response_or_timeout_falls_back_to_an_unregulated_transmitter_at_max() -> None:
    for tx in all_transmitters():
        if tx.phase is Phase.INIT:
            assert init_response(tx, Response.NONE) == Transmitter(Phase.FIXED) == init_timeout(tx)
            assert not Transmitter(Phase.FIXED).enable
        else:
            assert init_timeout(tx) == tx
            assert all(init_response(tx, r) == tx for r in Response)


def test_online_regulation_is_three_point() -> None:
    for tx in all_transmitters():
        for ack1, ack2 in itertools.product((False, True), repeat=2):
            new = online_test(tx, ack1, ack2)
            if tx.phase is not Phase.ONLINE:
                assert new == tx
                continue
            if not ack1:
                assert new.level == min(MAX_LEVEL, tx.level + 1) and new.passes == 0
            elif not ack2:
                assert new == Transmitter(tx.phase, tx.level, tx.steps, 0, tx.mau)
            elif tx.passes + 1 < DECREASE_AFTER:
                assert new.level == tx.level and new.passes == tx.passes + 1
            else:
                assert new.level == max(MIN_LEVEL, tx.level - 1) and new.passes == 0
            assert new.phase is Phase.ONLINE


def test_mau_hysteresis_of_1_6_3() -> None:
    for mau, old, new in itertools.product((False, True), LEVELS, LEVELS):
        expected = True if (old, new) == (14, 15) else False if (old, new) == (14, 13) else mau
        assert mau_after(mau, old, new) is expected


@given(st.lists(st.tuples(st.booleans(), st.booleans()), max_size=200), st.integers(MIN_LEVEL, MAX_LEVEL))
def test_mau_changes_only_at_the_hysteresis_edges_over_any_history(tests: list[tuple[bool, bool]], level: int
                                                                  ) -> None:
    tx = Transmitter(Phase.ONLINE, level, mau=level == MAX_LEVEL)  # online at MAX: warned (1.6.3)
    for ack1, ack2 in tests:
        new = online_test(tx, ack1, ack2)
        assert abs(new.level - tx.level) <= 1
        if new.mau and not tx.mau:
            assert new.level == MAX_LEVEL
        if tx.mau and not new.mau:
            assert (tx.level, new.level) == (MAX_LEVEL - 1, MAX_LEVEL - 2)
        tx = new


@given(st.integers(MIN_LEVEL, MAX_LEVEL), st.integers(MIN_LEVEL, MAX_LEVEL), st.integers(0, 30))
def test_a_constant_path_settles_and_never_oscillates(level: int, limit: int, extra: int) -> None:
    # Tests pass at a power of at least the limit's; the regulation reaches the limit and stays there.
    tx = Transmitter(Phase.ONLINE, level, mau=level == MAX_LEVEL)  # online at MAX: warned (1.6.3)
    for _ in range(2 * DECREASE_AFTER * MAX_LEVEL + extra):
        tx = online_test(tx, tx.level - 1 >= limit, tx.level - 2 >= limit)
    assert tx.level == max(MIN_LEVEL, min(MAX_LEVEL, limit + 1))
    settled = tx
    for _ in range(10):
        tx = online_test(tx, tx.level - 1 >= limit, tx.level - 2 >= limit)
        assert tx.level == settled.level


def test_rises_are_faster_than_falls() -> None:
    # Figure 1-12: a rise per failed test, a fall per DECREASE_AFTER passed tests.
    up = down = Transmitter(Phase.ONLINE, 8)
    for _ in range(4):
        up = online_test(up, False, False)
        down = online_test(down, True, True)
    assert up.level - 8 == 4 and 8 - down.level == 4 // DECREASE_AFTER


def test_diagnostic_mode_mau() -> None:
    for mau, ack1, ack2 in itertools.product((False, True), repeat=3):
        assert diagnostic_mau(mau, ack1, ack2) is (True if not ack1 else (False if ack2 else mau))


def test_probe_power() -> None:
    for level in LEVELS:
        assert probe_power_db(level, 0) == level - MAX_LEVEL
        assert probe_power_db(level, 1) == probe_power_db(level, 0) - 3
        assert probe_power_db(level, 2) == probe_power_db(level, 1) - 1


def test_fo_leds_follow_table_3_17_and_2_8() -> None:
    for tx in all_transmitters():
        assert fo_lit(tx, run=False) is (tx.phase is Phase.FIXED)
        assert fo_lit(tx, run=True) is tx.mau


def test_registers_match_the_register_map_layout() -> None:
    out = Transmitter(Phase.ONLINE, 11)
    branch = Transmitter(Phase.FIXED)
    status = OpticalStatus((Transmitter(Phase.ONLINE, 9), out, branch), (24, 63), (Medium.POLYMER, Medium.GLASS))
    r8, r9, r10, r11 = registers(status)
    assert LENGTH_OUT.decode(r8) == {"LENGTH": 24, "MEDIUM": 0, "ENABLE": 1}
    assert LENGTH_BRANCH.decode(r9) == {"LENGTH": 63, "MEDIUM": 1, "ENABLE": 0}
    assert POWER_IN.decode(r10) == {"LEVEL": 9, "ENABLE": 1}
    assert POWER_OUT_BRANCH.decode(r11) == {"OUT_LEVEL": 11, "BRANCH_LEVEL": MAX_LEVEL}
    assert registers(OpticalStatus()) == (0, 0, 0, 0)  # OPT-9: unused interfaces read 0
    assert status[Interface.BRANCH] is branch
    assert status.with_transmitter(Interface.OUT, branch)[Interface.OUT] is branch
    assert status.with_length(Interface.BRANCH, 5, Medium.POLYMER).length == (24, 5)


def test_timing_constants() -> None:
    assert INIT_TIME_LIMIT_CLOCKS == 192_000 and INIT_TIME_LIMIT_S == 6e-3
    # OPT-5: two directions of 14 steps fit the 6 ms at the slower rate.
    assert 2 * (INIT_MAX_STEPS + 1) * INIT_STEP_BITS / min(BIT_RATES) <= INIT_TIME_LIMIT_S
    assert [length_timer_enable_every(rate) for rate in sorted(BIT_RATES)] == [4, 1]


@pytest.mark.parametrize(("call", "name"), [
    (lambda: Transmitter(level=0), "level"),
    (lambda: Transmitter(level=16), "level"),
    (lambda: Transmitter(steps=14), "steps"),
    (lambda: Transmitter(passes=DECREASE_AFTER), "passes"),
    (lambda: Transmitter(mau=bad(1)), "mau"),
    (lambda: Transmitter(phase=bad("init")), "phase"),
    (lambda: start(bad(1), True), "mode"),
    (lambda: start(OpticalMode.REGULATION, bad(1)), "present"),
    (lambda: init_response(Transmitter(Phase.INIT), bad(1)), "response"),
    (lambda: init_response(bad(None), Response.NONE), "transmitter"),
    (lambda: online_test(Transmitter(), bad(1), True), "ack1"),
    (lambda: online_test(Transmitter(), True, bad(None)), "ack2"),
    (lambda: mau_after(False, 0, 1), "old"),
    (lambda: diagnostic_mau(bad(0), True, True), "mau"),
    (lambda: probe_power_db(5, 3), "test"),
    (lambda: fo_lit(Transmitter(), bad("yes")), "run"),
    (lambda: OpticalStatus(bad((Transmitter(),))), "transmitters"),
    (lambda: OpticalStatus(length=(64, 0)), "length"),
    (lambda: OpticalStatus(length=bad((1,))), "length"),
    (lambda: OpticalStatus(medium=bad((0, 1))), "medium"),
    (lambda: OpticalStatus().with_length(Interface.IN, 1, Medium.POLYMER), "interface"),
    (lambda: OpticalStatus()[bad(1)], "interface"),
    (lambda: registers(bad((0, 0, 0, 0))), "status"),
    (lambda: length_timer_enable_every(1_000_000), "bit_rate"),
])  # fmt: skip
def test_hostile_arguments_get_named_errors(call: object, name: str) -> None:
    assert callable(call)
    with pytest.raises(ArgumentError) as info:
        call()
    assert info.value.name == name

"""The length reading OPT-1 (supi3.optical.length): manual 1.6.1 (L = n / (f t), Table 1-5), 3.4.12 (Figure 3-16,
polymer 12 m / glass 200 m), Figure 1-10's lengths; every code, every timer count of the range, hostile input."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from supi3 import tables, timing
from supi3.errors import ArgumentError
from supi3.optical.length import (
    GLASS_UNIT_M,
    LENGTH_MAX_CODE,
    MAX_PATH_M,
    POLYMER_UNIT_M,
    Medium,
    code_range_m,
    length_code,
    length_m,
    timer_code,
    timer_count,
    unit_m,
)
from support import bad

MEDIA = list(Medium)


@pytest.mark.parametrize("medium", MEDIA)
def test_every_code_round_trips_through_its_range(medium: Medium) -> None:
    previous_high = 0.0
    for code in range(LENGTH_MAX_CODE + 1):
        low, high = code_range_m(code, medium)
        assert low == previous_high and low < high
        assert length_m(code, medium) == low
        assert length_code(low, medium) == code
        assert length_code(math.nextafter(high, 0.0), medium) == code
        previous_high = high
    assert previous_high == MAX_PATH_M


def test_table_1_5_value_range_holds_at_both_bit_rates_for_polymer() -> None:
    # 0..62 cover 0 m to 400 m, 63 is 400 m to 20 km; the boundary is 63 units = 393.75 m, "400 m" in round figures.
    boundary = LENGTH_MAX_CODE * POLYMER_UNIT_M
    assert boundary == 393.75
    for row in tables.OPTICAL_LENGTH_RANGES:
        low = max(row.min_m, boundary) if row.values[0] == LENGTH_MAX_CODE else row.min_m
        high = min(row.max_m, MAX_PATH_M, boundary - 1e-6) if row.values[1] < LENGTH_MAX_CODE else MAX_PATH_M
        codes = {timer_code(timer_count(m, row.bit_rate), row.bit_rate, Medium.POLYMER) for m in (low, high)}
        assert all(row.values[0] <= code <= row.values[1] for code in codes), row


def test_resolution_column_is_forward_and_return_metres_per_count() -> None:
    # Table 1-5: 24 m (500 kbit/s) and 6 m (2 Mbit/s) typical; one count is L = 1 / (f t) = 25 m and 6.25 m.
    for row in tables.OPTICAL_LENGTH_RANGES:
        if row.resolution_m is not None:
            per_count = timing.optical_length_m(1, row.bit_rate)
            assert abs(per_count - row.resolution_m[0]) / row.resolution_m[0] < 0.05


@pytest.mark.parametrize("bit_rate", tables.BIT_RATES)
def test_every_timer_count_gives_half_the_formula_in_units(bit_rate: int) -> None:
    for n in range(4 * 400):
        one_way = timing.optical_length_m(min(n, timing.MAX_OPTICAL_COUNT), bit_rate) / 2 if n <= 63 else None
        code = timer_code(n, bit_rate, Medium.POLYMER)
        if one_way is not None:
            assert code == min(LENGTH_MAX_CODE, math.floor(one_way / POLYMER_UNIT_M + 1e-9))
        assert code == min(LENGTH_MAX_CODE, n * 2 if bit_rate == 500_000 else n // 2)
        assert timer_code(n, bit_rate, Medium.GLASS) == min(LENGTH_MAX_CODE, n * 2 // 32 if bit_rate == 500_000
                                                             else n // 64)


def test_500_kbit_lengths_step_by_12_5_m_as_in_figure_1_10() -> None:
    # Figure 1-10 prints 62, 75, 87, 112, 125, 150, 200 and 275 m: 12.5 m steps, truncated.
    shown = {62, 75, 87, 112, 125, 150, 200, 275}
    reachable = {math.floor(length_m(timer_code(n, 500_000, Medium.POLYMER), Medium.POLYMER)) for n in range(32)}
    assert shown <= reachable
    assert unit_m(Medium.POLYMER) * 2 == 12.5  # 3.4.12: polymer "length resolution: 12 m"
    assert unit_m(Medium.GLASS) == GLASS_UNIT_M == 200  # 3.4.12: glass 200 m


@given(st.floats(0, MAX_PATH_M), st.sampled_from(tables.BIT_RATES), st.sampled_from(MEDIA))
def test_measured_code_never_exceeds_the_true_length(metres: float, bit_rate: int, medium: Medium) -> None:
    code = timer_code(timer_count(metres, bit_rate), bit_rate, medium)
    low, high = code_range_m(code, medium)
    assert low <= metres + 1e-6
    # The measurement loses at most one count (12.5 m or 3.125 m one way) plus the unit's truncation.
    if code < LENGTH_MAX_CODE:
        assert metres < high + (12.5 if bit_rate == 500_000 else 3.125)
    assert code == length_code(metres, medium) or code == length_code(metres, medium) - 1 or (
        bit_rate == 500_000 and code == length_code(metres, medium) - 2)


@pytest.mark.parametrize(("call", "name"), [
    (lambda: length_code(-1, Medium.POLYMER), "one_way_m"),
    (lambda: length_code(20_001, Medium.POLYMER), "one_way_m"),
    (lambda: length_code(float("nan"), Medium.POLYMER), "one_way_m"),
    (lambda: length_code(bad("5"), Medium.POLYMER), "one_way_m"),
    (lambda: length_code(5, bad(0)), "medium"),
    (lambda: code_range_m(64, Medium.GLASS), "code"),
    (lambda: code_range_m(-1, Medium.GLASS), "code"),
    (lambda: code_range_m(True, Medium.GLASS), "code"),
    (lambda: length_m(bad(1.0), Medium.GLASS), "code"),
    (lambda: timer_count(10, 1_000_000), "bit_rate"),
    (lambda: timer_count(10, bad("2M")), "bit_rate"),
    (lambda: timer_code(-1, 500_000, Medium.POLYMER), "count"),
    (lambda: timer_code(3, 500_000, bad("glass")), "medium"),
    (lambda: unit_m(bad(None)), "medium"),
])  # fmt: skip
def test_hostile_arguments_get_named_errors(call: object, name: str) -> None:
    assert callable(call)
    with pytest.raises(ArgumentError) as info:
        call()
    assert info.value.name == name

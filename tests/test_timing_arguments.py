"""supi3.timing's public functions refuse wrong types and out-of-range counts with named errors, never with an
OverflowError, a SyntaxError or a silent float."""

from __future__ import annotations

from collections.abc import Callable

import pytest

from supi3 import timing
from supi3.errors import ArgumentError, Supi3Error


@pytest.mark.parametrize("call", [
    lambda: timing.cpu_access_time_s(10**400, 500_000),
    lambda: timing.cpu_access_time_s(timing.MAX_NETWORK_BYTES + 1, 500_000),
    lambda: timing.data_cycle_time_s(4, 513, 500_000),
    lambda: timing.data_cycle_time_s(10**400, 1, 500_000),
    lambda: timing.report(10**400, 500_000),
    lambda: timing.report(4, 500_000, 513),
    lambda: timing.optical_length_m(timing.MAX_OPTICAL_COUNT + 1, 2_000_000),
    lambda: timing.optical_length_m(timing.max_optical_count(500_000) + 1, 500_000),
    lambda: timing.optical_length_m(10**400, 500_000),
    lambda: timing.timing_table("3-4", 500_000, 10**400),
    lambda: timing.evaluate("1 +", 500_000),
    lambda: timing.evaluate("1 / 0", 500_000),
    lambda: timing.evaluate("(" * 500 + "1" + ")" * 500, 500_000),
])
def test_out_of_range_is_a_timing_error(call: Callable[[], object]) -> None:
    with pytest.raises(timing.TimingError):
        call()


@pytest.mark.parametrize("call", [
    lambda: timing.cpu_access_time_s(4.0, 500_000),  # type: ignore[arg-type]
    lambda: timing.cpu_access_time_s(True, 500_000),
    lambda: timing.cpu_access_time_s(float("nan"), 500_000),  # type: ignore[arg-type]
    lambda: timing.cpu_access_time_s("4", 500_000),  # type: ignore[arg-type]
    lambda: timing.bit_period_s(500_000.0),  # type: ignore[arg-type]
    lambda: timing.data_cycle_time_s(4, 1.5, 500_000),  # type: ignore[arg-type]
    lambda: timing.optical_length_m(float("inf"), 500_000),  # type: ignore[arg-type]
    lambda: timing.report(4, "500k"),  # type: ignore[arg-type]
    lambda: timing.timing_table("3-4", 500_000, 2.0),  # type: ignore[arg-type]
    lambda: timing.evaluate(42, 500_000),  # type: ignore[arg-type]
])
def test_wrong_type_is_an_argument_error(call: Callable[[], object]) -> None:
    with pytest.raises(ArgumentError):
        call()


def test_limits_themselves_pass() -> None:
    assert timing.cpu_access_time_s(timing.MAX_NETWORK_BYTES, 2_000_000) > 0
    assert timing.data_cycle_time_s(0, 512, 500_000) > 0
    assert timing.optical_length_m(timing.MAX_OPTICAL_COUNT, 2_000_000) == pytest.approx(2 * 20_000.0)  # OPT-1
    assert timing.optical_length_m(timing.max_optical_count(500_000), 500_000) == pytest.approx(2 * 20_000.0)
    assert issubclass(timing.TimingError, Supi3Error)

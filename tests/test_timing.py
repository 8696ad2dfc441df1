"""The timing calculator: 3.4.14's CPU access time, the I/O access window, Tables 3-4/3-7/3-15, 1.6.1."""

from __future__ import annotations

import pytest

from supi3 import tables, timing


def test_manual_example_two_word_device_at_500k_gives_234_us() -> None:
    # 3.4.14: "Implemented device: 2 words (32 bits) ... T = 234 µs".
    assert timing.cpu_access_time_s(4, 500_000) == pytest.approx(234e-6)


@pytest.mark.parametrize("bit_rate", tables.BIT_RATES)
@pytest.mark.parametrize("n", [0, 1, 4, 512])
def test_cpu_access_time_formula(bit_rate: int, n: int) -> None:
    assert timing.cpu_access_time_s(n, bit_rate) == pytest.approx(13 * (5 + n) / bit_rate)


def test_io_access_window_is_60_us_at_500k() -> None:
    assert timing.io_access_window_s(500_000) == pytest.approx(60e-6)
    assert timing.io_access_window_s(2_000_000) == pytest.approx(15e-6)


@pytest.mark.parametrize(("call", "message"), [
    (lambda: timing.bit_period_s(1_000_000), "Table 1-7"),
    (lambda: timing.cpu_access_time_s(-1, 500_000), ">= 0"),
    (lambda: timing.timing_table("9-9", 500_000), "no timing table"),
    (lambda: timing.optical_length_m(-3, 500_000), ">= 0"),
    (lambda: timing.optical_range(30_000, 500_000), "Table 1-5"),
    (lambda: timing.evaluate("__import__('os')", 500_000), "cannot evaluate"),
])
def test_named_errors(call: object, message: str) -> None:
    with pytest.raises(timing.TimingError, match=message):
        call()  # type: ignore[operator]


def test_table_3_7_values_at_both_rates() -> None:
    slow = {r.symbol: r for r in timing.timing_table("3-7", 500_000)}
    fast = {r.symbol: r for r in timing.timing_table("3-7", 2_000_000)}
    assert slow["TCLK"].minimum_s == pytest.approx(125e-9)
    assert fast["TCLK"].minimum_s == pytest.approx(31.25e-9)
    assert slow["t0"].minimum_s == pytest.approx(667e-9)  # SCLK 1.5 MHz maximum
    assert fast["t0"].minimum_s == pytest.approx(167e-9)  # SCLK 6 MHz maximum
    assert slow["t3"].minimum_s == pytest.approx(2 * 125e-9 + 10e-9)
    assert slow["t6"].minimum_s == pytest.approx(250e-9)
    assert slow["t6"].maximum_s == pytest.approx(375e-9)
    assert slow["t_SAS_INIT"].minimum_s == pytest.approx(250e-9)


def test_table_3_4_and_3_15_at_500k() -> None:
    spi = {r.symbol: r for r in timing.timing_table("3-4", 500_000, n_bytes=2)}
    assert spi["t0"].minimum_s == pytest.approx(1e-6)  # SCLK 1 MHz at 500 kbaud (Table 3-3)
    assert spi["t8"].minimum_s == pytest.approx(18e-6)
    assert spi["t10"].minimum_s == pytest.approx(50.5e-6)
    exp = {r.symbol: r for r in timing.timing_table("3-15", 2_000_000)}
    assert exp["t0"].minimum_s == pytest.approx(0.5e-6)
    assert exp["t4"].maximum_s == pytest.approx(0.125e-6 - 50e-9)


@pytest.mark.parametrize("table", sorted(timing.TIMING_TABLES))
@pytest.mark.parametrize("bit_rate", tables.BIT_RATES)
def test_every_timing_row_evaluates(table: str, bit_rate: int) -> None:
    rows = timing.timing_table(table, bit_rate)
    assert len(rows) == len(timing.TIMING_TABLES[table])
    assert all(r.minimum_s is not None or r.maximum_s is not None for r in rows)
    assert all(v >= 0 for r in rows for v in (r.minimum_s, r.maximum_s) if v is not None)


def test_optical_length_formula() -> None:
    # 1.6.1: f = 8 MHz at 500 kbit/s, t = 5 ns/m: one timer count is 25 m of fibre (forward and return).
    assert timing.optical_length_m(1, 500_000) == pytest.approx(25.0)
    assert timing.optical_length_m(16, 2_000_000) == pytest.approx(100.0)
    assert timing.optical_range(399, 500_000).values == (0, 62)
    assert timing.optical_range(400, 2_000_000).values == (63, 63)


def test_report() -> None:
    r = timing.report(4, 500_000)
    assert r["cpu_access_time_us"] == 234.0 and r["io_access_window_us"] == 60.0
    assert r["optical_resolution_m"] == {"typical": 24, "worst": 48}


def test_data_cycle_time_follows_the_wire_format() -> None:
    from supi3.interbus import wire

    t = timing.data_cycle_time_s(4, 1, 500_000)
    assert t == pytest.approx(wire.cycle_bits(4, 1) * 2e-6)
    # At least the frame of 13 x (6 + n) bit periods (Beckhoff's formula, docs/interbus.md).
    assert t >= 13 * (6 + 4) * 2e-6
    assert timing.data_cycle_time_s(8, 2, 2_000_000) > timing.data_cycle_time_s(4, 1, 2_000_000)
    with pytest.raises(timing.TimingError, match="devices >= 1"):
        timing.data_cycle_time_s(4, 0, 500_000)


def test_limit_reads_one_table_value() -> None:
    assert timing.limit("3-7", "t_SAS_INIT", 500_000) == pytest.approx(250e-9)
    assert timing.limit("3-7", "t6", 500_000, maximum=True) == pytest.approx(375e-9)
    with pytest.raises(timing.TimingError, match="no maximum"):
        timing.limit("3-7", "t1", 500_000, maximum=True)
    with pytest.raises(timing.TimingError, match="no parameter"):
        timing.limit("3-7", "t99", 500_000)

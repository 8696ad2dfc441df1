"""The fibre-link physics (supi3.optical.link): CUR_LIM network (manual 2.1.2, Table 2-3), power per level (1.6.2,
OPT-4), fibre, connectors, receiver range and distortion, events over time, runtime of light (1.6.1); OPT-40..45."""

from __future__ import annotations

import itertools
import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from supi3.errors import ArgumentError
from supi3.optical import length, link, regulation
from supi3.optical.length import Medium
from supi3.optical.link import (
    Ageing,
    Bend,
    Direction,
    Fibre,
    FibreLink,
    LightState,
    Pull,
    Temperature,
    Transceiver,
)
from supi3.optical.regulation import MAX_LEVEL, MIN_LEVEL

FWD, RET = Direction.FORWARD, Direction.RETURN
ALLOWED = sorted(r for r in map(link.reference_ohm, range(32)) if r >= link.REFERENCE_MIN_OHM)


def test_network_of_table_2_3() -> None:
    assert link.reference_ohm(0) == 2400.0  # R1 alone, hard-wired
    assert link.reference_ohm(0b00001) == pytest.approx(1 / (1 / 2400 + 1 / 3900))  # LB1 adds R2
    assert link.reference_ohm(0b11111) < link.REFERENCE_MIN_OHM  # all bridges: 1.09 kOhm, not allowed
    with pytest.raises(ArgumentError, match=r"1\.2 kOhm to 2\.4 kOhm"):
        link.reference_current_a(link.reference_ohm(0b11111))
    for bad in (-1, 32, 1.0, "1", True):
        with pytest.raises(ArgumentError, match="bridges must be"):
            link.reference_ohm(bad)  # type: ignore[arg-type]


def test_network_steps_are_within_0_3_db() -> None:
    """2.1.2: "a maximum light output increment of 0.3 dB": with light proportional to current (OPT-40) the
    largest step between allowed settings is 0.18 dB; proportional to the square of the current it would be 0.36."""
    steps = [link.current_db(a) - link.current_db(b) for a, b in itertools.pairwise(ALLOWED)]
    assert 0.15 < max(steps) <= 0.3 < 2 * max(steps)
    assert len(ALLOWED) == 26  # of the 32 bridge settings, 6 fall below 1.2 kOhm
    assert link.current_db(2400.0) == 0.0
    assert link.current_db(1200.0) == pytest.approx(10 * math.log10(2))  # the whole range: 3 dB


def test_currents() -> None:
    assert link.reference_current_a(1200.0) == pytest.approx(1e-3)  # 1.2 V / 1.2 kOhm
    assert link.led_current_a(1200.0) == pytest.approx(60e-3)  # AN60 at full scale
    assert link.led_current_a(2400.0) == pytest.approx(30e-3)
    for level in range(MIN_LEVEL, MAX_LEVEL + 1):
        ratio = link.led_current_a(2400.0, level) / link.led_current_a(2400.0)
        assert 10 * math.log10(ratio) == pytest.approx(-(MAX_LEVEL - level) * 1.0)
    for bad in (1199.0, 2401.0, math.nan, "2400"):
        with pytest.raises(ArgumentError, match="ohm must be"):
            link.reference_current_a(bad)  # type: ignore[arg-type]


@pytest.mark.parametrize("fibre", list(Fibre))
def test_power_per_level_and_test(fibre: Fibre) -> None:
    cable = FibreLink(30.0, fibre)
    full = cable.received_dbm(FWD, MAX_LEVEL, 0, 0.0)
    for level in range(MIN_LEVEL, MAX_LEVEL + 1):
        for test in range(3):
            expected = regulation.probe_power_db(level, test)
            assert cable.received_dbm(FWD, level, test, 0.0) - full == pytest.approx(expected)
    spec = link.FIBRES[fibre]
    assert full == pytest.approx(link.TRANSCEIVERS[fibre].launch_dbm - 30 * spec.db_per_m - 2 * spec.connector_db)
    stronger = FibreLink(30.0, fibre, forward_ohm=1200.0, couplings=1)
    assert stronger.received_dbm(FWD, MAX_LEVEL, 0, 0.0) - full == pytest.approx(
        link.current_db(1200.0) - spec.connector_db)
    assert stronger.received_dbm(RET, MAX_LEVEL, 0, 0.0) - full == pytest.approx(-spec.connector_db)


def test_media_report_opt_3() -> None:
    assert [FibreLink(1.0, f).medium for f in Fibre] == [Medium.POLYMER, Medium.POLYMER, Medium.GLASS]


def test_runtime_of_light() -> None:
    cable = FibreLink(150.0)
    assert cable.delay_s == pytest.approx(750e-9)  # 5 ns/m
    for rate in (500_000, 2_000_000):
        assert cable.timer_count(rate) == length.timer_count(150.0, rate)
        assert length.timer_code(cable.timer_count(rate), rate, cable.medium) == length.length_code(150.0,
                                                                                                    Medium.POLYMER)


def test_polymer_levels_span_the_length_range() -> None:
    """OPT-4/OPT-42: 15 levels of 1 dB cover a polymer path from a few metres to about 80 m."""
    levels = [FibreLink(float(m)).settled_level(FWD, 0.0) for m in range(5, 81, 5)]
    assert levels[0] == MIN_LEVEL and levels[-1] == MAX_LEVEL
    assert all(a is not None and b is not None and a <= b for a, b in itertools.pairwise(levels))
    assert FibreLink(90.0).settled_level(FWD, 0.0) is None  # no reserve even at MAX: a MAU warning
    assert FibreLink(90.0).state(FWD, MAX_LEVEL, 0.0) is LightState.CLEAR  # ... but telegrams still pass
    assert FibreLink(100.0).state(FWD, MAX_LEVEL, 0.0) is LightState.MARGINAL
    assert FibreLink(200.0).state(FWD, MAX_LEVEL, 0.0) is LightState.DARK


def test_settled_level_is_the_regulation_target() -> None:
    """At the settled level test 1 is detected and test 2 is not (1.6.2: hold)."""
    for metres in range(5, 80, 3):
        cable = FibreLink(float(metres))
        level = cable.settled_level(FWD, 0.0)
        assert level is not None
        assert cable.detected(FWD, level, 1, 0.0)
        assert level == MIN_LEVEL or not cable.detected(FWD, level, 2, 0.0)


def test_distortion_and_margin() -> None:
    rx = Transceiver(launch_dbm=-5.0, sensitivity_dbm=-27.0, overload_dbm=-3.0)
    assert link.distortion_db(-15.0, rx) == 0.0  # mid-range
    assert link.distortion_db(-27.0, rx) == pytest.approx(link.DISTORTION_PENALTY_DB)
    assert link.distortion_db(-3.0, rx) == pytest.approx(link.DISTORTION_PENALTY_DB)
    assert link.margin_db(-15.0, rx) == 12.0
    assert link.margin_db(-27.0, rx) < 0 < link.margin_db(-26.0, rx)
    assert link.margin_db(-2.0, rx) < 0 < link.margin_db(-4.5, rx)  # overload
    assert link.margin_db(-math.inf, rx) == -math.inf


def test_overload_makes_a_short_link_fail() -> None:
    hot = Transceiver(launch_dbm=1.0, sensitivity_dbm=-27.0, overload_dbm=-3.0)
    cable = FibreLink(1.0, transceiver=hot)
    assert not cable.detected(FWD, MAX_LEVEL, 0, 0.0)
    assert cable.detected(FWD, MAX_LEVEL - 4, 0, 0.0)


def test_bit_error_rate() -> None:
    assert link.bit_error_rate(0.0) == pytest.approx(1e-9, rel=0.05)
    rates = [link.bit_error_rate(m / 2) for m in range(-12, 6)]
    assert rates == sorted(rates, reverse=True)
    assert link.bit_error_rate(-math.inf) == 0.5
    assert FibreLink(10.0).bit_error_rate(FWD, MAX_LEVEL, 0.0) < 1e-30


def test_pull_and_reconnect() -> None:
    cable = FibreLink(20.0, events=(Pull(1.0, 0.5),))
    assert cable.state(FWD, MAX_LEVEL, 0.99) is LightState.CLEAR
    for t in (1.0, 1.2, 1.49):
        for d in Direction:
            assert cable.received_dbm(d, MAX_LEVEL, 0, t) == -math.inf
            assert cable.state(d, MAX_LEVEL, t) is LightState.DARK
            assert not cable.detected(d, MAX_LEVEL, 0, t)
    assert cable.state(RET, MAX_LEVEL, 1.5) is LightState.CLEAR
    cable.add(Pull(2.0))
    assert cable.state(RET, MAX_LEVEL, 1000.0) is LightState.DARK


def test_bend_one_fibre() -> None:
    cable = FibreLink(20.0)
    cable.add(Bend(0.1, 0.2, 4.0, Direction.RETURN))
    assert cable.extra_loss_db(RET, 0.2) == 4.0 and cable.extra_loss_db(FWD, 0.2) == 0.0
    assert cable.extra_loss_db(RET, 0.31) == cable.extra_loss_db(RET, 0.09) == 0.0
    both = FibreLink(20.0, events=(Bend(0.0, None, 2.5),))
    assert both.extra_loss_db(FWD, 9.0) == both.extra_loss_db(RET, 9.0) == 2.5


def test_drift() -> None:
    cable = FibreLink(20.0, events=(Ageing(1.0, 2.0, limit_db=3.0, direction=FWD),))
    assert [cable.extra_loss_db(FWD, t) for t in (0.5, 1.0, 1.5, 2.0, 10.0)] == [0.0, 0.0, 1.0, 2.0, 3.0]
    assert cable.extra_loss_db(RET, 10.0) == 0.0
    warm = FibreLink(20.0, events=(Temperature(0.0, 10.0, 4.0),))
    assert warm.extra_loss_db(FWD, 1.0) == pytest.approx(-link.LED_TEMPCO_DB_PER_K * 10.0)  # warmest: less light
    assert warm.extra_loss_db(FWD, 3.0) == pytest.approx(link.LED_TEMPCO_DB_PER_K * 10.0)
    assert warm.extra_loss_db(FWD, 2.0) == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize(("kwargs", "name"), [
    ({"length_m": -1.0}, "length_m"), ({"length_m": 20_001.0}, "length_m"), ({"length_m": "5"}, "length_m"),
    ({"fibre": "polymer"}, "fibre"), ({"forward_ohm": 1000.0}, "forward_ohm"), ({"return_ohm": 3000.0}, "return_ohm"),
    ({"couplings": -1}, "couplings"), ({"couplings": 1.5}, "couplings"), ({"transceiver": 3}, "transceiver"),
    ({"events": [Pull(0.0)]}, "events"), ({"events": (3,)}, "event"),
])  # fmt: skip
def test_link_arguments_are_checked(kwargs: dict[str, object], name: str) -> None:
    args: dict[str, object] = {"length_m": 10.0, **kwargs}
    with pytest.raises(ArgumentError, match=rf"^{name} must be"):
        FibreLink(**args)  # type: ignore[arg-type]


def test_method_and_event_arguments_are_checked() -> None:
    cable = FibreLink(10.0)
    with pytest.raises(ArgumentError, match=r"^direction must be"):
        cable.received_dbm(0, MAX_LEVEL, 0, 0.0)  # type: ignore[arg-type]
    with pytest.raises(ArgumentError, match=r"^level must be"):
        cable.received_dbm(FWD, 16, 0, 0.0)
    with pytest.raises(ArgumentError, match=r"^test must be"):
        cable.detected(FWD, 3, 3, 0.0)
    with pytest.raises(ArgumentError, match=r"^t must be"):
        cable.state(FWD, 3, -1.0)
    for make, name in ((lambda: Bend(-1.0, None, 1.0), "start_s"), (lambda: Bend(0.0, -1.0, 1.0), "duration_s"),
                       (lambda: Bend(0.0, 1.0, 61.0), "loss_db"), (lambda: Bend(0.0, 1.0, 1.0, 1), "direction"),  # type: ignore[arg-type]
                       (lambda: Ageing(0.0, -1.0), "rate_db_per_s"), (lambda: Temperature(0.0, 1.0, 0.0), "period_s"),
                       (lambda: Transceiver(0.0, -27.0, -26.0), "overload_dbm")):  # fmt: skip
        with pytest.raises(ArgumentError, match=rf"^{name} must be"):
            make()


@given(st.floats(0.0, 120.0), st.integers(MIN_LEVEL, MAX_LEVEL), st.floats(0.0, 10.0))
def test_more_loss_never_helps_in_the_lower_half(metres: float, level: int, bend: float) -> None:
    """Below the middle of the receiver's range the margin falls with every dB lost (above it, it rises)."""
    plain = FibreLink(metres)
    bent = FibreLink(metres, events=(Bend(0.0, None, bend),))
    rx = link.TRANSCEIVERS[Fibre.POLYMER]
    for test in range(3):
        if plain.received_dbm(FWD, level, test, 0.0) <= (rx.sensitivity_dbm + rx.overload_dbm) / 2:
            assert bent.margin(FWD, level, test, 0.0) <= plain.margin(FWD, level, test, 0.0)

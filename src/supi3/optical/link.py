"""The physical fibre link between two SUPI 3 OPC devices: transmitter current, fibre, connectors, receiver, time.

What the optical block of a chip regulates (:mod:`supi3.optical.regulation`) is the light on a duplex fibre cable.
This module is the analog side that the manual leaves to the transceivers and the cable (DAC currents,
fibre); it feeds the model and the RTL alike as stimulus. Every number here is one named constant with its evidence
in OPT-40 onward of ``docs/assumptions/optical.md``; the manual gives only the CUR_LIM network
(2.1.2, Table 2-3) and the runtime of light (1.6.1); the fibre and transceiver figures are *typical* datasheet values
for 660 nm polymer/HCS and 850 nm glass transceivers, not the manual's.

* **Transmitter current** (2.1.2): the reference resistor at CUR_LIM (1.2 kOhm to 2.4 kOhm at 1.2 V; Table 2-3's
  network: R1 = 2.4 kOhm hard-wired, R2..R6 in parallel by the solder bridges LB1..LB5) sets the full-scale LED
  current; the light is proportional to the current (OPT-40), so the network's steps are at most about 0.3 dB.
* **Power per level**: the chip's level and test lower the light by :func:`~supi3.optical.regulation.probe_power_db`.
* **Fibre** (:class:`Fibre`): polymer, HCS or glass, with attenuation per metre, the loss of each end connector and
  of each in-line coupling, and the medium the transceiver reports (:class:`~supi3.optical.length.Medium`; OPT-3:
  HCS reports polymer).
* **Receiver** (:class:`Transceiver`): sensitivity and overload, and distortion: a penalty near both ends of the
  receiver's range (OPT-43). The margin above the distorted sensitivity decides whether a pattern is detected, and
  the bit-error risk of telegrams (OPT-44).
* **Time**: slow drift (:class:`Ageing`, :class:`Temperature`) and sudden events (:class:`Bend`, :class:`Pull`)
  change the loss of a fibre over bus time (OPT-45); light takes 5 ns/m (1.6.1, :func:`FibreLink.timer_count`).

A :class:`FibreLink` is one duplex cable: the forward fibre (transmitter: the upstream chip's outgoing interface, or
a bus terminal module's branch) and the return fibre (transmitter: the downstream chip's incoming interface).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum, IntEnum
from typing import Final

from supi3.checks import check_instance, check_int, check_real, fail
from supi3.optical.length import MAX_PATH_M, Medium, timer_count
from supi3.optical.regulation import MAX_LEVEL, MIN_LEVEL, probe_power_db
from supi3.tables import LIGHT_RUNTIME_S_PER_M

__all__ = [
    "AGEING_LIMIT_DB",
    "CUR_LIM_VOLTAGE_V",
    "DISTORTION_PENALTY_DB",
    "DISTORTION_WINDOW_DB",
    "FIBRES",
    "LED_CURRENT_GAIN",
    "LED_TEMPCO_DB_PER_K",
    "LOSS_OF_LIGHT_DB",
    "MAX_EXTRA_LOSS_DB",
    "NETWORK_OHMS",
    "REFERENCE_MAX_OHM",
    "REFERENCE_MIN_OHM",
    "SENSITIVITY_Q",
    "TRANSCEIVERS",
    "Ageing",
    "Bend",
    "Direction",
    "Event",
    "Fibre",
    "FibreLink",
    "FibreSpec",
    "LightState",
    "Pull",
    "Temperature",
    "Transceiver",
    "bit_error_rate",
    "current_db",
    "distortion_db",
    "led_current_a",
    "margin_db",
    "reference_current_a",
    "reference_ohm",
]

_MANUAL_212: Final = "manual 2.1.2: 1.2 kOhm to 2.4 kOhm at CUR_LIM"

# ----------------------------------------------------------------------------------------------------------------
# Transmitter current: the CUR_LIM reference network (2.1.2, Table 2-3; OPT-40)
# ----------------------------------------------------------------------------------------------------------------

CUR_LIM_VOLTAGE_V: Final = 1.2
"""The voltage at CUR_LIM (2.1.2: "The voltage at this pin is 1.2 V")."""
REFERENCE_MIN_OHM: Final = 1200.0
"""The smallest reference resistor allowed (2.1.2)."""
REFERENCE_MAX_OHM: Final = 2400.0
"""The largest reference resistor allowed (2.1.2); it is R1 of Table 2-3, hard-wired."""
NETWORK_OHMS: Final[tuple[float, ...]] = (2400.0, 3900.0, 7500.0, 15_000.0, 33_000.0, 56_000.0)
"""Table 2-3: R1 (hard-wired) and R2..R6, which the solder bridges LB1..LB5 connect in parallel."""
LED_CURRENT_GAIN: Final = 60.0
"""LED current per reference current (OPT-40): the DAC output is an AN60 cell (Table 1-4: "DAC current output
60 mA"), reached at the smallest resistor (1.2 V / 1.2 kOhm = 1 mA); 2.4 kOhm gives 30 mA."""


def reference_ohm(bridges: int) -> float:
    """The reference resistor of Table 2-3's network with the solder bridges ``bridges`` closed.

    ``bridges`` is a 5-bit mask: bit 0 is LB1 (R2 in parallel), ..., bit 4 is LB5 (R6). The result may lie below
    :data:`REFERENCE_MIN_OHM` (all bridges closed give 1.09 kOhm); :func:`reference_current_a` refuses those.
    """
    mask = check_int("bridges", bridges, 0, 0b11111, "solder bridges LB1..LB5 (Table 2-3), a 5-bit mask")
    conductance = 1 / NETWORK_OHMS[0] + sum(1 / r for i, r in enumerate(NETWORK_OHMS[1:]) if mask >> i & 1)
    return 1 / conductance


def _ohm(name: str, ohm: object) -> float:
    return check_real(name, ohm, REFERENCE_MIN_OHM, REFERENCE_MAX_OHM, limit=_MANUAL_212)


def reference_current_a(ohm: float) -> float:
    """The reference current at CUR_LIM for a resistor (1.2 V across it; 2.1.2)."""
    return CUR_LIM_VOLTAGE_V / _ohm("ohm", ohm)


def led_current_a(ohm: float, level: int = MAX_LEVEL) -> float:
    """The LED current at a power level: full scale (:data:`LED_CURRENT_GAIN` times the reference current) at
    :data:`~supi3.optical.regulation.MAX_LEVEL`, one level step of light less per level (OPT-4, OPT-40)."""
    return LED_CURRENT_GAIN * reference_current_a(ohm) * 10 ** (probe_power_db(level, 0) / 10)


def current_db(ohm: float) -> float:
    """The full-power light of a resistor relative to R1 alone (2.4 kOhm): 0 dB to +3 dB (light ~ current, OPT-40)."""
    return 10 * math.log10(REFERENCE_MAX_OHM / _ohm("ohm", ohm))


# ----------------------------------------------------------------------------------------------------------------
# Fibres and transceivers (typical datasheet values, not the manual's; OPT-41, OPT-42)
# ----------------------------------------------------------------------------------------------------------------


class Fibre(Enum):
    """The fibre of a cable."""

    POLYMER = "polymer"
    """1 mm step-index polymer fibre (POF), 660 nm."""
    HCS = "HCS"
    """Hard-clad silica, 200/230 um, on the same 660 nm transceivers (OPT-3)."""
    GLASS = "glass"
    """Multimode glass, 62.5/125 um, 850 nm."""


@dataclass(frozen=True)
class FibreSpec:
    """What a fibre type brings to a link: attenuation, connector loss, wavelength, the medium reported."""

    db_per_m: float
    connector_db: float
    wavelength_nm: int
    medium: Medium


@dataclass(frozen=True)
class Transceiver:
    """A transmitter and receiver pair for one fibre type (typical values, OPT-42).

    Attributes
    ----------
    launch_dbm:
        Light launched into the fibre at full power (level 15) with R1 alone (2.4 kOhm); a smaller resistor adds
        :func:`current_db`.
    sensitivity_dbm:
        The weakest light received with a bit-error rate of 1e-9 (:data:`SENSITIVITY_Q`).
    overload_dbm:
        The strongest light received without errors.
    """

    launch_dbm: float
    sensitivity_dbm: float
    overload_dbm: float

    def __post_init__(self) -> None:
        check_real("launch_dbm", self.launch_dbm, -60.0, 10.0, limit="a transmitter's launched power")
        check_real("sensitivity_dbm", self.sensitivity_dbm, -70.0, 0.0, limit="a receiver's sensitivity")
        check_real("overload_dbm", self.overload_dbm, self.sensitivity_dbm + 2 * DISTORTION_WINDOW_DB, 10.0,
                   limit="a receiver's overload, above its distortion windows")  # fmt: skip


POLYMER_DB_PER_M: Final = 0.20
"""POF attenuation at 660 nm (OPT-41; typical cable datasheets give 0.16 to 0.23 dB/m)."""
HCS_DB_PER_M: Final = 0.008
"""HCS attenuation at 660 nm, 8 dB/km (OPT-41; typical 6 to 10 dB/km)."""
GLASS_DB_PER_M: Final = 0.003
"""Multimode glass attenuation at 850 nm, 3 dB/km (OPT-41; typical 2.7 to 3.5 dB/km; about 1 dB/km at 1300 nm)."""
POLYMER_CONNECTOR_DB: Final = 1.0
"""Loss of one POF connection (end connector at a device or in-line coupling; OPT-41; typical 1 to 2 dB)."""
HCS_CONNECTOR_DB: Final = 1.0
"""Loss of one HCS connection (OPT-41; typical 0.5 to 1.5 dB)."""
GLASS_CONNECTOR_DB: Final = 0.5
"""Loss of one glass connection (ST/SC, OPT-41; typical 0.3 to 0.75 dB)."""
END_CONNECTORS: Final = 2
"""Connections every fibre has: the plug at each device (in-line couplings come on top)."""

FIBRES: Final[dict[Fibre, FibreSpec]] = {
    Fibre.POLYMER: FibreSpec(POLYMER_DB_PER_M, POLYMER_CONNECTOR_DB, 660, Medium.POLYMER),
    Fibre.HCS: FibreSpec(HCS_DB_PER_M, HCS_CONNECTOR_DB, 660, Medium.POLYMER),
    Fibre.GLASS: FibreSpec(GLASS_DB_PER_M, GLASS_CONNECTOR_DB, 850, Medium.GLASS),
}
"""Each fibre type's figures (OPT-41) and the medium its transceiver reports (OPT-3)."""

DISTORTION_WINDOW_DB: Final = 3.0
"""Distortion grows within this many dB of the sensitivity and of the overload (OPT-43)."""
DISTORTION_PENALTY_DB: Final = 1.0
"""The distortion penalty at the sensitivity and at the overload themselves (OPT-43)."""

TRANSCEIVERS: Final[dict[Fibre, Transceiver]] = {
    Fibre.POLYMER: Transceiver(launch_dbm=-5.0, sensitivity_dbm=-27.0, overload_dbm=-3.0),
    Fibre.HCS: Transceiver(launch_dbm=-12.0, sensitivity_dbm=-27.0, overload_dbm=-3.0),
    Fibre.GLASS: Transceiver(launch_dbm=-19.0, sensitivity_dbm=-36.0, overload_dbm=-13.0),
}
"""Typical 660 nm LED/PIN transceivers into POF and HCS (the HCS launch is lower: the 200 um core takes less of the
LED's light) and 850 nm LED/PIN transceivers into 62.5 um glass (OPT-42)."""

SENSITIVITY_Q: Final = 6.0
"""The receiver's Q factor at its sensitivity: a bit-error rate of 1e-9 (OPT-44)."""
LOSS_OF_LIGHT_DB: Final = -6.0
"""Below this margin the receiver sees no signal at all (a bit-error rate of 0.07): the line is dead (OPT-44)."""

LED_TEMPCO_DB_PER_K: Final = -0.02
"""Light of a 660 nm or 850 nm LED per kelvin (OPT-45; typical -0.4 to -0.6 %/K)."""
AGEING_LIMIT_DB: Final = 3.0
"""The most an LED loses over its life by default (OPT-45; typical end-of-life criterion -3 dB)."""
MAX_EXTRA_LOSS_DB: Final = 60.0
"""The most loss an event adds (a bend that leaves no light is a :class:`Pull`)."""


def distortion_db(received_dbm: float, transceiver: Transceiver) -> float:
    """The distortion penalty of light received at ``received_dbm`` (OPT-43): rising linearly to
    :data:`DISTORTION_PENALTY_DB` over the last :data:`DISTORTION_WINDOW_DB` before the sensitivity and before the
    overload, and beyond them."""
    power = check_real("received_dbm", received_dbm, finite=False)
    rx = check_instance("transceiver", transceiver, Transceiver)
    low = max(0.0, 1 - (power - rx.sensitivity_dbm) / DISTORTION_WINDOW_DB)
    high = max(0.0, 1 - (rx.overload_dbm - power) / DISTORTION_WINDOW_DB)
    return DISTORTION_PENALTY_DB * (low + high)


def margin_db(received_dbm: float, transceiver: Transceiver) -> float:
    """How far light received at ``received_dbm`` lies inside the receiver's range, less distortion (OPT-43):
    ``min(P - sensitivity, overload - P) - distortion``; 0 or more is error-free, ``-inf`` is no light."""
    power = check_real("received_dbm", received_dbm, finite=False)
    rx = check_instance("transceiver", transceiver, Transceiver)
    if power == -math.inf:
        return -math.inf
    return min(power - rx.sensitivity_dbm, rx.overload_dbm - power) - distortion_db(power, rx)


def bit_error_rate(margin: float) -> float:
    """The bit-error rate at a margin (OPT-44): Q = :data:`SENSITIVITY_Q` x 10^(margin / 10), BER = erfc(Q / sqrt 2)
    / 2; 0.5 without light."""
    m = check_real("margin", margin, finite=False)
    if m == -math.inf:
        return 0.5
    q = SENSITIVITY_Q * 10 ** (min(m, 20.0) / 10)
    return 0.5 * math.erfc(q / math.sqrt(2))


# ----------------------------------------------------------------------------------------------------------------
# Events over time (OPT-45)
# ----------------------------------------------------------------------------------------------------------------


class Direction(IntEnum):
    """The two fibres of a duplex cable."""

    FORWARD = 0
    """Upstream chip's outgoing interface (or a bus terminal module's branch) to the downstream chip."""
    RETURN = 1
    """Downstream chip's incoming interface back to the upstream chip."""


class LightState(Enum):
    """What a receiver makes of the light at the current level (OPT-44)."""

    CLEAR = "clear"
    """Margin 0 or more: error-free."""
    MARGINAL = "marginal"
    """Margin below 0 but above :data:`LOSS_OF_LIGHT_DB`: telegrams get through with bit errors."""
    DARK = "dark"
    """No signal: the line is dead."""


def _time(name: str, value: object) -> float:
    return check_real(name, value, 0.0, limit="bus time in seconds")


def _duration(value: object) -> float | None:
    return None if value is None else check_real("duration_s", value, 0.0, finite=False)


def _direction(value: object) -> Direction | None:
    return None if value is None else check_instance("direction", value, Direction, "a Direction or None (both)")


def _active(start: float, duration: float | None, t: float) -> bool:
    return start <= t and (duration is None or t < start + duration)


def _at(direction: object, t: object) -> tuple[Direction, float]:
    """The arguments of an event's ``loss``: a :class:`Direction` and a bus time, checked by name."""
    return check_instance("direction", direction, Direction), _time("t", t)


class _Timed:
    """What every event offers: :meth:`loss` with its arguments checked; the subclass's ``_loss`` computes it (the
    link checks once for all its events, :meth:`FibreLink.extra_loss_db`)."""

    def loss(self, direction: Direction, t: float) -> float:
        """The extra loss (dB; ``inf`` without light, negative for a gain) on ``direction`` at bus time ``t``."""
        return self._loss(*_at(direction, t))

    def _loss(self, direction: Direction, t: float) -> float:
        raise NotImplementedError


@dataclass(frozen=True)
class Bend(_Timed):
    """A fibre bent (or squeezed) from ``start_s`` for ``duration_s`` (``None``: until the end): ``loss_db`` more
    loss on ``direction`` (``None``: both fibres of the cable)."""

    start_s: float
    duration_s: float | None
    loss_db: float
    direction: Direction | None = None

    def __post_init__(self) -> None:
        _time("start_s", self.start_s)
        _duration(self.duration_s)
        check_real("loss_db", self.loss_db, 0.0, MAX_EXTRA_LOSS_DB, limit="an event's extra loss")
        _direction(self.direction)

    def _loss(self, direction: Direction, t: float) -> float:
        """The extra loss on ``direction`` at bus time ``t``."""
        hit = self.direction is None or self.direction is direction
        return self.loss_db if hit and _active(self.start_s, self.duration_s, t) else 0.0


@dataclass(frozen=True)
class Pull(_Timed):
    """The cable's connector pulled at ``start_s`` and put back after ``duration_s`` (``None``: never): no light on
    either fibre meanwhile."""

    start_s: float
    duration_s: float | None = None

    def __post_init__(self) -> None:
        _time("start_s", self.start_s)
        _duration(self.duration_s)

    def _loss(self, direction: Direction, t: float) -> float:  # noqa: ARG002 (a pull darkens both fibres)
        """``inf`` while pulled, else 0."""
        return math.inf if _active(self.start_s, self.duration_s, t) else 0.0


@dataclass(frozen=True)
class Ageing(_Timed):
    """The transmitter of ``direction`` (``None``: both) losing light from ``start_s`` at ``rate_db_per_s`` (time is
    compressed: a simulated second stands for months) up to ``limit_db``."""

    start_s: float
    rate_db_per_s: float
    limit_db: float = AGEING_LIMIT_DB
    direction: Direction | None = None

    def __post_init__(self) -> None:
        _time("start_s", self.start_s)
        check_real("rate_db_per_s", self.rate_db_per_s, 0.0)
        check_real("limit_db", self.limit_db, 0.0, MAX_EXTRA_LOSS_DB, limit="an event's extra loss")
        _direction(self.direction)

    def _loss(self, direction: Direction, t: float) -> float:
        """The light lost on ``direction`` by bus time ``t``."""
        if (self.direction is not None and self.direction is not direction) or t < self.start_s:
            return 0.0
        return min(self.limit_db, (t - self.start_s) * self.rate_db_per_s)


@dataclass(frozen=True)
class Temperature(_Timed):
    """The transmitters of ``direction`` (``None``: both) swinging by ``amplitude_k`` kelvin around their
    temperature with period ``period_s`` from ``start_s``: ``-LED_TEMPCO_DB_PER_K * dT`` dB more loss when warmer."""

    start_s: float
    amplitude_k: float
    period_s: float
    direction: Direction | None = None

    def __post_init__(self) -> None:
        _time("start_s", self.start_s)
        check_real("amplitude_k", self.amplitude_k, 0.0, 100.0, limit="a temperature swing in kelvin")
        check_real("period_s", self.period_s, 1e-6)
        _direction(self.direction)

    def _loss(self, direction: Direction, t: float) -> float:
        """The light lost (negative: gained) on ``direction`` at bus time ``t``."""
        if (self.direction is not None and self.direction is not direction) or t < self.start_s:
            return 0.0
        delta_k = self.amplitude_k * math.sin(2 * math.pi * (t - self.start_s) / self.period_s)
        return -LED_TEMPCO_DB_PER_K * delta_k


Event = Bend | Pull | Ageing | Temperature
"""Something that changes a fibre's loss over time."""

_EVENTS: Final = (Bend, Pull, Ageing, Temperature)


# ----------------------------------------------------------------------------------------------------------------
# The link
# ----------------------------------------------------------------------------------------------------------------


class FibreLink:
    """One duplex fibre cable between two devices.

    Parameters
    ----------
    length_m:
        One-way length of the cable, 0 to 20 km (Table 1-5).
    fibre:
        The fibre type (:class:`Fibre`).
    forward_ohm, return_ohm:
        The reference resistor at CUR_LIM of the forward transmitter (the upstream device) and of the return
        transmitter (the downstream device), 1.2 kOhm to 2.4 kOhm (2.1.2; :func:`reference_ohm` from solder bridges).
    couplings:
        In-line connections on each fibre besides the two end connectors.
    transceiver:
        The transceivers at both ends; ``None``: the fibre type's typical one (:data:`TRANSCEIVERS`).
    events:
        Events over time (:meth:`add` adds more).
    """

    def __init__(self, length_m: float, fibre: Fibre = Fibre.POLYMER, *, forward_ohm: float = REFERENCE_MAX_OHM,
                 return_ohm: float = REFERENCE_MAX_OHM, couplings: int = 0, transceiver: Transceiver | None = None,
                 events: tuple[Event, ...] = ()) -> None:  # fmt: skip
        self.length_m = check_real("length_m", length_m, 0.0, MAX_PATH_M, limit="Table 1-5: 0 m to 20 km")
        self.fibre = check_instance("fibre", fibre, Fibre)
        self.ohm = (_ohm("forward_ohm", forward_ohm), _ohm("return_ohm", return_ohm))
        self.couplings = check_int("couplings", couplings, 0, 100)
        rx = TRANSCEIVERS[self.fibre] if transceiver is None else transceiver
        self.transceiver = check_instance("transceiver", rx, Transceiver, "a Transceiver or None")
        if not isinstance(events, tuple):
            raise fail("events", "a tuple of events (Bend, Pull, Ageing, Temperature)", events)
        self.events: list[Event] = []
        for event in events:
            self.add(event)

    def __repr__(self) -> str:
        return f"FibreLink({self.length_m:g} m {self.fibre.value}, {len(self.events)} events)"

    @property
    def spec(self) -> FibreSpec:
        """The fibre type's figures."""
        return FIBRES[self.fibre]

    @property
    def medium(self) -> Medium:
        """The medium the transceivers report (OPT-3: HCS reports polymer)."""
        return self.spec.medium

    @property
    def delay_s(self) -> float:
        """One-way runtime of light, 5 ns/m (1.6.1)."""
        return self.length_m * LIGHT_RUNTIME_S_PER_M

    def timer_count(self, bit_rate: int) -> int:
        """The length timer's result for this cable at ``bit_rate`` (:func:`supi3.optical.length.timer_count`)."""
        return timer_count(self.length_m, bit_rate)

    def add(self, event: Event) -> None:
        """Add an event (its times are bus times)."""
        if not isinstance(event, _EVENTS):
            raise fail("event", "a Bend, Pull, Ageing or Temperature", event)
        self.events.append(event)

    def path_loss_db(self) -> float:
        """The fixed loss of either fibre: attenuation and connections."""
        spec = self.spec
        return self.length_m * spec.db_per_m + (END_CONNECTORS + self.couplings) * spec.connector_db

    def extra_loss_db(self, direction: Direction, t: float) -> float:
        """The loss the events add on ``direction`` at bus time ``t`` (``inf`` while pulled)."""
        direction, now = _at(direction, t)
        return sum(event._loss(direction, now) for event in self.events)  # checked once here

    def received_dbm(self, direction: Direction, level: int, test: int, t: float) -> float:
        """The light at the receiver of ``direction`` when its transmitter sends at ``level`` and ``test`` (0:
        telegrams; 1, 2: the regulation tests, :func:`~supi3.optical.regulation.probe_power_db`) at bus time ``t``;
        ``-inf`` without light."""
        extra = self.extra_loss_db(direction, t)
        sent = self.transceiver.launch_dbm + current_db(self.ohm[direction]) + probe_power_db(level, test)
        return -math.inf if extra == math.inf else sent - self.path_loss_db() - extra

    def margin(self, direction: Direction, level: int, test: int, t: float) -> float:
        """:func:`margin_db` of :meth:`received_dbm`."""
        return margin_db(self.received_dbm(direction, level, test, t), self.transceiver)

    def detected(self, direction: Direction, level: int, test: int, t: float) -> bool:
        """A pattern sent at ``level`` and ``test`` is detected: the margin is 0 or more (OPT-44)."""
        return self.margin(direction, level, test, t) >= 0.0

    def state(self, direction: Direction, level: int, t: float) -> LightState:
        """What telegrams at ``level`` meet on ``direction`` at bus time ``t`` (:class:`LightState`)."""
        m = self.margin(direction, level, 0, t)
        if m >= 0.0:
            return LightState.CLEAR
        return LightState.MARGINAL if m > LOSS_OF_LIGHT_DB else LightState.DARK

    def bit_error_rate(self, direction: Direction, level: int, t: float) -> float:
        """The bit-error rate of telegrams at ``level`` on ``direction`` at bus time ``t`` (:func:`bit_error_rate`)."""
        return bit_error_rate(self.margin(direction, level, 0, t))

    def settled_level(self, direction: Direction, t: float) -> int | None:
        """The level online regulation holds at bus time ``t``: the lowest whose test 1 is detected (1.6.2); ``None``
        if test 1 fails even at :data:`~supi3.optical.regulation.MAX_LEVEL` (a MAU warning, 1.6.3)."""
        for level in range(MIN_LEVEL, MAX_LEVEL + 1):
            if self.detected(direction, level, 1, t):
                return level
        return None

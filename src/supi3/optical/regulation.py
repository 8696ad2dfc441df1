"""Optical power regulation, as data and pure functions: initialization, online 3-point regulation, MAU warnings.

Manual 1.6 (1.6.1 initialization, 1.6.2 online regulation and optical diagnostics, 1.6.3 MAU warnings), Table 2-2
(RF[1..0]), Table 3-17 and Table 2-8 (FO1..FO3), 3.4.12/3.4.13 (reads 8 to 11). The decisions where the manual is
silent are OPT-2 to OPT-12 of ``docs/assumptions/optical.md``; each is one named constant or function here.

Each optical transmitter of a chip (incoming interface: the return line to the previous device; outgoing
interface: the forward line to the next one; branch: the bus terminal module's branch) is one :class:`Transmitter`
value. The chip's optical block holds three and the lengths of the outgoing interface and the branch
(:class:`OpticalStatus`); every change is one of the pure transitions below, so the model's pin level, its
transaction level and the RTL (which re-implements them in gates, ``supi3.rtl.optical``) have one behaviour.

* **Start** (:func:`start`): at the end of an INTERBUS reset, after the automatic interface recognition (1.6), every
  interface in use enters :attr:`Phase.INIT` at :data:`MAX_LEVEL` in regulation mode (RF = 00), or
  :attr:`Phase.DIAGNOSTIC` at :data:`MAX_LEVEL` in optical diagnostics mode (RF = 01, OPT-2); copper modes and
  interfaces not in use are :attr:`Phase.OFF`.
* **Initialization** (:func:`init_response`): each step tests the path at the current level (with the reserve,
  :data:`RESERVE_DB`) and gets the partner's response: "Light off" (:attr:`Response.DETECTED`) lowers the level by
  one; the first "Light on" (:attr:`Response.NOT_DETECTED`) raises it by one and ends the initialization
  (:attr:`Phase.ONLINE`, enabled); so does the 13th lowering (:data:`INIT_MAX_STEPS`). No response at all
  (:attr:`Response.NONE`: the partner is not regulated) or the end of the :data:`INIT_TIME_LIMIT_S` budget
  (:func:`init_timeout`) falls back to an unregulated transmitter at maximum power (:attr:`Phase.FIXED`).
* **Online regulation** (:func:`online_test`), every :data:`REPEAT_CYCLES` data cycles: a test at one level below
  (``ack1``) and at two levels below (``ack2``); negative at one level: up by one; positive at one and negative at
  two: hold; positive at both on :data:`DECREASE_AFTER` tests in a row: down by one (OPT-6).
* **MAU warning** (:func:`mau_after`, 1.6.3): on at the step MAX-1 -> MAX, off at the step MAX-1 -> MAX-2. In
  optical diagnostics mode (:func:`diagnostic_mau`) the warning belongs to the receiving interface: on when the test
  at the reserve fails, off when the test one level further passes.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from enum import Enum, IntEnum
from typing import Final

from supi3.checks import check_bool, check_instance, check_int, fail
from supi3.optical.length import LENGTH_MAX_CODE, Medium, check_bit_rate
from supi3.pinlevel import Pin
from supi3.regmap.registers import (
    OPTICAL_ENABLE_BIT,
    OPTICAL_MEDIUM_BIT,
    POWER_BRANCH_LSB,
    POWER_OUT_LSB,
)
from supi3.tables import CLOCK_HZ, LENGTH_TIMER_CLOCKS_PER_BIT

__all__ = [
    "BLOCK_INPUTS",
    "BLOCK_OUTPUTS",
    "DECREASE_AFTER",
    "INIT_MAX_STEPS",
    "INIT_ORDER",
    "INIT_STEP_BITS",
    "INIT_TIME_LIMIT_CLOCKS",
    "INIT_TIME_LIMIT_S",
    "LEVEL_STEP_DB",
    "MAX_LEVEL",
    "MIN_LEVEL",
    "REPEAT_CYCLES",
    "RESERVE_DB",
    "Interface",
    "OpticalMode",
    "OpticalStatus",
    "Phase",
    "Response",
    "Transmitter",
    "apply_test",
    "diagnostic_mau",
    "fo_lit",
    "init_response",
    "init_timeout",
    "initializing",
    "length_timer_enable_every",
    "mau_after",
    "online_test",
    "probe_power_db",
    "registers",
    "start",
]

MAX_LEVEL: Final = 15
"""Power levels 1..15 (1.6.1 "Initialization has 15 power levels", 1.6.2, Figure 1-10 "n (of 15)")."""
MIN_LEVEL: Final = 1
"""The lowest power level."""
INIT_MAX_STEPS: Final = 13
"""At most 13 regulation procedures (lowerings) in an initialization (1.6.1): from 15 down to 2."""
INIT_TIME_LIMIT_S: Final = 6e-3
"""An interface's initialization takes 6 ms at most (1.6.1); a transmitter not done by then falls back (OPT-5). Each
interface has its own budget, counted from the moment its initialization begins (:data:`INIT_ORDER`, OPT-56)."""
INIT_TIME_LIMIT_CLOCKS: Final = round(INIT_TIME_LIMIT_S * CLOCK_HZ)
""":data:`INIT_TIME_LIMIT_S` in chip clocks (192,000 at 32 MHz), counted from the end of the INTERBUS reset for the
first interface, from the end of the one before it for the others (OPT-56)."""
INIT_STEP_BITS: Final = 96
"""One initialization step (pattern out, response back) takes 96 bit periods (OPT-5): two directions of 14 steps
are 5.4 ms at 500 kbit/s, inside :data:`INIT_TIME_LIMIT_S`."""
RESERVE_DB: Final = 3.0
"""The system reserve: the first test is sent this far below the current power (1.6.2, Table 2-2 "3 dB")."""
LEVEL_STEP_DB: Final = 1.0
"""Optical power between two adjacent levels (OPT-4); the second test is one level below the first (1.6.2)."""
REPEAT_CYCLES: Final = 2
"""Online regulation tests once every two data cycles (1.6.2: the repeat rate is twice the cycle time)."""
DECREASE_AFTER: Final = 2
"""Online regulation lowers the power after this many tests in a row passed at both levels (OPT-6): rises follow
every failed test, falls every second passed one (Figure 1-12: "a power increase ... is faster than the power
reduction")."""


class Interface(IntEnum):
    """The three optical transmitters of a chip, in the order of the block's ports and MAUWH/MAUWR/MAUWS (1.6.3)."""

    IN = 0
    """Incoming interface: transmits the return line to the previous device (POWER_IN, read 10; FO1; MAUWH)."""
    OUT = 1
    """Outgoing interface: transmits the forward line to the next device (read 11 bits 3..0, read 8; FO2; MAUWR)."""
    BRANCH = 2
    """Branch of a bus terminal module (read 11 bits 7..4, read 9; FO3 on MFP8; MAUWS)."""


INIT_ORDER: Final[tuple[Interface, Interface, Interface]] = (Interface.IN, Interface.BRANCH, Interface.OUT)
"""The order in which a chip's transmitters initialize after the end of an INTERBUS reset (OPT-56): the incoming
interface first (the direction change of the path from the previous device, 1.6.1), then a bus terminal module's
branch, then the outgoing interface (OPT-54). Each has its own :data:`INIT_TIME_LIMIT_CLOCKS` budget, counted from
the moment the interfaces before it are done (regulated, fallen back or timed out), not one budget for the chip."""


class OpticalMode(IntEnum):
    """What RF[1..0] selects for the optical block (Table 2-2; OPT-2)."""

    OFF = 0
    """Copper (RF = 10 or 11), and the SUPI 3 LS: no regulation, registers 8 to 11 stay 0."""
    REGULATION = 1
    """RF = 00: fibre, automatic recognition, initialization and online regulation with the 3 dB reserve."""
    DIAGNOSTIC = 2
    """RF = 01: fibre, optical power diagnostics only (1.6.2): fixed maximum power, MAU warning on a falling reserve."""


class Response(IntEnum):
    """The partner's answer to one initialization step (1.6.1), as the block's 2-bit ``resp`` port carries it."""

    NONE = 0
    """No regulation response: the partner is not a regulated device."""
    DETECTED = 1
    """"Light off": regulation pattern detected."""
    NOT_DETECTED = 2
    """"Light on": regulation pattern not detected."""


class Phase(Enum):
    """Where a transmitter stands."""

    OFF = "off"
    """Not regulated: copper, interface not in use, or in reset."""
    INIT = "init"
    """Initializing: each step's response moves the level."""
    ONLINE = "online"
    """Initialized with a regulated partner: online regulation, enable status 1."""
    FIXED = "fixed"
    """Fallback (1.6.1): unregulated transmitter at maximum power, enable status 0."""
    DIAGNOSTIC = "diagnostic"
    """Optical diagnostics mode: maximum power, tests only watch the reserve."""


@dataclass(frozen=True)
class Transmitter:
    """One optical transmitter's regulation state.

    Attributes
    ----------
    phase:
        See :class:`Phase`.
    level:
        Power level, :data:`MIN_LEVEL` to :data:`MAX_LEVEL`.
    steps:
        Lowerings made in the initialization so far (0 to :data:`INIT_MAX_STEPS` - 1: the last one ends it).
    passes:
        Online tests passed at both levels in a row since the last change (0 to :data:`DECREASE_AFTER` - 1).
    mau:
        MAU warning (1.6.3).
    """

    phase: Phase = Phase.OFF
    level: int = MAX_LEVEL
    steps: int = 0
    passes: int = 0
    mau: bool = False

    def __post_init__(self) -> None:
        check_instance("phase", self.phase, Phase)
        check_int("level", self.level, MIN_LEVEL, MAX_LEVEL, "1.6.1: 15 power levels")
        check_int("steps", self.steps, 0, INIT_MAX_STEPS - 1, "1.6.1: the 13th regulation procedure ends it")
        check_int("passes", self.passes, 0, DECREASE_AFTER - 1, "OPT-6")
        check_bool("mau", self.mau)
        _check_reachable(self)

    @property
    def enable(self) -> bool:
        """Enable status of 3.4.12/3.4.13: initialization detected a regulated device."""
        return self.phase is Phase.ONLINE


_AT_MAX: Final = frozenset({Phase.OFF, Phase.FIXED, Phase.DIAGNOSTIC})
"""Phases that send at :data:`MAX_LEVEL` whatever happens: not regulated (1.6.1 fallback, 1.6.2 diagnostics)."""
_WARNS: Final = frozenset({Phase.ONLINE, Phase.DIAGNOSTIC})
"""Phases whose tests set a MAU warning (1.6.2, 1.6.3); a transmitter off, initializing or fixed has none."""


def _check_reachable(tx: Transmitter) -> None:
    """Refuse a state no history of :func:`start` and the transitions reaches (so a hand-made state cannot show,
    e.g., an FO LED or a power level for an interface that is off)."""
    phase = tx.phase.name
    if tx.steps and tx.phase is not Phase.INIT:
        raise fail("steps", f"0 in Phase.{phase} (1.6.1: lowerings are counted while initializing)", tx.steps)
    if tx.passes and tx.phase is not Phase.ONLINE:
        raise fail("passes", f"0 in Phase.{phase} (OPT-6: passes are counted by online regulation)", tx.passes)
    if tx.phase is Phase.INIT and tx.level != MAX_LEVEL - tx.steps:
        raise fail("level", f"{MAX_LEVEL - tx.steps} in Phase.INIT after {tx.steps} lowerings (1.6.1: from "
                   f"{MAX_LEVEL} down by one per step)", tx.level)
    if tx.phase in _AT_MAX and tx.level != MAX_LEVEL:
        raise fail("level", f"{MAX_LEVEL} in Phase.{phase} (1.6.1, 1.6.2: maximum power)", tx.level)
    if tx.mau and tx.phase not in _WARNS:
        raise fail("mau", f"False in Phase.{phase} (1.6.3: warnings come from online tests)", tx.mau)
    if tx.phase is Phase.ONLINE and tx.mau != (tx.level == MAX_LEVEL) and tx.level != MAX_LEVEL - 1:
        raise fail("mau", f"{tx.level == MAX_LEVEL} at level {tx.level} in Phase.ONLINE (1.6.3: on at the step MAX-1 "
                   "-> MAX, off at the step MAX-1 -> MAX-2)", tx.mau)


def _tx(tx: object) -> Transmitter:
    return check_instance("transmitter", tx, Transmitter)


def start(mode: OpticalMode, present: bool) -> Transmitter:
    """A transmitter at the end of an INTERBUS reset (1.6 "Behavior on a reset"; 1.6.1)."""
    check_instance("mode", mode, OpticalMode)
    if not check_bool("present", present) or mode is OpticalMode.OFF:
        return Transmitter()
    return Transmitter(Phase.INIT if mode is OpticalMode.REGULATION else Phase.DIAGNOSTIC)


def mau_after(mau: bool, old: int, new: int) -> bool:
    """The MAU warning after the level moved from ``old`` to ``new`` (1.6.3's hysteresis)."""
    check_bool("mau", mau)
    check_int("old", old, MIN_LEVEL, MAX_LEVEL)
    check_int("new", new, MIN_LEVEL, MAX_LEVEL)
    if old == MAX_LEVEL - 1 and new == MAX_LEVEL:
        return True
    if old == MAX_LEVEL - 1 and new == MAX_LEVEL - 2:
        return False
    return mau


def init_response(tx: Transmitter, response: Response) -> Transmitter:
    """One initialization step's response (1.6.1); a transmitter not initializing is returned unchanged."""
    tx = _tx(tx)
    check_instance("response", response, Response)
    if tx.phase is not Phase.INIT:
        return tx
    if response is Response.NONE:
        return Transmitter(Phase.FIXED)
    if response is Response.NOT_DETECTED:
        level = min(MAX_LEVEL, tx.level + 1)
        # Not detected at MAX itself: the reserve is not there even at full power (1.6.3).
        mau = tx.level == MAX_LEVEL or mau_after(False, tx.level, level)
        return Transmitter(Phase.ONLINE, level, mau=mau)
    level, steps = tx.level - 1, tx.steps + 1
    if steps == INIT_MAX_STEPS:
        return Transmitter(Phase.ONLINE, level)
    return Transmitter(Phase.INIT, level, steps)


def init_timeout(tx: Transmitter) -> Transmitter:
    """Its 6 ms budget ran out (1.6.1, OPT-5, OPT-56): a transmitter still initializing falls back to maximum power."""
    tx = _tx(tx)
    return Transmitter(Phase.FIXED) if tx.phase is Phase.INIT else tx


def initializing(transmitters: tuple[Transmitter, Transmitter, Transmitter]) -> Interface | None:
    """The interface whose initialization runs now and whose 6 ms budget counts (OPT-56): the first of
    :data:`INIT_ORDER` in :attr:`Phase.INIT`; ``None`` when none initializes (:attr:`OpticalStatus.initializing`).

    Raises
    ------
    ArgumentError
        ``transmitters`` is not a tuple of 3 :class:`Transmitter` (one per :class:`Interface`).
    """
    return OpticalStatus(transmitters).initializing


def online_test(tx: Transmitter, ack1: bool, ack2: bool) -> Transmitter:
    """One online regulation test (1.6.2): ``ack1`` at one level below, ``ack2`` at two levels below.

    Only :attr:`Phase.ONLINE` transmitters move; any other is returned unchanged (a diagnostics-mode test goes to
    :func:`diagnostic_mau`).
    """
    tx = _tx(tx)
    check_bool("ack1", ack1)
    check_bool("ack2", ack2)
    if tx.phase is not Phase.ONLINE:
        return tx
    if not ack1:
        level = min(MAX_LEVEL, tx.level + 1)
        mau = tx.mau or tx.level == MAX_LEVEL or mau_after(tx.mau, tx.level, level)
        return replace(tx, level=level, passes=0, mau=mau)
    if not ack2:
        return replace(tx, passes=0)
    if tx.passes + 1 < DECREASE_AFTER:
        return replace(tx, passes=tx.passes + 1)
    level = max(MIN_LEVEL, tx.level - 1)
    return replace(tx, level=level, passes=0, mau=mau_after(tx.mau, tx.level, level))


def diagnostic_mau(mau: bool, ack1: bool, ack2: bool) -> bool:
    """Optical diagnostics mode (1.6.2, OPT-7): the receiving interface's MAU warning after one test."""
    check_bool("mau", mau)
    check_bool("ack1", ack1)
    check_bool("ack2", ack2)
    if not ack1:
        return True
    return False if ack2 else mau


def apply_test(tx: Transmitter, ack1: bool, ack2: bool) -> Transmitter:
    """One online test of a transmitter, whatever the mode (1.6.2; OPT-22): :func:`online_test` for an
    :attr:`Phase.ONLINE` transmitter, :func:`diagnostic_mau` on the MAU warning of a :attr:`Phase.DIAGNOSTIC` one;
    any other transmitter is returned unchanged."""
    tx = _tx(tx)
    if tx.phase is Phase.DIAGNOSTIC:
        return replace(tx, mau=diagnostic_mau(tx.mau, ack1, ack2))
    return online_test(tx, ack1, ack2)


def probe_power_db(level: int, test: int) -> float:
    """Transmit power of test 1 or 2 relative to full power (level 15): level, reserve and one level more for
    test 2 (1.6.2; OPT-4). Test 0 is the normal power of the level."""
    check_int("level", level, MIN_LEVEL, MAX_LEVEL)
    check_int("test", test, 0, 2)
    power = -(MAX_LEVEL - level) * LEVEL_STEP_DB
    if test >= 1:
        power -= RESERVE_DB
    if test == 2:
        power -= LEVEL_STEP_DB
    return power


def fo_lit(tx: Transmitter, run: bool) -> bool:
    """The FO1/FO2/FO3 LED of a transmitter (Table 3-17, Table 2-8 FO3; OPT-8): in READY, lit when the interface
    is optical and its initialization did not find a regulated partner; in RUN, lit on a MAU warning."""
    tx = _tx(tx)
    if check_bool("run", run):
        return tx.mau
    return tx.phase is Phase.FIXED


@dataclass(frozen=True)
class OpticalStatus:
    """The chip's optical block: three transmitters (index :class:`Interface`) and the measured paths.

    ``length`` and ``medium`` hold the LENGTH code (0 to 63, :mod:`supi3.optical.length`) and medium of the outgoing
    interface and of the branch (index 0 and 1); only those two paths are measured (1.6.2, 3.4.12).
    """

    transmitters: tuple[Transmitter, Transmitter, Transmitter] = (Transmitter(), Transmitter(), Transmitter())
    length: tuple[int, int] = (0, 0)
    medium: tuple[Medium, Medium] = (Medium.POLYMER, Medium.POLYMER)

    def __post_init__(self) -> None:
        if not (isinstance(self.transmitters, tuple) and len(self.transmitters) == len(Interface)):
            raise fail("transmitters", "a tuple of 3 Transmitter", self.transmitters)
        for tx in self.transmitters:
            _tx(tx)
        for name, pair in (("length", self.length), ("medium", self.medium)):
            if not (isinstance(pair, tuple) and len(pair) == 2):
                raise fail(name, "a tuple of 2 (outgoing interface, branch)", pair)
        for code in self.length:
            check_int("length", code, 0, LENGTH_MAX_CODE, "LENGTH, 6 bits (RM-5)")
        for medium in self.medium:
            check_instance("medium", medium, Medium)

    def __getitem__(self, interface: Interface) -> Transmitter:
        return self.transmitters[check_instance("interface", interface, Interface)]

    @property
    def initializing(self) -> Interface | None:
        """The interface whose initialization runs now and whose 6 ms budget counts (OPT-56): the first of
        :data:`INIT_ORDER` in :attr:`Phase.INIT`; ``None`` when none initializes."""
        for interface in INIT_ORDER:
            if self.transmitters[interface].phase is Phase.INIT:
                return interface
        return None

    def with_transmitter(self, interface: Interface, tx: Transmitter) -> OpticalStatus:
        """This status with one transmitter replaced."""
        check_instance("interface", interface, Interface)
        txs = list(self.transmitters)
        txs[interface] = _tx(tx)
        return replace(self, transmitters=(txs[0], txs[1], txs[2]))

    def with_length(self, interface: Interface, code: int, medium: Medium) -> OpticalStatus:
        """This status with the measured path of the outgoing interface or the branch set."""
        if check_instance("interface", interface, Interface) is Interface.IN:
            raise fail("interface", "Interface.OUT or Interface.BRANCH (the incoming path is not measured, 1.6.2)",
                       interface)
        k = interface - 1
        length = list(self.length)
        media = list(self.medium)
        length[k] = check_int("code", code, 0, LENGTH_MAX_CODE, "LENGTH, 6 bits (RM-5)")
        media[k] = check_instance("medium", medium, Medium)
        return replace(self, length=(length[0], length[1]), medium=(media[0], media[1]))


def registers(status: OpticalStatus) -> tuple[int, int, int, int]:
    """Reads 8, 9, 10 and 11 (3.4.12, 3.4.13; layouts RM-5 and RM-6) from the optical block's status.

    The level of a transmitter that is off reads 0 (the interface is not in use, OPT-9).
    """
    check_instance("status", status, OpticalStatus)

    def level(i: Interface) -> int:
        tx = status[i]
        return 0 if tx.phase is Phase.OFF else tx.level

    def path(k: int, i: Interface) -> int:
        return (status.length[k] | int(status.medium[k]) << OPTICAL_MEDIUM_BIT
                | int(status[i].enable) << OPTICAL_ENABLE_BIT)

    read8 = path(0, Interface.OUT)
    read9 = path(1, Interface.BRANCH)
    read10 = level(Interface.IN) | int(status[Interface.IN].enable) << OPTICAL_ENABLE_BIT
    read11 = level(Interface.OUT) << POWER_OUT_LSB | level(Interface.BRANCH) << POWER_BRANCH_LSB
    return read8, read9, read10, read11


def length_timer_enable_every(bit_rate: int) -> int:
    """The length timer counts on every n-th chip clock: f = 16 x bit rate (F10) out of the 32 MHz clock."""
    return CLOCK_HZ // (LENGTH_TIMER_CLOCKS_PER_BIT * check_bit_rate(bit_rate))


_PER_INTERFACE: Final = len(Interface)

BLOCK_INPUTS: Final[tuple[Pin, ...]] = (
    Pin("ib_reset"), Pin("mode", 2), Pin("fast"), Pin("present", _PER_INTERFACE), Pin("medium", _PER_INTERFACE),
    Pin("resp_valid", _PER_INTERFACE), Pin("resp", 2 * _PER_INTERFACE), Pin("test_valid", _PER_INTERFACE),
    Pin("ack1", _PER_INTERFACE), Pin("ack2", _PER_INTERFACE), Pin("len_start", _PER_INTERFACE),
    Pin("len_stop", _PER_INTERFACE), Pin("run"),
)
"""The optical block's inputs, one bit per :class:`Interface` where a width is 3 (bit i = interface i):

``ib_reset`` the core's INTERBUS reset (the block restarts on its falling edge, :func:`start`); ``mode`` an
:class:`OpticalMode` (static, from RF[1..0]); ``fast`` 2 Mbit/s; ``present`` interfaces in use (static while out of
reset); ``medium`` the transceiver's medium (OPT-3); ``resp_valid``/``resp`` an initialization step's
:class:`Response` (2 bits per interface); ``test_valid``/``ack1``/``ack2`` an online test's result; ``len_start``
/``len_stop`` the length timer's start (first status telegram out) and stop (positive response in) for the outgoing
interface and the branch; ``run`` the master is in RUN (FO LEDs). Strobes are one clock wide; the line side (the
ring of fibre links, or a test) produces them."""

BLOCK_OUTPUTS: Final[tuple[Pin, ...]] = (
    Pin("optical_we", 4), Pin("optical", 32), Pin("mau", _PER_INTERFACE), Pin("fo", _PER_INTERFACE), Pin("hold"),
)
"""The optical block's outputs: ``optical`` reads 8..11 (byte k = read 8 + k, :func:`registers`) with
``optical_we`` bit k set in the clock a byte changes (the register file's ports, ``docs/upif.md``); ``mau``
MAUWH/MAUWR/MAUWS; ``fo`` FO1/FO2/FO3 (:func:`fo_lit`); ``hold`` the protocol core is held in reset (from the end of
the INTERBUS reset until no transmitter initializes any more, 1.6)."""

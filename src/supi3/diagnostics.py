"""The diagnostic outputs, as data and pure functions: DIAG_CONF, IB_DIAG, BA/RD/FO1/FO2 on DIAG1/DIAG2, RC, UL, and
the bus terminal module's LD, E, FO3 and ALARM.

Manual 3.6.1 (Tables 3-16 to 3-19), 2.4 (Tables 2-7, 2-8), 1.6.3 (MAU warnings) and Table 3-17 (the FO LEDs, by the
master's READY/RUN state, :func:`supi3.optical.regulation.fo_lit`). The decisions where the manual is silent are DG-1
to DG-8 of ``docs/assumptions/diagnostics.md``; each is one named constant or function here.

The model's outputs block (:mod:`supi3.model.blocks.outputs`), the transaction-level LED view
(:attr:`supi3.model.chip.Supi3.diagnostic_outputs`) and the RTL's outputs block (``supi3.rtl.core.OutputsRtl``, which
re-implements :func:`ib_diag_state` and :func:`diag_pins` in gates) all take their behaviour from here:

* **IB_DIAG** (Table 3-18): :func:`ib_diag_state` picks one :class:`IbDiag` from its causes in the order of
  :data:`IB_DIAG_PRIORITY` (DG-1); :func:`ib_diag_level` is the pin's level at a clock, from the free-running
  divider of M6 (:data:`supi3.pinout.IB_DIAG_DIVIDER_BITS`, 4 Hz: DG-2).
* **Line interrupt ahead** (the 4 Hz cause, DG-3): in the local bus modes (:func:`watches_line_interrupt`) the chip
  raises it when its incoming line falls silent for the 20 ms idle time-out (A13) while the bus is active; the
  master's reset pattern, the next cycle that ends at the chip, or a power-up clear it.
* **DIAG1/DIAG2** (Table 3-16): :func:`diag_pins` gives BA/RD with complete diagnostics (DIAG_CONF = 0), FO1/FO2 with
  limited diagnostics (DIAG_CONF = 1).
* **RD** ("Remote bus Disabled", Table 3-19, DG-5): lit while no following device is recognised on the outgoing
  interface (M5: the chip closes the ring itself, looping DO2 back onto DI1): :func:`remote_bus_disabled`.
* **RC** on /ResReg (Table 3-19, DG-4): the incoming line is heard; /ResReg is low while it is silent (from the idle
  time-out until the line is heard again) and for the reset pulses of Table 3-13 and RX-5.
* **Bus terminal modules** (Table 2-8, DG-6): LD on MFP14, E on MFP13, FO3 on MFP8 and ALARM on MFP15, whatever
  DIAG_CONF says (:data:`BUS_TERMINAL_PINS`, :func:`bus_terminal_mfp`).

What the chip's other blocks give the outputs block (the FO LEDs of the optical block and the bus terminal's LD, E
and ALARM) is one :class:`LedInputs` value (DG-6, DG-7).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum
from typing import Final

from supi3.checks import check_bool, check_instance, check_int, fail
from supi3.config import DeviceConfig, Interface
from supi3.optical.regulation import Interface as OpticalInterface
from supi3.optical.regulation import OpticalStatus, fo_lit
from supi3.pinout import IB_DIAG_DIVIDER_BITS
from supi3.tables import BUS_TERMINAL_MFP, DIAG_CONFIGURATIONS, LIMITED_DIAGNOSTICS

__all__ = [
    "BUS_TERMINAL_PINS",
    "IB_DIAG_PRIORITY",
    "LINE_INTERRUPT_INTERFACES",
    "DiagnosticOutputs",
    "IbDiag",
    "LedInputs",
    "bus_terminal_mfp",
    "diag_pins",
    "diagnostic_outputs",
    "fo_leds",
    "ib_diag_level",
    "ib_diag_state",
    "is_complete",
    "remote_bus_disabled",
    "watches_line_interrupt",
]


class IbDiag(Enum):
    """What the IB_DIAG LED shows (Table 3-18); the value is the divider of M6 that flashes it (None: steady)."""

    STEADY = None
    """Supply OK, module function error-free, bus active."""
    SLOW = "slow"
    """Flashing slowly (0.5 Hz): supply OK, bus not active."""
    FAST = "fast"
    """Flashing quickly (2 Hz): supply OK, peripheral fault (/StatErr, 3.6.2)."""
    VERY_FAST = "very_fast"
    """Flashing very quickly (4 Hz): supply OK, line interrupt ahead on the local bus (DG-3)."""

    @property
    def divider_bits(self) -> int | None:
        """The flashing period is ``2**divider_bits`` clocks (M6, DG-2); None for a steady light."""
        return None if self.value is None else IB_DIAG_DIVIDER_BITS[self.value]

    @property
    def hz(self) -> float | None:
        """The flash frequency Table 3-18 asks for (None: steady)."""
        return _TABLE_HZ[self]


_TABLE_HZ: Final[dict[IbDiag, float | None]] = dict(
    zip((IbDiag.STEADY, IbDiag.SLOW, IbDiag.FAST, IbDiag.VERY_FAST),
        (hz for _, hz, _ in LIMITED_DIAGNOSTICS[1:]), strict=True)
)  # fmt: skip

IB_DIAG_PRIORITY: Final[tuple[IbDiag, ...]] = (IbDiag.VERY_FAST, IbDiag.FAST, IbDiag.SLOW, IbDiag.STEADY)
"""DG-1: with several causes at once IB_DIAG shows the first of these: a line interrupt ahead over a peripheral fault
over "bus not active" over the steady light (the more local and the more urgent cause first)."""

LINE_INTERRUPT_INTERFACES: Final = frozenset({Interface.LB_MR, Interface.LBD_MR, Interface.LBD_OR})
"""DG-3: the modes whose incoming line is a local bus (Tables 2-4, 2-5); only they raise the 4 Hz cause."""

BUS_TERMINAL_PINS: Final[dict[str, int]] = {
    name: next(f.pin for f in BUS_TERMINAL_MFP if f.signal == signal)
    for name, signal in (("alarm", "ALARM"), ("ld", "LBDA"), ("e", "ERROR"), ("fo3", "FO3"))
}
"""The MFP of each bus terminal module LED output (Table 2-8): ALARM 15, LD (LBDA) 14, E (ERROR) 13, FO3 8."""


def ib_diag_state(line_interrupt: bool, peripheral_fault: bool, bus_active: bool) -> IbDiag:
    """IB_DIAG from its causes (Table 3-18), the first of :data:`IB_DIAG_PRIORITY` that holds (DG-1)."""
    causes = {
        IbDiag.VERY_FAST: check_bool("line_interrupt", line_interrupt),
        IbDiag.FAST: check_bool("peripheral_fault", peripheral_fault),
        IbDiag.SLOW: not check_bool("bus_active", bus_active),
        IbDiag.STEADY: True,
    }
    return next(state for state in IB_DIAG_PRIORITY if causes[state])


def ib_diag_level(state: IbDiag, clock: int) -> int:
    """The IB_DIAG pin at chip clock ``clock``: 1 (lit) for a steady light, else off in the second half of each
    period of the free-running divider (M6: the level is the inverted top bit of the divider's count)."""
    bits = check_instance("state", state, IbDiag).divider_bits
    c = check_int("clock", clock, 0, limit="32 MHz clock periods since power-up")
    return 1 if bits is None else 1 - ((c >> (bits - 1)) & 1)


def is_complete(config: DeviceConfig) -> bool:
    """DIAG_CONF selects complete diagnostics (Table 3-16: DIAG1 = BA, DIAG2 = RD); the SUPI 3 LS has no DIAG_CONF."""
    diag = check_instance("config", config, DeviceConfig).diagnostics
    return diag is not None and diag.diag_conf == DIAG_CONFIGURATIONS[0].diag_conf


def watches_line_interrupt(config: DeviceConfig) -> bool:
    """The chip raises the 4 Hz "line interrupt ahead on the local bus" cause in this mode (DG-3)."""
    return check_instance("config", config, DeviceConfig).interface in LINE_INTERRUPT_INTERFACES


def remote_bus_disabled(following: bool) -> bool:
    """RD (Table 3-19, DG-5): the outgoing interface is switched off, i.e. no following device is recognised on it
    (``following``: M5's recognition, RBST_EXT with RF = 10, else the first high level seen on DI2)."""
    return not check_bool("following", following)


def diag_pins(complete: bool, ba: bool, rd: bool, fo1: bool, fo2: bool) -> tuple[int, int]:
    """DIAG1 and DIAG2 (Table 3-16): BA and RD with complete diagnostics, else FO1 and FO2 (Table 3-17). Every
    argument is checked, the ones not shown too."""
    levels = {"ba": ba, "rd": rd, "fo1": fo1, "fo2": fo2}
    shown = ("ba", "rd") if check_bool("complete", complete) else ("fo1", "fo2")
    checked = {name: check_bool(name, value) for name, value in levels.items()}
    return int(checked[shown[0]]), int(checked[shown[1]])


def fo_leds(status: OpticalStatus, run: bool) -> tuple[bool, bool, bool]:
    """FO1, FO2, FO3 (Table 3-17, Table 2-8) of the optical block's ``status``: :func:`~supi3.optical.regulation.
    fo_lit` of the incoming, outgoing and branch transmitters, ``run`` the master in RUN (DG-7: the bus active)."""
    check_instance("status", status, OpticalStatus)
    check_bool("run", run)
    fo1, fo2, fo3 = (fo_lit(status[i], run) for i in OpticalInterface)
    return fo1, fo2, fo3


def _check_leds(leds: LedInputs | DiagnosticOutputs, names: tuple[str, ...]) -> None:
    """``leds.fo`` a tuple of 3 bool (FO1, FO2, FO3) and each attribute of ``names`` a bool, else the named error."""
    if not (isinstance(leds.fo, tuple) and len(leds.fo) == len(OpticalInterface)):
        raise fail("fo", "a tuple of 3 bool (FO1, FO2, FO3)", leds.fo)
    for name, value in (*zip(("fo1", "fo2", "fo3"), leds.fo, strict=True), *((n, getattr(leds, n)) for n in names)):
        check_bool(name, value)


@dataclass(frozen=True)
class LedInputs:
    """What the chip's other blocks give the outputs block: 0 until those blocks drive them (DG-6, DG-7).

    Attributes
    ----------
    fo:
        FO1, FO2, FO3 of the optical block (its ``fo`` port, :func:`fo_leds`).
    ld:
        Bus terminal module: the branch is switched off (LD, "Local bus Disabled", Table 2-8).
    e:
        Bus terminal module: error in the connected branch (E, Table 3-19).
    alarm:
        Bus terminal module: the alarm output the master sets (ALARM, Table 2-8).
    """

    fo: tuple[bool, bool, bool] = (False, False, False)
    ld: bool = False
    e: bool = False
    alarm: bool = False

    def __post_init__(self) -> None:
        _check_leds(self, ("ld", "e", "alarm"))


@dataclass(frozen=True)
class DiagnosticOutputs:
    """Every diagnostic LED of a chip at one moment (Tables 3-16 to 3-19, 2-8), True = lit.

    ``ld``, ``e``, ``alarm`` and ``fo[2]`` (FO3) are False on a chip that is no bus terminal module (Table 2-8).
    """

    complete: bool
    """DIAG_CONF = 0: DIAG1/DIAG2 show BA/RD, else FO1/FO2 (Table 3-16)."""
    ul: bool
    """UL on /ResU: the supply is good (the chip does not hold /ResU low, 1.7.2)."""
    rc: bool
    """RC on /ResReg: remote bus check, the incoming line is heard (DG-4)."""
    ba: bool
    """BA: bus active (a valid data cycle latched since the last reset)."""
    rd: bool
    """RD: the outgoing remote bus is switched off: no following device recognised (DG-5)."""
    ld: bool
    """LD on MFP14: the branch is switched off (bus terminal module)."""
    e: bool
    """E on MFP13: error in the connected branch (bus terminal module)."""
    alarm: bool
    """ALARM on MFP15 (bus terminal module)."""
    fo: tuple[bool, bool, bool]
    """FO1, FO2, FO3 (Table 3-17)."""
    ib_diag: IbDiag
    """The IB_DIAG pattern (Table 3-18)."""

    def __post_init__(self) -> None:
        _check_leds(self, ("complete", "ul", "rc", "ba", "rd", "ld", "e", "alarm"))
        check_instance("ib_diag", self.ib_diag, IbDiag, "an IbDiag (Table 3-18)")

    @property
    def diag1(self) -> int:
        """The DIAG1 pin (Table 3-16)."""
        return diag_pins(self.complete, self.ba, self.rd, self.fo[0], self.fo[1])[0]

    @property
    def diag2(self) -> int:
        """The DIAG2 pin (Table 3-16)."""
        return diag_pins(self.complete, self.ba, self.rd, self.fo[0], self.fo[1])[1]

    @property
    def mfp(self) -> int:
        """The bus terminal module's LED outputs on MFP[15..0] (Table 2-8; 0 on other chips)."""
        return bus_terminal_mfp(True, self.alarm, self.ld, self.e, self.fo[2])


def bus_terminal_mfp(bus_terminal: bool, alarm: bool, ld: bool, e: bool, fo3: bool) -> int:
    """ALARM, LD, E and FO3 at their MFPs (Table 2-8) on a bus terminal module, whatever DIAG_CONF (DG-6); else 0.
    Every level is checked, on other chips too."""
    levels = {"alarm": alarm, "ld": ld, "e": e, "fo3": fo3}
    mfp = sum(int(check_bool(name, levels[name])) << pin for name, pin in BUS_TERMINAL_PINS.items())
    return mfp if check_bool("bus_terminal", bus_terminal) else 0


def diagnostic_outputs(config: DeviceConfig, *, supply_ok: bool, line_heard: bool, bus_active: bool,
                       peripheral_fault: bool, line_interrupt: bool, following: bool,
                       leds: LedInputs) -> DiagnosticOutputs:  # fmt: skip
    """Every diagnostic LED of a chip of ``config`` from the chip's state (Tables 3-16 to 3-19, 2-8).

    ``supply_ok``: /ResU is not held low (UL); ``line_heard``: the incoming line is not silent (RC, DG-4);
    ``bus_active``, ``peripheral_fault``: the chip's BA and PF; ``line_interrupt``: the 4 Hz cause (DG-3);
    ``following``: a following device is recognised on the outgoing interface (M5; RD is its negation, DG-5);
    ``leds``: what the optical block and the bus terminal logic give (:class:`LedInputs`).
    """
    check_instance("leds", leds, LedInputs)
    bk = check_instance("config", config, DeviceConfig).interface.is_bus_terminal
    return DiagnosticOutputs(
        complete=is_complete(config),
        ul=check_bool("supply_ok", supply_ok),
        rc=check_bool("line_heard", line_heard),
        ba=check_bool("bus_active", bus_active),
        rd=remote_bus_disabled(following),
        ld=bk and leds.ld,
        e=bk and leds.e,
        alarm=bk and leds.alarm,
        fo=(leds.fo[0], leds.fo[1], bk and leds.fo[2]),
        ib_diag=ib_diag_state(line_interrupt, peripheral_fault, bus_active),
    )

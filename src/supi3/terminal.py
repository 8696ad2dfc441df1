"""The bus terminal module (BK) function, as data and pure functions: branch state, CONF, LBST, branch control,
extended BK function, counter telegram count, status byte, LEDs (manual 2.4, Tables 2-7, 2-8, 2-9, "Extended bus
terminal module functions"; 2.2.2; Table 3-19).

A chip strapped to a BK mode (C[4..0] = 00000..00100, Table 2-7) connects a branch to the remote bus. What the BK
decides about its branch is one :class:`Terminal` value; every change is one of the pure transitions below, so the
transaction level (:class:`supi3.model.bus_terminal.BusTerminal`), the pin-level block
(``supi3.model.blocks.terminal``) and the RTL (``supi3.rtl.terminal``, which re-implements them in gates) have one
behaviour. Decisions where the manual is silent are BK-1.. of ``docs/assumptions/bus-terminal.md``.

* **CONF** (MFP12, Table 2-8; :func:`conf_level`): a positive edge raises a reconfiguration request, kept until the
  master acknowledges it (BK-8). The level at power-up is no edge (:func:`power_up`).
* **LBST** (MFP11) with RF[1..0] (Table 2-9, BK-2): :func:`branch_present`; with the state, :func:`enabled`, and
  :func:`live` (the interface sends, so that a following chip can answer: automatic recognition, BK-37, BK-42).
* **Branch control** (:func:`command`): the master's command word switches the branch off, on, or on with the
  extended function (BK-4); its quit bit acknowledges the reports (0714h, BK-8); it sets the ALARM output (BK-12).
* **Extended BK function** (:func:`silence`): a branch whose return line carried none of the master's telegrams for
  :data:`BRANCH_SILENCE_S` while :func:`watching` is closed by the BK itself, with a "closed" report (BK-3). The
  silence is measured by the implementations (seconds at transaction level, :data:`BRANCH_SILENCE_CLOCKS` clocks at
  pin level); the master's telegrams and a branch switched on restart it, counter telegrams do not.
* **Counter telegram** (:func:`received`): the BK keeps the last count received on its branch return line, 0 when
  the master's own telegrams come back (BK-6) or the line falls silent, a break at the BK's own input (BK-58).
* **INTERBUS reset** (:func:`reset`, BK-9).
* Outputs: :attr:`Terminal.status` (the branch status byte, BK-5), :attr:`Terminal.attention`, the LEDs
  :attr:`Terminal.ld` and :attr:`Terminal.e` (BK-11) and :attr:`Terminal.alarm` (BK-12).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from enum import IntEnum
from typing import Final

from supi3 import tables
from supi3.checks import check_bits, check_bool, check_choice, check_instance, check_int
from supi3.config import Interface
from supi3.interbus import wire
from supi3.interbus.wire import BranchControl
from supi3.pinlevel import Pin
from supi3.tables import CLOCK_HZ

__all__ = [
    "BLOCK_INPUTS",
    "BLOCK_OUTPUTS",
    "BRANCH_DRAIN_BITS",
    "BRANCH_SILENCE_CLOCKS",
    "BRANCH_SILENCE_S",
    "CONF_PIN",
    "DI3_PIN",
    "DO3_PIN",
    "LBST_PIN",
    "RF_CODES",
    "TERMINAL_INTERFACES",
    "LineSource",
    "Terminal",
    "TerminalMode",
    "branch_present",
    "command",
    "conf_level",
    "enabled",
    "live",
    "power_up",
    "received",
    "reset",
    "restarts_silence",
    "rf_code",
    "rf_of",
    "silence",
    "silence_limit",
    "watching",
]

BRANCH_SILENCE_S: Final = 0.010
"""BK-3: the extended BK function closes a branch whose return line was silent this long: half the 20 ms after which
a device takes silence for a reset (A13), so the remote bus behind the BK is closed again before it resets."""
BRANCH_SILENCE_CLOCKS: Final = round(BRANCH_SILENCE_S * CLOCK_HZ)
""":data:`BRANCH_SILENCE_S` in chip clocks (320,000 at 32 MHz): the pin-level silence timer's limit."""
BRANCH_DRAIN_BITS: Final = wire.STATUS_TELEGRAM_BITS
"""BK-47: a BK leaving its branch's return line (DO2 no longer repeating DI3) waits until DI3 has been between
telegrams at the idle level for this many bit periods (a status telegram's length: the master fills every gap with
status telegrams, so the branch has drained what it held)."""


class LineSource(IntEnum):
    """What a BK's DO2 carries (BK-47): the transmitter's line, the synchronised DI3 (the branch in the data path), or
    the idle level while it switches between the two."""

    SENT = 0
    DI3 = 1
    IDLE = 2


def silence_limit(time_limit: object, name: str = "time_limit") -> int:
    """The silence limit ``time_limit`` (the parameter ``name``) in clocks, checked: 1 up to
    :data:`BRANCH_SILENCE_CLOCKS` (BK-3; shorter only so that a test reaches the closure quickly), at both
    fidelities."""
    return check_int(name, time_limit, 1, BRANCH_SILENCE_CLOCKS,
                     "the 10 ms of BK-3 in clocks; shorter only to test the closure quickly")  # fmt: skip

CONF_PIN: Final = next(p.pin for p in tables.BUS_TERMINAL_MFP if p.signal == "CONF")
"""MFP12 (Table 2-8)."""
LBST_PIN: Final = next(p.pin for p in tables.BUS_TERMINAL_MFP if p.signal == "LBST")
"""MFP11 (Table 2-8)."""
DI3_PIN: Final = next(p.pin for p in tables.BUS_TERMINAL_MFP if p.signal == "DI3")
"""MFP10 (Table 2-8): the branch data input, the return line from the branch."""
DO3_PIN: Final = next(p.pin for p in tables.BUS_TERMINAL_MFP if p.signal == "DO3_CU")
"""MFP9 (Table 2-8): the branch data output (copper), the forward line into the branch."""

TERMINAL_INTERFACES: Final = ("BK-RB", "BK-LB", "BK-LBD")
"""The interfaces of Table 2-7: remote bus branch, local bus branch, local bus branch with device-oriented
diagnostics."""

_CHIP_INTERFACES: Final = tuple(interface.value for interface in Interface)
"""Every chip interface name (:class:`supi3.config.Interface`): what :meth:`TerminalMode.of` takes."""
RF_CODES: Final = ("00", "01", "10", "11")
"""RF[1..0] (Table 2-2) by the value of the block's 2-bit ``rf`` port."""


class TerminalMode(IntEnum):
    """The block's ``mode`` port: which BK interface the straps select (Table 2-7), or none."""

    NONE = 0
    """Not a bus terminal module: the block stays in its power-up state and its outputs are 0."""
    RB = 1
    """BK-RB: remote bus branch."""
    LB = 2
    """BK-LB: local bus branch."""
    LBD = 3
    """BK-LBD: local bus branch with device-oriented diagnostics."""

    @classmethod
    def of(cls, interface: str | None) -> TerminalMode:
        """The mode of a chip interface (``"BK-RB"``, ``"BK-LB"``, ``"BK-LBD"``; the other interfaces of
        :class:`supi3.config.Interface`, and ``None``, are :attr:`NONE`; a name that is no chip interface is refused
        by name)."""
        if interface is not None:
            check_instance("interface", interface, str, "a chip interface name (a str) or None")
            check_choice("interface", interface, _CHIP_INTERFACES, "supi3.config.Interface")
        if interface is None or interface not in TERMINAL_INTERFACES:
            return cls.NONE
        return cls(TERMINAL_INTERFACES.index(interface) + 1)


def rf_code(rf: str | None) -> int:
    """The ``rf`` port's value for RF[1..0] = ``rf``; ``None`` (no RF pins, the SUPI 3 LS) counts as ``"11"``."""
    return 3 if rf is None else RF_CODES.index(check_choice("rf", rf, RF_CODES))


def branch_present(rf: str | None, lbst: bool, connected: bool) -> bool:
    """Whether a BK's branch is present, from the RF straps and LBST (Table 2-9, BK-2).

    RF = 10: LBST alone (an external connector signal, as on the IBS SUPI 3). RF = 11 (copper, automatic
    recognition): a device answers on the branch (``connected``) and LBST = 1 (LBST = 0 switches the branch
    interface off). RF = 00 or 01 (fibre, automatic recognition): a device answers, or LBST = 1 switches it on.
    ``rf`` ``None`` (no RF pins) counts as copper with automatic recognition.
    """
    rf = RF_CODES[rf_code(rf)]
    lbst = check_bool("lbst", lbst)
    connected = check_bool("connected", connected)
    if rf == "10":
        return lbst
    if rf == "11":
        return connected and lbst
    return connected or lbst


@dataclass(frozen=True)
class Terminal:
    """A BK's branch state (manual 2.4; docs/assumptions/bus-terminal.md).

    Attributes
    ----------
    conf:
        The CONF (MFP12) level last seen, for its edges.
    switched_on:
        The master's last branch control: on (the default after power-up and reset) or off (BK-4).
    extended:
        The extended BK function is active (the master activated it, BK-4).
    closed:
        The BK closed its branch itself (extended function), until the master switches the branch on again (BK-3).
    closed_report:
        The BK closed its branch and the master has not acknowledged it yet (status bit 6, BK-5).
    conf_request:
        A reconfiguration request (CONF edge) waits for the master's acknowledgement (BK-8).
    count:
        The count of the last counter telegram received on the branch return line, 0 if none (BK-6).
    alarm:
        The ALARM output (MFP15) the master set (BK-12).
    """

    conf: bool = False
    switched_on: bool = True
    extended: bool = False
    closed: bool = False
    closed_report: bool = False
    conf_request: bool = False
    count: int = 0
    alarm: bool = False

    def __post_init__(self) -> None:
        for name in ("conf", "switched_on", "extended", "closed", "closed_report", "conf_request", "alarm"):
            check_bool(name, getattr(self, name))
        check_int("count", self.count, 0, wire.COUNTER_MAX, "BK-6: a count is 6 bits")

    @property
    def status(self) -> int:
        """The branch status byte (BK-5, :func:`supi3.interbus.wire.bk_status`)."""
        return wire.bk_status(self.conf_request, self.closed_report, self.count)

    @property
    def attention(self) -> bool:
        """A report waits for the master's acknowledgement: the BK holds ATTN (BK-5, BK-8)."""
        return self.conf_request or self.closed_report

    @property
    def ld(self) -> bool:
        """LD (MFP14, "local bus disabled"): the master switched the branch off or the BK closed it (BK-11)."""
        return self.closed or not self.switched_on

    @property
    def e(self) -> bool:
        """E (MFP13, "error in connected branch"): the BK closed its branch or its count reports a break (BK-11)."""
        return self.closed or self.count > 0


def _terminal(state: object) -> Terminal:
    return check_instance("state", state, Terminal)


def power_up(conf: bool) -> Terminal:
    """The state after power-up with CONF at ``conf``: the level is taken as it is, no edge (nothing waits)."""
    return Terminal(conf=check_bool("conf", conf))


def conf_level(state: Terminal, conf: bool) -> Terminal:
    """CONF is at ``conf``: a positive edge raises a reconfiguration request (2.4, BK-8); it stays until
    acknowledged, through INTERBUS resets (BK-9)."""
    state = _terminal(state)
    if check_bool("conf", conf) == state.conf:
        return state
    return replace(state, conf=conf, conf_request=state.conf_request or conf)


def command(state: Terminal, branch: BranchControl, acknowledge: bool, alarm: bool | None = None) -> Terminal:
    """A latched command word: the branch control (BK-4), with ``acknowledge`` (0714h, the quit bit) the end of a
    reconfiguration request and of the closed report (BK-8), and the ALARM output unless ``alarm`` is ``None``
    (BK-12). Switching the branch on (with or without the extended function) reopens a branch the BK closed."""
    state = _terminal(state)
    check_instance("branch", branch, BranchControl)
    acknowledge = check_bool("acknowledge", acknowledge)
    if alarm is not None:
        state = replace(state, alarm=check_bool("alarm", alarm))
    if branch is BranchControl.OFF:
        state = replace(state, switched_on=False)
    elif restarts_silence(branch):
        state = replace(state, switched_on=True, closed=False, extended=branch is BranchControl.ON_EXTENDED)
    if acknowledge:
        state = replace(state, conf_request=False, closed_report=False)
    return state


def restarts_silence(branch: BranchControl) -> bool:
    """Whether a branch control switches the branch on, which restarts the measured silence (BK-3)."""
    return check_instance("branch", branch, BranchControl) in (BranchControl.ON, BranchControl.ON_EXTENDED)


def watching(state: Terminal) -> bool:
    """The extended function watches the return line: active, the branch switched on and not closed (BK-3)."""
    state = _terminal(state)
    return state.extended and state.switched_on and not state.closed


def silence(state: Terminal) -> Terminal:
    """The return line was silent for :data:`BRANCH_SILENCE_S`: a :func:`watching` BK closes its branch and reports
    it (BK-3); otherwise nothing changes."""
    if not watching(state):
        return state
    return replace(state, closed=True, closed_report=True)


def received(state: Terminal, count: int) -> Terminal:
    """The branch return line brought a counter telegram with ``count`` (1..63), or (0) the master's own telegrams
    or no counter telegram: the BK keeps it for its status byte and the E LED (BK-6, BK-11)."""
    state = _terminal(state)
    count = check_int("count", count, 0, wire.COUNTER_MAX, "BK-6: a count is 6 bits, 0 for none")
    return state if count == state.count else replace(state, count=count)


def reset(state: Terminal) -> Terminal:
    """INTERBUS reset (BK-9): the branch switched on again (also one the BK closed, whose report goes with it), the
    extended function and the ALARM output off, the count forgotten; a waiting reconfiguration request stays."""
    state = _terminal(state)
    return Terminal(conf=state.conf, conf_request=state.conf_request)


def enabled(state: Terminal, rf: str | None, lbst: bool, connected: bool) -> bool:
    """The branch is in the data path: present (Table 2-9, :func:`branch_present`), switched on by the master, not
    closed by the BK."""
    state = _terminal(state)
    return branch_present(rf, lbst, connected) and state.switched_on and not state.closed


def live(state: Terminal, rf: str | None, lbst: bool) -> bool:
    """The branch interface sends (DO3 carries the BK's forward stream, BK-42): the branch would be in the data path
    if a device answered (:func:`enabled` with ``connected``), so that a following protocol chip can answer before it
    is recognised (2.1.1, BK-37). False with RF = 10 and LBST = 0 (no recognition, nothing follows), with RF = 11 and
    LBST = 0 (the interface switched off, Table 2-9), and while the master has the branch off or the BK closed it."""
    return enabled(state, rf, lbst, True)


BLOCK_INPUTS: Final[tuple[Pin, ...]] = (
    Pin("ib_reset"), Pin("mode", 2), Pin("rf", 2), Pin("conf"), Pin("lbst"), Pin("connected"), Pin("cmd_valid"),
    Pin("branch", 2), Pin("ack"), Pin("alarm_set"), Pin("alarm_on"), Pin("ret_valid"), Pin("cnt_valid"),
    Pin("count", 6), Pin("frame_end"),
)  # fmt: skip
"""The bus terminal block's inputs:

``ib_reset`` the core's INTERBUS reset (:func:`reset` while high); ``mode`` a :class:`TerminalMode` (static, from
C[4..0]); ``rf`` RF[1..0] (static, :data:`RF_CODES`; 3 on a chip without RF pins); ``conf`` and ``lbst`` the levels of
MFP12 and MFP11 after the input synchroniser; ``connected`` a device answers on the branch (automatic recognition, Table
2-9; in the chip: the first start level on DI3, BK-37); ``cmd_valid`` a latched ID cycle's command word, whose fields
are ``branch`` (a :class:`~supi3.interbus.wire.BranchControl`, bits 7..6), ``ack`` (the quit bit, 0714h), ``alarm_set``
and ``alarm_on`` (bits 9 and 10 without a processor command, BK-12); ``ret_valid`` one of the master's telegrams (frame
or status telegram) came back on the branch return line; ``cnt_valid``/``count`` a counter telegram came back there with
that count (BK-6); ``frame_end`` the chip's frame engine completes a frame's check sequence at this edge (the only edges
at which the silence can close the branch, BK-50). Strobes are one clock wide."""

BLOCK_OUTPUTS: Final[tuple[Pin, ...]] = (
    Pin("enabled"), Pin("live"), Pin("status", 8), Pin("attention"), Pin("ld"), Pin("e"), Pin("alarm"), Pin("closed"),
)  # fmt: skip
"""The bus terminal block's outputs: ``enabled`` the branch is in the data path (:func:`enabled`); ``live`` the
branch interface sends (:func:`live`: DO3 carries the forward stream, so a following chip can answer); ``status`` the
branch status byte (BK-5); ``attention`` a report waits (the BK holds ATTN); ``ld``, ``e``, ``alarm`` the LEDs and
the ALARM output of Table 2-8 (MFP14, MFP13, MFP15; BK-11, BK-12); ``closed`` the BK closed its branch itself. All 0
when ``mode`` is :attr:`TerminalMode.NONE`."""


def rf_of(code: int) -> str:
    """RF[1..0] of the ``rf`` port's value (inverse of :func:`rf_code`)."""
    return RF_CODES[check_bits("rf", code, 2)]

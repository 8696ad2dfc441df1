"""The bus terminal module (BK) function of the SUPI 3 OPC, at transaction level (manual 2.4, Tables 2-7..2-9).

A chip strapped to a BK mode (C[4..0] = 00000..00100, Table 2-7) connects a branch (remote bus or local bus) to the
remote bus. :class:`BusTerminal` holds what the BK decides about its branch; :class:`supi3.model.chip.Supi3` owns
one in the BK modes and the transaction-level ring (:class:`supi3.interbus.ring.Ring`) asks it whether the branch
is in the data path. Decisions where the manual is silent are BK-1.. in docs/assumptions/bus-terminal.md.

* **CONF** (MFP12, Table 2-8): a positive edge is a reconfiguration request; the BK keeps it, asks for the master's
  attention and clears it when the master acknowledges it (Control_Device_Function 0714h, BK-8).
* **LBST** (MFP11) decides with the RF straps whether a branch is present (Table 2-9, BK-2): :func:`branch_present`.
* **Branch control**: the master switches the branch off and on in the BK's command word (BK-4); an INTERBUS reset
  switches it on again and the extended function off (BK-9).
* **Extended BK function** (2.4, activated by the master): the BK watches its branch return line; silent (no frame
  or status telegram of the master, BK-3) for ``BRANCH_SILENCE_S``, the branch is closed by the BK itself.
* **Device-oriented local-bus diagnostics** (2.2.2): the BK keeps the count of the last counter telegram received on
  the branch return line (BK-6), sent with the CONF and closed flags in its branch status byte (BK-5).
"""

from __future__ import annotations

from typing import Final

from supi3 import tables
from supi3.checks import check_bits, check_bool, check_choice, check_instance, check_real
from supi3.interbus import wire
from supi3.interbus.wire import BranchControl

BRANCH_SILENCE_S: Final = 0.010
"""BK-3: the extended BK function closes a branch whose return line was silent this long: half the 20 ms after which
a device takes silence for a reset (A13), so the remote bus behind the BK is closed again before it resets."""

CONF_PIN: Final = next(p.pin for p in tables.BUS_TERMINAL_MFP if p.signal == "CONF")
LBST_PIN: Final = next(p.pin for p in tables.BUS_TERMINAL_MFP if p.signal == "LBST")

TERMINAL_INTERFACES: Final = ("BK-RB", "BK-LB", "BK-LBD")
"""The interfaces of Table 2-7: remote bus branch, local bus branch, local bus branch with device-oriented
diagnostics."""


def branch_present(rf: str | None, lbst: bool, connected: bool) -> bool:
    """Whether a BK's branch is present, from the RF straps and LBST (Table 2-9, BK-2).

    RF = 10: LBST alone (an external connector signal, as on the IBS SUPI 3). RF = 11 (copper, automatic
    recognition): a device answers on the branch (``connected``) and LBST = 1 (LBST = 0 switches the branch
    interface off). RF = 00 or 01 (fibre, automatic recognition): a device answers, or LBST = 1 switches it on.
    ``rf`` ``None`` (no RF pins) counts as copper with automatic recognition.
    """
    rf = "11" if rf is None else check_choice("rf", rf, ("00", "01", "10", "11"))
    lbst = check_bool("lbst", lbst)
    connected = check_bool("connected", connected)
    if rf == "10":
        return lbst
    if rf == "11":
        return connected and lbst
    return connected or lbst


class BusTerminal:
    """A BK's branch state (manual 2.4; docs/assumptions/bus-terminal.md).

    Parameters
    ----------
    interface:
        ``"BK-RB"``, ``"BK-LB"`` or ``"BK-LBD"`` (Table 2-7).
    rf:
        The RF[1..0] straps (Table 2-2), ``None`` without RF pins.

    Attributes
    ----------
    switched_on:
        The master's last branch control: on (the default after power-up and reset) or off.
    extended:
        The extended BK function is active (the master activated it).
    closed:
        The BK closed its branch itself (extended function), until the master switches the branch on again.
    closed_report:
        The BK closed its branch and the master has not acknowledged it yet (status bit 6, BK-5).
    conf_request:
        A reconfiguration request (CONF edge) waits for the master's acknowledgement.
    alarm:
        The ALARM output (MFP15) the master set (BK-12); off after an INTERBUS reset.
    count:
        The count of the last counter telegram received on the branch return line, 0 if none.
    closures:
        How often the BK closed its branch itself.
    """

    def __init__(self, interface: str, rf: str | None) -> None:
        self.interface = check_choice("interface", interface, TERMINAL_INTERFACES)
        self.rf = rf
        self.lbst = False
        self.conf = False
        self.switched_on = True
        self.extended = False
        self.closed = False
        self.closed_report = False
        self.conf_request = False
        self.count = 0
        self.closures = 0
        self.alarm = False
        self._silent_since: float | None = None

    __hash__ = None  # type: ignore[assignment]  # mutable state, compared by value

    def __eq__(self, other: object) -> bool:
        return isinstance(other, BusTerminal) and vars(self) == vars(other)

    def __repr__(self) -> str:
        return f"BusTerminal({', '.join(f'{k}={v!r}' for k, v in vars(self).items())})"

    def inputs(self, levels: int) -> bool:
        """The MFP input levels changed to ``levels``: LBST follows MFP11; ``True`` on a CONF (MFP12) rising edge,
        which raises a reconfiguration request."""
        levels = check_bits("levels", levels, 16, "MFP[15..0]")
        conf = bool((levels >> CONF_PIN) & 1)
        self.lbst = bool((levels >> LBST_PIN) & 1)
        rising = conf and not self.conf
        self.conf = conf
        self.conf_request = self.conf_request or rising
        return rising

    def enabled(self, connected: bool) -> bool:
        """The branch is in the data path: present (Table 2-9), switched on by the master, not closed by the BK."""
        return branch_present(self.rf, self.lbst, connected) and self.switched_on and not self.closed

    def status(self) -> int:
        """The branch status byte (BK-5)."""
        return wire.bk_status(self.conf_request, self.closed_report, self.count)

    def command(self, branch: BranchControl, acknowledge: bool, alarm: bool | None = None) -> None:
        """Apply a latched command word: the branch control (BK-4), with ``acknowledge`` (0714h) the end of a
        reconfiguration request and of the closed flag's report (BK-8), and the ALARM output unless ``alarm`` is
        ``None`` (BK-12)."""
        check_instance("branch", branch, BranchControl)
        acknowledge = check_bool("acknowledge", acknowledge)
        if alarm is not None:
            self.alarm = check_bool("alarm", alarm)
        if branch is BranchControl.OFF:
            self.switched_on = False
        elif branch in (BranchControl.ON, BranchControl.ON_EXTENDED):
            self.switched_on = True
            self.closed = False
            self.extended = branch is BranchControl.ON_EXTENDED
            self._silent_since = None
        if acknowledge:
            self.conf_request = self.closed_report = False

    def returned(self, traffic: bool, count: int | None, start: float, end: float) -> bool:
        """The branch was driven from ``start`` to ``end``: whether the master's telegrams came back on its return
        line (``traffic``) and the count of the counter telegram received there (``None``: none). ``True`` when the
        extended function closes the branch now (BK-3)."""
        traffic = check_bool("traffic", traffic)
        start = check_real("start", start, 0.0)
        end = check_real("end", end, start)
        self.count = 0 if count is None else count
        if traffic:
            self._silent_since = None
            return False
        since = start if self._silent_since is None else self._silent_since
        self._silent_since = since
        if self.extended and not self.closed and end - since >= BRANCH_SILENCE_S:
            self.closed = self.closed_report = True
            self.closures += 1
            return True
        return False

    def reset(self) -> None:
        """INTERBUS reset: the branch switched on again (also one the BK closed), the extended function off, the
        count forgotten (BK-9); a waiting reconfiguration request stays until acknowledged."""
        self.switched_on = True
        self.extended = False
        self.closed = False
        self.count = 0
        self.alarm = False
        self._silent_since = None

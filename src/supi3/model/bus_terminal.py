"""The bus terminal module (BK) function of the SUPI 3 OPC, at transaction level (manual 2.4, Tables 2-7..2-9).

A chip strapped to a BK mode (C[4..0] = 00000..00100, Table 2-7) connects a branch (remote bus or local bus) to the
remote bus. :class:`BusTerminal` holds what the BK decides about its branch; :class:`supi3.model.chip.Supi3` owns
one in the BK modes and the transaction-level ring (:class:`supi3.interbus.ring.Ring`) asks it whether the branch
is in the data path. Every change of the branch state is a pure transition of :mod:`supi3.terminal` (the spec,
shared with the pin-level block and the RTL); this class adds the transaction level's view of time (the silence of
the return line in bus seconds) and of the inputs (MFP levels). Decisions where the manual is silent are BK-1.. in
docs/assumptions/bus-terminal.md.

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

from dataclasses import replace

from supi3 import terminal as spec
from supi3.checks import check_bits, check_bool, check_choice, check_real
from supi3.interbus.wire import BranchControl
from supi3.tables import CLOCK_HZ
from supi3.terminal import (
    BRANCH_SILENCE_CLOCKS,
    BRANCH_SILENCE_S,
    CONF_PIN,
    LBST_PIN,
    TERMINAL_INTERFACES,
    Terminal,
    branch_present,
)

__all__ = [
    "BRANCH_SILENCE_S",
    "CONF_PIN",
    "LBST_PIN",
    "TERMINAL_INTERFACES",
    "BusTerminal",
    "branch_present",
]


class BusTerminal:
    """A BK's branch state (manual 2.4; docs/assumptions/bus-terminal.md) at transaction level.

    Parameters
    ----------
    interface:
        ``"BK-RB"``, ``"BK-LB"`` or ``"BK-LBD"`` (Table 2-7).
    rf:
        The RF[1..0] straps (Table 2-2), ``None`` without RF pins.
    silence:
        The silence of the return line after which the extended function closes the branch (BK-3), in clocks: 1 up to
        :data:`~supi3.terminal.BRANCH_SILENCE_CLOCKS` (the default, :data:`BRANCH_SILENCE_S`); shorter only to reach
        the closure quickly in tests, as the pin level's (``Supi3Pins(config, branch_silence=...)``).

    Attributes
    ----------
    state:
        The branch state, a :class:`supi3.terminal.Terminal`; its fields are also attributes of this object
        (read-only but ``conf_request``): ``switched_on``, ``extended``, ``closed``, ``closed_report``,
        ``conf_request``, ``alarm`` and ``count`` (see there).
    lbst:
        The LBST (MFP11) level last seen.
    closures:
        How often the BK closed its branch itself.
    recognised:
        A device answered on the branch since the power-up (the automatic recognition of 2.1.1, BK-37, BK-48); an
        INTERBUS reset keeps it. The transaction-level ring sets it (:meth:`supi3.interbus.ring.Ring`).
    switched_on_commands:
        How many commands switched the branch on (each restarts the silence, BK-3; the pin level's silence timer
        reads it).
    """

    def __init__(self, interface: str, rf: str | None, silence: int = BRANCH_SILENCE_CLOCKS) -> None:
        self.interface = check_choice("interface", interface, TERMINAL_INTERFACES)
        spec.rf_code(rf)
        self.rf = rf
        self._limit = spec.silence_limit(silence, "silence")
        self.silence_s = self._limit / CLOCK_HZ
        """The silence limit in bus seconds."""
        self.lbst = False
        self.state = Terminal()
        self.closures = 0
        self.switched_on_commands = 0
        self.recognised = False
        self._silent_since: float | None = None

    __hash__ = None  # type: ignore[assignment]  # mutable state, compared by value

    def __eq__(self, other: object) -> bool:
        return isinstance(other, BusTerminal) and vars(self) == vars(other)

    def __repr__(self) -> str:
        return f"BusTerminal({', '.join(f'{k}={v!r}' for k, v in vars(self).items())})"

    @property
    def switched_on(self) -> bool:
        """The master's last branch control: on (the default after power-up and reset) or off."""
        return self.state.switched_on

    @property
    def extended(self) -> bool:
        """The extended BK function is active (the master activated it)."""
        return self.state.extended

    @property
    def closed(self) -> bool:
        """The BK closed its branch itself (extended function), until the master switches the branch on again."""
        return self.state.closed

    @property
    def closed_report(self) -> bool:
        """The BK closed its branch and the master has not acknowledged it yet (status bit 6, BK-5)."""
        return self.state.closed_report

    @property
    def conf_request(self) -> bool:
        """A reconfiguration request (CONF edge) waits for the master's acknowledgement."""
        return self.state.conf_request

    @conf_request.setter
    def conf_request(self, waiting: bool) -> None:
        self.state = replace(self.state, conf_request=check_bool("conf_request", waiting))

    @property
    def alarm(self) -> bool:
        """The ALARM output (MFP15) the master set (BK-12); off after an INTERBUS reset."""
        return self.state.alarm

    @property
    def count(self) -> int:
        """The count of the last counter telegram received on the branch return line, 0 if none."""
        return self.state.count

    def inputs(self, levels: int) -> bool:
        """The MFP input levels changed to ``levels``: LBST follows MFP11; ``True`` on a CONF (MFP12) rising edge,
        which raises a reconfiguration request."""
        levels = check_bits("levels", levels, 16, "MFP[15..0]")
        conf = bool((levels >> CONF_PIN) & 1)
        self.lbst = bool((levels >> LBST_PIN) & 1)
        rising = conf and not self.state.conf
        self.state = spec.conf_level(self.state, conf)
        return rising

    def enabled(self, connected: bool) -> bool:
        """The branch is in the data path: present (Table 2-9), switched on by the master, not closed by the BK."""
        return spec.enabled(self.state, self.rf, self.lbst, connected)

    def status(self) -> int:
        """The branch status byte (BK-5)."""
        return self.state.status

    def command(self, branch: BranchControl, acknowledge: bool, alarm: bool | None = None) -> None:
        """Apply a latched command word: the branch control (BK-4), with ``acknowledge`` (0714h) the end of a
        reconfiguration request and of the closed flag's report (BK-8), and the ALARM output unless ``alarm`` is
        ``None`` (BK-12)."""
        self.state = spec.command(self.state, branch, acknowledge, alarm)
        if spec.restarts_silence(branch):
            self._silent_since = None
            self.switched_on_commands += 1

    def returned(self, traffic: bool, count: int | None, start: float, end: float,
                 frame_end: float | None = None) -> bool:
        """The branch was driven from ``start`` to ``end``: whether the master's telegrams came back on its return
        line (``traffic``) and the count of the counter telegram received there (``None``: none); ``frame_end``: when
        the stretch's frame ended at the BK (``start`` to ``end``; ``None``: no frame, an idle stretch or a reset).
        ``True`` when the extended function closes the branch now (BK-3).

        The silence is judged at the ends of frames, as the pin level's timer (BK-50): it restarts at the first
        frame's end after the master's telegrams came back (a stretch with ``traffic``: back before and after its
        frame), after a power-up, an INTERBUS reset, a command switching the branch on or a stretch not watched;
        it closes the branch at the first frame's end by which it has lasted the limit (to the clock), counting
        also time not reported here (the BK not reached). Without a frame nothing closes."""
        traffic = check_bool("traffic", traffic)
        start = check_real("start", start, 0.0)
        end = check_real("end", end, start)
        if frame_end is not None:
            frame_end = check_real("frame_end", frame_end, start, end)
        self.state = spec.received(self.state, 0 if count is None else count)
        closes = False
        if not spec.watching(self.state):
            self._silent_since = None
        elif frame_end is not None:
            since = self._silent_since
            if since is None or traffic:
                self._silent_since = frame_end
            elif round((frame_end - since) * CLOCK_HZ) >= self._limit:
                self.state = spec.silence(self.state)
                self.closures += 1
                closes = True
        if traffic:
            self._silent_since = None
        return closes

    def reset(self) -> None:
        """INTERBUS reset: the branch switched on again (also one the BK closed), the extended function off, the
        count forgotten (BK-9); a waiting reconfiguration request stays until acknowledged."""
        self.state = spec.reset(self.state)
        self._silent_since = None

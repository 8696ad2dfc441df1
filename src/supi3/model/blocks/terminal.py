"""The bus terminal module (BK) block at pin level: a synchronous machine with the ports of
:data:`~supi3.terminal.BLOCK_INPUTS` and :data:`~supi3.terminal.BLOCK_OUTPUTS`.

Manual 2.4 (Tables 2-7, 2-8, 2-9, "Extended bus terminal module functions"), 2.2.2 (the counter telegram), Table 3-19
(LD, E). Every change of the branch state is a pure transition of :mod:`supi3.terminal` (the model restates none of
them); the RTL counterpart :mod:`supi3.rtl.terminal` re-implements them in gates and is held to this block cycle by
cycle (``tests/test_verif_lockstep_terminal.py``). Decisions: BK-1.. of ``docs/assumptions/bus-terminal.md``, this
block's timing BK-20.

What happens at the clock edge ending a cycle, from that cycle's inputs (:mod:`supi3.pinlevel`), first match wins:

1. ``mode`` is :attr:`~supi3.terminal.TerminalMode.NONE`: nothing (the block is not a BK).
2. The first edge in a BK mode after the ``sync`` reset: :func:`~supi3.terminal.power_up` with the ``conf`` level
   (no edge at power-up).
3. Otherwise :func:`~supi3.terminal.conf_level` with ``conf``, then with ``ib_reset`` high
   :func:`~supi3.terminal.reset` (strobes are ignored in reset); else, in this order, a command
   (``cmd_valid``: :func:`~supi3.terminal.command` with ``branch``, ``ack`` and, if ``alarm_set``, ``alarm_on``),
   the master's telegram back (``ret_valid``: :func:`~supi3.terminal.received` 0), a counter telegram
   (``cnt_valid``: :func:`~supi3.terminal.received` ``count``), and the silence running out
   (:func:`~supi3.terminal.silence`).

The silence timer counts edges while the branch is watched: the state before the edge has the extended function on
and the branch in the data path (:func:`~supi3.terminal.enabled` with this cycle's ``rf``, ``lbst``,
``connected``); anything else, a ``ret_valid``, or a command switching the branch on clears it. The edge at which it
would reach ``time_limit`` (:data:`~supi3.terminal.BRANCH_SILENCE_CLOCKS`) applies the silence and clears it.

Outputs during a cycle come from the state and this cycle's ``rf``, ``lbst``, ``connected`` (``enabled``); every one
is 0 while ``mode`` is NONE.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Final

from supi3.checks import check_inputs
from supi3.interbus.wire import BranchControl
from supi3.pinlevel import EventLog, Pin
from supi3.terminal import (
    BLOCK_INPUTS,
    BLOCK_OUTPUTS,
    BRANCH_SILENCE_CLOCKS,
    Terminal,
    TerminalMode,
    command,
    conf_level,
    enabled,
    power_up,
    received,
    reset,
    restarts_silence,
    rf_of,
    silence,
    silence_limit,
)

__all__ = ["TerminalBlock"]

_WIDTHS: Final[dict[str, int]] = {pin.name: pin.width for pin in BLOCK_INPUTS}
_OFF: Final[dict[str, int]] = {pin.name: 0 for pin in BLOCK_OUTPUTS}



class TerminalBlock:
    """The bus terminal block as a pin model (:class:`supi3.pinlevel.PinModel`); see the module docstring.

    Parameters
    ----------
    time_limit:
        The silence after which the extended function closes the branch, in clocks: 1 up to
        :data:`~supi3.terminal.BRANCH_SILENCE_CLOCKS` (the default, BK-3); shorter only to reach it quickly in tests.

    Attributes
    ----------
    state:
        The branch state, a :class:`~supi3.terminal.Terminal` (the state of the cycle to come).
    timer:
        Edges of silence counted so far.
    """

    inputs: Sequence[Pin] = BLOCK_INPUTS
    outputs: Sequence[Pin] = BLOCK_OUTPUTS

    def __init__(self, time_limit: int = BRANCH_SILENCE_CLOCKS) -> None:
        self.time_limit = silence_limit(time_limit)
        self.log = EventLog()
        self.reset()

    def reset(self) -> None:
        """The state after the ``sync`` reset: the power-up state, waiting for the first edge in a BK mode."""
        self.state = Terminal()
        self.timer = 0
        self._fresh = True
        self.cycle = 0
        self.log.clear()

    def step(self, inputs: Mapping[str, int]) -> dict[str, int]:
        """One clock (see :mod:`supi3.pinlevel`): this cycle's outputs, then the edge ending it.

        Raises
        ------
        ArgumentError
            ``inputs`` does not name exactly the block's input pins, or a value is not an integer within its pin's
            width (nothing changes).
        """
        v = check_inputs(inputs, _WIDTHS)
        self.cycle += 1
        if v["mode"] == TerminalMode.NONE:
            return dict(_OFF)
        state = self.state
        on = enabled(state, rf_of(v["rf"]), bool(v["lbst"]), bool(v["connected"]))
        outputs = {
            "enabled": int(on), "status": state.status, "attention": int(state.attention), "ld": int(state.ld),
            "e": int(state.e), "alarm": int(state.alarm), "closed": int(state.closed),
        }  # fmt: skip
        self._edge(v, state.extended and on)
        return outputs

    def _edge(self, v: Mapping[str, int], counting: bool) -> None:
        """The clock edge ending the cycle with inputs ``v`` (the order of the module docstring); ``counting``: the
        silence timer runs in this cycle."""
        cycle = self.cycle - 1
        if self._fresh:
            self._fresh = False
            self.state = power_up(bool(v["conf"]))
            return
        state = conf_level(self.state, bool(v["conf"]))
        if state.conf_request and not self.state.conf_request:
            self.log.add(cycle, "CONF edge: reconfiguration request")
        if v["ib_reset"]:
            self.state = reset(state)
            self.timer = 0
            return
        branch = BranchControl(v["branch"])
        restart = bool(v["ret_valid"] or (v["cmd_valid"] and restarts_silence(branch)))
        expired = counting and not restart and self.timer + 1 >= self.time_limit
        if v["cmd_valid"]:
            state = command(state, branch, bool(v["ack"]), bool(v["alarm_on"]) if v["alarm_set"] else None)
            self.log.add(cycle, "command {} ack={}: {}", branch.name, v["ack"], state)
        if v["ret_valid"]:
            state = received(state, 0)
        if v["cnt_valid"]:
            state = received(state, v["count"])
        if expired:
            state = silence(state)
            self.log.add(cycle, "silence over: {}", state)
        self.timer = self.timer + 1 if counting and not restart and not expired else 0
        self.state = state

    def recent_events(self) -> list[str]:
        """The block's last events, for mismatch reports."""
        return self.log.recent()

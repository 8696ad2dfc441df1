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

from bisect import bisect_right
from collections.abc import Mapping, Sequence
from typing import Final

import numpy as np
import numpy.typing as npt

from supi3.checks import check_inputs
from supi3.interbus import wire
from supi3.interbus.wire import BranchControl
from supi3.lbd import clocks_per_bit
from supi3.model.blocks.counter import CounterBlock
from supi3.model.blocks.transmitter import NEVER, recognition
from supi3.pinlevel import EventLog, Pin
from supi3.terminal import (
    BLOCK_INPUTS,
    BLOCK_OUTPUTS,
    BRANCH_SILENCE_CLOCKS,
    DI3_PIN,
    DO3_PIN,
    LBST_PIN,
    Terminal,
    TerminalMode,
    branch_present,
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

__all__ = ["BranchLines", "ReturnWatch", "TerminalBlock"]

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


class ReturnWatch:
    """The master's telegrams back on a BK's branch return line (BK-38): ``seen`` is 1 in the cycle after the stop
    bit of a status telegram was sampled at the idle level on the synchronised DI3 (``ret_valid`` of
    :data:`~supi3.terminal.BLOCK_INPUTS`). Counter telegrams are data telegrams: they never count (BK-3).

    The bit grid is the chip receiver's (M7): between telegrams a start level makes that clock the first of a bit
    period; the line is sampled mid-bit (``cpb // 2``); a start bit sampled at the idle level is no telegram; the type
    bit (``wire.POS_TYPE``) gives the length; after the stop bit's sample the watch is between telegrams again. The RTL
    counterpart is ``supi3.rtl.terminal.ReturnWatchRtl``, clocked and reset as the core's logic.

    Attributes
    ----------
    seen:
        ``ret_valid`` for the cycle to come.
    """

    __slots__ = ("bit", "data", "phase", "seen")

    def __init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        """Between telegrams, nothing seen."""
        self.bit = -1
        """The telegram's bit period now, -1 between telegrams."""
        self.phase = 0
        self.data = False
        self.seen = 0

    def clock(self, line: int, cpb: int) -> None:
        """The clock edge ending a cycle with the synchronised DI3 at ``line``, ``cpb`` clocks per bit."""
        seen = 0
        if self.bit < 0 and line == wire.START_LEVEL:
            self.bit, self.phase = 0, 0
        if self.bit >= 0:
            if self.phase == cpb // 2:
                bit = self.bit
                self.bit += 1
                if bit == wire.POS_START and line != wire.START_LEVEL:
                    self.bit = -1
                elif bit == wire.POS_TYPE:
                    self.data = line == wire.TYPE_DATA_LEVEL
                elif bit == (wire.DATA_TELEGRAM_BITS if self.data else wire.STATUS_TELEGRAM_BITS) - 1:
                    seen = int(not self.data and line == wire.IDLE_LEVEL)
                    self.bit = -1
            self.phase = 0 if self.phase >= cpb - 1 else self.phase + 1
        self.seen = seen


class BranchLines:
    """A BK's branch data lines in the chip core (manual 2.4, Tables 2-7, 2-8, 2-9; BK-1, BK-37): DO3_CU (MFP9),
    DI3 (MFP10) and the switch of DO2, for ``supi3.model.pins.Supi3Pins`` in the BK modes.

    While the branch is in the data path (:func:`~supi3.terminal.enabled`: present by Table 2-9, switched on, not
    closed) DO3 carries what the transmitter sends (the DO2 of a chip without branch) and DO2 repeats the
    synchronised DI3, the branch's return line: the data path runs through the BK, its branch, then on along the
    remote bus (BK-1's flattened order); the M5 loop-back takes this DO2. Otherwise DO3 idles and DO2 is the
    transmitter's. ``connected`` (a device answers on the branch, BK-37) latches the first high level of the
    synchronised DI3 at every clock edge where the core's logic runs (a device's idle return line, as M5 recognises
    a following device on DI2); a power-up reset clears it.

    The return line's strobes for the BK (``ret_valid``, ``cnt_valid``/``count`` of
    :data:`~supi3.terminal.BLOCK_INPUTS`): a :class:`ReturnWatch` on the synchronised DI3 (BK-38) and, in BK-LBD, a
    :class:`~supi3.model.blocks.counter.CounterBlock` whose ``seen`` and ``count`` give the BK its count (BK-39),
    clocked where the core's logic runs and cleared by a power-up reset. ``Supi3Pins.step`` clocks them each cycle;
    over a ``run()`` they are clocked ahead over the run's DI3 (:meth:`plan`, again after each power-up reset), and
    the run visits the cycles with a strobe (:meth:`next_strobe`).

    Parameters
    ----------
    rf:
        The RF[1..0] straps (Table 2-2), ``None`` without RF pins.
    cpb:
        Clocks per bit.
    lbd:
        BK-LBD: the counter block on DI3.

    Attributes
    ----------
    connected:
        A device answered on the branch (for the cycle to come).
    watch, counter:
        The blocks on DI3 (``counter`` ``None`` but in BK-LBD).
    """

    __slots__ = ("_c0", "_events", "_line", "_opens", "_start", "_strobes", "connected", "counter", "cpb", "fast",
                 "present", "watch")  # fmt: skip

    def __init__(self, rf: str | None, cpb: int, lbd: bool) -> None:
        self.present = np.array([[branch_present(rf, bool(lbst), bool(connected)) for connected in (0, 1)]
                                 for lbst in (0, 1)])  # fmt: skip
        """Table 2-9 by [LBST][connected] (:func:`~supi3.terminal.branch_present`)."""
        self.cpb = cpb
        self.fast = int(cpb == clocks_per_bit(1))
        self.connected = False
        self.watch = ReturnWatch()
        self.counter = CounterBlock() if lbd else None
        self._start: tuple[int, bool, int] = (0, False, 0)
        self._opens: list[tuple[int, bool]] = []
        self._c0 = 0
        self._line = np.zeros(0, dtype=np.int64)
        self._strobes = np.zeros((0, 3), dtype=np.int64)
        self._events: list[int] = []

    def strobes(self) -> tuple[int, int, int]:
        """``ret_valid``, ``cnt_valid`` and ``count`` in the cycle to come (``Supi3Pins.step``)."""
        counter = self.counter
        if counter is None:
            return self.watch.seen, 0, 0
        return self.watch.seen, counter.seen, counter.state.counted

    def strobes_at(self, c: int) -> tuple[int, int, int]:
        """:meth:`strobes` in cycle ``c`` of the run being planned."""
        ret, cnt, count = self._strobes[c - self._c0].tolist()
        return ret, cnt, count

    def _clock_blocks(self, di3: int) -> None:
        self.watch.clock(di3, self.cpb)
        counter = self.counter
        if counter is not None:
            counter.clock(di3, self.fast)
            counter.queue.clear()  # its line goes nowhere: the BK takes seen and count only

    def on(self, state: Terminal, mfp_in: int) -> bool:
        """The branch is in the data path in a cycle of the synchronised MFP inputs ``mfp_in`` (LBST) and the BK
        state ``state`` (:func:`~supi3.terminal.enabled`)."""
        return bool(self.present[mfp_in >> LBST_PIN & 1, int(self.connected)]) and _open(state)

    def route(self, outputs: dict[str, int], state: Terminal, mfp_in: int, next_present: bool) -> None:
        """Set ``do2``, ``mfp_out`` (DO3) and, when the chip loops back (M5: ``next_present`` false), ``di1`` of a
        cycle in that cycle's ``outputs`` (``do2`` the transmitter's)."""
        sent = outputs["do2"]
        if self.on(state, mfp_in):
            do2 = outputs["do2"] = mfp_in >> DI3_PIN & 1
            if not next_present:
                outputs["di1"] = do2
            outputs["mfp_out"] |= sent << DO3_PIN
        else:
            outputs["mfp_out"] |= wire.IDLE_LEVEL << DO3_PIN

    def clock(self, mfp_in: int) -> None:
        """A clock edge where the core's logic runs, with the synchronised MFP inputs ``mfp_in``."""
        di3 = mfp_in >> DI3_PIN & 1
        self.connected = self.connected or bool(di3)
        self._clock_blocks(di3)

    def power_up(self) -> None:
        """The core's power-up reset: no device seen, the blocks on DI3 cleared."""
        self.connected = False
        self.watch.reset()
        if self.counter is not None:
            self.counter.reset()

    def begin(self, c0: int, run_from: int, state: Terminal, mfp_in: npt.NDArray[np.int64]) -> None:
        """A run of ``Supi3Pins.run`` begins at cycle ``c0`` (the logic runs from ``run_from``, the BK state is
        ``state``, ``mfp_in`` the run's synchronised MFP inputs): :meth:`record` follows the state, :meth:`render`
        draws the lines; the blocks on DI3 are planned over the run."""
        self._start = (c0, self.connected, run_from)
        self._opens = [(0, _open(state))]
        self._c0 = c0
        self._line = mfp_in >> DI3_PIN & 1
        self._strobes = np.zeros((len(mfp_in), 3), dtype=np.int64)
        self.plan(c0, run_from)

    def plan(self, c: int, run_from: int) -> None:
        """Clock the blocks on DI3 from cycle ``c`` to the run's end where the logic runs (from ``run_from``),
        keeping their strobes: after :meth:`begin` and after each power-up reset (in cycle ``c - 1``)."""
        line, strobes, c0 = self._line, self._strobes, self._c0
        t = min(c - c0, len(line))
        first = max(t, run_from - c0) if run_from != NEVER else len(line)
        strobes[t:first] = self.strobes()
        for k in range(first, len(line)):
            strobes[k] = self.strobes()
            self._clock_blocks(int(line[k]))
        self._events = np.flatnonzero(strobes[:, 0] | strobes[:, 1]).tolist()

    def next_strobe(self, t: int) -> int:
        """The first cycle of the run after its cycle ``t`` with a strobe for the BK (the run's length if none)."""
        k = bisect_right(self._events, t)
        return self._events[k] if k < len(self._events) else len(self._line)

    def record(self, t: int, state: Terminal) -> None:
        """The BK state from the run's cycle ``t`` on is ``state``."""
        opened = _open(state)
        if opened != self._opens[-1][1]:
            self._opens.append((t, opened))

    def render(self, traces: dict[str, npt.NDArray[np.int64]], mfp_in: npt.NDArray[np.int64],
               power_ups: Sequence[tuple[int, int]]) -> None:
        """:meth:`route` over the run begun by :meth:`begin`: ``traces`` the run's outputs (``do2`` the
        transmitter's), ``mfp_in`` its synchronised MFP inputs, ``power_ups`` its power-up resets (cycle, logic runs
        from); :attr:`connected` is then the value after the run."""
        n = len(mfp_in)
        seen = mfp_in >> DI3_PIN & 1
        connected = recognition(self._start, power_ups, seen, False)
        self.connected = bool(connected[-1])
        starts = [t for t, _ in self._opens]
        opens = np.repeat([o for _, o in self._opens], np.diff([*starts, n]).clip(min=0))
        on = self.present[mfp_in >> LBST_PIN & 1, connected[:-1].astype(np.int64)] & opens
        sent = traces["do2"]
        traces["mfp_out"] = traces["mfp_out"] | np.where(on, sent, wire.IDLE_LEVEL) << DO3_PIN
        traces["do2"] = np.where(on, seen, sent)


def _open(state: Terminal) -> bool:
    """The BK keeps its branch open: switched on and not closed by itself (:func:`~supi3.terminal.enabled` without
    Table 2-9)."""
    return state.switched_on and not state.closed

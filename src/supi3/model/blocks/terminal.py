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

The silence is judged at the ends of frames (BK-50, :func:`silence_edge`): the branch is watched while the state
before the edge has the extended function on and the branch in the data path (:func:`~supi3.terminal.enabled` with
this cycle's ``rf``, ``lbst``, ``connected``). A ``ret_valid``, a command switching the branch on, or an edge not
watched marks the return line heard; the next ``frame_end`` (the frame engine completes a check sequence) with the
mark set restarts the silence timer there and clears the mark. The timer counts the edges since (holding at
``time_limit - 1``); a ``frame_end`` without the mark at which the silence has lasted ``time_limit``
(:data:`~supi3.terminal.BRANCH_SILENCE_CLOCKS`) edges applies the silence. Without frames (a master that idles)
nothing closes.

Outputs during a cycle come from the state and this cycle's ``rf``, ``lbst``, ``connected`` (``enabled``; ``live``
without ``connected``); every one is 0 while ``mode`` is NONE.
"""

from __future__ import annotations

import copy
from bisect import bisect_left, bisect_right
from collections.abc import Mapping, Sequence
from typing import Final

import numpy as np
import numpy.typing as npt

from supi3.checks import check_bool, check_choice, check_inputs
from supi3.interbus import wire
from supi3.interbus.wire import BranchControl
from supi3.lbd import clocks_per_bit
from supi3.model.blocks.counter import CounterBlock
from supi3.model.blocks.transmitter import NEVER
from supi3.pinlevel import EventLog, Pin
from supi3.terminal import (
    BLOCK_INPUTS,
    BLOCK_OUTPUTS,
    BRANCH_DRAIN_BITS,
    BRANCH_SILENCE_CLOCKS,
    DI3_PIN,
    DO3_PIN,
    LBST_PIN,
    LineSource,
    Terminal,
    TerminalMode,
    branch_present,
    command,
    conf_level,
    enabled,
    live,
    power_up,
    received,
    reset,
    restarts_silence,
    rf_of,
    silence,
    silence_limit,
    watching,
)

__all__ = ["BranchLines", "ReturnWatch", "TerminalBlock", "silence_edge"]

_WIDTHS: Final[dict[str, int]] = {pin.name: pin.width for pin in BLOCK_INPUTS}
_OFF: Final[dict[str, int]] = {pin.name: 0 for pin in BLOCK_OUTPUTS}
_CPBS: Final[tuple[int, int]] = (clocks_per_bit(0), clocks_per_bit(1))
"""Clocks per bit at 500 kbit/s and 2 Mbit/s (Table 1-7)."""


def silence_edge(timer: int, heard: bool, counting: bool, restart: bool, frame_end: bool,
                 limit: int) -> tuple[int, bool, bool]:
    """The silence timer at one clock edge (BK-3, BK-20, BK-50): ``timer`` the edges since the silence (re)started,
    ``heard`` the return line was heard since the last frame's end, ``counting`` the branch is watched in the cycle
    ending, ``restart`` a master's telegram came back or a command switched the branch on, ``frame_end`` the frame
    engine completed a check sequence at this edge, ``limit`` the silence in clocks. Returns the timer, the mark and
    whether the silence closes the branch at this edge (the caller applies :func:`~supi3.terminal.silence`).

    The silence restarts at the end of the first frame after the return line was heard (or the branch was not
    watched) and closes the branch at the end of the first frame by which it has lasted ``limit`` edges: a closure
    so comes only where a frame has just passed the BK, leaving DO2 the whole gap before the next one (BK-47)."""
    if not counting:
        return 0, True, False
    expired = frame_end and not heard and not restart and timer + 1 >= limit
    if frame_end and (heard or expired):
        return 0, restart, expired
    return min(timer + 1, limit - 1), heard or restart, False


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
        Edges since the silence (re)started at a frame's end (:func:`silence_edge`).
    heard:
        The return line was heard (or the branch not watched) since the last frame's end: the next one restarts the
        silence.
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
        self.heard = True
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
        rf, lbst = rf_of(v["rf"]), bool(v["lbst"])
        on = enabled(state, rf, lbst, bool(v["connected"]))
        outputs = {
            "enabled": int(on), "live": int(live(state, rf, lbst)), "status": state.status,
            "attention": int(state.attention), "ld": int(state.ld), "e": int(state.e), "alarm": int(state.alarm),
            "closed": int(state.closed),
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
            self.timer, self.heard = 0, True
            return
        branch = BranchControl(v["branch"])
        restart = bool(v["ret_valid"] or (v["cmd_valid"] and restarts_silence(branch)))
        self.timer, self.heard, expired = silence_edge(self.timer, self.heard, counting, restart,
                                                       bool(v["frame_end"]), self.time_limit)  # fmt: skip
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
    bit (``wire.POS_TYPE``) gives the length; after the stop bit's sample the watch is between telegrams again, also
    when it was sampled at the start level (no M16, BK-60). The RTL counterparts, clocked and reset as the core's
    logic: ``supi3.rtl.terminal.ReturnWatchRtl`` on the transmitter's line, and on DI3 the return counter block
    outside LBD-MR (``supi3.rtl.counter.CounterRtl(watch=True)`` with ``chain`` 0).

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

    @property
    def busy(self) -> bool:
        """A telegram is under way (begun, its stop bit not yet sampled)."""
        return self.bit >= 0

    def scan(self, line: npt.NDArray[np.int64], cpb: int) -> npt.NDArray[np.bool_]:
        """:meth:`clock` at every cycle of ``line`` (``seen`` aside), jumping from sample to sample: :attr:`busy`
        before each cycle's edge."""
        n = len(line)
        busy = np.zeros(n, dtype=bool)
        starts = np.flatnonzero(line == wire.START_LEVEL)
        half = cpb // 2
        k = 0
        while k < n:
            first = k
            if self.bit < 0:
                i = int(np.searchsorted(starts, k))
                if i == len(starts):
                    break
                k = int(starts[i])
                sample = k + half  # a whole telegram in the trace: its start and type samples give its end
                if sample + cpb < n and line[sample] == wire.START_LEVEL:
                    data = bool(line[sample + cpb] == wire.TYPE_DATA_LEVEL)
                    end = sample + ((wire.DATA_TELEGRAM_BITS if data else wire.STATUS_TELEGRAM_BITS) - 1) * cpb
                    if end < n:
                        self.data = data
                        busy[k + 1 : end + 1] = True
                        k = end + 1
                        continue
                self.bit, self.phase, first = 0, 0, k + 1
            while True:
                sample = k + (half - self.phase) % cpb
                if sample >= n:
                    busy[first:] = True
                    self.phase = (self.phase + n - k) % cpb
                    return busy
                bit, level = self.bit, int(line[sample])
                self.phase = (self.phase + sample + 1 - k) % cpb
                self.bit += 1
                k = sample + 1
                if bit == wire.POS_TYPE:
                    self.data = level == wire.TYPE_DATA_LEVEL
                elif (bit == wire.POS_START and level != wire.START_LEVEL) \
                        or bit == (wire.DATA_TELEGRAM_BITS if self.data else wire.STATUS_TELEGRAM_BITS) - 1:
                    busy[first:k] = True
                    self.bit = -1
                    break
        return busy

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

    While the branch interface is live (:func:`~supi3.terminal.live`: it would be in the data path if a device
    answered, BK-42) DO3 carries what the transmitter sends (the DO2 of a chip without branch), else DO3 idles. While
    the branch is in the data path (:func:`~supi3.terminal.enabled`: present by Table 2-9, switched on, not closed)
    DO2 repeats the synchronised DI3, the branch's return line: the data path runs through the BK, its branch, then
    on along the remote bus (BK-1's flattened order); the M5 loop-back takes this DO2. Otherwise DO2 is the
    transmitter's. Each line switches only between telegrams (BK-47, :meth:`_select`): :attr:`sel3` and
    :attr:`sel2`, registers updated where the core's logic runs, follow ``live`` and ``enabled``; DO2 idles between
    its two lines and leaves DI3 once the branch has drained. ``connected`` (a device answers on the branch,
    BK-37) latches the first start level (0) of the
    synchronised DI3 at a clock edge where the core's logic runs: a following protocol chip repeats what DO3 sends
    (the master's reset pattern, its telegrams) and loops it back, and each begins with a start level; a pulled-up
    DI3 (BK-41) or a broken line (BK-30) rests at the idle level and never shows one. A power-up reset clears it.

    The return line's strobes for the BK (``ret_valid``, ``cnt_valid``/``count`` of
    :data:`~supi3.terminal.BLOCK_INPUTS`): a :class:`ReturnWatch` on the synchronised DI3 (BK-38) and, in BK-LBD, a
    :class:`~supi3.model.blocks.counter.CounterBlock` whose ``seen`` and ``count`` give the BK its count (BK-39),
    clocked where the core's logic runs and cleared by a power-up reset. The silence timer of the extended function
    (BK-3, BK-20; :meth:`edge`) is :class:`TerminalBlock`'s. ``Supi3Pins.step`` clocks them each cycle; over a
    ``run()`` the lines are clocked ahead over the run's DI3 (:meth:`plan`, again after each power-up reset), the run
    visits the cycles with a strobe, a change of ``connected`` or LBST, or the silence running out
    (:meth:`next_event`), and the timer catches up over the cycles between.

    Parameters
    ----------
    rf:
        The RF[1..0] straps (Table 2-2), ``None`` without RF pins.
    cpb:
        Clocks per bit.
    lbd:
        BK-LBD: the counter block on DI3.
    time_limit:
        The silence after which the extended function closes the branch, in clocks (BK-3; shorter only in tests).

    Attributes
    ----------
    connected:
        A device answered on the branch (for the cycle to come).
    watch, counter:
        The blocks on DI3 (``counter`` ``None`` but in BK-LBD).
    timer, heard:
        :class:`TerminalBlock`'s, the timer counted up to cycle :attr:`timer_at` (BK-20, BK-50).
    """

    __slots__ = (
        "_c0", "_connected", "_events", "_initial", "_lbst", "_line", "_opens", "_restarts", "_running", "_starts",
        "_strobes", "connected", "counter", "counting", "cpb", "drain", "drained", "fast", "heard", "limit", "present",
        "sel2", "sel3", "timer", "timer_at", "tx", "watch",
    )  # fmt: skip

    def __init__(self, rf: str | None, cpb: int, lbd: bool, time_limit: int = BRANCH_SILENCE_CLOCKS) -> None:
        cpb = check_choice("cpb", cpb, _CPBS, "clocks per bit at 500 kbit/s or 2 Mbit/s")
        lbd = check_bool("lbd", lbd)
        self.present = np.array([[branch_present(rf, bool(lbst), bool(connected)) for connected in (0, 1)]
                                 for lbst in (0, 1)])  # fmt: skip
        """Table 2-9 by [LBST][connected] (:func:`~supi3.terminal.branch_present`); ``present[:, 1]`` is whether the
        interface is live with the branch open (:func:`~supi3.terminal.live`, BK-42)."""
        self.cpb = cpb
        self.fast = int(cpb == clocks_per_bit(1))
        self.limit = silence_limit(time_limit)
        self.connected = False
        self.watch = ReturnWatch()
        self.counter = CounterBlock() if lbd else None
        self.tx = ReturnWatch()
        """The telegram grid of what the transmitter sends (BK-47)."""
        self.drain = BRANCH_DRAIN_BITS * cpb
        self.sel3 = False
        """DO3 carries the transmitter's line (else it idles), BK-47."""
        self.sel2 = _SENT
        """What DO2 carries, a :class:`~supi3.terminal.LineSource` (BK-47)."""
        self.drained = 0
        """Clocks before this one that DI3 spent between telegrams at the idle level, at most :attr:`drain`."""
        self.timer = 0
        self.heard = True
        self.timer_at = 0
        self.counting = False
        """The timer counts in the cycles from :attr:`timer_at` on (a run's view, until its next visit)."""
        self._opens: list[tuple[int, bool]] = []
        self._c0 = 0
        self._line = np.zeros(0, dtype=np.int64)
        self._starts: list[int] = []
        self._lbst = np.zeros(0, dtype=np.int64)
        self._connected = np.zeros(0, dtype=np.int64)
        self._strobes = np.zeros((0, 3), dtype=np.int64)
        self._running = np.zeros(0, dtype=bool)
        self._restarts: list[int] = []
        self._initial = (self.sel3, self.sel2, self.drained, ReturnWatch(), ReturnWatch())
        self._events: list[int] = []

    # One cycle --------------------------------------------------------------------------------------------------

    def on(self, state: Terminal, lbst: int, connected: bool) -> bool:
        """The branch is in the data path with the BK state ``state``, the synchronised LBST ``lbst`` and
        ``connected`` (:func:`~supi3.terminal.enabled`)."""
        return bool(self.present[lbst, int(connected)]) and _open(state)

    def route(self, outputs: dict[str, int], mfp_in: int, next_present: bool) -> None:
        """Set ``do2``, ``mfp_out`` (DO3) and, when the chip loops back (M5: ``next_present`` false), ``di1`` of a
        cycle in that cycle's ``outputs`` (``do2`` the transmitter's; ``mfp_in`` the synchronised MFP inputs), as
        :attr:`sel3` and :attr:`sel2` select."""
        sent = outputs["do2"]
        outputs["mfp_out"] |= (sent if self.sel3 else wire.IDLE_LEVEL) << DO3_PIN
        if self.sel2 != _SENT:
            do2 = outputs["do2"] = mfp_in >> DI3_PIN & 1 if self.sel2 == _DI3 else wire.IDLE_LEVEL
            if not next_present:
                outputs["di1"] = do2

    def _select(self, live: bool, on: bool, sent: int, di3: int, tx_busy: bool, di3_busy: bool,
                drained: int) -> None:
        """BK-47 at a clock edge: the lines switch only between telegrams. ``live`` and ``on`` (the branch interface
        live, the branch in the data path) in the cycle ending, ``sent`` and ``di3`` its levels of the transmitter and
        of the synchronised DI3, ``tx_busy`` and ``di3_busy`` whether a telegram was under way on them, ``drained``
        the clocks before it that DI3 spent between telegrams at the idle level. A line is left between telegrams at
        the idle level (DI3 once drained, :data:`~supi3.terminal.BRANCH_DRAIN_BITS`) and taken between telegrams;
        DO2 idles between the two."""
        tx_free = not tx_busy
        tx_leave = tx_free and sent == wire.IDLE_LEVEL
        if self.sel3 != live and (tx_leave if self.sel3 else tx_free):
            self.sel3 = live
        want = _DI3 if on else _SENT
        sel = self.sel2
        if sel != want:
            di3_free = not di3_busy
            if sel == _IDLE or (tx_leave if sel == _SENT
                                else di3_free and di3 == wire.IDLE_LEVEL and drained >= self.drain):
                self.sel2 = want if (tx_free if want == _SENT else di3_free) else _IDLE

    def strobes(self) -> tuple[int, int, int]:
        """``ret_valid``, ``cnt_valid`` and ``count`` in the cycle to come (``Supi3Pins.step``)."""
        counter = self.counter
        if counter is None:
            return self.watch.seen, 0, 0
        return self.watch.seen, counter.seen, counter.state.counted

    def clock(self, mfp_in: int, sent: int, state: Terminal) -> None:
        """A clock edge where the core's logic runs, with the synchronised MFP inputs ``mfp_in``, the transmitter's
        level ``sent`` and the BK state ``state`` of the cycle ending."""
        di3 = mfp_in >> DI3_PIN & 1
        lbst = mfp_in >> LBST_PIN & 1
        di3_busy = self.watch.busy
        self._select(self.on(state, lbst, True), self.on(state, lbst, self.connected), sent, di3, self.tx.busy,
                     di3_busy, self.drained)
        self.drained = min(self.drained + 1, self.drain) if di3 == wire.IDLE_LEVEL and not di3_busy else 0
        self.tx.clock(sent, self.cpb)
        self._clock_di3(di3)

    def _clock_di3(self, di3: int) -> None:
        """The edge on the DI3 side: ``connected`` and the blocks on DI3."""
        self.connected = self.connected or di3 == wire.START_LEVEL
        self._clock_blocks(di3)

    def _clock_blocks(self, di3: int) -> None:
        self.watch.clock(di3, self.cpb)
        counter = self.counter
        if counter is not None:
            counter.clock(di3, self.fast)
            counter.queue.clear()  # its line goes nowhere: the BK takes seen and count only

    def power_up(self) -> None:
        """The core's power-up reset: no device seen, the blocks on DI3 and the timer cleared."""
        self.connected = False
        self.watch.reset()
        if self.counter is not None:
            self.counter.reset()
        self.timer, self.heard, self.counting = 0, True, False
        self.tx.reset()
        self.sel3, self.sel2, self.drained = False, _SENT, 0

    def quiet(self, c: int, state: Terminal, recording: bool) -> None:
        """The BK's edge ending cycle ``c`` takes no strobe (its first running clock, an INTERBUS reset): the timer
        starts from 0 (BK-20); ``state`` the BK state after it, ``recording`` in a run."""
        self.timer, self.heard, self.timer_at = 0, True, c + 1
        self.counting = recording and self._counts(c + 1, state)

    def edge(self, c: int, before: Terminal, after: Terminal, switched_on: bool, mfp_in: int, frame_end: bool,
             recording: bool) -> tuple[Terminal, bool]:
        """The BK's edge ending running cycle ``c`` after the core's (BK-20's order; the chip applied CONF and a
        command there): ``before`` the state before the edge, ``after`` after the core's, ``switched_on`` a command
        switched the branch on, ``mfp_in`` the synchronised MFP inputs, ``frame_end`` the frame engine completed a
        check sequence at this edge (the silence is judged there, BK-50, :func:`silence_edge`); ``recording``: in a
        run (the strobes planned). Returns the state after the
        master's telegram back, the counter telegram and the silence, and whether the silence closed the branch."""
        connected = bool(self._connected[c - self._c0]) if recording else self.connected
        ret, cnt, count = self._strobes[c - self._c0].tolist() if recording else self.strobes()
        if self.counting:  # the cycles between a run's visits
            self.timer += c - self.timer_at
        on = self.on(before, mfp_in >> LBST_PIN & 1, connected)
        if not on:  # BK-44: the return line's strobes count only while the branch is in the data path
            ret = cnt = 0
        counting = before.extended and on
        restart = bool(ret) or switched_on
        self.timer, self.heard, expired = silence_edge(self.timer, self.heard, counting, restart, frame_end,
                                                       self.limit)  # fmt: skip
        state = after
        if ret:
            state = received(state, 0)
        if cnt:
            state = received(state, count)
        closes = expired and not (before.switched_on and not after.switched_on) and watching(state)
        if closes:
            state = silence(state)
        self.timer_at = c + 1
        self.counting = recording and self._counts(c + 1, state)
        return state, closes

    def _counts(self, c: int, state: Terminal) -> bool:
        """The timer counts in a run's cycle ``c`` (and those after it until the next visit) with ``state``."""
        t = c - self._c0
        if not state.extended or t >= len(self._line):
            return False
        return self.on(state, int(self._lbst[t]), bool(self._connected[t]))

    # A run ------------------------------------------------------------------------------------------------------

    def begin(self, c0: int, run_from: int, state: Terminal, mfp_in: npt.NDArray[np.int64]) -> None:
        """A run of ``Supi3Pins.run`` begins at cycle ``c0`` (the logic runs from ``run_from``, the BK state is
        ``state``, ``mfp_in`` the run's synchronised MFP inputs): :meth:`record` follows the state, :meth:`render`
        draws the lines; the lines on DI3 are planned over the run."""
        self._opens = [(0, _open(state))]
        self._c0 = c0
        self._line = mfp_in >> DI3_PIN & 1
        self._starts = np.flatnonzero(self._line == wire.START_LEVEL).tolist()
        self._lbst = mfp_in >> LBST_PIN & 1
        self._strobes = np.zeros((len(mfp_in), 3), dtype=np.int64)
        self._connected = np.zeros(len(mfp_in), dtype=np.int64)
        self._running = np.zeros(len(mfp_in), dtype=bool)
        self._restarts = []
        self._initial = (self.sel3, self.sel2, self.drained, copy.copy(self.tx), copy.copy(self.watch))
        self.plan(c0, run_from, restart=False)
        counting = c0 >= run_from and self._counts(c0, state)
        if counting and not self.counting:  # the timer stood at 0
            self.timer, self.timer_at = 0, c0
        self.counting = counting

    def plan(self, c: int, run_from: int, restart: bool = True) -> None:
        """Clock the lines on DI3 from cycle ``c`` to the run's end where the logic runs (from ``run_from``),
        keeping their strobes, ``connected`` and whether a telegram was under way on DI3: after :meth:`begin` and
        after each power-up reset (in cycle ``c - 1``; the lines' selection restarts at ``c``)."""
        line, strobes, connected, c0 = self._line, self._strobes, self._connected, self._c0
        t = min(c - c0, len(line))
        if restart:
            self._restarts.append(t)
        first = max(t, run_from - c0) if run_from != NEVER else len(line)
        self._running[t:first] = False
        self._running[first:] = True
        strobes[t:first] = self.strobes()
        connected[t:first] = self.connected
        n, k = len(line), first
        starts = self._starts
        watch = self.watch
        while k < n:
            if self.counter is None and self.connected and watch.bit < 0 and not watch.seen and line[k]:
                # An idle line between telegrams changes nothing until its next start level: skip to it.
                s = bisect_left(starts, k)
                end = starts[s] if s < len(starts) else n
                strobes[k:end] = 0
                connected[k:end] = 1
                k = end
                continue
            strobes[k] = self.strobes()
            connected[k] = self.connected
            self._clock_di3(int(line[k]))
            k += 1
        rises = np.flatnonzero(np.diff(connected, prepend=connected[:1]) | np.diff(self._lbst, prepend=self._lbst[:1]))
        self._events = sorted({*np.flatnonzero(strobes[:, 0] | strobes[:, 1]).tolist(), *rises.tolist()})

    def next_event(self, t: int) -> int:
        """The first cycle of the run after its cycle ``t`` that the BK must see: a strobe, a change of ``connected``
        or LBST (the run's length if none); the ends of frames, where the silence is judged (BK-50), are the
        receiver's."""
        k = bisect_right(self._events, t)
        event = self._events[k] if k < len(self._events) else len(self._line)
        return max(event, t + 1)

    def record(self, t: int, state: Terminal) -> None:
        """The BK state from the run's cycle ``t`` on is ``state``."""
        opened = _open(state)
        if opened != self._opens[-1][1]:
            self._opens.append((t, opened))

    def render(self, traces: dict[str, npt.NDArray[np.int64]], mfp_in: npt.NDArray[np.int64]) -> None:
        """:meth:`route` over the run begun by :meth:`begin`: ``traces`` the run's outputs (``do2`` the
        transmitter's), ``mfp_in`` its synchronised MFP inputs; the timer catches up to the run's end."""
        n = len(mfp_in)
        if self.counting:
            self.timer += self._c0 + n - self.timer_at
            self.timer_at = self._c0 + n
        starts = [t for t, _ in self._opens]
        opens = np.repeat([o for _, o in self._opens], np.diff([*starts, n]).clip(min=0))
        on = self.present[self._lbst, self._connected] & opens
        sent = traces["do2"]
        live = self.present[self._lbst, 1] & opens
        self.sel3, self.sel2, self.drained, self.tx, di3 = self._initial
        sel3 = np.zeros(n, dtype=bool)
        sel2 = np.zeros(n, dtype=np.int64)
        for a, b in zip([0, *self._restarts], [*self._restarts, n], strict=True):
            if a:
                self.tx.reset()
                di3 = ReturnWatch()
                self.sel3, self.sel2, self.drained = False, _SENT, 0
            running = np.flatnonzero(self._running[a:b])
            first = a + int(running[0]) if running.size else b
            sel3[a:first], sel2[a:first] = self.sel3, self.sel2
            self._select_run(first, b, live, on, sent, di3, sel3, sel2)
        traces["mfp_out"] = traces["mfp_out"] | np.where(sel3, sent, wire.IDLE_LEVEL) << DO3_PIN
        traces["do2"] = np.where(sel2 == _SENT, sent, np.where(sel2 == _DI3, self._line, wire.IDLE_LEVEL))

    def _select_run(self, a: int, b: int, live: npt.NDArray[np.bool_], on: npt.NDArray[np.bool_],
                    sent: npt.NDArray[np.int64], di3: ReturnWatch, sel3: npt.NDArray[np.bool_],
                    sel2: npt.NDArray[np.int64]) -> None:
        """:meth:`_select` at the run's cycles ``a`` to ``b`` (the logic runs), into ``sel3`` and ``sel2``, with
        ``di3`` the return watch as at ``a`` (:attr:`watch`'s twin): only the cycles where a line waits to switch
        are visited."""
        m = b - a
        if m <= 0:
            return
        tx_busy = self.tx.scan(sent[a:b], self.cpb)
        line = self._line[a:b]
        di3_busy = di3.scan(line, self.cpb)
        idle = (line == wire.IDLE_LEVEL) & ~di3_busy
        last = np.maximum.accumulate(np.where(idle, -1, np.arange(m)))  # the last busy or start-level clock
        carry = self.drained

        def drained(j: int) -> int:
            if j == 0:
                return carry
            return min(self.drain, j - 1 - int(last[j - 1]) if last[j - 1] >= 0 else carry + j)

        want3 = live[a:b]
        want2 = np.where(on[a:b], _DI3, _SENT)
        changes = (np.flatnonzero((want3[1:] != want3[:-1]) | (want2[1:] != want2[:-1])) + 1).tolist()
        j = 0
        while j < m:
            if self.sel3 == want3[j] and self.sel2 == want2[j]:
                k = bisect_right(changes, j)
                end = changes[k] if k < len(changes) else m
                sel3[a + j : a + end], sel2[a + j : a + end] = self.sel3, self.sel2
                j = end
                continue
            sel3[a + j], sel2[a + j] = self.sel3, self.sel2
            self._select(bool(want3[j]), bool(want2[j] == _DI3), int(sent[a + j]), int(line[j]), bool(tx_busy[j]),
                         bool(di3_busy[j]), drained(j))
            j += 1
        self.drained = drained(m)


_SENT, _DI3, _IDLE = (int(source) for source in LineSource)


def _open(state: Terminal) -> bool:
    """The BK keeps its branch open: switched on and not closed by itself (:func:`~supi3.terminal.enabled` without
    Table 2-9)."""
    return state.switched_on and not state.closed

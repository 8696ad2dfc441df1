"""The bus terminal module (BK) block in Amaranth: the branch state, CONF edge detection, the command word's branch
control, the silence timer of the extended function, the status byte and the LEDs, with the ports of
:data:`supi3.terminal.BLOCK_INPUTS` / ``BLOCK_OUTPUTS``.

Manual 2.4 (Tables 2-7, 2-8, 2-9, "Extended bus terminal module functions"), 2.2.2, Table 3-19. The transitions of
:mod:`supi3.terminal` (``power_up``, ``conf_level``, ``command``, ``received``, ``silence``, ``reset``, ``enabled`` and
the outputs of ``Terminal``) are re-implemented here in gates (``live`` is ``enabled`` with a device answering), with
every constant taken from the spec at elaboration (the branch control codes, the status byte's bits, the RF codes of
Table 2-9, the silence in clocks). The edge order and the port timing are those of the pin model ``TerminalBlock``
(``src/supi3/model/blocks/terminal.py``, its module docstring, BK-20), which ``tests/test_verif_lockstep_terminal.py``
holds this block to, cycle by cycle.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Final

from amaranth.hdl import Const, Module, Mux, Signal, Value
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from supi3.errors import ArgumentError
from supi3.interbus import wire
from supi3.interbus.wire import BK_STATUS_CLOSED_BIT, BK_STATUS_CONF_BIT, COUNTER_MAX, BranchControl
from supi3.lbd import clocks_per_bit
from supi3.rtl.lfsr import TAPS, before, count_state, count_width, next_state
from supi3.terminal import BLOCK_INPUTS, BLOCK_OUTPUTS, BRANCH_SILENCE_CLOCKS, RF_CODES, TerminalMode, silence_limit

__all__ = ["ReturnWatchRtl", "TerminalRtl"]

_CPB: Final = (clocks_per_bit(0), clocks_per_bit(1))
"""Clocks per bit by the ``fast`` port (Table 1-7)."""


class TerminalRtl(wiring.Component):
    """The bus terminal block (see the module docstring).

    Parameters
    ----------
    time_limit:
        The silence after which the extended function closes the branch, in clocks (BK-3); a test may elaborate a
        shorter one to reach it quickly (1 up to the default; else :class:`~supi3.errors.ArgumentError`).
    """

    def __init__(self, time_limit: int = BRANCH_SILENCE_CLOCKS) -> None:
        try:
            self.time_limit = silence_limit(time_limit)
        except ArgumentError:
            self._MustUse__silence = True  # rejected, never elaborated: no "created but never used" warning
            raise
        super().__init__({
            **{pin.name: In(pin.width) for pin in BLOCK_INPUTS},
            **{pin.name: Out(pin.width) for pin in BLOCK_OUTPUTS},
        })  # fmt: skip

    def _present(self, m: Module, connected: Value) -> Value:
        """Table 2-9 (BK-2, ``branch_present``) with ``connected``: RF = 10 LBST alone, 11 a device answers and
        LBST, 00/01 either."""
        present = Signal()
        with m.Switch(self.rf):
            for code, rf in enumerate(RF_CODES):
                with m.Case(code):
                    if rf == "10":
                        m.d.comb += present.eq(self.lbst)
                    elif rf == "11":
                        m.d.comb += present.eq(connected & self.lbst)
                    else:
                        m.d.comb += present.eq(connected | self.lbst)
        return present

    def elaborate(self, _platform: object) -> Module:
        m = Module()
        sync, comb = m.d.sync, m.d.comb

        # State (Terminal's fields), the power-up flag and the silence timer -------------------------------------
        conf = Signal(reset_less=True)  # read only after the first edge in a BK mode, which sets it (``fresh``)
        switched_on = Signal(init=1)
        extended = Signal()
        closed = Signal()
        closed_report = Signal()
        conf_request = Signal()
        count = Signal(COUNTER_MAX.bit_length())
        alarm = Signal()
        fresh = Signal(init=1)
        # the silence timer counts the clocks since it was restarted as an LFSR (supi3.rtl.lfsr): ``idle`` is its 0,
        # and it is at the state 1 when the silence ends (time_limit - 1 clocks on); ``over`` holds that it was (the
        # timer steps on, no hold); ``heard``: the return line was heard (or not watched) since the last frame's end
        # (model: silence_edge, BK-50). The three are read only while the extended function counts, which starts
        # with ``extended`` at 0 after a reset: set (restarted) on every edge before, so no reset.
        width = max(min(TAPS), self.time_limit.bit_length())
        idle = before(self.time_limit - 1, width)
        timer = Signal(width, reset_less=True)
        over = Signal(reset_less=True)
        heard = Signal(reset_less=True)
        ended = over | (timer == 1)  # the silence has lasted the limit

        # Outputs from the state ---------------------------------------------------------------------------------
        bk = self.mode != TerminalMode.NONE
        opened = switched_on & ~closed
        on = self._present(m, self.connected) & opened
        status = Signal(8)
        comb += status.eq(count | (closed_report << BK_STATUS_CLOSED_BIT) | (conf_request << BK_STATUS_CONF_BIT))
        comb += [
            self.enabled.eq(bk & on),
            self.live.eq(bk & self._present(m, Const(1)) & opened),  # BK-42
            self.status.eq(Mux(bk, status, 0)),
            self.attention.eq(bk & (conf_request | closed_report)),
            self.ld.eq(bk & (closed | ~switched_on)),
            self.e.eq(bk & (closed | (count != 0))),
            self.alarm.eq(bk & alarm),
            self.closed.eq(bk & closed),
        ]

        # The edge -----------------------------------------------------------------------------------------------
        branch_on = self.branch.matches(BranchControl.ON.value, BranchControl.ON_EXTENDED.value)
        cmd_off = self.cmd_valid & (self.branch == BranchControl.OFF.value)
        cmd_on = self.cmd_valid & branch_on
        counting = extended & on
        restart = self.ret_valid | cmd_on
        ends = self.frame_end
        expired = counting & ends & ~heard & ~restart & ended  # BK-50: judged at a frame's end only
        with m.If(bk):
            with m.If(fresh):  # power_up: the CONF level, no edge
                sync += [fresh.eq(0), conf.eq(self.conf)]
            with m.Else():
                sync += conf.eq(self.conf)  # conf_level
                with m.If(self.conf & ~conf):
                    sync += conf_request.eq(1)
                with m.If(self.ib_reset):  # reset: all but the CONF level and the request
                    sync += [switched_on.eq(1), extended.eq(0), closed.eq(0), closed_report.eq(0), count.eq(0),
                             alarm.eq(0)]  # fmt: skip
                with m.Else():
                    with m.If(self.cmd_valid):  # command
                        with m.If(self.alarm_set):
                            sync += alarm.eq(self.alarm_on)
                        with m.If(cmd_off):
                            sync += switched_on.eq(0)
                        with m.If(cmd_on):
                            sync += [switched_on.eq(1), closed.eq(0),
                                     extended.eq(self.branch == BranchControl.ON_EXTENDED.value)]  # fmt: skip
                        with m.If(self.ack):
                            sync += [conf_request.eq(0), closed_report.eq(0)]
                    with m.If(self.cnt_valid):  # received
                        sync += count.eq(self.count)
                    with m.Elif(self.ret_valid):
                        sync += count.eq(0)
                    with m.If(expired & ~cmd_off):  # silence, on the state after the command (watching)
                        sync += [closed.eq(1), closed_report.eq(1)]
            with m.If(~fresh):
                with m.If(self.ib_reset | ~counting | (ends & (heard | expired))):  # the silence (re)starts here
                    sync += [timer.eq(idle), over.eq(0), heard.eq(self.ib_reset | ~counting | restart)]
                with m.Else():
                    sync += [timer.eq(next_state(timer)), over.eq(ended), heard.eq(heard | restart)]
        return m


class ReturnWatchRtl(wiring.Component):
    """The master's telegrams back on the branch return line (BK-38; the pin model's ``ReturnWatch`` in
    ``src/supi3/model/blocks/terminal.py``, whose docstring is the behaviour): ``line`` the synchronised DI3, ``fast``
    the bit rate (a strap: 1 is 2 Mbit/s, ``supi3.lbd.clocks_per_bit``); ``seen`` is 1 in the cycle after a status
    telegram's stop bit was sampled at the idle level; ``busy`` is 1 while a telegram is under way
    (``ReturnWatch.busy``: begun, its stop bit not yet sampled).

    The bit grid's end and mid-bit sample are constants per rate (one compare each); the bit within a telegram
    counts up as an LFSR (:mod:`supi3.rtl.lfsr`: only set to constants, stepped and compared with constants); it,
    the clock within a bit and the telegram's type have no reset and no enable: between telegrams the clock steps on
    and the bit is held at the start bit (round 6), a start restarts the clock, and all three are read only while
    ``busy``, which has a reset.
    """

    def __init__(self) -> None:
        super().__init__({"line": In(1), "fast": In(1), "seen": Out(1), "busy": Out(1)})

    def elaborate(self, _platform: object) -> Module:
        m = Module()
        sync = m.d.sync
        busy = Signal()
        data = Signal(reset_less=True)
        bit_width = count_width(wire.DATA_TELEGRAM_BITS)
        bit = Signal(bit_width, reset_less=True)
        phase = Signal(range(max(_CPB)), reset_less=True)
        seen = Signal()

        def at_rate(test: Callable[[int], Value]) -> Value:
            return Mux(self.fast, test(_CPB[1]), test(_CPB[0]))

        def bit_is(position: int) -> int:
            return count_state(position, bit_width)

        start = ~busy & (self.line == wire.START_LEVEL)
        now = Mux(start, 0, phase)
        sync += seen.eq(0)
        # the clock within a bit steps on between telegrams too, and the bit is set to the start bit there: both are
        # read only in a telegram (a start restarts the clock; its clock is no sample, so the bit is set by then)
        sync += phase.eq(Mux(at_rate(lambda cpb: now == cpb - 1), 0, now + 1))
        with m.If(start):
            sync += busy.eq(1)
        with m.If(~busy):
            sync += bit.eq(bit_is(0))
        with m.Elif(at_rate(lambda cpb: now == cpb >> 1)):
            sync += bit.eq(next_state(bit))
            with m.If(bit == bit_is(wire.POS_START)), m.If(self.line != wire.START_LEVEL):
                sync += busy.eq(0)
            with m.Elif(bit == bit_is(wire.POS_TYPE)):
                sync += data.eq(self.line == wire.TYPE_DATA_LEVEL)
            with m.Elif(bit == Mux(data, bit_is(wire.DATA_TELEGRAM_BITS - 1), bit_is(wire.STATUS_TELEGRAM_BITS - 1))):
                sync += [seen.eq(~data & (self.line == wire.IDLE_LEVEL)), busy.eq(0)]
        m.d.comb += [self.seen.eq(seen), self.busy.eq(busy)]
        return m

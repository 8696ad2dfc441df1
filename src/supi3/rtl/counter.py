"""The counter telegram block in Amaranth: one line direction of a chip in an LBD mode (manual 2.2.2, Table 2-5),
with the ports of :data:`supi3.lbd.COUNTER_INPUTS` / ``COUNTER_OUTPUTS``.

The bit-period transition :func:`supi3.lbd.counter_step` (receiver framing, recognition at the control
bit, the serial increment ``wire.count_bit`` with its saturation mark, the frame flag, the silence count, the
generator and the dropped telegram) is re-implemented here in gates, every constant taken from the spec at
elaboration; the clock timing (the bit grid restarted by a start level, the mid-bit sample
:func:`~supi3.lbd.sample_phase`, and each sample's bit on the line while the model's countdown
:func:`~supi3.lbd.send_countdown` would be 1..cpb, as the core's transmitter, M8) is that of the
pin model ``CounterBlock`` (``src/supi3/model/blocks/counter.py``, its module docstring), which
``tests/test_verif_lockstep_counter.py`` holds this block to, cycle by cycle. :class:`CounterLinesRtl` puts it
into ``Supi3Core`` (docs/rtl.md, "Counter telegram block").
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from itertools import pairwise
from typing import Final

from amaranth.hdl import Array, Cat, Const, Module, Mux, ResetInserter, Signal, Value
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from supi3.checks import check_bool
from supi3.errors import ArgumentError
from supi3.interbus import wire
from supi3.lbd import (
    COUNTER_INPUTS,
    COUNTER_OUTPUTS,
    COUNTER_SILENCE_BITS,
    GENERATED_TELEGRAM,
    IDLE_BIT,
    OUTPUT_SLOTS,
    Kind,
    clocks_per_bit,
    sample_phase,
    send_countdown,
)
from supi3.pinout import SYNC_STAGES
from supi3.rtl.lfsr import TAPS, count_state, count_width, down_state, down_step, next_state
from supi3.terminal import TerminalMode

__all__ = ["CLOCK_BITS", "CounterLinesRtl", "CounterRtl", "LineQueue", "check_watched_modes", "stamp_bits"]

_CPB: Final = (clocks_per_bit(0), clocks_per_bit(1))
_IDLE_VALUE: Final = wire.IDLE_LEVEL
"""A queue value (level in bit 0, drive in bit 1) for an idle line the block does not drive."""
_MARK_SHIFT: Final = wire.COUNT_BITS
_WAITING: Final = OUTPUT_SLOTS - 1
"""Bits sampled but not yet begun on the line: at most all of the queue's entries but the one being sent."""


def _begins(cpb: int) -> int:
    """Clocks from a sample to the first clock of its bit on the line (its countdown reaches ``cpb``, M8)."""
    return send_countdown(cpb) - cpb + 1


def stamp_bits(timing: tuple[tuple[int, int], ...]) -> int:
    """The width of a :class:`LineQueue`'s time stamps for ``timing``: the waiting bits' ages (under the longest
    ``begins``) are distinct modulo ``2 ** stamp_bits``."""
    return max(begins for begins, _ in timing).bit_length()


_TIMING: Final = tuple((_begins(c), c) for c in _CPB)
"""The output queue's (``begins``, ``length``) per bit rate (``fast`` 0, 1)."""
CLOCK_BITS: Final = stamp_bits(_TIMING)
"""The width of the ``now`` port of :class:`CounterRtl` and :class:`CounterLinesRtl` with a shared clock count."""


class LineQueue:
    """The bits on their way to a line, each sent for a bit period a fixed time after it was pushed, as time stamps
    (docs/rtl.md "Counter telegram block"), built in ``m``: a free-running clock count ``now``, the ``waiting``
    bits pushed but not yet begun (``values`` and their push times, newest first, shifted at each push), and the
    bit on the line (``sent``) with the clocks it has ``left``. The oldest waiting bit goes on the line from the
    clock ``begins`` after its push and stays there for ``length`` clocks or until the next one begins; then the
    line shows ``idle``. ``timing[rate]`` is (``begins``, ``length``) for each value of ``rate``. ``now`` may come
    from outside: any count of at least :func:`stamp_bits` bits that steps by one every clock and is reset only
    with the queue (only its differences are read), so that several queues share one.

    ``slots`` waiting bits at most: the caller proves that no more are pushed within the longest ``begins``. The
    time stamps and values need no reset (``waiting`` says which count), nor does ``left``: a reset sets ``sent`` to
    ``idle``, so the line is idle whatever ``left`` holds until the next bit begins and loads both (``left`` steps on
    to 0 and stays there, the LFSR's fixed point). A caller's later assignments to ``values`` win over the push's
    shift (the ERR pair of the transmitter).
    """

    def __init__(self, m: Module, *, push: Value, value: Value, rate: Value, timing: tuple[tuple[int, int], ...],
                 slots: int, idle: int, name: str, now: Value | None = None) -> None:  # fmt: skip
        sync = m.d.sync
        bits = stamp_bits(timing)
        if now is None:
            now = Signal(bits, name=f"{name}_now", reset_less=True)
            sync += now.eq(now + 1)
        elif len(now) < bits:
            raise ValueError(f"now must have at least {bits} bits, not {len(now)}")
        now = now[:bits]
        stamp = [Signal(bits, name=f"{name}{k}_stamp", reset_less=True) for k in range(slots)]
        self.values = [Signal(len(value), name=f"{name}{k}_value", reset_less=True) for k in range(slots)]
        waiting = Signal(range(slots + 1), name=f"{name}_waiting")
        sent = Signal(len(value), name=f"{name}_sent", init=idle)
        # the clocks left count down as an LFSR (lfsr.down_state), 0 when the line is idle
        left_width = max(min(TAPS), max(length for _, length in timing).bit_length())
        left = Signal(left_width, name=f"{name}_left", reset_less=True)

        def by_rate(pick: Callable[[int, int], int]) -> Value:
            result = Value.cast(pick(*timing[0]))
            for k, entry in enumerate(timing[1:], 1):
                result = Mux(rate == k, pick(*entry), result)
            return result

        # the oldest waiting bit (entry ``waiting - 1``, chosen by ``waiting``: one compare, not one per entry)
        # begins on the line in the next cycle (``begins`` clocks after its push)
        due = (now + by_rate(lambda begins, _: (1 - begins) % (1 << bits)))[:bits]
        begin_now = (waiting != 0) & (Array([stamp[0], *stamp])[waiting] == due)
        oldest = Array([self.values[0], *self.values])[waiting]
        with m.If(begin_now):
            sync += [sent.eq(oldest), left.eq(by_rate(lambda _, length: down_state(length, left_width)))]
        with m.Else():
            sync += left.eq(down_step(left))
        sync += waiting.eq(waiting - begin_now)
        with m.If(push):
            sync += [stamp[0].eq(now), self.values[0].eq(value), waiting.eq(waiting + 1 - begin_now),
                     *(stamp[k].eq(stamp[k - 1]) for k in range(1, slots)),
                     *(self.values[k].eq(self.values[k - 1]) for k in range(1, slots))]  # fmt: skip
        self.shown: Value = Mux(left != 0, sent, idle)  # the line: the bit being sent, else ``idle``


def _at_rate(fast: Value, test: Callable[[int], Value]) -> Value:
    """``test`` of the clocks per bit at the ``fast`` input's rate, one gate per rate (a constant compare each)."""
    return Mux(fast, test(_CPB[1]), test(_CPB[0]))


class CounterRtl(wiring.Component):
    """The counter telegram block (ports: :data:`~supi3.lbd.COUNTER_INPUTS` in,
    :data:`~supi3.lbd.COUNTER_OUTPUTS` out; the pin model ``CounterBlock`` defines their timing).
    ``fast`` is a strap: change it only while the line is idle. With ``shared_clock`` the output queue takes its
    clock count from an extra port ``now`` (:data:`CLOCK_BITS` wide, see :class:`LineQueue`) instead of its own.

    With ``watch`` the block can also be a return watch on its line (BK-38, the pin model's ``ReturnWatch``), three
    extra ports: in ``chain``, out ``returned`` and ``busy``. While ``chain`` is 1 the block is the counter block
    above (a stop bit sampled at the start level starts the next telegram on the same grid, M16); while it is 0 such
    a telegram ends there and the next start level restarts the grid, as the watch's (``ReturnWatch`` keeps no M16):
    the block's receiver is then the watch, ``returned`` is 1 in the cycle after a status telegram's stop bit was
    sampled at the idle level and ``busy`` while a telegram is under way (begun, its stop bit not yet sampled).
    ``chain`` is a strap as ``fast``.

    With ``strobed_count`` the ``count`` port is the model's only in the cycle of ``seen`` (as the bus terminal block
    takes it, ``cnt_valid``, BK-39) and undefined in the others: it comes from the received byte, which holds the
    telegram's count byte until the next counter telegram's data bits, or is 0 after a silent input's ``seen``
    (BK-58), without a register of its own (docs/rtl.md, round 6)."""

    def __init__(self, *, shared_clock: bool = False, watch: bool = False, strobed_count: bool = False) -> None:
        try:
            self.shared_clock = check_bool("shared_clock", shared_clock)
            self.watch = check_bool("watch", watch)
            self.strobed_count = check_bool("strobed_count", strobed_count)
        except ArgumentError:
            self._MustUse__silence = True  # rejected, never elaborated: no "created but never used" warning
            raise
        super().__init__({
            **{pin.name: In(pin.width) for pin in COUNTER_INPUTS},
            **{pin.name: Out(pin.width) for pin in COUNTER_OUTPUTS},
            **({"now": In(CLOCK_BITS)} if shared_clock else {}),
            **({"chain": In(1), "returned": Out(1), "busy": Out(1)} if watch else {}),
        })  # fmt: skip

    def elaborate(self, _platform: object) -> Module:
        m = Module()
        sync, comb = m.d.sync, m.d.comb
        line, fast = self.line, self.fast

        # State ---------------------------------------------------------------------------------------------------
        out, drive = Signal(), Signal()  # the bit sampled now on its way out (the output queue below)
        phase = Signal(range(max(_CPB)))
        pending = Signal()
        bit = Signal(range(IDLE_BIT + 1), init=IDLE_BIT)
        # (the telegram's fields are set at its begin before they are read: no reset)
        data = Signal(init=1, reset_less=True)
        kind = Signal(range(len(Kind)), init=Kind.PASS, reset_less=True)
        carry = Signal(reset_less=True)
        frame = Signal()
        # idle bits since the last telegram, up to COUNTER_SILENCE_BITS, counted as an LFSR (lfsr.count_state)
        quiet_width = count_width(COUNTER_SILENCE_BITS)
        quiet = Signal(quiet_width, init=count_state(0, quiet_width))
        quiet_full = quiet == count_state(COUNTER_SILENCE_BITS, quiet_width)
        quiet_start = count_state(0, quiet_width)
        byte = Signal(8, reset_less=True)
        counted = Signal(wire.COUNT_BITS)  # the count kept (unread with ``strobed_count``: synthesis drops it)
        quiet_seen = Signal(reset_less=True)  # the last sample was between telegrams (read with ``seen``: silent input)
        gen = Signal(range(IDLE_BIT + 1), init=IDLE_BIT)
        drop = Signal(reset_less=True)  # read only in a telegram (``~idle_rx``), set at every telegram's begin
        seen = Signal()
        returned = Signal()
        chain = self.chain if self.watch else Const(1)

        # The bit grid and the sample -----------------------------------------------------------------------------
        idle_rx = bit == IDLE_BIT
        restart = idle_rx & ~pending & (line == wire.START_LEVEL)
        ph = Mux(restart, 0, phase)
        sample = _at_rate(fast, lambda c: ph == sample_phase(c))
        sync += phase.eq(Mux(_at_rate(fast, lambda c: ph >= c - 1), 0, ph + 1))
        with m.If(restart):
            sync += pending.eq(1)
        sync += [seen.eq(0), returned.eq(0)]

        # The receiver (counter_step's _receive) ------------------------------------------------------------------
        rx_out, rx_drive, begin, seen_now = Signal(), Signal(), Signal(), Signal()
        last = Mux(data, bit == wire.DATA_TELEGRAM_BITS - 1, bit == wire.STATUS_TELEGRAM_BITS - 1)
        counting = (bit >= wire.COUNT_FIRST_BIT) & (bit < wire.SATURATION_BIT)
        saturating = bit == wire.SATURATION_BIT
        comb += rx_out.eq(line)
        mark = byte[_MARK_SHIFT:]
        saturated = mark == wire.COUNTER_SATURATED_MARK >> _MARK_SHIFT
        valid = saturated | ((mark == wire.COUNTER_MARK >> _MARK_SHIFT) & (byte[:_MARK_SHIFT] != 0))
        received = Mux(saturated, wire.COUNTER_MAX, byte[:_MARK_SHIFT])  # the count of the byte received
        with m.If(sample):
            sync += [pending.eq(0), quiet_seen.eq(idle_rx)]  # a ``seen`` at an idle sample is a silent input's
            with m.If(idle_rx):
                with m.If(line == wire.START_LEVEL):
                    comb += begin.eq(1)
                with m.Else():
                    # no hold at the end: an idle sample with the count full is silent and restarts it below; the
                    # frame flag, cleared when the count fills, can be set again only by a telegram, which restarts it
                    sync += quiet.eq(next_state(quiet))
                    with m.If(quiet == count_state(COUNTER_SILENCE_BITS - 1, quiet_width)):
                        sync += frame.eq(0)
            with m.Else():
                sync += bit.eq(bit + 1)
                with m.If(bit == wire.POS_TYPE):
                    sync += data.eq(line == wire.TYPE_DATA_LEVEL)
                    with m.If(line != wire.TYPE_DATA_LEVEL):
                        sync += kind.eq(Kind.PASS)
                with m.Elif(bit == wire.POS_SELECT):
                    sync += kind.eq(Mux(line == wire.SELECT_ID_LEVEL, kind, Kind.PASS))
                with m.Elif(bit == wire.POS_CONTROL):
                    check = line == wire.CONTROL_CHECK_LEVEL
                    sync += [frame.eq(Mux(data, Mux(check, frame, 1), 0)),
                             kind.eq(Mux((kind == Kind.MAYBE) & check, Kind.COUNT, Kind.PASS))]  # fmt: skip
                with m.Elif(kind == Kind.COUNT):
                    comb += [rx_out.eq(Mux(counting, line ^ carry, Mux(saturating, line | carry, line))),
                             rx_drive.eq(1)]  # fmt: skip
                    sync += carry.eq(Mux(counting, carry & line, Mux(saturating, 0, carry)))
                    with m.If(bit < wire.POS_DATA + 8):
                        sync += byte.eq(Cat(byte[1:], line))
                with m.If(last):
                    stop = line == wire.STOP_LEVEL
                    with m.If(~stop & chain):
                        comb += begin.eq(1)  # M16
                    with m.Else():
                        sync += [bit.eq(IDLE_BIT), drop.eq(0), returned.eq(stop & ~data)]
                        with m.If((kind == Kind.COUNT) & valid & stop):
                            sync += counted.eq(received)
                            comb += seen_now.eq(1)
            with m.If(begin):
                sync += [bit.eq(1), data.eq(1), kind.eq(Mux(frame, Kind.PASS, Kind.MAYBE)), carry.eq(1),
                         quiet.eq(quiet_start), drop.eq((gen != IDLE_BIT) | (drop & ~idle_rx))]  # fmt: skip

            # The generator and what goes out ----------------------------------------------------------------------
            silent = idle_rx & (line == wire.IDLE_LEVEL) & quiet_full
            with m.If((gen != IDLE_BIT) | silent):
                k = Mux(silent, 0, gen)
                comb += [out.eq(Const(GENERATED_TELEGRAM, wire.DATA_TELEGRAM_BITS).bit_select(k, 1)), drive.eq(1)]
                sync += gen.eq(k + 1)  # the stop bit's k + 1 is IDLE_BIT
                with m.If(silent):  # BK-58: count 0, seen
                    sync += [quiet.eq(quiet_start), counted.eq(0)]
                    comb += seen_now.eq(1)
            with m.Elif(drop & ~idle_rx):
                comb += [out.eq(wire.IDLE_LEVEL), drive.eq(1)]
            with m.Else():
                comb += [out.eq(rx_out), drive.eq(rx_drive)]
            sync += seen.eq(seen_now)

        # The output queue and the outputs ------------------------------------------------------------------------
        queue = LineQueue(m, push=sample, value=Cat(out, drive), rate=fast, timing=_TIMING, slots=_WAITING,
                          idle=_IDLE_VALUE, name="tx", now=self.now if self.shared_clock else None)  # fmt: skip
        shown = queue.shown
        comb += [self.out.eq(shown[0]), self.drive.eq(shown[1]), self.seen.eq(seen),
                 self.count.eq(Mux(quiet_seen, 0, received) if self.strobed_count else counted)]  # fmt: skip
        if self.watch:
            comb += [self.returned.eq(returned), self.busy.eq(~idle_rx | pending)]
        return m


class CounterLinesRtl(wiring.Component):
    """The counter blocks in the chip core (docs/rtl.md "Counter telegram block"; the pin model's
    ``LineCounters`` in ``src/supi3/model/blocks/counter.py``): one :class:`CounterRtl` on the forward line in the
    LBD modes (``forward``), one on the return line in LBD-MR (``looped``); in BK-LBD (``branch``) the forward block
    takes the branch return line instead (BK-39, the pin model's ``BranchLines.counter``: a BK has no counter block on
    its forward line, so the two share one block), and it is held in reset in the other modes. Outside LBD-MR the
    return block is the BK's return watch on the branch return line (BK-38, the pin model's ``ReturnWatch``:
    ``CounterRtl(watch=True)`` with ``chain`` 0; no mode is LBD-MR and a BK, :func:`check_watched_modes`).

    Ports: ``line`` the synchronised DO1 (the receiver's), ``fast`` the bit rate (1: 2 Mbit/s), ``sent`` the
    transmitter's DO2, ``source`` the return line's source (M5: DI2 or the chip's DO2), ``run`` and ``clear`` the
    core's enable and power-up reset (they gate both blocks; the return line's ``SYNC_STAGES`` synchroniser always
    runs, M1); out: ``do2`` (the forward block's ``out`` while its ``drive`` is 1, else ``sent``) and ``di1`` (the
    return block's ``out`` in LBD-MR, else ``source``); ``branch_line`` the synchronised DI3, out ``seen`` and
    ``count`` of the forward block, the BK's counter telegram strobe and count in BK-LBD (``cnt_valid``, ``count``;
    ``count`` holds the count only with ``seen``: ``CounterRtl(strobed_count=True)``),
    and ``returned`` the BK's return watch on DI3 outside LBD-MR (``ret_valid``, BK-38), ``branch_busy`` its
    ``busy`` (BK-47; in LBD-MR, where no BK is, both are the return line's); ``now`` the clock count both blocks'
    output queues share (:class:`LineQueue`).
    """

    def __init__(self) -> None:
        super().__init__({
            "line": In(1), "fast": In(1), "sent": In(1), "source": In(1), "forward": In(1), "looped": In(1),
            "run": In(1), "clear": In(1), "do2": Out(1), "di1": Out(1), "branch": In(1), "branch_line": In(1),
            "seen": Out(1), "count": Out(wire.COUNTER_MAX.bit_length()), "returned": Out(1), "branch_busy": Out(1),
            "now": In(CLOCK_BITS),
        })  # fmt: skip

    def elaborate(self, _platform: object) -> Module:
        m = Module()
        forward = CounterRtl(shared_clock=True, strobed_count=True)
        back = CounterRtl(shared_clock=True, watch=True)
        m.submodules.back = ResetInserter(self.clear | ~self.run)(back)
        on = self.forward | self.branch
        m.submodules.forward = ResetInserter(self.clear | ~self.run | ~on)(forward)
        stages = [Signal(init=wire.IDLE_LEVEL, name=f"source_s{k}") for k in range(SYNC_STAGES)]
        m.d.sync += [stages[0].eq(self.source), *(b.eq(a) for a, b in pairwise(stages))]
        m.d.comb += [
            forward.line.eq(Mux(self.branch, self.branch_line, self.line)), forward.fast.eq(self.fast),
            back.line.eq(Mux(self.looped, stages[-1], self.branch_line)), back.fast.eq(self.fast),
            back.chain.eq(self.looped), forward.now.eq(self.now), back.now.eq(self.now),
            self.do2.eq(Mux(forward.drive & self.forward, forward.out, self.sent)),
            self.di1.eq(Mux(self.looped, back.out, self.source)),
            self.seen.eq(forward.seen), self.count.eq(forward.count),
            self.returned.eq(back.returned), self.branch_busy.eq(back.busy),
        ]  # fmt: skip
        return m


def check_watched_modes(lines: Sequence[tuple[bool, bool]], terminals: Sequence[TerminalMode]) -> None:
    """Outside LBD-MR the return block of :class:`CounterLinesRtl` is the BK's return watch (BK-38), so no mode may be
    LBD-MR and a BK (``lines`` and ``terminals`` per mode row: ``CoreTables.lines`` and the bus terminal interface of
    ``CoreTables.diagnostics``); else :class:`ValueError` naming the row."""
    for k, ((_, looped), terminal) in enumerate(zip(lines, terminals, strict=True)):
        if looped and terminal != TerminalMode.NONE:
            raise ValueError(f"mode row {k} is LBD-MR and a bus terminal module ({terminal.name}): the return counter "
                             "block cannot watch its branch return line (BK-38)")  # fmt: skip

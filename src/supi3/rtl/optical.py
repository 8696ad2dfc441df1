"""The optical regulation block in Amaranth: three transmitters, the 6 ms initialization counter, two length timers
and reads 8 to 11, with the ports of :data:`supi3.optical.regulation.BLOCK_INPUTS` / ``BLOCK_OUTPUTS``.

Manual 1.6 (reset behaviour), 1.6.1 (initialization, length timer), 1.6.2 (online regulation, optical
diagnostics), 1.6.3 (MAU warnings), Table 3-17 (FO LEDs), 3.4.12/3.4.13 (reads 8 to 11). The transitions of
:mod:`supi3.optical.regulation` (:func:`~supi3.optical.regulation.start`, ``init_response``, ``init_timeout``,
``online_test``, ``diagnostic_mau``, ``mau_after``, ``fo_lit``, ``registers``) are re-implemented here in gates, one
function each, with every constant taken from the spec at elaboration (levels, steps, the 6 ms budget in clocks,
the length timer's clock divider, the LENGTH code's scale per bit rate and medium, the register layout). The edge
order and the port timing are those of the pin model ``OpticalBlock`` (``src/supi3/model/blocks/optical.py``, its
module docstring, OPT-25), which ``tests/test_verif_lockstep_optical.py`` holds this block to, cycle by cycle.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Final

from amaranth.hdl import Cat, Module, Mux, Signal, Value
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from supi3.optical.length import LENGTH_MAX_CODE, Medium, timer_code
from supi3.optical.regulation import (
    BLOCK_INPUTS,
    BLOCK_OUTPUTS,
    DECREASE_AFTER,
    INIT_MAX_STEPS,
    INIT_TIME_LIMIT_CLOCKS,
    MAX_LEVEL,
    MIN_LEVEL,
    Interface,
    OpticalMode,
    Phase,
    Response,
    length_timer_enable_every,
)
from supi3.regmap.registers import OPTICAL_ENABLE_BIT, OPTICAL_MEDIUM_BIT, POWER_BRANCH_LSB, POWER_OUT_LSB
from supi3.tables import BIT_RATES

__all__ = ["LENGTH_COUNT_BITS", "PHASES", "OpticalRtl", "length_shift"]

LENGTH_COUNT_BITS: Final = 14
"""Width of a length timer, saturating (the pin model's ``LENGTH_COUNT_BITS``; OPT-24)."""
PHASES: Final[tuple[Phase, ...]] = tuple(Phase)
"""The encoding of a transmitter's phase register: the index in this tuple."""
_BYTE: Final = 8
_OUT_K, _BRANCH_K = Interface.OUT - 1, Interface.BRANCH - 1  # index in the measured paths (OpticalStatus.length)


@functools.cache
def length_shift(bit_rate: int, medium: Medium) -> int:
    """The LENGTH code of a timer count ``n`` as a shift: ``timer_code(n) == min(63, n << s)`` (``n >> -s`` for a
    negative ``s``) for every count the timer holds; found and checked from the spec (OPT-1, OPT-24).

    Raises
    ------
    ValueError
        If no shift gives :func:`~supi3.optical.length.timer_code` at this bit rate and medium.
    """
    for shift in range(-LENGTH_COUNT_BITS, LENGTH_COUNT_BITS):
        if all(timer_code(n, bit_rate, medium) == min(LENGTH_MAX_CODE, _shifted(n, shift))
               for n in range(1 << LENGTH_COUNT_BITS)):  # fmt: skip
            return shift
    raise ValueError(f"timer_code at {bit_rate} bit/s, {medium.name} must be a shifted count for the RTL")


def _shifted(n: int, shift: int) -> int:
    return n << shift if shift >= 0 else n >> -shift


def _phase(phase: Phase) -> int:
    return PHASES.index(phase)


@dataclass(frozen=True)
class _Tx:
    """One transmitter's state (:class:`supi3.optical.regulation.Transmitter`) as values."""

    phase: Value | int
    level: Value | int = MAX_LEVEL
    steps: Value | int = 0
    passes: Value | int = 0
    mau: Value | int = 0

    def parts(self) -> tuple[Value | int, ...]:
        return (self.phase, self.level, self.steps, self.passes, self.mau)

    def where(self, cond: Value, other: _Tx) -> _Tx:
        """``other`` where ``cond``, else this."""
        return _Tx(*(Mux(cond, b, a) for a, b in zip(self.parts(), other.parts(), strict=True)))

    def with_(self, **parts: Value | int) -> _Tx:
        values = dict(zip(("phase", "level", "steps", "passes", "mau"), self.parts(), strict=True)) | parts
        return _Tx(**values)

    def is_(self, phase: Phase) -> Value:
        return Value.cast(self.phase) == _phase(phase)


def _off() -> _Tx:
    """:class:`~supi3.optical.regulation.Transmitter` ``()``: off at maximum power."""
    return _Tx(_phase(Phase.OFF))


def _up(level: Value | int) -> Value:
    """One level up, at most :data:`MAX_LEVEL`."""
    level = Value.cast(level)
    return Mux(level == MAX_LEVEL, MAX_LEVEL, level + 1)


def _mau_after(mau: Value | int, old: Value | int, new: Value) -> Value:
    """:func:`~supi3.optical.regulation.mau_after`: on at MAX-1 -> MAX, off at MAX-1 -> MAX-2 (1.6.3)."""
    from_below = Value.cast(old) == MAX_LEVEL - 1
    return Mux(from_below & (new == MAX_LEVEL), 1, Mux(from_below & (new == MAX_LEVEL - 2), 0, mau))


def _start(mode: Value, present: Value) -> _Tx:
    """:func:`~supi3.optical.regulation.start` (1.6.1, OPT-2); a mode code of 3 is off (OPT-23)."""
    phase = Mux(mode == OpticalMode.REGULATION, _phase(Phase.INIT),
                Mux(mode == OpticalMode.DIAGNOSTIC, _phase(Phase.DIAGNOSTIC), _phase(Phase.OFF)))  # fmt: skip
    return _Tx(Mux(present, phase, _phase(Phase.OFF)))


def _init_response(tx: _Tx, valid: Value, resp: Value) -> _Tx:
    """:func:`~supi3.optical.regulation.init_response` on a strobe; a ``resp`` of 3 is no response (OPT-23)."""
    level = Value.cast(tx.level)
    steps = Value.cast(tx.steps) + 1
    last = steps == INIT_MAX_STEPS
    lowered = _Tx(Mux(last, _phase(Phase.ONLINE), _phase(Phase.INIT)), level - 1, Mux(last, 0, steps))
    raised = _up(level)
    light_on = _Tx(_phase(Phase.ONLINE), raised, mau=(level == MAX_LEVEL) | _mau_after(0, level, raised))
    fixed = _Tx(_phase(Phase.FIXED))
    result = fixed.where(resp == Response.DETECTED, lowered).where(resp == Response.NOT_DETECTED, light_on)
    known = (resp == Response.NONE) | (resp == Response.DETECTED) | (resp == Response.NOT_DETECTED)
    return tx.where(valid & known & tx.is_(Phase.INIT), result)


def _online_test(tx: _Tx, valid: Value, ack1: Value, ack2: Value) -> _Tx:
    """:func:`~supi3.optical.regulation.online_test` of an online transmitter, or
    :func:`~supi3.optical.regulation.diagnostic_mau` of one in diagnostics mode, on a strobe (OPT-22)."""
    level, passes, mau = Value.cast(tx.level), Value.cast(tx.passes), Value.cast(tx.mau)
    raised = _up(level)
    lowered = Mux(level == MIN_LEVEL, MIN_LEVEL, level - 1)
    failed = tx.with_(level=raised, passes=0, mau=mau | (level == MAX_LEVEL) | _mau_after(mau, level, raised))
    counted = tx.with_(passes=passes + 1)
    lower = tx.with_(level=lowered, passes=0, mau=_mau_after(mau, level, lowered))
    passed = counted.where(passes + 1 >= DECREASE_AFTER, lower)
    online = failed.where(ack1, tx.with_(passes=0).where(ack2, passed))
    diagnostic = tx.with_(mau=Mux(~ack1, 1, Mux(ack2, 0, mau)))
    return tx.where(valid & tx.is_(Phase.ONLINE), online).where(valid & tx.is_(Phase.DIAGNOSTIC), diagnostic)


def _init_timeout(tx: _Tx, due: Value) -> _Tx:
    """:func:`~supi3.optical.regulation.init_timeout` when ``due`` (OPT-5)."""
    return tx.where(due & tx.is_(Phase.INIT), _Tx(_phase(Phase.FIXED)))


class OpticalRtl(wiring.Component):
    """The optical block (ports: :data:`~supi3.optical.regulation.BLOCK_INPUTS` in,
    :data:`~supi3.optical.regulation.BLOCK_OUTPUTS` out; the module docstring of the pin model ``OpticalBlock``
    defines their timing). ``mode``, ``fast``, ``present`` and ``medium`` are
    static while out of reset (straps and the interface recognition)."""

    def __init__(self, time_limit: int = INIT_TIME_LIMIT_CLOCKS) -> None:
        self.time_limit = time_limit
        """The initialization budget in clocks (OPT-5); a test may elaborate a shorter one to reach it quickly."""
        super().__init__({
            **{pin.name: In(pin.width) for pin in BLOCK_INPUTS},
            **{pin.name: Out(pin.width) for pin in BLOCK_OUTPUTS},
        })  # fmt: skip

    def elaborate(self, _platform: object) -> Module:
        m = Module()
        sync, comb = m.d.sync, m.d.comb

        # State ---------------------------------------------------------------------------------------------------
        phase = [Signal(range(len(PHASES)), name=f"phase_{i.name}", init=_phase(Phase.OFF)) for i in Interface]
        level = [Signal(range(MAX_LEVEL + 1), name=f"level_{i.name}", init=MAX_LEVEL) for i in Interface]
        steps = [Signal(range(INIT_MAX_STEPS + 1), name=f"steps_{i.name}") for i in Interface]
        passes = [Signal(range(max(DECREASE_AFTER, 2)), name=f"passes_{i.name}") for i in Interface]
        mau = [Signal(name=f"mau_{i.name}") for i in Interface]
        state = [_Tx(phase[i], level[i], steps[i], passes[i], mau[i]) for i in Interface]
        length = [Signal(LENGTH_MAX_CODE.bit_length(), name=f"length_{k}") for k in range(2)]
        medium = [Signal(name=f"medium_{k}") for k in range(2)]
        in_reset = Signal()
        countdown = Signal(range(self.time_limit + 1))

        def assign(i: int, tx: _Tx) -> None:
            for target, value in zip((phase[i], level[i], steps[i], passes[i], mau[i]), tx.parts(), strict=True):
                m.d.sync += target.eq(value)

        # Outputs from the state ---------------------------------------------------------------------------------
        def power(i: Interface) -> Value:
            return Mux(state[i].is_(Phase.OFF), 0, level[i])

        def enable(i: Interface) -> Value:
            return state[i].is_(Phase.ONLINE)

        def path(k: int, i: Interface) -> Value:
            return length[k] | (medium[k] << OPTICAL_MEDIUM_BIT) | (enable(i) << OPTICAL_ENABLE_BIT)

        reads = [
            path(_OUT_K, Interface.OUT),
            path(_BRANCH_K, Interface.BRANCH),
            power(Interface.IN) | (enable(Interface.IN) << OPTICAL_ENABLE_BIT),
            (power(Interface.OUT) << POWER_OUT_LSB) | (power(Interface.BRANCH) << POWER_BRANCH_LSB),
        ]
        shown = Signal(len(self.optical))
        comb += self.optical.eq(Cat(*(read.as_unsigned()[:_BYTE] for read in reads)))
        sync += shown.eq(self.optical)
        comb += self.optical_we.eq(Cat(*(self.optical.word_select(k, _BYTE) != shown.word_select(k, _BYTE)
                                         for k in range(len(reads)))))  # fmt: skip
        comb += [
            self.mau.eq(Cat(*mau)),
            self.fo.eq(Cat(*(Mux(self.run, mau[i], state[i].is_(Phase.FIXED)) for i in Interface))),
            self.hold.eq(Cat(*(state[i].is_(Phase.INIT) for i in Interface)).any()),
        ]

        # The edge: reset, start, or strobes and the 6 ms counter -----------------------------------------------
        timeout = countdown == 1
        with m.If(self.ib_reset):
            sync += [in_reset.eq(1), countdown.eq(0)]
            for i in Interface:
                assign(i, _off())
        with m.Elif(in_reset):
            sync += [in_reset.eq(0), countdown.eq(self.time_limit)]
            for i in Interface:
                assign(i, _start(self.mode, self.present[i]))
        with m.Else():
            with m.If(countdown != 0):
                sync += countdown.eq(countdown - 1)
            for i in Interface:
                tx = _init_response(state[i], self.resp_valid[i], self.resp.word_select(i, 2))
                tx = _online_test(tx, self.test_valid[i], self.ack1[i], self.ack2[i])
                assign(i, _init_timeout(tx, timeout))

        # Length timers of the outgoing interface and the branch ----------------------------------------------
        everies = [length_timer_enable_every(rate) for rate in BIT_RATES]
        every = Mux(self.fast, everies[1], everies[0])
        block_on = (self.mode == OpticalMode.REGULATION) | (self.mode == OpticalMode.DIAGNOSTIC)
        saturated = (1 << LENGTH_COUNT_BITS) - 1
        for k, i in ((_OUT_K, Interface.OUT), (_BRANCH_K, Interface.BRANCH)):
            running = Signal(name=f"timer_running_{k}")
            prescale = Signal(range(max(everies)), name=f"timer_prescale_{k}")
            counter = Signal(LENGTH_COUNT_BITS, name=f"timer_count_{k}")
            tick = prescale + 1 == every
            counted = Mux(tick & (counter != saturated), counter + 1, counter)
            codes = {
                (fast, medium_bit): self._code(counted, length_shift(rate, Medium(medium_bit)))
                for fast, rate in enumerate(BIT_RATES) for medium_bit in (0, 1)
            }  # fmt: skip
            code = Signal(len(length[k]), name=f"timer_code_{k}")
            with m.Switch(Cat(self.medium[i], self.fast)):
                for (fast, medium_bit), value in codes.items():
                    with m.Case(medium_bit | fast << 1):
                        comb += code.eq(value)
            with m.If(self.ib_reset):
                sync += running.eq(0)
            with m.Else():
                with m.If(running):
                    sync += [prescale.eq(Mux(tick, 0, prescale + 1)), counter.eq(counted)]
                    with m.If(self.len_stop[i]):
                        sync += running.eq(0)
                        with m.If(block_on):
                            sync += [length[k].eq(code), medium[k].eq(self.medium[i])]
                with m.If(self.len_start[i]):
                    sync += [running.eq(1), prescale.eq(0), counter.eq(0)]
        return m

    @staticmethod
    def _code(counter: Value, shift: int) -> Value:
        """``min(63, counter << shift)`` (``>>`` for a negative shift)."""
        scaled = counter << shift if shift >= 0 else counter >> -shift
        return Mux(scaled > LENGTH_MAX_CODE, LENGTH_MAX_CODE, scaled)


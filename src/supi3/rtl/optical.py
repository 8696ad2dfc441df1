"""The optical regulation block in Amaranth: three transmitters, the 6 ms initialization counter, one length timer
for the outgoing interface or the branch (OPT-57) and reads 8 to 11, with the ports of
:data:`supi3.optical.regulation.BLOCK_INPUTS` / ``BLOCK_OUTPUTS``.

Manual 1.6 (reset behaviour), 1.6.1 (initialization, length timer), 1.6.2 (online regulation, optical
diagnostics), 1.6.3 (MAU warnings), Table 3-17 (FO LEDs), 3.4.12/3.4.13 (reads 8 to 11). The transitions of
:mod:`supi3.optical.regulation` (:func:`~supi3.optical.regulation.start`, ``init_response``, ``init_timeout``,
``online_test``, ``diagnostic_mau``, ``mau_after``, ``fo_lit``, ``registers``) are re-implemented here as
``If``/``Switch`` statements on each register's value after the edge (``_transitions``; no nested ``Mux`` chains,
which made the core's Verilog twice as long), with every constant taken from the spec at elaboration (levels,
steps, the 6 ms budget in clocks, the length timer's clock divider, the LENGTH code's scale per bit rate and medium,
the register layout). The edge
order and the port timing are those of the pin model ``OpticalBlock`` (``src/supi3/model/blocks/optical.py``, its
module docstring, OPT-25), which ``tests/test_verif_lockstep_optical.py`` holds this block to, cycle by cycle.
"""

from __future__ import annotations

import functools
import itertools
from dataclasses import dataclass
from typing import Final

from amaranth.hdl import Cat, Const, Module, Mux, Signal, Value
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from supi3.optical.length import LENGTH_MAX_CODE, Medium, timer_code
from supi3.optical.regulation import (
    BLOCK_INPUTS,
    BLOCK_OUTPUTS,
    DECREASE_AFTER,
    INIT_MAX_STEPS,
    INIT_ORDER,
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
from supi3.rtl.lfsr import Countdown
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


@functools.cache
def _decode_bits(code: int) -> tuple[int, ...]:
    """The fewest bits of the phase register whose values tell ``code`` from every other phase's code."""
    width = (len(PHASES) - 1).bit_length()
    others = [c for c in range(len(PHASES)) if c != code]
    return next(bits for size in range(width + 1) for bits in itertools.combinations(range(width), size)
                if all(any((code ^ other) >> b & 1 for b in bits) for other in others))  # fmt: skip


@functools.cache
def _clock_bits() -> int:
    """The narrowest count of clocks whose largest value already reads as :data:`~supi3.optical.length.LENGTH_MAX_CODE`
    at every bit rate and medium (its count is the clocks shifted right by :func:`_prescale_bits`): a timer of that
    many bits that wraps and keeps a flag for having wrapped, read as all ones from then on, gives every LENGTH code of
    the model's saturating :data:`LENGTH_COUNT_BITS`-bit count (OPT-24)."""
    reads = [(_prescale_bits(rate), length_shift(rate, medium)) for rate in BIT_RATES for medium in Medium]
    return next(bits for bits in range(1, LENGTH_COUNT_BITS + 1)
                if all(_shifted((1 << bits) - 1 >> p, s) >= LENGTH_MAX_CODE for p, s in reads))  # fmt: skip


def _prescale_bits(bit_rate: int) -> int:
    """log2 of :func:`~supi3.optical.regulation.length_timer_enable_every`: the timer counts one every that many
    clocks, so its count is the clocks since the start shifted right by this.

    Raises
    ------
    ValueError
        If the enable period is not a power of two.
    """
    every = length_timer_enable_every(bit_rate)
    if every & (every - 1):
        raise ValueError(f"the length timer's enable period must be a power of two for the RTL, not {every}")
    return every.bit_length() - 1


@dataclass(frozen=True)
class _Tx:
    """One transmitter's state (:class:`supi3.optical.regulation.Transmitter`) as signals. ``steps`` is not kept:
    an initializing transmitter has lowered its level once per step, so it is ``MAX_LEVEL - level``."""

    phase: Signal
    level: Signal
    passes: Signal
    mau: Signal

    @staticmethod
    def signals(name: str, registers: _Tx | None = None) -> _Tx:
        """Signals of one transmitter (``registers``: the state registers whose width and reset they take)."""
        if registers is None:
            return _Tx(Signal(range(len(PHASES)), name=f"phase_{name}", init=_phase(Phase.OFF)),
                       Signal(range(MAX_LEVEL + 1), name=f"level_{name}", init=MAX_LEVEL),
                       Signal(range(max(DECREASE_AFTER, 2)), name=f"passes_{name}"),
                       Signal(name=f"mau_{name}"))  # fmt: skip
        return _Tx(*(Signal.like(r, name=f"{r.name}_{name}") for r in registers.parts()))

    def parts(self) -> tuple[Signal, Signal, Signal, Signal]:
        return (self.phase, self.level, self.passes, self.mau)

    def eq(self, other: _Tx) -> list[Value]:
        return [a.eq(b) for a, b in zip(self.parts(), other.parts(), strict=True)]

    def set(self, phase: Phase | Value, level: Value | int = MAX_LEVEL, mau: Value | int = 0) -> list[Value]:
        """A transmitter of ``phase`` at ``level`` with ``mau``, no passes (every transition but a test's)."""
        code = _phase(phase) if isinstance(phase, Phase) else phase
        return [self.phase.eq(code), self.level.eq(level), self.passes.eq(0), self.mau.eq(mau)]

    def is_(self, phase: Phase) -> Value:
        """The phase register holds ``phase``: a compare of only the bits that tell its code from the other codes
        (:func:`_decode_bits`; the register holds no other value)."""
        code = _phase(phase)
        return Cat(*(self.phase[b] == (code >> b & 1) for b in _decode_bits(code))).all()


def _start(mode: Value, present: Value) -> Value:
    """:func:`~supi3.optical.regulation.start`'s phase (1.6.1, OPT-2); a mode code of 3 is off (OPT-23)."""
    phase = Mux(mode == OpticalMode.REGULATION, _phase(Phase.INIT),
                Mux(mode == OpticalMode.DIAGNOSTIC, _phase(Phase.DIAGNOSTIC), _phase(Phase.OFF)))  # fmt: skip
    return Mux(present, phase, _phase(Phase.OFF))


def _moved(level: Value, up: Value) -> Value:
    """``level`` one step up (``up``) or down, held at :data:`~supi3.optical.regulation.MAX_LEVEL` and
    :data:`~supi3.optical.regulation.MIN_LEVEL`: one adder of +1 or -1 (all ones) for both directions."""
    step = Mux(up, 1, (1 << len(level)) - 1)
    held = Mux(up, level == MAX_LEVEL, level == MIN_LEVEL)
    return Mux(held, level, (level + step)[: len(level)])


def _transitions(m: Module, tx: _Tx, new: _Tx, strobes: tuple[Value, Value, Value, Value, Value],
                 timeout: Value) -> None:
    """``new`` = ``tx`` after this edge's strobes (``resp_valid``, ``resp``, ``test_valid``, ``ack1``, ``ack2`` of
    the transmitter) in the order of the pin model: a response (3 is none, OPT-23) by
    :func:`~supi3.optical.regulation.init_response`, a test by :func:`~supi3.optical.regulation.apply_test`
    (OPT-22), then :func:`~supi3.optical.regulation.init_timeout` when ``timeout``. The MAU hysteresis
    :func:`~supi3.optical.regulation.mau_after` (1.6.3) is written out where the level moves by one."""
    comb = m.d.comb
    resp_valid, resp, test_valid, ack1, ack2 = strobes
    mid = _Tx.signals("mid", tx)
    comb += mid.eq(tx)
    # an initializing transmitter's level is above MIN_LEVEL (INIT_MAX_STEPS steps down from MAX_LEVEL at most)
    resp_moved = _moved(tx.level, resp == Response.NOT_DETECTED)
    with m.If(resp_valid & tx.is_(Phase.INIT)), m.Switch(resp):
        with m.Case(Response.NONE):
            comb += mid.set(Phase.FIXED)
        with m.Case(Response.NOT_DETECTED):  # one up; MAU at MAX itself or reaching it from MAX - 1
            comb += mid.set(Phase.ONLINE, resp_moved, tx.level >= MAX_LEVEL - 1)
        with m.Case(Response.DETECTED):  # one down; online after the last of INIT_MAX_STEPS steps
            comb += mid.level.eq(resp_moved)
            with m.If(tx.level == MAX_LEVEL - INIT_MAX_STEPS + 1):
                comb += mid.phase.eq(_phase(Phase.ONLINE))
    comb += new.eq(mid)
    test_moved = _moved(mid.level, ~ack1)
    with m.If(test_valid & mid.is_(Phase.ONLINE)):
        with m.If(~ack1):  # failed: one up, MAU at MAX or reaching it
            comb += [new.level.eq(test_moved), new.passes.eq(0),
                     new.mau.eq(mid.mau | (mid.level >= MAX_LEVEL - 1))]  # fmt: skip
        with m.Elif(~ack2):
            comb += new.passes.eq(0)
        with m.Elif(mid.passes + 1 < DECREASE_AFTER):
            comb += new.passes.eq(mid.passes + 1)
        with m.Else():  # passed DECREASE_AFTER times: one down, MAU off leaving MAX - 1
            comb += [new.level.eq(test_moved), new.passes.eq(0),
                     new.mau.eq(mid.mau & (mid.level != MAX_LEVEL - 1))]  # fmt: skip
    with m.Elif(test_valid & mid.is_(Phase.DIAGNOSTIC)):  # diagnostic_mau
        comb += new.mau.eq(~ack1 | (~ack2 & mid.mau))
    with m.If(timeout & mid.is_(Phase.INIT)):
        comb += new.set(Phase.FIXED)


def _initializing(txs: list[_Tx]) -> Value:
    """:func:`~supi3.optical.regulation.initializing` one-hot (bit i = Interface i): the first of
    :data:`~supi3.optical.regulation.INIT_ORDER` initializing (OPT-56)."""
    bits: dict[Interface, Value] = {}
    earlier: Value = Const(0)
    for i in INIT_ORDER:
        bits[i] = txs[i].is_(Phase.INIT) & ~earlier
        earlier = earlier | txs[i].is_(Phase.INIT)
    return Cat(*(bits[i] for i in Interface))


def _reads(txs: list[_Tx], length: list[Signal], medium: list[Signal]) -> Value:
    """Reads 8..11 (:func:`~supi3.optical.regulation.registers`, 3.4.12, 3.4.13) of the transmitters ``txs`` and
    the measured paths' ``length`` and ``medium``, byte k = read 8 + k."""

    def power(tx: _Tx) -> Value:
        return Mux(tx.is_(Phase.OFF), 0, tx.level)

    def path(k: int, tx: _Tx) -> Value:
        return length[k] | (medium[k] << OPTICAL_MEDIUM_BIT) | (tx.is_(Phase.ONLINE) << OPTICAL_ENABLE_BIT)

    tx_in, tx_out, tx_branch = (txs[i] for i in Interface)
    reads = [
        path(_OUT_K, tx_out),
        path(_BRANCH_K, tx_branch),
        power(tx_in) | (tx_in.is_(Phase.ONLINE) << OPTICAL_ENABLE_BIT),
        (power(tx_out) << POWER_OUT_LSB) | (power(tx_branch) << POWER_BRANCH_LSB),
    ]
    return Cat(*(read.as_unsigned()[:_BYTE] for read in reads))


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

        # State (and each register's value after this edge, ``new``) ---------------------------------------------
        state = [_Tx.signals(i.name) for i in Interface]
        new = [_Tx.signals("next", tx) for tx in state]
        length = [Signal(LENGTH_MAX_CODE.bit_length(), name=f"length_{k}") for k in range(2)]
        medium = [Signal(name=f"medium_{k}") for k in range(2)]
        new_length = [Signal.like(r, name=f"{r.name}_next") for r in length]
        new_medium = [Signal.like(r, name=f"{r.name}_next") for r in medium]
        in_reset = Signal()
        changed = Signal(len(self.optical_we))
        for tx, after in zip(state, new, strict=True):
            sync += tx.eq(after)
        sync += [*(r.eq(n) for r, n in zip([*length, *medium], [*new_length, *new_medium], strict=True))]
        comb += [*(n.eq(r) for r, n in zip([*length, *medium], [*new_length, *new_medium], strict=True))]

        # Outputs from the state: reads 8..11, and a byte written while it differs from the cycle before ----------
        shown = _reads(state, length, medium)
        comb += [
            self.optical.eq(shown),
            self.optical_we.eq(changed),
            self.mau.eq(Cat(*(tx.mau for tx in state))),
            self.fo.eq(Cat(*(Mux(self.run, tx.mau, tx.is_(Phase.FIXED)) for tx in state))),
            self.hold.eq(Cat(*(tx.is_(Phase.INIT) for tx in state)).any()),
        ]
        after = _reads(new, new_length, new_medium)
        sync += changed.eq(Cat(*(after.word_select(k, _BYTE) != shown.word_select(k, _BYTE)
                                 for k in range(len(changed)))))  # fmt: skip

        # The edge: strobes and the 6 ms counter, unless a reset or the start --------------------------------------
        # (the 6 ms counter: loaded with the budget at the start and when the interface initializing is done, so the
        # next in INIT_ORDER has its own; zero in reset, ``last`` one clock before it ends; it ends the budget of the
        # one initializing only: OPT-56)
        current = _initializing(state)
        done = (current & ~Cat(*(tx.is_(Phase.INIT) for tx in new))).any()
        countdown = Countdown(m, self.time_limit, load=in_reset | done, clear=self.ib_reset, name="countdown")
        for i in Interface:
            strobes = (self.resp_valid[i], self.resp.word_select(i, 2), self.test_valid[i], self.ack1[i], self.ack2[i])
            _transitions(m, state[i], new[i], strobes, countdown.last & current[i])
        with m.If(self.ib_reset):
            sync += in_reset.eq(1)
            for i in Interface:
                comb += new[i].set(Phase.OFF)
        with m.Elif(in_reset):
            sync += in_reset.eq(0)
            for i in Interface:
                comb += new[i].set(_start(self.mode, self.present[i]))

        # The length timer of the outgoing interface or the branch (OPT-57): the clocks since the start, of which the
        # count is the clocks shifted right by log2 of the bit rate's enable period (OPT-24)
        prescale = [_prescale_bits(rate) for rate in BIT_RATES]
        block_on = (self.mode == OpticalMode.REGULATION) | (self.mode == OpticalMode.DIAGNOSTIC)
        running = Signal(name="timer_running")
        # the path it measures (index into MEASURED, set at each start: read only while running, so without reset);
        # the outgoing interface's start wins over the branch's at one edge
        path = Signal(name="timer_path", reset_less=True)
        paths = (Interface.OUT, Interface.BRANCH)  # in the order of the lengths (_OUT_K, _BRANCH_K)
        stop = Mux(path, self.len_stop[Interface.BRANCH], self.len_stop[Interface.OUT])
        path_medium = Mux(path, self.medium[Interface.BRANCH], self.medium[Interface.OUT])
        # the clocks since the start modulo 2 ** _clock_bits() and whether that many have passed (then read as all
        # ones, code 63): both cleared at each start, so without reset; no saturating multiplexer on the count
        clocks = Signal(_clock_bits(), name="timer_clocks", reset_less=True)
        over = Signal(name="timer_over", reset_less=True)
        counted = (clocks + 1)[: len(clocks)]
        counted_over = over | clocks.all()
        read = Mux(counted_over, (1 << len(clocks)) - 1, counted)
        code = Signal(LENGTH_MAX_CODE.bit_length(), name="timer_code")
        with m.Switch(Cat(path_medium, self.fast)):
            for fast, rate in enumerate(BIT_RATES):
                for medium_bit in (0, 1):
                    with m.Case(medium_bit | fast << 1):
                        shift = length_shift(rate, Medium(medium_bit))
                        comb += code.eq(self._code(read, prescale[fast], shift))
        with m.If(self.ib_reset):
            sync += running.eq(0)
        with m.Else():
            with m.If(running):
                sync += [clocks.eq(counted), over.eq(counted_over)]
                with m.If(stop):
                    sync += running.eq(0)
                    with m.If(block_on):
                        for k in range(len(paths)):
                            with m.If(path == k):
                                comb += [new_length[k].eq(code), new_medium[k].eq(path_medium)]
            with m.If(Cat(*(self.len_start[i] for i in paths)).any()):
                sync += [running.eq(1), path.eq(~self.len_start[Interface.OUT]), clocks.eq(0), over.eq(0)]
        return m

    @staticmethod
    def _code(clocks: Value, prescale: int, shift: int) -> Value:
        """``min(63, (clocks >> prescale) << shift)`` (``>>`` for a negative shift) as ``clocks`` shifted right by
        ``prescale - shift`` with its low ``shift`` bits cleared: the saturation compare depends only on the net
        shift, so the rates and media with the same one share it (and synthesis merges their identical cells)."""
        net = prescale - shift
        scaled = clocks >> net if net >= 0 else clocks << -net
        cleared = (1 << LENGTH_MAX_CODE.bit_length()) - (1 << max(shift, 0))  # the bits the prescale shifted out
        return Mux(scaled > LENGTH_MAX_CODE, LENGTH_MAX_CODE, scaled[: LENGTH_MAX_CODE.bit_length()] & cleared)

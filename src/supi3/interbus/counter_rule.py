"""The counter telegram's rule per bit period (device-oriented local-bus diagnostics, manual 2.2.2; BK-30 to BK-33 of
``docs/assumptions/bus-terminal.md``): :func:`counter_step`, the pure transition a chip in an LBD mode applies once per
line direction, and the clock timing around it (:func:`sample_phase`, :func:`send_countdown`).

:mod:`supi3.lbd` is its public face (the pin block :mod:`supi3.model.blocks.counter` and the RTL
:mod:`supi3.rtl.counter` take it from there, with the pins); it lives in the bus package so that the transaction
level's wake-up window (:mod:`supi3.interbus.wake`, M26) runs the same rule over a line without an import cycle
(``supi3.lbd`` imports :mod:`supi3.interbus.wire`).
"""

from __future__ import annotations

from enum import IntEnum
from typing import Final, NamedTuple, NoReturn

from supi3.checks import fail
from supi3.interbus import wire
from supi3.interbus.errors import InterbusArgumentError
from supi3.pinlevel import SYNC_STAGES
from supi3.tables import BIT_RATES

# BK-30 A line that stays at the idle level for this many bit periods is silent: the frame is forgotten and the next
# idle bit period starts a generated counter telegram (and so on, one every COUNTER_SILENCE_BITS + 1 bit periods). More
# than twice the longest idle-level run of working traffic (12, tested), far below the BK's 10 ms branch silence
# (BK-3) and the 20 ms idle time-out (A13); a power of two.
COUNTER_SILENCE_BITS: Final = 32

IDLE_BIT: Final = wire.DATA_TELEGRAM_BITS
""":attr:`CounterState.bit` between telegrams."""
GENERATED_TELEGRAM: Final = wire.count_on(None)
"""The counter telegram a block sends behind a silent line: count 1."""


class Kind(IntEnum):
    """What the block does with the telegram it is receiving (:attr:`CounterState.kind`)."""

    PASS = 0
    """Repeat it as received: no counter telegram."""
    MAYBE = 1
    """Repeat it; the header so far (bits 0..2) is a counter telegram's and no frame is open."""
    COUNT = 2
    """A counter telegram: increment it (bits 4..10) and keep its count."""


class CounterState(NamedTuple):
    """The block's state between two bit periods (all plain ints, as the RTL's registers)."""

    bit: int = IDLE_BIT
    """The bit period of the current telegram sampled next (0..12), :data:`IDLE_BIT` between telegrams."""
    data: int = 1
    """The current telegram is a data telegram (13 bit periods; known from its type bit)."""
    kind: Kind = Kind.PASS
    """What the current telegram is."""
    carry: int = 0
    """The increment's carry into the next bit period (``wire.count_bit``)."""
    frame: int = 0
    """A frame is open: the last data telegram was in a data sequence or a check sequence, and no status telegram
    or silence came since."""
    quiet: int = 0
    """Idle bit periods since the last telegram (0..:data:`COUNTER_SILENCE_BITS`)."""
    byte: int = 0
    """The data bits received so far of the counter telegram being received."""
    counted: int = 0
    """The count of the last counter telegram received (0: none, or the line fell silent since, BK-58)."""
    gen: int = IDLE_BIT
    """The bit of :data:`GENERATED_TELEGRAM` sent next, :data:`IDLE_BIT` while the generator is not sending."""
    drop: int = 0
    """The telegram being received began while the generator was sending: it is not sent on."""


class CounterBit(NamedTuple):
    """What the block does in one bit period."""

    out: int
    """The level it sends for this bit period."""
    drive: int
    """1 if ``out`` is the block's (a counter telegram's bits 4..12, a generated telegram)."""
    seen: int
    """1 if a counter telegram ended with this bit period or the generator began (the line fell silent, BK-58): the
    new :attr:`CounterState.counted` is the telegram's count, or 0."""


_LIMITS: Final = {
    "bit": IDLE_BIT, "data": 1, "kind": max(Kind), "carry": 1, "frame": 1, "quiet": COUNTER_SILENCE_BITS,
    "byte": 0xFF, "counted": wire.COUNTER_MAX, "gen": IDLE_BIT, "drop": 1,
}  # fmt: skip


def _refuse(name: str, wanted: str, value: object) -> NoReturn:
    error = fail(name, wanted, value)
    raise InterbusArgumentError(error.name, error.value, str(error), "docs/interbus.md, Counter telegram")


def _check_state(state: object) -> CounterState:
    if type(state) is not CounterState:
        _refuse("state", "a CounterState", state)
    bit, data, kind, carry, frame, quiet, byte, counted, gen, drop = state
    if (type(bit) is type(data) is type(carry) is type(frame) is type(quiet) is type(byte) is type(counted)
            is type(gen) is type(drop) is int and type(kind) in (Kind, int) and 0 <= kind <= Kind.COUNT
            and 0 <= bit <= IDLE_BIT and 0 <= gen <= IDLE_BIT and 0 <= quiet <= COUNTER_SILENCE_BITS
            and not (data | carry | frame | drop) >> 1 and 0 <= byte <= 0xFF and 0 <= counted <= wire.COUNTER_MAX):
        return state
    for name, limit in _LIMITS.items():
        value = getattr(state, name)
        if not isinstance(value, int) or isinstance(value, bool) or not 0 <= value <= limit:
            _refuse(f"state.{name}", f"an integer from 0 to {limit}", value)
    return state


def _receive(state: CounterState, level: int) -> tuple[CounterState, int, int, int]:
    """The receiver's part of a bit period: the state after it, the level to send and ``drive`` for a telegram
    repeated or passed on incremented, and ``seen``."""
    k = state.bit
    if k == IDLE_BIT:
        if level == wire.START_LEVEL:
            return _begin(state, state.frame), level, 0, 0
        quiet = min(state.quiet + 1, COUNTER_SILENCE_BITS)
        return state._replace(quiet=quiet, frame=state.frame if quiet < COUNTER_SILENCE_BITS else 0), level, 0, 0
    kind = state.kind
    new = state._replace(bit=k + 1)
    out, drive, seen = level, 0, 0
    if k == wire.POS_TYPE:
        data = int(level == wire.TYPE_DATA_LEVEL)
        new = new._replace(data=data, kind=kind if data else Kind.PASS)
    elif k == wire.POS_SELECT and level != wire.SELECT_ID_LEVEL:
        new = new._replace(kind=Kind.PASS)
    elif k == wire.POS_CONTROL:
        check = level == wire.CONTROL_CHECK_LEVEL
        frame = 0 if not state.data else state.frame if check else 1
        new = new._replace(frame=frame, kind=Kind.COUNT if kind == Kind.MAYBE and check else Kind.PASS)
    elif kind == Kind.COUNT:
        out, carry = wire.count_bit(k, level, state.carry)
        drive = 1
        byte = state.byte | level << (k - wire.POS_DATA) if k < wire.POS_DATA + 8 else state.byte
        new = new._replace(carry=carry, byte=byte)
    if k == (wire.DATA_TELEGRAM_BITS if state.data else wire.STATUS_TELEGRAM_BITS) - 1:
        if level != wire.STOP_LEVEL:  # M16: a stop bit at start level is the start bit of the next telegram
            return _begin(new, new.frame), out, drive, 0
        new = new._replace(bit=IDLE_BIT, drop=0)
        if kind == Kind.COUNT:
            count = wire.counter_count(new.byte)
            if count is not None:
                new, seen = new._replace(counted=count), 1
    return new, out, drive, seen


def _begin(state: CounterState, frame: int) -> CounterState:
    """A telegram whose start bit is this bit period (bit 1 is sampled next)."""
    kind = Kind.PASS if frame else Kind.MAYBE
    return state._replace(bit=1, data=1, kind=kind, carry=1, frame=frame, quiet=0, byte=0)


def counter_step(state: CounterState, level: int) -> tuple[CounterState, CounterBit]:
    """One bit period: the state after it and what the block sends for it, from the level sampled mid-bit.

    The receiver repeats every telegram and passes counter telegrams on incremented (:data:`Kind`). The generator
    sends :data:`GENERATED_TELEGRAM` from the bit period in which the receiver has been idle for
    :data:`COUNTER_SILENCE_BITS` bit periods and the line is still idle; its bits take precedence, and a telegram
    that begins on the line while it sends is *dropped*: received (its count is kept), but sent as the idle level,
    driven, to its end. Every telegram begun, received or generated, starts the idle count afresh.

    Parameters
    ----------
    state:
        The state before (``CounterState()`` after reset).
    level:
        The line level sampled in this bit period (0 or 1).

    Raises
    ------
    InterbusArgumentError
        ``state`` not a :class:`CounterState` with every field in range, or ``level`` not 0 or 1.
    """
    state = _check_state(state)
    if type(level) is not int or level not in (0, 1):
        _refuse("level", "a line level, 0 or 1", level)
    gen = state.gen
    silent = state.bit == IDLE_BIT and level == wire.IDLE_LEVEL and state.quiet == COUNTER_SILENCE_BITS
    new, out, drive, seen = _receive(state, level)
    if new.bit != IDLE_BIT and (state.bit == IDLE_BIT or new.bit < state.bit):  # a telegram begins
        new = new._replace(drop=int(gen != IDLE_BIT or (state.drop and state.bit != IDLE_BIT)))
    if gen != IDLE_BIT or silent:
        k = 0 if silent else gen
        new = new._replace(gen=k + 1 if k + 1 < wire.DATA_TELEGRAM_BITS else IDLE_BIT)
        if silent:  # BK-58: the line fell silent, the break is at this block's input: no device behind it, count 0
            new = new._replace(quiet=0, counted=0)
        return new, CounterBit((GENERATED_TELEGRAM >> k) & 1, 1, seen | silent)
    if state.drop and state.bit != IDLE_BIT:
        return new, CounterBit(wire.IDLE_LEVEL, 1, seen)
    return new, CounterBit(out, drive, seen)


def _check_cpb(cpb: object) -> int:
    rates = tuple(wire.clocks_per_bit(rate) for rate in BIT_RATES)
    if type(cpb) is not int or cpb not in rates:
        _refuse("cpb", f"clocks per bit at a bit rate of Table 1-7, one of {rates}", cpb)
    return cpb


def sample_phase(cpb: int) -> int:
    """The clock of a bit period (0: the first, where a start level restarts the grid) at which the line is
    sampled: mid-bit (A1, M7)."""
    return _check_cpb(cpb) // 2


def send_countdown(cpb: int) -> int:
    """Clocks from a sample to the end of the bit period sent for it, counted as the chip's transmitter counts
    (M8): the bit goes out ``REPEATER_DELAY_BITS`` bit periods after it began on the pin, the synchroniser's
    ``SYNC_STAGES`` clocks included, for one bit period. A sample's entry is on the line while its countdown is
    1..``cpb``."""
    cpb = _check_cpb(cpb)
    return wire.REPEATER_DELAY_BITS * cpb - SYNC_STAGES + sample_phase(cpb) - 1

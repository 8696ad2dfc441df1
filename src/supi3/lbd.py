"""The counter telegram on the line, one bit period at a time: recognised, incremented in flight, generated behind a
silent line (device-oriented local-bus diagnostics, manual 2.2.2).

The telegram's format and the transaction-level rule are :mod:`supi3.interbus.wire` (``counter_telegram``,
``count_on``, ``count_bit``); the protocol is ``docs/interbus.md`` "Counter telegram", the decisions BK-6, BK-30 to
BK-33 of ``docs/assumptions/bus-terminal.md``. This module is the line behaviour a chip in an LBD mode (Table 2-5)
applies once per line direction (forward; and the looped return line in LBD-MR), as a pure transition per bit period
(:func:`counter_step`) and the clock timing around it (:func:`sample_phase`, :func:`send_countdown`,
:data:`OUTPUT_SLOTS`) that the pin block :mod:`supi3.model.blocks.counter` and the RTL :mod:`supi3.rtl.counter` share.

The block sees the line's mid-bit samples, one per bit period, on the bit grid of its own receiver (a start level
between telegrams restarts the grid, as the chip's receiver, M7). Per sample, :func:`counter_step` gives the level to
send for that bit period (it goes out ``REPEATER_DELAY_BITS`` after the bit began on the input, A10, M8):

* Any telegram is repeated as received, except a *counter telegram*: a data telegram with select = ID and
  control = check that does not belong to a frame (BK-32). Normal traffic sends such a telegram only as a check
  telegram of an ID cycle, after its data sequence; the block knows the frame from the telegrams themselves: a
  data-sequence telegram opens it, a status telegram or :data:`COUNTER_SILENCE_BITS` idle bit periods close it.
  The decision falls at the control bit (bit 3), before the count (bits 4..9).
* A counter telegram's count bits are incremented serially (``wire.count_bit``): LSB first, the carry from bit to
  bit, the carry out of bit 9 sets the saturation mark bit 10 (BK-31).
* After :data:`COUNTER_SILENCE_BITS` idle bit periods, the next idle bit period starts a counter telegram of
  count 1 (``wire.count_on(None)``) that the block sends itself (the generator), and the count the block keeps becomes
  0: the break is at its own input, with no device behind it (a BK's count, BK-58); every telegram begun, received or
  generated, starts the idle count afresh, so a silent line gets one every ``COUNTER_SILENCE_BITS + 1`` bit
  periods, with ``COUNTER_SILENCE_BITS - 12`` idle ones between (the next device never reaches its own silence).
  A telegram that begins on the line while the generator sends is received (a counter telegram's count is kept)
  but *dropped*: sent as the idle level, driven, to its end (BK-30).
"""

from __future__ import annotations

from typing import Final

from supi3.interbus import wire
from supi3.interbus.counter_rule import (
    COUNTER_SILENCE_BITS,
    GENERATED_TELEGRAM,
    IDLE_BIT,
    CounterBit,
    CounterState,
    Kind,
    _refuse,
    counter_step,
    sample_phase,
    send_countdown,
)
from supi3.pinlevel import Pin
from supi3.tables import BIT_RATES

__all__ = [
    "COUNTER_INPUTS",
    "COUNTER_OUTPUTS",
    "COUNTER_SILENCE_BITS",
    "GENERATED_TELEGRAM",
    "IDLE_BIT",
    "OUTPUT_SLOTS",
    "CounterBit",
    "CounterState",
    "Kind",
    "clocks_per_bit",
    "counter_step",
    "sample_phase",
    "send_countdown",
]

COUNTER_INPUTS: Final[tuple[Pin, ...]] = (Pin("line"), Pin("fast"))
"""The block's inputs: ``line``, the line's level after the chip's synchroniser (``SYNC_STAGES`` clocks behind the
pin); ``fast``, the bit rate strap (1: 2 Mbit/s, 0: 500 kbit/s, Table 1-7; change it only with the line idle)."""
COUNTER_OUTPUTS: Final[tuple[Pin, ...]] = (
    Pin("out"), Pin("drive"), Pin("seen"), Pin("count", wire.COUNT_BITS),
)  # fmt: skip
"""The block's outputs: ``out``, the line it sends (every bit period of the input, ``REPEATER_DELAY_BITS`` later
pin to pin, idle between); ``drive``, 1 while ``out`` is a bit the block changed or made (count bits 4..12 of a
counter telegram passed on, all 13 of a generated one); ``seen``, one clock after a counter telegram ended on the
input (its stop bit sampled) or the input fell silent (the generator begins: count 0, BK-58); ``count``, the count of
the last counter telegram received (``wire.counter_count``), 0 if none since reset or since the input fell silent
(the break is at the block's own input, BK-58)."""


def clocks_per_bit(fast: int) -> int:
    """Clocks per bit period for the ``fast`` input: 16 at 2 Mbit/s, 64 at 500 kbit/s (1.7.1, Table 1-7)."""
    if type(fast) is not int or fast not in (0, 1):
        _refuse("fast", "0 (500 kbit/s) or 1 (2 Mbit/s)", fast)
    return wire.clocks_per_bit(max(BIT_RATES) if fast else min(BIT_RATES))


def _slots() -> int:
    """Output entries that can matter at once: every bit not yet begun plus the one being sent (samples are at
    least half a bit plus one clock apart: a stop bit sampled mid-bit, a start level on the next clock)."""
    most = 0
    for rate in BIT_RATES:
        cpb = wire.clocks_per_bit(rate)
        begins = send_countdown(cpb) - cpb + 1
        most = max(most, (begins - 2) // (sample_phase(cpb) + 1) + 1)
    return most + 1


OUTPUT_SLOTS: Final = _slots()
"""Entries of the output queue (model and RTL keep exactly this many; the oldest falls out)."""

"""A chip's wake-up after its power-up reset at transaction level (M22 of docs/assumptions/model.md).

The power-up reset's stretch (M2, 128 clocks, manual 1.7.2) ends at no telegram boundary: the woken chip's receiver
and those behind it (their line resumes when the woken chip's transmitter does, M12) find the telegram grid of the
master's gapless idle status telegrams by M16, a chip begins a frame after a whole status telegram (M19), and the
master's receiver finds the grid last. :func:`wake_window` gives the clocks from which a master's frame finds each
chip on the grid and its receiver meets no telegram error, from the receiver itself
(:func:`supi3.interbus.receiver.receive`) run over idle status telegrams.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from supi3.checks import check_instance, check_int, fail
from supi3.interbus import wire
from supi3.interbus.receiver import receive
from supi3.interbus.wire import Cycle, Frame, Telegram

_PROBE_TELEGRAMS = 64
"""Idle status telegrams the receiver is run over: far more than it needs to find the grid (M16: within two)."""


@functools.cache
def _idle_samples(bit_rate: int) -> npt.NDArray[np.int64]:
    return wire.levels_to_samples(wire.status_levels(Cycle.DATA, False, _PROBE_TELEGRAMS), bit_rate).astype(np.int64)


@functools.cache
def _resync(bit_rate: int, phase: int) -> tuple[int, int, int]:
    """A receiver (M16) that begins listening ``phase`` clocks into an idle status telegram of a gapless run: the
    clocks from then to its first start level (where a woken chip's transmitter resumes, M12), to the end of its first
    whole telegram on the grid (a good stop bit, M19), and to just past its last telegram error (0: none)."""
    cpb = wire.clocks_per_bit(bit_rate)
    telegram = wire.STATUS_TELEGRAM_BITS * cpb
    samples = _idle_samples(bit_rate)[phase:]
    first = int(np.flatnonzero(samples == wire.START_LEVEL)[0])
    for count in range(1, _PROBE_TELEGRAMS):
        end = count * telegram - phase
        if end <= 0:
            continue
        out, index, error = receive(samples[:end], 0, cpb)
        if index == end and out and isinstance(out[-1], Telegram):
            # M16: the telegram error before the grid restarts on its stop bit, the start of the grid's telegram.
            return first, end, end - telegram + cpb // 2 + 1 if error else 0
    raise AssertionError("the receiver finds the telegram grid within two status telegrams (M16)")


def _check(bit_rate: int, devices: int, wakes: Mapping[int, int]) -> int:
    wire.check_bit_rate(bit_rate)
    devices = check_int("devices", devices, 1, wire.MAX_DEVICES)
    if not isinstance(wakes, Mapping) or not all(
        type(index) is int and 0 <= index < devices and type(clock) is int for index, clock in wakes.items()
    ):
        raise fail("wakes", f"a mapping of ring indices (0 to {devices - 1}) to integer clocks", wakes, "M22")
    return devices


class Window(NamedTuple):
    """What a master's cycle meets after chips of a flat ring woke up (M22), in clocks from the start of the master's
    idle status telegrams."""

    ready: list[int]
    """Per ring index, the first clock from which a cycle's frame finds the chip on the grid (0: at once); a frame
    before passes through the chip as received, with no frame of its own (M19)."""
    heard: int
    """The first clock from which a cycle meets no telegram error of the master's receiver (0: at once)."""

    @property
    def end(self) -> int:
        """The first clock from which a cycle meets nothing of the window."""
        return max(self.heard, *self.ready)


def wake_window(bit_rate: int, devices: int, wakes: Mapping[int, int]) -> Window:
    """The window after chips of a flat ring of ``devices`` woke up (M22).

    ``wakes`` maps a ring index (0 = position 1) to the clock its reset stretch (M2) ended, counted from the start of
    the master's idle status telegrams. Chip ``j`` sees the master's line ``REPEATER_DELAY_BITS`` (A10) later per chip
    before it, from its wake-up or, if later, from when the chip before it resumed sending (its first start level after
    its own resumption or wake-up, M12); the chip takes a frame from the end of its first whole status telegram
    (M19); the master's receiver, behind the last chip with no added delay, listens from the last chip's resumption and
    makes its last telegram error before finding the grid (M16).

    Raises
    ------
    ArgumentError
        ``bit_rate`` not one of Table 1-7, ``devices`` not from 1 to ``wire.MAX_DEVICES``, or ``wakes`` not a mapping
        of ring indices (0 to ``devices`` - 1) to integer clocks.
    """
    devices = _check(bit_rate, devices, wakes)
    cpb = wire.clocks_per_bit(bit_rate)
    telegram = wire.STATUS_TELEGRAM_BITS * cpb
    delay = wire.REPEATER_DELAY_BITS * cpb
    resumed: int | None = None
    ready = [0] * devices
    heard = 0
    for index in range(devices + 1):  # the chips, then the master's receiver
        lag = index * delay
        listen = wakes.get(index) if index < devices else None
        if resumed is not None:
            listen = resumed if listen is None else max(listen, resumed)
        if listen is None:
            continue
        first, grid, error = _resync(bit_rate, (listen - lag) % telegram)
        if index < devices:
            ready[index] = listen + grid - lag
        elif error:
            heard = listen + error
        resumed = listen + first + delay
    return Window(ready, heard)


def wake_return(bit_rate: int, devices: int, wakes: Mapping[int, int], start: int,
                frame: Frame) -> tuple[bool, bool]:
    """What the master's receiver makes of a cycle in the window after chips of a flat ring woke up (M22): whether it
    meets a telegram error, and whether a telegram that opens a frame comes back (else a dead line).

    The master's line is followed bit by bit from the earliest wake-up: idle status telegrams, from clock ``start``
    (counted as in :func:`wake_window`) ``frame`` as it comes back and the ring delay's status telegrams (A11), the
    line of each chip silent from a wake-up until it resumes sending (its first start level after it began listening,
    M12, then ``REPEATER_DELAY_BITS`` later); the receiver (:func:`supi3.interbus.receiver.receive`) takes the line in
    two pieces, the idle before ``start`` and the cycle, as the pin level's master does.

    Raises
    ------
    ArgumentError
        As :func:`wake_window`; ``start`` not an integer clock, ``frame`` not a :class:`~supi3.interbus.wire.Frame`.
    """
    devices = _check(bit_rate, devices, wakes)
    start = check_int("start", start)
    check_instance("frame", frame, Frame)
    cpb = wire.clocks_per_bit(bit_rate)
    telegram = wire.STATUS_TELEGRAM_BITS * cpb
    delay = wire.REPEATER_DELAY_BITS * cpb
    origin = min(0, start, *wakes.values()) // telegram * telegram  # followed from a telegram boundary
    idle = wire.status_levels(Cycle.DATA, False, -(-(start - origin) // telegram))
    tail = np.concatenate([wire.frame_levels(frame),
                           wire.status_levels(frame.cycle, False, wire.ring_delay_status_telegrams(devices))])
    sent = np.concatenate([wire.levels_to_samples(idle, bit_rate)[: start - origin],
                           wire.levels_to_samples(tail, bit_rate)]).astype(np.int64)
    end = len(sent)
    resumed: int | None = None
    for index in range(devices):
        listen = wakes.get(index)
        if resumed is not None:
            listen = resumed if listen is None else max(listen, resumed)
        if listen is not None:
            lows = np.flatnonzero(sent[max(0, listen - origin - index * delay):] == wire.START_LEVEL)
            resumed = listen + (int(lows[0]) if lows.size else end) + delay
    lag = devices * delay
    line = np.full(end, wire.IDLE_LEVEL, dtype=np.int64)  # the master's line: the last chip's, no further delay
    line[lag:] = sent[: end - lag]
    if resumed is not None:
        line[: max(0, min(end, resumed - origin))] = wire.IDLE_LEVEL
    _, index, _ = receive(line[: start - origin], 0, cpb)
    telegrams, _, error = receive(line, index, cpb)
    return error, any(isinstance(t, Telegram) and wire.opens_frame(t) for t in telegrams)


_SHORT_HOLD_BITS = 12
"""The reset's low line as :func:`reset_ready` hands it to the receiver: as long as any telegram begun before it reads
into it (a data telegram's stop bit at most 11 bits in), shorter than ``RESET_DETECT_BITS`` (no line reset, which
the chip's receiver does not know: it reads status telegrams of 4 bit periods through the low, M16) and as long as
the hold modulo 4, so that the receiver leaves it where it leaves the whole hold."""


def reset_ready(bit_rate: int, devices: int, wakes: Mapping[int, int], start: int) -> list[int]:
    """Per ring index, the first clock from which a frame finds the chip out of an INTERBUS reset that the master
    begins at clock ``start`` (``wire.reset_levels``, A12) within the window after chips woke up (M22, counted as in
    :func:`wake_window`): a chip that reads the hold from its wake-up (or the chip before it resuming) for
    ``RESET_DETECT_BITS`` or more ends the reset at its fourth whole status telegram after the hold (M11), one that
    does not takes a frame from its first (M19); 0 for a chip on the telegram grid when the hold begins.

    Raises
    ------
    ArgumentError
        As :func:`wake_window`; ``start`` not an integer clock.
    """
    devices = _check(bit_rate, devices, wakes)
    start = check_int("start", start)
    window = wake_window(bit_rate, devices, wakes)
    cpb = wire.clocks_per_bit(bit_rate)
    telegram = wire.STATUS_TELEGRAM_BITS * cpb
    delay = wire.REPEATER_DELAY_BITS * cpb
    cut = (wire.RESET_HOLD_BITS - _SHORT_HOLD_BITS) * cpb
    origin = min(0, start, *wakes.values()) // telegram * telegram
    after = wire.status_levels(Cycle.DATA, False, wire.RESET_END_STATUS_TELEGRAMS + _PROBE_TELEGRAMS)
    idle = wire.levels_to_samples(wire.status_levels(Cycle.DATA, False, -(-(start - origin) // telegram)), bit_rate)
    low = np.full(_SHORT_HOLD_BITS * cpb, wire.START_LEVEL, dtype=np.int64)
    sent = np.concatenate([idle[: start - origin], low, wire.levels_to_samples(after, bit_rate)]).astype(np.int64)
    hold = wire.RESET_HOLD_BITS * cpb
    short_end = start - origin + len(low)  # the hold's end in the short line
    ready = [0] * devices
    resumed: int | None = None
    for index in range(devices):
        lag = index * delay
        listen = wakes.get(index)
        if resumed is not None:
            listen = resumed if listen is None else max(listen, resumed)
        if listen is None or window.ready[index] <= start:  # on the grid at the hold: it leaves the hold on the grid
            resumed = None
            continue
        at = listen - lag - origin  # where the chip begins to listen, on the master's line
        at = at % telegram if at < 0 else at  # before the line followed: idle status telegrams, periodic
        rest = start - origin + hold - at  # the hold it reads
        if at < start - origin:
            rest = hold
        elif rest <= 0:  # woken after the hold
            at -= cut
        else:  # inside the hold: as far from the short hold's end modulo 4 bit periods
            at = short_end - (rest if rest <= len(low) else rest % (4 * cpb) + (_SHORT_HOLD_BITS - 4) * cpb)
        lows = np.flatnonzero(sent[at:] == wire.START_LEVEL)
        resumed = listen + (int(lows[0]) if lows.size else 0) + delay
        line = sent[at:]
        _, begun, _ = receive(line[: max(0, short_end - at)], 0, cpb)
        need = wire.RESET_END_STATUS_TELEGRAMS if rest >= wire.RESET_DETECT_BITS * cpb else 1
        for count in range(1, _PROBE_TELEGRAMS):
            telegrams, _, _ = receive(line[: short_end - at + count * telegram], begun, cpb)
            if sum(isinstance(t, Telegram) and t.data is None for t in telegrams) >= need:
                ready[index] = start + hold + count * telegram
                break
    return ready

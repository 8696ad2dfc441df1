"""A chip's wake-up after its power-up reset at transaction level (M22 of docs/assumptions/model.md).

The power-up reset's stretch (M2, 128 clocks, manual 1.7.2) ends at no telegram boundary: the woken chip's receiver
and those behind it (their line resumes when the woken chip's transmitter does, M12) find the telegram grid of the
master's gapless idle status telegrams by M16, a chip begins a frame after a whole status telegram (M19), and the
master's receiver finds the grid last. :func:`wake_window` gives the clocks from which a master's frame finds each
chip on the grid and its receiver meets no telegram error, from the receiver itself
(:func:`supi3.interbus.receiver.receive`) run over idle status telegrams. In a tree (M25) the chips follow one another
along the data path, each at its lag (:func:`path_lags`: a branch's return repeaters and its BK's synchroniser add to
what follows it), and :attr:`Window.resumed` gives when a woken BK's output, DO3 with DO2, resumes: its branch
answers a loop later. In :func:`wake_return` a woken chip's line is what its own core sends over it (M28: a chip off
the grid may open a frame at a misread telegram inside the master's).
"""

from __future__ import annotations

import functools
import itertools
from collections.abc import Mapping, Sequence
from typing import NamedTuple, Protocol, runtime_checkable

import numpy as np
import numpy.typing as npt

from supi3.checks import check_instance, check_int, fail
from supi3.interbus import wire
from supi3.interbus.counter_rule import (
    COUNTER_SILENCE_BITS,
    IDLE_BIT,
    CounterState,
    counter_step,
    sample_phase,
    send_countdown,
)
from supi3.interbus.errors import InterbusError
from supi3.interbus.receiver import receive
from supi3.interbus.wire import Cycle, Frame, Telegram
from supi3.pinlevel import SYNC_STAGES
from supi3.tables import CLOCK_HZ, RESET_MIN_S

_STRETCH_CLOCKS = round(RESET_MIN_S * CLOCK_HZ)
"""The power-up reset's stretch (M2, 1.7.2): a chip's logic runs this many clocks after its power-up."""
_PROBE_TELEGRAMS = 64
"""Idle status telegrams the receiver is run over: far more than it needs to find the grid (M16: within two)."""


@functools.cache
def _idle_samples(bit_rate: int) -> npt.NDArray[np.int64]:
    return wire.levels_to_samples(wire.status_levels(Cycle.DATA, False, _PROBE_TELEGRAMS), bit_rate).astype(np.int64)


def _first_start(samples: npt.NDArray[np.int64], cpb: int) -> int | None:
    """Where a receiver that begins listening at ``samples[0]`` takes its first start bit, from which a woken chip's
    transmitter resumes (M12): the first start level still low at its mid-bit sample (M7: a start bit sampled at the
    idle level is no telegram; M25: the tail of a low bit heard first, shorter than that, is none, found behind a BK's
    synchroniser, 2 clocks off the bit grid); ``None``: none."""
    low = samples == wire.START_LEVEL
    edges = np.flatnonzero(np.diff(np.concatenate([[0], low.astype(np.int8), [0]])))
    return next((int(a) for a, b in zip(edges[::2], edges[1::2], strict=True) if b - a > cpb // 2 or b == len(low)),
                None)


@functools.cache
def _resync(bit_rate: int, phase: int) -> tuple[int, int, int]:
    """A receiver (M16) that begins listening ``phase`` clocks into an idle status telegram of a gapless run: the
    clocks from then to its first start level (where a woken chip's transmitter resumes, M12), to the end of its first
    whole telegram on the grid (a good stop bit, M19), and to just past its last telegram error (0: none)."""
    cpb = wire.clocks_per_bit(bit_rate)
    telegram = wire.STATUS_TELEGRAM_BITS * cpb
    samples = _idle_samples(bit_rate)[phase:]
    first = _first_start(samples, cpb)
    assert first is not None  # idle status telegrams begin with start bits
    for count in range(1, _PROBE_TELEGRAMS):
        end = count * telegram - phase
        if end <= 0:
            continue
        out, index, error = receive(samples[:end], 0, cpb)
        if index == end and out and isinstance(out[-1], Telegram):
            # M16: the telegram error before the grid restarts on its stop bit, the start of the grid's telegram.
            return first, end, end - telegram + cpb // 2 + 1 if error else 0
    raise AssertionError("the receiver finds the telegram grid within two status telegrams (M16)")


def _check(bit_rate: int, devices: int, wakes: Mapping[int, int], lags: Sequence[int] | None) -> tuple[int, list[int]]:
    """The checked ``devices`` and the lags (:func:`path_lags`'s, a flat ring's when ``None``), else the named error."""
    wire.check_bit_rate(bit_rate)
    devices = check_int("devices", devices, 1, wire.MAX_DEVICES)
    if not isinstance(wakes, Mapping) or not all(
        type(index) is int and 0 <= index < devices and type(clock) is int for index, clock in wakes.items()
    ):
        raise fail("wakes", f"a mapping of ring indices (0 to {devices - 1}) to integer clocks", wakes, "M22")
    if lags is None:
        return devices, path_lags(bit_rate, devices)
    if isinstance(lags, (str, bytes)) or not isinstance(lags, Sequence) or len(lags) != devices + 1 or not all(
            type(lag) is int for lag in lags) or lags[0] < 0 or any(b <= a for a, b in itertools.pairwise(lags)):
        raise fail("lags", f"{devices + 1} increasing integer clocks from 0 (each chip's input, then the master's "
                   "receiver, path_lags)", lags, "M25")  # fmt: skip
    return devices, list(lags)


def path_lags(bit_rate: int, devices: int, branches: Sequence[tuple[int, int, int]] = ()) -> list[int]:
    """The clocks from the master's line to each chip's input along a data path of ``devices`` chips, then to the
    master's receiver (M22, M25): ``REPEATER_DELAY_BITS`` a chip before it (A10), and after a branch (``branches``:
    the ring index of its BK, the index after its last device, its LBD-MR devices) that branch's return line, a repeater
    for each LBD-MR device (BK-35) and the BK's synchroniser on DI3 (``SYNC_STAGES``, M1; DO2 repeats it, BK-37).

    Raises
    ------
    ArgumentError
        ``bit_rate`` not one of Table 1-7, ``devices`` not from 1 to ``wire.MAX_DEVICES``, or ``branches`` not
        triples of a BK's index, the end of its branch (after the BK, at most ``devices``) and a count, or two
        branches of one BK or crossing (not a tree).
    """
    wire.check_bit_rate(bit_rate)
    devices = check_int("devices", devices, 1, wire.MAX_DEVICES)
    delay = wire.REPEATER_DELAY_BITS * wire.clocks_per_bit(bit_rate)
    if isinstance(branches, (str, bytes)) or not isinstance(branches, Sequence):
        raise fail("branches", "a sequence of (BK index, end, LBD-MR devices) triples", branches, "M25")
    extra = [0] * (devices + 2)
    for number, branch in enumerate(branches):
        if not (isinstance(branch, tuple) and len(branch) == 3 and all(type(v) is int for v in branch)
                and 0 <= branch[0] < branch[1] <= devices and 0 <= branch[2] < branch[1] - branch[0]):
            raise fail("branches", f"(BK index, end, LBD-MR devices) triples within {devices} chips", branch, "M25")
        for other in branches[:number]:  # one branch a BK, and a tree's branches nest: disjoint or one inside another
            if other[0] == branch[0] or other[0] < branch[0] < other[1] < branch[1] or (
                    branch[0] < other[0] < branch[1] < other[1]):
                raise fail("branches", "one branch a BK, nested or disjoint (a tree)", branch, "M25")
        extra[branch[1]] += branch[2] * delay + SYNC_STAGES
    lags, added = [], 0
    for index in range(devices + 1):
        added += extra[index]
        lags.append(index * delay + added)
    return lags


class Window(NamedTuple):
    """What a master's cycle meets after chips of a ring woke up (M22; a tree's data path, M25), in clocks from the
    start of the master's idle status telegrams."""

    ready: list[int]
    """Per ring index, the first clock from which a cycle's frame finds the chip on the grid (0: at once); a frame
    before passes through the chip as received, with no frame of its own (M19)."""
    heard: int
    """The first clock from which a cycle meets no telegram error of the master's receiver (0: at once)."""
    resumed: tuple[int | None, ...] = ()
    """Per ring index, the clock the chip's output resumes (its first start level after it began listening, on its
    output, M12), ``None`` for a chip on the grid all along: a BK's branch answers from its own (M25)."""

    @property
    def end(self) -> int:
        """The first clock from which a cycle meets nothing of the window."""
        return max(self.heard, *self.ready)


def wake_window(bit_rate: int, devices: int, wakes: Mapping[int, int], lags: Sequence[int] | None = None,
                counters: Counters | None = None, downs: Mapping[int, int] | None = None) -> Window:
    """The window after chips of a flat ring of ``devices`` woke up (M22).

    ``wakes`` maps a ring index (0 = position 1) to the clock its reset stretch (M2) ended, counted from the start of
    the master's idle status telegrams. Chip ``j`` sees the master's line ``REPEATER_DELAY_BITS`` (A10) later per chip
    before it, from its wake-up or, if later, from when the chip before it resumed sending (its first start level after
    its own resumption or wake-up, M12); the chip takes a frame from the end of its first whole status telegram
    (M19); the master's receiver, behind the last chip with no added delay, listens from the last chip's resumption and
    makes its last telegram error before finding the grid (M16). ``lags``: the clocks from the master's line to each
    chip's input and to the master's receiver (:func:`path_lags`: a tree's data path, M25; ``None``: a flat ring's).
    ``counters``: the counter blocks of LBD chips along the data path, followed on the lines (M26: ``ready`` and
    ``heard`` from :func:`_follow`'s lines); ``downs``: the clock each woken chip's power-down began (its outputs
    silent from then, M27; ``None``: the master's idle's start, clock 0).

    Raises
    ------
    ArgumentError
        ``bit_rate`` not one of Table 1-7, ``devices`` not from 1 to ``wire.MAX_DEVICES``, ``wakes`` not a mapping
        of ring indices (0 to ``devices`` - 1) to integer clocks, ``lags`` not ``devices`` + 1 increasing clocks
        from 0, ``counters`` not a :class:`Counters` of ring indices, or ``downs`` not a mapping of woken ring
        indices to integer clocks.
    """
    devices, lags = _check(bit_rate, devices, wakes, lags)
    cpb = wire.clocks_per_bit(bit_rate)
    telegram = wire.STATUS_TELEGRAM_BITS * cpb
    resumed: int | None = None
    ready = [0] * devices
    outputs: list[int | None] = [None] * devices
    heard = 0
    for index in range(devices + 1):  # the chips, then the master's receiver
        lag = lags[index]
        listen = wakes.get(index) if index < devices else None
        if resumed is not None:
            listen = resumed if listen is None else max(listen, resumed)
        if listen is None:
            continue
        first, grid, error = _resync(bit_rate, (listen - lag) % telegram)
        if index < devices:
            # A chip not powered up keeps its frame block (M19): its line resuming at a telegram's start, it reads
            # that telegram on the grid (M25: found behind a BK with no data register, BK-RB with RF = 10).
            on_grid = index not in wakes and (listen - lag) % telegram == 0
            ready[index] = listen - lag if on_grid else listen + grid - lag
            resumed = outputs[index] = listen + first + lags[index + 1] - lag
        elif error:
            heard = listen + error
    counters = _check_counters(devices, wakes, counters, downs)
    if counters is not None:  # M26: the counter blocks' lines followed
        found, heard = _counter_window(bit_rate, tuple(sorted(wakes.items())), tuple(sorted(
            _downs(cpb, wakes, downs).items())), tuple(lags), counters)
        ready = list(found)
    return Window(ready, heard, tuple(outputs))


def wake_return(bit_rate: int, devices: int, wakes: Mapping[int, int], start: int,
                frame: Frame, lags: Sequence[int] | None = None,
                chips: Mapping[int, WokenChip] | None = None) -> tuple[bool, bool]:
    """What the master's receiver makes of a cycle in the window after chips of a flat ring woke up (M22): whether it
    meets a telegram error, and whether a telegram that opens a frame comes back (else a dead line).

    The master's line is followed bit by bit from the earliest wake-up: idle status telegrams, from clock ``start``
    (counted as in :func:`wake_window`) ``frame`` as it comes back and the ring delay's status telegrams (A11), the
    line of each chip silent from a wake-up until it resumes sending (its first start level after it began listening,
    M12, then as much later as the next chip's input, ``lags``); the receiver (:func:`supi3.interbus.receiver.receive`)
    takes the line in two pieces, the idle before ``start`` and the cycle, as the pin level's master does. A woken
    chip of ``chips`` (ring index -> its transaction-level chip, :class:`WokenChip`) sends on what its own core
    sends over its line from its wake-up (:meth:`WokenChip.woken_output`, M28: off the grid its frame engine opens
    frames at misread telegrams, M19).

    Raises
    ------
    ArgumentError
        As :func:`wake_window`; ``start`` not an integer clock, ``frame`` not a :class:`~supi3.interbus.wire.Frame`,
        ``chips`` not a mapping of woken ring indices (keys of ``wakes``) to :class:`WokenChip` objects.
    """
    devices, lags = _check(bit_rate, devices, wakes, lags)
    start = check_int("start", start)
    check_instance("frame", frame, Frame)
    cpb = wire.clocks_per_bit(bit_rate)
    telegram = wire.STATUS_TELEGRAM_BITS * cpb
    origin = min(0, start, *wakes.values()) // telegram * telegram  # followed from a telegram boundary
    sent = _cycle_line(bit_rate, lags, start, origin, frame)
    end = len(sent)
    chips = _check_chips(chips, wakes)
    resumed: int | None = None
    for index in range(devices):
        listen = wakes.get(index)
        if resumed is not None:
            listen = resumed if listen is None else max(listen, resumed)
        if listen is not None:
            first = _first_start(sent[max(0, listen - origin - lags[index]):], cpb)
            if index in chips:  # M28: the woken chip's own core over its line (silent before the chip before resumed)
                if resumed is not None:
                    sent[: max(0, resumed - origin - lags[index])] = wire.IDLE_LEVEL
                sent = _woken_line(chips[index], sent, listen - origin - lags[index], bit_rate)
            resumed = listen + (end if first is None else first) + lags[index + 1] - lags[index]
    lag = lags[devices]
    line = np.full(end, wire.IDLE_LEVEL, dtype=np.int64)  # the master's line: the last chip's, no further delay
    line[lag:] = sent[: end - lag]
    if resumed is not None:
        line[: max(0, min(end, resumed - origin))] = wire.IDLE_LEVEL
    return _master_reads(line, start - origin, cpb)


def _cycle_line(bit_rate: int, lags: Sequence[int], start: int, origin: int, frame: Frame) -> npt.NDArray[np.int64]:
    """The master's line from clock ``origin`` (a telegram boundary): idle status telegrams, from ``start`` ``frame``
    as it comes back and the ring delay's status telegrams (A11) of the data path ``lags`` describes."""
    telegram = wire.STATUS_TELEGRAM_BITS * wire.clocks_per_bit(bit_rate)
    delay = wire.REPEATER_DELAY_BITS * wire.clocks_per_bit(bit_rate)
    devices = len(lags) - 1
    idle = wire.status_levels(Cycle.DATA, False, -(-(start - origin) // telegram))
    loops = (lags[devices] - devices * delay) // delay  # the return repeaters (BK-55; a synchroniser is < a repeater)
    tail = np.concatenate([wire.frame_levels(frame), wire.status_levels(
        frame.cycle, False, wire.ring_delay_status_telegrams(devices, loops))])
    return np.concatenate([wire.levels_to_samples(idle, bit_rate)[: start - origin],
                           wire.levels_to_samples(tail, bit_rate)]).astype(np.int64)


def _master_reads(line: npt.NDArray[np.int64], start: int, cpb: int) -> tuple[bool, bool]:
    """What the master's receiver makes of ``line``, taken in two pieces, the idle before index ``start`` and the
    cycle, as the pin level's master does: whether it meets a telegram error, and whether a frame comes back."""
    _, index, _ = receive(line[:start], 0, cpb)
    telegrams, _, error = receive(line, index, cpb)
    try:  # a frame comes back only if the master assembles one (as the pin level's master, PinRing.transfer)
        back = wire.returned_frame(telegrams)
    except InterbusError:
        return error, False
    return error, back is not None


@runtime_checkable
class WokenChip(Protocol):
    """A chip whose own core :func:`wake_return` runs over its line after its power-up (M28):
    :class:`supi3.model.chip.Supi3`."""

    def woken_output(self, do1: npt.NDArray[np.int64]) -> npt.NDArray[np.int64] | None:
        """What the chip, powered up at ``do1``'s first clock, sends on DO2 over the forward line ``do1``; ``None``:
        not followed (its output depends on other lines)."""


def _check_chips(chips: Mapping[int, WokenChip] | None, wakes: Mapping[int, int]) -> dict[int, WokenChip]:
    if chips is None:
        return {}
    if not isinstance(chips, Mapping) or not all(
            index in wakes and isinstance(chip, WokenChip) for index, chip in chips.items()):
        raise fail("chips", "a mapping of woken ring indices (keys of wakes) to chips with woken_output", chips, "M28")
    return dict(chips)


def _woken_line(chip: WokenChip, line: npt.NDArray[np.int64], wake: int, bit_rate: int) -> npt.NDArray[np.int64]:
    """M28: ``line`` (the master's line as the woken chip's input sees it: index ``i`` there ``i`` clocks after the
    line's first, a telegram boundary of the master's idle) as the chip sends it on, in the same clocks (its repeater's
    delay, A10, is in the lags of the chips behind): the chip's DO2 (:meth:`WokenChip.woken_output`), its logic
    running from index ``wake``, the end of its stretch (M2), seeing that index first through its synchroniser (M1);
    ``line`` itself for a chip not followed."""
    cpb = wire.clocks_per_bit(bit_rate)
    delay = wire.REPEATER_DELAY_BITS * cpb
    first = wake - (_STRETCH_CLOCKS - SYNC_STAGES)  # the power-up: the run's first index
    size = len(line) + delay - first
    at = np.arange(first, first + size)
    do1 = np.full(size, wire.IDLE_LEVEL, dtype=np.int64)
    inside = (at >= 0) & (at < len(line))
    do1[inside] = line[at[inside]]
    before = at < 0  # before the line followed: the master's idle status telegrams, periodic from its first index
    do1[before] = _idle_samples(bit_rate)[at[before] % (wire.STATUS_TELEGRAM_BITS * cpb)]
    sent = chip.woken_output(do1)
    if sent is None:
        return line
    out = np.full(len(line), wire.IDLE_LEVEL, dtype=np.int64)
    lo = max(0, first - delay)  # DO2 at the run's index p: the line's index p + first - delay
    out[lo:] = sent[lo + delay - first : len(line) + delay - first]
    return out


_SHORT_HOLD_BITS = 12
"""The reset's low line as :func:`reset_ready` hands it to the receiver: as long as any telegram begun before it reads
into it (a data telegram's stop bit at most 11 bits in), shorter than ``RESET_DETECT_BITS`` (no line reset, which
the chip's receiver does not know: it reads status telegrams of 4 bit periods through the low, M16) and as long as
the hold modulo 4, so that the receiver leaves it where it leaves the whole hold."""


def reset_ready(bit_rate: int, devices: int, wakes: Mapping[int, int], start: int,
                lags: Sequence[int] | None = None) -> list[int]:
    """Per ring index, the first clock from which a frame finds the chip out of an INTERBUS reset that the master
    begins at clock ``start`` (``wire.reset_levels``, A12) within the window after chips woke up (M22, counted as in
    :func:`wake_window`): a chip that reads the hold from its wake-up (or the chip before it resuming) for
    ``RESET_DETECT_BITS`` or more ends the reset at its fourth whole status telegram after the hold (M11), one that
    does not takes a frame from its first (M19); 0 for a chip on the telegram grid when the hold begins. ``lags`` as
    :func:`wake_window`'s.

    Raises
    ------
    ArgumentError
        As :func:`wake_window`; ``start`` not an integer clock.
    """
    devices, lags = _check(bit_rate, devices, wakes, lags)
    start = check_int("start", start)
    window = wake_window(bit_rate, devices, wakes, lags)
    cpb = wire.clocks_per_bit(bit_rate)
    telegram = wire.STATUS_TELEGRAM_BITS * cpb
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
        lag = lags[index]
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
        first = _first_start(sent[at:], cpb)
        resumed = listen + (first or 0) + lags[index + 1] - lag
        line = sent[at:]
        _, begun, _ = receive(line[: max(0, short_end - at)], 0, cpb)
        need = wire.RESET_END_STATUS_TELEGRAMS if rest >= wire.RESET_DETECT_BITS * cpb else 1
        for count in range(1, _PROBE_TELEGRAMS):
            telegrams, _, _ = receive(line[: short_end - at + count * telegram], begun, cpb)
            if sum(isinstance(t, Telegram) and t.data is None for t in telegrams) >= need:
                ready[index] = start + hold + count * telegram
                break
    return ready


# -- LBD chips in the window (M26) -----------------------------------------------------------------------------------


class Counters(NamedTuple):
    """M26: the counter blocks (2.2.2, BK-30) along a data path, by ring index: ``forward``, the LBD chips (Table 2-5:
    a block on the forward line, whose driven bits DO2 sends); ``returns``, per LBD-MR branch in the data path, the
    ring index its return line runs into (the one after the branch's last device; the device count: the master's
    receiver) and the devices whose return blocks repeat that line, in the order it runs (the last device first,
    BK-35)."""

    forward: frozenset[int] = frozenset()
    returns: tuple[tuple[int, tuple[int, ...]], ...] = ()


_step = functools.lru_cache(maxsize=1 << 14)(counter_step)
"""``counter_step``, remembered (a line visits few states), as the pin block does."""


def _counter_line(synced: npt.NDArray[np.int64], begin: int, cpb: int) -> tuple[npt.NDArray[np.int64],
                                                                                npt.NDArray[np.int64]]:
    """The line a counter block sends, ``out`` and ``drive`` per clock, over ``synced`` (its input after the chip's
    synchroniser, one sample a clock), the block reset at index ``begin`` and clocked from there by the pin block's
    clock rule (:meth:`supi3.model.blocks.counter.CounterBlock.clock`, BK-33): between telegrams a start level
    restarts the bit grid (M7) unless one waits for its sample, the line is sampled mid-bit (``sample_phase``) and
    :func:`~supi3.interbus.counter_rule.counter_step` decides the bit period sent for it, ``send_countdown`` later
    (M8); the idle level, not driven, where nothing is sent."""
    n = len(synced)
    half = sample_phase(cpb)
    shown = 1 + send_countdown(cpb) - cpb  # from a sample to the first clock of the bit period sent for it
    out = np.full(n, wire.IDLE_LEVEL, dtype=np.int64)
    drive = np.zeros(n, dtype=np.int64)
    starts = np.flatnonzero(synced[begin:] == wire.START_LEVEL) + begin
    state = CounterState()
    free, sample, pending = begin, begin + half, False  # free: the first clock a start level may restart the grid
    while sample < n:
        if state.bit == IDLE_BIT and not pending:
            k = int(np.searchsorted(starts, free))
            if k < len(starts) and starts[k] <= sample:
                sample, pending = int(starts[k]) + half, True
                continue
        state, sent = _step(state, int(synced[sample]))
        pending = False
        out[sample + shown : sample + shown + cpb] = sent.out
        drive[sample + shown : sample + shown + cpb] = sent.drive
        free, sample = sample + 1, sample + cpb
    return out, drive


def _later(line: npt.NDArray[np.int64], clocks: int) -> npt.NDArray[np.int64]:
    """``line`` ``clocks`` later, the idle level before."""
    moved = np.full(len(line), wire.IDLE_LEVEL, dtype=np.int64)
    moved[clocks:] = line[: len(line) - clocks]
    return moved


def _follow(cpb: int, wakes: Mapping[int, int], downs: Mapping[int, int], lags: Sequence[int], counters: Counters,
            sent: npt.NDArray[np.int64], chips: Mapping[int, WokenChip] | None = None,
            ) -> tuple[list[npt.NDArray[np.int64]], list[tuple[npt.NDArray[np.int64], int]]]:
    """M26: the line into each chip of the data path and into the master's receiver (the last), from ``sent``, the
    master's line from a telegram boundary, all indexed alike (``wakes``, ``downs`` in those indices; every chip on the
    telegram grid before the first power-down, ``lags`` behind the master's line: a block is reset at its line's first
    telegram). A chip repeats its input ``REPEATER_DELAY_BITS`` later
    (A10); a woken chip's output idles from its power-down (``downs``: /ResU low, 1.7.2) until its first start level
    after its wake-up (M12); an LBD chip's DO2 sends what its forward block drives (BK-30: a generated counter
    telegram, a telegram dropped while one is generated, a counter telegram's count), and an LBD-MR branch's return
    line runs through each device's return block (DI1, BK-35: its block's line) into its BK's synchroniser, DO2
    repeating it (BK-37). A woken chip's blocks idle from its power-down and run afresh from its wake-up (M2). What the
    master sent before a chip's power-down is followed as idle status telegrams (the last cycle's have other bits), so
    a woken chip listens from its wake-up or, if later, from when the master's line of its power-down's instant
    reaches it (M22's reading: the line followed from then). A woken chip of ``chips`` sends what its own core sends
    over its line from its power-down on (M28, :func:`_woken_line`). Second, each block's ``drive`` and the lag of its
    output behind the master's line."""
    n = len(sent)
    delay = wire.REPEATER_DELAY_BITS * cpb
    returns = dict(counters.returns)

    def block(line: npt.NDArray[np.int64], lag: int, index: int) -> tuple[npt.NDArray[np.int64],
                                                                          npt.NDArray[np.int64]]:
        synced = _later(line, SYNC_STAGES)
        out, drive = _counter_line(synced, lag + SYNC_STAGES, cpb)  # its line's first telegram: on the grid
        if index in wakes:  # the power-up reset: idle from the clock after the power-down, clocked again from M2's end
            again, again_drive = _counter_line(synced, max(wakes[index], downs[index] + lag + SYNC_STAGES), cpb)
            reset = downs[index] + 1
            out[reset:], drive[reset:] = again[reset:], again_drive[reset:]
        return out, drive

    line = sent
    lines = [line]
    driven = []
    for index in range(len(lags) - 1):
        out = _later(line, delay)
        lag = lags[index] + delay
        if index in wakes:
            listen = max(wakes[index], downs[index] + lags[index])
            start = _first_start(line[listen:], cpb)
            out[downs[index] : n if start is None else listen + start + delay] = wire.IDLE_LEVEL
            if chips and index in chips:  # M28: its own core over its line
                own = _woken_line(chips[index], line, wakes[index], CLOCK_HZ // cpb)
                if own is not line:
                    out[downs[index] :] = _later(own, delay)[downs[index] :]
        if index in counters.forward:
            counted, drive = block(line, lags[index], index)
            out = np.where(drive == 1, counted, out)
            driven.append((drive, lag))
        for device in returns.get(index + 1, ()):
            out, drive = block(out, lag, device)
            lag += delay
            driven.append((drive, lag))
        line = _later(out, max(0, lags[index + 1] - lag))
        lines.append(line)
    return lines, driven


def _grid_after(line: npt.NDArray[np.int64], lag: int, listen: int, after: int, woken: bool, cpb: int) -> int | None:
    """M26: the first telegram boundary of the master's grid on ``line`` (``lag`` behind the master's line, indexed
    alike) at or after ``after`` where a receiver that listens from ``listen`` (M16) is between telegrams, with a whole
    telegram received since if ``woken`` (its frame block, M19); ``None``: none within ``line``."""
    telegram = wire.STATUS_TELEGRAM_BITS * cpb
    boundary = -(-(max(after, listen) - lag) // telegram) * telegram + lag
    index, got = listen, False
    while boundary <= len(line):
        out, index, _ = receive(line[:boundary], index, cpb)
        got = got or any(isinstance(item, Telegram) for item in out)
        if index == boundary and (got or not woken):
            return boundary
        boundary += telegram
    return None


def _counter_origin(cpb: int, wakes: Mapping[int, int], downs: Mapping[int, int], lags: Sequence[int],
                    start: int = 0) -> int:
    """M26: a telegram boundary of the master's line from which :func:`_follow` follows every line: every chip on the
    grid for two telegrams before the first power-down reaches it."""
    telegram = wire.STATUS_TELEGRAM_BITS * cpb
    return (min(0, start, *wakes.values(), *downs.values()) - lags[-1] - 2 * telegram) // telegram * telegram


def _downs(cpb: int, wakes: Mapping[int, int], downs: Mapping[int, int] | None) -> dict[int, int]:
    """M26: the power-down of each woken chip (``downs``; else the start of the master's idle, clock 0, or its wake-up
    if earlier), no longer than needed: behind a silence past ``COUNTER_SILENCE_BITS`` the lines repeat with the
    counter telegrams' period (BK-30: one every ``COUNTER_SILENCE_BITS + 1`` bit periods) and the master's idle with
    its status telegrams', so a power-down longer than twice both periods' product is followed from as many products
    later as keep it within that."""
    period = (COUNTER_SILENCE_BITS + 1) * wire.STATUS_TELEGRAM_BITS * cpb
    found = {}
    for index, wake in wakes.items():
        down = min(0, wake) if downs is None or index not in downs else min(downs[index], wake)
        found[index] = down + max(0, (wake - down) // period - 1) * period
    return found


@functools.lru_cache(maxsize=256)
def _counter_window(bit_rate: int, wakes: tuple[tuple[int, int], ...], downs: tuple[tuple[int, int], ...],
                    lags: tuple[int, ...], counters: Counters) -> tuple[tuple[int, ...], int]:
    """M26: :func:`wake_window`'s ``ready`` and ``heard`` over the lines :func:`_follow` gives from the master's idle
    status telegrams: each chip (and the master's receiver, which takes no frame) on the grid again at the first
    telegram boundary after its line's last difference from the undisturbed one (a woken chip listening from its
    wake-up, M19)."""
    cpb = wire.clocks_per_bit(bit_rate)
    telegram = wire.STATUS_TELEGRAM_BITS * cpb
    woken, down = dict(wakes), dict(downs)
    origin = _counter_origin(cpb, woken, down, lags)
    count = -(-(max(woken.values()) - origin + lags[-1]) // telegram) + _PROBE_TELEGRAMS // 2
    sent = wire.levels_to_samples(wire.status_levels(Cycle.DATA, False, count), bit_rate).astype(np.int64)
    relative = {index: clock - origin for index, clock in woken.items()}
    lines, _ = _follow(cpb, relative, {index: clock - origin for index, clock in down.items()}, lags, counters, sent)
    first = min(down.values()) - origin
    ready = []
    for index, (line, lag) in enumerate(zip(lines, lags, strict=True)):
        differ = np.flatnonzero(line != _later(sent, lag))
        if index not in relative and not len(differ):
            ready.append(0)
            continue
        listen = relative.get(index, (first - lag) // telegram * telegram + lag)
        at = _grid_after(line, lag, listen, int(differ[-1]) + 1 if len(differ) else listen, index in relative, cpb)
        ready.append(len(line) + origin if at is None else at + origin - lag)
    return tuple(ready[:-1]), ready[-1] + lags[-1] if ready[-1] else 0


def counter_return(bit_rate: int, devices: int, wakes: Mapping[int, int], start: int, frame: Frame,
                   lags: Sequence[int] | None, counters: Counters, downs: Mapping[int, int] | None = None,
                   chips: Mapping[int, WokenChip] | None = None) -> tuple[bool, bool, bool]:
    """:func:`wake_return` with the counter blocks of LBD chips along the data path (M26: ``counters``; ``downs``: the
    clock each woken chip's power-down began, its outputs silent from then, else the master's idle's start) over the
    lines :func:`_follow` gives; and, third, whether a block drove the line inside the frame (BK-30: a telegram
    dropped while it generates one), which the chip behind it takes as a local error (the frame comes back with its
    CNTR's ERR set). A woken chip of ``chips`` sends what its own core sends (M28), as in :func:`wake_return`.

    Raises
    ------
    ArgumentError
        As :func:`wake_return`; ``counters`` not a :class:`Counters` of ring indices, ``downs`` not a mapping of woken
        ring indices to integer clocks.
    """
    devices, lags = _check(bit_rate, devices, wakes, lags)
    start = check_int("start", start)
    check_instance("frame", frame, Frame)
    checked = _check_counters(devices, wakes, counters, downs)
    chips = _check_chips(chips, wakes)
    if checked is None:
        return *wake_return(bit_rate, devices, wakes, start, frame, lags, chips), False
    cpb = wire.clocks_per_bit(bit_rate)
    downs = _downs(cpb, wakes, downs)
    origin = _counter_origin(cpb, wakes, downs, lags, start)
    sent = _cycle_line(bit_rate, lags, start, origin, frame)
    lines, driven = _follow(cpb, {index: clock - origin for index, clock in wakes.items()},
                            {index: clock - origin for index, clock in downs.items()}, lags, checked, sent, chips)
    span = len(wire.frame_levels(frame)) * cpb
    cut = any(drive[start - origin + lag : start - origin + lag + span].any() for drive, lag in driven)
    return *_master_reads(lines[-1], start - origin, cpb), cut


def _check_counters(devices: int, wakes: Mapping[int, int], counters: object, downs: object) -> Counters | None:
    """The checked ``counters`` (``None`` if there are no blocks or no wake-ups: nothing of M26 to follow) and
    ``downs``, else the named error."""
    if downs is not None and not (isinstance(downs, Mapping) and all(
            index in wakes and type(clock) is int for index, clock in downs.items())):
        raise fail("downs", "a mapping of woken ring indices (wakes) to integer clocks", downs, "M26")
    if counters is None:
        return None
    indices = range(devices + 1)
    if not (isinstance(counters, Counters) and isinstance(counters.forward, frozenset)
            and all(type(i) is int and i in indices[:-1] for i in counters.forward)
            and isinstance(counters.returns, tuple) and all(
                isinstance(r, tuple) and len(r) == 2 and type(r[0]) is int and r[0] in indices[1:]
                and isinstance(r[1], tuple) and all(type(i) is int and i in indices[: r[0]] for i in r[1])
                for r in counters.returns)):
        raise fail("counters", f"Counters of ring indices within {devices} chips", counters, "M26")
    return counters if wakes and (counters.forward or counters.returns) else None

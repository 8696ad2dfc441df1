"""The master's and a chip's receiver at pin level, over 32 MHz line samples (M7, M16 of docs/assumptions/model.md):
``supi3.model.pinring.PinRing``'s master receives the return line with it, and the transaction level's wake-up window
(``supi3.interbus.wake``, M22) runs it over idle status telegrams."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from supi3.checks import check_choice, check_instance, check_int, check_trace
from supi3.interbus import wire
from supi3.interbus.errors import InterbusError, TelegramError
from supi3.interbus.wire import Cycle, LineReset, Telegram
from supi3.tables import BIT_RATES


def receive(samples: npt.NDArray[np.integer], start: int, cpb: int) -> tuple[list[Telegram | LineReset], int, bool]:
    """Receive the telegrams in a 32 MHz sample trace from index ``start``.

    Returns the telegrams, the index to continue from (before any unfinished telegram) and whether a telegram
    error was seen (the erroneous telegram is skipped). The receiver resynchronises as the chip's does (M7, M16):
    on the first start level after a stop bit, or on the period of a stop bit read at start level.

    Raises
    ------
    ArgumentError
        ``samples`` is not a 1-D sequence of 0/1 integers, ``start`` not an index into it, or ``cpb`` not a number of
        clocks per bit (Table 1-7).
    """
    if not isinstance(samples, np.ndarray):
        samples = check_trace("samples", samples, 1)
    start = check_int("start", start, 0, len(samples))
    # An array is checked from ``start`` on: the return line grows run by run and is received piecewise.
    check_trace(f"samples[{start}:]", samples[start:], 1)
    cpb = check_choice("cpb", cpb, sorted({wire.clocks_per_bit(rate) for rate in BIT_RATES}), "Table 1-7")
    out: list[Telegram | LineReset] = []
    error = False
    n = len(samples)
    # Where the level changes (its edges) is found in one pass; each telegram's search for its start level and for the
    # end of a low run is a binary search among them, so a long trace takes time in proportion to its length (a search
    # over the rest of the trace per telegram took time in its square: 4,000 status telegrams, 2.9 s).
    tail = samples[start:]
    edges = np.flatnonzero(tail[1:] != tail[:-1]) + (start + 1)
    i = start
    while i < n:
        t0 = i if samples[i] == wire.START_LEVEL else _next_edge(edges, i, n)
        if t0 >= n:
            return out, n, error
        end = _next_edge(edges, t0, n)
        run = end - t0
        if run >= wire.RESET_DETECT_BITS * cpb:
            if end >= n:
                return out, t0, error
            out.append(LineReset(t0 // cpb))
            i = end
            continue
        mid = t0 + cpb // 2
        if mid + wire.POS_TYPE * cpb >= n:
            return out, t0, error
        is_data = samples[mid + wire.POS_TYPE * cpb] == wire.TYPE_DATA_LEVEL
        length = wire.DATA_TELEGRAM_BITS if is_data else wire.STATUS_TELEGRAM_BITS
        last = mid + (length - 1) * cpb
        if last >= n:
            return out, t0, error
        word = sum(int(level) << k for k, level in enumerate(samples[mid : last + 1 : cpb]))
        try:
            out.append(wire.decode_telegram(word, length))
        except TelegramError:
            error = True
            # As the chip's receiver (M16): a stop bit at start level is the next telegram's start bit.
            i = last - cpb // 2
        else:
            i = last + 1
    return out, n, error


def _next_edge(edges: npt.NDArray[np.intp], i: int, n: int) -> int:
    """The first index after ``i`` where the level changes (``n``: none before the end of the trace)."""
    k = int(np.searchsorted(edges, i, side="right"))
    return int(edges[k]) if k < len(edges) else n


def frame_start(samples: npt.NDArray[np.integer], cpb: int, cycle: Cycle, data_bytes: int) -> int | None:
    """Where a whole frame of ``cycle`` with ``data_bytes`` bytes in its data sequence begins on a line: the index of
    its first start bit in ``samples`` (32 MHz samples of one line, at ``cpb`` clocks per bit), or ``None`` if no
    such frame lies whole in the trace. Its telegrams follow one another without a gap (``wire.frame_bits``), so
    bit period ``b`` of the frame (``wire.locate_bit``) spans ``cpb`` samples from the start plus ``b * cpb``.

    A start is a sample at the start level after the idle or stop level (or the trace's first, at the start level)
    from which :func:`receive` reads the whole frame, telegram after telegram, and nothing else: a telegram read
    from within another (the trace may begin inside one) does not continue into a frame.

    Raises
    ------
    ArgumentError
        ``samples`` is not a 1-D sequence of 0/1 integers, ``cpb`` not a number of clocks per bit (Table 1-7),
        ``cycle`` not a :class:`~supi3.interbus.wire.Cycle` or ``data_bytes`` not an integer >= 0.
    """
    samples = check_trace("samples", samples, 1)
    cpb = check_choice("cpb", cpb, sorted({wire.clocks_per_bit(rate) for rate in BIT_RATES}), "Table 1-7")
    check_instance("cycle", cycle, Cycle)
    data_bytes = check_int("data_bytes", data_bytes, 0)
    telegrams = data_bytes + wire.CHECK_TELEGRAMS
    length = wire.DATA_TELEGRAM_BITS * telegrams * cpb
    low = samples == wire.START_LEVEL
    starts = np.flatnonzero(low[1:] & ~low[:-1]) + 1
    candidates = ([0] if len(samples) and low[0] else []) + starts[starts <= len(samples) - length].tolist()
    mid = cpb // 2
    for at in candidates:
        if samples[at + mid + wire.POS_TYPE * cpb] != wire.TYPE_DATA_LEVEL \
                or samples[at + mid + (wire.DATA_TELEGRAM_BITS - 1) * cpb] != wire.STOP_LEVEL:
            continue  # no data telegram begins here
        found, end, error = receive(samples[at : at + length], 0, cpb)
        if error or end != length or len(found) != telegrams:
            continue
        try:
            frame = wire.frame_from_telegrams(found)
        except InterbusError:
            continue
        if frame.cycle is cycle and len(frame.data) == data_bytes and isinstance(found[0], Telegram) \
                and wire.opens_frame(found[0]):
            return int(at)
    return None

"""The INTERBUS ring at transaction level: a distributed shift register of devices, with fault injection.

The ring carries one frame per cycle from the master through every device and back (docs/interbus.md,
"Ring"). Each device's register is spliced into the stream as the frame passes: what leaves device *k* is its
register followed by what entered it, cut to the frame's length, and what stays in the register is the tail of
what entered. Every line is checked by its receiver (telegrams, sequence, CRC, CNTR).

Speed: on a line without an injected fault the receiver's check passes by construction (the stream received is
the stream sent), so the ring neither materialises the stream nor computes the CRC there; it hands each device
its slice of the master's frame. Lines with a fault, and every line when ``record=True``, go through the full
path, which computes the CRC actually sent and the CRC of what was actually received.

In a data cycle a run of consecutive devices of one class whose class offers a ``data_kernel``
(:class:`~supi3.interbus.link.DataKernel`, e.g. the SUPI 3 model) is loaded and latched by one kernel call
rather than by two method calls per device (docs/interbus.md, "Ring kernel").

Lines are numbered like the devices: line *k* (1..N) enters ring position *k*, line N + 1 is the return line
into the master.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from enum import Enum
from itertools import accumulate
from operator import attrgetter, sub
from typing import Final, NamedTuple, Protocol, runtime_checkable

from supi3.checks import check_bool, check_instance, check_int, check_real, fail
from supi3.interbus import wire
from supi3.interbus.errors import InterbusArgumentError, InterbusError, TelegramError
from supi3.interbus.link import DataKernel, Device
from supi3.interbus.wire import Cycle, Frame


class ErrorKind(Enum):
    """What went wrong, as found by a receiver on the ring or by the master (docs/interbus.md, "Errors")."""

    TELEGRAM = "telegram"
    """Start, type or stop bit wrong."""
    SEQUENCE = "sequence"
    """Select or control bit wrong for its place in the cycle."""
    CRC = "crc"
    """The CRC of the data sequence received differs from the CRC word received."""
    CNTR = "cntr"
    """The CNTR word received is not a legal code."""
    TRANSMISSION = "transmission"
    """The CNTR word came back with ERR set: a device found one of the errors above on its incoming line."""
    LOOPBACK = "loopback"
    """The loopback word is missing or not where the configuration puts it."""
    DEAD_LINE = "dead line"
    """No telegram came back."""
    CONFIGURATION = "configuration"
    """The ID cycle found another configuration than expected, or a reserved length code."""
    PERIPHERAL_FAULT = "peripheral fault"
    """A device reports /StatErr (message 0BB1h, 3.6.2)."""
    WATCHDOG = "watchdog"
    """A device's layer-2 watchdog reset its process data (message 0C6Bh, Table 3-13)."""


# ----------------------------------------------------------------------------------------------------------------
# Fault injection
# ----------------------------------------------------------------------------------------------------------------


_LIMIT_DEVICES: Final = "manual: at most 512 devices in a ring"
_LIMIT_LINES: Final = "lines 1..N + 1 of a ring of at most 512 devices"


def _check_segment(segment: object) -> int:
    return check_int("segment", segment, 1, wire.MAX_DEVICES + 1, _LIMIT_LINES)


def _check_cycles(cycles: object) -> int | None:
    return None if cycles is None else check_int("cycles", cycles, 1)


@dataclass(frozen=True)
class BitFlip:
    """Invert bit period ``bit`` of the frame (0 = first start bit; see ``wire.locate_bit``) on line ``segment``.

    ``cycles`` is how many cycles the fault hits (``None``: every cycle).
    """

    segment: int
    bit: int
    cycles: int | None = 1

    def __post_init__(self) -> None:
        _check_segment(self.segment)
        check_int("bit", self.bit, 0)
        _check_cycles(self.cycles)


@dataclass(frozen=True)
class Truncate:
    """Only the first ``keep`` data-sequence telegrams reach the end of line ``segment``; the check follows."""

    segment: int
    keep: int
    cycles: int | None = 1

    def __post_init__(self) -> None:
        _check_segment(self.segment)
        check_int("keep", self.keep, 0)
        _check_cycles(self.cycles)


@dataclass(frozen=True)
class CorruptLoopback:
    """The loopback word on line ``segment`` is ``value``, with a CRC that matches (a fault in the sender)."""

    segment: int
    value: int
    cycles: int | None = 1

    def __post_init__(self) -> None:
        _check_segment(self.segment)
        check_int("value", self.value, 0, 0xFFFF, "the loopback word is 16 bits")
        _check_cycles(self.cycles)


@dataclass(frozen=True)
class DeadLine:
    """Line ``segment`` carries nothing at all (broken cable); permanent unless ``cycles`` is given."""

    segment: int
    cycles: int | None = None

    def __post_init__(self) -> None:
        _check_segment(self.segment)
        _check_cycles(self.cycles)


Fault = BitFlip | Truncate | CorruptLoopback | DeadLine


@dataclass
class _Active:
    fault: Fault
    remaining: int | None


# ----------------------------------------------------------------------------------------------------------------
# Transfer
# ----------------------------------------------------------------------------------------------------------------


_ATTENTION = attrgetter("attention")
_ONE_BYTE: Final = [bytes((value,)) for value in range(256)]


_Groups = list[tuple[int, int, DataKernel | None]]
"""A run's devices in groups of one class: (start, stop, the class's data kernel or None)."""


class _Run(NamedTuple):
    """Consecutive reached devices: their register contents at the end of the data sequence, whether they may
    latch (own check passed, no error flagged upstream), whether their own check failed, and their groups for the
    data kernels (``None``: every device by its own methods)."""

    devices: list[Device]
    received: list[bytes]
    eligible: bool
    local_error: bool
    groups: _Groups | None = None


def _group(devices: list[Device]) -> _Groups:
    """Split ``devices`` into runs of one class, each with its class's data kernel (``None`` if it has none)."""
    groups: _Groups = []
    start = 0
    for k in range(1, len(devices) + 1):
        if k == len(devices) or type(devices[k]) is not type(devices[start]):
            kernel = getattr(type(devices[start]), "data_kernel", None)
            groups.append((start, k, kernel if isinstance(kernel, DataKernel) else None))
            start = k
    return groups


def _shift(registers: list[bytes], stream: bytes) -> tuple[list[bytes], bytes, int]:
    """Shift ``stream`` through consecutive registers: what each register holds afterwards, what leaves the
    last one, and the registers' total width. A register emits its contents, then what entered it; the stream
    keeps its length."""
    size = len(stream)
    widths = list(map(len, registers))
    total = sum(widths)
    if total <= size:
        ends = accumulate(widths, sub, initial=size)
        received = [stream[end - width : end] for end, width in zip(ends, widths, strict=False)]
        return received, b"".join(reversed(registers)) + stream[: size - total], total
    received = []
    for register in registers:
        joined = register + stream
        received.append(joined[size:])
        stream = joined[:size]
    return received, stream, total


@dataclass(frozen=True)
class SegmentTrace:
    """One line of one cycle, recorded when the ring is built with ``record=True``.

    ``sent`` is the frame the line's sender put on it, ``received`` what its receiver got (``None`` on a dead
    line), ``error`` the receiver's verdict.
    """

    segment: int
    sent: Frame
    received: Frame | None
    error: ErrorKind | None


@dataclass
class Transfer:
    """The data and check sequences of one cycle, shifted through the ring, before the master's verdict.

    Attributes
    ----------
    cycle:
        ID or data cycle.
    sent:
        The data sequence the master sent.
    devices:
        Devices in the (possibly closed) ring for this cycle.
    returned:
        The data sequence that came back to the master, ``None`` if nothing came back.
    flags:
        The CNTR flags that came back (an illegal word reads as attention and error).
    receiver_error:
        The master's own check of its incoming line.
    """

    cycle: Cycle
    sent: bytes
    devices: int
    returned: bytes | None
    flags: wire.CntrFlags
    receiver_error: ErrorKind | None
    runs: list[_Run] = field(repr=False)
    """The reached devices, in ring order, in runs that share a verdict."""
    reached: int = 0


@dataclass
class _Line:
    """A materialised frame on one line: stream, CRC word (None: matches the stream) and CNTR word."""

    stream: bytes
    crc: int | None
    cntr: int

    def frame(self, cycle: Cycle) -> Frame:
        return Frame(cycle, self.stream, wire.crc16(self.stream) if self.crc is None else self.crc, self.cntr)


@runtime_checkable
class Bus(Protocol):
    """What a :class:`~supi3.interbus.master.Master` drives: the transaction-level :class:`Ring`, or the
    pin-level ring of cycle-accurate chips (:class:`supi3.model.pinring.PinRing`)."""

    @property
    def now(self) -> float:
        """Bus time in seconds."""
        ...

    def transfer(self, cycle: Cycle, data: bytes, close_after: int | None = None) -> Transfer:
        """Send one frame's data and check sequences and the ring delay; return what came back."""
        ...

    def finish(self, transfer: Transfer, latch: bool) -> None:
        """End the cycle with the latch telegrams (``latch``) or idle ones."""
        ...

    def reset(self) -> None:
        """INTERBUS reset (Alarm Stop)."""
        ...

    def idle(self, seconds: float) -> None:
        """Only idle status telegrams for ``seconds``."""
        ...


class Ring:
    """A master's ring of devices, at transaction level (docs/interbus.md, "Ring").

    Parameters
    ----------
    devices:
        The devices in ring order: ring position 1 is next to the master.
    bit_rate:
        500 000 or 2 000 000 bit/s (Table 1-7).
    record:
        Keep a :class:`SegmentTrace` of every line of the last cycle in :attr:`trace` (slow; for tests).

    Attributes
    ----------
    now:
        Bus time in seconds.
    """

    closes_early: Final = True
    """The ring can be closed after any position (``transfer(close_after=...)``), for the segment search."""
    direct_return_line: Final = True
    """The return line N + 1 runs from device N straight into the master: an error the master's receiver finds
    is on that line (at pin level the return path runs through every chip, and :class:`PinRing` has neither
    attribute)."""

    def __init__(self, devices: Sequence[Device], bit_rate: int = 500_000, record: bool = False) -> None:
        if isinstance(devices, (str, bytes)) or not isinstance(devices, Sequence):
            raise fail("devices", "a sequence of devices", devices)
        self.bit_rate = wire.check_bit_rate(bit_rate)
        if not 1 <= len(devices) <= wire.MAX_DEVICES:
            raise InterbusArgumentError("devices", devices, f"devices must be 1 to {wire.MAX_DEVICES} devices "
                                        f"({_LIMIT_DEVICES}), not {len(devices)}", _LIMIT_DEVICES)  # fmt: skip
        for k, device in enumerate(devices, 1):
            if not isinstance(device, Device):
                raise fail(f"device at ring position {k}", "a Device (load, latch, discard, ...)", device)
        self.devices: list[Device] = list(devices)
        self.record = check_bool("record", record)
        self.trace: list[SegmentTrace] = []
        self.now = 0.0
        self._faults: list[_Active] = []
        self._silent_since: dict[int, float] = {}
        self._silent_reset: set[int] = set()
        # Caches of the data-cycle hot path, each for the last run it served: the classes of the run's devices and
        # their groups; the registers loaded and the frame size, the registers joined, and the slices that cut each
        # device's received bytes.
        self._layout: tuple[list[type], _Groups] = ([], [])
        self._cuts: tuple[list[bytes], int, bytes, list[slice] | None, int] = ([], -1, b"", None, 0)

    # -- faults --------------------------------------------------------------------------------------------------

    def inject(self, fault: Fault) -> None:
        """Add a fault. Lines are 1..N + 1 (N + 1: the return line into the master)."""
        if not isinstance(fault, (BitFlip, Truncate, CorruptLoopback, DeadLine)):
            raise fail("fault", "a BitFlip, Truncate, CorruptLoopback or DeadLine", fault)
        if not 1 <= fault.segment <= len(self.devices) + 1:
            raise InterbusError("docs/interbus.md, Fault injection", fault.segment,
                                f"line must be in 1..{len(self.devices) + 1}")  # fmt: skip
        self._faults.append(_Active(fault, fault.cycles))

    def clear_faults(self) -> None:
        """Remove every injected fault."""
        self._faults.clear()

    def _faults_on(self, segments: int) -> dict[int, list[Fault]]:
        hits: dict[int, list[Fault]] = {}
        for active in self._faults:
            if active.fault.segment <= segments:
                hits.setdefault(active.fault.segment, []).append(active.fault)
                if active.remaining is not None:
                    active.remaining -= 1
        self._faults = [a for a in self._faults if a.remaining is None or a.remaining > 0]
        return hits

    def _first_dead(self) -> int | None:
        dead = [a.fault.segment for a in self._faults if isinstance(a.fault, DeadLine)]
        return min(dead) if dead else None

    # -- one line ------------------------------------------------------------------------------------------------

    def _receive(self, cycle: Cycle, line: _Line, faults: list[Fault], lbw_at: int) -> tuple[_Line, ErrorKind | None]:
        """What the receiver at the end of a faulted (or recorded) line gets, and its verdict."""
        stream = line.stream
        crc = wire.crc16(stream) if line.crc is None else line.crc
        cntr = line.cntr
        error: ErrorKind | None = None
        for fault in faults:
            if isinstance(fault, CorruptLoopback) and lbw_at + wire.LOOPBACK_BYTES <= len(stream):
                stream = stream[:lbw_at] + wire.word_bytes(fault.value) + stream[lbw_at + wire.LOOPBACK_BYTES :]
                crc = wire.crc16(stream)
        for fault in faults:
            if isinstance(fault, Truncate):
                stream = stream[: max(fault.keep, 0)]
        for fault in faults:
            if not isinstance(fault, BitFlip) or fault.bit >= wire.frame_bits(len(stream)):
                continue
            frame = Frame(cycle, stream, crc, cntr)
            where = wire.locate_bit(frame, fault.bit)
            try:
                telegram = wire.decode_telegram(where.word ^ (1 << where.offset), wire.DATA_TELEGRAM_BITS)
            except TelegramError:
                error = error or ErrorKind.TELEGRAM
                continue
            in_check = where.telegram >= len(stream)
            if telegram.cycle is not cycle or telegram.check != in_check:
                error = error or ErrorKind.SEQUENCE
                continue
            assert telegram.data is not None
            if not in_check:
                stream = stream[: where.telegram] + bytes([telegram.data]) + stream[where.telegram + 1 :]
                continue
            check = bytearray(frame.check_bytes())
            check[where.telegram - len(stream)] = telegram.data
            words = {n: wire.word_from_bytes(bytes(check[2 * i : 2 * i + 2]))
                     for i, n in enumerate(wire.CHECK_SEQUENCE_WORDS)}  # fmt: skip
            crc, cntr = words["crc"], words["cntr"]
        if error is None and wire.crc16(stream) != crc:
            error = ErrorKind.CRC
        if error is None and wire.decode_cntr(cntr) is None:
            error = ErrorKind.CNTR
        return _Line(stream, crc, cntr), error

    # -- the data-cycle kernel -----------------------------------------------------------------------------------

    def _groups(self, run: list[Device]) -> _Groups:
        """``_group(run)``, cached for the last run's classes."""
        types = list(map(type, run))
        if types != self._layout[0]:
            self._layout = (types, _group(run))
        return self._layout[1]

    def _load_run(self, cycle: Cycle, run: list[Device], now: float) -> tuple[list[bytes], bool, _Groups | None]:
        """Every device's ``load(cycle, now)`` and whether one of them wants attention, through the devices' data
        kernels where the cycle and time allow; the groups used, ``None`` if none."""
        if cycle is not Cycle.DATA or type(now) is not float or not 0.0 <= now < math.inf:
            return [device.load(cycle, now) for device in run], any(map(_ATTENTION, run)), None
        groups = self._groups(run)
        if len(groups) == 1 and groups[0][2] is not None:
            registers, attention = groups[0][2].load(run, now)
            return registers, attention, groups
        registers = []
        attention = False
        for start, stop, kernel in groups:
            part = run[start:stop]
            if kernel is None:
                registers += [device.load(cycle, now) for device in part]
                attention = attention or any(map(_ATTENTION, part))
            else:
                loaded, wants = kernel.load(part, now)
                registers += loaded
                attention = attention or wants
        return registers, attention, groups

    def _shift(self, registers: list[bytes], stream: bytes) -> tuple[list[bytes], bytes, int]:
        """``_shift(registers, stream)``, with what depends only on the registers and the frame size cached for
        the last registers (in a data cycle they are mostly the very same bytes objects as in the one before)."""
        size = len(stream)
        last_registers, last_size, head, cuts, total = self._cuts
        if size != last_size or registers != last_registers:
            widths = list(map(len, registers))
            total = sum(widths)
            if total > size:
                return _shift(registers, stream)
            ends = accumulate(widths, sub, initial=size)
            # None: one byte each, cut in one go (the last bytes of the stream, reversed)
            cuts = None if widths.count(1) == len(widths) else [
                slice(end - width, end) for end, width in zip(ends, widths, strict=False)]  # fmt: skip
            head = b"".join(reversed(registers))
            self._cuts = (registers, size, head, cuts, total)
        if cuts is None:
            received = list(map(_ONE_BYTE.__getitem__, stream[size - total : size][::-1]))
        else:
            received = list(map(stream.__getitem__, cuts))
        return received, head + stream[: size - total], total

    # -- a cycle -------------------------------------------------------------------------------------------------

    def transfer(self, cycle: Cycle, data: bytes, close_after: int | None = None) -> Transfer:
        """Shift one frame (data sequence ``data``, CRC and a clear CNTR) through the ring.

        Parameters
        ----------
        cycle:
            ID or data cycle.
        data:
            The master's data sequence: loopback word, then device data (docs/interbus.md, "Frame").
        close_after:
            Close the ring after this ring position (the master's segment search), inside that device, without
            the return line N + 1; a position beyond the ring closes it after its last device. ``None``: the
            whole ring, with the return line.

        Returns
        -------
        Transfer
            Hand it to :meth:`finish` with the master's verdict.
        """
        check_instance("cycle", cycle, Cycle)
        n_all = len(self.devices)
        if n_all > wire.MAX_DEVICES:
            raise InterbusError("docs/interbus.md, Ring", n_all, f"a ring has at most {wire.MAX_DEVICES} devices")
        # A position beyond the ring (the master's table may be older than the ring) closes it at its last device.
        n = n_all if close_after is None else min(check_int("close_after", close_after, 0), n_all)
        # Closed after a position (even the last), the ring returns inside that device: the return line N + 1
        # is only part of the whole ring (close_after=None), so a fault there is told from one on line N.
        segments = n + 1 if close_after is None else n
        faults = self._faults_on(segments) if self._faults else {}
        dead = min((s for s, fs in faults.items() if any(isinstance(f, DeadLine) for f in fs)), default=None)
        self.trace = []
        record = self.record
        now = self.now
        stream = bytes(data)
        shifted = 0
        crc: int | None = None
        attention = False
        error = False
        runs: list[_Run] = []
        devices = self.devices[: n if dead is None else min(n, dead - 1)]
        slow = range(len(devices)) if record else sorted(s - 1 for s in faults if s <= len(devices))
        index = 0
        for stop in [*slow, len(devices)]:
            if index < stop:
                # Unfaulted lines: every receiver gets what its sender sent; no materialising, no CRC.
                run = devices[index:stop]
                registers, wants, groups = self._load_run(cycle, run, now)
                attention = attention or wants
                received, stream, width = self._shift(registers, stream)
                runs.append(_Run(run, received, not error, False, groups))
                shifted += width
                crc = None
                index = stop
            if stop == len(devices):
                break
            segment = stop + 1
            sent = _Line(stream, crc, wire.cntr_word(attention, error))
            line, kind = self._receive(cycle, sent, faults.get(segment, []), shifted)
            if record:
                self.trace.append(SegmentTrace(segment, sent.frame(cycle), line.frame(cycle), kind))
            cntr, bad = wire.forward_cntr(line.cntr, kind is not None, False)
            flags_in = wire.decode_cntr(line.cntr)
            local = kind is not None or bad
            device = devices[stop]
            register = device.load(cycle, now)
            attention, error = wire.decode_cntr(cntr) or (True, True)
            attention = attention or device.attention
            received, stream, width = _shift([register], line.stream)
            runs.append(_Run([device], received, not (local or flags_in is None or flags_in.error), local))
            shifted += width
            crc = None
            index = stop + 1
        returned: bytes | None = None
        receiver_error: ErrorKind | None = None
        flags_back = wire.CntrFlags(attention, error)
        if dead is None or dead > segments:
            sent = _Line(stream, crc, wire.cntr_word(attention, error))
            last = n + 1
            if record or last in faults:
                line, receiver_error = self._receive(cycle, sent, faults.get(last, []), shifted)
                if record:
                    self.trace.append(SegmentTrace(last, sent.frame(cycle), line.frame(cycle), receiver_error))
                flags_back = wire.decode_cntr(line.cntr) or wire.CntrFlags(True, True)
                sent = line
            returned = sent.stream
        elif record:
            silent = _Line(stream, crc, wire.cntr_word(attention, error))
            self.trace.append(SegmentTrace(dead, silent.frame(cycle), None, None))
        return Transfer(cycle, bytes(data), n, returned, flags_back, receiver_error, runs, len(devices))

    def finish(self, transfer: Transfer, latch: bool) -> None:
        """End a cycle with the master's verdict: the latch telegrams (``latch``) or idle telegrams.

        Advances bus time by ``wire.cycle_bits``; a device latches only if its own check passed, no error was
        flagged upstream of it, and the master latches.
        """
        bits = wire.cycle_bits(len(transfer.sent) - wire.LOOPBACK_BYTES, transfer.devices)
        start = self.now
        end = start + bits / self.bit_rate
        cycle = transfer.cycle
        kernels = cycle is Cycle.DATA and type(end) is float and 0.0 <= end < math.inf
        for run in transfer.runs:
            if latch and run.eligible:
                if kernels and run.groups is not None:
                    self._latch_run(run, run.groups, end)
                    continue
                for device, received in zip(run.devices, run.received, strict=True):
                    device.latch(cycle, received, end)
            else:
                for device in run.devices:
                    device.discard(cycle, run.local_error, end)
        if self._silent_since:
            for index in range(transfer.reached):
                self._silent_since.pop(index, None)
                self._silent_reset.discard(index)
        self._go_silent(range(transfer.reached, len(self.devices)), start, end)
        self.now = end

    @staticmethod
    def _latch_run(run: _Run, groups: _Groups, end: float) -> None:
        """Every device of a data cycle's run latches its received bytes, through the data kernels."""
        if len(groups) == 1 and groups[0][2] is not None:
            groups[0][2].latch(run.devices, run.received, end)
            return
        for start, stop, kernel in groups:
            if kernel is not None:
                kernel.latch(run.devices[start:stop], run.received[start:stop], end)
                continue
            for device, received in zip(run.devices[start:stop], run.received[start:stop], strict=True):
                device.latch(Cycle.DATA, received, end)

    def _go_silent(self, indices: range, start: float, end: float) -> None:
        """Devices at ``indices`` heard nothing from ``start`` to ``end``: poll them, reset after the timeout."""
        for index in indices:
            since = self._silent_since.setdefault(index, start)
            device = self.devices[index]
            if index not in self._silent_reset and end - since >= wire.IDLE_TIMEOUT_S:
                device.reset(since + wire.IDLE_TIMEOUT_S)
                self._silent_reset.add(index)
            device.poll(end)

    def reset(self) -> None:
        """An INTERBUS reset (the master's Alarm Stop, 1303h): reset pattern, then idle (assumption A12)."""
        dead = self._first_dead()
        reached = len(self.devices) if dead is None else min(len(self.devices), dead - 1)
        end = self.now + wire.reset_bits(len(self.devices)) / self.bit_rate
        for device in self.devices[:reached]:
            device.reset(end)
        self._go_silent(range(reached, len(self.devices)), self.now, end)
        self.now = end

    def idle(self, seconds: float) -> None:
        """The master sends only idle status telegrams for ``seconds`` (no cycles)."""
        seconds = check_real("seconds", seconds, 0.0)
        dead = self._first_dead()
        reached = len(self.devices) if dead is None else min(len(self.devices), dead - 1)
        end = self.now + seconds
        for device in self.devices[:reached]:
            device.poll(end)
        self._go_silent(range(reached, len(self.devices)), self.now, end)
        self.now = end

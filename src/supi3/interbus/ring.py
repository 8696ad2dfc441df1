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

A device whose data path is open sends a constant line (RX-13: a SUPI 3 OPC with ExtReg = 1 and nothing on FromExR,
docs/assumptions/expansion.md): what leaves it is that level for the whole data sequence, with its own CRC, whatever
entered it (:func:`_shift_open`).

Lines are numbered like the devices: line *k* (1..N) enters ring position *k*, line N + 1 is the return line
into the master.

A ring can be a tree (Figure 1-10, docs/interbus.md "Tree"): a :class:`Branch` is a bus terminal module (BK) with the
devices of its branch. The data path runs into the BK, through the branch and back to the BK, then on along the remote
bus, so the ring flattens the tree into :attr:`Ring.devices` in that order, leaving out every branch its BK has not in
the data path (switched off by the master, closed by the BK itself, not present by Table 2-9: a BK recognises its
branch once a device answered, BK-48); it flattens again whenever a BK changes that. In a tree a fault belongs to the
physical line it was injected on: it follows that line when branches are switched, and sleeps while the line is out of
the data path; :meth:`Ring.cut` injects a break by the physical position of the device it enters, as the pin level's
``PinRing.cut`` (BK-52). A branch recognised in a cycle's run joins within its frame, which it loses (BK-54), with
the error of the first line of its loop repaired before that run (BK-56).
:class:`ReturnBreak` breaks a return line: a branch's (a branch in the data path with nothing attached is broken so at
its BK, BK-43) or the remote bus's (BK-59); behind a break in a branch with device-oriented diagnostics the devices
send the counter telegram to the BK (2.2.2, ``wire.counter_telegram``).
"""

from __future__ import annotations

import gc
import math
import numbers
import weakref
from collections.abc import Collection, Iterable, Sequence
from dataclasses import dataclass, field
from enum import Enum
from itertools import accumulate
from operator import attrgetter, sub
from typing import ClassVar, Final, NamedTuple, Protocol, cast, runtime_checkable

from supi3.checks import check_bool, check_bytes, check_instance, check_int, check_real, describe, fail
from supi3.config import DeviceConfig, Interface
from supi3.interbus import wire
from supi3.interbus.errors import InterbusArgumentError, InterbusError, TelegramError
from supi3.interbus.link import DataKernel, Device
from supi3.interbus.wake import Counters, WokenChip, counter_return, path_lags, reset_ready, wake_window
from supi3.interbus.wire import Cycle, Frame
from supi3.pinlevel import SYNC_STAGES
from supi3.tables import CLOCK_HZ, RESET_MIN_S


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
    """No frame came back: no telegram, or only counter telegrams (an interrupt in an LBD branch, BK-49)."""
    CONFIGURATION = "configuration"
    """The ID cycle found another configuration than expected, or a reserved length code."""
    PERIPHERAL_FAULT = "peripheral fault"
    """A device reports /StatErr (message 0BB1h, 3.6.2)."""
    WATCHDOG = "watchdog"
    """A device's layer-2 watchdog reset its process data (message 0C6Bh, Table 3-13)."""
    RECONFIGURATION_REQUEST = "reconfiguration request"
    """A bus terminal module's CONF input rose: a request to reconfigure the bus (2.4, Table 2-8; BK-8)."""
    BRANCH_CLOSED = "branch closed"
    """A bus terminal module closed its branch itself (extended BK function, 2.4; BK-3)."""
    MAU_WARNING = "MAU warning"
    """A device's MAU warning (MAUWH, MAUWR or MAUWS) came on or went off (1.6.3; OPT-50..OPT-53)."""


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


@dataclass(frozen=True)
class ReturnBreak:
    """The return line *into* ring position ``segment`` of a tree carries nothing (docs/interbus.md, "Tree").

    ``segment`` is a bus terminal module with a branch (its branch's return line, from the branch's first device in
    a branch with return, from the last in an LBD-OR branch; whether the branch is in the data path or not, BK-52)
    or a device with return lines that has a device behind it (the return line from that device): in a branch with
    return lines (REMOTE, LOCAL, LBD_MR), or on the remote bus outside branches, whose return lines run back into the
    master (BK-59; :func:`return_inputs`). The ring closed early uses the return line into position *k* only when it
    is closed behind *k*; permanent unless ``cycles`` is given.
    """

    segment: int
    cycles: int | None = None

    def __post_init__(self) -> None:
        check_int("segment", self.segment, 1, wire.MAX_DEVICES, _LIMIT_DEVICES)
        _check_cycles(self.cycles)


Fault = BitFlip | Truncate | CorruptLoopback | DeadLine | ReturnBreak


@dataclass
class _Active:
    fault: Fault
    remaining: int | None
    target: object = None
    """In a tree: the device whose incoming line the fault is on (``None``: the return line into the master)."""
    branch: bool = False
    """A :class:`ReturnBreak` at a BK with a branch: its branch return input (DI3), out of the data path (asleep) while
    that branch is (BK-48, BK-52); else the return input from the device behind."""


# ----------------------------------------------------------------------------------------------------------------
# Trees: bus terminal modules and their branches (2.4, Figure 1-10)
# ----------------------------------------------------------------------------------------------------------------


class BranchKind(Enum):
    """What hangs on a bus terminal module (Table 2-7; the local bus kinds of Tables 2-4, 2-5)."""

    REMOTE = "BK-RB"
    """Remote bus branch (BK-RB): remote bus devices, bus terminal modules among them; return lines."""
    LOCAL = "BK-LB"
    """Local bus branch without device-oriented diagnostics (BK-LB, LB-MR devices); return lines."""
    LBD_MR = "LBD-MR"
    """Local bus with device-oriented diagnostics, devices with return (BK-LBD; 2.2.2): the counter telegram is
    incremented on the forward and on the looped return line."""
    LBD_OR = "LBD-OR"
    """Local bus with device-oriented diagnostics, devices without return (BK-LBD; loop): forward only."""

    @property
    def terminal(self) -> str:
        """The BK interface of Table 2-7 this branch needs."""
        return "BK-LBD" if self in (BranchKind.LBD_MR, BranchKind.LBD_OR) else self.value

    @property
    def diagnostics(self) -> bool:
        """Device-oriented local-bus diagnostics (the counter telegram, 2.2.2)."""
        return self in (BranchKind.LBD_MR, BranchKind.LBD_OR)


@runtime_checkable
class Terminal(Device, Protocol):
    """What a ring needs from a bus terminal module (:class:`supi3.model.chip.Supi3` in a BK mode)."""

    @property
    def terminal_interface(self) -> str | None:
        """``"BK-RB"``, ``"BK-LB"`` or ``"BK-LBD"`` (Table 2-7); ``None`` for a device that is no BK."""
        ...

    def branch_enabled(self, connected: bool) -> bool:
        """Whether the branch is in the data path; ``connected``: a device answers on the branch."""
        ...

    @property
    def branch_recognised(self) -> bool:
        """A device on the branch has answered since the BK's power-up (BK-37, BK-48)."""
        ...

    def recognise_branch(self) -> None:
        """A device answered on the branch (BK-48): recognised until the BK's power-up reset."""
        ...

    def branch_returned(self, traffic: bool, count: int | None, start: float, end: float,
                        frame_end: float | None = None) -> None:
        """The ring drove the whole branch from ``start`` to ``end``: the master's telegrams came back on the return
        line (``traffic``), and the count of the counter telegram received there (``None``: none); ``frame_end``:
        when the cycle's frame ended at the BK (``None``: no frame, an idle stretch or a reset, BK-50)."""
        ...


@dataclass(frozen=True, eq=False)
class Branch:
    """A bus terminal module and the devices of its branch, in data-path order (docs/interbus.md, "Tree").

    Parameters
    ----------
    terminal:
        The BK; its :attr:`Terminal.terminal_interface` must be the one ``kind`` needs (Table 2-7).
    devices:
        The branch's devices, first to last; only a remote bus branch may hold further branches.
    kind:
        What the branch is.
    """

    terminal: Terminal
    devices: Sequence[Device | Branch]
    kind: BranchKind

    def __post_init__(self) -> None:
        if not isinstance(self.terminal, Terminal) or self.terminal.terminal_interface is None:
            raise fail("terminal", "a bus terminal module (a Supi3 in a mode of Table 2-7)", self.terminal)
        check_instance("kind", self.kind, BranchKind)
        if self.terminal.terminal_interface != self.kind.terminal:
            wanted = f"terminal must be a {self.kind.terminal} for a {self.kind.value} branch (Table 2-7)"
            raise InterbusArgumentError("terminal", self.terminal,
                                        f"{wanted}, not a {self.terminal.terminal_interface}", "Table 2-7")
        if isinstance(self.devices, (str, bytes)) or not isinstance(self.devices, Sequence):
            raise fail("devices", "a sequence of devices and branches", self.devices)
        object.__setattr__(self, "devices", tuple(self.devices))
        for k, device in enumerate(self.devices, 1):
            if isinstance(device, Branch):
                if self.kind is not BranchKind.REMOTE:
                    raise fail(f"branch device {k}", "a device (only a remote bus branch holds bus terminal "
                               "modules, 2.4)", device)  # fmt: skip
            elif not isinstance(device, Device):
                raise fail(f"branch device {k}", "a Device or a Branch", device)
            else:
                self._check_interface(k, device)

    def _check_interface(self, k: int, device: Device) -> None:
        """A SUPI 3 in the branch must be in the branch's kind of interface: "mixed operation is not permitted" on a
        local bus (2.2), and a remote bus branch holds remote bus devices and bus terminal modules (2.4)."""
        config = getattr(device, "config", None)
        if not isinstance(config, DeviceConfig):
            return  # another device model: its interface is not known here
        interface = config.interface
        wanted = _BRANCH_INTERFACES[self.kind]
        if interface.value not in wanted and not (self.kind is BranchKind.REMOTE and interface.is_bus_terminal):
            raise InterbusArgumentError(f"branch device {k}", device, f"branch device {k} must be in a "
                                        f"{' or '.join(wanted)} mode for a {self.kind.value} branch, not "
                                        f"{interface.value} (2.2: mixed operation is not permitted)", "2.2, 2.4")


_BRANCH_INTERFACES: Final[dict[BranchKind, tuple[str, ...]]] = {
    BranchKind.REMOTE: ("RB",), BranchKind.LOCAL: ("LB-MR",), BranchKind.LBD_MR: ("LBD-MR",),
    BranchKind.LBD_OR: ("LBD-OR",),
}
"""The interface a SUPI 3 in each kind of branch must have (Tables 2-4 to 2-6; a remote branch also holds BKs)."""


@dataclass(frozen=True)
class _Span:
    """An enabled branch in the flattened ring: the BK at index ``at``, its devices (nested ones too) at indices
    ``at + 1 .. end - 1``; ``own`` are the indices of its own devices in order (not those of nested branches)."""

    branch: Branch
    at: int
    end: int
    own: tuple[int, ...]


def join_error(kind: BranchKind, first_forward: int | None) -> ErrorKind:
    """The error a master reports for the cycle within whose frame a branch of ``kind`` joins the data path after a
    repair (BK-54, BK-56): ``first_forward`` is the place in the branch (0: its first device) of the first device whose
    forward input was among the lines repaired just before that cycle's run, ``None`` if only return lines were (a
    device's return input, the BK's branch return input DI3).

    The pin-level BK switches DO2 to DI3 at the telegram boundary after the first start level back on DI3 (BK-37,
    BK-47), and where that falls in the frame follows from the first repaired line of the loop the frame travels
    (measured, BK-56): the first device's forward input repaired, the device joins the frame mid-way with a local error
    (``TRANSMISSION``); a later device's, the frame comes back cut inside a telegram (``TELEGRAM``); only return lines,
    or any repair in an LBD-MR branch (its devices' return repeaters send counter telegrams on DI3 first, BK-30,
    BK-35), DO2 switches before the frame's head is back (``DEAD_LINE``)."""
    check_instance("kind", kind, BranchKind)
    if first_forward is not None:
        check_int("first_forward", first_forward, 0, wire.MAX_DEVICES - 1, _LIMIT_DEVICES)
    if first_forward is None or kind is BranchKind.LBD_MR:
        return ErrorKind.DEAD_LINE
    return ErrorKind.TRANSMISSION if first_forward == 0 else ErrorKind.TELEGRAM


def _branches(items: Sequence[Device | Branch]) -> list[Branch]:
    """Every branch of a tree, nested ones too, in data-path order."""
    found: list[Branch] = []
    for item in items:
        if isinstance(item, Branch):
            found.append(item)
            found += _branches(item.devices)
    return found


def _devices(items: Sequence[Device | Branch]) -> list[Device]:
    """Every device of a tree, enabled or not."""
    found: list[Device] = []
    for item in items:
        if isinstance(item, Branch):
            found.append(item.terminal)
            found += _devices(item.devices)
        else:
            found.append(item)
    return found


def _check_tree(items: object, first: object) -> None:
    """``items`` a sequence of devices and :class:`Branch` items, ``first`` a ring position; else the named error."""
    if isinstance(items, (str, bytes)) or not isinstance(items, Sequence) or not all(
            isinstance(item, (Device, Branch)) for item in items):  # fmt: skip
        raise fail("items", "a sequence of devices and Branch items (a tree, docs/interbus.md)", items)
    check_int("first", first, 1, wire.MAX_DEVICES, _LIMIT_DEVICES)


def terminal_positions(items: Sequence[Device | Branch], first: int = 1) -> set[int]:
    """The physical positions (from ``first`` on: a BK, then its branch's devices, nested branches in place, BK-1) of
    the BKs of :class:`Branch` items, nested ones too: where a cut of a BK's branch return input can be made (BK-52).

    Raises
    ------
    ArgumentError
        ``items`` is not a sequence of devices and branches, or ``first`` not a ring position (1 to 512).
    """
    _check_tree(items, first)
    found: set[int] = set()
    position = first
    for item in items:
        if isinstance(item, Branch):
            found.add(position)
            found |= terminal_positions(item.devices, position + 1)
            position += len(_devices(item.devices))
        position += 1
    return found


def return_inputs(items: Sequence[Device | Branch], first: int = 1, returns: bool = True) -> set[int]:
    """The physical positions (from ``first`` on, BK-1) of the devices of ``items`` whose return input a device drives:
    all but the last of a sequence with return lines (``returns``: the remote bus outside branches), in branches too;
    none in an LBD-OR branch (BK-52): where ``Ring.cut`` and ``PinRing.cut`` break a return input, and where
    ``Ring.inject`` takes a :class:`ReturnBreak` at a device that is no BK with a branch (BK-59).

    Raises
    ------
    ArgumentError
        ``items`` is not a sequence of devices and branches, ``first`` not a ring position (1 to 512), or ``returns``
        not a bool.
    """
    _check_tree(items, first)
    check_bool("returns", returns)
    found: set[int] = set()
    position = first
    for k, item in enumerate(items):
        if returns and k + 1 < len(items):
            found.add(position)
        if isinstance(item, Branch):
            found |= return_inputs(item.devices, position + 1, item.kind is not BranchKind.LBD_OR)
            position += len(_devices(item.devices))
        position += 1
    return found


def _check_lbd(kind: object, devices: object) -> None:
    """``kind`` an LBD branch kind and ``devices`` a branch size, else the named error."""
    if not check_instance("kind", kind, BranchKind).diagnostics:
        raise InterbusArgumentError("kind", kind, f"kind must be LBD_MR or LBD_OR (2.2.2), not {kind}", "2.2.2")
    check_int("devices", devices, 0, wire.MAX_DEVICES, _LIMIT_DEVICES)


def lbd_count(kind: BranchKind, devices: int, forward: Collection[int], back: Collection[int]) -> int | None:
    """The count the BK of an LBD branch of ``devices`` devices receives on its return line (2.2.2, BK-6).

    ``forward`` are the branch devices (1..m) whose incoming forward line is broken, ``back`` those whose incoming
    return line is broken (0 = the BK's own return input; 1..m - 1 in LBD-MR: the line from the next device).
    The first device behind the last break on the data path starts the count, every device after it passes the
    counter telegram on incremented (``wire.count_on``): LBD-MR devices on the forward and on the looped return
    line, LBD-OR devices forward only. ``None``: no counter telegram arrives (no break, or the BK's return input is
    broken).
    """
    _check_lbd(kind, devices)
    for name, lines in (("forward", forward), ("back", back)):
        if isinstance(lines, (str, bytes)) or not isinstance(lines, Collection):
            raise fail(name, "a collection of branch device numbers", lines)
        for k in lines:
            check_int(f"{name} device", k, 0 if name == "back" else 1, devices, "the branch's devices (0: the BK)")
    path = [("f", k) for k in range(1, devices + 1)]
    if kind is BranchKind.LBD_MR:
        path += [("r", k) for k in range(devices, 0, -1)]  # ("r", m): the loop inside device m, never broken
    if 0 in back:
        return None
    loop = ("r", devices)
    broken = [i for i, (way, k) in enumerate(path) if k in (forward if way == "f" else back) and (way, k) != loop]
    if not broken:
        return None
    word: int | None = None
    for _ in path[max(broken) :]:
        word = wire.count_on(word)
    assert word is not None
    return wire.decode_counter_telegram(word)


def lbd_position(kind: BranchKind, devices: int, count: int) -> tuple[int, bool] | None:
    """Where the break is, from the count a BK read (0: none arrived): ``(k, return_line)``, the branch device
    *k* (0: the BK) whose incoming forward line (``return_line`` False) or return line is broken; ``None`` if
    no single break gives this count (or the count saturated). The inverse of :func:`lbd_count` (BK-7)."""
    _check_lbd(kind, devices)
    count = check_int("count", count, 0, wire.COUNTER_MAX, "BK-5: a count is 6 bits")
    if count == 0:
        return 0, True
    if count == wire.COUNTER_MAX:
        return None
    if kind is BranchKind.LBD_OR:
        return (devices - count + 1, False) if count <= devices else None
    if count < devices:
        return count, True
    if devices < count <= 2 * devices:
        return 2 * devices - count + 1, False
    return None


# ----------------------------------------------------------------------------------------------------------------
# Transfer
# ----------------------------------------------------------------------------------------------------------------


_ATTENTION = attrgetter("attention")
_ONE_BYTE: Final = [bytes((value,)) for value in range(256)]
_FLAGS: Final = {(a, e): wire.CntrFlags(a, e) for a in (False, True) for e in (False, True)}
"""The CNTR flags by (attention, error): immutable, so one object each serves every cycle."""


_DATA: Final = Cycle.DATA
_INF: Final = math.inf
"""A31: the plain data cycle's tests (:meth:`Ring.transfer`, :meth:`Ring.finish`) without an attribute lookup each."""
_new_tuple: Final = tuple.__new__
"""A named tuple made from all its fields in order, as its class's own ``__new__`` does, without that Python call
(A29: a :class:`_Run` a data cycle)."""
_Groups = list[tuple[int, int, DataKernel | None]]
"""A run's devices in groups of one class: (start, stop, the class's data kernel or None)."""


class _Run(NamedTuple):
    """Consecutive reached devices: their register contents at the end of the data sequence, whether they may
    latch (own check passed, no error flagged upstream), whether their own check failed, their groups for the
    data kernels (``None``: every device by its own methods) and, for a run of one class, that class's kernel."""

    devices: list[Device]
    received: list[bytes]
    eligible: bool
    local_error: bool
    groups: _Groups | None = None
    kernel: DataKernel | None = None


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


def _timeout(device: Device, now: float, counted: bool = False) -> None:
    """A device's incoming line was silent for ``wire.IDLE_TIMEOUT_S`` until ``now`` (A13): its ``line_timeout`` if
    it has one (the SUPI 3 model: the reset plus DG-3/DG-4, docs/assumptions/diagnostics.md), else ``reset``;
    ``counted``: counter telegrams came in the silence (DG-9), told to a ``line_timeout`` that takes them."""
    timeout = getattr(device, "line_timeout", None)
    if callable(timeout):
        timeout(now, counted) if counted else timeout(now)
    else:
        device.reset(now)


def _tell_following(items: Sequence[Device | Branch]) -> None:
    """Tell every device that takes it (``set_following``, the SUPI 3 model) whether a device follows on its
    outgoing interface (M5; RD, DG-5): each but the last of the ring and of each branch. A BK's outgoing interface is
    its remote bus: what follows it there is the item after its :class:`Branch`, not the branch's first device
    (that one is on DO3). The wiring is physical: a branch switched off keeps it."""
    for k, item in enumerate(items):
        device = item.terminal if isinstance(item, Branch) else item
        tell = getattr(device, "set_following", None)
        if callable(tell):
            tell(k + 1 < len(items))
        if isinstance(item, Branch):
            _tell_following(item.devices)


def _interface(device: object) -> Interface | None:
    """The interface of a device that has a :class:`~supi3.config.DeviceConfig` (a SUPI 3 chip at either fidelity),
    else ``None``."""
    config = getattr(device, "config", None)
    return config.interface if isinstance(config, DeviceConfig) else None


def _sends_counts(device: Device) -> bool:
    """The device sends counter telegrams behind a break (an LBD chip, Table 2-5, BK-30): every device after it in
    the silent stretch hears them (DG-9)."""
    return _interface(device) in (Interface.LBD_MR, Interface.LBD_OR)


def _return_repeater(device: object) -> bool:
    """An LBD-MR chip: its counter block repeats its looped return line 3 bit periods later (2.2.2, BK-35)."""
    return _interface(device) is Interface.LBD_MR


def return_repeaters(devices: Iterable[object]) -> int:
    """The repeaters on the return lines of ``devices`` (A10): one per LBD-MR chip, whose counter block repeats its
    looped return line 3 bit periods later (2.2.2, BK-35). A cycle's ring delay (A11) counts them with the devices at
    both fidelities (BK-55)."""
    return sum(map(_return_repeater, devices))


class _Opening(Device, Protocol):
    """A device whose data path can open (its ``sends_constant`` set, the SUPI 3 model's
    :attr:`~supi3.model.chip.Supi3.sends_constant`): after a data-cycle load, the level it sends for the whole data
    sequence, ``None`` when the frame shifts through its register (RX-13)."""

    constant_output: int | None


_Opens = list[tuple[int, _Opening]]
"""The devices of a run whose data path can open, with their indices in the run (RX-13)."""


def _opens(run: list[Device]) -> _Opens:
    """The devices of ``run`` whose data path can open (their ``sends_constant`` set, RX-13), with their indices."""
    return cast(_Opens, [(k, device) for k, device in enumerate(run) if getattr(device, "sends_constant", False)])


def _levels(opens: _Opens) -> list[tuple[int, int]]:
    """After a data cycle's loads: (index, level) of each device of ``opens`` that sends a constant line this cycle
    (its ``constant_output`` not ``None``, RX-13).

    Raises
    ------
    InterbusError
        A ``constant_output`` that is not 0, 1 or ``None`` (RX-14: a user's model said 5 or 'x', once taken as 1).
    """
    levels = [(k, level) for k, device in opens if (level := device.constant_output) is not None]
    for k, level in levels:
        if type(level) is not int or not 0 <= level <= 1:
            _check_level(next(device for j, device in opens if j == k), level)
    return levels


def _check_level(device: Device, level: object) -> None:
    """RX-14: ``level``, ``device``'s ``constant_output`` after a data cycle's load, must be a level (0 or 1; a bool
    or a numpy integer passes): a model's 5 or 'x' was sent as 1 in silence."""
    if not (isinstance(level, numbers.Integral) and level in (0, 1)):
        raise InterbusError("RX-13", level, f"{type(device).__name__}.constant_output must be 0 or 1 after a data "
                            f"cycle's load (None while the frame shifts through), not {describe(level)}")


def _shift_open(registers: list[bytes], stream: bytes, levels: list[tuple[int, int]]) -> tuple[list[bytes], bytes, int]:
    """:func:`_shift` through registers of which those at the indices of ``levels`` send a constant line (RX-13): each
    of them takes in its bytes as any register, and what leaves it is its level in every bit of the stream's length
    (CRC and CNTR follow as on any line: a sender's CRC is over what it sends)."""
    received: list[bytes] = []
    size = len(stream)
    start = 0
    for k, level in levels:
        part, _, _ = _shift(registers[start : k + 1], stream)
        received += part
        stream = (b"\xff" if level else b"\x00") * size
        start = k + 1
    part, stream, _ = _shift(registers[start:], stream)
    return received + part, stream, sum(map(len, registers))


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
    branches: list[tuple[Terminal, bool, int | None]] = field(default_factory=list, repr=False)
    """In a tree: each bus terminal module whose whole branch this cycle drove, whether the master's telegrams came
    back on the branch's return line, and the count of the counter telegram received there."""
    spliced: bool = False
    """A branch joined the data path within this frame (BK-54): what came back was cut where its BK switched, so a
    receiver error is not on the return line N + 1 (BK-56); so too a receiver off the telegram grid after a chip's
    power-up (M22)."""
    return_repeaters: int = 0
    """Repeaters on the return lines of the cycle's ring (its LBD-MR devices, :func:`return_repeaters`): with
    :attr:`devices` they make the cycle's ring delay (A11, BK-55)."""


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

    @property
    def bit_rate(self) -> int:
        """The ring's bit rate in bit/s (Table 1-7)."""
        ...

    def transfer(self, cycle: Cycle, data: bytes, close_after: int | None = None) -> Transfer:
        """Send one frame's data and check sequences and the ring delay; return what came back."""
        ...

    def finish(self, transfer: Transfer, latch: bool) -> None:
        """End the cycle with the latch telegrams (``latch``) or idle ones; ``transfer`` is what this ring's last
        :meth:`transfer` returned, not finished yet (:func:`check_finish`)."""
        ...

    def reset(self) -> None:
        """INTERBUS reset (Alarm Stop)."""
        ...

    def idle(self, seconds: float) -> None:
        """Only idle status telegrams for ``seconds``."""
        ...


def check_transfer(cycle: object, data: object, close_after: object) -> tuple[bytes, int | None]:
    """The checks of a :class:`Bus`'s ``transfer``, made before the ring changes anything (a refused call leaves no
    trace: no branch recognised, no repair forgotten, no fibre's bit error drawn): ``cycle`` a :class:`Cycle`,
    ``data`` bytes (a ``bytes``, ``bytearray`` or ``memoryview``: an integer is no frame of that many zero bytes),
    ``close_after`` ``None`` or an integer from 0; ``data`` as ``bytes`` and ``close_after`` as an ``int``.

    Raises
    ------
    ArgumentError
        One of them is not what it must be.
    """
    if type(cycle) is not Cycle:
        check_instance("cycle", cycle, Cycle)
    stream = data if type(data) is bytes else check_bytes("data", data)
    return stream, None if close_after is None else check_int("close_after", close_after, 0)


def check_finish(transfer: object, pending: Transfer | None, latch: object) -> bool:
    """The checks of a :class:`Bus`'s ``finish``: ``transfer`` must be ``pending``, the :class:`Transfer` the ring's
    last ``transfer`` returned and no ``finish``, ``reset`` or ``idle`` has ended since (a cycle ends once, on the ring
    it ran on: another ring's transfer would latch that ring's devices on this ring's clock, a second finish latch them
    again), and ``latch`` a bool; ``latch`` as a bool.

    Raises
    ------
    ArgumentError
        ``transfer`` is not the pending transfer, or ``latch`` not a bool.
    """
    if transfer is not pending or pending is None:
        raise fail("transfer", "the Transfer this ring's last transfer() returned, not yet finished (a cycle ends "
                   "once, on its own ring)", transfer)  # fmt: skip
    return latch if latch is True or latch is False else check_bool("latch", latch)


_RINGS: Final[weakref.WeakValueDictionary[int, object]] = weakref.WeakValueDictionary()
"""UP-47: ``id`` of each device a live ring (a :class:`Ring`, a pin-level ``PinRing``) holds -> that ring. The ring
keeps its devices alive, so an ``id`` is its device's while the entry lives; the entry goes with the ring."""


def claim(ring: object, devices: Sequence[object]) -> None:
    """UP-47: ``ring`` takes ``devices``, none of which another live ring holds: one device object is one device in
    one place, and two rings (two benches) running it would mix its state (its registers, clock and loads) in
    silence. A ring no longer reachable but not yet collected (a reference cycle) is collected first, once. The
    pin-level ``PinRing`` claims its chips too (UP-49).

    Raises
    ------
    InterbusArgumentError
        A device another live ring holds (nothing is taken).
    """
    if any(id(device) in _RINGS for device in devices):
        gc.collect()  # only here: a dropped ring in a reference cycle (a bench) still holds its devices
        for k, device in enumerate(devices, 1):
            if id(device) in _RINGS:
                raise InterbusArgumentError(f"device at ring position {k}", device, f"device at ring position {k} "
                                            f"({type(device).__name__}) is in another live ring already: one device "
                                            "object is one device in one ring (two rings would mix its state); "
                                            "make a new device for this ring", "UP-47")  # fmt: skip
    for device in devices:
        _RINGS[id(device)] = ring


class Ring:
    """A master's ring of devices, at transaction level (docs/interbus.md, "Ring").

    Parameters
    ----------
    devices:
        The devices in ring order: ring position 1 is next to the master. A :class:`Branch` stands for its bus
        terminal module followed by its branch (a tree, docs/interbus.md "Tree"); :attr:`devices` is then the
        flattened data path, recomputed when a BK switches its branch (do not edit it in a tree).
    bit_rate:
        500 000 or 2 000 000 bit/s (Table 1-7); ``None``: the rate the devices with pin straps are strapped for
        (CLK_CONF), 500 000 when none is. A device strapped for another rate than the ring's is refused (UP-48).
    record:
        Keep a :class:`SegmentTrace` of every line of the last cycle in :attr:`trace` (slow; for tests).

    Attributes
    ----------
    now:
        Bus time in seconds.
    """

    _PLAIN: ClassVar[bool] = True
    """A29: a plain ring's data cycles take :meth:`_plain` (``False``: the general path, held to it by
    ``tests/test_cycle_caches.py``)."""

    closes_early: Final = True
    """The ring can be closed after any position (``transfer(close_after=...)``), for the segment search."""
    direct_return_line: Final = True
    """The return line N + 1 runs from device N straight into the master: an error the master's receiver finds
    is on that line (at pin level the return path runs through every chip, and :class:`PinRing` has neither
    attribute). A break of a return line before it (a :class:`ReturnBreak`, BK-59) brings back nothing: a dead line,
    which the segment search locates."""

    def __init__(self, devices: Sequence[Device | Branch], bit_rate: int | None = None, record: bool = False
                 ) -> None:  # fmt: skip
        if isinstance(devices, (str, bytes)) or not isinstance(devices, Sequence):
            raise fail("devices", "a sequence of devices", devices)
        if bit_rate is not None:
            bit_rate = wire.check_bit_rate(bit_rate)
        record = check_bool("record", record)  # every check before the devices are claimed (a refused ring holds none)
        every = _devices(devices) if all(isinstance(d, (Device, Branch)) for d in devices) else list(devices)
        if not 1 <= len(every) <= wire.MAX_DEVICES:
            raise InterbusArgumentError("devices", devices, f"devices must be 1 to {wire.MAX_DEVICES} devices "
                                        f"({_LIMIT_DEVICES}), not {len(every)}", _LIMIT_DEVICES)  # fmt: skip
        for k, device in enumerate(every, 1):
            if not isinstance(device, Device):
                raise fail(f"device at ring position {k}", "a Device (load, latch, discard, ...)", device)
        # UP-48, as the pin level's ring: every device runs at the ring's rate, its straps' (Table 1-7).
        strapped = [(k, device, config.bit_rate) for k, device in enumerate(every, 1)
                    if isinstance(config := getattr(device, "config", None), DeviceConfig)]  # fmt: skip
        self.bit_rate = bit_rate if bit_rate is not None else strapped[0][2] if strapped else 500_000
        for k, device, rate in strapped:
            if rate != self.bit_rate:
                raise InterbusArgumentError(f"device at ring position {k}", device, f"device at ring position {k} "
                                            f"is strapped for {rate} bit/s (CLK_CONF), not the ring's "
                                            f"{self.bit_rate}: every device of a ring runs at one bit rate",
                                            "Table 1-7")  # fmt: skip
        if len({id(d) for d in every}) != len(every):
            raise InterbusArgumentError("devices", devices, "devices must be distinct objects (one device is one "
                                        "place in the ring), not the same object twice", "Tree")  # fmt: skip
        claim(self, every)
        self._tree: list[Device | Branch] = list(devices)
        self._branches = _branches(self._tree)
        self._terminals = {id(branch.terminal) for branch in self._branches}
        self._enabled: tuple[bool, ...] = ()
        self._spans: list[_Span] = []
        self._settled = False
        """A BK's branch is in the data path by its recognition (BK-48) once the ring ran (a reset, a cycle, idle);
        before, as if every populated branch answered, so that faults are injected on the whole tree's lines."""
        self._unanswered: list[int] = []
        """The ring positions of the BKs whose branch is in the data path with nothing attached (BK-43): their branch
        return input carries nothing, as a :class:`ReturnBreak` there."""
        self._index: dict[int, int] = {}
        self._detached: dict[int, tuple[Device, float | None]] = {}
        self.devices: list[Device] = [d for d in self._tree if not isinstance(d, Branch)]
        self.record = record
        self.trace: list[SegmentTrace] = []
        self.now = 0.0
        self._faults: list[_Active] = []
        self._silent_since: dict[int, float] = {}
        self._silent_reset: set[int] = set()
        self._repaired: list[_Active] = []
        """In a tree: the breaks :meth:`clear_faults` removed since the ring last ran; a branch joining in the next
        cycle's run fails it with the error of its first repaired line (BK-56)."""
        # Caches of the data-cycle hot path, each for the last run it served: the run's devices, their groups and
        # the kernel of a run of one class; the registers loaded and the frame size, the registers joined, and the
        # slices that cut each device's received bytes.
        self._layout: tuple[list[Device], _Groups, DataKernel | None] = ([], [], None)
        self._cuts: tuple[list[bytes], int, bytes, list[slice] | None, int] = ([], -1, b"", None, 0)
        self._bits = ((-1, -1, -1), 0)  # (bytes sent, devices, return repeaters) of the last cycle, its cycle_bits
        self._pending: Transfer | None = None
        """What the last :meth:`transfer` returned, until :meth:`finish`, :meth:`reset` or :meth:`idle`."""
        self._wakes: dict[int, float] = {}
        """M22: ``id`` of a chip powered up by :meth:`power_up` -> bus time its reset stretch (M2) ends."""
        self._downs: dict[int, float] = {}
        """M26: ``id`` of a chip powered up by :meth:`power_up` -> bus time its power-down began (outputs silent)."""
        self._late: dict[int, float] = {}
        """M22: ``id`` of a chip -> bus time from which a frame finds it out of an INTERBUS reset it woke up in."""
        self._answers: dict[int, float] = {}
        """M25: ``id`` of a BK powered up by :meth:`power_up` -> bus time its branch's first start level is back on its
        synchronised DI3 (BK-37): its branch answers from then."""
        self._passed: dict[int, set[int]] = {}
        """BK-64: ``id`` of a BK with an answer due -> ``id`` of the breaks of its loop made after its start level
        passed them (:meth:`_pass_cut`): not in that answer's way."""
        self._woke_joins: set[int] = set()
        """M25: ``id`` of the BKs whose branch joins the data path within this cycle's frame after their power-up."""
        self._grid = 0.0
        """M22: bus time the master's idle status telegrams began (the end of its last cycle or reset)."""
        self._loops: tuple[list[Device], list[int]] = ([], [0])
        """The data path whose LBD-MR devices :meth:`_loops_before` counted last, the counts before each position."""
        self._plan: tuple[list[Device], _Groups, DataKernel | None, int, _Opens] = ([], [], None, 0, [])
        """A29: the plain ring's data-cycle plan (:meth:`_plain_plan`): a copy of :attr:`devices` as last planned, their
        groups for the data kernels, the kernel of a ring of one class, the ring's return repeaters and the devices
        whose data path can open (RX-13)."""
        self._open_run: tuple[list[Device], _Opens] = ([], [])
        """RX-13: the general path's last data-cycle run and its devices whose data path can open (:meth:`_opened`)."""
        _tell_following(self._tree)
        self._sync()

    # -- the tree ------------------------------------------------------------------------------------------------

    @property
    def tree(self) -> bool:
        """The ring has bus terminal modules with branches (:class:`Branch`)."""
        return bool(self._branches)

    @property
    def spans(self) -> list[tuple[int, int, BranchKind]]:
        """Every branch in the data path now: (ring position of its BK, ring positions its branch occupies (nested
        ones too), kind)."""
        return [(span.at + 1, span.end - span.at - 1, span.branch.kind) for span in self._spans]

    def _sync(self) -> None:
        """Flatten the tree again if a BK changed whether its branch is in the data path."""
        if not self._branches:
            return
        # A device answered on a recognised branch (BK-37, BK-48); one present without (by LBST) breaks at its BK
        # (BK-43).
        enabled = tuple(b.terminal.branch_enabled(self._answered(b)) for b in self._branches)
        if enabled == self._enabled and self._index:
            return
        self._enabled = enabled
        before = {id(self.devices[i]): t for i, t in self._silent_since.items() if i < len(self.devices)}
        was_reset = {id(self.devices[i]) for i in self._silent_reset if i < len(self.devices)}
        flat: list[Device] = []
        spans: list[_Span] = []

        def walk(items: Sequence[Device | Branch]) -> None:
            for item in items:
                if not isinstance(item, Branch):
                    flat.append(item)
                    continue
                at = len(flat)
                flat.append(item.terminal)
                if item.terminal.branch_enabled(self._answered(item)):
                    own = []
                    for device in item.devices:
                        own.append(len(flat))
                        walk((device,))
                    spans.append(_Span(item, at, len(flat), tuple(own)))

        walk(self._tree)
        self.devices = flat
        self._spans = sorted(spans, key=attrgetter("at"))
        self._unanswered = [span.at + 1 for span in self._spans if span.end == span.at + 1]
        self._index = {id(d): i for i, d in enumerate(flat)}
        self._silent_since = {self._index[k]: t for k, t in before.items() if k in self._index}
        self._silent_reset = {self._index[k] for k in was_reset if k in self._index}
        for device in _devices(self._tree):
            if id(device) not in self._index:
                self._detached.setdefault(id(device), (device, None))
            else:
                self._detached.pop(id(device), None)

    def _answered(self, branch: Branch) -> bool:
        """``connected`` of ``branch``'s BK: its recognition (BK-48), before the ring ran whether it is populated."""
        return branch.terminal.branch_recognised if self._settled else bool(branch.devices)

    def _recognise(self, now: float | None = None, frame: int | None = None) -> list[Branch]:
        """The ring runs (a reset, a cycle, idle telegrams): every BK whose branch device answers now recognises its
        branch (BK-48), then the tree flattens again; the branches recognised now. A branch with return lines (BK-RB,
        BK-LB) answers when its BK is reached, its interface is live (BK-42) and the loop from DO3 through the branch
        back to DI3 is whole; an LBD branch when its BK's return input is whole (its devices send counter telegrams on
        their own, BK-30).

        A BK powered up by :meth:`power_up` answers from its answer instant (M25), by bus time ``now`` (the run's time;
        :attr:`now` if ``None``); with ``frame`` (a cycle's frame of that many bits from ``now``) one answering before
        the frame's head reaches its BK joins before the frame (not returned), one answering while the frame passes
        joins within it (returned, BK-54), one answering later waits."""
        self._settled = True
        recognised: list[Branch] = []
        now = self.now if now is None else now
        lags = self._lags() if frame is not None and self._answers else []
        while True:
            self._sync()
            waiting = [b for b in self._branches if b.devices and not b.terminal.branch_recognised]
            if not waiting:
                return recognised
            forward = {id(a.target) for a in self._faults if isinstance(a.fault, DeadLine)}
            back = {(id(a.target), a.branch) for a in self._faults if isinstance(a.fault, ReturnBreak)}
            dead = self._first_dead()
            found = False
            for branch in waiting:
                at = self._index.get(id(branch.terminal))
                reached = at is not None and (dead is None or dead > at + 1) and branch.terminal.branch_enabled(True)
                due = self._answers.get(id(branch.terminal))
                passed = self._passed.get(id(branch.terminal)) if due is not None else None
                loop = (forward, back) if not passed else (  # BK-64: breaks its start level passed are no break
                    {id(a.target) for a in self._faults if isinstance(a.fault, DeadLine) and id(a) not in passed},
                    {(id(a.target), a.branch) for a in self._faults
                     if isinstance(a.fault, ReturnBreak) and id(a) not in passed})  # fmt: skip
                head = now
                if due is not None and frame is not None and at is not None:
                    # the frame's head leaving the BK: DO2 leaves its transmitter's line between telegrams (BK-47)
                    head += (lags[at] + wire.REPEATER_DELAY_BITS * wire.clocks_per_bit(self.bit_rate)) / CLOCK_HZ
                    if due > head + frame / self.bit_rate:
                        continue
                elif due is not None and due > now:
                    continue
                if (branch.kind.diagnostics or reached) and self._loop_whole(branch, *loop):
                    branch.terminal.recognise_branch()
                    self._answers.pop(id(branch.terminal), None)
                    self._passed.pop(id(branch.terminal), None)
                    found = True
                    if due is not None and frame is not None and (due <= head or branch.terminal.branch_enabled(False)):
                        # M25: joined before the frame, between telegrams (BK-47); M29: or in the data path without
                        # an answer (present by LBST, Table 2-9): DO2 repeats DI3 from the wake-up, nothing joins
                        continue
                    if due is not None:
                        self._woke_joins.add(id(branch.terminal))
                    recognised.append(branch)
                elif due is not None and due <= now:
                    # M25: nothing came back at the answer instant (a broken loop): it answers as any branch after
                    self._answers.pop(id(branch.terminal))
                    self._passed.pop(id(branch.terminal), None)
            if not found:
                return recognised

    def _loop_whole(self, branch: Branch, forward: set[int], back: set[tuple[int, bool]]) -> bool:
        """Something sent into ``branch`` comes back to its BK's DI3 (BK-48): its BK's return input is not broken
        (``back``: the devices whose return input is, with whether it is a BK's branch return input), and in a branch
        with return lines no line of the loop is (``forward``: the devices whose forward input is), nor the loop of a
        nested branch in the data path (its BK repeats its DI3 on DO2, BK-37). An LBD branch's devices send counter
        telegrams behind a break (BK-30)."""
        if not branch.devices or (id(branch.terminal), True) in back:
            return False
        for item in branch.devices:
            device = item.terminal if isinstance(item, Branch) else item
            if not branch.kind.diagnostics and (id(device) in forward or (id(device), False) in back):
                return False
            if isinstance(item, Branch) and item.terminal.branch_enabled(self._answered(item)) \
                    and not self._loop_whole(item, forward, back):
                return False
        return True

    def _silence_detached(self, start: float, end: float) -> None:
        """Devices of switched-off branches hear nothing: poll them, reset after the timeout (A13)."""
        for key, (device, since) in list(self._detached.items()):
            since = start if since is None else since
            if since >= 0.0 and end - since >= wire.IDLE_TIMEOUT_S:
                _timeout(device, since + wire.IDLE_TIMEOUT_S)
                since = -1.0  # reset once
            self._detached[key] = (device, since)
            device.poll(end)

    def _where(self, active: _Active) -> int | None:
        """The line a fault is on now (``None``: out of the data path); in a tree the line follows its device."""
        if not self._branches:
            return active.fault.segment
        if active.target is None:
            return len(self.devices) + 1
        index = self._index.get(id(active.target))
        if index is None or (active.branch and self._span_of(index, True) is None):
            return None
        return index + 1

    def _span_of(self, index: int, own: bool) -> _Span | None:
        """The innermost enabled branch whose BK (``own``) or whose device is at ``index``."""
        found = None
        for span in self._spans:
            if (own and span.at == index) or (not own and span.at < index < span.end):
                found = span
        return found

    def _returns(self, returns: list[tuple[int, bool]], close: int | None) -> tuple[int | None, bool]:
        """The effect of broken return lines (``returns``: 1-based positions, each with whether it is the BK's branch
        return input there or the return input from the device behind it, BK-52) on a transfer closed after ``close``
        (``None``: the whole ring): the first line that carries nothing on the way on (or ``None``), and whether
        nothing comes back from inside a branch the ring is closed in."""
        dead: int | None = None
        back_dead = False
        for position, own in returns:
            span = self._span_of(position - 1, own)
            # The return input from the device behind: behind a BK with its branch in the data path, after the branch.
            inner = None if own else self._span_of(position - 1, True)
            behind = position if inner is None else inner.end
            if (own and span is None) or not (close is None or close > behind):
                continue
            # Outside branches, the remote bus's return lines run back into the master: the whole ring (BK-59).
            end = len(self.devices) if span is None else span.end
            if close is None or close > end:
                dead = end + 1 if dead is None else min(dead, end + 1)
            else:
                back_dead = True
        return dead, back_dead

    def _reports(self, reached: int, close: int | None, dead_lines: list[int],
                 returns: list[tuple[int, bool]]) -> list[tuple[Terminal, bool, int | None]]:
        """What each BK whose whole branch was driven receives on its branch return line (docs/interbus.md,
        "Counter telegram")."""
        reports: list[tuple[Terminal, bool, int | None]] = []
        for span in self._spans:
            if span.at >= reached or not (close is None or close >= span.end):
                continue
            forward = [s for s in dead_lines if span.at + 2 <= s <= span.end]
            back = [p - 1 for p, own in returns if (own and p - 1 == span.at) or span.at < p - 1 < span.end]
            count = None
            if span.branch.kind.diagnostics:
                own = list(span.own)
                count = lbd_count(span.branch.kind, len(own), {own.index(s - 1) + 1 for s in forward},
                                  {0 if i == span.at else own.index(i) + 1 for i in back})  # fmt: skip
            reports.append((span.branch.terminal, not forward and not back, count))
        return reports

    # -- faults --------------------------------------------------------------------------------------------------

    def inject(self, fault: Fault) -> None:
        """Add a fault. Lines are 1..N + 1 (N + 1: the return line into the master); a :class:`ReturnBreak` only on
        a return line that exists: a BK's branch return input, or a return input :func:`return_inputs` names (the
        remote bus's too, BK-59; docs/interbus.md, "Tree")."""
        if not isinstance(fault, (BitFlip, Truncate, CorruptLoopback, DeadLine, ReturnBreak)):
            raise fail("fault", "a BitFlip, Truncate, CorruptLoopback, DeadLine or ReturnBreak", fault)
        self._sync()
        n = len(self.devices)
        if not 1 <= fault.segment <= n + (0 if isinstance(fault, ReturnBreak) else 1):
            raise InterbusError("docs/interbus.md, Fault injection", fault.segment,
                                f"line must be in 1..{n + (0 if isinstance(fault, ReturnBreak) else 1)}")  # fmt: skip
        target = None if fault.segment > n else self.devices[fault.segment - 1]
        branch = False
        if isinstance(fault, ReturnBreak):
            # A BK's branch return input whether or not the branch is in the data path now (BK-52); else the return
            # input from the device behind, by the one rule of positions (BK-59).
            branch = id(target) in self._terminals
            physical = next(k for k, device in enumerate(_devices(self._tree), 1) if device is target)
            if not branch and physical not in return_inputs(self._tree):
                raise InterbusError("docs/interbus.md, Tree", fault.segment,
                                    "a return line enters only a BK with a branch, or a device with return lines "
                                    "that has a device behind it (not the last of the ring or of a branch, none in "
                                    "an LBD-OR branch)")  # fmt: skip
        self._faults.append(_Active(fault, fault.cycles, target, branch))
        if self._answers:
            self._pass_cut(self._faults[-1])

    def cut(self, position: int, forward: bool, *, branch: bool = False) -> None:
        """Break a line for good, numbered as :meth:`PinRing.cut <supi3.model.pinring.PinRing.cut>` numbers it, by the
        physical position of the device it enters in every state (BK-52): ring positions 1..N of every device of the
        tree (a BK, then its branch's devices, nested branches in place, then on along the remote bus), whether a
        branch is in the data path or not. ``forward``: the line into the device (a :class:`DeadLine`; ``position``
        N + 1, one past the last device of the tree: the return line into the master, BK-61); else its
        return input from the device behind it in a branch with return lines (not into the last of a branch, none in
        an LBD-OR branch; a :class:`ReturnBreak`), or with ``branch`` a BK's branch return input (DI3). The break
        sleeps while its line is out of the data path (BK-1). The remote bus's return lines outside branches too
        (BK-59): nothing comes back to the master, the devices behind the break hear the frame and latch nothing.

        Raises
        ------
        ArgumentError
            ``forward`` or ``branch`` not a bool, ``position`` not a device of the tree (nor N + 1 with ``forward``),
            ``branch`` with ``forward`` or at a device that is no BK with a :class:`Branch`, or a return input no device
            drives; nothing changes.
        """
        check_bool("forward", forward)
        check_bool("branch", branch)
        every = _devices(self._tree)
        if forward and not branch:
            position = check_int("position", position, 1, len(every) + 1,
                                 "a device of the tree, or N + 1: the return line into the master")  # fmt: skip
        else:
            position = check_int("position", position, 1, len(every), "a device of the tree")
        if branch:
            terminals = terminal_positions(self._tree)
            if forward or position not in terminals:
                raise fail("position", f"the ring position of a BK with a branch ({sorted(terminals)}), with "
                           "forward=False (branch=True breaks the BK's branch return input)", (position, forward))
        elif not forward and position not in return_inputs(self._tree):
            raise fail("position", f"an integer from 1 to {len(every)} (a device of the tree; a return line only from "
                       "a device behind it: not into the last of the ring or of a branch, none in an LBD-OR branch, "
                       "BK-59)", position)  # fmt: skip
        fault: Fault = DeadLine(position) if forward else ReturnBreak(position)
        self._faults.append(_Active(fault, None, every[position - 1] if position <= len(every) else None, branch))
        if self._answers:
            self._pass_cut(self._faults[-1])

    def _pass_cut(self, active: _Active) -> None:
        """BK-64: a BK powered up whose answer is due (M25) answers through a break of its branch's loop made after its
        first start level passed the broken line (in the repeaters behind, it comes back on DI3 all the same, BK-37):
        a forward line once the device behind has sampled it mid-bit (M7), a return line or DI3 (wires, M5) once it
        began. A branch of devices with return lines (BK-RB, BK-LB; LBD branches answer by counter telegrams, BK-30)
        and no nested branch; the start level reaches the branch's first device a loop (:meth:`_loop_clocks`) before
        the answer, then the next a repeater later (A10), and comes back on the return lines from the last device's
        output."""
        cpb = wire.clocks_per_bit(self.bit_rate)
        delay = wire.REPEATER_DELAY_BITS * cpb
        for branch in self._branches:
            due = self._answers.get(id(branch.terminal))
            if due is None or branch.kind.diagnostics or any(isinstance(item, Branch) for item in branch.devices):
                continue
            out = due - self._loop_clocks(branch) / CLOCK_HZ  # the start level at the first device's input
            ids = [id(device) for device in branch.devices]
            if isinstance(active.fault, DeadLine) and id(active.target) in ids:
                at = out + (ids.index(id(active.target)) * delay + cpb // 2) / CLOCK_HZ
            elif isinstance(active.fault, ReturnBreak) and not active.branch and id(active.target) in ids:
                at = out + len(ids) * delay / CLOCK_HZ
            elif isinstance(active.fault, ReturnBreak) and active.branch and active.target is branch.terminal:
                at = due - SYNC_STAGES / CLOCK_HZ
            else:
                continue
            if at < self.now:
                self._passed.setdefault(id(branch.terminal), set()).add(id(active))

    def bit_error(self, position: int, bit: int, cycles: int | None = 1) -> None:
        """Invert bit period ``bit`` of the frame on the forward line into the device at ``position``, numbered as
        :meth:`cut` numbers it (the physical position in every state, BK-52; N + 1: the return line into the master),
        in the next ``cycles`` cycles whose data path holds that line (``None``: every one): a :class:`BitFlip` on
        that device's line, which follows it when positions move and sleeps while it is out of the data path (BK-1).
        ``PinRing.bit_error <supi3.model.pinring.PinRing.bit_error>`` is its pin-level twin, with the same arguments
        (BK-65).

        Raises
        ------
        ArgumentError
            ``position`` not from 1 to N + 1 (N: every device of the tree), ``bit`` not an integer >= 0 or ``cycles``
            not ``None`` or an integer >= 1; nothing changes.
        """
        every = _devices(self._tree)
        position = check_int("position", position, 1, len(every) + 1,
                             "a device of the tree, or N + 1: the return line into the master")  # fmt: skip
        flip = BitFlip(position, bit, cycles)
        self._faults.append(_Active(flip, flip.cycles, every[position - 1] if position <= len(every) else None))

    def clear_faults(self) -> None:
        """Remove every injected fault (a repair: in a tree the breaks removed decide the error of a cycle a branch
        joins within, BK-56)."""
        if self._branches:
            self._repaired += [a for a in self._faults if isinstance(a.fault, (DeadLine, ReturnBreak))]
        self._faults.clear()
        self._passed.clear()

    def _join_error(self, joined: list[Branch]) -> ErrorKind | None:
        """The error of a cycle within whose frame the branches ``joined`` join (BK-54): by the first line of the
        first one's loop repaired since the ring last ran (:func:`join_error`); ``None``: none joins the data path (an
        LBD branch recognised while out of it)."""
        span = next((span for span in self._spans if span.branch in joined), None)
        if span is None:
            return None
        forward = {id(a.target) for a in self._repaired if isinstance(a.fault, DeadLine)}
        first = next((k for k, index in enumerate(span.own) if id(self.devices[index]) in forward), None)
        if id(span.branch.terminal) in self._woke_joins:
            first = 0  # M25: the BK's DO3 resumed after its power-up, as the first device's forward input repaired
        return join_error(span.branch.kind, first)

    def _faults_on(self, segments: int) -> tuple[dict[int, list[Fault]], list[tuple[int, bool]]]:
        """The faults on lines 1..``segments`` now, by line, and the positions whose return line is broken, each with
        whether it is the BK's branch return input (a BK with nothing attached in the data path too, BK-43); each
        fault counts one of its cycles."""
        hits: dict[int, list[Fault]] = {}
        returns = [(at, True) for at in self._unanswered]
        for active in self._faults:
            where = self._where(active)
            if where is None:
                continue
            if isinstance(active.fault, ReturnBreak):
                returns.append((where, active.branch))
            elif where <= segments:
                hits.setdefault(where, []).append(active.fault)
            else:
                continue
            if active.remaining is not None:
                active.remaining -= 1
        self._faults = [a for a in self._faults if a.remaining is None or a.remaining > 0]
        return hits, returns

    def _breaks(self) -> tuple[list[int], list[tuple[int, bool]]]:
        """The lines broken now (``DeadLine``) and the positions whose return line is broken, with whether it is the
        BK's branch return input (a BK with nothing attached in the data path too, BK-43), without counting a fault's
        cycles."""
        lines = [(a, w) for a in self._faults if (w := self._where(a)) is not None]
        return ([w for a, w in lines if isinstance(a.fault, DeadLine)],
                [*((at, True) for at in self._unanswered),
                 *((w, a.branch) for a, w in lines if isinstance(a.fault, ReturnBreak))])  # fmt: skip

    def _first_dead(self) -> int | None:
        """The first line that carries nothing on the whole ring (broken return lines of branches too)."""
        dead, returns = self._breaks()
        first, _ = self._returns(returns, None)
        dead += [] if first is None else [first]
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

    def _load_run(self, cycle: Cycle, run: list[Device], now: float) \
            -> tuple[list[bytes], bool, _Groups | None, DataKernel | None]:  # fmt: skip
        """Every device's ``load(cycle, now)`` and whether one of them wants attention, through the devices' data
        kernels where the cycle and time allow; the groups used (``None`` if none) and, if the run is of one class
        with a kernel, that kernel. The groups are kept for the last run's classes."""
        if cycle is not Cycle.DATA or type(now) is not float or not 0.0 <= now < math.inf:
            return [device.load(cycle, now) for device in run], any(map(_ATTENTION, run)), None, None
        # Keyed on the devices themselves: the same objects have the same classes, and a list compares them by
        # identity first (about 2 µs for 512 devices, where listing their classes takes about 20)
        if run != self._layout[0]:
            groups = _group(run)
            self._layout = (run, groups, groups[0][2] if len(groups) == 1 else None)
        _, groups, single = self._layout
        if single is not None:
            registers, attention = single.load(run, now)
            return registers, attention, groups, single
        return *self._load_groups(run, groups, now), groups, None

    def _opened(self, run: list[Device]) -> list[tuple[int, int]]:
        """RX-13: after a data cycle's loads of ``run``, (index, level) of each of its devices that sends a constant
        line; the devices whose data path can open are kept for the last run (keyed on its devices, as A28's
        layout)."""
        if run != self._open_run[0]:
            self._open_run = (list(run), _opens(run))
        opens = self._open_run[1]
        return _levels(opens) if opens else []

    @staticmethod
    def _load_groups(run: list[Device], groups: _Groups, now: float) -> tuple[list[bytes], bool]:
        """A data cycle's loads of ``run`` by its ``groups`` (through each group's kernel, if it has one) at bus time
        ``now`` (a finite float), and whether one of the devices wants attention."""
        registers: list[bytes] = []
        attention = False
        for start, stop, kernel in groups:
            part = run[start:stop]
            if kernel is None:
                registers += [device.load(Cycle.DATA, now) for device in part]
                attention = attention or any(map(_ATTENTION, part))
            else:
                loaded, wants = kernel.load(part, now)
                registers += loaded
                attention = attention or wants
        return registers, attention

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
        if type(cycle) is not Cycle or type(data) is not bytes or close_after is not None:  # the master's own call
            data, close_after = check_transfer(cycle, data, close_after)  # passes these: no call for them
        now = self.now
        if not now <= wire.MAX_BUS_TIME_S:  # NaN too: the condition of check_bus_time, which raises
            wire.check_bus_time("cycle", cycle, now)
        if (self._PLAIN and cycle is _DATA and close_after is None and type(now) is float and now >= 0.0
                and not (self._branches or self._faults or self._unanswered or self._wakes or self._late
                         or self.record)):  # fmt: skip
            return self._plain(data, now)
        # A branch answering in this run joins the data path within its frame (BK-54): what leaves its BK is cut.
        joined = self._recognise(frame=wire.frame_bits(len(data))) if self._branches else []
        spliced = self._join_error(joined) if joined else None  # BK-56: the error of a branch joining the frame
        self._repaired = []
        self._woke_joins = set()
        n_all = len(self.devices)
        if n_all > wire.MAX_DEVICES:
            raise InterbusError("docs/interbus.md, Ring", n_all, f"a ring has at most {wire.MAX_DEVICES} devices")
        # A position beyond the ring (the master's table may be older than the ring) closes it at its last device.
        n = n_all if close_after is None else min(close_after, n_all)
        # Closed after a position (even the last), the ring returns inside that device: the return line N + 1
        # is only part of the whole ring (close_after=None), so a fault there is told from one on line N.
        segments = n + 1 if close_after is None else n
        faults: dict[int, list[Fault]] = {}
        returns: list[tuple[int, bool]] = []
        dead_lines: list[int] = []
        dead: int | None = None
        back_dead = False
        if self._faults or self._unanswered:
            faults, returns = self._faults_on(segments)
            dead_lines = [s for s, fs in faults.items() if any(isinstance(f, DeadLine) for f in fs)]
            dead = min(dead_lines, default=None)
            if returns:
                first, back_dead = self._returns(returns, None if close_after is None else n)
                dead = first if dead is None or (first is not None and first < dead) else dead
        if spliced is not None:
            cut = min(span.end + 1 for span in self._spans if span.branch in joined)
            # Only the whole ring, unbroken but for the joining branch, brings its cut frame back (BK-56).
            spliced = spliced if close_after is None and dead is None and not back_dead else ErrorKind.DEAD_LINE
            dead = cut if dead is None or cut < dead else dead
        self.trace = []
        record = self.record
        stream = bytes(data)
        shifted = 0
        crc: int | None = None
        attention = False
        error = False
        runs: list[_Run] = []
        devices = self.devices[: n if dead is None else min(n, dead - 1)]
        reached = last = n if dead is None else len(devices)  # n <= len(self.devices)
        woken: tuple[dict[int, int], int, list[int]] | None = None
        dropped = False  # M26: an LBD chip's counter block dropped telegrams of the frame in the window
        unheard = False
        if self._wakes or self._late:  # M22: a chip not on the telegram grid yet passes the frame on (M19)
            late, woken = self._waking()
            if spliced is ErrorKind.TRANSMISSION and woken is not None:
                # M25: a joining BK whose output resumed after the frame's head passed it sent no head: nothing
                # that opens a frame comes back, on its line before the join or on DI3 after it
                wakes, start, lags = woken
                at = next(span.at for span in self._spans if span.branch in joined)
                out = wake_window(self.bit_rate, len(self.devices), wakes, lags).resumed[at]
                spliced = ErrorKind.DEAD_LINE if out is not None and out > start + lags[at + 1] else spliced
            if late and faults:  # not modelled on a faulty ring: the master's receiver fails the cycle instead
                unheard = True
            elif late:
                devices = [device for index, device in enumerate(devices) if index not in late]
                last = len(devices)
        slow = range(last) if record else sorted(s - 1 for s in faults if s <= last) if faults else ()
        index = 0
        for stop in [*slow, last]:
            if index < stop:
                # Unfaulted lines: every receiver gets what its sender sent; no materialising, no CRC.
                run = devices if index == 0 and stop == last else devices[index:stop]  # devices: a copy already
                registers, wants, groups, kernel = self._load_run(cycle, run, now)
                attention = attention or wants
                levels = self._opened(run) if cycle is Cycle.DATA else None
                received, stream, width = _shift_open(registers, stream, levels) if levels \
                    else self._shift(registers, stream)
                runs.append(_Run(run, received, not error, False, groups, kernel))
                shifted += width
                crc = None
                index = stop
            if stop == last:
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
            levels = _levels(_opens([device])) if cycle is Cycle.DATA else None
            received, stream, width = _shift_open([register], line.stream, levels) if levels \
                else _shift([register], line.stream)
            runs.append(_Run([device], received, not (local or flags_in is None or flags_in.error), local))
            shifted += width
            crc = None
            index = stop + 1
        returned: bytes | None = None
        receiver_error: ErrorKind | None = None
        flags_back = _FLAGS[attention, error]
        if (dead is None or dead > segments) and not back_dead:
            returned = stream
            last = n + 1
            if record or last in faults:
                sent = _Line(stream, crc, wire.cntr_word(attention, error))
                line, receiver_error = self._receive(cycle, sent, faults.get(last, []), shifted)
                if record:
                    self.trace.append(SegmentTrace(last, sent.frame(cycle), line.frame(cycle), receiver_error))
                flags_back = wire.decode_cntr(line.cntr) or wire.CntrFlags(True, True)
                returned = line.stream
        elif record:
            silent = _Line(stream, crc, wire.cntr_word(attention, error))
            self.trace.append(SegmentTrace(segments if dead is None else dead, silent.frame(cycle), None, None))
        if spliced is ErrorKind.TELEGRAM:
            returned, receiver_error = stream, spliced
        opened = True
        if spliced is ErrorKind.TRANSMISSION:  # the frame comes back whole but for the join (BK-56)
            returned = stream
        if woken is not None and returned is not None:  # M22: the master's receiver, bit by bit in the window
            wakes, start, lags = woken
            chips = {index: device for index in wakes if isinstance(device := self.devices[index], WokenChip)}
            error, opened, dropped = counter_return(self.bit_rate, len(self.devices), wakes, start,
                                                Frame.build(cycle, returned), lags, *self._counter_lines(), chips=chips)
            unheard = unheard or error
            returned = returned if opened else None
        if unheard:  # not on the telegram grid yet: no fault of the return line N + 1
            receiver_error = receiver_error or ErrorKind.TELEGRAM
        elif (spliced is ErrorKind.TRANSMISSION or dropped) and opened:
            # M25: a frame whose head a woken chip's stretch cut comes back as no frame, whatever joins after it
            flags_back = wire.CntrFlags(attention, True)
        reports = self._reports(reached, None if close_after is None else n, dead_lines, returns) \
            if self._spans else []
        self._pending = Transfer(cycle, bytes(data), n, returned, flags_back, receiver_error, runs, reached, reports,
                                 spliced is not None or unheard, self._loops_before(n))
        return self._pending

    def _plain(self, data: bytes, now: float) -> Transfer:
        """A29: :meth:`transfer`'s data cycle through the whole of a plain ring (no fault, branch, chip waking up or
        record; bus time a finite float): what the general path gives there, one run on unfaulted lines whose CNTR
        flags only the devices' attention, with what depends only on the ring's devices planned once
        (:meth:`_plain_plan`)."""
        if self.trace:  # record was on before (the general path empties it every cycle)
            self.trace = []
        plan = self._plan  # A29's plan, worked out again only when the ring's devices differ (A31: no call else)
        run, groups, kernel, repeaters, opens = plan if self.devices == plan[0] else self._plain_plan()
        if kernel is not None:
            registers, attention = kernel.load(run, now)
        else:
            registers, attention = self._load_groups(run, groups, now)
        for _, device in opens:  # RX-13: a chip sending a constant line (no call while none does)
            if device.constant_output is not None:
                received, returned, _ = _shift_open(registers, data, _levels(opens))
                break
        else:
            received, returned, _ = self._shift(registers, data)
        n = len(run)
        self._pending = Transfer(_DATA, data, n, returned, _FLAGS[attention, False], None,
                                 [_new_tuple(_Run, (run, received, True, False, groups, kernel))], n, [], False,
                                 repeaters)  # fmt: skip
        return self._pending

    def _plain_plan(self) -> tuple[list[Device], _Groups, DataKernel | None, int, _Opens]:
        """A29: the plain ring's plan, worked out again only when :attr:`devices` holds other devices than last time
        (compared element by element, by identity first: the list edited in place is seen, as A28's layout)."""
        plan = self._plan
        devices = self.devices
        if devices != plan[0]:
            if len(devices) > wire.MAX_DEVICES:
                raise InterbusError("docs/interbus.md, Ring", len(devices),
                                    f"a ring has at most {wire.MAX_DEVICES} devices")  # fmt: skip
            run = list(devices)
            groups = _group(run)
            plan = self._plan = (run, groups, groups[0][2] if len(groups) == 1 else None,
                                 self._loops_before(len(run)), _opens(run))  # fmt: skip
        return plan

    def finish(self, transfer: Transfer, latch: bool) -> None:
        """End a cycle with the master's verdict: the latch telegrams (``latch``) or idle telegrams.

        Advances bus time by ``wire.cycle_bits``; a device latches only if its own check passed, no error was
        flagged upstream of it, and the master latches.

        Raises
        ------
        ArgumentError
            ``transfer`` is not what this ring's last :meth:`transfer` returned, or it was finished already, or a
            reset or idle came between (:func:`check_finish`); ``latch`` not a bool. Nothing changes.
        """
        if transfer is None or transfer is not self._pending or (latch is not True and latch is not False):
            latch = check_finish(transfer, self._pending, latch)  # raises (the master's own call passes)
        self._pending = None
        size = (len(transfer.sent), transfer.devices, transfer.return_repeaters)
        if size != self._bits[0]:
            self._bits = (size, wire.cycle_bits(size[0] - wire.LOOPBACK_BYTES, size[1], size[2]))
        bits = self._bits[1]
        start = self.now
        end = start + bits / self.bit_rate
        cycle = transfer.cycle
        kernels = cycle is _DATA and type(end) is float and 0.0 <= end < _INF
        if transfer.branches:  # before the latch telegrams, as a BK's closure at its frame's end (BK-50)
            frame = wire.frame_bits(len(transfer.sent))
            for terminal, traffic, count in transfer.branches:
                # The frame's end passes the BK REPEATER_DELAY_BITS later per repeater before it (A10, BK-55)
                before = self._index[id(terminal)]
                repeaters = before + self._loops_before(before)
                passed = start + (frame + wire.REPEATER_DELAY_BITS * repeaters) / self.bit_rate
                terminal.branch_returned(traffic, count, start, end, passed)
        for run in transfer.runs:
            if latch and run.eligible:
                if kernels and run.kernel is not None:  # a run of one class: its kernel at once
                    run.kernel.latch(run.devices, run.received, end)
                    continue
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
        if transfer.reached < len(self.devices):
            self._go_silent(range(transfer.reached, len(self.devices)), start, end)
        self.now = self._grid = end
        if self._branches:
            self._silence_detached(start, end)
            self._recognise()

    def _loops_before(self, n: int) -> int:
        """The return repeaters (:func:`return_repeaters`, BK-55) of the first ``n`` devices of the data path, counted
        again only when :attr:`devices` holds other devices than last time (a tree's switch, an edited plain ring; the
        list comparison takes the same object as equal at once: under a µs for 512 devices, where a scan takes 100)."""
        devices, counts = self._loops
        path = self.devices
        if devices != path:
            counts = list(accumulate(map(_return_repeater, path), initial=0))
            self._loops = (list(path), counts)
        return counts[n]

    @staticmethod
    def _latch_run(run: _Run, groups: _Groups, end: float) -> None:
        """Every device of a data cycle's run of several classes latches its received bytes, through the data
        kernels where its class has one."""
        for start, stop, kernel in groups:
            if kernel is not None:
                kernel.latch(run.devices[start:stop], run.received[start:stop], end)
                continue
            for device, received in zip(run.devices[start:stop], run.received[start:stop], strict=True):
                device.latch(Cycle.DATA, received, end)

    def _go_silent(self, indices: range, start: float, end: float) -> None:
        """Devices at ``indices`` heard nothing from ``start`` to ``end``: poll them, reset after the timeout; those
        behind an LBD chip of the stretch hear its counter telegrams (DG-9)."""
        counted = False
        for index in indices:
            since = self._silent_since.setdefault(index, start)
            device = self.devices[index]
            if index not in self._silent_reset and end - since >= wire.IDLE_TIMEOUT_S:
                _timeout(device, since + wire.IDLE_TIMEOUT_S, counted)
                self._silent_reset.add(index)
            device.poll(end)
            counted = counted or _sends_counts(device)

    def reset(self) -> None:
        """An INTERBUS reset (the master's Alarm Stop, 1303h): reset pattern, then idle (assumption A12). A branch is
        recognised in the reset's hold, before its devices reset (BK-37, BK-48). The reset's end allows for the ring
        delay of every device of the tree, which may all be in the data path after it (BK-9, A12; BK-53)."""
        wire.check_bus_time("reset", "INTERBUS reset", self.now)
        self._pending = None
        every = _devices(self._tree) if self._branches else self.devices
        end = self.now + wire.reset_bits(min(len(every), wire.MAX_DEVICES), return_repeaters(every)) / self.bit_rate
        self._recognise(end)  # in the hold (BK-37); a BK powered up answers by the reset's end (M25)
        self._repaired = []
        dead = self._first_dead()
        reached = len(self.devices) if dead is None else min(len(self.devices), dead - 1)
        for device in self.devices[:reached]:
            device.reset(end)
        self._go_silent(range(reached, len(self.devices)), self.now, end)
        if self._branches:
            self._silence_detached(self.now, end)
        if self._wakes:  # M22: a chip off the telegram grid at the hold may leave the reset late
            wakes = self._wake_clocks()
            ready = reset_ready(self.bit_rate, len(self.devices), wakes, round((self.now - self._grid) * CLOCK_HZ),
                                self._lags())
            self._late = {id(self.devices[index]): self._grid + at / CLOCK_HZ for index, at in enumerate(ready) if at}
        self.now = self._grid = end
        self._wakes = {}  # the master's receiver leaves the hold on the grid (a line reset, M11)
        self._sync()

    def power_up(self, position: int, down: float | None = None) -> None:
        """Power up the chip at ring ``position`` now (its power-up reset, 1.7.2): a master's cycle fails, as at pin
        level, until the chip and those behind it, then the master's receiver, are on the telegram grid (M22). In a
        tree ``position`` is the physical one (1..N over every device of the tree, a BK then its branch's devices, as
        :meth:`cut` numbers them, BK-52) and the window follows the data path's repeaters (M25); a BK's branch answers
        again once the first start level the BK sends after its wake-up is back on its DI3 (BK-37, M25), and joins the
        data path then: before a frame, within it (that cycle lost, BK-54) or after it.

        ``down``: the bus time the chip's power-down began (/ResU low, 1.7.2: its outputs silent from then; an LBD
        branch's counter blocks count that silence, BK-30, M26); ``None``: when the master's idle began (the end of
        its last cycle or reset), or the chip's previous wake-up in it if later.

        Raises
        ------
        ArgumentError
            ``position`` not a device of the ring (1 to N), the device there has no power-up reset (``power_up``),
            or ``down`` not a bus time from the master's idle's start to now; nothing changes.
        """
        every = _devices(self._tree) if self._branches else self.devices
        position = check_int("position", position, 1, len(every), "a device of the ring (of a tree: physical, BK-52)")
        device = every[position - 1]
        power_up = getattr(device, "power_up", None)
        if not callable(power_up):
            raise fail(f"device at ring position {position}", "a chip with a power-up reset (power_up)", device)
        if down is None:
            down = min(self.now, max(self._grid, self._wakes.get(id(device), self._grid)))
        else:
            down = check_real("down", down, self._grid, self.now, limit="M26: from the master's idle's start to now")
        power_up()
        self._downs[id(device)] = down
        self._wakes[id(device)] = self.now + round(RESET_MIN_S * CLOCK_HZ) / CLOCK_HZ  # the stretch, M2
        self._late.pop(id(device), None)
        if id(device) in self._terminals:  # M25: its recognition cleared (BK-37): the branch may leave the data path
            self._sync()
            self._answer(next(branch for branch in self._branches if branch.terminal is device))

    def _lags(self) -> list[int]:
        """M25: the clocks from the master's line to each device's input along the data path now, then to the master's
        receiver (:func:`~supi3.interbus.wake.path_lags`: every branch in it adds its return repeaters, BK-35, and its
        BK's synchroniser)."""
        branches = [(span.at, span.end, sum(_return_repeater(self.devices[i]) for i in span.own))
                    for span in self._spans]  # fmt: skip
        return path_lags(self.bit_rate, len(self.devices), branches)

    def _loop_clocks(self, branch: Branch) -> int:
        """M25: the clocks a start level takes from a BK's DO3 round its branch to the BK's synchronised DI3: a
        repeater a device (A10; a nested BK with its branch in the data path, that loop too), a repeater a LBD-MR
        device's return line (BK-35), the synchroniser (M1)."""
        delay = wire.REPEATER_DELAY_BITS * wire.clocks_per_bit(self.bit_rate)
        clocks = SYNC_STAGES
        for item in branch.devices:
            device = item.terminal if isinstance(item, Branch) else item
            clocks += delay * (1 + _return_repeater(device))
            if isinstance(item, Branch) and item.terminal.branch_enabled(self._answered(item)):
                clocks += self._loop_clocks(item)
        return clocks

    def _answer(self, branch: Branch) -> None:
        """M25: note when the branch of a BK just powered up answers: the BK's output resumes (M12, by
        :func:`~supi3.interbus.wake.wake_window` over the data path; its DO3 with its DO2) and that start level runs
        round the branch (:meth:`_loop_clocks`); a BK out of the data path answers at its next run, as before."""
        index = {id(device): k for k, device in enumerate(self.devices)}.get(id(branch.terminal))
        if index is None or not branch.devices:
            return
        if not branch.terminal.branch_enabled(True):  # DO3 idles (BK-42): only an LBD branch's counter telegrams
            # answer (BK-30), every 33 bit periods at a phase not followed: from the wake-up on, the earliest
            self._answers[id(branch.terminal)] = self._wakes[id(branch.terminal)] + SYNC_STAGES / CLOCK_HZ
            return
        resumed = wake_window(self.bit_rate, len(self.devices), self._wake_clocks(), self._lags()).resumed[index]
        assert resumed is not None  # the BK was just woken
        self._answers[id(branch.terminal)] = self._grid + (resumed + self._loop_clocks(branch)) / CLOCK_HZ

    def _wake_clocks(self) -> dict[int, int]:
        """M22: the ring index of each chip in the data path woken by :meth:`power_up` -> the clock its stretch ends,
        counted from the master's idle status telegrams."""
        index = {id(device): k for k, device in enumerate(self.devices)}
        return {index[key]: round((at - self._grid) * CLOCK_HZ) for key, at in self._wakes.items() if key in index}

    def _counter_lines(self) -> tuple[Counters, dict[int, int]]:
        """M26: the counter blocks along the data path now (an LBD chip's on its forward line, an LBD-MR branch's
        return blocks, BK-35) and the power-down of each chip woken in it, in clocks of the master's idle."""
        forward = frozenset(k for k, device in enumerate(self.devices) if _sends_counts(device))
        returns = tuple((span.end, tuple(i for i in reversed(span.own) if _return_repeater(self.devices[i])))
                        for span in self._spans if any(_return_repeater(self.devices[i]) for i in span.own))
        index = {id(device): k for k, device in enumerate(self.devices)}
        downs = {index[key]: round((self._downs[key] - self._grid) * CLOCK_HZ) for key in self._wakes if key in index}
        return Counters(forward, returns), downs

    def _waking(self) -> tuple[set[int], tuple[dict[int, int], int, list[int]] | None]:
        """M22: the ring indices of the chips a frame starting now finds off the telegram grid, and the wake-ups, the
        frame's start in clocks of the master's idle (:func:`~supi3.interbus.wake.wake_window`) and the data path's
        lags (M25); ``None`` past the window, which is then forgotten."""
        index = {id(device): k for k, device in enumerate(self.devices)}
        late = {index[key] for key, at in self._late.items() if key in index and self.now < at}
        self._late = {key: at for key, at in self._late.items() if self.now < at}
        wakes = self._wake_clocks()
        if not wakes:
            return late, None
        lags = self._lags()
        window = wake_window(self.bit_rate, len(self.devices), wakes, lags, *self._counter_lines())
        now = round((self.now - self._grid) * CLOCK_HZ)
        if now >= window.end:
            self._wakes = {}
            return late, None
        return late | {index for index, ready in enumerate(window.ready) if now < ready}, (wakes, now, lags)

    def idle(self, seconds: float) -> None:
        """The master sends only idle status telegrams for ``seconds`` (no cycles)."""
        seconds = check_real("seconds", seconds, 0.0)
        wire.check_bus_time("seconds", seconds, self.now, seconds)
        self._pending = None
        self._recognise()
        self._repaired = []
        dead = self._first_dead()
        reached = len(self.devices) if dead is None else min(len(self.devices), dead - 1)
        end = self.now + seconds
        for device in self.devices[:reached]:
            device.poll(end)
        self._go_silent(range(reached, len(self.devices)), self.now, end)
        if self._branches:
            for terminal, traffic, count in self._reports(reached, None, *self._breaks()):
                terminal.branch_returned(traffic, count, self.now, end)
            self._silence_detached(self.now, end)
        self.now = end
        if self._answers:
            self._recognise()  # M25: a BK powered up whose branch answered within the idle
        self._sync()

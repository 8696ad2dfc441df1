"""A ring of cycle-accurate chips driven at line level, one 32 MHz clock at a time.

:class:`PinRing` offers the interface of the transaction-level :class:`~supi3.interbus.ring.Ring` (the
:class:`~supi3.interbus.ring.Bus` protocol), so the same :class:`~supi3.interbus.master.Master` runs a scenario
on either fidelity. Here every bit of every telegram really travels: the master's line levels
(``wire.cycle_levels`` split into frame, ring delay and verdict) are expanded to 32 MHz samples, clocked through
each chip (forward line ``do1 -> do2``, return line ``di2 -> di1``), and the return line is received by a UART-style
receiver that resynchronises on every start edge. A chip is the core alone (:class:`~supi3.model.pins.Supi3Pins`) or
the whole chip (:class:`~supi3.top.Supi3Chip`: in the Init-µP modes with its serial µP interface on MFP[7..0], whose
pins :meth:`PinRing.set_input` holds (``mfp_in`` is 0 by default: give such a chip its µP's pins at rest,
``supi3.top.UP_REST``) or a software µP drives between runs, :class:`~supi3.spi.master.SoftMaster`).

A ring can be a tree (docs/interbus.md "Tree"): a :class:`PinBranch` is the pin-level twin of
:class:`~supi3.interbus.ring.Branch`, a bus terminal module (BK) chip with the chips of its branch. The BK sends on
DO3 (MFP9) into the branch's first chip and takes the branch's return line on DI3 (MFP10): the first chip's DI1, or
the last chip's DO2 in an LBD-OR branch (BK-37). The BK's outputs depend on DI3, which depends on its DO3 through the
branch, so a branch is closed by iteration on copies (BK-40): the BK runs on a copy with a guess of DI3, its branch
on a copy with the BK's DO3 gives the next guess, until the BK's DO3 comes back unchanged; then the chips themselves
run once with that DI3. An empty branch reads DI3 at the idle level, the pull-up the manual asks for on an unused
DI3 (BK-41).
"""

from __future__ import annotations

import copy
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Final, Protocol, runtime_checkable

import numpy as np
import numpy.typing as npt

from supi3.checks import (
    check_bits,
    check_bool,
    check_bytes,
    check_instance,
    check_int,
    check_real,
    check_trace,
    fail,
)
from supi3.config import DeviceConfig
from supi3.interbus import wire
from supi3.interbus.errors import InterbusError
from supi3.interbus.receiver import frame_start, receive
from supi3.interbus.ring import (
    BitFlip,
    Branch,
    BranchKind,
    ErrorKind,
    Transfer,
    check_finish,
    claim,
    return_inputs,
    return_repeaters,
    terminal_positions,
)
from supi3.interbus.wire import Cycle, Frame, LineReset, Telegram
from supi3.model.chip import Supi3
from supi3.model.pins import PinTrace, Supi3Pins
from supi3.pinlevel import Pin
from supi3.tables import CLOCK_HZ
from supi3.terminal import DI3_PIN, DO3_PIN


@runtime_checkable
class PinChip(Protocol):
    """A chip a :class:`PinRing` holds: :class:`~supi3.model.pins.Supi3Pins` or :class:`~supi3.top.Supi3Chip`. It
    runs whole traces forward first (its logic does not depend on DI2) and then gives the return line."""

    inputs: Sequence[Pin]
    outputs: Sequence[Pin]

    @property
    def chip(self) -> Supi3:
        """The chip's bus behaviour (the transaction-level model it drives)."""

    @property
    def config(self) -> DeviceConfig:
        """The pin straps (the ring reads the bit rate)."""

    @property
    def cycle(self) -> int:
        """Clock cycles since reset."""

    @property
    def branch_in_path(self) -> bool:
        """A BK's branch is in the data path now (:attr:`Supi3Pins.branch_in_path`); ``False`` for other chips."""

    def run_forward(self, inputs: Mapping[str, Sequence[int] | npt.NDArray[np.generic]]) -> dict[str, PinTrace]:
        """Every output but ``di1`` over the input traces (:meth:`Supi3Pins.run_forward`)."""

    def return_line(self, di2: PinTrace, do2: PinTrace) -> PinTrace:
        """``di1`` over the last :meth:`run_forward` (:meth:`Supi3Pins.return_line`)."""

@dataclass(frozen=True, eq=False)
class PinBranch:
    """A bus terminal module chip and the chips of its branch, in data-path order: the pin-level twin of
    :class:`~supi3.interbus.ring.Branch` (docs/interbus.md, "Tree"), checked by the same rules (Table 2-7, 2.2, 2.4:
    the BK's interface fits ``kind``, the branch's chips are in ``kind``'s interface, only a remote bus branch holds
    further branches).

    Parameters
    ----------
    terminal:
        The BK chip (:class:`PinChip` in a mode of Table 2-7).
    devices:
        The branch's chips and branches, first to last (none: nothing attached, BK-41).
    kind:
        What the branch is.
    """

    terminal: PinChip
    devices: Sequence[PinChip | PinBranch]
    kind: BranchKind

    def __post_init__(self) -> None:
        if not isinstance(self.terminal, PinChip):
            raise fail("terminal", "a Supi3Pins or Supi3Chip in a bus terminal mode (Table 2-7)", self.terminal)
        if isinstance(self.devices, (str, bytes)) or not isinstance(self.devices, Sequence) \
                or not all(isinstance(device, (PinChip, PinBranch)) for device in self.devices):
            raise fail("devices", "a sequence of Supi3Pins, Supi3Chip and PinBranch objects", self.devices)
        object.__setattr__(self, "devices", tuple(self.devices))
        self.transaction_level()  # Branch's checks, on the chips' bus behaviour

    def transaction_level(self) -> Branch:
        """The same tree over the chips' transaction-level models (:attr:`PinChip.chip`), as
        :class:`~supi3.interbus.ring.Branch` checks and describes it."""
        return Branch(self.terminal.chip, [_transaction_level(device) for device in self.devices], self.kind)


def _transaction_level(item: PinChip | PinBranch) -> Supi3 | Branch:
    return item.transaction_level() if isinstance(item, PinBranch) else item.chip


def _chips(items: Sequence[PinChip | PinBranch]) -> list[PinChip]:
    """Every chip of a tree in physical order: a BK, then its branch's chips (nested branches in place)."""
    found: list[PinChip] = []
    for item in items:
        if isinstance(item, PinBranch):
            found.append(item.terminal)
            found += _chips(item.devices)
        else:
            found.append(item)
    return found


def _in_path(items: Sequence[PinChip | PinBranch]) -> list[PinChip]:
    """The chips of a tree in the data path now: every chip, but a branch's only while its BK has it in the data path
    (BK-1's flattened data path, as ``Ring.devices`` holds it)."""
    found: list[PinChip] = []
    for item in items:
        if isinstance(item, PinBranch):
            found.append(item.terminal)
            found += _in_path(item.devices) if item.terminal.branch_in_path else []
        else:
            found.append(item)
    return found


@dataclass
class _BitError:
    """A bit error :meth:`PinRing.bit_error` injected: its line, the frame's bit period, the cycles left."""

    position: int
    bit: int
    remaining: int | None


IDLE_PIECE_TELEGRAMS: Final[int] = 64
"""The status telegrams :meth:`PinRing.idle` runs at a time (under 2 ms of bus time at 500 kbit/s): memory stays
bounded over an idle of any length, as every chip's pin traces of one run are held at once (about 260 bytes a clock:
one second of idle in one run took 8 GB)."""
APPLICATION_INPUTS: dict[str, int] = {
    pin.name: pin.width for pin in Supi3Pins.inputs if pin.name not in ("do1", "di2")
}
"""The input pins :meth:`PinRing.set_input` drives, with their widths (the line inputs are the ring's)."""


class PinRing:
    """INTERBUS master line -> chip 1 -> ... -> chip N -> return line, at pin level.

    Parameters
    ----------
    chips:
        The pin-level chips (:data:`PinChip`) in ring order (position 1 first), bus terminal modules with their
        branches as :class:`PinBranch`. All must run at the same bit rate.
    record:
        Keep every pin trace of every chip (for :meth:`recorded` and VCD files).

    Attributes
    ----------
    devices:
        Every chip in physical order: a BK, then its branch's chips (nested branches in place), then on along the
        remote bus; ring positions (:meth:`set_input`, :meth:`cut`) number them from 1.
    cycle:
        32 MHz clock cycles so far.
    returned:
        The return line's samples not yet received, from clock cycle :attr:`returned_from` on. What the master has
        received is dropped, so a long run keeps its memory flat.
    returned_from:
        The clock cycle of ``returned[0]``.
    """

    def __init__(self, chips: Sequence[PinChip | PinBranch], record: bool = False) -> None:
        if isinstance(chips, (str, bytes)) or not isinstance(chips, Sequence) \
                or not all(isinstance(chip, (PinChip, PinBranch)) for chip in chips):
            raise fail("chips", "a sequence of Supi3Pins or Supi3Chip objects and PinBranch trees", chips)
        every = _chips(chips)
        if len({id(chip) for chip in every}) != len(every):
            raise fail("chips", "distinct Supi3Pins or Supi3Chip objects (one per ring position)", chips)
        check_bool("record", record)
        if not chips:
            raise InterbusError("docs/interbus.md, Ring", 0, "a ring needs at least one device")
        rates = {chip.config.bit_rate for chip in every}
        if len(rates) != 1:
            raise InterbusError("Table 1-7", sorted(rates), "every device of a ring runs at one bit rate")
        self.tree: list[PinChip | PinBranch] = list(chips)
        """The ring's items as given (:class:`PinBranch` for a BK with its branch)."""
        self.devices = every
        self._loops = return_repeaters(every)
        self.repeaters = len(every) + self._loops
        """The repeaters a bit passes round the whole tree, each ``REPEATER_DELAY_BITS`` (A10): every chip on the
        forward line, and an LBD-MR chip once more on its return line (its counter block repeats it, M17). The end of
        an INTERBUS reset allows for them (A12: every branch may be in the data path after it, BK-9, BK-37); a cycle's
        ring delay (A11) only for those in the data path when it starts (:attr:`path_repeaters`, BK-53)."""
        transaction_level = [_transaction_level(item) for item in chips]
        self._return_inputs = return_inputs(transaction_level)
        self.bit_rate = rates.pop()
        self.cpb = wire.clocks_per_bit(self.bit_rate)
        self.cycle = 0
        self.returned = np.zeros(0, dtype=np.uint8)
        self.returned_from = 0
        self.record = record
        self.trials = 0
        """Runs of a branch's chips on copies so far (BK-40), for benches."""
        self._chunks: list[list[dict[str, npt.NDArray[np.int64]]]] = []
        self.cuts: set[tuple[int, bool]] = set()
        """Broken lines, as ``(position, forward)``: see :meth:`cut`."""
        self._pending: Transfer | None = None
        """What the last :meth:`transfer` returned, until :meth:`finish`, :meth:`reset` or :meth:`idle`."""
        self.branch_cuts: set[int] = set()
        """Positions of BKs whose branch return input DI3 is broken: see :meth:`cut`."""
        self.bit_errors: list[_BitError] = []
        """Bit errors still to hit a frame: see :meth:`bit_error`."""
        self._hits: dict[int, list[int]] = {}
        """The frame bit periods inverted on each line in the transfer running now (:meth:`bit_error`)."""
        self._frame: tuple[Cycle, int] = (Cycle.DATA, 0)
        """The cycle and data sequence length of the frame the transfer running now sends."""
        self._terminals = terminal_positions(transaction_level)
        self._inputs = [
            {"di2": 0, "rbst_ext": 0, "mfp_in": 0, "stat_err_n": 1, "resu_n": 1, "vmon_ok": 1, "from_exr": 0}
            for _ in every
        ]
        claim(self, every)  # UP-49, as a Ring's (UP-47); last, so that a ring refused on the way holds no chip

    @property
    def path_repeaters(self) -> int:
        """The repeaters of the chips in the data path now (:attr:`repeaters` of the data path, A10): a cycle's ring
        delay (A11) counts them, as the transaction level's cycle counts ``Ring.devices`` (BK-53); a branch closed,
        switched off or not recognised adds no delay (its BK sends on its own transmitter, BK-37)."""
        path = _in_path(self.tree)
        return len(path) + return_repeaters(path)

    @property
    def now(self) -> float:
        """Bus time in seconds."""
        return self.cycle / CLOCK_HZ

    def set_input(self, position: int, pin: str, value: int) -> None:
        """Drive an input pin of the chip at ring ``position`` (1..N) other than its line inputs.

        Raises
        ------
        ArgumentError
            ``position`` not from 1 to N, ``pin`` not one of :data:`APPLICATION_INPUTS`, or ``value`` not an integer
            within the pin's width (``mfp_in`` 0 to 0xFFFF, the others 0 or 1); nothing changes.
        """
        position = check_int("position", position, 1, len(self.devices))
        if not isinstance(pin, str) or pin not in APPLICATION_INPUTS:
            raise fail("pin", f"one of {', '.join(map(repr, APPLICATION_INPUTS))} (the line inputs are the ring's)",
                       pin, "docs/model.md")
        self._inputs[position - 1][pin] = check_bits(f"pin {pin!r}", value, APPLICATION_INPUTS[pin])

    def cut(self, position: int, forward: bool, *, branch: bool = False) -> None:
        """Break the line into the chip at ring ``position``: its forward input DO1 (``forward``, any chip; the first
        chip of a branch takes its BK's DO3; ``position`` N + 1, one past the last chip of the tree: the return line
        into the master, BK-61), or its return input DI2 from the chip behind it (a chip that has one:
        not the last of the ring or of a branch, none in an LBD-OR branch), or with ``branch`` (``forward`` false) a
        BK's branch return input DI3 (MFP10), the line ``ring.ReturnBreak`` breaks at a BK (BK-10). A broken line
        reads at the idle level (RS-485 fail-safe bias, BK-30); ``ring.Ring.cut`` takes the same arguments with the same
        physical numbering, in every state (BK-52). Behind a break the LBD chips' counter telegrams (2.2.2)
        bring the master, or the branch's BK, the count of ``ring.lbd_count`` (``forward``, ``back``) for a branch of
        these chips.

        Raises
        ------
        ArgumentError
            ``forward`` or ``branch`` not a bool, ``position`` out of range (1 to N, N + 1 with ``forward``), or
            ``branch`` with ``forward`` or at a chip that is not a BK with a branch (:class:`PinBranch`); nothing
            changes.
        """
        check_bool("forward", forward)
        check_bool("branch", branch)
        if forward and not branch:
            position = check_int("position", position, 1, len(self.devices) + 1,
                                 "a chip of the ring, or N + 1: the return line into the master")  # fmt: skip
        else:
            position = check_int("position", position, 1, len(self.devices), "a chip of the ring")
        if branch:
            if forward or position not in self._terminals:
                raise fail("position", f"the ring position of a BK with a branch ({sorted(self._terminals)}), with "
                           "forward=False (branch=True breaks the BK's DI3)", (position, forward))  # fmt: skip
            self.branch_cuts.add(position)
            return
        if not forward and position not in self._return_inputs:
            raise fail("position", f"an integer from 1 to {len(self.devices)} (a chip of the ring; a return line only "
                       "from a chip behind it: not into the last of the ring or of a branch, none in an LBD-OR branch)",
                       position)  # fmt: skip
        self.cuts.add((position, forward))

    def bit_error(self, position: int, bit: int, cycles: int | None = 1) -> None:
        """Invert bit period ``bit`` of the frame (0: its first start bit, ``wire.locate_bit``) on the forward line
        into the chip at ring ``position`` (numbered as :meth:`cut`; N + 1: the return line into the master), in the
        next ``cycles`` transfers (``None``: every one) whose data path holds that line: the pin-level twin of
        ``ring.Ring.bit_error`` (``ring.BitFlip`` by physical position, BK-65). The line's level is inverted for the
        ``clocks_per_bit`` samples of that bit period where the frame passes the line (``receiver.frame_start``); a
        bit period past the frame's end, or a line the whole frame does not reach in that transfer, is not hit (the
        transfer counts).

        Raises
        ------
        ArgumentError
            ``position`` not from 1 to N + 1, ``bit`` not an integer >= 0 or ``cycles`` not ``None`` or an integer
            >= 1; nothing changes.
        """
        position = check_int("position", position, 1, len(self.devices) + 1,
                             "a chip of the ring, or N + 1: the return line into the master")  # fmt: skip
        flip = BitFlip(position, bit, cycles)  # the transaction level's checks of bit and cycles
        self.bit_errors.append(_BitError(position, flip.bit, flip.cycles))

    def _aim(self, cycle: Cycle, data_bytes: int) -> None:
        """The bit errors that hit this transfer's frame (:meth:`bit_error`): each on a line in the data path now
        counts one of its cycles."""
        lines = {id(chip) for chip in _in_path(self.tree)}
        self._hits = {}
        self._frame = (cycle, data_bytes)
        every = [*self.devices, None]
        for error in self.bit_errors:
            chip = every[error.position - 1]
            if chip is None or id(chip) in lines:
                self._hits.setdefault(error.position, []).append(error.bit)
                error.remaining = None if error.remaining is None else error.remaining - 1
        self.bit_errors = [e for e in self.bit_errors if e.remaining is None or e.remaining > 0]

    def _hit(self, line: npt.NDArray[np.int64], position: int) -> npt.NDArray[np.int64]:
        """``line`` with this transfer's bit errors on the line into ``position`` (:meth:`bit_error`)."""
        start = frame_start(line, self.cpb, *self._frame)
        if start is None:
            return line
        hit = line.copy()
        for bit in self._hits[position]:
            if bit < wire.frame_bits(self._frame[1]):
                at = start + bit * self.cpb
                hit[at : at + self.cpb] ^= 1
        return hit

    def run_levels(self, levels: npt.NDArray[np.uint8]) -> None:
        """Send master line levels (one per bit period, 0 or 1) through the ring."""
        checked = check_trace("levels", levels, 1)
        self.run_samples(wire.levels_to_samples(checked.astype(np.uint8, copy=False), self.bit_rate))

    def run_samples(self, samples: npt.NDArray[np.uint8]) -> None:
        """Clock the ring once per sample of the master's forward line.

        Every chip runs the whole trace forward (``do1`` from its upstream neighbour's ``do2``, a branch's first
        chip's from its BK's DO3), then the return line is assembled from the last chip back to the first
        (:meth:`Supi3Pins.return_line`, :meth:`Supi3Chip.return_line`); a branch is closed first (BK-40).
        """
        forward = check_trace("samples", samples, 1).astype(np.int64, copy=False)
        n = len(forward)
        chunk: dict[int, dict[str, npt.NDArray[np.int64]]] | None = {} if self.record else None
        _, sent = self._forward(self.tree, 1, forward, chunk)
        back = self._back(sent, np.zeros(n, dtype=np.int64), chunk)
        if (len(self.devices) + 1, True) in self.cuts:  # the return line into the master (BK-61)
            back = np.full(n, wire.IDLE_LEVEL, dtype=np.int64)
        elif len(self.devices) + 1 in self._hits:
            back = self._hit(back, len(self.devices) + 1)
        if chunk is not None:
            self._chunks.append([chunk[k] for k in range(1, len(self.devices) + 1)])
        self.cycle += n
        self.returned = np.concatenate([self.returned, back.astype(np.uint8)])

    def _forward(self, items: Sequence[PinChip | PinBranch], first: int, line: npt.NDArray[np.int64],
                 chunk: dict[int, dict[str, npt.NDArray[np.int64]]] | None,
                 ) -> tuple[npt.NDArray[np.int64], list[tuple[PinChip, int, PinTrace]]]:
        """Run ``items`` (the first at ring position ``first``) forward on ``line``: what the last sends on, and each
        item's chip (a branch's BK), position and ``do2`` for :meth:`_back`."""
        sent = []
        position = first
        for item in items:
            if isinstance(item, PinBranch):
                chip = item.terminal
                outputs = self._branch(item, position, line, chunk)
                size = 1 + len(_chips(item.devices))
            else:
                chip, size = item, 1
                outputs = self._run(chip, position, line, None, chunk)
            line = outputs["do2"]
            sent.append((chip, position, line))
            position += size
        return line, sent

    def _back(self, sent: list[tuple[PinChip, int, PinTrace]], back: npt.NDArray[np.int64],
              chunk: dict[int, dict[str, npt.NDArray[np.int64]]] | None) -> npt.NDArray[np.int64]:
        """The return line through the chips :meth:`_forward` ran, from the last back to the first, ``back`` into the
        last: what the first sends back."""
        for chip, position, do2 in reversed(sent):
            if (position, False) in self.cuts:
                back = np.full(len(back), wire.IDLE_LEVEL, dtype=np.int64)
            if chunk is not None:
                chunk[position]["di2"] = back
            back = chip.return_line(back, do2)
            if chunk is not None:
                chunk[position]["di1"] = back
        return back

    def _run(self, chip: PinChip, position: int, line: npt.NDArray[np.int64], di3: npt.NDArray[np.int64] | None,
             chunk: dict[int, dict[str, npt.NDArray[np.int64]]] | None) -> dict[str, PinTrace]:
        """Run the chip at ``position`` forward with ``line`` on DO1 (broken: idle, BK-30) and, for a BK, ``di3``
        on DI3."""
        n = len(line)
        traces = {name: np.full(n, value, dtype=np.int64) for name, value in self._inputs[position - 1].items()}
        if (position, True) in self.cuts:
            line = np.full(n, wire.IDLE_LEVEL, dtype=np.int64)
        elif position in self._hits:
            line = self._hit(line, position)
        traces["do1"] = line
        traces["di2"] = np.zeros(n, dtype=np.int64)  # the return line comes in _back
        if di3 is not None:
            traces["mfp_in"] = traces["mfp_in"] & ~(1 << DI3_PIN) | di3 << DI3_PIN
        outputs = chip.run_forward(traces)
        if chunk is not None:
            chunk[position] = {**traces, **outputs}
        return outputs

    def _branch(self, branch: PinBranch, position: int, line: npt.NDArray[np.int64],
                chunk: dict[int, dict[str, npt.NDArray[np.int64]]] | None) -> dict[str, PinTrace]:
        """Run a BK at ``position`` with ``line`` on DO1 and its branch; the BK's outputs (BK-40).

        DI3 is the fixed point of guess -> the BK's DO3 -> the branch's return line, from the idle level, found on
        copies of the chips: a guess ``g`` gives the BK's DO3 ``d = B(g)`` and the branch's return line ``F(d)``, the
        next guess; once ``B(F(d)) == d`` the branch would return ``F(d)`` again, a fixed point. A loop through a
        branch delays by at least one repeater (3 bit periods, A10) and the BK reads DI3 through its synchroniser,
        so each guess is right for at least the loop's delay further than the one before: the iteration ends, at
        the latest after the run's length over that delay, and its fixed point is the one the chips would see (the
        line is causal). Usually the BK's DO3 does not depend on DI3 within a run, and two runs of the BK and one of
        the branch on copies find it. The chips then run once with it."""
        # Nothing attached: the pull-up (BK-41); DI3 broken: the idle level too (BK-30).
        di3 = np.full(len(line), wire.IDLE_LEVEL, dtype=np.int64)
        if branch.devices and position not in self.branch_cuts:
            do3 = None
            while True:
                outputs = self._run(copy.deepcopy(branch.terminal), position, line, di3, None)
                sent = (outputs["mfp_out"] >> DO3_PIN & 1).astype(np.int64)
                if do3 is not None and np.array_equal(sent, do3):
                    break
                do3 = sent
                self.trials += 1
                di3 = self._return(branch.kind, copy.deepcopy(branch.devices), position + 1, do3, None)
        outputs = self._run(branch.terminal, position, line, di3, chunk)
        if branch.devices:
            self._return(branch.kind, branch.devices, position + 1, (outputs["mfp_out"] >> DO3_PIN & 1).astype(
                np.int64), chunk)  # fmt: skip
        return outputs

    def _return(self, kind: BranchKind, devices: Sequence[PinChip | PinBranch], first: int,
                do3: npt.NDArray[np.int64], chunk: dict[int, dict[str, npt.NDArray[np.int64]]] | None,
                ) -> npt.NDArray[np.int64]:
        """Run a branch's ``devices`` (the first at ring position ``first``) with ``do3`` from their BK: the branch's
        return line into the BK's DI3, the first chip's DI1, or the last chip's DO2 in an LBD-OR branch."""
        end, sent = self._forward(devices, first, do3, chunk)
        back = self._back(sent, np.zeros(len(do3), dtype=np.int64), chunk)
        return (end if kind is BranchKind.LBD_OR else back).astype(np.int64, copy=False)

    def recorded(self) -> list[dict[str, npt.NDArray[np.int64]]]:
        """Every pin trace of every chip since the ring was made (``record=True``), chips in ring order."""
        if not self.record:
            raise InterbusError("docs/model.md", "record=False", "this ring does not record its pins")
        if not self._chunks:
            return [{} for _ in self.devices]
        return [
            {name: np.concatenate([chunk[k][name] for chunk in self._chunks]) for name in self._chunks[0][k]}
            for k in range(len(self.devices))
        ]

    def _received(self) -> tuple[list[Telegram | LineReset], bool]:
        telegrams, rx, error = receive(self.returned, 0, self.cpb)
        self.returned = self.returned[rx:]
        self.returned_from += rx
        return telegrams, error

    # -- the Bus protocol ------------------------------------------------------------------------------------------

    def transfer(self, cycle: Cycle, data: bytes, close_after: int | None = None) -> Transfer:
        """Send a frame and the ring delay; receive what came back (see :class:`~supi3.interbus.ring.Bus`)."""
        check_instance("cycle", cycle, Cycle)
        data = check_bytes("data", data)
        wire.check_bus_time("cycle", cycle, self.now)
        if close_after is not None:
            # The master does not ask (PinRing has no ``closes_early``): it reports such errors as not located.
            raise InterbusError("docs/interbus.md, Segment search", close_after,
                                "the pin-level ring does not close early")
        path = _in_path(self.tree)
        n = len(path)
        frame = Frame.build(cycle, data)
        loops = return_repeaters(path)
        delay = wire.ring_delay_status_telegrams(n, loops)
        if self.bit_errors:
            self._aim(cycle, len(data))
        try:
            self.run_levels(np.concatenate([wire.frame_levels(frame), wire.status_levels(cycle, False, delay)]))
        finally:
            self._hits = {}
        telegrams, error = self._received()
        receiver_error: ErrorKind | None = ErrorKind.TELEGRAM if error else None
        returned: bytes | None = None
        flags = wire.CntrFlags(True, True)
        try:  # counter telegrams alone are no frame (BK-49): a dead line
            back = wire.returned_frame(telegrams)
        except InterbusError:
            receiver_error = receiver_error or ErrorKind.SEQUENCE
        else:
            if back is not None:
                returned = back.data
                decoded = wire.decode_cntr(back.cntr)
                if decoded is None:
                    receiver_error = receiver_error or ErrorKind.CNTR
                else:
                    flags = decoded
                if wire.crc16(back.data) != back.crc:
                    receiver_error = receiver_error or ErrorKind.CRC
        self._pending = Transfer(cycle, bytes(data), n, returned, flags, receiver_error, [], n, return_repeaters=loops)
        return self._pending

    def finish(self, transfer: Transfer, latch: bool) -> None:
        """Send the verdict: the latch telegrams, or idle ones.

        Raises
        ------
        ArgumentError
            ``transfer`` is not what this ring's last :meth:`transfer` returned, or it was finished already, or a
            reset or idle came between (``ring.check_finish``); ``latch`` not a bool. Nothing changes.
        """
        latch = check_finish(transfer, self._pending, latch)
        self._pending = None
        self.run_levels(wire.status_levels(transfer.cycle, latch, wire.LATCH_STATUS_TELEGRAMS))
        self._received()

    def reset(self) -> None:
        """INTERBUS reset: the line held low, then idle status telegrams (``wire.reset_levels``)."""
        wire.check_bus_time("reset", "INTERBUS reset", self.now)
        self._pending = None
        self.run_levels(wire.reset_levels(len(self.devices), self._loops))
        self._received()

    def settle(self) -> None:
        """Idle status telegrams for the ring delay of the whole tree, so the last telegrams sent reach every chip."""
        delay = wire.ring_delay_status_telegrams(len(self.devices), self._loops)
        self.run_levels(wire.status_levels(Cycle.DATA, False, delay))
        self._received()

    def idle(self, seconds: float) -> None:
        """Idle status telegrams for ``seconds``."""
        check_real("seconds", seconds, finite=True)
        if seconds < 0:
            raise InterbusError("docs/interbus.md, Idle", seconds, "idle time must be >= 0")
        wire.check_bus_time("seconds", seconds, self.now, seconds)
        self._pending = None
        count = round(seconds * self.bit_rate / wire.STATUS_TELEGRAM_BITS)
        while count > 0:  # in pieces: the chips' traces of one run take about 260 bytes a clock
            piece = min(count, IDLE_PIECE_TELEGRAMS)
            self.run_levels(wire.status_levels(Cycle.DATA, False, piece))
            self._received()
            count -= piece

"""Bit errors on a line at both fidelities (issue 12, BK-65): ``PinRing.bit_error`` inverts the line's level for one
bit period of the frame where the frame passes the line, the pin-level twin of ``Ring.bit_error`` (a ``BitFlip``),
both numbered by the physical position as ``cut`` is (BK-52). A master locates a bit error of one cycle on every
forward line of every kind of tree (BK-RB, BK-LB, LBD-MR, LBD-OR) at the same position at both fidelities, by the
receiving chip's TE bit in the diagnostic ID cycle; an LBD branch's count is read at neither (BK-62: no interrupt).
Bit errors in a data field come back as the same error at both; in a telegram's start, type, select, control or stop
bit the pin-level chip loses the telegram (a telegram error or a dead line at the master, where the transaction level
passes the frame on with ERR: a transmission error), at the same position."""

from __future__ import annotations

import numpy as np
import pytest

from supi3.errors import ArgumentError
from supi3.interbus import wire
from supi3.interbus.master import Master
from supi3.interbus.receiver import frame_start
from supi3.interbus.ring import BranchKind, ErrorKind, Ring
from supi3.interbus.wire import Cycle, Frame
from supi3.model.pinring import PinRing
from test_model_pinring_tree import healthy, pin_tree, tl_tree

DATA_BIT = wire.DATA_TELEGRAM_BITS + wire.POS_DATA + 2
"""A bit period in the data field of the frame's second telegram."""
HEADER_BITS = [wire.DATA_TELEGRAM_BITS * k + offset for k, offset in
               ((1, wire.POS_START), (3, wire.POS_TYPE), (1, wire.POS_SELECT), (6, wire.POS_CONTROL),
                (1, wire.DATA_TELEGRAM_BITS - 1))]  # fmt: skip
"""A start, type, select, control and stop bit period of telegrams of the frame."""


def hit(ring: Ring | PinRing, position: int, bit: int) -> tuple[bool, list[tuple[ErrorKind, int | None]], bool]:
    """A master's cycle with one bit error on the line into ``position`` after a latched data cycle: its success, its
    diagnostics (kind, location) and whether the next cycle passes."""
    master = Master(ring, max_devices=8)
    assert master.start().ok
    healthy(master)
    ring.bit_error(position, bit)
    result = master.cycle()
    return result.ok, [(d.kind, d.location) for d in result.diagnostics], master.cycle().ok


def both(kind: BranchKind, m: int, position: int, bit: int) -> list[tuple[bool, list[tuple[ErrorKind, int | None]],
                                                                          bool]]:  # fmt: skip
    return [hit(tl_tree(kind, m), position, bit), hit(pin_tree(kind, m), position, bit)]


@pytest.mark.parametrize("kind", list(BranchKind))
def test_a_bit_error_is_located_on_its_line_at_both_fidelities(kind: BranchKind) -> None:
    """BK-65 (BK-62's pin-level twin): RB, BK with one branch device, RB: a data-field bit error on the line into the
    branch's device (the BK's DO3) is the same transmission error located there at both; a start bit on the line
    into the device after the branch (the BK's DO2) is located there at both, the kind aside."""
    tl, pin = both(kind, 1, 3, DATA_BIT)
    assert tl == pin == (False, [(ErrorKind.TRANSMISSION, 3)], True)
    tl, pin = both(kind, 1, 4, HEADER_BITS[0])
    assert (tl[0], tl[1][0][1], tl[2]) == (pin[0], pin[1][0][1], pin[2]) == (False, 4, True), (tl, pin)


@pytest.mark.slow
@pytest.mark.parametrize("kind", list(BranchKind))
def test_every_bit_error_is_located_alike_on_every_line(kind: BranchKind) -> None:
    """BK-65 on every forward line of the tree RB, BK with 2 branch devices, RB and the return line into the master, a
    data-field bit and a start, select and stop bit: lines
    1..N alike at both (the kind too for a data field); the return line into the master: at its line N + 1 at
    transaction level (one line into the master), not located at pin level (no chip has TE: the return path runs
    through every chip, master._check)."""
    n = 5
    for position in range(1, n + 2):
        for bit in [DATA_BIT, *HEADER_BITS[::2]]:
            tl, pin = both(kind, 2, position, bit)
            where = [diagnostics[0][1] for _, diagnostics, _ in (tl, pin)]
            assert not tl[0] and not pin[0] and tl[2] and pin[2], (position, bit, tl, pin)
            assert where == ([position, position] if position <= n else [n + 1, None]), (position, bit, tl, pin)
            if bit == DATA_BIT and position <= n:
                assert tl == pin, (position, bit)


@pytest.mark.parametrize("kind", [BranchKind.LBD_OR, pytest.param(BranchKind.LOCAL, marks=pytest.mark.slow)])
def test_a_bit_error_sleeps_out_of_the_data_path_and_counts_its_cycles_alike(kind: BranchKind) -> None:
    """A bit error on a line of a switched-off branch hits nothing until the branch is back; ``cycles`` counts the
    transfers whose data path holds the line, at both fidelities alike (every cycle's success and diagnostics)."""
    seen = []
    for ring in (tl_tree(kind, 1), pin_tree(kind, 1)):
        master = Master(ring, max_devices=8)
        assert master.start().ok
        master.switch_branch(2, False)
        healthy(master)
        ring.bit_error(3, DATA_BIT, 2)
        results = [master.cycle() for _ in range(2)]
        master.switch_branch(2, True)
        results += [master.cycle() for _ in range(6)]
        seen.append([(r.ok, [(d.kind, d.location) for d in r.diagnostics]) for r in results])
    assert seen[0] == seen[1]
    assert [ok for ok, _ in seen[0]].count(False) == 2


@pytest.mark.parametrize("ring", [lambda: tl_tree(BranchKind.LBD_MR, 1), lambda: pin_tree(BranchKind.LBD_MR, 1)])
@pytest.mark.parametrize(("args", "name"), [((0, 3), "position"), ((6, 3), "position"), ((3, -1), "bit"),
                                            ((3, 3, 0), "cycles"), ((3, 1.5), "bit")])  # fmt: skip
def test_bit_error_refuses_bad_input_by_name(ring: object, args: tuple[object, ...], name: str) -> None:
    built = ring()  # type: ignore[operator]
    with pytest.raises(ArgumentError, match=name):
        built.bit_error(*args)


def test_frame_start_finds_the_frame_behind_a_telegram_cut_anywhere() -> None:
    """``receiver.frame_start``: a frame behind idle status telegrams whose first one the trace cuts at any bit, at
    both bit rates; a trace without the whole frame has none."""
    frame = Frame.build(Cycle.ID, wire.LOOPBACK_BYTES_ON_LINE + bytes(4))
    for rate in (500_000, 2_000_000):
        cpb = wire.clocks_per_bit(rate)
        levels = np.concatenate([wire.status_levels(Cycle.ID, False, 4), wire.frame_levels(frame),
                                 wire.status_levels(Cycle.ID, False, 2)])  # fmt: skip
        samples = wire.levels_to_samples(levels, rate)
        before = 4 * wire.STATUS_TELEGRAM_BITS * cpb
        for cut in range(0, before, 7):
            assert frame_start(samples[cut:], cpb, Cycle.ID, len(frame.data)) == before - cut
        assert frame_start(samples[: before + cpb * 20], cpb, Cycle.ID, len(frame.data)) is None
        assert frame_start(samples, cpb, Cycle.DATA, len(frame.data)) is None

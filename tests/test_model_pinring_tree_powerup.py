"""A chip's power-up in a tree at both fidelities (M22, M25 of docs/assumptions/model.md; manual 1.7.2, 2.4; BK-37,
BK-54, BK-56): ``Ring.power_up`` takes any device of a tree by its physical position (a remote bus device, the BK, a
branch device) and the transaction level fails and passes the same cycles as the pin level
(:class:`~supi3.model.pinring.PinRing` with /ResU held low), with the same error kinds: the window of the woken chip
and of those behind it along the data path (its repeaters, a branch's return repeaters and its BK's synchroniser), and
after a BK's power-up its branch's answer (the first start level the BK sends after its wake-up, back on its DI3) that
joins the branch before, within (the cycle lost, BK-54) or after the master's next frame.
"""

from __future__ import annotations

import functools
import pickle

import pytest

from supi3 import tables
from supi3.config import DeviceConfig, decode
from supi3.errors import ArgumentError
from supi3.interbus.master import Master
from supi3.interbus.ring import Branch, BranchKind, ErrorKind, Ring
from supi3.interbus.wake import Counters, counter_return, wake_return
from supi3.interbus.wire import Cycle, Frame
from supi3.model.chip import Supi3
from supi3.model.pinring import PinBranch, PinRing
from supi3.model.pins import Supi3Pins
from support import BK_STRAPS
from test_model_pinring_powerup import idle, power_cycle
from test_model_pinring_tree import CASES, INPUTS, LBST, ROWS

RATES = [500_000, 2_000_000]
FIRST_IDLE_TELEGRAMS = 12
"""Idle status telegrams after the ring's first clock before the master's start: past every chip's wake-up window."""


def _config(row: str, rate: int) -> DeviceConfig:
    found = next(r for r in tables.MODE_ROWS if r.function == row)
    return decode(found.c, found.mfp, clk_conf=tables.clk_conf_for(rate))


def _bk(kind: BranchKind, rate: int) -> DeviceConfig:
    return decode(BK_STRAPS[kind.terminal], rf="11", clk_conf=tables.clk_conf_for(rate))


def trees(kind: BranchKind, m: int, rate: int) -> tuple[Ring, PinRing]:
    """RB device, BK (RF = 11, LBST = 1) with ``m`` branch devices of ``kind``, RB device at ``rate``, at both
    fidelities, every chip powered up at the ring's first clock (``Ring.power_up`` at transaction level)."""
    bk = Supi3(_bk(kind, rate))
    bk.set_mfp_inputs(LBST)
    chips = [Supi3(_config(ROWS[BranchKind.REMOTE], rate)), *(Supi3(_config(ROWS[kind], rate)) for _ in range(m)),
             Supi3(_config(ROWS[BranchKind.REMOTE], rate))]  # fmt: skip
    for chip, value in zip(chips, [0x5A, *INPUTS], strict=False):
        chip.set_mfp_inputs(value)
    tl = Ring([chips[0], Branch(bk, chips[1:-1], kind), chips[-1]], bit_rate=rate)
    for position in range(1, m + 4):
        tl.power_up(position)
    pin = PinRing([Supi3Pins(_config(ROWS[BranchKind.REMOTE], rate)),
                   PinBranch(Supi3Pins(_bk(kind, rate)), [Supi3Pins(_config(ROWS[kind], rate)) for _ in range(m)],
                             kind),
                   Supi3Pins(_config(ROWS[BranchKind.REMOTE], rate))])  # fmt: skip
    pin.set_input(2, "mfp_in", LBST)
    for position, value in zip([1, *range(3, m + 4)], [0x5A, *INPUTS], strict=False):
        pin.set_input(position, "mfp_in", value)
    return tl, pin


Seen = list[tuple[bool, list[ErrorKind], bool]]
"""Per cycle: its success, its error kinds, whether the BK recognised its branch after it."""


def _start(ring: Ring | PinRing) -> Master:
    """The part every run of :func:`after_power_up` shares: idle past the wake-up, the master's start and a data
    cycle."""
    idle(ring, FIRST_IDLE_TELEGRAMS)
    master = Master(ring, locate=False, max_devices=8)
    assert master.start().ok and master.cycle().ok
    return master


@functools.cache
def _started(kind: BranchKind, m: int, rate: int) -> bytes:
    """:func:`trees`' pin-level ring after :func:`_start`, pickled with its master."""
    pin = trees(kind, m, rate)[1]
    return pickle.dumps((pin, _start(pin)))


def _pin_seen(kind: BranchKind, m: int, rate: int, position: int, telegrams: int) -> Seen:
    """:func:`after_power_up` on :func:`trees`' pin-level ring, from a fresh copy of the ring and its master after
    :func:`_start`. The models are deterministic and the pickled copy holds their whole state, so the run from it is
    the run from the ring's first clock (:func:`test_a_started_pin_tree_runs_on_as_a_fresh_one`): the sweep of
    :func:`_window` starts its pin-level runs from one copy instead of running the same start again for every
    position and k (tests/README.md, "Run time"). Not the transaction level: its ``Ring`` keys state by ``id()``, and
    its runs are short."""
    ring, master = pickle.loads(_started(kind, m, rate))
    return after_power_up(ring, position, telegrams, master)


def after_power_up(ring: Ring | PinRing, position: int, telegrams: int, master: Master | None = None) -> Seen:
    """The master starts and runs a data cycle (unless its ``master`` has: :func:`_pin_seen`); the chip at
    ``position`` powers up, ``telegrams`` idle status telegrams, two cycles: per cycle its success and error kinds,
    and whether the BK recognised its branch then."""
    if master is None:
        master = _start(ring)
    power_cycle(ring, position)
    idle(ring, telegrams)
    seen: Seen = []
    for _ in range(2):
        result = master.cycle()
        bk = ring.devices[1]
        recognised = bk.branch_connected if isinstance(bk, Supi3Pins) else isinstance(bk, Supi3) and \
            bk.branch_recognised
        seen.append((result.ok, [d.kind for d in result.diagnostics], recognised))
    return seen


RESIDUAL = {(2_000_000, BranchKind.LBD_MR, 1, 2): (3, 3), (2_000_000, BranchKind.LBD_MR, 2, 2): (4, 5),
            (2_000_000, BranchKind.LBD_MR, 3, 2): (5, 6), (500_000, BranchKind.LBD_MR, 1, 2): (2, 2),
            (500_000, BranchKind.LBD_MR, 2, 2): (3, 4), (500_000, BranchKind.LBD_MR, 3, 2): (4, 5)}
"""M25's limit 1 (``python bench/wake_tree_sweep.py window --rate R``): (bit rate, tree, physical position) -> the
first passing k at transaction level and at pin level, where the cycles before are compared by success only. The BK's
power-up in an LBD-MR branch: with 1 device the cycles before fail with ``TRANSMISSION`` at pin level and
``DEAD_LINE`` at transaction level (BK-56's LBD-MR rule), with 2 and 3 devices the pin level loses one more cycle (its
switch, BK-47, later than ``Ring._answer``; no counter block drives there, M26). The second device of an LBD-MR branch
powered up (the first device's return block generating a counter telegram, BK-30) is followed since M26 and alike."""


def _window(kind: BranchKind, m: int, rate: int, positions: range) -> list[int]:
    """Per physical position of ``positions``, the first k from which the cycle after the power-up passes at
    transaction level; the cycle then and the one before (k - 1) alike at pin level, kinds and recognition too
    (:data:`RESIDUAL` aside)."""
    firsts = []
    for position in positions:
        tl_seen = [after_power_up(trees(kind, m, rate)[0], position, k) for k in range(14)]
        first = next(k for k, seen in enumerate(tl_seen) if seen[0][0])
        residual = RESIDUAL.get((rate, kind, m, position))
        for k in range(max(0, first - 1), first + 1):
            pin = _pin_seen(kind, m, rate, position, k)
            if residual is None:
                assert pin == tl_seen[k], (position, k, tl_seen[k])
            else:
                assert pin[0][0] is (k >= residual[1]) and tl_seen[k][0][0] is (k >= residual[0]), (position, k, pin)
        firsts.append(first)
    return firsts


def test_a_started_pin_tree_runs_on_as_a_fresh_one() -> None:
    """The copy :func:`_window` starts its pin-level runs from gives what the same run from the ring's first clock
    gives: the BK of a 2-device LBD-MR branch (within its window at k = 3, ``RESIDUAL``) and its second branch device
    (M26), a copy each."""
    for position, k in ((2, 3), (4, 1)):
        fresh = after_power_up(trees(BranchKind.LBD_MR, 2, 2_000_000)[1], position, k)
        assert _pin_seen(BranchKind.LBD_MR, 2, 2_000_000, position, k) == fresh, (position, k)


@pytest.mark.parametrize(("kind", "m"), CASES)
def test_a_bk_s_power_up_ends_its_window_alike(kind: BranchKind, m: int) -> None:
    """M25 over the trees of ``CASES`` at 2 Mbit/s: the BK powered up in a running tree, k idle status telegrams, two
    cycles: the first passing k is the same at both fidelities (BK-54: the cycle its branch joins within is lost at
    both, or the branch joins before it), and that cycle and the one before fail or pass alike, with the same error
    kinds and the same recognition (but :data:`RESIDUAL`)."""
    assert _window(kind, m, 2_000_000, range(2, 3))[0] >= 1  # the BK's own window, then its branch's answer


@pytest.mark.slow
@pytest.mark.parametrize("rate", RATES)
@pytest.mark.parametrize(("kind", "m"), CASES)
def test_the_window_after_a_power_up_in_a_tree_ends_alike(kind: BranchKind, m: int, rate: int) -> None:
    """M25, exhaustively over the trees of ``CASES`` at both bit rates: any one chip (a remote bus device, the BK, a
    branch device) powered up in a running tree: as :func:`test_a_bk_s_power_up_ends_its_window_alike` (at 500 kbit/s
    every cycle of k = 0..7 alike: ``python bench/wake_tree_sweep.py window --rate 500000``)."""
    _window(kind, m, rate, range(1, m + 4))


@pytest.mark.parametrize(("rate", "m", "ks"), [(2_000_000, 2, range(3)), (500_000, 3, range(1, 3))])
def test_an_lbd_mr_device_s_power_up_follows_the_counter_generator(rate: int, m: int, ks: range) -> None:
    """M26: the second device of an LBD-MR branch powered up in a running tree: its return output is silent longer
    than ``COUNTER_SILENCE_BITS`` (from its power-down through its stretch), the return block of the device before it
    generates a counter telegram and drops what begins meanwhile (BK-30), the frame's head too for the first k (the
    chip behind flags it: ``TRANSMISSION``), then repeats on the master's grid: every cycle, its error kinds and the
    recognition alike at both fidelities (before M26: ``LOOPBACK`` for ``TRANSMISSION``, and at 500 kbit/s
    ``TELEGRAM`` until k = 7 where the pin level passes from k = 2)."""
    for k in ks:
        tl, pin = trees(BranchKind.LBD_MR, m, rate)
        assert after_power_up(tl, 4, k) == after_power_up(pin, 4, k), k


def test_a_power_down_is_named_by_its_bus_time() -> None:
    """M26: ``Ring.power_up``'s ``down`` is a bus time from the master's idle's start to now, else refused by name;
    ``counter_return`` refuses counters or power-downs that name no chip."""
    tl, _ = trees(BranchKind.LBD_MR, 2, 2_000_000)
    for bad in (-1.0, tl.now + 1.0, "0"):
        with pytest.raises(ArgumentError, match=r"^down must be"):
            tl.power_up(4, down=bad)  # type: ignore[arg-type]
    tl.power_up(4, down=tl.now)
    frame = Frame.build(Cycle.DATA, bytes(4))
    with pytest.raises(ArgumentError, match=r"^counters must be"):
        counter_return(2_000_000, 3, {1: 10}, 0, frame, None, Counters(frozenset({3})))
    with pytest.raises(ArgumentError, match=r"^counters must be"):
        counter_return(2_000_000, 3, {1: 10}, 0, frame, None, "forward")  # type: ignore[arg-type]
    with pytest.raises(ArgumentError, match=r"^downs must be"):
        counter_return(2_000_000, 3, {1: 10}, 0, frame, None, Counters(frozenset({1})), {2: 0})
    assert counter_return(2_000_000, 3, {1: 10}, 0, frame, None, Counters(), {1: 0}) == (
        *wake_return(2_000_000, 3, {1: 10}, 0, frame), False)


def test_a_tree_s_power_up_names_the_device() -> None:
    """``Ring.power_up`` on a tree takes a physical position (BK-52's numbering) and names a bad one."""
    tl, _ = trees(BranchKind.LOCAL, 2, 2_000_000)
    with pytest.raises(ArgumentError, match=r"^position must be"):
        tl.power_up(6)
    with pytest.raises(ArgumentError, match=r"^position must be"):
        tl.power_up(0)

"""The counter telegram block at pin level (supi3.model.blocks.counter; manual 2.2.2, docs/interbus.md "Counter
telegram", BK-30 to BK-33): a repeater with the chip's delay for working traffic (frames, status telegrams, the
INTERBUS reset) at both bit rates, counter telegrams passed on incremented, and chains of blocks behind every break of
LBD-MR and LBD-OR branches giving ``ring.lbd_count``'s count at the BK (the pin level tied to the transaction
level); hostile inputs."""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.errors import ArgumentError
from supi3.interbus import wire
from supi3.interbus.ring import BranchKind, lbd_count
from supi3.interbus.wire import Cycle
from supi3.lbd import COUNTER_SILENCE_BITS
from supi3.model.blocks.counter import CounterBlock
from supi3.pinout import SYNC_STAGES
from support import bad, lbd_breaks

RATES = {1: 2_000_000, 0: 500_000}


def through(blocks: int, pin: Sequence[int] | npt.NDArray[np.uint8], fast: int,
            bk: bool = False) -> tuple[list[int], list[int], list[int]]:
    """``pin`` (one level per clock) through ``blocks`` blocks in a row, each behind the chip's synchroniser: the last
    block's ``out`` and ``drive`` per clock, and (``bk``) the counts a BK's block keeps from that line."""
    line = [int(v) for v in pin]
    drive: list[int] = []
    for _ in range(blocks):
        block = CounterBlock()
        synced = [wire.IDLE_LEVEL] * SYNC_STAGES + line[: len(line) - SYNC_STAGES]
        outputs = [block.step({"line": level, "fast": fast}) for level in synced]
        line, drive = [o["out"] for o in outputs], [o["drive"] for o in outputs]
    counts = []
    if bk:
        receiver = CounterBlock()
        synced = [wire.IDLE_LEVEL] * SYNC_STAGES + line[: len(line) - SYNC_STAGES]
        counts = [o["count"] for o in (receiver.step({"line": level, "fast": fast}) for level in synced) if o["seen"]]
    return line, drive, counts


def working_traffic() -> np.ndarray:
    """Idle status telegrams, an ID cycle, a data cycle, an INTERBUS reset and its end: never silent."""
    id_frame = wire.Frame.build(Cycle.ID, wire.LOOPBACK_BYTES_ON_LINE + bytes([0x0C, 0x01, 0xFF, 0xFF]))
    data_frame = wire.Frame.build(Cycle.DATA, wire.LOOPBACK_BYTES_ON_LINE + bytes([0xA5, 0x3F]))
    return np.concatenate([wire.status_levels(Cycle.DATA, False, 4), wire.cycle_levels(id_frame, 2, True),
                           wire.cycle_levels(data_frame, 2, True), wire.reset_levels(2),
                           wire.status_levels(Cycle.DATA, False, 2)])  # fmt: skip


@pytest.mark.parametrize("fast", [1, 0])
def test_working_traffic_is_repeated_three_bits_later(fast: int) -> None:
    """A10, M8: the block sends every bit of working traffic REPEATER_DELAY_BITS after it began on the pin, as the
    chip's transmitter, and drives none of it."""
    cpb = wire.clocks_per_bit(RATES[fast])
    pin = wire.levels_to_samples(working_traffic(), RATES[fast])
    out, drive, _ = through(1, np.concatenate([pin, np.ones(3 * cpb, dtype=np.uint8)]), fast)
    assert out == [wire.IDLE_LEVEL] * (3 * cpb) + pin.tolist()
    assert not any(drive)


@pytest.mark.parametrize("fast", [1, 0])
def test_counter_telegrams_pass_incremented(fast: int) -> None:
    """Counter telegrams outside a frame (after status telegrams) go on with count + 1, the first 4 bits repeated,
    the rest driven; 63 goes on saturated."""
    cpb = wire.clocks_per_bit(RATES[fast])
    words = [wire.counter_telegram(c) for c in (1, 5, 62, 63)]
    levels = np.concatenate([wire.status_levels(Cycle.DATA, False, 2), wire.telegram_levels(words, 13),
                             np.ones(4, dtype=np.uint8)])  # fmt: skip
    out, drive, counts = through(1, wire.levels_to_samples(levels, RATES[fast]), fast, bk=True)
    sent = wire.samples_to_levels(np.asarray(out[3 * cpb :]), RATES[fast])
    received = [t for t in wire.parse_levels(sent) if isinstance(t, wire.Telegram) and t.data is not None]
    assert [wire.counter_count(t.data) for t in received if t.data is not None] == [2, 6, 63, 63]
    assert counts == [2, 6, 63, 63]
    driven = wire.samples_to_levels(np.asarray(drive[3 * cpb :]), RATES[fast])
    assert driven[10 : 10 + 13].tolist() == [0] * 4 + [1] * 9


@pytest.mark.parametrize(("kind", "m", "fast"), [(BranchKind.LBD_MR, 1, 1), (BranchKind.LBD_MR, 3, 1),
                                                 (BranchKind.LBD_OR, 3, 1), (BranchKind.LBD_MR, 2, 0)])  # fmt: skip
def test_every_break_gives_the_transaction_levels_count_at_pin_level(kind: BranchKind, m: int, fast: int) -> None:
    """The master's traffic cut in the middle of a data sequence: the blocks behind the break (forward, and in
    LBD-MR the looped return line) bring the BK counter telegrams with exactly ``ring.lbd_count``'s count: two
    within 2 x (COUNTER_SILENCE_BITS + 1) + 3 per block + 20 bit periods of the break."""
    frame = wire.Frame.build(Cycle.ID, wire.LOOPBACK_BYTES_ON_LINE + bytes(range(8)))
    head = np.concatenate([wire.status_levels(Cycle.DATA, False, 3), wire.frame_levels(frame)[:50]])
    for forward, back, behind in lbd_breaks(kind, m):
        bits = len(head) + 2 * (COUNTER_SILENCE_BITS + 1) + 3 * behind + 20
        pin = wire.levels_to_samples(np.concatenate([head, np.ones(bits - len(head), dtype=np.uint8)]), RATES[fast])
        _, _, counts = through(behind, pin, fast, bk=True)
        assert len(counts) == 2 and set(counts) == {lbd_count(kind, m, forward, back)}, (forward, back, counts)


@pytest.mark.parametrize(("inputs", "name"), [
    (None, "inputs"),
    ({"line": 1}, "inputs"),
    ({"line": 1, "fast": 1, "do1": 0}, "inputs"),
    ({"line": 2, "fast": 1}, "pin 'line'"),
    ({"line": 1, "fast": bad(True)}, "pin 'fast'"),
    ({"line": bad(1.0), "fast": 0}, "pin 'line'"),
])  # fmt: skip
def test_hostile_inputs_are_named_and_change_nothing(inputs: object, name: str) -> None:
    block = CounterBlock()
    block.step({"line": 0, "fast": 1})
    before = (block.cycle, block.state, block.phase, list(block.queue))
    with pytest.raises(ArgumentError) as caught:
        block.step(bad(inputs))
    assert caught.value.name == name and str(caught.value).startswith(f"{name} must")
    assert (block.cycle, block.state, block.phase, list(block.queue)) == before


@settings(max_examples=40, deadline=None)
@given(
    runs=st.lists(st.tuples(st.integers(0, 1), st.integers(1, 3 * COUNTER_SILENCE_BITS * 16)), max_size=40),
    cuts=st.lists(st.floats(0, 1), max_size=5),
    fast=st.integers(0, 1),
)
def test_advance_and_render_agree_with_step(runs: list[tuple[int, int]], cuts: list[float], fast: int) -> None:
    """What the chip core's run() uses (M17): ``advance`` over any line in pieces, visiting only restarts and
    samples, then ``render``, gives every clock's ``out`` and ``drive`` and the state that ``step`` gives."""
    line = np.concatenate([np.full(n, level, dtype=np.int64) for level, n in runs] or [np.ones(1, np.int64)])
    n = len(line)
    stepped = CounterBlock()
    expected = [stepped.step({"line": int(level), "fast": fast}) for level in line]
    bulk = CounterBlock()
    bounds = sorted({0, n, *(int(n * cut) for cut in cuts)})
    pieces = []
    for a, b in itertools.pairwise(bounds):
        bulk.advance(line[a:b], a, b, fast)
        pieces.append(bulk.render(a, b - a, fast))
    for k, name in enumerate(("out", "drive")):
        assert np.concatenate([piece[k] for piece in pieces]).tolist() == [o[name] for o in expected]
    assert (bulk.state, bulk.phase, bulk.pending, bulk.cycle) == (stepped.state, stepped.phase, stepped.pending,
                                                                  stepped.cycle)

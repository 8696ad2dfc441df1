"""Hostile arguments to the counter telegram's public entries (supi3.lbd, the pin block
supi3.model.blocks.counter.CounterBlock, supi3.interbus.wire.count_bit / counter_count, PinRing.cut): a named error
"X must be ..., not ..." (supi3.checks; InterbusArgumentError is an ArgumentError), never a traceback or a silent
guess. And over random line histories (manual 2.2.2, BK-6, BK-31): a chain of counter blocks only ever reports a
count of 0..63 and counts a counter telegram of count c as c + k - 1 in its k-th block (63 at most); a cut and mended
PinRing carries a master's cycles again."""

from __future__ import annotations

import re
from collections.abc import Callable

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3 import lbd, tables
from supi3.config import Interface, decode
from supi3.errors import ArgumentError
from supi3.interbus import wire
from supi3.interbus.master import Master
from supi3.interbus.wire import Cycle
from supi3.lbd import CounterState
from supi3.model.blocks.counter import CounterBlock, LineCounters
from supi3.model.pinring import PinRing
from supi3.model.pins import Supi3Pins
from support import bad

ST = CounterState()
BAD_LEVELS = [2, -1, True, 1.0, None, "1", np.float32(1)]
BAD_CPB = [32, 0, -16, True, 16.0, None, "16"]
BAD_FIELDS = [("bit", 99), ("bit", True), ("kind", 3), ("kind", -1), ("quiet", 10**6), ("counted", 64), ("data", 2),
              ("gen", 1.0), ("byte", 256), ("drop", None)]  # fmt: skip

CASES: list[tuple[str, Callable[[], object], str]] = [
    *((f"counter_step level={v!r}", lambda v=v: lbd.counter_step(ST, v), "level") for v in BAD_LEVELS),
    ("counter_step state tuple", lambda: lbd.counter_step(bad(tuple(ST)), 1), "state"),
    ("counter_step state None", lambda: lbd.counter_step(bad(None), 1), "state"),
    *((f"counter_step state.{f}={v!r}", lambda f=f, v=v: lbd.counter_step(ST._replace(**{f: v}), 1), f"state.{f}")
      for f, v in BAD_FIELDS),
    *((f"clocks_per_bit({v!r})", lambda v=v: lbd.clocks_per_bit(v), "fast") for v in [2, True, -1, 1.0, None]),
    *((f"sample_phase({v!r})", lambda v=v: lbd.sample_phase(v), "cpb") for v in BAD_CPB),
    *((f"send_countdown({v!r})", lambda v=v: lbd.send_countdown(v), "cpb") for v in BAD_CPB),
    *((f"count_bit{a!r}", lambda a=a: wire.count_bit(*a), n) for a, n in [
        ((13, 0, 0), "position"), ((-1, 0, 0), "position"), ((True, 0, 0), "position"), ((4.0, 0, 0), "position"),
        ((4, 2, 0), "level"), ((4, None, 0), "level"), ((4, 0, 2), "carry"), ((4, 0, True), "carry")]),
    *((f"counter_count({v!r})", lambda v=v: wire.counter_count(v), "byte") for v in [256, -1, True, 1.0, None, "A"]),
    ("CounterBlock.step line 2", lambda: CounterBlock().step({"line": 2, "fast": 0}), "pin 'line'"),
    ("CounterBlock.step line True", lambda: CounterBlock().step({"line": True, "fast": 0}), "pin 'line'"),
    ("CounterBlock.step fast -1", lambda: CounterBlock().step({"line": 1, "fast": -1}), "pin 'fast'"),
    ("CounterBlock.step line None", lambda: CounterBlock().step({"line": bad(None), "fast": 0}), "pin 'line'"),
    ("CounterBlock.step None", lambda: CounterBlock().step(bad(None)), "inputs"),
    ("CounterBlock.step list", lambda: CounterBlock().step(bad([1, 0])), "inputs"),
    ("CounterBlock.step extra", lambda: CounterBlock().step({"line": 1, "fast": 0, "x": 1}), "inputs"),
    ("CounterBlock.step missing", lambda: CounterBlock().step({"line": 1}), "inputs"),
    *((f"LineCounters({f!r}, False)", lambda f=f: LineCounters(bad(f), False), "fast") for f in [2, -1, True, 1.0]),
    *((f"LineCounters(0, {v!r})", lambda v=v: LineCounters(0, bad(v)), "looped") for v in [1, None, "yes"]),
    *((f"LineCounters.of({v!r})", lambda v=v: LineCounters.of(bad(v)), "config") for v in [None, "LBD-MR"]),
]


@pytest.mark.parametrize(("call", "name"), [(call, name) for _, call, name in CASES], ids=[c[0] for c in CASES])
def test_hostile_arguments_give_named_errors(call: Callable[[], object], name: str) -> None:
    with pytest.raises(ArgumentError, match=rf"^{re.escape(name)} must be .*, not ") as caught:
        call()
    assert caught.value.name == name


def _ring(n: int) -> PinRing:
    row = next(r for r in tables.MODE_ROWS if r.function == f"{Interface.LBD_OR.value}, 8 IN/8 OUT")
    return PinRing([Supi3Pins(decode(row.c, row.mfp, clk_conf=tables.clk_conf_for(2_000_000))) for _ in range(n)])


@pytest.mark.parametrize(("n", "position", "forward"), [
    (1, 1, False), (1, 0, True), (1, 3, True), (3, 3, False), (3, 5, True), (2, True, True), (2, 1.0, True),
    (2, None, True), (2, "1", True),
])  # fmt: skip
def test_a_cut_where_no_line_is_refused(n: int, position: object, forward: bool) -> None:
    """A ring of N chips has forward inputs 1..N (and N + 1, the return line into the master, BK-61) and return
    inputs 1..N - 1 (the last chip loops its own): any other position is refused by name, with the rule, and nothing
    is cut."""
    ring = _ring(n)
    with pytest.raises(ArgumentError, match=r"^position must be an integer from 1 to \d+ \(a chip of the ring"):
        ring.cut(bad(position), forward)
    assert ring.cuts == set()


@pytest.mark.parametrize("forward", [1, 0, None, "yes"])
def test_a_cut_with_a_non_bool_direction_is_refused(forward: object) -> None:
    ring = _ring(2)
    with pytest.raises(ArgumentError, match=r"^forward must be"):
        ring.cut(1, bad(forward))
    assert ring.cuts == set()


def test_a_cut_ring_mended_carries_cycles_again() -> None:
    """Cut the forward line into chip 2: the master's cycle fails; take the cut away (``cuts`` is the ring's
    set of broken lines) and the ring carries its cycles again: nothing of the cut stays behind."""
    ring = _ring(2)
    master = Master(ring, locate=False, max_devices=3)
    assert master.start().ok
    ring.cut(2, True)
    ring.cut(2, True)  # twice is once
    assert ring.cuts == {(2, True)}
    assert not master.data_cycle().ok
    ring.cuts.clear()
    ring.settle()
    assert master.start().ok and master.data_cycle().ok


TELEGRAMS = st.one_of(
    st.tuples(st.just("count"), st.integers(1, wire.COUNTER_MAX)),
    st.tuples(st.just("status"), st.integers(1, 4)),
    st.tuples(st.just("idle"), st.integers(0, 40)),
    st.tuples(st.just("data"), st.integers(0, 0xFF), st.sampled_from(list(Cycle)), st.booleans()),
)


def _levels(item: tuple[object, ...]) -> list[int]:
    kind = item[0]
    if kind == "count":
        return [int(v) for v in wire.telegram_levels([wire.counter_telegram(bad(item[1]))], wire.DATA_TELEGRAM_BITS)]
    if kind == "status":
        return [int(v) for v in wire.status_levels(Cycle.DATA, False, bad(item[1]))]
    if kind == "idle":
        return [wire.IDLE_LEVEL] * bad(item[1])
    word = wire.data_telegram(bad(item[1]), bad(item[2]), bad(item[3]))
    return [int(v) for v in wire.telegram_levels([word], wire.DATA_TELEGRAM_BITS)]


@settings(max_examples=40)
@given(st.lists(TELEGRAMS, max_size=12), st.integers(1, 4))
def test_a_chain_of_counter_blocks_counts_in_range(items: list[tuple[object, ...]], blocks: int) -> None:
    """Any line history of counter telegrams, status telegrams, other data telegrams and silence through ``blocks``
    counter blocks (one bit period each, as :func:`supi3.lbd.counter_step`, the block's output the next block's
    input): every block's count stays 0..63, a ``seen`` count is 1..63 at a telegram's end and 0 where the block's
    generator begins (its input silent, BK-58); and a counter telegram of count c the
    first block receives outside a frame, followed by silence, is counted c + k - 1 by block k (63 at most)."""
    line = [level for item in items for level in _levels(item)] + [wire.IDLE_LEVEL] * 3
    states = [CounterState() for _ in range(blocks)]
    for level in line:
        for k in range(blocks):
            states[k], bit = lbd.counter_step(states[k], level)
            assert 0 <= states[k].counted <= wire.COUNTER_MAX
            silent = states[k].gen == 1 and bit.drive  # the generator's first bit went out now
            assert not bit.seen or (states[k].counted == 0 if silent else 1 <= states[k].counted <= wire.COUNTER_MAX)
            level = bit.out
    fresh = [CounterState() for _ in range(blocks)]
    trailer = _levels(("status", 2)) + [wire.IDLE_LEVEL] * 20 + _levels(("count", 5)) + [wire.IDLE_LEVEL] * 3
    for level in trailer:
        for k in range(blocks):
            fresh[k], bit = lbd.counter_step(fresh[k], level)
            level = bit.out
    assert [s.counted for s in fresh] == [min(5 + k, wire.COUNTER_MAX) for k in range(blocks)]


def test_a_chain_of_counter_block_pin_models_saturates_at_63() -> None:
    """Three CounterBlocks (pin level, 2 Mbit/s) in a chain, a counter telegram of 62 into the first: they count
    62, 63, 63 (the mark saturates, BK-31), nothing above 63."""
    levels = np.concatenate([wire.status_levels(Cycle.DATA, False, 2), np.full(20, wire.IDLE_LEVEL),
                             wire.telegram_levels([wire.counter_telegram(62)], wire.DATA_TELEGRAM_BITS),
                             np.full(30, wire.IDLE_LEVEL)])  # fmt: skip
    line = wire.levels_to_samples(levels, 2_000_000).astype(np.int64)
    counts = []
    for _ in range(3):
        block = CounterBlock()
        block.advance(line, 0, len(line), 1)
        out, _ = block.render(0, len(line), 1)
        counts.append(block.state.counted)
        line = out
    assert counts == [62, 63, 63]

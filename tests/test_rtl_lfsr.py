"""The LFSR down counter of the RTL (supi3.rtl.lfsr; docs/rtl.md, "Size and build time"): every tap set of the
table gives a maximal-length sequence, the jump ``advance`` equals stepping, and ``Countdown`` on Amaranth's
simulator counts exactly as a binary down counter from its limit (load, clear, ``last``, ``idle``), for random
load and clear strobes; an up counter's states (``count_state``) are distinct up to its end and step by
``next_state``."""

from __future__ import annotations

from itertools import pairwise

import pytest
from amaranth.hdl import Module, Signal
from amaranth.sim import Simulator, SimulatorContext
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.rtl.lfsr import (
    TAPS,
    Countdown,
    advance,
    count_state,
    count_width,
    down_state,
    down_step,
    next_state,
    step,
)


def _prime_factors(n: int) -> set[int]:
    factors, p = set(), 2
    while p * p <= n:
        while n % p == 0:
            factors.add(p)
            n //= p
        p += 1
    return factors | ({n} if n > 1 else set())


@pytest.mark.parametrize("width", sorted(TAPS))
def test_every_tap_set_is_maximal_length(width: int) -> None:
    period = (1 << width) - 1
    assert advance(1, width, period) == 1
    assert all(advance(1, width, period // q) != 1 for q in _prime_factors(period))


@settings(max_examples=30)
@given(st.sampled_from(sorted(TAPS)), st.integers(1, (1 << max(TAPS)) - 1), st.integers(0, 100))
def test_advance_is_repeated_step(width: int, seed: int, steps: int) -> None:
    state = expected = seed % ((1 << width) - 1) + 1
    for _ in range(steps):
        expected = step(expected, width)
    assert advance(state, width, steps) == expected
    assert step(0, width) == 0


@settings(max_examples=15)
@given(st.integers(1, 40), st.lists(st.tuples(st.booleans(), st.booleans()), min_size=1, max_size=120))
def test_countdown_counts_like_a_binary_down_counter(limit: int, strobes: list[tuple[bool, bool]]) -> None:
    m = Module()
    load, clear = Signal(), Signal()
    counter = Countdown(m, limit, load=load, clear=clear, name="c")
    last, idle = Signal(), Signal()
    m.d.comb += [last.eq(counter.last), idle.eq(counter.idle)]
    seen: list[tuple[int, int]] = []

    async def bench(ctx: SimulatorContext) -> None:
        for do_load, do_clear in strobes:
            seen.append((ctx.get(last), ctx.get(idle)))
            ctx.set(load, do_load)
            ctx.set(clear, do_clear)
            await ctx.tick()

    sim = Simulator(m)
    sim.add_clock(1e-6)
    sim.add_testbench(bench)
    sim.run()
    value, expected = 0, []
    for do_load, do_clear in strobes:
        expected.append((int(value == 1), int(value == 0)))
        value = 0 if do_clear else limit if do_load else max(value - 1, 0)
    assert seen == expected


@pytest.mark.parametrize("limit", [0, 1 << max(TAPS)])
def test_countdown_rejects_a_limit_out_of_range(limit: int) -> None:
    m = Module()
    m._MustUse__silence = True  # rejected, never elaborated
    with pytest.raises(ValueError, match="limit must be from 1"):
        Countdown(m, limit, load=Signal(), clear=Signal(), name="c")


@pytest.mark.parametrize("most", [0, 1, 2, 3, 6, 7, 255, 256, 1024])
def test_up_count_states_are_distinct_and_step(most: int) -> None:
    width = count_width(most)
    states = [count_state(v, width) for v in range(most + 1)]
    assert len(set(states)) == most + 1
    assert all(step(a, width) == b for a, b in pairwise(states))
    assert count_state(0, width) == 1


@given(st.integers(1, 1 << 12))
def test_next_state_in_gates_is_step(seed: int) -> None:
    width = count_width(seed)
    m = Module()
    state, after = Signal(width), Signal(width)
    m.d.comb += after.eq(next_state(state))
    got: list[int] = []

    async def bench(ctx: SimulatorContext) -> None:
        ctx.set(state, seed % (1 << width))
        got.append(ctx.get(after))

    sim = Simulator(m)
    sim.add_testbench(bench)
    sim.run()
    assert got == [step(seed % (1 << width), width)]


@pytest.mark.parametrize("most", [-1, (1 << max(TAPS)) - 1])
def test_count_width_rejects_a_count_out_of_range(most: int) -> None:
    with pytest.raises(ValueError, match="most must be an integer from 0"):
        count_width(most)


@pytest.mark.parametrize(("value", "width"), [(0, 2), (1, 2), (3, 2), (12, 9), (64, 9), (256, 9)])
def test_down_counter_reaches_zero_after_its_value(value: int, width: int) -> None:
    m = Module()
    state, after = Signal(width), Signal(width)
    m.d.comb += after.eq(down_step(state))
    trail: list[int] = []

    async def bench(ctx: SimulatorContext) -> None:
        current = down_state(value, width)
        for _ in range(value + 2):
            trail.append(current)
            ctx.set(state, current)
            current = ctx.get(after)

    sim = Simulator(m)
    sim.add_testbench(bench)
    sim.run()
    assert trail[value:] == [0, 0]
    assert 0 not in trail[:value]
    assert value == 0 or trail[value - 1] == 1

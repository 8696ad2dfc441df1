"""Lockstep of the counter telegram block's RTL (supi3.rtl.counter.CounterRtl) against its pin model
(supi3.model.blocks.counter.CounterBlock), every output every clock, on Amaranth's simulator
(supi3.verif.amaranth_sim; manual 2.2.2, docs/interbus.md "Counter telegram", BK-30 to BK-33).

Directed streams at both bit rates (working traffic, counter telegrams of every count byte, the saturated mark,
silence and the generator, a telegram colliding with it, the INTERBUS reset), each also checked to do what it is
about; and random line streams (hypothesis, the seeded profile of tests/conftest.py): real telegrams from ``wire``,
counter telegrams of any count, frames, silences around COUNTER_SILENCE_BITS, INTERBUS resets, glitches and
telegrams off the bit grid.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping

import numpy as np
import numpy.typing as npt
import pytest
from amaranth.hdl import Module, Mux
from amaranth.lib import wiring
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.interbus import wire
from supi3.interbus.wire import Cycle
from supi3.lbd import COUNTER_INPUTS, COUNTER_OUTPUTS, COUNTER_SILENCE_BITS
from supi3.model.blocks.counter import CounterBlock
from supi3.rtl.counter import CounterRtl
from supi3.verif.amaranth_sim import run_amaranth_sim

S = COUNTER_SILENCE_BITS
RATES = {1: 2_000_000, 0: 500_000}
Levels = npt.NDArray[np.uint8]


def lockstep(line: Levels | list[int], fast: int) -> list[dict[str, int]]:
    """``line`` (one synchronised level per clock) on the RTL and the model, compared every clock; the model's
    outputs."""
    rows = [{"line": int(level), "fast": fast} for level in line]
    assert run_amaranth_sim(CounterRtl, CounterBlock, rows).cycles == len(rows)
    block = CounterBlock()
    return [block.step(row) for row in rows]


def idle(bits: int) -> Levels:
    return np.ones(bits, dtype=np.uint8)


def counter_words(*bytes_: int) -> Levels:
    return wire.telegram_levels([wire.data_telegram(b, Cycle.ID, True) for b in bytes_], wire.DATA_TELEGRAM_BITS)


def test_every_count_byte_and_working_traffic() -> None:
    """2 Mbit/s: an ID cycle, then counter telegrams of every count under the mark (0..63), saturated ones, then
    silence: the generator twice; the BK's count follows every counter telegram, and is 0 at each generated one (the
    input silent, BK-58)."""
    frame = wire.Frame.build(Cycle.ID, wire.LOOPBACK_BYTES_ON_LINE + bytes([0x0C, 0x01]))
    counts = [wire.COUNTER_MARK | c for c in range(wire.COUNTER_MAX + 1)]
    levels = np.concatenate([wire.status_levels(Cycle.DATA, False, 2), wire.cycle_levels(frame, 2, True),
                             counter_words(*counts, 0xC0, 0xFF, 0xFE), idle(2 * (S + 1) + 4)])  # fmt: skip
    outputs = lockstep(wire.levels_to_samples(levels, RATES[1]), 1)
    seen = [o["count"] for o in outputs if o["seen"]]
    assert seen == [*range(1, wire.COUNTER_MAX + 1), wire.COUNTER_MAX, wire.COUNTER_MAX, wire.COUNTER_MAX, 0, 0]
    generated = sum(1 for a, b in itertools.pairwise(outputs) if b["drive"] and not a["drive"])
    assert generated == len(counts) + 3 + 2  # every counter telegram passed on, two generated


def test_slow_rate_generator_collision_and_reset() -> None:
    """500 kbit/s: a counter telegram, silence, the generated telegram with a counter telegram colliding with it
    (dropped, its count kept; the silence before it reads 0, BK-58), then an INTERBUS reset (repeated, never a
    counter telegram)."""
    levels = np.concatenate([wire.status_levels(Cycle.DATA, False, 1), counter_words(0x85), idle(S + 3),
                             counter_words(0x8A), idle(8), np.zeros(wire.RESET_DETECT_BITS + 2, dtype=np.uint8),
                             wire.status_levels(Cycle.DATA, False, 2)])  # fmt: skip
    outputs = lockstep(wire.levels_to_samples(levels, RATES[0]), 0)
    assert [o["count"] for o in outputs if o["seen"]] == [5, 0, 10]
    cpb = wire.clocks_per_bit(RATES[0])
    sent = wire.samples_to_levels(np.asarray([o["out"] for o in outputs])[3 * cpb :], RATES[0])
    telegrams = wire.parse_levels(sent[: 6 + 2 * 13 + S + 3])
    assert [t.data for t in telegrams if isinstance(t, wire.Telegram)] == [None, 0x86, 0x81]


# Random line streams --------------------------------------------------------------------------------------------

def samples(levels: Levels) -> Levels:
    """One synchronised level per clock at 2 Mbit/s."""
    return wire.levels_to_samples(levels, RATES[1])


def data_levels(byte: int, cycle: Cycle, check: bool) -> Levels:
    return samples(wire.telegram_levels([wire.data_telegram(byte, cycle, check)], wire.DATA_TELEGRAM_BITS))


def frame_levels(cycle: Cycle, data: bytes) -> Levels:
    return samples(wire.frame_levels(wire.Frame.build(cycle, wire.LOOPBACK_BYTES_ON_LINE + data)))


def held(level: int, clocks: int) -> Levels:
    return np.full(clocks, level, dtype=np.uint8)


SEGMENT = st.one_of(
    st.integers(0, 0xFF).map(lambda byte: samples(counter_words(byte))),
    st.builds(data_levels, st.integers(0, 0xFF), st.sampled_from(list(Cycle)), st.booleans()),
    st.builds(lambda cycle, check, n: samples(wire.status_levels(cycle, check, n)), st.sampled_from(list(Cycle)),
              st.booleans(), st.integers(1, 4)),
    st.builds(frame_levels, st.sampled_from(list(Cycle)), st.binary(min_size=0, max_size=3)),
    st.sampled_from([1, 5, 12, S - 1, S, S + 1, S + 5, S + 14, 2 * S + 2]).map(lambda n: samples(idle(n))),
    st.integers(wire.RESET_DETECT_BITS - 2, wire.RESET_DETECT_BITS + 4).map(
        lambda n: samples(held(wire.START_LEVEL, n))),
    st.integers(1, 20).map(lambda clocks: held(wire.START_LEVEL, clocks)),  # a glitch
    st.integers(1, 15).map(lambda clocks: held(wire.IDLE_LEVEL, clocks)),  # a skew off the bit grid
)
"""Pieces of a line, one synchronised level per clock at 2 Mbit/s: counter telegrams of any byte, data and status
telegrams, frames, silences around COUNTER_SILENCE_BITS, INTERBUS resets, glitches and skews off the bit grid."""


@settings(max_examples=3, deadline=None)
@given(segments=st.lists(SEGMENT, min_size=6, max_size=14))
def test_random_line_streams(segments: list[Levels]) -> None:
    """Any mix of telegrams, frames, counter telegrams, silences, INTERBUS resets, glitches and skews: the RTL
    equals the model on every output, every clock (and the generator runs in the final silence)."""
    line = np.concatenate([*segments, samples(idle(2 * S + 30))])
    outputs = lockstep(line, 1)
    # the generator runs at the latest S + 16 bit periods into the final silence (a telegram may end 13 in), one
    # telegram every S + 1: the last S + 16 bit periods hold driven bits
    assert any(o["drive"] for o in outputs[-16 * (S + 16) :])


# The count taken with ``seen`` (``CounterRtl(strobed_count=True)``, the core's forward block) ------------------------


class _Strobed(wiring.Component):  # type: ignore[misc]  # Amaranth is untyped (pyproject's mypy overrides)
    """``CounterRtl(strobed_count=True)`` with ``count`` shown only with ``seen`` (0 otherwise), as the bus terminal
    block reads it (``cnt_valid``, BK-39)."""

    def __init__(self) -> None:
        super().__init__({**{pin.name: wiring.In(pin.width) for pin in COUNTER_INPUTS},
                          **{pin.name: wiring.Out(pin.width) for pin in COUNTER_OUTPUTS}})  # fmt: skip

    def elaborate(self, _platform: object) -> Module:
        m = Module()
        m.submodules.block = block = CounterRtl(strobed_count=True)
        m.d.comb += [block.line.eq(self.line), block.fast.eq(self.fast), self.out.eq(block.out),
                     self.drive.eq(block.drive), self.seen.eq(block.seen),
                     self.count.eq(Mux(block.seen, block.count, 0))]  # fmt: skip
        return m


class _StrobedModel(CounterBlock):
    """``CounterBlock`` with ``count`` shown only with ``seen``."""

    def step(self, inputs: Mapping[str, int]) -> dict[str, int]:
        out = super().step(inputs)
        return {**out, "count": out["count"] if out["seen"] else 0}


def _strobed_lockstep(line: Levels, fast: int) -> list[dict[str, int]]:
    rows = [{"line": int(level), "fast": fast} for level in line]
    assert run_amaranth_sim(_Strobed, _StrobedModel, rows).cycles == len(rows)
    model = _StrobedModel()
    return [model.step(row) for row in rows]


@pytest.mark.slow  # about 6 s
@settings(max_examples=3, deadline=None)
@given(segments=st.lists(SEGMENT, min_size=6, max_size=14))
def test_the_strobed_count_is_the_model_s_with_every_seen(segments: list[Levels]) -> None:
    """With ``strobed_count`` (no count register: the received byte, or 0 after a silent input) ``count`` is the
    model's in every cycle of ``seen`` and every other output equals it every clock, over any mix of telegrams,
    counter telegrams, silences (BK-58's 0), resets, glitches and skews at 2 Mbit/s, and a directed stream at
    500 kbit/s (a count, the silence's 0, a count taken while the generator runs)."""
    line = np.concatenate([*segments, samples(idle(2 * S + 30))])
    assert any(o["seen"] for o in _strobed_lockstep(line, 1))
    levels = np.concatenate([wire.status_levels(Cycle.DATA, False, 1), counter_words(0x85), idle(S + 3),
                             counter_words(0x8A), idle(8)])  # fmt: skip
    slow = _strobed_lockstep(wire.levels_to_samples(levels, RATES[0]), 0)
    assert [o["count"] for o in slow if o["seen"]] == [5, 0, 10]

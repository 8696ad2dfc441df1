"""The register expansion block in Amaranth (supi3.rtl.expansion) against the spec's schedule (supi3.expansion).

Manual 3.5 (Tables 3-14, 3-15, Figure 3-23) and RX-1 to RX-7 of docs/assumptions/expansion.md, at both bit rates:
ToExR and ClkExR per data bit (``clock_high``), the end pulses after a latched data cycle and after any other
cycle end (``end_pulses``), Table 3-15 (supi3.verif.timing) on the trace, FromExR sent in place of the internal
register, idle pins without ExtReg or without data bytes. On Amaranth's own simulator; /ResReg is the core's
(tests/test_verif_lockstep_serial.py).
"""

from __future__ import annotations

import random
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest
from amaranth.sim import Simulator

from supi3 import expansion
from supi3.expansion import IDLE, ExpansionLevels
from supi3.interbus import wire
from supi3.rtl.expansion import PIN_NAMES, ExpansionRtl, _in_bits
from supi3.tables import BIT_RATES
from supi3.verif.timing import EXPANSION_PINS, check_expansion

Row = dict[str, int]


def simulate(bit_rate: int, rows: Iterator[Row]) -> tuple[list[ExpansionLevels], list[Row]]:
    """Per cycle: set the inputs of ``rows`` (missing ones 0; ``has_data`` 1), read the pins (/ResReg, not this
    block's, as 1) and ``send``/``overrun``/``active``."""
    dut = ExpansionRtl()
    levels: list[ExpansionLevels] = []
    seen: list[Row] = []

    async def bench(ctx: Any) -> None:
        ctx.set(dut.rate, BIT_RATES.index(bit_rate))
        for row in rows:
            for name in ("ext", "load", "load_id", "shift", "level", "ended", "latched", "from_exr"):
                ctx.set(getattr(dut, name), row.get(name, 0))
            ctx.set(dut.has_data, row.get("has_data", 1))
            pins = {name: ctx.get(getattr(dut, name)) for name in PIN_NAMES}
            levels.append(ExpansionLevels(**pins, res_reg_n=IDLE.res_reg_n))
            seen.append({name: ctx.get(getattr(dut, name)) for name in ("send", "overrun", "active")})
            await ctx.tick()

    simulator = Simulator(dut)
    simulator.add_clock(1 / 32e6)
    simulator.add_testbench(bench)
    simulator.run()
    return levels, seen


def window(first: int, span: tuple[int, int]) -> range:
    return range(first + span[0], first + span[1])


@pytest.mark.parametrize("bit_rate", BIT_RATES)
@pytest.mark.parametrize("id_cycle", [False, True])
def test_data_bits_clock_and_end_pulses(bit_rate: int, id_cycle: bool) -> None:
    """A cycle of 12 data bits one bit period apart, then its latch: ToExR takes each bit from the cycle after the
    shift, ClkExR is high clock_high() after that; LaOuD, then /LaInD after a latched data cycle, only /LaInD after
    an ID cycle; FromExR is what the chip sends. An ID cycle's bits stay inside the chip (RX-2)."""
    cpb = wire.clocks_per_bit(bit_rate)
    rng = random.Random(bit_rate)
    bits = [rng.getrandbits(1) for _ in range(12)]
    shifts = [5 + cpb * j for j in range(len(bits))]
    end = shifts[-1] + cpb
    length = end + expansion.end_pulses(True, cpb).length + 5
    from_exr = [rng.getrandbits(1) for _ in range(length)]
    latched = not id_cycle

    def rows() -> Iterator[Row]:
        for c in range(length):
            row = {"ext": 1, "from_exr": from_exr[c]}
            if c == 2:
                row.update(load=1, load_id=int(id_cycle))
            if c in shifts:
                row.update(shift=1, level=bits[shifts.index(c)])
            if c == end:
                row.update(ended=1, latched=int(latched))
            yield row

    levels, seen = simulate(bit_rate, rows())
    assert [row["send"] for row in seen] == from_exr
    assert [row["active"] for row in seen][3:] == [int(not id_cycle)] * (length - 3)
    high = set() if id_cycle else {c for s in shifts for c in window(s + 1, expansion.clock_high(cpb))}
    pulses = expansion.end_pulses(latched, cpb)
    ou = set() if pulses.la_ou_d is None else set(window(end + 1, pulses.la_ou_d))
    low = set(window(end + 1, pulses.la_in_d_n))
    for c, level in enumerate(levels):
        done = [b for s, b in zip(shifts, bits, strict=True) if s < c]
        to_exr = done[-1] if done and not id_cycle else IDLE.to_exr
        assert level == ExpansionLevels(int(c in high), to_exr, int(c in ou), int(c not in low), IDLE.res_reg_n), c
    assert not any(row["overrun"] for row in seen)
    traces = {name: np.array([getattr(level, name) for level in levels], dtype=np.int64) for name in EXPANSION_PINS}
    assert check_expansion(traces, bit_rate=bit_rate) == []  # Table 3-15 on the RTL's trace


@pytest.mark.parametrize(("ext", "has_data"), [(0, 1), (1, 0)])
def test_idle_without_ext_or_data(ext: int, has_data: int) -> None:
    """RX-6: without ExtReg every pin idles whatever the core does; RX-2: a length code without data bytes keeps
    the data bits inside the chip (no ClkExR, ToExR idle), but a cycle end with ExtReg still pulses (RX-4)."""
    bit_rate = max(BIT_RATES)
    cpb = wire.clocks_per_bit(bit_rate)

    def rows() -> Iterator[Row]:
        for c in range(40 * cpb):
            yield {"ext": ext, "has_data": has_data, "load": int(c == 4), "shift": int(c in (6, 6 + cpb)),
                   "level": 1, "ended": int(c == 3 * cpb), "latched": 1}  # fmt: skip

    levels, seen = simulate(bit_rate, rows())
    assert {level.clk_exr for level in levels} == {level.to_exr for level in levels} == {0}
    assert not any(row["active"] for row in seen)
    assert any(level.la_ou_d for level in levels) == bool(ext)


@pytest.mark.parametrize("bit_rate", BIT_RATES)
def test_overrun_when_a_data_bit_comes_before_the_end_pulses_are_over(bit_rate: int) -> None:
    """RX-4: a data cycle whose first ClkExR rises while the last cycle's end pulses run is an overrun; the pins
    follow the schedule regardless."""
    cpb = wire.clocks_per_bit(bit_rate)
    pulses = expansion.end_pulses(True, cpb)
    first, _ = expansion.clock_high(cpb)
    for gap, overrun in ((pulses.length - first - 2, True), (pulses.length - first, False)):

        def rows(gap: int = gap) -> Iterator[Row]:
            for c in range(pulses.length + 4 * cpb):
                yield {"ext": 1, "ended": int(c == 0), "latched": 1, "load": int(c == 1), "shift": int(c == gap)}

        levels, seen = simulate(bit_rate, rows())
        assert [c for c, row in enumerate(seen) if row["overrun"]] == ([gap + 1 + first] if overrun else [])
        assert [level.clk_exr for level in levels].index(1) == gap + 1 + first


def test_end_pulses_are_whole_bit_periods() -> None:
    """The block counts the end pulses in bit periods: ``expansion.end_pulses`` gives whole bit periods at both rates
    (Table 3-15, RX-4), and pulses between bit periods are refused at elaboration, named."""
    for bit_rate in BIT_RATES:
        cpb = wire.clocks_per_bit(bit_rate)
        for data in (True, False):
            pulses = expansion.end_pulses(data, cpb)
            bits = _in_bits(pulses, cpb)
            assert bits.la_in_d_n == (pulses.la_in_d_n[0] // cpb, pulses.la_in_d_n[1] // cpb)
            assert (bits.la_ou_d is None) == (pulses.la_ou_d is None)
            assert bits.length * cpb == pulses.length
    with pytest.raises(ValueError, match="whole bit period, not at 17 clocks"):
        _in_bits(expansion.EndPulses(None, (0, 17)), 16)

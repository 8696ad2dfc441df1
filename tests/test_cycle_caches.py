"""The master cycle's caches of issue #13's round 9 (docs/firmware-in-the-loop.md, Figures), held to the values they
stand for over histories of changes:

- ``Supi3._data_path``: a µP-mode chip's data path (the expansion or the internal registers) and data length, worked
  out again only when its register file took a configuration (``RegisterFile.configurations``: SET applied or
  dropped), against the same chip with the cache bypassed;
- the bench's cycle offsets: a cycle's end, latch phase and I/O access bit from its start, kept per cycle size, against
  the cycle's :class:`~supi3.sdk.bench.CycleTiming`.
"""

from __future__ import annotations

from typing import Any

from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.config import decode
from supi3.interbus import wire
from supi3.interbus.device import PlainDevice
from supi3.interbus.master import Master
from supi3.interbus.ring import Ring
from supi3.interbus.wire import Cycle
from supi3.model.chip import Supi3
from supi3.regmap import ID, IN0, SET
from supi3.sdk.bench import Bench, CycleTiming
from support import RB_INIT_UP

Op = tuple[str, int]
OPS = st.lists(st.one_of(
    st.tuples(st.just("set"), st.integers(0, 255)),  # any SET: applied, reserved, ExtReg (no chain attached)
    st.tuples(st.sampled_from(["id", "in"]), st.integers(0, 255)),
    st.tuples(st.sampled_from(["cycle", "cycle", "cycle", "power_up", "reset"]), st.just(0)),
    st.tuples(st.just("bus"), st.integers(0, 1)),
), max_size=40)  # fmt: skip


def _uncached(chip: Supi3) -> Supi3:
    """``chip`` with its data path worked out at every call (the cache bypassed: what the chip computed before)."""
    registers = chip.registers
    assert registers is not None
    chip.__dict__["_data_path"] = lambda: (registers.configurations, chip.expansion,
                                           wire.data_bytes((chip._id_and_length() >> 8) & 0x1F))  # fmt: skip
    return chip


def _apply(ring: Ring, master: Master, chip: Supi3, op: Op) -> object:
    """One step of a history; what it showed (its result or the error it raised, by type and text)."""
    kind, value = op
    registers = chip.registers
    assert registers is not None
    try:
        if kind == "set":
            registers.cpu_write(SET.address, value)
        elif kind == "id":
            registers.cpu_write(ID.address, value)
        elif kind == "in":
            registers.cpu_write(IN0.address, value)
        elif kind == "bus":
            registers.set_bus_running(bool(value))
        elif kind == "power_up":
            chip.power_up()
        elif kind == "reset":
            ring.reset()
        else:
            return master.cycle()
    except Exception as error:  # both chips must raise the same
        return type(error).__name__, str(error)
    return None


def _state(ring: Ring, master: Master, chip: Supi3) -> tuple[Any, ...]:
    registers = chip.registers
    assert registers is not None
    return (chip.data_bytes(), chip.expansion, dict(registers._values), len(registers.violations.records),
            master.config, master._in, ring.now)  # fmt: skip


@settings(derandomize=True, max_examples=60, deadline=None)
@given(OPS)
def test_a_chips_cached_data_path_agrees_with_the_uncached_one_over_any_history(ops: list[Op]) -> None:
    """Two rings, each a µP-mode chip and a plain device, one chip with its data path cached, one with the cache
    bypassed, take the same history of SET, ID and IN writes, bus running on and off, power-ups, INTERBUS resets and
    master cycles (with the configuration errors and rediscoveries they cause): after every step both show the same
    outcome, data length, data path, registers, violations and master's view; and the cached path always equals
    what the chip's configuration gives now."""
    sides = []
    for cached in (True, False):
        chip = Supi3(decode(*RB_INIT_UP), strict=False)
        if not cached:
            _uncached(chip)
        ring = Ring([chip, PlainDevice(0x02, 1)])
        sides.append((ring, Master(ring), chip))
    for side in sides:
        side[1].start()
    for op in ops:
        outcomes = [_apply(*side, op) for side in sides]
        assert outcomes[0] == outcomes[1]
        assert _state(*sides[0]) == _state(*sides[1])
        chip = sides[0][2]
        assert Supi3._data_path(chip)[1:] == (chip.expansion, wire.data_bytes((chip._id_and_length() >> 8) & 0x1F))


@settings(derandomize=True, max_examples=25, deadline=None)
@given(st.lists(st.one_of(st.tuples(st.just("advance"), st.integers(1, 1500)),
                          st.tuples(st.just("set"), st.sampled_from([0x80, 0x81, 0x82, 0x83, 0x84, 0x85])),
                          st.tuples(st.just("id"), st.integers(0, 255))), max_size=30))  # fmt: skip
def test_the_bench_s_cycle_offsets_agree_with_each_cycle_s_timing(ops: list[Op]) -> None:
    """A bench whose chip's data length changes (SET written between and during cycles: configuration errors,
    rediscoveries, ID and data cycles of several sizes) keeps each cycle's :class:`CycleTiming` as the cycle's size
    gives it and schedules its end, latch phase and I/O access bit at the times that timing gives, exactly (the
    phases and the offsets are kept per cycle size)."""
    bench = Bench(bit_rate=2_000_000, strict=False)
    start_cycle = bench._start_cycle
    seen: list[Cycle] = []

    def checked() -> None:
        start_cycle()
        pending = bench._bus.pending
        assert pending is not None
        transfer, _, start = pending
        phases = wire.cycle_phases(len(transfer.sent) - wire.LOOPBACK_BYTES, transfer.devices,
                                   transfer.return_repeaters)  # fmt: skip
        timing = CycleTiming(start, transfer.cycle, phases, 1 / bench.config.bit_rate)
        assert bench.timeline[-1] == timing
        expected = [(timing.end, "end")]
        if timing.cycle is Cycle.DATA:
            expected += [(timing.latch, "latch"), (timing.io_busy, "io")]
        assert bench._events == expected
        seen.append(timing.cycle)

    bench.__dict__["_start_cycle"] = checked
    for kind, value in ops:
        if kind == "advance":
            bench.advance(bench.now + value * 1e-5)  # up to 15 ms: the discovery ID cycle lasts 6.7 ms
        else:
            bench.registers.cpu_write((SET if kind == "set" else ID).address, value)
    assert len(seen) == bench.cycles + (1 if bench._events else 0)

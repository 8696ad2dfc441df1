"""The bench side's cached paths give what the plain ones give, over random histories.

- ``Bench.advance`` returns at once when no bus event is due (it keeps the next event's time): a history advanced in
  many small steps, most finding nothing due, ends in the very state of the same history advanced in one step per
  action, with ring faults, resets, master outputs and firmware writes between (3.4.14, Figure 3-22: the phases and
  the latch land at the same bus times).
- ``RegisterFile`` derives its data-cycle tables (the IN registers of the data length, the ones a PCP device erases,
  the length code of the ID register) from SET when SET is applied: after any sequence of SET and ID writes (valid,
  reserved, ExtReg, PCP), resets and latches, ``in_bytes``, ``latch`` and ``bus_id_register`` agree with the
  registers' values and the configuration read back through the public API (3.4.8, 3.4.11, Tables 3-11, 3-12).
"""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.config import decode
from supi3.interbus import wire
from supi3.interbus.device import PlainDevice
from supi3.interbus.ring import BitFlip
from supi3.model.registers import RegisterFile, RegisterFileError
from supi3.regmap import ID, IN0, SET
from supi3.regmap.registers import IN_BYTES, OUT_BYTES
from supi3.sdk.bench import Bench, Firmware
from supi3.sdk.driver import Irq, Mode, Supi3Driver, put_u16
from support import RB_INIT_UP

ACTIONS = st.lists(st.tuples(st.sampled_from(["wait", "out", "in", "flip", "clear", "reset"]), st.integers(0, 0xFFFF),
                             st.integers(1, 12)), min_size=1, max_size=20)  # fmt: skip
"""(action, value, pieces): what happens between two waits, and how many steps the fine-grained bench takes."""


class _Setup(Firmware):
    """Brings the chip up (1 word, the VALID interrupt) and nothing more: the test drives the rest."""

    def setup(self, drv: Supi3Driver) -> None:
        drv.initialize(Mode.MOTOROLA)
        drv.configure(0x83, 0x01)
        drv.irq_enable(Irq.VALID)


def _state(bench: Bench) -> tuple[object, ...]:
    """What a history leaves: clock, cycles, the master's view, the chip's registers and events, the timeline."""
    registers = bench.registers
    inputs = bench.master.inputs(1) if bench.master.config else None
    return (bench.now, bench.ring.now, bench.cycles, bench.bytes_clocked, inputs, list(bench.timeline),
            list(bench.results), registers.irq_n, registers.io_access, registers.latch_phase,
            [registers.value(r.name) for r in (*IN_BYTES, *OUT_BYTES)], dict(bench.chip.events))  # fmt: skip


def _advance(bench: Bench, until: float) -> None:
    """``bench.advance(until)``, then what it must leave (FW-2, Figure 3-22): the clock at ``until`` (never back),
    every cycle whose latch is due finished and no other, the I/O access bit and the latch phase of the cycle running
    as its phases say."""
    now = max(bench.now, until)
    bench.advance(until)
    assert bench.now == now
    assert bench.cycles == sum(timing.end <= now for timing in bench.timeline)
    last = bench.timeline[-1]
    data = last.cycle is wire.Cycle.DATA
    assert bench.registers.io_access == (data and last.io_busy <= now < last.end)
    assert bench.registers.latch_phase == (data and last.latch <= now < last.end)


@settings(max_examples=30, deadline=None)
@given(actions=ACTIONS, bit_rate=st.sampled_from([500_000, 2_000_000]), others=st.integers(0, 2),
       cycle_time=st.sampled_from([None, 150e-6]))  # fmt: skip
def test_small_steps_end_where_one_step_ends(actions: list[tuple[str, int, int]], bit_rate: int, others: int,
                                             cycle_time: float | None) -> None:  # fmt: skip
    benches = [Bench(firmware=_Setup(), bit_rate=bit_rate, others=[PlainDevice(0x02, 1) for _ in range(others)],
                     cycle_time_s=cycle_time, strict=False) for _ in range(2)]  # fmt: skip
    for bench in benches:
        bench.run(3)  # set-up, the discovery cycle, the ID cycle with the chip configured
    coarse, fine = benches
    for action, value, pieces in actions:
        for bench in benches:
            if action == "out" and bench.master.config is not None and bench.master.entry(1).data_bytes == 2:
                bench.master.set_outputs(1, put_u16(value))
            elif action == "in":
                bench.driver.write(IN0, value & 0xFF)  # clocks two bytes, each advancing the clock
            elif action == "flip":
                bench.ring.inject(BitFlip(1 + value % (others + 2), value % 40))
            elif action == "clear":
                bench.ring.clear_faults()
            elif action == "reset":
                bench.master.alarm_stop()
        target = coarse.now + (1 + value % 600) * 1e-6
        _advance(coarse, target)
        for k in range(1, pieces):
            _advance(fine, fine.now + (target - fine.now) * k / pieces)
        _advance(fine, target)
        assert _state(fine) == _state(coarse)


# ------------------------------------------------------------------------------------------------------------
# The register file's tables derived from SET
# ------------------------------------------------------------------------------------------------------------

STEPS = st.lists(st.tuples(st.sampled_from(["set", "id", "power_up", "sas_init", "ib_reset", "latch", "in"]),
                           st.integers(0, 0xFF)), min_size=1, max_size=30)  # fmt: skip


def _expected_in(registers: RegisterFile) -> bytes:
    """The IN bytes of a data cycle from the registers' values: IN0.. of the data length (3.4.8)."""
    return bytes(registers.value(r.name) for r in IN_BYTES[: registers.data_bytes()])


@settings(max_examples=200, deadline=None)
@given(steps=STEPS, running=st.booleans())
def test_data_cycle_tables_follow_set(steps: list[tuple[str, int]], running: bool) -> None:
    registers = RegisterFile(decode(*RB_INIT_UP), strict=False)
    for action, value in steps:
        if action == "set":
            registers.cpu_write(SET.address, value)
        elif action == "id":
            registers.cpu_write(ID.address, value)
        elif action == "power_up":
            registers.power_up_reset()
        elif action == "sas_init":
            registers.sas_init()
        elif action == "ib_reset":
            registers.interbus_reset()
        elif action == "in" and registers.internal_data_path and registers.data_bytes():  # IN0.. of the length
            registers.cpu_write(IN0.address + value % registers.data_bytes(), value)
        registers.set_bus_running(running)
        length_code = registers.bus_id_register() >> 8 & 0x1F
        if registers.configured:
            assert wire.data_bytes(length_code) == registers.data_bytes()
            assert registers.bus_id_register() & 0xFF == registers.value("ID")
        if not registers.internal_data_path:
            with pytest.raises(RegisterFileError, match="ExtReg = 1"):
                registers.in_bytes()
            continue
        expected = _expected_in(registers)
        assert registers.in_bytes() == expected
        if action == "latch":
            out = bytes((value + k) & 0xFF for k in range(registers.data_bytes()))
            assert registers.latch(out) == expected
            assert [registers.value(r.name) for r in OUT_BYTES[: len(out)]] == list(out)
            for k, register in enumerate(IN_BYTES[: len(out)]):
                erased = registers.pcp_device and register.name in ("IN0", "IN1")  # 3.4.11
                assert registers.value(register.name) == (0 if erased else expected[k])

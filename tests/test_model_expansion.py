"""Serial register expansion at transaction level (supi3.model.chip.Supi3, manual 3.5, 3.4.11, Table 3-11;
docs/assumptions/expansion.md RX-1 to RX-10): ExtReg = 1 in SET puts external registers in the data path."""

from __future__ import annotations

import pytest

from supi3 import tables
from supi3.config import Variant, decode
from supi3.errors import ArgumentError
from supi3.expansion import PULSE_T0, chain_to_line, line_to_chain
from supi3.interbus import wire
from supi3.interbus.master import Master
from supi3.interbus.ring import ErrorKind, Ring
from supi3.model.blocks.expansion import overrun_gap_clocks
from supi3.model.chip import RESREG_PULSE_CLOCKS, ChipArgumentError, ChipError, Supi3, clocks
from supi3.model.registers import SetRegisterError
from supi3.regmap import ID, IN0, OUT0, SET
from support import FakeChain

LENGTH_CODES = {1: 0b01001, 3: 0b01011, 4: 0b00010, 6: 0b00011, 16: 0b00110, 64: 0b10100}
"""Data lengths in bytes and their complete length codes (Table 3-11)."""


def extreg_set(length: int) -> int:
    """SET with ExtReg = 1 and the complete length code of ``length`` bytes (3.4.11)."""
    return SET.encode(EXTREG=1, LENGTH_CODE=LENGTH_CODES[length])


def up_chip(length: int | None, bit_rate: int = 500_000, variant: Variant = Variant.OPC) -> Supi3:
    """An Init-µP chip (RB, Table 2-4) whose SET was written: ExtReg = 1 of ``length`` bytes, or 1 internal byte
    (``None``)."""
    chip = Supi3(decode("10011", "1110", clk_conf=tables.clk_conf_for(bit_rate), variant=variant))
    assert chip.registers is not None
    chip.registers.cpu_write(SET.address, 0x82 if length is None else extreg_set(length))
    chip.registers.cpu_write(ID.address, 0x01)
    return chip


def started(*chips: Supi3) -> tuple[Ring, Master]:
    ring = Ring(list(chips))
    master = Master(ring)
    assert master.start().ok
    return ring, master


def gap_s(bit_rate: int, latched: bool = True) -> float:
    """The idle time the master leaves between cycles so that no overrun happens (RX-4): whole bit periods."""
    cpb = wire.clocks_per_bit(bit_rate)
    return -(-overrun_gap_clocks(latched, cpb) // cpb) / bit_rate


def test_manual_example_figure_3_24() -> None:
    """3 bytes travelled in the data cycle as 14h, 56h, 78h sit in the chain as bytes 0..2 = 78h, 56h, 14h."""
    chip = up_chip(3)
    chain = FakeChain(3, inputs=bytes([0xA1, 0xB2, 0xC3]))
    chip.attach_expansion(chain)
    _, master = started(chip)
    master.set_outputs(1, bytes([0x14, 0x56, 0x78]))
    assert master.data_cycle().ok
    assert chain.outputs == bytes([0x78, 0x56, 0x14])
    # The IN data: the chain's input registers loaded at the end of the cycle before, sent furthest byte first.
    assert master.inputs(1) == bytes([0xC3, 0xB2, 0xA1]) == chain_to_line(chain.inputs)
    assert chip.events["VALID"] == 1 and chip.events["EXPANSION_OVERRUN"] == 0


@pytest.mark.parametrize("bit_rate", tables.BIT_RATES)
@pytest.mark.parametrize("length", sorted(LENGTH_CODES))
def test_every_length_moves_data_both_ways(length: int, bit_rate: int) -> None:
    chip = up_chip(length, bit_rate)
    chain = FakeChain(length)
    chip.attach_expansion(chain)
    ring, master = started(chip)
    assert master.entry(1).data_bytes == length
    for k in range(3):
        out = bytes((17 * k + 5 * i + length) & 0xFF for i in range(length))
        chain.inputs = bytes((31 * k + 7 * i) & 0xFF for i in range(length))
        sent = chain_to_line(chain.contents)  # what the chain holds now: loaded at the previous cycle's end
        ring.idle(gap_s(bit_rate))
        master.set_outputs(1, out)
        assert master.data_cycle().ok
        assert chain.outputs == line_to_chain(out)
        assert master.inputs(1) == sent
        assert chain.contents == chain.inputs  # /LaInD after the latch: the next cycle's IN data
    assert chip.events["VALID"] == 3 and chip.events["EXPANSION_OVERRUN"] == 0


def test_internal_data_registers_are_out_of_the_data_path() -> None:
    """RX-2: with ExtReg = 1 neither IN bytes nor OUT bytes of the register file move: the chain's bytes are sent
    (a grounded FromExR, no chain, sends 0 bits for the whole frame: RX-13, test_detach_grounds_from_exr)."""
    chip = up_chip(1)
    chip.attach_expansion(FakeChain(1))
    assert chip.registers is not None and chip.expansion
    registers = chip.registers
    with registers.pedantic_paused():
        registers.cpu_write(IN0.address, 0x77)
    _, master = started(chip)
    master.set_outputs(1, b"\x99")
    assert master.data_cycle().ok
    assert master.inputs(1) == b"\x00"  # the chain's, not IN0's
    assert registers.value("OUT0") == 0 and registers.value(OUT0.name) == 0
    assert chip.events["VALID"] == 1


def test_without_extreg_the_chain_is_not_used() -> None:
    chip = up_chip(None)
    chain = FakeChain(1, inputs=b"\x55")
    chip.attach_expansion(chain)
    assert not chip.expansion
    _, master = started(chip)
    master.set_outputs(1, b"\x99")
    assert master.data_cycle().ok
    assert chain.calls == [] and chain.outputs == b"\x00"


def test_ls_refuses_extreg() -> None:
    """RX-1: 3.5 "not possible with the SUPI 3 LS"."""
    chip = Supi3(decode("10011", "1110", variant=Variant.LS))
    assert chip.registers is not None
    with pytest.raises(SetRegisterError, match="SUPI 3 LS"):
        chip.registers.cpu_write(SET.address, extreg_set(3))
    assert not chip.registers.configured and not chip.expansion
    with pytest.raises(ChipArgumentError, match="must be a SUPI 3 OPC"):
        chip.attach_expansion(FakeChain(3))


@pytest.mark.parametrize(
    ("chip", "chain", "message"),
    [
        (lambda: up_chip(3), lambda: "chain", "chain must be an ExternalRegisters"),
        (lambda: up_chip(3), lambda: 3, "chain must be an ExternalRegisters"),
        (lambda: Supi3(decode("10000")), lambda: FakeChain(3), "must be in an Init-µP mode"),
        (lambda: Supi3(decode("10000")), lambda: None, "must be in an Init-µP mode"),
    ],
)
def test_attach_refuses_bad_arguments(chip: object, chain: object, message: str) -> None:
    target = chip()  # type: ignore[operator]
    with pytest.raises(ArgumentError, match=message) as caught:
        target.attach_expansion(chain())  # type: ignore[operator]
    assert isinstance(caught.value, ChipError)
    assert target.expansion_chain is None


def test_chain_of_another_length_is_named() -> None:
    chip = up_chip(3)
    chip.attach_expansion(FakeChain(4))
    _, master = started(chip)
    with pytest.raises(ChipError, match=r"as long as SET's data length at transaction level \(3 bytes"):
        master.data_cycle()


def test_detach_grounds_from_exr() -> None:
    """RX-13: with the chain taken off FromExR is grounded: the chip sends 0 bits for the whole frame, the loopback
    word included, as at pin level (test_model_expansion_pins): the data cycle fails, nothing is latched."""
    chip = up_chip(1)
    chain = FakeChain(1, inputs=b"\xff")
    chip.attach_expansion(chain)
    chip.attach_expansion(None)
    assert chip.expansion_chain is None
    _, master = started(chip)
    result = master.data_cycle()
    assert not result.ok and result.diagnostics[0].kind is ErrorKind.LOOPBACK
    assert master.inputs(1) == b"\x00" and chip.constant_output == 0 and chip.events["VALID"] == 0


def test_interbus_reset_clears_the_chain_and_pulses_resreg_4_t0() -> None:
    """RX-5: /ResReg low 4 t0 on an INTERBUS reset with ExtReg = 1 (Table 3-15 t8)."""
    for bit_rate in tables.BIT_RATES:
        chip = up_chip(3, bit_rate)
        chain = FakeChain(3)
        chip.attach_expansion(chain)
        ring, master = started(chip)
        master.set_outputs(1, b"\x01\x02\x03")
        assert master.data_cycle().ok and chain.outputs == b"\x03\x02\x01"
        chain.calls.clear()
        at = clocks(ring.now)
        chip.reset_at(at)
        assert chain.calls == ["clear"] and chain.outputs == bytes(3)
        assert chip.resreg_until == at + PULSE_T0 * wire.clocks_per_bit(bit_rate)


def test_without_extreg_an_interbus_reset_gives_no_resreg_pulse() -> None:
    chip = up_chip(None)
    chip.reset_at(1000)
    assert chip.resreg_until == 0


def test_watchdog_reset_pulses_resreg_4_t0_with_extreg_and_375_ns_without() -> None:
    for length, width in ((3, PULSE_T0 * wire.clocks_per_bit(500_000)), (None, RESREG_PULSE_CLOCKS)):
        chip = up_chip(length)
        chain = FakeChain(3)
        if length is not None:
            chip.attach_expansion(chain)
        ring, master = started(chip)
        master.set_watchdog(tables.WATCHDOG_TIMEOUTS_S[1])
        assert master.cycle().cycle is wire.Cycle.ID  # the command word goes out in an ID cycle
        assert master.cycle().ok
        chain.calls.clear()
        ring.idle(1.0)
        master.cycle()
        assert chip.events["WATCHDOG"] == 1
        assert chip.resreg_until - width in range(clocks(ring.now))
        assert chain.calls[:1] == (["clear"] if length is not None else [])


@pytest.mark.parametrize("bit_rate", tables.BIT_RATES)
def test_back_to_back_data_cycles_overrun_and_a_gap_of_8_bits_does_not(bit_rate: int) -> None:
    """RX-4: after a latched data cycle the end pulses last 13 t0; a frame's first ClkExR rise comes 5.25 bit
    periods after its start, the pulses begin half a bit before the previous cycle ends: 7.75 bits of idle line."""
    chip = up_chip(1, bit_rate)
    chip.attach_expansion(FakeChain(1))
    ring, master = started(chip)
    assert master.data_cycle().ok  # after an ID cycle: only /LaInD, never an overrun
    assert chip.events["EXPANSION_OVERRUN"] == 0
    assert master.data_cycle().ok
    assert chip.events["EXPANSION_OVERRUN"] == 1
    ring.idle(7 / bit_rate)
    assert master.data_cycle().ok
    assert chip.events["EXPANSION_OVERRUN"] == 2
    ring.idle(8 / bit_rate)
    assert master.data_cycle().ok
    assert chip.events["EXPANSION_OVERRUN"] == 2
    assert gap_s(bit_rate) == 8 / bit_rate
    assert gap_s(bit_rate, latched=False) == 0


def test_discarded_cycle_loads_inputs_without_taking_outputs() -> None:
    chip = up_chip(1)
    chain = FakeChain(1, inputs=b"\x42")
    chip.attach_expansion(chain)
    ring, _ = started(chip)
    chain.calls.clear()
    transfer = ring.transfer(wire.Cycle.DATA, wire.LOOPBACK_BYTES_ON_LINE + b"\x99")
    ring.finish(transfer, latch=False)
    assert chain.calls == ["load_inputs"] and chain.outputs == b"\x00"
    assert chip.events["INVALID"] == 1

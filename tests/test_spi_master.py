"""The software µP (supi3.spi.master.SoftMaster) on the whole chip at pin level (supi3.top.ChipPort on a
Supi3Chip): the manual's byte sequences in Motorola and Intel mode, strict (any Table 3-7 violation would raise),
with the INTERBUS line fed while the µP works; the C/D, /IRQ and I/O pins as the µP reads them; SAS_INIT."""

from __future__ import annotations

import numpy as np
import pytest

from supi3.config import decode
from supi3.interbus import wire
from supi3.model.pins import RESET_STRETCH_CLOCKS
from supi3.regmap import BLOCK_ADDRESS, ID, IN0, IRQ_EN, IRQ_EVT, OUT0, SET, Register, encode_command
from supi3.spi.master import SoftMaster
from supi3.spi.slave_pins import TimingViolationError
from supi3.spi.upif import C_D_COMMAND, C_D_DATA, Mode, Phase
from supi3.tables import BIT_RATES, clk_conf_for
from supi3.top import QUIET_BOARD, ChipPort, Supi3Chip, up_input_levels
from support import IDLE, data_frame, id_frame

VALID_BIT = 0x10  # IRQ_EN/IRQ_EVT bit of the valid-data-cycle event (Table 3-13)
THREE_BYTES = SET.encode(PCP_N=1, CL=SET.field("CL").value("LEN_3_BYTES").value)  # 3.4.6: a 24-bit device


def session(mode: Mode, bit_rate: int = 2_000_000) -> tuple[SoftMaster, ChipPort]:
    """A strict RB chip in Init-µP mode on a quiet board, past its power-up reset, initialized for ``mode``."""
    port = ChipPort(Supi3Chip(decode("10011", "1110", clk_conf=clk_conf_for(bit_rate)), strict=True))
    master = SoftMaster(port, mode, record=False)
    master.run(2 * RESET_STRETCH_CLOCKS)  # the power-up reset's stretch (M2)
    master.byte(mode.init_byte)
    master.deselect()
    return master, port


def write(master: SoftMaster, register: Register, value: int) -> None:
    master.byte(encode_command(register.address, wr=True))
    master.byte(value)
    master.deselect()


def read(master: SoftMaster, register: Register) -> int | None:
    master.byte(encode_command(register.address, rd=True))
    value = master.byte(0, s_r=False)  # Intel: the chip sends (S/R = 0); Motorola: full duplex
    master.deselect()
    return value


def drain(master: SoftMaster, port: ChipPort, levels: np.ndarray) -> list[int]:
    """Send master line levels through the chip while the µP idles; the I/O bit (MFP1) of every cycle."""
    port.feed(wire.levels_to_samples(levels, port.registers.config.bit_rate))
    return [out.io for out in master.run(port.queued)]


@pytest.mark.parametrize("bit_rate", BIT_RATES)
@pytest.mark.parametrize("mode", list(Mode))
def test_configuration_example_of_3_4_5(mode: Mode, bit_rate: int) -> None:
    master, port = session(mode, bit_rate)
    assert master.c_d == C_D_COMMAND
    seen = []
    for byte in (0x4D, 0x82, 0x4C, 0x01):  # 3.4.5, Figs. 3-10 and 3-11: SET = 82h, ID = 01h
        master.byte(byte)
        master.deselect()
        seen.append(master.c_d)
    assert seen == [C_D_DATA, C_D_COMMAND, C_D_DATA, C_D_COMMAND]  # C/D announces the data byte (3.4.4)
    registers = port.registers
    assert (registers.value("SET"), registers.value("ID")) == (0x82, 0x01)
    assert registers.bus_id_register() == 0x0901  # what the master reads in the ID cycle
    assert read(master, SET) == 0x82 and read(master, ID) == 0x01
    assert registers.violations.records == []


@pytest.mark.parametrize("mode", list(Mode))
def test_read_of_out_after_a_data_cycle(mode: Mode) -> None:
    master, port = session(mode)
    write(master, SET, 0x82)
    write(master, ID, 0x01)
    write(master, IRQ_EN, VALID_BIT)
    assert master.irq_n == 1 and master.io == 0
    command = wire.command_word()
    drain(master, port, np.concatenate([IDLE, wire.reset_levels(1), IDLE, id_frame(command), IDLE]))
    io = drain(master, port, np.concatenate([data_frame(b"\x99"), IDLE]))
    assert 1 in io and io[-1] == 0  # the I/O bit marked the check sequence and latch phase (3.4.14)
    assert master.irq_n == 0  # /IRQ: valid data cycle
    assert read(master, OUT0) == 0x99
    assert read(master, IRQ_EVT) == VALID_BIT  # reading the event register releases /IRQ
    assert master.irq_n == 1
    write(master, IN0, 0x77)
    assert port.registers.in_bytes() == b"\x77"
    assert port.registers.violations.records == []


@pytest.mark.parametrize("mode", list(Mode))
def test_block_transfer_of_3_4_6(mode: Mode) -> None:
    master, port = session(mode)
    write(master, SET, THREE_BYTES)
    write(master, ID, 0x01)
    drain(master, port, np.concatenate([IDLE, wire.reset_levels(1), IDLE, id_frame(wire.command_word()), IDLE,
                                        data_frame(bytes([0x14, 0x56, 0x78])), IDLE]))
    if mode is Mode.INTEL:  # Fig. 3-12: 8Fh, then the three OUT bytes, the chip sending (S/R = 0)
        master.byte(encode_command(BLOCK_ADDRESS, rd=True))
        got = [master.byte(0, s_r=False) for _ in range(3)]
    else:  # full duplex: each byte sends IN byte k and receives OUT byte k
        master.byte(encode_command(BLOCK_ADDRESS, rd=True, wr=True))
        got = [master.byte(value) for value in (0xA1, 0xA2, 0xA3)]
    master.deselect()
    assert got == [0x14, 0x56, 0x78]
    assert master.c_d == C_D_COMMAND
    if mode is Mode.MOTOROLA:
        assert port.registers.in_bytes() == bytes([0xA1, 0xA2, 0xA3])
    assert port.registers.violations.records == []


@pytest.mark.parametrize("mode", list(Mode))
def test_sas_init_pulse_restarts_the_interface_and_keeps_the_registers(mode: Mode) -> None:
    master, port = session(mode)
    write(master, SET, 0x82)
    master.byte(encode_command(ID.address, wr=True))
    master.deselect()
    assert master.c_d == C_D_DATA  # a data byte is due
    master.pulse_sas_init()
    master.run(master.timing.gap)
    assert port.upif.protocol.phase is Phase.INIT and master.c_d == C_D_COMMAND
    assert port.registers.value("SET") == 0x82  # 3.4.3: SAS_INIT keeps the registers
    master.byte(mode.init_byte)
    master.deselect()
    assert read(master, SET) == 0x82
    with pytest.raises(TimingViolationError, match="t_SAS_INIT"):
        master.pulse_sas_init(1)  # 31.25 ns: shorter than Table 3-7's 250 ns


def test_port_holds_the_other_pins_and_names_bad_ones() -> None:
    chip = Supi3Chip(decode("10011", "1110", clk_conf="11"))
    port = ChipPort(chip, stat_err_n=0, mfp_in=0xAB00)
    assert port.inputs["stat_err_n"] == 0 and port.inputs["do1"] == 1
    master = SoftMaster(port, Mode.MOTOROLA, record=False)
    master.run(10)
    assert port.last["resu_drive"] == 1 and master.c_d == C_D_COMMAND
    with pytest.raises(ValueError, match="input pin names"):
        ChipPort(chip, sclk=1)
    with pytest.raises(ValueError, match="pin 'resu_n'"):
        ChipPort(chip, resu_n=2)
    with pytest.raises(ValueError, match="no serial µP interface"):
        ChipPort(Supi3Chip(decode("10000", clk_conf="11")))


@pytest.mark.parametrize("mode", list(Mode))
def test_port_feeds_the_line_while_the_up_works_as_step_would(mode: Mode) -> None:
    # The port steps short holds and runs long ones; either way the chip sees what step() would give it.
    config = decode("10011", "1110", clk_conf="11")
    port = ChipPort(Supi3Chip(config, strict=False))
    master = SoftMaster(port, mode)  # recording: every cycle's µP pins
    master.run(2 * RESET_STRETCH_CLOCKS)
    samples = wire.levels_to_samples(np.concatenate([IDLE, wire.reset_levels(1), IDLE, id_frame(wire.command_word()),
                                                     IDLE, data_frame(b"\x5a"), IDLE]), 2_000_000)
    port.feed(samples)
    master.byte(mode.init_byte)
    write(master, SET, 0x82)
    write(master, ID, 0x01)
    master.run(port.queued + 100)
    assert port.queued == 0
    reference = Supi3Chip(config, strict=False)
    pins = master.trace().inputs
    do1 = [*samples.tolist(), *[1] * (len(pins) - len(samples) - 2 * RESET_STRETCH_CLOCKS)]
    do1 = [1] * 2 * RESET_STRETCH_CLOCKS + do1
    for level, up in zip(do1, pins, strict=True):
        last = reference.step({**QUIET_BOARD, "do1": level, "mfp_in": up_input_levels(up)})
    assert last == port.last
    assert port.chip.chip.events == reference.chip.events
    assert port.registers.value("OUT0") == 0x5A
    assert reference.upif is not None
    assert [str(v) for v in port.registers.violations.records] == [
        str(v) for v in reference.upif.registers.violations.records]  # fmt: skip

"""A pin-level ring of whole chips (supi3.model.pinring.PinRing of supi3.top.Supi3Chip): chips in an Init-µP mode
configured by their µP through the serial interface (SET and ID written, 3.4.5), an INTERBUS master running ID and
data cycles over them, process data moving end to end between the master and each chip's µP."""

from __future__ import annotations

import pytest

from supi3.config import decode
from supi3.interbus.master import Master
from supi3.model.pinring import PinChip, PinRing
from supi3.model.pins import RESET_STRETCH_CLOCKS, Supi3Pins
from supi3.regmap import ID, IN0, IN1, OUT0, OUT1, SET, Register, encode_command
from supi3.spi.master import SoftMaster
from supi3.spi.upif import Mode
from supi3.top import UP_REST, ChipPort, Supi3Chip

ONE_BYTE = SET.encode(PCP_N=1, CL=SET.field("CL").value("LEN_1_BYTE").value)  # 82h, as in 3.4.5 (Table 3-12)
ONE_WORD = SET.encode(PCP_N=1, CL=SET.field("CL").value("LEN_1_WORD").value)


class Firmware:
    """One chip's µP on its MFP pins (strict: any Table 3-7 or protocol violation raises)."""

    def __init__(self, chip: Supi3Chip, mode: Mode) -> None:
        self.master = SoftMaster(ChipPort(chip, mfp_in=UP_REST), mode, record=False)
        self.master.run(2 * RESET_STRETCH_CLOCKS)
        self.master.byte(mode.init_byte)

    def write(self, register: Register, value: int) -> None:
        self.master.byte(encode_command(register.address, wr=True))
        self.master.byte(value)
        self.master.deselect()

    def read(self, register: Register) -> int | None:
        self.master.byte(encode_command(register.address, rd=True))
        value = self.master.byte(0, s_r=False)
        self.master.deselect()
        return value


@pytest.mark.parametrize("modes", [(Mode.MOTOROLA, Mode.INTEL), (Mode.INTEL, Mode.MOTOROLA)])
def test_master_exchanges_process_data_with_each_chips_firmware(modes: tuple[Mode, Mode]) -> None:
    config = decode("10011", "1110", clk_conf="11")  # RB, Init-µP, 2 Mbit/s
    chips = [Supi3Chip(config), Supi3Chip(config)]
    firmware = [Firmware(chip, mode) for chip, mode in zip(chips, modes, strict=True)]
    for fw, (set_value, id_code) in zip(firmware, [(ONE_BYTE, 0x01), (ONE_WORD, 0x03)], strict=True):
        fw.write(SET, set_value)
        fw.write(ID, id_code)
    ring = PinRing(chips)
    for position in (1, 2):
        ring.set_input(position, "mfp_in", UP_REST)  # the µP rests while the ring runs
    master = Master(ring, locate=False, max_devices=4)
    assert master.start().ok
    assert [(master.entry(k).id_code, master.entry(k).data_bytes) for k in (1, 2)] == [(0x01, 1), (0x03, 2)]
    ring.settle()
    # IN data: written by each µP after the INTERBUS reset of start() (3.4.7 clears them), read by the master.
    firmware[0].write(IN0, 0x5A)
    firmware[1].write(IN0, 0x12)
    firmware[1].write(IN1, 0x34)
    master.set_outputs(1, b"\xc3")
    master.set_outputs(2, b"\xbe\xef")
    assert master.data_cycle().ok
    ring.settle()
    assert master.inputs(1) == b"\x5a" and master.inputs(2) == b"\x12\x34"
    # OUT data: latched into each chip's OUT registers, read by its µP.
    assert firmware[0].read(OUT0) == 0xC3
    assert (firmware[1].read(OUT0), firmware[1].read(OUT1)) == (0xBE, 0xEF)
    assert all(chip.chip.events["VALID"] == 1 for chip in chips)
    assert all(not chip.chip.registers.violations.records for chip in chips if chip.chip.registers is not None)


def test_ring_takes_cores_and_whole_chips() -> None:
    core_config = decode("10000", clk_conf="11")  # the demo device: pin-strapped, no µP interface
    core, chip = Supi3Pins(core_config), Supi3Chip(decode("10011", "1110", clk_conf="11"))
    assert isinstance(core, PinChip) and isinstance(chip, PinChip)
    fw = Firmware(chip, Mode.MOTOROLA)
    fw.write(SET, ONE_BYTE)
    fw.write(ID, 0x01)
    ring = PinRing([core, chip])
    ring.set_input(2, "mfp_in", UP_REST)
    ring.idle(0.0002)  # the core's power-up reset stretch
    master = Master(ring, locate=False, max_devices=4)
    assert master.start().ok
    assert [master.entry(k).id_code for k in (1, 2)] == [core_config.id_code, 0x01]
    with pytest.raises(ValueError, match="chips must be a sequence of Supi3Pins or Supi3Chip"):
        PinRing([core, "chip"])  # type: ignore[list-item]

"""A pin-level ring of whole chips (supi3.model.pinring.PinRing of supi3.top.Supi3Chip): chips in an Init-µP mode
configured by their µP through the serial interface (SET and ID written, 3.4.5), an INTERBUS master running ID and
data cycles over them, process data moving end to end between the master and each chip's µP. And the line after
power-up: a chip that leaves its reset stretch (M2, 1.7.2) in the middle of a telegram resynchronises (M7, M16), so
the master starts the ring after any idle time at either bit rate (Table 1-7)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from supi3.config import decode
from supi3.interbus import wire
from supi3.interbus.master import Master
from supi3.interbus.receiver import receive
from supi3.interbus.wire import Cycle, Telegram
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


CLK_CONF_500K, CLK_CONF_2M = "01", "11"  # Table 1-7: CLK_CONF1..0 for 500 kbit/s and 2 Mbit/s
IDLE_STATUS = Telegram(Cycle.DATA, False, None)


def _idle_ring(clk_conf: str, chips: int, idle_telegrams: int) -> PinRing:
    """Demo devices (pin-strapped, ID 01h) powered up together, then ``idle_telegrams`` idle status telegrams."""
    ring = PinRing([Supi3Pins(decode("10000", None, clk_conf=clk_conf)) for _ in range(chips)])
    ring.idle(idle_telegrams * wire.STATUS_TELEGRAM_BITS / ring.bit_rate)
    return ring


@settings(max_examples=8)
@given(clk_conf=st.sampled_from([CLK_CONF_500K, CLK_CONF_2M]), chips=st.integers(1, 3),
       idle_telegrams=st.integers(0, 60), data_cycles=st.integers(1, 3))  # fmt: skip
@example(clk_conf=CLK_CONF_500K, chips=1, idle_telegrams=6, data_cycles=1)  # 32 bit periods: failed before M16
@example(clk_conf=CLK_CONF_500K, chips=3, idle_telegrams=20, data_cycles=2)  # 100 bit periods
def test_master_starts_the_ring_after_any_idle_from_power_up(
    clk_conf: str, chips: int, idle_telegrams: int, data_cycles: int
) -> None:
    ring = _idle_ring(clk_conf, chips, idle_telegrams)
    master = Master(ring, locate=False, max_devices=4)
    result = master.start()
    assert result.ok, result.diagnostics
    assert [master.entry(k).id_code for k in range(1, chips + 1)] == [ring.devices[0].config.id_code] * chips
    for _ in range(data_cycles):
        result = master.data_cycle()
        assert result.ok, result.diagnostics


@pytest.mark.parametrize("clk_conf", [CLK_CONF_500K, CLK_CONF_2M])
def test_a_chip_leaving_reset_mid_telegram_repeats_the_line_bit_for_bit(clk_conf: str) -> None:
    """M16, M19: the chip misreads the telegram it woke up in (at 2 Mbit/s as a data telegram), and a stop bit read at
    start level puts its receiver back on the telegram grid; no frame begins before a whole status telegram (M19), so
    it sends the misread bits on as received (before M19 it began a frame there and sent its register in their place,
    M8) and DO2 is the master's line 3 bit periods later (A10), read mid-bit, from the first bit period the chip sees
    whole. Before M16 such a stop bit restarted the receiver in the middle of a bit period, and the repeated line
    slipped by half a bit period."""
    chip = Supi3Pins(decode("10000", None, clk_conf=clk_conf))
    ring = PinRing([chip], record=True)
    count = 40
    ring.run_levels(wire.status_levels(Cycle.DATA, False, count))
    sent = wire.status_levels(Cycle.DATA, False, count)
    do2 = ring.recorded()[0]["do2"].astype(np.uint8)
    first = -(-RESET_STRETCH_CLOCKS // ring.cpb)  # the first bit period the chip sees whole after its reset
    assert first % wire.STATUS_TELEGRAM_BITS != 0  # it wakes up inside a telegram at both bit rates
    delay = wire.REPEATER_DELAY_BITS
    for phase in (ring.cpb // 4, ring.cpb // 2, 3 * ring.cpb // 4):  # whole bit periods, not just their middles
        repeated = wire.samples_to_levels(do2, ring.bit_rate, phase)
        assert np.array_equal(repeated[first + delay :], sent[first : len(sent) - delay]), phase
    assert not any("load" in entry for entry in chip.log.recent())  # no frame began


def test_the_rings_receiver_resynchronises_after_a_fragment() -> None:
    """A telegram's tail (a chip waking up inside it) then idle status telegrams: the stop bit read at start level
    is taken as the next start bit (M16), so the receiver finds the telegram grid again within two telegrams."""
    status = wire.status_levels(Cycle.DATA, False, 6)
    levels = np.concatenate([np.ones(5, dtype=np.uint8), status[2:wire.STATUS_TELEGRAM_BITS], status])
    cpb = wire.clocks_per_bit(500_000)
    telegrams, rest, error = receive(wire.levels_to_samples(levels, 500_000), 0, cpb)
    assert error and telegrams == [IDLE_STATUS] * 5 and rest == len(levels) * cpb

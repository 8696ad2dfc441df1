"""The RTL chip top (supi3.rtl.chip) against the whole-chip model (supi3.top), every pin every clock.

One Verilator build serves every scenario (the straps are ports). Stimulus is made by running the scenario on the
model itself: the INTERBUS master's line levels on do1 and a software µP (support.Firmware, over
supi3.spi.master.SoftMaster with Table 3-7 timing) on MFP[7..0], which reads the chip's answers off the model. The
recorded pins are then replayed through the batch lockstep, which is exact up to the first mismatch.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from supi3.config import decode
from supi3.interbus import wire
from supi3.regmap import IN0, IN1, OUT0
from supi3.rtl.chip import verilog
from supi3.spi.upif import Mode
from supi3.tables import BIT_RATES, clk_conf_for
from supi3.top import UP_OUTPUTS
from supi3.verif import Lockstep
from supi3.verif.straps import ChipStrapPins
from support import IDLE, LOOPBACK, RB_INIT_UP, ChipPins, Firmware, bring_up, data_frame, id_frame

IRQ_EVENTS = 14  # read: interrupt events (clears them); write: interrupt enables (3.4.14)
SET, ID = 13, 12  # writes (3.4.5)
PCMD_ALARM = 7  # read: processor command; write: processor alarm (3.4.9)


@pytest.fixture(scope="session")
def bench(chip_bench: Lockstep) -> Lockstep:
    return chip_bench  # tests/conftest.py: one build, shared with tests/test_verif_lockstep_serial.py


def replay(bench: Lockstep, pins: ChipPins) -> None:
    result = bench.run_batch(pins.stimulus())
    assert result.cycles == pins.cycle


# Scenarios ----------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("mode", list(Mode))
def test_firmware_configures_the_chip_and_exchanges_data(bench: Lockstep, mode: Mode) -> None:
    pins = ChipPins(decode(*RB_INIT_UP, clk_conf="11"))
    up = Firmware(pins, mode)
    up.idle(300)  # the power-up reset
    up.init()
    up.write(SET, 0x82)  # I/O device with 1 byte (3.4.5)
    up.write(ID, 0x01)
    up.write(IRQ_EVENTS, 0x10)  # the valid-data-cycle interrupt
    assert up.read(SET) == 0x82 and up.read(ID) == 0x01
    start = pins.cycle
    bring_up(pins)
    pins.drain()
    up.write(IN0, 0x77)  # IN byte 0, after the INTERBUS reset cleared it (3.4.7)
    pins.send(np.concatenate([data_frame(b"\x99"), IDLE]))
    pins.drain(64)
    returned = [out["di1"] for out in pins.outputs[start + 3 * wire.clocks_per_bit(pins.config.bit_rate) :]]
    frames = wire.frames_from_levels(wire.samples_to_levels(np.array(returned, dtype=np.uint8), pins.config.bit_rate))
    assert frames[0].data == wire.word_bytes(0x0901) + LOOPBACK  # ID 01h, length code 01001 (1 byte)
    assert frames[1].data == b"\x77" + LOOPBACK
    assert pins.outputs[-1]["mfp_out"] >> UP_OUTPUTS["irq_n"] & 1 == 0  # /IRQ: valid data cycle
    assert (up.read(IRQ_EVENTS) or 0) & 0x10
    assert pins.outputs[-1]["mfp_out"] >> UP_OUTPUTS["irq_n"] & 1 == 1  # released by the read
    assert up.read(OUT0) == 0x99  # OUT byte 0
    replay(bench, pins)


def test_management_channel(bench: Lockstep) -> None:
    pins = ChipPins(decode(*RB_INIT_UP, clk_conf="11"))
    up = Firmware(pins, Mode.MOTOROLA)
    up.idle(300)
    up.init()
    up.write(SET, 0x82)
    up.write(ID, 0x01)
    up.write(IRQ_EVENTS, 0xFF)  # every interrupt source
    up.write(PCMD_ALARM, 0x5A)  # the processor alarm
    start = pins.cycle
    bring_up(pins)
    pins.drain()
    assert up.read(IRQ_EVENTS) is not None  # clear the events of the reset and the ID cycle
    pins.send(np.concatenate([id_frame(wire.command_word(processor_command=0xC3, alarm_request=True)), IDLE,
                              id_frame(0), IDLE]))  # fmt: skip
    pins.drain(64)
    assert pins.outputs[-1]["mfp_out"] >> UP_OUTPUTS["irq_n"] & 1 == 0
    assert up.read(PCMD_ALARM) == 0xC3
    returned = [out["di1"] for out in pins.outputs[start + 3 * wire.clocks_per_bit(pins.config.bit_rate) :]]
    frames = wire.frames_from_levels(wire.samples_to_levels(np.array(returned, dtype=np.uint8), pins.config.bit_rate))
    assert frames[-1].data[:2] == wire.word_bytes(0x095A)  # the alarm in place of the ID code (A18)
    replay(bench, pins)


def test_binary_io_mode_through_the_top(bench: Lockstep) -> None:
    pins = ChipPins(decode("10000", clk_conf="11"))  # 8 IN / 8 OUT on the MFPs; the µP block idles
    rng = np.random.default_rng(3)
    pins.drain(300)
    bring_up(pins)
    for _ in range(3):
        pins.send(np.concatenate([data_frame(bytes([int(rng.integers(0, 256))])), IDLE]))
    while pins.line:
        pins.step(mfp_in=int(rng.integers(0, 1 << 16)) if rng.random() < 0.01 else pins.pins["mfp_in"])
    replay(bench, pins)


OPS = st.lists(
    st.tuples(st.sampled_from(["read", "write", "frame", "idle"]), st.integers(0, 15), st.integers(0, 255)),
    min_size=4,
    max_size=14,
)


@settings(max_examples=4, derandomize=True, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(mode=st.sampled_from(list(Mode)), rate=st.sampled_from([clk_conf_for(r) for r in BIT_RATES]), ops=OPS)
def test_random_interleavings(bench: Lockstep, mode: Mode, rate: str, ops: list[tuple[str, int, int]]) -> None:
    pins = ChipPins(decode(*RB_INIT_UP, clk_conf=rate))
    up = Firmware(pins, mode)
    up.idle(300)
    up.init()
    up.write(SET, 0x82)
    up.write(IRQ_EVENTS, 0xFF)
    bring_up(pins)
    for op, address, value in ops:
        if op == "read":
            up.read(address)
        elif op == "write" and address != SET:  # SET with ExtReg would leave the internal data path
            up.write(address, value)
        elif op == "frame":  # sent while the µP works on
            latch = value & 1 == 0
            pins.send(np.concatenate([data_frame(bytes([value]), latch=latch), IDLE]))
        else:
            up.idle(value * 8)
    pins.drain(64)
    replay(bench, pins)


def test_power_fail_and_watchdog(bench: Lockstep) -> None:
    pins = ChipPins(decode(*RB_INIT_UP, clk_conf="11"))
    up = Firmware(pins, Mode.MOTOROLA)
    up.idle(300)
    up.init()
    up.write(SET, 0x82)
    up.write(IRQ_EVENTS, 0xFF)
    up.write(IN0, 0x31)
    pins.pins["resu_n"] = 0  # /ResU pulled low from outside: both blocks reset
    up.idle(5)
    pins.pins["resu_n"] = 1
    up.idle(300)
    up.init()
    up.write(SET, 0x82)
    up.write(IRQ_EVENTS, 0xFF)
    bring_up(pins, wire.command_word(watchdog_code=0))  # 50 ms watchdog
    pins.send(np.concatenate([data_frame(b"\x42"), IDLE]))
    pins.drain()
    up.write(IN1, 0x11)
    assert up.read(OUT0) == 0x42
    replay(bench, pins)


def test_verilog_has_the_model_ports() -> None:
    text = verilog()
    for pin in ChipStrapPins.inputs:
        width = "[" + str(pin.width - 1) + ":0] " if pin.width > 1 else ""
        # A name that is a Verilog keyword is an escaped identifier ("medium" is a charge strength, IEEE 1800).
        assert f"input {width}{pin.name};" in text or f"input {width}\\{pin.name} ;" in text

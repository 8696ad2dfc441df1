"""Lockstep of the RTL (supi3.rtl.serial_io, supi3.rtl.expansion in the core) against the model: SPI master modes
and the serial register expansion (issue #11).

Manual 3.3: every SPI master mode of Tables 2-4 to 2-6 (16 and 32 bits; IN, OUT, IN/OUT) at both bit
rates, through an INTERBUS reset, ID and data cycles with random OUT data, with a random SerIn trace on MFP6: MFP3,
4, 5, 7 (/Conv, SCLK, /SS, SerOut), the IN data sent back on DO2 and every other pin equal on every clock. One
Verilator build of the core serves every mode (the straps are ports; ``core_bench`` of tests/conftest.py, shared with
tests/test_rtl_core.py); the batch path compares.

Manual 3.5: the whole chip (supi3.rtl.chip) with firmware writing SET with ExtReg = 1 and external registers of
several lengths on the expansion pins (supi3.peripherals.sre.Sre1, clocked by the model's pins), on the chip's build
(``chip_bench``, shared with tests/test_rtl_chip.py).
"""

from __future__ import annotations

from collections import deque
from dataclasses import fields

import numpy as np
import pytest

from supi3 import serial_io
from supi3.config import DataDirection, DeviceConfig, MfpKind, Variant, decode, mode_rows
from supi3.expansion import IDLE as EXPANSION_IDLE
from supi3.expansion import ExpansionLevels, chain_to_line, line_to_chain
from supi3.interbus import wire
from supi3.interbus.wire import Cycle
from supi3.peripherals.serial import SerialBus, ShiftIn, ShiftOut
from supi3.peripherals.sre import Sre1
from supi3.regmap.registers import ID, SET
from supi3.rtl.serial_io import MFP_BITS, SER_IN_PIN, WIDTHS
from supi3.spi.upif import Mode
from supi3.tables import BIT_RATES, clk_conf_for
from supi3.verif import Lockstep
from supi3.verif.straps import StrapPins
from support import (
    IDLE,
    LOOPBACK,
    RB_INIT_UP,
    ChipPins,
    CoreScript,
    Firmware,
    bring_up,
    data_frame,
)

SPI_ROWS = [row for row in mode_rows(Variant.OPC) if decode(row.c, row.mfp).mfp_mode.kind is MfpKind.SPI_MASTER]
MODES = {(decode(row.c, row.mfp).mfp_mode.direction, decode(row.c, row.mfp).mfp_mode.width): row for row in SPI_ROWS}
"""One row per SPI master mode (the four C codes of Tables 2-4 to 2-6 repeat the same six MFP modes)."""


def spi_script(config: DeviceConfig, seed: int, data_cycles: int = 3) -> CoreScript:
    """An INTERBUS reset (the clear sequence), an ID cycle, ``data_cycles`` data cycles with random OUT data (one
    unlatched), each followed by line idle long enough for its sequence; SerIn random, changing every few clocks."""
    rng = np.random.default_rng(seed)
    script = CoreScript(config, rng).bring_up()
    script.id_cycle(wire.command_word(1))
    seq = serial_io.sequence(config.mfp_mode.direction, config.mfp_mode.width, config.bit_rate)
    idle = np.ones(seq.length // wire.clocks_per_bit(config.bit_rate) + 4, dtype=np.uint8)
    for k in range(data_cycles):
        script.data_cycle(latch=k != 1).line(idle)
    return script


def with_ser_in(script: CoreScript, seed: int) -> np.ndarray:
    """The script's stimulus with MFP6 (SerIn) replaced by a random trace holding each level 1 to 40 clocks."""
    stimulus = np.asarray(script.stimulus()).copy()
    mfp = [pin.name for pin in StrapPins.inputs].index("mfp_in")
    rng = np.random.default_rng(seed)
    n = stimulus.shape[0]
    runs = rng.integers(1, 41, n // 10 + 1)
    trace = np.repeat(rng.integers(0, 2, len(runs)), runs)[:n].astype(np.uint64)
    column = stimulus[:, mfp] & ~np.uint64(1 << SER_IN_PIN)
    stimulus[:, mfp] = column | (trace << np.uint64(SER_IN_PIN))
    return stimulus


@pytest.mark.parametrize("bit_rate", BIT_RATES)
@pytest.mark.parametrize(("direction", "bits"), list(MODES), ids=[f"{d.value}-{b}" for d, b in MODES])
def test_spi_master_modes(core_bench: Lockstep, direction: DataDirection, bits: int, bit_rate: int) -> None:
    row = MODES[(direction, bits)]
    config = decode(row.c, row.mfp, clk_conf=clk_conf_for(bit_rate))
    seed = len(MODES) * BIT_RATES.index(bit_rate) + list(MODES).index((direction, bits))
    result = core_bench.run_batch(with_ser_in(spi_script(config, seed), seed))
    assert result.cycles > 0


def with_bus(stimulus: np.ndarray, bus: SerialBus) -> tuple[np.ndarray, StrapPins]:
    """``stimulus`` with MFP6 driven by ``bus`` as on a board: the bus is clocked with the model's MFP3, 4, 5, 7 at
    every change and answers on SerIn ``PERIPHERAL_DELAY_CLOCKS`` later (SM-10); and the model after it."""
    model = StrapPins("opc")
    names = [pin.name for pin in StrapPins.inputs]
    mfp = names.index("mfp_in")
    rows = stimulus.copy()
    answers = deque([0] * serial_io.PERIPHERAL_DELAY_CLOCKS)
    seen, answer = serial_io.IDLE, 0
    for row in rows:
        row[mfp] = (int(row[mfp]) & ~(1 << SER_IN_PIN)) | (answers.popleft() << SER_IN_PIN)
        out = model.step(dict(zip(names, row.tolist(), strict=True)))["mfp_out"]
        levels = serial_io.Levels(*((out >> MFP_BITS[name]) & 1 for name in ("conv_n", "sclk", "ss_n", "ser_out")))
        if levels != seen:
            seen, answer = levels, bus.clock(levels)
        answers.append(answer)
    return rows, model


@pytest.mark.parametrize("bits", WIDTHS)
def test_shift_register_chains_end_to_end(core_bench: Lockstep, bits: int) -> None:
    """IN/OUT mode with 74HCT165 and 74HCT594 chains of the word's length on the bus (3.3.1): the master's OUT word
    reaches the output chain, the input chain's word reaches the chip's IN data, both fidelities on every pin."""
    row = MODES[(DataDirection.IN_OUT, bits)]
    config = decode(row.c, row.mfp, clk_conf=clk_conf_for(max(BIT_RATES)))
    inputs, outputs = ShiftIn(bits // 8), ShiftOut(bits // 8)
    inputs.set_inputs(0xA55A_C33C & ((1 << bits) - 1))
    script = CoreScript(config, np.random.default_rng(bits)).bring_up().id_cycle(wire.command_word(1))
    seq = serial_io.sequence(DataDirection.IN_OUT, bits, config.bit_rate)
    idle = np.ones(seq.length // wire.clocks_per_bit(config.bit_rate) + 4, dtype=np.uint8)
    sent = [bytes(range(k, k + bits // 8)) for k in (0x11, 0x41)]
    for data in sent:
        script.frame(Cycle.DATA, data).line(idle)
    stimulus, model = with_bus(np.asarray(script.stimulus()), SerialBus(inputs, outputs))
    assert outputs.outputs == int.from_bytes(sent[-1], "big")
    assert model.pins is not None and model.pins.chip.in_word == inputs.inputs
    core_bench.run_batch(stimulus)


def test_every_spi_row_decodes(core_bench: Lockstep) -> None:
    """The other C codes of the SPI master rows (RB, RB with ID code 3, LB), one short scenario each."""
    for k, row in enumerate(SPI_ROWS):
        if MODES[(decode(row.c, row.mfp).mfp_mode.direction, decode(row.c, row.mfp).mfp_mode.width)] is row:
            continue
        config = decode(row.c, row.mfp, clk_conf=clk_conf_for(max(BIT_RATES)))
        core_bench.run_batch(with_ser_in(spi_script(config, 100 + k, data_cycles=1), 100 + k))


# Serial register expansion (3.5): the whole chip, SET with ExtReg = 1 written by firmware --------------------------


class ChainPins(ChipPins):
    """:class:`support.ChipPins` with external registers on the expansion pins, as on a board: the chain is clocked
    with the chip's ClkExR, ToExR, LaOuD, /LaInD, /ResReg at every change and drives FromExR
    ``serial_io.PERIPHERAL_DELAY_CLOCKS`` later (the model's own chain interface is not used: the RTL has only pins)."""

    def __init__(self, config: DeviceConfig, chain: Sre1) -> None:
        super().__init__(config)
        self.chain = chain
        self.seen = EXPANSION_IDLE
        self.answers = deque([0] * serial_io.PERIPHERAL_DELAY_CLOCKS)
        self.answer = 0

    def step(self, **pins: int) -> dict[str, int]:
        out = super().step(from_exr=self.answers.popleft(), **pins)
        levels = ExpansionLevels(**{field.name: out[field.name] for field in fields(EXPANSION_IDLE)})
        if levels != self.seen:
            self.seen = levels
            self.answer = self.chain.clock(levels)
        self.answers.append(self.answer)
        return out


@pytest.mark.parametrize(("code", "bit_rate"), [(8, max(BIT_RATES)), (3, max(BIT_RATES)), (21, max(BIT_RATES)),
                                                (1, min(BIT_RATES))])  # fmt: skip
def test_register_expansion(chip_bench: Lockstep, code: int, bit_rate: int) -> None:
    """SET = ExtReg | length code (3.4.11, Table 3-11: 1, 6, 20 bytes at 2 Mbit/s, 2 bytes at 500 kbit/s) with a
    chain of that length on the expansion pins: after the INTERBUS reset (/ResReg 4 t0) and an ID cycle (/LaInD),
    two data cycles with random OUT data go through the chain (ToExR, ClkExR) and the chain's inputs come back
    (FromExR): the master reads them, the chain's outputs take the OUT data (LaOuD)."""
    n = wire.data_bytes(code)
    rng = np.random.default_rng(code)
    chain = Sre1(n)
    chain.set_inputs(bytes(rng.integers(0, 256, n).tolist()))
    pins = ChainPins(decode(*RB_INIT_UP, clk_conf=clk_conf_for(bit_rate)), chain)
    up = Firmware(pins, Mode.MOTOROLA)
    up.idle(300)
    up.init()
    up.write(SET, SET.encode(EXTREG=1, LENGTH_CODE=code))
    up.write(ID, 0x01)
    start = pins.cycle
    bring_up(pins)
    sent = [bytes(rng.integers(0, 256, n).tolist()) for _ in range(2)]
    for data in sent:
        pins.send(np.concatenate([data_frame(data), IDLE]))
    pins.drain(64)
    returned = [out["di1"] for out in pins.outputs[start + 3 * wire.clocks_per_bit(bit_rate) :]]
    frames = wire.frames_from_levels(wire.samples_to_levels(np.array(returned, dtype=np.uint8), bit_rate))
    assert [frame.data for frame in frames[1:]] == [chain_to_line(chain.inputs) + LOOPBACK] * 2
    assert chain.outputs == line_to_chain(sent[-1])
    result = chip_bench.run_batch(pins.stimulus())
    assert result.cycles == pins.cycle

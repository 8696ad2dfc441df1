"""The serial I/O devices (supi3.peripherals.serial, manual 3.3.1, SM-12): every device in every SPI master mode
gives the same SerIn bits and the same outputs at transaction level (frame/convert) as when clocked with the chip's
waveform (serial_io.render), and both agree with a bit-string reference of the shift registers; capture, store
and load edges; the bus; the converters' voltages."""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.config import DataDirection
from supi3.peripherals import SerialBus, SerInConflictError, ShiftIn, ShiftOut, SpiAdc, SpiDac
from supi3.spi.serial_io import IDLE, PERIPHERAL_DELAY_CLOCKS, Levels, SerialDevice, SerialSequence, render, sequence
from supi3.tables import BIT_RATES

DIRECTIONS = (DataDirection.IN, DataDirection.OUT, DataDirection.IN_OUT)
MODES = [(direction, bits) for direction in DIRECTIONS for bits in (16, 32)]


def transaction(device: SerialDevice, seq: SerialSequence, word: int) -> int:
    """The sequence at transaction level (SM-11): its frames and /Conv in pin order; the word read."""
    read = 0
    for frame in seq.frames:
        answer = device.frame(word if frame.write else 0, frame.bits)
        if not frame.write:
            read = answer
    if seq.conv is not None:
        device.convert()
    return read


def pins(device: SerialDevice, seq: SerialSequence, word: int, level: int = 0) -> tuple[int, int]:
    """The sequence's waveform, then IDLE, through :meth:`clock` at every change; each answer reaches SerIn
    PERIPHERAL_DELAY_CLOCKS later, and the read frame samples SerIn in the cycle before SCLK rises (SM-5, SM-10).
    ``level``: SerIn before the sequence. Returns the word read and SerIn after the sequence."""
    answers: list[tuple[int, int]] = []
    seen = IDLE
    for cycle, levels in enumerate([*render(seq, word), IDLE]):
        if levels != seen:
            answers.append((cycle + PERIPHERAL_DELAY_CLOCKS, device.clock(levels)))
            seen = levels

    def ser_in(cycle: int) -> int:
        return next((answer for when, answer in reversed(answers) if when <= cycle), level)

    read = seq.read
    word_read = 0 if read is None else sum(ser_in(read.sample(j)) << (read.bits - 1 - j) for j in range(read.bits))
    return word_read, answers[-1][1]


class Reference:
    """The device as a string of bits: a source sends its captured bits then zeros; a sink keeps every bit shifted
    (zeros in read frames) and stores the last ``width`` at /Conv."""

    def __init__(self, width: int) -> None:
        self.width = width
        self.shifted = "0" * width
        self.stored = 0

    def read(self, captured: int, bits: int) -> int:
        return int((f"{captured:0{self.width}b}" + "0" * bits)[:bits], 2)

    def sequence(self, seq: SerialSequence, word: int) -> None:
        for frame in seq.frames:
            self.shifted += f"{word:0{frame.bits}b}" if frame.write else "0" * frame.bits
        if seq.conv is not None:
            self.stored = int(self.shifted[-self.width :], 2)


@dataclass(frozen=True)
class Kind:
    """A device under test: how to build it, its register width, how to set its inputs, what it outputs."""

    name: str
    make: Callable[[], SerialDevice]
    width: int
    feed: Callable[[SerialDevice, int], None] | None
    output: Callable[[SerialDevice], int] | None


def _set_chain(device: SerialDevice, value: int) -> None:
    assert isinstance(device, ShiftIn)
    device.set_inputs(value)


def _set_code(device: SerialDevice, value: int) -> None:
    assert isinstance(device, SpiAdc)
    device.set_input(value)


def _chain_out(device: SerialDevice) -> int:
    assert isinstance(device, ShiftOut)
    return device.outputs


def _dac_out(device: SerialDevice) -> int:
    assert isinstance(device, SpiDac)
    return device.output


def _bus_in(device: SerialDevice, value: int) -> None:
    assert isinstance(device, SerialBus)
    _set_chain(device.devices[0], value)


def _bus_out(device: SerialDevice) -> int:
    assert isinstance(device, SerialBus)
    return _chain_out(device.devices[1])


KINDS = [
    *(Kind(f"ShiftIn({n})", partial(ShiftIn, n), 8 * n, _set_chain, None) for n in range(1, 5)),
    *(Kind(f"ShiftOut({n})", partial(ShiftOut, n), 8 * n, None, _chain_out) for n in range(1, 5)),
    *(Kind(f"SpiAdc({b})", partial(SpiAdc, b), b, _set_code, None) for b in (16, 32)),
    *(Kind(f"SpiDac({b})", partial(SpiDac, b), b, None, _dac_out) for b in (16, 32)),
    Kind("SerialBus(ShiftIn(2), ShiftOut(2))", lambda: SerialBus(ShiftIn(2), ShiftOut(2)), 16, _bus_in, _bus_out),
]


def check_both_fidelities(kind: Kind, direction: DataDirection, bits: int, bit_rate: int,
                          steps: list[tuple[int, int]]) -> None:
    """Run ``steps`` ((OUT word, inputs) per sequence) on a transaction-level and a pin-level device and the
    reference; after every sequence the word read and the outputs agree."""
    seq = sequence(direction, bits, bit_rate)
    tl, pl, ref = kind.make(), kind.make(), Reference(kind.width)
    level = 0
    for word, value in steps:
        inputs = value & ((1 << kind.width) - 1)
        if kind.feed is not None:
            kind.feed(tl, inputs)
            kind.feed(pl, inputs)
        read_tl = transaction(tl, seq, word & ((1 << bits) - 1))
        read_pl, level = pins(pl, seq, word & ((1 << bits) - 1), level)
        ref.sequence(seq, word & ((1 << bits) - 1))
        expected = ref.read(inputs, bits) if kind.feed is not None and seq.read is not None else 0
        assert read_tl == read_pl == expected
        if kind.output is not None:
            assert kind.output(tl) == kind.output(pl) == ref.stored


@pytest.mark.parametrize("kind", KINDS, ids=lambda kind: kind.name)
@pytest.mark.parametrize(("direction", "bits"), MODES)
def test_every_device_in_every_mode_agrees_at_both_fidelities(kind: Kind, direction: DataDirection,
                                                              bits: int) -> None:
    steps = [(0xA5C3_96F1, 0xDEAD_BEEF), (0x0123_4567, 0x8000_0001), (0xFFFF_FFFF, 0x7F3C_55AA)]
    check_both_fidelities(kind, direction, bits, 2_000_000, steps)


@settings(max_examples=25)
@given(
    kind=st.sampled_from(KINDS),
    mode=st.sampled_from(MODES),
    bit_rate=st.sampled_from(BIT_RATES),
    steps=st.lists(st.tuples(st.integers(0, 2**32 - 1), st.integers(0, 2**32 - 1)), min_size=1, max_size=3),
)
def test_random_words_agree_at_both_fidelities(kind: Kind, mode: tuple[DataDirection, int], bit_rate: int,
                                               steps: list[tuple[int, int]]) -> None:
    check_both_fidelities(kind, *mode, bit_rate, steps)


# What a user sees -----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("bits", [16, 32])
def test_matched_widths_carry_the_words_unchanged(bits: int) -> None:
    """A 16/32-bit chain or converter in the mode of its width: IN word = inputs, outputs = OUT word (3.3.1)."""
    seq = sequence(DataDirection.IN_OUT, bits, 2_000_000)
    chain_in, chain_out, adc, dac = ShiftIn(bits // 8), ShiftOut(bits // 8), SpiAdc(bits), SpiDac(bits)
    chain_in.set_inputs(0x8421_F00F >> (32 - bits))
    adc.set_input(0x1357_9BDF >> (32 - bits))
    assert transaction(SerialBus(chain_in, chain_out), seq, 0xCAFE_F00D >> (32 - bits)) == 0x8421_F00F >> (32 - bits)
    assert transaction(SerialBus(adc, dac), seq, 0x2468_ACE0 >> (32 - bits)) == 0x1357_9BDF >> (32 - bits)
    assert chain_out.outputs == 0xCAFE_F00D >> (32 - bits)
    assert dac.output == 0x2468_ACE0 >> (32 - bits)


def test_short_and_long_chains_in_a_16_bit_mode() -> None:
    """A 1-byte 74HCT165 fills the IN word's high byte, zeros after (DS grounded); a 4-byte 74HCT594 in
    input/output mode holds the read frame's zeros above the OUT word (it has no select input, PR-3)."""
    seq = sequence(DataDirection.IN_OUT, 16, 2_000_000)
    short, long = ShiftIn(1), ShiftOut(4)
    short.set_inputs(0xB7)
    assert transaction(SerialBus(short, long), seq, 0x1234) == 0xB700
    assert long.outputs == 0x0000_1234


def _edge_cycles(seq: SerialSequence, word: int) -> list[Levels]:
    return [*render(seq, word), IDLE]


def test_shift_out_stores_at_the_end_of_conv_and_dac_at_its_start() -> None:
    """74HCT594: storage on /Conv rising; DAC: output on /Conv falling (SM-12)."""
    seq = sequence(DataDirection.OUT, 16, 2_000_000)
    assert seq.conv is not None
    chain, dac = ShiftOut(2), SpiDac(16)
    waves = _edge_cycles(seq, 0xBEEF)
    for levels in waves[: seq.conv[0]]:
        chain.clock(levels)
        dac.clock(levels)
    assert (chain.outputs, dac.output) == (0, 0)
    chain.clock(waves[seq.conv[0]])
    dac.clock(waves[seq.conv[0]])
    assert (chain.outputs, dac.output) == (0, 0xBEEF)
    chain.clock(waves[seq.conv[1]])
    assert chain.outputs == 0xBEEF


def test_shift_in_captures_at_ss_falling() -> None:
    """Inputs changed while /SS is low reach the next frame, not the running one (/PL = inverted /SS)."""
    seq = sequence(DataDirection.IN, 16, 2_000_000)
    chain = ShiftIn(2)
    chain.set_inputs(0xF0F0)
    waves = _edge_cycles(seq, 0)
    bits = []
    for cycle, levels in enumerate(waves):
        bits.append(chain.clock(levels))
        if cycle == 0:
            chain.set_inputs(0x0F0F)
    assert bits[0] == 1  # Q7 = input H of the stage at SerIn
    assert transaction(chain, seq, 0) == 0x0F0F


def test_clear_and_power_up() -> None:
    chain = ShiftOut(2)
    transaction(chain, sequence(DataDirection.OUT, 16, 2_000_000), 0x55AA)
    assert chain.outputs == 0x55AA
    chain.clear()
    assert chain.outputs == 0
    transaction(chain, sequence(DataDirection.IN, 16, 2_000_000), 0)
    chain.convert()
    assert chain.outputs == 0  # the shift register was cleared too
    assert SpiDac(32).output == 0 and SpiAdc(32).code == 0 and ShiftIn(4).inputs == 0


@pytest.mark.parametrize("bits", [16, 32])
def test_converter_voltages(bits: int) -> None:
    adc, dac = SpiAdc(bits), SpiDac(bits)
    full = (1 << bits) - 1
    adc.set_voltage(2.5, 5.0)
    assert adc.code == 1 << (bits - 1)
    adc.set_voltage(5.0, 5.0)
    assert adc.code == full
    adc.set_voltage(0, 10)
    assert adc.code == 0
    dac.frame(1 << (bits - 1), bits)
    dac.convert()
    assert dac.volts(5.0) == 2.5


# The bus ----------------------------------------------------------------------------------------------------------


def test_bus_fans_out_and_answers_with_its_driver() -> None:
    adc, dac, chain = SpiAdc(16), SpiDac(16), ShiftOut(1)
    bus = SerialBus(dac, adc, chain)
    assert isinstance(bus, SerialDevice) and bus.drives_ser_in and bus.devices == (dac, adc, chain)
    adc.set_input(0x8001)
    seq = sequence(DataDirection.IN_OUT, 16, 500_000)
    assert pins(bus, seq, 0x4321) == (0x8001, 1)  # /SS high again: the ADC shows its input's MSB (PR-1)
    assert (dac.output, chain.outputs) == (0x4321, 0x21)
    quiet = SerialBus(SpiDac(16), SerialBus(ShiftOut(2)))
    assert not quiet.drives_ser_in
    assert quiet.frame(0xFFFF, 16) == 0
    assert quiet.clock(Levels(0, 1, 0, 1)) == 0
    assert not SerialBus().drives_ser_in
    assert repr(bus) == "SerialBus(SpiDac(bits=16), SpiAdc(bits=16), ShiftOut(1))"


def test_bus_refuses_two_drivers_naming_both() -> None:
    with pytest.raises(SerInConflictError, match=r"not both ShiftIn\(2\) and SpiAdc\(bits=32\)") as caught:
        SerialBus(ShiftOut(1), ShiftIn(2), SpiAdc(32))
    assert caught.value.name == "devices"
    assert repr(caught.value.first) == "ShiftIn(2)" and repr(caught.value.second) == "SpiAdc(bits=32)"
    with pytest.raises(SerInConflictError, match="SerialBus"):
        SerialBus(SerialBus(ShiftIn(1)), SpiAdc(16))


@pytest.mark.parametrize("kind", KINDS, ids=lambda kind: kind.name)
def test_every_device_is_a_serial_device(kind: Kind) -> None:
    device = kind.make()
    assert isinstance(device, SerialDevice)  # the bus too
    assert device.drives_ser_in == (kind.feed is not None)


def test_the_docs_example_runs() -> None:
    text = (Path(__file__).resolve().parents[1] / "docs" / "peripherals.md").read_text(encoding="utf-8")
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.DOTALL)
    assert blocks
    for block in blocks:
        exec(compile(block, "docs/peripherals.md", "exec"), {})

"""The IBS SRE 1 role on the serial register expansion (supi3.peripherals.sre, manual 3.5, RX-8): the manual's
Figure 3-24 example at both fidelities; for every length and both bit rates the transaction level (chain,
shift_cycle, take_outputs, load_inputs, clear) equals clocking the chain with a ClkExR/ToExR waveform built from
expansion.clock_high and expansion.end_pulses; /ResReg."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.expansion import IDLE, PULSE_T0, ExpansionLevels, ExternalRegisters, clock_high, end_pulses
from supi3.peripherals import Sre1
from supi3.spi.serial_io import PERIPHERAL_DELAY_CLOCKS

CPBS = (64, 16)
"""Clocks per bit at 500 kbit/s and 2 Mbit/s."""
LEAD = 3
"""Idle cycles before the first data cycle (the chip takes FromExR for bit 0 the cycle before ToExR shows it)."""


def line_bits(data: bytes) -> list[int]:
    """The bits of ``data`` in the order they travel, each byte LSB first (Figure 3-24)."""
    return [(byte >> i) & 1 for byte in data for i in range(8)]


def data_cycle(received: bytes, cpb: int, latched: bool) -> list[ExpansionLevels]:
    """A data cycle on the pins (RX-3, RX-4): bit k on ToExR from cycle k * cpb, ClkExR high over
    clock_high(cpb) of it; then the end pulses; ToExR 0 outside the data."""
    first, end = clock_high(cpb)
    waves = [
        ExpansionLevels(clk_exr=int(first <= c < end), to_exr=bit, la_ou_d=0, la_in_d_n=1, res_reg_n=1)
        for bit in line_bits(received)
        for c in range(cpb)
    ]
    pulses = end_pulses(latched, cpb)
    for c in range(pulses.length):
        la_ou_d = int(pulses.la_ou_d is not None and pulses.la_ou_d[0] <= c < pulses.la_ou_d[1])
        la_in_d_n = int(not pulses.la_in_d_n[0] <= c < pulses.la_in_d_n[1])
        waves.append(ExpansionLevels(clk_exr=0, to_exr=0, la_ou_d=la_ou_d, la_in_d_n=la_in_d_n, res_reg_n=1))
    return waves


class PinBench:
    """An Sre1 clocked at every change of a running waveform; its answers reach FromExR
    PERIPHERAL_DELAY_CLOCKS later."""

    def __init__(self, chain: Sre1) -> None:
        self.chain = chain
        self.cycle = 0
        self.seen = IDLE
        self.answers: list[tuple[int, int]] = [(0, 0)]

    def run(self, waves: list[ExpansionLevels]) -> None:
        for levels in waves:
            if levels != self.seen:
                self.answers.append((self.cycle + PERIPHERAL_DELAY_CLOCKS, self.chain.clock(levels)))
                self.seen = levels
            self.cycle += 1

    def from_exr(self, cycle: int) -> int:
        return next(answer for when, answer in reversed(self.answers) if when <= cycle)

    def data_cycle(self, received: bytes, cpb: int, latched: bool) -> bytes:
        """Run a data cycle; the bytes sent on FromExR (the level the cycle before ToExR shows each bit, RX-3)."""
        start = self.cycle
        self.run(data_cycle(received, cpb, latched))
        bits = [self.from_exr(start + k * cpb - 1) for k in range(8 * len(received))]
        return bytes(sum(bits[8 * i + j] << j for j in range(8)) for i in range(len(received)))


def transaction(chain: Sre1, received: bytes, latched: bool) -> bytes:
    """The same data cycle at transaction level: sent, shifted, outputs taken (if latched), inputs loaded."""
    sent = chain.chain()
    chain.shift_cycle(received)
    if latched:
        chain.take_outputs()
    chain.load_inputs()
    return sent


def test_figure_3_24() -> None:
    """Received 14h, 56h, 78h: bytes 0..2 = 78h, 56h, 14h, shifted LSB first (3.5, Figure 3-24)."""
    received = bytes([0x14, 0x56, 0x78])
    tl = Sre1(3)
    tl.shift_cycle(received)
    tl.take_outputs()
    assert tl.contents() == tl.outputs == bytes([0x78, 0x56, 0x14])
    assert tl.chain() == received
    bench = PinBench(Sre1(3))
    bench.run([IDLE] * LEAD)
    bench.run(data_cycle(received, 16, True)[: 24 * 16])
    assert bench.chain.contents() == bytes([0x78, 0x56, 0x14])
    bench.run(data_cycle(received, 16, True)[24 * 16 :])
    assert bench.chain.outputs == bytes([0x78, 0x56, 0x14])


def check_both_fidelities(length: int, cpb: int, cycles: list[tuple[bytes, bytes, bool]]) -> None:
    """Data cycles (received, inputs to set before it, latched) on both fidelities: same bytes sent, same
    outputs and chain after every cycle; the chain sent what it had loaded."""
    tl, bench = Sre1(length), PinBench(Sre1(length))
    bench.run([IDLE] * LEAD)
    loaded = bytes(length)
    for received, inputs, latched in cycles:
        tl.set_inputs(inputs)
        bench.chain.set_inputs(inputs)
        sent = transaction(tl, received, latched)
        assert bench.data_cycle(received, cpb, latched) == sent == loaded[::-1]
        assert bench.chain.outputs == tl.outputs
        assert bench.chain.contents() == tl.contents() == inputs
        loaded = inputs


@pytest.mark.parametrize("cpb", CPBS)
@pytest.mark.parametrize("length", [1, 2, 3, 4, 5, 8, 16, 32, 64])
def test_every_length_agrees_at_both_fidelities(length: int, cpb: int) -> None:
    pattern = bytes((37 * i + 11) & 0xFF for i in range(length))
    inputs = bytes((91 * i + 200) & 0xFF for i in range(length))
    check_both_fidelities(length, cpb, [(pattern, inputs, True), (inputs, pattern, False), (pattern, pattern, True)])


@st.composite
def scenarios(draw: st.DrawFn) -> tuple[int, int, list[tuple[bytes, bytes, bool]]]:
    length = draw(st.integers(1, 6))
    block = st.binary(min_size=length, max_size=length)
    return length, draw(st.sampled_from(CPBS)), draw(st.lists(st.tuples(block, block, st.booleans()), max_size=3))


@settings(max_examples=30)
@given(scenarios())
def test_random_data_agrees_at_both_fidelities(scenario: tuple[int, int, list[tuple[bytes, bytes, bool]]]) -> None:
    check_both_fidelities(*scenario)


@pytest.mark.parametrize("cpb", CPBS)
def test_res_reg_clears_outputs_and_chain(cpb: int) -> None:
    """/ResReg low (4 t0, RX-5): outputs and chain 0, inputs kept; ClkExR ignored while it is low."""
    bench = PinBench(Sre1(2))
    bench.chain.set_inputs(b"\x12\x34")
    bench.run([IDLE] * LEAD)
    bench.data_cycle(b"\xab\xcd", cpb, True)
    assert bench.chain.outputs == b"\xcd\xab" and bench.chain.contents() == b"\x12\x34"
    low = ExpansionLevels(clk_exr=0, to_exr=1, la_ou_d=0, la_in_d_n=1, res_reg_n=0)
    bench.run([low, ExpansionLevels(1, 1, 0, 1, 0)] * (PULSE_T0 * cpb // 2) + [IDLE])
    assert bench.chain.outputs == bench.chain.contents() == b"\x00\x00"
    assert bench.chain.inputs == b"\x12\x34"
    assert bench.from_exr(bench.cycle) == 0
    tl = Sre1(2)
    tl.shift_cycle(b"\x01\x02")
    tl.take_outputs()
    tl.clear()
    assert tl.outputs == tl.contents() == bytes(2)


def test_is_external_registers() -> None:
    chain = Sre1(64)
    assert isinstance(chain, ExternalRegisters)
    assert chain.length == 64 and chain.chain() == chain.outputs == chain.inputs == bytes(64)
    assert repr(chain) == "Sre1(64)"

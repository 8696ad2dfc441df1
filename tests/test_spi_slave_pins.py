"""The serial µP interface at pin level: a software SPI / Intel master drives the 32 MHz model; cycle-exact output
timing, tri-state, Table 3-7 violations by name, agreement with the byte-level engine."""

from __future__ import annotations

from dataclasses import replace

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.config import DeviceConfig, decode
from supi3.model.registers import RegisterFile
from supi3.regmap import ID, SET, encode_command
from supi3.spi.slave_pins import INPUT_PINS, OUTPUT_PINS, PinsIn, PinsOut, SlavePins, TimingViolationError
from supi3.spi.upif import C_D_COMMAND, C_D_DATA, Mode, Phase, ProtocolViolationError, UpifUsageError, UpInterface
from supi3.tables import CLOCK_HZ, clk_conf_for
from support import FrameTiming, table_3_7_minimum

RATES = {"500k": 500_000, "2M": 2_000_000}  # bit rates (Table 1-7)


def config(rate: str) -> DeviceConfig:
    return decode("10011", "1110", clk_conf=clk_conf_for(RATES[rate]))


def limit(rate: str, symbol: str) -> float:
    return table_3_7_minimum(config(rate).bit_rate, symbol)


class Master:
    """A software master on the pins, within Table 3-7 unless told otherwise: SCLK idles high, the µP changes its
    data on falling edges and both sides sample on rising edges (UP-5)."""

    def __init__(self, chip: SlavePins, rate: str) -> None:
        self.chip = chip
        timing = FrameTiming.of(config(rate).bit_rate, chip.clocks_per_tclk)  # t0/t4, t1/t7, t2, UP-14 + t8
        self.half, self.lead, self.trail, self.gap = timing.half, timing.lead, timing.trail, timing.gap
        self.pins = PinsIn()
        self.seen: list[PinsOut] = []
        """Every output, cycle by cycle."""
        self.sas_window = range(0)
        """Cycles (counted in :attr:`seen`) in which SAS_INIT is forced high."""
        self.out = self.run()

    def run(self, cycles: int = 1, **changes: int) -> PinsOut:
        self.pins = replace(self.pins, **changes)
        for _ in range(cycles):
            forced = replace(self.pins, sas_init=1) if len(self.seen) in self.sas_window else self.pins
            self.out = self.chip.tick(forced)
            self.seen.append(self.out)
        return self.out

    def byte(self, mosi: int, *, s_r: bool = True, bits: int = 8, whole: bool = True) -> int | None:
        """One frame; returns the byte the chip drove (on MFP7 in Motorola, MFP6 in Intel), or None.
        ``whole``: check that the chip drove during all samples or none (not across a SAS_INIT)."""
        lsb_first = self.chip.protocol.lsb_first
        self.run(1, mfp7=int(s_r))
        self.run(self.lead, ss_n=0)
        samples: list[tuple[int, int]] = []
        for i in range(bits):
            bit = (mosi >> (i % 8 if lsb_first else 7 - i % 8)) & 1
            self.run(self.half, sclk=0, mfp6=bit if s_r else self.pins.mfp6)
            out = self.run(1, sclk=1)
            samples.append((out.mfp7, out.mfp7_oe) if out.mfp7_oe else (out.mfp6, out.mfp6_oe))
            self.run(self.half - 1)
        self.run(max(self.trail - self.half, 0))
        self.run(self.gap, ss_n=1)
        driven = {oe for _, oe in samples}
        if driven != {1}:
            assert driven <= {0} or not whole, samples
            return None
        value = 0
        for i, (bit, _) in enumerate(samples[:8]):
            value |= bit << (i if lsb_first else 7 - i)
        return value

    def sas_init(self, cycles: int = 8) -> None:
        self.run(cycles, sas_init=1)
        self.run(self.gap, sas_init=0)


def pins(rate: str = "2M", *, strict: bool = True) -> Master:
    return Master(SlavePins(RegisterFile(config(rate), strict=strict)), rate)


@pytest.mark.parametrize("rate", list(RATES))
def test_manual_initialization_example_at_pin_level(rate: str) -> None:
    """3.4.5 with an Intel master: 81h, 4Dh 82h, 4Ch 01h, LSB first on Ser_IN/OUT; then read back."""
    m = pins(rate)
    assert m.out.c_d == C_D_COMMAND
    assert m.byte(0x81) is None
    assert m.chip.protocol.mode is Mode.INTEL and m.out.c_d == C_D_COMMAND
    for command, data in ((0x4D, 0x82), (0x4C, 0x01)):
        m.byte(command)
        assert m.out.c_d == C_D_DATA
        m.byte(data)
        assert m.out.c_d == C_D_COMMAND
    assert m.chip.registers.bus_id_register() == 0x0901
    m.byte(encode_command(SET.address, rd=True))
    assert m.byte(0, s_r=False) == 0x82


def test_intel_block_transfer_example_at_pin_level() -> None:
    """3.4.6, Fig. 3-12: 8Fh, then 14h 56h 78h in three reads."""
    m = pins()
    m.byte(0x81)
    m.byte(0x4D)
    m.byte(0x84)  # 3 bytes
    m.chip.registers.latch(b"\x14\x56\x78")
    m.byte(0x8F)
    assert [m.byte(0, s_r=False) for _ in range(3)] == [0x14, 0x56, 0x78]
    assert m.out.c_d == C_D_COMMAND


@pytest.mark.parametrize("rate", list(RATES))
def test_motorola_software_master_reads_and_writes_registers(rate: str) -> None:
    m = pins(rate)
    regs = m.chip.registers
    m.byte(0x00)
    assert m.chip.protocol.mode is Mode.MOTOROLA
    for address, value in ((13, 0x85), (12, 0x03), (14, 0x10), (7, 0xA7), (0, 0x11), (3, 0x44)):
        m.byte(encode_command(address, wr=True))
        m.byte(value)
    assert regs.bus_id_register() == 0x0203 and regs.processor_alarm == 0xA7
    assert regs.value("IN0") == 0x11 and regs.value("IN3") == 0x44
    regs.latch(b"\xc1\xc2\xc3\xc4")
    regs.event("VALID")
    assert m.run(2 * m.chip.clocks_per_tclk + 2).irq_n == 0
    for address, value in ((0, 0xC1), (3, 0xC4), (13, 0x85), (12, 0x03), (14, 0x10), (6, 0)):
        assert m.byte(encode_command(address, rd=True)) is not None
        assert m.byte(0) == value
    assert m.out.irq_n == 1
    m.byte(0xCF)
    assert [m.byte(b) for b in b"\x91\x92\x93\x94"] == [0xC1, 0xC2, 0xC3, 0xC4]
    assert regs.in_bytes() == b"\x91\x92\x93\x94"
    assert regs.violations.records == []


@pytest.mark.parametrize("rate", list(RATES))
def test_output_latency_is_two_tclk_plus_one_clock(rate: str) -> None:
    """UP-14: an output changes in cycle u + 2 * c + 1 when the input edge that causes it first shows in cycle u
    (c = clocks per TCLK); the same for C/D (t6), SerOUT after /SS fall (t7) and after SCLK rise (t3, t9)."""
    m = pins(rate)
    latency = 2 * m.chip.clocks_per_tclk + 1
    m.byte(0x00)
    m.byte(encode_command(ID.address, wr=True))
    m.byte(0x96)
    m.byte(encode_command(ID.address, rd=True))
    history: list[PinsOut] = []

    def record(cycles: int = 1, **changes: int) -> None:
        for _ in range(cycles):
            history.append(m.run(1, **changes))

    record(1, ss_n=0)
    record(latency + 2)
    assert [o.mfp7_oe for o in history].index(1) == latency
    assert history[latency].mfp7 == 1  # 96h MSB first
    start = len(history)
    record(1, sclk=0)
    record(1, sclk=1)
    record(latency + 2)
    bits = [o.mfp7 for o in history[start:]]
    assert bits.index(0) == 1 + latency  # bit 1 of 96h appears 2c + 1 cycles after the rising edge
    for _ in range(7):
        record(m.half, sclk=0)
        record(m.half, sclk=1)
    start = len(history)
    record(m.trail)
    assert all(o.c_d == C_D_DATA for o in history)
    start = len(history)
    record(latency + 2, ss_n=1)
    c_d = [o.c_d for o in history[start:]]
    oe = [o.mfp7_oe for o in history[start:]]
    assert c_d.index(C_D_COMMAND) == latency == oe.index(0)
    assert m.chip.registers.violations.records == []
    tclk = limit(rate, "TCLK")
    delay_s = latency / CLOCK_HZ
    assert 2 * tclk <= delay_s <= 3 * tclk + 1e-12  # t6, t9
    assert delay_s >= limit(rate, "t3") - 10e-9  # t3 less the 10 ns pad delay of the real chip


def test_tristate_and_mfp7_input_until_the_mode_is_known() -> None:
    m = pins(strict=False)
    seen = m.seen
    m.byte(0x55, bits=8)  # faulty init byte: disabled, never driven
    m.byte(0x4D)
    assert all(o.mfp7_oe == 0 and o.mfp6_oe == 0 for o in seen)
    assert all(o.c_d_oe == o.irq_n_oe == o.io_oe == 1 for o in seen)
    m.sas_init()
    m.byte(0x00)
    seen.clear()
    m.byte(0x4C)
    assert any(o.mfp7_oe for o in seen) and not any(o.mfp6_oe for o in seen)
    m.run(5)
    assert m.out.mfp7_oe == 0  # /SS high: high impedance (3.4.1)
    m.sas_init()
    m.byte(0x81)
    seen.clear()
    m.byte(0x4C)  # S/R = 1: the µP sends, the chip does not drive
    m.byte(0x01)
    assert not any(o.mfp6_oe or o.mfp7_oe for o in seen)
    m.byte(0x8C)
    assert m.byte(0, s_r=False) == 0x01
    assert m.out.mfp6_oe == 0


def test_io_and_irq_pins_follow_the_register_file() -> None:
    m = pins()
    regs = m.chip.registers
    latency = 2 * m.chip.clocks_per_tclk + 1
    regs.set_io_access(True)
    regs.cpu_write(14, 0x08)
    regs.event("ID_CYCLE")
    outs = [m.run() for _ in range(latency + 1)]
    assert [o.io for o in outs].index(1) == [o.irq_n for o in outs].index(0) == latency - 2


@pytest.mark.parametrize(
    ("rate", "symbol", "tweak"),
    [
        ("500k", "t0", {"half": 8}),  # SCLK faster than 1.5 MHz
        ("2M", "t0", {"half": 2}),  # SCLK faster than 6 MHz (and setup t4 too short)
        ("500k", "t1", {"lead": 1}),
        ("500k", "t2", {"trail": 1}),
        ("500k", "t8", {"gap": 10}),  # /SS falls 1 clock after C/D changed (UP-14: 9 clocks after /SS rose)
    ],
)
def test_timing_violations_are_named(rate: str, symbol: str, tweak: dict[str, int]) -> None:
    lenient = pins(rate, strict=False)
    lenient.byte(0x00)
    for name, value in tweak.items():
        setattr(lenient, name, value)
    lenient.byte(0x4C)
    lenient.byte(0x4C)
    found = [v for v in lenient.chip.registers.violations.records if isinstance(v, TimingViolationError)]
    assert symbol in {v.parameter for v in found}
    v = next(v for v in found if v.parameter == symbol)
    assert v.measured_s is not None and v.measured_s < v.required_s == limit(rate, symbol)
    assert f"Table 3-7 {symbol}" in str(v)
    strict = pins(rate)
    strict.byte(0x00)
    for name, value in tweak.items():
        setattr(strict, name, value)
    with pytest.raises(TimingViolationError, match="Table 3-7 t"):
        _two_commands(strict)


def _two_commands(m: Master) -> None:
    m.byte(0x4C)
    m.byte(0x4C)


def test_setup_hold_s_r_and_sas_init_violations() -> None:
    m = pins("500k", strict=False)
    m.byte(0x81)
    m.run(m.lead, ss_n=0, mfp7=1)
    m.run(4, sclk=0)
    data = m.pins.mfp6
    m.run(1, sclk=1, mfp6=1 - data)  # data changes with the rising edge: setup 0 (t4)
    m.run(1, mfp6=data)  # and right after it: hold 31 ns (t5)
    m.run(3, mfp7=0)  # S/R changes while /SS is low (t11)
    m.run(m.gap, ss_n=1)
    m.run(4, sas_init=1)  # 125 ns < 250 ns
    m.run(m.gap, sas_init=0)
    names = [v.parameter for v in m.chip.registers.violations.records if isinstance(v, TimingViolationError)]
    assert names == ["t4", "t5", "t11", "t2", "t_SAS_INIT"]
    t11 = m.chip.registers.violations.records[2]
    assert isinstance(t11, TimingViolationError) and t11.measured_s is None
    assert m.chip.protocol.phase is Phase.INIT  # even a short pulse resets the interface (UP-16)


@pytest.mark.parametrize("bits", [0, 3, 7, 9, 16])
def test_frames_without_eight_bits_are_ignored(bits: int) -> None:
    """/SS glitches and /SS held low across two bytes (3.4.2): the frame is dropped and reported."""
    m = pins(strict=False)
    m.byte(0x00)
    m.byte(0x4D, bits=bits)
    assert m.chip.protocol.phase is Phase.COMMAND
    (v,) = m.chip.registers.violations.records
    assert isinstance(v, ProtocolViolationError)
    assert ("held low" if bits > 8 else "incomplete") in str(v)
    m.byte(0x4D)
    m.byte(0x81)
    assert m.chip.registers.value("SET") == 0x81


def test_step_by_name_and_clock_check() -> None:
    chip = SlavePins(RegisterFile(config("2M")))
    out = chip.step(dict.fromkeys(INPUT_PINS, 1) | {"sas_init": 0})
    assert list(out) == list(OUTPUT_PINS)
    assert out["c_d"] == C_D_COMMAND
    with pytest.raises(UpifUsageError, match="multiple of TCLK"):
        SlavePins(RegisterFile(config("2M")), clock_hz=30_000_000)


_BYTES = st.lists(st.tuples(st.integers(0, 255), st.booleans(), st.integers(0, 9)), min_size=1, max_size=14)


def _agree(rate: str, mode: Mode, ops: list[tuple[int, bool, int]]) -> None:
    """Run the same bytes through the byte-level and the pin-level model; compare every byte and the state."""
    byte_level = UpInterface(RegisterFile(config(rate), strict=False))
    m = pins(rate, strict=False)
    for up in (byte_level,):
        up.transfer(mode.init_byte)
    m.byte(mode.init_byte)
    for value, s_r, special in ops:
        if special == 0:
            byte_level.sas_init()
            m.sas_init()
            value = mode.init_byte
        if special == 1:
            for regs in (byte_level.registers, m.chip.registers):
                regs.set_io_access(True)
                regs.latch(bytes(regs.data_bytes())) if regs.internal_data_path else None
        sr = s_r if byte_level.protocol.mode is Mode.INTEL else True  # the µP drives the initialization byte
        assert m.byte(value, s_r=sr) == byte_level.transfer(value, s_r=sr), (value, s_r)
        assert m.out.c_d == byte_level.c_d
        assert m.out.irq_n == byte_level.registers.irq_n
        assert m.chip.protocol.phase is byte_level.protocol.phase
    for name in ("SET", "ID", "IRQ_EN", "IRQ_EVT", "ALARM", "IN0", "IN1", "IN2", "IN3"):
        assert m.chip.registers.value(name) == byte_level.registers.value(name), name
    assert [str(v) for v in m.chip.registers.violations.records] == [
        str(v) for v in byte_level.registers.violations.records
    ]


@pytest.mark.parametrize("mode", list(Mode))
@settings(max_examples=25)
@given(ops=_BYTES)
def test_pin_level_agrees_with_byte_level_2m(mode: Mode, ops: list[tuple[int, bool, int]]) -> None:
    _agree("2M", mode, ops)


@pytest.mark.parametrize("mode", list(Mode))
@settings(max_examples=4)
@given(ops=_BYTES)
def test_pin_level_agrees_with_byte_level_500k(mode: Mode, ops: list[tuple[int, bool, int]]) -> None:
    _agree("500k", mode, ops)


@settings(max_examples=15)
@given(st.integers(0, 2000), st.sampled_from(list(Mode)))
def test_sas_init_at_a_random_cycle(offset: int, mode: Mode) -> None:
    """SAS_INIT in the middle of anything: the interface waits for an initialization byte, SET and ID stay."""
    m = pins(strict=False)
    m.byte(mode.init_byte)
    m.byte(0x4D)
    m.byte(0x85)
    start = len(m.seen) + offset
    m.sas_window = range(start, start + 8)
    for value in (0x4C, 0x5A, 0x8D, 0x00, 0x8C, 0x00):
        m.byte(value, s_r=mode is Mode.MOTOROLA or value != 0x00, whole=False)
    m.sas_window = range(0)
    if start < len(m.seen):
        assert m.chip.protocol.phase in (Phase.INIT, Phase.DISABLED, Phase.COMMAND, Phase.DATA)
    m.sas_init()
    assert m.chip.protocol.phase is Phase.INIT and m.out.c_d == C_D_COMMAND
    assert m.chip.registers.value("SET") == 0x85
    m.byte(mode.init_byte)
    assert m.chip.protocol.mode is mode

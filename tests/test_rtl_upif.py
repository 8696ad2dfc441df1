"""The RTL serial µP interface (supi3.rtl.upif) against its pin model (supi3.spi.block_pins), every port every clock.

One Verilator build serves every test: the bit rate and the µP_Not_Ready code are strap ports. Stimulus is built
by :class:`support.UpifScript` (a software SPI / Intel master within Table 3-7, plus core strobes at chosen cycles)
and replayed on the batch path; one scenario also runs on the per-cycle cocotb path. Directed tests follow the
manual's examples (3.4.5, 3.4.6) and check what the µP and the core see; hypothesis (derandomized,
tests/conftest.py) mixes commands, data, SAS_INIT, power-up and INTERBUS resets, protocol abuse and core events at
random cycles.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.pinout import OPTICAL_REGISTERS
from supi3.regmap import (
    ALARM,
    BLOCK_ADDRESS,
    ID,
    IN0,
    IN1,
    INTERRUPT_SOURCES,
    IRQ_EN,
    IRQ_EVT,
    LENGTH_BRANCH,
    LENGTH_OUT,
    OUT0,
    OUT1,
    PCMD,
    POWER_IN,
    REGISTER_MAP,
    SET,
    encode_command,
)
from supi3.rtl.upif import UpifBlock, verilog
from supi3.spi.block_pins import UpifBlockPins
from supi3.spi.upif import C_D_COMMAND, Mode
from supi3.tables import BIT_RATES
from supi3.verif import Lockstep, WordLayout, model_trace
from supi3.verif.layout import CycleMatrix
from support import NOT_READY_ID, UpifScript, VerilatorBuild

SLOW, FAST = BIT_RATES
SOURCE_BIT = {s.name: s.bit for s in INTERRUPT_SOURCES}
WIDTH_MASK = {pin.name: pin.mask for pin in UpifBlockPins.inputs}


@dataclass
class Outcome:
    """The model's outputs of a script (the RTL's too: the lockstep compared them)."""

    layout: WordLayout
    trace: CycleMatrix
    script: UpifScript

    def __getitem__(self, name: str) -> npt.NDArray[np.uint64]:
        return self.trace[:, self.layout.output_names.index(name)]

    def final(self, name: str) -> int:
        return int(self[name][-1])

    def frames(self) -> Iterator[int | None]:
        """What the chip drove in each frame (MFP7 in Motorola, MFP6 in Intel), as the master sampled it."""
        for cycles in self.script.samples:
            for pin in ("mfp7", "mfp6"):
                oe = self[pin + "_oe"][cycles]
                if oe.all():
                    bits = self[pin][cycles]
                    order = range(8) if pin == "mfp6" else range(7, -1, -1)
                    yield sum(int(bit) << k for bit, k in zip(bits, order, strict=False))
                    break
            else:
                yield None


@pytest.fixture(scope="session")
def bench(verilator_build: VerilatorBuild) -> Lockstep:
    lockstep = Lockstep(UpifBlock, UpifBlockPins, build_dir=verilator_build("rtl_upif"))
    lockstep.prepare()
    return lockstep


def check(bench: Lockstep, script: UpifScript) -> Outcome:
    """Lockstep on the batch path, then the model's outputs for assertions."""
    array = script.stimulus()
    bench.run_batch(array)
    return Outcome(bench.layout, model_trace(UpifBlockPins(), bench.stimulus(array), bench.layout), script)


# Elaboration --------------------------------------------------------------------------------------------------------


def test_verilog_has_the_model_ports() -> None:
    text = verilog()
    assert "module supi3_upif" in text
    for pin in (*UpifBlockPins.inputs, *UpifBlockPins.outputs):
        assert f" {pin.name}" in text


# The manual's examples ------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("rate", BIT_RATES)
@pytest.mark.parametrize("mode", list(Mode))
def test_initialization_example(bench: Lockstep, mode: Mode, rate: int) -> None:
    # 3.4.5: initialization byte, SET = 82h (4Dh 82h), ID = 01h (4Ch 01h); the master then reads 0901h. Read back.
    script = UpifScript(rate).init(mode).write(SET, 0x82).write(ID, 0x01).read(SET).read(ID)
    outcome = check(bench, script)
    assert list(outcome.frames())[-3::2] == [0x82, 0x01]
    assert outcome.final("bus_id") == 0x0901
    assert outcome["bus_id"][0] == NOT_READY_ID
    assert outcome.final("c_d") == C_D_COMMAND


@pytest.mark.parametrize("rate", BIT_RATES)
def test_block_transfer_example_intel(bench: Lockstep, rate: int) -> None:
    # 3.4.6, Fig. 3-12: a 24-bit output device reads its OUT data with 8Fh and three bytes (14h 56h 78h).
    three_bytes = SET.encode(PCP_N=1, CL=SET.field("CL").value("LEN_3_BYTES").value)
    script = UpifScript(rate).init(Mode.INTEL).write(SET, three_bytes).write(ID, 0x01)
    script.run(20).strobe(latch=1, latch_out=int.from_bytes(bytes([0x14, 0x56, 0x78]), "little")).run(20)
    script.byte(encode_command(BLOCK_ADDRESS, rd=True))
    for _ in range(3):
        script.byte(0, s_r=0)
    outcome = check(bench, script)
    assert list(outcome.frames())[-3:] == [0x14, 0x56, 0x78]
    assert outcome.final("c_d") == C_D_COMMAND
    assert outcome.final("bus_id") == 0x0B01


@pytest.mark.parametrize("rate", BIT_RATES)
def test_block_transfer_motorola_full_duplex(bench: Lockstep, rate: int) -> None:
    # Motorola CFh: OUT k out while IN k comes in, for the configured 2 words; C/D data until the last byte.
    two_words = SET.encode(PCP_N=1, CL=SET.field("CL").value("LEN_2_WORDS").value)
    script = UpifScript(rate).init(Mode.MOTOROLA).write(SET, two_words)
    script.strobe(latch=1, latch_out=0x44332211).byte(encode_command(BLOCK_ADDRESS, rd=True, wr=True))
    for value in (0xA0, 0xB1, 0xC2, 0xD3):
        script.byte(value)
    outcome = check(bench, script)
    assert list(outcome.frames())[-4:] == [0x11, 0x22, 0x33, 0x44]
    assert outcome.final("in_data") == 0xD3C2B1A0
    assert outcome.final("c_d") == C_D_COMMAND


@pytest.mark.parametrize("mode", list(Mode))
def test_interrupts_and_core_ports(bench: Lockstep, mode: Mode) -> None:
    # Events latched only when enabled (UP-15), /IRQ low until read 14 clears them (3.4.14), D7 = I/O access; PCP
    # device erases IN0/IN1 at the latch (3.4.11); INTERBUS reset clears IN/OUT and raises its event (Table 3-13).
    enabled = IRQ_EN.mask & ~(1 << SOURCE_BIT["INVALID"])
    pcp_word = SET.encode(PCP_N=0, CL=SET.field("CL").value("LEN_1_WORD").value)
    script = UpifScript(FAST).init(mode).write(IRQ_EN, enabled).write(SET, pcp_word).write(IN0, 0x12).write(IN1, 0x34)
    script.strobe(events=(1 << SOURCE_BIT["VALID"]) | (1 << SOURCE_BIT["INVALID"]), latch=1, latch_out=0xBEEF)
    script.run(0, optical=0xFF00FF).strobe(pcmd_we=1, pcmd=0x5A)
    script.run(10, io_access=1).write(ALARM, 0x77).read(IRQ_EVT).read(PCMD).read(LENGTH_OUT).read(OUT0).read(OUT1)
    script.strobe(ib_reset=1).run(10).read(IRQ_EVT).read(OUT0)
    outcome = check(bench, script)
    frames = list(outcome.frames())
    read_bytes = frames[-13:-4:2] + frames[-3::2]
    valid_pcmd = (1 << SOURCE_BIT["VALID"]) | (1 << SOURCE_BIT["PCMD"])
    optical_8 = REGISTER_MAP.register(OPTICAL_REGISTERS[0]).mask
    assert read_bytes == [0x80 | valid_pcmd, 0x5A, optical_8, 0xEF, 0xBE, 0x80 | 1 << SOURCE_BIT["IB_RESET"], 0]
    assert outcome.final("alarm") == 0x77
    assert outcome.final("pcp") == 1 and outcome.final("in_data") == 0
    assert outcome.final("irq_n") == 1 and outcome["irq_n"].min() == 0


def test_optical_reads_are_live(bench: Lockstep) -> None:
    # UP-39: reads 8..11 are the optical block's ``optical`` port at the read's /SS falling edge (reserved bits of
    # read 10 dropped), not stored: a power-up reset does not clear them, a change shows at the next read.
    first, second = 0xF1E2D3C4, 0x8B7A6958
    script = UpifScript(FAST).run(0, optical=first).init(Mode.INTEL)
    for register in OPTICAL_REGISTERS:
        script.read(REGISTER_MAP.register(register))
    script.strobe(power_up=1).run(20).init(Mode.INTEL).read(LENGTH_BRANCH)
    script.run(0, optical=second).read(POWER_IN).read(LENGTH_OUT)
    outcome = check(bench, script)
    masks = [REGISTER_MAP.register(register).mask for register in OPTICAL_REGISTERS]
    shown = [[value >> 8 * k & mask for k, mask in enumerate(masks)] for value in (first, second)]
    driven = [frame for frame in outcome.frames() if frame is not None]  # Intel: only the reads' data bytes
    assert driven == [*shown[0], shown[0][1], shown[1][2], shown[1][0]]


def test_power_up_pulse_inside_a_driven_frame(bench: Lockstep) -> None:
    # The output pipeline (UP-14, 6 stages at 500 kbit/s) has no reset in the RTL: after a one-clock power-up pulse in
    # the middle of a driven frame the outputs show their power-up levels from the next cycle on (C/D = command, MFP7
    # undriven), not what the stages held.
    script = UpifScript(SLOW).init(Mode.MOTOROLA).write(ID, 0x5A)
    start = script.cycles
    script.read(ID)
    pulse = start + (script.cycles - start) * 3 // 4  # inside the data byte's frame
    script.strobes.append((pulse, {"power_up": 1}))
    outcome = check(bench, script.run(40))
    assert outcome["mfp7_oe"][pulse] == 1 and outcome["c_d"][pulse] != C_D_COMMAND
    assert not outcome["mfp7_oe"][pulse + 1 :].any() and (outcome["c_d"][pulse + 1 :] == C_D_COMMAND).all()


def test_straps_and_power_up(bench: Lockstep) -> None:
    # The µP_Not_Ready code comes from the straps until SET is written; power-up clears everything, SAS_INIT keeps
    # SET and ID (3.4.3).
    script = UpifScript(SLOW).run(4, np_id=0x78, np_length=0).init(Mode.MOTOROLA).write(SET, 0x82).write(ID, 0x42)
    script.sas_init().init(Mode.MOTOROLA).read(ID).strobe(power_up=1).run(30)
    outcome = check(bench, script)
    assert list(outcome.frames())[-1] == 0x42
    assert outcome["bus_id"][0] == 0x78 and outcome.final("bus_id") == 0x78
    assert 0x0942 in outcome["bus_id"]


# Random sequences ---------------------------------------------------------------------------------------------------

CL_VALUES = [v.value for v in SET.field("CL").values]
op = st.one_of(
    st.tuples(st.just("write"), st.integers(0, 15), st.integers(0, 255)),
    st.tuples(st.just("write"), st.just(SET.address), st.sampled_from([SET.encode(PCP_N=p, CL=c) for p in (0, 1)
                                                                       for c in CL_VALUES])),
    st.tuples(st.just("read"), st.integers(0, 15), st.just(0)),
    st.tuples(st.just("block"), st.integers(0, 3), st.integers(0, 255)),
    st.tuples(st.just("raw"), st.integers(0, 255), st.integers(0, 1)),
    st.tuples(st.just("glitch"), st.integers(0, 10), st.integers(1, 30)),
    st.tuples(st.just("sas"), st.integers(1, 12), st.just(0)),
    st.tuples(st.just("init"), st.sampled_from([m.init_byte for m in Mode] + [0x18]), st.just(0)),
    st.tuples(st.just("idle"), st.integers(1, 200), st.just(0)),
)
core = st.tuples(
    st.floats(0, 1),
    st.sampled_from(["events", "latch", "pcmd", "optical", "ib_reset", "io_access", "power_up"]),
    st.integers(0, 2**32 - 1),
)


def random_script(mode: Mode, rate: int, ops: list[tuple[str, int, int]],
                  strobes: list[tuple[float, str, int]]) -> UpifScript:
    script = UpifScript(rate).init(mode).write(IRQ_EN, IRQ_EN.mask)
    for kind, a, b in ops:
        if kind == "write":
            script.write(a, b)
        elif kind == "read":
            script.read(a)
        elif kind == "block":
            script.byte(encode_command(BLOCK_ADDRESS, rd=bool(a & 1), wr=bool(a & 2)))
            for k in range(4):
                script.byte((b + k) & 0xFF, s_r=int(mode is Mode.MOTOROLA or k >= 2))
        elif kind == "raw":
            script.byte(a, s_r=b)
        elif kind == "glitch":
            script.byte(0xFF, bits=a).run(b)  # /SS pulses with 0..10 SCLK edges (3.4.2)
        elif kind == "sas":
            script.sas_init(a).init(mode)
        elif kind == "init":
            script.byte(a)
        else:
            script.run(a)
    for at, what, value in strobes:
        cycle = int(at * (script.cycles - 1))
        pins = {
            "events": {"events": value},
            "latch": {"latch": 1, "latch_out": value},
            "pcmd": {"pcmd_we": 1, "pcmd": value & 0xFF},
            "ib_reset": {"ib_reset": 1},
            "io_access": {"io_access": 1},
            "power_up": {"power_up": 1},
            "optical": {"optical": value},  # a level from this cycle on (UP-39)
        }[what]
        changes = script.levels if what == "optical" else script.strobes
        changes.append((cycle, {name: value & WIDTH_MASK[name] for name, value in pins.items()}))
    return script


@settings(max_examples=30)
@given(rate=st.sampled_from(BIT_RATES), ops=st.lists(op, min_size=8, max_size=40),
       strobes=st.lists(core, min_size=4, max_size=40))
def test_random_motorola(bench: Lockstep, rate: int, ops: list[tuple[str, int, int]],
                         strobes: list[tuple[float, str, int]]) -> None:
    bench.run_batch(random_script(Mode.MOTOROLA, rate, ops, strobes).stimulus())


@settings(max_examples=30)
@given(rate=st.sampled_from(BIT_RATES), ops=st.lists(op, min_size=8, max_size=40),
       strobes=st.lists(core, min_size=4, max_size=40))
def test_random_intel(bench: Lockstep, rate: int, ops: list[tuple[str, int, int]],
                      strobes: list[tuple[float, str, int]]) -> None:
    bench.run_batch(random_script(Mode.INTEL, rate, ops, strobes).stimulus())


@pytest.mark.parametrize("rate", BIT_RATES)
@pytest.mark.parametrize("mode", list(Mode))
def test_long_random_sequence(bench: Lockstep, mode: Mode, rate: int) -> None:
    # Long runs on the batch path (about 73,000 cycles at 2 Mbit/s, 185,000 at 500 kbit/s): 500 random operations
    # and 400 core strobes.
    rng = np.random.default_rng([BIT_RATES.index(rate), list(Mode).index(mode)])
    kinds = ["write", "write", "read", "read", "block", "raw", "glitch", "sas", "idle"]
    ops = []
    for kind in rng.choice(kinds, 500):
        a, b = (int(x) for x in rng.integers(0, 256, 2))
        ops.append({"write": ("write", a & 15, b), "read": ("read", a & 15, 0), "block": ("block", a & 3, b),
                    "raw": ("raw", a, b & 1), "glitch": ("glitch", a % 11, b % 30 + 1), "sas": ("sas", a % 12 + 1, 0),
                    "idle": ("idle", a + 1, 0)}[str(kind)])
    ops[::25] = [("write", SET.address, SET.encode(PCP_N=int(p), CL=int(c))) for p, c in
                 zip(rng.integers(0, 2, 20), rng.choice(CL_VALUES, 20), strict=True)]
    whats = ["events", "latch", "pcmd", "optical", "ib_reset", "io_access", "power_up"]
    strobes = [(float(at), str(what), int(value)) for at, what, value in
               zip(rng.random(400), rng.choice(whats, 400, p=[0.3, 0.25, 0.1, 0.1, 0.1, 0.14, 0.01]),
                   rng.integers(0, 2**32, 400), strict=True)]
    result = bench.run_batch(random_script(mode, rate, ops, strobes).stimulus())
    assert result.cycles > 70_000


def test_ss_glitches_and_noise(bench: Lockstep) -> None:
    # /SS and SCLK pulses shorter than a synchroniser sees, random MFP6/MFP7 noise, SAS_INIT pulses of 1..3 clocks.
    rng = np.random.default_rng(7)
    script = UpifScript(FAST).init(Mode.MOTOROLA).write(IRQ_EN, 0x7F)
    for _ in range(300):
        script.run(int(rng.integers(1, 4)), ss_n=int(rng.integers(0, 2)), sclk=int(rng.integers(0, 2)),
                   mfp6_in=int(rng.integers(0, 2)), mfp7_in=int(rng.integers(0, 2)),
                   sas_init=int(rng.random() < 0.02))
    script.run(20, ss_n=1, sclk=1, sas_init=0).init(Mode.INTEL).read(IRQ_EVT)
    check(bench, script)


# Other paths ----------------------------------------------------------------------------------------------------------


def test_per_cycle_path(bench: Lockstep) -> None:
    script = UpifScript(FAST).init(Mode.INTEL).write(SET, 0x82).strobe(latch=1, latch_out=0x99).read(OUT0).read(SET)
    result = bench.run(script.stimulus())
    assert result.cycles == script.cycles

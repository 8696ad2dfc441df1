"""Serial register expansion at pin level (supi3.model.blocks.expansion in supi3.model.pins.Supi3Pins, manual 3.5,
Tables 3-14, 3-15, Figures 3-23, 3-24; docs/assumptions/expansion.md): the pins' schedule, the external chain
clocked by them, and the same results as the transaction level (tests/test_model_expansion.py)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from supi3 import tables
from supi3.config import MfpKind, decode
from supi3.errors import ArgumentError
from supi3.expansion import LAIND_AFTER_LAOUD_T0, PULSE_T0, chain_to_line, clock_high, line_to_chain
from supi3.interbus import wire
from supi3.interbus.master import Master
from supi3.interbus.ring import ErrorKind, Ring
from supi3.interbus.wire import Cycle, Frame
from supi3.model.blocks.expansion import OUTPUT_NAMES
from supi3.model.chip import Supi3
from supi3.model.pinring import PinRing
from supi3.model.pins import RESET_STRETCH_CLOCKS, Supi3Pins
from supi3.peripherals.sre import Sre1
from supi3.pinout import CORE_IDLE
from supi3.regmap import ID, IN0, SET, encode_command
from supi3.spi.master import SoftMaster
from supi3.spi.upif import Mode
from supi3.top import UP_REST, ChipPort, Supi3Chip
from supi3.verif.timing import check_expansion
from support import FakeChain, assert_run_matches_step, pulses
from test_model_expansion import extreg_set, up_chip

GAP_BITS = 10
"""Idle bits between cycles at both fidelities: two status telegrams, more than the 7.75 of RX-4."""
IDLE_LEVELS = {"clk_exr": 0, "to_exr": 0, "la_ou_d": 0, "la_in_d_n": 1}


def up_pins(length: int | None, bit_rate: int = 500_000) -> Supi3Pins:
    """A pin-level Init-µP chip whose SET was written directly on the register file before the bus starts."""
    config = decode("10011", "1110", clk_conf=tables.clk_conf_for(bit_rate))
    pins = Supi3Pins(config)
    registers = pins.chip.registers
    assert registers is not None
    registers.cpu_write(SET.address, 0x82 if length is None else extreg_set(length))
    registers.cpu_write(ID.address, 0x01)
    return pins


def pin_master(pins: Supi3Pins, record: bool = False) -> tuple[PinRing, Master]:
    ring = PinRing([pins], record=record)
    ring.idle(2 * RESET_STRETCH_CLOCKS / tables.CLOCK_HZ)
    master = Master(ring, locate=False, max_devices=4)
    assert master.start().ok
    return ring, master


def exchange(ring: Ring | PinRing, master: Master, out: bytes) -> bytes:
    """One data cycle after a gap, and a gap after it (the end pulses reach the chain); the IN data received."""
    ring.idle(GAP_BITS / ring.bit_rate)
    master.set_outputs(1, out)
    assert master.data_cycle().ok
    ring.idle(GAP_BITS / ring.bit_rate)
    return master.inputs(1)


def test_manual_example_figure_3_24_at_pin_level() -> None:
    pins = up_pins(3)
    chain = FakeChain(3, inputs=bytes([0xA1, 0xB2, 0xC3]))
    pins.chip.attach_expansion(chain)
    ring, master = pin_master(pins)
    assert exchange(ring, master, bytes([0x14, 0x56, 0x78])) == bytes([0xC3, 0xB2, 0xA1])
    assert chain.outputs == bytes([0x78, 0x56, 0x14])
    assert pins.chip.events["VALID"] == 1 and pins.chip.events["EXPANSION_OVERRUN"] == 0


def test_manual_example_through_the_whole_chip_and_its_firmware() -> None:
    """Supi3Chip with a soft µP writing SET = ExtReg, 3 bytes over the serial interface (3.4.5, 3.4.11)."""
    chip = Supi3Chip(decode("10011", "1110", clk_conf="11"))
    up = SoftMaster(ChipPort(chip, mfp_in=UP_REST), Mode.MOTOROLA, record=False)
    up.run(2 * RESET_STRETCH_CLOCKS)
    up.byte(Mode.MOTOROLA.init_byte)
    for register, value in ((SET, extreg_set(3)), (ID, 0x01)):
        up.byte(encode_command(register.address, wr=True))
        up.byte(value)
        up.deselect()
    chain = FakeChain(3, inputs=b"\x01\x02\x03")
    chip.chip.attach_expansion(chain)
    ring = PinRing([chip])
    ring.set_input(1, "mfp_in", UP_REST)
    master = Master(ring, locate=False, max_devices=4)
    assert master.start().ok
    assert master.entry(1).data_bytes == 3
    assert exchange(ring, master, bytes([0x14, 0x56, 0x78])) == b"\x03\x02\x01"
    assert chain.outputs == bytes([0x78, 0x56, 0x14])


@pytest.mark.parametrize("bit_rate", tables.BIT_RATES)
@pytest.mark.parametrize("length", [1, 3, 4, 6, 16, 64])
def test_every_length_at_pin_level(length: int, bit_rate: int) -> None:
    pins = up_pins(length, bit_rate)
    chain = FakeChain(length)
    pins.chip.attach_expansion(chain)
    ring, master = pin_master(pins)
    for k in range(2):
        out = bytes((17 * k + 5 * i + length) & 0xFF for i in range(length))
        chain.inputs = bytes((31 * k + 7 * i + 1) & 0xFF for i in range(length))
        sent = chain_to_line(chain.contents)
        assert exchange(ring, master, out) == sent
        assert chain.outputs == line_to_chain(out) and chain.contents == chain.inputs
    assert pins.chip.events["VALID"] == 2 and pins.chip.events["EXPANSION_OVERRUN"] == 0


@pytest.mark.parametrize("bit_rate", tables.BIT_RATES)
def test_pins_follow_table_3_15(bit_rate: int) -> None:
    """ClkExR high half a bit per data bit of the frame, ToExR valid 0.25 t0 before each rise and 0.75 t0 after;
    LaOuD 4 t0 high after the latch, /LaInD 4 t0 low 5 t0 after LaOuD fell; /ResReg 4 t0 on the INTERBUS reset."""
    length = 3
    cpb = wire.clocks_per_bit(bit_rate)
    pins = up_pins(length, bit_rate)
    pins.chip.attach_expansion(FakeChain(length))
    ring, master = pin_master(pins, record=True)
    exchange(ring, master, b"\x14\x56\x78")
    ring.idle(2 * GAP_BITS / ring.bit_rate)  # the end pulses last 13 t0 after the latch
    rec = ring.recorded()[0]
    (reset_at, reset_width), = pulses(rec["res_reg_n"])  # start()'s INTERBUS reset, 4 t0 (RX-5)
    assert reset_width == PULSE_T0 * cpb
    clk = rec["clk_exr"]
    # The data cycle after start() (master.start() may begin a frame before its INTERBUS reset)
    rises = np.flatnonzero(np.diff(clk) == 1) + 1
    falls = np.flatnonzero(np.diff(clk) == -1) + 1
    rises, falls = rises[rises > reset_at], falls[falls > reset_at]
    assert len(rises) == 8 * (wire.LOOPBACK_BYTES + length) == len(falls)
    assert set((falls - rises).tolist()) == {clock_high(cpb)[1] - clock_high(cpb)[0]}
    to = rec["to_exr"]
    for rise in rises.tolist():
        assert len(set(to[rise - cpb // 4 : rise + 3 * cpb // 4].tolist())) == 1
    # The bits on ToExR at the rises are the frame's data bits as the chip received them: loopback word, then OUT.
    bits = to[rises]
    received = np.packbits(bits.astype(np.uint8).reshape(-1, 8), axis=1, bitorder="little").ravel().tobytes()
    assert received == wire.LOOPBACK_BYTES_ON_LINE + b"\x14\x56\x78"
    high = [(start, width) for start, width in pulses(1 - rec["la_ou_d"]) if start > reset_at]
    low = [(start, width) for start, width in pulses(rec["la_in_d_n"]) if start > reset_at]
    assert [width for _, width in high] == [PULSE_T0 * cpb]
    (ou_start, _), = high
    assert (ou_start + (PULSE_T0 + LAIND_AFTER_LAOUD_T0) * cpb, PULSE_T0 * cpb) in low
    assert all(width == PULSE_T0 * cpb for _, width in low)


def test_without_extreg_the_pins_stay_idle() -> None:
    """RX-6, RX-7: with ExtReg = 0 FromExR is ignored and the expansion outputs never move."""
    pins = up_pins(None)
    chain = FakeChain(1, inputs=b"\xff")
    pins.chip.attach_expansion(chain)
    ring, master = pin_master(pins, record=True)
    ring.set_input(1, "from_exr", 1)
    assert pins.chip.registers is not None
    pins.chip.registers.cpu_write(0, 0x5A)  # IN0: the internal register is in the data path
    assert exchange(ring, master, b"\x99") == b"\x5a"
    rec = ring.recorded()[0]
    for name, level in IDLE_LEVELS.items():
        assert set(rec[name].tolist()) == {level}, name
    assert set(rec["res_reg_n"].tolist()) == {1}
    assert chain.calls == []


def test_nothing_on_from_exr_breaks_the_ring_at_both_fidelities() -> None:
    """RX-2, RX-11, RX-13: with ExtReg = 1 and FromExR held (grounded or high) every data bit the chip sends is that
    level, the loopback word included: the master sees a loopback error, at transaction level (FromExR grounded) as
    at pin level. With FromExR wired to ToExR (the chain of the data length) it works
    (test_every_length_at_pin_level)."""
    seen = []
    for level in (0, 1):
        pins = up_pins(1)
        ring, master = pin_master(pins)
        ring.set_input(1, "from_exr", level)
        seen.append(_failing_cycles(ring, master))
    chip = up_chip(1)
    ring_tl = Ring([chip])
    seen.append(_failing_cycles(ring_tl, Master(ring_tl, locate=False, max_devices=4)))
    assert seen[0] == seen[1] == seen[2]


def _failing_cycles(ring: Ring | PinRing, master: Master) -> list[object]:
    """Two data cycles after the master's start (the table kept: the diagnostic ID cycle finds the ring whole), each
    a loopback error; the IN data the master keeps."""
    if isinstance(ring, Ring):
        assert master.start().ok
    seen: list[object] = []
    for _ in range(2):
        ring.idle(GAP_BITS / ring.bit_rate)
        result = master.data_cycle()
        assert not result.ok and result.diagnostics[0].kind is ErrorKind.LOOPBACK
        seen.append(([(d.kind, d.location, d.detail) for d in result.diagnostics], master.inputs(1)))
    return seen


UP_STRAPS = ("10011", "1110")
"""The Init-µP mode of :func:`up_pins` and :func:`~test_model_expansion.up_chip` (RB, Table 2-4)."""
BINARY = next(decode(r.c, r.mfp) for r in tables.MODE_ROWS if decode(r.c, r.mfp).mfp_mode.kind is MfpKind.BINARY_IO)


def _running_ring(pin_level: bool, locate: bool) -> tuple[Ring | PinRing, Master, Supi3, list[Supi3]]:
    """A binary-I/O chip, a µP-mode chip (SET 82h: one internal byte; not strict, so that SET may be written while
    the bus runs, UP-20) and a binary-I/O chip, its master started: the ring, the master, the µP chip and all three
    chips."""
    config = decode(*UP_STRAPS, clk_conf=tables.clk_conf_for(500_000))
    ring: Ring | PinRing
    if pin_level:
        devices = [Supi3Pins(BINARY), Supi3Pins(config, Supi3(config, strict=False)), Supi3Pins(BINARY)]
        chips = [device.chip for device in devices]
        ring = PinRing(devices)
        ring.idle(2 * RESET_STRETCH_CLOCKS / tables.CLOCK_HZ)
    else:
        chips = [Supi3(BINARY), Supi3(config, strict=False), Supi3(BINARY)]
        ring = Ring(chips)
    registers = chips[1].registers
    assert registers is not None
    registers.cpu_write(SET.address, 0x82)
    registers.cpu_write(ID.address, 0x01)
    master = Master(ring, locate=locate, max_devices=4)
    assert master.start().ok
    ring.idle(GAP_BITS / ring.bit_rate)  # the pin level's chips take the ID cycle's end as the line goes idle
    registers.cpu_write(IN0.address, 0xA5)  # after the start: its reset clears the IN data (3.4.7)
    return ring, master, chips[1], chips


_Seen = tuple[Cycle, bool, list[tuple[ErrorKind, int | None, str]], list[bytes] | None, bytes, bytes, int]
"""A master cycle's kind, verdict and diagnostics, the master's IN data, and the OUT data each chip latched."""


def _master_cycle(ring: Ring | PinRing, master: Master, chips: list[Supi3], out: int) -> _Seen:
    """OUT data ``out`` to every device the table holds, a gap, the master's next cycle, a gap: what the master and
    the chips show afterwards (each chip's latched OUT data, the µP chip's OUT0)."""
    if master.config is not None:
        for entry in master.config:
            master.set_outputs(entry.ring_position, bytes([out]) * entry.data_bytes)
    ring.idle(GAP_BITS / ring.bit_rate)
    result = master.cycle()
    ring.idle(GAP_BITS / ring.bit_rate)  # the pin level's chips take the latch telegrams as the line goes idle
    registers = chips[1].registers
    assert registers is not None
    inputs = None if master.config is None else [master.inputs(e.ring_position) for e in master.config]
    return (result.cycle, result.ok, [(d.kind, d.location, d.detail) for d in result.diagnostics], inputs,
            chips[0]._out, chips[2]._out, registers.value("OUT0"))  # fmt: skip


@pytest.mark.parametrize("locate", [True, False])
def test_extreg_written_while_the_bus_runs_fails_alike_at_both_fidelities(locate: bool) -> None:
    """RX-13: SET with ExtReg = 1 (one byte, as before) written while the bus runs, nothing on FromExR: every data
    cycle fails with a loopback error at both fidelities, the master's IN data and every chip's latched OUT data
    unchanged ("a corrupted or invalid INTERBUS cycle never changes latched data or outputs"), not located at both
    (the diagnostic ID cycle passes: ID cycles do not go through the expansion); with ExtReg cleared the cycles pass
    again."""
    seen = []
    for pin_level, record in ((False, False), (False, True), (True, False)):  # record: every line checked (slow path)
        ring, master, chip, chips = _running_ring(pin_level, locate)
        ring.record = record
        registers = chip.registers
        assert registers is not None
        history = [_master_cycle(ring, master, chips, 0x11)]
        registers.cpu_write(SET.address, extreg_set(1))
        history += [_master_cycle(ring, master, chips, 0x22) for _ in range(4)]
        registers.cpu_write(SET.address, 0x82)
        history += [_master_cycle(ring, master, chips, 0x33) for _ in range(2)]
        seen.append(history)
    assert seen[0] == seen[1] == seen[2]
    valid: _Seen = (Cycle.DATA, True, [], [b"\x00", b"\xa5", b"\x00"], b"\x11", b"\x11", 0x11)
    assert seen[0][0] == valid
    failed = 0
    for cycle, ok, diagnostics, *shown in seen[0][1:5]:  # without location an ID cycle after each failure (A21)
        assert shown == [*valid[3:]] and ok is (cycle is Cycle.ID)
        if cycle is Cycle.DATA:
            [(kind, location, _)] = diagnostics
            assert kind is ErrorKind.LOOPBACK and location is None
            failed += 1
    assert failed == (4 if locate else 2)
    assert seen[0][5:] == [(Cycle.DATA, True, [], valid[3], b"\x33", b"\x33", 0x33)] * 2


EXTREG_OPS = st.lists(st.one_of(
    st.tuples(st.sampled_from(["ext", "chain"]), st.integers(0, 1)),
    st.tuples(st.just("cycle"), st.integers(0, 255)),
    st.tuples(st.just("reset"), st.just(0)),
), min_size=1, max_size=8)  # fmt: skip


@settings(max_examples=8, deadline=None)
@given(EXTREG_OPS)
@example([("ext", 1), ("cycle", 0x5A), ("chain", 1), ("cycle", 0x3C), ("chain", 0), ("reset", 0), ("cycle", 0x11),
          ("ext", 0), ("cycle", 0x22)])
def test_the_master_sees_the_same_at_both_fidelities_as_extreg_and_from_exr_change(ops: list[tuple[str, int]]) -> None:
    """RX-13 over histories: SET with ExtReg = 1 (one byte) written or cleared while the bus runs, a chain of that
    length attached to FromExR or taken off (nothing on FromExR: grounded), master cycles (OUT data and the chain's
    inputs of the step) and Alarm Stops: after every master cycle its kind, verdict, diagnostics and IN data and the
    chips' latched OUT data are the same at both fidelities. (The chain's registers are not compared: the pin level
    clocks the chain lazily, up to where the chip needs its answer, RX-10.)"""
    seen = []
    for pin_level in (False, True):
        ring, master, chip, chips = _running_ring(pin_level, locate=True)
        registers = chip.registers
        assert registers is not None
        chain = FakeChain(1)
        history: list[_Seen] = []
        for kind, value in ops:
            if kind == "ext":
                registers.cpu_write(SET.address, extreg_set(1) if value else 0x82)
            elif kind == "chain":
                chip.attach_expansion(chain if value else None)
            elif kind == "reset":
                master.alarm_stop()
                ring.idle(GAP_BITS / ring.bit_rate)
            else:
                chain.inputs = bytes([value ^ 0xFF])
                history.append(_master_cycle(ring, master, chips, value))
        seen.append(history)
    assert seen[0] == seen[1]


@pytest.mark.parametrize("bit_rate", tables.BIT_RATES)
def test_overrun_at_pin_level_as_at_transaction_level(bit_rate: int) -> None:
    """RX-4: back to back and after one status telegram (5 bits) the first ClkExR rise comes before the end pulses
    are over; after two (10 bits) it does not. Both fidelities count the same. (A cycle whose latch is missed ends
    with /LaInD only: the next one cannot overrun.)"""
    counts = []
    for make in (lambda: up_chip(1, bit_rate), lambda: up_pins(1, bit_rate)):
        device = make()
        chip = device.chip if isinstance(device, Supi3Pins) else device
        chip.attach_expansion(FakeChain(1))
        ring: Ring | PinRing
        ring, master = (pin_master(device) if isinstance(device, Supi3Pins)
                        else (lambda r: (r, Master(r)))(Ring([device])))  # fmt: skip
        if isinstance(device, Supi3):
            assert master.start().ok
        seen = []
        for gap in (0, 0, 5, 10, 0):
            if gap:
                ring.idle(gap / bit_rate)
            # At pin level an overrun's /LaInD reloads the chain while it shifts: the data (the loopback word too)
            # are lost and the master sees an error; the transaction level only counts (RX-4).
            master.data_cycle()
            seen.append(chip.events["EXPANSION_OVERRUN"])
        counts.append(seen)
    assert counts[0] == counts[1] == [0, 1, 2, 2, 3]


def test_hostile_from_exr_levels_are_named() -> None:
    pins = up_pins(1)
    row = {"do1": 1, "di2": 0, "rbst_ext": 0, "mfp_in": 0, "stat_err_n": 1, "resu_n": 1, "vmon_ok": 1, "from_exr": 2}
    with pytest.raises(ArgumentError, match="pin 'from_exr' must be an integer from 0 to 1"):
        pins.step(row)
    traces = {name: np.full(8, value, dtype=np.int64) for name, value in row.items()}
    with pytest.raises(ArgumentError, match=r"pin 'from_exr' trace\[0\] must be an integer from 0 to 1"):
        pins.run(traces)
    assert pins.cycle == 0
    ring = PinRing([pins])
    with pytest.raises(ArgumentError, match="pin 'from_exr' must be an integer from 0 to 1"):
        ring.set_input(1, "from_exr", -1)


# ------------------------------------------------------------------------------------------------------------
# step() and run() agree; pin level and transaction level agree
# ------------------------------------------------------------------------------------------------------------


def _traffic(length: int, outs: list[bytes], gap_bits: int) -> np.ndarray:
    lw = wire.LOOPBACK_BYTES_ON_LINE
    idle = wire.status_levels(Cycle.DATA, False, 4)
    gap = wire.status_levels(Cycle.DATA, False, -(-gap_bits // wire.STATUS_TELEGRAM_BITS))
    parts = [idle, idle, idle, wire.reset_levels(1), idle,
             wire.cycle_levels(Frame.build(Cycle.ID, lw + wire.word_bytes(wire.command_word())), 1, True)]
    for k, out in enumerate(outs):
        parts += [gap, wire.cycle_levels(Frame.build(Cycle.DATA, lw + out[:length]), 1, k % 3 != 2)]
    return np.concatenate([*parts, gap, gap, gap])


@settings(max_examples=4, deadline=None)
@given(outs=st.lists(st.binary(min_size=3, max_size=3), min_size=2, max_size=4), seed=st.integers(0, 2**16),
       chained=st.booleans(), gap_bits=st.sampled_from([0, 5, 10]), cuts=st.lists(st.floats(0, 1), max_size=4))
def test_step_and_run_agree_with_expansion(outs: list[bytes], seed: int, chained: bool, gap_bits: int,
                                           cuts: list[float]) -> None:
    length = 3
    stepped, bulk = up_pins(length, 2_000_000), up_pins(length, 2_000_000)
    rng = np.random.default_rng(seed)
    chains = [FakeChain(length, inputs=bytes(rng.integers(0, 256, length).tolist())) for _ in range(2)]
    chains[1].inputs = chains[0].inputs
    if chained:
        stepped.chip.attach_expansion(chains[0])
        bulk.chip.attach_expansion(chains[1])
    do1 = wire.levels_to_samples(_traffic(length, outs, gap_bits), 2_000_000).astype(np.int64)
    n = len(do1)
    idle = zip(Supi3Pins.inputs, CORE_IDLE, strict=True)
    inputs = {pin.name: np.full(n, level, dtype=np.int64) for pin, level in idle}
    inputs["do1"] = do1
    inputs["from_exr"] = np.repeat(rng.integers(0, 2, n // 7 + 1), 7)[:n]
    expected = assert_run_matches_step(stepped, bulk, inputs, cuts)
    assert set(OUTPUT_NAMES) <= set(expected)
    assert stepped.chip.events == bulk.chip.events
    assert (chains[0].contents, chains[0].outputs) == (chains[1].contents, chains[1].outputs)
    assert stepped.chip.events["VALID"] >= 1


@settings(max_examples=6, deadline=None)
@given(length=st.sampled_from([1, 3, 4, 6, 16]), bit_rate=st.sampled_from(tables.BIT_RATES), data=st.data())
def test_pin_level_and_transaction_level_agree(length: int, bit_rate: int, data: st.DataObject) -> None:
    """Random OUT data and chain inputs over several cycles: the master reads the same IN data and the chain ends
    with the same registers at both fidelities."""
    cycles = data.draw(st.integers(2, 4))
    outs = [data.draw(st.binary(min_size=length, max_size=length)) for _ in range(cycles)]
    ins = [data.draw(st.binary(min_size=length, max_size=length)) for _ in range(cycles)]
    results = []
    for pin_level in (False, True):
        chain = FakeChain(length)
        if pin_level:
            pins = up_pins(length, bit_rate)
            pins.chip.attach_expansion(chain)
            ring: Ring | PinRing
            ring, master = pin_master(pins)
        else:
            chip = up_chip(length, bit_rate)
            chip.attach_expansion(chain)
            ring = Ring([chip])
            master = Master(ring)
            assert master.start().ok
        seen = []
        for out, inputs in zip(outs, ins, strict=True):
            chain.inputs = inputs
            seen.append((exchange(ring, master, out), chain.outputs, chain.contents))
        results.append(seen)
    assert results[0] == results[1]



# ------------------------------------------------------------------------------------------------------------
# With the IBS SRE 1 model (supi3.peripherals.sre) and the Table 3-15 checker (supi3.verif.timing)
# ------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("bit_rate", tables.BIT_RATES)
def test_sre1_at_both_fidelities_figure_3_24(bit_rate: int) -> None:
    results = []
    for pin_level in (False, True):
        sre = Sre1(3)
        sre.set_inputs(b"\x01\x02\x03")
        ring: Ring | PinRing
        if pin_level:
            pins = up_pins(3, bit_rate)
            pins.chip.attach_expansion(sre)
            ring, master = pin_master(pins)
        else:
            chip = up_chip(3, bit_rate)
            chip.attach_expansion(sre)
            ring = Ring([chip])
            master = Master(ring)
            assert master.start().ok
        seen = [exchange(ring, master, bytes([0x14, 0x56, 0x78])), sre.outputs]
        seen.append(exchange(ring, master, bytes([0x9A, 0xBC, 0xDE])))
        results.append((*seen, sre.outputs, sre.contents()))
    assert results[0] == results[1]
    assert results[0][:2] == (b"\x03\x02\x01", bytes([0x78, 0x56, 0x14]))


@pytest.mark.parametrize("bit_rate", tables.BIT_RATES)
def test_model_pins_meet_table_3_15(bit_rate: int) -> None:
    """The pin-level model's expansion traces (INTERBUS reset, ID cycle, data cycles, a watchdog-free run) pass
    the Table 3-15 checker with no violation."""
    pins = up_pins(6, bit_rate)
    pins.chip.attach_expansion(Sre1(6))
    ring, master = pin_master(pins, record=True)
    for k in range(2):
        exchange(ring, master, bytes(range(k, k + 6)))
    ring.idle(2 * GAP_BITS / ring.bit_rate)
    rec = ring.recorded()[0]
    assert len(pulses(rec["res_reg_n"])) == 1 and len(pulses(rec["la_in_d_n"])) >= 3
    assert check_expansion(rec, bit_rate=bit_rate) == []


@pytest.mark.slow
def test_watchdog_reset_at_pin_level_pulses_resreg_4_t0_and_clears_the_chain() -> None:
    """RX-5 at pin level: the layer-2 watchdog's reset of process data (Table 3-13) with ExtReg = 1 pulls /ResReg
    low for 4 t0 (not 375 ns), and the chain sees it: outputs and chain cleared."""
    bit_rate = 2_000_000
    cpb = wire.clocks_per_bit(bit_rate)
    pins = up_pins(3, bit_rate)
    sre = Sre1(3)
    pins.chip.attach_expansion(sre)
    ring, master = pin_master(pins, record=True)
    timeout = tables.WATCHDOG_TIMEOUTS_S[0]
    assert timeout is not None
    master.set_watchdog(timeout)
    assert master.cycle().cycle is Cycle.ID
    exchange(ring, master, b"\x11\x22\x33")
    assert sre.outputs == b"\x33\x22\x11"
    for _ in range(120):  # 60 ms in short pieces (PinRing's receiver is quadratic in one call's length)
        ring.idle(timeout / 100)
    assert pins.chip.events["WATCHDOG"] == 1
    assert sre.outputs == bytes(3) and sre.contents() == bytes(3)
    rec = ring.recorded()[0]
    assert [width for _, width in pulses(rec["res_reg_n"])] == [PULSE_T0 * cpb, PULSE_T0 * cpb]  # reset, watchdog

"""The firmware bench (supi3.sdk.bench): firmware time and bus time on one clock, at transaction level.

Manual 3.4.14 and Figure 3-22: the I/O access bit is 1 from the check sequence to the latch, the latch phase ends
the cycle, a data-register access inside it is inconsistent; /IRQ interrupts the firmware. The phase positions
(wire.cycle_phases) are checked against the pin-level chip, and properties run over random histories of master
outputs, ring faults and resets.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3 import tables, timing
from supi3.config import decode
from supi3.interbus import wire
from supi3.interbus.device import PlainDevice
from supi3.interbus.ring import BitFlip
from supi3.interbus.wire import Cycle
from supi3.model.registers import InconsistentDataError, ReconfigurationError
from supi3.regmap import IRQ_EVT, OUT0, SET
from supi3.sdk.bench import IDLE_LOOPS_LIMIT, Bench, BenchError, CycleTiming, Firmware, default_config
from supi3.sdk.driver import DriverArgumentError, Irq, Mode, Supi3Driver, get_u16, put_u16
from supi3.timing import TimingError
from support import RB_INIT_UP, ChipPins, bring_up, data_frame


class Echo(Firmware):
    """1 word IN/OUT, interrupt driven: IN = OUT inverted, every valid data cycle (3.4.14, "Using interrupts")."""

    def __init__(self, mode: Mode = Mode.MOTOROLA) -> None:
        self.mode = mode
        self.seen: list[int] = []

    def setup(self, drv: Supi3Driver) -> None:
        drv.initialize(self.mode)
        drv.configure(0x83, 0x01)
        drv.irq_enable(Irq.VALID)

    def isr(self, drv: Supi3Driver) -> None:
        if drv.irq_service() & Irq.VALID:
            word = get_u16(drv.block_transfer(put_u16(0)))  # read OUT (writes IN 0 for now)
            self.seen.append(word)
            drv.block_transfer(put_u16(word ^ 0xFFFF))


def test_process_data_moves_both_ways_through_the_firmware() -> None:
    bench = Bench(firmware=Echo())
    bench.run(3)
    bench.master.set_outputs(1, b"\x12\x34")
    bench.run(4)
    assert bench.firmware is not None
    assert bench.chip.registers is not None
    assert bench.master.inputs(1) == b"\xed\xcb"
    assert bench.interrupts >= 4 and bench.bytes_clocked > 0


# ------------------------------------------------------------------------------------------------------------
# The phases of Figure 3-22 on the clock
# ------------------------------------------------------------------------------------------------------------


class Probe(Firmware):
    """A main loop that reads IRQ_EVT without pause and notes (time of the data byte, I/O bit)."""

    def __init__(self) -> None:
        self.samples: list[tuple[float, int]] = []
        self.bench: Bench | None = None

    def setup(self, drv: Supi3Driver) -> None:
        drv.initialize(Mode.MOTOROLA)
        drv.configure(0x83, 0x01)

    def loop(self, drv: Supi3Driver) -> None:
        assert self.bench is not None
        at = self.bench.now + self.bench.byte_s  # the data byte's /SS falls one byte after the command's
        self.samples.append((at, drv.read(IRQ_EVT) >> 7))


@pytest.mark.parametrize("bit_rate", [500_000, 2_000_000])
def test_io_access_bit_is_one_from_the_check_sequence_to_the_latch(bit_rate: int) -> None:
    probe = Probe()
    bench = Bench(firmware=probe, bit_rate=bit_rate)
    probe.bench = bench
    bench.run(12)
    data = [c for c in bench.timeline if c.cycle is Cycle.DATA and c.end <= bench.now]
    assert len(data) >= 5
    for at, bit in probe.samples:
        busy = any(c.io_busy <= at < c.end for c in data)
        if data[0].start <= at < data[-1].end:
            assert bit == int(busy), f"I/O bit {bit} at {at * 1e6:.2f} µs"
    # the window after the bit falls is at least 30 bit periods before the next latch phase (3.4.14)
    for c in data:
        assert c.latch - c.io_busy >= 30 * c.bit_s


@pytest.mark.parametrize("bit_rate", [500_000, 2_000_000])
def test_cycle_phases_are_where_the_pin_level_chip_has_them(bit_rate: int) -> None:
    config = decode(*RB_INIT_UP, clk_conf=tables.clk_conf_for(bit_rate))
    pins = ChipPins(config)
    regs = pins.registers
    regs.cpu_write(13, 0x83)
    bring_up(pins)
    pins.drain()
    start = pins.cycle
    pins.send(data_frame(b"\x00\x00"))
    io, latch = [], []
    while pins.line:
        pins.step()
        io.append(int(regs.io_access))
        latch.append(int(regs.latch_phase))
    pins.drain(40)
    io_trace, latch_trace = np.array(io), np.array(latch)
    cpb = round(pins.clock_hz / bit_rate)
    phases = wire.cycle_phases(2, 1)
    rises = [int(np.argmax(io_trace)), int(np.argmax(latch_trace))]
    ends = int(len(io_trace) - np.argmax(io_trace[::-1]))
    for got, bit in zip([*rises, ends], phases[:3], strict=True):
        # the mid-bit sample, give or take the synchroniser's few clocks
        assert abs(got - (bit + 0.5) * cpb) <= 4, (got, (bit + 0.5) * cpb)
    assert start >= 0


def next_data_cycle(bench: Bench) -> CycleTiming:
    """Run to the start of the next data cycle and return its timing."""
    while True:
        bench.advance(bench.now)  # starts the next cycle if it is due
        cycle = bench.timeline[-1]
        if cycle.cycle is Cycle.DATA and cycle.end > bench.now:
            return cycle
        bench.run(1)


def test_a_data_register_access_in_the_latch_phase_is_caught() -> None:
    bench = Bench(firmware=Echo())
    bench.run(4)
    bench.firmware = None  # the test plays the firmware from here
    cycle = next_data_cycle(bench)
    bench.advance(cycle.latch - bench.byte_s - cycle.bit_s)  # the data byte ends one bit before the latch phase
    bench.driver.read(OUT0)
    bench.run(1)
    cycle = next_data_cycle(bench)
    bench.advance(cycle.latch - bench.byte_s + cycle.bit_s)  # its data byte's /SS falls inside the latch phase
    with pytest.raises(InconsistentDataError, match=r"3\.4\.14") as caught:
        bench.driver.read(OUT0)
    assert caught.value.clock is not None
    assert bench.driver.initialized and bench.transport.protocol.c_d == 0  # the access ran to its end


class Lazy(Firmware):
    """Never reads IRQ_EVT: /IRQ stays low after the first event."""

    def __init__(self) -> None:
        self.calls = 0

    def setup(self, drv: Supi3Driver) -> None:
        drv.initialize(Mode.MOTOROLA)
        drv.configure(0x82, 0x01)
        drv.irq_enable(Irq.VALID)

    def isr(self, drv: Supi3Driver) -> None:
        del drv
        self.calls += 1


def test_the_interrupt_is_edge_triggered() -> None:
    lazy = Lazy()
    bench = Bench(firmware=lazy)
    bench.run(10)
    assert lazy.calls == 1 and bench.registers.irq_n == 0  # FW-3: no new falling edge, no new call


def test_interrupt_latency_is_within_the_manuals_access_time() -> None:
    bench = Bench(firmware=Echo())
    bench.run(50)
    assert bench.irq_latency_s <= timing.cpu_access_time_s(2, 500_000)


class Stuck(Firmware):
    def loop(self, drv: Supi3Driver) -> None:
        del drv


class Waiting(Firmware):
    def loop(self, drv: Supi3Driver) -> None:
        drv.transport.delay_us(10)


def test_a_main_loop_that_does_nothing_is_reported_and_one_that_waits_is_not() -> None:
    with pytest.raises(BenchError, match=f"{IDLE_LOOPS_LIMIT} times"):
        Bench(firmware=Stuck()).run(1)
    bench = Bench(firmware=Waiting())
    bench.run(3)
    assert bench.cycles == 3


# ------------------------------------------------------------------------------------------------------------
# Histories: nothing latched is ever wrong
# ------------------------------------------------------------------------------------------------------------

STEPS = st.lists(st.tuples(st.sampled_from(["run", "out", "flip", "clear", "reset"]), st.integers(0, 0xFFFF)),
                 min_size=1, max_size=25)  # fmt: skip


@settings(max_examples=40, deadline=None)
@given(steps=STEPS, bit_rate=st.sampled_from([500_000, 2_000_000]), mode=st.sampled_from(list(Mode)),
       others=st.integers(0, 3))  # fmt: skip
def test_firmware_sees_only_words_the_master_sent(steps: list[tuple[str, int]], bit_rate: int, mode: Mode,
                                                   others: int) -> None:  # fmt: skip
    echo = Echo(mode)
    bench = Bench(firmware=echo, bit_rate=bit_rate, others=[PlainDevice(0x02, 1) for _ in range(others)])
    sent = {0}
    last = 0
    bench.run(3)
    for action, value in steps:
        if action == "run":
            bench.run(1 + value % 4)
        elif action == "out" and bench.master.config is not None:
            bench.master.set_outputs(1, put_u16(value))
            sent.add(value)
            last = value
        elif action == "flip":
            bench.ring.inject(BitFlip(1 + value % (others + 2), value % 40))
        elif action == "clear":
            bench.ring.clear_faults()
        elif action == "reset":
            bench.master.alarm_stop()
            sent.add(0)  # an INTERBUS reset clears OUT (Table 3-13)
        assert set(echo.seen) <= sent
    bench.ring.clear_faults()
    bench.run(8)
    if bench.master.config is not None and last in sent:
        assert echo.seen[-1] == int.from_bytes(bench.master.outputs(1), "big")
        assert bench.master.inputs(1) == put_u16(echo.seen[-1] ^ 0xFFFF) or echo.seen[-1] != echo.seen[-2]


# ------------------------------------------------------------------------------------------------------------
# Hostile construction and calls
# ------------------------------------------------------------------------------------------------------------

BAD: list[tuple[str, Callable[[], object], type[Exception], str]] = [
    ("pin mode", lambda: Bench(decode("00001")), DriverArgumentError, "Init-µP mode"),
    ("firmware", lambda: Bench(firmware=object()), DriverArgumentError, "firmware must be"),  # type: ignore[arg-type]
    ("mode", lambda: Bench(mode="intel"), ValueError, "mode must be"),  # type: ignore[arg-type]
    ("bit rate", lambda: Bench(bit_rate=1_000_000), ValueError, "1000000"),
    ("config", lambda: Bench(config="10011"), ValueError, "config must be"),  # type: ignore[arg-type]
    ("sclk", lambda: Bench(sclk_hz=10e6), TimingError, "faster than Table 3-7"),
    ("cycle time", lambda: Bench(cycle_time_s=-1.0), ValueError, "cycle_time_s must be"),
    ("strict", lambda: Bench(strict="yes"), ValueError, "strict must be"),  # type: ignore[arg-type]
    ("run", lambda: Bench().run(-1), ValueError, "cycles must be"),
    ("run str", lambda: Bench().run("3"), ValueError, "cycles must be"),  # type: ignore[arg-type]
    ("run_for", lambda: Bench().run_for(float("nan")), ValueError, "seconds must be"),
    ("stat err", lambda: Bench().set_stat_err(2), ValueError, "active must be"),  # type: ignore[arg-type]
]


@pytest.mark.parametrize(("make", "error", "message"), [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_bad_bench_input_is_a_named_error(make: Callable[[], object], error: type[Exception], message: str) -> None:
    with pytest.raises(error, match=message):
        make()


def test_default_config_is_an_init_up_mode_at_the_bit_rate() -> None:
    for bit_rate in (500_000, 2_000_000):
        config = default_config(bit_rate)
        assert config.bit_rate == bit_rate
        assert Bench(config).registers is not None


def test_stat_err_and_mod_ack_reach_the_master_and_back() -> None:
    bench = Bench(firmware=Echo())
    bench.run(3)
    bench.set_stat_err(True)
    bench.run_for(0.21)
    assert bench.chip.pf  # latched after the 200 ms filter time (3.6.2)
    bench.set_stat_err(False)
    bench.master.quit_peripheral_error(1)
    bench.run(4)
    assert bench.chip.events["MODACK"] == 1 and not bench.chip.pf
    assert bench.mod_ack == 1  # the 375 ns pulse is over


class Reconfigures(Echo):
    """Rewrites SET to 2 words in its third service routine, while the bus runs (3.4.11: not permitted)."""

    def isr(self, drv: Supi3Driver) -> None:
        if len(self.seen) >= 3:  # reconfigured: only serve the interrupt
            drv.irq_service()
            return
        super().isr(drv)
        if len(self.seen) == 3:
            drv.write(SET, 0x85)


def test_set_rewritten_during_a_frame_latches_nothing_and_the_bus_recovers() -> None:
    bench = Bench(firmware=Reconfigures())
    with pytest.raises(ReconfigurationError, match="during bus operation"):
        bench.run(20)
    out_before = bench.registers.value("OUT0")
    invalid = bench.chip.events["INVALID"]
    assert bench.under_way  # the run raised inside the frame
    bench.run(0)  # the frame that loaded 2 bytes ends in a chip that now has 4: discarded (M15; a run ends it, MCU-76)
    assert bench.chip.events["INVALID"] == invalid + 1 and bench.registers.value("OUT0") == out_before
    bench.run(10)  # the master sees the new length and rebuilds its table (A19)
    config = bench.master.config
    assert config is not None and config[0].data_bytes == 4

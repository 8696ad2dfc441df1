"""FW-14 (docs/assumptions/sdk.md): the firmware bench's ``Bench.run`` ends once the firmware has served the last
cycle, by the emulated board's rule (MCU-30), one definition for both (``supi3.sdk.bench.MainLoopPasses``).

A firmware with a main loop is served when a whole pass of it (one ``Firmware.loop`` call) began after the run's last
cycle and after the last service routine, within ``SERVE_TELEGRAMS`` status telegrams of bus time. Before, the
bench returned inside the pass that saw the last cycle end: a polling firmware (the C ``polling_io``) showed its
output terminals one step behind, and so did a main loop that serves what its service routine noted (the board
port's ``main``, examples/fw_board.h). Ref: 3.4.14 (the interrupt and the polling method, Fig. 3-22).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.errors import ArgumentError
from supi3.interbus import wire
from supi3.interbus.device import PlainDevice
from supi3.interbus.ring import Branch, BranchKind
from supi3.sdk import native
from supi3.sdk.bench import (
    SERVE_PASSES,
    SERVE_TELEGRAMS,
    START_WAIT_S,
    Bench,
    BenchError,
    Firmware,
    MainLoopPasses,
    MasterStart,
    ServeWait,
    discovery_master,
    resume_s,
    ring_positions,
    serve_wait_s,
    telegram_end_s,
)
from supi3.sdk.driver import Mode, Supi3Driver
from supi3.sdk.examples import DigitalIo, PollingIo
from support import c_firmware, terminal

MCU = Path(__file__).parent / "mcu"
PASS_US = 20.0
"""The other work of one pass of the test's main loops (as tests/mcu/main_loop.c's PASS_US)."""


# The rule itself -----------------------------------------------------------------------------------------------------


def test_the_pass_rule_over_every_short_history() -> None:
    """Every history of up to 7 events (an arrival at the idle point, a handler, the wait's begin; times rising by
    one per event): served exactly when at least two arrivals came after the wait began and after the last
    handler, told at each arrival and by ``passed`` after each event."""
    assert SERVE_PASSES == 2
    for length in range(8):
        for events in itertools.product("abh", repeat=length):
            passes = MainLoopPasses()
            since: int | None = None
            counted = 0  # arrivals at or after since, after the last handler
            for at, event in enumerate(events):
                if event == "b":
                    passes.begin(at)
                    since = at
                    counted = 0
                elif event == "h":
                    passes.handler()
                    counted = 0
                else:
                    counted += since is not None
                    assert passes.arrive(at) is (counted >= SERVE_PASSES), events
                assert passes.passed() is (since is not None and counted >= SERVE_PASSES), events
            passes.end()
            assert not passes.passed()


@pytest.mark.parametrize("bit_rate", [500_000, 2_000_000])
def test_the_wait_is_serve_telegrams_status_telegrams(bit_rate: int) -> None:
    """64 status telegrams of 5 bits (0.64 ms at 500 kbit/s), the bound the board uses too (MCU-30)."""
    assert SERVE_TELEGRAMS == 64
    assert serve_wait_s(bit_rate) == pytest.approx(64 * 5 / bit_rate)
    assert Bench(bit_rate=bit_rate)._wait.begin(0.0) == serve_wait_s(bit_rate)  # ServeWait: from the last end (MCU-55)


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda p: p.arrive(float("nan")), r"at must be a finite number, not nan"),
        (lambda p: p.arrive("1"), r"at must be a finite number, not '1'"),
        (lambda p: p.begin(math.inf), r"since must be a finite number, not inf"),
        (lambda p: (p.arrive(5.0), p.arrive(4.0)), r"at must be a time at or after the last arrival .*\(FW-14\)"),
        (lambda p: (p.arrive(5.0), p.begin(4.0)), r"since must be a time at or after the last arrival .*\(FW-14\)"),
        (lambda p: (p.begin(5.0), p.arrive(4.0)), r"at must be a time at or after .*the wait's begin \(5.0\)"),
        (lambda _: serve_wait_s(0), r"bit_rate .*Table 1-7"),
        (lambda _: serve_wait_s(True), r"bit_rate .*Table 1-7"),
    ],
)
def test_the_rule_s_entries_name_bad_input(call: Callable[[MainLoopPasses], object], match: str) -> None:
    """A time that is no finite number or goes back, a bit rate Table 1-7 does not list: a named ``ArgumentError``,
    the passes unchanged."""
    passes = MainLoopPasses()
    with pytest.raises(ArgumentError, match=match):
        call(passes)
    assert not passes.passed() and len(passes.arrivals) <= 1


# Python firmware -----------------------------------------------------------------------------------------------------


class NotingDigitalIo(DigitalIo):
    """DigitalIo as the board port runs a firmware with a main loop: the service routine only notes the /IRQ edge,
    the main loop does PASS_US of other work, then serves a noted edge (examples/fw_board.h)."""

    def __init__(self, mode: Mode = Mode.MOTOROLA, pass_us: float = PASS_US) -> None:
        super().__init__(mode)
        self.noted = False
        self.pass_us = pass_us

    def isr(self, drv: Supi3Driver) -> None:
        del drv
        self.noted = True

    def loop(self, drv: Supi3Driver) -> None:
        drv.transport.delay_us(self.pass_us)
        if self.noted:
            self.noted = False
            super().isr(drv)


Step = tuple[int, int, float, int]
"""The master's OUT word, the input terminals, a ``run_for`` first (seconds, 0: none), the cycles of the run."""


def _history(seed: int, steps: int) -> list[Step]:
    rng = np.random.default_rng(seed)
    return [(int(rng.integers(0, 1 << 16)), int(rng.integers(0, 1 << 16)),
             float(rng.choice((0.0, 30e-6, 150e-6, 1e-3))), int(rng.integers(1, 4))) for _ in range(steps)]  # fmt: skip


def _play_python(bench: Bench, device: DigitalIo | PollingIo, history: list[Step]) -> list[tuple[int, int, bool]]:
    bench.run(6)
    seen = []
    for out, value, wait_s, cycles in history:
        bench.master.set_outputs(1, out.to_bytes(2, "big"))
        device.inputs = value
        if wait_s:
            bench.run_for(wait_s)
        bench.run(cycles)
        seen.append((device.outputs, int.from_bytes(bench.master.inputs(1), "big"), bench.served))
    return seen


@pytest.mark.parametrize("seed", [1, 2])
@pytest.mark.parametrize("mode", list(Mode))
def test_python_main_loop_and_polling_firmware_give_the_interrupt_firmware_s_data(seed: int, mode: Mode) -> None:
    """After every run of a random history (data changes, ``run_for`` of 0 to 1 ms cutting cycles anywhere, runs of
    1 to 3 cycles): the noting main loop shows the interrupt example's output terminals and IN data, the polling
    example (pin and register bit) its output terminals, each run ending served; a run of two or more cycles has its
    step's master word in the output terminals. Before FW-14 the noting main loop was a step behind. (The Python
    polling example exchanges whenever the I/O bit reads 0, a cycle's start included, so its IN data may reach the
    master a cycle before the interrupt example's.)"""
    history = _history(seed, 12)
    devices: dict[str, tuple[DigitalIo | PollingIo, bool]] = {
        "interrupt": (DigitalIo(mode), True), "noting": (NotingDigitalIo(mode), True),
        "polling": (PollingIo(mode), True), "polling_bit": (PollingIo(mode), False)}  # fmt: skip
    seen = {name: _play_python(Bench(firmware=device, mode=mode, io_pin=io_pin), device, history)
            for name, (device, io_pin) in devices.items()}  # fmt: skip
    assert seen["noting"] == seen["interrupt"] and seen["polling"] == seen["polling_bit"]
    assert [outputs for outputs, *_ in seen["polling"]] == [outputs for outputs, *_ in seen["interrupt"]]
    assert all(served for *_, served in seen["noting"] + seen["polling"])
    for name in ("noting", "polling"):
        for (out, *_, cycles), (outputs, *_) in zip(history, seen[name], strict=True):
            assert cycles < 2 or outputs == out, name


def test_the_wait_adds_at_most_a_pass_and_a_service_routine() -> None:
    """The noting main loop: each run ends within two passes and one service routine after its last cycle's end
    (the pass running at the end, then the whole pass), never before the end; ``run_for`` does not wait and leaves
    ``served`` as the last run left it."""
    device = NotingDigitalIo()
    bench = Bench(firmware=device)
    bench.run(6)
    routine_s = 8 * bench.byte_s  # IRQ_EVT read, OUT0, OUT1, IN0, IN1: at most 4 accesses of 2 bytes more
    for cycles in (1, 2, 3, 1, 5):
        target = bench.cycles + cycles
        bench.run(cycles)
        ended = [t.end for t in bench.timeline if t.end <= bench.now]
        last_end = sorted(ended)[-(bench.cycles - target) - 1]  # the run's last cycle (the wait may end more)
        assert bench.served and bench.cycles >= target
        assert 0 <= bench.now - last_end <= 2 * PASS_US * 1e-6 + 2 * routine_s
    bench.run_for(1e-3)
    assert bench.served


@pytest.mark.parametrize("pass_us", [750.0, 3000.0])
def test_a_pass_longer_than_the_wait_ends_the_run_unserved_and_the_next_run_goes_on(pass_us: float) -> None:
    """A main loop whose pass (0.75 ms, 3 ms) outlasts SERVE_TELEGRAMS status telegrams (0.64 ms at 500 kbit/s): the
    pass after the last cycle does not count, the run ends unserved after it (the bench cannot cut a pass, where
    the board's core stops at the bound); the next run goes on with the data of its cycles. (A pass this long serves
    an edge cycles late: where its reads fall depends on the cycles' phase. With the master's start at the set-up's
    end, FW-15, a 0.7 ms pass reads IRQ_EVT in the frame in which the next cycle's event comes, so /IRQ never rises
    again and the edge-triggered firmware waits for ever, 3.4.14; 0.65 and 0.8 ms read OUT0 in a latch phase.)"""
    device = NotingDigitalIo(pass_us=pass_us)
    bench = Bench(firmware=device)
    bench.run(3)
    assert not bench.served
    bench.master.set_outputs(1, b"\x12\x34")
    bench.run(6)
    assert not bench.served and device.outputs == 0x1234
    device.pass_us = PASS_US
    bench.run(1)
    assert bench.served


def test_a_run_that_raises_ends_unserved() -> None:
    """A main loop that goes wrong in the wait (FW-5: nothing clocked, no wait, 1,000 times): ``BenchError``, and
    ``served`` is False until a run ends served."""

    class Stalling(NotingDigitalIo):
        stall = False

        def loop(self, drv: Supi3Driver) -> None:
            if not self.stall:
                super().loop(drv)

    device = Stalling()
    bench = Bench(firmware=device)
    bench.run(3)
    assert bench.served
    device.stall = True
    with pytest.raises(BenchError, match=r"main loop ran 1000 times .*\(FW-5\)"):
        bench.run(1)
    assert not bench.served
    device.stall = False
    bench.run(1)
    assert bench.served


# C firmware: the board's variants on the host ------------------------------------------------------------------------


C_VARIANTS = {"interrupt": [native.example("digital_io")],
              "main_loop": [native.example("digital_io"), MCU / "main_loop.c"],
              "polling": [native.example("polling_io")]}  # fmt: skip
"""digital_io, with tests/mcu/main_loop.c's fw_loop, polling_io (the variants tests/test_mcu_serve.py runs on the
board and against this bench)."""


def play_c(cache: pytest.Cache, name: str, history: list[tuple[bytes, bytes, float, int]],
           mode: Mode = Mode.MOTOROLA) -> list[tuple[bytes, bytes, bool]]:  # fmt: skip
    """The C variant ``name`` (:data:`C_VARIANTS`) built for the host on the bench: power-up (3 cycles), then per
    step of ``history`` (OUT word, input terminals, a ``run_for`` first in seconds or 0, the run's cycles) the data
    set, the ``run_for``, the run; (output terminals, the master's IN data, served) after each."""
    defines = {"FW_MODE": "SUPI3_MODE_INTEL"} if mode is Mode.INTEL else None
    firmware = c_firmware(cache, C_VARIANTS[name], defines=defines)  # type: ignore[arg-type]
    bench = Bench(firmware=firmware, mode=mode)
    bench.run(3)
    seen = []
    for out_data, in_data, wait_s, cycles in history:
        bench.master.set_outputs(1, out_data)
        firmware.board.inputs[0 : len(in_data)] = in_data
        if wait_s:
            bench.run_for(wait_s)
        bench.run(cycles)
        seen.append((bytes(firmware.board.outputs[0 : len(out_data)]), bench.master.inputs(1), bench.served))
    return seen


@pytest.mark.parametrize("mode", [Mode.MOTOROLA, Mode.INTEL])
def test_c_main_loop_and_polling_firmware_give_the_interrupt_firmware_s_data(
    pytestconfig: pytest.Config, mode: Mode
) -> None:
    """The C variants the board tests (MCU-30) on the host bench: after every run of a random history the main-loop
    variant of digital_io and polling_io show the interrupt variant's output terminals and IN data, each run
    ending served. Before FW-14 polling_io's output terminals were a step behind."""
    assert pytestconfig.cache is not None
    history = [(out.to_bytes(2, "big"), value.to_bytes(2, "big"), wait_s, cycles)
               for out, value, wait_s, cycles in _history(4, 12)]  # runs of 2 and 3 straight after a data change
    seen = {name: play_c(pytestconfig.cache, name, history, mode) for name in C_VARIANTS}
    assert seen["main_loop"] == seen["interrupt"] == seen["polling"]
    assert all(served for *_, served in seen["polling"] + seen["main_loop"])
    for (out, *_, cycles), (outputs, *_) in zip(history, seen["polling"], strict=True):
        assert cycles < 2 or outputs == out


# -- FW-15 (MCU-45): the master starts when the set-up has ended ----------------------------------------------------


class Slow(DigitalIo):
    """DigitalIo whose set-up first does ``setup_us`` and whose service routine first does ``isr_us`` of other work
    (a service routine longer than the serve wait: unserved)."""

    def __init__(self, setup_us: float = 0.0, isr_us: float = 0.0) -> None:
        super().__init__()
        self.setup_us = setup_us
        self.isr_us = isr_us

    def setup(self, drv: Supi3Driver) -> None:
        drv.transport.delay_us(self.setup_us)
        super().setup(drv)

    def isr(self, drv: Supi3Driver) -> None:
        drv.transport.delay_us(self.isr_us)
        super().isr(drv)


def test_the_master_start_rule() -> None:
    """MasterStart: START_WAIT_S until the set-up is noted, then its time (the first note only, never after
    START_WAIT_S); the start on the status telegrams' grid; bad times refused by name."""
    start = MasterStart()
    assert (start.at, start.due(START_WAIT_S - 1e-9), start.due(START_WAIT_S)) == (START_WAIT_S, False, True)
    assert start.set_up(45e-6) and not start.set_up(10e-6) and start.at == 45e-6 and start.due(45e-6)
    for bit_rate in (500_000, 2_000_000):
        telegram_s = wire.STATUS_TELEGRAM_BITS / bit_rate
        assert start.start_s(bit_rate) == pytest.approx(math.ceil(45e-6 / telegram_s) * telegram_s, abs=1e-15)
    late = MasterStart()
    late.set_up(5e-3)
    assert late.at == START_WAIT_S
    for bad in (-1e-6, math.nan, math.inf, "0"):
        with pytest.raises(ArgumentError, match="at"):
            MasterStart().set_up(bad)  # type: ignore[arg-type]


@pytest.mark.parametrize("setup_us", [0.0, 100.0, 2000.0])
def test_the_bench_s_master_starts_when_the_set_up_has_ended(setup_us: float) -> None:
    """FW-15: the master's Alarm Stop begins at the end of the status telegram in which ``setup`` returned, at the
    latest at START_WAIT_S (a 2 ms set-up gets the master during it, and its ID cycle the chip's reset ID); the
    first ID cycle of a set-up done in time reads the firmware's ID code (3, no rediscovery), and ``run(3)``
    serves two data cycles. Without a firmware the master starts at the first run, after the test's own driver
    calls. The 2 ms set-up writes SET after the master's ID cycle (sized for the ring, MCU-56, FW-20: 0.25 ms at
    500 kbit/s), during its data cycles: a ReconfigurationError (before, the 27 ms ID cycle of the largest ring
    covered it), kept by a bench that is not strict."""
    bare = Bench()
    bare.run(1)
    reset_s = bare.timeline[0].start  # a master started at 0: its ID cycle begins after the reset alone
    device = Slow(setup_us=setup_us)
    bench = Bench(firmware=device, strict=False)
    bench.power_up()
    setup_end = bench.now
    bench.run(3)
    telegram_s = wire.STATUS_TELEGRAM_BITS / bench.config.bit_rate
    started = math.ceil(min(setup_end, START_WAIT_S) / telegram_s - 1e-9) * telegram_s
    assert bench.timeline[0].start - reset_s == pytest.approx(started, abs=1e-12)
    if setup_end < START_WAIT_S:
        assert [t.cycle.name for t in bench.timeline][:3] == ["ID", "DATA", "DATA"]
        assert bench.master.config is not None and bench.master.config[0].id_code == 0x03
        assert bench.interrupts == 2 and bench.served
    late = {type(error).__name__ for error in bench.registers.violations.records}
    assert late == (set() if setup_end < START_WAIT_S else {"ReconfigurationError"})
    tested = Bench()
    tested.driver.initialize(Mode.MOTOROLA)
    tested.driver.configure(0x83, 0x03)
    driven = tested.now
    tested.run(1)
    assert tested.timeline[0].start - reset_s == pytest.approx(math.ceil(driven / telegram_s) * telegram_s, abs=1e-12)
    assert tested.master.config is not None and tested.master.config[0].id_code == 0x03



HOLD_FIRMWARE: dict[str, Callable[[], Firmware]] = {
    "interrupt": DigitalIo, "polling": PollingIo, "slow": lambda: Slow(isr_us=700.0)}


@settings(max_examples=25, derandomize=True, deadline=None)
@given(name=st.sampled_from(sorted(HOLD_FIRMWARE)), bit_rate=st.sampled_from([500_000, 2_000_000]),
       history=st.lists(st.tuples(st.sampled_from([0.0, 20e-6, 300e-6]), st.integers(0, 4)), min_size=1,
                        max_size=5))  # fmt: skip
def test_the_bench_s_run_n_runs_exactly_n_cycles_then_waits_boundedly(
    name: str, bit_rate: int, history: list[tuple[float, int]]
) -> None:
    """FW-19 (MCU-55) on the firmware bench, back to back: ``run(n)`` starts exactly n master cycles (a cycle a
    ``run_for`` left under way ends first, run(0) too, MCU-76), the master holding while the
    firmware serves the last; a served run ends within SERVE_TELEGRAMS status telegrams of the last cycle's end; a
    service routine longer than that (700 µs) that runs after the last cycle ends its run unserved; the next run's
    first cycle starts at the end of the status telegram the line idled in. Before, the master went on during the
    last service routine and the passes: the slow routine's run(3), run(1), run(2) from power-up ran 8, 4 and 6
    cycles at 500 kbit/s, each "served"."""
    bench = Bench(firmware=HOLD_FIRMWARE[name](), bit_rate=bit_rate, strict=False)  # the slow one: latch-phase reads
    bench.run(3)
    wait_s = serve_wait_s(bit_rate)
    for run_for_s, cycles in history:
        if run_for_s:
            bench.run_for(run_for_s)
        before, under_way = bench.cycles, bench.under_way
        bench.run(cycles)
        assert bench.cycles - before == cycles + under_way and not bench.under_way
        last = bench.timeline[-1]
        if cycles:  # served: within the bound after the last cycle's end (the slow routine's only if none ran)
            assert bench.served is (bench.now - last.end <= wait_s)
            assert bench.served or name == "slow"
        if cycles:  # the next cycle starts at the end of the status telegram the line idled in when the run ended
            ended = bench.now  # (its first bit: the ring's time, within a bit after the bench's start)
            bench.run(1)
            late = bench.timeline[-1].start - telegram_end_s(last.end, ended, bit_rate)
            assert -1e-12 <= late < 1 / bit_rate


def test_the_serve_wait_and_the_resume_rule() -> None:
    """ServeWait: the bound SERVE_TELEGRAMS telegrams after the last cycle's end, over to half a telegram (the pin
    level's float sums); telegram_end_s and resume_s on the idle line's grid; bad times refused by name."""
    telegram_s = wire.STATUS_TELEGRAM_BITS / 500_000
    wait = ServeWait(500_000)
    with pytest.raises(BenchError, match="before begin"):
        _ = wait.until
    assert wait.begin(1e-3) == pytest.approx(1e-3 + SERVE_TELEGRAMS * telegram_s)
    assert not wait.over(wait.until - telegram_s) and wait.over(wait.until - telegram_s / 4)
    wait.end()
    assert wait.ended is None
    for bad in (-1.0, math.nan, math.inf):
        with pytest.raises(ArgumentError, match="ended"):
            wait.begin(bad)
    assert telegram_end_s(1e-3, 1e-3, 500_000) == 1e-3
    assert telegram_end_s(1e-3, 1e-3 + 0.5 * telegram_s, 500_000) == pytest.approx(1e-3 + telegram_s)
    assert telegram_end_s(1e-3, 0.0, 500_000) == 1e-3
    assert resume_s(1e-3, 5e-3, 2e-3, 500_000) == 5e-3  # the cycle time's schedule is later
    assert resume_s(1e-3, 1e-3, 1e-3 + 2.2 * telegram_s, 500_000) == pytest.approx(1e-3 + 3 * telegram_s)


def test_the_discovery_id_cycle_is_sized_for_the_ring() -> None:
    """FW-20 (MCU-56): the bench's master allows for the ring's positions (a branch: its bus terminal module and
    each device), not 512: one chip's discovery ID cycle at 500 kbit/s lasts 0.25 ms, not 27 ms; a ring of the chip
    and two devices reads all three. discovery_master refuses a count outside 1..MAX_DEVICES by name."""
    bench = Bench()
    bench.run(1)
    assert bench.master.max_devices == 1
    first = bench.timeline[0]
    assert first.cycle.name == "ID" and first.end - first.start < 0.3e-3
    others = [PlainDevice(0x02, 0b00001), PlainDevice(0x02, 0b00001)]
    ring = Bench(others=others)
    ring.run(2)
    assert ring.master.max_devices == 3 and ring.master.config is not None and len(ring.master.config) == 3
    assert ring_positions([others[0], Branch(terminal("BK-LB"), others, BranchKind.LOCAL)]) == 4
    for bad in (0, wire.MAX_DEVICES + 1):
        with pytest.raises(ArgumentError, match="max_devices"):
            discovery_master(ring.ring, bad)

"""Hostile inputs, orders and histories against the entries the last session changed (a user's review, round 14):
the ring's devices (:class:`~supi3.interbus.ring.Ring`: one device object in two live rings, UP-47; a device's
``constant_output`` that is no level, RX-14), a model's ``recent_events`` (:func:`supi3.pinlevel.recent_events`),
the firmware bench's and the emulated board's cycle time and runs (:mod:`supi3.sdk.bench`: ``bench_config``,
``check_run_cycles``; :class:`~supi3.mcu.board.Board`), the board's peripherals and helpers (``Exti.triggers``,
``Spi.replace_received``, :func:`supi3.mcu.pins.chip_clock`, :func:`supi3.mcu.pins.released`) and the spidev
transport's answers (:class:`~supi3.sdk.transports.SpidevTransport`).

Every bad input is refused by name (which argument, which rule, which value) and changes nothing. Over any history
of bench runs, timed runs, holds, resumes and clock steps with refused calls among them, a refused call changes
nothing and a run after a resume runs its cycles (FW-30); over any history of board runs with the core's native
exception traffic switched on and off, between runs and inside them at exception entries, the board shows what it
shows with the switch never touched (MCU-70, MCU-71).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.errors import ArgumentError
from supi3.interbus.device import PlainDevice
from supi3.interbus.errors import InterbusArgumentError, InterbusError
from supi3.interbus.master import Master
from supi3.interbus.ring import Ring
from supi3.mcu.pins import chip_clock, released
from supi3.mcu.stm32 import Exti, Rcc, Spi
from supi3.model.chip import Supi3
from supi3.model.pinring import PinRing
from supi3.model.pins import Supi3Pins
from supi3.pinlevel import PinSpecError, recent_events
from supi3.sdk.bench import Bench, BenchError, bench_config, default_config
from supi3.sdk.driver import Mode, Supi3Driver, TransportError
from supi3.sdk.examples.digital import DigitalIo
from supi3.sdk.transports import SpidevTransport
from support import digital_io_elf

# ---------------------------------------------------------------------------------------------------------------
# The ring's devices (supi3.interbus.ring)
# ---------------------------------------------------------------------------------------------------------------


def test_one_device_in_two_live_rings_is_refused_by_name() -> None:
    """Known defect of round 13: a device object put into a second ring while the first lives (two rings, two
    benches sharing a ``Supi3``) was taken in silence: both rings loaded and latched its one register file and
    clock, and the second ring even told it that a device now follows it (``set_following``). Now the second ring
    refuses it by name (UP-47) and the device is left as the first ring set it."""
    chip = Supi3(default_config())
    first = Ring([chip])
    assert chip.following is False
    with pytest.raises(InterbusArgumentError, match=r"device at ring position 1 \(Supi3\) is in another live ring"):
        Ring([chip, PlainDevice(0x02, 1)])
    assert chip.following is False  # the refused ring told it nothing
    bench = Bench()
    with pytest.raises(InterbusArgumentError, match=r"device at ring position 2 \(Supi3\) is in another live ring"):
        Bench(others=[bench.chip])
    assert first.devices == [chip]


def test_a_device_of_a_dropped_ring_goes_into_a_new_one() -> None:
    """UP-47's limit: the refusal is for live rings only. A ring dropped by the test, even one held in a reference
    cycle and not yet collected, gives its devices up. A bench's chip is not free once the test drops the bench:
    its registers read the bench's clock (``use_clock``), which keeps the bench and its ring alive, so a second
    bench is still refused (it would run a chip on the first bench's clock)."""
    chip = Supi3(default_config())
    dropped = Ring([chip])
    dropped.own = dropped  # type: ignore[attr-defined]  # a reference cycle: only the collector frees it
    del dropped
    ring = Ring([chip])
    assert ring.devices == [chip]
    bench = Bench()
    chip_of_bench = bench.chip
    del bench
    with pytest.raises(InterbusArgumentError, match=r"is in another live ring"):
        Bench(others=[chip_of_bench])


def test_a_refused_ring_holds_none_of_its_devices() -> None:
    """UP-47, a call after an error: ``Ring([chip], record="yes")`` was refused after it had claimed the chip, and
    while the error was kept (a test's ``pytest.raises``, an ``except`` block) the half-made ring held it: the next
    ``Ring([chip])`` was refused as "in another live ring". Every check now comes before the claim."""
    chip = Supi3(default_config())
    with pytest.raises(ArgumentError, match="record must be True or False") as refused:
        Ring([chip], record="yes")  # type: ignore[arg-type]
    assert Ring([chip]).devices == [chip] and refused.value is not None
    pins = Supi3Pins(default_config())
    with pytest.raises(ArgumentError, match="record") as refused_pins:
        PinRing([pins], record="yes")  # type: ignore[arg-type]
    assert PinRing([pins]).devices == [pins] and refused_pins.value is not None


def test_one_chip_in_two_live_pin_level_rings_is_refused_by_name() -> None:
    """UP-49 (UP-47's limit closed): a ``Supi3Pins`` put into a second live ``PinRing`` was taken in silence, both
    rings stepping its one core and pins. Now refused by name as at transaction level; the first ring keeps it,
    and once that ring is dropped the chip goes into a new one."""
    chip = Supi3Pins(default_config())
    first = PinRing([chip])
    with pytest.raises(InterbusArgumentError, match=r"device at ring position 2 \(Supi3Pins\) is in another live "
                                                    r"ring"):  # fmt: skip
        PinRing([Supi3Pins(default_config()), chip])
    assert first.devices == [chip]
    del first
    assert PinRing([chip]).devices == [chip]


def test_a_chip_of_another_bit_rate_is_refused_by_the_ring() -> None:
    """Defect: a 500 kbit/s bench took ``others=[<a chip strapped for 2 Mbit/s>]`` and its data cycles passed: at
    transaction level the ring never looked at the chips' CLK_CONF, where the pin level's ring refuses "every device
    of a ring runs at one bit rate" (Table 1-7). Now the ring refuses it by name (UP-48), at either rate."""
    with pytest.raises(InterbusArgumentError, match=r"device at ring position 2 is strapped for 2000000 bit/s"):
        Bench(others=[Supi3(default_config(2_000_000))])
    with pytest.raises(InterbusArgumentError, match=r"device at ring position 1 is strapped for 500000 bit/s "
                                                    r"\(CLK_CONF\), not the ring's 2000000"):  # fmt: skip
        Ring([Supi3(default_config())], bit_rate=2_000_000)
    assert Ring([Supi3(default_config(2_000_000)), PlainDevice(0x02, 1)], bit_rate=2_000_000).bit_rate == 2_000_000
    # No rate given: the straps' (a 2 Mbit/s chip ran a 500 kbit/s ring before), 500 kbit/s with no strapped device.
    assert Ring([PlainDevice(0x02, 1), Supi3(default_config(2_000_000))]).bit_rate == 2_000_000
    assert Ring([PlainDevice(0x02, 1)]).bit_rate == 500_000
    with pytest.raises(InterbusArgumentError, match=r"device at ring position 3 is strapped for 500000 bit/s "
                                                    r"\(CLK_CONF\), not the ring's 2000000"):  # fmt: skip
        Ring([PlainDevice(0x02, 1), Supi3(default_config(2_000_000)), Supi3(default_config())])


class _Opening(PlainDevice):
    """A user's device model that says its data path opens (RX-13) with a given ``constant_output``."""

    sends_constant = True

    def __init__(self, level: object) -> None:
        super().__init__(0x02, 1)
        self.constant_output = level


@pytest.mark.parametrize("level", [5, -1, "x", 0.5, b"\x00"])
def test_a_constant_output_that_is_no_level_is_named(level: object) -> None:
    """Defect: a device's ``constant_output`` after a data cycle's load was taken as a level by its truth: 5, 'x' and
    0.5 sent a line of ones, b'\\x00' too (a non-empty bytes). RX-13 says the level is 0 or 1 (``None``: the frame
    shifts through); anything else is now an :class:`InterbusError` naming the device's class and the value."""
    master = Master(Ring([_Opening(level), PlainDevice(0x02, 1)]))
    master.start()
    with pytest.raises(InterbusError, match=r"_Opening.constant_output must be 0 or 1 after a data cycle's load"):
        master.cycle()


@pytest.mark.parametrize("level", [0, 1, True, np.int64(1)])
def test_a_constant_output_level_passes(level: object) -> None:
    """The levels RX-13 allows (a bool and a numpy integer too): the open device sends a constant line, so every data
    cycle fails its loopback word (RX-13), nothing raises."""
    master = Master(Ring([_Opening(level)]))
    master.start()
    assert not master.cycle().ok


# ---------------------------------------------------------------------------------------------------------------
# A model's recent events (supi3.pinlevel)
# ---------------------------------------------------------------------------------------------------------------


class _Model:
    """A user's pin-level model whose ``recent_events`` returns ``events``."""

    def __init__(self, events: object) -> None:
        self.events = events

    def recent_events(self) -> object:
        return self.events


@pytest.mark.parametrize("events", [None, 5, "cycle 3: SET written", b"ab"])
def test_recent_events_that_are_no_lines_are_named(events: object) -> None:
    """Known defect of round 13: a model whose ``recent_events()`` returned None or a number raised a bare
    TypeError inside the mismatch report (the lockstep's and cocotb's harness call it when the RTL disagrees, so
    the mismatch itself was lost); one str was printed a character a line. Now a :class:`PinSpecError` naming the
    model's class and the value (UP-48)."""
    with pytest.raises(PinSpecError, match=r"_Model.recent_events\(\) must return a sequence of str"):
        recent_events(_Model(events))


def test_recent_events_of_any_iterable_are_lines() -> None:
    """What a model may return: any iterable of events, each shown as its str; no method: no events."""
    assert recent_events(_Model(("a", 3))) == ["a", "3"]
    assert recent_events(_Model(iter(["x"]))) == ["x"]
    assert recent_events(object()) == []


# ---------------------------------------------------------------------------------------------------------------
# The firmware bench's cycle time and runs (supi3.sdk.bench)
# ---------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("cycle_time", [1e30, 2e6])
def test_bench_cycle_time_past_the_bus_time_maximum_is_refused(cycle_time: float) -> None:
    """Defect: ``Bench(cycle_time_s=1e30)`` was taken; its second cycle's start then raised inside the ring (a
    "seconds 1e+30" the user never gave) with the bench's clock already set there. A cycle time is bus time (A26,
    UP-48)."""
    with pytest.raises(ArgumentError, match=r"cycle_time_s must be a finite number from 0.0 to 1048576"):
        Bench(cycle_time_s=cycle_time)


def test_bench_run_whose_cycles_end_past_the_maximum_is_refused_and_changes_nothing() -> None:
    """Defect: on a 600,000 s cycle time the third ``run(1)`` started its cycle at 1,200,000 s: the ring refused the
    idle time by A26 after the bench had set its clock there (``bench.now`` past the maximum, ``served`` False).
    ``run`` now counts the cycle time in its check (UP-48): refused before anything runs."""
    bench = Bench(cycle_time_s=6e5)
    bench.run(1)
    bench.run(1)
    state = (bench.now, bench.cycles, bench.served, bench.ring.now)
    with pytest.raises(ArgumentError, match=r"cycles 1 at bus time 600000\.\d+ s would take it past 1048576 s"):
        bench.run(1)
    assert (bench.now, bench.cycles, bench.served, bench.ring.now) == state


@pytest.mark.parametrize("bit_rate", [500_000.0, True, "500000"])
def test_bench_config_refuses_a_bit_rate_beside_a_config_as_without_one(bit_rate: object) -> None:
    """Defect: ``Bench(bit_rate=500000.0)`` is refused (not one of Table 1-7's rates), but beside a 500 kbit/s
    config the same float passed, since it compares equal; True said "is not the config's" instead of naming the
    rule. Now the bit rate is checked first, as without a config (UP-48)."""
    with pytest.raises(ArgumentError, match=r"bit_rate must be one of 500000, 2000000 \(Table 1-7\)"):
        bench_config(default_config(), bit_rate)  # type: ignore[arg-type]


def test_bench_run_after_a_test_held_timed_run_runs_its_cycles() -> None:
    """Defect (found by the history below): ``hold_after(0)``, then ``run_for``, then ``run(1)``: the timed run stopped
    the master at the hold (its next start at infinity) and the run raised "at must be a finite number, not inf"
    with the bench's clock set to infinity, for good. A hold raised above the cycles done resumes the master first
    (FW-30), as :meth:`Bench.resume` would."""
    bench = Bench()
    bench.hold_after(0)
    bench.run_for(10e-6)
    assert bench.cycles == 0
    bench.run(1)
    assert (bench.cycles, bench.served) == (1, True)
    assert bench.now < 0.01


def test_bench_last_end_of_a_run_begun_in_the_future_is_refused() -> None:
    """Defect: ``Bench.last_end(1e300)`` answered 1e300: the end of a run's last cycle after the clock, from which the
    run's wait (the board's too) would count. A run begins at or before the clock (UP-48)."""
    bench = Bench()
    bench.run(1)
    with pytest.raises(ArgumentError, match=r"began must be a bus time up to the bench's clock"):
        bench.last_end(bench.now + 1.0)
    assert bench.last_end(bench.now) == bench.now
    assert bench.last_end(0.0) == bench.timeline[-1].end


class _Resumes(DigitalIo):
    """The digital I/O example whose service routine also controls the bench (``call``: resume or hold it)."""

    def __init__(self, call: str) -> None:
        super().__init__()
        self.call = call
        self.bench: Bench | None = None

    def isr(self, drv: Supi3Driver) -> None:
        super().isr(drv)
        assert self.bench is not None
        if self.call == "resume":
            self.bench.resume()
        else:
            self.bench.hold_after(0)


@pytest.mark.parametrize("call", ["resume", "hold_after"])
def test_bench_hold_and_resume_from_the_firmware_are_refused(call: str) -> None:
    """Defect: a service routine that called ``bench.resume()`` dropped the run's hold: ``run(2)`` ran 3 cycles and
    ended not served, in silence (``run`` and ``run_for`` were already refused from inside the firmware, FW-19). Now a
    :class:`BenchError` as for them (UP-48), and the run that raised leaves the master resumed."""
    firmware = _Resumes(call)
    bench = Bench(firmware=firmware)
    firmware.bench = bench
    with pytest.raises(BenchError, match=rf"Bench.{call}\(\) called from the firmware's isr\(\)"):
        bench.run(3)
    firmware.call, firmware.bench = call, None
    firmware.isr = DigitalIo.isr.__get__(firmware)  # type: ignore[method-assign]
    cycles, under_way = bench.cycles, bench.under_way
    bench.run(2)
    assert bench.cycles == cycles + under_way + 2


BENCH_CALLS = st.lists(st.tuples(st.sampled_from(["run", "run_for", "hold", "resume", "advance", "bad_run",
                                                  "bad_run_for", "bad_hold", "bad_advance", "bad_last_end"]),
                                 st.integers(0, 0xFFFF)), min_size=1, max_size=25)  # fmt: skip

_BAD: dict[str, Callable[[Bench, int], object]] = {
    "bad_run": lambda bench, value: bench.run((-1, 1.5, "2", 2**60)[value % 4]),  # type: ignore[arg-type]
    "bad_run_for": lambda bench, value: bench.run_for((-1e-3, math.nan, 1e30, "1")[value % 4]),  # type: ignore[arg-type]
    "bad_hold": lambda bench, value: bench.hold_after((-1, 2.0, None)[value % 3]),  # type: ignore[arg-type]
    "bad_advance": lambda bench, value: bench.advance((math.nan, math.inf, 2e6, "0")[value % 4]),  # type: ignore[arg-type]
    "bad_last_end": lambda bench, value: bench.last_end((-1.0, math.nan, bench.now + 1e-3)[value % 3]),
}


def _bench_state(bench: Bench) -> tuple[float, int, bool, bool, float, int, int]:
    return (bench.now, bench.cycles, bench.served, bench.under_way, bench.ring.now, len(bench.results),
            len(bench.timeline))  # fmt: skip


@settings(max_examples=50, deadline=None)
@given(calls=BENCH_CALLS, cycle_time=st.sampled_from([None, 300e-6, 5e-3]), bit_rate=st.sampled_from([500_000,
                                                                                                     2_000_000]))
def test_history_bench_refused_calls_change_nothing_and_a_resumed_run_runs_its_cycles(
    calls: list[tuple[str, int]], cycle_time: float | None, bit_rate: int
) -> None:  # fmt: skip
    """Over any history of runs, timed runs, holds (:meth:`Bench.hold_after`), resumes, clock steps and calls the
    bench refuses (cycles, seconds, a hold, a time or a last end of no bus time; a run past A26), in any order: each
    refused call raises an :class:`ArgumentError` and leaves the clock, the cycles, ``served``, the cycle under way,
    the ring's clock and the results as they were; a timed run under a test's hold starts no cycle past the hold;
    after a resume, ``run(n)`` finishes exactly ``n`` cycles after one left under way (MCU-76, FW-19), and the clock
    never goes back."""
    bench = Bench(bit_rate=bit_rate, cycle_time_s=cycle_time)
    bench.driver.initialize(Mode.MOTOROLA)
    bench.driver.configure(0x83, 0x01)
    hold: int | None = None
    for action, value in calls:
        before = _bench_state(bench)
        if action.startswith("bad_"):
            with pytest.raises(ArgumentError):
                _BAD[action](bench, value)
            assert _bench_state(bench) == before, action
            continue
        if action == "run":
            under_way = bench.under_way
            bench.run(value % 4)
            assert bench.cycles == before[1] + under_way + value % 4
            hold = None  # a run ends by resuming the master
        elif action == "run_for":
            bench.run_for(value % 3000 * 1e-6)
            if hold is not None:  # a cycle under way at the hold ends; none starts past it
                assert bench.cycles <= max(hold, int(before[1]) + before[3])
        elif action == "hold":
            hold = bench.cycles + value % 3
            bench.hold_after(hold)
        elif action == "resume":
            bench.resume()
            hold = None
        else:
            bench.advance(bench.now + value % 700 * 1e-6)
        assert bench.now >= before[0]
        assert bench.cycles >= before[1]
    bench.resume()
    cycles, under_way = bench.cycles, bench.under_way
    bench.run(3)
    assert bench.cycles == cycles + under_way + 3


# ---------------------------------------------------------------------------------------------------------------
# The emulated board (supi3.mcu.board, supi3.mcu.stm32, supi3.mcu.pins)
# ---------------------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def digital_io(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return digital_io_elf(tmp_path_factory.mktemp("hostile14"))


def test_board_pin_level_cycle_time_past_the_maximum_is_refused(digital_io: Path) -> None:
    """Defect: the pin-level board took ``cycle_time_s=1e30`` (its second cycle then idled the line for 1e30 s, a
    named error of the ring from inside the run); the transaction level's bench refuses it alike now (UP-48)."""
    from supi3.mcu.board import Board

    for fidelity in ("pin", "transaction"):
        with pytest.raises(ArgumentError, match=r"cycle_time_s must be a finite number from 0.0 to 1048576"):
            Board(digital_io, fidelity=fidelity, cycle_time_s=1e30)


@pytest.mark.parametrize("budget", [0, -5, "many", 1.5])
def test_board_run_with_a_bad_budget_changes_nothing(digital_io: Path, budget: object) -> None:
    """Defect: ``Board.run(1, max_instructions=0)`` was refused only inside the run, after ``served`` had been set to
    False (and the master held for the run): a refused call changed what the board reports. Now refused first."""
    from supi3.mcu.board import Board

    board = Board(digital_io)
    board.run(2)
    served, cycles, now = board.served, board.cycles, board.now
    assert served
    with pytest.raises(ArgumentError, match=r"max_instructions must be an integer >= 1"):
        board.run(1, max_instructions=budget)  # type: ignore[arg-type]
    assert (board.served, board.cycles, board.now) == (served, cycles, now)
    board.run(1)
    assert board.cycles == cycles + 1


def _board_view(board: object) -> tuple[object, ...]:
    """What a run of the board shows: its cycles and clocks, the core's cycles, instructions and active exceptions,
    the interrupts and their latency, whether it served, the master's inputs."""
    from supi3.mcu.board import Board

    assert isinstance(board, Board)
    core = board.core
    return (board.cycles, board.now, core.cycles, core.instructions, tuple(core.active), board.interrupts,
            board.irq_latency_s, board.served, board.master.inputs(1) if board.master.config else None)  # fmt: skip


BOARD_STEPS = st.lists(st.tuples(st.sampled_from(["run", "run_for", "switch"]), st.integers(0, 0xFFFF)), min_size=1,
                       max_size=8)  # fmt: skip


@settings(max_examples=12, deadline=None)
@given(steps=BOARD_STEPS, switches=st.lists(st.booleans(), min_size=1, max_size=16))
def test_history_native_exceptions_switched_between_and_inside_runs_change_nothing(
    digital_io: Path, steps: list[tuple[str, int]], switches: list[bool]
) -> None:  # fmt: skip
    """Over any history of board runs and timed runs, with ``CortexM.native_exceptions`` switched between runs and,
    inside them, at exception entries (the entry on one path, its return on the other): the board shows what a board
    whose switch is never touched shows after each step (MCU-70, MCU-71: "the same registers, frames, cycles and
    reports either way")."""
    from supi3.mcu.board import Board

    reference, board = Board(digital_io), Board(digital_io)
    entered = board.core.entered
    turns = iter(switches * 64)

    def entered_and_switch(number: int) -> None:
        board.core.native_exceptions = next(turns, True)
        entered(number)

    board.core.entered = entered_and_switch
    for action, value in steps:
        if action == "switch":
            board.core.native_exceptions = not board.core.native_exceptions
            continue
        for each in (reference, board):
            if action == "run":
                each.run(1 + value % 3)
            else:
                each.run_for(value % 3000 * 1e-6)
        assert _board_view(board) == _board_view(reference)


BAD_EXTI: list[tuple[tuple[object, object, object], str]] = [
    ((0, -1, 1), r"pin must be an integer from 0 to 15"),
    ((0, "a", 1), r"pin must be an integer from 0 to 15"),
    ((0, 16, 1), r"pin must be an integer from 0 to 15"),
    ((7, 0, 1), r"port must be an integer from 0 to 6 \(GPIOA to GPIOG"),
    ((0, 0, 2), r"level must be an integer from 0 to 1, not 2"),
    ((0, 0, -1), r"level must be an integer from 0 to 1, not -1"),
    ((0, 0, "1"), r"level must be an integer from 0 to 1"),
]


@pytest.mark.parametrize(("args", "match"), BAD_EXTI, ids=[str(args) for args, _ in BAD_EXTI])
def test_exti_edges_of_no_pin_or_level_are_named(args: tuple[object, object, object], match: str) -> None:
    """Defect: ``Exti.triggers(0, -1, 1)`` raised "negative shift count", a pin 'a' a TypeError, and a level 2 or -1
    counted as a rising edge (setting PR on RTSR); ``Exti.edge`` alike. Now an ``ArgumentError`` naming the
    argument, PR untouched."""
    exti = Exti(Rcc())
    exti.rtsr = exti.ftsr = exti.imr = 0xF
    with pytest.raises(ArgumentError, match=match):
        exti.triggers(*args)  # type: ignore[arg-type]
    with pytest.raises(ArgumentError, match=match):
        exti.edge(*args)  # type: ignore[arg-type]
    assert exti.pr == 0
    exti.edge(0, 0, 1)
    assert exti.pr == 1


@pytest.mark.parametrize(("cycles", "cpu_hz", "match"), [(10, 0.0, r"cpu_hz must be a core clock above 0 Hz"),
                                                         (10, math.nan, r"cpu_hz must be a finite number"),
                                                         (-1, 48e6, r"cycles must be an integer >= 0, not -1"),
                                                         (1.5, 48e6, r"cycles must be an integer >= 0")])  # fmt: skip
def test_chip_clock_of_no_core_cycle_or_clock_is_named(cycles: object, cpu_hz: object, match: str) -> None:
    """Defect: ``chip_clock(10, 0)`` divided by zero and ``chip_clock(-1, 48e6)`` answered clock 0, before the chip's
    first (a pin change at no cycle of the core)."""
    with pytest.raises(ArgumentError, match=match):
        chip_clock(cycles, cpu_hz)  # type: ignore[arg-type]
    assert chip_clock(0, 48e6) == 1
    assert chip_clock(3, 48e6) == 3  # 3 cycles at 48 MHz: 2 chip clocks at 32 MHz have begun, the third runs


@pytest.mark.parametrize(("args", "match"), [((0x00, 8, 9, False), r"sampled must be an integer from 0 to 8"),
                                             ((0x00, 8, 9, True), r"sampled must be an integer from 0 to 8"),
                                             ((0x00, 8, -1, False), r"sampled must be an integer from 0 to 8"),
                                             ((0x100, 8, 4, False), r"word must be an integer from 0 to 255"),
                                             ((0x00, 9, 4, False), r"bits must be one of 8, 16"),
                                             ((0x00, 8, 4, 1), r"lsb_first must be True or False")])  # fmt: skip
def test_released_of_no_transfer_is_named(args: tuple[object, ...], match: str) -> None:
    """Defect: ``released(0, 8, 9, False)`` raised "negative shift count", LSB first it gave -256 (a negative word
    for SPI1's data register), and ``sampled`` -1 gave 511, nine bits of an 8-bit transfer."""
    with pytest.raises(ArgumentError, match=match):
        released(*args)  # type: ignore[arg-type]
    assert released(0x00, 8, 6, False) == 0x03  # MSB first: the last two bits sampled read MISO's pull-up
    assert released(0x00, 8, 6, True) == 0xC0


def test_spi_replace_received_outside_a_transfer_is_named() -> None:
    """Defect: ``Spi.replace_received`` outside a transfer failed an ``assert`` (a bare AssertionError; under
    ``python -O`` a TypeError deeper), and took a word of any size. Now an ``ArgumentError`` naming the call."""
    spi = Spi(Rcc(), lambda: 0, None)  # type: ignore[arg-type]  # no wire: no transfer can start
    with pytest.raises(ArgumentError, match=r"Spi.replace_received's transfer must be a transaction-level transfer"):
        spi.replace_received(0x12)
    with pytest.raises(ArgumentError, match=r"word must be an integer from 0 to 65535"):
        spi.replace_received(0x10000)


# ---------------------------------------------------------------------------------------------------------------
# The spidev transport's answers (supi3.sdk.transports)
# ---------------------------------------------------------------------------------------------------------------


class _FakeSpidev:
    """A stand-in for the ``spidev`` module whose device answers ``answer`` to every transfer."""

    answer: object = [0x00]

    class SpiDev:
        def open(self, bus: int, device: int) -> None:
            del bus, device

        def xfer(self, data: list[int]) -> object:
            del data
            return _FakeSpidev.answer

        def close(self) -> None:
            pass


@pytest.mark.parametrize("answer", [[3.5], [255.9], ["A"], [1, 2], [], 7, None])
def test_spidev_answer_that_is_no_byte_is_a_transport_error(answer: object) -> None:
    """Defect: ``SpidevTransport.xfer`` converted the controller's answer with ``int()``: 3.5 read as register value
    3 and 255.9 as 255 (the driver's byte check then passed), 'A' raised ValueError, and an answer of two bytes or
    none a ValueError of the unpacking, which the driver passed on raw. Now a :class:`TransportError` (the driver
    forgets its initialization, as for any transport failure)."""
    transport = SpidevTransport(0, 0, spidev_module=_FakeSpidev)
    drv = Supi3Driver(transport)
    _FakeSpidev.answer = answer
    try:
        with pytest.raises(TransportError, match=r"returned .*, not (a byte 0 to 255|one byte for the one sent)"):
            drv.initialize(Mode.MOTOROLA)
    finally:
        _FakeSpidev.answer = [0x00]
    assert not drv.initialized


@pytest.mark.parametrize("level", [np.True_, np.False_])
def test_spidev_pin_read_as_numpy_bool_is_a_level(level: object) -> None:
    """Defect: a GPIO callable that reads its level from a numpy array gives ``np.True_``; ``pin_level`` (whose
    docstring lets a bool and a numpy integer pass) refused it as "np.True_ (bool), not 0, 1 or None"."""
    transport = SpidevTransport(0, 0, spidev_module=_FakeSpidev, read_cd=lambda: level)  # type: ignore[arg-type,return-value]
    assert transport.read_cd() == int(bool(level))

"""Chips that took no INTERBUS reset since their power-up, at both fidelities (M19, M20 of
docs/assumptions/model.md; manual 1.7.2, 3.4.7): a flat ring of RB chips powered up, cut and repaired, with a master
that starts (an INTERBUS reset) or not, gives the master the same view of every cycle at pin level
(supi3.model.pinring.PinRing) as at transaction level (supi3.interbus.ring.Ring). Before M19 and M20 a chip that woke
up inside a telegram (its reset stretch ends mid-telegram, M2) took the misread telegram as a frame's head and kept
that frame open through the status telegrams after it, so the master's next frame ran on in it: the discovery ID cycle
without a reset before it failed at pin level (CRC, TELEGRAM) and passed at transaction level. The same held for the
chips behind a chip powered up in a running ring (their line resumes mid-telegram). The RTL core follows in lockstep.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from supi3 import tables
from supi3.config import DeviceConfig, decode
from supi3.errors import ArgumentError
from supi3.interbus import wire
from supi3.interbus.master import CycleResult, Master
from supi3.interbus.ring import ErrorKind, Ring
from supi3.interbus.wake import reset_ready, wake_return, wake_window
from supi3.interbus.wire import Cycle
from supi3.model.chip import Supi3
from supi3.model.pinring import PinRing
from supi3.model.pins import Supi3Pins
from supi3.verif import Lockstep
from support import IDLE, REPAIR_IDLE_TELEGRAMS, CoreScript, frame_levels, quiet_inputs
from test_model_pinring_tree import view

RB = next(row for row in tables.MODE_ROWS if row.function == "RB, 8 IN/8 OUT")
RATES = [500_000, 2_000_000]
POWER_DOWN_TELEGRAMS = 4
"""Idle status telegrams a power-up step holds the chip's /ResU low (its reset source, 1.7.2)."""
PAST_WINDOW_TELEGRAMS = 8
"""Idle status telegrams past M22's window after a power-up (at most 7: four chips, 2 Mbit/s, all at once)."""


def _config(rate: int) -> DeviceConfig:
    return decode(RB.c, RB.mfp, clk_conf=tables.clk_conf_for(rate))


def idle(ring: Ring | PinRing, telegrams: int) -> None:
    ring.idle(telegrams * wire.STATUS_TELEGRAM_BITS / ring.bit_rate)


Op = tuple[str, int]


def history(ring: Ring | PinRing, start: bool, ops: list[Op], wake: int, phase: int = 0) -> list[object]:
    """What a master sees of the flat ``ring`` (fresh chips, powered up together, then idle past their wake-up) over
    ``ops``: the master starts first (``start``: an INTERBUS reset and a discovery ID cycle) or not; then per step
    ``power`` (the chip at ring position ``k`` powered up: /ResU low at pin level, ``Supi3.power_up`` at transaction
    level, then idle), ``cut`` (the forward line into position ``k``), ``repair`` (every cut, then
    :data:`~support.REPAIR_IDLE_TELEGRAMS` idle status telegrams, M21), ``start`` or ``wait``, and two of the master's
    cycles. Every cycle's kind, success and diagnostics (kind, location, device, message code), after each step the
    configuration and IN data. ``wake``: idle status telegrams after a power-up (M22); ``phase``: bit periods into an
    idle status telegram at which a power-up releases /ResU (:func:`power_cycle`)."""
    idle(ring, wake)
    master = Master(ring, locate=False, max_devices=8)
    seen: list[object] = []

    def record(result: CycleResult) -> None:
        seen.append((result.cycle, result.ok, [(d.kind, d.location, d.device, d.code) for d in result.diagnostics]))

    if start:
        record(master.start())
    for op, k in ops:
        k = min(k, len(ring.devices))
        if op == "power":
            power_cycle(ring, k, phase)
            idle(ring, wake)
        elif op == "cut":
            ring.cut(k, True)
        elif op == "repair":
            if isinstance(ring, PinRing):
                ring.cuts.clear()
            else:
                ring.clear_faults()
            idle(ring, REPAIR_IDLE_TELEGRAMS)
        elif op == "start":
            record(master.start())
        for _ in range(2):
            record(master.cycle())
        seen.append(view(master) if master.config is not None else None)
    return seen


def both(rate: int, chips: int, start: bool, ops: list[Op], wake: int,
         phase: int = 0) -> tuple[list[object], list[object]]:
    config = _config(rate)
    tl_chips = [Supi3(config) for _ in range(chips)]
    tl = Ring(tl_chips, bit_rate=rate)
    for position in range(1, chips + 1):  # powered up at the first clock, as the pin level's fresh chips (M22)
        tl.power_up(position)
    pin = PinRing([Supi3Pins(config) for _ in range(chips)])
    for position, chip in enumerate(tl_chips, 1):  # the process data IN: each chip's MFP inputs
        chip.set_mfp_inputs(0x11 * position)
        pin.set_input(position, "mfp_in", 0x11 * position)
    return history(tl, start, ops, wake, phase), history(pin, start, ops, wake, phase)


OPS = st.lists(st.tuples(st.sampled_from(["power", "cut", "repair", "start", "wait"]), st.integers(1, 4)),
               min_size=1, max_size=4)  # fmt: skip


@settings(max_examples=12, deadline=None, derandomize=True)  # about 1 s an example: pin level is slow
@given(st.sampled_from(RATES), st.integers(1, 4), st.booleans(), OPS, st.integers(0, 7))
@example(2_000_000, 4, False, [("wait", 1)], 0)  # the master's first cycle() without start(): failed before M19
@example(2_000_000, 4, False, [("cut", 3), ("start", 1), ("repair", 1)], 0)  # the RB cut before start, repaired
@example(2_000_000, 3, True, [("power", 1), ("wait", 1)], 0)  # the chips behind a woken one: failed before M20
@example(500_000, 2, False, [("power", 2), ("cut", 1), ("repair", 1), ("power", 1)], 0)
@example(500_000, 4, False, [("wait", 1)], 4)  # the master's receiver is the last on the grid (M22: 5 telegrams)
@example(2_000_000, 4, False, [("power", 3), ("wait", 1)], 4)  # a chip behind others woken: 5 telegrams
@example(2_000_000, 4, False, [("power", 4), ("wait", 1)], 0)  # chips off the grid pass the discovery frame on
@example(2_000_000, 1, True, [("cut", 1)], 1)  # the start's hold meets the chip off the grid: it misses the discovery
def test_a_master_sees_every_cycle_alike_after_power_ups(rate: int, chips: int, start: bool, ops: list[Op],
                                                         wake: int) -> None:
    """M19, M20, M22: over any history of power-ups of any chips, cuts, repairs, starts or none, with ``wake`` idle
    status telegrams after each power-up (0 to 7: M22's window is up to 7), the master's every cycle (kind, success,
    diagnostics) and its configuration and IN data after each step are the same at both fidelities."""
    tl, pin = both(rate, chips, start, ops, wake)
    assert tl == pin


@pytest.mark.parametrize("rate", RATES)
def test_a_frame_that_meets_the_reset_stretch_fails_at_pin_level(rate: int) -> None:
    """M19's window: a master's first cycle at the chips' power-up meets their reset stretch (M2), and the chip
    that wakes inside the frame takes no part in it (no frame before a whole status telegram): the cycle fails at pin
    level, the next passes; so at transaction level after ``Ring.power_up`` (M22), and a ring whose chips were not
    powered up by it (ready at once) passes it."""
    ring = PinRing([Supi3Pins(_config(rate))])
    master = Master(ring, locate=False, max_devices=8)
    assert not master.cycle().ok
    assert master.cycle().ok
    assert Master(Ring([Supi3(_config(rate))], bit_rate=rate), locate=False, max_devices=8).cycle().ok
    tl = Ring([Supi3(_config(rate))], bit_rate=rate)
    tl.power_up(1)
    master = Master(tl, locate=False, max_devices=8)
    assert not master.cycle().ok
    assert master.cycle().ok


def power_cycle(ring: Ring | PinRing, position: int, phase: int = 0) -> None:
    """Power the chip at physical ``position`` down for :data:`POWER_DOWN_TELEGRAMS` idle status telegrams and up
    again: /ResU low then high at pin level, ``Ring.power_up`` at the transaction level (M22; trees too, M25). With
    ``phase`` (1 to 4) /ResU rises that many bit periods into a further idle status telegram, sent whole (M22's limit 4:
    a power-up off the master's telegram boundaries; the pin level's master receives that telegram on its own, as
    :meth:`PinRing.idle` receives its pieces)."""
    if isinstance(ring, PinRing):
        ring.set_input(position, "resu_n", 0)
        idle(ring, POWER_DOWN_TELEGRAMS)
        levels = wire.status_levels(Cycle.DATA, False, 1)
        if phase:
            ring.run_levels(levels[:phase])
        ring.set_input(position, "resu_n", 1)
        if phase:
            ring.run_levels(levels[phase:])
            ring._received()  # the idle received on its own (PinRing.idle's pieces)
    else:
        idle(ring, POWER_DOWN_TELEGRAMS)
        ring.idle(phase / ring.bit_rate)
        ring.power_up(position)
        ring.idle((wire.STATUS_TELEGRAM_BITS - phase) / ring.bit_rate if phase else 0.0)


def first_cycle(ring: Ring | PinRing, chips: int, position: int,
                telegrams: int) -> tuple[Cycle, bool, list[ErrorKind]]:
    """The master's cycle ``telegrams`` idle status telegrams after the power-up of ``position`` (0: every chip, at the
    ring's first clock; else one chip of a running ring, /ResU low for 4 idle status telegrams): its kind, success and
    error kinds (``bench/wake_flat_sweep.py window``)."""
    if position:
        idle(ring, PAST_WINDOW_TELEGRAMS)
        master = Master(ring, locate=False, max_devices=8)
        assert master.cycle().ok
        power_cycle(ring, position)
    else:
        if isinstance(ring, Ring):
            for k in range(1, chips + 1):
                ring.power_up(k)
        master = Master(ring, locate=False, max_devices=8)
    idle(ring, telegrams)
    result = master.cycle()
    return result.cycle, result.ok, [d.kind for d in result.diagnostics]


@pytest.mark.parametrize("rate", RATES)
def test_the_window_after_a_power_up_ends_alike(rate: int) -> None:
    """M22, exhaustively over flat rings of 1 to 4 chips, every chip at once at the first clock or any one chip of a
    running ring: the master's first cycle that passes after the power-up is the same at both fidelities (the last
    that fails before it too); the window is 1 to 7 idle status telegrams."""
    windows = []
    for chips in range(1, 5):
        for position in range(chips + 1):
            first = next(k for k in range(10) if first_cycle(Ring([Supi3(_config(rate)) for _ in range(chips)],
                                                                   bit_rate=rate), chips, position, k)[1])
            for k in (first - 1, first):
                pin = PinRing([Supi3Pins(_config(rate)) for _ in range(chips)])
                assert k < 0 or first_cycle(pin, chips, position, k)[1] is (k == first), (chips, position, k)
            windows.append(first)
    assert max(windows) == (5 if rate == 500_000 else 7)
    assert min(windows) == 1


@pytest.mark.parametrize("rate", RATES)
def test_every_single_power_up_of_a_flat_ring_fails_alike(rate: int) -> None:
    """M22, issue #12: every single power-up of a flat ring (1 to 3 chips, any chip, the master started or not, 0 to
    7 idle status telegrams after the power-up) gives the master the same cycles at both fidelities, each failing one
    with the same error kind. Found in round 7 (``test_hostile7``): 9 of these 96 at 2 Mbit/s failed with ``TELEGRAM``
    at transaction level where the pin level's master, whose receiver assembles no frame from what came back (the
    woken chip's check sequence otherwise than the master's, M22), reports a dead line."""
    kinds = set()
    for chips in range(1, 4):
        for position in range(1, chips + 1):
            for start in (False, True):
                for wake in range(8):
                    tl, pin = both(rate, chips, start, [("power", position)], wake)
                    assert tl == pin, (chips, position, start, wake)
                    # a cycle's record is (kind, success, diagnostics); a step's view is (configuration, IN data)
                    kinds |= {d[0] for seen in tl if isinstance(seen, tuple) and len(seen) == 3 for d in seen[2]}
    if rate == 2_000_000:
        assert {ErrorKind.DEAD_LINE, ErrorKind.TELEGRAM} <= kinds


def _start_after(ring: Ring | PinRing, chips: int, telegrams: int) -> tuple[bool, int, bool]:
    """Every chip powered up at the ring's first clock, ``telegrams`` idle status telegrams, then the master's start
    and a data cycle: the start's success, the devices it found, the data cycle's success."""
    if isinstance(ring, Ring):
        for k in range(1, chips + 1):
            ring.power_up(k)
    idle(ring, telegrams)
    master = Master(ring, locate=False, max_devices=8)
    started = master.start().ok
    return started, len(master.config or ()), master.cycle().ok


def test_a_chip_woken_in_the_reset_s_hold_ends_it_alike() -> None:
    """M22 (``reset_ready``): a start right after the power-up, its hold meeting chips off the telegram grid (their
    receivers read the hold as status telegrams, M16, and find the grid after it late): the discovery and the data
    cycle after it alike at both fidelities, 1 to 4 chips, both bit rates, 0 to 2 idle telegrams before the start;
    one chip at 2 Mbit/s started after 1 telegram ends its reset after the discovery (found with no device)."""
    seen = {}
    for rate in RATES:
        for chips in range(1, 5):
            for telegrams in range(3):
                tl = _start_after(Ring([Supi3(_config(rate)) for _ in range(chips)], bit_rate=rate), chips, telegrams)
                pin = _start_after(PinRing([Supi3Pins(_config(rate)) for _ in range(chips)]), chips, telegrams)
                assert tl == pin, (rate, chips, telegrams)
                seen[rate, chips, telegrams] = tl
    assert seen[2_000_000, 1, 1] == (True, 0, False)


def test_a_power_up_names_the_chip_it_takes() -> None:
    """M22's entries refuse bad input with the rule and the value."""
    ring = Ring([Supi3(_config(500_000))], bit_rate=500_000)
    with pytest.raises(ArgumentError, match="position"):
        ring.power_up(2)
    with pytest.raises(ArgumentError, match="wakes"):
        wake_window(500_000, 1, {1: 0})
    with pytest.raises(ArgumentError, match="bit"):
        wake_window(1_000_000, 1, {})
    with pytest.raises(ArgumentError, match="start"):
        reset_ready(500_000, 1, {0: 128}, 0.5)  # type: ignore[arg-type]
    with pytest.raises(ArgumentError, match="frame"):
        wake_return(500_000, 1, {0: 128}, 0, b"\x00")  # type: ignore[arg-type]


def test_a_status_telegram_ends_a_frame() -> None:
    """M20: a status telegram inside a frame ends it at once, discarded with a local error (TE, Table 3-13), and
    the next data telegram begins a new frame: the chip loads its register again (before M20 the frame ran on, the
    next frame's telegrams in it)."""
    chip = Supi3Pins(_config(2_000_000))
    levels = frame_levels(Cycle.ID, b"\x00\x00")
    cut = wire.DATA_TELEGRAM_BITS * 2  # the loopback word, then a status telegram where the data would follow
    do1 = wire.levels_to_samples(np.concatenate(
        [IDLE, wire.reset_levels(1), IDLE, levels[:cut], IDLE[: wire.STATUS_TELEGRAM_BITS], levels, IDLE]), 2_000_000)
    chip.run(quiet_inputs(len(do1)) | {"do1": do1.astype(np.int64)})
    log = chip.log.recent()
    assert sum("id cycle: load" in entry for entry in log) == 2
    assert any("status telegram inside a frame" in entry for entry in log)
    assert chip.chip.te is False  # the second ID cycle latched: TE cleared (A21)
    assert any("id cycle latched" in entry for entry in log)


def test_the_rtl_core_follows_power_ups_without_reset(core_bench: Lockstep) -> None:
    """M19, M20 in the RTL core, every pin every clock: power-ups whose stretch ends inside a telegram (status
    telegrams, a frame), frames without an INTERBUS reset before them, a status telegram inside a frame."""
    config = decode("10000", None, clk_conf="11")
    script = CoreScript(config, np.random.default_rng(19))
    script.line(IDLE).id_cycle(wire.command_word()).data_cycle()
    for hold in (1, 37, 150):  # /ResU low, then the stretch ends at another bit of the telegrams
        script.line(np.ones(2, dtype=np.uint8), resu_n=0).line(IDLE[: hold % wire.STATUS_TELEGRAM_BITS + 1])
        script.line(IDLE, resu_n=1).id_cycle(wire.command_word()).data_cycle()
    levels = frame_levels(Cycle.DATA, b"\x5a")
    script.line(levels[: wire.DATA_TELEGRAM_BITS]).line(IDLE).data_cycle()
    script.line(np.ones(2, dtype=np.uint8), resu_n=0).line(IDLE, resu_n=1)
    script.line(levels[:5]).line(IDLE).id_cycle(wire.command_word()).data_cycle()  # woken inside a frame
    core_bench.run_batch(script.stimulus())

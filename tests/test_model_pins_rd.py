"""RD, the outgoing interface switched off (DIAG2 with complete diagnostics, manual 3.6.1 Tables 3-16 and 3-19; DG-5),
and counter telegrams at the frame engine and the idle time-out (LBD modes, 2.2.2, Table 3-18's 4 Hz; BK-36, DG-9), at
pin level (``Supi3Pins``: ``step()`` and ``run()`` alike, a ``PinRing``) and at transaction level (the LED view, a
``Ring`` with a break)."""

from __future__ import annotations

import numpy as np
import pytest

from supi3 import tables
from supi3.config import DeviceConfig, Interface, decode
from supi3.diagnostics import IbDiag, diag_pins, diagnostic_outputs, is_complete, remote_bus_disabled
from supi3.errors import ArgumentError
from supi3.interbus import wire
from supi3.interbus.master import Master
from supi3.interbus.ring import Branch, BranchKind, DeadLine, Ring
from supi3.interbus.wire import Cycle
from supi3.model.chip import ChipArgumentError, Supi3
from supi3.model.pinring import PinRing
from supi3.model.pins import IDLE_TIMEOUT_CLOCKS, SYNC_STAGES, Supi3Pins
from support import (
    Columns,
    CoreScript,
    assert_run_matches_step,
    counter_levels,
    counters_in_reset,
    quiet_inputs,
    terminal,
)

FAST = tables.clk_conf_for(2_000_000)
PHASE = 300
"""Clocks of each phase of the RD scenario (more than the reset stretch of 128)."""


def _rd_inputs(rbst_by_pin: bool) -> Columns:
    """A following device appears (DI2 high, or RBST_EXT with RF = 10) after one phase and goes away after two."""
    inputs = {name: np.concatenate([trace] * 3) for name, trace in quiet_inputs(PHASE).items()}
    inputs["rbst_ext" if rbst_by_pin else "di2"][PHASE : 2 * PHASE] = 1
    return inputs


def _expected_rd(rbst_by_pin: bool) -> np.ndarray:
    """RD over :func:`_rd_inputs`: lit until the change shows (the synchroniser's stages, then the clock edge: the
    outputs of the cycle after it), then off; with RF = 10 it follows RBST_EXT back, else the recognition stays."""
    rd = np.ones(3 * PHASE, dtype=np.int64)
    shown = SYNC_STAGES + 1
    rd[PHASE + shown : 2 * PHASE + shown if rbst_by_pin else None] = 0
    return rd


@pytest.mark.parametrize("rf", ["11", "10"])
@pytest.mark.parametrize("diag_conf", [0, 1])
def test_rd_in_every_mode_row(diag_conf: int, rf: str) -> None:
    # Table 3-16 x every mode row of Tables 2-4 to 2-7: DIAG2 is RD (complete) or FO2 (limited, unlit: no optics with
    # RF = 11 or 10); RD is lit exactly while no following device is recognised (DG-5), and the transaction-level LED
    # view told the same recognition shows the same.
    rbst_by_pin = rf == "10"
    inputs = _rd_inputs(rbst_by_pin)
    rd = _expected_rd(rbst_by_pin)
    for row in tables.MODE_ROWS:
        config = decode(row.c, row.mfp, rf=rf, diag_conf=diag_conf)
        pins = Supi3Pins(config)
        out = pins.run(inputs)
        want = rd if is_complete(config) else np.zeros_like(rd)
        assert np.array_equal(out["diag2"], want), (row.function, np.flatnonzero(out["diag2"] != want)[:3])
        tl = Supi3(config)
        for following in (False, True):
            tl.set_following(following)
            view = tl.diagnostic_outputs
            assert view.rd == remote_bus_disabled(following) == (not following)
            assert view.diag2 == (int(not following) if diag_conf == 0 else 0)
        tl.set_following(pins.chip.following)
        assert tl.diagnostic_outputs.diag2 == int(out["diag2"][-1]) == pins.output_values(pins.cycle, 0)["diag2"]


@pytest.mark.parametrize("rf", ["11", "10"])
@pytest.mark.parametrize("c", ["10000", "11000", "00000"])
def test_rd_step_equals_run(c: str, rf: str) -> None:
    # The recognition is a register set at the clock edge: step() shows it from the next cycle, run() completes DIAG2
    # in its return-line pass; both agree cycle for cycle, through run pieces cut anywhere.
    config = decode(c, rf=rf, diag_conf=0)
    inputs = _rd_inputs(rf == "10")
    out = assert_run_matches_step(Supi3Pins(config), Supi3Pins(config), inputs, [0.2, 0.45, 0.75])
    assert np.array_equal(out["diag2"], _expected_rd(rf == "10"))


def test_rd_spec_table() -> None:
    # Table 3-16 with the RD of DG-5, every combination.
    for complete in (False, True):
        for following in (False, True):
            for fo2 in (False, True):
                rd = remote_bus_disabled(following)
                assert diag_pins(complete, True, rd, False, fo2)[1] == int(rd if complete else fo2)
    config = decode("10000", diag_conf=0)
    view = diagnostic_outputs(config, supply_ok=True, line_heard=True, bus_active=True, peripheral_fault=False,
                              line_interrupt=False, following=True, leds=Supi3(config).led_inputs)  # fmt: skip
    assert (view.rd, view.diag2) == (False, 0)


def test_bad_following_is_named() -> None:
    with pytest.raises(ChipArgumentError, match="present must be True or False"):
        Supi3(decode("10000")).set_following(1)  # type: ignore[arg-type]
    with pytest.raises(ArgumentError, match="following must be True or False"):
        remote_bus_disabled(None)  # type: ignore[arg-type]


def test_a_pin_ring_shows_rd_on_its_last_chip_only() -> None:
    # The last chip's DI2 carries nothing (no following device): it closes the ring and lights RD; every other chip
    # sees its neighbour's idle return line. The recording has RD too (run_forward's DIAG2 completed by return_line).
    config = decode("10000", clk_conf=FAST, diag_conf=0)
    ring = PinRing([Supi3Pins(config) for _ in range(3)], record=True)
    ring.run_levels(wire.status_levels(Cycle.DATA, False, 20))
    assert [chip.chip.following for chip in ring.devices] == [True, True, False]
    assert [int(pins["diag2"][-1]) for pins in ring.recorded()] == [0, 0, 1]



def test_a_ring_tells_each_chip_whether_a_device_follows() -> None:
    # The transaction-level ring tells its chips what the pin level's DI2 shows (DG-5): RD on the last of the ring
    # and the last of each branch only; a BK's outgoing remote bus is followed by what comes after its branch, and
    # switching its branch off changes no wiring.
    config = decode("10000", diag_conf=0)
    plain = [Supi3(config) for _ in range(3)]
    bk, last_bk = terminal("BK-LB"), terminal("BK-LB")
    b1, b2, b3 = (Supi3(decode("01000", diag_conf=0)) for _ in range(3))
    ring = Ring([plain[0], Branch(bk, [b1, b2], BranchKind.LOCAL), plain[1], Branch(last_bk, [b3], BranchKind.LOCAL)])
    expected = {plain[0]: False, bk: False, b1: False, b2: True, plain[1]: False, last_bk: True, b3: True}
    assert {chip: chip.diagnostic_outputs.rd for chip in expected} == expected
    Master(ring, locate=False).start()
    bk.set_mfp_inputs(0)  # LBST = 0: the branch switched off (Table 2-9)
    ring.idle(0.01)
    assert {chip: chip.diagnostic_outputs.rd for chip in expected} == expected
    alone = Ring([plain[2]])
    assert alone.devices[0].diagnostic_outputs.rd  # type: ignore[attr-defined]


# Counter telegrams (BK-36, DG-9) --------------------------------------------------------------------------------------


def _lbd(interface: Interface) -> DeviceConfig:
    row = next(r for r in tables.MODE_ROWS if r.function == f"{interface.value}, 8 IN/8 OUT")
    return decode(row.c, row.mfp, clk_conf=FAST, diag_conf=0)


def _local_errors(config: DeviceConfig, counters: bool) -> tuple[list[str], Supi3Pins]:
    """The local errors logged over two data cycles with, if ``counters``, counter telegrams between them."""
    script = CoreScript(config, np.random.default_rng(5)).bring_up().data_cycle()
    if counters:
        script.line(np.tile(counter_levels(3, 33), 3))
    pins = Supi3Pins(config)
    pins.run(script.data_cycle().columns())
    return [line for line in pins.log.recent() if "local error" in line], pins


@pytest.mark.parametrize("interface", [Interface.LBD_MR, Interface.LBD_OR, Interface.LB_MR])
def test_counter_telegrams_are_no_local_error(interface: Interface) -> None:
    # Between frames an ID check telegram is a counter telegram in the LBD modes: no logged local error, no frame; the
    # data cycle after them latches. LB-MR (no counter telegrams) keeps the rule of an ID check telegram out of place.
    config = decode("01000", clk_conf=FAST, diag_conf=0) if interface is Interface.LB_MR else _lbd(interface)
    errors, pins = _local_errors(config, True)
    baseline, _ = _local_errors(config, False)  # the bring-up's own (its first telegram cut by the start level)
    assert len(errors) - len(baseline) == (1 if interface is Interface.LB_MR else 0), errors
    assert pins.chip.events["VALID"] == 2


def _silence_after_counters(config: DeviceConfig, counters: bool) -> tuple[Supi3Pins, Columns]:
    """A latched data cycle, then the line silent or carrying counter telegrams (count 4) beyond the idle time-out."""
    cpb = wire.clocks_per_bit(config.bit_rate)
    script = CoreScript(config, np.random.default_rng(6)).bring_up().data_cycle()
    periods = IDLE_TIMEOUT_CLOCKS // cpb + 200
    tail = np.tile(counter_levels(4, 33), periods // 33 + 1) if counters else np.ones(periods, dtype=np.uint8)
    script.line(tail)
    pins = Supi3Pins(config)
    return pins, pins.run(script.columns())


@pytest.mark.slow
def test_only_the_chip_at_the_break_shows_the_line_interrupt() -> None:
    # DG-9: a silent input times out with the 4 Hz cause; counter telegrams do not restart the 20 ms, the chip resets
    # (bus not active: 0.5 Hz) but shows no line interrupt, the break being further ahead.
    config = _lbd(Interface.LBD_OR)
    for counters, shown in ((False, IbDiag.VERY_FAST), (True, IbDiag.SLOW)):
        pins, out = _silence_after_counters(config, counters)
        chip = pins.chip
        assert chip.line_silent and not chip.bus_active, counters
        assert chip.line_interrupt is (not counters)
        assert chip.diagnostic_outputs.ib_diag is shown
        assert int(out["res_reg_n"][-1]) == 0  # RC off: the time-out came (DG-4)


def test_counter_telegrams_in_an_interbus_reset_do_not_restart_the_idle_timeout() -> None:
    # DG-9 in an INTERBUS reset: the line held at start level (A12), then only counter telegrams, no status telegram
    # to end the reset: the 20 ms run from the last telegram start in the held line, the chip times out (RC off) with
    # no line interrupt ahead (counted). Before, the receiver took a counter telegram in reset for another telegram.
    config = _lbd(Interface.LBD_OR)
    script, start = counters_in_reset(config, np.random.default_rng(7))
    pins = Supi3Pins(config)
    out = pins.run(script.columns())
    low = np.flatnonzero(out["res_reg_n"][start:] == 0)
    assert low.size and low[0] <= IDLE_TIMEOUT_CLOCKS
    assert pins.chip.line_silent and not pins.chip.line_interrupt and not pins.chip.bus_active
    assert "idle timeout: INTERBUS reset" in pins.log.recent()[-1]


def test_a_ring_reset_with_a_break_times_out_the_chips_behind_it_counted() -> None:
    # DG-9 at transaction level: an Alarm Stop whose reset pattern stops at a break reaches no chip behind it; those
    # hear nothing (the chip directly behind: 4 Hz) or the counter telegrams of an LBD chip before them (no line
    # interrupt), and all of them reset after the 20 ms from the reset's start.
    chips = [Supi3(_lbd(Interface.LBD_OR)) for _ in range(3)]
    ring = Ring(chips, bit_rate=2_000_000)
    master = Master(ring, locate=False, max_devices=4)
    assert master.start().ok and master.data_cycle().ok
    ring.inject(DeadLine(2))
    ring.reset()
    ring.idle(wire.IDLE_TIMEOUT_S)
    assert [(chip.line_silent, chip.line_interrupt) for chip in chips] == [(False, False), (True, True), (True, False)]


BEHIND_A_BREAK = {
    Interface.LBD_OR: [IbDiag.STEADY, IbDiag.VERY_FAST, IbDiag.SLOW],
    Interface.LBD_MR: [IbDiag.STEADY, IbDiag.VERY_FAST, IbDiag.SLOW],
    Interface.LB_MR: [IbDiag.STEADY, IbDiag.VERY_FAST, IbDiag.VERY_FAST],
}
"""IB_DIAG of three chips with the forward line into chip 2 broken after the bus ran, 20 ms on (DG-3, DG-9): chip 1 is
still reached (steady), chip 2's input is silent (4 Hz; in the LBD modes it sends count 1), chip 3 hears chip 2's
counter telegrams in the LBD modes ("bus not active", 0.5 Hz); LB-MR chips have none, so every chip behind the break
shows 4 Hz."""


@pytest.mark.parametrize("interface", list(BEHIND_A_BREAK))
def test_a_ring_break_lights_4_hz_directly_behind_it(interface: Interface) -> None:
    # The transaction-level ring: the chips of the silent stretch behind an LBD chip time out counted (DG-9).
    config = decode("01000", clk_conf=FAST, diag_conf=0) if interface is Interface.LB_MR else _lbd(interface)
    chips = [Supi3(config) for _ in range(3)]
    ring = Ring(chips)
    master = Master(ring, locate=False, max_devices=4)
    assert master.start().ok and master.data_cycle().ok
    ring.inject(DeadLine(2))
    ring.idle(wire.IDLE_TIMEOUT_S * 1.02)
    assert [chip.diagnostic_outputs.ib_diag for chip in chips] == BEHIND_A_BREAK[interface]


@pytest.mark.slow
def test_a_pin_ring_break_lights_4_hz_directly_behind_it() -> None:
    # The same at pin level (LBD-OR): chip 2 generates count 1 behind the cut, chip 3's idle time-out runs on through
    # the counter telegrams; TL == pin.
    config = _lbd(Interface.LBD_OR)
    chips = [Supi3Pins(config) for _ in range(3)]
    ring = PinRing(chips)
    master = Master(ring, locate=False, max_devices=4)
    assert master.start().ok and master.data_cycle().ok
    ring.cut(2, True)
    ring.idle(wire.IDLE_TIMEOUT_S * 1.02)
    assert [chip.chip.diagnostic_outputs.ib_diag for chip in chips] == BEHIND_A_BREAK[Interface.LBD_OR]

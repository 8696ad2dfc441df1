"""The counter telegram blocks inside the pin-level chip core in the LBD modes (manual 2.2.2, Table 2-5; M17,
docs/rtl.md "Counter telegram block"): DO2 takes the forward block's bits while it drives them, DI1 is the return
block's line in LBD-MR; step() and run() agree cycle for cycle; working traffic goes out as before."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
import pytest

from supi3 import tables
from supi3.config import DeviceConfig, Interface, decode
from supi3.interbus import wire
from supi3.interbus.wire import Cycle, Frame
from supi3.model.pins import RESET_STRETCH_CLOCKS, Supi3Pins
from support import assert_run_matches_step, counter_counts, counter_levels, quiet_inputs

FAST = tables.clk_conf_for(2_000_000)
SLOW = tables.clk_conf_for(500_000)
LBD_ROWS = {iface: next(r for r in tables.MODE_ROWS if decode(r.c, r.mfp).interface is iface)
            for iface in (Interface.LBD_MR, Interface.LBD_OR)}  # fmt: skip
IDLE = wire.status_levels(Cycle.DATA, False, 20)


def _config(interface: Interface, clk: str = FAST) -> DeviceConfig:
    row = LBD_ROWS[interface]
    return decode(row.c, row.mfp, clk_conf=clk)


def _traffic(config: DeviceConfig) -> npt.NDArray[np.uint8]:
    """Master levels: reset, an ID cycle, a data cycle, idle (one device)."""
    lw = wire.LOOPBACK_BYTES_ON_LINE
    return np.concatenate([
        IDLE, wire.reset_levels(1), IDLE,
        wire.cycle_levels(Frame.build(Cycle.ID, lw + wire.word_bytes(wire.command_word(0))), 1, True), IDLE,
        wire.cycle_levels(Frame.build(Cycle.DATA, lw + bytes(range(config.data_bytes))), 1, True), IDLE,
    ])  # fmt: skip


def _line(levels: npt.NDArray[np.uint8], config: DeviceConfig, **pins: int) -> dict[str, npt.NDArray[np.int64]]:
    do1 = wire.levels_to_samples(levels, config.bit_rate).astype(np.int64)
    inputs = quiet_inputs(len(do1))
    inputs["do1"] = do1
    for name, value in pins.items():
        inputs[name][:] = value
    return inputs


@pytest.mark.parametrize("interface", [Interface.LBD_MR, Interface.LBD_OR])
def test_step_and_run_agree_with_a_silent_input_traffic_and_power_ups(interface: Interface) -> None:
    """A silent DO1 (the generator), then working traffic, /ResU pulled low twice (once inside a generated
    telegram), run() cut into pieces anywhere: every output, every cycle, as step() gives it."""
    config = _config(interface)
    silent = np.ones(80, dtype=np.uint8)
    inputs = _line(np.concatenate([silent, _traffic(config)[:400], silent]), config)
    n = len(inputs["do1"])
    for at in (RESET_STRETCH_CLOCKS + 16 * 33 + 40, n - 900):
        inputs["resu_n"][at : at + 30] = 0
    assert_run_matches_step(Supi3Pins(config), Supi3Pins(config), inputs, [0.13, 0.5, 0.501, 0.8])


@pytest.mark.parametrize("clk", [FAST, SLOW])
@pytest.mark.parametrize("interface", [Interface.LBD_MR, Interface.LBD_OR])
def test_a_silent_input_gives_count_1_forward_and_count_2_on_the_looped_return_line(interface: Interface,
                                                                                     clk: str) -> None:
    """Behind a break (DO1 idle), DO2 carries count 1 every 33 bit periods (BK-30); with no device following, the
    return line loops DO2 back: LBD-MR increments it once more (count 2), LBD-OR passes it as it is."""
    config = _config(interface, clk)
    cpb = wire.clocks_per_bit(config.bit_rate)
    traces = Supi3Pins(config).run(_line(np.ones(200, dtype=np.uint8), config))
    forward = counter_counts(traces["do2"], cpb)
    assert len(forward) == (200 - RESET_STRETCH_CLOCKS // cpb - 13) // 33 and set(forward) == {1}
    # LBD-MR: both blocks fall silent at once at power-up and race once (docs/interbus.md "Known limits"): the
    # return block's own count 1 comes first.
    looped = [1, *[2] * (len(forward) - 1)] if interface is Interface.LBD_MR else forward
    assert counter_counts(traces["di1"], cpb) == looped


@pytest.mark.parametrize("interface", [Interface.LBD_MR, Interface.LBD_OR])
def test_a_received_counter_telegram_goes_on_incremented(interface: Interface) -> None:
    """Counter telegrams arriving on DO1 as a device ahead sends them (one every 33 bit periods): DO2 passes each
    on incremented, DI1 (looped) once more in LBD-MR; the frame engine sees no frame in them."""
    config = _config(interface)
    cpb = wire.clocks_per_bit(config.bit_rate)
    model = Supi3Pins(config)
    traces = model.run(_line(np.concatenate([np.ones(20, dtype=np.uint8), np.tile(counter_levels(5, 33), 5)]), config))
    assert counter_counts(traces["do2"], cpb) == [6] * 5
    assert counter_counts(traces["di1"], cpb) == [7 if interface is Interface.LBD_MR else 6] * 5
    assert not model.chip.events


@pytest.mark.parametrize("interface", [Interface.LBD_MR, Interface.LBD_OR])
def test_working_traffic_goes_out_as_the_transmitter_sends_it(interface: Interface) -> None:
    """Working traffic: DO2 is the transmitter's line bit for bit (the counter block drives nothing); in LBD-MR
    the looped return line is DO2 again 3 bit periods later (the return block repeats it, A10), in LBD-OR DO2."""
    config = _config(interface)
    cpb = wire.clocks_per_bit(config.bit_rate)
    inputs = _line(_traffic(config), config)
    plain = Supi3Pins(config)
    plain._counters = None  # the transmitter alone
    traces, sent = Supi3Pins(config).run(inputs), plain.run(inputs)
    assert np.array_equal(traces["do2"], sent["do2"])
    start = RESET_STRETCH_CLOCKS + 3 * cpb
    delay = wire.REPEATER_DELAY_BITS * cpb if interface is Interface.LBD_MR else 0
    assert np.array_equal(traces["di1"][start + delay :], traces["do2"][start : len(traces["do2"]) - delay])
    assert len(counter_counts(traces["do2"], cpb)) > 10  # the frames went through

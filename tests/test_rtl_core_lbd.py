"""The counter telegram blocks inside the RTL chip core (``rtl.counter.CounterLinesRtl`` in ``Supi3Core``, docs/rtl.md
"Counter telegram block") against the pin model, every pin every clock, on Amaranth's simulator (no Verilator: this
runs in the quick tier; the Verilator benches of tests/test_rtl_core.py run the LBD rows of every mode too): an
LBD-MR and an LBD-OR chip with a silent input (the generator: count 1), working traffic and received counter
telegrams passed on incremented, on the forward and the looped return line (manual 2.2.2, Table 2-5)."""

from __future__ import annotations

import functools

import numpy as np
import pytest

from supi3 import tables
from supi3.config import Interface, decode
from supi3.interbus import wire
from supi3.model.pins import Supi3Pins
from supi3.rtl.core import Supi3Core
from supi3.verif.amaranth_sim import run_amaranth_sim
from supi3.verif.straps import StrapPins
from support import CoreScript, counter_counts, counter_levels

LBD_ROWS = {iface: next(r for r in tables.MODE_ROWS if decode(r.c, r.mfp).interface is iface)
            for iface in (Interface.LBD_MR, Interface.LBD_OR)}  # fmt: skip


@pytest.mark.parametrize("interface", [Interface.LBD_MR, Interface.LBD_OR])
def test_core_with_its_counter_blocks_in_lockstep(interface: Interface) -> None:
    row = LBD_ROWS[interface]
    config = decode(row.c, row.mfp, clk_conf="11")  # 2 Mbit/s
    script = CoreScript(config, np.random.default_rng(12)).line(np.ones(60, dtype=np.uint8))  # silent: count 1
    script.data_cycle()  # working traffic, then counter telegrams of count 9 from a device ahead: 10
    script.line(np.tile(counter_levels(9, 33), 2)).line(np.ones(16, dtype=np.uint8))
    stimulus = script.stimulus()
    result = run_amaranth_sim(functools.partial(Supi3Core, "opc"), functools.partial(StrapPins, "opc"), stimulus)
    assert result.cycles == len(stimulus)
    # What was compared, pin for pin: the counts on DO2 and on the looped return line DI1 (LBD-MR: once more).
    traces = Supi3Pins(config).run(script.columns())
    cpb = wire.clocks_per_bit(config.bit_rate)
    looped = 1 if interface is Interface.LBD_MR else 0
    assert [c for c in counter_counts(traces["do2"], cpb) if c is not None] == [1, 10, 10]
    assert [c for c in counter_counts(traces["di1"], cpb) if c is not None][-2:] == [10 + looped] * 2

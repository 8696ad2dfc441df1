"""The optical block inside the RTL chip core and chip (supi3.rtl.core, supi3.rtl.chip) against the pin-level model
(supi3.model.pins, supi3.top), every pin every clock (manual 1.6, 3.4.12, 3.4.13, Tables 3-16, 3-17; OPT-20,
OPT-26, OPT-50..OPT-53).

The core scenarios (support.optical_ops) run on the session's core bench: an INTERBUS reset with interfaces in use,
an ID cycle during the hold, the initialization responses, online tests and MAU changes, optical status requests
and the ID cycles answering them (the status byte and ATTN on the line), a length measurement, a reset left to the
full 6 ms time-out (192,000 clocks: cheap on the batch path, so the RTL's real budget is checked, not a shortened
one), in RF = 00 and 01, with DIAG1/DIAG2 as FO1/FO2. The chip scenario reads reads 8..11 through the µP interface.
"""

from __future__ import annotations

import pytest

from supi3.config import decode
from supi3.interbus import wire
from supi3.optical.regulation import MAX_LEVEL, Interface, OpticalMode, Response
from supi3.pinout import OPTICAL_REGISTERS
from supi3.regmap import REGISTER_MAP
from supi3.spi.upif import Mode
from supi3.verif import Lockstep
from support import RB_INIT_UP, ChipPins, Firmware, bring_up, optical_ops, optical_script
from test_model_pins_optical import BRANCH_OPS

IN, OUT = Interface.IN, Interface.OUT


@pytest.fixture(scope="session")
def bench(core_bench: Lockstep) -> Lockstep:
    return core_bench  # tests/conftest.py: one build, shared with tests/test_rtl_core.py


@pytest.mark.parametrize(("rf", "c"), [("00", "10000"), ("01", "10000"), ("00", "00001")])
def test_optical_scenario(bench: Lockstep, rf: str, c: str) -> None:
    """RF 00 (regulation) and 01 (diagnostics) in a binary I/O mode, and RF 00 in a bus terminal mode (FO3 on MFP8,
    Table 2-8)."""
    config = decode(c, rf=rf, clk_conf="11", diag_conf=1)
    script, _ = optical_script(config, optical_ops(OpticalMode.REGULATION if rf == "00" else OpticalMode.DIAGNOSTIC))
    assert bench.run_batch(script.stimulus()).cycles == len(script.inputs()["do1"])


@pytest.mark.parametrize("c", ["10000", "00001"])
def test_the_branch_line_side_starts_a_branch_in_a_bk_only(bench: Lockstep, c: str) -> None:
    """OPT-55: the branch bits of the line side (in use at the reset with IN and OUT, then alone; a response, a length
    measurement, an online test) reach the block in a bus terminal mode only (BK-LB, FO3 on MFP8): the RTL core holds
    them at 0 elsewhere (an RB chip), as the model, every pin every clock."""
    config = decode(c, rf="00", clk_conf="11", diag_conf=1)
    script, _ = optical_script(config, BRANCH_OPS)
    assert bench.run_batch(script.stimulus()).cycles == len(script.inputs()["do1"])


@pytest.fixture(scope="session")
def chip(chip_bench: Lockstep) -> Lockstep:
    return chip_bench  # tests/conftest.py: one build, shared with tests/test_rtl_chip.py


def test_reads_8_to_11_through_the_up_interface(chip: Lockstep) -> None:
    """3.4.12, 3.4.13: the µP reads the optical block's registers, which the RTL's register file reads from the
    block without storing them (UP-39); the model's register file gets the same bytes through the block's
    ``optical_we``, one clock after each change."""
    pins = ChipPins(decode(*RB_INIT_UP, rf="00", clk_conf="11"))
    up = Firmware(pins, Mode.MOTOROLA)
    up.idle(300)
    up.init()
    pins.pins["present"] = 0b011
    bring_up(pins)
    pins.drain(40)
    for response in (Response.DETECTED, Response.DETECTED, Response.NOT_DETECTED):
        pins.strobe(resp_valid=1 << IN, resp=response << 2 * IN)
    pins.strobe(resp_valid=1 << OUT, resp=Response.NONE << 2 * OUT)
    pins.strobe(len_start=1 << OUT)
    pins.drain(99)
    pins.pins["medium"] = 1 << OUT
    pins.strobe(len_stop=1 << OUT)
    pins.send(wire.status_levels(wire.Cycle.DATA, False, 2))
    pins.drain(8)
    read = [up.read(REGISTER_MAP.register(name)) or 0 for name in OPTICAL_REGISTERS]
    registers = pins.registers
    assert read == [registers.value(name) for name in OPTICAL_REGISTERS]
    assert read[2] & 0x0F == MAX_LEVEL - 1 and read[0] & 0x3F != 0  # 15 -> 14 -> 13, "Light on": 14; OUT measured
    assert chip.run_batch(pins.stimulus()).cycles == pins.cycle

"""The optical block inside the pin-level chip core (supi3.model.pins.Supi3Pins; manual 1.6, 1.6.1-1.6.3, 3.4.12,
3.4.13, Table 3-17; OPT-20, OPT-26, OPT-50..OPT-53): the line side's strobes at the core's inputs, the hold of the
protocol core, reads 8..11 in the register file, the FO LEDs, the optical status byte in the ID path; step() equals
run(); and the transaction-level chip (supi3.model.chip.Supi3) driven through its optical API on the same scenario
ends in the same state (one behaviour at both fidelities).
"""

from __future__ import annotations

import numpy as np
import pytest

from supi3.config import DeviceConfig, decode
from supi3.interbus import wire
from supi3.interbus.wire import Cycle
from supi3.model.chip import Supi3
from supi3.model.pins import Supi3Pins
from supi3.optical.length import Medium
from supi3.optical.regulation import (
    MAX_LEVEL,
    Interface,
    OpticalMode,
    OpticalStatus,
    Phase,
    Response,
    length_timer_enable_every,
)
from supi3.pinout import OPTICAL_REGISTERS
from support import OpticalOp, assert_run_matches_step, optical_ops, optical_script, quiet_inputs

IN, OUT, BRANCH = Interface.IN, Interface.OUT, Interface.BRANCH


def up_config(rf: str) -> DeviceConfig:
    return decode("10011", "1110", rf=rf, clk_conf="11", diag_conf=1)


def bk_up_config(rf: str) -> DeviceConfig:
    """A µP-mode BK (BK-RB, Init-µP, Table 2-7): the branch interface is its own (OPT-55)."""
    return decode("00011", rf=rf, clk_conf="11", diag_conf=1)


@pytest.mark.parametrize("rf", ["00", "01"])
def test_step_equals_run(rf: str) -> None:
    """One scenario with every optical strobe, stepped cycle by cycle and run in pieces: the same outputs (the 6 ms
    time-out left out: stepping it takes long; run() through it is held to the RTL, tests/test_rtl_core_optical.py)."""
    config = decode("10000", rf=rf, clk_conf="11", diag_conf=1)
    ops = [op for op in optical_ops(OpticalMode(int(rf == "01") + 1)) if op[0] != "timeout"]
    script, _ = optical_script(config, ops)
    stepped, bulk = Supi3Pins(config), Supi3Pins(config)
    assert_run_matches_step(stepped, bulk, script.inputs(), [0.13, 0.5, 0.77])
    assert stepped.chip.optical == bulk.chip.optical
    assert stepped.chip.optical != Supi3Pins(config).chip.optical


def test_hold_latches_nothing_and_the_block_drives_the_chip() -> None:
    """OPT-20: an ID cycle during the initialization is not latched; after it, the status byte asked for comes in
    the next ID cycle (OPT-50, OPT-51) and a MAU change raises ATTN (OPT-53); the FO LEDs are on DIAG1/DIAG2
    (Table 3-16, 3-17); reads 8..11 reach the register file (3.4.12)."""
    config = up_config("00")
    script, ends = optical_script(config, [("reset", 0b011), ("id", 0), ("resp", IN, Response.DETECTED),
                                           ("resp", IN, Response.NOT_DETECTED), ("resp", OUT, Response.NONE),
                                           ("id", wire.command_word(optical_request=True)),
                                           ("test", IN, False, True), ("id", 0)])  # fmt: skip
    pins = Supi3Pins(config)
    columns = script.inputs()
    outputs = [pins.run({name: trace[a:b] for name, trace in columns.items()})
               for a, b in zip([0, *ends], ends, strict=False)]  # fmt: skip
    chip = pins.chip
    assert chip.events["ID_CYCLE"] == 2  # the first one came during the hold
    assert chip.optical[IN].phase is Phase.ONLINE and chip.optical[IN].level == MAX_LEVEL
    assert chip.optical[IN].mau and chip.optical[OUT].phase is Phase.FIXED
    assert not chip.attention  # the change was read in the last ID cycle (OPT-53)
    assert chip.registers is not None
    assert [chip.registers.value(name) for name in OPTICAL_REGISTERS][2] & 0x0F == MAX_LEVEL
    # FO2 (OUT fixed, READY) on DIAG2 after the hold; FO1 lit by the MAU warning once the bus runs
    assert outputs[5]["diag2"][-1] == 1


@pytest.mark.parametrize("rf", ["00", "01"])
def test_transaction_level_ends_where_the_pin_level_does(rf: str) -> None:
    """The optical API of the TL chip and the pin level's strobes, op by op: the same optical status, reads 8..11,
    ID register and ATTN after every op."""
    assert_tl_equals_pins(bk_up_config(rf), optical_ops(OpticalMode(int(rf == "01") + 1)))


def test_each_interface_times_out_in_turn_at_both_levels() -> None:
    """OPT-56: with IN and OUT in use and no response, the incoming interface falls back 6 ms after the start and the
    outgoing one 6 ms after that, at pin level as at transaction level (the hold spans both; an ID cycle in between
    is not latched)."""
    ops: list[OpticalOp] = [("reset", 0b011), ("timeout",), ("id", 0), ("timeout",), ("id", 0)]
    seen = assert_tl_equals_pins(up_config("00"), ops)
    phases = [[tx.phase for tx in status.transmitters] for status, _ in seen]
    assert phases[1] == phases[2] == [Phase.FIXED, Phase.INIT, Phase.OFF]
    assert phases[3] == [Phase.FIXED, Phase.FIXED, Phase.OFF]
    assert [events for _, events in seen] == [0, 0, 0, 0, 1]  # the ID cycle during the hold is not latched


def assert_tl_equals_pins(config: DeviceConfig, ops: list[OpticalOp],
                          tl_ops: list[OpticalOp] | None = None) -> list[tuple[OpticalStatus, int]]:  # fmt: skip
    """``ops`` on the TL chip's optical API (``tl_ops`` in their place if given, one for each) and as the pin level's
    strobes, op by op: the same optical status, reads 8..11, ID register and ATTN after every op; the pin level's
    status and ID_CYCLE events after each."""
    script, ends = optical_script(config, ops)
    pins = Supi3Pins(config)
    tl = Supi3(config)
    columns = script.inputs()
    every = length_timer_enable_every(config.bit_rate)
    clk = 0
    seen = []
    for op, tl_side, a, b in zip(ops, tl_ops or ops, [0, *ends[:-1]], ends, strict=True):
        pins.run({name: trace[a:b] for name, trace in columns.items()})
        clk += 1000
        tl_op(tl, tl_side, clk, every)
        assert tl.optical == pins.chip.optical, op
        assert tl.id_register() == pins.chip.id_register(), op
        assert tl.attention == pins.chip.attention, op
        assert tl.registers is not None and pins.chip.registers is not None
        assert [tl.registers.value(r) for r in OPTICAL_REGISTERS] == [
            pins.chip.registers.value(r) for r in OPTICAL_REGISTERS], op  # fmt: skip
        seen.append((pins.chip.optical, pins.chip.events["ID_CYCLE"]))
    return seen


def tl_op(chip: Supi3, op: OpticalOp, clk: int, every: int) -> None:
    """``op`` through the TL chip's optical API and bus calls (``("none",)``: nothing)."""
    kind, *args = op
    if kind == "none":
        return
    if kind == "reset":
        chip.reset_at(clk)
        present = args[0]
        chip.optical_start((bool(present & 1), bool(present & 2), bool(present & 4)))
    elif kind == "resp":
        chip.optical_init_response(Interface(args[0]), Response(args[1]))
    elif kind == "test":
        chip.optical_test(Interface(args[0]), bool(args[1]), bool(args[2]))
    elif kind == "length":
        chip.optical_length(Interface(args[0]), args[1] // every, Medium(args[2]))
    elif kind == "timeout":
        chip.optical_init_timeout()
    else:
        chip.load_at(Cycle.ID, clk)
        chip.latch_at(Cycle.ID, wire.word_bytes(args[0]), clk + 1)


BRANCH_OPS: list[OpticalOp] = [
    ("reset", 0b111), ("id", 0), ("resp", BRANCH, Response.DETECTED), ("resp", IN, Response.NONE),
    ("resp", OUT, Response.NONE), ("length", BRANCH, 160, 1), ("length", OUT, 96, 0), ("test", BRANCH, True, True),
    ("id", 0), ("reset", 0b100), ("id", 0),
]  # fmt: skip
"""The line side of a BK's branch interface on a chip: in use at the reset (with IN and OUT, then alone), its response,
length measurement and online test."""


def test_a_chip_without_the_branch_interface_never_starts_a_branch_transmitter() -> None:
    """OPT-55 (2.1, Table 2-8, 1.6.3): the branch bits of the line side on a chip outside the bus terminal modes (an
    RB Init-µP chip) start no branch transmitter and measure no branch path, op by op as the transaction level, which
    refuses ``present[BRANCH]`` and ``optical_length(BRANCH)`` (given the ops without the branch there): the same
    status, reads 8..11 (read 9 and read 11 bits 7..4 stay 0), ID register and ATTN; FO3 stays dark. A BK (BK-RB,
    Init-µP) given the same line side starts and measures its branch."""
    without: list[OpticalOp] = []
    for kind, *args in BRANCH_OPS:
        if kind == "reset":
            without.append((kind, args[0] & ~(1 << BRANCH)))
        else:
            without.append(("none",) if kind in ("resp", "length", "test") and args[0] is BRANCH else (kind, *args))
    seen = assert_tl_equals_pins(up_config("00"), BRANCH_OPS, without)
    assert all(status[BRANCH].phase is Phase.OFF and not status.length[1] for status, _ in seen)
    bk = Supi3Pins(bk_up_config("00"))
    script, _ = optical_script(bk.config, BRANCH_OPS[:6])
    bk.run(script.inputs())
    assert bk.chip.optical[BRANCH].phase is Phase.INIT and bk.chip.optical.length[1]


def test_copper_and_quiet_line_side_leave_the_core_alone() -> None:
    """RF = 11 (copper): no block; the line side is accepted and ignored. Without the line side given, the core
    runs as before (quiet inputs)."""
    config = decode("10000", rf="11", clk_conf="11")
    pins = Supi3Pins(config)
    inputs = quiet_inputs(300) | {name: np.full(300, 1) for name in ("present", "resp_valid", "test_valid")}
    inputs |= {name: np.zeros(300, dtype=np.int64) for name in ("medium", "resp", "ack1", "ack2", "len_start",
                                                                 "len_stop")}  # fmt: skip
    pins.run(inputs)
    assert pins.chip.optical == Supi3Pins(config).chip.optical

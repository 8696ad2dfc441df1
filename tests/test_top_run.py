"""The whole chip's event-driven run(): the same outputs, state and violation records as step() cycle by cycle,
with INTERBUS traffic on the line and a µP on the MFP pins (issue #10; docs/model.md, "The whole chip")."""

from __future__ import annotations

from itertools import pairwise

import numpy as np
import numpy.typing as npt
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.config import decode
from supi3.interbus import wire
from supi3.model.registers import RegisterFile
from supi3.regmap import ID, IN0, IRQ_EN, IRQ_EVT, OUT0, REGISTER_MAP, SET, encode_command
from supi3.spi.master import SoftMaster
from supi3.spi.slave_pins import PinsIn, SlavePins, TimingViolationError
from supi3.spi.upif import Mode
from supi3.tables import clk_conf_for
from supi3.top import QUIET_BOARD, UP_INPUTS, UP_PINS, Supi3Chip
from support import CORE_INPUTS, IDLE, data_frame, id_frame, register_address

Traces = dict[str, npt.NDArray[np.int64]]
RATES = (500_000, 2_000_000)


def mfp_levels(pins: list[PinsIn]) -> npt.NDArray[np.int64]:
    """MFP[7..0] levels of the µP's pins, cycle by cycle (Tables 3-5, 3-6)."""
    return np.array([sum(getattr(p, name) << pin for name, pin in UP_INPUTS.items()) for p in pins], dtype=np.int64)


def up_script(bit_rate: int, mode: Mode, actions: list[tuple[int, int, int, bool]]) -> list[PinsIn]:
    """The µP's pins: initialization, SET and ID written, then ``actions`` (gap in cycles, kind, byte, S/R): kind
    0 a register write, 1 a register read, 2 one raw byte, 3 a SAS_INIT pulse. A software master on a scratch
    interface produces them (its pins do not depend on the chip's answers)."""
    scratch = SlavePins(RegisterFile(decode("10011", "1110", clk_conf=clk_conf_for(bit_rate)), strict=False))
    master = SoftMaster(scratch, mode)
    master.byte(mode.init_byte)
    for address, value in ((SET, 0x82), (ID, 0x01), (IRQ_EN, 0xFF)):
        master.byte(encode_command(register_address(address), wr=True))
        master.byte(value)
    targets = [register_address(r) for r in (IN0, OUT0, IRQ_EVT, SET, ID)]
    for gap, kind, value, s_r in actions:
        master.deselect()
        master.run(gap)
        target = targets[value % len(targets)]
        if kind == 0:
            master.byte(encode_command(target, wr=True))
            master.byte(value)
        elif kind == 1:
            master.byte(encode_command(target, rd=True))
            master.byte(0, s_r=False)
        elif kind == 2:
            master.byte(value, s_r=s_r)
        else:
            master.run(gap % 400 + 1, sas_init=1)
            master.run(1, sas_init=0)
    master.deselect()
    return master.trace().inputs


def line_script(frames: list[tuple[bool, bytes]]) -> npt.NDArray[np.uint8]:
    """The master's line levels: idle, reset, an ID cycle, then data cycles (latched or not)."""
    parts = [IDLE, wire.reset_levels(1), IDLE, id_frame(wire.command_word()), IDLE]
    for latch, data in frames:
        parts += [data_frame(data, latch=latch), IDLE]
    return np.concatenate(parts)


def chip_inputs(bit_rate: int, mode: Mode, actions: list[tuple[int, int, int, bool]],
                frames: list[tuple[bool, bytes]], power_dip: int | None = None) -> Traces:
    """Every input pin: the line from the master, the µP on MFP[7..0], a quiet board otherwise."""
    do1 = wire.levels_to_samples(line_script(frames), bit_rate).astype(np.int64)
    mfp = mfp_levels(up_script(bit_rate, mode, actions))
    n = max(len(do1), len(mfp))
    do1 = np.concatenate([do1, np.ones(n - len(do1), dtype=np.int64)])
    mfp = np.concatenate([mfp, np.full(n - len(mfp), mfp[-1], dtype=np.int64)])
    ones = np.ones(n, dtype=np.int64)
    vmon = ones.copy()
    if power_dip is not None:
        vmon[power_dip % n : power_dip % n + 20] = 0
    return {"do1": do1, "di2": np.zeros(n, dtype=np.int64), "rbst_ext": np.zeros(n, dtype=np.int64), "mfp_in": mfp,
            "stat_err_n": ones, "resu_n": ones, "vmon_ok": vmon, "from_exr": 0 * vmon}


def stepped(chip: Supi3Chip, inputs: Traces) -> Traces:
    columns = [inputs[name].tolist() for name in CORE_INPUTS]
    rows = [chip.step(dict(zip(CORE_INPUTS, values, strict=True))) for values in zip(*columns, strict=True)]
    return {pin.name: np.array([row[pin.name] for row in rows], dtype=np.int64) for pin in chip.outputs}


def in_pieces(chip: Supi3Chip, inputs: Traces, cuts: list[float]) -> Traces:
    n = len(inputs["do1"])
    bounds = [0, *sorted(int(cut * n) for cut in cuts), n]
    pieces = [chip.run({name: trace[a:b] for name, trace in inputs.items()}) for a, b in pairwise(bounds)]
    return {name: np.concatenate([piece[name] for piece in pieces]) for name in pieces[0]}


def state(chip: Supi3Chip) -> tuple[object, ...]:
    """Everything firmware or the master can observe, and the violation log."""
    upif = chip.upif
    assert upif is not None
    registers = upif.registers
    return (chip.cycle, upif.cycle, upif.protocol.mode, upif.protocol.phase, registers.io_access,
            registers.irq_n, [registers.value(r.name) for r in REGISTER_MAP.registers], dict(chip.chip.events),
            [(type(v).__name__, str(v)) for v in registers.violations.records])  # fmt: skip


ACTIONS = st.lists(st.tuples(st.integers(0, 3000), st.integers(0, 3), st.integers(0, 255), st.booleans()),
                   max_size=6)
FRAMES = st.lists(st.tuples(st.booleans(), st.binary(min_size=1, max_size=1)), min_size=1, max_size=4)


@settings(max_examples=20, deadline=None)
@given(bit_rate=st.sampled_from(RATES), mode=st.sampled_from(list(Mode)), actions=ACTIONS, frames=FRAMES,
       cuts=st.lists(st.floats(0, 1), max_size=5), power_dip=st.none() | st.integers(0, 10**6))
@pytest.mark.slow
def test_run_and_step_agree_cycle_for_cycle(bit_rate: int, mode: Mode, actions: list[tuple[int, int, int, bool]],
                                            frames: list[tuple[bool, bytes]], cuts: list[float],
                                            power_dip: int | None) -> None:
    inputs = chip_inputs(bit_rate, mode, actions, frames, power_dip)
    config = decode("10011", "1110", clk_conf=clk_conf_for(bit_rate))
    by_step, by_run = Supi3Chip(config, strict=False), Supi3Chip(config, strict=False)
    expected = stepped(by_step, inputs)
    got = in_pieces(by_run, inputs, cuts)
    for name, trace in expected.items():
        mismatch = np.flatnonzero(trace != got[name])
        assert not mismatch.size, f"{name} differs first at cycle {mismatch[:1]}"
    assert state(by_run) == state(by_step)


@pytest.mark.parametrize("mode", list(Mode))
def test_run_agrees_with_step_on_a_firmware_session(mode: Mode) -> None:
    # Configuration, register traffic between data cycles, a SAS_INIT pulse; no power dip, whole trace at once.
    inputs = chip_inputs(2_000_000, mode, [(500, 0, 0x5A, True), (900, 1, 1, True), (60, 3, 7, True)],
                         [(True, b"\x99"), (False, b"\x11"), (True, b"\x42")])
    config = decode("10011", "1110", clk_conf="11")
    by_step, by_run = Supi3Chip(config, strict=False), Supi3Chip(config, strict=False)
    expected = stepped(by_step, inputs)
    got = by_run.run(inputs)
    for name, trace in expected.items():
        assert np.array_equal(trace, got[name]), name
    assert state(by_run) == state(by_step)
    assert by_run.chip.events["VALID"] == 2


def test_empty_run_changes_nothing_and_quiet_board_is_quiet() -> None:
    chip = Supi3Chip(decode("10011", "1110", clk_conf="11"))
    empty = chip.run({name: np.zeros(0, dtype=np.int64) for name in CORE_INPUTS})
    assert all(len(trace) == 0 for trace in empty.values()) and chip.cycle == 0
    quiet = chip.run({name: np.full(400, level, dtype=np.int64) for name, level in QUIET_BOARD.items()})
    assert quiet["resu_drive"][-1] == 0 and quiet["mfp_oe"][-1] & UP_PINS == 0b1110  # I/O, C/D, /IRQ driven
    assert chip.upif is not None and not chip.upif.registers.violations.records


def test_strict_run_raises_the_violation_step_raises_once_every_cycle_ran() -> None:
    # /SS falls and SCLK falls in the same cycle: t1 (Table 3-7) is violated at that cycle.
    config = decode("10011", "1110", clk_conf="11")
    n, at = 600, 400
    inputs = {name: np.full(n, level, dtype=np.int64) for name, level in QUIET_BOARD.items()}
    ss_n, sclk = 1 << UP_INPUTS["ss_n"], 1 << UP_INPUTS["sclk"]
    inputs["mfp_in"][at:] &= ~(ss_n | sclk)
    by_step, by_run = Supi3Chip(config), Supi3Chip(config)
    for t in range(at):
        by_step.step({name: int(trace[t]) for name, trace in inputs.items()})
    with pytest.raises(TimingViolationError) as stepped_error:
        by_step.step({name: int(trace[at]) for name, trace in inputs.items()})
    with pytest.raises(TimingViolationError) as run_error:
        by_run.run(inputs)
    assert str(run_error.value) == str(stepped_error.value)  # the same cycle of the interface's clock
    assert by_run.cycle == n and by_step.cycle == at + 1  # step() stops after its cycle, run() after all

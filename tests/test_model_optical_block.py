"""The optical block at pin level (supi3.model.blocks.optical.OpticalBlock, issue 12): manual 1.6 (reset behaviour),
1.6.1 (initialization, 6 ms, the length timer), 1.6.2 (online regulation, optical diagnostics), 1.6.3 (MAU warnings),
Table 3-17 (FO LEDs), 3.4.12/3.4.13 (reads 8 to 11); OPT-20 onward of docs/assumptions/optical.md.

Directed cases for each transition and port, the block's timing (start at the falling edge of ib_reset, the 6 ms
counter, the length timers' divider, ``optical_we``), hostile input, and the transaction level and the pin level on
shared scenarios (same responses, tests and lengths: same OpticalStatus and reads 8..11).
"""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.config import decode
from supi3.errors import ArgumentError
from supi3.model.blocks.optical import LENGTH_COUNT_BITS, OpticalBlock
from supi3.model.chip import Supi3
from supi3.optical.length import Medium, timer_code
from supi3.optical.regulation import (
    BLOCK_INPUTS,
    BLOCK_OUTPUTS,
    INIT_MAX_STEPS,
    INIT_TIME_LIMIT_CLOCKS,
    MAX_LEVEL,
    Interface,
    OpticalMode,
    OpticalStatus,
    Phase,
    Response,
    Transmitter,
    init_response,
    length_timer_enable_every,
    registers,
)
from supi3.pinlevel import PinModel
from supi3.pinout import OPTICAL_REGISTERS
from supi3.tables import BIT_RATES, clk_conf_for
from support import OPTICAL_INPUTS, OpticalScript, run_optical

IN, OUT, BRANCH = Interface.IN, Interface.OUT, Interface.BRANCH
REG, DIAG, OFF = OpticalMode.REGULATION, OpticalMode.DIAGNOSTIC, OpticalMode.OFF


def read_bytes(optical: int) -> tuple[int, ...]:
    return tuple(optical >> (8 * k) & 0xFF for k in range(len(OPTICAL_REGISTERS)))


def started(mode: OpticalMode = REG, **static: int) -> OpticalScript:
    """An INTERBUS reset and the start (at the edge ending the cycle after it)."""
    return OpticalScript(mode, **static).reset()


def test_ports_are_the_spec_and_a_pin_model() -> None:
    assert tuple(OpticalBlock.inputs) == BLOCK_INPUTS
    assert tuple(OpticalBlock.outputs) == BLOCK_OUTPUTS
    assert isinstance(OpticalBlock(), PinModel)


def test_power_up_shows_nothing() -> None:
    _, outputs = run_optical(OpticalScript(REG).idle(5).rows)
    assert outputs == [{"optical_we": 0, "optical": 0, "mau": 0, "fo": 0, "hold": 0}] * 5


@pytest.mark.parametrize("mode", list(OpticalMode))
@pytest.mark.parametrize("present", range(8))
def test_start_at_the_end_of_the_reset(mode: OpticalMode, present: int) -> None:
    """1.6: nothing starts during the reset; at the edge ending the first cycle after it every interface starts as
    ``start`` says; hold from the next cycle while one initializes; reads 10/11 written (optical_we) then."""
    script = OpticalScript(mode, present=present).idle(2).reset(3).idle(2)
    block, outputs = run_optical(script.rows)
    phase = {REG: Phase.INIT, DIAG: Phase.DIAGNOSTIC, OFF: Phase.OFF}[mode]
    assert [tx.phase for tx in block.status.transmitters] == [phase if present >> i & 1 else Phase.OFF
                                                              for i in Interface]  # fmt: skip
    initializing = int(mode is REG and present != 0)
    assert [out["hold"] for out in outputs] == [0] * 6 + [initializing] * 2
    changed = registers(block.status) != registers(OpticalStatus())
    assert [out["optical_we"] != 0 for out in outputs] == [False] * 6 + [changed, False]
    assert read_bytes(outputs[-1]["optical"]) == registers(block.status)


def test_thirteen_steps_then_online_each_step_as_the_spec() -> None:
    """1.6.1: 13 "Light off" responses lower 15 -> 2 and end the initialization (ONLINE, enable 1)."""
    script = started(present=0b010)
    spec = Transmitter(Phase.INIT)
    block = OpticalBlock()
    for row in script.rows:
        block.step(row)
    for _ in range(INIT_MAX_STEPS):
        for row in OpticalScript(REG, present=0b010).response(OUT, Response.DETECTED).rows:
            block.step(row)
        spec = init_response(spec, Response.DETECTED)
        assert block.status[OUT] == spec
    assert spec == Transmitter(Phase.ONLINE, MAX_LEVEL - INIT_MAX_STEPS)
    assert not block.hold


@pytest.mark.parametrize(("responses", "want"), [
    ([Response.NOT_DETECTED], Transmitter(Phase.ONLINE, MAX_LEVEL, mau=True)),  # first step at MAX: MAU (1.6.3)
    ([Response.DETECTED, Response.NOT_DETECTED], Transmitter(Phase.ONLINE, MAX_LEVEL, mau=True)),
    ([Response.DETECTED] * 2 + [Response.NOT_DETECTED], Transmitter(Phase.ONLINE, MAX_LEVEL - 1)),
    ([Response.NONE], Transmitter(Phase.FIXED)),
    ([Response.DETECTED, Response.NONE], Transmitter(Phase.FIXED)),
])  # fmt: skip
def test_initialization_outcomes(responses: list[Response], want: Transmitter) -> None:
    script = started()
    for response in responses:
        script.response(BRANCH, response)
    block, outputs = run_optical(script.idle().rows)
    assert block.status[BRANCH] == want
    assert outputs[-1]["mau"] == int(want.mau) << BRANCH
    assert outputs[-1]["hold"] == 1  # IN and OUT still initialize


def test_budget_runs_out_after_six_ms_of_clocks() -> None:
    """OPT-5: the edge INIT_TIME_LIMIT_CLOCKS after the start edge turns initializing transmitters FIXED; hold is 1
    for exactly that many cycles."""
    script = started(present=0b011).response(OUT, Response.NOT_DETECTED).idle(INIT_TIME_LIMIT_CLOCKS + 5)
    block, outputs = run_optical(script.rows)
    holds = [out["hold"] for out in outputs]
    first = holds.index(1)
    assert holds[first:].count(1) == INIT_TIME_LIMIT_CLOCKS
    assert holds[first + INIT_TIME_LIMIT_CLOCKS] == 0
    assert [tx.phase for tx in block.status.transmitters] == [Phase.FIXED, Phase.ONLINE, Phase.OFF]
    assert outputs[-1]["fo"] == 0b001  # READY: FO1 lit for the unregulated partner (Table 3-17, OPT-8)


def online(script: OpticalScript, interface: Interface, steps: int) -> OpticalScript:
    """Initialize ``interface`` down ``steps`` and back up one: ONLINE at 15 - steps + 1."""
    for _ in range(steps):
        script.response(interface, Response.DETECTED)
    return script.response(interface, Response.NOT_DETECTED)


def test_online_regulation_decrease_after_and_hysteresis() -> None:
    """1.6.2, OPT-6: DECREASE_AFTER passes lower by one; a failure raises at once; the MAU warning comes on at the
    step 14 -> 15 and goes off only at 14 -> 13 (1.6.3)."""
    script = online(started(present=0b010), OUT, 2)  # ONLINE at 14
    script.test(OUT, False, False)  # 14 -> 15: MAU on
    block, _ = run_optical(script.rows)
    assert (block.status[OUT].level, block.status[OUT].mau) == (MAX_LEVEL, True)
    script.test(OUT, True, True).test(OUT, True, True)  # 15 -> 14: still on
    block, _ = run_optical(script.rows)
    assert (block.status[OUT].level, block.status[OUT].mau) == (MAX_LEVEL - 1, True)
    script.test(OUT, True, False).test(OUT, True, True).test(OUT, True, True)  # hold resets the passes; 14 -> 13
    block, outputs = run_optical(script.idle().rows)
    assert (block.status[OUT].level, block.status[OUT].mau) == (MAX_LEVEL - 2, False)
    assert read_bytes(outputs[-1]["optical"])[3] == MAX_LEVEL - 2


def test_diagnostics_mode_and_fo_in_run() -> None:
    """1.6.2, OPT-7: tests move only the MAU warning; FO shows it in RUN (Table 3-17)."""
    script = started(DIAG, present=0b101).test(BRANCH, False, False).idle(run=1).idle(run=0)
    block, outputs = run_optical(script.rows)
    assert block.status[BRANCH] == Transmitter(Phase.DIAGNOSTIC, mau=True)
    assert [out["fo"] for out in outputs[-2:]] == [0b100, 0]
    assert outputs[-1]["mau"] == 0b100


def test_unused_codes_are_off_and_no_response() -> None:
    """OPT-23: mode 3 starts nothing; resp 3 changes nothing."""
    block, _ = run_optical(OpticalScript(3).reset().length(OUT, 40).rows)
    assert block.status == OpticalStatus()
    block, _ = run_optical(started().response(IN, 3).rows)
    assert block.status[IN] == Transmitter(Phase.INIT)


@pytest.mark.parametrize("fast", [0, 1])
@pytest.mark.parametrize("medium", list(Medium))
@pytest.mark.parametrize("clocks", [1, 3, 4, 5, 63, 64, 65, 130, 1000, 5000])
def test_length_timer_counts_every_nth_clock(fast: int, medium: Medium, clocks: int) -> None:
    """1.6.1, OPT-1, OPT-24: len_stop ``clocks`` cycles after len_start: count = clocks // every (16 x the bit rate
    out of 32 MHz), code = timer_code(count) of the medium, at both measured paths."""
    bit_rate = BIT_RATES[fast]
    script = started(fast=fast).length(OUT, clocks, int(medium)).length(BRANCH, clocks + 1, int(medium)).idle()
    block, outputs = run_optical(script.rows)
    every = length_timer_enable_every(bit_rate)
    assert block.status.length == (timer_code(clocks // every, bit_rate, medium),
                                   timer_code((clocks + 1) // every, bit_rate, medium))  # fmt: skip
    assert block.status.medium == (medium, medium)
    assert read_bytes(outputs[-1]["optical"]) == registers(block.status)


def test_length_timer_saturates() -> None:
    every = length_timer_enable_every(BIT_RATES[1])
    block, _ = run_optical(started(fast=1).length(OUT, every << (LENGTH_COUNT_BITS + 1), 1).rows)
    assert block.status.length[0] == timer_code((1 << LENGTH_COUNT_BITS) - 1, BIT_RATES[1], Medium.GLASS)


def test_reset_stops_timers_and_keeps_lengths() -> None:
    """OPT-21: an INTERBUS reset turns the transmitters off and stops a running timer; the lengths stay; the block
    off (copper) measures nothing."""
    script = started().length(BRANCH, 100).idle(len_start=0b100).reset().idle(5, len_stop=0b100)
    block, _ = run_optical(script.rows)
    assert block.status.length == (0, timer_code(100 // 4, BIT_RATES[0], Medium.POLYMER))
    assert [tx.phase for tx in block.status.transmitters] == [Phase.INIT] * 3
    block, _ = run_optical(started(OFF).length(OUT, 100).rows)
    assert block.status == OpticalStatus()


def test_optical_we_marks_every_change_of_a_byte() -> None:
    """The register file takes byte k when optical_we bit k is set: replaying the strobes rebuilds every cycle's
    ``optical``."""
    script = online(started(), OUT, 4).response(IN, Response.NONE).length(OUT, 300, 1).test(OUT, False, False)
    script.reset().length(BRANCH, 77)
    _, outputs = run_optical(script.rows)
    held = [0, 0, 0, 0]
    for out in outputs:
        now = read_bytes(out["optical"])
        for k in range(len(held)):
            if out["optical_we"] >> k & 1:
                assert now[k] != held[k]
                held[k] = now[k]
        assert tuple(held) == now
    assert sum(bin(out["optical_we"]).count("1") for out in outputs) >= 6


# Hostile input ----------------------------------------------------------------------------------------------------


def test_hostile_inputs_are_named_and_change_nothing() -> None:
    block = OpticalBlock()
    for row in started().rows:
        block.step(row)
    good = OpticalScript(REG).idle().rows[0]
    before = (block.status, block.countdown, block.cycle)
    bad: list[object] = [
        None, [0] * len(OPTICAL_INPUTS), {k: v for k, v in good.items() if k != "run"}, good | {"extra": 0},
        good | {"mode": 4}, good | {"resp": -1}, good | {"present": 1.0}, good | {"run": True}, good | {"ack1": "1"},
    ]  # fmt: skip
    for inputs in bad:
        with pytest.raises(ArgumentError, match="must be"):
            block.step(inputs)  # type: ignore[arg-type]
        assert (block.status, block.countdown, block.cycle) == before


# Transaction level == pin level --------------------------------------------------------------------------------

OPERATION = st.one_of(
    st.tuples(st.just("restart"), st.integers(0, 7)),
    st.tuples(st.just("response"), st.sampled_from(list(Interface)), st.sampled_from(list(Response))),
    st.tuples(st.just("response"), st.sampled_from(list(Interface)), st.just(Response.DETECTED)),
    st.tuples(st.just("test"), st.sampled_from(list(Interface)), st.booleans(), st.booleans()),
    st.tuples(st.just("length"), st.sampled_from([OUT, BRANCH]), st.integers(1, 300), st.sampled_from(list(Medium))),
)


Outcome = tuple[Supi3, OpticalBlock, list[dict[str, int]]]


def tl_and_pin(mode: OpticalMode, fast: int, operations: list[tuple[object, ...]]) -> Outcome:
    """The operations on a µP-mode BK (BK-RB, Init-µP: all three interfaces, OPT-55; transaction level) and on the
    block (pin level)."""
    rf = {REG: "00", DIAG: "01", OFF: "11"}[mode]
    chip = Supi3(decode("00011", rf=rf, clk_conf=clk_conf_for(BIT_RATES[fast])))
    script = OpticalScript(mode, fast=fast)
    every = length_timer_enable_every(BIT_RATES[fast])
    for operation in operations:
        name, *args = operation
        if name == "restart":
            present = args[0]
            assert isinstance(present, int)
            chip.reset(0.0)
            chip.optical_start(tuple(bool(present >> i & 1) for i in Interface))  # type: ignore[arg-type]
            script.static["present"] = present
            script.reset()
        elif name == "response":
            chip.optical_init_response(*args)  # type: ignore[arg-type]
            script.response(*args)  # type: ignore[arg-type]
        elif name == "test":
            chip.optical_test(*args)  # type: ignore[arg-type]
            script.test(*args)  # type: ignore[arg-type]
        else:
            interface, count, medium = args
            assert isinstance(interface, Interface) and isinstance(count, int) and isinstance(medium, Medium)
            chip.optical_length(interface, count, medium)
            script.length(interface, count * every, int(medium))
    block, outputs = run_optical(script.idle().rows)
    return chip, block, outputs


@settings(max_examples=60)
@given(mode=st.sampled_from(list(OpticalMode)), fast=st.integers(0, 1),
       operations=st.lists(OPERATION, max_size=25))  # fmt: skip
def test_transaction_level_equals_pin_level(mode: OpticalMode, fast: int, operations: list[tuple[object, ...]]) -> None:
    """The same responses, tests and lengths give the same OpticalStatus and reads 8..11 at both fidelities."""
    chip, block, outputs = tl_and_pin(mode, fast, operations)
    assert block.status == chip.optical
    assert chip.registers is not None
    assert read_bytes(outputs[-1]["optical"]) == tuple(chip.registers.value(name) for name in OPTICAL_REGISTERS)
    assert outputs[-1]["hold"] == int(chip.optical_holding)


def test_transaction_level_equals_pin_level_on_a_full_scenario() -> None:
    """Every interface, both lengths, online tests at both fidelities (a directed example of the property)."""
    operations: list[tuple[object, ...]] = [("restart", 7)]
    operations += [("response", IN, Response.DETECTED)] * 5 + [("response", IN, Response.NOT_DETECTED)]
    operations += [("response", OUT, Response.NONE), ("response", BRANCH, Response.NOT_DETECTED)]
    operations += [("length", OUT, 17, Medium.POLYMER), ("length", BRANCH, 200, Medium.GLASS)]
    operations += [("test", IN, True, True)] * 3 + [("test", BRANCH, False, True)]
    chip, block, _ = tl_and_pin(REG, 0, operations)
    assert block.status == chip.optical
    assert [tx.phase for tx in chip.optical.transmitters] == [Phase.ONLINE, Phase.FIXED, Phase.ONLINE]
    assert chip.optical[IN].level == MAX_LEVEL - 5  # 15 - 5 + 1, then one decrease after two passes

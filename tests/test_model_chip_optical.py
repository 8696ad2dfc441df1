"""The transaction-level chip's optical block (Supi3.optical*, issue 12): manual 1.6 (reset behaviour, 1.6.1
initialization, 1.6.2 online regulation and optical diagnostics, 1.6.3 MAU warnings), 3.4.12/3.4.13 (reads 8 to 11);
decisions OPT-20 onward of docs/assumptions/optical.md.

Directed cases for every call and mode, the core held while the optical initialization runs (on the per-chip path
and the ring kernel's fast path), hostile input for every public entry, and hypothesis histories of starts,
responses, tests, lengths, timeouts, resets and time: the level stays in 1..15, the MAU warning keeps its hysteresis
and the register file always holds ``registers(status)``.
"""

from __future__ import annotations

from collections.abc import Callable

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.config import Variant, decode
from supi3.interbus.wire import Cycle
from supi3.model.chip import ChipArgumentError, Supi3, clocks
from supi3.optical import regulation
from supi3.optical.length import Medium, timer_code, timer_count
from supi3.optical.regulation import (
    INIT_MAX_STEPS,
    INIT_TIME_LIMIT_CLOCKS,
    MAX_LEVEL,
    Interface,
    OpticalMode,
    OpticalStatus,
    Phase,
    Response,
    Transmitter,
    registers,
)
from supi3.pinout import OPTICAL_REGISTERS
from supi3.tables import BIT_RATES, CLOCK_HZ, clk_conf_for
from support import bad

IN, OUT, BRANCH = Interface.IN, Interface.OUT, Interface.BRANCH
ALL = (True, True, True)
NO_BRANCH = (True, True, False)
RF = {OpticalMode.REGULATION: "00", OpticalMode.DIAGNOSTIC: "01"}
LIMIT_S = INIT_TIME_LIMIT_CLOCKS / CLOCK_HZ


def up_chip(rf: str = "00", bit_rate: int = BIT_RATES[0]) -> Supi3:
    """A bus terminal module in an Init-µP mode (BK-RB, Init-µP, Table 2-7), with a register file: it has all three
    interfaces, so reads 9 and 11 show its branch (OPT-55)."""
    return Supi3(decode("00011", rf=rf, clk_conf=clk_conf_for(bit_rate)))


def io_chip(rf: str = "00") -> Supi3:
    """The demo device (binary I/O, 8 IN / 8 OUT): no register file; its data cycles take the ring kernel; no branch
    interface (OPT-55)."""
    return Supi3(decode("10000", rf=rf))


def read_8_to_11(chip: Supi3) -> tuple[int, ...]:
    assert chip.registers is not None
    return tuple(chip.registers.value(name) for name in OPTICAL_REGISTERS)


# Mode and start ---------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(("rf", "mode"), [("00", OpticalMode.REGULATION), ("01", OpticalMode.DIAGNOSTIC),
                                          ("10", OpticalMode.OFF), ("11", OpticalMode.OFF)])  # fmt: skip
def test_mode_comes_from_rf(rf: str, mode: OpticalMode) -> None:
    """Table 2-2 and OPT-2: RF 00 regulation, 01 optical diagnostics, 10/11 copper."""
    assert up_chip(rf).optical_mode is mode
    assert io_chip(rf).optical_mode is mode


def test_ls_has_no_optics() -> None:
    """1.6: the SUPI 3 LS does not support optical regulation; calls change nothing, IN lengths are refused."""
    chip = Supi3(decode("10000", variant=Variant.LS))
    assert chip.optical_mode is OpticalMode.OFF
    chip.optical_start(NO_BRANCH)
    chip.optical_init_response(OUT, Response.DETECTED)
    chip.optical_test(OUT, False, False)
    chip.optical_length(OUT, 100, Medium.GLASS)
    chip.optical_init_timeout()
    assert chip.optical == OpticalStatus()
    assert not chip.optical_holding
    with pytest.raises(ChipArgumentError, match=r"interface must be Interface\.OUT or Interface\.BRANCH"):
        chip.optical_length(IN, 1, Medium.POLYMER)


@pytest.mark.parametrize(("c", "mfp"), [("10000", None), ("10011", "1110"), ("11011", "1110"), ("01000", None)])
def test_branch_refused_outside_the_bk_modes(c: str, mfp: str | None) -> None:
    """OPT-55: only a bus terminal module has the branch interface (Table 2-8: DI3, DO3_CU, FO3 on MFP10..8 in the
    BK modes; 1.6.3: MAUWS "for bus terminal modules only"); elsewhere a start with the branch in use, or a branch
    length, is refused by name and changes nothing."""
    chip = Supi3(decode(c, mfp, rf="00"))
    assert chip.terminal_interface is None
    for present in [(a, b, True) for a in (False, True) for b in (False, True)]:
        with pytest.raises(ChipArgumentError, match=r"present\[BRANCH\] must be False outside the bus terminal"):
            chip.optical_start(present)
    with pytest.raises(ChipArgumentError, match=r"interface must be Interface\.OUT outside the bus terminal"):
        chip.optical_length(BRANCH, 9, Medium.POLYMER)
    assert chip.optical == OpticalStatus()
    assert not chip.optical_holding


@pytest.mark.parametrize("c", ["00000", "00001", "00010", "00011", "00100"])
def test_every_bk_mode_has_the_branch(c: str) -> None:
    """Table 2-7: every BK mode starts its branch interface and measures its branch (read 9, OPT-55)."""
    chip = Supi3(decode(c, rf="00"))
    chip.optical_start(ALL)
    chip.optical_length(BRANCH, 9, Medium.POLYMER)
    assert chip.optical[BRANCH].phase is Phase.INIT
    assert chip.optical.length[1] == timer_code(9, chip.config.bit_rate, Medium.POLYMER)


@pytest.mark.parametrize("rf", ["10", "11"])
def test_copper_modes_change_nothing(rf: str) -> None:
    chip = up_chip(rf)
    chip.optical_start(ALL)
    chip.optical_length(BRANCH, 9, Medium.POLYMER)
    chip.optical_test(IN, False, True)
    assert chip.optical == OpticalStatus()
    assert read_8_to_11(chip) == (0, 0, 0, 0)


@pytest.mark.parametrize("mode", [OpticalMode.REGULATION, OpticalMode.DIAGNOSTIC])
@pytest.mark.parametrize("present", [(a, b, c) for a in (False, True) for b in (False, True) for c in (False, True)])
def test_start_uses_the_spec_for_each_interface(mode: OpticalMode, present: tuple[bool, bool, bool]) -> None:
    """1.6.1: interfaces in use initialize at MAX (regulation) or watch the reserve (diagnostics, OPT-2); the core
    is held only while one initializes."""
    chip = up_chip(RF[mode])
    chip.optical_start(present)
    phase = Phase.INIT if mode is OpticalMode.REGULATION else Phase.DIAGNOSTIC
    assert [tx.phase for tx in chip.optical.transmitters] == [phase if p else Phase.OFF for p in present]
    assert chip.optical_holding is (mode is OpticalMode.REGULATION and any(present))
    assert read_8_to_11(chip) == registers(chip.optical)


# Initialization ---------------------------------------------------------------------------------------------------


def test_initialization_ends_the_hold_and_fills_the_registers() -> None:
    """1.6.1: each "Light off" lowers by one; the first "Light on" raises by one and ends it (enable 1); NONE falls
    back to FIXED; the hold ends when no transmitter initializes (1.6 "the protocol core remains the reset state")."""
    chip = up_chip()
    chip.optical_start(ALL)
    for _ in range(4):
        chip.optical_init_response(OUT, Response.DETECTED)
    chip.optical_init_response(OUT, Response.NOT_DETECTED)
    assert chip.optical[OUT] == Transmitter(Phase.ONLINE, MAX_LEVEL - 3)
    chip.optical_init_response(BRANCH, Response.NONE)
    assert chip.optical[BRANCH] == Transmitter(Phase.FIXED)
    assert chip.optical_holding
    for _ in range(INIT_MAX_STEPS):
        chip.optical_init_response(IN, Response.DETECTED)
    assert chip.optical[IN] == Transmitter(Phase.ONLINE, MAX_LEVEL - INIT_MAX_STEPS)
    assert not chip.optical_holding
    # read 10: level 2 and enable; read 11: OUT level 12, BRANCH 15 (FIXED, enable 0); reads 8/9: enable bits.
    assert read_8_to_11(chip) == (0x80, 0x00, 0x82, 0xFC)
    chip.optical_init_response(IN, Response.NOT_DETECTED)  # not initializing any more: no change
    assert chip.optical[IN].level == MAX_LEVEL - INIT_MAX_STEPS


def test_not_detected_at_max_warns() -> None:
    """1.6.3: "Light on" at the very first step (level 15): up is impossible, the MAU warning comes on."""
    chip = up_chip()
    chip.optical_start((False, True, False))
    chip.optical_init_response(OUT, Response.NOT_DETECTED)
    assert chip.optical[OUT] == Transmitter(Phase.ONLINE, MAX_LEVEL, mau=True)


def test_budget_runs_out_in_chip_time() -> None:
    """OPT-5, OPT-20, OPT-56: 6 ms after the start (in the chip's time) the incoming interface, still initializing,
    falls back to FIXED at the first bus call at or after the limit; the branch's own 6 ms start there, and the hold
    ends when it runs out too; optical_init_timeout ends the running budget on request, one interface at a time in
    INIT_ORDER."""
    chip = up_chip()
    chip.poll(1e-3)
    chip.optical_start(ALL)
    chip.optical_init_response(OUT, Response.NOT_DETECTED)
    assert chip.due == clocks(1e-3) + INIT_TIME_LIMIT_CLOCKS
    chip.poll(1e-3 + LIMIT_S - 1 / CLOCK_HZ)
    assert chip.optical_holding
    chip.poll(1e-3 + LIMIT_S)
    assert chip.optical_holding
    assert [tx.phase for tx in chip.optical.transmitters] == [Phase.FIXED, Phase.ONLINE, Phase.INIT]
    assert chip.due == clocks(1e-3) + 2 * INIT_TIME_LIMIT_CLOCKS
    chip.poll(1e-3 + 2 * LIMIT_S)
    assert not chip.optical_holding
    assert [tx.phase for tx in chip.optical.transmitters] == [Phase.FIXED, Phase.ONLINE, Phase.FIXED]
    other = up_chip()
    other.optical_start(ALL)
    for done in regulation.INIT_ORDER:
        assert other.optical_holding
        other.optical_init_timeout()
        assert other.optical[done].phase is Phase.FIXED
    assert not other.optical_holding


def test_each_interface_has_its_own_budget_from_the_end_of_the_one_before() -> None:
    """OPT-56 (1.6.1: an interface's initialization takes 6 ms at most, the outgoing interface's after the direction
    change): the incoming interface's budget counts from the start, the branch's from the incoming one's end, the
    outgoing one's from the branch's end, whatever ends them (a response or a timeout); an interface that finishes
    out of turn moves no budget."""
    chip = up_chip()
    chip.optical_start(ALL, 0.0)
    chip.optical_init_response(OUT, Response.NONE)  # out of turn: IN's budget runs on
    assert chip.due == INIT_TIME_LIMIT_CLOCKS
    chip.poll(1e-3)
    chip.optical_init_response(IN, Response.NOT_DETECTED)
    assert chip.due == clocks(1e-3) + INIT_TIME_LIMIT_CLOCKS  # the branch's 6 ms
    chip.poll(1e-3 + LIMIT_S)
    assert [tx.phase for tx in chip.optical.transmitters] == [Phase.ONLINE, Phase.FIXED, Phase.FIXED]
    assert not chip.optical_holding
    other = up_chip()
    other.optical_start((True, True, False), 0.0)
    other.poll(LIMIT_S)  # IN timed out; OUT's 6 ms from there, not from the start
    assert other.optical[IN].phase is Phase.FIXED and other.optical_holding
    other.poll(2 * LIMIT_S - 1e-6)
    assert other.optical_holding
    other.optical_init_response(OUT, Response.NOT_DETECTED)
    assert other.optical[OUT].phase is Phase.ONLINE and not other.optical_holding


def test_a_second_start_restarts_the_budget() -> None:
    """A start while still initializing (no reset between: the line side's choice) counts 6 ms from itself."""
    chip = up_chip()
    chip.optical_start(ALL)
    chip.poll(LIMIT_S / 2)
    chip.optical_start(ALL)
    assert chip.due == clocks(LIMIT_S / 2) + INIT_TIME_LIMIT_CLOCKS
    chip.poll(LIMIT_S)
    assert chip.optical_holding
    assert {tx.phase for tx in chip.optical.transmitters} == {Phase.INIT}


def test_reset_turns_every_transmitter_off_and_keeps_lengths() -> None:
    """1.6: "regulation is reset for the reset period"; OPT-21: the lengths measured stay."""
    chip = up_chip()
    chip.optical_start(ALL)
    chip.optical_length(OUT, 40, Medium.GLASS)
    chip.reset(1e-3)
    assert chip.optical.transmitters == (Transmitter(),) * 3
    assert chip.optical.length[0] == timer_code(40, BIT_RATES[0], Medium.GLASS)
    assert not chip.optical_holding
    assert read_8_to_11(chip) == registers(chip.optical)
    chip.power_up()
    assert chip.optical == OpticalStatus()
    assert read_8_to_11(chip) == (0, 0, 0, 0)


# The core held --------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("path", ["chip", "kernel"])
def test_core_held_latches_nothing_until_initialized(path: str) -> None:
    """1.6, OPT-20: while held, data and ID cycles latch nothing and raise no event, on the per-chip path and the
    ring kernel's run; after the initialization the same cycle latches."""
    chip = io_chip()
    chip.reset(0.0)
    chip.optical_start((False, True, False))

    def cycle(now: float, out: bytes) -> None:
        if path == "chip":
            chip.load(Cycle.DATA, now)
            chip.latch(Cycle.DATA, out, now)
        else:
            Supi3.data_kernel.load((chip,), now)
            Supi3.data_kernel.latch((chip,), (out,), now)

    cycle(1e-4, b"\x5a")
    chip.latch(Cycle.ID, b"\x00\x01", 2e-4)
    chip.discard(Cycle.DATA, True, 3e-4)
    assert (chip.out_word, chip.bus_active, chip.watchdog_code, chip.te) == (0, False, None, False)
    assert chip.events["VALID"] == chip.events["INVALID"] == chip.events["ID_CYCLE"] == 0
    chip.optical_init_response(OUT, Response.NOT_DETECTED)
    cycle(4e-4, b"\x5a")
    assert (chip.out_word, chip.bus_active, chip.events["VALID"]) == (0x5A, True, 1)


def test_core_held_until_the_budget_ends_on_the_kernel_path() -> None:
    """The fast path honours the budgets' end (OPT-56: the incoming interface's 6 ms, then the outgoing one's): the
    first cycle at or after 12 ms latches."""
    chip = io_chip()
    chip.optical_start(NO_BRANCH)
    for now in (LIMIT_S / 2, LIMIT_S, 1.5 * LIMIT_S):
        Supi3.data_kernel.load((chip,), now)
        Supi3.data_kernel.latch((chip,), (b"\x11",), now)
        assert chip.out_word == 0
    Supi3.data_kernel.load((chip,), 2 * LIMIT_S)
    Supi3.data_kernel.latch((chip,), (b"\x22",), 2 * LIMIT_S)
    assert chip.out_word == 0x22
    assert [tx.phase for tx in chip.optical.transmitters] == [Phase.FIXED, Phase.FIXED, Phase.OFF]


# Lengths and tests --------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("bit_rate", BIT_RATES)
@pytest.mark.parametrize("medium", list(Medium))
def test_length_uses_the_chip_bit_rate(bit_rate: int, medium: Medium) -> None:
    """1.6.1, OPT-1: the timer result at the chip's bit rate gives the LENGTH code of reads 8/9."""
    chip = up_chip(bit_rate=bit_rate)
    for interface, metres in ((OUT, 100.0), (BRANCH, 5000.0)):
        count = timer_count(metres, bit_rate)
        chip.optical_length(interface, count, medium)
    assert chip.optical.length == (timer_code(timer_count(100.0, bit_rate), bit_rate, medium),
                                   timer_code(timer_count(5000.0, bit_rate), bit_rate, medium))  # fmt: skip
    assert chip.optical.medium == (medium, medium)
    assert read_8_to_11(chip) == registers(chip.optical)


def test_online_regulation_moves_the_level() -> None:
    """1.6.2, OPT-6: a failed test raises at once, DECREASE_AFTER passed ones lower, pass/fail holds."""
    chip = up_chip()
    chip.optical_start((False, True, False))
    chip.optical_init_response(OUT, Response.DETECTED)
    chip.optical_init_response(OUT, Response.NOT_DETECTED)  # ONLINE at 15
    chip.optical_test(OUT, True, True)
    chip.optical_test(OUT, True, True)
    assert chip.optical[OUT].level == MAX_LEVEL - 1
    chip.optical_test(OUT, True, False)
    assert chip.optical[OUT].level == MAX_LEVEL - 1
    chip.optical_test(OUT, False, False)
    assert (chip.optical[OUT].level, chip.optical[OUT].mau) == (MAX_LEVEL, True)
    assert read_8_to_11(chip) == registers(chip.optical)


def test_diagnostic_mode_tests_set_the_warning() -> None:
    """1.6.2, OPT-7, OPT-22: in optical diagnostics mode a test only moves the interface's MAU warning; an interface
    not in use ignores tests."""
    chip = up_chip("01")
    chip.optical_start((True, False, True))
    chip.optical_test(IN, False, True)
    assert chip.optical[IN] == Transmitter(Phase.DIAGNOSTIC, mau=True)
    chip.optical_test(IN, True, False)
    assert chip.optical[IN].mau
    chip.optical_test(IN, True, True)
    assert not chip.optical[IN].mau
    chip.optical_test(OUT, False, False)
    assert chip.optical[OUT] == Transmitter()


def test_binary_io_chip_keeps_the_status_only() -> None:
    chip = io_chip()
    assert chip.registers is None
    chip.optical_start(NO_BRANCH)
    chip.optical_init_response(IN, Response.NONE)
    assert chip.optical[IN].phase is Phase.FIXED


# Hostile input --------------------------------------------------------------------------------------------------


HOSTILE: list[tuple[str, Callable[[Supi3], object], str]] = [
    ("present list", lambda c: c.optical_start([True, True, True]), "present must be a tuple of 3 bools"),  # type: ignore[arg-type]
    ("present short", lambda c: c.optical_start((True, True)), "present must be a tuple of 3 bools"),  # type: ignore[arg-type]
    ("present ints", lambda c: c.optical_start((1, 0, 1)), "present must be a tuple of 3 bools"),  # type: ignore[arg-type]
    ("present None", lambda c: c.optical_start(None), "present must be a tuple of 3 bools"),  # type: ignore[arg-type]
    ("interface int", lambda c: c.optical_init_response(1, Response.NONE), "interface must be"),  # type: ignore[arg-type]
    ("response int", lambda c: c.optical_init_response(OUT, 1), "response must be"),  # type: ignore[arg-type]
    ("response str", lambda c: c.optical_init_response(OUT, "NONE"), "response must be"),  # type: ignore[arg-type]
    ("length interface", lambda c: c.optical_length("OUT", 1, Medium.GLASS), "interface must be"),  # type: ignore[arg-type]
    ("length IN", lambda c: c.optical_length(IN, 1, Medium.GLASS), r"interface must be Interface\.OUT"),
    ("count negative", lambda c: c.optical_length(OUT, -1, Medium.GLASS), "count must be"),
    ("count float", lambda c: c.optical_length(OUT, 1.0, Medium.GLASS), "count must be"),  # type: ignore[arg-type]
    ("count bool", lambda c: c.optical_length(OUT, True, Medium.GLASS), "count must be"),
    ("medium int", lambda c: c.optical_length(OUT, 1, 1), "medium must be"),  # type: ignore[arg-type]
    ("test interface", lambda c: c.optical_test(None, True, True), "interface must be"),  # type: ignore[arg-type]
    ("ack1 int", lambda c: c.optical_test(OUT, 1, True), "ack1 must be"),  # type: ignore[arg-type]
    ("ack2 None", lambda c: c.optical_test(OUT, True, None), "ack2 must be"),  # type: ignore[arg-type]
]  # fmt: skip


@pytest.mark.parametrize(("call", "message"), [case[1:] for case in HOSTILE], ids=[case[0] for case in HOSTILE])
@pytest.mark.parametrize("rf", ["00", "01", "11"])
def test_hostile_input_is_named_and_changes_nothing(call: Callable[[Supi3], object], message: str, rf: str) -> None:
    chip = up_chip(rf)
    chip.optical_start((True, True, False))
    before = (chip.optical, chip.optical_holding, read_8_to_11(chip), chip.due)
    with pytest.raises(ChipArgumentError, match=message):
        call(chip)
    assert (chip.optical, chip.optical_holding, read_8_to_11(chip), chip.due) == before


@pytest.mark.parametrize("rf", ["00", "01"])
def test_calls_out_of_order_are_harmless(rf: str) -> None:
    """A response, test or timeout before any start, and a response after the initialization, change nothing."""
    chip = up_chip(rf)
    chip.optical_init_response(OUT, Response.DETECTED)
    chip.optical_test(OUT, False, False)
    chip.optical_init_timeout()
    assert chip.optical == OpticalStatus()
    assert not chip.optical_holding


# Properties over histories --------------------------------------------------------------------------------------

INTERFACES = st.sampled_from(list(Interface))
OPERATIONS = st.one_of(
    st.tuples(st.just("start"), st.tuples(st.booleans(), st.booleans(), st.booleans())),
    st.tuples(st.just("response"), st.tuples(INTERFACES, st.sampled_from(list(Response)))),
    st.tuples(st.just("response"), st.tuples(INTERFACES, st.just(Response.DETECTED))),
    st.tuples(st.just("test"), st.tuples(INTERFACES, st.booleans(), st.booleans())),
    st.tuples(st.just("length"), st.tuples(st.sampled_from([OUT, BRANCH]), st.integers(0, 20_000),
                                           st.sampled_from(list(Medium)))),
    st.tuples(st.just("timeout"), st.just(())),
    st.tuples(st.just("reset"), st.just(())),
    st.tuples(st.just("wait"), st.tuples(st.floats(0.0, 4e-3))),
)


@settings(max_examples=150)
@given(rf=st.sampled_from(["00", "01", "10"]), bit_rate=st.sampled_from(BIT_RATES),
       history=st.lists(OPERATIONS, max_size=60))  # fmt: skip
def test_histories_keep_the_invariants(rf: str, bit_rate: int, history: list[tuple[str, tuple[object, ...]]]) -> None:
    """Any history: levels in 1..15; the MAU warning comes on only at MAX and goes off only at MAX-2 in regulation
    mode (1.6.3, besides start and reset); the register file holds registers(status); the hold equals "some
    transmitter initializes" and ends 6 ms after the start at the latest."""
    chip = up_chip(rf, bit_rate)
    now = 0.0
    started = -1.0
    for name, args in history:
        before = chip.optical
        if name == "start":
            chip.optical_start(args)  # type: ignore[arg-type]
            started = now
        elif name == "response":
            chip.optical_init_response(*args)  # type: ignore[arg-type]
        elif name == "test":
            chip.optical_test(*args)  # type: ignore[arg-type]
        elif name == "length":
            chip.optical_length(*args)  # type: ignore[arg-type]
        elif name == "timeout":
            chip.optical_init_timeout()
        elif name == "reset":
            chip.reset(now)
        else:
            now += args[0]  # type: ignore[operator]
            chip.poll(now)
        status = chip.optical
        assert read_8_to_11(chip) == registers(status)
        assert chip.optical_holding is any(tx.phase is Phase.INIT for tx in status.transmitters)
        if chip.optical_holding:  # each interface in turn, 6 ms at most each (OPT-56)
            assert clocks(now) < clocks(started) + len(regulation.INIT_ORDER) * INIT_TIME_LIMIT_CLOCKS
        for old, new in zip(before.transmitters, status.transmitters, strict=True):
            assert 1 <= new.level <= MAX_LEVEL
            if name in ("start", "reset") or new.phase is Phase.DIAGNOSTIC:
                continue
            if new.mau and not old.mau:
                assert new.level == MAX_LEVEL
            if old.mau and not new.mau:
                assert new.level == MAX_LEVEL - 2


def test_start_at_a_bus_time_counts_the_budget_from_it() -> None:
    """OPT-5, OPT-20: the 6 ms budget runs from the time the end of the reset reaches the chip."""
    chip = up_chip("00")
    chip.optical_start(ALL, 1.0)
    chip.poll(1.0 + regulation.INIT_TIME_LIMIT_S * 0.99)
    assert chip.optical_holding
    chip.poll(1.0 + regulation.INIT_TIME_LIMIT_S * 1.01)
    assert chip.optical_holding  # the incoming interface fell back; the branch has its own 6 ms (OPT-56)
    assert [tx.phase for tx in chip.optical.transmitters] == [Phase.FIXED, Phase.INIT, Phase.INIT]
    chip.poll(1.0 + regulation.INIT_TIME_LIMIT_S * 3.01)  # one call past all three budgets
    assert not chip.optical_holding
    assert all(tx.phase is Phase.FIXED for tx in chip.optical.transmitters)
    assert chip.due == Supi3(chip.config).due
    before = chip.optical
    for now in (-1.0, float("nan"), "1.0", True):
        with pytest.raises(ChipArgumentError):
            chip.optical_start(ALL, bad(now))
    assert chip.optical == before


def test_fo_leds_show_the_optical_block() -> None:
    """Table 3-17, OPT-8, DG-7: in READY (bus not active) a fallen-back interface lights its FO LED."""
    chip = up_chip("00")
    chip.optical_start(ALL, 0.0)
    chip.optical_init_response(IN, Response.NONE)
    chip.optical_init_response(OUT, Response.NOT_DETECTED)
    assert chip.diagnostic_outputs.fo == (True, False, False)

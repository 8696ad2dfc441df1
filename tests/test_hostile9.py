"""Hostile inputs, orders and histories against the INTERBUS, tree, optical, verification, register-map and
command-line entries (a user's review, round 9): the lockstep's stimulus (:func:`supi3.verif.layout.stimulus_array`
behind ``Lockstep.stimulus``, ``run``, ``run_batch`` and the Amaranth path; :func:`supi3.verif.lockstep.react`; the
cocotb coroutine :func:`supi3.verif.cocotb_lockstep.lockstep`), the register map's byte helpers
(:func:`supi3.regmap.encode_command`, :func:`~supi3.regmap.decode_command`, :func:`~supi3.regmap.decode_set`,
``ByteLayout.encode`` and ``decode``) and exporters (:func:`~supi3.regmap.render`, ``to_html``, ``write_checked_in``),
the data cycle time (:func:`supi3.timing.data_cycle_time_s`, ``supi3 timing --bytes``, A23), ``supi3 campaign --mix``,
a bus's ``transfer`` (:class:`~supi3.interbus.ring.Ring`, :class:`~supi3.optical.ring.OpticalRing`: its arguments
checked before the ring changes anything), and the master's state across a ring change (commands by ring position,
reported PF bits, ``rediscover=False``: A19; a ring grown past ``max_devices``: M31); and what held: any history of
branch switching, extended closures, cuts and repairs (forward, return, DI3), bit errors, power-ups, idle stretches,
ALARM outputs and Alarm Stops on a transaction-level tree leaves no latched output changed by a cycle that failed,
every latched data cycle delivered, and the master never stuck.

Every bad input is refused by name (which argument, which rule, which value), never a traceback or a silent guess; a
refused call leaves no trace.
"""

from __future__ import annotations

import asyncio
import math
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3 import cli, timing
from supi3.config import decode
from supi3.errors import ArgumentError, Supi3Error
from supi3.interbus import wire
from supi3.interbus.device import PlainDevice
from supi3.interbus.errors import InterbusError
from supi3.interbus.master import Master
from supi3.interbus.ring import (
    BitFlip,
    BranchKind,
    CorruptLoopback,
    ErrorKind,
    Ring,
    Transfer,
    Truncate,
    _devices,
    return_inputs,
)
from supi3.interbus.wire import Cycle
from supi3.model.chip import Supi3
from supi3.optical.link import FibreLink
from supi3.optical.ring import OpticalRing
from supi3.pinlevel import Pin, PinSpecError
from supi3.regmap import (
    SET,
    RegisterMapError,
    decode_command,
    decode_set,
    encode_command,
    render,
    to_html,
    write_checked_in,
)
from supi3.verif.cocotb_lockstep import lockstep
from supi3.verif.example import ShiftCounterModel
from supi3.verif.layout import stimulus_array
from supi3.verif.lockstep import react
from test_model_pinring_tree import RECOVERY, tl_tree

# -- the lockstep's stimulus --------------------------------------------------------------------------------------

PINS = [Pin("a", 4), Pin("b", 1)]
ROWS = [{"a": 1}, {"a": 2, "b": 1}, {"a": 3}]
ARRAY = np.array([[1, 0], [2, 1], [3, 1]])


@pytest.mark.parametrize("max_cycles", [-1, 1.5, True, "2", math.nan], ids=repr)
@pytest.mark.parametrize("form", ["array", "rows"])
def test_max_cycles_that_is_no_count_is_refused_in_both_forms(max_cycles: object, form: str) -> None:
    """``max_cycles=-1`` dropped the array's last cycle (a slice) but took no cycle of the rows; 1.5 was a
    TypeError of the slice for an array and 2 cycles for rows; ``True`` one cycle: now a named error for both."""
    stimulus = ARRAY if form == "array" else ROWS
    with pytest.raises(PinSpecError, match=r"^max_cycles must be an integer from 0, not "):
        stimulus_array(stimulus, PINS, max_cycles)  # type: ignore[arg-type]


def test_max_cycles_takes_numpy_integers_and_zero() -> None:
    assert stimulus_array(ARRAY, PINS, np.int64(2)).tolist() == [[1, 0], [2, 1]]  # type: ignore[arg-type]
    assert stimulus_array(ROWS, PINS, np.int32(2)).tolist() == [[1, 0], [2, 1]]  # type: ignore[arg-type]
    assert stimulus_array(ROWS, PINS, 0).shape == (0, 2)


@pytest.mark.parametrize("value", [1.7, "3", -1, -(2**70), True, None, math.nan, np.float64(2.0)], ids=repr)
def test_a_pin_value_that_is_no_level_is_refused_with_its_cycle(value: object) -> None:
    """A per-cycle dict's value was cast with ``int()``: 1.7 became 1, ``"3"`` 3 and ``True`` 1 (silent guesses);
    -1 and 2**70 ended in numpy's OverflowError, ``None`` in a TypeError, NaN in a ValueError."""
    with pytest.raises(PinSpecError, match=r"^cycle 1: input 'a' must be an integer from 0 to 0xf \(4 bits\), not "):
        stimulus_array([{"a": 1}, {"a": value}], PINS)  # type: ignore[dict-item]


def test_a_pin_value_too_wide_keeps_its_message_and_numpy_integers_pass() -> None:
    with pytest.raises(PinSpecError, match=r"^cycle 0: input 'a' = 0x10 exceeds 4 bits"):
        stimulus_array([{"a": 16}], PINS)
    with pytest.raises(PinSpecError, match=r"^cycle 0: input 'a' = 0x400000000000000000 exceeds 4 bits"):
        stimulus_array([{"a": 2**70}], PINS)  # was numpy's OverflowError
    assert stimulus_array([{"a": np.uint8(15), "b": np.int64(1)}], PINS).tolist() == [[15, 1]]  # type: ignore[dict-item]


@pytest.mark.parametrize(("stimulus", "message"), [
    (None, r"^stimulus must be an integer array \(cycles, inputs\) or an iterable of per-cycle dicts, not None"),
    ("ab", r"^stimulus must be an integer array"),
    ({"a": 1}, r"^stimulus must be an integer array"),
    ([{"a": 1}, 5], r"^cycle 1: stimulus must be a mapping of input pins to values, not 5"),
    (np.zeros((3, 2, 1), dtype=int), r"^array stimulus must have shape \(cycles, 2\), not \(3, 2, 1\)"),
])  # fmt: skip
def test_a_stimulus_that_is_no_stimulus_is_refused_by_name(stimulus: object, message: str) -> None:
    """``None`` was a TypeError, a string or a list of integers an AttributeError ('int' object has no attribute
    'items'); a 3-D array was flattened into a column (silently, for a model of one input)."""
    with pytest.raises(PinSpecError, match=message):
        stimulus_array(stimulus, PINS)  # type: ignore[arg-type]
    if isinstance(stimulus, np.ndarray):
        with pytest.raises(PinSpecError, match=r"^array stimulus must have shape \(cycles, 1\), not \(3, 2, 1\)"):
            stimulus_array(stimulus, [Pin("a", 1)])


@pytest.mark.parametrize(("cycles", "agent", "message"), [
    (-1, lambda *_: {"en": 1}, r"^cycles must be an integer from 0, not -1"),
    (1.5, lambda *_: {"en": 1}, r"^cycles must be an integer from 0, not 1.5"),
    (2, None, r"^agent must be a function agent\(cycle, outputs\) -> inputs, not None"),
    (2, lambda *_: [1], r"^cycle 0: stimulus must be a mapping of input pins to values, not \[1\]"),
    (2, lambda *_: {"din": 1.7}, r"^cycle 0: input 'din' must be an integer from 0 to 0xff \(8 bits\), not 1.7"),
    (2, lambda *_: {"en": True}, r"^cycle 0: input 'en' must be an integer from 0 to 0x1 \(1 bits\), not True"),
    (2, lambda *_: {"din": 300}, r"^cycle 0: input 'din' = 0x12c exceeds 8 bits"),
])  # fmt: skip
def test_a_reacting_agent_s_bad_inputs_are_refused_before_the_model_steps(cycles: object, agent: object,
                                                                          message: str) -> None:  # fmt: skip
    """``react`` kept its own copy of the per-cycle rule: ``cycles=-1`` gave an empty stimulus, 1.5 and an agent of
    ``None`` TypeErrors, a list an AttributeError, 1.7 and ``True`` were cast to 1, and 300 reached the model's
    ``step`` before the width check refused it. It now shares :func:`~supi3.verif.layout.apply_inputs`."""
    stepped: list[int] = []

    class Spy(ShiftCounterModel):
        def step(self, inputs: Mapping[str, int]) -> dict[str, int]:
            stepped.append(inputs["din"])
            return super().step(inputs)

    with pytest.raises(PinSpecError, match=message):
        react(Spy, agent, cycles)  # type: ignore[arg-type]
    assert all(0 <= level <= 0xFF for level in stepped)


@pytest.mark.parametrize(("stimulus", "message"), [
    ([{"en": 1}, {"din": 1.5}], r"^cycle 1: input 'din' must be an integer from 0 to 0xff \(8 bits\), not 1.5"),
    (np.zeros((2, 4), dtype=np.uint8), r"^array stimulus must have shape \(cycles, 5\), not \(2, 4\)"),
    (np.full((2, 5), 2, dtype=np.uint8), r"^cycle 0: input 'en' = 0x2 exceeds 1 bits"),
])  # fmt: skip
def test_the_cocotb_lockstep_checks_its_stimulus_before_the_clock_starts(stimulus: object, message: str) -> None:
    """The cocotb coroutine packed its stimulus unchecked: a list of dicts ended in an AttributeError, an array of
    the wrong width in a numpy error, a level too wide for its pin was driven into the design. It now takes what
    ``stimulus_array`` takes, checked first (``dut`` is never touched here)."""
    with pytest.raises(PinSpecError, match=message):
        asyncio.run(lockstep(None, ShiftCounterModel(), stimulus))  # type: ignore[arg-type]


# -- the register map's byte helpers ------------------------------------------------------------------------------

NOT_INTEGERS = [1.0, True, np.bool_(True), None, "3", [3]]


@pytest.mark.parametrize("value", NOT_INTEGERS, ids=repr)
def test_a_register_value_that_is_no_integer_is_refused_by_name(value: object) -> None:
    """``decode_command(1.0)`` and ``decode_set(1.5)`` were TypeErrors of ``&``, ``decode_set(None)`` one of
    ``<=``, ``encode_command(1.0)`` one of ``<<``, ``decode_command([3])`` the cache's (unhashable list);
    ``decode_command(True)`` read command byte 01h and ``decode_set(True)`` SET 01h (a bool taken for a byte)."""
    for call, name in ((decode_command, "CMD"), (decode_set, "SET"), (encode_command, "field A"),
                       (lambda v: SET.encode(EXTREG=v), "field EXTREG")):  # fmt: skip
        with pytest.raises(RegisterMapError, match=rf"^{name} must be an integer, not "):
            call(value)  # type: ignore[arg-type]


def test_a_numpy_byte_is_a_byte() -> None:
    """``decode_command(np.uint8(0x30))`` ended in numpy's OverflowError (``byte & ~mask``) instead of naming the
    reserved bits; ``np.int64(3)`` gave an address of type ``np.int64``."""
    with pytest.raises(RegisterMapError, match=r"^command byte 30h sets reserved bits 30h"):
        decode_command(np.uint8(0x30))  # type: ignore[arg-type]
    command = decode_command(np.uint8(0x4D))  # type: ignore[arg-type]
    assert (command.rd, command.wr, command.address) == (False, True, 13) and type(command.address) is int
    assert type(encode_command(np.int64(13), wr=True)) is int  # type: ignore[arg-type]
    assert decode_set(np.uint8(0x82)) == decode_set(0x82)  # type: ignore[arg-type]


@pytest.mark.parametrize("flag", [1, "x", None, 2], ids=repr)
def test_rd_and_wr_are_bools(flag: object) -> None:
    """``encode_command(3, rd="x")`` was int()'s ValueError, ``rd=1`` a command byte (the cached one of ``rd=True``
    once that was built: 1 == True to the cache): a flag is True or False."""
    encode_command(3, rd=True, wr=True)
    for name in ("rd", "wr"):
        with pytest.raises(RegisterMapError, match=rf"^{name} must be True or False, not "):
            encode_command(3, **{name: flag})  # type: ignore[arg-type]


def test_render_refuses_a_format_or_an_output_of_the_wrong_type(tmp_path: Path) -> None:
    """``render("md", "map.md")`` and ``to_html("site")`` were AttributeErrors ('str' object has no attribute
    'parent', 'mkdir'), ``write_checked_in(".")`` a TypeError (str / str), ``render(["md"])`` one too (unhashable
    list); nothing is written."""
    with pytest.raises(RegisterMapError, match=r"^out must be a pathlib.Path, not "):
        render("md", str(tmp_path / "map.md"))  # type: ignore[arg-type]
    with pytest.raises(RegisterMapError, match=r"^outdir must be a pathlib.Path, not "):
        to_html(str(tmp_path))  # type: ignore[arg-type]
    with pytest.raises(RegisterMapError, match=r"^root must be a pathlib.Path, not "):
        write_checked_in(str(tmp_path))  # type: ignore[arg-type]
    with pytest.raises(RegisterMapError, match=r"^format must be one of html, md, rdl, h, json, not \['md'\]"):
        render(["md"])  # type: ignore[arg-type]
    assert list(tmp_path.iterdir()) == []
    assert render("md", tmp_path / "map.md") == (tmp_path / "map.md").read_text(encoding="utf-8")


# -- the data cycle time (A23) and the command line -------------------------------------------------------------


def test_a_network_of_more_bytes_than_its_devices_hold_is_refused() -> None:
    """A23: ``data_cycle_time_s(32768, 1, ...)`` gave the cycle of one device of 32 kB, which Table 3-11 (at most
    32 words a device) rules out; the limit is 64 bytes a device, and it holds exactly."""
    with pytest.raises(timing.TimingError, match=r"^network byte count must be at most 64 for 1 device .*not 65"):
        timing.data_cycle_time_s(65, 1, 500_000)
    with pytest.raises(timing.TimingError, match=r"at most 128 for 2 devices"):
        timing.report(129, 500_000, 2)
    assert timing.data_cycle_time_s(64, 1, 500_000) > 0
    assert timing.data_cycle_time_s(timing.MAX_NETWORK_BYTES, timing.MAX_DEVICES, 2_000_000) > 0


def _main(capsys: pytest.CaptureFixture[str], argv: list[str]) -> tuple[int, str, str]:
    code = cli.main(argv)
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize(("argv", "message"), [
    (["timing", "--bytes", "32768"], "supi3: error: --bytes must be an integer from 0 to 64 (--devices 1 of at most "
                                     "32 words, Table 3-11 and A23), not 32768\n"),
    (["timing", "--bytes", "129", "--devices", "2"],
     "supi3: error: --bytes must be an integer from 0 to 128 (--devices 2 of at most 32 words, Table 3-11 and A23), "
     "not 129\n"),
    (["campaign", "--mix", "", "--cycles", "5", "--fidelity", "ring"],
     "supi3: error: --mix must be EVENT=WEIGHT pairs separated by commas, not ''\n"),
])  # fmt: skip
def test_the_command_line_names_what_it_cannot_take(capsys: pytest.CaptureFixture[str], argv: list[str],
                                                    message: str) -> None:  # fmt: skip
    """``supi3 timing --bytes 32768`` (one device) printed a cycle no ring can have; ``supi3 campaign --mix ""`` ran
    the default mix, which the user had not asked for (an empty option taken as none). Exit 2, one line."""
    assert _main(capsys, argv) == (2, "", message)


# -- a refused transfer leaves no trace -------------------------------------------------------------------------


@pytest.mark.parametrize("data", [5, None, "ab", [0x3C, 0x5A]], ids=repr)
def test_a_transfer_of_no_bytes_is_refused_by_name(data: object) -> None:
    """``Ring.transfer(Cycle.ID, 5)`` sent a frame of five zero bytes (``bytes(5)``, a silent guess), a list its bytes;
    ``None`` and a string were TypeErrors, and so was any of them on a tree or an optical ring (``len(data)``)."""
    for ring in (Ring([PlainDevice(0xBF, 1)]), tl_tree(BranchKind.LOCAL, 1), _optical_ring(20.0)):
        with pytest.raises(ArgumentError, match=r"^data must be bytes, not "):
            ring.transfer(Cycle.ID, data)  # type: ignore[arg-type]


def _optical_ring(metres: float) -> OpticalRing:
    chips = [Supi3(decode("10000", rf="00")) for _ in range(3)]
    return OpticalRing(chips, [FibreLink(20.0), FibreLink(metres), FibreLink(20.0)], seed=5)


def _optical_history(refuse: bool) -> list[tuple[bool, Cycle | None, list[object]]]:
    ring = _optical_ring(104.0)  # a marginal fibre: its bit errors are drawn per frame (OPT-47)
    master = Master(ring)
    seen: list[tuple[bool, Cycle | None, list[object]]] = [(master.start().ok, None, [])]
    for _ in range(30):
        if refuse:
            with pytest.raises(ArgumentError, match=r"^close_after must be an integer >= 0, not -1"):
                ring.transfer(Cycle.DATA, wire.LOOPBACK_BYTES_ON_LINE, -1)
        result = master.cycle()
        seen.append((result.ok, result.cycle, [(d.kind, d.location) for d in result.diagnostics]))
    return seen


def test_a_refused_transfer_draws_no_bit_error_of_a_marginal_fibre() -> None:
    """``OpticalRing.transfer`` set the fibres' faults (drawing from the ring's seeded bit errors) before its ring
    refused ``close_after=-1``: a history with refused calls in it failed other cycles than the same history without
    them. The arguments are now checked first (``ring.check_transfer``), on every ring."""
    plain = _optical_history(False)
    assert plain == _optical_history(True)
    assert any(not ok for ok, _, _ in plain[1:])


# -- M31: a ring grown past the master's discovery window ------------------------------------------------------


def test_devices_added_past_max_devices_are_not_located_at_the_return_line() -> None:
    """M31: ``Master(ring, max_devices=2)`` on two devices, a third appended: every cycle reported a loopback error at
    position 3 ("segment search: the return line"), a wrong location, for good. Nothing proves the return line: a
    ring longer than the discovery window looks the same. With the protocol's 512 the return line stands."""
    ring = Ring([PlainDevice(0xBF, 1) for _ in range(2)])
    master = Master(ring, max_devices=2)
    assert master.start().ok
    ring.devices.append(PlainDevice(0xBF, 1))
    for _ in range(3):
        (diagnostic,) = master.cycle().diagnostics
        assert diagnostic.location is None and "more devices than max_devices (2)" in diagnostic.detail
    wide = Ring([PlainDevice(0xBF, 1) for _ in range(2)])
    default = Master(wide)
    assert default.start().ok
    wide.inject(CorruptLoopback(3, 0x1234, None))
    located = [d.location for _ in range(3) for d in default.cycle().diagnostics]
    assert located and set(located) == {3}


# -- A19: commands by ring position do not outlive their table ----------------------------------------------------


def test_a_command_by_position_is_not_sent_to_the_device_a_ring_change_moved_there() -> None:
    """A19: ``quit_peripheral_error(3)`` and ``processor_command(4, ...)`` waiting when device 1 was removed: the
    configuration error dropped the table, but the quit went out in the first ID cycle on the new one, to ring
    position 3, now the device that was 4 (a Quit Peripheral Error for a fault it may not have, the one at 2 never
    acknowledged). Commands not yet sent are dropped with the table; the application sends them again."""
    ring = Ring([PlainDevice(0xBF, 1) for _ in range(4)])
    master = Master(ring)
    assert master.start().ok
    words: list[list[int]] = []
    transfer = ring.transfer

    def spy(cycle: Cycle, data: bytes, close_after: int | None = None) -> Transfer:
        if cycle is Cycle.ID and len(data) < 2 * wire.MAX_DEVICES:
            words.append([int.from_bytes(data[k : k + 2], "little") for k in range(2, len(data), 2)])
        return transfer(cycle, data, close_after)

    ring.transfer = spy  # type: ignore[method-assign]
    master.quit_peripheral_error(3)
    master.processor_command(4, 0x55)
    del ring.devices[0]
    kinds = [d.kind for _ in range(4) for d in master.cycle().diagnostics]
    assert kinds == [ErrorKind.CONFIGURATION]
    assert words[0] == [0x5510, 0x8, 0, 0]  # the commands went out once, in the cycle that found the change
    assert all(not any(w) for w in words[1:]), words


def test_a_peripheral_fault_moved_onto_a_reported_position_is_reported() -> None:
    """A19: device A's PF reported at position 1 (0BB1h), then A removed while device B, behind it, raised its own PF:
    B moved to position 1, whose PF the master took as the one already reported, and B's fault was never reported
    (a message lost). The reported PF bits are dropped with the table: B's is reported on the new one."""
    a, b = PlainDevice(0xBF, 1), PlainDevice(0xBF, 1)
    ring = Ring([a, b])
    master = Master(ring)
    assert master.start().ok
    a.set_peripheral_fault(True)
    assert [(d.kind, d.location) for _ in range(3) for d in master.cycle().diagnostics] == [
        (ErrorKind.PERIPHERAL_FAULT, 1)]
    b.set_peripheral_fault(True)
    del ring.devices[0]
    seen = [(d.kind, d.location) for _ in range(5) for d in master.cycle().diagnostics]
    assert seen == [(ErrorKind.CONFIGURATION, 2), (ErrorKind.PERIPHERAL_FAULT, 1)]


def test_a_stopped_master_waits_for_start_in_every_cycle_entry() -> None:
    """A19: with ``rediscover=False`` a configuration error stops the master until ``start()``; ``cycle()`` refused,
    but ``id_cycle()`` ran a discovery, rebuilt the table and cleared ``stopped``: running again without the Alarm
    Stop the rule asks for. Every cycle entry now refuses alike; ``start()`` runs."""
    ring = Ring([PlainDevice(0xBF, 1) for _ in range(3)])
    master = Master(ring, rediscover=False)
    assert master.start().ok
    del ring.devices[1]
    assert [d.kind for d in master.cycle().diagnostics] == [ErrorKind.CONFIGURATION] and master.stopped
    for entry in (master.cycle, master.id_cycle, master.data_cycle):
        with pytest.raises(InterbusError):
            entry()
        assert master.stopped and master.config is None
    assert master.start().ok and not master.stopped


# -- what held: histories on a transaction-level tree -------------------------------------------------------------

STEPS = ["on", "off", "extended", "cut", "back", "di3", "repair", "start", "power", "idle", "flip", "alarm"]


def _step(ring: Ring, master: Master, step: str, k: int, data: st.DataObject) -> None:
    """One step of a tree history; ``k`` a physical position of the tree (1 to N); calls the tree refuses are
    skipped (the test of those is elsewhere: test_hostile6, test_hostile7)."""
    bk = next((e.ring_position for e in master.config or () if e.id_code in (0x04, 0x08, 0x0C)), None)
    if step in ("on", "off", "extended") and bk is not None:
        master.switch_branch(bk, step != "off", step == "extended")
    elif step == "alarm" and bk is not None:
        master.set_alarm_output(bk, True)
    elif step == "cut":
        ring.cut(k, True)
    elif step == "back" and k in return_inputs(ring._tree):
        ring.cut(k, False)
    elif step == "di3":
        ring.cut(2, False, branch=True)
    elif step == "repair":
        ring.clear_faults()
        ring.idle(10 * wire.STATUS_TELEGRAM_BITS / ring.bit_rate)  # M21
    elif step == "start":
        master.start()
    elif step == "power":
        ring.power_up(k)
    elif step == "idle":
        ring.idle(data.draw(st.sampled_from([1e-5, 0.011, 0.025])))
    elif step == "flip":
        line = min(k, len(ring.devices) + 1)
        faults: list[BitFlip | Truncate | CorruptLoopback] = [BitFlip(line, 30, 2), Truncate(line, 1, 1),
                                                              CorruptLoopback(line, 0x1234, 1)]  # fmt: skip
        ring.inject(data.draw(st.sampled_from(faults)))


def _checked_cycle(ring: Ring, master: Master, data: st.DataObject) -> None:
    """One of the master's cycles with fresh OUT data: a cycle that does not latch a data cycle changes no chip's
    outputs (but to zeros, by a reset), a latched data cycle delivers what the master sent to every chip."""
    if master.config is not None and len(master.config) == len(ring.devices):
        for entry in master.config:
            if entry.data_bytes:
                master.set_outputs(entry.ring_position, data.draw(st.binary(min_size=entry.data_bytes,
                                                                            max_size=entry.data_bytes)))  # fmt: skip
    chips = [d for d in _devices(ring._tree) if isinstance(d, Supi3)]
    before = [c.out_word for c in chips]
    result = master.cycle()
    latched = result.ok and result.cycle is Cycle.DATA
    if not latched:
        assert all(c.out_word in (old, 0) for c, old in zip(chips, before, strict=True)), result
        return
    assert master.config is not None
    for entry in master.config:
        chip = ring.devices[entry.ring_position - 1]
        assert isinstance(chip, Supi3)
        assert chip.out_word == int.from_bytes(master.outputs(entry.ring_position), "big") or not entry.data_bytes


@settings(max_examples=30, deadline=None)
@given(kind=st.sampled_from([BranchKind.REMOTE, BranchKind.LOCAL, BranchKind.LBD_MR, BranchKind.LBD_OR]),
       m=st.integers(1, 2), history=st.lists(st.tuples(st.sampled_from(STEPS), st.integers(1, 5)), max_size=6),
       data=st.data())  # fmt: skip
def test_no_failed_cycle_changes_outputs_over_any_tree_history(kind: BranchKind, m: int,
                                                               history: list[tuple[str, int]],
                                                               data: st.DataObject) -> None:  # fmt: skip
    """What held: over any history of switching a branch off, on and on extended, cuts of forward lines, return lines
    and the BK's DI3, repairs, bit errors, power-ups, idle stretches past the 10 ms closure and the 20 ms time-out,
    ALARM outputs and Alarm Stops, each followed by two of the master's cycles, a cycle that fails changes no chip's
    outputs, a latched data cycle delivers every device's OUT data, and after a repair the master latches a data
    cycle on a table as long as the data path within its recovery."""
    ring = tl_tree(kind, m)
    master = Master(ring, max_devices=16)
    master.start()
    for step, k in history:
        _step(ring, master, step, min(k, m + 3), data)
        for _ in range(2):
            _checked_cycle(ring, master, data)
    ring.clear_faults()
    ring.idle(10 * wire.STATUS_TELEGRAM_BITS / ring.bit_rate)
    for _ in range(RECOVERY):
        result = master.cycle()
        if result.ok and result.cycle is Cycle.DATA:
            break
    else:
        raise AssertionError(f"stuck: {master.diagnostics[-3:]}")
    assert master.config is not None and len(master.config) == len(ring.devices)


def test_every_refusal_here_is_a_supi3_error() -> None:
    """The errors above are the project's (an application catches :class:`~supi3.errors.Supi3Error`)."""
    assert issubclass(PinSpecError, Supi3Error) and issubclass(RegisterMapError, Supi3Error)
    assert issubclass(timing.TimingError, Supi3Error)

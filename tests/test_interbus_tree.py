"""A ring that is a tree (manual 2.4, Figure 1-10): bus terminal modules with remote bus and local bus branches in
the transaction-level ring, the master switching branches, CONF reconfiguration requests, the extended BK function
(docs/interbus.md "Tree", docs/assumptions/bus-terminal.md)."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.config import decode
from supi3.errors import ArgumentError
from supi3.interbus import wire
from supi3.interbus.device import PlainDevice
from supi3.interbus.errors import InterbusError
from supi3.interbus.link import Device
from supi3.interbus.master import Master
from supi3.interbus.ring import Branch, BranchKind, DeadLine, ErrorKind, ReturnBreak, Ring
from supi3.interbus.wire import Cycle
from supi3.model.bus_terminal import BRANCH_SILENCE_S, CONF_PIN, LBST_PIN
from supi3.model.chip import Supi3
from support import terminal

RECOVERY_CYCLES = 12


def healthy(master: Master, ring: Ring) -> int:
    """Cycles until a data cycle is latched on a table that matches the ring (the master is never stuck)."""
    for k in range(1, RECOVERY_CYCLES + 1):
        result = master.cycle()
        if result.ok and result.cycle is Cycle.DATA:
            assert master.config is not None and len(master.config) == len(ring.devices)
            return k
    raise AssertionError(f"stuck: {master.diagnostics[-3:]}")


def figure_1_10() -> tuple[Ring, Master, dict[str, Supi3]]:
    """Remote bus: a device, a BK-RB whose remote bus branch holds a device and a BK-LBD (4 LBD-MR devices), a
    BK-LB with 2 local bus devices, a BK-LBD with 3 LBD-OR devices, a last device."""
    bks = {name: terminal(kind) for name, kind in
           [("rb", "BK-RB"), ("inner", "BK-LBD"), ("lb", "BK-LB"), ("or", "BK-LBD")]}  # fmt: skip
    inner = Branch(bks["inner"], [PlainDevice(0xBF, 0b01001) for _ in range(4)], BranchKind.LBD_MR)
    ring = Ring([
        PlainDevice(0x03, 0b01001),
        Branch(bks["rb"], [PlainDevice(0x02, 0b01001), inner], BranchKind.REMOTE),
        Branch(bks["lb"], [PlainDevice(0xBE, 0b00001), PlainDevice(0xBD, 0b00001)], BranchKind.LOCAL),
        Branch(bks["or"], [PlainDevice(0xB3, 0b01001) for _ in range(3)], BranchKind.LBD_OR),
        PlainDevice(0x01, 0b01001),
    ])  # fmt: skip
    master = Master(ring, max_devices=32)  # a short discovery: switched-off devices stay below the 20 ms silence
    assert master.start().ok
    healthy(master, ring)
    return ring, master, bks


def numbers(master: Master) -> list[str]:
    assert master.config is not None
    return [entry.number for entry in master.config]


def test_the_tree_flattens_in_data_path_order_and_numbers_like_a_g4_master() -> None:
    ring, master, bks = figure_1_10()
    assert ring.tree and len(ring.devices) == 16
    assert ring.devices[1] is bks["rb"] and ring.devices[3] is bks["inner"] and ring.devices[8] is bks["lb"]
    assert numbers(master) == ["1.0", "2.0", "3.0", "4.0", "4.1", "4.2", "4.3", "4.4", "5.0", "5.1", "5.2",
                               "6.0", "6.1", "6.2", "6.3", "7.0"]  # fmt: skip
    assert ring.spans == [(2, 6, BranchKind.REMOTE), (4, 4, BranchKind.LBD_MR), (9, 2, BranchKind.LOCAL),
                          (12, 3, BranchKind.LBD_OR)]  # fmt: skip
    master.set_outputs("6.2", b"\x5a")
    healthy(master, ring)
    assert ring.devices[13].outputs == b"\x5a"  # type: ignore[attr-defined]


def test_a_flat_ring_is_no_tree() -> None:
    ring = Ring([PlainDevice(0x03, 0b01001)])
    assert not ring.tree and ring.spans == []
    with pytest.raises(InterbusError, match="return line"):
        ring.inject(ReturnBreak(1))
    with pytest.raises(ArgumentError, match=r"^position must be .*not into the last of the ring"):
        ring.cut(1, False)


def test_a_flat_ring_breaks_its_return_lines_by_one_rule() -> None:
    """BK-59: in a flat ring every device but the last has a return input from the next (``return_inputs``): a
    ``ReturnBreak`` or ``cut(k, False)`` there, refused by name at the last device and outside the ring."""
    ring = Ring([PlainDevice(0x03, 0b01001) for _ in range(3)])
    master = Master(ring, locate=True)
    assert master.start().ok
    ring.inject(ReturnBreak(2))
    found = master.cycle().diagnostics[0]
    assert (found.kind, found.location, found.return_line) == (ErrorKind.DEAD_LINE, 3, False)
    ring.clear_faults()
    ring.cut(1, False)
    assert master.cycle().diagnostics[0].location == 2
    with pytest.raises(InterbusError, match=r"a return line enters only .*not the last of the ring"):
        ring.inject(ReturnBreak(3))
    for bad in (0, 3, 4):
        with pytest.raises(ArgumentError, match=r"^position must be"):
            ring.cut(bad, False)


def test_master_switches_a_branch_off_and_on_without_a_configuration_error() -> None:
    ring, master, bks = figure_1_10()
    master.clear_diagnostics()
    master.switch_branch("2.0", False)  # the remote bus branch with the nested BK-LBD
    healthy(master, ring)
    assert numbers(master) == ["1.0", "2.0", "3.0", "3.1", "3.2", "4.0", "4.1", "4.2", "4.3", "5.0"]
    master.switch_branch("3.0", False)
    healthy(master, ring)
    assert len(ring.devices) == 8
    master.switch_branch(2, True)
    healthy(master, ring)
    assert len(ring.devices) == 14 and ring.devices[3] is bks["inner"]
    assert master.diagnostics == []


def test_switched_off_devices_hear_nothing_and_reset_after_the_silence_timeout() -> None:
    ring, master, _ = figure_1_10()
    device = ring.devices[12]
    assert isinstance(device, PlainDevice)
    resets = device.resets
    master.switch_branch("6.0", False)
    healthy(master, ring)
    ring.idle(wire.IDLE_TIMEOUT_S / 2)
    assert device.resets == resets
    ring.idle(wire.IDLE_TIMEOUT_S)
    assert device.resets == resets + 1
    ring.idle(wire.IDLE_TIMEOUT_S * 3)
    assert device.resets == resets + 1  # once


def test_a_fault_stays_on_its_line_while_branches_switch() -> None:
    ring, master, _ = figure_1_10()
    master.switch_branch("5.0", True, extended=True)  # the BK-LB
    healthy(master, ring)
    ring.inject(DeadLine(10))  # into device 5.1
    for _ in range(40):
        master.cycle()
        if master.config is not None and len(master.config) == 14:
            break
    healthy(master, ring)  # the BK closed its branch: the break sleeps out of the data path
    assert len(ring.devices) == 14
    ring.inject(DeadLine(13))  # into device 6.2, now at ring position 13
    assert master.cycle().diagnostics[0].location == 13
    ring.clear_faults()
    ring.inject(DeadLine(10))  # into device 6.1, now at ring position 10
    master.clear_diagnostics()
    ring.clear_faults()
    healthy(master, ring)
    ring.inject(DeadLine(11))  # into 6.2 ... then 5.1's break comes back with its branch
    ring.clear_faults()
    master.switch_branch("5.0", True)
    healthy(master, ring)
    assert len(ring.devices) == 16
    ring.inject(DeadLine(10))
    assert master.cycle().diagnostics[0].location == 10


def test_break_in_the_nested_lbd_branch_is_located_exactly() -> None:
    ring, master, _ = figure_1_10()
    ring.inject(ReturnBreak(6))  # return line into device 4.2, from 4.3
    found = master.cycle().diagnostics[0]
    assert (found.location, found.device, found.return_line) == (6, "4.2", True)
    assert "counted 2" in found.detail


def test_return_break_in_a_branch_without_diagnostics_is_where_the_search_finds_it() -> None:
    ring, master, _ = figure_1_10()
    ring.inject(ReturnBreak(9))  # BK-LB's return input: the ring fails first when closed after 5.1
    found = master.cycle().diagnostics[0]
    assert (found.location, found.return_line) == (10, False)


@pytest.mark.parametrize(("cut", "found"), [(1, 2), (2, 9), (9, 12), (12, 16)])
def test_a_remote_bus_return_break_is_located_behind_the_branches(cut: int, found: int) -> None:
    """BK-59: the remote bus's return input into ``cut`` (1.0, the BK-RB 2.0, the BK-LB 5.0, the BK-LBD 6.0) from the
    next remote bus device: nothing comes back (a dead line); the segment search finds the ring failing first when
    closed after that device, behind the branches between (2.0's nested BK-LBD with them: the return line into 2.0
    comes from 5.0, at 9); no BK reports a break of its branch."""
    ring, master, bks = figure_1_10()
    ring.cut(cut, False)
    diagnostic = master.cycle().diagnostics[0]
    assert (diagnostic.kind, diagnostic.location, diagnostic.return_line) == (ErrorKind.DEAD_LINE, found, False)
    assert "segment search" in diagnostic.detail
    assert not any(bk.diagnostic_outputs.e for bk in bks.values())
    ring.clear_faults()
    healthy(master, ring)


def test_conf_edge_is_an_acknowledged_reconfiguration_request() -> None:
    ring, master, bks = figure_1_10()
    master.clear_diagnostics()
    bks["or"].set_mfp_inputs((1 << LBST_PIN) | (1 << CONF_PIN))
    healthy(master, ring)
    healthy(master, ring)
    requests = [d for d in master.diagnostics if d.kind is ErrorKind.RECONFIGURATION_REQUEST]
    assert [(d.location, d.device) for d in requests] == [(12, "6.0")]
    assert bks["or"].bus_terminal is not None and not bks["or"].bus_terminal.conf_request
    assert not bks["or"].attention and master.branch_status == {}  # the table was read anew: statuses too
    master.clear_diagnostics()
    healthy(master, ring)
    assert master.diagnostics == []  # reported once


def test_extended_function_closes_a_broken_branch_and_the_master_says_which() -> None:
    ring, master, bks = figure_1_10()
    master.switch_branch("6.0", True, extended=True)
    healthy(master, ring)
    master.clear_diagnostics()
    last = ring.devices[-1]
    assert isinstance(last, PlainDevice)
    resets = last.resets
    start = ring.now
    ring.inject(DeadLine(14))
    for _ in range(40):
        master.cycle()
        if master.config is not None and len(master.config) == 13:
            break
    healthy(master, ring)  # the first data cycle on the new table brings the BK's ATTN
    healthy(master, ring)
    kinds = [(d.kind, d.location) for d in master.diagnostics]
    assert (ErrorKind.DEAD_LINE, 14) in kinds  # located first by the counter telegram
    assert any(k is ErrorKind.CONFIGURATION and where == 13 for k, where in kinds)  # the data length changed
    closed = [d for d in master.diagnostics if d.kind is ErrorKind.BRANCH_CLOSED]
    assert [(d.location, d.device) for d in closed] == [(12, "6.0")]
    assert bks["or"].bus_terminal is not None and bks["or"].bus_terminal.closures == 1
    assert ring.now - start >= BRANCH_SILENCE_S
    assert last.resets == resets  # closed before the remote bus behind the BK took the silence for a reset
    ring.clear_faults()
    master.switch_branch("6.0", True)
    healthy(master, ring)
    assert len(ring.devices) == 16


def test_a_local_bus_chip_behind_a_break_shows_the_line_interrupt_ahead() -> None:
    """The ring's silence time-out goes through ``Supi3.line_timeout`` (DG-3): IB_DIAG's 4 Hz cause at transaction
    level, for a local bus chip in a branch behind a break."""
    chip = Supi3(decode("01000"))  # LB-MR, 8 IN/8 OUT (Table 2-4)
    ring = Ring([Branch(terminal("BK-LB"), [PlainDevice(0xBF, 0b01001), chip], BranchKind.LOCAL)])
    master = Master(ring, max_devices=8)
    master.start()
    healthy(master, ring)
    ring.inject(DeadLine(2))
    master.cycle()
    ring.idle(2 * wire.IDLE_TIMEOUT_S)
    assert chip.line_interrupt and chip.line_silent
    ring.clear_faults()
    healthy(master, ring)
    assert not chip.line_interrupt and not chip.line_silent


@settings(max_examples=15)
@given(st.data())
def test_master_is_never_stuck_with_extended_bks_breaks_and_switching(data: st.DataObject) -> None:
    ring, master, _ = figure_1_10()
    for _ in range(data.draw(st.integers(1, 6), label="events")):
        bks = [k for k, d in enumerate(ring.devices, 1) if getattr(d, "terminal_interface", None)]
        event = data.draw(st.sampled_from(["break", "switch", "reset", "wait"]), label="event")
        if event == "switch":
            on = data.draw(st.booleans(), label="on")
            master.switch_branch(data.draw(st.sampled_from(bks), label="bk"), on, on and data.draw(st.booleans()))
        elif event == "reset":
            master.start()
        elif event == "wait":
            ring.idle(data.draw(st.sampled_from([BRANCH_SILENCE_S, 2 * wire.IDLE_TIMEOUT_S]), label="idle"))
        else:
            returns = [ReturnBreak(at) for at, _, _ in ring.spans]
            fault = data.draw(st.sampled_from([DeadLine(k) for k in range(1, len(ring.devices) + 2)] + returns))
            ring.inject(fault)
            for _ in range(data.draw(st.integers(1, 30), label="cycles")):
                master.cycle()
            ring.clear_faults()
        healthy(master, ring)


# -- hostile -------------------------------------------------------------------------------------------------------


def test_branch_refuses_what_is_no_tree() -> None:
    with pytest.raises(ArgumentError, match=r"^terminal must be a bus terminal module"):
        Branch(Supi3(), [], BranchKind.LOCAL)
    with pytest.raises(ArgumentError, match=r"^terminal must be a bus terminal module"):
        Branch(PlainDevice(0x08, 0), [], BranchKind.LOCAL)  # type: ignore[arg-type]
    with pytest.raises(ArgumentError, match=r"^terminal must be a BK-LBD for a LBD-MR branch"):
        Branch(terminal("BK-LB"), [], BranchKind.LBD_MR)
    with pytest.raises(ArgumentError, match=r"^kind must be"):
        Branch(terminal("BK-LB"), [], "BK-LB")  # type: ignore[arg-type]
    with pytest.raises(ArgumentError, match=r"^devices must be"):
        Branch(terminal("BK-LB"), PlainDevice(0xBF, 1), BranchKind.LOCAL)  # type: ignore[arg-type]
    with pytest.raises(ArgumentError, match=r"^branch device 1 must be a device \(only a remote bus"):
        Branch(terminal("BK-LB"), [Branch(terminal("BK-LB"), [], BranchKind.LOCAL)], BranchKind.LOCAL)
    with pytest.raises(ArgumentError, match=r"^branch device 2 must be a Device or a Branch"):
        Branch(terminal("BK-RB"), [PlainDevice(0x03, 1), 7], BranchKind.REMOTE)  # type: ignore[list-item]
    # 2.2: no mixed operation on a local bus; a remote bus branch holds remote bus devices and BKs.
    lbd_mr, lbd_or, lb_mr = (Supi3(decode(c)) for c in ("11000", "11100", "01000"))
    with pytest.raises(ArgumentError, match=r"^branch device 2 must be in a LBD-MR mode for a LBD-MR branch, not LBD"):
        Branch(terminal("BK-LBD"), [lbd_mr, lbd_or], BranchKind.LBD_MR)
    with pytest.raises(ArgumentError, match=r"^branch device 1 must be in a LB-MR mode for a BK-LB branch, not LBD-MR"):
        Branch(terminal("BK-LB"), [lbd_mr], BranchKind.LOCAL)
    with pytest.raises(ArgumentError, match=r"^branch device 1 must be in a RB mode for a BK-RB branch, not LB-MR"):
        Branch(terminal("BK-RB"), [lb_mr], BranchKind.REMOTE)
    Branch(terminal("BK-RB"), [Supi3(decode("10000")), terminal("BK-LB")], BranchKind.REMOTE)  # a BK as a device


def test_ring_refuses_one_device_twice_and_bad_return_breaks() -> None:
    device: Device = PlainDevice(0xBF, 1)
    with pytest.raises(ArgumentError, match=r"^devices must be distinct objects"):
        Ring([Branch(terminal("BK-LB"), [device], BranchKind.LOCAL), device])
    ring, _, _ = figure_1_10()
    for segment in (8, 13, 16):  # the last of an MR branch, an OR device, the last device
        with pytest.raises(InterbusError, match="a return line enters only"):
            ring.inject(ReturnBreak(segment))
    ring.inject(ReturnBreak(1))  # the remote bus's return input into 1.0 from 2.0 (BK-59)
    with pytest.raises(InterbusError, match=r"line must be in 1\.\.16"):
        ring.inject(ReturnBreak(17))
    with pytest.raises(ArgumentError, match=r"^fault must be"):
        ring.inject("break")  # type: ignore[arg-type]


def test_switch_branch_refuses_wrong_devices_types_and_orders() -> None:
    _, master, _ = figure_1_10()
    with pytest.raises(InterbusError, match="must be a bus terminal module"):
        master.switch_branch("1.0", False)
    with pytest.raises(InterbusError, match="no such device"):
        master.switch_branch("9.0", False)
    with pytest.raises(ArgumentError, match=r"^on must be"):
        master.switch_branch("2.0", 0)  # type: ignore[arg-type]
    with pytest.raises(ArgumentError, match=r"^extended must be"):
        master.switch_branch("2.0", True, "yes")  # type: ignore[arg-type]
    with pytest.raises(InterbusError, match="with the branch on"):
        master.switch_branch("2.0", False, True)
    fresh = Master(Ring([Branch(terminal("BK-LB"), [PlainDevice(0xBF, 1)], BranchKind.LOCAL)]))
    with pytest.raises(InterbusError, match="no configuration"):
        fresh.switch_branch(1, False)  # before the first ID cycle


def test_the_master_sets_a_bks_alarm_output() -> None:
    """Table 2-8 (ALARM on MFP15, set by the master, 0714h; BK-12): sent in the next ID cycle, shown on the LED
    view and MFP15, off again after an Alarm Stop; only bus terminal modules have it."""
    _, master, bks = figure_1_10()
    lb = bks["lb"]
    assert lb.bus_terminal is not None and not lb.diagnostic_outputs.alarm
    number = next(e.number for e in master.config or () if e.ring_position == lb_position(master, lb))
    master.set_alarm_output(number, True)
    assert master.cycle().cycle is Cycle.ID  # the command goes out at once
    assert lb.bus_terminal.alarm and lb.diagnostic_outputs.alarm and lb.diagnostic_outputs.mfp >> 15 & 1
    assert not bks["rb"].diagnostic_outputs.alarm  # only the BK it was meant for
    assert master.cycle().cycle is Cycle.DATA  # nothing left to send
    master.set_alarm_output(number, False)
    master.cycle()
    assert not lb.diagnostic_outputs.alarm
    master.set_alarm_output(number, True)
    master.cycle()
    assert master.start().ok  # Alarm Stop: the INTERBUS reset switches it off
    assert not lb.diagnostic_outputs.alarm
    with pytest.raises(InterbusError, match="must be a bus terminal module to set its ALARM output"):
        master.set_alarm_output("1.0", True)
    with pytest.raises(ArgumentError, match=r"^on must be"):
        master.set_alarm_output(number, 1)
    assert wire.decode_command_word(wire.command_word(alarm_output=True)).alarm_output is True
    assert wire.decode_command_word(wire.command_word(alarm_output=False)).alarm_output is False
    assert wire.decode_command_word(wire.command_word()).alarm_output is None
    with pytest.raises(InterbusError, match="without a processor command"):
        wire.command_word(processor_command=1, alarm_output=True)


def lb_position(master: Master, chip: Supi3) -> int:
    """The ring position of ``chip`` (a BK) in the master's configuration."""
    ring = master.ring
    assert isinstance(ring, Ring)
    return ring.devices.index(chip) + 1

"""MAU warnings reported to the master (manual 1.6.3; docs/assumptions/optical.md OPT-50..OPT-53): the optical status
request in the command word, the optical status byte in place of the ID code, the chip holding ATTN while a MAU event
waits, and the master's ``ErrorKind.MAU_WARNING`` diagnostics, also next to PF and bus terminal reports."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.config import decode
from supi3.errors import ArgumentError
from supi3.interbus import wire
from supi3.interbus.device import PlainDevice
from supi3.interbus.errors import InterbusError
from supi3.interbus.master import MSG_MAU_WARNING, Master
from supi3.interbus.ring import Branch, BranchKind, ErrorKind, Ring
from supi3.interbus.wire import Cycle
from supi3.model.bus_terminal import CONF_PIN, LBST_PIN
from supi3.model.chip import Supi3
from supi3.optical.regulation import Interface
from supi3.tables import ID_CODES
from support import BK_STRAPS, bad

QUIET = 12
"""Cycles after the last change in which every MAU event reaches the master (ATTN, request, answer; OPT-52)."""


def optical_chip(straps: str = "10000") -> Supi3:
    """A chip in optical diagnostics mode (RF = 01): a MAU warning per interface, set by one test (OPT-7)."""
    return Supi3(decode(straps, rf="01"))


def start(devices: list[Supi3 | PlainDevice | Branch]) -> tuple[Ring, Master, list[Supi3]]:
    ring = Ring(devices)
    master = Master(ring, max_devices=16)
    assert master.start().ok
    chips = [d for d in ring.devices if isinstance(d, Supi3)]
    for chip in chips:
        chip.optical_start((True, True, chip.terminal_interface is not None), ring.now)
    return ring, master, chips


def warn(chip: Supi3, interface: Interface, on: bool) -> None:
    """Set or clear a diagnostics-mode MAU warning: a failed test sets it, a passed one clears it (OPT-7)."""
    chip.optical_test(interface, not on, not on)
    assert chip.optical[interface].mau is on


def run(master: Master, cycles: int) -> list[Cycle]:
    kinds = []
    for _ in range(cycles):
        result = master.cycle()
        assert result.ok, result.diagnostics
        kinds.append(result.cycle)
    return kinds


def warnings_of(master: Master) -> list[tuple[int | None, str, bool]]:
    return [(d.location, *d.mau) for d in master.diagnostics if d.kind is ErrorKind.MAU_WARNING and d.mau]


def actual(ring: Ring) -> dict[int, tuple[bool, bool, bool]]:
    found = {}
    for k, device in enumerate(ring.devices, 1):
        if isinstance(device, Supi3) and any(tx.mau for tx in device.optical.transmitters):
            mau = tuple(tx.mau for tx in device.optical.transmitters)
            found[k] = (mau[0], mau[1], mau[2])
    return found


# -- wire ------------------------------------------------------------------------------------------------------------


def test_command_word_optical_request_round_trips_and_refuses_a_second_answer() -> None:
    word = wire.command_word(optical_request=True, branch=wire.BranchControl.ON)
    assert word == 1 << wire.CMD_OPTICAL_BIT | 2 << wire.CMD_BRANCH_SHIFT
    assert wire.decode_command_word(word).optical_request
    # Bits 15..8 are a processor command byte when bit 4 is set: no optical request then (A18)
    assert not wire.decode_command_word(wire.command_word(processor_command=0x01)).optical_request
    for other in ({"processor_command": 0}, {"alarm_request": True}):
        with pytest.raises(InterbusError, match="optical status request"):
            wire.command_word(optical_request=True, **other)
    with pytest.raises(ArgumentError, match="optical_request must be"):
        wire.command_word(optical_request=bad(1))


def test_optical_status_byte_every_value_and_no_id_code_of_table_a3_reads_as_one() -> None:
    for bits in range(8):
        mau = (bool(bits & 1), bool(bits & 2), bool(bits & 4))
        byte = wire.optical_status(mau)
        assert byte == 0x80 | bits
        assert wire.decode_optical_status(byte) == mau
    assert all(wire.decode_optical_status(row.code) is None for row in ID_CODES)
    with pytest.raises(ArgumentError, match="mau must be"):
        wire.optical_status(bad((True, False)))


# -- the chip --------------------------------------------------------------------------------------------------------


def test_chip_holds_attn_until_the_master_read_each_change_and_sends_the_status_when_asked() -> None:
    chip = optical_chip()
    chip.reset(0.0)
    chip.optical_start((True, True, False), 0.0)
    id_word = chip.id_register()
    warn(chip, Interface.OUT, True)
    warn(chip, Interface.OUT, False)  # on and off again before the master asked: still two changes to tell
    assert chip.attention
    ask = wire.word_bytes(wire.command_word(optical_request=True))
    chip.latch(Cycle.ID, ask, 0.001)
    assert chip.attention and chip.id_register() == (id_word & ~0xFF) | wire.optical_status((False, True, False))
    chip.latch(Cycle.ID, ask, 0.002)  # the "on" was read; the "off" waits
    assert chip.attention and chip.id_register() & 0xFF == wire.optical_status((False, False, False))
    chip.latch(Cycle.ID, bytes(2), 0.003)
    assert not chip.attention and chip.id_register() == id_word


def test_reset_forgets_the_reports_with_the_master() -> None:
    chip = optical_chip()
    chip.reset(0.0)
    chip.optical_start((True, True, False), 0.0)
    warn(chip, Interface.IN, True)
    chip.latch(Cycle.ID, wire.word_bytes(wire.command_word(optical_request=True)), 0.001)
    chip.reset(0.002)
    assert not chip.attention
    assert chip.id_register() & 0xFF == chip.config.id_code


# -- the master ------------------------------------------------------------------------------------------------------


def test_master_reports_on_and_off_at_the_device_and_interface() -> None:
    _ring, master, chips = start([optical_chip(), PlainDevice(0x03, 0b01001), optical_chip()])
    warn(chips[1], Interface.IN, True)
    run(master, QUIET)
    on = [d for d in master.diagnostics if d.kind is ErrorKind.MAU_WARNING]
    assert [(d.location, d.device, d.code, d.mau) for d in on] == [(3, "3.0", MSG_MAU_WARNING, ("MAUWH", True))]
    assert "incoming interface" in on[0].detail
    assert master.mau_warnings == {3: (True, False, False)}
    warn(chips[1], Interface.IN, False)
    run(master, QUIET)
    assert warnings_of(master) == [(3, "MAUWH", True), (3, "MAUWH", False)]
    assert master.mau_warnings == {}


def test_no_extra_id_cycles_without_warnings() -> None:
    _ring, master, chips = start([optical_chip(), optical_chip(), PlainDevice(0x03, 0b01001)])
    assert run(master, 50).count(Cycle.ID) == 0
    warn(chips[0], Interface.OUT, True)
    kinds = run(master, 50)
    assert kinds.count(Cycle.ID) == 3  # after ATTN: the ID cycle, the request, the answer
    assert warnings_of(master) == [(1, "MAUWR", True)]


def test_next_to_a_peripheral_fault_in_the_same_cycle() -> None:
    ring, master, chips = start([optical_chip(), optical_chip()])
    chips[1].set_stat_err(True, ring.now)
    ring.idle(0.3)  # the /StatErr filter (3.6.2): PF and ATTN
    warn(chips[1], Interface.OUT, True)
    warn(chips[0], Interface.IN, True)
    run(master, QUIET)
    kinds = [(d.kind, d.location, d.mau) for d in master.diagnostics]
    assert (ErrorKind.PERIPHERAL_FAULT, 2, None) in kinds
    assert sorted(warnings_of(master)) == [(1, "MAUWH", True), (2, "MAUWR", True)]


def test_next_to_a_bus_terminal_report_and_at_its_branch_interface() -> None:
    bk = Supi3(decode(BK_STRAPS["BK-LB"], rf="01"))
    bk.set_mfp_inputs(1 << LBST_PIN)
    _ring, master, chips = start([optical_chip(), Branch(bk, [PlainDevice(0xBE, 0b00001)], BranchKind.LOCAL),
                                 optical_chip()])  # fmt: skip
    run(master, 3)
    bk.set_mfp_inputs(1 << LBST_PIN | 1 << CONF_PIN)  # a reconfiguration request (BK-8) ...
    warn(bk, Interface.BRANCH, True)  # ... and MAUWS in the same cycle
    warn(chips[-1], Interface.IN, True)
    run(master, 2 * QUIET)
    kinds = [(d.kind, d.location) for d in master.diagnostics]
    assert (ErrorKind.RECONFIGURATION_REQUEST, 2) in kinds
    # the acknowledged request makes the master read the configuration anew: it asks again and reports the
    # warnings still on under the new numbering (OPT-52)
    assert set(warnings_of(master)) == {(2, "MAUWS", True), (4, "MAUWH", True)}
    assert master.mau_warnings == {2: (False, False, True), 4: (True, False, False)}


def test_a_bk_whose_branch_status_has_no_report_is_asked_for_its_optical_status() -> None:
    bk = Supi3(decode(BK_STRAPS["BK-LB"], rf="01"))
    bk.set_mfp_inputs(1 << LBST_PIN)
    _ring, master, _chips = start([Branch(bk, [PlainDevice(0xBE, 0b00001)], BranchKind.LOCAL), optical_chip()])
    run(master, 3)
    warn(bk, Interface.OUT, True)
    run(master, QUIET)
    assert warnings_of(master) == [(1, "MAUWR", True)]


@settings(max_examples=25, deadline=None)
@given(st.lists(st.tuples(st.integers(0, 3), st.sampled_from(list(Interface)), st.booleans(), st.integers(0, 4)),
                min_size=1, max_size=14))  # fmt: skip
def test_random_histories_end_with_the_master_knowing_every_warning(
        steps: list[tuple[int, Interface, bool, int]]) -> None:  # fmt: skip
    bk = Supi3(decode(BK_STRAPS["BK-RB"], rf="01"))
    bk.set_mfp_inputs(1 << LBST_PIN)
    ring, master, chips = start([optical_chip(), Branch(bk, [optical_chip()], BranchKind.REMOTE),
                                 PlainDevice(0x03, 0b01001), optical_chip()])  # fmt: skip
    toggles: dict[tuple[int | None, str], int] = {}
    for which, interface, on, cycles in steps:
        chip = chips[which]
        if interface is Interface.BRANCH and chip is not bk:
            interface = Interface.OUT
        if chip.optical[interface].mau is not on:
            key: tuple[int | None, str] = (ring.devices.index(chip) + 1, wire.MAU_WARNINGS[interface])
            toggles[key] = toggles.get(key, 0) + 1
        warn(chip, interface, on)
        run(master, cycles)
    run(master, 2 * QUIET)
    assert master.mau_warnings == actual(ring)
    seen: dict[tuple[int | None, str], list[bool]] = {}
    for position, name, on in warnings_of(master):
        seen.setdefault((position, name), []).append(on)
    for where, ons in seen.items():
        assert ons == [k % 2 == 0 for k in range(len(ons))]  # on, off, on, ...: never twice the same
        assert len(ons) <= toggles[where] and len(ons) % 2 == toggles[where] % 2
    assert set(toggles) - set(seen) == {k for k, n in toggles.items() if n % 2 == 0} - set(seen)

"""The SUPI 3 as a bus terminal module (BK) at transaction level: manual 2.4, Tables 2-7, 2-8, 2-9; the BK state of
supi3.model.bus_terminal and its hooks in supi3.model.chip (docs/assumptions/bus-terminal.md BK-1..)."""

from __future__ import annotations

import itertools

import pytest

from supi3.config import decode
from supi3.errors import ArgumentError
from supi3.interbus import wire
from supi3.interbus.wire import BranchControl, Cycle
from supi3.model.bus_terminal import BRANCH_SILENCE_S, CONF_PIN, LBST_PIN, BusTerminal, branch_present
from supi3.model.chip import ChipArgumentError, ChipError, Supi3
from support import BK_STRAPS, terminal


def id_latch(chip: Supi3, now: float, **command: object) -> None:
    chip.load(Cycle.ID, now)
    chip.latch(Cycle.ID, wire.word_bytes(wire.command_word(**command)), now)  # type: ignore[arg-type]


def test_table_2_8_pins_are_conf_12_and_lbst_11() -> None:
    assert (CONF_PIN, LBST_PIN) == (12, 11)


@pytest.mark.parametrize(("rf", "lbst", "connected"), list(itertools.product(["00", "01", "10", "11"], [False, True],
                                                                        [False, True])))  # fmt: skip
def test_table_2_9_lbst_by_rf_every_case(rf: str, lbst: bool, connected: bool) -> None:
    expected = {"10": lbst, "11": connected and lbst, "00": connected or lbst, "01": connected or lbst}[rf]
    assert branch_present(rf, lbst, connected) is expected
    chip = Supi3(decode("00010", rf=rf))
    chip.set_mfp_inputs(int(lbst) << LBST_PIN)
    assert chip.branch_enabled(connected) is expected


@pytest.mark.parametrize("interface", list(BK_STRAPS))
def test_bk_modes_have_data_length_0_and_table_2_7_id_codes(interface: str) -> None:
    chip = terminal(interface)
    assert chip.terminal_interface == interface
    assert chip.data_bytes() == 0
    assert chip.id_register() & 0xFF == {"BK-RB": 0x0C, "BK-LB": 0x08, "BK-LBD": 0x04}[interface]


def test_conf_positive_edge_requests_reconfiguration_once_until_acknowledged() -> None:
    chip = terminal("BK-LBD")
    assert not chip.attention
    chip.set_mfp_inputs((1 << LBST_PIN) | (1 << CONF_PIN))
    assert chip.attention and chip.bus_terminal is not None and chip.bus_terminal.conf_request
    id_latch(chip, 0.001)  # an ID cycle without acknowledgement: the request and ATTN stay (BK-5)
    assert chip.attention and chip.bus_terminal.conf_request
    id_latch(chip, 0.002, quit_peripheral_error=True)
    assert not chip.attention and not chip.bus_terminal.conf_request
    chip.set_mfp_inputs((1 << LBST_PIN) | (1 << CONF_PIN))  # high stays high: no new edge
    assert not chip.attention
    chip.set_mfp_inputs(1 << LBST_PIN)  # falling edge: nothing
    assert not chip.attention and not chip.bus_terminal.conf_request


def test_conf_high_at_power_up_is_no_edge() -> None:
    chip = Supi3(decode("00010"))
    chip.set_mfp_inputs(1 << CONF_PIN)
    chip.power_up()
    assert chip.bus_terminal is not None and not chip.bus_terminal.conf_request


def test_status_request_sends_the_branch_status_in_place_of_the_id_code_once() -> None:
    chip = terminal("BK-LBD")
    chip.set_mfp_inputs((1 << LBST_PIN) | (1 << CONF_PIN))
    id_latch(chip, 0.001, alarm_request=True)
    word = chip.id_register()
    assert word & 0xFF == wire.bk_status(True, False, 0)
    assert (word >> 8) & 0x1F == 0  # the length code stays
    id_latch(chip, 0.002)
    assert chip.id_register() & 0xFF == 0x04


def test_branch_control_switches_and_extended_function_closes_a_silent_branch() -> None:
    chip = terminal("BK-LBD")
    id_latch(chip, 0.001, branch=BranchControl.OFF)
    assert not chip.branch_enabled(True)
    id_latch(chip, 0.002, branch=BranchControl.ON)
    assert chip.branch_enabled(True)
    chip.branch_returned(False, None, 0.0, 1.0)  # silent for 1 s, but the extended function is off
    assert chip.branch_enabled(True) and not chip.attention
    id_latch(chip, 1.001, branch=BranchControl.ON_EXTENDED)
    chip.branch_returned(False, 3, 1.01, 1.01 + BRANCH_SILENCE_S / 2, 1.011)  # the silence starts (BK-50)
    assert chip.branch_enabled(True)
    chip.branch_returned(True, None, 1.02, 1.03, 1.021)  # telegrams came back: the silence starts again
    chip.branch_returned(False, 3, 1.03, 1.03 + BRANCH_SILENCE_S * 0.99, 1.031)  # at this frame's end
    assert chip.branch_enabled(True)
    chip.branch_returned(False, 3, 1.031 + BRANCH_SILENCE_S * 0.99, 1.031 + BRANCH_SILENCE_S * 1.2)  # no frame
    assert chip.branch_enabled(True)
    chip.branch_returned(False, 3, 1.031 + BRANCH_SILENCE_S * 1.2, 1.031 + BRANCH_SILENCE_S * 1.3,
                         1.031 + BRANCH_SILENCE_S * 1.25)  # fmt: skip
    assert not chip.branch_enabled(True) and chip.attention
    assert chip.bus_terminal is not None
    assert wire.decode_bk_status(chip.bus_terminal.status()) == wire.BkStatus(False, True, 3)
    id_latch(chip, 1.1, quit_peripheral_error=True)  # acknowledged: reported no more, still closed
    assert wire.decode_bk_status(chip.bus_terminal.status()) == wire.BkStatus(False, False, 3)
    assert not chip.branch_enabled(True)
    id_latch(chip, 1.2, branch=BranchControl.ON)
    assert chip.branch_enabled(True)


def test_reset_reopens_the_branch_and_ends_the_extended_function_keeps_conf() -> None:
    chip = terminal("BK-RB")
    id_latch(chip, 0.001, branch=BranchControl.ON_EXTENDED)
    chip.branch_returned(False, None, 0.0, 0.5, 0.1)  # the silence starts at this frame's end (BK-50)
    chip.branch_returned(False, None, 0.5, 1.0, 0.6)  # and closes the branch at this one
    chip.set_mfp_inputs((1 << LBST_PIN) | (1 << CONF_PIN))
    assert not chip.branch_enabled(True)
    chip.reset(1.1)
    assert chip.branch_enabled(True) and chip.attention
    assert chip.bus_terminal is not None and not chip.bus_terminal.extended and chip.bus_terminal.conf_request


def test_chip_state_compares_by_value() -> None:
    assert terminal("BK-LB").bus_terminal == terminal("BK-LB").bus_terminal
    assert terminal("BK-LB").bus_terminal != terminal("BK-LB", lbst=False).bus_terminal
    assert "BK-LB" in repr(terminal("BK-LB").bus_terminal)


# -- hostile -----------------------------------------------------------------------------------------------------


def test_a_chip_that_is_no_bk_refuses_branch_calls_by_name() -> None:
    chip = Supi3()
    assert chip.terminal_interface is None and chip.bus_terminal is None
    with pytest.raises(ChipError, match="bus terminal mode"):
        chip.branch_enabled(True)
    with pytest.raises(ChipError, match="bus terminal mode"):
        chip.branch_returned(True, None, 0.0, 0.0)


@pytest.mark.parametrize(("args", "name"), [
    (("yes", None, 0.0, 1.0), "traffic"), ((True, 0, 0.0, 1.0), "count"), ((True, 64, 0.0, 1.0), "count"),
    ((True, 1.5, 0.0, 1.0), "count"), ((True, None, -1.0, 1.0), "start"), ((True, None, 1.0, 0.5), "end"),
    ((True, None, 0.0, float("nan")), "end"), ((True, None, 0.5, 1.0, 0.25), "frame_end"),
    ((True, None, 0.0, 1.0, 1.5), "frame_end"), ((True, None, 0.0, 1.0, "0.5"), "frame_end"),
])  # fmt: skip
def test_branch_returned_refuses_wrong_types_and_ranges(args: tuple[object, ...], name: str) -> None:
    with pytest.raises(ChipArgumentError, match=rf"^{name} must be"):
        terminal("BK-LBD").branch_returned(*args)  # type: ignore[arg-type]


def test_branch_enabled_and_block_refuse_wrong_types() -> None:
    with pytest.raises(ChipArgumentError, match=r"^connected must be"):
        terminal("BK-LB").branch_enabled(1)  # type: ignore[arg-type]
    with pytest.raises(ArgumentError, match=r"^interface must be"):
        BusTerminal("BK-XX", None)
    with pytest.raises(ArgumentError, match=r"^rf must be"):
        branch_present("12", True, True)
    with pytest.raises(ArgumentError, match=r"^lbst must be"):
        branch_present("10", 1, True)  # type: ignore[arg-type]
    with pytest.raises(ArgumentError, match=r"^levels must be"):
        BusTerminal("BK-LB", None).inputs(1 << 16)
    with pytest.raises(ArgumentError, match=r"^branch must be"):
        BusTerminal("BK-LB", None).command(2, False)  # type: ignore[arg-type]
    with pytest.raises(ArgumentError, match=r"^acknowledge must be"):
        BusTerminal("BK-LB", None).command(BranchControl.ON, 1)  # type: ignore[arg-type]


def test_ld_and_e_leds_follow_the_branch_state() -> None:
    """Tables 2-8, 3-19 (BK-11): LD lit while the branch is switched off or closed by the BK; E lit while a counter
    telegram reports a break behind the BK or the BK closed the branch; both also on MFP14/MFP13."""

    def leds(chip: Supi3) -> tuple[bool, bool, int]:
        view = chip.diagnostic_outputs
        return view.ld, view.e, view.mfp >> 13 & 0b11

    chip = terminal("BK-LBD")
    assert leds(chip) == (False, False, 0b00)
    id_latch(chip, 0.001, branch=BranchControl.OFF)
    assert leds(chip) == (True, False, 0b10)
    id_latch(chip, 0.002, branch=BranchControl.ON_EXTENDED)
    revision = chip.revision
    chip.branch_returned(True, 4, 0.002, 0.003)  # a break four counts behind
    assert leds(chip) == (False, True, 0b01) and chip.revision > revision
    chip.branch_returned(True, None, 0.003, 0.004)
    assert leds(chip) == (False, False, 0b00)
    chip.branch_returned(False, None, 0.004, 0.005, 0.0045)
    chip.branch_returned(False, None, 0.005, 0.005 + BRANCH_SILENCE_S, 0.0045 + BRANCH_SILENCE_S)  # silent: closed
    assert leds(chip) == (True, True, 0b11)
    assert Supi3(decode("10000")).diagnostic_outputs.ld is False  # no BK, no LD

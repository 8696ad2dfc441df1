"""The diagnostic outputs as data and pure functions (supi3.diagnostics): manual 3.6.1, Tables 3-16 to 3-19, 2-8;
decisions DG-1 to DG-8 (docs/assumptions/diagnostics.md)."""

from __future__ import annotations

import itertools

import pytest

from supi3.config import Interface, decode, mode_rows
from supi3.diagnostics import (
    BUS_TERMINAL_PINS,
    IB_DIAG_PRIORITY,
    LINE_INTERRUPT_INTERFACES,
    DiagnosticOutputs,
    IbDiag,
    LedInputs,
    bus_terminal_mfp,
    diag_pins,
    diagnostic_outputs,
    fo_leds,
    ib_diag_level,
    ib_diag_state,
    is_complete,
    watches_line_interrupt,
)
from supi3.errors import ArgumentError
from supi3.optical.regulation import Interface as Optical
from supi3.optical.regulation import OpticalStatus, Phase, Transmitter
from supi3.tables import CLOCK_HZ, LIMITED_DIAGNOSTICS

BOOLS = (False, True)


def test_ib_diag_priority_over_every_combination() -> None:
    # DG-1: 4 Hz over 2 Hz over 0.5 Hz over steady (Table 3-18).
    for interrupt, fault, active in itertools.product(BOOLS, repeat=3):
        state = ib_diag_state(interrupt, fault, active)
        if interrupt:
            assert state is IbDiag.VERY_FAST
        elif fault:
            assert state is IbDiag.FAST
        elif not active:
            assert state is IbDiag.SLOW
        else:
            assert state is IbDiag.STEADY
    assert IB_DIAG_PRIORITY == (IbDiag.VERY_FAST, IbDiag.FAST, IbDiag.SLOW, IbDiag.STEADY)


def test_ib_diag_frequencies_are_table_3_18s_within_m6s_divider() -> None:
    assert [state.hz for state in IbDiag] == [hz for _, hz, _ in LIMITED_DIAGNOSTICS[1:]]
    for state in (IbDiag.SLOW, IbDiag.FAST, IbDiag.VERY_FAST):
        assert state.divider_bits is not None and state.hz is not None
        hz = CLOCK_HZ / (1 << state.divider_bits)
        assert 0.75 * state.hz < hz <= state.hz  # a power-of-two divider, the nearest at or below (DG-2)


@pytest.mark.parametrize("state", list(IbDiag))
def test_ib_diag_level_flashes_with_a_half_period_on(state: IbDiag) -> None:
    bits = state.divider_bits
    if bits is None:
        assert {ib_diag_level(state, c) for c in (0, 1, 1 << 30)} == {1}
        return
    half = 1 << (bits - 1)
    assert [ib_diag_level(state, c) for c in (0, half - 1, half, 2 * half - 1, 2 * half)] == [1, 1, 0, 0, 1]


def test_diag_pins_by_diag_conf() -> None:
    # Table 3-16: DIAG_CONF = 0 BA/RD, 1 FO1/FO2.
    for ba, rd, fo1, fo2 in itertools.product(BOOLS, repeat=4):
        assert diag_pins(True, ba, rd, fo1, fo2) == (int(ba), int(rd))
        assert diag_pins(False, ba, rd, fo1, fo2) == (int(fo1), int(fo2))
    assert is_complete(decode("10000", diag_conf=0)) and not is_complete(decode("10000", diag_conf=1))
    assert not is_complete(decode("10000", variant="ls"))  # the LS has no DIAG_CONF


def test_fo_leds_follow_fo_lit_per_interface() -> None:
    # Table 3-17: READY shows the failed initialization (fallback), RUN the MAU warning.
    status = OpticalStatus().with_transmitter(Optical.IN, Transmitter(Phase.FIXED))
    status = status.with_transmitter(Optical.BRANCH, Transmitter(Phase.ONLINE, 15, mau=True))
    assert fo_leds(status, False) == (True, False, False)
    assert fo_leds(status, True) == (False, False, True)


def test_line_interrupt_only_in_local_bus_modes() -> None:
    for row in mode_rows():
        config = decode(row.c, row.mfp)
        assert watches_line_interrupt(config) == (config.interface in LINE_INTERRUPT_INTERFACES)
    assert {Interface.LB_MR, Interface.LBD_MR, Interface.LBD_OR} == LINE_INTERRUPT_INTERFACES


def test_bus_terminal_leds_on_their_mfps() -> None:
    # Table 2-8: ALARM MFP15, LD (LBDA) MFP14, E (ERROR) MFP13, FO3 MFP8.
    assert BUS_TERMINAL_PINS == {"alarm": 15, "ld": 14, "e": 13, "fo3": 8}
    assert bus_terminal_mfp(True, True, True, True, True) == 0xE100
    assert bus_terminal_mfp(True, False, True, False, False) == 1 << 14
    assert bus_terminal_mfp(False, True, True, True, True) == 0


@pytest.mark.parametrize("c", ["00000", "00100", "01000", "10000"])
@pytest.mark.parametrize("diag_conf", [0, 1])
def test_diagnostic_outputs_of_a_chip(c: str, diag_conf: int) -> None:
    config = decode(c, diag_conf=diag_conf)
    leds = LedInputs(fo=(True, False, True), ld=True, e=True, alarm=True)
    view = diagnostic_outputs(config, supply_ok=True, line_heard=False, bus_active=True, peripheral_fault=True,
                              line_interrupt=False, following=False, leds=leds)  # fmt: skip
    bk = config.interface.is_bus_terminal
    assert view == DiagnosticOutputs(diag_conf == 0, True, False, True, True, bk, bk, bk, (True, False, bk),
                                     IbDiag.FAST)  # fmt: skip
    assert (view.diag1, view.diag2) == ((1, 1) if diag_conf == 0 else (1, 0))
    assert view.mfp == (0xE100 if bk else 0)


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: ib_diag_state(1, False, True), "line_interrupt must be True or False"),  # type: ignore[arg-type]
        (lambda: ib_diag_level("fast", 0), "state must be a IbDiag"),  # type: ignore[arg-type]
        (lambda: ib_diag_level(IbDiag.FAST, -1), "clock must be an integer >= 0"),
        (lambda: diag_pins(True, 1, False, False, False), "ba must be True or False"),  # type: ignore[arg-type]
        (lambda: LedInputs(fo=(True, False)), "fo must be a tuple of 3 bool"),  # type: ignore[arg-type]
        (lambda: LedInputs(alarm=1), "alarm must be True or False"),  # type: ignore[arg-type]
        (lambda: fo_leds(None, True), "status must be a OpticalStatus"),  # type: ignore[arg-type]
        (lambda: is_complete("10000"), "config must be a DeviceConfig"),  # type: ignore[arg-type]
        (lambda: diagnostic_outputs(decode("10000"), supply_ok=True, line_heard=True, bus_active=True,
                                    peripheral_fault=False, line_interrupt=False, following=True,
                                    leds=None),  # type: ignore[arg-type]
         "leds must be a"),
    ],
)  # fmt: skip
def test_bad_arguments_are_named(call: object, message: str) -> None:
    assert callable(call)
    with pytest.raises(ArgumentError, match=message):
        call()

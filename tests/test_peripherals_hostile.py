"""Hostile arguments to every public entry of supi3.peripherals: a named ArgumentError "X must be ..., not ..."
(supi3.checks), raised before any state changes."""

from __future__ import annotations

import re
from collections.abc import Callable

import pytest

from supi3.errors import ArgumentError
from supi3.expansion import ExpansionLevels
from supi3.peripherals import SerialBus, ShiftIn, ShiftOut, SpiAdc, SpiDac, Sre1
from supi3.spi.serial_io import Levels

BAD_COUNTS = [0, 5, -1, True, 2.0, "2", None]

CASES: list[tuple[str, Callable[[], object], str]] = [
    *((f"ShiftIn({n!r})", lambda n=n: ShiftIn(n), "length") for n in BAD_COUNTS),
    *((f"ShiftOut({n!r})", lambda n=n: ShiftOut(n), "length") for n in BAD_COUNTS),
    *((f"SpiAdc({b!r})", lambda b=b: SpiAdc(b), "bits") for b in [8, 24, 16.0, True, "16"]),
    *((f"SpiDac({b!r})", lambda b=b: SpiDac(b), "bits") for b in [8, 24, 16.0, True, "16"]),
    *((f"Sre1({n!r})", lambda n=n: Sre1(n), "length") for n in [0, 65, True, 1.0, b"\x01"]),
    ("ShiftIn.set_inputs wide", lambda: ShiftIn(1).set_inputs(0x100), "value"),
    ("ShiftIn.set_inputs negative", lambda: ShiftIn(4).set_inputs(-1), "value"),
    ("ShiftIn.set_inputs bytes", lambda: ShiftIn(1).set_inputs(b"\x01"), "value"),  # type: ignore[arg-type]
    ("SpiAdc.set_input wide", lambda: SpiAdc(16).set_input(0x10000), "code"),
    ("SpiAdc.set_input float", lambda: SpiAdc(16).set_input(1.0), "code"),  # type: ignore[arg-type]
    ("SpiAdc.set_voltage above vref", lambda: SpiAdc(16).set_voltage(5.1, 5.0), "volts"),
    ("SpiAdc.set_voltage negative", lambda: SpiAdc(16).set_voltage(-0.1, 5.0), "volts"),
    ("SpiAdc.set_voltage nan", lambda: SpiAdc(16).set_voltage(float("nan"), 5.0), "volts"),
    ("SpiAdc.set_voltage zero vref", lambda: SpiAdc(16).set_voltage(0.0, 0.0), "vref"),
    ("SpiAdc.set_voltage vref str", lambda: SpiAdc(16).set_voltage(1.0, "5"), "vref"),  # type: ignore[arg-type]
    ("SpiDac.volts negative vref", lambda: SpiDac(16).volts(-5.0), "vref"),
    ("SpiDac.volts inf", lambda: SpiDac(16).volts(float("inf")), "vref"),
    ("frame bits 8", lambda: ShiftIn(1).frame(0, 8), "bits"),
    ("frame bits True", lambda: SpiDac(16).frame(0, True), "bits"),
    ("frame ser_out wide", lambda: SpiDac(16).frame(0x10000, 16), "ser_out"),
    ("frame ser_out negative", lambda: ShiftOut(1).frame(-1, 32), "ser_out"),
    ("bus frame bits", lambda: SerialBus(SpiDac(16)).frame(0, 24), "bits"),
    ("clock int", lambda: ShiftIn(1).clock(0x28), "levels"),  # type: ignore[arg-type]
    ("clock expansion levels", lambda: SpiDac(16).clock(ExpansionLevels(0, 0, 0, 1, 1)), "levels"),  # type: ignore[arg-type]
    ("bus clock None", lambda: SerialBus().clock(None), "levels"),  # type: ignore[arg-type]
    ("bus of a non-device", lambda: SerialBus(SpiDac(16), "ShiftIn"), "devices[1]"),  # type: ignore[arg-type]
    ("bus of an SRE", lambda: SerialBus(Sre1(1)), "devices[0]"),  # type: ignore[arg-type]
    ("Sre1.set_inputs short", lambda: Sre1(3).set_inputs(b"\x01\x02"), "data"),
    ("Sre1.set_inputs int", lambda: Sre1(1).set_inputs(1), "data"),  # type: ignore[arg-type]
    ("Sre1.shift_cycle long", lambda: Sre1(2).shift_cycle(b"\x01\x02\x03"), "received"),
    ("Sre1.shift_cycle str", lambda: Sre1(2).shift_cycle("ab"), "received"),  # type: ignore[arg-type]
    ("Sre1.clock serial levels", lambda: Sre1(1).clock(Levels(1, 0, 1, 0)), "levels"),  # type: ignore[arg-type]
]


@pytest.mark.parametrize(("call", "name"), [(call, name) for _, call, name in CASES], ids=[c[0] for c in CASES])
def test_hostile_arguments_give_named_errors(call: Callable[[], object], name: str) -> None:
    with pytest.raises(ArgumentError, match=rf"^{re.escape(name)} must be .*, not ") as caught:
        call()
    assert caught.value.name == name


def test_the_same_device_twice_is_refused() -> None:
    dac = SpiDac(16)
    with pytest.raises(ArgumentError, match=r"^devices\[1\] must be a device not already on the bus, not SpiDac"):
        SerialBus(dac, dac)


def test_a_refused_argument_changes_nothing() -> None:
    chain, sre, adc = ShiftIn(2), Sre1(2), SpiAdc(16)
    chain.set_inputs(0x1234)
    sre.set_inputs(b"\x01\x02")
    adc.set_input(7)
    with pytest.raises(ArgumentError):
        chain.set_inputs(0x10000)
    with pytest.raises(ArgumentError):
        sre.set_inputs(b"\x01")
    with pytest.raises(ArgumentError):
        adc.set_voltage(6.0, 5.0)
    with pytest.raises(ArgumentError):
        chain.frame(0, 12)
    assert (chain.inputs, sre.inputs, adc.code) == (0x1234, b"\x01\x02", 7)
    assert chain.frame(0, 16) == 0x1234

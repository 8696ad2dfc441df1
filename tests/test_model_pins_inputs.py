"""Hostile calls at every public entry of the pin-level modules: named errors, never a bare builtin, no state change.

Modules: supi3.model.pins (Supi3Pins), supi3.model.pinring (PinRing, receive), supi3.top (Supi3Chip,
up_pin_inputs/outputs), supi3.model.vcd (write_vcd), supi3.spi.slave_pins (PinsIn, PinsOut, SlavePins,
TimingChecker) and supi3.spi.block_pins (strap_values, block_model, UpifBlockPins). Each case makes a fresh object,
makes the wrong call, and checks the error's class and message ("X must be ..., not ...", with the pin's name and
width for pin values); then the same probe run on the object and on an untouched twin gives the same result.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from supi3.config import decode
from supi3.errors import ArgumentError, Supi3Error
from supi3.interbus import wire
from supi3.interbus.errors import InterbusError
from supi3.interbus.receiver import receive
from supi3.interbus.wire import Cycle
from supi3.model.chip import Supi3
from supi3.model.pinring import PinRing
from supi3.model.pins import Supi3Pins
from supi3.model.registers import InterfaceViolationError, RegisterFile
from supi3.model.vcd import write_vcd
from supi3.pinlevel import PinSpecError
from supi3.rtl.chip import Supi3ChipRtl
from supi3.rtl.core import Supi3Core
from supi3.rtl.tables import core_tables
from supi3.spi.block_pins import UpifBlockPins, block_model, strap_values
from supi3.spi.slave_pins import PinsIn, PinsOut, SlavePins, TimingChecker
from supi3.top import Supi3Chip, up_pin_inputs, up_pin_outputs
from supi3.verif.straps import ChipStrapPins, StrapPins, strap_inputs, strap_stimulus

BINARY = decode("10000", clk_conf="11")
UP = decode("10011", "1110", clk_conf="11")
IDLE = {"do1": 1, "di2": 0, "rbst_ext": 0, "mfp_in": 0, "stat_err_n": 1, "resu_n": 1, "vmon_ok": 1, "from_exr": 0}
N = 40


def traces(n: int = N, **changes: Any) -> dict[str, Any]:
    out: dict[str, Any] = {name: np.full(n, value, dtype=np.int64) for name, value in IDLE.items()}
    out.update(changes)
    return out


def bad(value: object) -> Any:
    """A wrong argument, typed ``Any`` so that the type checker lets the test make the call."""
    return value


def idle_with(**changes: Any) -> dict[str, Any]:
    return {**IDLE, **changes}


def without(mapping: dict[str, Any], name: str) -> dict[str, Any]:
    return {k: v for k, v in mapping.items() if k != name}


# Probes: what a later, valid use of the object shows (compared with an untouched twin) ---------------------------


def probe_pins(model: Supi3Pins) -> object:
    rows = [model.step(idle_with(do1=k % 2, mfp_in=k)) for k in range(5)]
    run = model.run(traces(20, do1=np.arange(20) % 2))
    return model.cycle, rows, {name: trace.tolist() for name, trace in run.items()}, model.chip.revision


def probe_ring(ring: PinRing) -> object:
    ring.set_input(1, "mfp_in", 0x1234)
    ring.run_levels(wire.status_levels(Cycle.DATA, False, 2))
    return ring.cycle, ring.returned.tolist(), [dict(pins) for pins in ring._inputs], [d.cycle for d in ring.devices]


def probe_chip(chip: Supi3Chip) -> object:
    rows = [chip.step(idle_with(mfp_in=0x20 if k % 4 else 0)) for k in range(8)]
    return chip.core.cycle, rows


def probe_slave(slave: SlavePins) -> object:
    return slave.cycle, [slave.tick(PinsIn(ss_n=int(k % 5 != 0))) for k in range(12)]


def probe_block(block: UpifBlockPins) -> object:
    base = {pin.name: 0 for pin in UpifBlockPins.inputs} | {"sclk": 1, "ss_n": 1, "mfp7_in": 1}
    return [block.step(base) for _ in range(4)]


def probe_none(_: object) -> object:
    return None


Factory = Callable[[], Any]
Call = Callable[[Any], object]


def _ring() -> PinRing:
    return PinRing([Supi3Pins(BINARY), Supi3Pins(BINARY)])


def _after_run_forward() -> Supi3Pins:
    model = Supi3Pins(BINARY)
    model.run_forward(traces())
    return model


def _up_chip() -> Supi3Chip:
    return Supi3Chip(UP, strict=False)


def _slave() -> SlavePins:
    return SlavePins(RegisterFile(UP, strict=False))


STRAPS = {name: value for name, value in strap_inputs(BINARY).items() if name != "mfp_expansion"}


def _strap_row(**changes: Any) -> dict[str, Any]:
    return {**IDLE, **STRAPS, **changes}


def _strap_traces(**changes: Any) -> dict[str, Any]:
    return {**traces(), **{k: np.full(N, v) for k, v in STRAPS.items()}, **changes}


def probe_straps(model: StrapPins | ChipStrapPins) -> object:
    return [model.step(_strap_row(do1=k % 2)) for k in range(4)]


def _checker() -> TimingChecker:
    return TimingChecker(2_000_000, 32_000_000, lambda _: None)


CASES: list[tuple[str, Factory, Call, type[Exception], str, Callable[[Any], object]]] = [
    # Supi3Pins: construction
    ("pins-config-none", lambda: None, lambda _: Supi3Pins(bad(None)), ArgumentError, "config must be a DeviceConfig",
     probe_none),
    ("pins-config-str", lambda: None, lambda _: Supi3Pins(bad("10000")), ArgumentError, "config must be", probe_none),
    ("pins-chip-type", lambda: None, lambda _: Supi3Pins(BINARY, bad("chip")), ArgumentError,
     "chip must be None or a Supi3", probe_none),
    ("pins-chip-config", lambda: None, lambda _: Supi3Pins(BINARY, Supi3(UP)), ArgumentError, "same configuration",
     probe_none),
    # Supi3Pins.step: every kind of wrong level
    ("step-do1-2", lambda: Supi3Pins(BINARY), lambda m: m.step(idle_with(do1=2)), ArgumentError,
     "pin 'do1' must be an integer from 0 to 1 (1 bit), not 2", probe_pins),
    ("step-do1-neg", lambda: Supi3Pins(BINARY), lambda m: m.step(idle_with(do1=-1)), ArgumentError,
     "pin 'do1' must be an integer from 0 to 1 (1 bit), not -1", probe_pins),
    ("step-do1-half", lambda: Supi3Pins(BINARY), lambda m: m.step(idle_with(do1=bad(0.5))), ArgumentError,
     "pin 'do1' must be an integer from 0 to 1 (1 bit), not 0.5", probe_pins),
    ("step-di2-nan", lambda: Supi3Pins(BINARY), lambda m: m.step(idle_with(di2=math.nan)), ArgumentError,
     "pin 'di2' must be an integer from 0 to 1 (1 bit), not nan", probe_pins),
    ("step-do1-str", lambda: Supi3Pins(BINARY), lambda m: m.step(idle_with(do1="1")), ArgumentError,
     "pin 'do1' must be an integer from 0 to 1 (1 bit), not '1'", probe_pins),
    ("step-do1-uint8", lambda: Supi3Pins(BINARY), lambda m: m.step(idle_with(do1=np.uint8(255))), ArgumentError,
     "pin 'do1' must be an integer from 0 to 1 (1 bit), not np.uint8(255)", probe_pins),
    ("step-do1-bool", lambda: Supi3Pins(BINARY), lambda m: m.step(idle_with(do1=True)), ArgumentError,
     "pin 'do1' must be an integer", probe_pins),
    ("step-do1-none", lambda: Supi3Pins(BINARY), lambda m: m.step(idle_with(do1=None)), ArgumentError,
     "pin 'do1' must be an integer", probe_pins),
    ("step-mfp-neg", lambda: Supi3Pins(BINARY), lambda m: m.step(idle_with(mfp_in=-1)), ArgumentError,
     "pin 'mfp_in' must be an integer from 0 to 65535 (16 bits), not -1", probe_pins),
    ("step-mfp-wide", lambda: Supi3Pins(BINARY), lambda m: m.step(idle_with(mfp_in=1 << 16)), ArgumentError,
     "pin 'mfp_in' must be an integer from 0 to 65535 (16 bits), not 65536", probe_pins),
    ("step-staterr-5", lambda: Supi3Pins(BINARY), lambda m: m.step(idle_with(stat_err_n=5)), ArgumentError,
     "pin 'stat_err_n' must be an integer from 0 to 1 (1 bit), not 5", probe_pins),
    ("step-missing", lambda: Supi3Pins(BINARY), lambda m: m.step(without(IDLE, "vmon_ok")), ArgumentError,
     "inputs must name exactly the pins do1, di2, rbst_ext, mfp_in, stat_err_n, resu_n, vmon_ok, from_exr, not without "
     "'vmon_ok'", probe_pins),
    ("step-unknown", lambda: Supi3Pins(BINARY), lambda m: m.step(idle_with(do3=1)), ArgumentError,
     "with 'do3', no such pin", probe_pins),
    ("step-not-mapping", lambda: Supi3Pins(BINARY), lambda m: m.step(bad([1, 0, 0, 0, 1, 1, 1])), ArgumentError,
     "inputs must be a mapping of pin name to value", probe_pins),
    # Supi3Pins.run / run_forward: traces, checked at once
    ("run-do1-2", lambda: Supi3Pins(BINARY), lambda m: m.run(traces(do1=np.array([1] * 39 + [2]))), ArgumentError,
     "pin 'do1' trace[39] must be an integer from 0 to 1 (1 bit), not 2", probe_pins),
    ("run-uint8-255", lambda: Supi3Pins(BINARY), lambda m: m.run(traces(resu_n=np.full(N, 255, np.uint8))),
     ArgumentError, "pin 'resu_n' trace[0] must be an integer from 0 to 1 (1 bit), not 255", probe_pins),
    ("run-int8-neg", lambda: Supi3Pins(BINARY), lambda m: m.run(traces(vmon_ok=np.array([1, -1] * 20, np.int8))),
     ArgumentError, "pin 'vmon_ok' trace[1] must be an integer from 0 to 1 (1 bit), not -1", probe_pins),
    ("run-mfp-wide", lambda: Supi3Pins(BINARY), lambda m: m.run(traces(mfp_in=np.full(N, 1 << 16))), ArgumentError,
     "pin 'mfp_in' trace[0] must be an integer from 0 to 65535 (16 bits), not 65536", probe_pins),
    ("run-float", lambda: Supi3Pins(BINARY), lambda m: m.run(traces(do1=np.full(N, 1.0))), ArgumentError,
     "pin 'do1' trace must be a 1-D sequence of integers from 0 to 1 (1 bit)", probe_pins),
    ("run-nan", lambda: Supi3Pins(BINARY), lambda m: m.run(traces(di2=[math.nan] * N)), ArgumentError,
     "pin 'di2' trace must be a 1-D sequence of integers", probe_pins),
    ("run-str", lambda: Supi3Pins(BINARY), lambda m: m.run(traces(do1=["1"] * N)), ArgumentError,
     "pin 'do1' trace must be a 1-D sequence of integers", probe_pins),
    ("run-bool", lambda: Supi3Pins(BINARY), lambda m: m.run(traces(do1=np.ones(N, dtype=bool))), ArgumentError,
     "pin 'do1' trace must be", probe_pins),
    ("run-2d", lambda: Supi3Pins(BINARY), lambda m: m.run(traces(do1=np.ones((N, 1), dtype=np.int64))),
     ArgumentError, "pin 'do1' trace must be a 1-D sequence", probe_pins),
    ("run-scalar", lambda: Supi3Pins(BINARY), lambda m: m.run(traces(do1=1)), ArgumentError,
     "pin 'do1' trace must be a 1-D sequence", probe_pins),
    ("run-lengths", lambda: Supi3Pins(BINARY), lambda m: m.run(traces(stat_err_n=np.ones(N - 1, np.int64))),
     ArgumentError, "len(pin 'stat_err_n' trace) must be 40, the length of pin 'do1' trace, not 39", probe_pins),
    ("run-missing", lambda: Supi3Pins(BINARY), lambda m: m.run(without(traces(), "mfp_in")), ArgumentError,
     "not without 'mfp_in'", probe_pins),
    ("run-unknown", lambda: Supi3Pins(BINARY), lambda m: m.run(traces(clk=np.ones(N))), ArgumentError,
     "with 'clk', no such pin", probe_pins),
    ("run-forward-do1-2", lambda: Supi3Pins(BINARY), lambda m: m.run_forward(traces(do1=np.full(N, 2))),
     ArgumentError, "pin 'do1' trace[0] must be an integer from 0 to 1 (1 bit), not 2", probe_pins),
    ("return-line-first", lambda: Supi3Pins(BINARY), lambda m: m.return_line(np.zeros(N), np.ones(N)),
     ArgumentError, "do2 must be the do2 trace of the last run_forward()", probe_pins),
    ("return-line-length", _after_run_forward, lambda m: m.return_line(np.zeros(N - 1, np.int64), np.ones(N - 1,
     np.int64)), ArgumentError, "len(pin 'di2' trace) must be 40", probe_pins),
    ("return-line-level", _after_run_forward, lambda m: m.return_line(np.full(N, 3), np.ones(N, np.int64)),
     ArgumentError, "pin 'di2' trace[0] must be an integer from 0 to 1 (1 bit), not 3", probe_pins),
    ("output-values-past", lambda: Supi3Pins(BINARY), lambda m: (m.step(IDLE), m.output_values(0, 0)),
     ArgumentError, "c must be an integer >= 1, not 0", probe_none),
    ("output-values-di2", lambda: Supi3Pins(BINARY), lambda m: m.output_values(0, 2), ArgumentError,
     "pin 'di2' must be an integer from 0 to 1 (1 bit), not 2", probe_pins),
    # PinRing
    ("ring-empty", lambda: None, lambda _: PinRing([]), InterbusError, "at least one device", probe_none),
    ("ring-str", lambda: None, lambda _: PinRing(bad("ab")), ArgumentError, "chips must be a sequence of Supi3Pins",
     probe_none),
    ("ring-ints", lambda: None, lambda _: PinRing(bad([1, 2])), ArgumentError, "chips must be a sequence of Supi3Pins",
     probe_none),
    ("ring-twice", lambda: Supi3Pins(BINARY), lambda m: PinRing([m, m]), ArgumentError, "distinct Supi3Pins",
     probe_pins),
    ("ring-record", lambda: None, lambda _: PinRing([Supi3Pins(BINARY)], record=bad(1)), ArgumentError,
     "record must be True or False, not 1", probe_none),
    ("set-input-0", _ring, lambda r: r.set_input(0, "mfp_in", 0xAB), ArgumentError,
     "position must be an integer from 1 to 2, not 0", probe_ring),
    ("set-input-neg", _ring, lambda r: r.set_input(-1, "mfp_in", 0xAB), ArgumentError,
     "position must be an integer from 1 to 2, not -1", probe_ring),
    ("set-input-n+1", _ring, lambda r: r.set_input(3, "mfp_in", 0xAB), ArgumentError,
     "position must be an integer from 1 to 2, not 3", probe_ring),
    ("set-input-float-pos", _ring, lambda r: r.set_input(bad(1.0), "mfp_in", 0xAB), ArgumentError,
     "position must be an integer from 1 to 2, not 1.0", probe_ring),
    ("set-input-bool-pos", _ring, lambda r: r.set_input(True, "mfp_in", 0xAB), ArgumentError,
     "position must be an integer", probe_ring),
    ("set-input-line", _ring, lambda r: r.set_input(1, "do1", 1), ArgumentError,
     "pin must be one of 'rbst_ext', 'mfp_in', 'stat_err_n', 'resu_n', 'vmon_ok', 'from_exr'", probe_ring),
    ("set-input-unknown", _ring, lambda r: r.set_input(1, "mfp", 1), ArgumentError, "pin must be one of", probe_ring),
    ("set-input-pin-int", _ring, lambda r: r.set_input(1, bad(5), 1), ArgumentError, "pin must be one of", probe_ring),
    ("set-input-mfp-neg", _ring, lambda r: r.set_input(1, "mfp_in", -1), ArgumentError,
     "pin 'mfp_in' must be an integer from 0 to 65535 (16 bits), not -1", probe_ring),
    ("set-input-mfp-wide", _ring, lambda r: r.set_input(1, "mfp_in", 1 << 16), ArgumentError,
     "pin 'mfp_in' must be an integer from 0 to 65535 (16 bits), not 65536", probe_ring),
    ("set-input-staterr-5", _ring, lambda r: r.set_input(2, "stat_err_n", 5), ArgumentError,
     "pin 'stat_err_n' must be an integer from 0 to 1 (1 bit), not 5", probe_ring),
    ("set-input-half", _ring, lambda r: r.set_input(2, "resu_n", 0.5), ArgumentError,
     "pin 'resu_n' must be an integer from 0 to 1 (1 bit), not 0.5", probe_ring),
    ("set-input-str", _ring, lambda r: r.set_input(2, "vmon_ok", "1"), ArgumentError,
     "pin 'vmon_ok' must be an integer from 0 to 1 (1 bit), not '1'", probe_ring),
    ("run-levels-2", _ring, lambda r: r.run_levels(np.array([1, 2, 1])), ArgumentError,
     "levels[1] must be an integer from 0 to 1 (1 bit), not 2", probe_ring),
    ("run-levels-float", _ring, lambda r: r.run_levels(np.array([1.0, 0.0])), ArgumentError,
     "levels must be a 1-D sequence of integers", probe_ring),
    ("run-samples-neg", _ring, lambda r: r.run_samples(np.array([1, -1], np.int64)), ArgumentError,
     "samples[1] must be an integer from 0 to 1 (1 bit), not -1", probe_ring),
    ("idle-nan", _ring, lambda r: r.idle(math.nan), ArgumentError, "seconds must be a finite number, not nan",
     probe_ring),
    ("idle-str", _ring, lambda r: r.idle(bad("1")), ArgumentError, "seconds must be a finite number", probe_ring),
    ("idle-negative", _ring, lambda r: r.idle(-1.0), InterbusError, "idle time must be >= 0", probe_ring),
    ("recorded-off", _ring, lambda r: r.recorded(), InterbusError, "does not record", probe_ring),
    ("receive-level", lambda: None, lambda _: receive(np.array([1, 3], np.uint8), 0, 16), ArgumentError,
     "samples[0:][1] must be an integer from 0 to 1 (1 bit), not 3", probe_none),
    ("receive-start", lambda: None, lambda _: receive(np.ones(4, np.uint8), 5, 16), ArgumentError,
     "start must be an integer from 0 to 4, not 5", probe_none),
    ("receive-cpb", lambda: None, lambda _: receive(np.ones(4, np.uint8), 0, 15), ArgumentError,
     "cpb must be one of", probe_none),
    ("vcd-ring", lambda: None, lambda _: write_vcd(Path("x.vcd"), bad("ring")), ArgumentError,
     "ring must be a PinRing", probe_none),
    ("vcd-path", lambda: None, lambda _: write_vcd(bad(3), PinRing([Supi3Pins(BINARY)], record=True)), ArgumentError,
     "path must be a path", probe_none),
    # Supi3Chip
    ("chip-config", lambda: None, lambda _: Supi3Chip(bad("10011")), ArgumentError, "config must be a DeviceConfig",
     probe_none),
    ("chip-strict", lambda: None, lambda _: Supi3Chip(UP, strict=bad("yes")), ArgumentError,
     "strict must be True or False, not 'yes'", probe_none),
    ("chip-step-mfp", _up_chip, lambda c: c.step(idle_with(mfp_in=1 << 16)), ArgumentError,
     "pin 'mfp_in' must be an integer from 0 to 65535 (16 bits), not 65536", probe_chip),
    ("chip-step-missing", _up_chip, lambda c: c.step(without(IDLE, "do1")), ArgumentError,
     "not without 'do1'", probe_chip),
    ("chip-run-up", _up_chip, lambda c: c.run(traces(mfp_in=np.full(N, -1))), ArgumentError,
     "pin 'mfp_in' trace[0] must be an integer from 0 to 65535 (16 bits), not -1", probe_chip),
    ("chip-run-lengths", _up_chip, lambda c: c.run(traces(do1=np.ones(3, np.int64))), ArgumentError,
     "the length of pin 'do1' trace", probe_chip),
    ("chip-run-binary", lambda: Supi3Chip(BINARY), lambda c: c.run(traces(do1=np.full(N, 2))), ArgumentError,
     "pin 'do1' trace[0] must be an integer from 0 to 1 (1 bit), not 2", probe_chip),
    ("up-pin-inputs", lambda: None, lambda _: up_pin_inputs(1 << 16), ArgumentError,
     "mfp must be an integer from 0 to 65535 (16 bits), not 65536", probe_none),
    ("up-pin-outputs", lambda: None, lambda _: up_pin_outputs(bad(None)), ArgumentError,
     "up must be a PinsOut, not None", probe_none),
    # spi.slave_pins
    ("pinsin-2", lambda: None, lambda _: PinsIn(sclk=2), ArgumentError,
     "pin 'sclk' must be an integer from 0 to 1 (1 bit), not 2", probe_none),
    ("pinsin-half", lambda: None, lambda _: PinsIn(ss_n=bad(0.5)), ArgumentError, "pin 'ss_n' must be an integer",
     probe_none),
    ("pinsout-neg", lambda: None, lambda _: PinsOut(0, 1, 0, 1, 1, 1, 0, 0, -1, 0), ArgumentError,
     "pin 'mfp7' must be an integer from 0 to 1 (1 bit), not -1", probe_none),
    ("slave-registers", lambda: None, lambda _: SlavePins(bad(None)), ArgumentError, "registers must be a RegisterFile",
     probe_none),
    ("slave-clock", lambda: None, lambda _: SlavePins(RegisterFile(UP), clock_hz=0), ArgumentError,
     "clock_hz must be an integer >= 1, not 0", probe_none),
    ("slave-clock-float", lambda: None, lambda _: SlavePins(RegisterFile(UP), clock_hz=bad(32e6)), ArgumentError,
     "clock_hz must be an integer >= 1, not 32000000.0", probe_none),
    ("slave-tick", _slave, lambda s: s.tick(bad({"sclk": 1})), ArgumentError,
     "pins must be a PinsIn", probe_slave),
    ("slave-step-2", _slave, lambda s: s.step(
        {"sas_init": 0, "sclk": 2, "ss_n": 1, "mfp6": 0, "mfp7": 1}), ArgumentError,
     "pin 'sclk' must be an integer from 0 to 1 (1 bit), not 2", probe_slave),
    ("slave-step-missing", _slave, lambda s: s.step({"sclk": 1}), ArgumentError,
     "inputs must name exactly the pins sas_init, sclk, ss_n, mfp6, mfp7, not without 'sas_init', 'ss_n'",
     probe_slave),
    ("slave-step-unknown", _slave, lambda s: s.step(
        {"sas_init": 0, "sclk": 1, "ss_n": 1, "mfp6": 0, "mfp7": 1, "mfp8": 0}), ArgumentError,
     "with 'mfp8', no such pin", probe_slave),
    ("checker-rate", lambda: None, lambda _: TimingChecker(1_000_000, 32_000_000, print), ArgumentError,
     "bit_rate must be one of", probe_none),
    ("checker-clock", lambda: None, lambda _: TimingChecker(500_000, 0, print), ArgumentError,
     "clock_hz must be an integer >= 1, not 0", probe_none),
    ("checker-report", lambda: None, lambda _: TimingChecker(500_000, 32_000_000, bad(None)), ArgumentError,
     "report must be a callable, not None", probe_none),
    ("checker-cycle", _checker, lambda c: c.check(-1, PinsIn(), PinsOut(0, 1, 0, 1, 1, 1, 0, 0, 0, 0), False),
     ArgumentError, "cycle must be an integer >= 0, not -1", probe_none),
    ("checker-intel", _checker, lambda c: c.check(0, PinsIn(), PinsOut(0, 1, 0, 1, 1, 1, 0, 0, 0, 0), bad(1)),
     ArgumentError, "intel must be True or False, not 1", probe_none),
    # spi.block_pins
    ("strap-rate", lambda: None, lambda _: strap_values(1_000_000, 0), PinSpecError, "bit rate must be one of",
     probe_none),
    ("strap-id", lambda: None, lambda _: strap_values(500_000, 256), ArgumentError,
     "np_id must be an integer from 0 to 255 (3.4.1), not 256", probe_none),
    ("strap-length", lambda: None, lambda _: strap_values(500_000, 0, 32), ArgumentError,
     "np_length must be an integer from 0 to 31 (Table 3-11), not 32", probe_none),
    ("block-model-strict", lambda: None, lambda _: block_model(500_000, strict=bad(1)), ArgumentError,
     "strict must be True or False, not 1", probe_none),
    ("block-strict", lambda: None, lambda _: UpifBlockPins(strict=bad(None)), ArgumentError,
     "strict must be True or False, not None", probe_none),
    ("block-step-missing", UpifBlockPins, lambda b: b.step({"sclk": 1}), ArgumentError,
     "inputs must name exactly the pins", probe_block),
    ("block-step-wide", UpifBlockPins, lambda b: b.step(
        {pin.name: 0 for pin in UpifBlockPins.inputs} | {"pcmd": 256}), ArgumentError,
     "pin 'pcmd' must be an integer from 0 to 255 (8 bits), not 256", probe_block),
    ("block-step-float", UpifBlockPins, lambda b: b.step(
        {pin.name: 0 for pin in UpifBlockPins.inputs} | {"ss_n": 1.0}), ArgumentError,
     "pin 'ss_n' must be an integer from 0 to 1 (1 bit), not 1.0", probe_block),
    # rtl: constructors and the lockstep harness's pin models
    ("core-variant", lambda: None, lambda _: Supi3Core(bad("tqfp")), ArgumentError,
     "variant must be one of 'opc', 'ls' (Table 1-1), not 'tqfp'", probe_none),
    ("core-register-file", lambda: None, lambda _: Supi3Core("opc", register_file=bad(1)), ArgumentError,
     "register_file must be True or False, not 1", probe_none),
    ("rtl-chip-variant", lambda: None, lambda _: Supi3ChipRtl(bad(None)), ArgumentError, "variant must be one of",
     probe_none),
    ("core-tables-variant", lambda: None, lambda _: core_tables(bad(1)), ArgumentError, "variant must be one of",
     probe_none),
    ("strap-pins-variant", lambda: None, lambda _: StrapPins(bad("OPC")), ArgumentError, "variant must be one of",
     probe_none),
    ("strap-inputs-config", lambda: None, lambda _: strap_inputs(bad("10000")), ArgumentError,
     "config must be a DeviceConfig", probe_none),
    ("strap-stimulus-shape", lambda: None, lambda _: strap_stimulus(BINARY, np.zeros((4, 6), np.int64)),
     ArgumentError, "stimulus must be a 2-D integer array of (cycles, 8)", probe_none),
    ("strap-stimulus-level", lambda: None, lambda _: strap_stimulus(BINARY, np.full((4, 8), 2, np.int64)),
     ArgumentError, "pin 'do1' trace[0] must be an integer from 0 to 1 (1 bit), not 2", probe_none),
    ("strap-step-missing", StrapPins, lambda m: m.step(without(_strap_row(), "c")), ArgumentError, "without 'c'",
     probe_straps),
    ("strap-step-wide", StrapPins, lambda m: m.step(_strap_row(c=32)), ArgumentError,
     "pin 'c' must be an integer from 0 to 31 (5 bits), not 32", probe_straps),
    ("strap-step-core", StrapPins, lambda m: m.step(_strap_row(do1=2)), ArgumentError,
     "pin 'do1' must be an integer from 0 to 1 (1 bit), not 2", probe_straps),
    ("strap-run-core", StrapPins, lambda m: m.run(_strap_traces(do1=np.full(N, 2))), ArgumentError,
     "pin 'do1' trace[0] must be an integer from 0 to 1 (1 bit), not 2", probe_straps),
    ("strap-run-length", StrapPins, lambda m: m.run(_strap_traces(c=np.full(3, 16))), ArgumentError,
     "len(pin 'c' trace) must be 40", probe_straps),
    ("chip-strap-step-core", ChipStrapPins, lambda m: m.step(_strap_row(mfp_in=-1)), ArgumentError,
     "pin 'mfp_in' must be an integer from 0 to 65535 (16 bits), not -1", probe_straps),
    ("chip-strap-run-float", ChipStrapPins, lambda m: m.run(_strap_traces(rf=np.full(N, 3.0))), ArgumentError,
     "pin 'rf' trace must be a non-empty 1-D integer sequence", probe_straps),
]  # fmt: skip


@pytest.mark.parametrize(
    ("factory", "call", "error", "message", "probe"),
    [pytest.param(*case[1:], id=case[0]) for case in CASES],
)
def test_hostile_call_is_named_and_changes_nothing(
    factory: Factory, call: Call, error: type[Exception], message: str, probe: Callable[[Any], object]
) -> None:
    target, twin = factory(), factory()
    with pytest.raises(error) as caught:
        call(target)
    assert isinstance(caught.value, Supi3Error), type(caught.value)  # never a bare builtin error
    assert message in str(caught.value), str(caught.value)
    assert probe(target) == probe(twin)


def test_golden_reference_no_longer_forwards_a_level_of_2() -> None:
    # Before: do1 = 2 came out as do2 = di1 = 2 three bit periods later.
    model = Supi3Pins(BINARY)
    with pytest.raises(ArgumentError, match="pin 'do1'"):
        model.run(traces(do1=np.where(np.arange(N) == 5, 2, 1)))
    assert model.cycle == 0


def test_set_input_reaches_the_chip_at_its_position() -> None:
    ring = _ring()
    ring.set_input(1, "mfp_in", bad(np.uint16(0xAB)))
    ring.set_input(2, "stat_err_n", 0)
    assert [pins["mfp_in"] for pins in ring._inputs] == [0xAB, 0]
    assert [pins["stat_err_n"] for pins in ring._inputs] == [1, 0]
    assert type(ring._inputs[0]["mfp_in"]) is int


def test_numpy_integers_and_narrow_dtypes_are_levels() -> None:
    # Exactly representable integer levels pass, whatever their integer type: a step with numpy scalars and a run
    # with uint8 traces agree with plain ints.
    a, b = Supi3Pins(BINARY), Supi3Pins(BINARY)
    row = a.step({name: bad(np.int64(value)) for name, value in IDLE.items()})
    assert row == b.step(IDLE)
    narrow = {name: trace.astype(np.uint8 if name != "mfp_in" else np.uint16) for name, trace in traces().items()}
    assert {k: v.tolist() for k, v in a.run(narrow).items()} == {k: v.tolist() for k, v in b.run(traces()).items()}


def test_checker_reports_are_interface_violations() -> None:
    seen: list[InterfaceViolationError] = []
    checker = TimingChecker(500_000, 32_000_000, seen.append)
    checker.check(0, PinsIn(sas_init=1), PinsOut(0, 1, 0, 1, 1, 1, 0, 0, 0, 0), False)
    checker.check(1, PinsIn(sas_init=0), PinsOut(0, 1, 0, 1, 1, 1, 0, 0, 0, 0), False)
    assert [type(v).__name__ for v in seen] == ["TimingViolationError"]

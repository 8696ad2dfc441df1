"""The whole chip at pin level: the INTERBUS core and, in the Init-µP modes, the serial µP interface.

:class:`Supi3Chip` joins :class:`~supi3.model.pins.Supi3Pins` (the INTERBUS core) and
:class:`~supi3.spi.slave_pins.SlavePins` (the serial µP interface of 3.4) through the one register file both
use: the interface reads and writes it on the µP's accesses, the core latches OUT data into it, takes IN data
from it, and raises its interrupt events, I/O access bit and latch phase (docs/upif.md, "Register file").

MFP[7..0] are the µP interface's pins in the Init-µP modes (Tables 3-5 and 3-6): SAS_INIT on MFP0, I/O on
MFP1, C/D on MFP2, /IRQ on MFP3, SCLK on MFP4, /SS on MFP5, SerIN or Ser_IN/OUT on MFP6, SerOUT or S/R on MFP7.
MFP[15..8] stay with the core (bus terminal signals in BK modes). While the core is in reset (it drives
``resu_drive``, or a power-up reset begins at this clock edge), the µP interface is held in reset too (docs/model.md
M2).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Final

import numpy as np
import numpy.typing as npt

from supi3 import pinout
from supi3.checks import check_bits, check_bool, check_instance
from supi3.config import DeviceConfig
from supi3.model.chip import Supi3
from supi3.model.pins import PinTrace, Supi3Pins, input_traces
from supi3.pinlevel import OE_SUFFIX, Pin
from supi3.spi.slave_pins import PinsIn, PinsOut, SlavePins

UP_INPUTS: Final = pinout.UP_INPUTS
"""The MFP pin of each input of the µP interface (:class:`PinsIn` field, Tables 3-5 and 3-6)."""
UP_OUTPUTS: Final = pinout.UP_OUTPUTS
"""The MFP pin of each output of the µP interface (:class:`PinsOut` field; its enable is ``<field>_oe``)."""
UP_PINS: Final = pinout.UP_PINS
"""MFP[7..0]: the µP interface's pins in the Init-µP modes."""


def up_pin_inputs(mfp: int) -> PinsIn:
    """The µP interface's inputs from the MFP[15..0] input levels."""
    mfp = check_bits("mfp", mfp, 16)
    return PinsIn(**{name: (mfp >> pin) & 1 for name, pin in UP_INPUTS.items()})


def up_pin_outputs(up: PinsOut) -> tuple[int, int]:
    """The MFP levels (undriven bits 0) and output enables of the µP interface's outputs ``up``."""
    check_instance("up", up, PinsOut)
    enables = sum(getattr(up, name + OE_SUFFIX) << pin for name, pin in UP_OUTPUTS.items())
    levels = sum(getattr(up, name) << pin for name, pin in UP_OUTPUTS.items())
    return levels & enables, enables


class Supi3Chip:
    """One SUPI 3 chip, every pin, one 32 MHz clock per :meth:`step` (the convention of
    :mod:`supi3.pinlevel`).

    Parameters
    ----------
    config:
        The pin straps.
    strict:
        µP interface rule violations (Table 3-7 timing, protocol, reconfiguration, inconsistent data) raise
        (``True``) or are recorded in ``registers.violations`` (``False``).
    pedantic:
        Also report suspicious µP accesses (:class:`~supi3.model.chip.Supi3`).
    """

    inputs: Sequence[Pin] = Supi3Pins.inputs
    outputs: Sequence[Pin] = Supi3Pins.outputs

    def __init__(self, config: DeviceConfig, *, strict: bool = True, pedantic: bool = False) -> None:
        check_instance("config", config, DeviceConfig)
        check_bool("strict", strict)
        self.core = Supi3Pins(config, Supi3(config, strict=strict, pedantic=pedantic))
        registers = self.core.chip.registers
        self.upif = SlavePins(registers) if registers is not None else None
        if registers is not None:
            # The µP interface ticks after the core's step, so the cycle it clocks is core.cycle - 1 (UP-19).
            registers.use_clock(lambda: self.core.cycle - 1)

    @property
    def chip(self) -> Supi3:
        """The bus behaviour (and, in µP modes, ``chip.registers``)."""
        return self.core.chip

    def reset(self) -> None:
        """The state after the ``sync`` reset."""
        self.core.reset()
        if self.upif is not None:
            self.upif.reset()

    def step(self, inputs: Mapping[str, int]) -> dict[str, int]:
        """Run one clock cycle.

        Raises
        ------
        ArgumentError
            As :meth:`Supi3Pins.step`: a pin missing or unknown, or a level out of its pin's width (nothing changes).
        """
        out = self.core.step(inputs)
        if self.upif is None:
            return out
        up = self.upif.tick(up_pin_inputs(int(inputs["mfp_in"])))
        if out["resu_drive"] or self.core.holding:
            self.upif.reset()
        levels, enables = up_pin_outputs(up)
        out["mfp_out"] = (out["mfp_out"] & ~UP_PINS) | levels
        out["mfp_oe"] = (out["mfp_oe"] & ~UP_PINS) | enables
        return out

    def run(self, inputs: Mapping[str, Sequence[int] | npt.NDArray[np.generic]]) -> dict[str, PinTrace]:
        """Whole traces at once: the core's event-driven :meth:`Supi3Pins.run` without a µP interface, else
        cycle by cycle (the interface and the core meet in the register file at any cycle).

        Raises
        ------
        ArgumentError
            As :meth:`Supi3Pins.run` (:func:`~supi3.model.pins.input_traces`); nothing changes.
        """
        if self.upif is None:
            return self.core.run(inputs)
        traces = input_traces(inputs)  # every trace checked before the first cycle runs
        names = [pin.name for pin in self.inputs]
        columns = [traces[name].tolist() for name in names]
        rows = [self.step(dict(zip(names, values, strict=True))) for values in zip(*columns, strict=True)]
        return {pin.name: np.array([row[pin.name] for row in rows], dtype=np.int64) for pin in self.outputs}

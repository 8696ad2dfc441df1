"""The whole chip at pin level: the INTERBUS core and, in the Init-µP modes, the serial µP interface.

:class:`Supi3Chip` joins :class:`~supi3.model.pins.Supi3Pins` (the INTERBUS core) and
:class:`~supi3.spi.slave_pins.SlavePins` (the serial µP interface of 3.4) through the one register file both
use: the interface reads and writes it on the µP's accesses, the core latches OUT data into it, takes IN data
from it, and raises its interrupt events, I/O access bit and latch phase (docs/upif.md, "Register file").

MFP[7..0] are the µP interface's pins in the Init-µP modes (Tables 3-5 and 3-6): SAS_INIT on MFP0, I/O on
MFP1, C/D on MFP2, /IRQ on MFP3, SCLK on MFP4, /SS on MFP5, SerIN or Ser_IN/OUT on MFP6, SerOUT or S/R on MFP7.
MFP[15..8] stay with the core (bus terminal signals in BK modes). While the core is in reset (it drives
``resu_drive``), the µP interface is held in reset too (docs/model.md M2).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import numpy.typing as npt

from supi3.config import DeviceConfig
from supi3.model.chip import Supi3
from supi3.model.pins import Supi3Pins, Trace
from supi3.spi.slave_pins import PinsIn, SlavePins
from supi3.verif.pinmodel import Pin

UP_PINS = 0x00FF
"""MFP[7..0]: the µP interface's pins in the Init-µP modes."""


class Supi3Chip:
    """One SUPI 3 chip, every pin, one 32 MHz clock per :meth:`step` (the convention of
    :mod:`supi3.verif.pinmodel`).

    Parameters
    ----------
    config:
        The pin straps.
    strict:
        µP interface rule violations (Table 3-7 timing, protocol, reconfiguration, inconsistent data) raise
        (``True``) or are recorded in ``registers.violations`` (``False``).
    """

    inputs: Sequence[Pin] = Supi3Pins.inputs
    outputs: Sequence[Pin] = Supi3Pins.outputs

    def __init__(self, config: DeviceConfig, *, strict: bool = True) -> None:
        self.core = Supi3Pins(config, Supi3(config, strict=strict))
        registers = self.core.chip.registers
        self.upif = SlavePins(registers) if registers is not None else None

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
        """Run one clock cycle."""
        out = self.core.step(inputs)
        if self.upif is None:
            return out
        mfp = int(inputs["mfp_in"])
        up = self.upif.tick(PinsIn(sas_init=mfp & 1, sclk=(mfp >> 4) & 1, ss_n=(mfp >> 5) & 1,
                                   mfp6=(mfp >> 6) & 1, mfp7=(mfp >> 7) & 1))
        if out["resu_drive"]:
            self.upif.reset()
        levels = (up.io << 1) | (up.c_d << 2) | (up.irq_n << 3) | (up.mfp6 << 6) | (up.mfp7 << 7)
        enables = (up.io_oe << 1) | (up.c_d_oe << 2) | (up.irq_n_oe << 3) | (up.mfp6_oe << 6) | (up.mfp7_oe << 7)
        out["mfp_out"] = (out["mfp_out"] & ~UP_PINS) | (levels & enables)
        out["mfp_oe"] = (out["mfp_oe"] & ~UP_PINS) | enables
        return out

    def run(self, inputs: Mapping[str, Sequence[int] | npt.NDArray[np.generic]]) -> dict[str, Trace]:
        """Whole traces at once: the core's event-driven :meth:`Supi3Pins.run` without a µP interface, else
        cycle by cycle (the interface and the core meet in the register file at any cycle)."""
        if self.upif is None:
            return self.core.run(inputs)
        names = [pin.name for pin in self.inputs]
        columns = [np.asarray(inputs[name], dtype=np.int64).tolist() for name in names]
        rows = [self.step(dict(zip(names, values, strict=True))) for values in zip(*columns, strict=True)]
        return {pin.name: np.array([row[pin.name] for row in rows], dtype=np.int64) for pin in self.outputs}

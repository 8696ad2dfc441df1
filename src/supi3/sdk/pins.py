"""The whole chip at pin level behind the Python firmware driver: a software µP on ``Supi3Chip``'s MFP pins.

Ref: IBS SUPI 3 OPC UM E rev. 05, 3.4.2 (frames), Table 3-7 (timing), Tables 3-5 and 3-6 (pins). Each byte the
driver sends is one :meth:`supi3.spi.master.SoftMaster.byte` at the fastest Table 3-7 timing (or the one given)
through a :class:`supi3.top.ChipPort`, which runs the chip event-driven between the µP's edges; C/D, /IRQ and the I/O
bit are the chip's output pins, SAS_INIT a pulse on MFP0. INTERBUS line samples fed to :attr:`PinTransport.port`
reach the chip while the µP works, so the same driver code runs against the cycle-accurate chip as against the
transaction-level model (tests/test_sdk_pins.py compares the two).
"""

from __future__ import annotations

import contextlib
import math
from typing import Final

from supi3.checks import check_int, check_real, describe
from supi3.interbus import wire
from supi3.model.pins import RESET_STRETCH_CLOCKS
from supi3.sdk.driver import UNDRIVEN_BYTE, DriverArgumentError, Mode, Transport
from supi3.spi.master import MasterTiming, SoftMaster
from supi3.top import ChipPort, Supi3Chip

__all__ = ["SETTLE_CYCLES", "PinTransport"]

SETTLE_CYCLES: Final = 2 * RESET_STRETCH_CLOCKS
"""Clocks the µP holds its pins at rest before its first byte: the power-up reset and its 4 µs stretch hold the µP
interface in reset (1.7.2, M2), with margin."""


class PinTransport(Transport):
    """The pin-level whole chip (:class:`~supi3.top.Supi3Chip`, an Init-µP mode) behind the driver.

    Parameters
    ----------
    chip:
        The chip.
    mode:
        The interface type the firmware will initialize (the bit order on the wire, UP-6).
    timing:
        The µP's edge placement; default :meth:`MasterTiming.fastest` at the chip's bit rate.
    record:
        Keep the µP's pins for :meth:`SoftMaster.trace` (waveforms; slower).
    inputs:
        Levels of the chip's other input pins (``ChipPort``), e.g. ``stat_err_n=0``.

    Attributes
    ----------
    port, master:
        The :class:`ChipPort` (``port.feed(samples)`` puts INTERBUS line samples on ``do1``) and the software µP.
    """

    def __init__(self, chip: Supi3Chip, mode: Mode, *, timing: MasterTiming | None = None, record: bool = False,
                 **inputs: int) -> None:  # fmt: skip
        if type(mode) is not Mode:
            raise DriverArgumentError("mode", mode, f"mode must be Mode.MOTOROLA or Mode.INTEL, not {describe(mode)}")
        self.port = ChipPort(chip, **inputs)
        self.master = SoftMaster(self.port, mode, timing, record=record)
        self.master.run(SETTLE_CYCLES)

    @property
    def chip(self) -> Supi3Chip:
        """The chip behind the port."""
        return self.port.chip

    def xfer(self, tx: int, s_r: bool) -> int:
        """One frame: the gap, /SS low, 8 SCLK periods, /SS high (the chip takes the byte at its rising edge). A
        frame the chip does not drive reads FFh (FW-26)."""
        master = self.master
        rx = master.byte(tx, s_r=s_r)
        master.deselect()
        return UNDRIVEN_BYTE if rx is None else rx

    def delay_us(self, us: float) -> None:
        """Hold the pins for ``us`` microseconds (rounded up to whole clocks), at most the bus time's maximum (A26)."""
        us = check_real("us", us, 0.0, wire.MAX_BUS_TIME_S * 1e6)
        self.master.run(math.ceil(us * 1e-6 * self.port.clock_hz))

    def read_cd(self) -> int:
        """C/D (MFP2) now."""
        return self.master.c_d

    def read_irq(self) -> int:
        """/IRQ (MFP3) now."""
        return self.master.irq_n

    def read_io(self) -> int:
        """The I/O access bit (MFP1) now."""
        return self.master.io

    def set_sas_init(self, level: int) -> bool:
        """SAS_INIT (MFP0): ``1`` pulses it for the shortest time Table 3-7 allows; ``0`` (its end) does nothing.

        Raises
        ------
        ArgumentError
            ``level`` not 0 or 1 (nothing is pulsed).
        """
        if check_int("level", level, 0, 1):
            self.master.pulse_sas_init()
        return True

    def access(self) -> contextlib.AbstractContextManager[None]:
        """Strict-mode violations the chip finds wait for the end of the driver call."""
        return self.port.registers.violations.deferred()

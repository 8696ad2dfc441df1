"""Peripheral models for the chip's serial interfaces (docs/peripherals.md): shift registers, an ADC, a DAC and a
bus on the serial I/O of the SPI master mode (manual 3.3), and the IBS SRE 1 role on the serial register expansion
(3.5). Each works at transaction level and at pin level through the protocols of the spec
(:class:`supi3.spi.serial_io.SerialDevice`, :class:`supi3.expansion.ExternalRegisters`)."""

from supi3.peripherals.serial import SerialBus, SerInConflictError, ShiftIn, ShiftOut, SpiAdc, SpiDac
from supi3.peripherals.sre import Sre1

__all__ = ["SerInConflictError", "SerialBus", "ShiftIn", "ShiftOut", "SpiAdc", "SpiDac", "Sre1"]

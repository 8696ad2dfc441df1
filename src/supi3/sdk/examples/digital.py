"""A 16 IN / 16 OUT digital device (ID 03h, DIO, Table A-3), register by register.

Ref: IBS SUPI 3 OPC UM E rev. 05, 3.4.3 (initialization), 3.4.5 (SET and ID before the bus runs), 3.4.4 (one
register per command), 3.4.7 and 3.4.8 (IN0/IN1, OUT0/OUT1; address 0 the most significant byte), 3.4.14 (the
"valid data cycle" interrupt: after it the data registers may be accessed until the next latch phase).
"""

from __future__ import annotations

from typing import Final

from supi3.regmap import IN0, IN1, OUT0, OUT1
from supi3.sdk.bench import Firmware
from supi3.sdk.driver import Irq, Mode, Supi3Driver

__all__ = ["DIO_ID", "ONE_WORD_IO", "DigitalIo"]

ONE_WORD_IO: Final = 0x83
"""SET: /PCP = 1 (I/O device), ExtReg = 0, CL = 011 (1 word) (3.4.5, Table 3-12)."""
DIO_ID: Final = 0x03
"""ID code 03h: digital input/output module, remote bus (Table A-3)."""


class DigitalIo(Firmware):
    """16 digital inputs to the master, 16 digital outputs from it.

    :attr:`inputs` is what the device's input terminals read (a test or the board sets it); :attr:`outputs` is what
    the firmware last drove on its output terminals. On each VALID interrupt the firmware reads OUT0, OUT1 and writes
    IN0, IN1: the master gets the inputs in the next data cycle.
    """

    DATA_BYTES = 2

    def __init__(self, mode: Mode = Mode.MOTOROLA) -> None:
        self.mode = mode
        self.inputs = 0
        self.outputs = 0

    def setup(self, drv: Supi3Driver) -> None:
        drv.initialize(self.mode)
        drv.configure(ONE_WORD_IO, DIO_ID)
        drv.irq_enable(Irq.VALID)

    def isr(self, drv: Supi3Driver) -> None:
        if drv.irq_service() & Irq.VALID:
            self.outputs = drv.read(OUT0) << 8 | drv.read(OUT1)
            drv.write(IN0, self.inputs >> 8)
            drv.write(IN1, self.inputs & 0xFF)

"""A 32-bit analog input/output device (ID 33h, AIO, Table A-3): one block transfer of two words per data cycle.

Ref: IBS SUPI 3 OPC UM E rev. 05, 3.4.5 (SET: 2 words), 3.4.6 (block transfer at address 15, the configured length),
3.4.8 (IN0..IN3 / OUT0..OUT3, byte 0 the most significant), 3.4.14 (VALID interrupt).
"""

from __future__ import annotations

from typing import Final

from supi3.sdk.bench import Firmware
from supi3.sdk.driver import Irq, Mode, Supi3Driver, get_u32, put_u32

__all__ = ["AIO_ID", "TWO_WORDS_IO", "AnalogIo"]

TWO_WORDS_IO: Final = 0x85
"""SET: /PCP = 1, ExtReg = 0, CL = 101 (2 words) (3.4.5, Table 3-12)."""
AIO_ID: Final = 0x33
"""ID code 33h: analog input/output module, remote bus (Table A-3)."""


class AnalogIo(Firmware):
    """A 32-bit ADC value to the master (:attr:`inputs`), a 32-bit DAC value from it (:attr:`outputs`).

    On each VALID interrupt one block transfer reads OUT0..OUT3 and writes IN0..IN3 (Motorola: full duplex; Intel:
    four reads, then four writes, Fig. 3-12).
    """

    DATA_BYTES = 4

    def __init__(self, mode: Mode = Mode.MOTOROLA) -> None:
        self.mode = mode
        self.inputs = 0
        self.outputs = 0

    def setup(self, drv: Supi3Driver) -> None:
        drv.initialize(self.mode)
        drv.configure(TWO_WORDS_IO, AIO_ID)
        drv.irq_enable(Irq.VALID)

    def isr(self, drv: Supi3Driver) -> None:
        if drv.irq_service() & Irq.VALID:
            self.outputs = get_u32(drv.block_transfer(put_u32(self.inputs)))

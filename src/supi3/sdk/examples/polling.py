"""A polling device: no interrupts; the firmware polls the I/O access bit before each data access.

Ref: IBS SUPI 3 OPC UM E rev. 05, 3.4.14 ("Using the polling bit", Fig. 3-22): while the bit reads 1 the data
registers may not be accessed; once it reads 0 they may be for the next 30 bit periods (60 µs at 500 kbit/s), after
which the latch phase may begin, and an access there may read or write inconsistent data. Without the I/O pin
(MFP1) wired, the driver reads the bit as D7 of the interrupt event register (address 14).
"""

from __future__ import annotations

from typing import Final

from supi3.sdk.bench import Firmware
from supi3.sdk.driver import Mode, Supi3Driver, get_u16, put_u16
from supi3.sdk.examples.digital import DIO_ID, ONE_WORD_IO

__all__ = ["MAX_POLLS", "PollingIo"]

MAX_POLLS: Final = 10_000
"""Polls before the firmware gives up on the bus (``IoWindowTimeoutError``): far more than one bus cycle."""


class PollingIo(Firmware):
    """16/16 process data from the main loop: poll, then one block transfer inside the window.

    :attr:`inputs` goes to the master, :attr:`outputs` is the master's last word.
    """

    DATA_BYTES = 2

    def __init__(self, mode: Mode = Mode.MOTOROLA) -> None:
        self.mode = mode
        self.inputs = 0
        self.outputs = 0

    def setup(self, drv: Supi3Driver) -> None:
        drv.initialize(self.mode)
        drv.configure(ONE_WORD_IO, DIO_ID)

    def loop(self, drv: Supi3Driver) -> None:
        drv.poll_io_window(MAX_POLLS)
        self.exchange(drv)

    def exchange(self, drv: Supi3Driver) -> None:
        """The data access itself: one block transfer (3 bytes, well inside 30 bit periods at the fastest SCLK)."""
        self.outputs = get_u16(drv.block_transfer(put_u16(self.inputs)))

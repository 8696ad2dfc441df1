"""A device that reports a peripheral fault on /StatErr and clears it when the master acknowledges.

Ref: IBS SUPI 3 OPC UM E rev. 05, 3.6.2: /StatErr low reports an I/O error (filtered, t3 = 200 ms +-31.5 %), the
master sees "I/O Device Error Indication" 0BB1h; the master's "Quit Peripheral Error" (0714h) pulses /ModAck.
"""

from __future__ import annotations

from typing import Protocol

from supi3.sdk.bench import Firmware
from supi3.sdk.driver import Irq, Mode, Supi3Driver, get_u16, put_u16
from supi3.sdk.examples.digital import DIO_ID, ONE_WORD_IO

__all__ = ["FaultBoard", "PeripheralFault"]


class FaultBoard(Protocol):
    """The board pins the fault example uses (:class:`~supi3.sdk.bench.Bench` has them)."""

    def set_stat_err(self, active: bool) -> None:
        """Drive /StatErr (``True``: low, a fault reported)."""

    @property
    def mod_ack_pulses(self) -> int:
        """/ModAck pulses so far (an edge-triggered input)."""
        ...


class PeripheralFault(Firmware):
    """16/16 process data on VALID, plus an I/O supply monitor.

    :attr:`io_fault` is the monitored condition (a test sets it). The firmware drives /StatErr low while the
    condition lasts; the chip latches the fault after its filter time and the master reports 0BB1h. The device
    itself stays in its fault state (outputs held at the safe state 0, :attr:`faulted`) until the master has quit
    the error (a /ModAck pulse) after the condition has gone: the chip clears its fault bit only if /StatErr is high
    at the Quit (docs/model.md), and the firmware restarts its outputs only on that acknowledgment.
    """

    DATA_BYTES = 2

    def __init__(self, board: FaultBoard, mode: Mode = Mode.MOTOROLA) -> None:
        self.board = board
        self.mode = mode
        self.io_fault = False
        self.faulted = False
        self.stat_err = False
        self.outputs = 0
        self.inputs = 0
        self._acks_seen = 0

    def setup(self, drv: Supi3Driver) -> None:
        drv.initialize(self.mode)
        drv.configure(ONE_WORD_IO, DIO_ID)
        drv.irq_enable(Irq.VALID)
        self._acks_seen = self.board.mod_ack_pulses

    def isr(self, drv: Supi3Driver) -> None:
        if drv.irq_service() & Irq.VALID:
            word = get_u16(drv.block_transfer(put_u16(self.inputs)))
            self.supervise()
            self.outputs = 0 if self.faulted else word

    def supervise(self) -> None:
        """/StatErr follows the fault condition; the fault state ends at a /ModAck pulse once the condition has gone."""
        acks = self.board.mod_ack_pulses
        acknowledged, self._acks_seen = acks != self._acks_seen, acks
        if self.io_fault != self.stat_err:
            self.stat_err = self.io_fault
            self.board.set_stat_err(self.io_fault)
        if self.io_fault:
            self.faulted = True
        elif acknowledged:
            self.faulted = False

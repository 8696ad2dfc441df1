"""An interrupt-driven device: every bus event the firmware cares about comes as an interrupt.

Ref: IBS SUPI 3 OPC UM E rev. 05, 3.4.14 ("Using interrupts": enable once, /IRQ low, read the event register, which
clears it and releases /IRQ), Table 3-13 / Fig. 3-19 (the sources), 3.4.7 (an INTERBUS reset clears the data
registers).
"""

from __future__ import annotations

from collections import Counter

from supi3.sdk.bench import Firmware
from supi3.sdk.driver import Irq, Mode, Supi3Driver, get_u16, put_u16
from supi3.sdk.examples.digital import DIO_ID, ONE_WORD_IO

__all__ = ["InterruptDriven"]


class InterruptDriven(Firmware):
    """16/16 process data on VALID, and the bus's state from the other events.

    - VALID: one block transfer: the terminals' word (:attr:`inputs`) to the master, the master's word to the
      outputs (:attr:`outputs`);
    - IB_RESET: the master reset the bus: outputs to the safe state 0 (3.4.7);
    - ID_CYCLE: counted (the master configures or diagnoses the ring).

    :attr:`events` counts each source taken; :attr:`history` keeps the output words in order.
    """

    DATA_BYTES = 2
    SOURCES = Irq.VALID | Irq.ID_CYCLE | Irq.IB_RESET

    def __init__(self, mode: Mode = Mode.MOTOROLA) -> None:
        self.mode = mode
        self.inputs = 0
        self.outputs = 0
        self.events: Counter[str] = Counter()
        self.history: list[int] = []

    def setup(self, drv: Supi3Driver) -> None:
        drv.initialize(self.mode)
        drv.configure(ONE_WORD_IO, DIO_ID)
        drv.irq_enable(self.SOURCES)

    def isr(self, drv: Supi3Driver) -> None:
        events = drv.irq_service()
        for source in Irq:
            if events & source:
                self.events[str(source.name)] += 1
        if events & Irq.IB_RESET:
            self.outputs = 0
        if events & Irq.VALID:
            self.outputs = get_u16(drv.block_transfer(put_u16(self.inputs)))
            self.history.append(self.outputs)

"""The management channel: the master sends processor commands, the firmware answers with processor alarms.

Ref: IBS SUPI 3 OPC UM E rev. 05, 3.4.9 (processor command register, read at address 7, with its interrupt; processor
alarm register, written at address 7, read by the master), 3.4.14 (the PCMD interrupt source); the master's side
of the channel is assumption A18 (docs/assumptions/interbus.md).
"""

from __future__ import annotations

from typing import Final

from supi3.sdk.bench import Firmware
from supi3.sdk.driver import Irq, Mode, Supi3Driver
from supi3.sdk.examples.digital import DIO_ID, ONE_WORD_IO
from supi3.sdk.examples.history import ProcessBench

__all__ = ["STATUS_REQUEST", "ManagementChannel", "ask"]

STATUS_REQUEST: Final = 0x01
"""This example's command "report your status": answered with :attr:`ManagementChannel.status`."""


class ManagementChannel(Firmware):
    """Answers every processor command with an alarm byte: :attr:`status` for :data:`STATUS_REQUEST`, else the
    command's one's complement (an echo the master can check). :attr:`commands` keeps the commands received."""

    def __init__(self, mode: Mode = Mode.MOTOROLA, status: int = 0x5A) -> None:
        self.mode = mode
        self.status = status
        self.commands: list[int] = []

    def setup(self, drv: Supi3Driver) -> None:
        drv.initialize(self.mode)
        drv.configure(ONE_WORD_IO, DIO_ID)
        drv.irq_enable(Irq.PCMD)

    def isr(self, drv: Supi3Driver) -> None:
        if drv.irq_service() & Irq.PCMD:
            command = drv.processor_command()
            self.commands.append(command)
            drv.processor_alarm(self.answer(command))

    def answer(self, command: int) -> int:
        """The alarm byte for ``command``."""
        return self.status if command == STATUS_REQUEST else command ^ 0xFF


def ask(bench: ProcessBench, command: int) -> int | None:
    """The master sends ``command`` to the device at ring position 1, then asks for its processor alarm: the ID cycle
    carrying the command and one for the PCMD interrupt to run, then the request and the answer in place of the ID
    code (A18). The alarm byte the master read (taken out of its ``processor_alarms``), ``None`` if none came; on
    either bench (:class:`~supi3.sdk.bench.Bench`, :class:`~supi3.sdk.rtl.RtlBench`)."""
    bench.master.processor_command(1, command)
    bench.run(2)
    bench.master.request_processor_alarm(1)
    bench.run(3)
    return bench.master.processor_alarms.pop(1, None)

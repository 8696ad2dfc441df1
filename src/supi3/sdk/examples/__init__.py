"""Example firmware for the SUPI 3 in Python, one short :class:`~supi3.sdk.bench.Firmware` per module.

Each runs unchanged on the transaction-level bench (:class:`supi3.sdk.bench.Bench`) and, through
:mod:`supi3.sdk.rtl`, on the RTL chip; tests/test_sdk_examples.py and tests/test_sdk_rtl.py drive them with an
INTERBUS master. Guide: docs/sdk-firmware-python.md.

- :class:`DigitalIo`: 16 IN / 16 OUT digital device, register by register on the VALID interrupt (3.4.4, 3.4.14).
- :class:`AnalogIo`: 32-bit analog device, one block transfer of two words (3.4.6, 3.4.8).
- :class:`InterruptDriven`: every bus event by interrupt: data, ID cycles, INTERBUS reset (3.4.14, Table 3-13).
- :class:`PollingIo`: no interrupts, the I/O access bit polled before each access (3.4.14, Fig. 3-22).
- :class:`PeripheralFault`: reports an I/O fault on /StatErr, clears it on Quit Peripheral Error (3.6.2).
- :class:`ManagementChannel`: answers processor commands with processor alarms (3.4.9).

:func:`play` runs a process data history through any of the I/O examples on either bench.
"""

from __future__ import annotations

from supi3.sdk.examples.analog import AnalogIo
from supi3.sdk.examples.digital import DigitalIo
from supi3.sdk.examples.fault import FaultBoard, PeripheralFault
from supi3.sdk.examples.history import ProcessBench, ProcessDevice, play
from supi3.sdk.examples.interrupts import InterruptDriven
from supi3.sdk.examples.management import ManagementChannel
from supi3.sdk.examples.polling import PollingIo

__all__ = [
    "AnalogIo",
    "DigitalIo",
    "FaultBoard",
    "InterruptDriven",
    "ManagementChannel",
    "PeripheralFault",
    "PollingIo",
    "ProcessBench",
    "ProcessDevice",
    "play",
]

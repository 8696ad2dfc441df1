"""INTERBUS layer 1/2: wire format, transaction-level ring and master (docs/interbus.md)."""

from supi3.interbus.device import Layer2Watchdog, PlainDevice
from supi3.interbus.errors import InterbusError, TelegramError
from supi3.interbus.link import Device
from supi3.interbus.master import (
    ALARM_STOP,
    CONTROL_DEVICE_FUNCTION,
    MSG_PERIPHERAL_FAULT,
    MSG_WATCHDOG,
    ConfigEntry,
    CycleResult,
    Diagnostic,
    InterfaceType,
    Master,
)
from supi3.interbus.ring import (
    BitFlip,
    CorruptLoopback,
    DeadLine,
    ErrorKind,
    Fault,
    Ring,
    SegmentTrace,
    Transfer,
    Truncate,
)
from supi3.interbus.wire import Cycle, Frame

__all__ = [
    "ALARM_STOP",
    "CONTROL_DEVICE_FUNCTION",
    "MSG_PERIPHERAL_FAULT",
    "MSG_WATCHDOG",
    "BitFlip",
    "ConfigEntry",
    "CorruptLoopback",
    "Cycle",
    "CycleResult",
    "DeadLine",
    "Device",
    "Diagnostic",
    "ErrorKind",
    "Fault",
    "Frame",
    "InterbusError",
    "InterfaceType",
    "Layer2Watchdog",
    "Master",
    "PlainDevice",
    "Ring",
    "SegmentTrace",
    "TelegramError",
    "Transfer",
    "Truncate",
]

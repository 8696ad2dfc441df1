"""A plain register device of the ring (the device interface it implements is :mod:`supi3.interbus.link`)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import ClassVar

from supi3.checks import check_bool, check_bytes, check_instance, check_int, check_real
from supi3.interbus import wire
from supi3.interbus.errors import InterbusError, checked
from supi3.interbus.link import DataKernel
from supi3.interbus.wire import Cycle
from supi3.tables import WATCHDOG_TIMEOUTS_S

_DATA = Cycle.DATA  # enum member lookups cost ~0.1 µs; the hot path compares with this alias
_ID = Cycle.ID


def _now(now: object) -> float:
    """A bus time: a finite number >= 0 (the named error otherwise)."""
    if type(now) is float and 0.0 <= now < math.inf:
        return now
    return checked(check_real, "now", now, 0.0)


def _cycle(cycle: object) -> Cycle:
    if cycle is _DATA or cycle is _ID:
        return cycle
    return checked(check_instance, "cycle", cycle, Cycle, "Cycle.ID or Cycle.DATA")


class Layer2Watchdog:
    """The layer-2 watchdog of Table 3-13: set by the master, resets process data when no valid data cycle
    arrives within the set time (50 ms, 200 ms, 1000 ms or off; off after power-up and INTERBUS reset).

    Attributes
    ----------
    timeout_s:
        The set time, ``None`` when off.
    deadline:
        Bus time at which the watchdog expires (``math.inf`` when off or already expired).
    """

    def __init__(self) -> None:
        self.timeout_s: float | None = None
        self.deadline = math.inf

    def configure(self, code: int, now: float) -> None:
        """Apply a command word's watchdog code (an index into ``WATCHDOG_TIMEOUTS_S``)."""
        code = checked(check_int, "code", code, 0, len(WATCHDOG_TIMEOUTS_S) - 1, limit="Table 3-13")
        now = _now(now)
        self.timeout_s = WATCHDOG_TIMEOUTS_S[code]
        self.kick(now)

    def off(self) -> None:
        """Switch the watchdog off (INTERBUS reset)."""
        self.timeout_s = None
        self.deadline = math.inf

    def kick(self, now: float) -> None:
        """A valid data cycle ended at ``now``."""
        now = _now(now)
        self.deadline = math.inf if self.timeout_s is None else now + self.timeout_s

    def expired(self, now: float) -> bool:
        """``True`` once when the set time has passed since the last valid data cycle."""
        now = _now(now)
        if now > self.deadline:
            self.deadline = math.inf
            return True
        return False


def _load_plain_run(devices: Sequence[PlainDevice], now: float) -> tuple[list[bytes], bool]:
    """``[d.load(Cycle.DATA, now) for d in devices]`` and whether any device wants attention afterwards."""
    registers: list[bytes] = []
    append = registers.append
    attention = False
    for device in devices:
        if now > device.watchdog.deadline:
            device._tick(now)
        append(device.inputs)
        if device.attention:
            attention = True
    return registers, attention


def _latch_plain_run(devices: Sequence[PlainDevice], received: Sequence[bytes], now: float) -> None:
    """``d.latch(Cycle.DATA, r, now)`` for every device ``d`` and its ``r``."""
    for device, data in zip(devices, received, strict=True):
        device.outputs = data
        device._te = False
        if device.watchdog.timeout_s is not None:
            device.watchdog.kick(now)
        device.valid_cycles += 1


class PlainDevice:
    """A plain INTERBUS register device: an ID code, a length code, IN and OUT data registers.

    Stands for devices that are not SUPI 3 based. Implements :class:`Device`.

    Parameters
    ----------
    id_code:
        ID code, 0..255 (Table A-3; any value is accepted).
    length_code:
        Length code (Table 3-11); reserved codes are refused.

    Attributes
    ----------
    attention:
        See :attr:`Device.attention`.
    inputs:
        IN data the device sends in the next data cycle (set with :meth:`set_inputs`).
    outputs:
        OUT data latched from the last valid data cycle.
    mod_ack_pulses:
        /ModAck pulses so far: one per Quit Peripheral Error (0714h) received (3.6.2).
    valid_cycles, invalid_cycles, id_cycles, resets, watchdog_resets:
        Event counters, the interrupt sources of Table 3-13.
    last_reset_s:
        Bus time of the last INTERBUS reset, ``None`` before one.
    """

    data_kernel: ClassVar[DataKernel | None] = DataKernel(_load_plain_run, _latch_plain_run)
    """The ring's fast path for runs of plain devices in a data cycle (:class:`DataKernel`)."""

    def __init__(self, id_code: int, length_code: int) -> None:
        wire.id_register(id_code, length_code)
        wire.data_bytes(length_code)
        self.id_code = id_code
        self.length_code = length_code
        self.size = wire.data_bytes(length_code)
        self.inputs = bytes(self.size)
        self.outputs = bytes(self.size)
        self.watchdog = Layer2Watchdog()
        self.stat_err = False
        self.mod_ack_pulses = 0
        self.valid_cycles = 0
        self.invalid_cycles = 0
        self.id_cycles = 0
        self.resets = 0
        self.watchdog_resets = 0
        self.last_reset_s: float | None = None
        self._pf = False
        self._wd = False
        self._te = False
        self.attention = False

    def __repr__(self) -> str:
        return f"PlainDevice(id_code={self.id_code:#04x}, length_code={self.length_code:#04x})"

    def set_inputs(self, data: bytes) -> None:
        """Set the IN data for the next data cycles."""
        data = checked(check_bytes, "data", data)
        if len(data) != self.size:
            raise InterbusError("Table 3-11", data, f"IN data of this device is {self.size} bytes")
        self.inputs = bytes(data)

    def set_peripheral_fault(self, active: bool) -> None:
        """Drive the /StatErr input (3.6.2): ``True`` is an I/O error; it latches the PF management bit."""
        active = checked(check_bool, "active", active)
        self.stat_err = active
        if active and not self._pf:
            self._pf = True
            self.attention = True

    def management(self) -> int:
        """The management bits 15..13 of the ID register (assumption A8)."""
        return (self._pf << wire.MGMT_PF_BIT) | (self._wd << wire.MGMT_WD_BIT) | (self._te << wire.MGMT_TE_BIT)

    def _tick(self, now: float) -> None:
        if now > self.watchdog.deadline and self.watchdog.expired(now):
            self.inputs = self.outputs = bytes(self.size)
            self._wd = True
            self.attention = True
            self.watchdog_resets += 1

    def load(self, cycle: Cycle, now: float) -> bytes:
        """See :meth:`Device.load`."""
        try:
            if now > self.watchdog.deadline:
                self._tick(now)
        except TypeError:
            _now(now)  # a wrong type: the named error (a right one re-raises the original)
            raise
        if cycle is _DATA:
            return self.inputs
        _cycle(cycle)
        return wire.word_bytes(wire.id_register(self.id_code, self.length_code, self.management()))

    def latch(self, cycle: Cycle, received: bytes, now: float) -> None:
        """See :meth:`Device.latch`."""
        if cycle is _DATA:
            if received.__class__ is not bytes:  # the length is the ring's: the register width load() gave it
                received = checked(check_bytes, "received", received, self.size, limit="Table 3-11")
            self.outputs = received
            self._te = False  # A21: a latched cycle clears TE (the error it recorded is over)
            if self.watchdog.timeout_s is not None:
                self.watchdog.kick(now)
            self.valid_cycles += 1
            return
        _cycle(cycle)
        now = _now(now)
        self.id_cycles += 1
        command = wire.decode_command_word(wire.word_from_bytes(received))
        if command.watchdog_code is not None:
            self.watchdog.configure(command.watchdog_code, now)
        if command.quit_peripheral_error:
            self.mod_ack_pulses += 1
            self._pf = self.stat_err
        self._wd = self._te = self.attention = False

    def discard(self, cycle: Cycle, local_error: bool, now: float) -> None:
        """See :meth:`Device.discard`."""
        _cycle(cycle)
        if type(local_error) is not bool:
            local_error = checked(check_bool, "local_error", local_error)
        if type(now) is not float:
            now = _now(now)
        self._tick(now)
        self._te = self._te or local_error
        self.invalid_cycles += cycle is _DATA

    def reset(self, now: float) -> None:
        """See :meth:`Device.reset`: IN and OUT data registers cleared, watchdog off (Table 3-13)."""
        now = _now(now)
        self.inputs = self.outputs = bytes(self.size)
        self.watchdog.off()
        self._wd = self._te = False
        self.attention = self._pf
        self.resets += 1
        self.last_reset_s = now

    def poll(self, now: float) -> None:
        """See :meth:`Device.poll`."""
        self._tick(_now(now))

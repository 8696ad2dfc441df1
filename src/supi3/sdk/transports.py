"""Transports for the Python firmware driver (:mod:`supi3.sdk.driver`): the model, and Linux spidev for hardware.

- :class:`ModelTransport`: the transaction-level chip (``supi3.model.chip.Supi3`` or its register file), one byte
  through the µP protocol engine per frame, C/D, /IRQ, the I/O bit and SAS_INIT from the model (3.4). No time
  passes; :class:`supi3.sdk.bench.Bench` adds bus time.
- :class:`SpidevTransport`: a real chip on a Linux SPI controller (the ``spidev`` module, optional extra
  ``supi3[hw]``), with the chip's status pins as callables (gpiod, sysfs, ...).

The pin-level whole chip and the RTL in cocotb have transports of their own (:mod:`supi3.sdk.pins`,
:mod:`supi3.sdk.rtl`).
"""

from __future__ import annotations

import contextlib
import importlib
import time
from collections.abc import Callable, Sequence
from typing import Any, Final

from supi3 import timing
from supi3.checks import check_int, check_real, describe
from supi3.model.chip import Supi3
from supi3.model.registers import RegisterFile
from supi3.sdk.driver import (
    UNDRIVEN_BYTE,
    DirectAccess,
    DriverArgumentError,
    Mode,
    Transport,
    TransportError,
    pin_level,
    received_byte,
)
from supi3.spi.upif import Phase, UpInterface
from supi3.tables import BIT_RATES

__all__ = ["MAX_SPEED_HZ", "ModelTransport", "SpidevTransport"]

MAX_SPEED_HZ: Final[int] = max(int(1 / timing.limit("3-7", "t0", rate) * (1 + 1e-9)) for rate in BIT_RATES)
"""The fastest SCLK of :class:`SpidevTransport`: Table 3-7's shortest t0 (167 ns at 2 Mbit/s), 5 988 023 Hz; a
faster clock the chip cannot follow at any bit rate (:func:`supi3.timing.upif_byte_s` refuses it as well)."""


class ModelTransport(Transport):
    """The transaction-level chip behind the driver: every byte goes through the chip's µP protocol engine.

    Parameters
    ----------
    chip:
        A :class:`~supi3.model.chip.Supi3` strapped for an Init-µP mode, its :class:`RegisterFile`, or an
        :class:`UpInterface` already made on one.

    Each driver call runs inside the register file's ``violations.deferred()`` block (:meth:`access`): in strict
    mode a rule the firmware broke is raised when the call has ended, with the chip back in a consistent phase.
    """

    def __init__(self, chip: Supi3 | RegisterFile | UpInterface) -> None:
        self.up = chip if isinstance(chip, UpInterface) else UpInterface(chip)
        self.protocol = self.up.protocol
        self.registers = self.up.registers
        self.sas_level = 0
        self._log = self.registers.violations

    def xfer(self, tx: int, s_r: bool) -> int:
        """One frame: /SS falls (the chip decides what it drives, UP-18), /SS rises (it takes the byte on the data
        line: its own in an Intel receive frame). As :meth:`UpInterface.transfer`, without its argument checks: the
        driver sends only bytes. A frame the chip does not drive reads :data:`UNDRIVEN_BYTE` (FW-26)."""
        protocol = self.protocol
        log = self._log
        log.hold()  # a deferred() block without the with statement's cost (the per-byte hot path)
        try:
            driven = protocol.begin(s_r)
            self._during_frame()
            protocol.end(driven if driven is not None and protocol.mode is Mode.INTEL else tx)
        except BaseException:
            log.release(failed=True)
            raise
        log.release()
        return UNDRIVEN_BYTE if driven is None else driven

    def _during_frame(self) -> None:
        """Between /SS falling and rising: no time passes on the bare model (a bench runs its bus here)."""

    def read_cd(self) -> int:
        """The protocol's C/D (UP-2)."""
        return self.protocol.c_d

    def read_irq(self) -> int:
        """The register file's /IRQ (3.4.14)."""
        return self.registers.irq_n

    def read_io(self) -> int | None:
        """The I/O access bit on MFP1 (3.4.14, Fig. 3-22): 1 = no data register access now."""
        return int(self.registers.io_access)

    def set_sas_init(self, level: int) -> bool:
        """SAS_INIT: the interface restarts on the rising edge of the pin (3.4.3); registers are kept."""
        level = check_int("level", level, 0, 1)
        if level and not self.sas_level:
            self.up.sas_init()
        self.sas_level = level
        return True

    def access(self) -> contextlib.AbstractContextManager[None]:
        """Strict-mode violations wait for the end of the driver call (``ViolationLog.deferred``)."""
        return self.registers.violations.deferred()

    def direct(self) -> DirectAccess | None:
        """``UpInterface``'s whole-access read and write (the same two frames' effect, tests/test_sdk_driver.py),
        unless a subclass changes how a frame goes (a bench's clock, a log): then ``None``."""
        if type(self).xfer is not ModelTransport.xfer or type(self).access is not ModelTransport.access:
            return None
        return _Direct(self.up)


class _Direct:
    """:class:`UpInterface` read/write as a driver shortcut, while the protocol waits for a command byte."""

    __slots__ = ("protocol", "read", "write")

    def __init__(self, up: UpInterface) -> None:
        self.protocol = up.protocol
        self.read = up.read
        self.write = up.write

    def ready(self) -> bool:
        return self.protocol.phase is Phase.COMMAND and not self.protocol.in_frame


class SpidevTransport(Transport):
    """A real SUPI 3 on a Linux SPI controller (``/dev/spidevB.D``), one byte per transfer.

    Parameters
    ----------
    bus, device:
        The spidev numbers.
    mode:
        Motorola: SPI mode 3, MSB first (UP-5). Intel: LSB first; then ``set_s_r`` is required.
    speed_hz:
        SCLK; at most 1.5 MHz at 500 kbit/s and 6 MHz at 2 Mbit/s (Table 3-7, t0 >= 667 ns and 167 ns): more than
        :data:`MAX_SPEED_HZ` is refused.
    read_cd, read_irq, read_io, set_sas_init, set_s_r:
        The board's GPIOs as callables (``None``: not wired): C/D, /IRQ and I/O levels, SAS_INIT and S/R drive.
    spidev_module:
        The module providing ``SpiDev`` (default: ``import spidev``); tests pass a stand-in.

    ``spidev`` toggles /SS around each ``xfer`` call, which is the one frame per byte the chip needs (3.4.2, UP-7).
    An ``OSError`` of the controller reaches the driver as its :class:`~supi3.sdk.driver.TransportError`.
    """

    def __init__(self, bus: int, device: int, *, mode: Mode = Mode.MOTOROLA, speed_hz: int = 1_000_000,
                 read_cd: Callable[[], int] | None = None, read_irq: Callable[[], int] | None = None,
                 read_io: Callable[[], int] | None = None, set_sas_init: Callable[[int], None] | None = None,
                 set_s_r: Callable[[int], None] | None = None, spidev_module: Any = None) -> None:  # fmt: skip
        if type(mode) is not Mode:
            raise DriverArgumentError("mode", mode, f"mode must be Mode.MOTOROLA or Mode.INTEL, not {describe(mode)}")
        if mode is Mode.INTEL and set_s_r is None:
            raise DriverArgumentError("set_s_r", set_s_r, "set_s_r must be a callable in Intel mode: the chip reads "
                                      "the direction from S/R (Table 3-9), not None")  # fmt: skip
        for name, pin in (("read_cd", read_cd), ("read_irq", read_irq), ("read_io", read_io),
                          ("set_sas_init", set_sas_init), ("set_s_r", set_s_r)):  # fmt: skip
            if pin is not None and not callable(pin):
                raise DriverArgumentError(name, pin, f"{name} must be a callable or None, not {describe(pin)}")
        bus, device = check_int("bus", bus, 0), check_int("device", device, 0)
        speed_hz = check_int("speed_hz", speed_hz, 1, MAX_SPEED_HZ, "Table 3-7: t0 >= 167 ns at 2 Mbit/s")
        module = importlib.import_module("spidev") if spidev_module is None else spidev_module
        self.spi = module.SpiDev()
        self.spi.open(bus, device)  # every argument checked first: a refused transport leaves no device open
        self.spi.mode = 0b11
        self.spi.lsbfirst = mode is Mode.INTEL
        self.spi.max_speed_hz = speed_hz
        self._pins = (read_cd, read_irq, read_io)
        self._sas = set_sas_init
        self._s_r = set_s_r

    def xfer(self, tx: int, s_r: bool) -> int:
        """One ``spidev.xfer([tx])``, S/R set first in Intel mode; the driver checks the answer.

        Raises
        ------
        ArgumentError
            ``tx`` not a byte.
        """
        tx = check_int("tx", tx, 0, 0xFF, "one byte per frame, UP-7")
        if self._s_r is not None:
            self._s_r(int(s_r))
        answer = self.spi.xfer([tx])
        if not isinstance(answer, Sequence) or len(answer) != 1:  # UP-48: a ValueError of the unpacking before
            raise TransportError(f"spidev's xfer([{tx}]) returned {describe(answer)}, not one byte for the one sent")
        return received_byte(answer[0])  # UP-48: int(3.5) was 3, int('A') a ValueError

    def delay_us(self, us: float) -> None:
        """Sleep (``time.sleep``; the frame gap and the SAS_INIT pulse are far above its resolution's needs).

        Raises
        ------
        ArgumentError
            ``us`` not a finite number >= 0.
        """
        time.sleep(check_real("us", us, 0.0) * 1e-6)

    def read_cd(self) -> int | None:
        """The C/D GPIO, if wired (:class:`~supi3.sdk.driver.TransportError` if it reads no level)."""
        return None if self._pins[0] is None else pin_level("read_cd", self._pins[0]())

    def read_irq(self) -> int | None:
        """The /IRQ GPIO, if wired (:class:`~supi3.sdk.driver.TransportError` if it reads no level)."""
        return None if self._pins[1] is None else pin_level("read_irq", self._pins[1]())

    def read_io(self) -> int | None:
        """The I/O GPIO, if wired (:class:`~supi3.sdk.driver.TransportError` if it reads no level)."""
        return None if self._pins[2] is None else pin_level("read_io", self._pins[2]())

    def set_sas_init(self, level: int) -> bool:
        """Drive the SAS_INIT GPIO, if wired.

        Raises
        ------
        ArgumentError
            ``level`` not 0 or 1.
        """
        level = check_int("level", level, 0, 1)
        if self._sas is None:
            return False
        self._sas(level)
        return True

    def close(self) -> None:
        """Release the spidev device."""
        self.spi.close()

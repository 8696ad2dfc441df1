"""The Python firmware driver: the C driver's API (``supi3.h``) over any transport, synchronous or async.

Ref: IBS SUPI 3 OPC UM E rev. 05, 3.4 to 3.4.14; guide docs/sdk.md. :class:`Supi3Driver` and
:class:`AsyncSupi3Driver` have the calls of the C driver, one for one (``supi3_read`` is :meth:`Supi3Driver.read`,
``supi3_irq_service`` is :meth:`Supi3Driver.irq_service`, ...), with registers as the named objects of
:mod:`supi3.regmap` (``drv.read(OUT0)``) and the C error codes as exceptions (:data:`ERROR_CODES`).

Every call is written once, as a generator of bus operations (sans-I/O): it yields what it needs from the board
(one byte frame, a pin level, a delay) and gets the answer back. The synchronous driver runs it against a
:class:`Transport` (the transaction-level model, the pin-level chip, Linux spidev), the async one against an
:class:`AsyncTransport` (the RTL in cocotb). Both therefore send the same bytes and make the same decisions as
``supi3.c``; tests/test_sdk_driver.py runs them side by side with the C driver.
"""

from __future__ import annotations

import contextlib
import numbers
from abc import ABC, abstractmethod
from collections.abc import Callable, Generator
from dataclasses import dataclass
from enum import IntEnum, IntFlag
from typing import Any, Final, Protocol, TypeVar

import numpy as np

from supi3.checks import check_bool, check_bytes, check_int, check_real, describe
from supi3.errors import ArgumentError, Supi3Error
from supi3.optical import length as _length
from supi3.regmap import ALARM as ALARM_REGISTER
from supi3.regmap import (
    BLOCK_ADDRESS,
    ID,
    IRQ_EN,
    IRQ_EVT,
    LENGTH_BRANCH,
    LENGTH_OUT,
    PCMD,
    POWER_IN,
    POWER_OUT_BRANCH,
    REGISTER_MAP,
    SET,
    AccessDirection,
    Register,
    RegisterMapError,
    decode_set,
    encode_command,
)
from supi3.spi.upif import Mode

__all__ = [
    "BLOCK_MAX_BYTES",
    "BLOCK_MIN_BYTES",
    "ERROR_CODES",
    "IRQ_SERVICE_MAX_READS",
    "UINT32_MAX",
    "UNDRIVEN_BYTE",
    "AsyncSupi3Driver",
    "AsyncTransport",
    "DirectAccess",
    "DriverArgumentError",
    "DriverError",
    "ErrorCode",
    "IoWindowTimeoutError",
    "Irq",
    "Mode",
    "NotInitializedError",
    "NotReadyError",
    "NotResetError",
    "OpticalStatus",
    "Supi3Driver",
    "Transport",
    "TransportError",
    "UnsupportedError",
    "get_u16",
    "get_u32",
    "optical_length_cm",
    "optical_length_code",
    "pin_level",
    "put_u16",
    "put_u32",
    "received_byte",
]

_T = TypeVar("_T")

BLOCK_MIN_BYTES: Final[int] = 2
"""Shortest block transfer: one word (3.4.6, "lengths >= 1 word"); ``SUPI3_BLOCK_MIN_BYTES``."""
BLOCK_MAX_BYTES: Final[int] = 4
"""Longest block transfer: IN0..IN3 / OUT0..OUT3 (3.4.8); ``SUPI3_BLOCK_MAX_BYTES``."""
IRQ_SERVICE_MAX_READS: Final[int] = 4
"""Most reads of IRQ_EVT in one :meth:`Supi3Driver.irq_service` while /IRQ stays low (3.4.14, FW-22);
``SUPI3_IRQ_SERVICE_MAX_READS``."""
SAS_INIT_PULSE_US: Final[float] = 1.0
"""SAS_INIT active time the driver holds (t_SAS_INIT >= 250 ns, 3.4.3), as ``supi3_sas_init``."""
UNDRIVEN_BYTE: Final[int] = 0xFF
"""What :meth:`Transport.xfer` returns for a frame in which the chip drives no data (before its initialization, a
disabled interface, an Intel send frame; 3.4.1, 3.4.3, UP-25): the data line's pull-up, as on the emulated board
(MCU-6, FW-26)."""

UINT32_MAX: Final[int] = 0xFFFF_FFFF
"""The largest ``frame_gap_us`` and ``max_polls``: the C driver's ``uint32_t`` (``supi3.h``), one range for both."""


class ErrorCode(IntEnum):
    """The C driver's error codes (``supi3_err_t`` in ``supi3.h``; tests/test_sdk_driver.py checks they agree)."""

    OK = 0
    E_ARG = -1
    E_NOT_INIT = -2
    E_TRANSPORT = -3
    E_NOT_READY = -4
    E_NOT_RESET = -5
    E_UNSUPPORTED = -6
    E_TIMEOUT = -7


ERROR_CODES: Final[dict[str, int]] = {f"SUPI3_{code.name}": code.value for code in ErrorCode}
"""``SUPI3_OK``, ``SUPI3_E_ARG``, ... by name, as ``supi3.h`` defines them."""


class DriverError(Supi3Error):
    """A driver call failed; :attr:`code` is the C driver's error code for the same failure."""

    code: ErrorCode = ErrorCode.E_ARG


class DriverArgumentError(ArgumentError, DriverError):
    """Bad argument (``SUPI3_E_ARG``): nothing was sent."""

    code = ErrorCode.E_ARG


class NotInitializedError(DriverError):
    """``SUPI3_E_NOT_INIT``: :meth:`Supi3Driver.initialize` missing, or lost after a transport error (UP-25); nothing
    was sent."""

    code = ErrorCode.E_NOT_INIT


class TransportError(DriverError):
    """``SUPI3_E_TRANSPORT``: the transport failed (its error is the ``__cause__``); the chip's state is unknown,
    pulse SAS_INIT and initialize again."""

    code = ErrorCode.E_TRANSPORT


class NotReadyError(DriverError):
    """``SUPI3_E_NOT_READY``: C/D showed "data" before the initialization byte (a command interrupted by a µP reset,
    UP-27, or a disabled interface, UP-4); nothing was sent."""

    code = ErrorCode.E_NOT_READY


class NotResetError(DriverError):
    """``SUPI3_E_NOT_RESET``: the chip was not reset and took the initialization byte as a command (3.4.3, UP-3);
    the driver completed it with a no-op data byte. Pulse SAS_INIT and initialize again."""

    code = ErrorCode.E_NOT_RESET


class UnsupportedError(DriverError):
    """``SUPI3_E_UNSUPPORTED``: not possible in this mode (exchange in Intel mode, 3.4.4) or without the pin."""

    code = ErrorCode.E_UNSUPPORTED


class IoWindowTimeoutError(DriverError):
    """``SUPI3_E_TIMEOUT``: a bounded wait of 3.4.14 ended: the I/O access window did not open within ``max_polls``
    polls (:meth:`Supi3Driver.poll_io_window`), or /IRQ stayed low after :data:`IRQ_SERVICE_MAX_READS` reads of
    IRQ_EVT (:meth:`Supi3Driver.irq_service`, FW-22). The events the reads returned (and so cleared) are in
    :attr:`events`."""

    code = ErrorCode.E_TIMEOUT

    def __init__(self, message: str, events: int = 0) -> None:
        super().__init__(message)
        self.events = Irq(events)

    def __reduce__(self) -> tuple[object, ...]:
        return (type(self), (str(self), int(self.events)))


class Irq(IntFlag):
    """Interrupt sources of IRQ_EN / IRQ_EVT (Table 3-13, Figs. 3-19 and 3-20; bit order RM-7)."""

    PCMD = IRQ_EN.field("PCMD").mask
    INVALID = IRQ_EN.field("INVALID").mask
    VALID = IRQ_EN.field("VALID").mask
    ID_CYCLE = IRQ_EN.field("ID_CYCLE").mask
    IB_RESET = IRQ_EN.field("IB_RESET").mask
    PCP_RX = IRQ_EN.field("PCP_RX").mask
    PCP_TX = IRQ_EN.field("PCP_TX").mask


_IO_ACCESS_MASK: Final[int] = IRQ_EVT.field("IO_ACCESS").mask
_EVENT_MASK: Final[int] = IRQ_EN.mask


_OPTICAL_READS: Final = (LENGTH_OUT, LENGTH_BRANCH, POWER_IN, POWER_OUT_BRANCH)
"""Reads 8 to 11 (3.4.12, 3.4.13), in the order :meth:`OpticalStatus.decode` takes their bytes."""


@dataclass(frozen=True)
class OpticalStatus:
    """Registers 8 to 11 decoded (3.4.12, 3.4.13, Figs. 3-16 to 3-18); ``supi3_optical_t``. Lengths are the
    register's codes (0..63), media 0 = polymer, 1 = glass, levels 1..15 of 15."""

    out_length: int
    out_medium: int
    out_enable: int
    branch_length: int
    branch_medium: int
    branch_enable: int
    in_level: int
    in_enable: int
    out_level: int
    branch_level: int

    @classmethod
    def decode(cls, raw: bytes) -> OpticalStatus:
        """From the four bytes read at addresses 8, 9, 10, 11.

        Raises
        ------
        DriverArgumentError
            ``raw`` is not 4 bytes.
        """
        raw = _exact(raw, len(_OPTICAL_READS), "raw")
        out, branch, power_in, power = (LENGTH_OUT.decode(raw[0]), LENGTH_BRANCH.decode(raw[1]),
                                        POWER_IN.decode(raw[2]), POWER_OUT_BRANCH.decode(raw[3]))  # fmt: skip
        return cls(out["LENGTH"], out["MEDIUM"], out["ENABLE"], branch["LENGTH"], branch["MEDIUM"], branch["ENABLE"],
                   power_in["LEVEL"], power_in["ENABLE"], power["OUT_LEVEL"], power["BRANCH_LEVEL"])  # fmt: skip


def _medium(value: object) -> _length.Medium:
    return _length.Medium(_checked(check_int, "medium", value, 0, 1, "MEDIUM: 0 polymer, 1 glass"))


def optical_length_cm(code: int, medium: int) -> tuple[int, int]:
    """The one-way path a LENGTH code stands for, ``(low_cm, high_cm)``, high exclusive (OPT-1); code 63 reaches up
    to 20 km. ``medium``: 0 polymer, 1 glass. ``supi3_optical_length_cm``."""
    code = _checked(check_int, "code", code, 0, _length.LENGTH_MAX_CODE, "LENGTH, 6 bits (RM-5)")
    low, high = _length.code_range_m(code, _medium(medium))
    return round(low * 100), round(high * 100)


def optical_length_code(one_way_cm: int, medium: int) -> int:
    """The LENGTH code a one-way path of ``one_way_cm`` centimetres reads (truncated to the medium's unit, 63 above
    the range; OPT-1). ``supi3_optical_length_code``."""
    cm = _checked(check_int, "one_way_cm", one_way_cm, 0, round(_length.MAX_PATH_M * 100), "20 km (Table 1-5)")
    return _length.length_code(cm / 100, _medium(medium))


# ------------------------------------------------------------------------------------------------------------
# Byte significance helpers (3.4.8: address 0 holds the most significant byte)
# ------------------------------------------------------------------------------------------------------------


def put_u16(value: int) -> bytes:
    """``value`` as the two data bytes of one word, byte 0 (address 0) the MSB (3.4.8); ``supi3_put_u16``."""
    return _checked(check_int, "value", value, 0, 0xFFFF, "a 16-bit word").to_bytes(2, "big")


def get_u16(data: bytes) -> int:
    """The word in data bytes 0 and 1 (byte 0 the MSB, 3.4.8); ``supi3_get_u16``."""
    return int.from_bytes(_exact(data, 2), "big")


def put_u32(value: int) -> bytes:
    """``value`` as data bytes 0..3, byte 0 the MSB (3.4.8); ``supi3_put_u32``."""
    return _checked(check_int, "value", value, 0, 0xFFFF_FFFF, "a 32-bit value").to_bytes(4, "big")


def get_u32(data: bytes) -> int:
    """The value in data bytes 0..3 (byte 0 the MSB, 3.4.8); ``supi3_get_u32``."""
    return int.from_bytes(_exact(data, 4), "big")


def _exact(data: object, length: int, name: str = "data") -> bytes:
    raw = _checked(check_bytes, name, data)
    if len(raw) != length:
        raise DriverArgumentError(name, data, f"{name} must be {length} bytes, not {describe(data)}")
    return raw


# ------------------------------------------------------------------------------------------------------------
# Transports
# ------------------------------------------------------------------------------------------------------------


class Transport(ABC):
    """The board under a :class:`Supi3Driver`: the callbacks of ``supi3_config_t``.

    Only :meth:`xfer` is required. A pin the board does not wire reads ``None`` (the driver then works without
    it, as the C driver does with a NULL callback). A failure of the hardware is an :class:`OSError` (or a
    :class:`TransportError`); any other exception (a model's rule violation, say) passes through the driver
    unchanged.
    """

    @abstractmethod
    def xfer(self, tx: int, s_r: bool) -> int:
        """One byte as one frame: /SS low, 8 SCLK periods, /SS high; return the byte the chip drove
        (:data:`UNDRIVEN_BYTE`, FFh, when it drove none: the data line's pull-up, FW-26). Motorola: SPI mode 3, MSB
        first. Intel: LSB first, S/R set to ``s_r`` before /SS falls (``True``: the µP sends; Table 3-9, UP-9)."""

    def delay_us(self, us: float) -> None:
        """Wait ``us`` microseconds (frame gap, SAS_INIT pulse); the default does not wait, but refuses what a
        transport that waits refuses (a test on the bare model runs on the bench too).

        Raises
        ------
        ArgumentError
            ``us`` not a finite number >= 0.
        """
        check_real("us", us, 0.0)

    def read_cd(self) -> int | None:
        """The C/D pin (MFP2), 0 = command expected; ``None``: not wired."""
        return None

    def read_irq(self) -> int | None:
        """The /IRQ pin (MFP3), 0 = event pending; ``None``: not wired."""
        return None

    def read_io(self) -> int | None:
        """The I/O access pin (MFP1), 1 = no data register access now; ``None``: not wired."""
        return None

    def set_sas_init(self, level: int) -> bool:
        """Drive SAS_INIT (MFP0, 1 = active); ``False``: not wired."""
        del level
        return False

    def access(self) -> contextlib.AbstractContextManager[None]:
        """Brackets each driver call: a model defers the rule violations it finds to the end of the call, so that
        the chip is never left between a command and its data byte by an exception."""
        return contextlib.nullcontext()

    def direct(self) -> DirectAccess | None:
        """A shortcut for whole register accesses that has exactly the effect of their two frames (a model's own
        read/write), or ``None``. The driver uses it for :meth:`Supi3Driver.read` and :meth:`Supi3Driver.write`
        when it has no frame gap to keep."""
        return None


class DirectAccess(Protocol):
    """What :meth:`Transport.direct` returns: one register access at once, while :meth:`ready` says it may."""

    def ready(self) -> bool:
        """Whether the chip waits for a command byte now (else the driver sends the frames one by one)."""

    def read(self, address: int) -> int:
        """Command RD|A and one data byte (the chip drives it), as two frames would."""

    def write(self, address: int, value: int) -> None:
        """Command WR|A and the data byte, as two frames would."""


class AsyncTransport(ABC):
    """:class:`Transport` for a simulation that runs on awaits (cocotb): the same callbacks, awaitable."""

    @abstractmethod
    async def xfer(self, tx: int, s_r: bool) -> int:
        """As :meth:`Transport.xfer`."""

    async def delay_us(self, us: float) -> None:
        """As :meth:`Transport.delay_us`."""
        del us

    async def read_cd(self) -> int | None:
        """As :meth:`Transport.read_cd`."""
        return None

    async def read_irq(self) -> int | None:
        """As :meth:`Transport.read_irq`."""
        return None

    async def read_io(self) -> int | None:
        """As :meth:`Transport.read_io`."""
        return None

    async def set_sas_init(self, level: int) -> bool:
        """As :meth:`Transport.set_sas_init`."""
        del level
        return False


# Operations a driver call yields to its runner: (kind, argument, argument).
_XFER, _DELAY, _CD, _IRQ, _IO, _SAS = range(6)
_Op = tuple[int, int | float, bool]
_Call = Generator[_Op, Any, _T]  # the runner sends each operation's answer back

_S_R_CHIP_DRIVES: Final[bool] = False
_S_R_UP_SENDS: Final[bool] = True
_READ: Final[tuple[int, ...]] = tuple(encode_command(a, rd=True) for a in range(BLOCK_ADDRESS))
_WRITE: Final[tuple[int, ...]] = tuple(encode_command(a, wr=True) for a in range(BLOCK_ADDRESS))
_EXCHANGE: Final[tuple[int, ...]] = tuple(encode_command(a, rd=True, wr=True) for a in range(BLOCK_ADDRESS))


def _block_bytes(set_value: int) -> int:
    """Block length of a SET value: its data bytes with ExtReg = 0 and at least one word, else 0 (3.4.6, UP-10)."""
    try:
        config = decode_set(set_value)
    except RegisterMapError:
        return 0  # CL 110, 111: reserved
    count = 0 if config.extreg or config.length.bits is None else (config.length.bits + 7) // 8
    return count if count >= BLOCK_MIN_BYTES else 0


_BLOCK_BYTES: Final[tuple[int, ...]] = tuple(_block_bytes(v) for v in range(256))


def _reaches(register: Register, direction: AccessDirection | None) -> bool:
    directions = tuple(AccessDirection) if direction is None else (direction,)
    return any(REGISTER_MAP.port(register.address, d).register == register for d in directions)


_ADDRESSES: Final[dict[tuple[int, AccessDirection | None], tuple[Register, int]]] = {
    (id(register), direction): (register, register.address)
    for register in REGISTER_MAP.registers
    for direction in (*AccessDirection, None)
    if _reaches(register, direction)
}
"""Every (register, direction) an access may name, with its address (Table 3-10); ``None``: either direction. Keyed
by the register's identity: the register map's objects are the names (hashing a register's fields costs more than
the access)."""


def _address(register: object, direction: AccessDirection | None) -> int:
    """The address of ``register`` if ``direction`` (``None``: either) reaches it there (Table 3-10)."""
    known = _ADDRESSES.get((id(register), direction))
    if known is not None and known[0] is register:
        return known[1]
    if not isinstance(register, Register):
        hint = " (registers are named objects: supi3.regmap.OUT0, IRQ_EVT, ...)" if isinstance(register, int) else ""
        raise DriverArgumentError("register", register, f"register must be a supi3.regmap.Register, not "
                                  f"{describe(register)}{hint}")  # fmt: skip
    if _reaches(register, direction):  # an equal copy of a map register (a pickled one, say)
        return register.address
    verb = "read and written" if direction is None else "read" if direction is AccessDirection.READ else "written"
    raise DriverArgumentError("register", register, f"register {register.name} cannot be {verb} at address "
                              f"{register.address} (Table 3-10)")  # fmt: skip


def _checked(check: Callable[..., _T], *args: object, **kwargs: object) -> _T:
    """Run a :mod:`supi3.checks` check; its error comes out as a :class:`DriverArgumentError` (``SUPI3_E_ARG``)."""
    try:
        return check(*args, **kwargs)
    except ArgumentError as error:
        raise DriverArgumentError(error.name, error.value, str(error)) from None


def _byte(name: str, value: object) -> int:
    if type(value) is int and 0 <= value <= 0xFF:
        return value
    return _checked(check_int, name, value, 0, 0xFF, "one byte")


class _Core:
    """The driver's state and its calls as operation generators; shared by the sync and async drivers."""

    def __init__(self, frame_gap_us: float) -> None:
        # the C driver's supi3_config_t.frame_gap_us and max_polls are uint32_t: one API shape, one range
        self.frame_gap_us = _checked(check_real, "frame_gap_us", frame_gap_us, 0.0, UINT32_MAX)
        self.initialized = False
        self.mode = Mode.MOTOROLA
        self.set_value: int | None = None
        """SET as written or read through this driver (``None``: unknown); fixes the block length (UP-10)."""

    # -- checks before the first byte ------------------------------------------------------------------------

    def _ready(self) -> None:
        if not self.initialized:
            raise NotInitializedError("driver not initialized: call initialize(Mode.MOTOROLA or Mode.INTEL) first "
                                      "(3.4.3), and again after SAS_INIT or a transport error; nothing sent")

    def _note_set(self, address: int, value: int | None) -> None:
        """Keep SET as an access to it left it; ``None`` (unknown) while the access is under way, so that a
        transport failure leaves it unknown, as ``supi3.c`` does (FW-16)."""
        if address == SET.address:
            self.set_value = value

    # -- calls -----------------------------------------------------------------------------------------------

    def initialize(self, mode: object) -> _Call[None]:
        if type(mode) is not Mode:
            raise DriverArgumentError("mode", mode, f"mode must be Mode.MOTOROLA or Mode.INTEL (Table 3-8), not "
                                      f"{describe(mode)}")  # fmt: skip
        self.initialized = False
        cd = yield (_CD, 0, False)
        if cd:
            raise NotReadyError("C/D shows data before the initialization byte: a command waits for its data byte "
                                "(µP reset mid-command, UP-27) or the interface is disabled (UP-4); pulse SAS_INIT "
                                "(3.4.3); nothing sent")  # fmt: skip
        yield (_XFER, mode.init_byte, _S_R_UP_SENDS)
        if cd is not None and (yield (_CD, 0, False)):
            # "Command status twice" missing (3.4.3, UP-3): complete the command the byte became, then report.
            yield (_XFER, 0x00, _S_R_CHIP_DRIVES if mode is Mode.INTEL else _S_R_UP_SENDS)
            raise NotResetError(f"initialize({mode.name}): the chip was not reset and took {mode.init_byte:02X}h "
                                "as a command (3.4.3, UP-3); pulse SAS_INIT and initialize again")  # fmt: skip
        self.mode = mode
        self.initialized = True

    def sas_init(self) -> _Call[None]:
        initialized, self.initialized = self.initialized, False  # the interface waits for the init byte (3.4.3)
        if not (yield (_SAS, 1, False)):
            self.initialized = initialized  # refused, nothing driven: the state is kept (FW-16, FW-21)
            raise UnsupportedError("sas_init(): the transport has no SAS_INIT pin")
        yield (_DELAY, SAS_INIT_PULSE_US, False)
        if not (yield (_SAS, 0, False)):  # driven, then "not wired": a failure, as supi3_sas_init (FW-21)
            raise TransportError("sas_init(): the transport drove SAS_INIT, then said it has no such pin; chip state "
                                 "unknown: pulse SAS_INIT and initialize again")  # fmt: skip

    def read(self, register: object) -> _Call[int]:
        address = _address(register, AccessDirection.READ)
        self._ready()
        return self._read(address)

    def _read(self, address: int) -> _Call[int]:
        self._note_set(address, None)
        yield (_XFER, _READ[address], _S_R_UP_SENDS)
        value: int = yield (_XFER, 0x00, _S_R_CHIP_DRIVES)
        self._note_set(address, value)
        return value

    def write(self, register: object, value: object) -> _Call[None]:
        address = _address(register, AccessDirection.WRITE)
        byte = _byte("value", value)
        self._ready()
        return self._write(address, byte)

    def _write(self, address: int, value: int) -> _Call[None]:
        self._note_set(address, None)
        yield (_XFER, _WRITE[address], _S_R_UP_SENDS)
        yield (_XFER, value, _S_R_UP_SENDS)
        self._note_set(address, value)

    def exchange(self, register: object, value: object) -> _Call[int]:
        address = _address(register, None)
        byte = _byte("value", value)
        self._ready()
        if self.mode is not Mode.MOTOROLA:
            raise UnsupportedError("exchange(): simultaneous read and write needs Motorola mode (3.4.4)")
        return self._exchange(address, byte)

    def _exchange(self, address: int, value: int) -> _Call[int]:
        self._note_set(address, None)
        yield (_XFER, _EXCHANGE[address], _S_R_UP_SENDS)
        result: int = yield (_XFER, value, _S_R_UP_SENDS)
        self._note_set(address, value)
        return result

    def block_transfer(self, in_data: object, read: object, write: object) -> _Call[bytes]:
        data = _checked(check_bytes, "in_data", in_data)
        rd, wr = _checked(check_bool, "read", read), _checked(check_bool, "write", write)
        self._ready()  # before the length, as supi3_block_transfer (FW-16)
        n = len(data)
        if not BLOCK_MIN_BYTES <= n <= BLOCK_MAX_BYTES:
            raise DriverArgumentError("in_data", in_data, f"in_data must be {BLOCK_MIN_BYTES} to {BLOCK_MAX_BYTES} "
                                      f"bytes, the block length (3.4.6, 3.4.8), not {describe(in_data)}")  # fmt: skip
        if self.set_value is not None and n != _BLOCK_BYTES[self.set_value]:
            raise DriverArgumentError("in_data", in_data, f"in_data must be {_BLOCK_BYTES[self.set_value]} bytes, "
                                      f"the block length of SET = {self.set_value:02X}h (UP-10; 0: no block "
                                      f"transfer), not {describe(in_data)}")  # fmt: skip
        intel = self.mode is Mode.INTEL
        if intel and not (rd or wr):
            raise DriverArgumentError("read", read, "read or write must be True in Intel mode (UP-11)")
        return self._block(data, rd, wr, intel)

    def _block(self, data: bytes, rd: bool, wr: bool, intel: bool) -> _Call[bytes]:
        yield (_XFER, encode_command(BLOCK_ADDRESS, rd=rd, wr=wr), _S_R_UP_SENDS)
        out = bytearray()
        if not intel:  # UP-11: every byte full duplex, IN k written whatever RD/WR say
            for value in data:
                out.append((yield (_XFER, value, _S_R_UP_SENDS)))
            return bytes(out) if rd else b""
        for _ in data if rd else b"":
            out.append((yield (_XFER, 0x00, _S_R_CHIP_DRIVES)))
        for value in data if wr else b"":
            yield (_XFER, value, _S_R_UP_SENDS)
        return bytes(out)

    def configure(self, set_value: object, id_code: object) -> _Call[None]:
        set_byte, id_byte = _byte("set_value", set_value), _byte("id_code", id_code)
        self._ready()
        return self._configure(set_byte, id_byte)

    def _configure(self, set_value: int, id_code: int) -> _Call[None]:
        yield from self._write(SET.address, set_value)
        yield from self._write(ID.address, id_code)

    def irq_enable(self, mask: object) -> _Call[None]:
        byte = _byte("mask", mask)
        if byte & ~_EVENT_MASK:
            raise DriverArgumentError("mask", mask, f"mask must set only interrupt sources {_EVENT_MASK:02X}h "
                                      f"(bit 7 is reserved, RM-7), not {byte:02X}h")  # fmt: skip
        self._ready()
        return self._write(IRQ_EN.address, byte)

    def irq_service(self) -> _Call[Irq]:
        self._ready()
        return self._irq_service()

    def _irq_service(self) -> _Call[Irq]:
        # Read IRQ_EVT until /IRQ is high (3.4.14): an event that came during a read gives no new edge (FW-22).
        events = 0
        for reads in range(IRQ_SERVICE_MAX_READS + 1):
            level = yield (_IRQ, 0, False)
            if level:  # high: nothing (left) pending
                break
            if reads == IRQ_SERVICE_MAX_READS:
                raise IoWindowTimeoutError(f"irq_service(): /IRQ still low after {reads} reads of IRQ_EVT (3.4.14, "
                                           "FW-22)", events)  # fmt: skip
            value = yield from self._read(IRQ_EVT.address)
            events = (events & _EVENT_MASK) | value  # D6..D0 of every read, D7 of the last (FW-16)
            if level is None:  # /IRQ not wired: one read (no edge to lose)
                break
        return Irq(events)

    def poll_io_window(self, max_polls: object) -> _Call[Irq]:
        polls = _checked(check_int, "max_polls", max_polls, 1, UINT32_MAX, "polls of the I/O access bit")
        self._ready()
        return self._poll(polls)

    def _poll(self, polls: int) -> _Call[Irq]:
        events = 0
        for _ in range(polls):
            level = yield (_IO, 0, False)
            if level is None:
                value = yield from self._read(IRQ_EVT.address)
                events |= value & _EVENT_MASK
                level = value & _IO_ACCESS_MASK
            if not level:
                return Irq(events)
        raise IoWindowTimeoutError(f"poll_io_window(): the I/O access window did not open in {polls} polls "
                                   "(3.4.14, Fig. 3-22)", events)  # fmt: skip

    def processor_alarm(self, value: object) -> _Call[None]:
        byte = _byte("value", value)
        self._ready()
        return self._write(ALARM_REGISTER.address, byte)

    def processor_command(self) -> _Call[int]:
        self._ready()
        return self._read(PCMD.address)

    def optical_status(self) -> _Call[OpticalStatus]:
        self._ready()
        return self._optical()

    def _optical(self) -> _Call[OpticalStatus]:
        raw = bytearray()
        for register in _OPTICAL_READS:
            raw.append((yield from self._read(register.address)))
        return OpticalStatus.decode(bytes(raw))


class _DriverApi:
    """The public calls; each builds its operation generator on :attr:`_core` and runs it."""

    _core: _Core

    @property
    def mode(self) -> Mode:
        """The interface mode of the last successful :meth:`initialize`."""
        return self._core.mode

    @property
    def initialized(self) -> bool:
        """Whether register accesses are allowed (after :meth:`initialize`, until SAS_INIT or a transport error)."""
        return self._core.initialized


class Supi3Driver(_DriverApi):
    """The SUPI 3 firmware driver over a synchronous :class:`Transport` (the C driver's API, ``supi3.h``).

    Parameters
    ----------
    transport:
        The board: the model (:class:`supi3.sdk.transports.ModelTransport`), the pin-level chip, spidev, ...
    frame_gap_us:
        Wait after each frame (t8, Table 3-7), as ``supi3_config_t.frame_gap_us``.

    Every call checks its arguments and the driver's state before the first byte goes out; a refused call sends
    nothing (:class:`DriverArgumentError`, :class:`NotInitializedError`, :class:`UnsupportedError`).
    """

    def __init__(self, transport: Transport, *, frame_gap_us: float = 0.0) -> None:
        if not isinstance(transport, Transport):
            raise DriverArgumentError("transport", transport, f"transport must be a supi3.sdk.driver.Transport, not "
                                      f"{describe(transport)}")  # fmt: skip
        self.transport = transport
        self._core = _Core(frame_gap_us)
        self._direct = transport.direct() if not self._core.frame_gap_us else None

    def _run(self, call: _Call[_T]) -> _T:
        transport = self.transport
        core = self._core
        gap = core.frame_gap_us
        with transport.access():
            answer: int | bool | None = None
            try:
                while True:
                    kind, argument, s_r = call.send(answer)
                    if kind == _XFER:
                        try:
                            answer = transport.xfer(int(argument), s_r)
                            if type(answer) is not int or not 0 <= answer <= 0xFF:  # every frame: one test
                                answer = received_byte(answer)
                        except (OSError, TransportError) as error:
                            core.initialized = False
                            raise _transport_error(error) from error
                        if gap:
                            transport.delay_us(gap)
                    elif kind == _DELAY:
                        answer = None
                        transport.delay_us(argument)
                    else:
                        try:
                            answer = _pin(transport, kind, int(argument))
                        except (OSError, TransportError) as error:  # a pin: the chip's state is as it was
                            raise _transport_error(error) from error
            except StopIteration as stop:
                return stop.value  # type: ignore[no-any-return]

    def initialize(self, mode: Mode) -> None:
        """Send the initialization byte of ``mode`` (3.4.3, Table 3-8); ``supi3_initialize``.

        With C/D wired: :class:`NotReadyError` if C/D shows data before the byte (nothing sent),
        :class:`NotResetError` if the chip took the byte as a command (UP-3; completed with a no-op data byte).
        """
        self._run(self._core.initialize(mode))

    def sas_init(self) -> None:
        """Pulse SAS_INIT; the driver forgets its mode until :meth:`initialize` (3.4.3); ``supi3_sas_init``."""
        self._run(self._core.sas_init())

    def read(self, register: Register) -> int:
        """Read one register (3.4.4): ``drv.read(OUT0)``; reading IRQ_EVT clears the events (3.4.14)."""
        direct = self._direct
        if direct is not None and direct.ready():
            address = _address(register, AccessDirection.READ)
            if address != SET.address:  # SET frame by frame: the driver keeps it when the model raises after (FW-16)
                self._core._ready()
                return direct.read(address)
        return self._run(self._core.read(register))

    def write(self, register: Register, value: int) -> None:
        """Write one register (3.4.4): ``drv.write(IN0, 0x12)``."""
        direct = self._direct
        if direct is not None and direct.ready():
            address = _address(register, AccessDirection.WRITE)
            if address != SET.address:  # as in read() (FW-16)
                byte = _byte("value", value)
                self._core._ready()
                direct.write(address, byte)
                return
        self._run(self._core.write(register, value))

    def exchange(self, register: Register, value: int) -> int:
        """Read and write one address in the same data byte (Motorola only, 3.4.4); ``register`` is either
        register at the address (``OUT0`` or ``IN0``)."""
        return self._run(self._core.exchange(register, value))

    def block_transfer(self, in_data: bytes, *, read: bool = True, write: bool = True) -> bytes:
        """Block transfer at address 15 (3.4.6; UP-10, UP-11): returns OUT0..OUT(n-1), writes ``in_data`` to
        IN0..IN(n-1); n = ``len(in_data)``, the configured length in bytes (2..4; SET's length once SET went
        through this driver). Intel: the reads if ``read``, then the writes if ``write``. Motorola: always both."""
        return self._run(self._core.block_transfer(in_data, read, write))

    def configure(self, set_value: int, id_code: int) -> None:
        """Write SET, then ID (3.4.5: 4Dh set, 4Ch id), before the bus runs."""
        self._run(self._core.configure(set_value, id_code))

    def irq_enable(self, mask: Irq | int) -> None:
        """Write IRQ_EN (3.4.14, Fig. 3-19): ``drv.irq_enable(Irq.VALID)``."""
        self._run(self._core.irq_enable(mask))

    def irq_service(self) -> Irq:
        """Read-clear IRQ_EVT (3.4.14): its events and, as ``supi3_irq_service``, D7, the I/O access status (RM-7,
        RM-8; a bit that is no :class:`Irq` member: test events with ``&``). With /IRQ wired: high at once, no
        events and nothing sent; else IRQ_EVT is read until /IRQ is high (an event that came during a read gives no
        new falling edge, FW-22), the events of every read OR-ed, D7 of the last; :class:`IoWindowTimeoutError`
        after :data:`IRQ_SERVICE_MAX_READS` reads. Without the pin: one read."""
        return self._run(self._core.irq_service())

    def poll_io_window(self, max_polls: int) -> Irq:
        """The polling method (3.4.14, Fig. 3-22): wait until the I/O access bit is 0 (the I/O pin if wired, else
        D7 of IRQ_EVT) and return the events those reads cleared; :class:`IoWindowTimeoutError` after
        ``max_polls``. The data registers may then be accessed for 30 bit periods."""
        return self._run(self._core.poll_io_window(max_polls))

    def processor_alarm(self, value: int) -> None:
        """Write the processor alarm register (address 7, 3.4.9)."""
        self._run(self._core.processor_alarm(value))

    def processor_command(self) -> int:
        """Read the processor command register (address 7, 3.4.9)."""
        return self._run(self._core.processor_command())

    def optical_status(self) -> OpticalStatus:
        """Read and decode registers 8 to 11 (3.4.12, 3.4.13)."""
        return self._run(self._core.optical_status())


class AsyncSupi3Driver(_DriverApi):
    """:class:`Supi3Driver` over an :class:`AsyncTransport`: the same calls, awaited (``await drv.read(OUT0)``)."""

    def __init__(self, transport: AsyncTransport, *, frame_gap_us: float = 0.0) -> None:
        if not isinstance(transport, AsyncTransport):
            raise DriverArgumentError("transport", transport, f"transport must be a supi3.sdk.driver.AsyncTransport, "
                                      f"not {describe(transport)}")  # fmt: skip
        self.transport = transport
        self._core = _Core(frame_gap_us)

    async def _run(self, call: _Call[_T]) -> _T:
        transport = self.transport
        answer: int | bool | None = None
        try:
            while True:
                kind, argument, s_r = call.send(answer)
                if kind == _XFER:
                    try:
                        answer = received_byte(await transport.xfer(int(argument), s_r))
                    except (OSError, TransportError) as error:
                        self._core.initialized = False
                        raise _transport_error(error) from error
                    if self._core.frame_gap_us:
                        await transport.delay_us(self._core.frame_gap_us)
                elif kind == _DELAY:
                    answer = None
                    await transport.delay_us(argument)
                else:
                    try:
                        answer = await _async_pin(transport, kind, int(argument))
                    except (OSError, TransportError) as error:  # a pin: the chip's state is as it was
                        raise _transport_error(error) from error
        except StopIteration as stop:
            return stop.value  # type: ignore[no-any-return]

    async def initialize(self, mode: Mode) -> None:
        """As :meth:`Supi3Driver.initialize`."""
        await self._run(self._core.initialize(mode))

    async def sas_init(self) -> None:
        """As :meth:`Supi3Driver.sas_init`."""
        await self._run(self._core.sas_init())

    async def read(self, register: Register) -> int:
        """As :meth:`Supi3Driver.read`."""
        return await self._run(self._core.read(register))

    async def write(self, register: Register, value: int) -> None:
        """As :meth:`Supi3Driver.write`."""
        await self._run(self._core.write(register, value))

    async def exchange(self, register: Register, value: int) -> int:
        """As :meth:`Supi3Driver.exchange`."""
        return await self._run(self._core.exchange(register, value))

    async def block_transfer(self, in_data: bytes, *, read: bool = True, write: bool = True) -> bytes:
        """As :meth:`Supi3Driver.block_transfer`."""
        return await self._run(self._core.block_transfer(in_data, read, write))

    async def configure(self, set_value: int, id_code: int) -> None:
        """As :meth:`Supi3Driver.configure`."""
        await self._run(self._core.configure(set_value, id_code))

    async def irq_enable(self, mask: Irq | int) -> None:
        """As :meth:`Supi3Driver.irq_enable`."""
        await self._run(self._core.irq_enable(mask))

    async def irq_service(self) -> Irq:
        """As :meth:`Supi3Driver.irq_service`."""
        return await self._run(self._core.irq_service())

    async def poll_io_window(self, max_polls: int) -> Irq:
        """As :meth:`Supi3Driver.poll_io_window`."""
        return await self._run(self._core.poll_io_window(max_polls))

    async def processor_alarm(self, value: int) -> None:
        """As :meth:`Supi3Driver.processor_alarm`."""
        await self._run(self._core.processor_alarm(value))

    async def processor_command(self) -> int:
        """As :meth:`Supi3Driver.processor_command`."""
        return await self._run(self._core.processor_command())

    async def optical_status(self) -> OpticalStatus:
        """As :meth:`Supi3Driver.optical_status`."""
        return await self._run(self._core.optical_status())


def _transport_error(error: BaseException) -> TransportError:
    if isinstance(error, TransportError):
        return error
    return TransportError(f"transport failed: {error}; chip state unknown: pulse SAS_INIT and initialize again")


def received_byte(rx: object) -> int:
    """FW-26: ``rx``, what a transport's ``xfer`` returned, as the byte the frame read (FFh when the chip drove
    none); the driver's check of every frame's answer.

    Raises
    ------
    TransportError
        ``rx`` not an integer from 0 to 255 (a bool is no byte): the driver forgets its initialization, as for any
        transport failure.
    """
    if type(rx) is int and 0 <= rx <= 0xFF:  # every frame: the common case in one test
        return rx
    if isinstance(rx, numbers.Integral) and not isinstance(rx, bool) and 0 <= int(rx) <= 0xFF:
        return int(rx)
    raise TransportError(f"Transport.xfer returned {describe(rx)}, not a byte 0 to 255 (FW-26: FFh when the chip "
                         "drives none); chip state unknown: pulse SAS_INIT and initialize again")  # fmt: skip


def pin_level(name: str, level: object) -> int | None:
    """``level``, what the transport's pin read ``name`` (``read_cd``, ``read_irq``, ``read_io``) returned, as 0, 1
    or ``None`` (not wired); a bool or a numpy integer 0 or 1 passes (a GPIO library's value).

    Raises
    ------
    TransportError
        ``level`` anything else ('0', 2, 0.5): no pin reads it.
    """
    if level is None or (isinstance(level, numbers.Integral | np.bool_) and level in (0, 1)):
        return None if level is None else int(level)  # UP-48: numpy's bool too (a GPIO read from an array)
    raise TransportError(f"Transport.{name} returned {describe(level)}, not 0, 1 or None (the pin's level; None: "
                         "not wired)")  # fmt: skip


_PIN_READS: Final[dict[int, str]] = {_CD: "read_cd", _IRQ: "read_irq", _IO: "read_io"}
"""The transport's read of each pin the driver reads (:func:`pin_level` names it)."""


def _pin(transport: Transport, kind: int, level: int) -> int | bool | None:
    if kind == _CD:
        value = transport.read_cd()
    elif kind == _IRQ:
        value = transport.read_irq()
    elif kind == _IO:
        value = transport.read_io()  # a polling firmware's every poll: the check below in one test when valid
    else:
        return transport.set_sas_init(level)
    if value is None or (type(value) is int and 0 <= value <= 1):
        return value
    return pin_level(_PIN_READS[kind], value)


async def _async_pin(transport: AsyncTransport, kind: int, level: int) -> int | bool | None:
    if kind == _SAS:
        return await transport.set_sas_init(level)
    read = {_CD: transport.read_cd, _IRQ: transport.read_irq, _IO: transport.read_io}[kind]
    return pin_level(_PIN_READS[kind], await read())


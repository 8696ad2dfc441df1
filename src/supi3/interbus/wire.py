"""The INTERBUS wire format, bit-exact: telegrams, summation frame, CRC, CNTR, timing and line levels.

Everything here follows ``docs/interbus.md``. The manual (IBS SUPI 3 OPC UM E, rev. 05) does not describe
layer 2; every constant the project had to decide sits in the "Assumed constants" section below and nowhere
else, each listed with its evidence in ``docs/assumptions/interbus.md``. Changing one is a one-line change.

Conventions
-----------
* A *level sequence* is one line level (0 or 1) per bit period, in the order the bits go on the line.
* A telegram is held as an ``int`` whose bit *i* is the *i*-th bit period of the telegram on the line.
* A *stream* is the ``bytes`` of the data sequence (loopback word and device data) as it passes one line.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from enum import Enum
from typing import Final, NamedTuple, NoReturn

import numpy as np
import numpy.typing as npt

from supi3.checks import check_bool, check_bytes, check_choice, check_instance, check_int, describe, fail
from supi3.interbus.errors import InterbusArgumentError, InterbusError, TelegramError, checked
from supi3.tables import BIT_RATES, CLOCK_HZ, LENGTH_CODE_BY_VALUE, WATCHDOG_TIMEOUTS_S

# ================================================================================================================
# Assumed constants. Evidence and alternatives: docs/assumptions/interbus.md (A1..A16).
# ================================================================================================================

# A1 Line levels (NRZ, RS-485 idle = mark).
IDLE_LEVEL: Final = 1
START_LEVEL: Final = 0
STOP_LEVEL: Final = 1

# A2 Telegram layout: positions (bit periods from the start bit) of the added bits, shared by data and status
# telegrams; the 8 data bits of a data telegram follow the control bit; the stop bit is always last.
POS_START: Final = 0
POS_TYPE: Final = 1
POS_SELECT: Final = 2
POS_CONTROL: Final = 3
POS_DATA: Final = 4
DATA_LSB_FIRST: Final = True

# A3 Meaning of the added bits: the level that stands for "data telegram", "ID cycle", "check sequence / latch".
TYPE_DATA_LEVEL: Final = 1
SELECT_ID_LEVEL: Final = 1
CONTROL_CHECK_LEVEL: Final = 1

# A4 16-bit words (loopback word, ID register, command word, CRC, CNTR) go low byte first.
WORD_LOW_BYTE_FIRST: Final = True

# A5 Loopback word. Its length-code field (bits 12..8 if read as an ID register) is 11010b, reserved in Table 3-11,
# so no conforming device can shift out a word equal to it during an ID cycle.
LOOPBACK_WORD: Final = 0x5A3C

# A6 Frame check: CRC-16 over the data bytes of the data sequence (Rocksoft model parameters; this set is the
# catalogued CRC-16/IBM-SDLC, alias X-25, check value 0x906E).
CRC_POLY: Final = 0x1021
CRC_INIT: Final = 0xFFFF
CRC_REFIN: Final = True
CRC_REFOUT: Final = True
CRC_XOROUT: Final = 0xFFFF

# A7 CNTR word: two complement-coded flags, everything else zero.
CNTR_ATTN_BIT: Final = 0
CNTR_NATTN_BIT: Final = 1
CNTR_NERR_BIT: Final = 14
CNTR_ERR_BIT: Final = 15

# A8 ID register management bits (IN direction of the ID cycle).
MGMT_PF_BIT: Final = 13  # peripheral fault (/StatErr) latched, message 0BB1h
MGMT_WD_BIT: Final = 14  # layer-2 watchdog has reset the process data, message 0C6Bh
MGMT_TE_BIT: Final = 15  # a transmission error was detected on this device's incoming line

# A9 Command word (OUT direction of the ID cycle, one per device).
CMD_WD_CODE_SHIFT: Final = 0  # 2 bits: index into WATCHDOG_TIMEOUTS_S (50 ms, 200 ms, 1000 ms, off)
CMD_WD_SET_BIT: Final = 2  # apply the watchdog code
CMD_QUIT_BIT: Final = 3  # Quit Peripheral Error (0714h): clear the PF latch, pulse /ModAck

# A18 Management channel (manual 3.4.9) in the command word: a processor command byte for the device's processor
# command register, and the request to send the processor alarm register in the next ID cycle, in place of the
# ID code (bits 7..0 of the ID register).
CMD_PCMD_BIT: Final = 4  # bits 15..8 carry a processor command byte
CMD_ALARM_BIT: Final = 5  # send the processor alarm in the next ID cycle
CMD_PCMD_SHIFT: Final = 8

# BK-4 Branch control in the command word of a bus terminal module (BK, Table 2-7; docs/assumptions/bus-terminal.md):
# a 2-bit field, 0 = leave the branch alone, 1 = switch it off, 2 = switch it on, 3 = switch it on with the
# extended BK function (2.4: the BK closes a silent branch by itself). Bits 7..6 had no meaning before.
CMD_BRANCH_SHIFT: Final = 6

# OPT-50 Optical status request (MAU warnings, manual 1.6.3; docs/assumptions/optical.md): bit 8 with bit 4 (the
# processor command) clear asks the device to send its optical status byte in the next ID cycle in place of the ID
# code. Bits 15..8 had a meaning only with bit 4 set (A18), so the two never go in one command word.
CMD_OPTICAL_BIT: Final = 8

# BK-12 A bus terminal module's ALARM output (MFP15, Table 2-8: "can be set by the master ... 0714h"): bit 9 with
# bit 4 (the processor command) clear sets the output to bit 10.
CMD_ALARM_OUT_SET_BIT: Final = 9
CMD_ALARM_OUT_BIT: Final = 10

# A10 Each device repeats the line with this delay; it may look this many bits minus one ahead (mid-bit sampling).
REPEATER_DELAY_BITS: Final = 3

# A11 Cycle end: idle status telegrams the master adds after the ring delay, then the latch status telegrams.
TURNAROUND_STATUS_TELEGRAMS: Final = 1
LATCH_STATUS_TELEGRAMS: Final = 2

# BK-46 After a latched cycle that switches a bus terminal module's branch the master sends only idle status
# telegrams for the ring delay and this many more: the BK switches its lines between telegrams (BK-47), so the
# switch waits up to a telegram for DO3, the drain of the branch and up to a telegram for DO2.
BRANCH_SWITCH_PAUSE_STATUS_TELEGRAMS: Final = 3


# A12 INTERBUS reset: the line held at START_LEVEL. Detected after RESET_DETECT_BITS such bit periods (longer
# than any run inside legal traffic), sent for RESET_HOLD_BITS, ended by RESET_END_STATUS_TELEGRAMS idle ones.
RESET_DETECT_BITS: Final = 16
RESET_HOLD_BITS: Final = 64
RESET_END_STATUS_TELEGRAMS: Final = 4

# A13 A device that receives no telegram for this long takes it as an INTERBUS reset.
IDLE_TIMEOUT_S: Final = 0.020

# A14 Ring size limit [public source], and the filler byte of a discovery ID cycle.
MAX_DEVICES: Final = 512
DISCOVERY_FILLER: Final = 0x00

# A15 Devices occupy whole bytes on the line: ceil(bits / 8) bytes for the length code's data length.
# A16 Check sequence: CRC word, then CNTR word.
CHECK_SEQUENCE_WORDS: Final = ("crc", "cntr")

# A26 Bus time (seconds, a float) stays at most 2**20 s (about 12 days): there a float still resolves 2**-32 s, 1/134
# of a 32 MHz clock (1/67 at twice the time, the margin for a cycle or reset begun just before). Past it cycles stop
# moving the clock (at 1e300 s not at all) and no watchdog or idle timeout ever expires: refused by name.
MAX_BUS_TIME_S: Final = float(2**20)

# ================================================================================================================
# Derived constants
# ================================================================================================================

DATA_TELEGRAM_BITS: Final = POS_DATA + 8 + 1
STATUS_TELEGRAM_BITS: Final = POS_DATA + 1
LOOPBACK_BYTES: Final = 2
CHECK_TELEGRAMS: Final = 2 * len(CHECK_SEQUENCE_WORDS)
FRAME_OVERHEAD_TELEGRAMS: Final = LOOPBACK_BYTES + CHECK_TELEGRAMS
"""Loopback word plus check sequence: the 6 of Beckhoff's 13 x (6 + N) (docs/interbus.md, "Cycle timing")."""

MGMT_MASK: Final = (1 << MGMT_PF_BIT) | (1 << MGMT_WD_BIT) | (1 << MGMT_TE_BIT)

_DATA_STOP: Final = DATA_TELEGRAM_BITS - 1
_STATUS_STOP: Final = STATUS_TELEGRAM_BITS - 1
_DATA_SHIFTS: Final = tuple(POS_DATA + (i if DATA_LSB_FIRST else 7 - i) for i in range(8))


def _other(level: int) -> int:
    return 1 - level


def _int(name: str, value: object, lo: int | None, hi: int | None, limit: str = "") -> int:
    """``value`` if it is a plain ``int`` in range (the fast case), else the checked value or the named error."""
    if type(value) is int and (lo is None or value >= lo) and (hi is None or value <= hi):
        return value
    return checked(check_int, name, value, lo, hi, limit=limit)


def _flag(name: str, value: object) -> bool:
    return value if type(value) is bool else checked(check_bool, name, value)


def _cycle(value: object) -> Cycle:
    return value if type(value) is Cycle else checked(check_instance, "cycle", value, Cycle, "Cycle.ID or Cycle.DATA")


def _data(name: str, value: object) -> bytes:
    return value if type(value) is bytes else checked(check_bytes, name, value)


def _levels(name: str, value: object) -> npt.NDArray[np.uint8]:
    """A sequence of line levels (0 or 1) as an array; anything else is a named error."""
    try:
        array = np.asarray(value)
    except (TypeError, ValueError):
        array = np.asarray([None])
    if array.ndim != 1 or not (array.size == 0 or np.issubdtype(array.dtype, np.integer) or array.dtype == bool):
        _refuse(name, "a sequence of line levels (0 or 1)", value)
    if array.size and (array.min() < 0 or array.max() > 1):
        _refuse(name, "a sequence of line levels (0 or 1)", value)
    return array.astype(np.uint8)


def _refuse(name: str, wanted: str, value: object) -> NoReturn:
    """Raise the named error for ``value`` ("name must be wanted, not value")."""
    error = fail(name, wanted, value)
    raise InterbusArgumentError(error.name, error.value, str(error))


# ================================================================================================================
# Cycles and telegrams
# ================================================================================================================


class Cycle(Enum):
    """The two INTERBUS cycle types, told apart by the select bit (docs/interbus.md, "Cycles")."""

    ID = "id"
    DATA = "data"

    @property
    def select_level(self) -> int:
        """Line level of the select bit in this cycle's telegrams."""
        return SELECT_ID_LEVEL if self is Cycle.ID else _other(SELECT_ID_LEVEL)


class Telegram(NamedTuple):
    """One received telegram.

    ``data`` is the byte of a data telegram and ``None`` for a status telegram. ``check`` is the control bit:
    the check sequence for a data telegram, a latch telegram for a status telegram.
    """

    cycle: Cycle
    check: bool
    data: int | None


class LineReset(NamedTuple):
    """An INTERBUS reset seen on the line: ``bit`` is where the low level began."""

    bit: int


def check_bus_time(name: str, value: object, now: float, seconds: float = 0.0) -> None:
    """A26: refuse a step of bus time from ``now`` by ``seconds`` (an idle; a cycle or a reset: 0, checked at its
    start) that would pass :data:`MAX_BUS_TIME_S`; ``name`` and ``value`` are the argument the error names. The one
    check of every entry that advances bus time (``Ring``, ``PinRing``, ``OpticalRing``, the firmware bench).

    Raises
    ------
    InterbusArgumentError
        Bus time would pass :data:`MAX_BUS_TIME_S` (or ``now + seconds`` is NaN).
    """
    if not now + seconds <= MAX_BUS_TIME_S:
        raise InterbusArgumentError(name, value, f"{name} {describe(value)} at bus time {now!r} s would take it past "
                                    f"{MAX_BUS_TIME_S:.0f} s (A26: the most where a float resolves a 32 MHz clock)",
                                    "docs/assumptions/interbus.md, A26")  # fmt: skip


def _header(type_level: int, cycle: Cycle, check: bool) -> int:
    control = CONTROL_CHECK_LEVEL if check else _other(CONTROL_CHECK_LEVEL)
    return (
        (START_LEVEL << POS_START)
        | (type_level << POS_TYPE)
        | (cycle.select_level << POS_SELECT)
        | (control << POS_CONTROL)
    )


def _data_field(byte: int) -> int:
    return sum(((byte >> i) & 1) << shift for i, shift in enumerate(_DATA_SHIFTS))


_DATA_FIELDS: Final = tuple(_data_field(b) for b in range(256))


def data_telegram(byte: int, cycle: Cycle, check: bool) -> int:
    """Encode one data telegram (13 bit periods, docs/interbus.md "Telegrams").

    Parameters
    ----------
    byte:
        The data byte, 0..255.
    cycle:
        ID or data cycle (the select bit).
    check:
        ``True`` in the check sequence, ``False`` in the data sequence (the control bit).

    Returns
    -------
    int
        Bit *i* is the level of bit period *i* of the telegram.
    """
    byte = _int("byte", byte, 0, 0xFF, "docs/interbus.md, Telegrams: a data telegram carries one byte, 0..255")
    header = _header(TYPE_DATA_LEVEL, _cycle(cycle), _flag("check", check))
    return header | _DATA_FIELDS[byte] | (STOP_LEVEL << _DATA_STOP)


def status_telegram(cycle: Cycle, check: bool) -> int:
    """Encode one status telegram (5 bit periods): idle (``check=False``) or latch (``check=True``)."""
    return _header(_other(TYPE_DATA_LEVEL), _cycle(cycle), _flag("check", check)) | (STOP_LEVEL << _STATUS_STOP)


def _bit(word: int, position: int) -> int:
    return (word >> position) & 1


def decode_telegram(word: int, length: int, at: int = 0) -> Telegram:
    """Decode one telegram of ``length`` (13 or 5) bit periods held as an int (bit *i* = bit period *i*).

    Raises
    ------
    TelegramError
        Wrong start or stop level, or a type bit that does not match ``length``. ``at`` is the index of the
        telegram's first bit period in the sequence being received, used in the error.
    """
    rule = "docs/interbus.md, Telegrams"
    if type(length) is not int or (length != DATA_TELEGRAM_BITS and length != STATUS_TELEGRAM_BITS):
        length = checked(check_choice, "length", length, (STATUS_TELEGRAM_BITS, DATA_TELEGRAM_BITS),
                         limit="docs/interbus.md, Telegrams")  # fmt: skip
    word = _int("word", word, 0, (1 << length) - 1, f"a {length}-bit telegram")
    at = _int("at", at, 0, None)
    if _bit(word, POS_START) != START_LEVEL:
        raise TelegramError(rule, _bit(word, POS_START), "start bit at the wrong level", at + POS_START)
    is_data = _bit(word, POS_TYPE) == TYPE_DATA_LEVEL
    if is_data != (length == DATA_TELEGRAM_BITS):
        raise TelegramError(rule, _bit(word, POS_TYPE), f"type bit does not match a {length}-bit telegram",
                            at + POS_TYPE)  # fmt: skip
    stop = length - 1
    if _bit(word, stop) != STOP_LEVEL:
        raise TelegramError(rule, _bit(word, stop), "stop bit at the wrong level", at + stop)
    cycle = Cycle.ID if _bit(word, POS_SELECT) == SELECT_ID_LEVEL else Cycle.DATA
    check = _bit(word, POS_CONTROL) == CONTROL_CHECK_LEVEL
    data = sum(_bit(word, shift) << i for i, shift in enumerate(_DATA_SHIFTS)) if is_data else None
    return Telegram(cycle, check, data)


# ================================================================================================================
# Words
# ================================================================================================================


def word_bytes(word: int) -> bytes:
    """The two bytes of a 16-bit word in line order (assumption A4)."""
    word = _int("word", word, 0, 0xFFFF, "docs/interbus.md, Words: a word is 16 bits")
    return word.to_bytes(2, "little" if WORD_LOW_BYTE_FIRST else "big")


def word_from_bytes(data: bytes) -> int:
    """Inverse of :func:`word_bytes`."""
    if type(data) is not bytes or len(data) != 2:
        data = checked(check_bytes, "data", data, 2, limit="docs/interbus.md, Words: a word is two bytes")
    return int.from_bytes(data, "little" if WORD_LOW_BYTE_FIRST else "big")


LOOPBACK_BYTES_ON_LINE: Final = word_bytes(LOOPBACK_WORD)


def data_bytes(length_code: int) -> int:
    """Bytes a device with this length code occupies on the line (Table 3-11, assumption A15).

    Raises
    ------
    InterbusError
        The code is outside 0..31 or reserved in Table 3-11.
    """
    length_code = _int("length_code", length_code, 0, 0x1F, "Table 3-11: a length code is 5 bits")
    row = LENGTH_CODE_BY_VALUE.get(length_code)
    if row is None or row.bits is None:
        raise InterbusError("Table 3-11", length_code, "length code is reserved or not a 5-bit code")
    return math.ceil(row.bits / 8)


def id_register(id_code: int, length_code: int, management: int = 0) -> int:
    """Compose the 16-bit ID register: ID code bits 7..0, length code bits 12..8, management bits 15..13.

    ``management`` holds the bits at their register positions (``MGMT_*_BIT``).
    """
    id_code = _int("id_code", id_code, 0, 0xFF, "Table A-3: an ID code is 8 bits")
    length_code = _int("length_code", length_code, 0, 0x1F, "Table 3-11: a length code is 5 bits")
    management = _int("management", management, 0, 0xFFFF, "docs/interbus.md, ID register")
    if management & ~MGMT_MASK:
        raise InterbusError("docs/interbus.md, ID register", management, "only bits 15..13 are management bits")
    return management | (length_code << 8) | id_code


class BranchControl(Enum):
    """What the master tells a bus terminal module to do with its branch (command word bits 7..6, BK-4)."""

    NONE = 0
    """Leave the branch as it is."""
    OFF = 1
    """Switch the branch off: it leaves the data path."""
    ON = 2
    """Switch the branch on, without the extended BK function."""
    ON_EXTENDED = 3
    """Switch the branch on and activate the extended BK function (2.4)."""


def command_word(watchdog_code: int | None = None, quit_peripheral_error: bool = False,
                 processor_command: int | None = None, alarm_request: bool = False,
                 branch: BranchControl = BranchControl.NONE, optical_request: bool = False,
                 alarm_output: bool | None = None) -> int:
    """Compose the 16-bit command word the master shifts into a device in an ID cycle (assumptions A9, A18).

    Parameters
    ----------
    watchdog_code:
        Index into ``WATCHDOG_TIMEOUTS_S`` (Table 3-13: 50 ms, 200 ms, 1000 ms, off), or ``None`` to leave the
        device's setting alone.
    quit_peripheral_error:
        Quit Peripheral Error (0714h, manual 3.6.2): the device clears its PF latch and pulses /ModAck.
    processor_command:
        A byte for the device's processor command register (management channel, 3.4.9), or ``None``.
    alarm_request:
        Ask the device to send its processor alarm register in the next ID cycle (3.4.9); a bus terminal module
        without a µP sends its branch status byte (:func:`bk_status`, BK-5).
    branch:
        A bus terminal module's branch control (BK-4).
    optical_request:
        Ask the device to send its optical status byte (:func:`optical_status`) in the next ID cycle in place of the
        ID code (OPT-50); not together with ``processor_command`` (both use bits 15..8) or ``alarm_request``.
    alarm_output:
        Set a bus terminal module's ALARM output (MFP15, Table 2-8) on or off, ``None`` to leave it (BK-12); not
        together with ``processor_command`` (bits 15..8).
    """
    if type(branch) is not BranchControl:
        branch = checked(check_instance, "branch", branch, BranchControl, "a BranchControl")
    word = branch.value << CMD_BRANCH_SHIFT
    quit_peripheral_error = _flag("quit_peripheral_error", quit_peripheral_error)
    alarm_request = _flag("alarm_request", alarm_request)
    if processor_command is not None:
        processor_command = _int("processor_command", processor_command, 0, 0xFF,
                                 "manual 3.4.9: a processor command is one byte")  # fmt: skip
        word |= (processor_command << CMD_PCMD_SHIFT) | (1 << CMD_PCMD_BIT)
    if alarm_request:
        word |= 1 << CMD_ALARM_BIT
    if _flag("optical_request", optical_request):
        if processor_command is not None or alarm_request:
            raise InterbusError("OPT-50", optical_request, "an optical status request goes without a processor "
                                "command and without an alarm request (one answer per ID cycle, bits 15..8)")
        word |= 1 << CMD_OPTICAL_BIT
    if alarm_output is not None:
        alarm_output = _flag("alarm_output", alarm_output)
        if processor_command is not None:
            raise InterbusError("BK-12", alarm_output, "the ALARM output is set without a processor command "
                                "(both use bits 15..8)")
        word |= 1 << CMD_ALARM_OUT_SET_BIT | int(alarm_output) << CMD_ALARM_OUT_BIT
    if watchdog_code is not None:
        watchdog_code = _int("watchdog_code", watchdog_code, 0, len(WATCHDOG_TIMEOUTS_S) - 1,
                             "Table 3-13: an index into WATCHDOG_TIMEOUTS_S")  # fmt: skip
        word |= (watchdog_code << CMD_WD_CODE_SHIFT) | (1 << CMD_WD_SET_BIT)
    if quit_peripheral_error:
        word |= 1 << CMD_QUIT_BIT
    return word


class CommandWord(NamedTuple):
    """A decoded command word: the watchdog code to apply (``None``: leave it), the quit request, a processor
    command byte (``None``: none) and the processor alarm request."""

    watchdog_code: int | None
    quit_peripheral_error: bool
    processor_command: int | None = None
    alarm_request: bool = False
    branch: BranchControl = BranchControl.NONE
    optical_request: bool = False
    alarm_output: bool | None = None


def decode_command_word(word: int) -> CommandWord:
    """Inverse of :func:`command_word`; bits without a meaning are ignored."""
    word = _int("word", word, 0, 0xFFFF, "a command word is 16 bits")
    code = (word >> CMD_WD_CODE_SHIFT) & 0b11 if _bit(word, CMD_WD_SET_BIT) else None
    pcmd = (word >> CMD_PCMD_SHIFT) & 0xFF if _bit(word, CMD_PCMD_BIT) else None
    branch = BranchControl((word >> CMD_BRANCH_SHIFT) & 0b11)
    optical = pcmd is None and bool(_bit(word, CMD_OPTICAL_BIT))
    alarm_out = bool(_bit(word, CMD_ALARM_OUT_BIT)) if pcmd is None and _bit(word, CMD_ALARM_OUT_SET_BIT) else None
    return CommandWord(code, bool(_bit(word, CMD_QUIT_BIT)), pcmd, bool(_bit(word, CMD_ALARM_BIT)), branch, optical,
                       alarm_out)


# ================================================================================================================
# MAU warnings: the optical status byte (manual 1.6.3; docs/assumptions/optical.md OPT-50..OPT-53)
# ================================================================================================================

# OPT-51 The optical status byte a device sends in place of its ID code when asked (CMD_OPTICAL_BIT): 10000b in
# bits 7..3 (80h..87h: no ID code of Table A-3 lies there, so the master tells it from the ID code of a device that
# does not know the request), bits 2..0 MAUWH, MAUWR, MAUWS.
OPTICAL_STATUS_MARK: Final = 0b10000 << 3
MAU_WARNINGS: Final = ("MAUWH", "MAUWR", "MAUWS")
"""The MAU warnings of 1.6.3 in bit order: incoming interface, outgoing interface, branch."""


def optical_status(mau: Sequence[bool]) -> int:
    """Compose the optical status byte from the three MAU warnings (MAUWH, MAUWR, MAUWS; OPT-51)."""
    if isinstance(mau, (str, bytes)) or not isinstance(mau, Sequence) or len(mau) != len(MAU_WARNINGS):
        _refuse("mau", "a sequence of 3 bools (MAUWH, MAUWR, MAUWS)", mau)
    bits = (_flag(name, on) << i for i, (name, on) in enumerate(zip(MAU_WARNINGS, mau, strict=True)))
    return OPTICAL_STATUS_MARK | sum(bits)


def decode_optical_status(byte: int) -> tuple[bool, bool, bool] | None:
    """The MAU warnings (MAUWH, MAUWR, MAUWS) of an optical status byte, ``None`` if ``byte`` has not the mark
    (an ID code: the device does not know the request, OPT-51)."""
    byte = _int("byte", byte, 0, 0xFF, "OPT-51: the optical status is one byte")
    if byte & ~0b111 != OPTICAL_STATUS_MARK:
        return None
    return bool(byte & 1), bool(byte & 2), bool(byte & 4)


# ================================================================================================================
# Bus terminal modules: the counter telegram of device-oriented local-bus diagnostics and the branch status byte
# (manual 2.2.2, 2.4; docs/interbus.md "Counter telegram"; docs/assumptions/bus-terminal.md BK-5..BK-7)
# ================================================================================================================

# BK-6 The counter telegram: a data telegram with select = ID and control = check, sent outside any frame by the
# first device behind a break in place of idle status telegrams; its byte is the count (bits 5..0, LSB first on the
# line in bit periods 4..9) under a 2-bit mark (bits 7..6): COUNTER_MARK, or COUNTER_SATURATED_MARK once a count
# went past COUNTER_MAX. Devices increment it serially in flight (count_bit, BK-31), so the mark, which comes after
# the count, takes the carry out of the count: a saturated count stays saturated.
COUNTER_CYCLE: Final = Cycle.ID
COUNTER_CHECK: Final = True
COUNTER_MARK: Final = 0b10 << 6
COUNTER_SATURATED_MARK: Final = 0b11 << 6
COUNTER_MAX: Final = 0x3F
"""The count saturates here (6 bits); a saturated count locates nothing (BK-6)."""

# BK-5 The branch status byte a bus terminal module without a µP sends in place of its ID code when asked (command
# word bit 5): bit 7 a reconfiguration request (CONF edge) waits, bit 6 the BK closed its branch itself
# (extended function), bits 5..0 the last count received on the branch return line (0: none).
BK_STATUS_CONF_BIT: Final = 7
BK_STATUS_CLOSED_BIT: Final = 6


COUNT_FIRST_BIT: Final = POS_DATA
"""The bit period of a counter telegram's count LSB (data bit 0)."""
COUNT_BITS: Final = COUNTER_MAX.bit_length()
SATURATION_BIT: Final = POS_DATA + COUNT_BITS
"""The bit period of the mark bit (data bit 6) that turns COUNTER_MARK into COUNTER_SATURATED_MARK."""


def counter_telegram(count: int) -> int:
    """Encode the counter telegram carrying ``count`` (1..``COUNTER_MAX``) as a data telegram (BK-6)."""
    count = _int("count", count, 1, COUNTER_MAX, "BK-6: a counter telegram counts 1..63 devices")
    return data_telegram(COUNTER_MARK | count, COUNTER_CYCLE, COUNTER_CHECK)


def is_counter_telegram(telegram: Telegram) -> bool:
    """A receiver that no frame runs for takes ``telegram`` as a counter telegram (BK-6, BK-36, BK-49): a data
    telegram with select = ID and control = check. Working traffic sends one only inside an ID cycle's check sequence
    (BK-32), so between frames it is a device's count behind a break, never a frame's."""
    return telegram.data is not None and (telegram.cycle, telegram.check) == (COUNTER_CYCLE, COUNTER_CHECK)


def counter_count(byte: int) -> int | None:
    """The count a counter telegram's byte stands for: the count under COUNTER_MARK (1..63), ``COUNTER_MAX`` under
    COUNTER_SATURATED_MARK whatever the count bits; ``None`` for any other byte (BK-6, BK-31)."""
    byte = _int("byte", byte, 0, 0xFF, "BK-6: a counter telegram carries one byte")
    mark = byte & ~COUNTER_MAX
    if mark == COUNTER_SATURATED_MARK:
        return COUNTER_MAX
    if mark != COUNTER_MARK or byte == COUNTER_MARK:
        return None
    return byte & COUNTER_MAX


def decode_counter_telegram(word: int) -> int | None:
    """The count of a counter telegram (:func:`counter_count` of its byte), ``None`` if ``word`` is no counter
    telegram (BK-6)."""
    word = _int("word", word, 0, (1 << DATA_TELEGRAM_BITS) - 1, "a data telegram is 13 bit periods")
    try:
        telegram = decode_telegram(word, DATA_TELEGRAM_BITS)
    except TelegramError:
        return None
    return counter_count(telegram.data) if telegram.data is not None and is_counter_telegram(telegram) else None


def count_bit(position: int, level: int, carry: int) -> tuple[int, int]:
    """One bit period of the serial increment a device applies to a counter telegram in flight (BK-31).

    Parameters
    ----------
    position:
        The bit period in the telegram (0..12).
    level:
        The level received in it.
    carry:
        The carry into it: 1 at the start of the telegram (the increment), then what this function returned.

    Returns
    -------
    tuple[int, int]
        The level to send and the carry into the next bit period. Count bits (``COUNT_FIRST_BIT`` ..) send
        ``level XOR carry`` and carry on ``carry AND level``; the mark bit at ``SATURATION_BIT`` is sent ORed with
        the carry out of the count (63 + 1 sets COUNTER_SATURATED_MARK, which stays set); every other bit goes on
        unchanged. Each sent level depends only on bits received up to it, so a repeater with any delay can apply it.
    """
    position = _int("position", position, 0, DATA_TELEGRAM_BITS - 1, "a data telegram is 13 bit periods")
    level, carry = _int("level", level, 0, 1), _int("carry", carry, 0, 1)
    if COUNT_FIRST_BIT <= position < SATURATION_BIT:
        return level ^ carry, carry & level
    if position == SATURATION_BIT:
        return level | carry, 0
    return level, carry


_COUNT_ZERO: Final = data_telegram(COUNTER_MARK, COUNTER_CYCLE, COUNTER_CHECK)
"""What a device behind a break increments in its mind: count 0 (not itself a counter telegram)."""


def count_on(word: int | None) -> int:
    """What a device behind a break sends on: ``None`` (it receives nothing: it is the first behind the break)
    starts the count at 1, a counter telegram is passed on incremented bit by bit (:func:`count_bit`): 63 and a
    saturated count give a saturated count (BK-6, BK-31)."""
    if word is not None and decode_counter_telegram(word) is None:
        raise InterbusError("docs/interbus.md, Counter telegram", word, "a device passes on counter telegrams only")
    received = _COUNT_ZERO if word is None else word
    sent, carry = 0, 1
    for position in range(DATA_TELEGRAM_BITS):
        level, carry = count_bit(position, (received >> position) & 1, carry)
        sent |= level << position
    return sent


class BkStatus(NamedTuple):
    """A decoded branch status byte (BK-5)."""

    conf_request: bool
    closed: bool
    counter: int


def bk_status(conf_request: bool, closed: bool, count: int) -> int:
    """Compose the branch status byte (BK-5); ``count`` 0..``COUNTER_MAX``, 0 for none received."""
    conf_request = _flag("conf_request", conf_request)
    closed = _flag("closed", closed)
    count = _int("count", count, 0, COUNTER_MAX, "BK-5: the count is 6 bits")
    return (conf_request << BK_STATUS_CONF_BIT) | (closed << BK_STATUS_CLOSED_BIT) | count


def decode_bk_status(byte: int) -> BkStatus:
    """Inverse of :func:`bk_status`."""
    byte = _int("byte", byte, 0, 0xFF, "BK-5: the status is one byte")
    return BkStatus(bool(_bit(byte, BK_STATUS_CONF_BIT)), bool(_bit(byte, BK_STATUS_CLOSED_BIT)), byte & COUNTER_MAX)


# ================================================================================================================
# CRC
# ================================================================================================================


def _reflect(value: int, width: int) -> int:
    return int(f"{value:0{width}b}"[::-1], 2)


def crc_update_bit(crc: int, bit: int) -> int:
    """One step of the bit-serial CRC register (the hardware form): shift in one message bit.

    The register is kept in normal (MSB-first) form; :func:`crc16` feeds bits in the order given by
    ``CRC_REFIN`` and applies ``CRC_REFOUT`` and ``CRC_XOROUT`` at the end.
    """
    crc = _int("crc", crc, 0, 0xFFFF, "a CRC register is 16 bits")
    bit = _int("bit", bit, 0, 1)
    feedback = ((crc >> 15) & 1) ^ bit
    crc = (crc << 1) & 0xFFFF
    return crc ^ CRC_POLY if feedback else crc


def _table_entry(byte: int) -> int:
    crc = 0
    for i in range(7, -1, -1):
        crc = crc_update_bit(crc, (byte >> i) & 1)
    return crc


_CRC_TABLE: Final = tuple(_table_entry(b) for b in range(256))
_BYTE_ORDER_TABLE: Final = tuple(_reflect(b, 8) if CRC_REFIN else b for b in range(256))


def crc16(data: bytes, init: int = CRC_INIT) -> int:
    """CRC-16 of ``data`` with the parameters of assumption A6 (table-driven, built from :func:`crc_update_bit`).

    Examples
    --------
    >>> hex(crc16(b"123456789"))
    '0x906e'
    """
    data = _data("data", data)
    crc = _int("init", init, 0, 0xFFFF, "a CRC register is 16 bits")
    table = _CRC_TABLE
    order = _BYTE_ORDER_TABLE
    for byte in data:
        crc = ((crc << 8) & 0xFFFF) ^ table[(crc >> 8) ^ order[byte]]
    if CRC_REFOUT:
        crc = _reflect(crc, 16)
    return crc ^ CRC_XOROUT


# ================================================================================================================
# CNTR
# ================================================================================================================


class CntrFlags(NamedTuple):
    """The two flags of a legal CNTR word: ``attention`` (some device wants an ID cycle) and ``error``."""

    attention: bool
    error: bool


def cntr_word(attention: bool, error: bool) -> int:
    """Encode a legal CNTR word (assumption A7): each flag next to its complement, all other bits zero."""
    attention, error = _flag("attention", attention), _flag("error", error)
    return (
        (attention << CNTR_ATTN_BIT)
        | ((not attention) << CNTR_NATTN_BIT)
        | (error << CNTR_ERR_BIT)
        | ((not error) << CNTR_NERR_BIT)
    )


CNTR_CLEAR: Final = cntr_word(False, False)
"""The CNTR word the master sends."""

_CNTR_LEGAL: Final = {cntr_word(a, e): CntrFlags(a, e) for a in (False, True) for e in (False, True)}


def decode_cntr(word: int) -> CntrFlags | None:
    """The flags of a CNTR word, or ``None`` if the word is not one of the four legal codes."""
    if type(word) is not int:
        word = _int("word", word, 0, 0xFFFF, "a CNTR word is 16 bits")
    return _CNTR_LEGAL.get(word)


def forward_cntr(word: int, local_error: bool, attention: bool) -> tuple[int, bool]:
    """What a device sends on for a received CNTR word (docs/interbus.md, "Check sequence").

    Parameters
    ----------
    word:
        The CNTR word received.
    local_error:
        The device's own check of its incoming line failed (telegram, sequence or CRC).
    attention:
        The device has a new management flag (PF or WD) for the master.

    Returns
    -------
    tuple[int, bool]
        The CNTR word sent on (always legal) and whether the received word was illegal (corrupted). An illegal
        word counts as a local error and sets the attention flag conservatively. The rule is causal for a
        repeater with ``REPEATER_DELAY_BITS`` of delay: the ERR pair is last on the line, so the device has seen
        the whole word, and the stop bit after it, before it sends the pair.
    """
    flags = decode_cntr(_int("word", word, 0, 0xFFFF, "a CNTR word is 16 bits"))
    local_error, attention = _flag("local_error", local_error), _flag("attention", attention)
    bad = flags is None
    attn_in, err_in = (True, False) if flags is None else flags
    return cntr_word(attn_in or attention, err_in or local_error or bad), bad


# ================================================================================================================
# Frame
# ================================================================================================================


@dataclass(frozen=True)
class Frame:
    """One summation frame as it passes one line: the data sequence and the check sequence.

    Attributes
    ----------
    cycle:
        ID or data cycle.
    data:
        The data sequence's bytes in line order (loopback word and device data, docs/interbus.md "Frame").
    crc:
        The CRC word of the check sequence.
    cntr:
        The CNTR word of the check sequence.
    """

    cycle: Cycle
    data: bytes
    crc: int
    cntr: int

    @classmethod
    def build(cls, cycle: Cycle, data: bytes, cntr: int = CNTR_CLEAR) -> Frame:
        """A frame whose CRC matches its data."""
        data = _data("data", data)
        return cls(_cycle(cycle), data, crc16(data), _int("cntr", cntr, 0, 0xFFFF, "a CNTR word is 16 bits"))

    def __post_init__(self) -> None:
        _cycle(self.cycle)
        _data("data", self.data)
        _int("crc", self.crc, 0, 0xFFFF, "a CRC word is 16 bits")
        _int("cntr", self.cntr, 0, 0xFFFF, "a CNTR word is 16 bits")

    def check_bytes(self) -> bytes:
        """The check sequence's bytes in line order."""
        words = {"crc": self.crc, "cntr": self.cntr}
        return b"".join(word_bytes(words[name]) for name in CHECK_SEQUENCE_WORDS)

    def telegrams(self) -> list[int]:
        """The frame's data telegrams in line order (data sequence, then check sequence)."""
        return [data_telegram(b, self.cycle, False) for b in self.data] + [
            data_telegram(b, self.cycle, True) for b in self.check_bytes()
        ]

    def bit_count(self) -> int:
        """Bit periods the frame occupies on the line."""
        return frame_bits(len(self.data))


def frame_bits(data_len: int) -> int:
    """Bit periods of a frame whose data sequence has ``data_len`` bytes."""
    data_len = _int("data_len", data_len, 0, None)
    return DATA_TELEGRAM_BITS * (data_len + CHECK_TELEGRAMS)


class BitLocation(NamedTuple):
    """Where a bit of a frame sits: telegram index, bit period inside the telegram, and the telegram's word."""

    telegram: int
    offset: int
    word: int


def locate_bit(frame: Frame, bit: int) -> BitLocation:
    """The telegram holding bit period ``bit`` of ``frame`` (0 = the first start bit)."""
    checked(check_instance, "frame", frame, Frame)
    bit = _int("bit", bit, 0, None)
    if not 0 <= bit < frame.bit_count():
        raise InterbusError("docs/interbus.md, Frame", bit, f"bit index outside a {frame.bit_count()}-bit frame")
    index, offset = divmod(bit, DATA_TELEGRAM_BITS)
    n = len(frame.data)
    if index < n:
        word = data_telegram(frame.data[index], frame.cycle, False)
    else:
        word = data_telegram(frame.check_bytes()[index - n], frame.cycle, True)
    return BitLocation(index, offset, word)


def frame_from_telegrams(telegrams: Iterable[Telegram | LineReset]) -> Frame:
    """Assemble the first frame in a received telegram sequence.

    Leading status telegrams and counter telegrams (:func:`is_counter_telegram`) are skipped; the frame is the run of
    data telegrams with the control bit clear, followed by ``CHECK_TELEGRAMS`` data telegrams with it set, all of one
    cycle type.

    Raises
    ------
    InterbusError
        A reset, a status telegram or a change of cycle type inside the frame, or a short check sequence.
    """
    rule = "docs/interbus.md, Frame"
    data = bytearray()
    check = bytearray()
    cycle: Cycle | None = None
    if isinstance(telegrams, (str, bytes)) or not isinstance(telegrams, Iterable):
        _refuse("telegrams", "an iterable of telegrams (Telegram or LineReset)", telegrams)
    for t in telegrams:
        if not isinstance(t, (Telegram, LineReset)):
            _refuse("telegram", "a Telegram or LineReset", t)
        if isinstance(t, LineReset):
            raise InterbusError(rule, t, "INTERBUS reset inside a frame")
        if cycle is None and not opens_frame(t):
            continue
        if t.data is None:
            raise InterbusError(rule, t, "status telegram inside a frame")
        if cycle is None:
            cycle = t.cycle
        if t.cycle is not cycle:
            raise InterbusError(rule, t, "cycle type changes inside a frame")
        if not t.check:
            if check:
                raise InterbusError(rule, t, "data sequence telegram after the check sequence began")
            data.append(t.data)
            continue
        check.append(t.data)
        if len(check) == CHECK_TELEGRAMS:
            words = {
                name: word_from_bytes(bytes(check[2 * i : 2 * i + 2])) for i, name in enumerate(CHECK_SEQUENCE_WORDS)
            }
            return Frame(cycle, bytes(data), words["crc"], words["cntr"])
    raise InterbusError(rule, len(check), "frame ends before its check sequence is complete")


# ================================================================================================================
# Cycle timing
# ================================================================================================================


def ring_delay_status_telegrams(devices: int, return_repeaters: int = 0) -> int:
    """Idle status telegrams the master sends while the check sequence travels the ring (assumption A10, A11): a
    repeater delay for each of the ``devices`` on the forward line and for each of the ``return_repeaters`` on the
    return lines (an LBD-MR device's counter block repeats its return line, BK-35, BK-55: at most one a device)."""
    devices = _int("devices", devices, 0, MAX_DEVICES, "manual: at most 512 devices in a ring")
    return_repeaters = _int("return_repeaters", return_repeaters, 0, devices, "BK-35: one per LBD-MR device")
    repeaters = devices + return_repeaters
    return math.ceil(repeaters * REPEATER_DELAY_BITS / STATUS_TELEGRAM_BITS) + TURNAROUND_STATUS_TELEGRAMS


def branch_switch_pause_bits(devices: int) -> int:
    """Bit periods of idle status telegrams the master sends after a latched cycle switching a branch in a ring of
    ``devices`` (BK-46): the ring delay (A10, A11) and :data:`BRANCH_SWITCH_PAUSE_STATUS_TELEGRAMS`."""
    return (ring_delay_status_telegrams(devices) + BRANCH_SWITCH_PAUSE_STATUS_TELEGRAMS) * STATUS_TELEGRAM_BITS


def cycle_bits(data_bytes: int, devices: int, return_repeaters: int = 0) -> int:
    """Bit periods of one cycle (docs/interbus.md, "Cycle timing").

    Parameters
    ----------
    data_bytes:
        Bytes of device data in the data sequence (all devices' registers; ``2 * devices`` in an ID cycle).
    devices:
        Devices in the ring.
    return_repeaters:
        Repeaters on the ring's return lines: its LBD-MR devices (BK-35, BK-55; ``ring.return_repeaters``).

    Returns
    -------
    int
        13 x (6 + data_bytes) for the frame, then the status telegrams of the ring delay, the master's
        turnaround and the latch: compare Beckhoff's (13 x (6 + N) + 1.5 x M) x T_bit.
    """
    data_bytes = _int("data_bytes", data_bytes, 0, None, "docs/interbus.md, Cycle timing")
    status = ring_delay_status_telegrams(devices, return_repeaters) + LATCH_STATUS_TELEGRAMS
    return frame_bits(LOOPBACK_BYTES + data_bytes) + STATUS_TELEGRAM_BITS * status


class CyclePhases(NamedTuple):
    """Where the phases of 3.4.14 (Figure 3-22) fall in one cycle: the bit periods (counted from the cycle's first
    bit, 0) whose mid-bit sample (A1) decides them, as the pin-level frame engine does; the transaction level has
    every device see them at once (docs/assumptions/sdk.md, FW-2)."""

    check_bit: int
    """The control bit of the first check telegram: a data cycle's I/O access bit turns 1 (busy)."""
    latch_bit: int
    """The stop bit of the first latch status telegram: the latch phase begins (data cycles)."""
    end_bit: int
    """The stop bit of the second latch status telegram: data latched, both phases over."""
    total_bits: int
    """The cycle's length (:func:`cycle_bits`)."""


def cycle_phases(data_bytes: int, devices: int, return_repeaters: int = 0) -> CyclePhases:
    """The phases of one cycle with ``data_bytes`` bytes of device data, ``devices`` devices and ``return_repeaters``
    LBD-MR devices among them (3.4.14, A11, :func:`cycle_bits`)."""
    total = cycle_bits(data_bytes, devices, return_repeaters)
    check = DATA_TELEGRAM_BITS * (LOOPBACK_BYTES + data_bytes) + POS_CONTROL
    last_stop = total - 1
    return CyclePhases(check, last_stop - STATUS_TELEGRAM_BITS * (LATCH_STATUS_TELEGRAMS - 1), last_stop, total)


def reset_bits(devices: int, return_repeaters: int = 0) -> int:
    """Bit periods of an INTERBUS reset sequence, including the ring delay of its end (assumption A12) over
    ``devices`` with ``return_repeaters`` LBD-MR devices among them (:func:`ring_delay_status_telegrams`)."""
    delay = ring_delay_status_telegrams(devices, return_repeaters)
    return RESET_HOLD_BITS + STATUS_TELEGRAM_BITS * (RESET_END_STATUS_TELEGRAMS + delay)


def check_bit_rate(bit_rate: int) -> int:
    """Return ``bit_rate`` if Table 1-7 lists it (500 kbit/s, 2 Mbit/s), else raise :class:`InterbusError`."""
    if type(bit_rate) is int and bit_rate in BIT_RATES:
        return bit_rate
    return checked(check_choice, "bit_rate", bit_rate, BIT_RATES, limit="Table 1-7")


def clocks_per_bit(bit_rate: int) -> int:
    """32 MHz clock periods per bit (1.7.1): 64 at 500 kbit/s, 16 at 2 Mbit/s."""
    return CLOCK_HZ // check_bit_rate(bit_rate)


# ================================================================================================================
# Line levels (the bit/pin-level view)
# ================================================================================================================

LevelArray = npt.NDArray[np.uint8]


def telegram_levels(words: Sequence[int], length: int) -> LevelArray:
    """Levels of telegrams of one length, concatenated."""
    length = _int("length", length, 1, 32)
    given = np.asarray(words) if isinstance(words, Sequence | np.ndarray) and not isinstance(words, str) else None
    if given is None or given.ndim != 1 or not (given.size == 0 or np.issubdtype(given.dtype, np.integer)) or (
        given.size and (given.min() < 0 or given.max() >> length)
    ):
        _refuse("words", f"a sequence of {length}-bit telegram words", words)
    packed = np.asarray(words, dtype=np.uint32)[:, None]
    return ((packed >> np.arange(length, dtype=np.uint32)) & 1).astype(np.uint8).ravel()


def frame_levels(frame: Frame) -> LevelArray:
    """Level sequence of a frame (data sequence and check sequence)."""
    checked(check_instance, "frame", frame, Frame)
    return telegram_levels(frame.telegrams(), DATA_TELEGRAM_BITS)


def status_levels(cycle: Cycle, check: bool, count: int) -> LevelArray:
    """Level sequence of ``count`` identical status telegrams."""
    count = _int("count", count, 0, None)
    return telegram_levels([status_telegram(cycle, check)] * count, STATUS_TELEGRAM_BITS)


def cycle_levels(frame: Frame, devices: int, latch: bool) -> LevelArray:
    """Everything the master sends in one cycle: the frame, the idle status telegrams of the ring delay and
    turnaround, then the latch status telegrams (``latch``) or as many idle ones (a failed cycle).

    Its length is :func:`cycle_bits` for the frame's data bytes and ``devices``.
    """
    checked(check_instance, "frame", frame, Frame)
    _flag("latch", latch)
    return np.concatenate(
        [
            frame_levels(frame),
            status_levels(frame.cycle, False, ring_delay_status_telegrams(devices)),
            status_levels(frame.cycle, latch, LATCH_STATUS_TELEGRAMS),
        ]
    )


def reset_levels(devices: int, return_repeaters: int = 0) -> LevelArray:
    """Level sequence of an INTERBUS reset (Alarm Stop): the line held low, then idle status telegrams (their count
    :func:`reset_bits`'s)."""
    low = np.full(RESET_HOLD_BITS, START_LEVEL, dtype=np.uint8)
    end = RESET_END_STATUS_TELEGRAMS + ring_delay_status_telegrams(devices, return_repeaters)
    return np.concatenate([low, status_levels(Cycle.DATA, False, end)])


def parse_levels(levels: Sequence[int] | LevelArray) -> list[Telegram | LineReset]:
    """Receive a level sequence: the reference receiver of docs/interbus.md, "Receiver".

    Idle levels between telegrams are skipped. A start level that lasts ``RESET_DETECT_BITS`` bit periods is an
    INTERBUS reset; the reset lasts until the line returns to the idle level. An unfinished telegram at the end
    of the sequence is ignored.

    Raises
    ------
    TelegramError
        Wrong stop level or a type bit that does not match the telegram's length.
    """
    line = [int(v) for v in _levels("levels", levels)]
    out: list[Telegram | LineReset] = []
    i = 0
    n = len(line)
    while i < n:
        if line[i] == IDLE_LEVEL:
            i += 1
            continue
        run = i
        while run < n and line[run] == START_LEVEL and run - i < RESET_DETECT_BITS:
            run += 1
        if run - i >= RESET_DETECT_BITS:
            out.append(LineReset(i))
            while i < n and line[i] == START_LEVEL:
                i += 1
            continue
        if i + POS_TYPE >= n:
            break
        length = DATA_TELEGRAM_BITS if line[i + POS_TYPE] == TYPE_DATA_LEVEL else STATUS_TELEGRAM_BITS
        if i + length > n:
            break
        word = sum(level << k for k, level in enumerate(line[i : i + length]))
        out.append(decode_telegram(word, length, at=i))
        i += length
    return out


def levels_to_samples(levels: Sequence[int] | LevelArray, bit_rate: int) -> LevelArray:
    """Expand one level per bit period to one sample per 32 MHz clock period (pin level, 1.7.1)."""
    return np.repeat(_levels("levels", levels), clocks_per_bit(bit_rate))


def samples_to_levels(samples: Sequence[int] | LevelArray, bit_rate: int, phase: int | None = None) -> LevelArray:
    """Sample a 32 MHz pin trace once per bit period, at ``phase`` clocks into each bit (default: mid-bit)."""
    cpb = clocks_per_bit(bit_rate)
    at = cpb // 2 if phase is None else _int("phase", phase, 0, cpb - 1, "docs/interbus.md, Line: within one bit")
    return _levels("samples", samples)[at::cpb]


def opens_frame(telegram: Telegram) -> bool:
    """``telegram`` begins a frame where no frame runs: a data telegram, not a counter telegram (BK-49: a master's
    receiver, :func:`frame_from_telegrams`, skips counter telegrams between frames as it skips status telegrams)."""
    return telegram.data is not None and not is_counter_telegram(telegram)


def returned_frame(telegrams: Iterable[Telegram | LineReset]) -> Frame | None:
    """The frame a master's receiver assembles from the telegrams that came back in a cycle: from its data telegrams
    alone (the status telegrams and line resets among them dropped), ``None`` if none opens a frame (a dead line;
    counter telegrams alone are none, BK-49). ``model.pinring.PinRing``'s master and the transaction level's
    wake-up window (``interbus.wake.wake_return``, M22) alike.

    Raises
    ------
    InterbusArgumentError
        ``telegrams`` is not an iterable of :class:`Telegram` and :class:`LineReset` items.
    InterbusError
        The data telegrams open a frame that does not assemble (:func:`frame_from_telegrams`).
    """
    wanted = "an iterable of telegrams (Telegram or LineReset)"
    if isinstance(telegrams, (str, bytes)) or not isinstance(telegrams, Iterable):
        _refuse("telegrams", wanted, telegrams)
    telegrams = list(telegrams)
    if not all(isinstance(t, (Telegram, LineReset)) for t in telegrams):
        _refuse("telegrams", wanted, telegrams)
    frames = [t for t in telegrams if isinstance(t, Telegram) and t.data is not None]
    return frame_from_telegrams(frames) if any(opens_frame(t) for t in frames) else None


def frames_from_levels(levels: Sequence[int] | LevelArray) -> list[Frame]:
    """Every complete frame in a received level sequence, in order; resets and status telegrams between frames
    and counter telegrams between frames are skipped (a receiving master's or testbench's view of a line)."""
    telegrams = [t for t in parse_levels(levels) if isinstance(t, Telegram)]
    frames: list[Frame] = []
    while any(opens_frame(t) for t in telegrams):
        frame = frame_from_telegrams(telegrams)
        frames.append(frame)
        first = next(i for i, t in enumerate(telegrams) if opens_frame(t))
        telegrams = telegrams[first + len(frame.data) + CHECK_TELEGRAMS :]
    return frames

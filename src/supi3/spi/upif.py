"""The serial µP interface protocol (SPI slave / Intel synchronous serial), at the byte level.

Ref: IBS SUPI 3 OPC UM E rev. 05, 3.4.1 - 3.4.7, Tables 3-5 to 3-10. :class:`UpifProtocol` is the one protocol
state machine: the pin-level model (:mod:`supi3.spi.slave_pins`) and the firmware-facing :class:`UpInterface`
both drive it, one byte ("frame": /SS low, 8 SCLK rising edges, /SS high) at a time:

1. :meth:`UpifProtocol.begin` at the falling edge of /SS decides what the chip drives during the byte (a read
   register, the echo of the last received byte, or nothing);
2. :meth:`UpifProtocol.end` at the rising edge of /SS processes the received byte, or :meth:`UpifProtocol.abort`
   drops a frame that did not have 8 bits.

Every decision is in ``docs/upif.md`` and ``docs/assumptions/upif.md``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from enum import StrEnum
from typing import Final, TypeVar

from supi3.checks import check_bits, check_bool, check_bytes, check_instance, check_int, describe
from supi3.config import DeviceConfig
from supi3.errors import ArgumentError, Supi3Error
from supi3.model.chip import Supi3
from supi3.model.registers import InterfaceViolationError, RegisterFile
from supi3.pinout import C_D_COMMAND, C_D_DATA
from supi3.regmap import (
    BLOCK_ADDRESS,
    COMMAND_BYTE,
    INIT_BYTE,
    REGISTER_MAP,
    Access,
    AccessDirection,
    CommandByte,
    Register,
    decode_command,
    encode_command,
)

__all__ = [
    "C_D_COMMAND",
    "C_D_DATA",
    "InterfaceDisabledError",
    "InterruptedCommandError",
    "Mode",
    "ModeLockedError",
    "NotInitializedError",
    "Phase",
    "ProtocolViolationError",
    "UninitializedAccessError",
    "UpInterface",
    "UpifArgumentError",
    "UpifProtocol",
    "UpifUsageError",
]

_T = TypeVar("_T")


_WORD_BITS: Final[int] = 16

# Firmware API after misuse (docs/assumptions/upif.md UP-25 to UP-29): where the manual is silent, one constant each.
REFUSED_BEFORE_INIT: Final[frozenset[str]] = frozenset({"read", "exchange", "block transfer"})
"""UP-25: the register accesses that return data; before initialization the chip drives none (3.4.1, 3.4.3), so
:class:`UpInterface` refuses them (:class:`NotInitializedError`) and sends nothing."""
UNINITIALIZED_WRITE: Final[str] = "interface not initialized: {command:02X}h taken as a faulty initialization byte; " \
    "SAS_INIT needed"
"""UP-26: a write before initialization goes out as on the real chip, which takes its command byte as a faulty
initialization byte and disables the interface (3.4.3); this is the violation reported (strict: raised)."""
INTERRUPTED_INIT: Final[str] = "initialize(): C/D = 1 before the initialization byte, the µP was reset in the middle " \
    "of a command: {byte:02X}h was taken as {what}{effect}; SAS_INIT before initialize() after a µP reset"
"""UP-27: :meth:`UpInterface.initialize` on a chip showing data sends the byte anyway (the chip takes it as the
pending data byte, 3.4.3, 3.4.4) and reports this violation; the initialization is not a first one."""
MODE_LOCKED: Final[str] = "initialize({wanted}): the interface is already initialized in {mode} mode, which only a " \
    "power-up reset or SAS_INIT changes; {byte:02X}h was taken as a command"
"""UP-29: :meth:`UpInterface.initialize` with the other mode on an initialized chip: the chip keeps its mode and
takes the byte as a command (3.4.3); this violation is reported, the initialization is not a first one."""


class Mode(StrEnum):
    """Interface type chosen by the initialization byte (Table 3-8)."""

    MOTOROLA = "motorola"
    """SPI, full duplex on SerIN (MFP6) / SerOUT (MFP7), MSB first."""
    INTEL = "intel"
    """Intel synchronous serial, half duplex on Ser_IN/OUT (MFP6), direction by S/R (MFP7), LSB first."""

    @property
    def init_byte(self) -> int:
        """The initialization byte that selects the mode (Table 3-8)."""
        return INIT_BYTE.constant(self.name).value

    @property
    def lsb_first(self) -> bool:
        """Bit order on the wire (UP-6): Intel LSB first, Motorola MSB first."""
        return self is Mode.INTEL


class Phase(StrEnum):
    """What the interface expects next (3.4.3 - 3.4.6)."""

    INIT = "init"
    """The initialization byte (after power-up reset or SAS_INIT)."""
    COMMAND = "command"
    DATA = "data"
    """The data byte of the last command."""
    BLOCK = "block"
    """The next byte of a block transfer."""
    DISABLED = "disabled"
    """A faulty initialization byte was received: nothing until power-up reset or SAS_INIT (3.4.3)."""


_COMMAND_PHASES: Final[frozenset[Phase]] = frozenset({Phase.INIT, Phase.COMMAND})
"""The phases in which C/D reads :data:`C_D_COMMAND` (a set: the board reads C/D at each /SS rise)."""


ACCESS_END_PHASES: Final[tuple[Phase, ...]] = (Phase.COMMAND, Phase.DISABLED)
"""UP-28: where a register access of :class:`UpInterface` (read, write, exchange, block transfer) leaves the
interface, whether or not it raised a violation: ready for the next command, or disabled after a write before
initialization (UP-26). The access runs to its end inside one :meth:`ViolationLog.deferred` block."""


class UpifUsageError(Supi3Error, ValueError):
    """A call that breaks the API contract of :class:`UpInterface` or :class:`UpifProtocol`."""


class ProtocolViolationError(InterfaceViolationError):
    """A frame that breaks a rule of the serial interface protocol (S/R against the command, a block transfer
    for less than one word, reserved command bits, an incomplete byte); the chip's reaction is modelled."""


@dataclass(frozen=True)
class _Slot:
    """One byte of a block transfer: the data address and what the byte does."""

    address: int
    read: bool
    write: bool


_Frame = tuple[bool, int | None]
"""What :meth:`UpifProtocol.begin` decided for the current byte: the S/R level and the byte the chip drives. A plain
tuple, not a dataclass: one is made per byte, and the C driver's bytes all come through here."""

_COMMANDS: Final[tuple[CommandByte, ...]] = tuple(decode_command(byte & COMMAND_BYTE.mask) for byte in range(256))
"""Every received command byte decoded, reserved bits 5..4 dropped (UP-12): the per-byte path indexes this table."""
_READS_REGISTER: Final[tuple[bool, ...]] = tuple(
    REGISTER_MAP.port(address, AccessDirection.READ).access is not Access.RESERVED_IGNORED
    for address in REGISTER_MAP.addresses
)
"""Per address: a read data byte reaches the register file; ``False`` at 4 and 5, whose data access the chip
ignores, sending the command byte back (3.4.4, 3.4.7)."""
_WRITES_REGISTER: Final[tuple[bool, ...]] = tuple(
    REGISTER_MAP.port(address, AccessDirection.WRITE).access is not Access.RESERVED_IGNORED
    for address in REGISTER_MAP.addresses
)
"""Per address: a written data byte reaches the register file; ``False`` at 4 and 5 (3.4.4, 3.4.7)."""
_PLAIN_COMMANDS: Final[tuple[bool, ...]] = tuple(
    not byte & ~COMMAND_BYTE.mask and _COMMANDS[byte].address != BLOCK_ADDRESS for byte in range(256)
)
"""Per byte: a command byte without reserved bits that starts no block transfer, whose frame reads no register and
reports nothing (UP-8, UP-12): :meth:`UpInterface.transfer` takes it without a frame or a deferred block."""


class UpifProtocol:
    """The protocol state machine of the serial µP interface, shared by the byte- and the pin-level model.

    Parameters
    ----------
    registers:
        The chip's register file; the protocol reads and writes it one data byte at a time.
    """

    def __init__(self, registers: RegisterFile) -> None:
        if not isinstance(registers, RegisterFile):
            raise _refused("registers", registers, "")
        self.registers = registers
        self.mode: Mode | None = None
        self.phase = Phase.INIT
        self.command: CommandByte | None = None
        self.last_rx = 0
        """The last complete received byte: what the chip sends back when a byte reads no register (UP-8)."""
        self._slots: tuple[_Slot, ...] = ()
        self._frame: _Frame | None = None

    # --------------------------------------------------------------------------------------------------------
    # Resets
    # --------------------------------------------------------------------------------------------------------

    def power_up_reset(self) -> None:
        """Hardware reset: the interface expects an initialization byte and every register is cleared."""
        self.registers.power_up_reset()
        self._restart()

    def sas_init(self) -> None:
        """SAS_INIT: the interface expects an initialization byte; the registers keep their values (3.4.3)."""
        self.registers.sas_init()
        self._restart()

    def _restart(self) -> None:
        self.mode = None
        self.phase = Phase.INIT
        self.command = None
        self.last_rx = 0
        self._slots = ()
        self._frame = None

    # --------------------------------------------------------------------------------------------------------
    # Status
    # --------------------------------------------------------------------------------------------------------

    @property
    def c_d(self) -> int:
        """The C/D level (MFP2): :data:`C_D_COMMAND` before an initialization or command byte, else
        :data:`C_D_DATA` (3.4.3, 3.4.4; UP-2, UP-4)."""
        return C_D_COMMAND if self.phase in _COMMAND_PHASES else C_D_DATA

    @property
    def in_frame(self) -> bool:
        """A byte has begun and not yet ended."""
        return self._frame is not None

    @property
    def lsb_first(self) -> bool:
        """Bit order of the next byte: LSB first in Intel mode only; the initialization byte reads the same
        either way (Table 3-8)."""
        return self.mode is not None and self.mode.lsb_first

    # --------------------------------------------------------------------------------------------------------
    # One frame
    # --------------------------------------------------------------------------------------------------------

    def begin(self, s_r: bool) -> int | None:
        """/SS fell: decide the byte the chip drives during this frame, or ``None`` if it drives nothing.

        Parameters
        ----------
        s_r:
            The S/R level sampled at the falling edge of /SS (Intel mode, Table 3-9): ``True`` = the µP sends;
            ignored in Motorola mode and before initialization.

        Returns
        -------
        int | None
            Motorola: always a byte (SerOUT drives during every frame). Intel: a byte when ``s_r`` is ``False``
            (the chip sends on Ser_IN/OUT), else ``None``. Before initialization and when disabled: ``None``.
            The byte is the read register for a read access, else :attr:`last_rx` (UP-8).
        """
        if type(s_r) is not bool:
            s_r = _checked(check_bool, "s_r", s_r)
        if self._frame is not None:
            raise UpifUsageError("begin() inside a frame: call end() or abort() first")
        mode = self.mode
        tx: int | None = None
        # The chip drives in every Motorola frame and in Intel frames with S/R = 0, which are read frames (Table
        # 3-9); what it drives is a read register or the echo of the last byte (UP-8).
        if mode is Mode.MOTOROLA or (mode is Mode.INTEL and not s_r):
            phase = self.phase
            if phase is Phase.DATA:
                command = self.command
                if command is not None and command.rd and _READS_REGISTER[command.address]:
                    tx = self.registers.cpu_read(command.address)
                else:
                    tx = self.last_rx
                    if command is not None and command.rd:
                        self._ignored(command.address, AccessDirection.READ, tx)
            elif phase is Phase.BLOCK:
                slot = self._slots[0]
                tx = self.registers.cpu_read(slot.address) if slot.read else self.last_rx
            elif phase is not Phase.DISABLED:
                tx = self.last_rx
        self._frame = (s_r, tx)
        return tx

    def end(self, rx: int) -> None:
        """/SS rose after 8 bits: process the received byte ``rx`` (in Intel receive frames the byte on the
        line is the chip's own, so ``rx`` equals what :meth:`begin` returned)."""
        if type(rx) is not int or not 0 <= rx <= 0xFF:
            rx = _checked(check_bits, "rx", rx, 8, "the received byte")
        frame = self._frame
        if frame is None:
            raise UpifUsageError("end() or abort() without begin()")
        self._frame = None
        phase = self.phase
        if phase is Phase.DATA:
            self._end_data(rx, frame[0])
        elif phase is Phase.COMMAND:
            self._end_command(rx, frame)
        elif phase is Phase.BLOCK:
            self._end_block(rx, frame[0])
        elif phase is Phase.INIT:
            self._end_init(rx)
        else:
            return  # DISABLED: data transmission is disabled until power-up reset or SAS_INIT (3.4.3)
        self.last_rx = rx

    def abort(self, bits: int) -> None:
        """/SS rose after ``bits`` != 8 SCLK edges: the frame is dropped, the protocol state is unchanged."""
        bits = _checked(check_int, "bits", bits, 0, limit="SCLK rising edges in the frame")
        if bits == 8:
            raise UpifArgumentError("bits", bits, "bits must be the SCLK edge count of an incomplete frame, not 8: a "
                                    "complete byte ends with end() (3.4.2)")
        if self._frame is None:
            raise UpifUsageError("end() or abort() without begin()")
        self._frame = None
        detail = "/SS held low across bytes" if bits > 8 else "incomplete byte"
        self._violation("3.4.2", f"{detail}: {bits} SCLK rising edges between /SS edges, frame ignored")

    def _violation(self, rule: str, detail: str) -> None:
        self.registers.violations.report(ProtocolViolationError(rule, detail))

    def _ignored(self, address: int, direction: AccessDirection, value: int) -> None:
        """A data access to reserved address 4 or 5, which the chip ignores (3.4.4): only pedantic mode tells."""
        if self.registers.pedantic:
            self.registers.ignored_access(address, direction, value)

    # --------------------------------------------------------------------------------------------------------
    # What a frame reads and writes
    # --------------------------------------------------------------------------------------------------------

    def _end_init(self, rx: int) -> None:
        for mode in Mode:
            if rx == mode.init_byte:
                self.mode = mode
                self.phase = Phase.COMMAND
                return
        self.phase = Phase.DISABLED

    def _end_command(self, rx: int, frame: _Frame) -> None:
        s_r, tx = frame
        if self.mode is Mode.INTEL and not s_r:
            self._violation("Table 3-9", f"Intel command byte received with S/R = 0 (the chip sent {tx:02X}h); "
                            "frame ignored")
            return
        if rx & ~COMMAND_BYTE.mask:
            self._violation("3.4.4, RM-1", f"command byte {rx:02X}h sets reserved bits; they are ignored")
        command = _COMMANDS[rx]
        self.command = command
        if command.address == BLOCK_ADDRESS:
            self._start_block(command)
        else:
            self.phase = Phase.DATA

    def _end_data(self, rx: int, s_r: bool) -> None:
        command = self.command
        self.phase = Phase.COMMAND
        if command is None:  # cannot happen: the DATA phase always has its command
            return
        address = command.address
        if not _WRITES_REGISTER[address]:
            if command.wr and (self.mode is Mode.MOTOROLA or s_r):
                self._ignored(address, AccessDirection.WRITE, rx)
            return
        if self.mode is Mode.INTEL:
            if command.rd != command.wr and command.rd == s_r:
                code = encode_command(address, rd=command.rd, wr=command.wr)
                wanted = "read" if command.rd else "write"
                self._violation("Table 3-9", f"command {code:02X}h asks for a {wanted} but S/R = {int(s_r)}; "
                                "data byte ignored")
                return
            if not s_r:
                return  # Intel frames with S/R = 0 write nothing (UP-9)
        if command.wr:  # Motorola frames (full duplex) and Intel frames with S/R = 1 write (UP-9)
            self.registers.cpu_write(address, rx)

    # --------------------------------------------------------------------------------------------------------
    # Fast paths of UpInterface: the same effects as the frames, checked against them by tests/test_spi_upif_fast.py
    # --------------------------------------------------------------------------------------------------------

    def _plain_command(self, rx: int) -> int | None:
        """A whole frame carrying command byte ``rx`` (one of :data:`_PLAIN_COMMANDS`) in the command phase,
        Motorola or Intel with S/R = 1: what :meth:`begin` and :meth:`end` do, reading no register and reporting
        nothing. Returns the byte the chip drove (the echo in Motorola mode, UP-8; nothing in Intel mode). Half of
        the bytes the C driver sends are command bytes."""
        tx = self.last_rx if self.mode is Mode.MOTOROLA else None
        self.command = _COMMANDS[rx]
        self.phase = Phase.DATA
        self.last_rx = rx
        return tx

    def _read_access(self, address: int) -> int:
        """A read command byte for ``address`` (0..14) and its data byte, given in the command phase of an
        initialized interface (Motorola: data byte 00h; Intel: S/R = 1, then 0): the effects of the four frame
        calls, without their per-byte bookkeeping, which costs three times as much (bench/bench_upif.py).
        ``tests/test_spi_upif_fast.py`` checks it against the frames for every address, mode and state. Runs
        inside a deferred block (``ViolationLog.hold``)."""
        self.command = _COMMANDS[_READ_COMMANDS[address]]
        if _READS_REGISTER[address]:
            value = self.registers.cpu_read(address)
        else:
            value = _READ_COMMANDS[address]  # the command byte is sent back (3.4.4)
            self._ignored(address, AccessDirection.READ, value)
        self.last_rx = value if self.mode is Mode.INTEL else 0
        return value

    def _write_access(self, address: int, value: int) -> None:
        """A write command byte for ``address`` (0..14) and the data byte ``value``, in the command phase of an
        initialized interface: the effects of the four frame calls (see :meth:`_read_access`)."""
        self.command = _COMMANDS[_WRITE_COMMANDS[address]]
        self.last_rx = value
        if _WRITES_REGISTER[address]:
            self.registers.cpu_write(address, value)
        else:
            self._ignored(address, AccessDirection.WRITE, value)

    def _start_block(self, command: CommandByte) -> None:
        """Address 15: lay out the block transfer's bytes (3.4.6; UP-10, UP-11)."""
        registers = self.registers
        count = registers.data_bytes()
        if not registers.internal_data_path:
            self._violation("3.4.6, 3.4.8", "block transfer with ExtReg = 1: the internal data registers are not "
                            "in the data path; no data bytes follow")
            count = 0
        elif registers.data_bits() < _WORD_BITS:
            self._violation("3.4.6", f"block transfer needs a data length >= 1 word, configured "
                            f"{registers.data_bits()} bits; {count} data byte(s) follow")
        if self.mode is Mode.MOTOROLA:
            slots = tuple(_Slot(k, True, True) for k in range(count))
        else:
            slots = tuple(_Slot(k, True, False) for k in range(count) if command.rd) + tuple(
                _Slot(k, False, True) for k in range(count) if command.wr
            )
        self._slots = slots
        self.phase = Phase.BLOCK if slots else Phase.COMMAND

    def _end_block(self, rx: int, s_r: bool) -> None:
        slot, self._slots = self._slots[0], self._slots[1:]
        if self.mode is Mode.INTEL and slot.read == s_r:
            wanted = "read" if slot.read else "write"
            self._violation("3.4.6, Table 3-9", f"block transfer byte {slot.address} is a {wanted} but "
                            f"S/R = {int(s_r)}; byte ignored")
        elif slot.write:
            self.registers.cpu_write(slot.address, rx)
        if not self._slots:
            self.phase = Phase.COMMAND


class UpInterface:
    """The serial µP interface as firmware sees it: one call per byte, plus register-level helpers.

    Parameters
    ----------
    registers:
        The chip's register file (shared with the INTERBUS core), or the transaction-level chip
        (:class:`~supi3.model.chip.Supi3`) itself, whose register file is taken; either way the chip must be strapped
        for an Init-µP mode (Tables 2-4 to 2-7).

    Notes
    -----
    Strict mode (``registers.violations.strict``) raises a violation after the register access (or byte) that
    caused it has completed; lenient mode records it in ``registers.violations.records``. Every method checks its
    arguments and the interface's state before the first byte goes out: a refused call (an
    :class:`UpifArgumentError` or :class:`UpifUsageError`) sends nothing and changes nothing. After a register
    access (:meth:`read`, :meth:`write`, :meth:`exchange`, :meth:`block_transfer`) the interface is back in the
    command phase, whether or not a violation was raised, except where the violation says otherwise (a write
    before initialization disables the interface, 3.4.3). See docs/upif.md, "Firmware API after misuse" (UP-25 to
    UP-29).
    """

    def __init__(self, registers: RegisterFile | Supi3) -> None:
        if isinstance(registers, Supi3):
            chip = registers
            if chip.registers is None:
                raise _refused("registers", chip, "the chip's strapped mode has no serial µP interface", chip.config)
            registers = chip.registers
        elif not isinstance(registers, RegisterFile):
            hint = "Supi3.registers is None outside the µP modes" if registers is None else ""
            raise _refused("registers", registers, hint)
        self.protocol = UpifProtocol(registers)

    @property
    def registers(self) -> RegisterFile:
        """The register file behind the interface."""
        return self.protocol.registers

    @property
    def c_d(self) -> int:
        """The C/D pin level: 0 = the next byte is a command (or the initialization byte), 1 = data."""
        return self.protocol.c_d

    def power_up_reset(self) -> None:
        """Hardware reset of the chip (registers and interface)."""
        self.protocol.power_up_reset()

    def sas_init(self) -> None:
        """A SAS_INIT pulse: the interface waits for an initialization byte, SET and ID are kept (3.4.3)."""
        self.protocol.sas_init()

    # --------------------------------------------------------------------------------------------------------
    # One byte
    # --------------------------------------------------------------------------------------------------------

    def transfer(self, mosi: int, *, s_r: bool | None = None) -> int | None:
        """One byte: /SS low, 8 bits, /SS high.

        Parameters
        ----------
        mosi:
            The byte the µP sends (SerIN in Motorola mode; Ser_IN/OUT in Intel mode with ``s_r=True``). In an
            Intel receive byte (``s_r=False``) the chip drives the line and ``mosi`` is not used.
        s_r:
            Intel mode: the S/R level (Table 3-9), required. Motorola mode and before initialization: ignored.

        Returns
        -------
        int | None
            The byte the chip drove (SerOUT, or Ser_IN/OUT when ``s_r`` is ``False``), ``None`` if it drove none.

        Raises
        ------
        UpifArgumentError
            If ``mosi`` is not a byte or ``s_r`` not a ``bool`` (or ``None``).
        UpifUsageError
            If ``s_r`` is missing in Intel mode, or a frame was begun on :attr:`protocol` and not ended.
        ProtocolViolationError, ReconfigurationError, InconsistentDataError, SetRegisterError
            In strict mode, after the byte was processed.
        """
        if type(mosi) is not int or not 0 <= mosi <= 0xFF:
            mosi = _checked(check_bits, "mosi", mosi, 8, "one byte per frame, 3.4.2")
        if s_r is not None and type(s_r) is not bool:
            s_r = _checked(check_bool, "s_r", s_r)
        protocol = self.protocol
        mode = protocol.mode
        if mode is Mode.INTEL and s_r is None:
            raise UpifUsageError("Intel mode: give s_r (True = the µP sends, False = it receives; Table 3-9)")
        if protocol._frame is not None:
            raise UpifUsageError("transfer() inside a frame begun on the protocol: end() or abort() it first")
        # A firmware model (the C driver through ctypes or cffi) sends every byte through here: a plain command byte
        # takes a fast path; any other byte is _byte() inside deferred(), both by hand (a with statement and a
        # call cost as much as the byte itself).
        if protocol.phase is Phase.COMMAND and _PLAIN_COMMANDS[mosi] and (s_r or mode is Mode.MOTOROLA):
            return protocol._plain_command(mosi)
        log = protocol.registers.violations
        log.hold()
        try:
            tx = protocol.begin(True if s_r is None else s_r)
            protocol.end(tx if tx is not None and mode is Mode.INTEL else mosi)
        except BaseException:
            log.release(failed=True)
            raise
        log.release()
        return tx

    def _byte(self, mosi: int, s_r: bool) -> int | None:
        """One frame, arguments and state already checked: begin, then end with what is on the data line."""
        protocol = self.protocol
        tx = protocol.begin(s_r)
        protocol.end(tx if tx is not None and protocol.mode is Mode.INTEL else mosi)
        return tx

    # --------------------------------------------------------------------------------------------------------
    # Initialization
    # --------------------------------------------------------------------------------------------------------

    def initialize(self, mode: Mode) -> bool:
        """Send the initialization byte of ``mode`` and tell whether this was a first initialization.

        A chip that was reset (power-up or SAS_INIT) shows the command status twice: C/D stays low after the
        byte (3.4.3). A chip that was already initialized took the byte as a command and shows data: a no-op
        data byte completes it (00h is command "no direction, address 0"; 81h reads OUT byte 1).

        A chip that shows data *before* the byte (C/D = 1: the µP was reset in the middle of a command or a block
        transfer) takes the initialization byte as that command's data byte, as the real chip does: this is
        reported as :class:`InterruptedCommandError` (UP-27), and the initialization is not a first one.

        Returns
        -------
        bool
            ``True`` for a first initialization, ``False`` if the chip was already initialized.

        Raises
        ------
        UpifArgumentError
            If ``mode`` is not a :class:`Mode`.
        InterfaceDisabledError
            If the interface is disabled by an earlier faulty initialization byte (needs SAS_INIT); nothing is
            sent.
        InterruptedCommandError
            In strict mode, after the byte was taken as a data byte (recorded in lenient mode).
        ModeLockedError
            In strict mode, when an initialized chip was asked for the other mode (recorded in lenient mode, UP-29).
        """
        if type(mode) is not Mode:
            mode = _checked(check_instance, "mode", mode, Mode, "Mode.MOTOROLA or Mode.INTEL (Table 3-8)")
        protocol = self.protocol
        self._check_frame("initialize")
        if protocol.phase is Phase.DISABLED:
            raise InterfaceDisabledError("initialize")
        # The bytes of initialize() are the procedure of 3.4.3; what they do to a chip that was not reset is
        # reported by UP-27 and UP-29, not as suspicious accesses of the firmware (UP-30).
        with protocol.registers.violations.deferred(), protocol.registers.pedantic_paused():
            if protocol.phase in (Phase.DATA, Phase.BLOCK):
                self._interrupted(mode)
                return False
            self._byte(mode.init_byte, True)
            if self.c_d == C_D_COMMAND:
                return True  # command status twice: a first initialization (3.4.3)
            command = protocol.command  # the byte was taken as command 00h or 81h: complete it
            self._byte(0, command is None or not command.rd)
            if protocol.mode is not mode and protocol.mode is not None:
                protocol.registers.violations.report(ModeLockedError("3.4.3", MODE_LOCKED.format(
                    wanted=f"Mode.{mode.name}", mode=protocol.mode.name.capitalize(), byte=mode.init_byte
                )))
            return False

    def _interrupted(self, mode: Mode) -> None:
        """The init byte goes to a chip that waits for a data byte (UP-27): send it as the chip takes it, report."""
        protocol = self.protocol
        command = protocol.command
        code = 0 if command is None else encode_command(command.address, rd=command.rd, wr=command.wr)
        what = ("the next byte of a block transfer" if protocol.phase is Phase.BLOCK
                else f"the data byte of command {code:02X}h")
        # Reported before the byte (the deferred block raises after it), so that in strict mode this violation,
        # not one the byte itself causes (Intel: a read command's data byte with S/R = 1, Table 3-9), is raised.
        name = _port_name(command) if command is not None and command.wr and protocol.phase is Phase.DATA else ""
        effect = f", written to {name}" if name else ""
        protocol.registers.violations.report(InterruptedCommandError(
            "3.4.3", INTERRUPTED_INIT.format(byte=mode.init_byte, what=what, effect=effect)
        ))
        self._byte(mode.init_byte, True)

    # --------------------------------------------------------------------------------------------------------
    # Register accesses
    # --------------------------------------------------------------------------------------------------------

    def _check_frame(self, what: str) -> None:
        if self.protocol.in_frame:
            raise UpifUsageError(f"{what}() inside a frame begun on the protocol: end() or abort() it first")

    def _start(self, what: str) -> None:
        """Refuse a register access the interface cannot start now; nothing has been sent."""
        protocol = self.protocol
        self._check_frame(what)
        phase = protocol.phase
        if phase is Phase.INIT and what in REFUSED_BEFORE_INIT:
            raise NotInitializedError(what)
        if phase is Phase.DISABLED:
            raise InterfaceDisabledError(what)
        if phase is not Phase.COMMAND:
            left = f", {len(protocol._slots)} block byte(s) left (3.4.6)" if phase is Phase.BLOCK else ""
            raise UpifUsageError(f"{what} needs the command phase: C/D = {self.c_d}, the chip is in phase "
                                 f"{phase}{left}; finish the command with transfer() or SAS_INIT")

    def read(self, address: int | Register) -> int:
        """Read one register: command byte with RD, then a data byte (3.4.4). Returns the data byte.

        ``address`` is a number or a register of :mod:`supi3.regmap` (``read(IRQ_EVT)``).

        Raises
        ------
        UpifArgumentError
            If ``address`` is not 0..14 (15 starts a block transfer: :meth:`block_transfer`), or a register that
            is not read there.
        NotInitializedError, InterfaceDisabledError, UpifUsageError
            If the interface cannot start a command now (nothing is sent).
        """
        if type(address) is not int or not 0 <= address < BLOCK_ADDRESS:
            known = _READ_ADDRESSES.get(id(address))
            address = known if known is not None else _register_address(address, AccessDirection.READ)
        protocol = self.protocol
        if protocol.phase is not Phase.COMMAND or protocol._frame is not None:
            self._start("read")
        log = protocol.registers.violations
        log.hold()  # deferred() by hand, as in transfer()
        try:
            value = protocol._read_access(address)
        except BaseException:
            log.release(failed=True)
            raise
        log.release()
        return value

    def write(self, address: int | Register, value: int) -> None:
        """Write one register: command byte with WR, then the data byte (3.4.4). ``address`` is a number or a
        register of :mod:`supi3.regmap` (``write(SET, 0x82)``).

        Before :meth:`initialize` the chip takes the command byte as a faulty initialization byte and disables the
        interface (3.4.3): the bytes go out as on the real chip and :class:`UninitializedAccessError` is reported
        (raised in strict mode, recorded in lenient mode); the interface then needs SAS_INIT (UP-26).

        Raises
        ------
        UpifArgumentError
            If ``address`` is not 0..14 or a register that is not written there, or ``value`` not a byte.
        InterfaceDisabledError, UpifUsageError
            If the interface cannot start a command now (nothing is sent).
        """
        if type(address) is not int or not 0 <= address < BLOCK_ADDRESS:
            known = _WRITE_ADDRESSES.get(id(address))
            address = known if known is not None else _register_address(address, AccessDirection.WRITE)
        if type(value) is not int or not 0 <= value <= 0xFF:
            value = _checked(check_bits, "value", value, 8, "a data byte, 3.4.4")
        protocol = self.protocol
        if protocol.phase is not Phase.COMMAND or protocol._frame is not None:
            if protocol.phase is Phase.INIT and protocol._frame is None:
                self._write_uninitialized(_WRITE_COMMANDS[address], value)
                return
            self._start("write")
        log = protocol.registers.violations
        log.hold()  # deferred() by hand, as in transfer()
        try:
            protocol._write_access(address, value)
        except BaseException:
            log.release(failed=True)
            raise
        log.release()

    def _write_uninitialized(self, command: int, value: int) -> None:
        violations = self.protocol.registers.violations
        with violations.deferred():
            self._byte(command, True)
            self._byte(value, True)
            violations.report(UninitializedAccessError("3.4.3", UNINITIALIZED_WRITE.format(command=command)))

    def exchange(self, address: int | Register, value: int) -> int:
        """Motorola only: read and write ``address`` in one data byte (RD and WR set, 3.4.4).

        Raises
        ------
        UpifArgumentError
            If ``address`` is not 0..14 or ``value`` not a byte.
        NotInitializedError, InterfaceDisabledError, UpifUsageError
            If the interface cannot start a command now, or is in Intel mode (nothing is sent).
        """
        address = _register_address(address)
        value = _checked(check_bits, "value", value, 8, "a data byte, 3.4.4")
        self._start("exchange")
        if self.protocol.mode is not Mode.MOTOROLA:
            raise UpifUsageError("simultaneous read and write needs Motorola mode (3.4.4)")
        with self.registers.violations.deferred():
            self._byte(encode_command(address, rd=True, wr=True), True)
            result = self._byte(value, True)
        if result is None:  # cannot happen: SerOUT drives in every Motorola frame
            raise UpifUsageError(f"exchange({address}): the chip drove no data byte")
        return result

    def block_transfer(self, in_data: bytes, *, read: bool = True, write: bool = True) -> bytes:
        """A block transfer (3.4.6): one command byte with address 15, then the data bytes.

        Parameters
        ----------
        in_data:
            The IN bytes to write, byte 0 first; its length must be the chip's block length: the configured data
            length in bytes, 0 with ExtReg = 1 (UP-10).
        read, write:
            Intel mode only: the RD and WR bits of the command byte, i.e. whether the read phase (OUT bytes) and
            the write phase (IN bytes, ``in_data``) take place (UP-11). Motorola mode exchanges both whatever
            they say, with command CFh.

        Returns
        -------
        bytes
            The OUT bytes read (empty if ``read`` is ``False`` in Intel mode).

        Raises
        ------
        UpifArgumentError
            If ``in_data`` is not bytes of the chip's block length, or ``read``/``write`` not ``bool``.
        NotInitializedError, InterfaceDisabledError, UpifUsageError
            If the interface cannot start a command now (nothing is sent).
        ProtocolViolationError
            In strict mode, after the whole block, for a data length below one word or ExtReg = 1 (3.4.6).
        """
        data = _checked(check_bytes, "in_data", in_data)
        rd = _checked(check_bool, "read", read)
        wr = _checked(check_bool, "write", write)
        self._start("block transfer")
        registers = self.registers
        count = registers.data_bytes() if registers.internal_data_path else 0
        if len(data) != count:
            raise UpifArgumentError("in_data", in_data, f"in_data must be {count} byte{'s' if count != 1 else ''}, "
                                    f"the block length (the configured data length, 3.4.6), not {describe(in_data)}: "
                                    f"a block transfer of {len(data)} bytes did not end the block; nothing sent")
        intel = self.protocol.mode is Mode.INTEL
        if not intel:
            rd = wr = True
        out = bytearray()
        with registers.violations.deferred():
            self._byte(encode_command(BLOCK_ADDRESS, rd=rd, wr=wr), True)
            if intel:
                out.extend(self._byte(0, False) or 0 for _ in range(count if rd else 0))
                for value in data if wr else b"":
                    self._byte(value, True)
            else:
                out.extend(self._byte(value, True) or 0 for value in data)
        return bytes(out)


class UpifArgumentError(ArgumentError, UpifUsageError):
    """An argument of :class:`UpInterface` or :class:`UpifProtocol` of the wrong type or out of its range ("X must
    be ..., not ..."): an :class:`~supi3.errors.ArgumentError` that code catching :class:`UpifUsageError` still
    catches. Nothing was sent."""


class NotInitializedError(UpifUsageError):
    """A register access before :meth:`UpInterface.initialize` that the API refuses (nothing sent): it would
    return data, and the chip drives none before its initialization byte (3.4.1, 3.4.3; UP-25)."""

    def __init__(self, what: str) -> None:
        self.what = what
        super().__init__(f"{what}: interface not initialized; call initialize(Mode.MOTOROLA or Mode.INTEL) first "
                         "(3.4.3: the chip expects its initialization byte before any other access); nothing sent")

    def __reduce__(self) -> tuple[object, ...]:
        return (type(self), (self.what,))


class InterfaceDisabledError(UpifUsageError):
    """A call to an interface disabled by a faulty initialization byte (3.4.3): nothing was sent."""

    def __init__(self, what: str) -> None:
        self.what = what
        super().__init__(f"{what}: the interface is disabled by a faulty initialization byte: SAS_INIT it (or "
                         "power-up reset), then initialize() (3.4.3); nothing sent")

    def __reduce__(self) -> tuple[object, ...]:
        return (type(self), (self.what,))


class UninitializedAccessError(ProtocolViolationError):
    """:meth:`UpInterface.write` before initialization: its command byte was taken as a faulty initialization
    byte and the interface disabled itself (3.4.3; UP-26)."""


class InterruptedCommandError(ProtocolViolationError):
    """:meth:`UpInterface.initialize` on a chip that waited for a data byte (the µP was reset in the middle of a
    command): the initialization byte was taken as that data byte (3.4.3; UP-27)."""


class ModeLockedError(ProtocolViolationError):
    """:meth:`UpInterface.initialize` asked for the other mode on an initialized chip, whose mode only a power-up
    reset or SAS_INIT changes (3.4.3; UP-29)."""


_READ_COMMANDS: Final[tuple[int, ...]] = tuple(encode_command(a, rd=True) for a in range(BLOCK_ADDRESS))
_WRITE_COMMANDS: Final[tuple[int, ...]] = tuple(encode_command(a, wr=True) for a in range(BLOCK_ADDRESS))
_PORT_REGISTERS: Final[dict[AccessDirection, tuple[Register | None, ...]]] = {
    direction: tuple(REGISTER_MAP.port(a, direction).register for a in range(BLOCK_ADDRESS))
    for direction in AccessDirection
}
"""The register each single access reaches, per direction and address 0..14 (Table 3-10): ``read(IN0)`` checks its
register by identity here, without hashing the register's layout."""
_READ_ADDRESSES: Final[dict[int, int]] = {id(r): r.address for r in _PORT_REGISTERS[AccessDirection.READ] if r}
"""The address of each register a read reaches, by the register's identity: ``read(OUT0)`` in one look-up (the
registers of :mod:`supi3.regmap` live as long as the program; any other object goes to :func:`_register_address`)."""
_WRITE_ADDRESSES: Final[dict[int, int]] = {id(r): r.address for r in _PORT_REGISTERS[AccessDirection.WRITE] if r}
"""As :data:`_READ_ADDRESSES`, for writes: ``write(IN0, ...)``."""


def _checked(check: Callable[..., _T], *args: object, **kwargs: object) -> _T:
    """Run a :mod:`supi3.checks` check; its error comes out as an :class:`UpifArgumentError`. Hot paths call this
    only after a cheap inline test failed."""
    try:
        return check(*args, **kwargs)
    except ArgumentError as error:
        raise UpifArgumentError(error.name, error.value, str(error)) from None


def _register_address(address: object, direction: AccessDirection | None = None) -> int:
    """``address`` checked as the address of one register access: 0..14 (15 starts a block transfer), or a
    :class:`~supi3.regmap.Register` that ``direction`` (``None``: either) reaches at its address."""
    if isinstance(address, Register):
        number = address.address
        for reached in (direction,) if direction is not None else tuple(AccessDirection):
            if number < BLOCK_ADDRESS and _PORT_REGISTERS[reached][number] is address:
                return number
        verb = "reached" if direction is None else "written" if direction is AccessDirection.WRITE else "read"
        raise UpifArgumentError("address", address, f"address: {address.name} is not {verb} at address "
                                f"{address.address} (Table 3-10)")
    return _checked(check_int, "address", address, 0, BLOCK_ADDRESS - 1,
                    "A3..0, 3.4.4; 15 starts a block transfer: use block_transfer(), 3.4.6")


def _refused(name: str, value: object, hint: str, config: DeviceConfig | None = None) -> UpifArgumentError:
    wanted = "the RegisterFile (or Supi3) of a chip strapped for an Init-µP mode (Tables 2-4 to 2-7)"
    shown = describe(value) if config is None else f"a Supi3 in mode {config.function!r} (Table {config.table})"
    return UpifArgumentError(name, value, f"{name} must be {wanted}, not {shown}{': ' + hint if hint else ''}")


def _port_name(command: CommandByte | None) -> str:
    """The register a command's write goes to, or ``""``."""
    if command is None:
        return ""
    register = REGISTER_MAP.port(command.address, AccessDirection.WRITE).register
    return "" if register is None else register.name

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

from dataclasses import dataclass
from enum import StrEnum
from typing import Final

from supi3.errors import Supi3Error
from supi3.model.registers import InterfaceViolationError, RegisterFile
from supi3.regmap import (
    COMMAND_BYTE,
    INIT_BYTE,
    REGISTER_MAP,
    Access,
    Command,
    Direction,
    decode_command,
    encode_command,
)

__all__ = [
    "C_D_COMMAND",
    "C_D_DATA",
    "Mode",
    "Phase",
    "ProtocolViolationError",
    "UpInterface",
    "UpifProtocol",
    "UpifUsageError",
]

C_D_COMMAND: Final[int] = 0
"""C/D (MFP2) level while the next byte is an initialization or command byte, in both modes (UP-2)."""
C_D_DATA: Final[int] = 1
"""C/D level while the next byte is a data byte, and while data transmission is disabled (UP-4)."""

BLOCK_ADDRESS: Final[int] = 15
"""A3..0 of the command byte that starts a block transfer (3.4.6)."""
_WORD_BITS: Final[int] = 16


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


@dataclass(frozen=True)
class _Frame:
    """What :meth:`UpifProtocol.begin` decided for the current byte."""

    s_r: bool
    tx: int | None


class UpifProtocol:
    """The protocol state machine of the serial µP interface, shared by the byte- and the pin-level model.

    Parameters
    ----------
    registers:
        The chip's register file; the protocol reads and writes it one data byte at a time.
    """

    def __init__(self, registers: RegisterFile) -> None:
        self.registers = registers
        self.mode: Mode | None = None
        self.phase = Phase.INIT
        self.command: Command | None = None
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
        return C_D_COMMAND if self.phase in (Phase.INIT, Phase.COMMAND) else C_D_DATA

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
        if self._frame is not None:
            raise UpifUsageError("begin() inside a frame: call end() or abort() first")
        tx: int | None = None
        drives = self.mode is Mode.MOTOROLA or (self.mode is Mode.INTEL and not s_r)
        if drives and self.phase is not Phase.DISABLED:
            address = self._read_address()
            tx = self.registers.cpu_read(address) if address is not None else self.last_rx
        self._frame = _Frame(s_r, tx)
        return tx

    def end(self, rx: int) -> None:
        """/SS rose after 8 bits: process the received byte ``rx`` (in Intel receive frames the byte on the
        line is the chip's own, so ``rx`` equals what :meth:`begin` returned)."""
        frame = self._take_frame()
        if not 0 <= rx <= 0xFF:
            raise UpifUsageError(f"received byte must be 0..255, not {rx!r}")
        if self.phase is Phase.DISABLED:
            return  # data transmission is disabled until power-up reset or SAS_INIT (3.4.3)
        if self.phase is Phase.INIT:
            self._end_init(rx)
        elif self.phase is Phase.COMMAND:
            self._end_command(rx, frame)
        elif self.phase is Phase.DATA:
            self._end_data(rx, frame)
        else:
            self._end_block(rx, frame)
        self.last_rx = rx

    def abort(self, bits: int) -> None:
        """/SS rose after ``bits`` != 8 SCLK edges: the frame is dropped, the protocol state is unchanged."""
        self._take_frame()
        detail = "/SS held low across bytes" if bits > 8 else "incomplete byte"
        self._violation("3.4.2", f"{detail}: {bits} SCLK rising edges between /SS edges, frame ignored")

    def _take_frame(self) -> _Frame:
        if self._frame is None:
            raise UpifUsageError("end() or abort() without begin()")
        frame, self._frame = self._frame, None
        return frame

    def _violation(self, rule: str, detail: str) -> None:
        self.registers.violations.report(ProtocolViolationError(rule, detail))

    # --------------------------------------------------------------------------------------------------------
    # What a frame reads and writes
    # --------------------------------------------------------------------------------------------------------

    def _read_address(self) -> int | None:
        """The register address a frame in which the chip drives reads, or ``None`` (echo). The chip drives in
        every Motorola frame and in Intel frames with S/R = 0, which are read frames (Table 3-9)."""
        if self.phase is Phase.BLOCK:
            slot = self._slots[0]
            return slot.address if slot.read else None
        if self.phase is Phase.DATA:
            assert self.command is not None
            port = REGISTER_MAP.port(self.command.address, Direction.READ)
            if self.command.rd and port.access is not Access.RESERVED_IGNORED:
                return self.command.address
        return None

    def _writes(self, s_r: bool) -> bool:
        """Whether a frame can write: every Motorola frame (full duplex), Intel frames with S/R = 1 (UP-9)."""
        return self.mode is Mode.MOTOROLA or s_r

    def _end_init(self, rx: int) -> None:
        for mode in Mode:
            if rx == mode.init_byte:
                self.mode = mode
                self.phase = Phase.COMMAND
                return
        self.phase = Phase.DISABLED

    def _end_command(self, rx: int, frame: _Frame) -> None:
        if self.mode is Mode.INTEL and not frame.s_r:
            self._violation("Table 3-9", f"Intel command byte received with S/R = 0 (the chip sent {frame.tx:02X}h); "
                            "frame ignored")
            return
        if rx & ~COMMAND_BYTE.mask:
            self._violation("3.4.4, RM-1", f"command byte {rx:02X}h sets reserved bits; they are ignored")
        command = decode_command(rx & COMMAND_BYTE.mask)
        self.command = command
        if command.block_transfer:
            self._start_block(command)
        else:
            self.phase = Phase.DATA

    def _end_data(self, rx: int, frame: _Frame) -> None:
        command = self.command
        assert command is not None
        port = REGISTER_MAP.port(command.address, Direction.WRITE)
        self.phase = Phase.COMMAND
        if port.access is Access.RESERVED_IGNORED:
            return
        if self.mode is Mode.INTEL and command.rd != command.wr and command.rd == frame.s_r:
            code = encode_command(command.address, rd=command.rd, wr=command.wr)
            wanted = "read" if command.rd else "write"
            self._violation("Table 3-9", f"command {code:02X}h asks for a {wanted} but S/R = {int(frame.s_r)}; "
                            "data byte ignored")
            return
        if command.wr and self._writes(frame.s_r):
            self.registers.cpu_write(command.address, rx)

    def _start_block(self, command: Command) -> None:
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

    def _end_block(self, rx: int, frame: _Frame) -> None:
        slot, self._slots = self._slots[0], self._slots[1:]
        if self.mode is Mode.INTEL and slot.read == frame.s_r:
            wanted = "read" if slot.read else "write"
            self._violation("3.4.6, Table 3-9", f"block transfer byte {slot.address} is a {wanted} but "
                            f"S/R = {int(frame.s_r)}; byte ignored")
        elif slot.write:
            self.registers.cpu_write(slot.address, rx)
        if not self._slots:
            self.phase = Phase.COMMAND


class UpInterface:
    """The serial µP interface as firmware sees it: one call per byte, plus register-level helpers.

    Parameters
    ----------
    registers:
        The chip's register file (shared with the INTERBUS core).

    Notes
    -----
    Strict mode (``registers.violations.strict``) raises a violation after the byte that caused it has been
    processed; lenient mode records it in ``registers.violations.records``.
    """

    def __init__(self, registers: RegisterFile) -> None:
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
        UpifUsageError
            If ``mosi`` is not a byte, or ``s_r`` is missing in Intel mode.
        ProtocolViolationError, ReconfigurationError, InconsistentDataError, SetRegisterError
            In strict mode, after the byte was processed.
        """
        if isinstance(mosi, bool) or not isinstance(mosi, int) or not 0 <= mosi <= 0xFF:
            raise UpifUsageError(f"mosi must be a byte 0..255, not {mosi!r}")
        if self.protocol.mode is Mode.INTEL and s_r is None:
            raise UpifUsageError("Intel mode: give s_r (True = the µP sends, False = it receives; Table 3-9)")
        with self.registers.violations.deferred():
            tx = self.protocol.begin(bool(s_r) if s_r is not None else True)
            line = tx if self.protocol.mode is Mode.INTEL and tx is not None else mosi
            self.protocol.end(line)
        return tx

    def _send(self, byte: int) -> int | None:
        return self.transfer(byte, s_r=True)

    def initialize(self, mode: Mode) -> bool:
        """Send the initialization byte of ``mode`` and tell whether this was a first initialization.

        A chip that was reset (power-up or SAS_INIT) shows the command status twice: C/D stays low after the
        byte (3.4.3). A chip that was already initialized took the byte as a command and shows data: a no-op
        data byte completes it (00h is command "no direction, address 0"; 81h reads OUT byte 1).

        Returns
        -------
        bool
            ``True`` for a first initialization, ``False`` if the chip was already initialized.

        Raises
        ------
        UpifUsageError
            If the interface is disabled by an earlier faulty initialization byte (needs SAS_INIT).
        """
        self._send(mode.init_byte)
        if self.c_d == C_D_COMMAND:
            return True
        if self.protocol.phase is Phase.DATA:
            assert self.protocol.command is not None
            self.transfer(0, s_r=not self.protocol.command.rd)
            return False
        raise UpifUsageError("the interface is disabled by a faulty initialization byte: SAS_INIT it (3.4.3)")

    def _expect(self, c_d: int, what: str) -> None:
        if self.c_d != c_d:
            raise UpifUsageError(f"{what}: C/D = {self.c_d}, the chip is in phase {self.protocol.phase}")

    def read(self, address: int) -> int:
        """Read one register: command byte with RD, then a data byte (3.4.4). Returns the data byte."""
        self._expect(C_D_COMMAND, "read needs the command phase")
        self._send(encode_command(address, rd=True))
        value = self.transfer(0, s_r=False)
        assert value is not None  # a data byte after a command always drives in Motorola and Intel receive
        return value

    def write(self, address: int, value: int) -> None:
        """Write one register: command byte with WR, then the data byte (3.4.4)."""
        self._expect(C_D_COMMAND, "write needs the command phase")
        self._send(encode_command(address, wr=True))
        self._send(value)

    def exchange(self, address: int, value: int) -> int:
        """Motorola only: read and write ``address`` in one data byte (RD and WR set, 3.4.4)."""
        if self.protocol.mode is not Mode.MOTOROLA:
            raise UpifUsageError("simultaneous read and write needs Motorola mode (3.4.4)")
        self._expect(C_D_COMMAND, "exchange needs the command phase")
        self._send(encode_command(address, rd=True, wr=True))
        result = self._send(value)
        assert result is not None
        return result

    def block_transfer(self, in_data: bytes, *, read: bool = True, write: bool = True) -> bytes:
        """A block transfer (3.4.6): one command byte with address 15, then the data bytes.

        Parameters
        ----------
        in_data:
            The IN bytes to write, byte 0 first; its length is the configured data length in bytes.
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
        UpifUsageError
            If the chip's block length differs from ``len(in_data)`` (C/D does not show a command afterwards).
        """
        self._expect(C_D_COMMAND, "block transfer needs the command phase")
        intel = self.protocol.mode is Mode.INTEL
        rd, wr = (read, write) if intel else (True, True)
        self._send(encode_command(BLOCK_ADDRESS, rd=rd, wr=wr))
        out = bytearray()
        if intel:
            out.extend(self._byte(0, s_r=False) for _ in in_data if rd)
            for value in in_data if wr else b"":
                self.transfer(value, s_r=True)
        else:
            out.extend(self._byte(value, s_r=True) for value in in_data)
        self._expect(C_D_COMMAND, f"block transfer of {len(in_data)} bytes did not end the block")
        return bytes(out)

    def _byte(self, value: int, *, s_r: bool) -> int:
        self._expect(C_D_DATA, "block transfer ended early")
        result = self.transfer(value, s_r=s_r)
        assert result is not None
        return result

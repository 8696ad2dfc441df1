"""The board's per-frame fast path in native code (MCU-51): plain µP interface frames without a Python call.

Ref: IBS SUPI 3 OPC UM E rev. 05, 3.4.2 (one /SS frame per byte), 3.4.4 (command and data bytes), Table 3-7 (t0, t1,
t2, t8), Table 3-10 (the registers); decisions MCU-51 to MCU-53 in docs/assumptions/mcu.md.

hook.c's ``supi3_port_write`` is GPIOA's, SPI1's and EXTI's write callback. It takes a /SS edge (a BSRR or BRR write
that changes only /SS) or SPI1's DR write that clocks the frame's byte itself when the frame's whole effect on the
Python model is plain, and EXTI's PR write (MCU-68), and calls the Python write (the existing board code, the one slow
path) for everything else; ``supi3_port_read`` answers GPIOA's IDR and ODR reads (MCU-66) and sends every other read
on to the held register's read (MCU-25) and Python:

- a command frame in the command phase with a plain command byte (``upif._PLAIN_COMMANDS``), or the data frame of a
  read of a register without side effects (a data register outside the latch phase) or of IRQ_EVT (read-clear: the
  read noted for the catch-up, /IRQ's rise followed unless it would set EXTI's pending bit, MCU-67) or of a write of
  a register that only stores (not SET or ID, not the read-clear event register /IRQ follows; a data register outside
  the latch phase), in Motorola mode, with a register file that is not pedantic, at transaction level;
- with every Table 3-7 check of the board passing (t8, t1, t2, t0, SPI mode 3, MSB first), by the board's thresholds
  in core cycles, and no bus event due up to the edge (:func:`first_due`: the first core cycle whose
  ``Board._sync`` would run one, by the same float expression), /IRQ and /ModAck followed, nothing else pending;
- MCU-84: an /SS edge with a bus event due at or before it has Python run the bus up to the edge and mirror the model
  again (:meth:`NativeFrames._bus_due`, what ``Board._on_output`` does before the edge), then hook.c takes the edge
  if it is plain by the new mirror.

Python hands the native side its tables once (:meth:`NativeFrames.__init__`), mirrors the state those conditions read
after each of its accesses of GPIOA, SPI1 or EXTI (:meth:`NativeFrames.refresh`: ``valid``; the peripherals'
configuration and the register values only when what they are made of changed, MCU-78), and at each entry into
Python (:attr:`supi3.mcu.core.CortexM.entry`: a peripheral's callback, a watched address, the end of a run) takes the
mirror's validity back and sets what the native frames changed, as its net effect, in the Python objects
(:meth:`NativeFrames.catch_up`): the protocol's phase, command and last byte, the written registers, the board's
frame, /SS rise and C/D, /IRQ's level, GPIOA's ODR, EXTI's PR, SPI1's transfer and received byte, IRQ_EVT's reads
(the register file's own ``cpu_read``), and the bus clock.
"""

from __future__ import annotations

import ctypes
import math
import operator
import struct
from dataclasses import dataclass
from typing import TYPE_CHECKING, Final, Protocol

from supi3.checks import check_bool
from supi3.interbus import wire
from supi3.mcu.core import IDLE_LOOP, HeldRegister
from supi3.mcu.hook import BUS_DUE, Frames, NativeHookError
from supi3.mcu.stm32 import (
    CR1_CPHA,
    CR1_CPOL,
    CR1_DFF,
    CR1_LSBFIRST,
    CR1_MSTR,
    CR1_SPE,
    EXTI_PR,
    IOPAEN,
    SPI1EN,
    SPI_DR,
    SPI_SR,
    SR_BSY,
    SR_MODF,
    SR_RXNE,
    SR_TXE,
)
from supi3.model import registers as _registers
from supi3.pinout import C_D_COMMAND, C_D_DATA
from supi3.regmap.registers import IO_ACCESS_BIT
from supi3.spi import upif as _upif
from supi3.spi.upif import Mode, Phase

if TYPE_CHECKING:
    from supi3.mcu.core import CortexM
    from supi3.mcu.stm32 import Exti, Gpio, Rcc, Spi
    from supi3.model.chip import Supi3
    from supi3.model.registers import RegisterFile
    from supi3.spi.upif import UpifProtocol

__all__ = ["FAST_READS", "FAST_WRITES", "IRQ_ADDRESS", "FrameBoard", "NativeFrames", "SsFrame", "first_due"]

@dataclass(slots=True)
class SsFrame:
    """A /SS frame the board has seen begin (3.4.2): the cycle /SS fell, what the chip drives on SerOUT (UP-18) and
    the bytes clocked in it, each (the byte as the chip sees it, bits, start cycle, SCLK period in cycles)."""

    fall: int
    driven: int | None
    transfers: list[tuple[int, int, int, int]]


class FrameBench(Protocol):
    """What the native frames read of the board's bench (``supi3.mcu.board._BoardBench``)."""

    low_at: float | None
    _events: list[tuple[float, str]]
    _next_start: float
    cycles: int
    _hold: float

    @property
    def chip(self) -> Supi3: ...


class FrameBoard(Protocol):
    """What the native frames read and set of the transaction-level board (:class:`supi3.mcu.board.Board`): its
    parts, its frame and /SS bookkeeping, /IRQ and /ModAck as it last followed them, its Table 3-7 thresholds in
    core cycles and its bus clock."""

    core: CortexM
    gpio: Gpio
    spi: Spi
    rcc: Rcc
    protocol: UpifProtocol
    registers: RegisterFile
    _frame: SsFrame | None
    _ss_rise: int
    _cd_before: int
    _irq_level: int
    _irq_fell: int | None
    _bounds: int
    _mod_ack_until: int
    _least_t1: int
    _least_t2: int
    _least_t8: int
    _least: dict[str, int]
    _shortest_period_s: float
    exti: Exti

    def _sync(self, cycles: int) -> None: ...

    def _chained(self, chains: int, latency: int, fell: int | None, returned: bool) -> None: ...

    def _deadline_of(self, at: float, wait_s: float) -> int: ...

    def _bus_ran(self, at: float) -> None: ...

    @property
    def bench(self) -> FrameBench: ...


_IO: Final[str] = "io"
_LATCH: Final[str] = "latch"
"""The bench's phase events (``Bench._step_bus``; ``supi3.mcu.board.FLAG_EVENTS``): the I/O access bit set, the latch
phase begun; they set flags of the chips only."""
_NEVER: Final[int] = (1 << 63) - 1
_TOP: Final[float] = wire.MAX_BUS_TIME_S
"""The latest bus time the bench takes (A26): :func:`first_due`'s bound."""
_PHASE_COMMAND: Final[int] = 1
_PHASE_DATA: Final[int] = 2
_PHASES: Final[dict[Phase, int]] = {Phase.COMMAND: _PHASE_COMMAND, Phase.DATA: _PHASE_DATA}
"""The protocol phases the native frames run in, by the number hook.c knows them by (0: any other)."""
_PHASE_NUMBERS: Final[dict[Phase, int]] = {phase: _PHASES.get(phase, 0) for phase in Phase}
"""Every phase's number (MCU-65: a subscript, not a Python call)."""
_PHASE_OF: Final[dict[int, Phase]] = {number: phase for phase, number in _PHASES.items()}
_NO_COMMAND: Final[int] = 0x100
"""The protocol has no command (hook.c reads the command only in the data phase, which always has one)."""
_CODES: Final[dict[object, int]] = {}
for _byte in range(255, -1, -1):  # each decoded command by its lowest byte
    _CODES[_upif._COMMANDS[_byte]] = _byte
_CODES_BY_ID: Final[dict[int, int]] = {id(command): code for command, code in _CODES.items()}
"""MCU-65: :data:`_CODES` by the identity of ``upif._COMMANDS``'s objects (which the table keeps alive), without a
``CommandByte``'s hash (a Python call); an equal command of another identity is looked up by value."""

_EVENT_REGISTERS: Final[frozenset[str]] = frozenset(
    name for name, clears in zip(_registers._READ_NAMES, _registers._READ_CLEARS, strict=True) if name and clears
)
"""The read-clear registers (IRQ_EVT, 3.4.14): /IRQ follows them, so no native frame writes them; a native frame
reads one only by hook.c's ``read_clear`` (MCU-67), not as a fast read."""
_IRQ_ADDRESSES: Final[tuple[int, ...]] = tuple(address for address, name in enumerate(_registers._READ_NAMES)
                                               if name in _EVENT_REGISTERS)  # fmt: skip
if len(_IRQ_ADDRESSES) != 1:  # RegisterFile.irq_n follows the one event register
    raise NativeHookError(f"the register map has {len(_IRQ_ADDRESSES)} read-clear registers, MCU-67 knows one")
IRQ_ADDRESS: Final[int] = _IRQ_ADDRESSES[0]
"""MCU-67: the address of the read-clear register /IRQ follows (IRQ_EVT, 3.4.14), whose reads hook.c takes."""
_MOTOROLA: Final[Mode] = Mode.MOTOROLA
"""MCU-78: the wiring the native frames run in (an enum member's class attribute is a slow look-up)."""


def _access(name: str | None, side_effects: frozenset[str]) -> int:
    if name is None or name in side_effects:
        return 0
    return 2 if name in _registers._DATA_REGISTERS else 1


FAST_READS: Final[tuple[int, ...]] = tuple(_access(name, _EVENT_REGISTERS) for name in _registers._READ_NAMES)
"""Per address, a read data frame a native frame may take: 0 never (no register, or read-clear), 1 always, 2 outside
the latch phase (a data register, 3.4.14: inside it the read reports inconsistent data)."""
FAST_WRITES: Final[tuple[int, ...]] = tuple(_access(name, _EVENT_REGISTERS | _registers._CONFIGURATION)
                                            for name in _registers._WRITE_NAMES)  # fmt: skip
"""Per address, a write data frame a native frame may take (0, 1, 2 as :data:`FAST_READS`): never SET or ID (they
configure the chip, 3.4.3), nor an address without a register (pedantic mode may report it: left to Python)."""
if any(fast and name in _registers._READ_NAMES
       for fast, name in zip(FAST_WRITES, _registers._WRITE_NAMES, strict=True)):  # fmt: skip
    # MCU-78: then a native write changes Frames.values, which the values' memo of NativeFrames.refresh does not know
    raise NativeHookError("a register a native frame writes is readable: MCU-78's values memo knows none")

_STATE_FIELDS: Final[tuple[str, ...]] = (
    "pending", "odr", "synced", "phase", "command", "last_rx", "frame_open", "frame_fall", "frame_driven", "transfer",
    "transfer_seen", "transfer_start", "transfer_period", "ss_rise", "cd_before", "irq_level", "written", "cleared",
    "cleared_at", "exti_pr", "dr_writes", "rx_last", "shift_received", "shift_start", "shift_end")  # fmt: skip
"""The fields of :class:`~supi3.mcu.hook.Frames` the native frames change, in their order there."""
_CONFIG_FIELDS: Final[tuple[str, ...]] = (
    "gpio_ok", "gpio_mask", "gpio_pulled_up", "spi_ok", "period", "sr_modf", "exti_rise")
"""MCU-78: the fields :meth:`NativeFrames.refresh` writes only when the peripherals' configuration they are computed
from changed (:meth:`NativeFrames._configuration`), in their order there."""
_MIRROR_FIELDS: Final[tuple[str, ...]] = (
    "valid", "due", "latch", "latch_at", "gpio_levels", "io", "io_at", *_STATE_FIELDS[:-3])  # fmt: skip
"""The fields :meth:`NativeFrames.refresh` writes at each call, in their order there."""
_CHAIN_FIELDS: Final[tuple[str, ...]] = (
    "chain_leave", "chain_pending", "exti_imr", "irq_fell", "chain_vector", "thread_deadline")
"""MCU-86: the fields :meth:`NativeFrames.refresh` writes for hook.c's returns of EXTI0, in their order there."""


def _packed(names: tuple[str, ...]) -> tuple[struct.Struct, int]:
    """A ``struct.Struct`` of :class:`~supi3.mcu.hook.Frames`'s fields ``names`` (8-byte integers one after the
    other, which hook.check_layout holds to hook.c's) and its offset: one call reads or writes them all."""
    start = at = getattr(Frames, names[0]).offset
    layout = "<"
    for name in names:
        field = getattr(Frames, name)
        if field.offset != at or field.size != 8:
            raise NativeHookError(f"Frames.{name} is not an 8-byte field at offset {at}")
        layout += "q" if name in ("ss_rise", "irq_fell") else "Q"
        at += 8
    return struct.Struct(layout), start


_STATE, _STATE_AT = _packed(_STATE_FIELDS)
_MIRROR, _MIRROR_AT = _packed(_MIRROR_FIELDS)
_CONFIG, _CONFIG_AT = _packed(_CONFIG_FIELDS)
_CHAIN, _CHAIN_AT = _packed(_CHAIN_FIELDS)
_BUS_STATE, _BUS_STATE_AT = _packed(("irq_level", "written", "cleared", "cleared_at", "exti_pr"))
"""MCU-88: the native state the bus run reads (``NativeFrames._bus_half``)."""
_BUS_MIRROR, _BUS_MIRROR_AT = _packed(("valid", "due", "latch", "latch_at"))
"""MCU-88: the mirror's fields before GPIOA's levels that a bus run changes (``NativeFrames._bus_refresh``)."""


def first_due(next_at: float, cpu_hz: float, noise: float) -> int:
    """The first core cycle ``c`` at which ``Board._sync(c)`` would run a bus event, by its own float expression
    (``Bench.advance((c + noise) / cpu_hz)`` runs the events at or before that time), or past which it would refuse the
    time (:data:`~supi3.interbus.wire.MAX_BUS_TIME_S`); a cycle before it synchronises without a Python effect beyond
    the clock. At most 2^63 - 1."""
    top = _TOP
    at = next_at if next_at < top else top
    if not at * cpu_hz < _NEVER:
        return _NEVER
    # the board's rounding (Board._cycles): the answer or one of its neighbours, found by the expression itself
    cycles = math.ceil(at * cpu_hz - noise)
    if cycles < 0:
        cycles = 0
    while cycles > 0 and (next_at <= (until := (cycles - 1 + noise) / cpu_hz) or until > top):
        cycles -= 1
    while not (next_at <= (until := (cycles + noise) / cpu_hz) or until > top):
        cycles += 1
    return cycles


def _unseen(pin: int, level: int) -> None:
    """MCU-84: a GPIOA output change nobody sees (the write a failed bus run left behind)."""


class NativeFrames:
    """The native per-frame fast path of a transaction-level board (MCU-51): the tables handed to hook.c, the
    mirror refreshed after Python's writes of GPIOA and SPI1, the catch-up at each entry into Python."""

    def __init__(self, board: FrameBoard, spi_held: HeldRegister, ss_pin: int, pins: tuple[int, int, int],
                 noise: float, exti0: int) -> None:
        self._board = board
        core = board.core
        self._frames = frames = core.frames
        self._hz = core.cpu_hz
        self._noise = noise
        self._spi_held = spi_held
        frames.spi = ctypes.pointer(spi_held.native)
        frames.least_t1, frames.least_t2, frames.least_t8 = board._least_t1, board._least_t2, board._least_t8
        frames.ss_pin = ss_pin
        frames.cd_command, frames.cd_data = C_D_COMMAND, C_D_DATA
        frames.phase_command, frames.phase_data = _PHASE_COMMAND, _PHASE_DATA
        frames.sr_txe, frames.sr_bsy, frames.sr_rxne = SR_TXE, SR_BSY, SR_RXNE
        frames.spi_dr, frames.spi_sr = SPI_DR, SPI_SR
        frames.least_t6max = board._least["t6max"]
        frames.irq_pin, frames.cd_pin, frames.io_pin = pins
        self._irq_pin = pins[0]
        frames.irq_address, frames.irq_clear = IRQ_ADDRESS, _registers._READ_CLEARS[IRQ_ADDRESS]
        frames.io_bit = IO_ACCESS_BIT
        frames.exti_pr_offset = EXTI_PR
        commands = _upif._COMMANDS
        frames.plain[:] = [int(plain) for plain in _upif._PLAIN_COMMANDS]
        frames.address[:] = [command.address for command in commands]
        frames.rd[:] = [int(command.rd) for command in commands]
        frames.wr[:] = [int(command.wr) for command in commands]
        frames.reads_register[:] = [int(reads) for reads in _upif._READS_REGISTER]
        frames.writes_register[:] = [int(writes) for writes in _upif._WRITES_REGISTER]
        frames.fast_read[:] = FAST_READS
        frames.fast_write[:] = FAST_WRITES
        frames.write_mask[:] = _registers._WRITE_MASKS
        read_names = _registers._READ_NAMES
        frames.alias[:] = [read_names.index(name) if name in read_names else -1 for name in _registers._WRITE_NAMES]
        reads = [name for address, name in enumerate(read_names)
                 if name is not None and (FAST_READS[address] or address == IRQ_ADDRESS)]  # fmt: skip
        self._read_values = operator.itemgetter(*reads)  # the fast-readable registers' values, in address order
        self._values = struct.Struct("<" + "".join("B" if name in reads else "x" for name in read_names))
        self._values_at = Frames.values.offset
        self._packed: tuple[int, ...] | None = None  # MCU-78: the values last packed into Frames.values
        self._configured: tuple[object, ...] | None = None  # MCU-78: what the configuration fields were made of
        self._bench = board.bench  # the transaction-level bench, set once at the board's construction
        self._due_key: tuple[int, float | None, float] | None = None  # the bench's next events, as last mirrored
        self._due = (0, _NEVER, _NEVER, _NEVER, math.inf)
        self._written: tuple[str | None, ...] = _registers._WRITE_NAMES
        self._exti0 = exti0
        frames.chain_number, frames.tail_chain_cycles = exti0, core.cpu.tail_chain_cycles  # MCU-86
        frames.return_cycles, frames.idle_loop = core.cpu.return_cycles, int.from_bytes(IDLE_LOOP, "little")
        self.tail_chained = 0
        """MCU-86: the tail-chains hook.c took (a count for tests and benchmarks)."""
        self.plain_returns = 0
        """MCU-86: the plain returns of EXTI0's handler hook.c took (a count for tests and benchmarks)."""
        self._tail_chains = True
        self._command: object = None
        self._code = _NO_COMMAND
        self.bus_dues = 0
        """MCU-84: the /SS edges whose bus event hook.c had Python run (:meth:`_bus_due`; a count for tests)."""
        self._bus_due_callback = BUS_DUE(self._bus_due)  # kept alive with the frames, which point at it
        frames.bus_due = self._bus_due_callback
        frames.valid = 0
        frames.pending = 0
        core.entry = self.catch_up
        core.resume = self.refresh

    @property
    def tail_chains(self) -> bool:
        """MCU-86: hook.c takes EXTI0's returns, tail-chains and plain ones (the default); ``False``: every return
        goes to Python's ``CortexM.exception_return``, for a test that watches it and ``CortexM.entered``. The same
        run either way."""
        return self._tail_chains

    @tail_chains.setter
    def tail_chains(self, value: bool) -> None:
        self._tail_chains = check_bool("tail_chains", value)

    def _bus_due(self, offset: int, value: int, now: int) -> None:
        """MCU-84: hook.c's /SS edge (GPIOA's BSRR or BRR written with ``value``) has a bus event due at or before
        it: an entry into Python, the bus run up to the edge and /IRQ followed, as ``Board._on_output`` does before
        the edge, and the mirror made again; hook.c then takes the edge if it is still plain, else calls Python's
        write, which finds the bus run. A failure stops the run as Python's write would (:meth:`CortexM.fail`), with
        the register written: that write's state at its failure. MCU-88: only what the bus run reads is caught up
        first (:meth:`_bus_half`) and only what it changes mirrored after (:meth:`_bus_refresh`); the frames' own
        state stays hook.c's until the next entry's catch-up. ``now``: the edge's core cycle, which hook.c handed out
        as :meth:`CortexM.cycles_now` would (MCU-90)."""
        self._frames.valid = 0  # hook.c calls with the mirror valid (MCU-84)
        frame_pending = self._bus_half(False)
        self.bus_dues += 1
        board = self._board
        try:
            board._sync(now)  # MCU-90: Board._now's run, at the time hook.c handed out as cycles_now does
        except BaseException as error:  # handed to the run loop, raised there (CortexM's own callbacks do the same)
            if frame_pending:
                self._frame_half()
            board.core.fail(error)
            gpio = board.gpio
            output, gpio.on_output = gpio.on_output, _unseen
            try:  # the levels set without the board seeing the edge: Gpio.write's state when the edge failed
                gpio.write(offset, 4, value)
            finally:
                gpio.on_output = output
            return
        board._bus_ran(self._bus_refresh())

    def catch_up(self) -> None:
        """An entry into Python (:attr:`CortexM.entry`): the mirror is no longer valid (Python may change what it
        mirrors); the native frames' net effect, if they took any, set in the Python objects (what their slow path
        would have set). One Python call an entry (MCU-65)."""
        frames = self._frames
        if not frames.valid:
            return
        frames.valid = 0
        if self._bus_half():
            self._frame_half()

    def _bus_half(self, sync: bool = True) -> bool:
        """The part of :meth:`catch_up` the bus and /IRQ's bookkeeping read (MCU-88): hook.c's returns of EXTI0
        (MCU-86), EXTI's PR (MCU-68), the IRQ_EVT reads (MCU-67), /IRQ as followed, the bus synchronised to the
        latest access, the data registers written; whether the frames' own state (:meth:`_frame_half`) is pending.
        ``sync=False`` (MCU-90): the caller runs the bus up to now right after, so the runs up to the
        accesses are left to it: hook.c took them before ``due``, so only the phases' flags could run there, which
        neither the replayed reads nor the written values depend on."""
        frames = self._frames
        if frames.chains or frames.returned:
            self._chained()
        if not frames.pending:
            return False
        irq_level, written, cleared, cleared_at, exti_pr = _BUS_STATE.unpack_from(frames, _BUS_STATE_AT)
        synced = frames.synced
        frames.written = frames.cleared = frames.synced = 0
        board = self._board
        board.exti.pr = exti_pr  # MCU-68: the handler's writes of PR (before the bus runs on: its edges come after)
        if cleared:  # MCU-67: the register file's own read-clear, each read at the latest one's time (no bus event)
            self._packed = None  # MCU-78: the native reads changed Frames.values
            if sync:
                board._sync(cleared_at - 1)
            read = board.registers.cpu_read
            for _ in range(cleared):
                read(IRQ_ADDRESS)
        board._irq_level = irq_level  # /IRQ rose with the clear: the board followed it (no EXTI bit, MCU-67)
        if synced and sync:  # the bus run up to the latest synchronisation: no event but the phases' flags (MCU-52)
            board._sync(synced - 1)
        if written:
            values = board.registers._values
            masked = frames.written_values
            names = self._written
            while written:  # each address written, lowest first
                address = (written & -written).bit_length() - 1
                values[names[address]] = masked[address]  # FAST_WRITES: a register
                written &= written - 1
        return True

    def _frame_half(self) -> None:
        """The rest of :meth:`catch_up`: GPIOA's outputs, the µP protocol's phase, command and frame, the board's /SS
        bookkeeping, SPI1's bytes (nothing the bus reads, MCU-88)."""
        frames = self._frames
        (_, odr, _, phase, command, last_rx, frame_open, fall, driven, transfer, seen, start, period, ss_rise,
         cd_before, _, _, _, _, _, dr_writes, rx_last, received, shift_start, shift_end) = _STATE.unpack_from(
            frames, _STATE_AT)  # fmt: skip
        frames.pending = frames.dr_writes = 0
        board = self._board
        gpio = board.gpio
        gpio.odr = odr
        gpio._levels = frames.gpio_levels
        protocol = board.protocol
        protocol.phase = _PHASE_OF[phase]
        if command < _NO_COMMAND:
            protocol.command = _upif._COMMANDS[command]
        protocol.last_rx = last_rx
        board._ss_rise, board._cd_before = ss_rise, cd_before
        if frame_open:
            board._frame = SsFrame(fall, driven, [(seen, 8, start, period)] if transfer else [])
            protocol._frame = (True, driven)
        else:
            board._frame = None
            protocol._frame = None
        if dr_writes:
            spi = board.spi
            spi.rx_last, spi.rx_buffer, spi._ovr_seen = rx_last, None, False
            spi.shifting = (received, shift_start, shift_end)
            spi.transfers += dr_writes
            spi._holding = True

    def _chained(self) -> None:
        """MCU-86: hook.c's returns of EXTI0's handler since the last catch-up (tail-chains, then perhaps a plain
        return), handed to the board (``Board._chained``); the bus synchronisation to them is the catch-up's
        (``synced``)."""
        frames = self._frames
        chains, latency, fell, returned = frames.chains, frames.chain_latency, frames.irq_fell, frames.returned
        frames.chains = frames.returned = 0
        frames.chain_latency = -1
        self.tail_chained += chains
        self.plain_returns += returned
        self._board._chained(chains, latency, None if fell < 0 else fell, bool(returned))

    def _thresholds(self, events: list[tuple[float, str]], next_start: float) -> tuple[int, int, int, int, float]:
        """The first core cycle whose synchronisation runs a cycle's start or end, the one that runs the latch
        phase's start and the one that sets the I/O access bit (each :data:`_NEVER` if none comes before): the phases
        only set the chips' flags (MCU-52, MCU-66); the run loop's deadline for thread mode at that event (MCU-86:
        ``Board._deadline_of``, the next event ``Board._bus_deadline`` stops at) and the event's time (MCU-90)."""
        hz, noise = self._hz, self._noise
        latch_at = io_at = _NEVER
        for at, what in reversed(events):  # the next first
            if what == _LATCH:
                latch_at = first_due(at, hz, noise)
            elif what == _IO:
                io_at = first_due(at, hz, noise)
            else:
                return first_due(at, hz, noise), latch_at, io_at, self._board._deadline_of(at, 0.0), at
        return (first_due(next_start, hz, noise), latch_at, io_at, self._board._deadline_of(next_start, 0.0),
                next_start)

    def refresh(self) -> None:
        """After Python's write of GPIOA or SPI1: mirror the model's state for the native frames, valid if the
        conditions they need hold (module docstring)."""
        frames = self._frames
        board = self._board
        protocol, registers = board.protocol, board.registers
        bench = self._bench
        phase = _PHASE_NUMBERS[protocol.phase]
        command = protocol.command
        if command is not self._command:  # a CommandByte's hash is a Python call: the last one's code kept
            self._command = command
            if command is None:
                self._code = _NO_COMMAND
            else:  # by identity first (MCU-65)
                code = _CODES_BY_ID.get(id(command), -1)
                self._code = _CODES[command] if code < 0 else code
        code = self._code
        frame = board._frame
        core = board.core
        valid = (protocol.mode is _MOTOROLA and not registers._pedantic and bench.low_at is None
                 and board._irq_level == registers.irq_n and bench.chip.mod_ack_until == board._mod_ack_until
                 and phase and (phase != _PHASE_DATA or code != _NO_COMMAND)
                 and (not board.exti.requesting(0) or self._exti0 in core.active
                      or self._exti0 in core.pending))  # _sync's _pend: nothing to do  # fmt: skip
        transfer = (0, 0, 0, 0)
        if frame is not None:  # a frame Python began: the native frames may go on with it
            valid = valid and protocol._frame is not None and frame.driven is not None and len(frame.transfers) <= 1
            if valid and frame.transfers:
                seen, bits, start, period = frame.transfers[0]
                valid = bits == 8
                transfer = (1, seen, start, period)
        elif protocol._frame is not None:
            valid = False
        if not valid:
            frames.valid = 0
            return
        gpio, spi, rcc, exti = board.gpio, board.spi, board.rcc, board.exti
        cr = gpio.cr
        configured = (rcc.apb2enr, rcc.apb2rstr, spi.cr1, spi.modf, spi.holder, spi.offer, cr[0], cr[1],
                      gpio.pulled_up, exti.exticr1, exti.rtsr)  # fmt: skip
        if configured != self._configured:  # MCU-78: everything the configuration fields are computed from
            self._configured = configured
            self._configuration()
        self._pack_values()
        due, latch_at, io_at, thread, _ = self._events_due()
        _MIRROR.pack_into(
            frames, _MIRROR_AT, 1, due, int(registers._latch_phase), latch_at, gpio._levels,
            int(registers._io_access), io_at, 0, gpio.odr, 0, phase, code, protocol.last_rx,
            int(frame is not None), 0 if frame is None else frame.fall,
            0 if frame is None or frame.driven is None else frame.driven, *transfer, board._ss_rise, board._cd_before,
            board._irq_level, 0, 0, 0, exti.pr, 0, 0)  # fmt: skip
        self._chain_mirror(thread)

    def _pack_values(self) -> None:
        """The register file's fast-readable values into ``Frames.values`` if they changed (MCU-78: only Python's
        changes and the native reads' clears change them)."""
        values = self._read_values(self._board.registers._values)
        if values != self._packed:
            self._packed = values
            self._values.pack_into(self._frames, self._values_at, *values)

    def _events_due(self) -> tuple[int, int, int, int, float]:
        """:meth:`_thresholds` of the bench's next events, recomputed only when they changed."""
        bench = self._bench
        events = bench._events  # only popped from the end until the next cycle's start makes a new list
        key = (len(events), events[-1][0] if events else None, bench._next_start)
        if key != self._due_key:
            self._due_key = key
            self._due = self._thresholds(events, bench._next_start)
        return self._due

    def _chain_mirror(self, thread: int) -> None:
        """MCU-86: the fields of hook.c's returns of EXTI0: Python's leave and what the returns read (``thread``: the
        run loop's deadline for thread mode at the bus's next event)."""
        frames, board, bench = self._frames, self._board, self._bench
        core = board.core
        exti0, active, pending = self._exti0, core.active, core.pending
        if (len(active) == 1 and active[0] == exti0 and len(pending) == (exti0 in pending) and exti0 in core.enabled
                and core._native_exceptions and bench.cycles < bench._hold and self._tail_chains):  # fmt: skip
            fell = board._irq_fell
            _CHAIN.pack_into(frames, _CHAIN_AT, 1, int(exti0 in pending), board.exti.imr, -1 if fell is None else fell,
                             core.vtor + 4 * exti0, min(board._bounds, thread))  # fmt: skip
        else:
            frames.chain_leave = 0

    def _bus_refresh(self) -> float:
        """MCU-88: after :meth:`_bus_half` and the bus run, the mirror's part a bus run changes made again (what
        :meth:`catch_up` then :meth:`refresh` would make of it; the frames' own state, which the bus does not touch,
        stays hook.c's while pending): the registers' values, the bus's next events, the chip's flags, /IRQ's level,
        EXTI's PR and the returns' fields. Still valid: the bus ran an event (``due`` was reached), so the board
        followed /IRQ and /ModAck after it (no fall left to time) and settled EXTI0's request, the bus conditions of
        :meth:`refresh`; the others the bus does not change. The time of the bus's next start or end (MCU-90)."""
        frames, board = self._frames, self._board
        registers = board.registers
        self._pack_values()
        due, latch_at, io_at, thread, at = self._events_due()
        _BUS_MIRROR.pack_into(frames, _BUS_MIRROR_AT, 1, due, int(registers._latch_phase), latch_at)
        frames.io, frames.io_at = int(registers._io_access), io_at
        frames.irq_level, frames.exti_pr = board._irq_level, board.exti.pr
        self._chain_mirror(thread)
        return at

    def _configuration(self) -> None:
        """MCU-78: the fields the peripherals' configuration decides (GPIOA's clock and output pins, SPI1's mode and
        SCLK period, MODF, EXTI's trigger on /IRQ's rise), when what :meth:`refresh` computes them from changed."""
        board = self._board
        gpio, spi, rcc = board.gpio, board.spi, board.rcc
        cr1, period = spi.cr1, spi.period
        spi_ok = (spi.holder is self._spi_held and spi.offer is self._spi_held  # hook.c holds and offers as they would
                  and rcc.apb2enr & SPI1EN and not rcc.apb2rstr & SPI1EN and cr1 & CR1_SPE and cr1 & CR1_MSTR
                  and not cr1 & (CR1_DFF | CR1_LSBFIRST) and cr1 & (CR1_CPOL | CR1_CPHA) == CR1_CPOL | CR1_CPHA
                  and not period / self._hz < board._shortest_period_s)  # fmt: skip
        _CONFIG.pack_into(
            self._frames, _CONFIG_AT, int(bool(rcc.apb2enr & IOPAEN) and not rcc.apb2rstr & IOPAEN),
            gpio._output_mask(), gpio.pulled_up, int(bool(spi_ok)), period, SR_MODF if spi.modf else 0,
            int(board.exti.triggers(0, self._irq_pin, 1)))

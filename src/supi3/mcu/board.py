"""The emulated SUPI 3 board: a Cortex-M core, STM32F10x peripherals and the transaction-level chip on the bench.

Ref: IBS SUPI 3 OPC UM E rev. 05, 3.4.2 (one /SS frame per byte), 3.4.3 (SAS_INIT, C/D), 3.4.14 (/IRQ, the I/O
access bit), Table 3-7 (t0, t1, t2, t6, t8, t_SAS_INIT), 3.6.2 (/StatErr); the board's wiring is
``src/supi3/sdk/c/board/board.h``; guide docs/firmware-in-the-loop.md, decisions MCU-n in docs/assumptions/mcu.md.

One clock: the core's cycle count is the bench's time (``bench.now = cycles / cpu_hz``). Before every peripheral
access the bus runs up to the instruction's cycle (:meth:`Board.sync`), so what the firmware sees on C/D, /IRQ
and the I/O pin, and what the chip sees on /SS and the SPI lines, happens at the firmware's own time. The run loop
stops the core at each bus event that may change /IRQ (a cycle's start and end, MCU-31) and at each SysTick wrap, so
an edge of /IRQ enters EXTI0's handler at the next block boundary after it (MCU-1).
"""

from __future__ import annotations

import itertools
import math
import struct
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from os import PathLike
from pathlib import Path
from typing import Final, TypeVar, cast

from supi3 import timing
from supi3.checks import check_bool, check_bytes, check_choice, check_instance, check_int, fail
from supi3.config import DeviceConfig
from supi3.errors import Supi3Error
from supi3.interbus import wire
from supi3.interbus.link import Device
from supi3.interbus.master import Master
from supi3.mcu.core import (
    EXTERNAL,
    MAX_DEADLINE,
    UNASKED,
    CortexM,
    FirmwareImage,
    FirmwareStoppedError,
    Frame,
    SourceLine,
    Stop,
)
from supi3.mcu.frames import NativeFrames, SsFrame
from supi3.mcu.pins import (
    SAS_INIT_BIT,
    SR_BIT,
    SS_BIT,
    SYNC_S,
    Cause,
    LockstepRing,
    chip_clock,
    mcu_lines,
    released,
    ss_high_byte,
)
from supi3.mcu.stm32 import (
    AFIO_BASE,
    CR1_CPHA,
    CR1_CPOL,
    CR1_LSBFIRST,
    EXTI0_IRQ,
    EXTI_BASE,
    GPIOA_BASE,
    GPIOB_BASE,
    IOPAEN,
    IOPBEN,
    PERIPHERAL_SIZE,
    RCC_BASE,
    SPI1_BASE,
    Exti,
    Gpio,
    Rcc,
    Spi,
)
from supi3.model.chip import STATERR_FILTER_CLOCKS
from supi3.model.pinring import PinBranch, PinChip
from supi3.model.registers import InterfaceViolationError
from supi3.model.vcd import write_vcd
from supi3.pinout import C_D_COMMAND
from supi3.sdk.bench import (
    Bench,
    MainLoopPasses,
    MasterStart,
    ServeWait,
    bench_config,
    check_cycle_time,
    check_run_cycles,
    check_run_seconds,
    discovery_master,
    serve_wait_s,
)
from supi3.sdk.driver import UNDRIVEN_BYTE
from supi3.spi.slave_pins import reaction_clocks, shorter_than
from supi3.spi.upif import Mode, UpifProtocol
from supi3.tables import CLOCK_HZ
from supi3.top import Supi3Chip

__all__ = [
    "DEFAULT_MAX_INSTRUCTIONS",
    "FIDELITIES",
    "MAX_CPU_HZ",
    "PIN_CD",
    "PIN_IO",
    "PIN_IRQ",
    "PIN_MODACK",
    "PIN_SAS_INIT",
    "PIN_SS",
    "PIN_STAT_ERR",
    "Board",
    "BoardError",
    "FwBoard",
    "ViolationAt",
]

# GPIOA pins of board.h (BOARD_PIN_*); tests/test_mcu_board.py checks they agree.
MAX_CPU_HZ: Final[int] = 72_000_000
"""MCU-50: the board's highest core clock, the STM32F10x's 72 MHz (RM0008 7.2: SYSCLK, AHB and APB2, which clocks
SPI1, at most 72 MHz); a faster clock is refused, not run as a part that does not exist."""
PIN_IRQ: Final[int] = 0
PIN_CD: Final[int] = 1
PIN_IO: Final[int] = 2
PIN_SAS_INIT: Final[int] = 3
PIN_SS: Final[int] = 4
PIN_STAT_ERR: Final[int] = 8
PIN_MODACK: Final[int] = 1
"""On port B: PB1."""
PORT_B: Final[int] = 1
PIN_SR: Final[int] = 0
"""On port B: PB0, S/R to MFP7 on the Intel board (MCU-18)."""
PULL_UPS: Final[int] = (1 << PIN_SS) | (1 << PIN_STAT_ERR)
"""MCU-6: /SS and /StatErr have pull-ups on the board: high while the MCU does not drive them."""
_CHIP_INPUTS: Final[dict[int, tuple[str, int]]] = {PIN_SS: ("mfp_in", SS_BIT), PIN_SAS_INIT: ("mfp_in", SAS_INIT_BIT),
                                                   PIN_STAT_ERR: ("stat_err_n", 0)}  # fmt: skip
"""At pin level, the chip input (pin, bit) each GPIOA output drives: /SS on MFP5, SAS_INIT on MFP0, /StatErr."""
MISO_IDLE: Final[int] = UNDRIVEN_BYTE
"""MCU-6: what the SPI receives when the chip drives no SerOUT (pulled up): the firmware bench's undriven byte, one
value for both (FW-26)."""
DEFAULT_MAX_INSTRUCTIONS: Final[int] = 20_000_000
"""The instruction budget of one :meth:`Board.run` call unless given, renewed each time the core waits (MCU-41) and
each time the main loop comes to :data:`SERVE_POINT` (MCU-43)."""
FIDELITIES: Final[tuple[str, ...]] = ("transaction", "pin")
"""The chip on the board: the transaction-level model (:class:`supi3.sdk.bench.Bench`) or the pin-level whole chip
(:class:`supi3.top.Supi3Chip` in lockstep with the core, :mod:`supi3.mcu.pins`)."""
SERVE_POINT: Final[str] = "fw_loop"
"""MCU-30: the main loop's idle point: the entry of the board contract's ``fw_loop`` (examples/fw_board.h), which the
board port's ``main`` calls again and again, serving the /IRQ edge its EXTI0 handler noted after each call. A
:meth:`Board.run` of a firmware with this symbol ends only once a whole pass (entry to entry) began after the last
master cycle's end and after the last EXTI0 handler (the rule of :class:`supi3.sdk.bench.MainLoopPasses`, which
the firmware bench shares, FW-14), waiting at most :data:`supi3.sdk.bench.SERVE_TELEGRAMS` status telegrams."""


FLAG_EVENTS: Final[frozenset[str]] = frozenset({"io", "latch"})
"""MCU-31: the bench's phase events that only set a flag of the chip (``Supi3.set_io_access``, ``set_latch_phase``:
no /IRQ, no /ModAck); the firmware sees them at its next access, which runs the bus up to its time, so the run loop
does not stop the core at them."""

_EXTI0: Final[int] = EXTERNAL + EXTI0_IRQ
"""The exception number of EXTI0, /IRQ's line."""
NOISE_CYCLES: Final[float] = 1e-6
"""A bus time's float rounding, in core cycles: a time within this much after a core cycle is at that cycle (the bus
events are sums of bit times in seconds; MCU-45 moved their origin off 0, where a cycle's end came a float's ulp
after its core cycle and the board took its /IRQ edge a cycle late)."""

_T = TypeVar("_T")
_R = TypeVar("_R")


class BoardError(Supi3Error, RuntimeError):
    """The board cannot do what was asked at its fidelity (the transaction-level bench at pin level, a VCD at
    transaction level)."""


@dataclass(frozen=True)
class ViolationAt:
    """An interface rule the firmware broke: the chip's violation, with the bus time and where the core was."""

    time_s: float
    pc: int
    function: str | None
    error: InterfaceViolationError
    backtrace: tuple[Frame, ...] = ()
    """The firmware's call stack, innermost first (:meth:`supi3.mcu.core.CortexM.backtrace`)."""

    @property
    def source(self) -> SourceLine | None:
        """The source line of :attr:`pc` (DWARF)."""
        return self.backtrace[0].source if self.backtrace else None

    @property
    def place(self) -> str:
        """``PC 08000B7Eh in board_xfer() board.c:95, t = 7.125 µs, called from supi3_read() supi3.c:120 <-
        fw_isr() digital_io.c:32``."""
        function = f" in {self.function}()" if self.function else ""
        source = f" {self.source}" if self.source else ""
        calls = " <- ".join(str(frame) for frame in self.backtrace[1:])
        return f"PC {self.pc:08X}h{function}{source}, t = {self.time_s * 1e6:.3f} µs" + \
            (f", called from {calls}" if calls else "")  # fmt: skip

    @classmethod
    def now(cls, core: CortexM, time_s: float, error: InterfaceViolationError) -> ViolationAt:
        """``error`` at the core's PC and call stack now."""
        pc = core.pc
        return cls(time_s, pc, core.image.function_at(pc), error, core.backtrace())

    def __str__(self) -> str:
        return f"{self.place}: {self.error}"


class _BoardBench(Bench):
    """The bench, driven by the core's clock: the run loop needs the next bus event to stop the core there."""

    low_at: float | None = None
    """The bus time of the first bus event since the board last followed /IRQ at which /IRQ was low (MCU-44: the
    board times a fall it finds later, at a peripheral access or a stop, at that event); the board takes it back."""

    def irq_edge(self) -> None:
        """The board's watch of /IRQ at a bus event, in place of the firmware bench's (its service routine is the
        board's EXTI0 handler): note the first event since the board last looked at which /IRQ was low."""
        if self.low_at is None and not self.registers.irq_n:
            self.low_at = self.now

    def next_change_s(self) -> float:
        """The time of the next bus event that may change /IRQ or /ModAck: a cycle's start or end, not the phases
        between, which only set the chip's I/O access bit and latch phase (MCU-31)."""
        for at, what in reversed(self._events):  # the next first
            if what not in FLAG_EVENTS:
                return at
        return self._next_start


class FwBoard:
    """The firmware's ``fw_board_t fw_board`` (examples/fw_board.h) in the emulated RAM: the terminals the host
    writes (inputs, fault) and what the firmware keeps (outputs, command, cycles, error). Offsets are the
    structure's layout under the ARM EABI (AAPCS: ``uint32_t`` and ``int`` 4-byte aligned)."""

    INPUTS: Final = 0
    OUTPUTS: Final = 4
    FAULT: Final = 8
    COMMAND: Final = 9
    CYCLES: Final = 12
    ERROR: Final = 16
    SIZE: Final = 36

    def __init__(self, core: CortexM, symbol: str = "fw_board") -> None:
        self.core = core
        self.address = core.image.address(symbol)

    @property
    def inputs(self) -> bytes:
        """The input terminals (4 bytes, byte 0 the most significant, 3.4.8)."""
        return self.core.read_bytes(self.address + self.INPUTS, 4)

    @inputs.setter
    def inputs(self, data: bytes) -> None:
        """At most 4 bytes, the rest 0 (5 bytes lost the fifth silently: ArgumentError)."""
        data = check_bytes("inputs", data)
        if len(data) > self.OUTPUTS - self.INPUTS:
            raise fail("inputs", "at most 4 bytes (fw_board_t's inputs[FW_DATA_BYTES], examples/fw_board.h)", data)
        self.core.write_bytes(self.address + self.INPUTS, data.ljust(4, b"\0"))

    @property
    def outputs(self) -> bytes:
        """The output terminals (4 bytes)."""
        return self.core.read_bytes(self.address + self.OUTPUTS, 4)

    @property
    def fault(self) -> int:
        """1 = the peripheral has an error."""
        return self.core.read_bytes(self.address + self.FAULT, 1)[0]

    @fault.setter
    def fault(self, value: int) -> None:
        self.core.write_bytes(self.address + self.FAULT, bytes([check_int("fault", value, 0, 1)]))

    @property
    def command(self) -> int:
        """The last processor command (3.4.9)."""
        return self.core.read_bytes(self.address + self.COMMAND, 1)[0]

    @property
    def cycles(self) -> int:
        """Data cycles the firmware exchanged."""
        return int(struct.unpack("<I", self.core.read_bytes(self.address + self.CYCLES, 4))[0])

    @property
    def error(self) -> int:
        """The first driver error (supi3_err_t), 0 = none."""
        return int(struct.unpack("<i", self.core.read_bytes(self.address + self.ERROR, 4))[0])


class Board:
    """The firmware's ELF on an emulated STM32F10x-class board, wired to the chip of a :class:`Bench`.

    Parameters
    ----------
    firmware:
        The ELF (built by :func:`supi3.mcu.build.build` with the SDK's board port, or any firmware for
        ``board.h``'s wiring and ``board.ld``'s memory map).
    cpu, cpu_hz:
        The core (``"cortex_m3"``, ``"cortex_m0"``) and its clock (MCU-1; the board port's ``BOARD_SYSCLK_HZ``
        must agree: 48 MHz by default), at most :data:`MAX_CPU_HZ` (MCU-50).
    config, bit_rate, others, cycle_time_s, strict, pedantic:
        The bench's (:class:`supi3.sdk.bench.Bench`): the chip's straps, the ring, the master's cycle, and whether
        an interface violation raises (strict) or is only recorded in :attr:`violations`.
    fidelity:
        ``"transaction"`` (default): the transaction-level bench, the board checking Table 3-7 on SPI1's transfers;
        ``"pin"``: the pin-level whole chip in lockstep with the core (:mod:`supi3.mcu.pins`), SPI1 and the GPIO
        pins driving its MFP pins at chip clocks, Table 3-7 checked by the chip itself; ``others`` then are pin-level
        chips behind it (``Supi3Pins`` or ``Supi3Chip`` objects, ``PinBranch`` trees, MCU-23).
    record:
        Pin level only: keep every pin for :meth:`write_vcd`.
    stat_err_filter:
        Pin level only: the chip's /StatErr filter in clocks (3.6.2: t3 = 200 ms, the default); shorter only to test
        a peripheral fault (``fault_report``) in a few milliseconds of bus time (MCU-24).
    mode:
        The board's wiring for the interface type the firmware initializes (Table 3-8): ``Mode.MOTOROLA`` (MISO on
        SerOUT, MFP7) or ``Mode.INTEL`` (MCU-18: MISO on Ser_IN/OUT, MFP6, MOSI on it through a resistor, S/R from
        PB0 to MFP7; build the firmware with ``-DFW_MODE=SUPI3_MODE_INTEL``).
    native_frames:
        MCU-51: the plain µP interface frames (/SS edges and SPI1's DR write; MCU-67: IRQ_EVT's read-clear frame too),
        GPIOA's input reads (MCU-66) and EXTI's PR write (MCU-68) taken in native code without a Python call, their
        net effect set in the model at the next entry into Python (:mod:`supi3.mcu.frames`; the same run to the
        cycle). Transaction level on the Motorola board only; ``False`` runs every frame through Python.

    Attributes
    ----------
    core, spi, gpio, exti, rcc:
        The parts. :attr:`master` exchanges the process data.
    bench:
        The transaction-level bench (``bench.chip`` is the chip); :class:`BoardError` at pin level.
    ring, chip:
        Pin level: the :class:`~supi3.mcu.pins.LockstepRing` and its :class:`~supi3.top.Supi3Chip`.
    fw_board:
        The firmware's ``fw_board`` (:class:`FwBoard`), if the ELF has that symbol.
    interrupts:
        EXTI0 handler entries (/IRQ edges served).
    irq_latency_s:
        The longest time from a falling edge of /IRQ to the first instruction of its handler.
    violations:
        Every interface violation with its bus time and program counter (strict mode raises the first).
    served:
        The last :meth:`run` ended with the firmware's work served (MCU-30).
    """

    def __init__(self, firmware: str | Path | FirmwareImage, *, cpu: str = "cortex_m3", cpu_hz: float = 48e6,
                 config: DeviceConfig | None = None, bit_rate: int | None = None,
                 others: Sequence[Device | PinChip | PinBranch] = (),
                 cycle_time_s: float | None = None, strict: bool = True, pedantic: bool = False,
                 fidelity: str = "transaction", record: bool = False, mode: Mode = Mode.MOTOROLA,
                 stat_err_filter: int = STATERR_FILTER_CLOCKS, native_frames: bool = True) -> None:  # fmt: skip
        self.fidelity = check_choice("fidelity", fidelity, FIDELITIES)
        self.intel = check_instance("mode", mode, Mode) is Mode.INTEL
        self._s_r = 1  # PB0: S/R, 1 = the µP sends
        check_bool("record", record)
        native_frames = check_bool("native_frames", native_frames)  # before the ring claims its devices (UP-47)
        self.core = CortexM(firmware, cpu=cpu, cpu_hz=cpu_hz)
        if self.core.cpu_hz > MAX_CPU_HZ:
            raise fail("cpu_hz", f"at most {MAX_CPU_HZ} (the STM32F10x's highest SYSCLK, RM0008 7.2; MCU-50)", cpu_hz)
        self._bench: _BoardBench | None = None
        self._ring: LockstepRing | None = None
        self.protocol: UpifProtocol
        if fidelity == "pin":
            self._pin_setup(config, bit_rate, others, cycle_time_s, strict, pedantic, record, stat_err_filter)
        else:
            if record:
                raise fail("record", "False at transaction level (the chip has no pins: fidelity='pin')", record)
            if check_int("stat_err_filter", stat_err_filter, 1, STATERR_FILTER_CLOCKS) != STATERR_FILTER_CLOCKS:
                raise fail("stat_err_filter", f"{STATERR_FILTER_CLOCKS} (200 ms) at transaction level, which runs it "
                           "in well under a second (a shorter filter is for the pin level's tests, MCU-24)",
                           stat_err_filter)  # fmt: skip
            devices = cast("Sequence[Device]", others)  # the ring names a device that is not one (ArgumentError)
            self._bench = bench = _BoardBench(config, bit_rate=bit_rate, others=devices, cycle_time_s=cycle_time_s,
                                              strict=strict, pedantic=pedantic)  # fmt: skip
            self.registers = bench.registers
            self.protocol = bench.transport.protocol
            self.config = bench.config
        self._advance: Callable[[float], bool] = self._no_bench if self._bench is None else self._bench.advance
        self._cpu_hz = self.core.cpu_hz
        bit_rate = self.config.bit_rate
        self._telegram_s = wire.STATUS_TELEGRAM_BITS / bit_rate  # the line idles in whole telegrams (MCU-22, -30)
        self._wait = ServeWait(bit_rate)  # MCU-55: the run's end, at most SERVE_TELEGRAMS after its last cycle
        self._wait_s = serve_wait_s(bit_rate)
        self._bounds = MAX_DEADLINE  # MCU-86: the step's deadline but the bus's (_run, _step)
        self._limits = {symbol: timing.limit("3-7", symbol, bit_rate) for symbol in ("t0", "t1", "t2", "t8")}
        self._limits["t6max"] = timing.limit("3-7", "t6", bit_rate, maximum=True)
        self._limits["t_SAS_INIT"] = timing.limit("3-7", "t_SAS_INIT", bit_rate)
        self._least = {symbol: self._cycles(limit) for symbol, limit in self._limits.items()}  # in core cycles
        self._least["t8"] = self._cycles(self._limits["t6max"] + self._limits["t8"])  # after /SS rises
        # t2 in core cycles such that any /SS rise this long after an SCLK rise is t2 or more in chip clocks, whatever
        # the two clocks' phase (MCU-74: the chip times it in whole clocks, a core cycle is 2/3 of one at 48 MHz)
        t2_clocks = next(n for n in itertools.count() if not shorter_than(n, CLOCK_HZ, self._limits["t2"]))
        self._least["t2"] = math.ceil(t2_clocks * self._cpu_hz / CLOCK_HZ) + 1
        self._least_t1, self._least_t2, self._least_t8 = self._least["t1"], self._least["t2"], self._least["t8"]
        self._serout_release = reaction_clocks(bit_rate)  # SerOUT released after /SS rose (MCU-74)
        self._shortest_period_s = self._limits["t0"] * (1 - 1e-9)  # t0, a rounding's tolerance
        self.rcc = Rcc()
        self.exti = Exti(self.rcc)
        self.gpio = Gpio(self.rcc, IOPAEN, "GPIOA", self._inputs, self._on_output, PULL_UPS)
        self.gpio_b = Gpio(self.rcc, IOPBEN, "GPIOB", self._inputs_b, self._on_output_b, 0)
        self.spi = Spi(self.rcc, self.core.cycles_now, self if self._ring is None else self._ring,
                       self.core.cycles_polled)  # fmt: skip
        self.spi.on_poll = self.core.skip_poll
        self.spi.on_misuse = self._mcu_violation
        core = self.core
        # MCU-51: the native frames at transaction level on the Motorola board, GPIOA's and SPI1's writes through them
        native = native_frames and self._ring is None and not self.intel
        core.mmio(RCC_BASE, PERIPHERAL_SIZE, self.rcc.read, self.rcc.write)
        if native:
            core.mmio(GPIOA_BASE, PERIPHERAL_SIZE, self._gpio_read, self._gpio_write, port=0)
        else:
            core.mmio(GPIOA_BASE, PERIPHERAL_SIZE, self.gpio.read, self.gpio.write)
        core.mmio(GPIOB_BASE, PERIPHERAL_SIZE, self.gpio_b.read, self.gpio_b.write)
        core.mmio(AFIO_BASE, PERIPHERAL_SIZE, self.exti.read_afio, self.exti.write_afio)
        core.mmio(EXTI_BASE, PERIPHERAL_SIZE, self._exti_read, self._exti_write, port=2 if native else None)
        if native:
            held = core.mmio(SPI1_BASE, PERIPHERAL_SIZE, self._spi_read, self._spi_write, port=1)
        else:
            held = core.mmio(SPI1_BASE, PERIPHERAL_SIZE, self.spi.read, self.spi.write)
        self.spi.holder = self.spi.offer = held  # SR held (MCU-25), DR's read after its byte (MCU-26)
        core.entered = self._entered
        core.returning = self._returning
        self.fw_board = FwBoard(core) if "fw_board" in core.image.symbols else None
        self.interrupts = 0
        self.irq_latency_s = 0.0
        self.violations: list[ViolationAt] = []
        self._frame: SsFrame | None = None
        self._ss_rise = -(1 << 62)
        self._cd_before = C_D_COMMAND  # C/D until t6 max after /SS rises (MCU-9)
        self._sas_rise = 0
        self._irq_level = 1
        self._irq_fell: int | None = None
        self._mod_ack_until = 0
        self._limit = self._budget = 0
        self._entry: int | None = UNASKED  # the run loop's answer to CortexM.next_entry for the next step (MCU-79)
        pins = (PIN_IRQ, PIN_CD, PIN_IO)
        self.native_frames = NativeFrames(self, held, PIN_SS, pins, NOISE_CYCLES, _EXTI0) if native else None
        """MCU-51: the native per-frame fast path (``native_frames=True`` at transaction level on the Motorola
        board), else ``None``."""
        if self.native_frames is not None:  # the wrappers' refresh, one Python call (MCU-65)
            self._refresh = self.native_frames.refresh
        self._held: list[tuple[str, int, int]] | None = None  # pin level: edges held while a sleeping core waits
        self._setting_up = True  # MCU-45: the firmware has not yet first waited or come to SERVE_POINT
        self.served = True
        """MCU-30: the last :meth:`run` ended with the firmware's work served (False: the wait for the main loop's
        pass ran out, or the run raised)."""
        self._passes = MainLoopPasses()  # arrivals at SERVE_POINT (core cycles), counted from the last cycle's end
        self._began = 0.0  # the bus time the current run began (MCU-55: its wait counts from its last cycle's end)
        self._serve_end: int | None = None  # the core cycle the wait for the main loop's pass gives up
        if SERVE_POINT in core.image.symbols:  # MCU-30: note the main loop's passes
            self._serve_point: int | None = core.image.address(SERVE_POINT)
            core.watch(self._serve_point, self._on_serve_point)
        else:
            self._serve_point = None

    def _pin_setup(self, config: DeviceConfig | None, bit_rate: int | None,
                   others: Sequence[Device | PinChip | PinBranch], cycle_time_s: float | None, strict: bool,
                   pedantic: bool, record: bool, stat_err_filter: int) -> None:  # fmt: skip
        """The pin-level chip, its ring and master (MCU-14 to MCU-17)."""
        self.config = bench_config(config, bit_rate)
        if isinstance(others, str | bytes) or not isinstance(others, Sequence) \
                or not all(isinstance(other, PinChip | PinBranch) for other in others):  # fmt: skip
            raise fail("others", "pin-level chips at pin level (Supi3Pins or Supi3Chip objects, PinBranch trees: "
                       "MCU-23)", others)  # fmt: skip
        self._cycle_time_s = None if cycle_time_s is None else check_cycle_time(cycle_time_s)
        self.chip = chip = Supi3Chip(self.config, strict=check_bool("strict", strict),
                                     pedantic=check_bool("pedantic", pedantic), stat_err_filter=stat_err_filter)
        if chip.upif is None or chip.chip.registers is None:
            raise fail("config", "the straps of an Init-µP mode (Tables 2-4 to 2-7)", self.config.function)
        self.registers = chip.chip.registers
        self.protocol = chip.upif.protocol
        chips = cast("Sequence[PinChip | PinBranch]", others)  # checked above
        self._ring = ring = LockstepRing(chip, self.core.cpu_hz, self._cause, record=record, intel=self.intel,
                                         others=chips)  # fmt: skip
        ring.runner = self._lockstep
        ring.on_edge = self._pin_edge
        ring.on_violation = self._pin_violation
        self._master = discovery_master(ring, len(ring.devices))  # MCU-56: sized for the ring; MCU-64: locates
        self._start = MasterStart()  # MCU-45: the master's first cycle waits for the set-up's end
        self._cycles_done = 0
        self._next_start = 0.0  # cycle_time_s: the bus time the next master cycle starts

    # -- what both fidelities show -----------------------------------------------------------------------------

    @property
    def bench(self) -> _BoardBench:
        """The transaction-level bench (:class:`BoardError` at pin level: use :attr:`master`, :attr:`ring`)."""
        if self._bench is None:
            raise BoardError("Board.bench is the transaction-level bench; this board runs the pin-level chip "
                             "(fidelity='pin'): use board.master, board.ring, board.chip")  # fmt: skip
        return self._bench

    @property
    def ring(self) -> LockstepRing:
        """The pin-level ring (:class:`BoardError` at transaction level)."""
        if self._ring is None:
            raise BoardError("Board.ring is the pin-level ring; this board runs the transaction-level chip "
                             "(fidelity='transaction')")  # fmt: skip
        return self._ring

    @property
    def master(self) -> Master:
        """The INTERBUS master: it exchanges the process data with the chip."""
        return self.bench.master if self._ring is None else self._master

    @property
    def cycles(self) -> int:
        """Master cycles finished (ID and data)."""
        return self.bench.cycles if self._ring is None else self._cycles_done

    @property
    def now(self) -> float:
        """Bus time, seconds since power-up (at pin level: the chip's clocks run)."""
        return self.bench.now if self._ring is None else self._ring.now

    def write_vcd(self, path: str | Path) -> Path:
        """Write the chip's pins (scope ``dev1``, :func:`supi3.model.vcd.write_vcd`) and the MCU's lines (scope
        ``mcu``: the GPIO and SPI1 pins of board.h, named ``pa5_sck`` ...) to the VCD file ``path``.

        Raises
        ------
        BoardError
            The board is not a pin-level one made with ``record=True``.
        ArgumentError
            ``path`` is not a path.
        OSError
            The file cannot be written.
        """
        if not isinstance(path, str | PathLike):
            raise fail("path", "a file path (str or os.PathLike)", path)
        ring = self.ring
        if not ring.record:
            raise BoardError("Board.write_vcd needs a board made with record=True")
        traces = ring.recorded()[0]  # none yet if the firmware stopped before the chip's first clock: no samples
        return write_vcd(Path(path), ring, {"mcu": mcu_lines(traces, intel=self.intel)} if traces else None)

    def _cause(self) -> Cause:
        core = self.core
        pc = core.pc
        return Cause(pc, core.image.function_at(pc), core.backtrace())

    def _pin_edge(self, name: str, level: int, clock: int) -> None:
        """/IRQ or /ModAck changed in chip clock ``clock`` (held while a sleeping core waits for it)."""
        if self._held is not None:
            self._held.append((name, level, clock))
            return
        if name == "mod_ack_n":
            self.exti.edge(PORT_B, PIN_MODACK, level)
        elif level != self._irq_level:
            self._irq_level = level
            if not level and self._irq_fell is None:
                self._irq_fell = self.ring.core_cycle(clock)
            self.exti.edge(0, PIN_IRQ, level)
        self._request()

    def _pin_violation(self, error: InterfaceViolationError, clock: int, cause: Cause | None) -> None:
        if cause is None:
            self.violations.append(ViolationAt.now(self.core, clock / CLOCK_HZ, error))
        else:
            self.violations.append(ViolationAt(clock / CLOCK_HZ, cause.pc, cause.function, error, cause.backtrace))

    # -- time --------------------------------------------------------------------------------------------------

    def _seconds(self, cycles: int) -> float:
        return cycles / self.core.cpu_hz

    def _sync(self, cycles: int) -> None:
        """Run the bus up to core cycle ``cycles``, then follow /IRQ. /IRQ and /ModAck change only at a bus event or
        a chip action (:meth:`_chip` follows its own), and EXTI0's request only with them, a write of EXTI
        (:meth:`_exti_write`) or an exception's return (the run loop): with no bus event on the way there is nothing
        to follow (MCU-31)."""
        until = (cycles + NOISE_CYCLES) / self._cpu_hz
        bench = self._bench
        if bench is not None and until < bench._next_at and until <= wire.MAX_BUS_TIME_S:
            # FW-27: Bench.advance's own shortcut, without its call: no bus event due, only the clock moves (the
            # expression and comparison frames.first_due mirrors)
            if until > bench.now:
                bench.now = until
            return
        if self._advance(until):
            self._follow_irq(cycles)

    def _no_bench(self, until: float) -> bool:
        """:attr:`_advance` at pin level: :class:`BoardError` (the transaction-level bench is not there)."""
        return self.bench.advance(until)

    def _now(self) -> int:
        cycles = self.core.cycles_now()
        self._sync(cycles)
        return cycles

    # -- /IRQ, EXTI0 and the NVIC ------------------------------------------------------------------------------

    def _follow_irq(self, cycles: int, *, request: bool = True) -> None:
        """Pass /IRQ's and /ModAck's edges since the last call to EXTI, then let EXTI0 request its interrupt;
        ``request=False``: only if an edge was passed (the caller requested since, and nothing else changes EXTI or
        the NVIC within one peripheral access). A fall is timed at the first bus event since the last call at which
        /IRQ was low (the core cycle at or after it), else at ``cycles`` (a chip action's, MCU-44)."""
        bench = self._bench
        assert bench is not None
        low_at, bench.low_at = bench.low_at, None
        pulse = bench.chip.mod_ack_until
        if pulse != self._mod_ack_until:  # a new /ModAck pulse (375 ns, 3.6.2): both edges, the falling one latched
            self._mod_ack_until = pulse
            self.exti.edge(PORT_B, PIN_MODACK, 0)
            self.exti.edge(PORT_B, PIN_MODACK, 1)
            request = True
        level = self.registers.irq_n
        if level != self._irq_level:
            self._irq_level = level
            if not level and self._irq_fell is None:
                self._irq_fell = cycles if low_at is None else math.ceil(low_at * self._cpu_hz - NOISE_CYCLES)
            self.exti.edge(0, PIN_IRQ, level)
            request = True
        if request:
            self._request()

    def _request(self) -> None:
        """The NVIC's look at EXTI0's line (PR AND IMR) after a change: pend EXTI0 if the line is asserted while it
        is not active, and stop the run for it; while it is active, pend it only if the line rose since the last
        look (MCU-81: the Cortex-M3 NVIC pends at a rising edge even while active; a line held from before the entry
        pends nothing), without a stop, since the interrupt waits for the handler's return, which stops the run
        anyway (MCU-44, MCU-70). The core's lists asked first: inside the handler no question to EXTI (MCU-79)."""
        core, exti = self.core, self.exti
        rose, exti.rose = exti.rose, 0
        if _EXTI0 in core.pending:
            return
        if _EXTI0 in core.active:
            if rose & 1:
                core.pend(_EXTI0)
        elif exti.requesting(0):
            core.pend(_EXTI0)
            core.stop_request = True

    def _returning(self, number: int) -> None:
        """:attr:`CortexM.returning`: the bus run up to the return's first cycle (an /IRQ fall inside the handler
        that no access has seen yet pends EXTI0 now, MCU-44's bound), then, for EXTI0's own return, the NVIC samples
        its line: asserted, EXTI0 is pending again, and the return tail-chains into it (MCU-81, MCU-20)."""
        core = self.core
        ring = self._ring
        if ring is None:
            self._sync(core.cycles)
        else:
            ring.sync_to_core(core.cycles)
        if number == _EXTI0 and self.exti.requesting(0):
            core.pend(_EXTI0)

    def _exti_read(self, offset: int, size: int) -> int:
        """The firmware reads EXTI: at transaction level the bus runs up to the access first, so PR holds every edge
        of /IRQ before it (MCU-44: the run loop does not stop at a bus event while EXTI0 is active)."""
        if self._ring is None:
            self._now()
        value = self.exti.read(offset, size)
        if self.native_frames is not None:  # MCU-66: the mirror valid again for GPIOA's reads after it
            self._refresh()
        return value

    def _exti_write(self, offset: int, size: int, value: int) -> None:
        """The firmware writes EXTI (the bus run up to it first, as :meth:`_exti_read`): a line it unmasks (IMR) or
        sets (SWIER) with PR set requests at once (MCU-31)."""
        if self._ring is None:
            self._now()
        self.exti.write(offset, size, value)
        self._request()
        if self.native_frames is not None:  # MCU-66: the mirror valid again for GPIOA's reads after it
            self._refresh()

    def _entered(self, number: int) -> None:
        if number == _EXTI0:
            self._passes.handler()  # MCU-30: a pass serves the edge only if it begins after the handler
            self.interrupts += 1
            if self._irq_fell is not None:
                self.irq_latency_s = max(self.irq_latency_s, (self.core.cycles - self._irq_fell) / self._cpu_hz)
                self._irq_fell = None

    def _chained(self, chains: int, latency: int, fell: int | None, returned: bool) -> None:
        """MCU-86: the returns of EXTI0's handler hook.c took since the last catch-up, as
        :meth:`CortexM.exception_return` and :meth:`_entered` take them: ``chains`` tail-chains (EXTI0 no longer
        pending, still active, the entries counted; the main loop's passes were reset at the first entry of the
        chain, and none arrives in a handler), then, ``returned``, a plain return (EXTI0 no longer active);
        ``latency``: the longest /IRQ latency of their entries in core cycles (-1: none measured), ``fell``:
        :attr:`_irq_fell` after them."""
        core = self.core
        core.pending.discard(_EXTI0)
        if returned:
            core.active.pop()
        self.interrupts += chains
        if latency >= 0:
            self.irq_latency_s = max(self.irq_latency_s, latency / self._cpu_hz)
        self._irq_fell = fell

    # -- the main loop's passes (MCU-30) --------------------------------------------------------------------------

    def _on_serve_point(self) -> None:
        """The core is about to run :data:`SERVE_POINT`: note the arrival (at the end of the block it is in, the
        core's clock now, MCU-1); once a whole pass began after the run's last cycle, end the core's run. A pass of
        the main loop renews the instruction budget, as a wait does (MCU-43)."""
        core = self.core
        self._limit = core.instructions + self._budget
        if self._setting_up:  # MCU-45: the first pass ends the set-up; at transaction level the master starts now
            self._set_up()
            core.stop_request = True
        if self._passes.arrive(core.cycles):
            core.stop_request = True

    def _passed(self) -> bool:
        """A whole pass of the main loop began at or after the run's last cycle's end and after the last EXTI0
        handler (:meth:`MainLoopPasses.passed`; always, without :data:`SERVE_POINT`)."""
        return self._serve_point is None or self._passes.passed()

    def _served(self) -> bool:
        """The firmware has served what the bus gave it: no exception active or pending and the main loop's pass
        done (MCU-30)."""
        return not self.core.in_exception and self._passed()

    def _serve_wait(self) -> bool:
        """Transaction level, :meth:`run`'s master cycles done (the bench's master holds, MCU-55): whether the run is
        done. The first call is at the block boundary the core stopped at for the last cycle's end (the run loop
        stops at each bus event; while EXTI0's handler runs, at its return or at most the wait's bound after it,
        MCU-44): the main loop's passes count from there; the run ends once the firmware has served the cycles (no
        exception active or pending, the pass made) or at the latest :data:`~supi3.sdk.bench.SERVE_TELEGRAMS` status
        telegrams after the last cycle's end (:class:`~supi3.sdk.bench.ServeWait`, a bound of the run loop's
        steps)."""
        core = self.core
        if self._serve_end is None:
            self._passes.begin(core.cycles)
            self._serve_end = self._cycles(self._wait.begin(self.bench.last_end(self._began)))
        self.served = self._served()
        return self.served or core.cycles >= self._serve_end

    # -- pins --------------------------------------------------------------------------------------------------

    def _inputs(self) -> int:
        ring = self._ring
        if ring is not None:
            ring.sync_to_core(self.core.cycles_now())
            return ring.irq_n << PIN_IRQ | ring.c_d << PIN_CD | ring.io << PIN_IO
        cycles = self._now()
        cd = self.protocol.c_d if cycles >= self._ss_rise + self._least["t6max"] else self._cd_before
        return self.registers.irq_n << PIN_IRQ | cd << PIN_CD | int(self.registers.io_access) << PIN_IO

    def _inputs_b(self) -> int:
        ring = self._ring
        if ring is not None:
            ring.sync_to_core(self.core.cycles_now())
            return ring.mod_ack_n << PIN_MODACK
        self._now()
        return self.bench.mod_ack << PIN_MODACK

    def _on_output_b(self, pin: int, level: int) -> None:
        """Port B drives S/R (PB0, MFP7) on the Intel board, nothing the chip sees on the Motorola board."""
        if not self.intel or pin != PIN_SR:
            return
        ring = self._ring
        if ring is not None:
            ring.drive(self.core.cycles_now(), "mfp_in", SR_BIT, level)
        else:
            self._now()
            self._s_r = level

    def _cycles(self, seconds: float) -> int:
        return math.ceil(seconds * self.core.cpu_hz - NOISE_CYCLES)

    # MCU-51: GPIOA's and SPI1's accesses that reach Python (the native frames did not take them), each followed by
    # the native frames' mirror refreshed, valid again for the frames after it

    def _gpio_read(self, offset: int, size: int) -> int:
        value = self.gpio.read(offset, size)
        self._refresh()
        return value

    def _gpio_write(self, offset: int, size: int, value: int) -> None:
        self.gpio.write(offset, size, value)
        self._refresh()

    def _spi_read(self, offset: int, size: int) -> int:
        value = self.spi.read(offset, size)
        self._refresh()
        return value

    def _spi_write(self, offset: int, size: int, value: int) -> None:
        self.spi.write(offset, size, value)
        self._refresh()

    def _on_output(self, pin: int, level: int) -> None:
        ring = self._ring
        if ring is not None:
            wire = _CHIP_INPUTS.get(pin)
            if wire is not None:
                ring.drive(self.core.cycles_now(), *wire, level)
            return
        cycles = self.core.cycles_now()
        self._sync(cycles)
        if pin == PIN_SS:
            self._ss_edge(level, cycles)
        elif pin == PIN_SAS_INIT:
            if level:
                self._sas_rise = cycles
            elif cycles - self._sas_rise < self._least["t_SAS_INIT"]:
                self._violation("Table 3-7 t_SAS_INIT", f"SAS_INIT pulse of {self._ns(cycles - self._sas_rise)} ns, "
                                f"shorter than {self._limits['t_SAS_INIT'] * 1e9:.0f} ns")  # fmt: skip
            self._chip(self.bench.transport.set_sas_init, cycles, level)
        elif pin == PIN_STAT_ERR:
            self._chip(self.bench.set_stat_err, cycles, not level)

    def _ns(self, cycles: int) -> str:
        return f"{self._seconds(cycles) * 1e9:.0f}"

    def _ss_edge(self, level: int, cycles: int) -> None:
        if not level:
            gap = cycles - self._ss_rise
            if gap < self._least_t8:
                need = self._limits["t6max"] + self._limits["t8"]
                self._violation("Table 3-7 t8", f"/SS fell {self._ns(gap)} ns after it rose: C/D settles t6 "
                                f"(max) + t8 = {need * 1e9:.0f} ns after the rise")  # fmt: skip
            driven = self._chip(self.protocol.begin, cycles, bool(self._s_r) if self.intel else True)
            self._frame = SsFrame(cycles, driven, [])
            return
        frame, self._frame = self._frame, None
        if frame is None:
            return
        self._ss_rise = cycles
        self._cd_before = self.protocol.c_d
        edges = 0
        last = -1  # the frame's last rising SCLK edge
        for _, bits, start, period in frame.transfers:
            clocked = (cycles - start) // period
            if clocked > bits:  # not min(): no call on the per-byte path (MCU-42)
                clocked = bits
            if clocked:
                last = start + clocked * period
            edges += clocked
        if edges != 8 or cycles - last < self._least_t2:  # not whole and clear of t2 at any chip clock's phase
            edges = self._ss_rose_near_an_edge(frame, cycles)
        if edges == 8:
            # An Intel receive frame: the chip's driver wins on Ser_IN/OUT, it takes its own byte (MCU-18).
            on_line = frame.driven if self.intel and frame.driven is not None else frame.transfers[-1][0]
            self._chip(self.protocol.end, cycles, on_line)
        else:
            self._chip(self.protocol.abort, cycles, edges)

    def _ss_rose_near_an_edge(self, frame: SsFrame, cycles: int) -> int:
        """/SS rose at core cycle ``cycles`` within a few chip clocks of t2 after the frame's last SCLK edge, or before
        its 8th: the frame's SCLK edges as the pin-level chip sees them, at chip-clock resolution (MCU-74). An SCLK
        rise the chip sees before the /SS rise is the frame's bit (in the same clock it is not: the edge detectors act
        on /SS first, ``SlavePins._edge``); t2 is timed from the last SCLK rise up to the /SS rise's clock
        (TimingChecker); SerOUT stays driven until the chip reacts to the rise
        (:func:`~supi3.spi.slave_pins.reaction_clocks`), then SPI1 samples MISO's pull-up."""
        cpu_hz = self._cpu_hz
        rise = chip_clock(cycles, cpu_hz)
        until = rise + self._serout_release
        edges = sampled = bits = 0
        last = -1
        for _, bits, start, period in frame.transfers:
            sampled = 0
            for k in range(1, bits + 1):
                edge = chip_clock(start + k * period, cpu_hz)
                if edge > until:
                    break
                sampled += 1
                if edge <= rise:
                    last = edge
                    edges += edge < rise
        if last >= 0 and shorter_than(rise - last, CLOCK_HZ, self._limits["t2"]):
            self._violation("Table 3-7 t2", f"/SS rose {(rise - last) / CLOCK_HZ * 1e9:.0f} ns after the last SCLK "
                            f"edge, less than t2 = {self._limits['t2'] * 1e9:.0f} ns")  # fmt: skip
        spi = self.spi
        if sampled < bits and not self.intel and spi.shifting is not None and cycles < spi.shifting[2]:
            # SPI1 samples MISO's pull-up from the release on (MCU-6); the Intel board's line reads MOSI through its
            # resistor then, not modelled (MCU-74's limit)
            received = spi.shifting[0]
            assert type(received) is int
            spi.replace_received(released(received, bits, sampled, bool(spi.cr1 & CR1_LSBFIRST)))
        return edges

    def spi_byte(self, tx: int, bits: int, start: int, period: int, cr1: int) -> int:
        """:class:`~supi3.mcu.stm32.SpiWire`: SPI1 starts a transfer; the chip sees it inside its /SS frame."""
        self._sync(start)
        period_s = period / self._cpu_hz
        if period_s < self._shortest_period_s:
            self._violation("Table 3-7 t0", f"SCLK period {period_s * 1e9:.0f} ns, shorter than t0 = "
                            f"{self._limits['t0'] * 1e9:.0f} ns")  # fmt: skip
        if cr1 & (CR1_CPOL | CR1_CPHA) != CR1_CPOL | CR1_CPHA:
            self._violation("3.4.2", f"SPI mode CPOL={cr1 >> 1 & 1}, CPHA={cr1 & 1}: the chip needs mode 3 (SCLK "
                            "idles high, data taken on the rising edge, UP-5)")  # fmt: skip
        frame = self._frame
        if frame is None:
            lint = ss_high_byte(tx)  # the same lint as the pin-level board's (MCU-63)
            self._violation(lint.rule, lint.detail)
            return MISO_IDLE
        lsb = bool(cr1 & CR1_LSBFIRST)
        reverse = lsb != (self.protocol.mode is Mode.INTEL)  # the chip shifts LSB first in Intel mode (UP-6)
        seen = _reverse(tx & 0xFF) if reverse else tx & 0xFF
        if not frame.transfers and start + period // 2 - frame.fall < self._least_t1:
            self._violation("Table 3-7 t1", f"first SCLK edge {self._ns(start + period // 2 - frame.fall)} ns after "
                            f"/SS fell, less than t1 = {self._limits['t1'] * 1e9:.0f} ns")  # fmt: skip
        frame.transfers.append((seen, bits, start, period))
        driven = MISO_IDLE if frame.driven is None else frame.driven
        return _reverse(driven) if reverse else driven

    # -- the chip and its violations ---------------------------------------------------------------------------

    def _chip(self, action: Callable[[_T], _R], cycles: int, argument: _T) -> _R:
        """``action(argument)`` on the chip with its violations deferred to its end; note the new ones with the PC.
        Called within a peripheral access after :meth:`sync`, which let EXTI0 request its interrupt."""
        log = self.registers.violations
        records = log.records
        before = len(records)
        defer = log.strict  # a non-strict log only records: nothing to defer (MCU-42)
        if defer:
            log.hold()  # log.deferred() without the with statement's cost (the per-byte hot path)
        try:
            try:
                result = action(argument)
            except BaseException:
                if defer:
                    log.release(failed=True)
                raise
            if defer:
                log.release()
            return result
        finally:
            if len(records) > before:
                self._note(records[before:], cycles)
            self._follow_irq(cycles, request=False)

    def _violation(self, rule: str, detail: str) -> None:
        self._chip(self.registers.violations.report, self.core.cycles_now(), InterfaceViolationError(rule, detail))

    def _mcu_violation(self, rule: str, detail: str) -> None:
        """A rule of the microcontroller's own peripherals broken (SPI1's CR1 during a transfer, MCU-40): reported
        as the board's other violations, with the bus time and where the core is, at either fidelity."""
        if self._ring is None:
            self._violation(rule, detail)
            return
        error = InterfaceViolationError(rule, detail)
        self.violations.append(ViolationAt.now(self.core, self._seconds(self.core.cycles_now()), error))
        self.registers.violations.report(error)

    def _note(self, errors: list[InterfaceViolationError], cycles: int) -> None:
        for error in errors:
            self.violations.append(ViolationAt.now(self.core, self._seconds(cycles), error))

    # -- running -----------------------------------------------------------------------------------------------

    def run(self, cycles: int, *, max_instructions: int = DEFAULT_MAX_INSTRUCTIONS) -> None:
        """Run the firmware until ``cycles`` more master cycles have finished and it has served them (MCU-30): no
        exception active or pending (the interrupts they raised taken, as :meth:`Bench.run` takes the last cycle's)
        and, for a firmware with :data:`SERVE_POINT` (``fw_loop``), a whole pass of its main loop begun after the
        last cycle and the last EXTI0 handler. The wait for that pass lasts at most :data:`SERVE_TELEGRAMS` status
        telegrams of bus time; :attr:`served` tells whether the run ended served. At pin level the master's cycles
        run whole, then the line idles in status telegrams while the firmware is in a handler, has an /IRQ edge to
        serve or its pass to make, up to :data:`SERVE_TELEGRAMS` of them (MCU-17). A cycle a transaction-level
        :meth:`run_for` left under way ends first, then the run's ``cycles`` start (MCU-76: the pin level's
        :meth:`run_for` has run it whole). The instruction budget bounds the work between two waits of the core
        (MCU-41) or two passes of its main loop (MCU-43).

        Raises
        ------
        FirmwareFaultError
            The core faulted (report: fault type, PC, stacked registers).
        FirmwareStoppedError
            ``max_instructions`` ran out since the core last waited or its main loop last came to
            :data:`SERVE_POINT` (checked where the core stops, at basic-block
            boundaries, so the run may end up to one block past it, MCU-1), or the firmware loops on ``b .`` inside
            a handler.
        InterfaceViolationError
            In strict mode, the first rule the firmware broke, with a note: bus time, PC and function.
        PeripheralClockError, PeripheralResetError
            The firmware touched a peripheral whose clock is off or which RCC_APB2RSTR holds in reset (MCU-7,
            MCU-29).
        """
        # MCU-76: a cycle a run_for left under way (transaction level) ends first, then the run's own cycles start,
        # as at pin level, whose run_for runs it whole
        cycle_time_s = self._cycle_time_s if self._bench is None else self._bench.cycle_time_s
        target = (self.cycles + check_run_cycles(cycles, self.now, self.config.bit_rate, cycle_time_s)  # A26
                  + (self._bench is not None and self._bench.under_way))
        check_int("max_instructions", max_instructions, 1)  # UP-48: refused before `served` and the hold change
        self._passes.end()
        self._serve_end = None
        self.served = False  # until the run ends served (MCU-30)
        try:
            if self._ring is not None:
                self._run_pin(lambda: self._cycles_done >= target, max_instructions)
                return
            bench = self.bench
            self._began = bench.now
            bench.hold_after(target)  # MCU-55: exactly the run's cycles, then the line idles while it waits
            self._run(lambda: bench.cycles >= target and self._serve_wait(), max_instructions)
        finally:
            self._passes.end()
            self._wait.end()
            self._serve_end = None
            if self._bench is not None:
                self._bench.resume()

    def run_for(self, seconds: float, *, max_instructions: int = DEFAULT_MAX_INSTRUCTIONS) -> None:
        """Run the firmware for ``seconds`` of bus time (raises as :meth:`run`). At pin level (MCU-22) the master
        cycles that start before the end run whole, then the line idles up to the end, to the nearest status
        telegram; a cycle that runs past the end ends the call there, and the rest of a cycle time's idle is left
        to the next call; the firmware's handler of the last cycle is not waited for (as at transaction level)."""
        seconds = check_run_seconds(seconds, self.now)  # A26
        ring = self._ring
        if ring is not None:
            end_s = ring.now + seconds
            self._run_pin(lambda: ring.now > end_s - self._telegram_s / 2, max_instructions, end_s)
            return
        end = self.core.cycles + self._cycles(seconds)
        self._run(lambda: self.core.cycles >= end, max_instructions, end)

    def _run(self, done: Callable[[], bool], max_instructions: int, end: int | None = None) -> None:
        core, bench = self.core, self._bench
        assert bench is not None  # transaction level
        self._set_budget(max_instructions)
        self._sync(core.cycles)
        self._follow_irq(core.cycles)  # the chip may have changed between runs (the host's calls)
        systick = core.systick
        while True:
            tick = systick.due()
            self._request()
            if done():
                return
            self._entry = core.next_entry()  # once a step: for the deadline and the step's entry (MCU-79)
            bounds = MAX_DEADLINE
            for bound in (tick, end, self._serve_end):
                if bound is not None:
                    bounds = min(bounds, bound)
            self._bounds = bounds
            self._step(min(self._bus_deadline(bench.next_change_s()), bounds))
            self._sync(core.cycles)

    def _bus_deadline(self, at: float) -> int:
        """The core cycle the run loop stops the core at for the bus: the next bus event that may change /IRQ or
        /ModAck (MCU-31); while EXTI0 is active or about to be entered at the step's start, :func:`serve_wait_s`
        after it (MCU-44: an edge of /IRQ then only sets EXTI's pending bit, and the firmware's next access, or the
        next stop, at the latest the handler's return, runs the bus up to it; MCU-55: a handler that makes no access
        for that long, spinning, still lets the bus run on, and a run's wait ends at its bound); none while the
        master holds at a run's end (MCU-55: no bus event comes). The core's next entry: the run loop's answer of
        the step (MCU-79). ``at``: the bus's next event that may change /IRQ or /ModAck
        (:meth:`_BoardBench.next_change_s`)."""
        handler = self._entry == _EXTI0 or _EXTI0 in self.core.active
        return self._deadline_of(at, self._wait_s if handler else 0.0)

    def _deadline_of(self, at: float, wait_s: float) -> int:
        """The core cycle the run loop stops at ``wait_s`` after a bus event at ``at`` (never: no bound)."""
        if at == math.inf:
            return MAX_DEADLINE
        return math.ceil((at + wait_s) * self._cpu_hz - NOISE_CYCLES)

    def _bus_ran(self, at: float) -> None:
        """MCU-86: the bus ran during a step (hook.c's /SS edge past a bus event, :meth:`NativeFrames._bus_due`)
        and the run is not at its end: the step's deadline moves to the one the run loop would give a step starting
        now (:meth:`_bus_deadline` from the bus's next event, the step's other bounds). A stop at the old one would
        find no bus event due: nothing but the clock (MCU-31, MCU-44); not stopping there lets hook.c's tail-chains
        go on to the next bus event. ``at``: the bus's next event that may change /IRQ or /ModAck, which the native
        frames' thresholds found (MCU-90)."""
        bench = self._bench
        assert bench is not None  # the native frames run at transaction level
        if bench.cycles < bench._hold:  # at a run's end, the serve wait begins at the loop's next stop (MCU-30)
            state = self.core._state
            state.deadline = max(state.deadline, min(self._bus_deadline(at), self._bounds))

    def _set_budget(self, max_instructions: int) -> None:
        self._budget = check_int("max_instructions", max_instructions, 1)
        self._limit = self.core.instructions + self._budget

    def _step(self, deadline: int) -> None:
        """One run of the core up to ``deadline`` (at least one block), within the instruction budget; the exception
        it enters first: the run loop's answer handed in :attr:`_entry` (taken once, MCU-79), else the core asks."""
        core = self.core
        entry, self._entry = self._entry, UNASKED
        cycles = core.cycles
        if not core.sleeping:  # a sleeping core runs no instruction (MCU-4)
            left = self._limit - core.instructions
            if left <= 0:
                raise FirmwareStoppedError(core.report(Stop.BUDGET, f"instruction budget of {self._budget} used up "
                                                       "(an endless loop?)"))  # fmt: skip
            deadline = min(deadline, cycles + left)  # within the budget: an instruction costs a cycle at least (MCU-1)
            self._bounds = min(self._bounds, cycles + left)
        core._handed = entry  # UNASKED: the step asks
        try:
            state = core.step(max(deadline, cycles + 1))
        except InterfaceViolationError as error:
            self._place(error)
            raise
        if state == "run" and core.idle_loop():
            if core.active:
                raise FirmwareStoppedError(core.report(Stop.HANG, f"endless loop (b .) in the handler of exception "
                                                  f"{core.active[-1]}"))  # fmt: skip
            core.sleeping = True
        if core.sleeping:  # MCU-41: the budget bounds the work between two waits (and passes, MCU-43)
            self._limit = core.instructions + self._budget
            if self._setting_up:  # MCU-45: the first wait ends the set-up
                self._set_up()

    def _set_up(self) -> None:
        """MCU-45: the firmware's set-up has ended (the core's first wait or first arrival at :data:`SERVE_POINT`,
        the core's clock now): the master starts now (:class:`~supi3.sdk.bench.MasterStart`, the firmware bench's
        rule), unless :data:`~supi3.sdk.bench.START_WAIT_S` has passed."""
        self._setting_up = False
        at = self._seconds(self.core.cycles)
        if self._bench is None:
            self._start.set_up(at)
        else:
            self._bench.set_up_done(at)

    def _place(self, error: InterfaceViolationError) -> None:
        """Note on ``error`` where the firmware broke the rule (once)."""
        if any(note.startswith("firmware at ") for note in getattr(error, "__notes__", ())):
            return
        where = next((v for v in reversed(self.violations) if v.error is error), None)
        if where is None:  # raised by the bus between two accesses: where the core stopped
            where = ViolationAt.now(self.core, self.core.time_s, error)
        error.add_note(f"firmware at {where.place}")

    # -- running at pin level ------------------------------------------------------------------------------------

    def _run_pin(self, done: Callable[[], bool], max_instructions: int, end_s: float | None = None) -> None:
        core, ring, master = self.core, self.ring, self._master
        self._set_budget(max_instructions)
        ended, ended_s = core.cycles, ring.now  # the core cycle and bus time the last master cycle ended (MCU-30)
        try:
            while not done():
                if self._idle_to(end_s):  # to the next start, in the next run as at transaction level (MCU-64)
                    continue
                start = ring.now
                if self._cycles_done:
                    master.cycle()
                else:
                    ring.settle()  # the power-up reset stretch (as supi3 demo --vcd)
                    while not self._start.due(ring.now):  # MCU-45: the set-up's end, at the latest START_WAIT_S
                        ring.status_telegram()
                    master.start()
                self._cycles_done += 1
                ended, ended_s = core.cycles, ring.now
                if self._cycle_time_s is not None:  # on its schedule: no drift from the line's whole telegrams
                    on_time = abs(start - self._next_start) < self._telegram_s
                    self._next_start = (self._next_start if on_time else start) + self._cycle_time_s
            if end_s is not None:
                return
            self._passes.begin(ended)  # MCU-30: the passes count from the last cycle's end (not a cycle time's idle)
            wait = self._wait
            wait.begin(ended_s)  # MCU-55: the line idles in status telegrams, at most SERVE_TELEGRAMS of them
            while not self._served() and not wait.over(ring.now):  # an /IRQ edge counts once it pends EXTI0 (MCU-64)
                ring.status_telegram()
            self.served = self._served()
        except InterfaceViolationError as error:
            self._place(error)
            raise

    def _idle_to(self, end_s: float | None) -> bool:
        """Idle status telegrams up to the next cycle's start (``cycle_time_s``), not past ``end_s``; whether any
        (the line idles in whole telegrams: a wait under half of one is none)."""
        until = self._next_start if end_s is None else min(self._next_start, end_s)
        ring = self.ring
        before = ring.cycle
        ring.idle(max(0.0, until - ring.now))
        return ring.cycle != before

    def _lockstep(self, clock: int) -> None:
        """:attr:`LockstepRing.runner`: run the firmware and the chip until the chip has clocked ``clock`` cycles
        (MCU-14: the chip catches up at each peripheral access and every :data:`~supi3.mcu.pins.SYNC_S`; a sleeping
        core sleeps until the chip clock where /IRQ or /ModAck changes)."""
        core, ring = self.core, self.ring
        end = ring.core_cycle(clock)
        interval = max(1, self._cycles(SYNC_S))
        while ring.cycle < clock:
            if core.cycles >= end:  # the core ran past the chip's target in its last block
                ring.sync(clock)
                break
            tick = core.systick.due()
            self._request()
            if core.sleeping:
                stop = clock if tick is None else min(clock, ring.clock_of(tick))
                held: list[tuple[str, int, int]] = []
                self._held = held
                try:
                    reached = ring.sync(stop, until_edge=True)
                finally:
                    self._held = None
                wake = ring.core_cycle(reached - 1) if held else (end if stop == clock else tick)
                self._step(max(core.cycles, wake if wake is not None else end))
                for edge in held:
                    self._pin_edge(*edge)
                continue
            deadline = min(end, core.cycles + interval, end if tick is None else tick)
            self._step(deadline)
            ring.sync(min(clock, ring.clock_of(core.cycles)))


def _reverse(byte: int) -> int:
    return int(f"{byte:08b}"[::-1], 2)

"""The RTL chip as a back end of the Python firmware driver: cocotb drives its pins, Verilator simulates it.

Ref: IBS SUPI 3 OPC UM E rev. 05, 3.4.2 and Table 3-7 (a frame's edges), Tables 3-5, 3-6, 3-9 (the µP pins on
MFP[7..0]), 3.4.14 (/IRQ, the I/O bit); guide docs/sdk-firmware-python.md, "The RTL back end".

Everything here runs inside a cocotb 2.x simulation of :class:`supi3.rtl.chip.Supi3ChipRtl` (top ``supi3_chip``,
:func:`supi3.rtl.chip.verilog`), on its 32 MHz clock:

- :class:`RtlBoard`: the chip on a board: clock, straps, the quiet board inputs, the power-up reset, the MFP input
  levels the µP drives, and a record of the return line ``di1``;
- :class:`RtlTransport`: an :class:`~supi3.sdk.driver.AsyncTransport` on the µP pins (SCLK, /SS, SerIN/SerOUT,
  Ser_IN/OUT and S/R in Intel mode, C/D, /IRQ, I/O, SAS_INIT) with the edges of
  :class:`supi3.spi.master.MasterTiming` (Table 3-7): ``AsyncSupi3Driver(RtlTransport(board, mode))``;
- :class:`BridgedTransport`: any ``AsyncTransport`` as a synchronous :class:`~supi3.sdk.driver.Transport` for code
  run in a ``cocotb.task.bridge`` thread (each call is ``cocotb.task.resume``-d), so the very same synchronous firmware
  (:mod:`supi3.sdk.examples`) runs on the RTL;
- :class:`RtlRing`: the INTERBUS line through the RTL chip as the :class:`~supi3.interbus.ring.Bus` of a
  :class:`~supi3.interbus.master.Master` (the line levels of :class:`supi3.model.pinring.PinRing`, driven on ``do1``
  and received from ``di1``);
- :class:`RtlBench`: master, ring, chip and firmware together, with the ``master`` and ``run(cycles)`` of
  :class:`supi3.sdk.bench.Bench`; :meth:`RtlBench.call` runs a synchronous scenario while the firmware runs beside
  it, each in its own bridge thread.

Decisions (docs/assumptions/sdk.md): the board's pins change at falling clock edges, a frame's edges are
:meth:`MasterTiming.fastest` (FW-11); the firmware's interrupt input is level-sensitive and taken between main-loop
passes (FW-12); :class:`RtlRing` is :class:`PinRing` with the RTL on the line (FW-13).
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable
from typing import Any, Final, TypeVar

import cocotb
import numpy as np
import numpy.typing as npt
from cocotb.clock import Clock
from cocotb.task import bridge, resume
from cocotb.triggers import Edge, Event, FallingEdge, First, Timer
from cocotb.utils import get_sim_time

from supi3.checks import check_bool, check_instance, check_int, check_real, check_trace, describe
from supi3.config import DeviceConfig, MfpKind
from supi3.errors import Supi3Error
from supi3.interbus import wire
from supi3.interbus.master import Master
from supi3.model.pinring import PinRing
from supi3.model.pins import Supi3Pins
from supi3.pinout import EXPANSION_BITS, MFP_PINS, UP_INPUT_IDLE, UP_INPUTS, UP_OUTPUTS
from supi3.sdk.bench import PIN_READ_S, Firmware
from supi3.sdk.driver import AsyncTransport, DriverArgumentError, Mode, Supi3Driver, Transport
from supi3.spi.master import MasterTiming
from supi3.tables import CLOCK_HZ
from supi3.verif.straps import strap_inputs

__all__ = [
    "CLOCK_PS",
    "PIN_READ_CLOCKS",
    "BridgedTransport",
    "RtlBench",
    "RtlBoard",
    "RtlBoardError",
    "RtlRing",
    "RtlTransport",
]

_T = TypeVar("_T")

CLOCK_PS: Final[int] = round(1e12 / CLOCK_HZ)
"""The chip clock's period in ps (32 MHz: 31 250 ps); simulate with a 1 ps precision."""
_QUIET: Final[dict[str, int]] = {"di2": 0, "rbst_ext": 0, "stat_err_n": 1, "resu_n": 1, "vmon_ok": 1}
"""The board inputs other than the line and the MFPs: last device in the ring, no fault, power good."""
PIN_READ_CLOCKS: Final[int] = math.ceil(PIN_READ_S * CLOCK_HZ)
"""FW-9 on the RTL: one read of the I/O pin by the firmware costs :data:`supi3.sdk.bench.PIN_READ_S` (8 clocks)."""
_RESET_POLL_CLOCKS: Final[int] = 16
"""How often :meth:`RtlBoard.start` looks whether the power-up reset has ended."""


class RtlBoardError(Supi3Error, RuntimeError):
    """The RTL board used out of order: before :meth:`RtlBoard.start`, started twice, a pin the chip does not drive
    read as a level, :meth:`RtlBench.call` while another runs."""


class RtlBoard:
    """The RTL chip (``supi3_chip``) on a board in a running cocotb simulation.

    Parameters
    ----------
    dut:
        The cocotb handle of the ``supi3_chip`` top.
    config:
        The straps (an Init-µP mode for the µP interface to be live).
    """

    def __init__(self, dut: Any, config: DeviceConfig) -> None:
        self.dut = dut
        self.config = check_instance("config", config, DeviceConfig)
        straps = strap_inputs(config)
        expansion = straps.pop("mfp_expansion") << (MFP_PINS - EXPANSION_BITS)  # MFP[15..12] (Table 2-4)
        self._straps = straps
        self.mfp_in = expansion | sum(level << UP_INPUTS[name] for name, level in UP_INPUT_IDLE.items())
        self._di1: list[tuple[int, int]] = []  # (first clock index, level) of each change of di1
        self._di1_level = 1
        self.started = False
        """Whether :meth:`start` ran: the clock runs and the power-up reset is over."""

    def require_started(self, what: str) -> None:
        """Raise :class:`RtlBoardError` unless :meth:`start` ran (without the clock every wait would hang)."""
        if not self.started:
            raise RtlBoardError(f"{what} before RtlBoard.start(): the chip's clock does not run yet")

    # -- time --------------------------------------------------------------------------------------------------

    @staticmethod
    def clock() -> int:
        """The current clock cycle (cycle ``k`` begins at its rising edge, ``k * CLOCK_PS``)."""
        return int(get_sim_time("ps")) // CLOCK_PS

    async def align(self) -> None:
        """Wait, if need be, for the next falling clock edge, where the board changes its pins (FW-11)."""
        if int(get_sim_time("ps")) % CLOCK_PS != CLOCK_PS // 2:
            await FallingEdge(self.dut.clk)

    @staticmethod
    async def clocks(count: int) -> None:
        """Let ``count`` (>= 0) clock cycles pass (from a falling edge, to a falling edge)."""
        if check_int("count", count, 0) > 0:
            await Timer(count * CLOCK_PS, unit="ps")

    # -- power-up ----------------------------------------------------------------------------------------------

    async def start(self) -> None:
        """Straps and quiet inputs, the clock, ``rst`` over a rising edge, then wait out the chip's power-up reset (the
        µP block is held in reset while ``resu_drive`` is 1) and start recording ``di1``. Once per board object (a
        second clock on ``clk`` and a second record of ``di1`` would run beside the first): make a new
        :class:`RtlBoard` for each cocotb test."""
        if self.started:
            raise RtlBoardError("RtlBoard.start() called again: the clock and di1's record run already; make a new "
                                "RtlBoard for each cocotb test")  # fmt: skip
        self.started = True
        dut = self.dut
        for name, value in {**self._straps, **_QUIET, "do1": wire.IDLE_LEVEL}.items():
            getattr(dut, name).value = value
        dut.mfp_in.value = self.mfp_in
        dut.rst.value = 1
        Clock(dut.clk, CLOCK_PS, unit="ps").start()
        await FallingEdge(dut.clk)
        await self.clocks(1)  # a rising edge with rst high, whatever level an earlier test's clock stopped at
        dut.rst.value = 0
        await self.clocks(1)
        while int(dut.resu_drive.value):
            await self.clocks(_RESET_POLL_CLOCKS)
        self._di1_level = int(dut.di1.value)
        cocotb.start_soon(self._watch_di1())

    async def _watch_di1(self) -> None:
        di1 = self.dut.di1
        while True:
            await Edge(di1)
            # A change after the rising edge that begins cycle k is the level of samples k, k + 1, ...
            self._di1.append((math.ceil(int(get_sim_time("ps")) / CLOCK_PS - 0.5), int(di1.value)))

    def returned(self, first: int, count: int) -> npt.NDArray[np.uint8]:
        """``di1`` in clock cycles ``first`` to ``first + count - 1`` (both >= 0); forgets what came before them."""
        first, count = check_int("first", first, 0), check_int("count", count, 0)
        samples = np.full(count, self._di1_level, dtype=np.uint8)
        kept: list[tuple[int, int]] = []
        for cycle, level in self._di1:
            if cycle < first + count:
                samples[max(cycle - first, 0) :] = level
                self._di1_level = level
            else:
                kept.append((cycle, level))
        self._di1 = kept
        return samples

    # -- pins --------------------------------------------------------------------------------------------------

    def drive_up(self, **levels: int) -> None:
        """Set µP input pins by name (``sclk``, ``ss_n``, ``mfp6``, ``mfp7``, ``sas_init``; Tables 3-5, 3-6) to 0 or
        1; a name that is no µP input or a level that is no bit changes no pin."""
        value = self.mfp_in
        for name, level in levels.items():
            if name not in UP_INPUTS:
                raise DriverArgumentError("name", name, f"pin must be one of the µP inputs {sorted(UP_INPUTS)} "
                                          f"(Tables 3-5, 3-6), not {name!r}")  # fmt: skip
            bit = 1 << UP_INPUTS[name]
            value = value | bit if check_int(name, level, 0, 1) else value & ~bit
        if value != self.mfp_in:
            self.mfp_in = value
            self.dut.mfp_in.value = value

    def up_output(self, name: str) -> int | None:
        """A µP output pin's level (``io``, ``c_d``, ``irq_n``, ``mfp6``, ``mfp7``), ``None`` while undriven."""
        if name not in UP_OUTPUTS:
            raise DriverArgumentError("name", name, f"name must be one of the µP outputs {sorted(UP_OUTPUTS)} "
                                      f"(Tables 3-5, 3-6), not {describe(name)}")  # fmt: skip
        bit = UP_OUTPUTS[name]
        if not (int(self.dut.mfp_oe.value) >> bit) & 1:
            return None
        return (int(self.dut.mfp_out.value) >> bit) & 1

    def set_stat_err(self, active: bool) -> None:
        """Drive /StatErr (3.6.2): ``True`` pulls it low."""
        self.dut.stat_err_n.value = int(not check_bool("active", active))

    def status_pin(self, name: str) -> int:
        """A status output the chip always drives in the µP modes (``c_d``, ``irq_n``, ``io``; UP-24) as a level;
        :class:`RtlBoardError` if it is undriven (the board not started, or not strapped for Init-µP): ``None``
        would tell the driver the board does not wire the pin and turn its checks off."""
        level = self.up_output(name)
        if level is None:
            raise RtlBoardError(f"{name} is not driven by the chip: a status output is driven in the Init-µP mode "
                                "once the power-up reset is over (UP-24)")  # fmt: skip
        return level

    async def irq_low_or(self, stop: Event) -> None:
        """Return once /IRQ is low, or ``stop`` is set."""
        while self.up_output("irq_n") != 0 and not stop.is_set():
            await First(Edge(self.dut.mfp_out), stop.wait())


class RtlTransport(AsyncTransport):
    """The firmware's SPI port and status pins on the RTL chip: one frame per byte (3.4.2), Table 3-7 edges.

    Parameters
    ----------
    board:
        The running chip.
    mode:
        The µP interface type: Motorola (SerIN = MFP6, SerOUT = MFP7, MSB first) or Intel (Ser_IN/OUT = MFP6, S/R =
        MFP7, LSB first) (Tables 3-5, 3-6, 3-9).
    timing:
        Edge placement in chip clocks; default :meth:`MasterTiming.fastest` at the chip's bit rate.
    io_pin:
        Whether the I/O access pin (MFP1) is wired to the firmware: if not, :meth:`read_io` returns ``None`` and the
        driver polls D7 of the interrupt event register, the manual's polling method (3.4.14; FW-9, as
        ``Bench(io_pin=False)``).
    """

    def __init__(self, board: RtlBoard, mode: Mode = Mode.MOTOROLA, timing: MasterTiming | None = None, *,
                 io_pin: bool = True) -> None:  # fmt: skip
        self.board = check_instance("board", board, RtlBoard)
        if board.config.mfp_mode.kind is not MfpKind.INIT_UP:
            raise DriverArgumentError("board", board, f"board must be strapped for the Init-µP mode (Tables 3-1, "
                                      f"3-2): in {board.config.mfp_mode.name} the chip has no serial µP interface "
                                      "(as UpInterface)")  # fmt: skip
        if type(mode) is not Mode:
            raise DriverArgumentError("mode", mode, f"mode must be Mode.MOTOROLA or Mode.INTEL, not {describe(mode)}")
        self.mode = mode
        if timing is None:
            timing = MasterTiming.fastest(board.config.bit_rate)
        self.timing = check_instance("timing", timing, MasterTiming)
        self.io_pin = check_bool("io_pin", io_pin)
        self.frames = 0

    async def xfer(self, tx: int, s_r: bool) -> int:
        """/SS high for the gap (S/R set at its start in Intel mode), /SS low, eight SCLK periods (data out at each
        fall, the chip's bit sampled at each rise), SCLK high until /SS rises (UP-5 to UP-9). ``tx`` one byte,
        ``s_r`` a bool, as from the driver (checked: a direct caller's 300 would go out as 2Ch)."""
        if type(tx) is not int or not 0 <= tx <= 0xFF:
            tx = check_int("tx", tx, 0, 0xFF, "one byte")
        s_r = check_bool("s_r", s_r)
        board, t = self.board, self.timing
        board.require_started("RtlTransport.xfer()")
        intel = self.mode is Mode.INTEL
        sends = not intel or s_r
        await board.align()
        board.drive_up(ss_n=1, **({"mfp7": int(s_r)} if intel else {}))
        await board.clocks(t.gap)
        board.drive_up(ss_n=0)
        await board.clocks(t.lead)
        received = 0
        for i in range(8):
            shift = i if self.mode.lsb_first else 7 - i
            board.drive_up(sclk=0, **({"mfp6": (tx >> shift) & 1} if sends else {}))
            await board.clocks(t.low)
            bit = board.up_output("mfp6" if intel else "mfp7")
            received |= (bit or 0) << shift
            board.drive_up(sclk=1)
            await board.clocks(t.high if i < 7 else t.trail)
        board.drive_up(ss_n=1)
        self.frames += 1
        return received

    async def delay_us(self, us: float) -> None:
        """Wait whole clocks, at least ``us`` (a finite number >= 0)."""
        clocks = math.ceil(check_real("us", us, 0.0) * 1e6 / CLOCK_PS)
        self.board.require_started("RtlTransport.delay_us()")
        await self.board.align()
        await self.board.clocks(clocks)

    async def read_cd(self) -> int | None:
        """C/D (MFP2) once the last frame's /SS rise has settled (t6 of Table 3-7, a gap)."""
        self.board.require_started("RtlTransport.read_cd()")
        await self.board.align()
        await self.board.clocks(self.timing.gap)
        return self.board.status_pin("c_d")

    async def read_irq(self) -> int | None:
        """/IRQ (MFP3)."""
        self.board.require_started("RtlTransport.read_irq()")
        return self.board.status_pin("irq_n")

    async def read_io(self) -> int | None:
        """The I/O access pin (MFP1), read in :data:`PIN_READ_CLOCKS` (so a loop polling it lets the bus run);
        ``None`` if the pin is not wired (``io_pin``)."""
        if not self.io_pin:
            return None
        self.board.require_started("RtlTransport.read_io()")
        await self.board.align()
        await self.board.clocks(PIN_READ_CLOCKS)
        return self.board.status_pin("io")

    async def set_sas_init(self, level: int) -> bool:
        """SAS_INIT (MFP0), 1 = active."""
        level = check_int("level", level, 0, 1)
        self.board.require_started("RtlTransport.set_sas_init()")
        await self.board.align()
        self.board.drive_up(sas_init=level)
        return True


class BridgedTransport(Transport):
    """An :class:`AsyncTransport` as a synchronous :class:`Transport`, for code run with ``cocotb.task.bridge``: each
    call blocks its thread while the simulation runs the awaitable (``cocotb.task.resume``)."""

    def __init__(self, inner: AsyncTransport) -> None:
        if not isinstance(inner, AsyncTransport):
            raise DriverArgumentError("inner", inner, f"inner must be a supi3.sdk.driver.AsyncTransport, not "
                                      f"{describe(inner)}")  # fmt: skip
        self.inner = inner

    def xfer(self, tx: int, s_r: bool) -> int:
        """As :meth:`AsyncTransport.xfer`, blocking."""
        return resume(self.inner.xfer)(tx, s_r)

    def delay_us(self, us: float) -> None:
        """As :meth:`AsyncTransport.delay_us`, blocking."""
        resume(self.inner.delay_us)(us)

    def read_cd(self) -> int | None:
        """As :meth:`AsyncTransport.read_cd`, blocking."""
        return resume(self.inner.read_cd)()

    def read_irq(self) -> int | None:
        """As :meth:`AsyncTransport.read_irq`, blocking."""
        return resume(self.inner.read_irq)()

    def read_io(self) -> int | None:
        """As :meth:`AsyncTransport.read_io`, blocking."""
        return resume(self.inner.read_io)()

    def set_sas_init(self, level: int) -> bool:
        """As :meth:`AsyncTransport.set_sas_init`, blocking."""
        return resume(self.inner.set_sas_init)(level)


class RtlRing(PinRing):
    """The INTERBUS line through the RTL chip: :class:`PinRing`'s telegrams, receiver and Bus protocol, with the
    forward line driven on ``do1`` and the return line read from ``di1``. Call it from a ``cocotb.task.bridge`` thread
    (the master's calls block while the simulation runs)."""

    def __init__(self, board: RtlBoard) -> None:
        # The model of the same straps stands for the chip in PinRing's bookkeeping (bit rate, ring size); the
        # line runs through the RTL.
        super().__init__([Supi3Pins(check_instance("board", board, RtlBoard).config)])
        self.board = board

    def run_samples(self, samples: npt.NDArray[np.uint8]) -> None:
        """Drive ``samples`` (one level per clock, 0 or 1, as :meth:`PinRing.run_samples`) on ``do1`` and append what
        ``di1`` returned meanwhile."""
        forward = check_trace("samples", samples, 1).astype(np.uint8, copy=False)
        if not len(forward):
            return
        self.board.require_started("RtlRing.run_samples()")
        returned = resume(self._drive)(forward)
        self.cycle += len(forward)
        self.returned = np.concatenate([self.returned, returned])

    async def _drive(self, samples: npt.NDArray[np.uint8]) -> npt.NDArray[np.uint8]:
        board = self.board
        await board.align()
        first = board.clock()
        changes = np.flatnonzero(np.diff(samples)) + 1
        starts = [0, *changes.tolist()]
        ends = [*changes.tolist(), len(samples)]
        do1 = board.dut.do1
        for start, end in zip(starts, ends, strict=True):
            do1.value = int(samples[start])
            await board.clocks(end - start)
        return board.returned(first, len(samples))


class RtlBench:
    """The RTL chip with its firmware and an INTERBUS master: :class:`supi3.sdk.bench.Bench`'s ``master`` and
    ``run(cycles)`` on the RTL.

    Parameters
    ----------
    board:
        The started chip (:meth:`RtlBoard.start`).
    firmware:
        The synchronous firmware (the same class the model bench runs).
    mode:
        The interface type the firmware initializes (the transport's bit order).
    cycle_time_s:
        A master cycle starts this often (the line idles between); ``None``: back to back.
    io_pin:
        Whether the firmware reads the I/O access pin (:class:`RtlTransport`); ``False`` for the polling examples,
        as on the model bench (FW-9).

    Call :meth:`call` from the cocotb test: it runs the firmware's setup, then the firmware and the given synchronous
    scenario side by side (bridge threads), and stops the firmware when the scenario returns.
    """

    def __init__(self, board: RtlBoard, firmware: Firmware, *, mode: Mode = Mode.MOTOROLA,
                 cycle_time_s: float | None = None, io_pin: bool = True) -> None:  # fmt: skip
        self.board = check_instance("board", board, RtlBoard)
        self.firmware = check_instance("firmware", firmware, Firmware)
        self.transport = RtlTransport(board, mode, io_pin=io_pin)
        self.driver = Supi3Driver(BridgedTransport(self.transport))
        self.ring = RtlRing(board)
        self.master = Master(self.ring)
        self.cycle_time_s = None if cycle_time_s is None else check_real("cycle_time_s", cycle_time_s, 0.0)
        self.cycles = 0
        self.interrupts = 0
        self._stop = Event()
        self._stopping = threading.Event()
        self._set_up = False
        self._calling = False

    def run(self, cycles: int) -> None:
        """Run ``cycles`` more master cycles (the first call starts the master: Alarm Stop and discovery)."""
        for _ in range(check_int("cycles", cycles, 0)):
            start = self.ring.now
            if self.cycles:
                self.master.cycle()
            else:
                self.master.start()
            self.cycles += 1
            if self.cycle_time_s is not None:
                self.ring.idle(max(0.0, start + self.cycle_time_s - self.ring.now))

    def _firmware(self) -> None:
        firmware, driver = self.firmware, self.driver
        has_loop = type(firmware).loop is not Firmware.loop
        while not self._stopping.is_set():
            if resume(self.transport.read_irq)() == 0:
                self.interrupts += 1
                firmware.isr(driver)
            elif has_loop:
                firmware.loop(driver)
            else:
                resume(self.board.irq_low_or)(self._stop)

    def _scenario(self, scenario: Callable[[], _T]) -> _T:
        try:
            return scenario()
        finally:
            self._stopping.set()
            resume(self._set_stop)()

    async def _set_stop(self) -> None:
        self._stop.set()

    async def call(self, scenario: Callable[[], _T]) -> _T:
        """Run the firmware's setup (at the first call only: power-up, as ``Bench.power_up``), then ``scenario()``
        with the firmware running; return what it returns. Calls run one after the other (each starts the firmware
        again where the last left it); one while another runs is an :class:`RtlBoardError`. Whatever the scenario
        raises is raised once the firmware has stopped."""
        if not callable(scenario):
            raise DriverArgumentError("scenario", scenario, f"scenario must be a callable, not {describe(scenario)}")
        self.board.require_started("RtlBench.call()")
        if self._calling:
            raise RtlBoardError("RtlBench.call() while another call runs: await it first")
        self._calling = True
        try:
            if not self._set_up:
                self._set_up = True
                await bridge(self.firmware.setup)(self.driver)
            self._stop = Event()
            self._stopping.clear()
            running = cocotb.start_soon(bridge(self._firmware)())
            try:
                result = await bridge(self._scenario)(scenario)
            finally:
                await running
        finally:
            self._calling = False
        return result

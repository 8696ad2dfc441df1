"""SPI1's read of DR after its byte, offered to the core and answered in native code (MCU-26).

MCU-26: a write of SPI1's DR holds SR as a read of SR would then, and while SR is held with a byte shifting into an
empty receive buffer, the byte's read of DR from its end on is offered to the core: ``supi3_held_read`` (hook.c)
answers it and the SR reads after it, and the model catches up at its next access. The real native read callback,
driven over random histories of waits, reads, writes and clock switches, gives the same values, poll skips and model
state as the model answering every read; the board does the same work to the cycle with the offer and without it,
and fewer reads reach the model.
"""

from __future__ import annotations

import ctypes
from collections.abc import Callable
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.mcu import build as mcu_build
from supi3.mcu import hook
from supi3.mcu.board import Board
from supi3.mcu.core import CPUS, HeldRegister
from supi3.mcu.stm32 import (
    APB2ENR,
    CR1_CPHA,
    CR1_CPOL,
    CR1_DFF,
    CR1_MSTR,
    CR1_SPE,
    CR1_SSI,
    CR1_SSM,
    SPI1EN,
    SPI_CR1,
    SPI_DR,
    SPI_SR,
    PeripheralClockError,
    Rcc,
    Spi,
)
from supi3.sdk import native

pytestmark = pytest.mark.skipif(mcu_build.toolchain_missing() is not None, reason=str(mcu_build.toolchain_missing()))


class Core:
    """What the core gives a peripheral: the time of an access (the running block's end, never earlier than a time
    handed out, as :meth:`supi3.mcu.core.CortexM.cycles_polled`) in the native hook's state."""

    def __init__(self) -> None:
        self.state = hook.State()
        self.state.skip_polls = self.state.block_poll = 1

    def __call__(self) -> int:
        state = self.state
        state.handed = max(state.handed, state.cycles)
        return int(state.handed)

    def skip_poll(self, until: int) -> None:
        """:meth:`supi3.mcu.core.CortexM.skip_poll` in a pure poll loop."""
        self.state.skip_until, self.state.skip_pending = until, 1


class Wire:
    """The far end of the SPI lines: each byte receives :attr:`driven` (the board's chip drives its byte from /SS's
    fall on, which the board tells SPI1 when it arms a write, MCU-27); keeps what it saw."""

    def __init__(self) -> None:
        self.driven = 0xA5
        self.seen: list[tuple[int, int, int, int]] = []

    def spi_byte(self, tx: int, bits: int, start: int, period: int, cr1: int) -> int:
        del cr1
        self.seen.append((tx, bits, start, period))
        return self.driven


class Mapped:
    """SPI1 mapped as :meth:`supi3.mcu.core.CortexM.mmio` maps it: each read and write goes to hook.c's
    ``supi3_held_read`` and ``supi3_held_write`` first, which call the model (``slow``) for what they do not answer;
    an armed write's catch-up runs before any call into the model (``deferred``), as the core runs it. An access's
    time is the clock (the block's entry; no instruction before it in the block)."""

    def __init__(self, spi: Spi, core: Core) -> None:
        self.spi, self.core = spi, core
        self.failure: BaseException | None = None
        self.slow = 0
        self.deferred: list[Callable[[], None]] = []

        def slow_read(handle: int, offset: int, size: int, data: int) -> int:
            del handle, data
            return self._slow(lambda: spi.read(offset, size))

        def slow_write(handle: int, offset: int, size: int, value: int, data: int) -> None:
            del handle, data
            self._slow(lambda: spi.write(offset, size, value))

        self._callbacks = (hook.MMIO_READ(slow_read), hook.MMIO_WRITE(slow_write))
        self.held = hook.Held(ctypes.pointer(core.state), self._callbacks[0])
        self.held.slow_write = self._callbacks[1]
        self.register = HeldRegister(self.held, self.deferred)
        library = hook.library()
        self._read, self._write = library.supi3_held_read, library.supi3_held_write
        self._read.restype, self._write.restype = ctypes.c_uint64, None
        self._read.argtypes = (ctypes.c_void_p, ctypes.c_uint64, ctypes.c_uint, ctypes.c_void_p)
        self._write.argtypes = (ctypes.c_void_p, ctypes.c_uint64, ctypes.c_uint, ctypes.c_uint64, ctypes.c_void_p)

    def catch_up(self) -> None:
        while self.deferred:
            self.deferred.pop(0)()

    def _slow(self, call: Callable[[], int | None]) -> int:
        self.slow += 1
        try:
            self.catch_up()
            return call() or 0
        except PeripheralClockError as error:  # raised after the native call (ctypes drops it)
            self.failure = error
            return 0

    def _native(self, call: Callable[[], int]) -> int:
        self.failure = None
        state = self.core.state
        state.block_start = state.cycles
        value = call()
        if self.failure is not None:
            raise self.failure
        return value

    def read(self, offset: int) -> int:
        return int(self._native(lambda: int(self._read(None, offset, 4, ctypes.byref(self.held)))))

    def write(self, offset: int, value: int) -> None:
        self._native(lambda: self._write(None, offset, 4, value, ctypes.byref(self.held)) or 0)


def _spi(core: Core) -> Spi:
    rcc = Rcc()
    rcc.write(APB2ENR, 4, SPI1EN)
    spi = Spi(rcc, core, Wire(), core)
    spi.write(SPI_CR1, 4, CR1_CPHA | CR1_CPOL | CR1_MSTR | CR1_SSM | CR1_SSI | CR1_SPE)  # BR = 0: 16 clocks a byte
    return spi


_READ = st.tuples(st.just("read"), st.sampled_from([SPI_SR] * 4 + [SPI_DR] * 3 + [SPI_CR1]))
_WAIT = st.tuples(st.just("wait"), st.integers(0, 24))
_STEP = st.one_of(
    _READ, _READ, _READ, _WAIT, _WAIT,
    # /SS falls: the board arms DR's write from `early` cycles ago to `late` cycles on, the chip drives `driven`
    # (MCU-27), then a wait
    st.tuples(st.just("arm"), st.integers(-4, 8), st.integers(0, 40), st.integers(0, 0xFF), st.integers(0, 12)),
    st.tuples(st.just("byte"), st.integers(0, 0xFF), st.integers(0, 40)),  # DR, SR until RXNE, DR, SR: board_xfer
    st.tuples(st.just("byte"), st.integers(0, 0xFF), st.integers(0, 40)),
    st.tuples(st.just("write"), st.just(SPI_DR), st.integers(0, 0xFF)),
    st.tuples(st.just("write"), st.just(SPI_CR1), st.sampled_from([0, 1, CR1_DFF]).map(lambda v: v | CR1_SPE)),
    st.tuples(st.just("clock"), st.sampled_from([SPI1EN, 0])),
)  # fmt: skip


def _history(steps: list[tuple[object, ...]], native: bool) -> tuple[list[object], list[int], object, int, int]:
    """Run ``steps`` on SPI1 mapped with the native callbacks (the hold, the offer and the armed write on) or with
    the model answering every access: the values read, the poll skips told, what the wire saw and the model's state
    once it has caught up, the latest time handed out, the accesses that reached the model."""
    core = Core()
    spi = _spi(core)
    assert isinstance(spi.wire, Wire)
    wire = spi.wire
    polls: list[int] = []
    mapped = Mapped(spi, core)
    state = core.state
    if native:
        spi.holder = spi.offer = mapped.register
        spi.on_poll = core.skip_poll
    else:
        spi.on_poll = polls.append
    accesses = 0

    def read(offset: int) -> int:
        nonlocal accesses
        accesses += 1
        state.skip_pending = 0
        value = mapped.read(offset) if native else spi.read(offset, 4)
        if native and state.skip_pending:
            polls.append(int(state.skip_until))
        return value

    def write(offset: int, value: int) -> None:
        nonlocal accesses
        accesses += 1
        if native:
            mapped.write(offset, value)
        else:
            spi.write(offset, 4, value)

    seen: list[object] = []
    for step in steps:
        values = [int(str(value)) for value in step[1:]]
        try:
            if step[0] == "wait":
                state.cycles += values[0]
            elif step[0] == "read":
                seen.append(read(values[0]))
            elif step[0] == "arm":
                mapped.catch_up()  # the board arms in a GPIO write: a call into the peripherals
                wire.driven = values[2]
                start = max(0, state.cycles - values[0])
                spi.arm_byte(start, start + values[1], values[2])
                state.cycles += values[3]
            elif step[0] == "byte":
                write(SPI_DR, values[0])
                for _ in range(8):
                    state.cycles += values[1] // 8 + 1
                    seen.append(value := read(SPI_SR))
                    if value & 1:
                        break
                seen += [read(SPI_DR), read(SPI_SR)]
            elif step[0] == "write":
                write(values[0], values[1] | (CR1_MSTR | CR1_SSM | CR1_SSI) * (values[0] == SPI_CR1))
            else:
                mapped.catch_up()
                spi.rcc.write(APB2ENR, 4, values[0])
        except PeripheralClockError as error:
            seen.append(str(error))
    told = list(polls)
    mapped.catch_up()
    spi.rcc.write(APB2ENR, 4, SPI1EN)
    seen.append(spi.read(SPI_SR, 4))  # the model catches up with the time (a hold or an offer leaves it behind)
    model = (spi.cr1, spi.ovr, spi.modf, spi.tx_buffer, spi.rx_buffer, spi.rx_last, spi.shifting, spi.transfers,
             wire.seen)  # fmt: skip
    return seen, told, model, int(state.handed), mapped.slow if native else accesses


@settings(derandomize=True, max_examples=300, deadline=None)
@given(st.lists(_STEP, min_size=20, max_size=80))
def test_the_native_answers_are_the_model_s(steps: list[tuple[object, ...]]) -> None:
    """MCU-26, MCU-27 with the native callbacks themselves: over random histories of waits, reads, writes of DR
    armed by the board or not, whole bytes as the board port moves them, other writes, clock switches and faults (a
    clock switched off raises in both), answering SR, the offered read of DR and the armed write of DR natively
    gives the same values, poll skips, bytes on the wire (value, time), handed-out times and model state as the
    model answering every access, and no more accesses reach the model."""
    native_run, model_run = _history(steps, True), _history(steps, False)
    assert native_run[:4] == model_run[:4]
    assert native_run[4] <= model_run[4]


def test_a_byte_costs_the_model_no_call() -> None:
    """MCU-26, MCU-27: after the board arms DR's write (/SS fell), the write of DR, the status reads until RXNE, the
    read of DR and the status read after it are all answered natively (the board port's byte), and the model,
    caught up at its next access, is where they left it: the byte sent at the write's time and received, RXNE clear,
    not busy."""
    core = Core()
    spi = _spi(core)
    mapped = Mapped(spi, core)
    spi.holder = spi.offer = mapped.register
    assert isinstance(spi.wire, Wire)
    core.state.cycles = 5
    spi.arm_byte(4, 20, spi.wire.driven)
    mapped.write(SPI_DR, 0x5A)
    values = [mapped.read(SPI_SR)]
    core.state.cycles = 21
    values += [mapped.read(SPI_SR), mapped.read(SPI_DR), mapped.read(SPI_SR)]
    assert values == [0x82, 0x03, spi.wire.driven, 0x02]  # TXE BSY; RXNE TXE; the byte; TXE
    assert mapped.slow == 0 and spi.transfers == 0  # nothing reached the model yet
    assert mapped.read(SPI_DR) == spi.wire.driven == spi.rx_last  # a second read: the model catches up first
    assert mapped.slow == 1 and spi.wire.seen == [(0x5A, 8, 5, 2)]
    assert spi.rx_buffer is None and spi.shifting is None and spi.transfers == 1


@pytest.fixture(scope="module")
def digital_io(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """The digital 16/16 example for each core at the port's SPI1 clock, and for the Cortex-M3 at 3 MHz (issue
    #13's bench case)."""
    folder = tmp_path_factory.mktemp("offer")
    elves = {cpu: mcu_build.build(native.example("digital_io"), folder / f"dio_{cpu}.elf", cpu=cpu) for cpu in CPUS}
    elves["br3"] = mcu_build.build(native.example("digital_io"), folder / "br3.elf", defines={"BOARD_SPI_BR": "3u"})
    return elves


class Counted:
    """The core's offered reads and armed writes (``reads``, ``writes``: which of them are on), counting those the
    core took natively."""

    def __init__(self, inner: HeldRegister, reads: bool, writes: bool) -> None:
        self.inner, self.reads, self.writes = inner, reads, writes
        self.taken = self.written = 0

    def offer(self, offset: int, value: int, start: int, then: int) -> None:
        if self.reads:
            self.inner.offer(offset, value, start, then)

    def withdraw(self) -> int | None:
        taken = self.inner.withdraw()
        self.taken += taken is not None
        return taken

    def arm_write(self, offset: int, start: int, end: int, length: int, hold: tuple[int, int, int],
                  offer: tuple[int, int, int], catch_up: Callable[[], None]) -> None:  # fmt: skip
        if self.writes:
            self.inner.arm_write(offset, start, end, length, hold, offer, catch_up)

    def disarm_write(self) -> tuple[int, int] | None:
        written = self.inner.disarm_write()
        self.written += written is not None
        return written


@pytest.mark.parametrize(("case", "bit_rate"), [("cortex_m3", 500_000), ("cortex_m0", 500_000), ("br3", 2_000_000)])
def test_the_offer_changes_nothing_on_the_board(digital_io: dict[str, Path], case: str, bit_rate: int) -> None:
    """MCU-26 and MCU-27 on the board (non-strict: issue #13's case breaks Table 3-7 in its handler): power-up and
    six data cycles give the same cycles, instructions, registers, bus time, interrupts, latency, process data and
    violations (time, PC, rule) with DR's write armed and its read offered, with the read offered only, and with
    neither; the core takes the armed writes and the offered reads."""
    runs = []
    for reads, writes in ((True, True), (True, False), (False, False)):
        board = Board(digital_io[case], cpu="cortex_m0" if case == "cortex_m0" else "cortex_m3", bit_rate=bit_rate,
                      strict=False)  # fmt: skip
        assert isinstance(board.spi.offer, HeldRegister)
        board.spi.offer = counted = Counted(board.spi.offer, reads, writes)
        board.run(3)
        board.bench.master.set_outputs(1, b"\x9a\xbc")
        assert board.fw_board is not None
        board.fw_board.inputs = b"\xde\xf0"
        board.run(6)
        core = board.core
        runs.append(((core.cycles, core.instructions, core.registers(), board.bench.now, board.interrupts,
                      board.irq_latency_s, board.fw_board.outputs, board.bench.master.inputs(1),
                      [(v.time_s, v.pc, v.error.rule) for v in board.violations]), counted.taken, counted.written))
    (both, taken, written), (offered, taken_alone, none), (plain, no_read, no_write) = runs
    assert both == offered == plain
    assert both[6:8] == (b"\x9a\xbc\0\0", b"\xde\xf0")
    assert taken > 9 * 4 and written > 9 * 4 and taken_alone > 9 * 4  # a data cycle: at least four bytes
    assert none == no_read == no_write == 0

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
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.mcu import build as mcu_build
from supi3.mcu import hook
from supi3.mcu.board import Board
from supi3.mcu.core import HeldRegister
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
from support import digital_io_elves

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
    """The far end of the SPI lines: answers each byte with a value of its own."""

    def spi_byte(self, tx: int, bits: int, start: int, period: int, cr1: int) -> int:
        del bits, period, cr1
        return (tx * 7 + start) & 0xFF


class NativeReads:
    """SPI1 mapped as :meth:`supi3.mcu.core.CortexM.mmio` maps it: each read goes to hook.c's ``supi3_held_read``
    first, which calls the model (``slow``) for what it does not answer."""

    def __init__(self, spi: Spi, core: Core) -> None:
        self.spi, self.core = spi, core
        self.failure: BaseException | None = None
        self.slow = 0

        def slow(handle: int, offset: int, size: int, data: int) -> int:
            del handle, data
            self.slow += 1
            try:
                return spi.read(offset, size)
            except PeripheralClockError as error:  # raised after the native call (ctypes drops it)
                self.failure = error
                return 0

        self._slow = hook.MMIO_READ(slow)
        self.held = hook.Held(ctypes.pointer(core.state), self._slow)
        self._read = hook.library().supi3_held_read
        self._read.restype = ctypes.c_uint64
        self._read.argtypes = (ctypes.c_void_p, ctypes.c_uint64, ctypes.c_uint, ctypes.c_void_p)

    def read(self, offset: int) -> int:
        self.failure = None
        value = int(self._read(None, offset, 4, ctypes.byref(self.held)))
        if self.failure is not None:
            raise self.failure
        return value


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
    st.tuples(st.just("byte"), st.integers(0, 0xFF), st.integers(0, 40)),  # DR, SR until RXNE, DR, SR: board_xfer
    st.tuples(st.just("write"), st.just(SPI_DR), st.integers(0, 0xFF)),
    st.tuples(st.just("write"), st.just(SPI_CR1), st.sampled_from([0, 1, CR1_DFF]).map(lambda v: v | CR1_SPE)),
    st.tuples(st.just("clock"), st.sampled_from([SPI1EN, 0])),
)  # fmt: skip


def _history(steps: list[tuple[object, ...]], native_reads: bool) -> tuple[list[object], list[int], object, int, int]:
    """Run ``steps`` on SPI1 with the native read callback (the hold and the offer on) or with the model answering
    every read: the values read, the poll skips told, the model's state once it has caught up."""
    core = Core()
    spi = _spi(core)
    polls: list[int] = []
    reader = NativeReads(spi, core)
    state = core.state
    if native_reads:
        spi.holder = spi.offer = HeldRegister(reader.held)
        spi.on_poll = core.skip_poll
    else:
        spi.on_poll = polls.append
    reads = 0

    def read(offset: int) -> int:
        nonlocal reads
        reads += 1
        state.skip_pending = 0
        value = reader.read(offset) if native_reads else spi.read(offset, 4)
        if native_reads and state.skip_pending:
            polls.append(int(state.skip_until))
        return value

    seen: list[object] = []
    for step in steps:
        try:
            if step[0] == "wait":
                state.cycles += int(str(step[1]))
            elif step[0] == "read":
                seen.append(read(int(str(step[1]))))
            elif step[0] == "byte":
                spi.write(SPI_DR, 4, int(str(step[1])))
                for _ in range(8):
                    state.cycles += int(str(step[2])) // 8 + 1
                    seen.append(value := read(SPI_SR))
                    if value & 1:
                        break
                seen += [read(SPI_DR), read(SPI_SR)]
            elif step[0] == "write":
                spi.write(int(str(step[1])), 4, int(str(step[2])) | (CR1_MSTR | CR1_SSM | CR1_SSI) *
                          (step[1] == SPI_CR1))  # fmt: skip
            else:
                spi.rcc.write(APB2ENR, 4, int(str(step[1])))
        except PeripheralClockError as error:
            seen.append(str(error))
    told = list(polls)
    spi.rcc.write(APB2ENR, 4, SPI1EN)
    seen.append(spi.read(SPI_SR, 4))  # the model catches up with the time (a hold or an offer leaves it behind)
    model = (spi.cr1, spi.ovr, spi.modf, spi.tx_buffer, spi.rx_buffer, spi.rx_last, spi.shifting, spi.transfers)
    return seen, told, model, int(state.handed), reader.slow if native_reads else reads


@settings(derandomize=True, max_examples=300, deadline=None)
@given(st.lists(_STEP, min_size=20, max_size=80))
def test_the_offered_read_answers_as_the_model_would(steps: list[tuple[object, ...]]) -> None:
    """MCU-26 with the native read callback itself: over random histories of waits, reads, whole bytes as the board
    port moves them, writes, clock switches and faults (a clock switched off raises in both), answering SR and the
    offered read of DR natively gives the same values, poll skips, handed-out times and model state as the model
    answering every read, and no more reads reach the model."""
    native_run, model_run = _history(steps, True), _history(steps, False)
    assert native_run[:4] == model_run[:4]
    assert native_run[4] <= model_run[4]


def test_a_byte_costs_the_model_no_read() -> None:
    """MCU-26: after a write of DR, the status reads until RXNE, the read of DR and the status read after it are all
    answered natively (the board port's byte), and the model, caught up at its next access, is where the reads left
    it: the byte received, RXNE clear, not busy."""
    core = Core()
    spi = _spi(core)
    reader = NativeReads(spi, core)
    spi.holder = spi.offer = HeldRegister(reader.held)
    spi.write(SPI_DR, 4, 0x5A)
    received = Wire().spi_byte(0x5A, 8, 0, 2, 0)
    values = [reader.read(SPI_SR)]
    core.state.cycles = 16
    values += [reader.read(SPI_SR), reader.read(SPI_DR), reader.read(SPI_SR), reader.read(SPI_DR)]
    assert values[:4] == [0x82, 0x03, received, 0x02]  # TXE BSY; RXNE TXE; the byte; TXE
    assert reader.slow == 1  # only the second read of DR (the offer is one read) reached the model
    assert values[4] == received == spi.rx_last and spi.rx_buffer is None and spi.shifting is None


@pytest.fixture(scope="module")
def digital_io(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """The digital 16/16 example for each core at the port's SPI1 clock, and for the Cortex-M3 at 3 MHz (issue
    #13's bench case)."""
    return digital_io_elves(tmp_path_factory.mktemp("offer"))


class NoOffer:
    """A board whose SPI offers no read: every read of DR goes to the model."""

    def offer(self, offset: int, value: int, start: int, then: int) -> None:
        del offset, value, start, then

    def withdraw(self) -> int | None:
        return None


class Counted:
    """The core's offer, counting the reads it answered natively."""

    def __init__(self, offer: HeldRegister) -> None:
        self.inner, self.taken = offer, 0

    def offer(self, offset: int, value: int, start: int, then: int) -> None:
        self.inner.offer(offset, value, start, then)

    def withdraw(self) -> int | None:
        taken = self.inner.withdraw()
        self.taken += taken is not None
        return taken


@pytest.mark.parametrize(("case", "bit_rate"), [("cortex_m3", 500_000), ("cortex_m0", 500_000), ("br3", 2_000_000)])
def test_the_offer_changes_nothing_on_the_board(digital_io: dict[str, Path], case: str, bit_rate: int) -> None:
    """MCU-26 on the board (non-strict: issue #13's case breaks Table 3-7 in its handler): power-up and six data
    cycles give the same cycles, instructions, registers, bus time, interrupts, latency, process data and violations
    (time, PC, rule) with DR's read offered as without, and the offered reads are taken."""
    runs = []
    for offering in (True, False):
        board = Board(digital_io[case], cpu="cortex_m0" if case == "cortex_m0" else "cortex_m3", bit_rate=bit_rate,
                      strict=False)  # fmt: skip
        assert isinstance(board.spi.offer, HeldRegister)
        counted = Counted(board.spi.offer)
        board.spi.offer = counted if offering else NoOffer()
        board.run(3)
        board.bench.master.set_outputs(1, b"\x9a\xbc")
        assert board.fw_board is not None
        board.fw_board.inputs = b"\xde\xf0"
        board.run(6)
        core = board.core
        runs.append(((core.cycles, core.instructions, core.registers(), board.bench.now, board.interrupts,
                      board.irq_latency_s, board.fw_board.outputs, board.bench.master.inputs(1),
                      [(v.time_s, v.pc, v.error.rule) for v in board.violations]), counted.taken))  # fmt: skip
    (offered, taken), (plain, none) = runs
    assert offered == plain
    assert offered[6:8] == (b"\x9a\xbc\0\0", b"\xde\xf0")
    assert taken > 9 * 4 and none == 0  # at least four bytes a cycle (a data cycle's status, IN and OUT bytes)

"""Firmware in the loop: the SDK's example firmware as a Cortex-M0 and -M3 binary on the emulated board
(supi3.mcu.board) against the transaction-level chip, with the INTERBUS master exchanging data.

The binary is built once per module with ziglang (supi3.mcu.build: the C driver, the board port of
src/supi3/sdk/c/board, the example) and must give the process data the host build gives on the firmware bench
(tests/test_sdk_c_examples.py). Ref: 3.4.14 (interrupt-driven exchange), Table 3-7 (the frame timing the board
checks), RM0008 (the board's peripherals).
"""

from __future__ import annotations

import gc
import re
import tracemalloc
import weakref
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.interbus.ring import ErrorKind
from supi3.mcu import board as mcu_board
from supi3.mcu import build as mcu_build
from supi3.mcu.board import Board
from supi3.mcu.core import CPUS, FirmwareStoppedError, Stop
from supi3.model.registers import InconsistentDataError, InterfaceViolationError
from supi3.sdk import native
from supi3.sdk.bench import KEPT, Bench
from supi3.sdk.examples.history import SETTLE_CYCLES
from supi3.spi.upif import Mode
from support import c_firmware
from test_mcu_hostile import FILES

pytestmark = pytest.mark.skipif(mcu_build.toolchain_missing() is not None, reason=str(mcu_build.toolchain_missing()))

WORDS = (0x0000, 0xFFFF, 0x1234, 0x8001, 0x00FF)
"""As tests/test_sdk_c_examples.py."""
MODES = (Mode.MOTOROLA, Mode.INTEL)
INTEL = {"FW_MODE": "SUPI3_MODE_INTEL"}
"""The examples' build for the Intel interface (fw_board.h FW_MODE), on the board and on the host (MCU-18)."""


def _example(name: str, folder: Path, cpu: str, mode: Mode) -> Path:
    """The example ``name`` built for ``cpu`` and the interface ``mode``."""
    return mcu_build.build(native.example(name), folder / f"{name}_{cpu}_{mode.name}.elf", cpu=cpu,
                           defines=INTEL if mode is Mode.INTEL else None)  # fmt: skip


@pytest.fixture(scope="module")
def digital_io(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """The digital 16/16 example built for each core, once per module."""
    folder = tmp_path_factory.mktemp("mcu")
    return {cpu: mcu_build.build(native.example("digital_io"), folder / f"digital_io_{cpu}.elf", cpu=cpu)
            for cpu in CPUS}  # fmt: skip


def test_the_board_pins_are_board_h_s() -> None:
    """The emulator's wiring constants are the board port's (board.h BOARD_PIN_*)."""
    text = (mcu_build.BOARD_DIR / "board.h").read_text()
    defined = {name: int(value) for name, value in re.findall(r"#define BOARD_PIN_(\w+) (\d+)u", text)}
    for name in ("IRQ", "CD", "IO", "SAS_INIT", "SS", "STAT_ERR", "MODACK"):
        assert getattr(mcu_board, f"PIN_{name}") == defined[name], name


def _binary_exchange(board: Board, words: tuple[bytes, ...]) -> list[tuple[bytes, bytes]]:
    """Per step: the master's outputs and the device's inputs set, SETTLE_CYCLES (3) cycles run; (the firmware's
    output terminals, the master's inputs) after them. (Back to back the firmware's IN goes out with the third
    cycle; before MCU-55 two were run, the master having started the third in the run's wait.)"""
    fw = board.fw_board
    assert fw is not None
    n = len(words[0])
    seen = []
    for out_data, in_data in zip(words, reversed(words), strict=True):
        board.bench.master.set_outputs(1, out_data)
        fw.inputs = in_data
        board.run(SETTLE_CYCLES)
        seen.append((fw.outputs[:n], board.bench.master.inputs(1)))
    return seen


def _host_exchange(pytestconfig: pytest.Config, name: str, words: tuple[bytes, ...],
                   mode: Mode = Mode.MOTOROLA) -> list[tuple[bytes, bytes]]:  # fmt: skip
    """The same steps with the same firmware built for the host, on the firmware bench."""
    assert pytestconfig.cache is not None
    host = c_firmware(pytestconfig.cache, native.example(name), defines=INTEL if mode is Mode.INTEL else None)
    bench = Bench(firmware=host, mode=mode)
    bench.run(3)
    n = len(words[0])
    seen = []
    for out_data, in_data in zip(words, reversed(words), strict=True):
        bench.master.set_outputs(1, out_data)
        for k, value in enumerate(in_data):
            host.board.inputs[k] = value
        bench.run(SETTLE_CYCLES)
        assert bench.served  # FW-14: a main loop's pass after the last cycle, as on the board (MCU-30)
        seen.append((bytes(host.board.outputs[0:n]), bench.master.inputs(1)))
    return seen


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("cpu", CPUS)
def test_digital_io_binary_gives_the_host_builds_process_data(
    pytestconfig: pytest.Config, digital_io: dict[str, Path], tmp_path: Path, cpu: str, mode: Mode
) -> None:
    """SET 83h, ID 03h, then OUT0/OUT1 read and IN0/IN1 written in the EXTI0 handler after each VALID event: the
    master's configuration and the data both ways are those of the same firmware compiled for the host; in either
    interface mode (the Intel build on the Intel board, MCU-18)."""
    elf = digital_io[cpu] if mode is Mode.MOTOROLA else _example("digital_io", tmp_path, cpu, mode)
    board = Board(elf, cpu=cpu, mode=mode)
    board.run(3)
    config = board.bench.master.config
    assert config is not None and (config[0].id_code, config[0].data_bytes) == (0x03, 2)
    words = tuple(w.to_bytes(2, "big") for w in WORDS)
    seen = _binary_exchange(board, words)
    assert seen == _host_exchange(pytestconfig, "digital_io", words, mode)
    assert seen == list(zip(words, reversed(words), strict=True))
    assert board.fw_board is not None and board.fw_board.error == 0 and board.protocol.mode is mode
    assert board.fw_board.cycles == board.interrupts > 0  # one VALID event per data cycle, each served
    assert board.violations == []


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("cpu", CPUS)
@pytest.mark.parametrize(
    ("name", "size", "interrupts"),
    [("polling_io", 2, False), ("analog_io", 4, True), ("irq_dispatch", 2, True), ("pcmd_alarm", 2, True)],
)
def test_more_example_binaries_give_the_host_builds_process_data(
    pytestconfig: pytest.Config, tmp_path: Path, name: str, size: int, interrupts: bool, cpu: str, mode: Mode
) -> None:
    """The polling example (fw_loop: the main loop polls the I/O pin), the block transfer (analog_io, 3.4.6), the
    event dispatch and the processor command examples, on both cores, in either interface mode (MCU-18: the Intel
    build on the Intel board against the Intel host build). The board's run and the host bench's end once the
    polling main loop has served the last cycle (MCU-30, FW-14): its data then arrive as the interrupt examples' do,
    the same on both."""
    board = Board(_example(name, tmp_path, cpu, mode), cpu=cpu, mode=mode)
    board.run(3)
    words = (bytes(range(1, size + 1)), bytes(range(0xF0, 0xF0 + size)), bytes(size))
    seen = _binary_exchange(board, words)
    assert seen == _host_exchange(pytestconfig, name, words, mode)
    assert seen == list(zip(words, reversed(words), strict=True)) and board.served
    assert board.fw_board is not None and board.fw_board.error == 0 and board.protocol.mode is mode
    assert (board.interrupts > 0) == interrupts
    assert board.violations == []


@pytest.mark.parametrize("cpu", CPUS)
def test_a_sleeping_core_enters_the_handler_in_its_interrupt_latency(digital_io: dict[str, Path], cpu: str) -> None:
    """The example sleeps in WFI between cycles: from the falling edge of /IRQ to the handler's first instruction
    is the core's exception entry, 12 cycles on the Cortex-M3 and 16 on the Cortex-M0 at 48 MHz (MCU-2)."""
    board = Board(digital_io[cpu], cpu=cpu)
    board.run(6)
    assert board.interrupts >= 3
    assert board.irq_latency_s == pytest.approx(CPUS[cpu].entry_cycles / 48e6)


@pytest.mark.parametrize("options", [{}, {"native_frames": False}, {"fidelity": "pin"}],
                         ids=["native-frames", "python-frames", "pin-level"])  # fmt: skip
def test_a_board_let_go_is_freed(digital_io: dict[str, Path], options: dict[str, object]) -> None:
    """MCU-92: nothing outside a board that ran keeps it alive; the collector frees it with its emulator. Before, the
    core kept ``ctypes.byref`` objects of its native state, which the collector cannot see into, so the board's
    cycle looked referenced from outside: every board stayed, 3.4 MB each (6 GB in one test worker)."""
    board = Board(digital_io["cortex_m3"], **options)  # type: ignore[arg-type]
    board.run(3)
    assert board.interrupts > 0
    gone = weakref.ref(board)
    del board
    gc.collect()
    assert gone() is None


def test_a_long_run_stays_flat_in_memory(digital_io: dict[str, Path]) -> None:
    """A firmware test of any length: once the bench keeps its last ``KEPT`` cycles (FW-6), 1,000 more master cycles
    leave no more memory held (MCU-92's companion: a board let go is freed, a board kept running does not grow)."""
    board = Board(digital_io["cortex_m3"], bit_rate=500_000)
    tracemalloc.start()  # before the kept history fills, so that each cycle it drops was traced too
    try:
        board.run(KEPT + 100)
        gc.collect()
        before = tracemalloc.get_traced_memory()[0]
        board.run(1000)
        gc.collect()
        grown = tracemalloc.get_traced_memory()[0] - before
    finally:
        tracemalloc.stop()
    assert board.cycles >= 2 * KEPT and board.violations == []
    assert grown < 16 * 1024, f"{grown} bytes more after 1,000 cycles"


def test_a_too_fast_sclk_is_caught_with_the_program_counter(tmp_path: Path) -> None:
    """BOARD_SPI_BR = 0 (f_PCLK / 2 = 24 MHz) breaks Table 3-7's t0 (667 ns at 500 kbit/s): strict mode stops the
    run at the first byte, the note names the transport function; non-strict mode records each byte."""
    elf = mcu_build.build(native.example("digital_io"), tmp_path / "fast.elf", defines={"BOARD_SPI_BR": "0u"})
    board = Board(elf)
    with pytest.raises(InterfaceViolationError, match=r"SCLK period 42 ns, shorter than t0 = 667 ns") as caught:
        board.run(1)
    assert caught.value.rule == "Table 3-7 t0"
    assert any("in board_xfer()" in note for note in caught.value.__notes__)
    lenient = Board(elf, strict=False)
    lenient.run(3)
    assert lenient.violations and {v.function for v in lenient.violations} == {"board_xfer"}
    assert "t0" in str(lenient.violations[0])


def test_raising_ss_before_the_byte_is_out_is_an_incomplete_frame(tmp_path: Path) -> None:
    """tests/mcu/early_ss.c waits for TXE instead of BSY: /SS rises while SPI1 still shifts, the chip drops the
    frame (3.4.2), and the violation names fw_setup."""
    elf = mcu_build.build(Path(__file__).parent / "mcu" / "early_ss.c", tmp_path / "early_ss.elf")
    board = Board(elf)
    with pytest.raises(InterfaceViolationError, match=r"incomplete byte: [0-7] SCLK rising edges") as caught:
        board.run(1)
    assert caught.value.rule == "3.4.2"
    assert any("in fw_setup()" in note for note in caught.value.__notes__)
    assert board.protocol.mode is None  # the initialization byte did not count


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("cpu", CPUS)
def test_fault_report_binary_trips_until_quit_peripheral_error(tmp_path: Path, cpu: str, mode: Mode) -> None:
    """fault_report.c as a binary, the steps of its host test (tests/test_sdk_c_examples.py): /StatErr (PA8) low
    for the filter time -> 0BB1h at the master, outputs off until a Quit Peripheral Error after the fault has gone;
    the /ModAck pulse reaches the firmware through EXTI line 1's pending bit (PB1, 3.6.2); in either interface
    mode."""
    board = Board(_example("fault_report", tmp_path, cpu, mode), cpu=cpu, cycle_time_s=1e-3, mode=mode)
    fw, chip, master = board.fw_board, board.bench.chip, board.bench.master
    assert fw is not None
    board.run(3)
    master.set_outputs(1, b"\x81\x18")
    board.run_for(0.02)
    assert fw.outputs[:2] == b"\x81\x18"
    fw.fault = 1
    board.run_for(0.3)  # > t3 = 200 ms + 31.5 %
    assert chip.module_error and chip.pf and fw.outputs[:2] == b"\x00\x00"
    assert sum(d.kind is ErrorKind.PERIPHERAL_FAULT for d in master.diagnostics) == 1
    master.quit_peripheral_error(1)  # while the fault lasts: nothing changes
    board.run_for(0.01)
    assert chip.pf and fw.outputs[:2] == b"\x00\x00"
    fw.fault = 0
    board.run_for(0.01)
    assert not chip.module_error and chip.pf and fw.outputs[:2] == b"\x00\x00"
    master.quit_peripheral_error(1)
    board.run_for(0.01)
    assert not chip.pf and fw.outputs[:2] == b"\x81\x18"
    assert fw.error == 0 and board.violations == [] and board.protocol.mode is mode


@pytest.mark.parametrize("cpu", CPUS)
def test_skipping_poll_loops_changes_nothing_but_the_speed(digital_io: dict[str, Path], cpu: str) -> None:
    """MCU-10: the SPI status polls counted without running them give the same cycles, instructions, bus time,
    interrupts and data as running each."""
    outcomes = []
    for skip in (True, False):
        board = Board(digital_io[cpu], cpu=cpu)
        board.core.skip_polls = skip
        board.run(3)
        board.bench.master.set_outputs(1, b"\x12\x34")
        assert board.fw_board is not None
        board.fw_board.inputs = b"\x56\x78"
        board.run(4)
        outcomes.append((board.core.cycles, board.core.instructions, board.bench.now, board.interrupts,
                         board.irq_latency_s, board.fw_board.outputs, board.bench.master.inputs(1)))  # fmt: skip
    assert outcomes[0] == outcomes[1]
    assert outcomes[0][5][:2] == b"\x12\x34" and outcomes[0][6] == b"\x56\x78"


def _line_of(path: Path, marker: str) -> int:
    return next(k for k, text in enumerate(path.read_text().splitlines(), 1) if marker in text)


def test_a_data_register_read_in_the_latch_phase_names_the_source_line(tmp_path: Path) -> None:
    """tests/mcu/latch_bug.c reads OUT0 in its main loop without looking at the I/O access bit (3.4.14): at
    2 Mbit/s a read soon falls into the latch phase. The chip's InconsistentDataError carries the bus time, the
    PC in the transport and the call stack from DWARF down to the line marked LATCH-BUG."""
    source = Path(__file__).parent / "mcu" / "latch_bug.c"
    line = _line_of(source, "LATCH-BUG */")
    board = Board(mcu_build.build(source, tmp_path / "latch_bug.elf"), bit_rate=2_000_000)
    with pytest.raises(InconsistentDataError, match="OUT0 read during the latch phase") as caught:
        board.run(40)
    assert caught.value.rule == "3.4.14"
    note = caught.value.__notes__[-1]
    assert f"fw_loop() latch_bug.c:{line}" in note and "in board_xfer() board.c:" in note
    assert len(board.violations) == 1  # the run ends at the first: nothing after it is reported
    where = board.violations[0]
    assert where.error is caught.value and where.function == "board_xfer"
    assert [frame.function for frame in where.backtrace][:4] == ["board_xfer", "frame", "supi3_read", "fw_loop"]
    assert where.backtrace[3].source is not None and where.backtrace[3].source.line == line


def test_digital_io_with_a_3_mhz_sclk_at_2_mbit_s_reaches_the_latch_phase(tmp_path: Path) -> None:
    """Round 1's finding: SPI1 at f_PCLK / 16 = 3 MHz (BOARD_SPI_BR = 3, the fastest that meets t0 = 333 ns at
    2 Mbit/s) with back-to-back cycles: the handler's four single accesses (3.4.4) end after the next cycle's latch
    phase has begun (3.4.14), which the host build (bytes at their Table 3-7 time) does not show. Every report
    names a data register access of fw_isr in digital_io.c. 16 back-to-back cycles from power-up reach three, the
    first at 0.35 ms (MCU-55, MCU-56: before, ``run(8)`` ran many more cycles after a 6.7 ms discovery ID cycle, the
    master going on while the run waited for the handler)."""
    elf = mcu_build.build(native.example("digital_io"), tmp_path / "br3.elf", defines={"BOARD_SPI_BR": "3u"})
    board = Board(elf, bit_rate=2_000_000, strict=False)
    board.run(16)
    assert board.violations
    source = native.example("digital_io")
    accesses = range(_line_of(source, "SUPI3_OUT0_ADDR"), _line_of(source, "SUPI3_IN1_ADDR") + 1)
    for where in board.violations:
        assert isinstance(where.error, InconsistentDataError) and where.error.rule == "3.4.14"
        isr = next(frame for frame in where.backtrace if frame.function == "fw_isr")
        assert isr.source is not None and isr.source.file == "digital_io.c" and isr.source.line in accesses
        assert "during the latch phase" in str(where) and "fw_isr() digital_io.c:" in str(where)


FINGERPRINTS = {
    2_000_000: (111_418, 51_721, 29, [(t, "board_xfer") for t in (549_750, 1_727_396, 1_851_542, 2_100_708)]),
    500_000: (421_868, 118_642, 32, []),
}
"""MCU-21: power-up and 30 data cycles of bench/bench_mcu.py's cases, as measured before the round-4 speed work (the
core's cycles, instructions, EXTI0 entries, each violation's time in ns and function); pinned to the firmware the
ziglang pinned in pyproject.toml's firmware extra builds (a toolchain or board port change re-measures them with
``Board.run``). Re-measured for MCU-45 (the master waits for the set-up): the power-up's rediscovery is gone
(before: 761,182 and 2,969,198 core cycles, 15.86 and 61.86 ms of bus time; its discovery ID cycle 6.76 and 27.0 ms)
and the firmware serves the power-up's data cycles (before: 56,211 and 110,250 instructions, 33 and 30 interrupts).
At 500 kbit/s: 35.20 ms, two data cycles and their two interrupts more, 7,170 instructions more. At 2 Mbit/s the
handler outlasts a back-to-back cycle (the reason for the violations), so the power-up's ``run(3)`` waits for it
through 13 cycles (11 interrupts, MCU-30: an exception active or pending is waited for): 9.84 ms; the latch-phase
reads recur every 744 µs as before (now exactly: before, 21 ns of a float's rounding moved some, NOISE_CYCLES),
from 7.36 ms (6.76 ms earlier: the rediscovery), four of them in the run. (The
firmware sleeps after its set-up at 110.4 and 54.4 µs; the master starts at the end of that status telegram, 120 and
55 µs, MCU-45.) Re-measured for FW-22 (``supi3_irq_service`` reads /IRQ again after IRQ_EVT and reads IRQ_EVT
again while it is low): at 500 kbit/s one GPIO read more per handler (before: 1,690,094 core cycles, 117,420
instructions). At 2 Mbit/s the handler outlasts the cycle, so the next cycle's event is pending after each read and
the handler reads it too (before: 472,366 cycles, 74,496 instructions, 44 entries, four latch-phase reads from
7.36 ms every 744 µs): each read's clear and the next event are an /IRQ edge that re-enters EXTI0, and the handler's
data accesses fall in more latch phases (24 in the run, from 6.99 ms): an overloaded handler stays wrong, the
violations only move. Re-measured for MCU-55 and MCU-56 (run(n) runs exactly n master cycles,
the master holding while the firmware serves the last; the discovery ID cycle sized for the ring, 62 µs and 0.25 ms,
not 6.76 and 27.0 ms): at 500 kbit/s the same instructions and interrupts, 1,268,304 core cycles fewer (26.42 ms:
the ID cycle 26.57 ms shorter, the 30 cycles 0.15 ms longer, starting once run(3) has returned instead of during its
wait): 8.79 ms. At 2 Mbit/s run(3) is 3 cycles and 2 interrupts (before 74 cycles and 64 interrupts: it waited for
the re-entered handler with the master cycling on), run(30) 30 cycles and 27 interrupts, 2.33 ms in all; five
latch-phase reads, from 0.55 ms. Re-measured for MCU-81 (EXTI0 pended while active, tail-chained at its return): at
2 Mbit/s 416 core cycles fewer (before: 111,834), 26 re-entries of the 29 now tail-chains, each 16 cycles shorter
(6 in place of the return's 10 and the entry's 12), the same instructions and interrupts; the handlers start
earlier against the bus, so the latch-phase reads move: four (before five, at 550,083, 1,046,542, 1,292,833,
1,789,292 and 2,160,938 ns), the first 333 ns (one chain's 16 cycles) earlier. 500 kbit/s: no /IRQ fall inside a
handler, unchanged."""


@pytest.mark.parametrize("bit_rate", list(FINGERPRINTS))
def test_the_bench_cases_keep_their_fingerprint(digital_io: dict[str, Path], tmp_path: Path, bit_rate: int) -> None:
    """The speed work changes nothing the firmware or the master sees: the same cycles, instructions, interrupts,
    violations (time, function) and process data as before it, at both bit rates of the bench."""
    elf = digital_io["cortex_m3"] if bit_rate == 500_000 else mcu_build.build(
        native.example("digital_io"), tmp_path / "br3.elf", defines={"BOARD_SPI_BR": "3u"})  # fmt: skip
    board = Board(elf, bit_rate=bit_rate, strict=False)
    board.run(3)
    board.bench.master.set_outputs(1, b"\x12\x34")
    assert board.fw_board is not None
    board.fw_board.inputs = b"\xab\xcd"
    board.run(30)
    violations = [(round(v.time_s * 1e9), v.function) for v in board.violations]
    assert (board.core.cycles, board.core.instructions, board.interrupts, violations) == FINGERPRINTS[bit_rate]
    assert (board.fw_board.outputs, board.bench.master.inputs(1)) == (b"\x12\x34\0\0", b"\xab\xcd")



IDLE_TICK = Path(__file__).parent / "mcu" / "idle_tick.S"
"""SysTick every 100 µs waking a thread-mode ``b .``: nine instructions to it, five in the handler."""


@pytest.fixture(scope="module")
def idle_tick(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """idle_tick.S (Thumb-1) as it is (``tick``), with SysTick on Default_Handler's ``b .`` (``hang``), and
    test_mcu_hostile's ``loop.elf`` (``loop``: ``b .`` at the reset vector, nothing else)."""
    folder = tmp_path_factory.mktemp("idle")
    (folder / "loop.elf").write_bytes(FILES["loop.elf"])
    return {"loop": folder / "loop.elf", **{
        name: mcu_build.build(IDLE_TICK, folder / f"{name}.elf", cpu="cortex_m0", port=False,
                              defines={"HANG": "1"} if name == "hang" else None) for name in ("tick", "hang")}}


FIDELITIES = ["transaction", "pin"]


@pytest.mark.parametrize("fidelity", FIDELITIES)
@pytest.mark.parametrize("budget", [1, 2, 1000, 10**7])
def test_a_thread_mode_b_dot_is_a_wait_from_its_first_iteration_at_any_budget(
    idle_tick: dict[str, Path], fidelity: str, budget: int
) -> None:
    """MCU-4: the core stops at its first ``b .`` whatever the run's deadline, and sleeps; a sleeping core spends
    none of the budget. Round 4 ran the loop up to the next bus event or the budget's end at transaction level (334
    iterations for a budget of 1000), for 1 µs at pin level (16), and a budget of 1 stopped the run: the verdict and
    the count now are the same at both fidelities and any budget."""
    board = Board(idle_tick["loop"], fidelity=fidelity)
    for _ in range(2):
        board.run(1, max_instructions=budget)
        assert board.core.sleeping and board.core.instructions == 1 and board.cycles > 0


@pytest.mark.parametrize("fidelity", FIDELITIES)
def test_an_interrupt_returning_to_b_dot_sleeps_at_once(idle_tick: dict[str, Path], fidelity: str) -> None:
    """Each SysTick wake runs the handler's five instructions; its return to the ``b .`` sleeps without running it:
    the instructions are the set-up's nine, one iteration, and five a wake, at both fidelities."""
    board = Board(idle_tick["tick"], cpu="cortex_m0", fidelity=fidelity)
    board.run(1)
    ticks = int.from_bytes(board.core.read_bytes(board.core.image.address("ticks"), 4), "little")
    assert ticks == board.core.cycles // 4800 > 0
    assert board.core.sleeping and board.core.instructions == 9 + 1 + 5 * ticks


@pytest.mark.parametrize("fidelity", FIDELITIES)
def test_b_dot_in_a_handler_is_a_hang_at_its_first_iteration(idle_tick: dict[str, Path], fidelity: str) -> None:
    """SysTick's vector on Default_Handler (``b .``): the first wake stops the run with a hang report at the loop,
    after the set-up, its ``b .`` and the handler's one iteration, at both fidelities (MCU-4)."""
    board = Board(idle_tick["hang"], cpu="cortex_m0", fidelity=fidelity)
    with pytest.raises(FirmwareStoppedError, match=r"endless loop \(b \.\) in the handler of exception 15") as caught:
        board.run(1)
    report = caught.value.report
    assert (report.stop, report.symbol, report.instructions) == (Stop.HANG, "Default_Handler", 11)
    assert 4800 < board.core.cycles - CPUS["cortex_m0"].entry_cycles - 3 < 4800 + 20  # the first wrap: its iteration


BUDGETS = [1, 7, 100, 2000, 10**6]
"""Instruction budgets from below the set-up to far above a run's instructions."""


@settings(max_examples=20, derandomize=True, deadline=None)
@given(calls=st.lists(st.tuples(st.booleans(), st.integers(0, 3), st.sampled_from(BUDGETS)), min_size=1, max_size=6))
def test_any_history_of_runs_keeps_the_wait_out_of_the_budget(idle_tick: dict[str, Path],
                                                              calls: list[tuple[bool, int, int]]) -> None:  # fmt: skip
    """MCU-4 over histories: any sequence of ``run(n)`` and ``run_for(n x 100 µs)`` calls, each with its own budget,
    on the SysTick-woken ``b .``: after each the instructions are the set-up's nine, one iteration and five a wake
    (the handler is one block: run whole, or not yet entered), never more, the core asleep or about to run the
    handler; a call ends in a budget stop only if it ran at least its budget."""
    board = Board(idle_tick["tick"], cpu="cortex_m0")
    ticks_at = board.core.image.address("ticks")
    for by_time, amount, budget in calls:
        before = board.core.instructions
        stopped: FirmwareStoppedError | None = None
        try:
            if by_time:
                board.run_for(amount * 100e-6, max_instructions=budget)
            else:
                board.run(amount, max_instructions=budget)
        except FirmwareStoppedError as error:
            stopped = error
        if stopped is not None:
            assert stopped.report.stop is Stop.BUDGET and board.core.instructions - before >= budget
            return
        ticks = int.from_bytes(board.core.read_bytes(ticks_at, 4), "little")
        core = board.core
        if core.instructions:  # (a first run(0) or run_for(0) runs nothing) the handler is one block: whole or not yet
            assert core.instructions == 9 + 1 + 5 * ticks and (core.sleeping or core.in_exception)

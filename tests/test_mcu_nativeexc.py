"""The exception entry's and return's traffic in native code against the Python path (MCU-70, MCU-71; ARMv7-M B1.5.6
to B1.5.8).

``CortexM.native_exceptions`` (default ``True``) moves the registers and the frame of an entry, a tail-chain and a
plain return with one call to the native library each; ``False`` does the same steps through ctypes call by call
(the reference). Both paths leave the same registers (both stack pointers and CONTROL), the same stack bytes, cycles,
instructions, active and pending exceptions, over the hand-written exception programs (nesting, the alignment word,
the process stack, tail-chaining), the fault reports (stacking,
unstacking and vector-table errors, INVSTATE, a bad EXC_RETURN, a core fault's HardFault frame) and the example
firmwares on the board (registers, RAM, cycles, instructions, interrupts, latency, bus time, data, violations).
Random register contents, stack depths and stacks: ``test_mcu_batch.py`` (the native path, the batches and single
accesses).
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from pathlib import Path

import pytest

from supi3.errors import ArgumentError
from supi3.mcu import build as mcu_build
from supi3.mcu import core as mcu_core
from supi3.mcu.board import Board
from supi3.mcu.core import CPUS, EXTERNAL, CortexM, FirmwareError
from supi3.sdk import native

pytestmark = pytest.mark.skipif(mcu_build.toolchain_missing() is not None, reason=str(mcu_build.toolchain_missing()))

PROGRAMS = Path(__file__).parent / "mcu"


@pytest.fixture(scope="module")
def exceptions_elf(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """exceptions.S (Thumb-1: one ELF for both cores), once per module."""
    out = tmp_path_factory.mktemp("nativeexc") / "exceptions.elf"
    return mcu_build.build(PROGRAMS / "exceptions.S", out, cpu="cortex_m0", port=False)


def _sleep(core: CortexM, steps: int = 100) -> None:
    """Run until the core sleeps (WFI)."""
    for _ in range(steps):
        if core.step(core.cycles + 10_000) == "sleep":
            return
    raise AssertionError("the program did not reach its WFI")


def _state(core: CortexM) -> tuple[object, ...]:
    """Everything an entry or a return may change: the registers, CONTROL, both stack pointers, the whole RAM (both
    stacks), the cycles, the instructions, the active and pending exceptions."""
    return (core.registers(), core.reg("control"), core.reg("msp"), core.reg("psp"), core.read_bytes(*core.ram),
            core.cycles, core.instructions, list(core.active), sorted(core.pending))  # fmt: skip


Run = tuple[object, list[int], tuple[object, ...]]
"""A scenario's outcome (a fault report as its text and report), the exceptions it entered, the core's state after."""


def _both(elf: Path, cpu: str, scenario: Callable[[CortexM], object]) -> list[Run]:
    """``scenario`` on a new core with the native traffic and on one with the Python path."""
    results = []
    for fast in (True, False):
        core = CortexM(elf, cpu=cpu)
        core.native_exceptions = fast
        entries: list[int] = []
        core.entered = entries.append
        try:
            outcome: object = scenario(core)
        except FirmwareError as error:
            outcome = (str(error), error.report)
        results.append((outcome, entries, _state(core)))
    return results


def _nested(misalign: int, process: bool) -> Callable[[CortexM], object]:
    def scenario(core: CortexM) -> object:
        _sleep(core)
        if process:
            core.set_reg("psp", 0x2000_4000 - misalign)
            core.set_reg("control", 0b10)
        else:
            core.set_reg("sp", core.reg("sp") - misalign)
        core.pend(EXTERNAL + 0)  # IRQ 0, preempted by IRQ 1, both return (B1.5.6 to B1.5.8)
        _sleep(core)
        core.pend(EXTERNAL + 1)
        core.pend(EXTERNAL + 0)  # IRQ 1 then IRQ 0 tail-chained on its frame (MCU-20)
        _sleep(core)
        return core.step(core.cycles + 10_000)

    return scenario


def _stacking_error(core: CortexM) -> object:
    _sleep(core)
    core.set_reg("sp", core.ram[0] + 8)  # the frame would start below RAM
    return core.enter(EXTERNAL + 0)


def _unstacking_error(core: CortexM) -> object:
    _sleep(core)
    core.enter(EXTERNAL + 0)
    core.set_reg("sp", core.ram[0] + core.ram[1] - 16)  # the frame runs past RAM's end
    core.exception_return(mcu_core.EXC_RETURN_THREAD_MSP)
    return None


def _vector_error(core: CortexM) -> object:
    _sleep(core)
    core.vtor = 0x3000_0000  # as a write of SCB->VTOR would set it
    return core.enter(EXTERNAL + 0)


def _invstate(core: CortexM) -> object:
    _sleep(core)
    table = core.ram[0] + 0x1000
    core.write_bytes(table, struct.pack("<I", core.image.address("Irq1_Handler")) * (EXTERNAL + 2))  # bit 0 clear
    core.vtor = table
    return core.enter(EXTERNAL + 1)


def _bad_return(core: CortexM) -> object:
    _sleep(core)
    core.enter(EXTERNAL + 0)
    core.exception_return(mcu_core.EXC_RETURN_HANDLER)  # one active exception: a nesting mismatch (B1.5.8)
    return None


def _spsel_in_handler(core: CortexM) -> object:
    _sleep(core)
    core.enter(EXTERNAL + 0)
    core.set_reg("control", mcu_core.CONTROL_SPSEL)  # a host write: handler mode still stacks as handler mode
    return core.enter(mcu_core.HARDFAULT), core.reg("lr")


SCENARIOS: dict[str, Callable[[CortexM], object]] = {
    **{f"nested{'_psp' * process}_{misalign}": _nested(misalign, process) for misalign in (0, 4)
       for process in (False, True)},
    "stacking_error": _stacking_error, "unstacking_error": _unstacking_error, "vector_error": _vector_error,
    "invstate": _invstate, "bad_return": _bad_return, "spsel_in_handler": _spsel_in_handler,
}  # fmt: skip


@pytest.mark.parametrize("cpu", sorted(CPUS))
@pytest.mark.parametrize("name", list(SCENARIOS))
def test_the_native_traffic_is_the_python_paths_over_the_exception_programs(exceptions_elf: Path, cpu: str,
                                                                            name: str) -> None:  # fmt: skip
    """MCU-70, MCU-71: nested entries and returns on the main and the process stack with and without the alignment
    word, a tail-chain, and each fault (its report's text, frame and registers) give the same outcome, entries and
    state with the native traffic as with the Python path."""
    native_run, python_run = _both(exceptions_elf, cpu, SCENARIOS[name])
    assert native_run == python_run
    if name == "spsel_in_handler":
        assert native_run[0][1] == mcu_core.EXC_RETURN_HANDLER  # type: ignore[index]
    elif name.startswith("nested"):
        assert native_run[1] == [EXTERNAL + 0, EXTERNAL + 1, EXTERNAL + 1, EXTERNAL + 0, EXTERNAL + 1]  # IRQ 0 pends 1
    else:
        assert isinstance(native_run[0], tuple)
        assert "UsageFault" in native_run[0][0] or " error: " in native_run[0][0]


def _board_run(elf: Path, cpu: str, bit_rate: int, fast: bool) -> tuple[object, ...]:
    """Power-up, then data cycles with process data both ways: what the firmware, the core and the master show."""
    board = Board(elf, cpu=cpu, bit_rate=bit_rate, strict=False)
    board.core.native_exceptions = fast
    board.run(3)
    master = board.bench.master
    master.set_outputs(1, bytes(range(0x12, 0x12 + master.entry(1).data_bytes)))
    if board.fw_board is not None:
        board.fw_board.inputs = bytes(range(0x56, 0x56 + len(board.fw_board.inputs)))
    board.run(12)
    core = board.core
    return (core.cycles, core.instructions, core.registers(), core.reg("control"), core.reg("msp"), core.reg("psp"),
            core.read_bytes(*core.ram), list(core.active), sorted(core.pending), board.bench.now, board.interrupts,
            board.irq_latency_s, board.bench.master.inputs(1), board.served,
            [(v.time_s, v.pc, str(v.error)) for v in board.violations])  # fmt: skip


BOARD_CASES = [("digital_io", "cortex_m3", 2_000_000, {"BOARD_SPI_BR": "3u"}), ("digital_io", "cortex_m0", 500_000, {}),
               ("irq_dispatch", "cortex_m3", 500_000, {}), ("pcmd_alarm", "cortex_m3", 500_000, {}),
               ("analog_io", "cortex_m0", 500_000, {})]  # fmt: skip


@pytest.mark.parametrize(("example", "cpu", "bit_rate", "defines"), BOARD_CASES)
def test_the_example_firmwares_run_alike_with_either_path(tmp_path: Path, example: str, cpu: str, bit_rate: int,
                                                          defines: dict[str, str]) -> None:  # fmt: skip
    """MCU-70, MCU-71: each example firmware on the board (issue #13's case among them) gives the same cycles,
    instructions, registers, RAM, exceptions, bus time, interrupts, latency, process data and violations with the
    native traffic as with the Python path; its EXTI0 handler runs (the entries and returns are exercised)."""
    elf = mcu_build.build(native.example(example), tmp_path / f"{example}.elf", cpu=cpu, defines=defines)
    fast, slow = (_board_run(elf, cpu, bit_rate, flag) for flag in (True, False))
    assert fast == slow
    assert isinstance(fast[10], int) and fast[10] >= 10


@pytest.mark.parametrize("value", [1, "yes", None])
def test_the_switch_takes_a_bool_only(exceptions_elf: Path, value: object) -> None:
    """``native_exceptions`` set to anything but a bool is an ArgumentError naming it; the core keeps its path."""
    core = CortexM(exceptions_elf)
    with pytest.raises(ArgumentError, match="native_exceptions"):
        core.native_exceptions = value  # type: ignore[assignment]
    assert core.native_exceptions is True

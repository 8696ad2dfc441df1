"""The run loop's step with less Python (MCU-79) against the loop that asks every question where it did before.

MCU-79: the board's run loop asks the core once a step which exception it enters next (``CortexM.next_entry``) and
hands the answer to the deadline and to the step (``Board._entry``, ``CortexM._handed``) instead of asking in
both; an exception
return asks for a tail-chain only with an exception pending; the board asks EXTI whether EXTI0 requests only once
the core's lists say a request would pend it. The reference board asks the core in its deadline and at the step's start
(as ``CortexM.step`` does), asks EXTI first, and its core's exception returns always ask for a tail-chain (a pending set
that is never empty to ``bool``). Over the example firmwares on the board and the hand-written exception programs,
the state after every step is the same: registers, CONTROL, both stack pointers, RAM, cycles, instructions, active
and pending exceptions, interrupts, latency, bus time, process data and violations.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import pytest

from supi3.mcu import build as mcu_build
from supi3.mcu.board import _EXTI0, NOISE_CYCLES, Board
from supi3.mcu.core import CPUS, MAX_DEADLINE, PENDSV, UNASKED, CortexM
from supi3.sdk import native
from test_mcu_nativeexc import BOARD_CASES, SCENARIOS, _both, _state

pytestmark = pytest.mark.skipif(mcu_build.toolchain_missing() is not None, reason=str(mcu_build.toolchain_missing()))

PROGRAMS = Path(__file__).parent / "mcu"


class _AlwaysAsked(set[int]):
    """A pending set that is true to ``bool`` even empty: the exception return asks for a tail-chain every time (the
    path before MCU-79; ``_takeable`` of an empty set still answers ``None``)."""

    def __bool__(self) -> bool:
        return True


class AskingBoard(Board):
    """The run loop before MCU-79: the deadline and the step each ask the core for its entry, EXTI is asked
    first."""

    def _bus_deadline(self, at: float) -> int:
        del at  # worked out here, not taken from the run loop or the native frames (MCU-90)
        core = self.core
        at = self.bench.next_change_s()
        if at == math.inf:
            return MAX_DEADLINE
        if _EXTI0 in core.active or (_EXTI0 in core.pending and core.next_entry() == _EXTI0):
            at += self._wait_s
        return math.ceil(at * core.cpu_hz - NOISE_CYCLES)

    def _step(self, deadline: int) -> None:
        self._entry = UNASKED
        super()._step(deadline)

    def _request(self) -> None:
        core = self.core
        if self.exti.requesting(0) and _EXTI0 not in core.active and _EXTI0 not in core.pending:
            core.pend(_EXTI0)
            core.stop_request = True


def _board_steps(elf: Path, cpu: str, bit_rate: int, lean: bool) -> list[tuple[object, ...]]:
    """Power-up and a history of runs of one to five data cycles with new process data both ways after each; the
    board's state after every step."""
    board = (Board if lean else AskingBoard)(elf, cpu=cpu, bit_rate=bit_rate, strict=False)
    if not lean:
        board.core.pending = _AlwaysAsked()
    steps: list[tuple[object, ...]] = []
    step = board._step

    def recorded(deadline: int) -> None:
        try:
            step(deadline)
        finally:
            master, fw_board = board.bench.master, board.fw_board
            steps.append((_state(board.core), board.bench.now, board.interrupts, board.irq_latency_s,
                          None if master.config is None else master.inputs(1),
                          None if fw_board is None else fw_board.outputs,
                          [(v.time_s, v.pc, str(v.error)) for v in board.violations]))  # fmt: skip

    board._step = recorded  # type: ignore[method-assign]
    for cycles, data in ((3, 0x21), (1, 0x43), (4, 0x65), (2, 0x87), (5, 0xA9)):  # new process data each run
        board.run(cycles)
        size = board.bench.master.entry(1).data_bytes
        board.bench.master.set_outputs(1, bytes((data + k) & 0xFF for k in range(size)))
        if board.fw_board is not None:
            board.fw_board.inputs = bytes((data ^ 0xFF) - k for k in range(len(board.fw_board.inputs)))
    assert board.interrupts >= 10  # the EXTI0 handler's entries and returns are exercised
    return steps


@pytest.mark.parametrize(("example", "cpu", "bit_rate", "defines"), BOARD_CASES)
def test_the_lean_step_is_the_asking_step_on_the_example_firmwares(
    tmp_path: Path, example: str, cpu: str, bit_rate: int, defines: dict[str, str]
) -> None:
    """MCU-79: each example firmware on the board (issue #13's case first) gives after every step of the run loop
    the same registers, RAM, cycles, instructions, exceptions, bus time, interrupts, latency, process data and
    violations as the loop that asks every question where it did before."""
    elf = mcu_build.build(native.example(example), tmp_path / f"{example}.elf", cpu=cpu, defines=defines)
    lean, asking = (_board_steps(elf, cpu, bit_rate, flag) for flag in (True, False))
    assert len(lean) == len(asking)
    for number, (one, other) in enumerate(zip(lean, asking, strict=True)):
        assert one == other, f"step {number}"


def test_the_handed_entry_is_the_core_s_answer_at_the_step(tmp_path: Path) -> None:
    """MCU-79's invariant in issue #13's case: the entry the loop hands the step is what the core answers at the
    step's start, and EXTI0 is entered from it (the run's first entry; the re-entries after a return are tail-chains
    at the return since MCU-81, entered by the core without a step: before, 7 of the 7 entries were handed)."""
    elf = mcu_build.build(native.example("digital_io"), tmp_path / "br3.elf", defines={"BOARD_SPI_BR": "3u"})
    board = Board(elf, bit_rate=2_000_000, strict=False)
    core = board.core
    handed: list[int | None] = []
    step = core.step

    def checked(deadline: int) -> str:
        number = core._handed
        assert number == core.next_entry()
        handed.append(number)
        return step(deadline)

    core.step = checked  # type: ignore[method-assign]
    board.run(8)
    assert handed.count(_EXTI0) == 1 and board.interrupts == 7


def _asking(scenario: Callable[[CortexM], object]) -> Callable[[CortexM], object]:
    """``scenario`` on a core whose returns always ask for a tail-chain."""

    def run(core: CortexM) -> object:
        core.pending = _AlwaysAsked()
        return scenario(core)

    return run


@pytest.fixture(scope="module")
def exceptions_elf(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """exceptions.S (Thumb-1: one ELF for both cores), once per module."""
    return mcu_build.build(PROGRAMS / "exceptions.S", tmp_path_factory.mktemp("steploop") / "exceptions.elf",
                           cpu="cortex_m0", port=False)  # fmt: skip


@pytest.mark.parametrize("cpu", sorted(CPUS))
@pytest.mark.parametrize("name", list(SCENARIOS))
def test_a_return_asks_for_a_chain_only_with_an_exception_pending(exceptions_elf: Path, cpu: str, name: str) -> None:
    """MCU-79 over the hand-written exception programs (nesting, both stacks, a tail-chain, the faults), with the
    native and the Python traffic (MCU-70, MCU-71): the same outcome, entries and state as a core whose every
    return asks for a tail-chain."""
    scenario = SCENARIOS[name]
    assert _both(exceptions_elf, cpu, scenario) == _both(exceptions_elf, cpu, _asking(scenario))


def test_a_host_s_step_after_a_run_asks_for_its_entry(tmp_path: Path) -> None:
    """MCU-79: the answer the run loop handed is taken by its step alone (in issue #13's case the last one of a run
    is EXTI0); the host's own step after the run asks, and enters the PendSV exception the host pended."""
    elf = mcu_build.build(native.example("digital_io"), tmp_path / "br3.elf", defines={"BOARD_SPI_BR": "3u"})
    board = Board(elf, bit_rate=2_000_000, strict=False)
    board.run(3)
    core = board.core
    assert board.served and not core.active and not core.pending
    core.pend(PENDSV)
    core.step(core.cycles + 1)
    assert core.active == [PENDSV]
    assert board.interrupts == 2  # power-up's EXTI0 entries only

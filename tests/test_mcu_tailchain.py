"""EXTI0 pended again while active and tail-chained at its return (MCU-81; ARMv7-M B1.5.8, the Cortex-M3 NVIC's
pending rules, RM0008 10.2).

``mcu/late_irq.c``'s handler serves the chip's event, then busy-waits ``hold_us`` (set in RAM between runs): a wait
longer than the rest of a master cycle lets the next cycle's event make /IRQ fall inside the handler, after its PR
write. EXTI0's line to the NVIC (PR AND IMR) then rises while EXTI0 is active: the NVIC pends it, and the return
tail-chains into the handler on the same frame, :attr:`Cpu.tail_chain_cycles` (MCU-20: 6 on the Cortex-M3, 16 on the
Cortex-M0) after the return began. The /IRQ latency the board reports is the fall to that first instruction.
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import pytest
from hypothesis import Phase, example, given, settings
from hypothesis import strategies as st

from supi3.errors import ArgumentError
from supi3.mcu import build as mcu_build
from supi3.mcu.board import Board
from supi3.mcu.core import CPUS, EXTERNAL, idle_loops
from supi3.mcu.stm32 import EXTI_PR
from supi3.sdk import native

pytestmark = pytest.mark.skipif(mcu_build.toolchain_missing() is not None, reason=str(mcu_build.toolchain_missing()))

MCU = Path(__file__).parent / "mcu"
EXTI0 = EXTERNAL + 6  # IRQ 6 (the STM32F10x's vector table)
CHAIN_CYCLES = {"cortex_m3": 6, "cortex_m0": 16}
"""MCU-20's figures, the Cortex-M3 TRM's 6 cycles and the Cortex-M0's bound, as ``Cpu.tail_chain_cycles`` holds them."""


@pytest.fixture(scope="module")
def late_irq(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """mcu/late_irq.c built for each core, once per module."""
    folder = tmp_path_factory.mktemp("tailchain")
    return {cpu: mcu_build.build(MCU / "late_irq.c", folder / f"late_irq_{cpu}.elf", cpu=cpu) for cpu in CPUS}


@dataclass
class Entry:
    """One EXTI0 entry: its handler's first cycle, the /IRQ fall the board times it from, and the first cycle of the
    return that tail-chained into it (``None``: entered from thread mode)."""

    cycles: int
    fell: int | None
    returned: int | None


@dataclass
class History:
    """EXTI0's entries and its returns that unstacked (their first cycle), in order; the latency before."""

    latency_s: float
    events: list[Entry | int] = field(default_factory=list)

    @property
    def entries(self) -> list[Entry]:
        return [event for event in self.events if isinstance(event, Entry)]


def _watched(board: Board) -> History:
    """Note every EXTI0 entry and return of ``board``'s core from now (around the board's own callbacks; hook.c's
    tail-chains off, MCU-86: each return reaches them)."""
    core, history = board.core, History(board.irq_latency_s)
    if board.native_frames is not None:
        board.native_frames.tail_chains = False
    exception_return, entered = core.exception_return, core.entered
    returning: list[int | None] = [None]

    def on_return(exc_return: int) -> None:
        start = returning[0] = core.cycles
        try:
            exception_return(exc_return)
        finally:
            returning[0] = None
        if not core.active:
            history.events.append(start)

    def on_entered(number: int) -> None:
        assert number == EXTI0
        history.events.append(Entry(core.cycles, board._irq_fell, returning[0]))
        entered(number)

    core.exception_return = on_return  # type: ignore[method-assign]
    core.entered = on_entered
    return history


def _board(elf: Path, cpu: str, bit_rate: int, **options: object) -> Board:
    """A board with late_irq's set-up done (its first cycle served): ``hold_us`` can be set now (the start-up code
    clears it at reset)."""
    board = Board(elf, cpu=cpu, bit_rate=bit_rate, strict=False, **options)  # type: ignore[arg-type]
    board.run(1)
    return board


def _hold(board: Board, microseconds: int, *, clear_late: bool = False) -> None:
    """late_irq's wait in the handler and whether it writes PR again after it."""
    core = board.core
    core.write_bytes(core.image.address("hold_us"), struct.pack("<I", microseconds))
    core.write_bytes(core.image.address("clear_late"), struct.pack("<I", clear_late))


@pytest.mark.parametrize("clear_late", [False, True])
@pytest.mark.parametrize("fidelity", ["transaction", "pin"])
@pytest.mark.parametrize("cpu", sorted(CPUS))
def test_an_irq_fall_inside_the_handler_is_tail_chained_at_its_return(
        late_irq: dict[str, Path], cpu: str, fidelity: str, clear_late: bool) -> None:  # fmt: skip
    """A wait longer than the master cycle: every entry after the first is tail-chained, the handler's first
    instruction 6 (Cortex-M3) or 16 (Cortex-M0) cycles after the return began, on the same frame (the stack pointer
    the handler starts with is the first entry's), the fall inside the handler before the return; the latency
    reported is the longest fall to first instruction. With ``clear_late`` the handler clears PR after the wait: the
    line is low at the return, but the NVIC latched its rise while active (a pulse), so it chains as well. Without the
    wait no fall comes inside a handler: nothing chains."""
    board = _board(late_irq[cpu], cpu, 500_000, fidelity=fidelity)
    core = board.core
    assert core.cpu.tail_chain_cycles == CHAIN_CYCLES[cpu]
    history = _watched(board)
    board.run(3)
    assert len(history.entries) == 3 and all(entry.returned is None for entry in history.entries)
    _check(history, board)
    _hold(board, 300, clear_late=clear_late)
    history = _watched(board)
    stacks: list[int] = []
    entered = core.entered

    def on_entered(number: int) -> None:
        stacks.append(core.reg("sp"))
        entered(number)

    core.entered = on_entered
    board.run(5)
    _check(history, board)
    chained = [entry for entry in history.entries if entry.returned is not None]
    assert len(chained) >= 3 and len(chained) == len(history.entries) - 1
    assert len(set(stacks)) == 1  # one frame: no unstacking and stacking between the handlers
    assert board.irq_latency_s > 100e-6  # a fall waits for the rest of the handler (about 300 us of wait)


@settings(max_examples=12, deadline=None, phases=(Phase.explicit, Phase.reuse, Phase.generate))
@example(cpu="cortex_m3", bit_rate=500_000, runs=[(300, 3, False), (0, 2, False), (300, 3, True)])  # chains, plain
@given(cpu=st.sampled_from(sorted(CPUS)), bit_rate=st.sampled_from([500_000, 2_000_000]),
       runs=st.lists(st.tuples(st.integers(0, 500), st.integers(1, 3), st.booleans()), min_size=1, max_size=4))
def test_every_exti0_entry_is_where_the_architecture_puts_it(late_irq: dict[str, Path], cpu: str, bit_rate: int,
                                                             runs: list[tuple[int, int, bool]]) -> None:  # fmt: skip
    """A history of runs with random waits in the handler, PR cleared again after it or not: every EXTI0 entry is
    tail-chained iff its /IRQ fall came before the return began, thread-mode entries only after a fall that came
    later, and the latency is the longest fall to first instruction (:func:`_check`)."""
    board = _board(late_irq[cpu], cpu, bit_rate)
    history = _watched(board)
    for hold, cycles, clear_late in runs:
        _hold(board, hold, clear_late=clear_late)
        board.run(cycles)
    _check(history, board)


@pytest.mark.parametrize("cpu", sorted(CPUS))
def test_a_line_held_through_the_handler_chains_at_every_return(late_irq: dict[str, Path], cpu: str) -> None:
    """A handler whose PR write is lost (the test drops EXTI's PR writes; the native frames off so that each reaches
    Python) leaves EXTI0's line asserted through the handler: no rising edge, so nothing pends while it runs, but the
    NVIC samples the line at the return and finds it asserted: every return tail-chains into the handler again
    (the Cortex-M3 NVIC's level rule); with the writes kept, the same run chains nothing."""
    for lost in (False, True):
        board = _board(late_irq[cpu], cpu, 500_000, native_frames=False)
        exti = board.exti
        write = exti.write

        def dropping(offset: int, size: int, value: int, write: Callable[[int, int, int], None] = write) -> None:
            if offset != EXTI_PR:
                write(offset, size, value)

        if lost:
            exti.write = dropping  # type: ignore[method-assign]
        history = _watched(board)
        board.run(2)
        returns = [event for event in history.events if isinstance(event, int)]
        chained = [entry for entry in history.entries if entry.returned is not None]
        if lost:
            assert not returns and len(chained) >= 5 and list(board.core.active) == [EXTI0]
            assert all(entry.cycles == entry.returned + CHAIN_CYCLES[cpu] for entry in chained if entry.returned)
        else:
            assert returns and not chained


@pytest.mark.parametrize("cpu", sorted(CPUS))
def test_a_line_held_until_the_handler_s_late_pr_write_pends_nothing(late_irq: dict[str, Path], cpu: str) -> None:
    """The level case the NVIC does not pend: board.c's PR write at the handler's start dropped (the test drops EXTI's
    PR writes from ``EXTI0_IRQHandler``), late_irq's write after the wait kept: EXTI0's line stays asserted from
    before the entry until that write, with no rising edge (the /IRQ rise at the IRQ_EVT read sets no PR bit), so
    nothing pends while the handler runs and the line is low at the return: no tail-chain, each entry from thread
    mode after its own fall."""
    board = _board(late_irq[cpu], cpu, 500_000, native_frames=False)
    core, exti = board.core, board.exti
    write = exti.write

    def dropping(offset: int, size: int, value: int) -> None:
        if offset != EXTI_PR or core.image.function_at(core.pc) != "EXTI0_IRQHandler":
            write(offset, size, value)

    exti.write = dropping  # type: ignore[method-assign]
    _hold(board, 0, clear_late=True)
    history = _watched(board)
    board.run(4)
    _check(history, board)
    assert len(history.entries) == 4 and all(entry.returned is None for entry in history.entries)
    assert len([event for event in history.events if isinstance(event, int)]) == 4


def _outcome(elf: Path, cpu: str, *, native_exceptions: bool = True, **options: object) -> tuple[object, ...]:
    """Four runs with waits in the handler that chain and that do not: the history and what the run shows."""
    board = Board(elf, cpu=cpu, bit_rate=500_000, strict=False, **options)  # type: ignore[arg-type]
    board.core.native_exceptions = native_exceptions
    board.run(1)
    history = _watched(board)
    for hold, clear_late in ((300, False), (0, False), (450, True), (120, False)):
        _hold(board, hold, clear_late=clear_late)
        board.run(3)
    core = board.core
    return (history.events, core.cycles, core.instructions, core.registers(), core.read_bytes(*core.ram),
            board.interrupts, board.irq_latency_s, board.now, board.master.inputs(1),
            [(v.time_s, v.pc, str(v.error)) for v in board.violations])  # fmt: skip


@pytest.mark.parametrize("cpu", sorted(CPUS))
def test_the_fast_paths_chain_alike(late_irq: dict[str, Path], cpu: str) -> None:
    """The native exception traffic (MCU-70, MCU-71) and the native frames (MCU-51, MCU-68: the handler's PR write
    taken natively) give the same history, its tail-chains included, and the same run as the Python paths."""
    reference = _outcome(late_irq[cpu], cpu, native_exceptions=False, native_frames=False)
    events = reference[0]
    assert isinstance(events, list) and any(isinstance(e, Entry) and e.returned is not None for e in events)
    assert _outcome(late_irq[cpu], cpu) == reference
    assert _outcome(late_irq[cpu], cpu, native_frames=False) == reference
    assert _outcome(late_irq[cpu], cpu, native_exceptions=False) == reference


def _check(history: History, board: Board) -> None:
    """The architecture's rule over a history: EXTI0 is tail-chained at its return iff its /IRQ fall (timed at its
    bus event, MCU-44) came at or before the return's first cycle, and then starts 6 (Cortex-M3) or 16 (Cortex-M0)
    cycles after it; an entry from thread mode follows a fall after the last return began; the latency reported is
    the longest fall to first instruction; a fall not yet served at the end has its handler running or pending (none
    is lost: late_irq clears PR before /IRQ can fall again)."""
    chain = board.core.cpu.tail_chain_cycles
    last: int | None = None  # the first cycle of the last return that unstacked
    for event in history.events:
        if isinstance(event, int):
            last = event
        elif event.returned is not None:
            assert event.fell is not None and event.fell <= event.returned, event
            assert event.cycles == event.returned + chain, event
        else:
            assert event.fell is None or last is None or event.fell > last, (event, last)
    latencies = [(entry.cycles - entry.fell) / board.core.cpu_hz for entry in history.entries if entry.fell is not None]
    assert board.irq_latency_s == max([history.latency_s, *latencies])
    core = board.core  # no fall lost: one not yet served has its handler running or pending
    assert board._irq_fell is None or EXTI0 in core.active or EXTI0 in core.pending


Run = tuple[int, int, int, bool]
"""One run of a history: late_irq's wait (µs), ``board.run``'s cycles (0: ``run_for`` instead), ``run_for``'s µs,
whether the handler clears PR again after its wait."""


def _unwatched(elf: Path, cpu: str, bit_rate: int, runs: list[Run], *, primask_at: int | None = None,
               tick: tuple[int, int, int] | None = None,
               **options: object) -> tuple[tuple[object, ...], tuple[int, int]]:  # fmt: skip
    """A history of runs on a board nobody watches (MCU-86: hook.c's returns on, unless ``options`` turn them
    off): everything the run shows, and how many tail-chains and plain returns hook.c took. ``primask_at``: the run
    after which PRIMASK is set (the core stopped wherever ``run_for`` ended: inside a handler, EXTI0's next return
    cannot chain). ``tick``: SysTick's reload, EXTI0's and SysTick's priorities, started at the next EXTI0 entry."""
    tail_chains = options.pop("tail_chains", True)
    board = _board(elf, cpu, bit_rate, **options)
    frames = board.native_frames
    if frames is not None:
        frames.tail_chains = bool(tail_chains)
    core = board.core
    if tick is not None:
        for name, value in zip(("tick_reload", "exti0_priority", "tick_priority"), tick, strict=True):
            core.write_bytes(core.image.address(name), struct.pack("<I", value))
    for index, (hold, cycles, micros, clear_late) in enumerate(runs):
        _hold(board, hold, clear_late=clear_late)
        if cycles:
            board.run(cycles)
        else:
            board.run_for(micros * 1e-6)
        if index == primask_at:
            board.core.set_reg("primask", 1)
    core = board.core
    return ((core.cycles, core.instructions, core.registers(), core.read_bytes(*core.ram), board.interrupts,
             board.irq_latency_s, board._irq_fell, board.now, board.bench.cycles, board.master.inputs(1),
             sorted(core.pending), list(core.active), board.served,
             [(v.time_s, v.pc, str(v.error)) for v in board.violations]),
            (0, 0) if frames is None else (frames.tail_chained, frames.plain_returns))  # fmt: skip


def _alike(elf: Path, cpu: str, bit_rate: int, runs: list[Run], primask_at: int | None = None,
           tick: tuple[int, int, int] | None = None) -> tuple[int, int]:  # fmt: skip
    """:func:`_unwatched` with hook.c's returns, without them and with every frame in Python: the same run; the
    number of tail-chains and plain returns hook.c took."""
    native, chains = _unwatched(elf, cpu, bit_rate, runs, primask_at=primask_at, tick=tick)
    assert native == _unwatched(elf, cpu, bit_rate, runs, primask_at=primask_at, tick=tick, tail_chains=False)[0]
    assert native == _unwatched(elf, cpu, bit_rate, runs, primask_at=primask_at, tick=tick, native_frames=False)[0]
    return chains


@pytest.mark.parametrize("cpu", sorted(CPUS))
def test_the_native_tail_chain_runs_alike(late_irq: dict[str, Path], cpu: str) -> None:
    """MCU-86: hook.c takes the returns whose tail-chain only samples EXTI0's line (the mirror valid, no bus event
    due): runs that chain (a wait longer than the cycle, PR cleared late or not), runs that end inside a handler
    (``run_for``) and runs on after it show the same as with each return in Python. late_irq's wait makes no access,
    so most of its chains find the next cycle's event due (Python's); one chain here is hook.c's (issue #13's case
    below: nearly all), and the returns of the handlers without a wait are plain ones, hook.c's."""
    runs: list[Run] = [(300, 3, 0, False), (300, 0, 700, True), (300, 0, 450, False), (0, 2, 0, False),
                       (450, 3, 0, True)]  # fmt: skip
    chains, plain = _alike(late_irq[cpu], cpu, 500_000, runs)
    assert chains >= 1 and plain >= 3


def test_a_return_under_primask_is_python_s(late_irq: dict[str, Path]) -> None:
    """MCU-86: PRIMASK set inside a handler (by the test, where ``run_for`` ended) masks EXTI0 in thread mode
    (B1.5.4): its next return does not chain, EXTI0 stays pending, the same with hook.c's tail-chains as without."""
    runs: list[Run] = [(300, 0, 650, False), (300, 0, 900, False)]
    counts = _alike(late_irq["cortex_m3"], "cortex_m3", 500_000, runs, primask_at=0)
    _, native = _unwatched(late_irq["cortex_m3"], "cortex_m3", 500_000, runs[:1])
    assert counts == native  # none after PRIMASK


def test_issue_13_s_case_chains_natively_alike(tmp_path: Path) -> None:
    """MCU-86 in issue #13's case (bench/bench_mcu.py: digital_io at 2 Mbit/s, SPI1 at f_PCLK / 16): hook.c takes
    nearly every EXTI0 return (a tail-chain), with the same run as every frame in Python."""
    elf = mcu_build.build(native.example("digital_io"), tmp_path / "br3.elf", defines={"BOARD_SPI_BR": "3u"})
    outcomes = []
    for native_frames in (True, False):
        board = Board(elf, bit_rate=2_000_000, strict=False, native_frames=native_frames)
        board.run(3)
        board.bench.master.set_outputs(1, b"\x12\x34")
        assert board.fw_board is not None
        board.fw_board.inputs = b"\xab\xcd"
        board.run(60)
        core = board.core
        outcomes.append((core.cycles, core.instructions, core.registers(), board.interrupts, board.irq_latency_s,
                         board.now, board.master.inputs(1), board.fw_board.outputs,
                         [(v.time_s, v.pc, str(v.error)) for v in board.violations]))  # fmt: skip
        if native_frames:
            assert board.native_frames is not None and board.native_frames.tail_chained >= 45
    assert outcomes[0] == outcomes[1]


@settings(max_examples=10, deadline=None, phases=(Phase.explicit, Phase.reuse, Phase.generate))
@given(cpu=st.sampled_from(sorted(CPUS)), bit_rate=st.sampled_from([500_000, 2_000_000]),
       runs=st.lists(st.tuples(st.integers(0, 500), st.integers(0, 3), st.integers(1, 900), st.booleans()),
                     min_size=1, max_size=4),
       primask=st.none() | st.integers(0, 3))  # fmt: skip
def test_any_history_runs_alike_with_the_native_tail_chain(late_irq: dict[str, Path], cpu: str, bit_rate: int,
                                                            runs: list[Run], primask: int | None) -> None:  # fmt: skip
    """MCU-86 over histories: random waits, PR cleared late or not, ``run`` and ``run_for`` (ending anywhere, inside
    a handler too), PRIMASK set at a run's end: hook.c's tail-chains change nothing a run shows."""
    _alike(late_irq[cpu], cpu, bit_rate, runs, primask_at=primask)


def test_a_line_held_through_the_handler_chains_natively_alike(late_irq: dict[str, Path]) -> None:
    """MCU-86, the level rule: the handler's PR writes lost (hook.c's own PR write turned off, so that each reaches
    Python's EXTI, which drops it), EXTI0's line stays asserted with nothing pended while active; hook.c samples it at
    the return and chains, as Python's return does."""
    outcomes = []
    for native_frames in (True, False):
        board = _board(late_irq["cortex_m3"], "cortex_m3", 500_000, native_frames=native_frames)
        exti = board.exti
        write = exti.write

        def dropping(offset: int, size: int, value: int, write: Callable[[int, int, int], None] = write) -> None:
            if offset != EXTI_PR:
                write(offset, size, value)

        exti.write = dropping  # type: ignore[method-assign]
        board.core.frames.exti_pr_offset = 1 << 32  # no offset: every PR write is Python's
        board.run(2)
        core = board.core
        outcomes.append((core.cycles, core.instructions, core.registers(), board.interrupts, board.irq_latency_s,
                         board.now, list(core.active), sorted(core.pending)))  # fmt: skip
        if native_frames:
            assert board.native_frames is not None and board.native_frames.tail_chained >= 5
    assert outcomes[0] == outcomes[1]


def test_a_return_onto_b_dot_is_python_s(late_irq: dict[str, Path]) -> None:
    """MCU-86 and MCU-4: the frame of a handler that ``run_for`` left running gets a ``b .`` in flash as its return
    address (the test writes it), so every later EXTI0 handler returns onto that wait, which the run loop takes
    without running its block; hook.c leaves those returns to Python, and the run is the same with every frame in
    Python."""
    outcomes = []
    for native_frames in (True, False):
        board = _board(late_irq["cortex_m3"], "cortex_m3", 500_000, native_frames=native_frames)
        core = board.core
        _hold(board, 100)
        board.run_for(400e-6)
        assert list(core.active) == [EXTI0]
        idle = idle_loops(core.image, core.flash)[0]
        core.write_bytes(int(core._state.frame) + 24, struct.pack("<I", idle))  # the stacked return address
        _hold(board, 0)
        board.run(6)
        outcomes.append((core.cycles, core.instructions, core.registers(), board.interrupts, board.irq_latency_s,
                         board.now, core.sleeping, core.pc))  # fmt: skip
        if native_frames:
            assert board.native_frames is not None and board.native_frames.plain_returns == 0
        assert board.interrupts >= 7 and core.pc == idle
    assert outcomes[0] == outcomes[1]


def test_a_main_loop_after_a_plain_return_stops_at_the_bus_event(tmp_path: Path) -> None:
    """MCU-86: digital_io with mcu/main_loop.c's fw_loop: the EXTI0 handler only notes the edge and returns, plain, to
    a main loop that keeps running; hook.c's return gives the step the run loop's deadline for thread mode (the next
    bus event, not the handler's wait after it), so the next /IRQ fall is taken on time, as with every frame in
    Python."""
    elf = mcu_build.build([native.example("digital_io"), MCU / "main_loop.c"], tmp_path / "loop.elf")
    outcomes = []
    for native_frames in (True, False):
        board = Board(elf, bit_rate=500_000, strict=False, native_frames=native_frames)
        board.run(10)
        core = board.core
        outcomes.append((core.cycles, core.instructions, core.registers(), board.interrupts, board.irq_latency_s,
                         board.now, board.master.inputs(1)))  # fmt: skip
        if native_frames:
            assert board.native_frames is not None and board.native_frames.plain_returns >= 5
    assert outcomes[0] == outcomes[1]


@pytest.mark.parametrize("value", ["no", 0, None, 1.0])
def test_tail_chains_takes_a_bool_only(late_irq: dict[str, Path], value: object) -> None:
    """MCU-86's switch refuses anything but a bool by name (a string would have reached ``int()`` at the next
    refresh)."""
    board = Board(late_irq["cortex_m3"], strict=False)
    assert board.native_frames is not None and board.native_frames.tail_chains
    with pytest.raises(ArgumentError, match="tail_chains"):
        board.native_frames.tail_chains = value  # type: ignore[assignment]
    assert board.native_frames.tail_chains


PRIORITIES = {"tick above": (0x40, 0x00), "tick below": (0x00, 0x40), "equal": (0x00, 0x00)}
"""EXTI0's and SysTick's priority bytes: SysTick preempts EXTI0's handler, waits for its return (a tail-chain into
it, or into EXTI0 first), or is pending beside it at the same priority."""


@pytest.mark.parametrize("order", sorted(PRIORITIES))
def test_returns_with_systick_about_run_alike(late_irq: dict[str, Path], order: str) -> None:
    """MCU-86 with a second exception: SysTick ticking through late_irq's handlers, preempting them or pending at
    their returns: hook.c leaves those returns to Python (another exception active or pending), takes the others,
    and the run (the ticks counted in RAM included) is the same as with each return in Python."""
    runs: list[Run] = [(0, 2, 0, False), (300, 3, 0, False), (120, 0, 700, True), (0, 3, 0, False)]
    chains, plain = _alike(late_irq["cortex_m3"], "cortex_m3", 500_000, runs, tick=(4_799, *PRIORITIES[order]))
    assert chains + plain >= 1


@settings(max_examples=8, deadline=None, phases=(Phase.explicit, Phase.reuse, Phase.generate))
@given(cpu=st.sampled_from(sorted(CPUS)), bit_rate=st.sampled_from([500_000, 2_000_000]),
       runs=st.lists(st.tuples(st.integers(0, 400), st.integers(0, 3), st.integers(1, 700), st.booleans()),
                     min_size=1, max_size=3),
       reload=st.integers(600, 30_000), order=st.sampled_from(sorted(PRIORITIES)))  # fmt: skip
def test_any_history_with_systick_runs_alike(late_irq: dict[str, Path], cpu: str, bit_rate: int, runs: list[Run],
                                             reload: int, order: str) -> None:  # fmt: skip
    """MCU-86 over histories with SysTick at a random period and priority order: hook.c's returns change nothing."""
    _alike(late_irq[cpu], cpu, bit_rate, runs, tick=(reload, *PRIORITIES[order]))

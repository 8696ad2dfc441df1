"""The board's run loop step by step: Python calls per step by function, and EXTI0's re-entries after a return.

Issue #13's case (``bench_mcu.py``'s: ``digital_io`` on the Cortex-M3 at 2 Mbit/s, SPI1 at 3 MHz, non-strict) or the
500 kbit/s one, ``--cycles`` master cycles after power-up (``bench_mcu._board``). ``--calls`` (default): cProfile's
call counts, each function's count and its count per step of the run loop (``Board._step``), the most called first
(MCU-79). ``--chain``: how many EXTI0 entries are tail-chained at a return (MCU-81), how many follow at once an
exception return whose /IRQ fall came before the return began, that is entries the core would tail-chain (MCU-80's
finding, before MCU-81), and the /IRQ latency reported. Both counts are deterministic. Run from the repository root:

    python bench/bench_steps.py [--rate 2000000|500000] [--cycles N] [--calls [--top N] | --chain]
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import tempfile
from pathlib import Path

from bench_mcu import _board
from supi3.mcu.board import Board
from supi3.mcu.build import build
from supi3.sdk import native


def _case(folder: Path, rate: int) -> Board:
    defines = {"BOARD_SPI_BR": "3u"} if rate == 2_000_000 else {}
    elf = build(native.example("digital_io"), folder / f"dio_{rate}.elf", defines=defines)
    return _board(elf, rate, True)


def calls(board: Board, cycles: int, top: int) -> None:
    """Print the run's calls in all and per step, and the ``top`` most called functions."""
    profiler = cProfile.Profile()
    profiler.runcall(board.run, cycles)
    stats = pstats.Stats(profiler).stats  # type: ignore[attr-defined]
    steps = next(v[0] for k, v in stats.items() if k[2] == "_step" and k[0].endswith("board.py"))
    total = sum(v[0] for v in stats.values())
    print(f"{total:,} calls, {steps} steps, {total / steps:.1f} a step")
    for count, (path, line, name) in sorted(((v[0], k) for k, v in stats.items()), reverse=True)[:top]:
        print(f"{count:8,} {count / steps:6.2f}  {Path(path).name}:{line} {name}")


def chain(board: Board, cycles: int) -> None:
    """Print how EXTI0 is entered: tail-chained at a return (MCU-81), at once after a return whose /IRQ fall came
    before the return began (the entries the core would tail-chain: MCU-80's finding), or otherwise; and the
    longest /IRQ latency the run reports."""
    core = board.core
    returned: list[tuple[int, int] | None] = [None]  # the last return's first and last cycle, back to thread mode
    in_return = [False]
    exception_return, entered = core.exception_return, core.entered
    counts = {"tail-chained": 0, "re-entered": 0, "other": 0}
    early: list[int] = []

    def on_return(exc_return: int) -> None:
        start = core.cycles
        in_return[0] = True
        try:
            exception_return(exc_return)
        finally:
            in_return[0] = False
        returned[0] = None if core.active else (start, core.cycles)

    def on_entered(number: int) -> None:
        fell, last = board._irq_fell, returned[0]
        if in_return[0]:
            counts["tail-chained"] += 1
        elif last is not None and fell is not None and fell <= last[0] and \
                core.cycles - core.cpu.entry_cycles == last[1]:  # fmt: skip
            counts["re-entered"] += 1
            early.append(last[0] - fell)
        else:
            counts["other"] += 1
        returned[0] = None
        entered(number)

    core.exception_return = on_return  # type: ignore[method-assign]
    core.entered = on_entered
    board.run(cycles)
    print(f"EXTI0 entries: {counts['tail-chained']} tail-chained at a return, {counts['re-entered']} right after a "
          f"return with /IRQ fallen before it (the fall {min(early, default=0)} to {max(early, default=0)} cycles "
          f"before the return), {counts['other']} other; /IRQ latency {board.irq_latency_s * 1e6:.3f} us")


def main(argv: list[str] | None = None) -> None:
    """Parse the arguments and print the chosen count."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rate", type=int, choices=(2_000_000, 500_000), default=2_000_000)
    parser.add_argument("--cycles", type=int, default=500)
    parser.add_argument("--top", type=int, default=40)
    mode = parser.add_mutually_exclusive_group()
    mode.add_argument("--calls", action="store_true", help="calls per step by function (the default)")
    mode.add_argument("--chain", action="store_true", help="EXTI0's re-entries after a return (MCU-80)")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as folder:
        board = _case(Path(folder), args.rate)
        if args.chain:
            chain(board, args.cycles)
        else:
            calls(board, args.cycles, args.top)


if __name__ == "__main__":
    main()

"""Benchmark: the firmware's binary on the emulated board (supi3.mcu) against the transaction-level chip.

The issue's case (#13): the digital 16/16 example (``digital_io.c``) built for the Cortex-M3, the core at 48 MHz, the
ring at 2 Mbit/s with back-to-back cycles, the transaction-level chip. SPI1 runs at f_PCLK / 16 = 3 MHz
(``BOARD_SPI_BR=3u``), the fastest the board's divider gives within Table 3-7's t0 = 333 ns at 2 Mbit/s (the board
port's default, 750 kHz, cannot serve a 2 Mbit/s cycle: its handler outlasts the cycle). The run is non-strict: the
handler's accesses reach the next latch phase (a finding, tests/test_mcu_board.py), which the run counts. Beside it
the same example at 500 kbit/s with the port's defaults, and the host build of the example on the firmware bench in
the same process (the baseline: the C driver through cffi, bytes at their Table 3-7 time).

Figures: simulated time / CPU time of the process (``time.process_time``: the machine is shared, wall time swings
with its load; the issue's goal: >= 1x), emulated instructions per second, and two ratios measured in the same
process: against the same binary with every poll and countdown loop iteration run (``skip_polls = False``: MCU-10
and MCU-11 off), against it with every µP interface frame through Python (``native_frames=False``: MCU-51 off) and
against the host build. ``--profile`` also splits the CPU time of one run (cProfile, which
slows the calls it counts, so the split is a guide, not a measure) by part: unicorn's C code with the native block
and memory hooks (MCU-25) and the ctypes transitions into the Python callbacks, a block's first costing, the rest of
the core, the STM32 peripheral models, the board's bus synchronisation and checks, and the chip, ring and bench
models. Every measured window (each mode, ``--profile`` too) begins after the power-up and after the firmware's
DWARF line tables have been read (``_board``): the first violation's backtrace reads them once, and whether that
violation falls in the power-up or in the window depends on the run. Run from the repository root:

    python bench/bench_mcu.py [--cycles N] [--repeat R] [--profile]
"""

from __future__ import annotations

import argparse
import collections
import cProfile
import os
import platform
import pstats
import tempfile
import time
from collections.abc import Callable
from functools import partial
from pathlib import Path

from supi3.mcu.board import Board
from supi3.mcu.build import build
from supi3.mcu.session import POWER_UP_CYCLES
from supi3.sdk import native
from supi3.sdk.bench import Bench


def _cpu_s(run: Callable[[], None], repeat: int) -> float:
    """The fastest of ``repeat`` runs, in CPU seconds of this process."""
    fastest = float("inf")
    for _ in range(repeat):
        start = time.process_time()
        run()
        fastest = min(fastest, time.process_time() - start)
    return fastest


def _board(elf: Path, bit_rate: int, skip: bool, native_frames: bool = True) -> Board:
    """The board after power-up, the master's outputs and the firmware's inputs set, and the firmware's DWARF line
    tables read (a violation's backtrace reads them once, at the first; whether that falls in the power-up depends
    on the run, so it is done here, outside every measured window)."""
    board = Board(elf, bit_rate=bit_rate, strict=False, native_frames=native_frames)
    board.core.skip_polls = skip
    board.run(POWER_UP_CYCLES)
    board.bench.master.set_outputs(1, b"\x12\x34")
    assert board.fw_board is not None
    board.fw_board.inputs = b"\xab\xcd"
    _ = board.core.image.line_at(0)  # the DWARF tables, else read at the first backtrace
    return board


def binary_run(elf: Path, bit_rate: int, cycles: int, repeat: int, skip: bool = True, native_frames: bool = True
               ) -> tuple[float, float, int, int, int]:  # fmt: skip
    """CPU seconds for ``cycles`` master cycles of ``elf`` after power-up (the fastest of ``repeat``), simulated
    seconds, instructions, interrupts, violations; ``skip``: MCU-10 and MCU-11 on; ``native_frames``: MCU-51 on."""
    outcome = (0.0, 0, 0, 0)
    fastest = float("inf")
    for _ in range(repeat):
        board = _board(elf, bit_rate, skip, native_frames)
        start_s, start_i = board.bench.now, board.core.instructions
        fastest = min(fastest, _cpu_s(partial(board.run, cycles), 1))
        outcome = (board.bench.now - start_s, board.core.instructions - start_i, board.interrupts,
                   len(board.violations))  # fmt: skip
    return (fastest, *outcome)


PARTS: tuple[tuple[str, str, frozenset[str] | None], ...] = (
    ("unicorn: C code with the native hooks (MCU-25), ctypes transitions", "/unicorn/", frozenset({"emu_start"})),
    ("unicorn's Python binding", "/unicorn/", None),
    ("core: a block's first cost (MCU-1, -10, -11)", "mcu/core.py", frozenset({"_describe"})),
    ("core: memory callbacks", "mcu/core.py", frozenset({"on_read", "on_write"})),
    ("core: the rest (run loop, access times, exceptions, registers)", "mcu/core.py", None),
    ("stm32: peripheral models", "mcu/stm32.py", None),
    ("board: bus synchronisation, pins, Table 3-7 checks", "mcu/board.py", None),
    ("board: the native frames' mirror and catch-up (MCU-51)", "mcu/frames.py", None),
    ("chip, ring and bench models (supi3 outside mcu)", "/supi3/", None),
    ("Python builtins and the rest", "", None),
)
"""The parts of ``--profile`` (name, part of the file's path, function names or all): the first that matches a
function takes its own time."""


def profile_split(elf: Path, bit_rate: int, cycles: int) -> list[tuple[str, float]]:
    """The own CPU time of ``cycles`` master cycles under cProfile, by part (:data:`PARTS`), largest first, as
    fractions of the whole."""
    board = _board(elf, bit_rate, skip=True)
    profiler = cProfile.Profile()
    profiler.runcall(board.run, cycles)
    split: collections.Counter[str] = collections.Counter()
    for (path, _line, name), row in pstats.Stats(profiler).stats.items():  # type: ignore[attr-defined]
        part = next(part for part, where, names in PARTS if where in path and (names is None or name in names))
        split[part] += row[2]
    total = sum(split.values())
    return [(part, seconds / total) for part, seconds in split.most_common()]


def host_run(bit_rate: int, cycles: int, repeat: int) -> tuple[float, float]:
    """CPU and simulated seconds of the same example built for the host, on the firmware bench."""
    simulated = 0.0
    firmware = native.CFirmware(native.example("digital_io"))
    fastest = float("inf")
    for _ in range(repeat):
        bench = Bench(firmware=firmware, bit_rate=bit_rate)
        bench.run(POWER_UP_CYCLES)
        start = bench.now
        fastest = min(fastest, _cpu_s(partial(bench.run, cycles), 1))
        simulated = bench.now - start
    return fastest, simulated


def main(argv: list[str] | None = None) -> None:
    """Measure and print."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cycles", type=int, default=500, help="master cycles measured after power-up")
    parser.add_argument("--repeat", type=int, default=3, help="runs; the fastest is reported")
    parser.add_argument("--profile", action="store_true", help="also split the CPU time by part (cProfile)")
    args = parser.parse_args(argv)
    print(f"reproduce: python bench/bench_mcu.py --cycles {args.cycles} --repeat {args.repeat}"
          + " --profile" * args.profile)  # fmt: skip
    load = ", ".join(f"{value:.1f}" for value in os.getloadavg())
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} CPUs, load {load}, "
          f"Python {platform.python_version()}")  # fmt: skip
    with tempfile.TemporaryDirectory() as folder:
        cases = [("issue case: 2 Mbit/s, SPI1 3 MHz", 2_000_000, {"BOARD_SPI_BR": "3u"}),
                 ("500 kbit/s, SPI1 750 kHz (the port's default)", 500_000, {})]  # fmt: skip
        for title, bit_rate, defines in cases:
            elf = build(native.example("digital_io"), Path(folder) / f"dio_{bit_rate}.elf", defines=defines)
            cpu, simulated, instructions, interrupts, violations = binary_run(elf, bit_rate, args.cycles,
                                                                              args.repeat)  # fmt: skip
            slow_cpu, slow_simulated = binary_run(elf, bit_rate, args.cycles, args.repeat, skip=False)[:2]
            python_cpu, python_simulated = binary_run(elf, bit_rate, args.cycles, args.repeat,
                                                      native_frames=False)[:2]  # fmt: skip
            host_cpu, host_simulated = host_run(bit_rate, args.cycles, args.repeat)
            speed = simulated / cpu
            print(
                f"digital_io.c on the Cortex-M3 at 48 MHz, {title}: {args.cycles} cycles, "
                f"{simulated * 1e3:.2f} ms simulated in {cpu:.3f} CPU s = {speed:.3f}x real time; "
                f"{instructions / cpu / 1e6:.2f} M instructions/s; {interrupts} interrupts, {violations} "
                f"violations; {speed / (slow_simulated / slow_cpu):.2f}x the speed with every loop iteration "
                f"run; {speed / (python_simulated / python_cpu):.2f}x the speed with every frame in Python "
                f"(native_frames=False, MCU-51); the host build on the bench {host_simulated / host_cpu:.2f}x real "
                f"time (binary / host {speed / (host_simulated / host_cpu):.3f})"
            )
            if args.profile:
                for part, share in profile_split(elf, bit_rate, args.cycles):
                    print(f"    {share * 100:5.1f} %  {part}")


if __name__ == "__main__":
    main()

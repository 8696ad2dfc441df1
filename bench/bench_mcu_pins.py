"""Benchmark: the firmware's binary on the emulated board against the pin-level chip (``fidelity="pin"``).

``digital_io.c`` built for the Cortex-M3 at 48 MHz, the ring at 500 kbit/s with the board port's defaults (SPI1 at
750 kHz), the pin-level whole chip stepped with the core (supi3.mcu.pins, MCU-14 to MCU-23): the power-up (3 master
cycles: set-up, the ID cycle, the first data cycle) and then ``--cycles`` data cycles, each part the fastest of
``--repeat`` fresh boards. Figures: CPU seconds of the process (``time.process_time``: the machine is shared) per
millisecond of bus time, and the bus time over the CPU time. Run from the repository root:

    python bench/bench_mcu_pins.py [--cycles N] [--repeat R]
"""

from __future__ import annotations

import argparse
import os
import platform
import tempfile
import time
from pathlib import Path

from supi3.cli import positive_integer
from supi3.mcu.board import Board
from supi3.mcu.build import build
from supi3.mcu.session import POWER_UP_CYCLES
from supi3.sdk import native


def pin_run(elf: Path, cycles: int, repeat: int) -> tuple[tuple[float, float], tuple[float, float]]:
    """(CPU s, bus s) of the power-up and of ``cycles`` data cycles after it, each the fastest of ``repeat``."""
    best = [(float("inf"), 0.0), (float("inf"), 0.0)]
    for _ in range(repeat):
        board = Board(elf, fidelity="pin")
        for part, count in enumerate((POWER_UP_CYCLES, cycles)):
            if part:
                board.master.set_outputs(1, b"\x12\x34")
                assert board.fw_board is not None
                board.fw_board.inputs = b"\xab\xcd"
            start_s, start = board.now, time.process_time()
            board.run(count)
            spent = time.process_time() - start
            if spent < best[part][0]:
                best[part] = (spent, board.now - start_s)
    return best[0], best[1]


def main() -> None:
    """Build the example, run the parts, print the figures."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cycles", type=positive_integer, default=10, help="data cycles measured after the power-up")
    parser.add_argument("--repeat", type=positive_integer, default=3, help="fresh boards; the fastest part is reported")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        elf = build(native.example("digital_io"), Path(folder) / "digital_io.elf", cpu="cortex_m3")
        parts = pin_run(elf, args.cycles, args.repeat)
    print(f"{platform.machine()}, load {os.getloadavg()[0]:.1f}; digital_io, Cortex-M3 at 48 MHz, 500 kbit/s, "
          f"pin level, best of {args.repeat}")  # fmt: skip
    names = (f"power-up, {POWER_UP_CYCLES} cycles", f"{args.cycles} data cycles")
    for name, (cpu_s, bus_s) in zip(names, parts, strict=True):
        print(f"  {name:24} {bus_s * 1e3:7.3f} ms of bus time in {cpu_s:6.2f} CPU s: "
              f"{cpu_s / (bus_s * 1e3):5.2f} CPU s a ms ({bus_s / cpu_s:.5f}x real time)")  # fmt: skip


if __name__ == "__main__":
    main()

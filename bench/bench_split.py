"""Benchmark: where the host build's time on the firmware bench goes (A32): the data cycle's side against the bytes.

Two runs of ``--cycles`` master cycles at 2 Mbit/s back to back, interleaved in one process (``time.process_time``,
the machine is shared), each after power-up:

- ``host2M``: ``digital_io.c`` built for the host (``bench_side.py``'s case of that name): the master, the ring, the
  chip model and the bench's events, plus the firmware's service routine clocking its bytes through the driver, the
  transport and the chip's µP interface;
- ``bench side``: the same bench, chip and set-up (the Python example's, ``DigitalIo``: the same cycles) with a
  service routine that clears IRQ_EVT without a frame (one ``cpu_read`` of register 14) and then moves the clock in
  10 steps of 3 µs (A29's measure of the bench side alone): the master, the ring, the chip's loads and latches and
  the bench's events, no byte.

Printed: each run's simulated / CPU time and the bench side's share of ``host2M``'s CPU time (the fastest runs).
``--opcodes``: in place of CPU time, each case's Python calls and opcodes a master cycle (``sys.settrace``, over
``--cycles`` cycles: deterministic, the machine's load does not move them) and the functions that run the most
opcodes; also for issue #13's case (``bench_side.py``'s ``issue13``: the binary on the emulated board), whose emulated
core's native work the count does not see. Run from the repository root::

    python bench/bench_split.py [--cycles N] [--rounds R] [--opcodes]
"""

from __future__ import annotations

import argparse
import gc
import os
import sys
import tempfile
import time
from collections import Counter
from collections.abc import Callable
from pathlib import Path
from types import FrameType
from typing import Any

from supi3.mcu.board import Board
from supi3.mcu.build import build
from supi3.sdk import native
from supi3.sdk.bench import Bench, Firmware
from supi3.sdk.driver import Supi3Driver
from supi3.sdk.examples.digital import DigitalIo

BIT_RATE = 2_000_000
POWER_UP = 3
STEPS = 10
STEP_S = 3e-6


class QuietIsr(DigitalIo):
    """The bench side alone: the example's set-up (the same SET, ID and interrupt, so the same cycles), then a service
    routine that clears IRQ_EVT without a frame and moves the clock in steps."""

    def __init__(self) -> None:
        super().__init__()
        self.bench: Bench | None = None

    def isr(self, drv: Supi3Driver) -> None:  # noqa: ARG002 (no driver call: no byte)
        bench = self.bench
        assert bench is not None
        bench.registers.cpu_read(14)  # IRQ_EVT, read-clear (3.4.14)
        bench.irq_edge()
        for _ in range(STEPS):
            bench.advance(bench.now + STEP_S)


def powered(firmware: Firmware) -> Bench:
    """The bench of a case at 2 Mbit/s back to back, with ``firmware``, after power-up."""
    bench = Bench(firmware=firmware, bit_rate=BIT_RATE)
    if isinstance(firmware, QuietIsr):
        firmware.bench = bench
    bench.run(POWER_UP)
    return bench


def run(firmware: Firmware, cycles: int) -> tuple[float, float, int]:
    """CPU seconds, simulated seconds and service routines of ``cycles`` master cycles after power-up."""
    bench = powered(firmware)
    start, interrupts = bench.now, bench.interrupts
    gc.collect()
    cpu = time.process_time()
    bench.run(cycles)
    return time.process_time() - cpu, bench.now - start, bench.interrupts - interrupts


def board(folder: Path) -> Board:
    """Issue #13's case (``bench_side.py``'s ``issue13``): ``digital_io.c`` built in ``folder`` for the emulated
    Cortex-M3, SPI1 at 3 MHz, on the board after power-up, its DWARF tables read."""
    elf = build(native.example("digital_io"), folder / "dio_2M.elf", defines={"BOARD_SPI_BR": "3u"})
    emulated = Board(elf, bit_rate=BIT_RATE, strict=False)
    emulated.run(POWER_UP)
    emulated.bench.master.set_outputs(1, b"\x12\x34")
    terminals = emulated.fw_board
    assert terminals is not None  # the example's image has its fw_board
    terminals.inputs = b"\xab\xcd"
    _ = emulated.core.image.line_at(0)
    return emulated


def count(run_cycles: Callable[[int], object], cycles: int) -> tuple[Counter[str], Counter[str], int]:
    """Python calls and opcodes by function (``file:name``, the file from ``supi3/`` on) of ``run_cycles(cycles)``:
    a powered bench's or board's ``run``; and the opcodes run inside the bus run before an /SS edge
    (``NativeFrames._bus_due``, MCU-84: issue #13's one entry into Python a steady cycle, MCU-91)."""
    calls: Counter[str] = Counter()
    opcodes: Counter[str] = Counter()
    inside = [0, 0]  # the _bus_due frames on the stack, the opcodes run while one is

    def trace(frame: FrameType, event: str, _: Any) -> Any:
        where = f"{frame.f_code.co_filename.rpartition('/src/')[2]}:{frame.f_code.co_name}"
        if event == "call":
            calls[where] += 1
            frame.f_trace_opcodes = True
            inside[0] += where == _BUS_DUE
        elif event == "opcode":
            opcodes[where] += 1
            inside[1] += inside[0] > 0
        elif event == "return":
            inside[0] -= where == _BUS_DUE
        return trace

    sys.settrace(trace)
    try:
        run_cycles(cycles)
    finally:
        sys.settrace(None)
    return calls, opcodes, inside[1]


_BUS_DUE = "supi3/mcu/frames.py:_bus_due"


def main(argv: list[str] | None = None) -> None:
    """Measure and print."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cycles", type=int, default=2000, help="master cycles measured after power-up")
    parser.add_argument("--rounds", type=int, default=3, help="runs of each case, interleaved")
    parser.add_argument("--opcodes", action="store_true", help="count Python calls and opcodes a cycle in place of "
                        "CPU time (sys.settrace: slow, try --cycles 100)")  # fmt: skip
    args = parser.parse_args(argv)
    if args.cycles < 1 or args.rounds < 1:
        parser.error("--cycles and --rounds must be at least 1")
    print(f"reproduce: python bench/bench_split.py --cycles {args.cycles} --rounds {args.rounds}"
          + " --opcodes" * args.opcodes)  # fmt: skip
    host = native.CFirmware(native.example("digital_io"))
    if args.opcodes:
        with tempfile.TemporaryDirectory() as folder:
            runs = [("host2M", powered(host).run), ("bench side", powered(QuietIsr()).run),
                    ("issue13 (the emulated core's own work not counted)", board(Path(folder)).run)]  # fmt: skip
            counts = [(case, *count(run_cycles, args.cycles)) for case, run_cycles in runs]
        for case, calls, opcodes, bus_due in counts:
            print(f"{case}: {calls.total() / args.cycles:.1f} Python calls and {opcodes.total() / args.cycles:.0f} "
                  "opcodes a master cycle" + (f" ({bus_due / args.cycles:.0f} inside the bus run before an /SS "
                  "edge, NativeFrames._bus_due)" if bus_due else "") + "; the most opcodes a cycle:")  # fmt: skip
            for where, n in opcodes.most_common(12):
                print(f"  {n / args.cycles:7.1f} opcodes, {calls[where] / args.cycles:5.1f} calls  {where}")
            files: Counter[str] = Counter()
            for where, n in opcodes.items():
                files[where.rpartition(":")[0]] += n
            print("  by file: " + ", ".join(f"{name} {n / args.cycles:.0f}" for name, n in files.most_common(8)))
        return
    results: dict[str, list[tuple[float, float, int]]] = {"host2M": [], "bench side": []}
    for _ in range(args.rounds):
        results["host2M"].append(run(host, args.cycles))
        results["bench side"].append(run(QuietIsr(), args.cycles))
    load = ", ".join(f"{value:.1f}" for value in os.getloadavg())
    print(f"load {load} (1, 5, 15 min) on {os.cpu_count()} CPUs; {args.cycles} cycles, fastest of {args.rounds}")
    fastest = {}
    for case, measured in results.items():
        cpu, simulated, interrupts = min(measured)
        fastest[case] = cpu
        print(f"{case:10}: {simulated / cpu:.3f}x real time ({cpu * 1e3:.1f} ms CPU for {simulated * 1e3:.2f} ms, "
              f"{interrupts} service routines)")  # fmt: skip
    print(f"the bench side's share of host2M's CPU time: {fastest['bench side'] / fastest['host2M']:.2f}")


if __name__ == "__main__":
    main()

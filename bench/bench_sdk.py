"""Benchmark: the Python firmware driver (supi3.sdk.driver) on the model, and a firmware run on the bench.

1. ``Supi3Driver.write``/``read`` register accesses per second over ``ModelTransport`` (half writes of IN0, half
   reads of OUT0, Motorola), beside ``UpInterface`` in the same process, each as a ratio to the real interface at
   the maximum SCLK of Table 3-7 (``supi3.timing.upif_byte_s``, two bytes per access).
2. An interrupt-driven firmware (1 word each way, the VALID interrupt, block transfers) on the firmware bench for
   ``--cycles`` master cycles: wall time, and simulated time / wall time. Issue #10 asks for 1,000 data cycles in
   under a second. Run from the repository root:

    python bench/bench_sdk.py [--accesses N] [--cycles N] [--repeat R]
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable

from supi3 import tables, timing
from supi3.config import decode
from supi3.model.registers import RegisterFile
from supi3.regmap import IN0, OUT0, SET
from supi3.sdk.bench import Bench, Firmware
from supi3.sdk.driver import Irq, Mode, Supi3Driver, get_u16, put_u16
from supi3.sdk.transports import ModelTransport
from supi3.spi.upif import UpInterface


def best(repeat: int, run: Callable[[], None]) -> float:
    """The fastest of ``repeat`` runs, in seconds."""
    best = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        run()
        best = min(best, time.perf_counter() - start)
    return best


def _registers() -> RegisterFile:
    return RegisterFile(decode("10011", "1110"))  # RB, Init-µP


def driver_accesses_per_s(accesses: int, repeat: int) -> float:
    """``Supi3Driver`` register accesses per second over ``ModelTransport``."""
    drv = Supi3Driver(ModelTransport(_registers()))
    drv.initialize(Mode.MOTOROLA)
    drv.write(SET, 0x82)

    def run() -> None:
        for k in range(accesses // 2):
            drv.write(IN0, k & 0xFF)
            drv.read(OUT0)

    return accesses // 2 * 2 / best(repeat, run)


def upif_accesses_per_s(accesses: int, repeat: int) -> float:
    """``UpInterface`` register accesses per second, the same workload (the model alone)."""
    up = UpInterface(_registers())
    up.initialize(Mode.MOTOROLA)
    up.write(SET, 0x82)

    def run() -> None:
        for k in range(accesses // 2):
            up.write(IN0, k & 0xFF)
            up.read(OUT0)

    return accesses // 2 * 2 / best(repeat, run)


class Echo(Firmware):
    """1 word each way, interrupt driven: IN = OUT + 1 after every valid data cycle."""

    def setup(self, drv: Supi3Driver) -> None:
        drv.initialize(Mode.MOTOROLA)
        drv.configure(0x83, 0x01)
        drv.irq_enable(Irq.VALID)

    def isr(self, drv: Supi3Driver) -> None:
        if drv.irq_service() & Irq.VALID:
            word = get_u16(drv.block_transfer(put_u16(0)))
            drv.block_transfer(put_u16((word + 1) & 0xFFFF))


def firmware_run(cycles: int, bit_rate: int, repeat: int) -> tuple[float, float, int]:
    """Wall seconds for ``cycles`` master cycles of :class:`Echo` on the bench, simulated seconds, interrupts."""
    simulated = 0.0
    interrupts = 0

    def run() -> None:
        nonlocal simulated, interrupts
        bench = Bench(firmware=Echo(), bit_rate=bit_rate)
        bench.run(cycles)
        simulated, interrupts = bench.now, bench.interrupts

    return best(repeat, run), simulated, interrupts


def main(argv: list[str] | None = None) -> None:
    """Measure and print."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--accesses", type=int, default=50_000, help="register accesses per rate")
    parser.add_argument("--cycles", type=int, default=1_000, help="master cycles of the firmware run")
    parser.add_argument("--repeat", type=int, default=3, help="runs; the fastest is reported")
    args = parser.parse_args(argv)
    print(f"reproduce: python bench/bench_sdk.py --accesses {args.accesses} --cycles {args.cycles} "
          f"--repeat {args.repeat}")
    drv_rate = driver_accesses_per_s(args.accesses, args.repeat)
    up_rate = upif_accesses_per_s(args.accesses, args.repeat)
    print(f"Supi3Driver over ModelTransport: {drv_rate:,.0f} accesses/s; UpInterface alone: {up_rate:,.0f} "
          f"accesses/s (driver/model {drv_rate / up_rate:.2f})")
    for bit_rate in tables.BIT_RATES:
        real = 1 / (2 * timing.upif_byte_s(bit_rate))
        print(f"  {bit_rate // 1000} kbit/s real interface {real:,.0f} accesses/s: driver {drv_rate / real:.2f}x, "
              f"UpInterface {up_rate / real:.2f}x")
    for bit_rate in tables.BIT_RATES:
        wall, simulated, interrupts = firmware_run(args.cycles, bit_rate, args.repeat)
        print(f"firmware bench, {bit_rate // 1000} kbit/s: {args.cycles} cycles, {interrupts} interrupts in "
              f"{wall:.3f} s wall = {simulated / wall:.2f}x real time ({simulated * 1e3:.1f} ms simulated)")


if __name__ == "__main__":
    main()

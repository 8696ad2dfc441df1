"""Benchmark: a ring of 512 one-byte devices (4096 I/O bits) at 2 Mbit/s, data cycles back to back.

Reports simulated bus time / wall time (target >= 10). Run from the repository root:

    python bench/bench_ring.py [--cycles N] [--repeat R] [--bit-rate 2000000]
"""

from __future__ import annotations

import argparse
import sys
import time

from supi3.interbus import wire
from supi3.interbus.device import PlainDevice
from supi3.interbus.master import Master
from supi3.interbus.ring import Ring

DEVICES = 512
LENGTH_CODE_1_BYTE = 0b01001  # Table 3-11: "1 byte"
ID_CODE_DIO = 0xBF  # Table A-3: local bus digital input/output module


def main(argv: list[str] | None = None) -> float:
    """Run the benchmark and return bus time / wall time."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cycles", type=int, default=2000)
    parser.add_argument("--repeat", type=int, default=3, help="runs; the fastest is reported")
    parser.add_argument("--bit-rate", type=int, default=2_000_000, choices=(500_000, 2_000_000))
    args = parser.parse_args(argv)
    devices = [PlainDevice(ID_CODE_DIO, LENGTH_CODE_1_BYTE) for _ in range(DEVICES)]
    ring = Ring(devices, bit_rate=args.bit_rate)
    master = Master(ring)
    if not master.start().ok:
        raise SystemExit("start-up ID cycle failed")
    for k, device in enumerate(devices, 1):
        device.set_inputs(bytes([k & 0xFF]))
        master.set_outputs(k, bytes([(k * 7) & 0xFF]))
    bus = wall = 0.0
    for _ in range(args.repeat):
        bus_start = ring.now
        wall_start = time.perf_counter()
        for _ in range(args.cycles):
            if not master.data_cycle().ok:
                raise SystemExit("data cycle failed")
        run_wall = time.perf_counter() - wall_start
        if wall == 0.0 or run_wall < wall:
            bus, wall = ring.now - bus_start, run_wall
    assert devices[-1].outputs == bytes([(DEVICES * 7) & 0xFF]) and master.inputs(DEVICES) == bytes([0])
    bits = wire.cycle_bits(DEVICES, DEVICES)
    ratio = bus / wall
    print(f"ring: {DEVICES} devices, {8 * DEVICES} I/O bits, {args.bit_rate} bit/s, {bits} bits per cycle "
          f"({bits / args.bit_rate * 1e3:.3f} ms)")  # fmt: skip
    print(f"{args.cycles} data cycles (best of {args.repeat} runs): bus time {bus:.3f} s, wall time {wall:.3f} s, "
          f"bus/wall = {ratio:.1f} (target >= 10)")  # fmt: skip
    print(f"reproduce: python bench/bench_ring.py --cycles {args.cycles} --repeat {args.repeat} "
          f"--bit-rate {args.bit_rate}")  # fmt: skip
    return ratio


if __name__ == "__main__":
    main(sys.argv[1:])

"""Benchmark: a ring of 512 one-byte devices (4096 I/O bits) at 2 Mbit/s, data cycles back to back.

Reports simulated bus time / wall time (target >= 10), for SUPI 3 chips (transaction-level model, binary I/O
mode LB-MR 8 IN/OUT) and, as the baseline in the same process, for plain register devices. Run from the
repository root:

    python bench/bench_ring.py [--cycles N] [--repeat R] [--bit-rate 2000000] [--profile TOP]

``--profile TOP`` runs ``--cycles`` more data cycles of each ring under cProfile and prints the TOP entries by own
time (docs/interbus.md, "Ring kernel", quotes them).
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import sys
import time

from supi3.config import decode
from supi3.interbus import wire
from supi3.interbus.device import PlainDevice
from supi3.interbus.master import Master
from supi3.interbus.ring import Ring
from supi3.model.chip import Supi3
from supi3.tables import clk_conf_for

DEVICES = 512
LENGTH_CODE_1_BYTE = 0b01001  # Table 3-11: "1 byte"
ID_CODE_DIO = 0xBF  # Table A-3: local bus digital input/output module


def _measure(kind: str, cycles: int, repeat: int, bit_rate: int, profile: int = 0) -> tuple[float, float]:
    """Best-of-``repeat`` (bus time, wall time) of ``cycles`` data cycles on a ring of ``kind`` devices."""
    clk_conf = clk_conf_for(bit_rate)
    devices: list[Supi3 | PlainDevice]
    if kind == "supi3":
        config = decode("01000", clk_conf=clk_conf)  # Table 2-4: LB-MR, 8 IN/OUT, ID BFh, 1 byte
        assert (config.id_code, config.length_code) == (ID_CODE_DIO, LENGTH_CODE_1_BYTE)
        chips = [Supi3(config) for _ in range(DEVICES)]
        for k, chip in enumerate(chips, 1):
            chip.set_mfp_inputs(k & 0xFF)
        devices = list(chips)
    else:
        devices = [PlainDevice(ID_CODE_DIO, LENGTH_CODE_1_BYTE) for _ in range(DEVICES)]
    ring = Ring(devices, bit_rate=bit_rate)
    master = Master(ring)
    if not master.start().ok:
        raise SystemExit("start-up ID cycle failed")
    for k, device in enumerate(devices, 1):
        if isinstance(device, PlainDevice):
            device.set_inputs(bytes([k & 0xFF]))  # after start-up: the INTERBUS reset clears IN data
    for k in range(1, DEVICES + 1):
        master.set_outputs(k, bytes([(k * 7) & 0xFF]))
    bus = wall = 0.0
    for _ in range(repeat):
        bus_start = ring.now
        wall_start = time.perf_counter()
        for _ in range(cycles):
            if not master.data_cycle().ok:
                raise SystemExit("data cycle failed")
        run_wall = time.perf_counter() - wall_start
        if wall == 0.0 or run_wall < wall:
            bus, wall = ring.now - bus_start, run_wall
    assert master.inputs(DEVICES) == bytes([0]) and master.inputs(1) == bytes([1])
    if profile:
        profiler = cProfile.Profile()
        profiler.enable()
        for _ in range(cycles):
            master.data_cycle()
        profiler.disable()
        print(f"{kind}: cProfile of {cycles} data cycles, top {profile} by own time")
        pstats.Stats(profiler, stream=sys.stdout).sort_stats("tottime").print_stats(profile)
    return bus, wall


def main(argv: list[str] | None = None) -> float:
    """Run the benchmark and return bus time / wall time for the SUPI 3 ring."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cycles", type=int, default=2000)
    parser.add_argument("--repeat", type=int, default=3, help="runs; the fastest is reported")
    parser.add_argument("--bit-rate", type=int, default=2_000_000, choices=(500_000, 2_000_000))
    parser.add_argument("--profile", type=int, default=0, metavar="TOP", help="print cProfile's TOP entries")
    args = parser.parse_args(argv)
    bits = wire.cycle_bits(DEVICES, DEVICES)
    print(f"ring: {DEVICES} devices, {8 * DEVICES} I/O bits, {args.bit_rate} bit/s, {bits} bits per cycle "
          f"({bits / args.bit_rate * 1e3:.3f} ms)")  # fmt: skip
    ratios = {}
    for kind in ("plain", "supi3"):
        bus, wall = _measure(kind, args.cycles, args.repeat, args.bit_rate, args.profile)
        ratios[kind] = bus / wall
        print(f"{kind:6} {args.cycles} data cycles (best of {args.repeat}): bus time {bus:.3f} s, wall time "
              f"{wall:.3f} s, bus/wall = {ratios[kind]:.1f} (target >= 10)")  # fmt: skip
    print(f"SUPI 3 model / plain devices speed ratio: {ratios['supi3'] / ratios['plain']:.2f}")
    print(f"reproduce: python bench/bench_ring.py --cycles {args.cycles} --repeat {args.repeat} "
          f"--bit-rate {args.bit_rate}")  # fmt: skip
    return ratios["supi3"]


if __name__ == "__main__":
    main(sys.argv[1:])

"""Benchmark: the cycle-accurate pin-level model on a data-cycle workload, clock cycles per second.

One SUPI 3 chip (RB, 8 IN/8 OUT) receives back-to-back data cycles from a master; the same traffic is run cycle
by cycle (``step``, what a per-cycle lockstep uses) and as whole traces (``run``, event-driven), and the ratio is
reported. The two give identical outputs (tests/test_model_pins.py). Run from the repository root:

    python bench/bench_model.py [--cycles N] [--repeat R]
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

from supi3.config import decode
from supi3.interbus import wire
from supi3.interbus.wire import Cycle, Frame
from supi3.model.pins import Supi3Pins
from supi3.tables import clk_conf_for


def workload(bit_rate: int, cycles: int) -> dict[str, np.ndarray]:
    """Input traces: idle, reset, an ID cycle, then ``cycles`` data cycles with changing data and MFP inputs."""
    lw = wire.LOOPBACK_BYTES_ON_LINE
    idle = wire.status_levels(Cycle.DATA, False, 4)
    parts = [idle, wire.reset_levels(1), idle,
             wire.cycle_levels(Frame.build(Cycle.ID, lw + wire.word_bytes(wire.command_word())), 1, True)]
    parts += [wire.cycle_levels(Frame.build(Cycle.DATA, lw + bytes([n & 0xFF])), 1, True) for n in range(cycles)]
    do1 = wire.levels_to_samples(np.concatenate(parts), bit_rate).astype(np.int64)
    n = len(do1)
    period = len(do1) // max(cycles, 1)
    mfp = (np.arange(n) // period) & 0xFF
    ones, zeros = np.ones(n, dtype=np.int64), np.zeros(n, dtype=np.int64)
    return {"do1": do1, "di2": zeros, "rbst_ext": zeros, "mfp_in": mfp, "stat_err_n": ones, "resu_n": ones,
            "vmon_ok": ones, "from_exr": 0 * ones}


def measure(bit_rate: int, cycles: int, repeat: int) -> tuple[int, float, float]:
    """(clock cycles, best step() seconds, best run() seconds)."""
    config = decode("10000", clk_conf=clk_conf_for(bit_rate))
    inputs = workload(bit_rate, cycles)
    n = len(inputs["do1"])
    names = list(inputs)
    rows = [dict(zip(names, values, strict=True)) for values in zip(*(inputs[k].tolist() for k in names),
                                                                     strict=True)]
    best_step = best_run = float("inf")
    for _ in range(repeat):
        model = Supi3Pins(config)
        start = time.perf_counter()
        for row in rows:
            model.step(row)
        best_step = min(best_step, time.perf_counter() - start)
        model = Supi3Pins(config)
        start = time.perf_counter()
        model.run(inputs)
        best_run = min(best_run, time.perf_counter() - start)
    return n, best_step, best_run


def main(argv: list[str] | None = None) -> None:
    """Print clock cycles per second at both bit rates."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cycles", type=int, default=50, help="data cycles in the workload")
    parser.add_argument("--repeat", type=int, default=3, help="runs; the fastest is reported")
    args = parser.parse_args(argv)
    for bit_rate in (500_000, 2_000_000):
        n, step_s, run_s = measure(bit_rate, args.cycles, args.repeat)
        print(f"{bit_rate // 1000:>5} kbit/s, {n} clocks: step() {n / step_s / 1e3:8.0f} k cycles/s, "
              f"run() {n / run_s / 1e6:6.2f} M cycles/s, run/step = {step_s / run_s:.1f}")
    print(f"reproduce: python bench/bench_model.py --cycles {args.cycles} --repeat {args.repeat}")


if __name__ == "__main__":
    main(sys.argv[1:])

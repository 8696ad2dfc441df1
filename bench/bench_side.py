"""Benchmark: the bench side of firmware in the loop (the chip model, the master and ring, the bench's clock and the
board's bus synchronisation), this tree against another one, interleaved in one process.

Cases, each simulated time / CPU time (``time.process_time``, the machine is shared) after power-up (and, for the
binary, after the firmware's DWARF tables have been read, as ``bench_mcu``'s windows begin):

- ``issue13``: ``digital_io.c`` on the emulated Cortex-M3 at 48 MHz, 2 Mbit/s back to back, SPI1 at 3 MHz (issue #13,
  ``bench_mcu.binary_run``); ``500k``: the same at 500 kbit/s with the board port's defaults;
- ``host2M``, ``host500k``: the same example built for the host on the firmware bench (``bench_mcu.host_run``): no
  emulation, so nearly all of its time is the bench side;
- ``ring512``: 512 SUPI 3 chips at 2 Mbit/s, data cycles (``bench_ring``'s ring), bus time / CPU time.

``--against SRC`` loads a second tree's ``src`` folder beside this one (e.g. ``git worktree add /tmp/base <commit>``,
then ``--against /tmp/base/src``): the rounds alternate the trees' order, each run starts after a garbage collection,
and the figures are the fastest and slowest run of each tree, the ratio of the fastest, and whether both trees did
the same work (instructions, interrupts, violations, process data). ``--tree SRC`` measures another ``src`` folder in
place of this repository's (``bench/bench_mypyc.py`` measures a compiled copy of this tree so). Run from the
repository root:

    python bench/bench_side.py [--against SRC] [--tree SRC] [--rounds N] [--cases issue13,500k,host2M,host500k,ring512]
"""

from __future__ import annotations

import argparse
import cProfile
import gc
import importlib
import os
import pstats
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import Any

Tree = dict[str, ModuleType]
Outcome = tuple[float, float, tuple[object, ...]]
"""CPU seconds, simulated seconds, what the run did (to compare the trees)."""
POWER_UP = 3
"""Cycles before the measured ones (as bench_mcu)."""
CYCLES = {"issue13": 500, "500k": 500, "host2M": 500, "host500k": 500, "ring512": 50}
RING_DEVICES = 512


def _own(name: str) -> bool:
    return name == "supi3" or name.startswith("supi3.")


def load(src: str) -> Tree:
    """Import the modules the cases use from the ``src`` folder ``src``; return that tree's modules."""
    if not (Path(src) / "supi3" / "__init__.py").is_file():  # else another supi3 on the path would be measured
        raise SystemExit(f"bench_side.py: {src} holds no supi3 package")
    for name in [n for n in sys.modules if _own(n)]:
        del sys.modules[name]
    sys.path.insert(0, src)
    try:
        for module in ("supi3.sdk.bench", "supi3.mcu.board", "supi3.mcu.build", "supi3.sdk.native",
                       "supi3.interbus.master", "supi3.interbus.ring", "supi3.model.chip", "supi3.config",
                       "supi3.tables"):  # fmt: skip
            importlib.import_module(module)
    except ImportError as error:  # a tree too old for a case's modules
        raise SystemExit(f"bench_side.py: {src}: {error}") from error
    finally:
        sys.path.remove(src)
    return {n: m for n, m in sys.modules.items() if _own(n)}


def use(tree: Tree) -> None:
    """Make ``tree`` the ``supi3`` that imports inside functions find."""
    for name in [n for n in sys.modules if _own(n)]:
        del sys.modules[name]
    sys.modules.update(tree)


COUNT_CALLS = False
"""``--calls``: run the measured part under cProfile and report its function calls in place of CPU seconds."""


def _cpu(run: Callable[[], object]) -> float:
    gc.collect()
    if COUNT_CALLS:
        profiler = cProfile.Profile()
        profiler.runcall(run)
        return float(pstats.Stats(profiler).total_calls)  # type: ignore[attr-defined]
    start = time.process_time()
    run()
    return time.process_time() - start


def binary(tree: Tree, elf: Path, bit_rate: int, cycles: int) -> Outcome:
    """``cycles`` master cycles of the firmware binary on the board (``bench_mcu._board``'s set-up)."""
    board: Any = tree["supi3.mcu.board"].Board(elf, bit_rate=bit_rate, strict=False)
    board.run(POWER_UP)
    board.bench.master.set_outputs(1, b"\x12\x34")
    board.fw_board.inputs = b"\xab\xcd"
    _ = board.core.image.line_at(0)  # the DWARF tables, else read at the first backtrace (bench_mcu._board)
    start = board.bench.now
    cpu = _cpu(lambda: board.run(cycles))
    return cpu, board.bench.now - start, (board.core.instructions, board.interrupts, len(board.violations),
                                          board.bench.master.inputs(1), board.fw_board.outputs)  # fmt: skip


def host(tree: Tree, bit_rate: int, cycles: int) -> Outcome:
    """``cycles`` master cycles of the host build on the firmware bench (``bench_mcu.host_run``)."""
    native: Any = tree["supi3.sdk.native"]
    bench: Any = tree["supi3.sdk.bench"].Bench(firmware=native.CFirmware(native.example("digital_io")),
                                                bit_rate=bit_rate)  # fmt: skip
    bench.run(POWER_UP)
    start = bench.now
    cpu = _cpu(lambda: bench.run(cycles))
    return cpu, bench.now - start, (bench.interrupts, bench.bytes_clocked, bench.master.inputs(1))


def ring512(tree: Tree, cycles: int) -> Outcome:
    """``cycles`` data cycles of 512 SUPI 3 chips in LB-MR 8 IN/OUT at 2 Mbit/s (``bench_ring``'s ring)."""
    chip: Any = tree["supi3.model.chip"]
    config = tree["supi3.config"].decode("01000", clk_conf=tree["supi3.tables"].clk_conf_for(2_000_000))
    chips = [chip.Supi3(config) for _ in range(RING_DEVICES)]
    for k, device in enumerate(chips, 1):
        device.set_mfp_inputs(k & 0xFF)
    ring: Any = tree["supi3.interbus.ring"].Ring(chips, bit_rate=2_000_000)
    master: Any = tree["supi3.interbus.master"].Master(ring)
    if not master.start().ok:
        raise SystemExit("start-up ID cycle failed")
    for k in range(1, RING_DEVICES + 1):
        master.set_outputs(k, bytes([(k * 7) & 0xFF]))
    start = ring.now

    def run() -> None:
        for _ in range(cycles):
            master.data_cycle()

    cpu = _cpu(run)
    return cpu, ring.now - start, tuple(master.inputs(k) for k in range(1, RING_DEVICES + 1))


def main(argv: list[str] | None = None) -> None:
    """Measure and print."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--against", help="another tree's src folder, measured interleaved with this one")
    parser.add_argument("--tree", help="the src folder measured as this tree (default: this repository's)")
    parser.add_argument("--rounds", type=int, default=3, help="runs of each case and tree")
    parser.add_argument("--cases", default=",".join(CYCLES), help="comma-separated: " + ", ".join(CYCLES))
    parser.add_argument("--calls", action="store_true", help="count the function calls of each run (cProfile) in "
                        "place of its CPU time: a measure the machine's load does not move")  # fmt: skip
    args = parser.parse_args(argv)
    if args.rounds < 1:
        parser.error(f"--rounds must be at least 1, not {args.rounds}")
    global COUNT_CALLS
    COUNT_CALLS = args.calls
    cases = args.cases.split(",")
    unknown = set(cases) - CYCLES.keys()
    if unknown:
        parser.error(f"unknown case(s) {sorted(unknown)}: choose from {list(CYCLES)}")
    print(f"reproduce: python bench/bench_side.py --rounds {args.rounds} --cases {args.cases}"
          + (f" --against {args.against}" if args.against else "") + (f" --tree {args.tree}" if args.tree else "")
          + " --calls" * args.calls)  # fmt: skip
    here = args.tree or str(Path(__file__).resolve().parents[1] / "src")
    trees = {"this": load(here)}
    if args.against:
        trees = {"before": load(args.against), "after": trees["this"]}
    use(trees["this" if "this" in trees else "after"])
    build: Any = sys.modules["supi3.mcu.build"].build
    native: Any = sys.modules["supi3.sdk.native"]
    with tempfile.TemporaryDirectory() as folder:
        elfs = {rate: build(native.example("digital_io"), Path(folder) / f"dio_{rate}.elf", defines=defines)
                for rate, defines in ((2_000_000, {"BOARD_SPI_BR": "3u"}), (500_000, {}))}  # fmt: skip
        runs: dict[str, Callable[[Tree], Outcome]] = {
            "issue13": lambda t: binary(t, elfs[2_000_000], 2_000_000, CYCLES["issue13"]),
            "500k": lambda t: binary(t, elfs[500_000], 500_000, CYCLES["500k"]),
            "host2M": lambda t: host(t, 2_000_000, CYCLES["host2M"]),
            "host500k": lambda t: host(t, 500_000, CYCLES["host500k"]),
            "ring512": lambda t: ring512(t, CYCLES["ring512"]),
        }
        results: dict[tuple[str, str], list[Outcome]] = {(c, k): [] for c in cases for k in trees}
        order = list(trees)
        for round_ in range(args.rounds):
            for case in cases:
                for key in order if round_ % 2 == 0 else order[::-1]:
                    use(trees[key])
                    results[case, key].append(runs[case](trees[key]))
    load_avg = ", ".join(f"{value:.1f}" for value in os.getloadavg())
    print(f"load {load_avg} (1, 5, 15 min) on {os.cpu_count()} CPUs; simulated / CPU time, fastest and slowest run")
    for case in cases:
        parts = []
        if args.calls:
            counts = {key: int(results[case, key][0][0]) for key in trees}
            ratio = f"; after / before {counts['before'] / counts['after']:.2f}x" if args.against else ""
            print(f"{case:8} {CYCLES[case]} cycles: " + ", ".join(f"{k} {n:,} calls" for k, n in counts.items())
                  + ratio)  # fmt: skip
            continue
        for key in trees:
            cpus = sorted(run[0] for run in results[case, key])
            simulated = results[case, key][0][1]
            parts.append(f"{key} {simulated / cpus[0]:.3f}x-{simulated / cpus[-1]:.3f}x ({cpus[0] * 1e3:.1f} ms "
                         f"CPU for {simulated * 1e3:.2f} ms)")  # fmt: skip
        line = f"{case:8} {CYCLES[case]} cycles: " + "; ".join(parts)
        if args.against:
            before = min(run[0] for run in results[case, "before"])
            after = min(run[0] for run in results[case, "after"])
            same = all(run[2] == results[case, "before"][0][2] for key in trees for run in results[case, key])
            line += f"; after / before {before / after:.2f}x; same work: {same}"
        print(line)


if __name__ == "__main__":
    main()

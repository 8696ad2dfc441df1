"""Sweep: a BK's self-closure of a silent branch seen alike at both fidelities (BK-50), over ``branch_silence``.

For every silence limit (clocks) and every tree of the tests' ``CASES`` (BK-RB, BK-LB, LBD-MR, LBD-OR, and LBD-MR
branches of 2 and 3 devices, BK-55), the branch
is switched on with the extended function and cut, then the master runs 6 cycles at the transaction level and at
pin level: every cycle's view (kind, success, diagnostics, configuration, data, BK status) must be alike and the BK
closed at both (``closes_alike`` of tests/test_model_pinring_tree.py, about 0.5 s a run: too slow for the suite,
which runs a seeded sample and the old window points). Run from the repository root:

    python bench/closure_sweep.py                          # 6,000..13,750 in steps of 250: 192 runs
    python bench/closure_sweep.py --start 8900 --stop 12800 --step 25   # the fine sweep: 942 runs

Prints one line per run and the differing runs; exits 1 if any differs.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

from supi3.cli import positive_integer
from supi3.terminal import BRANCH_SILENCE_CLOCKS
from test_model_pinring_tree import CASES, closes_alike  # the tests' helpers, on the path above


def main() -> int:
    """Run the sweep given on the command line; 0 if every run is alike."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--start", type=positive_integer, default=6_000, help="first silence limit, clocks")
    parser.add_argument("--stop", type=positive_integer, default=13_750, help="last silence limit (included), clocks")
    parser.add_argument("--step", type=positive_integer, default=250, help="step, clocks")
    args = parser.parse_args()
    if args.stop < args.start:
        parser.error(f"--stop ({args.stop}) must not be before --start ({args.start})")
    if args.stop > BRANCH_SILENCE_CLOCKS:
        parser.error(f"--stop ({args.stop}) must be at most {BRANCH_SILENCE_CLOCKS} clocks (BK-3's 10 ms: a chip's "
                     "branch_silence)")
    differing: list[tuple[int, str]] = []
    runs = 0
    for silence in range(args.start, args.stop + 1, args.step):
        for kind, devices in CASES:
            began = time.process_time()
            try:
                closes_alike(kind, devices, [], silence)
                alike = True
            except AssertionError:
                alike = False
                differing.append((silence, f"{kind.name} x {devices}"))
            runs += 1
            print(f"{silence} {kind.name} x {devices} {'alike' if alike else 'DIFFERS'} "
                  f"{time.process_time() - began:.1f} s", flush=True)  # fmt: skip
    print(f"{runs - len(differing)} of {runs} alike; differing: {differing or 'none'}")
    return 1 if differing else 0


if __name__ == "__main__":
    sys.exit(main())

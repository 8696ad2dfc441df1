"""Sweep: the idle a tree's history needs after its chips' power-up before both fidelities agree (M22's limit 2).

The tree of tests/test_model_pinring_recognition.py (RB, a BK with 2 branch devices, RB; 2 Mbit/s), every branch kind
and the rows RF = 11 with LBST = 1, 00, 10 with LBST = 0 and 1; a few histories around the BK's power-up (``power``)
or around the ring's first clock (``initial``), each run with k idle status telegrams there (0..12 and 20, the other
wait at 20): prints per kind and row the k at which some step differs (the BK's recognition or the master's view,
``recognition_history``, about 0.3 s a run). Run from the repository root:

    python bench/wake_tree_sweep.py power          # after the BK's power-up step: 1,120 runs
    python bench/wake_tree_sweep.py initial        # before the first step: 896 runs
    python bench/wake_tree_sweep.py power --max-k 6   # k = 0..6 and 20 only (M23: the transaction level follows)

Exits 1 if a k at or above the tests' wait differs.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

from supi3.interbus import wire
from supi3.interbus.ring import BranchKind
from test_model_pinring_recognition import (  # the tests' helpers, on the path above
    FIRST_IDLE_TELEGRAMS,
    POWER_IDLE_TELEGRAMS,
    Op,
    recognition_history,
)

ROWS = [("11", True), ("00", False), ("10", False), ("10", True)]
START, POWER, CYCLE = ("start", 0), ("power", 0), ("cycle", 0)
HISTORIES: dict[str, list[list[Op]]] = {
    "power": [[START, POWER, CYCLE, CYCLE, CYCLE], [POWER, CYCLE, CYCLE, CYCLE],
              [START, ("off", 0), POWER, CYCLE, ("on", 0), CYCLE, CYCLE],
              [START, ("cut", 0), POWER, ("repair", 0), CYCLE, CYCLE], [START, CYCLE, POWER, POWER, CYCLE, CYCLE]],
    "initial": [[START, CYCLE, CYCLE], [CYCLE, CYCLE], [("cut", 0), START, ("repair", 0), CYCLE],
                [("off", 0), CYCLE, CYCLE]],
}
TELEGRAM_S = wire.STATUS_TELEGRAM_BITS / 2_000_000


def main() -> int:
    """Run the sweep named on the command line; 0 if nothing differs at or above the tests' wait."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("where", choices=sorted(HISTORIES), help="the wait swept")
    parser.add_argument("--max-k", type=int, default=12, choices=range(13), help="the largest k below 20 swept")
    args = parser.parse_args()
    wait = POWER_IDLE_TELEGRAMS if args.where == "power" else FIRST_IDLE_TELEGRAMS
    started = time.process_time()
    worst = -1
    for kind in BranchKind:
        for row in ROWS:
            differ = []
            for k in [*range(args.max_k + 1), 20]:
                first, power = (20, k) if args.where == "power" else (k, 20)
                if any(a != b for ops in HISTORIES[args.where]
                       for a, b in recognition_history(kind, row, ops, first * TELEGRAM_S, power * TELEGRAM_S)):
                    differ.append(k)
            worst = max(worst, *differ) if differ else worst
            print(f"{args.where} {kind.name} RF={row[0]} LBST={int(row[1])}: differ at k = {differ}", flush=True)
    print(f"last differing k: {worst}; the tests wait {wait}; CPU {time.process_time() - started:.0f} s")
    return 1 if worst >= wait else 0


if __name__ == "__main__":
    sys.exit(main())

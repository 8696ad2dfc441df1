"""Sweep: the idle a tree's history needs after its chips' power-up before both fidelities agree (M22's limit 2, M25).

The tree of tests/test_model_pinring_recognition.py (RB, a BK with 2 branch devices, RB; 2 Mbit/s), every branch kind
and the rows RF = 11 with LBST = 1, 00, 10 with LBST = 0 and 1; a few histories around the BK's power-up (``power``)
or around the ring's first clock (``initial``), each run with k idle status telegrams there (0..12 and 20, the other
wait at 20): prints per kind and row the k at which some step differs (the BK's recognition or the master's view,
``recognition_history``, about 0.3 s a run). Run from the repository root:

    python bench/wake_tree_sweep.py power          # after the BK's power-up step: 1,120 runs
    python bench/wake_tree_sweep.py initial        # before the first step: 896 runs
    python bench/wake_tree_sweep.py power --max-k 6   # k = 0..6 and 20 only (M25: the transaction level follows)
    python bench/wake_tree_sweep.py window --rate 2000000   # M25: one chip of a running tree powered up, k = 0..7
    python bench/wake_tree_sweep.py trace --rate 500000 --devices 3 --position 4 --k 2   # M25's limit 1, at pin level

``window`` runs the trees of ``test_model_pinring_tree.CASES`` (RF = 11, LBST = 1): every chip in turn powered up in a
running tree (/ResU low for 4 status telegrams; ``Ring.power_up``), k idle status telegrams, two cycles, and prints per
tree and physical position both fidelities' cycles (``P``: passed, else the first error kind's first three letters;
``r``: the branch recognised after it) and the k where they differ; exits 1 if the first passing k differs.

``trace`` runs one case of ``window`` in an LBD-MR branch of ``--devices`` at pin level with its pins recorded from the
power-down on: the first cycle's success and error kinds, then each chip's forward output (DO2) and return output
(DI1, an LBD-MR chip's looped return line, BK-35) from the power-down to the cycle's start + 40 bit periods, as runs of
level x bit periods (M25's limit 1: the return block of the device before the woken one generates a counter telegram
after 32 idle bit periods, BK-30).

Exits 1 if a k at or above the tests' wait (per branch kind) differs.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

from supi3.interbus import wire
from supi3.interbus.master import Master
from supi3.interbus.ring import BranchKind
from supi3.model.pinring import PinRing
from test_model_pinring_powerup import idle, power_cycle
from test_model_pinring_recognition import (  # the tests' helpers, on the path above
    FIRST_IDLE_TELEGRAMS,
    POWER_IDLE_TELEGRAMS,
    TELEGRAM_S,
    Op,
    recognition_history,
)
from test_model_pinring_tree import CASES
from test_model_pinring_tree_powerup import FIRST_IDLE_TELEGRAMS as TREE_IDLE_TELEGRAMS
from test_model_pinring_tree_powerup import RATES, Seen, after_power_up, trees

ROWS = [("11", True), ("00", False), ("10", False), ("10", True)]
START, POWER, CYCLE = ("start", 0), ("power", 0), ("cycle", 0)
HISTORIES: dict[str, list[list[Op]]] = {
    "power": [[START, POWER, CYCLE, CYCLE, CYCLE], [POWER, CYCLE, CYCLE, CYCLE],
              [START, ("off", 0), POWER, CYCLE, ("on", 0), CYCLE, CYCLE],
              [START, ("cut", 0), POWER, ("repair", 0), CYCLE, CYCLE], [START, CYCLE, POWER, POWER, CYCLE, CYCLE]],
    "initial": [[START, CYCLE, CYCLE], [CYCLE, CYCLE], [("cut", 0), START, ("repair", 0), CYCLE],
                [("off", 0), CYCLE, CYCLE]],
}


def _short(seen: Seen) -> str:
    return "".join(("P" if ok else kinds[0].name[:3] if kinds else "F") + ("r" if recognised else "-")
                   for ok, kinds, recognised in seen)


def window(rate: int) -> int:
    """The ``window`` sweep at ``rate``: 0 if every first passing k is the same at both fidelities."""
    started = time.process_time()
    firsts_differ = 0
    for kind, m in CASES:
        for position in range(1, m + 4):
            tl = [_short(after_power_up(trees(kind, m, rate)[0], position, k)) for k in range(8)]
            pin = [_short(after_power_up(trees(kind, m, rate)[1], position, k)) for k in range(8)]
            first = [next((k for k, seen in enumerate(side) if seen[0] == "P"), None) for side in (tl, pin)]
            firsts_differ += first[0] != first[1]
            print(f"{kind.name} m={m} position {position}: first passing k {first[0]}/{first[1]}, differ at k = "
                  f"{[k for k in range(8) if tl[k] != pin[k]]}; TL {' '.join(tl)} | pin {' '.join(pin)}", flush=True)
    print(f"first passing k differing: {firsts_differ}; CPU {time.process_time() - started:.0f} s")
    return 1 if firsts_differ else 0


def _runs(samples: np.ndarray, cpb: int) -> str:
    """``samples`` as runs of level x bit periods."""
    edges = np.flatnonzero(np.diff(samples)) + 1
    starts = np.concatenate([[0], edges])
    lengths = np.diff(np.concatenate([starts, [len(samples)]]))
    return " ".join(f"{int(samples[a])}x{n / cpb:g}" for a, n in zip(starts, lengths, strict=True))


def trace(rate: int, devices: int, position: int, telegrams: int) -> int:
    """The ``trace`` of one LBD-MR case at pin level (the history of ``after_power_up``, its first cycle)."""
    pin = trees(BranchKind.LBD_MR, devices, rate)[1]
    assert isinstance(pin, PinRing)
    idle(pin, TREE_IDLE_TELEGRAMS)
    master = Master(pin, locate=False, max_devices=8)
    assert master.start().ok and master.cycle().ok
    pin.record = True
    power_cycle(pin, position)
    idle(pin, telegrams)
    start = len(pin.recorded()[0]["do2"])
    result = master.cycle()
    print(f"cycle ok {result.ok}, {[d.kind.name for d in result.diagnostics]}; cycle starts {start} clocks after the "
          "power-down")
    cpb = wire.clocks_per_bit(rate)
    for number, pins in enumerate(pin.recorded(), 1):
        for name in ("do2", "di1"):
            print(f"position {number} {name}: {_runs(np.asarray(pins[name][: start + 40 * cpb]), cpb)}")
    return 0


def main() -> int:
    """Run the sweep named on the command line; 0 if nothing differs at or above the tests' wait."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("where", choices=[*sorted(HISTORIES), "window", "trace"],
                        help="the wait swept, M25's window, or one LBD-MR case traced")
    parser.add_argument("--max-k", type=int, choices=range(13), help="the largest k below 20 swept (12)")
    parser.add_argument("--rate", type=int, choices=RATES, help="the window's bit rate (2000000)")
    parser.add_argument("--devices", type=int, choices=range(1, 4), help="trace: LBD-MR devices (3)")
    parser.add_argument("--position", type=int, help="trace: the physical position powered up (4)")
    parser.add_argument("--k", type=int, choices=range(13), help="trace: idle telegrams after it (2)")
    args = parser.parse_args()
    # option: (its default, the sweeps that read it); one given to another sweep would be ignored silently
    used = {"max_k": (12, ("initial", "power")), "rate": (2_000_000, ("window", "trace")),
            "devices": (3, ("trace",)), "position": (4, ("trace",)), "k": (2, ("trace",))}  # fmt: skip
    for dest, (default, sweeps) in used.items():
        if getattr(args, dest) is None:
            setattr(args, dest, default)
        elif args.where not in sweeps:
            parser.error(f"--{dest.replace('_', '-')} is for {' and '.join(sweeps)} only, not {args.where}")
    if args.where == "trace":
        positions = args.devices + 3  # trees(): the RB device, the BK, its branch devices, the RB device
        if not 1 <= args.position <= positions:
            parser.error(f"--position must be a physical position from 1 to {positions} (--devices "
                         f"{args.devices}), not {args.position}")
        return trace(args.rate, args.devices, args.position, args.k)
    if args.where == "window":
        return window(args.rate)
    waits = POWER_IDLE_TELEGRAMS if args.where == "power" else FIRST_IDLE_TELEGRAMS
    started = time.process_time()
    late = []
    for kind in BranchKind:
        worst = -1
        for row in ROWS:
            differ = []
            for k in [*range(args.max_k + 1), 20]:
                first, power = (20, k) if args.where == "power" else (k, 20)
                if any(a != b for ops in HISTORIES[args.where]
                       for a, b in recognition_history(kind, row, ops, first * TELEGRAM_S, power * TELEGRAM_S)):
                    differ.append(k)
            worst = max(worst, *differ) if differ else worst
            print(f"{args.where} {kind.name} RF={row[0]} LBST={int(row[1])}: differ at k = {differ}", flush=True)
        print(f"{kind.name}: last differing k {worst}; the tests wait {waits[kind]}", flush=True)
        late += [kind.name] if worst >= waits[kind] else []
    print(f"waits too short: {late}; CPU {time.process_time() - started:.0f} s")
    return 1 if late else 0


if __name__ == "__main__":
    sys.exit(main())

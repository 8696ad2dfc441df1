"""Sweep: every cycle in M22's window after a power-up of a flat ring, alike at both fidelities (issue #12).

Two sweeps of flat rings of RB chips at both bit rates, each comparing the master's view at pin level
(``PinRing``) and at transaction level (``Ring.power_up``); prints every case that differs. Run from the repository
root:

    python bench/wake_flat_sweep.py single   # 1..3 chips, any one powered up, start or not, 0..7 idle: 192 runs
    python bench/wake_flat_sweep.py window   # 1..4 chips, all at the first clock or one of a running ring,
                                             # the first cycle 0..7 idle telegrams after: 224 runs
    python bench/wake_flat_sweep.py phase    # as single, /ResU released 1..4 bit periods into a telegram: 768 runs
    python bench/wake_flat_sweep.py faults   # 1..3 chips, a forward line cut before or after a power-up, then
                                             # repaired, start or not, 0..7 idle: 896 runs (M22's limit 3)

``single`` is ``test_model_pinring_powerup.both`` with one ``power`` step (the whole history: every cycle's kind,
success and diagnostics); ``window`` is ``first_cycle`` (M22's table of first passing cycles, with the error kinds);
``phase`` and ``faults`` are ``both`` with a power-up off the telegram boundaries (M22's limit 4) and with a cut
line and its repair around a power-up (limit 3).
Exits 1 if any case differs.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

from supi3.interbus.ring import Ring
from supi3.model.chip import Supi3
from supi3.model.pinring import PinRing
from supi3.model.pins import Supi3Pins
from test_model_pinring_powerup import RATES, _config, both, first_cycle  # the tests' helpers, on the path above


def _single(rate: int) -> list[tuple[object, object, object]]:
    return [((chips, position, start, wake), *both(rate, chips, start, [("power", position)], wake))
            for chips in range(1, 4) for position in range(1, chips + 1) for start in (False, True)
            for wake in range(8)]


def _phase(rate: int) -> list[tuple[object, object, object]]:
    return [((chips, position, start, wake, phase), *both(rate, chips, start, [("power", position)], wake, phase))
            for chips in range(1, 4) for position in range(1, chips + 1) for start in (False, True)
            for wake in range(8) for phase in range(1, 5)]


def _faults(rate: int) -> list[tuple[object, object, object]]:
    return [((chips, ops, start, wake), *both(rate, chips, start, ops, wake))
            for chips in range(1, 4) for position in range(1, chips + 1) for line in range(1, chips + 1)
            for ops in ([("cut", line), ("power", position), ("repair", 0)],
                        [("power", position), ("cut", line), ("repair", 0)])
            for start in (False, True) for wake in range(8)]


def _window(rate: int) -> list[tuple[object, object, object]]:
    return [((chips, position, k),
             first_cycle(Ring([Supi3(_config(rate)) for _ in range(chips)], bit_rate=rate), chips, position, k),
             first_cycle(PinRing([Supi3Pins(_config(rate)) for _ in range(chips)]), chips, position, k))
            for chips in range(1, 5) for position in range(chips + 1) for k in range(8)]


def main() -> int:
    """Run the sweep named on the command line; 0 if no case differs."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("sweep", choices=["single", "window", "phase", "faults"])
    args = parser.parse_args()
    started = time.process_time()
    runs = differ = 0
    for rate in RATES:
        sweep = {"single": _single, "window": _window, "phase": _phase, "faults": _faults}[args.sweep]
        for case, tl, pin in sweep(rate):
            runs += 1
            if tl != pin:
                differ += 1
                print(f"{rate} bit/s {case}: transaction level {tl}\n    pin level {pin}", flush=True)
    print(f"{differ} of {runs} differ; CPU {time.process_time() - started:.0f} s")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())

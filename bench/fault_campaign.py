"""Fault campaign: a master runs a ring through random faults, ring changes and resets (``supi3 campaign``).

Run from the repository root, for example:

    python bench/fault_campaign.py --cycles 20000 --seed 1 --devices 16 --pin-cycles 500

Prints cycles, faults injected, detected, located right / wrong / not located, corrupted latches, recoveries,
stuck masters and memory; ``--json`` for JSON. The same as ``supi3 campaign``; the logic is ``supi3.campaign``.
"""

from __future__ import annotations

import sys

from supi3.cli import main

if __name__ == "__main__":
    sys.exit(main(["campaign", *sys.argv[1:]]))

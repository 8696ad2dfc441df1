"""``python -m supi3.regmap --write-checked-in [--root DIR]``: regenerate the checked-in register-map files."""

from __future__ import annotations

import argparse
from pathlib import Path

from supi3.regmap.export import CHECKED_IN, write_checked_in


def main(argv: list[str] | None = None) -> int:
    """Regenerate ``docs/regmap.md`` and ``src/supi3/sdk/c/include/supi3_regs.h`` under the repository root."""
    parser = argparse.ArgumentParser(prog="python -m supi3.regmap", description=main.__doc__)
    parser.add_argument(
        "--write-checked-in",
        action="store_true",
        required=True,
        help=f"write {', '.join(str(p) for p in CHECKED_IN.values())}",
    )
    parser.add_argument("--root", type=Path, default=Path.cwd(), help="repository root (default: current dir)")
    args = parser.parse_args(argv)
    for path in write_checked_in(args.root):
        print(path)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

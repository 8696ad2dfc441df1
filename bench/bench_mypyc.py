"""Benchmark: the hot modules of firmware in the loop compiled with mypyc (the same Python source), against this tree.

An evaluation, not a build of the package (MCU-42, docs/firmware-in-the-loop.md, Figures, round 8): this tree's ``src``
is copied to a scratch folder, the copy's classes mypyc cannot compile as native classes are marked there (exception
classes with two bases, which mypyc does not implement; classes that interpreted code subclasses), the modules named
are compiled in place with ``mypyc`` (mypy's compiler, in the ``dev`` extra; it needs a C compiler and Python's
headers), and ``bench/bench_side.py`` measures the copy (``after``) interleaved with this tree (``before``) in one
process: CPU time, or Python calls with ``--calls``, and whether both did the same work. Run from the repository root:

    python bench/bench_mypyc.py [--rounds N] [--cases issue13,host2M] [--modules supi3/mcu/board.py,...] [--keep DIR]
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import bench_side  # beside this script
from supi3.cli import positive_integer

MODULES = ("supi3/mcu/board.py", "supi3/mcu/stm32.py", "supi3/sdk/bench.py", "supi3/spi/upif.py",
           "supi3/model/registers.py")  # fmt: skip
"""The default set: the board, the STM32 models, the bench, the µP protocol and the register file (the per-byte path
of issue #13's case but the core). ``supi3/mcu/core.py`` compiles, but the firmware then runs wrong (the master finds
its device with no process data: MCU-42)."""
SUBCLASSED: dict[str, tuple[str, ...]] = {"supi3/sdk/bench.py": ("Firmware",)}
"""Classes of the compiled modules that interpreted code subclasses (the examples' firmware, CFirmware)."""
_EXCEPTION = re.compile(r"class \w+\([^)]*(Error|Exception)\b")
_CLASS = re.compile(r"class (\w+)\b")
ROOT = Path(__file__).resolve().parents[1]


def mark(source: str, subclassed: tuple[str, ...]) -> str:
    """``source`` with ``@mypyc_attr(native_class=False)`` on each exception class and
    ``@mypyc_attr(allow_interpreted_subclasses=True)`` on each class named in ``subclassed`` (mypyc's own markers)."""
    lines = []
    for line in source.splitlines(keepends=True):
        match = _CLASS.match(line)
        if match and _EXCEPTION.match(line):
            lines.append("@mypyc_attr(native_class=False)\n")
        elif match and match.group(1) in subclassed:
            lines.append("@mypyc_attr(allow_interpreted_subclasses=True)\n")
        lines.append(line)
    marked = "".join(lines)
    return marked.replace("from __future__ import annotations\n",
                          "from __future__ import annotations\n\nfrom mypy_extensions import mypyc_attr\n", 1)


def compile_copy(folder: Path, modules: tuple[str, ...]) -> Path:
    """Copy this tree's ``src`` into ``folder``, mark and compile ``modules`` there; the copy's ``src``."""
    src = folder / "src"
    shutil.copytree(ROOT / "src", src, ignore=shutil.ignore_patterns("__pycache__", "*.so"))
    for module in modules:
        path = src / module
        if not path.is_file():
            raise SystemExit(f"bench_mypyc.py: no module {module} in {ROOT / 'src'}")
        path.write_text(mark(path.read_text(), SUBCLASSED.get(module, ())))
    env = {name: value for name, value in os.environ.items() if name != "PYTHONPATH"}  # the copy, not a tree there
    done = subprocess.run([sys.executable, "-m", "mypyc", *modules], cwd=src, capture_output=True, text=True,
                          env={**env, "MYPYPATH": str(src)}, check=False)  # fmt: skip
    if done.returncode:
        raise SystemExit(f"bench_mypyc.py: mypyc failed:\n{done.stdout[-3000:]}{done.stderr[-3000:]}")
    return src


def main(argv: list[str] | None = None) -> None:
    """Compile, then measure with bench_side.py."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=positive_integer, default=3, help="runs of each case and tree")
    parser.add_argument("--cases", default="issue13,host2M", help="bench_side.py's cases, comma-separated")
    parser.add_argument("--modules", default=",".join(MODULES), help="the modules compiled, paths under src")
    parser.add_argument("--calls", action="store_true", help="count Python calls in place of CPU time")
    parser.add_argument("--keep", type=Path, help="an empty folder to build in and keep (else a temporary one)")
    args = parser.parse_args(argv)
    modules = tuple(args.modules.split(","))
    with tempfile.TemporaryDirectory() as scratch:
        folder = args.keep if args.keep is not None else Path(scratch)
        folder.mkdir(parents=True, exist_ok=True)
        if any(folder.iterdir()):
            parser.error(f"--keep {folder} is not empty")
        compiled = compile_copy(folder, modules)
        print(f"compiled with mypyc: {', '.join(modules)}")
        bench_side.main(["--rounds", str(args.rounds), "--cases", args.cases, "--tree", str(compiled),
                         "--against", str(ROOT / "src")] + ["--calls"] * args.calls)  # fmt: skip


if __name__ == "__main__":
    main()

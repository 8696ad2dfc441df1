"""``bench/bench_split.py`` (A32): its stand-in firmware runs the host build's cycles, and its command line.

The split's claim rests on its ``bench side`` case running the very master cycles of ``host2M`` (the same set-up,
so the same frame, phases and bus time) with a service routine that clocks no byte; and a bad command line stops
with one line, before any measurement.
"""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path
from types import ModuleType

import pytest

from supi3.sdk import native

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "bench" / "bench_split.py"


def _split() -> ModuleType:
    spec = importlib.util.spec_from_file_location("bench_split", SCRIPT)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_bench_side_runs_the_host_builds_cycles_without_a_byte() -> None:
    split = _split()
    benches = [split.powered(native.CFirmware(native.example("digital_io"))), split.powered(split.QuietIsr())]
    before = [bench.interrupts for bench in benches]
    for bench in benches:
        bench.run(20)
    # the power-up's 3 cycles and 20 more, the same frames; the 20 back to back (the runs' ends and so the first
    # measured cycle's start differ: a run ends when the firmware has served, FW-14)
    host, quiet = ([(t.cycle, t.phases, round(t.start - timeline[k - 1].start, 12) if k > 3 else None)
                    for k, t in enumerate(timeline)]
                   for timeline in (list(bench.timeline) for bench in benches))  # fmt: skip
    assert quiet == host and len(host) == 23
    assert [bench.results[-1] for bench in benches] == [benches[0].results[-1]] * 2
    assert [bench.interrupts - n for bench, n in zip(benches, before, strict=True)] == [20, 20]  # one a cycle
    calls, opcodes, bus_due = split.count(split.powered(split.QuietIsr()).run, 5)
    assert not any("upif.py" in where or "transports.py" in where for where in calls)  # no byte clocked
    assert calls["supi3/model/chip.py:latch_at"] == 5  # one latch of the chip a master cycle
    assert opcodes.total() > calls.total() > 0 and bus_due == 0  # no emulated board


def test_the_opcodes_inside_the_bus_run_before_an_edge_are_counted_on_the_board(tmp_path: Path) -> None:
    """MCU-91's split: on issue #13's board the bus runs inside ``NativeFrames._bus_due`` at the steady cycles' /SS
    edges, and the opcodes counted there are those of its calls and theirs: at least its own, fewer than all."""
    split = _split()
    calls, opcodes, bus_due = split.count(split.board(tmp_path).run, 8)
    assert calls[split._BUS_DUE] > 0
    assert opcodes[split._BUS_DUE] + opcodes["supi3/interbus/master.py:data_cycle"] <= bus_due < opcodes.total()


@pytest.mark.parametrize(("argv", "message"), [
    (["--cycles", "0"], "--cycles and --rounds must be at least 1"),
    (["--rounds", "-1"], "--cycles and --rounds must be at least 1"),
    (["--cycles", "x"], "invalid int value: 'x'"),
])  # fmt: skip
def test_bench_split_refuses_a_bad_command_line(argv: list[str], message: str) -> None:
    done = subprocess.run([sys.executable, str(SCRIPT), *argv], capture_output=True, text=True, cwd=ROOT, timeout=120,
                          check=False)  # fmt: skip
    assert (done.returncode, message in done.stderr, "Traceback" in done.stderr) == (2, True, False), done.stderr

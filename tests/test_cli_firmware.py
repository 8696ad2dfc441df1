"""``supi3 firmware build`` and ``supi3 firmware run`` (src/supi3/cli.py, supi3.mcu.session): the report of a good
firmware, of one that breaks the latch-phase rule (3.4.14) and of one that faults or runs away, and hostile
arguments (one line on stderr, exit status 2, never a traceback).

Exit statuses of ``firmware run``: 0 clean, 3 the firmware stopped (fault, hang, budget), 4 a violation or process
data that did not arrive (cli.FIRMWARE_STOPPED_STATUS, cli.FIRMWARE_FAILED_STATUS).
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from supi3 import cli
from supi3.cli import main
from supi3.mcu import build as mcu_build
from supi3.sdk import native

pytestmark = pytest.mark.skipif(mcu_build.toolchain_missing() is not None, reason=str(mcu_build.toolchain_missing()))

PROGRAMS = Path(__file__).parent / "mcu"


def _call(capsys: pytest.CaptureFixture[str], argv: list[str]) -> tuple[int, str, str]:
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def _line_of(path: Path, marker: str) -> int:
    return next(k for k, text in enumerate(path.read_text().splitlines(), 1) if marker in text)


@pytest.fixture(scope="module")
def elves(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """The firmware the tests run, built through ``supi3 firmware build`` once per module."""
    folder = tmp_path_factory.mktemp("fw")
    builds = {"digital_io": [str(native.example("digital_io"))], "latch_bug": [str(PROGRAMS / "latch_bug.c")],
              "bus_fault": [str(PROGRAMS / "faults.c"), "-D", "FAULTS_SCENARIO=1u"],
              "endless": [str(PROGRAMS / "faults.c"), "-D", "FAULTS_SCENARIO=2u"]}  # fmt: skip
    elves = {}
    for name, argv in builds.items():
        elves[name] = folder / f"{name}.elf"
        assert main(["firmware", "build", *argv, "-o", str(elves[name])]) == 0
    return elves


def test_a_good_firmware_runs_clean_with_its_configuration_and_data(
    capsys: pytest.CaptureFixture[str], elves: dict[str, Path]
) -> None:
    """digital_io: the master's configuration table (ID 03h, one word), its OUT data in the firmware's outputs and
    the firmware's inputs at the master, one EXTI0 entry per data cycle with the Cortex-M3's 12-cycle latency."""
    code, out, err = _call(capsys, ["firmware", "run", str(elves["digital_io"]), "--out", "8118", "--in", "0ff0"])
    assert (code, err) == (0, "")
    assert "03h  00001       2  remote bus" in out
    assert "master OUT 81 18 -> firmware outputs 81 18" in out and "firmware inputs 0f f0 -> master IN 0f f0  ok" in out
    assert "longest /IRQ latency 250 ns (12 core cycles) of the 182 µs the manual leaves" in out  # 13 * 7 * 2 µs
    assert "violations  none" in out
    code, out, _ = _call(capsys, ["firmware", "run", str(elves["digital_io"]), "--json", "--devices", "3",
                                  "--cycles", "6"])  # fmt: skip
    data = json.loads(out)
    assert code == 0 and data["process_data"]["ok"] and data["interrupts"] > 0 and data["violations"] == []
    assert data["access_time_s"] == pytest.approx(13 * (5 + 2 + 2 + 2) * 2e-6)  # three one-word devices
    assert [(d["ring_position"], d["id_code"]) for d in data["configuration"]] == [(1, 0x03), (2, 0x02), (3, 0x02)]


def test_a_latch_phase_read_is_reported_with_its_source_line(
    capsys: pytest.CaptureFixture[str], elves: dict[str, Path]
) -> None:
    """tests/mcu/latch_bug.c at 2 Mbit/s: the violation with the bus time, PC, function and latch_bug.c:line of
    the read; the firmware never writes IN, so the data check fails too: status 4."""
    code, out, err = _call(capsys, ["firmware", "run", str(elves["latch_bug"]), "--bit-rate", "2M", "--cycles", "30"])
    assert (code, err) == (cli.FIRMWARE_FAILED_STATUS, "")
    line = _line_of(PROGRAMS / "latch_bug.c", "LATCH-BUG */")
    assert "3.4.14: inconsistent data: OUT0 read during the latch phase" in out
    assert "in board_xfer() board.c:" in out and f"fw_loop() latch_bug.c:{line}" in out
    assert "MISMATCH" in out


@pytest.mark.parametrize(("name", "argv", "expect"), [
    ("bus_fault", [], r"STOPPED     fault: precise bus fault: read of unmapped memory at PC [0-9A-F]{8}h \(fw_loop\) "
                      r"faults\.c:\d+, .*stacked r0="),
    ("endless", ["--max-instructions", "100000"],
     r"STOPPED     budget: instruction budget of 100000 used up .*faults\.c"),
])  # fmt: skip
def test_a_fault_or_a_run_away_ends_with_a_report_and_status_3(
    capsys: pytest.CaptureFixture[str], elves: dict[str, Path], name: str, argv: list[str], expect: str
) -> None:
    code, out, err = _call(capsys, ["firmware", "run", str(elves[name]), *argv])
    assert (code, err) == (cli.FIRMWARE_STOPPED_STATUS, "")
    assert re.search(expect, out), out


@pytest.mark.parametrize(("argv", "expect"), [
    (["run", "{missing}"], "FIRMWARE must be an ELF file"),
    (["run", "{text}"], "must be a readable ELF file"),
    (["run", "{elf}", "--cycles", "2"], "--cycles must be"),
    (["run", "{elf}", "--cycles", "1e3"], "must be an integer in decimal digits"),
    (["run", "{elf}", "--cpu-hz", "0"], "--cpu-hz must be"),
    (["run", "{elf}", "--devices", "65"], "--devices must be"),
    (["run", "{elf}", "--max-instructions", "-1"], "--max-instructions must be"),
    (["run", "{elf}", "--bit-rate", "1M"], "--bit-rate must be 500k or 2M"),
    (["run", "{elf}", "--mfp", "0000"], "config must strap an Init-µP mode"),
    (["run", "{elf}", "--c", "01000"], "config must strap an Init-µP mode"),
    (["run", "{elf}", "--c", "1x011"], "C[4..0]"),
    (["run", "{elf}", "--out", "zz"], "must be bytes in hex digits"),
    (["run", "{elf}", "--in", ""], "must be 1 to 32 bytes"),
    (["run", "{elf}", "--cpu", "cortex_m4"], "invalid choice"),
    (["run", "{elf}", "--cyc", "5"], "unrecognized arguments"),
    (["run"], "the following arguments are required"),
    (["build", "{missing}", "-o", "{tmp}/x.elf"], "sources must be paths of existing .c or .S files"),
    (["build", "{text}", "-o", "{missing}/x.elf"], "does not exist"),
    (["build", "{source}", "-o", "{tmp}/x.elf", "-D", "1X=2"], "-D must be NAME or NAME=VALUE"),
])  # fmt: skip
def test_hostile_arguments_are_one_line_and_status_2(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, elves: dict[str, Path], argv: list[str], expect: str
) -> None:
    (tmp_path / "text.c").write_text("not an ELF\n")
    names = {"missing": str(tmp_path / "missing"), "text": str(tmp_path / "text.c"), "tmp": str(tmp_path),
             "elf": str(elves["digital_io"]), "source": str(native.example("digital_io"))}  # fmt: skip
    code, out, err = _call(capsys, ["firmware", *(arg.format(**names) for arg in argv)])
    assert code == 2, (out, err)
    assert "Traceback" not in err and err.endswith("\n") and err.count("\n") == 1, err
    assert expect in err, err
    assert out == ""

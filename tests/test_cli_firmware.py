"""``supi3 firmware build`` and ``supi3 firmware run`` (src/supi3/cli.py, supi3.mcu.session): the report of a good
firmware, of one that breaks the latch-phase rule (3.4.14) and of one that faults or runs away, and hostile
arguments (one line on stderr, exit status 2, never a traceback).

Exit statuses of ``firmware run``: 0 clean, 3 the firmware stopped (fault, hang, budget), 4 a violation or process
data that did not arrive (cli.FIRMWARE_STOPPED_STATUS, cli.FIRMWARE_FAILED_STATUS).
"""

from __future__ import annotations

import importlib.util
import json
import re
from pathlib import Path

import pytest

from supi3 import cli
from supi3.cli import main
from supi3.errors import ArgumentError
from supi3.mcu import build as mcu_build
from supi3.mcu.board import MAX_CPU_HZ, Board
from supi3.mcu.session import MIN_CYCLES, POWER_UP_CYCLES, run_firmware
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
    ("endless", ["--max-instructions", "20000"],  # MCU-56: 100,000 outlast the 10 cycles' 2.7 ms of bus time now
     r"STOPPED     budget: instruction budget of 20000 used up .*faults\.c"),
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
    (["run", "{elf}", "--cpu-hz", "72000001"],
     "--cpu-hz must be an integer from 1000000 to 72000000 (the STM32F10x's highest SYSCLK, RM0008 7.2; MCU-50)"),
    (["run", "{elf}", "--cycles", "5"],
     "--cycles must be an integer from 6 to 100000 (the power-up's 3 and 3 to check the exchange), not 5"),
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


# -- issue #13's hostile review of supi3 firmware run (MCU-49, MCU-50, MIN_CYCLES) and bench/bench_mcu.py ---------

DATA_LENGTH = "must be 2 bytes, the data of device 1.0 (the chip) as the firmware configured it (ID code 03h, " \
    "length code 00001, Table 3-11; MCU-49), not "  # fmt: skip


@pytest.mark.parametrize(("argv", "expect"), [
    (["--out", "12345678901234567890"], "--out " + DATA_LENGTH + "10 bytes (12 34 56 78 90 12 34 56 ...)"),
    (["--out", "12"], "--out " + DATA_LENGTH + "1 byte (12)"),
    (["--in", "12"], "--in " + DATA_LENGTH + "1 byte (12)"),
    (["--out", "1234", "--in", "123456"], "--in " + DATA_LENGTH + "3 bytes (12 34 56)"),
    (["--fidelity", "pin", "--cycles", "6", "--out", "12", "--vcd", "{tmp}/x.vcd"],
     "--out " + DATA_LENGTH + "1 byte (12)"),
])  # fmt: skip
def test_data_of_another_length_than_the_firmware_configures_is_a_bad_argument(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, elves: dict[str, Path], argv: list[str], expect: str
) -> None:
    """MCU-49: ``--out``/``--in`` longer than the chip's data were cut silently (exit 0), shorter ones ended in
    "STOPPED the bench" or a MISMATCH blamed on the firmware (exit 4): now one line naming the option, the value
    and the length the firmware configured, status 2, no report and no VCD."""
    code, out, err = _call(capsys, ["firmware", "run", str(elves["digital_io"]),
                                    *(arg.format(tmp=tmp_path) for arg in argv)])  # fmt: skip
    assert (code, out) == (2, ""), out
    assert err == f"supi3: error: {expect}\n"
    assert not (tmp_path / "x.vcd").exists()


def test_run_firmware_checks_the_data_against_the_configured_length(elves: dict[str, Path]) -> None:
    """MCU-49 in the API: the same named error (``out_data``, ``in_data``), empty data included; the right length
    runs clean."""
    for name in ("out_data", "in_data"):
        for data in (b"", b"\x01", b"\x01\x02\x03"):
            with pytest.raises(ArgumentError, match=f"^{name} " + re.escape(DATA_LENGTH)) as info:
                run_firmware(elves["digital_io"], cycles=MIN_CYCLES, **{name: data})  # type: ignore[arg-type]
            assert info.value.name == name and info.value.value == data
    report = run_firmware(elves["digital_io"], cycles=MIN_CYCLES, out_data=b"\x81\x18", in_data=b"\x0f\xf0")
    assert not report.failed and report.sent_out == b"\x81\x18" and report.master_inputs == b"\x0f\xf0"


@pytest.mark.parametrize("fidelity", ["transaction", "pin"])
def test_min_cycles_is_the_least_that_checks_a_good_firmware_s_exchange(elves: dict[str, Path], fidelity: str) -> None:
    """``MIN_CYCLES``: ``--cycles 3`` (the power-up alone) was accepted and every firmware reported MISMATCH. A
    fresh board per count, cycles back to back as in ``run_firmware``: both fidelities need all of them (MCU-55:
    before, the transaction level needed one fewer, its master having started the next cycle, and taken its IN data,
    in the run's wait); ``run_firmware`` refuses fewer."""
    least = MIN_CYCLES
    for cycles, ok in ((least - 1, False), (least, True)):
        board = Board(elves["digital_io"], strict=False, fidelity=fidelity)
        board.run(POWER_UP_CYCLES)
        board.master.set_outputs(1, b"\x81\x18")
        assert board.fw_board is not None
        board.fw_board.inputs = b"\x0f\xf0"
        board.run(cycles - POWER_UP_CYCLES)
        exchanged = board.fw_board.outputs[:2] == b"\x81\x18" and board.master.inputs(1) == b"\x0f\xf0"
        assert exchanged == ok, (cycles, board.fw_board.outputs, board.master.inputs(1))
    with pytest.raises(ArgumentError, match=r"^cycles must be an integer from 6 to 100000 \(the power-up's 3 and 3"):
        run_firmware(elves["digital_io"], cycles=MIN_CYCLES - 1, fidelity=fidelity)


def test_the_help_names_the_constants(capsys: pytest.CaptureFixture[str]) -> None:
    """``--cycles`` and ``--cpu-hz``'s help (written out: the command line loads the board only to run) name
    ``MIN_CYCLES`` and ``MAX_CPU_HZ``."""
    assert main(["firmware", "run", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    assert f"master cycles in all, {MIN_CYCLES} (the power-up's {POWER_UP_CYCLES} and" in text
    assert f"core clock, 1 MHz to {MAX_CPU_HZ // 10**6} MHz" in text


def test_the_board_refuses_a_clock_above_the_stm32f1_s(capsys: pytest.CaptureFixture[str],
                                                      elves: dict[str, Path]) -> None:  # fmt: skip
    """MCU-50: up to 1 GHz ran without a word; the board takes up to 72 MHz (RM0008 7.2), which runs clean."""
    with pytest.raises(ArgumentError, match=r"^cpu_hz must be at most 72000000 \(the STM32F10x's highest SYSCLK"):
        Board(elves["digital_io"], cpu_hz=MAX_CPU_HZ + 1)
    code, out, err = _call(capsys, ["firmware", "run", str(elves["digital_io"]), "--cpu-hz", str(MAX_CPU_HZ)])
    assert (code, err) == (0, "") and "at 72 MHz" in out and "violations  none" in out


def test_bench_mcu_reads_the_dwarf_tables_before_its_measured_window(elves: dict[str, Path]) -> None:
    """bench/bench_mcu.py: every measured window starts from ``_board``, which has read the firmware's DWARF tables
    (the first violation's backtrace read them inside or outside the window, as the power-up went)."""
    spec = importlib.util.spec_from_file_location("bench_mcu", Path(__file__).parents[1] / "bench" / "bench_mcu.py")
    assert spec is not None and spec.loader is not None
    bench_mcu = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench_mcu)
    board = bench_mcu._board(elves["digital_io"], 500_000, skip=True)
    assert "_debug" in vars(board.core.image) and board.core.image.line_at(board.core.image.entry) is not None

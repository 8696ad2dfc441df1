"""This session's firmware-in-the-loop entries against a hostile user (round 2): ``CortexM`` (read_bytes/write_bytes
on unmapped memory and with wrong types, enter as pend), ``Board(fidelity=, mode=, record=)`` and ``Board.write_vcd``,
the instruction budget over runaway firmware at both fidelities, and ``supi3 firmware run --fidelity pin --vcd --mode
--devices --cycles`` (src/supi3/cli.py's contract: exit 2 with one named line on stderr, 3 for a stopped firmware, 4
for a failed exchange; the report on stdout). The ELF files are test_mcu_hostile's, a few bytes each."""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("unicorn")
pytest.importorskip("elftools")

from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.cli import main
from supi3.errors import ArgumentError
from supi3.interbus.device import PlainDevice
from supi3.mcu.board import Board, BoardError
from supi3.mcu.core import CortexM
from supi3.mcu.pins import mcu_lines
from supi3.mcu.session import MIN_CYCLES, run_firmware
from supi3.spi.upif import Mode
from support import bad
from test_mcu_hostile import FILES, RAM_TOP, firmware

NOP_LOOP = b"\x00\xbf\xfd\xe7"
"""nop; b.n back to the nop: a runaway the idle-loop rule (MCU-4) does not take for a wait."""
RAM = 0x2000_0000
TRACES = ["mfp_in", "mfp_out", "mfp_oe", "mod_ack_n", "stat_err_n"]
"""The pin traces the MCU's lines come from."""


@pytest.fixture(scope="module")
def files(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("fw")
    for name, data in {**FILES, "nop.elf": firmware(NOP_LOOP)}.items():
        (folder / name).write_bytes(data)
    return folder


Case = tuple[str, Callable[[Path], object], str]
CASES: list[Case] = [
    # read_bytes/write_bytes: a wrong type was ctypes' "argument 2: TypeError: wrong type", a negative size a bare
    # ValueError, a float size a TypeError "1.5"
    *((f"read_bytes(address={v!r})", lambda d, v=v: CortexM(d / "loop.elf").read_bytes(bad(v), 4), "address")
      for v in ["x", None, -1, 1 << 32, 1 << 40, 1.0, True]),
    *((f"read_bytes(size={v!r})", lambda d, v=v: CortexM(d / "loop.elf").read_bytes(RAM, bad(v)), "size")
      for v in [-1, 1.5, "4", None, True]),
    *((f"write_bytes(address={v!r})", lambda d, v=v: CortexM(d / "loop.elf").write_bytes(bad(v), b"ab"), "address")
      for v in ["x", None, -1, 1 << 32, 2.0]),
    *((f"read_bytes unmapped {a:#x}+{n}", lambda d, a=a, n=n: CortexM(d / "loop.elf").read_bytes(a, n), "address")
      for a, n in [(0, 4), (RAM_TOP - 2, 4), (0xFFFF_FFFF, 2), (0x4000_0000, 1)]),
    # a size of 2 GB made unicorn allocate it before it failed (15 s)
    *((f"read_bytes(size={v})", lambda d, v=v: CortexM(d / "loop.elf").read_bytes(0x0800_0000, v), "size")
      for v in [1 << 31, 0x10001]),
    *((f"write_bytes unmapped {a:#x}", lambda d, a=a: CortexM(d / "loop.elf").write_bytes(a, b"abcd"), "address")
      for a in [0, RAM_TOP - 2, 0x4000_0000]),
    ("write_bytes list", lambda d: CortexM(d / "loop.elf").write_bytes(RAM, bad([1, 2])), "data"),
    # enter(-1) wrote xPSR = T | -1 and left a core that failed later with struct.error
    *((f"enter({v!r})", lambda d, v=v: CortexM(d / "loop.elf").enter(bad(v)), "number")
      for v in [-1, 0, 1, 512, True, "3", 3.0, None]),
    # exception_return("x") was a ValueError "Unknown format code 'X'"
    *((f"exception_return({v!r})", lambda d, v=v: CortexM(d / "loop.elf").exception_return(bad(v)), "exc_return")
      for v in ["x", None, 1.5, -1, 1 << 32, True]),
    *((f"Board({k}={v!r})", lambda d, k=k, v=v: Board(d / "loop.elf", **{k: bad(v)}), k) for k, v in [
        ("fidelity", "PIN"), ("fidelity", None), ("fidelity", "both"), ("mode", "intel"), ("mode", 1),
        ("record", 1), ("record", None)]),
    ("Board(record=True) at transaction level", lambda d: Board(d / "loop.elf", record=True), "record"),
    ("Board(pin, others=[x])", lambda d: Board(d / "loop.elf", fidelity="pin", others=bad([object()])), "others"),
    ("Board(pin, others=[PlainDevice])",
     lambda d: Board(d / "loop.elf", fidelity="pin", others=bad([PlainDevice(2, 1)])), "others"),
    ("Board(pin, others='ab')", lambda d: Board(d / "loop.elf", fidelity="pin", others=bad("ab")), "others"),
    *((f"Board({f}, stat_err_filter={v!r})",
       lambda d, f=f, v=v: Board(d / "loop.elf", fidelity=f, stat_err_filter=bad(v)), "stat_err_filter")
      for f, v in [("transaction", 32_000), ("pin", 0), ("pin", 6_400_001), ("pin", 1.5), ("pin", "1")]),
    ("Board(pin, cycle_time_s=-1)", lambda d: Board(d / "loop.elf", fidelity="pin", cycle_time_s=-1.0),
     "cycle_time_s"),
    ("Board(pin, strict=1)", lambda d: Board(d / "loop.elf", fidelity="pin", strict=bad(1)), "strict"),
    *((f"write_vcd({v!r})", lambda d, v=v: Board(d / "loop.elf", fidelity="pin", record=True).write_vcd(bad(v)),
       "path") for v in [None, 3, b"x.vcd"]),
    # mcu_lines took what it was given: KeyError 'mfp_out', "'NoneType' object is not subscriptable"
    *((f"mcu_lines({v!r})", lambda _d, v=v: mcu_lines(bad(v)), "traces") for v in [{}, {"mfp_out": 0}, None, "x"]),
    ("mcu_lines(intel=1)", lambda _d: mcu_lines({k: np.zeros(2, np.int64) for k in TRACES}, intel=bad(1)), "intel"),
    ("run_firmware(vcd=) at transaction level", lambda d: run_firmware(d / "loop.elf", vcd=d / "x.vcd"), "vcd"),
    ("run_firmware(pin, devices=5)", lambda d: run_firmware(d / "loop.elf", fidelity="pin", devices=5), "devices"),
]


@pytest.mark.parametrize(("call", "name"), [(call, name) for _, call, name in CASES], ids=[c[0] for c in CASES])
def test_hostile_arguments_give_named_errors(files: Path, call: Callable[[Path], object], name: str) -> None:
    with pytest.raises(ArgumentError, match=rf"^{re.escape(name)} must .*, not ") as caught:
        call(files)
    assert caught.value.name == name


def test_a_refused_entry_leaves_the_core_as_it_was(files: Path) -> None:
    core = CortexM(files / "loop.elf")
    before = core.registers()
    for number in (-1, 0, 1, 512):
        with pytest.raises(ArgumentError):
            core.enter(number)
    assert core.registers() == before and not core.active


@pytest.mark.parametrize("fidelity", ["transaction", "pin"])
def test_write_vcd_names_what_is_missing(files: Path, tmp_path: Path, fidelity: str) -> None:
    # a transaction-level board has no pins, a pin-level board without record=True kept none: no file is made
    board = Board(files / "loop.elf", fidelity=fidelity)
    message = "pin-level ring" if fidelity == "transaction" else "record=True"
    with pytest.raises(BoardError, match=message):
        board.write_vcd(tmp_path / "x.vcd")
    assert not (tmp_path / "x.vcd").exists()


def test_write_vcd_before_the_first_clock_writes_no_samples(files: Path, tmp_path: Path) -> None:
    # a board that has not clocked its chip yet (a firmware that faults at its first instruction) writes a VCD with
    # the declarations only (was KeyError 'mfp_out', a traceback from supi3 firmware run --vcd)
    path = Board(files / "loop.elf", fidelity="pin", record=True).write_vcd(tmp_path / "x.vcd")
    text = path.read_text(encoding="ascii")
    assert "$enddefinitions" in text and "#1" not in text


@settings(max_examples=10)
@given(budget=st.integers(1, 30_000), fidelity=st.sampled_from(["transaction", "pin"]),
       name=st.sampled_from(["nop.elf", "udf.elf"]))  # fmt: skip
def test_the_budget_ends_a_runaway_with_a_report(files: Path, budget: int, fidelity: str, name: str) -> None:
    # Any budget, either fidelity: a runaway firmware ends with a report (never an exception), stopped by its budget
    # within one block of it (was 648,168 instructions for a budget of 1 at transaction level), or by its fault.
    if fidelity == "pin":
        budget = min(budget, 2000)  # every chip clock is stepped
    report = run_firmware(files / name, fidelity=fidelity, cycles=MIN_CYCLES, max_instructions=budget)
    assert report.stop is not None and report.error is None
    if name == "udf.elf":
        assert report.stop.stop == "fault"
    else:
        assert report.stop.stop == "budget" and budget <= report.instructions <= budget + 8, report.instructions


# -- supi3 firmware run ---------------------------------------------------------------------------------------------

CLI_BAD: list[tuple[list[str], str]] = [
    (["--fidelity", "pin", "--devices", "5"], "--devices must be an integer from 1 to 4 (with --fidelity pin"),
    (["--fidelity", "pin", "--devices", "0"], "--devices must be an integer from 1 to 4 (with --fidelity pin"),
    (["--fidelity", "pin", "--cycles", "5"], "--cycles must be an integer from 6 to 50"),
    (["--fidelity", "pin", "--cycles", "51"], "--cycles must be an integer from 6 to 50"),
    (["--fidelity", "PIN"], "argument --fidelity: invalid choice"),
    (["--mode", "INTEL"], "argument --mode: invalid choice"),
    (["--mode", ""], "argument --mode: invalid choice"),
    (["--vcd", "{d}/x.vcd"], "--vcd needs --fidelity pin"),
    (["--fidelity", "pin", "--cycles", "6", "--vcd", "{d}"], "(--vcd): is a directory"),
    (["--fidelity", "pin", "--cycles", "6", "--vcd", "{d}/missing/x.vcd"], "does not exist"),
    (["--devices", "x"], "argument --devices: must be an integer"),
    (["--cycles", "1e3"], "argument --cycles: must be an integer"),
]


@pytest.mark.parametrize(("argv", "expect"), CLI_BAD, ids=[" ".join(a) for a, _ in CLI_BAD])
def test_bad_firmware_run_options_are_one_line_and_status_2(capsys: pytest.CaptureFixture[str], files: Path,
                                                           argv: list[str], expect: str) -> None:  # fmt: skip
    code = main(["firmware", "run", str(files / "loop.elf"), *(a.replace("{d}", str(files)) for a in argv)])
    out, err = capsys.readouterr()
    assert code == 2 and out == "", (out, err)
    assert "Traceback" not in err and err.endswith("\n") and err.count("\n") == 1 and expect in err, err
    assert not (files / "x.vcd").exists()


@pytest.mark.parametrize(("name", "argv", "status"), [
    ("udf.elf", ["--fidelity", "pin", "--cycles", "6"], 3),
    ("udf.elf", ["--fidelity", "pin", "--cycles", "6", "--mode", "intel", "--vcd", "{d}/udf.vcd"], 3),
    ("nop.elf", ["--fidelity", "pin", "--cycles", "6", "--max-instructions", "1000"], 3),
    pytest.param("loop.elf", ["--fidelity", "pin", "--cycles", "6", "--max-instructions", "1000"], 4,
                 marks=pytest.mark.slow),  # b .: a wait (MCU-4), six whole cycles stepped
])  # fmt: skip
def test_a_stopped_or_failed_firmware_gives_3_or_4_and_its_report(capsys: pytest.CaptureFixture[str], files: Path,
                                                                  name: str, argv: list[str], status: int) -> None:
    code = main(["firmware", "run", str(files / name), *(a.replace("{d}", str(files)) for a in argv)])
    out, err = capsys.readouterr()
    assert code == status and err == "", err
    assert ("STOPPED" in out) == (status == 3) and "pin level" in out
    if "--vcd" in argv:  # written also when the run stopped
        assert "wrote" in out and (files / "udf.vcd").read_text(encoding="ascii").startswith("$")


def test_mode_is_a_board_mode(files: Path) -> None:
    # the Intel board at both fidelities takes the same firmware without a bad-argument error
    for fidelity in ("transaction", "pin"):
        board = Board(files / "loop.elf", fidelity=fidelity, mode=Mode.INTEL)
        assert board.intel

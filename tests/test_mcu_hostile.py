"""Hostile input to the firmware-in-the-loop entries (supi3.mcu: FirmwareImage, CortexM, Board, build,
run_firmware) and to ``supi3 firmware build|run``: a named error "X must be ..., not ..." (supi3.checks), never a
traceback, a compiler's message for what is not the compiler's business, or a bad argument turned into a report;
the command line exits 2 with one line on stderr. The ELF files are made here, a few bytes each (no toolchain)."""

from __future__ import annotations

import re
import struct
from collections.abc import Callable
from pathlib import Path

import pytest

pytest.importorskip("unicorn")
pytest.importorskip("elftools")

from supi3.cli import main
from supi3.errors import ArgumentError
from supi3.mcu import build as mcu_build
from supi3.mcu.board import Board, FwBoard
from supi3.mcu.core import CortexM, FirmwareError, FirmwareImage
from supi3.mcu.session import run_firmware
from support import bad

EM_ARM, EM_386 = 40, 3
FLASH, RAM_TOP = 0x0800_0000, 0x2000_5000
UDF, LOOP = b"\xfe\xde", b"\xfe\xe7"  # udf #254; b .


def elf(segments: list[tuple[int, bytes]], *, machine: int = EM_ARM, big_endian: bool = False) -> bytes:
    """A 32-bit ELF executable with one PT_LOAD program header per segment (address, bytes), no sections."""
    order = ">" if big_endian else "<"
    offset = 52 + 32 * len(segments)
    ident = b"\x7fELF" + bytes([1, 2 if big_endian else 1, 1, 0]) + bytes(8)
    header = ident + struct.pack(f"{order}HHIIIIIHHHHHH", 2, machine, 1, FLASH | 0x41, 52, 0, 0, 52, 32,
                                 len(segments), 40, 0, 0)  # fmt: skip
    programs, body = b"", b""
    for address, data in segments:
        programs += struct.pack(f"{order}8I", 1, offset + len(body), address, address, len(data), len(data), 5, 4)
        body += data
    return header + programs + body


def firmware(code: bytes, at: int = FLASH) -> bytes:
    """A vector table (initial SP, reset at ``at + 0x40``) and ``code`` at ``at``."""
    return elf([(at, struct.pack("<II", RAM_TOP, (at + 0x40) | 1) + bytes(0x38) + code)])


FILES: dict[str, bytes] = {
    "empty.elf": b"",
    "text.elf": b"hello, not an ELF\n",
    "x86.elf": elf([(FLASH, LOOP)], machine=EM_386),
    "big.elf": elf([(FLASH, LOOP)], big_endian=True),
    "cut.elf": elf([(FLASH, LOOP)])[:30],
    "noload.elf": elf([]),
    "low.elf": firmware(LOOP, at=0),
    "udf.elf": firmware(UDF),
    "loop.elf": firmware(LOOP),
}


@pytest.fixture
def files(tmp_path: Path) -> Path:
    for name, data in FILES.items():
        (tmp_path / name).write_bytes(data)
    (tmp_path / "a.c").write_text("int x;\n", encoding="utf-8")
    (tmp_path / "a.txt").write_text("int x;\n", encoding="utf-8")
    return tmp_path


Case = tuple[str, Callable[[Path], object], str]
CASES: list[Case] = [
    *((f"load {n}", lambda d, n=n: FirmwareImage.load(d / n), "path")
      for n in ["empty.elf", "text.elf", "x86.elf", "big.elf", "cut.elf", "noload.elf", "missing.elf", "."]),
    ("load None", lambda _d: FirmwareImage.load(bad(None)), "path"),
    ("load int", lambda _d: FirmwareImage.load(bad(3)), "path"),
    ("CortexM image outside memory", lambda d: CortexM(d / "low.elf"), "image"),
    ("CortexM cpu list", lambda d: CortexM(d / "loop.elf", cpu=bad([])), "cpu"),
    ("CortexM cpu m4", lambda d: CortexM(d / "loop.elf", cpu="cortex_m4"), "cpu"),
    *((f"CortexM cpu_hz={v!r}", lambda d, v=v: CortexM(d / "loop.elf", cpu_hz=bad(v)), "cpu_hz")
      for v in [0, -1, True, "48e6", None, float("nan"), 1e12]),
    *((f"CortexM flash={v!r}", lambda d, v=v: CortexM(d / "loop.elf", flash=bad(v)), "flash")
      for v in [None, (1, 5), (FLASH, 0), (FLASH,), [FLASH, 0x10000], (FLASH, True), (0xFFFF_F000, 0x2000),
                (0xE000_0000, 0x10000)]),
    ("CortexM ram over flash", lambda d: CortexM(d / "loop.elf", ram=(FLASH, 0x1000)), "ram"),
    *((f"CortexM.step({v!r})", lambda d, v=v: CortexM(d / "loop.elf").step(bad(v)), "deadline")
      for v in ["x", None, -5, 1.5]),
    *((f"CortexM.reg({v!r})", lambda d, v=v: CortexM(d / "loop.elf").reg(bad(v)), "name")
      for v in ["xx", None, "r0; x", ""]),
    *((f"CortexM.set_reg r0 {v!r}", lambda d, v=v: CortexM(d / "loop.elf").set_reg("r0", bad(v)), "value")
      for v in [-1, 1 << 32, 1.0, None]),
    ("CortexM.write_bytes str", lambda d: CortexM(d / "loop.elf").write_bytes(RAM_TOP - 4, bad("ab")), "data"),
    *((f"CortexM.pend({v!r})", lambda d, v=v: CortexM(d / "loop.elf").pend(bad(v)), "number")
      for v in [999, -1, 0, 1, True]),
    ("CortexM.backtrace(-1)", lambda d: CortexM(d / "loop.elf").backtrace(-1), "depth"),
    ("Board cycles -1", lambda d: Board(d / "loop.elf").run(-1), "cycles"),
    ("Board cycles 1.5", lambda d: Board(d / "loop.elf").run(bad(1.5)), "cycles"),
    ("Board max_instructions 0", lambda d: Board(d / "loop.elf").run(1, max_instructions=0), "max_instructions"),
    ("Board run_for nan", lambda d: Board(d / "loop.elf").run_for(float("nan")), "seconds"),
    ("build missing", lambda d: mcu_build.build_command([d / "missing.c"], d / "o.elf"), "sources"),
    ("build not C", lambda d: mcu_build.build_command([d / "a.txt"], d / "o.elf"), "sources"),
    ("build a folder", lambda d: mcu_build.build_command([d], d / "o.elf"), "sources"),
    ("build None", lambda d: mcu_build.build_command(bad(None), d / "o.elf"), "sources"),
    ("build an int", lambda d: mcu_build.build_command(bad(3), d / "o.elf"), "sources"),
    ("build a str", lambda d: mcu_build.build_command(bad(str(d / "a.c")), d / "o.elf"), "sources"),
    ("build nothing", lambda d: mcu_build.build_command([], d / "o.elf"), "sources"),
    ("build cpu list", lambda d: mcu_build.build_command([d / "a.c"], d / "o.elf", cpu=bad([])), "cpu"),
    ("build macro name", lambda d: mcu_build.build_command([d / "a.c"], d / "o", defines={"1x; y": "2"}), "defines"),
    ("build macro value", lambda d: mcu_build.build_command([d / "a.c"], d / "o", defines={"X": bad(2)}), "defines"),
    ("build include None", lambda d: mcu_build.build_command([d / "a.c"], d / "o", include_dirs=bad(None)),
     "include_dirs"),
    *((f"run_firmware {k}={v!r}", lambda d, k=k, v=v: run_firmware(d / "loop.elf", **{k: bad(v)}), k) for k, v in [
        ("devices", 0), ("devices", True), ("cycles", 1), ("cycles", 2.0), ("cpu_hz", 0), ("cpu", "m4"),
        ("straps", None), ("straps", "10011"), ("out_data", "ab"), ("in_data", 5), ("max_instructions", 0),
        ("max_instructions", -5), ("max_instructions", 1.5)]),
    *((f"run_firmware {n}", lambda d, n=n: run_firmware(d / n), "path") for n in ["empty.elf", "x86.elf", "missing"]),
]


@pytest.mark.parametrize(("call", "name"), [(call, name) for _, call, name in CASES], ids=[c[0] for c in CASES])
def test_hostile_arguments_give_named_errors(files: Path, call: Callable[[Path], object], name: str) -> None:
    with pytest.raises(ArgumentError, match=rf"^{re.escape(name)} must be .*, not ") as caught:
        call(files)
    assert caught.value.name == name


@pytest.mark.parametrize(("attribute", "value"), [("inputs", 5), ("inputs", "ab"), ("inputs", None), ("fault", 2),
                                                 ("fault", True)])  # fmt: skip
def test_the_firmware_board_refuses_bad_terminals(files: Path, attribute: str, value: object) -> None:
    """``FwBoard``'s input terminals are bytes (an int was taken as that many zero bytes), the fault flag 0 or 1;
    nothing is written."""
    image = FirmwareImage.load(files / "loop.elf")
    core = CortexM(FirmwareImage(image.path, image.segments, image.entry, {"fw_board": (RAM_TOP - 0x1000, 36)}))
    board = FwBoard(core)
    board.inputs = b"\x12\x34\x56\x78"
    with pytest.raises(ArgumentError, match=rf"^{attribute} must be "):
        setattr(board, attribute, value)
    assert (board.inputs, board.fault) == (b"\x12\x34\x56\x78", 0)


def test_a_run_after_a_fault_stops_again_with_a_report(files: Path) -> None:
    """A core that faulted (an undefined instruction) has taken its HardFault (B1.5.6): stepping it again runs the
    handler, here none (vector 0), which stops with a report, never a traceback."""
    core = CortexM(files / "udf.elf")
    with pytest.raises(FirmwareError, match="undefined instruction"):
        core.step(core.cycles + 1000)
    with pytest.raises(FirmwareError, match="instruction bus fault: fetch from unmapped memory"):  # PC 0 (vector 0)
        core.step(core.cycles + 1000)


def test_a_firmware_that_faults_is_reported_not_raised(files: Path) -> None:
    report = run_firmware(files / "udf.elf")
    assert report.stop is not None and "undefined instruction" in report.stop.reason and report.error is None


CLI: list[tuple[list[str], str]] = [
    (["run", "{d}/empty.elf"], "path must be a readable ELF file"),
    (["run", "{d}/x86.elf"], "path must be a 32-bit little-endian ARM ELF"),
    (["run", "{d}/noload.elf"], "path must be an ELF with a loadable segment"),
    (["run", "{d}/low.elf"], "image must be a firmware whose segments lie in flash"),
    (["run", "{d}"], "(not a file)"),
    (["run", "{d}/missing.elf"], "(no such file)"),
    (["run", "{d}/loop.elf", "--cycles", "2"], "--cycles must be"),
    (["run", "{d}/loop.elf", "--devices", "65"], "--devices must be"),
    (["run", "{d}/loop.elf", "--cpu-hz", "5"], "--cpu-hz must be"),
    (["run", "{d}/loop.elf", "--max-instructions", "0"], "--max-instructions must be"),
    (["run", "{d}/loop.elf", "--bit-rate", "3M"], "--bit-rate must be"),
    (["run", "{d}/loop.elf", "--c", "2"], "C[4..0]"),
    (["run", "{d}/loop.elf", "--out", "zz"], "--out"),
    (["run", "{d}/loop.elf", "--cpu", "cortex_m4"], "--cpu"),
    (["build", "{d}/missing.c", "-o", "{d}/o.elf"], "sources must be"),
    (["build", "{d}/a.txt", "-o", "{d}/o.elf"], "sources must be"),
    (["build", "{d}/a.c", "-o", "{d}"], "-o/--output"),
    (["build", "{d}/a.c", "-o", "{d}/o.elf", "-D", "1x"], "-D must be NAME or NAME=VALUE"),
]


@pytest.mark.parametrize(("argv", "said"), CLI, ids=[" ".join(a).replace("{d}/", "") for a, _ in CLI])
def test_the_command_line_exits_2_with_one_line(files: Path, capsys: pytest.CaptureFixture[str], argv: list[str],
                                                said: str) -> None:  # fmt: skip
    try:
        code = main(["firmware", *(a.replace("{d}", str(files)) for a in argv)])
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else 1
    out, err = capsys.readouterr()
    assert (code, out) == (2, "") and err.count("\n") == 1 and said in err, err

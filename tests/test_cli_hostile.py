"""The supi3 command line against a hostile user: bad values, bad paths, broken pipes, an ASCII-only terminal.

The contract (src/supi3/cli.py's docstring, README "The command line"): bad input gives exactly one line on stderr
and exit status 2, never a traceback; a reader that closes the pipe early gives exit status 141 and nothing on
stderr; a terminal that cannot show a character gets a stand-in; a genuine bug keeps its traceback.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tomllib
from pathlib import Path
from typing import Any

import pytest

from supi3 import cli
from supi3.cli import main
from supi3.interbus import wire

DATA = Path(__file__).resolve().parent / "data" / "cli_bad_inputs.toml"
SRC = Path(__file__).resolve().parents[1] / "src"
CASES: list[dict[str, Any]] = tomllib.loads(DATA.read_text(encoding="utf-8"))["case"]
BROKEN_PIPE_STATUS = 141


def _call(capsys: pytest.CaptureFixture[str], argv: list[str]) -> tuple[int, str, str]:
    """Run ``main(argv)`` in-process; an escaping ``SystemExit`` counts as its exit status."""
    try:
        code = main(argv)
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else 1
    out, err = capsys.readouterr()
    return code, out, err


def _fill(argv: list[str], tmp_path: Path) -> list[str]:
    folder = tmp_path / "folder"
    folder.mkdir(exist_ok=True)
    regular = tmp_path / "regular.txt"
    regular.write_text("not a folder\n", encoding="utf-8")
    names = {"dir": str(folder), "file": str(regular), "missing": str(tmp_path / "missing"), "long": "a" * 300}
    return [arg.format(**names) for arg in argv]


def _case_id(case: dict[str, Any]) -> str:
    return " ".join(case["argv"]).replace("\n", "\\n")[:60] or "(nothing)"


@pytest.mark.parametrize("case", CASES, ids=[_case_id(c) for c in CASES])
def test_bad_input_is_one_line_and_status_2(capsys: pytest.CaptureFixture[str], tmp_path: Path,
                                            case: dict[str, Any]) -> None:
    code, out, err = _call(capsys, _fill(case["argv"], tmp_path))
    assert code == 2, (out, err)
    assert "Traceback" not in err and err.endswith("\n") and err.count("\n") == 1, err
    assert case["expect"] in err, err
    assert len(err) <= 300, err  # a long value is quoted cut short
    if not case.get("run", False):
        assert out == ""  # checked before any work: nothing printed, nothing run
    assert not (tmp_path / "missing").exists()  # a missing parent folder is reported, not created


def test_main_returns_a_status_and_never_raises_system_exit(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["frobnicate"]) == 2
    assert main(["timing", "--help"]) == 0
    out, _ = capsys.readouterr()
    assert "--devices" in out


def test_a_repeated_option_takes_the_last_value(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = _call(capsys, ["timing", "--bytes", "400", "--bytes", "4", "--json"])
    assert code == 0 and json.loads(out)["network_bytes"] == 4


@pytest.mark.parametrize(("option", "value"), [("--bytes", "32768"), ("--bytes", "0"), ("--devices", "512"),
                                               ("--optical-count", "1600"), ("--optical-count", "0")])
def test_limits_themselves_are_accepted(capsys: pytest.CaptureFixture[str], option: str, value: str) -> None:
    devices = ["--devices", "512"] if option == "--bytes" else []  # 32768 bytes need 512 devices (A23)
    code, out, err = _call(capsys, ["timing", option, value, *devices, "--json"])
    assert code == 0 and err == "" and json.loads(out)


def test_output_file_is_written_and_overwritten(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    target = tmp_path / "map.md"
    target.write_text("old\n", encoding="utf-8")
    code, out, err = _call(capsys, ["regmap", "--format", "md", "-o", str(target)])
    assert code == 0 and err == "" and out == f"wrote {target}\n"
    assert "µ" in target.read_text(encoding="utf-8")


def test_relative_output_file_in_the_current_folder(capsys: pytest.CaptureFixture[str], tmp_path: Path,
                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    code, _, err = _call(capsys, ["regmap", "--format", "h", "-o", "supi3.h"])
    assert code == 0 and err == "" and (tmp_path / "supi3.h").read_text(encoding="utf-8").startswith("/*")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["supi3.h"]  # the write probe left nothing behind


def test_html_into_an_existing_empty_folder(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    code, _, err = _call(capsys, ["regmap", "--format", "html", "-o", str(tmp_path)])
    assert code == 0 and err == "" and (tmp_path / "index.html").exists()


def test_html_without_the_docs_extra(capsys: pytest.CaptureFixture[str], tmp_path: Path,
                                     monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "peakrdl_html", None)  # as on `pip install supi3`: import fails
    code, out, err = _call(capsys, ["regmap", "--format", "html", "-o", str(tmp_path / "site")])
    assert code == 2 and out == "" and err.count("\n") == 1 and "supi3[docs]" in err
    assert not (tmp_path / "site").exists()


def test_a_failed_path_check_leaves_no_probe_file(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    code, _, _ = _call(capsys, ["demo", "--cycles", "1", "--bit-rate", "9600", "--vcd", str(tmp_path / "x.vcd")])
    assert code == 2 and list(tmp_path.iterdir()) == []


def test_a_bug_keeps_its_traceback(monkeypatch: pytest.MonkeyPatch) -> None:
    def broken(_args: object) -> None:
        raise RuntimeError("a genuine bug")

    monkeypatch.setattr(cli, "cmd_timing", broken)
    with pytest.raises(RuntimeError, match="genuine bug"):
        main(["timing"])


def test_ctrl_c_is_status_130_without_traceback(capsys: pytest.CaptureFixture[str],
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    def interrupted(_args: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(cli, "cmd_modes", interrupted)
    code, _, err = _call(capsys, ["modes"])
    assert code == 130 and "Traceback" not in err and err.count("\n") <= 1


def test_main_leaves_the_caller_stdout_as_it_was(capsys: pytest.CaptureFixture[str]) -> None:
    before = sys.stdout.errors
    _call(capsys, ["modes"])
    assert sys.stdout.errors == before


# ------------------------------------------------------------------------------------------------------------
# Subprocesses: broken pipes, encodings, a full disk on stdout
# ------------------------------------------------------------------------------------------------------------


def _env(**extra: str) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONIOENCODING", "PYTHONWARNINGS")}
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(SRC), os.environ.get("PYTHONPATH", "")) if p)
    return env | extra


def _command(*argv: str) -> list[str]:
    return [sys.executable, "-m", "supi3.cli", *argv]


SHORT_AND_LONG = [
    ["decode", "--c", "10000", "--json"],
    ["decode", "--c", "10000"],
    ["modes"],
    ["modes", "--json"],
    ["timing"],
    ["timing", "--table", "3-4", "--json"],
    ["regmap", "--format", "md"],
    ["regmap", "--format", "json"],
    ["demo", "--cycles", "1"],
    ["demo", "--cycles", "1000"],
    ["--help"],
]


@pytest.mark.parametrize("argv", SHORT_AND_LONG, ids=" ".join)
def test_pipe_closed_before_any_output(argv: list[str]) -> None:
    read_end, write_end = os.pipe()
    os.close(read_end)  # like `supi3 ... | true`: every write fails with EPIPE
    try:
        result = subprocess.run(_command(*argv), stdout=write_end, stderr=subprocess.PIPE, env=_env(),
                                check=False, timeout=120)
    finally:
        os.close(write_end)
    assert result.stderr == b""  # no traceback, no "Exception ignored"
    assert result.returncode == BROKEN_PIPE_STATUS


@pytest.mark.parametrize("argv", [["demo", "--cycles", "1000"], ["modes"]], ids=" ".join)
def test_pipe_closed_after_ten_bytes(argv: list[str]) -> None:
    # `supi3 demo | head -c 10`
    with subprocess.Popen(_command(*argv), stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=_env()) as proc:
        assert proc.stdout is not None and proc.stderr is not None
        assert len(proc.stdout.read(10)) == 10
        proc.stdout.close()
        err = proc.stderr.read()
        code = proc.wait(timeout=120)
    assert err == b""
    # A short output may fit in the pipe before it closes; a long one cannot.
    assert code == BROKEN_PIPE_STATUS or (code == 0 and argv == ["modes"])


ASCII_CASES = [
    ["demo", "--cycles", "1"],
    ["modes"],
    ["decode", "--c", "10011", "--mfp", "1110"],
    ["timing", "--table", "3-7"],
    ["regmap", "--format", "md"],
    ["regmap", "--format", "rdl"],
    ["regmap", "--format", "h"],
    ["--help"],
]
ASCII_JSON_CASES = [
    ["modes", "--json"],
    ["decode", "--c", "10011", "--mfp", "1110", "--json"],
    ["timing", "--table", "3-7", "--json"],
    ["regmap", "--format", "json"],
]


@pytest.mark.parametrize("argv", ASCII_CASES, ids=" ".join)
def test_ascii_terminal_gets_stand_ins(argv: list[str]) -> None:
    result = subprocess.run(_command(*argv), capture_output=True, env=_env(PYTHONIOENCODING="ascii"),
                            check=False, timeout=120)
    assert result.returncode == 0 and result.stderr == b""
    text = result.stdout.decode("ascii")  # nothing but ASCII
    if argv[0] in ("demo", "regmap") and argv[-1] != "h":
        assert "uP" in text or "us" in text  # µ degrades to u


@pytest.mark.parametrize("argv", ASCII_JSON_CASES, ids=" ".join)
def test_ascii_terminal_gets_escaped_json(capsys: pytest.CaptureFixture[str], argv: list[str]) -> None:
    result = subprocess.run(_command(*argv), capture_output=True, env=_env(PYTHONIOENCODING="ascii"),
                            check=False, timeout=120)
    assert result.returncode == 0 and result.stderr == b""
    code, out, _ = _call(capsys, argv)  # in-process, UTF-8
    assert code == 0 and json.loads(result.stdout.decode("ascii")) == json.loads(out)  # lossless


def test_ascii_terminal_error_line() -> None:
    result = subprocess.run(_command("decode", "--c", "µ\n"), capture_output=True,
                            env=_env(PYTHONIOENCODING="ascii"), check=False, timeout=120)
    assert result.returncode == 2 and result.stdout == b""
    assert result.stderr.count(b"\n") == 1 and b"Traceback" not in result.stderr


def test_ascii_terminal_undecodable_path(tmp_path: Path) -> None:
    target = os.fsencode(tmp_path) + b"/\xff.h"  # not UTF-8: argv carries it as a surrogate escape
    result = subprocess.run([*map(os.fsencode, _command("regmap", "--format", "h", "-o")), target],
                            capture_output=True, env=_env(PYTHONIOENCODING="ascii"), check=False, timeout=120)
    assert result.returncode == 0 and result.stderr == b""
    assert result.stdout.startswith(b"wrote ") and Path(os.fsdecode(target)).exists()


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full")
def test_stdout_on_a_full_device() -> None:
    with open("/dev/full", "wb") as full:  # `supi3 demo > /dev/full`
        result = subprocess.run(_command("demo", "--cycles", "1000"), stdout=full, stderr=subprocess.PIPE,
                                env=_env(), check=False, timeout=120)
    assert result.returncode == 2
    assert result.stderr.count(b"\n") == 1 and b"No space left on device" in result.stderr


README = Path(__file__).resolve().parents[1] / "README.md"


def test_readme_cli_section_matches(capsys: pytest.CaptureFixture[str]) -> None:
    text = README.read_text(encoding="utf-8")
    section = text[text.index("## The command line"):text.index("## In Python")]
    # Every "$ supi3 ..." example prints what the README shows.
    examples = [line.split("    $ supi3 ", 1)[1] for line in section.splitlines() if line.startswith("    $ supi3 ")]
    assert examples
    for example in examples:
        shown = section.split(f"$ supi3 {example}\n", 1)[1].splitlines()[0].strip()
        code, out, err = _call(capsys, example.split())
        assert (out + err).strip() == shown and code == 2
    # The exit-status table gives the statuses main() returns.
    for status in (0, 2, cli.BROKEN_PIPE_STATUS, cli.INTERRUPTED_STATUS, 1):
        assert f"\n| {status} | " in section
    for limit in (cli.MAX_DEMO_CYCLES, cli.MAX_VCD_CYCLES, cli.MAX_NETWORK_BYTES, wire.MAX_DEVICES,
                  cli.MAX_OPTICAL_COUNT):
        assert f" to {limit}" in section

"""The supi3 command line: data subcommands with --json, and one-line errors with a non-zero status."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from supi3 import tables
from supi3.cli import main


def _run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_modes_json_lists_every_row(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = _run(capsys, "modes", "--json")
    rows = json.loads(out)
    assert code == 0 and len(rows) == len(tables.MODE_ROWS)
    assert rows[0] == {"table": "Table 2-4", "c": "01000", "mfp": None, "length_code": "01001",
                       "data_length": "1 byte", "id_code": "BF", "function": "LB-MR, 8 IN/OUT"}


def test_modes_filters(capsys: pytest.CaptureFixture[str]) -> None:
    _, out, _ = _run(capsys, "modes", "--variant", "ls", "--json")
    assert len(json.loads(out)) == 54
    _, out, _ = _run(capsys, "modes", "--interface", "LBD-OR", "--json")
    assert {r["function"].split(",")[0] for r in json.loads(out)} == {"LBD-OR"}
    code, out, _ = _run(capsys, "modes", "--interface", "RB")
    assert code == 0 and "RB, Init-µP" in out and "Table" in out.splitlines()[0]


def test_decode_json(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = _run(capsys, "decode", "--c", "11111", "--mfp", "1011", "--clk-conf", "11", "--json")
    data = json.loads(out)
    assert code == 0
    assert (data["interface"], data["mfp_mode"], data["id_code"], data["length_code"], data["data_bits"]) == (
        "LBD-OR", "SPI 32 IN/32 OUT", "73", "00010", 32)
    assert data["function"] == "LBD-OR, SPI 32 IN/32 OUT" and data["bit_rate"] == 2_000_000
    assert {p["pin"] for p in data["mfp_pins"]} >= {3, 4, 5, 6, 7}


def test_decode_text(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = _run(capsys, "decode", "--c", "10000")
    assert code == 0 and "RB, 8 IN/8 OUT" in out and "MFP15=Out7(out)" in out


@pytest.mark.parametrize("argv", [
    ["decode", "--c", "00101"],
    ["decode", "--c", "01011"],
    ["decode", "--c", "00000", "--variant", "ls"],
    ["decode", "--c", "10000", "--clk-conf", "00"],
    ["timing", "--bit-rate", "1M"],
    ["timing", "--bytes", "-1"],
    ["demo", "--cycles", "0"],
    ["demo", "--bit-rate", "9600"],
])
def test_errors_are_one_line_with_status_2(capsys: pytest.CaptureFixture[str], argv: list[str]) -> None:
    code, out, err = _run(capsys, *argv)
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith("supi3: error: ")
    assert "Traceback" not in err


@pytest.mark.parametrize("argv", [["decode"], ["decode", "--c", "10000", "--bogus"], ["frobnicate"],
                                  ["regmap", "--format", "pdf"], []])
def test_usage_errors_are_one_line(capsys: pytest.CaptureFixture[str], argv: list[str]) -> None:
    code, out, err = _run(capsys, *argv)  # main() returns the status; it never raises SystemExit
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and "error:" in err and "--help" in err


def test_timing_json_manual_example(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = _run(capsys, "timing", "--json")
    data = json.loads(out)
    assert code == 0 and data["cpu_access_time_us"] == 234.0 and data["io_access_window_us"] == 60.0


def test_timing_table_and_optical(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = _run(capsys, "timing", "--bit-rate", "2M", "--table", "3-7", "--optical-count", "8")
    assert code == 0 and "t_SAS_INIT" in out and "optical_length_m" in out
    code, out, _ = _run(capsys, "timing", "--table", "3-4", "--json")
    assert code == 0 and json.loads(out)["table"][0]["min_ns"] == 1000.0


def test_console_script_entry_point() -> None:
    result = subprocess.run([sys.executable, "-m", "supi3.cli", "decode", "--c", "10011", "--mfp", "1110",
                             "--json"], capture_output=True, text=True, check=False)
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout)["id_code"] == "38"
    bad = subprocess.run([sys.executable, "-m", "supi3.cli", "decode", "--c", "x"], capture_output=True,
                         text=True, check=False)
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1


def test_demo(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = _run(capsys, "demo", "--cycles", "2")
    assert code == 0
    assert "Configuration table" in out and "Interrupt event (IRQ_EVT)" in out
    assert out.count("(ok,") == 2
    assert "03h" in out and "BFh" in out and "32h" in out


def test_demo_writes_a_vcd(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    vcd = tmp_path / "demo.vcd"
    code, out, _ = _run(capsys, "demo", "--cycles", "2", "--bit-rate", "2M", "--vcd", str(vcd))
    assert code == 0 and f"wrote {vcd}" in out and out.count("(ok,") == 4
    text = vcd.read_text(encoding="ascii")
    assert "$scope module dev1 $end" in text and "$scope module dev3 $end" in text
    assert "$timescale 1 ps $end" in text and "mfp_out" in text


@pytest.mark.parametrize(("fmt", "marker"), [("md", "#"), ("rdl", "addrmap"), ("h", "#define SUPI3_"),
                                             ("json", "{")])
def test_regmap_formats_to_stdout(capsys: pytest.CaptureFixture[str], fmt: str, marker: str) -> None:
    code, out, _ = _run(capsys, "regmap", "--format", fmt)
    assert code == 0 and marker in out


def test_regmap_html_to_directory(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    out_dir = tmp_path / "html"
    code, out, _ = _run(capsys, "regmap", "--format", "html", "-o", str(out_dir))
    assert code == 0 and (out_dir / "index.html").exists() and str(out_dir) in out


@pytest.mark.parametrize(("argv", "expected"), [
    (["--metres", "150"], {"code": 24, "medium": "polymer", "register": "0x18", "one_way_m_from": 150.0}),
    (["--metres", "150", "--medium", "glass"], {"code": 0, "medium": "glass", "register": "0x40"}),
    (["--code", "63"], {"one_way_m_from": 393.75, "one_way_m_below": 20_000.0, "beyond_range": True}),
    (["--register", "0xD8"], {"code": 24, "medium": "glass", "enable": 1, "one_way_m_from": 4800.0}),
    (["--register", "152"], {"code": 24, "medium": "polymer", "enable": 1}),
    (["--count", "12"], {"code": 24, "one_way_m_from": 150.0}),  # 500 kbit/s: 12.5 m one way per count
    (["--count", "48", "--bit-rate", "2M"], {"code": 24}),  # 2 Mbit/s: 3.125 m per count
])  # fmt: skip
def test_optical_converts_both_ways(capsys: pytest.CaptureFixture[str], argv: list[str],
                                    expected: dict[str, object]) -> None:
    code, out, _ = _run(capsys, "optical", *argv, "--json")
    data = json.loads(out)
    assert code == 0 and {k: data[k] for k in expected} == expected
    code, text, _ = _run(capsys, "optical", *argv)
    assert code == 0 and f"code             {data['code']}" in text

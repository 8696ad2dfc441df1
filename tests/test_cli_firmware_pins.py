"""``supi3 firmware run --fidelity pin`` and ``--vcd`` (src/supi3/cli.py, supi3.mcu.session): the example firmware's
report on the pin-level whole chip with the VCD of its pins and the MCU's lines, and the options' refusals (one line
on stderr, exit status 2)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from supi3.cli import main
from supi3.mcu import build as mcu_build
from supi3.sdk import native

pytestmark = pytest.mark.skipif(mcu_build.toolchain_missing() is not None, reason=str(mcu_build.toolchain_missing()))


@pytest.fixture(scope="module")
def elf(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """digital_io for the Cortex-M3, built once per module."""
    return mcu_build.build(native.example("digital_io"), tmp_path_factory.mktemp("fw") / "digital_io.elf")


@pytest.mark.slow
def test_a_pin_level_run_reports_the_data_and_writes_the_vcd(
    capsys: pytest.CaptureFixture[str], elf: Path, tmp_path: Path
) -> None:
    """Six cycles at 500 kbit/s: the configuration (ID 03h, one word), the data both ways, no violation, exit 0,
    and the VCD named in the report and the JSON with the chip's scope and the MCU's."""
    vcd = tmp_path / "run.vcd"
    code = main(["firmware", "run", str(elf), "--fidelity", "pin", "--cycles", "6", "--out", "8118", "--in", "0ff0",
                 "--vcd", str(vcd), "--json"])  # fmt: skip
    out, err = capsys.readouterr()
    assert (code, err) == (0, "")
    report = json.loads(out)
    assert (report["fidelity"], report["vcd"], report["violations"]) == ("pin", str(vcd), [])
    assert [(e["id_code"], e["data_bytes"]) for e in report["configuration"]] == [(3, 2)]
    assert report["process_data"] == {"master_out": "8118", "firmware_outputs": "8118", "firmware_inputs": "0ff0",
                                      "master_in": "0ff0", "ok": True}  # fmt: skip
    text = vcd.read_text()
    assert "$scope module dev1" in text and "$scope module mcu" in text and "pa7_mosi" in text


@pytest.mark.slow
def test_devices_behind_the_chip_at_pin_level_are_the_transaction_levels(
    capsys: pytest.CaptureFixture[str], elf: Path
) -> None:
    """``--devices 2`` at pin level (MCU-23): the device behind the chip is a pin-level SUPI 3 strapped RB 16 IN, so
    the report's configuration table and process data are those of the transaction-level run with its plain
    device of the same ID code and length (02h, one word)."""
    reports = []
    for fidelity in ("transaction", "pin"):
        code = main(["firmware", "run", str(elf), "--fidelity", fidelity, "--devices", "2", "--cycles", "6", "--out",
                     "8118", "--in", "0ff0", "--json"])  # fmt: skip
        out, err = capsys.readouterr()
        assert (code, err) == (0, "")
        reports.append(json.loads(out))
    for key in ("configuration", "process_data", "violations"):
        assert reports[0][key] == reports[1][key], key
    assert [(e["id_code"], e["data_bytes"]) for e in reports[1]["configuration"]] == [(3, 2), (2, 2)]


@pytest.mark.parametrize(("argv", "expect"), [
    (["--vcd", "{tmp}/x.vcd"], "--vcd needs --fidelity pin (the transaction-level chip has no pins)"),
    (["--fidelity", "pin", "--devices", "5"], "--devices must be an integer from 1 to 4 (with --fidelity pin"),
    (["--fidelity", "pin", "--cycles", "51"],
     "--cycles must be an integer from 6 to 50 (the power-up's 3 and 3 to check the exchange; with --fidelity pin"),
    (["--fidelity", "gate"], "invalid choice: 'gate'"),
    (["--mode", "spi"], "invalid choice: 'spi'"),
    (["--fidelity", "pin", "--vcd", "{tmp}/no/x.vcd"], "--vcd"),
])  # fmt: skip
def test_pin_level_options_are_refused_in_one_line(
    capsys: pytest.CaptureFixture[str], elf: Path, tmp_path: Path, argv: list[str], expect: str
) -> None:
    code = main(["firmware", "run", str(elf), *(arg.format(tmp=tmp_path) for arg in argv)])
    out, err = capsys.readouterr()
    assert code == 2, (out, err)
    assert "Traceback" not in err and err.count("\n") == 1 and expect in err, err
    assert out == "" and not (tmp_path / "x.vcd").exists()

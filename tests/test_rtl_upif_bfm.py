"""The RTL serial µP interface under cocotb + Verilator, driven by cocotbext-spi's SpiMaster (sim/rtl_upif.py)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

from supi3.rtl.upif import verilog
from supi3.verif.rtl import ensure_toolchain

SIM_DIR = Path(__file__).resolve().parents[1] / "sim"
TOP = "supi3_upif"


def test_spi_master_bfm(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    if importlib.util.find_spec("cocotbext.spi") is None:
        pytest.skip("cocotbext-spi is not installed (the rtl extra)")
    from cocotb_tools.check_results import get_results
    from cocotb_tools.runner import get_runner

    ensure_toolchain("verilator")
    source = tmp_path / f"{TOP}.v"
    source.write_text(verilog(), encoding="utf-8")
    runner = get_runner("verilator")
    runner.build(sources=[source], hdl_toplevel=TOP, build_dir=tmp_path, build_args=["-Wno-fatal"],
                 timescale=("1ns", "1ps"), log_file=tmp_path / "build.log")
    monkeypatch.syspath_prepend(str(SIM_DIR))
    results = runner.test(test_module="rtl_upif", hdl_toplevel=TOP, hdl_toplevel_lang="verilog",
                          build_dir=tmp_path, test_dir=tmp_path, results_xml=str(tmp_path / "results.xml"),
                          log_file=tmp_path / "sim.log")
    tests, failed = get_results(Path(results))
    log = (tmp_path / "sim.log").read_text(encoding="utf-8", errors="replace")
    assert (tests, failed) == (1, 0), log[-3000:]

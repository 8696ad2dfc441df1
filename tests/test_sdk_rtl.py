"""The Python example firmware on the RTL chip (supi3.sdk.rtl): the same firmware classes, the same process data
as on the model bench.

Ref: IBS SUPI 3 OPC UM E rev. 05, 3.4 (the µP interface, Table 3-7 timing), 3.4.14 (VALID interrupt); guide
docs/sdk-firmware-python.md. One Verilator build of ``supi3_chip`` (the straps are ports) serves every case; each case
is one cocotb run of sim/sdk_rtl.py, which drives the chip's µP pins from the synchronous firmware in a
``cocotb.task.bridge`` thread and its INTERBUS line from a master (:class:`supi3.sdk.rtl.RtlRing`).
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from supi3.sdk.bench import Bench
from supi3.sdk.driver import Mode
from supi3.sdk.examples import DigitalIo, InterruptDriven, play
from supi3.tables import BIT_RATES
from support import VerilatorBuild

SIM_DIR = Path(__file__).resolve().parents[1] / "sim"
TOP = "supi3_chip"
CYCLE_TIME_S = 1e-3
"""A master cycle every millisecond on both benches: the firmware's service routine ends between two cycles."""
START_CYCLES = 4
HISTORY = [(0x1234, 0xBEEF), (0xFFFF, 0x0001), (0x8001, 0x7FFE), (0x0000, 0xA55A)]


@pytest.fixture(scope="session")
def chip_build(verilator_build: VerilatorBuild) -> Path:
    """The Verilator build of the RTL chip for cocotb."""
    from cocotb_tools.runner import get_runner

    from supi3.rtl.chip import verilog
    from supi3.verif.rtl import ensure_toolchain

    ensure_toolchain("verilator")
    build = verilator_build("sdk_rtl")
    source = build / f"{TOP}.v"
    source.write_text(verilog(), encoding="utf-8")
    get_runner("verilator").build(sources=[source], hdl_toplevel=TOP, build_dir=build, build_args=["-Wno-fatal"],
                                  timescale=("1ns", "1ps"), log_file=build / "build.log")  # fmt: skip
    return build


def simulate(build: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, testcase: str, **env: str) -> None:
    """Run one cocotb test of sim/sdk_rtl.py on the build, with ``env`` set; fail with the log's end if it fails."""
    from cocotb_tools.check_results import get_results
    from cocotb_tools.runner import get_runner

    for name, value in env.items():
        monkeypatch.setenv(name, value)
    monkeypatch.syspath_prepend(str(SIM_DIR))
    log = tmp_path / "sim.log"
    try:
        results = get_runner("verilator").test(test_module="sdk_rtl", testcase=testcase, hdl_toplevel=TOP,
                                               hdl_toplevel_lang="verilog", build_dir=build, test_dir=tmp_path,
                                               results_xml=str(tmp_path / "results.xml"), log_file=log)  # fmt: skip
    except SystemExit:  # the runner exits when a test fails
        results = tmp_path / "results.xml"
    assert get_results(Path(results)) == (1, 0), log.read_text(encoding="utf-8", errors="replace")[-3000:]


def on_rtl(build: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, example: str, mode: Mode,
           bit_rate: int) -> dict[str, object]:  # fmt: skip
    job = tmp_path / "job.json"
    job.write_text(json.dumps({"example": example, "mode": mode.value, "bit_rate": bit_rate,
                               "cycle_time_s": CYCLE_TIME_S, "history": HISTORY}), encoding="utf-8")  # fmt: skip
    simulate(build, tmp_path, monkeypatch, "example_on_rtl", SUPI3_SDK_RTL_JOB=str(job))
    result: dict[str, object] = json.loads(job.with_suffix(".result.json").read_text(encoding="utf-8"))
    return result


def on_model(example: type[DigitalIo | InterruptDriven], mode: Mode, bit_rate: int) -> list[tuple[int, int]]:
    device = example(mode)
    bench = Bench(firmware=device, mode=mode, bit_rate=bit_rate, cycle_time_s=CYCLE_TIME_S)
    bench.run(START_CYCLES)
    return play(bench, device, HISTORY)


@pytest.mark.parametrize(("example", "mode", "bit_rate"), [
    (DigitalIo, Mode.MOTOROLA, BIT_RATES[0]),
    (InterruptDriven, Mode.MOTOROLA, BIT_RATES[0]),
    (DigitalIo, Mode.INTEL, BIT_RATES[1]),
])  # fmt: skip
def test_example_on_rtl_gives_the_model_benchs_process_data(
    chip_build: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, example: type[DigitalIo | InterruptDriven],
    mode: Mode, bit_rate: int,
) -> None:  # fmt: skip
    result = on_rtl(chip_build, tmp_path, monkeypatch, example.__name__, mode, bit_rate)
    assert (result["id_code"], result["data_bits"]) == (0x03, 16)  # SET 83h, ID 03h went through the RTL's pins
    seen = [tuple(step) for step in result["seen"]]  # type: ignore[attr-defined]
    assert seen == HISTORY
    assert seen == on_model(example, mode, bit_rate)
    assert result["interrupts"] >= len(HISTORY)  # type: ignore[operator]


@pytest.mark.parametrize("mode", list(Mode))
def test_async_driver_on_rtl_pins(
    chip_build: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, mode: Mode
) -> None:
    """AsyncSupi3Driver over RtlTransport from a coroutine: init, SET/ID, events, UP-3, SAS_INIT (sim/sdk_rtl.py)."""
    simulate(chip_build, tmp_path, monkeypatch, "async_driver_registers", SUPI3_SDK_RTL_MODE=mode.value)

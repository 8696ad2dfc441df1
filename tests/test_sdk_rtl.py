"""The Python example firmware on the RTL chip (supi3.sdk.rtl): the same firmware classes, the same process data
as on the model bench.

Ref: IBS SUPI 3 OPC UM E rev. 05, 3.4 (the µP interface, Table 3-7 timing), 3.4.14 (VALID interrupt); guide
docs/sdk-firmware-python.md. One Verilator build of ``supi3_chip`` (the straps are ports) serves every case; each case
is one cocotb run of sim/sdk_rtl.py, which drives the chip's µP pins from the synchronous firmware in a
``cocotb.task.bridge`` thread and its INTERBUS line from a master (:class:`supi3.sdk.rtl.RtlRing`).
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any, NamedTuple

import pytest

from supi3.sdk.bench import Bench
from supi3.sdk.driver import Mode
from supi3.sdk.examples import AnalogIo, DigitalIo, InterruptDriven, ManagementChannel, PollingIo, play
from supi3.sdk.examples.analog import AIO_ID
from supi3.sdk.examples.digital import DIO_ID
from supi3.sdk.examples.management import STATUS_REQUEST, ask
from supi3.tables import BIT_RATES
from support import SDK_CHIP_TOP

Example = AnalogIo | DigitalIo | InterruptDriven | ManagementChannel | PollingIo
SIM_DIR = Path(__file__).resolve().parents[1] / "sim"
TOP = SDK_CHIP_TOP
CYCLE_TIME_S = 1e-3
"""A master cycle every millisecond on both benches: the firmware's service routine ends between two cycles."""
START_CYCLES = 4
FAST_CYCLE_TIME_S = 0.25e-3
"""At 2 Mbit/s a cycle every 250 µs still leaves the firmware most of the period (a 32-bit data cycle is under
40 µs); the shorter simulated time keeps the CI cost down."""
HISTORY = [(0x1234, 0xBEEF), (0xFFFF, 0x0001), (0x8001, 0x7FFE), (0x0000, 0xA55A)]
COMMANDS = [STATUS_REQUEST, 0x3C]
LONG_HISTORY = [(0x1234_5678, 0xDEAD_BEEF), (0xFFFF_FFFF, 0x0000_0001), (0x8000_0001, 0x7FFF_FFFE)]


def simulate(build: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, testcase: str, tests: int = 1,
             **env: str) -> None:  # fmt: skip
    """Run the cocotb test ``testcase`` of sim/sdk_rtl.py on the build (``tests`` of them if it is parametrized),
    with ``env`` set; fail with the log's end if one fails."""
    from cocotb_tools.check_results import get_results
    from cocotb_tools.runner import get_runner

    for name, value in env.items():
        monkeypatch.setenv(name, value)
    monkeypatch.syspath_prepend(str(SIM_DIR))
    log = tmp_path / "sim.log"
    try:
        results = get_runner("verilator").test(test_module="sdk_rtl", test_filter=rf"\.{testcase}(/.*)?$",
                                               hdl_toplevel=TOP, hdl_toplevel_lang="verilog", build_dir=build,
                                               test_dir=tmp_path,
                                               results_xml=str(tmp_path / "results.xml"), log_file=log)  # fmt: skip
    except SystemExit:  # the runner exits when a test fails
        results = tmp_path / "results.xml"
    assert get_results(Path(results)) == (tests, 0), log.read_text(encoding="utf-8", errors="replace")[-3000:]


class Case(NamedTuple):
    """One example run on both benches: a process data ``history`` (:func:`play`), or for the management channel the
    processor ``commands`` (:func:`ask`)."""

    example: type[Example]
    mode: Mode
    bit_rate: int
    history: Sequence[tuple[int, int]] = ()
    commands: Sequence[int] = ()
    cycle_time_s: float | None = CYCLE_TIME_S
    io_pin: bool = True

    def job(self) -> dict[str, object]:
        """The case as sim/sdk_rtl.py reads it."""
        return {"example": self.example.__name__, "mode": self.mode.value, "bit_rate": self.bit_rate,
                "cycle_time_s": self.cycle_time_s, "io_pin": self.io_pin, "history": list(self.history),
                "commands": list(self.commands)}  # fmt: skip

    def on_model(self) -> list[Any]:
        """What the model bench (:class:`supi3.sdk.bench.Bench`) gives: the history's steps or the alarm bytes."""
        device = self.example(self.mode)
        bench = Bench(firmware=device, mode=self.mode, bit_rate=self.bit_rate, cycle_time_s=self.cycle_time_s,
                      io_pin=self.io_pin)  # fmt: skip
        bench.run(START_CYCLES)
        if isinstance(device, ManagementChannel):
            return [ask(bench, command) for command in self.commands]
        return play(bench, device, self.history)


def on_rtl(build: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, cases: list[Case]) -> list[dict[str, Any]]:
    """Run ``cases`` in one simulation (sim/sdk_rtl.py, one cocotb test each); what each saw."""
    job = tmp_path / "job.json"
    job.write_text(json.dumps([case.job() for case in cases]), encoding="utf-8")
    simulate(build, tmp_path, monkeypatch, "example_on_rtl", len(cases), SUPI3_SDK_RTL_JOB=str(job))
    return [json.loads(job.with_suffix(f".{i}.result.json").read_text(encoding="utf-8")) for i in range(len(cases))]


def check_process_data(case: Case, result: dict[str, Any], identity: tuple[int, int]) -> None:
    """The RTL gave the configuration ``identity`` (ID code, data bits) to the master, the history back, and the
    model bench's words."""
    assert (result["id_code"], result["data_bits"]) == identity  # SET and ID went through the RTL's pins (3.4.5)
    seen = [tuple(step) for step in result["seen"]]
    assert seen == list(case.history)
    assert seen == case.on_model()


@pytest.mark.parametrize("case", [
    Case(DigitalIo, Mode.MOTOROLA, BIT_RATES[0], HISTORY),
    Case(InterruptDriven, Mode.MOTOROLA, BIT_RATES[0], HISTORY),
    Case(DigitalIo, Mode.INTEL, BIT_RATES[1], HISTORY),
], ids=lambda case: f"{case.example.__name__}-{case.mode.value}-{case.bit_rate}")  # fmt: skip
def test_example_on_rtl_gives_the_model_benchs_process_data(
    chip_build: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, case: Case
) -> None:
    [result] = on_rtl(chip_build, tmp_path, monkeypatch, [case])
    check_process_data(case, result, (DIO_ID, 16))
    assert result["interrupts"] >= len(HISTORY)


def test_analog_polling_and_management_on_rtl(
    chip_build: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """One simulation, 2 Mbit/s, short cycles (CI time), the model bench's results:

    - AnalogIo: SET 85h, one 4-byte block transfer per VALID (3.4.6; Intel: four reads, then four writes, Fig. 3-12);
    - PollingIo: no interrupt; the I/O access bit polled as D7 of register 14 (3.4.14, Fig. 3-22; FW-9), the block
      transfer in the window; then on the I/O pin (MFP1), each read costing ``PIN_READ_CLOCKS``;
    - ManagementChannel: each processor command read on PCMD (address 7) and answered by a processor alarm the
      master reads in place of the ID code (3.4.9, A18).
    """
    analog, polling, management, pin = cases = [
        Case(AnalogIo, Mode.INTEL, BIT_RATES[1], LONG_HISTORY, cycle_time_s=FAST_CYCLE_TIME_S),
        Case(PollingIo, Mode.MOTOROLA, BIT_RATES[1], HISTORY[:3], cycle_time_s=FAST_CYCLE_TIME_S, io_pin=False),
        Case(ManagementChannel, Mode.INTEL, BIT_RATES[1], commands=COMMANDS, cycle_time_s=FAST_CYCLE_TIME_S),
        Case(PollingIo, Mode.INTEL, BIT_RATES[1], HISTORY[-2:], cycle_time_s=FAST_CYCLE_TIME_S),
    ]
    analog_result, polling_result, management_result, pin_result = on_rtl(chip_build, tmp_path, monkeypatch, cases)
    check_process_data(analog, analog_result, (AIO_ID, 32))
    assert analog_result["interrupts"] >= len(LONG_HISTORY)
    check_process_data(polling, polling_result, (DIO_ID, 16))
    assert polling_result["interrupts"] == 0
    assert (management_result["id_code"], management_result["data_bits"]) == (DIO_ID, 16)
    assert management_result["commands"] == COMMANDS
    assert management_result["seen"] == [ManagementChannel().answer(command) for command in COMMANDS]
    assert management_result["seen"] == management.on_model()
    check_process_data(pin, pin_result, (DIO_ID, 16))
    assert pin_result["interrupts"] == 0


@pytest.mark.parametrize("mode", list(Mode))
def test_async_driver_on_rtl_pins(
    chip_build: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, mode: Mode
) -> None:
    """AsyncSupi3Driver over RtlTransport from a coroutine: init, SET/ID, events, UP-3, SAS_INIT (sim/sdk_rtl.py)."""
    simulate(chip_build, tmp_path, monkeypatch, "async_driver_registers", SUPI3_SDK_RTL_MODE=mode.value)

"""cocotb test: a Python example firmware (supi3.sdk.examples) on the RTL chip, with an INTERBUS master on its line.

Ref: guide docs/sdk-firmware-python.md, "The RTL back end". The job (JSON, path in ``SUPI3_SDK_RTL_JOB``) names the
example, the interface mode, the bit rate, the cycle time and a process data history; the test starts the chip
(:class:`supi3.sdk.rtl.RtlBoard`), runs the firmware with the master (:class:`supi3.sdk.rtl.RtlBench`), plays the
history (:func:`supi3.sdk.examples.play`) and writes what it saw as JSON next to the job. Started by
tests/test_sdk_rtl.py, not by hand.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import cocotb

from supi3.sdk import examples
from supi3.sdk.bench import default_config
from supi3.sdk.driver import Mode
from supi3.sdk.rtl import RtlBench, RtlBoard

JOB_ENV = "SUPI3_SDK_RTL_JOB"
START_CYCLES = 4
"""Master cycles before the history: Alarm Stop and discovery, the rediscovery, data cycles (as on the model
bench, tests/test_sdk_examples.py)."""


@cocotb.test()
async def example_on_rtl(dut: Any) -> None:
    """Play the job's history through its example firmware on the RTL chip."""
    path = Path(os.environ[JOB_ENV])
    job = json.loads(path.read_text(encoding="utf-8"))
    mode = Mode(job["mode"])
    board = RtlBoard(dut, default_config(job["bit_rate"]))
    await board.start()
    device = getattr(examples, job["example"])(mode)
    bench = RtlBench(board, device, mode=mode, cycle_time_s=job["cycle_time_s"])
    history = [tuple(step) for step in job["history"]]

    def scenario() -> dict[str, Any]:
        bench.run(START_CYCLES)
        entry = bench.master.entry(1)
        seen = examples.play(bench, device, history)
        return {"id_code": entry.id_code, "data_bits": entry.data_bits, "seen": seen,
                "interrupts": bench.interrupts, "frames": bench.transport.frames}  # fmt: skip

    result = await bench.call(scenario)
    path.with_suffix(".result.json").write_text(json.dumps(result), encoding="utf-8")

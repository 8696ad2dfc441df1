"""cocotb tests: the Python driver and example firmware (supi3.sdk) on the RTL chip.

Ref: guide docs/sdk-firmware-python.md, "The RTL back end"; 3.4.3 to 3.4.5, 3.4.14. ``async_driver_registers``
drives the chip with the async driver straight from a coroutine; ``bench_called_twice`` calls one ``RtlBench`` twice
(FW-23). ``example_on_rtl`` runs an example firmware with an
INTERBUS master on the chip's line: the job (JSON, path in ``SUPI3_SDK_RTL_JOB``) is a list of cases, each naming
the example, the interface mode, the bit rate, the cycle time, whether the I/O pin is wired and a process data
history (or, for the management channel, the processor commands); one simulation runs them all, one parametrized
test per case: each starts the chip (:class:`supi3.sdk.rtl.RtlBoard`), runs the firmware with the master
(:class:`supi3.sdk.rtl.RtlBench`), plays the history (:func:`supi3.sdk.examples.play`) or sends the commands
(:func:`supi3.sdk.examples.management.ask`) and writes what it saw as JSON next to the job
(``job.<case>.result.json``). Started by tests/test_sdk_rtl.py, not by hand.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import cocotb

from supi3.regmap import ID, IRQ_EVT, SET
from supi3.sdk import examples
from supi3.sdk.bench import default_config
from supi3.sdk.driver import AsyncSupi3Driver, Irq, Mode, NotResetError
from supi3.sdk.examples.digital import DIO_ID, ONE_WORD_IO
from supi3.sdk.examples.management import ask
from supi3.sdk.rtl import RtlBench, RtlBoard, RtlBoardError, RtlTransport

JOB_ENV = "SUPI3_SDK_RTL_JOB"
MODE_ENV = "SUPI3_SDK_RTL_MODE"
START_CYCLES = 4
"""Master cycles before the history: Alarm Stop and discovery, the rediscovery, data cycles (as on the model
bench, tests/test_sdk_examples.py)."""


def _cases() -> list[int]:
    """The indices of the job's cases (none without a job: the module is also loaded for the driver test)."""
    path = os.environ.get(JOB_ENV)
    return list(range(len(json.loads(Path(path).read_text(encoding="utf-8"))))) if path else []


@cocotb.test()
@cocotb.parametrize(case=_cases())
async def example_on_rtl(dut: Any, case: int) -> None:
    """Play case ``case`` of the job through its example firmware on the RTL chip, from a fresh power-up (each
    parametrized test ends with its clock stopped; the next one resets the chip)."""
    path = Path(os.environ[JOB_ENV])
    job = json.loads(path.read_text(encoding="utf-8"))[case]
    mode = Mode(job["mode"])
    board = RtlBoard(dut, default_config(job["bit_rate"]))
    await board.start()
    device = getattr(examples, job["example"])(mode)
    bench = RtlBench(board, device, mode=mode, cycle_time_s=job["cycle_time_s"], io_pin=job["io_pin"])

    def scenario() -> dict[str, Any]:
        bench.run(START_CYCLES)
        entry = bench.master.entry(1)
        result: dict[str, Any] = {"id_code": entry.id_code, "data_bits": entry.data_bits}
        if isinstance(device, examples.ManagementChannel):
            result["seen"] = [ask(bench, command) for command in job["commands"]]
            result["commands"] = device.commands
        else:
            result["seen"] = examples.play(bench, device, [tuple(step) for step in job["history"]])
        return {**result, "interrupts": bench.interrupts, "frames": bench.transport.frames}

    result = await bench.call(scenario)
    path.with_suffix(f".{case}.result.json").write_text(json.dumps(result), encoding="utf-8")


@cocotb.test()
async def async_driver_registers(dut: Any) -> None:
    """``AsyncSupi3Driver`` over ``RtlTransport``: initialize (C/D checked, 3.4.3), SET and ID written and read back
    (3.4.5), the events of the power-up read and cleared (3.4.14), the init byte refused as a command once the
    interface runs (UP-3), SAS_INIT restarts it with the registers kept (3.4.3)."""
    mode = Mode(os.environ.get(MODE_ENV, Mode.MOTOROLA.value))
    board = RtlBoard(dut, default_config(500_000))
    await board.start()
    transport = RtlTransport(board, mode)
    drv = AsyncSupi3Driver(transport)
    await drv.initialize(mode)
    await drv.configure(ONE_WORD_IO, DIO_ID)
    assert (await drv.read(SET), await drv.read(ID)) == (ONE_WORD_IO, DIO_ID)
    await drv.irq_enable(Irq.VALID | Irq.IB_RESET)
    assert await drv.read(IRQ_EVT) & Irq.VALID == 0  # no data cycle yet
    assert await drv.irq_service() == Irq(0)  # /IRQ high: nothing sent
    try:
        await drv.initialize(mode)
    except NotResetError:
        pass
    else:
        raise AssertionError("a second initialization byte must be taken as a command (UP-3)")
    await drv.sas_init()
    await drv.initialize(mode)
    assert (await drv.read(SET), await drv.read(ID)) == (ONE_WORD_IO, DIO_ID)  # SAS_INIT keeps the registers


@cocotb.test()
async def bench_called_twice(dut: Any) -> None:
    """FW-23: one ``RtlBench`` called twice: the firmware's setup at the first call only (a second initialization
    byte would be taken as a command, UP-3: ``NotResetError``), the firmware served in both; the board refuses a
    second start; the status pins read as levels (UP-24)."""
    board = RtlBoard(dut, default_config(2_000_000))
    await board.start()
    device = examples.DigitalIo(Mode.MOTOROLA)
    bench = RtlBench(board, device, cycle_time_s=0.25e-3)

    def first() -> list[tuple[int, int]]:
        bench.run(START_CYCLES)
        return examples.play(bench, device, [(0x1234, 0xBEEF)])

    assert await bench.call(first) == [(0x1234, 0xBEEF)]
    assert await bench.call(lambda: examples.play(bench, device, [(0x8001, 0x7FFE)])) == [(0x8001, 0x7FFE)]
    try:
        await board.start()
    except RtlBoardError:
        pass
    else:
        raise AssertionError("a second start must be refused")
    transport = bench.transport
    assert (await transport.read_cd(), await transport.read_irq(), await transport.read_io()) in {
        (0, level, io) for level in (0, 1) for io in (0, 1)}

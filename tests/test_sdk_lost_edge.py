"""FW-22: the lost /IRQ edge of an edge-triggered firmware, and the SDK's service routine that leaves none.

/IRQ is low while the interrupt event register holds an event (3.4.14, "Interrupt operation"); an MCU's external
interrupt takes its falling edge (FW-3). A firmware that reads IRQ_EVT once per edge loses the edge for good when the
next event comes in the very frame that reads the register: the read clears only the events it returned (UP-18),
/IRQ stays low (at transaction level; on a chip at most a pulse too short for the input), no new falling edge comes,
and the firmware waits for ever. ``supi3_irq_service`` / ``Supi3Driver.irq_service`` read /IRQ after each read and
read IRQ_EVT again while it is low (at most ``SUPI3_IRQ_SERVICE_MAX_READS``), so nothing is pending when they return.

Here a service routine does 990 µs of other work before it reads the events, with a master cycle every millisecond:
its read meets the next cycle's VALID event. Python firmware (each routine), the host build of
tests/c/firmware/late_service.c (its first routine) on the firmware bench, its binary on the emulated board (where an
event comes inside the first handler and is served in it).
"""

from __future__ import annotations

import itertools
from pathlib import Path

import pytest

from supi3.mcu import build as mcu_build
from supi3.mcu.board import Board
from supi3.regmap import IN0, IN1, IRQ_EVT, OUT0, OUT1
from supi3.sdk.bench import Bench
from supi3.sdk.driver import IRQ_SERVICE_MAX_READS, Irq, Supi3Driver
from supi3.sdk.examples import DigitalIo
from support import c_firmware
from test_sdk_serve import NotingDigitalIo

LATE_SERVICE = Path(__file__).parent / "c" / "firmware" / "late_service.c"
CYCLE_TIME_S = 1e-3
DELAY_US = 990
"""The service routine's other work before its read of IRQ_EVT: at 500 kbit/s with a cycle every millisecond the
read's data frame holds the next cycle's end (found by a sweep of 950 to 1,005 µs in steps of 5)."""
BOARD_DELAY_US = 730
"""The same on the emulated board (its busy wait and 750 kHz SCLK differ from the bench's costs; 726 to 734 µs do)."""


class LateService(DigitalIo):
    """DigitalIo whose service routine first does ``delay_us`` of other work; ``once``: it reads IRQ_EVT once, by
    ``read``, as a firmware that serves one event per edge; else by ``irq_service``. ``reads`` counts the IRQ_EVT
    reads of each routine."""

    def __init__(self, delay_us: float, *, once: bool) -> None:
        super().__init__()
        self.delay_us, self.once = delay_us, once
        self.reads: list[int] = []
        self.exchanged = 0

    def isr(self, drv: Supi3Driver) -> None:
        bench = drv.transport.bench  # type: ignore[attr-defined]
        drv.transport.delay_us(self.delay_us)
        before = bench.bytes_clocked
        events = Irq(drv.read(IRQ_EVT)) if self.once else drv.irq_service()
        self.reads.append((bench.bytes_clocked - before) // 2)
        if events & Irq.VALID:
            self.outputs = drv.read(OUT0) << 8 | drv.read(OUT1)
            drv.write(IN0, self.inputs >> 8)
            drv.write(IN1, self.inputs & 0xFF)
            self.exchanged += 1


def _play(bench: Bench) -> None:
    bench.run(4)
    bench.master.set_outputs(1, b"\x12\x34")
    bench.run(6)


def test_a_firmware_that_reads_the_events_once_per_edge_loses_the_edge_for_good() -> None:
    """The reproduction: the first service routine's read meets the next VALID event; /IRQ stays low from then on,
    the routine never runs again, the outputs never follow the master."""
    device = LateService(DELAY_US, once=True)
    bench = Bench(firmware=device, cycle_time_s=CYCLE_TIME_S)
    _play(bench)
    assert bench.interrupts == 1 and device.exchanged == 1
    assert bench.registers.irq_n == 0 and bench.registers.value("IRQ_EVT") & Irq.VALID
    assert device.outputs == 0


def test_irq_service_reads_until_irq_is_high_and_the_firmware_keeps_up() -> None:
    """The same routine with ``irq_service``: each call reads IRQ_EVT twice (the second read takes the event that
    came during the first), /IRQ is high after it, every edge is served and the outputs follow."""
    device = LateService(DELAY_US, once=False)
    bench = Bench(firmware=device, cycle_time_s=CYCLE_TIME_S)
    _play(bench)
    assert 2 in device.reads and max(device.reads) <= IRQ_SERVICE_MAX_READS
    assert bench.interrupts == len(device.reads) >= 5 and device.exchanged == bench.interrupts
    assert bench.registers.irq_n == 1 and device.outputs == 0x1234


def test_the_last_stop_s_700_us_main_loop_no_longer_hangs() -> None:
    """tests/test_sdk_serve.py's noting main loop with a 0.7 ms pass (FW-15's note): its service routine read IRQ_EVT
    in the frame of the next cycle's event and the firmware waited for ever on a low /IRQ (one interrupt in nine
    cycles). Now the routine takes that event too; a pass that long (back-to-back cycles of some 0.2 ms) puts the
    routine's data accesses anywhere in the cycle. Since MCU-55 and MCU-56 (the master holds at a run's end, the
    discovery ID cycle is sized for the ring) they miss the latch phases here: 40 cycles take 8 routines, each run
    ending unserved (the pass outlasts the wait), none silent; before, the next access fell in a latch phase (3.4.14)
    within six cycles."""
    device = NotingDigitalIo(pass_us=700.0)
    bench = Bench(firmware=device)
    bench.run(3)
    bench.master.set_outputs(1, b"\x12\x34")
    bench.run(40)
    assert (bench.interrupts, bench.cycles, bench.served) == (8, 43, False)
    assert bench.registers.violations.records == []


@pytest.mark.parametrize(("once", "served"), [("1", False), ("0", True)])
def test_the_host_build_of_the_c_firmware_loses_or_serves_alike(pytestconfig: pytest.Config, once: str,
                                                                 served: bool) -> None:  # fmt: skip
    """late_service.c on the bench: its first service routine reads register 14 late; by ``supi3_read`` once per
    edge it loses the edge (one data cycle exchanged, /IRQ low for good), by ``supi3_irq_service`` it takes the next
    event too and every later edge is served."""
    assert pytestconfig.cache is not None
    firmware = c_firmware(pytestconfig.cache, LATE_SERVICE, defines={"SERVICE_DELAY_US": f"{DELAY_US}u",
                                                                     "ONCE": once})  # fmt: skip
    bench = Bench(firmware=firmware, cycle_time_s=CYCLE_TIME_S)
    _play(bench)
    outputs = bytes(firmware.board.outputs[0:2])
    if served:
        assert bench.registers.irq_n == 1 and outputs == b"\x12\x34" and firmware.board.cycles >= 5
    else:
        assert bench.registers.irq_n == 0 and outputs == b"\0\0" and firmware.board.cycles == 1


@pytest.mark.skipif(mcu_build.toolchain_missing() is not None, reason=str(mcu_build.toolchain_missing()))
def test_the_binary_serves_an_event_that_comes_inside_its_handler(tmp_path: Path) -> None:
    """late_service.c's binary on the emulated board: the handler's read of IRQ_EVT meets the next cycle's event
    (two reads of register 14 within 60 µs: ``supi3_irq_service`` read again as /IRQ was still low), and nothing is
    lost: /IRQ high after the run, the outputs the master's, a data cycle exchanged in each handler."""
    elf = mcu_build.build(LATE_SERVICE, tmp_path / "late_service.elf",
                          defines={"SERVICE_DELAY_US": f"{BOARD_DELAY_US}u", "ONCE": "0"})  # fmt: skip
    board = Board(elf, cycle_time_s=CYCLE_TIME_S)
    registers, clock = board.registers, board.bench
    reads: list[float] = []
    read = registers.cpu_read

    def counted(address: int) -> int:
        if address == IRQ_EVT.address:
            reads.append(clock.now)
        return read(address)

    registers.cpu_read = counted  # type: ignore[method-assign]
    board.run(4)
    board.master.set_outputs(1, b"\x12\x34")
    board.run(6)
    fw = board.fw_board
    assert fw is not None
    assert min(b - a for a, b in itertools.pairwise(reads)) < 60e-6
    assert registers.irq_n == 1 and fw.outputs[:2] == b"\x12\x34" and board.served
    assert fw.cycles >= 5

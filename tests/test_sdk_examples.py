"""The Python example firmware (supi3.sdk.examples) on the firmware bench, end to end with the INTERBUS master.

Ref: IBS SUPI 3 OPC UM E rev. 05, 3.4.3 to 3.4.9, 3.4.14 (interrupts, polling bit, latch phase, Fig. 3-22), 3.6.2
(/StatErr, /ModAck); guide docs/sdk-firmware-python.md.
"""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.interbus.master import MSG_PERIPHERAL_FAULT
from supi3.interbus.ring import ErrorKind
from supi3.interbus.wire import Cycle
from supi3.model.registers import InconsistentDataError
from supi3.sdk.bench import Bench, Firmware
from supi3.sdk.driver import Mode, Supi3Driver
from supi3.sdk.examples import (
    AnalogIo,
    DigitalIo,
    InterruptDriven,
    ManagementChannel,
    PeripheralFault,
    PollingIo,
    play,
)
from supi3.sdk.examples.analog import AIO_ID
from supi3.sdk.examples.digital import DIO_ID
from supi3.sdk.examples.history import SETTLE_CYCLES
from supi3.sdk.examples.management import STATUS_REQUEST, ask
from supi3.tables import BIT_RATES

MODES = st.sampled_from(list(Mode))
RATES = st.sampled_from(BIT_RATES)
WORD = st.integers(0, 0xFFFF)
LONG = st.integers(0, 0xFFFF_FFFF)
START_CYCLES = 4
"""Discovery, the rediscovery once the firmware has written SET and ID, and a data cycle or two."""
FILTER_S = 0.2 * 1.315
"""/StatErr's filter time t3 at its maximum (3.6.2: 200 ms +-31.5 %)."""


def started(firmware: Firmware, mode: Mode, rate: int, **options: object) -> Bench:
    """A bench with ``firmware`` after start-up: the master has the device's configuration and runs data cycles."""
    bench = Bench(firmware=firmware, mode=mode, bit_rate=rate, **options)  # type: ignore[arg-type]
    bench.run(START_CYCLES)
    assert bench.results[-1].cycle is Cycle.DATA and bench.results[-1].ok
    return bench


# Process data: the same history comes back on both sides ---------------------------------------------------------


@given(mode=MODES, rate=RATES, history=st.lists(st.tuples(WORD, WORD), min_size=1, max_size=6))
def test_digital_16_in_16_out(mode: Mode, rate: int, history: list[tuple[int, int]]) -> None:
    device = DigitalIo(mode)
    bench = started(device, mode, rate)
    entry = bench.master.entry(1)
    assert (entry.id_code, entry.data_bits) == (DIO_ID, 16)  # SET 83h, ID 03h (3.4.5)
    assert play(bench, device, history) == history


@given(mode=MODES, rate=RATES, history=st.lists(st.tuples(LONG, LONG), min_size=1, max_size=6))
def test_analog_32_bit_block_transfer(mode: Mode, rate: int, history: list[tuple[int, int]]) -> None:
    device = AnalogIo(mode)
    bench = started(device, mode, rate)
    entry = bench.master.entry(1)
    assert (entry.id_code, entry.data_bits) == (AIO_ID, 32)  # 2 words (Table 3-12)
    assert play(bench, device, history) == history


@settings(max_examples=10)  # the polling firmware clocks bytes all the time: the slowest bench
@given(mode=MODES, rate=RATES, history=st.lists(st.tuples(WORD, WORD), min_size=1, max_size=6))
def test_polling_device_in_the_io_window(mode: Mode, rate: int, history: list[tuple[int, int]]) -> None:
    device = PollingIo(mode)
    bench = started(device, mode, rate, io_pin=False)  # the manual's method: D7 of register 14 (3.4.14)
    assert play(bench, device, history) == history
    assert bench.interrupts == 0
    assert bench.registers.violations.records == []  # never inside the latch phase


@settings(max_examples=5)
@given(mode=MODES, rate=RATES, history=st.lists(st.tuples(WORD, WORD), min_size=1, max_size=4))
def test_polling_device_on_the_io_pin(mode: Mode, rate: int, history: list[tuple[int, int]]) -> None:
    """The same firmware with MFP1 wired: each pin read costs its time (FW-9), the bus runs on, the window opens."""
    device = PollingIo(mode)
    bench = started(device, mode, rate)
    assert play(bench, device, history) == history
    assert bench.registers.violations.records == []


# A timing bug the model catches ------------------------------------------------------------------------------------


class Unsynchronized(PollingIo):
    """The polling device with its poll forgotten: it accesses the data registers whenever it likes."""

    def loop(self, drv: Supi3Driver) -> None:
        self.exchange(drv)


@pytest.mark.parametrize("rate", BIT_RATES)
@pytest.mark.parametrize("mode", list(Mode))
def test_access_across_the_latch_phase_is_caught(mode: Mode, rate: int) -> None:
    bench = Bench(firmware=Unsynchronized(mode), mode=mode, bit_rate=rate, io_pin=False)
    with pytest.raises(InconsistentDataError, match=r"during the latch phase .*\(3\.4\.14\)") as caught:
        bench.run(50)
    assert caught.value.time_s is not None and caught.value.time_s > 0
    fixed = Bench(firmware=PollingIo(mode), mode=mode, bit_rate=rate, io_pin=False)
    fixed.run(50)  # the same accesses after the poll: no error
    assert fixed.registers.violations.records == []


# Interrupts ----------------------------------------------------------------------------------------------------------


@settings(max_examples=30)
@given(mode=MODES, rate=RATES, history=st.lists(st.tuples(WORD, WORD), min_size=1, max_size=6))
def test_interrupt_driven_device(mode: Mode, rate: int, history: list[tuple[int, int]]) -> None:
    device = InterruptDriven(mode)
    bench = started(device, mode, rate)
    before, first = device.events.copy(), len(bench.results)
    assert play(bench, device, history) == history
    assert device.history[-1] == history[-1][0]
    cycles = list(bench.results)[first:]
    assert device.events["VALID"] - before["VALID"] == sum(r.cycle is Cycle.DATA and r.ok for r in cycles)
    assert device.events["ID_CYCLE"] - before["ID_CYCLE"] == sum(r.cycle is Cycle.ID and r.ok for r in cycles)
    assert bench.interrupts >= device.events["VALID"]  # one service call may take several events


def test_interrupt_driven_device_goes_safe_on_bus_reset() -> None:
    device = InterruptDriven()
    bench = started(device, Mode.MOTOROLA, BIT_RATES[0])
    bench.master.set_outputs(1, b"\x12\x34")
    bench.run(SETTLE_CYCLES)
    # the master's start-up Alarm Stop comes after the set-up (MCU-45, FW-15): the firmware saw that reset once
    assert device.outputs == 0x1234 and device.events["IB_RESET"] == 1
    bench.master.alarm_stop()  # INTERBUS reset (3.4.7)
    bench.run(1)  # the discovery ID cycle after it: no data cycle yet
    assert bench.results[-1].cycle is Cycle.ID
    assert device.events["IB_RESET"] == 2 and device.outputs == 0


# Peripheral fault (3.6.2) -----------------------------------------------------------------------------------------


def fault_bench(mode: Mode = Mode.MOTOROLA) -> tuple[Bench, PeripheralFault]:
    bench = Bench(mode=mode, cycle_time_s=2e-3)
    device = PeripheralFault(bench, mode)
    bench.firmware = device
    bench.run(START_CYCLES)
    return bench, device


def faults(bench: Bench) -> list[int | None]:
    return [d.code for d in bench.master.diagnostics if d.kind is ErrorKind.PERIPHERAL_FAULT]


@pytest.mark.parametrize("mode", list(Mode))
def test_peripheral_fault_reported_and_quit(mode: Mode) -> None:
    bench, device = fault_bench(mode)
    bench.master.set_outputs(1, b"\x00\x07")
    bench.run(SETTLE_CYCLES)
    assert device.outputs == 7
    device.io_fault = True
    bench.run_for(FILTER_S + 0.01)
    assert faults(bench) == [MSG_PERIPHERAL_FAULT]  # 0BB1h, once
    assert device.faulted and device.outputs == 0  # safe state
    device.io_fault = False
    bench.run(SETTLE_CYCLES)
    assert device.faulted and device.outputs == 0, "the fault state lasts until the master quits it"
    assert bench.mod_ack == 1 and bench.mod_ack_pulses == 0
    bench.master.quit_peripheral_error(1)  # 0714h: /ModAck pulses
    bench.run(SETTLE_CYCLES + 1)
    assert bench.mod_ack_pulses == 1
    assert not device.faulted and device.outputs == 7
    assert not bench.chip.pf
    device.io_fault = True  # a second fault latches again
    bench.run_for(FILTER_S + 0.01)
    assert bench.chip.pf and device.faulted and device.outputs == 0


def test_quit_while_the_fault_lasts_keeps_it() -> None:
    bench, device = fault_bench()
    device.io_fault = True
    bench.run_for(FILTER_S + 0.01)
    bench.master.quit_peripheral_error(1)
    bench.run(SETTLE_CYCLES + 1)
    assert bench.mod_ack_pulses == 1
    assert device.faulted and bench.chip.pf  # /StatErr still low at the Quit: the fault stays
    assert faults(bench) == [MSG_PERIPHERAL_FAULT]


def test_short_fault_below_the_filter_time_is_not_reported() -> None:
    bench, device = fault_bench()
    device.io_fault = True
    bench.run_for(0.2 * (1 - 0.315) - 0.01)
    device.io_fault = False
    bench.run_for(FILTER_S)
    assert faults(bench) == []
    assert device.faulted, "the device saw it: it waits for an acknowledgment"


# Management channel (3.4.9) ----------------------------------------------------------------------------------------


@given(mode=MODES, rate=RATES, commands=st.lists(st.integers(0, 0xFF), min_size=1, max_size=4))
def test_processor_command_answered_by_alarm(mode: Mode, rate: int, commands: list[int]) -> None:
    device = ManagementChannel(mode)
    bench = started(device, mode, rate)
    for command in commands:
        bench.master.processor_command(1, command)
        bench.run(2)  # the ID cycle carrying it, then the PCMD interrupt has run
        bench.master.request_processor_alarm(1)
        bench.run(3)  # the request, then the answer in place of the ID code (A18)
        assert bench.master.processor_alarms[1] == device.answer(command)
    assert device.commands == commands


def test_status_request() -> None:
    device = ManagementChannel(status=0xA5)
    bench = started(device, Mode.MOTOROLA, BIT_RATES[0])
    bench.master.processor_command(1, STATUS_REQUEST)
    bench.run(2)
    bench.master.request_processor_alarm(1)
    bench.run(3)
    assert bench.master.processor_alarms[1] == 0xA5


def test_ask_gives_the_answer_once() -> None:
    """``ask()`` (the RTL tests' management scenario): the alarm byte, taken out of the master's record."""
    device = ManagementChannel(Mode.INTEL)
    bench = started(device, Mode.INTEL, BIT_RATES[1])
    assert [ask(bench, STATUS_REQUEST), ask(bench, 0x3C)] == [device.status, 0xC3]
    assert bench.master.processor_alarms == {}
    assert device.commands == [STATUS_REQUEST, 0x3C]

"""The example C firmware (src/supi3/sdk/c/examples) on the firmware bench: master, ring and strict chip model.

Each example is built with the strict flags (-std=c99 -Wall -Wextra -Werror -pedantic) and run through
:class:`supi3.sdk.native.CFirmware`; its process data goes end to end between the INTERBUS master and the board's
terminals (``fw_board_t``). The model runs strict, so any access a firmware makes in the latch phase or any SET
written while the bus runs fails the test; tests/c/firmware/latch_bug.c shows such a bug being caught.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.interbus.ring import ErrorKind
from supi3.model.registers import InconsistentDataError
from supi3.regmap import IN0, IN1, OUT0, OUT1
from supi3.sdk import native
from supi3.sdk.bench import Bench, Firmware
from supi3.sdk.driver import Irq, Mode, Supi3Driver
from supi3.sdk.native import CFirmware
from supi3.timing import upif_byte_s
from support import TEST_FIRMWARE, c_firmware

MODES = (Mode.MOTOROLA, Mode.INTEL)
INTEL = {"FW_MODE": "SUPI3_MODE_INTEL"}
"""The examples' build option for the Intel mode (fw_board.h, Table 3-8)."""


def _bench(cache: pytest.Cache, name: str, mode: Mode = Mode.MOTOROLA, **options: object) -> tuple[Bench, CFirmware]:
    firmware = c_firmware(cache, native.example(name), defines=INTEL if mode is Mode.INTEL else None)
    return Bench(firmware=firmware, mode=mode, **options), firmware  # type: ignore[arg-type]


def _set_inputs(firmware: CFirmware, data: bytes) -> None:
    for k, value in enumerate(data):
        firmware.board.inputs[k] = value


def _outputs(firmware: CFirmware, n: int) -> bytes:
    return bytes(firmware.board.outputs[0:n])


@pytest.mark.parametrize("name", sorted(p.stem for p in native.EXAMPLES_DIR.glob("*.c")))
def test_every_example_builds_under_the_strict_flags(pytestconfig: pytest.Config, name: str) -> None:
    assert pytestconfig.cache is not None
    firmware = c_firmware(pytestconfig.cache, native.example(name))
    assert firmware.library.has_setup
    assert firmware.library.has_isr or firmware.library.has_loop  # each example does something after setup


@pytest.fixture
def cache(pytestconfig: pytest.Config) -> pytest.Cache:
    assert pytestconfig.cache is not None
    return pytestconfig.cache


WORDS = (0x0000, 0xFFFF, 0x1234, 0x8001, 0x00FF)


@pytest.mark.parametrize("mode", MODES)
def test_digital_io_moves_16_bits_each_way_end_to_end(cache: pytest.Cache, mode: Mode) -> None:
    """SET 83h (one word, 3.4.11), ID 03h; OUT0/OUT1 read and IN0/IN1 written in the VALID service routine."""
    bench, firmware = _bench(cache, "digital_io", mode)
    bench.run(3)
    entry = bench.master.config[0] if bench.master.config is not None else None
    assert entry is not None and (entry.id_code, entry.data_bytes) == (0x03, 2)
    for out_word, in_word in zip(WORDS, reversed(WORDS), strict=True):
        bench.master.set_outputs(1, out_word.to_bytes(2, "big"))
        _set_inputs(firmware, in_word.to_bytes(2, "big"))
        bench.run(3)  # one cycle brings OUT to the firmware, whose IN is written in the next and goes out with the
        # third, back to back (MCU-55, FW-19: the master holds after a run's cycles; before, it had started the
        # third in the run's wait)
        assert _outputs(firmware, 2) == out_word.to_bytes(2, "big")
        assert bench.master.inputs(1) == in_word.to_bytes(2, "big")
    assert firmware.board.error == 0
    assert firmware.board.cycles == bench.interrupts  # one VALID event per data cycle, each served


class DigitalIoTwin(Firmware):
    """digital_io.c written with the Python driver, call for call."""

    def __init__(self, mode: Mode) -> None:
        self.mode = mode
        self.inputs = b"\x00\x00"
        self.outputs = b""

    def setup(self, drv: Supi3Driver) -> None:
        drv.initialize(self.mode)
        drv.configure(0x83, 0x03)
        drv.irq_enable(Irq.VALID)

    def isr(self, drv: Supi3Driver) -> None:
        if drv.irq_service() & Irq.VALID:
            self.outputs = bytes([drv.read(OUT0), drv.read(OUT1)])
            drv.write(IN0, self.inputs[0])
            drv.write(IN1, self.inputs[1])


@pytest.mark.parametrize("bit_rate", [500_000, 2_000_000])
@pytest.mark.parametrize("mode", MODES)
def test_c_firmware_costs_the_bus_time_of_its_python_twin(cache: pytest.Cache, bit_rate: int, mode: Mode) -> None:
    """The same calls through the C driver and the Python driver: the same bytes at the same bus times, so the
    same interrupt latency and the same data (FW-1: each byte its Table 3-7 time)."""
    c_bench, c_firmware_ = _bench(cache, "digital_io", mode, bit_rate=bit_rate)
    twin = DigitalIoTwin(mode)
    py_bench = Bench(firmware=twin, bit_rate=bit_rate, mode=mode)
    for bench in (c_bench, py_bench):
        bench.run(3)
        bench.master.set_outputs(1, b"\x3c\xc3")
    _set_inputs(c_firmware_, b"\x96\x69")
    twin.inputs = b"\x96\x69"
    for bench in (c_bench, py_bench):
        bench.run(30)
    assert c_bench.bytes_clocked == py_bench.bytes_clocked
    assert c_bench.now == py_bench.now
    assert c_bench.irq_latency_s == py_bench.irq_latency_s
    assert c_bench.interrupts == py_bench.interrupts
    assert _outputs(c_firmware_, 2) == twin.outputs == b"\x3c\xc3"
    assert c_bench.master.inputs(1) == py_bench.master.inputs(1) == b"\x96\x69"


@settings(max_examples=25)
@given(values=st.lists(st.integers(0, 0xFFFF_FFFF), min_size=1, max_size=4))
def test_analog_io_carries_any_32_bit_values(pytestconfig: pytest.Config, values: list[int]) -> None:
    assert pytestconfig.cache is not None
    bench, firmware = _bench(pytestconfig.cache, "analog_io")
    bench.run(3)
    for value in values:
        bench.master.set_outputs(1, value.to_bytes(4, "big"))
        _set_inputs(firmware, value.to_bytes(4, "little"))
        bench.run(3)  # the round trip back to back (FW-19)
        assert _outputs(firmware, 4) == value.to_bytes(4, "big")
        assert bench.master.inputs(1) == value.to_bytes(4, "little")


@pytest.mark.parametrize(("mode", "block_bytes"), [(Mode.MOTOROLA, 4), (Mode.INTEL, 8)])
def test_analog_io_moves_32_bits_with_one_block_transfer(cache: pytest.Cache, mode: Mode, block_bytes: int) -> None:
    """SET 85h (two words), ID 33h; 4-byte block transfer (3.4.6), byte 0 the MSB (3.4.8); Intel: four reads, then
    four writes (UP-11)."""
    bench, firmware = _bench(cache, "analog_io", mode)
    bench.run(3)
    entry = bench.master.config[0] if bench.master.config is not None else None
    assert entry is not None and (entry.id_code, entry.data_bytes) == (0x33, 4)
    bytes_before = bench.bytes_clocked
    for value in (0x0000_0000, 0xFFFF_FFFF, 0x1234_5678, 0x8000_0001):
        bench.master.set_outputs(1, value.to_bytes(4, "big"))
        _set_inputs(firmware, (value ^ 0xFFFF_FFFF).to_bytes(4, "big"))
        bench.run(3)  # the round trip back to back (FW-19)
        assert _outputs(firmware, 4) == value.to_bytes(4, "big")
        assert bench.master.inputs(1) == (value ^ 0xFFFF_FFFF).to_bytes(4, "big")
    # per data cycle: /IRQ service (2 bytes) + block transfer (command + its data bytes), no single accesses; four
    # steps of three data cycles (MCU-55, FW-19: exactly the run's cycles; before, two a step)
    assert bench.bytes_clocked - bytes_before == (2 + 1 + block_bytes) * 12


@pytest.mark.parametrize("mode", MODES)
def test_irq_dispatch_sends_its_inputs_in_the_first_data_cycle(cache: pytest.Cache, mode: Mode) -> None:
    """The ID cycle event writes IN before any data cycle (Table 3-13), unlike a VALID-only firmware. The master
    leaves it the time: a cycle every 30 ms, the discovery ID cycle lasting 27 ms (back to back the first data cycle
    starts 1 µs after the ID cycle's end, before any service routine can write; before FW-15 the master started
    before the set-up, and the rediscovery after its configuration error gave the firmware its first ID cycle's
    event 27 ms ahead)."""
    bench, firmware = _bench(cache, "irq_dispatch", mode, cycle_time_s=30e-3)
    _set_inputs(firmware, b"\x5a\xa5")
    while not any(r.cycle.name == "DATA" and r.ok for r in bench.results):
        bench.run(1)
    assert bench.master.inputs(1) == b"\x5a\xa5"
    bench.master.set_outputs(1, b"\x0f\xf0")
    bench.run(2)
    assert _outputs(firmware, 2) == b"\x0f\xf0"
    assert firmware.board.error == 0


def test_digital_io_without_id_cycle_handler_sends_zeros_first(cache: pytest.Cache) -> None:
    """The counterpart of the test above: digital_io writes IN only after the first VALID event."""
    bench, firmware = _bench(cache, "digital_io")
    _set_inputs(firmware, b"\x5a\xa5")
    while not any(r.cycle.name == "DATA" and r.ok for r in bench.results):
        bench.run(1)
    assert bench.master.inputs(1) == b"\x00\x00"


@pytest.mark.parametrize("mode", MODES)
def test_polling_io_exchanges_every_cycle_without_interrupts(cache: pytest.Cache, mode: Mode) -> None:
    """3.4.14 polling: the 1 -> 0 edge of the I/O access bit, then four accesses inside the 30-bit window."""
    bench, firmware = _bench(cache, "polling_io", mode)
    bench.run(5)  # each run ends once a main-loop pass after its last cycle has seen that fall (FW-14)
    served = firmware.board.cycles
    bench.master.set_outputs(1, b"\xbe\xef")
    _set_inputs(firmware, b"\xca\xfe")
    bench.run(10)
    assert bench.interrupts == 0
    assert all(r.cycle.name == "DATA" for r in list(bench.results)[-10:])
    assert firmware.board.cycles - served == 10  # every data cycle seen and served once
    assert _outputs(firmware, 2) == b"\xbe\xef"
    assert bench.master.inputs(1) == b"\xca\xfe"
    # the window the manual guarantees holds the 8 bytes (30 bit periods, 3.4.14)
    assert 8 * upif_byte_s(bench.config.bit_rate) < 30 / bench.config.bit_rate


def test_latch_phase_bug_in_c_firmware_is_caught(cache: pytest.Cache) -> None:
    """tests/c/firmware/latch_bug.c reads OUT 230 µs after the I/O bit fell: in the next latch phase."""
    firmware = c_firmware(cache, TEST_FIRMWARE / "latch_bug.c")
    bench = Bench(firmware=firmware)
    with pytest.raises(InconsistentDataError, match=r"OUT[01] read during the latch phase") as caught:
        bench.run(20)
    assert caught.value.__notes__[-1] in (
        "in fw_loop(): command 80h (read OUT0), data byte (sent 00h)",
        "in fw_loop(): command 81h (read OUT1), data byte (sent 00h)",
    )


def _peripheral_faults(bench: Bench) -> int:
    return sum(d.kind is ErrorKind.PERIPHERAL_FAULT for d in bench.master.diagnostics)


def test_fault_report_trips_until_quit_peripheral_error(cache: pytest.Cache) -> None:
    """3.6.2: /StatErr low for the filter time -> 0BB1h at the master; the outputs stay off until the master's
    Quit Peripheral Error (/ModAck pulse) comes after the fault has gone; the chip's fault clears with it."""
    bench, firmware = _bench(cache, "fault_report", cycle_time_s=1e-3)
    bench.run(3)
    bench.master.set_outputs(1, b"\x81\x18")
    bench.run_for(0.02)
    assert _outputs(firmware, 2) == b"\x81\x18"
    firmware.board.fault = 1
    bench.run_for(0.3)  # > t3 = 200 ms + 31.5 %
    assert bench.chip.module_error and bench.chip.pf
    assert _peripheral_faults(bench) == 1
    assert _outputs(firmware, 2) == b"\x00\x00"
    bench.master.quit_peripheral_error(1)  # while the fault lasts: nothing changes
    bench.run_for(0.01)
    assert bench.chip.pf and _outputs(firmware, 2) == b"\x00\x00"
    firmware.board.fault = 0  # gone by itself: /StatErr released, the outputs stay off, the chip keeps PF
    bench.run_for(0.01)
    assert not bench.chip.module_error
    assert bench.chip.pf and _outputs(firmware, 2) == b"\x00\x00"
    bench.master.quit_peripheral_error(1)
    bench.run_for(0.01)
    assert not bench.chip.pf
    assert _outputs(firmware, 2) == b"\x81\x18"
    assert _peripheral_faults(bench) == 1
    assert firmware.board.error == 0


@pytest.mark.parametrize(("command", "alarm"), [(0x01, 0x12), (0x55, 0xFF), (0x00, 0xFF), (0xFF, 0xFF)])
def test_pcmd_alarm_answers_the_masters_command(cache: pytest.Cache, command: int, alarm: int) -> None:
    """3.4.9: the processor command raises PCMD (Table 3-13); the answer goes to the processor alarm register."""
    bench, firmware = _bench(cache, "pcmd_alarm")
    bench.run(3)
    bench.master.processor_command(1, command)
    bench.run(2)
    assert firmware.board.command == command
    bench.master.request_processor_alarm(1)
    bench.run(3)
    assert bench.master.processor_alarms == {1: alarm}


def test_pcmd_alarm_reports_its_data_cycles(cache: pytest.Cache) -> None:
    bench, firmware = _bench(cache, "pcmd_alarm")
    bench.run(10)
    bench.master.processor_command(1, 0x02)
    bench.run(1)  # the command goes out with the run's first cycle, answered after it (FW-19: no cycle under way
    cycles = firmware.board.cycles  # between runs; before, the first cycle of run(2) had started before the command)
    bench.master.request_processor_alarm(1)
    bench.run(3)
    assert bench.master.processor_alarms == {1: cycles & 0xFF}
    assert cycles > 0


def test_the_guides_example_runs_as_written(cache: pytest.Cache, monkeypatch: pytest.MonkeyPatch) -> None:
    """The first Python block of docs/sdk-firmware-c.md."""
    if (reason := native.toolchain_missing()) is not None:
        pytest.skip(reason)
    guide = (Path(__file__).resolve().parents[1] / "docs" / "sdk-firmware-c.md").read_text(encoding="utf-8")
    code = guide.split("```python\n", 1)[1].split("```", 1)[0]
    monkeypatch.setenv(native.CACHE_ENV, str(cache.mkdir("supi3-native")))
    exec(compile(code, "docs/sdk-firmware-c.md", "exec"), {})

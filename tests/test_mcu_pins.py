"""The pin-level whole chip on the emulated board (supi3.mcu.pins, ``Board(..., fidelity="pin")``): SPI1's edges
from its baud-rate divider (RM0008 25.3.3, MCU-8, MCU-16), the example firmware's process data on both fidelities,
Table 3-7 and 3.4.2 violations found by the chip's own checks and reported with the firmware's program counter,
function and source line, and the VCD of the chip's pins and the MCU's lines.
"""

from __future__ import annotations

import itertools
import re
from pathlib import Path

import numpy as np
import pytest

from supi3.config import decode
from supi3.errors import ArgumentError
from supi3.interbus.device import PlainDevice
from supi3.interbus.ring import ErrorKind
from supi3.mcu import board as mcu_board
from supi3.mcu import build as mcu_build
from supi3.mcu import pins as mcu_pins
from supi3.mcu.board import Board, BoardError
from supi3.mcu.core import CPUS
from supi3.mcu.pins import MISO_PULL_UP, Cause, LockstepRing, mcu_lines
from supi3.mcu.session import RING_DEVICE, RING_DEVICE_STRAPS, run_firmware
from supi3.mcu.stm32 import CR1_CPHA, CR1_CPOL, CR1_LSBFIRST
from supi3.model.chip import Supi3
from supi3.model.pins import Supi3Pins
from supi3.model.registers import InterfaceViolationError
from supi3.sdk import native
from supi3.sdk.bench import default_config
from supi3.spi.upif import Mode
from supi3.tables import clk_conf_for
from supi3.top import Supi3Chip

pytestmark = pytest.mark.skipif(mcu_build.toolchain_missing() is not None, reason=str(mcu_build.toolchain_missing()))

WORDS = tuple(w.to_bytes(2, "big") for w in (0x1234, 0x8001))


@pytest.fixture(scope="module")
def digital_io(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The digital 16/16 example for the Cortex-M3, built once per module."""
    return mcu_build.build(native.example("digital_io"), tmp_path_factory.mktemp("pins") / "digital_io.elf")


def _falls(trace: np.ndarray) -> list[int]:
    return (np.flatnonzero(np.diff(trace) < 0) + 1).tolist()


def _rises(trace: np.ndarray) -> list[int]:
    return (np.flatnonzero(np.diff(trace) > 0) + 1).tolist()


@pytest.mark.parametrize(("cpol", "cpha", "lsb"), list(itertools.product((0, 1), repeat=3)))
def test_spi1_edges_follow_its_baud_rate_divider(cpol: int, cpha: int, lsb: int) -> None:
    """One transfer of A6h, 64 core clocks a period (BR = 5 at 48 MHz), from core cycle 960: SCLK's leading edge of
    bit k half a period after 960 + 64 k, its trailing edge at 960 + 64 (k + 1), each at the chip clock after it
    (32 MHz: 2/3 of a core clock); MOSI carries bit k from its leading edge (CPHA = 1) or half a period before it;
    the chip drives no SerOUT while /SS is high, so SPI1 receives the pull-up's FFh (MCU-6)."""
    ring = LockstepRing(Supi3Chip(default_config()), 48e6, lambda: Cause(0, None, ()), record=True)
    cr1 = CR1_CPOL * cpol | CR1_CPHA * cpha | CR1_LSBFIRST * lsb
    received = ring.spi_byte(0xA6, 8, 960, 64, cr1)
    assert received() == 0xFF * MISO_PULL_UP
    ring.sync(ring.clock_of(960 + 64 * 9))
    lines = mcu_lines(ring.recorded()[0])
    leads = [ring.clock_of(960 + 64 * k + 32) for k in range(8)]
    trails = [ring.clock_of(960 + 64 * (k + 1)) for k in range(8)]
    sck = lines["pa5_sck"]
    if cpol:
        assert (_falls(sck), _rises(sck)) == (leads, trails)
    else:  # the board rests SCLK high (UP-5) until SPI1 drives its CPOL at the transfer's start
        assert (_falls(sck), _rises(sck)) == ([ring.clock_of(960), *trails], leads)
    sampled = [int(lines["pa7_mosi"][c]) for c in (trails if cpha else leads)]
    assert sampled == [(0xA6 >> (k if lsb else 7 - k)) & 1 for k in range(8)]


def _exchange(board: Board) -> list[tuple[bytes, bytes]]:
    """Per word: the master's outputs and the firmware's inputs set, two cycles run; (the firmware's outputs, the
    master's inputs) after them (as tests/test_mcu_board.py)."""
    fw = board.fw_board
    assert fw is not None
    seen = []
    for out_data, in_data in zip(WORDS, reversed(WORDS), strict=True):
        board.master.set_outputs(1, out_data)
        fw.inputs = in_data
        board.run(2)
        seen.append((fw.outputs[:2], board.master.inputs(1)))
    return seen


@pytest.mark.slow
@pytest.mark.parametrize("mode", list(Mode))
def test_digital_io_gives_the_same_process_data_on_both_fidelities(
    digital_io: Path, tmp_path: Path, mode: Mode
) -> None:
    """A master cycle every 400 µs at 500 kbit/s (the handler's four accesses end before the next cycle begins,
    MCU-17): the pin-level chip, its µP pins driven by SPI1 and the GPIO port in lockstep with the core, gives the
    master's configuration and the process data of the transaction-level run, breaks no Table 3-7 rule, and a
    sleeping core enters the handler the 12 cycles of its exception entry after the falling edge of /IRQ on MFP3
    (MCU-2, MCU-14). The same on the Intel board (MCU-18: S/R from PB0, Ser_IN/OUT half duplex, LSB first; at pin
    level the chip checks t10/t11 on S/R too) with the example built for it."""
    elf = digital_io if mode is Mode.MOTOROLA else mcu_build.build(
        native.example("digital_io"), tmp_path / "intel.elf", defines={"FW_MODE": "SUPI3_MODE_INTEL"})
    seen = {}
    for fidelity in ("transaction", "pin"):
        board = Board(elf, cycle_time_s=400e-6, fidelity=fidelity, mode=mode)
        board.run(3)
        config = board.master.config
        assert config is not None and (config[0].id_code, config[0].data_bytes) == (0x03, 2)
        seen[fidelity] = _exchange(board)
        assert board.violations == [] and board.fw_board is not None and board.fw_board.error == 0
        assert board.protocol.mode is mode
        assert board.irq_latency_s == pytest.approx(CPUS["cortex_m3"].entry_cycles / 48e6)
    assert seen["pin"] == seen["transaction"] == list(zip(WORDS, reversed(WORDS), strict=True))


def test_the_intel_block_transfer_gives_the_same_process_data_on_both_fidelities(tmp_path: Path) -> None:
    """analog_io (the 4-byte block transfer, 3.4.6) built for the Intel interface on the Intel board (MCU-18): the
    pin-level chip, S/R from PB0 on MFP7 and Ser_IN/OUT half duplex, gives the process data of the transaction-level
    run (which is the Intel host build's, tests/test_mcu_board.py), with no Table 3-7 rule broken (t10/t11 on S/R
    included). A master cycle every 1 ms: the Intel handler clocks more frames than the Motorola one (about 145 µs
    against 85 µs at 500 kbit/s), and with a cycle every 400 µs it ends after the next data frame began, so the
    pin-level chip, which loads IN when a frame begins, sends its IN data a cycle later (docs/model.md M10, MCU-17)."""
    elf = mcu_build.build(native.example("analog_io"), tmp_path / "analog_intel.elf",
                          defines={"FW_MODE": "SUPI3_MODE_INTEL"})  # fmt: skip
    words = (bytes(range(1, 5)), bytes(range(0xF0, 0xF4)))
    seen = {}
    for fidelity in ("transaction", "pin"):
        board = Board(elf, cycle_time_s=1e-3, fidelity=fidelity, mode=Mode.INTEL)
        board.run(3)
        fw = board.fw_board
        assert fw is not None
        steps = []
        for out_data, in_data in zip(words, reversed(words), strict=True):
            board.master.set_outputs(1, out_data)
            fw.inputs = in_data
            board.run(2)
            steps.append((fw.outputs, board.master.inputs(1)))
        seen[fidelity] = steps
        assert board.violations == [] and fw.error == 0 and board.protocol.mode is Mode.INTEL
    assert seen["pin"] == seen["transaction"] == list(zip(words, reversed(words), strict=True))


def test_run_for_gives_the_transaction_levels_cycles_time_and_data(digital_io: Path) -> None:
    """``run_for`` at pin level (MCU-22): with a master cycle every 400 µs, 1.6 ms and then 0.8 ms of bus time run
    the cycles that start in them and idle the line to the end, as at transaction level: the same bus time (to
    half a status telegram, 5 µs at 500 kbit/s; the line's telegrams do not drift from the cycle time's schedule),
    the same master cycles, EXTI0 handler entries and data cycles of the firmware, and the same process data; a
    zero time runs nothing. A cycle running past the end ends the call at its end: the pin-level master cannot stop
    inside a cycle."""
    seen = {}
    for fidelity in ("transaction", "pin"):
        board = Board(digital_io, cycle_time_s=400e-6, fidelity=fidelity)
        board.run(3)
        fw = board.fw_board
        assert fw is not None
        steps = []
        words = zip(WORDS, reversed(WORDS), strict=True)
        for seconds, (out_data, in_data) in zip((1.6e-3, 0.8e-3), words, strict=True):
            board.master.set_outputs(1, out_data)
            fw.inputs = in_data
            before = (board.now, board.cycles, board.interrupts, fw.cycles)
            board.run_for(seconds)
            assert board.now - before[0] == pytest.approx(seconds, abs=5e-6)
            steps.append((board.cycles - before[1], board.interrupts - before[2], fw.cycles - before[3],
                          fw.outputs, board.master.inputs(1)))  # fmt: skip
        after = (board.now, board.cycles, board.core.instructions)
        board.run_for(0.0)
        assert (board.now, board.cycles, board.core.instructions) == after
        assert board.violations == [] and fw.error == 0
        seen[fidelity] = steps
    assert seen["pin"] == seen["transaction"]
    assert [step[:3] for step in seen["pin"]] == [(4, 4, 4), (2, 2, 2)]
    assert [step[3:] for step in seen["pin"]] == [(WORDS[0] + bytes(2), WORDS[1]), (WORDS[1] + bytes(2), WORDS[0])]
    board = Board(digital_io, cycle_time_s=400e-6, fidelity="pin")
    board.run(3)
    start = board.now
    board.run_for(50e-6)  # inside the next cycle: it runs whole (a data cycle of one device: 248 µs)
    assert (board.cycles, 240e-6 < board.now - start < 260e-6) == (4, True)


@pytest.mark.slow  # one device behind the chip: three times the chip's CPU time (MCU-23)
@pytest.mark.parametrize("mode", list(Mode))
def test_a_device_behind_the_chip_at_pin_level_gives_the_transaction_levels_ring(
    digital_io: Path, tmp_path: Path, mode: Mode
) -> None:
    """MCU-23: a pin-level SUPI 3 strapped RB 16 IN (session.RING_DEVICE_STRAPS: ID 02h, one word) behind the board's
    chip, each piece of the chip's lockstep run carried on through it and back: the master's configuration table and
    the process data both ways (the chip's, and the device's inputs at ring position 2) are those of the same ring
    at transaction level, with no violation; the VCD holds the second chip's pins (scope dev2). On the Motorola and
    the Intel board (MCU-18)."""
    config = decode(*RING_DEVICE_STRAPS, clk_conf=clk_conf_for(500_000))
    elf = digital_io if mode is Mode.MOTOROLA else mcu_build.build(
        native.example("digital_io"), tmp_path / "intel.elf", defines={"FW_MODE": "SUPI3_MODE_INTEL"})
    seen = {}
    for fidelity in ("transaction", "pin"):
        behind = Supi3Pins(config) if fidelity == "pin" else Supi3(config)
        board = Board(elf, cycle_time_s=600e-6, fidelity=fidelity, others=[behind], record=fidelity == "pin",
                      mode=mode)  # fmt: skip
        board.run(3)
        assert board.master.config is not None
        table = [(e.id_code, e.length_code) for e in board.master.config]
        board.master.set_outputs(1, WORDS[0])
        assert board.fw_board is not None
        board.fw_board.inputs = WORDS[1]
        if isinstance(behind, Supi3):
            behind.set_mfp_inputs(0xA55A)
        else:
            board.ring.set_input(2, "mfp_in", 0xA55A)
        board.run(2)
        assert board.violations == [] and board.protocol.mode is mode
        seen[fidelity] = (table, board.fw_board.outputs[:2], board.master.inputs(1), board.master.inputs(2))
    assert seen["pin"] == seen["transaction"] == ([(0x03, 0b00001), RING_DEVICE], WORDS[0], WORDS[1], b"\xa5\x5a")
    assert "$scope module dev2" in board.write_vcd(tmp_path / "ring.vcd").read_text()


def test_fault_report_trips_and_quits_at_pin_level_with_a_short_stat_err_filter(tmp_path: Path) -> None:
    """fault_report.c at pin level, the steps of tests/test_mcu_board.py's transaction-level test, with the chip's
    /StatErr filter shortened from 200 ms to 1 ms (``stat_err_filter``, MCU-24; the filter's logic is the chip's
    own, only its constant differs): PA8 drives /StatErr, the fault is latched once it has been low for the filter
    time and not before, 0BB1h reaches the master; the Quit Peripheral Error's /ModAck pulse (375 ns on the chip's
    pin, 3.6.2) sets EXTI line 1's pending bit, which the firmware reads: while the fault lasts nothing changes,
    after it went the chip clears PF and the firmware drives its outputs again."""
    elf = mcu_build.build(native.example("fault_report"), tmp_path / "fault_report.elf")
    board = Board(elf, fidelity="pin", stat_err_filter=32_000)  # 1 ms at 32 MHz
    fw, chip, master = board.fw_board, board.chip.chip, board.master
    assert fw is not None
    board.run(3)
    master.set_outputs(1, b"\x81\x18")
    board.run(3)
    assert fw.outputs[:2] == b"\x81\x18" and board.ring.inputs["stat_err_n"] == 1
    fw.fault = 1
    board.run_for(0.6e-3)  # /StatErr low since the first handler of these cycles: under the filter time
    assert not chip.module_error and not chip.pf and fw.outputs[:2] == b"\x00\x00"
    assert board.ring.inputs["stat_err_n"] == 0  # PA8 low on the chip's pin
    board.run_for(0.9e-3)
    assert chip.module_error and chip.pf and fw.outputs[:2] == b"\x00\x00"
    assert [d.kind for d in master.diagnostics] == [ErrorKind.PERIPHERAL_FAULT]
    acks = chip.events["MODACK"]
    master.quit_peripheral_error(1)  # while the fault lasts: nothing changes
    board.run(2)
    assert chip.events["MODACK"] == acks + 1 and chip.pf and fw.outputs[:2] == b"\x00\x00"
    fw.fault = 0
    board.run(2)
    assert not chip.module_error and chip.pf and fw.outputs[:2] == b"\x00\x00"
    master.quit_peripheral_error(1)
    board.run(3)
    assert not chip.pf and fw.outputs[:2] == b"\x81\x18"
    assert fw.error == 0 and board.violations == []


def test_a_too_fast_sclk_is_found_by_the_pin_level_chip_with_the_source_line(tmp_path: Path) -> None:
    """BOARD_SPI_BR = 3: a 16-clock SCLK period (333 ns, at the chip's 32 MHz 11 clocks) is shorter than Table 3-7's
    t0 = 667 ns at 500 kbit/s: the chip's own timing check finds it at the first byte's second rising edge, and the
    note names the transport function, its line and the calls (fw_setup, supi3_initialize); non-strict, every byte
    breaks t0 and nothing else. (The period measured between two chip clocks' samples depends on where the byte
    starts against the chip's clock: 343.75 ns before FW-21 moved supi3_initialize's instructions, 312.50 ns now.)"""
    elf = mcu_build.build(native.example("digital_io"), tmp_path / "fast.elf", defines={"BOARD_SPI_BR": "3u"})
    board = Board(elf, fidelity="pin")
    with pytest.raises(InterfaceViolationError, match=r"measured 312\.50 ns, required >= 667\.00 ns") as caught:
        board.run(1)
    assert caught.value.rule == "Table 3-7 t0"
    notes = caught.value.__notes__
    assert any("in board_xfer() board.c:" in note and "supi3_initialize()" in note for note in notes), notes
    lenient = Board(elf, fidelity="pin", strict=False)
    lenient.run(1)
    assert lenient.violations and {(v.error.rule, v.function) for v in lenient.violations} == {
        ("Table 3-7 t0", "board_xfer")}
    first = lenient.violations[0]
    assert first.source is not None and first.source.file == "board.c" and 0 < first.time_s < 20e-6


def test_raising_ss_before_the_byte_is_out_is_an_incomplete_frame_at_pin_level(tmp_path: Path) -> None:
    """tests/mcu/early_ss.c waits for TXE instead of BSY: /SS rises on MFP5 before SCLK's first rising edge, the
    chip's µP interface ignores the frame (3.4.2), and the violation names fw_setup and its line."""
    elf = mcu_build.build(Path(__file__).parent / "mcu" / "early_ss.c", tmp_path / "early_ss.elf")
    board = Board(elf, fidelity="pin")
    with pytest.raises(InterfaceViolationError, match=r"incomplete byte: 0 SCLK rising edges") as caught:
        board.run(1)
    assert caught.value.rule == "3.4.2"
    assert any("in fw_setup() early_ss.c:" in note for note in caught.value.__notes__)
    assert board.protocol.mode is None  # the initialization byte did not count


def test_the_vcd_holds_the_chip_pins_and_the_mcu_lines(digital_io: Path, tmp_path: Path) -> None:
    """``record=True``: :meth:`Board.write_vcd` writes scope dev1 (the chip's pins) and scope mcu (board.h's lines);
    each SPI1 transfer is one /SS frame of 8 SCLK periods, the same on the MCU's PA4/PA5 and the chip's MFP5/MFP4."""
    board = Board(digital_io, bit_rate=2_000_000, fidelity="pin", record=True)
    board.run(1)
    path = board.write_vcd(tmp_path / "run.vcd")
    text = path.read_text()
    for name in ("$scope module dev1", "$scope module mcu", "pa5_sck", "pa6_miso", "mfp4_sclk", "mfp5_ss_n"):
        assert name in text
    chip = board.ring.recorded()[0]
    lines = mcu_lines(chip)
    transfers = board.spi.transfers
    assert transfers > 3
    assert len(_falls(lines["pa4_ss_n"])) == len(_falls(chip["mfp_in"] >> 5 & 1)) == transfers
    assert len(_falls(lines["pa5_sck"])) == len(_falls(chip["mfp_in"] >> 4 & 1)) == 8 * transfers


def test_the_board_refuses_what_its_fidelity_has_not(digital_io: Path, tmp_path: Path) -> None:
    """Named errors: an unknown fidelity, other devices or a transaction-level bench at pin level, the pin-level ring,
    a record or a VCD at transaction level, and the session's VCD or ring without the pin level."""
    with pytest.raises(ArgumentError, match=r"fidelity must be one of 'transaction', 'pin', not 'gate'"):
        Board(digital_io, fidelity="gate")
    with pytest.raises(ArgumentError, match=r"others must be pin-level chips at pin level \(Supi3Pins"):
        Board(digital_io, fidelity="pin", others=[PlainDevice(0x02, 1)])
    with pytest.raises(ArgumentError, match=r"record must be False at transaction level"):
        Board(digital_io, record=True)
    with pytest.raises(BoardError, match=r"Board.bench is the transaction-level bench"):
        _ = Board(digital_io, fidelity="pin").bench
    with pytest.raises(BoardError, match=r"Board.write_vcd needs a board made with record=True"):
        Board(digital_io, fidelity="pin").write_vcd(tmp_path / "x.vcd")
    with pytest.raises(BoardError, match=r"Board.ring is the pin-level ring"):
        Board(digital_io).write_vcd(tmp_path / "x.vcd")
    with pytest.raises(ArgumentError, match=r"vcd must be None at transaction level"):
        run_firmware(digital_io, vcd=tmp_path / "x.vcd")
    with pytest.raises(ArgumentError, match=r"devices must be an integer from 1 to 4 \(at pin level, MCU-23"):
        run_firmware(digital_io, fidelity="pin", devices=5)
    assert not (tmp_path / "x.vcd").exists()


@pytest.mark.parametrize("fidelity", ["transaction", "pin"])
def test_sas_init_restarts_the_interface_and_keeps_the_registers(tmp_path: Path, fidelity: str) -> None:
    """tests/mcu/sas_init.c: SAS_INIT (PA3 on MFP0) after SET 83h, then the initialization byte again: the interface
    runs in Motorola mode again and SET still reads 83h (3.4.3), with no violation; on either fidelity."""
    elf = mcu_build.build(Path(__file__).parent / "mcu" / "sas_init.c", tmp_path / "sas_init.elf")
    board = Board(elf, bit_rate=2_000_000, fidelity=fidelity)
    board.run(1)
    assert board.fw_board is not None and (board.fw_board.error, board.fw_board.outputs[0]) == (0, 0x83)
    assert board.protocol.mode is not None and board.violations == []


@pytest.mark.parametrize("fidelity", ["transaction", "pin"])
def test_a_too_short_sas_init_pulse_names_the_line(tmp_path: Path, fidelity: str) -> None:
    """SAS_SHORT = 1: SAS_INIT high for two stores (about 40 ns) breaks Table 3-7's t_SAS_INIT on either fidelity,
    reported at the store that ends the pulse (pin level: the chip's own check, clock-exact)."""
    elf = mcu_build.build(Path(__file__).parent / "mcu" / "sas_init.c", tmp_path / "short.elf",
                          defines={"SAS_SHORT": "1u"})  # fmt: skip
    board = Board(elf, bit_rate=2_000_000, fidelity=fidelity, strict=False)
    board.run(1)
    rules = [(v.error.rule, v.function, v.source.file if v.source else None) for v in board.violations]
    assert rules == [("Table 3-7 t_SAS_INIT", "fw_setup", "sas_init.c")]


def test_the_intel_boards_s_r_pin_is_board_h_s() -> None:
    """The emulator's S/R wiring (MCU-18) is the board port's: PB0, board.h BOARD_PIN_SR."""
    text = (mcu_build.BOARD_DIR / "board.h").read_text()
    assert re.search(rf"#define BOARD_PIN_SR {mcu_board.PIN_SR}u /\* on port B", text)


def _pin_fingerprint(elf: Path) -> tuple[object, ...]:
    """Power-up and one data cycle at pin level, recorded: the core's cycles, instructions, interrupts and /IRQ
    latency, the violations (time, PC, rule), the firmware's outputs, the master's inputs, every chip pin."""
    board = Board(elf, fidelity="pin", strict=False, record=True)
    board.run(3)
    assert board.fw_board is not None
    traces = board.ring.recorded()[0]
    return (board.core.cycles, board.core.instructions, board.interrupts, board.irq_latency_s,
            [(v.time_s, v.pc, v.error.rule) for v in board.violations], board.fw_board.outputs,
            board.master.inputs(1), {name: trace.tolist() for name, trace in traces.items()})  # fmt: skip


@pytest.mark.slow
def test_the_look_ahead_to_an_edge_changes_nothing(digital_io: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """MCU-21: a sleeping core's wait for /IRQ run to the edge in one piece (found on a copy of the chip) gives the
    same core, violations, process data and chip pins, clock for clock, as the chip stepped clock by clock."""
    ahead = _pin_fingerprint(digital_io)
    monkeypatch.setattr(mcu_pins, "LOOK_AHEAD_FROM", 1 << 62)
    assert _pin_fingerprint(digital_io) == ahead

"""One run of a firmware binary on the default bench, and its report: what ``supi3 firmware run`` prints.

The run (:func:`run_firmware`): the ELF on the emulated board (:class:`supi3.mcu.board.Board`, non-strict, so that
every interface violation is kept), power-up and the ID cycle, then the master's OUT data and the firmware's input
terminals set and the remaining cycles run. The report (:class:`FirmwareRun`) holds the master's configuration
table, the process data both ways, the interrupts and their latency, every violation with its bus time, program
counter, function and source line, and, if the firmware faulted, hung or used up its budget, the core's report.
With ``fidelity="pin"`` the chip is the pin-level whole chip (:mod:`supi3.mcu.pins`), and ``vcd`` writes its pins
and the MCU's lines. Guide: docs/firmware-in-the-loop.md.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from os import PathLike
from pathlib import Path
from typing import Final

from supi3 import tables, timing
from supi3.checks import check_bytes, check_choice, check_int, fail
from supi3.config import decode
from supi3.errors import ArgumentError, Supi3Error
from supi3.interbus.device import PlainDevice
from supi3.interbus.link import Device
from supi3.interbus.master import ConfigEntry
from supi3.mcu.board import DEFAULT_MAX_INSTRUCTIONS, FIDELITIES, Board, ViolationAt
from supi3.mcu.core import FirmwareError, StopReport
from supi3.model.pins import Supi3Pins
from supi3.sdk.bench import DEFAULT_STRAPS, SERVE_TELEGRAMS
from supi3.spi.upif import Mode

__all__ = ["DEFAULT_CYCLES", "MAX_PIN_DEVICES", "MIN_CYCLES", "MIN_CYCLES_LIMIT", "POWER_UP_CYCLES", "RING_DEVICE",
           "RING_DEVICE_STRAPS", "FirmwareRun", "run_firmware"]

DEFAULT_CYCLES: Final[int] = 10
"""Master cycles a run has unless told (ID cycles included)."""
POWER_UP_CYCLES: Final[int] = 3
"""Cycles before the process data is set: the firmware's set-up, the ID cycle, the first data cycle."""
MIN_CYCLES: Final[int] = POWER_UP_CYCLES + 3
"""The fewest cycles of a run whose exchange is checked (MCU-45's master start): after the power-up one data cycle
carries the master's OUT data to the chip and the firmware's handler answers with its inputs, one latches them, one
brings them to the master. Both fidelities need all three since MCU-55 (before, the transaction level needed two,
its master having started the third in the run's wait); measured: ``digital_io`` and ``polling_io`` on the
Cortex-M3 and M0 at 500 kbit/s, 1 and 3 devices, exchange their data from 6 cycles at both fidelities; with fewer
every firmware reports MISMATCH."""
MIN_CYCLES_LIMIT: Final[str] = (f"the power-up's {POWER_UP_CYCLES} and {MIN_CYCLES - POWER_UP_CYCLES} to check the "
                                 "exchange")
"""Why :data:`MIN_CYCLES`, as an error about a run's cycles says it."""
RING_DEVICE: Final[tuple[int, int]] = (0x02, 0b00001)
"""ID code and length code of each further device in the ring, behind the chip: a plain digital output module of
one word (Table A-3, Table 3-11)."""
RING_DEVICE_STRAPS: Final[tuple[str, str | None]] = ("10001", None)
"""MCU-23: at pin level each further device is a pin-level SUPI 3 (:class:`~supi3.model.pins.Supi3Pins`) strapped RB,
16 IN (Table 2-6): the ID code and length code of :data:`RING_DEVICE`, so the master sees the same ring."""
MAX_PIN_DEVICES: Final[int] = 4
"""MCU-23: the longest ring at pin level (the chip and three devices behind it): each further chip runs every piece
of the board's chip, so each costs about as much CPU time again."""


@dataclass
class FirmwareRun:
    """What a run showed. ``stop`` is set if the firmware faulted, hung or used up its instruction budget (the run
    ended there); ``error`` if the bench itself refused to go on."""

    firmware: Path
    cpu: str
    cpu_hz: float
    straps: tuple[str, str | None]
    bit_rate: int
    devices: int
    cycles: int
    config: tuple[ConfigEntry, ...] | None = None
    sent_out: bytes = b""
    firmware_outputs: bytes | None = None
    firmware_inputs: bytes = b""
    master_inputs: bytes | None = None
    interrupts: int = 0
    irq_latency_s: float = 0.0
    access_time_s: float | None = None
    """T = 13 (5 + n) t_Bit, the time the manual leaves the firmware after /IRQ for n data bytes in the whole ring
    (3.4.14); ``None`` without a configuration."""
    instructions: int = 0
    core_cycles: int = 0
    bus_time_s: float = 0.0
    wall_s: float = 0.0
    violations: list[ViolationAt] = field(default_factory=list)
    stop: StopReport | None = None
    error: str | None = None
    fidelity: str = "transaction"
    mode: Mode = Mode.MOTOROLA
    """The board's wiring: the interface type the firmware initializes (MCU-18)."""
    vcd: Path | None = None
    """The VCD file written (pin level only)."""
    served: bool = True
    """The last run ended with the firmware's work served (:attr:`Board.served`, MCU-30): ``False`` if its main loop
    did not come back within the serve wait, or the run stopped."""

    @property
    def data_ok(self) -> bool:
        """Both ways the data arrived: the firmware's outputs are the master's OUT, the master's IN the firmware's
        inputs (``False`` if the firmware has no ``fw_board`` or the chip has no data)."""
        n = len(self.sent_out)
        return bool(n) and self.firmware_outputs is not None and self.firmware_outputs[:n] == self.sent_out \
            and self.master_inputs == self.firmware_inputs[:n]  # fmt: skip

    @property
    def failed(self) -> bool:
        """The run did not end cleanly: a stop, a bench error, a violation, data that did not arrive, or a main loop
        that did not serve the last cycle (MCU-30)."""
        return self.stop is not None or self.error is not None or bool(self.violations) or not self.data_ok \
            or not self.served  # fmt: skip

    def as_dict(self) -> dict[str, object]:
        """The report as JSON data."""
        return {
            "firmware": str(self.firmware), "cpu": self.cpu, "cpu_hz": self.cpu_hz,
            "straps": {"c": self.straps[0], "mfp": self.straps[1]}, "bit_rate": self.bit_rate,
            "devices": self.devices, "cycles": self.cycles,
            "configuration": [{"ring_position": e.ring_position, "number": e.number, "id_code": e.id_code,
                               "length_code": e.length_code, "data_bytes": e.data_bytes,
                               "interface": e.interface.value} for e in self.config or ()],
            "process_data": {"master_out": self.sent_out.hex(), "firmware_outputs": _hex(self.firmware_outputs),
                             "firmware_inputs": self.firmware_inputs.hex(), "master_in": _hex(self.master_inputs),
                             "ok": self.data_ok},
            "interrupts": self.interrupts, "irq_latency_s": self.irq_latency_s, "access_time_s": self.access_time_s,
            "instructions": self.instructions, "core_cycles": self.core_cycles, "bus_time_s": self.bus_time_s,
            "wall_s": self.wall_s,
            "violations": [{"time_s": v.time_s, "pc": v.pc, "function": v.function,
                            "source": None if v.source is None else str(v.source), "rule": v.error.rule,
                            "message": str(v.error), "place": v.place} for v in self.violations],
            "stop": None if self.stop is None else {"stop": self.stop.stop.value, "reason": self.stop.reason,
                                                    "pc": self.stop.pc, "text": str(self.stop)},
            "error": self.error, "fidelity": self.fidelity,
            "mode": self.mode.value, "vcd": None if self.vcd is None else str(self.vcd), "served": self.served,
        }  # fmt: skip

    def __str__(self) -> str:
        mhz = self.cpu_hz / 1e6
        lines = [f"firmware    {self.firmware.name} on {self.cpu} at {mhz:g} MHz",
                 f"chip        C[4..0] = {self.straps[0]}, MFP[15..12] = {self.straps[1] or '-'}, "
                 f"{self.bit_rate / 1000:g} kbit/s, ring of {self.devices} device(s), {self.cycles} cycles, "
                 f"{self.fidelity} level, {self.mode.value} board",
                 "configuration table (the master's ID cycle):"]  # fmt: skip
        if self.config:
            lines.append(f"  {'pos':>3}  {'number':6}  {'ID':>3}  {'length':6}  {'bytes':>5}  interface")
            lines += [f"  {e.ring_position:>3}  {e.number:6}  {e.id_code:02X}h  {e.length_code:05b}   "
                      f"{e.data_bytes:>5}  {e.interface.value}" for e in self.config]  # fmt: skip
        else:
            lines.append("  none: the master has read no configuration")
        ok = "ok" if self.data_ok else "MISMATCH"
        lines += ["process data (ring position 1, the chip):",
                  f"  master OUT {_spaced(self.sent_out)} -> firmware outputs {_spaced(self.firmware_outputs)}",
                  f"  firmware inputs {_spaced(self.firmware_inputs)} -> master IN {_spaced(self.master_inputs)}  {ok}",
                  f"interrupts  {self.interrupts} EXTI0 handler entries, longest /IRQ latency "
                  f"{self.irq_latency_s * 1e9:.0f} ns ({round(self.irq_latency_s * self.cpu_hz)} core cycles)"
                  + ("" if self.access_time_s is None else f" of the {self.access_time_s * 1e6:g} µs the manual "
                     "leaves the firmware after /IRQ (T = 13 (5 + n) t_Bit, 3.4.14)"),
                  f"run         {self.bus_time_s * 1e3:.3f} ms of bus time, {self.instructions} instructions, "
                  f"{self.core_cycles} core cycles, {self.wall_s:.2f} s wall "
                  f"({self.bus_time_s / max(self.wall_s, 1e-9):.3g}x real time)"]  # fmt: skip
        if not self.served and self.stop is None and self.error is None:
            lines.append("UNSERVED    the firmware's main loop did not come back to fw_loop after the last cycle "
                         f"within {SERVE_TELEGRAMS} status telegrams (MCU-30)")  # fmt: skip
        lines.append(f"violations  {len(self.violations) or 'none'}")
        lines += [f"  {v.error.rule}: {v.error}\n    at {v.place}" for v in self.violations]
        if self.stop is not None:
            lines.append(f"STOPPED     {self.stop}")
        if self.error is not None:
            lines.append(f"STOPPED     the bench: {self.error}")
        if self.vcd is not None:
            lines.append(f"wrote       {self.vcd}")
        return "\n".join(lines)


def _hex(data: bytes | None) -> str | None:
    return None if data is None else data.hex()


def _spaced(data: bytes | None) -> str:
    return "-" if data is None else data.hex(" ") or "(none)"


def run_firmware(firmware: str | Path, *, cpu: str = "cortex_m3", cpu_hz: float = 48e6,
                 straps: tuple[str, str | None] = DEFAULT_STRAPS, bit_rate: int = 500_000, devices: int = 1,
                 cycles: int = DEFAULT_CYCLES, out_data: bytes | None = None, in_data: bytes | None = None,
                 max_instructions: int = DEFAULT_MAX_INSTRUCTIONS, fidelity: str = "transaction",
                 vcd: str | Path | None = None, mode: Mode = Mode.MOTOROLA) -> FirmwareRun:  # fmt: skip
    """Run ``firmware`` (an ELF for the board port) on the default bench and report (see the module docstring).

    ``straps``: C[4..0] and MFP[15..12] (``None``: unset) of the chip (CLK_CONF follows ``bit_rate``);
    ``devices``: the ring's length, the chip first and :data:`RING_DEVICE` modules behind it; ``cycles``: master
    cycles in all, at least :data:`MIN_CYCLES`; ``out_data``/``in_data``: the master's OUT data and the firmware's
    input terminals (default: a pattern as long as the chip's data), each exactly as long as the chip's data as the
    firmware configures it (MCU-49: checked when the master has read the configuration, after the power-up; not
    if it read none); ``max_instructions``: the budget of each of the two runs (power-up, exchange); ``fidelity``:
    the chip at transaction level or the pin-level whole chip (:data:`~supi3.mcu.board.FIDELITIES`; at pin level
    the devices behind it are pin-level chips strapped :data:`RING_DEVICE_STRAPS`, ``devices`` up to
    :data:`MAX_PIN_DEVICES`); ``vcd``: pin level only, the VCD file to write the chip's pins and the MCU's lines to
    (:meth:`Board.write_vcd`), also when the run stopped; ``mode``: the board's wiring
    for the interface type the firmware initializes (``Board``'s ``mode``, MCU-18).

    Bad arguments raise :class:`~supi3.errors.Supi3Error` subclasses (``firmware`` not a path: an
    :class:`~supi3.errors.ArgumentError` before anything runs; ``out_data`` or ``in_data`` of the wrong length
    after the power-up, MCU-49: :class:`~supi3.errors.ArgumentError`, no report, no VCD); what the firmware does wrong
    is in the report.
    ``OSError`` if the VCD file cannot be written.
    """
    if not isinstance(firmware, str | PathLike):  # the report names the file (a FirmwareImage raised TypeError there)
        raise fail("firmware", "a path of an ELF file (str or os.PathLike)", firmware)
    fidelity = check_choice("fidelity", fidelity, FIDELITIES)
    if vcd is not None and fidelity != "pin":
        raise fail("vcd", "None at transaction level (a VCD holds pins: fidelity='pin')", vcd)
    pin = fidelity == "pin"
    devices = check_int("devices", devices, 1, MAX_PIN_DEVICES if pin else 64, "at pin level, MCU-23" if pin else "")
    cycles = check_int("cycles", cycles, MIN_CYCLES, 100_000, MIN_CYCLES_LIMIT)
    max_instructions = check_int("max_instructions", max_instructions, 1)
    out_data = None if out_data is None else check_bytes("out_data", out_data)
    in_data = None if in_data is None else check_bytes("in_data", in_data)
    if not isinstance(straps, tuple) or len(straps) != 2:
        raise fail("straps", "a pair (C[4..0], MFP[15..12] or None)", straps)
    clk_conf = tables.clk_conf_for(bit_rate)
    config = decode(straps[0], straps[1], clk_conf=clk_conf)
    others: list[Device | Supi3Pins] = [
        Supi3Pins(decode(*RING_DEVICE_STRAPS, clk_conf=clk_conf)) if pin else PlainDevice(*RING_DEVICE)
        for _ in range(devices - 1)]  # fmt: skip
    board = Board(firmware, cpu=cpu, cpu_hz=cpu_hz, config=config, others=others, strict=False, fidelity=fidelity,
                  record=vcd is not None, mode=mode)  # fmt: skip
    report = FirmwareRun(Path(firmware), cpu, cpu_hz, straps, config.bit_rate, devices, cycles, fidelity=fidelity,
                         mode=mode)  # fmt: skip
    master = board.master
    started = time.perf_counter()
    if _run(board, report, POWER_UP_CYCLES, max_instructions):
        report.config = master.config
        entry = report.config[0] if report.config else None
        report.sent_out = _data("out_data", out_data, entry, bytes([0x12, 0x34, 0x56, 0x78] * 64))
        report.firmware_inputs = _data("in_data", in_data, entry, bytes([0xAB, 0xCD, 0xEF, 0x01] * 64))
        if report.sent_out:
            master.set_outputs(1, report.sent_out)
            if board.fw_board is not None:
                board.fw_board.inputs = report.firmware_inputs
        _run(board, report, cycles - POWER_UP_CYCLES, max_instructions)
    report.wall_s = time.perf_counter() - started
    report.served = board.served
    report.config = master.config
    if report.config:
        network_bytes = sum(entry.data_bytes for entry in report.config)
        report.access_time_s = timing.cpu_access_time_s(network_bytes, report.bit_rate)
    if report.sent_out and board.fw_board is not None:
        report.firmware_outputs = board.fw_board.outputs[: len(report.sent_out)]
    if report.sent_out:
        report.master_inputs = master.inputs(1)
    report.interrupts = board.interrupts
    report.irq_latency_s = board.irq_latency_s
    report.instructions = board.core.instructions
    report.core_cycles = board.core.cycles
    report.bus_time_s = board.now
    report.violations = list(board.violations)
    if vcd is not None:
        report.vcd = board.write_vcd(vcd)
    return report


def _run(board: Board, report: FirmwareRun, cycles: int, max_instructions: int) -> bool:
    """``board.run(cycles)``; a stop or a bench error goes into ``report``. Whether the run went on to the end."""
    try:
        board.run(cycles, max_instructions=max_instructions)
    except FirmwareError as error:
        report.stop = error.report
    except Supi3Error as error:  # the bench cannot go on (a stuck firmware, a chip refusing the straps' mode)
        report.error = str(error)
    else:
        return True
    return False


def _data(name: str, data: bytes | None, entry: ConfigEntry | None, default: bytes) -> bytes:
    """MCU-49: ``data`` checked against the chip's data length, which the master's ID cycle has read from the
    configuration the firmware wrote (``entry``; ``None``: no configuration, no data to send); ``None``: as much of
    ``default`` as the chip takes."""
    size = 0 if entry is None else entry.data_bytes
    if data is None:
        return default[:size]
    if entry is None or len(data) == size:
        return data[:size]
    shown = data[:8].hex(" ") + (" ..." if len(data) > 8 else "")
    raise ArgumentError(name, data, f"{name} must be {entry.data_bytes} byte{'s' * (entry.data_bytes != 1)}, the "
                        f"data of device {entry.number} (the chip) as the firmware configured it (ID code "
                        f"{entry.id_code:02X}h, length code {entry.length_code:05b}, Table 3-11; MCU-49), not "
                        f"{len(data)} byte{'s' * (len(data) != 1)} ({shown})")  # fmt: skip

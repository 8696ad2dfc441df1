"""Hostile inputs, orders and histories against the public entries no earlier round attacked (a user's review,
round 12): the software µP on the serial µP interface's pins (:mod:`supi3.spi.master`: ``SoftMaster``,
``MasterTiming`` (UP-45), ``SpiTrace``, ``decode_bytes``, ``write_spi_vcd``), the figures' WaveJSON
(:func:`supi3.spi.figures.to_wavejson`, :mod:`supi3.figures`), the RTL's LFSR counters (:mod:`supi3.rtl.lfsr`: a
negative count looped for ever), the RTL's strap tables (:mod:`supi3.rtl.tables`) and serial I/O schedules
(:func:`supi3.rtl.serial_io.schedule`), the serial I/O and register-expansion schedules (:mod:`supi3.serial_io`,
:mod:`supi3.expansion`), the timing expressions (:func:`supi3.timing.evaluate`), the pin-list helpers
(:mod:`supi3.pinlevel`, :mod:`supi3.pinout`, :mod:`supi3.config`), the timing checkers'
:func:`supi3.verif.timing.raise_first` and the lockstep's scoreboard :func:`supi3.verif.layout.first_mismatch`.

Every bad input is refused by name (which argument, which rule, which value) and changes nothing. Over any history of
bytes, deselects, SAS_INIT pulses, holds and refused calls, the bytes read back from the pins alone
(``decode_bytes``) are the bytes the software µP sent and received (UP-5, UP-6, UP-7); over any history of data
cycles, bit errors, INTERBUS resets, idle time and input changes, external registers on the expansion interface
hold the OUT data of the last valid data cycle (3.5, RX-4, RX-5); the scoreboard reports exactly the first
compared difference of any two traces and never accepts one that differs.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import numpy.typing as npt
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3 import expansion, serial_io, timing
from supi3.config import DataDirection, Variant, decode, decode_straps, mode_rows, parse_function
from supi3.errors import ArgumentError
from supi3.expansion import chain_to_line, line_to_chain
from supi3.figures import expansion_wavejson, serial_io_wavejson, write_figures
from supi3.interbus import wire
from supi3.interbus.master import Master
from supi3.interbus.ring import Ring
from supi3.mcu.pins import ss_high_byte
from supi3.model.blocks.expansion import overrun_gap_clocks
from supi3.model.chip import Supi3
from supi3.model.pins import Supi3Pins
from supi3.peripherals.sre import Sre1
from supi3.pinlevel import EventLog, Pin, PinSpecError
from supi3.pinout import up_input_port
from supi3.regmap import ID, SET
from supi3.rtl import lfsr
from supi3.rtl import serial_io as rtl_serial_io
from supi3.rtl import tables as rtl_tables
from supi3.sdk import bench
from supi3.spi.block_pins import block_model
from supi3.spi.figures import to_wavejson
from supi3.spi.master import MasterTiming, SoftMaster, SpiTrace, decode_bytes, write_spi_vcd
from supi3.spi.slave_pins import PinsIn
from supi3.spi.upif import Mode
from supi3.tables import BIT_RATES, clk_conf_for
from supi3.verif.example import ShiftCounterModel
from supi3.verif.layout import WordLayout, first_mismatch
from supi3.verif.straps import strap_stimulus
from supi3.verif.timing import raise_first

# ---------------------------------------------------------------------------------------------------------------
# The software µP (supi3.spi.master)
# ---------------------------------------------------------------------------------------------------------------


def _master(mode: Mode = Mode.MOTOROLA, rate: int = 2_000_000, **kwargs: object) -> SoftMaster:
    return SoftMaster(block_model(rate), mode, **kwargs)  # type: ignore[arg-type]


def _trace() -> SpiTrace:
    master = _master()
    master.byte(0x5A)
    master.deselect()
    return master.trace()


_FASTEST = MasterTiming.fastest(2_000_000)

BAD_MASTER: list[tuple[str, Callable[[], object], str]] = [
    # Before: 256 and -1 went out as their low eight bits (0x00, 0xFF), a float or None was a TypeError deep in the
    # bit loop, True was the byte 01h.
    ("byte 256", lambda: _master().byte(256), "mosi"),
    ("byte -1", lambda: _master().byte(-1), "mosi"),
    ("byte 1.5", lambda: _master().byte(1.5), "mosi"),  # type: ignore[arg-type]
    ("byte None", lambda: _master().byte(None), "mosi"),  # type: ignore[arg-type]
    ("byte True", lambda: _master().byte(True), "mosi"),
    ("byte s_r 0", lambda: _master(Mode.INTEL).byte(3, s_r=0), "s_r"),  # type: ignore[arg-type]
    # Before: a negative count ran nothing, a float a TypeError from range(), an unknown pin a TypeError from
    # dataclasses.replace.
    ("run -1", lambda: _master().run(-1), "cycles"),
    ("run 1.5", lambda: _master().run(1.5), "cycles"),  # type: ignore[arg-type]
    ("run unknown pin", lambda: _master().run(1, foo=1), "pin"),
    # Before: a str mode ("intel" == Mode.INTEL for a StrEnum) was taken, driven as Motorola, then failed with an
    # AttributeError at the first byte; None and a chip of another kind failed with AttributeErrors.
    ("mode str", lambda: SoftMaster(block_model(500_000), "intel"), "mode"),  # type: ignore[arg-type]
    ("mode None", lambda: SoftMaster(block_model(500_000), None), "mode"),  # type: ignore[arg-type]
    ("chip None", lambda: SoftMaster(None, Mode.INTEL), "chip"),  # type: ignore[arg-type]
    ("timing str", lambda: _master(timing="x"), "timing"),
    ("record 0", lambda: _master(record=0), "record"),
    ("deselect s_r str", lambda: _master(Mode.INTEL).deselect(s_r="no"), "s_r"),  # type: ignore[arg-type]
    # Before: zero or negative fields made timings that ran run(-1) (nothing) inside a byte, or no /SS high
    # between bytes (two bytes merged into one frame), floats ran into range(); aligned() divided by zero.
    ("timing zeros", lambda: MasterTiming(0, 0, 0, 0, 0), "low"),
    ("timing high 0", lambda: MasterTiming(4, 0, 1, 3, 4), "high"),
    ("timing gap 0", lambda: MasterTiming(4, 2, 1, 3, 0), "gap"),
    ("timing trail 0", lambda: MasterTiming(4, 2, 1, 0, 4), "trail"),
    ("timing lead -1", lambda: MasterTiming(4, 2, -1, 3, 4), "lead"),
    ("timing float", lambda: MasterTiming(1.5, 2, 3, 4, 5), "low"),  # type: ignore[arg-type]
    ("timing bool", lambda: MasterTiming(True, 2, 3, 4, 5), "low"),
    # Before: sclk_hz 0 was a ZeroDivisionError, NaN a ValueError, a str a TypeError; clock_hz 0 or negative gave
    # an all-zero timing silently.
    ("fastest sclk 0", lambda: MasterTiming.fastest(500_000, sclk_hz=0), "sclk_hz"),
    ("fastest sclk nan", lambda: MasterTiming.fastest(500_000, sclk_hz=float("nan")), "sclk_hz"),
    ("fastest sclk str", lambda: MasterTiming.fastest(500_000, sclk_hz="1e6"), "sclk_hz"),  # type: ignore[arg-type]
    ("fastest clock 0", lambda: MasterTiming.fastest(500_000, clock_hz=0), "clock_hz"),
    ("fastest clock -5", lambda: MasterTiming.fastest(500_000, clock_hz=-5), "clock_hz"),
    # Before: AttributeErrors and IndexErrors from inside.
    ("decode None", lambda: decode_bytes(None), "trace"),  # type: ignore[arg-type]
    ("decode list", lambda: decode_bytes([]), "trace"),  # type: ignore[arg-type]
    ("window str", lambda: _trace().window("a"), "start"),  # type: ignore[arg-type]
    ("window stop float", lambda: _trace().window(0, 2.0), "stop"),  # type: ignore[arg-type]
    ("mfp6_line past", lambda: _trace().mfp6_line(10**6), "k"),
    ("mfp7_line -1", lambda: _trace().mfp7_line(-1), "k"),
    # Before: a trace of lists of different lengths, or of a str mode, was made and failed later in decode_bytes
    # or write_spi_vcd with an IndexError or AttributeError.
    ("SpiTrace lengths", lambda: SpiTrace(Mode.INTEL, _FASTEST, 32_000_000, 2_000_000, inputs=[PinsIn()]),
     "outputs"),
    ("SpiTrace mode str", lambda: SpiTrace("intel", _FASTEST, 32_000_000, 2_000_000), "mode"),  # type: ignore[arg-type]
    ("SpiTrace clock 0", lambda: SpiTrace(Mode.INTEL, _FASTEST, 0, 2_000_000), "clock_hz"),
    ("vcd str path", lambda: write_spi_vcd("/tmp/never.vcd", _trace()), "path"),  # type: ignore[arg-type]
    ("vcd not a trace", lambda: write_spi_vcd(Path("never.vcd"), None), "trace"),  # type: ignore[arg-type]
    ("vcd empty trace", lambda: write_spi_vcd(Path("never.vcd"), _trace().window(0, 0)), "trace"),
]


@pytest.mark.parametrize(("call", "name"), [pytest.param(c, n, id=label) for label, c, n in BAD_MASTER])
def test_soft_master_refuses_by_name(call: Callable[[], object], name: str) -> None:
    """Each call used to send a wrong byte, run nothing, or fail deep inside (see the comments of BAD_MASTER)."""
    with pytest.raises(ArgumentError, match=rf"^{name}\b.* must be .*, not "):
        call()


def test_a_table_3_7_breaking_timing_is_still_allowed() -> None:
    """One clock less than Table 3-7 allows is a legal MasterTiming (the chip's checks are tested with it); only
    what is not a byte at all is refused (UP-45)."""
    timing = MasterTiming(low=1, high=1, lead=0, trail=1, gap=1)
    master = _master(timing=timing)
    master.byte(Mode.MOTOROLA.init_byte)
    master.deselect()
    assert [d.to_chip for d in decode_bytes(master.trace())] == [Mode.MOTOROLA.init_byte]


def test_refused_run_changes_no_pin() -> None:
    """Before: ``run(1.5, sclk=0)`` changed the held pins, then failed in range(): the next run drove SCLK low."""
    master = _master()
    master.run(3)
    with pytest.raises(ArgumentError, match="cycles"):
        master.run(1.5, sclk=0)  # type: ignore[arg-type]
    with pytest.raises(ArgumentError, match="pin"):
        master.run(1, sclk=0, foo=1)
    master.run(2)
    assert all(pins.sclk == 1 for pins in master.trace().inputs)
    assert len(master.trace()) == 5


def test_vcd_of_a_trace(tmp_path: Path) -> None:
    """The VCD writer still writes a recorded trace (the checks do not refuse good input)."""
    text = write_spi_vcd(tmp_path / "up.vcd", _trace()).read_text(encoding="ascii")
    assert "$scope module line $end" in text and "mosi_oe" in text


_OP = st.one_of(
    st.tuples(st.just("byte"), st.integers(0, 255), st.booleans()),
    st.tuples(st.just("deselect"), st.booleans(), st.booleans()),
    st.tuples(st.just("sas_init"), st.integers(1, 40), st.booleans()),
    st.tuples(st.just("hold"), st.integers(0, 30), st.booleans()),
    st.tuples(st.just("bad"), st.integers(0, 5), st.booleans()),
)

_BAD_CALLS: tuple[Callable[[SoftMaster], object], ...] = (
    lambda m: m.byte(256),
    lambda m: m.byte(-1),
    lambda m: m.run(-3),
    lambda m: m.run(2.5, ss_n=0),  # type: ignore[arg-type]
    lambda m: m.run(1, ss_n=0, nope=1),
    lambda m: m.deselect(s_r=1),  # type: ignore[arg-type]
)


@settings(max_examples=25, deadline=None)
@given(mode=st.sampled_from(Mode), rate=st.sampled_from(BIT_RATES), ops=st.lists(_OP, max_size=10))
def test_history_pins_decode_to_what_the_master_sent(mode: Mode, rate: int,
                                                     ops: list[tuple[str, int | bool, bool]]) -> None:
    """Over any history of bytes, deselects, SAS_INIT pulses, holds and refused calls (the chip initialized first,
    then commands and data at random), the pins decode (``decode_bytes``, from the trace alone) to one frame per
    byte, with eight SCLK rises, the byte the µP sent on its data line when it drove it and the chip did not, and
    the byte ``byte()`` returned; a refused call adds no cycle and leaves the held pins as they were."""
    master = _master(mode, rate)
    master.byte(mode.init_byte)
    sent: list[tuple[int, bool, int | None]] = [(mode.init_byte, True, None)]
    for kind, a, b in ops:
        if kind == "byte":
            assert isinstance(a, int)
            sent.append((a, b, master.byte(a, s_r=b)))
        elif kind == "deselect":
            master.deselect(s_r=b if a else None)
        elif kind == "sas_init":
            master.pulse_sas_init(int(a))
        elif kind == "hold":
            master.run(int(a))
        else:
            before = (len(master.trace()), master.cycle, master._pins)
            with pytest.raises(ArgumentError):
                _BAD_CALLS[int(a)](master)
            assert (len(master.trace()), master.cycle, master._pins) == before
    master.deselect()
    decoded = decode_bytes(master.trace())
    assert len(decoded) == len(sent)
    for frame, (mosi, s_r, received) in zip(decoded, sent, strict=True):
        assert frame.edges == 8
        if received is not None or frame.from_chip is not None:
            assert frame.from_chip == received
        drives = mode is Mode.MOTOROLA or s_r
        if drives and frame.from_chip is None:
            assert frame.to_chip == mosi
        if not drives:
            assert frame.to_chip is None


# ---------------------------------------------------------------------------------------------------------------
# The RTL's LFSR counters, strap tables and serial I/O schedules
# ---------------------------------------------------------------------------------------------------------------

BAD_RTL: list[tuple[str, Callable[[], object], str]] = [
    # Before: a negative step count looped for ever (steps >>= 1 stays -1).
    ("advance -1", lambda: lfsr.advance(1, 8, -1), "steps"),
    ("count_state -1", lambda: lfsr.count_state(-1, 8), "value"),
    # Before: past the period the state of a smaller count came back (a comparison fires early), silently.
    ("count_state past the period", lambda: lfsr.count_state(255, 8), "value"),
    ("count_state 1.5", lambda: lfsr.count_state(1.5, 8), "value"),  # type: ignore[arg-type]
    # Before: KeyError 1 / 99.
    ("step width 1", lambda: lfsr.step(1, 1), "width"),
    ("step width 99", lambda: lfsr.step(1, 99), "width"),
    ("step state too wide", lambda: lfsr.step(300, 8), "state"),
    ("count_width 1.5", lambda: lfsr.count_width(1.5), "most"),  # type: ignore[arg-type]
    ("before past", lambda: lfsr.before(255, 8), "steps"),
    ("down_state -3", lambda: lfsr.down_state(-3, 8), "value"),
    # Before: silently a position outside the register (-85, 23, -8).
    ("line_position past", lambda: rtl_tables.line_position(99, 2), "word_bit"),
    ("line_position -1", lambda: rtl_tables.line_position(-1, 2), "word_bit"),
    ("line_position n 0", lambda: rtl_tables.line_position(0, 0), "n"),
    # Before: AttributeErrors.
    ("mode_entry None", lambda: rtl_tables.mode_entry(None), "config"),  # type: ignore[arg-type]
    ("clock_entry clk 7", lambda: rtl_tables.clock_entry(7, None), "clk_conf"),  # type: ignore[arg-type]
    ("serial_mode str", lambda: rtl_tables.serial_mode("x"), "config"),  # type: ignore[arg-type]
    ("rbst_by_pin None", lambda: rtl_tables.rbst_by_pin(None), "config"),  # type: ignore[arg-type]
    ("complete_diagnostics 1", lambda: rtl_tables.complete_diagnostics(1), "config"),  # type: ignore[arg-type]
    # Before: kind -1 was the last direction's clear sequence (DIRECTIONS[-1]), 9 an IndexError, True kind 1.
    ("schedule -1", lambda: rtl_serial_io.schedule(-1, 16, 500_000), "kind"),
    ("schedule 9", lambda: rtl_serial_io.schedule(9, 16, 500_000), "kind"),
    ("schedule True", lambda: rtl_serial_io.schedule(True, 16, 500_000), "kind"),
]


@pytest.mark.parametrize(("call", "name"), [pytest.param(c, n, id=label) for label, c, n in BAD_RTL])
def test_rtl_builders_refuse_by_name(call: Callable[[], object], name: str) -> None:
    """Each call used to hang, wrap silently or fail deep inside (see the comments of BAD_RTL)."""
    with pytest.raises(ArgumentError, match=rf"^{name}\b.* must be .*, not "):
        call()


def test_lfsr_counts_within_the_period_stay_distinct() -> None:
    """Every count the checks let through has its own state (the checks refuse exactly where states repeat)."""
    width = 5
    states = [lfsr.count_state(v, width) for v in range((1 << width) - 1)]
    assert len(set(states)) == len(states)
    assert lfsr.advance(1, width, 0) == 1 and lfsr.down_state((1 << width) - 1, width) == lfsr.before(30, width)


def test_rtl_tables_take_a_config() -> None:
    """Good input still passes: the tables of every mode row are built as before, and every bit of a word has its
    own place in the register."""
    row = next(iter(mode_rows(Variant.OPC)))
    config = decode(row.c, row.mfp)
    assert rtl_tables.mode_entry(config).pattern.startswith(config.straps().c)
    assert rtl_tables.clock_entry(0, config).clocks_per_bit in expansion.CLOCKS_PER_BIT
    assert sorted(rtl_tables.line_position(w, 2) for w in range(16)) == list(range(16))


# ---------------------------------------------------------------------------------------------------------------
# Serial I/O and register expansion schedules, timing expressions, pin lists, raise_first
# ---------------------------------------------------------------------------------------------------------------

_FRAMES = serial_io.sequence(DataDirection.IN_OUT, 16, 500_000).frames
_LEVELS = ("clk_exr", "to_exr", "la_ou_d", "la_in_d_n", "res_reg_n")

BAD_SPEC: list[tuple[str, Callable[[], object], type[Exception], str]] = [
    # Before: a cpb with no bit rate behind it gave a schedule (5 clocks per bit: ClkExR high at 1..3).
    ("clock_high 5", lambda: expansion.clock_high(5), ArgumentError, "cpb"),
    ("end_pulses 7", lambda: expansion.end_pulses(True, 7), ArgumentError, "cpb"),
    # Before: a /Conv pulse ending before it starts, or a length shorter than the frames, was taken; a conv of
    # strings failed in levels() with a TypeError.
    ("conv reversed", lambda: serial_io.SerialSequence(_FRAMES, (5, 2), 10_000), ArgumentError, "conv"),
    ("conv strings", lambda: serial_io.SerialSequence(_FRAMES, ("a", "b"), 10_000), ArgumentError,  # type: ignore[arg-type]
     "conv"),
    ("conv past length", lambda: serial_io.SerialSequence(_FRAMES, (5, 20_000), 10_000), ArgumentError, "conv"),
    ("length short", lambda: serial_io.SerialSequence(_FRAMES, None, 1), ArgumentError, "length"),
    # Before: n_bytes -3 gave a negative time, t0_s NaN or -1 NaN and a negative time; "a|b|c" a ValueError from
    # unpacking.
    ("evaluate n -3", lambda: timing.evaluate("n", 500_000, n_bytes=-3), timing.TimingError, "n_bytes"),
    ("evaluate t0 nan", lambda: timing.evaluate("t0", 500_000, t0_s=float("nan")), ArgumentError, "t0_s"),
    ("evaluate t0 -1", lambda: timing.evaluate("t0", 500_000, t0_s=-1.0), ArgumentError, "t0_s"),
    ("evaluate a|b|c", lambda: timing.evaluate("1|2|3", 500_000), timing.TimingError, "alternatives"),
    # Before: AttributeError, a tristate of 1 taken, a TypeError from '<'.
    ("Pin name 5", lambda: Pin(5), PinSpecError, "pin name"),  # type: ignore[arg-type]
    ("Pin tristate 1", lambda: Pin("a", 1, 1), PinSpecError, "tristate"),  # type: ignore[arg-type]
    ("EventLog str", lambda: EventLog("a"), PinSpecError, "depth"),  # type: ignore[arg-type]
    # Before: a name not of the µP interface came back unchanged ("zz" -> "zz"); a bad variant or interface of
    # mode_rows raised only at the first row taken (a generator), as a bare ValueError of the enum; parse_function
    # of None a TypeError from re, decode_straps of None an AttributeError.
    ("up_input_port zz", lambda: up_input_port("zz"), ArgumentError, "name"),
    ("mode_rows variant", lambda: mode_rows("xx"), ArgumentError, "variant"),
    ("mode_rows interface", lambda: mode_rows("opc", "zz"), ArgumentError, "interface"),
    ("parse_function None", lambda: parse_function(None), ArgumentError, "function"),  # type: ignore[arg-type]
    ("parse_function xyz", lambda: parse_function("xyz"), ArgumentError, "function"),
    ("decode_straps None", lambda: decode_straps(None), ArgumentError, "straps"),  # type: ignore[arg-type]
    # Before: a TypeError from iterating None.
    ("raise_first None", lambda: raise_first(None), ArgumentError, "violations"),  # type: ignore[arg-type]
]


@pytest.mark.parametrize(("call", "error", "name"),
                         [pytest.param(c, e, n, id=label) for label, c, e, n in BAD_SPEC])
def test_schedules_and_helpers_refuse_by_name(call: Callable[[], object], error: type[Exception], name: str) -> None:
    """Each call used to give a silent wrong answer or fail deep inside (see the comments of BAD_SPEC)."""
    with pytest.raises(error, match=name):
        call()


def test_levels_store_numpy_levels_as_int() -> None:
    """Before: a numpy level passed the check and stayed a numpy integer in the frozen dataclass (``PinsIn``
    stores ``int``); now every level of ``Levels`` and ``ExpansionLevels`` is a plain int."""
    levels = serial_io.Levels(np.int64(1), 0, np.uint8(1), 0)  # type: ignore[arg-type]
    assert all(type(v) is int for v in vars(levels).values())
    exp = expansion.ExpansionLevels(*(np.int8(1) for _ in _LEVELS))  # type: ignore[arg-type]
    assert all(type(v) is int for v in vars(exp).values()) and exp == expansion.ExpansionLevels(1, 1, 1, 1, 1)


def test_evaluate_alternatives_follow_the_bit_rate() -> None:
    """'a | b' gives a at 500 kbit/s and b at 2 Mbit/s (unchanged), and a t0 given is used."""
    assert timing.evaluate("667 ns | 167 ns", 500_000) == pytest.approx(667e-9)
    assert timing.evaluate("667 ns | 167 ns", 2_000_000) == pytest.approx(167e-9)
    assert timing.evaluate("2 * t0", 500_000, t0_s=1e-6) == pytest.approx(2e-6)


# ---------------------------------------------------------------------------------------------------------------
# The figures' WaveJSON (supi3.spi.figures, supi3.figures)
# ---------------------------------------------------------------------------------------------------------------

BAD_FIGURES: list[tuple[str, Callable[[], object], str]] = [
    # Before: step 0 silently meant the default, a negative step drew a figure of no column, 1.5 a TypeError from
    # range(); a trace of another kind an AttributeError.
    ("to_wavejson step 0", lambda: to_wavejson(_trace(), "t", step=0), "step"),
    ("to_wavejson step -2", lambda: to_wavejson(_trace(), "t", step=-2), "step"),
    ("to_wavejson step 1.5", lambda: to_wavejson(_trace(), "t", step=1.5), "step"),  # type: ignore[arg-type]
    ("to_wavejson trace", lambda: to_wavejson(None, "t"), "trace"),  # type: ignore[arg-type]
    ("to_wavejson title", lambda: to_wavejson(_trace(), None), "title"),  # type: ignore[arg-type]
    ("serial_io_wavejson trace", lambda: serial_io_wavejson(None, "t"), "trace"),  # type: ignore[arg-type]
    ("expansion_wavejson trace", lambda: expansion_wavejson("x", "t"), "trace"),  # type: ignore[arg-type]
    # Before: an AttributeError (a str has no mkdir), and vcd=1 taken as True.
    ("write_figures str", lambda: write_figures("/tmp/never-figures"), "out"),  # type: ignore[arg-type]
    ("write_figures vcd 1", lambda: write_figures(Path("never-figures"), vcd=1), "vcd"),  # type: ignore[arg-type]
]


@pytest.mark.parametrize(("call", "name"), [pytest.param(c, n, id=label) for label, c, n in BAD_FIGURES])
def test_figures_refuse_by_name(call: Callable[[], object], name: str) -> None:
    """Each call used to guess or fail deep inside (see the comments of BAD_FIGURES); nothing is written."""
    with pytest.raises(ArgumentError, match=rf"^{name} must be .*, not "):
        call()
    assert not Path("never-figures").exists()


def test_to_wavejson_step_one_draws_every_cycle() -> None:
    """A step of 1 (the finest) gives one column per recorded cycle."""
    trace = _trace()
    wave = to_wavejson(trace, "every cycle", step=1)
    lanes = wave["signal"]
    assert isinstance(lanes, list) and all(len(lane["wave"]) == len(trace) for lane in lanes)


# ---------------------------------------------------------------------------------------------------------------
# Serial register expansion over histories (3.5, RX-2, RX-4, RX-5): what the external registers hold
# ---------------------------------------------------------------------------------------------------------------

_EXT_LENGTH_CODES = {1: 0b01001, 3: 0b01011, 6: 0b00011}
"""Data lengths in bytes with ExtReg = 1 and their complete length codes (Table 3-11)."""

_EXT_OP = st.one_of(
    st.tuples(st.just("data"), st.binary(min_size=6, max_size=6), st.integers(0, 0)),
    st.tuples(st.just("error"), st.binary(min_size=6, max_size=6), st.integers(8, 60)),
    st.tuples(st.just("reset"), st.just(b""), st.integers(0, 0)),
    st.tuples(st.just("inputs"), st.binary(min_size=6, max_size=6), st.integers(0, 0)),
    st.tuples(st.just("idle"), st.just(b""), st.integers(0, 2000)),
)


@settings(max_examples=40, deadline=None)
@given(length=st.sampled_from(sorted(_EXT_LENGTH_CODES)), rate=st.sampled_from(BIT_RATES),
       ops=st.lists(_EXT_OP, max_size=14))
def test_history_external_registers_hold_the_last_valid_out_data(
        length: int, rate: int, ops: list[tuple[str, bytes, int]]) -> None:
    """Over any history of data cycles, bit errors on either line, INTERBUS resets, idle time and input changes, the
    IBS SRE 1's output registers hold the OUT data of the last valid data cycle in chain order (LaOuD only after a
    latched cycle, RX-4; cleared by /ResReg on the reset, RX-5): a corrupted cycle never changes them. A valid data
    cycle right after a valid one brings the IN data the chain loaded at that one's end (/LaInD)."""
    chip = Supi3(decode("10011", "1110", clk_conf=clk_conf_for(rate)))
    assert chip.registers is not None
    chip.registers.cpu_write(SET.address, SET.encode(EXTREG=1, LENGTH_CODE=_EXT_LENGTH_CODES[length]))
    chip.registers.cpu_write(ID.address, 0x01)
    sre = Sre1(length)
    chip.attach_expansion(sre)
    ring = Ring([chip])
    master = Master(ring)
    assert master.start().ok
    cpb = wire.clocks_per_bit(rate)
    gap_s = -(-overrun_gap_clocks(True, cpb) // cpb) / rate  # no expansion overrun between cycles (RX-4)
    expected = bytes(length)
    loaded: bytes | None = sre.inputs  # what /LaInD took at the end of the last cycle, if that was valid
    for kind, data, n in ops:
        if kind in ("data", "error"):
            out = data[:length]
            ring.idle(gap_s)
            master.set_outputs(1, out)
            if kind == "error":
                ring.bit_error(1 + n % 2, n)
            result = master.data_cycle()
            if result.ok:
                assert loaded is None or master.inputs(1) == chain_to_line(loaded)
                expected = line_to_chain(out)
            loaded = sre.inputs if result.ok else None
        elif kind == "reset":
            ring.idle(gap_s)
            assert master.start().ok
            expected, loaded = bytes(length), None
        elif kind == "inputs":
            sre.set_inputs(data[:length])
        else:
            ring.idle(n * 1e-6)
        assert sre.outputs == expected


# ---------------------------------------------------------------------------------------------------------------
# The lockstep's scoreboard on whole traces (supi3.verif.layout.first_mismatch)
# ---------------------------------------------------------------------------------------------------------------

_LAYOUT = WordLayout.of(ShiftCounterModel())
_SIGNALS = len(_LAYOUT.out_fields)


def _outputs(*rows: dict[str, int]) -> npt.NDArray[np.uint64]:
    names = [field.name for field in _LAYOUT.out_fields]
    return np.array([[row.get(name, 0) for name in names] for row in rows], dtype=np.uint64).reshape(-1, _SIGNALS)


def test_first_mismatch_never_accepts_a_value_that_spills_into_the_next_signal() -> None:
    """Before: a value wider than its signal was packed into the next signal's bits, so count 256 with sr 0 equalled
    count 0 with sr 1 (no mismatch reported), and count 256 alone was reported on sr; now the value is refused by
    name (which trace, cycle and signal)."""
    expected = _outputs({"count": 0, "sr": 1})
    with pytest.raises(ArgumentError, match=r"^actual\[0, 0\] must be a value of 'count' within 8 bits, not 256"):
        first_mismatch(_LAYOUT, expected, _outputs({"count": 256, "sr": 0}))
    with pytest.raises(ArgumentError, match=r"^expected\[0, 0\] .* not -1"):
        first_mismatch(_LAYOUT, np.full((1, _SIGNALS), -1, dtype=np.int64), expected)


@pytest.mark.parametrize(("expected", "actual", "name"), [
    pytest.param(np.zeros((3, _SIGNALS), np.uint64), np.zeros((2, _SIGNALS), np.uint64), "actual", id="lengths"),
    pytest.param(np.zeros((3, _SIGNALS), np.uint64), np.zeros((3, 2), np.uint64), "actual", id="columns"),
    pytest.param(np.zeros((3, _SIGNALS)), np.zeros((3, _SIGNALS)), "expected", id="floats"),
    pytest.param(np.zeros(_SIGNALS, np.uint64), np.zeros(_SIGNALS, np.uint64), "expected", id="1-D"),
])  # fmt: skip
def test_first_mismatch_refuses_traces_by_name(expected: object, actual: object, name: str) -> None:
    """Before: a broadcast ValueError, a zip() ValueError, a ufunc TypeError; now the trace is named."""
    with pytest.raises(ArgumentError, match=rf"^{name} must be "):
        first_mismatch(_LAYOUT, expected, actual)  # type: ignore[arg-type]


@settings(max_examples=60, deadline=None)
@given(st.data())
def test_first_mismatch_finds_the_first_difference(data: st.DataObject) -> None:
    """Over random traces within their signals' widths and random changes to one copy, the scoreboard reports
    exactly the first compared difference (a tri-state value compared only while the model's enable is 1), and
    never accepts a trace that differs in a compared signal."""
    cycles = data.draw(st.integers(1, 6))
    rows = [{field.name: data.draw(st.integers(0, field.mask)) for field in _LAYOUT.out_fields}
            for _ in range(cycles)]
    expected = _outputs(*rows)
    actual = expected.copy()
    for _ in range(data.draw(st.integers(0, 3))):
        cycle, index = data.draw(st.integers(0, cycles - 1)), data.draw(st.integers(0, _SIGNALS - 1))
        actual[cycle, index] = data.draw(st.integers(0, _LAYOUT.out_fields[index].mask))
    enables = {field.name: i for i, field in enumerate(_LAYOUT.out_fields)}
    differences = [(c, i) for c in range(cycles) for i, field in enumerate(_LAYOUT.out_fields)
                   if expected[c, i] != actual[c, i]
                   and (field.enable is None or expected[c, enables[field.enable]])]
    assert first_mismatch(_LAYOUT, expected, actual) == (differences[0] if differences else None)


@pytest.mark.parametrize("value", [9, -1])
def test_strap_stimulus_refuses_an_optical_value_past_its_width(value: int) -> None:
    """Before: ``strap_stimulus``'s ``optical`` lines were taken unchecked (9 in a 3-bit port, -1 as 2**64 - 1), and
    ``WordLayout.input_words`` (which packs a range-checked stimulus by one matrix product) spilled them into the next
    port of the RTL's input words; now the column is named."""
    config = decode("10011", "1110")
    stimulus = np.zeros((3, len(Supi3Pins.inputs)), np.int64)
    optical = np.zeros((3, len(Supi3Pins.optical_inputs)), np.int64)
    optical[1, 1] = value
    with pytest.raises(ArgumentError, match=r"^optical column 1 \('medium'\)\[1\] must be an integer from 0 to 7"):
        strap_stimulus(config, stimulus, optical)
    optical[1, 1] = 7
    assert strap_stimulus(config, stimulus, optical)[1, -len(Supi3Pins.optical_inputs) + 1] == 7


def test_input_words_refuse_a_value_past_its_pin() -> None:
    """Before: ``WordLayout.input_words`` packed by one matrix product, so a value past its pin's width (or a negative
    one) spilled into the next field: the design saw other inputs than the model. Now it is named."""
    layout = WordLayout([Pin("a", 3), Pin("b", 1)], [Pin("x")])
    with pytest.raises(ArgumentError, match=r"^stimulus\[1, 0\] must be a value of 'a' within 3 bits, not 8"):
        layout.input_words(np.array([[7, 1], [8, 0]], dtype=np.uint64))
    with pytest.raises(ArgumentError, match=r"^stimulus\[0, 1\] must be a value of 'b' within 1 bit, not -1"):
        layout.input_words(np.array([[0, -1]], dtype=np.int64))
    with pytest.raises(ArgumentError, match=r"^stimulus must be a \(cycles, 2\) integer array"):
        layout.input_words(np.zeros((2, 3), dtype=np.uint64))
    assert layout.input_words(np.array([[7, 1]], dtype=np.uint64)).tolist() == [[7 | 1 << 3]]


@pytest.mark.parametrize(("call", "name"), [
    (lambda: bench.telegram_end_s(0.0, 1.0, 0), "bit_rate"),
    (lambda: bench.telegram_end_s(0.0, math.nan, 500_000), "at"),
    (lambda: bench.telegram_end_s("a", 1.0, 500_000), "since"),  # type: ignore[arg-type]
    (lambda: bench.telegram_end_s(-1.0, 1.0, 500_000), "since"),
    (lambda: bench.resume_s(0.0, 1.0, 2.0, -5), "bit_rate"),
    (lambda: bench.resume_s(0.0, math.nan, 2.0, 500_000), "scheduled"),
    (lambda: bench.ring_positions(5), "devices"),  # type: ignore[arg-type]
    (lambda: bench.ring_positions("ab"), "devices"),  # type: ignore[arg-type]
    (lambda: bench.ring_positions([object()]), "devices"),  # type: ignore[list-item]
])  # fmt: skip
def test_the_run_rule_s_helpers_refuse_by_name(call: Callable[[], object], name: str) -> None:
    """MCU-55/56's public helpers of ``supi3.sdk.bench`` (added the same day, the lead's probe): a zero or negative
    bit rate was a ``ZeroDivisionError`` or a silent wrong time (``resume_s(..., -5)`` returned 1.0), NaN a
    conversion error, a string a ``TypeError`` deep inside, ``ring_positions(5)`` "not iterable"."""
    with pytest.raises(ArgumentError, match=name):
        call()


def test_the_run_rule_s_helpers_still_answer() -> None:
    """The same helpers with good arguments: a status telegram's end, the schedule when later, a tree's positions."""
    telegram = wire.STATUS_TELEGRAM_BITS / 500_000
    assert bench.telegram_end_s(0.0, 0.5 * telegram, 500_000) == telegram
    assert bench.resume_s(0.0, math.inf, 0.0, 500_000) == math.inf
    assert bench.resume_s(0.0, 0.0, 0.5 * telegram, 500_000) == telegram
    assert bench.ring_positions([]) == 0


@pytest.mark.parametrize("tx", [-1, 1 << 16, "a", 1.5, True, None])
def test_the_ss_high_lint_refuses_what_is_no_data_frame(tx: object) -> None:
    """MCU-63's public ``ss_high_byte`` (the lead's probe): a string or a float was a format ``ValueError``; -1 and
    10000h went into the report as "byte -1h" and "byte 10000h"."""
    with pytest.raises(ArgumentError, match="tx"):
        ss_high_byte(tx)  # type: ignore[arg-type]
    assert ss_high_byte(0xA5).rule == "3.4.2"

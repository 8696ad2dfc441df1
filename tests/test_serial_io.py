"""The serial I/O schedule (manual 3.3, Table 3-3, Table 3-4, Figures 3-1 to 3-3; SM-1 to SM-9) and the register
expansion schedule (3.5, Table 3-15, Figure 3-24; RX-3 to RX-5): the spec modules every fidelity derives from."""

from __future__ import annotations

import itertools
import json

import pytest
from hypothesis import given
from hypothesis import strategies as st

from supi3 import expansion, serial_io, tables
from supi3.cli import main
from supi3.config import DataDirection, DeviceConfig, MfpKind, decode, mode_rows
from supi3.errors import ArgumentError
from supi3.interbus import wire
from supi3.serial_io import IDLE, Levels, clear_sequence, render, sequence, t0_clocks

SPI_CONFIGS = [
    decode(row.c, row.mfp, clk_conf=clk)
    for row in mode_rows()
    if " SPI " in f" {row.function} "
    for clk in ("01", "11")
]
"""Every SPI master row of Tables 2-4 to 2-6, at 500 kbit/s and 2 Mbit/s."""


def test_every_spi_row_is_covered() -> None:
    kinds = {c.mfp_mode.kind for c in SPI_CONFIGS}
    assert kinds == {MfpKind.SPI_MASTER}
    assert {(c.mfp_mode.direction, c.mfp_mode.width) for c in SPI_CONFIGS} == {
        (d, w) for d in (DataDirection.IN, DataDirection.OUT, DataDirection.IN_OUT) for w in (16, 32)
    }
    assert {c.bit_rate for c in SPI_CONFIGS} == set(tables.BIT_RATES)


def _edges(trace: list[int], level: int) -> list[int]:
    """Cycles where ``trace`` takes ``level`` after the other level."""
    return [k for k in range(1, len(trace)) if trace[k] == level and trace[k - 1] != level]


@pytest.mark.parametrize("config", SPI_CONFIGS, ids=lambda c: f"{c.function}@{c.bit_rate}")
def test_sequence_meets_table_3_4(config: DeviceConfig) -> None:
    mode = config.mfp_mode
    t0 = t0_clocks(config.bit_rate)
    assert t0 * 2 == wire.clocks_per_bit(config.bit_rate)  # t0 = 0.5 t_Bit_IBS: SCLK 1 MHz / 4 MHz
    seq = sequence(mode.direction, mode.width, config.bit_rate)
    word = 0xA5C3 if mode.width == 16 else 0xA5C3_5A3C
    lv = [IDLE, *render(seq, word), IDLE]  # one idle cycle either side
    ss = [v.ss_n for v in lv]
    sclk = [v.sclk for v in lv]
    conv = [v.conv_n for v in lv]
    falls, rises = _edges(ss, 0), _edges(ss, 1)
    assert len(falls) == len(rises) == len(seq.frames)
    for frame, fall, rise in zip(seq.frames, falls, rises, strict=True):
        n = mode.width // 8
        assert rise - fall == 9 * n * t0  # t8
        clock_rises = [k for k in _edges(sclk, 1) if fall < k < rise]
        assert len(clock_rises) == mode.width
        assert clock_rises[0] - fall == t0  # t1
        assert rise - clock_rises[-1] == t0  # t2
        gaps = {b - a for a, b in itertools.pairwise(clock_rises)}
        assert gaps == {t0, 2 * t0}  # t0 within a byte, t9 = 2 t0 between bytes
        if frame.write:
            bits = [lv[k - 1].ser_out for k in clock_rises]  # the level SerOut has at each rising edge
            assert int("".join(map(str, bits)), 2) == word  # MSB first (t11)
            for k in clock_rises:  # t3, t12: SerOut changes only half a t0 away from a rising edge
                assert lv[k - t0 // 2].ser_out == lv[k + t0 // 2 - 1].ser_out
        else:
            assert all(lv[k].ser_out == 0 for k in range(fall, rise))
            assert [seq.frames[0].sample(j) + 1 for j in range(mode.width)] == [k - 1 for k in clock_rises]
    if len(seq.frames) == 2:
        assert falls[1] - rises[0] == serial_io.PAUSE_T0 * t0  # t10 >= 50.5 t0
    if seq.write is not None:
        (conv_fall,) = _edges(conv, 0)
        (conv_rise,) = _edges(conv, 1)
        assert conv_fall - rises[-1] == t0 and conv_rise - conv_fall == t0  # t6, t7
        assert conv_rise == seq.length + 1  # the sequence ends with /Conv
    else:
        assert set(conv) == {1}
        assert rises[-1] == seq.length + 1
    assert lv[-1] == IDLE


@pytest.mark.parametrize("config", SPI_CONFIGS, ids=lambda c: f"{c.function}@{c.bit_rate}")
def test_sequence_fits_in_the_shortest_data_cycle(config: DeviceConfig) -> None:
    """SM-2: a new latch cannot come while a sequence runs: the sequence is shorter than a one-device data cycle."""
    seq = sequence(config.mfp_mode.direction, config.mfp_mode.width, config.bit_rate)
    assert seq.length < wire.cycle_bits(config.data_bytes, 1) * wire.clocks_per_bit(config.bit_rate)


@given(st.sampled_from([(d, w, r) for d in DataDirection if d is not DataDirection.NONE for w in (16, 32)
                        for r in tables.BIT_RATES]), st.data())  # fmt: skip
def test_levels_outside_the_sequence_are_idle(case: tuple[DataDirection, int, int], data: st.DataObject) -> None:
    direction, bits, rate = case
    seq = sequence(direction, bits, rate)
    word = data.draw(st.integers(0, (1 << bits) - 1))
    k = data.draw(st.one_of(st.integers(-1000, -1), st.integers(seq.length, seq.length + 1000)))
    assert seq.levels(k, word) == IDLE


def test_clear_sequence_writes_zeros() -> None:
    for bits in (16, 32):
        for rate in tables.BIT_RATES:
            assert clear_sequence(DataDirection.IN, bits, rate) is None
            for direction in (DataDirection.OUT, DataDirection.IN_OUT):
                clear = clear_sequence(direction, bits, rate)
                assert clear == sequence(DataDirection.OUT, bits, rate)
                assert clear is not None and all(v.ser_out == 0 for v in render(clear, 0))


def test_levels_mfp_bits() -> None:
    assert IDLE.mfp() == (1 << 3) | (1 << 5)
    assert Levels(0, 1, 0, 1).mfp() == (1 << 4) | (1 << 7)
    assert decode("01011", "1000").mfp_output_mask == serial_io.MFP_MASK  # Table 3-3: MFP3, 4, 5, 7 driven


def test_wiring_names_the_pins_of_table_3_3() -> None:
    used = {p.pin: p.signal for p in tables.SPI_MASTER_MFP if p.signal != "GND"}
    assert {w.mfp: w.signal for w in serial_io.WIRING} == used


@pytest.mark.parametrize(("call", "name"), [
    (lambda: sequence("in", 16, 500_000), "direction"),  # type: ignore[arg-type]
    (lambda: sequence(DataDirection.NONE, 16, 500_000), "direction"),
    (lambda: sequence(DataDirection.IN, 8, 500_000), "bits"),
    (lambda: sequence(DataDirection.IN, 16, 1_000_000), "bit_rate"),
    (lambda: clear_sequence(DataDirection.IN, 24, 500_000), "bits"),
    (lambda: t0_clocks(True), "bit_rate"),
    (lambda: render(sequence(DataDirection.OUT, 16, 500_000), 1 << 16), "out_word"),
    (lambda: expansion.clock_high(2), "cpb"),
    (lambda: expansion.end_pulses(1, 16), "latched_data"),  # type: ignore[arg-type]
    (lambda: expansion.line_to_chain("abc"), "received"),  # type: ignore[arg-type]
    (lambda: sequence(DataDirection.IN, 16, 500_000).levels("a", 0), "k"),  # type: ignore[arg-type]
    (lambda: sequence(DataDirection.OUT, 16, 500_000).levels(5, -1), "out_word"),
    (lambda: sequence(DataDirection.OUT, 16, 500_000).levels(5, 1 << 16), "out_word"),
    (lambda: sequence(DataDirection.IN, 16, 500_000).frames[0].sample(16), "j"),
    (lambda: sequence(DataDirection.IN, 16, 500_000).frames[0].slot(-1), "j"),
    (lambda: serial_io.SerialFrame(-1, 16, True, 8), "start"),
    (lambda: serial_io.SerialFrame(0, 12, True, 8), "bits"),
    (lambda: serial_io.SerialFrame(0, 16, 1, 8), "write"),  # type: ignore[arg-type]
    (lambda: serial_io.SerialFrame(0, 16, True, 7), "t0"),
    (lambda: serial_io.SerialSequence((), None, 5), "frames"),
    (lambda: serial_io.SerialSequence(sequence(DataDirection.IN, 16, 500_000).frames, 3, 5), "conv"),  # type: ignore[arg-type]
    (lambda: serial_io.SerialSequence(sequence(DataDirection.IN, 16, 500_000).frames, None, 0), "length"),
    (lambda: render("x", 0), "seq"),  # type: ignore[arg-type]
    (lambda: Levels(2, 0, 0, 0), "Levels.conv_n"),
    (lambda: expansion.ExpansionLevels(0, 0, 0, 0, "1"), "ExpansionLevels.res_reg_n"),  # type: ignore[arg-type]
])  # fmt: skip
def test_bad_arguments_are_named(call: object, name: str) -> None:
    assert callable(call)
    with pytest.raises(ArgumentError, match=name):
        call()


# ---------------------------------------------------------------------------------------------------------------
# Register expansion (3.5)
# ---------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("rate", tables.BIT_RATES)
def test_expansion_schedule_meets_table_3_15(rate: int) -> None:
    cpb = wire.clocks_per_bit(rate)  # t0 = t_Bit_IBS (Table 3-15)
    first, end = expansion.clock_high(cpb)
    assert first == cpb // 4 and end - first == cpb // 2  # ToExR valid 0.25 t0 before and 0.75 t0 after the rise
    latched = expansion.end_pulses(True, cpb)
    assert latched.la_ou_d == (0, 4 * cpb)
    assert latched.la_in_d_n == (9 * cpb, 13 * cpb)  # 5 t0 after LaOuD fell, 4 t0 long
    assert latched.length == 13 * cpb
    other = expansion.end_pulses(False, cpb)
    assert other.la_ou_d is None and other.la_in_d_n == (0, 4 * cpb)


def test_figure_3_24_byte_order() -> None:
    """3.5: bytes 0..2 = 78h, 56h, 14h in the external registers travelled in the data cycle as 14h, 56h, 78h."""
    assert expansion.line_to_chain(bytes([0x14, 0x56, 0x78])) == bytes([0x78, 0x56, 0x14])
    assert expansion.chain_to_line(bytes([0x78, 0x56, 0x14])) == bytes([0x14, 0x56, 0x78])


# ---------------------------------------------------------------------------------------------------------------
# supi3 decode shows the wiring
# ---------------------------------------------------------------------------------------------------------------


def test_decode_shows_serial_io_wiring(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["decode", "--c", "01011", "--mfp", "1000"]) == 0
    out = capsys.readouterr().out
    assert "SCLK 1 MHz" in out and "/SS frame 18 µs" in out
    assert "DAC DIN" in out and "ADC DOUT" in out
    assert main(["decode", "--c", "01011", "--mfp", "1010", "--clk-conf", "11", "--json"]) == 0  # SPI 16 IN
    data = json.loads(capsys.readouterr().out)
    assert data["serial_io"]["sclk_hz"] == 4_000_000
    wiring = {w["signal"]: w["connect"] for w in data["serial_io"]["wiring"]}
    assert wiring["SerOut"] == "-" and wiring["/Conv"] == "-" and "ADC" in wiring["SerIn"]
    assert main(["decode", "--c", "10000", "--json"]) == 0
    assert "serial_io" not in json.loads(capsys.readouterr().out)

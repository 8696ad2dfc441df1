"""``supi3 demo --analog`` (supi3.demo.run_analog): an SPI ADC and DAC behind a SUPI 3 in SPI 16 IN/16 OUT (manual
3.3, Table 2-6), values moving from the master to the DAC output and from the ADC input back to the master, at
transaction level and at pin level, the pin level's SPI pins in a VCD and checked against Table 3-4."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from vcd.reader import TokenKind, tokenize

from supi3 import demo, tables
from supi3.cli import main
from supi3.errors import ArgumentError
from supi3.verif.timing import TimingViolation, check_serial_io

LINE = re.compile(r"  cycle (\d+) \(ok, +[\d.]+ ms\)  master OUT ([0-9A-F]{4})h -> DAC ([0-9A-F]{4})h = ([\d.]+) V  "
                  r"\|  ADC input ([\d.]+) V = ([0-9A-F]{4})h  \|  master IN ([0-9A-F]{4})h")
FULL_SCALE = 1 << 16
"""16-bit converters (SPI 16 IN/16 OUT)."""


Row = tuple[int, int, int, int, int, int, int]
"""One cycle line: cycle, master OUT, DAC code, DAC mV, ADC mV, ADC code, master IN."""


def _cycles(lines: list[str]) -> list[Row]:
    """The :data:`Row` of every cycle line, in order."""
    rows: list[Row] = []
    for line in lines:
        match = LINE.fullmatch(line)
        if match:
            n, out, dac, dac_v, adc_v, adc, inp = match.groups()
            rows.append((int(n), int(out, 16), int(dac, 16), round(float(dac_v) * 1000), round(float(adc_v) * 1000),
                         int(adc, 16), int(inp, 16)))
    return rows


def test_default_output_is_exact() -> None:
    lines = list(demo.run_analog())
    assert lines == [
        "supi3 demo --analog: INTERBUS master and a ring of 3 devices at 500 kbit/s (transaction level)",
        "Device 1: RB, SPI 16 IN/16 OUT (Table 2-6) with a 16-bit SPI ADC and a 16-bit SPI DAC (vref 5 V) on its "
        "serial I/O bus (3.3); the DAC output is wired to the ADC input",
        "Alarm Stop (1303h) and discovery ID cycle: ok",
        "Configuration table:",
        "  Pos  Device   ID     Length  Interface     Table A-3",
        "    1     1.0  33h     16 bit  remote bus    Analog input/output modules",
        "    2     2.0  03h      8 bit  remote bus    Digital input/output modules",
        "    3     3.0  02h      8 bit  remote bus    Digital input modules",
        "Data cycles (master OUT -> DAC; DAC output -> ADC input, sampled before the DAC takes the new word -> master "
        "IN one cycle later), device 1:",
        "  cycle 1 (ok,  27.338 ms)  master OUT 2000h -> DAC 2000h = 0.625 V  |  ADC input 0.000 V = 0000h  |  "
        "master IN 0000h",
        "  cycle 2 (ok,  27.648 ms)  master OUT 4000h -> DAC 4000h = 1.250 V  |  ADC input 0.625 V = 2000h  |  "
        "master IN 0000h",
        "  cycle 3 (ok,  27.958 ms)  master OUT 6000h -> DAC 6000h = 1.875 V  |  ADC input 1.250 V = 4000h  |  "
        "master IN 2000h",
        "  cycle 4 (ok,  28.268 ms)  master OUT 8000h -> DAC 8000h = 2.500 V  |  ADC input 1.875 V = 6000h  |  "
        "master IN 4000h",
    ]


@pytest.mark.parametrize("clk_conf", ["01", "11"], ids=["500k", "2M"])
def test_values_move_end_to_end(clk_conf: str) -> None:
    rows = _cycles(list(demo.run_analog(10, clk_conf=clk_conf)))
    assert [r[0] for r in rows] == list(range(1, 11))
    previous_dac = previous_adc = 0  # power-up and the Alarm Stop's clear sequence (SM-9): everything at 0
    for n, out, dac, dac_mv, adc_mv, adc, inp in rows:
        assert out == demo.setpoint(n - 1) == (0x2000 * n) % FULL_SCALE  # the ramp, wrapping at cycle 8
        assert dac == out  # the master's OUT word reaches the DAC in the cycle's sequence
        assert dac_mv == round(5000 * dac / FULL_SCALE)
        assert adc == previous_dac and adc_mv == round(5000 * adc / FULL_SCALE)  # read frame before write frame
        assert inp == previous_adc  # the word read travels in the next data cycle
        previous_dac, previous_adc = dac, adc
    assert any(inp for *_, inp in rows)  # not a run of zeros


def test_cycles_is_checked() -> None:
    with pytest.raises(ArgumentError, match="cycles must be"):
        list(demo.run_analog(0))


def test_the_command_line_runs_it(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["demo", "--analog"]) == 0
    out, err = capsys.readouterr()
    assert err == "" and out.splitlines() == list(demo.run_analog())  # no register map: no µP interface here
    assert main(["demo"]) == 0  # the default demo is unchanged
    assert "Register map" in capsys.readouterr().out


def _mfp_out(vcd: Path, scope: str) -> np.ndarray:
    """The ``mfp_out`` trace of ``scope`` rebuilt from the VCD, one sample a 32 MHz clock, to its last change."""
    current, wanted, time = "", None, 0
    changes: list[tuple[int, int]] = []
    with vcd.open("rb") as stream:
        for token in tokenize(stream):
            if token.kind is TokenKind.SCOPE:
                current = token.scope.ident
            elif token.kind is TokenKind.VAR and current == scope and token.var.reference == "mfp_out":
                wanted = token.var.id_code
            elif token.kind is TokenKind.CHANGE_TIME:
                time = token.time_change
            elif token.kind is TokenKind.CHANGE_VECTOR and token.vector_change.id_code == wanted:
                value = token.vector_change.value
                assert isinstance(value, int)
                changes.append((time * tables.CLOCK_HZ // 10**12, value))
    trace = np.zeros(changes[-1][0] + 1, dtype=np.int64)
    for at, value in changes:
        trace[at:] = value
    return trace


def _frame_words(mfp_out: np.ndarray) -> list[int]:
    """The SerOut word of every /SS frame: SerOut at each SCLK rise inside the frame, MSB first (SM-4)."""
    bit = {levels: next(r.pin for r in tables.SPI_MASTER_MFP if r.signal == levels)
           for levels in ("SCLK", "/SS", "SerOut")}
    sclk, ss_n, ser_out = ((mfp_out >> bit[name]) & 1 for name in ("SCLK", "/SS", "SerOut"))
    words, word = [], 0
    for k in range(1, len(mfp_out)):
        if ss_n[k] == 0 and ss_n[k - 1] == 1:
            word = 0
        if ss_n[k] == 0 and sclk[k] == 1 and sclk[k - 1] == 0:
            word = (word << 1) | int(ser_out[k])
        if ss_n[k] == 1 and ss_n[k - 1] == 0:
            words.append(word)
    return words


@pytest.mark.parametrize(("rate", "bit_rate"), [("500k", 500_000), ("2M", 2_000_000)])
def test_vcd_holds_the_spi_pins_and_meets_table_3_4(capsys: pytest.CaptureFixture[str], tmp_path: Path, rate: str,
                                                    bit_rate: int) -> None:
    vcd = tmp_path / "analog.vcd"
    assert main(["demo", "--analog", "--cycles", "3", "--bit-rate", rate, "--vcd", str(vcd)]) == 0
    out, err = capsys.readouterr()
    lines = out.splitlines()
    assert err == "" and lines[-2:] == ["Table 3-4 on device 1's SPI pins (MFP3..MFP7): no violations", f"wrote {vcd}"]
    split = next(k for k, line in enumerate(lines) if line.startswith("Pin level, SUPI 3 chips only"))
    transaction, pins = lines[:split], lines[split:]
    assert len(_cycles(transaction)) == 3 and _cycles(pins) == _cycles(transaction)  # the same values (SM-11)
    mfp_out = _mfp_out(vcd, "dev1")
    # Independently of the demo's own check: the waveform in the file meets every row of Table 3-4.
    assert check_serial_io({"mfp_out": mfp_out}, bit_rate=bit_rate, bits=16) == []
    # The Alarm Stop's clear sequence writes 0 (SM-9); each data cycle reads (SerOut 0), then writes the setpoint.
    assert _frame_words(mfp_out) == [0, 0, 0x2000, 0, 0x4000, 0, 0x6000]


def test_violations_are_listed(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    found = TimingViolation("3-4", "t0", "SCLK period", 1e-7, 2.5e-7, False, 1234)
    monkeypatch.setattr(demo, "check_serial_io", lambda *_, **__: [found])
    lines = list(demo.run_analog(1, tmp_path / "a.vcd"))
    at = lines.index("Table 3-4 on device 1's SPI pins (MFP3..MFP7): 1 violation")
    assert lines[at + 1] == f"  {found}" and "measured 100.00 ns, required >= 250.00 ns at clock 1234" in lines[at + 1]

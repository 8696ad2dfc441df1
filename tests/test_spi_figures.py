"""Timing diagrams from model traces: the checked-in figures are current (regenerated through ``supi3 figures``), each
figure's trace carries the manual's bytes, the software µP is within Table 3-7 (and minimal where the model can
tell), VCD output."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest
from vcd.reader import TokenKind, tokenize

from supi3.cli import main
from supi3.config import decode
from supi3.figures import ALL_FIGURES
from supi3.model.registers import RegisterFile
from supi3.regmap import IN0, encode_command
from supi3.spi.figures import FIGURES, Figure
from supi3.spi.master import MasterTiming, SoftMaster, SpiTrace, decode_bytes, write_spi_vcd
from supi3.spi.slave_pins import SlavePins, TimingViolationError
from supi3.spi.upif import C_D_COMMAND, C_D_DATA, Mode, UpifUsageError
from supi3.tables import clk_conf_for

FIGURE_DIR = Path(__file__).resolve().parents[1] / "docs" / "figures"

# (to chip, from chip, C/D when /SS fell, S/R) per byte, as the manual's figures and text give them (3.4.5, 3.4.6).
EXPECTED = {
    "fig3-4": [(0x5A, 0xC3, C_D_DATA, None)],
    "fig3-5": [(None, 0xC3, C_D_DATA, 0)],
    "fig3-9": [(0x81, None, C_D_COMMAND, 1)],
    "fig3-10": [(0x4D, None, C_D_COMMAND, 1), (0x82, None, C_D_DATA, 1)],
    "fig3-11": [(0x4C, None, C_D_COMMAND, 1), (0x01, None, C_D_DATA, 1)],
    "fig3-12": [(0x8F, None, C_D_COMMAND, 1), (None, 0x14, C_D_DATA, 0), (None, 0x56, C_D_DATA, 0),
                (None, 0x78, C_D_DATA, 0)],
}


@pytest.fixture(scope="module")
def generated(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("figures")
    assert main(["figures", "-o", str(out), "--vcd"]) == 0
    return out


def test_every_manual_figure_is_redrawn() -> None:
    assert [f.name for f in FIGURES] == list(EXPECTED)


def test_every_figure_file_is_listed_in_the_docs() -> None:
    written = {path.stem for path in FIGURE_DIR.glob("*.json")}
    docs = (FIGURE_DIR.parent / "figures.md").read_text(encoding="utf-8")
    assert written == {f.name for f in ALL_FIGURES}
    assert all(f"(figures/{f.name}.svg)" in docs for f in ALL_FIGURES)


@pytest.mark.parametrize("name", [f.name for f in ALL_FIGURES])
def test_checked_in_figures_are_current(generated: Path, name: str) -> None:
    """Regenerate with ``supi3 figures`` (in the source tree's root) if this fails."""
    checked_in = json.loads((FIGURE_DIR / f"{name}.json").read_text(encoding="utf-8"))
    assert json.loads((generated / f"{name}.json").read_text(encoding="utf-8")) == checked_in
    svg = (FIGURE_DIR / f"{name}.svg").read_text(encoding="utf-8")
    assert svg.startswith("<svg") and checked_in["head"]["text"].split(" (")[0] in svg
    if name in EXPECTED:  # VCD files are of the µP interface's software master traces
        assert (generated / f"{name}.vcd").stat().st_size > 0


@pytest.mark.parametrize("figure", FIGURES, ids=lambda f: f.name)
def test_figure_trace_carries_the_manual_bytes(figure: Figure[SpiTrace]) -> None:
    trace = figure.build()
    frames = decode_bytes(trace)
    assert [(f.to_chip, f.from_chip, f.c_d, f.s_r) for f in frames] == EXPECTED[figure.name]
    assert all(f.edges == 8 for f in frames)
    assert trace.outputs[0].c_d == frames[0].c_d  # settled before the figure starts
    assert trace.outputs[-1].c_d == C_D_COMMAND  # every figure ends waiting for a command


def test_wavejson_annotates_the_bytes_and_the_c_d_change(generated: Path) -> None:
    """Fig. 3-10: 4Dh then 82h on Ser_IN/OUT, C/D command -> data -> command."""
    wavejson = json.loads((generated / "fig3-10.json").read_text(encoding="utf-8"))
    lanes = {lane["name"]: lane for lane in wavejson["signal"]}
    assert lanes["µP → chip"]["data"] == ["4Dh", "82h"] and lanes["chip → µP"]["data"] == []
    assert lanes["C/D (MFP2)"]["wave"].replace(".", "") == "010"
    assert lanes["/SS (MFP5)"]["wave"].replace(".", "") == "10101"
    assert lanes["SCLK (MFP4)"]["wave"].replace(".", "") == "1" + "01" * 16


def test_vcd_of_a_scenario(tmp_path: Path) -> None:
    trace = FIGURES[-1].build()
    path = write_spi_vcd(tmp_path / "block.vcd", trace)
    ids: dict[str, str] = {}
    falls = 0
    with path.open("rb") as stream:
        for token in tokenize(stream):
            if token.kind is TokenKind.VAR:
                ids.setdefault(token.var.reference, token.var.id_code)
            elif token.kind is TokenKind.CHANGE_SCALAR and token.scalar_change.id_code == ids["ss_n"]:
                falls += token.scalar_change.value == "0"
    assert falls == len(decode_bytes(trace)) == 4
    assert {"sclk", "mfp6", "mfp7", "c_d", "mosi_oe", "mfp6_oe"} <= set(ids)


def _chip(bit_rate: int, *, strict: bool = True) -> SlavePins:
    return SlavePins(RegisterFile(decode("10011", "1110", clk_conf=clk_conf_for(bit_rate)), strict=strict))


@pytest.mark.parametrize(("bit_rate", "period"), [(500_000, 22), (2_000_000, 6)])
def test_fastest_master_is_within_table_3_7(bit_rate: int, period: int) -> None:
    """t0 = 667 ns / 167 ns rounded up to 32 MHz clocks; a strict chip raises on any Table 3-7 violation."""
    chip = _chip(bit_rate)
    m = SoftMaster(chip, Mode.MOTOROLA, record=False)
    assert m.timing.period == period
    m.byte(Mode.MOTOROLA.init_byte)
    for address, value in ((13, 0x82), (0, 0xA5)):
        m.byte(encode_command(address, wr=True))
        m.byte(value)
    chip.registers.latch(b"\x3c")
    m.byte(encode_command(IN0.address, rd=True, wr=True))
    assert m.byte(0x11) == 0x3C
    m.deselect()
    assert chip.registers.value("IN0") == 0x11 and chip.registers.value("SET") == 0x82


@pytest.mark.parametrize(("bit_rate", "parameter", "symbol"), [
    (500_000, "lead", "t1"), (2_000_000, "lead", "t1"), (500_000, "trail", "t2"), (2_000_000, "trail", "t2"),
    (500_000, "low", "t0"), (500_000, "high", "t0"),  # at 500 kbit/s the SCLK phases are set by t0
    (2_000_000, "low", "t4"), (2_000_000, "high", "t5"),  # at 2 Mbit/s by the setup and hold times
])
def test_one_clock_less_breaks_table_3_7(bit_rate: int, parameter: str, symbol: str) -> None:
    chip = _chip(bit_rate, strict=False)
    fastest = MasterTiming.fastest(bit_rate)
    m = SoftMaster(chip, Mode.MOTOROLA, replace(fastest, **{parameter: getattr(fastest, parameter) - 1}))
    m.byte(Mode.MOTOROLA.init_byte)
    m.byte(0x55)  # data changes at every falling edge: t4 and t5 are measured
    m.deselect()
    found = {v.parameter for v in chip.registers.violations.records if isinstance(v, TimingViolationError)}
    assert symbol in found


def test_sclk_faster_than_t0_is_refused() -> None:
    with pytest.raises(UpifUsageError, match="t0"):
        MasterTiming.fastest(500_000, sclk_hz=1.6e6)
    assert MasterTiming.fastest(500_000, sclk_hz=1e6).period == 32
    with pytest.raises(UpifUsageError, match="symmetric"):
        MasterTiming.fastest(2_000_000).aligned()

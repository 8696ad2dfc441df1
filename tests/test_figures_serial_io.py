"""Figures 3-1 to 3-3 (serial I/O, SPI master mode, manual 3.3.2) redrawn from pin-level ring traces: the devices
attached to the chip saw the data cycle's words, the traces meet Table 3-4, the WaveJSON's bit names D15..D0 sit on
the levels of the words' bits, the t10 pause is a gap, and generation fails on a trace that breaks Table 3-4."""

from __future__ import annotations

import numpy as np
import pytest

from supi3 import figures
from supi3.figures import (
    SERIAL_IO_FIGURES,
    SERIAL_IO_IN,
    SERIAL_IO_OUT,
    FigureTraceError,
    SerialIoTrace,
    serial_io_wavejson,
)
from supi3.peripherals.serial import ShiftIn, ShiftOut, SpiAdc, SpiDac
from supi3.serial_io import Levels
from supi3.spi.figures import Figure
from supi3.verif.timing import TraceTimingError, check_serial_io

OUT = int.from_bytes(SERIAL_IO_OUT, "big")
BY_NAME = {f.name: f for f in SERIAL_IO_FIGURES}


@pytest.fixture(scope="module")
def drawn() -> dict[str, tuple[SerialIoTrace, dict[str, object]]]:
    return {f.name: f.wavejson() for f in SERIAL_IO_FIGURES}


def _lanes(wavejson: dict[str, object]) -> dict[str, dict[str, object]]:
    signal = wavejson["signal"]
    assert isinstance(signal, list)
    return {lane["name"]: lane for lane in signal}


def _segments(lane: dict[str, object]) -> list[tuple[int, int]]:
    """(first, last) column of each ``=`` segment of a data lane (a gap column continues it)."""
    wave = str(lane["wave"])
    starts = [k for k, ch in enumerate(wave) if ch == "="]
    ends = [next((m for m in range(k + 1, len(wave)) if wave[m] not in ".|"), len(wave)) - 1 for k in starts]
    return list(zip(starts, ends, strict=True))


def _level(lane: dict[str, object], column: int) -> str:
    """The level a wave string shows in ``column``."""
    wave = str(lane["wave"])
    return next(ch for ch in reversed(wave[: column + 1]) if ch not in ".|")


def test_the_manuals_figures_3_1_to_3_3() -> None:
    assert [f.manual.split(" ", 2)[1] for f in SERIAL_IO_FIGURES] == ["3-1", "3-2", "3-3"]
    assert [f.draw for f in SERIAL_IO_FIGURES] == [serial_io_wavejson] * 3


def test_devices_saw_the_data_cycles_words(drawn: dict[str, tuple[SerialIoTrace, dict[str, object]]]) -> None:
    (adc,) = drawn["fig3-1"][0].devices
    (dac,) = drawn["fig3-2"][0].devices
    chain_in, chain_out = drawn["fig3-3"][0].devices
    assert isinstance(adc, SpiAdc) and drawn["fig3-1"][0].in_word == SERIAL_IO_IN
    assert isinstance(dac, SpiDac) and dac.output == OUT == drawn["fig3-2"][0].out_word
    assert isinstance(chain_in, ShiftIn) and drawn["fig3-3"][0].in_word == SERIAL_IO_IN
    assert isinstance(chain_out, ShiftOut) and chain_out.outputs == OUT


@pytest.mark.parametrize("name", list(BY_NAME))
def test_drawn_traces_meet_table_3_4(drawn: dict[str, tuple[SerialIoTrace, dict[str, object]]], name: str) -> None:
    trace = drawn[name][0]
    assert check_serial_io({"mfp_out": trace.mfp_out}, bit_rate=trace.config.bit_rate, bits=16,
                           ser_in=trace.ser_in, first_clock=trace.start) == []  # fmt: skip


@pytest.mark.parametrize("name", list(BY_NAME))
def test_bit_names_sit_on_the_words_bits(drawn: dict[str, tuple[SerialIoTrace, dict[str, object]]],
                                         name: str) -> None:  # fmt: skip
    trace, wavejson = drawn[name]
    lanes = _lanes(wavejson)
    assert list(lanes)[:3] == ["/SS (MFP5)", "SCLK (MFP4)", "SerOut (MFP7)"] and list(lanes)[-1] == "/Conv (MFP3)"
    frames = len(trace.sequence.frames)
    assert str(lanes["SCLK (MFP4)"]["wave"]).count("1") == 16 * frames
    assert str(lanes["/SS (MFP5)"]["wave"]).replace(".", "").replace("|", "") == "10" * frames + "1"
    for bits_lane, level_lane, word in (("SerOut bit", "SerOut (MFP7)", trace.out_word),
                                        ("SerIn bit", "SerIn (MFP6)", trace.in_word)):  # fmt: skip
        if bits_lane not in lanes:
            continue
        assert lanes[bits_lane]["data"] == [f"D{15 - j}" for j in range(16)]
        for j, (first, last) in enumerate(_segments(lanes[bits_lane])):
            levels = {_level(lanes[level_lane], k) for k in range(first, last + 1)}
            assert levels == {str((word >> (15 - j)) & 1)}, (bits_lane, j)
    assert ("SerOut bit" in lanes) == (trace.sequence.write is not None)
    assert ("SerIn bit" in lanes) == (trace.sequence.read is not None)
    conv = str(lanes["/Conv (MFP3)"]["wave"]).replace(".", "").replace("|", "")
    assert conv == ("1" if trace.sequence.conv is None else "101")


def test_only_the_input_output_figure_has_the_t10_gap(
        drawn: dict[str, tuple[SerialIoTrace, dict[str, object]]]) -> None:  # fmt: skip
    for name, (_, wavejson) in drawn.items():
        waves = [str(lane["wave"]) for lane in _lanes(wavejson).values()]
        gaps = {wave.index("|") if "|" in wave else None for wave in waves}
        assert gaps == ({None} if name != "fig3-3" else {40}), name
        assert ("edge" in wavejson) == (name == "fig3-3")
    assert drawn["fig3-3"][1]["edge"] == ["a<->b t10 = 51 t0"]
    node = str(_lanes(drawn["fig3-3"][1])["/SS (MFP5)"]["node"])
    assert node.index("a") == 38 and node.index("b") == 43  # the read /SS rise and the write /SS fall


def test_a_trace_breaking_table_3_4_is_not_drawn(monkeypatch: pytest.MonkeyPatch) -> None:
    # SerIn answering in the clock of the SCLK rise: it changes at the sampling edge (Table 3-4 t4, t5).
    monkeypatch.setattr(figures, "PERIPHERAL_DELAY_CLOCKS", 0)
    with pytest.raises(TraceTimingError, match=r"Table 3-4 t[45] "):
        BY_NAME["fig3-1"].wavejson()


def test_serin_needs_an_answer_to_every_pin_change() -> None:
    mfp = np.array([0x28, 0x28, 0x08, 0x18, 0x18, 0x18], dtype=np.int64)
    answers = [(Levels(conv_n=1, sclk=0, ss_n=0, ser_out=0).mfp(), 1), (0x18, 0), (0x18, 0)]
    # Each answer from 2 clocks after its change (SM-10); a repeated call with unchanged pins is one change.
    assert figures._answered(mfp, answers, 2).tolist() == [0, 0, 0, 0, 1, 0]
    assert figures._answered(mfp, [(0x28, 1), *answers], 2).tolist() == [1, 1, 1, 1, 1, 0]  # told when attached
    with pytest.raises(FigureTraceError, match="saw 1 pin changes"):
        figures._answered(mfp, answers[:1], 2)
    with pytest.raises(FigureTraceError, match="answered 0, then 1 to unchanged pins 0x18"):
        figures._answered(mfp, [*answers, (0x18, 1)], 2)


def test_figure_title_marks_the_redraw() -> None:
    figure: Figure[SerialIoTrace] = BY_NAME["fig3-2"]
    assert figure.title == "Figure 3-2 Serial output mode timing (redrawn from the model)"

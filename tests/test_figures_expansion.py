"""Figure 3-23 (serial register expansion, manual 3.5, Table 3-15) redrawn from a pin-level ring trace with an IBS
SRE 1 chain attached: the chain took the data cycle's OUT data and the master got its IN data, the trace meets Table
3-15, the bit names sit on the bits the chip sent and took, and generation fails on a trace that breaks the table."""

from __future__ import annotations

import pytest

from supi3 import figures
from supi3.expansion import line_to_chain
from supi3.figures import EXPANSION_FIGURES, EXPANSION_IN, EXPANSION_OUT, ExpansionTrace, expansion_wavejson
from supi3.interbus.wire import LOOPBACK_BYTES_ON_LINE
from supi3.verif.timing import TraceTimingError, check_expansion

(FIGURE,) = EXPANSION_FIGURES


@pytest.fixture(scope="module")
def drawn() -> tuple[ExpansionTrace, dict[str, object]]:
    return FIGURE.wavejson()


def _lanes(wavejson: dict[str, object]) -> dict[str, dict[str, object]]:
    signal = wavejson["signal"]
    assert isinstance(signal, list)
    return {lane["name"]: lane for lane in signal}


def _segments(wave: str) -> list[tuple[int, int]]:
    """(first, last) column of each ``=`` segment of a data lane."""
    starts = [k for k, ch in enumerate(wave) if ch == "="]
    return [(k, next((m for m in range(k + 1, len(wave)) if wave[m] not in ".|"), len(wave)) - 1) for k in starts]


def _level(wave: str, column: int) -> int:
    return int(next(ch for ch in reversed(wave[: column + 1]) if ch not in ".|"))


def test_the_chain_took_the_out_data_and_gave_the_in_data(drawn: tuple[ExpansionTrace, dict[str, object]]) -> None:
    trace, _ = drawn
    assert FIGURE.name == "fig3-23" and FIGURE.draw is expansion_wavejson
    assert trace.chain.outputs == line_to_chain(EXPANSION_OUT) == b"\x78\x56\x14"  # Figure 3-24
    assert trace.chain.contents() == trace.chain.inputs == EXPANSION_IN  # /LaInD loaded the next IN data
    assert trace.out_byte == 0x78 and trace.in_byte == LOOPBACK_BYTES_ON_LINE[-1]


def test_drawn_trace_meets_table_3_15(drawn: tuple[ExpansionTrace, dict[str, object]]) -> None:
    trace, _ = drawn
    pins = {name: trace.pins[name] for name in ("clk_exr", "to_exr", "la_ou_d", "la_in_d_n")}
    pins["res_reg_n"] = trace.pins["clk_exr"] * 0 + 1
    assert check_expansion(pins, bit_rate=trace.config.bit_rate, from_exr=trace.pins["from_exr"],
                           first_clock=trace.start) == []  # fmt: skip


def test_bit_names_sit_on_the_bits(drawn: tuple[ExpansionTrace, dict[str, object]]) -> None:
    trace, wavejson = drawn
    lanes = _lanes(wavejson)
    assert list(lanes) == ["ClkExR", "ToExR", "ToExR bit", "FromExR", "FromExR bit", "LaOuD", "/LaInD"]
    assert str(lanes["ClkExR"]["wave"]).count("1") == 8
    for bits, level, byte in (("ToExR bit", "ToExR", trace.out_byte), ("FromExR bit", "FromExR", trace.in_byte)):
        assert lanes[bits]["data"] == [f"D{k}" for k in range(8)]
        for k, (_, last) in enumerate(_segments(str(lanes[bits]["wave"]))):
            # The level at the segment's last column (FromExR: the chip's sample; ToExR: the bit's last quarter).
            assert _level(str(lanes[level]["wave"]), last) == (byte >> k) & 1, (bits, k)
    assert str(lanes["LaOuD"]["wave"]).replace(".", "").replace("|", "") == "010"
    assert str(lanes["/LaInD"]["wave"]).replace(".", "").replace("|", "") == "101"
    waves = [str(lane["wave"]) for lane in lanes.values()]
    assert len({wave.index("|") for wave in waves}) == 1 and all(wave.count("|") == 1 for wave in waves)
    assert wavejson["edge"] == ["a<->b t6", "b<->c t7", "c<->d t5"]
    ou, lain = str(lanes["LaOuD"]["wave"]), str(lanes["/LaInD"]["wave"])
    ou_node, lain_node = str(lanes["LaOuD"]["node"]), str(lanes["/LaInD"]["node"])
    assert (ou_node.index("a"), ou_node.index("b")) == (ou.index("1"), ou.rindex("0"))
    assert (lain_node.index("c"), lain_node.index("d")) == (lain.rindex("0"), lain.rindex("1"))
    # 4 t0 high, 5 t0 between, 4 t0 low: 16, 20 and 16 quarter-bit columns.
    assert ou.rindex("0") - ou.index("1") == 16 and lain.rindex("0") - ou.rindex("0") == 20
    assert lain.rindex("1") - lain.rindex("0") == 16


def test_a_trace_breaking_table_3_15_is_not_drawn(monkeypatch: pytest.MonkeyPatch) -> None:
    # A chain answering 10 clocks late: FromExR changes 6 clocks before the next ClkExR rise, less than the setup
    # time 0.25 t0 + 100 ns before it (Table 3-15 t3).
    monkeypatch.setattr(figures, "PERIPHERAL_DELAY_CLOCKS", 10)
    with pytest.raises(TraceTimingError, match=r"Table 3-15 t3 "):
        FIGURE.wavejson()

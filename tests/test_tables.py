"""Every row of every transcribed table, checked against the manual's own text, plus the rules between tables."""

from __future__ import annotations

import pytest

from supi3 import tables
from supi3.config import DataDirection, MfpKind, decode, parse_function
from supi3.errors import ConfigurationError

HEX = "0123456789ABCDEF"


def _rows_starting(lines: list[list[str]], first: list[str]) -> list[list[str]]:
    return [f for f in lines if f[: len(first)] == first]


# ------------------------------------------------------------------------------------------------------------
# Operating modes, Tables 2-4 to 2-7
# ------------------------------------------------------------------------------------------------------------


def _mode_lines(lines: list[list[str]]) -> list[list[str]]:
    return [f for f in lines if len(f) >= 8 and all(x in "01" for x in f[:5])
            and any(f[-1].startswith(p) for p in ("LB", "RB", "BK"))]


@pytest.mark.parametrize("row", tables.MODE_ROWS, ids=lambda r: f"{r.table}:{r.c}:{r.mfp}")
def test_mode_row_is_in_the_manual(row: tables.ModeRow, manual_lines: list[list[str]]) -> None:
    matches = [
        f for f in _mode_lines(manual_lines)
        if f[:5] == list(row.c) and f[-3:] == [row.length_code, f"{row.id_code:02X}", row.function]
        and (row.mfp is None or f[5:9] == list(row.mfp))
    ]
    assert len(matches) == 1


def test_mode_tables_have_no_untranscribed_row(manual_lines: list[list[str]]) -> None:
    assert len(_mode_lines(manual_lines)) == len(tables.MODE_ROWS) == 77
    assert {r.table for r in tables.MODE_ROWS} == set(tables.MODE_TABLE_TITLES)


def test_mode_table_titles_are_the_manuals(manual_lines: list[list[str]]) -> None:
    # The manual's list of tables (appendix C 2) gives each title followed by its page number.
    for number, title in tables.MODE_TABLE_TITLES.items():
        assert any(f[:1] == [f"Table {number}:"] and f[1].startswith(title) for f in manual_lines)


def test_every_mode_selects_a_unique_interface_and_mfp_mode() -> None:
    keys = [parse_function(r.function) for r in tables.MODE_ROWS]
    assert len(set(keys)) == len(keys)
    assert len({(r.c, r.mfp) for r in tables.MODE_ROWS}) == len(tables.MODE_ROWS)


def test_every_mode_id_code_exists_in_table_a3() -> None:
    for row in tables.MODE_ROWS:
        assert row.id_code in tables.ID_CODE_VALUES, row


def test_every_mode_length_code_decodes_through_table_3_11() -> None:
    for row in tables.MODE_ROWS:
        assert tables.LENGTH_CODE_BY_VALUE[int(row.length_code, 2)].bits is not None, row


@pytest.mark.parametrize("row", tables.MODE_ROWS, ids=lambda r: r.function)
def test_mode_length_and_id_agree_with_the_function(row: tables.ModeRow) -> None:
    _, mode = parse_function(row.function)
    bits = tables.LENGTH_CODE_BY_VALUE[int(row.length_code, 2)].bits
    if mode.kind in (MfpKind.BINARY_IO, MfpKind.SPI_MASTER):
        # The data length is the width of one direction, and the ID code's two low bits give the direction
        # (01 output, 10 input, 11 input/output: Table A-3).
        assert bits == mode.width
        expected = {DataDirection.OUT: 0b01, DataDirection.IN: 0b10, DataDirection.IN_OUT: 0b11}
        assert row.id_code & 0b11 == expected[mode.direction]
    elif mode.kind is MfpKind.INIT_UP:
        # Until software writes SET: zero data length and a µP_Not_Ready code (3.4.1).
        assert bits == 0
        assert row.id_code in tables.UP_NOT_READY_ID_CODES
    else:
        assert bits == 0


def test_configuration_expansion_rows_cover_mfp_0000_to_1110() -> None:
    by_c: dict[str, list[str]] = {}
    for row in tables.MODE_ROWS:
        if row.mfp is not None:
            by_c.setdefault(row.c, []).append(row.mfp)
    assert set(by_c) == {"01011", "11011", "11111", "10011"}
    for patterns in by_c.values():
        assert patterns == [f"{i:04b}" for i in range(15)]


# ------------------------------------------------------------------------------------------------------------
# Length codes, Tables 3-11, A-5 and 3-12
# ------------------------------------------------------------------------------------------------------------


def test_length_codes_cover_all_32_codes_in_order() -> None:
    assert [int(lc.code, 2) for lc in tables.LENGTH_CODES] == list(range(32))


@pytest.mark.parametrize("lc", [lc for lc in tables.LENGTH_CODES if not lc.code.startswith("11")],
                         ids=lambda lc: lc.code)
def test_length_code_row_is_in_tables_3_11_and_a_5(lc: tables.LengthCode, manual_lines: list[list[str]]) -> None:
    expected = [*lc.code, lc.text] + ([lc.firmware] if lc.firmware else [])
    # Once in Table 3-11, once in Table A-5.
    assert manual_lines.count(expected) == 2


def test_reserved_11xxx_row_is_in_both_tables(manual_lines: list[list[str]]) -> None:
    assert manual_lines.count(["1", "1", "x", "x", "x", "Reserved"]) == 2
    assert all(lc.bits is None for lc in tables.LENGTH_CODES if lc.code.startswith("11"))


def _bits_of(text: str) -> int:
    """Bits in the manual's wording of a data length ("2 words", "4 bits (1 nibble)")."""
    unit = {"word": 16, "words": 16, "byte": 8, "bytes": 8, "bits": 1, "nibble": 4}
    count, name = text.split()[:2]
    return int(count) * unit[name]


def test_length_code_bits_agree_with_wording() -> None:
    for lc in tables.LENGTH_CODES:
        if lc.bits is None:
            assert lc.text == "Reserved"
        else:
            assert lc.bits == _bits_of(lc.text)


@pytest.mark.parametrize("row", tables.ABBREVIATED_LENGTHS, ids=lambda r: r.cl)
def test_table_3_12_row(row: tables.AbbreviatedLength, manual_lines: list[list[str]]) -> None:
    assert [*row.cl, row.text, row.length_code] in manual_lines
    decoded = tables.LENGTH_CODE_BY_VALUE[int(row.length_code, 2)]
    assert decoded.bits is not None
    assert decoded.bits == _bits_of(row.text)


# ------------------------------------------------------------------------------------------------------------
# ID codes, Table A-3
# ------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("row", tables.ID_CODES, ids=lambda r: f"{r.code:02X}:{r.description}")
def test_id_code_row_is_in_table_a3(row: tables.IdCode, manual_lines: list[list[str]]) -> None:
    hits = [f for f in manual_lines if len(f) >= 4 and f[-2:] == [str(row.code), f"{row.code:02X}"]
            and f[0].startswith(row.description)]
    assert hits, row
    if row.note:
        assert any(f[0].endswith(row.note) for f in hits)


def test_id_code_groups_are_in_the_manual(manual_text: str) -> None:
    for group in {r.group for r in tables.ID_CODES}:
        assert group in manual_text


def test_up_not_ready_codes() -> None:
    assert {0x38, 0x3C, 0x78, 0x6C, 0x68} == tables.UP_NOT_READY_ID_CODES


# ------------------------------------------------------------------------------------------------------------
# MFP assignments, Tables 3-1, 3-2, 3-3, 3-5, 3-6, 2-8
# ------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("mode", [m for m, t in tables.BINARY_IO_TABLE.items() if t == "3-1"])
def test_table_3_1_row(mode: str, manual_lines: list[list[str]]) -> None:
    (line,) = [f for f in manual_lines if f[:1] == ["C[85]"] and f[-1] == mode]
    printed = [cell.replace("ln", "In") for cell in line[1:13]]  # MFP11 .. MFP0
    pins = {p.pin: p.signal for p in tables.BINARY_IO_MFP[mode]}
    assert printed == [pins.get(pin, "-") for pin in range(11, -1, -1)]


@pytest.mark.parametrize("mode", [m for m, t in tables.BINARY_IO_TABLE.items() if t == "3-2"])
def test_table_3_2_row(mode: str, manual_text: str) -> None:
    # Table 3-2's text copy is garbled; its operating modes and cell texts can still be asserted.
    assert mode in manual_text
    pins = tables.BINARY_IO_MFP[mode]
    assert sorted(p.pin for p in pins) == list(range(16))
    width = 16 if mode != "8 IN/8 OUT" else 8
    for p in pins:
        assert p.signal[:-1].rstrip("0123456789") in ("In", "Out")
        assert int(p.signal.lstrip("InOut")) < width


def test_binary_modes_directions() -> None:
    for mode, pins in tables.BINARY_IO_MFP.items():
        n_in = sum(p.direction is tables.PinDirection.IN for p in pins)
        n_out = sum(p.direction is tables.PinDirection.OUT for p in pins)
        width = int(mode.split()[0])
        assert (n_in, n_out) == (width if "IN" in mode else 0, width if "OUT" in mode else 0)


def _check_pin_table(rows: tuple[tables.PinFunction, ...], manual_lines: list[list[str]], label: str) -> None:
    directions = {"IN": tables.PinDirection.IN, "OUT": tables.PinDirection.OUT, "I/O": tables.PinDirection.INOUT}
    for pin in rows:
        hits = [f for f in manual_lines if len(f) >= 3 and f[0] in (f"{label}{pin.pin}", str(pin.pin))
                and f[1] == pin.signal]
        assert hits, pin
        if label == "":
            assert any(directions.get(f[-1]) is pin.direction for f in hits), pin


def test_table_3_3_spi_master_pins(manual_lines: list[list[str]]) -> None:
    named = [p for p in tables.SPI_MASTER_MFP if p.pin < 8]
    _check_pin_table(tuple(named), manual_lines, "MFP")
    assert ["MFP118", "GND", "Does not serve any function"]  # sic: "MFP11..8" in manual_lines


def test_table_3_5_motorola_pins(manual_lines: list[list[str]]) -> None:
    _check_pin_table(tables.UP_MOTOROLA_MFP, manual_lines, "")


def test_table_3_6_intel_pins(manual_lines: list[list[str]]) -> None:
    _check_pin_table(tables.UP_INTEL_MFP, manual_lines, "")


def test_table_2_8_bus_terminal_pins(manual_lines: list[list[str]]) -> None:
    _check_pin_table(tables.BUS_TERMINAL_MFP, manual_lines, "")
    assert [p.pin for p in tables.BUS_TERMINAL_MFP] == list(range(8, 16))


# ------------------------------------------------------------------------------------------------------------
# Pins, Tables 1-2, 1-3, 1-4
# ------------------------------------------------------------------------------------------------------------


def _pin_table(lines: list[list[str]]) -> dict[int, str]:
    found: dict[int, str] = {}
    for f in lines:
        if len(f) in (2, 4, 6) and all(x.isdigit() for x in f[0::2]):
            for number, name in zip(f[0::2], f[1::2], strict=True):
                found[int(number)] = name.replace("V _{cc}", "Vcc")
    return found


def test_table_1_2_and_1_3_pins(manual_lines: list[list[str]]) -> None:
    split = next(i for i, f in enumerate(manual_lines) if f == ["TQFP 44 pin board"])
    end = next(i for i, f in enumerate(manual_lines) if f and f[0] == "1.5 Pin description")
    tqfp64 = _pin_table(manual_lines[:split])
    tqfp44 = _pin_table(manual_lines[split:end])
    assert tqfp64 == {i + 1: name for i, name in enumerate(tables.TQFP64_PINS)}
    assert tqfp44 == {i + 1: name for i, name in enumerate(tables.TQFP44_PINS)}


@pytest.mark.parametrize("row", tables.PIN_DESCRIPTIONS, ids=lambda r: r.designation)
def test_table_1_4_row(row: tables.PinDescription, manual_lines: list[list[str]]) -> None:
    designation = row.designation.replace("[1..0]", "[10]").replace("[3..0]", "[30]").replace("[15..0]", "[150]")
    designation = designation.replace("Vcc", "V _{cc}")
    marks = ["X", "X" if row.tqfp44 else "-"]
    cell = [] if row.cell is None else [row.cell.replace("CIp", "Clp")]
    hits = [f for f in manual_lines if f[:1] == [designation] and len(f) >= 4]
    assert any(f == [designation, row.meaning, *cell, *marks]
               or (f[-1] == "_" and f[:-1] == [designation, row.meaning, *cell, "X"]) for f in hits), hits


def test_every_package_pin_has_a_description() -> None:
    def expand(designation: str) -> set[str]:
        if "[" not in designation:
            return {designation}
        base, rng = designation.rstrip("]").split("[")
        hi, lo = map(int, rng.split(".."))
        return {f"{base}{i}" for i in range(lo, hi + 1)}

    described = set().union(*(expand(r.designation) for r in tables.PIN_DESCRIPTIONS))
    on44 = set().union(*(expand(r.designation) for r in tables.PIN_DESCRIPTIONS if r.tqfp44))
    assert set(tables.TQFP64_PINS) <= described
    assert set(tables.TQFP44_PINS) <= on44
    assert all(r.cell is None or r.cell in tables.CELL_TYPES for r in tables.PIN_DESCRIPTIONS)


def test_cell_types_are_the_manuals(manual_lines: list[list[str]]) -> None:
    for code, meaning in tables.CELL_TYPES.items():
        assert [f"{code.replace('CIp', 'Clp')}:", meaning] in manual_lines


# ------------------------------------------------------------------------------------------------------------
# Clock, RF, diagnostics, address map
# ------------------------------------------------------------------------------------------------------------


def test_table_1_7_clock_configurations(manual_lines: list[list[str]]) -> None:
    for row in tables.CLOCK_CONFIGURATIONS:
        rate = {500_000: ["500 kbps"], 2_000_000: ["2 Mbps"], None: []}[row.bit_rate]
        assert [row.clk_conf1, row.clk_conf0, row.clock_source, *rate] in manual_lines


def test_table_1_6_clock_timing(manual_lines: list[list[str]]) -> None:
    for row in tables.CLOCK_TIMING:
        values = [f"{v:g}" for v in (row.minimum, row.typical, row.maximum)]
        assert any(len(f) > 5 and [f[0].lower(), f[1]] == [row.designation, row.name] and f[-4:-1] == values
                   for f in manual_lines), row
    # The ±3.125 ps tolerance row is ±100 ppm of the 31.25 ns period.
    assert tables.CLOCK_TIMING[0].typical * 1e3 * tables.CLOCK_PPM * 1e-6 == tables.CLOCK_PERIOD_TOLERANCE_PS
    assert tables.CLOCK_TIMING[0].typical == 1e9 / tables.CLOCK_HZ


def test_table_2_2_and_2_9_rf_modes(manual_lines: list[list[str]]) -> None:
    manual_rows = [row for row in tables.RF_MODES if row.rf != "01"]
    for row in manual_rows:
        assert [*row.rf, row.rbst_ext, row.function] in manual_lines
        lbst = [f for f in manual_lines if f[:2] == list(row.rf) and f[-1].startswith(row.lbst_function)]
        assert lbst, row
    assert {r.rf for r in manual_rows} == {"10", "11", "00"}
    # RF = 01 is the optical diagnostics mode of 1.6.2 (OPT-2): fibre, no regulation, the LBST function of RF = 00.
    (diagnostics,) = (row for row in tables.RF_MODES if row.rf == "01")
    assert "OPT-2" in diagnostics.function and not diagnostics.optical_regulation
    assert diagnostics.medium == "fiber optic"
    assert diagnostics.lbst_function == next(r.lbst_function for r in manual_rows if r.rf == "00")


def test_tables_3_16_to_3_19_diagnostics(manual_lines: list[list[str]]) -> None:
    for d in tables.DIAG_CONFIGURATIONS:
        assert [str(d.diag_conf), d.kind, d.diag1, d.diag2] in manual_lines
    for signal, pin, interface in tables.FIBER_OPTIC_DIAGNOSTICS:
        assert any(f[:2] == [signal, pin] and interface in f for f in manual_lines)
    for state, _, cause in tables.LIMITED_DIAGNOSTICS:
        assert [state, cause] in manual_lines
    for row in tables.COMPLETE_DIAGNOSTICS:
        assert list(row) in manual_lines


def test_table_3_10_address_map(manual_lines: list[list[str]]) -> None:
    assert [r.address for r in tables.ADDRESS_MAP] == list(range(16))
    for r in tables.ADDRESS_MAP:
        assert [str(r.address), r.write or "-", r.read] in manual_lines


# ------------------------------------------------------------------------------------------------------------
# Timing tables 3-4, 3-7, 3-15 and the optical length table 1-5
# ------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("table", [tables.SPI_MASTER_TIMING, tables.UP_INTERFACE_TIMING,
                                   tables.REGISTER_EXPANSION_TIMING], ids=["3-4", "3-7", "3-15"])
def test_timing_explanations_are_the_manuals(table: tuple[tables.TimingParameter, ...], manual_text: str) -> None:
    text = manual_text.replace("C*/D", "C/D").replace("S/R*", "S/R")
    for row in table:
        words = row.explanation.split(" (")[0]
        assert words in text, row


def test_table_1_5_optical_ranges(manual_lines: list[list[str]]) -> None:
    speed = {500_000: "500 kbaud", 2_000_000: "2 Mbytes"}  # sic, the manual's wording
    for row in tables.OPTICAL_LENGTH_RANGES:
        lo, hi = row.values
        values = f"{lo} to {hi}" if lo != hi else str(lo)
        assert any(f[-2:] == [values, speed[row.bit_rate]] for f in manual_lines), row
    # 1.6.1's formula gives 1 / (16 * bit rate * 5 ns/m) metres per timer count: 25 m at 500 kbit/s and
    # 6.25 m at 2 Mbit/s, the typical resolutions Table 1-5 rounds to 24 m and 6 m.
    for row in tables.OPTICAL_LENGTH_RANGES:
        if row.resolution_m:
            per_count = 1 / (tables.LENGTH_TIMER_CLOCKS_PER_BIT * row.bit_rate * tables.LIGHT_RUNTIME_S_PER_M)
            assert abs(per_count - row.resolution_m[0]) / row.resolution_m[0] < 0.05


def test_clk_conf_for_every_data_rate_and_nothing_else() -> None:
    """Table 1-7 read backwards: each data rate's CLK_CONF[1..0] decodes to it; the reserved row and values that
    only compare equal to a rate (a float, True) select nothing."""
    for rate in tables.BIT_RATES:
        assert decode("10000", clk_conf=tables.clk_conf_for(rate)).bit_rate == rate
    for bad in (None, 2e6, True, "2M", 1_000_000):
        with pytest.raises(ConfigurationError, match="Table 1-7"):
            tables.clk_conf_for(bad)  # type: ignore[arg-type]

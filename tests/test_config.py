"""Pin-strap decoding: every mode row, every error rule, the whole input space, and the round trip."""

from __future__ import annotations

import functools
import itertools
from collections.abc import Iterator

import pytest
from hypothesis import given
from hypothesis import strategies as st

from supi3 import tables
from supi3.config import (
    DataDirection,
    DeviceConfig,
    Interface,
    MfpKind,
    Straps,
    Variant,
    decode,
    decode_straps,
    mode_rows,
)
from supi3.errors import ConfigurationError


def _bit_strings(width: int) -> list[str]:
    return [format(i, f"0{width}b") for i in range(1 << width)]


def _all_straps() -> Iterator[Straps]:
    """The whole pin-strap input space: every C, MFP, RF, CLK_CONF and DIAG_CONF value on both variants."""
    for variant, c, mfp, rf, clk, diag in itertools.product(
        Variant, _bit_strings(5), [None, *_bit_strings(4)], [None, *_bit_strings(2)], _bit_strings(2), [None, "0", "1"]
    ):
        yield Straps(c, mfp, rf, clk, diag, variant)


@functools.cache
def _outcomes() -> tuple[list[tuple[Straps, DeviceConfig]], list[tuple[Straps, ConfigurationError]]]:
    """Every strap combination decoded: 65,280 decodes, made once by the first test that needs them rather than at
    collection, which every xdist worker and every run of other tests would pay (tests/README.md, "Run time")."""
    valid: list[tuple[Straps, DeviceConfig]] = []
    invalid: list[tuple[Straps, ConfigurationError]] = []
    for straps in _all_straps():
        try:
            valid.append((straps, decode_straps(straps)))
        except ConfigurationError as exc:
            invalid.append((straps, exc))
    return valid, invalid


def test_whole_input_space_decodes_or_raises_configuration_error() -> None:
    # Any other exception escapes _outcomes() and fails the test.
    valid, invalid = _outcomes()
    assert len(valid) + len(invalid) == 2 * 32 * 17 * 5 * 4 * 3
    # OPC: 77 mode rows x CLK_CONF {01, 11} x RF {open, 10, 11, 00, 01 (OPT-2)} x DIAG_CONF {open, 0, 1};
    # LS: the 54 rows with C4 = 1 x CLK_CONF {01, 11}, RF and DIAG_CONF absent.
    assert len(valid) == 77 * 2 * 5 * 3 + 54 * 2


def test_every_error_names_pins_value_and_rule() -> None:
    for _, exc in _outcomes()[1]:
        assert exc.pins and exc.value and exc.rule
        assert "Table" in exc.rule or exc.rule.startswith(("1.", "3."))
        assert exc.pins in str(exc) and exc.rule in str(exc)


def test_every_valid_configuration_round_trips() -> None:
    for straps, config in _outcomes()[0]:
        assert decode_straps(config.straps()) == config
        explicit = config.straps()
        # Open CIp pins read as 1; explicit straps come back unchanged.
        if None not in (straps.rf, straps.diag_conf) or straps.variant is Variant.LS:
            assert explicit == straps


@pytest.mark.parametrize("row", tables.MODE_ROWS, ids=lambda r: f"{r.c}:{r.mfp}:{r.function}")
def test_every_mode_row_decodes(row: tables.ModeRow) -> None:
    config = decode(row.c, row.mfp)
    assert config.function == row.function
    assert config.id_code == row.id_code
    assert f"{config.length_code:05b}" == row.length_code
    assert config.table == row.table
    assert config.interface.value == row.function.split(",")[0].split(" ")[0]
    if row.c[0] == "1":
        assert decode(row.c, row.mfp, variant="ls").function == row.function
    else:
        with pytest.raises(ConfigurationError, match="C4 is set to 1 in the SUPI 3 LS") as info:
            decode(row.c, row.mfp, variant="ls")
        assert info.value.pins == "C4"


@pytest.mark.parametrize(
    ("kwargs", "pins", "rule"),
    [
        ({"c": "00101"}, "C[4..0]", "Tables 2-4 to 2-7"),
        ({"c": "01100"}, "C[4..0]", "Tables 2-4 to 2-7"),
        ({"c": "01011"}, "MFP[15..12]", "Table 2-4"),
        ({"c": "11111", "mfp": "1111"}, "MFP[15..12]", "Table 2-5"),
        ({"c": "10011", "mfp": "1111"}, "MFP[15..12]", "Table 2-6"),
        ({"c": "10000", "mfp": "0000"}, "MFP[15..12]", "Table 2-6"),
        ({"c": "00000", "mfp": "0000"}, "MFP[15..12]", "Table 2-7"),
        ({"c": "10000", "clk_conf": "00"}, "CLK_CONF[1..0]", "Table 1-7"),
        ({"c": "10000", "clk_conf": "10"}, "CLK_CONF[1..0]", "Table 1-7"),
        ({"c": "10000", "rf": "11", "variant": "ls"}, "RF[1..0]", "Table 1-4; 1.6"),
        ({"c": "10000", "diag_conf": "1", "variant": "ls"}, "DIAG_CONF", "Table 1-4; Table 3-16"),
        ({"c": "00000", "variant": "ls"}, "C4", "Tables 2-4 to 2-6, footnote *; Table 1-4"),
        ({"c": "10000", "variant": "tqfp"}, "variant", "Table 1-1"),
        ({"c": "1000"}, "C[4..0]", "input format"),
        ({"c": 32}, "C[4..0]", "input format"),
        ({"c": "10000", "mfp": "2"}, "MFP[15..12]", "input format"),
    ],
)
def test_named_errors(kwargs: dict[str, str], pins: str, rule: str) -> None:
    with pytest.raises(ConfigurationError) as info:
        decode(**kwargs)
    assert (info.value.pins, info.value.rule) == (pins, rule)


@given(
    c=st.one_of(st.integers(-5, 40), st.text(max_size=7), st.booleans(), st.none(), st.floats()),
    mfp=st.one_of(st.none(), st.integers(-2, 20), st.text(max_size=5)),
    rf=st.one_of(st.none(), st.integers(-1, 5), st.text(max_size=3)),
    clk=st.one_of(st.integers(-1, 5), st.text(max_size=3)),
    diag=st.one_of(st.none(), st.integers(-1, 3), st.text(max_size=2)),
    variant=st.one_of(st.sampled_from(["opc", "ls"]), st.text(max_size=4)),
)
def test_arbitrary_input_only_raises_configuration_error(
    c: object, mfp: object, rf: object, clk: object, diag: object, variant: str
) -> None:
    try:
        config = decode(c, mfp, rf, clk, diag, variant)  # type: ignore[arg-type]  # deliberately ill-typed
    except ConfigurationError:
        return
    assert decode_straps(config.straps()) == config


@given(st.deferred(lambda: st.sampled_from([cfg for _, cfg in _outcomes()[0]])))
def test_configuration_to_pins_to_configuration(config: DeviceConfig) -> None:
    assert decode_straps(config.straps()) == config


def test_open_cip_pins_read_as_pull_ups() -> None:
    config = decode("10000")
    assert config.rf_mode is not None and config.rf_mode.rf == "11"
    assert config.diagnostics is not None and config.diagnostics.diag_conf == 1
    assert not config.optical_regulation
    assert decode("10000", rf="00").optical_regulation


def test_bit_rates_from_clk_conf() -> None:
    assert decode("10000", clk_conf="01").bit_rate == 500_000
    assert decode("10000", clk_conf="11").bit_rate == 2_000_000
    assert decode(0b10000, clk_conf=0b11).bit_rate == 2_000_000


def test_ls_variant() -> None:
    config = decode("11011", "1110", variant="ls")
    assert config.variant is Variant.LS
    assert config.rf_mode is None and config.diagnostics is None
    assert config.package_pins == tables.TQFP44_PINS
    assert len(list(mode_rows("ls"))) == 54
    assert decode("10000").package_pins == tables.TQFP64_PINS


@pytest.mark.parametrize("mode", list(tables.BINARY_IO_MFP))
def test_binary_io_pins_follow_tables_3_1_and_3_2(mode: str) -> None:
    configs = [decode(r.c, r.mfp) for r in tables.MODE_ROWS]
    matching = [c for c in configs if c.mfp_mode.kind is MfpKind.BINARY_IO and c.mfp_mode.name == mode]
    assert len(matching) == 4  # one per interface: LB-MR, LBD-MR, LBD-OR, RB
    for config in matching:
        pins = {p.pin: p for p in config.mfp_pins}
        for expected in tables.BINARY_IO_MFP[mode]:
            assert pins[expected.pin] == expected
        if tables.BINARY_IO_TABLE[mode] == "3-1":
            assert [pins[p].signal for p in range(12, 16)] == ["C5", "C6", "C7", "C8"]
        outputs = {p.pin for p in tables.BINARY_IO_MFP[mode] if p.direction is tables.PinDirection.OUT}
        assert config.mfp_output_mask == sum(1 << p for p in outputs)


def test_spi_master_and_up_and_bus_terminal_pins() -> None:
    spi = decode("10011", "1011")
    assert spi.mfp_mode.kind is MfpKind.SPI_MASTER and spi.mfp_mode.width == 32
    assert spi.mfp_mode.direction is DataDirection.IN_OUT
    assert spi.mfp_output_mask == (1 << 3) | (1 << 4) | (1 << 5) | (1 << 7)
    up = decode("10011", "1110")
    assert up.mfp_mode.kind is MfpKind.INIT_UP and up.data_bits == 0 and up.id_code == 0x38
    # MFP7 is an input after every hardware reset until the mode is known (3.4.3).
    assert up.mfp_output_mask == (1 << 1) | (1 << 2) | (1 << 3)
    bk = decode("00000")
    assert bk.interface is Interface.BK_RB and bk.mfp_mode.kind is MfpKind.NONE
    assert bk.mfp_output_mask == sum(1 << p.pin for p in tables.BUS_TERMINAL_MFP
                                     if p.direction is tables.PinDirection.OUT)
    bk_up = decode("00100")
    assert bk_up.interface is Interface.BK_LB and bk_up.mfp_mode.kind is MfpKind.INIT_UP


def test_lbd_or_spi_16_rows_keep_the_manuals_order() -> None:
    # Table 2-5 lists LBD-OR SPI 16 IN before OUT, unlike the other tables; the ID codes agree with that order.
    assert decode("11111", "1001").function == "LBD-OR, SPI 16 IN"
    assert decode("11111", "1001").id_code == 0x72
    assert decode("10011", "1001").function == "RB, SPI 16 OUT"


def test_as_dict_keys() -> None:
    d = decode("10011", "0011").as_dict()
    assert {"interface", "mfp_mode", "id_code", "length_code", "data_bits", "function"} <= set(d)
    assert d["interface"] == "RB" and d["id_code"] == "03" and d["data_bits"] == 4


@pytest.mark.parametrize("value", ["1" * 5000, 10**5000], ids=["long-string", "huge-int"])
def test_huge_strap_values_are_quoted_short(value: str | int) -> None:
    with pytest.raises(ConfigurationError) as caught:
        decode(value)
    assert len(str(caught.value)) < 160


@pytest.mark.parametrize("row", tables.MODE_ROWS, ids=lambda r: f"{r.c}-{r.mfp}")
def test_io_bits_follow_the_pin_tables(row: tables.ModeRow) -> None:
    """In<k>/Out<k> of Tables 3-1/3-2 as (bit, pin) pairs: one per signal, each bit once, only in binary I/O modes."""
    config = decode(row.c, row.mfp)
    for bits, prefix in ((config.in_bits, "In"), (config.out_bits, "Out")):
        signals = {p.pin: p.signal for p in config.mfp_pins if p.signal.startswith(prefix)}
        if config.mfp_mode.kind is not MfpKind.BINARY_IO:
            assert bits == ()
            continue
        assert sorted(pin for _, pin in bits) == sorted(signals)
        assert all(signals[pin] == f"{prefix}{bit}" for bit, pin in bits)
        assert len({bit for bit, _ in bits}) == len(bits)

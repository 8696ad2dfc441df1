"""The optical block in Amaranth (supi3.rtl.optical.OpticalRtl, issue 12): its ports are the spec's
(supi3.optical.regulation.BLOCK_INPUTS / BLOCK_OUTPUTS), its constants come from the spec at elaboration (the LENGTH
code as a shift of the timer count, OPT-1, OPT-24), and it converts to Verilog. Its behaviour, cycle by cycle against
the pin model, is tests/test_verif_lockstep_optical.py."""

from __future__ import annotations

import re

import pytest
from amaranth.back import verilog
from amaranth.lib.wiring import In, Out

from supi3.model.blocks import optical as model_block
from supi3.optical import length as length_spec
from supi3.optical.length import LENGTH_MAX_CODE, Medium, timer_code
from supi3.optical.regulation import BLOCK_INPUTS, BLOCK_OUTPUTS
from supi3.rtl import optical
from supi3.rtl.optical import LENGTH_COUNT_BITS, OpticalRtl, length_shift
from supi3.tables import BIT_RATES


@pytest.mark.parametrize("bit_rate", BIT_RATES)
@pytest.mark.parametrize("medium", list(Medium))
def test_length_code_is_a_shift_of_the_count(bit_rate: int, medium: Medium) -> None:
    """OPT-1: at 500 kbit/s a count is two polymer units (shift 1) and 1/16 glass unit (shift -4); at 2 Mbit/s half a
    polymer unit (shift -1) and 1/64 glass unit (shift -6)."""
    shift = length_shift(bit_rate, medium)
    assert shift == {(500_000, Medium.POLYMER): 1, (500_000, Medium.GLASS): -4,
                     (2_000_000, Medium.POLYMER): -1, (2_000_000, Medium.GLASS): -6}[(bit_rate, medium)]  # fmt: skip
    for n in (0, 1, 2, 31, 32, 63, 64, 125, 126, 1007, 1008, 4031, 4032, (1 << LENGTH_COUNT_BITS) - 1):
        assert timer_code(n, bit_rate, medium) == min(LENGTH_MAX_CODE, n << shift if shift >= 0 else n >> -shift)


def test_a_length_code_that_is_no_shift_is_refused(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(optical, "timer_code", lambda n, _rate, _medium: min(LENGTH_MAX_CODE, n // 3))
    with pytest.raises(ValueError, match="must be a shifted count"):
        length_shift.__wrapped__(BIT_RATES[0], Medium.POLYMER)


def test_the_rtl_timer_keeps_the_narrowest_clock_count_that_gives_every_code() -> None:
    """OPT-24: the RTL's 12 bits of clocks (10 bits of count at 500 kbit/s, 12 at 2 Mbit/s) read as code 63 when all
    ones at every rate and medium, so with its wrapped flag its codes are the model's 14-bit count's; 11 bits would
    not."""
    bits = optical._clock_bits()
    reads = [(optical._prescale_bits(rate), length_shift(rate, medium)) for rate in BIT_RATES for medium in Medium]
    assert bits == 12
    for width, saturates in ((bits, True), (bits - 1, False)):
        count = (1 << width) - 1
        assert all(min(LENGTH_MAX_CODE, count >> p << s if s >= 0 else count >> p >> -s) == LENGTH_MAX_CODE
                   for p, s in reads) is saturates  # fmt: skip


def test_a_length_timer_enable_period_that_is_no_power_of_two_is_refused(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(optical, "length_timer_enable_every", lambda _rate: 3)
    with pytest.raises(ValueError, match="must be a power of two"):
        optical._prescale_bits(BIT_RATES[0])


def test_timer_width_is_the_model_s_and_holds_20_km() -> None:
    """12,800 counts for 20 km one way at 2 Mbit/s fit (1.6.1, Table 1-5)."""
    assert LENGTH_COUNT_BITS == model_block.LENGTH_COUNT_BITS
    assert length_spec.timer_count(length_spec.MAX_PATH_M, BIT_RATES[1]) < 1 << LENGTH_COUNT_BITS


def test_ports_are_the_spec_and_it_converts_to_verilog() -> None:
    """Every pin of BLOCK_INPUTS / BLOCK_OUTPUTS, with its width and direction, and nothing else; Verilog of it."""
    design = OpticalRtl()
    members = design.signature.members
    assert {name: (member.flow, len(getattr(design, name))) for name, member in members.items()} == {
        **{pin.name: (In, pin.width) for pin in BLOCK_INPUTS},
        **{pin.name: (Out, pin.width) for pin in BLOCK_OUTPUTS},
    }
    header = re.search(r"module optical\((.*?)\);", verilog.convert(design, name="optical"))
    assert header is not None
    ports = {port.strip(" \\") for port in header.group(1).split(",")}
    assert ports == {pin.name for pin in (*BLOCK_INPUTS, *BLOCK_OUTPUTS)} | {"clk", "rst"}


def test_a_phase_decode_tells_its_code_from_every_other() -> None:
    """The phase register compares only the bits that tell a phase's code apart (round 4): on every code the
    register can hold exactly one phase decodes true, and no bit of a decode can be left out."""
    codes = range(len(optical.PHASES))
    for phase in optical.PHASES:
        bits = optical._decode_bits(optical._phase(phase))
        own = optical._phase(phase)
        assert [all((c >> b & 1) == (own >> b & 1) for b in bits) for c in codes] == [c == own for c in codes]
        for b in bits:  # leaving out any one bit lets another code through
            narrower = [x for x in bits if x != b]
            assert any(all((c >> x & 1) == (own >> x & 1) for x in narrower) for c in codes if c != own)

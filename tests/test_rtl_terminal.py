"""The bus terminal block in Amaranth (supi3.rtl.terminal.TerminalRtl; manual 2.4): its ports are the spec's
(supi3.terminal.BLOCK_INPUTS / BLOCK_OUTPUTS), its silence timer holds the spec's 10 ms in clocks, and it converts to
Verilog. Its behaviour, cycle by cycle against the pin model, is tests/test_verif_lockstep_terminal.py."""

from __future__ import annotations

import re

from amaranth.back import verilog
from amaranth.lib.wiring import In, Out

from supi3.rtl.terminal import TerminalRtl
from supi3.terminal import BLOCK_INPUTS, BLOCK_OUTPUTS, BRANCH_SILENCE_CLOCKS


def test_ports_are_the_spec_and_it_converts_to_verilog() -> None:
    """Every pin of BLOCK_INPUTS / BLOCK_OUTPUTS, with its width and direction, and nothing else; Verilog of it."""
    design = TerminalRtl()
    members = design.signature.members
    assert {name: (member.flow, len(getattr(design, name))) for name, member in members.items()} == {
        **{pin.name: (In, pin.width) for pin in BLOCK_INPUTS},
        **{pin.name: (Out, pin.width) for pin in BLOCK_OUTPUTS},
    }
    text = verilog.convert(design, name="terminal")
    header = re.search(r"module terminal\((.*?)\);", text, re.DOTALL)
    assert header is not None
    ports = {port.strip(" \\\n") for port in header.group(1).split(",")}
    assert ports == {pin.name for pin in (*BLOCK_INPUTS, *BLOCK_OUTPUTS)} | {"clk", "rst"}
    timer = re.search(r"reg \[(\d+):0\] timer\b", text)
    assert timer is not None and int(timer.group(1)) + 1 == (BRANCH_SILENCE_CLOCKS - 1).bit_length() == 19

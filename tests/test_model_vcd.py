"""VCD output of a pin-level ring (``supi3.model.vcd``): every MFP a mode uses is a named 1-bit signal at its pin
level (Tables 3-1 to 3-6), beside the 16-bit vectors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from vcd.reader import TokenKind, tokenize

from supi3.config import decode
from supi3.errors import ArgumentError
from supi3.interbus.master import Master
from supi3.model.pinring import PinRing
from supi3.model.pins import Supi3Pins
from supi3.model.vcd import mfp_signals, write_vcd


def test_mfp_signal_names_follow_the_mode_tables() -> None:
    assert mfp_signals(decode("10011", "1000"))[:5] == [  # RB, SPI 16 IN/16 OUT (Table 3-3)
        (3, "mfp3_conv_n"), (4, "mfp4_sclk"), (5, "mfp5_ss_n"), (6, "mfp6_serin"), (7, "mfp7_serout")]
    assert mfp_signals(decode("10011", "1110"))[:4] == [  # Init-µP, Motorola/Intel (Tables 3-5, 3-6)
        (0, "mfp0_sas_init"), (1, "mfp1_i_o"), (2, "mfp2_c_d"), (3, "mfp3_irq_n")]
    assert mfp_signals(decode("10000"))[0] == (0, "mfp0_in0")
    with pytest.raises(ArgumentError, match="config must be a DeviceConfig"):
        mfp_signals("10000")  # type: ignore[arg-type]


def _changes(vcd: Path, scope: str) -> dict[str, list[tuple[int, int]]]:
    """(time in ps, value) of every variable of ``scope``."""
    current, names, time = "", {}, 0
    changes: dict[str, list[tuple[int, int]]] = {}
    with vcd.open("rb") as stream:
        for token in tokenize(stream):
            if token.kind is TokenKind.SCOPE:
                current = token.scope.ident
            elif token.kind is TokenKind.VAR and current == scope:
                names[token.var.id_code] = token.var.reference
                changes[token.var.reference] = []
            elif token.kind is TokenKind.CHANGE_TIME:
                time = token.time_change
            elif token.kind is TokenKind.CHANGE_SCALAR and token.scalar_change.id_code in names:
                changes[names[token.scalar_change.id_code]].append((time, int(token.scalar_change.value)))
            elif token.kind is TokenKind.CHANGE_VECTOR and token.vector_change.id_code in names:
                value = token.vector_change.value
                assert isinstance(value, int)
                changes[names[token.vector_change.id_code]].append((time, value))
    return changes


def test_spi_pins_are_named_signals(tmp_path: Path) -> None:
    ring = PinRing([Supi3Pins(decode("10011", "1000", clk_conf="11"))], record=True)
    ring.idle(0.0001)
    master = Master(ring, locate=False)
    assert master.start().ok
    master.set_outputs(1, b"\x5a\xc3")
    assert master.data_cycle().ok
    ring.idle(0.0001)  # the sequence after the latch (SM-2)
    changes = _changes(write_vcd(tmp_path / "spi.vcd", ring), "dev1")
    mfp_out = changes["mfp_out"]
    for pin, name in mfp_signals(ring.devices[0].config)[:5]:
        if pin == 6:  # SerIn: an input, held at 0 by the ring
            assert changes[name] == [(0, 0)]
            continue
        levels = [(t, (v >> pin) & 1) for t, v in mfp_out]
        edges = [(t, b) for (t, b), (_, a) in zip(levels[1:], levels, strict=False) if a != b]
        assert changes[name] == [levels[0], *edges] and edges  # the initial level and the vector bit's edges
    serout = [b for _, b in changes["mfp7_serout"]]
    assert np.count_nonzero(serout) > 0

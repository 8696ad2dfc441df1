"""SlavePins.hold(): held inputs in one step, the same as that many tick() calls (outputs, checks, state); the
whole chip's event-driven run() relies on it (supi3.top; docs/upif.md, "Pin level")."""

from __future__ import annotations

from itertools import groupby

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.config import decode
from supi3.errors import ArgumentError
from supi3.model.registers import RegisterFile
from supi3.spi.master import SoftMaster
from supi3.spi.slave_pins import QUIET_FOREVER, PinsIn, PinsOut, SlavePins
from supi3.spi.upif import Mode, UpifUsageError
from supi3.tables import clk_conf_for

PINS = st.builds(PinsIn, sas_init=st.sampled_from([0, 0, 0, 1]), sclk=st.integers(0, 1), ss_n=st.integers(0, 1),
                 mfp6=st.integers(0, 1), mfp7=st.integers(0, 1))


def interface(bit_rate: int) -> SlavePins:
    return SlavePins(RegisterFile(decode("10011", "1110", clk_conf=clk_conf_for(bit_rate)), strict=False))


def expand(changes: list[tuple[int, PinsOut]], cycles: int) -> list[PinsOut]:
    """Per-cycle outputs from hold()'s (index, outputs) changes."""
    bounds = [i for i, _ in changes[1:]] + [cycles]
    return [out for (start, out), stop in zip(changes, bounds, strict=True) for _ in range(stop - start)]


def master_pieces(bit_rate: int, mode: Mode, values: list[int]) -> list[tuple[PinsIn, int]]:
    """A software µP's pins as (pins, cycles held): initialization, then a write and a read of SET per value."""
    master = SoftMaster(interface(bit_rate), mode)
    master.byte(mode.init_byte)
    for value in values:
        for byte, s_r in ((0x4D, True), (value, True), (0x8D, True), (0, False)):
            master.byte(byte, s_r=s_r)
    master.deselect()
    return [(pins, len(list(run))) for pins, run in groupby(master.trace().inputs)]


@settings(max_examples=60, deadline=None)
@given(bit_rate=st.sampled_from([500_000, 2_000_000]), mode=st.sampled_from(list(Mode)),
       values=st.lists(st.integers(0, 255), max_size=3),
       noise=st.lists(st.tuples(PINS, st.integers(1, 40)), max_size=20),
       chunks=st.lists(st.integers(1, 12), min_size=1))
def test_hold_is_ticks(bit_rate: int, mode: Mode, values: list[int], noise: list[tuple[PinsIn, int]],
                       chunks: list[int]) -> None:
    held, ticked = interface(bit_rate), interface(bit_rate)
    interned: dict[PinsIn, PinsIn] = {}  # equal inputs as one object, as the whole chip passes them
    script = master_pieces(bit_rate, mode, values) + noise
    for k, (fresh, cycles) in enumerate(script):
        pins = interned.setdefault(fresh, fresh)
        expected = [ticked.tick(pins) for _ in range(cycles)]
        got: list[PinsOut] = []
        while len(got) < cycles:  # hold in chunks where the edges are quiet, tick where one acts
            quiet = held.quiet(pins)
            if quiet:
                n = min(chunks[(k + len(got)) % len(chunks)], cycles - len(got), quiet)
                got += expand(held.hold(pins, n), n)
            else:
                got.append(held.tick(pins))
        assert got == expected
        assert held.cycle == ticked.cycle
    assert [str(v) for v in held.registers.violations.records] == [str(v) for v in ticked.registers.violations.records]
    assert (held.protocol.phase, held.protocol.mode) == (ticked.protocol.phase, ticked.protocol.mode)
    # The state left behind is the same: both go on alike.
    for pins in interned.values():
        assert held.tick(pins) == ticked.tick(pins)


def test_quiet_counts_the_edges_before_one_acts_and_hold_refuses_more() -> None:
    upif = interface(2_000_000)
    assert upif.quiet(PinsIn()) == QUIET_FOREVER  # after reset: idle levels everywhere
    selected = PinsIn(ss_n=0)
    assert upif.quiet(selected) == 2  # /SS low passes s1 and s2; the third edge sees the fall (s2 != s3)
    with pytest.raises(UpifUsageError, match=r"SlavePins\.quiet"):
        upif.hold(selected, 3)
    assert upif.quiet(PinsIn(sas_init=1)) == 2  # SAS_INIT acts once it reaches s2 (3.4.3)
    with pytest.raises(ArgumentError, match="cycles"):
        upif.hold(PinsIn(), 0)
    with pytest.raises(ArgumentError, match="pins"):
        upif.quiet("idle")  # type: ignore[arg-type]
    assert upif.cycle == 0
    upif.hold(selected, 2)
    assert upif.quiet(selected) == 0 and not upif.protocol.in_frame
    upif.tick(selected)
    assert upif.protocol.in_frame and upif.quiet(selected) == QUIET_FOREVER


@pytest.mark.parametrize("bit_rate", [500_000, 2_000_000])
def test_rests_counts_cycles_only_while_the_interface_rests_on_those_pins(bit_rate: int) -> None:
    upif, ticked = interface(bit_rate), interface(bit_rate)
    idle = PinsIn()
    assert not upif.rests(idle, 5) and upif.cycle == 0  # nothing held since reset
    settle = upif.output_delay + 4  # the pipeline (output_delay + 1 stages) and the three synchroniser flops
    upif.hold(idle, settle)
    assert upif.rests(idle, 7) and upif.cycle == settle + 7
    assert not upif.rests(PinsIn(), 1)  # equal pins, but not the object held: not known to rest on it
    upif.registers.set_io_access(True)  # the core moves the I/O access bit (MFP1, D7 of read 14)
    assert not upif.rests(idle, 1) and upif.cycle == settle + 7
    expected = [ticked.tick(idle) for _ in range(settle + 7)]
    ticked.registers.set_io_access(True)
    expected += [ticked.tick(idle) for _ in range(settle)]
    assert expand(upif.hold(idle, settle), settle) == expected[-settle:] and expected[-1].io == 1
    assert upif.rests(idle, 1) and ticked.tick(idle) == expected[-1]  # resting again, on the new outputs
    for _ in range(3):
        assert upif.tick(idle) == ticked.tick(idle)
    assert upif.cycle == ticked.cycle

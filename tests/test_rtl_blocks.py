"""The RTL core's blocks (issue #9 part 5): the seams and names agreed with the model, components joined by signatures.

Behaviour is the lockstep's business (tests/test_rtl_core.py, tests/test_rtl_chip.py); here only the structure.
"""

from __future__ import annotations

import pytest
from amaranth.hdl import Fragment
from amaranth.lib import wiring

from supi3.config import Variant
from supi3.interbus import wire
from supi3.rtl import core
from supi3.rtl.core import DataPathRtl, FrameEngineRtl, OutputsRtl, ReceiverRtl, Supi3Core, TransmitterRtl
from supi3.rtl.counter import CounterLinesRtl
from supi3.rtl.expansion import ExpansionRtl
from supi3.rtl.optical import OpticalRtl
from supi3.rtl.serial_io import SerialIoRtl
from supi3.rtl.tables import core_tables
from supi3.rtl.terminal import ReturnWatchRtl, TerminalRtl

BLOCKS = {"receiver": ReceiverRtl, "frame": FrameEngineRtl, "datapath": DataPathRtl, "transmitter": TransmitterRtl,
          "outputs": OutputsRtl, "serial_io": SerialIoRtl, "expansion": ExpansionRtl,
          "counter_lines": CounterLinesRtl, "terminal": TerminalRtl, "tx_watch": ReturnWatchRtl,
          "optical": OpticalRtl}  # fmt: skip
"""Block name (the same in supi3.model; ``counter_lines``: ``Supi3Pins``'s ``LineCounters``, M17; ``terminal``: its
state is the model chip's, supi3.model.bus_terminal; ``tx_watch``: the telegram grid of the transmitter's line that
times the BK's switch of DO3 and DO2, ``BranchLines``' watch, BK-47) -> RTL component."""


@pytest.mark.parametrize("variant", list(Variant))
def test_core_is_its_blocks(variant: Variant) -> None:
    fragment = Fragment.get(Supi3Core(variant), None)
    assert [name for _, name, _ in fragment.subfragments] == list(BLOCKS)


def blocks() -> list[wiring.Component]:
    """One of each block, elaborated on its own (so none is left unused)."""
    tables = core_tables()
    made = [ReceiverRtl(tables), FrameEngineRtl(), DataPathRtl(tables), TransmitterRtl(tables), OutputsRtl(26),
            SerialIoRtl(), ExpansionRtl(), CounterLinesRtl(), TerminalRtl(), ReturnWatchRtl(),
            OpticalRtl()]  # fmt: skip
    for block in made:
        Fragment.get(block, None)
    return made


def test_blocks_are_components_with_signatures() -> None:
    for block, cls in zip(blocks(), BLOCKS.values(), strict=True):
        assert isinstance(block, cls)
        assert isinstance(block, wiring.Component)
        assert block.signature.members


def test_block_interfaces_fit() -> None:
    """Every interface between two blocks is one signature, seen from both sides (connect() needs that)."""
    receiver, frame, datapath, transmitter, outputs, *_ = blocks()
    pairs = [
        (receiver.signature.members["line"], frame.signature.members["line"], core.LINE),
        (frame.signature.members["register"], datapath.signature.members["frame"], core.REGISTER),
        (frame.signature.members["management"], outputs.signature.members["frame"], core.MANAGEMENT),
        (frame.signature.members["tx"], transmitter.signature.members["frame"], core.TRANSMIT),
        (datapath.signature.members["words"], outputs.signature.members["words"], core.WORDS),
    ]
    for source, sink, signature in pairs:
        assert source.signature == signature
        assert sink.signature == signature.flip()


def _feed(crc: int, word: int) -> int:
    for k in range(core.WORD_BITS):
        crc = wire.crc_update_bit(crc, (word >> k) & 1)
    return crc


def test_the_crc_word_is_checked_by_its_residue() -> None:
    """The frame engine feeds the received CRC word on into its register (docs/rtl.md, round 5): every register
    state followed by its own word (``wire.crc16``'s output stage) ends at the residue, and the 16 single wrong bits
    change it by linearly independent amounts, so every set of wrong bits is caught."""
    for state in range(0, 1 << core.WORD_BITS, 257):
        word = int(f"{state:016b}"[::-1], 2) ^ wire.CRC_XOROUT
        assert _feed(state, word) == core._CRC_RESIDUE
        # the bit sent: register bit 15 of the register shifted left k times, flipped
        assert all((word >> k) & 1 == ((state << k) >> 15 & 1) ^ core._CRC_SENT_FLIP for k in range(16))
        pivots: dict[int, int] = {}  # GF(2) elimination of the changes caused by one wrong bit each, by leading bit
        for k in range(core.WORD_BITS):
            delta = _feed(state, word ^ (1 << k)) ^ core._CRC_RESIDUE
            while delta and delta.bit_length() in pivots:
                delta ^= pivots[delta.bit_length()]
            assert delta
            pivots[delta.bit_length()] = delta

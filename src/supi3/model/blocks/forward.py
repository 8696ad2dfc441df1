"""The core's forward path wired from its blocks: receiver, frame engine, data path with the expansion, transmitter.

One wiring for :class:`supi3.model.pins.Supi3Pins` (the whole pin-level core adds the outputs, serial I/O, counter,
branch and optical blocks around it) and :meth:`supi3.model.chip.Supi3.woken_output` (a woken chip's line in the
transaction level's wake-up window, M28 of docs/assumptions/model.md).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

from supi3.interbus import wire
from supi3.model.blocks.datapath import DataPath
from supi3.model.blocks.expansion import Expansion
from supi3.model.blocks.frame import FrameEngine
from supi3.model.blocks.receiver import Receiver
from supi3.model.blocks.transmitter import Transmitter
from supi3.pinlevel import SYNC_STAGES, EventLog

if TYPE_CHECKING:
    from supi3.model.chip import Supi3

__all__ = ["ForwardPath", "forward_path"]


class ForwardPath(NamedTuple):
    """The blocks of the forward path, wired to each other and to one chip."""

    transmitter: Transmitter
    expansion: Expansion
    datapath: DataPath
    frame: FrameEngine
    receiver: Receiver


def forward_path(chip: Supi3, log: EventLog) -> ForwardPath:
    """The forward path of ``chip`` (its configuration's bit rate; RBST_EXT tells a following device with RF = 10,
    Table 2-2, M5), its events in ``log``: a repeater delay of ``REPEATER_DELAY_BITS`` from the mid-bit sample through
    the synchroniser (A10, M1, M8), an INTERBUS reset after ``RESET_DETECT_BITS`` of start level (M11)."""
    cpb = wire.clocks_per_bit(chip.config.bit_rate)
    rf_mode = chip.config.rf_mode
    rbst_by_pin = rf_mode is not None and rf_mode.rf == "10"
    transmitter = Transmitter(cpb, wire.REPEATER_DELAY_BITS * cpb - SYNC_STAGES, rbst_by_pin)
    expansion = Expansion(chip, cpb)
    datapath = DataPath(chip, log, expansion)
    frame = FrameEngine(chip, log, datapath, transmitter)
    receiver = Receiver(cpb, wire.RESET_DETECT_BITS * cpb, chip, log, frame, transmitter)
    return ForwardPath(transmitter, expansion, datapath, frame, receiver)

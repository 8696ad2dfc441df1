"""Data path: the shift register of a frame's data bytes, loaded at the frame's start and latched at its end.

Manual: 3.2 and 3.4.8 (the IN data loaded from the MFP inputs or the µP's data registers, the OUT data taken over),
3.4.10 (the ID register sent in an ID cycle), 3.4.14 (data taken over only at the latch, after a valid check
sequence). INTERBUS (``/work/shared/reference/interbus-layer2.md`` "Cycles and frame", ``docs/interbus.md``): each
device is a shift register in the ring; byte 0 goes out first, each byte LSB first. What is loaded and what a latch
does to the chip are :class:`supi3.model.chip.Supi3` (``load_at``, ``latch_at``); this block is their timing.

RTL counterpart: the ``datapath`` block of :mod:`supi3.rtl.core` (``DataPath``: the data register, its load and
its latch).

With ExtReg = 1 (3.4.11, 3.5) a data frame's bits go through the register expansion block instead
(:class:`~supi3.model.blocks.expansion.Expansion`): the bit sent is FromExR's, the bit received leaves on ToExR
(RX-2); the register still collects the bits received, which the chip hands to the cycle's end.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from supi3.interbus.wire import Cycle
from supi3.pinlevel import EventLog

if TYPE_CHECKING:
    from supi3.model.blocks.expansion import Expansion
    from supi3.model.chip import Supi3


class DataPath:
    """The frame's shift register, as wide as the bytes the chip loads for the cycle (line order: bit i of
    :attr:`register` goes out i-th).

    Parameters
    ----------
    chip:
        The bus behaviour that gives the bytes to send (``load_at``) and takes the bytes received (``latch_at``).
    log:
        The core's event log.
    expansion:
        The register expansion block the bits of a data frame with ExtReg = 1 go through.
    """

    __slots__ = ("chip", "expansion", "external", "log", "register", "width")

    def __init__(self, chip: Supi3, log: EventLog, expansion: Expansion) -> None:
        self.chip = chip
        self.log = log
        self.expansion = expansion
        self.power_up()

    def power_up(self) -> None:
        """Power-up reset: an empty register."""
        self.register = 0
        self.width = 0
        """Bits in the register: 8 times the bytes loaded."""
        self.external = False
        """The frame's bits go through the register expansion (a data frame with ExtReg = 1)."""

    def load(self, cycle: Cycle, c: int) -> None:
        """A frame of ``cycle`` begins at cycle ``c``: load the chip's bytes for it."""
        loaded = self.chip.load_at(cycle, c)
        self.log.add(c, f"{cycle.value} cycle: load {loaded.hex()}")
        self.width = 8 * len(loaded)
        # Line order: byte 0 first, each byte LSB first: bit i of the register goes out i-th.
        self.register = int.from_bytes(loaded, "little")
        self.external = cycle is Cycle.DATA and self.width > 0 and self.chip.expansion
        if self.external:
            self.expansion.begin()

    def shift(self, level: int, c: int) -> int:
        """One data bit in at ``level``, sampled at the tick of cycle ``c``; the bit that goes out in its place (the
        level itself if nothing was loaded: the chip has no data in this cycle)."""
        if self.width:
            out = self.register & 1
            self.register = (self.register >> 1) | (level << (self.width - 1))
            return self.expansion.shift(level, c) if self.external else out
        return level

    def latch(self, cycle: Cycle, c: int) -> None:
        """The frame of ``cycle`` is latched at cycle ``c``: the chip takes over the bytes received."""
        received = self.register.to_bytes(self.width // 8, "little")
        self.log.add(c, f"{cycle.value} cycle latched: {received.hex()}")
        self.chip.latch_at(cycle, received, c)

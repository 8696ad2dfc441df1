"""External data registers on the serial register expansion (manual 3.5) in the role of the IBS SRE 1: an
:class:`supi3.expansion.ExternalRegisters` at both fidelities (RX-8 of ``docs/assumptions/expansion.md``).

Wiring (Table 3-14): ClkExR clocks the chain, ToExR feeds its first bit, its last bit drives FromExR, LaOuD rising
makes the output registers take the chain, /LaInD falling makes the chain take the input registers, /ResReg (RC)
low clears output registers and chain ("/ResReg (RC) should be connected to the /ResReg input ... for external
register expansions with the IBS SRE 1", 3.5).

Bit order (Figure 3-24): bytes are numbered from ToExR (byte 0 next to it) and move along the chain LSB first, so
after a data cycle that received 14h, 56h, 78h the chain holds bytes 0..2 = 78h, 56h, 14h
(:func:`supi3.expansion.line_to_chain`). Inside, the chain is the integer whose big-endian bytes are bytes 0, 1,
...: bit 0 is the bit furthest from ToExR (byte ``length - 1``'s LSB, on FromExR), and a ClkExR rise shifts the
integer right, ToExR entering at the top (byte 0's MSB). The choices where the manual is silent are PR-6 and PR-7
of ``docs/peripherals.md``.
"""

from __future__ import annotations

from typing import Final

from supi3.checks import check_bytes, check_instance, check_int
from supi3.expansion import IDLE as EXPANSION_IDLE
from supi3.expansion import ExpansionLevels, chain_to_line, line_to_chain

__all__ = ["MAX_LENGTH", "Sre1"]

MAX_LENGTH: Final = 64
"""Longest chain in bytes: the complete length code of Table 3-11 reaches 32 words (3.4.11, ExtReg = 1)."""


class Sre1:
    """A chain of ``length`` bytes of external input and output registers (the IBS SRE 1 role, 3.5, RX-8).

    :meth:`set_inputs` sets the input registers and :attr:`outputs` shows the output registers, both as ``length``
    bytes numbered from ToExR (Figure 3-24). The transaction level drives it through :meth:`chain`,
    :meth:`shift_cycle`, :meth:`take_outputs`, :meth:`load_inputs` and :meth:`clear`; the pin level through
    :meth:`clock`. Power-up state: chain, inputs and outputs all zero.
    """

    def __init__(self, length: int) -> None:
        self._length = check_int("length", length, 1, MAX_LENGTH, limit="Table 3-11: up to 32 words")
        self._bits = 8 * self._length
        self._chain = 0
        self._inputs = bytes(self._length)
        self._outputs = bytes(self._length)
        self._seen = EXPANSION_IDLE

    @property
    def length(self) -> int:
        """Bytes in the chain."""
        return self._length

    @property
    def outputs(self) -> bytes:
        """The output registers, byte 0 next to ToExR."""
        return self._outputs

    @property
    def inputs(self) -> bytes:
        """The input registers, byte 0 next to ToExR."""
        return self._inputs

    def set_inputs(self, data: bytes) -> None:
        """Set the input registers (``length`` bytes, byte 0 next to ToExR); the next /LaInD loads them."""
        self._inputs = check_bytes("data", data, self._length)

    def contents(self) -> bytes:
        """The chain now, byte 0 next to ToExR."""
        return self._chain.to_bytes(self._length, "big")

    def chain(self) -> bytes:
        """The chain in line order: what the next data cycle sends, first byte first (transaction level)."""
        return chain_to_line(self.contents())

    def shift_cycle(self, received: bytes) -> None:
        """A whole data cycle shifted through (transaction level): the chain holds ``received`` (line order,
        ``length`` bytes), the first byte received furthest from ToExR."""
        data = check_bytes("received", received, self._length)
        self._chain = int.from_bytes(line_to_chain(data), "big")

    def take_outputs(self) -> None:
        """LaOuD: the output registers take the chain."""
        self._outputs = self.contents()

    def load_inputs(self) -> None:
        """/LaInD: the chain takes the input registers."""
        self._chain = int.from_bytes(self._inputs, "big")

    def clear(self) -> None:
        """/ResReg: output registers and chain cleared (the input registers follow their pins)."""
        self._chain = 0
        self._outputs = bytes(self._length)

    def clock(self, levels: ExpansionLevels) -> int:
        """The chip's expansion outputs changed to ``levels`` (pin level); returns the FromExR level from then on.

        While /ResReg is low the chain and outputs stay cleared and the other inputs are ignored. Otherwise a ClkExR
        rise shifts ToExR in, a LaOuD rise takes the outputs, a /LaInD fall loads the inputs, in that order.
        """
        check_instance("levels", levels, ExpansionLevels)
        seen, self._seen = self._seen, levels
        if levels.res_reg_n == 0:
            self.clear()
            return 0
        if seen.clk_exr == 0 and levels.clk_exr == 1:
            self._chain = (self._chain >> 1) | (levels.to_exr << (self._bits - 1))
        if seen.la_ou_d == 0 and levels.la_ou_d == 1:
            self.take_outputs()
        if seen.la_in_d_n == 1 and levels.la_in_d_n == 0:
            self.load_inputs()
        return self._chain & 1

    def __repr__(self) -> str:
        return f"Sre1({self._length})"

"""Serial register expansion (manual 3.5, Tables 3-14 and 3-15, Figures 3-23 and 3-24): the signals, clock by clock.

The one definition of what the SUPI 3 OPC drives on ClkExR, ToExR, LaOuD, /LaInD and /ResReg when the SET register
selects external data registers (ExtReg = 1, 3.4.11), and of how bytes sit in the external chain. The pin-level
model, the RTL, the transaction-level chip and the IBS SRE 1 model derive from it; the Table 3-15 checker measures
traces on its own. Decisions RX-1 to RX-10 are in ``docs/assumptions/expansion.md``.

* **Data path** (RX-2): in a data cycle every data bit the chip receives leaves on ToExR instead of entering the
  internal data registers, and the bit the chip sends in its place is the one FromExR shows; the external chain is
  the chip's shift register (as long as the SET register's complete length code says, Table 3-11).
* **ClkExR** (RX-3): at the clock edge where the receiver samples data bit ``k`` the chip takes FromExR (through its
  synchroniser) and puts bit ``k`` on ToExR from the next cycle; ClkExR is high from :func:`clock_high` cycles
  after that, for half a bit: ToExR is valid 0.25 t0 before the rising edge and 0.75 t0 after it (Table 3-15).
* **End of a cycle** (RX-4): after a latched data cycle LaOuD is high for 4 t0 (the external registers take the
  OUT data), then 5 t0 later /LaInD is low for 4 t0 (they load the IN data of the next cycle into the chain); after
  any other cycle end (ID cycle, discarded data cycle) only /LaInD, at once.
* **/ResReg** (RX-5): with expansion, low for 4 t0 on an INTERBUS reset and on a watchdog reset of process data.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final, Protocol, runtime_checkable

from supi3.checks import check_bool, check_bytes, check_choice
from supi3.interbus import wire
from supi3.serial_io import check_levels
from supi3.tables import BIT_RATES

__all__ = [
    "CLOCKS_PER_BIT",
    "LAIND_AFTER_LAOUD_T0",
    "PULSE_T0",
    "EndPulses",
    "ExpansionLevels",
    "ExternalRegisters",
    "chain_to_line",
    "clock_high",
    "end_pulses",
    "line_to_chain",
]

PULSE_T0: Final = 4
"""LaOuD, /LaInD and /ResReg pulses last 4 t0 = 4 bit periods (Table 3-15 minimums, RX-4, RX-5)."""
LAIND_AFTER_LAOUD_T0: Final = 5
"""/LaInD falls 5 t0 after LaOuD fell (Table 3-15 minimum)."""


CLOCKS_PER_BIT: Final = tuple(wire.clocks_per_bit(rate) for rate in BIT_RATES)
"""The chip clocks of one bit at the bit rates of Table 1-7 (64, 16): the ``cpb`` the schedules take."""


def _cpb(cpb: int) -> int:
    return check_choice("cpb", cpb, CLOCKS_PER_BIT, limit="clocks per bit at a rate of Table 1-7")


def clock_high(cpb: int) -> tuple[int, int]:
    """(first, end) offsets of ClkExR's high phase from the first cycle ToExR shows a bit, in clocks: a quarter of
    a bit to three quarters (RX-3). ``cpb``: clocks per bit (64 or 16, :data:`CLOCKS_PER_BIT`).

    Raises
    ------
    ArgumentError
        ``cpb`` not one of :data:`CLOCKS_PER_BIT` (another count has no bit rate of Table 1-7 behind it).
    """
    _cpb(cpb)
    return cpb // 4, 3 * cpb // 4


@dataclass(frozen=True)
class EndPulses:
    """The pulses after a cycle's end, as (first, end) offsets in clocks from the cycle after the end's edge."""

    la_ou_d: tuple[int, int] | None
    """LaOuD high (only after a latched data cycle)."""
    la_in_d_n: tuple[int, int]
    """/LaInD low."""

    @property
    def length(self) -> int:
        """Cycles until both pulses are over: the chain holds the next IN data from here."""
        return self.la_in_d_n[1]


def end_pulses(latched_data: bool, cpb: int) -> EndPulses:
    """The pulses after a cycle ends: a latched data cycle (``latched_data``) or anything else (RX-4).

    Raises
    ------
    ArgumentError
        ``latched_data`` not a bool, ``cpb`` not one of :data:`CLOCKS_PER_BIT`.
    """
    check_bool("latched_data", latched_data)
    _cpb(cpb)
    width = PULSE_T0 * cpb
    if not latched_data:
        return EndPulses(None, (0, width))
    start = width + LAIND_AFTER_LAOUD_T0 * cpb
    return EndPulses((0, width), (start, start + width))


def line_to_chain(received: bytes) -> bytes:
    """The external chain after the data cycle, numbered from ToExR (byte 0 next to ToExR) as Figure 3-24 numbers
    it, from the bytes in the order the chip received them: the first received is furthest from ToExR. The manual's
    example: received 14h, 56h, 78h gives bytes 0..2 = 78h, 56h, 14h."""
    return bytes(reversed(check_bytes("received", received)))


def chain_to_line(chain: bytes) -> bytes:
    """The bytes the chain sends, in line order, from the chain numbered from ToExR (the inverse of
    :func:`line_to_chain`): the byte furthest from ToExR reaches FromExR first."""
    return bytes(reversed(check_bytes("chain", chain)))


@dataclass(frozen=True)
class ExpansionLevels:
    """The chip's register-expansion outputs in one cycle (Table 3-14)."""

    clk_exr: int
    to_exr: int
    la_ou_d: int
    la_in_d_n: int
    res_reg_n: int

    def __post_init__(self) -> None:
        check_levels(self)


IDLE: Final = ExpansionLevels(clk_exr=0, to_exr=0, la_ou_d=0, la_in_d_n=1, res_reg_n=1)
"""After power-up and without expansion (ExtReg = 0, RX-6, RX-7)."""


@runtime_checkable
class ExternalRegisters(Protocol):
    """External data registers on the expansion interface (the IBS SRE 1's role, 3.5), at either fidelity.

    The transaction level calls :meth:`chain`, :meth:`shift_cycle`, :meth:`take_outputs`, :meth:`load_inputs` and
    :meth:`clear` at the bus events; the pin level calls :meth:`clock` at every cycle in which the chip's expansion
    outputs change. A chain is driven at one fidelity.
    """

    @property
    def length(self) -> int:
        """Bytes in the chain."""

    def chain(self) -> bytes:
        """The chain's contents in line order: what the next data cycle sends (transaction level)."""

    def shift_cycle(self, received: bytes) -> None:
        """A whole data cycle shifted through: the chain now holds ``received`` (line order, transaction level)."""

    def take_outputs(self) -> None:
        """LaOuD: the output registers take the chain."""

    def load_inputs(self) -> None:
        """/LaInD: the chain takes the input registers."""

    def clear(self) -> None:
        """/ResReg: output registers and chain cleared."""

    def clock(self, levels: ExpansionLevels) -> int:
        """The chip's pins changed to ``levels``; returns the FromExR level the chain drives from then on (it
        answers ``supi3.serial_io.PERIPHERAL_DELAY_CLOCKS`` = 2 clocks later, as the serial I/O devices do)."""

"""Outputs and diagnostics: the MFP outputs and enables, /ModAck, /ResReg, DIAG1/DIAG2, IB_DIAG, DCLK and /ResU.

Manual: Table 1-4 (the output pins), Tables 3-1 to 3-6 and 2-8 (MFP directions), 3.6.2 (/ModAck), Table 3-13 and
3.4.14 (the /ResReg pulse on a watchdog reset of process data), 3.6.1 (Tables 3-16 to 3-19: DIAG1/DIAG2 as BA/RD or
FO1/FO2 by DIAG_CONF, the IB_DIAG flashing codes, RC on /ResReg, UL on /ResU), Table 2-8 (a bus terminal module's
ALARM, LD, E and FO3 on MFP15, 14, 13 and 8), 1.7.2 (the chip pulling /ResU low during its reset). The levels come
from :class:`supi3.model.chip.Supi3` (its LED view :attr:`~supi3.model.chip.Supi3.diagnostic_outputs`, built by
:mod:`supi3.diagnostics`); this block gives their timing at the pins. Decisions: M3 (pulses seen from the cycle
after the edge that starts them), M6 (IB_DIAG divider), ``docs/model.md``; DG-1 to DG-8,
``docs/assumptions/diagnostics.md``.

What the optical block (FO1..FO3) and the bus terminal logic (LD, E, ALARM) give this block is the chip's
:attr:`~supi3.model.chip.Supi3.led_inputs` (:class:`supi3.diagnostics.LedInputs`, all 0 until those blocks set it).
RD (DIAG2 with complete diagnostics, DG-5) is the transmitter's recognition of a following device (M5), a register
that changes at clock edges: ``step()`` tells the chip at each edge (:meth:`~supi3.model.chip.Supi3.set_following`);
``run()`` knows it only once the return line is known and completes DIAG2 then (:meth:`Outputs.show_following`).

RTL counterpart: the ``outputs`` block of :mod:`supi3.rtl.core` (``Outputs``: the pulse counters, the IB_DIAG
divider, the diagnostic outputs).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

import numpy as np
import numpy.typing as npt

from supi3.diagnostics import DiagnosticOutputs, is_complete
from supi3.model.blocks.serial_io import SerialIo
from supi3.model.blocks.transmitter import PinTrace, Transmitter

if TYPE_CHECKING:
    from supi3.model.chip import Supi3

class _View(NamedTuple):
    """The chip's LEDs at one ``Supi3.revision`` and what they put on the pins (DIAG1, DIAG2, the bus terminal's
    MFP bits, the IB_DIAG divider's bits or 0 for a steady light)."""

    revision: int
    leds: DiagnosticOutputs
    diag1: int
    diag2: int
    mfp: int
    ib_bits: int


Snapshot = tuple[int, int, int, int, int, int, int, int]
"""What the outputs of a cycle depend on besides the cycle number (see :meth:`Outputs.snapshot`)."""


class Outputs:
    """Every output pin but the INTERBUS lines' levels, from the chip's state and the cycle number.

    Parameters
    ----------
    chip:
        The bus behaviour whose outputs are shown.
    transmitter:
        The transmitter (DO2, and whether DI1 passes DI2 through).
    cpb:
        Clocks per bit (DCLK).
    mfp_oe:
        The MFP output enables of the configuration.
    serial:
        The serial I/O block driving MFP3, 4, 5 and 7 in the SPI master modes (3.3), else None.
    """

    __slots__ = ("_view", "chip", "complete", "cpb", "mfp_oe", "serial", "transmitter")

    def __init__(self, chip: Supi3, transmitter: Transmitter, cpb: int, mfp_oe: int,
                 serial: SerialIo | None = None) -> None:  # fmt: skip
        self.chip = chip
        self.serial = serial
        self.transmitter = transmitter
        self.cpb = cpb
        self.mfp_oe = mfp_oe
        self.complete = is_complete(chip.config)
        """DIAG2 shows RD (DIAG_CONF = 0, Table 3-16)."""
        self._view: _View | None = None

    def view(self) -> _View:
        """The chip's LEDs now (:attr:`supi3.model.chip.Supi3.diagnostic_outputs`) and the pin levels they make,
        computed once per change of what the pins show (``Supi3.revision``): ``step()`` reads them every cycle."""
        chip = self.chip
        cached = self._view
        if cached is None or cached.revision != chip.revision:
            leds = chip.diagnostic_outputs
            cached = self._view = _View(chip.revision, leds, leds.diag1, leds.diag2, leds.mfp,
                                        leds.ib_diag.divider_bits or 0)  # fmt: skip
        return cached

    def values(self, c: int, di2: int, run_from: int) -> dict[str, int]:
        """Every output pin during cycle ``c`` (``di2``: that cycle's input; the logic runs from ``run_from``)."""
        chip = self.chip
        tx = self.transmitter
        do2 = tx.level(c)
        view = self.view()
        flash = view.ib_bits
        return {
            "do2": do2,
            # The return line passes straight through when a device follows; the last device loops back (M5).
            "di1": di2 if tx.next_present else do2,
            # A bus terminal module's LEDs on MFP15, 14, 13, 8 (Table 2-8); 0 on other chips.
            "mfp_out": (chip.mfp_outputs if self.serial is None else self.serial.mfp(c)) | view.mfp,
            "mfp_oe": self.mfp_oe,
            # A pulse the chip starts at clock clk (the edge ending cycle clk) lasts until clk + width in chip
            # time; the pins show it from cycle clk + 1, so for cycles clk + 1 .. clk + width (M3). Cycle 0 comes
            # before any edge (the chip's "no pulse" value is 0). /ResReg is low while the line is silent too: RC
            # off (DG-4).
            "mod_ack_n": int(not 0 < c <= chip.mod_ack_until),
            "res_reg_n": int(not (0 < c <= chip.resreg_until or chip.line_silent)),
            "diag1": view.diag1,
            "diag2": view.diag2,
            "ib_diag": 1 if not flash else 1 - ((c >> (flash - 1)) & 1),  # ib_diag_level(view.leds.ib_diag, c)
            "dclk_out": int(c % self.cpb < self.cpb // 2),
            "resu_drive": int(c < run_from),
        }

    def snapshot(self, run_from: int) -> Snapshot:
        """The outputs' state now, for :meth:`render` (``run_from``: the cycle the logic runs from)."""
        chip = self.chip
        view = self.view()
        return (chip.mfp_outputs | view.mfp, view.diag1, view.diag2, view.ib_bits, chip.mod_ack_until,
                chip.resreg_until, int(chip.line_silent), run_from)  # fmt: skip

    def render(self, c0: int, n: int, snaps: list[tuple[int, Snapshot]], do2: PinTrace) -> dict[str, PinTrace]:
        """Every output pin but ``di1`` over cycles ``c0`` to ``c0 + n - 1``, as :meth:`values` gives them: each
        ``(t, snapshot)`` of ``snaps`` holds from run cycle ``t`` until the next; ``do2`` is the transmitter's."""
        cycles = np.arange(c0, c0 + n, dtype=np.int64)
        # The snapshot taken after each visited cycle holds until the next one: repeat each over its cycles.
        starts = np.array([t for t, _ in snaps], dtype=np.int64)
        lengths = np.diff(np.append(starts, n)).clip(min=0)
        table = np.array([snap for _, snap in snaps], dtype=np.int64)
        mfp_out, diag1, diag2, ib_bits, mod_ack_until, resreg_until, silent, run_from = (
            np.repeat(column, lengths) for column in table.T
        )
        # ib_diag_level over the run: steady (0 bits) or the inverted top bit of the divider.
        flash = 1 - ((cycles >> np.maximum(ib_bits - 1, 0)) & 1)
        cpb = self.cpb
        out: dict[str, npt.NDArray[np.int64]] = {
            "mfp_out": mfp_out if self.serial is None else self.serial.render(c0, n) | mfp_out,
            "diag1": diag1,
            "mod_ack_n": ((cycles <= 0) | (cycles > mod_ack_until)).astype(np.int64),  # as values()
            "res_reg_n": (((cycles <= 0) | (cycles > resreg_until)) & (silent == 0)).astype(np.int64),
            "resu_drive": (cycles < run_from).astype(np.int64),
            "ib_diag": np.where(ib_bits == 0, 1, flash),
            "do2": do2,
            "mfp_oe": np.full(n, self.mfp_oe, dtype=np.int64),
            "diag2": diag2,
            "dclk_out": (cycles % cpb < cpb // 2).astype(np.int64),
        }
        return out

    def show_following(self, diag2: PinTrace, present: npt.NDArray[np.bool_]) -> None:
        """With complete diagnostics, set ``diag2`` (a run's DIAG2 trace, in place) to RD over the run: lit in each
        cycle whose outputs see no following device recognised (``present``, M5; DG-5). The rest of the run's
        outputs do not depend on DI2, so :meth:`render` gives them before the return line is known."""
        if self.complete:
            diag2[:] = ~present

"""Synchroniser and line receiver: the input pins as the logic sees them, and the INTERBUS line read bit by bit.

Manual: Table 1-4 (the input pins DO1, DI2, RBST_EXT, MFP, /StatErr, /ResU), 1.7.1 (the 32 MHz clock every input is
sampled on), 1.7.2 (/ResU and the voltage monitor as inputs). INTERBUS (``/work/shared/reference/interbus-layer2.md``
"Telegrams", ``docs/interbus.md``): the start bit, mid-bit sampling, the telegram-type bit that tells a 13-bit data
telegram from a 5-bit status telegram, the INTERBUS reset (start level held, A12) and the 20 ms idle time-out (A13),
which counter telegrams (LBD modes, BK-36) do not restart: it runs from the start of the last other telegram, taken
at its control bit where the frame engine knows a counter telegram, and a time-out after counter telegrams is no
line interrupt ahead (DG-9, ``docs/assumptions/diagnostics.md``).
Decisions: M1 (two synchroniser stages), M7 (framing), M11 (reset detection), M16 (a stop bit at start level starts
the next telegram), ``docs/model.md``.

RTL counterpart: the ``receiver`` block of :mod:`supi3.rtl.core` (``Receiver``: the synchronisers, the INTERBUS
reset and idle time-out counters, framing and mid-bit sampling).

Each sampled bit goes to the frame engine (:class:`~supi3.model.blocks.frame.FrameEngine`), which decides the level
to send on, and then to the transmitter (:class:`~supi3.model.blocks.transmitter.Transmitter`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Final, NamedTuple

import numpy as np
import numpy.typing as npt

from supi3.checks import check_bits, check_trace, fail
from supi3.errors import ArgumentError
from supi3.interbus import wire
from supi3.model.blocks.transmitter import NEVER
from supi3.pinlevel import EventLog, Pin
from supi3.pinout import CORE_IDLE, CORE_INPUTS, SYNC_STAGES
from supi3.tables import CLOCK_HZ

if TYPE_CHECKING:
    from supi3.model.blocks.frame import FrameEngine
    from supi3.model.blocks.transmitter import Transmitter
    from supi3.model.chip import Supi3

IDLE_TIMEOUT_CLOCKS: Final = round(wire.IDLE_TIMEOUT_S * CLOCK_HZ)
"""A line without a telegram start for 20 ms is an INTERBUS reset (docs/interbus.md A13), once per silence."""

class Synced(NamedTuple):
    """The input pins as the logic sees them, after the synchroniser."""

    do1: int
    di2: int
    rbst_ext: int
    mfp_in: int
    stat_err_n: int
    resu_n: int
    vmon_ok: int
    from_exr: int


INPUT_NAMES: Final = Synced._fields
IDLE_INPUTS: Final = Synced(*CORE_IDLE)
"""What the synchroniser holds after reset: the levels of a quiet board (idle line, no fault, power good)."""

INPUT_PINS: Final[tuple[Pin, ...]] = CORE_INPUTS
"""``Supi3Pins.inputs``, in :class:`Synced` order (the declaration in :mod:`supi3.pinout`, which the RTL uses too)."""
_INPUT_WIDTHS: Final[dict[str, int]] = {pin.name: pin.width for pin in INPUT_PINS}
"""Bits of each input pin."""


def check_names(what: str, given: object, names: Sequence[str]) -> Mapping[object, object]:
    """``given`` if it is a mapping whose keys are exactly ``names`` (any order), else a named error that lists the
    missing and the unknown names."""
    if not isinstance(given, Mapping):
        raise fail(what, "a mapping of pin name to value", given)
    mapping: Mapping[object, object] = given
    missing = [name for name in names if name not in mapping]
    unknown = [name for name in mapping if name not in names]
    if missing or unknown:
        problems = [f"without {', '.join(map(repr, missing))}" if missing else "",
                    f"with {', '.join(map(repr, unknown))}, no such pin" if unknown else ""]  # fmt: skip
        raise ArgumentError(what, given, f"{what} must name exactly the pins {', '.join(names)}, not "
                                         + "; ".join(problem for problem in problems if problem))
    return mapping


def input_row(inputs: object) -> Synced:
    """One cycle's input levels by name, checked: every input pin, each an integer within its pin's width.

    Raises
    ------
    ArgumentError
        With the pin's name and width ("pin 'do1' must be an integer from 0 to 1 (1 bit), not 2").
    """
    mapping = check_names("inputs", inputs, INPUT_NAMES)
    return Synced(*(check_bits(f"pin {name!r}", mapping[name], _INPUT_WIDTHS[name]) for name in INPUT_NAMES))


def input_traces(inputs: object) -> dict[str, npt.NDArray[np.integer]]:
    """Input traces by name, checked at once (vectorised): every input pin, each a 1-D integer sequence within its
    pin's width, all of one length. Integer arrays are not copied.

    Raises
    ------
    ArgumentError
        With the pin's name, width and the first bad index, or the lengths.
    """
    mapping = check_names("inputs", inputs, INPUT_NAMES)
    traces = {name: check_trace(f"pin {name!r} trace", mapping[name], _INPUT_WIDTHS[name]) for name in INPUT_NAMES}
    n = len(traces["do1"])
    for name, trace in traces.items():
        if len(trace) != n:
            raise fail(f"len(pin {name!r} trace)", f"{n}, the length of pin 'do1' trace", len(trace))
    return traces


class Receiver:
    """The synchroniser (:attr:`pipe`) and the line receiver of the forward line.

    Parameters
    ----------
    cpb:
        Clocks per bit at the configured bit rate.
    reset_run:
        Clocks of start level that make an INTERBUS reset (M11).
    chip:
        The bus behaviour, told of an idle time-out (``line_timeout_at``).
    log:
        The core's event log.
    frame:
        The frame engine every sampled bit goes to.
    transmitter:
        The transmitter every sampled bit is repeated on.

    Notes
    -----
    The state holds absolute cycle numbers (when the current telegram began, when the line went to start level,
    when the last telegram began) instead of counters, so that :meth:`supi3.model.pins.Supi3Pins.run` can skip the
    cycles in which nothing happens: :meth:`next_due` says when the receiver acts next with unchanged inputs.
    """

    __slots__ = (
        "bit", "busy", "chip", "counted", "cpb", "frame", "half_bit", "last_start", "length", "log", "low_since",
        "pipe",
        "reset_run", "run_low", "t0", "transmitter", "word",
    )  # fmt: skip

    def __init__(
        self, cpb: int, reset_run: int, chip: Supi3, log: EventLog, frame: FrameEngine, transmitter: Transmitter
    ) -> None:
        self.cpb = cpb
        self.half_bit = cpb // 2
        self.reset_run = reset_run
        self.chip = chip
        self.log = log
        self.frame = frame
        self.transmitter = transmitter
        self.run_low: tuple[int, int | None, npt.NDArray[np.intp]] = (0, None, np.zeros(0, dtype=np.intp))
        """For a run: (its first cycle, :attr:`low_since` before it, where each cycle's run of line level began)."""
        self.reset()

    def reset(self) -> None:
        """The synchroniser after the ``sync`` reset: the levels of a quiet board."""
        self.pipe: list[Synced] = [IDLE_INPUTS] * SYNC_STAGES
        """The synchroniser's stages, newest first; the last one is what the logic sees this cycle."""

    def power_up(self, run_from: int) -> None:
        """Power-up reset: no telegram in progress; the logic runs again from cycle ``run_from``."""
        self.busy = False
        """A telegram is being received (between its start bit and its last bit)."""
        self.t0 = 0
        """The cycle the current telegram's start bit was seen."""
        self.bit = 0
        """The next bit of the telegram to sample."""
        self.length = wire.DATA_TELEGRAM_BITS
        """The current telegram's length in bits, known from its type bit."""
        self.word = 0
        """The bits of the current telegram sampled so far, bit k at 2**k."""
        self.low_since: int | None = None
        """The first cycle of the current run of start level on the line, or ``None``."""
        self.last_start = run_from - 1
        """The cycle the last telegram that was no counter telegram began (for the idle time-out): taken at its
        control bit, where a counter telegram is known (DG-9)."""
        self.counted = False
        """A counter telegram came since that telegram (DG-9): a time-out now is no line interrupt ahead."""

    def clock(self, line: int, c: int) -> None:
        """The rising edge at the end of cycle ``c`` with the synchronised forward line at ``line``."""
        # INTERBUS reset: the start level held for RESET_DETECT_BITS bit periods (docs/interbus.md).
        if line == wire.START_LEVEL:
            if self.low_since is None:
                self.low_since = c
            if c - self.low_since + 1 == self.reset_run:
                self.frame.enter_reset(c)
        else:
            self.low_since = None
        if c - self.last_start == IDLE_TIMEOUT_CLOCKS:
            self.log.add(c, "idle timeout: INTERBUS reset")
            self.frame.abandon(c)
            self.chip.line_timeout_at(c, self.counted)
        if not self.busy:
            if line == wire.START_LEVEL:
                self._begin(c)
            return
        if c == self.t0 + self.half_bit + self.bit * self.cpb:
            self._sample(line, c)
            self.bit += 1

    def _begin(self, t0: int) -> None:
        """A telegram whose start bit began at cycle ``t0``; its bit 0 is sampled next."""
        self.busy = True
        self.t0 = t0
        self.bit = 0
        self.word = 0
        self.length = wire.DATA_TELEGRAM_BITS

    def _sample(self, level: int, c: int) -> None:
        """Bit :attr:`bit` of the telegram, sampled mid-bit: to the frame engine, then out on the repeater."""
        k = self.bit
        self.word |= level << k
        if k == wire.POS_TYPE:
            data = level == wire.TYPE_DATA_LEVEL
            self.length = wire.DATA_TELEGRAM_BITS if data else wire.STATUS_TELEGRAM_BITS
        out = level
        frame = self.frame
        framed = not frame.in_reset and self.length == wire.DATA_TELEGRAM_BITS
        if k == wire.POS_CONTROL:
            # The idle time-out restarts from this telegram's start unless it is a counter telegram (DG-9, BK-36),
            # in an INTERBUS reset too (the frame engine idles there: no frame takes it either way).
            self.counted = self.length == wire.DATA_TELEGRAM_BITS and frame.counter_telegram(self.word)
            if self.counted:
                framed = False  # no frame's telegram: the frame engine does not see its control bit
            else:
                self.last_start = self.t0
        if framed:
            out = frame.data_telegram_bit(k, level, c, self.word)
        self.transmitter.repeat(c, out)
        if k == self.length - 1:
            word, length = self.word, self.length
            if level == wire.STOP_LEVEL:
                self.busy = False
            else:
                # M16: a stop bit at start level is the start bit of the next telegram, on the same bit grid
                # (its bit 0 counts as sampled: :meth:`clock` steps on to bit 1).
                self._begin(c - self.half_bit)
            frame.telegram_end(level, c, word, length)

    def next_due(self, c: int, line: int, run_from: int) -> int:
        """The next cycle after ``c`` at which the logic acts with unchanged inputs (the line at ``line``, the logic
        running from ``run_from``): the receiver's next sample, reset detection or time-out, or the chip's."""
        # Comparisons rather than min(): this runs once per visited cycle of run().
        if c < run_from:
            return run_from
        if not self.busy and line == wire.START_LEVEL:
            return c + 1  # a start bit: nothing can be due sooner
        due = self.last_start + IDLE_TIMEOUT_CLOCKS
        if due <= c:
            due = NEVER
        if self.busy:
            sample = self.t0 + self.half_bit + self.bit * self.cpb
            if sample < due:
                due = sample
        low = self.low_since
        if low is not None and c < low + self.reset_run - 1 < due:
            due = low + self.reset_run - 1
        chip_due = self.chip.due
        if chip_due < due:
            due = chip_due if chip_due > c else c + 1
        return due

    def restore_low_run(self, t: int, level: int, run_from: int) -> None:
        """Set the reset detector's :attr:`low_since` as :meth:`clock` leaves it at run cycle ``t`` (the logic
        running from ``run_from``, the synchronised line at ``level``): where this run of start level began, or
        ``None``. A run visits a cycle in a telegram only when something is due, so the detector is restored from
        the line's trace (:attr:`run_low`) rather than kept by every line change."""
        if level != wire.START_LEVEL:
            self.low_since = None
            return
        c0, before, starts = self.run_low
        start = starts.item(t)
        # A run of start level that began before this run() call continues the one the detector already saw.
        self.low_since = before if start == 0 and before is not None else max(c0 + start, run_from)

"""Frame engine: the data telegrams of a summation frame, its CRC and check sequence, the latch telegrams.

Manual: 3.4.14 (a cycle's data is taken over, "latched", only after a valid check sequence; the I/O access window of
a data cycle, Figure 3-22) and Table 3-13 (the valid and invalid data cycle events). INTERBUS
(``/work/shared/reference/interbus-layer2.md`` "Telegrams" and "Cycles and frame", ``docs/interbus.md``): the select
bit (ID or data cycle) and the control bit (data or check sequence) of each data telegram, the 32-bit check
sequence (own CRC word out, received CRC compared, CNTR forwarded with the ERR pair settled at the last stop bit),
the latch status telegrams, the end of an INTERBUS reset (status telegrams), the local errors. The cycle-level
decisions are in ``docs/model.md``.

RTL counterpart: the ``frame`` block of :mod:`supi3.rtl.core` (``FrameEngine``: the frame state, the CRC registers,
the check sequence and the telegram end).

Counter telegrams (LBD modes, Table 2-5; BK-36 of ``docs/assumptions/bus-terminal.md``): an ID check telegram while
no frame runs (between frames, or waiting for the latch telegrams) is a counter telegram (:meth:`FrameEngine.
counter_telegram`, the forward counter block's recognition of BK-32 from the frame engine's own state); it changes no
frame and is no local error, and the receiver's idle time-out runs on through it (DG-9).

The frame's data bits go through the data path (:class:`~supi3.model.blocks.datapath.DataPath`); the frame engine
computes both CRCs over what comes in and what goes out.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Final

from supi3.interbus import wire
from supi3.interbus.wire import Cycle
from supi3.pinlevel import EventLog

if TYPE_CHECKING:
    from supi3.model.blocks.datapath import DataPath
    from supi3.model.blocks.transmitter import Transmitter
    from supi3.model.chip import Supi3

_DATA_BITS: Final = range(wire.POS_DATA, wire.POS_DATA + 8)
_CHECK_WORDS: Final = wire.CHECK_TELEGRAMS  # CRC low, CRC high, CNTR low, CNTR high


def crc_word(register: int) -> int:
    """The CRC word a bit-serial register stands for (``wire.crc16``'s output stage)."""
    word = int(f"{register:016b}"[::-1], 2) if wire.CRC_REFOUT else register
    return word ^ wire.CRC_XOROUT


class FrameEngine:
    """The frame state of the line receiver's data and status telegrams.

    Parameters
    ----------
    chip:
        The bus behaviour: told of frames discarded, resets, the I/O access and latch phases.
    log:
        The core's event log.
    datapath:
        The shift register the frame's data bits pass through.
    transmitter:
        The transmitter, whose ERR pair is settled at the end of the check sequence.

    Attributes
    ----------
    state:
        ``"idle"`` (no frame), ``"data"`` (data telegrams), ``"check"`` (check telegrams) or ``"wait"`` (check
        sequence complete, waiting for the latch telegrams).
    checks:
        Frames whose check sequence this engine completed (``"check"`` to ``"wait"``, the RTL's ``checked`` strobe):
        a BK closes its silent branch only at such an edge (BK-50).
    in_reset:
        An INTERBUS reset is in progress (until :data:`~supi3.interbus.wire.RESET_END_STATUS_TELEGRAMS` status
        telegrams): data telegrams are repeated as received.
    counter_telegrams:
        The chip is in an LBD mode (Table 2-5): it takes counter telegrams as such (BK-36); set by the core.
    on_grid:
        A whole status telegram has been received since the power-up reset: the receiver is on the telegram grid
        (M16), and only now does a data telegram begin a frame (M19).
    """

    __slots__ = (
        "attn", "check_index", "check_rx", "checks", "chip", "counter_telegrams", "crc_rx", "crc_tx", "cycle",
        "datapath", "err_in", "in_reset", "latches", "local_error", "log", "on_grid", "reset_end_count", "state",
        "transmitter",
    )  # fmt: skip

    def __init__(self, chip: Supi3, log: EventLog, datapath: DataPath, transmitter: Transmitter) -> None:
        self.chip = chip
        self.log = log
        self.datapath = datapath
        self.transmitter = transmitter
        self.counter_telegrams = False
        self.power_up()

    def power_up(self) -> None:
        """Power-up reset: no frame, no INTERBUS reset in progress."""
        self.state = "idle"  # idle | data | check | wait
        self.checks = 0
        self.cycle = Cycle.DATA
        """The current frame's cycle type (its select bit)."""
        self.crc_rx = wire.CRC_INIT
        """The CRC register over the data bits received."""
        self.crc_tx = wire.CRC_INIT
        """The CRC register over the data bits sent."""
        self.check_index = 0
        """Which check telegram (0 to 3) is being received."""
        self.check_rx = 0
        """The check sequence received so far, bit n at 2**n (line order)."""
        self.local_error = False
        """An error seen by this chip in the current frame."""
        self.err_in = False
        """The received CNTR word reports an error (or is illegal)."""
        self.latches = 0
        """Latch status telegrams in a row since the check sequence."""
        self.attn = 0
        """The CNTR attention bit sent."""
        self.in_reset = False
        self.reset_end_count = 0
        """Status telegrams seen since the INTERBUS reset ended on the line."""
        self.on_grid = False

    def enter_reset(self, c: int) -> None:
        """The receiver saw an INTERBUS reset at cycle ``c``."""
        self.log.add(c, "INTERBUS reset detected")
        self.in_reset = True
        self.reset_end_count = 0
        self.end_phases()
        self.state = "idle"
        self.latches = 0
        self.chip.reset_at(c)

    def abandon(self, c: int) -> None:
        """A frame that was not latched ends: invalid cycle (Table 3-13)."""
        if self.state != "idle":
            self.log.add(c, f"{self.cycle.value} cycle discarded")
            self.end_phases()
            self.chip.discard_at(self.cycle, self.local_error, c)
        self.state = "idle"
        self.latches = 0

    def end_phases(self) -> None:
        """Close the I/O access and latch phases (3.4.14, Figure 3-22)."""
        if self.chip.io_access:
            self.chip.set_latch_phase(False)
            self.chip.set_io_access(False)

    def counter_telegram(self, word: int) -> bool:
        """The data telegram whose bits up to its control bit are ``word`` is a counter telegram (BK-36): an LBD
        mode, select = ID, control = check, and no frame running (between frames or waiting for the latch
        telegrams). Normal traffic sends ID check telegrams only inside an ID cycle's check sequence (BK-32)."""
        return (self.counter_telegrams and self.state in ("idle", "wait")
                and (word >> wire.POS_SELECT) & 1 == wire.SELECT_ID_LEVEL
                and (word >> wire.POS_CONTROL) & 1 == wire.CONTROL_CHECK_LEVEL)  # fmt: skip

    def data_telegram_bit(self, k: int, level: int, c: int, word: int) -> int:
        """Bit ``k`` of a data telegram, received at ``level`` (``word``: the telegram's bits so far): the level to
        send on in its place."""
        if k == wire.POS_CONTROL:
            cycle = Cycle.ID if (word >> wire.POS_SELECT) & 1 == wire.SELECT_ID_LEVEL else Cycle.DATA
            check = level == wire.CONTROL_CHECK_LEVEL
            if not check and self.state != "data":
                if self.on_grid:  # M19: not off the grid a chip woke up on, after its power-up
                    self.abandon(c)
                    self._start_frame(cycle, c)
            elif cycle is not self.cycle:
                self._error(c, "select bit changes inside a frame")
            if check:
                if self.state == "data":
                    self.state = "check"
                    self.check_index = 0
                    self.check_rx = 0
                    if self.cycle is Cycle.DATA:
                        self.chip.set_io_access(True)
                elif self.state == "check":
                    self.check_index += 1
                if self.state != "check" or self.check_index >= _CHECK_WORDS:
                    self._error(c, "check telegram out of place")
            return level
        if k not in _DATA_BITS:
            return level
        j = k - wire.POS_DATA
        if self.state == "data":
            out = self.datapath.shift(level, c)
            self.crc_rx = wire.crc_update_bit(self.crc_rx, level)
            self.crc_tx = wire.crc_update_bit(self.crc_tx, out)
            return out
        if self.state == "check" and self.check_index < _CHECK_WORDS:
            return self._check_bit(self.check_index * 8 + j, level)
        return level

    def _start_frame(self, cycle: Cycle, c: int) -> None:
        self.datapath.load(cycle, c)
        self.state = "data"
        self.cycle = cycle
        self.crc_rx = wire.CRC_INIT
        self.crc_tx = wire.CRC_INIT
        self.local_error = False
        self.err_in = False
        self.latches = 0

    def _check_bit(self, n: int, level: int) -> int:
        """Bit ``n`` (0..31, line order) of the check sequence: own CRC word out, CNTR forwarded
        (``wire.forward_cntr``). The ERR pair is decided at the stop bit of the last check telegram, before it
        goes out (:meth:`_close_check`)."""
        self.check_rx |= level << n
        if n < 16:
            return (crc_word(self.crc_tx) >> n) & 1
        bit = n - 16
        if bit == wire.CNTR_ATTN_BIT:
            self.attn = level | int(self.chip.attention)
            return self.attn
        if bit == wire.CNTR_NATTN_BIT:
            return 1 - self.attn
        return 0

    def _close_check(self, c: int) -> None:
        """The whole check sequence has been received: check it and settle the ERR pair still to be sent."""
        if self.check_rx & 0xFFFF != crc_word(self.crc_rx):
            self._error(c, "CRC mismatch")
        flags = wire.decode_cntr(self.check_rx >> 16)
        if flags is None:
            self._error(c, "illegal CNTR word")
        self.err_in = flags is None or flags.error
        self.transmitter.settle_err(int(self.local_error or self.err_in))

    def _error(self, c: int, what: str) -> None:
        if not self.local_error:
            self.log.add(c, f"local error: {what}")
        self.local_error = True

    def telegram_end(self, stop: int, c: int, word: int, length: int) -> None:
        """The last bit of a telegram of ``length`` bits (``word``) was received: its stop bit at level ``stop``."""
        last_check = self.state == "check" and self.check_index == _CHECK_WORDS - 1
        if stop != wire.STOP_LEVEL:
            self._error(c, "stop bit")
        if last_check and length == wire.DATA_TELEGRAM_BITS and not self.in_reset:
            self._close_check(c)
            self.state = "wait"
            self.checks += 1
        if stop != wire.STOP_LEVEL:
            return
        if length == wire.STATUS_TELEGRAM_BITS:
            self.on_grid = True
        if self.in_reset:
            if length == wire.STATUS_TELEGRAM_BITS:
                self.reset_end_count += 1
                if self.reset_end_count == wire.RESET_END_STATUS_TELEGRAMS:
                    self.in_reset = False
                    self.log.add(c, "INTERBUS reset ended")
            return
        if length == wire.DATA_TELEGRAM_BITS:
            return
        latch = (word >> wire.POS_CONTROL) & 1 == wire.CONTROL_CHECK_LEVEL
        if self.state in ("data", "check"):
            self._error(c, "status telegram inside a frame")
            self.abandon(c)
        elif self.state == "wait":
            self.latches = self.latches + 1 if latch else 0
            if self.latches == 1 and self.chip.io_access:
                self.chip.set_latch_phase(True)
            if self.latches == wire.LATCH_STATUS_TELEGRAMS:
                self._finish(c)

    def _finish(self, c: int) -> None:
        if self.local_error or self.err_in:
            self.abandon(c)
            return
        self.datapath.latch(self.cycle, c)
        self.end_phases()
        self.state = "idle"
        self.latches = 0

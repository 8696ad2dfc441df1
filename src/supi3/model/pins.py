"""The cycle-accurate pin-level model of the SUPI 3 chip core: the reference the Amaranth RTL matches pin for pin.

A synchronous machine clocked at 32 MHz (1.7.1), following the convention of :mod:`supi3.verif.pinmodel`: each
call of :meth:`Supi3Pins.step` takes the input pins of one clock cycle, returns the output pins seen during that
cycle, and moves the state across the rising edge at the end of it. The bus behaviour (what is loaded, latched,
discarded, reset) is :class:`supi3.model.chip.Supi3`, the same object the transaction-level ring uses; this module
adds the line receiver, the repeater, the frame engine and the timing of every output pin. Every cycle-level
decision is listed in ``docs/model.md``; the wire format is ``docs/interbus.md``.

Pins (names as in the RTL):

====================  ===  =============================================================================
pin                   dir  meaning
====================  ===  =============================================================================
``do1``               in   INTERBUS forward line in (Table 1-4 "DO1: data line OUT forward", input)
``di2``               in   INTERBUS return line in from the next device (Table 1-4 DI2)
``rbst_ext``          in   a device follows on the outgoing interface (RF = 10, Table 2-2)
``mfp_in``            in   MFP[15..0] levels (16 bits)
``stat_err_n``        in   /StatErr, module error alarm input, active low (3.6.2)
``resu_n``            in   /ResU as seen from outside: 0 while something pulls it low (1.7.2)
``vmon_ok``           in   the voltage monitor's output: 1 above 4.5 V, 0 below 3.9 V (1.7.2)
``do2``               out  INTERBUS forward line out (Table 1-4 DO2_CU)
``di1``               out  INTERBUS return line out to the previous device (Table 1-4 DI1_CU)
``mfp_out``           out  levels driven on MFP[15..0] (undriven bits 0)
``mfp_oe``            out  MFP output enables, one bit per pin (Tables 3-1 to 3-6, 2-8)
``mod_ack_n``         out  /ModAck (3.6.2)
``res_reg_n``         out  /ResReg (Table 3-13, 375 ns pulse on a watchdog reset of process data)
``diag1``, ``diag2``  out  BA/RD or FO1/FO2 (Table 3-16)
``ib_diag``           out  IB_DIAG LED (Table 3-18)
``dclk_out``          out  data clock (Table 1-4)
``resu_drive``        out  1 while the chip pulls /ResU low (open drain, 1.7.2)
====================  ===  =============================================================================
"""

from __future__ import annotations

from bisect import bisect_right
from collections.abc import Mapping, Sequence
from itertools import chain
from typing import Final, NamedTuple

import numpy as np
import numpy.typing as npt

from supi3.checks import check_bits, check_instance, check_int, check_trace, fail
from supi3.config import DeviceConfig
from supi3.errors import ArgumentError
from supi3.interbus import wire
from supi3.interbus.wire import Cycle
from supi3.model.chip import Supi3
from supi3.tables import CLOCK_HZ, RESET_MIN_S
from supi3.verif.pinmodel import EventLog, Pin

# ----------------------------------------------------------------------------------------------------------------
# Cycle-level decisions (docs/model.md; evidence in docs/assumptions/model.md)
# ----------------------------------------------------------------------------------------------------------------

SYNC_STAGES: Final = 2
"""Every asynchronous input passes two flip-flops before use (M1)."""

RESET_STRETCH_CLOCKS: Final = round(RESET_MIN_S * CLOCK_HZ)
"""The internal reset lasts 128 clocks (4 µs, 1.7.2) after its last source went away (M2)."""

IB_DIAG_DIVIDER_BITS: Final[dict[str, int]] = {"slow": 26, "fast": 24}
"""IB_DIAG flashes from a free-running binary divider: 2**26 clocks (0.48 Hz) for "bus not active", 2**24
(1.9 Hz) for "peripheral fault" (Table 3-18 asks 0.5 Hz and 2 Hz; M6)."""

IDLE_TIMEOUT_CLOCKS: Final = round(wire.IDLE_TIMEOUT_S * CLOCK_HZ)
"""A line without a telegram start for 20 ms is an INTERBUS reset (docs/interbus.md A13), once per silence."""

_DATA_BITS: Final = range(wire.POS_DATA, wire.POS_DATA + 8)
_CHECK_WORDS: Final = wire.CHECK_TELEGRAMS  # CRC low, CRC high, CNTR low, CNTR high


def _crc_word(register: int) -> int:
    """The CRC word a bit-serial register stands for (``wire.crc16``'s output stage)."""
    word = int(f"{register:016b}"[::-1], 2) if wire.CRC_REFOUT else register
    return word ^ wire.CRC_XOROUT


Trace = npt.NDArray[np.int64]


class Synced(NamedTuple):
    """The input pins as the logic sees them, after the synchroniser."""

    do1: int
    di2: int
    rbst_ext: int
    mfp_in: int
    stat_err_n: int
    resu_n: int
    vmon_ok: int


_INPUT_NAMES: Final = Synced._fields
IDLE_INPUTS: Final = Synced(wire.IDLE_LEVEL, 0, 0, 0, 1, 1, 1)
"""What the synchroniser holds after reset: the levels of a quiet board (idle line, no fault, power good)."""

_NEVER: Final = 1 << 62


_INPUT_PINS: Final[tuple[Pin, ...]] = (
    Pin("do1"), Pin("di2"), Pin("rbst_ext"), Pin("mfp_in", 16), Pin("stat_err_n"), Pin("resu_n"), Pin("vmon_ok"),
)  # fmt: skip
"""``Supi3Pins.inputs``, in :class:`Synced` order."""
_INPUT_WIDTHS: Final[dict[str, int]] = {pin.name: pin.width for pin in _INPUT_PINS}
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
    mapping = check_names("inputs", inputs, _INPUT_NAMES)
    return Synced(*(check_bits(f"pin {name!r}", mapping[name], _INPUT_WIDTHS[name]) for name in _INPUT_NAMES))


def input_traces(inputs: object) -> dict[str, npt.NDArray[np.integer]]:
    """Input traces by name, checked at once (vectorised): every input pin, each a 1-D integer sequence within its
    pin's width, all of one length. Integer arrays are not copied.

    Raises
    ------
    ArgumentError
        With the pin's name, width and the first bad index, or the lengths.
    """
    mapping = check_names("inputs", inputs, _INPUT_NAMES)
    traces = {name: check_trace(f"pin {name!r} trace", mapping[name], _INPUT_WIDTHS[name]) for name in _INPUT_NAMES}
    n = len(traces["do1"])
    for name, trace in traces.items():
        if len(trace) != n:
            raise fail(f"len(pin {name!r} trace)", f"{n}, the length of pin 'do1' trace", len(trace))
    return traces


class Supi3Pins:
    """The SUPI 3 chip core at pin level, one 32 MHz clock per :meth:`step`, or many per :meth:`run`.

    Parameters
    ----------
    config:
        The pin-strap configuration (the RTL reads the same straps from its strap ports).
    chip:
        The bus behaviour to drive; a new :class:`~supi3.model.chip.Supi3` for ``config`` by default.

    Attributes
    ----------
    chip:
        The transaction-level chip this pin model drives; inspect its registers and events in tests.
    cycle:
        Clock cycles since reset.

    Notes
    -----
    The state holds absolute cycle numbers (when the current telegram began, when the line went low, when the
    reset stretch ends, ...) instead of counters, so that cycles in which nothing happens can be skipped:
    :meth:`run` visits only the cycles where an input changes or an internal event is due, and renders the
    output traces between them. :meth:`step` and :meth:`run` share every line of the per-cycle logic
    (:meth:`_tick`) and agree cycle for cycle (tested).
    """

    # Slots: more than 29 instance attributes in a plain __dict__ slow every attribute access on CPython 3.11.
    __slots__ = (
        "_attn", "_bit", "_check_index", "_check_rx", "_crc_rx", "_crc_tx", "_cycle", "_err_in", "_half_bit",
        "_holding", "_in_reset", "_last_start", "_latches", "_length", "_local_error", "_low_since", "_next_present",
        "_pipe", "_power_ups", "_recording", "_register", "_reset_end_count", "_return_start", "_run_from", "_run_low",
        "_rx_busy", "_stat_active", "_state", "_synced_run", "_t0", "_tx", "_width", "_word", "chip",
        "complete_diagnostics", "config", "cpb", "cycle", "forward_delay", "log", "mfp_oe", "rbst_by_pin", "reset_run",
    )  # fmt: skip

    inputs: Sequence[Pin] = _INPUT_PINS
    outputs: Sequence[Pin] = (
        Pin("do2"), Pin("di1"), Pin("mfp_out", 16), Pin("mfp_oe", 16), Pin("mod_ack_n"), Pin("res_reg_n"),
        Pin("diag1"), Pin("diag2"), Pin("ib_diag"), Pin("dclk_out"), Pin("resu_drive"),
    )  # fmt: skip

    def __init__(self, config: DeviceConfig, chip: Supi3 | None = None) -> None:
        check_instance("config", config, DeviceConfig)
        if chip is not None and (not isinstance(chip, Supi3) or chip.config != config):
            raise fail("chip", "None or a Supi3 of the same configuration", chip)
        self.config = config
        self.chip = chip if chip is not None else Supi3(config)
        self.cpb = wire.clocks_per_bit(config.bit_rate)
        self._half_bit = self.cpb // 2
        self.mfp_oe = config.mfp_output_mask
        self.log = EventLog()
        self.complete_diagnostics = config.diagnostics is not None and config.diagnostics.diag_conf == 0
        """DIAG1 shows BA (DIAG_CONF = 0, Table 3-16)."""
        self.rbst_by_pin = config.rf_mode is not None and config.rf_mode.rf == "10"
        """A following device is told by RBST_EXT (RF = 10, Table 2-2), not recognised on DI2 (M5)."""
        self.forward_delay = wire.REPEATER_DELAY_BITS * self.cpb - SYNC_STAGES
        """Clocks from a bit's mid-bit sample to its first clock on DO2, plus cpb/2 (M8)."""
        self.reset_run = wire.RESET_DETECT_BITS * self.cpb
        """Clocks of start level that make an INTERBUS reset (M11)."""
        self.reset()

    # ------------------------------------------------------------------------------------------------------------
    # Reset
    # ------------------------------------------------------------------------------------------------------------

    def reset(self) -> None:
        """The state right after the ``sync`` reset: power-up reset in progress (it lasts the reset stretch)."""
        self.cycle = 0
        self.log.clear()
        self._pipe: list[Synced] = [IDLE_INPUTS] * SYNC_STAGES
        self._holding = False
        self._recording = False
        self._power_ups: list[tuple[int, int]] = []
        self._tx: list[tuple[int, int]] = []
        self._return_start: tuple[int, bool, int, list[int]] | None = None
        self._power_up(RESET_STRETCH_CLOCKS)

    def _power_up(self, run_from: int) -> None:
        """Power-up reset; the logic runs again from cycle ``run_from`` (after the reset stretch, M2)."""
        if self._recording:
            self._power_ups.append((self.cycle, run_from))
        # /StatErr is sampled afresh after a power-up (_stat_active below): the chip forgets the level it had, so
        # its filter restarts at the first running clock instead of counting from clock 0.
        self.chip._stat_err = False
        self.chip.power_up()
        self.chip.mfp_in = 0
        self._run_from = run_from
        self._stat_active = False
        self._next_present = False
        # receiver
        self._rx_busy = False
        self._t0 = 0
        self._bit = 0
        self._length = wire.DATA_TELEGRAM_BITS
        self._word = 0
        self._low_since: int | None = None
        self._last_start = run_from - 1
        self._in_reset = False
        self._reset_end_count = 0
        # transmitter: (first cycle, level) of every bit sent, oldest first; a power-up drops the bits not yet
        # begun and idles the line from the next cycle
        now = self.cycle
        self._tx = [
            *(entry for entry in self._tx if entry[0] <= now), (now + 1, wire.IDLE_LEVEL)
        ]
        # frame engine
        self._state = "idle"  # idle | data | check | wait
        self._cycle = Cycle.DATA
        self._register = 0
        self._width = 0
        self._crc_rx = wire.CRC_INIT
        self._crc_tx = wire.CRC_INIT
        self._check_index = 0
        self._check_rx = 0
        self._local_error = False
        self._err_in = False
        self._latches = 0
        self._attn = 0

    # ------------------------------------------------------------------------------------------------------------
    # One clock: step()
    # ------------------------------------------------------------------------------------------------------------

    def step(self, inputs: Mapping[str, int]) -> dict[str, int]:
        """Run one clock cycle (see :mod:`supi3.verif.pinmodel`).

        Parameters
        ----------
        inputs:
            The level of every input pin (exactly the names of :attr:`inputs`), each an integer within the pin's
            width: 0 or 1, ``mfp_in`` 0 to 0xFFFF.

        Raises
        ------
        ArgumentError
            A pin missing or unknown, or a level that is not such an integer (:func:`input_row`); nothing changes.
        """
        try:
            do1, di2, rbst = inputs["do1"], inputs["di2"], inputs["rbst_ext"]
            mfp, stat, resu, vmon = inputs["mfp_in"], inputs["stat_err_n"], inputs["resu_n"], inputs["vmon_ok"]
            # The fast path: plain ints within range (one type chain and two shifts), the seven names exactly.
            fast = (int is type(do1) is type(di2) is type(rbst) is type(mfp) is type(stat) is type(resu) is type(vmon)
                    and not (do1 | di2 | rbst | stat | resu | vmon) >> 1 and not mfp >> 16 and len(inputs) == 7)
        except Exception:  # anything a broken mapping raises: input_row() names the problem
            fast = False
        row = Synced(do1, di2, rbst, mfp, stat, resu, vmon) if fast else input_row(inputs)
        c = self.cycle
        synced = self._pipe[-1]
        outputs = self._outputs(c, row.di2)
        self._pipe = [row, *self._pipe[:-1]]
        if c >= self._run_from or self._holding or not (synced.resu_n and synced.vmon_ok):
            self._tick(c, synced, synced.do1)
            if c >= self._run_from:
                self._next_present = bool(synced.rbst_ext) if self.rbst_by_pin else self._next_present or bool(
                    synced.di2
                )
        if len(self._tx) > 8:
            del self._tx[:-8]
        self.cycle = c + 1
        return outputs

    @property
    def holding(self) -> bool:
        """A source of the power-up reset (``vmon_ok`` low, /ResU pulled low) was seen at the last clock edge (M2)."""
        return self._holding

    def forward_level(self) -> int:
        """The forward line output (``do2``) of the current cycle; it depends on state only."""
        return self._do2(self.cycle)

    def output_values(self, c: int, di2: int) -> dict[str, int]:
        """Every output pin during cycle ``c`` (``c`` >= the current cycle; ``di2`` is that cycle's input)."""
        check_int("c", c, self.cycle)
        return self._outputs(c, check_bits("pin 'di2'", di2, 1))

    def _outputs(self, c: int, di2: int) -> dict[str, int]:
        chip = self.chip
        do2 = self._do2(c)
        return {
            "do2": do2,
            # The return line passes straight through when a device follows; the last device loops back (M5).
            "di1": di2 if self._next_present else do2,
            "mfp_out": chip.mfp_outputs,
            "mfp_oe": self.mfp_oe,
            # A pulse the chip starts at clock clk (the edge ending cycle clk) lasts until clk + width in chip
            # time; the pins show it from cycle clk + 1, so for cycles clk + 1 .. clk + width (M3). Cycle 0 comes
            # before any edge (the chip's "no pulse" value is 0).
            "mod_ack_n": int(not 0 < c <= chip.mod_ack_until),
            "res_reg_n": int(not 0 < c <= chip.resreg_until),
            "diag1": int(chip.bus_active) if self.complete_diagnostics else 0,
            "diag2": 0,
            "ib_diag": self._ib_diag(c),
            "dclk_out": int(c % self.cpb < self.cpb // 2),
            "resu_drive": int(c < self._run_from),
        }

    def _ib_diag(self, c: int) -> int:
        """Table 3-18: flashing fast on a peripheral fault, slowly while the bus is not active, else steady."""
        if self.chip.pf:
            return 1 - ((c >> (IB_DIAG_DIVIDER_BITS["fast"] - 1)) & 1)
        if not self.chip.bus_active:
            return 1 - ((c >> (IB_DIAG_DIVIDER_BITS["slow"] - 1)) & 1)
        return 1

    def _do2(self, c: int) -> int:
        """The repeater's output: the last bit whose bit period covers ``c``, else the idle level."""
        cpb = self.cpb
        for start, bit in reversed(self._tx):
            if start <= c:
                return bit if c < start + cpb else wire.IDLE_LEVEL
        return wire.IDLE_LEVEL

    # ------------------------------------------------------------------------------------------------------------
    # The per-cycle logic, shared by step() and run()
    # ------------------------------------------------------------------------------------------------------------

    def _tick(self, c: int, s: Synced, line: int) -> None:
        """The rising edge at the end of cycle ``c``, with the synchronised inputs ``s`` of that cycle; ``line`` is
        their ``do1`` (given apart, since :meth:`run` keeps the line as a trace of its own)."""
        if not (s.resu_n and s.vmon_ok):
            if not self._holding:
                self.log.add(c, "power-up reset")
            self._holding = True
            self._power_up(_NEVER)
            return
        if self._holding:
            self._holding = False
            self._power_up(c + RESET_STRETCH_CLOCKS)
            return
        if c < self._run_from:
            return
        chip = self.chip
        chip.mfp_in = s.mfp_in
        stat = not s.stat_err_n
        if stat != self._stat_active:
            self._stat_active = stat
            chip._set_stat_err(stat, c)
        if c >= chip._due:
            chip._advance(c)
        self._receive(line, c)

    def _next_due(self, c: int, line: int) -> int:
        """The next cycle after ``c`` at which the logic acts with unchanged inputs."""
        # Comparisons rather than min(): this runs once per visited cycle of run().
        if c < self._run_from:
            return self._run_from
        if not self._rx_busy and line == wire.START_LEVEL:
            return c + 1  # a start bit: nothing can be due sooner
        due = self._last_start + IDLE_TIMEOUT_CLOCKS
        if due <= c:
            due = _NEVER
        if self._rx_busy:
            sample = self._t0 + self._half_bit + self._bit * self.cpb
            if sample < due:
                due = sample
        low = self._low_since
        if low is not None and c < low + self.reset_run - 1 < due:
            due = low + self.reset_run - 1
        chip_due = self.chip._due
        if chip_due < due:
            due = chip_due if chip_due > c else c + 1
        return due

    def _receive(self, line: int, c: int) -> None:
        # INTERBUS reset: the start level held for RESET_DETECT_BITS bit periods (docs/interbus.md).
        if line == wire.START_LEVEL:
            if self._low_since is None:
                self._low_since = c
            if c - self._low_since + 1 == self.reset_run:
                self._enter_reset(c)
        else:
            self._low_since = None
        if c - self._last_start == IDLE_TIMEOUT_CLOCKS:
            self.log.add(c, "idle timeout: INTERBUS reset")
            self._abandon_frame(c)
            self.chip.reset_at(c)
        if not self._rx_busy:
            if line == wire.START_LEVEL:
                self._rx_busy = True
                self._t0 = c
                self._bit = 0
                self._word = 0
                self._length = wire.DATA_TELEGRAM_BITS
                self._last_start = c
            return
        if c == self._t0 + self._half_bit + self._bit * self.cpb:
            self._sample(line, c)
            self._bit += 1

    def _enter_reset(self, c: int) -> None:
        self.log.add(c, "INTERBUS reset detected")
        self._in_reset = True
        self._reset_end_count = 0
        self._end_phases()
        self._state = "idle"
        self._latches = 0
        self.chip.reset_at(c)

    def _abandon_frame(self, c: int) -> None:
        """A frame that was not latched ends: invalid cycle (Table 3-13)."""
        if self._state != "idle":
            self.log.add(c, f"{self._cycle.value} cycle discarded")
            self._end_phases()
            self.chip.discard_at(self._cycle, self._local_error, c)
        self._state = "idle"
        self._latches = 0

    def _end_phases(self) -> None:
        if self.chip.io_access:
            self.chip.set_latch_phase(False)
            self.chip.set_io_access(False)

    def _sample(self, level: int, c: int) -> None:
        k = self._bit
        self._word |= level << k
        if k == wire.POS_TYPE:
            data = level == wire.TYPE_DATA_LEVEL
            self._length = wire.DATA_TELEGRAM_BITS if data else wire.STATUS_TELEGRAM_BITS
        out = level
        if not self._in_reset and self._length == wire.DATA_TELEGRAM_BITS:
            out = self._data_telegram_bit(k, level, c)
        # The repeater sends this bit REPEATER_DELAY_BITS after it began on the line (docs/interbus.md).
        self._tx.append((c - self.cpb // 2 + self.forward_delay, out))
        if k == self._length - 1:
            self._rx_busy = False
            self._telegram_end(level, c)

    def _data_telegram_bit(self, k: int, level: int, c: int) -> int:
        word = self._word
        if k == wire.POS_CONTROL:
            cycle = Cycle.ID if (word >> wire.POS_SELECT) & 1 == wire.SELECT_ID_LEVEL else Cycle.DATA
            check = level == wire.CONTROL_CHECK_LEVEL
            if not check and self._state != "data":
                self._abandon_frame(c)
                self._start_frame(cycle, c)
            elif cycle is not self._cycle:
                self._error(c, "select bit changes inside a frame")
            if check:
                if self._state == "data":
                    self._state = "check"
                    self._check_index = 0
                    self._check_rx = 0
                    if self._cycle is Cycle.DATA:
                        self.chip.set_io_access(True)
                elif self._state == "check":
                    self._check_index += 1
                if self._state != "check" or self._check_index >= _CHECK_WORDS:
                    self._error(c, "check telegram out of place")
            return level
        if k not in _DATA_BITS:
            return level
        j = k - wire.POS_DATA
        if self._state == "data":
            return self._shift(level)
        if self._state == "check" and self._check_index < _CHECK_WORDS:
            return self._check_bit(self._check_index * 8 + j, level)
        return level

    def _start_frame(self, cycle: Cycle, c: int) -> None:
        loaded = self.chip.load_at(cycle, c)
        self.log.add(c, f"{cycle.value} cycle: load {loaded.hex()}")
        self._state = "data"
        self._cycle = cycle
        self._width = 8 * len(loaded)
        # Line order: byte 0 first, each byte LSB first: bit i of the register goes out i-th.
        self._register = int.from_bytes(loaded, "little")
        self._crc_rx = wire.CRC_INIT
        self._crc_tx = wire.CRC_INIT
        self._local_error = False
        self._err_in = False
        self._latches = 0

    def _shift(self, level: int) -> int:
        if self._width:
            out = self._register & 1
            self._register = (self._register >> 1) | (level << (self._width - 1))
        else:
            out = level
        self._crc_rx = wire.crc_update_bit(self._crc_rx, level)
        self._crc_tx = wire.crc_update_bit(self._crc_tx, out)
        return out

    def _check_bit(self, n: int, level: int) -> int:
        """Bit ``n`` (0..31, line order) of the check sequence: own CRC word out, CNTR forwarded
        (``wire.forward_cntr``). The ERR pair is decided at the stop bit of the last check telegram, before it
        goes out (:meth:`_close_check`)."""
        self._check_rx |= level << n
        if n < 16:
            return (_crc_word(self._crc_tx) >> n) & 1
        bit = n - 16
        if bit == wire.CNTR_ATTN_BIT:
            self._attn = level | int(self.chip.attention)
            return self._attn
        if bit == wire.CNTR_NATTN_BIT:
            return 1 - self._attn
        return 0

    def _close_check(self, c: int) -> None:
        """The whole check sequence has been received: check it and settle the ERR pair still to be sent."""
        if self._check_rx & 0xFFFF != _crc_word(self._crc_rx):
            self._error(c, "CRC mismatch")
        flags = wire.decode_cntr(self._check_rx >> 16)
        if flags is None:
            self._error(c, "illegal CNTR word")
        self._err_in = flags is None or flags.error
        err = int(self._local_error or self._err_in)
        # The last two data bits sent (CNTR bits 14 and 15) are still in the transmitter.
        stop = self._tx.pop()
        err_bit, nerr_bit = self._tx.pop(), self._tx.pop()
        self._tx += [(nerr_bit[0], 1 - err), (err_bit[0], err), stop]

    def _error(self, c: int, what: str) -> None:
        if not self._local_error:
            self.log.add(c, f"local error: {what}")
        self._local_error = True

    def _telegram_end(self, stop: int, c: int) -> None:
        word = self._word
        last_check = self._state == "check" and self._check_index == _CHECK_WORDS - 1
        if stop != wire.STOP_LEVEL:
            self._error(c, "stop bit")
        if last_check and self._length == wire.DATA_TELEGRAM_BITS and not self._in_reset:
            self._close_check(c)
            self._state = "wait"
        if stop != wire.STOP_LEVEL:
            return
        if self._in_reset:
            if self._length == wire.STATUS_TELEGRAM_BITS:
                self._reset_end_count += 1
                if self._reset_end_count == wire.RESET_END_STATUS_TELEGRAMS:
                    self._in_reset = False
                    self.log.add(c, "INTERBUS reset ended")
            return
        if self._length == wire.DATA_TELEGRAM_BITS:
            return
        latch = (word >> wire.POS_CONTROL) & 1 == wire.CONTROL_CHECK_LEVEL
        if self._state in ("data", "check"):
            self._error(c, "status telegram inside a frame")
        elif self._state == "wait":
            self._latches = self._latches + 1 if latch else 0
            if self._latches == 1 and self.chip.io_access:
                self.chip.set_latch_phase(True)
            if self._latches == wire.LATCH_STATUS_TELEGRAMS:
                self._finish(c)

    def _finish(self, c: int) -> None:
        if self._local_error or self._err_in:
            self._abandon_frame(c)
            return
        received = self._register.to_bytes(self._width // 8, "little")
        self.log.add(c, f"{self._cycle.value} cycle latched: {received.hex()}")
        self.chip.latch_at(self._cycle, received, c)
        self._end_phases()
        self._state = "idle"
        self._latches = 0


    # ------------------------------------------------------------------------------------------------------------
    # Many clocks: run()
    # ------------------------------------------------------------------------------------------------------------

    def _snapshot(self) -> tuple[int, ...]:
        chip = self.chip
        return (chip.mfp_outputs, int(chip.bus_active) if self.complete_diagnostics else 0, int(chip.pf),
                int(chip.bus_active), chip.mod_ack_until, chip.resreg_until, self._run_from)  # fmt: skip

    def run(self, inputs: Mapping[str, Sequence[int] | npt.NDArray[np.generic]]) -> dict[str, Trace]:
        """Run as many clock cycles as the input traces are long; return every output pin's trace.

        The same cycles as calling :meth:`step` once per cycle, with the same results, but only the cycles in
        which something happens are visited (see the class notes).

        Parameters
        ----------
        inputs:
            One equally long trace per input pin (exactly the names of :attr:`inputs`): 1-D integer sequences or
            arrays within the pin's width.

        Raises
        ------
        ArgumentError
            A pin missing or unknown, a trace not such a sequence, a value out of range (with its index), or traces
            of different lengths (:func:`input_traces`); nothing changes.
        """
        raw = input_traces(inputs)
        traces = self._run_forward(raw)
        traces["di1"] = self._return_line(raw["di2"].astype(np.int64, copy=False), traces["do2"])
        return traces

    def _synced_traces(self, raw: Mapping[str, npt.NDArray[np.integer]]) -> dict[str, npt.NDArray[np.int64]]:
        """What the synchroniser delivers in each cycle of ``raw``, followed by the pipeline left after them, as
        contiguous ``int64`` traces (the one copy of the inputs a run makes)."""
        synced = {}
        for name in _INPUT_NAMES:
            held = np.asarray([getattr(stage, name) for stage in reversed(self._pipe)], dtype=np.int64)
            synced[name] = np.concatenate([held, raw[name]], dtype=np.int64, casting="unsafe")
        return synced

    def run_forward(self, inputs: Mapping[str, Sequence[int] | npt.NDArray[np.generic]]) -> dict[str, Trace]:
        """:meth:`run` without ``di1``: the chip's logic does not depend on DI2 beyond the return line's
        pass-through, so a ring runs every chip forward first and then the return line backwards
        (:meth:`return_line`). The ``di2`` trace given here is checked but not used."""
        return self._run_forward(input_traces(inputs))

    def _run_forward(self, raw: Mapping[str, npt.NDArray[np.integer]]) -> dict[str, Trace]:
        n = len(raw["do1"])
        c0 = self.cycle
        self._return_start = (c0, self._next_present, self._run_from,
                              [stage.di2 for stage in reversed(self._pipe)])
        self._power_ups = []
        self._recording = True
        full = self._synced_traces(raw)
        synced = {name: trace[:n] for name, trace in full.items()}
        line = synced["do1"]
        line_change = np.ones(n, dtype=bool)
        line_change[1:] = line[1:] != line[:-1]
        change = np.zeros(n, dtype=bool)
        change[:1] = True
        for name in ("stat_err_n", "resu_n", "vmon_ok"):
            trace = synced[name]
            change[1:] |= trace[1:] != trace[:-1]
        # Input events: cycles where a synchronised input the logic reads changes. A change of the line (do1) only
        # matters while the receiver waits for a start bit: in a telegram the receiver acts at its due cycles
        # (mid-bit samples), and the one thing a line change does there, marking where a run of start level began
        # for the INTERBUS-reset detector, is restored from the trace at each visited cycle (_restore_low_run).
        line_events = np.flatnonzero(line_change).tolist()
        other_events = [*np.flatnonzero(change).tolist(), n]
        self._run_low = (c0, self._low_since, np.maximum.accumulate(np.where(line_change, np.arange(n), 0)))
        # The other synchronised inputs are piecewise constant: keep their values once per piece, found by
        # bisection (a piece's do1 is its first cycle's: the line is read from its own trace).
        pieces = change.copy()
        for name in ("mfp_in", "di2", "rbst_ext"):
            trace = synced[name]
            pieces[1:] |= trace[1:] != trace[:-1]
        starts = np.flatnonzero(pieces)
        values = list(map(Synced._make, zip(*(synced[name][starts].tolist() for name in _INPUT_NAMES), strict=True)))
        starts_list = starts.tolist()
        # Outputs are recorded after a visited cycle only when they may have changed (Supi3.revision).
        chip = self.chip
        shown, run_from = chip.revision, self._run_from
        snaps = [(0, self._snapshot())]
        k = kl = 0
        due = self._next_due(c0 - 1, int(line[0])) if n else _NEVER
        t = -1
        while True:
            while other_events[k] <= t:
                k += 1
            after = min(other_events[k], due - c0)
            if not self._rx_busy:
                kl = bisect_right(line_events, t, kl)
                if kl < len(line_events) and line_events[kl] < after:
                    after = line_events[kl]
            t = after
            if t >= n:
                break
            c = c0 + t
            s = values[bisect_right(starts_list, t) - 1]
            level = line.item(t)
            self.cycle = c
            if c >= self._run_from:
                self._restore_low_run(t, level)
            if c >= self._run_from or self._holding or not (s.resu_n and s.vmon_ok):
                self._tick(c, s, level)
            if chip.revision != shown or self._run_from != run_from:
                shown, run_from = chip.revision, self._run_from
                snaps.append((t + 1, self._snapshot()))
            due = self._next_due(c, level)
        if n and c0 + n - 1 >= self._run_from:
            self._restore_low_run(n - 1, int(line[n - 1]))
        self._recording = False
        self.cycle = c0 + n
        self._pipe = [Synced(*(int(full[name][n + SYNC_STAGES - 1 - i]) for name in _INPUT_NAMES))
                      for i in range(SYNC_STAGES)] if n >= SYNC_STAGES else self._shifted_pipe(raw, n)
        self._synced_run = synced
        traces = self._render(c0, n, snaps, self._tx)
        if len(self._tx) > 8:
            del self._tx[:-8]
        return traces

    def _restore_low_run(self, t: int, level: int) -> None:
        """Set the reset detector's ``_low_since`` as :meth:`_receive` leaves it at run cycle ``t`` (the logic
        running, the synchronised line at ``level``): where this run of start level began, or ``None``."""
        if level != wire.START_LEVEL:
            self._low_since = None
            return
        c0, before, starts = self._run_low
        start = starts.item(t)
        # A run of start level that began before this run() call continues the one the detector already saw.
        self._low_since = before if start == 0 and before is not None else max(c0 + start, self._run_from)

    def _shifted_pipe(self, raw: Mapping[str, npt.NDArray[np.integer]], n: int) -> list[Synced]:
        pipe = list(self._pipe)
        for t in range(n):
            pipe = [Synced(*(int(raw[name][t]) for name in _INPUT_NAMES)), *pipe[:-1]]
        return pipe

    def _render(self, c0: int, n: int, snaps: list[tuple[int, tuple[int, ...]]], tx: list[tuple[int, int]]
                ) -> dict[str, Trace]:
        cycles = np.arange(c0, c0 + n, dtype=np.int64)
        # The snapshot taken after each visited cycle holds until the next one: repeat each over its cycles.
        starts = np.array([t for t, _ in snaps], dtype=np.int64)
        lengths = np.diff(np.append(starts, n)).clip(min=0)
        table = np.array([snap for _, snap in snaps], dtype=np.int64)
        mfp_out, diag1, pf, bus_active, mod_ack_until, resreg_until, run_from = (
            np.repeat(column, lengths) for column in table.T
        )
        fast = 1 - ((cycles >> (IB_DIAG_DIVIDER_BITS["fast"] - 1)) & 1)
        slow = 1 - ((cycles >> (IB_DIAG_DIVIDER_BITS["slow"] - 1)) & 1)
        out = {
            "mfp_out": mfp_out,
            "diag1": diag1,
            "mod_ack_n": ((cycles <= 0) | (cycles > mod_ack_until)).astype(np.int64),  # as output_values()
            "res_reg_n": ((cycles <= 0) | (cycles > resreg_until)).astype(np.int64),
            "resu_drive": (cycles < run_from).astype(np.int64),
            "ib_diag": np.where(pf != 0, fast, np.where(bus_active != 0, 1, slow)),
        }
        cpb = self.cpb
        if tx:
            # Each bit lasts cpb clocks or until the next bit begins (starts are in order), as _do2() reads it; the
            # line idles in the gaps. Runs of (gap, bit) levels, repeated over their lengths, are the trace.
            sent = np.fromiter(chain.from_iterable(tx), dtype=np.int64, count=2 * len(tx)).reshape(-1, 2)
            bit_starts, bits = sent[:, 0], sent[:, 1]
            ends = np.minimum(bit_starts + cpb, np.append(bit_starts[1:], _NEVER))
            lo = np.clip(bit_starts - c0, 0, n)
            hi = np.maximum(np.clip(ends - c0, 0, n), lo)
            gaps = lo - np.append(0, hi[:-1])
            levels = np.column_stack([np.full(len(bits), wire.IDLE_LEVEL), bits]).ravel()
            runs = np.column_stack([gaps, hi - lo]).ravel()
            do2 = np.append(np.repeat(levels, runs), np.full(n - int(hi[-1]), wire.IDLE_LEVEL, dtype=np.int64))
        else:
            do2 = np.full(n, wire.IDLE_LEVEL, dtype=np.int64)
        out["do2"] = do2
        out["mfp_oe"] = np.full(n, self.mfp_oe, dtype=np.int64)
        out["diag2"] = np.zeros(n, dtype=np.int64)
        out["dclk_out"] = (cycles % cpb < cpb // 2).astype(np.int64)
        return out

    def return_line(self, di2: Trace, do2: Trace) -> Trace:
        """``di1`` over the last :meth:`run_forward`, given that run's DI2 trace: the return line passes DI2
        through once a following device is recognised, else loops ``do2`` back (M5).

        Recognition is updated at every clock edge where the logic runs, as in :meth:`step`: with RF = 10 it is
        the synchronised RBST_EXT, otherwise it latches the first high level seen on DI2; power-up clears it.

        Raises
        ------
        ArgumentError
            No :meth:`run_forward` came before, or a trace is not 0/1 integers as long as that run.
        """
        if self._return_start is None:
            raise fail("do2", "the do2 trace of the last run_forward()", do2, "none ran since reset")
        n = len(self._synced_run["do1"])
        traces = {"di2": check_trace("pin 'di2' trace", di2, 1), "do2": check_trace("pin 'do2' trace", do2, 1)}
        for name, trace in traces.items():
            if len(trace) != n:
                raise fail(f"len(pin {name!r} trace)", f"{n}, the length of the last run_forward()", len(trace))
        return self._return_line(traces["di2"].astype(np.int64, copy=False), traces["do2"].astype(np.int64, copy=False))

    def _return_line(self, di2: npt.NDArray[np.int64], do2: npt.NDArray[np.int64]) -> Trace:
        assert self._return_start is not None
        c0, value, run_from, held_di2 = self._return_start
        n = len(do2)
        if self.rbst_by_pin:
            seen = self._synced_run["rbst_ext"]
        else:
            seen = np.concatenate([np.asarray(held_di2, dtype=np.int64), di2])[:n]
            # The synchroniser now holds the real DI2, not the placeholder the forward run saw.
            tail = np.concatenate([np.asarray(held_di2, dtype=np.int64), di2])[-SYNC_STAGES:][::-1]
            self._pipe = [stage._replace(di2=int(v)) for stage, v in zip(self._pipe, tail, strict=True)]
        state = np.empty(n + 1, dtype=bool)  # state[t]: what the outputs of cycle c0 + t see
        state[0] = value
        t = 0
        for at, new_run_from in [*self._power_ups, (c0 + n, run_from)]:
            end = at - c0
            if end > t:
                active = np.arange(c0 + t, c0 + end) >= run_from
                level = seen[t:end] != 0
                if self.rbst_by_pin:
                    values = np.where(active, level, value)
                else:
                    values = np.logical_or.accumulate(level & active) | value
                state[t + 1 : end + 1] = values
                value = bool(values[-1])
            if end < n:
                value = False
                run_from = new_run_from
                state[end + 1] = False
                t = end + 1
        self._next_present = value
        return np.where(state[:n], di2, do2).astype(np.int64)

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

from collections.abc import Mapping, Sequence
from typing import Final

from supi3.config import DeviceConfig
from supi3.interbus import wire
from supi3.interbus.wire import Cycle
from supi3.model.chip import Supi3
from supi3.tables import CLOCK_HZ, RESET_MIN_S, Direction
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


class Supi3Pins:
    """The SUPI 3 chip core at pin level, one 32 MHz clock per :meth:`step`.

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
    """

    inputs: Sequence[Pin] = (
        Pin("do1"), Pin("di2"), Pin("rbst_ext"), Pin("mfp_in", 16), Pin("stat_err_n"), Pin("resu_n"),
        Pin("vmon_ok"),
    )  # fmt: skip
    outputs: Sequence[Pin] = (
        Pin("do2"), Pin("di1"), Pin("mfp_out", 16), Pin("mfp_oe", 16), Pin("mod_ack_n"), Pin("res_reg_n"),
        Pin("diag1"), Pin("diag2"), Pin("ib_diag"), Pin("dclk_out"), Pin("resu_drive"),
    )  # fmt: skip

    def __init__(self, config: DeviceConfig, chip: Supi3 | None = None) -> None:
        self.config = config
        self.chip = chip if chip is not None else Supi3(config)
        self.cpb = wire.clocks_per_bit(config.bit_rate)
        self.mfp_oe = config.mfp_output_mask
        self.log = EventLog()
        self._out_pins = tuple(p.pin for p in config.mfp_pins if p.direction is Direction.OUT)
        self._complete_diag = config.diagnostics is not None and config.diagnostics.diag_conf == 0
        self._pin_rbst = config.rf_mode is not None and config.rf_mode.rf == "10"
        self._forward_delay = wire.REPEATER_DELAY_BITS * self.cpb - SYNC_STAGES
        self.reset()

    # ------------------------------------------------------------------------------------------------------------
    # Reset
    # ------------------------------------------------------------------------------------------------------------

    def reset(self) -> None:
        """The state right after the ``sync`` reset: power-up reset in progress (it lasts the reset stretch)."""
        self.cycle = 0
        self.log.clear()
        self._sync: dict[str, list[int]] = {
            "do1": [wire.IDLE_LEVEL] * SYNC_STAGES, "di2": [0] * SYNC_STAGES, "rbst_ext": [0] * SYNC_STAGES,
            "mfp_in": [0] * SYNC_STAGES, "stat_err_n": [1] * SYNC_STAGES, "resu_n": [1] * SYNC_STAGES,
            "vmon_ok": [1] * SYNC_STAGES,
        }  # fmt: skip
        self._stretch = RESET_STRETCH_CLOCKS
        self._power_up()

    def _power_up(self) -> None:
        self.chip.power_up()
        self.chip.mfp_in = 0
        self._stat_active = False
        # receiver
        self._rx_busy = False
        self._phase = 0
        self._bit = 0
        self._length = 0
        self._word = 0
        self._low_run = 0
        self._in_reset = False
        self._reset_end_count = 0
        self._silent = 0
        # transmitter: (first cycle, level) of the bits being sent, oldest first
        self._tx: list[tuple[int, int]] = []
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
        self._next_present = False

    # ------------------------------------------------------------------------------------------------------------
    # One clock
    # ------------------------------------------------------------------------------------------------------------

    def step(self, inputs: Mapping[str, int]) -> dict[str, int]:
        """Run one clock cycle (see :mod:`supi3.verif.pinmodel`)."""
        sync = self._sync
        s = {name: stages[-1] for name, stages in sync.items()}
        outputs = self._outputs(inputs)
        # rising edge
        for name, stages in sync.items():
            stages.pop()
            stages.insert(0, int(inputs[name]))
        if not s["vmon_ok"] or not s["resu_n"]:
            if self._stretch == 0:
                self.log.add(self.cycle, "power-up reset")
            self._stretch = RESET_STRETCH_CLOCKS
            self._power_up()
        elif self._stretch:
            self._stretch -= 1
            if self._stretch == 0:
                self.log.add(self.cycle, "reset released")
        else:
            self._clock(s)
        self.cycle += 1
        return outputs

    def _outputs(self, inputs: Mapping[str, int]) -> dict[str, int]:
        chip = self.chip
        c = self.cycle
        do2 = self._do2(c)
        bus_active = chip.bus_active
        if chip.pf:
            ib_diag = 1 - ((c >> (IB_DIAG_DIVIDER_BITS["fast"] - 1)) & 1)
        elif not bus_active:
            ib_diag = 1 - ((c >> (IB_DIAG_DIVIDER_BITS["slow"] - 1)) & 1)
        else:
            ib_diag = 1
        return {
            "do2": do2,
            # The return line passes straight through when a device follows; the last device loops back (M5).
            "di1": int(inputs["di2"]) if self._next_present else do2,
            "mfp_out": chip.mfp_outputs,
            "mfp_oe": self.mfp_oe,
            "mod_ack_n": int(c >= chip.mod_ack_until),
            "res_reg_n": int(c >= chip.resreg_until),
            "diag1": int(bus_active) if self._complete_diag else 0,
            "diag2": 0,
            "ib_diag": ib_diag,
            "dclk_out": int(c % self.cpb < self.cpb // 2),
            "resu_drive": int(self._stretch > 0),
        }

    def forward_level(self) -> int:
        """The forward line output (``do2``) of the current cycle; it depends on state only."""
        return self._do2(self.cycle)

    def _do2(self, c: int) -> int:
        level = wire.IDLE_LEVEL
        for start, bit in self._tx:
            if start <= c < start + self.cpb:
                level = bit
        return level

    # ------------------------------------------------------------------------------------------------------------
    # Synchronous logic
    # ------------------------------------------------------------------------------------------------------------

    def _clock(self, s: Mapping[str, int]) -> None:
        c = self.cycle
        chip = self.chip
        chip.mfp_in = s["mfp_in"]
        stat = not s["stat_err_n"]
        if stat != self._stat_active:
            self._stat_active = stat
            chip._set_stat_err(stat, c)
        chip._advance(c)
        if self._pin_rbst:
            self._next_present = bool(s["rbst_ext"])
        elif s["di2"]:
            self._next_present = True
        if len(self._tx) > 4:
            del self._tx[:-4]
        self._receive(s["do1"], c)

    def _receive(self, line: int, c: int) -> None:
        cpb = self.cpb
        # INTERBUS reset: the start level held for RESET_DETECT_BITS bit periods (docs/interbus.md).
        if line == wire.START_LEVEL:
            self._low_run += 1
            if self._low_run == wire.RESET_DETECT_BITS * cpb:
                self._enter_reset(c)
        else:
            self._low_run = 0
        self._silent += 1
        if self._silent == IDLE_TIMEOUT_CLOCKS:
            self.log.add(c, "idle timeout: INTERBUS reset")
            self._abandon_frame(c)
            self.chip.reset_at(c)
        if not self._rx_busy:
            if line != wire.START_LEVEL:
                return
            self._rx_busy = True
            self._phase = 0
            self._bit = 0
            self._word = 0
            self._length = wire.DATA_TELEGRAM_BITS
            self._silent = 0
        elif self._phase == cpb - 1:
            self._phase = 0
            self._bit += 1
        else:
            self._phase += 1
        if self._phase == cpb // 2:
            self._sample(line, c)

    def _enter_reset(self, c: int) -> None:
        self.log.add(c, "INTERBUS reset detected")
        self._in_reset = True
        self._reset_end_count = 0
        self._state = "idle"
        self._latches = 0
        self.chip.reset_at(c)

    def _abandon_frame(self, c: int) -> None:
        """A frame that was not latched ends: invalid cycle (Table 3-13)."""
        if self._state != "idle":
            self.log.add(c, f"{self._cycle.value} cycle discarded")
            self.chip.discard_at(self._cycle, self._local_error, c)
        self._state = "idle"
        self._latches = 0

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
        self._tx.append((c - self.cpb // 2 + self._forward_delay, out))
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
            if self._latches == wire.LATCH_STATUS_TELEGRAMS:
                self._finish(c)

    def _finish(self, c: int) -> None:
        if self._local_error or self._err_in:
            self._abandon_frame(c)
            return
        received = self._register.to_bytes(self._width // 8, "little")
        self.log.add(c, f"{self._cycle.value} cycle latched: {received.hex()}")
        self.chip.latch_at(self._cycle, received, c)
        self._state = "idle"
        self._latches = 0


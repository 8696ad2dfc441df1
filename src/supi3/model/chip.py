"""The SUPI 3 chip's INTERBUS slave behaviour, shared by both model fidelities.

:class:`Supi3` is the transaction-level chip: it implements :class:`supi3.interbus.link.Device`, so a
:class:`~supi3.interbus.ring.Ring` shifts whole frames through it. The cycle-accurate pin-level model drives the
very same object at the exact clock of each bus event, so both fidelities share one behaviour; only the pin level
adds the line receiver, the repeater and the pins' timing.

Time inside the chip is counted in periods of the 32 MHz clock (1.7.1); the transaction-level interface takes
bus time in seconds and converts.

What the chip does on each bus event (docs/interbus.md, docs/assumptions/model.md):

* **load** (a frame begins): the register is parallel-loaded: the ID register in an ID cycle; the IN data in a
  data cycle, sampled from the MFP inputs in binary I/O modes (Tables 3-1, 3-2) or taken from IN bytes 0..3 in
  the µP modes (3.4.8).
* **latch** (the master's latch telegrams after a good check): OUT data is taken over (MFP outputs in binary I/O
  modes, OUT bytes in µP modes), the valid-data-cycle event is raised and the layer-2 watchdog restarted; in an ID
  cycle the command word is applied (watchdog setting, Quit Peripheral Error) and the ID-cycle event raised.
* **discard** (no latch): nothing latched changes; the invalid-data-cycle event is raised (Table 3-13).
* **reset** (INTERBUS reset): IN and OUT data registers and MFP outputs are cleared, the watchdog is switched off,
  the INTERBUS-reset event is raised (3.4.7, Table 3-13).
* /StatErr low for the filter time (200 ms, 3.6.2) latches the peripheral fault (PF) that the master reports as
  0BB1h; the watchdog's expiry resets process data and latches WD (0C6Bh). Quit Peripheral Error (0714h) pulses
  /ModAck.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import ClassVar, Final, Protocol, TypeVar

import numpy as np
import numpy.typing as npt

from supi3 import tables
from supi3.checks import check_bits, check_bool, check_bytes, check_instance, check_int, check_real, fail
from supi3.config import DeviceConfig, MfpKind, Variant, decode
from supi3.config import Interface as LineInterface
from supi3.diagnostics import DiagnosticOutputs, LedInputs, diagnostic_outputs, fo_leds, watches_line_interrupt
from supi3.errors import ArgumentError, Supi3Error
from supi3.expansion import PULSE_T0, ExternalRegisters, end_pulses
from supi3.interbus import wire
from supi3.interbus.link import DataKernel
from supi3.interbus.wire import Cycle
from supi3.model.blocks.forward import forward_path
from supi3.model.bus_terminal import BusTerminal
from supi3.model.registers import RegisterFile, event_mask
from supi3.optical import regulation
from supi3.optical.length import Medium, timer_code
from supi3.optical.regulation import Interface, OpticalMode, OpticalStatus, Phase, Response
from supi3.pinlevel import EventLog
from supi3.pinout import OPTICAL_REGISTERS, SYNC_STAGES, TIME_BASE_BITS, time_base_end
from supi3.serial_io import SerialDevice, SerialSequence, clear_sequence, sequence
from supi3.terminal import BRANCH_SILENCE_CLOCKS, silence_limit

CLOCK_HZ: Final = tables.CLOCK_HZ
_NEVER: Final = 1 << 62
_DATA: Final = Cycle.DATA  # enum attribute lookups cost ~0.1 µs on the hot path

STATERR_FILTER_CLOCKS: Final = round(tables.STATERR_FILTER_S * CLOCK_HZ)
"""/StatErr must stay low this many clocks (200 ms, 3.6.2) before the peripheral fault is latched."""

MODACK_PULSE_CLOCKS: Final = tables.RESREG_PULSE_CLOCKS
"""/ModAck pulse on Quit Peripheral Error: the manual gives no width; the chip's other single pulse (375 ns,
Table 3-13) is used (docs/assumptions/model.md M3)."""

RESREG_PULSE_CLOCKS: Final = tables.RESREG_PULSE_CLOCKS
"""/ResReg pulse on a layer-2 watchdog reset of process data: 375 ns (Table 3-13)."""

WATCHDOG_CLOCKS: Final[tuple[int | None, ...]] = tuple(
    None if t is None else round(t * CLOCK_HZ) for t in tables.WATCHDOG_TIMEOUTS_S
)
"""Layer-2 watchdog times in clocks, indexed by the command word's watchdog code (Table 3-13)."""


class ChipError(Supi3Error, ValueError):
    """A request the chip model cannot carry out (wrong data width, pin value out of range, ...)."""


class SerialModeError(ChipError):
    """A serial I/O request the chip's mode does not allow: a device attached outside the SPI master modes of
    Tables 2-4 to 2-6, or IN data set by hand while a device provides them (manual 3.3)."""


class ChipArgumentError(ArgumentError, ChipError):
    """An argument of a :class:`Supi3` method of the wrong type or out of its range ("X must be ..., not ..."): an
    :class:`~supi3.errors.ArgumentError` that code catching :class:`ChipError` still catches."""


class ExpansionDriver(Protocol):
    """The pin level's register-expansion block (:class:`supi3.model.blocks.expansion.Expansion`): when a chip has
    one, the cycle ends and resets go to its pins, and the chain is clocked there, not at transaction level."""

    def end(self, clk: int, latched_data: bool) -> None:
        """The cycle ended at the edge ending cycle ``clk``."""

    def reset(self, clk: int) -> None:
        """An INTERBUS or watchdog reset at the edge ending cycle ``clk``."""


EXPANSION_LEAD_BITS: Final = wire.POS_DATA + 1.25
"""Bit periods from the start of a frame to its first ClkExR rise, less the half bit from the mid-bit sample of the
previous cycle's last stop bit (where its end pulses begin) to that bit's end: the transaction level's view of
RX-4 (``supi3.model.blocks.expansion.lead_clocks``; ``docs/assumptions/expansion.md``)."""


_T = TypeVar("_T")
_INF: Final = math.inf
_WORD_BYTES: Final = 2
"""Bytes of the command word an ID cycle latches (16 bits, docs/interbus.md "Words")."""
TIME_LIMIT: Final = "bus time in seconds since power-up"
"""What a transaction-level time argument is: finite and not negative (NaN and infinity have no clock count)."""


def _checked(check: Callable[..., _T], *args: object, **kwargs: object) -> _T:
    """Run a :mod:`supi3.checks` check; its error comes out as a :class:`ChipArgumentError`. Hot paths call this
    only after a cheap inline test failed, so a valid call never pays for it."""
    try:
        return check(*args, **kwargs)
    except ArgumentError as error:
        raise ChipArgumentError(error.name, error.value, str(error)) from None


def clocks(now: float) -> int:
    """Bus time in seconds as a count of 32 MHz clock periods.

    Raises
    ------
    ChipArgumentError
        If ``now`` is not a finite number >= 0.
    """
    if type(now) is not float or not 0.0 <= now < _INF:
        now = _checked(check_real, "now", now, 0, limit=TIME_LIMIT)
    return round(now * CLOCK_HZ)


def _clock(clk: object) -> int:
    """``clk`` checked as a clock count (an ``int`` >= 0)."""
    return _checked(check_int, "clk", clk, 0, limit="32 MHz clock periods since power-up")


def _cycle(cycle: object) -> Cycle:
    """``cycle`` checked as a :class:`~supi3.interbus.wire.Cycle`."""
    checked: Cycle = _checked(check_instance, "cycle", cycle, Cycle, "Cycle.ID or Cycle.DATA")
    return checked


_VALID_EVENTS: Final[int] = event_mask("VALID", "PCP_RX", "PCP_TX")
"""M32, M33: the interrupt events of a valid data cycle's latch (Table 3-13), as one mask made once."""
_OPTICAL_MODES: Final[dict[str, OpticalMode]] = {"00": OpticalMode.REGULATION, "01": OpticalMode.DIAGNOSTIC}
"""RF[1..0] patterns with an optical block at work (Table 2-2, OPT-2); the others are copper (OFF)."""


def _interface(interface: object) -> Interface:
    """``interface`` checked as an optical :class:`~supi3.optical.regulation.Interface`."""
    checked: Interface = _checked(check_instance, "interface", interface, Interface, "Interface.IN, OUT or BRANCH")
    return checked


# ----------------------------------------------------------------------------------------------------------------
# The ring kernel (docs/interbus.md, "Ring kernel")
# ----------------------------------------------------------------------------------------------------------------
# The transaction-level ring's hot path: one call per run of chips in a data cycle instead of two method calls per
# chip, and Supi3.load and Supi3.latch take their shortcut through it too. It reads the chip's flat state directly
# and takes the shortcut where nothing is due; every other case goes through load_at/latch_at in full:
#   _due_s        the bus time of the next time-driven change (/StatErr filter, watchdog), in seconds; -1.0 in
#                 the µP modes, whose data path goes through the register file;
#   _loaded       (MFP levels, IN bytes) of the last data-cycle sample (binary I/O modes; (-1, b"") otherwise);
#   _fixed_bytes  the data length of a pin-strapped mode (None in the µP modes, which never take the shortcut);
#   watchdog_code None while the master has set no watchdog (a latch then leaves the schedule alone);
#   _fast_valid   valid data cycles latched by the shortcut (and by a µP-mode chip, M33), merged into Supi3.events.
# Supi3 declares its state in __slots__, so these reads are fixed-offset loads whatever the number of attributes.
# tests/test_interbus_ring_kernel.py holds the kernel to the per-chip path.


def _load_data_run(chips: Sequence[Supi3], now: float) -> tuple[list[bytes], bool]:
    """``[chip.load(Cycle.DATA, now) for chip in chips]`` and whether any chip wants attention afterwards."""
    registers: list[bytes] = []
    append = registers.append
    attention = False
    for chip in chips:
        loaded = chip._loaded
        if now < chip._due_s and chip.mfp_in == loaded[0]:
            append(loaded[1])
        else:
            append(chip.load_at(_DATA, round(now * CLOCK_HZ)))  # clocks(now): the callers' now is a finite float >= 0
        if chip.attention:
            attention = True
    return registers, attention


def _latch_data_run(chips: Sequence[Supi3], received: Sequence[bytes], now: float) -> None:
    """``chip.latch(Cycle.DATA, data, now)`` for every chip and its ``data`` (of the width its load gave: a µP
    mode chip, whose width may change, has ``_due_s`` -1 and never takes the shortcut)."""
    for chip, data in zip(chips, received, strict=True):
        if now < chip._due_s and chip.watchdog_code is None:
            chip.bus_active = True
            chip._out = data
            chip.revision += 1
            chip._fast_valid += 1
        else:
            chip.latch_at(_DATA, data, round(now * CLOCK_HZ))  # clocks(now), as in _load_data_run


class _SerialPins(Protocol):
    """The pin-level serial I/O block (:class:`supi3.model.blocks.serial_io.SerialIo`) as the chip drives it."""

    def start(self, c: int, word: int) -> None: ...
    def clear(self, c: int) -> None: ...


def _transact(seq: SerialSequence, device: SerialDevice, word: int) -> int | None:
    """``seq`` on ``device`` at transaction level, writing ``word``: its frames in order, then /Conv; the word read
    (None without a read frame), checked (SM-11)."""
    read = None
    for frame in seq.frames:
        answer = device.frame(word if frame.write else 0, frame.bits)
        if not frame.write:
            read = _checked(check_bits, "SerialDevice.frame()", answer, frame.bits, "the bits read, MSB first")
    if seq.conv is not None:
        device.convert()
    return read


class Supi3:
    """One SUPI 3 OPC (or LS) chip on an INTERBUS ring, at transaction level.

    Parameters
    ----------
    config:
        The pin-strap configuration (:func:`supi3.config.decode`); ``None`` for the demo device (C[4..0] = 10000).
    strict:
        µP modes: raise interface rule violations (``True``) or record them (``False``), see
        :class:`~supi3.model.registers.RegisterFile`.
    pedantic:
        µP modes: also report legal but suspicious µP accesses (:class:`~supi3.model.registers.RegisterFile`,
        UP-30); ignored in the other modes.
    stat_err_filter:
        The /StatErr input filter (3.6.2: t3 = 200 ms) in clocks: 1 up to :data:`STATERR_FILTER_CLOCKS` (the default);
        shorter only to reach a peripheral fault quickly in tests at pin level (MCU-24), as ``Supi3Pins``'s
        ``branch_silence``.
    branch_silence:
        In the BK modes, the silence of the branch return line after which the extended function closes the branch
        (BK-3), in clocks: 1 up to :data:`~supi3.terminal.BRANCH_SILENCE_CLOCKS` (the default, 10 ms); shorter only
        to reach the closure quickly in tests, as ``Supi3Pins``'s ``branch_silence`` (the same value at both
        fidelities).

    Attributes
    ----------
    registers:
        The µP-visible register file in Init-µP modes, else ``None``.
    events:
        How often each interrupt source of Table 3-13 fired (``"VALID"``, ``"INVALID"``, ``"ID_CYCLE"``,
        ``"IB_RESET"``, ``"PCP_RX"``, ``"PCP_TX"``), plus ``"WATCHDOG"`` and ``"MODACK"``.
    """

    __slots__ = (
        "__dict__",  # room beyond the declared state, so that a test can spy on a chip's methods
        "_branch_silence", "_chain", "_cpb", "_deadline", "_due_s", "_events", "_exr_driver", "_exr_free",
        "_fast_valid", "_fixed_bytes",
        "_frame_bytes", "_in_map", "_loaded", "_mau_events", "_mau_told", "_now", "_optical", "_optical_driven",
        "_optical_held", "_optical_until", "_out", "_out_map", "_path", "_send_alarm", "_send_optical",
        "_serial_pins", "_shown", "_stat_due", "_stat_err", "_stat_filter", "_watch_line", "attention",
        "bus_active", "config", "constant_output",
        "due", "following", "in_word", "io_access", "led_inputs", "line_interrupt", "line_silent", "mfp_in",
        "mod_ack_until", "pf", "registers", "resreg_until", "revision", "sends_constant", "serial_device",
        "spi_sequences", "te",
        "watchdog_code", "wd",
    )  # fmt: skip

    data_kernel: ClassVar[DataKernel] = DataKernel(_load_data_run, _latch_data_run)
    """The ring's fast path for runs of chips in a data cycle (:class:`supi3.interbus.link.DataKernel`)."""

    def __init__(self, config: DeviceConfig | None = None, *, strict: bool = True, pedantic: bool = False,
                 stat_err_filter: int = STATERR_FILTER_CLOCKS,
                 branch_silence: int = BRANCH_SILENCE_CLOCKS) -> None:  # fmt: skip
        if config is not None and not isinstance(config, DeviceConfig):
            _checked(check_instance, "config", config, DeviceConfig, "a DeviceConfig (supi3.config.decode) or None")
        _checked(check_bool, "strict", strict)
        _checked(check_bool, "pedantic", pedantic)
        self._stat_filter = _checked(check_int, "stat_err_filter", stat_err_filter, 1, STATERR_FILTER_CLOCKS,
                                     "the 200 ms of 3.6.2 in clocks; shorter only to test a fault quickly")  # fmt: skip
        self._branch_silence = _checked(silence_limit, branch_silence, "branch_silence")
        self.config = config if config is not None else decode("10000")
        kind = self.config.mfp_mode.kind
        self.registers = (
            RegisterFile(self.config, strict=strict, pedantic=pedantic) if kind is MfpKind.INIT_UP else None
        )
        if self.registers is not None:
            self.registers.use_clock(self._clock)  # violations name the clock of the last bus call (docs/model.md)
        self._in_map = self.config.in_bits
        self._out_map = self.config.out_bits
        self._events: Counter[str] = Counter()
        self._fast_valid = 0  # valid data cycles taken by the fast path of latch(), merged into events
        self.mfp_in = 0
        self._stat_err = False
        # Pin-strapped modes have a fixed data length; the µP modes ask the register file every time.
        self._fixed_bytes = None if self.registers is not None else wire.data_bytes(self.config.length_code)
        self._path = (-1, False, 0)  # µP modes: (the register file's configurations, expansion, data bytes)
        self._loaded = (-1, b"")  # (MFP levels, IN bytes) of the last data-cycle load
        self._frame_bytes = -1  # µP modes: the data bytes the last data-cycle load gave (M15)
        self._shown: tuple[bytes | None, int] = (None, 0)  # (OUT bytes, MFP levels) last driven
        self._init_serial()
        self.sends_constant = self.registers is not None and self.config.variant is not Variant.LS
        """RX-13: the chip's data path can open, so that a data cycle's :attr:`constant_output` may be a level: a
        SUPI 3 OPC in an Init-µP mode (the chips with the expansion interface, RX-1). Fixed by the configuration:
        the ring reads it when it plans its devices."""
        self._chain: ExternalRegisters | None = None
        self._exr_driver: ExpansionDriver | None = None
        self._optical_driven = False  # pin level: the optical block makes every transition (_optical_drive, OPT-26)
        self._cpb = wire.clocks_per_bit(self.config.bit_rate)
        self._watch_line = watches_line_interrupt(self.config)
        self.led_inputs = LedInputs()
        """What the optical block and the bus terminal logic show on the LEDs (:meth:`set_led_inputs`)."""
        self.following = False
        """A following device is recognised on the outgoing interface (M5; RD is off, DG-5): :meth:`set_following`
        (the pin level's transmitter tells it at every clock edge)."""
        self.revision = 0
        """Counts the changes of what the pins show (OUT data, ``pf``, ``bus_active``, the /ModAck and /ResReg
        pulses): the pin level records its outputs only when this moves."""
        self.power_up()

    # --------------------------------------------------------------------------------------------------------
    # Power-up and pins
    # --------------------------------------------------------------------------------------------------------

    def woken_output(self, do1: npt.NDArray[np.int64]) -> npt.NDArray[np.int64] | None:
        """What this chip, powered up at the first clock of the forward line ``do1`` (32 MHz samples), sends on DO2
        over it: its core's forward path (the blocks :class:`~supi3.model.pins.Supi3Pins` wires: the synchroniser
        and receiver, M1, M7, M16; the frame engine and data path, M8, M19; the transmitter, M12) on a fresh chip of its
        configuration with its MFP inputs (the power-up clears the rest, 1.7.2), its logic running from the end of the
        reset's stretch (M2). The transaction level's wake-up window follows a woken chip's line with it
        (``interbus.wake.wake_return``, M28). ``None`` for a BK or an LBD chip, whose DO2 also depends on lines ``do1``
        does not give (the branch's DI3, the counter blocks, M17, M18; M25's limit 1)."""
        interface = self.config.interface
        if interface.is_bus_terminal or interface in (LineInterface.LBD_MR, LineInterface.LBD_OR):
            return None
        chip = Supi3(self.config)
        chip.set_mfp_inputs(self.mfp_in)
        path = forward_path(chip, EventLog())
        transmitter, receiver = path.transmitter, path.receiver
        stretch = round(tables.RESET_MIN_S * tables.CLOCK_HZ)
        receiver.power_up(stretch)
        synced = np.concatenate([np.full(SYNC_STAGES, wire.IDLE_LEVEL, dtype=np.int64), do1])  # M1
        for c in range(stretch, len(do1)):
            receiver.clock(int(synced[c]), c)
        return np.asarray(transmitter.render(0, len(do1)), dtype=np.int64)

    def power_up(self) -> None:
        """Power-up reset (1.7.2): every register 0, watchdog off, no fault latched (3.4.7)."""
        self.revision += 1
        if self.registers is not None:
            self.registers.power_up_reset()
        self.in_word = 0
        self._out = b""
        self.pf = False
        self.wd = False
        self.te = False
        self.attention = False
        self.bus_active = False
        self.watchdog_code: int | None = None
        self._now = 0
        self._deadline: int | None = None
        self._stat_due: int | None = self._stat_end(0) if self._stat_err else None
        self.mod_ack_until = 0
        self.resreg_until = 0
        self.io_access = False
        self._send_alarm = False
        self._exr_free = 0
        self.constant_output: int | None = None
        """RX-13: after a data-cycle load, the level the chip sends for every data bit of the frame in place of what
        shifts through it (ExtReg = 1 with nothing on FromExR: 0, the grounded pin), ``None`` when the frame shifts
        through its register (the ring reads it for the chips whose :attr:`sends_constant` is set)."""
        self.line_silent = False
        """The incoming line fell silent (idle time-out) and was not heard since: RC off, /ResReg low (DG-4)."""
        self.line_interrupt = False
        """IB_DIAG's 4 Hz cause: a line interrupt ahead on the local bus (DG-3)."""
        self._init_bus_terminal()
        self._optical_power_up()  # optical block (1.6)
        self._reschedule()

    def _clock(self) -> int:
        """The chip's clock count as last told by a bus call (load, latch, discard, reset, poll, /StatErr)."""
        return self._now

    @property
    def events(self) -> Counter[str]:
        """How often each interrupt source of Table 3-13 fired, plus ``"WATCHDOG"`` and ``"MODACK"``."""
        fast = self._fast_valid
        return self._events + Counter({"VALID": fast, "PCP_RX": fast, "PCP_TX": fast})

    @property
    def out_word(self) -> int:
        """The OUT data of the last valid data cycle (binary I/O, SPI master and bus terminal modes)."""
        return int.from_bytes(self._out, "big")

    def set_io_access(self, busy: bool) -> None:
        """The I/O access (polling) bit (3.4.14, Fig. 3-22): 1 from the start of a data cycle's check sequence to
        the end of its latch phase, so a 0 leaves at least the check sequence (52 bit periods, more than the
        manual's 30) before data move; in µP modes it is D7 of the interrupt event register and MFP1."""
        if type(busy) is not bool:
            busy = _checked(check_bool, "busy", busy)
        self.io_access = busy
        if self.registers is not None:
            self.registers.set_io_access(busy)

    def set_latch_phase(self, active: bool) -> None:
        """The latch phase (3.4.14): from the first latch telegram to the latch; µP accesses to the data
        registers inside it are reported as inconsistent data."""
        if type(active) is not bool:
            active = _checked(check_bool, "active", active)
        if self.registers is not None:
            self.registers.set_latch_phase(active)

    def set_mfp_inputs(self, levels: int) -> None:
        """Drive the MFP[15..0] input pins (binary I/O modes sample them when a data cycle begins)."""
        self.mfp_in = _checked(check_bits, "levels", levels, 16, "MFP[15..0]")
        self._bus_terminal_inputs()

    @property
    def mfp_outputs(self) -> int:
        """The levels the chip drives on its MFP output pins (binary I/O modes, Tables 3-1 and 3-2)."""
        out = self._out
        if out is not self._shown[0]:  # recomputed only when new OUT data were latched
            word = int.from_bytes(out, "big")
            self._shown = (out, sum(((word >> bit) & 1) << pin for bit, pin in self._out_map))
        return self._shown[1]

    def set_stat_err(self, active: bool, now: float) -> None:
        """Drive /StatErr (3.6.2): ``True`` pulls it low (an I/O error); the fault latches after the filter time."""
        active = _checked(check_bool, "active", active)
        self._set_stat_err(active, clocks(now))

    def _set_stat_err(self, active: bool, clk: int) -> None:
        self._advance(clk)
        if active and not self._stat_err:
            self._stat_due = self._stat_end(clk)
        elif not active:
            self._stat_due = None
        self._stat_err = active
        self._reschedule()

    @property
    def module_error(self) -> bool:
        """/StatErr has been low for the whole filter time (3.6.2)."""
        return self._filtered

    # --------------------------------------------------------------------------------------------------------
    # Diagnostic outputs (3.6.1, Tables 3-16 to 3-19, 2-8): the LED view, the silent line and the line interrupt
    # ahead (supi3.diagnostics; docs/assumptions/diagnostics.md DG-1 to DG-8). The pin level's outputs block shows
    # the same state at the pins (supi3.model.blocks.outputs).
    # --------------------------------------------------------------------------------------------------------

    @property
    def diagnostic_outputs(self) -> DiagnosticOutputs:
        """Every diagnostic LED now (read-only), from the chip's state through :func:`supi3.diagnostics.
        diagnostic_outputs`: UL, RC, BA, RD, LD, E, ALARM, FO1..FO3, the IB_DIAG pattern, and DIAG1/DIAG2 as
        DIAG_CONF selects. At transaction level the supply is always good (UL lit): the power-up reset has no
        duration here (1.7.2 is the pin level's)."""
        # FO1..FO3 come from the optical block (Table 3-17, OPT-8; RUN is the bus active, DG-7), LD, E and ALARM from
        # the bus terminal: the branch switched off or closed by the BK (LD), a break behind it or closed (E; BK-11),
        # the master's ALARM (BK-12).
        leds = replace(self.led_inputs, fo=fo_leds(self._optical, self.bus_active))
        terminal = self.bus_terminal
        if terminal is not None:
            state = terminal.state
            leds = replace(leds, ld=state.ld, e=state.e, alarm=state.alarm)
        return diagnostic_outputs(self.config, supply_ok=True, line_heard=not self.line_silent,
                                  bus_active=self.bus_active, peripheral_fault=self.pf,
                                  line_interrupt=self.line_interrupt, following=self.following,
                                  leds=leds)  # fmt: skip

    def set_following(self, present: bool) -> None:
        """The line side's recognition of a following device on the outgoing interface (M5): RD is lit while there
        is none (DG-5). A chip alone has none; a ring's line side tells each chip (the pin level's recognition is
        the transmitter's, RBST_EXT with RF = 10, else the first high level seen on DI2).

        Raises
        ------
        ChipArgumentError
            ``present`` is not a bool.
        """
        present = _checked(check_bool, "present", present)
        if present != self.following:
            self.following = present
            self.revision += 1

    def set_led_inputs(self, leds: LedInputs) -> None:
        """What the LED inputs show from now on; both fidelities read it (the RTL ties these ports to 0). FO1..FO3
        always come from the chip's own optical block (:attr:`optical`, :func:`supi3.diagnostics.fo_leds`) and, in
        the bus terminal modes, LD, E and ALARM from its branch state (BK-11, BK-12), so those fields are not used.

        Raises
        ------
        ChipArgumentError
            ``leds`` is not a :class:`~supi3.diagnostics.LedInputs`.
        """
        self.led_inputs = _checked(check_instance, "leds", leds, LedInputs)
        self.revision += 1

    def line_timeout(self, now: float, counted: bool = False) -> None:
        """The incoming line was silent for ``wire.IDLE_TIMEOUT_S`` (A13), ending at bus time ``now``: what the
        line side calls in place of :meth:`reset` for a silent line (:meth:`line_timeout_at`); ``counted``: counter
        telegrams came in the silence (DG-9)."""
        self.line_timeout_at(clocks(now), counted)

    def line_timeout_at(self, clk: int, counted: bool = False) -> None:
        """The idle time-out at clock ``clk``: the INTERBUS reset it makes (:meth:`reset_at`); the line counts as
        silent until it is heard again (RC off, /ResReg low: DG-4), and in the local bus modes a bus that was
        active raises the line interrupt ahead (IB_DIAG 4 Hz: DG-3) unless ``counted``: counter telegrams came in
        the silence, so the break is further ahead (DG-9). The master's reset pattern, the end of the next cycle
        that reaches the chip (latch or discard) and a power-up clear both."""
        if type(clk) is not int or clk < 0:
            clk = _clock(clk)
        if type(counted) is not bool:
            counted = _checked(check_bool, "counted", counted)
        interrupt = self._watch_line and self.bus_active and not counted
        self.reset_at(clk)
        self.line_silent = True
        self.line_interrupt = interrupt
        self._reschedule()

    def _line_heard(self) -> None:
        """A cycle ended at the chip, or the master's reset pattern arrived: the line is not silent (DG-3, DG-4)."""
        if self.line_silent:
            self.line_silent = self.line_interrupt = False
            self.revision += 1
            self._reschedule()

    # --------------------------------------------------------------------------------------------------------
    # What the master sees
    # --------------------------------------------------------------------------------------------------------

    def _id_and_length(self) -> int:
        if self.registers is not None:
            word = self.registers.bus_id_register()
            if self._send_alarm:  # the master asked for the processor alarm (3.4.9, docs/interbus.md A18)
                word = (word & ~0xFF) | self.registers.processor_alarm
            return word
        return (self.config.length_code << 8) | self._bus_terminal_id_code()

    def management(self) -> int:
        """Management bits 15..13 of the ID register: PF, WD, TE (docs/interbus.md, assumption A8)."""
        return (self.pf << wire.MGMT_PF_BIT) | (self.wd << wire.MGMT_WD_BIT) | (self.te << wire.MGMT_TE_BIT)

    def id_register(self) -> int:
        """The 16-bit ID register shifted out in an ID cycle."""
        return self._optical_id(self.management() | self._id_and_length())  # optical status when asked (OPT-50)

    def data_bytes(self) -> int:
        """Bytes the chip occupies on the line in a data cycle (Table 3-11, assumption A15)."""
        if self._fixed_bytes is not None:
            return self._fixed_bytes
        return self._data_path()[2]

    def _data_path(self) -> tuple[int, bool, int]:
        """µP modes: (the register file's :attr:`~supi3.model.registers.RegisterFile.configurations`, whether data
        cycles go through the expansion, :meth:`data_bytes`), worked out again only when a configuration was taken
        since (SET applied or dropped): both follow SET alone (the length code of the ID register; a processor
        alarm replaces only its ID code), and every master cycle asks for them."""
        registers = self.registers
        assert registers is not None  # the µP modes only (their _fixed_bytes is None)
        path = self._path
        if path[0] != registers.configurations:
            path = self._path = (registers.configurations, not registers.internal_data_path,
                                 wire.data_bytes((self._id_and_length() >> 8) & 0x1F))  # fmt: skip
        return path

    def _sample_inputs(self) -> int:
        if self._in_map:
            return sum(((self.mfp_in >> pin) & 1) << bit for bit, pin in self._in_map)
        return self.in_word

    def set_inputs(self, word: int) -> None:
        """IN data for the bus terminal modes, whose data path is not modelled at pin level yet, and for the SPI
        master modes without a serial device (:meth:`attach_serial`): at transaction level the word is what the
        next data cycles load; at pin level the next sequence's read frame replaces it with what SerIn gave.

        Raises
        ------
        SerialModeError
            A serial device is attached: it provides the IN data (3.3).
        ChipArgumentError
            ``word`` is not an integer of the chip's data length.
        """
        if self.serial_device is not None:
            raise SerialModeError(f"set_inputs is refused while a serial device is attached ({self.serial_device!r}):"
                                  " the device provides the IN data through the read frame (manual 3.3)")
        self.in_word = _checked(check_bits, "word", word, 8 * self.data_bytes(),
                                f"the IN data of {self.data_bytes()} bytes, Table 3-11")

    # --------------------------------------------------------------------------------------------------------
    # Serial I/O (SPI master mode, 3.3; docs/assumptions/serial-io.md)
    # --------------------------------------------------------------------------------------------------------

    def _init_serial(self) -> None:
        mode = self.config.mfp_mode
        self.spi_sequences: tuple[SerialSequence, SerialSequence | None] | None = None
        """The SPI master modes' sequence after a valid data cycle and clear sequence after a reset (SM-6, SM-9,
        :mod:`supi3.serial_io`); None in the other modes."""
        if mode.kind is MfpKind.SPI_MASTER:
            rate = self.config.bit_rate
            self.spi_sequences = (sequence(mode.direction, mode.width, rate),
                                  clear_sequence(mode.direction, mode.width, rate))  # fmt: skip
        self.serial_device: SerialDevice | None = None
        """The device on the serial I/O bus (:meth:`attach_serial`), or None."""
        self._serial_pins: _SerialPins | None = None

    def attach_serial(self, device: SerialDevice | None) -> None:
        """Attach ``device`` to the serial I/O pins (SPI master modes, 3.3), or detach with None.

        At transaction level each valid data cycle's latch runs the whole sequence on the device at once (read
        frame, write frame, /Conv, in that order) and the word read is the IN data of the next data cycles; an
        INTERBUS reset or a watchdog reset writes zeros in the modes with OUT data (SM-9, SM-11). At pin level
        (:class:`supi3.model.pins.Supi3Pins`) the device is clocked with the pins and answers on SerIn instead of
        the MFP6 input (SM-5). Attach between sequences; :meth:`set_inputs` is refused while a device is attached.

        Raises
        ------
        SerialModeError
            The chip is not in an SPI master mode (Tables 2-4 to 2-6).
        ChipArgumentError
            ``device`` is neither a :class:`~supi3.serial_io.SerialDevice` nor None.
        """
        if self.spi_sequences is None:
            raise SerialModeError(f"attach_serial needs an SPI master mode (Tables 2-4 to 2-6, manual 3.3), not "
                                  f"{self.config.function!r}")
        # A class has the protocol's methods too: an instance is wanted.
        if device is not None and (isinstance(device, type) or not isinstance(device, SerialDevice)):
            error = fail("device", "a SerialDevice (supi3.serial_io) or None", device)
            raise ChipArgumentError(error.name, device, str(error))
        self.serial_device = device
        self._reschedule()

    def _serial_latched(self, clk: int) -> None:
        """A valid data cycle latched at ``clk``: its sequence runs (SM-2, SM-11)."""
        if self._serial_pins is not None:
            self._serial_pins.start(clk, self.out_word)
        elif self.serial_device is not None:
            assert self.spi_sequences is not None
            read = _transact(self.spi_sequences[0], self.serial_device, self.out_word)
            if read is not None:
                self.in_word = read

    def _serial_cleared(self, clk: int) -> None:
        """Process data cleared at ``clk`` (INTERBUS reset, watchdog): the clear sequence (SM-9)."""
        if self._serial_pins is not None:
            self._serial_pins.clear(clk)
        elif self.serial_device is not None:
            assert self.spi_sequences is not None
            clear = self.spi_sequences[1]
            if clear is not None:
                _transact(clear, self.serial_device, 0)
    # Serial register expansion (3.5, docs/assumptions/expansion.md)
    # --------------------------------------------------------------------------------------------------------

    @property
    def expansion(self) -> bool:
        """SET selects the external data registers (ExtReg = 1, 3.4.11): data cycles go through the expansion."""
        return self.registers is not None and not self.registers.internal_data_path

    @property
    def expansion_chain(self) -> ExternalRegisters | None:
        """The external registers on the expansion interface (:meth:`attach_expansion`), ``None`` if none."""
        return self._chain

    def attach_expansion(self, chain: ExternalRegisters | None) -> None:
        """Wire external data registers (the IBS SRE 1's role) to the expansion interface, ``None`` to remove them.

        They are used while SET has ExtReg = 1 (RX-2): at transaction level a data cycle sends
        ``chain.chain()`` and its latch calls ``shift_cycle``, ``take_outputs`` and ``load_inputs``; at pin level
        (:class:`supi3.model.pins.Supi3Pins`) the chain is clocked at every change of the expansion pins. Without
        a chain a data cycle with ExtReg = 1 sends 0 bits (FromExR grounded): for the whole frame, not only the
        chip's own bytes (:attr:`constant_output`, RX-13).

        Raises
        ------
        ChipArgumentError
            ``chain`` is not an :class:`~supi3.expansion.ExternalRegisters` or ``None``, or the chip has no
            expansion interface: the SUPI 3 LS (3.5) or a mode other than Init-µP (ExtReg is a SET bit, 3.4.11).
        """
        if chain is not None and not isinstance(chain, ExternalRegisters):
            raise ChipArgumentError("chain", chain, "chain must be an ExternalRegisters (supi3.expansion) or None, "
                                    f"not {chain!r}")
        if self.config.variant is Variant.LS:
            raise ChipArgumentError("chain", chain, "the chip must be a SUPI 3 OPC for the register expansion "
                                    "(3.5: not possible with the SUPI 3 LS), not a SUPI 3 LS")
        if self.registers is None:
            raise ChipArgumentError("chain", chain, "the chip must be in an Init-µP mode for the register expansion "
                                    f"(ExtReg in SET, 3.4.11), not {self.config.mfp_mode.kind}")
        self._chain = chain

    def _count(self, event: str) -> None:
        """Count an event that is no interrupt source (``"EXPANSION_OVERRUN"``)."""
        self._events[event] += 1

    def _expansion_load(self, clk: int) -> bytes:
        """A data cycle with ExtReg = 1 begins at ``clk``: what it sends (transaction level: the chain's contents,
        RX-2), after the overrun check of RX-4, or zeros without a chain (and :attr:`constant_output` 0, RX-13);
        zeros at pin level, where FromExR is shifted bit by bit."""
        length = self.data_bytes()
        if self._exr_driver is not None:
            return bytes(length)
        if clk < self._exr_free:
            self._count("EXPANSION_OVERRUN")
        chain = self._chain
        if chain is None:
            # RX-13: FromExR grounded, nothing between ToExR and FromExR: every data bit the chip sends is 0, the
            # bits of the devices before it and the loopback word too (the ring sends the constant line)
            self.constant_output = 0
            return bytes(length)
        if chain.length != length:
            raise ChipError(f"the external registers must be as long as SET's data length at transaction level "
                            f"({length} bytes, Table 3-11), not {chain.length} bytes")
        return chain.chain()

    def _expansion_end(self, clk: int, latched: bytes | None) -> None:
        """A cycle ended at ``clk`` with ExtReg = 1: the data cycle's ``latched`` bytes (``None``: ID cycle or
        discarded) go to the chain, then the end pulses (RX-4)."""
        if self._exr_driver is not None:
            self._exr_driver.end(clk, latched is not None)
            return
        pulses = end_pulses(latched is not None, self._cpb)
        self._exr_free = clk + pulses.length - round(EXPANSION_LEAD_BITS * self._cpb)
        chain = self._chain
        if chain is not None:
            if latched is not None:
                chain.shift_cycle(latched)
                chain.take_outputs()
            chain.load_inputs()

    def _expansion_reset(self, clk: int) -> None:
        """INTERBUS or watchdog reset at ``clk`` with ExtReg = 1: /ResReg low for 4 t0, the chain cleared (RX-5)."""
        self.resreg_until = clk + PULSE_T0 * self._cpb
        if self._exr_driver is not None:
            self._exr_driver.reset(clk)
        elif self._chain is not None:
            self._chain.clear()

    # --------------------------------------------------------------------------------------------------------
    # Bus terminal module (2.4, Tables 2-7..2-9; supi3.model.bus_terminal, docs/assumptions/bus-terminal.md)
    # --------------------------------------------------------------------------------------------------------
    # In the BK modes the chip owns a BusTerminal (self.bus_terminal, None in every other mode). The hooks in the
    # methods above are one line each: power_up -> _init_bus_terminal, set_mfp_inputs -> _bus_terminal_inputs,
    # _id_and_length -> _bus_terminal_id_code, latch_at (ID cycle) -> _bus_terminal_command, reset_at ->
    # _bus_terminal_reset. The ring (supi3.interbus.ring.Branch) asks terminal_interface, branch_enabled and
    # reports branch_returned.

    def _init_bus_terminal(self) -> None:
        """Power-up: a fresh BK state in the BK modes, taking the MFP input levels as they are (no CONF edge)."""
        interface = self.config.interface
        self.bus_terminal = BusTerminal(interface.value, self.config.rf_mode.rf if self.config.rf_mode else None,
                                        self._branch_silence) if interface.is_bus_terminal else None  # fmt: skip
        if self.bus_terminal is not None:
            self.bus_terminal.inputs(self.mfp_in)
            self.bus_terminal.conf_request = False

    def _bus_terminal_inputs(self) -> None:
        """MFP inputs changed: LBST and CONF; a CONF rising edge asks for the master's attention (BK-8)."""
        if self.bus_terminal is not None and self.bus_terminal.inputs(self.mfp_in):
            self.attention = True
            self.revision += 1

    def _bus_terminal_id_code(self) -> int:
        """Bits 7..0 of the ID register outside the µP modes: the ID code, or the branch status byte when the
        master asked for it in the last ID cycle (BK-5)."""
        if self._send_alarm and self.bus_terminal is not None:
            return self.bus_terminal.status()
        return self.config.id_code

    def _bus_terminal_command(self, command: wire.CommandWord) -> bool:
        """A latched ID cycle's command word: branch control, acknowledgement, status request (BK-4, BK-5, BK-8).
        ``True`` while a report (reconfiguration request, branch closed) waits for acknowledgement: the BK keeps
        ATTN up until then, so an ATTN lost in a failed cycle comes back (BK-5)."""
        terminal = self.bus_terminal
        if terminal is None:
            return False
        terminal.command(command.branch, command.quit_peripheral_error, command.alarm_output)
        if self.registers is None:
            self._send_alarm = command.alarm_request
        return terminal.conf_request or terminal.closed_report

    def _bus_terminal_reset(self) -> bool:
        """INTERBUS reset (BK-9); ``True`` while a reconfiguration request still waits (it keeps ATTN)."""
        if self.bus_terminal is None:
            return False
        self.bus_terminal.reset()
        return self.bus_terminal.conf_request

    @property
    def terminal_interface(self) -> str | None:
        """``"BK-RB"``, ``"BK-LB"`` or ``"BK-LBD"`` in the BK modes of Table 2-7, else ``None``."""
        return None if self.bus_terminal is None else self.bus_terminal.interface

    def branch_enabled(self, connected: bool) -> bool:
        """Whether the branch is in the data path (present by Table 2-9, switched on, not closed by the BK);
        ``connected``: a device answers on the branch.

        Raises
        ------
        ChipError
            The chip is not in a BK mode (Table 2-7).
        """
        return self._terminal().enabled(_checked(check_bool, "connected", connected))

    @property
    def branch_recognised(self) -> bool:
        """A device answered on the branch since the power-up (BK-37, BK-48); ``False`` in the modes that are no BK
        (Table 2-7)."""
        return self.bus_terminal is not None and self.bus_terminal.recognised

    def recognise_branch(self) -> None:
        """A device answered on the branch (BK-48): recognised until the power-up reset (an INTERBUS reset keeps it).

        Raises
        ------
        ChipError
            The chip is not in a BK mode (Table 2-7).
        """
        terminal = self._terminal()
        if not terminal.recognised:
            terminal.recognised = True
            self.revision += 1

    def branch_returned(self, traffic: bool, count: int | None, start: float, end: float,
                        frame_end: float | None = None) -> None:
        """The ring drove the branch from ``start`` to ``end`` (bus seconds): ``traffic`` says whether the master's
        telegrams came back on the return line, ``count`` is the counter telegram's count received there (``None``:
        none), ``frame_end`` when the stretch's frame ended at the BK (``None``: no frame). The extended function may
        close the branch at a frame's end; that asks for the master's attention (BK-3, BK-50)."""
        if count is not None:
            _checked(check_int, "count", count, 1, wire.COUNTER_MAX, "BK-6: a counter telegram counts 1..63")
        terminal = self._terminal()
        before = terminal.count
        if _checked(terminal.returned, traffic, count, start, end, frame_end):
            self.attention = True
            self.revision += 1
        elif terminal.count != before:  # the E LED follows the count (BK-11)
            self.revision += 1

    def _terminal(self) -> BusTerminal:
        if self.bus_terminal is None:
            raise ChipError(f"the chip must be in a bus terminal mode (Table 2-7) for a branch, not "
                            f"{self.config.function!r}")
        return self.bus_terminal

    # --------------------------------------------------------------------------------------------------------
    # Optical regulation block (manual 1.6, 3.4.12, 3.4.13; OPT-20 onward of docs/assumptions/optical.md)
    # --------------------------------------------------------------------------------------------------------
    # State: _optical, the block's OpticalStatus; _optical_until, the clock at which the budget of the interface
    # initializing now runs out (INIT_TIME_LIMIT_CLOCKS from optical_start for the first of INIT_ORDER, from the end of
    # the one before for the others: OPT-56) while a transmitter initializes, _NEVER otherwise. While it
    # is not _NEVER the core is held in reset (latch_at and discard_at do nothing) and the ring kernel takes the slow
    # path (_reschedule). Every change goes through a pure transition of supi3.optical.regulation and _optical_set.

    #
    # MAU warnings to the master (OPT-50..OPT-53): _mau_told are the warnings the master last read, _mau_events which
    # of them changed since (MAU_WARNING_EVENT, 1.6.3); the chip holds ATTN while an event waits. Asked in an ID
    # cycle's command word (_send_optical), it sends its optical status byte in the next one in place of the ID
    # code, each waiting event flipping the bit the master knows, and once that cycle is latched the master knows it.

    def _optical_power_up(self) -> None:
        """Power-up: every transmitter off, no length measured, no MAU report waiting."""
        self._optical_until: int = _NEVER
        self._optical_held = False
        self._optical: OpticalStatus = OpticalStatus()
        self._mau_told = self._mau_events = (False, False, False)
        self._send_optical = False
        self._optical_publish()

    def _mau_sent(self) -> tuple[bool, bool, bool]:
        """The MAU warnings the optical status byte shows: what the master knows, flipped where an event waits."""
        told, events = self._mau_told, self._mau_events
        return told[0] ^ events[0], told[1] ^ events[1], told[2] ^ events[2]

    def _optical_id(self, word: int) -> int:
        """The ID register ``word`` with the optical status byte in place of the ID code when asked (OPT-50)."""
        return (word & ~0xFF) | wire.optical_status(self._mau_sent()) if self._send_optical else word

    def _optical_command(self, command: wire.CommandWord) -> bool:
        """A latched ID cycle: the master has the status byte sent in it (if asked); take the next request (OPT-50).
        ``True`` while a MAU event waits (the chip holds ATTN, OPT-53)."""
        if self._send_optical:
            self._mau_told = self._mau_sent()
            mau = tuple(tx.mau for tx in self._optical.transmitters)
            self._mau_events = (mau[0] != self._mau_told[0], mau[1] != self._mau_told[1], mau[2] != self._mau_told[2])
        self._send_optical = command.optical_request and not command.alarm_request
        return any(self._mau_events)

    @property
    def optical(self) -> OpticalStatus:
        """The optical block's status now: three transmitters, the lengths of the outgoing interface and branch."""
        return self._optical

    @property
    def optical_mode(self) -> OpticalMode:
        """What RF[1..0] selects (Table 2-2, OPT-2): 00 regulation, 01 optical diagnostics, copper and the LS off."""
        rf = self.config.rf_mode
        if rf is None:
            return OpticalMode.OFF
        return _OPTICAL_MODES.get(rf.rf, OpticalMode.OFF)

    @property
    def optical_holding(self) -> bool:
        """The protocol core is held in reset (1.6): a transmitter still initializes (each interface in turn with its
        own 6 ms budget, OPT-56, the first counted from :meth:`optical_start` in the chip's time, the last bus call)."""
        return self._optical_held or (self._optical_until != _NEVER and self._now < self._optical_until)

    def optical_start(self, present: tuple[bool, bool, bool], now: float | None = None) -> None:
        """The end of the INTERBUS reset (1.6): every interface starts (:func:`~supi3.optical.regulation.start`)
        in the chip's optical mode; ``present`` says which of IN, OUT, BRANCH are in use (automatic interface
        recognition). The 6 ms budget counts from bus time ``now`` (seconds; ``None``: the chip's last bus call).

        Raises
        ------
        ChipArgumentError
            ``present`` is not a tuple of three bools, ``present[BRANCH]`` is set on a chip that is not a bus terminal
            module (OPT-55), or ``now`` is not a time.
        ChipError
            The chip's optical block runs at pin level (:class:`~supi3.model.pins.Supi3Pins`, OPT-26): so does every
            ``optical_*`` call.
        """
        self._transaction_level_optics()
        if not (type(present) is tuple and len(present) == len(Interface)
                and all(type(p) is bool for p in present)):  # fmt: skip
            raise ChipArgumentError("present", present, "present must be a tuple of 3 bools (IN, OUT, BRANCH in "
                                    f"use), not {present!r:.60}")
        if present[Interface.BRANCH] and self.bus_terminal is None:
            raise ChipArgumentError("present", present, "present[BRANCH] must be False outside the bus terminal "
                                    "modes of Table 2-7 (OPT-55: the branch interface DI3/DO3/FO3 is a BK's, "
                                    f"Table 2-8, 1.6.3), not True in {self.config.function!r}")
        if now is not None:
            self.poll(now)
        mode = self.optical_mode
        txs = tuple(regulation.start(mode, p) for p in present)
        status = OpticalStatus((txs[0], txs[1], txs[2]), self._optical.length, self._optical.medium)
        initializing = any(tx.phase is Phase.INIT for tx in txs)
        self._optical_until = self._now + regulation.INIT_TIME_LIMIT_CLOCKS if initializing else _NEVER
        self._optical_set(status)
        self._reschedule()  # a new budget even if the status is the same (a start while initializing)

    def optical_init_response(self, interface: Interface, response: Response) -> None:
        """One initialization step's response on ``interface`` (:func:`~supi3.optical.regulation.init_response`,
        1.6.1); a transmitter not initializing does not change. When it ends the initialization of the interface whose
        turn it is, the next one's 6 ms budget counts from the chip's clock (its last bus call: ``poll`` first, OPT-56).

        Raises
        ------
        ChipArgumentError
            ``interface`` is not an :class:`Interface` or ``response`` not a :class:`Response`.
        """
        self._transaction_level_optics()
        interface = _interface(interface)
        response = _checked(check_instance, "response", response, Response)
        self._optical_set(self._optical.with_transmitter(
            interface, regulation.init_response(self._optical[interface], response)))

    def optical_init_timeout(self) -> None:
        """The running 6 ms budget ran out (1.6.1, OPT-5, OPT-56): the interface initializing now
        (:func:`~supi3.optical.regulation.initializing`) falls back to maximum power and the next one's budget
        starts. The chip also does this by itself at the first bus call at or after a budget's end."""
        self._transaction_level_optics()
        self._optical_timeout(self._now)

    def _transaction_level_optics(self) -> None:
        """Refuse the transaction-level optical API on a chip whose optical block runs at pin level (OPT-26): the
        block makes every transition there, so a call here would leave the chip and the block apart."""
        if self._optical_driven:
            raise ChipError("the optical block of a pin-level chip (Supi3Pins, OPT-26) is driven by its line side "
                            "(Supi3Pins.step/run with pinout.OPTICAL_LINE_INPUTS), not by the Supi3.optical_* calls")

    def _optical_timeout(self, ends: int) -> None:
        """The budget that ran to clock ``ends`` is over: the interface initializing falls back; the next one's
        budget counts from ``ends`` (OPT-56)."""
        current = self._optical.initializing
        if current is None:
            self._optical_until = _NEVER
            return
        tx = regulation.init_timeout(self._optical[current])
        self._optical_set(self._optical.with_transmitter(current, tx), since=ends)

    def optical_length(self, interface: Interface, count: int, medium: Medium) -> None:
        """The length timer's result ``count`` for the outgoing interface or the branch, at the chip's bit rate
        (:func:`~supi3.optical.length.timer_code`, 1.6.1, OPT-1); ignored when the optical block is off.

        Raises
        ------
        ChipArgumentError
            ``interface`` is not OUT or BRANCH (the incoming path is not measured, 3.4.12), BRANCH on a chip that
            is not a bus terminal module (OPT-55), ``count`` not an int >= 0, or ``medium`` not a :class:`Medium`.
        """
        self._transaction_level_optics()
        if _interface(interface) is Interface.IN:
            raise ChipArgumentError("interface", interface, "interface must be Interface.OUT or Interface.BRANCH "
                                    "(the incoming path is not measured, 3.4.12), not Interface.IN")
        if interface is Interface.BRANCH and self.bus_terminal is None:
            raise ChipArgumentError("interface", interface, "interface must be Interface.OUT outside the bus terminal "
                                    "modes of Table 2-7 (OPT-55: only a BK has a branch path, read 9), not "
                                    f"Interface.BRANCH in {self.config.function!r}")
        count = _checked(check_int, "count", count, 0, limit="length timer counts")
        medium = _checked(check_instance, "medium", medium, Medium)
        if self.optical_mode is not OpticalMode.OFF:
            code = timer_code(count, self.config.bit_rate, medium)
            self._optical_set(self._optical.with_length(interface, code, medium))

    def optical_test(self, interface: Interface, ack1: bool, ack2: bool) -> None:
        """One online test on ``interface`` (1.6.2): ``ack1`` at the reserve, ``ack2`` one level further. Online
        regulation (:func:`~supi3.optical.regulation.online_test`) in regulation mode; in optical diagnostics mode
        the interface's MAU warning (:func:`~supi3.optical.regulation.diagnostic_mau`, OPT-22).

        Raises
        ------
        ChipArgumentError
            ``interface`` is not an :class:`Interface`, ``ack1`` or ``ack2`` not a bool.
        """
        self._transaction_level_optics()
        interface = _interface(interface)
        ack1 = _checked(check_bool, "ack1", ack1)
        ack2 = _checked(check_bool, "ack2", ack2)
        self._optical_set(self._optical.with_transmitter(
            interface, regulation.apply_test(self._optical[interface], ack1, ack2)))

    def _optical_apply(self, transition: Callable[[regulation.Transmitter], regulation.Transmitter]) -> None:
        """``transition`` applied to every transmitter."""
        txs = tuple(transition(tx) for tx in self._optical.transmitters)
        self._optical_set(OpticalStatus((txs[0], txs[1], txs[2]), self._optical.length, self._optical.medium))

    def _optical_reset(self) -> None:
        """INTERBUS reset: every transmitter off for the reset period (1.6); the lengths stay (OPT-21); the master
        forgets the MAU warnings with its configuration, so does the chip (OPT-53). At pin level the block turns its
        transmitters off itself (OPT-26)."""
        if not self._optical_driven:
            self._optical_apply(lambda _tx: regulation.Transmitter())
        self._mau_told = self._mau_events = (False, False, False)
        self._send_optical = False

    def _optical_set(self, status: OpticalStatus, report: bool = True, since: int | None = None) -> None:
        """Take ``status``; the hold ends once no transmitter initializes; reads 8..11 follow (3.4.12). A MAU
        change is an event for the master when ``report`` (not in the reset period: OPT-26, OPT-53). When another
        interface's initialization begins, its 6 ms budget counts from clock ``since`` (``None``: now; OPT-56)."""
        if status == self._optical:
            return
        old, was_initializing = self._optical.transmitters, self._optical.initializing
        self._optical = status
        self.revision += 1
        events = tuple(e or new.mau != was.mau for e, new, was in zip(self._mau_events, status.transmitters, old,
                                                                       strict=True))  # fmt: skip
        if report and events != self._mau_events:  # a MAU warning came on or went off: an event for the master (OPT-53)
            self._mau_events = (events[0], events[1], events[2])
            self.attention = True
        if not self._optical_driven:  # the budgets (OPT-56); at pin level the block counts them
            current = status.initializing
            if current is None:
                self._optical_until = _NEVER
            elif current is not was_initializing:
                self._optical_until = (self._now if since is None else since) + regulation.INIT_TIME_LIMIT_CLOCKS
        self._optical_publish()
        self._reschedule()

    def _optical_drive(self, status: OpticalStatus, hold: bool, report: bool) -> None:
        """Pin level (:class:`supi3.model.pins.Supi3Pins`, OPT-26): the optical block's ``status`` and ``hold`` after
        a clock edge. The block makes every transition; the chip takes its status for the ID path (OPT-50..OPT-53),
        the FO LEDs and the hold (OPT-20); a MAU change is an event when ``report`` (the block was not in reset).
        Reads 8..11 reach the register file through the block's ``optical_we`` port, a clock later."""
        self._optical_held = hold
        if status is not self._optical:
            self._optical_set(status, report)

    def _optical_publish(self) -> None:
        """Reads 8..11 into the register file (µP modes; the other modes have none, 3.4.12, 3.4.13); at pin level
        the block writes them (``optical_we``, OPT-26)."""
        if self.registers is not None and not self._optical_driven:
            for name, value in zip(OPTICAL_REGISTERS, regulation.registers(self._optical), strict=True):
                self.registers.set_optical(name, value)

    # --------------------------------------------------------------------------------------------------------
    # Time
    # --------------------------------------------------------------------------------------------------------

    def _stat_end(self, since: int) -> int:
        """The clock from which /StatErr, low since clock ``since``, has passed the filter: the edge of the time base's
        tick that ends the filter time (M24), seen on the next clock; a shorter filter (a test's, MCU-24) counts
        clocks."""
        filter_clocks = self._stat_filter
        bits = TIME_BASE_BITS if filter_clocks == STATERR_FILTER_CLOCKS else 0
        return time_base_end(since, filter_clocks, bits) + 1

    @property
    def _filtered(self) -> bool:
        return self._stat_due is not None and self._now >= self._stat_due

    def _reschedule(self) -> None:
        # due (public, read-only): the next clock at which time alone changes the chip (filter expiry, watchdog),
        # _NEVER if none; the pin level (supi3.model.pins and its receiver) reads it on every cycle it visits.
        due = _NEVER if self._deadline is None else self._deadline
        if self._stat_due is not None and not self.pf:
            due = min(due, self._stat_due)
        due = min(due, self._optical_until)  # optical block: the 6 ms initialization budget (OPT-20)
        self.due = due
        # See "The ring kernel"; a serial device takes the latch's slow path (the sequence runs there).
        # A silent line takes the slow path too: the next cycle's end is heard there (_line_heard); and so does a chip
        # held by the optical initialization (OPT-20).
        kernel = (self.registers is None and self.serial_device is None and not self.line_silent
                  and self._optical_until == _NEVER)  # fmt: skip
        self._due_s = due / CLOCK_HZ if kernel else -1.0

    def _advance(self, clk: int) -> None:
        """Bring time-driven state up to clock ``clk``: the /StatErr filter and the layer-2 watchdog. The chip's clock
        never goes back: a call stamped before the chip's last one (the bench and the ring stamp a cycle's calls by
        their place in it, a few clocks apart) leaves it where it is, so the budgets and the filter do not run again
        from a time that has passed."""
        if clk > self._now:
            self._now = clk
        if clk >= self.due:
            self._expire(clk)

    def _expire(self, clk: int) -> None:
        self.revision += 1
        while clk >= self._optical_until:  # optical block: an interface's budget ran out (OPT-5, OPT-20, OPT-56)
            self._optical_timeout(self._optical_until)
        if self._filtered and not self.pf:
            self.pf = True
            self.attention = True
        if self._deadline is not None and clk >= self._deadline:
            self._deadline = None
            self._clear_process_data()
            self.wd = True
            self.attention = True
            self.resreg_until = clk + RESREG_PULSE_CLOCKS
            if self.expansion:
                self._expansion_reset(clk)
            self._events["WATCHDOG"] += 1
            self._event("IB_RESET")
        self._reschedule()

    def _clear_process_data(self) -> None:
        self.in_word = 0
        self._out = b""
        if self.spi_sequences is not None:
            self._serial_cleared(self._now)
        if self.registers is not None:
            self.registers.interbus_reset()

    def _event(self, *sources: str) -> None:
        """Interrupt events of ``sources`` (Table 3-13), counted and told to the register file at once."""
        events = self._events
        for source in sources:
            events[source] += 1
        if self.registers is not None:
            self.registers.event(*sources)

    # --------------------------------------------------------------------------------------------------------
    # The ring's Device protocol (supi3.interbus.link.Device), in clocks
    # --------------------------------------------------------------------------------------------------------

    def load_at(self, cycle: Cycle, clk: int) -> bytes:
        """A frame begins: the register's parallel load, in line order."""
        if type(cycle) is not Cycle:
            cycle = _cycle(cycle)
        if type(clk) is not int or clk < 0:
            clk = _clock(clk)
        self._now = clk
        if clk >= self.due:
            self._expire(clk)
        if cycle is Cycle.ID:
            return wire.word_bytes(self.id_register())
        registers = self.registers
        if registers is not None:
            path = self._path  # _data_path's cache, read without the call while it is current (M34)
            _, expansion, size = path if path[0] == registers.configurations else self._data_path()
            self.constant_output = None  # RX-13: the frame shifts through, unless the open expansion says otherwise
            if expansion:
                data = self._expansion_load(clk)
            elif size:
                data = registers.in_bytes()
            else:
                data = b""
            self._frame_bytes = len(data)
            return data
        if not self._in_map:
            return self.in_word.to_bytes(self.data_bytes(), "big")
        levels, loaded = self._loaded
        if levels != self.mfp_in:
            loaded = self._sample_inputs().to_bytes(self.data_bytes(), "big")
            self._loaded = (self.mfp_in, loaded)
        return loaded

    def latch_at(self, cycle: Cycle, received: bytes, clk: int) -> None:
        """The master latched the cycle: take over ``received`` (OUT data or the command word).

        Raises
        ------
        ChipArgumentError
            If ``received`` is not bytes of this cycle's length: :meth:`data_bytes` in a data cycle, the two bytes
            of the command word in an ID cycle.
        """
        if type(cycle) is not Cycle:
            cycle = _cycle(cycle)
        if type(clk) is not int or clk < 0:
            clk = _clock(clk)
        # µP modes: the data path and length once (SET does not change within a latch)
        registers = self.registers
        path = None
        if cycle is _DATA and registers is not None:  # µP modes (the only ones whose _fixed_bytes is None)
            path = self._path  # _data_path's cache, read without the call while it is current (M34)
            if path[0] != registers.configurations:
                path = self._data_path()
        length = _WORD_BYTES if cycle is not _DATA else self._fixed_bytes if path is None else path[2]
        if type(received) is not bytes or len(received) != length:
            if cycle is _DATA and type(received) is bytes and len(received) == self._frame_bytes:
                # SET was rewritten while this frame ran (ReconfigurationError, 3.4.11): the frame's length is
                # not the chip's any more, so nothing is latched (M15).
                self.discard_at(cycle, True, clk)
                return
            what = "the OUT data" if cycle is _DATA else "the command word"
            received = _checked(check_bytes, "received", received, length, f"{what} of the {cycle.value} cycle")
        self.revision += 1
        self._now = clk
        if self.line_silent:  # only then does the line's hearing change anything (M33: no call a cycle)
            self._line_heard()
        if clk >= self.due:
            self._expire(clk)
        if self._optical_until != _NEVER or self._optical_held:  # optical block: held in reset, no latch (OPT-20)
            return
        if cycle is _DATA:
            self.bus_active = True
            if self.watchdog_code is not None:
                timeout = WATCHDOG_CLOCKS[self.watchdog_code]
                self._deadline = None if timeout is None else time_base_end(clk + 1, timeout)
                self._reschedule()
            if registers is None:
                self._out = received
                self._fast_valid += 1
                if self.spi_sequences is not None:
                    self._serial_latched(clk)
                return
            assert path is not None  # the µP modes (registers), whose _fixed_bytes is None
            if path[1]:  # the expansion
                self._expansion_end(clk, received)
            elif received:
                registers.latch(received)
            registers.set_bus_running(True)
            self._fast_valid += 1  # M33: VALID, PCP_RX and PCP_TX counted at once (Supi3.events merges them)
            registers.raise_events(_VALID_EVENTS)
            return
        events = self._events
        command = wire.decode_command_word(wire.word_from_bytes(received))
        if command.watchdog_code is not None:
            self.watchdog_code = command.watchdog_code
            timeout = WATCHDOG_CLOCKS[command.watchdog_code]
            self._deadline = None if timeout is None else time_base_end(clk + 1, timeout)
            self._reschedule()
        if command.quit_peripheral_error:
            self.pf = self.module_error
            self.mod_ack_until = clk + MODACK_PULSE_CLOCKS
            events["MODACK"] += 1
            self._reschedule()
        if self.registers is not None:
            if command.processor_command is not None:
                self.registers.processor_command(command.processor_command)
            self._send_alarm = command.alarm_request
        self.wd = self.te = False
        self.attention = self._bus_terminal_command(command) | self._optical_command(command)  # BK-5, OPT-53
        if self.expansion:
            self._expansion_end(clk, None)
        self._event("ID_CYCLE", "PCP_TX")

    def discard_at(self, cycle: Cycle, local_error: bool, clk: int) -> None:
        """The cycle ended without a latch: nothing latched changes (Table 3-13, invalid data cycle)."""
        if type(cycle) is not Cycle:
            cycle = _cycle(cycle)
        if type(local_error) is not bool:
            local_error = _checked(check_bool, "local_error", local_error)
        if type(clk) is not int or clk < 0:
            clk = _clock(clk)
        self._advance(clk)
        self._line_heard()
        if self._optical_until != _NEVER or self._optical_held:  # optical block: the core is held in reset (OPT-20)
            return
        self.te = self.te or local_error
        if self.expansion:
            self._expansion_end(clk, None)
        if cycle is Cycle.DATA:
            self._event("INVALID")

    def reset_at(self, clk: int) -> None:
        """INTERBUS reset (3.4.7, Table 3-13)."""
        if type(clk) is not int or clk < 0:
            clk = _clock(clk)
        self.revision += 1
        self._advance(clk)
        self._line_heard()
        self._clear_process_data()
        if self.expansion:
            self._expansion_reset(clk)
        self.watchdog_code = None
        self._deadline = None
        self._reschedule()
        self._send_alarm = False
        self.wd = self.te = False
        self._optical_reset()  # optical block: regulation reset for the reset period (1.6), MAU reports (OPT-53)
        self.attention = self.pf or self._bus_terminal_reset()
        self.bus_active = False
        self._events["IB_RESET"] += 1
        if self.registers is not None:
            self.registers.set_bus_running(False)

    # Device protocol in bus seconds -------------------------------------------------------------------------

    def load(self, cycle: Cycle, now: float) -> bytes:
        """See :meth:`supi3.interbus.link.Device.load`."""
        if cycle is _DATA and type(now) is float and 0.0 <= now < _INF:
            return _load_data_run((self,), now)[0][0]  # the ring kernel's shortcut, for one chip
        return self.load_at(cycle, clocks(now))

    def latch(self, cycle: Cycle, received: bytes, now: float) -> None:
        """See :meth:`supi3.interbus.link.Device.latch`."""
        # len(received) == _fixed_bytes: the kernel's width (and never in the µP modes, where _fixed_bytes is None)
        if (cycle is _DATA and type(now) is float and 0.0 <= now < _INF
                and type(received) is bytes and len(received) == self._fixed_bytes):  # fmt: skip
            _latch_data_run((self,), (received,), now)  # the ring kernel's shortcut, for one chip
            return
        self.latch_at(cycle, received, clocks(now))

    def discard(self, cycle: Cycle, local_error: bool, now: float) -> None:
        """See :meth:`supi3.interbus.link.Device.discard`."""
        self.discard_at(cycle, local_error, clocks(now))

    def reset(self, now: float) -> None:
        """See :meth:`supi3.interbus.link.Device.reset`."""
        self.reset_at(clocks(now))

    def poll(self, now: float) -> None:
        """See :meth:`supi3.interbus.link.Device.poll`."""
        self._advance(clocks(now))


class VoltageMonitor:
    """The reset unit's voltage monitor (1.7.2): its output goes high above 4.5 V and low below 3.9 V, and keeps
    its level in between (hysteresis). Its output is the pin-level model's ``vmon_ok`` input.

    Attributes
    ----------
    ok:
        The output level; low at power-up.
    """

    def __init__(self) -> None:
        self.ok = False

    def sense(self, vcc: float) -> bool:
        """Apply the supply voltage ``vcc`` (volts) and return the output."""
        vcc = _checked(check_real, "vcc", vcc, limit="the supply voltage in volts")
        if vcc > tables.VOLTAGE_MONITOR_HIGH_V:
            self.ok = True
        elif vcc < tables.VOLTAGE_MONITOR_LOW_V:
            self.ok = False
        return self.ok

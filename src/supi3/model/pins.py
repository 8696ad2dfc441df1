"""The cycle-accurate pin-level model of the SUPI 3 chip core: the reference the Amaranth RTL matches pin for pin.

A synchronous machine clocked at 32 MHz (1.7.1), following the convention of :mod:`supi3.pinlevel`: each
call of :meth:`Supi3Pins.step` takes the input pins of one clock cycle, returns the output pins seen during that
cycle, and moves the state across the rising edge at the end of it. The bus behaviour (what is loaded, latched,
discarded, reset) is :class:`supi3.model.chip.Supi3`, the same object the transaction-level ring uses; this module
adds the line receiver, the repeater, the frame engine and the timing of every output pin. Every cycle-level
decision is listed in ``docs/model.md``; the wire format is ``docs/interbus.md``.

The core is made of the blocks of :mod:`supi3.model.blocks`, named as the blocks of the RTL core
(:mod:`supi3.rtl.core`): ``receiver`` (synchroniser and line receiver), ``frame`` (frame engine: telegram framing,
CRC and check sequence), ``datapath`` (shift register, load and latch), ``transmitter`` (transmitter and repeater)
and ``outputs`` (outputs and diagnostics). :class:`Supi3Pins` composes them and owns what is common to them all: the
power-up reset (1.7.2, M2), the clock, and the event-driven scheduler of :meth:`Supi3Pins.run`.

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
``from_exr``          in   FromExR, the register expansion's serial input (3.5, Table 3-14; 0 = nothing attached)
``present`` ...       in   the optical block's line side, :data:`~supi3.pinout.OPTICAL_LINE_INPUTS` (optional, below)
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
``clk_exr``           out  ClkExR, the register expansion's shift clock (3.5, Table 3-15)
``to_exr``            out  ToExR, the data bit shifted into the external registers
``la_ou_d``           out  LaOuD, the external output registers take the chain (high pulse)
``la_in_d_n``         out  /LaInD, the chain takes the external input registers (low pulse)
====================  ===  =============================================================================

The optical regulation block (1.6, 3.4.12, 3.4.13; OPT-26 of ``docs/assumptions/optical.md``): with RF = 00 or 01
(:attr:`Supi3.optical_mode <supi3.model.chip.Supi3.optical_mode>`) the core owns an
:class:`~supi3.model.blocks.optical.OpticalBlock` clocked with it. Its line side (:data:`~supi3.pinout.
OPTICAL_LINE_INPUTS`) may be given with the pins above, to :meth:`Supi3Pins.step` and :meth:`Supi3Pins.run`, all or
none (none: 0, quiet); its ``ib_reset`` is the core's INTERBUS reset period (the reset on the line, or the idle
time-out until the line is heard), ``mode`` and ``fast`` come from the straps, ``run`` is the bus active. At each edge
the block's status goes to the chip (``Supi3._optical_drive``): its ``hold`` holds the protocol core (OPT-20), its FO
LEDs are the outputs block's, its MAU warnings the optical status byte of the ID path (OPT-50..OPT-53); its
``optical_we`` writes reads 8..11 into the register file.
"""

from __future__ import annotations

from bisect import bisect_right
from collections.abc import Callable, Mapping, Sequence
from typing import Final

import numpy as np
import numpy.typing as npt

from supi3.checks import check_bits, check_instance, check_int, check_trace, fail
from supi3.config import DeviceConfig, Interface
from supi3.diagnostics import is_complete
from supi3.interbus import wire
from supi3.model.blocks.counter import LineCounters
from supi3.model.blocks.forward import forward_path
from supi3.model.blocks.optical import OpticalBlock
from supi3.model.blocks.outputs import Outputs, Snapshot
from supi3.model.blocks.receiver import (
    IDLE_INPUTS,
    IDLE_TIMEOUT_CLOCKS,
    INPUT_NAMES,
    INPUT_PINS,
    Synced,
    check_names,
    input_row,
    input_traces,
)
from supi3.model.blocks.serial_io import SerialIo
from supi3.model.blocks.terminal import BranchLines
from supi3.model.blocks.transmitter import NEVER, PinTrace
from supi3.model.chip import Supi3
from supi3.optical.regulation import OpticalMode
from supi3.pinlevel import EventLog, Pin
from supi3.pinout import (
    CORE_OUTPUTS,
    IB_DIAG_DIVIDER_BITS,
    OPTICAL_BRANCH_BIT,
    OPTICAL_BRANCH_INPUTS,
    OPTICAL_LINE_INPUTS,
    OPTICAL_REGISTERS,
    SYNC_STAGES,
)
from supi3.tables import BIT_RATES, CLOCK_HZ, RESET_MIN_S
from supi3.terminal import BRANCH_SILENCE_CLOCKS, CONF_PIN, LBST_PIN, silence_limit

__all__ = [
    "IB_DIAG_DIVIDER_BITS",
    "IDLE_INPUTS",
    "IDLE_TIMEOUT_CLOCKS",
    "RESET_STRETCH_CLOCKS",
    "SYNC_STAGES",
    "PinTrace",
    "Supi3Pins",
    "Synced",
    "check_names",
    "input_row",
    "input_traces",
    "split_optical",
    "split_optical_traces",
]

RESET_STRETCH_CLOCKS: Final = round(RESET_MIN_S * CLOCK_HZ)
"""The internal reset lasts 128 clocks (4 µs, 1.7.2) after its last source went away (M2)."""

_OPTICAL_WIDTHS: Final[dict[str, int]] = {pin.name: pin.width for pin in OPTICAL_LINE_INPUTS}
_OPTICAL_QUIET: Final[dict[str, int]] = dict.fromkeys(_OPTICAL_WIDTHS, 0)
_OPTICAL_STROBES: Final = ("resp_valid", "test_valid", "len_start", "len_stop")


def split_optical(inputs: object) -> tuple[object, dict[str, int] | None]:
    """The core's pins of one cycle and, if ``inputs`` names the optical line side too, its levels (checked: each an
    integer within its pin's width); otherwise ``inputs`` unchanged and ``None``."""
    if not isinstance(inputs, Mapping) or len(inputs) != len(INPUT_PINS) + len(_OPTICAL_WIDTHS) or any(
            name not in inputs for name in _OPTICAL_WIDTHS):  # fmt: skip
        return inputs, None
    optical = {name: check_bits(f"pin {name!r}", inputs[name], width) for name, width in _OPTICAL_WIDTHS.items()}
    return {name: value for name, value in inputs.items() if name not in _OPTICAL_WIDTHS}, optical


def split_optical_traces(inputs: object) -> tuple[dict[str, npt.NDArray[np.integer]], dict[str, npt.NDArray[np.int64]]]:
    """:func:`input_traces` of the core's pins, and the optical line side's traces (checked, as long as the others;
    zeros when ``inputs`` does not name them)."""
    if isinstance(inputs, Mapping) and any(name in inputs for name in _OPTICAL_WIDTHS):
        core = input_traces({name: value for name, value in inputs.items() if name not in _OPTICAL_WIDTHS})
        n = len(core["do1"])
        optical = {}
        for name, width in _OPTICAL_WIDTHS.items():
            if name not in inputs:
                raise fail("inputs", f"a mapping with every optical line pin ({', '.join(_OPTICAL_WIDTHS)}) or none",
                           inputs, f"without {name!r}")
            trace = check_trace(f"pin {name!r} trace", inputs[name], width)
            if len(trace) != n:
                raise fail(f"len(pin {name!r} trace)", f"{n}, the length of pin 'do1' trace", len(trace))
            optical[name] = trace.astype(np.int64, copy=False)
        return core, optical
    core = input_traces(inputs)
    n = len(core["do1"])
    return core, {name: np.zeros(n, dtype=np.int64) for name in _OPTICAL_WIDTHS}


class Supi3Pins:
    """The SUPI 3 chip core at pin level, one 32 MHz clock per :meth:`step`, or many per :meth:`run`.

    Parameters
    ----------
    config:
        The pin-strap configuration (the RTL reads the same straps from its strap ports).
    chip:
        The bus behaviour to drive; a new :class:`~supi3.model.chip.Supi3` for ``config`` by default.
    branch_silence:
        In the BK modes, the silence of the branch return line after which the extended function closes the
        branch, in clocks: 1 up to :data:`~supi3.terminal.BRANCH_SILENCE_CLOCKS` (the default, BK-3, as the RTL
        core's); shorter only to reach it quickly in tests.

    Attributes
    ----------
    chip:
        The transaction-level chip this pin model drives; inspect its registers and events in tests.
    cycle:
        Clock cycles since reset.

    Notes
    -----
    The blocks (:mod:`supi3.model.blocks`) hold absolute cycle numbers (when the current telegram began, when the
    line went low, ...) and the core holds when the reset stretch ends, instead of counters, so that cycles in
    which nothing happens can be skipped: :meth:`run` visits only the cycles where an input changes or an internal
    event is due, and renders the output traces between them. :meth:`step` and :meth:`run` share every line of the
    per-cycle logic (:meth:`_tick` and the blocks) and agree cycle for cycle (tested).
    """

    __slots__ = (
        "_branch", "_counters", "_datapath", "_diag2", "_expansion", "_frame", "_holding", "_optical", "_optical_at",
        "_optical_fixed", "_optical_gated", "_outputs", "_power_ups", "_receiver", "_recording",
        "_return_start", "_run_from", "_serial", "_stat_active", "_synced_run", "_transmitter", "chip",
        "complete_diagnostics",
        "config", "cpb", "cycle", "forward_delay", "log", "mfp_oe", "rbst_by_pin", "reset_run",
    )  # fmt: skip

    inputs: Sequence[Pin] = INPUT_PINS
    outputs: Sequence[Pin] = CORE_OUTPUTS
    optical_inputs: Sequence[Pin] = OPTICAL_LINE_INPUTS
    """The optical block's line side, inputs that may be given with :attr:`inputs` (see the module docstring)."""

    def __init__(self, config: DeviceConfig, chip: Supi3 | None = None, *,
                 branch_silence: int = BRANCH_SILENCE_CLOCKS) -> None:
        check_instance("config", config, DeviceConfig)
        if chip is not None and (not isinstance(chip, Supi3) or chip.config != config):
            raise fail("chip", "None or a Supi3 of the same configuration", chip)
        silence_limit(branch_silence, "branch_silence")
        self.config = config
        self.chip = chip if chip is not None else Supi3(config, branch_silence=branch_silence)
        self.cpb = wire.clocks_per_bit(config.bit_rate)
        self.mfp_oe = config.mfp_output_mask
        self.log = EventLog()
        self.complete_diagnostics = is_complete(config)
        """DIAG1 shows BA (DIAG_CONF = 0, Table 3-16)."""
        # The blocks, wired to each other (supi3.model.blocks; the RTL core's blocks of the same names).
        (self._transmitter, self._expansion, self._datapath, self._frame,
         self._receiver) = forward_path(self.chip, self.log)
        self.rbst_by_pin = self._transmitter.rbst_by_pin
        """A following device is told by RBST_EXT (RF = 10, Table 2-2), not recognised on DI2 (M5)."""
        self.forward_delay = self._transmitter.delay + self.cpb // 2
        """Clocks from a bit's mid-bit sample to its first clock on DO2, plus cpb/2 (M8)."""
        self.reset_run = self._receiver.reset_run
        """Clocks of start level that make an INTERBUS reset (M11)."""
        self.chip._exr_driver = self._expansion  # cycle ends and resets move the expansion pins (RX-3 to RX-5)
        # Serial I/O in the SPI master modes (3.3): the chip starts its sequences at each latch (Supi3.attach_serial).
        self._serial = SerialIo(self.chip) if self.chip.spi_sequences is not None else None
        self.chip._serial_pins = self._serial
        self._outputs = Outputs(self.chip, self._transmitter, self.cpb, self.mfp_oe, self._serial)
        # LBD modes (Table 2-5): the counter telegram blocks on DO2 and, in LBD-MR, DI1 (M17).
        self._counters = LineCounters.of(config)
        self._frame.counter_telegrams = self._counters is not None  # BK-36: the frame engine takes them as such
        # BK modes (Table 2-7): the branch's data lines DO3 and DI3 and the switch of DO2 (BK-1, BK-37).
        rf = config.rf_mode.rf if config.rf_mode is not None else None
        self._branch = BranchLines(rf, self.cpb, config.interface is Interface.BK_LBD, branch_silence) \
            if config.interface.is_bus_terminal else None  # fmt: skip
        # The optical block (1.6) with RF = 00 or 01; it makes every optical transition, the chip takes its status.
        mode = self.chip.optical_mode
        self._optical = OpticalBlock() if mode is not OpticalMode.OFF else None
        self.chip._optical_driven = self._optical is not None
        self._optical_fixed = {"mode": int(mode), "fast": BIT_RATES.index(config.bit_rate)}
        """The block's inputs from the straps."""
        self._optical_gated = () if config.interface.is_bus_terminal else OPTICAL_BRANCH_INPUTS
        """The line-side inputs whose branch bit the core holds at 0: a chip without the branch interface (OPT-55)."""
        self.reset()

    # ------------------------------------------------------------------------------------------------------------
    # Reset
    # ------------------------------------------------------------------------------------------------------------

    def reset(self) -> None:
        """The state right after the ``sync`` reset, which is the RTL's initial state (M23): power-up reset in progress
        (it lasts the reset stretch), the synchronisers at the idle levels, the clock count at 0."""
        self.cycle = 0
        self.log.clear()
        self._receiver.reset()
        self._transmitter.reset()
        if self._serial is not None:
            self._serial.reset()
        self._expansion.sync_reset()
        if self._counters is not None:
            self._counters.reset()
        self._holding = False
        self._recording = False
        self._power_ups: list[tuple[int, int]] = []
        self._return_start: tuple[int, bool, int, list[int]] | None = None
        self._power_up(RESET_STRETCH_CLOCKS)

    def _power_up(self, run_from: int) -> None:
        """Power-up reset of every block; the logic runs again from cycle ``run_from`` (after the reset stretch,
        M2)."""
        if self._recording:
            self._power_ups.append((self.cycle, run_from))
        # /StatErr is sampled afresh after a power-up (_stat_active below): the chip forgets the level it had, so
        # its filter restarts at the first running clock instead of counting from clock 0.
        self.chip._stat_err = False
        self.chip.power_up()
        self.chip.mfp_in = 0
        self._run_from = run_from
        self._stat_active = False
        self._receiver.power_up(run_from)
        # The transmitter drops the bits not yet begun and idles the line from the next cycle.
        self._transmitter.power_up(self.cycle)
        self._frame.power_up()
        self._datapath.power_up()
        if self._serial is not None:
            self._serial.power_up(self.cycle)
        self._expansion.power_up(self.cycle)
        if self._counters is not None and not self._recording:  # a run replays its power-ups (_run_forward)
            self._counters.power_up(self.cycle, run_from)
        if self._branch is not None:  # a run renders its lines afterwards (BranchLines.render) and plans anew
            self._branch.power_up()
            if self._recording:
                self._branch.plan(self.cycle + 1, run_from)
        if self._optical is not None:
            self._optical.reset()
        self._optical_at = run_from
        """The cycle whose edge the optical block takes next (it catches up in one go, OpticalBlock.quiet)."""

    # ------------------------------------------------------------------------------------------------------------
    # One clock: step()
    # ------------------------------------------------------------------------------------------------------------

    def step(self, inputs: Mapping[str, int]) -> dict[str, int]:
        """Run one clock cycle (see :mod:`supi3.pinlevel`).

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
        optical = None
        if type(inputs) is not dict or len(inputs) != len(INPUT_PINS):
            inputs, optical = split_optical(inputs)  # type: ignore[assignment]
        try:
            do1, di2, rbst = inputs["do1"], inputs["di2"], inputs["rbst_ext"]
            mfp, stat, resu, vmon = inputs["mfp_in"], inputs["stat_err_n"], inputs["resu_n"], inputs["vmon_ok"]
            exr = inputs["from_exr"]
            # The fast path: plain ints within range (one type chain and two shifts), the eight names exactly.
            fast = (int is type(do1) is type(di2) is type(rbst) is type(mfp) is type(stat) is type(resu) is type(vmon)
                    is type(exr) and not (do1 | di2 | rbst | stat | resu | vmon | exr) >> 1 and not mfp >> 16
                    and len(inputs) == 8)  # fmt: skip
        except Exception:  # anything a broken mapping raises: input_row() names the problem
            fast = False
        row = Synced(do1, di2, rbst, mfp, stat, resu, vmon, exr) if fast else input_row(inputs)
        c = self.cycle
        receiver = self._receiver
        pipe = receiver.pipe
        synced = pipe[-1]
        outputs = self._outputs.values(c, row.di2, self._run_from)
        if self._serial is not None:
            self._serial.feed(c)
        outputs.update(self._expansion.values(c))
        receiver.pipe = [row, *pipe[:-1]]
        tx = self._transmitter
        if self._counters is not None:
            running = c >= self._run_from and synced.resu_n and synced.vmon_ok
            source = self._counters.show(c, outputs, row.di2, tx.next_present)
            self._counters.clock(source, synced.do1 if running else None)
        branch = self._branch
        if branch is not None:
            assert self.chip.bus_terminal is not None
            sent, state = outputs["do2"], self.chip.bus_terminal.state
            branch.route(outputs, synced.mfp_in, tx.next_present)
        if c >= self._run_from or self._holding or not (synced.resu_n and synced.vmon_ok):
            self._tick(c, synced, synced.do1, optical or _OPTICAL_QUIET)
            if c >= self._run_from:
                tx.next_present = bool(synced.rbst_ext) if tx.rbst_by_pin else tx.next_present or bool(synced.di2)
                if branch is not None:
                    branch.clock(synced.mfp_in, sent, state)
            if tx.next_present != self.chip.following:  # RD (DG-5): the outputs of the next cycle show it
                self.chip.set_following(tx.next_present)
        if len(tx.bits) > 8:  # tested here, not in trim(): one call less per step()
            tx.trim()
        self.cycle = c + 1
        return outputs

    @property
    def run_from(self) -> int:
        """The first cycle the logic runs after the power-up reset's stretch (M2); ``resu_drive`` is 1 before it."""
        return self._run_from

    @property
    def holding(self) -> bool:
        """A source of the power-up reset (``vmon_ok`` low, /ResU pulled low) was seen at the last clock edge (M2)."""
        return self._holding

    @property
    def branch_connected(self) -> bool:
        """A BK's ``connected``: DI3 has shown a start level since the power-up reset (BK-37), the pin-level twin of
        the transaction level's ``Supi3.branch_recognised`` (BK-48); ``False`` in the other modes."""
        return self._branch is not None and self._branch.connected

    @property
    def branch_in_path(self) -> bool:
        """A BK's branch is in the data path in the current cycle (BK-37: present by Table 2-9 with the synchronised
        LBST and ``connected``, switched on, not closed; :meth:`BranchLines.on`); ``False`` in the other modes."""
        branch = self._branch
        if branch is None:
            return False
        assert self.chip.bus_terminal is not None
        return branch.on(self.chip.bus_terminal.state, self._receiver.pipe[-1].mfp_in >> LBST_PIN & 1,
                         branch.connected)  # fmt: skip

    def forward_level(self) -> int:
        """The forward line output (``do2``) of the current cycle; it depends on state only."""
        sent = self._transmitter.level(self.cycle)
        if self._branch is not None:
            return self._route(self.cycle, {"do2": sent, "di1": 0, "mfp_out": 0})["do2"]
        return sent if self._counters is None else self._counters.do2(self.cycle, sent)

    def _route(self, c: int, values: dict[str, int]) -> dict[str, int]:
        """``values`` of cycle ``c`` through a BK's branch lines (:class:`BranchLines`): the synchronised inputs of
        cycle ``c`` are in the synchroniser (the latest one held for the cycles beyond it)."""
        assert self._branch is not None and self.chip.bus_terminal is not None
        pipe = self._receiver.pipe
        synced = pipe[max(len(pipe) - 1 - (c - self.cycle), 0)]
        self._branch.route(values, synced.mfp_in, self._transmitter.next_present)
        return values

    def output_values(self, c: int, di2: int) -> dict[str, int]:
        """Every output pin during cycle ``c`` (``c`` >= the current cycle; ``di2`` is that cycle's input)."""
        check_int("c", c, self.cycle)
        values = {**self._outputs.values(c, check_bits("pin 'di2'", di2, 1), self._run_from),
                  **self._expansion.peek(c)}
        if self._counters is not None:
            self._counters.show(c, values, di2, self._transmitter.next_present)
        return values if self._branch is None else self._route(c, values)

    # ------------------------------------------------------------------------------------------------------------
    # The per-cycle logic, shared by step() and run()
    # ------------------------------------------------------------------------------------------------------------

    def _tick(self, c: int, s: Synced, line: int, optical: Mapping[str, int]) -> None:
        """The rising edge at the end of cycle ``c``, with the synchronised inputs ``s`` of that cycle; ``line`` is
        their ``do1`` (given apart, since :meth:`run` keeps the line as a trace of its own); ``optical``: the
        optical block's line side in that cycle."""
        if not (s.resu_n and s.vmon_ok):
            if not self._holding:
                self.log.add(c, "power-up reset")
            self._holding = True
            self._power_up(NEVER)
            return
        if self._holding:
            self._holding = False
            self._power_up(c + RESET_STRETCH_CLOCKS)
            return
        if c < self._run_from:
            return
        chip = self.chip
        resets = chip._events["IB_RESET"]
        terminal = chip.bus_terminal
        if terminal is not None:
            before, switched_on = terminal.state, terminal.switched_on_commands
            checks = self._frame.checks  # BK-50: the silence closes the branch only where a frame's check ends
        if chip.bus_terminal is None:
            chip.mfp_in = s.mfp_in
        elif c == self._run_from:  # a BK takes CONF as it is at the first running clock: no edge (BK-20)
            chip.mfp_in = s.mfp_in
            chip._init_bus_terminal()
        elif s.mfp_in != chip.mfp_in:  # a BK's CONF edge (reconfiguration request, ATTN; BK-8) and LBST
            chip.set_mfp_inputs(s.mfp_in)
        stat = not s.stat_err_n
        if stat != self._stat_active:
            self._stat_active = stat
            chip._set_stat_err(stat, c)
        if c >= chip.due:
            chip._advance(c)
        serial = self._serial
        if serial is not None and c >= serial.due:
            serial.clock(c, s.mfp_in)
        self._expansion.from_exr = s.from_exr
        if self._optical is None:
            self._receiver.clock(line, c)
        else:
            resetting = self._frame.in_reset or chip.line_silent
            self._receiver.clock(line, c)
            self._optical_edge(c, resetting, optical)
        branch = self._branch
        if branch is None:
            return
        # The BK's edge after the core's (BK-20's order): a fresh BK (its first running clock) and an INTERBUS reset
        # take no strobe; else the master's telegram back, the counter telegram, the silence (BK-3, BK-38, BK-39).
        terminal = chip.bus_terminal
        assert terminal is not None
        if c == self._run_from or chip._events["IB_RESET"] != resets:
            branch.quiet(c, terminal.state, self._recording)
            return
        state, closes = branch.edge(c, before, terminal.state, terminal.switched_on_commands != switched_on,
                                    s.mfp_in, self._frame.checks != checks, self._recording)  # fmt: skip
        if state is not terminal.state:
            terminal.state = state
            chip.revision += 1  # the E LED, LD and the status byte (BK-5, BK-11)
        if closes:
            terminal.closures += 1
            chip.attention = True
            self.log.add(c, "the BK closed its silent branch (BK-3)")
    def _optical_edge(self, c: int, resetting: bool, line: Mapping[str, int]) -> None:
        """The optical block's edge ending cycle ``c`` (after the core's: the core saw the hold of the cycle), with
        the line side ``line``; ``resetting``: the core's INTERBUS reset period before the core's edge (OPT-26)."""
        block = self._optical
        assert block is not None
        chip = self.chip
        # ib_reset: the INTERBUS reset period, this cycle included: the reset on the line (from the edge detecting it
        # to the one ending it) or the idle time-out until the line is heard (the RTL's in_reset | idle_timeout |
        # line_silent).
        ib = int(resetting or self._frame.in_reset or chip.line_silent)
        values = {**line, **self._optical_fixed, "ib_reset": ib, "run": int(chip.bus_active),
                  **{name: line[name] & ~OPTICAL_BRANCH_BIT for name in self._optical_gated}}  # fmt: skip
        if c > self._optical_at:
            block.quiet(c - self._optical_at, {**values, **_OPTICAL_QUIET, "ib_reset": int(resetting)})
        shown = block.outputs_now(values["run"])
        written = shown["optical_we"]
        if written and chip.registers is not None:  # the register file takes reads 8..11 (TO_REGISTER_FILE ports)
            for k, name in enumerate(OPTICAL_REGISTERS):
                if written >> k & 1:
                    chip.registers.set_optical(name, shown["optical"] >> (8 * k) & 0xFF)
        block.edge(values)
        self._optical_at = c + 1
        chip._optical_drive(block.status, block.hold, not ib)

    def _optical_due(self, c: int) -> int:
        """The next cycle the optical block needs a visit after the edge ending cycle ``c`` (:meth:`run`)."""
        assert self._optical is not None
        due = self._optical.next_change(int(self._frame.in_reset or self.chip.line_silent))
        return NEVER if due is None else c + 1 + due

    # ------------------------------------------------------------------------------------------------------------
    # Many clocks: run()
    # ------------------------------------------------------------------------------------------------------------

    def run(self, inputs: Mapping[str, Sequence[int] | npt.NDArray[np.generic]], *,
            before: Callable[[int], object] | None = None) -> dict[str, PinTrace]:
        """Run as many clock cycles as the input traces are long; return every output pin's trace.

        The same cycles as calling :meth:`step` once per cycle, with the same results, but only the cycles in
        which something happens are visited (see the class notes).

        Parameters
        ----------
        inputs:
            One equally long trace per input pin (exactly the names of :attr:`inputs`): 1-D integer sequences or
            arrays within the pin's width.
        before:
            Called with the index of each cycle whose clock edge may change the chip, before that edge: between
            two calls nothing in the chip changes (its register file included), so a model that shares it, the µP
            interface of :class:`supi3.top.Supi3Chip`, catches up to the index in the call.

        Raises
        ------
        ArgumentError
            A pin missing or unknown, a trace not such a sequence, a value out of range (with its index), or traces
            of different lengths (:func:`input_traces`); nothing changes.
        """
        raw, optical = split_optical_traces(inputs)
        traces = self._run_forward(raw, optical, before)
        traces["di1"] = self._return_line(raw["di2"].astype(np.int64, copy=False), traces["do2"])
        return traces

    def _synced_traces(self, raw: Mapping[str, npt.NDArray[np.integer]]) -> dict[str, npt.NDArray[np.int64]]:
        """What the synchroniser delivers in each cycle of ``raw``, followed by the pipeline left after them, as
        contiguous ``int64`` traces (the one copy of the inputs a run makes)."""
        synced = {}
        for name in INPUT_NAMES:
            held = np.asarray([getattr(stage, name) for stage in reversed(self._receiver.pipe)], dtype=np.int64)
            synced[name] = np.concatenate([held, raw[name]], dtype=np.int64, casting="unsafe")
        return synced

    def run_forward(self, inputs: Mapping[str, Sequence[int] | npt.NDArray[np.generic]], *,
                    before: Callable[[int], object] | None = None) -> dict[str, PinTrace]:
        """:meth:`run` without ``di1``: the chip's logic does not depend on DI2 beyond the return line's
        pass-through, so a ring runs every chip forward first and then the return line backwards
        (:meth:`return_line`). The ``di2`` trace given here is checked but not used."""
        return self._run_forward(*split_optical_traces(inputs), before)

    def _run_forward(self, raw: Mapping[str, npt.NDArray[np.integer]], optical: Mapping[str, npt.NDArray[np.int64]],
                     before: Callable[[int], object] | None) -> dict[str, PinTrace]:
        # The run kernel: the event scheduler over the blocks' per-cycle logic. It stays flat on purpose (one loop,
        # locals for what it reads every visit): its cost per visited cycle is the run() rate (bench/bench_model.py).
        n = len(raw["do1"])
        c0 = self.cycle
        receiver = self._receiver
        self._return_start = (c0, self._transmitter.next_present, self._run_from,
                              [stage.di2 for stage in reversed(receiver.pipe)])
        self._power_ups = []
        self._recording = True
        branch = self._branch
        full = self._synced_traces(raw)
        if branch is not None:
            assert self.chip.bus_terminal is not None
            branch.begin(c0, self._run_from, self.chip.bus_terminal.state, full["mfp_in"][:n])
        synced = {name: trace[:n] for name, trace in full.items()}
        line = synced["do1"]
        line_change = np.ones(n, dtype=bool)
        line_change[1:] = line[1:] != line[:-1]
        change = np.zeros(n, dtype=bool)
        change[:1] = True
        for name in ("stat_err_n", "resu_n", "vmon_ok"):
            trace = synced[name]
            change[1:] |= trace[1:] != trace[:-1]
        if self.chip.bus_terminal is not None:  # a BK's CONF edges (BK-8)
            conf = synced["mfp_in"] >> CONF_PIN & 1
            change[1:] |= conf[1:] != conf[:-1]
        block = self._optical
        if block is not None:  # the optical block's line side: every strobe and every change of a level
            for name, trace in optical.items():
                change[1:] |= trace[1:] != trace[:-1]
                if name in _OPTICAL_STROBES:
                    change |= trace != 0
        # Input events: cycles where a synchronised input the logic reads changes. A change of the line (do1) only
        # matters while the receiver waits for a start bit: in a telegram the receiver acts at its due cycles
        # (mid-bit samples), and the one thing a line change does there, marking where a run of start level began
        # for the INTERBUS-reset detector, is restored from the trace at each visited cycle (restore_low_run).
        line_events = np.flatnonzero(line_change).tolist()
        other_events = [*np.flatnonzero(change).tolist(), n]
        receiver.run_low = (c0, receiver.low_since, np.maximum.accumulate(np.where(line_change, np.arange(n), 0)))
        # The other synchronised inputs are piecewise constant: keep their values once per piece, found by
        # bisection (a piece's do1 is its first cycle's: the line is read from its own trace).
        pieces = change.copy()
        for name in ("mfp_in", "di2", "rbst_ext", "from_exr"):
            trace = synced[name]
            pieces[1:] |= trace[1:] != trace[:-1]
        starts = np.flatnonzero(pieces)
        values = list(map(Synced._make, zip(*(synced[name][starts].tolist() for name in INPUT_NAMES), strict=True)))
        starts_list = starts.tolist()
        # Outputs are recorded after a visited cycle only when they may have changed (Supi3.revision).
        chip = self.chip
        outputs = self._outputs
        shown, run_from = chip.revision, self._run_from
        snaps: list[tuple[int, Snapshot]] = [(0, outputs.snapshot(run_from))]
        next_due, restore_low_run = receiver.next_due, receiver.restore_low_run
        serial = self._serial
        if serial is not None:
            serial.keep_from = c0
        k = kl = 0
        due = next_due(c0 - 1, int(line[0]), self._run_from) if n else NEVER
        if serial is not None and serial.due < due:
            due = max(serial.due, c0)
        if block is not None and self._optical_at != NEVER:  # a change the block showed before this run
            due = min(due, max(self._optical_due(self._optical_at - 1), c0))
        if branch is not None:
            due = min(due, c0 + branch.next_event(-1))
        t = -1
        while True:
            while other_events[k] <= t:
                k += 1
            after = min(other_events[k], due - c0)
            if not receiver.busy:
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
                restore_low_run(t, level, self._run_from)
            if c >= self._run_from or self._holding or not (s.resu_n and s.vmon_ok):
                if before is not None:
                    before(t)
                self._tick(c, s, level, {name: trace.item(t) for name, trace in optical.items()}
                           if block is not None else _OPTICAL_QUIET)  # fmt: skip
            if chip.revision != shown or self._run_from != run_from:
                shown, run_from = chip.revision, self._run_from
                snaps.append((t + 1, outputs.snapshot(run_from)))
            if branch is not None:
                branch.record(t + 1, chip.bus_terminal.state)  # type: ignore[union-attr]  # a BK has one
            due = next_due(c, level, self._run_from)
            if serial is not None and serial.due < due:
                due = serial.due if serial.due > c else c + 1
            if block is not None and c >= self._run_from:
                due = min(due, self._optical_due(c))
            if branch is not None:
                due = min(due, c0 + branch.next_event(t))
        if n and c0 + n - 1 >= self._run_from:
            restore_low_run(n - 1, int(line[n - 1]), self._run_from)
        self._recording = False
        self.cycle = c0 + n
        receiver.pipe = [Synced(*(int(full[name][n + SYNC_STAGES - 1 - i]) for name in INPUT_NAMES))
                         for i in range(SYNC_STAGES)] if n >= SYNC_STAGES else self._shifted_pipe(raw, n)
        self._synced_run = synced
        if serial is not None:
            serial.feed(c0 + n - 1)
        traces = outputs.render(c0, n, snaps, self._transmitter.render(c0, n))
        self._diag2 = traces["diag2"]  # RD in it waits for the return line (_return_line, DG-5)
        if self._counters is not None:
            traces["do2"] = self._counters.forward_run(line, c0, self._power_ups, traces["do2"])
        if branch is not None:
            branch.render(traces, synced["mfp_in"])
        traces.update(self._expansion.render(c0, n))
        self._transmitter.trim()
        if serial is not None:
            serial.keep_from = NEVER
        return traces

    def _shifted_pipe(self, raw: Mapping[str, npt.NDArray[np.integer]], n: int) -> list[Synced]:
        pipe = list(self._receiver.pipe)
        for t in range(n):
            pipe = [Synced(*(int(raw[name][t]) for name in INPUT_NAMES)), *pipe[:-1]]
        return pipe

    def return_line(self, di2: PinTrace, do2: PinTrace) -> PinTrace:
        """``di1`` over the last :meth:`run_forward`, given that run's DI2 trace: the return line passes DI2
        through once a following device is recognised, else loops ``do2`` back (M5). With complete diagnostics it
        also completes, in place, the ``diag2`` trace that run returned: RD, lit while no following device is
        recognised (DG-5).

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

    def _return_line(self, di2: npt.NDArray[np.int64], do2: npt.NDArray[np.int64]) -> PinTrace:
        assert self._return_start is not None
        c0, value, run_from, held_di2 = self._return_start
        n = len(do2)
        transmitter = self._transmitter
        if transmitter.rbst_by_pin:
            seen = self._synced_run["rbst_ext"]
        else:
            seen = np.concatenate([np.asarray(held_di2, dtype=np.int64), di2])[:n]
            # The synchroniser now holds the real DI2, not the placeholder the forward run saw.
            tail = np.concatenate([np.asarray(held_di2, dtype=np.int64), di2])[-SYNC_STAGES:][::-1]
            receiver = self._receiver
            receiver.pipe = [stage._replace(di2=int(v)) for stage, v in zip(receiver.pipe, tail, strict=True)]
        source, present = transmitter.return_line((c0, value, run_from), self._power_ups, seen, di2, do2)
        self._outputs.show_following(self._diag2, present)
        self.chip.set_following(transmitter.next_present)
        return source if self._counters is None else self._counters.return_run(source, c0, self._power_ups)

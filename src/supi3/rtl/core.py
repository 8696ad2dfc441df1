"""The SUPI 3 chip core in Amaranth: the INTERBUS slave of the model ``model.pins.Supi3Pins``, pin for pin.

The model is the specification; this RTL matches it on every output pin on every 32 MHz clock (``docs/rtl.md``).
Its ports are the model's pins plus the pin straps C[4..0], RF[1..0], CLK_CONF[1..0] and DIAG_CONF (and MFP[15..12]
in the configuration-expansion modes), so one netlist covers every operating mode of Tables 2-4 to 2-7. The straps
are decoded combinationally from tables generated at elaboration (:mod:`supi3.rtl.tables`); they must be static,
as on the board. Strap values the manual's tables reserve decode to "no mode" (ID and length 0, no MFP outputs,
the first bit rate of Table 1-7).

Blocks, in the order the model's ``_tick`` runs them within one clock:

* synchronisers (model M1) and the power-up reset with its stretch (1.7.2, M2);
* time: the /StatErr filter (3.6.2), the layer-2 watchdog (Table 3-13), the /ModAck and /ResReg pulses;
* receiver: INTERBUS reset detection, idle time-out, telegram framing and mid-bit sampling (docs/interbus.md);
* frame engine: the register's parallel load, shifting, CRC, check sequence and CNTR, latch and discard;
* transmitter: a short queue of (countdown, level) entries that repeats each bit ``REPEATER_DELAY_BITS`` after it
  began on DO1, with the ERR pair of the CNTR word settled at the last stop bit (docs/interbus.md, A7, A10);
* serial I/O (SPI master modes, 3.3, :class:`supi3.rtl.serial_io.SerialIoRtl`): the sequence on MFP3, 4, 5, 7 after
  each valid data cycle's latch, the clear sequence after a reset, and the IN word read from SerIn (MFP6), which
  the next data cycle loads;
* register expansion (OPC, SET with ExtReg = 1 from the register file, 3.5, :class:`supi3.rtl.expansion.ExpansionRtl`):
  a data frame's bits through ToExR/ClkExR and back from FromExR, the end pulses on LaOuD and /LaInD, and /ResReg
  4 t0 on both resets (the outputs block's counter).

µP modes: built with ``register_file=True`` (:class:`supi3.rtl.chip.Supi3ChipRtl`), the core has the ports of the
register file's core side (:class:`supi3.rtl.upif.UpifBlock`): in Init-µP modes it takes the IN bytes, the ID
register and the processor alarm from it and strobes the latch, events, processor command, I/O access bit and
resets at the clocks the model calls its register file (``model.registers.RegisterFile``). Without it, and in bus
terminal modes, the core sends IN data 0 and the straps' ID code, which is what the model does before software acts.
"""

from __future__ import annotations

from collections.abc import Callable
from itertools import pairwise
from typing import Final

from amaranth.back import verilog as amaranth_verilog
from amaranth.hdl import Array, Cat, Const, Elaboratable, Module, Mux, ResetInserter, Signal, Value
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from supi3.checks import check_bool
from supi3.config import Variant
from supi3.diagnostics import BUS_TERMINAL_PINS
from supi3.errors import ArgumentError
from supi3.expansion import PULSE_T0
from supi3.interbus import wire
from supi3.interbus.errors import InterbusError
from supi3.lbd import clocks_per_bit
from supi3.optical.regulation import OpticalMode
from supi3.pinlevel import Pin
from supi3.pinout import (
    BLOCK_STRAPS,
    CORE_IDLE,
    CORE_INPUTS,
    CORE_OUTPUTS,
    EVENT_BITS,
    EXPANSION_BITS,
    FROM_REGISTER_FILE,
    IB_DIAG_DIVIDER_BITS,
    MFP_PINS,
    OPTICAL_BRANCH_BIT,
    OPTICAL_BRANCH_INPUTS,
    OPTICAL_LINE_INPUTS,
    STRAP_PINS,
    SYNC_STAGES,
    TIME_BASE_BITS,
    TO_REGISTER_FILE,
    time_base_ticks,
)
from supi3.regmap import INTERRUPT_SOURCES
from supi3.regmap.core import BYTE_BITS
from supi3.regmap.registers import IN_BYTES
from supi3.rtl.counter import CounterLinesRtl, LineQueue, check_watched_modes, stamp_bits
from supi3.rtl.expansion import PIN_NAMES as EXPANSION_PINS
from supi3.rtl.expansion import ExpansionRtl
from supi3.rtl.lfsr import TAPS, before, count_state, count_width, down_state, down_step, next_state
from supi3.rtl.optical import OpticalRtl
from supi3.rtl.serial_io import DIRECTIONS, SER_IN_PIN, WIDTHS, SerialIoRtl
from supi3.rtl.tables import (
    IDLE_TIMEOUT_CLOCKS,
    MODACK_PULSE_CLOCKS,
    RESET_STRETCH_CLOCKS,
    RESREG_PULSE_CLOCKS,
    STATERR_FILTER_CLOCKS,
    WATCHDOG_CLOCKS,
    ClockEntry,
    CoreTables,
    check_variant,
    core_tables,
    line_position,
)
from supi3.rtl.terminal import ReturnWatchRtl, TerminalRtl
from supi3.rtl.upif import upif_tables
from supi3.tables import BIT_RATES, RF_MODES, RfMode
from supi3.terminal import BRANCH_DRAIN_BITS, CONF_PIN, DI3_PIN, DO3_PIN, LBST_PIN, LineSource, TerminalMode

__all__ = [
    "LINE",
    "MANAGEMENT",
    "REGISTER",
    "REGISTER_FILE_INPUTS",
    "REGISTER_FILE_OUTPUTS",
    "STRAP_PINS",
    "TRANSMIT",
    "WORDS",
    "DataPathRtl",
    "FrameEngineRtl",
    "OutputsRtl",
    "ReceiverRtl",
    "Supi3Core",
    "TransmitterRtl",
    "verilog",
]

REGISTER_FILE_INPUTS: Final = tuple(
    pin for pin in FROM_REGISTER_FILE if pin.name in ("in_data", "bus_id", "ext_reg", "alarm")
)
"""What the core takes from the register file (:class:`supi3.rtl.upif.UpifBlock`'s outputs of the same names)."""
REGISTER_FILE_OUTPUTS: Final = (
    *BLOCK_STRAPS,
    *(pin for pin in TO_REGISTER_FILE
      if pin.name in ("power_up", "ib_reset", "events", "io_access", "latch", "latch_out", "pcmd_we", "pcmd",
                      "optical")),
)  # fmt: skip
"""What the core gives the register file (the block's inputs of the same names; reads 8..11 from the optical
block)."""

WORD_BITS: Final = 8 * len(wire.word_bytes(0))
"""16-bit words: ID register, command word, CRC, CNTR (docs/interbus.md A4)."""

_DATA_TELEGRAM_END: Final = wire.DATA_TELEGRAM_BITS - 1
_STATUS_TELEGRAM_END: Final = wire.STATUS_TELEGRAM_BITS - 1
_WD_OFF: Final = WATCHDOG_CLOCKS.index(None)
"""The watchdog code that stands for "off"; also the state after an INTERBUS reset (no code set)."""
_WD_CODE_BITS: Final = (len(WATCHDOG_CLOCKS) - 1).bit_length()
_SOURCE_BIT: Final = {source.name: source.bit for source in INTERRUPT_SOURCES}
"""The ``events`` bit of each interrupt source (Table 3-13)."""


_EXPANSION_PULSE_MAX: Final = PULSE_T0 * max(wire.clocks_per_bit(rate) for rate in BIT_RATES)
"""The longest /ResReg pulse with the register expansion: 4 t0 at the slowest bit rate (RX-5)."""


def _code_bytes(code: int) -> int:
    """The data bytes of a complete length code (Table 3-11), 0 for reserved codes."""
    try:
        return wire.data_bytes(code)
    except InterbusError:
        return 0


def _width(value: int) -> int:
    return max(1, value.bit_length())


def _branch_gated(line: Signal, bus_terminal: Signal) -> Value:
    """A per-interface line-side input with its branch bit held at 0 outside the bus terminal modes (OPT-55:
    :data:`~supi3.pinout.OPTICAL_BRANCH_INPUTS`)."""
    return Mux(bus_terminal, line, line & ((1 << len(line)) - 1 - OPTICAL_BRANCH_BIT))


def _optical_mode(row: RfMode) -> OpticalMode:
    """The optical block's mode for a row of Table 2-2 (OPT-2): regulation, diagnostics on fibre without it, else
    off (copper)."""
    if row.optical_regulation:
        return OpticalMode.REGULATION
    return OpticalMode.DIAGNOSTIC if row.medium == _FIBRE else OpticalMode.OFF


_FIBRE: Final = next(row.medium for row in RF_MODES if row.optical_regulation)
"""Table 2-2's medium of the fibre optic rows."""


_SENT, _DI3, _IDLE = (int(source) for source in LineSource)
_POSITION: Final = range(wire.DATA_TELEGRAM_BITS + 1)
"""The bit counter of a telegram: the position of the next bit (docs/interbus.md, "Telegrams")."""

LINE: Final = wiring.Signature({
    "level": Out(1), "sample": Out(1), "frame_bit": Out(1), "telegram_end": Out(1), "position": Out(_POSITION),
    "data_now": Out(1), "in_reset": Out(1), "select": Out(1), "control": Out(1), "bus_reset": Out(1),
    "idle_timeout": Out(1), "counted": Out(1), "counter": In(1),
})  # fmt: skip
"""Receiver -> frame engine, as the receiver sees it: the synchronised line ``level``; ``sample``, the mid-bit
sample of a telegram bit; ``frame_bit``, a sample in a data telegram outside an INTERBUS reset; ``telegram_end``, the
stop bit's sample; ``position``, the sampled bit's place in the telegram; ``data_now``, the telegram is a data
telegram; ``in_reset``, an INTERBUS reset runs (this clock included); ``select`` and ``control``, the bits received;
``bus_reset``, an INTERBUS reset begins (A12); ``idle_timeout``, 20 ms without a telegram (A13); ``counted``, a
counter telegram came since the last other telegram (DG-9); back comes ``counter``, the control bit sampled now is a
counter telegram's (BK-36): the idle time-out runs on through it."""

REGISTER: Final = wiring.Signature({
    "load": Out(1), "load_id": Out(1), "shift": Out(1), "level": Out(1), "latch": Out(1), "clear": Out(1),
    "shift_out": In(1),
})  # fmt: skip
"""Frame engine -> data path, as the frame engine sees it: ``load`` the register (the ID register if ``load_id``,
else the IN data) as a frame begins; ``shift`` in ``level`` (a data bit); ``latch`` OUT data to the MFPs; ``clear``
the MFP outputs (INTERBUS reset); back comes ``shift_out``, the bit the register sends."""

MANAGEMENT: Final = wiring.Signature({
    "clear": Out(1), "abandon": Out(1), "frame_error": Out(1), "latch_id": Out(1), "latch_data": Out(1),
    "attention": In(1),
})  # fmt: skip
"""Frame engine -> outputs and diagnostics, as the frame engine sees it: ``clear`` (INTERBUS reset or idle
time-out: chip.reset_at), ``abandon`` (a frame ends unlatched), ``frame_error`` (a frame runs with a local error:
TE, Table 3-13), ``latch_id`` (an ID cycle's command word is taken), ``latch_data`` (a data cycle's OUT data are
taken); back comes ``attention``, the ATTN bit the chip adds to the CNTR word."""

TRANSMIT: Final = wiring.Signature({"push": Out(1), "level": Out(1), "set_err": Out(1), "err": Out(1)})
"""Frame engine -> transmitter: ``push`` the ``level`` this sample sends; ``set_err`` rewrites the ERR pair of the
CNTR word with ``err`` at the last stop bit of the check sequence."""

WORDS: Final = wiring.Signature({"command": Out(WORD_BITS), "status": In(WORD_BITS), "watchdog_reset": In(1)})
"""Data path <-> outputs and diagnostics, as the data path sees it: the ``command`` word in the register (an ID
cycle's latch); back come the management bits 15..13 of the ID register (``status``: PF, WD, TE) and
``watchdog_reset``, the layer-2 watchdog firing (process data cleared, Table 3-13)."""


def _crc_step(crc: Value, bit: Value) -> Value:
    """One step of ``wire.crc_update_bit``: shift the 16-bit register left, feed back the polynomial."""
    feedback = crc[WORD_BITS - 1] ^ bit
    return (crc << 1)[:WORD_BITS] ^ Mux(feedback, wire.CRC_POLY, 0)


def _crc_check_constants() -> tuple[int, int]:
    """The bit flip of the CRC word sent and the residue of the received one, checked at elaboration.

    The CRC word goes out LSB first and is the register reflected (``wire.CRC_REFOUT``) and XORed with
    ``wire.CRC_XOROUT``, so its bit k is register bit 15 - k flipped by XOROUT's bit k: the transmitter sends bit 15
    of a register shifted left once per bit, flipped by one constant (XOROUT all zeros or all ones). The received
    word is fed on through the CRC step instead of being compared bit by bit with the register: every correct bit
    makes the feedback XOROUT's bit, so after the 16 bits the register holds a constant (the residue) whatever the
    data, and a wrong bit k adds ``CRC_POLY << (15 - k)`` (truncated), whose lowest set bit is k (the polynomial's bit
    0 is 1): any error changes it. Checked on register states below (docs/rtl.md, round 5).
    """
    full = (1 << WORD_BITS) - 1
    if not wire.CRC_REFOUT or wire.CRC_XOROUT not in (0, full) or not wire.CRC_POLY & 1:
        raise ValueError("the check sequence's CRC needs CRC_REFOUT, CRC_XOROUT 0 or all ones and CRC_POLY odd")
    flip = wire.CRC_XOROUT & 1
    residues = set()
    for data in (b"", b"\x00", b"\xa5\x5a", b"123456789"):
        crc = wire.CRC_INIT
        for byte in data:
            for i in range(BYTE_BITS):
                crc = wire.crc_update_bit(crc, (byte >> (i if wire.CRC_REFIN else BYTE_BITS - 1 - i)) & 1)
        word = wire.crc16(data)
        if word != int(f"{crc:016b}"[::-1], 2) ^ wire.CRC_XOROUT:
            raise ValueError("the bit-serial CRC register differs from wire.crc16")
        for k in range(WORD_BITS):
            crc = wire.crc_update_bit(crc, (word >> k) & 1)
        residues.add(crc)
    if len(residues) != 1:
        raise ValueError("the CRC has no residue")
    return flip, residues.pop()


_CRC_SENT_FLIP, _CRC_RESIDUE = _crc_check_constants()
"""The CRC word's bits are bit 15 of a register shifted left, XOR ``_CRC_SENT_FLIP``; a received CRC word fed into
the register after its data leaves ``_CRC_RESIDUE`` there exactly when it is right."""


def _per_rate(rate: Value, clocks: tuple[ClockEntry, ...], value: Callable[[ClockEntry], Value | int]) -> Value:
    """``value`` of the clock entry whose bit rate is ``rate``, one term per entry (the first for any other
    ``rate``): a compare or load with a constant per bit rate costs a few gates where one with the bit period as a
    signal needs an adder or a magnitude comparator (docs/rtl.md "Size and build time", round 3)."""
    result = Value.cast(value(clocks[0]))
    for entry in clocks[1:]:
        result = Mux(rate == entry.rate, value(entry), result)
    return result


class Supi3Core(wiring.Component):
    """The SUPI 3 chip core with the pins of :data:`supi3.pinout.CORE_INPUTS` and ``CORE_OUTPUTS`` and the strap ports.

    Parameters
    ----------
    variant:
        ``"opc"`` (TQFP 64) or ``"ls"`` (TQFP 44, Table 1-1). On the LS the ``rf`` and ``diag_conf`` ports exist
        but are ignored (the pins do not, Table 1-4), and only the LS's modes decode (C4 = 1).
    register_file:
        Add the ports :data:`REGISTER_FILE_INPUTS` (in) and :data:`REGISTER_FILE_OUTPUTS` and ``init_up`` (out)
        that join the core to :class:`supi3.rtl.upif.UpifBlock` in Init-µP modes (``init_up`` = 1).
    """

    def __init__(self, variant: Variant | str = Variant.OPC, *, register_file: bool = False) -> None:
        try:
            self.variant = check_variant(variant)
            self.register_file = check_bool("register_file", register_file)
        except ArgumentError:
            self._MustUse__silence = True  # rejected, never elaborated: no "created but never used" warning
            raise
        self.tables = core_tables(self.variant)
        members: dict[str, object] = {}
        for pin in (*CORE_INPUTS, *STRAP_PINS, *OPTICAL_LINE_INPUTS, *(REGISTER_FILE_INPUTS if register_file else ())):
            members[pin.name] = In(pin.width)
        for pin in (*CORE_OUTPUTS, *((*REGISTER_FILE_OUTPUTS, Pin("init_up")) if register_file else ())):
            members[pin.name] = Out(pin.width)
        super().__init__(members)

    # ------------------------------------------------------------------------------------------------------------

    def elaborate(self, _platform: object) -> Module:
        m = Module()
        tables = self.tables

        # Strap decode (Tables 2-4 to 2-7, 1-7, 2-2, 3-16) --------------------------------------------------------
        strap_id = Signal(WORD_BITS)
        strap_bytes = Signal(range(tables.register_bits // 8 + 1))
        init_up = Signal()
        spi = Signal()  # an SPI master mode (SM-1): the serial I/O block drives MFP3, 4, 5, 7
        spi_direction = Signal(range(len(DIRECTIONS)))
        spi_wide = Signal()
        rate = Signal(range(max(e.rate for e in tables.clocks) + 1))
        io_map = Signal(range(len(tables.io_maps)))
        clocks = tables.clocks
        cpb = Signal(range(max(e.clocks_per_bit for e in clocks) + 1))
        dclk = Signal()
        rbst_by_pin = Signal()
        complete_diag = Signal()
        local_bus = Signal()  # the mode raises the line interrupt ahead (DG-3)
        bus_terminal = Signal()  # a bus terminal module: LEDs on MFP15, 14, 13, 8 (Table 2-8)
        terminal_mode = Signal(range(len(TerminalMode)))  # which one (Table 2-7)
        maps = tables.io_maps
        lbd, lbd_mr = Signal(), Signal()  # an LBD mode, LBD-MR (Table 2-5): the counter telegram blocks run
        serial = tables.serial
        rom: tuple[tuple[Signal, Callable[[int], int]], ...] = (  # each field and its value in mode k
            (lbd, lambda k: tables.lines[k][0]),
            (lbd_mr, lambda k: tables.lines[k][1]),
            (local_bus, lambda k: tables.diagnostics[k][0]),
            (bus_terminal, lambda k: tables.diagnostics[k][1] != TerminalMode.NONE),
            (terminal_mode, lambda k: tables.diagnostics[k][1]),
            (spi, lambda k: serial[k] is not None),
            (spi_direction, lambda k: 0 if (mode := serial[k]) is None else DIRECTIONS.index(mode.direction)),
            (spi_wide, lambda k: 0 if (mode := serial[k]) is None else WIDTHS.index(mode.bits)),
            (strap_id, lambda k: tables.modes[k].id_register),
            (strap_bytes, lambda k: tables.modes[k].data_bytes),
            (init_up, lambda k: tables.modes[k].init_up),
            (io_map, lambda k: maps.index(tables.modes[k].io_map)),
            (self.mfp_oe, lambda k: tables.modes[k].mfp_oe),
        )
        # One ROM word per strap value (reserved values: 0, no mode), looked up by the straps: smaller than a case
        # per mode row (docs/rtl.md, round 4)
        words = [Cat(*(Const(0 if k is None else int(value(k)), len(field)) for field, value in rom))
                 for k in tables.strap_modes]  # fmt: skip
        straps = Cat(self.mfp_in[MFP_PINS - EXPANSION_BITS :], self.c)  # C[4..0] above MFP[15..12]
        m.d.comb += Cat(*(field for field, _ in rom)).eq(Array(words)[straps])
        # The free-running clock count: never reset (M23), it starts at 0 as the model's clock; the queues read only
        # differences of it, DCLK_OUT and IB_DIAG their phase.
        cycle = Signal(max(*IB_DIAG_DIVIDER_BITS.values(), *(_width(e.clocks_per_bit) for e in clocks)),
                       reset_less=True)  # fmt: skip
        m.d.sync += cycle.eq(cycle + 1)

        def clock(entry: ClockEntry) -> list[Value]:
            cpb_bits = entry.clocks_per_bit.bit_length() - 1
            if entry.clocks_per_bit != 1 << cpb_bits:
                raise ValueError(f"DCLK_OUT needs a power-of-two bit period, not {entry.clocks_per_bit}")
            return [
                rate.eq(entry.rate),
                cpb.eq(entry.clocks_per_bit),
                dclk.eq(~cycle[cpb_bits - 1]),  # c % cpb < cpb // 2 (the model's DCLK_OUT)
            ]

        with m.Switch(self.clk_conf):
            for entry in clocks:
                with m.Case(entry.clk_conf):
                    m.d.comb += clock(entry)
            with m.Default():  # reserved (Table 1-7)
                m.d.comb += clock(clocks[0])
        m.d.comb += [
            rbst_by_pin.eq(Cat(*(self.rf == v for v in tables.rbst_by_pin)).any()),
            complete_diag.eq(Cat(*(self.diag_conf == v for v in tables.complete_diagnostics)).any()),
        ]

        # The blocks (docs/rtl.md, "Architecture"). Each block's clocked logic runs on the clocks where the model's
        # _tick runs (``running``) and is held in its reset state otherwise (``gated``); the receiver's synchronisers
        # always run, so the receiver applies ``run`` and ``clear`` to its line receiver itself.
        m.submodules.receiver = receiver = ReceiverRtl(tables)
        frame = FrameEngineRtl()
        datapath = DataPathRtl(tables)
        transmitter = TransmitterRtl(tables)
        outputs = OutputsRtl(len(cycle))
        serial_io = SerialIoRtl()
        expansion = ExpansionRtl()
        optical = OpticalRtl()

        # The power-up reset with its stretch (1.7.2, M2), from the synchronised /ResU and voltage monitor ---------
        power_fail = ~(receiver.resu_n_s & receiver.vmon_ok_s)
        # The stretch counts down as an LFSR (lfsr.down_state), loaded with one clock more than it while the power
        # fails: that clock is the one after the failure the model holds the chip in (its ``holding``, round 5).
        stretch_width = max(min(TAPS), RESET_STRETCH_CLOCKS.bit_length())
        # No reset (M23): it starts loaded, as the model starts in the power-up reset; on the chip /ResU loads it.
        stretch = Signal(stretch_width, init=down_state(RESET_STRETCH_CLOCKS, stretch_width), reset_less=True)
        m.d.sync += stretch.eq(Mux(power_fail, down_state(RESET_STRETCH_CLOCKS, stretch_width), down_step(stretch)))
        running = ~power_fail & (stretch == 0)

        def gated(block: wiring.Component) -> Elaboratable:
            # Held in reset while not running, which is the same as stopping it: every stop begins with a power
            # failure, which resets it, and the initial state is the reset state, so it stays in that state until
            # ``running`` rises; a reset costs a gate per flip-flop, an enable a multiplexer (docs/rtl.md "Size and
            # build time", round 3). The registers without reset may change meanwhile: each is written before read.
            gated_block: Elaboratable = ResetInserter(~running)(block)
            return gated_block

        m.submodules.frame = gated(frame)
        m.submodules.datapath = gated(datapath)
        m.submodules.transmitter = gated(transmitter)
        m.submodules.outputs = gated(outputs)
        m.submodules.serial_io = gated(serial_io)
        m.submodules.expansion = gated(expansion)
        # LBD modes (Table 2-5): the counter telegram blocks on DO2 and DI1 (docs/rtl.md, "Counter telegram block")
        m.submodules.counter_lines = lines = CounterLinesRtl()
        check_watched_modes(tables.lines, [terminal for _, terminal in tables.diagnostics])  # the DI3 watch
        m.d.comb += [
            lines.line.eq(receiver.do1_s), lines.fast.eq(cpb == clocks_per_bit(1)), lines.sent.eq(transmitter.do2),
            lines.source.eq(outputs.di1), lines.forward.eq(lbd), lines.looped.eq(lbd_mr), lines.run.eq(running),
            lines.clear.eq(power_fail), frame.lbd.eq(lbd), lines.now.eq(cycle),
        ]  # fmt: skip

        # The bus terminal module (2.4, docs/bus-terminal.md): in reset until the core runs, so that it takes CONF as it
        # is at the first running clock (BK-20). A device answers on the branch once the synchronised DI3 was at the
        # start level where the logic ran (BK-37: a pulled-up or broken DI3 never is); a power failure forgets it.
        # While the interface is live DO3 (MFP9) takes the DO2 the core would send (BK-42), else it idles; while the
        # branch is in the data path DO2 repeats the synchronised DI3 (BK-1's order: the BK, its branch, on along the
        # remote bus; the pin model's BranchLines). Each switches only between telegrams (BK-47: ``sel3``, ``sel2``
        # follow ``live`` and ``enabled`` where the logic runs; DO2 idles between its two lines and leaves DI3 once
        # drained).
        terminal = TerminalRtl()
        m.submodules.terminal = ResetInserter(~running)(terminal)
        di3 = receiver.mfp_in_s[DI3_PIN]
        connected = Signal()
        with m.If(power_fail):
            m.d.sync += connected.eq(0)
        with m.Elif(running & (di3 == wire.START_LEVEL)):
            m.d.sync += connected.eq(1)
        tx_watch = ReturnWatchRtl()
        m.submodules.tx_watch = ResetInserter(~running)(tx_watch)
        m.d.comb += [tx_watch.line.eq(lines.do2), tx_watch.fast.eq(lines.fast)]
        sel3 = Signal()
        sel2 = Signal(2, init=_SENT)
        # DI3's idle clocks, counted up as an LFSR (lfsr.count_state) that runs on past its end, and ``full`` set on
        # the clock after it read BRANCH_DRAIN_BITS bit periods less one, kept while DI3 stays idle (round 5: no hold)
        drain_width = count_width(max(e.clocks_per_bit for e in clocks) * BRANCH_DRAIN_BITS)
        drained = Signal(drain_width, init=count_state(0, drain_width))
        full = Signal()
        ending = _per_rate(rate, clocks, lambda e: drained == count_state(e.clocks_per_bit * BRANCH_DRAIN_BITS - 1,
                                                                           drain_width))  # fmt: skip
        tx_free = ~tx_watch.busy
        tx_leave = tx_free & (lines.do2 == wire.IDLE_LEVEL)
        di3_free = ~lines.branch_busy
        di3_idle = di3_free & (di3 == wire.IDLE_LEVEL)
        want = Mux(terminal.enabled, _DI3, _SENT)
        leave = (sel2 == _IDLE) | Mux(sel2 == _SENT, tx_leave, di3_idle & full)
        with m.If(~running):  # reset, and held so until the core runs (as ``gated``)
            m.d.sync += [sel3.eq(0), sel2.eq(_SENT), drained.eq(count_state(0, drain_width)), full.eq(0)]
        with m.Else():
            with m.If((sel3 != terminal.live) & Mux(sel3, tx_leave, tx_free)):
                m.d.sync += sel3.eq(terminal.live)
            with m.If((sel2 != want) & leave):
                m.d.sync += sel2.eq(Mux(Mux(terminal.enabled, di3_free, tx_free), want, _IDLE))
            m.d.sync += [drained.eq(Mux(di3_idle, next_state(drained), count_state(0, drain_width))),
                         full.eq(di3_idle & (full | ending))]
        do2 = Signal(init=wire.IDLE_LEVEL)
        m.d.comb += do2.eq(Mux(sel2 == _SENT, lines.do2, Mux(sel2 == _DI3, di3, wire.IDLE_LEVEL)))
        # The master's telegrams back on DI3 (BK-38) and, in BK-LBD, the counter block on DI3 (BK-39).
        m.d.comb += [lines.branch_line.eq(di3), lines.branch.eq(terminal_mode == TerminalMode.LBD)]
        command = datapath.words.command
        m.d.comb += [
            terminal.ib_reset.eq(frame.management.clear),
            terminal.mode.eq(terminal_mode),
            terminal.rf.eq(self.rf),
            terminal.conf.eq(receiver.mfp_in_s[CONF_PIN]),
            terminal.lbst.eq(receiver.mfp_in_s[LBST_PIN]),
            terminal.cmd_valid.eq(frame.management.latch_id),
            terminal.branch.eq(command[wire.CMD_BRANCH_SHIFT :][: len(terminal.branch)]),
            terminal.ack.eq(command[wire.CMD_QUIT_BIT]),
            terminal.alarm_set.eq(command[wire.CMD_ALARM_OUT_SET_BIT] & ~command[wire.CMD_PCMD_BIT]),
            terminal.alarm_on.eq(command[wire.CMD_ALARM_OUT_BIT]),
            terminal.connected.eq(connected),
            terminal.ret_valid.eq(lines.returned & terminal.enabled),  # BK-44: only while in the data path
            terminal.cnt_valid.eq(lines.seen & terminal.enabled),
            terminal.count.eq(lines.count),
            terminal.frame_end.eq(frame.checked),  # BK-50: the silence is judged at a frame's end
            outputs.ld.eq(terminal.ld),
            outputs.e.eq(terminal.e),
            outputs.alarm.eq(terminal.alarm),
            outputs.bk_attention.eq(terminal.attention),
        ]
        m.submodules.optical = gated(optical)

        # Joins between the blocks: connect() where the interfaces fit ---------------------------------------------
        wiring.connect(m, receiver=receiver.line, frame=frame.line)
        wiring.connect(m, frame=frame.register, datapath=datapath.frame)
        wiring.connect(m, frame=frame.management, outputs=outputs.frame)
        wiring.connect(m, frame=frame.tx, transmitter=transmitter.frame)
        wiring.connect(m, datapath=datapath.words, outputs=outputs.words)
        # ... and plain assignments for pins, straps and the synchronised inputs each block takes a few of.
        m.d.comb += [getattr(receiver, pin.name).eq(getattr(self, pin.name)) for pin in CORE_INPUTS]
        m.d.comb += [
            receiver.run.eq(running),
            receiver.clear.eq(power_fail),
            receiver.rate.eq(rate),
            transmitter.rate.eq(rate),
            transmitter.now.eq(cycle),  # the free-running clock count (never reset) the output queues share
            datapath.mfp_in.eq(receiver.mfp_in_s),
            datapath.io_map.eq(io_map),
            outputs.stat_err_n_s.eq(receiver.stat_err_n_s),
            outputs.di2_s.eq(receiver.di2_s),
            outputs.rbst_ext_s.eq(receiver.rbst_ext_s),
            outputs.di2.eq(self.di2),
            outputs.do2.eq(do2),
            outputs.divider.eq(cycle),
            outputs.rbst_by_pin.eq(rbst_by_pin),
            outputs.complete_diag.eq(complete_diag),
            outputs.local_bus.eq(local_bus),
            outputs.bus_terminal.eq(bus_terminal),
            outputs.idle_timeout.eq(receiver.line.idle_timeout),
            outputs.counted.eq(receiver.line.counted),
            outputs.ended.eq(frame.ended),
        ]

        # The optical block (1.6, OPT-26): RF[1..0] selects its mode (the LS has none); its INTERBUS reset is the
        # reset period (the reset on the line, or the idle time-out until the line is heard); it holds the protocol
        # core (OPT-20: no latch, discard, event), lights FO1..FO3, writes reads 8..11 and gives the MAU warnings of
        # the optical status byte (OPT-50..OPT-53).
        optical_mode = Signal(range(len(OpticalMode)))
        if self.variant is Variant.OPC:
            with m.Switch(self.rf):
                for row in RF_MODES:
                    with m.Case(int(row.rf, 2)):
                        m.d.comb += optical_mode.eq(_optical_mode(row))
        m.d.comb += [
            *(getattr(optical, pin.name).eq(getattr(self, pin.name)) for pin in OPTICAL_LINE_INPUTS
              if pin.name not in OPTICAL_BRANCH_INPUTS),
            # OPT-55: the branch interface is a BK's (Table 2-8); elsewhere its line-side bits are held at 0.
            *(getattr(optical, name).eq(_branch_gated(getattr(self, name), bus_terminal))
              for name in OPTICAL_BRANCH_INPUTS),
            optical.ib_reset.eq(receiver.line.in_reset | receiver.line.idle_timeout | outputs.line_silent),
            optical.mode.eq(optical_mode),
            optical.fast.eq(rate == BIT_RATES.index(max(BIT_RATES))),
            optical.run.eq(outputs.bus_active),
            frame.hold.eq(optical.hold),
            outputs.fo.eq(optical.fo),  # DG-7
            outputs.mau.eq(optical.mau),
            outputs.optical_quiet.eq(optical.ib_reset),
            datapath.optical_send.eq(outputs.send_optical),
            datapath.optical_mau.eq(outputs.mau_sent),
        ]

        # SPI master modes (3.3): the serial I/O block takes the OUT word of a valid data cycle's latch and gives
        # the IN word the next data cycle loads (SM-2, SM-4, SM-6); resets clear it (SM-9).
        # The word's bit w is the register's bit line_position(w, bytes) in either width. A 16-bit sequence reads
        # only the OUT word's low 16 bits (SerOut from D15), and a 2-byte data cycle only the register's low 16 bits,
        # so only those choose by the width; the rest are the 32-bit word's in both (round 4).
        narrow, wide = WIDTHS
        out_word = Signal(wide)
        in_data = Signal(tables.register_bits)
        in_word = serial_io.in_word
        for w in range(wide):
            at = line_position(w, wide // 8)
            word_bit = datapath.register[at]
            if w < narrow:
                word_bit = Mux(spi_wide, word_bit, datapath.register[line_position(w, narrow // 8)])
            m.d.comb += out_word[w].eq(word_bit)
            if at < narrow:
                in_bit = next(k for k in range(narrow) if line_position(k, narrow // 8) == at)
                m.d.comb += in_data[at].eq(Mux(spi_wide, in_word[w], in_word[in_bit]))
            else:
                m.d.comb += in_data[at].eq(in_word[w])
        m.d.comb += [
            serial_io.start.eq(spi & frame.management.latch_data),
            serial_io.out_word.eq(out_word),
            serial_io.reset.eq(spi & (frame.management.clear | outputs.words.watchdog_reset)),
            serial_io.ser_in.eq(receiver.mfp_in_s[SER_IN_PIN]),
            serial_io.direction.eq(spi_direction),
            serial_io.wide.eq(spi_wide),
            serial_io.rate.eq(rate),
        ]

        # The register expansion (3.5, OPC only): with ExtReg = 1 in the SET register (Init-µP modes), a data
        # frame's bits go out on ToExR and the bits sent come from FromExR (RX-2); every cycle end pulses LaOuD and
        # /LaInD (RX-4); /ResReg is the outputs block's pulse, 4 t0 on both resets with expansion (RX-5).
        up = self.register_file
        ext = Signal()
        has_data = Signal()
        if up and self.variant is Variant.OPC:
            m.d.comb += ext.eq(init_up & self.ext_reg)
            codes = range(1 << len(self.bus_id[BYTE_BITS:]))  # the complete length code (Table 3-11), a ROM
            m.d.comb += has_data.eq(Array(Const(_code_bytes(code) > 0) for code in codes)[self.bus_id[BYTE_BITS:]])
        register = frame.register
        management = frame.management
        m.d.comb += [
            expansion.ext.eq(ext),
            expansion.has_data.eq(has_data),
            expansion.rate.eq(rate),
            expansion.load.eq(register.load),
            expansion.load_id.eq(register.load_id),
            expansion.shift.eq(register.shift),
            expansion.level.eq(register.level),
            expansion.ended.eq(management.latch_data | management.latch_id | (frame.discard & ~optical.hold)),
            expansion.latched.eq(management.latch_data),
            expansion.from_exr.eq(receiver.from_exr_s),
            datapath.chain.eq(expansion.active),
            datapath.chain_bit.eq(expansion.send),
            outputs.expansion.eq(ext),
            outputs.rate.eq(rate),
        ]

        # Init-µP modes: the ID register, the data length and the IN data from the register file (docs/upif.md)
        m.d.comb += [
            # A BK without µP sends its branch status byte when the master asked for it (BK-5)
            datapath.id_register.eq(Mux(outputs.send_alarm & bus_terminal & ~init_up,
                                        Cat(terminal.status, strap_id[BYTE_BITS:]), strap_id)),
            datapath.data_bytes.eq(strap_bytes),
            datapath.external.eq(spi | init_up if up else spi),
            # Init-µP modes have no SPI master (checked here), so the serial I/O's IN word stays at its reset 0 in them;
            # outside them the register file is held in its power-up reset (``power_up``), where the IN bytes are 0
            # (checked here): so the two words are ORed, not chosen (round 5)
            datapath.in_data.eq(self.in_data | in_data if up else in_data),
        ]
        if up and (any(tables.modes[k].init_up and serial[k] is not None for k in tables.strap_modes if k is not None)
                   or any(register.reset for register in IN_BYTES)):
            raise ValueError("the IN data are ORed: no SPI master in Init-µP modes, IN bytes reset to 0")
        if up:
            up_bytes = Signal.like(strap_bytes)
            counts = [upif_tables().internal_bytes.get(code, 0) for code in range(1 << len(self.bus_id[BYTE_BITS:]))]
            # the length code (Table 3-11) as the register file applies it, a ROM
            m.d.comb += up_bytes.eq(Array(Const(count, len(up_bytes)) for count in counts)[self.bus_id[BYTE_BITS:]])
            with m.If(init_up):
                # A18: the processor alarm in place of the ID code when the master asked for it
                up_id = Mux(outputs.send_alarm, self.alarm, self.bus_id[:BYTE_BITS])
                m.d.comb += [
                    datapath.id_register.eq(Cat(up_id, self.bus_id[BYTE_BITS:])),
                    datapath.data_bytes.eq(up_bytes),
                ]
            command = datapath.words.command
            events = frame.events | (outputs.words.watchdog_reset << _SOURCE_BIT["IB_RESET"])
            io_now = Mux(running, frame.io_set | (frame.io & ~frame.io_clear), frame.io)
            m.d.comb += [
                self.init_up.eq(init_up),
                self.rate.eq(rate),
                Cat(self.np_id, self.np_length).eq(strap_id),
                self.power_up.eq(~init_up | power_fail | self.resu_drive),
                self.ib_reset.eq(running & (frame.management.clear | outputs.words.watchdog_reset)),
                self.events.eq(Mux(running, events, 0)),
                self.io_access.eq(io_now),
                self.latch.eq(running & frame.management.latch_data),
                self.latch_out.eq(datapath.register),
                self.pcmd_we.eq(running & frame.management.latch_id & command[wire.CMD_PCMD_BIT]),
                self.pcmd.eq(Mux(frame.management.latch_id, command[wire.CMD_PCMD_SHIFT :][:BYTE_BITS], 0)),
                self.optical.eq(optical.optical),
            ]

        m.d.comb += [
            self.do2.eq(do2),
            self.di1.eq(lines.di1),
            self.mfp_out.eq(datapath.mfp_out | Mux(spi, serial_io.mfp, 0) | outputs.mfp_diag
                            | Mux(bus_terminal, Mux(sel3, lines.do2, wire.IDLE_LEVEL) << DO3_PIN, 0)),
            self.mod_ack_n.eq(outputs.mod_ack_n),
            self.res_reg_n.eq(outputs.res_reg_n),
            self.diag1.eq(outputs.diag1),
            self.diag2.eq(outputs.diag2),
            self.ib_diag.eq(outputs.ib_diag),
            self.dclk_out.eq(dclk),
            self.resu_drive.eq(stretch != 0),
            *(getattr(self, name).eq(getattr(expansion, name)) for name in EXPANSION_PINS),
        ]
        return m


class ReceiverRtl(wiring.Component):
    """Synchroniser and line receiver (block ``receiver``; the model's ``receiver`` block).

    Every input pin passes :data:`~supi3.pinout.SYNC_STAGES` flip-flops (M1) that always run; the synchronised
    levels come out as ``<pin>_s``. The line receiver runs while ``run`` is 1 and is cleared by ``clear`` (the core's
    enable and power-up reset): INTERBUS reset detection (a start-level run of ``reset_run`` clocks, A12) and its end
    after the status telegrams of Table A12, the 20 ms idle time-out (A13), telegram framing (an ``m.FSM``: between
    telegrams / in a telegram; a stop bit at start level starts the next one, M16) and the mid-bit sample at
    ``cpb // 2`` clocks into every bit. Its view of the line is the :data:`LINE` interface ``line``.
    """

    def __init__(self, tables: CoreTables) -> None:
        clocks = tables.clocks
        members: dict[str, object] = {pin.name: In(pin.width) for pin in CORE_INPUTS}
        members.update({f"{pin.name}_s": Out(pin.width) for pin in CORE_INPUTS})
        members.update(
            run=In(1),
            clear=In(1),
            rate=In(range(max(e.rate for e in clocks) + 1)),
            line=Out(LINE),
        )
        self.clocks = clocks
        super().__init__(members)

    def elaborate(self, _platform: object) -> Module:
        m = Module()
        for pin, idle in zip(CORE_INPUTS, CORE_IDLE, strict=True):
            # No reset (M23): the stages start at the idle levels, as the model's; on the chip the power-up reset
            # (/ResU low while the power comes up, 1.7.2) holds the core while they fill.
            stages = [Signal(pin.width, init=idle, name=f"{pin.name}_s{k}", reset_less=True)
                      for k in range(SYNC_STAGES)]  # fmt: skip
            m.d.sync += [stages[0].eq(getattr(self, pin.name)), *(b.eq(a) for a, b in pairwise(stages))]
            m.d.comb += getattr(self, f"{pin.name}_s").eq(stages[-1])
        rx = Module()
        m.submodules.line = ResetInserter(self.clear | ~self.run)(rx)
        sync, comb = rx.d.sync, rx.d.comb
        line = self.do1_s
        out = self.line
        clocks = self.clocks

        def per_rate(value: Callable[[ClockEntry], Value | int]) -> Value:
            return _per_rate(self.rate, clocks, value)

        # INTERBUS reset, idle time-out (docs/interbus.md A12, A13)
        in_reset = Signal()
        reset_end = Signal(range(wire.RESET_END_STATUS_TELEGRAMS + 1))
        # Both counters count up as LFSRs (supi3.rtl.lfsr): only loaded, stepped and compared with constants, so the
        # count v is the state v steps after 1 (``lfsr.count_state``) and a step is an XOR instead of a carry chain.
        run_width = count_width(max(e.reset_run for e in clocks))
        # clocks at the start level, stepping on while it lasts; ``ran``: this run began an INTERBUS reset (the LFSR
        # passes the state again 2 ** run_width - 1 clocks later)
        low_run = Signal(run_width, init=count_state(0, run_width))
        ran = Signal()
        silent_width = count_width(IDLE_TIMEOUT_CLOCKS + 1)
        # clocks since the last start of no counter telegram, from 1 on, stopping one beyond the time-out
        silent = Signal(silent_width, init=count_state(1, silent_width))

        def since_start(e: ClockEntry) -> int:
            """``silent`` after a control bit's sample, cpb // 2 + 3 cpb clocks after its telegram's start bit."""
            return count_state(e.clocks_per_bit // 2 + wire.POS_CONTROL * e.clocks_per_bit + 1, silent_width)

        counted = Signal()  # a counter telegram since then (DG-9)
        low = line == wire.START_LEVEL
        enter_reset = low & ~ran & per_rate(lambda e: low_run == count_state(e.reset_run - 1, run_width))
        idle_timeout = silent == count_state(IDLE_TIMEOUT_CLOCKS, silent_width)  # once per silence
        with rx.If(~low):
            sync += [low_run.eq(count_state(0, run_width)), ran.eq(0)]
        with rx.Else():
            sync += [low_run.eq(next_state(low_run)), ran.eq(ran | enter_reset)]
        with rx.If(silent != count_state(IDLE_TIMEOUT_CLOCKS + 1, silent_width)):
            sync += silent.eq(next_state(silent))
        with rx.If(enter_reset):
            sync += [in_reset.eq(1), reset_end.eq(0)]
        in_reset_now = in_reset | enter_reset

        # Framing and mid-bit sampling
        busy = Signal()  # in a telegram (the FSM below)
        # Set at every start bit (phase, bit, is_data) or sampled in every telegram before its control bit and its
        # end (select, control: positions 2 and 3 of both kinds), read only with ``sample`` (in a telegram): no reset.
        phase = Signal(range(max(e.clocks_per_bit for e in clocks)), reset_less=True)  # clocks since the start bit,
        bit = Signal(_POSITION, reset_less=True)  # modulo the bit; the position of the next bit
        select = Signal(reset_less=True)
        control = Signal(reset_less=True)
        is_data = Signal(init=1, reset_less=True)
        sample = busy & per_rate(lambda e: phase == e.clocks_per_bit // 2)
        data_now = Mux(bit == wire.POS_TYPE, line == wire.TYPE_DATA_LEVEL, is_data)
        end = bit == Mux(data_now, _DATA_TELEGRAM_END, _STATUS_TELEGRAM_END)
        with rx.FSM(name="telegram") as fsm:
            with rx.State("BETWEEN"), rx.If(low):  # a start bit
                sync += [phase.eq(1), bit.eq(0), is_data.eq(1)]
                rx.next = "TELEGRAM"
            with rx.State("TELEGRAM"):
                sync += phase.eq(Mux(per_rate(lambda e: phase == e.clocks_per_bit - 1), 0, phase + 1))
                with rx.If(sample & end & (line == wire.STOP_LEVEL)):
                    rx.next = "BETWEEN"
        comb += busy.eq(fsm.ongoing("TELEGRAM"))
        with rx.If(sample):
            sync += [bit.eq(bit + 1), is_data.eq(data_now)]
            with rx.If(bit == wire.POS_SELECT):
                sync += select.eq(line)
            with rx.If(bit == wire.POS_CONTROL):
                # The idle time-out restarts from this telegram's start bit (its control bit's sample is cpb // 2 +
                # 3 cpb clocks after it) unless it is a counter telegram (DG-9, BK-36).
                sync += [control.eq(line), counted.eq(out.counter)]
                with rx.If(~out.counter):
                    sync += silent.eq(per_rate(since_start))
            with rx.If(end & (line != wire.STOP_LEVEL)):  # M16: the stop bit's period is the next start bit
                sync += [bit.eq(1), is_data.eq(1)]

        # The end of an INTERBUS reset: the status telegrams after it (docs/interbus.md A12)
        with rx.If(sample & end & (line == wire.STOP_LEVEL) & ~data_now & in_reset_now):
            sync += reset_end.eq(reset_end + 1)
            with rx.If(reset_end + 1 == wire.RESET_END_STATUS_TELEGRAMS):
                sync += in_reset.eq(0)

        comb += [
            out.level.eq(line),
            out.sample.eq(sample),
            out.frame_bit.eq(sample & data_now & ~in_reset_now),
            out.telegram_end.eq(sample & end),
            out.position.eq(bit),
            out.data_now.eq(data_now),
            out.in_reset.eq(in_reset_now),
            out.select.eq(select),
            out.control.eq(control),
            out.bus_reset.eq(enter_reset),
            out.idle_timeout.eq(idle_timeout),
            out.counted.eq(counted),
        ]
        return m


class FrameEngineRtl(wiring.Component):
    """Frame engine (block ``frame``): telegram framing into cycles, CRC and check sequence, latch and discard.

    An ``m.FSM`` with the model's states IDLE, DATA (data field), CHECK (check sequence), WAIT (latch telegrams).
    Bit-serial CRC-16 of the data received and sent; the received check sequence is checked bit-serially (the CRC
    word fed on into its register up to the residue, CNTR legality, ERR) instead of stored; the CNTR word is forwarded
    with the chip's ATTN. It drives the data path through ``register`` (:data:`REGISTER`), the chip registers through
    ``management`` (:data:`MANAGEMENT`) and the transmitter through ``tx`` (:data:`TRANSMIT`); ``events`` are the
    frame's interrupt sources at their IRQ_EVT bits, ``io`` the I/O access bit with this clock's ``io_set`` and
    ``io_clear``, ``discard`` a frame ending unlatched (``chip.discard_at``). The statements follow the model's order
    within one clock, later assignments winning as later Python assignments do.
    """

    def __init__(self) -> None:
        super().__init__({
            "line": In(LINE), "register": Out(REGISTER), "management": Out(MANAGEMENT), "tx": Out(TRANSMIT),
            "events": Out(EVENT_BITS), "io": Out(1), "io_set": Out(1), "io_clear": Out(1), "discard": Out(1),
            "hold": In(1), "ended": Out(1), "lbd": In(1), "checked": Out(1),
        })  # fmt: skip

    def elaborate(self, _platform: object) -> Module:
        m = Module()
        sync, comb = m.d.sync, m.d.comb
        rx, reg, mg, tx = self.line, self.register, self.management, self.tx
        line = rx.level
        events = Signal(EVENT_BITS)  # the frame's interrupt sources; none while the optical block holds the core

        def event(source: str) -> Value:
            return events[_SOURCE_BIT[source]].eq(1)

        # The FSM's state as flags, for the conditions below; the transitions are at the end.
        idle, in_data, in_check, in_wait = Signal(), Signal(), Signal(), Signal()
        load, check_start, check_done, latch_done = Signal(), Signal(), Signal(), Signal()
        broken = Signal()  # a status telegram inside a frame: the frame ends, discarded with its local error (M20)

        # Read only outside IDLE (id_cycle, latches, local_error, err_in) or in CHECK (the rest), and set when a frame
        # is loaded, enters CHECK or receives the CNTR bit before the one that reads it (attn, err_bit, the pairs'
        # first bits); a frame leaves IDLE only by its load: no reset.
        id_cycle = Signal(reset_less=True)  # the frame's cycle type: 1 = ID cycle
        latches = Signal(range(wire.LATCH_STATUS_TELEGRAMS + 1), reset_less=True)
        crc_rx = Signal(WORD_BITS, init=wire.CRC_INIT, reset_less=True)
        crc_tx = Signal(WORD_BITS, init=wire.CRC_INIT, reset_less=True)
        index = Signal(range(wire.CHECK_TELEGRAMS + 2), reset_less=True)
        cntr_bad = Signal(reset_less=True)
        local_error = Signal(reset_less=True)
        err_in = Signal(reset_less=True)
        attn = Signal(reset_less=True)
        err_bit = Signal(reset_less=True)
        on_grid = Signal()  # a whole status telegram since the power-up: a frame may begin (M19)
        pairs = [
            tuple(sorted(p))
            for p in ((wire.CNTR_ATTN_BIT, wire.CNTR_NATTN_BIT), (wire.CNTR_NERR_BIT, wire.CNTR_ERR_BIT))
        ]
        firsts = [Signal(name=f"cntr_pair{k}", reset_less=True) for k in range(len(pairs))]
        paired = {b for p in pairs for b in p}
        if (wire.CNTR_NERR_BIT, wire.CNTR_ERR_BIT) != (
            WORD_BITS - 2,
            WORD_BITS - 1,
        ) or wire.CNTR_ATTN_BIT > wire.CNTR_NATTN_BIT:
            raise ValueError("the model settles the ERR pair as the last two CNTR bits, after ATTN and /ATTN")

        discard = self.discard  # a frame ends unlatched (chip.discard_at): the invalid-data-cycle event
        io = self.io
        sync += io.eq(self.io_set | (io & ~self.io_clear))
        comb += [tx.push.eq(rx.sample), tx.level.eq(line), reg.level.eq(line),
                 mg.frame_error.eq(~idle & (local_error | broken) & ~self.hold)]  # fmt: skip

        # INTERBUS reset and idle time-out: the frame is dropped, the chip reset (chip.reset_at)
        clear = rx.bus_reset | rx.idle_timeout
        comb += [mg.clear.eq(clear), reg.clear.eq(clear)]
        with m.If(clear):
            sync += latches.eq(0)
            comb += self.io_clear.eq(1)
        with m.If(rx.idle_timeout):
            # A frame abandoned here raises TE, which the INTERBUS reset clears again at once.
            comb += discard.eq(~idle)

        def error() -> Value:
            return local_error.eq(1)

        def abandon() -> None:
            """A frame ends unlatched: invalid cycle, TE |= local error (Table 3-13)."""
            m.d.comb += [discard.eq(~idle), self.io_clear.eq(1), mg.abandon.eq(~self.hold)]
            m.d.sync += latches.eq(0)

        data_field = (rx.position >= wire.POS_DATA) & (rx.position < wire.POS_DATA + 8)
        j = (rx.position - wire.POS_DATA)[:3]
        check_n = Cat(j, index[:2])  # bit of the check sequence, line order
        cntr_b = check_n[:4]
        control_bit = rx.frame_bit & (rx.position == wire.POS_CONTROL)
        cycle_id = rx.select == wire.SELECT_ID_LEVEL
        check = line == wire.CONTROL_CHECK_LEVEL
        # A counter telegram (LBD modes, BK-36): an ID check telegram while no frame runs; the frame ignores it. In an
        # INTERBUS reset too (the frame idles; DG-9: it does not restart the idle time-out there either).
        counter_bit = rx.sample & rx.data_now & (rx.position == wire.POS_CONTROL)
        comb += rx.counter.eq(counter_bit & self.lbd & cycle_id & check & (idle | in_wait | rx.idle_timeout))
        with m.If(control_bit & ~rx.counter):
            with m.If(~check & ~in_data), m.If(on_grid):  # a frame begins: the register's parallel load
                abandon()
                comb += [load.eq(1), reg.load.eq(1), reg.load_id.eq(cycle_id)]
                sync += [
                    id_cycle.eq(cycle_id),
                    crc_rx.eq(wire.CRC_INIT),
                    crc_tx.eq(wire.CRC_INIT),
                    local_error.eq(0),
                    err_in.eq(0),
                    latches.eq(0),
                ]
            with m.Elif(cycle_id != id_cycle):
                sync += error()
            with m.If(check):
                with m.If(in_data):
                    sync += [index.eq(0), cntr_bad.eq(0)]
                    comb += [check_start.eq(1), self.io_set.eq(~id_cycle)]  # the I/O access window (Fig. 3-22)
                with m.Elif(in_check):
                    sync += index.eq(index + 1)
                with m.If(~(in_data | (in_check & (index + 1 < wire.CHECK_TELEGRAMS)))):
                    sync += error()
        with m.Elif(rx.frame_bit & data_field & in_data):
            comb += [tx.level.eq(reg.shift_out), reg.shift.eq(1)]
            sync += [crc_rx.eq(_crc_step(crc_rx, line)), crc_tx.eq(_crc_step(crc_tx, reg.shift_out))]
        with m.Elif(rx.frame_bit & data_field & in_check & (index < wire.CHECK_TELEGRAMS)):
            with m.If(check_n < WORD_BITS):  # own CRC word out, the received one fed on (_CRC_RESIDUE)
                comb += tx.level.eq(crc_tx[WORD_BITS - 1] ^ _CRC_SENT_FLIP)
                sync += [crc_rx.eq(_crc_step(crc_rx, line)), crc_tx.eq(crc_tx << 1)]
            with m.Else():  # CNTR forwarded (wire.forward_cntr); the ERR pair is settled at the last stop bit
                comb += tx.level.eq(0)
                with m.Switch(cntr_b):
                    for b in range(WORD_BITS):
                        with m.Case(b):
                            if b == wire.CNTR_ATTN_BIT:
                                comb += tx.level.eq(line | mg.attention)
                                sync += attn.eq(line | mg.attention)
                            elif b == wire.CNTR_NATTN_BIT:
                                comb += tx.level.eq(~attn)
                            if b == wire.CNTR_ERR_BIT:
                                sync += err_bit.eq(line)
                            for first, (lo, hi) in zip(firsts, pairs, strict=True):
                                if b == lo:
                                    sync += first.eq(line)
                                elif b == hi:
                                    with m.If(line == first):
                                        sync += cntr_bad.eq(1)
                            if b not in paired:
                                with m.If(line):
                                    sync += cntr_bad.eq(1)

        # Telegram end: check sequence, latch (docs/interbus.md "Cycle end")
        stop_bad = line != wire.STOP_LEVEL
        with m.If(rx.telegram_end):
            with m.If(stop_bad):
                sync += error()
            with m.If(in_check & (index == wire.CHECK_TELEGRAMS - 1) & rx.data_now & ~rx.in_reset):
                error_now = local_error | stop_bad | (crc_rx != _CRC_RESIDUE) | cntr_bad
                err = error_now | cntr_bad | err_bit
                sync += [local_error.eq(error_now), err_in.eq(cntr_bad | err_bit)]
                comb += [check_done.eq(1), tx.set_err.eq(1), tx.err.eq(err)]
            with m.If(~stop_bad & ~rx.data_now):
                sync += on_grid.eq(1)
            with m.If(~stop_bad & ~rx.data_now & ~rx.in_reset):
                with m.If(in_data | in_check):
                    sync += error()
                    comb += broken.eq(1)
                    abandon()
                with m.Elif(in_wait):
                    latched = Mux(rx.control == wire.CONTROL_CHECK_LEVEL, latches + 1, 0)
                    sync += latches.eq(latched)
                    with m.If((latched == wire.LATCH_STATUS_TELEGRAMS) & (local_error | err_in)):
                        abandon()
                        comb += latch_done.eq(1)
                    with m.Elif(latched == wire.LATCH_STATUS_TELEGRAMS):  # chip.latch_at
                        sync += latches.eq(0)
                        comb += [latch_done.eq(1), self.io_clear.eq(1), event("PCP_TX")]
                        with m.If(id_cycle):  # the command word (docs/interbus.md A9)
                            comb += [mg.latch_id.eq(~self.hold), event("ID_CYCLE")]
                        with m.Else():  # OUT data to the MFPs (Tables 3-1, 3-2), watchdog restarted
                            comb += [mg.latch_data.eq(~self.hold), reg.latch.eq(~self.hold), event("VALID"),
                                     event("PCP_RX")]  # fmt: skip
        comb += events[_SOURCE_BIT["INVALID"]].eq(discard & ~id_cycle)
        # The optical block's hold (OPT-20): the core behaves as in reset, a cycle's end latches nothing, raises no
        # event, sets no TE; the line is still heard (``ended``: a cycle ended at the chip, DG-3, DG-4).
        comb += [self.events.eq(Mux(self.hold, 0, events)), self.ended.eq(discard | latch_done)]

        # The states (the model's _state), later transitions winning as later assignments do
        with m.FSM(name="frame") as fsm:
            with m.State("IDLE"), m.If(load):
                m.next = "DATA"
            with m.State("DATA"):
                with m.If(clear | broken):
                    m.next = "IDLE"
                with m.If(check_start):
                    m.next = "CHECK"
            with m.State("CHECK"):
                with m.If(clear | broken):
                    m.next = "IDLE"
                with m.If(load):
                    m.next = "DATA"
                with m.If(check_done):
                    m.next = "WAIT"
            with m.State("WAIT"):
                with m.If(clear):
                    m.next = "IDLE"
                with m.If(load):
                    m.next = "DATA"
                with m.If(latch_done):
                    m.next = "IDLE"
        comb += [
            idle.eq(fsm.ongoing("IDLE")),
            in_data.eq(fsm.ongoing("DATA")),
            in_check.eq(fsm.ongoing("CHECK")),
            in_wait.eq(fsm.ongoing("WAIT")),
            self.checked.eq(check_done),  # a frame's check sequence completes at this edge (BK-50)
        ]
        return m


class DataPathRtl(wiring.Component):
    """Shift register, load and latch (block ``datapath``).

    The frame's shift register (width 8 x data bytes, or 16 in an ID cycle; bit 0 goes out first) with its length
    fixed at the load; the parallel load of the ID register (``id_register`` with the management bits ``status``)
    or of the IN data (the MFP inputs through the mode's map, or ``in_data`` with ``external``: the register file's IN
    bytes in Init-µP modes, the serial I/O's IN word in SPI master modes; 0 if the watchdog fires at that clock);
    the latch of OUT data to the MFP outputs through the mode's map, and their clearing by an INTERBUS reset or the
    watchdog (Tables 3-1, 3-2, 3-13). Driven by the frame engine through ``frame``
    (:data:`REGISTER`, flipped); ``words`` (:data:`WORDS`) joins it to the outputs and diagnostics.
    """

    def __init__(self, tables: CoreTables) -> None:
        self.tables = tables
        super().__init__({
            "frame": In(REGISTER), "words": Out(WORDS),
            "id_register": In(WORD_BITS), "data_bytes": In(range(tables.register_bits // 8 + 1)), "external": In(1),
            "in_data": In(tables.register_bits), "io_map": In(range(len(tables.io_maps))), "mfp_in": In(MFP_PINS),
            "chain": In(1), "chain_bit": In(1), "optical_send": In(1), "optical_mau": In(len(wire.MAU_WARNINGS)),
            "register": Out(tables.register_bits), "mfp_out": Out(MFP_PINS),
        })  # fmt: skip

    def elaborate(self, _platform: object) -> Module:
        m = Module()
        sync, comb = m.d.sync, m.d.comb
        f, words = self.frame, self.words
        reg_bits = self.tables.register_bits
        # The shift register: every frame's load sets all of it before it is shifted, latched or read as the
        # command word (the frame engine, reset with it, loads before it latches), so it needs no reset.
        register = Signal(reg_bits, reset_less=True)
        frame_bytes = Signal.like(self.data_bytes)  # the register's length, fixed when the frame is loaded
        comb += [
            f.shift_out.eq(Mux(self.chain, self.chain_bit, Mux(frame_bytes == 0, f.level, register[0]))),
            words.command.eq(register[:WORD_BITS]),
        ]
        shifted = Signal(reg_bits)
        for i in range(reg_bits):
            above = register[i + 1] if i + 1 < reg_bits else register[i]
            comb += shifted[i].eq(Mux(frame_bytes == (i + 1) // 8, f.level, above) if (i + 1) % 8 == 0 else above)

        id_word = Signal(WORD_BITS)
        comb += id_word.eq(self.id_register | words.status)
        # The optical status byte in place of the ID code when the master asked (OPT-50, OPT-51: wire.optical_status)
        none = (False,) * len(wire.MAU_WARNINGS)
        status = Const(wire.optical_status(none), BYTE_BITS)
        for i in range(len(none)):
            status |= Mux(self.optical_mau[i], wire.optical_status(tuple(k == i for k in range(len(none)))), 0)
        with m.If(self.optical_send):
            comb += id_word.eq(Cat(status, self.id_register[BYTE_BITS:]) | words.status)
        in_word = Signal(reg_bits)
        with m.Switch(self.io_map):
            for k, (in_pins, _) in enumerate(self.tables.io_maps):
                with m.Case(k):
                    comb += in_word.eq(Cat(*(self.mfp_in[p] if p is not None else Const(0) for p in in_pins)))
        with m.If(self.external):  # the IN bytes or word, cleared first by a watchdog reset at this clock
            comb += in_word.eq(Mux(words.watchdog_reset, 0, self.in_data))

        with m.If(f.load):
            sync += [
                frame_bytes.eq(Mux(f.load_id, WORD_BITS // 8, self.data_bytes)),
                register.eq(Mux(f.load_id, id_word, in_word)),
            ]
        with m.Elif(f.shift & (frame_bytes != 0)):
            sync += register.eq(shifted)

        comb += self.register.eq(register)
        mfp_out = self.mfp_out
        with m.If(words.watchdog_reset | f.clear):  # process data cleared (Table 3-13, 3.4.7)
            sync += mfp_out.eq(0)
        with m.If(f.latch), m.Switch(self.io_map):
            for k, (_, out_bits) in enumerate(self.tables.io_maps):
                with m.Case(k):
                    sync += mfp_out.eq(Cat(*(register[b] if b is not None else Const(0) for b in out_bits)))
        return m


class TransmitterRtl(wiring.Component):
    """Transmitter and repeater (block ``transmitter``).

    Each sample pushes the level it sends, which goes out on DO2 from ``forward_delay - cpb // 2`` clocks later for
    one bit period (``cpb``) or until the next one begins, so every bit is repeated
    :data:`supi3.interbus.wire.REPEATER_DELAY_BITS` after it began on DO1 (A10): the levels wait in the time-stamp
    queue of the counter telegram block (:class:`supi3.rtl.counter.LineQueue`, the same timing, M8). The ERR pair of
    the CNTR word is rewritten at the last stop bit (``tx``, :data:`TRANSMIT`, flipped) in the two levels pushed
    before it, which are still waiting (``_tx_waiting``).
    """

    def __init__(self, tables: CoreTables) -> None:
        self.tables = tables
        clocks = tables.clocks
        if sorted(e.rate for e in clocks) != list(range(len(clocks))):
            raise ValueError("the transmitter needs one clock entry per bit rate, by rate index")
        members: dict[str, object] = {
            "frame": In(TRANSMIT),
            "rate": In(range(max(e.rate for e in clocks) + 1)),
            "now": In(stamp_bits(_tx_timing(tables))),
            "do2": Out(1, init=wire.IDLE_LEVEL),
        }
        super().__init__(members)

    def elaborate(self, _platform: object) -> Module:
        m = Module()
        f = self.frame
        queue = LineQueue(m, push=f.push, value=f.level, rate=self.rate, timing=_tx_timing(self.tables),
                          slots=_tx_waiting(self.tables), idle=wire.IDLE_LEVEL, name="tx", now=self.now)  # fmt: skip
        with m.If(f.set_err):
            m.d.sync += [queue.values[1].eq(f.err), queue.values[2].eq(~f.err)]
        m.d.comb += self.do2.eq(queue.shown)
        return m


class OutputsRtl(wiring.Component):
    """Outputs and diagnostics (block ``outputs``): the chip registers behind the diagnostic pins.

    The /StatErr filter (200 ms, 3.6.2) and the peripheral fault PF, the layer-2 watchdog (Table 3-13) and WD, TE
    and the attention bit, "bus active", the processor alarm request (A18); the /ModAck and /ResReg pulse counters
    (loaded with the width at the edge that starts the pulse, the pin low while non-zero); the following device
    (Table 2-2, M5) and DI1; the diagnostic outputs of ``supi3.diagnostics`` (3.6.1, DG-1 to DG-8): the silent line
    and the line interrupt ahead (set by the receiver's ``idle_timeout`` unless ``counted``, DG-9; cleared when a
    cycle ends at the chip or the master's reset pattern comes), DIAG1/DIAG2 (BA/RD or FO1/FO2 by ``complete_diag``,
    Table 3-16), /ResReg low while the line is silent (RC, DG-4), IB_DIAG flashing from the free-running ``divider``
    (Table 3-18, M6, DG-1, DG-2), RD on DIAG2 the following device not recognised (DG-5: the same register that
    switches DI1), and a bus terminal module's ALARM, LD, E and FO3 on ``mfp_diag`` (Table 2-8). ``fo`` (the optical
    block's FO1..FO3), ``ld``, ``e`` and ``alarm`` are ``supi3.diagnostics.LedInputs``: ``fo`` is the optical
    block's (DG-7), ``ld``, ``e`` and ``alarm`` come from the bus terminal block; ``bk_attention``, the bus terminal
    block's waiting report, joins the attention bit. The MAU warnings of the optical block (``mau``) make the
    optical status byte's events and ATTN (``send_optical``, ``mau_sent``; OPT-50..OPT-53). The chip registers
    follow ``model.chip.Supi3``; the frame engine drives them through ``frame`` (:data:`MANAGEMENT`, flipped) and
    ``ended``, and ``words`` (:data:`WORDS`, flipped) gives the data path the management bits and the watchdog's
    reset and takes the command word.
    """

    def __init__(self, divider_bits: int) -> None:
        super().__init__({
            "frame": In(MANAGEMENT), "words": In(WORDS),
            "stat_err_n_s": In(1), "di2_s": In(1), "rbst_ext_s": In(1), "di2": In(1), "do2": In(1),
            "divider": In(divider_bits), "rbst_by_pin": In(1), "complete_diag": In(1),
            "expansion": In(1), "rate": In(range(len(BIT_RATES))),
            "local_bus": In(1), "bus_terminal": In(1), "idle_timeout": In(1), "counted": In(1), "ended": In(1),
            "fo": In(3), "ld": In(1), "e": In(1), "alarm": In(1), "bk_attention": In(1),
            "mau": In(len(wire.MAU_WARNINGS)), "optical_quiet": In(1),
            "send_alarm": Out(1), "di1": Out(1), "mod_ack_n": Out(1), "res_reg_n": Out(1), "diag1": Out(1),
            "diag2": Out(1), "ib_diag": Out(1), "mfp_diag": Out(MFP_PINS),
            "bus_active": Out(1), "line_silent": Out(1), "send_optical": Out(1),
            "mau_sent": Out(len(wire.MAU_WARNINGS)),
        })  # fmt: skip

    def elaborate(self, _platform: object) -> Module:
        m = Module()
        sync, comb = m.d.sync, m.d.comb
        f, words = self.frame, self.words
        stat = ~self.stat_err_n_s
        pf, wd, te, attention = Signal(), Signal(), Signal(), Signal()
        bus_active = self.bus_active
        next_present = Signal()

        # The model calls chip._advance at the start of every running clock: the /StatErr filter and the watchdog.
        # Both count ticks of the time base (M24: the free-running ``divider``'s low TIME_BASE_BITS all ones, every
        # 1.024 ms), one shared prescaler instead of a counter of clocks each (round 6).
        tick = self.divider[:TIME_BASE_BITS].all()
        # The ticks /StatErr has been low, counted up as an LFSR (lfsr.count_state) from 0 at its first low clock,
        # held at 0 while it is high (one gate a bit, no load, no end state); ``filtered`` is set at the tick that
        # reads the last count and stays while /StatErr stays low, so the LFSR may run on past its end (round 5).
        st_ticks = time_base_ticks(STATERR_FILTER_CLOCKS)
        st_width = count_width(st_ticks - 1)
        st_count = Signal(st_width, init=count_state(0, st_width))
        filtered = Signal()
        with m.If(~stat):
            sync += st_count.eq(count_state(0, st_width))
        with m.Elif(tick):
            sync += st_count.eq(next_state(st_count))
        sync += filtered.eq(stat & (filtered | (tick & (st_count == count_state(st_ticks - 1, st_width)))))
        module_error = stat & filtered

        timeouts = [t for t in WATCHDOG_CLOCKS if t is not None]
        wd_code = Signal(_WD_CODE_BITS, init=_WD_OFF)
        # The watchdog's ticks to its deadline as an LFSR (supi3.rtl.lfsr) that fires at the tick it reads the state
        # 1: loaded with the state ticks - 1 steps before it, stepping at every tick; read only while ``wd_active``
        # (no reset).
        wd_active = Signal()
        wd_count = Signal(max(min(TAPS), time_base_ticks(max(timeouts)).bit_length()), reset_less=True)
        fire = wd_active & tick & (wd_count == 1)
        with m.If(tick):
            sync += wd_count.eq(next_state(wd_count))

        def arm(code: Value) -> list[Value]:
            """The deadline for a watchdog code: clk + timeout, or none ("off")."""
            on = Array(Const(int(t is not None), 1) for t in WATCHDOG_CLOCKS)[code]
            width = len(wd_count)
            # "off" loads a don't-care (``wd_active`` is 0): code 1's value (codes 0b11 and 0b01), one term less
            loads = [before(time_base_ticks(t or timeouts[1]) - 1, width) for t in WATCHDOG_CLOCKS]
            count = Array(Const(load, width) for load in loads)[code]
            return [wd_active.eq(on), wd_count.eq(count)]

        # Pulse counters: loaded with the width at the edge that starts the pulse, the pin low while non-zero, so
        # low for exactly the width's clocks (Table 3-13: 375 ns = tables.RESREG_PULSE_CLOCKS; /ModAck M3).
        # Both count down as LFSRs (lfsr.down_state): loaded with constants, ``0`` when done.
        mod_width = max(min(TAPS), MODACK_PULSE_CLOCKS.bit_length())
        mod_ack = Signal(mod_width)
        res_width = max(min(TAPS), max(RESREG_PULSE_CLOCKS, _EXPANSION_PULSE_MAX).bit_length())
        res_reg = Signal(res_width)
        # 4 t0 with the register expansion (RX-5), per bit rate
        expansion_pulse = Array(Const(down_state(PULSE_T0 * clocks_per_bit(rate), res_width), res_width)
                                for rate in range(len(BIT_RATES)))[self.rate]  # fmt: skip
        sync += [mod_ack.eq(down_step(mod_ack)), res_reg.eq(down_step(res_reg))]
        # RC (DG-4): /ResReg is low while the incoming line is silent, too.
        line_silent, line_interrupt = self.line_silent, Signal()
        comb += [self.mod_ack_n.eq(mod_ack == 0), self.res_reg_n.eq((res_reg == 0) & ~line_silent)]

        # MAU warnings to the master (OPT-50..OPT-53; model.chip._optical_set, _optical_command, _optical_reset):
        # ``told`` what the master last read, ``events`` which changed since; a change of the optical block's ``mau``
        # at an edge out of its reset period (``optical_quiet``) is an event, seen here from the next clock on.
        warnings = len(wire.MAU_WARNINGS)
        told, events, mau_seen, quiet_seen = Signal(warnings), Signal(warnings), Signal(warnings), Signal()
        send_optical = self.send_optical
        pending = Mux(quiet_seen, 0, self.mau ^ mau_seen)
        events_now = events | pending
        sync += [mau_seen.eq(self.mau), quiet_seen.eq(self.optical_quiet), events.eq(events_now)]
        comb += self.mau_sent.eq(told ^ events_now)

        pf_now = pf | filtered
        wd_now = wd | fire
        attention_now = attention | (filtered & ~pf) | fire | (pending & ~events).any()
        sync += [pf.eq(pf_now), wd.eq(wd_now), attention.eq(attention_now)]
        with m.If(fire):  # the watchdog resets process data (Table 3-13); 4 t0 with the register expansion (RX-5)
            sync += [wd_active.eq(0),
                     res_reg.eq(Mux(self.expansion, expansion_pulse, down_state(RESREG_PULSE_CLOCKS, res_width)))]
        with m.If(f.clear & self.expansion):  # /ResReg on an INTERBUS reset with the register expansion (RX-5)
            sync += res_reg.eq(expansion_pulse)
        comb += words.watchdog_reset.eq(fire)

        # The following device (Table 2-2, M5)
        with m.If(self.rbst_by_pin):
            sync += next_present.eq(self.rbst_ext_s)
        with m.Elif(self.di2_s):
            sync += next_present.eq(1)

        with m.If(f.clear):  # chip.reset_at: watchdog off, WD and TE cleared (3.4.7, Table 3-13)
            sync += [
                wd_code.eq(_WD_OFF),
                wd_active.eq(0),
                wd.eq(0),
                te.eq(0),
                attention.eq(pf_now),
                bus_active.eq(0),
                self.send_alarm.eq(0),
                told.eq(0),
                events.eq(0),
                send_optical.eq(0),
            ]
        te_now = te | f.frame_error
        comb += [
            words.status.eq((pf_now << wire.MGMT_PF_BIT) | (wd_now << wire.MGMT_WD_BIT) | (te_now << wire.MGMT_TE_BIT)),
            f.attention.eq(attention_now | self.bk_attention),  # a BK's waiting report (BK-5, BK-8)
        ]
        with m.If(f.abandon):  # TE |= local error (Table 3-13)
            sync += te.eq(te_now)
        with m.If(f.latch_id):  # the command word (docs/interbus.md A9)
            command = words.command
            sync += self.send_alarm.eq(command[wire.CMD_ALARM_BIT])  # A18
            code = command[wire.CMD_WD_CODE_SHIFT :][:_WD_CODE_BITS]
            with m.If(command[wire.CMD_WD_SET_BIT]):
                sync += [wd_code.eq(code), *arm(code)]
            with m.If(command[wire.CMD_QUIT_BIT]):  # Quit Peripheral Error (3.6.2)
                sync += [pf.eq(module_error), mod_ack.eq(down_state(MODACK_PULSE_CLOCKS, mod_width))]
            # OPT-50, OPT-53: the status byte sent in this cycle is read; the next request; ATTN while an event waits
            told_next = Mux(send_optical, told ^ events_now, told)
            events_next = Mux(send_optical, self.mau ^ told_next, events_now)
            request = command[wire.CMD_OPTICAL_BIT] & ~command[wire.CMD_PCMD_BIT] & ~command[wire.CMD_ALARM_BIT]
            sync += [wd.eq(0), te.eq(0), attention.eq(events_next.any()), told.eq(told_next), events.eq(events_next),
                     send_optical.eq(request)]  # fmt: skip
        with m.If(f.latch_data):  # a valid data cycle: the bus is active, the watchdog restarted
            sync += [bus_active.eq(1), *arm(wd_code)]

        # The line is heard (chip._line_heard): a cycle ends at the chip, or the master's reset pattern comes; the
        # idle time-out (chip.line_timeout_at) comes after the frame it abandons, so it wins (DG-3, DG-4).
        heard = (f.clear & ~self.idle_timeout) | self.ended
        with m.If(heard):
            sync += [line_silent.eq(0), line_interrupt.eq(0)]
        with m.If(self.idle_timeout):
            sync += [line_silent.eq(1), line_interrupt.eq(self.local_bus & bus_active & ~self.counted)]  # DG-9

        very_fast, fast, slow = (IB_DIAG_DIVIDER_BITS[k] - 1 for k in ("very_fast", "fast", "slow"))
        mfp = Signal(MFP_PINS)
        for name, pin in BUS_TERMINAL_PINS.items():  # Table 2-8 (DG-6)
            comb += mfp[pin].eq(self.fo[2] if name == "fo3" else getattr(self, name))
        comb += [
            # The return line passes straight through when a device follows; the last device loops back (M5).
            self.di1.eq(Mux(next_present, self.di2, self.do2)),
            # Table 3-16: BA/RD with complete diagnostics, FO1/FO2 with limited diagnostics.
            self.diag1.eq(Mux(self.complete_diag, bus_active, self.fo[0])),
            self.diag2.eq(Mux(self.complete_diag, ~next_present, self.fo[1])),  # RD: no following device (DG-5)
            # Table 3-18 in the order of DG-1: line interrupt ahead (4 Hz), peripheral fault (2 Hz), bus not active
            # (0.5 Hz), else steady (M6, DG-2).
            self.ib_diag.eq(Mux(line_interrupt, ~self.divider[very_fast],
                                Mux(pf, ~self.divider[fast], Mux(bus_active, 1, ~self.divider[slow])))),
            self.mfp_diag.eq(Mux(self.bus_terminal, mfp, 0)),
        ]  # fmt: skip
        return m


def _tx_begins(entry: ClockEntry) -> int:
    """Clocks from a bit's push (its mid-bit sample, ``cpb // 2`` clocks into the bit on DO1) to its first clock on
    DO2, ``forward_delay`` after it began on DO1."""
    return entry.forward_delay - entry.clocks_per_bit // 2


def _tx_timing(tables: CoreTables) -> tuple[tuple[int, int], ...]:
    """The transmitter's :class:`~supi3.rtl.counter.LineQueue` timing: (``_tx_begins``, ``cpb``) by rate index."""
    return tuple((_tx_begins(e), e.clocks_per_bit) for e in sorted(tables.clocks, key=lambda e: e.rate))


def _tx_waiting(tables: CoreTables) -> int:
    """Transmitter levels pushed and not yet begun on DO2, at most.

    A bit goes out ``_tx_begins`` clocks after its sample; samples are at least ``cpb // 2 + 1`` clocks apart (a
    stop bit sampled mid-bit, then a start bit on the next clock). The ERR pair needs the two levels pushed before a
    stop bit to be waiting: they were pushed ``cpb`` and ``2 cpb`` clocks before it (one telegram's grid), and
    ``2 cpb + 1`` is less than ``_tx_begins`` at every bit rate (checked here). The model keeps more entries (eight).
    """
    most = 0
    for entry in tables.clocks:
        delay = _tx_begins(entry)
        if 2 * entry.clocks_per_bit + 1 >= delay:  # not begun, nor beginning at that clock
            raise ValueError("the ERR pair's levels must still be waiting when the last stop bit is sampled")
        spacing = entry.clocks_per_bit // 2 + 1
        most = max(most, (delay - 2) // spacing + 1)
    return max(most, 3)  # the ERR pair rewrites the two entries before the last stop bit


def verilog(variant: Variant | str = Variant.OPC) -> str:
    """The Verilog of :class:`Supi3Core` for ``variant``, top module ``supi3_core``."""
    text: str = amaranth_verilog.convert(Supi3Core(variant), name="supi3_core", emit_src=False)
    return text

"""The SUPI 3 chip core in Amaranth: the INTERBUS slave of :class:`supi3.model.pins.Supi3Pins`, pin for pin.

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
  began on DO1, with the ERR pair of the CNTR word settled at the last stop bit (docs/interbus.md, A7, A10).

µP modes: built with ``register_file=True`` (:class:`supi3.rtl.chip.Supi3Chip`), the core has the ports of the
register file's core side (:class:`supi3.rtl.upif.UpifBlock`): in Init-µP modes it takes the IN bytes, the ID
register and the processor alarm from it and strobes the latch, events, processor command, I/O access bit and
resets at the clocks the model calls :class:`~supi3.model.registers.RegisterFile`. Without it, and in SPI master and
bus terminal modes, the core sends IN data 0 and the straps' ID code, which is what the model does before software
acts.
"""

from __future__ import annotations

from itertools import pairwise
from typing import Final

from amaranth.back import verilog as amaranth_verilog
from amaranth.hdl import Array, Cat, Const, Elaboratable, EnableInserter, Module, Mux, ResetInserter, Signal, Value
from amaranth.lib import enum, wiring
from amaranth.lib.wiring import In, Out

from supi3.checks import check_bool
from supi3.config import Variant
from supi3.errors import ArgumentError
from supi3.interbus import wire
from supi3.model.chip import MODACK_PULSE_CLOCKS, STATERR_FILTER_CLOCKS, WATCHDOG_CLOCKS
from supi3.model.pins import (
    IB_DIAG_DIVIDER_BITS,
    IDLE_INPUTS,
    IDLE_TIMEOUT_CLOCKS,
    RESET_STRETCH_CLOCKS,
    SYNC_STAGES,
    Supi3Pins,
)
from supi3.regmap import INTERRUPT_SOURCES
from supi3.regmap.core import BYTE_BITS
from supi3.rtl.tables import (
    C_BITS,
    CLK_CONF_BITS,
    DIAG_CONF_BITS,
    EXPANSION_BITS,
    MFP_PINS,
    RF_BITS,
    ClockEntry,
    CoreTables,
    check_variant,
    core_tables,
)
from supi3.rtl.upif import upif_tables
from supi3.spi.block_pins import CORE_INPUTS, CORE_OUTPUTS, EVENT_BITS, STRAP_INPUTS
from supi3.tables import RESREG_PULSE_CLOCKS
from supi3.verif.pinmodel import Pin

__all__ = ["REGISTER_FILE_INPUTS", "REGISTER_FILE_OUTPUTS", "STRAP_PINS", "Supi3Core", "verilog"]

STRAP_PINS: Final = (Pin("c", C_BITS), Pin("rf", RF_BITS), Pin("clk_conf", CLK_CONF_BITS),
                     Pin("diag_conf", DIAG_CONF_BITS))  # fmt: skip
"""The strap input ports, beyond the model's pins (Tables 2-2, 2-4 to 2-7, 1-7, 3-16)."""

REGISTER_FILE_INPUTS: Final = tuple(pin for pin in CORE_OUTPUTS if pin.name in ("in_data", "bus_id", "alarm"))
"""What the core takes from the register file (:class:`supi3.rtl.upif.UpifBlock`'s outputs of the same names)."""
REGISTER_FILE_OUTPUTS: Final = (
    *STRAP_INPUTS,
    *(pin for pin in CORE_INPUTS
      if pin.name in ("power_up", "ib_reset", "events", "io_access", "latch", "latch_out", "pcmd_we", "pcmd")),
)  # fmt: skip
"""What the core gives the register file (the block's inputs of the same names; the optical ones stay 0)."""

WORD_BITS: Final = 8 * len(wire.word_bytes(0))
"""16-bit words: ID register, command word, CRC, CNTR (docs/interbus.md A4)."""

_DATA_TELEGRAM_END: Final = wire.DATA_TELEGRAM_BITS - 1
_STATUS_TELEGRAM_END: Final = wire.STATUS_TELEGRAM_BITS - 1
_WD_OFF: Final = WATCHDOG_CLOCKS.index(None)
"""The watchdog code that stands for "off"; also the state after an INTERBUS reset (no code set)."""
_WD_CODE_BITS: Final = (len(WATCHDOG_CLOCKS) - 1).bit_length()
_SOURCE_BIT: Final = {source.name: source.bit for source in INTERRUPT_SOURCES}
"""The ``events`` bit of each interrupt source (Table 3-13)."""


def _width(value: int) -> int:
    return max(1, value.bit_length())


class _State(enum.Enum):
    """Frame engine states of the model (``_state``)."""

    IDLE = 0
    DATA = 1
    CHECK = 2
    WAIT = 3


def _crc_step(crc: Value, bit: Value) -> Value:
    """One step of ``wire.crc_update_bit``: shift the 16-bit register left, feed back the polynomial."""
    feedback = crc[WORD_BITS - 1] ^ bit
    return (crc << 1)[:WORD_BITS] ^ Mux(feedback, wire.CRC_POLY, 0)


def _crc_word(crc: Value) -> Value:
    """The CRC word a register stands for (``wire.crc16``'s output stage: reflection and final XOR)."""
    word = Cat(*reversed([crc[i] for i in range(WORD_BITS)])) if wire.CRC_REFOUT else crc
    return word ^ wire.CRC_XOROUT


class Supi3Core(wiring.Component):
    """The SUPI 3 chip core with the pins of :class:`~supi3.model.pins.Supi3Pins` and the strap ports.

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
        for pin in (*Supi3Pins.inputs, *STRAP_PINS, *(REGISTER_FILE_INPUTS if register_file else ())):
            members[pin.name] = In(pin.width)
        for pin in (*Supi3Pins.outputs, *((*REGISTER_FILE_OUTPUTS, Pin("init_up")) if register_file else ())):
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
        rate = Signal(range(max(e.rate for e in tables.clocks) + 1))
        io_map = Signal(range(len(tables.io_maps)))
        clocks = tables.clocks
        cpb = Signal(range(max(e.clocks_per_bit for e in clocks) + 1))
        reset_run = Signal(range(max(e.reset_run for e in clocks) + 1))
        tx_countdown = max(e.forward_delay + e.clocks_per_bit // 2 - 1 for e in clocks)
        tx_init = Signal(range(tx_countdown + 1))
        dclk = Signal()
        rbst_by_pin = Signal()
        complete_diag = Signal()
        maps = tables.io_maps
        with m.Switch(Cat(self.mfp_in[MFP_PINS - EXPANSION_BITS :], self.c)):
            for mode in tables.modes:
                with m.Case(mode.pattern):
                    m.d.comb += [
                        strap_id.eq(mode.id_register),
                        strap_bytes.eq(mode.data_bytes),
                        init_up.eq(mode.init_up),
                        io_map.eq(maps.index(mode.io_map)),
                        self.mfp_oe.eq(mode.mfp_oe),
                    ]
        cycle = Signal(max(*IB_DIAG_DIVIDER_BITS.values(), *(_width(e.clocks_per_bit) for e in clocks)))
        m.d.sync += cycle.eq(cycle + 1)

        def clock(entry: ClockEntry) -> list[Value]:
            cpb_bits = entry.clocks_per_bit.bit_length() - 1
            if entry.clocks_per_bit != 1 << cpb_bits:
                raise ValueError(f"DCLK_OUT needs a power-of-two bit period, not {entry.clocks_per_bit}")
            return [
                rate.eq(entry.rate),
                cpb.eq(entry.clocks_per_bit),
                reset_run.eq(entry.reset_run),
                tx_init.eq(entry.forward_delay + entry.clocks_per_bit // 2 - 1),
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

        # Synchronisers (M1) and the power-up reset with its stretch (1.7.2, M2) -------------------------------------
        synced: dict[str, Value] = {}
        for pin, idle in zip(Supi3Pins.inputs, IDLE_INPUTS, strict=True):
            stages = [Signal(pin.width, init=idle, name=f"{pin.name}_s{k}") for k in range(SYNC_STAGES)]
            m.d.sync += [stages[0].eq(getattr(self, pin.name)), *(b.eq(a) for a, b in pairwise(stages))]
            synced[pin.name] = stages[-1]
        power_fail = ~(synced["resu_n"] & synced["vmon_ok"])
        holding = Signal()
        stretch = Signal(range(RESET_STRETCH_CLOCKS + 1), init=RESET_STRETCH_CLOCKS)
        with m.If(power_fail):
            m.d.sync += holding.eq(1)
        with m.Elif(holding):
            m.d.sync += [holding.eq(0), stretch.eq(RESET_STRETCH_CLOCKS - 1)]
        with m.Elif(stretch != 0):
            m.d.sync += stretch.eq(stretch - 1)
        running = ~power_fail & ~holding & (stretch == 0)

        # Init-µP modes: the ID register, the data length and the IN data from the register file (docs/upif.md)
        id_register = Signal(WORD_BITS)
        data_bytes = Signal.like(strap_bytes)
        up = self.register_file
        in_data = self.in_data if up else Const(0, tables.register_bits)
        engine = _Engine(
            tables,
            id_register=id_register,
            data_bytes=data_bytes,
            init_up=init_up if up else Const(0),
            in_data=in_data,
            io_map=io_map,
            cpb=cpb,
            reset_run=reset_run,
            tx_init=tx_init,
            rbst_by_pin=rbst_by_pin,
            synced=synced,
        )
        m.submodules.engine = ResetInserter(power_fail)(EnableInserter(running)(engine))
        m.d.comb += [id_register.eq(strap_id), data_bytes.eq(strap_bytes)]
        if up:
            up_bytes = Signal.like(strap_bytes)
            with m.Switch(self.bus_id[BYTE_BITS:]):  # the length code (Table 3-11) as the register file applies it
                for code, count in upif_tables().internal_bytes.items():
                    with m.Case(code):
                        m.d.comb += up_bytes.eq(count)
            with m.If(init_up):
                # A18: the processor alarm in place of the ID code when the master asked for it
                up_id = Mux(engine.send_alarm, self.alarm, self.bus_id[:BYTE_BITS])
                m.d.comb += [id_register.eq(Cat(up_id, self.bus_id[BYTE_BITS:])), data_bytes.eq(up_bytes)]
            m.d.comb += [
                self.init_up.eq(init_up),
                self.rate.eq(rate),
                Cat(self.np_id, self.np_length).eq(strap_id),
                self.power_up.eq(~init_up | power_fail | self.resu_drive),
                self.ib_reset.eq(running & engine.ib_reset),
                self.events.eq(Mux(running, engine.events, 0)),
                self.io_access.eq(Mux(running, engine.io_set | (engine.io & ~engine.io_clear), engine.io)),
                self.latch.eq(running & engine.latch),
                self.latch_out.eq(engine.register),
                self.pcmd_we.eq(running & engine.pcmd_we),
                self.pcmd.eq(engine.pcmd),
            ]

        pf, bus_active = engine.pf, engine.bus_active
        fast, slow = (IB_DIAG_DIVIDER_BITS[k] - 1 for k in ("fast", "slow"))
        m.d.comb += [
            self.do2.eq(engine.do2),
            # The return line passes straight through when a device follows; the last device loops back (M5).
            self.di1.eq(Mux(engine.next_present, self.di2, engine.do2)),
            self.mfp_out.eq(engine.mfp_out),
            self.mod_ack_n.eq(engine.mod_ack_n),
            self.res_reg_n.eq(engine.res_reg_n),
            self.diag1.eq(complete_diag & bus_active),
            self.diag2.eq(0),
            # Table 3-18: fast flashing on a peripheral fault, slow while the bus is not active (M6).
            self.ib_diag.eq(Mux(pf, ~cycle[fast], Mux(bus_active, 1, ~cycle[slow]))),
            self.dclk_out.eq(dclk),
            self.resu_drive.eq(holding | (stretch != 0)),
        ]
        return m


class _Engine(Elaboratable):
    """Everything the model's power-up reset clears: time, receiver, frame engine, chip registers, transmitter.

    It runs only on the clocks where the model's ``_tick`` runs its logic; :class:`Supi3Core` inserts the enable and
    the power-up reset. The chip registers follow :class:`supi3.model.chip.Supi3`; the order of the statements
    follows the model's order within one clock, later assignments winning as later Python assignments do.

    In Init-µP modes (``init_up``) the IN data come from ``in_data``; the strobes ``latch``, ``pcmd_we``,
    ``events``, ``ib_reset``, ``io_set`` and ``io_clear`` mark the clocks at which the model calls its register
    file (:class:`Supi3Core` gates them with the enable).
    """

    def __init__(
        self,
        tables: CoreTables,
        *,
        id_register: Value,
        data_bytes: Value,
        init_up: Value,
        in_data: Value,
        io_map: Value,
        cpb: Value,
        reset_run: Value,
        tx_init: Value,
        rbst_by_pin: Value,
        synced: dict[str, Value],
    ) -> None:
        self.tables = tables
        self.id_register = id_register
        self.data_bytes = data_bytes
        self.init_up = init_up
        self.in_data = in_data
        self.io_map = io_map
        self.cpb = cpb
        self.reset_run = reset_run
        self.tx_init = tx_init
        self.rbst_by_pin = rbst_by_pin
        self.synced = synced
        self.do2 = Signal(init=wire.IDLE_LEVEL)
        self.next_present = Signal()
        self.mfp_out = Signal(MFP_PINS)
        self.mod_ack_n = Signal()
        self.res_reg_n = Signal()
        self.pf = Signal()
        self.bus_active = Signal()
        self.register = Signal(tables.register_bits)
        self.send_alarm = Signal()
        self.io = Signal()
        self.io_set = Signal()
        self.io_clear = Signal()
        self.latch = Signal()
        self.pcmd_we = Signal()
        self.pcmd = Signal(BYTE_BITS)
        self.events = Signal(EVENT_BITS)
        self.ib_reset = Signal()

    def elaborate(self, _platform: object) -> Module:
        m = Module()
        sync, comb = m.d.sync, m.d.comb
        s = self.synced
        line = s["do1"]
        stat = ~s["stat_err_n"]
        tables = self.tables
        reg_bits = tables.register_bits

        # Chip registers (supi3.model.chip.Supi3) ------------------------------------------------------------------
        pf, bus_active = self.pf, self.bus_active
        wd, te, attention = Signal(), Signal(), Signal()
        mfp_out = self.mfp_out

        # The model calls chip._advance at the start of every running clock: the /StatErr filter and the watchdog.
        st_valid = Signal()
        st_count = Signal(range(STATERR_FILTER_CLOCKS + 1))
        filtered = st_valid & (st_count == STATERR_FILTER_CLOCKS)
        sync += st_valid.eq(stat)
        with m.If(stat & ~st_valid):
            sync += st_count.eq(1)  # low since this clock: one clock old at the next
        with m.Elif(stat & (st_count != STATERR_FILTER_CLOCKS)):
            sync += st_count.eq(st_count + 1)
        module_error = stat & filtered

        timeouts = [t for t in WATCHDOG_CLOCKS if t is not None]
        wd_code = Signal(_WD_CODE_BITS, init=_WD_OFF)
        wd_active = Signal()
        wd_count = Signal(range(max(timeouts)))
        fire = wd_active & (wd_count == 0)
        with m.If(wd_active):
            sync += wd_count.eq(wd_count - 1)

        def arm(code: Value) -> list[Value]:
            """The deadline for a watchdog code: clk + timeout, or none ("off")."""
            on = Array(Const(int(t is not None), 1) for t in WATCHDOG_CLOCKS)[code]
            count = Array(Const(max(t or 1, 1) - 1, len(wd_count)) for t in WATCHDOG_CLOCKS)[code]
            return [wd_active.eq(on), wd_count.eq(count)]

        # Pulse counters: loaded with the width at the edge that starts the pulse, the pin low while non-zero, so
        # low for exactly the width's clocks (Table 3-13: 375 ns = tables.RESREG_PULSE_CLOCKS; /ModAck M3).
        mod_ack = Signal(range(MODACK_PULSE_CLOCKS + 1))
        res_reg = Signal(range(RESREG_PULSE_CLOCKS + 1))
        with m.If(mod_ack != 0):
            sync += mod_ack.eq(mod_ack - 1)
        with m.If(res_reg != 0):
            sync += res_reg.eq(res_reg - 1)
        comb += [self.mod_ack_n.eq(mod_ack == 0), self.res_reg_n.eq(res_reg == 0)]

        pf_now = pf | filtered
        wd_now = wd | fire
        attention_now = attention | (filtered & ~pf) | fire
        sync += [pf.eq(pf_now), wd.eq(wd_now), attention.eq(attention_now)]
        events = self.events

        def event(source: str) -> Value:
            return events[_SOURCE_BIT[source]].eq(1)

        with m.If(fire):  # the watchdog resets process data (Table 3-13)
            sync += [wd_active.eq(0), mfp_out.eq(0), res_reg.eq(RESREG_PULSE_CLOCKS)]
            comb += [self.ib_reset.eq(1), event("IB_RESET")]

        # The following device (Table 2-2, M5)
        with m.If(self.rbst_by_pin):
            sync += self.next_present.eq(s["rbst_ext"])
        with m.Elif(s["di2"]):
            sync += self.next_present.eq(1)

        # Receiver: INTERBUS reset, idle time-out (docs/interbus.md A12, A13) ------------------------------------
        state = Signal(_State)
        latches = Signal(range(wire.LATCH_STATUS_TELEGRAMS + 1))
        in_reset = Signal()
        reset_end = Signal(range(wire.RESET_END_STATUS_TELEGRAMS + 1))
        low_run = Signal.like(self.reset_run)
        silent = Signal(range(IDLE_TIMEOUT_CLOCKS + 2), init=1)  # clocks since the last telegram start
        low = line == wire.START_LEVEL
        enter_reset = low & (low_run + 1 == self.reset_run)
        idle_timeout = silent == IDLE_TIMEOUT_CLOCKS  # once per silence: the count stops one beyond
        with m.If(~low):
            sync += low_run.eq(0)
        with m.Elif(low_run != self.reset_run):
            sync += low_run.eq(low_run + 1)
        with m.If(silent != IDLE_TIMEOUT_CLOCKS + 1):
            sync += silent.eq(silent + 1)

        def chip_reset() -> list[Value]:
            """chip.reset_at: process data cleared, watchdog off, WD and TE cleared (3.4.7, Table 3-13)."""
            return [
                mfp_out.eq(0),
                wd_code.eq(_WD_OFF),
                wd_active.eq(0),
                wd.eq(0),
                te.eq(0),
                attention.eq(pf_now),
                bus_active.eq(0),
                self.send_alarm.eq(0),
            ]

        discard = Signal()  # a frame ends unlatched (chip.discard_at): the invalid-data-cycle event
        io = self.io
        sync += io.eq(self.io_set | (io & ~self.io_clear))

        with m.If(enter_reset):
            sync += [in_reset.eq(1), reset_end.eq(0), state.eq(_State.IDLE), latches.eq(0), *chip_reset()]
            comb += [self.ib_reset.eq(1), self.io_clear.eq(1)]
        with m.If(idle_timeout):
            # A frame abandoned here raises TE, which the INTERBUS reset clears again at once.
            sync += [state.eq(_State.IDLE), latches.eq(0), *chip_reset()]
            comb += [self.ib_reset.eq(1), self.io_clear.eq(1), discard.eq(state != _State.IDLE)]
        in_reset_now = in_reset | enter_reset

        # Receiver: framing and mid-bit sampling ------------------------------------------------------------------
        rx_busy = Signal()
        phase = Signal.like(self.cpb)  # clocks since the start bit began, modulo the bit period
        bit = Signal(range(wire.DATA_TELEGRAM_BITS + 1))
        select = Signal()
        control = Signal()
        is_data = Signal(init=1)
        start = ~rx_busy & low
        sample = rx_busy & (phase == self.cpb // 2)
        with m.If(start):
            sync += [rx_busy.eq(1), phase.eq(1), bit.eq(0), is_data.eq(1), silent.eq(1)]
        with m.Elif(rx_busy):
            sync += phase.eq(Mux(phase == self.cpb - 1, 0, phase + 1))
        data_now = Mux(bit == wire.POS_TYPE, line == wire.TYPE_DATA_LEVEL, is_data)
        end = bit == Mux(data_now, _DATA_TELEGRAM_END, _STATUS_TELEGRAM_END)
        frame_bit = sample & data_now & ~in_reset_now
        data_field = (bit >= wire.POS_DATA) & (bit < wire.POS_DATA + 8)
        j = (bit - wire.POS_DATA)[:3]
        out = Signal()  # the level this sample sends on
        comb += out.eq(line)
        with m.If(sample):
            sync += [bit.eq(bit + 1), is_data.eq(data_now)]
            with m.If(bit == wire.POS_SELECT):
                sync += select.eq(line)
            with m.If(bit == wire.POS_CONTROL):
                sync += control.eq(line)
            with m.If(end):
                sync += rx_busy.eq(0)

        # Frame engine --------------------------------------------------------------------------------------------
        id_cycle = Signal()  # the frame's cycle type: 1 = ID cycle
        register = self.register
        frame_bytes = Signal.like(self.data_bytes)  # the register's length, fixed when the frame is loaded
        crc_rx = Signal(WORD_BITS, init=wire.CRC_INIT)
        crc_tx = Signal(WORD_BITS, init=wire.CRC_INIT)
        index = Signal(range(wire.CHECK_TELEGRAMS + 2))
        local_error = Signal()
        err_in = Signal()
        attn = Signal()
        crc_bad = Signal()
        cntr_bad = Signal()
        err_bit = Signal()
        pairs = [
            tuple(sorted(p))
            for p in ((wire.CNTR_ATTN_BIT, wire.CNTR_NATTN_BIT), (wire.CNTR_NERR_BIT, wire.CNTR_ERR_BIT))
        ]
        firsts = [Signal(name=f"cntr_pair{k}") for k in range(len(pairs))]
        paired = {b for p in pairs for b in p}
        if (wire.CNTR_NERR_BIT, wire.CNTR_ERR_BIT) != (
            WORD_BITS - 2,
            WORD_BITS - 1,
        ) or wire.CNTR_ATTN_BIT > wire.CNTR_NATTN_BIT:
            raise ValueError("the model settles the ERR pair as the last two CNTR bits, after ATTN and /ATTN")

        register_bytes = frame_bytes
        shift_out = Mux(register_bytes == 0, line, register[0])
        shifted = Signal(reg_bits)
        for i in range(reg_bits):
            above = register[i + 1] if i + 1 < reg_bits else register[i]
            comb += shifted[i].eq(Mux(register_bytes == (i + 1) // 8, line, above) if (i + 1) % 8 == 0 else above)

        def error() -> Value:
            return local_error.eq(1)

        def abandon() -> list[Value]:
            """A frame ends unlatched: invalid cycle, TE |= local error (Table 3-13)."""
            m.d.comb += [discard.eq(state != _State.IDLE), self.io_clear.eq(1)]
            return [state.eq(_State.IDLE), latches.eq(0), te.eq(te | ((state != _State.IDLE) & local_error))]

        te_now = te | ((state != _State.IDLE) & local_error)
        id_word = Signal(WORD_BITS)
        comb += id_word.eq(
            self.id_register
            | (pf_now << wire.MGMT_PF_BIT)
            | (wd_now << wire.MGMT_WD_BIT)
            | (te_now << wire.MGMT_TE_BIT)
        )
        in_word = Signal(reg_bits)
        mfp_s = s["mfp_in"]
        with m.Switch(self.io_map):
            for k, (in_pins, _) in enumerate(tables.io_maps):
                with m.Case(k):
                    comb += in_word.eq(Cat(*(mfp_s[p] if p is not None else Const(0) for p in in_pins)))
        with m.If(self.init_up):  # the IN bytes, cleared first by a watchdog reset at this clock
            comb += in_word.eq(Mux(fire, 0, self.in_data))

        check_n = Cat(j, index[:2])  # bit of the check sequence, line order
        cntr_b = check_n[:4]
        with m.If(frame_bit & (bit == wire.POS_CONTROL)):
            cycle_id = select == wire.SELECT_ID_LEVEL
            check = line == wire.CONTROL_CHECK_LEVEL
            with m.If(~check & (state != _State.DATA)):
                sync += [
                    *abandon(),
                    state.eq(_State.DATA),
                    id_cycle.eq(cycle_id),
                    frame_bytes.eq(Mux(cycle_id, WORD_BITS // 8, self.data_bytes)),
                    register.eq(Mux(cycle_id, id_word, in_word)),
                    crc_rx.eq(wire.CRC_INIT),
                    crc_tx.eq(wire.CRC_INIT),
                    local_error.eq(0),
                    err_in.eq(0),
                    latches.eq(0),
                ]
            with m.Elif(cycle_id != id_cycle):
                sync += error()
            with m.If(check):
                with m.If(state == _State.DATA):
                    sync += [state.eq(_State.CHECK), index.eq(0), crc_bad.eq(0), cntr_bad.eq(0)]
                    comb += self.io_set.eq(~id_cycle)  # the I/O access window of a data cycle (Fig. 3-22)
                with m.Elif(state == _State.CHECK):
                    sync += index.eq(index + 1)
                with m.If(~((state == _State.DATA) | ((state == _State.CHECK) & (index + 1 < wire.CHECK_TELEGRAMS)))):
                    sync += error()
        with m.Elif(frame_bit & data_field & (state == _State.DATA)):
            comb += out.eq(shift_out)
            sync += [crc_rx.eq(_crc_step(crc_rx, line)), crc_tx.eq(_crc_step(crc_tx, shift_out))]
            with m.If(register_bytes != 0):
                sync += register.eq(shifted)
        with m.Elif(frame_bit & data_field & (state == _State.CHECK) & (index < wire.CHECK_TELEGRAMS)):
            with m.If(check_n < WORD_BITS):  # own CRC word out, the received one compared
                comb += out.eq(_crc_word(crc_tx).bit_select(check_n[:4], 1))
                with m.If(line != _crc_word(crc_rx).bit_select(check_n[:4], 1)):
                    sync += crc_bad.eq(1)
            with m.Else():  # CNTR forwarded (wire.forward_cntr); the ERR pair is settled at the last stop bit
                comb += out.eq(0)
                with m.Switch(cntr_b):
                    for b in range(WORD_BITS):
                        with m.Case(b):
                            if b == wire.CNTR_ATTN_BIT:
                                comb += out.eq(line | attention_now)
                                sync += attn.eq(line | attention_now)
                            elif b == wire.CNTR_NATTN_BIT:
                                comb += out.eq(~attn)
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

        # Transmitter: (countdown to the end of the bit period, level), newest first -------------------------------
        slots = _tx_slots(tables)
        width = len(self.tx_init)
        countdown = [Signal(width, name=f"tx{k}_count") for k in range(slots)]
        level = [Signal(name=f"tx{k}_level") for k in range(slots)]
        for r in countdown:
            with m.If(r != 0):
                sync += r.eq(r - 1)
        with m.If(sample):
            sync += [countdown[0].eq(self.tx_init), level[0].eq(out)]
            for k in range(1, slots):
                sync += [
                    countdown[k].eq(Mux(countdown[k - 1] != 0, countdown[k - 1] - 1, 0)),
                    level[k].eq(level[k - 1]),
                ]
        do2 = Const(wire.IDLE_LEVEL)
        for r, v in reversed(list(zip(countdown, level, strict=True))):
            do2 = Mux(r <= self.cpb, Mux(r != 0, v, wire.IDLE_LEVEL), do2)
        comb += self.do2.eq(do2)

        # Telegram end: check sequence, INTERBUS reset end, latch (docs/interbus.md "Cycle end") ---------------------
        stop_bad = line != wire.STOP_LEVEL
        with m.If(sample & end):
            with m.If(stop_bad):
                sync += error()
            with m.If((state == _State.CHECK) & (index == wire.CHECK_TELEGRAMS - 1) & data_now & ~in_reset_now):
                error_now = local_error | stop_bad | crc_bad | cntr_bad
                err = error_now | cntr_bad | err_bit
                sync += [
                    local_error.eq(error_now),
                    err_in.eq(cntr_bad | err_bit),
                    state.eq(_State.WAIT),
                    level[1].eq(err),
                    level[2].eq(~err),
                ]
            with m.If(~stop_bad & ~data_now):
                with m.If(in_reset_now):
                    sync += reset_end.eq(reset_end + 1)
                    with m.If(reset_end + 1 == wire.RESET_END_STATUS_TELEGRAMS):
                        sync += in_reset.eq(0)
                with m.Elif((state == _State.DATA) | (state == _State.CHECK)):
                    sync += error()
                with m.Elif(state == _State.WAIT):
                    latched = Mux(control == wire.CONTROL_CHECK_LEVEL, latches + 1, 0)
                    sync += latches.eq(latched)
                    with m.If((latched == wire.LATCH_STATUS_TELEGRAMS) & (local_error | err_in)):
                        sync += abandon()
                    with m.Elif(latched == wire.LATCH_STATUS_TELEGRAMS):  # chip.latch_at
                        sync += [state.eq(_State.IDLE), latches.eq(0)]
                        comb += [self.io_clear.eq(1), event("PCP_TX")]
                        with m.If(id_cycle):  # the command word (docs/interbus.md A9)
                            command = register[:WORD_BITS]
                            sync += self.send_alarm.eq(command[wire.CMD_ALARM_BIT])  # A18
                            comb += [
                                self.pcmd_we.eq(command[wire.CMD_PCMD_BIT]),
                                self.pcmd.eq(command[wire.CMD_PCMD_SHIFT :][:BYTE_BITS]),
                                event("ID_CYCLE"),
                            ]
                            code = command[wire.CMD_WD_CODE_SHIFT :][:_WD_CODE_BITS]
                            with m.If(command[wire.CMD_WD_SET_BIT]):
                                sync += [wd_code.eq(code), *arm(code)]
                            with m.If(command[wire.CMD_QUIT_BIT]):  # Quit Peripheral Error (3.6.2)
                                sync += [pf.eq(module_error), mod_ack.eq(MODACK_PULSE_CLOCKS)]
                            sync += [wd.eq(0), te.eq(0), attention.eq(0)]
                        with m.Else():  # OUT data to the MFPs (Tables 3-1, 3-2), watchdog restarted
                            sync += [bus_active.eq(1), *arm(wd_code)]
                            comb += [self.latch.eq(1), event("VALID"), event("PCP_RX")]
                            with m.Switch(self.io_map):
                                for k, (_, out_bits) in enumerate(tables.io_maps):
                                    with m.Case(k):
                                        sync += mfp_out.eq(
                                            Cat(*(register[b] if b is not None else Const(0) for b in out_bits))
                                        )
        comb += events[_SOURCE_BIT["INVALID"]].eq(discard & ~id_cycle)
        return m


def _tx_slots(tables: CoreTables) -> int:
    """Transmitter entries needed: every bit not yet begun on DO2 plus the one being sent.

    A bit goes out ``forward_delay - cpb // 2`` clocks after its sample; samples are at least ``cpb // 2 + 1``
    clocks apart (a stop bit sampled mid-bit, then a start bit on the next clock). The model keeps more entries
    (eight); the older ones can no longer be on the line.
    """
    most = 0
    for entry in tables.clocks:
        delay = entry.forward_delay - entry.clocks_per_bit // 2
        spacing = entry.clocks_per_bit // 2 + 1
        most = max(most, (delay - 2) // spacing + 1)
    return max(most + 1, 3)  # the ERR pair rewrites the two entries before the last stop bit


def verilog(variant: Variant | str = Variant.OPC) -> str:
    """The Verilog of :class:`Supi3Core` for ``variant``, top module ``supi3_core``."""
    text: str = amaranth_verilog.convert(Supi3Core(variant), name="supi3_core", emit_src=False)
    return text

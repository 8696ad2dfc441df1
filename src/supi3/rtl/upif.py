"""The serial µP interface of the SUPI 3 OPC in Amaranth: SPI slave / Intel synchronous serial and register file.

Ref: IBS SUPI 3 OPC UM E rev. 05, 3.4 to 3.4.14, Tables 3-5 to 3-13; ``docs/upif.md`` ("Pin level: cycle-exact
specification" and "RTL"). The block matches the model ``spi.block_pins.UpifBlockPins`` (that is,
``spi.slave_pins.SlavePins``, ``spi.upif.UpifProtocol`` and ``model.registers.RegisterFile``) on every port on
every 32 MHz clock. Its ports are declared in :mod:`supi3.pinout` (:data:`~supi3.pinout.UP_BLOCK_INPUTS`,
:data:`~supi3.pinout.UP_BLOCK_OUTPUTS`), as are the model's: the µP pins, the straps (bit rate, µP_Not_Ready
code) and the register file's core interface.

Nothing is typed in: register addresses, access kinds, masks, reset values and reset classes come from
:data:`supi3.regmap.REGISTER_MAP`; the SET decoding is tabulated from :func:`supi3.regmap.decode_set`; the output
delay per bit rate comes from TCLK (Table 3-7, UP-14) and the outputs after reset are the decode of the reset state.
Nothing is read off the model (``tests/test_rtl_tables.py`` compares).

One clock edge does what the model does between two ticks, in the same order (UP-13, UP-14, ``docs/upif.md``):

1. the core's inputs update the registers (latch, processor command, events, INTERBUS reset); reads 8 to 11 are
   the optical block's ``optical`` port itself (UP-39);
2. the µP pins act on the synchronised edges: SAS_INIT, /SS falling (``begin``: the byte to send, reads and their
   side effects), SCLK rising (shift in), /SS rising (``end``: the received byte, writes);
3. the outputs are decoded from the new state and delayed by the bit rate's output pipeline.

``power_up`` resets everything at the edge, like the ``sync`` reset.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from typing import Final

from amaranth.back import verilog as amaranth_verilog
from amaranth.hdl import Array, Cat, Const, Elaboratable, Module, Mux, ResetInserter, Signal, Value
from amaranth.lib import enum, wiring
from amaranth.lib.wiring import In, Out

from supi3 import timing
from supi3.pinlevel import OE_SUFFIX
from supi3.pinout import (
    C_D_COMMAND,
    C_D_DATA,
    DATA_BYTES,
    OPTICAL_REGISTERS,
    SYNC_STAGES,
    UP_BLOCK_INPUTS,
    UP_BLOCK_OUTPUTS,
    UP_INPUT_IDLE,
)
from supi3.regmap import (
    COMMAND_BYTE,
    INIT_BYTE,
    INTERRUPT_SOURCES,
    REGISTER_MAP,
    Access,
    AccessDirection,
    RegisterMapError,
    Reset,
    decode_set,
)
from supi3.regmap.core import BYTE_BITS, BYTE_MASK
from supi3.regmap.registers import IN_BYTES, IO_ACCESS_BIT, OUT_BYTES
from supi3.tables import BIT_RATES, CLOCK_HZ, LENGTH_CODE_BY_VALUE, UP_INTERFACE_TIMING

__all__ = ["UpifBlock", "UpifTables", "output_delay", "upif_tables", "verilog"]

_SET = REGISTER_MAP.register("SET")
_LENGTH_CODE = _SET.field("LENGTH_CODE")
_EXTREG = _SET.field("EXTREG")
_PCP_N = _SET.field("PCP_N")
_RD = COMMAND_BYTE.field("RD")
_WR = COMMAND_BYTE.field("WR")
_ADDRESS = COMMAND_BYTE.field("A")
_READ_PORTS: Final = {a: REGISTER_MAP.port(a, AccessDirection.READ) for a in REGISTER_MAP.addresses}
_WRITE_PORTS: Final = {a: REGISTER_MAP.port(a, AccessDirection.WRITE) for a in REGISTER_MAP.addresses}
_BLOCK_ADDRESSES: Final = tuple(a for a, port in _WRITE_PORTS.items() if port.access is Access.BLOCK_TRANSFER)
"""A3..0 that start a block transfer (3.4.6: 15)."""
_IRQ_EVT = REGISTER_MAP.register("IRQ_EVT")
_IRQ_EN = REGISTER_MAP.register("IRQ_EN")
_SOURCE_BIT: Final[dict[str, int]] = {source.name: source.bit for source in INTERRUPT_SOURCES}
_PCP_ERASED: Final[tuple[int, ...]] = (0, 1)
"""IN bytes erased after their transfer in a PCP device (3.4.11; ``RegisterFile.latch``)."""
_BIT_COUNT_LIMIT: Final[int] = BYTE_BITS + 1
"""The SCLK edge counter saturates here: the model only asks for 8, below 8, and more than 8 (3.4.2, UP-7)."""

_TCLK: Final = next(parameter for parameter in UP_INTERFACE_TIMING if parameter.symbol == "TCLK")
"""The internal reference clock of the µP interface (Table 3-7: TCLK = t_Bit_IBS / 16)."""
_INIT_BYTES: Final[dict[str, int]] = {name: INIT_BYTE.constant(name).value for name in ("MOTOROLA", "INTEL")}
"""The initialization bytes that select Motorola (SPI) and Intel mode (Table 3-8)."""


class _Phase(enum.Enum):
    """What the interface expects next (3.4.3 to 3.4.6)."""

    INIT = 0
    """The initialization byte (after power-up reset or SAS_INIT)."""
    COMMAND = 1
    DATA = 2
    """The data byte of the last command."""
    BLOCK = 3
    """The next byte of a block transfer."""
    DISABLED = 4
    """A faulty initialization byte was received: nothing until power-up reset or SAS_INIT (3.4.3)."""


def output_delay(bit_rate: int) -> int:
    """Output pipeline stages at ``bit_rate``: 2 TCLK less 2 clocks (UP-14), TCLK from Table 3-7."""
    expression = _TCLK.minimum or _TCLK.maximum
    assert expression is not None  # Table 3-7 gives TCLK as an expression
    clocks_per_tclk = round(timing.evaluate(expression, bit_rate) * CLOCK_HZ)
    return 2 * clocks_per_tclk - 2


def _reset_outputs() -> dict[str, int]:
    """The outputs decoded from the power-up state (shown until the output pipeline has filled, UP-14): no I/O access,
    the initialization byte next (C/D = command, UP-2), /IRQ from IRQ_EVT's reset value, no frame: nothing sent."""
    return {
        "io": 0, "io_oe": 1,
        "c_d": C_D_COMMAND, "c_d_oe": 1,
        "irq_n": int(_IRQ_EVT.reset == 0), "irq_n_oe": 1,
        "mfp6": 0, "mfp6_oe": 0,
        "mfp7": 0, "mfp7_oe": 0,
    }  # fmt: skip


@dataclass(frozen=True)
class UpifTables:
    """What the RTL derives from the manual's tables and the register map at elaboration.

    Attributes
    ----------
    output_delay:
        Output pipeline stages per bit rate, in :data:`~supi3.tables.BIT_RATES` order (UP-14).
    reset_outputs:
        The pin outputs after a power-up reset (shown until the output pipeline has filled).
    set_codes:
        For each applicable (ExtReg, ID12..8 field) of a SET value: the complete length code applied; SET values
        missing here (reserved codes) are stored and configure nothing (Tables 3-11, 3-12; UP-20, UP-40).
    internal_bytes:
        For each length code applicable with ExtReg = 0: the data bytes of the internal data path (3.4.8).
    """

    output_delay: tuple[int, ...]
    reset_outputs: dict[str, int]
    set_codes: dict[tuple[int, int], int]
    internal_bytes: dict[int, int]


@cache
def upif_tables() -> UpifTables:
    """The elaboration tables (see :class:`UpifTables`)."""
    set_codes: dict[tuple[int, int], int] = {}
    for extreg in range(1 << _EXTREG.width):
        for low in range(1 << _LENGTH_CODE.width):
            try:
                config = decode_set(_SET.encode(EXTREG=extreg, LENGTH_CODE=low))
            except RegisterMapError:
                continue
            if config.length.bits is not None:
                set_codes[(extreg, low)] = int(config.length.code, 2)
    internal_bytes = {}
    for (extreg, _), code in set_codes.items():
        bits = LENGTH_CODE_BY_VALUE[code].bits
        if not extreg and bits is not None:
            internal_bytes[code] = (bits + BYTE_BITS - 1) // BYTE_BITS
    return UpifTables(tuple(output_delay(rate) for rate in BIT_RATES), _reset_outputs(), set_codes, internal_bytes)


class _Sync:
    """A 2-flop synchroniser plus the edge-detect flop, as if reset to the pin's idle level (UP-13).

    The two synchroniser flops have no reset: ``s2`` reads as the idle level until ``settled`` (two clocks after the
    power-up reset, when flops reset to the idle level would first hold the pin), so the edges come on the same
    clocks; the edge-detect flop ``s3`` keeps its reset.
    """

    def __init__(self, m: Module, name: str, pin: Value, idle: int, settled: Value) -> None:
        s1 = Signal(name=f"{name}_s1", init=idle, reset_less=True)
        s2 = Signal(name=f"{name}_s2", init=idle, reset_less=True)
        self.s2 = Mux(settled, s2, idle)
        self.s3 = Signal(name=f"{name}_s3", init=idle)
        m.d.sync += [s1.eq(pin), s2.eq(s1), self.s3.eq(self.s2)]

    @property
    def rose(self) -> Value:
        return self.s2 & ~self.s3

    @property
    def fell(self) -> Value:
        return ~self.s2 & self.s3


class UpifBlock(wiring.Component):
    """The serial µP interface block with the ports of :data:`supi3.pinout.UP_BLOCK_INPUTS` and ``UP_BLOCK_OUTPUTS``.

    Every input pin of the model is an ``In`` port of the same name and width; every output an ``Out`` port, a
    tri-state output with its ``<name>_oe``. The straps (``rate``, ``np_id``, ``np_length``) must be static.
    """

    def __init__(self) -> None:
        members: dict[str, object] = {pin.name: In(pin.width) for pin in UP_BLOCK_INPUTS}
        for pin in UP_BLOCK_OUTPUTS:
            members[pin.name] = Out(pin.width)
            if pin.tristate:
                members[pin.name + OE_SUFFIX] = Out(1)
        super().__init__(members)

    def elaborate(self, _platform: object) -> Elaboratable:
        m = Module()
        _Builder(m, self, upif_tables()).build()
        top = Module()
        top.submodules.upif = ResetInserter({"sync": self.power_up})(m)
        return top


class _Builder:
    """The logic of one :class:`UpifBlock`, section by section (the module docstring's steps)."""

    def __init__(self, m: Module, block: UpifBlock, tables: UpifTables) -> None:
        self.m = m
        self.b = block
        self.tables = tables
        self.regs = {
            r.name: Signal(BYTE_BITS, name=r.name.lower(), init=r.reset)
            for r in REGISTER_MAP.registers
            if r.name not in OPTICAL_REGISTERS
        }
        """The registers as stored (at the start of the cycle). Reads 8..11 are not stored: they are the optical
        block's ``optical`` port as it is now (UP-39)."""
        self.core = {r.name: Signal(BYTE_BITS, name=f"{r.name.lower()}_core") for r in REGISTER_MAP.registers}
        """The registers after the core's inputs of this edge: what a read at this edge sees."""
        self.io = Signal()
        # No reset (nor clear) where every reader is gated by state that has one and the state is written before
        # that gate opens: the command and block transfer
        # fields (read only in the DATA and BLOCK phases their command byte enters), the frame's S/R, bit count and
        # whether it drives (read only in a frame, set at its /SS falling edge), and the byte sent (``tx``: sent
        # only once Motorola or Intel mode is set, by the initialization byte's end, which also stores it).
        self.set_written = Signal()
        """SET was written since the power-up reset; the configuration is then the stored SET's, if its length code
        applies (UP-40: the applied configuration is not stored apart from SET)."""
        self.configured = Signal()
        self.cfg_code = Signal(_LENGTH_CODE.width)
        """The complete length code of the stored SET (Tables 3-11, 3-12), read only while ``configured``."""
        self.n_bytes = Signal(DATA_BYTES)
        """Data bytes of the internal data path as a thermometer code (bit k: byte k is exchanged): none before SET
        and with ExtReg = 1 (``data_bytes()`` gated by ``internal_data_path``). Its users ask only whether byte k
        is in it, whether there is none and whether k is the last: each a bit or two of the ROM's word."""
        self.pcp_device = Signal()
        # Protocol (UpifProtocol) and frame (SlavePins) state.
        self.phase = Signal(_Phase, init=_Phase.INIT)
        self.motorola, self.intel = Signal(), Signal()
        self.cmd_rd, self.cmd_wr = Signal(reset_less=True), Signal(reset_less=True)
        self.cmd_addr = Signal(_ADDRESS.width, reset_less=True)
        """The command's RD, WR and address (DATA phase); in a block transfer (BLOCK phase) the slot's: whether it
        reads OUT k and writes IN k, and k (UP-11). The two phases never read each other's values: a command byte
        sets them for the phase it enters."""
        self.blk_then_wr = Signal(reset_less=True)
        self.in_frame = Signal()
        self.frame_s_r, self.tx_valid = Signal(reset_less=True), Signal(reset_less=True)
        self.tx = Signal(BYTE_BITS, reset_less=True)
        """The byte sent: the last byte received (the model's ``last_rx``, stored at each ``end`` outside DISABLED),
        replaced by the value a frame's /SS falling edge reads. One register serves both: the model sends
        ``last_rx`` in a frame without a read, and after a frame that read (``tx`` then holds the value read, not
        ``last_rx``) every frame reads again until an ``end`` stores the byte received: the read depends only on the
        phase and the command, which change only at an ``end``, or at SAS_INIT and power-up, after which nothing is
        driven until the initialization byte's ``end``."""
        self.rx = Signal(BYTE_BITS, reset_less=True)
        """The byte shifted in: read only after exactly 8 SCLK edges of a frame (``end``), which replace all of it,
        so it has neither reset nor clear."""
        self.bits = Signal(range(_BIT_COUNT_LIMIT + 1), reset_less=True)

    def build(self) -> None:
        # A pipeline of 1s reset to 0: stage k is 1 from the k-th clock after the power-up reset (``filled``, below).
        self.filled_stages = self.stages("filled", Const(1), init=0)
        self.configuration()
        self.core_inputs()
        self.pins()
        self.outputs()

    # Configuration seen by the core (RegisterFile.bus_id_register, internal_data_path, pcp_device) ---------------

    def configuration(self) -> None:
        m, b, regs = self.m, self.b, self.regs
        # ROMs indexed by the stored SET's (ExtReg, ID12..8) (Tables 3-11, 3-12; UP-20, UP-40): whether its length
        # code applies, the complete code, the internal data path's bytes (0 with ExtReg = 1)
        stored = regs[_SET.name]
        extreg, pcp_n = stored[_EXTREG.lsb], stored[_PCP_N.lsb]
        key = Cat(stored[_LENGTH_CODE.lsb : _LENGTH_CODE.lsb + _LENGTH_CODE.width], extreg)
        codes = self.tables.set_codes
        entries = [codes.get(divmod(key_value, 1 << _LENGTH_CODE.width)) for key_value in range(1 << len(key))]
        counts = [0 if code is None else self.tables.internal_bytes.get(code, 0) for code in entries]
        counts[1 << _LENGTH_CODE.width :] = [0] * (len(counts) >> 1)  # ExtReg = 1: no internal data path
        m.d.comb += [
            self.configured.eq(self.set_written & Array(Const(code is not None) for code in entries)[key]),
            self.cfg_code.eq(Array(Const(code or 0, _LENGTH_CODE.width) for code in entries)[key]),
        ]
        with m.If(self.set_written):  # a SET whose code does not apply gives none
            m.d.comb += self.n_bytes.eq(Array(Const((1 << count) - 1, DATA_BYTES) for count in counts)[key])
        m.d.comb += [
            self.pcp_device.eq(self.configured & ~extreg & ~pcp_n),
            b.in_data.eq(Cat(*(regs[r.name] for r in IN_BYTES))),
            b.bus_id.eq(Mux(self.configured, Cat(regs["ID"], self.cfg_code), Cat(b.np_id, b.np_length))),
            b.ext_reg.eq(self.configured & extreg),
            b.pcp.eq(self.pcp_device),
            b.alarm.eq(regs["ALARM"]),
        ]

    # 1. Core inputs, in the wrapper's order: latch, processor command, events, optical, INTERBUS reset -----------

    def core_inputs(self) -> None:
        m, b, regs, core = self.m, self.b, self.regs, self.core
        m.d.comb += [core[name].eq(value) for name, value in regs.items()]
        with m.If(b.latch):
            for k, register in enumerate(OUT_BYTES):
                with m.If(self.n_bytes[k]):
                    m.d.comb += core[register.name].eq(b.latch_out.word_select(k, BYTE_BITS))
            with m.If(self.pcp_device):
                for k in _PCP_ERASED:
                    with m.If(self.n_bytes[k]):
                        m.d.comb += core[IN_BYTES[k].name].eq(0)
        with m.If(b.pcmd_we):
            m.d.comb += core["PCMD"].eq(b.pcmd)
        raised = b.events | (b.pcmd_we << _SOURCE_BIT["PCMD"]) | (b.ib_reset << _SOURCE_BIT["IB_RESET"])
        m.d.comb += core[_IRQ_EVT.name].eq(regs[_IRQ_EVT.name] | (raised & regs[_IRQ_EN.name]))
        for k, name in enumerate(OPTICAL_REGISTERS):  # read as the optical block shows them now (UP-39)
            mask = REGISTER_MAP.register(name).mask
            m.d.comb += core[name].eq(b.optical.word_select(k, BYTE_BITS) & mask)
        with m.If(b.ib_reset):
            m.d.comb += [core[r.name].eq(r.reset) for r in REGISTER_MAP.cleared_by(Reset.INTERBUS)]
        m.d.sync += [regs[name].eq(core[name]) for name in regs]
        m.d.sync += self.io.eq(b.io_access)

    # 2. The µP pins: SAS_INIT, /SS falling, SCLK rising, /SS rising (SlavePins._edge) ---------------------------

    def pins(self) -> None:
        m, b = self.m, self.b
        idle = UP_INPUT_IDLE
        settled = self.filled_stages[SYNC_STAGES]  # 1 from the second clock after the power-up reset
        ss = _Sync(m, "ss", b.ss_n, idle["ss_n"], settled)
        sclk = _Sync(m, "sclk", b.sclk, idle["sclk"], settled)
        sas = _Sync(m, "sas", b.sas_init, idle["sas_init"], settled)
        data = _Sync(m, "data", Mux(b.mfp6_oe, b.mfp6, b.mfp6_in), idle["mfp6"], settled)
        s_r = _Sync(m, "s_r", b.mfp7_in, idle["mfp7"], settled)
        with m.If(sas.s2):
            m.d.sync += [self.phase.eq(_Phase.INIT), self.motorola.eq(0), self.intel.eq(0)]
            self.clear_frame()
        with m.Else():
            with m.If(ss.fell):
                self.begin(s_r.s2)
            with m.If((self.in_frame | ss.fell) & ~ss.s2 & sclk.rose):
                self.shift_in(Mux(ss.fell, 0, self.bits), data.s2)
            with m.If(self.in_frame & ss.rose):
                self.clear_frame()
                with m.If(self.bits == BYTE_BITS):
                    self.end()

    def clear_frame(self) -> None:
        self.m.d.sync += self.in_frame.eq(0)

    def shift_in(self, count: Value, bit: Value) -> None:
        """One SCLK rising edge (``SlavePins._shift_in``): Intel LSB first, else MSB first (UP-6). The byte is a
        shift register (right for Intel, left for Motorola): after the 8 edges ``end`` takes, the first bit is at
        bit 0 or bit 7, as the model's bit insertion puts it."""
        m = self.m
        rx = self.rx
        m.d.sync += rx.eq(Mux(self.intel, Cat(rx[1:], bit), Cat(bit, rx[:-1])))
        with m.If(count < BYTE_BITS):
            m.d.sync += self.bits.eq(count + 1)
        with m.Else():
            m.d.sync += self.bits.eq(_BIT_COUNT_LIMIT)

    def begin(self, s_r: Value) -> None:
        """/SS fell (``UpifProtocol.begin``): the byte to send and the read's side effect (UP-8, UP-9, UP-18)."""
        m, core = self.m, self.core
        drives = self.motorola | (self.intel & ~s_r)
        m.d.sync += [
            self.in_frame.eq(1),
            self.frame_s_r.eq(s_r),
            self.tx_valid.eq(drives),
            self.bits.eq(0),
        ]
        # A block transfer's slot addresses OUT k, which is readable: one address for both phases. An address
        # without a read (4, 5: reserved, ignored) has no case, so it reads nothing.
        reads = self.phase.matches(_Phase.DATA, _Phase.BLOCK) & self.cmd_rd
        with m.If(reads), m.Switch(self.cmd_addr):
            for a, port in _READ_PORTS.items():
                register = port.register
                if port.access is Access.RESERVED_ZERO:
                    with m.Case(a):
                        m.d.sync += self.tx.eq(0)
                elif register is not None:
                    with m.Case(a):
                        value = core[register.name]
                        if port.access is Access.RC:
                            m.d.sync += self.tx.eq(value | (self.b.io_access << IO_ACCESS_BIT))
                            with m.If(drives):
                                m.d.sync += self.regs[register.name].eq(value & ~port.clear_on_read_mask & BYTE_MASK)
                        else:
                            m.d.sync += self.tx.eq(value)

    def end(self) -> None:
        """/SS rose after 8 bits (``UpifProtocol.end``): process the received byte ``rx``; a data byte's and a block
        transfer's writes share one address decoder (``write`` at ``cmd_addr``)."""
        m, rx = self.m, self.rx
        write = Signal()
        with m.Switch(self.phase):
            with m.Case(_Phase.INIT):
                m.d.sync += self.phase.eq(_Phase.DISABLED)
                for mode, flag in (("MOTOROLA", self.motorola), ("INTEL", self.intel)):
                    with m.If(rx == _INIT_BYTES[mode]):
                        m.d.sync += [flag.eq(1), self.phase.eq(_Phase.COMMAND)]
            with m.Case(_Phase.COMMAND), m.If(self.motorola | self.frame_s_r):
                # An Intel command byte needs S/R = 1 (Table 3-9); the received byte is kept either way.
                self.command(rx[_RD.lsb], rx[_WR.lsb], rx[_ADDRESS.lsb : _ADDRESS.lsb + _ADDRESS.width])
            with m.Case(_Phase.DATA):
                self.data(write)
            with m.Case(_Phase.BLOCK):
                self.block(write)
        with m.If(write):
            self.cpu_write(self.cmd_addr, rx)
        with m.If(self.phase != _Phase.DISABLED):
            m.d.sync += self.tx.eq(rx)

    def command(self, rd: Value, wr: Value, address: Value) -> None:
        """A command byte (3.4.4): a data byte follows, or address 15 starts a block transfer (3.4.6, UP-10/11)."""
        m = self.m
        m.d.sync += [self.cmd_rd.eq(rd), self.cmd_wr.eq(wr), self.cmd_addr.eq(address), self.phase.eq(_Phase.DATA)]
        with m.If(address.matches(*_BLOCK_ADDRESSES)):  # the first slot: k = 0, what it reads and writes
            m.d.sync += [self.phase.eq(_Phase.BLOCK), self.cmd_addr.eq(0)]
            with m.If(~self.n_bytes[0] | (self.intel & ~rd & ~wr)):
                m.d.sync += self.phase.eq(_Phase.COMMAND)
            with m.If(self.motorola):
                m.d.sync += [self.cmd_rd.eq(1), self.cmd_wr.eq(1), self.blk_then_wr.eq(0)]
            with m.Else():
                m.d.sync += [self.cmd_rd.eq(rd), self.cmd_wr.eq(~rd), self.blk_then_wr.eq(rd & wr)]

    def data(self, write: Signal) -> None:
        """The data byte of a command (3.4.4): a write where RD/WR and S/R allow it (UP-9); 4 and 5 ignored."""
        m, s_r = self.m, self.frame_s_r
        m.d.sync += self.phase.eq(_Phase.COMMAND)
        refused = self.intel & (self.cmd_rd != self.cmd_wr) & (self.cmd_rd == s_r)
        m.d.comb += write.eq(self.cmd_wr & (self.motorola | s_r) & ~refused)

    def block(self, write: Signal) -> None:
        """One byte of a block transfer: write IN k in a write slot; then the next slot (UP-11). The slot's k is
        ``cmd_addr`` (below 4: only its low bits count), what it reads and writes ``cmd_rd``, ``cmd_wr``."""
        m = self.m
        refused = self.intel & (self.cmd_rd == self.frame_s_r)
        m.d.comb += write.eq(self.cmd_wr & ~refused)
        slot = self.cmd_addr[: (DATA_BYTES - 1).bit_length()]
        last = self.n_bytes.bit_select(slot, 1) & ~Cat(self.n_bytes[1:], 0).bit_select(slot, 1)  # slot k, no k + 1
        with m.If(last):
            with m.If(self.blk_then_wr):
                m.d.sync += [self.cmd_addr.eq(0), self.cmd_rd.eq(0), self.cmd_wr.eq(1), self.blk_then_wr.eq(0)]
            with m.Else():
                m.d.sync += self.phase.eq(_Phase.COMMAND)
        with m.Else():
            m.d.sync += slot.eq(slot + 1)

    def cpu_write(self, address: Value, value: Value) -> None:
        """``RegisterFile.cpu_write``: store the byte's register bits; a SET write configures the device with the
        stored SET if its length code applies (UP-40)."""
        m = self.m
        with m.Switch(address):
            for a, port in _WRITE_PORTS.items():
                register = port.register
                if port.access is Access.W and register is not None:
                    with m.Case(a):
                        m.d.sync += self.regs[register.name].eq(value & register.mask)
                        if register is _SET:
                            self.m.d.sync += self.set_written.eq(1)

    # 3. Outputs: the state decoded (SlavePins._decode), then the bit rate's pipeline (UP-14) ---------------------

    def outputs(self) -> None:
        m, b = self.m, self.b
        # Intel sends LSB first, Motorola MSB first: bit ``index`` or ``7 - index`` (the index inverted) of ``tx``
        index = Mux(self.bits > BYTE_BITS - 1, BYTE_BITS - 1, self.bits)[: (BYTE_BITS - 1).bit_length()]
        bit = self.tx.bit_select(index ^ Mux(self.intel, 0, BYTE_BITS - 1), 1)
        drive = self.in_frame & self.tx_valid
        phase = self.phase
        decoded: dict[str, Value] = {
            "io": self.io, "io_oe": Const(1),
            "c_d": Mux(phase.matches(_Phase.INIT, _Phase.COMMAND), C_D_COMMAND, C_D_DATA), "c_d_oe": Const(1),
            "irq_n": self.regs[_IRQ_EVT.name] == 0, "irq_n_oe": Const(1),
            "mfp6_oe": drive & self.intel, "mfp7_oe": drive & self.motorola,
        }  # fmt: skip
        # No pipeline stage has a reset: one more pipeline, of 1s with a reset to 0 (``filled``), says whether the
        # output stage holds a value decoded since the power-up reset, else the output shows its power-up level
        # (as stages reset to it would). The bit sent goes through one pipeline for both data pins, each gated by
        # its delayed enable.
        filled = self.tap(self.filled_stages)
        power_up = self.tables.reset_outputs
        delayed = {
            name: value if isinstance(value, Const) else Mux(filled, self.delay(name, value), power_up[name])
            for name, value in decoded.items()
        }
        sent = self.delay("bit", bit)
        delayed.update({"mfp6": sent & delayed["mfp6_oe"], "mfp7": sent & delayed["mfp7_oe"]})
        m.d.comb += [getattr(b, name).eq(value) for name, value in delayed.items()]

    def delay(self, name: str, value: Value) -> Value:
        """``value`` through the bit rate's output pipeline (UP-14), of stages without reset."""
        return self.tap(self.stages(name, value))

    def stages(self, name: str, value: Value, *, init: int | None = None) -> list[Value]:
        """``value`` and the longest output pipeline's stages after it: without reset, or reset to ``init``. The
        synchronisers read the second stage of the ``filled`` pipeline, so there are at least that many.

        Raises
        ------
        ValueError
            If the longest output pipeline is shorter than the synchronisers (UP-13, UP-14).
        """
        if max(self.tables.output_delay) < SYNC_STAGES:
            raise ValueError(f"the output pipeline needs at least {SYNC_STAGES} stages, the synchronisers' flops")
        m = self.m
        taps: list[Value] = [value]
        for stage in range(max(self.tables.output_delay)):
            stage_signal = Signal(name=f"{name}_d{stage + 1}", init=init or 0, reset_less=init is None)
            m.d.sync += stage_signal.eq(taps[-1])
            taps.append(stage_signal)
        return taps

    def tap(self, taps: list[Value]) -> Value:
        """The output of a pipeline's ``taps`` (:meth:`stages`) at the bit rate's delay (UP-14)."""
        return Array(taps[delay] for delay in self.tables.output_delay)[self.b.rate]


def verilog() -> str:
    """The Verilog of :class:`UpifBlock` (module ``supi3_upif``), ports named like the model's pins."""
    block = UpifBlock()
    text: str = amaranth_verilog.convert(block, name="supi3_upif", emit_src=False)
    return text

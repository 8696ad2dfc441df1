"""The SUPI 3's pin declarations: names, widths, directions and idle levels, as data the spec level owns.

The model (:mod:`supi3.model.pins`, :mod:`supi3.top`, :mod:`supi3.spi.block_pins`) and the RTL
(:mod:`supi3.rtl`) both take their port lists from here, so neither derives its interface from the other: the
lockstep then compares two implementations of one declaration. Nothing here depends on the model or the RTL; the
widths come from the manual's tables (:mod:`supi3.tables`) and the register map (:mod:`supi3.regmap`).

Three groups:

* the chip core (the INTERBUS slave, Table 1-4): :data:`CORE_INPUTS` with their idle levels :data:`CORE_IDLE`,
  :data:`CORE_OUTPUTS`, and the strap ports of the RTL, :data:`STRAP_PINS`;
* the serial µP interface (3.4, Tables 3-5, 3-6): its pins (:data:`UP_INPUT_IDLE`, :data:`UP_OUTPUT_NAMES`) and the
  MFP each sits on in the Init-µP modes (:data:`UP_INPUTS`, :data:`UP_OUTPUTS`, :data:`UP_PINS`);
* the join of the two through the register file: the µP block's straps (:data:`BLOCK_STRAPS`), what the core gives
  the register file (:data:`TO_REGISTER_FILE`) and what it gives back (:data:`FROM_REGISTER_FILE`).

Two cycle-level decisions are visible on the pins and belong to the declaration as well: :data:`SYNC_STAGES` (M1)
and :data:`IB_DIAG_DIVIDER_BITS` (M6, ``docs/model.md``).
"""

from __future__ import annotations

from typing import Final

from supi3.checks import check_int, fail
from supi3.interbus import wire
from supi3.optical.regulation import BLOCK_INPUTS, Interface
from supi3.pinlevel import SYNC_STAGES as SYNC_STAGES
from supi3.pinlevel import Pin
from supi3.regmap import INTERRUPT_SOURCES, REGISTER_MAP, Access, AccessDirection
from supi3.regmap.core import BYTE_BITS
from supi3.regmap.registers import IN_BYTES
from supi3.tables import BIT_RATES, CLOCK_CONFIGURATIONS, DIAG_CONFIGURATIONS, LENGTH_CODES, MODE_ROWS, RF_MODES

__all__ = [
    "BLOCK_STRAPS",
    "CLK_CONF_BITS",
    "CORE_IDLE",
    "CORE_INPUTS",
    "CORE_OUTPUTS",
    "C_BITS",
    "C_D_COMMAND",
    "C_D_DATA",
    "DATA_BYTES",
    "DIAG_CONF_BITS",
    "EVENT_BITS",
    "EXPANSION_BITS",
    "FROM_REGISTER_FILE",
    "IB_DIAG_DIVIDER_BITS",
    "LENGTH_CODE_BITS",
    "MFP_PINS",
    "OPTICAL_BRANCH_BIT",
    "OPTICAL_BRANCH_INPUTS",
    "OPTICAL_CORE_DRIVEN",
    "OPTICAL_LINE_INPUTS",
    "OPTICAL_REGISTERS",
    "RF_BITS",
    "STRAP_PINS",
    "SYNC_STAGES",
    "TIME_BASE_BITS",
    "TO_REGISTER_FILE",
    "UP_BLOCK_INPUTS",
    "UP_BLOCK_OUTPUTS",
    "UP_INPUTS",
    "UP_INPUT_IDLE",
    "UP_OUTPUTS",
    "UP_OUTPUT_NAMES",
    "UP_PINS",
    "UP_SERIAL_INPUTS",
    "UP_SERIAL_OUTPUTS",
    "time_base_end",
    "time_base_ticks",
    "up_input_port",
]

# ----------------------------------------------------------------------------------------------------------------
# Widths (Table 1-4 and the tables that decode the straps)
# ----------------------------------------------------------------------------------------------------------------

MFP_PINS: Final = 16
"""MFP[15..0] (Table 1-4)."""
C_BITS: Final = len(MODE_ROWS[0].c)
"""C[4..0] (Tables 2-4 to 2-7)."""
RF_BITS: Final = len(RF_MODES[0].rf)
"""RF[1..0] (Table 2-2)."""
CLK_CONF_BITS: Final = len(CLOCK_CONFIGURATIONS[0].clk_conf1 + CLOCK_CONFIGURATIONS[0].clk_conf0)
"""CLK_CONF[1..0] (Table 1-7)."""
DIAG_CONF_BITS: Final = len(str(DIAG_CONFIGURATIONS[0].diag_conf))
"""DIAG_CONF (Table 3-16), one pin."""
EXPANSION_BITS: Final = next(len(row.mfp) for row in MODE_ROWS if row.mfp is not None)
"""MFP[15..12]: the configuration expansion C[8..5] in the modes of Table 3-1 (Tables 2-4 to 2-6)."""
LENGTH_CODE_BITS: Final = len(LENGTH_CODES[0].code)
"""ID12..ID8 (Table 3-11)."""
DATA_BYTES: Final = len(IN_BYTES)
"""IN0..IN3 and OUT0..OUT3: the internal data registers of the µP modes (3.4.8)."""
EVENT_BITS: Final = max(source.bit for source in INTERRUPT_SOURCES) + 1
"""One bit per interrupt source, at its IRQ_EVT position (Table 3-13)."""
OPTICAL_REGISTERS: Final[tuple[str, ...]] = tuple(
    port.register.name
    for address in REGISTER_MAP.addresses
    for port in (REGISTER_MAP.port(address, AccessDirection.READ),)
    if port.register is not None and REGISTER_MAP.port(address, AccessDirection.WRITE).access is Access.NO_EFFECT
)
"""The read-only registers set by the optical block (reads 8 to 11, 3.4.12, 3.4.13), in address order."""

# ----------------------------------------------------------------------------------------------------------------
# The chip core (the INTERBUS slave)
# ----------------------------------------------------------------------------------------------------------------

CORE_INPUTS: Final[tuple[Pin, ...]] = (
    Pin("do1"), Pin("di2"), Pin("rbst_ext"), Pin("mfp_in", MFP_PINS), Pin("stat_err_n"), Pin("resu_n"),
    Pin("vmon_ok"), Pin("from_exr"),
)  # fmt: skip
"""DO1 (forward line in), DI2 (return line in), RBST_EXT, MFP[15..0], /StatErr, /ResU as seen from outside, the
voltage monitor's output, FromExR (Table 1-4, 1.7.2, 3.6.2; FromExR: 3.5, Table 3-14)."""
CORE_IDLE: Final[tuple[int, ...]] = (wire.IDLE_LEVEL, 0, 0, 0, 1, 1, 1, 0)
"""The levels of a quiet board, in :data:`CORE_INPUTS` order: idle line, no fault, power good, FromExR grounded
(nothing attached sends 0 bits, RX-2) (what the synchronisers hold after reset)."""
CORE_OUTPUTS: Final[tuple[Pin, ...]] = (
    Pin("do2"), Pin("di1"), Pin("mfp_out", MFP_PINS), Pin("mfp_oe", MFP_PINS), Pin("mod_ack_n"), Pin("res_reg_n"),
    Pin("diag1"), Pin("diag2"), Pin("ib_diag"), Pin("dclk_out"), Pin("resu_drive"), Pin("clk_exr"), Pin("to_exr"),
    Pin("la_ou_d"), Pin("la_in_d_n"),
)  # fmt: skip
"""DO2_CU, DI1_CU, MFP levels and output enables, /ModAck, /ResReg, DIAG1/2, IB_DIAG, DCLK_OUT, the open-drain
/ResU driver (Table 1-4) and the register expansion's ClkExR, ToExR, LaOuD, /LaInD (3.5, Table 3-14; idle levels
:data:`supi3.expansion.IDLE`)."""
STRAP_PINS: Final[tuple[Pin, ...]] = (
    Pin("c", C_BITS), Pin("rf", RF_BITS), Pin("clk_conf", CLK_CONF_BITS), Pin("diag_conf", DIAG_CONF_BITS),
)  # fmt: skip
"""The strap inputs beyond the core's pins (Tables 2-2, 2-4 to 2-7, 1-7, 3-16); MFP[15..12] are read from
``mfp_in`` in the configuration-expansion modes (Table 3-1)."""

OPTICAL_CORE_DRIVEN: Final[tuple[str, ...]] = ("ib_reset", "mode", "fast", "run")
"""The optical block's inputs the core drives (OPT-26): its INTERBUS reset, the mode of RF[1..0], the bit rate, the bus
active (RUN)."""
OPTICAL_LINE_INPUTS: Final[tuple[Pin, ...]] = tuple(pin for pin in BLOCK_INPUTS if pin.name not in OPTICAL_CORE_DRIVEN)
"""The optical block's line side (the fibre transceivers and the regulation's analog part: interfaces in use, medium,
initialization responses, online test results, length timer start and stop; :data:`supi3.optical.regulation.
BLOCK_INPUTS`): inputs of the chip core beside :data:`CORE_INPUTS`, taken as they are at each clock (no synchroniser,
OPT-26); 0 is quiet."""

OPTICAL_BRANCH_INPUTS: Final[tuple[str, ...]] = ("present", "len_start", "len_stop")
"""The line-side inputs whose bit :attr:`~supi3.optical.regulation.Interface.BRANCH` the chip core passes to the
optical block in the bus terminal modes (Table 2-7) only; elsewhere it holds that bit at 0 (OPT-55): the branch
transmitter never starts and the branch path is never measured (reads 9 and 11 bits 7..4 stay 0), as the transaction
level refuses ``present[BRANCH]`` and ``optical_length(BRANCH)``. The other inputs' branch bits act on the branch
transmitter only, which then stays off (OPT-22)."""
OPTICAL_BRANCH_BIT: Final = 1 << Interface.BRANCH
"""The branch interface's bit in the per-interface line-side inputs (:data:`OPTICAL_BRANCH_INPUTS`)."""
IB_DIAG_DIVIDER_BITS: Final[dict[str, int]] = {"slow": 26, "fast": 24, "very_fast": 23}
"""IB_DIAG flashes from a free-running binary divider: 2**26 clocks (0.48 Hz) for "bus not active", 2**24
(1.9 Hz) for "peripheral fault", 2**23 (3.8 Hz) for "line interrupt ahead on the local bus" (Table 3-18 asks
0.5 Hz, 2 Hz and 4 Hz; M6, DG-2 of ``docs/assumptions/diagnostics.md``)."""
TIME_BASE_BITS: Final = 15
"""The /StatErr filter (3.6.2) and the layer-2 watchdog (Table 3-13) count ticks of one time base, the same
free-running divider: a tick at the edge ending every clock whose count's low 15 bits are all ones, every 2**15
clocks (1.024 ms; M24 of ``docs/assumptions/model.md``)."""


def time_base_ticks(clocks: int, bits: int = TIME_BASE_BITS) -> int:
    """The ticks that stand for a time of ``clocks`` (1 or more) on a time base of ``2**bits`` clocks: the fewest
    ``n`` for which the ``n``-th tick after a start is never less than ``clocks`` clocks after it (at most
    ``2 * 2**bits - 2`` more; ``bits`` 0: ``clocks``; M24).

    Raises
    ------
    ArgumentError
        ``clocks`` not an integer from 1, or ``bits`` not one from 0 (M24).
    """
    clocks = check_int("clocks", clocks, 1, None, "M24")
    bits = check_int("bits", bits, 0, None, "M24")
    return (clocks - 2) // (1 << bits) + 2


def time_base_end(start: int, clocks: int, bits: int = TIME_BASE_BITS) -> int:
    """The clock whose edge ends a time of ``clocks`` counted from clock ``start`` on a time base of ``2**bits``
    clocks: the :func:`time_base_ticks`-th clock at or after ``start`` whose edge is a tick (``bits`` 0:
    ``start + clocks - 1``; M24).

    Raises
    ------
    ArgumentError
        ``start`` not an integer from 0, ``clocks`` not one from 1, or ``bits`` not one from 0 (M24).
    """
    start = check_int("start", start, 0, None, "M24")
    ticks = time_base_ticks(clocks, bits)
    period = 1 << int(bits)
    return start + (period - 1 - start) % period + (ticks - 1) * period

# ----------------------------------------------------------------------------------------------------------------
# The serial µP interface (3.4) and its place on the MFPs
# ----------------------------------------------------------------------------------------------------------------

UP_INPUT_IDLE: Final[dict[str, int]] = {"sas_init": 0, "sclk": 1, "ss_n": 1, "mfp6": 0, "mfp7": 1}
"""The µP interface's inputs and their idle levels: SAS_INIT, SCLK (idles high, UP-5), /SS, MFP6 (SerIN or
Ser_IN/OUT), MFP7 (S/R in Intel mode) (Tables 3-5, 3-6, 3-9)."""
UP_OUTPUT_NAMES: Final[tuple[str, ...]] = ("io", "c_d", "irq_n", "mfp6", "mfp7")
"""The µP interface's outputs, each with an output enable ``<name>_oe``: I/O, C/D, /IRQ, Ser_IN/OUT, SerOUT."""
UP_INPUTS: Final[dict[str, int]] = {"sas_init": 0, "sclk": 4, "ss_n": 5, "mfp6": 6, "mfp7": 7}
"""The MFP pin of each input of the µP interface (Tables 3-5 and 3-6)."""
UP_OUTPUTS: Final[dict[str, int]] = {"io": 1, "c_d": 2, "irq_n": 3, "mfp6": 6, "mfp7": 7}
"""The MFP pin of each output of the µP interface (its enable is ``<name>_oe``)."""
UP_PINS: Final = 0x00FF
"""MFP[7..0]: the µP interface's pins in the Init-µP modes."""
C_D_COMMAND: Final = 0
"""C/D (MFP2) level while the next byte is an initialization or command byte, in both modes (UP-2)."""
C_D_DATA: Final = 1
"""C/D level while the next byte is a data byte, and while data transmission is disabled (UP-4)."""


def up_input_port(name: str) -> str:
    """The µP block's input port of µP pin ``name``: pins that are also outputs (MFP6, MFP7) get ``_in``.

    Raises
    ------
    ArgumentError
        ``name`` not an input of the µP interface (:data:`UP_INPUT_IDLE`; another name used to pass unchanged).
    """
    if name not in UP_INPUT_IDLE:
        raise fail("name", f"an input of the µP interface ({', '.join(UP_INPUT_IDLE)})", name, "Tables 3-5, 3-6")
    return f"{name}_in" if name in UP_OUTPUT_NAMES else name


UP_SERIAL_INPUTS: Final[tuple[Pin, ...]] = tuple(Pin(up_input_port(name)) for name in UP_INPUT_IDLE)
"""The µP block's input ports of SAS_INIT, SCLK, /SS, MFP6 and MFP7 (``mfp6_in``, ``mfp7_in``)."""
UP_SERIAL_OUTPUTS: Final[tuple[Pin, ...]] = tuple(Pin(name, tristate=True) for name in UP_OUTPUT_NAMES)
"""The µP block's output ports, each with its enable ``<name>_oe`` (UP-24)."""

# ----------------------------------------------------------------------------------------------------------------
# The join of core and µP interface through the register file
# ----------------------------------------------------------------------------------------------------------------

BLOCK_STRAPS: Final[tuple[Pin, ...]] = (
    Pin("rate", max(1, (len(BIT_RATES) - 1).bit_length())),
    Pin("np_id", BYTE_BITS),
    Pin("np_length", LENGTH_CODE_BITS),
)
"""The bit rate index (Table 1-7) and the µP_Not_Ready ID / length code of the straps (3.4.1)."""
TO_REGISTER_FILE: Final[tuple[Pin, ...]] = (
    Pin("power_up"),
    Pin("ib_reset"),
    Pin("events", EVENT_BITS),
    Pin("io_access"),
    Pin("latch"),
    Pin("latch_out", BYTE_BITS * DATA_BYTES),
    Pin("pcmd_we"),
    Pin("pcmd", BYTE_BITS),
    Pin("optical", BYTE_BITS * len(OPTICAL_REGISTERS)),
)
"""What the INTERBUS core (and the optical block) give the register file; ``optical`` is reads 8 to 11 as the optical
block shows them now, which the register file reads without storing them (UP-39)."""
FROM_REGISTER_FILE: Final[tuple[Pin, ...]] = (
    Pin("in_data", BYTE_BITS * DATA_BYTES),
    Pin("bus_id", LENGTH_CODE_BITS + BYTE_BITS),
    Pin("ext_reg"),
    Pin("pcp"),
    Pin("alarm", BYTE_BITS),
)
"""What the register file gives the INTERBUS core."""
UP_BLOCK_INPUTS: Final[tuple[Pin, ...]] = (*UP_SERIAL_INPUTS, *BLOCK_STRAPS, *TO_REGISTER_FILE)
"""The input ports of the µP interface block (the serial pins, the straps, the core's side of the register file)."""
UP_BLOCK_OUTPUTS: Final[tuple[Pin, ...]] = (*UP_SERIAL_OUTPUTS, *FROM_REGISTER_FILE)
"""The output ports of the µP interface block."""

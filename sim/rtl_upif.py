"""cocotb test: the RTL serial µP interface (supi3.rtl.upif) driven by cocotbext-spi's SpiMaster in Motorola mode.

Ref: IBS SUPI 3 OPC UM E rev. 05, 3.4.3 to 3.4.5, 3.4.14, Table 3-7; docs/upif.md (SPI mode 3, MSB first, UP-5).
A bus-functional model written elsewhere drives the block's pins (SCLK, /SS, SerIN = MFP6, SerOUT = MFP7) at
1 MHz, one byte per /SS low period; the test initializes the interface, writes SET and ID and reads them back, and
reads the interrupt event register. Started by tests/test_rtl_upif_bfm.py, not by hand.

cocotbext-spi 0.5 predates cocotb 2: it imports ``cocotb.clock.BaseClock`` (removed; its SCLK generator only uses
the constructor, which keeps the signal, so a stand-in is installed before the import) and reads MISO as
``handle.value.integer`` (a 1-bit value is now a ``Logic`` without it, so MISO is handed over behind
:class:`_Miso`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import cocotb
import cocotb.clock
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, Timer

from supi3.config import decode
from supi3.regmap import ID, INTERRUPT_SOURCES, IRQ_EN, IRQ_EVT, SET, encode_command
from supi3.spi.block_pins import strap_values
from supi3.spi.upif import C_D_COMMAND, C_D_DATA, Mode
from supi3.tables import BIT_RATES, CLOCK_HZ


class _BaseClock:
    """What cocotbext-spi's ``_SpiClock`` needs of cocotb 1's ``BaseClock``: it stores the signal."""

    def __init__(self, signal: Any) -> None:
        self.signal = signal


if not hasattr(cocotb.clock, "BaseClock"):
    setattr(cocotb.clock, "BaseClock", _BaseClock)  # noqa: B010  (a module attribute cocotb 2 no longer has)

from cocotbext.spi import SpiBus, SpiConfig, SpiMaster  # noqa: E402  (after the stand-in)


@dataclass(frozen=True)
class _Level:
    integer: int


class _Miso:
    """A 1-bit output read the cocotb 1 way, ``.value.integer``, as cocotbext-spi's master does."""

    def __init__(self, handle: Any) -> None:
        self._handle = handle

    @property
    def value(self) -> _Level:
        return _Level(int(self._handle.value))


SCLK_HZ = 1_000_000
"""Below t0's 1.5 MHz at 500 kbit/s (Table 3-7)."""
NOT_READY_ID = decode("10011", "1110").id_code
"""RB, Init-µP (Table 2-6): the µP_Not_Ready code the master sees before SET is written (38h)."""
VALID = next(s.bit for s in INTERRUPT_SOURCES if s.name == "VALID")


async def exchange(master: SpiMaster, mosi: int) -> int:
    """One byte: the master's frame, then time for C/D to settle (t6) before the next one."""
    await master.write([mosi])
    (miso,) = await master.read(1)
    await Timer(1, unit="us")
    return int(miso)


@cocotb.test()
async def spi_master_reads_and_writes_registers(dut: Any) -> None:
    """Init 00h, SET = 82h and ID = 01h (3.4.5) read back; an enabled VALID event read from IRQ_EVT."""
    Clock(dut.clk, 1e9 / CLOCK_HZ, unit="ns").start()
    for name, value in strap_values(BIT_RATES[0], NOT_READY_ID).items():
        getattr(dut, name).value = value
    for name in ("power_up", "ib_reset", "events", "io_access", "latch", "latch_out", "pcmd_we", "pcmd", "optical",
                 "sas_init"):
        getattr(dut, name).value = 0
    dut.mfp7_in.value = 1
    bus = SpiBus.from_entity(dut, sclk_name="sclk", mosi_name="mfp6_in", miso_name="mfp7", cs_name="ss_n")
    bus.miso = _Miso(dut.mfp7)
    master = SpiMaster(bus, SpiConfig(word_width=8, sclk_freq=SCLK_HZ, cpol=True, cpha=True, msb_first=True,
                                      frame_spacing_ns=1000, cs_active_low=True))
    dut.rst.value = 1
    await ClockCycles(dut.clk, 4)
    dut.rst.value = 0
    await ClockCycles(dut.clk, 20)
    assert int(dut.c_d.value) == C_D_COMMAND
    assert int(dut.bus_id.value) == NOT_READY_ID

    await exchange(master, Mode.MOTOROLA.init_byte)
    assert int(dut.c_d.value) == C_D_COMMAND, "first initialization shows the command status twice (3.4.3)"
    await exchange(master, encode_command(SET.address, wr=True))
    assert int(dut.c_d.value) == C_D_DATA
    await exchange(master, 0x82)
    await exchange(master, encode_command(ID.address, wr=True))
    await exchange(master, 0x01)
    assert int(dut.bus_id.value) == 0x0901
    assert await exchange(master, encode_command(SET.address, rd=True)) == 0x01, "a command byte echoes (UP-8)"
    assert await exchange(master, 0) == 0x82
    await exchange(master, encode_command(ID.address, rd=True))
    assert await exchange(master, 0) == 0x01

    await exchange(master, encode_command(IRQ_EN.address, wr=True))
    await exchange(master, 1 << VALID)
    dut.events.value = 1 << VALID
    await ClockCycles(dut.clk, 1)
    dut.events.value = 0
    await ClockCycles(dut.clk, 12)
    assert int(dut.irq_n.value) == 0
    await exchange(master, encode_command(IRQ_EVT.address, rd=True))
    assert await exchange(master, 0) == 1 << VALID
    assert int(dut.irq_n.value) == 1
    await exchange(master, encode_command(IRQ_EVT.address, rd=True))
    assert await exchange(master, 0) == 0

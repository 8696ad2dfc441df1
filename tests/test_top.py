"""The whole chip at pin level: firmware configures a µP-mode chip through the serial interface on the MFP pins,
the master reads the configured ID register and exchanges data through IN/OUT bytes, all clock by clock."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from supi3.config import decode
from supi3.interbus import wire
from supi3.interbus.wire import Cycle, Frame
from supi3.regmap import ID, IN0, IRQ_EN, IRQ_EVT, OUT0, SET, Register, encode_command
from supi3.spi.upif import Phase
from supi3.top import Supi3Chip
from support import register_address

HALF = 8  # SCLK half period in clocks at 2 Mbit/s: 4 MHz, below the 6 MHz maximum (Table 3-7)
SCLK, SS_N, MOSI, MFP7 = 1 << 4, 1 << 5, 1 << 6, 1 << 7
IDLE_MFP = SCLK | SS_N | MFP7  # SCLK idles high (mode 3), /SS high, MFP7 (an input until the mode is known) high


class Bench:
    """Drives the chip's pins: the INTERBUS line on do1 and a software SPI master (Motorola) on MFP[7..0]."""

    def __init__(self) -> None:
        self.chip = Supi3Chip(decode("10011", "1110", clk_conf="11"))  # RB, Init-µP, 2 Mbit/s
        self.line: list[int] = []
        self.returned: list[int] = []
        self.irq_n: list[int] = []
        self.idle(300)

    def tick(self, mfp: int, do1: int = 1) -> dict[str, int]:
        out = self.chip.step({"do1": do1, "di2": 0, "rbst_ext": 0, "mfp_in": mfp, "stat_err_n": 1, "resu_n": 1,
                              "vmon_ok": 1, "from_exr": 0})
        self.returned.append(out["di1"])
        self.irq_n.append((out["mfp_out"] >> 3) & 1)
        return out

    def idle(self, cycles: int) -> None:
        for _ in range(cycles):
            self.tick(IDLE_MFP)

    def spi(self, mosi: int) -> int:
        """One byte, MSB first; returns what the chip sent on MFP7 (SerOUT)."""
        mfp = IDLE_MFP & ~SS_N
        for _ in range(HALF):
            self.tick(mfp)
        miso = 0
        for i in range(8):
            bit = MOSI if (mosi >> (7 - i)) & 1 else 0
            for _ in range(HALF):
                out = self.tick((mfp & ~SCLK & ~MOSI) | bit)
            miso = (miso << 1) | ((out["mfp_out"] >> 7) & 1)
            for _ in range(HALF):
                self.tick(mfp | bit)
        for _ in range(HALF):
            self.tick(mfp)
        for _ in range(2 * HALF):
            self.tick(IDLE_MFP)
        return miso

    def write(self, address: int | Register, value: int) -> None:
        self.spi(encode_command(register_address(address), wr=True))
        self.spi(value)

    def read(self, address: int | Register) -> int:
        self.spi(encode_command(register_address(address), rd=True))
        return self.spi(0)

    def send(self, levels: npt.NDArray[np.uint8]) -> None:
        """Master line levels, with the µP idle."""
        for level in wire.levels_to_samples(levels, 2_000_000).tolist():
            self.tick(IDLE_MFP, int(level))


def test_firmware_configures_the_chip_and_exchanges_data_at_pin_level() -> None:
    bench = Bench()
    assert bench.spi(0x00) == 0  # initialization byte: Motorola (Table 3-8)
    bench.write(SET, 0x82)  # 3.4.5: SET = 82h, I/O device with 1 byte
    bench.write(ID, 0x01)  # ID code 01h, digital output device
    bench.write(IRQ_EN, 0x10)  # enable the valid-data-cycle interrupt (3.4.14)
    assert bench.read(SET) == 0x82 and bench.read(ID) == 0x01
    idle = wire.status_levels(Cycle.DATA, False, 8)
    lw = wire.LOOPBACK_BYTES_ON_LINE
    start = len(bench.returned)
    bench.send(np.concatenate([
        idle, wire.reset_levels(1), idle,
        wire.cycle_levels(Frame.build(Cycle.ID, lw + wire.word_bytes(wire.command_word())), 1, True), idle,
    ]))  # fmt: skip
    # The INTERBUS reset cleared the IN bytes (3.4.7): firmware writes them after the ID cycle (Table 3-13).
    bench.write(IN0, 0x77)
    bench.send(np.concatenate([wire.cycle_levels(Frame.build(Cycle.DATA, lw + b"\x99"), 1, True), idle]))
    returned = np.array(bench.returned[start + 3 * 16 :], dtype=np.uint8)  # the repeater delays by 3 bit periods
    frames = wire.frames_from_levels(wire.samples_to_levels(returned, 2_000_000))
    assert frames[0].data == wire.word_bytes(0x0901) + lw  # ID register: ID 01h, length code 01001 (1 byte)
    assert frames[1].data == b"\x77" + lw  # IN byte 0 went to the master
    assert bench.irq_n[-1] == 0  # /IRQ on MFP3: valid data cycle
    assert bench.read(IRQ_EVT) & 0x10
    assert bench.irq_n[-1] == 1  # reading the event register releases /IRQ
    assert bench.read(OUT0) == 0x99  # OUT byte 0 from the master


def test_chip_without_up_interface_is_the_core() -> None:
    chip = Supi3Chip(decode("10000", clk_conf="11"))
    assert chip.upif is None
    traces = chip.run({"do1": np.ones(50, dtype=np.int64), "di2": np.zeros(50, dtype=np.int64),
                       "rbst_ext": np.zeros(50, dtype=np.int64), "mfp_in": np.zeros(50, dtype=np.int64),
                       "stat_err_n": np.ones(50, dtype=np.int64), "resu_n": np.ones(50, dtype=np.int64),
                       "vmon_ok": np.ones(50, dtype=np.int64), "from_exr": np.zeros(50, dtype=np.int64)})
    assert traces["resu_drive"].all()


def test_power_fail_resets_the_up_interface_at_the_edge_it_is_seen() -> None:
    # The µP interface is reset together with the register file at the first edge of a power-up reset, not one
    # clock later when resu_drive shows it (the RTL resets the whole block at that edge).
    bench = Bench()
    assert bench.spi(0x00) == 0
    assert bench.chip.upif is not None and bench.chip.upif.protocol.phase is not Phase.INIT
    inputs = {"do1": 1, "di2": 0, "rbst_ext": 0, "mfp_in": IDLE_MFP, "stat_err_n": 1, "resu_n": 1, "vmon_ok": 0,
              "from_exr": 0}
    while not bench.chip.core.holding:
        out = bench.chip.step(inputs)
        assert not out["resu_drive"]
    assert bench.chip.upif.protocol.phase in {Phase.INIT}  # "in": mypy still holds the narrowing from above

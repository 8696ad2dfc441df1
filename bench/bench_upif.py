"""Benchmark: the serial µP interface models against the real interface at its maximum SCLK.

Transaction level: ``UpInterface.write`` / ``read`` register accesses per second (pedantic mode off, and on for its
cost), and bytes per second of ``UpInterface.transfer`` (one byte per call, as the C driver is served). Pin level:
bytes per second of
a software µP (``supi3.spi.master.SoftMaster``) driving ``SlavePins`` at the fastest Table 3-7 timing. Each is
printed as a ratio to the real interface, whose times come from Table 3-7: per byte, /SS fall to first SCLK fall
max(t1, t7 - t0/2), 7.5 SCLK periods t0 to the last rising edge, t2 to /SS rise, and /SS high for t6 (maximum, C/D
settles) plus t8 before the next byte; one register access is a command byte and a data byte. Run from the
repository root:

    python bench/bench_upif.py [--accesses N] [--bytes N] [--repeat R]
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable

from supi3 import tables
from supi3.config import decode
from supi3.model.registers import RegisterFile
from supi3.regmap import IN0, OUT0, REGISTER_MAP, encode_command
from supi3.spi.figures import SET_1_BYTE
from supi3.spi.master import SoftMaster
from supi3.spi.slave_pins import SlavePins
from supi3.spi.upif import Mode, UpInterface
from supi3.timing import limit

BYTES_PER_ACCESS = 2  # command byte + data byte (3.4.4)


def _registers(bit_rate: int, *, pedantic: bool = False) -> RegisterFile:
    return RegisterFile(decode("10011", "1110", clk_conf=tables.clk_conf_for(bit_rate)), pedantic=pedantic)  # RB


def _configured(*, pedantic: bool = False) -> UpInterface:
    """A Motorola interface configured as an I/O device of 1 byte (Fig. 3-10) after one valid data cycle, so that
    pedantic mode finds nothing to report in the accesses measured."""
    up = UpInterface(_registers(500_000, pedantic=pedantic))
    assert up.initialize(Mode.MOTOROLA)
    up.write(REGISTER_MAP.register("SET").address, SET_1_BYTE)
    up.registers.latch(b"\x00")
    return up


def real_byte_s(bit_rate: int) -> float:
    """Shortest time per byte of the real interface at the maximum SCLK (Table 3-7)."""
    def low(symbol: str) -> float:
        return limit("3-7", symbol, bit_rate)

    def high(symbol: str) -> float:
        return limit("3-7", symbol, bit_rate, maximum=True)

    t0 = low("t0")
    lead = max(low("t1"), high("t7") - t0 / 2)
    return lead + 7.5 * t0 + low("t2") + high("t6") + low("t8")


def _best(repeat: int, run: Callable[[], None]) -> float:
    best = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        run()
        best = min(best, time.perf_counter() - start)
    return best


def transaction_accesses_per_s(accesses: int, repeat: int, *, pedantic: bool = False) -> float:
    """``UpInterface`` register accesses per second, half writes of IN0, half reads of OUT0 (Motorola)."""
    up = _configured(pedantic=pedantic)

    def run() -> None:
        for k in range(accesses // 2):
            up.write(IN0, k & 0xFF)
            up.read(OUT0)

    return accesses // 2 * 2 / _best(repeat, run)


def transfer_bytes_per_s(count: int, repeat: int) -> float:
    """``UpInterface.transfer`` bytes per second: the same accesses one byte per call (Motorola)."""
    up = _configured()
    transfer = up.transfer
    write, read = encode_command(IN0.address, wr=True), encode_command(OUT0.address, rd=True)

    def run() -> None:
        for k in range(count // 4):
            transfer(write)
            transfer(k & 0xFF)
            transfer(read)
            transfer(0)

    return count // 4 * 4 / _best(repeat, run)


def pin_bytes_per_s(bit_rate: int, count: int, repeat: int) -> tuple[float, float]:
    """Pin-level bytes per second (wall clock) and the simulated time per byte, for a Motorola µP writing IN0 at
    the fastest Table 3-7 timing."""
    chip = SlavePins(_registers(bit_rate))
    master = SoftMaster(chip, Mode.MOTOROLA, record=False)
    master.byte(Mode.MOTOROLA.init_byte)
    command = encode_command(IN0.address, wr=True)
    cycles = 0

    def run() -> None:
        nonlocal cycles
        start = chip.cycle
        for k in range(count // 2):
            master.byte(command)
            master.byte(k & 0xFF)
        cycles = chip.cycle - start

    wall = _best(repeat, run)
    return count // 2 * 2 / wall, cycles / (count // 2 * 2) / chip.clock_hz


def main(argv: list[str] | None = None) -> None:
    """Measure and print both levels' rates and their ratios to the real interface."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--accesses", type=int, default=50_000, help="transaction-level register accesses")
    parser.add_argument("--bytes", type=int, default=1_000, help="pin-level bytes per rate")
    parser.add_argument("--repeat", type=int, default=3, help="runs; the fastest is reported")
    args = parser.parse_args(argv)
    print(f"reproduce: python bench/bench_upif.py --accesses {args.accesses} --bytes {args.bytes} "
          f"--repeat {args.repeat}")
    access_rate = transaction_accesses_per_s(args.accesses, args.repeat)
    pedantic_rate = transaction_accesses_per_s(args.accesses, args.repeat, pedantic=True)
    byte_rate = transfer_bytes_per_s(2 * args.accesses, args.repeat)
    print(f"transaction level: {access_rate:,.0f} register accesses/s (UpInterface.write/read, best of "
          f"{args.repeat}); pedantic on: {pedantic_rate:,.0f} = {pedantic_rate / access_rate:.2f} x off")
    print(f"transfer(): {byte_rate:,.0f} bytes/s (one byte per call, best of {args.repeat})")
    for bit_rate in tables.BIT_RATES:
        real_bytes = 1 / real_byte_s(bit_rate)
        real_accesses = real_bytes / BYTES_PER_ACCESS
        sclk_mhz = 1e-6 / limit("3-7", "t0", bit_rate)
        pin_rate, model_byte_s = pin_bytes_per_s(bit_rate, args.bytes, args.repeat)
        print(f"{bit_rate // 1000} kbit/s, SCLK max {sclk_mhz:.2f} MHz: real {real_byte_s(bit_rate) * 1e6:.3f} µs/byte"
              f" = {real_bytes:,.0f} bytes/s = {real_accesses:,.0f} accesses/s")
        print(f"  transaction level: {access_rate / real_accesses:.2f} x real time; transfer(): "
              f"{byte_rate / real_bytes:.2f} x real time")
        print(f"  pin level: {pin_rate:,.0f} bytes/s = {pin_rate / real_bytes:.4f} x real time (software µP at "
              f"{model_byte_s * 1e6:.3f} µs/byte simulated, {round(model_byte_s * tables.CLOCK_HZ)} clocks/byte)")


if __name__ == "__main__":
    main()

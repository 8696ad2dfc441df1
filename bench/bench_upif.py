"""Benchmark: the serial µP interface models against the real interface at its maximum SCLK.

Transaction level: ``UpInterface.write`` / ``read`` register accesses per second (pedantic mode off, and on for its
cost), and bytes per second of ``UpInterface.transfer`` (one byte per call, as the C driver is served). Pin level:
bytes per second of a software µP (``supi3.spi.master.SoftMaster``) driving ``SlavePins`` at the fastest Table 3-7
timing. Each is printed as a ratio to the real interface, whose time per byte is ``supi3.timing.upif_byte_s`` (Table
3-7, at the fastest SCLK); one register access is a command byte and a data byte. Run from the repository root:

    python bench/bench_upif.py [--accesses N] [--bytes N] [--repeat R]
"""

from __future__ import annotations

import argparse
import ctypes
import importlib
import shutil
import subprocess
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

from supi3 import tables
from supi3.config import decode
from supi3.model.registers import RegisterFile
from supi3.regmap import IN0, OUT0, REGISTER_MAP, encode_command
from supi3.spi.figures import SET_1_BYTE
from supi3.spi.master import SoftMaster
from supi3.spi.slave_pins import SlavePins
from supi3.spi.upif import Mode, UpInterface
from supi3.timing import limit, upif_byte_s

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


_C_LOOP = """
#include <stdint.h>
typedef int (*xfer_fn)(void *user, uint8_t tx, uint8_t *rx, int s_r);
/* n/4 register accesses byte by byte, as the C driver makes them: write IN0, read OUT0 */
int run(xfer_fn xfer, void *user, long n) {
    uint8_t rx;
    for (long k = 0; k < n / 4; k++) {
        if (xfer(user, 0x40, &rx, 1) || xfer(user, (uint8_t)k, &rx, 1)) return -1;
        if (xfer(user, 0x80, &rx, 1) || xfer(user, 0, &rx, 0)) return -1;
    }
    return 0;
}
"""
_XFER = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_uint8, ctypes.POINTER(ctypes.c_uint8), ctypes.c_int)


def c_callback_bytes_per_s(count: int, repeat: int) -> dict[str, float]:
    """``transfer()`` bytes per second called back from C, one byte per callback (the ``xfer`` hook of the C
    driver, src/supi3/sdk/c), through ctypes and, if installed, cffi; empty without a C compiler."""
    compiler = shutil.which("cc") or shutil.which("gcc")
    if compiler is None:
        return {}
    rates: dict[str, float] = {}
    with tempfile.TemporaryDirectory() as folder:
        source, library = Path(folder, "loop.c"), Path(folder, "libloop.so")
        source.write_text(_C_LOOP, encoding="utf-8")
        subprocess.run([compiler, "-O2", "-shared", "-fPIC", "-o", str(library), str(source)], check=True)
        transfer = _configured().transfer

        def xfer(_user: object, tx: int, rx: ctypes._Pointer[ctypes.c_uint8], _s_r: int) -> int:
            rx[0] = transfer(tx) or 0
            return 0

        loop = ctypes.CDLL(str(library))
        hook = _XFER(xfer)
        rates["ctypes"] = count / _best(repeat, lambda: loop.run(hook, None, ctypes.c_long(count)))
        try:
            cffi = importlib.import_module("cffi")  # optional: no dependency of the project, and without stubs
        except ImportError:
            return rates
        ffi = cffi.FFI()
        ffi.cdef("int run(int (*xfer)(void *, uint8_t, uint8_t *, int), void *user, long n);")
        cffi_loop = ffi.dlopen(str(library))
        cffi_hook = ffi.callback("int(void *, uint8_t, uint8_t *, int)", xfer)
        rates["cffi"] = count / _best(repeat, lambda: cffi_loop.run(cffi_hook, ffi.NULL, count))
    return rates


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
    c_rates = c_callback_bytes_per_s(2 * args.accesses, args.repeat)
    print(f"transfer(): {byte_rate:,.0f} bytes/s (one byte per call, best of {args.repeat})"
          + "".join(f"; from C through {name} callbacks: {rate:,.0f} bytes/s" for name, rate in c_rates.items()))
    for bit_rate in tables.BIT_RATES:
        real_bytes = 1 / upif_byte_s(bit_rate)
        real_accesses = real_bytes / BYTES_PER_ACCESS
        sclk_mhz = 1e-6 / limit("3-7", "t0", bit_rate)
        pin_rate, model_byte_s = pin_bytes_per_s(bit_rate, args.bytes, args.repeat)
        print(f"{bit_rate // 1000} kbit/s, SCLK max {sclk_mhz:.2f} MHz: real {upif_byte_s(bit_rate) * 1e6:.3f} µs/byte"
              f" = {real_bytes:,.0f} bytes/s = {real_accesses:,.0f} accesses/s")
        print(f"  transaction level: {access_rate / real_accesses:.2f} x real time; transfer(): "
              f"{byte_rate / real_bytes:.2f} x real time"
              + "".join(f"; through {name}: {rate / real_bytes:.2f} x" for name, rate in c_rates.items()))
        print(f"  pin level: {pin_rate:,.0f} bytes/s = {pin_rate / real_bytes:.4f} x real time (software µP at "
              f"{model_byte_s * 1e6:.3f} µs/byte simulated, {round(model_byte_s * tables.CLOCK_HZ)} clocks/byte)")


if __name__ == "__main__":
    main()

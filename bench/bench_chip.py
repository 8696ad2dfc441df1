"""Benchmark: the whole chip at pin level (INTERBUS core + serial µP interface, ``supi3.top.Supi3Chip``) on a
firmware workload, clock cycles per second.

One RB chip in an Init-µP mode (Motorola) is configured by a software µP (initialization byte, SET = 82h, ID = 01h,
IRQ_EN), then receives back-to-back data cycles of 1 data byte from the master while the µP does ``--accesses``
register accesses (2 bytes each, at the fastest Table 3-7 timing; alternately a write of IN0 and a read of OUT0)
per data cycle, its pins idle otherwise. The same traces run cycle by cycle (``step``) and as whole traces
(``run``, event-driven); the outputs are identical (tests/test_top_run.py). For scale, the INTERBUS core alone
(``Supi3Pins.run``, bench/bench_model.py's kernel) runs the same traces too. Run from the repository root:

    python bench/bench_chip.py [--cycles N] [--accesses A] [--repeat R]
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np
import numpy.typing as npt

from supi3.config import decode
from supi3.interbus import wire
from supi3.interbus.wire import Cycle, Frame
from supi3.model.pins import RESET_STRETCH_CLOCKS, Supi3Pins
from supi3.model.registers import RegisterFile
from supi3.regmap import ID, IN0, IRQ_EN, OUT0, SET, encode_command
from supi3.spi.master import SoftMaster
from supi3.spi.slave_pins import SlavePins
from supi3.spi.upif import Mode
from supi3.tables import clk_conf_for
from supi3.top import UP_INPUTS, Supi3Chip

IDLE_TELEGRAMS = 4
"""Status telegrams between two data cycles."""


def workload(bit_rate: int, cycles: int, accesses: int) -> dict[str, npt.NDArray[np.int64]]:
    """Input traces: the line (reset, ID cycle, ``cycles`` data cycles) and the µP's pins on MFP[7..0]."""
    config = decode("10011", "1110", clk_conf=clk_conf_for(bit_rate))
    lw = wire.LOOPBACK_BYTES_ON_LINE
    idle = wire.status_levels(Cycle.DATA, False, IDLE_TELEGRAMS)
    setup = wire.status_levels(Cycle.DATA, False, 200)  # the µP configures the chip meanwhile
    head = [setup, wire.reset_levels(1), idle,
            wire.cycle_levels(Frame.build(Cycle.ID, lw + wire.word_bytes(wire.command_word())), 1, True), idle]
    data = [np.concatenate([wire.cycle_levels(Frame.build(Cycle.DATA, lw + bytes([n & 0xFF])), 1, True), idle])
            for n in range(cycles)]
    cpb = wire.clocks_per_bit(bit_rate)
    do1 = wire.levels_to_samples(np.concatenate(head + data), bit_rate).astype(np.int64)
    master = SoftMaster(SlavePins(RegisterFile(config, strict=False)), Mode.MOTOROLA, record=True)
    master.run(2 * RESET_STRETCH_CLOCKS)  # the power-up reset's stretch (M2)
    master.byte(Mode.MOTOROLA.init_byte)
    for register, value in ((SET, 0x82), (ID, 0x01), (IRQ_EN, 0x10)):
        master.byte(encode_command(register.address, wr=True))
        master.byte(value)
    start = sum(len(part) for part in head) * cpb
    for n, part in enumerate(data):
        for k in range(accesses):
            if k % 2:
                master.byte(encode_command(OUT0.address, rd=True))
                master.byte(0)
            else:
                master.byte(encode_command(IN0.address, wr=True))
                master.byte(n & 0xFF)
            master.deselect()
        start += len(part) * cpb
        if start > master.cycle:
            master.run(start - master.cycle)
    pins = master.trace().inputs
    mfp = np.array([sum(getattr(p, name) << pin for name, pin in UP_INPUTS.items()) for p in pins], dtype=np.int64)
    n = len(do1)
    mfp = np.concatenate([mfp, np.full(max(n - len(mfp), 0), mfp[-1], dtype=np.int64)])[:n]
    ones, zeros = np.ones(n, dtype=np.int64), np.zeros(n, dtype=np.int64)
    return {"do1": do1, "di2": zeros, "rbst_ext": zeros, "mfp_in": mfp, "stat_err_n": ones, "resu_n": ones,
            "vmon_ok": ones, "from_exr": 0 * ones}


def measure(bit_rate: int, cycles: int, accesses: int, repeat: int) -> tuple[int, float, float, float, int]:
    """(clock cycles, best step() seconds, best run() seconds, best run() seconds of the core alone, valid data
    cycles seen by the chip)."""
    config = decode("10011", "1110", clk_conf=clk_conf_for(bit_rate))
    inputs = workload(bit_rate, cycles, accesses)
    n = len(inputs["do1"])
    names = list(inputs)
    rows = [dict(zip(names, values, strict=True)) for values in zip(*(inputs[k].tolist() for k in names),
                                                                     strict=True)]
    best_step = best_run = best_core = float("inf")
    valid = 0
    for _ in range(repeat):
        chip = Supi3Chip(config)
        begin = time.perf_counter()
        for row in rows:
            chip.step(row)
        best_step = min(best_step, time.perf_counter() - begin)
        chip = Supi3Chip(config)
        begin = time.perf_counter()
        chip.run(inputs)
        best_run = min(best_run, time.perf_counter() - begin)
        valid = chip.chip.events["VALID"]
        core = Supi3Pins(config)
        begin = time.perf_counter()
        core.run(inputs)
        best_core = min(best_core, time.perf_counter() - begin)
    return n, best_step, best_run, best_core, valid


def main(argv: list[str] | None = None) -> None:
    """Print clock cycles per second at both bit rates."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cycles", type=int, default=50, help="data cycles in the workload")
    parser.add_argument("--accesses", type=int, default=2, help="µP register accesses per data cycle")
    parser.add_argument("--repeat", type=int, default=3, help="runs; the fastest is reported")
    args = parser.parse_args(argv)
    for bit_rate in (500_000, 2_000_000):
        n, step_s, run_s, core_s, valid = measure(bit_rate, args.cycles, args.accesses, args.repeat)
        print(f"{bit_rate // 1000:>5} kbit/s, {n} clocks, {valid} valid data cycles: step() "
              f"{n / step_s / 1e3:4.0f} k cycles/s, run() {n / run_s / 1e6:5.2f} M cycles/s, "
              f"run/step = {step_s / run_s:5.1f}, core alone run() {n / core_s / 1e6:5.2f} M cycles/s "
              f"(whole chip / core = {core_s / run_s:.2f})")
    print(f"reproduce: python bench/bench_chip.py --cycles {args.cycles} --accesses {args.accesses} "
          f"--repeat {args.repeat}")


if __name__ == "__main__":
    main(sys.argv[1:])

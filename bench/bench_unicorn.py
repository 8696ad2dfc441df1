"""Benchmark: the emulator's own time (unicorn and the native hooks of hook.c) in issue #13's case, and what each hook
costs in unicorn (MCU-87).

Three parts, each run from the repository root:

- ``counts``: what unicorn executes in issue #13's case (``bench_mcu.py``'s board: the digital 16/16 example at
  2 Mbit/s, SPI1 at f_PCLK / 16) over ``--cycles`` master cycles after power-up: guest instructions and blocks it
  runs (the instructions MCU-10 and MCU-11 count without running them are not among them), its runs, its memory
  accesses by region and the entries into Python from a peripheral access or a watched address. Counting hooks are
  added to the board's core (and its translations dropped, so they reach every block): deterministic, not timed.
- ``synthetic``: unicorn alone on a Thumb loop in flash that has issue #13's mix (4 blocks, 14 instructions and 6 loads
  or stores of RAM an iteration; a variant reads a peripheral in place of one RAM load, answered by hook.c's
  held-register callback without Python), with the hooks added one by one as ``CortexM`` added them before MCU-89:
  (a) none but the seven peripheral ranges mapped with ``uc_mmio_map``; (b) the native block hook; (c) the
  ``UC_HOOK_MEM_READ | UC_HOOK_MEM_WRITE`` hooks of the peripheral ranges (``supi3_exact_pc``, one a run of adjacent
  ranges, MCU-87); (d) a flash write hook (MCU-28's, never called by the loop) and two code hooks at addresses the
  loop never runs (the idle loops and the serve point, ``CortexM.watch``); and (e) as ``CortexM`` sets them up since
  MCU-89: the block hook, the exact-PC hooks as protection hooks over the peripheral ranges mapped inaccessible, the
  virtual TLB's fill (``supi3_tlb_fill``) and the two code hooks. Each figure is the fastest of ``--rounds``
  interleaved runs, in CPU time. From them: the block hook's cost a block, a RAM access's cost once any memory hook
  exists (unicorn then sends every guest load and store through its slow path), a peripheral access's cost and the
  cost of the exact PC at one (unicorn restores the PC from the host return address, ``cpu_restore_state``, when a
  memory or protection hook covers the address), and what they come to with ``counts``' figures.
- ``split``: issue #13's case as ``bench_mcu.py`` runs it, its CPU time split into unicorn with hook.c (the native
  runs less the Python they call) and Python; interleaved rounds, the fastest. Run it on the tree before MCU-89 for
  the memory hooks' figures (the same process cannot hold both).
- ``run``: issue #13's case once, power-up and ``--cycles`` master cycles, nothing else: for a count of the host's
  instructions, deterministic where CPU time is not (MCU-89), with another tree's ``src`` on ``PYTHONPATH`` too;
  the difference between ``--cycles 501`` and ``--cycles 1`` is 500 cycles':

    PYTHONHASHSEED=0 valgrind --tool=callgrind --cache-sim=no --smc-check=all-non-file python bench/bench_unicorn.py run

The machine is shared: its CPU time per run swings by up to 2x with the other sessions' load (the figures of one
process are comparable with each other, not with another process's). Run from the repository root:

    python bench/bench_unicorn.py [counts|synthetic|split|run ...] [--cycles N] [--rounds R]
"""

from __future__ import annotations

import argparse
import collections
import ctypes
import struct
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from unicorn import arm_const as arm
from unicorn import unicorn_const as ucc

import bench_mcu
from supi3.mcu import board as board_module
from supi3.mcu import core as core_module
from supi3.mcu import frames as frames_module
from supi3.mcu import hook
from supi3.mcu.board import Board
from supi3.mcu.build import build
from supi3.sdk import native

_LIB: Any = core_module._LIB
_MEM_HOOK = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_int, ctypes.c_uint64, ctypes.c_int, ctypes.c_int64,
                             ctypes.c_void_p)  # fmt: skip

FLASH, RAM, SPI1 = 0x0800_0000, 0x2000_0000, 0x4001_3000
PERIPHERALS = ((0xE000_E000, 0x1000), (0x4002_1000, 0x400), (0x4001_0800, 0x400), (0x4001_0C00, 0x400),
               (0x4001_0000, 0x400), (0x4001_0400, 0x400), (SPI1, 0x400))  # fmt: skip
"""The board's mapped ranges (SCS, RCC, GPIOA, GPIOB, AFIO, EXTI, SPI1), as ``Board`` maps them."""
EXACT_PC_RUNS = ((0xE000_E000, 0x1000), (0x4002_1000, 0x400), (0x4001_0000, 0x1000), (SPI1, 0x400))
"""The exact-PC hooks' ranges as ``CortexM`` hooks the board's: adjacent ranges in one (MCU-87)."""
PARTS = ["counts", "synthetic", "split", "run"]
CONFIGURATIONS: dict[str, frozenset[str]] = {
    "(a) no hook": frozenset(),
    "(b) + block hook": frozenset({"block"}),
    "(c) + exact-PC memory hooks": frozenset({"block", "exact"}),
    "(d) + flash and code hooks": frozenset({"block", "exact", "flash"}),
    "(b) + flash and code hooks only": frozenset({"block", "flash"}),
    "(e) MCU-89: protection hooks, TLB fill": frozenset({"block", "protection"}),
}
"""The synthetic loop's hooks: (a) to (d) as ``CortexM`` added them before MCU-89, one without the exact-PC hooks,
(e) as it adds them since."""
LOOP_INSTRUCTIONS, LOOP_BLOCKS, LOOP_ACCESSES = 14, 4, 6


def issue_board(elf: Path) -> Board:
    """Issue #13's board after power-up, as ``bench_mcu.py`` measures it."""
    return bench_mcu._board(elf, 2_000_000, True)


def issue_elf(folder: Path) -> Path:
    """The digital 16/16 example built as in issue #13's case (SPI1 at f_PCLK / 16)."""
    return build(native.example("digital_io"), folder / "dio_2000000.elf", defines={"BOARD_SPI_BR": "3u"})


def counts(elf: Path, cycles: int) -> dict[str, int]:
    """What unicorn runs in issue #13's case over ``cycles`` master cycles (see the module's docstring)."""
    board = issue_board(elf)
    core = board.core
    found: collections.Counter[str] = collections.Counter()

    def on_code(handle: int, address: int, size: int, data: int | None) -> None:
        del handle, address, size, data
        found["instructions run"] += 1

    def on_block(handle: int, address: int, size: int, data: int | None) -> None:
        del handle, address, size, data
        found["blocks entered"] += 1

    def on_memory(handle: int, kind: int, address: int, size: int, value: int, data: int | None) -> None:
        del handle, size, value, data
        region = "flash" if address < RAM else "RAM" if address < 0x4000_0000 else "peripheral"
        found[f"{region} {'writes' if kind == ucc.UC_MEM_WRITE else 'reads'}"] += 1

    core._hook(ucc.UC_HOOK_CODE, core_module._HOOK_CODE(on_code))
    core._hook(ucc.UC_HOOK_BLOCK, core_module._HOOK_CODE(on_block))
    core._hook(ucc.UC_HOOK_MEM_READ | ucc.UC_HOOK_MEM_WRITE, _MEM_HOOK(on_memory))
    core.uc.ctl_flush_tb()  # the translations made before the hooks would not reach them
    entry, run = core.entry, core._native_run

    def counted_entry() -> None:
        found["entries into Python"] += 1
        if entry is not None:
            entry()

    def counted_run(*arguments: Any) -> int:
        found["runs"] += 1
        return int(run(*arguments))

    core.entry, core._native_run = counted_entry, counted_run
    instructions = core.instructions
    board.run(cycles)
    found["instructions counted (MCU-1, skips included)"] = core.instructions - instructions
    return dict(found)


def _loop(peripheral: bool) -> tuple[bytes, list[tuple[int, int, int, int]]]:
    """The synthetic loop's Thumb code (R0 iterations, R1 RAM, R3 SPI1) ending in ``b .``, and each block's address,
    size, instructions and cycles (MCU-1)."""
    load = 0x689C if peripheral else 0x690C  # ldr r4, [r3, #8] (SPI1's SR) or ldr r4, [r1, #16]
    blocks = [[0x680A, 0x3201, 0x600A, 0xE7FF],  # ldr r2, [r1]; adds r2, #1; str r2, [r1]; b (next)
              [load, 0x684D, 0xE7FF],  # ldr r5, [r1, #4]; b (next)
              [0x192D, 0x608D, 0x2600, 0xE7FF],  # adds r5, r5, r4; str r5, [r1, #8]; movs r6, #0; b (next)
              [0x68CE, 0x3801, 0xD100]]  # ldr r6, [r1, #12]; subs r0, #1; bne (the loop)  # fmt: skip
    halfwords: list[int] = []
    costs = []
    for block in blocks:
        costs.append((FLASH + 2 * len(halfwords), 2 * len(block), len(block), len(block) + 2))
        halfwords += block
    halfwords[-1] |= (-(len(halfwords) + 1)) & 0xFF
    halfwords.append(0xE7FE)  # b .: the end
    return struct.pack(f"<{len(halfwords)}H", *halfwords), costs


class _Engine:
    """unicorn with the board's memory map, the synthetic loop and the ``hooks`` (:data:`CONFIGURATIONS`)."""

    def __init__(self, hooks: frozenset[str], peripheral: bool) -> None:
        library = hook.library()
        self.uc: Any = core_module._UNICORN.Uc(ucc.UC_ARCH_ARM, ucc.UC_MODE_THUMB | ucc.UC_MODE_MCLASS)
        self.uc.ctl_set_cpu_model(arm.UC_CPU_ARM_CORTEX_M3)
        if "protection" in hooks:
            self.uc.ctl_set_tlb_mode(ucc.UC_TLB_VIRTUAL)
        self._keep: list[object] = []
        code, costs = _loop(peripheral)
        self.end = FLASH + len(code) - 2
        self.uc.mem_map(FLASH, 64 * 1024)
        self.uc.mem_map(RAM, 20 * 1024)
        self.uc.mem_write(FLASH, code)
        self.state = state = hook.State()
        cache = (hook.Block * core_module.BLOCK_CACHE_SLOTS)()
        for address, size, instructions, cycles in costs:  # described beforehand: no call into Python
            cache[(address >> 1) & (core_module.BLOCK_CACHE_SLOTS - 1)] = hook.Block(address, size, instructions,
                                                                                     cycles, -1, 0)  # fmt: skip
        state.cache, state.mask, state.deadline = cache, core_module.BLOCK_CACHE_SLOTS - 1, core_module.MAX_DEADLINE
        state.emu_stop = ctypes.cast(_LIB.uc_emu_stop, ctypes.c_void_p)
        state.reg_read = ctypes.cast(_LIB.uc_reg_read, ctypes.c_void_p)
        state.pc_register = arm.UC_ARM_REG_PC
        state.rewritable, state.rewritable_size = RAM, 20 * 1024
        held = hook.Held(ctypes.pointer(state), hook.MMIO_READ(lambda *_: 0))
        held.held, held.offset, held.value, held.until = 1, 8, 0x5A, core_module.MAX_DEADLINE  # SR, held natively
        self._keep += [cache, held]
        handle = self.uc._uch
        for base, size in PERIPHERALS:
            assert _LIB.uc_mmio_map(handle, base, size, ctypes.cast(library.supi3_held_read, ctypes.c_void_p),
                                    ctypes.byref(held), None, None) == 0  # fmt: skip
        if "block" in hooks:
            self._hook(ucc.UC_HOOK_BLOCK, library.supi3_block_hook, 1, 0, ctypes.byref(state))
        if "exact" in hooks:  # before MCU-89 (the native hook's answer is not read by a memory hook's caller)
            for base, size in EXACT_PC_RUNS:
                self._hook(ucc.UC_HOOK_MEM_READ | ucc.UC_HOOK_MEM_WRITE, library.supi3_exact_pc, base,
                           base + size - 1, ctypes.byref(state))  # fmt: skip
        if "flash" in hooks:  # before MCU-89: a flash write hook (the loop stores into RAM only: never called)
            self._hook(ucc.UC_HOOK_MEM_WRITE, _MEM_HOOK(lambda *_: None), FLASH, FLASH + 64 * 1024 - 1, None)
        if "protection" in hooks:  # as CortexM since MCU-89
            memory = core_module._virtual_tlb(state, (FLASH, 64 * 1024))
            self._keep.append(memory)
            self._hook(ucc.UC_HOOK_TLB_FILL, library.supi3_tlb_fill, 1, 0, ctypes.byref(memory))
            for base, size in PERIPHERALS:
                self.uc.mem_protect(base, size, ucc.UC_PROT_NONE)
            for base, size in EXACT_PC_RUNS:
                self._hook(ucc.UC_HOOK_MEM_READ_PROT | ucc.UC_HOOK_MEM_WRITE_PROT, library.supi3_exact_pc, base,
                           base + size - 1, ctypes.byref(state))  # fmt: skip
        if hooks & {"flash", "protection"}:
            nothing = core_module._HOOK_CODE(lambda *_: None)
            for address in (FLASH + 0x1000, FLASH + 0x1100):
                self._hook(ucc.UC_HOOK_CODE, nothing, address, address, None)
        self.uc.reg_write(arm.UC_ARM_REG_R1, RAM)
        self.uc.reg_write(arm.UC_ARM_REG_R3, SPI1)

    def _hook(self, kind: int, callback: Any, begin: int, end: int, data: Any) -> None:
        self._keep.append(callback)
        handle = ctypes.c_size_t()
        assert _LIB.uc_hook_add(self.uc._uch, ctypes.byref(handle), kind, ctypes.cast(callback, ctypes.c_void_p), data,
                                ctypes.c_uint64(begin), ctypes.c_uint64(end)) == 0  # fmt: skip

    def run(self, iterations: int) -> float:
        """CPU seconds for ``iterations`` of the loop (translated before)."""
        self.uc.reg_write(arm.UC_ARM_REG_R0, iterations)
        start = time.process_time()
        self.uc.emu_start(FLASH | 1, self.end)
        return time.process_time() - start


def synthetic(iterations: int, rounds: int) -> dict[tuple[str, bool], float]:
    """The fastest CPU seconds an iteration of each configuration and variant (peripheral read or not)."""
    best: dict[tuple[str, bool], float] = {}
    for _ in range(rounds):
        for peripheral in (False, True):
            for configuration, hooks in CONFIGURATIONS.items():
                engine = _Engine(hooks, peripheral)
                engine.run(10)  # the translation, outside the measure
                seconds = engine.run(iterations) / iterations
                assert engine.uc.reg_read(arm.UC_ARM_REG_R0) == 0
                key = (configuration, peripheral)
                best[key] = min(best.get(key, seconds), seconds)
    return best


def unit_costs(best: dict[tuple[str, bool], float]) -> dict[str, float]:
    """Seconds per unit, from ``synthetic``'s figures."""
    a, b, c = list(CONFIGURATIONS)[:3]
    slow = (best[c, False] - best[b, False]) / LOOP_ACCESSES
    return {"block hook, a block": (best[b, False] - best[a, False]) / LOOP_BLOCKS,
            "slow path, a RAM access": slow,
            "peripheral access (mmio, no memory hook)": best[a, True] - best[a, False],
            "exact PC, a peripheral access": best[c, True] - best[b, True] - (LOOP_ACCESSES - 1) * slow}  # fmt: skip


_clock = time.process_time
_nested = {"python": 0.0, "native": 0.0, "depth": 0, "calls": 0}


def _timed_python(function: Callable[..., Any]) -> Callable[..., Any]:
    """``function``, its CPU time counted when unicorn's run calls it (directly or through hook.c)."""

    def timed(*arguments: Any, **keywords: Any) -> Any:
        if _nested["depth"] != 1:
            return function(*arguments, **keywords)
        _nested["depth"] = 2
        _nested["calls"] += 1
        start = _clock()
        try:
            return function(*arguments, **keywords)
        finally:
            _nested["python"] += _clock() - start
            _nested["depth"] = 1

    return timed


_PYTHON_FROM_RUN = ((frames_module.NativeFrames, ("_bus_due", "catch_up")),
                    (board_module.Board, ("_gpio_write", "_gpio_read", "_spi_write", "_spi_read", "_exti_read",
                                          "_exti_write", "_on_serve_point")),
                    (core_module.CortexM, ("_describe",)))  # fmt: skip
"""The Python that unicorn's runs call in issue #13's case (the peripherals' callbacks, the serve point, the native
frames' catch-up and bus synchronisation, a block's costing)."""


def split(elf: Path, cycles: int, rounds: int) -> tuple[float, float, int, int, int]:
    """Of the round with the fastest run: its CPU seconds, those of unicorn with hook.c in it, the instructions counted
    (MCU-1), the violations and the Python calls from unicorn's runs."""
    for owner, names in _PYTHON_FROM_RUN:
        for name in names:
            setattr(owner, name, _timed_python(getattr(owner, name)))
    best: tuple[float, float, int, int, int] | None = None
    for _ in range(rounds):
        board = issue_board(elf)
        core = board.core
        run = core._native_run

        def timed_run(*arguments: Any, run: Any = run) -> int:
            _nested["depth"] = 1
            start = _clock()
            try:
                return int(run(*arguments))
            finally:
                _nested["native"] += _clock() - start
                _nested["depth"] = 0

        core._native_run = timed_run
        _nested["python"] = _nested["native"] = _nested["calls"] = 0
        instructions = core.instructions
        start = time.process_time()
        board.run(cycles)
        total = time.process_time() - start
        row = (total, _nested["native"] - _nested["python"], core.instructions - instructions, len(board.violations),
               int(_nested["calls"]))  # fmt: skip
        if best is None or row[0] < best[0]:
            best = row
    assert best is not None
    return best


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("parts", nargs="*", help="counts, synthetic, split, run (default: the first three)")
    parser.add_argument("--cycles", type=int, default=500, help="master cycles in issue #13's case")
    parser.add_argument("--rounds", type=int, default=5, help="interleaved rounds (the fastest of each is given)")
    parser.add_argument("--iterations", type=int, default=200_000, help="iterations of the synthetic loop")
    args = parser.parse_args(argv)
    for name in ("cycles", "rounds", "iterations"):
        if getattr(args, name) < 1:
            parser.error(f"--{name} must be at least 1, not {getattr(args, name)}")
    parts = args.parts or PARTS[:3]
    if not set(parts) <= set(PARTS):
        parser.error(f"parts: {', '.join(PARTS)}, not {' '.join(parts)}")
    with tempfile.TemporaryDirectory() as folder:
        elf = issue_elf(Path(folder))
        simulated = None
        if {"counts", "split", "run"} & set(parts):
            board = issue_board(elf)
            start = board.bench.now
            board.run(args.cycles)
            simulated = board.bench.now - start
            print(f"issue #13's case, {args.cycles} master cycles: {simulated * 1e3:.2f} ms simulated")
        found: dict[str, int] = {}
        if "counts" in parts:
            found = counts(elf, args.cycles)
            for name, value in sorted(found.items()):
                print(f"  {name:48s} {value:9d}")
        if "synthetic" in parts:
            best = synthetic(args.iterations, args.rounds)
            print(f"synthetic loop ({LOOP_INSTRUCTIONS} instructions, {LOOP_BLOCKS} blocks, {LOOP_ACCESSES} RAM "
                  f"accesses an iteration; 'peripheral': one of them a held SPI1 SR read):")  # fmt: skip
            for peripheral in (False, True):
                for name in CONFIGURATIONS:
                    seconds = best[name, peripheral]
                    print(f"  {'peripheral' if peripheral else 'RAM only':10s} {name:33s} {seconds * 1e9:6.1f} ns an "
                          f"iteration, {LOOP_INSTRUCTIONS / seconds / 1e6:5.1f} M instructions/s, "
                          f"{LOOP_BLOCKS / seconds / 1e6:5.2f} M blocks/s")  # fmt: skip
            units = unit_costs(best)
            for name, seconds in units.items():
                print(f"  {name:48s} {seconds * 1e9:6.1f} ns")
            if found:
                ram = sum(value for name, value in found.items() if name.startswith(("RAM", "flash")))
                accesses = sum(value for name, value in found.items() if name.startswith("peripheral"))
                hooks = ram * units["slow path, a RAM access"] + accesses * units["exact PC, a peripheral access"]
                print(f"  issue #13's case: the memory hooks' cost {hooks * 1e3:.1f} ms ({ram} RAM accesses through "
                      f"the slow path, {accesses} exact PCs), the block hook's "
                      f"{found['blocks entered'] * units['block hook, a block'] * 1e3:.1f} ms")  # fmt: skip
        if "split" in parts:
            total, emulator, instructions, violations, calls = split(elf, args.cycles, args.rounds)
            ratio = f", simulated / emulator {simulated / emulator:.2f}x" if simulated else ""
            print(f"issue #13's case, CPU time split (the fastest round): total {total * 1e3:6.1f} ms, unicorn with "
                  f"hook.c {emulator * 1e3:5.1f} ms{ratio}; instructions {instructions}, violations {violations}, "
                  f"Python calls from the runs {calls}")  # fmt: skip

if __name__ == "__main__":
    main()

"""MCU-87: the exact-PC memory hooks of adjacent peripheral ranges merged into one: every access to every mapped
range still sees the PC of its instruction, whatever the order the ranges are mapped in (MCU-1: a peripheral access
is timed by its PC)."""

from __future__ import annotations

import itertools
from pathlib import Path

import pytest

from supi3.mcu import build as mcu_build
from supi3.mcu.core import MAX_DEADLINE, CortexM
from supi3.mcu.stm32 import PERIPHERAL_SIZE

PROGRAM = Path(__file__).parent / "mcu" / "peripheral_pc.S"
RANGES = (0x4001_0800, 0x4001_0C00, 0x4001_0000, 0x4001_0400, 0x4001_3000, 0x4002_1000, 0x4001_1400, 0x4001_1000)
"""GPIOA, GPIOB, AFIO, EXTI, SPI1, RCC (the board's order), then two more: one apart, one joining GPIOB's run to it."""
CPUS = ("cortex_m3", "cortex_m0")


@pytest.fixture(scope="module")
def programs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """peripheral_pc.S built for each core, once per module."""
    folder = tmp_path_factory.mktemp("exactpc")
    return {cpu: mcu_build.build(PROGRAM, folder / f"peripheral_pc_{cpu}.elf", cpu=cpu, port=False) for cpu in CPUS}


def _accesses(elf: Path, cpu: str, order: tuple[int, ...]) -> tuple[CortexM, list[tuple[str, int, int]]]:
    """The core after the program, its ranges mapped in ``order``, and each access's kind, address and PC as the
    peripheral's callback saw them."""
    core = CortexM(elf, cpu=cpu)
    seen: list[tuple[str, int, int]] = []
    for base in order:

        def read(offset: int, size: int, base: int = base) -> int:
            del size
            seen.append(("read", base + offset, core.pc))
            return base + offset

        def write(offset: int, size: int, value: int, base: int = base) -> None:
            del size, value
            seen.append(("write", base + offset, core.pc))

        core.mmio(base, PERIPHERAL_SIZE, read, write)
    for _ in range(100):
        core.step(MAX_DEADLINE)
        if core.idle_loop():
            return core, seen
    raise AssertionError(f"the core did not reach done: PC {core.pc:08X}h")


@pytest.mark.parametrize("cpu", CPUS)
@pytest.mark.parametrize("shift", range(0, len(RANGES), 3))
def test_every_access_to_every_range_sees_its_pc(programs: dict[str, Path], cpu: str, shift: int) -> None:
    """Each range's first and last word read and written by an instruction inside its block: the callback sees that
    instruction's PC (not the block's first), for the board's order of mapping and rotations of it; the adjacent
    ranges share one hook (GPIOA, GPIOB, AFIO, EXTI and the one joining them: 40010000h to 400117FFh)."""
    order = RANGES[shift:] + RANGES[:shift]
    core, seen = _accesses(programs[cpu], cpu, order)
    read_at, write_at = core.image.address("read_at"), core.image.address("write_at")
    words = [(base, base + PERIPHERAL_SIZE - 4) for base in RANGES]
    expected = [(kind, address, pc) for address in itertools.chain(*words)
                for kind, pc in (("read", read_at), ("write", write_at))]  # fmt: skip
    assert seen == expected
    spans = sorted((first, last) for first, last, _ in core._exact_spans)
    assert spans == [(0x4001_0000, 0x4001_17FF), (0x4001_3000, 0x4001_33FF), (0x4002_1000, 0x4002_13FF),
                     (0xE000_E000, 0xE000_EFFF)]  # fmt: skip

"""The board port's busy wait (``board_delay_us`` in ``sdk/c/board/board.c``, MCU-62) on the emulated board:
``delay_us(k)`` lasts at least k µs and no more than the emulator's 4/3 of it (MCU-11) and a call's cost, with the
same shape on the Cortex-M3 and the Cortex-M0 (no run-time divide, which the M0 would call ``__aeabi_uidiv`` for).
``mcu/delay.c`` times each call with SysTick on the core clock (MCU-5).
"""

from __future__ import annotations

from pathlib import Path
from typing import Final

import pytest

from supi3.mcu import build as mcu_build
from supi3.mcu.board import Board

pytestmark = pytest.mark.skipif(mcu_build.toolchain_missing() is not None, reason=str(mcu_build.toolchain_missing()))

SOURCE: Final = Path(__file__).parent / "mcu" / "delay.c"
DELAYS: Final = 6
"""delay.c's DELAYS."""
CPU_HZ: Final = 48_000_000
"""The board's core clock and the port's ``BOARD_SYSCLK_HZ`` (MCU-7)."""
CALL_CYCLES: Final = CPU_HZ // 1_000_000
"""The most a call may cost beyond its iterations: the call through ``fw_board_t.delay_us``, the multiplication,
the loop's last iteration and SysTick's two reads, under a microsecond."""
EMULATED_ITERATION_CYCLES: Final = 4
"""MCU-11: an iteration of the countdown costs 4 cycles on the emulated core, the port counts 3 (the least on a real
Cortex-M3), so a wait lasts 4/3 of what it asks."""


def _words(board: Board, symbol: str) -> list[int]:
    core = board.core
    raw = core.read_bytes(core.image.address(symbol), 4 * DELAYS)
    return [int.from_bytes(raw[4 * k : 4 * k + 4], "little") for k in range(DELAYS)]


def _timed(elf: Path, cpu: str) -> list[tuple[int, int]]:
    """Each delay of delay.c's table and the core clocks its call took."""
    board = Board(elf, cpu=cpu, cpu_hz=CPU_HZ)
    board.run(1)  # the master starts once fw_setup has returned (MCU-45): its first cycle ends after the delays
    return list(zip(_words(board, "fw_delay_us"), _words(board, "fw_delay_cycles"), strict=True))


@pytest.fixture(scope="module")
def timed(tmp_path_factory: pytest.TempPathFactory) -> dict[str, list[tuple[int, int]]]:
    folder = tmp_path_factory.mktemp("delay")
    return {cpu: _timed(mcu_build.build(SOURCE, folder / f"delay_{cpu}.elf", cpu=cpu), cpu)
            for cpu in ("cortex_m3", "cortex_m0")}  # fmt: skip


@pytest.mark.parametrize("cpu", ["cortex_m3", "cortex_m0"])
def test_delay_us_lasts_at_least_its_time_and_close_to_it(timed: dict[str, list[tuple[int, int]]], cpu: str) -> None:
    """delay_us(k) for k = 0, 1, 4, 20, 100, 255: at least k µs, at most 4/3 k µs (the emulated iteration) and one
    more µs, on either core. Before MCU-62 the Cortex-M0's run-time division cost about 850 clocks more (a
    ``delay_us(4)`` of 23.6 µs)."""
    per_us = CPU_HZ // 1_000_000
    for us, cycles in timed[cpu]:
        assert us * per_us <= cycles <= us * per_us * EMULATED_ITERATION_CYCLES // 3 + CALL_CYCLES, (us, cycles)


def test_delay_us_costs_the_same_on_both_cores(timed: dict[str, list[tuple[int, int]]]) -> None:
    """The two cores' calls differ by less than a microsecond, whatever the delay: no cost that only one core pays."""
    for (us, m3), (_, m0) in zip(timed["cortex_m3"], timed["cortex_m0"], strict=True):
        assert abs(m3 - m0) < CALL_CYCLES, (us, m3, m0)

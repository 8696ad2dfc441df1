"""The core's native block and memory hooks and SPI1's held status (supi3.mcu.hook, hook.c; MCU-25).

MCU-25: the block hook, the empty memory hooks and the reads of a held register run in C built with the Zig
toolchain; the board does the same work to the cycle as with every block costed and every status read by Python
(each block's cost asked again: a cache of two slots; no register held), on both cores and at pin level. The build
lands in the cache once for parallel processes; no compiler, a source that does not compile, a cached file that does
not load and an unwritable cache are each a NativeHookError with the reason.
"""

from __future__ import annotations

import importlib.metadata
import os
import subprocess
import sys
from pathlib import Path

import pytest

from supi3.mcu import build as mcu_build
from supi3.mcu import core as mcu_core
from supi3.mcu import hook
from supi3.mcu.board import Board
from supi3.mcu.core import CPUS, CortexM
from supi3.sdk import native
from supi3.sdk.native import CACHE_ENV

pytestmark = pytest.mark.skipif(mcu_build.toolchain_missing() is not None, reason=str(mcu_build.toolchain_missing()))


@pytest.fixture(scope="module")
def digital_io(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """The digital 16/16 example built for each core, once per module."""
    folder = tmp_path_factory.mktemp("mcu")
    return {cpu: mcu_build.build(native.example("digital_io"), folder / f"digital_io_{cpu}.elf", cpu=cpu)
            for cpu in CPUS}  # fmt: skip


class NoHolder:
    """A board whose SPI holds nothing: every status read goes to the model."""

    def hold(self, offset: int, value: int, until: int | None, after: int | None) -> None:
        del offset, value, until, after

    def release(self) -> None:
        pass


def _count_status(board: Board) -> dict[str, int]:
    """A count of the SR reads that reach the SPI model (``Spi.status``), from now on."""
    counts = {"status": 0}
    status = board.spi.status

    def counted() -> int:
        counts["status"] += 1
        return status()

    board.spi.status = counted  # type: ignore[method-assign]
    return counts


def _outcome(board: Board) -> tuple[object, ...]:
    """Power-up, then four data cycles with process data both ways: what the firmware and the master saw."""
    board.run(3)
    board.bench.master.set_outputs(1, b"\x12\x34")
    assert board.fw_board is not None
    board.fw_board.inputs = b"\x56\x78"
    board.run(4)
    core = board.core
    return (core.cycles, core.instructions, core.registers(), board.bench.now, board.interrupts, board.irq_latency_s,
            board.fw_board.outputs, board.bench.master.inputs(1), board.violations)  # fmt: skip


@pytest.mark.parametrize("cpu", CPUS)
def test_the_native_shortcuts_change_nothing(digital_io: dict[str, Path], cpu: str,
                                             monkeypatch: pytest.MonkeyPatch) -> None:  # fmt: skip
    """MCU-25: the cached block costs and the held SR give the same cycles, instructions, registers, bus time,
    interrupts, latency and data as costing every block in Python again (a cache of two slots: nearly every block
    finds its slot taken) and as reading every SR in the model. The shortcuts are taken: fewer blocks reach
    Python, fewer SR reads reach the model."""
    described: list[int] = []
    describe = CortexM._describe

    def counted(self: CortexM, address: int, size: int) -> int:
        described.append(address)
        return describe(self, address, size)

    monkeypatch.setattr(CortexM, "_describe", counted)
    runs = []
    for slots, holding in ((mcu_core.BLOCK_CACHE_SLOTS, True), (2, True), (mcu_core.BLOCK_CACHE_SLOTS, False)):
        monkeypatch.setattr(mcu_core, "BLOCK_CACHE_SLOTS", slots)
        described.clear()
        board = Board(digital_io[cpu], cpu=cpu)
        if not holding:
            board.spi.holder = NoHolder()
        counts = _count_status(board)
        runs.append((_outcome(board), len(described), len(set(described)), counts["status"]))
    (cached, described_cached, distinct, status_held), (small, described_small, _, _), (plain, _, _, status) = runs
    assert cached == small == plain
    assert cached[6:8] == (b"\x12\x34\0\0", b"\x56\x78")
    assert described_cached == distinct < described_small  # each block asks Python once, unless its slot is taken
    assert status_held < status


def test_parallel_processes_build_the_hook_once(tmp_path: Path) -> None:
    """Three processes that find an empty cache build the library at the same time: each loads a whole file, the
    cache holds one, no temporary file is left."""
    env = {**os.environ, CACHE_ENV: str(tmp_path), "PYTHONPATH": os.pathsep.join(sys.path)}
    script = "from supi3.mcu import hook; print(hook.library()._name)"
    processes = [subprocess.Popen([sys.executable, "-c", script], env=env, stdout=subprocess.PIPE, text=True)
                 for _ in range(3)]  # fmt: skip
    paths = {process.communicate(timeout=120)[0].strip() for process in processes}
    assert all(process.returncode == 0 for process in processes)
    assert len(paths) == 1 and sorted(tmp_path.iterdir()) == [Path(paths.pop())]


def test_no_compiler_a_broken_source_or_a_broken_build_is_a_named_error(
        digital_io: dict[str, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:  # fmt: skip
    """MCU-25: the core needs the native hook; without ziglang, with a source that does not compile and with a
    cached file that is no library, building a core raises NativeHookError with the reason, and no file is left."""
    monkeypatch.setenv(CACHE_ENV, str(tmp_path / "cache"))
    monkeypatch.setattr(hook, "_LOADED", [])

    def missing(name: str) -> str:
        raise importlib.metadata.PackageNotFoundError(name)

    with monkeypatch.context() as patch:
        patch.setattr(importlib.metadata, "version", missing)
        with pytest.raises(hook.NativeHookError, match=r"ziglang is not installed: .*pip install supi3\[firmware\]"):
            Board(digital_io["cortex_m3"])
    broken = tmp_path / "hook.c"
    broken.write_text("void supi3_block_hook(void) { return 1; }\n")
    with monkeypatch.context() as patch:
        patch.setattr(hook, "SOURCE", broken)
        with pytest.raises(hook.NativeHookError, match=r"does not build \(MCU-25\).*\n.*error: void function"):
            CortexM(digital_io["cortex_m3"])
    assert list((tmp_path / "cache").iterdir()) == []
    hook.cached_path().write_bytes(b"not a library")
    with pytest.raises(hook.NativeHookError, match=r"_supi3_mcu_hook_\w+\.so does not load \(MCU-25\)"):
        CortexM(digital_io["cortex_m3"])
    unwritable = tmp_path / "file"
    unwritable.write_text("")
    monkeypatch.setenv(CACHE_ENV, str(unwritable / "cache"))
    with pytest.raises(hook.NativeHookError, match=r"cannot be built into .*file/cache \(MCU-25\)"):
        CortexM(digital_io["cortex_m3"])


def test_the_held_status_changes_nothing_at_pin_level(digital_io: dict[str, Path]) -> None:
    """MCU-25 at pin level, where a byte's end reads MISO from the pin-level chip (no value after the byte is held):
    power-up and the first data cycles give the same core cycles, instructions, registers, interrupts, latency and
    violations with SR held as with every SR read by the model, and fewer SR reads reach the model."""
    runs = []
    for holding in (True, False):
        board = Board(digital_io["cortex_m3"], fidelity="pin")
        if not holding:
            board.spi.holder = NoHolder()
        counts = _count_status(board)
        board.run(3)
        core = board.core
        runs.append(((core.cycles, core.instructions, core.registers(), board.interrupts, board.irq_latency_s,
                      board.violations), counts["status"]))  # fmt: skip
    assert runs[0][0] == runs[1][0]
    assert runs[0][1] < runs[1][1]

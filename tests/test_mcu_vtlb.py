"""MCU-89: the memory path without memory hooks (the exact-PC hooks as protection hooks over the peripherals, MCU-28's
flash write detection in the virtual TLB's fill, a fetch the default memory map refuses reported as before) shows
every run as the memory hooks did.

Each case below is run on this tree and compared with its fingerprint recorded on the tree before MCU-89 (commit
1c41125, ``python tests/test_mcu_vtlb.py --record tests/data/mcu_vtlb.json`` with that tree's ``src`` first on
``PYTHONPATH``): the bench cases of ``test_mcu_board.py``'s fingerprint and issue #13's ``digital_io`` at 2 Mbit/s
(SPI1 at f_PCLK / 16) and 500 kbit/s on both cores, with the native frames and without them (then every peripheral
access reaches Python, and each one's PC, block and cycle as the peripheral sees them is in the fingerprint); every
fault case of ``test_mcu_core.py`` (``mcu/fault_address.S``, ``mcu/faults.c``) and fetches, loads and stores at the
edges of the default memory map's Execute Never regions (B3.1, Table B3-1; ``mcu/vtlb_fetch.S``), each with its
report (type, reason, PC, stacked registers, fault status registers, the text) and the core's cycles, instructions
and active exceptions; and the firmware's stores into flash (MCU-28: ``mcu/flash_rewrite.S`` and ``mcu/vtlb_flash.S``,
stores in separate runs and one before a fault) step by step with a short deadline, each step's result, PC, cycles
and instructions. The fingerprints are pinned to the firmware the pinned ziglang builds (as ``test_mcu_board.py``'s).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import struct
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from functools import partial
from pathlib import Path
from typing import Any

import pytest
from unicorn import unicorn_const as ucc

from supi3.errors import Supi3Error
from supi3.mcu import build as mcu_build
from supi3.mcu.board import Board
from supi3.mcu.core import MAX_DEADLINE, CortexM, FirmwareError
from supi3.sdk import native

PROGRAMS = Path(__file__).parent / "mcu"
RECORDED = Path(__file__).parent / "data" / "mcu_vtlb.json"
CPUS = ("cortex_m0", "cortex_m3")
EDGES = (0x0000_0000, 0x3000_0000, 0x3FFF_FFFC, 0x4000_0000, 0x4001_0800, 0x4001_3000, 0x5000_0000, 0x5FFF_FFFC,
         0x6000_0000, 0x9FFF_FFFC, 0xA000_0000, 0xE000_0000, 0xE000_E100, 0xE000_EFFC, 0xFFFF_FFF8)  # fmt: skip
"""Addresses each side of the Execute Never regions' edges (B3.1), in mapped peripherals and SCS and unmapped."""


def _built(folder: Path, source: Path, name: str, cpu: str, **options: Any) -> Path:
    out = folder / f"{name}_{cpu}.elf"
    if not out.exists():
        mcu_build.build(source, out, cpu=cpu, **options)
    return out


@contextmanager
def _access_log(log: list[tuple[int, ...]]) -> Iterator[None]:
    """Cores built meanwhile note each peripheral access that reaches Python: read or write, address, size, value,
    the access's PC as the core hands it to the peripheral (MCU-1, MCU-25), its block's address and entry cycle."""
    mmio = CortexM.mmio

    def logged(self: CortexM, base: int, size: int, read: Any, write: Any, *, port: int | None = None) -> Any:
        state = self._state

        def on_read(offset: int, width: int) -> int:
            value = int(read(offset, width))
            log.append((0, base + offset, width, value, state.access_pc, state.block_address, state.block_start))
            return value

        def on_write(offset: int, width: int, value: int) -> None:
            log.append((1, base + offset, width, value, state.access_pc, state.block_address, state.block_start))
            write(offset, width, value)

        return mmio(self, base, size, on_read, on_write, port=port)

    CortexM.mmio = logged  # type: ignore[method-assign]
    try:
        yield
    finally:
        CortexM.mmio = mmio  # type: ignore[method-assign]


def _bench(folder: Path, cpu: str, bit_rate: int, native_frames: bool) -> dict[str, Any]:
    """``test_mcu_board.py``'s fingerprint run (issue #13's SPI1 at f_PCLK / 16 at 2 Mbit/s)."""
    defines = {"BOARD_SPI_BR": "3u"} if bit_rate == 2_000_000 else None
    elf = _built(folder, native.example("digital_io"), f"dio_{bit_rate}", cpu, defines=defines)
    log: list[tuple[int, ...]] = []
    with _access_log(log):
        board = Board(elf, cpu=cpu, bit_rate=bit_rate, strict=False, native_frames=native_frames)
    board.run(3)
    board.bench.master.set_outputs(1, b"\x12\x34")
    assert board.fw_board is not None
    board.fw_board.inputs = b"\xab\xcd"
    board.run(30)
    return {"cycles": board.core.cycles, "instructions": board.core.instructions, "interrupts": board.interrupts,
            "violations": [str(v) for v in board.violations],
            "data": [board.fw_board.outputs.hex(), board.bench.master.inputs(1).hex()],
            "accesses": len(log), "access_log": hashlib.sha256(repr(log).encode()).hexdigest()}  # fmt: skip


def _stopped(board: Board, error: FirmwareError) -> dict[str, Any]:
    report = error.report
    core = board.core
    return {"type": type(error).__name__, "text": str(error), "stop": report.stop.name, "reason": report.reason,
            "pc": report.pc, "stacked": report.stacked, "fault_status": report.fault_status, "cycles": core.cycles,
            "instructions": core.instructions, "active": core.active, "core_pc": core.pc}  # fmt: skip


def _fault_address(folder: Path, cpu: str, scenario: int) -> dict[str, Any]:
    """``test_mcu_core.py``'s ``fault_address.S`` scenarios (5: flash made read-only through unicorn first)."""
    elf = _built(folder, PROGRAMS / "fault_address.S", f"fa{scenario}", "cortex_m0", port=False,
                 defines={"SCENARIO": str(scenario)})  # fmt: skip
    board = Board(elf, cpu=cpu)
    if scenario == 5:
        board.core.uc.mem_protect(*board.core.flash, ucc.UC_PROT_READ | ucc.UC_PROT_EXEC)
    with pytest.raises(FirmwareError) as caught:
        board.run(1)
    return _stopped(board, caught.value)


def _faults_c(folder: Path, scenario: int) -> dict[str, Any]:
    """``test_mcu_core.py``'s ``faults.c`` scenarios: 1 bus fault, 2 budget, 3 hang in Default_Handler, 4 UDF."""
    elf = _built(folder, PROGRAMS / "faults.c", "faults", "cortex_m3")
    board = Board(elf)
    board.run_for(20e-6)
    board.core.write_bytes(board.core.image.address("scenario"), struct.pack("<I", scenario))
    runs: dict[int, Callable[[], None]] = {2: lambda: board.run(1000, max_instructions=50_000),
                                           3: lambda: board.run(10)}  # fmt: skip
    with pytest.raises(FirmwareError) as caught:
        runs.get(scenario, lambda: board.run_for(20e-6))()
    return _stopped(board, caught.value)


def _edge(folder: Path, cpu: str, kind: str, address: int) -> dict[str, Any]:
    """``vtlb_fetch.S``: a branch to ``address`` (``FETCH``), a word read (``LOAD``) or written (``STORE``) there."""
    target = address | 1 if kind == "FETCH" else address
    elf = _built(folder, PROGRAMS / "vtlb_fetch.S", f"{kind.lower()}_{address:08x}", "cortex_m0", port=False,
                 defines={kind: "1", "TARGET": f"{target:#x}"})  # fmt: skip
    board = Board(elf, cpu=cpu)
    try:
        board.run(1, max_instructions=20_000)
    except FirmwareError as error:
        return _stopped(board, error)
    except Supi3Error as error:  # a peripheral's own error (its clock off, say): where the core was
        return {"type": type(error).__name__, "text": str(error), "cycles": board.core.cycles,
                "instructions": board.core.instructions, "pc": board.core.pc}  # fmt: skip
    return {"ran": True, "cycles": board.core.cycles, "instructions": board.core.instructions, "pc": board.core.pc}


def _stepped(core: CortexM, step: int, limit: int = 400) -> list[Any]:
    """Each step with a deadline ``step`` cycles on (a report ends the list) until the core sits on ``b .``."""
    trace: list[Any] = []
    for _ in range(limit):
        try:
            result = core.step(min(MAX_DEADLINE, core.cycles + step))
        except FirmwareError as error:
            trace.append(["stopped", type(error).__name__, str(error), core.pc, core.cycles, core.instructions])
            continue  # the report entered HardFault: its handler runs next
        trace.append([result, core.pc, core.cycles, core.instructions])
        if core.idle_loop():
            break
    flash = core.read_bytes(core.flash[0], 0x1000)
    trace.append(hashlib.sha256(flash).hexdigest())
    return trace


def _flash(folder: Path, cpu: str, name: str, step: int, skip: bool) -> list[Any]:
    """MCU-28's stores into flash, step by step: where each run stops, what it costs."""
    core = CortexM(_built(folder, PROGRAMS / f"{name}.S", name, cpu, port=False), cpu=cpu)
    core.skip_polls = skip
    return _stepped(core, step)


def cases() -> dict[str, Callable[[Path], Any]]:
    """Every case's name and its run (a folder for the builds)."""
    found: dict[str, Callable[[Path], Any]] = {}
    for cpu in CPUS:
        for bit_rate in (2_000_000, 500_000):
            for frames in (True, False):
                found[f"bench {cpu} {bit_rate} {'native' if frames else 'python'}"] = partial(
                    _bench, cpu=cpu, bit_rate=bit_rate, native_frames=frames)  # fmt: skip
        for scenario in range(1, 6):
            found[f"fault_address {cpu} {scenario}"] = partial(_fault_address, cpu=cpu, scenario=scenario)
        for kind in ("FETCH", "LOAD", "STORE"):
            for address in EDGES:
                found[f"edge {cpu} {kind} {address:08X}"] = partial(_edge, cpu=cpu, kind=kind, address=address)
        found[f"edge {cpu} FETCH RAM"] = partial(_edge, cpu=cpu, kind="FETCH", address=0x2000_0000)
        for name in ("flash_rewrite", "vtlb_flash"):
            for step in (5, 40, MAX_DEADLINE):
                for skip in (True, False):
                    found[f"{name} {cpu} {step} {skip}"] = partial(_flash, cpu=cpu, name=name, step=step, skip=skip)
    for scenario in range(1, 5):
        found[f"faults.c {scenario}"] = partial(_faults_c, scenario=scenario)
    return found


def _plain(value: Any) -> Any:
    """As JSON keeps it (tuples as lists, keys as strings)."""
    return json.loads(json.dumps(value))


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("vtlb")


@pytest.fixture(scope="module")
def recorded() -> dict[str, Any]:
    return dict(json.loads(RECORDED.read_text()))


pytestmark = pytest.mark.skipif(mcu_build.toolchain_missing() is not None, reason=str(mcu_build.toolchain_missing()))


@pytest.mark.parametrize("name", list(cases()))
def test_every_run_shows_what_it_showed_before(folder: Path, recorded: dict[str, Any], name: str) -> None:
    """The case's fingerprint now is the one recorded before MCU-89 (see the module's docstring)."""
    assert _plain(cases()[name](folder)) == recorded[name]


def test_every_case_has_a_recorded_fingerprint(recorded: dict[str, Any]) -> None:
    assert sorted(recorded) == sorted(cases())


def test_a_peripheral_access_calls_no_python_of_the_core(folder: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The peripherals' protection events go to the exact-PC hook alone: the core's hook of invalid accesses (BFAR,
    MMFAR) watches the unmapped addresses and the protection of flash and RAM only, so issue #13's case never calls
    it (over the peripherals it would run at each of their accesses, before the exact-PC hook)."""
    calls: list[int] = []
    noted = CortexM._on_invalid_access

    def counted(self: CortexM, *arguments: Any) -> bool:
        calls.append(arguments[2])
        return noted(self, *arguments)

    monkeypatch.setattr(CortexM, "_on_invalid_access", counted)
    fingerprint = _bench(folder, "cortex_m3", 2_000_000, True)
    assert fingerprint["instructions"] > 50_000 and calls == []


def main() -> None:
    parser = argparse.ArgumentParser(description="record the fingerprints of tests/test_mcu_vtlb.py's cases")
    parser.add_argument("--record", type=Path, required=True, help="the JSON file to write")
    parser.add_argument("--folder", type=Path, required=True, help="a folder for the builds")
    args = parser.parse_args()
    args.folder.mkdir(parents=True, exist_ok=True)
    found = {name: _plain(run(args.folder)) for name, run in cases().items()}
    args.record.write_text(json.dumps(found, indent=1, sort_keys=True) + "\n")


if __name__ == "__main__":
    main()

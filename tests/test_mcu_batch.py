"""The exception entry's and return's register accesses in one call each (MCU-27; ARMv7-M B1.5.6, B1.5.8).

MCU-27: ``CortexM.enter`` reads CONTROL, SP, the frame's registers, xPSR and PC with one ``uc_reg_read_batch``, and
``exception_return`` writes the unstacked registers with xPSR, then SP and PC, with one ``uc_reg_write_batch`` each.
Over random register contents a batch reads what the single accesses read and writes what they write, in order (the
mode before the SP it selects); an entry and its return leave the registers, the frame in memory and the cycles as
the single accesses do (the same steps, spelt register by register, as before MCU-27).
"""

from __future__ import annotations

import struct
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from unicorn.arm_const import UC_ARM_REG_CONTROL, UC_ARM_REG_MSP, UC_ARM_REG_PSP, UC_ARM_REG_SP, UC_ARM_REG_XPSR

from supi3.mcu import build as mcu_build
from supi3.mcu import core as mcu_core
from supi3.mcu.core import CPUS, CortexM

pytestmark = pytest.mark.skipif(mcu_build.toolchain_missing() is not None, reason=str(mcu_build.toolchain_missing()))

EXCEPTIONS = Path(__file__).parent / "mcu" / "exceptions.S"


@pytest.fixture(scope="module")
def cores(tmp_path_factory: pytest.TempPathFactory) -> dict[str, CortexM]:
    """A core of each kind on exceptions.S (Thumb-1), once per module; each test example resets the registers."""
    elf = mcu_build.build(EXCEPTIONS, tmp_path_factory.mktemp("batch") / "exceptions.elf", cpu="cortex_m0",
                          port=False)  # fmt: skip
    return {cpu: CortexM(elf, cpu=cpu) for cpu in CPUS}


_WORD = st.integers(0, 0xFFFF_FFFF)
_GENERAL = [f"r{k}" for k in range(13)] + ["lr"]


def _single_enter(core: CortexM, number: int) -> int:
    """CortexM.enter as it was before MCU-27: each register read on its own (the same steps)."""
    control = core._read(UC_ARM_REG_CONTROL)
    process = bool(control & mcu_core.CONTROL_SPSEL) and not core.active
    sp = core._read(UC_ARM_REG_SP)
    words = [core._read(r) for r in mcu_core._FRAME_REGS]
    xpsr = core._read(UC_ARM_REG_XPSR)
    frame = (sp - mcu_core.FRAME_WORDS * 4) & ~7
    words += [core.pc, xpsr | (mcu_core.XPSR_ALIGN if sp & 4 else 0)]
    core.uc.mem_write(frame, struct.pack("<8I", *words))
    core._write(UC_ARM_REG_SP, frame)
    if process:
        core._write(UC_ARM_REG_CONTROL, control & ~mcu_core.CONTROL_SPSEL)
    exc_return = mcu_core.EXC_RETURN_HANDLER if core.active else mcu_core.EXC_RETURN_THREAD_PSP if process \
        else mcu_core.EXC_RETURN_THREAD_MSP  # fmt: skip
    core._take(number, exc_return, frame, core.cpu.entry_cycles)
    return frame


def _state(core: CortexM) -> tuple[object, ...]:
    """The registers, both stack pointers, the cycles, the active exceptions and the top KiB of RAM (both stacks)."""
    end = core.ram[0] + core.ram[1]
    return (core.registers(), core.reg("control"), core.reg("msp"), core.reg("psp"), core.cycles, list(core.active),
            core.read_bytes(end - 1024, 1024))  # fmt: skip


@settings(derandomize=True, max_examples=60, deadline=None)
@given(st.sampled_from(sorted(CPUS)), st.lists(_WORD, min_size=len(_GENERAL), max_size=len(_GENERAL)),
       st.integers(0, 15), st.booleans(), st.booleans(), st.sampled_from([15, mcu_core.EXTERNAL + 6]))  # fmt: skip
def test_a_batched_entry_and_return_are_the_single_accesses(
    cores: dict[str, CortexM], cpu: str, values: list[int], depth: int, process: bool, nested: bool, number: int
) -> None:
    """MCU-27: from random registers, stack depths (word-aligned, so the alignment word comes and goes) and stacks
    (main or process in thread mode), an entry (SysTick or EXTI0) with batched reads stacks the same frame and leaves
    the same registers, cycles and active list as one with single reads; its return with batched writes restores
    what was there before the entry. MCU-70, MCU-71: the native traffic (one call each, the default) does the same,
    also with a HardFault entered and returned from inside the handler (a nested frame, EXC_RETURN to handler
    mode)."""
    core = cores[cpu]
    results = []
    for path in ("native", "batched", "single"):
        core.native_exceptions = path == "native"
        core.reset()
        core.active.clear()
        core.cycles = 0
        core.write_bytes(core.ram[0] + core.ram[1] - 1024, bytes(1024))  # no frame of the path before (nested)
        for name, value in zip(_GENERAL, values, strict=True):
            core.set_reg(name, value)
        top = core.ram[0] + core.ram[1] - 4 * depth
        core._write(UC_ARM_REG_PSP, top - 512)
        core._write(UC_ARM_REG_MSP, top)
        if process:
            core._write(UC_ARM_REG_CONTROL, mcu_core.CONTROL_SPSEL)
        before = _state(core)
        enter = _single_enter if path == "single" else CortexM.enter
        frame = enter(core, number)
        entered = [_state(core), frame]
        if nested:
            entered += [enter(core, mcu_core.HARDFAULT), _state(core)]
            core.exception_return(core.reg("lr"))
            entered.append(_state(core))
            core.cycles -= core.cpu.return_cycles + core.cpu.entry_cycles
        core.exception_return(core.reg("lr"))
        core.cycles -= core.cpu.return_cycles + core.cpu.entry_cycles
        results.append((entered, _state(core)[:-1] == before[:-1]))  # the frame stays in RAM below the SP
    core.native_exceptions = True
    assert results[0] == results[1] == results[2]
    assert results[0][1]

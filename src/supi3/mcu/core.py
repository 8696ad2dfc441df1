"""A Cortex-M core on unicorn: memory map, ELF loading, the timing model, exceptions, SysTick and the NVIC.

Ref: ARMv7-M Architecture Reference Manual (ARM DDI 0403): B1.5 (exception model: B1.5.6 entry, B1.5.7 stack
alignment, B1.5.8 return), B3.2 (SCB), B3.3 (SysTick), B3.4 (NVIC); ARMv6-M (ARM DDI 0419) for the Cortex-M0;
Cortex-M3 Technical Reference Manual (ARM DDI 0337): instruction timing, interrupt latency. Guide:
docs/firmware-in-the-loop.md; decisions MCU-n in docs/assumptions/mcu.md.

unicorn 2 runs Thumb code of an M-profile core but has no NVIC: it neither enters an exception nor returns from one
(a branch to an EXC_RETURN value only raises its internal "exception exit", number :data:`EXCP_EXCEPTION_EXIT`, and
then loops on a prefetch abort). :class:`CortexM` does both itself, as the architecture says (B1.5.6, B1.5.8).

Timing (MCU-1): every basic block unicorn enters costs its instructions' cycles (:func:`block_cost`: one per
instruction, one more per single load or store, one per register of a multiple load or store, two more for a
branch that ends the block, taken as taken), so the clock is exact at block boundaries; a peripheral access is
placed inside its block by the program counter (:meth:`CortexM.cycles_now`; unicorn keeps the PC exact at an
access only under a memory or protection hook: the peripherals are mapped inaccessible, each run of them has a
protection hook that lets the access go on, MCU-89). Emulation only ever stops at a block
boundary (a block hook refuses the next block), because unicorn restarts an instruction stopped inside a memory
callback and a peripheral would see its access twice.

Speed (MCU-19): the peripheral callbacks and the register reads they need go to unicorn's C library through ctypes
directly; the binding's wrappers around each call cost as much again as the call. The block hook, the exact-PC hooks
and the virtual TLB's fill are native code (MCU-25, MCU-89, :mod:`supi3.mcu.hook`): a block in flash calls Python only
the first time it runs (one in RAM each time it runs, MCU-28). No memory hook is set: any one sends every guest load
and store through unicorn's slow path (MCU-87); the fill notes the firmware's stores into flash (MCU-28) instead.
"""

from __future__ import annotations

import bisect
import ctypes
import struct
from collections.abc import Callable
from dataclasses import dataclass
from enum import StrEnum
from functools import cached_property
from os import PathLike
from pathlib import Path
from typing import Any, Final

import unicorn
from unicorn import arm_const as arm
from unicorn import unicorn_const as ucc

from supi3.checks import check_bool, check_bytes, check_int, check_real, fail
from supi3.errors import ArgumentError, Supi3Error
from supi3.mcu import hook

_UNICORN: Any = unicorn  # typed, but its Uc methods are not annotated
UcError: type[Exception] = _UNICORN.UcError
_LIB: Any = _UNICORN.unicorn_py3.unicorn.uclib
"""unicorn's C library as its binding loaded it (with the argument types it declares): the hot callbacks and
register accesses go to it directly (MCU-19), without the binding's wrappers around each call."""
# Callback types of unicorn.h (uc_cb_hookcode_t, uc_cb_eventmem_t; mmio reads and writes: hook.MMIO_READ, MMIO_WRITE).
_HOOK_CODE: Final = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_uint64, ctypes.c_uint32, ctypes.c_void_p)
_HOOK_MEM_INVALID: Final = ctypes.CFUNCTYPE(ctypes.c_bool, ctypes.c_void_p, ctypes.c_int, ctypes.c_uint64, ctypes.c_int,
                                            ctypes.c_int64, ctypes.c_void_p)  # fmt: skip

__all__ = [
    "CPUS",
    "EXC_RETURN_HANDLER",
    "EXC_RETURN_THREAD_MSP",
    "EXC_RETURN_THREAD_PSP",
    "IDLE_LOOP",
    "CortexM",
    "Cpu",
    "FirmwareError",
    "FirmwareFaultError",
    "FirmwareImage",
    "FirmwareStoppedError",
    "Frame",
    "HeldRegister",
    "SourceLine",
    "Stop",
    "StopReport",
    "SysTick",
    "block_cost",
    "check_cpu",
    "countdown_register",
    "idle_loops",
    "is_poll_loop",
]

EXCP_EXCEPTION_EXIT: Final[int] = 8
"""unicorn's interrupt number for a branch to an EXC_RETURN value in handler mode (QEMU's EXCP_EXCEPTION_EXIT)."""
EXCP_SWI: Final[int] = 2
EXCP_PREFETCH_ABORT: Final[int] = 3
"""unicorn's interrupt number for an instruction fetch it cannot make (QEMU's EXCP_PREFETCH_ABORT): from a peripheral
callback's region, or from some unmapped addresses (0). MCU-89: a fetch the virtual TLB's fill refuses (Execute Never)
ends the run with UC_ERR_EXCEPTION, the fill noting this number, and is taken as this interrupt."""
EXECUTE_NEVER: Final[tuple[tuple[int, int], ...]] = ((0x4000_0000, 0x6000_0000), (0xA000_0000, 0x1_0000_0000))
"""The Execute Never regions of the default memory map (B3.1, Table B3-1: Peripheral, Device, System): a fetch there
is a MemManage fault (IACCVIOL)."""
EXCP_BKPT: Final[int] = 7
EXC_RETURN_HANDLER: Final[int] = 0xFFFF_FFF1
"""Return to handler mode, main stack (B1.5.8, Table B1-8)."""
EXC_RETURN_THREAD_MSP: Final[int] = 0xFFFF_FFF9
"""Return to thread mode, main stack."""
EXC_RETURN_THREAD_PSP: Final[int] = 0xFFFF_FFFD
"""Return to thread mode, process stack."""
FRAME_WORDS: Final[int] = 8
"""The basic stack frame: R0-R3, R12, LR, return address, xPSR (B1.5.6)."""
XPSR_T: Final[int] = 1 << 24
XPSR_ALIGN: Final[int] = 1 << 9
"""Stacked xPSR bit 9: the frame was aligned to 8 bytes by one more word (B1.5.7)."""
CONTROL_SPSEL: Final[int] = 1 << 1

HARDFAULT: Final[int] = 3
SVCALL: Final[int] = 11
PENDSV: Final[int] = 14
SYSTICK: Final[int] = 15
EXTERNAL: Final[int] = 16
"""Exception number of IRQ 0 (B1.5.2)."""
MAX_EXCEPTION: Final[int] = 511
"""ARMv7-M B1.5.2: exception numbers up to 16 + 495 external interrupts (ARMv6-M has fewer; the NVIC ignores more)."""
EXCEPTION_NAMES: Final[dict[int, str]] = {1: "Reset", 2: "NMI", 3: "HardFault", 4: "MemManage", 5: "BusFault",
                                          6: "UsageFault", 11: "SVCall", 12: "DebugMonitor", 14: "PendSV",
                                          15: "SysTick"}  # fmt: skip

SCS_BASE: Final[int] = 0xE000_E000
SCS_SIZE: Final[int] = 0x1000
_PAGE: Final[int] = 0x1000
"""The emulator maps memory in 4 KiB pages: a memory's base and size are multiples of it."""
IDLE_LOOP: Final[bytes] = b"\xfe\xe7"
"""``b .``, a branch to itself (B T2 with offset -4: E7FEh), MCU-4."""
_ADDRESS_SPACE: Final[int] = 1 << 32
SYST_MAX: Final[int] = 0xFF_FFFF
"""SysTick is a 24-bit down counter (B3.3.1)."""
BACKTRACE_DEPTH: Final[int] = 16
"""Frames :meth:`CortexM.backtrace` unwinds at most."""
BACKTRACE_MEMO: Final[int] = 64
"""MCU-83: the PCs (with a depth) whose call stacks :meth:`CortexM.backtrace` keeps, :data:`BACKTRACE_STACKS` each
(the memo is emptied when a new one would pass it: a firmware's violations come from a few places)."""
BACKTRACE_STACKS: Final[int] = 8
"""MCU-83: the call stacks kept per PC, the latest (a PC is reached from a few callers)."""
_STACK_BYTES: Final[int] = 1024
"""MCU-83: the widest span of stack words a kept call stack compares in one read (a wider unwinding is not kept)."""
BLOCK_CACHE_SLOTS: Final[int] = 1 << 13
PREFIX_SLOTS: Final[int] = 1 << 10
"""MCU-51: the slots of the native memo of :meth:`CortexM.cycles_now`'s prefix costs (a power of two; a PC whose slot
another took is timed by Python, through the slow path)."""
"""Slots of the native block hook's cost cache (MCU-25), one per halfword address modulo their number: 16 KiB of
code without two blocks sharing a slot (a block that finds its slot taken asks Python again)."""
IRQ_LINES: Final[int] = 32
"""External interrupts the NVIC model has (one ISER word)."""
CFSR: Final[int] = 0xD28
"""Configurable Fault Status Register, offset in the SCS (B3.2.15): MMFSR bits 0-7, BFSR 8-15, UFSR 16-31."""
HFSR: Final[int] = 0xD2C
"""HardFault Status Register (B3.2.16)."""
HFSR_FORCED: Final[int] = 1 << 30
"""A configurable fault escalated to HardFault: its handler is disabled (SHCSR, as from reset; MCU-3)."""
MMFAR: Final[int] = 0xD34
"""MemManage Fault Address Register, offset in the SCS (B3.2.17): the data address of a DACCVIOL."""
BFAR: Final[int] = 0xD38
"""BusFault Address Register (B3.2.18): the data address of a precise bus fault."""
PRECISERR: Final[int] = 1 << 9
DACCVIOL: Final[int] = 1 << 1
IACCVIOL: Final[int] = 1 << 0
_FAULT_ADDRESS: Final[dict[int, tuple[str, int, int]]] = {PRECISERR: ("BFAR", BFAR, 1 << 15),  # BFSR.BFARVALID
                                                          DACCVIOL: ("MMFAR", MMFAR, 1 << 7)}  # MMFSR.MMARVALID
"""The faults that load an address register (B3.2.15): the CFSR bit, the register's name, offset and valid bit. An
instruction fetch fault (IBUSERR, IACCVIOL) loads none."""
_FAULTS: Final[dict[int, tuple[str, int]]] = {
    ucc.UC_ERR_READ_UNMAPPED: ("precise bus fault: read of unmapped memory", PRECISERR),  # BFSR.PRECISERR
    ucc.UC_ERR_WRITE_UNMAPPED: ("precise bus fault: write to unmapped memory", PRECISERR),
    ucc.UC_ERR_FETCH_UNMAPPED: ("instruction bus fault: fetch from unmapped memory (run-away PC)", 1 << 8),  # IBUSERR
    ucc.UC_ERR_INSN_INVALID: ("usage fault: undefined instruction", 1 << 16),  # UFSR.UNDEFINSTR
    ucc.UC_ERR_READ_UNALIGNED: ("usage fault: unaligned read", 1 << 24),  # UFSR.UNALIGNED
    ucc.UC_ERR_WRITE_UNALIGNED: ("usage fault: unaligned write", 1 << 24),
    ucc.UC_ERR_FETCH_PROT: ("memory fault: execute from a non-executable region", IACCVIOL),  # MMFSR.IACCVIOL
    ucc.UC_ERR_WRITE_PROT: ("memory fault: write to read-only memory", DACCVIOL),  # MMFSR.DACCVIOL
}
"""unicorn's error of a fault: the report's reason and the CFSR bit the core sets (B3.2.15)."""


@dataclass(frozen=True)
class Cpu:
    """A core variant: unicorn's CPU model, CPUID (B3.2.3) and its exception entry and return cycles (MCU-2)."""

    name: str
    model: int
    cpuid: int
    entry_cycles: int
    return_cycles: int
    vtor: bool
    fault_status: bool
    """The core has CFSR and HFSR (ARMv7-M B3.2.15, B3.2.16; ARMv6-M has neither)."""
    tail_chain_cycles: int
    """From an exception return to the next handler's first instruction when a pending exception is taken at once,
    without unstacking and stacking again (tail-chaining, MCU-20)."""


CPUS: Final[dict[str, Cpu]] = {
    # Cortex-M3: 12 cycles from the interrupt to the handler's first instruction, return 10 (MCU-2).
    "cortex_m3": Cpu("cortex_m3", arm.UC_CPU_ARM_CORTEX_M3, 0x412F_C231, 12, 10, vtor=True, fault_status=True,
                     tail_chain_cycles=6),
    # Cortex-M0: 16 cycles interrupt latency, the return taken as long (MCU-2). ARMv6-M: no VTOR.
    "cortex_m0": Cpu("cortex_m0", arm.UC_CPU_ARM_CORTEX_M0, 0x410C_C200, 16, 16, vtor=False, fault_status=False,
                     tail_chain_cycles=16),
}
"""The cores :class:`CortexM` emulates, by their ``-mcpu`` names."""


def check_cpu(cpu: object) -> str:
    """``cpu`` if it names a core of :data:`CPUS`; else an :class:`ArgumentError`."""
    if isinstance(cpu, str) and cpu in CPUS:
        return cpu
    raise fail("cpu", f"one of {', '.join(CPUS)}", cpu)


_REGS: Final[tuple[tuple[str, int], ...]] = (
    *((f"r{k}", getattr(arm, f"UC_ARM_REG_R{k}")) for k in range(13)),
    ("sp", arm.UC_ARM_REG_SP), ("lr", arm.UC_ARM_REG_LR), ("pc", arm.UC_ARM_REG_PC), ("xpsr", arm.UC_ARM_REG_XPSR),
)  # fmt: skip
_LOW_REGS: Final[tuple[int, ...]] = tuple(getattr(arm, f"UC_ARM_REG_R{k}") for k in range(8))
_FRAME_REGS: Final[tuple[int, ...]] = (arm.UC_ARM_REG_R0, arm.UC_ARM_REG_R1, arm.UC_ARM_REG_R2, arm.UC_ARM_REG_R3,
                                       arm.UC_ARM_REG_R12, arm.UC_ARM_REG_LR)  # fmt: skip
_ENTRY_READS: Final[tuple[int, ...]] = (arm.UC_ARM_REG_CONTROL, arm.UC_ARM_REG_SP, *_FRAME_REGS, arm.UC_ARM_REG_XPSR,
                                        arm.UC_ARM_REG_PC)  # fmt: skip
"""What an exception entry reads (B1.5.6), in one call (MCU-19)."""
_UNSTACK_WRITES: Final[tuple[int, ...]] = (*_FRAME_REGS, arm.UC_ARM_REG_XPSR)
"""What an exception return writes from the frame, the mode last (it selects the SP), in one call (B1.5.8)."""
_RESUME_WRITES: Final[tuple[int, ...]] = (arm.UC_ARM_REG_SP, arm.UC_ARM_REG_PC)
"""An exception return's SP and PC, after the mode, in one call."""
_UNWIND_READS: Final[tuple[int, ...]] = (*(getattr(arm, f"UC_ARM_REG_R{n}") for n in range(13)), arm.UC_ARM_REG_SP,
                                         arm.UC_ARM_REG_LR)  # fmt: skip
"""What :meth:`CortexM.backtrace` starts from, R0 to R12, SP, LR, in one call (MCU-31: a violation's note)."""
FRAME_NAMES: Final[tuple[str, ...]] = ("r0", "r1", "r2", "r3", "r12", "lr", "pc", "xpsr")
"""The stacked frame's words in address order (B1.5.6)."""


# ------------------------------------------------------------------------------------------------------------
# Reports
# ------------------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class SourceLine:
    """A place in the firmware's source, from the ELF's DWARF line program (``.debug_line``)."""

    path: str
    """The file as the compiler named it (its directory joined)."""
    line: int

    @property
    def file(self) -> str:
        """The file's name without its directory."""
        return Path(self.path).name

    def __str__(self) -> str:
        return f"{self.file}:{self.line}"


@dataclass(frozen=True)
class Frame:
    """One frame of the firmware's call stack: the address running (innermost) or returned to, its function and
    its source line (for a return address: the line of the call)."""

    pc: int
    function: str | None
    source: SourceLine | None

    def __str__(self) -> str:
        name = f"{self.function}()" if self.function else f"{self.pc:08X}h"
        return name + (f" {self.source}" if self.source else "")


class Stop(StrEnum):
    """Why a run of the firmware ended before its goal."""

    FAULT = "fault"
    BUDGET = "budget"
    HANG = "hang"


@dataclass(frozen=True)
class StopReport:
    """What the core looked like when a run ended early: the why, the registers and, for a fault, the frame the
    core stacked when it took the HardFault (what a debugger shows in the fault handler)."""

    stop: Stop
    reason: str
    pc: int
    registers: dict[str, int]
    instructions: int
    cycles: int
    time_s: float
    stacked: dict[str, int] | None = None
    symbol: str | None = None
    backtrace: tuple[Frame, ...] = ()
    """The call stack at :attr:`pc`, innermost first (DWARF call frame information), up to an exception entry."""
    fault_status: dict[str, int] | None = None
    """For a fault on an ARMv7-M core: CFSR and HFSR as its HardFault handler would read them (B3.2.15, B3.2.16)."""

    @property
    def source(self) -> SourceLine | None:
        """The source line of :attr:`pc`."""
        return self.backtrace[0].source if self.backtrace else None

    def __str__(self) -> str:
        where = f"PC {self.pc:08X}h" + (f" ({self.symbol})" if self.symbol else "")
        where += f" {self.source}" if self.source else ""
        text = f"{self.stop.value}: {self.reason} at {where}, t = {self.time_s * 1e6:.3f} µs, " \
               f"{self.instructions} instructions"  # fmt: skip
        if len(self.backtrace) > 1:
            text += "; called from " + " <- ".join(str(frame) for frame in self.backtrace[1:])
        if self.stacked is not None:
            text += "; stacked " + " ".join(f"{name}={value:08X}h" for name, value in self.stacked.items())
        if self.fault_status is not None:
            text += "; " + " ".join(f"{name}={value:08X}h" for name, value in self.fault_status.items())
        return text


class FirmwareError(Supi3Error, RuntimeError):
    """The firmware did not reach the run's goal; :attr:`report` says why and where."""

    def __init__(self, report: StopReport) -> None:
        self.report = report
        super().__init__(str(report))


class FirmwareFaultError(FirmwareError):
    """The core faulted (bus error, undefined instruction, bad state): the HardFault frame is in the report."""


class FirmwareStoppedError(FirmwareError):
    """The run's instruction budget ran out, the firmware hung in a handler, or it needs what is not modelled."""


# ------------------------------------------------------------------------------------------------------------
# The firmware image
# ------------------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class FirmwareImage:
    """An ELF firmware: its loadable segments (physical addresses), entry point and symbols (pyelftools)."""

    path: Path
    segments: tuple[tuple[int, bytes], ...]
    entry: int
    symbols: dict[str, tuple[int, int]]
    """name -> (address, size) of the functions, objects and labels; Thumb functions without their bit 0."""

    @classmethod
    def load(cls, path: str | Path) -> FirmwareImage:
        """Read ``path``; raises :class:`ArgumentError` if it is not a 32-bit little-endian ARM ELF."""
        from elftools.common.exceptions import ELFError
        from elftools.elf.elffile import ELFFile
        from elftools.elf.sections import SymbolTableSection

        if not isinstance(path, str | PathLike):
            raise fail("path", "a path (str or os.PathLike)", path)
        path = Path(path)
        try:
            with path.open("rb") as stream:
                elf = ELFFile(stream)
                if elf["e_machine"] != "EM_ARM" or elf.elfclass != 32 or not elf.little_endian:
                    raise ArgumentError("path", path, f"path must be a 32-bit little-endian ARM ELF, not {path}")
                segments = tuple(_segment(path, seg) for seg in elf.iter_segments()
                                 if seg["p_type"] == "PT_LOAD" and seg["p_filesz"])  # fmt: skip
                table = elf.get_section_by_name(".symtab")
                symbols = {} if not isinstance(table, SymbolTableSection) else {
                    sym.name: (int(sym["st_value"]) & ~1 if sym["st_info"]["type"] == "STT_FUNC"
                               else int(sym["st_value"]), int(sym["st_size"]))
                    for sym in table.iter_symbols()
                    if sym.name and not sym.name.startswith("$") and sym["st_shndx"] != "SHN_UNDEF"
                    and sym["st_info"]["type"] in ("STT_FUNC", "STT_OBJECT", "STT_NOTYPE")
                }  # fmt: skip
                if not segments:
                    raise ArgumentError("path", path, f"path must be an ELF with a loadable segment, not {path}")
                return cls(path, segments, int(elf["e_entry"]), symbols)
        except (OSError, ELFError) as error:
            raise ArgumentError("path", path, f"path must be a readable ELF file, not {path} ({error})") from error

    def address(self, name: str) -> int:
        """The address of symbol ``name``; :class:`ArgumentError` if the firmware has none."""
        try:
            return self.symbols[name][0]
        except KeyError:
            raise ArgumentError("name", name, f"name must be a symbol of {self.path.name}, not {name!r}") from None

    def function_at(self, pc: int) -> str | None:
        """The function whose code holds ``pc``, if the symbol table says (the first such symbol; remembered per
        address: a violation's backtrace asks for the same few, MCU-31)."""
        memo = self._functions
        if pc in memo:
            return memo[pc]
        found = memo[pc] = next((name for name, (address, size) in self.symbols.items()
                                 if address <= pc < address + max(size, 1)), None)  # fmt: skip
        return found

    @cached_property
    def _functions(self) -> dict[int, str | None]:
        return {}

    def line_at(self, pc: int) -> SourceLine | None:
        """The source line of the instruction at ``pc`` from the DWARF line program, if the ELF has one (built with
        ``-g``: :func:`supi3.mcu.build.build` does)."""
        addresses, lines = self._lines
        k = bisect.bisect_right(addresses, pc) - 1
        return lines[k] if k >= 0 else None

    def frame_rule(self, pc: int) -> tuple[int, int, dict[int, int]] | None:
        """How to find the caller of the code at ``pc`` (DWARF ``.debug_frame``): (CFA register, CFA offset,
        {register: offset from the CFA of its saved copy}); ``None`` where the ELF has no call frame information."""
        starts, entries = self._frames
        k = bisect.bisect_right(starts, pc) - 1
        if k < 0 or pc >= entries[k][0]:
            return None
        rows = entries[k][1]
        row = rows[bisect.bisect_right([r[0] for r in rows], pc) - 1]
        return row[1], row[2], row[3]

    @cached_property
    def _lines(self) -> tuple[list[int], list[SourceLine | None]]:
        return self._debug[0]

    @cached_property
    def _frames(self) -> _FrameTable:
        return self._debug[1]

    @cached_property
    def _debug(self) -> tuple[tuple[list[int], list[SourceLine | None]], _FrameTable]:
        """The line table and the call frame information, read on first use; empty if the ELF has no DWARF or can
        no longer be read (the reports then name no lines)."""
        from elftools.common.exceptions import DWARFError, ELFError
        from elftools.elf.elffile import ELFFile

        try:
            with self.path.open("rb") as stream:
                elf = ELFFile(stream)
                dwarf = elf.get_dwarf_info() if elf.has_dwarf_info() else None
                return _line_table(dwarf), _frame_table(dwarf)
        except (OSError, ELFError, DWARFError):
            return ([], []), ([], [])


_FrameRow = tuple[int, int, int, dict[int, int]]
_FrameTable = tuple[list[int], list[tuple[int, list[_FrameRow]]]]


def _line_table(dwarf: Any) -> tuple[list[int], list[SourceLine | None]]:
    """The line program's rows: sorted addresses and the line starting at each (``None``: a sequence ends there)."""
    rows: list[tuple[int, int, SourceLine | None]] = []
    for unit in dwarf.iter_CUs() if dwarf is not None else ():
        program = dwarf.line_program_for_CU(unit)
        if program is None:
            continue
        header = program.header
        v5 = header["version"] >= 5  # DWARF 5 counts files and directories from 0, DWARF 4 from 1
        top = unit.get_top_DIE().attributes.get("DW_AT_comp_dir")
        folders = [top.value.decode() if top else ""] * (not v5)
        folders += [bytes(d).decode() for d in header["include_directory"]]
        files = [str(Path(folders[f.dir_index]) / bytes(f.name).decode()) for f in header["file_entry"]]
        for entry in program.get_entries():
            state = entry.state
            if state is None:
                continue
            if state.end_sequence or not state.line:
                rows.append((state.address, 0, None))
            else:
                rows.append((state.address, 1, SourceLine(files[state.file - (not v5)], state.line)))
    rows.sort(key=lambda row: row[:2])
    return [row[0] for row in rows], [row[2] for row in rows]


def _frame_table(dwarf: Any) -> _FrameTable:
    """The call frame information: sorted function starts and, per function, its end and its rows (address, CFA
    register, CFA offset, saved registers)."""
    from elftools.dwarf.callframe import FDE, RegisterRule

    functions: list[tuple[int, int, list[_FrameRow]]] = []
    for entry in dwarf.CFI_entries() if dwarf is not None and dwarf.has_CFI() else ():
        if not isinstance(entry, FDE):
            continue
        start = int(entry["initial_location"])
        rows = [(int(row["pc"]), int(row["cfa"].reg), int(row["cfa"].offset),
                 {int(reg): int(rule.arg) for reg, rule in row.items()
                  if isinstance(reg, int) and rule.type == RegisterRule.OFFSET})
                for row in entry.get_decoded().table if row["cfa"].reg is not None]  # fmt: skip
        if rows:
            functions.append((start, start + int(entry["address_range"]), rows))
    functions.sort(key=lambda f: f[0])
    return [f[0] for f in functions], [(f[1], f[2]) for f in functions]


# ------------------------------------------------------------------------------------------------------------
# The timing model (MCU-1)
# ------------------------------------------------------------------------------------------------------------


def _register(name: object) -> int:
    """Unicorn's number of the register ``name`` (``r0``, ``sp``, ``primask``, ...); else an ArgumentError."""
    number = getattr(arm, f"UC_ARM_REG_{name.upper()}", None) if isinstance(name, str) and name.isalnum() else None
    if not isinstance(number, int):
        raise fail("name", "a register name (r0..r12, sp, lr, pc, xpsr, msp, psp, primask, control, ...)", name)
    return number


def _segment(path: Path, segment: Any) -> tuple[int, bytes]:
    """A loadable segment of an ELF file as (physical address, bytes); a file cut short inside it is an
    :class:`ArgumentError`, never a part of it run (MCU-47)."""
    data = bytes(segment.data())
    if len(data) != segment["p_filesz"]:
        raise ArgumentError("path", path, f"path must be an ELF file that holds its segments, not {path} (the "
                            f"segment at {segment['p_paddr']:#x} has {segment['p_filesz']} bytes in the file, "
                            f"{len(data)} there)")  # fmt: skip
    return int(segment["p_paddr"]), data


def _check_memories(image: FirmwareImage, flash: object, ram: object) -> None:
    """Refuse memories the emulator cannot map (whole pages within the address space, apart from each other and
    from the system control space) and an image with a segment outside them, by name."""
    mapped: list[tuple[int, int]] = [(SCS_BASE, SCS_SIZE)]
    for name, region in (("flash", flash), ("ram", ram)):
        if not (isinstance(region, tuple) and len(region) == 2
                and all(type(v) is int and v >= 0 and not v % _PAGE for v in region)
                and 0 < region[1] <= _ADDRESS_SPACE - region[0]
                and not any(region[0] < base + size and base < region[0] + region[1] for base, size in mapped)):
            raise fail(name, f"a (base, size) of whole {_PAGE}-byte pages, apart from the other memories", region)
        mapped.append(region)
    for address, data in image.segments:
        if not any(base <= address and address + len(data) <= base + size for base, size in mapped[1:]):
            raise fail("image", f"a firmware whose segments lie in flash {flash} or RAM {ram}",
                       f"a segment at {address:#x}, {len(data)} bytes")


def _is_32bit(halfword: int) -> bool:
    return (halfword >> 11) in (0b11101, 0b11110, 0b11111)


def _cost(first: int, second: int | None) -> tuple[int, bool]:
    """Cycles of one instruction (MCU-1), and whether it is a branch."""
    if second is None:
        if (first >> 11) == 0b01001 or (first >> 12) in (0b0101, 0b1000, 0b1001) or (first >> 13) == 0b011:
            return 2, False  # LDR literal, LDR/STR register, immediate, halfword, SP-relative
        if (first & 0xF600) == 0xB400:  # PUSH / POP
            pc = (first & 0xFF00) == 0xBD00
            return 1 + bin(first & 0x1FF).count("1"), pc
        if (first >> 12) == 0b1100:  # LDM / STM
            return 1 + bin(first & 0xFF).count("1"), False
        branch = ((first >> 12) == 0b1101 and (first >> 9) & 0b111 != 0b111) or (first >> 11) == 0b11100 \
            or (first & 0xFF00) == 0x4700 or (first & 0xF500) == 0xB100  # fmt: skip
        return 1, branch
    if (first >> 9) == 0b1111100:  # load / store single (32-bit encodings)
        return 2, False
    if (first >> 9) == 0b1110100:  # LDM / STM (32-bit)
        return 1 + bin(second & 0xDFFF).count("1"), bool(second & 0x8000) and bool(first & 0x10)
    if (first >> 11) != 0b11110 or not second & 0x8000:
        return 1, False
    # B.W and BL (second[12] or second[14] set), B<c>.W unless its condition field is 111x (MSR, MRS, hints)
    return 1, bool(second & 0x5000) or (first >> 7) & 0b111 != 0b111


def is_poll_loop(code: bytes, address: int) -> bool:
    """The block ``code`` at ``address`` is a pure poll loop (MCU-10): ``LDR Rt, [Rn, #imm]`` (Rt is not Rn), then
    only shifts of Rt by an immediate (LSLS, LSRS), ``TST Rt, Rm`` or ``CMP Rt, #imm``, and a conditional branch
    back to ``address``. Its iterations write only Rt and the flags, which the last one writes again."""
    halfwords = [code[k] | code[k + 1] << 8 for k in range(0, len(code) - 1, 2)]
    if len(halfwords) < 2 or (halfwords[0] >> 11) != 0b01101:
        return False
    rt, rn = halfwords[0] & 7, halfwords[0] >> 3 & 7
    if rt == rn:
        return False
    for middle in halfwords[1:-1]:
        shift = (middle >> 11) in (0b00000, 0b00001) and middle & 7 == rt and middle >> 3 & 7 == rt
        test = (middle & 0xFFC0) == 0x4200 and middle & 7 == rt
        compare = (middle >> 11) == 0b00101 and middle >> 8 & 7 == rt
        if not (shift or test or compare):
            return False
    branch = halfwords[-1]
    if (branch >> 12) != 0b1101 or (branch >> 9) & 0b111 == 0b111:
        return False
    offset = (branch & 0xFF) - (0x100 if branch & 0x80 else 0)
    return address + 2 * (len(halfwords) - 1) + 4 + 2 * offset == address


def idle_loops(image: FirmwareImage, flash: tuple[int, int]) -> tuple[int, ...]:
    """The halfword-aligned addresses in the firmware's flash that hold ``b .`` (FEE7h: a branch to itself), where
    the core stops at the first iteration (MCU-4); a constant that happens to read so is never run and costs
    nothing."""
    base, size = flash
    found = []
    for address, data in image.segments:
        if base <= address < base + size:
            start = address & 1
            found += [address + k for k in range(start, len(data) - 1, 2) if data[k:k + 2] == IDLE_LOOP]
    return tuple(found)


def countdown_register(code: bytes) -> int:
    """The register a countdown loop counts down (MCU-11), or -1: the block ``code`` is exactly ``SUBS Rd, Rd,
    #1`` (a 16-bit encoding, Rd one of R0-R7) and ``BNE`` back to the ``SUBS``. Its iterations
    write only Rd and the flags, which the last one writes again."""
    if len(code) != 4:
        return -1
    first, branch = code[0] | code[1] << 8, code[2] | code[3] << 8
    if (first & 0xFFC0) == 0x1E40 and first & 7 == first >> 3 & 7:  # SUBS Rd, Rn, #1 (T1) with Rn = Rd
        register = first & 7
    elif (first & 0xF8FF) == 0x3801:  # SUBS Rdn, #1 (T2)
        register = first >> 8 & 7
    else:
        return -1
    return register if branch == 0xD1FD else -1  # BNE to the SUBS: 4 + 2 * (-3) bytes from the branch


def block_cost(code: bytes) -> tuple[int, int]:
    """(instructions, cycles) of the Thumb code ``code`` run straight through (MCU-1): one cycle per instruction,
    one more per single load or store, one per register of LDM/STM/PUSH/POP, two more if the last instruction is
    a branch (the pipeline refill of a taken branch)."""
    instructions = cycles = 0
    offset = 0
    branch = False
    while offset + 1 < len(code):
        first = code[offset] | code[offset + 1] << 8
        if _is_32bit(first) and offset + 3 < len(code):
            second = code[offset + 2] | code[offset + 3] << 8
            cost, branch = _cost(first, second)
            offset += 4
        else:
            cost, branch = _cost(first, None)
            offset += 2
        instructions += 1
        cycles += cost
    return instructions, cycles + (2 if branch else 0)


# ------------------------------------------------------------------------------------------------------------
# The core
# ------------------------------------------------------------------------------------------------------------

ReadFn = Callable[[int, int], int]
WriteFn = Callable[[int, int, int], None]
_FOREVER: Final[int] = (1 << 64) - 1
UNASKED: Final[int] = -1
""":attr:`CortexM._handed` when no caller has handed the next step its entry: the step asks (an exception number is at
least 2, MCU-79)."""
MAX_DEADLINE: Final[int] = (1 << 63) - 1
"""The latest cycle a run may end at (MCU-28): the native hook's clock is 64-bit and a run passes its deadline by a
block, an exception entry or a sleep; half its range (6000 years at 48 MHz) leaves it room never to wrap."""


_NO_INTERRUPT: Final[int] = 0xFFFF_FFFF
"""The native state's ``interrupt`` after a run in which unicorn raised no CPU exception (MCU-72)."""


def _virtual_tlb(state: hook.State, flash: tuple[int, int]) -> hook.Memory:
    """The user data of hook.c's ``supi3_tlb_fill`` (MCU-89): the default memory map's Execute Never regions
    (:data:`EXECUTE_NEVER`), ``flash`` (base, size: its stores noted in ``state``, MCU-28) and unicorn's numbers."""
    memory = hook.Memory(ctypes.pointer(state), *flash)
    memory.never_low[:], memory.never_high[:] = zip(*EXECUTE_NEVER, strict=True)
    memory.fetch, memory.store = ucc.UC_MEM_FETCH, ucc.UC_MEM_WRITE
    memory.prot_write, memory.prot_exec, memory.prot_all = ucc.UC_PROT_WRITE, ucc.UC_PROT_EXEC, ucc.UC_PROT_ALL
    memory.prefetch_abort = EXCP_PREFETCH_ABORT
    return memory


def _native(function: Any, *arguments: Any) -> Any:
    """A function of the native hook library taking unicorn's engine, the core's state and ``arguments`` (ctypes
    types), returning an ``int`` (MCU-70 to MCU-72)."""
    function.argtypes = (ctypes.c_void_p, ctypes.c_void_p, *arguments)
    function.restype = ctypes.c_int
    return function


@dataclass(frozen=True, slots=True)
class _Unwound:
    """MCU-83: a call stack :meth:`CortexM.backtrace` unwound, with everything its unwinding read: the core's
    registers (number, value) and the stack words (from ``low``, picked by ``layout``)."""

    frames: tuple[Frame, ...]
    registers: tuple[tuple[int, int], ...]
    low: int
    layout: struct.Struct
    words: tuple[int, ...]

    @classmethod
    def of(cls, frames: tuple[Frame, ...], used: dict[int, int], words: dict[int, int]) -> _Unwound | None:
        """The record of an unwinding that read ``used`` and ``words``; ``None`` if its words span more than one
        read takes."""
        addresses = sorted(words)
        low = addresses[0] if addresses else 0
        layout = "<"
        at = low
        for address in addresses:
            if address < at:  # words that overlap (no unwinding reads them): not kept
                return None
            layout += f"{address - at}xI" if address > at else "I"
            at = address + 4
        packed = struct.Struct(layout)
        if packed.size > _STACK_BYTES:
            return None
        return cls(frames, tuple(used.items()), low, packed, tuple(words[address] for address in addresses))


class _Batch:
    """Core registers read or written in one call to unicorn's C library (``uc_reg_read_batch``,
    ``uc_reg_write_batch``; MCU-19: 32-bit values in 64-bit slots)."""

    def __init__(self, handle: Any, registers: tuple[int, ...]) -> None:
        count = self._count = len(registers)
        self._handle = handle
        self._ids = (ctypes.c_int32 * count)(*registers)
        self._values = (ctypes.c_uint64 * count)()
        base = ctypes.addressof(self._values)
        self._slots = (ctypes.c_void_p * count)(*(base + 8 * k for k in range(count)))

    def read(self) -> list[int]:
        """The registers' values, in order."""
        CortexM._check(_LIB.uc_reg_read_batch(self._handle, self._ids, self._slots, self._count))
        return list(self._values)

    def write(self, values: list[int]) -> None:
        """Write the registers, in order (32-bit values)."""
        typed: list[ctypes.c_uint64 | int] = [*values]
        self._values[:] = typed
        CortexM._check(_LIB.uc_reg_write_batch(self._handle, self._ids, self._slots, self._count))


_FORMATS: Final[dict[type, str]] = {ctypes.c_uint64: "Q", ctypes.c_uint32: "I"}
"""The ``struct`` format of each ctypes type the native state's packed fields have."""


def _fields_struct(structure: type[ctypes.Structure], names: tuple[str, ...]) -> tuple[struct.Struct, int]:
    """A ``struct.Struct`` that reads or writes the fields ``names`` of ``structure`` (unsigned, in the order given,
    their gaps skipped) with one ``unpack_from`` or ``pack_into`` at the offset returned: one call in place of one
    ctypes attribute access each (MCU-31; the offsets are ctypes', which :func:`hook.check_layout` checks against
    the C library's)."""
    fields = dict(structure._fields_)  # type: ignore[arg-type]
    start = at = getattr(structure, names[0]).offset
    layout = "<"
    for name in names:
        offset = getattr(structure, name).offset
        if offset < at:
            raise hook.NativeHookError(f"{structure.__name__}.{name} at {offset} overlaps the field before it")
        layout += "x" * (offset - at) + _FORMATS[fields[name]]
        at = offset + ctypes.sizeof(fields[name])
    return struct.Struct(layout), start


_HOLD, _HOLD_AT = _fields_struct(hook.Held, ("until", "offset", "value", "held", "poll", "after", "has_after"))
_OFFER, _OFFER_AT = _fields_struct(hook.Held, ("once_from", "once_at", "once_offset", "once_value", "once", "taken",
                                              "once_then"))  # fmt: skip
_CLOCK, _CLOCK_AT = _fields_struct(hook.State, ("block_start", "block_address", "handed", "access_pc"))
_PREFIX, _ = _fields_struct(hook.Prefix, ("address", "pc", "cycles"))


def _prefix_slot(address: int, pc: int) -> int:
    """The slot of the prefix cost of the block at ``address`` up to ``pc`` in the native memo (hook.c's
    ``prefix_slot``, the same sum modulo 2^64; a PC may be reached from more than one block)."""
    return ((pc >> 1) * 31 + (address >> 1)) & (PREFIX_SLOTS - 1)


class HeldRegister:
    """A peripheral's register that the core answers natively while the peripheral holds its value (MCU-25), and a
    read the peripheral offers from a cycle on (MCU-26), from :meth:`CortexM.mmio`. A peripheral holds a value (or
    offers a read) for as long as its own reads would return it and change nothing but what its next access catches
    up with (its model runs on the time), and releases it at that access."""

    def __init__(self, held: hook.Held) -> None:
        self._held = held

    @property
    def native(self) -> hook.Held:
        """The native structure (the native frames write it as :meth:`hold` and :meth:`offer` would, MCU-51)."""
        return self._held

    def hold(self, offset: int, value: int, until: int | None, after: int | None = None) -> None:
        """Reads of ``offset`` return ``value`` while their time (:meth:`CortexM.cycles_polled`) is before cycle
        ``until`` and tell the poll skip (:meth:`CortexM.skip_poll`, MCU-10) that cycle (``None``: until
        :meth:`release`, no poll skip), then ``after`` (``None``: the peripheral answers). Any other read goes to the
        peripheral."""
        _HOLD.pack_into(self._held, _HOLD_AT, _FOREVER if until is None else until, offset, value, 1,
                        0 if until is None else 1, 0 if after is None else after, 0 if after is None else 1)

    def release(self) -> None:
        """Every read goes to the peripheral again."""
        self._held.held = 0

    def offer(self, offset: int, value: int, start: int, then: int) -> None:
        """MCU-26: the first read of ``offset`` at a time (:meth:`CortexM.cycles_polled`) from cycle ``start`` on
        returns ``value``, once, and from then on the held register reads ``then`` (as long as it is held)."""
        _OFFER.pack_into(self._held, _OFFER_AT, start, 0, offset, value, 1, 0, then)  # once_at: set when taken

    def withdraw(self) -> int | None:
        """No more offered read; the time of the one taken since :meth:`offer`, if one was (the peripheral catches
        up with it)."""
        held = self._held
        held.once = 0
        if not held.taken:
            return None
        held.taken = 0
        return int(held.once_at)


class CortexM:
    """A Cortex-M0 or -M3 with flash, RAM, the system control space (SysTick, NVIC, SCB) and the firmware loaded.

    Parameters
    ----------
    image:
        The firmware (:class:`FirmwareImage` or an ELF path).
    cpu:
        ``"cortex_m3"`` or ``"cortex_m0"`` (:data:`CPUS`).
    cpu_hz:
        The core clock: cycles to seconds.
    flash, ram:
        (base, size) of each memory.

    Attributes
    ----------
    cycles, instructions:
        Cycles and instructions since reset (exception entry and return cycles included in :attr:`cycles`).
    """

    def __init__(self, image: FirmwareImage | str | Path, *, cpu: str = "cortex_m3", cpu_hz: float = 48e6,
                 flash: tuple[int, int] = (0x0800_0000, 64 * 1024),
                 ram: tuple[int, int] = (0x2000_0000, 20 * 1024)) -> None:  # fmt: skip
        self.image = image if isinstance(image, FirmwareImage) else FirmwareImage.load(image)
        self.cpu = CPUS[check_cpu(cpu)]
        self.cpu_hz = check_real("cpu_hz", cpu_hz, 1e3, 1e9, limit="the core clock in Hz")
        _check_memories(self.image, flash, ram)
        self.uc: Any = _UNICORN.Uc(ucc.UC_ARCH_ARM, ucc.UC_MODE_THUMB | ucc.UC_MODE_MCLASS)
        self.uc.ctl_set_cpu_model(self.cpu.model)
        self._handle = self.uc._uch  # the engine (uc_engine *) for the direct calls (MCU-19)
        self._register_value = ctypes.c_uint64()
        self._register_ref = ctypes.byref(self._register_value)
        self._frame_buffer = ctypes.create_string_buffer(FRAME_WORDS * 4)  # _peek's (MCU-31)
        self._entry_reads = _Batch(self._handle, _ENTRY_READS)
        self._unstack = _Batch(self._handle, _UNSTACK_WRITES)
        self._resume = _Batch(self._handle, _RESUME_WRITES)
        self._unwind_reads = _Batch(self._handle, _UNWIND_READS)
        self._stack_buffer = ctypes.create_string_buffer(_STACK_BYTES)  # MCU-83: a kept call stack's words
        self._backtraces: dict[tuple[int, int], list[_Unwound]] = {}
        self._callbacks: list[object] = []  # the ctypes callbacks unicorn holds: kept alive with the core
        self.flash = flash
        self.ram = ram
        self.uc.ctl_set_tlb_mode(ucc.UC_TLB_VIRTUAL)  # MCU-89: the fill (hook.c's supi3_tlb_fill) in place of QEMU's
        for base, size in (flash, ram):
            self.uc.mem_map(base, size)
        for address, data in self.image.segments:
            self.uc.mem_write(address, data)
        native = hook.library()
        self._exact_pc = native.supi3_exact_pc
        self._held_read = ctypes.cast(native.supi3_held_read, ctypes.c_void_p)
        self._state = state = hook.State()  # cycles, instructions, deadline, ...: shared with the native hook
        self._cache = (hook.Block * BLOCK_CACHE_SLOTS)()
        self._describe_callback = hook.DESCRIBE(self._describe)
        state.cache = self._cache
        state.mask = BLOCK_CACHE_SLOTS - 1
        state.low_registers[:] = _LOW_REGS
        state.pc_register = arm.UC_ARM_REG_PC
        state.emu_stop = ctypes.cast(_LIB.uc_emu_stop, ctypes.c_void_p)
        state.reg_read = ctypes.cast(_LIB.uc_reg_read, ctypes.c_void_p)
        state.reg_write = ctypes.cast(_LIB.uc_reg_write, ctypes.c_void_p)
        state.describe = self._describe_callback
        state.rewritable, state.rewritable_size = ram  # MCU-28: code in RAM is costed each time it runs
        # MCU-70 to MCU-72: the entry's and return's traffic and a run's start in native code, with unicorn's
        # functions and numbers and the architecture's constants from here
        for name in ("mem_read", "mem_write", "emu_start"):
            setattr(state, name, ctypes.cast(getattr(_LIB, f"uc_{name}"), ctypes.c_void_p))
        state.exc_registers[:] = (*_ENTRY_READS, arm.UC_ARM_REG_PSP)
        state.exc_return_handler, state.exc_return_thread_msp = EXC_RETURN_HANDLER, EXC_RETURN_THREAD_MSP
        state.exc_return_thread_psp = EXC_RETURN_THREAD_PSP
        state.xpsr_t, state.xpsr_align, state.control_spsel = XPSR_T, XPSR_ALIGN, CONTROL_SPSEL
        state.no_interrupt = _NO_INTERRUPT
        # MCU-92: a pointer, not a byref: the collector sees into a pointer, so a board let go is freed (a byref held
        # for the core's life hid the state's references back to the core and kept every board alive)
        self._state_ref = ctypes.pointer(state)
        self._native_enter = _native(native.supi3_enter, ctypes.c_uint32, ctypes.c_uint32, ctypes.c_uint64)
        self._native_take = _native(native.supi3_take, ctypes.c_uint32, ctypes.c_uint32, ctypes.c_uint64)
        self._native_return = _native(native.supi3_return, ctypes.c_uint32)
        self._native_run = _native(native.supi3_run, ctypes.c_void_p)
        self._native_exceptions = True
        self._prefixes = (hook.Prefix * PREFIX_SLOTS)()  # cycles_now's memo for the native frames (MCU-51)
        self.frames = frames = hook.Frames()
        """The native per-frame fast path's state (MCU-51; :mod:`supi3.mcu.frames` sets it up: off until then)."""
        frames.state = ctypes.pointer(state)
        frames.prefixes = self._prefixes
        frames.prefix_mask = PREFIX_SLOTS - 1
        frames.exception_exit, frames.primask_register = EXCP_EXCEPTION_EXIT, arm.UC_ARM_REG_PRIMASK  # MCU-86
        frames.irq_fell = frames.chain_latency = -1
        self._frames_ref = ctypes.pointer(frames)
        self.entry: Callable[[], None] | None = None
        """MCU-51: called first at each entry into Python while the core runs (a peripheral's read or write, a watched
        address) and when a run ends: the native frames' catch-up."""
        self.resume: Callable[[], None] | None = None
        """MCU-51: called when a run starts: the native frames' mirror refreshed."""
        self._port_write = ctypes.cast(native.supi3_port_write, ctypes.c_void_p)
        self._port_read = ctypes.cast(native.supi3_port_read, ctypes.c_void_p)
        self.sleeping = False
        self.active: list[int] = []  # active exceptions, outermost first
        self.pending: set[int] = set()
        self._handed: int | None = UNASKED
        """The board's run loop's :meth:`next_entry` answer for the next :meth:`step`, asked with nothing run or
        written since (it asks once a step, for its deadline and the entry, MCU-79); the step takes it once."""
        self.enabled: set[int] = set()  # external interrupts enabled in the NVIC (exception numbers)
        self.priorities: dict[int, int] = {}
        self.stop_request = False
        self.error: BaseException | None = None
        self.entered: Callable[[int], None] = _nothing
        """Called with the exception number after each exception entry (the board measures latency)."""
        self.returning: Callable[[int], None] = _nothing
        """Called with the returning exception's number at each exception return, before the tail-chain is decided
        (MCU-81: the board runs the bus up to the return and lets the NVIC sample EXTI0's line)."""
        self._costs: dict[tuple[int, int], tuple[int, int]] = {}  # the cost of a block's first instructions
        self._running = False
        self._held: list[hook.Held] = []  # the peripherals' held registers (MCU-25)
        self._idle: dict[int, bool] = {}  # address: the instruction there is ``b .``
        self._sleeps: dict[int, bool] = {}  # address: the instruction before it is WFI or WFE
        # (address, size, code in RAM or b"": MCU-28) of a block: its cost, countdown register (MCU-11), whether a
        # pure poll loop (MCU-10)
        self._blocks: dict[tuple[int, int, bytes], tuple[tuple[int, int], int, bool]] = {}
        self.skip_polls = True
        self.vtor = 0
        self.systick = SysTick(self)
        self._scs_words: dict[int, int] = {}
        self._exact_spans: list[tuple[int, int, int]] = []  # first, last address and handle of each exact-PC hook
        self.mmio(SCS_BASE, SCS_SIZE, self._scs_read, self._scs_write)
        self._hook(ucc.UC_HOOK_BLOCK, native.supi3_block_hook, data=ctypes.byref(state))
        # MCU-89: no memory hook (each one sends every load and store through unicorn's slow path, MCU-87): the
        # default memory map's permissions in the virtual TLB's fill, which notes a store into flash (MCU-28)
        self._memory = _virtual_tlb(state, flash)
        self._hook(ucc.UC_HOOK_TLB_FILL, native.supi3_tlb_fill, data=ctypes.byref(self._memory))
        on_idle_loop = _HOOK_CODE(self._on_idle_loop)
        for address in idle_loops(self.image, flash):  # MCU-4: the core stops at its first ``b .``
            self._hook(ucc.UC_HOOK_CODE, on_idle_loop, address, address)
        self._hook(ucc.UC_HOOK_INTR, native.supi3_interrupt, data=self._state_ref)  # native (MCU-72)
        self._fault_address: int | None = None  # the address of the last unmapped or protected access (BFAR, MMFAR)
        on_invalid_access = _HOOK_MEM_INVALID(self._on_invalid_access)
        self._hook(ucc.UC_HOOK_MEM_UNMAPPED, on_invalid_access)
        for base, size in (flash, ram):  # MCU-89: not the peripherals', whose protection hooks take every access
            self._hook(ucc.UC_HOOK_MEM_PROT, on_invalid_access, base, base + size - 1)
        self.reset()

    # -- memory ------------------------------------------------------------------------------------------------

    def mmio(self, base: int, size: int, read: ReadFn, write: WriteFn, *, port: int | None = None) -> HeldRegister:
        """Map a peripheral: ``read(offset, size) -> value`` and ``write(offset, size, value)`` run on every
        access, but a read of a register the peripheral holds (the :class:`HeldRegister` returned) is answered
        natively (MCU-25), and with ``port`` (0: GPIOA, 1: SPI1, 2: EXTI) a write (and a GPIOA read) the native
        frames take (:attr:`frames`, MCU-51, MCU-66 to MCU-68) is too. An exception they raise stops the run at the end
        of the block (:attr:`error`); the block's later accesses reach no peripheral (no follow-on reports of a run
        that has ended)."""

        def on_read(handle: int, offset: int, size: int, data: int | None) -> int:
            del handle, data
            entry = self.entry
            if entry is not None:
                entry()
            if self.error is not None:  # the run ends with this block: its later accesses reach no peripheral
                return 0
            try:
                return read(offset, size)
            except BaseException as error:  # handed to the run loop, raised there
                self.fail(error)
                return 0

        def on_write(handle: int, offset: int, size: int, value: int, data: int | None) -> None:
            del handle, data
            entry = self.entry
            if entry is not None:
                entry()
            if self.error is not None:
                return
            try:
                write(offset, size, value)
            except BaseException as error:  # handed to the run loop, raised there
                self.fail(error)

        callbacks = (hook.MMIO_READ(on_read), hook.MMIO_WRITE(on_write))
        self._callbacks += callbacks
        held = hook.Held(ctypes.pointer(self._state), callbacks[0])
        self._held.append(held)
        if port is None:
            self._check(_LIB.uc_mmio_map(self._handle, base, size, self._held_read, ctypes.byref(held), callbacks[1],
                                         None))  # fmt: skip
        else:  # MCU-51, MCU-66: the native frames take the write (and GPIOA's input read) or call Python's
            native = hook.Port(ctypes.pointer(self.frames), callbacks[1], check_int("port", port, 0, 2),
                               ctypes.pointer(held))  # fmt: skip
            self._callbacks.append(native)
            self._check(_LIB.uc_mmio_map(self._handle, base, size, self._port_read, ctypes.byref(native),
                                         self._port_write, ctypes.byref(native)))  # fmt: skip
        self.uc.mem_protect(base, size, ucc.UC_PROT_NONE)  # MCU-89: each access calls the exact-PC hook
        self._exact_pc_over(base, base + size - 1)
        return HeldRegister(held)

    def _exact_pc_over(self, first: int, last: int) -> None:
        """The exact-PC hook over the addresses ``first`` to ``last``, merged with those of the ranges next to them:
        one hook a run of adjacent ranges (MCU-87).

        unicorn updates the PC before a load or store only if a memory or protection hook covers its address: without
        one, a peripheral callback sees the PC of the block's first instruction, and the access would be timed there
        (MCU-1 places it by the PC). The ranges are mapped inaccessible (:meth:`mmio`), so each access raises a
        protection event, which this native hook takes: it notes the PC for cycles_now (MCU-25) and lets the access go
        on (MCU-89: a memory hook would send every load and store of RAM and flash through unicorn's slow path too).
        unicorn walks the whole list at each event: the board's GPIOA, GPIOB, AFIO and EXTI, next to each other,
        share one hook; the addresses covered are the same."""
        kept = []
        for low, high, handle in self._exact_spans:
            if high + 1 == first or last + 1 == low:  # next to it (ranges never overlap: uc_mmio_map refuses that)
                self._check(_LIB.uc_hook_del(self._handle, ctypes.c_size_t(handle)))
                first, last = min(first, low), max(last, high)
            else:
                kept.append((low, high, handle))
        handle = self._hook(ucc.UC_HOOK_MEM_READ_PROT | ucc.UC_HOOK_MEM_WRITE_PROT, self._exact_pc, first, last,
                            ctypes.byref(self._state))  # fmt: skip
        self._exact_spans = [*kept, (first, last, handle)]

    def watch(self, address: int, callback: Callable[[], None]) -> None:
        """Call ``callback`` each time the instruction at ``address`` is about to run (a code hook on it: the board's
        main-loop idle point, MCU-30). The callback may set :attr:`stop_request` to end the run at the next block
        boundary (the block it is in runs whole, as MCU-1 counted it); an exception it raises stops the run there and
        is raised by :meth:`step` (as a peripheral's, :meth:`mmio`)."""
        check_int("address", address, 0, 0xFFFF_FFFF, "the 32-bit address space")
        if not callable(callback):
            raise fail("callback", "a callable taking no argument", callback)

        def on_code(handle: int, at: int, size: int, data: int | None) -> None:
            del handle, at, size, data
            entry = self.entry
            if entry is not None:
                entry()
            if self.error is not None:
                return
            try:
                callback()
            except BaseException as error:  # handed to the run loop, raised there
                self.fail(error)

        self._hook(ucc.UC_HOOK_CODE, _HOOK_CODE(on_code), address, address)

    def _hook(self, kind: int, callback: Any, begin: int = 1, end: int = 0, data: Any = None) -> int:
        """Add a hook with a ctypes callback or a native function (MCU-19, MCU-25) and its user data; ``begin >
        end``: every address. Returns unicorn's handle of the hook."""
        self._callbacks.append(callback)
        handle = ctypes.c_size_t()  # uc_hook
        self._check(_LIB.uc_hook_add(self._handle, ctypes.byref(handle), kind, ctypes.cast(callback, ctypes.c_void_p),
                                     data, ctypes.c_uint64(begin), ctypes.c_uint64(end)))  # fmt: skip
        return handle.value

    @staticmethod
    def _check(status: int) -> None:
        if status != ucc.UC_ERR_OK:
            raise UcError(status)

    def read_bytes(self, address: int, size: int) -> bytes:
        """Memory as the core sees it (RAM, flash); an :class:`ArgumentError` if any of it is not mapped."""
        check_int("address", address, 0, 0xFFFF_FFFF, "the 32-bit address space")
        check_int("size", size, 0, max(self.flash[1], self.ram[1]), "bytes: no more than the larger memory")
        try:
            return bytes(self.uc.mem_read(address, size))
        except UcError:
            raise self._unmapped(address, size) from None

    def write_bytes(self, address: int, data: bytes) -> None:
        """Write memory (RAM) from the host, between runs; an :class:`ArgumentError` if any of it is not mapped. Code
        written so runs as written: the emulator's translations of it are dropped (MCU-28)."""
        check_int("address", address, 0, 0xFFFF_FFFF, "the 32-bit address space")
        try:
            self.uc.mem_write(address, check_bytes("data", data))
        except UcError:
            raise self._unmapped(address, len(data)) from None
        if not data:
            return
        self.uc.ctl_remove_cache(address, address + len(data))  # unicorn keeps running its old translation otherwise
        if not (self._rewritable(address) and self._rewritable(address + len(data) - 1)):  # code in flash: costed anew
            self._forget_code()

    def _forget_code(self) -> None:
        """Code in flash has changed (MCU-28): every block is costed anew, every memo of code is dropped."""
        ctypes.memset(self._cache, 0, ctypes.sizeof(self._cache))
        ctypes.memset(self._prefixes, 0, ctypes.sizeof(self._prefixes))
        for memo in (self._blocks, self._costs, self._sleeps, self._idle):
            memo.clear()

    def _unmapped(self, address: int, size: int) -> ArgumentError:
        memories = ", ".join(f"{name} {base:08X}h to {base + length - 1:08X}h"
                             for name, (base, length) in (("flash", self.flash), ("RAM", self.ram)))  # fmt: skip
        return ArgumentError("address", address, f"address must start {size} bytes of mapped memory ({memories}), "
                             f"not {address:#010x}")  # fmt: skip

    def fail(self, error: BaseException) -> None:
        """Stop at the end of the running block and raise ``error`` from :meth:`run` (the first one wins)."""
        if self.error is None:
            self.error = error
        self.stop_request = True
        for held in self._held:  # the peripherals are silent now (mmio): no register is answered natively either
            held.held = held.once = 0

    # -- registers ---------------------------------------------------------------------------------------------

    def reg(self, name: str) -> int:
        """One register by name (``r0``..``r12``, ``sp``, ``lr``, ``pc``, ``xpsr``, ``primask``, ``control``)."""
        return int(self.uc.reg_read(_register(name)))  # any width: through the binding

    def set_reg(self, name: str, value: int) -> None:
        """Write one register by name (as :meth:`reg`) with a 32-bit value, between runs."""
        self.uc.reg_write(_register(name), check_int("value", value, 0, 0xFFFF_FFFF, "a 32-bit register"))

    def registers(self) -> dict[str, int]:
        """R0-R12, SP, LR, PC and xPSR."""
        return {name: self._read(reg) for name, reg in _REGS}

    @property
    def pc(self) -> int:
        """The address of the next instruction."""
        return self._read(arm.UC_ARM_REG_PC)

    def _read(self, register: int) -> int:
        """A 32-bit core register by unicorn's number, read by the C library directly (MCU-19)."""
        _LIB.uc_reg_read(self._handle, register, self._register_ref)
        return self._register_value.value

    def _write(self, register: int, value: int) -> None:
        """Write a 32-bit core register by unicorn's number, by the C library directly (MCU-19)."""
        self._register_value.value = value
        _LIB.uc_reg_write(self._handle, register, self._register_ref)

    # -- the clock, shared with the native block hook (MCU-1, MCU-25) ------------------------------------------------

    @property
    def cycles(self) -> int:
        """Cycles since reset (exception entry and return cycles included)."""
        return int(self._state.cycles)

    @cycles.setter
    def cycles(self, value: int) -> None:
        self._state.cycles = value

    @property
    def instructions(self) -> int:
        """Instructions since reset."""
        return int(self._state.instructions)

    @instructions.setter
    def instructions(self, value: int) -> None:
        self._state.instructions = value

    @property
    def deadline(self) -> int:
        """The cycle the running :meth:`step` ends at (checked at block boundaries)."""
        return int(self._state.deadline)

    @deadline.setter
    def deadline(self, value: int) -> None:
        if type(value) is not int or not 0 <= value <= MAX_DEADLINE:  # the run loop's int: one test (MCU-31)
            value = check_int("deadline", value, 0, MAX_DEADLINE, "core cycles: MAX_DEADLINE (MCU-28)")
        self._state.deadline = value

    @property
    def stop_request(self) -> bool:
        """End the run at the next block boundary (a peripheral's change the run loop must see)."""
        return bool(self._state.stop_request)

    @stop_request.setter
    def stop_request(self, value: bool) -> None:
        self._state.stop_request = value

    @property
    def skip_polls(self) -> bool:
        """MCU-10, MCU-11: count the iterations of pure poll loops and countdown loops without running them (the
        same result, faster); ``False`` runs each."""
        return bool(self._state.skip_polls)

    @skip_polls.setter
    def skip_polls(self, value: bool) -> None:
        self._state.skip_polls = value

    @property
    def native_exceptions(self) -> bool:
        """MCU-70, MCU-71: the exception entry's, tail-chain's and return's register and memory traffic in native code,
        one call each (the default); ``False``: through ctypes call by call, the reference path the tests compare it
        with. The same registers, frames, cycles and reports either way."""
        return self._native_exceptions

    @native_exceptions.setter
    def native_exceptions(self, value: bool) -> None:
        self._native_exceptions = check_bool("native_exceptions", value)

    @property
    def time_s(self) -> float:
        """Core time: cycles / cpu_hz."""
        return self.cycles / self.cpu_hz

    def cycles_now(self) -> int:
        """The cycle of the instruction running now: inside a peripheral callback the block's entry plus the
        instructions before the program counter (MCU-1), between runs :attr:`cycles`. Never earlier than a time
        already handed out (:meth:`cycles_polled`)."""
        state = self._state
        if not self._running:
            return int(state.cycles)
        start, address, handed, pc = _CLOCK.unpack_from(state, _CLOCK_AT)
        if pc > address:
            key = (address, pc - address)
            cost = self._costs.get(key)
            if cost is None:
                cost = block_cost(self.read_bytes(address, pc - address))
                if not self._rewritable(address):  # code in RAM may change (MCU-28)
                    self._costs[key] = cost
            if not self._rewritable(address):  # the native frames' memo (MCU-51): its slot, taken or not
                _PREFIX.pack_into(self._prefixes, _prefix_slot(address, pc) * _PREFIX.size, address, pc, cost[1])
            start += cost[1]
        if start > handed:
            state.handed = start
            return int(start)
        return int(handed)

    def cycles_polled(self) -> int:
        """The time of a status read (a flag the firmware polls): the end of the running block, which costs no
        register read; later times handed out are never earlier (MCU-1)."""
        state = self._state
        cycles = int(state.cycles)
        if not self._running:
            return cycles
        if cycles > state.handed:
            state.handed = cycles
        return int(state.handed)

    # -- reset and exceptions ----------------------------------------------------------------------------------

    def reset(self) -> None:
        """Power-on reset (B1.5.5): MSP and PC from the vector table at the flash base, thread mode, privileged."""
        base = self.flash[0]
        sp, entry = struct.unpack("<2I", self.read_bytes(base, 8))
        self._write(arm.UC_ARM_REG_XPSR, XPSR_T)
        self._write(arm.UC_ARM_REG_MSP, sp)
        self._write(arm.UC_ARM_REG_SP, sp)
        self._write(arm.UC_ARM_REG_PC, entry & ~1)
        self.vtor = base
        self.active.clear()
        self.pending.clear()

    def vector(self, number: int) -> int:
        """Entry ``number`` of the vector table (an :class:`ArgumentError` if it is not mapped)."""
        return int(struct.unpack("<I", self._peek(self.vtor + 4 * number, 4))[0])

    def _peek(self, address: int, size: int) -> bytes:
        """``size`` bytes of memory, a stacked frame's at most, read by unicorn's C library directly (MCU-19; the
        exception entry's and return's, MCU-31); the :class:`ArgumentError` of :meth:`read_bytes` if any of it is not
        mapped."""
        buffer = self._frame_buffer
        if not 0 <= size <= len(buffer):  # the buffer's bound (a caller's bug, never taken for unmapped memory)
            raise ValueError(f"_peek reads 0 to {len(buffer)} bytes, not {size}")
        if _LIB.uc_mem_read(self._handle, address, buffer, size) != ucc.UC_ERR_OK:
            raise self._unmapped(address, size)
        return buffer.raw[:size]

    def priority(self, number: int) -> int:
        """The priority of exception ``number``: Reset, NMI, HardFault fixed at -3, -2, -1 (B1.5.4)."""
        if number <= HARDFAULT:
            return number - 4
        return self.priorities.get(number, 0)

    def execution_priority(self) -> int:
        """The running priority: the highest (lowest number) active exception, 0 under PRIMASK (B1.5.4); 256 in
        thread mode with nothing masked."""
        active = self.active
        running = min((self.priority(n) for n in active), default=256) if active else 256
        if self._read(arm.UC_ARM_REG_PRIMASK) & 1:
            running = min(running, 0)
        return running

    def pend(self, number: int) -> None:
        """Make exception ``number`` pending (an external interrupt: ``EXTERNAL + irq``)."""
        self.pending.add(_exception_number(number))
        if self.sleeping and self._takeable() is not None:  # only a sleeping core asks (MCU-72)
            self.sleeping = False

    @property
    def in_exception(self) -> bool:
        """An exception is active, or pending and allowed to preempt: the core has interrupt work to do."""
        return bool(self.active) or self._takeable() is not None

    def next_entry(self) -> int | None:
        """The pending exception the next :meth:`step` enters first (the highest priority allowed to preempt,
        B1.5.4), ``None`` if none."""
        return self._takeable()

    def _takeable(self) -> int | None:
        pending = self.pending
        if not pending:  # the run loop's common case (MCU-31)
            return None
        if len(pending) == 1:  # the next common one: EXTI0 alone
            (best,) = pending  # no call (MCU-79)
            if best >= EXTERNAL and best not in self.enabled:
                return None
        else:
            candidates = [n for n in pending if n < EXTERNAL or n in self.enabled]
            if not candidates:
                return None
            best = min(candidates, key=lambda n: (self.priority(n), n))
        return best if self.priority(best) < self.execution_priority() else None

    def enter(self, number: int) -> int:
        """Exception entry (B1.5.6): stack the basic frame on the current stack (the process stack in thread mode
        with CONTROL.SPSEL = 1), aligned to 8 bytes (B1.5.7), LR = EXC_RETURN, CONTROL.SPSEL = 0 (the handler runs
        on the main stack), IPSR = ``number``, PC = its vector; costs :attr:`Cpu.entry_cycles`. Returns the
        frame's address."""
        return self._enter(_exception_number(number))

    def _enter(self, number: int) -> int:
        """:meth:`enter` of a checked exception number."""
        handler_mode = bool(self.active)
        if self._native_exceptions:  # MCU-71: the same traffic in one call
            failed = self._native_enter(self._handle, self._state_ref, number, handler_mode, self.vtor + 4 * number)
            frame = int(self._state.frame)
            if failed == 1:
                self._stacking_error(frame, self._state.status)
            self._took(number, frame, self.cpu.entry_cycles, None if failed else int(self._state.vector))
            return frame
        control, sp, *words, xpsr, pc = self._entry_reads.read()
        process = bool(control & CONTROL_SPSEL) and not handler_mode
        aligned = sp & 4
        frame = (sp - FRAME_WORDS * 4) & ~7
        words += [pc, xpsr | (XPSR_ALIGN if aligned else 0)]
        status = _LIB.uc_mem_write(self._handle, frame, struct.pack("<8I", *words), FRAME_WORDS * 4)  # MCU-31
        if status != ucc.UC_ERR_OK:
            self._stacking_error(frame, status)
        self._write(arm.UC_ARM_REG_SP, frame)
        if process:
            self._write(arm.UC_ARM_REG_CONTROL, control & ~CONTROL_SPSEL)  # unicorn switches SP to the MSP
        exc_return = EXC_RETURN_HANDLER if handler_mode else EXC_RETURN_THREAD_PSP if process else EXC_RETURN_THREAD_MSP
        self._take(number, exc_return, frame, self.cpu.entry_cycles)
        return frame

    def _stacking_error(self, frame: int, status: int) -> None:
        """The entry's frame at ``frame`` is not in memory (unicorn's ``status``): a fault report (B1.5.6)."""
        raise FirmwareFaultError(self.report(Stop.FAULT, f"stacking error: the frame at {frame:08X}h is not in "
                                             f"memory ({UcError(status)})"))  # fmt: skip

    def _take(self, number: int, exc_return: int, frame: int, cycles: int) -> None:
        """The part of an entry after the stacking (B1.5.6), also a tail-chain's: LR = ``exc_return``, IPSR, PC =
        the vector of ``number``, which becomes active; costs ``cycles``. ``frame``: the stacked frame, for a
        report."""
        if self._native_exceptions:  # MCU-71: the same traffic in one call
            failed = self._native_take(self._handle, self._state_ref, number, exc_return, self.vtor + 4 * number)
            self._took(number, frame, cycles, None if failed else int(self._state.vector))
            return
        self._write(arm.UC_ARM_REG_LR, exc_return)
        self._write(arm.UC_ARM_REG_XPSR, XPSR_T | number)
        try:
            target: int | None = self.vector(number)
        except ArgumentError:
            target = None
        if target is not None:
            self._write(arm.UC_ARM_REG_PC, target & ~1)
        self._took(number, frame, cycles, target)

    def _took(self, number: int, frame: int, cycles: int, target: int | None) -> None:
        """The rest of :meth:`_take` once LR, xPSR and PC are written: ``number`` active at the vector ``target``
        (``None``: its entry in the vector table is not in memory, a fault)."""
        if target is None:
            reason = f"vector table read error: entry {number} ({_name(number)}) at VTOR {self.vtor:08X}h is unmapped"
            raise FirmwareFaultError(self.report(Stop.FAULT, reason, stacked=frame))
        self.pending.discard(number)
        self.active.append(number)
        self._state.cycles += cycles
        self.sleeping = False
        self.entered(number)
        if not target & 1:
            reason = f"vector {number} ({_name(number)}) is {target:08X}h: bit 0 clear, an INVSTATE UsageFault (B1.5.6)"
            raise FirmwareFaultError(self.report(Stop.FAULT, reason, stacked=frame))

    def exception_return(self, exc_return: int) -> None:
        """Exception return (B1.5.8): unstack the frame, undo the alignment word, back to the mode EXC_RETURN
        names; costs :attr:`Cpu.return_cycles`. A pending exception that may preempt the code returned to is
        tail-chained instead (MCU-20): its handler starts on the same frame, with the same EXC_RETURN, after
        :attr:`Cpu.tail_chain_cycles`."""
        if type(exc_return) is not int or not 0 <= exc_return <= 0xFFFF_FFFF:  # the host's call, not the firmware's
            check_int("exc_return", exc_return, 0, 0xFFFF_FFFF, "a 32-bit EXC_RETURN value (B1.5.8)")
        if exc_return not in (EXC_RETURN_HANDLER, EXC_RETURN_THREAD_MSP, EXC_RETURN_THREAD_PSP) or not self.active:
            raise FirmwareFaultError(self.report(Stop.FAULT, f"exception return with EXC_RETURN {exc_return:08X}h "
                                            f"{'in' if self.active else 'outside'} a handler: an INVPC "
                                            "UsageFault (B1.5.8)"))  # fmt: skip
        if (exc_return == EXC_RETURN_HANDLER) != (len(self.active) > 1):
            nesting = f"{len(self.active)} active exception(s)"
            reason = f"EXC_RETURN {exc_return:08X}h does not match the nesting of {nesting}: INVPC UsageFault (B1.5.8)"
            raise FirmwareFaultError(self.report(Stop.FAULT, reason))
        self.returning(self.active[-1])  # MCU-81: what is pending at the return's first cycle
        if self.pending:  # else nothing to chain (MCU-79: the run loop's common return, no question asked)
            returning = self.active.pop()
            chained = self._takeable()
            if chained is not None:
                sp = self._read(arm.UC_ARM_REG_PSP if exc_return == EXC_RETURN_THREAD_PSP else arm.UC_ARM_REG_SP)
                self._take(chained, exc_return, sp, self.cpu.tail_chain_cycles)
                return
            self.active.append(returning)  # until the frame is back: a fault report shows the handler still active
        if self._native_exceptions:  # MCU-70: the same traffic in one call
            if self._native_return(self._handle, self._state_ref, exc_return):
                self._unstacking_error(int(self._state.frame))
            self.active.pop()
            self._state.cycles += self.cpu.return_cycles
            return
        sp = self._read(arm.UC_ARM_REG_PSP if exc_return == EXC_RETURN_THREAD_PSP else arm.UC_ARM_REG_SP)
        try:
            words = struct.unpack("<8I", self._peek(sp, FRAME_WORDS * 4))
        except ArgumentError:
            self._unstacking_error(sp)
        xpsr = words[7]
        sp += FRAME_WORDS * 4 + (4 if xpsr & XPSR_ALIGN else 0)
        self._unstack.write([*words[:6], (xpsr & ~XPSR_ALIGN) | XPSR_T])  # the mode last: it selects the SP
        if exc_return == EXC_RETURN_THREAD_PSP:
            self._write(arm.UC_ARM_REG_CONTROL, self._read(arm.UC_ARM_REG_CONTROL) | CONTROL_SPSEL)
        self._resume.write([sp, words[6] & ~1])
        self.active.pop()
        self._state.cycles += self.cpu.return_cycles

    def _unstacking_error(self, sp: int) -> None:
        """The frame to unstack at ``sp`` is not in memory: a fault report (B1.5.8)."""
        raise FirmwareFaultError(self.report(Stop.FAULT, f"unstacking error: the frame at {sp:08X}h is not in "
                                             "memory (B1.5.8)"))  # fmt: skip

    # -- running -----------------------------------------------------------------------------------------------

    def _describe(self, address: int, size: int) -> int:
        """The native block hook met a block not in its cache: its cost (MCU-1), countdown register (MCU-11) and
        whether it is a pure poll loop (MCU-10) into the cache and :attr:`hook.State.fresh`; 1 (stop the run) if its
        code cannot be read."""
        try:
            rewritable = self._rewritable(address)
            key = (address, size, self.read_bytes(address, size) if rewritable else b"")
            block = self._blocks.get(key)
            if block is None:
                code = key[2] or self.read_bytes(address, size)
                block = self._blocks[key] = (block_cost(code), countdown_register(code),
                                             is_poll_loop(code, address))  # fmt: skip
            (instructions, cycles), countdown, poll = block
            self._state.fresh = fresh = hook.Block(address, size, instructions, cycles, countdown, poll)
            if not rewritable:  # the native hook never takes a block in RAM from its cache (MCU-28)
                self._cache[(address >> 1) & (len(self._cache) - 1)] = fresh
            return 0
        except BaseException as error:  # handed to the run loop, raised there (an escape would be lost in ctypes)
            self.fail(error)
            return 1

    def _rewritable(self, address: int) -> bool:
        """Code at ``address`` may be rewritten by the firmware as it runs: it is in RAM (MCU-28)."""
        return 0 <= address - self.ram[0] < self.ram[1]

    def _on_idle_loop(self, handle: int, address: int, size: int, data: int | None) -> None:
        """A ``b .`` is about to run (its block counted): stop there, at its first iteration, whatever the deadline;
        the run loop takes it for a wait in thread mode and a hang in a handler (MCU-4); unless the firmware has
        written other code there since (MCU-28)."""
        del size, data
        if not self._idle_at(address):
            return
        self.stop_request = True
        _LIB.uc_emu_stop(handle)

    def skip_poll(self, until: int) -> None:
        """The status register just read keeps its value until cycle ``until``: if the running block is a pure poll
        loop on it (:func:`is_poll_loop`), its next iterations up to then are counted without running (MCU-10)."""
        state = self._state
        if state.skip_polls and state.block_poll:  # the native hook's held_read does the same (MCU-25)
            state.skip_address, state.skip_until, state.skip_pending = state.block_address, until, 1

    def step(self, deadline: int) -> str:
        """Run from the current PC until the clock reaches ``deadline`` (cycles; checked at block boundaries), a
        peripheral asks to stop, or the core sleeps, faults or returns from an exception. Returns ``"run"`` or
        ``"sleep"``; raises :class:`FirmwareError` for a fault or a breakpoint, or the error a peripheral raised.

        A pending exception that may preempt (B1.5.4) is entered first; a sleeping core (WFI, or ``b .`` in thread
        mode: MCU-4) only lets the time pass."""
        number, self._handed = self._handed, UNASKED  # taken once (MCU-79)
        self.deadline = deadline
        if number == UNASKED:
            number = self._takeable()
        if number is not None:
            self._enter(number)
        state = self._state
        if self.sleeping:
            state.cycles = max(state.cycles, deadline)
            return "sleep"
        state.stop_request = False
        resume = self.resume
        if resume is not None:  # MCU-51: the native frames' mirror, valid for the run
            resume()
        self._running = True
        try:  # from the PC; unicorn's CPU exception noted in the state (MCU-72: supi3_run, supi3_interrupt)
            status = self._native_run(self._handle, self._state_ref, self._frames_ref)
            if status == ucc.UC_ERR_EXCEPTION and state.interrupt == EXCP_PREFETCH_ABORT:
                status = ucc.UC_ERR_OK  # MCU-89: the virtual TLB refused the fetch, as QEMU's map did (_after_stop)
            if status != ucc.UC_ERR_OK:
                raise FirmwareFaultError(self._fault(UcError(status)))
        finally:
            self._running = False
            if state.code_written:  # MCU-89: flash read-only again in the TLB, so the next store is noted too
                self.uc.ctl(ucc.UC_CTL_TLB_FLUSH, ucc.UC_CTL_IO_WRITE)
            entry = self.entry
            if entry is not None:  # MCU-51: the native frames' effects into the Python objects
                entry()
        if self._state.code_written:  # the firmware stored into flash (MCU-28)
            self._state.code_written = 0
            self._forget_code()
        failure = self.error
        if failure is not None:
            self.error = None
            raise failure
        return self._after_stop()

    def _after_stop(self) -> str:
        state = self._state
        pc = int(state.pc)
        number = state.interrupt
        if number == EXCP_EXCEPTION_EXIT:
            self.exception_return(pc | 1)
            return "run"
        if number == EXCP_SWI:
            self.enter(SVCALL)
            return "run"
        if number == EXCP_PREFETCH_ABORT:
            if any(low <= pc < high for low, high in EXECUTE_NEVER):
                raise FirmwareFaultError(self._fault_report(f"memory fault: execute from a peripheral region at "
                                                            f"{pc:08X}h (Execute Never)", IACCVIOL))  # fmt: skip
            raise FirmwareFaultError(self._fault_report(*_FAULTS[ucc.UC_ERR_FETCH_UNMAPPED]))
        if number != _NO_INTERRUPT:
            what = "a breakpoint (BKPT)" if number == EXCP_BKPT else f"core exception {number}"
            raise FirmwareStoppedError(self.report(Stop.FAULT, f"{what}: not modelled"))
        if pc == self._state.block_end:
            sleeps = self._sleeps.get(pc)  # the code in flash does not change (as the block costs; MCU-28)
            if sleeps is None:
                sleeps = self.read_bytes(pc - 2, 2) in (b"\x30\xbf", b"\x20\xbf")
                if not self._rewritable(pc):
                    self._sleeps[pc] = sleeps
            if sleeps:
                self.sleeping = True  # the last block ended in WFI or WFE: unicorn halts the core after them
                return "sleep"
        if state.stop_request or state.cycles >= state.deadline:
            return "run"
        raise FirmwareStoppedError(self.report(Stop.FAULT, "the core stopped for no known reason"))

    def idle_loop(self) -> bool:
        """The core sits on ``b .`` (a branch to itself): in thread mode it waits for an interrupt (MCU-4)."""
        return self._idle_at(self.pc)

    def _idle_at(self, pc: int) -> bool:
        """The instruction at ``pc`` in flash is ``b .`` (memoised until code in flash changes, MCU-28)."""
        idle = self._idle.get(pc)
        if idle is None:
            idle = self._idle[pc] = bool(self.flash[0] <= pc < self.flash[0] + self.flash[1] - 1 and
                                         self.read_bytes(pc, 2) == IDLE_LOOP)  # fmt: skip
        return idle

    def _on_invalid_access(self, handle: int, access: int, address: int, size: int, value: int,
                           data: int | None) -> bool:  # fmt: skip
        """An access to unmapped memory or against flash's or RAM's protection is about to fault: note its address
        (BFAR, MMFAR); unicorn then stops with the error (``False``: not handled). Not hooked over the peripherals
        (MCU-89): their protection events are the exact-PC hook's, which this one would precede at every access."""
        del handle, access, size, value, data
        self._fault_address = address
        return False

    def _fault(self, error: Any) -> StopReport:
        reason, bit = _FAULTS.get(error.errno, (f"fault ({error})", 0))
        return self._fault_report(reason, bit)

    def _fault_report(self, reason: str, bit: int) -> StopReport:
        """The report of a core fault (``bit``: its CFSR bit, 0 if none), the HardFault entry taken (MCU-3)."""
        pc = self.pc
        address, self._fault_address = self._fault_address, None
        status = None
        if self.cpu.fault_status and bit:  # the status registers as the fault leaves them (B3.2.15 to B3.2.18)
            words = self._scs_words
            loaded = _FAULT_ADDRESS.get(bit)
            if loaded is not None and address is not None:
                words[loaded[1]] = address
                bit |= loaded[2]
            words[CFSR], words[HFSR] = words.get(CFSR, 0) | bit, words.get(HFSR, 0) | HFSR_FORCED
            status = {"CFSR": words[CFSR], "HFSR": words[HFSR]}
            if loaded is not None and address is not None:
                status[loaded[0]] = address
        backtrace = self.backtrace()
        frame: int | None = None
        if self.ram[0] + FRAME_WORDS * 4 <= (self.reg("sp") & ~7) <= self.ram[0] + self.ram[1]:
            try:  # take the HardFault as the core would: the report shows the frame its handler would see
                frame = self.enter(HARDFAULT)
            except FirmwareError:
                frame = None
        return self.report(Stop.FAULT, reason, pc=pc, stacked=frame, backtrace=backtrace, fault_status=status)

    def report(self, stop: Stop, reason: str, *, pc: int | None = None, stacked: int | None = None,
               backtrace: tuple[Frame, ...] | None = None, fault_status: dict[str, int] | None = None
               ) -> StopReport:  # fmt: skip
        """A :class:`StopReport` of the core now; ``stacked``: the address of a stacked frame to include;
        ``backtrace``: the call stack if not the core's now (:meth:`backtrace`); ``fault_status``: CFSR and HFSR."""
        pc = self.pc if pc is None else pc
        frame = None
        if stacked is not None:
            words = struct.unpack("<8I", self.read_bytes(stacked, FRAME_WORDS * 4))
            frame = dict(zip(FRAME_NAMES, words, strict=True))
        return StopReport(stop, reason, pc, self.registers(), self.instructions, self.cycles, self.time_s, frame,
                          self.image.function_at(pc), self.backtrace() if backtrace is None else backtrace,
                          fault_status)  # fmt: skip

    def backtrace(self, depth: int = BACKTRACE_DEPTH) -> tuple[Frame, ...]:
        """The call stack now, innermost first: the PC's function and line, then each caller's return address
        with the line of its call, unwound with the ELF's call frame information (``.debug_frame``) up to
        ``depth`` frames, a frame without that information, or an exception entry (LR = EXC_RETURN).

        MCU-83: a call stack already unwound at this PC and depth is taken again when every register and stack word
        its unwinding read holds the same value now (the unwinding is a function of those and the ELF alone): one
        register read and one memory read in place of the unwinding's."""
        check_int("depth", depth, 1)
        pc = self.pc
        registers = self._unwind_reads.read()  # R0..R12, 13 SP, 14 LR
        key = (pc, depth)
        kept = self._backtraces.get(key)
        if kept is not None:
            for unwound in kept:
                if all(registers[reg] == value for reg, value in unwound.registers) \
                        and self._stack_words(unwound.low, unwound.layout) == unwound.words:  # fmt: skip
                    return unwound.frames
        frames, used, words = self._unwind(pc, registers, depth)
        if words is not None:
            record = _Unwound.of(frames, used, words)
            if record is not None and self._stack_words(record.low, record.layout) == record.words:
                if kept is None:
                    if len(self._backtraces) >= BACKTRACE_MEMO:
                        self._backtraces.clear()
                    kept = self._backtraces[key] = []
                elif len(kept) >= BACKTRACE_STACKS:
                    del kept[0]
                kept.append(record)
        return frames

    def _unwind(self, pc: int, registers: list[int], depth: int
                ) -> tuple[tuple[Frame, ...], dict[int, int], dict[int, int] | None]:  # fmt: skip
        """:meth:`backtrace`'s unwinding from ``pc`` and the core's ``registers`` (R0..R12, SP, LR): the frames, and
        what decided them (MCU-83): the registers of ``registers`` it used and the stack words it used (address:
        value; ``None`` if a word it read is outside RAM and flash or unmapped: not to be kept). A restored register
        the unwinding never uses (a callee-saved R4 holding the caller's data) decides nothing."""
        image = self.image
        frames = [Frame(pc, image.function_at(pc), image.line_at(pc))]
        regs = dict(enumerate(registers))
        used: dict[int, int] = {}
        words: dict[int, int] | None = {}
        restored: dict[int, int | None] = {}  # a register's stack word, None for the CFA (SP); absent: `registers`

        def value(reg: int) -> int:
            if words is not None:
                where = restored.get(reg, -1)
                if where == -1:
                    used[reg] = regs[reg]
                elif where is not None:
                    words[where] = regs[reg]
            return regs[reg]

        while len(frames) < depth:
            rule = image.frame_rule(pc)
            if rule is None or rule[0] not in regs:
                break
            cfa = value(rule[0]) + rule[1]
            try:
                saved = {reg: int(struct.unpack("<I", self._peek(cfa + offset, 4))[0])
                         for reg, offset in rule[2].items()}  # fmt: skip
            except ArgumentError:
                words = None
                break
            for reg, offset in rule[2].items():
                restored[reg] = cfa + offset
                if words is not None and not (self._in(self.ram, cfa + offset) or self._in(self.flash, cfa + offset)):
                    words = None  # a word read elsewhere (a peripheral's): every unwinding reads it again
            regs |= saved
            regs[13] = cfa
            restored[13] = None
            lr = value(14)
            back = lr & ~1
            if lr >= EXC_RETURN_HANDLER or not self.flash[0] <= back < self.flash[0] + self.flash[1] \
                    or (back == pc and not saved):  # fmt: skip
                break
            pc = back
            frames.append(Frame(pc, image.function_at(pc - 1), image.line_at(pc - 1)))  # the call's line
        return tuple(frames), used, words

    @staticmethod
    def _in(memory: tuple[int, int], address: int) -> bool:
        """Whether the word at ``address`` lies in ``memory`` (base, size)."""
        return memory[0] <= address and address + 4 <= memory[0] + memory[1]

    def _stack_words(self, low: int, layout: struct.Struct) -> tuple[int, ...] | None:
        """MCU-83: the words ``layout`` picks from memory at ``low`` on, in one read; ``None`` if unmapped."""
        buffer = self._stack_buffer
        if not layout.size:
            return ()
        if _LIB.uc_mem_read(self._handle, low, buffer, layout.size) != ucc.UC_ERR_OK:
            return None
        return layout.unpack_from(buffer)

    # -- system control space: SysTick, NVIC, SCB (B3.2 to B3.4) -----------------------------------------------

    def _scs_read(self, offset: int, size: int) -> int:
        if 0x010 <= offset < 0x020:
            return self.systick.read(offset - 0x010)
        if 0x100 <= offset < 0x104 or 0x180 <= offset < 0x184:  # ISER0, ICER0
            return sum(1 << (n - EXTERNAL) for n in self.enabled)
        if 0x200 <= offset < 0x204 or 0x280 <= offset < 0x284:  # ISPR0, ICPR0
            return sum(1 << (n - EXTERNAL) for n in self.pending if n >= EXTERNAL)
        if 0x300 <= offset < 0x304:  # IABR0
            return sum(1 << (n - EXTERNAL) for n in self.active if n >= EXTERNAL)
        if 0x400 <= offset < 0x420:  # IPR: one byte per interrupt
            return self._priority_bytes(EXTERNAL + offset - 0x400, size)
        if offset == 0xD00:
            return self.cpu.cpuid
        if offset == 0xD04:  # ICSR: VECTACTIVE, PENDSTSET
            return (self.active[-1] if self.active else 0) | ((SYSTICK in self.pending) << 26)
        if offset == 0xD08:
            return self.vtor if self.cpu.vtor else 0
        if 0xD18 <= offset < 0xD24:  # SHPR1..3
            return self._priority_bytes(4 + offset - 0xD18, size)
        return self._scs_words.get(offset, 0)

    def _priority_bytes(self, first: int, size: int) -> int:
        return sum(self.priorities.get(first + k, 0) << (8 * k) for k in range(size))

    def _scs_write(self, offset: int, size: int, value: int) -> None:
        if 0x010 <= offset < 0x020:
            self.systick.write(offset - 0x010, value)
        elif 0x100 <= offset < 0x104:
            self.enabled |= {EXTERNAL + k for k in range(IRQ_LINES) if value >> k & 1}
            self.stop_request = True  # a pending interrupt may now be taken
        elif 0x180 <= offset < 0x184:
            self.enabled -= {EXTERNAL + k for k in range(IRQ_LINES) if value >> k & 1}
        elif 0x200 <= offset < 0x204:
            self.pending |= {EXTERNAL + k for k in range(IRQ_LINES) if value >> k & 1}
            self.stop_request = True
        elif 0x280 <= offset < 0x284:
            self.pending -= {EXTERNAL + k for k in range(IRQ_LINES) if value >> k & 1}
        elif 0x400 <= offset < 0x420 or 0xD18 <= offset < 0xD24:
            first = EXTERNAL + offset - 0x400 if offset < 0xD00 else 4 + offset - 0xD18
            for k in range(size):
                self.priorities[first + k] = value >> (8 * k) & 0xFF
        elif offset == 0xD04:
            if value & (1 << 26):
                self.pending.add(SYSTICK)
                self.stop_request = True
            if value & (1 << 25):
                self.pending.discard(SYSTICK)
            if value & (1 << 28):
                self.pending.add(PENDSV)
                self.stop_request = True
        elif offset == 0xD08 and self.cpu.vtor:
            self.vtor = value & ~0x7F
        elif offset in (CFSR, HFSR):  # write 1 to clear (B3.2.15, B3.2.16)
            self._scs_words[offset] = self._scs_words.get(offset, 0) & ~value
        else:
            self._scs_words[offset] = value


def _nothing(number: int) -> None:
    del number


def _name(number: int) -> str:
    return EXCEPTION_NAMES.get(number, f"IRQ {number - EXTERNAL}")


def _exception_number(number: object) -> int:
    """``number`` checked as an exception that can be pended or entered: NMI (2) up to the last interrupt."""
    if type(number) is int and 2 <= number <= MAX_EXCEPTION:  # the core's own numbers: one test (MCU-31)
        return number
    return check_int("number", number, 2, MAX_EXCEPTION, "B1.5.2: NMI (2) up to the last interrupt")


class SysTick:
    """The SysTick timer (B3.3): a 24-bit down counter at the core clock (CLKSOURCE 1) or the reference clock
    (CLKSOURCE 0: the core clock / :data:`REFERENCE_DIVIDER`, as the STM32F1's HCLK/8, RM0008 7.2), computed from
    the core's cycle count when read (MCU-5)."""

    REFERENCE_DIVIDER: Final[int] = 8

    def __init__(self, core: CortexM) -> None:
        self.core = core
        self.csr = 0
        self.rvr = 0
        self._start = 0  # cycle at which the counter held _value
        self._value = 0
        self._seen = 0  # zeros since the base that pended the exception (or were passed with TICKINT off)
        self._flag_zeros = 0  # zeros since the base that COUNTFLAG reported
        self._flag = False  # a zero before the last rebase that COUNTFLAG has not reported

    @property
    def enabled(self) -> bool:
        """CSR.ENABLE."""
        return bool(self.csr & 1)

    def _divider(self) -> int:
        return 1 if self.csr & 4 else self.REFERENCE_DIVIDER

    def _ticks(self, cycles: int) -> int:
        return (cycles - self._start) // self._divider() if self.enabled else 0

    def _value_after(self, ticks: int) -> int:
        if ticks <= self._value:
            return self._value - ticks
        if self.rvr == 0:
            return 0
        return self.rvr - (ticks - self._value - 1) % (self.rvr + 1)

    def _zeros_until(self, ticks: int) -> int:
        """How many times the counter reached 0 from 1 in the first ``ticks`` ticks after the base."""
        if self.rvr == 0 and not self._value:
            return 0
        first = self._first()
        if ticks < first:
            return 0
        return 1 + ((ticks - first) // (self.rvr + 1) if self.rvr else 0)

    def _first(self) -> int:
        """Ticks from the base to the first time the counter reaches 0."""
        return self._value if self._value else self.rvr + 1

    def next_event(self) -> int | None:
        """The cycle of the next wrap that pends the SysTick exception (TICKINT), or ``None``."""
        if not self.enabled or not self.csr & 2 or (self.rvr == 0 and (self._seen or not self._value)):
            return None
        at = self._first() + self._seen * (self.rvr + 1)
        return self._start + at * self._divider()

    def due(self) -> int | None:
        """:meth:`update`, then :meth:`next_event`: the run loop's one call at each stop (none with SysTick off)."""
        if not self.csr & 1:
            return None
        self.update()
        return self.next_event()

    def update(self) -> None:
        """Pend the exception if the counter reached 0 since the last update (TICKINT)."""
        if not self.csr & 1:  # disabled (CSR.ENABLE 0): no tick, nothing to pend (MCU-31: the run loop's case)
            return
        zeros = self._zeros_until(self._ticks(self.core.cycles))
        if zeros > self._seen:
            self._seen = zeros
            if self.csr & 2:
                self.core.pend(SYSTICK)

    def _rebase(self, cycles: int) -> None:
        ticks = self._ticks(cycles)
        zeros = self._zeros_until(ticks)
        self._flag = self._flag or zeros > self._flag_zeros
        self._value = self._value_after(ticks)
        self._start += ticks * self._divider()
        self._seen = self._flag_zeros = 0

    def read(self, offset: int) -> int:
        """CSR (COUNTFLAG clears on read), RVR, CVR, CALIB (at the polled time: a busy wait reads it)."""
        cycles = self.core.cycles_polled()
        if offset == 0x0:
            zeros = self._zeros_until(self._ticks(cycles))
            flag = self._flag or zeros > self._flag_zeros
            self._flag, self._flag_zeros = False, zeros
            return self.csr | (flag << 16)
        if offset == 0x4:
            return self.rvr
        if offset == 0x8:
            return self._value_after(self._ticks(cycles))
        return 0

    def write(self, offset: int, value: int) -> None:
        """CSR, RVR, CVR (any write clears the counter and COUNTFLAG)."""
        cycles = self.core.cycles_now()
        self._rebase(cycles)
        self._start = cycles
        if offset == 0x0:
            self.csr = value & 0b111
        elif offset == 0x4:
            self.rvr = value & SYST_MAX
        elif offset == 0x8:
            self._value = 0
            self._flag = False
        self.core.stop_request = True  # the next wrap may come sooner: the run loop recomputes its deadline

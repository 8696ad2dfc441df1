"""The emulated Cortex-M core (supi3.mcu.core): exception entry and return against hand-written assembly, the timing
model, and the reports of a fault, an endless loop and a hang instead of a hang of the test.

Ref: ARMv7-M ARM B1.5.6 (entry: the 8-word frame R0-R3, R12, LR, return address, xPSR; LR = EXC_RETURN), B1.5.7
(8-byte stack alignment, stacked xPSR bit 9), B1.5.8 (return); ARMv6-M the same for the Cortex-M0. The programs are
tests/mcu/exceptions.S (Thumb-1, runs on both cores) and tests/mcu/faults.c (through the SDK's board port).
"""

from __future__ import annotations

import struct
from pathlib import Path

import pytest
from unicorn import unicorn_const as ucc

from supi3.errors import ArgumentError
from supi3.mcu import build as mcu_build
from supi3.mcu.board import Board
from supi3.mcu.core import (
    EXC_RETURN_HANDLER,
    EXC_RETURN_THREAD_MSP,
    EXC_RETURN_THREAD_PSP,
    EXTERNAL,
    FRAME_NAMES,
    XPSR_ALIGN,
    CortexM,
    FirmwareFaultError,
    FirmwareImage,
    FirmwareStoppedError,
    Stop,
    block_cost,
    countdown_register,
    is_poll_loop,
)

pytestmark = pytest.mark.skipif(mcu_build.toolchain_missing() is not None, reason=str(mcu_build.toolchain_missing()))

PROGRAMS = Path(__file__).parent / "mcu"
CPUS = ("cortex_m0", "cortex_m3")


@pytest.fixture(scope="module")
def exceptions_elf(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """exceptions.S linked with the board's linker script, once per module (Thumb-1: one ELF for both cores)."""
    out = tmp_path_factory.mktemp("mcu") / "exceptions.elf"
    return mcu_build.build(PROGRAMS / "exceptions.S", out, cpu="cortex_m0", port=False)


@pytest.fixture(scope="module")
def faults_elf(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return mcu_build.build(PROGRAMS / "faults.c", tmp_path_factory.mktemp("mcu") / "faults.elf")


def _sleep(core: CortexM, steps: int = 100) -> None:
    """Run until the core sleeps (WFI)."""
    for _ in range(steps):
        if core.step(core.cycles + 10_000) == "sleep":
            return
    raise AssertionError("the program did not reach its WFI")


def _word(core: CortexM, name: str, index: int = 0) -> int:
    return int(struct.unpack("<I", core.read_bytes(core.image.address(name) + 4 * index, 4))[0])


@pytest.mark.parametrize("misalign", [0, 4])
@pytest.mark.parametrize("cpu", CPUS)
def test_nested_exception_entry_and_return_to_thread_mode(exceptions_elf: Path, cpu: str, misalign: int) -> None:
    """IRQ 0 from thread mode stacks R0-R3, R12, LR, the return address and xPSR on the main stack and enters with
    LR = FFFFFFF9h; IRQ 1 (higher priority) preempts it with LR = FFFFFFF1h and the frame of handler mode; both
    return, and thread mode has its registers and stack pointer back (B1.5.6 to B1.5.8). A stack pointer that is
    4 mod 8 gets one more word and bit 9 in the stacked xPSR (B1.5.7)."""
    core = CortexM(exceptions_elf, cpu=cpu)
    _sleep(core)
    image = core.image
    assert core.pc == image.address("resume1")  # WFI done: the return address is the next instruction
    sp = core.reg("sp") - misalign
    core.set_reg("sp", sp)
    before = {name: core.reg(name) for name in ("r0", "r1", "r2", "r3", "r12", "lr", "xpsr")}
    assert before["r0"] == 0xA0A0_A0A0 and before["r12"] == 0xC0C0_C0C0
    core.pend(EXTERNAL + 0)
    _sleep(core)
    assert _word(core, "order") == 0x123  # IRQ 0 entered, IRQ 1 preempted it, IRQ 0 resumed
    assert _word(core, "seen0_lr") == EXC_RETURN_THREAD_MSP
    assert _word(core, "seen1_lr") == EXC_RETURN_HANDLER
    frame0 = _word(core, "seen0_sp")
    assert frame0 == (sp - 32) & ~7
    stacked = dict(zip(FRAME_NAMES, struct.unpack("<8I", core.read_bytes(frame0, 32)), strict=True))
    assert {name: stacked[name] for name in ("r0", "r1", "r2", "r3", "r12", "lr")} == \
        {name: before[name] for name in ("r0", "r1", "r2", "r3", "r12", "lr")}  # fmt: skip
    assert stacked["pc"] == image.address("resume1")
    assert stacked["xpsr"] == before["xpsr"] | (XPSR_ALIGN if misalign else 0)
    frame1 = _word(core, "seen1_sp")
    assert frame1 == frame0 - 32
    nested = struct.unpack("<8I", core.read_bytes(frame1, 32))
    assert nested[6] == image.address("irq0_resumed")  # the preempted handler's next instruction
    assert nested[7] & 0x1FF == EXTERNAL + 0  # its IPSR: exception 16 was running
    assert nested[5] == EXC_RETURN_THREAD_MSP  # its LR
    after = struct.unpack("<6I", core.read_bytes(image.address("after"), 24))
    assert after == (0xA0A0_A0A0, 0xA1A1_A1A1, 0xA2A2_A2A2, 0xA3A3_A3A3, 0xC0C0_C0C0, sp)
    assert core.active == [] and core.reg("xpsr") & 0x1FF == 0  # thread mode again
    assert core.pc == image.address("sleep2") + 2


@pytest.mark.parametrize("cpu", CPUS)
def test_exception_entry_and_return_cost_the_cores_cycles(exceptions_elf: Path, cpu: str) -> None:
    """MCU-2: 12 cycles entry and 10 return on the Cortex-M3, 16 and 16 on the Cortex-M0, around the handler's
    cycles (Irq1_Handler is one block of 12 instructions ending in BX LR)."""
    core = CortexM(exceptions_elf, cpu=cpu)
    _sleep(core)
    start = core.cycles
    entries: list[int] = []
    core.entered = entries.append
    core.pend(EXTERNAL + 1)
    assert core.step(start + 10_000) == "run"  # entry, the handler, the exception return
    assert entries == [EXTERNAL + 1]
    assert core.active == []
    handler = block_cost(core.read_bytes(core.image.address("Irq1_Handler"), 2 * 12))
    assert handler[0] == 12
    assert core.cycles == start + core.cpu.entry_cycles + handler[1] + core.cpu.return_cycles


@pytest.mark.parametrize("cpu", CPUS)
def test_a_pending_interrupt_at_the_return_is_tail_chained_on_the_same_frame(exceptions_elf: Path, cpu: str) -> None:
    """MCU-20: IRQ 1 and IRQ 0 pend together in thread mode; IRQ 1 (priority 40h) runs first, and at its return IRQ 0
    (80h, still above thread mode) starts on the frame IRQ 1 left, with the same EXC_RETURN, after the core's
    tail-chain cycles instead of a return and an entry; thread mode then gets its registers back (B1.5.8)."""
    core = CortexM(exceptions_elf, cpu=cpu)
    _sleep(core)
    entries: list[int] = []
    core.entered = entries.append
    core.pend(EXTERNAL + 1)
    core.pend(EXTERNAL + 0)
    start, thread_sp = core.cycles, core.reg("sp")
    assert core.step(start + 10_000) == "run"  # entry of IRQ 1, its handler, the tail-chain into IRQ 0
    assert entries == [EXTERNAL + 1, EXTERNAL + 0] and core.active == [EXTERNAL + 0]
    assert core.pc == core.image.address("Irq0_Handler")
    frame = core.reg("sp")
    assert frame == _word(core, "seen1_sp") == (thread_sp - 32) & ~7  # the one frame, not unstacked
    assert core.reg("lr") == _word(core, "seen1_lr") == EXC_RETURN_THREAD_MSP
    handler = block_cost(core.read_bytes(core.image.address("Irq1_Handler"), 2 * 12))
    assert core.cycles == start + core.cpu.entry_cycles + handler[1] + core.cpu.tail_chain_cycles
    _sleep(core)  # IRQ 0 pends IRQ 1 again, which preempts it; both return to thread mode
    assert core.active == [] and core.reg("sp") == thread_sp
    assert [_word(core, "after", k) for k in range(5)] == [0xA0A0A0A0, 0xA1A1A1A1, 0xA2A2A2A2, 0xA3A3A3A3, 0xC0C0C0C0]


def test_block_cost_counts_loads_stores_and_a_final_branch() -> None:
    """MCU-1: 1 cycle per instruction, +1 per single load/store, +N for N registers of PUSH/POP/LDM/STM, +2 for a
    block-ending branch."""
    assert block_cost(bytes.fromhex("0120")) == (1, 1)  # movs r0, #1
    assert block_cost(bytes.fromhex("0868")) == (1, 2)  # ldr r0, [r1]
    assert block_cost(bytes.fromhex("30b5")) == (1, 4)  # push {r4, r5, lr}
    assert block_cost(bytes.fromhex("0120fee7")) == (2, 4)  # movs; b .
    assert block_cost(bytes.fromhex("7047")) == (1, 3)  # bx lr
    assert block_cost(bytes.fromhex("d1f80800")) == (1, 2)  # ldr.w r0, [r1, #8]
    assert block_cost(bytes.fromhex("00f002f8")) == (1, 3)  # bl
    assert block_cost(bytes.fromhex("eff30880")) == (1, 1)  # mrs r0, msp: not a branch


def _line_of(path: Path, marker: str) -> int:
    """The 1-based line of ``path`` holding ``marker`` (the source line a report must name)."""
    return next(k for k, text in enumerate(path.read_text().splitlines(), 1) if marker in text)


def _faulting(faults_elf: Path, scenario: int) -> Board:
    board = Board(faults_elf)
    board.run_for(20e-6)  # reset, set-up, the main loop runs
    board.core.write_bytes(board.core.image.address("scenario"), struct.pack("<I", scenario))
    return board


def test_a_bus_fault_ends_the_run_with_the_hard_fault_frame(faults_elf: Path) -> None:
    board = _faulting(faults_elf, 1)
    with pytest.raises(FirmwareFaultError) as caught:
        board.run_for(20e-6)
    report = caught.value.report
    assert report.stop is Stop.FAULT
    assert "read of unmapped memory" in report.reason
    assert report.symbol == "fw_loop"
    assert report.stacked is not None and report.stacked["pc"] == report.pc  # the faulting instruction
    assert report.stacked["xpsr"] & 0x1FF == 0  # it ran in thread mode
    assert board.core.active == [3]  # HardFault taken as the core would, then stopped
    assert "stacked r0=" in str(caught.value)
    # BFSR.PRECISERR and BFARVALID, BFAR the address, escalated (B3.2.15, B3.2.16, B3.2.18)
    assert report.fault_status == {"CFSR": 1 << 9 | 1 << 15, "HFSR": 1 << 30, "BFAR": 0x3000_0000}
    assert str(caught.value).endswith("; CFSR=00008200h HFSR=40000000h BFAR=30000000h")
    assert board.core._scs_read(0xD28, 4) == 1 << 9 | 1 << 15  # what the HardFault handler reads
    board.core._scs_write(0xD28, 4, 1 << 9 | 1 << 15)  # write 1 to clear
    assert board.core._scs_read(0xD28, 4) == 0
    line = _line_of(PROGRAMS / "faults.c", "REG32(0x30000000u)")
    assert report.source is not None and (report.source.file, report.source.line) == ("faults.c", line)
    assert f"(fw_loop) faults.c:{line}" in str(caught.value)
    assert [frame.function for frame in report.backtrace] == ["fw_loop", "main", "Reset_Handler"]  # .debug_frame


FAULT_ADDRESSES = {
    1: ("precise bus fault: read of unmapped memory", 1 << 9 | 1 << 15, {"BFAR": 0x3000_0004}),
    2: ("precise bus fault: write to unmapped memory", 1 << 9 | 1 << 15, {"BFAR": 0x6000_0010}),
    3: ("instruction bus fault: fetch from unmapped memory", 1 << 8, {}),
    4: ("memory fault: execute from a peripheral region at 40010800h (Execute Never)", 1 << 0, {}),
    5: ("memory fault: write to read-only memory", 1 << 1 | 1 << 7, {"MMFAR": 0x0800_0100}),
}
"""tests/mcu/fault_address.S's scenarios: the reason, CFSR (B3.2.15: PRECISERR 9 and BFARVALID 15, IBUSERR 8,
IACCVIOL 0, DACCVIOL 1 and MMARVALID 7) and the address registers loaded."""


@pytest.mark.parametrize("cpu", CPUS)
@pytest.mark.parametrize("scenario", list(FAULT_ADDRESSES))
def test_a_data_fault_loads_bfar_or_mmfar_with_its_valid_bit(tmp_path: Path, scenario: int, cpu: str) -> None:
    """MCU-3: a precise data bus fault loads BFAR with the address and sets BFARVALID (B3.2.18), a data access
    violation MMFAR and MMARVALID (B3.2.17); an instruction fetch fault (IBUSERR, IACCVIOL: a fetch from a peripheral
    region, Execute Never in the default memory map, B3.1) loads neither. The report shows them after CFSR and HFSR,
    and the HardFault handler would read them in the SCS; the Cortex-M0 (ARMv6-M) has none of these registers. The
    board maps flash writable and has no MPU, so scenario 5 makes flash read-only through unicorn first: no firmware
    on this board can raise a DACCVIOL."""
    elf = mcu_build.build(PROGRAMS / "fault_address.S", tmp_path / "fa.elf", cpu="cortex_m0", port=False,
                          defines={"SCENARIO": str(scenario)})  # fmt: skip
    board = Board(elf, cpu=cpu)
    if scenario == 5:
        board.core.uc.mem_protect(*board.core.flash, ucc.UC_PROT_READ | ucc.UC_PROT_EXEC)
    with pytest.raises(FirmwareFaultError) as caught:
        board.run(1)
    reason, cfsr, loaded = FAULT_ADDRESSES[scenario]
    report = caught.value.report
    assert reason in report.reason and board.core.active == [3]
    assert report.stacked is not None and report.stacked["r0"] == 5
    if cpu == "cortex_m0":
        assert report.fault_status is None
        return
    assert report.fault_status == {"CFSR": cfsr, "HFSR": 1 << 30, **loaded}
    assert str(caught.value).endswith(" ".join(f"{name}={value:08X}h" for name, value in report.fault_status.items()))
    for name, offset in (("MMFAR", 0xD34), ("BFAR", 0xD38)):
        if name in loaded:
            assert board.core._scs_read(offset, 4) == loaded[name]
    if scenario < 3:
        assert report.pc == board.core.image.address("faulting")  # precise: the faulting load or store


def test_a_report_without_the_elf_names_no_line(faults_elf: Path, tmp_path: Path) -> None:
    """MCU-12: the DWARF tables are read on first use; an ELF gone by then gives a report without lines, not an
    error of its own."""
    copy = tmp_path / "gone.elf"
    copy.write_bytes(faults_elf.read_bytes())
    board = _faulting(copy, 1)
    copy.unlink()
    with pytest.raises(FirmwareFaultError, match="read of unmapped memory") as caught:
        board.run_for(20e-6)
    assert caught.value.report.symbol == "fw_loop" and caught.value.report.source is None


def test_an_undefined_instruction_ends_the_run_with_a_usage_fault(faults_elf: Path) -> None:
    board = _faulting(faults_elf, 4)
    with pytest.raises(FirmwareFaultError, match="undefined instruction") as caught:
        board.run_for(20e-6)
    assert caught.value.report.symbol == "fw_loop"
    assert board.core.read_bytes(caught.value.report.pc, 2) == b"\x00\xde"
    assert caught.value.report.fault_status == {"CFSR": 1 << 16, "HFSR": 1 << 30}  # UFSR.UNDEFINSTR


def test_an_endless_loop_ends_when_the_instruction_budget_runs_out(faults_elf: Path) -> None:
    board = _faulting(faults_elf, 2)
    with pytest.raises(FirmwareStoppedError, match="instruction budget of 50000") as caught:
        board.run(1000, max_instructions=50_000)
    report = caught.value.report
    assert report.stop is Stop.BUDGET and report.symbol == "fw_loop"
    assert report.source is not None and report.source.file == "faults.c"
    assert report.source.line in range(
        _line_of(PROGRAMS / "faults.c", "case 2u"), _line_of(PROGRAMS / "faults.c", "case 3u")
    )
    assert board.bench.cycles < 1000


def test_an_interrupt_without_handler_is_a_hang_in_default_handler(faults_elf: Path) -> None:
    board = _faulting(faults_elf, 3)
    with pytest.raises(FirmwareStoppedError, match="endless loop") as caught:
        board.run(10)
    report = caught.value.report
    assert report.stop is Stop.HANG and report.pc == board.core.image.address("Default_Handler")
    assert board.core.active == [15]  # SysTick


def test_the_image_names_its_symbols(exceptions_elf: Path) -> None:
    image = FirmwareImage.load(exceptions_elf)
    assert image.entry & ~1 == image.address("Reset_Handler")
    assert image.function_at(image.address("Irq1_Handler")) == "Irq1_Handler"
    with pytest.raises(ValueError, match="name must be a symbol"):
        image.address("nothing")


def test_systick_counts_down_from_its_reload_and_pends_on_each_wrap(exceptions_elf: Path) -> None:
    """B3.3: a CVR write clears the counter, the next tick loads RVR, the counter reaching 0 sets COUNTFLAG (read
    clears it) and, with TICKINT, pends SysTick: every RVR + 1 ticks."""
    core = CortexM(exceptions_elf)
    systick = core.systick
    systick.write(0x4, 99)  # RVR
    systick.write(0x8, 0)  # CVR
    systick.write(0x0, 0b111)  # ENABLE, TICKINT, CLKSOURCE = core clock
    start = core.cycles
    assert systick.next_event() == start + 100
    for ticks, value in ((1, 99), (50, 50), (99, 1), (100, 0), (101, 99), (200, 0)):
        core.cycles = start + ticks
        assert systick.read(0x8) == value, ticks
    core.cycles = start + 99
    systick.update()
    assert 15 not in core.pending and not systick.read(0x0) & (1 << 16)
    core.cycles = start + 100
    systick.update()
    assert 15 in core.pending
    assert systick.read(0x0) & (1 << 16) and not systick.read(0x0) & (1 << 16)  # COUNTFLAG clears on read
    assert systick.next_event() == start + 200


def test_primask_holds_an_interrupt_until_cleared(exceptions_elf: Path) -> None:
    """B1.5.4: PRIMASK = 1 raises the execution priority to 0: IRQ 0 stays pending and the core sleeps on."""
    core = CortexM(exceptions_elf)
    _sleep(core)
    core.set_reg("primask", 1)
    core.pend(EXTERNAL + 0)
    assert core.step(core.cycles + 1000) == "sleep"
    assert core.active == [] and EXTERNAL + 0 in core.pending
    core.set_reg("primask", 0)
    core.pend(EXTERNAL + 0)
    _sleep(core)
    assert _word(core, "order") == 0x123


@pytest.mark.parametrize("cpu", CPUS)
def test_an_interrupt_in_thread_mode_on_the_process_stack_stacks_there_and_returns_there(
    exceptions_elf: Path, cpu: str
) -> None:
    """Thread mode on the process stack (CONTROL.SPSEL = 1): the entry stacks the frame on the PSP, the handler runs
    on the main stack with LR = FFFFFFFDh and SPSEL = 0, and the return unstacks from the PSP and selects it again
    (B1.5.6, B1.5.8), at the same cycles as on the main stack."""
    core = CortexM(exceptions_elf, cpu=cpu)
    _sleep(core)
    msp, psp = core.reg("msp"), 0x2000_4000
    core.set_reg("psp", psp)
    core.set_reg("control", 0b10)
    assert core.reg("sp") == psp
    core.pend(EXTERNAL + 1)
    start = core.cycles
    assert core.step(start + 10_000) == "run"  # entry, Irq1_Handler, the exception return
    assert _word(core, "seen1_lr") == EXC_RETURN_THREAD_PSP
    assert _word(core, "seen1_sp") == msp  # the handler's stack: the main one, untouched by the frame
    frame = dict(zip(FRAME_NAMES, struct.unpack("<8I", core.read_bytes(psp - 32, 32)), strict=True))
    assert [frame[r] for r in ("r0", "r1", "r2", "r3", "r12")] == [0xA0A0A0A0, 0xA1A1A1A1, 0xA2A2A2A2, 0xA3A3A3A3,
                                                                  0xC0C0C0C0]  # fmt: skip
    assert frame["pc"] == core.image.address("resume1") == core.pc
    assert core.active == [] and core.reg("control") == 0b10
    assert (core.reg("sp"), core.reg("psp"), core.reg("msp")) == (psp, psp, msp)
    handler = block_cost(core.read_bytes(core.image.address("Irq1_Handler"), 2 * 12))
    assert core.cycles == start + core.cpu.entry_cycles + handler[1] + core.cpu.return_cycles


def test_memory_outside_flash_and_ram_is_a_named_error_and_a_fault_when_unstacked(exceptions_elf: Path) -> None:
    """The host's reads and writes of unmapped memory raise ArgumentError naming the memories; an exception return
    whose stack pointer leaves RAM is an unstacking fault with a report (B1.5.8), an exception entry whose vector
    table is not in memory a vector read fault (B1.5.6), not unicorn's own error."""
    core = CortexM(exceptions_elf)
    ram_end = core.ram[0] + core.ram[1]
    for address, size in ((0, 4), (ram_end - 2, 4), (0x4000_0000, 1)):
        with pytest.raises(ArgumentError, match=f"address must start {size} bytes of mapped memory .*RAM 20000000h"):
            core.read_bytes(address, size)
        with pytest.raises(ArgumentError, match="address must start"):
            core.write_bytes(address, bytes(size))
    _sleep(core)
    core.enter(EXTERNAL + 0)
    core.set_reg("sp", ram_end)
    with pytest.raises(FirmwareFaultError, match=f"unstacking error: the frame at {ram_end:08X}h is not in memory"):
        core.exception_return(EXC_RETURN_THREAD_MSP)
    core = CortexM(exceptions_elf)
    core.vtor = 0x3000_0000  # as a write of SCB->VTOR would set it
    with pytest.raises(FirmwareFaultError, match="vector table read error: entry 16 \\(IRQ 0\\) at VTOR 30000000h"):
        core.enter(EXTERNAL + 0)


@pytest.mark.parametrize(
    ("code", "pure"),
    [
        ("0168 c907 fcd0", True),  # ldr r1, [r0]; lsls r1, r1, #31; beq .-4: wait for RXNE
        ("0168 0906 fcd4", True),  # ldr r1, [r0]; lsls r1, r1, #24; bmi: wait while BSY
        ("0168 0142 fcd0", True),  # ldr r1, [r0]; tst r1, r0; beq
        ("0068 c007 fcd0", False),  # ldr r0, [r0]: the base is overwritten
        ("0168 4a1c c907 fbd0", False),  # adds r2, r1, #1: another register written
        ("0168 c907 fdd0", False),  # the branch does not go back to the block's start
        ("0168 c907 fce7", False),  # b: not a poll (no exit)
    ],
)
def test_a_pure_poll_loop_is_a_load_tests_and_a_branch_back(code: str, pure: bool) -> None:
    """MCU-10: only loops that write nothing but the loaded register and the flags are skipped."""
    assert is_poll_loop(bytes.fromhex(code.replace(" ", "")), 0x0800_0100) is pure


@pytest.mark.parametrize(
    ("code", "register"),
    [
        ("401e fdd1", 0),  # subs r0, r0, #1; bne .-2 (T1): the board port's wait
        ("5b1e fdd1", 3),  # subs r3, r3, #1 (T1)
        ("013f fdd1", 7),  # subs r7, #1 (T2)
        ("481e fdd1", -1),  # subs r0, r1, #1: counts another register down
        ("801e fdd1", -1),  # subs r0, r0, #2
        ("401e fcd1", -1),  # bne elsewhere
        ("401e fdd0", -1),  # beq
        ("401e fdd1 00bf", -1),  # more than the two instructions
    ],
)
def test_a_countdown_loop_is_subs_1_and_bne_back(code: str, register: int) -> None:
    """MCU-11: only SUBS Rd, Rd, #1 and BNE to it are counted without running (they write only Rd and flags)."""
    assert countdown_register(bytes.fromhex(code.replace(" ", ""))) == register

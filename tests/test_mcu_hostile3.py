"""The native block hook (hook.c, supi3.mcu.hook; MCU-25, MCU-28) as a hostile user and a C reviewer drive it.

MCU-28: code the firmware writes into RAM and runs is costed from its bytes each time it runs, so a block rewritten
in place (same address, same size) never runs with the cost, countdown register (MCU-11) or poll flag of the code it
replaced; a deadline up to MAX_DEADLINE (2^63 - 1) cycles away keeps the countdown skip, whose arithmetic never passes
INT64_MAX, and counts past 2^32 instructions; a later one is an ArgumentError, not a wrap to cycle 0. The
structs hook.c shares with ctypes have, field by field, the offsets the compiler gave them (checked at load); a
cached library cut short, or a cache folder given as ".", is a named error or loads, never a crash of the process.

MCU-29: SPI1's reset through RCC_APB2RSTR (RM0008 7.3.4) takes back the native answers and resets SPI1, or is a named
error (held in reset, a byte shifting).
"""

from __future__ import annotations

import ctypes
import os
import subprocess
import sys
from pathlib import Path

import pytest

from supi3.errors import ArgumentError
from supi3.mcu import build as mcu_build
from supi3.mcu import hook
from supi3.mcu.core import CPUS, MAX_DEADLINE, CortexM, HeldRegister
from supi3.mcu.stm32 import (
    APB2ENR,
    APB2RSTR,
    CR1_MSTR,
    CR1_SPE,
    CR1_SSI,
    CR1_SSM,
    IOPAEN,
    SPI1EN,
    SPI_CR1,
    SPI_CR2,
    SPI_DR,
    SPI_SR,
    SR_BSY,
    SR_RXNE,
    SR_TXE,
    PeripheralResetError,
    Rcc,
    Spi,
)
from supi3.sdk.native import CACHE_ENV
from test_mcu_stm32 import Clock

pytestmark = pytest.mark.skipif(mcu_build.toolchain_missing() is not None, reason=str(mcu_build.toolchain_missing()))

PROGRAMS = Path(__file__).parent / "mcu"
_TOP = (1 << 64) - 1


@pytest.fixture(scope="module")
def programs(tmp_path_factory: pytest.TempPathFactory) -> dict[tuple[str, str], Path]:
    """ram_rewrite.S, long_count.S and flash_rewrite.S built for each core, once per module."""
    folder = tmp_path_factory.mktemp("hostile3")
    return {(name, cpu): mcu_build.build(PROGRAMS / f"{name}.S", folder / f"{name}_{cpu}.elf", cpu=cpu, port=False)
            for name in ("ram_rewrite", "long_count", "flash_rewrite") for cpu in CPUS}  # fmt: skip


def _run_to_done(core: CortexM, deadline: int) -> None:
    """Step the core until it sits on the thread's ``b .`` (``done``)."""
    for _ in range(20):
        core.step(deadline)
        if core.idle_loop():
            return
    raise AssertionError(f"the core did not reach done: PC {core.pc:08X}h, {core.cycles} cycles")


@pytest.mark.parametrize("cpu", CPUS)
def test_code_rewritten_in_ram_runs_with_its_own_cost(programs: dict[tuple[str, str], Path], cpu: str) -> None:
    """ram_rewrite.S: a countdown block on R3 in RAM, rewritten in place into one on R4 (same address, same size).
    The second loop leaves R3 = 1000 and costs what it runs, with the skips (MCU-10, MCU-11) on, off, and with the
    deadline near (the skip bounded by it) or MAX_DEADLINE; before MCU-28 the cached block skipped R3 down to 1."""
    results = []
    for skip, step in ((True, 50), (True, MAX_DEADLINE), (False, 50), (False, MAX_DEADLINE)):
        core = CortexM(programs["ram_rewrite", cpu], cpu=cpu)
        core.skip_polls = skip
        for _ in range(2000):
            core.step(min(MAX_DEADLINE, core.cycles + step))
            if core.idle_loop():
                break
        results.append((core.reg("r3"), core.reg("r4"), core.cycles, core.instructions))
    assert results[0][:2] == (1000, 0)
    assert results == [results[0]] * 4
    # 12 set-up instructions, 100 iterations of 2, 1 BX, 5 re-write instructions, 100 iterations, 1 BX
    # 9 set-up instructions, 100 iterations of SUBS and BNE, BX, 6 to rewrite and call, 100 iterations, BX, the b .
    assert results[0][3] == 9 + 200 + 1 + 6 + 200 + 1 + 1


@pytest.mark.parametrize("cpu", CPUS)
def test_code_the_firmware_rewrites_in_flash_runs_with_its_own_cost(programs: dict[tuple[str, str], Path],
                                                                    cpu: str) -> None:  # fmt: skip
    """flash_rewrite.S: a countdown loop in flash on R0, run, then rewritten by a halfword store into one on R1: the
    store stops the run at its block's end and the core forgets every cost of code (MCU-28), so the second call
    leaves R0 = 1000, with the skips on and off; before, the cached block skipped R0 down."""
    results = []
    for skip in (True, False):
        core = CortexM(programs["flash_rewrite", cpu], cpu=cpu)
        core.skip_polls = skip
        _run_to_done(core, MAX_DEADLINE)
        results.append((core.reg("r0"), core.reg("r1"), core.cycles, core.instructions))
    assert results[0][:2] == (1000, 0)
    assert results[0] == results[1]
    # movs, bl, 10 iterations, bx, ldr, ldr, strh, ldr, movs, bl, 10 iterations, bx, the b .
    assert results[0][3] == 2 + 20 + 1 + 6 + 20 + 1 + 1


@pytest.mark.parametrize("cpu", CPUS)
def test_host_writes_into_ram_code_between_runs_are_seen(programs: dict[tuple[str, str], Path], cpu: str) -> None:
    """The host patches the RAM function between runs (CortexM.write_bytes) after its first call: the second call
    runs the patched bytes with their cost, as the firmware's own store would."""
    core = CortexM(programs["ram_rewrite", cpu], cpu=cpu)
    ramfn = core.image.address("ramfn")
    _run_to_done(core, MAX_DEADLINE)
    assert core.read_bytes(ramfn, 4) == bytes.fromhex("013cfdd1")  # subs r4, #1; bne
    assert (core.reg("r3"), core.reg("r4")) == (1000, 0)
    # the loop again, now on R3 (3B01h) patched by the host, called from `done` by hand: R3 counts down, R4 stays
    core.write_bytes(ramfn, bytes.fromhex("013bfdd1"))
    core.set_reg("r3", 7)
    core.set_reg("r4", 5)
    core.set_reg("lr", core.pc | 1)
    core.set_reg("pc", ramfn)
    _run_to_done(core, MAX_DEADLINE)
    assert (core.reg("r3"), core.reg("r4")) == (0, 5)


@pytest.mark.parametrize("cpu", CPUS)
@pytest.mark.parametrize("deadline", [(1 << 62), MAX_DEADLINE - 2, MAX_DEADLINE])
def test_a_far_deadline_keeps_the_countdown_skip(programs: dict[tuple[str, str], Path], cpu: str,
                                                 deadline: int) -> None:  # fmt: skip
    """long_count.S counts R0 down from 2^32 - 1: with a deadline 2^62 cycles away up to MAX_DEADLINE (2^63 - 1) the
    countdown skip (MCU-11) takes all but the last iteration at once, past 2^32 instructions. Before MCU-28 the
    ceiling of a count near INT64_MAX overflowed (and a deadline more than 2^63 - 1 cycles away turned negative) and
    the 2^32 iterations ran one by one: the run seemed to hang."""
    core = CortexM(programs["long_count", cpu], cpu=cpu)
    _run_to_done(core, deadline)
    assert core.reg("r0") == 0
    assert core.instructions == 3 + 2 * ((1 << 32) - 1) + 1  # movs, subs, b; 2^32 - 1 iterations of subs, bne; b .
    assert core.instructions > 1 << 32 and core.cycles > 1 << 33


@pytest.mark.parametrize("deadline", [MAX_DEADLINE + 1, _TOP, 1 << 64, -1])
def test_a_deadline_past_the_64_bit_clock_is_an_argument_error(programs: dict[tuple[str, str], Path],
                                                               deadline: int) -> None:  # fmt: skip
    """step(2^64) was stored modulo 2^64 (cycle 0): a run that returned at once, forever; a deadline past 2^63 - 1
    left the 64-bit clock no room not to wrap. Now an ArgumentError, from step and the deadline's setter."""
    core = CortexM(programs["long_count", "cortex_m0"], cpu="cortex_m0")
    for attempt in (lambda: core.step(deadline), lambda: setattr(core, "deadline", deadline)):
        with pytest.raises(ArgumentError, match=r"deadline must be an integer from 0 to 9223372036854775807 \(core "
                                                r"cycles: MAX_DEADLINE \(MCU-28\)\)"):  # fmt: skip
            attempt()
    assert (core.cycles, core.instructions) == (0, 0)


def test_the_shared_structs_match_the_compiled_layout() -> None:
    """Every field of Block, State and Held sits at the offset hook.c's compiler gave it, and the sizes agree (the
    library's own tables); a ctypes mirror that differs (a field moved) is a NativeHookError at load."""
    loaded = hook.library()
    for table, structure in (("supi3_block_layout", hook.Block), ("supi3_state_layout", hook.State),
                             ("supi3_held_layout", hook.Held)):  # fmt: skip
        assert hook.native_layout(loaded, table) == hook.layout(structure)
        assert len(hook.layout(structure)) == len(structure._fields_) + 1

    class Moved(ctypes.Structure):
        _fields_ = (("size", ctypes.c_uint32), ("address", ctypes.c_uint32), ("instructions", ctypes.c_uint64))

    original = hook._LAYOUTS["supi3_block_layout"]
    try:
        hook._LAYOUTS["supi3_block_layout"] = Moved
        with pytest.raises(hook.NativeHookError, match=r"lays out Moved as \[24, 0, 4, 8, 12, 16, 20\].*another "
                                                       r"source or for another ABI"):  # fmt: skip
            hook.check_layout(loaded, "x.so")
    finally:
        hook._LAYOUTS["supi3_block_layout"] = original


_LOAD_CUTS = """
import sys
from pathlib import Path
from supi3.mcu import hook
whole = Path(sys.argv[1]).read_bytes()
target = hook.cached_path()
target.parent.mkdir(parents=True, exist_ok=True)
for cut in map(int, sys.argv[2:]):
    target.write_bytes(whole[:cut])
    hook._LOADED.clear()
    try:
        hook.library()
        print(cut, "loaded")
    except hook.NativeHookError as error:
        print(cut, "named", "cut short" in str(error) or "does not load" in str(error))
"""


def test_a_cached_library_cut_short_is_a_named_error(tmp_path: Path) -> None:
    """A cached library cut anywhere (a full disk, a broken copy) is refused with a NativeHookError before the loader
    maps it: before, a cut at 1000 bytes crashed the process in dlopen (SIGSEGV). Checked for every cut from 6 bytes
    on (in steps of 23) by check_whole, and through library() in a separate process for a few."""
    whole = Path(hook.library()._name)
    data = whole.read_bytes()
    hook.check_whole(whole)
    cut_file = tmp_path / "cut.so"
    for cut in range(6, len(data), 23):
        cut_file.write_bytes(data[:cut])
        with pytest.raises(hook.NativeHookError, match=r"is cut short: \d+ bytes, its ELF headers name \d+"):
            hook.check_whole(cut_file)
    cuts = [0, 5, 64, 1000, len(data) // 2, len(data) - 1]
    env = {**os.environ, CACHE_ENV: str(tmp_path / "cache"), "PYTHONPATH": os.pathsep.join(sys.path)}
    result = subprocess.run([sys.executable, "-c", _LOAD_CUTS, str(whole), *map(str, cuts)], env=env,
                            capture_output=True, text=True, check=False, timeout=120)  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert result.stdout.split("\n")[:-1] == [f"{cut} named True" for cut in cuts]


def test_a_cache_folder_given_as_dot_builds_and_loads(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """SUPI3_NATIVE_CACHE=. (and a relative folder): the library is built there and loaded by its absolute path.
    Before, "." made the path a bare file name, which the loader looked up on the system's library path: "cannot
    open shared object file". An empty value is the default folder."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(hook, "_LOADED", [])
    monkeypatch.setenv(CACHE_ENV, ".")
    assert hook.cached_path().parent == tmp_path
    loaded = hook.library()
    assert Path(loaded._name).parent == tmp_path and Path(loaded._name).is_file()
    monkeypatch.setenv(CACHE_ENV, "sub/dir")
    assert hook.cached_path().parent == tmp_path / "sub" / "dir"
    monkeypatch.setenv(CACHE_ENV, "")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert hook.cached_path().parent == tmp_path / "xdg" / "supi3" / "native"


@pytest.mark.parametrize("cpu", CPUS)
def test_host_writes_into_flash_code_between_runs_are_seen(programs: dict[tuple[str, str], Path], cpu: str) -> None:
    """The host turns long_count.S's loop on R0 (flash, cached natively after its run) into one on R1: run again
    from the loop, R1 counts down and R0 stays; before, the cached countdown (MCU-11) skipped R0 and unicorn ran its
    old translation."""
    core = CortexM(programs["long_count", cpu], cpu=cpu)
    _run_to_done(core, MAX_DEADLINE)
    loop = core.image.address("done") - 4
    assert core.read_bytes(loop, 4) == bytes.fromhex("0138fdd1")  # subs r0, #1; bne
    core.write_bytes(loop, bytes.fromhex("0139"))  # subs r1, #1
    core.set_reg("r0", 1234)
    core.set_reg("r1", 50)
    core.set_reg("pc", loop)
    before = core.instructions
    _run_to_done(core, MAX_DEADLINE)
    assert (core.reg("r0"), core.reg("r1"), core.instructions - before) == (1234, 0, 100 + 1)


class _Native:
    """A HeldRegister stand-in that notes what SPI1 tells the core, and may say the offered DR read was taken."""

    def __init__(self) -> None:
        self.log: list[str] = []
        self.taken: int | None = None

    def hold(self, offset: int, value: int, until: int | None, after: int | None) -> None:
        del value, until, after
        self.log.append(f"hold {offset}")

    def release(self) -> None:
        self.log.append("release")

    def offer(self, offset: int, value: int, start: int, then: int) -> None:
        del value, start, then
        self.log.append(f"offer {offset}")

    def withdraw(self) -> int | None:
        taken, self.taken = self.taken, None
        return taken


class _Echo:
    def spi_byte(self, tx: int, bits: int, start: int, period: int, cr1: int) -> int:
        del bits, start, period, cr1
        return tx ^ 0xFF


def _spi1() -> tuple[Rcc, Spi, Clock, _Native]:
    rcc, clock, native = Rcc(), Clock(), _Native()
    rcc.write(APB2ENR, 4, SPI1EN | IOPAEN)
    spi = Spi(rcc, clock, _Echo(), clock)
    spi.holder = spi.offer = native
    spi.write(SPI_CR1, 4, CR1_MSTR | CR1_SSM | CR1_SSI | CR1_SPE)  # BR = 0: 16 clocks a byte
    return rcc, spi, clock, native


def test_spi1_reset_through_rcc_resets_it_or_is_a_named_error() -> None:
    """RCC_APB2RSTR's SPI1RST (bit 12, RM0008 7.3.4; MCU-29): before, the write was kept and ignored, and SPI1 went
    on with its CR1, received byte and held SR. Now: the native answers are taken back first (an offered DR read
    already taken caught up with at its time), SPI1 goes to its reset values (CR1 0, SR TXE, DR 0), an access while
    held in reset and a reset while a byte shifts are each a PeripheralResetError; other bits leave SPI1 alone."""
    rcc, spi, clock, native = _spi1()
    spi.write(SPI_DR, 4, 0x5A)
    assert spi.read(SPI_SR, 4) & SR_BSY
    clock.cycles = 8
    with pytest.raises(PeripheralResetError, match=r"SPI1 reset \(RCC_APB2RSTR bit 12\) at cycle 8 while a byte "
                                                   r"shifts: a cut byte is not modelled"):  # fmt: skip
        rcc.write(APB2RSTR, 4, SPI1EN)
    # the byte ends at 16; the core took the offered DR read at 16 natively, then the firmware resets SPI1
    rcc, spi, clock, native = _spi1()
    spi.write(SPI_DR, 4, 0x5A)
    spi.read(SPI_SR, 4)
    native.log.clear()
    native.taken = clock.cycles = 16
    rcc.write(APB2RSTR, 4, IOPAEN)  # GPIOA's reset bit only: SPI1 untouched but the holds taken back
    assert native.log == ["release"] and spi.rx_last == 0xA5 and spi.rx_buffer is None
    spi.write(SPI_DR, 4, 0x11)
    clock.cycles = 40  # the byte has ended: RXNE
    assert spi.read(SPI_SR, 4) & SR_RXNE
    native.log.clear()
    rcc.write(APB2RSTR, 4, SPI1EN | IOPAEN)
    assert native.log == ["release"]
    for access in (lambda: spi.read(SPI_SR, 4), lambda: spi.write(SPI_CR1, 4, CR1_SPE)):
        with pytest.raises(PeripheralResetError, match=r"SPI1 accessed while RCC_APB2RSTR bit 12 holds it in reset"):
            access()
    rcc.write(APB2RSTR, 4, 0)
    assert (spi.read(SPI_CR1, 4), spi.read(SPI_SR, 4), spi.read(SPI_DR, 4)) == (0, SR_TXE, 0)
    assert rcc.read(APB2RSTR, 4) == 0


def test_a_folder_in_the_library_s_place_is_a_named_error(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A folder where the cached library goes: the build cannot be renamed into place. Before, an IsADirectoryError
    with a traceback; now a NativeHookError naming the place, and no temporary file is left."""
    monkeypatch.setattr(hook, "_LOADED", [])
    monkeypatch.setenv(CACHE_ENV, str(tmp_path))
    hook.cached_path().mkdir()
    with pytest.raises(hook.NativeHookError, match=r"cannot be put at .*_supi3_mcu_hook_\w+\.so \(MCU-25\): "
                                                   r"\[Errno 21\] Is a directory"):  # fmt: skip
        hook.library()
    assert [path.name for path in tmp_path.iterdir()] == [hook.cached_path().name]


@pytest.mark.parametrize("late", [-1, 0, 1])
def test_a_dr_read_at_the_byte_s_end_answers_as_the_model(late: int) -> None:
    """DR read by the core one cycle before, exactly at and one cycle after the byte's end (MCU-26's offer starts at
    the end, inclusive, as the model's byte ends at it): hook.c's ``supi3_held_read`` returns what the model returns,
    and SR after it too."""
    answers = []
    for native in (True, False):
        state = hook.State()
        state.skip_polls = 1

        def polled(state: hook.State = state) -> int:
            state.handed = max(state.handed, state.cycles)
            return int(state.handed)

        rcc = Rcc()
        rcc.write(APB2ENR, 4, SPI1EN)
        spi = Spi(rcc, polled, _Echo(), polled)

        slow_reads: list[int] = []

        def slow(handle: int, offset: int, size: int, data: int, spi: Spi = spi, log: list[int] = slow_reads) -> int:
            del handle, data
            log.append(offset)
            return spi.read(offset, size)

        callback = hook.MMIO_READ(slow)
        held = hook.Held(ctypes.pointer(state), callback)
        if native:
            spi.holder = spi.offer = HeldRegister(held)
        read = hook.library().supi3_held_read
        read.restype, read.argtypes = ctypes.c_uint64, (ctypes.c_void_p, ctypes.c_uint64, ctypes.c_uint,
                                                        ctypes.c_void_p)  # fmt: skip
        spi.write(SPI_CR1, 4, CR1_MSTR | CR1_SSM | CR1_SSI | CR1_SPE)
        spi.write(SPI_DR, 4, 0x3C)  # ends at cycle 16
        state.cycles = 16 + late
        values = [int(read(None, offset, 4, ctypes.byref(held))) for offset in (SPI_DR, SPI_SR, SPI_DR, SPI_SR)]
        spi.write(SPI_CR2, 4, 0)  # the model catches up
        answers.append((values, spi.rx_last, spi.rx_buffer, int(state.handed)))
        if native:  # from the end on the byte's DR read and SR after it are answered in C (a second DR read goes to
            # the model, MCU-26); before the end, every read goes to the model
            assert slow_reads == [SPI_DR, SPI_SR] * (1 if late >= 0 else 2), slow_reads
    assert answers[0] == answers[1]
    assert answers[0][0][0] == (0xC3 if late >= 0 else 0)

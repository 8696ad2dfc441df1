"""The core's block hook in native code (MCU-25): ``hook.c`` built for the host with the Zig toolchain from PyPI. It
also holds the exception entry's, tail-chain's and return's register and memory traffic, a run's start and the
interrupt hook (MCU-70 to MCU-72), which :class:`supi3.mcu.core.CortexM` calls with its :class:`State`.

Ref: unicorn.h (uc_cb_hookcode_t, uc_cb_eventmem_t, uc_cb_tlbevent_t); decisions MCU-1, MCU-10, MCU-11, MCU-25,
MCU-89 in docs/assumptions/mcu.md. The C source ships with the package; :func:`library` compiles it on first use with

    python -m ziglang cc -shared -fPIC -O2 -target native -mcpu=baseline -nostdlib -std=c99 -Wall -Wextra
        -pedantic -Werror hook.c -o <cache>/_supi3_mcu_hook_<hash>.so

into the native build cache (:func:`supi3.sdk.native.default_cache_dir`), keyed by the source, the flags, the
compiler's version and the machine, and loads it with ctypes. Parallel processes (pytest-xdist workers) each build
into a temporary file of the cache folder and rename it into place: a process sees no file or a whole one. The
library links against nothing: the unicorn functions it calls are pointers in :class:`State`. Before it is used, a
cached file is checked whole (:func:`check_whole`) and its structs' layout against the ctypes mirrors
(:func:`check_layout`; MCU-28).
"""

from __future__ import annotations

import ctypes
import hashlib
import importlib.metadata
import os
import platform
import struct
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Final

from supi3.errors import Supi3Error
from supi3.sdk.native import default_cache_dir

__all__ = ["BUS_DUE", "DESCRIBE", "FLAGS", "MMIO_READ", "MMIO_WRITE", "SOURCE", "Block", "Frames", "Held",
           "Memory", "NativeHookError", "Port", "Prefix", "State", "cached_path", "check_layout", "check_whole",
           "layout", "library", "native_layout"]

SOURCE: Final[Path] = Path(__file__).with_name("hook.c")
FLAGS: Final[tuple[str, ...]] = ("-shared", "-fPIC", "-O2", "-target", "native", "-mcpu=baseline", "-nostdlib",
                                 "-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror")  # fmt: skip
"""The host build of :data:`SOURCE`: position-independent, no C library, the SDK's strictness."""

DESCRIBE: Final = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_uint64, ctypes.c_uint32)
"""``describe(address, size)``: Python's cost of a block not in the cache (fills it and :attr:`State.fresh`);
nonzero stops the run."""
MMIO_READ: Final = ctypes.CFUNCTYPE(ctypes.c_uint64, ctypes.c_void_p, ctypes.c_uint64, ctypes.c_uint, ctypes.c_void_p)
"""unicorn.h's uc_cb_mmio_read_t: a peripheral's read (``handle, offset, size, user data -> value``)."""


class NativeHookError(Supi3Error, RuntimeError):
    """The native block hook cannot be built or loaded here (no ziglang, or the compiler failed): the emulated core
    needs it (MCU-25); the firmware extra installs the compiler (``pip install supi3[firmware]``)."""


class Block(ctypes.Structure):
    """A cached block cost (``supi3_block``): the block's address and size (0: empty), its instructions and cycles
    (MCU-1), the register it counts down or -1 (MCU-11), whether it is a pure poll loop (MCU-10)."""

    _fields_ = (("address", ctypes.c_uint32), ("size", ctypes.c_uint32), ("instructions", ctypes.c_uint32),
                ("cycles", ctypes.c_uint32), ("countdown", ctypes.c_int32), ("poll", ctypes.c_int32))  # fmt: skip


class State(ctypes.Structure):
    """The state the native hook shares with :class:`supi3.mcu.core.CortexM` (``supi3_state`` of hook.c)."""

    _fields_ = (
        ("cycles", ctypes.c_uint64),
        ("instructions", ctypes.c_uint64),
        ("deadline", ctypes.c_uint64),
        ("block_start", ctypes.c_uint64),
        ("block_address", ctypes.c_uint64),
        ("block_end", ctypes.c_uint64),
        ("skip_until", ctypes.c_uint64),
        ("skip_address", ctypes.c_uint64),
        ("handed", ctypes.c_uint64),
        ("skip_pending", ctypes.c_uint32),
        ("stop_request", ctypes.c_uint32),
        ("skip_polls", ctypes.c_uint32),
        ("mask", ctypes.c_uint32),
        ("block_poll", ctypes.c_uint32),
        ("cache", ctypes.POINTER(Block)),
        ("fresh", Block),
        ("access_pc", ctypes.c_uint64),
        ("low_registers", ctypes.c_int32 * 8),
        ("pc_register", ctypes.c_int32),
        ("emu_stop", ctypes.c_void_p),
        ("reg_read", ctypes.c_void_p),
        ("reg_write", ctypes.c_void_p),
        ("describe", DESCRIBE),
        ("rewritable", ctypes.c_uint64),
        ("rewritable_size", ctypes.c_uint64),
        ("code_written", ctypes.c_uint32),
        ("mem_read", ctypes.c_void_p),
        ("mem_write", ctypes.c_void_p),
        ("emu_start", ctypes.c_void_p),
        ("exc_registers", ctypes.c_int32 * 11),
        ("exc_return_handler", ctypes.c_uint32),
        ("exc_return_thread_msp", ctypes.c_uint32),
        ("exc_return_thread_psp", ctypes.c_uint32),
        ("xpsr_t", ctypes.c_uint32),
        ("xpsr_align", ctypes.c_uint32),
        ("control_spsel", ctypes.c_uint32),
        ("interrupt", ctypes.c_uint32),
        ("no_interrupt", ctypes.c_uint32),
        ("frame", ctypes.c_int64),
        ("vector", ctypes.c_uint64),
        ("pc", ctypes.c_uint64),
        ("status", ctypes.c_int32),
    )


class Held(ctypes.Structure):
    """A register value a peripheral holds until a cycle, and one read a peripheral offers from a cycle on (MCU-26),
    answered natively (``supi3_held`` of hook.c)."""

    _fields_ = (
        ("state", ctypes.POINTER(State)),
        ("slow", MMIO_READ),
        ("until", ctypes.c_uint64),
        ("offset", ctypes.c_uint32),
        ("value", ctypes.c_uint32),
        ("held", ctypes.c_uint32),
        ("poll", ctypes.c_uint32),
        ("after", ctypes.c_uint32),
        ("has_after", ctypes.c_uint32),
        ("once_from", ctypes.c_uint64),
        ("once_at", ctypes.c_uint64),
        ("once_offset", ctypes.c_uint32),
        ("once_value", ctypes.c_uint32),
        ("once", ctypes.c_uint32),
        ("taken", ctypes.c_uint32),
        ("once_then", ctypes.c_uint32),
    )


MMIO_WRITE: Final = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_uint64, ctypes.c_uint, ctypes.c_uint64,
                                     ctypes.c_void_p)  # fmt: skip
"""unicorn.h's uc_cb_mmio_write_t: a peripheral's write (``handle, offset, size, value, user data``)."""


BUS_DUE: Final = ctypes.CFUNCTYPE(None, ctypes.c_uint64, ctypes.c_uint64, ctypes.c_uint64)
"""MCU-84: hook.c's ``bus_due_fn``, :meth:`supi3.mcu.frames.NativeFrames._bus_due` (GPIOA's offset and value
written, the edge's core cycle: MCU-90)."""


class Prefix(ctypes.Structure):
    """The cost in cycles of a block's instructions before an access's PC (``supi3_prefix``: the memo of
    :meth:`supi3.mcu.core.CortexM.cycles_now`, MCU-51); address 0: an empty slot."""

    _fields_ = (("address", ctypes.c_uint64), ("pc", ctypes.c_uint64), ("cycles", ctypes.c_uint64))


class Frames(ctypes.Structure):
    """The per-frame fast path's state (``supi3_frames`` of hook.c, MCU-51; :mod:`supi3.mcu.frames` fills and reads
    it): the tables and thresholds it is given once, what Python mirrors into it after its writes of GPIOA and SPI1,
    and what the native frames changed since the last catch-up."""

    _fields_ = (
        ("state", ctypes.POINTER(State)),
        ("spi", ctypes.POINTER(Held)),
        ("prefixes", ctypes.POINTER(Prefix)),
        ("prefix_mask", ctypes.c_uint64),
        ("bus_due", BUS_DUE),
        ("least_t1", ctypes.c_int64),
        ("least_t2", ctypes.c_int64),
        ("least_t8", ctypes.c_int64),
        ("ss_pin", ctypes.c_uint64),
        ("cd_command", ctypes.c_uint64),
        ("cd_data", ctypes.c_uint64),
        ("phase_command", ctypes.c_uint64),
        ("phase_data", ctypes.c_uint64),
        ("sr_txe", ctypes.c_uint64),
        ("sr_bsy", ctypes.c_uint64),
        ("sr_rxne", ctypes.c_uint64),
        ("spi_dr", ctypes.c_uint64),
        ("spi_sr", ctypes.c_uint64),
        ("least_t6max", ctypes.c_int64),
        ("irq_pin", ctypes.c_uint64),
        ("cd_pin", ctypes.c_uint64),
        ("io_pin", ctypes.c_uint64),
        ("irq_address", ctypes.c_uint64),
        ("irq_clear", ctypes.c_uint64),
        ("io_bit", ctypes.c_uint64),
        ("exti_pr_offset", ctypes.c_uint64),
        ("gpio_ok", ctypes.c_uint64),
        ("gpio_mask", ctypes.c_uint64),
        ("gpio_pulled_up", ctypes.c_uint64),
        ("spi_ok", ctypes.c_uint64),
        ("period", ctypes.c_uint64),
        ("sr_modf", ctypes.c_uint64),
        ("exti_rise", ctypes.c_uint64),
        ("valid", ctypes.c_uint64),
        ("due", ctypes.c_uint64),
        ("latch", ctypes.c_uint64),
        ("latch_at", ctypes.c_uint64),
        ("gpio_levels", ctypes.c_uint64),
        ("io", ctypes.c_uint64),
        ("io_at", ctypes.c_uint64),
        ("pending", ctypes.c_uint64),
        ("odr", ctypes.c_uint64),
        ("synced", ctypes.c_uint64),
        ("phase", ctypes.c_uint64),
        ("command", ctypes.c_uint64),
        ("last_rx", ctypes.c_uint64),
        ("frame_open", ctypes.c_uint64),
        ("frame_fall", ctypes.c_uint64),
        ("frame_driven", ctypes.c_uint64),
        ("transfer", ctypes.c_uint64),
        ("transfer_seen", ctypes.c_uint64),
        ("transfer_start", ctypes.c_uint64),
        ("transfer_period", ctypes.c_uint64),
        ("ss_rise", ctypes.c_int64),
        ("cd_before", ctypes.c_uint64),
        ("irq_level", ctypes.c_uint64),
        ("written", ctypes.c_uint64),
        ("cleared", ctypes.c_uint64),
        ("cleared_at", ctypes.c_uint64),
        ("exti_pr", ctypes.c_uint64),
        ("dr_writes", ctypes.c_uint64),
        ("rx_last", ctypes.c_uint64),
        ("shift_received", ctypes.c_uint64),
        ("shift_start", ctypes.c_uint64),
        ("shift_end", ctypes.c_uint64),
        ("taken", ctypes.c_uint64),
        ("exception_exit", ctypes.c_uint64),
        ("primask_register", ctypes.c_uint64),
        ("chain_number", ctypes.c_uint64),
        ("tail_chain_cycles", ctypes.c_uint64),
        ("return_cycles", ctypes.c_uint64),
        ("idle_loop", ctypes.c_uint64),
        ("chain_leave", ctypes.c_uint64),
        ("chain_pending", ctypes.c_uint64),
        ("exti_imr", ctypes.c_uint64),
        ("irq_fell", ctypes.c_int64),
        ("chain_vector", ctypes.c_uint64),
        ("thread_deadline", ctypes.c_uint64),
        ("chains", ctypes.c_uint64),
        ("returned", ctypes.c_uint64),
        ("chain_latency", ctypes.c_int64),
        ("values", ctypes.c_uint8 * 16),
        ("written_values", ctypes.c_uint8 * 16),
        ("plain", ctypes.c_uint8 * 256),
        ("address", ctypes.c_uint8 * 256),
        ("rd", ctypes.c_uint8 * 256),
        ("wr", ctypes.c_uint8 * 256),
        ("reads_register", ctypes.c_uint8 * 16),
        ("writes_register", ctypes.c_uint8 * 16),
        ("fast_read", ctypes.c_uint8 * 16),
        ("fast_write", ctypes.c_uint8 * 16),
        ("write_mask", ctypes.c_uint8 * 16),
        ("alias", ctypes.c_int8 * 16),
    )


class Port(ctypes.Structure):
    """The user data of :func:`supi3_port_write` and :func:`supi3_port_read`, GPIOA's, SPI1's or EXTI's write and read
    in native code (``supi3_port``): the frames, Python's write, which peripheral (0: GPIOA, 1: SPI1, 2: EXTI), and the
    held register its other reads go to (:func:`supi3_held_read`)."""

    _fields_ = (("frames", ctypes.POINTER(Frames)), ("slow", MMIO_WRITE), ("port", ctypes.c_uint64),
                ("held", ctypes.POINTER(Held)))


class Memory(ctypes.Structure):
    """The user data of :func:`supi3_tlb_fill`, the virtual TLB's fill (``supi3_memory``, MCU-89): the state, flash
    (base, size: writable only for a store's fill, which notes it, MCU-28), the Execute Never regions (low, high)
    and unicorn's numbers: the fetch and store access types, the write, execute and all permissions, and the
    interrupt number a refused fetch notes in :attr:`State.interrupt`."""

    _fields_ = (("state", ctypes.POINTER(State)), ("flash", ctypes.c_uint64), ("flash_size", ctypes.c_uint64),
                ("never_low", ctypes.c_uint64 * 2), ("never_high", ctypes.c_uint64 * 2), ("fetch", ctypes.c_int32),
                ("store", ctypes.c_int32), ("prot_write", ctypes.c_int32), ("prot_exec", ctypes.c_int32),
                ("prot_all", ctypes.c_int32), ("prefetch_abort", ctypes.c_uint32))  # fmt: skip


_LOADED: list[ctypes.CDLL] = []
_LAYOUTS: Final[dict[str, type[ctypes.Structure]]] = {
    "supi3_block_layout": Block, "supi3_state_layout": State, "supi3_held_layout": Held,
    "supi3_prefix_layout": Prefix, "supi3_frames_layout": Frames, "supi3_port_layout": Port,
    "supi3_memory_layout": Memory}  # fmt: skip
"""hook.c's layout tables and their ctypes mirrors."""


def layout(structure: type[ctypes.Structure]) -> list[int]:
    """``structure``'s size and its fields' offsets in ctypes, in the order of hook.c's layout tables."""
    fields: tuple[tuple[str, object], ...] = structure._fields_  # type: ignore[assignment]
    return [ctypes.sizeof(structure), *(getattr(structure, name).offset for name, _ in fields)]


def native_layout(loaded: ctypes.CDLL, table: str) -> list[int]:
    """A layout table of the loaded library (``supi3_block_layout``, ...): the struct's size and its fields'
    offsets as the C compiler laid them out."""
    count = ctypes.c_uint32.in_dll(loaded, table).value
    return list((ctypes.c_uint32 * (count + 1)).in_dll(loaded, table))[1:]


def check_layout(loaded: ctypes.CDLL, name: str) -> None:
    """:class:`NativeHookError` unless each struct the library shares with Python has, field by field, the offsets
    and size of its ctypes mirror (a library of another source or ABI would write the wrong memory)."""
    for table, structure in _LAYOUTS.items():
        try:
            native = native_layout(loaded, table)
        except ValueError:
            raise NativeHookError(f"the native block hook {name} has no {table} (MCU-25): not built from "
                                  f"{SOURCE}") from None  # fmt: skip
        if native != layout(structure):
            raise NativeHookError(f"the native block hook {name} lays out {structure.__name__} as {native} (size, "
                                  f"offsets), ctypes as {layout(structure)} (MCU-25): built from another source or "
                                  "for another ABI")  # fmt: skip


def _compiler_version() -> str:
    try:
        return importlib.metadata.version("ziglang")
    except importlib.metadata.PackageNotFoundError:
        raise NativeHookError("ziglang is not installed: the emulated core's block hook is built with it (MCU-25; "
                              "pip install supi3[firmware])") from None  # fmt: skip


_ELF: Final[dict[int, tuple[str, int, str]]] = {1: ("IIIHHHHHH", 0x1C, "IIIIII"), 2: ("QQQIHHHHHH", 0x18, "IIQQQQ")}
"""ELF class (32, 64 bit): the header from e_entry on and its offset, a program header's fields up to p_filesz (ELF
specification, "ELF Header", "Program Header")."""


def check_whole(path: Path) -> None:
    """:class:`NativeHookError` if the ELF file ``path`` ends before its program's segments or its section header
    table do: a cut-short library (a full disk, a copy broken off) that the loader may crash on instead of failing
    (MCU-28). A file of another format is left to the loader."""
    data = path.read_bytes()
    if data[:4] != b"\x7fELF" or len(data) < 6 or data[4] not in _ELF or data[5] not in (1, 2):
        return
    header, at, program = _ELF[data[4]]
    order = "<" if data[5] == 1 else ">"
    try:
        _entry, phoff, shoff, _flags, _size, phentsize, phnum, shentsize, shnum, _names = \
            struct.unpack_from(order + header, data, at)  # fmt: skip
        ends = [phoff + phentsize * phnum, shoff + shentsize * shnum]
        for k in range(phnum):
            fields = struct.unpack_from(order + program, data, phoff + k * phentsize)
            offset, filesz = (fields[1], fields[4]) if data[4] == 1 else (fields[2], fields[5])
            ends.append(offset + filesz)
    except struct.error:
        ends = [len(data) + 1]
    if max(ends) > len(data):
        raise NativeHookError(f"the native block hook {path} is cut short: {len(data)} bytes, its ELF headers name "
                              f"{max(ends)} (MCU-28); delete it to build it again")  # fmt: skip


def cached_path() -> Path:
    """Where :func:`library` keeps the build: the native build cache, named by the hash of the source, the flags,
    the compiler's version and the machine; :class:`NativeHookError` if there is no compiler."""
    digest = hashlib.sha256()
    for part in (SOURCE.read_bytes(), _compiler_version().encode(), *(flag.encode() for flag in FLAGS),
                 platform.machine().encode(), sys.platform.encode()):  # fmt: skip
        digest.update(part + b"\0")
    # absolute: a bare file name (SUPI3_NATIVE_CACHE=.) would send the loader to the system's library path
    return default_cache_dir().absolute() / f"_supi3_mcu_hook_{digest.hexdigest()[:20]}.so"


def library() -> ctypes.CDLL:
    """The native hook library, built into the cache on first use (:func:`cached_path`), loaded once a process;
    :class:`NativeHookError` if it cannot be built or loaded."""
    if _LOADED:
        return _LOADED[0]
    target = cached_path()
    folder = target.parent
    if not target.is_file():
        try:
            folder.mkdir(parents=True, exist_ok=True)
            handle, work = tempfile.mkstemp(dir=folder, prefix=f"{target.stem}.", suffix=".tmp")
        except OSError as error:
            raise NativeHookError(f"the native block hook cannot be built into {folder} (MCU-25): {error}") from error
        os.close(handle)
        try:
            command = [sys.executable, "-m", "ziglang", "cc", *FLAGS, str(SOURCE), "-o", work]
            result = subprocess.run(command, capture_output=True, text=True, check=False)
            if result.returncode != 0:
                raise NativeHookError(f"the native block hook does not build (MCU-25): {' '.join(command)}\n"
                                      f"{result.stderr}")  # fmt: skip
            os.replace(work, target)
        except OSError as error:  # the place of the library taken by a folder, a full disk, ...
            raise NativeHookError(f"the native block hook cannot be put at {target} (MCU-25): {error}") from error
        finally:
            Path(work).unlink(missing_ok=True)
    check_whole(target)
    try:
        loaded = ctypes.CDLL(str(target))
    except OSError as error:
        raise NativeHookError(f"the native block hook {target} does not load (MCU-25): {error}; delete it to "
                              "build it again") from error  # fmt: skip
    check_layout(loaded, str(target))
    _LOADED.append(loaded)
    return loaded

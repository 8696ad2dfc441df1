"""Shared test configuration: seeded hypothesis, the ``rtl`` marker and its Verilator check, and the chip manual's
text for tables checked against it. Helpers that test modules import live in support.py (tests/README.md)."""

from __future__ import annotations

import functools
import os
import re
from pathlib import Path
from typing import TYPE_CHECKING

import pytest
from hypothesis import settings

from support import SDK_CHIP_TOP, VerilatorBuild, verilator_missing

if TYPE_CHECKING:
    from supi3.verif import Lockstep

settings.register_profile("supi3", derandomize=True, deadline=None, print_blob=True)
settings.load_profile("supi3")

MANUAL = Path(__file__).resolve().parents[2] / "shared" / "seeds" / "004_297a3ab37838a9fc.txt"

# OCR confusions in the text copy of the manual: Cyrillic look-alikes, l for I, typographic variants.
_OCR = str.maketrans({"Х": "X", "х": "x", "З": "3", "а": "a", "с": "c", "С": "C", "ı": "i", "μ": "µ"})


def manual_fields(line: str) -> list[str]:
    """A manual line split into its non-empty, normalised table cells."""
    return [re.sub(r"\s+", " ", cell).strip() for cell in line.translate(_OCR).split("\t") if cell.strip()]


@pytest.fixture(scope="session")
def manual_lines() -> list[list[str]]:
    """Every line of the chip manual (seed 004) as table cells; skips when the manual is not beside the repo."""
    if not MANUAL.exists():
        pytest.skip(f"chip manual not found at {MANUAL}")
    return [manual_fields(line) for line in MANUAL.read_text(encoding="utf-8").splitlines()]


@pytest.fixture(scope="session")
def manual_text() -> str:
    """The chip manual's text, normalised like :func:`manual_fields`."""
    if not MANUAL.exists():
        pytest.skip(f"chip manual not found at {MANUAL}")
    return MANUAL.read_text(encoding="utf-8").translate(_OCR)


# The rtl marker ------------------------------------------------------------------------------------------------------


@pytest.fixture(scope="session")
def verilator_build(tmp_path_factory: pytest.TempPathFactory) -> VerilatorBuild:
    """Build directories for Verilator models (``verilator_build("rtl_core")``), one per name for the whole run.

    Under xdist every worker gets the same directory for a name (under the run's base temporary directory, the parent
    of the worker's own, which xdist makes ``<basetemp>/popen-gwN``): the builds in it are keyed by the hash of their
    sources and made under a file lock (:func:`supi3.verif.rtl.build_slot`), so a design is compiled once per run
    and the other worker waits for it rather than compiling the same Verilog again beside it (tests/README.md,
    "Run time").

    Every test that needs Verilator requests it, directly or through its bench fixture: that marks the test ``rtl``
    (:func:`pytest_collection_modifyitems`), and skips it with the reason when Verilator is not installed.
    """
    reason = verilator_missing()
    if reason is not None:
        pytest.skip(reason)
    root = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER"):
        root = root.parent
    root = root / "verilator"

    def build_dir(name: str) -> Path:
        directory = root / name
        directory.mkdir(parents=True, exist_ok=True)
        return directory

    return build_dir


@pytest.fixture(scope="session")
def chip_build(verilator_build: VerilatorBuild) -> Path:
    """The Verilator build of the RTL chip (top ``supi3_chip``) for the SDK's cocotb tests (sim/sdk_rtl.py): one per
    run for tests/test_sdk_rtl.py and tests/test_sdk_hostile_rtl.py (shared by the xdist workers, keyed by the
    Verilog and the options like a :class:`~supi3.verif.Lockstep` build)."""
    from cocotb_tools.runner import get_runner

    from supi3.rtl.chip import verilog
    from supi3.verif.rtl import build_slot, ensure_toolchain

    ensure_toolchain("verilator")
    source_text = verilog()
    options = ["-Wno-fatal"]
    with build_slot(verilator_build("sdk_rtl"), "cocotb-chip", source_text, *options) as (build, ready):
        if not ready:
            source = build / f"{SDK_CHIP_TOP}.v"
            source.write_text(source_text, encoding="utf-8")
            get_runner("verilator").build(sources=[source], hdl_toplevel=SDK_CHIP_TOP, build_dir=build,
                                          build_args=options, timescale=("1ns", "1ps"),
                                          log_file=build / "build.log")  # fmt: skip
    return build


@pytest.fixture(scope="session")
def core_bench(verilator_build: VerilatorBuild) -> Lockstep:
    """The OPC core (``supi3.rtl.core``) against ``verif.straps.StrapPins``: one Verilator build per session, with the
    per-cycle path, for every test module that runs the core (the straps are ports)."""
    from supi3.rtl.core import Supi3Core  # Amaranth: only when a bench runs
    from supi3.verif import Lockstep
    from supi3.verif.straps import StrapPins

    lockstep = Lockstep(
        functools.partial(Supi3Core, "opc"), functools.partial(StrapPins, "opc"), build_dir=verilator_build("rtl_core")
    )
    lockstep.prepare()
    return lockstep


@pytest.fixture(scope="session")
def chip_bench(verilator_build: VerilatorBuild) -> Lockstep:
    """The OPC chip (``supi3.rtl.chip``) against ``verif.straps.ChipStrapPins``: one Verilator build per session
    (batch path) for every test module that runs the whole chip."""
    from supi3.rtl.chip import Supi3ChipRtl  # Amaranth: only when a bench runs
    from supi3.verif import Lockstep
    from supi3.verif.straps import ChipStrapPins

    lockstep = Lockstep(
        functools.partial(Supi3ChipRtl, "opc"),
        functools.partial(ChipStrapPins, "opc"),
        build_dir=verilator_build("rtl_chip"),
    )
    lockstep.prepare(simulators=())
    return lockstep


@pytest.hookimpl(tryfirst=True)  # before -m deselects by marker
def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Mark ``rtl`` every test that uses :func:`verilator_build`, and ``slow`` every ``rtl`` test (a Verilator
    build alone takes a minute); skip every ``rtl`` test when Verilator is missing, with the reason, rather than fail
    in its fixture. Then run the long modules first (:func:`_long_first`)."""
    reason = verilator_missing()
    for item in items:
        if "verilator_build" in getattr(item, "fixturenames", ()):
            item.add_marker(pytest.mark.rtl)
        if item.get_closest_marker("rtl") is not None:
            item.add_marker(pytest.mark.slow)
            if reason is not None:
                item.add_marker(pytest.mark.skip(reason=reason))
    _long_first(items)


def _long_first(items: list[pytest.Item]) -> None:
    """Order the modules with an ``rtl`` test first, then those with a ``slow`` test, then the rest, each group and
    each module in collection order (a stable sort by module: a module's tests stay together, so its fixtures are
    set up once).

    With ``--dist worksteal`` the run ends when the last long test does: started late, a Verilator lockstep or a
    pin-level sweep of tens of seconds keeps one worker busy while the other has nothing left to take. Started first,
    the long tests overlap the short ones, which the workers then share to the end (tests/README.md, "Run time").
    The order is the same in every worker, as xdist requires, and needs no timing file.
    """
    rank: dict[Path, int] = {}
    for item in items:
        long = 0 if item.get_closest_marker("rtl") else 1 if item.get_closest_marker("slow") else 2
        rank[item.path] = min(rank.get(item.path, 2), long)
    items.sort(key=lambda item: rank[item.path])

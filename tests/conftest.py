"""Shared test configuration: seeded hypothesis, the ``rtl`` marker and its Verilator check, and the chip manual's
text for tables checked against it. Helpers that test modules import live in support.py (tests/README.md)."""

from __future__ import annotations

import functools
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
    """Fresh, numbered build directories for Verilator models (``verilator_build("rtl_core")``).

    Every test that needs Verilator requests it, directly or through its bench fixture: that marks the test ``rtl``
    (:func:`pytest_collection_modifyitems`), and skips it with the reason when Verilator is not installed.
    """
    reason = verilator_missing()
    if reason is not None:
        pytest.skip(reason)
    return tmp_path_factory.mktemp


@pytest.fixture(scope="session")
def chip_build(verilator_build: VerilatorBuild) -> Path:
    """The Verilator build of the RTL chip (top ``supi3_chip``) for the SDK's cocotb tests (sim/sdk_rtl.py): one per
    session for tests/test_sdk_rtl.py and tests/test_sdk_hostile_rtl.py."""
    from cocotb_tools.runner import get_runner

    from supi3.rtl.chip import verilog
    from supi3.verif.rtl import ensure_toolchain

    ensure_toolchain("verilator")
    build = verilator_build("sdk_rtl")
    source = build / f"{SDK_CHIP_TOP}.v"
    source.write_text(verilog(), encoding="utf-8")
    get_runner("verilator").build(sources=[source], hdl_toplevel=SDK_CHIP_TOP, build_dir=build,
                                  build_args=["-Wno-fatal"], timescale=("1ns", "1ps"),
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
    in its fixture."""
    reason = verilator_missing()
    for item in items:
        if "verilator_build" in getattr(item, "fixturenames", ()):
            item.add_marker(pytest.mark.rtl)
        if item.get_closest_marker("rtl") is not None:
            item.add_marker(pytest.mark.slow)
            if reason is not None:
                item.add_marker(pytest.mark.skip(reason=reason))

"""Shared test configuration: seeded hypothesis, and the chip manual's text for tables checked against it."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from hypothesis import settings

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

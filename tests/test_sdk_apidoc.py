"""docs/sdk-api.md is generated from supi3.h and the Python driver, and is current; the two have the same calls."""

from __future__ import annotations

from pathlib import Path

import pytest

from supi3 import sdk
from supi3.sdk import apidoc

DOC = Path(__file__).resolve().parents[1] / "docs" / "sdk-api.md"


def test_the_checked_in_reference_is_current() -> None:
    assert DOC.read_text(encoding="utf-8") == apidoc.render(), "run: python -m supi3.sdk.apidoc docs/sdk-api.md"


def test_every_c_call_has_its_python_counterpart() -> None:
    header = (sdk.include_dir() / "supi3.h").read_text(encoding="utf-8")
    names = [name for name, _, _ in apidoc.c_calls(header)]
    assert "supi3_read" in names and "supi3_block_transfer" in names
    for name in names:
        python, _ = apidoc.python_counterpart(name)
        assert python


def test_a_c_call_without_counterpart_is_named() -> None:
    with pytest.raises(apidoc.ApiDocError, match="supi3_frobnicate has no Python counterpart"):
        apidoc.python_counterpart("supi3_frobnicate")

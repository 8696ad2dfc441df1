"""The generated C header compiles cleanly under C99 and C11, every macro equals the Python declaration, and every
macro that rests on a recorded decision names it (docs/assumptions)."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

from supi3.regmap import REGISTER_MAP, ByteLayout, RegisterMapError, to_c_header
from supi3.regmap.core import Assumption

C_DIR = Path(__file__).parent / "c"
ASSUMPTIONS_DIR = Path(__file__).parent.parent / "docs" / "assumptions"


def _layout_checks(layout: ByteLayout) -> list[tuple[str, int]]:
    checks = []
    for f in layout.fields:
        checks += [(f"SUPI3_{layout.name}_{f.name}_POS", f.lsb), (f"SUPI3_{layout.name}_{f.name}_MSK", f.mask)]
        checks += [(f"SUPI3_{layout.name}_{f.name}_{v.name}", v.value << f.lsb) for v in f.values]
    return checks + [(f"SUPI3_{layout.name}_{c.name}", c.value) for c in layout.constants]


def expected_checks() -> list[tuple[str, int]]:
    """Every (macro, value) the header must define, straight from the Python declaration."""
    checks = [("SUPI3_ADDR_COUNT", len(REGISTER_MAP.addresses))]
    for layout in (REGISTER_MAP.command_byte, REGISTER_MAP.init_byte):
        checks += _layout_checks(layout)
    for register in REGISTER_MAP.registers:
        checks += [(f"SUPI3_{register.name}_ADDR", register.address), (f"SUPI3_{register.name}_RESET", 0)]
        checks += _layout_checks(register)
    checks += [
        (f"SUPI3_{p.register.name}_CLEAR_ON_READ_MSK", p.clear_on_read_mask)
        for p in REGISTER_MAP.ports
        if p.register is not None and p.clear_on_read_mask
    ]
    return checks


def test_every_macro_is_defined_once() -> None:
    defined = re.findall(r"^#define\s+(SUPI3_\w+)", to_c_header(), flags=re.MULTILINE)
    assert len(defined) == len(set(defined))
    assert {name for name, _ in expected_checks()} <= set(defined)


def test_header_is_ascii() -> None:
    assert to_c_header().isascii()


@pytest.mark.parametrize("std", ["c99", "c11"])
def test_header_compiles_and_matches_declaration(tmp_path: Path, std: str) -> None:
    gcc = shutil.which("gcc")
    if gcc is None:
        pytest.skip("gcc not found: the C header compile test needs it")
    (tmp_path / "supi3_regs.h").write_text(to_c_header(), encoding="ascii")
    (tmp_path / "supi3_expected.h").write_text(
        "".join(f"    SUPI3_CHECK({name}, {value}u);\n" for name, value in expected_checks()), encoding="ascii"
    )
    result = subprocess.run(
        [
            gcc,
            f"-std={std}",
            "-Wall",
            "-Wextra",
            "-Werror",
            "-pedantic",
            "-fsyntax-only",
            "-I",
            str(tmp_path),
            str(C_DIR / "test_regs.c"),
        ],
        capture_output=True,
        text=True,
        check=False,
    )
    assert result.returncode == 0, result.stderr


def test_a_wrong_expectation_fails_the_build(tmp_path: Path) -> None:
    gcc = shutil.which("gcc")
    if gcc is None:
        pytest.skip("gcc not found: the C header compile test needs it")
    (tmp_path / "supi3_regs.h").write_text(to_c_header(), encoding="ascii")
    (tmp_path / "supi3_expected.h").write_text("    SUPI3_CHECK(SUPI3_SET_ADDR, 12u);\n", encoding="ascii")
    for std in ("c99", "c11"):
        result = subprocess.run(
            [gcc, f"-std={std}", "-fsyntax-only", "-I", str(tmp_path), str(C_DIR / "test_regs.c")],
            capture_output=True,
            text=True,
            check=False,
        )
        assert result.returncode != 0, std


def _recorded_ids() -> set[str]:
    """The IDs of docs/assumptions/*.md: the ``## RM-7 ...`` headings."""
    return {
        found
        for path in ASSUMPTIONS_DIR.glob("*.md")
        for found in re.findall(r"^##\s+([A-Z]+-[0-9]+)\b", path.read_text(encoding="utf-8"), flags=re.MULTILINE)
    }


def _macro_lines() -> dict[str, str]:
    """Every macro of the header by name (function-like ones with their parameter list), its whole line."""
    pattern = r"^#define\s+(SUPI3_\w+(?:\(\w+\))?).*$"
    return {m.group(1): m.group(0) for m in re.finditer(pattern, to_c_header(), re.MULTILINE)}


NAMED = re.compile(r"/\* assumptions? ([A-Z]+-[0-9]+(?:, [A-Z]+-[0-9]+)*) \*/")
LEGEND = re.compile(r"^ \*   ([A-Z]+-[0-9]+): \S", re.MULTILINE)


def _named_ids() -> set[str]:
    """Every assumption ID the header's macros name in their comments."""
    return {one for group in NAMED.findall(to_c_header()) for one in group.split(", ")}


def test_every_assumption_the_header_names_is_recorded() -> None:
    named = _named_ids()
    assert {"RM-1", "RM-4", "RM-7", "RM-8"} <= named
    assert named <= _recorded_ids(), named - _recorded_ids()


def test_macros_name_the_assumptions_they_rest_on() -> None:
    lines = _macro_lines()
    for layout in (REGISTER_MAP.command_byte, REGISTER_MAP.init_byte, *REGISTER_MAP.registers):
        for f in layout.fields:
            for suffix in ("POS", "MSK", *(v.name for v in f.values)):
                line = lines[f"SUPI3_{layout.name}_{f.name}_{suffix}"]
                assert ("assumption" in line) == bool(f.assumptions), line
                assert all(a.id in line for a in f.assumptions), line
    assert lines["SUPI3_IRQ_EVT_IO_ACCESS_MSK"].endswith("/* assumptions RM-7, RM-8 */")
    assert lines["SUPI3_IRQ_EVT_CLEAR_ON_READ_MSK"].endswith("/* assumptions RM-7, RM-8 */")
    assert lines["SUPI3_CMD_BLOCK_TRANSFER"].endswith("/* assumptions RM-1, RM-2 */")
    assert lines["SUPI3_CMD_READ(addr)"].endswith("/* assumption RM-1 */")
    assert lines["SUPI3_SET_EXTREG_MSK"].endswith("/* assumption RM-4 */")
    assert "assumption" not in lines["SUPI3_SET_ADDR"] + lines["SUPI3_IN1_DATA_MSK"] + lines["SUPI3_ADDR_COUNT"]


def test_the_opening_comment_lists_each_named_assumption_once_with_its_summary() -> None:
    opening = to_c_header().split("*/", 1)[0]
    listed = LEGEND.findall(opening)
    assert sorted(listed) == sorted(set(listed)) and set(listed) == _named_ids()


@pytest.mark.parametrize("bad", ["RM7", "rm-7", "RM-", ""])
def test_an_assumption_needs_an_id_like_rm_7(bad: str) -> None:
    with pytest.raises(RegisterMapError, match="assumption id must look like 'RM-7'"):
        Assumption(bad, "summary")
    with pytest.raises(RegisterMapError):
        Assumption("RM-7", "")

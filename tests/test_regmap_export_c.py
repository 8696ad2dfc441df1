"""The generated C header compiles cleanly under C99 and C11, and every macro equals the Python declaration."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

from supi3.regmap import REGISTER_MAP, ByteLayout, to_c_header

C_DIR = Path(__file__).parent / "c"


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

"""The portable C99 driver (src/supi3/sdk/c) builds warning-free and passes its unit tests against a fake chip in C."""

from __future__ import annotations

import shlex
import shutil
import subprocess
import tomllib
from pathlib import Path

import pytest

from supi3 import sdk
from supi3.cli import main

ROOT = Path(__file__).parent.parent
SDK_C = ROOT / "src" / "supi3" / "sdk" / "c"
TEST_SOURCE = Path(__file__).parent / "c" / "test_driver.c"
STRICT = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic"]
SANITIZE = ["-fsanitize=address,undefined", "-fno-omit-frame-pointer", "-fno-sanitize-recover=all"]


def _gcc() -> str:
    gcc = shutil.which("gcc")
    if gcc is None:
        pytest.skip("gcc not found: the C driver tests need it")
    return gcc


def _build_and_run(tmp_path: Path, extra: list[str]) -> str:
    exe = tmp_path / "test_driver"
    build = subprocess.run(
        [
            _gcc(),
            *STRICT,
            *extra,
            "-I",
            str(SDK_C / "include"),
            str(SDK_C / "src" / "supi3.c"),
            str(TEST_SOURCE),
            "-o",
            str(exe),
        ],
        capture_output=True,
        text=True,
        check=False,
    )
    assert build.returncode == 0, build.stderr
    run = subprocess.run([str(exe)], capture_output=True, text=True, check=False)
    assert run.returncode == 0, run.stdout + run.stderr
    return run.stdout


def test_driver_unit_tests_pass(tmp_path: Path) -> None:
    out = _build_and_run(tmp_path, [])
    assert out.strip().endswith(" passed, 0 failed"), out
    assert not out.startswith("0 passed")


def test_driver_unit_tests_pass_under_sanitizers(tmp_path: Path) -> None:
    out = _build_and_run(tmp_path, SANITIZE)
    assert out.strip().endswith(" passed, 0 failed"), out


def test_driver_compiles_as_c11_with_conversion_warnings() -> None:
    gcc = _gcc()
    result = subprocess.run(
        [
            gcc,
            "-std=c11",
            "-Wall",
            "-Wextra",
            "-Werror",
            "-pedantic",
            "-Wconversion",
            "-fsyntax-only",
            "-I",
            str(SDK_C / "include"),
            str(SDK_C / "src" / "supi3.c"),
        ],
        capture_output=True,
        text=True,
        check=False,
    )
    assert result.returncode == 0, result.stderr


def test_cmake_builds_library_and_test(tmp_path: Path) -> None:
    cmake = shutil.which("cmake")
    if cmake is None:
        pytest.skip("cmake not found: the CMake build test needs it")
    _gcc()
    build = tmp_path / "build"
    configure = subprocess.run(
        [cmake, "-S", str(SDK_C), "-B", str(build), f"-DSUPI3_TEST_SOURCE={TEST_SOURCE}"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert configure.returncode == 0, configure.stdout + configure.stderr
    compiled = subprocess.run([cmake, "--build", str(build)], capture_output=True, text=True, check=False)
    assert compiled.returncode == 0, compiled.stdout + compiled.stderr
    assert list(build.glob("**/libsupi3.a"))
    run = subprocess.run([str(build / "supi3_test_driver")], capture_output=True, text=True, check=False)
    assert run.returncode == 0, run.stdout + run.stderr
    assert run.stdout.strip().endswith(" passed, 0 failed")


def test_package_paths_point_at_the_shipped_sources() -> None:
    assert SDK_C.resolve() == sdk.SDK_DIR
    assert (sdk.include_dir() / "supi3.h").is_file()
    assert (sdk.include_dir() / "supi3_regs.h").is_file()
    assert [p.name for p in sdk.sources()] == ["supi3.c"]
    assert (sdk.SDK_DIR / "CMakeLists.txt").is_file()


def test_cli_flags_build_the_driver(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    gcc = _gcc()
    printed = []
    for option in ("--cflags", "--sources"):
        assert main(["sdk", option]) == 0
        printed += shlex.split(capsys.readouterr().out)
    assert main(["sdk", "--includes"]) == 0
    assert shlex.split(capsys.readouterr().out) == [f"-I{sdk.include_dir()}"]
    assert main(["sdk", "--dir"]) == 0
    assert capsys.readouterr().out.strip() == str(sdk.SDK_DIR)
    result = subprocess.run(
        [gcc, *printed, "-Werror", "-c", "-o", str(tmp_path / "supi3.o")], capture_output=True, text=True, check=False
    )
    assert result.returncode == 0, result.stderr


def test_package_data_lists_the_sdk_files() -> None:
    data = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    patterns = data["tool"]["setuptools"]["package-data"]["supi3"]
    shipped = {p for pattern in patterns for p in (ROOT / "src" / "supi3").glob(pattern)}
    assert {p for p in SDK_C.rglob("*") if p.is_file()} <= shipped


STUBS = """#include "supi3.h"
static int board_xfer(void *u, uint8_t tx, uint8_t *rx, int s_r) { (void)u; (void)tx; (void)s_r; *rx = 0u; return 0; }
static void board_delay_us(void *u, uint32_t us) { (void)u; (void)us; }
static int board_irq(void *u, int *level) { (void)u; *level = 1; return 0; }
static int board_cd(void *u, int *level) { (void)u; *level = 0; return 0; }
static int board_sas(void *u, int level) { (void)u; (void)level; return 0; }
static int board_io(void *u, int *level) { (void)u; *level = 0; return 0; }
static int hspi1;
int example(void);
int example(void)
{
"""


def _compile_guide_example(tmp_path: Path, heading: str, prelude: str) -> None:
    """The first C block under ``heading`` in docs/sdk.md, inside a function after the stubs, compiles strictly."""
    gcc = _gcc()
    guide = (ROOT / "docs" / "sdk.md").read_text(encoding="utf-8")
    section = guide.split(f"## {heading}", 1)[1]
    snippet = section.split("```c\n", 1)[1].split("```", 1)[0]
    source = tmp_path / "example.c"
    source.write_text(STUBS + prelude + snippet + "    return err;\n}\n", encoding="ascii")
    result = subprocess.run(
        [gcc, *STRICT, "-fsyntax-only", f"-I{sdk.include_dir()}", str(source)],
        capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr


def test_start_up_example_of_the_guide_compiles(tmp_path: Path) -> None:
    _compile_guide_example(tmp_path, "Start-up and recovery", "")


def test_polling_example_of_the_guide_compiles(tmp_path: Path) -> None:
    _compile_guide_example(tmp_path, "Synchronizing with the bus: interrupt or polling", "    static supi3_t chip;\n")


def test_header_is_usable_from_cxx(tmp_path: Path) -> None:
    gxx = shutil.which("g++")
    if gxx is None:
        pytest.skip("g++ not found: the C++ include test needs it")
    source = tmp_path / "user.cpp"
    source.write_text(
        '#include "supi3.h"\nint f();\nint f() { return supi3_init(nullptr, nullptr); }\n', encoding="ascii"
    )
    result = subprocess.run(
        [gxx, "-std=c++11", "-Wall", "-Wextra", "-Werror", "-pedantic", "-fsyntax-only", f"-I{sdk.include_dir()}",
         str(source)],
        capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr

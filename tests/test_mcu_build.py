"""supi3.mcu.build's failure report: a firmware that does not compile gives the compiler's messages as it wrote them,
line by line, in :class:`BuildError` and on ``supi3 firmware build``'s stderr, before the one error line (status 2)."""

from __future__ import annotations

import pickle
from pathlib import Path

import pytest

from supi3.cli import main
from supi3.mcu import build as mcu_build
from supi3.mcu.build import BuildError, build

pytestmark = pytest.mark.skipif(mcu_build.toolchain_missing() is not None, reason=str(mcu_build.toolchain_missing()))

BROKEN = "int broken(void)\n{\n    return undeclared;\n}\n"
"""A C syntax error on line 3."""


def test_a_compile_error_keeps_the_compilers_lines(tmp_path: Path) -> None:
    """The summary is one line, the output the compiler's own lines (file:line:column, the source line, the caret);
    the error survives pickling (a worker process)."""
    (tmp_path / "broken.c").write_text(BROKEN)
    with pytest.raises(BuildError) as caught:
        build(tmp_path / "broken.c", tmp_path / "x.elf", port=False)
    error = caught.value
    assert error.summary == "the firmware does not build for cortex_m3"
    assert "broken.c:3:12: error: use of undeclared identifier 'undeclared'\n" in error.output
    assert "\\n" not in error.output and str(error) == f"{error.summary}:\n{error.output}"
    assert (pickle.loads(pickle.dumps(error)).summary, pickle.loads(pickle.dumps(error)).output) == (
        error.summary, error.output)  # fmt: skip
    assert not (tmp_path / "x.elf").exists()


def test_firmware_build_prints_the_compilers_messages_with_line_breaks(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """No literal backslash-n: each of the compiler's lines on a line of stderr, then ``supi3: error: ...`` once."""
    (tmp_path / "broken.c").write_text(BROKEN)
    code = main(["firmware", "build", str(tmp_path / "broken.c"), "-o", str(tmp_path / "x.elf")])
    out, err = capsys.readouterr()
    assert (code, out) == (2, "")
    lines = err.splitlines()
    assert "\\n" not in err and len(lines) > 3 and "Traceback" not in err
    assert any(line.endswith("broken.c:3:12: error: use of undeclared identifier 'undeclared'") for line in lines)
    assert lines[-1] == "supi3: error: the firmware does not build for cortex_m3 (the compiler's messages above)"
    assert sum(line.startswith("supi3: error:") for line in lines) == 1

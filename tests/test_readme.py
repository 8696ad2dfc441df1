"""The README's Python example runs as written."""

from __future__ import annotations

import re
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def test_readme_python_examples_run() -> None:
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(encoding="utf-8"), flags=re.DOTALL)
    assert blocks
    for block in blocks:
        exec(compile(block, str(README), "exec"), {})


def test_tests_readme_names_every_test_file() -> None:
    """tests/README.md's table maps every test file to the source it tests."""
    tests = Path(__file__).resolve().parent
    listed = (tests / "README.md").read_text(encoding="utf-8")
    assert [p.name for p in sorted(tests.glob("test_*.py")) if f"`{p.name}`" not in listed] == []


def test_ci_runs_the_readmes_test_command() -> None:
    """.ci/run calls the quick start's second command (install everything the tests need, run the whole suite)."""
    commands = re.findall(r"^    (python3 -m venv .*)$", README.read_text(encoding="utf-8"), flags=re.MULTILINE)
    assert len(commands) == 2, commands
    ci = (README.parent / ".ci" / "run").read_text(encoding="utf-8")
    assert commands[1] in ci.splitlines()

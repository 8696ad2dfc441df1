"""The portable C99 firmware SDK shipped inside the package (docs/sdk.md): paths and compiler flags.

``supi3 sdk --includes`` prints ``-I<dir>`` for ``supi3.h`` and the generated ``supi3_regs.h``, ``--sources`` the
driver's C files, ``--cflags`` the flags the project builds it with, ``--dir`` the SDK folder (with its
``CMakeLists.txt``), like ``pybind11 --includes``.
"""

from __future__ import annotations

import shlex
from pathlib import Path
from typing import Final

__all__ = ["CFLAGS", "SDK_DIR", "cflags", "include_dir", "includes", "sources"]

SDK_DIR: Final[Path] = Path(__file__).resolve().parent / "c"
"""The C SDK: ``include/`` (``supi3.h``, ``supi3_regs.h``), ``src/`` (``supi3.c``), ``CMakeLists.txt``."""

CFLAGS: Final[tuple[str, ...]] = ("-std=c99", "-Wall", "-Wextra", "-pedantic")
"""The language and warning flags the driver is tested with (tests/test_sdk_c.py adds ``-Werror``)."""


def include_dir() -> Path:
    """The folder to put on the include path."""
    return SDK_DIR / "include"


def sources() -> tuple[Path, ...]:
    """The driver's C sources, sorted."""
    return tuple(sorted((SDK_DIR / "src").glob("*.c")))


def includes() -> str:
    """``-I<include dir>``, quoted for a POSIX shell if the path needs it."""
    return shlex.quote(f"-I{include_dir()}")


def cflags() -> str:
    """The language and warning flags followed by :func:`includes`."""
    return " ".join((*CFLAGS, includes()))

"""Argument checks for every public entry: one wording ("X must be ..., not ...") and one error class.

A public constructor or method calls these on what it is given before it changes any state, so a wrong type or
value is reported where it was passed, by name, never as a bare ``TypeError`` deep inside or as a silent cast.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Collection, Mapping
from typing import TypeVar

import numpy as np
import numpy.typing as npt

from supi3.errors import ArgumentError

T = TypeVar("T")

_SHOWN = 60
"""Longest ``repr`` an error message quotes; longer values are cut with an ellipsis."""


def describe(value: object) -> str:
    """The value as an error message quotes it: its ``repr`` (cut to 60 characters) and, unless obvious, its type."""
    if isinstance(value, int) and value.bit_length() > 4 * _SHOWN:
        # repr() of an integer past 4,300 digits raises; the size is what matters in a message anyway.
        text = f"{'-' if value < 0 else ''}<{value.bit_length()}-bit integer>"
    else:
        text = repr(value)
    if len(text) > _SHOWN:
        text = text[: _SHOWN - 3] + "..."
    if isinstance(value, (bool, int, float, str, bytes)) and type(value) in (bool, int, float, str, bytes):
        return text
    return f"{text} ({type(value).__name__})"


def fail(name: str, wanted: str, value: object, limit: str = "") -> ArgumentError:
    """The error for ``name`` given ``value`` where ``wanted`` was expected; ``limit`` names the manual's rule."""
    rule = f" ({limit})" if limit else ""
    return ArgumentError(name, value, f"{name} must be {wanted}{rule}, not {describe(value)}")


def _range_text(lo: int | float | None, hi: int | float | None) -> str:
    if lo is not None and hi is not None:
        return f" from {lo} to {hi}"
    if lo is not None:
        return f" >= {lo}"
    if hi is not None:
        return f" <= {hi}"
    return ""


def check_int(name: str, value: object, lo: int | None = None, hi: int | None = None, limit: str = "") -> int:
    """``value`` as an ``int`` in ``[lo, hi]``: Python and numpy integers pass; ``bool``, floats and strings do not."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise fail(name, "an integer" + _range_text(lo, hi), value, limit)
    number = int(value)
    if (lo is not None and number < lo) or (hi is not None and number > hi):
        raise fail(name, "an integer" + _range_text(lo, hi), value, limit)
    return number


def check_bits(name: str, value: object, width: int, limit: str = "") -> int:
    """``value`` as a ``width``-bit unsigned integer (a pin or a register), 0 to ``2**width - 1``."""
    return check_int(name, value, 0, (1 << width) - 1, limit or f"{width} bit{'s' if width != 1 else ''}")


def check_real(
    name: str,
    value: object,
    lo: float | None = None,
    hi: float | None = None,
    *,
    finite: bool = True,
    limit: str = "",
) -> float:
    """``value`` as a ``float`` in ``[lo, hi]``; NaN never passes, infinity only with ``finite=False``."""
    wanted = ("a finite number" if finite else "a number") + _range_text(lo, hi)
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise fail(name, wanted, value, limit)
    number = float(value)
    if math.isnan(number) or (finite and math.isinf(number)):
        raise fail(name, wanted, value, limit)
    if (lo is not None and number < lo) or (hi is not None and number > hi):
        raise fail(name, wanted, value, limit)
    return number


def check_bytes(name: str, value: object, length: int | None = None, limit: str = "") -> bytes:
    """``value`` (``bytes``, ``bytearray`` or ``memoryview``) as ``bytes``, of exactly ``length`` bytes if given."""
    wanted = "bytes" if length is None else f"{length} byte{'s' if length != 1 else ''}"
    if not isinstance(value, (bytes, bytearray, memoryview)):
        raise fail(name, wanted, value, limit)
    data = bytes(value)
    if length is not None and len(data) != length:
        raise fail(name, wanted, value, limit)
    return data


def check_instance(name: str, value: object, kind: type[T], wanted: str = "", limit: str = "") -> T:
    """``value`` if it is a ``kind``; ``wanted`` words what is expected (default: the class name)."""
    if not isinstance(value, kind):
        raise fail(name, wanted or f"a {kind.__name__}", value, limit)
    return value


def check_choice(name: str, value: T, choices: Collection[T], limit: str = "") -> T:
    """``value`` if it is one of ``choices`` (compared with ``==``, so ``1`` is not ``True`` here)."""
    for choice in choices:
        if type(choice) is type(value) and choice == value:
            return value
    shown = ", ".join(repr(c) for c in choices)
    raise fail(name, f"one of {shown}", value, limit)


def check_bool(name: str, value: object) -> bool:
    """``value`` if it is a ``bool`` (numpy's included); ``0``, ``1`` and ``None`` do not pass."""
    if isinstance(value, bool | np.bool_):
        return bool(value)
    raise fail(name, "True or False", value)


def check_trace(name: str, value: object, width: int) -> npt.NDArray[np.integer]:
    """``value`` (a sequence or array) as a 1-D integer array of ``width``-bit values, checked in one pass.

    Integer dtypes only (no bool, float, str or object arrays: a level is never cast); the range is checked with a
    single ``max`` over the data seen as unsigned, so negative values fail too. An empty sequence passes.
    """
    mask = (1 << width) - 1
    wanted = f"a 1-D sequence of integers from 0 to {mask} ({width} bit{'s' if width != 1 else ''})"
    if isinstance(value, (str, bytes, bytearray)) or not hasattr(value, "__len__"):
        raise fail(name, wanted, value)
    try:
        array = np.asarray(value)
    except (TypeError, ValueError) as error:
        raise fail(name, wanted, value) from error
    if array.ndim != 1:
        raise fail(name, wanted, value)
    if not array.size:
        return np.zeros(0, dtype=np.int64)
    if array.dtype.kind not in "iu":
        raise fail(name, wanted, value)
    unsigned = array.view(np.dtype(f"u{array.dtype.itemsize}")) if array.dtype.kind == "i" else array
    if int(unsigned.max()) > mask:
        index = int(np.argmax(unsigned > mask))
        raise fail(f"{name}[{index}]", f"an integer from 0 to {mask} ({width} bit{'s' if width != 1 else ''})",
                   array[index].item())
    return array


def check_inputs(inputs: object, widths: Mapping[str, int]) -> Mapping[str, int]:
    """A pin block's inputs: a mapping of exactly the pins of ``widths`` (name -> width) to integers within their
    widths; else the named error (a block's ``step`` calls it before it changes any state)."""
    if not isinstance(inputs, Mapping) or inputs.keys() != widths.keys():
        raise ArgumentError("inputs", inputs, f"inputs must be a mapping of exactly the pins {', '.join(widths)} "
                                              f"to integers, not {inputs!r:.80}")
    for name, width in widths.items():
        value = inputs[name]
        if type(value) is not int or value < 0 or value >> width:  # the cheap test first
            check_bits(f"pin {name!r}", value, width)
    return inputs

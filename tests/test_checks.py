"""The shared argument checks (supi3.checks): what passes, what fails, and how the failure reads."""

from __future__ import annotations

import math
import pickle

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from supi3.checks import check_bits, check_bool, check_bytes, check_choice, check_instance, check_int, check_real
from supi3.errors import ArgumentError, Supi3Error


@pytest.mark.parametrize("value", [True, 1.0, 1.5, "1", None, b"\x01", math.nan])
def test_int_refuses_non_integers(value: object) -> None:
    with pytest.raises(ArgumentError, match=r"^n must be an integer from 0 to 9, not "):
        check_int("n", value, 0, 9)


def test_int_accepts_numpy_integers_and_returns_int() -> None:
    value = check_int("n", np.uint8(255), 0, 255)
    assert value == 255 and type(value) is int


@given(st.integers(), st.integers(0, 8))
def test_bits_range(value: int, width: int) -> None:
    if 0 <= value < 1 << width:
        assert check_bits("pin", value, width) == value
    else:
        with pytest.raises(ArgumentError, match=f"{width} bit"):
            check_bits("pin", value, width)


@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf, -1.0, True, "1", None])
def test_real_refuses(value: object) -> None:
    with pytest.raises(ArgumentError, match=r"^seconds must be a finite number >= 0"):
        check_real("seconds", value, 0)


def test_real_infinity_only_when_allowed() -> None:
    assert check_real("t", math.inf, 0, finite=False) == math.inf
    with pytest.raises(ArgumentError):
        check_real("t", math.nan, finite=False)


def test_bytes_type_and_length() -> None:
    assert check_bytes("data", bytearray(b"ab"), 2) == b"ab"
    for bad in (None, "ab", [1, 2], b"abc"):
        with pytest.raises(ArgumentError, match=r"^data must be 2 bytes"):
            check_bytes("data", bad, 2)


def test_choice_is_type_strict() -> None:
    assert check_choice("x", 1, (1, 2)) == 1
    with pytest.raises(ArgumentError, match=r"one of 1, 2"):
        check_choice("x", True, (1, 2))


def test_instance_bool_and_error_classes() -> None:
    assert check_instance("s", "a", str) == "a"
    assert check_bool("b", np.bool_(True)) is True
    with pytest.raises(ArgumentError, match="True or False, not 1"):
        check_bool("b", 1)
    with pytest.raises(ArgumentError) as caught:
        check_instance("s", 1, str, limit="rule 7")
    # One class that old callers catching TypeError, ValueError or Supi3Error all still catch.
    assert isinstance(caught.value, TypeError | ValueError | Supi3Error)
    assert caught.value.name == "s" and caught.value.value == 1 and "(rule 7)" in str(caught.value)


def test_long_values_are_cut() -> None:
    with pytest.raises(ArgumentError) as caught:
        check_int("n", "x" * 500)
    assert len(str(caught.value)) < 120


def test_huge_integers_are_described_by_size() -> None:
    with pytest.raises(ArgumentError, match=r"not <13288-bit integer>"):
        check_int("n", 10**4000, 0, 9)
    with pytest.raises(ArgumentError, match=r"not -<"):
        check_int("n", -(10**5000), 0, 9)


def test_argument_error_pickles() -> None:
    with pytest.raises(ArgumentError) as caught:
        check_int("n", 1.5, 0, 9)
    copy = pickle.loads(pickle.dumps(caught.value))
    assert (type(copy), copy.name, copy.value, str(copy)) == (ArgumentError, "n", 1.5, str(caught.value))

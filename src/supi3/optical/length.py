"""Optical path length: the length timer, the LENGTH and MEDIUM fields of reads 8 and 9, metres both ways.

Manual 1.6.1 (formula L = n / (f t), Table 1-5) and 3.4.12 (Figure 3-16: length, medium, enable). The manual does not
agree with itself here; the reading this module implements is OPT-1 of ``docs/assumptions/optical.md``:

* The timer counts the round trip (first status telegram out to the positive response back) at ``f`` = 16 times the
  bit rate (F10: 8 MHz at 500 kbit/s, 32 MHz at 2 Mbit/s). ``L = n / (f t)`` is the *forward and return* fibre, as
  1.6.1 says, so the one-way path is ``L / 2``: 12.5 m per count at 500 kbit/s, 3.125 m at 2 Mbit/s. Table 1-5's
  resolution column (24 m, 6 m) is ``L`` per count (25 m, 6.25 m).
* LENGTH holds the one-way length in one unit at both bit rates, :data:`POLYMER_UNIT_M` = 6.25 m (400 m / 64), so
  Table 1-5's value range holds at both rates: 0..62 is 0 m to 387.5 m, 63 is "400 m to 20 km". At 500 kbit/s a
  count is two units, so codes step by 2 (12.5 m, the "12 m" polymer resolution of 3.4.12 and the 12.5 m steps of
  Figure 1-10's lengths); at 2 Mbit/s a count is half a unit.
* MEDIUM = 1 (glass) reports in units of :data:`GLASS_UNIT_M` = 200 m (3.4.12: "length resolution 200 m"); 63 is then
  12.6 km and more. The medium is not measured: the fibre link's transceiver tells it (OPT-3).
"""

from __future__ import annotations

import math
from enum import IntEnum
from typing import Final

from supi3.checks import check_instance, check_int, check_real, fail
from supi3.tables import BIT_RATES, LENGTH_TIMER_CLOCKS_PER_BIT, LIGHT_RUNTIME_S_PER_M

__all__ = [
    "GLASS_UNIT_M",
    "LENGTH_MAX_CODE",
    "MAX_PATH_M",
    "POLYMER_UNIT_M",
    "Medium",
    "check_bit_rate",
    "code_range_m",
    "length_code",
    "length_m",
    "timer_code",
    "timer_count",
    "unit_m",
]

LENGTH_MAX_CODE: Final = 63
"""LENGTH is 6 bits (RM-5); 63 means "longer than the range" (Table 1-5: 400 m to 20 km)."""
POLYMER_UNIT_M: Final = 6.25
"""One-way metres per LENGTH code with MEDIUM = 0: 400 m / 64, so 0..62 cover Table 1-5's 0 m to 400 m (OPT-1)."""
GLASS_UNIT_M: Final = 200.0
"""One-way metres per LENGTH code with MEDIUM = 1 (3.4.12: glass fibre, length resolution 200 m; OPT-1)."""
MAX_PATH_M: Final = 20_000.0
"""The longest path Table 1-5 names (20 km)."""


class Medium(IntEnum):
    """The MEDIUM bit of reads 8 and 9 (3.4.12, Figure 3-16)."""

    POLYMER = 0
    """Polymer fibre; hard-clad silica (HCS) uses the same 660 nm transceivers and reports 0 as well (OPT-3)."""
    GLASS = 1
    """Glass fibre."""


def _medium(medium: object) -> Medium:
    return check_instance("medium", medium, Medium)


def check_bit_rate(bit_rate: object) -> int:
    """``bit_rate`` if it is one of Table 1-7's bit rates, else a named error."""
    rate = check_int("bit_rate", bit_rate)
    if rate not in BIT_RATES:
        raise fail("bit_rate", f"one of Table 1-7's {BIT_RATES}", bit_rate)
    return rate


def unit_m(medium: Medium) -> float:
    """One-way metres per LENGTH code for a medium (OPT-1)."""
    return POLYMER_UNIT_M if _medium(medium) is Medium.POLYMER else GLASS_UNIT_M


def length_code(one_way_m: float, medium: Medium) -> int:
    """The LENGTH code the chip reports for a one-way path (truncated to the unit, 63 above the range)."""
    metres = check_real("one_way_m", one_way_m, 0.0, MAX_PATH_M, limit="Table 1-5: 0 m to 20 km")
    return min(LENGTH_MAX_CODE, math.floor(metres / unit_m(medium)))


def code_range_m(code: int, medium: Medium) -> tuple[float, float]:
    """The one-way lengths ``[low, high)`` a LENGTH code stands for; 63 is ``[63 units, 20 km]``."""
    value = check_int("code", code, 0, LENGTH_MAX_CODE, "LENGTH, 6 bits (RM-5)")
    unit = unit_m(medium)
    if value == LENGTH_MAX_CODE:
        return (value * unit, MAX_PATH_M)
    return (value * unit, (value + 1) * unit)


def length_m(code: int, medium: Medium) -> float:
    """The one-way length a LENGTH code shows, as a master's diagnostic table prints it: the range's low end."""
    return code_range_m(code, medium)[0]


def timer_count(one_way_m: float, bit_rate: int) -> int:
    """The length timer's result n for a one-way path: round trip 2 L t, counted at f = 16 x bit rate (1.6.1, F10)."""
    metres = check_real("one_way_m", one_way_m, 0.0, MAX_PATH_M, limit="Table 1-5: 0 m to 20 km")
    f = LENGTH_TIMER_CLOCKS_PER_BIT * check_bit_rate(bit_rate)
    # The small epsilon keeps exact multiples (e.g. 12.5 m at 500 kbit/s) from falling one count short in floats.
    return math.floor(2 * metres * LIGHT_RUNTIME_S_PER_M * f + 1e-9)


def timer_code(count: int, bit_rate: int, medium: Medium) -> int:
    """The LENGTH code from a timer result n: one-way L / 2 = n / (2 f t), in the medium's unit, 63 above."""
    n = check_int("count", count, 0)
    f = LENGTH_TIMER_CLOCKS_PER_BIT * check_bit_rate(bit_rate)
    # units = n / (2 f t u); with f t u a ratio of integers in both media, integer arithmetic keeps it exact.
    clocks_per_unit = round(2 * f * LIGHT_RUNTIME_S_PER_M * unit_m(medium) * 1000)  # in thousandths of a count
    return min(LENGTH_MAX_CODE, (n * 1000) // clocks_per_unit)

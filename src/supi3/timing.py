"""Timing calculator: bit periods, the CPU access time of 3.4.14, the I/O access window, the manual's timing
tables evaluated for a bit rate, and the optical length formula of 1.6.1 with the resolution of Table 1-5."""

from __future__ import annotations

import ast
import operator
from collections.abc import Callable
from dataclasses import dataclass

from supi3 import tables
from supi3.checks import check_instance, check_int, check_real, fail
from supi3.errors import Supi3Error
from supi3.interbus import wire
from supi3.optical import length as optical_length


class TimingError(Supi3Error, ValueError):
    """A timing question the manual cannot answer (unknown bit rate, negative byte count, ...)."""


MAX_DEVICES = wire.MAX_DEVICES
"""Devices in one INTERBUS ring, 512."""

MAX_DEVICE_BYTES = max(lc.bits or 0 for lc in tables.LENGTH_CODES) // 8
"""Data bytes of one device at most: the longest data length, 32 words (Table 3-11); ``devices`` devices carry at
most ``devices`` times as many (A23)."""

MAX_NETWORK_BYTES = MAX_DEVICES * MAX_DEVICE_BYTES
"""Data bytes in a whole network: 512 devices of the longest data length, 32 words (Table 3-11)."""

def max_optical_count(bit_rate: int) -> int:
    """Largest length timer result n at ``bit_rate``: a 20 km path (Table 1-5) there and back (1.6.1, OPT-1), 1,600
    at 500 kbit/s and 6,400 at 2 Mbit/s. (Table 1-5's 0 to 63 is the LENGTH code's range, not the timer's.)"""
    bit_period_s(bit_rate)
    return optical_length.timer_count(optical_length.MAX_PATH_M, bit_rate)


MAX_OPTICAL_COUNT = max(optical_length.timer_count(optical_length.MAX_PATH_M, rate) for rate in tables.BIT_RATES)
"""Largest length timer result at any bit rate (:func:`max_optical_count`), 6,400 at 2 Mbit/s."""

_MAX_EXPRESSION = 200
"""Longest timing expression evaluated; the manual's are a few dozen characters."""


def _shown(number: int) -> str:
    """An integer for an error message; a huge one by its size (``str`` refuses more than 4300 digits)."""
    return str(number) if number.bit_length() <= 64 else f"an integer of {number.bit_length()} bits"


def _network_bytes(value: object, name: str = "network byte count") -> int:
    number = check_int(name, value)
    if not 0 <= number <= MAX_NETWORK_BYTES:
        raise TimingError(f"{name} must be >= 0 and <= {MAX_NETWORK_BYTES} ({MAX_DEVICES} devices of 32 words), "
                          f"not {_shown(number)}")
    return number


def bit_period_s(bit_rate: int) -> float:
    """t_Bit_IBS: 2 µs at 500 kbit/s, 0.5 µs at 2 Mbit/s (Table 1-7 bit rates only)."""
    check_int("bit_rate", bit_rate)
    if bit_rate not in tables.BIT_RATES:
        raise TimingError(f"bit rate {bit_rate} bit/s is not one of Table 1-7's {tables.BIT_RATES}")
    return 1.0 / bit_rate


def cpu_access_time_s(network_bytes: int, bit_rate: int) -> float:
    """Worst-case time the CPU has after a valid-data-cycle interrupt: T = 13 * (5 + n) * t_Bit (3.4.14).

    ``network_bytes`` is n, the number of data bytes in the entire network. The manual's example, one 2-word
    device at 500 kbit/s, gives 234 µs.
    """
    _network_bytes(network_bytes)
    return (tables.CPU_ACCESS_TELEGRAM_BITS * (tables.CPU_ACCESS_OVERHEAD_BYTES + network_bytes)
            * bit_period_s(bit_rate))


def io_access_window_s(bit_rate: int) -> float:
    """Time the data registers may be accessed after the I/O access bit falls: 30 bit periods (3.4.14)."""
    return tables.IO_ACCESS_WINDOW_BITS * bit_period_s(bit_rate)


# ------------------------------------------------------------------------------------------------------------
# The manual's timing expressions ("0.5 * t_Bit_IBS", "2 * TCLK + 10 ns", "667 ns | 167 ns")
# ------------------------------------------------------------------------------------------------------------

_OPS: dict[type, Callable[[float, float], float]] = {
    ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
}


def _eval(node: ast.AST, names: dict[str, float]) -> float:
    if isinstance(node, ast.Expression):
        return _eval(node.body, names)
    if isinstance(node, ast.Constant) and isinstance(node.value, int | float):
        return float(node.value)
    if isinstance(node, ast.Name) and node.id in names:
        return names[node.id]
    if isinstance(node, ast.BinOp) and type(node.op) in _OPS:
        return _OPS[type(node.op)](_eval(node.left, names), _eval(node.right, names))
    raise TimingError(f"cannot evaluate {ast.dump(node)} in a timing expression")


def evaluate(expression: str, bit_rate: int, n_bytes: int = 1, t0_s: float | None = None) -> float:
    """Evaluate one of the manual's timing expressions in seconds for a bit rate.

    Names: ``t_Bit_IBS`` (bit period), ``TCLK`` (t_Bit_IBS / 16, Table 3-7), ``t0`` (the table's clock period,
    passed in ``t0_s``), ``n`` (bytes, Table 3-4 t8), ``ns`` (1e-9). ``"a | b"`` gives ``a`` at 500 kbit/s and
    ``b`` at 2 Mbit/s.

    Raises
    ------
    ArgumentError
        ``expression`` not a str, ``n_bytes`` not an integer, ``t0_s`` neither ``None`` nor a finite number > 0.
    TimingError
        A bit rate not of Table 1-7, ``n_bytes`` outside 0 to :data:`MAX_NETWORK_BYTES`, an expression too long,
        with more than one ``|`` or that is not the manual's arithmetic.
    """
    check_instance("expression", expression, str, "a timing expression (str)")
    if len(expression) > _MAX_EXPRESSION:
        raise TimingError(f"timing expression of {len(expression)} characters; at most {_MAX_EXPRESSION}")
    t_bit = bit_period_s(bit_rate)
    n_bytes = _network_bytes(n_bytes, "n_bytes")
    if t0_s is not None:
        t0_s = check_real("t0_s", t0_s, limit="a clock period in seconds")
        if t0_s <= 0:
            raise fail("t0_s", "a finite number > 0", t0_s, "a clock period in seconds")
    if "|" in expression:
        parts = expression.split("|")
        if len(parts) != len(tables.BIT_RATES):
            raise TimingError(f"timing expression {expression!r} has {len(parts)} alternatives; "
                              f"'a | b' gives one per bit rate of Table 1-7")
        expression = parts[tables.BIT_RATES.index(bit_rate)]
    names = {"t_Bit_IBS": t_bit, "TCLK": t_bit / tables.TCLK_PER_BIT, "n": float(n_bytes), "ns": 1e-9}
    if t0_s is not None:
        names["t0"] = t0_s
    # "100 ns" is the manual's notation for 100 * ns.
    source = expression.strip().replace(" ns", " * ns")
    try:
        return _eval(ast.parse(source, mode="eval"), names)
    except (SyntaxError, ZeroDivisionError, RecursionError, MemoryError) as exc:
        raise TimingError(f"cannot evaluate timing expression {expression!r}: {exc}") from None


@dataclass(frozen=True)
class EvaluatedTiming:
    """A timing parameter with its limits in seconds (``None`` where the table gives no limit)."""

    symbol: str
    explanation: str
    minimum_s: float | None
    maximum_s: float | None


TIMING_TABLES: dict[str, tuple[tables.TimingParameter, ...]] = {
    "3-4": tables.SPI_MASTER_TIMING,
    "3-7": tables.UP_INTERFACE_TIMING,
    "3-15": tables.REGISTER_EXPANSION_TIMING,
}


def timing_table(table: str, bit_rate: int, n_bytes: int = 2) -> list[EvaluatedTiming]:
    """Evaluate every row of Table 3-4, 3-7 or 3-15 for a bit rate (``n_bytes`` for Table 3-4's t8)."""
    if table not in TIMING_TABLES:
        raise TimingError(f"no timing table {table!r}; choose from {sorted(TIMING_TABLES)}")
    _network_bytes(n_bytes, "n_bytes")
    result: list[EvaluatedTiming] = []
    t0: float | None = None
    for row in TIMING_TABLES[table]:
        low = evaluate(row.minimum, bit_rate, n_bytes, t0) if row.minimum else None
        high = evaluate(row.maximum, bit_rate, n_bytes, t0) if row.maximum else None
        if row.symbol == "t0":
            t0 = low
        result.append(EvaluatedTiming(row.symbol, row.explanation, low, high))
    return result


def limit(table: str, symbol: str, bit_rate: int, *, maximum: bool = False) -> float:
    """One limit of a timing table for a bit rate, in seconds (the minimum unless ``maximum``).

    Raises
    ------
    TimingError
        If the table has no such symbol, or gives no such limit for it.
    """
    for row in timing_table(table, bit_rate):
        if row.symbol == symbol:
            value = row.maximum_s if maximum else row.minimum_s
            if value is None:
                raise TimingError(f"Table {table} gives no {'maximum' if maximum else 'minimum'} for {symbol}")
            return value
    raise TimingError(f"Table {table} has no parameter {symbol!r}")


def upif_byte_s(bit_rate: int, sclk_hz: float | None = None) -> float:
    """Time one byte of the serial µP interface takes, /SS edge to the next byte's /SS edge (Table 3-7).

    /SS fall to the first SCLK fall max(t1, t7 - t0/2), 7.5 SCLK periods to the last rising edge, t2 to /SS rise,
    and /SS high for t6 (maximum: C/D has settled) plus t8. ``sclk_hz`` ``None``: the fastest SCLK (t0 minimum).

    Raises
    ------
    TimingError
        If ``sclk_hz`` is faster than Table 3-7 allows at ``bit_rate``.
    """
    t0 = limit("3-7", "t0", bit_rate)
    if sclk_hz is not None:
        period = 1.0 / check_real("sclk_hz", sclk_hz, 1.0, limit="SCLK frequency in Hz")
        if period < t0 * (1 - 1e-9):
            raise TimingError(f"sclk_hz {sclk_hz:g} is faster than Table 3-7 allows at {bit_rate} bit/s "
                              f"(t0 >= {t0 * 1e9:.0f} ns)")
        t0 = period
    lead = max(limit("3-7", "t1", bit_rate), limit("3-7", "t7", bit_rate, maximum=True) - t0 / 2)
    return lead + 7.5 * t0 + limit("3-7", "t2", bit_rate) + limit("3-7", "t6", bit_rate, maximum=True) + \
        limit("3-7", "t8", bit_rate)


# ------------------------------------------------------------------------------------------------------------
# Optical path length (1.6.1, Table 1-5)
# ------------------------------------------------------------------------------------------------------------


def optical_length_m(timer_count: int, bit_rate: int) -> float:
    """Forward-and-return fibre length from the runtime timer: L = n / (f * t) (1.6.1).

    f is the timer clock, 16 times the bit rate (8 MHz at 500 kbit/s), t = 5 ns/m.
    """
    check_int("timer_count", timer_count)
    most = max_optical_count(bit_rate)
    if not 0 <= timer_count <= most:
        raise TimingError(f"timer count must be >= 0 and <= {most} (a 20 km path there and back, Table 1-5, OPT-1) "
                          f"at {bit_rate} bit/s, not {_shown(timer_count)}")
    f = tables.LENGTH_TIMER_CLOCKS_PER_BIT * bit_rate
    return timer_count / (f * tables.LIGHT_RUNTIME_S_PER_M)


def optical_range(length_m: float, bit_rate: int) -> tables.OpticalLengthRange:
    """The Table 1-5 row that applies to a one-way path length at a bit rate (20 km itself is the last row's, as
    everywhere else: :data:`supi3.optical.length.MAX_PATH_M`)."""
    metres = check_real("length_m", length_m, finite=False)
    bit_period_s(bit_rate)
    rows = [r for r in tables.OPTICAL_LENGTH_RANGES if r.bit_rate == bit_rate]
    for row in rows:
        if row.min_m <= metres < row.max_m or metres == row.max_m == optical_length.MAX_PATH_M:
            return row
    raise TimingError(f"{length_m} m is outside Table 1-5's 0 m to 20 km")


def data_cycle_time_s(network_bytes: int, devices: int, bit_rate: int) -> float:
    """Duration of one INTERBUS data cycle on the wire: frame, ring delay, turnaround and latch
    (``supi3.interbus.wire.cycle_bits``, docs/interbus.md "Cycle timing"). ``network_bytes`` are at most 64 per
    device (32 words, Table 3-11; A23): more is a :class:`TimingError`, not a longer cycle no ring can have."""
    network_bytes = _network_bytes(network_bytes)
    check_int("devices", devices)
    if not 1 <= devices <= MAX_DEVICES:
        raise TimingError(f"need devices >= 1 and <= {MAX_DEVICES} (the INTERBUS limit), not "
                          f"{_shown(devices)}")
    if network_bytes > devices * MAX_DEVICE_BYTES:  # A23
        raise TimingError(f"network byte count must be at most {devices * MAX_DEVICE_BYTES} for {devices} device"
                          f"{'s' if devices != 1 else ''} (at most 32 words each, Table 3-11), not {network_bytes}")
    return wire.cycle_bits(network_bytes, devices) * bit_period_s(bit_rate)


def report(network_bytes: int, bit_rate: int, devices: int = 1) -> dict[str, object]:
    """Everything ``supi3 timing`` prints, as data (times in µs)."""
    _network_bytes(network_bytes)
    t_bit = bit_period_s(bit_rate)
    resolution = optical_length_m(1, bit_rate)
    near = optical_range(0, bit_rate)
    return {
        "bit_rate": bit_rate,
        "t_bit_us": t_bit * 1e6,
        "network_bytes": network_bytes,
        "devices": devices,
        "data_cycle_time_us": round(data_cycle_time_s(network_bytes, devices, bit_rate) * 1e6, 6),
        "data_cycle_formula": "13 * (6 + n) bit periods of frame, then status telegrams for the ring delay, "
        "turnaround and latch (docs/interbus.md)",
        "cpu_access_time_us": round(cpu_access_time_s(network_bytes, bit_rate) * 1e6, 6),
        "cpu_access_formula": "T = 13 * (5 + n) * t_Bit (manual 3.4.14)",
        "io_access_window_us": round(io_access_window_s(bit_rate) * 1e6, 6),
        "io_access_window_formula": "30 * t_Bit (manual 3.4.14, Figure 3-22)",
        "optical_formula": "L = n / (f * t), f = 16 * bit rate, t = 5 ns/m (manual 1.6.1)",
        "optical_m_per_count": resolution,
        "optical_resolution_m": {"typical": near.resolution_m[0] if near.resolution_m else None,
                                 "worst": near.resolution_m[1] if near.resolution_m else None},
        "optical_value_range": list(near.values),
        "optical_long_value": 63,
    }

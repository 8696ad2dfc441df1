"""A down counter as a maximal-length linear feedback shift register (docs/rtl.md, "Size and build time").

A long time-out counter that is loaded, steps once a clock and reports when it reaches its end needs only the
order of its states, not their binary values: a Fibonacci LFSR steps with one or three XOR gates where a binary
decrement needs a carry chain of its width. :class:`Countdown` gives the behaviour of a down counter
``c`` that is loaded with ``limit``, counts down while non-zero, and is at ``1`` (``last``) one clock before it
stops at ``0``; its states are the LFSR's, the idle state ``0`` (the LFSR's fixed point) is the counter's ``0``
and the state ``1`` is the counter's ``1``, so a counter value ``v`` is the state ``v - 1`` steps before ``1``.
The feedback taps are the maximal-length ones of Xilinx XAPP052 (Table 3), for every width from 2 to 25;
``tests/test_rtl_lfsr.py`` checks each sequence's period. An up counter that is only loaded with constants,
stepped and compared with constants is the same LFSR read the other way (:func:`count_state`).
"""

from __future__ import annotations

from typing import Final

from amaranth.hdl import Cat, Module, Mux, Signal, Value

from supi3.checks import check_bits, check_int

__all__ = [
    "TAPS", "Countdown", "advance", "before", "count_state", "count_width", "down_state", "down_step", "next_state",
    "step",
]  # fmt: skip

TAPS: Final[dict[int, tuple[int, ...]]] = {
    2: (2, 1), 3: (3, 2), 4: (4, 3), 5: (5, 3), 6: (6, 5), 7: (7, 6), 8: (8, 6, 5, 4), 9: (9, 5), 10: (10, 7),
    11: (11, 9), 12: (12, 6, 4, 1), 13: (13, 4, 3, 1), 14: (14, 5, 3, 1), 15: (15, 14), 16: (16, 15, 13, 4),
    17: (17, 14), 18: (18, 11), 19: (19, 6, 2, 1), 20: (20, 17), 21: (21, 19), 22: (22, 21), 23: (23, 18),
    24: (24, 23, 22, 17), 25: (25, 22),
}  # fmt: skip
"""Feedback taps (bit numbers from 1) of a maximal-length LFSR of each width: the sequence from any non-zero state
runs through all ``2 ** width - 1`` non-zero states."""


def _width(width: object) -> int:
    """``width`` as a width with taps (2 to 25), else the named error."""
    return check_int("width", width, min(TAPS), max(TAPS), limit="XAPP052 Table 3 taps")


def step(state: int, width: int) -> int:
    """The state after ``state`` (the new bit, the XOR of the taps, enters at bit 0; ``0`` stays ``0``).

    Raises
    ------
    ArgumentError
        ``width`` not 2 to 25, ``state`` not a ``width``-bit state.
    """
    state = check_bits("state", state, _width(width))
    feedback = 0
    for tap in TAPS[width]:
        feedback ^= state >> (tap - 1) & 1
    return (state << 1 | feedback) & ((1 << width) - 1)


def advance(state: int, width: int, steps: int) -> int:
    """The state ``steps`` steps after ``state``: the step is linear over GF(2), so its power is found by squaring
    (the images of the unit vectors), in a few dozen operations for any count.

    Raises
    ------
    ArgumentError
        ``width`` not 2 to 25, ``state`` not a ``width``-bit state, ``steps`` not an integer >= 0 (a negative
        count used to loop for ever).
    """
    state = check_bits("state", state, _width(width))
    steps = check_int("steps", steps, 0)
    power = [1 << i for i in range(width)]  # the identity: images of the unit vectors
    square = [step(1 << i, width) for i in range(width)]  # one step

    def apply(images: list[int], value: int) -> int:
        result = 0
        for i in range(width):
            if value >> i & 1:
                result ^= images[i]
        return result

    while steps:
        if steps & 1:
            power = [apply(square, image) for image in power]
        square = [apply(square, image) for image in square]
        steps >>= 1
    return apply(power, state)


def before(steps: int, width: int) -> int:
    """The state ``steps`` steps before the state ``1`` (``steps`` below ``2 ** width - 1``): what a counter that
    ends at ``1`` is loaded with to end ``steps`` clocks later.

    Raises
    ------
    ArgumentError
        ``width`` not 2 to 25, ``steps`` not from 0 to ``2 ** width - 2``.
    """
    steps = check_int("steps", steps, 0, (1 << _width(width)) - 2, limit="within one period of the LFSR")
    return advance(1, width, (1 << width) - 1 - steps)


def count_width(most: int) -> int:
    """The width of an LFSR that counts from 0 to ``most`` (``most`` from 0 to ``2 ** 25 - 2``): its first
    ``most + 1`` states from ``1`` (:func:`count_state`) are distinct.

    Raises
    ------
    ArgumentError
        ``most`` not an integer from 0 to ``2 ** 25 - 2``.
    """
    most = check_int("most", most, 0, (1 << max(TAPS)) - 2, limit="the widest LFSR's period")
    return max(min(TAPS), (most + 1).bit_length())


def count_state(value: int, width: int) -> int:
    """The state that stands for the count ``value`` of an up counter as an LFSR, ``value`` steps after the state
    ``1``: a counter that is only loaded with constants, stepped and compared with constants counts ``v`` to
    ``v + 1`` by :func:`next_state`.

    Raises
    ------
    ArgumentError
        ``width`` not 2 to 25, ``value`` not from 0 to ``2 ** width - 2``: past the period a count's state is that
        of a smaller count, and a comparison with it would fire early.
    """
    value = check_int("value", value, 0, (1 << _width(width)) - 2, limit="within one period of the LFSR")
    return advance(1, width, value)


def down_state(value: int, width: int) -> int:
    """The state that stands for the value ``value`` of a down counter as an LFSR that ends at ``1`` then ``0``
    (:class:`Countdown`'s states): ``0`` is ``0``, ``v`` the state ``v - 1`` steps before ``1``.

    Raises
    ------
    ArgumentError
        ``width`` not 2 to 25, ``value`` not from 0 to ``2 ** width - 1``.
    """
    value = check_int("value", value, 0, (1 << _width(width)) - 1, limit="within one period of the LFSR")
    return 0 if value == 0 else before(value - 1, width)


def down_step(state: Value) -> Value:
    """One step of such a down counter in gates: ``1`` goes to ``0``, ``0`` stays, any other state steps."""
    return Mux(state == 1, 0, next_state(state))


def next_state(state: Value) -> Value:
    """:func:`step` in gates, for a signal whose width has taps."""
    return Cat(Cat(*(state[tap - 1] for tap in TAPS[len(state)])).xor(), state[:-1])


class Countdown:
    """A down counter from ``limit`` (1 to ``2 ** 24 - 1``) as an LFSR, built in ``m``'s ``sync`` domain.

    ``load`` (a value: 1 loads ``limit``), ``clear`` (1 sets ``0``, winning over ``load``) and otherwise one step
    while not ``0``; ``last`` is 1 while the counter is at ``1``, ``idle`` while it is at ``0``.
    """

    def __init__(self, m: Module, limit: int, *, load: Value, clear: Value, name: str) -> None:
        if not 1 <= limit < 1 << max(TAPS):
            raise ValueError(f"limit must be from 1 to {(1 << max(TAPS)) - 1}, not {limit}")
        width = max(min(TAPS), limit.bit_length())  # limit < 2 ** width: the states limit..1 are distinct
        start = down_state(limit, width)
        state = Signal(width, name=name)
        self.last: Value = state == 1
        self.idle: Value = state == 0
        with m.If(clear):
            m.d.sync += state.eq(0)
        with m.Elif(load):
            m.d.sync += state.eq(start)
        with m.Elif(self.last):
            m.d.sync += state.eq(0)
        with m.Else():  # 0 steps to 0
            m.d.sync += state.eq(next_state(state))

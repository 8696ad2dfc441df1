"""A small example design and its pin model: the starting point for a design of one's own, and what proves the
lockstep harness (``tests/test_verif_lockstep.py``, the installed-wheel test) and benchmarks it
(``bench/bench_lockstep.py``).

The design has every kind of output the chip has: registered outputs (``count``, ``sr``, ``acc``, a 40-bit one
wider than a word), a combinational output from state (``zero``), a combinational output from inputs and state
(``match``), and a tri-state bus (``bus`` with ``bus_oe``) that drives a different value while disabled.

Per cycle, with inputs ``en``, ``load``, ``din``, ``sin``, ``rd``:

* ``count`` loads ``din`` when ``load``, else counts up when ``en`` (8 bits, wrapping);
* ``sr`` shifts ``sin`` in at bit 0 when ``en`` (16 bits);
* ``acc`` adds ``din`` when ``en`` (40 bits, wrapping);
* ``zero`` is ``count == 0``; ``match`` is ``din == count``;
* ``bus`` drives ``sr[15:8] ^ count`` while ``rd``, and ``~count`` (not compared) otherwise.
"""

from __future__ import annotations

from collections.abc import Mapping

from amaranth.hdl import Elaboratable, Module, Signal

from supi3.pinlevel import EventLog, Pin

__all__ = ["ShiftCounter", "ShiftCounterModel"]

ACC_BITS = 40
ACC_MASK = (1 << ACC_BITS) - 1


class ShiftCounter(Elaboratable):
    """The example design (see the module docstring); its pins are attributes named like the model's."""

    def __init__(self) -> None:
        self.en = Signal()
        self.load = Signal()
        self.din = Signal(8)
        self.sin = Signal()
        self.rd = Signal()
        self.count = Signal(8)
        self.sr = Signal(16)
        self.acc = Signal(ACC_BITS)
        self.zero = Signal()
        self.match = Signal()
        self.bus = Signal(8)
        self.bus_oe = Signal()

    def elaborate(self, _platform: object) -> Module:
        m = Module()
        with m.If(self.load):
            m.d.sync += self.count.eq(self.din)
        with m.Elif(self.en):
            m.d.sync += self.count.eq(self.count + 1)
        with m.If(self.en):
            m.d.sync += [self.sr.eq(self.sr << 1 | self.sin), self.acc.eq(self.acc + self.din)]
        m.d.comb += [
            self.zero.eq(self.count == 0),
            self.match.eq(self.din == self.count),
            self.bus_oe.eq(self.rd),
        ]
        with m.If(self.rd):
            m.d.comb += self.bus.eq(self.sr[8:16] ^ self.count)
        with m.Else():
            m.d.comb += self.bus.eq(~self.count)
        return m


class ShiftCounterModel:
    """The example's cycle-accurate pin model, following :class:`~supi3.pinlevel.PinModel`."""

    inputs: tuple[Pin, ...] = (Pin("en"), Pin("load"), Pin("din", 8), Pin("sin"), Pin("rd"))
    outputs: tuple[Pin, ...] = (
        Pin("count", 8),
        Pin("sr", 16),
        Pin("acc", ACC_BITS),
        Pin("zero"),
        Pin("match"),
        Pin("bus", 8, tristate=True),
    )

    def __init__(self) -> None:
        self.events = EventLog(16)
        self.reset()

    def reset(self) -> None:
        """Counter, shift register and accumulator to 0."""
        self.cycle = 0
        self.count = 0
        self.sr = 0
        self.acc = 0
        self.events.clear()

    def step(self, inputs: Mapping[str, int]) -> dict[str, int]:
        """One clock cycle (see :mod:`supi3.pinlevel`)."""
        count = self.count
        sr = self.sr
        acc = self.acc
        din = inputs["din"]
        rd = inputs["rd"]
        bus = (sr >> 8) ^ count if rd else 0
        if rd:
            self.events.add(self.cycle, "bus read {:#04x}", bus)
        if inputs["load"]:
            self.count = din
            self.events.add(self.cycle, "load {:#04x}", din)
        elif inputs["en"]:
            self.count = (count + 1) & 0xFF
        if inputs["en"]:
            self.sr = (sr << 1 | inputs["sin"]) & 0xFFFF
            self.acc = (acc + din) & ACC_MASK
        self.cycle += 1
        return {
            "count": count,
            "sr": sr,
            "acc": acc,
            "zero": int(count == 0),
            "match": int(din == count),
            "bus": bus,
            "bus_oe": rd,
        }

    def recent_events(self) -> list[str]:
        """The last bus reads and loads, for mismatch reports."""
        return self.events.recent()

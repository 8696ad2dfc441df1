"""The ring's data-cycle kernel (docs/interbus.md, "Ring kernel") against the straightforward path.

A ring built with ``record=True`` runs every line through the full path and every device through its own
``load``/``latch`` methods; a plain ring hands runs of one class to the class's ``data_kernel``. The reference ring
is recorded and holds reference devices, whose methods take no shortcut (``Supi3.load_at``/``latch_at``). Both
must give identical results: master verdicts and diagnostics, IN data, and every device's state (OUT data, latched
registers, events, management bits), over random rings of SUPI 3 chips (binary I/O and µP modes), plain devices
and devices without a kernel, with random data, faults, /StatErr, watchdogs, idle time and resets.
"""

from __future__ import annotations

import copy
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3 import tables
from supi3.config import MfpKind, decode
from supi3.interbus import wire
from supi3.interbus.device import PlainDevice
from supi3.interbus.link import DataKernel
from supi3.interbus.master import Master
from supi3.interbus.ring import BitFlip, CorruptLoopback, DeadLine, Ring, Truncate
from supi3.interbus.wire import Cycle
from supi3.model.chip import Supi3, clocks
from support import fields

CLK_2M = tables.clk_conf_for(2_000_000)
"""The rings here run at 2 Mbit/s, so do their chips (UP-48)."""
BINARY = [decode(r.c, r.mfp, clk_conf=CLK_2M) for r in tables.MODE_ROWS
          if decode(r.c, r.mfp).mfp_mode.kind is MfpKind.BINARY_IO]  # fmt: skip
MICRO = [decode(r.c, r.mfp, clk_conf=CLK_2M) for r in tables.MODE_ROWS
         if decode(r.c, r.mfp).mfp_mode.kind is MfpKind.INIT_UP]  # fmt: skip


class NoKernelDevice(PlainDevice):
    """A plain device whose class offers no kernel: the ring must call its methods one by one."""

    data_kernel = None


class ReferenceChip(Supi3):
    """A SUPI 3 chip without the kernel: every load and latch goes the full way."""

    __slots__ = ()  # Supi3's layout, so that a copy of a chip can become one (_reference)
    data_kernel = None  # type: ignore[assignment]

    def load(self, cycle: Cycle, now: float) -> bytes:
        return self.load_at(cycle, clocks(now))

    def latch(self, cycle: Cycle, received: bytes, now: float) -> None:
        self.latch_at(cycle, received, clocks(now))


class ReferencePlain(PlainDevice):
    """A plain device without the kernel (its methods are the reference)."""

    data_kernel = None


def _reference(devices: list[Any]) -> list[Any]:
    twins = copy.deepcopy(devices)
    for twin in twins:
        if type(twin) is Supi3:
            twin.__class__ = ReferenceChip
        elif type(twin) is PlainDevice:
            twin.__class__ = ReferencePlain
    return twins


def _device(kind: str, index: int) -> Any:
    if kind == "binary":
        chip = Supi3(BINARY[index % len(BINARY)])
        chip.set_mfp_inputs((index * 0x1357) & 0xFFFF)
        return chip
    if kind == "micro":
        return Supi3(MICRO[index % len(MICRO)], strict=False)
    cls = PlainDevice if kind == "plain" else NoKernelDevice
    return cls(0xBF if index % 2 else 0x03, 0b01001 if index % 3 else 0b00001)


def _state(device: Any) -> dict[str, object]:
    """What a device shows: its attributes, without caches and objects compared by identity. The events count
    merged (the shortcut counts valid cycles apart); the clock of the last bus call left out (the shortcut does not
    move it, as before the kernel: it is read only in the µP modes, which never take the shortcut, and by the next
    full bus call after setting it)."""
    hidden = ("registers", "watchdog", "_loaded", "_shown", "_events", "_fast_valid", "_now")
    state = {k: v for k, v in fields(device).items() if k not in hidden}
    if isinstance(device, Supi3):
        state["events"] = device.events
        state["mfp_outputs"] = device.mfp_outputs
        if device.registers is not None:
            registers = vars(device.registers)
            state["registers"] = {k: v for k, v in registers.items() if not callable(v) and k != "violations"}
            state["violations"] = repr(registers["violations"].records)
            state["in_bytes"] = device.registers.in_bytes()
    else:
        state["watchdog"] = vars(device.watchdog)
    return state


KINDS = st.sampled_from(["binary", "binary", "binary", "micro", "plain", "nokernel"])


@st.composite
def _op(draw: st.DrawFn, n: int) -> tuple[Any, ...]:
    kind = draw(st.sampled_from(["cycle"] * 6 + ["inputs", "outputs"] * 2
                                + ["fault", "stat_err", "watchdog", "idle", "jump", "reset"]))  # fmt: skip
    if kind in ("inputs", "outputs"):
        return (kind, draw(st.integers(0, n - 1)), draw(st.integers(0, 0xFFFF)))
    if kind == "fault":
        segment = draw(st.integers(1, n + 1))
        cycles = draw(st.sampled_from([1, 2, 3]))
        fault = draw(st.sampled_from([
            BitFlip(segment, draw(st.integers(0, 200)), cycles),
            Truncate(segment, draw(st.integers(0, 6)), cycles),
            CorruptLoopback(segment, draw(st.integers(0, 0xFFFF)), cycles),
            DeadLine(segment, cycles),
        ]))  # fmt: skip
        return (kind, fault)
    if kind == "stat_err":
        return (kind, draw(st.integers(0, n - 1)), draw(st.booleans()))
    if kind == "watchdog":
        return (kind, draw(st.sampled_from(tables.WATCHDOG_TIMEOUTS_S)))
    if kind in ("idle", "jump"):
        return (kind, draw(st.sampled_from([0.001, 0.06, 0.25, 1.2])))
    return (kind,)


def _apply(op: tuple[Any, ...], ring: Ring, master: Master) -> object:
    kind = op[0]
    devices = ring.devices
    if kind == "cycle":
        if master.stopped:
            return master.start()
        return master.cycle()
    if kind == "inputs":
        device = devices[op[1]]
        if isinstance(device, Supi3):
            device.set_mfp_inputs(op[2])
        elif isinstance(device, PlainDevice):
            device.set_inputs(bytes([op[2] & 0xFF]) * device.size)
    elif kind == "outputs":
        if master.config is not None and not master.stopped:
            position = op[1] % len(master.config) + 1
            master.set_outputs(position, bytes((op[2] + k) & 0xFF for k in range(master.entry(position).data_bytes)))
    elif kind == "fault":
        ring.inject(op[1])
    elif kind == "stat_err":
        device = devices[op[1]]
        if isinstance(device, Supi3):
            device.set_stat_err(op[2], ring.now)
        elif isinstance(device, PlainDevice):
            device.set_peripheral_fault(op[2])
    elif kind == "watchdog":
        master.set_watchdog(op[1])
    elif kind == "idle":
        ring.idle(op[1])
    elif kind == "jump":  # bus time moves on unseen: the next cycle finds filters and watchdogs due at its load
        ring.now += op[1]
    else:
        master.alarm_stop()
    return None


@settings(max_examples=120, deadline=None)
@given(data=st.data(), kinds=st.lists(KINDS, min_size=1, max_size=12))
def test_kernel_ring_equals_straightforward_ring(data: st.DataObject, kinds: list[str]) -> None:
    fast_devices = [_device(kind, k) for k, kind in enumerate(kinds)]
    slow_devices = _reference(fast_devices)
    fast, slow = Ring(fast_devices, bit_rate=2_000_000), Ring(slow_devices, bit_rate=2_000_000, record=True)
    fast_master, slow_master = Master(fast), Master(slow)
    assert fast_master.start() == slow_master.start()
    ops = data.draw(st.lists(_op(len(kinds)), min_size=1, max_size=40), label="ops")
    for op in ops:
        assert _apply(op, fast, fast_master) == _apply(op, slow, slow_master), op
        assert fast.now == slow.now
        assert [_state(d) for d in fast.devices] == [_state(d) for d in slow.devices], op
        assert fast_master.diagnostics == slow_master.diagnostics
        if fast_master.config is not None and not fast_master.stopped:
            for position in range(1, len(fast_master.config) + 1):
                assert fast_master.inputs(position) == slow_master.inputs(position)


@settings(max_examples=60, deadline=None)
@given(
    kinds=st.lists(st.sampled_from(["binary", "micro", "plain"]), min_size=1, max_size=8),
    levels=st.lists(st.integers(0, 0xFFFF), min_size=8, max_size=8),
    watchdog=st.sampled_from([None, 0, 1, 3]),
    stat_err=st.booleans(),
    now=st.sampled_from([0.0, 0.01, 0.3, 2.0]),
)
def test_each_kernel_equals_its_methods(
    kinds: list[str], levels: list[int], watchdog: int | None, stat_err: bool, now: float
) -> None:
    """Every class's kernel gives what the class's own load/latch give, device by device, in any state."""
    for cls in (Supi3, PlainDevice):
        devices = [_device(kind, k) for k, kind in enumerate(kinds) if isinstance(_device(kind, k), cls)]
        if not devices:
            continue
        for k, device in enumerate(devices):
            device.load(Cycle.DATA, 0.0)  # the kernel's shortcut needs a data cycle before
            if k % 2:
                device.discard(Cycle.DATA, True, 0.0)  # TE set: a latched data cycle clears it (A21)
            if isinstance(device, Supi3):
                if device.registers is None and k % 3:
                    device.set_mfp_inputs(levels[k])
                device.set_stat_err(stat_err and k % 2 == 0, 0.0)
                if watchdog is not None:
                    device.latch(Cycle.ID, wire.word_bytes(wire.command_word(watchdog_code=watchdog)), 0.0)
            else:
                device.set_peripheral_fault(stat_err and k % 2 == 0)
                if watchdog is not None:
                    device.latch(Cycle.ID, wire.word_bytes(wire.command_word(watchdog_code=watchdog)), 0.0)
        twins = _reference(devices)
        kernel = cls.data_kernel
        assert isinstance(kernel, DataKernel)
        registers, attention = kernel.load(devices, now)
        expected = [twin.load(Cycle.DATA, now) for twin in twins]
        assert registers == expected
        assert attention == any(twin.attention for twin in twins)
        assert [_state(d) for d in devices] == [_state(t) for t in twins]
        received = [bytes((0xA5 + k) & 0xFF for _ in range(len(r))) for k, r in enumerate(registers)]
        later = now + 0.004
        kernel.latch(devices, received, later)
        for twin, data in zip(twins, received, strict=True):
            twin.latch(Cycle.DATA, data, later)
        assert [_state(d) for d in devices] == [_state(t) for t in twins]


@pytest.mark.parametrize("cls", [Supi3, PlainDevice])
def test_classes_offer_a_kernel(cls: type[Supi3 | PlainDevice]) -> None:
    assert isinstance(cls.data_kernel, DataKernel)

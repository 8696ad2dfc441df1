"""A seeded fault campaign: a master runs a ring through random faults, ring changes and resets, and every cycle
is checked against what really happened (docs/interbus.md, "Fault campaign").

For each *episode* the campaign injects one event, runs the master for a few cycles, removes the event and lets
the master recover. It counts

- **faults injected / detected**: events that should make a cycle fail, and those that did;
- **located right / located wrong / not located**: per detected event, from its error diagnostics: right if one
  names the true position and none names another, wrong if any names another, not located if none names any;
- **corrupted latches**: a device whose latched OUT data differ from what the master sent it, a master whose IN
  data differ from what the devices sent, or a device that took over data in a cycle that failed;
- **recoveries / stuck masters**: episodes after which the master latched a data cycle on a table that matches
  the ring within ``RECOVERY_CYCLES`` cycles, and those after which it did not (the campaign then restarts it);
- **peak memory** (``tracemalloc``) and the growth of live memory (after ``gc.collect()``) between the end of
  the warm-up and the end; ring changes keep the ring size within ``RING_SIZE_SPREAD`` of its start, so a long
  run's growth is comparable to a short one's.

Two fidelities: the transaction-level :class:`~supi3.interbus.ring.Ring` of
:class:`~supi3.interbus.device.PlainDevice` (faults on lines: bit flips, truncation, a wrong loopback word, dead
lines; ring changes: a device removed, inserted, or changing its length as a µP-mode SUPI 3 does when software
rewrites SET; peripheral faults, 0BB1h; resets), and the pin-level :class:`~supi3.model.pinring.PinRing` of
cycle-accurate SUPI 3 chips (a chip's supply monitor dropping ``vmon_ok`` for some cycles; resets).

The true position of a fault on line *k* is *k* (N + 1: the return line); of a ring change, the first ring position
whose device differs; of a chip losing its supply, the chip's position; of a peripheral fault, the device's.
"""

from __future__ import annotations

import gc
import json
import random
import tracemalloc
from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass, field
from typing import Final, Literal

from supi3 import tables
from supi3.checks import check_choice, check_int, fail
from supi3.config import DeviceConfig, MfpKind, decode
from supi3.interbus import wire
from supi3.interbus.device import PlainDevice
from supi3.interbus.master import MSG_PERIPHERAL_FAULT, STATUS_TERMINAL_ID_CODES, CycleResult, Diagnostic, Master
from supi3.interbus.ring import BitFlip, CorruptLoopback, DeadLine, Fault, Ring, Truncate
from supi3.interbus.wire import Cycle

Fidelity = Literal["ring", "pin"]
FIDELITIES: Final = ("ring", "pin")

RING_EVENTS: Final = ("bitflip", "truncate", "loopback", "deadline", "remove", "insert", "length", "peripheral",
                      "reset")  # fmt: skip
PIN_EVENTS: Final = ("vmon", "reset")
DEFAULT_MIX: Final[dict[str, dict[str, int]]] = {
    "ring": {"bitflip": 4, "truncate": 2, "loopback": 2, "deadline": 2, "remove": 1, "insert": 1, "length": 1,
             "peripheral": 1, "reset": 1},
    "pin": {"vmon": 3, "reset": 1},
}  # fmt: skip
"""Relative weights of the events of each fidelity."""

RECOVERY_CYCLES: Final = 8
"""Cycles a master gets, after an event is removed, to latch a data cycle on a table that matches the ring."""
HEALTHY_CYCLES: Final = (1, 4)
"""Fault-free cycles between episodes (inclusive range)."""
HOLD_CYCLES: Final = (1, 3)
"""Cycles an event stays before it is removed (inclusive range); a fault with ``cycles`` set may vanish earlier."""
PERSISTENT_SHARE: Final = 0.5
"""Share of line faults that stay until removed (``cycles=None``); the others hit 1 to 4 cycles."""
RING_SIZE_SPREAD: Final = 2
"""Ring changes keep the size between start / 2 and start x 2 (and within 1..64): a bounded walk."""
WARM_UP_SHARE: Final = 0.1
"""Share of the cycles run before the memory baseline is taken."""

_USABLE: Final = [int(r.code, 2) for r in tables.LENGTH_CODES if r.bits is not None and 0 < r.bits <= 64]
"""Length codes of 1 to 8 data bytes: every ring change then changes the data cycle's length, so the master can
see it in a data cycle (a change that keeps the length is only seen by the next ID cycle)."""
_IDS: Final = sorted({r.code for r in tables.ID_CODES} - STATUS_TERMINAL_ID_CODES)
"""The ring's plain register devices take any ID code of the table but a bus terminal module's that answers a status
request (BK-5: 04h, 08h, 0Ch): the master trusts such a device's branch status, whose counter telegram count locates a
break in a BK-LBD's branch (BK-7), and a plain device keeps none (its ID register read as one: a count that put a
corrupted loopback word one line off, ``--seed 4 --devices 16``, or left a located break not located)."""
_PIN_ROW: Final = next(r for r in tables.MODE_ROWS if decode(r.c, r.mfp).mfp_mode.kind is MfpKind.BINARY_IO)
_PIN_CLK_CONF: Final = "11"  # 2 Mbit/s: 16 clocks per bit keeps the pin level short


MAX_DEVICES: Final[dict[Fidelity, int]] = {"ring": 64, "pin": 8}
"""The largest ring a campaign runs, per fidelity (a pin-level ring of more chips runs too slowly to be useful)."""
DEVICE_LIMITS: Final[dict[Fidelity, str]] = {"ring": "the campaign's ring sizes", "pin": "pin level: at most 8 chips"}
MAX_CYCLES: Final[dict[Fidelity, int]] = {"ring": 1_000_000, "pin": 10_000}
"""A27: the most master cycles a campaign runs, per fidelity: hours of run time (measured 25 to 76 cycles/s at
transaction level, 8 to 64 devices, 1.5 cycles/s at pin level, 3 chips, on a loaded 2-core machine); the bus time of
the longest ring's cycles stays far within A26's maximum. A soak beyond is several seeds."""
CYCLE_LIMITS: Final = "A27: hours of run time"


@dataclass(frozen=True)
class CampaignConfig:
    """What a campaign runs.

    Attributes
    ----------
    cycles:
        Master cycles to run in all (every cycle counts: healthy, faulted and recovery cycles), at most
        :data:`MAX_CYCLES` (A27).
    seed:
        Seed of the campaign's only random generator.
    devices:
        Ring size at the start (ring changes vary it between 1 and 64 at transaction level).
    fidelity:
        ``"ring"`` (transaction level) or ``"pin"`` (cycle-accurate chips).
    mix:
        Relative weights of the events (``RING_EVENTS`` or ``PIN_EVENTS``); ``None``: ``DEFAULT_MIX``.
    """

    cycles: int = 2000
    seed: int = 1
    devices: int = 8
    fidelity: Fidelity = "ring"
    mix: Mapping[str, int] | None = None

    def __post_init__(self) -> None:
        check_choice("fidelity", self.fidelity, FIDELITIES)
        check_int("cycles", self.cycles, 1, MAX_CYCLES[self.fidelity], CYCLE_LIMITS)
        check_int("seed", self.seed)
        check_int("devices", self.devices, 1, MAX_DEVICES[self.fidelity], DEVICE_LIMITS[self.fidelity])
        if self.mix is not None:
            events = RING_EVENTS if self.fidelity == "ring" else PIN_EVENTS
            if not isinstance(self.mix, Mapping) or not self.mix:
                raise fail("mix", f"a mapping of events ({', '.join(events)}) to weights", self.mix)
            for event, weight in self.mix.items():
                check_choice("mix event", event, events)
                check_int(f"mix weight of {event!r}", weight, 0)
            if not any(self.mix.values()):
                raise fail("mix", "at least one positive weight", self.mix)

    def weights(self) -> dict[str, int]:
        """The event weights in force."""
        return dict(DEFAULT_MIX[self.fidelity] if self.mix is None else self.mix)


@dataclass
class CampaignResult:
    """What a campaign found. The goals: ``located_wrong``, ``corrupted_latches`` and ``stuck`` are 0,
    ``recoveries == episodes``, and ``memory_growth_bytes`` stays small (flat) however long it runs."""

    fidelity: str
    devices: int
    seed: int
    cycles: int = 0
    episodes: int = 0
    faults_injected: int = 0
    detected: int = 0
    located_right: int = 0
    located_wrong: int = 0
    not_located: int = 0
    wrong_diagnostics: int = 0
    corrupted_latches: int = 0
    recoveries: int = 0
    stuck: int = 0
    ring_changes: int = 0
    resets: int = 0
    data_cycles_latched: int = 0
    peak_memory_bytes: int = 0
    memory_growth_bytes: int = 0
    by_event: dict[str, int] = field(default_factory=dict)
    examples: list[str] = field(default_factory=list)
    """Up to 5 descriptions of wrong locations, corrupted latches and stuck masters, for debugging."""

    @property
    def ok(self) -> bool:
        """Every goal met (memory growth aside, which the caller judges against the run's length)."""
        return (self.located_wrong == 0 and self.corrupted_latches == 0 and self.stuck == 0
                and self.recoveries == self.episodes)  # fmt: skip

    def as_dict(self) -> dict[str, object]:
        """The result as plain data (``--json``)."""
        data = asdict(self)
        data["ok"] = self.ok
        return data

    def rows(self) -> list[tuple[str, str]]:
        """(label, value) rows for a text report."""
        pct = f"{100 * self.recoveries / self.episodes:.1f} %" if self.episodes else "-"
        return [
            ("fidelity", f"{self.fidelity}, {self.devices} devices, seed {self.seed}"),
            ("cycles", str(self.cycles)),
            ("episodes", f"{self.episodes} ({', '.join(f'{k} {v}' for k, v in sorted(self.by_event.items()))})"),
            ("faults injected", str(self.faults_injected)),
            ("detected", str(self.detected)),
            ("located right", str(self.located_right)),
            ("located wrong", f"{self.located_wrong} ({self.wrong_diagnostics} diagnostics)"),
            ("not located", str(self.not_located)),
            ("corrupted latches", str(self.corrupted_latches)),
            ("recoveries", f"{self.recoveries} of {self.episodes} ({pct})"),
            ("stuck masters", str(self.stuck)),
            ("ring changes", str(self.ring_changes)),
            ("resets", str(self.resets)),
            ("data cycles latched", str(self.data_cycles_latched)),
            ("peak memory", f"{self.peak_memory_bytes / 1024:.1f} KiB"),
            ("memory growth after warm-up", f"{self.memory_growth_bytes / 1024:+.1f} KiB"),
        ]


# ----------------------------------------------------------------------------------------------------------------
# The two benches: what the campaign needs from a fidelity
# ----------------------------------------------------------------------------------------------------------------


class _Bench:
    """One fidelity's ring, master and truth: drives IN data, checks latches, injects and removes events."""

    ring: Ring
    master: Master

    def __init__(self, rng: random.Random) -> None:
        self.rng = rng
        self.expected_in: list[bytes] = []

    def size(self) -> int:
        raise NotImplementedError

    def specs(self) -> list[tuple[int, int]]:
        """(ID code, length code) of the devices, in ring order."""
        raise NotImplementedError

    def prepare(self) -> None:
        """New IN data in every device and OUT data in the master, before a cycle."""
        raise NotImplementedError

    def check(self, result: CycleResult) -> list[str]:
        """Latch checks after a cycle; descriptions of what was wrong."""
        raise NotImplementedError

    def table_matches(self) -> bool:
        config = self.master.config
        return config is not None and [(e.id_code, e.length_code) for e in config] == self.specs()


class _RingBench(_Bench):
    def __init__(self, rng: random.Random, devices: int) -> None:
        super().__init__(rng)
        self.initial = devices
        self.devices = [self.new_device() for _ in range(devices)]
        self.ring = Ring(list(self.devices))
        self.master = Master(self.ring)
        # Keyed by the device itself (never by id(): a removed device's id may be reused by an inserted one).
        self.latched: dict[PlainDevice, bytes] = {}
        self.resets: dict[PlainDevice, int] = {}

    def new_device(self) -> PlainDevice:
        return PlainDevice(self.rng.choice(_IDS), self.rng.choice(_USABLE))

    def plain(self) -> list[PlainDevice]:
        return [d for d in self.ring.devices if isinstance(d, PlainDevice)]

    def size(self) -> int:
        return len(self.ring.devices)

    def specs(self) -> list[tuple[int, int]]:
        return [(d.id_code, d.length_code) for d in self.plain()]

    def prepare(self) -> None:
        self.expected_in = []
        for k, device in enumerate(self.plain(), 1):
            device.set_inputs(self.rng.randbytes(device.size))
            self.expected_in.append(device.inputs)
            self.latched.setdefault(device, device.outputs)
            self.resets.setdefault(device, device.resets)
            if self.master.config is not None and k <= len(self.master.config):
                entry = self.master.entry(k)
                self.master.set_outputs(k, self.rng.randbytes(entry.data_bytes))

    def check(self, result: CycleResult) -> list[str]:
        problems: list[str] = []
        devices = self.plain()
        if result.ok and result.cycle is Cycle.DATA:
            for k, device in enumerate(devices, 1):
                if device.outputs != self.master.outputs(k):
                    problems.append(f"device {k} latched {device.outputs.hex()}, master sent "
                                    f"{self.master.outputs(k).hex()}")  # fmt: skip
                if self.master.inputs(k) != self.expected_in[k - 1]:
                    problems.append(f"master read {self.master.inputs(k).hex()} from device {k}, it sent "
                                    f"{self.expected_in[k - 1].hex()}")  # fmt: skip
        else:
            for k, device in enumerate(devices, 1):
                before = self.latched.get(device, device.outputs)
                was_reset = device.resets != self.resets.get(device, device.resets)
                if device.outputs != before and not (was_reset and device.outputs == bytes(device.size)):
                    problems.append(f"device {k} took over {device.outputs.hex()} in a {result.cycle.value} cycle "
                                    "that was not latched for it")  # fmt: skip
        self.latched = {device: device.outputs for device in devices}
        self.resets = {device: device.resets for device in devices}
        return problems


def _pin_config() -> DeviceConfig:
    return decode(_PIN_ROW.c, _PIN_ROW.mfp, clk_conf=_PIN_CLK_CONF)


def _expected_in(config: DeviceConfig, mfp: int) -> bytes:
    """IN data from the MFP input levels (Tables 3-1/3-2: In<k> on pin p is bit k, 3.2)."""
    word = sum(((mfp >> pin) & 1) << bit for bit, pin in config.in_bits)
    return word.to_bytes(config.data_bytes, "big")


def _expected_mfp(config: DeviceConfig, out: bytes) -> int:
    """MFP output levels from OUT data (Out<k> on pin p is bit k)."""
    word = int.from_bytes(out, "big")
    return sum(((word >> bit) & 1) << pin for bit, pin in config.out_bits)


class _PinBench(_Bench):
    def __init__(self, rng: random.Random, devices: int) -> None:
        from supi3.model.pinring import PinRing  # the pin level imports numpy-heavy models: only when asked
        from supi3.model.pins import Supi3Pins

        super().__init__(rng)
        self.config = _pin_config()
        self.chips = [Supi3Pins(self.config) for _ in range(devices)]
        self.pin_ring = PinRing(self.chips)
        self.pin_ring.idle(0.0002)  # power-up reset stretch
        self.master = Master(self.pin_ring, max_devices=devices)
        self.latched = [chip.chip.mfp_outputs for chip in self.chips]

    def size(self) -> int:
        return len(self.chips)

    def specs(self) -> list[tuple[int, int]]:
        return [(self.config.id_code, self.config.length_code)] * len(self.chips)

    def prepare(self) -> None:
        self.expected_in = []
        for k in range(1, len(self.chips) + 1):
            mfp = self.rng.getrandbits(16)
            self.pin_ring.set_input(k, "mfp_in", mfp)
            self.expected_in.append(_expected_in(self.config, mfp))
            if self.master.config is not None:
                self.master.set_outputs(k, self.rng.randbytes(self.master.entry(k).data_bytes))

    def check(self, result: CycleResult) -> list[str]:
        self.pin_ring.settle()  # the latch telegrams reach every chip
        problems: list[str] = []
        now = [chip.chip.mfp_outputs for chip in self.chips]
        if result.ok and result.cycle is Cycle.DATA:
            for k, outputs in enumerate(now, 1):
                if outputs != _expected_mfp(self.config, self.master.outputs(k)):
                    problems.append(f"chip {k} drives {outputs:04X}h, master sent {self.master.outputs(k).hex()}")
                if self.master.inputs(k) != self.expected_in[k - 1]:
                    problems.append(f"master read {self.master.inputs(k).hex()} from chip {k}, it sent "
                                    f"{self.expected_in[k - 1].hex()}")  # fmt: skip
        else:
            for k, (outputs, before) in enumerate(zip(now, self.latched, strict=True), 1):
                if outputs not in (before, _expected_mfp(self.config, bytes(self.config.data_bytes))):
                    problems.append(f"chip {k} changed its outputs in a cycle that was not latched")
        self.latched = now
        return problems


# ----------------------------------------------------------------------------------------------------------------
# Events
# ----------------------------------------------------------------------------------------------------------------


@dataclass
class _Episode:
    """One event: its name, whether it should fail cycles, its true position, and how to remove it."""

    event: str
    fault: bool
    position: int | None
    remove: Callable[[], None]
    diagnostics: list[Diagnostic] = field(default_factory=list)


def _noop() -> None:
    return None


def _line_fault(bench: _RingBench, event: str) -> Fault:
    rng = bench.rng
    n = bench.size()
    line = rng.randint(1, n + 1)
    cycles = None if rng.random() < PERSISTENT_SHARE else rng.randint(1, 4)
    data_len = wire.LOOPBACK_BYTES + sum(d.size for d in bench.plain())
    if event == "bitflip":
        return BitFlip(line, rng.randrange(wire.frame_bits(data_len)), cycles)
    if event == "truncate":
        return Truncate(line, rng.randrange(data_len), cycles)
    if event == "loopback":
        value = rng.getrandbits(16)
        return CorruptLoopback(line, value ^ 1 if value == wire.LOOPBACK_WORD else value, cycles)
    return DeadLine(line, cycles)


def _first_difference(before: list[tuple[int, int]], after: list[tuple[int, int]]) -> int:
    for k, (a, b) in enumerate(zip(before, after, strict=False), 1):
        if a != b:
            return k
    return min(len(before), len(after)) + 1


def _ring_event(bench: _RingBench, event: str, result: CampaignResult) -> _Episode:
    rng = bench.rng
    ring = bench.ring
    n = bench.size()
    if event in ("bitflip", "truncate", "loopback", "deadline"):
        fault = _line_fault(bench, event)
        ring.inject(fault)
        return _Episode(event, True, fault.segment, ring.clear_faults)
    if event in ("remove", "insert", "length"):
        before = bench.specs()
        # The ring size walks within RING_SIZE_SPREAD of its start, so memory can be compared over a long run.
        low, high = max(1, bench.initial // RING_SIZE_SPREAD), min(64, bench.initial * RING_SIZE_SPREAD)
        if (event == "remove" and n > low) or (event == "insert" and n >= high):
            del ring.devices[rng.randrange(n)]
        elif event in ("insert", "remove") and n < high:
            ring.devices.insert(rng.randint(0, n), bench.new_device())
        else:
            at = rng.randrange(n)
            old = bench.plain()[at]
            codes = [c for c in _USABLE if wire.data_bytes(c) != old.size]
            ring.devices[at] = PlainDevice(old.id_code, rng.choice(codes))  # a µP-mode chip rewriting SET
        result.ring_changes += 1
        return _Episode(event, True, _first_difference(before, bench.specs()), _noop)
    if event == "peripheral":
        at = rng.randrange(n)
        device = bench.plain()[at]
        device.set_peripheral_fault(True)

        def quit_fault() -> None:
            device.set_peripheral_fault(False)
            if bench.master.config is not None and device in ring.devices:
                bench.master.quit_peripheral_error(ring.devices.index(device) + 1)

        return _Episode(event, False, at + 1, quit_fault)
    return _reset_episode(bench, result)


def _pin_event(bench: _PinBench, event: str, result: CampaignResult) -> _Episode:
    if event == "vmon":
        at = bench.rng.randint(1, bench.size())
        bench.pin_ring.set_input(at, "vmon_ok", 0)
        return _Episode(event, True, at, lambda: bench.pin_ring.set_input(at, "vmon_ok", 1))
    return _reset_episode(bench, result)


def _reset_episode(bench: _Bench, result: CampaignResult) -> _Episode:
    start = bench.master.start()
    result.resets += 1
    episode = _Episode("reset", False, None, _noop)
    episode.diagnostics.extend(start.diagnostics)
    return episode


# ----------------------------------------------------------------------------------------------------------------
# The campaign
# ----------------------------------------------------------------------------------------------------------------


def run_campaign(config: CampaignConfig, progress: Callable[[CampaignResult], None] | None = None) -> CampaignResult:
    """Run a campaign and return what it found (see the module documentation).

    Parameters
    ----------
    config:
        Cycles, seed, ring size, fidelity and event mix.
    progress:
        Called after every episode with the result so far (for a live display), if given.
    """
    if not isinstance(config, CampaignConfig):
        raise fail("config", "a CampaignConfig", config)
    rng = random.Random(config.seed)
    result = CampaignResult(config.fidelity, config.devices, config.seed)
    weights = config.weights()
    events = [e for e, w in weights.items() if w > 0]
    chances = [weights[e] for e in events]
    tracing = tracemalloc.is_tracing()
    if not tracing:
        tracemalloc.start()
    tracemalloc.reset_peak()
    baseline: int | None = None
    try:
        bench: _Bench = _RingBench(rng, config.devices) if config.fidelity == "ring" else _PinBench(rng, config.devices)
        start = bench.master.start()
        result.cycles += 1
        if not start.ok:
            raise AssertionError(f"the campaign's ring does not start: {start.diagnostics}")

        def run(count: int, episode: _Episode | None) -> CycleResult | None:
            last = None
            for _ in range(count):
                if result.cycles >= config.cycles:
                    break
                bench.prepare()
                last = bench.master.cycle()
                result.cycles += 1
                result.data_cycles_latched += last.ok and last.cycle is Cycle.DATA
                for problem in bench.check(last):
                    result.corrupted_latches += 1
                    _example(result, f"cycle {result.cycles}: {problem}")
                if episode is not None:
                    episode.diagnostics.extend(last.diagnostics)
                bench.master.clear_diagnostics()  # read, so the master's memory stays flat
                bench.master.services.clear()
            return last

        while result.cycles < config.cycles:
            if baseline is None and result.cycles >= WARM_UP_SHARE * config.cycles:
                gc.collect()  # live memory only: cyclic garbage waiting for the collector is not growth
                baseline = tracemalloc.get_traced_memory()[0]
            run(rng.randint(*HEALTHY_CYCLES), None)
            if result.cycles >= config.cycles:
                break
            event = rng.choices(events, chances)[0]
            if isinstance(bench, _RingBench):
                episode = _ring_event(bench, event, result)
            else:
                assert isinstance(bench, _PinBench)
                episode = _pin_event(bench, event, result)
            result.episodes += 1
            result.by_event[event] = result.by_event.get(event, 0) + 1
            run(rng.randint(*HOLD_CYCLES), episode)
            episode.remove()
            recovered = False
            for _ in range(RECOVERY_CYCLES):
                last = run(1, episode) if result.cycles < config.cycles else _extra_cycle(bench, episode, result)
                if last is not None and last.ok and last.cycle is Cycle.DATA and bench.table_matches():
                    recovered = True
                    break
            _judge(episode, result)
            if recovered:
                result.recoveries += 1
            else:
                result.stuck += 1
                _example(result, f"cycle {result.cycles}: master stuck after {episode.event}: "
                                 f"{[d.detail for d in episode.diagnostics[-2:]]}")  # fmt: skip
                bench.master.start()
            if progress is not None:
                progress(result)
        gc.collect()
        current, peak = tracemalloc.get_traced_memory()
        result.peak_memory_bytes = peak
        result.memory_growth_bytes = current - (baseline if baseline is not None else current)
    finally:
        if not tracing:
            tracemalloc.stop()
    return result


def _extra_cycle(bench: _Bench, episode: _Episode, result: CampaignResult) -> CycleResult:
    """A recovery cycle beyond the campaign's budget: the last episode is judged to its end (not counted)."""
    bench.prepare()
    last = bench.master.cycle()
    for problem in bench.check(last):
        result.corrupted_latches += 1
        _example(result, f"recovery: {problem}")
    episode.diagnostics.extend(last.diagnostics)
    bench.master.clear_diagnostics()
    return last


def _judge(episode: _Episode, result: CampaignResult) -> None:
    """Classify an episode's diagnostics against its true position."""
    if episode.event == "peripheral":
        messages = [d for d in episode.diagnostics if d.code == MSG_PERIPHERAL_FAULT]
        wrong = [d for d in messages if d.location != episode.position]
        result.wrong_diagnostics += len(wrong)
        if wrong:
            result.located_wrong += 1
            _example(result, f"0BB1h at {wrong[0].location}, the device is at {episode.position}")
        return
    errors = [d for d in episode.diagnostics if d.code is None]
    if not episode.fault:
        # Resets: no error may be reported at all (a wrong location is one with no fault behind it).
        wrong = [d for d in errors if d.location is not None]
        result.wrong_diagnostics += len(wrong)
        if wrong:
            result.located_wrong += 1
            _example(result, f"after a reset: {wrong[0].detail} at {wrong[0].location}")
        return
    result.faults_injected += 1
    if not errors:
        return
    result.detected += 1
    wrong = [d for d in errors if d.location is not None and d.location != episode.position]
    right = [d for d in errors if d.location == episode.position]
    result.wrong_diagnostics += len(wrong)
    if wrong:
        result.located_wrong += 1
        _example(result, f"{episode.event} at {episode.position}: reported at {wrong[0].location} "
                         f"({wrong[0].kind.value}: {wrong[0].detail})")  # fmt: skip
    elif right:
        result.located_right += 1
    else:
        result.not_located += 1


def _example(result: CampaignResult, text: str) -> None:
    if len(result.examples) < 5:
        result.examples.append(text)


def format_result(result: CampaignResult) -> str:
    """A text report of one campaign."""
    rows = result.rows()
    width = max(len(label) for label, _ in rows)
    lines = [f"{label:<{width}}  {value}" for label, value in rows]
    lines.append(f"{'verdict':<{width}}  {'OK' if result.ok else 'GOALS MISSED'}")
    lines.extend(f"  ! {text}" for text in result.examples)
    return "\n".join(lines)


# ----------------------------------------------------------------------------------------------------------------
# Command line (``supi3 campaign`` and ``bench/fault_campaign.py`` are thin wrappers of these)
# ----------------------------------------------------------------------------------------------------------------


def parse_mix(text: str) -> dict[str, int]:
    """``"bitflip=4,reset=1"`` as a weight mapping (validated by :class:`CampaignConfig`): weights in ASCII decimal
    digits, each event once."""
    mix: dict[str, int] = {}
    for item in filter(None, (part.strip() for part in text.split(","))):
        event, sep, weight = (part.strip() for part in item.partition("="))
        try:  # int() refuses over 4,300 digits
            value = int(weight) if sep and weight.isascii() and weight.isdigit() else None
        except ValueError:
            value = None
        if value is None:
            raise fail("--mix", "EVENT=WEIGHT pairs separated by commas", item)
        if event in mix:
            raise fail("--mix", "EVENT=WEIGHT pairs naming each event once", text)
        mix[event] = value
    if not mix:
        raise fail("--mix", "EVENT=WEIGHT pairs separated by commas", text)
    return mix


def campaign_report(results: list[CampaignResult], as_json: bool) -> str:
    """Text or JSON report of campaigns."""
    if as_json:
        return json.dumps([r.as_dict() for r in results], indent=2)
    return "\n\n".join(format_result(r) for r in results)

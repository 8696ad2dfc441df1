"""Four defects today's hostile review (round 9, ``test_hostile9.py``) found and left: bus time frozen by a long idle
(A26: :data:`supi3.interbus.wire.MAX_BUS_TIME_S`, one check, :func:`supi3.interbus.wire.check_bus_time`, at every entry
that advances bus time: ``Ring``, ``PinRing``, ``OpticalRing``, the firmware bench's ``advance``); the master's
:attr:`~supi3.interbus.master.Master.processor_alarms` kept by ring position across a new configuration (A19: now
dropped with ``branch_status`` and ``mau_warnings``); ``supi3 campaign --fidelity both`` with a mix naming no event
of one fidelity ran that fidelity with its default mix (a silent guess, now refused by name, A27); and
``supi3 campaign --cycles`` without an upper bound (A27). Then the lead's pass over today's new entries:
``receiver.frame_start`` (BK-65) and ``wire.returned_frame`` (M29) took anything.

Every bad input is refused by name (which argument, which rule, which value); a refused call leaves no trace.
"""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3 import cli
from supi3.campaign import MAX_CYCLES, CampaignConfig, Fidelity
from supi3.config import decode
from supi3.errors import ArgumentError
from supi3.interbus import wire
from supi3.interbus.device import PlainDevice
from supi3.interbus.errors import InterbusArgumentError
from supi3.interbus.master import Master
from supi3.interbus.receiver import frame_start
from supi3.interbus.ring import Ring
from supi3.model.chip import Supi3
from supi3.model.pinring import PinRing
from supi3.model.pins import Supi3Pins
from supi3.optical.link import FibreLink
from supi3.optical.ring import OpticalRing
from supi3.sdk.bench import Bench

# -- A26: the bus time's maximum ------------------------------------------------------------------------------------


def test_a_cycle_moves_bus_time_by_whole_clocks_up_to_the_maximum() -> None:
    """``Ring.idle(1e300)`` froze bus time (a cycle added nothing to 1e300): now refused by name, and at A26's maximum
    a cycle still moves bus time by its clocks (so a watchdog or an idle timeout still expires)."""
    ring = Ring([PlainDevice(0xBF, 1)])
    master = Master(ring)
    assert master.start().ok
    with pytest.raises(InterbusArgumentError, match=r"seconds 1e\+300 at bus time .*A26"):
        ring.idle(1e300)
    ring.idle(wire.MAX_BUS_TIME_S - ring.now - 1.0)
    before = ring.now
    assert master.cycle().ok
    cycle_s = ring.now - before
    assert cycle_s > 0 and abs(cycle_s * 32e6 - round(cycle_s * 32e6)) < 0.05  # whole clocks of 32 MHz still


@pytest.mark.parametrize("entry", ["ring", "pin", "optical"])
def test_every_bus_refuses_an_idle_past_the_maximum_and_changes_nothing(entry: str) -> None:
    """One check (A26) at every bus: an idle past :data:`~supi3.interbus.wire.MAX_BUS_TIME_S` is refused by name
    (the pin level ran ``idle(1e300)`` for ever, one status telegram piece after another) and bus time stays."""
    bus: Ring | PinRing | OpticalRing
    if entry == "ring":
        bus = Ring([PlainDevice(0xBF, 1)])
    elif entry == "pin":
        bus = PinRing([Supi3Pins(decode("10000"))])
    else:
        bus = OpticalRing([Supi3(decode("10000", rf="00"))], [FibreLink(20.0)], seed=5)
    for seconds in (1e300, wire.MAX_BUS_TIME_S + 1.0):
        with pytest.raises(InterbusArgumentError, match=r"seconds .* past 1048576 s \(A26"):
            bus.idle(seconds)
    assert bus.now == 0.0


def test_a_cycle_and_a_reset_at_the_maximum_are_refused() -> None:
    """Past the maximum (reached by the cycle begun just before it) no cycle or reset starts: refused by name, the
    master's cycle raises before the ring changes anything."""
    ring = Ring([PlainDevice(0xBF, 1)])
    master = Master(ring)
    assert master.start().ok
    ring.idle(wire.MAX_BUS_TIME_S - ring.now)
    assert ring.now == wire.MAX_BUS_TIME_S
    assert master.cycle().ok  # begun at the maximum: it runs
    after = ring.now
    with pytest.raises(InterbusArgumentError, match=r"cycle <Cycle.DATA: .data.> \(Cycle\) at bus time .*A26"):
        master.cycle()
    with pytest.raises(InterbusArgumentError, match=r"reset 'INTERBUS reset' .*A26"):
        ring.reset()
    assert ring.now == after


@pytest.mark.parametrize("until", [1e300, wire.MAX_BUS_TIME_S * 2, math.inf], ids=repr)
def test_the_bench_refuses_to_advance_past_the_maximum(until: float) -> None:
    """The firmware bench's clock follows the same rule (A26): ``advance`` past it is refused, nothing runs."""
    bench = Bench()
    with pytest.raises(ValueError, match="until"):
        bench.advance(until)
    assert bench.now == 0.0 and bench.cycles == 0


# -- A19: the master's records by ring position ---------------------------------------------------------------------


def _alarm_chip(alarm: int) -> Supi3:
    """An RB Init-µP chip (as ``test_model_chip``'s management test) whose processor alarm register holds ``alarm``."""
    chip = Supi3(decode("10011", "1110"))
    assert chip.registers is not None
    chip.registers.cpu_write(13, 0x82)
    chip.registers.cpu_write(12, 0x01)
    chip.registers.cpu_write(7, alarm)  # 3.4.9: the processor alarm for the master
    return chip


def _settle(master: Master, ring: Ring) -> None:
    """The master's cycles until one is latched on a table as long as the ring (at most 8)."""
    for _ in range(8):
        if master.cycle().ok and master.config is not None and len(master.config) == len(ring.devices):
            return


def test_a_processor_alarm_read_before_a_ring_change_is_dropped_with_the_table() -> None:
    """Round 9's A19 left :attr:`Master.processor_alarms` out: the alarm read from position 2 still stood at position
    2 after position 1 was removed and the table rebuilt, now the position of another device."""
    chips = [_alarm_chip(0x10 + k) for k in range(3)]
    ring = Ring(list(chips))
    master = Master(ring)
    assert master.start().ok
    master.request_processor_alarm(2)
    _settle(master, ring)
    _settle(master, ring)
    assert master.processor_alarms == {2: 0x11}
    del ring.devices[0]
    _settle(master, ring)
    assert master.config is not None and len(master.config) == 2
    assert master.processor_alarms == {}


@given(st.lists(st.tuples(st.sampled_from(["request", "remove", "insert"]), st.integers(1, 4)), max_size=6))
@settings(max_examples=25, deadline=None)
def test_after_any_ring_change_no_record_names_another_device(steps: list[tuple[str, int]]) -> None:
    """Over any history of processor alarm requests, removals and insertions (each followed by the master's cycles
    until its table matches the ring again), every record kept by ring position (processor alarms) is the one of the
    device at that position now."""
    pool = [_alarm_chip(0x10 + k) for k in range(5)]
    alarm = {id(chip): 0x10 + k for k, chip in enumerate(pool)}
    ring = Ring(pool[:3])
    master = Master(ring)
    assert master.start().ok
    for step, at in steps:
        n = len(ring.devices)
        if step == "request":
            master.request_processor_alarm(min(at, n))
        elif step == "remove" and n > 1:
            del ring.devices[min(at, n) - 1]
        elif step == "insert" and n < len(pool):
            ring.devices.insert(min(at, n + 1) - 1, next(c for c in pool if c not in ring.devices))
        _settle(master, ring)
        _settle(master, ring)  # a request goes out in the next ID cycle and is answered in the one after (A18)
        assert master.config is not None and len(master.config) == len(ring.devices)
        for position, value in master.processor_alarms.items():
            assert value == alarm[id(ring.devices[position - 1])], (position, steps)


# -- A27: supi3 campaign's limits -----------------------------------------------------------------------------------


def _refused(capsys: pytest.CaptureFixture[str], argv: list[str]) -> str:
    """``main(argv)`` exits 2 with one line on stderr, no traceback; that line."""
    try:
        code = cli.main(argv)
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else 1
    out, err = capsys.readouterr()
    assert code == 2 and out == "" and "Traceback" not in err and err.count("\n") == 1 and err.endswith("\n"), err
    return err


@pytest.mark.parametrize(("argv", "expect"), [
    (["--cycles", str(10**20)], "--cycles must be an integer from 1 to 1000000 (A27: hours of run time), not 10"),
    (["--cycles", "1000001"], "--cycles must be an integer from 1 to 1000000"),
    (["--pin-cycles", "10001"], "--pin-cycles must be an integer from 1 to 10000 (A27"),
], ids=["cycles 10**20", "cycles 1000001", "pin-cycles 10001"])
def test_campaign_cycles_have_an_upper_bound(capsys: pytest.CaptureFixture[str], argv: list[str],
                                             expect: str) -> None:
    """``supi3 campaign --cycles 10**20`` ran until killed: now refused by name, one line, exit status 2 (A27); the
    API (:class:`~supi3.campaign.CampaignConfig`) follows the same limit."""
    assert expect in _refused(capsys, ["campaign", *argv])


@pytest.mark.parametrize(("fidelity", "cycles"), [("ring", 1_000_001), ("pin", 10_001)])
def test_campaign_config_refuses_cycles_past_the_bound(fidelity: Fidelity, cycles: int) -> None:
    with pytest.raises(ArgumentError, match=r"cycles must be an integer from 1 to \d+ \(A27"):
        CampaignConfig(cycles=cycles, fidelity=fidelity)
    assert CampaignConfig(cycles=MAX_CYCLES[fidelity], fidelity=fidelity).cycles == MAX_CYCLES[fidelity]


@pytest.mark.parametrize(("mix", "expect"), [
    ("bitflip=1", "--mix must be an event the pin campaign runs (vmon, reset) with --fidelity both, not 'bitflip=1'"),
    ("vmon=2", "--mix must be an event the ring campaign runs (bitflip, "),
], ids=["bitflip", "vmon"])
def test_campaign_mix_with_both_fidelities_names_an_event_of_each(capsys: pytest.CaptureFixture[str], mix: str,
                                                                   expect: str) -> None:
    """``--mix bitflip=1 --fidelity both`` ran the pin-level campaign with its default mix (a silent guess): now each
    fidelity needs an event of the mix it runs, else the mix is refused by name (A27)."""
    assert expect in _refused(capsys, ["campaign", "--fidelity", "both", "--mix", mix])


def test_campaign_mix_with_both_fidelities_is_split_between_them() -> None:
    """A mix naming events of both fidelities (``reset`` is in both) gives each its own, as documented."""
    args = cli.build_parser().parse_args(["campaign", "--mix", "bitflip=2,vmon=1,reset=1"])
    configs = cli._campaign_configs(args)
    assert [(c.fidelity, c.mix) for c in configs] == [("ring", {"bitflip": 2, "reset": 1}),
                                                       ("pin", {"vmon": 1, "reset": 1})]


@pytest.mark.parametrize("cycles", [10**20, 10**400], ids=["10**20", "10**400"])
def test_the_bench_refuses_a_run_of_more_cycles_than_fit_before_the_maximum(cycles: int) -> None:
    """``Bench.run(10**20)`` would run until the ring refused its cycle at the maximum, 10^8 cycles later: refused
    first, by name, nothing run (A26: no cycle is shorter than the shortest of a one-device ring)."""
    bench = Bench()
    refused = r"cycles (1\d*|<1329-bit integer>) at bus time 0.0 s would take it past 1048576 s"
    with pytest.raises(ValueError, match=refused):
        bench.run(cycles)
    assert bench.now == 0.0 and bench.cycles == 0


# ------------------------------------------------------------------------------------------------------------
# The lead's own pass over today's new entries: the frame finder of the pin level's bit errors (BK-65) and the
# master's frame from its data telegrams (M29) check what they are given
# ------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(("args", "name"), [
    ((None, 16, wire.Cycle.ID, 2), "samples"), (("0101", 16, wire.Cycle.ID, 2), "samples"),
    (([0, 2, 1], 16, wire.Cycle.ID, 2), "samples"), (([0.5, 1.0], 16, wire.Cycle.ID, 2), "samples"),
    (([1, 1], 15, wire.Cycle.ID, 2), "cpb"), (([1, 1], 16, "id", 2), "cycle"),
    (([1, 1], 16, wire.Cycle.ID, -1), "data_bytes"), (([1, 1], 16, wire.Cycle.ID, 1.5), "data_bytes"),
])  # fmt: skip
def test_frame_start_refuses_what_is_no_line_by_name(args: tuple[object, ...], name: str) -> None:
    with pytest.raises(ArgumentError) as caught:
        frame_start(*args)  # type: ignore[arg-type]
    assert caught.value.name.split("[")[0] == name  # a sample is named by its index: samples[1]


@pytest.mark.parametrize("telegrams", [None, "ab", b"ab", [1], [wire.LineReset(0), "telegram"]])
def test_returned_frame_refuses_what_is_no_telegram_by_name(telegrams: object) -> None:
    """Before, items of another type were dropped silently: ``returned_frame([1])`` was a dead line."""
    with pytest.raises(InterbusArgumentError, match="telegrams must be an iterable of telegrams"):
        wire.returned_frame(telegrams)  # type: ignore[arg-type]

"""The fibre-linked ring (supi3.optical.ring): initialization after an INTERBUS reset (manual 1.6, 1.6.1), length
measurement (1.6.1, OPT-1), online regulation and optical diagnostics (1.6.2), MAU reports (1.6.3), faults the master
locates, the diagnostic table of Figure 1-10 (3.4.12, 3.4.13); OPT-46, OPT-47."""

from __future__ import annotations

import itertools

import pytest

from supi3.config import decode
from supi3.errors import ArgumentError
from supi3.interbus import wire
from supi3.interbus.master import Master
from supi3.interbus.ring import ErrorKind
from supi3.model.chip import Supi3
from supi3.optical import length
from supi3.optical.link import Bend, Direction, Fibre, FibreLink, Pull
from supi3.optical.regulation import INIT_MAX_STEPS, INIT_STEP_BITS, MAX_LEVEL, Interface, Phase
from supi3.optical.ring import MauReport, OpticalRing, diagnostic_table, format_table

FWD, RET = Direction.FORWARD, Direction.RETURN
LENGTHS = (20.0, 40.0, 70.0, 10.0)


def _chips(n: int, rf: str = "00", clk_conf: str = "01") -> list[Supi3]:
    return [Supi3(decode("10000", rf=rf, clk_conf=clk_conf)) for _ in range(n)]


def _ring(lengths: tuple[float, ...] = LENGTHS, rf: str = "00", clk_conf: str = "01",
          **kwargs: object) -> tuple[OpticalRing, Master]:  # fmt: skip
    ring = OpticalRing(_chips(len(lengths), rf, clk_conf), [FibreLink(m) for m in lengths], **kwargs)  # type: ignore[arg-type]
    master = Master(ring)
    assert master.start().ok
    return ring, master


def _init_steps(level: int) -> int:
    """Steps of one direction's initialization that ends at ``level`` (1.6.1): lowerings down to ``level - 1``,
    then the "Light on" that raises it back; 13 lowerings end it at level 2 (OPT-11)."""
    return INIT_MAX_STEPS if level == 2 else MAX_LEVEL - level + 2


@pytest.mark.parametrize("clk_conf", ["01", "11"], ids=["500k", "2M"])
def test_initialization_settles_every_cable(clk_conf: str) -> None:
    chips = _chips(len(LENGTHS), clk_conf=clk_conf)
    ring = OpticalRing(chips, [FibreLink(m) for m in LENGTHS])
    assert Master(ring).start().ok
    assert chips[0].optical[Interface.IN].phase is Phase.FIXED  # the master is not a regulated partner
    assert chips[-1].optical[Interface.OUT].phase is Phase.OFF  # nothing behind the last chip
    for k in range(2, len(chips) + 1):
        cable = ring.links[k - 1]
        assert cable is not None
        up, down = chips[k - 2].optical[Interface.OUT], chips[k - 1].optical[Interface.IN]
        for tx, direction in ((up, FWD), (down, RET)):
            assert tx.phase is Phase.ONLINE and tx.enable and not tx.mau
            settled = cable.settled_level(direction, 0.0)
            assert settled is not None
            assert tx.level in (settled, settled + 1) or (settled == 1 and tx.level in (1, 2))
        count = cable.timer_count(ring.bit_rate)
        assert chips[k - 2].optical.length[0] == length.timer_code(count, ring.bit_rate, cable.medium)
    assert not any(chip.optical_holding for chip in chips)


def test_initialization_takes_its_steps_and_the_master_waits() -> None:
    chips = _chips(len(LENGTHS))
    ring = OpticalRing(chips, [FibreLink(m) for m in LENGTHS])
    ring.reset()
    levels = [chips[k - 2].optical[Interface.OUT].level for k in range(2, len(chips) + 1)]
    levels += [chips[k - 1].optical[Interface.IN].level for k in range(2, len(chips) + 1)]
    steps = sum(map(_init_steps, levels)) + 1  # + chip 1's incoming interface: one step without a response
    expected = (wire.reset_bits(len(chips)) + steps * INIT_STEP_BITS) / ring.bit_rate
    assert ring.now == pytest.approx(expected)
    assert [len(h) for h in ring.history] == [1] * len(chips)  # one sample at the end of the initialization


def test_unregulated_and_diagnostic_partners() -> None:
    """A copper-mode chip (RF = 11) and a diagnostics-mode chip (RF = 01) give no regulation response: the
    regulated transmitter facing them falls back to maximum power (1.6.1)."""
    chips = [Supi3(decode("10000", rf=rf)) for rf in ("00", "01", "00", "11")]
    ring = OpticalRing(chips, [FibreLink(20.0) for _ in chips])
    master = Master(ring)
    assert master.start().ok
    assert chips[0].optical[Interface.OUT].phase is Phase.FIXED  # partner in diagnostics mode
    assert chips[1].optical[Interface.OUT].phase is Phase.DIAGNOSTIC
    assert chips[1].optical[Interface.IN].phase is Phase.DIAGNOSTIC
    assert chips[2].optical[Interface.IN].phase is Phase.FIXED  # partner in diagnostics mode
    assert chips[2].optical[Interface.OUT].phase is Phase.FIXED  # copper partner
    assert all(tx.phase is Phase.OFF for tx in chips[3].optical.transmitters)
    rows = diagnostic_table(ring, master)
    assert [(r.forward_quality, r.return_quality, r.forward_level) for r in rows] == [
        ("unregulated", "unmonitored", MAX_LEVEL), ("unmonitored", "unregulated", MAX_LEVEL),
        ("unregulated", "unregulated", MAX_LEVEL)]  # fmt: skip


def test_diagnostics_mode_warns_on_the_receiving_interface() -> None:
    """OPT-7: in optical diagnostics mode a falling reserve sets the MAU warning of the receiving interface."""
    chips = _chips(3, rf="01")
    cables = [FibreLink(20.0), FibreLink(70.0), FibreLink(20.0)]
    ring = OpticalRing(chips, cables)
    master = Master(ring)
    assert master.start().ok
    cables[1].add(Bend(ring.now + 0.01, 0.02, 5.0, FWD))
    for _ in range(200):
        assert master.cycle().ok
    on_off = [(r.ring_position, r.interface, r.on) for r in ring.reports]
    assert on_off == [(2, Interface.IN, True), (2, Interface.IN, False)]


def test_bend_raises_the_level_and_warns() -> None:
    ring, master = _ring()
    cable = ring.links[2]
    assert cable is not None
    before = ring.chips[1].optical[Interface.OUT].level
    start = ring.now + 0.02
    cable.add(Bend(start, 0.05, 4.0, FWD))
    for _ in range(600):
        assert master.cycle().ok  # regulation keeps the light in: no cycle fails
    samples = ring.history[2]
    during = [s.forward_level for s in samples if start + 0.02 < s.time_s < start + 0.05]
    assert during and set(during) == {MAX_LEVEL}
    assert samples[-1].forward_level == before
    assert {s.return_level for s in samples} == {ring.chips[2].optical[Interface.IN].level}  # the other fibre
    assert [(r.ring_position, r.interface, r.on) for r in ring.reports] == [(2, Interface.OUT, True),
                                                                            (2, Interface.OUT, False)]
    assert all(isinstance(r, MauReport) and start <= r.time_s for r in ring.reports)


def test_rises_are_faster_than_falls() -> None:
    """Figure 1-12: one level up per test, one level down per two tests (OPT-6)."""
    ring, master = _ring((20.0, 30.0))
    cable = ring.links[1]
    assert cable is not None
    start = ring.now + 0.005
    cable.add(Bend(start, 0.03, 5.0, FWD))
    for _ in range(400):
        master.cycle()
    levels = [(s.time_s, s.forward_level) for s in ring.history[1]]
    ups = [t for (t, a), (_, b) in itertools.pairwise(levels) if b > a]
    downs = [t for (t, a), (_, b) in itertools.pairwise(levels) if b < a]
    assert len(ups) == len(downs) == 5
    assert ups[-1] - ups[0] < (downs[-1] - downs[0]) / 1.5


def test_pulled_connector_is_located_and_the_ring_recovers() -> None:
    ring, master = _ring()
    cable = ring.links[2]
    assert cable is not None
    start = ring.now + 0.01
    cable.add(Pull(start, 0.02))
    found = []
    for _ in range(200):
        result = master.cycle()
        found += [d for d in result.diagnostics if d.location is not None]
    assert found and all(d.kind is ErrorKind.DEAD_LINE and d.location == 3 and d.device == "3.0" for d in found)
    assert master.cycle().ok and ring.now > start + 0.02
    assert master.start().ok  # Alarm Stop: initialized again
    assert all(chip.optical[Interface.IN].phase is Phase.ONLINE for chip in ring.chips[1:])


def test_diagnostic_table_of_figure_1_10() -> None:
    ring, master = _ring((20.0, 40.0, 60.0), record=False)
    lines = format_table(diagnostic_table(ring, master))
    assert lines[0].split() == ["Path", "Forward", "path", "Return", "path", "PFor", "PReturn", "Dist.", "Medium"]
    assert lines[1].startswith("1.0<->2.0  optimal")
    assert "37.5m" in lines[1]  # 40 m at 500 kbit/s: 12.5 m steps (OPT-1)
    assert "(of 15)" in lines[1] and lines[2].endswith("polymer")
    hcs = OpticalRing(_chips(2), [None, FibreLink(300.0, Fibre.HCS)])
    Master(hcs).start()
    row = diagnostic_table(hcs)[0]
    assert row.path == "1.0<->2.0" and row.length_m == 300.0 and row.medium is length.Medium.POLYMER  # OPT-3
    glass = OpticalRing(_chips(2), [None, FibreLink(2000.0, Fibre.GLASS)])
    Master(glass).start()
    assert diagnostic_table(glass)[0].cells()[-2:] == ("2000m", "glass")


def test_arguments_are_checked() -> None:
    chips = _chips(2)
    for args, name in (((chips, [FibreLink(1.0)]), "links"), (([], []), "chips"), ((chips, "ab"), "links"),
                       (([chips[0], 3], [None, None]), "chip at ring position 2"),
                       ((chips, [None, 3]), "link into chip 2"),
                       (([chips[0], Supi3(decode("10000", clk_conf="11"))], [None, None]), "chips")):  # fmt: skip
        with pytest.raises(ArgumentError, match=rf"^{name} must be"):
            OpticalRing(*args)
    ring = OpticalRing(chips, [None, None])
    with pytest.raises(ArgumentError, match=r"^seed must be"):
        OpticalRing(chips, [None, None], seed=1.5)  # type: ignore[arg-type]
    with pytest.raises(ArgumentError, match=r"^seconds must be"):
        ring.idle(-1.0)
    with pytest.raises(ArgumentError, match=r"^k must be"):
        ring.dark(3)
    with pytest.raises(ArgumentError, match=r"^ring must be"):
        diagnostic_table(3)  # type: ignore[arg-type]

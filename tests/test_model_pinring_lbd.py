"""A pin-level ring (supi3.model.pinring.PinRing) of chips in the LBD modes (manual 2.2.2, Table 2-5): behind every
break of the forward or the return line, the chips' counter telegram blocks bring the master the count that the
transaction level's ``ring.lbd_count`` gives (BK-6); and the master's ring-delay allowance (A11) counts the LBD-MR
return lines' repeaters (M17), so a master runs cycles over LBD-MR chips as over any others, in the same time as at
transaction level (BK-55)."""

from __future__ import annotations

import pytest

from supi3 import tables
from supi3.config import DeviceConfig, Interface, decode
from supi3.interbus import wire
from supi3.interbus.master import Master
from supi3.interbus.ring import BranchKind, Ring, lbd_count
from supi3.interbus.wire import Cycle
from supi3.model.chip import Supi3
from supi3.model.pinring import PinRing
from supi3.model.pins import Supi3Pins
from support import counter_counts

FAST = tables.clk_conf_for(2_000_000)
KINDS = {BranchKind.LBD_MR: Interface.LBD_MR, BranchKind.LBD_OR: Interface.LBD_OR}


def _config(interface: Interface) -> DeviceConfig:
    row = next(r for r in tables.MODE_ROWS if r.function == f"{interface.value}, 8 IN/8 OUT")
    return decode(row.c, row.mfp, clk_conf=FAST)


@pytest.mark.parametrize("kind", list(KINDS))
@pytest.mark.parametrize("m", [1, 2, 3])
def test_every_break_brings_the_master_the_count_of_lbd_count(kind: BranchKind, m: int) -> None:
    """Every single break of a branch of ``m`` chips (the forward line into chip k, the return line into chip c
    from chip c + 1) while the master sends idle status telegrams: the last counter telegrams the master receives
    carry ``lbd_count``'s count; without a break none arrives."""
    config = _config(KINDS[kind])
    cpb = wire.clocks_per_bit(config.bit_rate)
    breaks = [((k,), ()) for k in range(1, m + 1)] + [((), (c,)) for c in range(1, m)] + [((), ())]
    for forward, back in breaks:
        ring = PinRing([Supi3Pins(config) for _ in range(m)])
        for k in forward:
            ring.cut(k, True)
        for c in back:
            ring.cut(c, False)
        ring.run_levels(wire.status_levels(Cycle.DATA, False, 60))
        counts = [count for count in counter_counts(ring.returned, cpb) if count is not None]
        expected = lbd_count(kind, m, forward, back)
        assert counts[-3:] == ([expected] * 3 if expected is not None else []), (forward, back, counts)


def test_a_master_runs_cycles_over_lbd_mr_chips() -> None:
    """The return line of an LBD-MR chip is repeated 3 bit periods later (its counter block): the ring delay the
    master allows for counts 2 repeaters per LBD-MR chip, so ID and data cycles come back whole and latch."""
    chips = [Supi3Pins(_config(Interface.LBD_MR)) for _ in range(3)]  # 3 repeaters short without M17: no latch
    ring = PinRing(chips)
    assert ring.repeaters == 6 and PinRing([Supi3Pins(_config(Interface.LBD_OR))]).repeaters == 1
    master = Master(ring, locate=False, max_devices=4)
    assert master.start().ok
    master.set_outputs(2, b"\x5a")
    assert master.data_cycle().ok
    ring.settle()
    assert chips[1].chip.mfp_outputs != 0 and all(chip.chip.events["VALID"] == 1 for chip in chips)


@pytest.mark.parametrize("interfaces", [(Interface.LBD_MR,) * 2, (Interface.LBD_MR,) * 3,
                                        (Interface.LBD_MR, Interface.LBD_OR, Interface.LBD_MR)])  # fmt: skip
def test_a_ring_of_lbd_chips_takes_the_same_time_at_both_fidelities(interfaces: tuple[Interface, ...]) -> None:
    """BK-55: the transaction level counts an LBD-MR chip's return repeater in its ring delay as the pin level does
    (before, 2 status telegrams a cycle short with 2 or 3 of them): the INTERBUS reset and every ID and data cycle
    end on the same clock at both fidelities, ``wire.cycle_bits`` with the ring's return repeaters."""
    configs = [_config(interface) for interface in interfaces]
    rings: list[Ring | PinRing] = [Ring([Supi3(c) for c in configs], bit_rate=2_000_000),
                                   PinRing([Supi3Pins(c) for c in configs])]  # fmt: skip
    loops = sum(interface is Interface.LBD_MR for interface in interfaces)
    n = len(interfaces)
    ends = []
    for ring in rings:
        master = Master(ring, locate=False, max_devices=4)
        clocks = []
        assert master.start().ok
        clocks.append(round(ring.now * tables.CLOCK_HZ))
        for _ in range(3):
            assert master.data_cycle().ok
            clocks.append(round(ring.now * tables.CLOCK_HZ))
        ends.append(clocks)
    assert ends[0] == ends[1]
    cpb = wire.clocks_per_bit(2_000_000)
    assert ends[0][-1] - ends[0][-2] == wire.cycle_bits(n, n, loops) * cpb

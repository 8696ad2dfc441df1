"""Branch recognition of a bus terminal module at both fidelities (manual 2.1.1, Table 2-2, Tables 2-7 to 2-9;
BK-37, BK-41..BK-43): for BK-RB, BK-LB and BK-LBD, every row of Table 2-9 (RF = 00, 01, 10, 11 with LBST = 0 and 1)
with the branch empty (nothing attached: DI3 pulled up) and populated (one device), a master on the pin-level ring
(:class:`~supi3.model.pinring.PinRing` with :class:`~supi3.model.pinring.PinBranch`) and one on the transaction-level
ring (:class:`~supi3.interbus.ring.Ring` with :class:`~supi3.interbus.ring.Branch`) of the same tree see the same
thing: whether the start succeeds and the diagnostics it reports, the configuration (numbers, ID codes, data
lengths), the process data IN, and every chip's RD, LD and E LEDs. A branch present by LBST with nothing attached
breaks the ring at both (BK-43); an empty branch that needs a device's answer (RF = 11, or fibre with LBST = 0) is
not present and the ring runs through the BK.
"""

from __future__ import annotations

import pytest

from supi3.interbus.master import Master
from supi3.interbus.ring import Branch, BranchKind, DeadLine, ErrorKind, Ring
from supi3.model.chip import Supi3
from supi3.model.pinring import PinBranch, PinRing
from supi3.model.pins import Supi3Pins
from supi3.terminal import RF_CODES, branch_present
from test_model_pinring_tree import INPUTS, LBST, ROWS, _bk, _config, view

KINDS = [BranchKind.REMOTE, BranchKind.LOCAL, BranchKind.LBD_MR]
"""BK-RB, BK-LB and BK-LBD (Table 2-7)."""
CYCLES = 4
"""Master cycles after the start, each compared."""


def tl_ring(kind: BranchKind, rf: str, lbst: bool, m: int) -> tuple[Ring, list[Supi3]]:
    """RB device, BK (``rf``, ``lbst``) with ``m`` branch devices of ``kind``, RB device; and every chip in physical
    order."""
    bk = Supi3(_bk(kind, rf))
    bk.set_mfp_inputs(LBST if lbst else 0)
    first, last = Supi3(_config(ROWS[BranchKind.REMOTE])), Supi3(_config(ROWS[BranchKind.REMOTE]))
    branch = [Supi3(_config(ROWS[kind])) for _ in range(m)]
    for chip, value in zip([first, *branch, last], [0x5A, *INPUTS], strict=False):
        chip.set_mfp_inputs(value)
    return Ring([first, Branch(bk, branch, kind), last], bit_rate=2_000_000), [first, bk, *branch, last]


def pin_ring(kind: BranchKind, rf: str, lbst: bool, m: int) -> tuple[PinRing, list[Supi3]]:
    """The pin-level twin of :func:`tl_ring`."""
    chips = [Supi3Pins(_config(ROWS[kind])) for _ in range(m)]
    ring = PinRing([Supi3Pins(_config(ROWS[BranchKind.REMOTE])), PinBranch(Supi3Pins(_bk(kind, rf)), chips, kind),
                    Supi3Pins(_config(ROWS[BranchKind.REMOTE]))])  # fmt: skip
    ring.set_input(2, "mfp_in", LBST if lbst else 0)
    ring.set_input(2, "rbst_ext", 1)  # RF = 10: the board tells the BK that a device follows on its remote bus (M5)
    for position, value in zip([1, *range(3, m + 4)], [0x5A, *INPUTS], strict=False):
        ring.set_input(position, "mfp_in", value)
    return ring, [pins.chip for pins in ring.devices]


View = tuple[list[tuple[str, int, int]], list[bytes]]
Leds = list[tuple[bool, bool, bool]]
Step = tuple[bool, list[ErrorKind], View | None, Leds]


def history(ring: Ring | PinRing, chips: list[Supi3]) -> list[Step]:
    """Start a master on ``ring`` and cycle it: per step, whether it latched, the diagnostics' kinds, the master's
    view (configuration and process data IN, ``None`` without a configuration) and every chip's RD, LD and E (DG-5,
    BK-11)."""
    master = Master(ring, locate=False, max_devices=8)
    steps: list[Step] = []
    for k in range(CYCLES + 1):
        result = master.start() if k == 0 else master.cycle()
        leds = [(leds.rd, leds.ld, leds.e) for leds in (chip.diagnostic_outputs for chip in chips)]
        seen = view(master) if master.config is not None else None
        steps.append((result.ok, [d.kind for d in result.diagnostics], seen, leds))
    return steps


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("rf", RF_CODES)
def test_every_row_of_table_2_9_is_the_same_at_both_fidelities(kind: BranchKind, rf: str) -> None:
    """LBST 0/1 x empty/populated: the start, every cycle after it and every chip's RD/LD/E agree; a branch present
    without a device's answer (RF = 10 or fibre with LBST = 1, nothing attached) breaks the ring at both (the master
    reports a dead line), an empty branch that needs the answer is left out at both, a populated branch present by
    Table 2-9 joins the data path at both (BK-41, BK-43)."""
    for lbst in (False, True):
        for m in (0, 1):
            tl = history(*tl_ring(kind, rf, lbst, m))
            pin = history(*pin_ring(kind, rf, lbst, m))
            assert pin == tl, (lbst, m)
            present = branch_present(rf, lbst, m > 0)
            ok, _, seen, leds = tl[-1]
            if present and m == 0:
                assert not tl[0][0] and tl[0][1] == [ErrorKind.DEAD_LINE] and seen is None
            else:
                assert tl[0][0] and ok and seen is not None and len(seen[0]) == 3 + (m if present else 0)
                assert leds[1][1:] == (False, False)  # the BK's LD and E dark


def test_a_branch_cut_before_the_first_start_is_the_recorded_limit() -> None:
    """BK-37's limit, pinned down: a BK-LB branch whose forward line into its second device is cut before the master's
    first start returns the idle level to DI3, so the pin-level BK never recognises it and the ring runs through the
    BK; the transaction-level ring recognised the populated branch when it was built and reports the break."""
    pin, _ = pin_ring(BranchKind.LOCAL, "11", True, 2)
    pin.cut(4, True)
    tl, _ = tl_ring(BranchKind.LOCAL, "11", True, 2)
    tl.inject(DeadLine(4))
    pin_master, tl_master = Master(pin, locate=False, max_devices=8), Master(tl, locate=False, max_devices=8)
    assert pin_master.start().ok and pin_master.config is not None and len(pin_master.config) == 3
    result = tl_master.start()
    assert not result.ok and result.diagnostics[0].kind is ErrorKind.DEAD_LINE

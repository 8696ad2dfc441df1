"""The fibre-linked ring as a tree (manual 2.4, Figure 1-10; docs/assumptions/optical.md OPT-54): a bus terminal
module's branch interface linked to its branch's first device, initialization of branch paths, the branch length
(read 9), the diagnostic table's branch rows, fibre faults in a branch on the tree's lines (BK-1, BK-10) located
exactly in an LBD branch (BK-7), MAUWS at the master and FO3."""

from __future__ import annotations

import pytest

from supi3.config import decode
from supi3.interbus.master import Master
from supi3.interbus.ring import Branch, BranchKind, ErrorKind
from supi3.model.chip import Supi3
from supi3.optical import length
from supi3.optical.link import Bend, Direction, FibreLink, Pull
from supi3.optical.regulation import MAX_LEVEL, Interface, Phase, registers
from supi3.optical.ring import OpticalRing, diagnostic_table
from supi3.regmap.registers import OPTICAL_LENGTH_WIDTH, POWER_BRANCH_LSB, POWER_LEVEL_WIDTH

LENGTHS = (15.0, 30.0, 20.0, 40.0, 10.0, 25.0, 50.0)
"""Cables into 1.0, 2.0, the BK 3.0, its LBD-MR devices 3.1 to 3.3 (the first from the BK's branch interface), and
4.0 (from the BK's outgoing interface)."""
BK_AT = 3
BRANCH = 3


def chip(straps: str = "10000", rf: str = "00") -> Supi3:
    return Supi3(decode(straps, rf=rf))


def tree(lengths: tuple[float, ...] = LENGTHS, kind: BranchKind = BranchKind.LBD_MR,
         ) -> tuple[OpticalRing, Master, Supi3, list[Supi3]]:  # fmt: skip
    bk = chip({BranchKind.LBD_MR: "00010", BranchKind.LBD_OR: "00010", BranchKind.REMOTE: "00000",
               BranchKind.LOCAL: "00001"}[kind])  # fmt: skip
    straps = {BranchKind.LBD_MR: "11000", BranchKind.LBD_OR: "11100", BranchKind.LOCAL: "01000",
              BranchKind.REMOTE: "10000"}[kind]  # fmt: skip
    branch = [chip(straps) for _ in range(BRANCH)]
    ring = OpticalRing([chip(), chip(), Branch(bk, branch, kind), chip()], [FibreLink(m) for m in lengths])
    master = Master(ring)
    assert master.start().ok
    return ring, master, bk, branch


def settle(master: Master, cycles: int = 30) -> None:
    for _ in range(cycles):
        master.cycle()


def test_initialization_regulates_the_branch_and_the_table_has_its_rows() -> None:
    ring, master, bk, branch = tree()
    settle(master)
    assert [e.number for e in master.config or ()] == ["1.0", "2.0", "3.0", "3.1", "3.2", "3.3", "4.0"]
    for interface in Interface:
        assert bk.optical[interface].phase is Phase.ONLINE and bk.optical[interface].enable
    assert branch[-1].optical[Interface.OUT].phase is Phase.OFF  # the branch's last device sends nothing on
    cable = ring.links[BK_AT]
    assert cable is not None
    read9 = registers(bk.optical)[1]
    assert read9 & ((1 << OPTICAL_LENGTH_WIDTH) - 1) == length.timer_code(
        cable.timer_count(ring.bit_rate), ring.bit_rate, cable.medium)
    rows = diagnostic_table(ring, master)
    ends = [(0, 1), (1, 2), (2, 3), (3, 4), (4, 5), (5, 6), (3, 7)]  # 4.0's cable comes from the BK
    assert [ring.ends(k) for k in range(1, len(LENGTHS) + 1)] == ends
    assert [r.path for r in rows] == ["1.0<->2.0", "2.0<->3.0", "3.0<->3.1", "3.1<->3.2", "3.2<->3.3", "3.0<->4.0"]
    branch_row = rows[2]
    level = registers(bk.optical)[3] >> POWER_BRANCH_LSB & ((1 << POWER_LEVEL_WIDTH) - 1)
    assert branch_row.forward_level == level == bk.optical[Interface.BRANCH].level
    assert branch_row.return_level == branch[0].optical[Interface.IN].level
    assert rows[-1].forward_level == bk.optical[Interface.OUT].level
    assert all(r.forward_quality == r.return_quality == "optimal" for r in rows)


def test_a_branch_switched_off_leaves_the_table_and_its_faults_sleep() -> None:
    ring, master, _, _ = tree(kind=BranchKind.LOCAL)
    settle(master, 5)
    master.switch_branch("3.0", False)
    settle(master, 5)
    assert [r.path for r in diagnostic_table(ring, master)] == ["1.0<->2.0", "2.0<->3.0", "3.0<->4.0"]
    for index in range(BK_AT, BK_AT + BRANCH):
        link = ring.links[index]
        assert link is not None and ring.ends(index + 1) is None
        link.add(Pull(start_s=ring.now, duration_s=None))
    for _ in range(20):
        assert master.cycle().ok


@pytest.mark.parametrize("k", range(1, BRANCH + 1))
@pytest.mark.parametrize("direction", [Direction.FORWARD, Direction.RETURN, None], ids=["fwd", "ret", "pull"])
def test_lbd_branch_fibre_breaks_are_located_on_the_exact_line(k: int, direction: Direction | None) -> None:
    """The cable into branch device k: its forward fibre is the forward line into k, its return fibre the return
    line into device k - 1 (the BK for k = 1); a pulled connector breaks both, and the count names the return line,
    the last break on the data path (BK-6, BK-7)."""
    ring, master, _, _ = tree()
    settle(master, 4)
    link = ring.links[BK_AT + k - 1]
    assert link is not None
    link.add(Bend(start_s=ring.now, duration_s=None, loss_db=60.0, direction=direction))
    result = master.cycle()
    assert not result.ok
    (found,) = result.diagnostics
    assert found.kind is ErrorKind.DEAD_LINE
    back = direction is not Direction.FORWARD
    assert (found.location, found.return_line) == (BK_AT + k - back, back)
    assert "device-oriented local-bus diagnostics" in found.detail


def test_a_bent_branch_fibre_warns_at_the_branch_interface_and_lights_fo3() -> None:
    ring, master, bk, _ = tree((15.0, 30.0, 20.0, 75.0, 10.0, 25.0, 50.0))
    settle(master)
    assert bk.optical[Interface.BRANCH].level < MAX_LEVEL and not bk.diagnostic_outputs.fo[2]
    link = ring.links[BK_AT]
    assert link is not None
    link.add(Bend(start_s=ring.now, duration_s=None, loss_db=4.0))
    settle(master, 80)
    assert bk.optical[Interface.BRANCH].mau and bk.diagnostic_outputs.fo[2]
    warnings = [(d.device, d.mau) for d in master.diagnostics if d.kind is ErrorKind.MAU_WARNING]
    assert ("3.0", ("MAUWS", True)) in warnings and ("3.1", ("MAUWH", True)) in warnings
    assert master.mau_warnings[BK_AT] == (False, False, True)


def test_each_bk_interface_has_its_own_budget() -> None:
    """OPT-56 (1.6.1: an interface's initialization takes 6 ms at most): on 1 m cables at 500 kbit/s each of the
    BK's transmitters takes all 13 steps (2.5 ms each, 7.5 ms in a row), yet every one ends regulated; with one 6 ms
    budget for the chip its outgoing interface would fall back to FIXED."""
    ring, _, bk, _ = tree(lengths=(1.0,) * len(LENGTHS))
    assert ring.bit_rate == 500_000
    assert [bk.optical[i].phase for i in Interface] == [Phase.ONLINE] * 3
    assert [bk.optical[i].level for i in Interface] == [MAX_LEVEL - 13] * 3
    assert all(c.optical[Interface.IN].phase is Phase.ONLINE for c in ring.chips[1:])  # the master is not regulated

"""A hostile, random differential test of the firmware path (issue #13; docs/assumptions/mcu.md MCU-59 to 61, 63, 74).

``mcu/scripted.c`` is a firmware whose behaviour is data: its ``fw_setup`` runs a script of driver calls, raw frames
and deliberately bad SPI1 use that the test writes into its ``fw_script`` (flash) before the first run, and keeps
every result byte and error code in ``fw_log``. Hypothesis writes random scripts (derandomized by the conftest
profile), every example runs on ONE binary per core (and one Intel build), and each script gives an
:class:`Outcome` (the log, the chip's registers, the violations by rule, the master's cycles and IN data, the
interface's phase):

- (a) the binary on the board at transaction level against the same script through the Python driver on the
  transaction-level firmware bench (:func:`run_on_bench`), both chips pedantic, on both cores and in Intel mode;
- (b) short scripts before the master's start, and scripts served after the first VALID interrupt, on the binary at
  transaction level against pin level.

:func:`run_script` takes the board's options as keywords, so a further board flag (another per-byte path, say) is
one more comparison: ``run_script(elf, script, flag=False) == run_script(elf, script, flag=True)``.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, replace
from enum import IntEnum
from pathlib import Path
from typing import Final

import pytest
from hypothesis import Phase as Stage
from hypothesis import example, given, settings
from hypothesis import strategies as st

from supi3.interbus.errors import InterbusError
from supi3.interbus.master import Master
from supi3.mcu import build as mcu_build
from supi3.mcu.board import MISO_IDLE, Board
from supi3.mcu.pins import released, ss_high_byte
from supi3.model.registers import InterfaceViolationError, RegisterFile
from supi3.regmap import REGISTER_MAP
from supi3.regmap.core import AccessDirection
from supi3.regmap.registers import encode_command
from supi3.sdk.bench import Bench, Firmware
from supi3.sdk.driver import DriverError, ErrorCode, Mode, Supi3Driver
from supi3.spi.upif import UpifProtocol

pytestmark = pytest.mark.skipif(mcu_build.toolchain_missing() is not None, reason=str(mcu_build.toolchain_missing()))

SOURCE: Final = Path(__file__).parent / "mcu" / "scripted.c"
STEPS: Final = 48
"""scripted.c's SCRIPT_STEPS."""
LOG_BYTES: Final = 6
"""scripted.c's LOG_BYTES: ran, error code, four result bytes."""
WAIT_STEP_US: Final = 4
WAIT_POLLS_PER_UNIT: Final = 250
LATCH_POLLS_PER_UNIT: Final = 10_000
"""scripted.c's poll bounds: a wait of argument a polls /IRQ at most (a + 1) * 250 times, 4 µs apart, a timed read
the I/O pin at most (a + 1) * 10,000 times without a pause."""
SPI_BIT_S: Final = 64 / 48e6
"""One SCLK period of the board port (BR = 5 at 48 MHz): what a byte with /SS cut short counts its edges in."""
HALF_PERIOD: Final = 8
"""``SS_CUT``'s c for a cut half an SCLK period after the b-th edge (8 spin units of 4 core clocks, MCU-61)."""
CYCLE_TIME_S: Final = 2e-3
"""The master's cycle time on both sides: data cycles with long idle gaps between them, so that the two firmware
clocks (the board's instructions, the bench's Table 3-7 byte times, FW-1) rarely straddle a bus event (MCU-60)."""


class Op(IntEnum):
    """scripted.c's OP_* codes."""

    END = 0
    INIT = 1
    CONFIG = 2
    READ = 3
    WRITE = 4
    EXCHANGE = 5
    BLOCK = 6
    IRQ_ENABLE = 7
    IRQ_SERVICE = 8
    SAS_INIT = 9
    DELAY = 10
    WAIT_IRQ = 11
    POLL_IO = 12
    RAW = 13
    SS_HIGH = 14
    SS_CUT = 15
    LATCH = 16


Step = tuple[int, int, int, int]
"""One step: the operation and its arguments a, b, c."""


@dataclass(frozen=True)
class Outcome:
    """What a script left: per step (error code as a byte, result bytes), the chip's registers and the interface
    violations by rule (a multiset: the two fidelities may find them in another order)."""

    log: tuple[tuple[int, ...], ...]
    registers: tuple[tuple[str, int], ...]
    violations: tuple[tuple[str, int], ...]
    cycles: int
    """Master cycles finished at the end: the first cycle that ended after the script, and one more."""
    inputs: bytes | None
    """The master's IN data of the chip from the last data cycle (``None``: the master has no configuration)."""
    interface: tuple[str, str | None]
    """The µP interface's phase and mode (3.4.3): what it expects next."""


def _inputs(master: Master) -> bytes | None:
    try:
        return master.inputs(1)
    except InterbusError:
        return None


def _registers(registers: RegisterFile) -> tuple[tuple[str, int], ...]:
    return tuple((r.name, registers.value(r.name)) for r in REGISTER_MAP.registers)


def _interface(protocol: UpifProtocol) -> tuple[str, str | None]:
    return (str(protocol.phase), None if protocol.mode is None else str(protocol.mode))


def _rules(errors: list[InterfaceViolationError]) -> tuple[tuple[str, int], ...]:
    return tuple(sorted(Counter(error.rule for error in errors).items()))


def _encode(script: list[Step]) -> bytes:
    return bytes(b for step in script for b in step).ljust(STEPS * 4, b"\0")


def scripted_board(elf: Path, script: list[Step], **board_options: object) -> Board:
    """A board on ``scripted.c``'s binary ``elf`` (non-strict, the master every :data:`CYCLE_TIME_S`) with
    ``script`` loaded, not yet run."""
    board = Board(elf, strict=False, cycle_time_s=CYCLE_TIME_S, **board_options)  # type: ignore[arg-type]
    board.core.write_bytes(board.core.image.address("fw_script"), _encode(script))
    return board


def run_script(elf: Path, script: list[Step], **board_options: object) -> Outcome:
    """``script`` on the board (``scripted.c``'s binary ``elf``, non-strict, the master every
    :data:`CYCLE_TIME_S`): run to the end of the first master cycle that ends after the script, and one more."""
    board = scripted_board(elf, script, **board_options)
    core = board.core
    steps = core.image.address("fw_log_steps")
    for _ in range(100):
        board.run(1)
        if int.from_bytes(core.read_bytes(steps, 4), "little") == len(script):
            break
    else:
        raise AssertionError(f"the script did not end in 100 master cycles: {script}")
    board.run(1)
    raw = core.read_bytes(core.image.address("fw_log"), len(script) * LOG_BYTES)
    log = tuple(tuple(raw[n * LOG_BYTES + 1 : (n + 1) * LOG_BYTES]) for n in range(len(script)))
    return Outcome(log, _registers(board.registers), _rules([v.error for v in board.violations]), board.cycles,
                   _inputs(board.master), _interface(board.protocol))


class _Scripted(Firmware):
    """The same script through the Python driver on the firmware bench: what scripted.c's ``step`` does, call for
    call (the C driver's refusals are the Python driver's exceptions, their ``code``)."""

    def __init__(self, bench: Bench, script: list[Step]) -> None:
        self.bench = bench
        self.script = script
        self.log: list[tuple[int, ...]] = []

    def setup(self, drv: Supi3Driver) -> None:
        for step in self.script:
            result = bytearray(4)
            try:
                error = self._step(drv, *step, result)
            except DriverError as failure:
                error = int(failure.code)
            self.log.append((error & 0xFF, *result))

    def _wait_pin(self, read: object, level: int, units: int) -> int:
        transport = self.bench.transport
        for _ in range((units + 1) * WAIT_POLLS_PER_UNIT):
            if read() == level:  # type: ignore[operator]
                return 0
            transport.delay_us(WAIT_STEP_US)
        return 1

    def _step(self, drv: Supi3Driver, op: int, a: int, b: int, c: int, result: bytearray) -> int:
        bench, transport = self.bench, self.bench.transport
        protocol = transport.protocol
        if op == Op.INIT:
            drv.initialize(Mode.MOTOROLA if a == 0 else Mode.INTEL if a == 1 else a)  # type: ignore[arg-type]
        elif op == Op.CONFIG:
            drv.configure(a, b)
        elif op in (Op.READ, Op.WRITE, Op.EXCHANGE):
            return self._access(drv, Op(op), a, b, result)
        elif op == Op.BLOCK:
            data = bytes((c + 0x11 * k) & 0xFF for k in range(b))
            out = drv.block_transfer(data, read=bool(a & 1), write=bool(a & 2))
            result[: len(out)] = out
        elif op == Op.IRQ_ENABLE:
            drv.irq_enable(a)
        elif op == Op.IRQ_SERVICE:
            result[0] = int(drv.irq_service())
        elif op == Op.SAS_INIT:
            drv.sas_init()
        elif op == Op.DELAY:
            transport.delay_us(a)
        elif op == Op.WAIT_IRQ:
            return self._wait_pin(transport.read_irq, 0, a)
        elif op == Op.POLL_IO:
            result[0] = int(drv.poll_io_window(a))
        elif op == Op.RAW:
            result[0] = transport.xfer(a, True)  # FFh where the chip drives nothing, as MISO's pull-up (FW-26)
        elif op == Op.SS_HIGH:
            bench.advance(bench.now + bench.byte_s)  # the board's oracle: the chip sees nothing (3.4.2)
            transport.registers.violations.report(ss_high_byte(a))
            result[0] = MISO_IDLE
        elif op == Op.SS_CUT:  # half a period after the b-th edge (HALF_PERIOD): b bits of the chip's byte
            bench.advance(bench.now)
            driven = protocol.begin(True)
            bench.advance(bench.now + (b + 1) * SPI_BIT_S)
            protocol.abort(b)  # 3.4.2: a frame cut short is dropped
            result[0] = released(MISO_IDLE if driven is None else driven, 8, b, False)  # then MISO's pull-up (MCU-74)
            bench.irq_edge()
            bench.advance(bench.now + 8 * SPI_BIT_S)
        elif op == Op.LATCH:
            for _ in range((c + 1) * LATCH_POLLS_PER_UNIT):
                if transport.read_io() == 1:
                    break
            else:
                return 1
            transport.delay_us(a)
            return self._access(drv, Op.READ, b, 0, result)
        return 0

    def _access(self, drv: Supi3Driver, op: Op, address: int, value: int, result: bytearray) -> int:
        """A single access: the Python driver names registers (FW-8), so an address with no register in the
        direction (4, 5, 6, 8 to 11 written) goes as the C driver's two frames (MCU-60)."""
        if address > 14:
            drv.read(address)  # type: ignore[arg-type]  # SUPI3_E_ARG, as supi3_read(15)
        directions = {Op.READ: (AccessDirection.READ,), Op.WRITE: (AccessDirection.WRITE,),
                      Op.EXCHANGE: (AccessDirection.READ, AccessDirection.WRITE)}[op]  # fmt: skip
        register = next((p.register for d in directions if (p := REGISTER_MAP.port(address, d)).register), None)
        if register is not None:
            if op is Op.READ:
                result[0] = drv.read(register)
            elif op is Op.WRITE:
                drv.write(register, value)
            else:
                result[0] = drv.exchange(register, value)
            return 0
        if not drv.initialized:
            drv.read(REGISTER_MAP.register("SET"))  # SUPI3_E_NOT_INIT, nothing sent
        transport = self.bench.transport
        with transport.access():
            transport.xfer(encode_command(address, rd=op is not Op.WRITE, wr=op is not Op.READ), True)
            rx = transport.xfer(0 if op is Op.READ else value, True)
        if op is not Op.WRITE:
            result[0] = rx
        return 0


def run_on_bench(script: list[Step], **bench_options: object) -> Outcome:
    """``script`` through the Python driver on the transaction-level firmware bench (non-strict, the master every
    :data:`CYCLE_TIME_S`, the board's SCLK of 750 kHz), run and ended as :func:`run_script` ends it."""
    bench = Bench(strict=False, cycle_time_s=CYCLE_TIME_S, sclk_hz=1 / SPI_BIT_S, **bench_options)  # type: ignore[arg-type]
    firmware = _Scripted(bench, script)
    bench.firmware = firmware
    bench.power_up()  # the whole script, the bus running along
    bench.run(0 if bench.under_way else 1)  # to the end of the first master cycle after it, as run_script (MCU-76)
    bench.run(1)
    return Outcome(tuple(firmware.log), _registers(bench.registers), _rules(bench.registers.violations.records),
                   bench.cycles, _inputs(bench.master), _interface(bench.transport.protocol))


@pytest.fixture(scope="module")
def scripted(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """scripted.c built once per core for the Motorola board, and for the Intel board (``"intel"``, Cortex-M3)."""
    folder = tmp_path_factory.mktemp("fuzz")
    elves = {cpu: mcu_build.build(SOURCE, folder / f"scripted_{cpu}.elf", cpu=cpu)
             for cpu in ("cortex_m3", "cortex_m0")}  # fmt: skip
    elves["intel"] = mcu_build.build(SOURCE, folder / "scripted_intel.elf", defines={"FW_MODE": "SUPI3_MODE_INTEL"})
    return elves


# -- the scripts ---------------------------------------------------------------------------------------------------

BYTE = st.integers(0, 0xFF)
ADDRESS = st.integers(0, 15)
INIT_BYTES: Final = {Mode.MOTOROLA: 0, Mode.INTEL: 1}
"""scripted.c's INIT argument for each mode (supi3_mode_t)."""


def untimed(mode: Mode = Mode.MOTOROLA, *, other_mode: bool = False,
            any_cut: bool = False) -> st.SearchStrategy[tuple[int, int, int, int]]:  # fmt: skip
    """Steps whose results do not hang on the bus's timing (MCU-60): before the master's first cycle (1 ms, MCU-45)
    six of them take well under a millisecond on either clock. The initialization in the board's ``mode`` or in
    none (7: ``SUPI3_E_ARG``), with ``other_mode`` in the other mode too: a board wired for one mode sends the other's
    bytes in the wrong bit order and S/R, which the firmware bench, whose transport leaves the bit order to the
    wiring, does not model (MCU-60). The Intel board has no step that drives SPI1 directly (its S/R line, PB0, is
    the transport's, MCU-18). A frame cut short (``SS_CUT``) ends half an SCLK period after an edge, whose bits the
    bench's firmware counts, or with ``any_cut`` at any point of the byte, within t2 of an edge and across the chip
    clock's phase too, for the comparison of the fidelities (MCU-74)."""
    own = INIT_BYTES[mode]
    modes = (own, own, own, 7, 1 - own) if other_mode else (own, own, own, 7)
    steps = [
        st.tuples(st.just(Op.INIT), st.sampled_from(modes), st.just(0), st.just(0)),
        st.tuples(st.just(Op.CONFIG), st.sampled_from((0x83, 0x82, 0x84, 0x80, 0x03)) | BYTE, BYTE, st.just(0)),
        st.tuples(st.sampled_from((Op.READ, Op.WRITE, Op.EXCHANGE)), ADDRESS, BYTE, st.just(0)),
        st.tuples(st.just(Op.BLOCK), st.integers(0, 3), st.integers(0, 5), BYTE),
        st.tuples(st.just(Op.IRQ_ENABLE), st.sampled_from((0x10, 0x00, 0x7F)) | BYTE, st.just(0), st.just(0)),
        st.tuples(st.sampled_from((Op.IRQ_SERVICE, Op.SAS_INIT)), st.just(0), st.just(0), st.just(0)),
        st.tuples(st.just(Op.DELAY), st.integers(0, 50), st.just(0), st.just(0)),
        st.tuples(st.just(Op.RAW), BYTE, st.just(0), st.just(0)),
    ]
    if mode is Mode.MOTOROLA:
        cut = (st.tuples(st.just(Op.SS_CUT), BYTE, st.integers(0, 8), st.integers(0, 15)) if any_cut
               else st.tuples(st.just(Op.SS_CUT), BYTE, st.integers(0, 7), st.just(HALF_PERIOD)))  # fmt: skip
        steps.append(cut)
        steps.append(st.tuples(st.just(Op.SS_HIGH), BYTE, st.just(0), st.just(0)))
    return st.one_of(steps)


def recover(mode: Mode) -> list[Step]:
    """Whatever the prefix left: SAS_INIT, initialize, one word of digital I/O, the VALID interrupt (3.4.14), and
    the wait for its /IRQ: both sides then start the body at the same data cycle's end, with the idle gap of
    :data:`CYCLE_TIME_S` before the next."""
    return [(Op.SAS_INIT, 0, 0, 0), (Op.INIT, INIT_BYTES[mode], 0, 0), (Op.CONFIG, 0x83, 0x03, 0),
            (Op.IRQ_ENABLE, 0x10, 0, 0), (Op.IRQ_SERVICE, 0, 0, 0), (Op.WAIT_IRQ, 40, 0, 0)]  # fmt: skip


CUT_FRAMES: Final[list[Step]] = [
    (Op.INIT, 0, 0, 0), (Op.CONFIG, 0x83, 0xA5, 0),
    (Op.RAW, 0x8C, 0, 0),  # a read of ID: each cut frame drives its data byte, A5h, until a whole one ends it
    *((Op.SS_CUT, 0x00, b, c) for b in range(9) for c in (1, 11, 13, 14)),
]  # fmt: skip
"""Frames cut at each edge of the byte, at four points of each SCLK period: just after the rising edge (t2), in the
chip's reaction time before the next (SerOUT still driven), and around the edge itself (the chip takes an SCLK rise
only in a clock before /SS rises; MCU-74)."""
NO_SHRINK: Final = (Stage.explicit, Stage.reuse, Stage.generate)
"""An example costs up to half a second of bus emulation: a failure prints its script as generated (shrinking one
took over five minutes)."""
LATCH_DELAYS_US: Final = (60, 117, 150)
"""A read timed from the I/O access bit's rise (the check sequence, 111 µs into a one-word data cycle at 500 kbit/s)
so that its data byte begins before the latch phase (237 to 247 µs), in its middle, or after the cycle (3.4.14)."""


@st.composite
def scripts(draw: st.DrawFn, mode: Mode = Mode.MOTOROLA) -> list[Step]:
    """A hostile prefix, the recovery and the wait for /IRQ, a body in the idle gap (window polls and waits too:
    at most about 1.7 ms on the Cortex-M0, the gap is 1.86 ms), maybe a timed read. The timed read comes after
    SAS_INIT and the initialization: a raw byte of the body may have left a command waiting for its data byte, which
    the read's command byte would complete close to the latch phase's edge, where the clocks differ (MCU-60)."""
    body = st.one_of(untimed(mode), st.tuples(st.just(Op.POLL_IO), BYTE, st.just(0), st.just(0)),
                     st.tuples(st.just(Op.DELAY), st.integers(0, 120), st.just(0), st.just(0)))  # fmt: skip
    script = [*draw(st.lists(untimed(mode), max_size=6)), *recover(mode), *draw(st.lists(body, max_size=6))]
    if draw(st.booleans()):
        script += [(Op.SAS_INIT, 0, 0, 0), (Op.INIT, INIT_BYTES[mode], 0, 0),
                   (Op.LATCH, draw(st.sampled_from(LATCH_DELAYS_US)), draw(st.integers(0, 3)), 3)]  # fmt: skip
    return [(int(op), a, b, c) for op, a, b, c in script]


@pytest.mark.parametrize("cpu", ["cortex_m3", "cortex_m0"])
@settings(max_examples=15, phases=NO_SHRINK)
@given(script=scripts())
def test_a_script_on_the_binary_does_what_the_python_driver_does_on_the_bench(
        scripted: dict[str, Path], cpu: str, script: list[Step]) -> None:  # fmt: skip
    """(a) The binary at transaction level against the Python driver on the firmware bench, both pedantic (UP-30):
    every step's error code and result bytes, the chip's registers, the violations by rule (the suspicious accesses
    too), the cycles run, the master's IN data and the interface's phase are the same."""
    assert run_script(scripted[cpu], script, cpu=cpu, pedantic=True) == run_on_bench(script, pedantic=True)


@settings(max_examples=8, phases=NO_SHRINK)
@given(script=scripts(Mode.INTEL))
def test_an_intel_script_on_the_binary_does_what_the_python_driver_does_on_the_bench(
        scripted: dict[str, Path], script: list[Step]) -> None:  # fmt: skip
    """(a) on the Intel board (MCU-18): the Intel build at transaction level against the Python driver in Intel
    mode."""
    assert run_script(scripted["intel"], script, mode=Mode.INTEL, pedantic=True) == \
        run_on_bench(script, mode=Mode.INTEL, pedantic=True)


@settings(max_examples=4, phases=NO_SHRINK)
@given(script=st.lists(untimed(other_mode=True, any_cut=True), min_size=1, max_size=6))
@example(script=[(Op.SS_HIGH, 0x0B, 0, 0), (Op.SS_CUT, 0x00, 2, HALF_PERIOD)])  # 3.4.2 twice at both (MCU-63)
@example(script=CUT_FRAMES)  # MCU-74: the bits SPI1 received, t2 and the edges the chip took, at every cut
def test_a_short_script_does_the_same_at_both_fidelities(scripted: dict[str, Path], script: list[Step]) -> None:
    """(b) Short scripts, all before the master's first cycle (the pin level's discovery ID cycle is not the
    transaction level's, MCU-17), on the binary at transaction and at pin level."""
    script = [(int(op), a, b, c) for op, a, b, c in script]
    elf = scripted["cortex_m3"]
    assert run_script(elf, script, pedantic=True) == run_script(elf, script, fidelity="pin", pedantic=True)


@pytest.mark.parametrize("bit_rate", [500_000, 2_000_000])
@pytest.mark.parametrize("cpu", ["cortex_m3", "cortex_m0"])
def test_frames_cut_anywhere_do_the_same_at_both_fidelities(scripted: dict[str, Path], cpu: str,
                                                            bit_rate: int) -> None:  # fmt: skip
    """MCU-74: :data:`CUT_FRAMES` on both cores (their own instruction timing puts the cuts elsewhere against the
    edges) and at both bit rates (the chip's reaction to /SS is 9 chip clocks at 500 kbit/s, 3 at 2 Mbit/s): the
    bytes SPI1 received, the t2 and 3.4.2 violations and the interface's phase are the same at both fidelities, and
    the cuts reach the cases they are for (t2 broken, bytes cut short)."""
    outcomes = [run_script(scripted[cpu], CUT_FRAMES, cpu=cpu, bit_rate=bit_rate, fidelity=fidelity, pedantic=True)
                for fidelity in ("transaction", "pin")]  # fmt: skip
    assert outcomes[0] == outcomes[1]
    rules = dict(outcomes[0].violations)
    assert rules.get("Table 3-7 t2", 0) > 0 and rules.get("3.4.2", 0) > 0
    received = {entry[1] for entry in outcomes[0].log[3:]}
    assert {0xFF, 0xA5} < received and len(received) > 4  # nothing sampled, the whole byte, and bits of it


@st.composite
def synced_scripts(draw: st.DrawFn) -> list[Step]:
    """A short prefix, the recovery and the wait for /IRQ, a body in the idle gap; no timed read: the pin-level latch
    phase is the time between the two latch telegrams' receipt, not the transaction level's (docs/model.md M10)."""
    body = st.one_of(untimed(any_cut=True), st.tuples(st.just(Op.POLL_IO), BYTE, st.just(0), st.just(0)),
                     st.tuples(st.just(Op.DELAY), st.integers(0, 120), st.just(0), st.just(0)))  # fmt: skip
    script = [*draw(st.lists(untimed(any_cut=True), max_size=3)), *recover(Mode.MOTOROLA),
              *draw(st.lists(body, min_size=1, max_size=4))]  # fmt: skip
    return [(int(op), a, b, c) for op, a, b, c in script]


RECONFIGURED: Final = "3.4.3, 3.4.11"
"""The rule of SET or ID written while the bus runs (``ReconfigurationError``)."""


@settings(max_examples=2, phases=NO_SHRINK)
@given(script=synced_scripts())
@example(script=[(Op.SS_CUT, 0x1D, 6, HALF_PERIOD), *recover(Mode.MOTOROLA), (Op.BLOCK, 2, 2, 0x5A),
                 (Op.CONFIG, 0x77, 0xBB, 0)])  # SET written while the bus runs: 28 bytes against 2 before MCU-64
def test_a_script_served_after_an_interrupt_does_the_same_at_both_fidelities(
        scripted: dict[str, Path], script: list[Step]) -> None:  # fmt: skip
    """(b) with the bus running: the body after the first VALID interrupt gives the same outcome at both
    fidelities but the master's cycle count (the discovery ID cycle is sized for the largest ring at transaction
    level, for the ring's chips at pin level, MCU-17); after SET or ID written while the bus runs the master's IN
    data too (MCU-64)."""
    elf = scripted["cortex_m3"]
    transaction = replace(run_script(elf, script, pedantic=True), cycles=0)
    pin = replace(run_script(elf, script, fidelity="pin", pedantic=True), cycles=0)
    assert transaction == pin


RUNNING_RECONFIGURATIONS: Final[list[list[Step]]] = [
    [(Op.CONFIG, 0x84, 0x03, 0)],  # SET and ID: 3 bytes (the length changes)
    [(Op.EXCHANGE, 12, 0x55, 0)],  # ID alone: the table's ID code is checked in ID cycles only
    [(Op.EXCHANGE, 13, 0x82, 0)],  # SET alone: 1 byte
    [(Op.BLOCK, 2, 2, 0x5A), (Op.CONFIG, 0x85, 0xBB, 0)],  # MCU-63's script with ExtReg = 0: 2 words, ID BBh
    [(Op.CONFIG, 0x49, 0x03, 0)],  # SET with ExtReg = 1, 1 byte, nothing on FromExR: LOOPBACK after it (RX-13)
]
"""Bodies served after the VALID interrupt that write SET or ID while the bus runs (MCU-64); with ExtReg = 1 and
nothing on FromExR every data cycle after the rediscovery fails with LOOPBACK at both fidelities (RX-11, RX-13)."""


@pytest.mark.parametrize("body", RUNNING_RECONFIGURATIONS)
def test_set_or_id_written_while_the_bus_runs_gives_the_same_master_cycles_at_both_fidelities(
        scripted: dict[str, Path], body: list[Step]) -> None:  # fmt: skip
    """MCU-64: after SET or ID written while the bus runs (``ReconfigurationError``, UP-20: applied at once at both
    fidelities), run by run the master's cycles, its diagnostics, its table and its IN data of the chip are the
    same at both fidelities."""
    script = [(int(op), a, b, c) for op, a, b, c in [*recover(Mode.MOTOROLA), *body]]
    seen: dict[str, list[object]] = {}
    for fidelity in ("transaction", "pin"):
        board = scripted_board(scripted["cortex_m3"], script, fidelity=fidelity, pedantic=True)
        runs: list[object] = []
        for _ in range(6):
            board.run(1)
            master = board.master
            runs.append((board.cycles, [(d.kind, d.location, d.detail) for d in master.diagnostics],
                         None if master.config is None else [(e.id_code, e.data_bytes) for e in master.config],
                         _inputs(master)))  # fmt: skip
        assert RECONFIGURED in dict(_rules([v.error for v in board.violations]))
        seen[fidelity] = runs
    assert seen["transaction"] == seen["pin"]

EVERY_OP: Final[list[Step]] = [
    (Op.RAW, 0x55, 0, 0), (Op.INIT, 0, 0, 0), (Op.READ, 13, 0, 0), (Op.SAS_INIT, 0, 0, 0), (Op.INIT, 7, 0, 0),
    (Op.INIT, 0, 0, 0), (Op.CONFIG, 0x83, 0x03, 0),
    (Op.IRQ_ENABLE, 0x80, 0, 0), (Op.IRQ_ENABLE, 0x10, 0, 0), (Op.READ, 12, 0, 0), (Op.RAW, 0x8D, 0, 0),
    (Op.RAW, 0, 0, 0), (Op.BLOCK, 3, 4, 0), (Op.BLOCK, 3, 2, 0x12), (Op.READ, 4, 0, 0), (Op.WRITE, 9, 1, 0),
    (Op.EXCHANGE, 7, 0x5A, 0), (Op.SS_HIGH, 0x55, 0, 0), (Op.SS_CUT, 0x8E, 3, HALF_PERIOD), (Op.DELAY, 20, 0, 0),
    (Op.WAIT_IRQ, 40, 0, 0), (Op.IRQ_SERVICE, 0, 0, 0), (Op.POLL_IO, 0, 0, 0), (Op.POLL_IO, 5, 0, 0),
    (Op.BLOCK, 3, 2, 0x34),
    (Op.LATCH, 117, 0, 3), (Op.READ, 15, 0, 0),
]
"""Each operation once (the bad ones too), in an order that makes each do something."""


@pytest.mark.parametrize("cpu", ["cortex_m3", "cortex_m0"])
def test_every_operation_once_does_what_the_python_driver_does(scripted: dict[str, Path], cpu: str) -> None:
    """The fixed script on each core's binary against the bench: the same outcome, and the outcome expected."""
    script = [(int(op), a, b, c) for op, a, b, c in EVERY_OP]
    outcome = run_script(scripted[cpu], script, cpu=cpu)
    assert outcome == run_on_bench(script)
    log = dict(zip(EVERY_OP, outcome.log, strict=True))  # the first INIT's entry is the second's
    assert outcome.log[:3] == ((0, MISO_IDLE, 0, 0, 0),  # no mode yet: MISO pulled up (MCU-6); 55h disables (UP-4)
                               (ErrorCode.E_NOT_READY & 0xFF, 0, 0, 0, 0), (ErrorCode.E_NOT_INIT & 0xFF, 0, 0, 0, 0))
    assert log[Op.INIT, 7, 0, 0][0] == ErrorCode.E_ARG & 0xFF
    assert log[Op.IRQ_ENABLE, 0x80, 0, 0][0] == ErrorCode.E_ARG & 0xFF  # bit 7 reserved (RM-7)
    assert log[Op.READ, 12, 0, 0] == (0, 0x03, 0, 0, 0)  # ID
    assert log[Op.RAW, 0, 0, 0] == (0, 0x83, 0, 0, 0)  # the raw read of SET
    assert log[Op.BLOCK, 3, 4, 0][0] == ErrorCode.E_ARG & 0xFF  # SET 83h: one word (UP-10)
    assert log[Op.WAIT_IRQ, 40, 0, 0] == (0, 0, 0, 0, 0)
    assert log[Op.IRQ_SERVICE, 0, 0, 0][:2] == (0, 0x10)  # VALID (3.4.14)
    assert log[Op.POLL_IO, 5, 0, 0] == (0, 0, 0, 0, 0)  # the window is open after the cycle (3.4.14)
    assert log[Op.READ, 15, 0, 0][0] == ErrorCode.E_ARG & 0xFF  # 15 is the block transfer's (3.4.6)
    assert outcome.inputs == b"\x34\x45"  # IN data written after the master's start (its reset clears them, 3.4.7)
    assert outcome.violations == (("3.4.14", 1), ("3.4.2", 2))  # the latch-phase read, /SS high, /SS cut short

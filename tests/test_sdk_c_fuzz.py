"""The C driver (src/supi3/sdk/c) fuzzed against a scripted chip: every path that reads from the chip.

``tests/c/fuzz_driver.c`` runs the driver with callbacks whose every received byte, C/D, /IRQ and I/O (MFP1) level
comes from a script (a used-up script makes the callback fail). Hypothesis writes the scripts and the calls. The
harness, built with ``-fsanitize=address,undefined`` (the slow tier adds a plain -O2 build and more examples), runs
many cases in one process (one line in, one line out), and every result is checked against :class:`Reference`, a
Python statement of what the driver must do (3.4.3 to 3.4.14, docs/sdk.md): return codes, values read, block
bytes, events OR-ed while polling, optical fields decoded with the Python register map, the u16/u32 helpers, and
the bytes and S/R levels it sent. The sanitizers abort on the first finding (``-fno-sanitize-recover=all``), which
fails the test with their report; at the end the process must exit 0 with nothing on stderr.
"""

from __future__ import annotations

import shutil
import subprocess
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3 import sdk
from supi3.regmap import (
    ALARM,
    ID,
    INIT_BYTE,
    IRQ_EN,
    IRQ_EVT,
    LENGTH_BRANCH,
    LENGTH_OUT,
    PCMD,
    POWER_IN,
    POWER_OUT_BRANCH,
    SET,
    RegisterMapError,
    decode_set,
    encode_command,
)
from supi3.sdk.driver import IRQ_SERVICE_MAX_READS

HARNESS = Path(__file__).parent / "c" / "fuzz_driver.c"
SANITIZE = ["-fsanitize=address,undefined", "-fno-omit-frame-pointer", "-fno-sanitize-recover=all"]

OK, E_ARG, E_NOT_INIT, E_TRANSPORT, E_NOT_READY, E_NOT_RESET, E_UNSUPPORTED, E_TIMEOUT = 0, -1, -2, -3, -4, -5, -6, -7
MOTOROLA, INTEL = 0, 1
SENTINEL, OPTICAL_SENTINEL = 0xA5, 0xEE
UP_SENDS, CHIP_DRIVES = 1, 0  # S/R (Table 3-9, UP-9)
ADDR_MAX = 14  # 15 is the block transfer (3.4.6)
BYTE_BITS = 8
OPTICAL = (LENGTH_OUT, LENGTH_BRANCH, POWER_IN, POWER_OUT_BRANCH)

(INITIALIZE, READ, WRITE, EXCHANGE, BLOCK, IRQ_SERVICE, POLL, PCMD_OP, ALARM_OP, OPTICAL_OP, IRQ_ENABLE, CONFIGURE,
 SAS_INIT, HELPERS) = range(14)  # fmt: skip

Op = tuple[int, tuple[int, ...]]


@dataclass
class Case:
    """One harness case: which pin callbacks exist, the chip's scripts, and the driver calls."""

    with_cd: bool
    with_irq: bool
    with_io: bool
    rx: list[int]
    cd: list[int]
    irq: list[int]
    io: list[int]
    ops: list[Op]

    def line(self) -> str:
        words = [int(self.with_cd), int(self.with_irq), int(self.with_io)]
        for stream in (self.rx, self.cd, self.irq, self.io):
            words += [len(stream), *stream]
        words.append(len(self.ops))
        for code, args in self.ops:
            words += [code, *args, *[0] * (8 - len(args))]
        return " ".join(map(str, words)) + "\n"


@dataclass
class Result:
    """What the harness printed for a case: per op (rc, outputs), the frames sent, the script entries used."""

    ops: list[tuple[int, list[int]]]
    frames: list[tuple[int, int]]
    used: tuple[int, int, int, int]

    @classmethod
    def parse(cls, line: str, n_ops: int) -> Result:
        words: Iterator[int] = iter(int(w) for w in line.split())
        ops = []
        for _ in range(n_ops):
            rc, n = next(words), next(words)
            ops.append((rc, [next(words) for _ in range(n)]))
        frames = [(next(words), next(words)) for _ in range(next(words))]
        used = (next(words), next(words), next(words), next(words))
        assert next(words, None) is None, line
        return cls(ops, frames, used)


class TransportError(Exception):
    """A callback of the scripted chip failed (its script was used up)."""


@dataclass
class Reference:
    """The driver's contract in Python, run against the same scripted chip as the C harness."""

    case: Case
    initialized: bool = False
    mode: int = MOTOROLA
    set_known: bool = False
    set_value: int = 0
    frames: list[tuple[int, int]] = field(default_factory=list)
    used: list[int] = field(default_factory=lambda: [0, 0, 0, 0])

    # the scripted chip --------------------------------------------------------------------------------------------

    def frame(self, tx: int, s_r: int) -> int:
        """One byte; a failed transfer leaves the chip's phase unknown: the driver must be initialized again."""
        self.frames.append((tx, s_r))
        if self.used[0] == len(self.case.rx):
            self.initialized = False
            raise TransportError
        self.used[0] += 1
        return self.case.rx[self.used[0] - 1]

    def pin(self, index: int) -> int:
        """A pin level (1 = C/D, 2 = /IRQ, 3 = I/O); any non-zero level is high. Reading a pin changes nothing."""
        stream = (self.case.rx, self.case.cd, self.case.irq, self.case.io)[index]
        if self.used[index] == len(stream):
            raise TransportError
        self.used[index] += 1
        return int(stream[self.used[index] - 1] != 0)

    # the driver ---------------------------------------------------------------------------------------------------

    def entry_ok(self, args_ok: bool) -> int:
        """Value arguments first (SUPI3_E_ARG), then the state; pointer arguments are checked after this."""
        if not args_ok:
            return E_ARG
        return OK if self.initialized else E_NOT_INIT

    def access_ok(self, addr: int) -> int:
        return self.entry_ok(addr <= ADDR_MAX)

    def note_set(self, addr: int, value: int, rc: int) -> None:
        if addr == SET.address:
            self.set_known, self.set_value = rc == OK, value

    @staticmethod
    def block_bytes(set_value: int) -> int:
        """Whole bytes of a block transfer for SET (3.4.6: >= 1 word; ExtReg = 1 or a reserved code: none)."""
        try:
            decoded = decode_set(set_value)
        except RegisterMapError:
            return 0
        bits = decoded.length.bits
        if decoded.extreg or bits is None or bits < 2 * BYTE_BITS:
            return 0
        return bits // BYTE_BITS

    def initialize(self, mode: int) -> int:
        if mode not in (MOTOROLA, INTEL):
            return E_ARG
        self.initialized = False
        if self.case.with_cd and self.pin(1):
            return E_NOT_READY  # data phase before the init byte: nothing sent (UP-27, UP-4)
        self.frame(INIT_BYTE.constant("INTEL" if mode == INTEL else "MOTOROLA").value, UP_SENDS)
        if self.case.with_cd and self.pin(1):
            self.frame(0x00, CHIP_DRIVES if mode == INTEL else UP_SENDS)  # complete the command (UP-3)
            return E_NOT_RESET
        self.mode, self.initialized = mode, True
        return OK

    def read(self, addr: int, null: bool = False) -> tuple[int, int | None]:
        rc = self.access_ok(addr)
        if rc == OK and null:
            rc = E_ARG
        if rc != OK:
            return rc, None
        value = None
        try:
            self.frame(encode_command(addr, rd=True), UP_SENDS)
            value = self.frame(0x00, CHIP_DRIVES)
        except TransportError:
            rc = E_TRANSPORT
        self.note_set(addr, 0 if value is None else value, rc)
        return rc, value

    def write(self, addr: int, value: int) -> int:
        rc = self.access_ok(addr)
        if rc != OK:
            return rc
        try:
            self.frame(encode_command(addr, wr=True), UP_SENDS)
            self.frame(value, UP_SENDS)
        except TransportError:
            rc = E_TRANSPORT
        self.note_set(addr, value, rc)
        return rc

    def exchange(self, addr: int, wr: int, null: bool) -> tuple[int, int | None]:
        rc = self.access_ok(addr)
        if rc == OK and null:
            rc = E_ARG
        if rc == OK and self.mode != MOTOROLA:
            rc = E_UNSUPPORTED  # 3.4.4
        if rc != OK:
            return rc, None
        value = None
        try:
            self.frame(encode_command(addr, rd=True, wr=True), UP_SENDS)
            value = self.frame(wr, UP_SENDS)
        except TransportError:
            rc = E_TRANSPORT
        self.note_set(addr, wr, rc)
        return rc, value

    def block(self, rd: int, wr: int, n: int, data: list[int], flags: int) -> tuple[int, list[int]]:
        out = [SENTINEL] * 4
        out_null, in_null = bool(flags & 1), bool(flags & 2)
        rc = self.access_ok(0)
        if rc == OK and (not 2 <= n <= 4 or (self.set_known and n != self.block_bytes(self.set_value))):
            rc = E_ARG  # 3.4.6, UP-10
        if rc == OK and self.mode == MOTOROLA and (in_null or (rd and out_null)):
            rc = E_ARG
        if rc == OK and self.mode == INTEL and ((not rd and not wr) or (rd and out_null) or (wr and in_null)):
            rc = E_ARG
        if rc != OK:
            return rc, out
        try:
            self.frame(encode_command(15, rd=bool(rd), wr=bool(wr)), UP_SENDS)
            if self.mode == MOTOROLA:  # n full-duplex bytes (UP-11)
                for k in range(n):
                    got = self.frame(data[k], UP_SENDS)
                    if not out_null:
                        out[k] = got
            else:  # Intel: n reads, then n writes (UP-11, Fig. 3-12)
                for k in range(n if rd else 0):
                    out[k] = self.frame(0x00, CHIP_DRIVES)
                for k in range(n if wr else 0):
                    self.frame(data[k], UP_SENDS)
        except TransportError:
            rc = E_TRANSPORT
        return rc, out

    def irq_service(self, null: bool) -> tuple[int, int | None]:
        rc = self.access_ok(IRQ_EVT.address)
        if rc == OK and null:
            rc = E_ARG
        if rc != OK:
            return rc, None
        events = 0  # written whatever the result: the events read, and so cleared (FW-22)
        for reads in range(IRQ_SERVICE_MAX_READS + 1):
            if self.case.with_irq:
                try:
                    if self.pin(2):
                        return OK, events  # /IRQ high: nothing (left) pending
                except TransportError:
                    return E_TRANSPORT, events
            if reads == IRQ_SERVICE_MAX_READS:
                break
            rc, value = self.read(IRQ_EVT.address)
            if rc != OK or value is None:
                return rc, events
            events = (events & ~IRQ_EVT.field("IO_ACCESS").mask) | value  # D6..D0 OR-ed, D7 of the last read
            if not self.case.with_irq:
                return OK, events  # without /IRQ: one read
        return E_TIMEOUT, events  # /IRQ stayed low

    def poll(self, max_polls: int, null: bool) -> tuple[int, int | None]:
        rc = self.entry_ok(max_polls != 0)
        if rc == OK and null and not self.case.with_io:
            rc = E_ARG
        if rc != OK:
            return rc, None
        events = None if null else 0
        for _ in range(max_polls):
            if self.case.with_io:
                try:
                    busy = self.pin(3)
                except TransportError:
                    return E_TRANSPORT, events
            else:
                rc, value = self.read(IRQ_EVT.address)
                if rc != OK or value is None or events is None:
                    return rc, events
                events |= value & ~IRQ_EVT.field("IO_ACCESS").mask  # every read clears D6..D0 (3.4.14)
                busy = IRQ_EVT.field("IO_ACCESS").extract(value)
            if not busy:
                return OK, events
        return E_TIMEOUT, events

    def irq_enable(self, mask: int) -> int:
        rc = self.entry_ok(not mask & ~IRQ_EN.mask)  # bit 7 reserved (RM-7)
        return rc if rc != OK else self.write(IRQ_EN.address, mask)

    def optical(self, null: bool) -> tuple[int, list[int]]:
        fields = [OPTICAL_SENTINEL] * 10
        rc = self.access_ok(LENGTH_OUT.address)
        if rc == OK and null:
            rc = E_ARG
        raw = []
        for register in OPTICAL:
            if rc != OK:
                return rc, fields
            rc, value = self.read(register.address)
            raw.append(value)
        if rc != OK:
            return rc, fields
        decoded = [register.decode(value) for register, value in zip(OPTICAL, raw, strict=True) if value is not None]
        out_length, branch_length, power_in, power_out_branch = decoded
        return OK, [
            out_length["LENGTH"], out_length["MEDIUM"], out_length["ENABLE"],
            branch_length["LENGTH"], branch_length["MEDIUM"], branch_length["ENABLE"],
            power_in["LEVEL"], power_in["ENABLE"],
            power_out_branch["OUT_LEVEL"], power_out_branch["BRANCH_LEVEL"],
        ]  # fmt: skip

    @staticmethod
    def helpers(args: tuple[int, ...]) -> list[int]:
        """Byte 0 (address 0) is the most significant (3.4.8)."""
        data, u16, u32 = bytes(args[:4]), args[4], args[5]
        return [
            int.from_bytes(data[:2], "big"),
            int.from_bytes(data, "big"),
            *u16.to_bytes(2, "big"),
            *u32.to_bytes(4, "big"),
        ]

    def run(self, code: int, a: tuple[int, ...]) -> tuple[int, list[int]]:
        """One call: (return code, the outputs as the harness prints them)."""

        def one(result: tuple[int, int | None]) -> tuple[int, list[int]]:
            return result[0], [SENTINEL if result[1] is None else result[1]]

        try:
            if code == INITIALIZE:
                return self.initialize(a[0]), []
            if code == READ:
                return one(self.read(a[0], bool(a[1])))
            if code == WRITE:
                return self.write(a[0], a[1]), []
            if code == EXCHANGE:
                return one(self.exchange(a[0], a[1], bool(a[2])))
            if code == BLOCK:
                return self.block(a[0], a[1], a[2], list(a[3:7]), a[7])
            if code == IRQ_SERVICE:
                return one(self.irq_service(bool(a[0])))
            if code == POLL:
                return one(self.poll(a[0], bool(a[1])))
            if code == PCMD_OP:
                return one(self.read(PCMD.address, bool(a[0])))
            if code == ALARM_OP:
                return self.write(ALARM.address, a[0]), []
            if code == OPTICAL_OP:
                return self.optical(bool(a[0]))
            if code == IRQ_ENABLE:
                return self.irq_enable(a[0]), []
            if code == CONFIGURE:
                rc = self.write(SET.address, a[0])
                return (rc if rc != OK else self.write(ID.address, a[1])), []
            if code == SAS_INIT:
                self.initialized = False  # SAS_INIT keeps every register, SET too (3.4.3)
                return OK, []
            return OK, self.helpers(a)
        except TransportError:  # a pin read of initialize()
            return E_TRANSPORT, []


# ------------------------------------------------------------------------------------------------------------------
# Strategies
# ------------------------------------------------------------------------------------------------------------------

BYTES = st.integers(0, 255)
ADDRESS = st.integers(0, 15)
FLAG = st.integers(0, 1)
# SET values: the block lengths (1 word, 3 bytes, 2 words), shorter ones, ExtReg = 1, reserved CL, any byte
SET_VALUES = st.one_of(st.sampled_from([0x83, 0x84, 0x85, 0x03, 0x82, 0x81, 0x45, 0x86, 0x87]), BYTES)


def _op(code: int, *args: st.SearchStrategy[int]) -> st.SearchStrategy[Op]:
    return st.tuples(*args).map(lambda values: (code, tuple(values)))


NULL = st.sampled_from([0, 0, 0, 1])  # mostly a buffer, sometimes NULL
AUTO = -1
"""Block length placeholder: SET's length where the driver knows SET (else 2..4), resolved by :func:`cases`."""
BLOCK_LENGTH = st.one_of(st.just(AUTO), st.integers(0, 5))
BLOCK_FLAGS = st.one_of(st.just(0), st.integers(1, 3))  # 1: out NULL, 2: in NULL
RD_WR = st.integers(0, 2)  # any non-zero int is set
READING_OPS: tuple[st.SearchStrategy[Op], ...] = (
    _op(READ, ADDRESS, NULL),
    _op(READ, st.sampled_from([SET.address, IRQ_EVT.address, PCMD.address]), st.just(0)),
    _op(EXCHANGE, ADDRESS, BYTES, NULL),
    _op(BLOCK, RD_WR, RD_WR, BLOCK_LENGTH, *(BYTES,) * 4, BLOCK_FLAGS),
    _op(IRQ_SERVICE, NULL),
    _op(POLL, st.integers(1, 6), NULL),
    _op(POLL, st.integers(0, 6), NULL),
    _op(PCMD_OP, NULL),
    _op(OPTICAL_OP, NULL),
    _op(HELPERS, BYTES, BYTES, BYTES, BYTES, st.integers(0, 0xFFFF), st.integers(0, 0xFFFF_FFFF)),
)
OTHER_OPS: tuple[st.SearchStrategy[Op], ...] = (
    _op(INITIALIZE, st.sampled_from([MOTOROLA, INTEL, MOTOROLA, INTEL, 2])),
    _op(WRITE, st.one_of(st.just(SET.address), ADDRESS), st.one_of(SET_VALUES, BYTES)),
    _op(ALARM_OP, BYTES),
    _op(IRQ_ENABLE, BYTES),
    _op(CONFIGURE, SET_VALUES, BYTES),
)
_SAS_INIT_THEN_INITIALIZE = st.tuples(_op(SAS_INIT), _op(INITIALIZE, st.sampled_from([MOTOROLA, INTEL])))
OPS: st.SearchStrategy[list[Op]] = st.sampled_from(
    [op.map(lambda one: [one]) for op in READING_OPS * 3 + OTHER_OPS + (_op(SAS_INIT),)]
    + [_SAS_INIT_THEN_INITIALIZE.map(list)]
).flatmap(lambda ops: ops)
"""The calls (SAS_INIT alone or followed by initialize), those that read from the chip three times as often."""
# Bytes the chip sends: I/O access D7 = 1 more often than not, so that polls take several reads.
RX_BYTES = st.one_of(BYTES, st.integers(0x80, 0xFF))


CD_LEVELS = st.sampled_from([0, 1, 7])
PROPER = st.sampled_from([True, True, True, True, False])  # mostly a chip that behaves, sometimes not


@st.composite
def cases(draw: st.DrawFn) -> Case:
    """Mostly a chip that initializes and has bytes to spare, so that the calls get past SUPI3_E_NOT_INIT;
    sometimes scripts that end early (SUPI3_E_TRANSPORT at any byte or pin read) or show C/D = data."""
    first = [(INITIALIZE, (draw(st.sampled_from([MOTOROLA, INTEL])),))] if draw(PROPER) else []
    ops = first + [op for group in draw(st.lists(OPS, min_size=1, max_size=5)) for op in group]
    cd = draw(st.lists(st.just(0), min_size=8, max_size=8) if draw(PROPER) else st.lists(CD_LEVELS, max_size=6))
    case = Case(
        with_cd=draw(st.booleans()),
        with_irq=draw(st.booleans()),
        with_io=draw(st.booleans()),
        rx=draw(st.lists(RX_BYTES, min_size=32, max_size=64) if draw(PROPER) else st.lists(RX_BYTES, max_size=32)),
        cd=cd,
        irq=draw(st.lists(CD_LEVELS, max_size=6)),
        io=draw(st.lists(st.sampled_from([1, 1, 0, 5]), min_size=draw(st.sampled_from([8, 0])), max_size=8)),
        ops=ops,
    )
    reference = Reference(case)
    for k, (code, args) in enumerate(ops):
        if code == BLOCK and args[2] == AUTO:
            known = reference.block_bytes(reference.set_value) if reference.set_known else 0
            ops[k] = (code, (*args[:2], known or draw(st.integers(2, 4)), *args[3:]))
        reference.run(*ops[k])
    return case


# ------------------------------------------------------------------------------------------------------------------
# The harness process
# ------------------------------------------------------------------------------------------------------------------


class Harness:
    """The fuzz harness as a co-process: one case line in, one result line out."""

    def __init__(self, exe: Path) -> None:
        self.proc = subprocess.Popen(
            [str(exe)], stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, bufsize=1
        )

    def _pipes(self) -> tuple[IO[str], IO[str]]:
        assert self.proc.stdin is not None and self.proc.stdout is not None
        return self.proc.stdin, self.proc.stdout

    def run(self, case: Case) -> Result:
        stdin, stdout = self._pipes()
        stdin.write(case.line())
        stdin.flush()
        line = stdout.readline()
        if not line:
            code, stderr = self.close()
            pytest.fail(f"the harness died (exit status {code}) on {case!r}:\n{stderr}")
        return Result.parse(line, len(case.ops))

    def close(self) -> tuple[int, str]:
        """End the process: its exit status and everything it wrote to stderr (the sanitizers' reports)."""
        stdin, stdout = self._pipes()
        if not stdin.closed:
            stdin.close()
        assert self.proc.stderr is not None
        stderr = self.proc.stderr.read()
        stdout.close()
        self.proc.stderr.close()
        return self.proc.wait(timeout=30), stderr


@pytest.fixture(scope="module", params=["sanitized", pytest.param("plain", marks=pytest.mark.slow)])
def harness(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> Iterator[Harness]:
    gcc = shutil.which("gcc")
    if gcc is None:
        pytest.skip("gcc not found: the C driver fuzz needs it")
    exe = tmp_path_factory.mktemp("fuzz") / f"fuzz_{request.param}"
    flags = SANITIZE if request.param == "sanitized" else ["-O2"]  # plain: optimized, as firmware ships
    build = subprocess.run(
        [gcc, "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-g", *flags, f"-I{sdk.include_dir()}",
         *map(str, sdk.sources()), str(HARNESS), "-o", str(exe)],
        capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert build.returncode == 0, build.stderr
    process = Harness(exe)
    yield process
    code, stderr = process.close()
    assert (code, stderr) == (0, ""), stderr  # nothing from the sanitizers


def check(harness: Harness, case: Case) -> None:
    got = harness.run(case)
    reference = Reference(case)
    expected = [reference.run(code, args) for code, args in case.ops]
    for (code, args), want, have in zip(case.ops, expected, got.ops, strict=True):
        assert have == want, f"op {code} {args}: driver {have}, reference {want}"
    assert got.frames == reference.frames
    assert got.used == tuple(reference.used)


@settings(max_examples=400)
@given(case=cases())
def test_driver_matches_the_reference_on_scripted_chips(harness: Harness, case: Case) -> None:
    check(harness, case)


@pytest.mark.slow
@settings(max_examples=1000)
@given(case=cases())
def test_driver_matches_the_reference_on_many_scripted_chips(harness: Harness, case: Case) -> None:
    check(harness, case)


def test_reference_and_harness_agree_on_a_known_case(harness: Harness) -> None:
    """A hand-checked case: the fuzz compares like with like (3.4.5, 3.4.12, 3.4.14)."""
    case = Case(
        with_cd=True, with_irq=False, with_io=False,
        rx=[0, 0, 0x82, 0, 0x01, 0, 0xC0 | 12, 0, 0x3F, 0, 0x8F, 0, 0x21, 0, 0x90, 0, 0x10],
        cd=[0, 0], irq=[], io=[],
        ops=[(INITIALIZE, (MOTOROLA,)), (CONFIGURE, (0x82, 0x01)), (OPTICAL_OP, (0,)), (POLL, (3, 0))],
    )  # fmt: skip
    got = harness.run(case)
    assert got.ops == [
        (OK, []),
        (OK, []),
        (OK, [12, 1, 1, 63, 0, 0, 15, 1, 1, 2]),
        (OK, [0x10 | 0x10]),  # D7 = 1 with VALID, then D7 = 0 with VALID again: OR-ed
    ]
    assert got.frames[:5] == [(0x00, 1), (0x4D, 1), (0x82, 1), (0x4C, 1), (0x01, 1)]
    assert got.used == (17, 2, 0, 0)
    check(harness, case)

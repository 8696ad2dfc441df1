"""The fast paths of ``UpInterface`` (issue #10): a whole register access (``read``, ``write``) does exactly what its
command byte and data byte do when sent one at a time through ``transfer`` (3.4.4, Table 3-9; UP-8, UP-9), for
every address, both modes, strict and lenient, pedantic or not, and the states that change an access's effect
(latch phase, bus running, configured or not, ExtReg); and ``transfer`` does exactly what one frame of
``UpifProtocol.begin``/``end`` does, for random byte streams."""

from __future__ import annotations

import itertools
from collections.abc import Callable

import pytest
from hypothesis import given
from hypothesis import strategies as st

from supi3.config import decode
from supi3.model.registers import RegisterFile
from supi3.regmap import BLOCK_ADDRESS, REGISTER_MAP, encode_command
from supi3.spi.upif import Mode, UpifProtocol, UpInterface

RB_UP = decode("10011", "1110")  # RB, Init-µP (Table 2-6)
SET_VALUES = (None, 0x82, 0x85, 0x03, 0x40 | 0b10010)  # none, I/O 1 byte, I/O 2 words, PCP 1 word, ExtReg 16 words
SITUATIONS = ("idle", "latch phase", "bus running")
WRITE_VALUE = 0xA5  # sets reserved bits of SET (bit 5) and IRQ_EN (bit 7); a valid SET code (CL = 101)


def prepared(mode: Mode, strict: bool, pedantic: bool, set_value: int | None, situation: str) -> UpInterface:
    """An initialized interface with data in the registers: OUT latched, events pending, an echo byte left."""
    registers = RegisterFile(RB_UP, strict=strict, pedantic=pedantic)
    up = UpInterface(registers)
    assert up.initialize(mode)
    with registers.violations.deferred(), registers.pedantic_paused():
        if set_value is not None:
            registers.cpu_write(13, set_value)
        registers.cpu_write(14, 0x7F)
        if registers.internal_data_path and registers.data_bytes():
            registers.latch(bytes(range(0x31, 0x31 + registers.data_bytes())))
        registers.event("VALID")
        registers.set_io_access(True)
        registers.cpu_write(7, 0x3C)
    registers.violations.records.clear()
    up.transfer(0x47, s_r=True)  # write ALARM: leaves a command and an echo byte behind
    up.transfer(0x5E, s_r=True)
    registers.set_latch_phase(situation == "latch phase")
    registers.set_bus_running(situation == "bus running")
    return up


def outcome(up: UpInterface, access: Callable[..., object], *args: int) -> tuple[object, ...]:
    """What ``access(up, *args)`` returned or raised, and everything it changed."""
    try:
        result: object = access(up, *args)
    except Exception as error:  # compared by type and message
        result = (type(error), str(error))
    p, r = up.protocol, up.registers
    return (result, p.mode, p.phase, p.command, p.last_rx, p._frame,
            tuple(r.value(x.name) for x in REGISTER_MAP.registers), r.configured, r.data_bits(), r.irq_n,
            [(type(v), str(v)) for v in r.violations.records])


def by_bytes_read(up: UpInterface, address: int) -> int | None:
    intel = up.protocol.mode is Mode.INTEL
    up.transfer(encode_command(address, rd=True), s_r=True)
    return up.transfer(0, s_r=False if intel else None)


def by_bytes_write(up: UpInterface, address: int, value: int) -> None:
    up.transfer(encode_command(address, wr=True), s_r=True)
    up.transfer(value, s_r=True)


@pytest.mark.parametrize("mode", list(Mode))
@pytest.mark.parametrize("strict", [True, False])
@pytest.mark.parametrize("pedantic", [False, True])
@pytest.mark.parametrize("set_value", SET_VALUES)
def test_read_and_write_equal_their_bytes(mode: Mode, strict: bool, pedantic: bool, set_value: int | None) -> None:
    for situation, address in itertools.product(SITUATIONS, range(BLOCK_ADDRESS)):
        fast, slow = (prepared(mode, strict, pedantic, set_value, situation) for _ in range(2))
        assert outcome(fast, UpInterface.read, address) == outcome(slow, by_bytes_read, address), (situation, address)
        fast, slow = (prepared(mode, strict, pedantic, set_value, situation) for _ in range(2))
        assert outcome(fast, UpInterface.write, address, WRITE_VALUE) == outcome(
            slow, by_bytes_write, address, WRITE_VALUE), (situation, address)


def by_frame(up: UpInterface, mosi: int, s_r: bool) -> int | None:
    """One byte as the protocol's frame calls, the reference of ``transfer``."""
    protocol: UpifProtocol = up.protocol
    with protocol.registers.violations.deferred():
        tx = protocol.begin(s_r)
        protocol.end(tx if tx is not None and protocol.mode is Mode.INTEL else mosi)
    return tx


BYTES = st.one_of(
    st.sampled_from([0x00, 0x81, 0x0F, 0x4F, 0x8F, 0xCF, 0x30, 0x3D, 0xF4]),  # init, block, reserved bits
    st.integers(0x40, 0x4E), st.integers(0x80, 0x8E), st.integers(0xC0, 0xCE), st.integers(0, 0xFF),
)


@given(
    stream=st.lists(st.tuples(BYTES, st.booleans()), max_size=40),
    strict=st.booleans(), pedantic=st.booleans(), latch_phase=st.booleans(), bus_running=st.booleans(),
)
def test_transfer_equals_one_frame(stream: list[tuple[int, bool]], strict: bool, pedantic: bool, latch_phase: bool,
                                   bus_running: bool) -> None:
    fast, slow = (UpInterface(RegisterFile(RB_UP, strict=strict, pedantic=pedantic)) for _ in range(2))
    for up in (fast, slow):
        up.registers.set_latch_phase(latch_phase)
        up.registers.set_bus_running(bus_running)
    for mosi, s_r in stream:
        assert outcome(fast, lambda up, m, s: up.transfer(m, s_r=bool(s)), mosi, s_r) == outcome(
            slow, lambda up, m, s: by_frame(up, m, bool(s)), mosi, s_r), (mosi, s_r)

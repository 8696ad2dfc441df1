"""The Python firmware driver (supi3.sdk.driver) against the transaction-level model, with hostile calls.

Manual 3.4.3 to 3.4.14. The driver must send the bytes ``supi3.c`` sends (3.4.5's 4Dh 82h 4Ch 01h, Fig. 3-12's
8Fh + reads), refuse bad calls before the first byte, carry transport failures as TransportError and let the
model's own rule violations through unchanged; the async driver sends exactly what the sync one sends.
"""

from __future__ import annotations

import asyncio
import re
from collections.abc import Callable
from typing import Any

import pytest
from hypothesis import given
from hypothesis import strategies as st

from supi3 import sdk
from supi3.config import decode
from supi3.model.registers import ReconfigurationError, RegisterFile
from supi3.optical import length
from supi3.regmap import (
    ALARM,
    ID,
    IN0,
    IN1,
    IRQ_EN,
    IRQ_EVT,
    OUT0,
    OUT1,
    PCMD,
    REGISTER_MAP,
    SET,
    AccessDirection,
    Register,
)
from supi3.sdk import include_dir
from supi3.sdk.driver import (
    ERROR_CODES,
    AsyncSupi3Driver,
    AsyncTransport,
    DriverArgumentError,
    ErrorCode,
    IoWindowTimeoutError,
    Irq,
    Mode,
    NotInitializedError,
    NotReadyError,
    NotResetError,
    OpticalStatus,
    Supi3Driver,
    TransportError,
    UnsupportedError,
    get_u16,
    get_u32,
    optical_length_cm,
    optical_length_code,
    put_u16,
    put_u32,
)
from supi3.sdk.transports import ModelTransport, SpidevTransport
from support import bad


class Recording(ModelTransport):
    """The model, with every frame logged as (tx, s_r, rx)."""

    def __init__(self, registers: RegisterFile | None = None, *, sas: bool = True, io: bool = False) -> None:
        super().__init__(registers or RegisterFile(decode("10011", "1110")))
        self.log: list[tuple[int, bool, int]] = []
        self.sas = sas
        self.io = io
        self.fail_at: int | None = None

    def xfer(self, tx: int, s_r: bool) -> int:
        if self.fail_at is not None and len(self.log) == self.fail_at:
            raise OSError("SPI controller timeout")
        rx = super().xfer(tx, s_r)
        self.log.append((tx, s_r, rx))
        return rx

    def set_sas_init(self, level: int) -> bool:
        return super().set_sas_init(level) if self.sas else False

    def read_io(self) -> int | None:  # the pin is optional here
        return super().read_io() if self.io else None

    @property
    def sent(self) -> list[int]:
        return [tx for tx, _, _ in self.log]


def driver(mode: Mode = Mode.MOTOROLA, **kwargs: Any) -> tuple[Supi3Driver, Recording]:
    transport = Recording(**kwargs)
    drv = Supi3Driver(transport)
    drv.initialize(mode)
    transport.log.clear()
    return drv, transport


MODES = pytest.mark.parametrize("mode", list(Mode), ids=[m.value for m in Mode])


# ------------------------------------------------------------------------------------------------------------
# One API with the C driver
# ------------------------------------------------------------------------------------------------------------


def test_error_codes_are_the_c_drivers() -> None:
    header = (sdk.include_dir() / "supi3.h").read_text(encoding="utf-8")
    declared = {name: int(value) for name, value in re.findall(r"\b(SUPI3_(?:OK|E_\w+))\s*=\s*(-?\d+)", header)}
    assert declared == ERROR_CODES


def test_every_driver_error_names_its_c_code() -> None:
    errors = (DriverArgumentError, NotInitializedError, TransportError, NotReadyError, NotResetError,
              UnsupportedError, IoWindowTimeoutError)  # fmt: skip
    assert {e.code for e in errors} == set(ErrorCode) - {ErrorCode.OK}


def test_irq_flags_are_the_register_maps_bits() -> None:
    assert {flag.name: flag.value for flag in Irq} == {
        f.name: f.mask for f in IRQ_EN.fields if f.name != "IO_ACCESS"
    }


# ------------------------------------------------------------------------------------------------------------
# The manual's byte sequences
# ------------------------------------------------------------------------------------------------------------


@MODES
def test_configuration_sends_the_manuals_bytes(mode: Mode) -> None:
    drv, t = driver(mode)
    drv.configure(0x82, 0x01)
    assert t.sent == [0x4D, 0x82, 0x4C, 0x01]  # 3.4.5
    assert t.registers.bus_id_register() & 0x1FFF == 0x0901
    assert (drv.read(SET), drv.read(ID)) == (0x82, 0x01)


@MODES
def test_read_and_write_reach_the_data_registers(mode: Mode) -> None:
    drv, t = driver(mode)
    drv.configure(0x83, 0x01)  # 1 word
    drv.write(IN0, 0x12)
    drv.write(IN1, 0x34)
    assert t.registers.in_bytes() == b"\x12\x34"
    t.registers.latch(b"\xab\xcd")
    assert (drv.read(OUT0), drv.read(OUT1)) == (0xAB, 0xCD)
    t.log.clear()
    drv.read(OUT1)
    assert [(tx, s_r) for tx, s_r, _ in t.log] == [(0x81, True), (0x00, False)]  # S/R = 0: the chip sends


def test_intel_block_read_is_figure_3_12() -> None:
    drv, t = driver(Mode.INTEL)
    drv.configure(0x84, 0x03)  # 3 bytes
    t.registers.latch(b"\x14\x56\x78")
    t.log.clear()
    assert drv.block_transfer(b"\0\0\0", write=False) == b"\x14\x56\x78"
    assert t.sent[0] == 0x8F and len(t.log) == 4  # 8Fh, three reads (Fig. 3-12)


@MODES
def test_block_transfer_exchanges_every_data_byte(mode: Mode) -> None:
    drv, t = driver(mode)
    drv.configure(0x85, 0x03)  # 2 words
    t.registers.latch(b"\x01\x02\x03\x04")
    assert drv.block_transfer(put_u32(0xA1B2C3D4)) == b"\x01\x02\x03\x04"
    assert get_u32(t.registers.in_bytes()) == 0xA1B2C3D4
    assert t.protocol.c_d == 0


def test_exchange_is_motorola_only() -> None:
    drv, t = driver()
    drv.configure(0x82, 0x01)
    t.registers.latch(b"\x77")
    assert drv.exchange(OUT0, 0x55) == 0x77
    assert t.registers.in_bytes() == b"\x55"
    intel, t2 = driver(Mode.INTEL)
    with pytest.raises(UnsupportedError, match="Motorola"):
        intel.exchange(IN0, 1)
    assert t2.log == []


@MODES
def test_irq_service_reads_and_clears_and_skips_when_irq_is_high(mode: Mode) -> None:
    drv, t = driver(mode)
    drv.configure(0x82, 0x01)
    drv.irq_enable(Irq.VALID | Irq.PCMD)
    t.log.clear()
    assert drv.irq_service() == Irq(0)
    assert t.log == []  # /IRQ high: nothing sent
    t.registers.event("VALID")
    t.registers.processor_command(0x5A)
    assert drv.irq_service() == Irq.VALID | Irq.PCMD
    assert t.registers.irq_n == 1
    assert drv.processor_command() == 0x5A


@MODES
def test_poll_io_window_keeps_the_events_it_cleared(mode: Mode) -> None:
    drv, t = driver(mode)
    drv.configure(0x82, 0x01)
    drv.irq_enable(Irq.VALID)
    t.log.clear()
    t.registers.event("VALID")
    t.registers.set_io_access(True)
    with pytest.raises(IoWindowTimeoutError, match="3 polls") as caught:
        drv.poll_io_window(3)
    assert caught.value.events == Irq.VALID and caught.value.code == ErrorCode.E_TIMEOUT
    assert len(t.log) == 6
    t.registers.set_io_access(False)
    assert drv.poll_io_window(1) == Irq(0)


def test_poll_io_window_uses_the_pin_when_wired() -> None:
    drv, t = driver(io=True)
    t.registers.set_io_access(True)
    with pytest.raises(IoWindowTimeoutError):
        drv.poll_io_window(5)
    t.registers.set_io_access(False)
    assert drv.poll_io_window(1) == Irq(0)
    assert t.log == []


@MODES
def test_alarm_and_optical_status(mode: Mode) -> None:
    drv, t = driver(mode)
    drv.processor_alarm(0xC3)
    assert t.registers.processor_alarm == 0xC3
    t.registers.set_optical("LENGTH_OUT", 0b1100_0101)
    t.registers.set_optical("LENGTH_BRANCH", 0b0011_1111)
    t.registers.set_optical("POWER_IN", 0b1000_1111)
    t.registers.set_optical("POWER_OUT_BRANCH", 0x3C)
    assert drv.optical_status() == OpticalStatus(5, 1, 1, 63, 0, 0, 15, 1, 12, 3)


# ------------------------------------------------------------------------------------------------------------
# Start-up and recovery (3.4.3; UP-3, UP-4, UP-27)
# ------------------------------------------------------------------------------------------------------------


@MODES
def test_a_chip_that_was_not_reset_is_reported_and_recovered(mode: Mode) -> None:
    drv, t = driver(mode)
    other = Mode.INTEL if mode is Mode.MOTOROLA else Mode.MOTOROLA
    t.registers.violations.strict = False  # the model reports the locked mode (UP-29) as well
    with pytest.raises(NotResetError, match="SAS_INIT"):
        Supi3Driver(t).initialize(other)
    assert t.protocol.c_d == 0  # the driver completed the command the byte became
    t.registers.violations.strict = True
    drv.sas_init()
    assert not drv.initialized
    drv.initialize(other)
    assert t.protocol.mode is other


def test_data_phase_before_the_init_byte_sends_nothing() -> None:
    drv, t = driver()
    t.xfer(0x80, True)  # a command whose data byte never came (µP reset mid-command)
    t.log.clear()
    with pytest.raises(NotReadyError):
        drv.initialize(Mode.MOTOROLA)
    assert t.log == [] and not drv.initialized


def test_sas_init_needs_the_pin() -> None:
    drv, t = driver(sas=False)
    with pytest.raises(UnsupportedError, match="SAS_INIT"):
        drv.sas_init()
    assert t.log == []


def test_a_transport_failure_leaves_the_driver_uninitialized() -> None:
    drv, t = driver()
    t.fail_at = 1  # the data byte of the next access fails
    with pytest.raises(TransportError, match="SPI controller timeout") as caught:
        drv.write(IN0, 1)
    assert isinstance(caught.value.__cause__, OSError)
    assert not drv.initialized
    t.fail_at = None
    with pytest.raises(NotInitializedError):
        drv.read(OUT0)


def test_model_violations_pass_through_with_the_access_complete() -> None:
    drv, t = driver()
    drv.configure(0x82, 0x01)
    t.registers.set_bus_running(True)
    with pytest.raises(ReconfigurationError):
        drv.write(SET, 0x83)
    assert t.protocol.c_d == 0 and drv.initialized  # back in the command phase (UP-28)


# ------------------------------------------------------------------------------------------------------------
# Hostile calls: refused before the first byte
# ------------------------------------------------------------------------------------------------------------

HOSTILE: list[tuple[str, Callable[[Supi3Driver], object], str]] = [
    ("read int", lambda d: d.read(0), r"register must be a supi3.regmap.Register, not 0 .*named objects"),  # type: ignore[arg-type]
    ("read write-only", lambda d: d.read(IN0), r"register IN0 cannot be read at address 0"),
    ("read alarm", lambda d: d.read(ALARM), r"register ALARM cannot be read"),
    ("write read-only", lambda d: d.write(OUT0, 1), r"register OUT0 cannot be written"),
    ("write pcmd", lambda d: d.write(PCMD, 1), r"register PCMD cannot be written"),
    ("write 256", lambda d: d.write(IN0, 256), r"value must be"),
    ("write bool", lambda d: d.write(IN0, True), r"value must be"),
    ("write str", lambda d: d.write(IN0, "1"), r"value must be"),  # type: ignore[arg-type]
    ("exchange value", lambda d: d.exchange(OUT0, -1), r"value must be"),
    ("block short", lambda d: d.block_transfer(b"\0"), r"in_data must be 2 to 4 bytes"),
    ("block long", lambda d: d.block_transfer(bytes(5)), r"in_data must be 2 to 4 bytes"),
    ("block str", lambda d: d.block_transfer("ab"), r"in_data must be"),  # type: ignore[arg-type]
    ("block read", lambda d: d.block_transfer(b"\0\0", read=1), r"read must be"),  # type: ignore[arg-type]
    ("configure", lambda d: d.configure(0x182, 1), r"set_value must be"),
    ("configure id", lambda d: d.configure(0x82, None), r"id_code must be"),  # type: ignore[arg-type]
    ("irq bit 7", lambda d: d.irq_enable(0x80), r"bit 7 is reserved, RM-7"),
    ("irq str", lambda d: d.irq_enable("VALID"), r"mask must be"),  # type: ignore[arg-type]
    ("poll 0", lambda d: d.poll_io_window(0), r"max_polls must be"),
    ("poll float", lambda d: d.poll_io_window(2.5), r"max_polls must be"),  # type: ignore[arg-type]
    ("alarm", lambda d: d.processor_alarm(300), r"value must be"),
    ("init mode", lambda d: d.initialize("motorola"), r"mode must be Mode.MOTOROLA or Mode.INTEL"),  # type: ignore[arg-type]
]


@pytest.mark.parametrize(("call", "message"), [(c, m) for _, c, m in HOSTILE], ids=[i for i, _, _ in HOSTILE])
def test_hostile_calls_are_refused_before_the_first_byte(call: Callable[[Supi3Driver], object], message: str) -> None:
    drv, t = driver()
    drv.configure(0x83, 0x01)
    t.log.clear()
    before = (t.protocol.phase, t.registers.in_bytes(), drv.initialized)
    with pytest.raises(DriverArgumentError, match=message) as caught:
        call(drv)
    assert isinstance(caught.value, (TypeError, ValueError)) and caught.value.code == ErrorCode.E_ARG
    assert t.log == [] and (t.protocol.phase, t.registers.in_bytes(), drv.initialized) == before


def test_block_length_must_be_sets_once_set_went_through_the_driver() -> None:
    drv, t = driver()
    drv.configure(0x82, 0x01)  # 1 byte: no block transfer
    t.log.clear()
    with pytest.raises(DriverArgumentError, match="SET = 82h"):
        drv.block_transfer(b"\0\0")
    assert t.log == []


@pytest.mark.parametrize("call", [
    lambda d: d.read(OUT0), lambda d: d.write(IN0, 1), lambda d: d.exchange(IN0, 1),
    lambda d: d.block_transfer(b"\0\0"), lambda d: d.configure(0x82, 1), lambda d: d.irq_enable(Irq.VALID),
    lambda d: d.irq_service(), lambda d: d.poll_io_window(1), lambda d: d.processor_alarm(1),
    lambda d: d.processor_command(), lambda d: d.optical_status(),
])  # fmt: skip
def test_every_access_before_initialize_sends_nothing(call: Callable[[Supi3Driver], object]) -> None:
    t = Recording()
    with pytest.raises(NotInitializedError, match="initialize"):
        call(Supi3Driver(t))
    assert t.log == []


def test_bad_construction() -> None:
    with pytest.raises(DriverArgumentError, match="transport must be"):
        Supi3Driver(object())  # type: ignore[arg-type]
    with pytest.raises(DriverArgumentError, match="AsyncTransport"):
        AsyncSupi3Driver(Recording())  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="frame_gap_us"):
        Supi3Driver(Recording(), frame_gap_us=-1)


# ------------------------------------------------------------------------------------------------------------
# Async: the same bytes
# ------------------------------------------------------------------------------------------------------------


class AsyncModel(AsyncTransport):
    def __init__(self, inner: Recording) -> None:
        self.inner = inner

    async def xfer(self, tx: int, s_r: bool) -> int:
        await asyncio.sleep(0)
        return self.inner.xfer(tx, s_r)

    async def read_cd(self) -> int | None:
        return self.inner.read_cd()

    async def read_irq(self) -> int | None:
        return self.inner.read_irq()

    async def set_sas_init(self, level: int) -> bool:
        return self.inner.set_sas_init(level)


CALLS = st.sampled_from(["read", "write", "block", "irq", "service", "alarm", "command", "optical", "sas", "poll"])


def plan(d: Any, name: str, v: int) -> Any:
    """One call on a sync or async driver (the async one returns a coroutine)."""
    if name == "init" or not d.initialized:
        return d.initialize(d.wanted)
    calls: dict[str, Callable[[], Any]] = {
        "read": lambda: d.read(OUT1), "write": lambda: d.write(IN1, v), "block": lambda: d.block_transfer(put_u16(v)),
        "irq": lambda: d.irq_enable(v & 0x7F), "service": lambda: d.irq_service(),
        "alarm": lambda: d.processor_alarm(v),
        "command": lambda: d.processor_command(), "optical": lambda: d.optical_status(), "sas": lambda: d.sas_init(),
        "poll": lambda: d.poll_io_window(2), "configure": lambda: d.configure(0x83, 0x01),
    }  # fmt: skip
    return calls[name]()


@given(mode=st.sampled_from(list(Mode)), calls=st.lists(st.tuples(CALLS, st.integers(0, 255)), max_size=12))
def test_async_driver_sends_what_the_sync_driver_sends(mode: Mode, calls: list[tuple[str, int]]) -> None:
    sync_t, async_t = Recording(), Recording()
    for t in (sync_t, async_t):
        t.registers.violations.strict = False
    sync_d, async_d = Supi3Driver(sync_t), AsyncSupi3Driver(AsyncModel(async_t))
    steps = [("init", 0), ("configure", 0), *calls]
    sync_d.wanted = async_d.wanted = mode  # type: ignore[attr-defined]

    sync_results: list[object] = []
    for name, v in steps:
        try:
            sync_results.append(plan(sync_d, name, v))
        except Exception as error:
            sync_results.append(type(error))

    async def run() -> list[object]:
        results: list[object] = []
        for name, v in steps:
            try:
                results.append(await plan(async_d, name, v))
            except Exception as error:
                results.append(type(error))
        return results

    assert asyncio.run(run()) == sync_results
    assert async_t.log == sync_t.log


# ------------------------------------------------------------------------------------------------------------
# Byte significance helpers (3.4.8)
# ------------------------------------------------------------------------------------------------------------


@given(st.integers(0, 0xFFFF), st.integers(0, 0xFFFF_FFFF))
def test_word_helpers_put_the_msb_in_byte_0(word: int, value: int) -> None:
    assert put_u16(word)[0] == word >> 8 and get_u16(put_u16(word)) == word
    assert put_u32(value)[0] == value >> 24 and get_u32(put_u32(value)) == value


@pytest.mark.parametrize(("call", "message"), [
    (lambda: put_u16(0x10000), "value must be"), (lambda: put_u32(-1), "value must be"),
    (lambda: get_u16(b"\0"), "data must be 2 bytes"), (lambda: get_u32(b"\0\0"), "data must be 4 bytes"),
    (lambda: get_u16([1, 2]), "data must be"),  # type: ignore[arg-type]
])  # fmt: skip
def test_word_helpers_refuse_bad_input(call: Callable[[], object], message: str) -> None:
    with pytest.raises(ValueError, match=message):
        call()


# ------------------------------------------------------------------------------------------------------------
# spidev (its module stubbed, not our driver)
# ------------------------------------------------------------------------------------------------------------


class FakeSpiDev:
    def __init__(self) -> None:
        self.opened: tuple[int, int] | None = None
        self.mode = 0
        self.lsbfirst = False
        self.max_speed_hz = 0
        self.frames: list[list[int]] = []
        self.fail = False

    def open(self, bus: int, device: int) -> None:
        self.opened = (bus, device)

    def xfer(self, data: list[int]) -> list[int]:
        if self.fail:
            raise OSError(5, "Input/output error")
        self.frames.append(list(data))
        return [0xA5]

    def close(self) -> None:
        self.opened = None


class FakeSpidevModule:
    SpiDev = FakeSpiDev


def test_spidev_transport_sends_one_frame_per_byte_in_mode_3() -> None:
    s_r: list[int] = []
    transport = SpidevTransport(0, 1, mode=Mode.INTEL, speed_hz=1_000_000, set_s_r=s_r.append,
                                read_cd=lambda: 0, spidev_module=FakeSpidevModule)  # fmt: skip
    spi = transport.spi
    assert (spi.opened, spi.mode, spi.lsbfirst, spi.max_speed_hz) == ((0, 1), 3, True, 1_000_000)
    drv = Supi3Driver(transport)
    drv.initialize(Mode.INTEL)
    assert drv.read(OUT0) == 0xA5
    assert spi.frames == [[0x81], [0x80], [0x00]] and s_r == [1, 1, 0]
    spi.fail = True
    with pytest.raises(TransportError, match="Input/output error"):
        drv.read(IRQ_EVT)
    transport.close()
    assert spi.opened is None


def test_spidev_transport_refuses_intel_without_s_r() -> None:
    with pytest.raises(DriverArgumentError, match="set_s_r must be a callable"):
        SpidevTransport(0, 0, mode=Mode.INTEL, spidev_module=FakeSpidevModule)
    with pytest.raises(DriverArgumentError, match="read_irq must be a callable"):
        SpidevTransport(0, 0, read_irq=3, spidev_module=FakeSpidevModule)  # type: ignore[arg-type]


def test_registers_are_named_objects() -> None:
    drv, _ = driver()
    assert isinstance(OUT0, Register)
    assert drv.read(IRQ_EVT) & 0x80 == 0


# ------------------------------------------------------------------------------------------------------------
# The model's shortcut for whole accesses has exactly the effect of the frames
# ------------------------------------------------------------------------------------------------------------

READABLE = [r for r in REGISTER_MAP.registers if any(r is REGISTER_MAP.port(r.address, d).register
                                                   for d in [AccessDirection.READ])]  # fmt: skip
WRITABLE = [r for r in REGISTER_MAP.registers if r is REGISTER_MAP.port(r.address, AccessDirection.WRITE).register]
OPS = st.one_of(
    st.tuples(st.just("read"), st.sampled_from(READABLE), st.just(0)),
    st.tuples(st.just("write"), st.sampled_from(WRITABLE), st.integers(0, 255)),
    st.tuples(st.sampled_from(["sas", "init", "raw", "latch", "running"]), st.just(IN0), st.integers(0, 255)),
)


def apply_op(drv: Supi3Driver, t: ModelTransport, mode: Mode, name: str, register: Register, value: int) -> object:
    calls: dict[str, Callable[[], object]] = {
        "read": lambda: drv.read(register), "write": lambda: drv.write(register, value), "sas": drv.sas_init,
        "init": lambda: drv.initialize(mode),
        "raw": lambda: t.xfer(value, True),  # a stray byte: the chip may now wait for a data byte
        "latch": lambda: t.registers.latch(bytes(t.registers.data_bytes())),
        "running": lambda: t.registers.set_bus_running(bool(value & 1)),
    }  # fmt: skip
    return calls[name]()


@given(mode=st.sampled_from(list(Mode)), strict=st.booleans(), pedantic=st.booleans(),
       ops=st.lists(OPS, max_size=25))  # fmt: skip
def test_the_direct_path_has_the_effect_of_the_frames(mode: Mode, strict: bool, pedantic: bool,
                                                      ops: list[tuple[str, Register, int]]) -> None:  # fmt: skip
    fast_t = ModelTransport(RegisterFile(decode("10011", "1110"), strict=strict, pedantic=pedantic))
    slow_t = Recording(RegisterFile(decode("10011", "1110"), strict=strict, pedantic=pedantic))
    assert fast_t.direct() is not None and slow_t.direct() is None
    outcomes: list[list[object]] = [[], []]
    for k, t in enumerate((fast_t, slow_t)):
        drv = Supi3Driver(t)
        for name, register, value in [("init", IN0, 0), *ops]:
            try:
                outcomes[k].append(apply_op(drv, t, mode, name, register, value))
            except Exception as error:
                outcomes[k].append((type(error), str(error)))
        outcomes[k] += [t.protocol.phase, t.protocol.c_d, [(type(v), str(v)) for v in t.registers.violations.records],
                        [t.registers.value(r.name) for r in REGISTER_MAP.registers if r.name != "IRQ_EVT"]]  # fmt: skip
    assert outcomes[0] == outcomes[1]


def test_optical_length_conversions_match_the_c_header_and_opt_1() -> None:
    header = (include_dir() / "supi3.h").read_text(encoding="utf-8")
    defines = dict(re.findall(r"#define SUPI3_OPTICAL_(\w+) (\d+)u", header))
    assert int(defines["POLYMER_UNIT_CM"]) == round(length.POLYMER_UNIT_M * 100)
    assert int(defines["GLASS_UNIT_CM"]) == round(length.GLASS_UNIT_M * 100)
    assert int(defines["LENGTH_MAX_CODE"]) == length.LENGTH_MAX_CODE
    assert int(defines["MAX_PATH_CM"]) == round(length.MAX_PATH_M * 100)
    for medium in (0, 1):
        for code in range(64):
            low, high = optical_length_cm(code, medium)
            assert optical_length_code(low, medium) == code == optical_length_code(high - 1, medium)
    assert optical_length_code(15_000, 0) == 24 and optical_length_cm(63, 0) == (39_375, 2_000_000)
    for call in (lambda: optical_length_cm(64, 0), lambda: optical_length_cm(0, 2),
                 lambda: optical_length_code(2_000_001, 0), lambda: optical_length_code(bad(1.5), 0),
                 lambda: optical_length_code(0, bad(True))):
        with pytest.raises(DriverArgumentError):
            call()

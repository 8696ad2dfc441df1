"""The RTL back end of the firmware SDK (``supi3.sdk.rtl``) as a hostile user drives it (not in hostile review 10's
run): wrong types and ranges, wrong orders (before ``RtlBoard.start``, started twice, ``RtlBench.call`` twice or
while one runs), a chip strapped without the µP interface, and the transport contract of docs/sdk.md shared with
the other transports (a status pin the chip does not drive is no "not wired" ``None``).

Each entry checks its arguments before its first await, so the refusals are tested on a stand-in for the cocotb
handle, without a simulation; tests/test_sdk_rtl.py runs the back end on the Verilator build, and the slow test here
runs one ``RtlBench`` through two calls on it.
"""

from __future__ import annotations

from collections.abc import Callable, Coroutine
from pathlib import Path
from typing import Any

import pytest

from supi3.config import decode
from supi3.errors import ArgumentError
from supi3.sdk.bench import DEFAULT_STRAPS, Firmware, default_config
from supi3.sdk.driver import AsyncSupi3Driver, DriverArgumentError, Mode, Supi3Driver
from supi3.sdk.examples import DigitalIo
from supi3.spi.master import MasterTiming

rtl = pytest.importorskip("supi3.sdk.rtl", reason="cocotb is not installed (pip install -e '.[rtl]')")


class Signal:
    """A cocotb handle's ``value``."""

    def __init__(self, value: int = 0) -> None:
        self.value = value


class Dut:
    """A stand-in for the ``supi3_chip`` top's handle: only the signals the entries touch without awaiting."""

    def __init__(self) -> None:
        self.mfp_in, self.mfp_oe, self.mfp_out, self.stat_err_n = Signal(), Signal(), Signal(), Signal(1)


def board() -> Any:
    return rtl.RtlBoard(Dut(), default_config(500_000))


def refused_at_once(coroutine: Coroutine[Any, Any, object]) -> None:
    """Run a coroutine to its first await: it must raise before (a refusal sends nothing, waits for nothing)."""
    try:
        coroutine.send(None)
    finally:
        coroutine.close()
    raise AssertionError("the call awaited before refusing")  # pragma: no cover


class Quiet(Firmware):
    """A firmware that does nothing."""


# The board ------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("levels", "match"),
    [
        ({"irq_n": 1}, r"pin must be one of the µP inputs .*'irq_n'"),  # an output
        ({"sclk": 0, "mosi": 1}, r"'mosi'"),
        ({"sclk": 2}, r"sclk must be an integer from 0 to 1"),
        ({"ss_n": True}, r"ss_n must be an integer"),
        ({"sas_init": "1"}, r"sas_init must be an integer"),
    ],
)
def test_drive_up_refuses_what_is_no_input_or_no_bit_and_changes_no_pin(levels: dict[str, Any], match: str) -> None:
    """Before, an unknown name was a bare ``KeyError`` and a level 2 or ``"1"`` drove the pin high (truthiness);
    now a named error, and no pin of the call changed (all or nothing)."""
    b = board()
    before = b.mfp_in
    with pytest.raises(ArgumentError, match=match):
        b.drive_up(**levels)
    assert b.mfp_in == before and b.dut.mfp_in.value == 0


def test_pins_read_by_name_and_status_pins_refuse_to_be_undriven() -> None:
    """``up_output`` refuses a name that is no µP output (was a ``KeyError``); a status pin the chip does not drive
    (no power-up yet, UP-24) is an ``RtlBoardError``, not ``None``, which the driver would take as "not wired" and
    skip its C/D check and /IRQ wait (docs/sdk.md, "A transport implements")."""
    b = board()
    with pytest.raises(ArgumentError, match=r"name must be one of the µP outputs .*'sclk'"):
        b.up_output("sclk")
    assert b.up_output("c_d") is None
    with pytest.raises(rtl.RtlBoardError, match=r"c_d is not driven by the chip: .*\(UP-24\)"):
        b.status_pin("c_d")
    b.dut.mfp_oe.value, b.dut.mfp_out.value = 0b1110, 0b1000  # I/O 0, C/D 0, /IRQ 1 (Tables 3-5, 3-6)
    assert (b.status_pin("io"), b.status_pin("c_d"), b.status_pin("irq_n")) == (0, 0, 1)


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda b: b.returned(0, -1), r"count must be an integer >= 0"),  # was numpy's "negative dimensions"
        (lambda b: b.returned(-3, 4), r"first must be an integer >= 0"),
        (lambda b: b.returned(0.5, 4), r"first must be an integer"),
        (lambda b: b.set_stat_err(1), r"active must be True or False"),  # 1 passed, "no" drove it low
        (lambda b: refused_at_once(b.clocks(-5)), r"count must be an integer >= 0"),  # was no wait at all
        (lambda b: refused_at_once(b.clocks(2.5)), r"count must be an integer"),
    ],
)
def test_the_board_s_other_entries_name_bad_input(call: Callable[[Any], object], match: str) -> None:
    with pytest.raises(ArgumentError, match=match):
        call(board())


def test_a_board_starts_once() -> None:
    """A second ``start`` on one board would run a second clock on ``clk`` and record ``di1`` twice (each change
    then twice in ``returned``); refused by name before it touches a pin. (Each cocotb test makes its own board.)"""
    b = board()
    b.started = True  # as after the first start
    with pytest.raises(rtl.RtlBoardError, match=r"start\(\) called again"):
        refused_at_once(b.start())
    assert b.dut.mfp_in.value == 0


def test_a_board_needs_a_device_config() -> None:
    with pytest.raises(ArgumentError, match=r"config"):
        rtl.RtlBoard(Dut(), "10011")


# The transport --------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("make", "match"),
    [
        (lambda: rtl.RtlTransport("board"), r"board must be"),
        (lambda: rtl.RtlTransport(board(), 0), r"mode must be Mode.MOTOROLA or Mode.INTEL, not 0"),
        (lambda: rtl.RtlTransport(board(), timing=(2, 3, 4)), r"timing must be"),  # was an AttributeError later
        (lambda: rtl.RtlTransport(board(), io_pin=1), r"io_pin must be True or False"),
        (lambda: rtl.RtlTransport(rtl.RtlBoard(Dut(), decode(DEFAULT_STRAPS[0], "0000"))),
         r"Init-µP mode .*in 2 IN/2 OUT the chip has no serial µP interface"),  # as UpInterface
    ],
)
def test_the_transport_is_refused_with_what_it_cannot_drive(make: Callable[[], object], match: str) -> None:
    with pytest.raises(ArgumentError, match=match):
        make()


@pytest.mark.parametrize(
    ("call", "error", "match"),
    [
        (lambda t: t.xfer(0x100, True), ArgumentError, r"tx must be an integer from 0 to 255"),  # was sent as 00h
        (lambda t: t.xfer(-1, True), ArgumentError, r"tx must be"),  # was sent as FFh
        (lambda t: t.xfer(0x12, 1), ArgumentError, r"s_r must be True or False"),
        (lambda t: t.delay_us(-1.0), ArgumentError, r"us must be a finite number"),
        (lambda t: t.delay_us(float("nan")), ArgumentError, r"us must be a finite number"),
        (lambda t: t.set_sas_init(2), ArgumentError, r"level must be an integer from 0 to 1"),
        (lambda t: t.xfer(0x12, True), rtl.RtlBoardError, r"xfer\(\) before RtlBoard.start\(\)"),  # was a hang
        (lambda t: t.delay_us(1.0), rtl.RtlBoardError, r"delay_us\(\) before RtlBoard.start\(\)"),
        (lambda t: t.read_cd(), rtl.RtlBoardError, r"read_cd\(\) before RtlBoard.start\(\)"),
        (lambda t: t.read_irq(), rtl.RtlBoardError, r"read_irq\(\) before RtlBoard.start\(\)"),  # was None
        (lambda t: t.read_io(), rtl.RtlBoardError, r"read_io\(\) before RtlBoard.start\(\)"),
        (lambda t: t.set_sas_init(1), rtl.RtlBoardError, r"set_sas_init\(\) before RtlBoard.start\(\)"),
    ],
)
def test_the_transport_s_entries_check_before_they_wait(call: Callable[[Any], Coroutine[Any, Any, object]],
                                                       error: type[Exception], match: str) -> None:  # fmt: skip
    """Arguments first (a direct caller's 256 went out as 00h), then the board's state (before ``start`` the clock
    does not run: a frame waited for ever, ``read_irq`` said "not wired"); nothing driven."""
    transport = rtl.RtlTransport(board())
    with pytest.raises(error, match=match):
        refused_at_once(call(transport))
    assert transport.board.dut.mfp_in.value == 0 and transport.frames == 0


def test_an_unwired_io_pin_reads_none_as_on_the_model_bench() -> None:
    """``io_pin=False`` is "not wired" (``None``, FW-9), whatever the board's state: the driver polls register 14."""
    coroutine = rtl.RtlTransport(board(), io_pin=False).read_io()
    with pytest.raises(StopIteration) as stop:
        coroutine.send(None)
    assert stop.value.value is None


def test_the_drivers_take_only_the_transport_of_their_kind() -> None:
    """``RtlTransport`` is async (``AsyncSupi3Driver``), ``BridgedTransport`` sync (``Supi3Driver``), as docs/sdk.md
    says; the other way round is refused by name, and a bridge over what is no ``AsyncTransport`` too."""
    transport = rtl.RtlTransport(board())
    with pytest.raises(DriverArgumentError, match=r"transport must be a supi3.sdk.driver.Transport"):
        Supi3Driver(transport)
    with pytest.raises(DriverArgumentError, match=r"transport must be a supi3.sdk.driver.AsyncTransport"):
        AsyncSupi3Driver(rtl.BridgedTransport(transport))
    with pytest.raises(DriverArgumentError, match=r"inner must be a supi3.sdk.driver.AsyncTransport"):
        rtl.BridgedTransport(rtl.BridgedTransport(transport))
    assert isinstance(rtl.BridgedTransport(transport), rtl.Transport)


# The ring and the bench -----------------------------------------------------------------------------------------------


def test_the_ring_checks_its_board_and_its_samples_as_the_pin_level_ring() -> None:
    """``RtlRing("x")`` was an ``AttributeError``; samples other than 0/1 went to ``do1`` as they were (PinRing
    refuses them: ``check_trace``); before ``start`` the line is not driven."""
    with pytest.raises(ArgumentError, match=r"board must be"):
        rtl.RtlRing("board")
    ring = rtl.RtlRing(board())
    for samples in ([0, 2, 1], [[0, 1]], "0101", [0.0, 1.0]):
        with pytest.raises(ArgumentError, match=r"samples(\[1\])? must be (a 1-D sequence of integers|an integer) "
                                                r"from 0 to 1"):
            ring.run_samples(samples)
    ring.run_samples([])  # nothing to drive
    with pytest.raises(rtl.RtlBoardError, match=r"run_samples\(\) before RtlBoard.start\(\)"):
        ring.run_samples([1, 1, 0])
    assert ring.cycle == 0 and not len(ring.returned)


@pytest.mark.parametrize(
    ("make", "match"),
    [
        (lambda: rtl.RtlBench("board", Quiet()), r"board must be"),
        (lambda: rtl.RtlBench(board(), DigitalIo), r"firmware must be"),  # the class, not an object
        (lambda: rtl.RtlBench(board(), Quiet(), mode="intel"), r"mode must be Mode.MOTOROLA or Mode.INTEL"),
        (lambda: rtl.RtlBench(board(), Quiet(), cycle_time_s=-1e-3), r"cycle_time_s must be a finite number"),
        (lambda: rtl.RtlBench(board(), Quiet(), io_pin="no"), r"io_pin must be True or False"),
    ],
)
def test_the_bench_is_refused_as_the_model_bench(make: Callable[[], object], match: str) -> None:
    with pytest.raises(ArgumentError, match=match):
        make()


def test_the_bench_s_call_checks_its_scenario_state_and_order() -> None:
    """A scenario that is no callable (was raised in a bridge thread after the firmware's setup had run), a call
    before ``start``, a call while another runs: refused by name, before the firmware's setup."""
    bench = rtl.RtlBench(board(), Quiet())
    with pytest.raises(DriverArgumentError, match=r"scenario must be a callable, not 'play'"):
        refused_at_once(bench.call("play"))
    with pytest.raises(rtl.RtlBoardError, match=r"call\(\) before RtlBoard.start\(\)"):
        refused_at_once(bench.call(lambda: None))
    bench.board.started = True
    bench._calling = True  # as while a call runs
    with pytest.raises(rtl.RtlBoardError, match=r"call\(\) while another call runs"):
        refused_at_once(bench.call(lambda: None))
    with pytest.raises(ArgumentError, match=r"cycles must be an integer >= 0"):
        bench.run(-1)
    assert bench.cycles == 0 and not bench._set_up


def test_one_bench_called_twice_on_the_rtl(chip_build: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """On the Verilator build (sim/sdk_rtl.py ``bench_called_twice``): the setup once, the firmware served in both
    calls (before, the second call ran the setup again and its scenario without a firmware), a second start
    refused, the status pins levels."""
    from test_sdk_rtl import simulate

    simulate(chip_build, tmp_path, monkeypatch, "bench_called_twice")


def test_timing_other_than_the_fastest_is_kept() -> None:
    timing = MasterTiming.fastest(500_000)
    assert rtl.RtlTransport(board(), Mode.INTEL, timing).timing is timing

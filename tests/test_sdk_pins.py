"""The Python driver on the pin-level whole chip (supi3.sdk.pins.PinTransport): the same calls give the same results
as on the transaction-level model, with INTERBUS traffic on the line; strict, so any Table 3-7 or protocol violation
of the software µP would raise."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.config import decode
from supi3.interbus import wire
from supi3.model.registers import RegisterFile
from supi3.regmap import ID, IN0, IN1, IRQ_EVT, OUT0, OUT1, SET
from supi3.sdk.driver import UNDRIVEN_BYTE, DriverArgumentError, Irq, Mode, Supi3Driver, put_u16
from supi3.sdk.pins import PinTransport
from supi3.sdk.transports import ModelTransport
from supi3.tables import BIT_RATES, clk_conf_for
from supi3.top import Supi3Chip
from support import IDLE, RB_INIT_UP, data_frame


def pin_driver(mode: Mode, bit_rate: int = 2_000_000) -> tuple[Supi3Driver, PinTransport]:
    transport = PinTransport(Supi3Chip(decode(*RB_INIT_UP, clk_conf=clk_conf_for(bit_rate))), mode)
    return Supi3Driver(transport), transport


@pytest.mark.parametrize("bit_rate", BIT_RATES)
@pytest.mark.parametrize("mode", list(Mode))
def test_configure_and_exchange_data_with_the_bus_running(mode: Mode, bit_rate: int) -> None:
    drv, t = pin_driver(mode, bit_rate)
    drv.initialize(mode)
    drv.configure(0x83, 0x01)  # 1 word; 3.4.5
    assert (drv.read(SET), drv.read(ID)) == (0x83, 0x01)
    drv.irq_enable(Irq.VALID)
    drv.write(IN0, 0xA5)
    drv.write(IN1, 0x5A)
    samples = wire.levels_to_samples(np.concatenate([IDLE, wire.reset_levels(1), IDLE]), bit_rate)
    t.port.feed(samples)
    while t.port.queued:
        drv.transport.delay_us(10)
    assert drv.irq_service() == Irq(0)  # the INTERBUS reset's event is not enabled
    t.port.feed(wire.levels_to_samples(np.concatenate([data_frame(b"\x12\x34"), IDLE]), bit_rate))
    while t.port.queued:
        drv.transport.delay_us(10)
    assert drv.irq_service() & Irq.VALID
    assert (drv.read(OUT0), drv.read(OUT1)) == (0x12, 0x34)


STEPS = st.lists(st.tuples(st.sampled_from(["read", "write", "block", "irq", "service", "alarm", "command", "sas",
                                            "poll", "evt"]), st.integers(0, 255)), max_size=6)  # fmt: skip


def step(d: Supi3Driver, name: str, v: int, mode: Mode) -> Any:
    if not d.initialized:
        return d.initialize(mode)
    calls: dict[str, Callable[[], Any]] = {
        "read": lambda: d.read(OUT1), "write": lambda: d.write(IN1, v), "block": lambda: d.block_transfer(put_u16(v)),
        "irq": lambda: d.irq_enable(v & 0x7F), "service": lambda: d.irq_service(), "evt": lambda: d.read(IRQ_EVT),
        "alarm": lambda: d.processor_alarm(v), "command": lambda: d.processor_command(), "sas": lambda: d.sas_init(),
        "poll": lambda: d.poll_io_window(2),
    }  # fmt: skip
    return calls[name]()


@settings(max_examples=12, deadline=None)
@given(mode=st.sampled_from(list(Mode)), steps=STEPS)
def test_pin_level_and_transaction_level_give_the_same_results(mode: Mode, steps: list[tuple[str, int]]) -> None:
    pin, pt = pin_driver(mode)
    model = Supi3Driver(ModelTransport(RegisterFile(decode(*RB_INIT_UP, clk_conf=clk_conf_for(2_000_000)))))
    results: list[list[object]] = [[], []]
    for name, v in [("init", 0), *steps]:
        for k, d in enumerate((pin, model)):
            try:
                results[k].append(step(d, name, v, mode))
                if name == "init":
                    d.configure(0x83, 0x01)
            except Exception as error:
                results[k].append(type(error))
    assert results[0] == results[1]
    assert pt.port.registers.in_bytes() == model.transport.registers.in_bytes()  # type: ignore[attr-defined]


@pytest.mark.parametrize("mode", list(Mode))
def test_a_frame_the_chip_does_not_drive_reads_ffh_on_both_transports(mode: Mode) -> None:
    """FW-26: before the initialization byte and in the interface 55h disabled (UP-4) the chip drives no data; the
    line's pull-up reads FFh at both fidelities, as on the emulated board (MCU-6)."""
    _, pin = pin_driver(mode)
    model = ModelTransport(RegisterFile(decode(*RB_INIT_UP, clk_conf=clk_conf_for(2_000_000))))
    for transport in (pin, model):
        assert [transport.xfer(0x55, True), transport.xfer(0x00, True)] == [UNDRIVEN_BYTE] * 2 == [0xFF] * 2


def test_bad_mode_is_refused() -> None:
    with pytest.raises(DriverArgumentError, match="mode must be"):
        PinTransport(Supi3Chip(decode(*RB_INIT_UP)), "intel")  # type: ignore[arg-type]

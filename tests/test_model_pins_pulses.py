"""Pin-level single pulses: /ResReg (3.4.14, Table 3-13, INTERBUS reset: "If no valid INTERBUS cycle is detected
within the time preset by the master ... process data will be reset. The /ResReg signal will be activated ...
A single pulse of 375 ns is generated") and /ModAck, which reuses its width (docs/assumptions/model.md M3). At 32 MHz,
375 ns is exactly 12 clocks; both ``step()`` and ``run()`` must show 12 low cycles (the RTL too:
tests/test_rtl_core.py, test_watchdog_expiry and test_mod_ack_pulse_width).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
import pytest

from supi3 import tables
from supi3.config import DeviceConfig, decode
from supi3.interbus import wire
from supi3.interbus.wire import Cycle
from supi3.model.chip import WATCHDOG_CLOCKS
from supi3.model.pins import Supi3Pins
from support import IDLE, WATCHDOG_LATEST, Columns, frame_levels, pulses

WIDTH = 12
"""375 ns at 32 MHz (Table 3-13), counted here independently of the code under test."""


def _config() -> DeviceConfig:
    return decode("10000", clk_conf="11")


def _columns(config: DeviceConfig, levels: npt.NDArray[np.uint8]) -> Columns:
    do1 = wire.levels_to_samples(levels, config.bit_rate).astype(np.int64)
    n = len(do1)
    ones, zeros = np.ones(n, dtype=np.int64), np.zeros(n, dtype=np.int64)
    return {"do1": do1, "di2": zeros, "rbst_ext": zeros, "mfp_in": zeros, "stat_err_n": ones, "resu_n": ones,
            "vmon_ok": ones, "from_exr": 0 * ones}  # fmt: skip


def _cycle(kind: Cycle, device: bytes) -> npt.NDArray[np.uint8]:
    return np.concatenate([frame_levels(kind, device), IDLE])


def _bring_up(command: int) -> npt.NDArray[np.uint8]:
    return np.concatenate([IDLE, wire.reset_levels(1), IDLE, _cycle(Cycle.ID, wire.word_bytes(command))])


def _step(model: Supi3Pins, columns: Columns) -> Columns:
    names = list(columns)
    rows = [model.step(dict(zip(names, values, strict=True))) for values in zip(*(columns[k].tolist() for k in names),
                                                                                 strict=True)]
    return {name: np.array([row[name] for row in rows], dtype=np.int64) for name in rows[0]}


def test_width_is_375_ns_at_32_mhz(manual_text: str) -> None:
    assert "A single pulse of 375 ns is generated" in manual_text  # Table 3-13
    assert tables.RESREG_PULSE_NS * tables.CLOCK_HZ == WIDTH * 10**9 == tables.RESREG_PULSE_CLOCKS * 10**9


@pytest.mark.parametrize("how", ["run", "step"])
def test_mod_ack_pulse_is_12_clocks(how: str) -> None:
    config = _config()
    columns = _columns(config, _bring_up(wire.command_word(quit_peripheral_error=True)))
    model = Supi3Pins(config)
    out = model.run(columns) if how == "run" else _step(model, columns)
    assert [length for _, length in pulses(out["mod_ack_n"])] == [WIDTH]
    assert out["res_reg_n"].all()


@pytest.mark.parametrize("how", ["run", "step"])
def test_res_reg_pulse_is_12_clocks(how: str) -> None:
    # Watchdog 50 ms (Table 3-13), one latched data cycle, then idle status telegrams past the deadline: process
    # data are reset and /ResReg pulses once. The long idle part runs event-driven; the pulse itself is stepped.
    config = _config()
    head = np.concatenate([_bring_up(wire.command_word(0)), _cycle(Cycle.DATA, b"\x5a\xa5")])
    clocks = WATCHDOG_LATEST + 20_000  # M24: the deadline counts ticks of the time base
    telegrams = clocks // (wire.STATUS_TELEGRAM_BITS * wire.clocks_per_bit(config.bit_rate))
    columns = _columns(config, np.concatenate([head, wire.status_levels(Cycle.DATA, False, telegrams)]))
    model = Supi3Pins(config)
    if how == "run":
        out = model.run(columns)["res_reg_n"]
    else:
        split = len(head) * wire.clocks_per_bit(config.bit_rate) + (WATCHDOG_CLOCKS[0] or 0) - 40_000
        first = model.run({name: trace[:split] for name, trace in columns.items()})["res_reg_n"]
        rest = _step(model, {name: trace[split:] for name, trace in columns.items()})["res_reg_n"]
        out = np.concatenate([first, rest])
    assert [length for _, length in pulses(out)] == [WIDTH]
    assert model.chip.events["WATCHDOG"] == 1


def test_pulses_helper() -> None:
    assert pulses(np.array([1, 0, 0, 1, 0, 1, 1, 0])) == [(1, 2), (4, 1), (7, 1)]

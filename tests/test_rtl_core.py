"""The RTL chip core (supi3.rtl.core) against the cycle-accurate model (supi3.model.pins), every pin every clock."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from supi3.config import DeviceConfig, decode
from supi3.model.chip import STATERR_FILTER_CLOCKS
from supi3.model.pins import Supi3Pins

Columns = dict[str, npt.NDArray[np.int64]]


def quiet_inputs(n: int) -> Columns:
    """``n`` clocks of a quiet board: idle line, no fault, power good, no following device."""
    ones, zeros = np.ones(n, dtype=np.int64), np.zeros(n, dtype=np.int64)
    return {"do1": ones.copy(), "di2": zeros.copy(), "rbst_ext": zeros.copy(), "mfp_in": zeros.copy(),
            "stat_err_n": ones.copy(), "resu_n": ones.copy(), "vmon_ok": ones.copy()}  # fmt: skip


def fast_config(c: str = "10000", mfp: str | None = None) -> DeviceConfig:
    return decode(c, mfp, clk_conf="11")


def test_model_staterr_filter_restarts_after_power_up() -> None:
    # /StatErr low for 1200 clocks, released while a power-up reset holds the chip: no fault may latch later (the
    # model used to keep the level across the power-up and time the 200 ms filter from clock 0).
    n = STATERR_FILTER_CLOCKS + 100_000
    inputs = quiet_inputs(n)
    inputs["stat_err_n"][1000:2200] = 0
    inputs["resu_n"][2000:2500] = 0
    model = Supi3Pins(fast_config())
    model.run(inputs)
    assert not model.chip.pf

"""The pytest plugin (supi3.sdk.pytest_plugin): fixtures as a firmware team uses them, in its own project."""

from __future__ import annotations

import pytest

from supi3.interbus.master import Master
from supi3.interbus.ring import Ring
from supi3.sdk.bench import Bench

pytest_plugins = ["pytester"]


def test_fixtures_in_this_project(supi3_bench: Bench, supi3_ring: Ring, supi3_master: Master) -> None:
    assert supi3_ring is supi3_bench.ring and supi3_master is supi3_bench.master
    supi3_bench.run(2)
    assert supi3_master.config is not None  # the µP_Not_Ready ID code without firmware (3.4.1)


@pytest.mark.supi3(bit_rate=2_000_000)
def test_the_marker_configures_the_bench(supi3_bench: Bench) -> None:
    assert supi3_bench.config.bit_rate == 2_000_000


FIRMWARE_TEST = '''
import pytest
from supi3.regmap import OUT0
from supi3.sdk.bench import Firmware
from supi3.sdk.driver import Irq, Mode


class Dio(Firmware):
    def __init__(self):
        self.out = None

    def setup(self, drv):
        drv.initialize(Mode.INTEL)
        drv.configure(0x82, 0x01)
        drv.irq_enable(Irq.VALID)

    def isr(self, drv):
        if drv.irq_service() & Irq.VALID:
            self.out = drv.read(OUT0)


@pytest.mark.supi3(firmware=Dio(), mode=Mode.INTEL)
def test_outputs_reach_the_firmware(supi3_bench, supi3_master):
    supi3_bench.run(3)
    supi3_master.set_outputs(1, b"\\x5a")
    supi3_bench.run(3)
    assert supi3_bench.firmware.out == 0x5A


@pytest.mark.supi3(3)
def test_positional_marker_arguments_are_refused(supi3_bench):
    pass


@pytest.mark.supi3(bitrate=2_000_000)
def test_unknown_marker_arguments_are_refused(supi3_bench):
    pass
'''


def test_a_firmware_project_uses_the_fixtures(pytester: pytest.Pytester) -> None:
    pytester.makepyfile(test_firmware=FIRMWARE_TEST)
    result = pytester.runpytest("--strict-markers", "-p", "no:cacheprovider")
    result.assert_outcomes(passed=1, errors=2)
    result.stdout.fnmatch_lines(["*keyword arguments of Bench only*not (3,)*",
                                 "*keyword arguments of Bench only*not bitrate*"])

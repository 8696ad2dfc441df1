"""pytest fixtures for firmware tests against the SUPI 3 model (registered as the ``supi3`` pytest plugin).

``pip install supi3`` makes pytest load this module (entry point ``pytest11``), so a firmware team writes::

    from supi3.sdk.bench import Firmware

    @pytest.mark.supi3(bit_rate=2_000_000, firmware=MyFirmware())
    def test_outputs_follow_the_master(supi3_bench):
        supi3_bench.run(5)
        ...

- ``supi3_bench``: a :class:`supi3.sdk.bench.Bench` made from the ``supi3`` marker's keyword arguments (any
  argument of ``Bench``: ``config``, ``firmware``, ``mode``, ``bit_rate``, ``others``, ``sclk_hz``,
  ``frame_gap_us``, ``cycle_time_s``, ``strict``); without the marker, the defaults. Markers of the test, its class
  and its module add up, the closest one's keyword winning (UP-46).
- ``supi3_ring``, ``supi3_master``: that bench's ring and INTERBUS master.

A firmware object keeps its state (a C firmware its statics and ``fw_board_t``), so the marker's ``firmware`` serves
one test: a second test given the same object (``parametrize``, a class or module mark) is an error naming the
first (FW-17); ``pytest.param(..., marks=pytest.mark.supi3(firmware=...))`` gives each case its own.
"""

from __future__ import annotations

import inspect

import pytest

from supi3.interbus.master import Master
from supi3.interbus.ring import Ring
from supi3.sdk.bench import Bench

MARKER = "supi3"
"""The marker whose keyword arguments configure ``supi3_bench``."""
_FIRMWARE_TESTS = pytest.StashKey[dict[int, tuple[object, str]]]()
"""id of each marker firmware that ran -> (the object, kept so that the id stays its, the test it ran in)."""


def pytest_configure(config: pytest.Config) -> None:
    """Register the ``supi3`` marker (so ``--strict-markers`` accepts it)."""
    config.addinivalue_line("markers", f"{MARKER}(**options): keyword arguments of supi3.sdk.bench.Bench for the "
                            "supi3_bench fixture")  # fmt: skip


@pytest.fixture
def supi3_bench(request: pytest.FixtureRequest) -> Bench:
    """A firmware bench (master, ring, chip and firmware on one clock), configured by the ``supi3`` marker."""
    # UP-46: every supi3 marker that reaches the test (its own, its class's, its module's), the closest one's
    # keyword winning; the closest marker alone dropped a class's bit_rate under a test's strict=False
    markers = list(request.node.iter_markers(MARKER))
    if not markers:
        return Bench()
    options: dict[str, object] = {}
    for marker in reversed(markers):  # the farthest first: the closest marker's keywords overwrite
        unknown = sorted(set(marker.kwargs) - set(inspect.signature(Bench).parameters))
        if marker.args or unknown:
            shown = repr(marker.args) if marker.args else ", ".join(unknown)
            raise pytest.UsageError(f"@pytest.mark.{MARKER} takes keyword arguments of Bench only "
                                    f"({', '.join(inspect.signature(Bench).parameters)}), not {shown}")
        options.update(marker.kwargs)
    bench = Bench(**options)  # type: ignore[arg-type]  # its own errors first (a firmware class, say)
    firmware = bench.firmware
    if firmware is not None:
        ran = request.config.stash.setdefault(_FIRMWARE_TESTS, {})
        _, first = ran.setdefault(id(firmware), (firmware, request.node.nodeid))
        if first != request.node.nodeid:
            raise pytest.UsageError(f"@pytest.mark.{MARKER}(firmware=...): this firmware object already ran in "
                                    f"{first} and keeps its state there; a firmware is one per test: "
                                    f"pytest.param(..., marks=pytest.mark.{MARKER}(firmware=...)) per case, or a "
                                    f"marker per test (FW-17)")  # fmt: skip
    return bench


@pytest.fixture
def supi3_ring(supi3_bench: Bench) -> Ring:
    """The bench's transaction-level ring (faults: ``supi3_ring.inject(BitFlip(...))``)."""
    return supi3_bench.ring


@pytest.fixture
def supi3_master(supi3_bench: Bench) -> Master:
    """The bench's INTERBUS master."""
    return supi3_bench.master

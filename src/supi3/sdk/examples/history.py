"""Process data histories: the master's OUT words and the device's IN words, cycle after cycle, on any bench.

The same :func:`play` runs on the transaction-level bench (:class:`supi3.sdk.bench.Bench`) and on the RTL chip
(:class:`supi3.sdk.rtl.RtlBench`): both have a ``master`` and ``run(cycles)``, so a test compares what the two give
for one history.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Final, Protocol

from supi3.interbus.master import Master

__all__ = ["SETTLE_CYCLES", "ProcessBench", "ProcessDevice", "play"]

SETTLE_CYCLES: Final = 3
"""Master cycles per history step: a word set before the first is latched by its end, the firmware's answer is
written after that latch (or in the next access window), during the second when cycles run back to back, and goes
out with the third. (Before MCU-55 and FW-19 two were enough on the transaction-level benches only because their
master had already started a third cycle, and taken its IN data, by the time the run returned.)"""


class ProcessDevice(Protocol):
    """An example firmware with process data: :attr:`inputs` to the master, :attr:`outputs` from it."""

    DATA_BYTES: int
    inputs: int
    outputs: int


class ProcessBench(Protocol):
    """A bench with an INTERBUS master in front of one device (ring position 1)."""

    @property
    def master(self) -> Master:
        """The master."""
        ...

    def run(self, cycles: int) -> None:
        """Run ``cycles`` more master cycles with the firmware."""


def play(bench: ProcessBench, device: ProcessDevice, history: Sequence[tuple[int, int]]) -> list[tuple[int, int]]:
    """For each ``(out, in)`` of ``history``: the master sends ``out``, the device's terminals read ``in``, and
    :data:`SETTLE_CYCLES` cycles later the step records ``(device.outputs, the master's IN word)``. A device that
    passes its data both ways returns ``history``."""
    seen = []
    for out, value in history:
        bench.master.set_outputs(1, out.to_bytes(device.DATA_BYTES, "big"))
        device.inputs = value
        bench.run(SETTLE_CYCLES)
        seen.append((device.outputs, int.from_bytes(bench.master.inputs(1), "big")))
    return seen

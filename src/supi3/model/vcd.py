"""Write a pin-level ring's recorded pins as a VCD waveform (one scope per chip, time in 32 MHz clocks)."""

from __future__ import annotations

from os import PathLike
from pathlib import Path

import numpy as np
from vcd import VCDWriter
from vcd.writer import Variable

from supi3.checks import check_instance, fail
from supi3.model.pinring import PinRing
from supi3.tables import CLOCK_HZ

CLOCK_PS = 10**12 // CLOCK_HZ
"""One 32 MHz clock period in picoseconds (31250), the VCD time step."""


def write_vcd(path: Path, ring: PinRing) -> Path:
    """Write every pin of every chip of ``ring`` (made with ``record=True``) to ``path``.

    Scopes are ``dev1`` .. ``devN`` in ring order; ``dev1.do1`` is the master's forward line and ``dev1.di1``
    the return line into the master. Only changes are written, so the file stays small.

    Raises
    ------
    ArgumentError
        ``path`` is not a path (``str`` or ``os.PathLike``), or ``ring`` not a :class:`PinRing`.
    InterbusError
        The ring does not record its pins.
    """
    if not isinstance(path, (str, PathLike)):
        raise fail("path", "a path (str or os.PathLike)", path)
    path = Path(path)
    check_instance("ring", ring, PinRing)
    chips = ring.recorded()
    widths = {pin.name: pin.width for chip in ring.devices for pin in (*chip.inputs, *chip.outputs)}
    path.parent.mkdir(parents=True, exist_ok=True)
    changes: list[tuple[int, int, Variable[int], int]] = []
    with path.open("w", encoding="ascii") as stream, VCDWriter(stream, timescale="1 ps", date="") as writer:
        for k, traces in enumerate(chips, start=1):
            for name, trace in sorted(traces.items()):
                var = writer.register_var(f"dev{k}", name, "wire", size=widths[name], init=int(trace[0]))
                at = np.flatnonzero(np.diff(trace)) + 1
                changes.extend((int(t), len(changes), var, int(trace[t])) for t in at)
        changes.sort(key=lambda change: (change[0], change[1]))
        for cycle, _, var, value in changes:
            writer.change(var, cycle * CLOCK_PS, value)
    return path

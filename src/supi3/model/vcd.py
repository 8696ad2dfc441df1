"""Write a pin-level ring's recorded pins as a VCD waveform (one scope per chip, time in 32 MHz clocks)."""

from __future__ import annotations

import re
from collections.abc import Mapping
from os import PathLike
from pathlib import Path

import numpy as np
import numpy.typing as npt
from vcd import VCDWriter
from vcd.writer import Variable

from supi3.checks import check_instance, fail
from supi3.config import DeviceConfig
from supi3.model.pinring import PinRing
from supi3.tables import CLOCK_HZ

CLOCK_PS = 10**12 // CLOCK_HZ
"""One 32 MHz clock period in picoseconds (31250), the VCD time step."""


def mfp_signals(config: DeviceConfig) -> list[tuple[int, str]]:
    """(MFP pin, VCD name) of every MFP the mode uses (Tables 3-1 to 3-6, 2-8): ``mfp4_sclk``, ``mfp5_ss_n`` (a
    leading "/" becomes ``_n``), ``mfp0_in0``; GND pins are left out."""
    check_instance("config", config, DeviceConfig)
    named = []
    for p in config.mfp_pins:
        signal = p.signal.split(" | ")[0]
        if signal == "GND":
            continue
        base = re.sub(r"[^0-9a-z]+", "_", signal.lstrip("/").lower()).strip("_")
        named.append((p.pin, f"mfp{p.pin}_{base}{'_n' if signal.startswith('/') else ''}"))
    return named


def write_vcd(path: Path, ring: PinRing, scopes: Mapping[str, Mapping[str, npt.NDArray[np.int64]]] | None = None
              ) -> Path:  # fmt: skip
    """Write every pin of every chip of ``ring`` (made with ``record=True``) to ``path``, and the 1-bit ``scopes``
    given (scope name -> signal name -> a level per clock over the whole recording, e.g. a board's own lines).

    Scopes are ``dev1`` .. ``devN`` in ring order; ``dev1.do1`` is the master's forward line and ``dev1.di1``
    the return line into the master. Besides the 16-bit ``mfp_in``/``mfp_out``/``mfp_oe`` vectors, every MFP the
    mode uses is a 1-bit signal of its own (:func:`mfp_signals`: ``mfp4_sclk``, ``mfp5_ss_n``, ...), at the level
    on the pin: the chip's output where it drives the pin, else the input given to the model (a device attached
    with ``Supi3.attach_serial`` answers the chip directly, so SerIn shows the pin, not its answer). Only changes
    are written, so the file stays small.

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
        for k, (chip, traces) in enumerate(zip(ring.devices, chips, strict=True), start=1):
            traces = dict(traces)
            if traces:
                driven = traces["mfp_oe"]
                for pin, name in mfp_signals(chip.config):
                    widths[name] = 1
                    traces[name] = np.where((driven >> pin) & 1, traces["mfp_out"] >> pin, traces["mfp_in"] >> pin) & 1
            for name, trace in sorted(traces.items()):
                _add(writer, changes, f"dev{k}", name, widths[name], trace)
        for scope, signals in (scopes or {}).items():
            for name, trace in sorted(signals.items()):
                _add(writer, changes, scope, name, 1, trace)
        changes.sort(key=lambda change: (change[0], change[1]))
        for cycle, _, var, value in changes:
            writer.change(var, cycle * CLOCK_PS, value)
    return path


def _add(writer: VCDWriter, changes: list[tuple[int, int, Variable[int], int]], scope: str, name: str, size: int,
         trace: npt.NDArray[np.int64]) -> None:  # fmt: skip
    """Register ``scope.name`` and queue its changes (clock, order, variable, level)."""
    var = writer.register_var(scope, name, "wire", size=size, init=int(trace[0]))
    at = np.flatnonzero(np.diff(trace)) + 1
    changes.extend((int(t), len(changes), var, int(trace[t])) for t in at)

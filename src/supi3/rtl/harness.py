"""The chip core's pin model for the lockstep harness: :class:`~supi3.model.pins.Supi3Pins` behind the RTL's ports.

The RTL core (:class:`supi3.rtl.core.Supi3Core`) reads its configuration from strap ports, so one netlist serves
every operating mode. :class:`StrapPins` gives the model the same ports: it decodes the straps it sees on the first
clock (:func:`supi3.config.decode`) and from then on is the model of that configuration. Stimulus drives the straps
as constants (:func:`strap_inputs`), with MFP[15..12] at the configuration expansion where the mode has one.
:class:`ChipStrapPins` does the same for the whole chip (:class:`supi3.model.top.Supi3Chip`, the model of
:class:`supi3.rtl.chip.Supi3Chip`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import numpy.typing as npt

from supi3.config import DeviceConfig, Variant, decode, mode_rows
from supi3.model.pins import Supi3Pins
from supi3.model.top import Supi3Chip
from supi3.rtl.core import STRAP_PINS
from supi3.rtl.tables import EXPANSION_BITS, MFP_PINS
from supi3.verif.errors import PinSpecError
from supi3.verif.pinmodel import Pin

__all__ = ["ChipStrapPins", "StrapPins", "strap_inputs", "strap_stimulus"]

_STRAP_NAMES = tuple(pin.name for pin in STRAP_PINS)
_CORE_NAMES = tuple(pin.name for pin in Supi3Pins.inputs)
"""The model's own pins: its step() takes exactly these (the straps are this wrapper's)."""
_EXPANSION_SHIFT = MFP_PINS - EXPANSION_BITS


def _open(width: int) -> int:
    """A strap left open reads as 1 on every pin (CIp pull-ups, Table 1-4)."""
    return (1 << width) - 1


def strap_inputs(config: DeviceConfig) -> dict[str, int]:
    """The strap port values that select ``config`` (pins the variant lacks driven as if open), and the MFP[15..12]
    expansion bits as ``"mfp_expansion"`` (0 when the mode has none)."""
    straps = config.straps()
    widths = {pin.name: pin.width for pin in STRAP_PINS}
    values = {
        "c": int(straps.c, 2),
        "rf": int(straps.rf, 2) if straps.rf is not None else _open(widths["rf"]),
        "clk_conf": int(straps.clk_conf, 2),
        "diag_conf": int(straps.diag_conf, 2) if straps.diag_conf is not None else _open(widths["diag_conf"]),
    }
    values["mfp_expansion"] = int(straps.mfp, 2) if straps.mfp is not None else 0
    return values


def strap_stimulus(config: DeviceConfig, stimulus: npt.NDArray[np.integer]) -> npt.NDArray[np.uint64]:
    """``stimulus`` (``(cycles, model inputs)`` in :attr:`Supi3Pins.inputs` order) with the strap columns appended
    and MFP[15..12] forced to the configuration expansion where the mode has one."""
    values = strap_inputs(config)
    array = np.asarray(stimulus, dtype=np.uint64)
    mfp = [pin.name for pin in Supi3Pins.inputs].index("mfp_in")
    if config.straps().mfp is not None:
        low = np.uint64((1 << _EXPANSION_SHIFT) - 1)
        array[:, mfp] = (array[:, mfp] & low) | np.uint64(values["mfp_expansion"] << _EXPANSION_SHIFT)
    straps = np.tile(np.array([values[name] for name in _STRAP_NAMES], dtype=np.uint64), (array.shape[0], 1))
    return np.concatenate([array, straps], axis=1)


class StrapPins:
    """:class:`~supi3.model.pins.Supi3Pins` with the strap ports of the RTL core (a :class:`PinModel`).

    Parameters
    ----------
    variant:
        The chip variant the straps are decoded for (the RTL's elaboration parameter).

    Raises
    ------
    PinSpecError
        From :meth:`step`, when the straps of the first clock select no operating mode, or change later.
    """

    inputs: Sequence[Pin] = (*Supi3Pins.inputs, *STRAP_PINS)
    outputs: Sequence[Pin] = Supi3Pins.outputs

    def __init__(self, variant: Variant | str = Variant.OPC) -> None:
        self.variant = Variant(variant)
        self.pins: Supi3Pins | None = None
        self._straps: tuple[int, ...] = ()

    def reset(self) -> None:
        """Forget the configuration: the next :meth:`step` decodes the straps again."""
        self.pins = None

    def config_for(self, inputs: Mapping[str, int]) -> DeviceConfig:
        """The configuration the straps in ``inputs`` select (:func:`supi3.config.decode`)."""
        c = format(int(inputs["c"]), f"0{STRAP_PINS[0].width}b")
        expansion = any(row.mfp is not None for row in mode_rows(self.variant) if row.c == c)
        mfp = format(int(inputs["mfp_in"]) >> _EXPANSION_SHIFT, f"0{EXPANSION_BITS}b") if expansion else None
        widths = {pin.name: pin.width for pin in STRAP_PINS}
        opc = self.variant is Variant.OPC
        return decode(
            c,
            mfp,
            rf=format(int(inputs["rf"]), f"0{widths['rf']}b") if opc else None,
            clk_conf=format(int(inputs["clk_conf"]), f"0{widths['clk_conf']}b"),
            diag_conf=format(int(inputs["diag_conf"]), f"0{widths['diag_conf']}b") if opc else None,
            variant=self.variant,
        )

    def step(self, inputs: Mapping[str, int]) -> dict[str, int]:
        """One clock of the model of the configuration the straps select (see :mod:`supi3.verif.pinmodel`)."""
        straps = tuple(int(inputs[name]) for name in _STRAP_NAMES)
        if self.pins is None:
            self.pins = Supi3Pins(self.config_for(inputs))
            self._straps = straps
        elif straps != self._straps:
            raise PinSpecError(f"cycle {self.pins.cycle}: the straps changed ({self._straps} -> {straps})")
        return self.pins.step({name: inputs[name] for name in _CORE_NAMES})

    def run(self, inputs: Mapping[str, npt.NDArray[np.integer]]) -> dict[str, npt.NDArray[np.int64]]:
        """Whole traces at once (:meth:`Supi3Pins.run`, event-driven); the straps must be constant."""
        first = {name: int(np.asarray(trace)[0]) for name, trace in inputs.items()}
        for name in _STRAP_NAMES:
            if np.any(np.asarray(inputs[name]) != first[name]):
                raise PinSpecError(f"the straps must not change during a run ({name})")
        if self.pins is None:
            self.pins = Supi3Pins(self.config_for(first))
            self._straps = tuple(first[name] for name in _STRAP_NAMES)
        elif tuple(first[name] for name in _STRAP_NAMES) != self._straps:
            raise PinSpecError(f"cycle {self.pins.cycle}: the straps changed")
        return self.pins.run({pin.name: np.asarray(inputs[pin.name]) for pin in Supi3Pins.inputs})

    def recent_events(self) -> list[str]:
        """The model's last bus events, for mismatch reports."""
        return self.pins.log.recent() if self.pins is not None else []


class ChipStrapPins:
    """:class:`~supi3.model.top.Supi3Chip` with the strap ports of the RTL chip (a :class:`PinModel`).

    The µP interface rules are not enforced (``strict=False``): violations are recorded in the register file's
    ``violations`` and the chip carries on, as the RTL does.

    Parameters
    ----------
    variant:
        The chip variant the straps are decoded for (the RTL's elaboration parameter).

    Raises
    ------
    PinSpecError
        From :meth:`step` and :meth:`run`, when the straps of the first clock select no operating mode, or change.
    """

    inputs: Sequence[Pin] = StrapPins.inputs
    outputs: Sequence[Pin] = Supi3Chip.outputs

    def __init__(self, variant: Variant | str = Variant.OPC) -> None:
        self.straps = StrapPins(variant)
        self.chip: Supi3Chip | None = None
        self._straps: tuple[int, ...] = ()

    def reset(self) -> None:
        """Forget the configuration: the next :meth:`step` decodes the straps again."""
        self.chip = None

    def _model(self, inputs: Mapping[str, int]) -> Supi3Chip:
        straps = tuple(int(inputs[name]) for name in _STRAP_NAMES)
        if self.chip is None:
            self.chip = Supi3Chip(self.straps.config_for(inputs), strict=False)
            self._straps = straps
        elif straps != self._straps:
            raise PinSpecError(f"cycle {self.chip.core.cycle}: the straps changed ({self._straps} -> {straps})")
        return self.chip

    def step(self, inputs: Mapping[str, int]) -> dict[str, int]:
        """One clock of the chip the straps select (see :mod:`supi3.verif.pinmodel`)."""
        return self._model(inputs).step({name: inputs[name] for name in _CORE_NAMES})

    def run(self, inputs: Mapping[str, npt.NDArray[np.integer]]) -> dict[str, npt.NDArray[np.int64]]:
        """Whole traces at once (:meth:`Supi3Chip.run`); the straps must be constant."""
        first = {name: int(np.asarray(trace)[0]) for name, trace in inputs.items()}
        for name in _STRAP_NAMES:
            if np.any(np.asarray(inputs[name]) != first[name]):
                raise PinSpecError(f"the straps must not change during a run ({name})")
        return self._model(first).run({pin.name: np.asarray(inputs[pin.name]) for pin in Supi3Pins.inputs})

    def recent_events(self) -> list[str]:
        """The core's last bus events and the register file's last violations, for mismatch reports."""
        if self.chip is None:
            return []
        registers = self.chip.chip.registers
        violations = [str(v) for v in registers.violations.records[-8:]] if registers is not None else []
        return [*self.chip.core.log.recent(), *violations]

"""The chip core's pin model for the lockstep harness: :class:`~supi3.model.pins.Supi3Pins` behind the RTL's ports.

The RTL core (:class:`supi3.rtl.core.Supi3Core`) reads its configuration from strap ports, so one netlist serves
every operating mode. :class:`StrapPins` gives the model the same ports: it decodes the straps it sees on the first
clock (:func:`supi3.config.decode`) and from then on is the model of that configuration. Stimulus drives the straps
as constants (:func:`strap_inputs`), with MFP[15..12] at the configuration expansion where the mode has one.
:class:`ChipStrapPins` does the same for the whole chip (:class:`supi3.top.Supi3Chip`, the model of
:class:`supi3.rtl.chip.Supi3ChipRtl`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import numpy.typing as npt

from supi3.checks import check_bits, check_instance, check_trace, fail
from supi3.config import DeviceConfig, Variant, decode, mode_rows
from supi3.model.pins import Supi3Pins, check_names, input_row, input_traces, split_optical, split_optical_traces
from supi3.pinlevel import Pin, PinSpecError
from supi3.rtl.core import STRAP_PINS
from supi3.rtl.tables import EXPANSION_BITS, MFP_PINS, check_variant
from supi3.top import Supi3Chip

__all__ = ["ChipStrapPins", "StrapPins", "strap_inputs", "strap_stimulus"]

_STRAP_NAMES = tuple(pin.name for pin in STRAP_PINS)
_CORE_NAMES = tuple(pin.name for pin in Supi3Pins.inputs)
"""The model's own pins: its step() takes exactly these (the straps are this wrapper's)."""
_OPTICAL_NAMES = tuple(pin.name for pin in Supi3Pins.optical_inputs)
"""The optical block's line side: the model's step() and run() take them with its pins."""
_ALL_NAMES = (*_CORE_NAMES, *_STRAP_NAMES, *_OPTICAL_NAMES)
_BOARD_NAMES = (*_CORE_NAMES, *_STRAP_NAMES)
"""What a caller may give without the optical line side (quiet then, as :class:`Supi3Pins` takes it)."""


def _names(inputs: object) -> tuple[str, ...]:
    """The input names ``inputs`` must have: with the optical line side if it names any of it."""
    optical = isinstance(inputs, Mapping) and any(name in inputs for name in _OPTICAL_NAMES)
    return _ALL_NAMES if optical else _BOARD_NAMES
_EXPANSION_SHIFT = MFP_PINS - EXPANSION_BITS


def _open(width: int) -> int:
    """A strap left open reads as 1 on every pin (CIp pull-ups, Table 1-4)."""
    return (1 << width) - 1


def strap_inputs(config: DeviceConfig) -> dict[str, int]:
    """The strap port values that select ``config`` (pins the variant lacks driven as if open), and the MFP[15..12]
    expansion bits as ``"mfp_expansion"`` (0 when the mode has none)."""
    check_instance("config", config, DeviceConfig)
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


def strap_stimulus(config: DeviceConfig, stimulus: npt.NDArray[np.integer],
                   optical: npt.NDArray[np.integer] | None = None) -> npt.NDArray[np.uint64]:  # fmt: skip
    """``stimulus`` (``(cycles, model inputs)`` in :attr:`Supi3Pins.inputs` order) with the strap columns appended
    and MFP[15..12] forced to the configuration expansion where the mode has one, then the optical block's line side
    (``optical``: ``(cycles, lines)`` in :attr:`Supi3Pins.optical_inputs` order; zeros, quiet, if ``None``).

    Raises
    ------
    ArgumentError
        ``config`` is not a :class:`DeviceConfig`, or ``stimulus`` (``optical``) not a 2-D integer array of that
        shape whose columns fit their pins' widths.
    """
    values = strap_inputs(config)
    pins = Supi3Pins.inputs
    given = np.asarray(stimulus) if isinstance(stimulus, (np.ndarray, list, tuple)) else None
    if given is None or given.ndim != 2 or given.shape[1] != len(pins) or (given.size and given.dtype.kind not in "iu"):
        raise fail("stimulus", f"a 2-D integer array of (cycles, {len(pins)}) in Supi3Pins.inputs order", stimulus)
    input_traces({pin.name: given[:, k] for k, pin in enumerate(pins)})  # every column within its pin's width
    array = given.astype(np.uint64)
    mfp = [pin.name for pin in Supi3Pins.inputs].index("mfp_in")
    if config.straps().mfp is not None:
        low = np.uint64((1 << _EXPANSION_SHIFT) - 1)
        array[:, mfp] = (array[:, mfp] & low) | np.uint64(values["mfp_expansion"] << _EXPANSION_SHIFT)
    straps = np.tile(np.array([values[name] for name in _STRAP_NAMES], dtype=np.uint64), (array.shape[0], 1))
    lines = np.zeros((array.shape[0], len(_OPTICAL_NAMES)), dtype=np.uint64)
    if optical is not None:
        given_lines = np.asarray(optical)
        if given_lines.shape != lines.shape or (given_lines.size and given_lines.dtype.kind not in "iu"):
            raise fail("optical", f"a 2-D integer array of {lines.shape} in Supi3Pins.optical_inputs order", optical)
        for k, pin in enumerate(Supi3Pins.optical_inputs):  # a value past its width would spill into the next port
            check_trace(f"optical column {k} ({pin.name!r})", given_lines[:, k], pin.width)
        lines = given_lines.astype(np.uint64)
    return np.concatenate([array, straps, lines], axis=1)


_STRAP_WIDTHS = {pin.name: pin.width for pin in STRAP_PINS}


def _straps_of(inputs: object) -> dict[str, int]:
    """The straps and ``mfp_in`` of ``inputs``, checked (named error for a missing or bad value)."""
    if not isinstance(inputs, Mapping):
        raise fail("inputs", "a mapping of pin name to value", inputs)
    widths = {**_STRAP_WIDTHS, "mfp_in": MFP_PINS}
    missing = [name for name in widths if name not in inputs]
    if missing:
        raise fail("inputs", f"a mapping with the pins {', '.join(widths)}", inputs, f"without {missing}")
    return {name: check_bits(f"pin {name!r}", inputs[name], width) for name, width in widths.items()}


def _strap_values(inputs: Mapping[str, int]) -> tuple[int, ...]:
    """The strap values of one clock; every name of :attr:`StrapPins.inputs` exactly (the optical line side may be
    left out), else a named error."""
    if not isinstance(inputs, Mapping) or len(inputs) != len(_names(inputs)) \
            or any(name not in inputs for name in _names(inputs)):
        check_names("inputs", inputs, _names(inputs))
    return tuple(check_bits(f"pin {name!r}", inputs[name], width) for name, width in _STRAP_WIDTHS.items())


def _first_row(inputs: object) -> dict[str, int]:
    """The straps and ``mfp_in`` of the first cycle of whole traces, checked (the model's ``run`` checks the rest)."""
    mapping = check_names("inputs", inputs, _names(inputs))
    first = {}
    for name, width in {**_STRAP_WIDTHS, "mfp_in": MFP_PINS}.items():
        trace = np.asarray(mapping[name])
        if trace.ndim != 1 or not trace.size or trace.dtype.kind not in "iu":
            raise fail(f"pin {name!r} trace", "a non-empty 1-D integer sequence", mapping[name])
        first[name] = check_bits(f"pin {name!r} trace[0]", trace[0].item(), width)
    return first


def _checked_run(inputs: object) -> tuple[dict[str, int], dict[str, npt.NDArray[np.integer]]]:
    """Whole traces, checked before anything is built: the first cycle's straps and ``mfp_in``, and the model's traces
    (:func:`~supi3.model.pins.input_traces`); the straps must be constant."""
    first = _first_row(inputs)
    assert isinstance(inputs, Mapping)
    split = split_optical_traces({name: inputs[name] for name in (*_CORE_NAMES, *_OPTICAL_NAMES) if name in inputs})
    core = {**split[0], **split[1]}
    for name in _STRAP_NAMES:
        trace = np.asarray(inputs[name])
        if len(trace) != len(core["do1"]):
            raise fail(f"len(pin {name!r} trace)", f"{len(core['do1'])}, the length of pin 'do1' trace", len(trace))
        if np.any(trace != first[name]):
            raise PinSpecError(f"the straps must not change during a run ({name})")
    return first, core


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

    inputs: Sequence[Pin] = (*Supi3Pins.inputs, *STRAP_PINS, *Supi3Pins.optical_inputs)
    outputs: Sequence[Pin] = Supi3Pins.outputs

    def __init__(self, variant: Variant | str = Variant.OPC) -> None:
        self.variant = check_variant(variant)
        self.pins: Supi3Pins | None = None
        self._straps: tuple[int, ...] = ()

    def reset(self) -> None:
        """Forget the configuration: the next :meth:`step` decodes the straps again."""
        self.pins = None

    def config_for(self, inputs: Mapping[str, int]) -> DeviceConfig:
        """The configuration the straps in ``inputs`` select (:func:`supi3.config.decode`).

        Raises
        ------
        ArgumentError
            A strap or ``mfp_in`` missing, or not an integer within its pin's width.
        ConfigurationError
            The straps select no operating mode.
        """
        inputs = _straps_of(inputs)
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
        """One clock of the model of the configuration the straps select (see :mod:`supi3.pinlevel`).

        Raises
        ------
        ArgumentError
            ``inputs`` does not name exactly :attr:`inputs`, or a value is not an integer within its pin's width.
        """
        straps = _strap_values(inputs)
        core = {name: inputs[name] for name in (*_CORE_NAMES, *_OPTICAL_NAMES) if name in inputs}
        if self.pins is None:
            input_row(split_optical(core)[0])  # checked before the model is built: a rejected call changes nothing
            self.pins = Supi3Pins(self.config_for(inputs))
            self._straps = straps
        elif straps != self._straps:
            raise PinSpecError(f"cycle {self.pins.cycle}: the straps changed ({self._straps} -> {straps})")
        return self.pins.step(core)

    def run(self, inputs: Mapping[str, npt.NDArray[np.integer]]) -> dict[str, npt.NDArray[np.int64]]:
        """Whole traces at once (:meth:`Supi3Pins.run`, event-driven); the straps must be constant."""
        first, core = _checked_run(inputs)
        if self.pins is None:
            self.pins = Supi3Pins(self.config_for(first))
            self._straps = tuple(first[name] for name in _STRAP_NAMES)
        elif tuple(first[name] for name in _STRAP_NAMES) != self._straps:
            raise PinSpecError(f"cycle {self.pins.cycle}: the straps changed")
        return self.pins.run(core)

    def recent_events(self) -> list[str]:
        """The model's last bus events, for mismatch reports."""
        return self.pins.log.recent() if self.pins is not None else []


class ChipStrapPins:
    """:class:`~supi3.top.Supi3Chip` with the strap ports of the RTL chip (a :class:`PinModel`).

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

    def _model(self, straps: tuple[int, ...], inputs: Mapping[str, int]) -> Supi3Chip:
        if self.chip is None:
            self.chip = Supi3Chip(self.straps.config_for(inputs), strict=False)
            self._straps = straps
        elif straps != self._straps:
            raise PinSpecError(f"cycle {self.chip.core.cycle}: the straps changed ({self._straps} -> {straps})")
        return self.chip

    def step(self, inputs: Mapping[str, int]) -> dict[str, int]:
        """One clock of the chip the straps select (see :mod:`supi3.pinlevel`).

        Raises
        ------
        ArgumentError
            ``inputs`` does not name exactly :attr:`inputs`, or a value is not an integer within its pin's width.
        """
        straps = _strap_values(inputs)
        core = {name: inputs[name] for name in (*_CORE_NAMES, *_OPTICAL_NAMES) if name in inputs}
        if self.chip is None:
            input_row(split_optical(core)[0])  # checked before the model is built: a rejected call changes nothing
        return self._model(straps, inputs).step(core)

    def run(self, inputs: Mapping[str, npt.NDArray[np.integer]]) -> dict[str, npt.NDArray[np.int64]]:
        """Whole traces at once (:meth:`Supi3Chip.run`); the straps must be constant."""
        first, core = _checked_run(inputs)
        return self._model(tuple(first[name] for name in _STRAP_NAMES), first).run(core)

    def recent_events(self) -> list[str]:
        """The core's last bus events and the register file's last violations, for mismatch reports."""
        if self.chip is None:
            return []
        registers = self.chip.chip.registers
        violations = [str(v) for v in registers.violations.records[-8:]] if registers is not None else []
        return [*self.chip.core.log.recent(), *violations]

"""The manual's serial µP interface figures, redrawn from traces of the pin-level model.

The text copy of the manual (IBS SUPI 3 OPC UM E rev. 05) lacks Figures 3-4, 3-5 and 3-9 to 3-12. :data:`FIGURES`
redraws each from a :class:`~supi3.spi.master.SpiTrace` of :class:`~supi3.spi.slave_pins.SlavePins` driven by a
:class:`~supi3.spi.master.SoftMaster`: :func:`to_wavejson` turns a trace into WaveJSON sampled once per half SCLK
period, :func:`render_svg` renders it with the ``wavedrom`` package (the ``docs`` extra, imported only there), and
:func:`supi3.figures.write_figures` writes them with the other redrawn figures; ``supi3 figures`` runs it (see
``docs/figures.md``).
"""

from __future__ import annotations

import importlib
import json
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from types import ModuleType
from typing import Final, Generic, TypeVar

from supi3.checks import check_instance, check_int
from supi3.config import decode
from supi3.model.registers import RegisterFile
from supi3.regmap import BLOCK_ADDRESS, REGISTER_MAP, encode_command
from supi3.spi.master import MasterTiming, SoftMaster, SpiTrace, decode_bytes
from supi3.spi.slave_pins import SlavePins
from supi3.spi.upif import Mode

__all__ = [
    "FIGURES",
    "GAP",
    "Figure",
    "render_svg",
    "to_wavejson",
    "wave_string",
    "wavedrom_module",
]

DOCS_EXTRA_HINT: Final[str] = "pip install 'supi3[docs]'"


def wavedrom_module() -> ModuleType:
    """The ``wavedrom`` package, which renders SVG.

    Raises
    ------
    ModuleNotFoundError
        When it is not installed (it comes with the ``docs`` extra), saying how to install it.
    """
    try:
        return importlib.import_module("wavedrom")
    except ModuleNotFoundError as error:
        raise ModuleNotFoundError(f"SVG figures need the wavedrom package of the docs extra, {DOCS_EXTRA_HINT} "
                                  f"({error})", name="wavedrom") from None


# ------------------------------------------------------------------------------------------------------------
# WaveJSON and SVG
# ------------------------------------------------------------------------------------------------------------


def _lanes(trace: SpiTrace) -> list[tuple[str, Callable[[int], str]]]:
    ss_sclk: list[tuple[str, Callable[[int], str]]] = [
        ("/SS (MFP5)", lambda k: str(trace.inputs[k].ss_n)),
        ("SCLK (MFP4)", lambda k: str(trace.inputs[k].sclk)),
    ]
    c_d: tuple[str, Callable[[int], str]] = ("C/D (MFP2)", lambda k: str(trace.outputs[k].c_d))
    if trace.mode is Mode.INTEL:
        return [*ss_sclk, ("S/R (MFP7)", trace.mfp7_line), ("Ser_IN/OUT (MFP6)", trace.mfp6_line), c_d]
    return [*ss_sclk, ("SerIN (MFP6)", trace.mfp6_line), ("SerOUT (MFP7)", trace.mfp7_line), c_d]


GAP: Final = object()
"""A column key of :func:`wave_string` drawn as a gap (``|``): time left out, the lane's level unchanged."""


def wave_string(keys: Sequence[object], data_key: Callable[[object], bool]) -> str:
    """WaveJSON wave string of one lane: a key per column, ``.`` where it repeats, ``=`` for a data segment, ``|``
    for a :data:`GAP` column."""
    chars: list[str] = []
    previous: object = None
    for key in keys:
        if key is GAP:
            chars.append("|")
            continue
        if key == previous:
            chars.append(".")
        else:
            chars.append("=" if data_key(key) else str(key))
        previous = key
    return "".join(chars)


def to_wavejson(trace: SpiTrace, title: str, *, step: int | None = None) -> dict[str, object]:
    """The WaveJSON of ``trace``: one column per ``step`` cycles (default half an SCLK period), each showing
    the pins in the first cycle of its window, plus two lanes with the bytes that
    :func:`~supi3.spi.master.decode_bytes` reads.

    With :meth:`MasterTiming.aligned` every edge of the µP starts a column; the chip's outputs (2 TCLK + 1
    clock after their cause, UP-14) then show one column after it as long as that is less than ``step``.

    Raises
    ------
    ArgumentError
        ``trace`` not a :class:`SpiTrace`, ``title`` not a str, ``step`` neither ``None`` nor an integer >= 1 (0
        used to mean the default, a negative step drew no column).
    """
    check_instance("trace", trace, SpiTrace)
    check_instance("title", title, str, "a str")
    step = trace.timing.low if step is None else check_int("step", step, 1, limit="chip clocks per column")
    columns = range(0, len(trace), step)
    signal: list[object] = []
    for name, level in _lanes(trace):
        signal.append({"name": name, "wave": wave_string([level(k) for k in columns], lambda _: False)})
    frames = decode_bytes(trace)
    for name, attribute in (("µP → chip", "to_chip"), ("chip → µP", "from_chip")):
        keys: list[object] = []
        for k in columns:
            hit = next((i for i, f in enumerate(frames) if f.start <= k < f.stop and getattr(f, attribute) is not None),
                       None)
            keys.append("z" if hit is None else hit)
        labels = [f"{getattr(frames[i], attribute):02X}h" for i in dict.fromkeys(keys) if isinstance(i, int)]
        signal.append({"name": name, "wave": wave_string(keys, lambda key: isinstance(key, int)), "data": labels})
    t = trace.timing
    sclk_mhz = trace.clock_hz / t.period / 1e6
    foot = (f"SUPI 3 model trace ({trace.mode.name.capitalize()}, {trace.bit_rate // 1000} kbit/s, SCLK "
            f"{sclk_mhz:.2f} MHz); one column = {step} chip clocks = {step * 1e9 / trace.clock_hz:.2f} ns")
    return {"signal": signal, "head": {"text": title}, "foot": {"text": foot}}


def render_svg(wavejson: dict[str, object]) -> str:
    """Render WaveJSON to SVG text with the ``wavedrom`` package.

    Raises
    ------
    ModuleNotFoundError
        When ``wavedrom`` (the ``docs`` extra) is not installed (:func:`wavedrom_module`).
    """
    return str(wavedrom_module().render(json.dumps(wavejson)).tostring())


# ------------------------------------------------------------------------------------------------------------
# The manual's figures, redrawn from model traces
# ------------------------------------------------------------------------------------------------------------

FIGURE_STRAPS: Final[tuple[str, str]] = ("10011", "1110")
"""C4..0 and MFP15..12 of the figures' chip: remote bus device, Init-µP, 500 kbit/s (``docs/upif.md``)."""
SET_1_BYTE: Final[int] = 0x82
"""The SET value of Fig. 3-10: an I/O device with one byte (``decode_set(0x82)``, Table 3-12)."""
SET_3_BYTES: Final[int] = 0x84
"""SET for the 24-bit output device of Fig. 3-12 (``decode_set(0x84)``: 3 bytes)."""
ID_DIGITAL_OUTPUT: Final[int] = 0x01
"""The ID code of Fig. 3-11: digital output device."""
BLOCK_OUT_DATA: Final[bytes] = b"\x14\x56\x78"
"""The OUT data read in Fig. 3-12."""
EXAMPLE_OUT: Final[int] = 0xC3
"""OUT0 and IN0 data of the one-byte figures 3-4 and 3-5 (any byte; not the manual's)."""
EXAMPLE_IN: Final[int] = 0x5A

_SET = REGISTER_MAP.register("SET").address
_ID = REGISTER_MAP.register("ID").address
_DATA0 = REGISTER_MAP.register("IN0").address


T = TypeVar("T")


@dataclass(frozen=True)
class Figure(Generic[T]):
    """One of the manual's timing figures, the scenario that redraws it and how its trace becomes WaveJSON."""

    name: str
    """File stem under ``docs/figures``."""
    manual: str
    """The manual's figure number and caption."""
    description: str
    """What the redrawn figure shows."""
    build: Callable[[], T]
    """Runs the scenario on a fresh chip and returns the trace the figure shows."""
    draw: Callable[[T, str], dict[str, object]]
    """The WaveJSON of a trace of :attr:`build`, given the title."""

    @property
    def title(self) -> str:
        """The figure's heading: the manual's caption, marked as redrawn."""
        return f"{self.manual} (redrawn from the model)"

    def wavejson(self) -> tuple[T, dict[str, object]]:
        """Run the scenario: its trace and the figure's WaveJSON."""
        trace = self.build()
        return trace, self.draw(trace, self.title)


class _Scenario:
    """A fresh chip at :data:`FIGURE_STRAPS` and a µP with aligned fastest timing; bytes before :meth:`show`
    set the chip up, bytes after it are the figure."""

    def __init__(self, mode: Mode) -> None:
        chip = SlavePins(RegisterFile(decode(*FIGURE_STRAPS)))
        timing = MasterTiming.fastest(chip.registers.config.bit_rate, clock_hz=chip.clock_hz).aligned()
        self.master = SoftMaster(chip, mode, timing)
        self.start = 0

    def show(self) -> None:
        """The figure starts here: once the chip's outputs settled after the set-up bytes, with one idle gap."""
        self.master.deselect()
        self.start = len(self.master.trace())
        self.master.deselect()

    def trace(self) -> SpiTrace:
        """The figure's cycles, ending one idle gap after C/D settled after its last byte."""
        self.master.deselect()
        self.master.deselect()
        return self.master.trace().window(self.start)


def _intel_configured(set_value: int) -> _Scenario:
    """Intel initialization and a SET write (Figs. 3-9, 3-10) as the set-up."""
    scenario = _Scenario(Mode.INTEL)
    m = scenario.master
    m.byte(Mode.INTEL.init_byte)
    m.byte(encode_command(_SET, wr=True))
    m.byte(set_value)
    m.deselect()
    return scenario


def _figure_3_4() -> SpiTrace:
    scenario = _Scenario(Mode.MOTOROLA)
    m = scenario.master
    m.byte(Mode.MOTOROLA.init_byte)
    m.byte(encode_command(_SET, wr=True))
    m.byte(SET_1_BYTE)
    m.deselect()
    m.chip.registers.latch(bytes([EXAMPLE_OUT]))
    m.byte(encode_command(_DATA0, rd=True, wr=True))
    scenario.show()
    m.byte(EXAMPLE_IN)
    return scenario.trace()


def _figure_3_5() -> SpiTrace:
    scenario = _intel_configured(SET_1_BYTE)
    m = scenario.master
    m.chip.registers.latch(bytes([EXAMPLE_OUT]))
    m.byte(encode_command(_DATA0, rd=True))
    scenario.show()
    m.byte(s_r=False)
    return scenario.trace()


def _figure_3_9() -> SpiTrace:
    scenario = _Scenario(Mode.INTEL)
    scenario.show()
    scenario.master.byte(Mode.INTEL.init_byte)
    return scenario.trace()


def _figure_3_10() -> SpiTrace:
    scenario = _Scenario(Mode.INTEL)
    m = scenario.master
    m.byte(Mode.INTEL.init_byte)
    scenario.show()
    m.byte(encode_command(_SET, wr=True))
    m.byte(SET_1_BYTE)
    return scenario.trace()


def _figure_3_11() -> SpiTrace:
    scenario = _intel_configured(SET_1_BYTE)
    scenario.show()
    scenario.master.byte(encode_command(_ID, wr=True))
    scenario.master.byte(ID_DIGITAL_OUTPUT)
    return scenario.trace()


def _figure_3_12() -> SpiTrace:
    scenario = _intel_configured(SET_3_BYTES)
    m = scenario.master
    m.chip.registers.latch(BLOCK_OUT_DATA)
    scenario.show()
    m.byte(encode_command(BLOCK_ADDRESS, rd=True))
    for _ in BLOCK_OUT_DATA:
        m.byte(s_r=False)
    return scenario.trace()


FIGURES: Final[tuple[Figure[SpiTrace], ...]] = (
    Figure("fig3-4", "Figure 3-4 Timing of the synchronous serial interface (Motorola)",
           "One full-duplex data byte (command C0h before it): SerIN carries 5Ah MSB first into IN0 while SerOUT "
           "drives OUT0 = C3h; SerOUT is tri-state while /SS is high; C/D returns from data to command.",
           _figure_3_4, to_wavejson),
    Figure("fig3-5", "Figure 3-5 Timing of the synchronous serial interface (Intel)",
           "One read data byte (command 80h before it): S/R = 0, the chip drives Ser_IN/OUT with OUT0 = C3h LSB "
           "first, released when /SS rises; C/D returns from data to command.",
           _figure_3_5, to_wavejson),
    Figure("fig3-9", "Figure 3-9 Initialization byte timing (81hex)",
           "The Intel initialization byte 81h after power-up: C/D shows command before and after it (the "
           "first-initialization signature of 3.4.3).",
           _figure_3_9, to_wavejson),
    Figure("fig3-10", "Figure 3-10 Timing access to the SET register (address and data)",
           "Command 4Dh (write address 13), C/D goes to data, then 82h (I/O device, one byte), C/D back to command.",
           _figure_3_10, to_wavejson),
    Figure("fig3-11", "Figure 3-11 Timing access to the ID code register (address and data)",
           "Command 4Ch (write address 12), then the ID code 01h (digital output device).",
           _figure_3_11, to_wavejson),
    Figure("fig3-12", "Figure 3-12 Command and data access during block transfer",
           "Intel block transfer on a 24-bit output device: command 8Fh (S/R = 1), then three reads (S/R = 0) of "
           "OUT bytes 14h 56h 78h; C/D stays data until the last byte.",
           _figure_3_12, to_wavejson),
)
"""The redrawn figures, in the manual's order."""


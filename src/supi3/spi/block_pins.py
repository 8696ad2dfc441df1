"""The serial µP interface block as one pin model: :class:`SlavePins` plus the register file's core interface as ports.

Ref: IBS SUPI 3 OPC UM E rev. 05, 3.4 (Tables 3-5 to 3-13); ``docs/upif.md`` ("RTL"). The RTL of the block
(:mod:`supi3.rtl.upif`) has the µP pins of :class:`~supi3.spi.slave_pins.SlavePins` and, as plain ports, what the
INTERBUS core gives and takes through :class:`~supi3.model.registers.RegisterFile`. :class:`UpifBlockPins` gives the
model the same ports, so the lockstep harness compares every one of them on every clock:

* strap inputs, static like the pins they come from: ``rate`` (the index of the bit rate in
  :data:`supi3.tables.BIT_RATES`, from CLK_CONF, Table 1-7), ``np_id`` and ``np_length`` (the µP_Not_Ready ID and
  length code of the operating mode, 3.4.1). The model is built from them on the first clock.
* core inputs, sampled at the clock edge ending the cycle, *before* the µP pins act at that edge (``docs/upif.md``,
  "core call between ticks"), in this order: ``io_access`` (level), ``latch`` with ``latch_out`` (a valid data
  cycle, ignored with ExtReg = 1), ``pcmd_we`` with ``pcmd`` (management message), ``events`` (one bit per
  interrupt source, at the source's IRQ_EVT bit), ``optical`` (reads 8 to 11 as the optical block shows them now,
  reserved bits dropped: taken at every edge, so a read at an edge sees the value of the cycle it ends, UP-39),
  ``ib_reset``. ``power_up`` resets the whole block at that edge and overrides everything else.
* core outputs, decoded from the registers (they change in the cycle after the edge that changed them):
  ``in_data`` (IN0..IN3), ``bus_id`` (bits 12..0 of the ID register, :meth:`RegisterFile.bus_id_register`),
  ``ext_reg`` (ExtReg applied: the internal data registers are not in the data path), ``pcp`` (a PCP device,
  IN0/IN1 erased by the latch) and ``alarm`` (the processor alarm, write 7).

Multi-byte ports hold byte ``k`` (address ``k``) in bits ``8k + 7 .. 8k``. The register file's ``set_bus_running``
and ``set_latch_phase`` only decide which violations are reported (3.4.3, 3.4.14): they change no output, and the
chip has no pin for a violation, so the block has no ports for them.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from typing import Final

from supi3 import pinout
from supi3.checks import check_bits, check_bool
from supi3.config import MfpKind, Variant, decode, mode_rows
from supi3.errors import ArgumentError
from supi3.model.registers import RegisterFile
from supi3.pinlevel import OE_SUFFIX, Pin, PinSpecError
from supi3.pinout import LENGTH_CODE_BITS, OPTICAL_REGISTERS
from supi3.regmap import INTERRUPT_SOURCES, REGISTER_MAP
from supi3.regmap.core import BYTE_BITS, BYTE_MASK
from supi3.regmap.registers import IN_BYTES
from supi3.spi.slave_pins import INPUT_PINS, OUTPUT_PINS, PinsIn, SlavePins
from supi3.tables import BIT_RATES

__all__ = [
    "CORE_INPUTS",
    "CORE_OUTPUTS",
    "SERIAL_INPUTS",
    "SERIAL_OUTPUTS",
    "STRAP_INPUTS",
    "UpifBlockPins",
    "block_model",
    "strap_values",
]

_PAD_INPUTS: Final[dict[str, str]] = {"mfp6": "mfp6_in", "mfp7": "mfp7_in"}
"""MFP6 and MFP7 are inputs and outputs of the same name in :class:`SlavePins`; the block's input ports are renamed."""

SERIAL_INPUTS: Final[tuple[Pin, ...]] = tuple(Pin(_PAD_INPUTS.get(name, name)) for name in INPUT_PINS)
"""SAS_INIT, SCLK, /SS, MFP6 and MFP7 as inputs (Tables 3-5, 3-6), in :class:`PinsIn` order."""
SERIAL_OUTPUTS: Final[tuple[Pin, ...]] = tuple(
    Pin(name, tristate=True) for name in OUTPUT_PINS if not name.endswith(OE_SUFFIX)
)
"""I/O, C/D, /IRQ, MFP6 and MFP7 with their output enables (:class:`PinsOut`; UP-24)."""
STRAP_INPUTS: Final[tuple[Pin, ...]] = pinout.BLOCK_STRAPS
"""The bit rate index (Table 1-7) and the µP_Not_Ready ID / length code of the straps (3.4.1)."""
CORE_INPUTS: Final[tuple[Pin, ...]] = pinout.TO_REGISTER_FILE
"""What the INTERBUS core (and the optical block) give the register file (see the module docstring)."""
CORE_OUTPUTS: Final[tuple[Pin, ...]] = pinout.FROM_REGISTER_FILE
"""What the register file gives the INTERBUS core (see the module docstring)."""

_BASE_CONFIG: Final = next(
    config
    for row in mode_rows(Variant.OPC)
    for config in (decode(row.c, row.mfp),)
    if config.mfp_mode.kind is MfpKind.INIT_UP
)
"""An Init-µP configuration; the block sees only its bit rate and µP_Not_Ready code, which the straps replace."""


def strap_values(rate: int, np_id: int, np_length: int = 0) -> dict[str, int]:
    """The strap port values for bit rate ``rate`` (bit/s, one of :data:`~supi3.tables.BIT_RATES`) and a
    µP_Not_Ready code.

    Raises
    ------
    PinSpecError
        If ``rate`` is not a bit rate of Table 1-7.
    ArgumentError
        ``np_id`` not a byte, ``np_length`` not a 5-bit length code (Table 3-11).
    """
    if isinstance(rate, bool) or rate not in BIT_RATES:
        raise PinSpecError(f"bit rate must be one of {BIT_RATES}, not {rate!r}")
    return {"rate": BIT_RATES.index(rate), "np_id": check_bits("np_id", np_id, BYTE_BITS, "3.4.1"),
            "np_length": check_bits("np_length", np_length, LENGTH_CODE_BITS, "Table 3-11")}


def block_model(rate: int, np_id: int = 0, np_length: int = 0, *, strict: bool = False) -> SlavePins:
    """A :class:`SlavePins` in its power-up state for bit rate ``rate`` (bit/s) and the µP_Not_Ready code
    ``np_id`` / ``np_length`` (3.4.1), the only parts of the configuration the interface sees.

    Raises
    ------
    PinSpecError
        ``rate`` is not a bit rate of Table 1-7.
    ArgumentError
        ``np_id`` not a byte, ``np_length`` not a 5-bit length code, ``strict`` not a bool.
    """
    strap_values(rate, np_id, np_length)
    check_bool("strict", strict)
    config = dataclasses.replace(_BASE_CONFIG, bit_rate=rate, id_code=np_id, length_code=np_length)
    return SlavePins(RegisterFile(config, strict=strict))


def _bytes(value: int, count: int) -> bytes:
    """Bytes 0..count-1 of a port holding byte k in bits 8k + 7 .. 8k."""
    return bytes((value >> (BYTE_BITS * k)) & BYTE_MASK for k in range(count))


_WIDTHS: Final[dict[str, int]] = {pin.name: pin.width for pin in (*SERIAL_INPUTS, *STRAP_INPUTS, *CORE_INPUTS)}


def _checked(inputs: object) -> dict[str, int]:
    """The block's inputs by name, each an integer within its port's width, as plain ``int``; else a named error."""
    if not isinstance(inputs, Mapping):
        raise ArgumentError("inputs", inputs, f"inputs must be a mapping of pin name to value, not {inputs!r:.60}")
    missing = [name for name in _WIDTHS if name not in inputs]
    unknown = [name for name in inputs if name not in _WIDTHS]
    if missing or unknown:
        problems = [f"without {', '.join(map(repr, missing))}" if missing else "",
                    f"with {', '.join(map(repr, unknown))}, no such pin" if unknown else ""]  # fmt: skip
        raise ArgumentError("inputs", inputs, f"inputs must name exactly the pins {', '.join(_WIDTHS)}, not "
                                              + "; ".join(problem for problem in problems if problem))
    return {name: check_bits(f"pin {name!r}", inputs[name], width) for name, width in _WIDTHS.items()}


class UpifBlockPins:
    """:class:`SlavePins` and its :class:`RegisterFile` with the ports of the RTL block (a ``PinModel``).

    Parameters
    ----------
    strict:
        Passed to :class:`RegisterFile`: raise protocol and timing violations (``True``) or only record them in
        ``registers.violations`` (``False``, the default: the chip carries on, and so does the lockstep).

    Raises
    ------
    PinSpecError
        From :meth:`step`: the straps select no bit rate, or change after the first clock.
    """

    inputs: Sequence[Pin] = (*SERIAL_INPUTS, *STRAP_INPUTS, *CORE_INPUTS)
    outputs: Sequence[Pin] = (*SERIAL_OUTPUTS, *CORE_OUTPUTS)

    def __init__(self, *, strict: bool = False) -> None:
        self.strict = check_bool("strict", strict)
        self.pins: SlavePins | None = None
        self._straps: tuple[int, ...] = ()

    def reset(self) -> None:
        """Forget the straps: the next :meth:`step` builds the model in its power-up state."""
        self.pins = None

    def _build(self, inputs: Mapping[str, int]) -> SlavePins:
        straps = tuple(int(inputs[pin.name]) for pin in STRAP_INPUTS)
        if self.pins is None:
            rate, np_id, np_length = straps
            if rate >= len(BIT_RATES):
                raise PinSpecError(f"rate strap {rate} selects no bit rate of {BIT_RATES}")
            self.pins = block_model(BIT_RATES[rate], np_id, np_length, strict=self.strict)
            self._straps = straps
        elif straps != self._straps:
            raise PinSpecError(f"cycle {self.pins.cycle}: the straps changed ({self._straps} -> {straps})")
        return self.pins

    def step(self, inputs: Mapping[str, int]) -> dict[str, int]:
        """One clock (see :mod:`supi3.pinlevel`): the outputs of this cycle, then the edge ending it.

        Raises
        ------
        ArgumentError
            ``inputs`` does not name exactly the pins of :attr:`inputs`, or a value is not an integer within its
            pin's width (nothing changes).
        PinSpecError
            The straps select no bit rate, or changed after the first clock.
        """
        inputs = _checked(inputs)
        pins = self._build(inputs)
        registers = pins.registers
        outputs = {
            "in_data": sum(registers.value(r.name) << (BYTE_BITS * k) for k, r in enumerate(IN_BYTES)),
            "bus_id": registers.bus_id_register(),
            "ext_reg": int(not registers.internal_data_path),
            "pcp": int(registers.pcp_device),
            "alarm": registers.processor_alarm,
        }
        serial = PinsIn(*(int(inputs[pin.name]) for pin in SERIAL_INPUTS))
        if inputs["power_up"]:
            out = pins.tick(serial)
            pins.reset()
        else:
            self._core(registers, inputs)
            out = pins.tick(serial)
        outputs.update(vars(out))
        return outputs

    @staticmethod
    def _core(registers: RegisterFile, inputs: Mapping[str, int]) -> None:
        """The core's calls at the edge, in the order of the module docstring."""
        registers.set_io_access(bool(inputs["io_access"]))
        if inputs["latch"] and registers.internal_data_path:
            registers.latch(_bytes(int(inputs["latch_out"]), registers.data_bytes()))
        if inputs["pcmd_we"]:
            registers.processor_command(int(inputs["pcmd"]))
        events = int(inputs["events"])
        for source in INTERRUPT_SOURCES:
            if events >> source.bit & 1:
                registers.event(source.name)
        optical = _bytes(int(inputs["optical"]), len(OPTICAL_REGISTERS))
        for name, value in zip(OPTICAL_REGISTERS, optical, strict=True):  # every edge: read as shown now (UP-39)
            registers.set_optical(name, value & REGISTER_MAP.register(name).mask)
        if inputs["ib_reset"]:
            registers.interbus_reset()

    def recent_events(self) -> list[str]:
        """The last violations the register file recorded, for mismatch reports."""
        if self.pins is None:
            return []
        return [str(violation) for violation in self.pins.registers.violations.records[-16:]]

"""Devices on the serial I/O bus (SPI master mode, manual 3.3.1): shift registers, an ADC, a DAC and the bus joining
them, each a :class:`supi3.spi.serial_io.SerialDevice` at both fidelities.

3.3.1: "The serial I/O interface ... is designed for direct connection of DACs ... and ADCs ... It is also possible
to connect shift registers (e.g., 74HCT165 or 74HCT594) with a data length of up to 32 bits." The wiring (Table
3-3): /Conv MFP3, SCLK MFP4, /SS MFP5, SerIn MFP6, SerOut MFP7. The roles are SM-12 of
``docs/assumptions/serial-io.md``; the choices of these models are PR-1 to PR-5 and PR-7 of ``docs/peripherals.md``.

At transaction level the chip calls :meth:`frame` once per /SS frame and :meth:`convert` once per /Conv pulse; at
pin level it calls :meth:`clock` with its MFP3..MFP7 levels at every cycle in which they change, and drives the
returned SerIn level into its own input :data:`~supi3.spi.serial_io.PERIPHERAL_DELAY_CLOCKS` later. A device
detects edges by comparing with the levels it saw last (:data:`~supi3.spi.serial_io.IDLE` after construction).
"""

from __future__ import annotations

from typing import Final

from supi3.checks import check_bits, check_choice, check_instance, check_int, check_real, fail
from supi3.errors import ArgumentError
from supi3.spi.serial_io import IDLE, Levels, SerialDevice

__all__ = [
    "FRAME_BITS",
    "MAX_CHAIN_BYTES",
    "SerInConflictError",
    "SerialBus",
    "ShiftIn",
    "ShiftOut",
    "SpiAdc",
    "SpiDac",
]

FRAME_BITS: Final = (16, 32)
"""SCLK pulses per /SS frame: the chip's 16- and 32-bit SPI master modes (Tables 2-4 to 2-6, SM-3)."""
MAX_CHAIN_BYTES: Final = 4
"""Longest shift-register chain: "shift registers ... with a data length of up to 32 bits" (3.3.1)."""
CONVERTER_BITS: Final = (16, 32)
"""Word lengths of the generic ADC and DAC: one 16- or 32-bit transfer (3.3.1, SM-12)."""


def _mask(width: int) -> int:
    return (1 << width) - 1


def _check_frame(ser_out: int, bits: int) -> tuple[int, int]:
    count = check_choice("bits", bits, FRAME_BITS, limit="Tables 2-4 to 2-6")
    return check_bits("ser_out", ser_out, count), count


def _rose(before: int, after: int) -> bool:
    return before == 0 and after == 1


def _fell(before: int, after: int) -> bool:
    return before == 1 and after == 0


class _Source:
    """Parallel in, serial out on SerIn: the register follows the parallel value while /SS is high and holds the
    one it had when /SS fell, shows its MSB on SerIn and shifts towards it on every SCLK rise while /SS is low,
    zeros coming in behind (PR-1, PR-2)."""

    def __init__(self, width: int) -> None:
        self._width = width
        self._parallel = 0
        self._register = 0
        self._seen = IDLE

    @property
    def drives_ser_in(self) -> bool:
        """True: the serial output is wired to the chip's SerIn (MFP6, Table 3-3)."""
        return True

    def frame(self, ser_out: int, bits: int) -> int:
        """One /SS frame (transaction level): the register takes the parallel value and shifts ``bits`` times;
        returns the bits it put on SerIn, MSB first (zeros after the register's own bits)."""
        _, count = _check_frame(ser_out, bits)
        self._register = self._parallel
        sent = (self._register << count) >> self._width
        self._register = (self._register << count) & _mask(self._width)
        return sent

    def convert(self) -> None:
        """A /Conv pulse: an input device ignores it."""

    def clock(self, levels: Levels) -> int:
        """The chip's pins changed to ``levels`` (pin level); returns the SerIn level from then on."""
        check_instance("levels", levels, Levels)
        seen, self._seen = self._seen, levels
        if seen.ss_n == 1:  # /SS high until this change: loading, and the value at its fall is captured
            self._register = self._parallel
        elif levels.ss_n == 0 and _rose(seen.sclk, levels.sclk):
            self._register = (self._register << 1) & _mask(self._width)
        return self._register >> (self._width - 1)


class _Sink:
    """Serial in from SerOut, parallel out: the shift register takes SerOut on every SCLK rise (only while /SS is
    low if ``selected``); the output register takes the shift register at the /Conv edge ``store_on_rise`` names."""

    def __init__(self, width: int, *, selected: bool, store_on_rise: bool) -> None:
        self._width = width
        self._selected = selected
        self._store_on_rise = store_on_rise
        self._shift = 0
        self._stored = 0
        self._seen = IDLE

    @property
    def drives_ser_in(self) -> bool:
        """False: an output device does not drive SerIn."""
        return False

    def frame(self, ser_out: int, bits: int) -> int:
        """One /SS frame (transaction level): ``bits`` bits of ``ser_out`` shifted in MSB first; returns 0."""
        word, count = _check_frame(ser_out, bits)
        self._shift = ((self._shift << count) | word) & _mask(self._width)
        return 0

    def convert(self) -> None:
        """A /Conv pulse (transaction level): the output register takes the shift register."""
        self._stored = self._shift

    def clock(self, levels: Levels) -> int:
        """The chip's pins changed to ``levels`` (pin level); returns 0 (SerIn not driven)."""
        check_instance("levels", levels, Levels)
        seen, self._seen = self._seen, levels
        if (not self._selected or levels.ss_n == 0) and _rose(seen.sclk, levels.sclk):
            self._shift = ((self._shift << 1) | levels.ser_out) & _mask(self._width)
        edge = _rose if self._store_on_rise else _fell
        if edge(seen.conv_n, levels.conv_n):
            self._stored = self._shift
        return 0


class ShiftIn(_Source):
    """A chain of ``length`` 74HCT165 parallel-in/serial-out registers (1 to 4 bytes) on SerIn (3.3.1, SM-12).

    Wiring: SCLK (MFP4) on CP of every stage, /SS (MFP5) inverted onto /PL (the chain loads while /SS is high and
    holds what it had when /SS fell), Q7 of the last stage on SerIn (MFP6), DS of the first stage grounded (zeros
    follow the chain's bits in a longer frame), /CE low. The chain's MSB (input H of the stage at SerIn) is the
    first bit of a frame, so a 16-bit chain in a 16-bit mode gives the IN word ``inputs``; a shorter chain fills the
    word's high bits, a longer one shows only its high bits.
    """

    def __init__(self, length: int) -> None:
        self._length = check_int("length", length, 1, MAX_CHAIN_BYTES, limit="3.3.1: up to 32 bits")
        super().__init__(8 * self._length)

    @property
    def length(self) -> int:
        """Bytes (74HCT165 stages) in the chain."""
        return self._length

    @property
    def inputs(self) -> int:
        """The parallel inputs, MSB = input H of the stage at SerIn."""
        return self._parallel

    def set_inputs(self, value: int) -> None:
        """Set the parallel inputs (``8 * length`` bits); the next /SS falling edge captures them."""
        self._parallel = check_bits("value", value, self._width)

    def __repr__(self) -> str:
        return f"ShiftIn({self._length})"


class ShiftOut(_Sink):
    """A chain of ``length`` 74HCT594 serial-in/parallel-out registers (1 to 4 bytes) on SerOut (3.3.1, SM-12).

    Wiring: SerOut (MFP7) on SER of the first stage, SCLK (MFP4) on SRCLK, /Conv (MFP3) on RCLK, /SRCLR and /RCLR
    on the board's reset (:meth:`clear`). The shift register shifts on every SCLK rise (the 594 has no select
    input, so read frames shift zeros in too, PR-3); the storage register takes it at the rising edge of /Conv, the
    end of the pulse (SM-12: /SS rising would store the read frame's zeros in input/output mode). The bit shifted
    in first is the MSB of :attr:`outputs`: a 16-bit chain in a 16-bit mode shows the OUT word; a shorter chain
    keeps the word's low (last-sent) bits.
    """

    def __init__(self, length: int) -> None:
        self._length = check_int("length", length, 1, MAX_CHAIN_BYTES, limit="3.3.1: up to 32 bits")
        super().__init__(8 * self._length, selected=False, store_on_rise=True)

    @property
    def length(self) -> int:
        """Bytes (74HCT594 stages) in the chain."""
        return self._length

    @property
    def outputs(self) -> int:
        """The storage registers' outputs, MSB = the stage furthest from SerOut."""
        return self._stored

    def clear(self) -> None:
        """/SRCLR and /RCLR low: shift and storage registers cleared."""
        self._shift = 0
        self._stored = 0

    def __repr__(self) -> str:
        return f"ShiftOut({self._length})"


def _check_converter_bits(bits: int) -> int:
    return check_choice("bits", bits, CONVERTER_BITS, limit="3.3.1: 16 or 32 bits")


def _check_vref(vref: object) -> float:
    reference = check_real("vref", vref)
    if reference <= 0.0:
        raise fail("vref", "a finite number > 0", vref)
    return reference


class SpiAdc(_Source):
    """A generic SPI analog-to-digital converter of ``bits`` (16 or 32) on SerIn (3.3.1, SM-12).

    Wiring: /SS (MFP5) on its chip select, SCLK (MFP4) on its clock, its data output on SerIn (MFP6). It samples
    its analog input (given as a code, :meth:`set_input`, or as a voltage, :meth:`set_voltage`) when /SS falls and
    shifts the code out MSB first on the SCLK rises while /SS is low, zeros after its last bit (PR-2). A 16-bit ADC
    in a 16-bit mode gives the IN word ``code``.
    """

    def __init__(self, bits: int = 16) -> None:
        super().__init__(_check_converter_bits(bits))

    @property
    def bits(self) -> int:
        """Bits of the conversion result."""
        return self._width

    @property
    def code(self) -> int:
        """The analog input as a code (what the next /SS falling edge samples)."""
        return self._parallel

    def set_input(self, code: int) -> None:
        """Set the analog input as its conversion result, 0 to ``2**bits - 1``."""
        self._parallel = check_bits("code", code, self._width)

    def set_voltage(self, volts: float, vref: float) -> None:
        """Set the analog input as a voltage from 0 to ``vref`` (unipolar straight binary: code =
        ``floor(volts / vref * 2**bits)``, full scale saturating at ``2**bits - 1``, PR-4)."""
        reference = _check_vref(vref)
        level = check_real("volts", volts, 0.0, reference)
        self._parallel = min(int(level / reference * (1 << self._width)), _mask(self._width))

    def __repr__(self) -> str:
        return f"SpiAdc(bits={self._width})"


class SpiDac(_Sink):
    """A generic SPI digital-to-analog converter of ``bits`` (16 or 32) on SerOut (3.3.1, SM-12).

    Wiring: /SS (MFP5) on its chip select, SCLK (MFP4) on its clock, SerOut (MFP7) on its data input, /Conv (MFP3)
    on its load input (LDAC style: "the /Conv signal ... which DACs, for example, can use to begin a conversion",
    3.3.1). It shifts SerOut in on the SCLK rises while /SS is low; :attr:`output` takes the last ``bits`` bits
    shifted when /Conv falls. A 16-bit DAC in a 16-bit mode outputs the OUT word.
    """

    def __init__(self, bits: int = 16) -> None:
        super().__init__(_check_converter_bits(bits), selected=True, store_on_rise=False)

    @property
    def bits(self) -> int:
        """Bits of the converter's input word."""
        return self._width

    @property
    def output(self) -> int:
        """The word being converted (0 after power-up)."""
        return self._stored

    def volts(self, vref: float) -> float:
        """The output voltage for reference ``vref`` (unipolar straight binary: ``vref * output / 2**bits``, PR-4)."""
        return _check_vref(vref) * self._stored / (1 << self._width)

    def __repr__(self) -> str:
        return f"SpiDac(bits={self._width})"


class SerInConflictError(ArgumentError):
    """Two devices of one :class:`SerialBus` drive SerIn (MFP6 has one driver, SM-12).

    Attributes
    ----------
    first, second:
        The two devices, in the order given.
    """

    def __init__(self, first: SerialDevice, second: SerialDevice) -> None:
        self.first = first
        self.second = second
        super().__init__(
            "devices",
            (first, second),
            f"devices must have at most one device driving SerIn (Table 3-3: MFP6), not both {first!r} and "
            f"{second!r}",
        )


class SerialBus:
    """Several devices on one serial I/O bus (3.3.1): each sees every frame, /Conv pulse and pin change; at most one
    drives SerIn (:class:`SerInConflictError` otherwise), and the bus answers with its level (0 without one: SerIn
    is grounded when unused, 3.3.1). The bus is itself a :class:`~supi3.spi.serial_io.SerialDevice`, so buses nest.
    """

    def __init__(self, *devices: SerialDevice) -> None:
        wanted = "a SerialDevice (drives_ser_in, frame, convert, clock)"
        for index, device in enumerate(devices):
            check_instance(f"devices[{index}]", device, SerialDevice, wanted)  # type: ignore[type-abstract]
            if any(device is other for other in devices[:index]):
                raise fail(f"devices[{index}]", "a device not already on the bus", device)
        drivers = [device for device in devices if device.drives_ser_in]
        if len(drivers) > 1:
            raise SerInConflictError(drivers[0], drivers[1])
        self._devices = devices
        self._driver = drivers[0] if drivers else None

    @property
    def devices(self) -> tuple[SerialDevice, ...]:
        """The devices, in the order given."""
        return self._devices

    @property
    def drives_ser_in(self) -> bool:
        """True if one of the devices drives SerIn."""
        return self._driver is not None

    def frame(self, ser_out: int, bits: int) -> int:
        """One /SS frame on every device; returns the SerIn bits of the driving device (0 without one)."""
        _check_frame(ser_out, bits)
        sent = 0
        for device in self._devices:
            answer = device.frame(ser_out, bits)
            if device is self._driver:
                sent = answer
        return sent

    def convert(self) -> None:
        """A /Conv pulse on every device."""
        for device in self._devices:
            device.convert()

    def clock(self, levels: Levels) -> int:
        """The pins changed to ``levels`` on every device; returns the driving device's SerIn level (0 without one)."""
        check_instance("levels", levels, Levels)
        level = 0
        for device in self._devices:
            answer = device.clock(levels)
            if device is self._driver:
                level = answer
        return level

    def __repr__(self) -> str:
        return f"SerialBus({', '.join(repr(device) for device in self._devices)})"

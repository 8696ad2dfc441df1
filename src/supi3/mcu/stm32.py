"""STM32F10x peripherals of the emulated board: RCC clock enables, GPIO, AFIO/EXTI and the SPI master.

Ref: STM32F10x reference manual RM0008: RCC 7.3.7 (APB2ENR), GPIO 9.2 (CRL, CRH, IDR, ODR, BSRR, BRR), AFIO 9.4.3
(EXTICR1), EXTI 10.3 (IMR, FTSR, RTSR, PR), SPI 25.3.3 (master mode), 25.3.5 (transmit and receive sequence),
25.3.7 (status flags), 25.3.10 (overrun), 25.5 (registers). Written from the manual's register descriptions; only
what a SUPI 3 firmware uses is modelled (docs/firmware-in-the-loop.md, MCU-6 to MCU-8 in docs/assumptions/mcu.md).

Each peripheral is a plain object with ``read(offset, size)`` and ``write(offset, size, value)`` for
:meth:`supi3.mcu.core.CortexM.mmio`; time comes from the core (:meth:`~supi3.mcu.core.CortexM.cycles_now`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Final, Protocol

from supi3.checks import check_int, fail
from supi3.errors import Supi3Error

__all__ = [
    "AFIO_BASE",
    "APB2RSTR",
    "EXTI0_IRQ",
    "EXTI_BASE",
    "EXTI_PR",
    "GPIOA_BASE",
    "GPIOB_BASE",
    "PERIPHERAL_SIZE",
    "RCC_BASE",
    "SPI1_BASE",
    "Exti",
    "Gpio",
    "PeripheralClockError",
    "PeripheralResetError",
    "Rcc",
    "ReadOffer",
    "Spi",
    "SpiWire",
    "ValueHolder",
]

RCC_BASE: Final[int] = 0x4002_1000
GPIOA_BASE: Final[int] = 0x4001_0800
GPIOB_BASE: Final[int] = 0x4001_0C00
AFIO_BASE: Final[int] = 0x4001_0000
EXTI_BASE: Final[int] = 0x4001_0400
SPI1_BASE: Final[int] = 0x4001_3000
PERIPHERAL_SIZE: Final[int] = 0x400
"""Each peripheral's address block (RM0008 3.3, Table 3)."""
EXTI0_IRQ: Final[int] = 6
"""The EXTI line 0 interrupt in the STM32F10x vector table (RM0008 10.1.2, Table 63)."""
EXTI_PR: Final[int] = 0x14
"""EXTI's pending register, by its offset (RM0008 10.3.6: a 1 written clears its bit)."""

APB2RSTR: Final[int] = 0x0C
"""RCC_APB2RSTR (RM0008 7.3.4): a peripheral's reset bit is at the place of its clock enable bit in APB2ENR."""
APB2ENR: Final[int] = 0x18
AFIOEN: Final[int] = 1 << 0
IOPAEN: Final[int] = 1 << 2
IOPBEN: Final[int] = 1 << 3
SPI1EN: Final[int] = 1 << 12

# SPI (RM0008 25.5.1 to 25.5.3)
CR1_CPHA: Final[int] = 1 << 0
CR1_CPOL: Final[int] = 1 << 1
CR1_MSTR: Final[int] = 1 << 2
CR1_BR_SHIFT: Final[int] = 3
CR1_SPE: Final[int] = 1 << 6
CR1_LSBFIRST: Final[int] = 1 << 7
CR1_SSI: Final[int] = 1 << 8
CR1_SSM: Final[int] = 1 << 9
CR1_DFF: Final[int] = 1 << 11
CR1_BR: Final[int] = 0b111 << CR1_BR_SHIFT
CR1_ONGOING: Final[dict[int, str]] = {CR1_CPHA: "CPHA", CR1_CPOL: "CPOL", CR1_MSTR: "MSTR", CR1_BR: "BR",
                                      CR1_LSBFIRST: "LSBFIRST"}  # fmt: skip
"""MCU-40: the CR1 fields RM0008 25.5.1 says "should not be changed when communication is ongoing" (BSY = 1)."""
SR_RXNE: Final[int] = 1 << 0
SR_TXE: Final[int] = 1 << 1
SR_MODF: Final[int] = 1 << 5
SR_OVR: Final[int] = 1 << 6
SR_BSY: Final[int] = 1 << 7
SPI_CR1, SPI_CR2, SPI_SR, SPI_DR = 0x0, 0x4, 0x8, 0xC


class PeripheralClockError(Supi3Error, RuntimeError):
    """The firmware touched a peripheral whose clock is off (RCC_APB2ENR, RM0008 7.3.7): on the chip the access
    does nothing, here it stops the run (MCU-7)."""


class PeripheralResetError(Supi3Error, RuntimeError):
    """The firmware touched GPIOA, GPIOB, AFIO or SPI1 while RCC_APB2RSTR holds it in reset (RM0008 7.3.4: the access
    would be lost), or reset SPI1 while a byte shifts (the cut byte is not modelled); here it stops the run (MCU-29)."""


class Rcc:
    """RCC with the APB2 clock enables only (MCU-7: the clock tree is not modelled, SYSCLK = PCLK2 = the core
    clock from reset)."""

    def __init__(self) -> None:
        self.apb2enr = 0
        self.apb2rstr = 0
        """RCC_APB2RSTR: the peripherals held in reset (RM0008 7.3.4)."""
        self._other: dict[int, int] = {}
        self.on_enable_change: list[Callable[[], None]] = []
        """Called when APB2ENR is written: a peripheral whose register the core answers natively takes it back."""
        self.on_reset: list[Callable[[int], None]] = []
        """Called with the value when APB2RSTR is written: a peripheral whose bit is set resets (MCU-29)."""

    def require(self, bit: int, name: str) -> None:
        """Raise :class:`PeripheralClockError` unless APB2ENR has ``bit``, :class:`PeripheralResetError` if APB2RSTR
        has it (the peripheral is held in reset: MCU-29)."""
        if not self.apb2enr & bit:
            raise PeripheralClockError(f"{name} accessed while its clock is off (RCC_APB2ENR bit {bit.bit_length() - 1}"
                                       " = 0, RM0008 7.3.7)")  # fmt: skip
        if self.apb2rstr & bit:
            raise PeripheralResetError(f"{name} accessed while RCC_APB2RSTR bit {bit.bit_length() - 1} holds it in "
                                       "reset (RM0008 7.3.4)")  # fmt: skip

    def read(self, offset: int, size: int) -> int:
        """APB2ENR, APB2RSTR, or what was written."""
        del size
        if offset == APB2ENR:
            return self.apb2enr
        return self.apb2rstr if offset == APB2RSTR else self._other.get(offset, 0)

    def write(self, offset: int, size: int, value: int) -> None:
        """APB2ENR, APB2RSTR (each peripheral whose bit is set resets: MCU-29), or kept."""
        del size
        if offset == APB2ENR:
            self.apb2enr = value
            for changed in self.on_enable_change:
                changed()
        elif offset == APB2RSTR:
            self.apb2rstr = value
            for reset in self.on_reset:
                reset(value)
        else:
            self._other[offset] = value


class Gpio:
    """One GPIO port (RM0008 9.2): CRL/CRH configure each pin, IDR reads the inputs, ODR/BSRR/BRR drive outputs.

    Parameters
    ----------
    rcc, enable_bit, name:
        The port's clock enable.
    inputs:
        The levels on the pins (bit mask) when read: the board's wiring.
    on_output:
        Called with (pin, level) when a pin configured as an output changes level.

    A pin is an output when its MODE bits are not 00 (RM0008 9.2.1); a pin that is not an output reads its input
    level, an output reads back ODR. An output pin not configured as one is not driven (MCU-6: the board's pull-ups
    keep /SS and /StatErr high).
    """

    def __init__(self, rcc: Rcc, enable_bit: int, name: str, inputs: Callable[[], int],
                 on_output: Callable[[int, int], None], pulled_up: int) -> None:  # fmt: skip
        self.rcc = rcc
        self.enable_bit = enable_bit
        self.name = name
        self.inputs = inputs
        self.on_output = on_output
        self.pulled_up = pulled_up
        self.cr = [0x4444_4444, 0x4444_4444]  # reset: every pin a floating input
        self.odr = 0
        self._mask: int | None = None  # the output pins, from CRL and CRH
        self._levels = self.levels()
        rcc.on_reset.append(self._reset)

    def _reset(self, apb2rstr: int) -> None:
        """RCC_APB2RSTR written (RM0008 7.3.4, MCU-29): with the port's bit set, CRL, CRH and ODR go to their reset
        values (9.2: every pin a floating input, ODR 0), so the pins it drove float: the board's pull-ups and the
        chip see the change (:attr:`on_output`)."""
        if apb2rstr & self.enable_bit:
            self.cr = [0x4444_4444, 0x4444_4444]
            self.odr = 0
            self._mask = None
            self._changed()

    def is_output(self, pin: int) -> bool:
        """MODE of ``pin`` is not 00 (input)."""
        return bool(self.cr[pin // 8] >> (4 * (pin % 8)) & 0b11)

    def _output_mask(self) -> int:
        if self._mask is None:
            self._mask = sum(1 << pin for pin in range(16) if self.is_output(pin))
        return self._mask

    def levels(self) -> int:
        """The levels the port drives: ODR on output pins, the pull-ups elsewhere."""
        mask = self._mask
        if mask is None:
            mask = self._output_mask()
        return (self.odr & mask) | (self.pulled_up & ~mask)

    def _changed(self) -> None:
        levels = self.levels()
        changed, self._levels = levels ^ self._levels, levels
        while changed:  # the changed pins, lowest first
            pin = (changed & -changed).bit_length() - 1
            changed &= changed - 1
            self.on_output(pin, levels >> pin & 1)

    def read(self, offset: int, size: int) -> int:
        """CRL, CRH, IDR, ODR."""
        del size
        self.rcc.require(self.enable_bit, self.name)
        if offset in (0x0, 0x4):
            return self.cr[offset // 4]
        if offset == 0x8:
            mask = self._output_mask()
            return (self.inputs() & ~mask | self.odr & mask) & 0xFFFF
        if offset == 0xC:
            return self.odr
        return 0

    def write(self, offset: int, size: int, value: int) -> None:
        """CRL, CRH, ODR, BSRR (set in bits 0..15, reset in 16..31, set wins), BRR."""
        del size
        if not self.rcc.apb2enr & self.enable_bit or self.rcc.apb2rstr & self.enable_bit:  # no call if fine (MCU-31)
            self.rcc.require(self.enable_bit, self.name)  # clock on, not held in reset (MCU-7, MCU-29)
        if offset in (0x0, 0x4):
            self.cr[offset // 4] = value
            self._mask = None
        elif offset == 0xC:
            self.odr = value & 0xFFFF
        elif offset == 0x10:
            self.odr = (self.odr & ~(value >> 16) | value) & 0xFFFF
        elif offset == 0x14:
            self.odr &= ~value & 0xFFFF
        else:
            return
        self._changed()


class Exti:
    """AFIO's EXTICR1 and the EXTI controller for lines 0..3 (RM0008 9.4.3, 10.3): an edge on a selected pin sets
    PR if its trigger is enabled; a line's interrupt request is PR AND IMR, held until PR is cleared by writing 1.

    :attr:`rose` notes the lines whose request went from low to high (an edge, a SWIER write or an IMR write), for
    the NVIC, which pends an interrupt at a rising edge of its line even while it is active (MCU-81); the board
    takes and clears it after each change.
    """

    def __init__(self, rcc: Rcc) -> None:
        self.rcc = rcc
        self.exticr1 = 0
        self.imr = 0
        self.emr = 0
        self.rtsr = 0
        self.ftsr = 0
        self.pr = 0
        self.rose = 0
        rcc.on_reset.append(self._reset)

    def _reset(self, apb2rstr: int) -> None:
        """RCC_APB2RSTR's AFIORST (bit 0, RM0008 7.3.4, MCU-29): EXTICR1 goes to 0 (9.4.3: every EXTI line on port A);
        EXTI has no reset bit and keeps its registers (10.3)."""
        if apb2rstr & AFIOEN:
            self.exticr1 = 0

    def edge(self, port: int, pin: int, level: int) -> None:
        """Pin ``pin`` of port ``port`` (0 = A) went to ``level``."""
        if self.triggers(port, pin, level):
            bit = 1 << pin
            self.rose |= bit & self.imr & ~self.pr
            self.pr |= bit

    def triggers(self, port: int, pin: int, level: int) -> bool:
        """Whether pin ``pin`` of port ``port`` going to ``level`` sets its line's pending bit: the line selects that
        port (EXTICR1) and the edge's trigger is enabled (RTSR, FTSR).

        Raises
        ------
        ArgumentError
            ``port`` not 0 to 6 (GPIOA to GPIOG, RM0008 9.4.3), ``pin`` not 0 to 15, ``level`` not 0 or 1 (UP-48:
            pin -1 raised a negative shift count, level 2 counted as a rising edge).
        """
        if type(pin) is not int or not 0 <= pin <= 15 or type(port) is not int or not 0 <= port <= 6 \
                or level not in (0, 1):  # fmt: skip
            check_int("port", port, 0, 6, "GPIOA to GPIOG, RM0008 9.4.3")
            check_int("pin", pin, 0, 15, "a port's 16 pins")
            check_int("level", level, 0, 1)
        if pin >= 4 or (self.exticr1 >> (4 * pin)) & 0xF != port:
            return False
        return bool((self.rtsr if level else self.ftsr) >> pin & 1)

    def requesting(self, line: int) -> bool:
        """Line ``line`` asks the NVIC for its interrupt."""
        return bool(self.pr & self.imr >> line & 1)

    def read_afio(self, offset: int, size: int) -> int:
        """EXTICR1 (other AFIO registers read 0)."""
        del size
        self.rcc.require(AFIOEN, "AFIO")
        return self.exticr1 if offset == 0x8 else 0

    def write_afio(self, offset: int, size: int, value: int) -> None:
        """EXTICR1."""
        del size
        self.rcc.require(AFIOEN, "AFIO")
        if offset == 0x8:
            self.exticr1 = value & 0xFFFF

    def read(self, offset: int, size: int) -> int:
        """IMR, EMR, RTSR, FTSR, SWIER (0), PR."""
        del size
        return {0x0: self.imr, 0x4: self.emr, 0x8: self.rtsr, 0xC: self.ftsr, EXTI_PR: self.pr}.get(offset, 0)

    def write(self, offset: int, size: int, value: int) -> None:
        """IMR, EMR, RTSR, FTSR, SWIER (sets PR), PR (write 1 to clear)."""
        del size
        if offset == 0x0:
            self.rose |= value & ~self.imr & self.pr
            self.imr = value
        elif offset == 0x4:
            self.emr = value
        elif offset == 0x8:
            self.rtsr = value
        elif offset == 0xC:
            self.ftsr = value
        elif offset == 0x10:
            self.rose |= value & self.imr & ~self.pr
            self.pr |= value & self.imr
        elif offset == EXTI_PR:
            self.pr &= ~value


class SpiWire(Protocol):
    """The other end of the SPI peripheral's pins: the board."""

    def spi_byte(self, tx: int, bits: int, start: int, period: int, cr1: int) -> int | Callable[[], int]:
        """A transfer of ``bits`` bits starts at cycle ``start``, one SCLK period every ``period`` cycles, with
        CR1 ``cr1``: return what MISO shifts in (as the data register will hold it), or what reads it when the
        transfer has ended (a pin-level chip drives MISO bit by bit)."""


class ValueHolder(Protocol):
    """Where a peripheral says that a register holds its value (the core answers its reads natively, MCU-25):
    :class:`supi3.mcu.core.HeldRegister`."""

    def hold(self, offset: int, value: int, until: int | None, after: int | None) -> None:
        """Reads of ``offset`` return ``value`` while their time is before cycle ``until`` (``None``: always), then
        ``after`` (``None``: the peripheral answers)."""

    def release(self) -> None:
        """Every read goes to the peripheral again."""


class ReadOffer(Protocol):
    """Where a peripheral offers one read of a register from a cycle on (the core answers it natively, MCU-26):
    :class:`supi3.mcu.core.HeldRegister`."""

    def offer(self, offset: int, value: int, start: int, then: int) -> None:
        """The first read of ``offset`` at a time from cycle ``start`` on returns ``value``, once; from then on the
        held register (:class:`ValueHolder`) reads ``then``."""

    def withdraw(self) -> int | None:
        """No more offered read; the time of the one taken, if one was."""


class _NoHolder:
    """No native answers: every read goes to the peripheral."""

    def hold(self, offset: int, value: int, until: int | None, after: int | None) -> None:
        del offset, value, until, after

    def release(self) -> None:
        pass

    def offer(self, offset: int, value: int, start: int, then: int) -> None:
        del offset, value, start, then

    def withdraw(self) -> int | None:
        return None


class Spi:
    """SPI1 as a full-duplex master (RM0008 25.3.3, 25.3.5; timing model MCU-8).

    ``now`` gives the time of a write, ``polled`` that of a status or data read (default ``now``; the board gives
    the cheaper block-end time, MCU-1).

    Writing DR while the shift register is idle starts a transfer at once (TXE stays 1, BSY 1); a second write
    waits in the transmit buffer (TXE 0) and starts when the running byte ends, back to back. A transfer takes 8
    SCLK periods (16 with DFF), a period 2^(BR+1) core clocks (PCLK2 = the core clock, MCU-7); at its end the
    received byte is in DR (RXNE 1), or lost with OVR if RXNE was still 1 (25.3.10). BSY is 1 from the start of a
    transfer to the end of the last one. MODF: SSM = 1 with SSI = 0 in master mode clears MSTR and SPE
    (25.3.10); /NSS is not wired (SSM = 0 reads it high, MCU-6).

    After a read of SR, SR holds its value (:attr:`holder`) until the shifting byte ends, then the value after it if
    nothing starts then, until the next access to SPI1 or RCC_APB2ENR: the core answers the reads in between
    natively (MCU-25). A write of DR holds SR as a read of it would then (MCU-26), and while SR is held with a byte
    shifting into an empty receive buffer, the byte's read of DR from its end on is offered (:attr:`offer`): the core
    answers it natively, SR reads as after that read, and the model catches up at its next access.
    """

    def __init__(
        self, rcc: Rcc, now: Callable[[], int], wire: SpiWire, polled: Callable[[], int] | None = None
    ) -> None:
        self.rcc = rcc
        self.now = now
        self.polled = now if polled is None else polled
        self.on_poll: Callable[[int], None] = _ignore
        """Called on a status read while a byte shifts, with the cycle SR changes next (the board's poll skip)."""
        self.on_misuse: Callable[[str, str], None] = _unreported
        """Called with (rule, detail) when a CR1 write breaks RM0008's rules for a transfer under way (MCU-40): the
        board reports it as its other violations (alone, the model goes on as written and nothing is reported)."""
        self.wire = wire
        self.cr1 = 0
        self.cr2 = 0
        self.modf = False
        self.ovr = False
        self._ovr_seen = False
        self.tx_buffer: int | None = None
        self.rx_buffer: int | None = None
        self.rx_last = 0
        self.shifting: tuple[int | Callable[[], int], int, int] | None = None  # (received, start cycle, end cycle)
        self.transfers = 0
        self.holder: ValueHolder = _NoHolder()
        """Told when SR holds its value (:meth:`supi3.mcu.core.CortexM.mmio`'s register, MCU-25)."""
        self.offer: ReadOffer = _NoHolder()
        """Told when the read of DR after the shifting byte is known (the same register of the core, MCU-26)."""
        self._holding = False
        rcc.on_enable_change.append(self._release)
        rcc.on_reset.append(self._reset)

    def _reset(self, apb2rstr: int) -> None:
        """RCC_APB2RSTR written (RM0008 7.3.4, MCU-29): with SPI1RST set, SPI1's registers and state go to their reset
        values (25.5: CR1, CR2 0, SR 0002h, DR 0) and stay there until the bit is cleared; a byte shifting at the
        write is a :class:`PeripheralResetError` (its cut is not modelled: the other end took it whole)."""
        self._release()
        if not apb2rstr & SPI1EN:
            return
        cycles = self.now()
        self._run(cycles)
        if self.shifting is not None:
            raise PeripheralResetError(f"SPI1 reset (RCC_APB2RSTR bit {SPI1EN.bit_length() - 1}) at cycle {cycles} "
                                       "while a byte shifts: a cut byte is not modelled (RM0008 7.3.4, MCU-29)")
        self.cr1 = self.cr2 = self.rx_last = 0
        self.modf = self.ovr = self._ovr_seen = False
        self.rx_buffer = self.tx_buffer = None

    def _release(self) -> None:
        if self._holding:
            self._holding = False
            self.holder.release()
            taken = self.offer.withdraw()
            if taken is not None:  # the core answered the offered read of DR at cycle `taken`: catch up with it
                self._read_dr(taken)

    @property
    def period(self) -> int:
        """Core clocks per SCLK period: f_PCLK / 2^(BR+1) (RM0008 25.5.1)."""
        return 2 << (self.cr1 >> CR1_BR_SHIFT & 0b111)

    def _run(self, cycles: int) -> None:
        while self.shifting is not None and cycles >= self.shifting[2]:
            received, _, end = self.shifting
            self.shifting = None
            if self.rx_buffer is not None:
                self.ovr = True  # the new byte is lost (25.3.10)
            else:
                self.rx_buffer = received if isinstance(received, int) else received()
            if self.tx_buffer is not None and self.cr1 & CR1_SPE:
                self._start(end)

    def _start(self, cycles: int) -> None:
        tx = self.tx_buffer if self.tx_buffer is not None else 0
        self.tx_buffer = None
        bits = 16 if self.cr1 & CR1_DFF else 8
        period = self.period
        received = self.wire.spi_byte(tx, bits, cycles, period, self.cr1)
        self.shifting = (received, cycles, cycles + bits * period)
        self.transfers += 1

    def status(self) -> int:
        """SR now (25.5.3); while a byte shifts, tells :attr:`on_poll` when SR changes next (its end)."""
        self._run(self.polled())
        if self.shifting is not None:
            self.on_poll(self.shifting[2])
        return self._status()

    def _status(self) -> int:
        """SR from the state as it is (the time caught up with)."""
        busy = self.shifting is not None or self.tx_buffer is not None
        return self._flags(self.rx_buffer is not None, self.ovr, busy)

    def _flags(self, rxne: bool, ovr: bool, busy: bool) -> int:
        return (rxne * SR_RXNE | (self.tx_buffer is None) * SR_TXE | self.modf * SR_MODF | ovr * SR_OVR
                | busy * SR_BSY)  # fmt: skip

    def read(self, offset: int, size: int) -> int:
        """CR1, CR2, SR, DR (reading DR clears RXNE; reading SR after DR clears OVR, 25.3.10)."""
        del size
        self._release()
        self.rcc.require(SPI1EN, "SPI1")  # clock on, not held in reset (MCU-7, MCU-29)
        if offset == SPI_CR1:
            return self.cr1
        if offset == SPI_CR2:
            return self.cr2
        if offset == SPI_SR:
            value = self.status()
            if self._ovr_seen:
                self.ovr = self._ovr_seen = False
            else:
                self._hold(value)
            return value
        if offset == SPI_DR:
            return self._read_dr(self.polled())
        return 0

    def _check_cr1(self, old: int, busy: bool, cycles: int) -> None:
        """A CR1 write (``old`` before it, applied; ``busy``: a byte was shifting then) against RM0008 (MCU-40):
        while a byte shifts the fields of :data:`CR1_ONGOING` must not change (25.5.1) and SPE must not be cleared
        (25.3.8: wait for RXNE, TXE, then BSY = 0 before disabling, else the transfer may be corrupted); DFF is
        written only with SPE = 0 (25.5.1). Each is reported to :attr:`on_misuse`; the model goes on as written:
        the byte shifting ends with the settings it started with, a byte waiting starts only with SPE set."""
        new = self.cr1
        changed = old ^ new
        fields = [name for mask, name in CR1_ONGOING.items() if changed & mask] if busy else []
        if fields:
            self.on_misuse("RM0008 25.5.1", f"SPI1 CR1 {', '.join(fields)} changed at cycle {cycles} while a byte "
                           "shifts (BSY = 1): they should not be changed when communication is ongoing")  # fmt: skip
        if busy and old & CR1_SPE and not new & CR1_SPE:
            self.on_misuse("RM0008 25.3.8", f"SPI1 disabled (SPE cleared) at cycle {cycles} while a byte shifts "
                           "(BSY = 1): wait for RXNE, TXE, then BSY = 0 before clearing SPE")  # fmt: skip
        if changed & CR1_DFF and old & CR1_SPE:
            self.on_misuse("RM0008 25.5.1", f"SPI1 CR1 DFF changed at cycle {cycles} while SPE = 1: it is written "
                           "only with the SPI disabled")  # fmt: skip

    def _hold(self, value: int) -> None:
        """SR now holds ``value`` until the shifting byte ends (the time a poll may skip to, MCU-10), then its value
        after the byte if known now, until an access (MCU-25); with a byte shifting into an empty receive buffer and
        none waiting, DR's read from the byte's end on is offered, and SR after it (MCU-26)."""
        self._holding = True
        shifting = self.shifting
        if shifting is None:
            self.holder.hold(SPI_SR, value, None, None)
            return
        received, _, end = shifting
        # SR once the shifting byte has ended, if nothing starts then (no byte waits) and the byte's end needs no
        # look at the wire (a received value known now): RXNE, OVR if RXNE was still 1 (25.3.10), not busy
        if type(received) is not int or self.tx_buffer is not None:
            self.holder.hold(SPI_SR, value, end, None)
            return
        self.holder.hold(SPI_SR, value, end, self._flags(True, self.ovr or self.rx_buffer is not None, False))
        if self.rx_buffer is None and not self.ovr:
            self.offer.offer(SPI_DR, received, end, self._flags(False, False, False))

    def replace_received(self, word: int) -> None:
        """The other end changed the word the shifting transfer receives (the chip released MISO before its end,
        MCU-74): the transfer ends with ``word``, and SR's hold and DR's offered read (MCU-25, MCU-26) are made
        again for it. The offered read starts at the transfer's end, so none can have been taken yet.

        Raises
        ------
        ArgumentError
            ``word`` not an integer of 16 bits at most, or no transaction-level transfer shifting (UP-48: an
            ``assert``, gone under ``python -O``).
        """
        check_int("word", word, 0, 0xFFFF, "SPI1's data register, 8 or 16 bits")
        shifting = self.shifting
        if shifting is None or type(shifting[0]) is not int:
            raise fail("Spi.replace_received's transfer", "a transaction-level transfer shifting (SPI1 has none: "
                       "nothing to replace)", shifting)  # fmt: skip
        self.shifting = (word, shifting[1], shifting[2])
        if self._holding:
            self.holder.release()
            self.offer.withdraw()
            self._hold(self._status())

    def _read_dr(self, cycles: int) -> int:
        """A read of DR at cycle ``cycles``: the received byte, RXNE cleared, OVR seen (25.3.10)."""
        self._run(cycles)
        if self.rx_buffer is not None:
            self.rx_last, self.rx_buffer = self.rx_buffer, None
        self._ovr_seen = self.ovr
        return self.rx_last

    def write(self, offset: int, size: int, value: int) -> None:
        """CR1 (MODF check on enabling), CR2, DR (into the transmit buffer; starts a transfer if idle)."""
        del size
        self._release()
        if not self.rcc.apb2enr & SPI1EN or self.rcc.apb2rstr & SPI1EN:  # the common case without a call (MCU-31)
            self.rcc.require(SPI1EN, "SPI1")  # clock on, not held in reset (MCU-7, MCU-29)
        cycles = self.now()
        if self.shifting is not None:
            self._run(cycles)
        if offset == SPI_CR1:
            old, busy, self.cr1 = self.cr1, self.shifting is not None, value & 0xFFFF
            if self.cr1 & CR1_MSTR and self.cr1 & CR1_SSM and not self.cr1 & CR1_SSI:
                self.modf = True
                self.cr1 &= ~(CR1_MSTR | CR1_SPE)
            if self.cr1 & CR1_SPE and self.tx_buffer is not None and self.shifting is None:
                self._start(cycles)
            self._check_cr1(old, busy, cycles)
        elif offset == SPI_CR2:
            self.cr2 = value & 0xFF
        elif offset == SPI_DR:
            self.tx_buffer = value & 0xFFFF  # a write with TXE = 0 overwrites the waiting byte
            if self.cr1 & CR1_SPE and self.cr1 & CR1_MSTR and self.shifting is None:
                self._start(cycles)
            if not self._ovr_seen:  # SR holds what a read of it would hold now, until the byte ends (MCU-26)
                self._hold(self._status())


def _ignore(cycles: int) -> None:
    del cycles


def _unreported(rule: str, detail: str) -> None:
    del rule, detail

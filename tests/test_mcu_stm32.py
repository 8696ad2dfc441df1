"""The STM32F10x peripherals of the emulated board (supi3.mcu.stm32) against the reference manual RM0008.

SPI: the full-duplex master sequence of 25.3.5 (Figure 240: TXE set again as soon as the byte moves to the shift
register, RXNE at the end of each byte, BSY over back-to-back bytes), overrun (25.3.10), mode fault (25.3.10), the
baud-rate divider (25.5.1). GPIO: BSRR/BRR (9.2.5, 9.2.6), outputs only where MODE is not 00 (9.2.1). EXTI: the
falling trigger, mask and pending bit (10.3). RCC: a peripheral with its clock off (7.3.7). MCU-25: SR held for the
core's native reads answers as the model would, over random histories of accesses.
"""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.mcu.stm32 import (
    AFIOEN,
    APB2ENR,
    CR1_BR_SHIFT,
    CR1_CPHA,
    CR1_CPOL,
    CR1_DFF,
    CR1_MSTR,
    CR1_SPE,
    CR1_SSI,
    CR1_SSM,
    IOPAEN,
    SPI1EN,
    SPI_CR1,
    SPI_DR,
    SPI_SR,
    SR_BSY,
    SR_MODF,
    SR_OVR,
    SR_RXNE,
    SR_TXE,
    Exti,
    Gpio,
    PeripheralClockError,
    Rcc,
    Spi,
)


class Clock:
    def __init__(self) -> None:
        self.cycles = 0

    def __call__(self) -> int:
        return self.cycles


class Wire:
    """The far end of the SPI lines: answers each byte with its complement and keeps what it saw."""

    def __init__(self) -> None:
        self.seen: list[tuple[int, int, int, int]] = []

    def spi_byte(self, tx: int, bits: int, start: int, period: int, cr1: int) -> int:
        del cr1
        self.seen.append((tx, bits, start, period))
        return ~tx & 0xFF


def _spi(br: int = 2) -> tuple[Spi, Clock, Wire]:
    rcc = Rcc()
    rcc.write(0x18, 4, SPI1EN)
    clock, wire = Clock(), Wire()
    spi = Spi(rcc, clock, wire)
    spi.write(SPI_CR1, 4, CR1_CPHA | CR1_CPOL | CR1_MSTR | CR1_SSM | CR1_SSI | br << CR1_BR_SHIFT | CR1_SPE)
    return spi, clock, wire


def _flags(spi: Spi) -> set[str]:
    value = spi.read(SPI_SR, 4)
    return {name for name, bit in (("RXNE", SR_RXNE), ("TXE", SR_TXE), ("BSY", SR_BSY), ("OVR", SR_OVR),
                                   ("MODF", SR_MODF)) if value & bit}  # fmt: skip


def test_spi_flags_follow_the_full_duplex_master_sequence() -> None:
    """RM0008 25.3.5 / Figure 240, two bytes back to back at BR = 2 (f_PCLK / 8: 64 clocks a byte)."""
    spi, clock, wire = _spi(br=2)
    assert spi.period == 8
    assert _flags(spi) == {"TXE"}  # reset: TXE = 1 (25.5.3)
    spi.write(SPI_DR, 4, 0x3C)  # 1. first byte: straight into the shift register
    assert _flags(spi) == {"TXE", "BSY"}
    clock.cycles = 10
    spi.write(SPI_DR, 4, 0xA5)  # 2. second byte waits in the transmit buffer
    assert _flags(spi) == {"BSY"}
    clock.cycles = 63
    assert _flags(spi) == {"BSY"}
    clock.cycles = 64  # 3. the first byte is in: RXNE; the second moved to the shift register: TXE
    assert _flags(spi) == {"RXNE", "TXE", "BSY"}
    assert spi.read(SPI_DR, 4) == 0xC3  # reading DR clears RXNE
    assert _flags(spi) == {"TXE", "BSY"}
    clock.cycles = 128  # 4. the last byte is in, BSY falls
    assert _flags(spi) == {"RXNE", "TXE"}
    assert spi.read(SPI_DR, 4) == 0x5A
    assert _flags(spi) == {"TXE"}
    assert wire.seen == [(0x3C, 8, 0, 8), (0xA5, 8, 64, 8)]


@pytest.mark.parametrize("br", range(8))
def test_spi_baud_rate_divider_is_two_to_the_br_plus_one(br: int) -> None:
    spi, clock, wire = _spi(br)
    spi.write(SPI_DR, 4, 0)
    clock.cycles = 8 * (2 << br) - 1
    assert _flags(spi) == {"TXE", "BSY"}
    clock.cycles += 1
    assert _flags(spi) == {"TXE", "RXNE"}
    assert wire.seen[0][3] == 2 ** (br + 1)


def test_spi_overrun_keeps_the_old_byte_until_dr_then_sr_are_read() -> None:
    """25.3.10: a byte received with RXNE still 1 is lost and OVR set; reading DR then SR clears OVR."""
    spi, clock, _ = _spi(br=0)
    spi.write(SPI_DR, 4, 0x01)
    clock.cycles = 16
    spi.write(SPI_DR, 4, 0x02)
    clock.cycles = 32
    assert _flags(spi) == {"RXNE", "TXE", "OVR"}
    assert spi.read(SPI_DR, 4) == 0xFE  # the first byte; the second (FDh) is lost
    assert "OVR" in _flags(spi)  # this SR read (after DR) clears it
    assert _flags(spi) == {"TXE"}


def test_spi_16_bit_frames_take_16_periods() -> None:
    spi, clock, wire = _spi(br=0)
    spi.write(SPI_CR1, 4, spi.cr1 | CR1_DFF)
    spi.write(SPI_DR, 4, 0x1234)
    clock.cycles = 31
    assert "BSY" in _flags(spi)
    clock.cycles = 32
    assert "BSY" not in _flags(spi)
    assert wire.seen[0][:2] == (0x1234, 16)


def test_spi_mode_fault_with_software_slave_select_low() -> None:
    """25.3.10: master with SSM = 1, SSI = 0 (NSS low): MODF, MSTR and SPE cleared, nothing sent."""
    spi, _, wire = _spi()
    spi.write(SPI_CR1, 4, CR1_MSTR | CR1_SSM | CR1_SPE)
    assert "MODF" in _flags(spi)
    assert not spi.cr1 & (CR1_MSTR | CR1_SPE)
    spi.write(SPI_DR, 4, 0x55)
    assert wire.seen == []


def test_a_peripheral_with_its_clock_off_stops_the_run() -> None:
    rcc = Rcc()
    spi = Spi(rcc, Clock(), Wire())
    with pytest.raises(PeripheralClockError, match=r"SPI1 accessed while its clock is off \(RCC_APB2ENR bit 12"):
        spi.read(SPI_SR, 4)
    gpio = Gpio(rcc, IOPAEN, "GPIOA", lambda: 0, lambda *_: None, 0)
    with pytest.raises(PeripheralClockError, match="GPIOA"):
        gpio.write(0x10, 4, 1)


def _gpio(inputs: int = 0) -> tuple[Gpio, list[tuple[int, int]]]:
    rcc = Rcc()
    rcc.write(0x18, 4, IOPAEN | AFIOEN)
    changes: list[tuple[int, int]] = []
    gpio = Gpio(rcc, IOPAEN, "GPIOA", lambda: inputs, lambda pin, level: changes.append((pin, level)), 1 << 4)
    return gpio, changes


def test_gpio_bsrr_brr_and_odr_drive_only_output_pins() -> None:
    gpio, changes = _gpio(inputs=0b101)
    gpio.write(0x10, 4, 1 << 3)  # BSRR on an input pin: ODR changes, the pin does not
    assert changes == []
    gpio.write(0x0, 4, 0x4442_2444)  # CRL: pins 3 and 4 outputs (MODE 10)
    assert changes == [(3, 1), (4, 0)]  # pin 3 drives ODR's 1, pin 4 leaves its pull-up for ODR's 0
    gpio.write(0x10, 4, (1 << 4) | (1 << (16 + 3)))  # set 4, reset 3
    gpio.write(0x14, 4, 1 << 4)  # BRR: reset 4
    assert changes == [(3, 1), (4, 0), (3, 0), (4, 1), (4, 0)]
    gpio.write(0x10, 4, (1 << 3) | (1 << 19))  # set and reset the same pin: set wins (9.2.5)
    assert gpio.read(0xC, 4) & 0b1000
    assert gpio.read(0x8, 4) == 0b1101  # IDR: inputs 0 and 2, outputs read back ODR (pin 3 high, 4 low)


def test_exti_falling_edge_sets_pending_which_asks_while_unmasked() -> None:
    rcc = Rcc()
    rcc.write(0x18, 4, AFIOEN)
    exti = Exti(rcc)
    exti.edge(0, 0, 0)
    assert exti.pr == 0  # no trigger selected
    exti.write(0xC, 4, 1)  # FTSR line 0
    exti.edge(0, 0, 1)
    assert exti.pr == 0  # a rising edge
    exti.edge(0, 0, 0)
    assert exti.pr == 1 and not exti.requesting(0)  # pending, masked
    exti.write(0x0, 4, 1)  # IMR
    assert exti.requesting(0)
    exti.write(0x14, 4, 1)  # PR: write 1 to clear
    assert exti.pr == 0 and not exti.requesting(0)
    exti.write_afio(0x8, 4, 1)  # EXTICR1: line 0 from port B
    exti.edge(0, 0, 1)
    exti.edge(0, 0, 0)
    assert exti.pr == 0
    exti.edge(1, 0, 0)
    assert exti.pr == 1


class Holder:
    """What the core does with a held register (supi3_held_read in src/supi3/mcu/hook.c, MCU-25), in Python."""

    def __init__(self, spi: Spi, clock: Clock) -> None:
        self.spi, self.clock = spi, clock
        self.held: tuple[int, int, int | None, int | None] | None = None
        self.native = 0  # reads answered without the model

    def hold(self, offset: int, value: int, until: int | None, after: int | None) -> None:
        self.held = (offset, value, until, after)

    def release(self) -> None:
        self.held = None

    def read(self, offset: int) -> int:
        if self.held is None or self.held[0] != offset:
            return self.spi.read(offset, 4)
        _, value, until, after = self.held
        if until is None or self.clock() < until:
            self.native += 1
            if until is not None:
                self.spi.on_poll(until)
            return value
        if after is not None:
            self.native += 1
            return after
        return self.spi.read(offset, 4)


_READ = st.tuples(st.just("read"), st.sampled_from([SPI_SR] * 6 + [SPI_DR, SPI_CR1]))
_WAIT = st.tuples(st.just("wait"), st.integers(0, 24))
_STEP = st.one_of(
    _READ, _READ, _READ, _WAIT, _WAIT,
    st.tuples(st.just("poll"), st.integers(0, 40)),  # SR, a wait, SR: into or past the byte's end
    st.tuples(st.just("write"), st.just(SPI_DR), st.integers(0, 0xFF)),
    st.tuples(st.just("write"), st.just(SPI_CR1), st.sampled_from([0, 1, CR1_DFF]).map(lambda v: v | CR1_SPE)),
    st.tuples(st.just("clock"), st.sampled_from([SPI1EN, 0])),
)  # fmt: skip


@settings(derandomize=True, max_examples=300, deadline=None)
@given(st.lists(_STEP, min_size=20, max_size=80))
def test_a_held_status_answers_as_the_model_would(steps: list[tuple[object, ...]]) -> None:
    """MCU-25: the SPI holds SR after a status read until its byte ends or the next access to SPI1 or RCC_APB2ENR;
    a core that answers SR from the hold in between (no call into the model) reads the same values, tells the poll
    skip the same cycles and leaves the model in the same state (once it catches up with the time) as one that
    always asks the model, over random histories of waits, reads, polls, writes, clock switches and faults (a clock
    switched off raises in both)."""
    runs = []
    for holding in (True, False):
        spi, clock, _ = _spi(br=0)
        polls: list[int] = []
        spi.on_poll = polls.append
        holder = Holder(spi, clock)
        if holding:
            spi.holder = holder
        seen: list[object] = []
        for step in steps:
            try:
                if step[0] == "wait":
                    clock.cycles += int(str(step[1]))
                elif step[0] == "poll":
                    seen.append(holder.read(SPI_SR))
                    clock.cycles += int(str(step[1]))
                    seen.append(holder.read(SPI_SR))
                elif step[0] == "read":
                    seen.append(holder.read(int(str(step[1]))))
                elif step[0] == "write":
                    spi.write(int(str(step[1])), 4, int(str(step[2])) | (CR1_MSTR | CR1_SSM | CR1_SSI) *
                              (step[1] == SPI_CR1))  # fmt: skip
                else:
                    spi.rcc.write(APB2ENR, 4, int(str(step[1])))
            except PeripheralClockError as error:
                seen.append(str(error))
        spi.rcc.write(APB2ENR, 4, SPI1EN)
        seen.append(spi.read(SPI_SR, 4))  # the model catches up with the time (a hold leaves it behind)
        state = (spi.cr1, spi.ovr, spi.modf, spi.tx_buffer, spi.rx_buffer, spi.rx_last, spi.shifting, spi.transfers)
        runs.append((seen, polls, state, holder.native))
    assert runs[0][:3] == runs[1][:3]
    assert runs[1][3] == 0

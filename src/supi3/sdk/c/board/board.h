/**
 * board.h - the emulated SUPI 3 evaluation board of supi3.mcu (docs/firmware-in-the-loop.md): an STM32F103-class
 * Cortex-M3 (or a Cortex-M0 core on the same memory map) wired to the chip's serial uP interface.
 *
 * Register layouts from the STM32F10x reference manual (RM0008): RCC 7.3, GPIO 9.2, AFIO 9.4, EXTI 10.3, SPI 25.5;
 * the core's SysTick, NVIC and SCB from the ARMv7-M Architecture Reference Manual (B3.2, B3.3, B3.4). Only what
 * the board port (board.c) uses is named here.
 *
 * Wiring (the pin numbers are the emulator's too: supi3.mcu.stm32 PIN_* constants, checked by a test):
 *   PA0  <- /IRQ (MFP3)       input, EXTI line 0, falling edge (3.4.14)
 *   PA1  <- C/D (MFP2)        input (3.4.3)
 *   PA2  <- I/O access (MFP1) input, 1 = no data register access now (3.4.14, Fig. 3-22)
 *   PA3  -> SAS_INIT          output, 1 = active (3.4.3)
 *   PA4  -> /SS               output (GPIO, one frame per byte: 3.4.2)
 *   PA5  -> SCLK, PA6 <- SerOUT (MISO), PA7 -> SerIN (MOSI): SPI1, mode 3, MSB first (Motorola, 3.4.2)
 *   PA8  -> /StatErr          output, 0 = peripheral fault (3.6.2)
 *   PB1  <- /ModAck           input, EXTI line 1 falling edge: PR latches the 375 ns pulse (3.6.2); no interrupt
 */
#ifndef SUPI3_BOARD_H
#define SUPI3_BOARD_H

#include <stdint.h>

/** CPU clock the firmware assumes (SYSCLK = HCLK = PCLK2; the emulator's default cpu_hz). */
#ifndef BOARD_SYSCLK_HZ
#define BOARD_SYSCLK_HZ 48000000u
#endif

/** SPI1 baud-rate divider code CR1.BR: f_SCLK = f_PCLK2 / 2^(BR+1) (RM0008 25.5.1). 5 = /64: 750 kHz at 48 MHz,
 *  slower than Table 3-7's t0 at 500 kbit/s (667 ns) and 2 Mbit/s (167 ns). */
#ifndef BOARD_SPI_BR
#define BOARD_SPI_BR 5u
#endif

#define BOARD_PIN_IRQ 0u
#define BOARD_PIN_CD 1u
#define BOARD_PIN_IO 2u
#define BOARD_PIN_SAS_INIT 3u
#define BOARD_PIN_SS 4u
#define BOARD_PIN_SCK 5u
#define BOARD_PIN_MISO 6u
#define BOARD_PIN_MOSI 7u
#define BOARD_PIN_STAT_ERR 8u
#define BOARD_PIN_MODACK 1u /* on port B */
#define BOARD_PIN_SR 0u /* on port B: S/R to MFP7, Intel mode only (docs/assumptions/mcu.md MCU-18) */

#define REG32(address) (*(volatile uint32_t *)(address))

/* RCC (RM0008 7.3.7): APB2 peripheral clock enable. */
#define RCC_APB2ENR REG32(0x40021018u)
#define RCC_APB2ENR_AFIOEN (1u << 0)
#define RCC_APB2ENR_IOPAEN (1u << 2)
#define RCC_APB2ENR_IOPBEN (1u << 3)
#define RCC_APB2ENR_SPI1EN (1u << 12)

/* GPIOA (RM0008 9.2): CRL/CRH 4 bits per pin (MODE[1:0], CNF[1:0]), IDR, ODR, BSRR (set low half), BRR. */
#define GPIOA_CRL REG32(0x40010800u)
#define GPIOA_CRH REG32(0x40010804u)
#define GPIOA_IDR REG32(0x40010808u)
#define GPIOA_BSRR REG32(0x40010810u)
#define GPIOA_BRR REG32(0x40010814u)
#define GPIOB_CRL REG32(0x40010C00u)
#define GPIOB_BSRR REG32(0x40010C10u)
#define GPIOB_BRR REG32(0x40010C14u)
#define GPIO_CFG_INPUT_FLOATING 0x4u   /* CNF 01, MODE 00 */
#define GPIO_CFG_OUTPUT_PP_2MHZ 0x2u   /* CNF 00, MODE 10 */
#define GPIO_CFG_AF_PP_50MHZ 0xBu      /* CNF 10, MODE 11 */

/* AFIO (RM0008 9.4.3): EXTICR1 selects the port of EXTI lines 0..3, 4 bits each (0 = PA, 1 = PB). */
#define AFIO_EXTICR1 REG32(0x40010008u)
#define AFIO_EXTICR_PB 1u

/* EXTI (RM0008 10.3): interrupt mask, falling trigger, pending (write 1 to clear). */
#define EXTI_IMR REG32(0x40010400u)
#define EXTI_FTSR REG32(0x4001040Cu)
#define EXTI_PR REG32(0x40010414u)

/* SPI1 (RM0008 25.5). */
#define SPI1_CR1 REG32(0x40013000u)
#define SPI1_CR2 REG32(0x40013004u)
#define SPI1_SR REG32(0x40013008u)
#define SPI1_DR REG32(0x4001300Cu)
#define SPI_CR1_CPHA (1u << 0)
#define SPI_CR1_CPOL (1u << 1)
#define SPI_CR1_MSTR (1u << 2)
#define SPI_CR1_BR_POS 3u
#define SPI_CR1_SPE (1u << 6)
#define SPI_CR1_LSBFIRST (1u << 7)
#define SPI_CR1_SSI (1u << 8)
#define SPI_CR1_SSM (1u << 9)
#define SPI_SR_RXNE (1u << 0)
#define SPI_SR_TXE (1u << 1)
#define SPI_SR_BSY (1u << 7)

/* SysTick (ARMv7-M B3.3): CSR, RVR, CVR. */
#define SYST_CSR REG32(0xE000E010u)
#define SYST_RVR REG32(0xE000E014u)
#define SYST_CVR REG32(0xE000E018u)
#define SYST_CSR_ENABLE (1u << 0)
#define SYST_CSR_CLKSOURCE (1u << 2)

/* NVIC (ARMv7-M B3.4): interrupt set-enable. EXTI0 is IRQ 6 of the STM32F10x vector table (RM0008 10.1.2). */
#define NVIC_ISER0 REG32(0xE000E100u)
#define BOARD_EXTI0_IRQN 6u

#endif /* SUPI3_BOARD_H */

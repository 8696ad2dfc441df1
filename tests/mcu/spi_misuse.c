/*
 * spi_misuse.c - a firmware that changes SPI1's CR1 while a byte shifts (tests/test_mcu_serve.py, MCU-30): RM0008
 * 25.5.1 says BR, CPOL, CPHA, LSBFIRST and MSTR "should not be changed when communication is ongoing" and DFF is
 * written only with SPE = 0; 25.3.8 clears SPE only after RXNE, TXE and BSY = 0. MISUSE selects the write:
 * 1 = BR, 2 = SPE cleared, 3 = DFF with SPE set (between bytes), 4 = none (the same byte done right).
 */
#include "board.h"
#include "fw_board.h"

#ifndef MISUSE
#define MISUSE 1
#endif

void fw_setup(supi3_t *chip, fw_board_t *board)
{
    uint32_t cr1 = SPI1_CR1;
    (void)chip;
    GPIOA_BRR = 1u << BOARD_PIN_SS;
    board->delay_us(board->user, 1u); /* t1 */
    SPI1_DR = 0x00u; /* the initialization byte, Motorola (3.4.3) */
    if (MISUSE == 1) {
        SPI1_CR1 = cr1 ^ (1u << SPI_CR1_BR_POS); /* the neighbouring divider */
    } else if (MISUSE == 2) {
        SPI1_CR1 = cr1 & ~SPI_CR1_SPE;
    }
    while ((SPI1_SR & SPI_SR_RXNE) == 0u) {
    }
    (void)SPI1_DR;
    while ((SPI1_SR & SPI_SR_BSY) != 0u) {
    }
    if (MISUSE == 3) {
        SPI1_CR1 = cr1 | (1u << 11); /* DFF with SPE still set */
    }
    SPI1_CR1 = cr1; /* back as it was (SPE set again after case 2): no byte shifts now */
    board->delay_us(board->user, 1u); /* t2 */
    GPIOA_BSRR = 1u << BOARD_PIN_SS;
}

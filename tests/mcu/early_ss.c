/*
 * early_ss.c - a firmware with the classic SPI bug (tests/test_mcu_board.py): it raises /SS when TXE is set, which
 * is as soon as the byte has moved to the shift register (RM0008 25.3.5), not when the byte is out (BSY = 0).
 * The chip sees a frame of fewer than 8 SCLK edges (3.4.2).
 */
#include "board.h"
#include "fw_board.h"

void fw_setup(supi3_t *chip, fw_board_t *board)
{
    (void)chip;
    (void)board;
    GPIOA_BRR = 1u << BOARD_PIN_SS;
    SPI1_DR = 0x00u; /* the initialization byte, Motorola (3.4.3) */
    while ((SPI1_SR & SPI_SR_TXE) == 0u) {
    }
    GPIOA_BSRR = 1u << BOARD_PIN_SS;
}

/*
 * gpio_reset.c - a firmware that resets GPIOA and AFIO through RCC_APB2RSTR (RM0008 7.3.4) in the middle of its
 * work (tests/test_mcu_serve.py, MCU-30): /SS is low (a frame has begun) when GPIOA's reset floats it, so the
 * board's pull-up raises it and the chip sees the frame end with no SCLK edge (3.4.2). The registers read back
 * after the reset land in reset_seen; ACCESS_IN_RESET = 1 reads GPIOA while the reset bit is still set.
 */
#include "board.h"
#include "fw_board.h"

#define RCC_APB2RSTR REG32(0x4002100Cu)

#ifndef ACCESS_IN_RESET
#define ACCESS_IN_RESET 0
#endif

volatile uint32_t reset_seen[3]; /* GPIOA_CRL, GPIOA_CRH, AFIO_EXTICR1 after the reset */

void fw_setup(supi3_t *chip, fw_board_t *board)
{
    (void)chip;
    GPIOA_BRR = 1u << BOARD_PIN_SS;
    board->delay_us(board->user, 1u);
    RCC_APB2RSTR = RCC_APB2ENR_IOPAEN | RCC_APB2ENR_AFIOEN;
    if (ACCESS_IN_RESET) {
        reset_seen[0] = GPIOA_IDR;
    }
    RCC_APB2RSTR = 0u;
    reset_seen[0] = GPIOA_CRL;
    reset_seen[1] = GPIOA_CRH;
    reset_seen[2] = AFIO_EXTICR1;
}

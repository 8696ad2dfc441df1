/*
 * delay.c - the board port's busy wait timed on the emulated board (tests/test_mcu_delay.py, MCU-62): fw_setup calls
 * board->delay_us(k) for each k of fw_delay_us and keeps the core clocks each call took, read from SysTick on the
 * core clock (CLKSOURCE 1, MCU-5), in fw_delay_cycles. The count includes the call through the board's pointer and
 * the two reads of SysTick's counter.
 */
#include "board.h"
#include "fw_board.h"

#define DELAYS 6u

const volatile uint32_t fw_delay_us[DELAYS] = {0u, 1u, 4u, 20u, 100u, 255u};
uint32_t fw_delay_cycles[DELAYS];

void fw_setup(supi3_t *chip, fw_board_t *board)
{
    uint32_t k;
    uint32_t start;
    (void)chip;
    SYST_RVR = 0xFFFFFFu;
    SYST_CVR = 0u;
    SYST_CSR = SYST_CSR_ENABLE | SYST_CSR_CLKSOURCE;
    for (k = 0u; k < DELAYS; ++k) {
        start = SYST_CVR;
        board->delay_us(board->user, fw_delay_us[k]);
        fw_delay_cycles[k] = (start - SYST_CVR) & 0xFFFFFFu;
    }
}

/*
 * main_loop.c - the main-loop variant of an interrupt example (tests/test_mcu_serve.py, MCU-30): linked beside
 * digital_io.c it defines fw_loop, so the board port's EXTI0 handler only notes the /IRQ edge and main() calls
 * fw_isr() between two passes of fw_loop (examples/fw_board.h). A pass is PASS_US of other work; with STUCK = 1 the
 * first pass never returns (a main loop that never comes back to its idle point).
 */
#include "fw_board.h"

#ifndef PASS_US
#define PASS_US 20u
#endif
#ifndef STUCK
#define STUCK 0
#endif

void fw_loop(supi3_t *chip, fw_board_t *board)
{
    (void)chip;
    do {
        board->delay_us(board->user, PASS_US);
    } while (STUCK);
}

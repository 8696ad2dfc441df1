/*
 * due_cross.c - native frames that would run across a cycle's end (tests/test_mcu_fastbyte.py, MCU-52): the handler
 * writes IN0 and IN1 with a new value, then reads PCMD (a register that is no data register, so the latch phase's
 * check does not stop its frames) for longer than a 2 Mbit/s cycle. The next cycle's latch must take the new IN
 * data: it does only if the frames past the cycle's end go to Python, which runs the bus after the earlier frames'
 * writes (the `due` threshold of hook.c).
 */
#include "fw_board.h"

#define READS 16u /* PCMD reads: two frames each, about 8 us at SPI1's 3 MHz, longer than a 62.5 us cycle in all */

void fw_setup(supi3_t *chip, fw_board_t *board)
{
    if (fw_note(board, supi3_initialize(chip, FW_MODE)) != SUPI3_OK ||
        fw_note(board, supi3_configure(chip, 0x83u, 0x03u)) != SUPI3_OK) {
        return;
    }
    (void)fw_note(board, supi3_irq_enable(chip, SUPI3_IRQ_EN_VALID_MSK));
}

void fw_isr(supi3_t *chip, fw_board_t *board)
{
    uint8_t events = 0u;
    uint8_t pcmd = 0u;
    (void)fw_note(board, supi3_irq_service(chip, &events));
    board->cycles++;
    (void)fw_note(board, supi3_write(chip, SUPI3_IN0_ADDR, (uint8_t)board->cycles));
    (void)fw_note(board, supi3_write(chip, SUPI3_IN1_ADDR, (uint8_t)(board->cycles >> 8)));
    for (uint32_t k = 0u; k < READS; k++) {
        (void)fw_note(board, supi3_read(chip, SUPI3_PCMD_ADDR, &pcmd));
    }
    board->outputs[0] = pcmd;
}

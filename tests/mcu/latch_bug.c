/*
 * latch_bug.c - a firmware with a deliberate latch-phase bug (tests/test_mcu_board.py): the main loop reads OUT0
 * whenever it likes, without looking at the I/O access bit (3.4.14, Fig. 3-22). Sooner or later a read falls into
 * the latch phase and the chip reports inconsistent data; the report must name the line marked LATCH-BUG.
 * (The read's result is used: a tail call would leave no frame of fw_loop on the stack.)
 */
#include "fw_board.h"

void fw_setup(supi3_t *chip, fw_board_t *board)
{
    if (fw_note(board, supi3_initialize(chip, FW_MODE)) != SUPI3_OK) {
        return;
    }
    (void)fw_note(board, supi3_configure(chip, 0x83u, 0x03u)); /* one word, digital I/O (Table 3-12, A-3) */
}

void fw_loop(supi3_t *chip, fw_board_t *board)
{
    if (fw_note(board, supi3_read(chip, SUPI3_OUT0_ADDR, &board->outputs[0])) == SUPI3_OK) { /* LATCH-BUG */
        board->cycles++;
    }
}

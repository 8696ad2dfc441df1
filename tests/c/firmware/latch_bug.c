/*
 * latch_bug.c - a polling firmware with a timing bug, for the model to catch (3.4.14, Fig. 3-22).
 *
 * It waits for the I/O access bit to fall (the end of a cycle) correctly, but then runs a 230 us computation
 * before it reads OUT: far past the 30 bit periods (60 us at 500 kbit/s) the window guarantees. On a short
 * ring the next cycle's latch phase comes first, and the read overlaps it: inconsistent data.
 */
#include "fw_board.h"

#define WORK_US 230u

void fw_setup(supi3_t *chip, fw_board_t *board)
{
    if (fw_note(board, supi3_initialize(chip, SUPI3_MODE_MOTOROLA)) == SUPI3_OK) {
        (void)fw_note(board, supi3_configure(chip, 0x83u, 0x03u));
    }
}

void fw_loop(supi3_t *chip, fw_board_t *board)
{
    static int busy_seen = 0;
    uint8_t events = 0u;
    int err = supi3_poll_io_window(chip, 1u, &events);
    if (err == SUPI3_E_TIMEOUT) {
        busy_seen = 1;
    } else if (fw_note(board, err) != SUPI3_OK) {
        return;
    } else if (busy_seen) {
        busy_seen = 0;
        board->delay_us(board->user, WORK_US); /* the bug: the window closes meanwhile */
        if (fw_note(board, supi3_read(chip, SUPI3_OUT0_ADDR, &board->outputs[0])) != SUPI3_OK ||
            fw_note(board, supi3_read(chip, SUPI3_OUT1_ADDR, &board->outputs[1])) != SUPI3_OK) {
            return;
        }
        board->cycles++;
    }
    board->delay_us(board->user, 10u);
}

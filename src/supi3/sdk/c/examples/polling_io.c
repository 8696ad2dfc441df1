/*
 * polling_io.c - a 16 IN / 16 OUT digital device synchronized by the I/O access bit instead of interrupts
 * (3.4.14, "Using the polling bit", Fig. 3-22).
 *
 * The I/O access bit (MFP1, or D7 of read 14 without the pin) is 1 from the check sequence to the end of a
 * cycle, latch phase included; when it reads 0 the data registers may be accessed within the next 30 bit
 * periods (60 us at 500 kbit/s). The main loop polls it every POLL_US: the 1 -> 0 edge is the end of a cycle,
 * so the firmware then exchanges its data at once: four single accesses, 8 bytes, inside the 30-bit window.
 * (Two words would take longer; the manual advises interrupts for them, 3.4.6.)
 */
#include "fw_board.h"

#define DEV_SET 0x83u     /* /PCP = 1, ExtReg = 0, CL = 011: one word (Table 3-12) */
#define DEV_ID_CODE 0x03u /* remote bus digital input/output module (Table A-3) */
#define POLL_US 10u       /* the other work of one main-loop pass; far below the 1-phase (>= 30 bit periods) */

void fw_setup(supi3_t *chip, fw_board_t *board)
{
    if (fw_note(board, supi3_initialize(chip, FW_MODE)) != SUPI3_OK) {
        return;
    }
    (void)fw_note(board, supi3_configure(chip, DEV_SET, DEV_ID_CODE)); /* no interrupt enabled */
}

void fw_loop(supi3_t *chip, fw_board_t *board)
{
    static int busy_seen = 0; /* the I/O bit was 1 since the last exchange: a cycle is running */
    uint8_t events = 0u;
    int err = supi3_poll_io_window(chip, 1u, &events);
    if (err == SUPI3_E_TIMEOUT) {
        busy_seen = 1;
    } else if (fw_note(board, err) != SUPI3_OK) {
        return;
    } else if (busy_seen) {
        /* The bit just fell: new OUT data, and the 30-bit window is open. */
        busy_seen = 0;
        if (fw_note(board, supi3_read(chip, SUPI3_OUT0_ADDR, &board->outputs[0])) != SUPI3_OK ||
            fw_note(board, supi3_read(chip, SUPI3_OUT1_ADDR, &board->outputs[1])) != SUPI3_OK ||
            fw_note(board, supi3_write(chip, SUPI3_IN0_ADDR, board->inputs[0])) != SUPI3_OK ||
            fw_note(board, supi3_write(chip, SUPI3_IN1_ADDR, board->inputs[1])) != SUPI3_OK) {
            return;
        }
        board->cycles++;
    }
    board->delay_us(board->user, POLL_US);
}

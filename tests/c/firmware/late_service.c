/*
 * late_service.c - a 16 IN / 16 OUT device (SET 83h, one block transfer per VALID event, 3.4.6) whose first service
 * routine does SERVICE_DELAY_US of other work before it reads the interrupt events (FW-22, tests/test_sdk_lost_edge.py).
 * With the master's cycle a little longer than the delay, the events are read in the frame in which the next cycle's
 * VALID event comes (3.4.14): /IRQ stays low, and no new falling edge follows. ONCE = 1 reads register 14 once
 * (supi3_read), as a firmware that serves one event per edge; ONCE = 0 calls supi3_irq_service, which reads until
 * /IRQ is high.
 */
#include "fw_board.h"

#ifndef SERVICE_DELAY_US
#define SERVICE_DELAY_US 990u
#endif
#ifndef ONCE
#define ONCE 0
#endif

#define DIO_SET 0x83u     /* one word (Table 3-12) */
#define DIO_ID_CODE 0x03u /* digital input/output module (Table A-3) */

void fw_setup(supi3_t *chip, fw_board_t *board)
{
    if (fw_note(board, supi3_initialize(chip, FW_MODE)) != SUPI3_OK ||
        fw_note(board, supi3_configure(chip, DIO_SET, DIO_ID_CODE)) != SUPI3_OK) {
        return;
    }
    (void)fw_note(board, supi3_irq_enable(chip, SUPI3_IRQ_EN_VALID_MSK));
}

void fw_isr(supi3_t *chip, fw_board_t *board)
{
    static int delayed;
    uint8_t events = 0u;
    int err;
    if (!delayed) { /* once: later entries (the edge of the event read in this one, too) come at once */
        delayed = 1;
        board->delay_us(board->user, SERVICE_DELAY_US);
    }
    err = ONCE ? supi3_read(chip, SUPI3_IRQ_EVT_ADDR, &events) : supi3_irq_service(chip, &events);
    if (fw_note(board, err) == SUPI3_OK && (events & SUPI3_IRQ_EVT_VALID_MSK) != 0u &&
        fw_note(board, supi3_block_transfer(chip, 1, 1, board->outputs, board->inputs, 2u)) == SUPI3_OK) {
        board->cycles++; /* OUT0..1 to the outputs, the inputs to IN0..1 (3.4.6) */
    }
}

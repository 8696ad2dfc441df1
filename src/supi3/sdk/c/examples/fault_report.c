/*
 * fault_report.c - a 16 IN / 16 OUT output module that reports a peripheral fault on /StatErr and waits for the
 * master's "Quit Peripheral Error" (/ModAck pulse) before it drives its outputs again (3.6.2).
 *
 * /StatErr low is an I/O error, e.g. a short circuit at an output; after the chip's input filter
 * (t3 = 200 ms +-31.5 %) the master shows "I/O Device Error Indication" 0BB1h. The firmware:
 *  - drives /StatErr while the fault lasts, and on a fault switches the outputs off and keeps them off
 *    ("tripped") even when the fault goes away by itself;
 *  - on the /ModAck pulse of Control_Device_Function 0714h "Quit Peripheral Error" (375 ns: the board latches
 *    its edge) drives the outputs again, if the fault is gone; if not, it stays tripped.
 * The chip itself keeps reporting the fault to the master until a Quit Peripheral Error after /StatErr went
 * high. The work runs in the "valid data cycle" service routine: one block transfer of one word (3.4.6).
 */
#include "fw_board.h"

#define DEV_SET 0x83u     /* /PCP = 1, ExtReg = 0, CL = 011: one word (Table 3-12) */
#define DEV_ID_CODE 0x03u /* remote bus digital input/output module (Table A-3) */
#define DEV_BYTES 2u

void fw_setup(supi3_t *chip, fw_board_t *board)
{
    if (fw_note(board, supi3_initialize(chip, FW_MODE)) != SUPI3_OK ||
        fw_note(board, supi3_configure(chip, DEV_SET, DEV_ID_CODE)) != SUPI3_OK) {
        return;
    }
    (void)fw_note(board, supi3_irq_enable(chip, SUPI3_IRQ_EN_VALID_MSK));
}

/* /StatErr follows the fault; returns whether the outputs may be driven. */
static int outputs_allowed(fw_board_t *board)
{
    static int stat_err = 0; /* /StatErr is driven */
    static int tripped = 0;  /* outputs off until the master acknowledges */
    int acknowledged = 0;
    if (board->mod_ack_seen(board->user, &acknowledged) != 0) {
        board->error = SUPI3_E_TRANSPORT;
        return 0;
    }
    if (board->fault) {
        tripped = 1;
    } else if (acknowledged) {
        tripped = 0;
    }
    if (board->fault != stat_err) {
        if (board->set_stat_err(board->user, board->fault) != 0) {
            board->error = SUPI3_E_TRANSPORT;
            return 0;
        }
        stat_err = board->fault;
    }
    return !tripped;
}

void fw_isr(supi3_t *chip, fw_board_t *board)
{
    uint8_t events = 0u;
    uint8_t out[DEV_BYTES];
    if (fw_note(board, supi3_irq_service(chip, &events)) != SUPI3_OK || (events & SUPI3_IRQ_EVT_VALID_MSK) == 0u) {
        return;
    }
    if (fw_note(board, supi3_block_transfer(chip, 1, 1, out, board->inputs, DEV_BYTES)) != SUPI3_OK) {
        return;
    }
    if (outputs_allowed(board)) {
        board->outputs[0] = out[0];
        board->outputs[1] = out[1];
    } else {
        board->outputs[0] = 0u; /* safe state */
        board->outputs[1] = 0u;
    }
    board->cycles++;
}

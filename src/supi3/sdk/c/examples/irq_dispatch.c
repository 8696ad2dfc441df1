/*
 * irq_dispatch.c - an interrupt-driven device serving the interrupt sources of Table 3-13 (3.4.14).
 *
 * A 16 IN / 16 OUT digital device (SET 83h, ID 03h) whose service routine reads the event register once per
 * /IRQ (the read clears it and releases /IRQ, 3.4.14) and serves every source that is set:
 *  - ID cycle: write the inputs now, so that the first data cycle already carries them (Table 3-13);
 *  - valid data cycle: take the new OUT data and write the next IN data (one block transfer of one word, 3.4.6);
 *  - invalid data cycle: OUT is still the last valid cycle's; write IN again (Table 3-13);
 *  - INTERBUS reset: the chip reset its data registers; the outputs go to their safe state (all off).
 */
#include "fw_board.h"

#define DEV_SET 0x83u     /* /PCP = 1, ExtReg = 0, CL = 011: one word (Table 3-12) */
#define DEV_ID_CODE 0x03u /* remote bus digital input/output module (Table A-3) */
#define DEV_BYTES 2u
#define DEV_EVENTS (SUPI3_IRQ_EN_ID_CYCLE_MSK | SUPI3_IRQ_EN_VALID_MSK | SUPI3_IRQ_EN_INVALID_MSK | \
                    SUPI3_IRQ_EN_IB_RESET_MSK)

void fw_setup(supi3_t *chip, fw_board_t *board)
{
    if (fw_note(board, supi3_initialize(chip, FW_MODE)) != SUPI3_OK ||
        fw_note(board, supi3_configure(chip, DEV_SET, DEV_ID_CODE)) != SUPI3_OK) {
        return;
    }
    (void)fw_note(board, supi3_irq_enable(chip, DEV_EVENTS));
}

static int write_inputs(supi3_t *chip, fw_board_t *board)
{
    return fw_note(board, supi3_write(chip, SUPI3_IN0_ADDR, board->inputs[0])) != SUPI3_OK ||
           fw_note(board, supi3_write(chip, SUPI3_IN1_ADDR, board->inputs[1])) != SUPI3_OK;
}

void fw_isr(supi3_t *chip, fw_board_t *board)
{
    uint8_t events = 0u;
    uint8_t out[DEV_BYTES];
    if (fw_note(board, supi3_irq_service(chip, &events)) != SUPI3_OK) {
        return;
    }
    if ((events & SUPI3_IRQ_EVT_IB_RESET_MSK) != 0u) {
        board->outputs[0] = 0u; /* safe state */
        board->outputs[1] = 0u;
    }
    if ((events & SUPI3_IRQ_EVT_VALID_MSK) != 0u) {
        if (fw_note(board, supi3_block_transfer(chip, 1, 1, out, board->inputs, DEV_BYTES)) != SUPI3_OK) {
            return;
        }
        board->outputs[0] = out[0];
        board->outputs[1] = out[1];
        board->cycles++;
    } else if ((events & (SUPI3_IRQ_EVT_ID_CYCLE_MSK | SUPI3_IRQ_EVT_INVALID_MSK)) != 0u) {
        (void)write_inputs(chip, board);
    }
}

/*
 * reconfigure_bug.c - a firmware that writes SET while the bus runs (forbidden: 3.4.3 note, 3.4.11), for the
 * strict model to catch: after its first valid data cycle it "switches" to two words.
 */
#include "fw_board.h"

void fw_setup(supi3_t *chip, fw_board_t *board)
{
    if (fw_note(board, supi3_initialize(chip, SUPI3_MODE_MOTOROLA)) == SUPI3_OK &&
        fw_note(board, supi3_configure(chip, 0x83u, 0x03u)) == SUPI3_OK) {
        (void)fw_note(board, supi3_irq_enable(chip, SUPI3_IRQ_EN_VALID_MSK));
    }
}

void fw_isr(supi3_t *chip, fw_board_t *board)
{
    uint8_t events = 0u;
    if (fw_note(board, supi3_irq_service(chip, &events)) == SUPI3_OK && (events & SUPI3_IRQ_EVT_VALID_MSK) != 0u) {
        (void)fw_note(board, supi3_write(chip, SUPI3_SET_ADDR, 0x85u)); /* the bug */
    }
}

/*
 * sas_init.c - SAS_INIT on the emulated board (tests/test_mcu_pins.py): the interface is initialized and configured
 * (SET 83h, ID 03h), reset with SAS_INIT (3.4.3: the registers are kept, the initialization byte is expected again),
 * initialized again, and SET read back into outputs[0]. With SAS_SHORT = 1 the pulse is two stores back to back,
 * shorter than Table 3-7's t_SAS_INIT.
 */
#include "board.h"
#include "fw_board.h"

#ifndef SAS_SHORT
#define SAS_SHORT 0u
#endif

void fw_setup(supi3_t *chip, fw_board_t *board)
{
    if (fw_note(board, supi3_initialize(chip, FW_MODE)) != SUPI3_OK ||
        fw_note(board, supi3_configure(chip, 0x83u, 0x03u)) != SUPI3_OK) {
        return;
    }
    if (SAS_SHORT) {
        GPIOA_BSRR = 1u << BOARD_PIN_SAS_INIT;
        GPIOA_BRR = 1u << BOARD_PIN_SAS_INIT;
        return;
    }
    if (fw_note(board, supi3_sas_init(chip)) != SUPI3_OK || fw_note(board, supi3_initialize(chip, FW_MODE)) != SUPI3_OK) {
        return;
    }
    (void)fw_note(board, supi3_read(chip, SUPI3_SET_ADDR, &board->outputs[0]));
}

/*
 * digital_io.c - a 16-input / 16-output digital remote bus device (ID code 03h "DIO", Table A-3).
 *
 * One word of process data each way (SET 83h: /PCP = 1, an I/O device; ExtReg = 0; CL = 011, one word,
 * Tables 3-11 and 3-12). Synchronized by the "valid data cycle" interrupt (3.4.14, "Using interrupts"):
 * after each valid data cycle the firmware reads OUT0, OUT1 (the master's outputs, 3.4.8: byte 0 is the
 * most significant) with single register accesses (3.4.4) and writes its inputs to IN0, IN1 for the next
 * cycle. Four accesses are 8 bytes, well inside T = 13 * (5 + n) * t_Bit after /IRQ (3.4.14).
 */
#include "fw_board.h"

#define DIO_SET 0x83u     /* /PCP = 1, ExtReg = 0, CL = 011: one word (3.4.11, Table 3-12) */
#define DIO_ID_CODE 0x03u /* remote bus digital input/output module (Table A-3) */

void fw_setup(supi3_t *chip, fw_board_t *board)
{
    /* 3.4.3: initialization byte first, then SET and ID while the bus does not run yet, then the interrupt. */
    if (fw_note(board, supi3_initialize(chip, FW_MODE)) != SUPI3_OK) {
        return;
    }
    if (fw_note(board, supi3_configure(chip, DIO_SET, DIO_ID_CODE)) != SUPI3_OK) {
        return;
    }
    (void)fw_note(board, supi3_irq_enable(chip, SUPI3_IRQ_EN_VALID_MSK));
}

void fw_isr(supi3_t *chip, fw_board_t *board)
{
    uint8_t events = 0u;
    if (fw_note(board, supi3_irq_service(chip, &events)) != SUPI3_OK || (events & SUPI3_IRQ_EVT_VALID_MSK) == 0u) {
        return;
    }
    /* Valid data cycle: OUT holds the master's new outputs (Table 3-13). */
    if (fw_note(board, supi3_read(chip, SUPI3_OUT0_ADDR, &board->outputs[0])) != SUPI3_OK ||
        fw_note(board, supi3_read(chip, SUPI3_OUT1_ADDR, &board->outputs[1])) != SUPI3_OK ||
        fw_note(board, supi3_write(chip, SUPI3_IN0_ADDR, board->inputs[0])) != SUPI3_OK ||
        fw_note(board, supi3_write(chip, SUPI3_IN1_ADDR, board->inputs[1])) != SUPI3_OK) {
        return;
    }
    board->cycles++;
}

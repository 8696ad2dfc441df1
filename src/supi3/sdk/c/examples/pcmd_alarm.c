/*
 * pcmd_alarm.c - a device answering the master's management messages (3.4.9: processor command register,
 * read 7, and processor alarm register, write 7).
 *
 * The master writes a processor command; it arrives with an ID cycle and raises the processor command
 * interrupt (Table 3-13, IRQ_EN D6). The service routine reads the command and writes its answer to the
 * processor alarm register, where the master reads it. A small protocol for the example:
 *   01h "firmware version?" -> the version byte FW_VERSION
 *   02h "data cycles?"      -> the number of data cycles served, modulo 256
 *   other                   -> FFh "unknown command"
 * The device also exchanges one word of process data on the valid data cycle interrupt (block transfer).
 */
#include "fw_board.h"

#define DEV_SET 0x83u     /* /PCP = 1, ExtReg = 0, CL = 011: one word (Table 3-12) */
#define DEV_ID_CODE 0x03u /* remote bus digital input/output module (Table A-3) */
#define DEV_BYTES 2u
#define CMD_VERSION 0x01u
#define CMD_CYCLES 0x02u
#define FW_VERSION 0x12u
#define ANSWER_UNKNOWN 0xFFu

void fw_setup(supi3_t *chip, fw_board_t *board)
{
    if (fw_note(board, supi3_initialize(chip, FW_MODE)) != SUPI3_OK ||
        fw_note(board, supi3_configure(chip, DEV_SET, DEV_ID_CODE)) != SUPI3_OK) {
        return;
    }
    (void)fw_note(board, supi3_irq_enable(chip, SUPI3_IRQ_EN_PCMD_MSK | SUPI3_IRQ_EN_VALID_MSK));
}

static uint8_t answer(const fw_board_t *board, uint8_t command)
{
    switch (command) {
    case CMD_VERSION:
        return FW_VERSION;
    case CMD_CYCLES:
        return (uint8_t)board->cycles;
    default:
        return ANSWER_UNKNOWN;
    }
}

void fw_isr(supi3_t *chip, fw_board_t *board)
{
    uint8_t events = 0u;
    if (fw_note(board, supi3_irq_service(chip, &events)) != SUPI3_OK) {
        return;
    }
    if ((events & SUPI3_IRQ_EVT_PCMD_MSK) != 0u) {
        if (fw_note(board, supi3_processor_command(chip, &board->command)) != SUPI3_OK ||
            fw_note(board, supi3_processor_alarm(chip, answer(board, board->command))) != SUPI3_OK) {
            return;
        }
    }
    if ((events & SUPI3_IRQ_EVT_VALID_MSK) != 0u) {
        if (fw_note(board, supi3_block_transfer(chip, 1, 1, board->outputs, board->inputs, DEV_BYTES)) == SUPI3_OK) {
            board->cycles++;
        }
    }
}

/*
 * analog_io.c - a 32-bit analog input/output remote bus device (ID code 33h "AIO", Table A-3).
 *
 * Two words of process data each way (SET 85h: /PCP = 1, ExtReg = 0, CL = 101, two words, Table 3-12), moved
 * with one block transfer (3.4.6: command CFh, RD and WR at address 15, then four data bytes: OUT0..OUT3 out and
 * IN0..IN3 in, full duplex in the Motorola mode; four reads, then four writes in the Intel mode). Here the two words are two 16-bit channels: the DAC value the master sets arrives in
 * OUT0..OUT3, the ADC value goes back in IN0..IN3 (byte 0 the most significant, 3.4.8). The "valid data cycle"
 * interrupt synchronizes the access (3.4.14; the manual advises interrupts for more than one word).
 */
#include "fw_board.h"

#define AIO_SET 0x85u     /* /PCP = 1, ExtReg = 0, CL = 101: two words (3.4.11, Table 3-12) */
#define AIO_ID_CODE 0x33u /* remote bus analog input/output module (Table A-3) */
#define AIO_BYTES 4u      /* the block transfer moves exactly the configured length (3.4.6) */

void fw_setup(supi3_t *chip, fw_board_t *board)
{
    if (fw_note(board, supi3_initialize(chip, FW_MODE)) != SUPI3_OK ||
        fw_note(board, supi3_configure(chip, AIO_SET, AIO_ID_CODE)) != SUPI3_OK) {
        return;
    }
    (void)fw_note(board, supi3_irq_enable(chip, SUPI3_IRQ_EN_VALID_MSK));
}

void fw_isr(supi3_t *chip, fw_board_t *board)
{
    uint8_t events = 0u;
    uint8_t out[AIO_BYTES];
    uint8_t in[AIO_BYTES];
    if (fw_note(board, supi3_irq_service(chip, &events)) != SUPI3_OK || (events & SUPI3_IRQ_EVT_VALID_MSK) == 0u) {
        return;
    }
    /* The ADC value (two channels) as the master will read it: 32 bits, most significant byte first. */
    supi3_put_u32(in, supi3_get_u32(board->inputs));
    if (fw_note(board, supi3_block_transfer(chip, 1, 1, out, in, AIO_BYTES)) != SUPI3_OK) {
        return;
    }
    supi3_put_u32(board->outputs, supi3_get_u32(out)); /* to the DAC */
    board->cycles++;
}

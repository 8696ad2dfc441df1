/**
 * fw_board.h - the board contract of the example firmware (docs/sdk-firmware-c.md, "C firmware on the bench").
 *
 * A firmware is up to three entry points; the board's start-up code and interrupt vector call them:
 *
 *   void fw_setup(supi3_t *chip, fw_board_t *board);  required: once at power-up
 *   void fw_isr(supi3_t *chip, fw_board_t *board);    optional: on each falling edge of /IRQ (MFP3, 3.4.14)
 *   void fw_loop(supi3_t *chip, fw_board_t *board);   optional: one pass of the main loop, called again and again
 *
 * Before fw_setup the board has called supi3_init() with its transport (xfer, delay_us, read_irq, read_cd,
 * read_io, set_sas_init); fw_setup sends the initialization byte itself (supi3_initialize, 3.4.3). fw_isr is
 * never nested and is taken between two passes of fw_loop, never inside one. The firmware keeps the chip's
 * context and the board only through these pointers: no globals are needed (static state is allowed).
 *
 * fw_board_t is the device's other side: the peripheral's terminals (inputs, outputs, fault), the two other
 * chip pins a device firmware uses (/StatErr and /ModAck, 3.6.2) and a busy wait. On the bench the host
 * (supi3.sdk.native.CFirmware) fills it in and tests read and write the data fields between runs.
 */
#ifndef FW_BOARD_H
#define FW_BOARD_H

#include <stdint.h>

#include "supi3.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The interface mode the examples initialize (3.4.3, Table 3-8); build with -DFW_MODE=SUPI3_MODE_INTEL for the
 *  8051 serial mode 0 (then a board's xfer drives S/R, Table 3-9). */
#ifndef FW_MODE
#define FW_MODE SUPI3_MODE_MOTOROLA
#endif

/** Process data bytes the board holds per direction: the chip's data registers, IN0..IN3 / OUT0..OUT3 (3.4.8). */
#define FW_DATA_BYTES 4u

typedef struct fw_board {
    /* The peripheral; byte 0 is the most significant (3.4.8). The host writes inputs and fault. */
    uint8_t inputs[FW_DATA_BYTES];  /**< input terminals: the firmware sends them to the master as IN data */
    uint8_t outputs[FW_DATA_BYTES]; /**< output terminals: the firmware drives them with the master's OUT data */
    uint8_t fault;                  /**< 1 = the peripheral has an error (missing I/O supply, short circuit, ...) */
    /* Firmware state the host may read. */
    uint8_t command;                /**< the last processor command the master sent (3.4.9) */
    uint32_t cycles;                /**< data cycles whose process data the firmware exchanged */
    int error;                      /**< the first driver error the firmware met (supi3_err_t); 0 = none */
    /* Board services, set by the host; user is passed to each. Each int function returns 0 on success. */
    void *user;
    void (*delay_us)(void *user, uint32_t us);      /**< busy wait (the bus runs on) */
    int (*set_stat_err)(void *user, int active);    /**< drive /StatErr: 1 = pin low, a peripheral fault (3.6.2) */
    int (*mod_ack_seen)(void *user, int *seen);     /**< *seen = 1 if /ModAck pulsed since the last call (3.6.2):
                                                         the pulse is 375 ns, so the board latches its edge */
} fw_board_t;

/** Keep the first driver error in board->error and pass err on: `if (fw_note(board, supi3_read(...)) != 0)`. */
static inline int fw_note(fw_board_t *board, int err)
{
    if (err != SUPI3_OK && board->error == SUPI3_OK) {
        board->error = err;
    }
    return err;
}

#ifdef __cplusplus
}
#endif

#endif /* FW_BOARD_H */

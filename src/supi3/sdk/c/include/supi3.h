/**
 * supi3.h - portable C99 driver for the serial uP interface of the IBS SUPI 3 OPC (INTERBUS slave).
 *
 * Manual: IBS SUPI 3 OPC UM E rev. 05, 3.4 to 3.4.14. Decisions: docs/assumptions/upif.md (UP-n),
 * guide: docs/sdk.md. The API mirrors supi3.spi.upif.UpInterface (initialize, read, write, exchange,
 * block_transfer). No dynamic memory, no global state: everything lives in a caller-owned supi3_t.
 *
 * Transport contract (decision, docs/sdk.md "Porting the transport"):
 *  - xfer() moves ONE byte as ONE frame: /SS low, 8 SCLK periods, /SS high. The chip needs a /SS edge per
 *    byte (3.4.2, UP-7), so the callback drives /SS itself; there are no separate select/deselect callbacks.
 *  - Motorola (SPI): mode 3 (SCLK idles high, sample on the rising edge, UP-5), MSB first. s_r is ignored.
 *  - Intel (8051 serial mode 0): LSB first on the wire (UP-6); the callback sets the S/R pin to s_r before
 *    /SS falls: 1 = the uP sends (chip writes), 0 = the chip drives Ser_IN/OUT (Table 3-9, UP-9).
 *  - Byte values in this API are always the manual's values (bit 7 = RD etc.); bit order is the transport's job.
 *  - Every callback returns 0 on success, anything else is reported as SUPI3_E_TRANSPORT, except that a pin
 *    callback (read_irq, read_cd, read_io, set_sas_init) may return SUPI3_E_UNSUPPORTED to say "this board does not
 *    wire the pin" (one image for board variants): the driver then works as with a NULL callback, its state kept
 *    (FW-21, docs/sdk.md). set_sas_init may say so only when asked to drive the pin active (level 1).
 */
#ifndef SUPI3_H
#define SUPI3_H

#include <stddef.h>
#include <stdint.h>

#include "supi3_regs.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Error codes: 0 = success, negative = failure. Names follow supi3.spi.upif's exceptions. */
typedef enum {
    SUPI3_OK = 0,
    SUPI3_E_ARG = -1,         /**< bad argument (NULL pointer, address not 0..14, block length, mode, reserved bit, max_polls 0): nothing sent (UpifArgumentError) */
    SUPI3_E_NOT_INIT = -2,    /**< supi3_init() or supi3_initialize() not done: nothing sent (NotInitializedError, UP-25) */
    SUPI3_E_TRANSPORT = -3,   /**< a transport callback failed; state of the chip unknown: SAS_INIT and initialize again */
    SUPI3_E_NOT_READY = -4,   /**< C/D showed "data" before the init byte: command interrupted or interface disabled (UP-4, UP-27); nothing sent */
    SUPI3_E_NOT_RESET = -5,   /**< the chip was not reset: it took the init byte as a command (UP-3); pulse SAS_INIT, initialize again */
    SUPI3_E_UNSUPPORTED = -6, /**< not possible in this mode or without an optional callback (exchange in Intel mode, 3.4.4) */
    SUPI3_E_TIMEOUT = -7      /**< a bounded wait ended: the I/O access window did not open within max_polls (supi3_poll_io_window), /IRQ stayed low (supi3_irq_service), 3.4.14 */
} supi3_err_t;

/** Interface mode selected by the initialization byte (3.4.3, Table 3-8). */
typedef enum {
    SUPI3_MODE_MOTOROLA = 0, /**< init byte 00h, SPI */
    SUPI3_MODE_INTEL = 1     /**< init byte 81h, 8051 serial mode 0 with S/R */
} supi3_mode_t;

/** Block transfer lengths: one word to two words, IN0..IN3 / OUT0..OUT3 (3.4.6: "lengths >= 1 word", 3.4.8). */
#define SUPI3_BLOCK_MIN_BYTES 2u
#define SUPI3_BLOCK_MAX_BYTES 4u
/** Highest address a single access may name; 15 is the block transfer (3.4.6, 3.4.7). */
#define SUPI3_ADDR_MAX 14u
/** Most reads of IRQ_EVT in one supi3_irq_service() while /IRQ stays low (3.4.14; FW-22): events come at most once
 * per INTERBUS cycle, a read takes far less, so two reads are the most a working board needs. */
#define SUPI3_IRQ_SERVICE_MAX_READS 4u

typedef int (*supi3_xfer_fn)(void *user, uint8_t tx, uint8_t *rx, int s_r);
typedef void (*supi3_delay_us_fn)(void *user, uint32_t us);
typedef int (*supi3_read_pin_fn)(void *user, int *level);
typedef int (*supi3_write_pin_fn)(void *user, int level);

/** Board configuration: copied by supi3_init(). Only xfer is required. */
typedef struct {
    supi3_xfer_fn xfer;          /**< one byte, one /SS frame (required) */
    supi3_delay_us_fn delay_us;  /**< busy wait; used for frame_gap_us and the SAS_INIT pulse (optional) */
    supi3_read_pin_fn read_irq;  /**< /IRQ level, 0 = event pending (optional, supi3_irq_service) */
    supi3_read_pin_fn read_cd;   /**< C/D level, 0 = command expected (optional, init check UP-3) */
    supi3_write_pin_fn set_sas_init; /**< drive SAS_INIT, 1 = active (optional, supi3_sas_init) */
    void *user;                  /**< passed to every callback */
    uint32_t frame_gap_us;       /**< wait after each frame (t8, Table 3-7); 0 = none */
    supi3_read_pin_fn read_io;   /**< I/O access pin MFP1 level, 1 = no access now (optional, supi3_poll_io_window) */
} supi3_config_t;

/** Driver context. Treat the fields as private; allocate it anywhere (static, stack). */
typedef struct {
    uint32_t magic;
    supi3_config_t cfg;
    uint8_t initialized;
    uint8_t mode;
    uint8_t set_known; /* SET was written or read through this context since supi3_init() */
    uint8_t set_value;
} supi3_t;

/** Copy cfg into ctx and reset the driver state (the chip is not touched). */
int supi3_init(supi3_t *ctx, const supi3_config_t *cfg);

/** Send the initialization byte (3.4.3). With read_cd, check the first-initialization signature (UP-3). */
int supi3_initialize(supi3_t *ctx, supi3_mode_t mode);

/** Pulse SAS_INIT (>= 1 us, t_SAS_INIT >= 250 ns) with set_sas_init; the driver forgets the mode (3.4.3).
 * SUPI3_E_UNSUPPORTED, the driver's state kept: set_sas_init NULL or returning SUPI3_E_UNSUPPORTED (FW-21). */
int supi3_sas_init(supi3_t *ctx);

/** Read one register (3.4.4): command RD|A, then one data byte. addr 0..14. */
int supi3_read(supi3_t *ctx, uint8_t addr, uint8_t *value);

/** Write one register (3.4.4): command WR|A, then the data byte. addr 0..14. */
int supi3_write(supi3_t *ctx, uint8_t addr, uint8_t value);

/** Read and write one address in the same data byte (Motorola only, 3.4.4). */
int supi3_exchange(supi3_t *ctx, uint8_t addr, uint8_t wr_value, uint8_t *rd_value);

/**
 * Block transfer at address 15 (3.4.6, UP-10, UP-11); n = the configured data length in bytes, 2..4. Once SET
 * went through this context (supi3_write, supi3_configure, supi3_read), n must be its length and ExtReg 0.
 * out receives OUT0..OUT(n-1) (read), in supplies IN0..IN(n-1) (write).
 * Motorola: n full-duplex bytes whatever rd/wr say: in is required (the chip writes it), out may be NULL.
 * Intel: n reads if rd (out required), then n writes if wr (in required); rd or wr must be set.
 */
int supi3_block_transfer(supi3_t *ctx, int rd, int wr, uint8_t *out, const uint8_t *in, size_t n);

/** Write SET, then ID (3.4.5: 4Dh set, 4Ch id), before the bus runs. */
int supi3_configure(supi3_t *ctx, uint8_t set_value, uint8_t id_value);

/**
 * Read-clear the interrupt event register (3.4.14, read 14): *events = the events D6..D0 and D7, the I/O access
 * status (RM-7, RM-8). With read_irq, /IRQ is read first and after each read, and IRQ_EVT read again while it is low
 * (an event that came during the read gives no new falling edge, FW-22): D6..D0 of every read OR-ed, D7 of the last;
 * /IRQ high at once: *events = 0 and nothing is sent. Still low after SUPI3_IRQ_SERVICE_MAX_READS reads:
 * SUPI3_E_TIMEOUT, *events holding what was read. Without read_irq: one read. *events holds the events read
 * (and so cleared) whatever the result.
 */
int supi3_irq_service(supi3_t *ctx, uint8_t *events);

/** Write the interrupt enable register (write 14, 3.4.14, Fig. 3-19). Bit 7 is reserved (RM-7): SUPI3_E_ARG. */
int supi3_irq_enable(supi3_t *ctx, uint8_t mask);

/**
 * Wait for the I/O access window (3.4.14 "Using the polling bit", Fig. 3-22), at most max_polls polls (>= 1).
 * With read_io: poll the I/O pin (MFP1) until it reads 0; nothing is sent and *events (may be NULL) = 0.
 * Without: read register 14 until D7 (I/O access) is 0; *events (required) = D6..D0 of every read OR-ed,
 * since each read clears them (RM-8: D7 is live and not cleared). *events holds them whatever the result.
 * SUPI3_OK: the data registers may be accessed for the next 30 bit periods (60 us at 500 kbit/s);
 * SUPI3_E_TIMEOUT: D7 or the pin stayed 1 for max_polls polls.
 */
int supi3_poll_io_window(supi3_t *ctx, uint32_t max_polls, uint8_t *events);

/** Write the processor alarm register (write 7): a management message to the master (3.4.9). */
int supi3_processor_alarm(supi3_t *ctx, uint8_t value);

/** Read the processor command register (read 7): the master's management message (3.4.9). */
int supi3_processor_command(supi3_t *ctx, uint8_t *value);

/**
 * Optical registers 8 to 11 decoded (3.4.12, 3.4.13; layouts RM-5, RM-6): raw field values, no metre conversion.
 * medium: 0 polymer, 1 glass fibre; enable: 1 = optical initialization detected a regulated device; levels 1..15.
 */
typedef struct {
    uint8_t out_length;    /**< read 8 LENGTH: 0..62, 63 = 400 m to 20 km (Table 1-5) */
    uint8_t out_medium;    /**< read 8 MEDIUM */
    uint8_t out_enable;    /**< read 8 ENABLE */
    uint8_t branch_length; /**< read 9 LENGTH */
    uint8_t branch_medium; /**< read 9 MEDIUM */
    uint8_t branch_enable; /**< read 9 ENABLE */
    uint8_t in_level;      /**< read 10 LEVEL: power level of the incoming interface */
    uint8_t in_enable;     /**< read 10 ENABLE */
    uint8_t out_level;     /**< read 11 OUT_LEVEL: power level of the outgoing interface */
    uint8_t branch_level;  /**< read 11 BRANCH_LEVEL: power level of the bus branch */
} supi3_optical_t;

/** Read 8, 9, 10 and 11 and decode them into *status (written only when all four reads succeeded). */
int supi3_optical_status(supi3_t *ctx, supi3_optical_t *status);

/* One-way optical path lengths of reads 8 and 9 in centimetres (OPT-1 of docs/assumptions/optical.md): the LENGTH
 * code counts units of 6.25 m (MEDIUM 0, polymer) or 200 m (MEDIUM 1, glass); 63 is beyond the range, up to 20 km. */
#define SUPI3_OPTICAL_POLYMER_UNIT_CM 625u
#define SUPI3_OPTICAL_GLASS_UNIT_CM 20000u
#define SUPI3_OPTICAL_LENGTH_MAX_CODE 63u
#define SUPI3_OPTICAL_MAX_PATH_CM 2000000u

/**
 * The one-way path a LENGTH code stands for, [*low_cm, *high_cm) in centimetres (OPT-1); code 63 reaches up to
 * 20 km. medium: 0 polymer, 1 glass. SUPI3_E_ARG: code > 63, medium > 1 or a NULL pointer (nothing written).
 */
int supi3_optical_length_cm(uint8_t code, uint8_t medium, uint32_t *low_cm, uint32_t *high_cm);

/**
 * The LENGTH code a one-way path of one_way_cm centimetres reads (truncated to the medium's unit, 63 above the
 * range; OPT-1). SUPI3_E_ARG: one_way_cm > 2,000,000 (20 km), medium > 1 or code NULL (nothing written).
 */
int supi3_optical_length_code(uint32_t one_way_cm, uint8_t medium, uint8_t *code);

/** Text for an error code ("unknown error" for others). */
const char *supi3_strerror(int err);

/* Multi-byte values in the manual's significance: byte 0 (address 0) is the MSB (3.4.8). */
void supi3_put_u16(uint8_t *bytes, uint16_t value);
uint16_t supi3_get_u16(const uint8_t *bytes);
void supi3_put_u32(uint8_t *bytes, uint32_t value);
uint32_t supi3_get_u32(const uint8_t *bytes);

#ifdef __cplusplus
}
#endif

#endif /* SUPI3_H */

/*
 * supi3.c - portable C99 driver for the IBS SUPI 3 OPC serial uP interface (manual 3.4 to 3.4.14).
 * See supi3.h for the transport contract and docs/sdk.md for the guide. No dynamic memory, no globals.
 */
#include "supi3.h"

#define SUPI3_MAGIC 0x53503343u /* "SP3C": set by supi3_init() */

/* S/R levels for the Intel mode (Table 3-9, UP-9); ignored in Motorola mode. */
#define SR_CHIP_DRIVES 0
#define SR_UP_SENDS 1

/* The interrupt sources of IRQ_EN (3.4.14, Table 3-13); bit 7 is reserved (RM-7). */
#define IRQ_EN_SOURCES                                                                                    \
    (SUPI3_IRQ_EN_PCMD_MSK | SUPI3_IRQ_EN_INVALID_MSK | SUPI3_IRQ_EN_VALID_MSK | SUPI3_IRQ_EN_ID_CYCLE_MSK | \
     SUPI3_IRQ_EN_IB_RESET_MSK | SUPI3_IRQ_EN_PCP_RX_MSK | SUPI3_IRQ_EN_PCP_TX_MSK)

static int ctx_ok(const supi3_t *ctx)
{
    return ctx != NULL && ctx->magic == SUPI3_MAGIC;
}

/* One frame; waits frame_gap_us afterwards (t8, Table 3-7). */
static int frame(supi3_t *ctx, uint8_t tx, uint8_t *rx, int s_r)
{
    uint8_t dummy = 0u;
    if (ctx->cfg.xfer(ctx->cfg.user, tx, rx != NULL ? rx : &dummy, s_r) != 0) {
        ctx->initialized = 0u; /* chip state unknown (a half-done command): SAS_INIT needed */
        return SUPI3_E_TRANSPORT;
    }
    if (ctx->cfg.delay_us != NULL && ctx->cfg.frame_gap_us != 0u) {
        ctx->cfg.delay_us(ctx->cfg.user, ctx->cfg.frame_gap_us);
    }
    return SUPI3_OK;
}

/* A pin level through an optional callback (C/D, /IRQ, I/O); reading a pin leaves the chip's state as it was.
 * SUPI3_E_UNSUPPORTED: the pin is not wired, by a NULL callback or by a callback that returns SUPI3_E_UNSUPPORTED
 * (a board revision without the pin, FW-21); the caller then works as without the pin. Any other non-zero return
 * is SUPI3_E_TRANSPORT. */
static int read_pin(const supi3_t *ctx, supi3_read_pin_fn read, int *level)
{
    int rc;
    if (read == NULL) {
        return SUPI3_E_UNSUPPORTED;
    }
    rc = read(ctx->cfg.user, level);
    if (rc == SUPI3_OK || rc == SUPI3_E_UNSUPPORTED) {
        return rc;
    }
    return SUPI3_E_TRANSPORT;
}

/* Common entry check of the register accesses (UP-25: refused before the first byte): the context, then the
 * value arguments (args_ok), then the state; pointer arguments are checked after this. */
static int entry_ok(const supi3_t *ctx, int args_ok)
{
    if (!ctx_ok(ctx)) {
        return ctx == NULL ? SUPI3_E_ARG : SUPI3_E_NOT_INIT;
    }
    if (!args_ok) {
        return SUPI3_E_ARG;
    }
    if (!ctx->initialized) {
        return SUPI3_E_NOT_INIT;
    }
    return SUPI3_OK;
}

static int access_ok(const supi3_t *ctx, uint8_t addr)
{
    return entry_ok(ctx, addr <= SUPI3_ADDR_MAX); /* 15 is the block transfer (3.4.6): supi3_block_transfer() */
}

/* Bytes of a SET value with ExtReg = 0 (Table 3-12; block transfers at >= 1 word, 3.4.6); 0 = no block. */
static size_t block_bytes(uint8_t set)
{
    if ((set & SUPI3_SET_EXTREG_MSK) != 0u) {
        return 0u; /* ExtReg = 1: the registers are not in the data path (3.4.8, UP-10) */
    }
    switch (set & SUPI3_SET_CL_MSK) {
    case SUPI3_SET_CL_LEN_1_WORD:
        return 2u;
    case SUPI3_SET_CL_LEN_3_BYTES:
        return 3u;
    case SUPI3_SET_CL_LEN_2_WORDS:
        return 4u;
    default:
        return 0u; /* below one word, or reserved */
    }
}

static void note_set(supi3_t *ctx, uint8_t addr, uint8_t value, int err)
{
    if (addr == (uint8_t)SUPI3_SET_ADDR) {
        ctx->set_known = (uint8_t)(err == SUPI3_OK);
        ctx->set_value = value;
    }
}

int supi3_init(supi3_t *ctx, const supi3_config_t *cfg)
{
    if (ctx == NULL || cfg == NULL || cfg->xfer == NULL) {
        return SUPI3_E_ARG;
    }
    ctx->cfg = *cfg;
    ctx->initialized = 0u;
    ctx->mode = (uint8_t)SUPI3_MODE_MOTOROLA;
    ctx->set_known = 0u;
    ctx->set_value = 0u;
    ctx->magic = SUPI3_MAGIC;
    return SUPI3_OK;
}

int supi3_initialize(supi3_t *ctx, supi3_mode_t mode)
{
    uint8_t init_byte;
    int cd = 0;
    int checked;
    int err;
    if (ctx == NULL || (mode != SUPI3_MODE_MOTOROLA && mode != SUPI3_MODE_INTEL)) {
        return SUPI3_E_ARG;
    }
    if (!ctx_ok(ctx)) {
        return SUPI3_E_NOT_INIT;
    }
    init_byte = mode == SUPI3_MODE_INTEL ? (uint8_t)SUPI3_INIT_INTEL : (uint8_t)SUPI3_INIT_MOTOROLA;
    ctx->initialized = 0u;
    /* C/D = 1 before the init byte: a command waits for its data byte (uP reset mid-command, UP-27) or the
     * interface is disabled (UP-4). The init byte would be taken as data: send nothing, ask for SAS_INIT. */
    err = read_pin(ctx, ctx->cfg.read_cd, &cd);
    if (err == SUPI3_E_TRANSPORT) {
        return err;
    }
    checked = err == SUPI3_OK; /* C/D wired */
    if (checked && cd != 0) {
        return SUPI3_E_NOT_READY;
    }
    err = frame(ctx, init_byte, NULL, SR_UP_SENDS);
    if (err != SUPI3_OK) {
        return err;
    }
    if (checked) {
        err = read_pin(ctx, ctx->cfg.read_cd, &cd);
        if (err == SUPI3_E_TRANSPORT) {
            return err;
        }
        if (err == SUPI3_OK && cd != 0) {
            /* "Command status twice" missing (3.4.3, UP-3): the chip was initialized already and took the byte
             * as a command (00h: no direction, address 0; 81h: read OUT1). Complete it with a no-op data
             * byte so the chip is back in its command phase, then report: the mode cannot be changed now. */
            err = frame(ctx, 0x00u, NULL, mode == SUPI3_MODE_INTEL ? SR_CHIP_DRIVES : SR_UP_SENDS);
            return err != SUPI3_OK ? err : SUPI3_E_NOT_RESET;
        }
    }
    ctx->mode = (uint8_t)mode;
    ctx->initialized = 1u;
    return SUPI3_OK;
}

int supi3_sas_init(supi3_t *ctx)
{
    int rc;
    if (ctx == NULL) {
        return SUPI3_E_ARG;
    }
    if (!ctx_ok(ctx)) {
        return SUPI3_E_NOT_INIT;
    }
    if (ctx->cfg.set_sas_init == NULL) {
        return SUPI3_E_UNSUPPORTED; /* not wired: nothing driven, the driver's state kept (FW-16) */
    }
    rc = ctx->cfg.set_sas_init(ctx->cfg.user, 1);
    if (rc == SUPI3_E_UNSUPPORTED) {
        return SUPI3_E_UNSUPPORTED; /* the callback says the board does not wire the pin: as NULL (FW-21) */
    }
    ctx->initialized = 0u; /* the interface waits for the init byte again; registers are kept (3.4.3) */
    if (rc != SUPI3_OK) {
        return SUPI3_E_TRANSPORT;
    }
    if (ctx->cfg.delay_us != NULL) {
        ctx->cfg.delay_us(ctx->cfg.user, 1u); /* t_SAS_INIT >= 250 ns */
    }
    if (ctx->cfg.set_sas_init(ctx->cfg.user, 0) != SUPI3_OK) {
        return SUPI3_E_TRANSPORT; /* the pin was driven: any failure to release it, "not wired" too */
    }
    return SUPI3_OK;
}

int supi3_read(supi3_t *ctx, uint8_t addr, uint8_t *value)
{
    int err = access_ok(ctx, addr);
    if (err == SUPI3_OK && value == NULL) {
        err = SUPI3_E_ARG;
    }
    if (err != SUPI3_OK) {
        return err;
    }
    err = frame(ctx, (uint8_t)SUPI3_CMD_READ(addr), NULL, SR_UP_SENDS);
    if (err == SUPI3_OK) {
        err = frame(ctx, 0x00u, value, SR_CHIP_DRIVES);
    }
    note_set(ctx, addr, err == SUPI3_OK ? *value : 0u, err);
    return err;
}

int supi3_write(supi3_t *ctx, uint8_t addr, uint8_t value)
{
    int err = access_ok(ctx, addr);
    if (err != SUPI3_OK) {
        return err;
    }
    err = frame(ctx, (uint8_t)SUPI3_CMD_WRITE(addr), NULL, SR_UP_SENDS);
    if (err == SUPI3_OK) {
        err = frame(ctx, value, NULL, SR_UP_SENDS);
    }
    note_set(ctx, addr, value, err);
    return err;
}

int supi3_exchange(supi3_t *ctx, uint8_t addr, uint8_t wr_value, uint8_t *rd_value)
{
    int err = access_ok(ctx, addr);
    if (err == SUPI3_OK && rd_value == NULL) {
        err = SUPI3_E_ARG;
    }
    if (err != SUPI3_OK) {
        return err;
    }
    if (ctx->mode != (uint8_t)SUPI3_MODE_MOTOROLA) {
        return SUPI3_E_UNSUPPORTED; /* 3.4.4: simultaneous read and write is impossible in Intel mode */
    }
    err = frame(ctx, (uint8_t)SUPI3_CMD_READ_WRITE(addr), NULL, SR_UP_SENDS);
    if (err == SUPI3_OK) {
        err = frame(ctx, wr_value, rd_value, SR_UP_SENDS);
    }
    note_set(ctx, addr, wr_value, err);
    return err;
}

int supi3_block_transfer(supi3_t *ctx, int rd, int wr, uint8_t *out, const uint8_t *in, size_t n)
{
    uint8_t cmd = (uint8_t)SUPI3_CMD_A(SUPI3_BLOCK_TRANSFER_ADDR);
    size_t k;
    int err = access_ok(ctx, 0u);
    if (err != SUPI3_OK) {
        return err;
    }
    if (n < SUPI3_BLOCK_MIN_BYTES || n > SUPI3_BLOCK_MAX_BYTES) {
        return SUPI3_E_ARG;
    }
    if (ctx->set_known && n != block_bytes(ctx->set_value)) {
        return SUPI3_E_ARG; /* UP-10: the chip moves exactly the configured length */
    }
    if (ctx->mode == (uint8_t)SUPI3_MODE_MOTOROLA) {
        /* UP-11: RD/WR have no meaning, every byte is full duplex and writes IN k. */
        if (in == NULL || (rd && out == NULL)) {
            return SUPI3_E_ARG;
        }
    } else if ((!rd && !wr) || (rd && out == NULL) || (wr && in == NULL)) {
        return SUPI3_E_ARG;
    }
    if (rd) {
        cmd = (uint8_t)(cmd | SUPI3_CMD_RD_MSK);
    }
    if (wr) {
        cmd = (uint8_t)(cmd | SUPI3_CMD_WR_MSK);
    }
    err = frame(ctx, cmd, NULL, SR_UP_SENDS);
    if (ctx->mode == (uint8_t)SUPI3_MODE_MOTOROLA) {
        for (k = 0u; err == SUPI3_OK && k < n; ++k) {
            err = frame(ctx, in[k], out != NULL ? &out[k] : NULL, SR_UP_SENDS);
        }
        return err;
    }
    /* Intel (UP-11, Fig. 3-12): first n reads with S/R = 0, then n writes with S/R = 1. */
    for (k = 0u; err == SUPI3_OK && rd && k < n; ++k) {
        err = frame(ctx, 0x00u, &out[k], SR_CHIP_DRIVES);
    }
    for (k = 0u; err == SUPI3_OK && wr && k < n; ++k) {
        err = frame(ctx, in[k], NULL, SR_UP_SENDS);
    }
    return err;
}

int supi3_configure(supi3_t *ctx, uint8_t set_value, uint8_t id_value)
{
    int err = supi3_write(ctx, (uint8_t)SUPI3_SET_ADDR, set_value);
    if (err != SUPI3_OK) {
        return err;
    }
    return supi3_write(ctx, (uint8_t)SUPI3_ID_ADDR, id_value);
}

int supi3_irq_service(supi3_t *ctx, uint8_t *events)
{
    uint8_t value = 0u;
    uint8_t seen = 0u;
    uint32_t reads;
    int irq_n = 0;
    int wired;
    int err = access_ok(ctx, (uint8_t)SUPI3_IRQ_EVT_ADDR);
    if (err == SUPI3_OK && events == NULL) {
        err = SUPI3_E_ARG;
    }
    if (err != SUPI3_OK) {
        return err;
    }
    /* /IRQ is low while IRQ_EVT holds an event (3.4.14); an MCU's external interrupt takes its falling edge. An
     * event that comes while IRQ_EVT is read gives no new edge (or one too short to see): read until /IRQ is high,
     * at most SUPI3_IRQ_SERVICE_MAX_READS times, so no event is left pending on return (FW-22). */
    for (reads = 0u;; ++reads) {
        err = read_pin(ctx, ctx->cfg.read_irq, &irq_n);
        if (err == SUPI3_E_TRANSPORT) {
            break;
        }
        wired = err == SUPI3_OK;
        if (wired && irq_n != 0) {
            err = SUPI3_OK; /* /IRQ high: nothing (left) pending */
            break;
        }
        if (reads == SUPI3_IRQ_SERVICE_MAX_READS) {
            err = SUPI3_E_TIMEOUT; /* /IRQ stayed low */
            break;
        }
        err = supi3_read(ctx, (uint8_t)SUPI3_IRQ_EVT_ADDR, &value);
        if (err != SUPI3_OK) {
            break;
        }
        /* each read clears the events it returns: keep them all; D7 (live, RM-8) is the last read's */
        seen = (uint8_t)((seen & SUPI3_IRQ_EVT_CLEAR_ON_READ_MSK) | value);
        if (!wired) {
            break; /* without /IRQ: one read (no edge to lose: such a firmware polls) */
        }
    }
    *events = seen;
    return err;
}

int supi3_irq_enable(supi3_t *ctx, uint8_t mask)
{
    /* bit 7 is reserved: the I/O access bit is a status, not a source (RM-7) */
    int err = entry_ok(ctx, (mask & (uint8_t)~IRQ_EN_SOURCES) == 0u);
    if (err != SUPI3_OK) {
        return err;
    }
    return supi3_write(ctx, (uint8_t)SUPI3_IRQ_EN_ADDR, mask);
}

int supi3_poll_io_window(supi3_t *ctx, uint32_t max_polls, uint8_t *events)
{
    uint32_t k;
    uint8_t value = 0u;
    uint8_t seen = 0u;
    int level = 1;
    int err = entry_ok(ctx, max_polls != 0u);
    if (err == SUPI3_OK && events == NULL && ctx->cfg.read_io == NULL) {
        err = SUPI3_E_ARG;
    }
    if (err != SUPI3_OK) {
        return err;
    }
    for (k = 0u; err == SUPI3_OK && k < max_polls; ++k) {
        err = read_pin(ctx, ctx->cfg.read_io, &level); /* MFP1 mirrors D7 (Table 3-5): nothing sent */
        if (err == SUPI3_E_UNSUPPORTED) {
            /* Not wired (FW-21): read 14, which clears D6..D0 (3.4.14): keep every event; D7 is live (RM-8). A
             * callback that says so with events NULL has nowhere to keep them: SUPI3_E_ARG, as a NULL read_io. */
            err = events == NULL ? SUPI3_E_ARG : supi3_read(ctx, (uint8_t)SUPI3_IRQ_EVT_ADDR, &value);
            if (err == SUPI3_OK) {
                seen = (uint8_t)(seen | (value & SUPI3_IRQ_EVT_CLEAR_ON_READ_MSK));
                level = (value & SUPI3_IRQ_EVT_IO_ACCESS_MSK) != 0u;
            }
        }
        if (err == SUPI3_OK && level == 0) {
            break; /* the window is open: 30 bit periods from now (Fig. 3-22) */
        }
    }
    if (events != NULL) {
        *events = seen;
    }
    if (err == SUPI3_OK && level != 0) {
        err = SUPI3_E_TIMEOUT;
    }
    return err;
}

int supi3_processor_alarm(supi3_t *ctx, uint8_t value)
{
    return supi3_write(ctx, (uint8_t)SUPI3_ALARM_ADDR, value);
}

int supi3_processor_command(supi3_t *ctx, uint8_t *value)
{
    return supi3_read(ctx, (uint8_t)SUPI3_PCMD_ADDR, value);
}

/* A field of a register byte, shifted down. */
#define FIELD(byte, reg, fld) ((uint8_t)(((byte) & SUPI3_##reg##_##fld##_MSK) >> SUPI3_##reg##_##fld##_POS))

int supi3_optical_status(supi3_t *ctx, supi3_optical_t *status)
{
    static const uint8_t addrs[4] = {
        (uint8_t)SUPI3_LENGTH_OUT_ADDR, (uint8_t)SUPI3_LENGTH_BRANCH_ADDR,
        (uint8_t)SUPI3_POWER_IN_ADDR, (uint8_t)SUPI3_POWER_OUT_BRANCH_ADDR,
    };
    uint8_t raw[4] = {0u, 0u, 0u, 0u};
    size_t k;
    int err = access_ok(ctx, addrs[0]);
    if (err == SUPI3_OK && status == NULL) {
        err = SUPI3_E_ARG;
    }
    for (k = 0u; err == SUPI3_OK && k < 4u; ++k) {
        err = supi3_read(ctx, addrs[k], &raw[k]);
    }
    if (err != SUPI3_OK) {
        return err;
    }
    status->out_length = FIELD(raw[0], LENGTH_OUT, LENGTH);
    status->out_medium = FIELD(raw[0], LENGTH_OUT, MEDIUM);
    status->out_enable = FIELD(raw[0], LENGTH_OUT, ENABLE);
    status->branch_length = FIELD(raw[1], LENGTH_BRANCH, LENGTH);
    status->branch_medium = FIELD(raw[1], LENGTH_BRANCH, MEDIUM);
    status->branch_enable = FIELD(raw[1], LENGTH_BRANCH, ENABLE);
    status->in_level = FIELD(raw[2], POWER_IN, LEVEL);
    status->in_enable = FIELD(raw[2], POWER_IN, ENABLE);
    status->out_level = FIELD(raw[3], POWER_OUT_BRANCH, OUT_LEVEL);
    status->branch_level = FIELD(raw[3], POWER_OUT_BRANCH, BRANCH_LEVEL);
    return SUPI3_OK;
}

const char *supi3_strerror(int err)
{
    switch (err) {
    case SUPI3_OK:
        return "ok";
    case SUPI3_E_ARG:
        return "invalid argument (NULL pointer, address not 0..14, block length not 2..4 or not SET's, mode, "
               "reserved bit, max_polls 0)";
    case SUPI3_E_NOT_INIT:
        return "not initialized: call supi3_init() and supi3_initialize() first";
    case SUPI3_E_TRANSPORT:
        return "transport error: chip state unknown, pulse SAS_INIT and initialize again";
    case SUPI3_E_NOT_READY:
        return "C/D shows data before the initialization byte: pulse SAS_INIT (3.4.3)";
    case SUPI3_E_NOT_RESET:
        return "chip was not reset: initialization byte taken as a command, pulse SAS_INIT (3.4.3)";
    case SUPI3_E_UNSUPPORTED:
        return "not supported in this mode or without the optional callback (pin not wired)";
    case SUPI3_E_TIMEOUT:
        return "timeout: the I/O access window did not open within max_polls, or /IRQ stayed low (3.4.14)";
    default:
        return "unknown error";
    }
}

int supi3_optical_length_cm(uint8_t code, uint8_t medium, uint32_t *low_cm, uint32_t *high_cm)
{
    uint32_t unit = medium == 0u ? SUPI3_OPTICAL_POLYMER_UNIT_CM : SUPI3_OPTICAL_GLASS_UNIT_CM;
    if (code > SUPI3_OPTICAL_LENGTH_MAX_CODE || medium > 1u || low_cm == NULL || high_cm == NULL) {
        return SUPI3_E_ARG;
    }
    *low_cm = code * unit;
    *high_cm = code == SUPI3_OPTICAL_LENGTH_MAX_CODE ? SUPI3_OPTICAL_MAX_PATH_CM : (code + 1u) * unit;
    return SUPI3_OK;
}

int supi3_optical_length_code(uint32_t one_way_cm, uint8_t medium, uint8_t *code)
{
    uint32_t units;
    if (one_way_cm > SUPI3_OPTICAL_MAX_PATH_CM || medium > 1u || code == NULL) {
        return SUPI3_E_ARG;
    }
    units = one_way_cm / (medium == 0u ? SUPI3_OPTICAL_POLYMER_UNIT_CM : SUPI3_OPTICAL_GLASS_UNIT_CM);
    *code = (uint8_t)(units < SUPI3_OPTICAL_LENGTH_MAX_CODE ? units : SUPI3_OPTICAL_LENGTH_MAX_CODE);
    return SUPI3_OK;
}

void supi3_put_u16(uint8_t *bytes, uint16_t value)
{
    if (bytes != NULL) {
        bytes[0] = (uint8_t)(value >> 8);
        bytes[1] = (uint8_t)value;
    }
}

uint16_t supi3_get_u16(const uint8_t *bytes)
{
    if (bytes == NULL) {
        return 0u;
    }
    return (uint16_t)(((uint16_t)bytes[0] << 8) | bytes[1]);
}

void supi3_put_u32(uint8_t *bytes, uint32_t value)
{
    if (bytes != NULL) {
        bytes[0] = (uint8_t)(value >> 24);
        bytes[1] = (uint8_t)(value >> 16);
        bytes[2] = (uint8_t)(value >> 8);
        bytes[3] = (uint8_t)value;
    }
}

uint32_t supi3_get_u32(const uint8_t *bytes)
{
    if (bytes == NULL) {
        return 0u;
    }
    return ((uint32_t)bytes[0] << 24) | ((uint32_t)bytes[1] << 16) | ((uint32_t)bytes[2] << 8) | bytes[3];
}

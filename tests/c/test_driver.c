/*
 * Unit tests of sdk/c (supi3.c) against a fake chip in C, built and run by tests/test_sdk_c.py.
 * The fake implements the chip side of the byte protocol (manual 3.4.3 to 3.4.6, docs/upif.md): init byte,
 * command/data alternation with C/D (UP-2), registers 0..14 with read-clear of 14, block transfer (UP-10,
 * UP-11), Intel S/R direction (UP-9), a faulty init byte disabling the interface (UP-4), the optical read
 * registers 8..11 (3.4.12, 3.4.13) and the I/O access bit D7 of read 14 and its pin MFP1 (3.4.14, RM-8).
 * Prints "N passed, M failed"; exit status 1 on any failure.
 */
#include <stdio.h>
#include <string.h>

#include "supi3.h"

enum phase { PH_INIT, PH_COMMAND, PH_DATA, PH_BLOCK, PH_DISABLED };

typedef struct {
    enum phase phase;
    int intel;
    uint8_t cmd;
    uint8_t last_rx;
    uint8_t in[4], out[4];
    uint8_t alarm, pcmd, id, set, irq_en, irq_evt;
    size_t block_len, slot;
    /* log of what the driver sent */
    uint8_t tx[64];
    int sr[64];
    size_t ntx;
    int fail_at; /* xfer number that fails, -1 = never */
    int sas_pulses, sas_level, delays;
    int irq_pin_reads;
    uint8_t optical[4]; /* reads 8..11 */
    /* I/O access: when io_scripted, D7 of read 14 is 1 for the next io_busy_reads reads, then 0 (RM-8); the
     * events in evt_after[] arrive one after each read of 14 (new events between polls). */
    int io_scripted, io_busy_reads;
    uint8_t evt_after[4];
    size_t n_evt_after, evt_idx;
    int io_pin_busy, io_pin_reads, io_pin_fail; /* MFP1: 1 for io_pin_busy reads, then 0 */
} fake_t;

static int c_d(const fake_t *f)
{
    return f->phase == PH_COMMAND || f->phase == PH_INIT ? 0 : 1;
}

static uint8_t reg_read(fake_t *f, uint8_t a)
{
    uint8_t v;
    switch (a) {
    case 0: case 1: case 2: case 3: return f->out[a];
    case 7: return f->pcmd;
    case 8: case 9: case 10: case 11: return f->optical[a - 8u];
    case 12: return f->id;
    case 13: return f->set;
    case 14:
        if (f->io_scripted) {
            f->irq_evt = (uint8_t)((f->irq_evt & SUPI3_IRQ_EVT_CLEAR_ON_READ_MSK) |
                                   (f->io_busy_reads > 0 ? SUPI3_IRQ_EVT_IO_ACCESS_MSK : 0u));
            f->io_busy_reads -= f->io_busy_reads > 0;
        }
        v = f->irq_evt;
        f->irq_evt = (uint8_t)(f->irq_evt & (uint8_t)~SUPI3_IRQ_EVT_CLEAR_ON_READ_MSK);
        if (f->evt_idx < f->n_evt_after) {
            f->irq_evt = (uint8_t)(f->irq_evt | f->evt_after[f->evt_idx++]);
        }
        return v;
    default: return 0u;
    }
}

static void reg_write(fake_t *f, uint8_t a, uint8_t v)
{
    switch (a) {
    case 0: case 1: case 2: case 3: f->in[a] = v; break;
    case 7: f->alarm = v; break;
    case 12: f->id = v; break;
    case 13: f->set = v; break;
    case 14: f->irq_en = v; break;
    default: break;
    }
}

static size_t set_bytes(uint8_t set)
{
    static const size_t bytes[8] = {0u, 1u, 1u, 2u, 3u, 4u, 0u, 0u};
    return bytes[set & SUPI3_SET_CL_MSK];
}

/* One frame: what the chip sends is decided first (/SS falling), the received byte processed last (UP-7). */
static int fake_xfer(void *user, uint8_t tx, uint8_t *rx, int s_r)
{
    fake_t *f = (fake_t *)user;
    uint8_t a = (uint8_t)(f->cmd & SUPI3_CMD_A_MSK);
    int reads = 0, writes = 0;
    uint8_t send = f->last_rx;
    if (f->fail_at >= 0 && (size_t)f->fail_at == f->ntx) {
        return -1;
    }
    if (f->ntx < sizeof f->tx) {
        f->tx[f->ntx] = tx;
        f->sr[f->ntx] = s_r;
    }
    f->ntx++;
    if (f->phase == PH_DATA) {
        reads = (f->cmd & SUPI3_CMD_RD_MSK) && (!f->intel || s_r == 0);
        writes = (f->cmd & SUPI3_CMD_WR_MSK) && (!f->intel || s_r == 1);
        if (a == 4u || a == 5u) {
            reads = writes = 0;
        }
        if (reads) {
            send = reg_read(f, a);
        }
    } else if (f->phase == PH_BLOCK) {
        size_t k = f->intel ? f->slot % f->block_len : f->slot;
        int reading = f->intel && (f->cmd & SUPI3_CMD_RD_MSK) && f->slot < f->block_len;
        if (!f->intel || reading) {
            send = f->out[k];
        }
    }
    *rx = send;
    switch (f->phase) {
    case PH_INIT:
        if (tx == SUPI3_INIT_MOTOROLA || tx == SUPI3_INIT_INTEL) {
            f->intel = tx == SUPI3_INIT_INTEL;
            f->phase = PH_COMMAND;
        } else {
            f->phase = PH_DISABLED;
        }
        break;
    case PH_COMMAND:
        f->cmd = tx;
        if ((tx & SUPI3_CMD_A_MSK) == SUPI3_BLOCK_TRANSFER_ADDR) {
            size_t phases = f->intel ? (size_t)(((tx & SUPI3_CMD_RD_MSK) != 0) + ((tx & SUPI3_CMD_WR_MSK) != 0)) : 1u;
            f->block_len = set_bytes(f->set);
            f->slot = 0u;
            f->phase = f->block_len * phases > 0u ? PH_BLOCK : PH_COMMAND;
            f->block_len = f->block_len == 0u ? 1u : f->block_len;
        } else {
            f->phase = PH_DATA;
        }
        break;
    case PH_DATA:
        if (writes) {
            reg_write(f, a, tx);
        }
        f->phase = PH_COMMAND;
        break;
    case PH_BLOCK: {
        size_t phases = f->intel ? (size_t)(((f->cmd & SUPI3_CMD_RD_MSK) != 0) + ((f->cmd & SUPI3_CMD_WR_MSK) != 0)) : 1u;
        int writing = !f->intel || ((f->cmd & SUPI3_CMD_WR_MSK) && (f->slot >= f->block_len || !(f->cmd & SUPI3_CMD_RD_MSK)));
        if (writing) {
            f->in[f->slot % f->block_len] = tx;
        }
        if (++f->slot == f->block_len * phases) {
            f->phase = PH_COMMAND;
        }
        break;
    }
    case PH_DISABLED:
        return 0;
    }
    f->last_rx = tx;
    return 0;
}

static int fake_read_cd(void *user, int *level)
{
    *level = c_d((const fake_t *)user);
    return 0;
}

static int fake_read_irq(void *user, int *level)
{
    fake_t *f = (fake_t *)user;
    f->irq_pin_reads++;
    *level = (f->irq_evt & f->irq_en & SUPI3_IRQ_EVT_CLEAR_ON_READ_MSK) ? 0 : 1;
    return 0;
}

static int fake_read_io(void *user, int *level)
{
    fake_t *f = (fake_t *)user;
    if (f->io_pin_fail) {
        return -1;
    }
    f->io_pin_reads++;
    *level = f->io_pin_busy > 0;
    f->io_pin_busy -= f->io_pin_busy > 0;
    return 0;
}

static int fake_sas(void *user, int level)
{
    fake_t *f = (fake_t *)user;
    if (f->sas_level && !level) {
        f->sas_pulses++;
        f->phase = PH_INIT; /* SAS_INIT keeps every register (3.4.3) */
    }
    f->sas_level = level;
    return 0;
}

static void fake_delay(void *user, uint32_t us)
{
    (void)us;
    ((fake_t *)user)->delays++;
}

/* ---- tiny test harness ---- */
static int g_failed, g_checks_failed_in_test;
#define CHECK(cond)                                                                   \
    do {                                                                              \
        if (!(cond)) {                                                                \
            printf("FAIL %s:%d: %s\n", __FILE__, __LINE__, #cond);                    \
            g_checks_failed_in_test++;                                                \
        }                                                                             \
    } while (0)
#define CHECK_EQ(a, b)                                                                \
    do {                                                                              \
        long va_ = (long)(a), vb_ = (long)(b);                                        \
        if (va_ != vb_) {                                                             \
            printf("FAIL %s:%d: %s == %s (%ld != %ld)\n", __FILE__, __LINE__, #a, #b, va_, vb_); \
            g_checks_failed_in_test++;                                                \
        }                                                                             \
    } while (0)

static void fake_reset(fake_t *f)
{
    memset(f, 0, sizeof *f);
    f->fail_at = -1;
}

static void setup(supi3_t *ctx, fake_t *f, int with_cd)
{
    supi3_config_t cfg;
    fake_reset(f);
    memset(&cfg, 0, sizeof cfg);
    cfg.xfer = fake_xfer;
    cfg.read_cd = with_cd ? fake_read_cd : NULL;
    cfg.read_irq = fake_read_irq;
    cfg.set_sas_init = fake_sas;
    cfg.delay_us = fake_delay;
    cfg.user = f;
    memset(ctx, 0xA5, sizeof *ctx); /* garbage, as on a stack */
    (void)supi3_init(ctx, &cfg);
}

static void use_io_pin(supi3_t *ctx)
{
    supi3_config_t cfg = ctx->cfg;
    cfg.read_io = fake_read_io;
    (void)supi3_init(ctx, &cfg);
}

static void log_is(const fake_t *f, const uint8_t *bytes, size_t n)
{
    size_t k;
    CHECK_EQ(f->ntx, n);
    for (k = 0u; k < n && k < f->ntx; ++k) {
        CHECK_EQ(f->tx[k], bytes[k]);
    }
}

static void test_motorola_init_and_configure(void)
{
    supi3_t ctx; fake_t f; uint8_t v = 0u;
    static const uint8_t expect[] = {0x00u, 0x4Du, 0x82u, 0x4Cu, 0x01u, 0x8Du, 0x00u};
    setup(&ctx, &f, 1);
    CHECK_EQ(supi3_initialize(&ctx, SUPI3_MODE_MOTOROLA), SUPI3_OK);
    CHECK_EQ(supi3_configure(&ctx, SUPI3_SET_PCP_N_MSK | SUPI3_SET_CL_LEN_1_BYTE, 0x01u), SUPI3_OK); /* 3.4.5 */
    CHECK_EQ(supi3_read(&ctx, SUPI3_SET_ADDR, &v), SUPI3_OK);
    CHECK_EQ(v, 0x82u);
    CHECK_EQ(f.id, 0x01u);
    log_is(&f, expect, sizeof expect);
    CHECK_EQ(c_d(&f), 0);
}

static void test_intel_init_sr_levels(void)
{
    supi3_t ctx; fake_t f; uint8_t v = 0u;
    setup(&ctx, &f, 1);
    CHECK_EQ(supi3_initialize(&ctx, SUPI3_MODE_INTEL), SUPI3_OK);
    CHECK_EQ(f.tx[0], SUPI3_INIT_INTEL);
    CHECK(f.intel);
    f.pcmd = 0x5Au;
    CHECK_EQ(supi3_read(&ctx, SUPI3_PCMD_ADDR, &v), SUPI3_OK);
    CHECK_EQ(v, 0x5Au);
    CHECK_EQ(f.sr[1], 1); /* command byte: the uP sends */
    CHECK_EQ(f.sr[2], 0); /* data byte of a read: the chip drives (Table 3-9) */
    CHECK_EQ(supi3_write(&ctx, SUPI3_ALARM_ADDR, 0x33u), SUPI3_OK);
    CHECK_EQ(f.alarm, 0x33u);
    CHECK_EQ(f.sr[4], 1);
    CHECK_EQ(supi3_exchange(&ctx, 0u, 1u, &v), SUPI3_E_UNSUPPORTED); /* 3.4.4 */
    CHECK_EQ(f.ntx, 5u);
}

static void test_not_reset_detected(void)
{
    supi3_t ctx; fake_t f; uint8_t v;
    setup(&ctx, &f, 1);
    CHECK_EQ(supi3_initialize(&ctx, SUPI3_MODE_MOTOROLA), SUPI3_OK);
    /* the uP restarts; the chip keeps its state: the init byte becomes a command (UP-3) */
    (void)supi3_init(&ctx, &ctx.cfg);
    CHECK_EQ(supi3_initialize(&ctx, SUPI3_MODE_MOTOROLA), SUPI3_E_NOT_RESET);
    CHECK_EQ(c_d(&f), 0);    /* the no-op data byte completed the command */
    CHECK_EQ(f.ntx, 3u);
    CHECK_EQ(supi3_read(&ctx, 0u, &v), SUPI3_E_NOT_INIT);
    CHECK_EQ(supi3_sas_init(&ctx), SUPI3_OK);
    CHECK_EQ(f.sas_pulses, 1);
    CHECK_EQ(supi3_initialize(&ctx, SUPI3_MODE_INTEL), SUPI3_OK);
    CHECK(f.intel);
}

static void test_interrupted_and_disabled(void)
{
    supi3_t ctx; fake_t f; uint8_t v = 0u;
    setup(&ctx, &f, 1);
    f.phase = PH_COMMAND; f.cmd = 0x4Du; f.phase = PH_DATA; /* uP reset between 4Dh and its data byte */
    CHECK_EQ(supi3_initialize(&ctx, SUPI3_MODE_MOTOROLA), SUPI3_E_NOT_READY);
    CHECK_EQ(f.ntx, 0u); /* nothing sent: SET not overwritten */
    f.phase = PH_DISABLED;
    CHECK_EQ(supi3_initialize(&ctx, SUPI3_MODE_MOTOROLA), SUPI3_E_NOT_READY);
    CHECK_EQ(supi3_sas_init(&ctx), SUPI3_OK);
    CHECK_EQ(supi3_initialize(&ctx, SUPI3_MODE_MOTOROLA), SUPI3_OK);
    f.out[2] = 0x42u;
    CHECK_EQ(supi3_read(&ctx, 2u, &v), SUPI3_OK);
    CHECK_EQ(v, 0x42u);
}

static void test_without_read_cd(void)
{
    supi3_t ctx; fake_t f;
    setup(&ctx, &f, 0);
    CHECK_EQ(supi3_initialize(&ctx, SUPI3_MODE_MOTOROLA), SUPI3_OK);
    CHECK_EQ(f.ntx, 1u);
}

static void test_argument_checks(void)
{
    supi3_t ctx; fake_t f; uint8_t v = 0u, buf[4] = {0};
    supi3_config_t cfg;
    memset(&cfg, 0, sizeof cfg);
    CHECK_EQ(supi3_init(NULL, &cfg), SUPI3_E_ARG);
    CHECK_EQ(supi3_init(&ctx, NULL), SUPI3_E_ARG);
    CHECK_EQ(supi3_init(&ctx, &cfg), SUPI3_E_ARG); /* no xfer */
    CHECK_EQ(supi3_read(NULL, 0u, &v), SUPI3_E_ARG);
    CHECK_EQ(supi3_write(NULL, 0u, 0u), SUPI3_E_ARG);
    CHECK_EQ(supi3_initialize(NULL, SUPI3_MODE_MOTOROLA), SUPI3_E_ARG);
    CHECK_EQ(supi3_irq_service(NULL, &v), SUPI3_E_ARG);
    CHECK_EQ(supi3_sas_init(NULL), SUPI3_E_ARG);
    setup(&ctx, &f, 1);
    CHECK_EQ(supi3_initialize(&ctx, (supi3_mode_t)2), SUPI3_E_ARG);
    CHECK_EQ(supi3_read(&ctx, 0u, &v), SUPI3_E_NOT_INIT); /* UP-25 */
    CHECK_EQ(supi3_write(&ctx, 0u, 0u), SUPI3_E_NOT_INIT);
    CHECK_EQ(supi3_block_transfer(&ctx, 1, 1, buf, buf, 2u), SUPI3_E_NOT_INIT);
    CHECK_EQ(f.ntx, 0u);
    CHECK_EQ(supi3_initialize(&ctx, SUPI3_MODE_MOTOROLA), SUPI3_OK);
    CHECK_EQ(supi3_read(&ctx, 15u, &v), SUPI3_E_ARG);
    CHECK_EQ(supi3_write(&ctx, 15u, 0u), SUPI3_E_ARG);
    CHECK_EQ(supi3_read(&ctx, 0u, NULL), SUPI3_E_ARG);
    CHECK_EQ(supi3_exchange(&ctx, 0u, 0u, NULL), SUPI3_E_ARG);
    CHECK_EQ(supi3_irq_service(&ctx, NULL), SUPI3_E_ARG);
    CHECK_EQ(supi3_block_transfer(&ctx, 1, 1, buf, buf, 0u), SUPI3_E_ARG);
    CHECK_EQ(supi3_block_transfer(&ctx, 1, 1, buf, buf, 5u), SUPI3_E_ARG);
    CHECK_EQ(supi3_block_transfer(&ctx, 1, 1, buf, NULL, 2u), SUPI3_E_ARG); /* Motorola writes IN anyway */
    CHECK_EQ(supi3_block_transfer(&ctx, 1, 1, NULL, buf, 2u), SUPI3_E_ARG);
    CHECK_EQ(f.ntx, 1u); /* only the init byte went out */
    CHECK_EQ(c_d(&f), 0);
}

static void test_motorola_block_and_exchange(void)
{
    supi3_t ctx; fake_t f; uint8_t out[4] = {0}, in[4] = {0x12u, 0x34u, 0x56u, 0x78u}, v = 0u;
    setup(&ctx, &f, 1);
    CHECK_EQ(supi3_initialize(&ctx, SUPI3_MODE_MOTOROLA), SUPI3_OK);
    CHECK_EQ(supi3_configure(&ctx, SUPI3_SET_PCP_N_MSK | SUPI3_SET_CL_LEN_2_WORDS, 0x03u), SUPI3_OK);
    supi3_put_u32(f.out, 0xCAFEBABEu);
    f.ntx = 0u;
    CHECK_EQ(supi3_block_transfer(&ctx, 1, 1, out, in, 4u), SUPI3_OK);
    CHECK_EQ(f.tx[0], SUPI3_CMD_BLOCK_TRANSFER);
    CHECK_EQ(f.ntx, 5u);
    CHECK_EQ(supi3_get_u32(out), 0xCAFEBABEu);
    CHECK(memcmp(f.in, in, 4u) == 0);
    CHECK_EQ(c_d(&f), 0); /* block complete: command phase */
    f.out[1] = 0x99u;
    CHECK_EQ(supi3_exchange(&ctx, 1u, 0x77u, &v), SUPI3_OK);
    CHECK_EQ(f.tx[5], SUPI3_CMD_READ_WRITE(1u));
    CHECK_EQ(v, 0x99u);
    CHECK_EQ(f.in[1], 0x77u);
}

static void test_intel_block_fig_3_12(void)
{
    /* Fig. 3-12: 24-bit output device, 8Fh then three reads with S/R = 0 */
    supi3_t ctx; fake_t f; uint8_t out[3] = {0}, in[3] = {0xA1u, 0xB2u, 0xC3u};
    setup(&ctx, &f, 1);
    CHECK_EQ(supi3_initialize(&ctx, SUPI3_MODE_INTEL), SUPI3_OK);
    CHECK_EQ(supi3_configure(&ctx, SUPI3_SET_PCP_N_MSK | SUPI3_SET_CL_LEN_3_BYTES, 0x02u), SUPI3_OK);
    f.out[0] = 0x14u; f.out[1] = 0x56u; f.out[2] = 0x78u;
    f.ntx = 0u;
    CHECK_EQ(supi3_block_transfer(&ctx, 1, 0, out, NULL, 3u), SUPI3_OK);
    CHECK_EQ(f.tx[0], 0x8Fu);
    CHECK_EQ(f.ntx, 4u);
    CHECK_EQ(f.sr[1], 0); CHECK_EQ(f.sr[3], 0);
    CHECK_EQ(out[0], 0x14u); CHECK_EQ(out[1], 0x56u); CHECK_EQ(out[2], 0x78u);
    CHECK_EQ(c_d(&f), 0);
    f.ntx = 0u;
    CHECK_EQ(supi3_block_transfer(&ctx, 1, 1, out, in, 3u), SUPI3_OK); /* reads, then writes (UP-11) */
    CHECK_EQ(f.ntx, 7u);
    CHECK_EQ(f.sr[3], 0); CHECK_EQ(f.sr[4], 1);
    CHECK(memcmp(f.in, in, 3u) == 0);
    CHECK_EQ(c_d(&f), 0);
    CHECK_EQ(supi3_block_transfer(&ctx, 0, 0, out, in, 3u), SUPI3_E_ARG);
    CHECK_EQ(supi3_block_transfer(&ctx, 0, 1, NULL, NULL, 3u), SUPI3_E_ARG);
}

static void test_block_length_follows_set(void)
{
    supi3_t ctx; fake_t f; uint8_t out[4] = {0}, in[4] = {0};
    setup(&ctx, &f, 1);
    CHECK_EQ(supi3_initialize(&ctx, SUPI3_MODE_MOTOROLA), SUPI3_OK);
    CHECK_EQ(supi3_block_transfer(&ctx, 1, 1, out, in, 1u), SUPI3_E_ARG); /* below one word (3.4.6) */
    f.set = SUPI3_SET_PCP_N_MSK | SUPI3_SET_CL_LEN_3_BYTES; /* set before this uP started */
    CHECK_EQ(supi3_block_transfer(&ctx, 1, 1, out, in, 3u), SUPI3_OK);    /* SET unknown: 2..4 taken */
    CHECK_EQ(c_d(&f), 0);
    f.ntx = 0u;
    CHECK_EQ(supi3_configure(&ctx, SUPI3_SET_PCP_N_MSK | SUPI3_SET_CL_LEN_1_WORD, 0x01u), SUPI3_OK);
    f.ntx = 0u;
    CHECK_EQ(supi3_block_transfer(&ctx, 1, 1, out, in, 3u), SUPI3_E_ARG); /* UP-10: SET says 2 bytes */
    CHECK_EQ(supi3_block_transfer(&ctx, 1, 1, out, in, 2u), SUPI3_OK);
    CHECK_EQ(f.ntx, 3u);
    CHECK_EQ(supi3_write(&ctx, SUPI3_SET_ADDR, SUPI3_SET_PCP_N_MSK | SUPI3_SET_CL_LEN_1_BYTE), SUPI3_OK);
    CHECK_EQ(supi3_block_transfer(&ctx, 1, 1, out, in, 2u), SUPI3_E_ARG); /* one byte: no block transfer */
    CHECK_EQ(supi3_write(&ctx, SUPI3_SET_ADDR, SUPI3_SET_EXTREG_MSK | SUPI3_SET_CL_LEN_2_WORDS), SUPI3_OK);
    CHECK_EQ(supi3_block_transfer(&ctx, 1, 1, out, in, 4u), SUPI3_E_ARG); /* ExtReg = 1 (3.4.8) */
    f.set = SUPI3_SET_PCP_N_MSK | SUPI3_SET_CL_LEN_2_WORDS;
    CHECK_EQ(supi3_read(&ctx, SUPI3_SET_ADDR, out), SUPI3_OK); /* a read teaches the driver too */
    f.ntx = 0u;
    CHECK_EQ(supi3_block_transfer(&ctx, 1, 1, out, in, 4u), SUPI3_OK);
    CHECK_EQ(f.ntx, 5u);
    (void)supi3_init(&ctx, &ctx.cfg); /* a restarted uP does not know SET */
    CHECK_EQ(supi3_sas_init(&ctx), SUPI3_OK);
    CHECK_EQ(supi3_initialize(&ctx, SUPI3_MODE_MOTOROLA), SUPI3_OK);
    CHECK_EQ(supi3_block_transfer(&ctx, 1, 1, out, in, 4u), SUPI3_OK);
    CHECK_EQ(c_d(&f), 0);
}

static void test_irq_service(void)
{
    supi3_t ctx; fake_t f; uint8_t ev = 0xFFu;
    setup(&ctx, &f, 1);
    CHECK_EQ(supi3_initialize(&ctx, SUPI3_MODE_MOTOROLA), SUPI3_OK);
    CHECK_EQ(supi3_write(&ctx, SUPI3_IRQ_EN_ADDR, SUPI3_IRQ_EN_VALID_MSK | SUPI3_IRQ_EN_PCMD_MSK), SUPI3_OK);
    f.ntx = 0u;
    CHECK_EQ(supi3_irq_service(&ctx, &ev), SUPI3_OK); /* /IRQ high: nothing sent */
    CHECK_EQ(ev, 0u);
    CHECK_EQ(f.ntx, 0u);
    f.irq_evt = SUPI3_IRQ_EVT_VALID_MSK | SUPI3_IRQ_EVT_IO_ACCESS_MSK;
    CHECK_EQ(supi3_irq_service(&ctx, &ev), SUPI3_OK);
    CHECK_EQ(ev, SUPI3_IRQ_EVT_VALID_MSK | SUPI3_IRQ_EVT_IO_ACCESS_MSK);
    CHECK_EQ(f.tx[0], SUPI3_CMD_READ(SUPI3_IRQ_EVT_ADDR));
    CHECK_EQ(f.irq_evt, SUPI3_IRQ_EVT_IO_ACCESS_MSK); /* read-clear of bits 6..0 (3.4.14) */
    CHECK_EQ(f.irq_pin_reads, 3); /* before, and after the read: /IRQ high, nothing left (FW-22) */
    /* an event that comes during the read keeps /IRQ low (no new edge): read again until /IRQ is high (FW-22) */
    f.ntx = 0u; f.irq_pin_reads = 0;
    f.irq_evt = SUPI3_IRQ_EVT_VALID_MSK;
    f.evt_after[0] = SUPI3_IRQ_EVT_PCMD_MSK; f.n_evt_after = 1u; f.evt_idx = 0u;
    CHECK_EQ(supi3_irq_service(&ctx, &ev), SUPI3_OK);
    CHECK_EQ(ev, SUPI3_IRQ_EVT_VALID_MSK | SUPI3_IRQ_EVT_PCMD_MSK);
    CHECK_EQ(f.ntx, 4u);
    CHECK_EQ(f.irq_pin_reads, 3);
    CHECK_EQ(f.irq_evt, 0u);
    /* /IRQ still low after SUPI3_IRQ_SERVICE_MAX_READS reads: SUPI3_E_TIMEOUT, the events read kept */
    f.ntx = 0u; f.irq_pin_reads = 0;
    f.irq_evt = SUPI3_IRQ_EVT_VALID_MSK;
    memset(f.evt_after, SUPI3_IRQ_EVT_VALID_MSK, sizeof f.evt_after); f.n_evt_after = 4u; f.evt_idx = 0u;
    CHECK_EQ(SUPI3_IRQ_SERVICE_MAX_READS, 4u);
    CHECK_EQ(supi3_irq_service(&ctx, &ev), SUPI3_E_TIMEOUT);
    CHECK_EQ(ev, SUPI3_IRQ_EVT_VALID_MSK);
    CHECK_EQ(f.ntx, 2u * SUPI3_IRQ_SERVICE_MAX_READS);
    CHECK_EQ(f.irq_pin_reads, SUPI3_IRQ_SERVICE_MAX_READS + 1u);
    CHECK_EQ(supi3_irq_service(&ctx, &ev), SUPI3_OK); /* the driver stays initialized: the next call serves it */
    CHECK_EQ(ev, SUPI3_IRQ_EVT_VALID_MSK);
}

static int unwired_pin(void *user, int *level)
{
    (void)user;
    *level = 0;
    return SUPI3_E_UNSUPPORTED;
}

static int unwired_sas(void *user, int level)
{
    (void)user; (void)level;
    return SUPI3_E_UNSUPPORTED;
}

static void test_pin_callbacks_saying_not_wired(void)
{
    /* FW-21: a callback that returns SUPI3_E_UNSUPPORTED is a pin the board does not wire, as a NULL callback */
    supi3_t ctx; fake_t f; uint8_t ev = 0xFFu; uint8_t v = 0u;
    static const uint8_t poll[] = {0x8Eu, 0x00u};
    setup(&ctx, &f, 1);
    ctx.cfg.read_cd = unwired_pin; /* the init byte goes out unchecked */
    CHECK_EQ(supi3_initialize(&ctx, SUPI3_MODE_MOTOROLA), SUPI3_OK);
    ctx.cfg.set_sas_init = unwired_sas; /* refused, nothing driven, still initialized */
    CHECK_EQ(supi3_sas_init(&ctx), SUPI3_E_UNSUPPORTED);
    CHECK_EQ(f.sas_pulses, 0);
    CHECK_EQ(supi3_read(&ctx, 0u, &v), SUPI3_OK);
    ctx.cfg.read_irq = unwired_pin; /* one read of 14, as without read_irq */
    f.ntx = 0u; f.irq_evt = SUPI3_IRQ_EVT_VALID_MSK;
    CHECK_EQ(supi3_irq_service(&ctx, &ev), SUPI3_OK);
    CHECK_EQ(ev, SUPI3_IRQ_EVT_VALID_MSK);
    CHECK_EQ(f.ntx, 2u);
    ctx.cfg.read_io = unwired_pin; /* polls register 14 */
    f.ntx = 0u; f.irq_evt = SUPI3_IRQ_EVT_PCMD_MSK;
    CHECK_EQ(supi3_poll_io_window(&ctx, 2u, &ev), SUPI3_OK);
    CHECK_EQ(ev, SUPI3_IRQ_EVT_PCMD_MSK);
    log_is(&f, poll, sizeof poll);
    f.ntx = 0u;
    CHECK_EQ(supi3_poll_io_window(&ctx, 2u, NULL), SUPI3_E_ARG); /* nowhere to keep the events: nothing sent */
    CHECK_EQ(f.ntx, 0u);
    CHECK_EQ(supi3_read(&ctx, 0u, &v), SUPI3_OK);
}

static void test_transport_error(void)
{
    supi3_t ctx; fake_t f; uint8_t v = 0u;
    setup(&ctx, &f, 1);
    CHECK_EQ(supi3_initialize(&ctx, SUPI3_MODE_MOTOROLA), SUPI3_OK);
    f.fail_at = 2; /* the data byte of the next read */
    CHECK_EQ(supi3_read(&ctx, 0u, &v), SUPI3_E_TRANSPORT);
    CHECK_EQ(supi3_read(&ctx, 0u, &v), SUPI3_E_NOT_INIT); /* state unknown: initialize again */
    f.fail_at = -1;
    CHECK_EQ(supi3_initialize(&ctx, SUPI3_MODE_MOTOROLA), SUPI3_E_NOT_READY); /* chip waits for data */
    CHECK_EQ(supi3_sas_init(&ctx), SUPI3_OK);
    CHECK_EQ(supi3_initialize(&ctx, SUPI3_MODE_MOTOROLA), SUPI3_OK);
}

static void test_irq_enable(void)
{
    supi3_t ctx; fake_t f;
    static const uint8_t expect[] = {0x00u, 0x4Eu, 0x50u};
    setup(&ctx, &f, 1);
    CHECK_EQ(supi3_irq_enable(NULL, 0x10u), SUPI3_E_ARG);
    CHECK_EQ(supi3_irq_enable(&ctx, 0x10u), SUPI3_E_NOT_INIT);
    CHECK_EQ(supi3_irq_enable(&ctx, 0x80u), SUPI3_E_ARG); /* value arguments before the state, as addresses */
    CHECK_EQ(supi3_initialize(&ctx, SUPI3_MODE_MOTOROLA), SUPI3_OK);
    CHECK_EQ(supi3_irq_enable(&ctx, SUPI3_IRQ_EN_PCMD_MSK | SUPI3_IRQ_EN_VALID_MSK), SUPI3_OK); /* 3.4.14 step 1 */
    CHECK_EQ(f.irq_en, 0x50u);
    CHECK_EQ(supi3_irq_enable(&ctx, 0x80u), SUPI3_E_ARG); /* bit 7 reserved (RM-7) */
    CHECK_EQ(supi3_irq_enable(&ctx, 0xFFu), SUPI3_E_ARG);
    log_is(&f, expect, sizeof expect);
    CHECK_EQ(supi3_irq_enable(&ctx, 0x7Fu), SUPI3_OK);
    CHECK_EQ(f.irq_en, 0x7Fu);
    CHECK_EQ(supi3_irq_enable(&ctx, 0x00u), SUPI3_OK);
    CHECK_EQ(f.irq_en, 0x00u);
}

static void test_poll_io_window_by_register(void)
{
    supi3_t ctx; fake_t f; uint8_t ev = 0xFFu;
    static const uint8_t expect[] = {0x8Eu, 0x00u, 0x8Eu, 0x00u, 0x8Eu, 0x00u};
    setup(&ctx, &f, 1);
    CHECK_EQ(supi3_poll_io_window(&ctx, 1u, &ev), SUPI3_E_NOT_INIT);
    CHECK_EQ(supi3_poll_io_window(&ctx, 0u, &ev), SUPI3_E_ARG);
    CHECK_EQ(supi3_poll_io_window(&ctx, 1u, NULL), SUPI3_E_NOT_INIT); /* pointers after the state */
    CHECK_EQ(supi3_initialize(&ctx, SUPI3_MODE_MOTOROLA), SUPI3_OK);
    f.ntx = 0u;
    f.io_scripted = 1; f.io_busy_reads = 2;
    f.irq_evt = SUPI3_IRQ_EVT_VALID_MSK;
    f.evt_after[0] = SUPI3_IRQ_EVT_PCMD_MSK; f.n_evt_after = 1u; /* arrives between the first and second poll */
    CHECK_EQ(supi3_poll_io_window(&ctx, 3u, &ev), SUPI3_OK); /* D7 = 1, 1, 0 */
    CHECK_EQ(ev, SUPI3_IRQ_EVT_VALID_MSK | SUPI3_IRQ_EVT_PCMD_MSK); /* no event lost, D7 not in events */
    CHECK_EQ(f.irq_evt, 0u);
    log_is(&f, expect, sizeof expect);
    f.ntx = 0u; f.io_busy_reads = 5; f.irq_evt = SUPI3_IRQ_EVT_IB_RESET_MSK;
    CHECK_EQ(supi3_poll_io_window(&ctx, 3u, &ev), SUPI3_E_TIMEOUT);
    CHECK_EQ(ev, SUPI3_IRQ_EVT_IB_RESET_MSK); /* the events read before the timeout are kept */
    CHECK_EQ(f.ntx, 6u);
    CHECK_EQ(f.io_busy_reads, 2);
    f.ntx = 0u;
    CHECK_EQ(supi3_poll_io_window(&ctx, 0u, &ev), SUPI3_E_ARG);
    CHECK_EQ(supi3_poll_io_window(&ctx, 1u, NULL), SUPI3_E_ARG); /* without read_io the events are needed */
    CHECK_EQ(supi3_poll_io_window(NULL, 1u, &ev), SUPI3_E_ARG);
    CHECK_EQ(f.ntx, 0u);
    f.fail_at = 1; /* the data byte of the first read */
    CHECK_EQ(supi3_poll_io_window(&ctx, 3u, &ev), SUPI3_E_TRANSPORT);
    CHECK_EQ(supi3_poll_io_window(&ctx, 3u, &ev), SUPI3_E_NOT_INIT);
}

static void test_poll_io_window_by_pin(void)
{
    supi3_t ctx; fake_t f; uint8_t ev = 0xFFu;
    setup(&ctx, &f, 1);
    use_io_pin(&ctx);
    CHECK_EQ(supi3_initialize(&ctx, SUPI3_MODE_INTEL), SUPI3_OK);
    f.ntx = 0u;
    f.io_pin_busy = 3;
    f.irq_evt = SUPI3_IRQ_EVT_VALID_MSK;
    CHECK_EQ(supi3_poll_io_window(&ctx, 4u, &ev), SUPI3_OK);
    CHECK_EQ(ev, 0u);
    CHECK_EQ(f.io_pin_reads, 4);
    CHECK_EQ(f.ntx, 0u); /* nothing sent: the events stay pending */
    CHECK_EQ(f.irq_evt, SUPI3_IRQ_EVT_VALID_MSK);
    f.io_pin_busy = 2;
    CHECK_EQ(supi3_poll_io_window(&ctx, 2u, NULL), SUPI3_E_TIMEOUT);
    CHECK_EQ(f.io_pin_reads, 6);
    CHECK_EQ(supi3_poll_io_window(&ctx, 1u, NULL), SUPI3_OK);
    CHECK_EQ(supi3_poll_io_window(&ctx, 0u, NULL), SUPI3_E_ARG);
    f.io_pin_fail = 1;
    CHECK_EQ(supi3_poll_io_window(&ctx, 1u, &ev), SUPI3_E_TRANSPORT);
    f.io_pin_fail = 0;
    CHECK_EQ(supi3_poll_io_window(&ctx, 1u, &ev), SUPI3_OK); /* a pin read leaves the chip as it was */
    CHECK_EQ(f.ntx, 0u);
}

static void test_processor_alarm_and_command(void)
{
    supi3_t ctx; fake_t f; uint8_t v = 0u;
    int intel;
    for (intel = 0; intel <= 1; ++intel) {
        static const uint8_t expect[] = {0x47u, 0xA5u, 0x87u, 0x00u};
        setup(&ctx, &f, 1);
        CHECK_EQ(supi3_processor_alarm(&ctx, 0xA5u), SUPI3_E_NOT_INIT);
        CHECK_EQ(supi3_processor_command(&ctx, &v), SUPI3_E_NOT_INIT);
        CHECK_EQ(supi3_initialize(&ctx, intel ? SUPI3_MODE_INTEL : SUPI3_MODE_MOTOROLA), SUPI3_OK);
        f.ntx = 0u;
        f.pcmd = 0x3Cu;
        CHECK_EQ(supi3_processor_alarm(&ctx, 0xA5u), SUPI3_OK);  /* 3.4.9: slave to master */
        CHECK_EQ(supi3_processor_command(&ctx, &v), SUPI3_OK);   /* 3.4.9: master to slave */
        CHECK_EQ(f.alarm, 0xA5u);
        CHECK_EQ(v, 0x3Cu);
        log_is(&f, expect, sizeof expect);
        CHECK_EQ(f.sr[3], 0); /* read data byte: the chip drives (Table 3-9) */
        CHECK_EQ(f.sr[1], 1);
        CHECK_EQ(supi3_processor_command(&ctx, NULL), SUPI3_E_ARG);
        CHECK_EQ(supi3_processor_alarm(NULL, 0u), SUPI3_E_ARG);
        CHECK_EQ(f.ntx, 4u);
    }
}

static void test_optical_status(void)
{
    supi3_t ctx; fake_t f; supi3_optical_t st;
    static const uint8_t expect[] = {0x88u, 0x00u, 0x89u, 0x00u, 0x8Au, 0x00u, 0x8Bu, 0x00u};
    setup(&ctx, &f, 1);
    memset(&st, 0xEE, sizeof st);
    CHECK_EQ(supi3_optical_status(&ctx, &st), SUPI3_E_NOT_INIT);
    CHECK_EQ(supi3_initialize(&ctx, SUPI3_MODE_MOTOROLA), SUPI3_OK);
    f.ntx = 0u;
    f.optical[0] = 0x80u | 0x40u | 62u; /* enabled, glass, 62 (RM-5) */
    f.optical[1] = 63u;                 /* not enabled, polymer, 63 = 400 m to 20 km */
    f.optical[2] = 0x80u | 15u;         /* enabled, level 15 (RM-6) */
    f.optical[3] = 0x3Cu;               /* branch 3, out 12 */
    CHECK_EQ(supi3_optical_status(&ctx, &st), SUPI3_OK);
    log_is(&f, expect, sizeof expect);
    CHECK_EQ(st.out_length, 62); CHECK_EQ(st.out_medium, 1); CHECK_EQ(st.out_enable, 1);
    CHECK_EQ(st.branch_length, 63); CHECK_EQ(st.branch_medium, 0); CHECK_EQ(st.branch_enable, 0);
    CHECK_EQ(st.in_level, 15); CHECK_EQ(st.in_enable, 1);
    CHECK_EQ(st.out_level, 12); CHECK_EQ(st.branch_level, 3);
    CHECK_EQ(supi3_optical_status(&ctx, NULL), SUPI3_E_ARG);
    CHECK_EQ(supi3_optical_status(NULL, &st), SUPI3_E_ARG);
    CHECK_EQ(f.ntx, 8u);
    memset(&st, 0xEE, sizeof st);
    f.fail_at = 13; /* the third register's data byte */
    CHECK_EQ(supi3_optical_status(&ctx, &st), SUPI3_E_TRANSPORT);
    CHECK_EQ(st.out_length, 0xEE); /* written only when all four reads went through */
}

static void test_optical_length_conversions(void)
{
    /* OPT-1: every code of both media round-trips; 150 m polymer is code 24; limits and NULLs are refused. */
    uint32_t lo = 7u, hi = 7u, m;
    uint8_t code = 99u, c, medium;
    for (medium = 0u; medium <= 1u; ++medium) {
        for (c = 0u; c <= SUPI3_OPTICAL_LENGTH_MAX_CODE; ++c) {
            CHECK_EQ(supi3_optical_length_cm(c, medium, &lo, &hi), SUPI3_OK);
            CHECK(lo < hi);
            CHECK_EQ(supi3_optical_length_code(lo, medium, &code), SUPI3_OK); CHECK_EQ(code, c);
            CHECK_EQ(supi3_optical_length_code(hi - 1u, medium, &code), SUPI3_OK); CHECK_EQ(code, c);
        }
        CHECK_EQ(hi, SUPI3_OPTICAL_MAX_PATH_CM);
    }
    CHECK_EQ(supi3_optical_length_code(15000u, 0u, &code), SUPI3_OK); CHECK_EQ(code, 24u);
    CHECK_EQ(supi3_optical_length_code(15000u, 1u, &code), SUPI3_OK); CHECK_EQ(code, 0u);
    CHECK_EQ(supi3_optical_length_cm(63u, 0u, &lo, &hi), SUPI3_OK); CHECK_EQ(lo, 39375u);
    m = SUPI3_OPTICAL_MAX_PATH_CM;
    CHECK_EQ(supi3_optical_length_code(m, 1u, &code), SUPI3_OK); CHECK_EQ(code, 63u);
    code = 99u; lo = hi = 7u;
    CHECK_EQ(supi3_optical_length_code(m + 1u, 0u, &code), SUPI3_E_ARG);
    CHECK_EQ(supi3_optical_length_code(0u, 2u, &code), SUPI3_E_ARG);
    CHECK_EQ(supi3_optical_length_code(0u, 0u, NULL), SUPI3_E_ARG);
    CHECK_EQ(supi3_optical_length_cm(64u, 0u, &lo, &hi), SUPI3_E_ARG);
    CHECK_EQ(supi3_optical_length_cm(0u, 2u, &lo, &hi), SUPI3_E_ARG);
    CHECK_EQ(supi3_optical_length_cm(0u, 0u, NULL, &hi), SUPI3_E_ARG);
    CHECK_EQ(supi3_optical_length_cm(0u, 0u, &lo, NULL), SUPI3_E_ARG);
    CHECK_EQ(code, 99u); CHECK_EQ(lo, 7u); CHECK_EQ(hi, 7u);
}

static void test_helpers_and_strerror(void)
{
    uint8_t b[4];
    supi3_put_u16(b, 0x0901u); /* 3.4.5: the master sees 0901h */
    CHECK_EQ(b[0], 0x09u); CHECK_EQ(b[1], 0x01u);
    CHECK_EQ(supi3_get_u16(b), 0x0901u);
    supi3_put_u32(b, 0x01020304u);
    CHECK_EQ(b[0], 1); CHECK_EQ(b[3], 4);
    CHECK_EQ(supi3_get_u32(b), 0x01020304u);
    CHECK_EQ(supi3_get_u32(NULL), 0u);
    CHECK(strcmp(supi3_strerror(SUPI3_OK), "ok") == 0);
    CHECK(strcmp(supi3_strerror(12345), "unknown error") == 0);
    CHECK(strstr(supi3_strerror(SUPI3_E_NOT_RESET), "SAS_INIT") != NULL);
    CHECK(strcmp(supi3_strerror(SUPI3_E_ARG), supi3_strerror(SUPI3_E_TRANSPORT)) != 0);
    CHECK(strstr(supi3_strerror(SUPI3_E_TIMEOUT), "max_polls") != NULL);
    CHECK_EQ(SUPI3_E_TIMEOUT, -7);
}

static void test_frame_gap_and_no_globals(void)
{
    /* two contexts on two fakes do not interfere; frame_gap_us calls delay_us once per frame */
    supi3_t a, b; fake_t fa, fb; uint8_t v = 0u;
    setup(&a, &fa, 1);
    setup(&b, &fb, 1);
    a.cfg.frame_gap_us = 2u; /* reconfigure through supi3_init */
    (void)supi3_init(&a, &a.cfg);
    CHECK_EQ(supi3_initialize(&a, SUPI3_MODE_MOTOROLA), SUPI3_OK);
    CHECK_EQ(supi3_initialize(&b, SUPI3_MODE_INTEL), SUPI3_OK);
    fa.out[0] = 1u; fb.out[0] = 2u;
    CHECK_EQ(supi3_read(&a, 0u, &v), SUPI3_OK); CHECK_EQ(v, 1u);
    CHECK_EQ(supi3_read(&b, 0u, &v), SUPI3_OK); CHECK_EQ(v, 2u);
    CHECK_EQ(fa.delays, 3);
    CHECK_EQ(fb.delays, 0);
}

int main(void)
{
    static void (*const tests[])(void) = {
        test_motorola_init_and_configure, test_intel_init_sr_levels, test_not_reset_detected,
        test_interrupted_and_disabled, test_without_read_cd, test_argument_checks,
        test_motorola_block_and_exchange, test_intel_block_fig_3_12, test_block_length_follows_set, test_irq_service,
        test_transport_error, test_irq_enable, test_poll_io_window_by_register, test_poll_io_window_by_pin,
        test_processor_alarm_and_command, test_optical_status, test_optical_length_conversions,
        test_helpers_and_strerror,
        test_pin_callbacks_saying_not_wired,
        test_frame_gap_and_no_globals,
    };
    size_t k, n = sizeof tests / sizeof tests[0];
    int passed = 0;
    for (k = 0u; k < n; ++k) {
        g_checks_failed_in_test = 0;
        tests[k]();
        if (g_checks_failed_in_test == 0) {
            passed++;
        } else {
            g_failed++;
        }
    }
    printf("%d passed, %d failed\n", passed, g_failed);
    return g_failed == 0 ? 0 : 1;
}

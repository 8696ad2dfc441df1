/*
 * Fuzz harness of sdk/c (supi3.c), driven by tests/test_sdk_c_fuzz.py: the driver against a scripted chip.
 *
 * Every byte the chip returns, every C/D, /IRQ and I/O (MFP1) level comes from the case's script; a callback whose
 * script is used up fails (returns -1), which the driver must report as SUPI3_E_TRANSPORT. The harness never
 * checks results itself: it prints what the driver returned and what it sent, and the Python reference decides.
 *
 * Input, whitespace-separated decimal integers, one case after another until end of input:
 *   with_cd with_irq with_io  n_rx rx...  n_cd cd...  n_irq irq...  n_io io...  n_ops (op a0 .. a7)...
 * Output, one line per case:
 *   for each op: rc n_out out...   then: n_frames (tx s_r)...   then: used_rx used_cd used_irq used_io
 * Outputs the driver did not write keep their fill value (SENTINEL), so a partial write shows.
 * Ops (a0.. as named; "null" = pass NULL for the output pointer):
 *   0 initialize mode | 1 read addr null | 2 write addr value | 3 exchange addr wr null |
 *   4 block_transfer rd wr n in0 in1 in2 in3 flags(1: out NULL, 2: in NULL) | 5 irq_service null |
 *   6 poll_io_window max_polls null | 7 processor_command null | 8 processor_alarm value | 9 optical_status null |
 *   10 irq_enable mask | 11 configure set id | 12 sas_init | 13 helpers b0 b1 b2 b3 u16 u32
 * Exit status 2 on malformed input.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "supi3.h"

#define MAX_SCRIPT 256
#define MAX_OPS 32
#define MAX_FRAMES 1024
#define SENTINEL 0xA5u
#define OPTICAL_SENTINEL 0xEEu

typedef struct {
    long v[MAX_SCRIPT];
    size_t n, used;
} stream_t;

typedef struct {
    stream_t rx, cd, irq, io;
    uint8_t tx[MAX_FRAMES];
    int sr[MAX_FRAMES];
    size_t frames;
} chip_t;

static int next_level(stream_t *s, int *level)
{
    if (s->used >= s->n) {
        return -1;
    }
    *level = (int)s->v[s->used++];
    return 0;
}

static int chip_xfer(void *user, uint8_t tx, uint8_t *rx, int s_r)
{
    chip_t *c = (chip_t *)user;
    if (c->frames < MAX_FRAMES) {
        c->tx[c->frames] = tx;
        c->sr[c->frames] = s_r;
    }
    c->frames++;
    if (c->rx.used >= c->rx.n) {
        return -1;
    }
    *rx = (uint8_t)c->rx.v[c->rx.used++];
    return 0;
}

static int chip_cd(void *user, int *level) { return next_level(&((chip_t *)user)->cd, level); }
static int chip_irq(void *user, int *level) { return next_level(&((chip_t *)user)->irq, level); }
static int chip_io(void *user, int *level) { return next_level(&((chip_t *)user)->io, level); }
static int chip_sas(void *user, int level) { (void)user; (void)level; return 0; }

static int read_long(long *out)
{
    return scanf("%ld", out) == 1;
}

static void bad_input(const char *what)
{
    fprintf(stderr, "malformed input: %s\n", what);
    exit(2);
}

static void read_stream(stream_t *s)
{
    long n, k;
    if (!read_long(&n) || n < 0 || n > MAX_SCRIPT) {
        bad_input("stream length");
    }
    for (k = 0; k < n; ++k) {
        if (!read_long(&s->v[k])) {
            bad_input("stream value");
        }
    }
    s->n = (size_t)n;
    s->used = 0u;
}

static void print_bytes(const uint8_t *bytes, size_t n)
{
    size_t k;
    printf(" %lu", (unsigned long)n);
    for (k = 0u; k < n; ++k) {
        printf(" %u", (unsigned)bytes[k]);
    }
}

static void run_op(supi3_t *ctx, long op, const long *a)
{
    uint8_t out[8];
    int rc = SUPI3_OK;
    size_t n_out = 0u;
    memset(out, SENTINEL, sizeof out);
    switch (op) {
    case 0:
        rc = supi3_initialize(ctx, (supi3_mode_t)a[0]);
        break;
    case 1:
        rc = supi3_read(ctx, (uint8_t)a[0], a[1] ? NULL : &out[0]);
        n_out = 1u;
        break;
    case 2:
        rc = supi3_write(ctx, (uint8_t)a[0], (uint8_t)a[1]);
        break;
    case 3:
        rc = supi3_exchange(ctx, (uint8_t)a[0], (uint8_t)a[1], a[2] ? NULL : &out[0]);
        n_out = 1u;
        break;
    case 4: {
        /* buffers of exactly n bytes (n <= 5): ASan sees any access beyond them */
        size_t n = (size_t)a[2], k, size = n > 0u ? n : 1u;
        uint8_t *o = (a[7] & 1) ? NULL : (uint8_t *)malloc(size);
        uint8_t *i = (a[7] & 2) ? NULL : (uint8_t *)malloc(size);
        if (o != NULL) {
            memset(o, SENTINEL, size);
        }
        for (k = 0u; i != NULL && k < n && k < 4u; ++k) {
            i[k] = (uint8_t)a[3 + k];
        }
        rc = supi3_block_transfer(ctx, (int)a[0], (int)a[1], o, i, n);
        for (k = 0u; o != NULL && k < n && k < 4u; ++k) {
            out[k] = o[k];
        }
        free(o);
        free(i);
        n_out = 4u;
        break;
    }
    case 5:
        rc = supi3_irq_service(ctx, a[0] ? NULL : &out[0]);
        n_out = 1u;
        break;
    case 6:
        rc = supi3_poll_io_window(ctx, (uint32_t)a[0], a[1] ? NULL : &out[0]);
        n_out = 1u;
        break;
    case 7:
        rc = supi3_processor_command(ctx, a[0] ? NULL : &out[0]);
        n_out = 1u;
        break;
    case 8:
        rc = supi3_processor_alarm(ctx, (uint8_t)a[0]);
        break;
    case 9: {
        supi3_optical_t st;
        memset(&st, OPTICAL_SENTINEL, sizeof st);
        rc = supi3_optical_status(ctx, a[0] ? NULL : &st);
        printf("%d 10 %u %u %u %u %u %u %u %u %u %u ", rc, st.out_length, st.out_medium, st.out_enable,
               st.branch_length, st.branch_medium, st.branch_enable, st.in_level, st.in_enable, st.out_level,
               st.branch_level);
        return;
    }
    case 10:
        rc = supi3_irq_enable(ctx, (uint8_t)a[0]);
        break;
    case 11:
        rc = supi3_configure(ctx, (uint8_t)a[0], (uint8_t)a[1]);
        break;
    case 12:
        rc = supi3_sas_init(ctx);
        break;
    case 13: {
        uint8_t b[4];
        uint8_t p16[2], p32[4];
        size_t k;
        for (k = 0u; k < 4u; ++k) {
            b[k] = (uint8_t)a[k];
        }
        supi3_put_u16(p16, (uint16_t)a[4]);
        supi3_put_u32(p32, (uint32_t)(unsigned long)a[5]);
        printf("0 8 %u %lu %u %u %u %u %u %u ", (unsigned)supi3_get_u16(b), (unsigned long)supi3_get_u32(b),
               (unsigned)p16[0], (unsigned)p16[1], (unsigned)p32[0], (unsigned)p32[1], (unsigned)p32[2],
               (unsigned)p32[3]);
        return;
    }
    default:
        bad_input("unknown op");
    }
    printf("%d", rc);
    print_bytes(out, n_out);
    printf(" ");
}

int main(void)
{
    static chip_t chip;
    for (;;) {
        supi3_t ctx;
        supi3_config_t cfg;
        long with_cd, with_irq, with_io, n_ops, k, j;
        if (!read_long(&with_cd)) {
            break;
        }
        if (!read_long(&with_irq) || !read_long(&with_io)) {
            bad_input("callback flags");
        }
        memset(&chip, 0, sizeof chip);
        read_stream(&chip.rx);
        read_stream(&chip.cd);
        read_stream(&chip.irq);
        read_stream(&chip.io);
        memset(&cfg, 0, sizeof cfg);
        cfg.xfer = chip_xfer;
        cfg.read_cd = with_cd ? chip_cd : NULL;
        cfg.read_irq = with_irq ? chip_irq : NULL;
        cfg.read_io = with_io ? chip_io : NULL;
        cfg.set_sas_init = chip_sas;
        cfg.user = &chip;
        memset(&ctx, 0x5A, sizeof ctx); /* garbage, as on a stack */
        if (supi3_init(&ctx, &cfg) != SUPI3_OK) {
            bad_input("supi3_init refused the configuration");
        }
        if (!read_long(&n_ops) || n_ops < 0 || n_ops > MAX_OPS) {
            bad_input("op count");
        }
        for (k = 0; k < n_ops; ++k) {
            long op, a[8];
            if (!read_long(&op)) {
                bad_input("op");
            }
            for (j = 0; j < 8; ++j) {
                if (!read_long(&a[j])) {
                    bad_input("op argument");
                }
            }
            run_op(&ctx, op, a);
        }
        printf("%lu", (unsigned long)chip.frames);
        for (k = 0; k < (long)chip.frames && k < MAX_FRAMES; ++k) {
            printf(" %u %d", (unsigned)chip.tx[k], chip.sr[k]);
        }
        printf(" %lu %lu %lu %lu\n", (unsigned long)chip.rx.used, (unsigned long)chip.cd.used,
               (unsigned long)chip.irq.used, (unsigned long)chip.io.used);
        fflush(stdout);
    }
    return 0;
}

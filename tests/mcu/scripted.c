/*
 * scripted.c - a firmware whose behaviour is data (tests/test_mcu_fuzz.py, MCU-59): fw_setup runs the script the
 * test wrote into fw_script before the first run, one step after the other, and keeps each step's result in fw_log.
 *
 * A step is four bytes: the operation and its arguments a, b, c (the OP_* codes, mirrored by test_mcu_fuzz.Op). Its
 * log entry is LOG_BYTES bytes: 1 (the step ran), the driver's error code (supi3_err_t as a byte, 0 = OK, or 1 for a
 * wait that timed out) and up to four result bytes (0 where a step has none). The script ends at OP_END or after
 * SCRIPT_STEPS steps. The driver calls are the SDK's (supi3.h); OP_RAW clocks one frame through the driver's own
 * transport, OP_SS_HIGH and OP_SS_CUT drive SPI1 and /SS directly (board.h) to break 3.4.2 on purpose. There is no
 * fw_isr: the board port never enables EXTI0, so the script's waits poll the pins and the core never sleeps until
 * the script has ended.
 *
 * fw_script is const (in flash): the reset handler copies .data and clears .bss before main, so RAM the host wrote
 * before the first run would be overwritten; the host writes the flash image as a programmer would (MCU-59).
 */
#include "board.h"
#include "fw_board.h"

#define SCRIPT_STEPS 48u
#define STEP_BYTES 4u
#define LOG_BYTES 6u
#define WAIT_STEP_US 4u       /* a wait's poll interval */
#define WAIT_POLLS_PER_UNIT 250u /* a wait of argument a polls at most (a + 1) * 250 times: (a + 1) ms */
#define LATCH_POLLS_PER_UNIT 10000u

enum {
    OP_END = 0,
    OP_INIT = 1,        /* supi3_initialize(a) */
    OP_CONFIG = 2,      /* supi3_configure(a, b) */
    OP_READ = 3,        /* supi3_read(a) */
    OP_WRITE = 4,       /* supi3_write(a, b) */
    OP_EXCHANGE = 5,    /* supi3_exchange(a, b) */
    OP_BLOCK = 6,       /* supi3_block_transfer(rd = a & 1, wr = a & 2, n = b, in[k] = c + 11h * k) */
    OP_IRQ_ENABLE = 7,  /* supi3_irq_enable(a) */
    OP_IRQ_SERVICE = 8, /* supi3_irq_service */
    OP_SAS_INIT = 9,    /* supi3_sas_init */
    OP_DELAY = 10,      /* board->delay_us(a) */
    OP_WAIT_IRQ = 11,   /* poll /IRQ every WAIT_STEP_US until low, at most (a + 1) ms */
    OP_POLL_IO = 12,    /* supi3_poll_io_window(a) */
    OP_RAW = 13,        /* one frame of byte a through the driver's transport (cfg.xfer) */
    OP_SS_HIGH = 14,    /* byte a clocked on SPI1 with /SS high (3.4.2: the chip ignores it) */
    OP_SS_CUT = 15,     /* byte a with /SS raised b SCLK periods and c spin units (4 core clocks each, c < 16)
                           after the DR write, b <= 8: a frame cut short (3.4.2) at any point of the byte, within
                           t2 of an SCLK edge too; r[0] the byte SPI1 received (MCU-74) */
    OP_LATCH = 16       /* poll the I/O pin without a pause until 1, at most (c + 1) * 10000 times, then spin a us
                           (a countdown of a us on the emulated core, as the bench's wait: delay_us lasts 4/3 of
                           its time there, MCU-11) and supi3_read(b): a read timed into the latch phase or beside it
                           (3.4.14) */
};

const volatile uint8_t fw_script[SCRIPT_STEPS * STEP_BYTES] = {OP_END, 0xA5u}; /* not all zero: kept in .rodata */
uint8_t fw_log[SCRIPT_STEPS * LOG_BYTES];
volatile uint32_t fw_log_steps;

#define PIN(n) (1u << (n))
#define SPI_BIT_CYCLES (2u << BOARD_SPI_BR) /* one SCLK period in core clocks (RM0008 25.5.1) */

static uint32_t pin(uint32_t number)
{
    return (GPIOA_IDR >> number) & 1u;
}

/* Poll a pin every WAIT_STEP_US until it reads `level`, at most (units + 1) ms: 0 when it did, 1 on time-out. */
static int wait_pin(fw_board_t *board, uint32_t number, uint32_t level, uint8_t units)
{
    uint32_t polls;
    for (polls = 0u; polls < (units + 1u) * WAIT_POLLS_PER_UNIT; ++polls) {
        if (pin(number) == level) {
            return 0;
        }
        board->delay_us(board->user, WAIT_STEP_US);
    }
    return 1;
}

/* A countdown of about `cycles` core clocks (board.c's busy wait: SUBS, BNE; 4 clocks an iteration, MCU-1). */
static void spin(uint32_t cycles)
{
    uint32_t n = cycles / 4u + 1u;
    __asm__ volatile("1: subs %0, %0, #1\n\tbne 1b" : "+l"(n) : : "cc");
}

static uint8_t spi_finish(void)
{
    uint8_t rx;
    while ((SPI1_SR & SPI_SR_RXNE) == 0u) {
    }
    rx = (uint8_t)SPI1_DR;
    while ((SPI1_SR & SPI_SR_BSY) != 0u) {
    }
    return rx;
}

static int step(supi3_t *chip, fw_board_t *board, const uint8_t *s, uint8_t *r)
{
    uint8_t in[5];
    uint8_t k;
    uint32_t polls;
    switch (s[0]) {
    case OP_INIT:
        return supi3_initialize(chip, (supi3_mode_t)s[1]);
    case OP_CONFIG:
        return supi3_configure(chip, s[1], s[2]);
    case OP_READ:
        return supi3_read(chip, s[1], &r[0]);
    case OP_WRITE:
        return supi3_write(chip, s[1], s[2]);
    case OP_EXCHANGE:
        return supi3_exchange(chip, s[1], s[2], &r[0]);
    case OP_BLOCK:
        for (k = 0u; k < sizeof in; ++k) {
            in[k] = (uint8_t)(s[3] + 0x11u * k);
        }
        return supi3_block_transfer(chip, s[1] & 1u, (s[1] >> 1) & 1u, (s[1] & 1u) ? r : NULL, in, s[2]);
    case OP_IRQ_ENABLE:
        return supi3_irq_enable(chip, s[1]);
    case OP_IRQ_SERVICE:
        return supi3_irq_service(chip, &r[0]);
    case OP_SAS_INIT:
        return supi3_sas_init(chip);
    case OP_DELAY:
        board->delay_us(board->user, s[1]);
        return 0;
    case OP_WAIT_IRQ:
        return wait_pin(board, BOARD_PIN_IRQ, 0u, s[1]);
    case OP_POLL_IO:
        return supi3_poll_io_window(chip, s[1], &r[0]);
    case OP_RAW:
        return chip->cfg.xfer(chip->cfg.user, s[1], &r[0], 1) == 0 ? SUPI3_OK : SUPI3_E_TRANSPORT;
    case OP_SS_HIGH:
        SPI1_DR = s[1];
        r[0] = spi_finish();
        return 0;
    case OP_SS_CUT:
        GPIOA_BRR = PIN(BOARD_PIN_SS);
        spin(SPI_BIT_CYCLES);                                     /* t1 */
        SPI1_DR = s[1];
        spin(s[2] * SPI_BIT_CYCLES + s[3] * 4u);                  /* b SCLK periods and c spin units */
        GPIOA_BSRR = PIN(BOARD_PIN_SS);
        r[0] = spi_finish();                                      /* the rest of the byte, /SS high */
        spin(2u * SPI_BIT_CYCLES);                                /* t6 max + t8 */
        return 0;
    case OP_LATCH:
        for (polls = 0u; pin(BOARD_PIN_IO) == 0u; ++polls) {
            if (polls == (s[3] + 1u) * LATCH_POLLS_PER_UNIT) {
                return 1;
            }
        }
        spin(s[1] * (BOARD_SYSCLK_HZ / 1000000u));
        return supi3_read(chip, s[2], &r[0]);
    default:
        return SUPI3_E_ARG;
    }
}

void fw_setup(supi3_t *chip, fw_board_t *board)
{
    uint32_t n;
    for (n = 0u; n < SCRIPT_STEPS && fw_script[n * STEP_BYTES] != OP_END; ++n) {
        uint8_t s[STEP_BYTES];
        uint8_t *r = &fw_log[n * LOG_BYTES];
        uint8_t k;
        for (k = 0u; k < STEP_BYTES; ++k) {
            s[k] = fw_script[n * STEP_BYTES + k];
        }
        r[1] = (uint8_t)step(chip, board, s, &r[2]);
        r[0] = 1u;
        fw_log_steps = n + 1u;
    }
}

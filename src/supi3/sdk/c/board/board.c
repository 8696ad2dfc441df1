/*
 * board.c - the SDK's port to the emulated SUPI 3 board (board.h): the C driver's transport on SPI1 and GPIOA,
 * /IRQ on EXTI0, a register-only busy wait, and main() running the board contract of examples/fw_board.h.
 *
 * main() sets the clocks, pins and SPI1 up, calls supi3_init() with the transport, then fw_setup(). A falling edge
 * of /IRQ enters EXTI0_IRQHandler: a firmware without fw_loop gets fw_isr() there (its main loop only sleeps,
 * WFI); with fw_loop, the handler only notes the edge and the main loop calls fw_isr() between two passes, as
 * fw_board.h promises ("never inside one"). The host reads and writes fw_board (inputs, outputs, cycles, error) by
 * its symbol.
 */
#include "board.h"
#include "fw_board.h"

void fw_setup(supi3_t *chip, fw_board_t *board);
void fw_isr(supi3_t *chip, fw_board_t *board) __attribute__((weak));
void fw_loop(supi3_t *chip, fw_board_t *board) __attribute__((weak));
void EXTI0_IRQHandler(void);
int main(void);

supi3_t fw_chip;
fw_board_t fw_board;
static volatile uint32_t irq_noted;

#define PIN(n) (1u << (n))
/* Table 3-7 at 500 kbit/s (they halve at 2 Mbit/s): t2 min, t6 max, t8 min in ns; CPU clocks for ns, rounded up. */
#define BOARD_T2_NS 375u
#define BOARD_T6_MAX_NS 375u
#define BOARD_T8_NS 125u
#define BOARD_CYCLES_PER_US ((BOARD_SYSCLK_HZ + 999999u) / 1000000u)
#define BOARD_NS_CYCLES(ns) (((ns) * BOARD_CYCLES_PER_US + 999u) / 1000u)

/* Busy wait: a countdown loop of `n` >= 1 iterations of two 16-bit instructions (SUBS, BNE) that takes at least
 * BOARD_SPIN_CYCLES clocks an iteration on either core (Cortex-M3: SUBS 1, a taken branch 2 or more; Cortex-M0:
 * 1 + 3). Registers only: safe in a handler and in the code it interrupts, SysTick stays the firmware's. The emulator
 * counts the iterations without running them (MCU-11). Every count is a compile-time constant or a product with one:
 * no run-time division, which the Cortex-M0 (no divide instruction) would make a call of __aeabi_uidiv of about 850
 * clocks (MCU-62). */
#define BOARD_SPIN_CYCLES 3u
/* Iterations for at least `cycles` clocks (a constant expression). */
#define BOARD_SPINS(cycles) ((cycles) / BOARD_SPIN_CYCLES + 1u)
/* Iterations per microsecond, rounded up: delay_us(n) lasts at least n us. */
#define BOARD_SPINS_PER_US ((BOARD_CYCLES_PER_US + BOARD_SPIN_CYCLES - 1u) / BOARD_SPIN_CYCLES)
static void board_spin(uint32_t n)
{
    __asm__ volatile("1: subs %0, %0, #1\n\tbne 1b" : "+l"(n) : : "cc");
}

/* At least `us` microseconds: us * BOARD_SPINS_PER_US + 1 iterations (the product wraps above 2^32 /
 * BOARD_SPINS_PER_US us, 268 s at 48 MHz). */
static void board_delay_us(void *user, uint32_t us)
{
    (void)user;
    board_spin(us * BOARD_SPINS_PER_US + 1u);
}

/* One byte, one /SS frame (supi3.h transport contract; RM0008 25.3.5, full-duplex master sequence). Table 3-7 at
 * 500 kbit/s, the slower rate's longer times: /SS rises t2 after the last SCLK edge (BSY falls with it), and stays
 * high until C/D has settled (t6 max) plus t8 before the next frame may begin. */
static int board_xfer(void *user, uint8_t tx, uint8_t *rx, int s_r)
{
    (void)user;
    if (FW_MODE == SUPI3_MODE_INTEL) { /* S/R before /SS falls (t10); receiving, MOSI sends FFh (MCU-18) */
        if (s_r != 0) {
            GPIOB_BSRR = PIN(BOARD_PIN_SR);
        } else {
            GPIOB_BRR = PIN(BOARD_PIN_SR);
            tx = 0xFFu;
        }
    }
    GPIOA_BRR = PIN(BOARD_PIN_SS);
    SPI1_DR = tx;
    while ((SPI1_SR & SPI_SR_RXNE) == 0u) {
    }
    *rx = (uint8_t)SPI1_DR;
    while ((SPI1_SR & SPI_SR_BSY) != 0u) {
    }
    board_spin(BOARD_SPINS(BOARD_NS_CYCLES(BOARD_T2_NS)));
    GPIOA_BSRR = PIN(BOARD_PIN_SS);
    board_spin(BOARD_SPINS(BOARD_NS_CYCLES(BOARD_T6_MAX_NS + BOARD_T8_NS)));
    return 0;
}

static int board_pin(int *level, uint32_t pin)
{
    *level = (GPIOA_IDR & PIN(pin)) != 0u;
    return 0;
}

static int board_read_irq(void *user, int *level)
{
    (void)user;
    return board_pin(level, BOARD_PIN_IRQ);
}

static int board_read_cd(void *user, int *level)
{
    (void)user;
    return board_pin(level, BOARD_PIN_CD);
}

static int board_read_io(void *user, int *level)
{
    (void)user;
    return board_pin(level, BOARD_PIN_IO);
}

static void board_drive(uint32_t pin, int high)
{
    if (high) {
        GPIOA_BSRR = PIN(pin);
    } else {
        GPIOA_BRR = PIN(pin);
    }
}

static int board_set_sas_init(void *user, int level)
{
    (void)user;
    board_drive(BOARD_PIN_SAS_INIT, level);
    return 0;
}

static int board_set_stat_err(void *user, int active)
{
    (void)user;
    board_drive(BOARD_PIN_STAT_ERR, !active); /* /StatErr is active low (3.6.2) */
    return 0;
}

/* The edge latch fw_board.h asks for: EXTI line 1's pending bit caught the falling edge of /ModAck (3.6.2). */
static int board_mod_ack_seen(void *user, int *seen)
{
    (void)user;
    *seen = (EXTI_PR & PIN(BOARD_PIN_MODACK)) != 0u;
    EXTI_PR = PIN(BOARD_PIN_MODACK);
    return 0;
}

static void board_init(void)
{
    RCC_APB2ENR |= RCC_APB2ENR_AFIOEN | RCC_APB2ENR_IOPAEN | RCC_APB2ENR_IOPBEN | RCC_APB2ENR_SPI1EN;
    GPIOA_BSRR = PIN(BOARD_PIN_SS) | PIN(BOARD_PIN_STAT_ERR); /* /SS and /StatErr idle high */
    GPIOA_BRR = PIN(BOARD_PIN_SAS_INIT);
    GPIOA_CRL = (GPIO_CFG_INPUT_FLOATING << (4u * BOARD_PIN_IRQ)) | (GPIO_CFG_INPUT_FLOATING << (4u * BOARD_PIN_CD)) |
                (GPIO_CFG_INPUT_FLOATING << (4u * BOARD_PIN_IO)) | (GPIO_CFG_OUTPUT_PP_2MHZ << (4u * BOARD_PIN_SAS_INIT)) |
                (GPIO_CFG_OUTPUT_PP_2MHZ << (4u * BOARD_PIN_SS)) | (GPIO_CFG_AF_PP_50MHZ << (4u * BOARD_PIN_SCK)) |
                (GPIO_CFG_INPUT_FLOATING << (4u * BOARD_PIN_MISO)) | (GPIO_CFG_AF_PP_50MHZ << (4u * BOARD_PIN_MOSI));
    GPIOA_CRH = GPIO_CFG_OUTPUT_PP_2MHZ << (4u * (BOARD_PIN_STAT_ERR - 8u));
    /* Mode 3 (CPOL 1, CPHA 1: SCLK idles high, the chip samples on the rising edge, UP-5), MSB first, master,
     * software slave select (SSM, SSI: /SS is the GPIO above). */
    SPI1_CR1 = SPI_CR1_CPHA | SPI_CR1_CPOL | SPI_CR1_MSTR | (BOARD_SPI_BR << SPI_CR1_BR_POS) | SPI_CR1_SSI | SPI_CR1_SSM |
               (FW_MODE == SUPI3_MODE_INTEL ? SPI_CR1_LSBFIRST : 0u); /* Intel: LSB first (UP-6) */
    SPI1_CR1 |= SPI_CR1_SPE;
    GPIOB_BSRR = PIN(BOARD_PIN_SR); /* S/R idles high: the uP sends */
    GPIOB_CRL = (GPIO_CFG_INPUT_FLOATING << (4u * BOARD_PIN_MODACK)) | (GPIO_CFG_OUTPUT_PP_2MHZ << (4u * BOARD_PIN_SR));
    AFIO_EXTICR1 = AFIO_EXTICR_PB << (4u * BOARD_PIN_MODACK); /* EXTI0 on PA0, EXTI1 on PB1 */
    EXTI_FTSR |= PIN(BOARD_PIN_IRQ) | PIN(BOARD_PIN_MODACK);
    EXTI_IMR |= PIN(BOARD_PIN_IRQ) | PIN(BOARD_PIN_MODACK); /* EXTI1's NVIC line stays disabled: a latch only */
}

void EXTI0_IRQHandler(void)
{
    EXTI_PR = PIN(BOARD_PIN_IRQ);
    if (fw_loop == 0) {
        fw_isr(&fw_chip, &fw_board);
    } else {
        irq_noted = 1u;
    }
}

int main(void)
{
    supi3_config_t cfg;
    board_init();
    cfg.user = 0;
    cfg.frame_gap_us = 0u;
    cfg.xfer = board_xfer;
    cfg.delay_us = board_delay_us;
    cfg.read_irq = board_read_irq;
    cfg.read_cd = board_read_cd;
    cfg.read_io = board_read_io;
    cfg.set_sas_init = board_set_sas_init;
    fw_board.delay_us = board_delay_us;
    fw_board.set_stat_err = board_set_stat_err;
    fw_board.mod_ack_seen = board_mod_ack_seen;
    (void)fw_note(&fw_board, supi3_init(&fw_chip, &cfg));
    fw_setup(&fw_chip, &fw_board);
    if (fw_isr != 0) {
        NVIC_ISER0 = PIN(BOARD_EXTI0_IRQN);
    }
    for (;;) {
        if (fw_loop == 0) {
            __asm__ volatile("wfi");
            continue;
        }
        fw_loop(&fw_chip, &fw_board);
        if (irq_noted != 0u && fw_isr != 0) {
            irq_noted = 0u;
            fw_isr(&fw_chip, &fw_board);
        }
    }
}

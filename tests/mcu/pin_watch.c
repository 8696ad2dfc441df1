/*
 * pin_watch.c - GPIOA's inputs read at every point of a master cycle (tests/test_mcu_fastbyte.py, MCU-66): the
 * handler serves /IRQ by the driver's routine (IDR before and after IRQ_EVT), then runs raw frames for longer than a
 * 2 Mbit/s cycle, reading GPIOA_IDR (/IRQ, C/D, the I/O access pin) right after each /SS rise (inside t6 max: C/D as
 * before the frame) and again at waits that step through the cycle's bus events (the I/O access bit set, the latch
 * phase, the cycle's end, where /IRQ falls while the handler runs), and OUT0 (a data register: in the latch phase
 * too, 3.4.14), and clearing EXTI0's pending bit at each of those times and then for a while without any other
 * access; then it serves /IRQ again, which fell while the loops ran (the lost edge of FW-22: IRQ_EVT read with /IRQ low). Each IDR and ODR value and each service's events land in `seen`, which the test compares
 * between the boards. RISING = 1 enables EXTI0's rising trigger (each rise of /IRQ pends the handler again) and
 * leaves EXTI0's pending bit to the handler's entry.
 */
#include "board.h"
#include "fw_board.h"

#define SS (1u << BOARD_PIN_SS)
#define READ(address) (0x80u | (address))
#define GPIOA_ODR REG32(0x4001080Cu)
#define EXTI_RTSR REG32(0x40010408u)
#define ROUNDS 8u
#define SEEN 128u
#define CLEARS 300u
#ifndef RISING
#define RISING 0u
#endif

volatile uint32_t seen[SEEN];
static uint32_t at;
static uint32_t shift;

static void spin(uint32_t loops)
{
    for (volatile uint32_t k = 0u; k < loops; k++) {
    }
}

static void note(uint32_t value)
{
    seen[at] = value;
    at = (at + 1u) % SEEN;
}

/* One byte in its /SS frame, GPIOA's IDR read at once after /SS rose (C/D not yet settled) and after `after` loops. */
static uint8_t byte(uint8_t tx, uint32_t after)
{
    GPIOA_BRR = SS;
    SPI1_DR = tx;
    while ((SPI1_SR & SPI_SR_RXNE) == 0u) {
    }
    uint8_t rx = (uint8_t)SPI1_DR;
    while ((SPI1_SR & SPI_SR_BSY) != 0u) {
    }
    spin(2u);
    GPIOA_BSRR = SS;
    note(GPIOA_IDR);
    if (!RISING) {
        EXTI_PR = 1u << BOARD_PIN_IRQ; /* a fall of /IRQ before it is forgotten (served by the last service) */
    }
    spin(after);
    note(GPIOA_IDR ^ (GPIOA_ODR << 16));
    return rx;
}

void fw_setup(supi3_t *chip, fw_board_t *board)
{
    if (fw_note(board, supi3_initialize(chip, FW_MODE)) != SUPI3_OK ||
        fw_note(board, supi3_configure(chip, 0x83u, 0x03u)) != SUPI3_OK) {
        return;
    }
    (void)fw_note(board, supi3_irq_enable(chip, SUPI3_IRQ_EN_VALID_MSK));
    if (RISING) {
        EXTI_RTSR |= 1u << BOARD_PIN_IRQ;
    }
}

void fw_isr(supi3_t *chip, fw_board_t *board)
{
    uint8_t events = 0u;
    (void)fw_note(board, supi3_irq_service(chip, &events));
    note(events);
    board->cycles++;
    shift = (shift + 7u) % 23u; /* the waits step through the cycle from one handler to the next */
    for (uint32_t k = 0u; k < ROUNDS; k++) {
        (void)byte(READ(SUPI3_OUT0_ADDR), 4u + shift + k % 5u);
        board->outputs[0] = byte(0u, 9u + (k * shift) % 17u);
    }
    for (uint32_t k = 0u; k < (RISING ? 0u : CLEARS); k++) { /* EXTI0's pending bit cleared: across a bus event */
        EXTI_PR = 1u << BOARD_PIN_IRQ;
    }
    (void)fw_note(board, supi3_irq_service(chip, &events));
    note(events);
}

/*
 * frame_edges.c - raw µP interface frames across every boundary of the board's native frames
 * (tests/test_mcu_fastbyte.py, MCU-51): plain command and data frames, and each kind the native frames leave to
 * Python: a read of IRQ_EVT (read-clear), writes of SET and ID, a byte clocked with /SS high, /SS falling too soon
 * after it rose (Table 3-7 t8), /SS rising too soon after the last SCLK edge (t2), a frame of two bytes, a frame of no
 * byte, a reserved command byte, a byte whose DR is not read, SPI mode 0, LSB first, a long wait inside
 * a frame (bus events in it), /StatErr changed in the write of an /SS edge, SAS_INIT, and data registers read and
 * written whenever the handler runs (in the latch phase too, 3.4.14). Every frame is raw GPIOA and SPI1 accesses, as
 * board.c's transport makes them.
 */
#include "board.h"
#include "fw_board.h"

#define SS (1u << BOARD_PIN_SS)
#define SAS (1u << BOARD_PIN_SAS_INIT)
#define STATERR (1u << BOARD_PIN_STAT_ERR)
#define SETTLE 60u /* cycles after /SS rises: more than t6 (max) + t8 at 500 kbit/s (24 cycles at 48 MHz) */
#define READ(address) (0x80u | (address))
#define WRITE(address) (0x40u | (address))
#define GAP 1500u /* cycles: a 2 Mbit/s cycle's time at 48 MHz */
#define ROUNDS 9u
#ifndef CLOCK_OFF
#define CLOCK_OFF 0u
#endif /* handlers that run the edges; later ones serve the data cycle only */

static void wait(uint32_t cycles)
{
    for (volatile uint32_t k = 0u; k < cycles / 4u; k++) {
    }
}

/* One byte in one /SS frame: `low` = drive /SS; `t2` = wait before /SS rises; `after` = wait after it rose. */
static uint8_t frame(uint8_t tx, int low, uint32_t t2, uint32_t after)
{
    if (low) {
        GPIOA_BRR = SS;
    }
    SPI1_DR = tx;
    while ((SPI1_SR & SPI_SR_RXNE) == 0u) {
    }
    uint8_t rx = (uint8_t)SPI1_DR;
    while ((SPI1_SR & SPI_SR_BSY) != 0u) {
    }
    wait(t2);
    if (low) {
        GPIOA_BSRR = SS;
    }
    wait(after);
    return rx;
}

static uint8_t access(uint8_t command, uint8_t data)
{
    (void)frame(command, 1, 40u, SETTLE);
    return frame(data, 1, 40u, SETTLE);
}

static uint32_t round_number;

static void edges(fw_board_t *board)
{
    uint32_t n = round_number++;
    board->outputs[0] = access(READ(7u), 0u);       /* PCMD: plain */
    (void)access(WRITE(14u), SUPI3_IRQ_EN_VALID_MSK); /* IRQ_EN: plain */
    board->outputs[1] = access(READ(14u), 0u);      /* IRQ_EVT: read-clear */
    (void)access(WRITE(0u), (uint8_t)n);            /* IN0: a data register */
    board->outputs[2] = access(READ(0u), 0u);       /* OUT0: a data register */
    (void)frame(0x55u, 0, 40u, SETTLE);             /* a byte with /SS high */
    GPIOA_BRR = SS;                                 /* /SS falls again at once after it rose: t8 */
    (void)frame(READ(7u), 0, 40u, 0u);
    GPIOA_BSRR = SS;
    GPIOA_BRR = SS;
    (void)frame(0u, 0, 40u, 0u);
    GPIOA_BSRR = SS;
    wait(SETTLE);
    (void)frame(READ(7u), 1, 40u, SETTLE);
    GPIOA_BRR = SS;                                 /* /SS rises at once: t2 */
    SPI1_DR = 0u;
    while ((SPI1_SR & SPI_SR_RXNE) == 0u) {
    }
    (void)SPI1_DR;
    while ((SPI1_SR & SPI_SR_BSY) != 0u) {
    }
    GPIOA_BSRR = SS;
    wait(SETTLE);
    GPIOA_BRR = SS;                                 /* two bytes in one frame */
    (void)frame(READ(7u), 0, 40u, 0u);
    (void)frame(0u, 0, 40u, 0u);
    GPIOA_BSRR = SS;
    wait(SETTLE);
    GPIOA_BRR = SS;                                 /* a frame of no byte */
    wait(SETTLE);
    GPIOA_BSRR = SS;
    wait(SETTLE);
    GPIOA_BRR = SS;                                 /* long between /SS falling and the byte: bus events */
    wait(GAP);
    (void)frame(READ(7u), 0, 40u, 0u);
    GPIOA_BSRR = SS;
    wait(SETTLE);
    (void)frame(0u, 1, GAP, SETTLE);                /* and between the byte and /SS rising */
    (void)access(WRITE(0u), (uint8_t)(n + 0x40u));  /* IN0, then a wait a cycle's end may fall in */
    (void)frame(READ(0u), 1, 40u, GAP);             /* and before /SS falls for OUT0's data byte */
    board->outputs[2] ^= frame(0u, 1, 40u, SETTLE);
    GPIOA_BRR = SS;                                 /* a byte whose DR is not read, SR read after it in the model */
    SPI1_DR = READ(7u);
    wait(SETTLE);
    (void)SPI1_CR1;
    while ((SPI1_SR & SPI_SR_BSY) != 0u) {
    }
    wait(40u);
    GPIOA_BSRR = SS;
    wait(SETTLE);
    (void)frame(0u, 1, 40u, SETTLE);                /* its data byte reads the byte before (RXNE was still set) */
    (void)SPI1_DR;                                  /* the data byte's: the receive buffer empty again */
    (void)access(0x30u | READ(7u), 0u);             /* reserved command bits */
    if (n == 0u) {
        (void)access(WRITE(13u), 0x83u);            /* SET, ID: configuration (3.4.3) */
        (void)access(WRITE(12u), 0x03u);
    }
    GPIOA_BRR = SS | STATERR;                       /* /StatErr lowered with /SS's fall, raised with its rise */
    (void)frame(READ(7u), 0, 40u, 0u);
    GPIOA_BSRR = SS | STATERR;
    wait(SETTLE);
    (void)frame(0u, 1, 40u, SETTLE);
    if (n == 1u) { /* between bytes (RM0008 25.5.1 allows it): SPI mode 0, then LSB first (the chip sees E1h, 00h) */
        uint32_t cr1 = SPI1_CR1;
        SPI1_CR1 = cr1 & ~(SPI_CR1_CPOL | SPI_CR1_CPHA);
        (void)access(READ(7u), 0u);
        SPI1_CR1 = cr1 | SPI_CR1_LSBFIRST;
        (void)access(READ(7u), 0u);
        SPI1_CR1 = cr1;
    }
    if (n == 2u) { /* SAS_INIT, then the initialization byte again */
        GPIOA_BSRR = SAS;
        wait(SETTLE);
        GPIOA_BRR = SAS;
        wait(SETTLE);
        (void)frame(0x00u, 1, 40u, SETTLE);
    }
    board->outputs[3] = access(READ(1u), 0u);       /* OUT1 */
}

void fw_setup(supi3_t *chip, fw_board_t *board)
{
    if (fw_note(board, supi3_initialize(chip, FW_MODE)) != SUPI3_OK ||
        fw_note(board, supi3_configure(chip, 0x83u, 0x03u)) != SUPI3_OK) {
        return;
    }
    (void)access(WRITE(14u), SUPI3_IRQ_EN_VALID_MSK);
    edges(board);
    if (CLOCK_OFF) { /* SPI1's clock turned off (RCC_APB2ENR, RM0008 7.3.7), then a frame: the board stops (MCU-7) */
        RCC_APB2ENR &= ~(1u << 12);
        (void)access(READ(7u), 0u);
    }
}

void fw_isr(supi3_t *chip, fw_board_t *board)
{
    (void)chip;
    if (round_number < ROUNDS) {
        edges(board);
        return;
    }
    (void)access(READ(14u), 0u); /* the plain service: IRQ_EVT, IN0, OUT0 */
    (void)access(WRITE(0u), board->inputs[0]);
    board->outputs[0] = access(READ(0u), 0u);
}

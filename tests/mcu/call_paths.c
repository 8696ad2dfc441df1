/*
 * call_paths.c - one interface rule broken at one PC from several call stacks (tests/test_mcu_fastbyte.py, MCU-83):
 * stray_byte() clocks a byte with /SS high (the board's 3.4.2 lint, at its SPI1_DR write), called through inner()
 * from via_a() and from via_b() (the same SP and LR at the write, inner()'s saved return address differs), and
 * directly (another SP and LR, the deeper stack words still those of the last call through inner()), from two call
 * sites of fw_setup() (only LR differs) and at the bottom of nested() two calls deep, then one, from one call site
 * (only SP differs: the deeper call's frames still in memory). A kept call stack must be taken again only when everything its unwinding
 * read is the same.
 */
#include "board.h"
#include "fw_board.h"

#define ROUNDS 3u

volatile uint32_t path_seen; /* a store after each call: no call here is a tail call */
volatile uint32_t deepest = 2u;

__attribute__((noinline)) static void stray_byte(void)
{
    SPI1_DR = 0x00u;
    while ((SPI1_SR & SPI_SR_RXNE) == 0u) {
    }
    (void)SPI1_DR;
    while ((SPI1_SR & SPI_SR_BSY) != 0u) {
    }
}

__attribute__((noinline)) static void inner(void)
{
    stray_byte();
    path_seen = 1u;
}

__attribute__((noinline)) static void via_a(void)
{
    inner();
    path_seen = 2u;
}

__attribute__((noinline)) static void via_b(void)
{
    inner();
    path_seen = 3u;
}

__attribute__((noinline)) static void nested(uint32_t depth)
{
    if (depth != 0u) {
        nested(depth - 1u);
    } else {
        stray_byte();
    }
    path_seen = 4u + depth;
}

void fw_setup(supi3_t *chip, fw_board_t *board)
{
    (void)chip;
    (void)board;
    for (uint32_t round = 0u; round < ROUNDS; round++) {
        via_a();
        via_b();
        stray_byte();
        inner();
        for (uint32_t depth = deepest; depth != 0u; depth--) { /* one call site (a count not known: no unrolling) */
            nested(depth);
        }
        stray_byte();
        path_seen = 8u;
    }
    path_seen = 0u;
}

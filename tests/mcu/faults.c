/*
 * faults.c - a firmware that goes wrong on request (tests/test_mcu_core.py): the test sets `scenario` while the
 * main loop runs. 1: read of unmapped memory (a precise bus fault), 2: an endless loop, 3: the SysTick interrupt
 * without a handler (Default_Handler loops in handler mode), 4: an undefined instruction. -DFAULTS_SCENARIO=n starts
 * with scenario n (tests/test_cli_firmware.py).
 */
#include "board.h"
#include "fw_board.h"

#ifndef FAULTS_SCENARIO
#define FAULTS_SCENARIO 0u
#endif

volatile uint32_t scenario = FAULTS_SCENARIO;
volatile uint32_t spins;

void fw_setup(supi3_t *chip, fw_board_t *board)
{
    (void)chip;
    (void)board;
}

void fw_loop(supi3_t *chip, fw_board_t *board)
{
    (void)chip;
    (void)board;
    switch (scenario) {
    case 1u:
        spins = REG32(0x30000000u);
        break;
    case 2u:
        for (;;) {
            spins++;
        }
    case 3u:
        SYST_RVR = 100u;
        SYST_CVR = 0u;
        SYST_CSR = SYST_CSR_ENABLE | SYST_CSR_CLKSOURCE | 2u; /* TICKINT */
        scenario = 0u;
        break;
    case 4u:
        __asm__ volatile(".short 0xde00"); /* UDF #0 */
        break;
    default:
        break;
    }
}

/*
 * late_irq.c - tests/test_mcu_tailchain.py (MCU-81): an EXTI0 handler that serves the "valid data cycle" event
 * (IRQ_EVT read: /IRQ rises, 3.4.7), then busy-waits hold_us. A wait longer than the rest of a master cycle lets the
 * next cycle's event make /IRQ fall while the handler runs (after its PR write, board.c): EXTI0's line to the NVIC
 * rises while EXTI0 is active, so it is pending at the return and the core tail-chains into it. With clear_late the
 * handler writes PR again after the wait: the line falls before the return, but the NVIC latched its rising edge (a
 * pulse while active), so EXTI0 is still pending and chained. hold_us and clear_late are in RAM: the test sets them
 * between runs (the start-up code clears them). The chip is set up as digital_io.c's (one word each way).
 *
 * With tick_reload set, the handler's next entry also starts SysTick (every tick_reload + 1 core cycles, its handler
 * counting ticks) with the priorities exti0_priority and tick_priority (the upper nibble counts on the STM32): a tick
 * that preempts the handler, waits for it or tail-chains after it (MCU-86's returns with SysTick about).
 */
#include "board.h"
#include "fw_board.h"

volatile uint32_t hold_us = 0u;
volatile uint32_t clear_late = 0u;
volatile uint32_t tick_reload = 0u;
volatile uint32_t exti0_priority = 0u;
volatile uint32_t tick_priority = 0u;
volatile uint32_t ticks = 0u;

#define NVIC_IPR1 REG32(0xE000E404u) /* IRQ 4 to 7, IRQ 6 (EXTI0) in bits 23:16 */
#define SCB_SHPR3 REG32(0xE000ED20u) /* SysTick's priority in bits 31:24 */

void SysTick_Handler(void)
{
    ticks++;
}

static void start_tick(void)
{
    if (tick_reload == 0u || (SYST_CSR & SYST_CSR_ENABLE) != 0u) {
        return;
    }
    NVIC_IPR1 = (NVIC_IPR1 & ~(0xFFu << 16)) | ((exti0_priority & 0xFFu) << 16); /* word accesses: ARMv6-M too */
    SCB_SHPR3 = (SCB_SHPR3 & 0x00FFFFFFu) | ((tick_priority & 0xFFu) << 24);
    SYST_RVR = tick_reload;
    SYST_CVR = 0u;
    SYST_CSR = SYST_CSR_ENABLE | (1u << 1) | SYST_CSR_CLKSOURCE; /* TICKINT: the exception at each wrap */
}

void fw_setup(supi3_t *chip, fw_board_t *board)
{
    if (fw_note(board, supi3_initialize(chip, FW_MODE)) != SUPI3_OK) {
        return;
    }
    if (fw_note(board, supi3_configure(chip, 0x83u, 0x03u)) != SUPI3_OK) { /* digital_io.c's SET and ID code */
        return;
    }
    (void)fw_note(board, supi3_irq_enable(chip, SUPI3_IRQ_EN_VALID_MSK));
}

void fw_isr(supi3_t *chip, fw_board_t *board)
{
    uint8_t events = 0u;
    (void)fw_note(board, supi3_irq_service(chip, &events));
    board->cycles++;
    start_tick();
    board->delay_us(board->user, hold_us);
    if (clear_late != 0u) {
        EXTI_PR = 1u << BOARD_PIN_IRQ;
    }
}

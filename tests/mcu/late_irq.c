/*
 * late_irq.c - tests/test_mcu_tailchain.py (MCU-81): an EXTI0 handler that serves the "valid data cycle" event
 * (IRQ_EVT read: /IRQ rises, 3.4.7), then busy-waits hold_us. A wait longer than the rest of a master cycle lets the
 * next cycle's event make /IRQ fall while the handler runs (after its PR write, board.c): EXTI0's line to the NVIC
 * rises while EXTI0 is active, so it is pending at the return and the core tail-chains into it. With clear_late the
 * handler writes PR again after the wait: the line falls before the return, but the NVIC latched its rising edge (a
 * pulse while active), so EXTI0 is still pending and chained. hold_us and clear_late are in RAM: the test sets them
 * between runs (the start-up code clears them). The chip is set up as digital_io.c's (one word each way).
 */
#include "board.h"
#include "fw_board.h"

volatile uint32_t hold_us = 0u;
volatile uint32_t clear_late = 0u;

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
    board->delay_us(board->user, hold_us);
    if (clear_late != 0u) {
        EXTI_PR = 1u << BOARD_PIN_IRQ;
    }
}

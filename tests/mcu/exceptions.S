@ exceptions.S - exception entry and return on the emulated core (tests/test_mcu_core.py).
@ Thumb-1 only, so that it runs on the Cortex-M0 and the Cortex-M3. IRQ 0 (priority 80h) pends IRQ 1 (priority
@ 40h), which preempts it; each handler records its SP and LR, and shifts its digit into `order`: 1 = IRQ 0
@ entered, 2 = IRQ 1 ran, 3 = IRQ 0 resumed after IRQ 1. Back in thread mode the code stores R0-R3, R12 and SP
@ into `after` (the handlers clobbered R0-R3: unstacking restores them).
    .syntax unified
    .thumb

    .section .isr_vector,"a"
    .word _estack
    .word Reset_Handler
    .rept 14
    .word Default_Handler
    .endr
    .word Irq0_Handler
    .word Irq1_Handler

    .bss
    .align 2
    .global seen0_sp, seen0_lr, seen1_sp, seen1_lr, order, after
seen0_sp: .space 4
seen0_lr: .space 4
seen1_sp: .space 4
seen1_lr: .space 4
order: .space 4
after: .space 24

    .text
    .thumb_func
    .global Reset_Handler
Reset_Handler:
    ldr r0, =0xE000E400     @ NVIC_IPR0
    movs r1, #0x80
    strb r1, [r0]
    movs r1, #0x40
    strb r1, [r0, #1]
    ldr r0, =0xE000E100     @ NVIC_ISER0: IRQ 0 and IRQ 1
    movs r1, #3
    str r1, [r0]
    ldr r0, =0xA0A0A0A0
    ldr r1, =0xA1A1A1A1
    ldr r2, =0xA2A2A2A2
    ldr r3, =0xA3A3A3A3
    ldr r4, =0xC0C0C0C0
    mov r12, r4
    .global sleep1
sleep1:
    wfi
    .global resume1
resume1:
    ldr r4, =after
    str r0, [r4]
    str r1, [r4, #4]
    str r2, [r4, #8]
    str r3, [r4, #12]
    mov r5, r12
    str r5, [r4, #16]
    mov r5, sp
    str r5, [r4, #20]
    .global sleep2
sleep2:
    wfi
    b sleep2

    .thumb_func
    .global Irq0_Handler
Irq0_Handler:
    mov r0, sp
    ldr r1, =seen0_sp
    str r0, [r1]
    mov r0, lr
    ldr r1, =seen0_lr
    str r0, [r1]
    ldr r1, =order
    ldr r0, [r1]
    lsls r0, r0, #4
    adds r0, r0, #1
    str r0, [r1]
    ldr r0, =0xE000E200     @ NVIC_ISPR0: pend IRQ 1
    movs r1, #2
    str r1, [r0]
    b irq0_resumed          @ ends the block: the interrupt is taken at a block boundary (MCU-1)
    .global irq0_resumed
irq0_resumed:
    ldr r1, =order
    ldr r0, [r1]
    lsls r0, r0, #4
    adds r0, r0, #3
    str r0, [r1]
    movs r0, #0
    movs r1, #0
    movs r2, #0
    movs r3, #0
    bx lr

    .thumb_func
    .global Irq1_Handler
Irq1_Handler:
    mov r0, sp
    ldr r1, =seen1_sp
    str r0, [r1]
    mov r0, lr
    ldr r1, =seen1_lr
    str r0, [r1]
    ldr r1, =order
    ldr r0, [r1]
    lsls r0, r0, #4
    adds r0, r0, #2
    str r0, [r1]
    bx lr

    .thumb_func
    .global Default_Handler
Default_Handler:
    b .
    .ltorg

@ peripheral_pc.S - a read and a write of each word in a table of peripheral addresses, each inside its block
@ (tests/test_mcu_exactpc.py, MCU-1, MCU-87). Thumb-1: both cores. For each address: `ldr r2, [r1]` at `read_at`
@ and `str r2, [r1]` at `write_at`, neither the first instruction of its block, so a peripheral callback sees their PC
@ only if unicorn restored it (a memory hook over the address). The thread ends in `b .` at `done`.
    .syntax unified
    .thumb

    .section .isr_vector,"a"
    .word _estack
    .word Reset_Handler
    .rept 14
    .word Default_Handler
    .endr

    .text
    .thumb_func
    .global Reset_Handler
Reset_Handler:
    ldr r4, =addresses
    ldr r5, =addresses_end
next:
    cmp r4, r5
    beq done
    ldr r1, [r4]
    adds r4, #4
    b access                @ a block of its own
access:
    nop
    .global read_at
read_at:
    ldr r2, [r1]
    nop
    .global write_at
write_at:
    str r2, [r1]
    b next
    .global done
done:
    b .

    .thumb_func
    .global Default_Handler
Default_Handler:
    b .

    .align 2
    .global addresses
addresses:                  @ the first and last word of each range the test maps, in the order it maps them
    .word 0x40010800, 0x40010BFC    @ GPIOA
    .word 0x40010C00, 0x40010FFC    @ GPIOB
    .word 0x40010000, 0x400103FC    @ AFIO
    .word 0x40010400, 0x400107FC    @ EXTI
    .word 0x40013000, 0x400133FC    @ SPI1
    .word 0x40021000, 0x400213FC    @ RCC
    .word 0x40011400, 0x400117FC    @ apart from the others until the next is mapped
    .word 0x40011000, 0x400113FC    @ between GPIOB and the one before: joins both runs
addresses_end:

@ idle_tick.S - a thread-mode `b .` woken by SysTick (tests/test_mcu_board.py, MCU-4). Thumb-1: both cores.
@ SysTick every 4800 core clocks (100 µs at 48 MHz: RVR = 4799, CSR = ENABLE | TICKINT | CLKSOURCE); its handler
@ counts the wraps in `ticks` (five instructions) and returns to the `b .` at `idle`, the only code of the thread
@ after its nine set-up instructions.
@ With -DHANG=1 SysTick's vector is Default_Handler's, a `b .` in handler mode: a hang.
    .syntax unified
    .thumb

    .section .isr_vector,"a"
    .word _estack
    .word Reset_Handler
    .rept 13
    .word Default_Handler
    .endr
#ifdef HANG
    .word Default_Handler
#else
    .word SysTick_Handler
#endif

    .bss
    .align 2
    .global ticks
ticks: .space 4

    .text
    .thumb_func
    .global Reset_Handler
Reset_Handler:
    ldr r0, =0xE000E014     @ SYST_RVR
    ldr r1, =4799
    str r1, [r0]
    ldr r0, =0xE000E010     @ SYST_CSR
    movs r1, #7
    str r1, [r0]
    b 1f                    @ the SysTick write stops the core at this block's end: the next run starts at 1
1:
    movs r2, #0
    b idle                  @ into the loop within a run, as a firmware's main falls into its `for (;;) {}`
    .global idle
idle:
    b .

    .thumb_func
    .global SysTick_Handler
SysTick_Handler:
    ldr r0, =ticks
    ldr r1, [r0]
    adds r1, r1, #1
    str r1, [r0]
    bx lr

    .thumb_func
    .global Default_Handler
Default_Handler:
    b .

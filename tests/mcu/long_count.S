@ long_count.S - a countdown loop of 2^32 - 1 iterations (tests/test_mcu_hostile3.py, MCU-11, MCU-28). Thumb-1: both
@ cores. R0 counts down from FFFFFFFFh to 0 in `subs r0, #1; bne`, then the thread stops at `done` (`b .`): more
@ than 2^32 instructions and cycles, counted by the countdown skip (MCU-11) without running them.
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
    movs r0, #0
    subs r0, r0, #1         @ FFFFFFFFh
    b 1f
    .align 2
1:
    subs r0, #1
    bne 1b
    .global done
done:
    b .

    .thumb_func
    .global Default_Handler
Default_Handler:
    b .

@ flash_rewrite.S - the firmware rewrites a loop in flash as it runs (tests/test_mcu_hostile3.py, MCU-28). Thumb-1:
@ both cores. `loop` (flash) is `subs r0, #1; bne loop; bx lr`, a countdown on R0 (MCU-11), called with R0 = 10;
@ then a halfword store makes it `subs r1, #1`, called with R1 = 10 while R0 = 1000 must stay untouched. The thread
@ ends in `b .` at `done`.
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
    movs r0, #10
    bl loop                 @ R0 counts down to 0
    ldr r2, =loop
    ldr r3, =0x3901         @ subs r1, #1
    strh r3, [r2]
    ldr r0, =1000
    movs r1, #10
    bl loop                 @ R1 counts down to 0; R0 stays 1000
    .global done
done:
    b .

    .align 2
    .global loop
loop:                       @ not a .thumb_func: `ldr r2, =loop` is the halfword's address
    subs r0, #1
    bne loop
    bx lr

    .thumb_func
    .global Default_Handler
Default_Handler:
    b .

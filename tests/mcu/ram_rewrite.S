@ ram_rewrite.S - code copied to RAM, run, rewritten in place and run again (tests/test_mcu_hostile3.py, MCU-25).
@ Thumb-1: both cores. `ramfn` (RAM) first holds `subs r3, r3, #1; bne .-2; bx lr` (a countdown loop on R3,
@ MCU-11), which runs with R3 = 100; then the same four-byte loop block on R4 (`subs r4, r4, #1; bne .-2`), which
@ runs with R4 = 100 while R3 = 1000 must stay untouched. The thread ends in `b .` at `done` with R3, R4 and the
@ loop counts as they are.
    .syntax unified
    .thumb

    .section .isr_vector,"a"
    .word _estack
    .word Reset_Handler
    .rept 14
    .word Default_Handler
    .endr

    .bss
    .align 2
    .global ramfn
ramfn: .space 8

    .text
    .thumb_func
    .global Reset_Handler
Reset_Handler:
    ldr r0, =ramfn
    ldr r1, =0xD1FD3B01     @ subs r3, #1 (3B01h); bne .-2 (D1FDh)
    str r1, [r0]
    ldr r1, =0x00004770     @ bx lr
    str r1, [r0, #4]
    movs r3, #100
    adds r0, r0, #1         @ Thumb bit
    mov r6, r0
    blx r6                  @ R3 counts down to 0 in RAM
    ldr r0, =ramfn
    ldr r1, =0xD1FD3C01     @ subs r4, #1 (3C01h); bne .-2: the same address and size, another register
    str r1, [r0]
    ldr r3, =1000
    movs r4, #100
    blx r6                  @ R4 counts down to 0; R3 stays 1000
    .global done
done:
    b .

    .thumb_func
    .global Default_Handler
Default_Handler:
    b .

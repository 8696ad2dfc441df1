@ vtlb_flash.S - stores into flash in separate runs, and one before a bus fault in the same block (tests/test_mcu_vtlb.py,
@ MCU-28, MCU-89): three stores to `slot` in a loop, one more followed by a read of unmapped memory, and a store
@ from the HardFault handler once the fault report has entered it. Thumb-1: both cores.
    .syntax unified
    .thumb

    .section .isr_vector,"a"
    .word _estack
    .word Reset_Handler
    .word Default_Handler
    .word HardFault_Handler
    .rept 12
    .word Default_Handler
    .endr

    .text
    .thumb_func
    .global Reset_Handler
Reset_Handler:
    ldr r2, =slot
    movs r0, #3
    movs r1, #0
1:  str r0, [r2]
    adds r1, r1, #1
    adds r1, r1, #2
    subs r0, #1
    bne 1b
    ldr r3, =0x30000000
    movs r0, #9
    str r0, [r2, #4]
    ldr r4, [r3]            @ a precise bus fault in the block of the store
    b .

    .thumb_func
    .global HardFault_Handler
HardFault_Handler:
    ldr r2, =slot
    movs r0, #7
    str r0, [r2, #8]        @ the run stops at this block's end: a store noted after the fault's run as well
    b 1f
1:  movs r5, #1
    adds r5, r5, #1
    b 2f
2:  adds r5, r5, #1
    .global done
done:
    b .

    .thumb_func
    .global Default_Handler
Default_Handler:
    b .

    .align 2
    .global slot
slot:
    .word 0, 0, 0

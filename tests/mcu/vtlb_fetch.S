@ vtlb_fetch.S - one access per build, for the faults the memory path reports (tests/test_mcu_vtlb.py, MCU-89):
@ -DTARGET=address with -DFETCH (a branch there, its Thumb bit given in TARGET), -DLOAD (a word read) or -DSTORE (a
@ word written). Thumb-1: both cores.
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
    movs r0, #5
    ldr r1, =TARGET
    .global faulting
faulting:
#if defined(FETCH)
    bx r1
#elif defined(LOAD)
    ldr r0, [r1]
#elif defined(STORE)
    str r0, [r1]
#endif
    b .

    .thumb_func
    .global Default_Handler
Default_Handler:
    b .

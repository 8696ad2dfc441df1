@ fault_address.S - one faulting access per build (-DSCENARIO=n), for the fault address registers
@ (tests/test_mcu_core.py): BFAR and MMFAR with CFSR's BFARVALID and MMARVALID (ARMv7-M B3.2.15 to B3.2.18).
@ Thumb-1 only, so that it runs on the Cortex-M0 (which has none of these registers) as well.
@ 1: a load from unmapped memory (precise bus fault, BFAR = 30000004h); 2: a store to unmapped memory (BFAR =
@ 60000010h); 3: a branch to unmapped memory (instruction bus fault: no address); 4: a branch into GPIOA's registers
@ (a peripheral region, Execute Never: MemManage IACCVIOL, no address); 5: a store to flash (DACCVIOL once the test
@ has made flash read-only; the board maps it writable, no MPU: MCU-3).
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
#if SCENARIO == 1
    ldr r1, =0x30000004
    .global faulting
faulting:
    ldr r0, [r1]
#elif SCENARIO == 2
    ldr r1, =0x60000010
    .global faulting
faulting:
    str r0, [r1]
#elif SCENARIO == 3
    ldr r1, =0x30000001
    .global faulting
faulting:
    bx r1
#elif SCENARIO == 4
    ldr r1, =0x40010801
    .global faulting
faulting:
    bx r1
#elif SCENARIO == 5
    ldr r1, =0x08000100
    .global faulting
faulting:
    str r0, [r1]
#endif
    b .

    .thumb_func
    .global Default_Handler
Default_Handler:
    b .

/*
 * startup.c - reset and vector table of the emulated SUPI 3 board (board.h, board.ld).
 *
 * Reset_Handler copies .data from flash, zeroes .bss and calls main() (board.c). The vector table holds the core's
 * exceptions (ARMv7-M B1.5.2) and the STM32F10x interrupts up to EXTI0 (IRQ 6, RM0008 10.1.2), the only one the
 * board uses. A handler a firmware does not define loops in Default_Handler: the emulator reports it as a stop
 * (supi3.mcu: budget exhausted, PC in Default_Handler).
 *
 * The run-time helpers the compiler calls are here too, because the build links no library (-nostdlib): memcpy
 * and memset (structure copies), the ARM EABI's __aeabi_memcpy/memclr/memset and the unsigned division of cores
 * without a divide instruction (Cortex-M0: __aeabi_uidiv, __aeabi_uidivmod; run-time ABI for the ARM
 * architecture, 4.3 and 4.3.4). A firmware that needs more (signed division, 64-bit arithmetic) builds with
 * compiler_rt=True (supi3.mcu.build), which links the toolchain's compiler-rt (slower first build).
 */
#include <stddef.h>
#include <stdint.h>

extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _estack;
int main(void);

void Reset_Handler(void);
void Default_Handler(void);
void NMI_Handler(void) __attribute__((weak, alias("Default_Handler")));
void HardFault_Handler(void) __attribute__((weak, alias("Default_Handler")));
void SVC_Handler(void) __attribute__((weak, alias("Default_Handler")));
void PendSV_Handler(void) __attribute__((weak, alias("Default_Handler")));
void SysTick_Handler(void) __attribute__((weak, alias("Default_Handler")));
void EXTI0_IRQHandler(void) __attribute__((weak, alias("Default_Handler")));

typedef void (*vector_t)(void);

__attribute__((section(".isr_vector"), used)) const vector_t board_vectors[16 + 7] = {
    (vector_t)(uintptr_t)&_estack, /* initial MSP */
    Reset_Handler,
    NMI_Handler,
    HardFault_Handler,
    0, 0, 0, 0, 0, 0, 0, /* MemManage, BusFault, UsageFault (M3; escalate to HardFault when disabled), reserved */
    SVC_Handler,
    0, 0, /* DebugMon, reserved */
    PendSV_Handler,
    SysTick_Handler,
    0, 0, 0, 0, 0, 0, /* WWDG, PVD, TAMPER, RTC, FLASH, RCC */
    EXTI0_IRQHandler,
};

void Default_Handler(void)
{
    for (;;) {
    }
}

void Reset_Handler(void)
{
    const uint32_t *src = &_sidata;
    uint32_t *dst;
    for (dst = &_sdata; dst < &_edata;) {
        *dst++ = *src++;
    }
    for (dst = &_sbss; dst < &_ebss;) {
        *dst++ = 0u;
    }
    (void)main();
    for (;;) {
    }
}

void *memcpy(void *dest, const void *src, size_t n)
{
    uint8_t *d = dest;
    const uint8_t *s = src;
    while (n-- != 0u) {
        *d++ = *s++;
    }
    return dest;
}

void *memset(void *dest, int c, size_t n)
{
    uint8_t *d = dest;
    while (n-- != 0u) {
        *d++ = (uint8_t)c;
    }
    return dest;
}

void __aeabi_memcpy(void *dest, const void *src, size_t n);
void __aeabi_memcpy4(void *dest, const void *src, size_t n) __attribute__((alias("__aeabi_memcpy")));
void __aeabi_memcpy8(void *dest, const void *src, size_t n) __attribute__((alias("__aeabi_memcpy")));
void __aeabi_memset(void *dest, size_t n, int c);
void __aeabi_memclr(void *dest, size_t n);
void __aeabi_memclr4(void *dest, size_t n) __attribute__((alias("__aeabi_memclr")));
void __aeabi_memclr8(void *dest, size_t n) __attribute__((alias("__aeabi_memclr")));
unsigned __aeabi_uidiv(unsigned n, unsigned d);
unsigned long long __aeabi_uidivmod(unsigned n, unsigned d);

void __aeabi_memcpy(void *dest, const void *src, size_t n)
{
    (void)memcpy(dest, src, n);
}

void __aeabi_memset(void *dest, size_t n, int c)
{
    (void)memset(dest, c, n);
}

void __aeabi_memclr(void *dest, size_t n)
{
    (void)memset(dest, 0, n);
}

/* Quotient in the low word (r0), remainder in the high word (r1), as the run-time ABI returns them. Shift and
 * subtract, one quotient bit per step; a division by zero gives 0 rem n (the ABI's __aeabi_idiv0 is not called). */
unsigned long long __aeabi_uidivmod(unsigned n, unsigned d)
{
    unsigned quotient = 0u;
    unsigned remainder = 0u;
    int bit;
    if (d == 0u) {
        return (unsigned long long)n << 32;
    }
    for (bit = 31; bit >= 0; --bit) {
        remainder = (remainder << 1) | ((n >> bit) & 1u);
        if (remainder >= d) {
            remainder -= d;
            quotient |= 1u << bit;
        }
    }
    return ((unsigned long long)remainder << 32) | quotient;
}

unsigned __aeabi_uidiv(unsigned n, unsigned d)
{
    return (unsigned)__aeabi_uidivmod(n, d);
}

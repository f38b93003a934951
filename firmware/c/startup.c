/* Start-up of the C firmware example on a Cortex-M4F (QEMU mps2-an386): the vector table, the
   reset handler (FPU on, .data copied, .bss zeroed, then main) and semihosting output and exit.
   A real board's vendor start-up file does the same; keep yours. */
#include <stdint.h>

#include "semihosting.h"

extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _estack;
int main(void);
void reset_handler(void);
void default_handler(void);

typedef void (*handler)(void);

/* Initial stack pointer, then the 15 system exception handlers. */
struct vector_table {
    uint32_t *initial_sp;
    handler exceptions[15];
};

__attribute__((section(".vectors"), used)) const struct vector_table vectors = {
    &_estack,
    {reset_handler, default_handler, default_handler, default_handler, default_handler,
     default_handler, default_handler, default_handler, default_handler, default_handler,
     default_handler, default_handler, default_handler, default_handler, default_handler}};

void reset_handler(void) {
    /* The FPU first (CPACR: full access to CP10 and CP11): the library is built for hard
       float, and so is this code. */
    volatile uint32_t *cpacr = (volatile uint32_t *)0xE000ED88u;
    uint32_t *src = &_sidata;
    uint32_t *dst;
    *cpacr |= 0xFu << 20;
    __asm__ volatile("dsb\n\tisb" ::: "memory");
    for (dst = &_sdata; dst < &_edata;) {
        *dst++ = *src++;
    }
    for (dst = &_sbss; dst < &_ebss;) {
        *dst++ = 0;
    }
    semihosting_exit(main() == 0);
}

/* A fault or an unexpected exception: report it and fail. */
void default_handler(void) {
    semihosting_write("FAIL: exception\n");
    semihosting_exit(0);
}

/* Output and exit through semihosting (QEMU's -semihosting, or a debugger). On a board running
   alone a semihosting call stops the core: replace these with your UART and your own end. */
#ifndef SEMIHOSTING_H
#define SEMIHOSTING_H

static inline int semihosting_call(int op, const void *arg) {
    register int r0 __asm__("r0") = op;
    register const void *r1 __asm__("r1") = arg;
    __asm__ volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}

/* SYS_WRITE0: a NUL-terminated string to the host's console. */
static inline void semihosting_write(const char *s) {
    semihosting_call(0x04, s);
}

/* SYS_EXIT: QEMU exits with 0 for ADP_Stopped_ApplicationExit, 1 for any other reason. */
static inline void semihosting_exit(int ok) {
    semihosting_call(0x18, (const void *)(ok ? 0x20026 : 0x20024));
    for (;;) {
    }
}

#endif

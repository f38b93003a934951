//! Size-first versions of the two memory routines the compiler calls, for firmware built for
//! size (opt-level `"s"`/`"z"`; `cfg(firmware_size)`, set by build.rs).
//!
//! Rust lowers a copy or a zeroing of a 4-byte aligned object to calls of the ARM run-time ABI
//! routines `__aeabi_memcpy4` (`dest`, `src`, `n`) and `__aeabi_memclr4` (`dest`, `n`) (and their
//! `…8` forms for 8-byte alignment), which `compiler_builtins` implements for speed: unrolled
//! word loops and a general `memcpy` for misaligned tails, 1,060 B in all on a Cortex-M4F. The
//! versions here are one word loop and one byte loop each, 70 B in all. C toolchains make the
//! same choice: newlib builds its byte-loop `memcpy` when `__OPTIMIZE_SIZE__` is defined.
//!
//! Only the size builds use these. Opt-level 2/3 firmware keeps `compiler_builtins`' unrolled
//! loops (about 2.75 instead of 4 instructions per copied word), so the instruction-count
//! budgets, held at opt-level 3, are not affected. Any other memory routine the compiler might
//! call (`memcpy`, `memset`, `memmove`, …) still comes from `compiler_builtins`: the linker takes
//! a symbol from the library only when no object file defines it.
//!
//! The demo checks both routines on every length from 0 to 40 bytes, with guard bytes on both
//! sides (`check mem routines`), at both opt-levels.

// The ABI (ARM RTABI, section 4.3.4): `dest` and `src` are 4-byte aligned, `n` is any byte count;
// the routines may clobber r0-r3, r12 and the flags, and return nothing.
#[cfg(firmware_size)]
core::arch::global_asm!(
    ".section .text.__aeabi_memcpy4,\"ax\",%progbits",
    ".globl __aeabi_memcpy4",
    ".globl __aeabi_memcpy8",
    ".type __aeabi_memcpy4,%function",
    ".type __aeabi_memcpy8,%function",
    ".thumb_func",
    "__aeabi_memcpy4:",
    ".thumb_func",
    "__aeabi_memcpy8:",
    "    subs r2, #4", // n -= 4; fewer than 4 bytes left: to the tail
    "    blo 2f",
    "1:  ldr r3, [r1], #4", // one word
    "    str r3, [r0], #4",
    "    subs r2, #4",
    "    bhs 1b",
    "2:  adds r2, #4", // undo the last subtraction: 0 to 3 bytes left
    "    beq 4f",
    "3:  ldrb r3, [r1], #1", // one byte
    "    strb r3, [r0], #1",
    "    subs r2, #1",
    "    bne 3b",
    "4:  bx lr",
    ".size __aeabi_memcpy4, . - __aeabi_memcpy4",
    ".section .text.__aeabi_memclr4,\"ax\",%progbits",
    ".globl __aeabi_memclr4",
    ".globl __aeabi_memclr8",
    ".type __aeabi_memclr4,%function",
    ".type __aeabi_memclr8,%function",
    ".thumb_func",
    "__aeabi_memclr4:",
    ".thumb_func",
    "__aeabi_memclr8:",
    "    movs r2, #0",
    "    subs r1, #4",
    "    blo 2f",
    "1:  str r2, [r0], #4",
    "    subs r1, #4",
    "    bhs 1b",
    "2:  adds r1, #4",
    "    beq 4f",
    "3:  strb r2, [r0], #1",
    "    subs r1, #1",
    "    bne 3b",
    "4:  bx lr",
    ".size __aeabi_memclr4, . - __aeabi_memclr4",
);

//! The device part of the vector table, sized for the board these binaries run on.
//!
//! Without its `device` feature, cortex-m-rt reserves the architectural maximum of 240 external
//! interrupt vectors (960 B of flash), because it cannot know the device. QEMU's `mps2-an386`
//! gives its NVIC 32 external interrupt lines (`num-irq` in `hw/arm/mps2.c`), as the AN386 FPGA
//! image does, so the table here has 32 entries (128 B), all pointing at cortex-m-rt's
//! `DefaultHandler`: none of these binaries enables an interrupt. A device crate (PAC) does the
//! same for a real part, with its own count; the flash figures in README.md include this table.

/// Number of external interrupt lines of the AN386 image's NVIC.
const IRQ_LINES: usize = 32;

extern "C" {
    /// cortex-m-rt's default exception and interrupt handler (an endless loop unless the
    /// firmware overrides it with `#[exception]`).
    fn DefaultHandler();
}

/// IRQ 0 to 31, placed right after the 16 system exception vectors by cortex-m-rt's `link.x`.
#[allow(unsafe_code)]
#[link_section = ".vector_table.interrupts"]
#[no_mangle]
static __INTERRUPTS: [unsafe extern "C" fn(); IRQ_LINES] = [DefaultHandler; IRQ_LINES];

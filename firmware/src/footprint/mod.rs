//! What the footprint binaries (`src/bin/fp_*.rs`) share: opaque sensor input, a sink for
//! results, and the no-panic handler.
//!
//! Each footprint binary is the smallest realistic firmware for one use of estimator-core (an
//! attitude filter, an inertial filter, a PnP solver): its loop reads opaque samples and calls
//! only what such firmware calls. Their flash at opt-level "s" is what a user of that part
//! alone pays, next to the `nopanic` binary that links the whole public API. Like `nopanic`,
//! they link only if no panic path is reachable.

use core::hint::black_box;

/// The run-time's entry attribute of the core the binary is built for (the navigators'
/// footprints are also built for RISC-V; the filters' and PnP's only for Cortex-M).
#[cfg(target_arch = "arm")]
#[allow(unused_imports)]
pub use cortex_m_rt::entry;
#[cfg(target_arch = "riscv32")]
#[allow(unused_imports)]
pub use riscv_rt::entry;

/// An opaque `f32`: the optimizer knows nothing of it (a sensor register, in real firmware).
#[inline(always)]
pub fn input(i: usize) -> f32 {
    static SAMPLES: [f32; 8] = [0.01, -0.02, 0.03, 9.81, 0.2, 0.4, 1.5, 0.005];
    let s = black_box(&SAMPLES);
    s.get(i % 8).copied().unwrap_or(0.0)
}

/// Three opaque numbers from `i` on, as a vector (a sensor's three axes).
#[inline(always)]
pub fn input3(i: usize) -> nalgebra::Vector3<f32> {
    nalgebra::Vector3::new(input(i), input(i + 1), input(i + 2))
}

/// Waits forever (where a constructor was refused: the firmware has nothing to run).
#[allow(dead_code)] // the navigators' footprints call it; the filters' have their own loop
pub fn idle() -> ! {
    loop {
        #[cfg(target_arch = "arm")]
        cortex_m::asm::wfi();
        #[cfg(not(target_arch = "arm"))]
        core::hint::spin_loop();
    }
}

/// Keeps a result alive: its address goes to `black_box`.
#[inline(always)]
pub fn keep<X>(x: &X) {
    black_box(x);
}

#[path = "../no_panic_handler.rs"]
mod no_panic_handler;

#[cfg(target_arch = "arm")]
#[path = "../vectors.rs"]
mod vectors;

#[path = "../mem.rs"]
mod mem;

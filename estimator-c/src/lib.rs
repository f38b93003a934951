//! C interface to the navigators of `estimator-core`, in `f32`: the attitude navigator (an
//! AHRS: gyro, accelerometer, optional magnetometer) and the INS navigator (IMU, GNSS, optional
//! magnetometer and barometer).
//!
//! The header `include/estimator.h` is generated from this crate by `cbindgen`
//! (`estimator-c/cbindgen.toml`); `tests/header.rs` checks that it is up to date.
//!
//! Conventions (as in `estimator-core`'s `nav` module): timestamps are `uint64_t` nanoseconds
//! on one clock, strictly increasing per sensor; vectors are `float[3]`; the world frame is ENU
//! (`z` up, north along `y`); the body frame is the IMU's; quaternions are `w, x, y, z` and
//! rotate body vectors into the world (`R`: world from body).
//!
//! Memory: nothing is allocated. The caller gives the storage of a navigator (a static array
//! of at least `est_*_storage_size()` bytes, aligned to `est_*_storage_align()`), and
//! `est_*_init` builds the navigator in it; the handle it returns points into that storage.
//! Every call returns an [`est_error`]; on any error the navigator is unchanged (apart from
//! its count of refused samples) and no output is written. A handle must not be used from two
//! threads (or an interrupt and the main loop) at the same time.
#![no_std]
#![deny(unsafe_op_in_unsafe_fn, missing_docs)]

// Hosted targets (tests, host tools) take the panic runtime from std. On bare metal no path
// of this library panics (no unwrap, no indexing that can fail), and the link proves it: the
// handler calls a function that exists nowhere, so a program linked with `--gc-sections` fails
// to link (`undefined reference to __estimator_c_panic_path_reachable`) if any panic path is
// reachable.
#[cfg(not(target_os = "none"))]
extern crate std;

#[cfg(target_os = "none")]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    extern "C" {
        /// Defined nowhere: referencing it makes the link fail if a panic is reachable.
        fn __estimator_c_panic_path_reachable() -> !;
    }
    // SAFETY: never executed: a program in which this call is reachable does not link.
    unsafe { __estimator_c_panic_path_reachable() }
}

mod attitude;
mod error;
mod ins;
mod report;
mod storage;

pub use attitude::*;
pub use error::*;
pub use ins::*;
pub use report::*;
pub use storage::{est_api_version, EST_API_VERSION};

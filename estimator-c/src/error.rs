//! Error codes: one per `NavError` of `estimator-core`, and those of the C boundary.

use core::ffi::c_char;
use estimator_core::nav::NavError;

/// The result of every call (`int32_t`): `EST_OK` or why the call was refused.
/// On any error the navigator is unchanged and no output was written.
#[allow(non_camel_case_types, clippy::upper_case_acronyms)]
#[repr(i32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum est_error {
    /// Success.
    EST_OK = 0,
    /// A NaN or infinite value in the sample.
    EST_ERR_NON_FINITE = 1,
    /// An IMU sample beyond the sensor's range (or beyond 200 rad/s, 5000 m/s²): a fault.
    EST_ERR_OUT_OF_RANGE = 2,
    /// An all-zero accelerometer or magnetometer sample (taken for a fault).
    EST_ERR_ZERO_VECTOR = 3,
    /// A timestamp equal to or before the previous sample of the same sensor.
    EST_ERR_TIME_NOT_INCREASING = 4,
    /// A configuration value out of its domain (see the field's documentation).
    EST_ERR_INVALID_CONFIG = 5,
    /// A measurement's sigma out of its range (GNSS fixes).
    EST_ERR_INVALID_SIGMA = 6,
    /// A measurement older than the INS's fusion horizon.
    EST_ERR_TOO_OLD = 7,
    /// A measurement stamped after the newest IMU sample by more than `max_dt_s`.
    EST_ERR_IN_FUTURE = 8,
    /// The INS's measurement queue is full.
    EST_ERR_QUEUE_FULL = 9,
    /// The filter refused a step (a numerical failure; the next sample is taken normally), or
    /// refused the filter part of a configuration (noise densities, gravity, `max_dt_s`).
    EST_ERR_FILTER = 10,
    /// A pointer argument is NULL.
    EST_ERR_NULL_POINTER = 100,
    /// A pointer argument is not aligned for its type (storage: `est_*_storage_align()`).
    EST_ERR_MISALIGNED = 101,
    /// The storage is smaller than `est_*_storage_size()`.
    EST_ERR_STORAGE_TOO_SMALL = 102,
    /// The handle does not point to a navigator built by `est_*_init` of the same kind.
    EST_ERR_NOT_INITIALIZED = 103,
    /// No estimate yet: the navigator is still starting (collecting its start-up window, or
    /// for the INS aligning until its first GNSS fix).
    EST_ERR_NOT_STARTED = 104,
}

impl From<NavError> for est_error {
    fn from(e: NavError) -> Self {
        match e {
            NavError::NonFinite => Self::EST_ERR_NON_FINITE,
            NavError::OutOfRange => Self::EST_ERR_OUT_OF_RANGE,
            NavError::ZeroVector => Self::EST_ERR_ZERO_VECTOR,
            NavError::TimeNotIncreasing => Self::EST_ERR_TIME_NOT_INCREASING,
            NavError::InvalidConfig => Self::EST_ERR_INVALID_CONFIG,
            NavError::InvalidSigma => Self::EST_ERR_INVALID_SIGMA,
            NavError::TooOld => Self::EST_ERR_TOO_OLD,
            NavError::InFuture => Self::EST_ERR_IN_FUTURE,
            NavError::QueueFull => Self::EST_ERR_QUEUE_FULL,
            NavError::Filter(_) => Self::EST_ERR_FILTER,
        }
    }
}

/// `Ok` as `EST_OK`, an error as its code.
pub(crate) fn code(r: Result<(), est_error>) -> est_error {
    match r {
        Ok(()) => est_error::EST_OK,
        Err(e) => e,
    }
}

/// A static, NUL-terminated name of an error code (`"EST_ERR_TOO_OLD"`), for logs;
/// `"EST_ERR_UNKNOWN"` for a value that is no code. Never NULL.
#[no_mangle]
pub extern "C" fn est_error_name(code: i32) -> *const c_char {
    let name: &'static core::ffi::CStr = match code {
        0 => c"EST_OK",
        1 => c"EST_ERR_NON_FINITE",
        2 => c"EST_ERR_OUT_OF_RANGE",
        3 => c"EST_ERR_ZERO_VECTOR",
        4 => c"EST_ERR_TIME_NOT_INCREASING",
        5 => c"EST_ERR_INVALID_CONFIG",
        6 => c"EST_ERR_INVALID_SIGMA",
        7 => c"EST_ERR_TOO_OLD",
        8 => c"EST_ERR_IN_FUTURE",
        9 => c"EST_ERR_QUEUE_FULL",
        10 => c"EST_ERR_FILTER",
        100 => c"EST_ERR_NULL_POINTER",
        101 => c"EST_ERR_MISALIGNED",
        102 => c"EST_ERR_STORAGE_TOO_SMALL",
        103 => c"EST_ERR_NOT_INITIALIZED",
        104 => c"EST_ERR_NOT_STARTED",
        _ => c"EST_ERR_UNKNOWN",
    };
    name.as_ptr()
}

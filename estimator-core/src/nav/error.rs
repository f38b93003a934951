//! Why a navigator refused a sample.

use crate::eskf::EskfError;

/// Why a call refused its input. Whenever one of these is returned, the navigator is bit for
/// bit what it was before the call.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum NavError {
    /// A NaN or infinite value in the sample.
    NonFinite,
    /// An IMU sample beyond any sensor's range ([`IMU_RATE_LIMIT`](crate::nav::IMU_RATE_LIMIT),
    /// [`IMU_ACCEL_LIMIT`](crate::nav::IMU_ACCEL_LIMIT)): a fault, not a measurement.
    OutOfRange,
    /// An all-zero accelerometer or magnetometer sample: no sensor reads exactly zero on
    /// every axis, so the sample is taken for a fault.
    ZeroVector,
    /// A timestamp equal to or before the previous sample of the same sensor.
    TimeNotIncreasing,
    /// A configuration value out of its domain (named in the docs of the field).
    InvalidConfig,
    /// A measurement's sigma is not positive (or its square not finite).
    InvalidSigma,
    /// A measurement stamped before the time the filter has reached (older than the
    /// delayed-fusion horizon).
    TooOld,
    /// A measurement stamped after the newest IMU sample by more than `max_dt`.
    InFuture,
    /// The measurement queue is full: measurements arrive faster than the filter reaches
    /// their time (a horizon too long for the queue, or a stalled IMU).
    QueueFull,
    /// The filter refused a step the navigator built from valid samples (a numerical failure;
    /// the navigator is unchanged and the next sample is taken normally).
    Filter(EskfError),
}

impl core::fmt::Display for NavError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::NonFinite => f.write_str("non-finite value in the sample"),
            Self::OutOfRange => f.write_str("IMU sample beyond any sensor's range"),
            Self::ZeroVector => f.write_str("all-zero sample"),
            Self::TimeNotIncreasing => f.write_str("timestamp is not after the previous one"),
            Self::InvalidConfig => f.write_str("configuration value out of its domain"),
            Self::InvalidSigma => f.write_str("sigma is not positive"),
            Self::TooOld => f.write_str("measurement older than the fusion horizon"),
            Self::InFuture => f.write_str("measurement stamped after the newest IMU sample"),
            Self::QueueFull => f.write_str("measurement queue full"),
            Self::Filter(e) => write!(f, "filter: {e}"),
        }
    }
}

impl From<EskfError> for NavError {
    fn from(e: EskfError) -> Self {
        Self::Filter(e)
    }
}

//! Navigators: the layer a firmware main loop calls, one timestamped sample at a time.
//!
//! A filter ([`crate::eskf`]) knows the mathematics of one step; a navigator owns a filter and
//! everything a real sensor stream needs around it: start-up from whatever the stream gives,
//! IMU integration between samples, the sensor policy (what to fuse, when, with which noise),
//! fault handling, and a report after every call saying which parts of the estimate are valid
//! and why not.
//!
//! * [`AttitudeNavigator`]: attitude and gyro bias from a gyro, an accelerometer and an
//!   optional magnetometer (an AHRS).
//!
//! Conventions: timestamps are `u64` nanoseconds on one clock, strictly increasing per
//! sensor; the world frame is ENU (`z` up), gravity `[0, 0, −9.81]`; the body frame is the
//! IMU's; the attitude `R` maps body to world. Every call that takes a sample returns a
//! `Result`; on `Err` the navigator is unchanged bit for bit. Nothing allocates or panics.

mod attitude;
mod clock;
mod error;
mod mean;

pub use attitude::{
    AttitudeConfig, AttitudeEstimate, AttitudeNavigator, AttitudeReport, Counters, Event, Fusion,
    Fusions, MagneticConfig, MagneticFusion, MagneticStatus, Reason, Validity,
};
pub use error::NavError;
pub use mean::VectorMean;

//! What the INS navigator says after every call: the validity of each quantity of the
//! estimate, each aiding sensor's state, and what it did on its own.

use crate::eskf::InsState;
use crate::nav::attitude::Validity;
use crate::Real;
use nalgebra::Matrix3;

/// An aiding sensor's state.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum AidStatus {
    /// Not configured (or, for GNSS, no fix ever received).
    Absent,
    /// Configured; nothing fused yet.
    Waiting,
    /// The last measurement was fused.
    Fused,
    /// No measurement has come due for 2.5 of the sensor's own measurement intervals (an
    /// outage, or a sensor that stopped; [`AID_STALE_NS`](crate::nav::AID_STALE_NS) before an
    /// interval is known).
    Stale,
    /// The last measurement failed the gate (an outlier, or a fault if it lasts).
    Rejected,
    /// The last measurement was refused before the gate: a GNSS fix repeating the previous
    /// one exactly (a frozen receiver), or a magnetometer whose norm disagrees with the
    /// reference.
    Faulty,
}

/// Something the navigator did on its own in the last call.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum InsEvent {
    /// The INS started: attitude and biases from the alignment, position and velocity from
    /// the first fix.
    Started,
    /// An IMU gap longer than `max_dt`: the navigator went back to aligning.
    Realigned,
    /// The fixes were rejected for `gnss_reset_s`: position and velocity were reset to them.
    PositionReset,
    /// A clipped or stuck IMU sample: the velocity (clipped accelerometer) or the attitude
    /// (stuck or clipped gyro) covariance was widened by what the sample may hide.
    ImuFault,
    /// Without a magnetometer, the heading was set from the bank of yaw hypotheses that the
    /// GNSS velocities weigh (`nav/ins/yaw.rs`): first resolved, or the INS's own had grown
    /// wider than the bank's or disagreed with it.
    HeadingFromGnss,
}

/// The validity of each quantity of the estimate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct InsValidity {
    /// Roll and pitch.
    pub tilt: Validity,
    /// Yaw.
    pub heading: Validity,
    /// Velocity.
    pub velocity: Validity,
    /// Position.
    pub position: Validity,
    /// Gyro bias.
    pub gyro_bias: Validity,
    /// Accelerometer bias.
    pub accel_bias: Validity,
}

/// The aiding measurements the navigator fuses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Aiding {
    /// A GNSS position (3 degrees of freedom).
    GnssPosition,
    /// A GNSS velocity (3).
    GnssVelocity,
    /// A magnetometer field (3).
    Magnetometer,
    /// A barometric altitude (1).
    Barometer,
}

/// One aiding update made in a call.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InsFusion<T: Real> {
    /// Which.
    pub aid: Aiding,
    /// The measurement's time, ns.
    pub t_ns: u64,
    /// `NIS = rᵀ S⁻¹ r`.
    pub nis: T,
    /// Fused (`false`: the gate rejected it).
    pub accepted: bool,
}

/// The report after every call.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InsReport<T: Real> {
    /// The time of the estimate, ns: the newest IMU sample.
    pub t_ns: u64,
    /// Each quantity's validity.
    pub validity: InsValidity,
    /// GNSS.
    pub gnss: AidStatus,
    /// Magnetometer.
    pub magnetometer: AidStatus,
    /// Barometer.
    pub barometer: AidStatus,
    /// The IMU's last sample was clipped or had a stuck axis.
    pub imu_fault: bool,
    /// What the navigator did on its own in this call, if anything.
    pub event: Option<InsEvent>,
    /// The update made in this call, if any (at most one per call).
    pub fused: Option<InsFusion<T>>,
}

/// The estimate at the newest IMU sample, with the diagonal blocks of its covariance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InsEstimate<T: Real> {
    /// The time, ns.
    pub t_ns: u64,
    /// `(R, v, p, b_g, b_a)`: world (ENU) from body, m/s, m, rad/s, m/s².
    pub state: InsState<T>,
    /// The 3 × 3 covariance blocks of `δθ` (body frame, rad²), `δv`, `δp`, `δb_g`, `δb_a`.
    pub covariance: [Matrix3<T>; 5],
}

/// Counts since construction, for logs and summaries.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct InsCounters {
    /// IMU samples taken.
    pub imu: u32,
    /// Samples refused with an error (any sensor).
    pub refused: u32,
    /// GNSS position updates fused.
    pub gnss_position_fused: u32,
    /// GNSS position updates that failed the gate.
    pub gnss_position_rejected: u32,
    /// GNSS velocity updates fused.
    pub gnss_velocity_fused: u32,
    /// GNSS velocity updates that failed the gate.
    pub gnss_velocity_rejected: u32,
    /// GNSS fixes refused as frozen (an exact repeat of the previous one).
    pub gnss_frozen: u32,
    /// Magnetometer updates fused.
    pub magnetometer_fused: u32,
    /// Magnetometer updates that failed the gate.
    pub magnetometer_rejected: u32,
    /// Magnetometer samples refused for a norm that disagrees with the reference.
    pub magnetometer_disturbed: u32,
    /// Barometer updates fused.
    pub barometer_fused: u32,
    /// Barometer updates that failed the gate.
    pub barometer_rejected: u32,
    /// Measurements that came due while aligning and could not be used.
    pub unused: u32,
    /// Resets of position and velocity to the fixes.
    pub resets: u32,
    /// Restarts after IMU gaps.
    pub realigned: u32,
    /// IMU samples taken as clipped or stuck.
    pub imu_faults: u32,
    /// Headings set from the GNSS track's bank of yaw hypotheses ([`InsEvent::HeadingFromGnss`]).
    pub heading_resets: u32,
    /// A ground vehicle's zero lateral velocity ([`crate::eskf::LateralVelocity`]), fused at a
    /// GNSS velocity.
    pub lateral_fused: u32,
    /// … and rejected by the gate (the vehicle slid, or the heading is wrong).
    pub lateral_rejected: u32,
    /// Without a magnetometer: windows over which the GNSS velocities disagreed with the
    /// positions (`nav/ins/velocity_check.rs`); the bank of yaw hypotheses takes no velocity
    /// until a window agrees again.
    pub gnss_velocity_inconsistent: u32,
    /// Updates or predictions the filter refused (a numerical failure: skipped, the filter
    /// left as it was).
    pub numerical_failures: u32,
}

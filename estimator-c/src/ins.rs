//! The INS navigator (IMU, GNSS, optional magnetometer and barometer): configuration,
//! storage, samples, estimate, report.

use crate::attitude::est_attitude_config;
use crate::error::{code, est_error};
use crate::report::{est_aid_status, est_ins_event, est_validity};
use crate::storage::{
    init_nav, nav_mut, nav_ref, read_in, read_vec3, read_vec3_pair, slot_align, slot_size, vec3,
    write_out, MAGIC_INS,
};
use core::ffi::c_void;
use estimator_core::eskf::FilterConfig;
use estimator_core::nalgebra::{Matrix3, Vector3};
use estimator_core::nav::{AttitudeConfig, GnssFix, InsConfig, InsCounters, InsNavigator, Travel};

/// An INS navigator in caller-provided storage (opaque; the handle `est_ins_init` returns).
#[allow(non_camel_case_types)]
pub struct est_ins {
    _opaque: [u8; 0],
}

/// How the vehicle moves against its body (`est_ins_config::travel`).
#[allow(non_camel_case_types, clippy::upper_case_acronyms)]
#[repr(i32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum est_travel {
    /// Learned from the GNSS track whether the vehicle travels along its body x axis (the
    /// default).
    EST_TRAVEL_DETECT = 0,
    /// A vehicle that may move sideways (multirotor, hand-held device).
    EST_TRAVEL_SIDEWAYS = 1,
    /// A vehicle that does not move sideways (car, rover), with `lateral_sigma`.
    EST_TRAVEL_FORWARD = 2,
}

/// The configuration of an INS navigator. Fill it with `est_ins_config_default`, then set
/// what differs. Units SI (m, m/s, s, rad); fields not listed keep `estimator-core`'s
/// defaults (`InsConfig::new`).
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct est_ins_config {
    /// The IMU, the magnetometer and the alignment (the INS aligns like an attitude navigator
    /// until its first GNSS fix).
    pub attitude: est_attitude_config,
    /// How far in the past a measurement may be stamped, s (0.3), in `[0, 10]`: the filter
    /// runs this far behind the newest IMU sample. At most 64 IMU intervals.
    pub horizon_s: f32,
    /// The GNSS antenna's position in the body frame, m.
    pub gnss_lever_arm: [f32; 3],
    /// A barometer is present (`false`): then `barometer_sigma` must be set.
    pub has_barometer: bool,
    /// The barometer's white noise per sample, m, between 0.001 and 1000 (0: must be set).
    pub barometer_sigma: f32,
    /// The accelerometer's range, m/s² (0: unknown): samples at 99.9 % of it are clipped.
    pub accelerometer_range: f32,
    /// The gyro's range, rad/s (0: unknown), as `accelerometer_range`.
    pub gyro_range: f32,
    /// Consecutive rejected GNSS fixes for this long, s (10), reset position and velocity to
    /// the fixes.
    pub gnss_reset_s: f32,
    /// Position valid below this horizontal 1σ, m (10).
    pub position_valid_sigma: f32,
    /// Velocity valid below this 1σ, m/s (1).
    pub velocity_valid_sigma: f32,
    /// Tilt valid below this 1σ, rad (5°).
    pub tilt_valid_sigma: f32,
    /// Heading valid below this 1σ, rad (10°).
    pub heading_valid_sigma: f32,
    /// Gyro bias valid below this 1σ, rad/s (0.05 °/s).
    pub gyro_bias_valid_sigma: f32,
    /// Accelerometer bias valid below this 1σ, m/s² (0.05).
    pub accel_bias_valid_sigma: f32,
    /// How the vehicle moves against its body: an `est_travel` value (`int32_t`).
    pub travel: i32,
    /// With `EST_TRAVEL_FORWARD`: 1σ of the lateral body velocity, m/s, between 0.001 and
    /// 100 (0: must be set).
    pub lateral_sigma: f32,
}

impl est_ins_config {
    fn from_rust(c: &InsConfig<f32>) -> Self {
        let (travel, lateral_sigma) = match c.travel {
            Travel::Detect => (est_travel::EST_TRAVEL_DETECT, 0.0),
            Travel::Sideways => (est_travel::EST_TRAVEL_SIDEWAYS, 0.0),
            Travel::Forward { lateral_sigma } => (est_travel::EST_TRAVEL_FORWARD, lateral_sigma),
        };
        Self {
            attitude: est_attitude_config::from_rust(&c.attitude),
            horizon_s: c.horizon_s,
            gnss_lever_arm: vec3(&c.gnss_lever_arm),
            has_barometer: c.barometer_sigma.is_some(),
            barometer_sigma: c.barometer_sigma.unwrap_or(0.0),
            accelerometer_range: c.accelerometer_range,
            gyro_range: c.gyro_range,
            gnss_reset_s: c.gnss_reset_s,
            position_valid_sigma: c.position_valid_sigma,
            velocity_valid_sigma: c.velocity_valid_sigma,
            tilt_valid_sigma: c.tilt_valid_sigma,
            heading_valid_sigma: c.heading_valid_sigma,
            gyro_bias_valid_sigma: c.gyro_bias_valid_sigma,
            accel_bias_valid_sigma: c.accel_bias_valid_sigma,
            travel: travel as i32,
            lateral_sigma,
        }
    }

    /// The Rust configuration (checked by the navigator's constructor, `InsConfig::validate`;
    /// here only the enum codes).
    pub(crate) fn to_rust(self) -> Result<InsConfig<f32>, est_error> {
        let mut c = InsConfig::new(self.attitude.to_rust()?);
        c.horizon_s = self.horizon_s;
        c.gnss_lever_arm = Vector3::from(self.gnss_lever_arm);
        c.barometer_sigma = self.has_barometer.then_some(self.barometer_sigma);
        c.accelerometer_range = self.accelerometer_range;
        c.gyro_range = self.gyro_range;
        c.gnss_reset_s = self.gnss_reset_s;
        c.position_valid_sigma = self.position_valid_sigma;
        c.velocity_valid_sigma = self.velocity_valid_sigma;
        c.tilt_valid_sigma = self.tilt_valid_sigma;
        c.heading_valid_sigma = self.heading_valid_sigma;
        c.gyro_bias_valid_sigma = self.gyro_bias_valid_sigma;
        c.accel_bias_valid_sigma = self.accel_bias_valid_sigma;
        c.travel = match self.travel {
            0 => Travel::Detect,
            1 => Travel::Sideways,
            2 => Travel::Forward {
                lateral_sigma: self.lateral_sigma,
            },
            _ => return Err(est_error::EST_ERR_INVALID_CONFIG),
        };
        Ok(c)
    }
}

/// A GNSS fix: antenna position and optional velocity, world frame (ENU), with their 1σ.
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct est_gnss_fix {
    /// Antenna position, m, ENU in the navigator's local frame.
    pub position: [f32; 3],
    /// The receiver gives a velocity (`velocity`, `sigma_velocity`).
    pub has_velocity: bool,
    /// Antenna velocity, m/s, ENU.
    pub velocity: [f32; 3],
    /// Horizontal position 1σ per axis, m (0.001 to 10000); also the vertical one unless
    /// `has_sigma_position_up`.
    pub sigma_position: f32,
    /// Velocity 1σ per axis, m/s (0.001 to 100).
    pub sigma_velocity: f32,
    /// The vertical position 1σ is given in `sigma_position_up`.
    pub has_sigma_position_up: bool,
    /// Vertical position 1σ, m (0.001 to 10000).
    pub sigma_position_up: f32,
}

/// The INS estimate at the newest IMU sample, with the diagonal 3×3 blocks of its covariance
/// (row-major).
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct est_ins_estimate {
    /// The time of the estimate (the newest IMU sample), ns.
    pub t_ns: u64,
    /// Attitude `w, x, y, z`: the rotation world (ENU) from body, unit norm.
    pub quaternion: [f32; 4],
    /// Velocity, world frame (ENU), m/s.
    pub velocity: [f32; 3],
    /// Position of the IMU, world frame (ENU), m.
    pub position: [f32; 3],
    /// Gyro bias, body frame, rad/s.
    pub gyro_bias: [f32; 3],
    /// Accelerometer bias, body frame, m/s².
    pub accel_bias: [f32; 3],
    /// Covariance of the attitude error (body frame), rad².
    pub attitude_covariance: [f32; 9],
    /// Covariance of the velocity, (m/s)².
    pub velocity_covariance: [f32; 9],
    /// Covariance of the position, m².
    pub position_covariance: [f32; 9],
    /// Covariance of the gyro bias, (rad/s)².
    pub gyro_bias_covariance: [f32; 9],
    /// Covariance of the accelerometer bias, (m/s²)².
    pub accel_bias_covariance: [f32; 9],
}

/// The INS navigator's report after its last call.
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct est_ins_report {
    /// The time of the estimate (the newest IMU sample), ns.
    pub t_ns: u64,
    /// Roll and pitch.
    pub tilt: est_validity,
    /// Yaw.
    pub heading: est_validity,
    /// Velocity.
    pub velocity: est_validity,
    /// Position.
    pub position: est_validity,
    /// Gyro bias.
    pub gyro_bias: est_validity,
    /// Accelerometer bias.
    pub accel_bias: est_validity,
    /// GNSS.
    pub gnss: est_aid_status,
    /// Magnetometer.
    pub magnetometer: est_aid_status,
    /// Barometer.
    pub barometer: est_aid_status,
    /// The last IMU sample was clipped or had a stuck axis.
    pub imu_fault: bool,
    /// What the navigator did on its own in the last call.
    pub event: est_ins_event,
}

/// Counts since init, for logs.
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct est_ins_counters {
    /// IMU samples taken.
    pub imu: u32,
    /// Samples refused with an error by the navigator (any sensor).
    pub refused: u32,
    /// GNSS position updates fused.
    pub gnss_position_fused: u32,
    /// GNSS position updates that failed the gate.
    pub gnss_position_rejected: u32,
    /// GNSS velocity updates fused.
    pub gnss_velocity_fused: u32,
    /// GNSS velocity updates that failed the gate.
    pub gnss_velocity_rejected: u32,
    /// GNSS fixes refused as frozen.
    pub gnss_frozen: u32,
    /// Magnetometer updates fused.
    pub magnetometer_fused: u32,
    /// Magnetometer updates that failed the gate.
    pub magnetometer_rejected: u32,
    /// Magnetometer samples refused for a disturbed norm.
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
    /// Headings set from the GNSS track.
    pub heading_resets: u32,
    /// Zero lateral velocity updates fused.
    pub lateral_fused: u32,
    /// Zero lateral velocity updates rejected.
    pub lateral_rejected: u32,
    /// Windows over which GNSS velocities disagreed with the positions.
    pub gnss_velocity_inconsistent: u32,
    /// Updates or predictions the filter refused (numerical failures, skipped).
    pub numerical_failures: u32,
}

impl From<&InsCounters> for est_ins_counters {
    fn from(c: &InsCounters) -> Self {
        Self {
            imu: c.imu,
            refused: c.refused,
            gnss_position_fused: c.gnss_position_fused,
            gnss_position_rejected: c.gnss_position_rejected,
            gnss_velocity_fused: c.gnss_velocity_fused,
            gnss_velocity_rejected: c.gnss_velocity_rejected,
            gnss_frozen: c.gnss_frozen,
            magnetometer_fused: c.magnetometer_fused,
            magnetometer_rejected: c.magnetometer_rejected,
            magnetometer_disturbed: c.magnetometer_disturbed,
            barometer_fused: c.barometer_fused,
            barometer_rejected: c.barometer_rejected,
            unused: c.unused,
            resets: c.resets,
            realigned: c.realigned,
            imu_faults: c.imu_faults,
            heading_resets: c.heading_resets,
            lateral_fused: c.lateral_fused,
            lateral_rejected: c.lateral_rejected,
            gnss_velocity_inconsistent: c.gnss_velocity_inconsistent,
            numerical_failures: c.numerical_failures,
        }
    }
}

type Nav = InsNavigator<f32>;

/// A 3×3 matrix, row-major.
fn row_major(m: &Matrix3<f32>) -> [f32; 9] {
    [
        m.m11, m.m12, m.m13, m.m21, m.m22, m.m23, m.m31, m.m32, m.m33,
    ]
}

/// Fills `cfg` with `estimator-core`'s defaults
/// (`InsConfig::new(AttitudeConfig::new(FilterConfig::default()))`).
///
/// # Safety
/// `cfg` is NULL or points to writable memory for one `est_ins_config`.
#[no_mangle]
pub unsafe extern "C" fn est_ins_config_default(cfg: *mut est_ins_config) -> est_error {
    let c = InsConfig::new(AttitudeConfig::<f32>::new(FilterConfig::default()));
    // SAFETY: this function's # Safety section covers `cfg` (null and alignment are checked).
    code(unsafe { write_out(cfg, est_ins_config::from_rust(&c)) })
}

/// The size in bytes of the storage of one INS navigator.
#[no_mangle]
pub extern "C" fn est_ins_storage_size() -> usize {
    slot_size::<Nav>()
}

/// The alignment in bytes the storage of an INS navigator needs.
#[no_mangle]
pub extern "C" fn est_ins_storage_align() -> usize {
    slot_align::<Nav>()
}

/// Builds an INS navigator in `storage` and sets `*out` to its handle; as
/// `est_attitude_init`.
///
/// # Safety
/// As `est_attitude_init`, with `est_ins_storage_size()` and `est_ins_storage_align()`.
#[no_mangle]
pub unsafe extern "C" fn est_ins_init(
    storage: *mut c_void,
    size: usize,
    cfg: *const est_ins_config,
    out: *mut *mut est_ins,
) -> est_error {
    // SAFETY: this function's # Safety section covers `storage`, `size`, `cfg` and `out`.
    unsafe {
        init_nav(storage, size, cfg, out, MAGIC_INS, |c: est_ins_config| {
            Nav::new(c.to_rust()?).map_err(est_error::from)
        })
    }
}

/// Takes one IMU sample at `t_ns`: `gyro` (rad/s) and `accel` (specific force, m/s²), body
/// frame, `float[3]` each.
///
/// # Safety
/// `nav` is NULL or a handle from `est_ins_init` (or points to initialized memory of
/// `est_ins_storage_size()` bytes); `gyro` and `accel` are NULL or point to 3 floats.
#[no_mangle]
pub unsafe extern "C" fn est_ins_imu(
    nav: *mut est_ins,
    t_ns: u64,
    gyro: *const f32,
    accel: *const f32,
) -> est_error {
    // SAFETY: this function's # Safety section covers `nav`, `gyro` and `accel`.
    let inputs = unsafe {
        (
            nav_mut::<Nav, _>(nav, MAGIC_INS),
            read_vec3_pair(gyro, accel),
        )
    };
    code(match inputs {
        (Ok(n), Ok((g, a))) => n.imu(t_ns, &g, &a).map(drop).map_err(est_error::from),
        (Err(e), _) | (_, Err(e)) => Err(e),
    })
}

/// Takes one GNSS fix valid at `t_ns` (the time it describes, not when it arrived: up to
/// `horizon_s` in the past).
///
/// # Safety
/// `nav` as in `est_ins_imu`; `fix` is NULL or points to an initialized `est_gnss_fix`.
#[no_mangle]
pub unsafe extern "C" fn est_ins_gnss(
    nav: *mut est_ins,
    t_ns: u64,
    fix: *const est_gnss_fix,
) -> est_error {
    // SAFETY: this function's # Safety section covers `nav` and `fix`.
    let inputs = unsafe { (nav_mut::<Nav, _>(nav, MAGIC_INS), read_in(fix)) };
    code(match inputs {
        (Ok(n), Ok(f)) => {
            let mut g = GnssFix::new(
                Vector3::from(f.position),
                f.has_velocity.then(|| Vector3::from(f.velocity)),
                f.sigma_position,
                f.sigma_velocity,
            );
            if f.has_sigma_position_up {
                g = g.with_vertical_sigma(f.sigma_position_up);
            }
            n.gnss(t_ns, &g).map(drop).map_err(est_error::from)
        }
        (Err(e), _) | (_, Err(e)) => Err(e),
    })
}

/// Takes one magnetometer sample valid at `t_ns`: `field`, body frame, the unit of
/// `magnetometer_sigma`, `float[3]`. Ignored without a configured magnetometer.
///
/// # Safety
/// `nav` as in `est_ins_imu`; `field` is NULL or points to 3 floats.
#[no_mangle]
pub unsafe extern "C" fn est_ins_magnetometer(
    nav: *mut est_ins,
    t_ns: u64,
    field: *const f32,
) -> est_error {
    // SAFETY: this function's # Safety section covers `nav` and `field`.
    let inputs = unsafe { (nav_mut::<Nav, _>(nav, MAGIC_INS), read_vec3(field)) };
    code(match inputs {
        (Ok(n), Ok(f)) => n.magnetometer(t_ns, &f).map(drop).map_err(est_error::from),
        (Err(e), _) | (_, Err(e)) => Err(e),
    })
}

/// Takes one barometric altitude, m (up), valid at `t_ns`. Ignored without a configured
/// barometer.
///
/// # Safety
/// `nav` as in `est_ins_imu`.
#[no_mangle]
pub unsafe extern "C" fn est_ins_barometer(
    nav: *mut est_ins,
    t_ns: u64,
    altitude: f32,
) -> est_error {
    // SAFETY: this function's # Safety section covers `nav`.
    let n = unsafe { nav_mut::<Nav, _>(nav, MAGIC_INS) };
    code(n.and_then(|n| {
        n.barometer(t_ns, altitude)
            .map(drop)
            .map_err(est_error::from)
    }))
}

/// Writes the estimate to `*out`; `EST_ERR_NOT_STARTED` while aligning (before the first GNSS
/// fix is fused).
///
/// # Safety
/// `nav` as in `est_ins_imu`; `out` is NULL or points to a writable `est_ins_estimate`.
#[no_mangle]
pub unsafe extern "C" fn est_ins_get_estimate(
    nav: *const est_ins,
    out: *mut est_ins_estimate,
) -> est_error {
    // SAFETY: this function's # Safety section covers `nav`.
    let n = unsafe { nav_ref::<Nav, _>(nav, MAGIC_INS) };
    let estimate = n.and_then(|n| n.estimate().ok_or(est_error::EST_ERR_NOT_STARTED));
    code(estimate.and_then(|e| {
        let s = &e.state;
        let q = s.attitude.quaternion();
        let [att, vel, pos, bg, ba] = &e.covariance;
        let value = est_ins_estimate {
            t_ns: e.t_ns,
            quaternion: [q.w, q.i, q.j, q.k],
            velocity: vec3(&s.velocity),
            position: vec3(&s.position),
            gyro_bias: vec3(&s.gyro_bias),
            accel_bias: vec3(&s.accel_bias),
            attitude_covariance: row_major(att),
            velocity_covariance: row_major(vel),
            position_covariance: row_major(pos),
            gyro_bias_covariance: row_major(bg),
            accel_bias_covariance: row_major(ba),
        };
        // SAFETY: this function's # Safety section covers `out`.
        unsafe { write_out(out, value) }
    }))
}

/// Writes the report of the last call to `*out`.
///
/// # Safety
/// `nav` as in `est_ins_imu`; `out` is NULL or points to a writable `est_ins_report`.
#[no_mangle]
pub unsafe extern "C" fn est_ins_get_report(
    nav: *const est_ins,
    out: *mut est_ins_report,
) -> est_error {
    // SAFETY: this function's # Safety section covers `nav`.
    let n = unsafe { nav_ref::<Nav, _>(nav, MAGIC_INS) };
    code(n.and_then(|n| {
        let r = n.report();
        let v = &r.validity;
        let value = est_ins_report {
            t_ns: r.t_ns,
            tilt: v.tilt.into(),
            heading: v.heading.into(),
            velocity: v.velocity.into(),
            position: v.position.into(),
            gyro_bias: v.gyro_bias.into(),
            accel_bias: v.accel_bias.into(),
            gnss: r.gnss.into(),
            magnetometer: r.magnetometer.into(),
            barometer: r.barometer.into(),
            imu_fault: r.imu_fault,
            event: r.event.into(),
        };
        // SAFETY: this function's # Safety section covers `out`.
        unsafe { write_out(out, value) }
    }))
}

/// Writes the counts since init to `*out`.
///
/// # Safety
/// `nav` as in `est_ins_imu`; `out` is NULL or points to a writable `est_ins_counters`.
#[no_mangle]
pub unsafe extern "C" fn est_ins_get_counters(
    nav: *const est_ins,
    out: *mut est_ins_counters,
) -> est_error {
    // SAFETY: this function's # Safety section covers `nav`.
    let n = unsafe { nav_ref::<Nav, _>(nav, MAGIC_INS) };
    // SAFETY: this function's # Safety section covers `out`.
    code(n.and_then(|n| unsafe { write_out(out, n.counters().into()) }))
}

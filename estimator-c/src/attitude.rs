//! The attitude navigator (an AHRS): configuration, storage, samples, estimate, report.

use crate::error::{code, est_error};
use crate::report::{est_attitude_event, est_magnetic_status, est_validity};
use crate::storage::{
    init_nav, nav_mut, nav_ref, read_vec3, read_vec3_pair, slot_align, slot_size, vec3, write_out,
    MAGIC_ATTITUDE,
};
use core::ffi::c_void;
use estimator_core::eskf::{FilterConfig, ImuNoise};
use estimator_core::nalgebra::Vector3;
use estimator_core::nav::{
    AttitudeConfig, AttitudeNavigator, Counters, MagneticConfig, MagneticFusion,
};

/// An attitude navigator in caller-provided storage (opaque; the handle `est_attitude_init`
/// returns).
#[allow(non_camel_case_types)]
pub struct est_attitude {
    _opaque: [u8; 0],
}

/// What the magnetometer corrects (`est_attitude_config::magnetometer_fusion`).
#[allow(non_camel_case_types, clippy::upper_case_acronyms)]
#[repr(i32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum est_magnetic_fusion {
    /// The heading only: a wrong field can move the heading but never the tilt (the default;
    /// for real magnetometers near iron).
    EST_FUSION_HEADING = 0,
    /// The whole field, which also measures the tilt: only for a calibrated magnetometer in
    /// a clean, known field.
    EST_FUSION_VECTOR = 1,
}

/// The configuration of an attitude navigator (also the alignment part of an INS's).
/// Fill it with `est_attitude_config_default`, then set what differs. Times in seconds,
/// angles in radians; every field not listed here keeps `estimator-core`'s default
/// (`AttitudeConfig::new`).
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct est_attitude_config {
    /// Gyro white noise density, rad/s/√Hz.
    pub gyro_noise_density: f32,
    /// Gyro bias random walk, rad/s²/√Hz.
    pub gyro_random_walk: f32,
    /// Accelerometer white noise density, m/s²/√Hz.
    pub accel_noise_density: f32,
    /// Accelerometer bias random walk, m/s³/√Hz.
    pub accel_random_walk: f32,
    /// Gravity in the world frame (ENU, z up), m/s²: `{0, 0, -9.81}` by default; its norm
    /// between 0.5 and 50.
    pub gravity: [f32; 3],
    /// The longest IMU interval integrated, s (0.1); a longer one is a gap after which the
    /// navigator starts again. Below 4 s.
    pub max_dt_s: f32,
    /// IMU samples are instantaneous values (a simulator) rather than means over their
    /// interval (a MEMS IMU's decimation filter, the default `false`).
    pub instantaneous_imu: bool,
    /// The body only rotates in place (gimbal, turntable): motion terms left out (`false`).
    pub rotation_only: bool,
    /// Start-up window over which the first attitude is averaged, s (1), below 4 s.
    pub startup_s: f32,
    /// Aiding block length, s (0.25), below 4 s: accelerometer and magnetometer are averaged
    /// over a block and fused at its end.
    pub block_s: f32,
    /// The gyro's full scale, rad/s (±2000 °/s): samples at the rail are flagged as clipped,
    /// beyond it by more than 1 % refused (`EST_ERR_OUT_OF_RANGE`).
    pub gyro_range: f32,
    /// The accelerometer's full scale, m/s² (±16 g), as `gyro_range`.
    pub accel_range: f32,
    /// Tilt (roll, pitch) reported valid while its 1σ is below this, rad (5°).
    pub tilt_valid_sigma: f32,
    /// Heading reported valid while its 1σ is below this, rad (10°).
    pub heading_valid_sigma: f32,
    /// A magnetometer is present (`false` by default): then `magnetometer_sigma` must be set.
    pub has_magnetometer: bool,
    /// The magnetometer's white noise per sample and axis, in its own unit (µT, gauss…);
    /// `> 0` when `has_magnetometer` (0 by default: must be set).
    pub magnetometer_sigma: f32,
    /// The world reference field is given in `magnetometer_reference`; `false` (the
    /// default): learned at start-up from the first samples, which then define north.
    pub has_magnetometer_reference: bool,
    /// The world reference field, ENU, the magnetometer's unit: `{0, B_north, B_up}`.
    pub magnetometer_reference: [f32; 3],
    /// What the magnetometer corrects: an `est_magnetic_fusion` value (`int32_t`).
    pub magnetometer_fusion: i32,
    /// Learn the magnetometer's hard iron (a constant body-frame offset) while the body
    /// turns, and take it off every sample (`true`).
    pub magnetometer_hard_iron: bool,
    /// The magnetometer's delay behind the gyro known beforehand, s (0), at most 0.25.
    pub magnetometer_delay_s: f32,
    /// The largest delay learned, s (0.05), at most 0.25; 0: not learned.
    pub magnetometer_delay_max_s: f32,
}

impl est_attitude_config {
    /// The C view of a Rust configuration (the magnetometer's fields from `mag`, whose
    /// defaults stand in when there is none).
    pub(crate) fn from_rust(c: &AttitudeConfig<f32>) -> Self {
        let mag = c
            .magnetometer
            .unwrap_or_else(|| MagneticConfig::new(0.0, None));
        let n = &c.filter.imu_noise;
        Self {
            gyro_noise_density: n.gyroscope_noise_density,
            gyro_random_walk: n.gyroscope_random_walk,
            accel_noise_density: n.accelerometer_noise_density,
            accel_random_walk: n.accelerometer_random_walk,
            gravity: vec3(&c.filter.gravity),
            max_dt_s: c.filter.max_dt,
            instantaneous_imu: c.instantaneous_imu,
            rotation_only: c.rotation_only,
            startup_s: c.startup_s,
            block_s: c.block_s,
            gyro_range: c.gyro_range,
            accel_range: c.accel_range,
            tilt_valid_sigma: c.tilt_valid_sigma,
            heading_valid_sigma: c.heading_valid_sigma,
            has_magnetometer: c.magnetometer.is_some(),
            magnetometer_sigma: mag.sigma,
            has_magnetometer_reference: mag.reference.is_some(),
            magnetometer_reference: vec3(&mag.reference.unwrap_or_else(Vector3::zeros)),
            magnetometer_fusion: match mag.fusion {
                MagneticFusion::Heading => est_magnetic_fusion::EST_FUSION_HEADING as i32,
                MagneticFusion::Vector => est_magnetic_fusion::EST_FUSION_VECTOR as i32,
            },
            magnetometer_hard_iron: mag.hard_iron,
            magnetometer_delay_s: mag.delay_s,
            magnetometer_delay_max_s: mag.delay_max_s,
        }
    }

    /// The Rust configuration: `estimator-core`'s defaults with these fields set. Its domain
    /// is checked by the navigator's constructor (`AttitudeConfig::validate`); here only the
    /// enum code.
    pub(crate) fn to_rust(self) -> Result<AttitudeConfig<f32>, est_error> {
        let filter = FilterConfig {
            imu_noise: ImuNoise {
                gyroscope_noise_density: self.gyro_noise_density,
                gyroscope_random_walk: self.gyro_random_walk,
                accelerometer_noise_density: self.accel_noise_density,
                accelerometer_random_walk: self.accel_random_walk,
            },
            gravity: Vector3::from(self.gravity),
            max_dt: self.max_dt_s,
        };
        let mut c = AttitudeConfig::new(filter);
        c.instantaneous_imu = self.instantaneous_imu;
        c.rotation_only = self.rotation_only;
        c.startup_s = self.startup_s;
        c.block_s = self.block_s;
        c.gyro_range = self.gyro_range;
        c.accel_range = self.accel_range;
        c.tilt_valid_sigma = self.tilt_valid_sigma;
        c.heading_valid_sigma = self.heading_valid_sigma;
        if self.has_magnetometer {
            let reference = self
                .has_magnetometer_reference
                .then(|| Vector3::from(self.magnetometer_reference));
            let mut m = MagneticConfig::new(self.magnetometer_sigma, reference);
            m.fusion = match self.magnetometer_fusion {
                0 => MagneticFusion::Heading,
                1 => MagneticFusion::Vector,
                _ => return Err(est_error::EST_ERR_INVALID_CONFIG),
            };
            m.hard_iron = self.magnetometer_hard_iron;
            m.delay_s = self.magnetometer_delay_s;
            m.delay_max_s = self.magnetometer_delay_max_s;
            c.magnetometer = Some(m);
        }
        Ok(c)
    }
}

/// The attitude estimate with its uncertainty.
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct est_attitude_estimate {
    /// The time of the estimate (the last IMU sample), ns.
    pub t_ns: u64,
    /// Attitude `w, x, y, z`: the rotation world (ENU) from body, unit norm.
    pub quaternion: [f32; 4],
    /// Gyro bias, body frame, rad/s (subtracted from the samples).
    pub gyro_bias: [f32; 3],
    /// Accelerometer bias, body frame, m/s².
    pub accel_bias: [f32; 3],
    /// 1σ of the tilt (the larger of the two horizontal axes), rad.
    pub sigma_tilt: f32,
    /// 1σ of the heading (about world up), rad.
    pub sigma_heading: f32,
    /// The magnetometer's learned hard iron, body frame, its unit (zero without one).
    pub hard_iron: [f32; 3],
    /// 1σ of the hard iron per axis, the magnetometer's unit.
    pub sigma_hard_iron: [f32; 3],
    /// The magnetometer's learned delay behind the gyro, s.
    pub magnetometer_delay_s: f32,
}

/// The attitude navigator's report after its last call.
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct est_attitude_report {
    /// The time of the estimate (the last IMU sample), ns.
    pub t_ns: u64,
    /// Roll and pitch.
    pub tilt: est_validity,
    /// Yaw against the reference field's north.
    pub heading: est_validity,
    /// The body was found at rest in the last block (zero-rate update applied).
    pub at_rest: bool,
    /// The last IMU sample was at the rail of the gyro or the accelerometer.
    pub clipped: bool,
    /// The magnetometer's state.
    pub magnetic: est_magnetic_status,
    /// What the navigator did on its own in the last call.
    pub event: est_attitude_event,
}

/// Counts since init, for logs.
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct est_attitude_counters {
    /// IMU samples taken.
    pub imu: u32,
    /// Magnetometer samples taken.
    pub magnetometer: u32,
    /// Samples refused with an error by the navigator (errors of the C boundary, such as a
    /// NULL pointer, are not counted: they never reach it).
    pub refused: u32,
    /// Accelerometer blocks fused.
    pub gravity_fused: u32,
    /// Accelerometer blocks that failed the gate.
    pub gravity_rejected: u32,
    /// Magnetometer blocks fused.
    pub heading_fused: u32,
    /// Magnetometer blocks that failed the gate.
    pub heading_rejected: u32,
    /// Magnetometer blocks found disturbed.
    pub magnetic_disturbed: u32,
    /// Zero-rate updates at rest.
    pub zero_rate: u32,
    /// Covariance widenings after repeated rejections.
    pub widened: u32,
    /// Restarts after IMU gaps.
    pub realigned: u32,
    /// New reference fields taken.
    pub new_fields: u32,
    /// New hard-iron offsets learned.
    pub new_hard_irons: u32,
    /// IMU samples at the rail.
    pub clipped: u32,
    /// Magnetometer samples not used because they repeated (stuck).
    pub magnetometer_stuck: u32,
    /// Updates the filter refused (numerical failures, skipped).
    pub numerical_failures: u32,
}

impl From<&Counters> for est_attitude_counters {
    fn from(c: &Counters) -> Self {
        Self {
            imu: c.imu,
            magnetometer: c.magnetometer,
            refused: c.refused,
            gravity_fused: c.gravity_fused,
            gravity_rejected: c.gravity_rejected,
            heading_fused: c.heading_fused,
            heading_rejected: c.heading_rejected,
            magnetic_disturbed: c.magnetic_disturbed,
            zero_rate: c.zero_rate,
            widened: c.widened,
            realigned: c.realigned,
            new_fields: c.new_fields,
            new_hard_irons: c.new_hard_irons,
            clipped: c.clipped,
            magnetometer_stuck: c.magnetometer_stuck,
            numerical_failures: c.numerical_failures,
        }
    }
}

type Nav = AttitudeNavigator<f32>;

/// Fills `cfg` with `estimator-core`'s defaults (`AttitudeConfig::new(FilterConfig::default())`:
/// a consumer MEMS IMU, no magnetometer).
///
/// # Safety
/// `cfg` is NULL or points to writable memory for one `est_attitude_config`.
#[no_mangle]
pub unsafe extern "C" fn est_attitude_config_default(cfg: *mut est_attitude_config) -> est_error {
    let c = AttitudeConfig::<f32>::new(FilterConfig::default());
    // SAFETY: this function's # Safety section covers `cfg` (null and alignment are checked).
    code(unsafe { write_out(cfg, est_attitude_config::from_rust(&c)) })
}

/// The size in bytes of the storage of one attitude navigator.
#[no_mangle]
pub extern "C" fn est_attitude_storage_size() -> usize {
    slot_size::<Nav>()
}

/// The alignment in bytes the storage of an attitude navigator needs.
#[no_mangle]
pub extern "C" fn est_attitude_storage_align() -> usize {
    slot_align::<Nav>()
}

/// Builds an attitude navigator in `storage` and sets `*out` to its handle (which points to
/// `storage`). The configuration is checked as `estimator-core` checks it
/// (`EST_ERR_INVALID_CONFIG`, or `EST_ERR_FILTER` for the noise densities, gravity or
/// `max_dt_s`). On any error nothing is written. Init again to restart.
///
/// # Safety
/// `storage` is NULL or points to `size` writable bytes, aligned to
/// `est_attitude_storage_align()` (checked), that nothing else uses while the navigator lives;
/// `cfg` is NULL or points to an initialized `est_attitude_config`; `out` is NULL or points to
/// a writable `est_attitude *`.
#[no_mangle]
pub unsafe extern "C" fn est_attitude_init(
    storage: *mut c_void,
    size: usize,
    cfg: *const est_attitude_config,
    out: *mut *mut est_attitude,
) -> est_error {
    // SAFETY: this function's # Safety section covers `storage`, `size`, `cfg` and `out`.
    unsafe {
        init_nav(
            storage,
            size,
            cfg,
            out,
            MAGIC_ATTITUDE,
            |c: est_attitude_config| Nav::new(c.to_rust()?).map_err(est_error::from),
        )
    }
}

/// Takes one IMU sample at `t_ns`: `gyro` (rad/s) and `accel` (specific force, m/s²), body
/// frame, `float[3]` each.
///
/// # Safety
/// `nav` is NULL or a handle from `est_attitude_init` (or points to initialized memory of
/// `est_attitude_storage_size()` bytes); `gyro` and `accel` are NULL or point to 3 floats.
#[no_mangle]
pub unsafe extern "C" fn est_attitude_imu(
    nav: *mut est_attitude,
    t_ns: u64,
    gyro: *const f32,
    accel: *const f32,
) -> est_error {
    // SAFETY: this function's # Safety section covers `nav`, `gyro` and `accel`.
    let inputs = unsafe {
        (
            nav_mut::<Nav, _>(nav, MAGIC_ATTITUDE),
            read_vec3_pair(gyro, accel),
        )
    };
    code(match inputs {
        (Ok(n), Ok((g, a))) => n.imu(t_ns, &g, &a).map(drop).map_err(est_error::from),
        (Err(e), _) | (_, Err(e)) => Err(e),
    })
}

/// Takes one magnetometer sample at `t_ns`: `field`, body frame, the unit of
/// `magnetometer_sigma`, `float[3]`. Ignored without a configured magnetometer.
///
/// # Safety
/// As `est_attitude_imu`; `field` is NULL or points to 3 floats.
#[no_mangle]
pub unsafe extern "C" fn est_attitude_magnetometer(
    nav: *mut est_attitude,
    t_ns: u64,
    field: *const f32,
) -> est_error {
    // SAFETY: this function's # Safety section covers `nav` and `field`.
    let inputs = unsafe { (nav_mut::<Nav, _>(nav, MAGIC_ATTITUDE), read_vec3(field)) };
    code(match inputs {
        (Ok(n), Ok(f)) => n.magnetometer(t_ns, &f).map(drop).map_err(est_error::from),
        (Err(e), _) | (_, Err(e)) => Err(e),
    })
}

/// Writes the estimate to `*out`; `EST_ERR_NOT_STARTED` while the start-up window is being
/// collected.
///
/// # Safety
/// `nav` as in `est_attitude_imu`; `out` is NULL or points to a writable
/// `est_attitude_estimate`.
#[no_mangle]
pub unsafe extern "C" fn est_attitude_get_estimate(
    nav: *const est_attitude,
    out: *mut est_attitude_estimate,
) -> est_error {
    // SAFETY: this function's # Safety section covers `nav`.
    let n = unsafe { nav_ref::<Nav, _>(nav, MAGIC_ATTITUDE) };
    let estimate = n.and_then(|n| n.estimate().ok_or(est_error::EST_ERR_NOT_STARTED));
    code(estimate.and_then(|e| {
        let q = e.attitude.quaternion();
        let value = est_attitude_estimate {
            t_ns: e.t_ns,
            quaternion: [q.w, q.i, q.j, q.k],
            gyro_bias: vec3(&e.gyro_bias),
            accel_bias: vec3(&e.accel_bias),
            sigma_tilt: e.sigma_tilt,
            sigma_heading: e.sigma_heading,
            hard_iron: vec3(&e.hard_iron),
            sigma_hard_iron: vec3(&e.sigma_hard_iron),
            magnetometer_delay_s: e.magnetometer_delay_s,
        };
        // SAFETY: this function's # Safety section covers `out`.
        unsafe { write_out(out, value) }
    }))
}

/// Writes the report of the last call to `*out`.
///
/// # Safety
/// `nav` as in `est_attitude_imu`; `out` is NULL or points to a writable
/// `est_attitude_report`.
#[no_mangle]
pub unsafe extern "C" fn est_attitude_get_report(
    nav: *const est_attitude,
    out: *mut est_attitude_report,
) -> est_error {
    // SAFETY: this function's # Safety section covers `nav`.
    let n = unsafe { nav_ref::<Nav, _>(nav, MAGIC_ATTITUDE) };
    code(n.and_then(|n| {
        let r = n.report();
        let value = est_attitude_report {
            t_ns: r.t_ns,
            tilt: r.tilt.into(),
            heading: r.heading.into(),
            at_rest: r.at_rest,
            clipped: r.clipped,
            magnetic: r.magnetic.into(),
            event: r.event.into(),
        };
        // SAFETY: this function's # Safety section covers `out`.
        unsafe { write_out(out, value) }
    }))
}

/// Writes the counts since init to `*out`.
///
/// # Safety
/// `nav` as in `est_attitude_imu`; `out` is NULL or points to a writable
/// `est_attitude_counters`.
#[no_mangle]
pub unsafe extern "C" fn est_attitude_get_counters(
    nav: *const est_attitude,
    out: *mut est_attitude_counters,
) -> est_error {
    // SAFETY: this function's # Safety section covers `nav`.
    let n = unsafe { nav_ref::<Nav, _>(nav, MAGIC_ATTITUDE) };
    // SAFETY: this function's # Safety section covers `out`.
    code(n.and_then(|n| unsafe { write_out(out, n.counters().into()) }))
}

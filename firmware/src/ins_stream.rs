//! The INS navigator's stream, synthesized (the embedded host-sim stream has GNSS only in the
//! 15-state filter's 2 s, too short for a navigator that aligns from switch-on first): a level
//! vehicle driving straight at constant velocity, yaw 0.5 rad, read by an IMU at 200 Hz, a
//! magnetometer at 50 Hz and a GNSS receiver at 5 Hz (position and velocity), each sample with
//! a small deterministic noise (a hash of the sample's index, uniform in `[−s, s]`) and the IMU
//! with constant biases. The magnetometer samples and the fixes are stamped with the time they
//! were valid and delivered `DELAY_NS` (0.2 s) later, after the IMU sample of their arrival, as
//! a receiver's fixes reach a main loop. The truth is known in closed form ([`truth_position`]).
//!
//! The same stream without its magnetometer samples is the navigator's without a magnetometer
//! ([`config_without_magnetometer`]): its heading found by the bank of yaw hypotheses from the
//! GNSS track (estimator-core's `nav/ins/yaw.rs`; at constant velocity the accelerations say
//! nothing of it, the track along the body's `x` axis does). The stream's track,
//! `atan2(0.6, 1.2)` = 0.464 rad, is 0.036 rad off its yaw (a crab of 0.049 m/s sideways): a
//! heading found from the track is that far from the truth.

use crate::scenario::{attitude_config, Scalar};
use estimator_core::lie::{LieGroup, So3};
use estimator_core::nav::{GnssFix, InsConfig};
use estimator_core::Real;
use nalgebra::Vector3;

/// The first IMU sample's time, ns.
pub const T0_NS: u64 = 1_000_000_000;
/// IMU period, ns (200 Hz).
pub const DT_NS: u64 = 5_000_000;
/// IMU samples: 8 s.
pub const IMU_SAMPLES: u64 = 1_601;
/// IMU samples per magnetometer sample (50 Hz) and per GNSS fix (5 Hz).
const MAG_EVERY: u64 = 4;
const GNSS_EVERY: u64 = 40;
/// How late the magnetometer samples and the fixes arrive after their time of validity, ns.
pub const DELAY_NS: u64 = 200_000_000;
/// Fix 1σ: position (m per axis), velocity (m/s per axis).
const SIGMA_P: f64 = 1.0;
const SIGMA_V: f64 = 0.1;

/// One delivered sample, in the order a main loop gets them.
#[derive(Clone, Copy, Debug)]
pub enum InsSample<T: Real> {
    /// Gyroscope (rad/s) and accelerometer (m/s²), body frame, at `t_ns`.
    Imu {
        t_ns: u64,
        gyro: Vector3<T>,
        accel: Vector3<T>,
    },
    /// Magnetometer (µT), body frame, valid at `t_ns` (delivered `DELAY_NS` later).
    Mag { t_ns: u64, field: Vector3<T> },
    /// A GNSS fix valid at `t_ns` (delivered `DELAY_NS` later).
    Gnss { t_ns: u64, fix: GnssFix<T> },
}

/// The navigator's configuration: the attitude navigator's of the embedded stream (its IMU
/// noise, the magnetometer's σ and reference field), the INS defaults around it (0.3 s horizon).
pub fn config<T: Scalar>() -> InsConfig<T> {
    InsConfig::new(attitude_config::<T>())
}

/// The configuration without a magnetometer: [`config`] with none configured, the rest
/// `InsConfig::new`'s defaults. The navigator's heading is then unknown until the bank of yaw
/// hypotheses resolves it from the GNSS velocities (estimator-core's `nav/ins/heading.rs`).
pub fn config_without_magnetometer<T: Scalar>() -> InsConfig<T> {
    let mut c = config::<T>();
    c.attitude.magnetometer = None;
    c
}

#[inline(always)]
fn lit3<T: Real>(x: f64, y: f64, z: f64) -> Vector3<T> {
    Vector3::new(T::lit(x), T::lit(y), T::lit(z))
}

/// The true velocity (m/s, ENU).
#[inline(always)]
pub fn truth_velocity<T: Real>() -> Vector3<T> {
    lit3(1.2, 0.6, 0.0)
}

/// The true position at `t_ns` (m, ENU).
pub fn truth_position<T: Real>(t_ns: u64) -> Vector3<T> {
    let since = u32::try_from((t_ns.saturating_sub(T0_NS)) / 1_000_000).unwrap_or(u32::MAX);
    let t = T::from_count(since) * T::lit(1e-3);
    lit3::<T>(20.0, -8.0, 3.0) + truth_velocity::<T>() * t
}

/// The true attitude (world from body): level, yaw 0.5 rad.
pub fn truth_attitude<T: Real>() -> So3<T> {
    So3::exp(&lit3(0.0, 0.0, 0.5))
}

/// A noise in `[−s, s]` for sample `k` of channel `c` (a hash, deterministic).
fn noise<T: Real>(k: u64, c: u64, s: T) -> T {
    let mut x = k
        .wrapping_mul(0x9E37_79B9_7F4A_7C15)
        .wrapping_add(c.wrapping_mul(0xBF58_476D_1CE4_E5B9));
    x ^= x >> 31;
    x = x.wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^= x >> 29;
    let u = u32::try_from(x >> 40).unwrap_or(0); // 24 bits
    (T::from_count(u) * T::lit(1.0 / 8_388_608.0) - T::one()) * s
}

fn noise3<T: Real>(k: u64, c: u64, s: T) -> Vector3<T> {
    Vector3::new(noise(k, c, s), noise(k, c + 1, s), noise(k, c + 2, s))
}

/// Calls `f` with every sample in delivery order: IMU sample `k`, then the magnetometer sample
/// and the fix valid `DELAY_NS` before it, if any.
pub fn samples<T: Scalar>(mut f: impl FnMut(InsSample<T>)) {
    let config = attitude_config::<T>();
    let reference = config
        .magnetometer
        .and_then(|m| m.reference)
        .unwrap_or_else(Vector3::zeros);
    let body_from_world = truth_attitude::<T>().inverse();
    let field = body_from_world.act(&reference);
    let specific_force = body_from_world.act(&(-config.filter.gravity));
    let (gyro_bias, accel_bias) = (
        lit3::<T>(0.003, -0.002, 0.001),
        lit3::<T>(0.02, -0.015, 0.01),
    );
    let delay = DELAY_NS / DT_NS;
    for k in 0..IMU_SAMPLES {
        let t_ns = T0_NS + k * DT_NS;
        f(InsSample::Imu {
            t_ns,
            gyro: gyro_bias + noise3(k, 0, T::lit(0.002)),
            accel: specific_force + accel_bias + noise3(k, 3, T::lit(0.03)),
        });
        let Some(j) = k.checked_sub(delay) else {
            continue;
        };
        let valid = T0_NS + j * DT_NS;
        if j % MAG_EVERY == 0 {
            f(InsSample::Mag {
                t_ns: valid,
                field: field + noise3(j, 6, T::lit(0.3)),
            });
        }
        // The receiver's first fix is valid 0.2 s after switch-on (one valid at the first IMU
        // sample would be older than the filter's time, which starts there: refused).
        if j % GNSS_EVERY == 0 && j > 0 {
            let fix = GnssFix::new(
                truth_position::<T>(valid) + noise3(j, 9, T::lit(0.6)),
                Some(truth_velocity::<T>() + noise3(j, 12, T::lit(0.05))),
                T::lit(SIGMA_P),
                T::lit(SIGMA_V),
            );
            f(InsSample::Gnss { t_ns: valid, fix });
        }
    }
}

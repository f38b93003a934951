//! A firmware-style main loop on the host: the attitude navigator and the INS navigator fed
//! one timestamped sample at a time, every outcome handled, the estimate printed once a second.
//!
//! The sensors are a stand-in (a body turning slowly about the vertical at rest on a turntable,
//! with white noise): replace `read_sensors` by your drivers. Run with
//! `cargo run --release -p estimator-core --example main_loop`.
//!
//! What each piece does:
//! * [`AttitudeNavigator`]: attitude and gyro bias from gyro, accelerometer and magnetometer.
//!   It starts itself (the first second of samples), chooses what to fuse, detects rest and
//!   magnetic disturbances, and says after every call which parts of its estimate are valid.
//! * [`InsNavigator`]: position, velocity, attitude and both IMU biases from the IMU, GNSS and
//!   the magnetometer. It aligns until the first fix, fuses every measurement at the time it
//!   was valid (a fix delivered 0.2 s late is stamped with its own time), handles frozen,
//!   jumping and drifting fixes, and reports each quantity's validity after every call. A
//!   device with GNSS needs only this one; the attitude navigator is shown for one without.
//!
//! Tuning: the noise densities come from the sensor (`host-sim calibrate` measures them from a
//! static recording); the navigator's other parameters are explained in the `nav` module docs.

use estimator_core::eskf::{FilterConfig, ImuNoise};
use estimator_core::lie::{LieGroup, So3};
use estimator_core::nav::{
    AttitudeConfig, AttitudeNavigator, GnssFix, InsConfig, InsNavigator, MagneticConfig, NavError,
};
use nalgebra::Vector3;

const IMU_HZ: u64 = 200;
const MAG_EVERY: u64 = 4; // 50 Hz
const GNSS_EVERY: u64 = 40; // 5 Hz
const FIELD: [f32; 3] = [0.0, 20.0, -45.0]; // µT, ENU: north and down
const GNSS_LATENCY_NS: u64 = 200_000_000; // a fix arrives 0.2 s after the time it describes

/// One reading of every sensor at sample `k` (the stand-in for the drivers).
struct Sensors {
    t_ns: u64,
    gyro: Vector3<f32>,
    accel: Vector3<f32>,
    mag: Option<Vector3<f32>>,
    gnss: Option<Vector3<f32>>,
}

/// A small deterministic noise (a real loop reads the drivers instead).
fn noise(k: u64, axis: u64, scale: f32) -> f32 {
    let x = (k
        .wrapping_mul(6_364_136_223_846_793_005)
        .wrapping_add(axis * 1_442_695_040_888_963_407)
        >> 40) as f32;
    (x / (1u64 << 24) as f32 - 0.5) * 2.0 * scale
}

fn read_sensors(k: u64) -> Sensors {
    let t = k as f32 / IMU_HZ as f32;
    // Level, turning about up at 10 °/s after the first 2 s.
    let rate = if t < 2.0 { 0.0 } else { 10f32.to_radians() };
    let yaw = if t < 2.0 { 0.0 } else { rate * (t - 2.0) };
    let attitude = So3::<f32>::exp(&Vector3::new(0.0, 0.0, yaw));
    let n3 = |s: f32, a: u64| Vector3::new(noise(k, a, s), noise(k, a + 1, s), noise(k, a + 2, s));
    Sensors {
        t_ns: 1_000_000_000 + k * (1_000_000_000 / IMU_HZ),
        gyro: Vector3::new(0.002, -0.001, rate) + n3(0.003, 0),
        accel: Vector3::new(0.0, 0.0, 9.81) + n3(0.03, 3),
        mag: k
            .is_multiple_of(MAG_EVERY)
            .then(|| attitude.inverse().act(&Vector3::from(FIELD)) + n3(0.3, 6)),
        gnss: k.is_multiple_of(GNSS_EVERY).then(|| n3(0.5, 9)),
    }
}

fn main() {
    let noise_densities = ImuNoise {
        gyroscope_noise_density: 2e-4,
        gyroscope_random_walk: 2e-5,
        accelerometer_noise_density: 2e-3,
        accelerometer_random_walk: 3e-3,
    };
    let filter = FilterConfig {
        imu_noise: noise_densities,
        ..FilterConfig::default()
    };

    // The attitude navigator: a configuration, then one call per sample.
    let mut config = AttitudeConfig::new(filter);
    config.magnetometer = Some(MagneticConfig::new(0.3, Some(Vector3::from(FIELD))));
    let mut nav = match AttitudeNavigator::new(config) {
        Ok(n) => n,
        Err(e) => return eprintln!("configuration refused: {e}"),
    };

    // The INS navigator: the same attitude configuration (it aligns with it until the first
    // fix), a 0.3 s horizon for late measurements.
    let mut ins: InsNavigator<f32> = match InsNavigator::new(InsConfig::new(config)) {
        Ok(n) => n,
        Err(e) => return eprintln!("configuration refused: {e}"),
    };

    for k in 0..20 * IMU_HZ {
        let s = read_sensors(k);
        match nav.imu(s.t_ns, &s.gyro, &s.accel) {
            Ok(report) => {
                if let Some(event) = report.event {
                    println!("{:6.2} s  navigator: {event:?}", k as f32 / IMU_HZ as f32);
                }
            }
            // A refused sample leaves the navigator as it was: log it and go on.
            Err(NavError::TimeNotIncreasing) => eprintln!("IMU sample out of order, dropped"),
            Err(e) => eprintln!("IMU sample refused: {e}"),
        }
        match ins.imu(s.t_ns, &s.gyro, &s.accel) {
            Ok(report) => {
                if let Some(event) = report.event {
                    println!("{:6.2} s  INS: {event:?}", k as f32 / IMU_HZ as f32);
                }
            }
            Err(e) => eprintln!("INS: IMU sample refused: {e}"),
        }
        if let Some(m) = s.mag {
            if let Err(e) = nav.magnetometer(s.t_ns, &m) {
                eprintln!("magnetometer sample refused: {e}");
            }
            if let Err(e) = ins.magnetometer(s.t_ns, &m) {
                eprintln!("INS: magnetometer sample refused: {e}");
            }
        }
        // A fix read now describes the time `GNSS_LATENCY_NS` ago: stamp it with that time.
        if let Some(p) = s.gnss {
            let fix = GnssFix::new(p, Some(Vector3::zeros()), 1.0, 0.1);
            match ins.gnss(s.t_ns.saturating_sub(GNSS_LATENCY_NS), &fix) {
                Ok(_) => {}
                // Older than the horizon (the first fix, before the filter's start) or a
                // duplicate: nothing to do but log it.
                Err(NavError::TooOld) => eprintln!("GNSS fix older than the horizon, dropped"),
                Err(e) => eprintln!("GNSS fix refused: {e}"),
            }
        }

        if k.is_multiple_of(IMU_HZ) {
            if let Some(e) = nav.estimate() {
                let (roll, pitch, yaw) = e.attitude.quaternion().euler_angles();
                let r = nav.report();
                println!(
                    "{:6.2} s  roll {:6.2}° pitch {:6.2}° yaw {:7.2}° (±{:.2}°, tilt {}, heading {}), at rest {}",
                    k as f32 / IMU_HZ as f32,
                    roll.to_degrees(),
                    pitch.to_degrees(),
                    yaw.to_degrees(),
                    e.sigma_heading.to_degrees(),
                    if r.tilt.is_valid() { "valid" } else { "invalid" },
                    if r.heading.is_valid() { "valid" } else { "invalid" },
                    r.at_rest
                );
            }
            if let Some(e) = ins.estimate() {
                let (x, v) = (e.state.position, ins.report().validity);
                println!(
                    "          INS position {:6.2} {:6.2} {:6.2} m ({:?}), velocity {:5.2} m/s ({:?}), GNSS {:?}",
                    x.x,
                    x.y,
                    x.z,
                    v.position,
                    e.state.velocity.norm(),
                    v.velocity,
                    ins.report().gnss
                );
            }
        }
    }
    let c = ins.counters();
    println!(
        "INS: {} IMU samples, {} GNSS positions fused, {} gated out, {} magnetometer updates, {} refused",
        c.imu, c.gnss_position_fused, c.gnss_position_rejected, c.magnetometer_fused, c.refused
    );
    let c = nav.counters();
    println!(
        "navigator: {} IMU and {} magnetometer samples, {} refused, {} zero-rate updates, {} accelerometer and {} heading blocks fused",
        c.imu, c.magnetometer, c.refused, c.zero_rate, c.gravity_fused, c.heading_fused
    );
}

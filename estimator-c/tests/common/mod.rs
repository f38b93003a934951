//! What the tests share: a deterministic sensor stream of a turning body, the configuration it
//! is run with, and the C compiler.
#![allow(dead_code)] // each test file uses a part

use estimator_core::lie::{LieGroup, So3};
use estimator_core::nalgebra::Vector3;
use std::process::Command;

/// The world field, µT, ENU (north and down).
pub const FIELD: [f32; 3] = [0.0, 20.0, -45.0];
pub const IMU_HZ: u64 = 200;
const STEP_NS: u64 = 1_000_000_000 / IMU_HZ;

/// One sensor sample, body frame.
#[derive(Clone, Copy, Debug)]
pub enum Sample {
    Imu {
        t_ns: u64,
        gyro: [f32; 3],
        accel: [f32; 3],
    },
    Mag {
        t_ns: u64,
        field: [f32; 3],
    },
}

/// A small deterministic noise in [-scale, scale].
fn noise(k: u64, axis: u64, scale: f64) -> f64 {
    let x = (k
        .wrapping_mul(6_364_136_223_846_793_005)
        .wrapping_add((axis + 1).wrapping_mul(1_442_695_040_888_963_407))
        >> 40) as f64;
    (x / (1u64 << 24) as f64 - 0.5) * 2.0 * scale
}

/// `seconds` of a body at rest for 2 s, then turning about all three axes (rates up to
/// 0.5 rad/s, a full turn in yaw every 13 s) in place: IMU at 200 Hz, magnetometer at 50 Hz,
/// with white noise. Returns the samples and the true attitude (world from body) at the end.
pub fn turning_body(seconds: u64) -> (Vec<Sample>, So3<f64>) {
    let field = Vector3::new(FIELD[0] as f64, FIELD[1] as f64, FIELD[2] as f64);
    let gravity_up = Vector3::new(0.0, 0.0, 9.81);
    let mut attitude = So3::<f64>::exp(&Vector3::new(0.05, -0.03, 0.4));
    let mut samples = Vec::new();
    let f3 = |v: Vector3<f64>| [v.x as f32, v.y as f32, v.z as f32];
    for k in 0..seconds * IMU_HZ {
        let t = k as f64 / IMU_HZ as f64;
        let rate = if t < 2.0 {
            Vector3::zeros()
        } else {
            Vector3::new(0.3 * (0.7 * t).sin(), 0.2 * (0.5 * t).cos(), 0.5)
        };
        let t_ns = 1_000_000_000 + k * STEP_NS;
        let n3 = |axis: u64, s: f64| {
            Vector3::new(
                noise(k, axis, s),
                noise(k, axis + 1, s),
                noise(k, axis + 2, s),
            )
        };
        let to_body = attitude.inverse();
        samples.push(Sample::Imu {
            t_ns,
            gyro: f3(rate + n3(0, 0.003)),
            accel: f3(to_body.act(&gravity_up) + n3(3, 0.03)),
        });
        if k % 4 == 0 {
            samples.push(Sample::Mag {
                t_ns,
                field: f3(to_body.act(&field) + n3(6, 0.3)),
            });
        }
        attitude = attitude.compose(&So3::exp(&(rate / IMU_HZ as f64)));
    }
    (samples, attitude)
}

/// The stream as the C replay program reads it: floats as the hex of their bits.
pub fn stream_text(samples: &[Sample]) -> String {
    let mut s = String::new();
    for sample in samples {
        match sample {
            Sample::Imu { t_ns, gyro, accel } => {
                s.push_str(&format!("I {t_ns}"));
                for v in gyro.iter().chain(accel) {
                    s.push_str(&format!(" {:08x}", v.to_bits()));
                }
            }
            Sample::Mag { t_ns, field } => {
                s.push_str(&format!("M {t_ns}"));
                for v in field {
                    s.push_str(&format!(" {:08x}", v.to_bits()));
                }
            }
        }
        s.push('\n');
    }
    s
}

/// `cc` (or `$CC`), or `None` with a message where there is no C compiler.
pub fn c_compiler() -> Option<String> {
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".to_owned());
    match Command::new(&cc).arg("--version").output() {
        Ok(o) if o.status.success() => Some(cc),
        _ => {
            eprintln!("skipped: no C compiler `{cc}` on this machine");
            None
        }
    }
}

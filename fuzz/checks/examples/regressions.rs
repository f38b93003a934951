//! Writes the hand-made regression inputs of `fuzz/regressions/` (the findings reported
//! before the fuzzer ran, written out as inputs the targets decode to the same calls):
//!
//! ```sh
//! cargo run --manifest-path fuzz/checks/Cargo.toml --example regressions
//! ```
//!
//! Each input is described next to its bytes; `KNOWN.md` lists those that still break a
//! promise.

use estimator_fuzz_checks::input::Encoder;
use std::path::Path;

/// Filter choice bytes of the filters target.
const INS_F32: u8 = 0;
const AHRS_F32: u8 = 2;
const AHRS_F64: u8 = 3;

/// Operation bytes of the filters target.
const PREDICT: u8 = 0;
const PREDICT_RUN: u8 = 1;
/// `Heading` in the Ahrs' operations.
const AHRS_HEADING: u8 = 6;
/// `BaroAltitude` in the Ins' operations.
const INS_BARO: u8 = 6;

/// An IMU sample given exactly: gyro and accel as `vec3`, `dt` as a general real.
fn imu<T: estimator_fuzz_checks::input::Scalar>(e: &mut Encoder, gyro: [T; 3], dt: T) {
    e.byte(255).vec3(gyro);
    e.byte(255).vec3([T::zero(), T::zero(), T::lit(9.81)]);
    e.general(dt);
}

/// Update options: the gate byte (3 off, 4 a threshold), one iteration, the default tolerance.
fn options_off(e: &mut Encoder) {
    e.byte(3).byte(0).byte(0);
}

fn write(dir: &Path, name: &str, e: &Encoder) {
    let path = dir.join(name);
    std::fs::write(&path, &e.bytes).unwrap_or_else(|err| panic!("{}: {err}", path.display()));
    println!("{} ({} bytes)", path.display(), e.bytes.len());
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../regressions");
    let filters = root.join("filters");
    std::fs::create_dir_all(&filters).expect("regressions/filters");

    // `Ins<f32>::new` with a gyro noise density of 1e20 (its `σ² dt` overflows `f32`), then a
    // prediction: refused at construction, so the run goes on with the fallback filter.
    let mut e = Encoder::new();
    e.byte(INS_F32).byte(0); // Ins<f32>, `new`
    e.byte(0); // attitude: identity
    for _ in 0..4 {
        e.byte(3); // velocity, position, biases: zero
    }
    e.byte(0).general(0.1f32); // P = 0.1² I
    e.byte(1).real(1e20f32); // config: gyroscope_noise_density = 1e20
    e.byte(PREDICT);
    imu(&mut e, [0.1f32, 0.0, 0.0], 0.01);
    write(&filters, "noise-density-overflow-f32", &e);

    // `Ahrs<f32>` with P = diag(1e-2 × 3, 1e-6 × 3), ten predictions with ω = (0.3, −0.2, 0.5)
    // and dt = 0.01, then `Heading::new(0.1, 1e-5)` with the gate off.
    let mut e = Encoder::new();
    e.byte(AHRS_F32).byte(0); // Ahrs<f32>, `new`
    e.byte(0).byte(3); // attitude identity, gyro bias zero
    e.byte(1); // P: a diagonal of variances
    for v in [1e-2f32, 1e-2, 1e-2, 1e-6, 1e-6, 1e-6] {
        e.general(v);
    }
    e.byte(0); // default configuration
    e.byte(PREDICT_RUN);
    imu(&mut e, [0.3f32, -0.2, 0.5], 0.01);
    e.byte(8); // 2 + 8 = 10 predictions
    e.byte(AHRS_HEADING).real(0.1f32).byte(0).general(1e-5f32);
    options_off(&mut e);
    write(&filters, "heading-tiny-sigma-ahrs-f32", &e);

    // `Ahrs<f64>::from_alignment` with the defaults (level, zero bias, `InitialSigmas` and
    // `FilterConfig` defaults), one prediction with ω = (0, −2.836, −2.086) and dt = 0.1, then a
    // `Heading` of yaw 5e-324 and noise R = 5e-324 with the gate off.
    let mut e = Encoder::new();
    e.byte(AHRS_F64).byte(1); // Ahrs<f64>, `from_alignment`
    e.byte(0).byte(0).byte(3).byte(0); // given directly: identity, zero gyro bias
    e.byte(0).byte(0); // default sigmas and configuration
    e.byte(PREDICT);
    imu(&mut e, [0.0f64, -2.836, -2.086], 0.1);
    e.byte(AHRS_HEADING)
        .real(5e-324f64)
        .byte(255)
        .real(5e-324f64);
    options_off(&mut e);
    write(&filters, "heading-subnormal-noise-ahrs-f64", &e);

    // `Ins<f32>` default, then a `BaroAltitude` update gated by `Gate::Threshold(-1.0)`.
    let mut e = Encoder::new();
    e.byte(INS_F32).byte(2);
    e.byte(INS_BARO)
        .real(1.0f32)
        .byte(0)
        .byte(0)
        .general(0.5f32);
    e.byte(4).real(-1.0f32).byte(0).byte(0);
    write(&filters, "negative-gate-threshold", &e);

    lie(&root.join("lie"));
}

/// A moderate 1.0: scale 1, fraction 65535 (the top of `[−1, 1]`).
fn moderate_one(e: &mut Encoder) {
    e.byte(3).u16(u16::MAX);
}

/// The Lie-group inputs: one round each (byte 0: a whole-range round) on the group chosen by
/// the first byte.
fn lie(dir: &Path) {
    std::fs::create_dir_all(dir).expect("regressions/lie");
    const SO2_F32: u8 = 0;
    const SO2_F64: u8 = 1;
    const SE2_F32: u8 = 2;
    const SE2_F64: u8 = 3;
    const SO3_F32: u8 = 4;
    const SO3_F64: u8 = 5;
    const SE3_F32: u8 = 6;
    const SE3_F64: u8 = 7;

    // `So3::exp_jac` and `So3::right_jacobian` of ω = (1e155, 0, 0) (f64) and (1e20, 0, 0)
    // (f32): `θ²` overflows; then the unit quaternion 1 for `from_quaternion`.
    let mut e = Encoder::new();
    e.byte(SO3_F64).byte(0).vec3([1e155f64, 0.0, 0.0]);
    for x in [1.0f64, 0.0, 0.0, 0.0] {
        e.real(x);
    }
    write(dir, "so3-f64-huge-rotation-vector", &e);
    let mut e = Encoder::new();
    e.byte(SO3_F32).byte(0).vec3([1e20f32, 0.0, 0.0]);
    for x in [1.0f32, 0.0, 0.0, 0.0] {
        e.real(x);
    }
    write(dir, "so3-f32-huge-rotation-vector", &e);

    // `Se3::exp`, `exp_jac`, `right_jacobian` of ξ = (1, 1, 1, 1e155, 0, 0) (f64) and
    // (1, 1, 1, 1e20, 0, 0) (f32).
    let mut e = Encoder::new();
    e.byte(SE3_F64).byte(0);
    for _ in 0..3 {
        moderate_one(&mut e);
    }
    e.vec3([1e155f64, 0.0, 0.0]);
    write(dir, "se3-f64-huge-rotation-vector", &e);
    let mut e = Encoder::new();
    e.byte(SE3_F32).byte(0);
    for _ in 0..3 {
        moderate_one(&mut e);
    }
    e.vec3([1e20f32, 0.0, 0.0]);
    write(dir, "se3-f32-huge-rotation-vector", &e);

    // `Se2::exp`, `exp_jac`, `right_jacobian` of τ = (1, 1, 1e155) (f64) and (1, 1, 1e20) (f32).
    let mut e = Encoder::new();
    e.byte(SE2_F64).byte(0);
    moderate_one(&mut e);
    moderate_one(&mut e);
    e.real(1e155f64);
    write(dir, "se2-f64-huge-angle", &e);
    let mut e = Encoder::new();
    e.byte(SE2_F32).byte(0);
    moderate_one(&mut e);
    moderate_one(&mut e);
    e.real(1e20f32);
    write(dir, "se2-f32-huge-angle", &e);

    // `So2::from_cos_sin(1e200, 0)` and `(1e-200, 0)` (f64), `(1e30, 0)` and `(1e-30, 0)`
    // (f32): `None`, where the docs promise a rotation for any finite non-zero input.
    let mut e = Encoder::new();
    e.byte(SO2_F64);
    for re in [1e200f64, 1e-200] {
        e.byte(0).real(1.0f64).real(re).real(0.0f64);
    }
    write(dir, "so2-f64-from-cos-sin-extreme", &e);
    let mut e = Encoder::new();
    e.byte(SO2_F32);
    for re in [1e30f32, 1e-30] {
        e.byte(0).real(1.0f32).real(re).real(0.0f32);
    }
    write(dir, "so2-f32-from-cos-sin-extreme", &e);
}

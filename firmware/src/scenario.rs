//! The embedded data stream and the run of every estimator on it, generic over the scalar.
//!
//! Shared, unchanged, by the firmware (`src/bin/demo.rs`, in `f32`) and the host tool
//! (`host-check/`, in `f64` and `f32`), which prints the expected values committed in
//! `src/expected.rs`. The stream is computed from a few constants by a deterministic generator
//! (no integer-to-float conversion, no `f64` arithmetic in `f32`): 2 s of a 100 Hz IMU on a
//! rotating, accelerating body, a 10 Hz GNSS position and a 20 Hz magnetometer, and 20 landmarks
//! seen by a pinhole camera for PnP. The "noise" is a sum of incommensurate sines, so the f32 and
//! f64 runs see the same data up to rounding.

use estimator_core::eskf::{
    Ahrs, AhrsState, FilterConfig, Gate, GateProbability, GnssPosition, GravityDirection, Ins,
    InsState, Magnetometer, UpdateOptions,
};
use estimator_core::gn::{solve_pnp, PinholeCamera, PnpOptions};
use estimator_core::lie::{LieGroup, Se3, So3};
use estimator_core::Real;
use nalgebra::{SMatrix, Vector2, Vector3, Vector6};

/// IMU steps in the stream (100 Hz).
pub const STEPS: usize = 200;
/// Landmarks in the PnP problem.
pub const PNP_POINTS: usize = 20;

/// Pseudo-noise in `[-1, 1]`: a fixed sum of sines of `t`, distinct per `channel` (0..).
pub fn wobble<T: Real>(t: T, channel: T) -> T {
    let a = t * (T::lit(37.3) + T::lit(5.71) * channel) + T::lit(0.7) * channel;
    let b = t * (T::lit(91.7) - T::lit(3.13) * channel) + T::lit(1.9) * channel;
    T::lit(0.6) * a.sincos().0 + T::lit(0.4) * b.sincos().1
}

/// Three channels of [`wobble`] from `c`, scaled by `s`.
pub fn noise3<T: Real>(t: T, c: T, s: T) -> Vector3<T> {
    Vector3::new(
        s * wobble(t, c),
        s * wobble(t, c + T::one()),
        s * wobble(t, c + T::lit(2.0)),
    )
}

fn v3<T: Real>(x: f64, y: f64, z: f64) -> Vector3<T> {
    Vector3::new(T::lit(x), T::lit(y), T::lit(z))
}

/// Everything the demo compares, as plain numbers (quaternions `w, x, y, z`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Outcome<T> {
    /// `So3::exp([0.3, -0.2, 0.9])` as a quaternion.
    pub so3_exp: [T; 4],
    /// `log` of that rotation composed with itself.
    pub so3_log: [T; 3],
    /// `log(Se3::exp(a) · Se3::exp(b))`.
    pub se3_log: [T; 6],
    /// INS: final attitude quaternion, velocity, position, trace of P.
    pub ins_q: [T; 4],
    /// INS final velocity (m/s).
    pub ins_v: [T; 3],
    /// INS final position (m).
    pub ins_p: [T; 3],
    /// Accepted GNSS and magnetometer updates of the INS.
    pub ins_accepted: u32,
    /// AHRS: final attitude quaternion.
    pub ahrs_q: [T; 4],
    /// AHRS final gyro bias (rad/s).
    pub ahrs_bg: [T; 3],
    /// Accepted AHRS updates.
    pub ahrs_accepted: u32,
    /// PnP camera-from-world quaternion.
    pub pnp_q: [T; 4],
    /// PnP camera-from-world translation.
    pub pnp_t: [T; 3],
    /// Truth errors (for the sanity bound): INS position error norm (m), INS attitude error (rad),
    /// AHRS attitude error (rad), PnP rotation (rad) and translation (m) error.
    pub truth_errors: [T; 5],
    /// Non-zero when something returned an error: the stage that failed.
    pub failure: u32,
}

fn quat<T: Real>(r: &So3<T>) -> [T; 4] {
    let q = r.quaternion();
    // One sign for the comparison (w ≥ 0).
    let s = if q.w < T::zero() { -T::one() } else { T::one() };
    [q.w * s, q.i * s, q.j * s, q.k * s]
}

/// The filters, the inputs of one more call of each, and the PnP problem: what the demo
/// benchmarks after the run (instructions, stack).
pub struct Workload<T: Real> {
    /// The INS at the end of the stream.
    pub ins: Ins<T>,
    /// The AHRS at the end of the stream.
    pub ahrs: Ahrs<T>,
    /// One more IMU sample.
    pub imu: estimator_core::eskf::ImuSample<T>,
    /// One more GNSS position.
    pub gnss: GnssPosition<T>,
    /// One more magnetometer sample (INS and AHRS).
    pub mag: Magnetometer<T>,
    /// One more accelerometer sample as a gravity direction (AHRS).
    pub gravity: GravityDirection<T>,
    /// Update options (EKF, 99.9 % gate).
    pub options: UpdateOptions<T>,
    /// PnP landmarks.
    pub world: [Vector3<T>; PNP_POINTS],
    /// PnP pixels.
    pub pixels: [Vector2<T>; PNP_POINTS],
    /// PnP camera.
    pub camera: PinholeCamera<T>,
    /// PnP initial guess.
    pub guess: Se3<T>,
    /// PnP options.
    pub pnp_options: PnpOptions<T>,
}

/// Runs everything; returns the outcome and the workload for the benchmarks.
pub fn run<T: Real>() -> (Outcome<T>, Workload<T>) {
    let z = T::zero();
    let mut out = Outcome {
        so3_exp: [z; 4],
        so3_log: [z; 3],
        se3_log: [z; 6],
        ins_q: [z; 4],
        ins_v: [z; 3],
        ins_p: [z; 3],
        ins_accepted: 0,
        ahrs_q: [z; 4],
        ahrs_bg: [z; 3],
        ahrs_accepted: 0,
        pnp_q: [z; 4],
        pnp_t: [z; 3],
        truth_errors: [z; 5],
        failure: 0,
    };

    // --- Lie groups.
    let r = So3::<T>::exp(&v3(0.3, -0.2, 0.9));
    out.so3_exp = quat(&r);
    let l = r.compose(&r).log();
    out.so3_log = [l[0], l[1], l[2]];
    let a = Se3::<T>::exp(&Vector6::new(
        T::lit(0.5),
        T::lit(-1.0),
        T::lit(2.0),
        T::lit(0.1),
        T::lit(0.4),
        T::lit(-0.3),
    ));
    let b = Se3::<T>::exp(&Vector6::new(
        T::lit(-0.2),
        T::lit(0.3),
        T::lit(0.1),
        T::lit(-0.6),
        T::lit(0.2),
        T::lit(0.5),
    ));
    let x = a.compose(&b).log();
    out.se3_log = [x[0], x[1], x[2], x[3], x[4], x[5]];

    // --- The inertial stream.
    let config = FilterConfig::<T>::default();
    let g = config.gravity;
    let dt = T::lit(0.01);
    let gyro_bias = v3::<T>(0.004, -0.003, 0.002);
    let accel_bias = v3::<T>(0.05, -0.04, 0.03);
    let mag_world = v3::<T>(20.0, 5.0, -40.0);
    let options = UpdateOptions::ekf(Gate::Probability(GateProbability::P999));

    let mut truth_r = So3::<T>::exp(&v3(0.05, -0.04, 0.6));
    let mut truth_v = v3::<T>(0.3, 0.0, 0.0);
    let mut truth_p = v3::<T>(1.0, 2.0, 0.5);

    let init_err = So3::<T>::exp(&v3(0.02, -0.015, 0.05));
    let mut p0 = SMatrix::<T, 15, 15>::zeros();
    // Initial 1-σ: attitude 0.05/0.05/0.1 rad, velocity 0.2 m/s, position 0.5 m, gyro bias
    // 0.01 rad/s, accelerometer bias 0.1 m/s² (variances written out: no f64 at run time).
    let var = [
        T::lit(0.0025),
        T::lit(0.0025),
        T::lit(0.01),
        T::lit(0.04),
        T::lit(0.04),
        T::lit(0.04),
        T::lit(0.25),
        T::lit(0.25),
        T::lit(0.25),
        T::lit(1e-4),
        T::lit(1e-4),
        T::lit(1e-4),
        T::lit(0.01),
        T::lit(0.01),
        T::lit(0.01),
    ];
    for (i, v) in var.iter().enumerate() {
        p0[(i, i)] = *v;
    }
    let ins0 = InsState {
        attitude: truth_r.compose(&init_err),
        velocity: truth_v + v3(0.1, -0.1, 0.05),
        position: truth_p + v3(0.4, -0.3, 0.2),
        gyro_bias: Vector3::zeros(),
        accel_bias: Vector3::zeros(),
    };
    let mut ins = match Ins::new(ins0, p0, config) {
        Ok(f) => f,
        Err(_) => {
            out.failure = 1;
            return (out, dummy_workload(config, options));
        }
    };
    let mut pa = SMatrix::<T, 6, 6>::zeros();
    for i in 0..6 {
        pa[(i, i)] = if i < 3 { T::lit(0.01) } else { T::lit(1e-4) };
    }
    let ahrs0 = AhrsState {
        attitude: truth_r.compose(&init_err),
        gyro_bias: Vector3::zeros(),
    };
    let mut ahrs = match Ahrs::new(ahrs0, pa, config) {
        Ok(f) => f,
        Err(_) => {
            out.failure = 2;
            return (out, dummy_workload(config, options));
        }
    };

    let mut t = z;
    let mut imu = estimator_core::eskf::ImuSample {
        gyro: Vector3::zeros(),
        accel: Vector3::zeros(),
        dt,
    };
    let mut gnss = GnssPosition::new(truth_p, Vector3::zeros(), T::lit(0.1));
    let mut mag = Magnetometer::new(mag_world, mag_world, T::lit(0.5));
    let mut gravity = GravityDirection::new(-g, T::lit(0.05));
    for k in 0..STEPS {
        // Truth over [t, t + dt]: body rate and world acceleration held constant.
        let w = Vector3::new(
            T::lit(0.3) * (T::lit(1.3) * t).sincos().0,
            T::lit(0.2) * (T::lit(0.7) * t).sincos().1,
            T::lit(0.5),
        );
        let acc = Vector3::new(
            T::lit(0.5) * (T::lit(0.9) * t).sincos().1,
            T::lit(0.3) * (T::lit(1.1) * t).sincos().0,
            T::lit(0.1) * (T::lit(2.0) * t).sincos().0,
        );
        imu.gyro = w + gyro_bias + noise3(t, T::lit(0.0), T::lit(2e-3));
        imu.accel =
            truth_r.inverse().act(&(acc - g)) + accel_bias + noise3(t, T::lit(3.0), T::lit(2e-2));
        gravity = GravityDirection::new(imu.accel, T::lit(0.05));
        if ins.predict(&imu).is_err() {
            out.failure = 3;
        }
        if ahrs.predict(&imu.gyro, dt).is_err() {
            out.failure = 4;
        }
        truth_p += truth_v * dt + acc * (T::lit(0.5) * dt * dt);
        truth_v += acc * dt;
        truth_r = truth_r.compose(&So3::exp(&(w * dt)));
        t += dt;

        if k % 5 == 4 {
            let m = truth_r.inverse().act(&mag_world) + noise3(t, T::lit(6.0), T::lit(0.3));
            mag = Magnetometer::new(m, mag_world, T::lit(0.5));
            match ins.update(&mag, &options) {
                Ok(o) if o.is_accepted() => out.ins_accepted += 1,
                Ok(_) => {}
                Err(_) => out.failure = 5,
            }
            match ahrs.update(&mag, &options) {
                Ok(o) if o.is_accepted() => out.ahrs_accepted += 1,
                Ok(_) => {}
                Err(_) => out.failure = 6,
            }
            match ahrs.update(&gravity, &options) {
                Ok(o) if o.is_accepted() => out.ahrs_accepted += 1,
                Ok(_) => {}
                Err(_) => out.failure = 7,
            }
        }
        if k % 10 == 9 {
            gnss = GnssPosition::new(
                truth_p + noise3(t, T::lit(9.0), T::lit(0.05)),
                Vector3::zeros(),
                T::lit(0.1),
            );
            match ins.update(&gnss, &options) {
                Ok(o) if o.is_accepted() => out.ins_accepted += 1,
                Ok(_) => {}
                Err(_) => out.failure = 8,
            }
        }
    }
    let s = ins.state();
    out.ins_q = quat(&s.attitude);
    out.ins_v = [s.velocity[0], s.velocity[1], s.velocity[2]];
    out.ins_p = [s.position[0], s.position[1], s.position[2]];
    out.ahrs_q = quat(&ahrs.state().attitude);
    let bg = ahrs.state().gyro_bias;
    out.ahrs_bg = [bg[0], bg[1], bg[2]];
    out.truth_errors[0] = (s.position - truth_p).norm();
    out.truth_errors[1] = truth_r.between(&s.attitude).log().norm();
    out.truth_errors[2] = truth_r.between(&ahrs.state().attitude).log().norm();

    // --- PnP: 20 landmarks 4-7 m in front of the camera.
    let camera = PinholeCamera::new(T::lit(400.0), T::lit(400.0), T::lit(320.0), T::lit(240.0));
    let truth_cw = Se3::<T>::exp(&Vector6::new(
        T::lit(0.1),
        T::lit(-0.2),
        T::lit(0.3),
        T::lit(0.05),
        T::lit(-0.1),
        T::lit(0.02),
    ));
    let mut world = [Vector3::zeros(); PNP_POINTS];
    let mut pixels = [Vector2::zeros(); PNP_POINTS];
    let mut j = z;
    for (pw, px) in world.iter_mut().zip(pixels.iter_mut()) {
        // Points spread in the camera frame, mapped to the world with the true pose.
        let c = Vector3::new(
            T::lit(2.2) * (T::lit(1.7) * j + T::lit(0.3)).sincos().0,
            T::lit(1.6) * (T::lit(2.9) * j + T::lit(1.1)).sincos().0,
            T::lit(5.5) + T::lit(1.5) * (T::lit(1.3) * j).sincos().1,
        );
        *pw = truth_cw.inverse().act(&c);
        let uv = camera
            .project(&c, T::lit(1e-3))
            .unwrap_or_else(Vector2::zeros);
        *px = uv
            + Vector2::new(
                T::lit(0.3) * wobble(j, T::lit(12.0)),
                T::lit(0.3) * wobble(j, T::lit(13.0)),
            );
        j += T::one();
    }
    let guess = truth_cw.rplus(&Vector6::new(
        T::lit(0.2),
        T::lit(-0.1),
        T::lit(0.15),
        T::lit(0.05),
        T::lit(0.04),
        T::lit(-0.06),
    ));
    let pnp_options = PnpOptions::default().with_sigma(T::lit(0.3));
    match solve_pnp(&world, &pixels, &camera, &guess, &pnp_options) {
        Ok(sol) => {
            out.pnp_q = quat(&sol.camera_from_world.rotation());
            let tr = sol.camera_from_world.translation();
            out.pnp_t = [tr[0], tr[1], tr[2]];
            let e = truth_cw.between(&sol.camera_from_world).log();
            out.truth_errors[3] = Vector3::new(e[3], e[4], e[5]).norm();
            out.truth_errors[4] = (truth_cw.translation() - tr).norm();
        }
        Err(_) => out.failure = 9,
    }

    let work = Workload {
        ins,
        ahrs,
        imu,
        gnss,
        mag,
        gravity,
        options,
        world,
        pixels,
        camera,
        guess,
        pnp_options,
    };
    (out, work)
}

fn dummy_workload<T: Real>(config: FilterConfig<T>, options: UpdateOptions<T>) -> Workload<T> {
    let mut p = SMatrix::<T, 15, 15>::identity();
    p *= T::lit(0.01);
    let mut pa = SMatrix::<T, 6, 6>::identity();
    pa *= T::lit(0.01);
    let ins = Ins::new(InsState::identity(), p, config);
    let ahrs = Ahrs::new(AhrsState::identity(), pa, config);
    // `new` cannot fail on these inputs with the default configuration; loop rather than panic.
    let (ins, ahrs) = match (ins, ahrs) {
        (Ok(i), Ok(a)) => (i, a),
        _ => loop {
            core::hint::spin_loop();
        },
    };
    Workload {
        ins,
        ahrs,
        imu: estimator_core::eskf::ImuSample {
            gyro: Vector3::zeros(),
            accel: -config.gravity,
            dt: T::lit(0.01),
        },
        gnss: GnssPosition::new(Vector3::zeros(), Vector3::zeros(), T::one()),
        mag: Magnetometer::new(Vector3::x(), Vector3::x(), T::one()),
        gravity: GravityDirection::new(-config.gravity, T::one()),
        options,
        world: [Vector3::zeros(); PNP_POINTS],
        pixels: [Vector2::zeros(); PNP_POINTS],
        camera: PinholeCamera::new(T::one(), T::one(), T::zero(), T::zero()),
        guess: Se3::identity(),
        pnp_options: PnpOptions::default(),
    }
}

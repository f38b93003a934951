//! The run of every estimator on the embedded stream, generic over the scalar.
//!
//! Shared, unchanged, by the firmware (`src/bin/demo.rs`, in `f32`) and the host tool
//! (`host-check/`, in `f64` and `f32`), which prints the expected values committed in
//! `src/expected.rs`. The data is `src/stream.rs`: 2 s of host-sim's `default` scenario for the
//! 15-state filter (IMU 200 Hz, magnetometer 50 Hz, GNSS position and velocity 5 Hz), 2 s of
//! its `handheld_ahrs` scenario for the attitude-only filter (IMU 200 Hz, magnetometer 50 Hz),
//! and one frame of its `camera` scenario for PnP (20 landmarks), each with its ground truth;
//! generated once by `tools/make_stream.sh` and committed. The numbers are `f32`; the `f64`
//! run widens them exactly, so both runs see the same data.
//!
//! The filters run as `host-sim replay` runs them: each IMU interval integrated with the mean
//! of its two samples (the simulator's samples are instantaneous), a measurement applied after
//! the IMU sample of its timestamp, the attitude-only filter's tilt aiding from the
//! accelerometer every fourth sample while `|‖f‖ − g| < 1 m/s²`, with host-sim's noise rule.
//! The filters start from the truth displaced by a fixed error (below) inside their initial
//! covariance; PnP starts from the true pose displaced by 0.2 m and 0.1 rad.

use estimator_core::eskf::{
    AccelerometerAtRest, Ahrs, AhrsState, BaroAltitude, CameraLandmark, FilterConfig, GnssPosition,
    GnssVelocity, GravityDirection, Heading, ImuNoise, ImuSample, Ins, InsState, Magnetometer,
    UpdateOptions, ZeroVelocity,
};
use estimator_core::gn::{solve_pnp, PinholeCamera, PnpOptions};
use estimator_core::lie::{LieGroup, Se3, So3};
use estimator_core::Real;
use nalgebra::{Matrix3, SMatrix, Vector2, Vector3, Vector6};

#[path = "stream.rs"]
pub mod stream;

use stream::Truth;

/// Landmarks in the PnP problem.
pub const PNP_POINTS: usize = 20;

/// The scalars the scenario runs in, with the exact conversion of the stream's `f32` numbers
/// (identity in `f32`, widening in `f64`: no `f64` operation in the `f32` firmware).
pub trait Scalar: Real {
    /// `x` in `Self`, exactly.
    fn of(x: f32) -> Self;
}

impl Scalar for f32 {
    fn of(x: f32) -> f32 {
        x
    }
}

impl Scalar for f64 {
    fn of(x: f32) -> f64 {
        f64::from(x)
    }
}

fn v3<T: Scalar>(a: &[f32; 3]) -> Vector3<T> {
    Vector3::new(T::of(a[0]), T::of(a[1]), T::of(a[2]))
}

/// Literals as `T`. Always inlined, so each `T::lit` folds to a constant (a call at run time
/// would convert `f64` to `f32` in software on the Cortex-M4F).
#[inline(always)]
fn lit3<T: Real>(x: f64, y: f64, z: f64) -> Vector3<T> {
    Vector3::new(T::lit(x), T::lit(y), T::lit(z))
}

/// Six literals as a `T` vector (always inlined, as [`lit3`]).
#[inline(always)]
fn lit6<T: Real>(a: f64, b: f64, c: f64, d: f64, e: f64, f: f64) -> Vector6<T> {
    Vector6::new(
        T::lit(a),
        T::lit(b),
        T::lit(c),
        T::lit(d),
        T::lit(e),
        T::lit(f),
    )
}

fn attitude<T: Scalar>(t: &Truth) -> Option<So3<T>> {
    let q = &t.attitude_wxyz;
    So3::from_wxyz(T::of(q[0]), T::of(q[1]), T::of(q[2]), T::of(q[3]))
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
    /// INS: final attitude quaternion.
    pub ins_q: [T; 4],
    /// INS final velocity (m/s).
    pub ins_v: [T; 3],
    /// INS final position (m).
    pub ins_p: [T; 3],
    /// Accepted GNSS (position, velocity) and magnetometer updates of the INS.
    pub ins_accepted: u32,
    /// AHRS: final attitude quaternion.
    pub ahrs_q: [T; 4],
    /// AHRS final gyro bias (rad/s).
    pub ahrs_bg: [T; 3],
    /// Accepted AHRS updates (magnetometer and gravity direction).
    pub ahrs_accepted: u32,
    /// PnP camera-from-world quaternion.
    pub pnp_q: [T; 4],
    /// PnP camera-from-world translation.
    pub pnp_t: [T; 3],
    /// Errors against the truth: INS position (m) and attitude (rad), AHRS attitude (rad), PnP
    /// rotation (rad) and translation (m), INS gyro bias (rad/s) and accelerometer bias (m/s²),
    /// AHRS gyro bias (rad/s); the attitude errors are `‖log(R̂ᵀ R)‖`, the others norms.
    pub truth_errors: [T; 8],
    /// The bound each error is checked against: three times the root of the trace of the
    /// estimator's own covariance block (a 3-σ radius).
    pub truth_bounds: [T; 8],
    /// Non-zero when something returned an error: the stage that failed.
    pub failure: u32,
}

fn quat<T: Real>(r: &So3<T>) -> [T; 4] {
    let q = r.quaternion();
    // One sign for the comparison (w ≥ 0).
    let s = if q.w < T::zero() { -T::one() } else { T::one() };
    [q.w * s, q.i * s, q.j * s, q.k * s]
}

/// `3·√(tr P[i..i+3, i..i+3])`: the 3-σ radius of a three-component block.
fn radius3<T: Real, const N: usize>(p: &SMatrix<T, N, N>, i: usize) -> T {
    let tr = p[(i, i)] + p[(i + 1, i + 1)] + p[(i + 2, i + 2)];
    T::lit(3.0) * tr.sqrt()
}

/// One more call of every update model and of each predict, at the end of the stream: what the
/// demo benchmarks (instructions, stack). Each measurement is made consistent with the filter's
/// estimate (its predicted value, displaced by about one sigma), so that every benchmarked
/// update is accepted and runs its whole path.
pub struct Workload<T: Real> {
    /// The INS at the end of the stream.
    pub ins: Ins<T>,
    /// The INS nearly at rest (a few cm/s, the same covariance), for the at-rest models.
    pub ins_at_rest: Ins<T>,
    /// The AHRS at the end of the stream.
    pub ahrs: Ahrs<T>,
    /// One more IMU sample.
    pub imu: ImuSample<T>,
    /// GNSS position.
    pub gnss_position: GnssPosition<T>,
    /// GNSS velocity.
    pub gnss_velocity: GnssVelocity<T>,
    /// Magnetometer, for the INS.
    pub ins_mag: Magnetometer<T>,
    /// Gravity direction, for the INS.
    pub ins_gravity: GravityDirection<T>,
    /// Barometric altitude.
    pub baro: BaroAltitude<T>,
    /// Heading, for the INS.
    pub ins_heading: Heading<T>,
    /// Zero velocity (for `ins_at_rest`).
    pub zero_velocity: ZeroVelocity<T>,
    /// The accelerometer at rest (for `ins_at_rest`).
    pub at_rest: AccelerometerAtRest<T>,
    /// A camera landmark 5 m in front of the camera.
    pub landmark: CameraLandmark<T>,
    /// Magnetometer, for the AHRS.
    pub ahrs_mag: Magnetometer<T>,
    /// Gravity direction, for the AHRS.
    pub ahrs_gravity: GravityDirection<T>,
    /// Heading, for the AHRS.
    pub ahrs_heading: Heading<T>,
    /// Update options (EKF, 99.9 % gate).
    pub options: UpdateOptions<T>,
    /// Iterated update options (at most 5 iterations, step tolerance 1e-6), for the landmark.
    pub iterated: UpdateOptions<T>,
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

/// The filter configuration of a stream: its IMU noise, ENU gravity, the default `max_dt`.
fn config<T: Scalar>(noise: &[f32; 4]) -> FilterConfig<T> {
    FilterConfig {
        imu_noise: ImuNoise {
            gyroscope_noise_density: T::of(noise[0]),
            gyroscope_random_walk: T::of(noise[1]),
            accelerometer_noise_density: T::of(noise[2]),
            accelerometer_random_walk: T::of(noise[3]),
        },
        ..FilterConfig::default()
    }
}

/// The IMU interval from sample `k` to `k + 1`: the mean of its two ends (trapezoidal rule).
fn interval<T: Scalar>(imu: &[[f32; 6]], k: usize, dt: T) -> Option<ImuSample<T>> {
    let (a, b) = (imu.get(k)?, imu.get(k + 1)?);
    let half = T::lit(0.5);
    let m = |i: usize| (T::of(a[i]) + T::of(b[i])) * half;
    Some(ImuSample {
        gyro: Vector3::new(m(0), m(1), m(2)),
        accel: Vector3::new(m(3), m(4), m(5)),
        dt,
    })
}

/// The fixed error the filters start with: attitude (rad, right perturbation), velocity (m/s),
/// position (m).
fn start_error<T: Real>() -> (Vector3<T>, Vector3<T>, Vector3<T>) {
    (
        lit3(0.02, -0.015, 0.05),
        lit3(0.1, -0.1, 0.05),
        lit3(0.4, -0.3, 0.2),
    )
}

/// Runs everything; returns the outcome and the workload for the benchmarks, or the stage that
/// failed (the outcome's `failure`) when a filter or the solver could not even start.
pub fn run<T: Scalar>() -> (Outcome<T>, Option<Workload<T>>) {
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
        truth_errors: [z; 8],
        truth_bounds: [z; 8],
        failure: 0,
    };
    lie(&mut out);
    let work = match (ins(&mut out), ahrs(&mut out), pnp(&mut out)) {
        (Some(ins), Some(ahrs), Some(p)) => Some(workload(ins, ahrs, p)),
        _ => None,
    };
    (out, work)
}

fn lie<T: Real>(out: &mut Outcome<T>) {
    let r = So3::<T>::exp(&lit3(0.3, -0.2, 0.9));
    out.so3_exp = quat(&r);
    let l = r.compose(&r).log();
    out.so3_log = [l[0], l[1], l[2]];
    let a = Se3::<T>::exp(&lit6(0.5, -1.0, 2.0, 0.1, 0.4, -0.3));
    let b = Se3::<T>::exp(&lit6(-0.2, 0.3, 0.1, -0.6, 0.2, 0.5));
    let x = a.compose(&b).log();
    out.se3_log = [x[0], x[1], x[2], x[3], x[4], x[5]];
}

/// Counts an accepted update; records `stage` on an error.
fn tally<T: Real>(
    r: Result<estimator_core::eskf::UpdateOutcome<T>, estimator_core::eskf::EskfError>,
    accepted: &mut u32,
    failure: &mut u32,
    stage: u32,
) {
    match r {
        Ok(o) if o.is_accepted() => *accepted += 1,
        Ok(_) => {}
        Err(_) => *failure = stage,
    }
}

/// The 15-state filter over `stream::ins`.
fn ins<T: Scalar>(out: &mut Outcome<T>) -> Option<Ins<T>> {
    use stream::ins as s;
    let cfg = config::<T>(&s::IMU_NOISE);
    let options = UpdateOptions::default();
    let (Some(r0), Some(r1)) = (attitude::<T>(&s::TRUTH_START), attitude::<T>(&s::TRUTH_END))
    else {
        out.failure = 1;
        return None;
    };
    let (e_att, e_v, e_p) = start_error::<T>();
    let x0 = InsState {
        attitude: r0.rplus(&e_att),
        velocity: v3::<T>(&s::TRUTH_START.velocity) + e_v,
        position: v3::<T>(&s::TRUTH_START.position) + e_p,
        gyro_bias: Vector3::zeros(),
        accel_bias: Vector3::zeros(),
    };
    // Initial 1-σ: attitude 0.05/0.05/0.1 rad, velocity 0.2 m/s, position 0.5 m, gyro bias
    // 0.03 rad/s (host-sim's turn-on bias reaches 0.024), accelerometer bias 0.1 m/s².
    let (att, yaw) = (T::lit(0.05 * 0.05), T::lit(0.1 * 0.1));
    let (vel, pos) = (T::lit(0.2 * 0.2), T::lit(0.5 * 0.5));
    let (bg, ba) = (T::lit(0.03 * 0.03), T::lit(0.1 * 0.1));
    let var = [
        att, att, yaw, vel, vel, vel, pos, pos, pos, bg, bg, bg, ba, ba, ba,
    ];
    let p0 = SMatrix::<T, 15, 15>::from_fn(|i, j| if i == j { var[i] } else { T::zero() });
    let Ok(mut f) = Ins::new(x0, p0, cfg) else {
        out.failure = 2;
        return None;
    };
    let dt = T::of(s::DT);
    let reference = v3::<T>(&s::MAG_REFERENCE);
    let lever = v3::<T>(&s::GNSS_LEVER_ARM);
    let (mut mags, mut fixes) = (s::MAG.iter().peekable(), s::GNSS.iter().peekable());
    for k in 0..s::IMU.len() - 1 {
        let Some(imu) = interval(&s::IMU, k, dt) else {
            out.failure = 3;
            return None;
        };
        if f.predict(&imu).is_err() {
            out.failure = 3;
        }
        while let Some((_, m)) = mags.next_if(|(i, _)| *i == k + 1) {
            let model = Magnetometer::new(v3(m), reference, T::of(s::MAG_SIGMA));
            tally(
                f.update(&model, &options),
                &mut out.ins_accepted,
                &mut out.failure,
                4,
            );
        }
        while let Some(g) = fixes.next_if(|g| g.imu_index == k + 1) {
            let position = GnssPosition::new(v3(&g.position), lever, T::of(g.sigma_p));
            tally(
                f.update(&position, &options),
                &mut out.ins_accepted,
                &mut out.failure,
                5,
            );
            let velocity = GnssVelocity::new(v3(&g.velocity), T::of(g.sigma_v));
            tally(
                f.update(&velocity, &options),
                &mut out.ins_accepted,
                &mut out.failure,
                6,
            );
        }
    }
    let x = f.state();
    out.ins_q = quat(&x.attitude);
    out.ins_v = [x.velocity[0], x.velocity[1], x.velocity[2]];
    out.ins_p = [x.position[0], x.position[1], x.position[2]];
    out.truth_errors[0] = (x.position - v3::<T>(&s::TRUTH_END.position)).norm();
    out.truth_errors[1] = x.attitude.between(&r1).log().norm();
    out.truth_errors[5] = (x.gyro_bias - v3::<T>(&s::TRUTH_END.gyro_bias)).norm();
    out.truth_errors[6] = (x.accel_bias - v3::<T>(&s::TRUTH_END.accel_bias)).norm();
    let p = f.covariance();
    out.truth_bounds[0] = radius3(p, 6);
    out.truth_bounds[1] = radius3(p, 0);
    out.truth_bounds[5] = radius3(p, 9);
    out.truth_bounds[6] = radius3(p, 12);
    Some(f)
}

/// The attitude-only filter over `stream::ahrs`.
fn ahrs<T: Scalar>(out: &mut Outcome<T>) -> Option<Ahrs<T>> {
    use stream::ahrs as s;
    let cfg = config::<T>(&s::IMU_NOISE);
    let options = UpdateOptions::default();
    let (Some(r0), Some(r1)) = (attitude::<T>(&s::TRUTH_START), attitude::<T>(&s::TRUTH_END))
    else {
        out.failure = 11;
        return None;
    };
    let x0 = AhrsState {
        attitude: r0.rplus(&start_error::<T>().0),
        gyro_bias: Vector3::zeros(),
    };
    // Initial 1-σ: attitude 0.1 rad, gyro bias 0.03 rad/s.
    let p0 = SMatrix::<T, 6, 6>::from_fn(|i, j| match (i == j, i < 3) {
        (true, true) => T::lit(0.01),
        (true, false) => T::lit(9e-4),
        _ => T::zero(),
    });
    let Ok(mut f) = Ahrs::new(x0, p0, cfg) else {
        out.failure = 12;
        return None;
    };
    let dt = T::of(s::DT);
    let reference = v3::<T>(&s::MAG_REFERENCE);
    let g = cfg.gravity.norm();
    // host-sim replay's tilt-aiding noise: the accelerometer's white noise as a direction,
    // σ_a·√rate/g, plus twice the mismatch beyond its 3 σ, plus a 0.02 rad floor.
    let white = T::of(s::IMU_NOISE[2]) / (dt.sqrt() * g);
    let mut mags = s::MAG.iter().peekable();
    for k in 0..s::IMU.len() - 1 {
        let Some(imu) = interval(&s::IMU, k, dt) else {
            out.failure = 13;
            return None;
        };
        if f.predict(&imu).is_err() {
            out.failure = 13;
        }
        let now = k + 1;
        if let (true, Some(a)) = (now % 4 == 0, s::IMU.get(now)) {
            let accel = Vector3::new(T::of(a[3]), T::of(a[4]), T::of(a[5]));
            let mismatch = (accel.norm() - g).abs();
            if mismatch < T::one() {
                let excess = (mismatch - T::lit(3.0) * white * g).max(T::zero());
                let m = T::lit(2.0) * excess / g;
                let sigma = (white * white + m * m + T::lit(4e-4)).sqrt();
                let model = GravityDirection::new(accel, sigma);
                tally(
                    f.update(&model, &options),
                    &mut out.ahrs_accepted,
                    &mut out.failure,
                    14,
                );
            }
        }
        while let Some((_, m)) = mags.next_if(|(i, _)| *i == now) {
            let model = Magnetometer::new(v3(m), reference, T::of(s::MAG_SIGMA));
            tally(
                f.update(&model, &options),
                &mut out.ahrs_accepted,
                &mut out.failure,
                15,
            );
        }
    }
    let x = f.state();
    out.ahrs_q = quat(&x.attitude);
    out.ahrs_bg = [x.gyro_bias[0], x.gyro_bias[1], x.gyro_bias[2]];
    out.truth_errors[2] = x.attitude.between(&r1).log().norm();
    out.truth_errors[7] = (x.gyro_bias - v3::<T>(&s::TRUTH_END.gyro_bias)).norm();
    out.truth_bounds[2] = radius3(f.covariance(), 0);
    out.truth_bounds[7] = radius3(f.covariance(), 3);
    Some(f)
}

/// The PnP problem of `stream::pnp` and its solve.
struct Pnp<T: Real> {
    world: [Vector3<T>; PNP_POINTS],
    pixels: [Vector2<T>; PNP_POINTS],
    camera: PinholeCamera<T>,
    guess: Se3<T>,
    options: PnpOptions<T>,
    body_from_camera: Se3<T>,
    sigma_px: T,
}

fn pnp<T: Scalar>(out: &mut Outcome<T>) -> Option<Pnp<T>> {
    use stream::pnp as s;
    let k = &s::INTRINSICS;
    let camera = PinholeCamera::new(T::of(k[0]), T::of(k[1]), T::of(k[2]), T::of(k[3]));
    let m = &s::BODY_FROM_CAMERA_R;
    let rbc = So3::from_rotation_matrix(&Matrix3::from_fn(|i, j| T::of(m[3 * i + j])));
    let (Some(rbc), Some(rwb)) = (rbc, attitude::<T>(&s::TRUTH)) else {
        out.failure = 21;
        return None;
    };
    let body_from_camera = Se3::from_parts(rbc, v3(&s::BODY_FROM_CAMERA_T));
    let world_from_body = Se3::from_parts(rwb, v3(&s::TRUTH.position));
    let truth = world_from_body.compose(&body_from_camera).inverse();
    let world = s::LANDMARKS.map(|p| v3::<T>(&p));
    let pixels = s::PIXELS.map(|p| Vector2::new(T::of(p[0]), T::of(p[1])));
    let guess = truth.rplus(&lit6(0.12, -0.1, 0.13, 0.06, 0.05, -0.06));
    let sigma_px = T::of(s::SIGMA_PX);
    let options = PnpOptions::default().with_sigma(sigma_px);
    match solve_pnp(&world, &pixels, &camera, &guess, &options) {
        Ok(sol) => {
            let est = sol.camera_from_world;
            out.pnp_q = quat(&est.rotation());
            let t = est.translation();
            out.pnp_t = [t[0], t[1], t[2]];
            out.truth_errors[3] = est.rotation().between(&truth.rotation()).log().norm();
            out.truth_errors[4] = (t - truth.translation()).norm();
            out.truth_bounds[3] = radius3(&sol.covariance, 3);
            out.truth_bounds[4] = radius3(&sol.covariance, 0);
        }
        Err(_) => out.failure = 22,
    }
    Some(Pnp {
        world,
        pixels,
        camera,
        guess,
        options,
        body_from_camera,
        sigma_px,
    })
}

/// The benchmark inputs at the end of the stream (see [`Workload`]).
fn workload<T: Scalar>(ins: Ins<T>, ahrs: Ahrs<T>, p: Pnp<T>) -> Workload<T> {
    let options = UpdateOptions::default();
    let x = *ins.state();
    let cfg = config::<T>(&stream::ins::IMU_NOISE);
    let n = stream::ins::IMU.len();
    let imu = interval(
        &stream::ins::IMU,
        n.saturating_sub(2),
        T::of(stream::ins::DT),
    )
    .unwrap_or(ImuSample {
        gyro: Vector3::zeros(),
        accel: -cfg.gravity,
        dt: T::of(stream::ins::DT),
    });
    let rt = x.attitude.inverse();
    let up = -cfg.gravity;
    let reference = v3::<T>(&stream::ins::MAG_REFERENCE);
    // Predicted values displaced by about one sigma.
    let d = lit3::<T>(0.6, -0.4, 0.5);
    let yaw = |r: &So3<T>| {
        let m = r.rotation_matrix();
        m.m21.arctan2(m.m11)
    };
    // The at-rest copy: the same estimate and covariance with a velocity of a few cm/s.
    let rest = InsState {
        velocity: d * T::lit(0.05),
        ..x
    };
    let ins_at_rest = Ins::new(rest, *ins.covariance(), cfg).unwrap_or(ins);
    // A landmark 5 m in front of the camera, seen 1 px off its predicted pixel.
    let c = lit3::<T>(0.3, -0.2, 5.0);
    let world_from_camera = Se3::from_parts(x.attitude, x.position).compose(&p.body_from_camera);
    let landmark = world_from_camera.act(&c);
    let pixel = p
        .camera
        .project(&c, T::lit(1e-3))
        .unwrap_or_else(Vector2::zeros)
        + Vector2::new(T::one(), -T::one());
    let bx = ahrs.state().attitude;
    Workload {
        ins,
        ins_at_rest,
        ahrs,
        imu,
        gnss_position: GnssPosition::new(x.position + d, Vector3::zeros(), T::lit(1.5)),
        gnss_velocity: GnssVelocity::new(x.velocity + d * T::lit(0.1), T::lit(0.1)),
        ins_mag: Magnetometer::new(rt.act(&reference) + d * T::lit(0.4), reference, T::lit(0.4)),
        ins_gravity: GravityDirection::new(rt.act(&up) + d * T::lit(0.2), T::lit(0.05)),
        baro: BaroAltitude::new(x.position.z + T::lit(0.5), T::lit(0.5)),
        ins_heading: Heading::new(yaw(&x.attitude) + T::lit(0.02), T::lit(0.03)),
        zero_velocity: ZeroVelocity::new(T::lit(0.1)),
        at_rest: AccelerometerAtRest::new(
            rt.act(&up) + x.accel_bias + d * T::lit(0.05),
            T::lit(0.1),
        ),
        landmark: CameraLandmark::new(pixel, landmark, p.camera, p.body_from_camera, p.sigma_px),
        ahrs_mag: Magnetometer::new(
            bx.inverse().act(&reference) + d * T::lit(0.4),
            reference,
            T::lit(0.4),
        ),
        ahrs_gravity: GravityDirection::new(bx.inverse().act(&up) + d * T::lit(0.2), T::lit(0.05)),
        ahrs_heading: Heading::new(yaw(&bx) + T::lit(0.02), T::lit(0.03)),
        options,
        iterated: UpdateOptions::iterated(options.gate, 5, T::lit(1e-6)),
        world: p.world,
        pixels: p.pixels,
        camera: p.camera,
        guess: p.guess,
        pnp_options: p.options,
    }
}

//! The filters target (see [`crate::run_filters`]).
//!
//! Input: a byte choosing the filter (`Ins`, `Ahrs`, `AhrsAccelBias` × `f32`, `f64`), its
//! construction, then operations until the input ends: a prediction, a run of predictions with
//! one sample, a widening, a restart, or an update with one of the filter's models.

use crate::input::{Input, Scalar};
use crate::{covariance_problem, finding, same, Log, Outcome};
use estimator_core::eskf::{
    align_at_rest, AccelerometerAtRest, Alignment, BaroAltitude, CameraLandmark, ErrorState,
    EskfError, Filter, FilterConfig, Gate, GateProbability, GnssPosition, GnssVelocity,
    GravityDirection, Heading, ImuSample, InitialSigmas, MagneticHeading, Magnetometer,
    MagnetometerWindow, Measurement, PinholeIntrinsics, UpdateOptions, UpdateOutcome, ZeroRate,
    ZeroVelocity,
};
use estimator_core::eskf::{AhrsAccelBiasState, AhrsState, InsState};
use estimator_core::lie::{LieGroup, Se3, So3};
use estimator_core::nalgebra::{Matrix1, Matrix2, Matrix3, SMatrix, Vector2, Vector3};

/// Operations per input, at most.
const MAX_OPS: usize = 400;
/// Predictions per input, at most (a run repeats one sample up to 255 times).
const MAX_PREDICTIONS: usize = 2000;

pub(crate) fn run(data: &[u8]) -> Outcome {
    let mut input = Input::new(data);
    let mut log = Log::default();
    match input.pick(6) {
        0 => ins::<f32>(&mut input, &mut log)?,
        1 => ins::<f64>(&mut input, &mut log)?,
        2 => ahrs::<f32>(&mut input, &mut log)?,
        3 => ahrs::<f64>(&mut input, &mut log)?,
        4 => ahrs_accel_bias::<f32>(&mut input, &mut log)?,
        _ => ahrs_accel_bias::<f64>(&mut input, &mut log)?,
    }
    log.finish()
}

/// A filter's name and scalar, as in the findings: `Ins<f32>`.
fn name<T: Scalar>(filter: &str) -> String {
    format!("{filter}<{}>", T::NAME)
}

/// The promises after a call on `after` that started from `before`.
fn check<T: Scalar, S, const N: usize>(
    call: &str,
    before: &Filter<T, S, N>,
    after: &Filter<T, S, N>,
    result: Result<Option<UpdateOutcome<T>>, EskfError>,
) -> Outcome
where
    S: ErrorState<T, N> + PartialEq + core::fmt::Debug,
{
    match result {
        Err(e) => {
            if !same(before, after) {
                return Err(finding(
                    "unchanged-on-error",
                    call,
                    format!("returned Err({e:?}) but changed the filter: before {before:?}, after {after:?}"),
                ));
            }
            Ok(())
        }
        Ok(Some(UpdateOutcome::Rejected { nis, threshold })) => {
            if !same(before, after) {
                return Err(finding(
                    "unchanged-on-rejection",
                    call,
                    format!(
                        "rejected (nis {nis:?}, threshold {threshold:?}) but changed the filter"
                    ),
                ));
            }
            Ok(())
        }
        Ok(outcome) => valid(call, after, &format!("{outcome:?}")),
    }
}

/// `state-finite` and `covariance-valid` on a filter a call succeeded on.
fn valid<T: Scalar, S, const N: usize>(call: &str, f: &Filter<T, S, N>, what: &str) -> Outcome
where
    S: ErrorState<T, N> + core::fmt::Debug,
{
    if !f.state().is_finite() {
        return Err(finding(
            "state-finite",
            call,
            format!("{what}: state {:?}", f.state()),
        ));
    }
    if let Some(problem) = covariance_problem(f.covariance()) {
        return Err(finding(
            "covariance-valid",
            call,
            format!("{what}: {problem}"),
        ));
    }
    Ok(())
}

fn config<T: Scalar>(input: &mut Input<'_>) -> FilterConfig<T> {
    let mut c = FilterConfig::default();
    let mask = input.byte();
    let n = &mut c.imu_noise;
    if mask & 1 != 0 {
        n.gyroscope_noise_density = input.real();
    }
    if mask & 2 != 0 {
        n.gyroscope_random_walk = input.real();
    }
    if mask & 4 != 0 {
        n.accelerometer_noise_density = input.real();
    }
    if mask & 8 != 0 {
        n.accelerometer_random_walk = input.real();
    }
    if mask & 16 != 0 {
        c.gravity = input.vec3();
    }
    if mask & 32 != 0 {
        c.max_dt = input.real();
    }
    if mask & 64 != 0 {
        // Large but plausible densities: where `P` grows fastest.
        n.gyroscope_noise_density = input.sigma();
        n.accelerometer_noise_density = input.sigma();
    }
    c
}

/// A rotation: identity, `exp` of a moderate vector, or a quaternion of arbitrary reals.
pub(crate) fn attitude<T: Scalar>(input: &mut Input<'_>) -> So3<T> {
    match input.byte() % 4 {
        0 => So3::identity(),
        1 => So3::exp(&input.moderate3()),
        2 => So3::from_wxyz(input.real(), input.real(), input.real(), input.real())
            .unwrap_or_else(So3::identity),
        _ => So3::exp(&input.vec3()),
    }
}

/// An `N × N` covariance: `σ²I`, a diagonal of variances, arbitrary entries, `LLᵀ + εI`, or
/// arbitrary symmetric entries.
fn covariance<T: Scalar, const N: usize>(input: &mut Input<'_>) -> SMatrix<T, N, N> {
    match input.byte() % 5 {
        0 => {
            let s: T = input.sigma();
            SMatrix::identity() * (s * s)
        }
        1 => SMatrix::from_diagonal(&SMatrix::<T, N, 1>::from_fn(|_, _| input.sigma())),
        2 => SMatrix::from_fn(|_, _| input.real()),
        3 => {
            let l = SMatrix::<T, N, N>::from_fn(|_, _| input.moderate());
            let eps: T = input.sigma();
            l * l.transpose() + SMatrix::identity() * eps
        }
        _ => {
            let mut p = SMatrix::<T, N, N>::from_fn(|_, _| input.real());
            for j in 0..N {
                for i in 0..j {
                    p[(j, i)] = p[(i, j)];
                }
            }
            p
        }
    }
}

fn sigmas<T: Scalar>(input: &mut Input<'_>) -> InitialSigmas<T> {
    let mut s = InitialSigmas::default();
    let mask = input.byte();
    let fields = [
        &mut s.tilt,
        &mut s.yaw,
        &mut s.velocity,
        &mut s.position,
        &mut s.gyro_bias,
        &mut s.accel_bias,
    ];
    for (k, field) in fields.into_iter().enumerate() {
        if mask & (1 << k) != 0 {
            *field = if mask & 128 != 0 {
                input.real()
            } else {
                input.sigma()
            };
        }
    }
    s
}

/// An alignment: from [`align_at_rest`] on drawn windows (`Err` passed on), or given directly.
fn alignment<T: Scalar>(input: &mut Input<'_>) -> Result<Alignment<T>, EskfError> {
    if input.chance(128) {
        return Ok(Alignment {
            attitude: attitude(input),
            gyro_bias: input.vec3(),
            heading_from_magnetometer: input.chance(128),
        });
    }
    let n = input.pick(6);
    let mut accel = Vec::new();
    let mut gyro = Vec::new();
    for _ in 0..n {
        let up = if input.chance(200) {
            Vector3::new(T::zero(), T::zero(), T::lit(9.81)) + input.moderate3() * T::lit(1e-3)
        } else {
            input.vec3()
        };
        accel.push(up);
        gyro.push(input.vec3());
    }
    let gravity = if input.chance(200) {
        Vector3::new(T::zero(), T::zero(), T::lit(-9.81))
    } else {
        input.vec3()
    };
    let samples: Vec<Vector3<T>> = (0..input.pick(4)).map(|_| input.vec3()).collect();
    let window = MagnetometerWindow {
        samples: &samples,
        reference: input.vec3(),
    };
    let mag = input.chance(128).then_some(&window);
    let tolerance = if input.chance(200) {
        T::lit(0.5)
    } else {
        input.real()
    };
    align_at_rest(&accel, &gyro, &gravity, mag, tolerance)
}

fn imu<T: Scalar>(input: &mut Input<'_>) -> ImuSample<T> {
    let gyro = if input.chance(200) {
        input.moderate3::<T>() * T::lit(1e-3)
    } else {
        input.vec3()
    };
    let accel = if input.chance(200) {
        Vector3::new(T::zero(), T::zero(), T::lit(9.81)) + input.moderate3::<T>() * T::lit(1e-3)
    } else {
        input.vec3()
    };
    ImuSample {
        gyro,
        accel,
        dt: input.dt(),
    }
}

fn options<T: Scalar>(input: &mut Input<'_>) -> UpdateOptions<T> {
    let gate = match input.byte() % 6 {
        0 => Gate::Probability(GateProbability::P95),
        1 => Gate::Probability(GateProbability::P99),
        3 => Gate::Off,
        4 => Gate::Threshold(input.real()),
        _ => Gate::Probability(GateProbability::P999),
    };
    let max_iterations = match input.byte() {
        b @ 0..=199 => 1 + b % 2,
        200..=239 => 2 + input.byte() % 8,
        _ => input.byte(),
    };
    let step_tolerance = if input.chance(200) {
        T::lit(1e-6)
    } else {
        input.real()
    };
    UpdateOptions {
        gate,
        max_iterations,
        step_tolerance,
    }
}

fn noise1<T: Scalar>(input: &mut Input<'_>) -> Matrix1<T> {
    if input.chance(216) {
        let s: T = input.sigma();
        Matrix1::new(s * s)
    } else {
        Matrix1::new(input.real())
    }
}

fn noise2<T: Scalar>(input: &mut Input<'_>) -> Matrix2<T> {
    if input.chance(216) {
        let s: T = input.sigma();
        Matrix2::identity() * (s * s)
    } else {
        Matrix2::from_fn(|_, _| input.real())
    }
}

fn noise3<T: Scalar>(input: &mut Input<'_>) -> Matrix3<T> {
    match input.byte() {
        0..=199 => {
            let s: T = input.sigma();
            Matrix3::identity() * (s * s)
        }
        200..=231 => {
            let d = Vector3::new(input.sigma::<T>(), input.sigma(), input.sigma());
            Matrix3::from_diagonal(&d.component_mul(&d))
        }
        _ => input.mat3(),
    }
}

fn magnetometer<T: Scalar>(input: &mut Input<'_>) -> Magnetometer<T> {
    Magnetometer {
        field: input.vec3(),
        reference: input.vec3(),
        noise: noise3(input),
    }
}

fn magnetic_heading<T: Scalar>(input: &mut Input<'_>) -> MagneticHeading<T> {
    MagneticHeading {
        field: input.vec3(),
        reference: input.vec3(),
        noise: noise1(input),
    }
}

fn gravity_direction<T: Scalar>(input: &mut Input<'_>) -> GravityDirection<T> {
    let mut g = GravityDirection::new(input.vec3(), T::one());
    if input.chance(32) {
        g.up = input.vec3();
    }
    g.noise = noise3(input);
    g
}

fn accelerometer_at_rest<T: Scalar>(input: &mut Input<'_>) -> AccelerometerAtRest<T> {
    let mut a = AccelerometerAtRest::new(input.vec3(), T::one());
    a.noise = noise3(input);
    if input.chance(32) {
        a.gravity = input.vec3();
    }
    match input.byte() % 8 {
        0 => a.bias_map = input.mat3(),
        1 => a.bias_map = attitude::<T>(input).rotation_matrix(),
        _ => {}
    }
    a
}

fn heading<T: Scalar>(input: &mut Input<'_>) -> Heading<T> {
    Heading {
        yaw: input.real(),
        noise: noise1(input),
    }
}

fn zero_rate<T: Scalar>(input: &mut Input<'_>) -> ZeroRate<T> {
    ZeroRate {
        rate: input.vec3(),
        noise: noise3(input),
    }
}

fn gnss_position<T: Scalar>(input: &mut Input<'_>) -> GnssPosition<T> {
    GnssPosition {
        position: input.vec3(),
        lever_arm: input.vec3(),
        noise: noise3(input),
    }
}

fn gnss_velocity<T: Scalar>(input: &mut Input<'_>) -> GnssVelocity<T> {
    GnssVelocity {
        velocity: input.vec3(),
        noise: noise3(input),
    }
}

fn baro<T: Scalar>(input: &mut Input<'_>) -> BaroAltitude<T> {
    BaroAltitude {
        altitude: input.real(),
        offset: if input.chance(200) {
            T::zero()
        } else {
            input.real()
        },
        noise: noise1(input),
    }
}

fn camera<T: Scalar>(input: &mut Input<'_>) -> CameraLandmark<T> {
    let intrinsics = if input.chance(200) {
        PinholeIntrinsics::new(T::lit(400.0), T::lit(400.0), T::lit(320.0), T::lit(240.0))
    } else {
        PinholeIntrinsics::new(input.real(), input.real(), input.real(), input.real())
    };
    let body_from_camera = if input.chance(160) {
        Se3::identity()
    } else {
        Se3::from_parts(attitude(input), input.vec3())
    };
    let pixel = if input.chance(200) {
        Vector2::new(T::lit(320.0), T::lit(240.0))
            + Vector2::new(input.moderate(), input.moderate())
    } else {
        input.vec2()
    };
    let landmark = if input.chance(200) {
        Vector3::new(
            input.moderate(),
            input.moderate(),
            T::lit(4.0) + input.moderate::<T>().abs(),
        )
    } else {
        input.vec3()
    };
    let mut c = CameraLandmark::new(pixel, landmark, intrinsics, body_from_camera, T::one());
    c.noise = noise2(input);
    if input.chance(32) {
        c.min_depth = input.real();
    }
    c
}

/// One update with `model`, checked.
fn update<T: Scalar, S, Mo, const N: usize, const M: usize>(
    f: &mut Filter<T, S, N>,
    filter: &str,
    model: &str,
    m: &Mo,
    input: &mut Input<'_>,
) -> Outcome
where
    S: ErrorState<T, N> + PartialEq + core::fmt::Debug,
    Mo: Measurement<T, S, N, M> + core::fmt::Debug,
{
    let options = options(input);
    let before = *f;
    let result = f.update(m, &options);
    let call = format!("{filter}::update({model})");
    check(&call, &before, f, result.map(Some)).map_err(|mut e| {
        e.detail = format!("{} [model {m:?}, options {options:?}]", e.detail);
        e
    })
}

/// The operations every filter has: 0 predict, 1 a run of predictions, 2 widen. `None` for
/// another operation (a model's update).
fn common<T: Scalar, S, const N: usize>(
    f: &mut Filter<T, S, N>,
    filter: &str,
    op: usize,
    input: &mut Input<'_>,
    predictions: &mut usize,
) -> Option<Outcome>
where
    S: ErrorState<T, N> + PartialEq + core::fmt::Debug,
{
    Some(match op {
        0 | 1 => {
            let sample = imu(input);
            let repeats = if op == 0 { 1 } else { 2 + input.pick(254) };
            let repeats = repeats.min(*predictions);
            *predictions -= repeats;
            let call = format!("{filter}::predict");
            for _ in 0..repeats {
                let before = *f;
                let result = f.predict(&sample);
                let failed = result.is_err();
                if let Err(mut e) = check(&call, &before, f, result.map(|()| None)) {
                    e.detail = format!("{} [sample {sample:?}]", e.detail);
                    return Some(Err(e));
                }
                if failed {
                    break;
                }
            }
            Ok(())
        }
        2 => {
            let (tilt, yaw) = (input.real(), input.real());
            let before = *f;
            let result = f.widen_attitude(tilt, yaw);
            check(
                &format!("{filter}::widen_attitude"),
                &before,
                f,
                result.map(|()| None),
            )
        }
        _ => return None,
    })
}

/// The loop of operations; `extra` runs the filter's own operations (numbered from 3).
fn operate<T: Scalar, S, const N: usize>(
    f: &mut Filter<T, S, N>,
    filter: &str,
    operations: usize,
    input: &mut Input<'_>,
    log: &mut Log,
    mut extra: impl FnMut(&mut Filter<T, S, N>, usize, &mut Input<'_>) -> Outcome,
) -> Outcome
where
    S: ErrorState<T, N> + PartialEq + core::fmt::Debug,
{
    let mut predictions = MAX_PREDICTIONS;
    for _ in 0..MAX_OPS {
        if input.is_empty() {
            break;
        }
        let op = input.pick(operations);
        let outcome = match common(f, filter, op, input, &mut predictions) {
            Some(outcome) => outcome,
            None => extra(f, op, input),
        };
        log.take(outcome)?;
    }
    Ok(())
}

/// The fallback when a drawn construction is refused: a filter that exists.
fn fallback<T: Scalar, S: ErrorState<T, N>, const N: usize>(state: S) -> Filter<T, S, N> {
    Filter::new(
        state,
        SMatrix::identity() * T::lit(1e-2),
        FilterConfig::default(),
    )
    .expect("the default filter is valid")
}

/// `Filter::new` with drawn arguments, checked; the fallback when refused.
fn construct<T: Scalar, S, const N: usize>(
    filter: &str,
    state: S,
    identity: S,
    input: &mut Input<'_>,
    log: &mut Log,
) -> Result<Filter<T, S, N>, crate::Finding>
where
    S: ErrorState<T, N> + PartialEq + core::fmt::Debug,
{
    let p = covariance::<T, N>(input);
    let c = config::<T>(input);
    match Filter::new(state, p, c) {
        Ok(f) => {
            log.take(valid(&format!("{filter}::new"), &f, "constructed"))?;
            Ok(f)
        }
        Err(_) => Ok(fallback(identity)),
    }
}

fn ins<T: Scalar>(input: &mut Input<'_>, log: &mut Log) -> Outcome {
    let filter = name::<T>("Ins");
    let mut f = match input.byte() % 3 {
        0 => {
            let state = InsState {
                attitude: attitude(input),
                velocity: input.vec3(),
                position: input.vec3(),
                gyro_bias: input.vec3(),
                accel_bias: input.vec3(),
            };
            construct(&filter, state, InsState::identity(), input, log)?
        }
        1 => {
            let a = alignment::<T>(input);
            let (position, s, c) = (input.vec3(), sigmas(input), config(input));
            match a.and_then(|a| Filter::<T, InsState<T>, 15>::from_alignment(&a, position, &s, c))
            {
                Ok(f) => {
                    log.take(valid(
                        &format!("{filter}::from_alignment"),
                        &f,
                        "constructed",
                    ))?;
                    f
                }
                Err(_) => fallback(InsState::identity()),
            }
        }
        _ => fallback(InsState::identity()),
    };
    operate(&mut f, &filter, 14, input, log, |f, op, input| {
        let fname = filter.as_str();
        match op {
            3 => update(f, fname, "GnssPosition", &gnss_position(input), input),
            4 => update(f, fname, "GnssVelocity", &gnss_velocity(input), input),
            5 => update(
                f,
                fname,
                "ZeroVelocity",
                &ZeroVelocity {
                    noise: noise3(input),
                },
                input,
            ),
            6 => update(f, fname, "BaroAltitude", &baro(input), input),
            7 => update(f, fname, "Magnetometer", &magnetometer(input), input),
            8 => update(f, fname, "MagneticHeading", &magnetic_heading(input), input),
            9 => update(
                f,
                fname,
                "GravityDirection",
                &gravity_direction(input),
                input,
            ),
            10 => update(
                f,
                fname,
                "AccelerometerAtRest",
                &accelerometer_at_rest(input),
                input,
            ),
            11 => update(f, fname, "Heading", &heading(input), input),
            12 => update(f, fname, "ZeroRate", &zero_rate(input), input),
            _ => update(f, fname, "CameraLandmark", &camera(input), input),
        }
    })
}

fn ahrs<T: Scalar>(input: &mut Input<'_>, log: &mut Log) -> Outcome {
    let filter = name::<T>("Ahrs");
    let mut f = match input.byte() % 3 {
        0 => {
            let state = AhrsState {
                attitude: attitude(input),
                gyro_bias: input.vec3(),
            };
            construct(&filter, state, AhrsState::identity(), input, log)?
        }
        1 => {
            let a = alignment::<T>(input);
            let (s, c) = (sigmas(input), config(input));
            match a.and_then(|a| Filter::<T, AhrsState<T>, 6>::from_alignment(&a, &s, c)) {
                Ok(f) => {
                    log.take(valid(
                        &format!("{filter}::from_alignment"),
                        &f,
                        "constructed",
                    ))?;
                    f
                }
                Err(_) => fallback(AhrsState::identity()),
            }
        }
        _ => fallback(AhrsState::identity()),
    };
    operate(&mut f, &filter, 8, input, log, |f, op, input| {
        let fname = filter.as_str();
        match op {
            3 => update(
                f,
                fname,
                "GravityDirection",
                &gravity_direction(input),
                input,
            ),
            4 => update(f, fname, "Magnetometer", &magnetometer(input), input),
            5 => update(f, fname, "MagneticHeading", &magnetic_heading(input), input),
            6 => update(f, fname, "Heading", &heading(input), input),
            _ => update(f, fname, "ZeroRate", &zero_rate(input), input),
        }
    })
}

fn ahrs_accel_bias<T: Scalar>(input: &mut Input<'_>, log: &mut Log) -> Outcome {
    let filter = name::<T>("AhrsAccelBias");
    let mut f = match input.byte() % 3 {
        0 => {
            let state = AhrsAccelBiasState {
                attitude: attitude(input),
                gyro_bias: input.vec3(),
                accel_bias: input.vec3(),
                velocity: input.vec3(),
            };
            construct(&filter, state, AhrsAccelBiasState::identity(), input, log)?
        }
        1 => {
            let a = alignment::<T>(input);
            let (s, c) = (sigmas(input), config(input));
            match a.and_then(|a| Filter::<T, AhrsAccelBiasState<T>, 12>::from_alignment(&a, &s, c))
            {
                Ok(f) => {
                    log.take(valid(
                        &format!("{filter}::from_alignment"),
                        &f,
                        "constructed",
                    ))?;
                    f
                }
                Err(_) => fallback(AhrsAccelBiasState::identity()),
            }
        }
        _ => fallback(AhrsAccelBiasState::identity()),
    };
    operate(&mut f, &filter, 10, input, log, |f, op, input| {
        let fname = filter.as_str();
        match op {
            3 => update(
                f,
                fname,
                "GravityDirection",
                &gravity_direction(input),
                input,
            ),
            4 => update(f, fname, "Magnetometer", &magnetometer(input), input),
            5 => update(f, fname, "MagneticHeading", &magnetic_heading(input), input),
            6 => update(f, fname, "Heading", &heading(input), input),
            7 => update(f, fname, "ZeroRate", &zero_rate(input), input),
            8 => update(
                f,
                fname,
                "AccelerometerAtRest",
                &accelerometer_at_rest(input),
                input,
            ),
            _ => {
                let a = alignment::<T>(input);
                let s = sigmas(input);
                let before = *f;
                let result = a.and_then(|a| f.restart_from_alignment(&a, &s));
                check(
                    &format!("{fname}::restart_from_alignment"),
                    &before,
                    f,
                    result.map(|()| None),
                )
            }
        }
    })
}

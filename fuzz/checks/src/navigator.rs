//! The navigator target (see [`crate::run_navigator`]).
//!
//! Input: a byte choosing `f32` or `f64`, the configuration (a mask of fields drawn, the rest
//! default), then samples until the input ends. The samples come from a simulated body whose
//! attitude the gyro turns (so that accelerometer and magnetometer agree with it and the
//! navigator reaches its deep states: start-up, blocks, rest, heading fusion), unless the input
//! asks for arbitrary values; timestamps advance by a plausible step, or jump anywhere.

use crate::input::{Input, Scalar};
use crate::{covariance_problem, differing, finding, same, Log, Outcome};
use estimator_core::eskf::FilterConfig;
use estimator_core::lie::{LieGroup, So3};
use estimator_core::nalgebra::Vector3;
use estimator_core::nav::{
    AttitudeConfig, AttitudeNavigator, AttitudeReport, MagneticConfig, MagneticFusion, NavError,
};

/// Calls per input, at most.
const MAX_CALLS: usize = 6000;

pub(crate) fn run(data: &[u8]) -> Outcome {
    let mut input = Input::new(data);
    let mut log = Log::default();
    if input.chance(128) {
        navigate::<f32>(&mut input, &mut log)?;
    } else {
        navigate::<f64>(&mut input, &mut log)?;
    }
    log.finish()
}

/// An attitude configuration: a mask of fields drawn, the rest default (the INS target draws
/// its alignment's with it too).
pub(crate) fn config<T: Scalar>(input: &mut Input<'_>) -> AttitudeConfig<T> {
    let mut c = AttitudeConfig::new(FilterConfig::default());
    let mask = input.u32();
    let draw = |input: &mut Input<'_>, bit: u32| -> Option<T> {
        (mask & (1 << bit) != 0).then(|| {
            if mask & (1 << 31) != 0 {
                input.real()
            } else {
                input.sigma()
            }
        })
    };
    let fields: [&mut T; 16] = [
        &mut c.filter.imu_noise.gyroscope_noise_density,
        &mut c.filter.imu_noise.gyroscope_random_walk,
        &mut c.filter.imu_noise.accelerometer_noise_density,
        &mut c.filter.imu_noise.accelerometer_random_walk,
        &mut c.filter.max_dt,
        &mut c.startup_s,
        &mut c.block_s,
        &mut c.velocity_sigma,
        &mut c.motion_memory_s,
        &mut c.accelerometer_bias_sigma,
        &mut c.gyro_scale_sigma,
        &mut c.gyro_bias_sigma,
        &mut c.rest_gyro,
        &mut c.rest_accel,
        &mut c.rest_min_s,
        &mut c.rest_rate_sigma,
    ];
    for (bit, field) in (0..).zip(fields) {
        if let Some(x) = draw(input, bit) {
            *field = x;
        }
    }
    let more: [&mut T; 2] = [&mut c.tilt_valid_sigma, &mut c.heading_valid_sigma];
    for (bit, field) in (16..).zip(more) {
        if let Some(x) = draw(input, bit) {
            *field = x;
        }
    }
    if mask & (1 << 18) != 0 {
        c.filter.gravity = input.vec3();
    }
    if mask & (1 << 19) != 0 {
        c.max_rejected_blocks = input.u16();
    }
    c.instantaneous_imu = mask & (1 << 20) == 0;
    c.rotation_only = mask & (1 << 21) != 0;
    c.magnetometer = match input.byte() % 4 {
        0 => None,
        1 => Some(MagneticConfig::new(input.sigma(), None)),
        _ => {
            let reference = if input.chance(200) {
                Vector3::new(T::zero(), T::lit(22.0), T::lit(-42.0))
            } else {
                input.vec3()
            };
            Some(MagneticConfig::new(input.sigma(), Some(reference)))
        }
    };
    if let Some(m) = c.magnetometer.as_mut() {
        let mask = input.byte();
        if mask & 1 != 0 {
            m.fusion = MagneticFusion::Vector;
        }
        let fields: [&mut T; 7] = [
            &mut m.heading_noise,
            &mut m.heading_floor,
            &mut m.norm_tolerance,
            &mut m.dip_tolerance,
            &mut m.new_field_s,
            &mut m.new_field_min_rate,
            &mut m.sigma,
        ];
        for (bit, field) in (1..).zip(fields) {
            if mask & (1 << bit) != 0 {
                *field = input.real();
            }
        }
    }
    c
}

/// The simulated body: its attitude, the world field, the clocks.
struct Body<T: Scalar> {
    attitude: So3<T>,
    field: Vector3<T>,
    t_imu: u64,
    t_mag: u64,
    /// A small generator for the sample noise, seeded by the input.
    noise: u32,
}

impl<T: Scalar> Body<T> {
    /// A number in `[−1, 1)`.
    fn jitter(&mut self) -> T {
        self.noise = self
            .noise
            .wrapping_mul(1_664_525)
            .wrapping_add(1_013_904_223);
        T::lit(f64::from(self.noise >> 8) / f64::from(1u32 << 23) - 1.0)
    }

    fn jitter3(&mut self, scale: T) -> Vector3<T> {
        Vector3::new(self.jitter(), self.jitter(), self.jitter()) * scale
    }
}

/// A step of a clock, ns.
fn step(input: &mut Input<'_>, t: u64) -> u64 {
    match input.byte() {
        0..=159 => t.wrapping_add([1_000_000, 5_000_000, 10_000_000, 20_000_000][input.pick(4)]),
        160..=199 => t.wrapping_add(u64::from(input.u16()) * 1000),
        200..=229 => t.wrapping_add(u64::from(input.u32())),
        230..=239 => t,
        240..=247 => t.wrapping_sub(u64::from(input.u16())),
        _ => input.u64(),
    }
}

/// The body rate for a run of samples, rad/s.
fn rate<T: Scalar>(input: &mut Input<'_>) -> Vector3<T> {
    if input.chance(220) {
        let scale = [0.0, 1e-3, 0.05, 0.5, 3.0][input.pick(5)];
        input.moderate3::<T>() * T::lit(scale * 1e-4)
    } else {
        input.vec3()
    }
}

/// What a navigator call returned, for the check.
type Called<T> = Result<AttitudeReport<T>, NavError>;

fn navigate<T: Scalar>(input: &mut Input<'_>, log: &mut Log) -> Outcome {
    let c = config::<T>(input);
    let mut nav = match AttitudeNavigator::new(c) {
        Ok(nav) => nav,
        Err(_) => AttitudeNavigator::new(AttitudeConfig::new(FilterConfig::default()))
            .expect("the default configuration is valid"),
    };
    let t0 = if input.chance(200) {
        1_000_000_000
    } else {
        input.u64()
    };
    let reference = nav
        .config()
        .magnetometer
        .and_then(|m| m.reference)
        .unwrap_or_else(|| Vector3::new(T::zero(), T::lit(22.0), T::lit(-42.0)));
    let mut body = Body {
        attitude: So3::exp(&input.moderate3::<T>()),
        field: reference,
        t_imu: t0,
        t_mag: t0,
        noise: u32::from(input.u16()),
    };
    let up = Vector3::new(T::zero(), T::zero(), T::lit(9.81));
    let imu_call = format!("AttitudeNavigator<{}>::imu", T::NAME);
    let mag_call = format!("AttitudeNavigator<{}>::magnetometer", T::NAME);
    let mut calls = 0;
    while !input.is_empty() && calls < MAX_CALLS {
        match input.byte() % 8 {
            // A run of IMU samples (with magnetometer samples every `every` when asked).
            0..=3 => {
                let count = 1 + input.pick(200);
                let w = rate::<T>(input);
                let (accel_noise, mag_noise) = (T::lit(input.pick(4) as f64 * 0.1), T::lit(0.3));
                let motion = input.moderate3::<T>() * T::lit([0.0, 1e-4, 1e-3][input.pick(3)]);
                let every = input.pick(4);
                let dt_ns = [2_500_000u64, 5_000_000, 10_000_000, 20_000_000][input.pick(4)];
                for k in 0..count {
                    body.t_imu = body.t_imu.wrapping_add(dt_ns);
                    let dt = T::lit(dt_ns as f64 * 1e-9);
                    body.attitude = body.attitude.rplus(&(w * dt)).normalize();
                    let gyro = w + body.jitter3(T::lit(1e-3));
                    let accel =
                        body.attitude.inverse().act(&up) + motion + body.jitter3(accel_noise);
                    let before = nav;
                    let result = nav.imu(body.t_imu, &gyro, &accel);
                    log.take(check::<T>(&imu_call, before, &nav, result))?;
                    calls += 1;
                    if every != 0 && k % every == 0 {
                        body.t_mag = body.t_imu.wrapping_add(1);
                        let field =
                            body.attitude.inverse().act(&body.field) + body.jitter3(mag_noise);
                        let before = nav;
                        let result = nav.magnetometer(body.t_mag, &field);
                        log.take(check::<T>(&mag_call, before, &nav, result))?;
                        calls += 1;
                    }
                }
            }
            // One IMU sample, any values, any time.
            4 => {
                body.t_imu = step(input, body.t_imu);
                let (gyro, accel) = (input.vec3::<T>(), input.vec3::<T>());
                let before = nav;
                let result = nav.imu(body.t_imu, &gyro, &accel);
                log.take(check::<T>(&imu_call, before, &nav, result))?;
                calls += 1;
            }
            // One magnetometer sample, any values, any time.
            5 => {
                body.t_mag = step(input, body.t_mag);
                let field = input.vec3::<T>();
                let before = nav;
                let result = nav.magnetometer(body.t_mag, &field);
                log.take(check::<T>(&mag_call, before, &nav, result))?;
                calls += 1;
            }
            // The world field changes (iron nearby, a new place).
            6 => body.field = input.vec3(),
            // The clocks jump.
            _ => {
                body.t_imu = step(input, body.t_imu);
                body.t_mag = step(input, body.t_mag);
            }
        }
    }
    Ok(())
}

/// The promises after one call: on `Err` the navigator is `before` but for one more refusal; on
/// `Ok` the filter's covariance is valid and the estimate finite.
fn check<T: Scalar>(
    call: &str,
    before: AttitudeNavigator<T>,
    after: &AttitudeNavigator<T>,
    result: Called<T>,
) -> Outcome {
    match result {
        Err(e) => {
            // Counted as a refusal and nothing else: `before` with a refusal that changes
            // nothing by construction (a NaN sample is refused before anything is read).
            let mut expected = before;
            let refused = expected.magnetometer(0, &Vector3::repeat(T::lit(f64::NAN)));
            if refused.is_ok() || !same(&expected, after) {
                let mut counters = *after.counters();
                counters.refused = expected.counters().refused;
                let parts = [
                    ("estimate()", same(&expected.estimate(), &after.estimate())),
                    ("report()", same(expected.report(), after.report())),
                    ("filter()", same(&expected.filter(), &after.filter())),
                    ("counters()", same(expected.counters(), &counters)),
                    (
                        "refusal count",
                        expected.counters().refused == after.counters().refused,
                    ),
                ];
                let changed = differing(&parts);
                return Err(finding(
                    "unchanged-on-error",
                    call,
                    format!(
                        "returned Err({e:?}) but changed the navigator ({}; otherwise its private state): before {before:?}, after {after:?}",
                        if changed.is_empty() { "no public part".to_owned() } else { changed.join(", ") }
                    ),
                ));
            }
            Ok(())
        }
        Ok(report) => {
            // A call that left the filter as it was has nothing new to check (a covariance
            // broken earlier was reported by the call that broke it).
            let changed = !same(&before.filter(), &after.filter());
            if let Some(f) = after.filter().filter(|_| changed) {
                if !f.state().attitude.is_finite()
                    || !f.state().gyro_bias.iter().all(|x| x.is_finite())
                    || !f.state().accel_bias.iter().all(|x| x.is_finite())
                {
                    return Err(finding(
                        "state-finite",
                        call,
                        format!("state {:?}; report {report:?}", f.state()),
                    ));
                }
                if let Some(problem) = covariance_problem(f.covariance()) {
                    return Err(finding(
                        "covariance-valid",
                        call,
                        format!("{problem}; report {report:?}"),
                    ));
                }
            }
            if let Some(e) = after.estimate().filter(|_| changed) {
                if !(e.attitude.is_finite()
                    && e.sigma_tilt.is_finite()
                    && e.sigma_heading.is_finite())
                {
                    return Err(finding("state-finite", call, format!("estimate {e:?}")));
                }
            }
            Ok(())
        }
    }
}

//! The INS navigator target (see [`crate::run_ins`]).
//!
//! Input: a byte choosing `f32` or `f64` and the navigator's capacities (the default ring and
//! queue, or a ring of 8 intervals and a queue of 4, which a 0.3 s horizon keeps full), the
//! configuration (mostly the defaults; a mask of fields drawn, and through the attitude
//! navigator target's decoder every field of the alignment's), then operations until the input
//! ends. Most operations are runs of a simulated body: its attitude turned by the gyro, its
//! velocity and position integrated from a world acceleration, so that the IMU, the
//! magnetometer, the barometer and the GNSS fixes agree, and the navigator aligns, starts,
//! fuses, and meets the faults it handles (fixes that jump or drift away until a reset, a
//! frozen receiver, a disturbed magnetometer, a barometer step, a clipped accelerometer, a
//! stuck gyro axis, outages). The aids of a run are valid at an IMU sample's time and
//! delivered 0–0.4 s later, in the order they arrive (fixes with random delays arrive out of
//! order). The other operations give one sample of any sensor with any values at any time
//! (past, future, duplicate, a jump), or move the clocks.

use crate::input::{Input, Scalar};
use crate::{covariance_problem, differing, finding, same, Finding, Log, Outcome};
use estimator_core::eskf::{ErrorState, FilterConfig};
use estimator_core::lie::{LieGroup, So3};
use estimator_core::nalgebra::Vector3;
use estimator_core::nav::{
    AttitudeConfig, GnssFix, InsConfig, InsNavigator, InsReport, MagneticConfig, NavError,
};

/// Navigator calls per input, at most.
const MAX_CALLS: usize = 6000;

/// Measurements waiting for their arrival, at most (more are dropped).
const MAX_PENDING: usize = 256;

/// The world magnetic field when the configuration gives none, µT.
const FIELD: [f64; 3] = [0.0, 22.0, -42.0];

pub(crate) fn run(data: &[u8]) -> Outcome {
    let mut input = Input::new(data);
    let mut log = Log::default();
    match input.byte() % 4 {
        0 => navigate(
            &mut input,
            &mut log,
            "InsNavigator<f32>",
            InsNavigator::<f32>::new,
        )?,
        1 => navigate(
            &mut input,
            &mut log,
            "InsNavigator<f64>",
            InsNavigator::<f64>::new,
        )?,
        2 => navigate(
            &mut input,
            &mut log,
            "InsNavigator<f32, 8, 4>",
            InsNavigator::<f32, 8, 4>::new,
        )?,
        _ => navigate(
            &mut input,
            &mut log,
            "InsNavigator<f64, 8, 4>",
            InsNavigator::<f64, 8, 4>::new,
        )?,
    }
    log.finish()
}

/// A value for a configuration field: one of `typical` (most bytes), a standard deviation
/// ([`Input::sigma`]), or with `general` any real.
fn drawn<T: Scalar>(input: &mut Input<'_>, typical: &[f64], general: bool) -> T {
    if general {
        return input.real();
    }
    let b = usize::from(input.byte());
    match typical.get(b % typical.len().max(1)) {
        Some(x) if b < 192 => T::lit(*x),
        _ => input.sigma(),
    }
}

fn config<T: Scalar>(input: &mut Input<'_>) -> InsConfig<T> {
    let attitude = if input.chance(64) {
        crate::navigator::config(input)
    } else {
        let mut a = AttitudeConfig::new(FilterConfig::default());
        a.magnetometer = match input.byte() % 4 {
            0 => None,
            1 => Some(MagneticConfig::new(T::lit(0.5), None)),
            _ => Some(MagneticConfig::new(
                T::lit(0.5),
                Some(Vector3::from(FIELD.map(T::lit))),
            )),
        };
        a
    };
    let mut c = InsConfig::new(attitude);
    // A byte below 160 (an exhausted input too) keeps every default.
    let mask = if input.chance(160) { 0 } else { input.u16() };
    let general = mask & (1 << 15) != 0;
    let g = 9.81;
    let fields: [(&mut T, &[f64]); 11] = [
        (
            &mut c.horizon_s,
            &[0.0, 0.05, 0.1, 0.3, 0.5, 1.0, 2.0, 10.0],
        ),
        (
            &mut c.accelerometer_range,
            &[0.0, 2.0 * g, 4.0 * g, 8.0 * g, 16.0 * g],
        ),
        (&mut c.gyro_range, &[0.0, 4.36, 8.73, 17.45, 34.9]),
        (&mut c.gyro_stuck_s, &[0.0, 0.01, 0.05, 0.1, 1.0]),
        (&mut c.gnss_reset_s, &[0.2, 0.5, 1.0, 2.0, 5.0, 10.0]),
        (&mut c.position_valid_sigma, &[0.0, 1.0, 10.0, 100.0]),
        (&mut c.velocity_valid_sigma, &[0.0, 0.1, 1.0, 10.0]),
        (&mut c.tilt_valid_sigma, &[0.0, 0.01, 0.1, 1.0]),
        (&mut c.heading_valid_sigma, &[0.0, 0.01, 0.2, 3.0]),
        (&mut c.gyro_bias_valid_sigma, &[0.0, 1e-4, 1e-3, 0.1]),
        (&mut c.accel_bias_valid_sigma, &[0.0, 0.01, 0.05, 1.0]),
    ];
    for (bit, (field, typical)) in (0..).zip(fields) {
        if mask & (1 << bit) != 0 {
            *field = drawn(input, typical, general);
        }
    }
    if mask & (1 << 11) != 0 {
        c.gnss_lever_arm = if general {
            input.vec3()
        } else {
            input.moderate3::<T>() * T::lit([1e-4, 0.1, 0.5][input.pick(3)])
        };
    }
    c.barometer_sigma = match (mask >> 12) & 3 {
        0 => None,
        1 | 2 => Some(T::lit(0.5)),
        _ => Some(drawn(input, &[0.01, 0.1, 1.0, 5.0], general)),
    };
    c
}

/// A measurement of an aiding sensor.
#[derive(Clone, Copy, Debug)]
enum Aid<T: Scalar> {
    Gnss(GnssFix<T>),
    Magnetometer(Vector3<T>),
    Barometer(T),
}

/// A measurement on its way: arrival time, validity time, value.
type Pending<T> = (u64, u64, Aid<T>);

/// The simulated body and its sensors.
struct Body<T: Scalar> {
    attitude: So3<T>,
    velocity: Vector3<T>,
    position: Vector3<T>,
    /// The world magnetic field and gravity the sensors see.
    field: Vector3<T>,
    gravity: Vector3<T>,
    /// The GNSS antenna in the body frame.
    lever: Vector3<T>,
    /// The IMU clock, ns.
    t: u64,
    /// A fault of the fixes: an offset from the truth, growing by `drift` m/s.
    offset: Vector3<T>,
    drift: Vector3<T>,
    /// The 1σ the simulated fixes are given (and drawn with).
    sigma_position: T,
    sigma_velocity: T,
    /// The last simulated fix, for a frozen receiver.
    last_fix: Option<GnssFix<T>>,
    /// Measurements not yet delivered.
    pending: Vec<Pending<T>>,
    /// A small generator for the sample noise and the delays, started from the input.
    noise: u32,
}

impl<T: Scalar> Body<T> {
    fn next(&mut self) -> u32 {
        self.noise = self
            .noise
            .wrapping_mul(1_664_525)
            .wrapping_add(1_013_904_223);
        self.noise >> 8
    }

    /// A number in `[−1, 1)`.
    fn jitter(&mut self) -> T {
        T::lit(f64::from(self.next()) / f64::from(1u32 << 23) - 1.0)
    }

    fn jitter3(&mut self, scale: T) -> Vector3<T> {
        Vector3::new(self.jitter(), self.jitter(), self.jitter()) * scale
    }

    /// A delay of `0 … 400` ms.
    fn delay(&mut self) -> u64 {
        u64::from(self.next() % 401) * 1_000_000
    }

    fn send(&mut self, arrival: u64, valid: u64, aid: Aid<T>) {
        if self.pending.len() < MAX_PENDING {
            self.pending.push((arrival, valid, aid));
        }
    }

    /// The earliest measurement that has arrived by `t`, taken out.
    fn arrived(&mut self, t: u64) -> Option<Pending<T>> {
        let i = (0..self.pending.len())
            .filter(|&i| self.pending.get(i).is_some_and(|p| p.0 <= t))
            .min_by_key(|&i| self.pending.get(i).map(|p| p.0))?;
        Some(self.pending.remove(i))
    }
}

/// A step of a clock, ns: plausible, repeated, backwards, or anywhere.
fn step(input: &mut Input<'_>, t: u64) -> u64 {
    match input.byte() {
        0..=159 => t.wrapping_add([1_000_000, 5_000_000, 10_000_000, 20_000_000][input.pick(4)]),
        160..=199 => t.wrapping_add(u64::from(input.u16()) * 100_000),
        200..=229 => t.wrapping_add(u64::from(input.u32())),
        230..=239 => t,
        240..=247 => t.wrapping_sub(u64::from(input.u32())),
        _ => input.u64(),
    }
}

/// The time of a measurement given on its own: in the horizon, at the newest sample, a little
/// ahead, or anywhere.
fn aid_time(input: &mut Input<'_>, t: u64, last: u64) -> u64 {
    match input.byte() % 8 {
        0..=3 => t.wrapping_sub(u64::from(input.u16()) * 10_000),
        4 => last,
        5 => t.wrapping_add(u64::from(input.u32())),
        6 => t,
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

/// A sample given to the navigator.
enum Sample<T: Scalar> {
    Imu(Vector3<T>, Vector3<T>),
    Aid(Aid<T>),
}

/// The navigator under test, with what the checks need.
struct Driver<'l, T: Scalar, const H: usize, const Q: usize> {
    nav: InsNavigator<T, H, Q>,
    log: &'l mut Log,
    label: &'static str,
    calls: usize,
    /// The delayed filter keeps `state-finite` and `covariance-valid` (or there is none).
    filter_valid: bool,
}

/// An attitude variance at least this large, rad² (σ ≥ 1000 rad: no information), marks the
/// calls made with it: ` [huge attitude variance]` after their names.
const HUGE_ATTITUDE_VARIANCE: f64 = 1e6;

impl<T: Scalar, const H: usize, const Q: usize> Driver<'_, T, H, Q> {
    /// One call, then the checks.
    fn give(&mut self, t: u64, sample: &Sample<T>) -> Outcome {
        let before = self.nav;
        let (method, result) = match sample {
            Sample::Imu(gyro, accel) => ("imu", self.nav.imu(t, gyro, accel)),
            Sample::Aid(Aid::Gnss(fix)) => ("gnss", self.nav.gnss(t, fix)),
            Sample::Aid(Aid::Magnetometer(field)) => {
                ("magnetometer", self.nav.magnetometer(t, field))
            }
            Sample::Aid(Aid::Barometer(h)) => ("barometer", self.nav.barometer(t, *h)),
        };
        self.calls += 1;
        let found = check(&before, &self.nav, &result, self.filter_valid);
        if !same(&before.filter(), &self.nav.filter()) {
            self.filter_valid = filter_problem(&self.nav).is_none();
        }
        let Some((promise, detail)) = found else {
            return Ok(());
        };
        // The call's name says what it did, so that a known cause can be listed for the calls
        // it appears in: `InsNavigator<f32>::imu(Started)`, `…::imu(GnssPosition)`, and
        // `… [huge attitude variance]` for a call made on a filter whose attitude was widened
        // beyond any information (KNOWN.md's second cause: a stuck gyro axis at a huge rate).
        let mut did: Vec<String> = Vec::new();
        if let Ok(report) = &result {
            if let Some(event) = report.event {
                did.push(format!("{event:?}"));
            }
            if let Some(f) = report.fused.filter(|f| f.accepted) {
                did.push(format!("{:?}", f.aid));
            }
        }
        let mut call = if did.is_empty() {
            format!("{}::{method}", self.label)
        } else {
            format!("{}::{method}({})", self.label, did.join(", "))
        };
        let huge = T::lit(HUGE_ATTITUDE_VARIANCE);
        if before
            .filter()
            .is_some_and(|f| (0..3).any(|i| f.covariance()[(i, i)] >= huge))
        {
            call.push_str(" [huge attitude variance]");
        }
        self.log.take(Err(finding(promise, &call, detail)))
    }

    fn full(&self) -> bool {
        self.calls >= MAX_CALLS
    }
}

fn navigate<T: Scalar, const H: usize, const Q: usize>(
    input: &mut Input<'_>,
    log: &mut Log,
    label: &'static str,
    new: fn(InsConfig<T>) -> Result<InsNavigator<T, H, Q>, NavError>,
) -> Outcome {
    stream(input, log, label, new).map(|_| ())
}

/// The navigator driven by the input; the navigator at its end.
fn stream<T: Scalar, const H: usize, const Q: usize>(
    input: &mut Input<'_>,
    log: &mut Log,
    label: &'static str,
    new: fn(InsConfig<T>) -> Result<InsNavigator<T, H, Q>, NavError>,
) -> Result<InsNavigator<T, H, Q>, Finding> {
    let c = config::<T>(input);
    let nav = match new(c) {
        Ok(nav) => nav,
        Err(_) => new(InsConfig::new(AttitudeConfig::new(FilterConfig::default())))
            .expect("the default configuration is valid"),
    };
    let t0 = if input.chance(200) {
        1_000_000_000
    } else {
        input.u64()
    };
    let c = *nav.config();
    let mut body = Body {
        attitude: So3::exp(&input.moderate3::<T>()),
        velocity: if input.chance(160) {
            Vector3::zeros()
        } else {
            input.moderate3::<T>() * T::lit(1e-3)
        },
        position: input.moderate3::<T>(),
        field: c
            .attitude
            .magnetometer
            .and_then(|m| m.reference)
            .unwrap_or_else(|| Vector3::from(FIELD.map(T::lit))),
        gravity: c.attitude.filter.gravity,
        lever: c.gnss_lever_arm,
        t: t0,
        offset: Vector3::zeros(),
        drift: Vector3::zeros(),
        sigma_position: T::one(),
        sigma_velocity: T::lit(0.1),
        last_fix: None,
        pending: Vec::new(),
        noise: u32::from(input.u16()),
    };
    let mut d = Driver {
        nav,
        log,
        label,
        calls: 0,
        filter_valid: true,
    };
    // The last time an aid was given on its own (for duplicates).
    let mut last_aid = t0;
    while !input.is_empty() && !d.full() {
        match input.byte() % 16 {
            0..=6 => simulate(input, &mut d, &mut body)?,
            // One IMU sample, any values, any time.
            7 => {
                body.t = step(input, body.t);
                let (gyro, accel) = (input.vec3::<T>(), input.vec3::<T>());
                d.give(body.t, &Sample::Imu(gyro, accel))?;
            }
            // One GNSS fix, any values, any time.
            8 => {
                let t = aid_time(input, body.t, last_aid);
                last_aid = t;
                let position = input.vec3::<T>();
                let velocity = input.chance(160).then(|| input.vec3::<T>());
                let fix = GnssFix::new(position, velocity, input.sigma(), input.sigma());
                d.give(t, &Sample::Aid(Aid::Gnss(fix)))?;
            }
            // One magnetometer sample, any values, any time.
            9 => {
                let t = aid_time(input, body.t, last_aid);
                last_aid = t;
                let field = input.vec3::<T>();
                d.give(t, &Sample::Aid(Aid::Magnetometer(field)))?;
            }
            // One barometer sample, any value, any time.
            10 => {
                let t = aid_time(input, body.t, last_aid);
                last_aid = t;
                let h = input.real::<T>();
                d.give(t, &Sample::Aid(Aid::Barometer(h)))?;
            }
            // The fixes leave the truth: a jump, a drift, or back.
            11 => match input.byte() % 4 {
                0 => {
                    let scale = [1.0, 10.0, 50.0, 1e3][input.pick(4)];
                    body.offset += input.moderate3::<T>() * T::lit(scale * 1e-4);
                }
                1 => {
                    body.drift =
                        input.moderate3::<T>() * T::lit([0.5, 2.0, 10.0][input.pick(3)] * 1e-4)
                }
                _ => {
                    body.offset = Vector3::zeros();
                    body.drift = Vector3::zeros();
                }
            },
            // The sigmas of the simulated fixes (tiny, huge, or back to usual).
            12 => {
                if input.chance(128) {
                    body.sigma_position = T::one();
                    body.sigma_velocity = T::lit(0.1);
                } else {
                    body.sigma_position = input.sigma();
                    body.sigma_velocity = input.sigma();
                }
            }
            // Everything on its way arrives now (a burst: the queue fills).
            13 => {
                while let Some((_, valid, aid)) = body.arrived(u64::MAX) {
                    if d.full() {
                        break;
                    }
                    d.give(valid, &Sample::Aid(aid))?;
                }
            }
            // The world field changes (iron nearby, a new place).
            14 => body.field = input.vec3(),
            // The IMU clock jumps (a gap, or backwards).
            _ => body.t = step(input, body.t),
        }
    }
    Ok(d.nav)
}

/// A run of simulated IMU samples with the aids valid at their times, each delivered when it
/// arrives.
fn simulate<T: Scalar, const H: usize, const Q: usize>(
    input: &mut Input<'_>,
    d: &mut Driver<'_, T, H, Q>,
    body: &mut Body<T>,
) -> Outcome {
    let count = (1 + input.pick(200)) * (1 + input.pick(4));
    let w = rate::<T>(input);
    let acceleration = input.moderate3::<T>() * T::lit([0.0, 0.0, 1e-4, 1e-3][input.pick(4)]);
    let dt_ns = [5_000_000u64, 2_500_000, 10_000_000, 20_000_000][input.pick(4)];
    let (gyro_noise, accel_noise) = (
        T::lit([1e-3, 0.0, 1e-2][input.pick(3)]),
        T::lit([0.02, 0.0, 0.1, 0.5][input.pick(4)]),
    );
    // Every how many samples each aid is measured (0: not in this run), and its delays.
    let mag_every = [4usize, 0, 1, 10][input.pick(4)];
    let baro_every = [8usize, 0, 4, 40][input.pick(4)];
    let gnss_every = [40usize, 0, 20, 200][input.pick(4)];
    let delays = input.byte();
    let fixed_delay = [0u64, 50, 100, 200, 300, 400][input.pick(6)] * 1_000_000;
    let faults = input.byte();
    let (frozen, clipped, stuck) = (faults & 1 != 0, faults & 2 != 0, faults & 4 != 0);
    let (rotated, scaled, baro_step) = (faults & 8 != 0, faults & 16 != 0, faults & 32 != 0);
    let no_velocity = faults & 64 != 0;
    let dt = T::lit(dt_ns as f64 * 1e-9);
    let half = T::lit(0.5);
    let g_2_5 = body.gravity.norm() * T::lit(2.5);
    let clip = if d.nav.config().accelerometer_range > T::zero() {
        d.nav.config().accelerometer_range
    } else {
        g_2_5
    };
    let mut stuck_z = None;
    for k in 0..count {
        if d.full() {
            break;
        }
        body.t = body.t.wrapping_add(dt_ns);
        let t = body.t;
        body.attitude = body.attitude.rplus(&(w * dt)).normalize();
        body.position += body.velocity * dt + acceleration * (half * dt * dt);
        body.velocity += acceleration * dt;
        body.offset += body.drift * dt;
        let r_t = body.attitude.inverse();
        let mut gyro = w + body.jitter3(gyro_noise);
        if stuck {
            gyro.z = *stuck_z.get_or_insert(gyro.z);
        }
        let mut accel = r_t.act(&(acceleration - body.gravity)) + body.jitter3(accel_noise);
        if clipped {
            let phase = T::lit((k % 8) as f64 * core::f64::consts::FRAC_PI_4);
            accel.z += g_2_5 * phase.sin();
            accel = accel.map(|a| a.max(-clip).min(clip));
        }
        d.give(t, &Sample::Imu(gyro, accel))?;
        let delay = |body: &mut Body<T>, aid: u8| match (delays >> (2 * aid)) & 3 {
            0 => fixed_delay,
            1 => body.delay(),
            _ => 0,
        };
        if mag_every != 0 && k % mag_every == 0 {
            let mut field = r_t.act(&body.field) + body.jitter3(T::lit(0.3));
            if rotated {
                field = Vector3::new(-field.y, field.x, field.z);
            }
            if scaled {
                field *= T::lit(1.5);
            }
            let arrival = t.wrapping_add(delay(body, 0));
            body.send(arrival, t, Aid::Magnetometer(field));
        }
        if baro_every != 0 && k % baro_every == 0 {
            let step = if baro_step { T::lit(20.0) } else { T::zero() };
            let h = body.position.z + step + body.jitter() * T::lit(0.3);
            let arrival = t.wrapping_add(delay(body, 1));
            body.send(arrival, t, Aid::Barometer(h));
        }
        if gnss_every != 0 && k % gnss_every == gnss_every / 2 {
            let fix = match body.last_fix.filter(|_| frozen) {
                Some(fix) => fix,
                None => {
                    let antenna = body.position + body.attitude.act(&body.lever) + body.offset;
                    let velocity = body.velocity + body.attitude.act(&w.cross(&body.lever));
                    let (sp, sv) = (body.sigma_position, body.sigma_velocity);
                    let position = antenna + body.jitter3(sp);
                    let velocity = (!no_velocity).then(|| velocity + body.jitter3(sv));
                    GnssFix::new(position, velocity, sp, sv)
                }
            };
            body.last_fix = Some(fix);
            let arrival = t.wrapping_add(delay(body, 2));
            body.send(arrival, t, Aid::Gnss(fix));
        }
        while let Some((_, valid, aid)) = body.arrived(t) {
            if d.full() {
                break;
            }
            d.give(valid, &Sample::Aid(aid))?;
        }
    }
    Ok(())
}

/// Why the delayed filter of `nav` breaks `state-finite` or `covariance-valid`, if it does.
fn filter_problem<T: Scalar, const H: usize, const Q: usize>(
    nav: &InsNavigator<T, H, Q>,
) -> Option<(&'static str, String)> {
    let f = nav.filter()?;
    if !f.state().is_finite() {
        return Some(("state-finite", format!("filter state {:?}", f.state())));
    }
    covariance_problem(f.covariance()).map(|problem| ("covariance-valid", problem))
}

/// Why the estimate of `nav` breaks `state-finite`, if it does.
fn estimate_problem<T: Scalar, const H: usize, const Q: usize>(
    nav: &InsNavigator<T, H, Q>,
) -> Option<(&'static str, String)> {
    let e = nav.estimate()?;
    let finite =
        e.state.is_finite() && e.covariance.iter().all(|m| m.iter().all(|x| x.is_finite()));
    (!finite).then(|| ("state-finite", format!("estimate {e:?}")))
}

/// The promises after one call: on `Err` the navigator is `before` but for one more refusal; on
/// `Ok` the delayed filter, when the call changed it, has a finite state and a valid
/// covariance, and the estimate, when it changed, is finite. A promise is checked where it
/// held before the call (the filter's: `filter_was_valid`; the estimate's: that and a finite
/// estimate of `before`): the call reported is the one that broke it, and a run going on past
/// a known finding does not report its consequences again under the names of later calls.
/// `None`, or the promise broken and what was seen.
fn check<T: Scalar, const H: usize, const Q: usize>(
    before: &InsNavigator<T, H, Q>,
    after: &InsNavigator<T, H, Q>,
    result: &Result<InsReport<T>, NavError>,
    filter_was_valid: bool,
) -> Option<(&'static str, String)> {
    match result {
        Err(e) => {
            // Counted as a refusal and nothing else: `before` with a refusal that changes
            // nothing by construction (a NaN magnetometer sample is refused by its value check,
            // before anything is read or queued, configured magnetometer or not).
            let mut expected = *before;
            let refused = expected.magnetometer(0, &Vector3::repeat(T::lit(f64::NAN)));
            if refused.is_ok() || !same(&expected, after) {
                let mut counters = *after.counters();
                counters.refused = expected.counters().refused;
                let parts = [
                    ("estimate()", same(&expected.estimate(), &after.estimate())),
                    ("report()", same(expected.report(), after.report())),
                    ("filter()", same(&expected.filter(), &after.filter())),
                    ("aligning()", same(&expected.aligning(), &after.aligning())),
                    ("counters()", same(expected.counters(), &counters)),
                    (
                        "refusal count",
                        expected.counters().refused == after.counters().refused,
                    ),
                ];
                let changed = differing(&parts);
                return Some((
                    "unchanged-on-error",
                    format!(
                        "returned Err({e:?}) but changed the navigator ({}; otherwise its private state): before {before:?}, after {after:?}",
                        if changed.is_empty() { "no public part".to_owned() } else { changed.join(", ") }
                    ),
                ));
            }
            None
        }
        Ok(report) => {
            // A call that left the filter as it was has nothing new to check.
            let changed = !same(&before.filter(), &after.filter());
            if changed && (filter_was_valid || before.filter().is_none()) {
                if let Some((promise, detail)) = filter_problem(after) {
                    return Some((promise, format!("{detail}; report {report:?}")));
                }
            }
            // The estimate is the filter's carried over the horizon: checked while the
            // filter keeps its promises (a filter broken earlier breaks it too).
            let estimate = after.estimate();
            if (changed || !same(&before.estimate(), &estimate))
                && filter_was_valid
                && estimate_problem(before).is_none()
            {
                if let Some((promise, detail)) = estimate_problem(after) {
                    return Some((promise, format!("{detail}; report {report:?}")));
                }
            }
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::input::Encoder;

    /// `runs` seconds of a body at rest (or, `moving`, accelerating at 1 m/s² along x) at
    /// 200 Hz, magnetometer every 4 samples, barometer every 8, a fix every 40, delivered
    /// after `delays` (two bits per aid: 0 for 200 ms, 1 for random), with `faults`.
    fn seconds(e: &mut Encoder, runs: usize, moving: bool, delays: u8, faults: u8) {
        for _ in 0..runs {
            e.byte(0); // a run
            e.byte(199).byte(0); // 200 samples
            e.byte(0).byte(0); // rate: scale 0
            for _ in 0..3 {
                e.byte(0).u16(32768);
            }
            // The acceleration: (1e4·1, ~0, ~0)·1e-4, or none.
            e.byte(7).u16(if moving { 65535 } else { 32768 });
            e.byte(0).u16(32768).byte(0).u16(32768);
            e.byte(2).byte(0); // acceleration scale 1e-4; 200 Hz
            e.byte(0).byte(0); // noise 1e-3 rad/s, 0.02 m/s²
            e.byte(0).byte(0).byte(0); // magnetometer /4, barometer /8, GNSS /40
            e.byte(delays).byte(3); // the delays; 200 ms when fixed
            e.byte(faults);
        }
    }

    /// The start of an input: `InsNavigator<f64>` with the default alignment and its
    /// magnetometer, a barometer, t0 = 1 s, the body level at the origin.
    fn start() -> Encoder {
        let mut e = Encoder::new();
        e.byte(1); // InsNavigator<f64>
        e.byte(200).byte(2); // the default alignment, a magnetometer with its reference
        e.byte(200).u16(1 << 12); // the INS defaults but a barometer of 0.5 m
        e.byte(0); // t0 = 1 s
        for _ in 0..3 {
            e.byte(3).u16(32768); // attitude: a rotation vector of 1.5e-5
        }
        e.byte(0); // at rest
        for _ in 0..3 {
            e.byte(0).u16(32768); // position near zero
        }
        e.u16(7); // noise
        e
    }

    /// `stream` on an input made by [`start`]: the navigator at its end.
    fn replay(data: &[u8]) -> InsNavigator<f64> {
        assert_eq!(run(data), Ok(()));
        let mut input = Input::new(data);
        assert_eq!(input.byte(), 1);
        let mut log = Log::default();
        stream(&mut input, &mut log, "", InsNavigator::<f64>::new).expect("every promise kept")
    }

    #[test]
    fn a_simulated_stream_starts_and_fuses_every_aid() {
        let mut e = start();
        seconds(&mut e, 8, false, 0, 0);
        let nav = replay(&e.bytes);
        let c = nav.counters();
        assert!(nav.estimate().is_some(), "{c:?}");
        assert!(
            c.gnss_position_fused > 20 && c.gnss_velocity_fused > 20,
            "{c:?}"
        );
        assert!(
            c.magnetometer_fused > 100 && c.barometer_fused > 50,
            "{c:?}"
        );
        assert!(
            nav.report().validity.position.is_valid(),
            "{:?}",
            nav.report()
        );
    }

    #[test]
    fn faults_of_the_simulated_stream_are_seen() {
        // Two good seconds and more, then a frozen receiver on a body at rest (judged by the
        // gate), a rotated magnetometer, a barometer step, a clipped accelerometer and a
        // stuck gyro axis.
        let mut e = start();
        seconds(&mut e, 8, false, 0, 0);
        seconds(&mut e, 4, false, 0, 1 | 2 | 4 | 8 | 32);
        let nav = replay(&e.bytes);
        let c = nav.counters();
        assert!(c.imu_faults > 100, "{c:?}");
        assert!(
            c.magnetometer_rejected + c.magnetometer_disturbed > 50,
            "{c:?}"
        );
        assert!(c.barometer_rejected > 10, "{c:?}");
    }

    #[test]
    fn a_frozen_receiver_on_a_moving_body_and_drifting_fixes_are_seen() {
        let mut e = start();
        seconds(&mut e, 8, false, 0, 0);
        seconds(&mut e, 2, true, 0, 0);
        seconds(&mut e, 2, false, 0, 1); // frozen at 2 m/s
        let nav = replay(&e.bytes);
        let c = nav.counters();
        assert!(c.gnss_frozen >= 8, "{c:?}");
        // Fixes drifting away at 2 m/s along x (random delays): rejected, then a reset.
        let mut e = start();
        seconds(&mut e, 8, false, 0, 0);
        e.byte(11).byte(1); // the fixes drift
        e.byte(7).u16(65535).byte(0).u16(32768).byte(0).u16(32768);
        e.byte(1); // 2 m/s
        seconds(&mut e, 14, false, 0b01_0101, 0);
        let nav = replay(&e.bytes);
        let c = nav.counters();
        assert!(c.gnss_position_rejected > 40 && c.resets >= 1, "{c:?}");
    }
}

//! Link-time no-panic check.
//!
//! Calls every public entry point of `estimator-core` (f32; f64 too with `--features f64`) with
//! opaque inputs (`core::hint::black_box`: the optimizer knows nothing of lengths, values or
//! enum variants), and keeps every result alive. Every number comes from one black-boxed array
//! of [`Seed`] values read through a pointer the optimizer cannot see into; every slice and enum
//! is black-boxed where it is made; every result is kept by [`keep`], which hands its address to
//! an empty `asm!` block the compiler must assume reads it (no copy of large results). The panic
//! handler calls a function that exists nowhere, so the link fails (`undefined symbol:
//! __estimator_core_panic_path_reachable`) as soon as any panic path survives optimization.
//! With `--features locate-panics` the handler is a plain loop instead: the binary links, and
//! `.ci/firmware.sh` lists which functions call into `core::panicking` (the culprits).
//!
//! Each entry point is called once, at one call site: an opaque argument already reaches every
//! path of the callee, so a second call with other options would add call sites, not coverage.
//! Where the API offers several ways to build an argument (`UpdateOptions::ekf` and
//! `::iterated`, the solver's methods), each is built and kept, and one opaque choice between
//! them is passed.
//!
//! This binary is never run; it is also the "firmware calling the whole public API" whose flash
//! footprint the README reports (opt-level "s").
#![no_std]
#![no_main]
#![allow(unused_must_use)] // results are kept alive with black_box, not inspected

use core::hint::black_box as bb;
#[cfg(target_arch = "arm")]
use cortex_m_rt::entry;
use estimator_core::eskf::{
    align_at_rest, AccelerometerAtRest, Ahrs, AhrsAccelBias, AhrsAccelBiasState, AhrsState,
    Alignment, BaroAltitude, CameraLandmark, ErrorState, FilterConfig, Gate, GateProbability,
    GnssPosition, GnssVelocity, GravityDirection, Heading, ImuNoise, ImuSample, InitialSigmas, Ins,
    InsState, LateralVelocity, MagneticHeading, Magnetometer, MagnetometerWindow, Measurement,
    PinholeIntrinsics, UpdateOptions, ZeroRate, ZeroVelocity,
};
use estimator_core::gn::{
    check_point_spread, point_reprojection_error, reprojection_error, solve, solve_pnp,
    solve_rotation_from_vectors, triangulate, vector_pair_error, Factor, Loss, Manifold, Method,
    NormalEquations, PinholeCamera, PnpOptions, PnpProblem, Product, SolverOptions,
    TriangulationOptions, VectorPair,
};
use estimator_core::lie::{skew, LieGroup, Se2, Se3, So2, So3};
use estimator_core::nav::{
    AttitudeConfig, AttitudeNavigator, GnssFix, InsConfig, InsNavigator, MagneticConfig, Validity,
    VectorMean,
};
use estimator_core::Real;
use nalgebra::{
    Matrix2, Matrix3, Matrix4, Quaternion, SMatrix, SVector, UnitQuaternion, Vector1, Vector2,
    Vector3, Vector6,
};
#[cfg(target_arch = "riscv32")]
use riscv_rt::entry;

/// The numbers every input is built from, read through a `black_box`ed reference (see [`api`]):
/// the optimizer never sees them.
type Seed<T> = [T; 8];

/// Keeps a result alive: its address goes, in a register, to an empty `asm!` block that the
/// compiler must assume reads it (no `nomem`). This is `black_box(x)` without the spill of the
/// reference to the stack that `black_box` makes: one instruction less per call site.
#[inline(always)]
fn keep<X>(x: &X) {
    // SAFETY: the assembly is empty: it reads and writes nothing and leaves the stack alone. The
    // compiler cannot know that and must assume it reads through the pointer, so `x` is
    // materialised in memory, exactly as for `black_box`.
    unsafe {
        core::arch::asm!("/* {0} */", in(reg) x as *const X, options(nostack, preserves_flags, readonly))
    }
}

/// Every method of `LieGroup`, on opaque inputs.
#[inline(never)]
fn group<T: Real, G: LieGroup<T>>(
    a: &G,
    b: &G,
    tau: &G::Tangent,
    p: &G::Point,
    m: &G::Matrix,
    s: T,
) {
    keep(&G::identity());
    keep(&G::exp(tau));
    keep(&a.log());
    keep(&G::hat(tau));
    keep(&G::vee(m));
    keep(&a.compose(b));
    keep(&a.inverse());
    keep(&a.between(b));
    keep(&a.act(p));
    keep(&a.rplus(tau));
    keep(&a.rminus(b));
    keep(&a.adjoint());
    keep(&G::right_jacobian(tau));
    keep(&G::left_jacobian(tau));
    keep(&G::right_jacobian_inv(tau));
    keep(&G::left_jacobian_inv(tau));
    keep(&G::exp_jac(tau));
    keep(&a.log_jac());
    keep(&a.inverse_jac());
    keep(&a.compose_jac(b));
    keep(&a.act_jac(p));
    keep(&a.rplus_jac(tau));
    keep(&a.rminus_jac(b));
    keep(&a.between_jac(b));
    keep(&a.matrix());
    keep(&a.normalize());
    keep(&G::try_from_matrix(m));
    keep(&a.interpolate(b, s));
    keep(&a.is_finite());
}

#[inline(never)]
fn lie<T: Real>(x: &Seed<T>) {
    let [a, b, c, d, e, f, g, h] = *x;
    let v = Vector3::new(a, b, c);
    let w = Vector3::new(d, e, f);
    let m3 = Matrix3::new(a, b, c, d, e, f, g, h, a);
    // SO(2), SE(2).
    let s2 = So2::<T>::from_angle(a);
    keep(&So2::<T>::from_cos_sin(b, c));
    keep(&(
        s2.angle(),
        s2.cos(),
        s2.sin(),
        s2.rotation_matrix(),
        s2.cast::<f32>(),
    ));
    let v2 = Vector2::new(d, e);
    group::<T, So2<T>>(
        &s2,
        &So2::from_angle(b),
        &Vector1::new(c),
        &v2,
        &Matrix2::new(a, b, c, d),
        g,
    );
    let e2 = Se2::<T>::new(a, b, c);
    let e2b = Se2::from_parts(s2, Vector2::new(e, f));
    keep(&(e2.rotation(), e2.translation(), e2.cast::<f32>()));
    group::<T, Se2<T>>(&e2, &e2b, &w, &v2, &m3, g);
    // SO(3), SE(3).
    let q = Quaternion::new(d, a, b, c);
    keep(&So3::<T>::from_quaternion(&q));
    keep(&So3::<T>::from_wxyz(e, f, g, h));
    let r = So3::<T>::from_unit_quaternion(UnitQuaternion::new_unchecked(q));
    keep(&(r.quaternion(), r.cast::<f32>(), r.rotation_matrix()));
    keep(&r.renormalize());
    keep(&So3::<T>::from_rotation_matrix(&m3));
    group::<T, So3<T>>(&r, &So3::exp(&w), &v, &w, &m3, g);
    let t = Se3::<T>::from_parts(r, w);
    keep(&(t.rotation(), t.translation(), t.cast::<f32>()));
    let xi = Vector6::new(a, b, c, d, e, f);
    let m4 = Matrix4::from_diagonal_element(h);
    group::<T, Se3<T>>(&t, &Se3::exp(&xi), &(xi * g), &v, &m4, g);
    keep(&skew(&v));
    keep(&h.sincos());
    keep(&h.arctan2(a));
}

#[inline(never)]
fn eskf<T: Real>(x: &Seed<T>) {
    let [a, b, c, d, e, f, g, h] = *x;
    let v = Vector3::new(a, b, c);
    let w = Vector3::new(d, e, f);
    let config = FilterConfig::<T> {
        imu_noise: bb(ImuNoise::mems()),
        gravity: w,
        max_dt: a,
    };
    let config = bb(config);
    keep(&config.validate());
    keep(&FilterConfig::<T>::default());
    let imu = ImuSample {
        gyro: v,
        accel: w,
        dt: g,
    };
    // Both constructors; one opaque choice between them is what every update gets (an opaque
    // value reaches every code path of the update, so a second call per model adds no coverage,
    // only call sites).
    let ekf_opts = UpdateOptions::ekf(bb(Gate::Probability(bb(GateProbability::P99))));
    let iter = UpdateOptions::iterated(bb(Gate::Threshold(h)), bb(3), g);
    let opts = bb(if bb(false) { iter } else { ekf_opts });
    ahrs(x, &config, &opts);
    ahrs_accel_bias(x, &config, &opts);
    nav(x, &config);
    ins_nav(x, &config);
    keep(&UpdateOptions::<T>::default());
    keep(&bb(Gate::<T>::Probability(GateProbability::P95)).threshold(bb(3)));
    keep(&GateProbability::P999.quantile::<T>(bb(9)));
    keep(&bb(GateProbability::P95).z_score());

    // Alignment and initial covariance.
    let acc = [v; 8];
    let mags = [w; 8];
    let win = MagnetometerWindow {
        samples: bb(&mags[..]),
        reference: v,
    };
    let align = align_at_rest(bb(&acc[..]), bb(&acc[..]), &w, bb(Some(&win)), d);
    keep(&align);
    let sigmas = bb(InitialSigmas::<T>::default());
    keep(&sigmas.attitude_covariance(&So3::exp(&v), &w));

    // The 15-state filter.
    let state = bb(InsState::<T>::identity());
    keep(&state.oplus(&SVector::<T, 15>::repeat(g)));
    keep(&ErrorState::is_finite(&state));
    keep(&ErrorState::attitude(&state));
    let mut ins = match Ins::new(
        state,
        SMatrix::<T, 15, 15>::from_diagonal_element(a),
        config,
    ) {
        Ok(f) => f,
        Err(e) => {
            keep(&e);
            return;
        }
    };
    if let Ok(al) = &align {
        keep(&Ins::from_alignment(al, v, &sigmas, config));
        keep(&Ahrs::from_alignment(al, &sigmas, config));
    }
    keep(&(ins.state(), ins.covariance(), ins.config(), ins.sigmas()));
    keep(&ins.predict(&imu));
    let intr = PinholeIntrinsics {
        fx: h,
        fy: h,
        cx: e,
        cy: f,
    };
    let cam = CameraLandmark::new(
        Vector2::new(d, e),
        v,
        intr,
        Se3::exp(&Vector6::repeat(a)),
        b,
    );
    keep(&cam.project(ins.state()));
    macro_rules! ins_update {
        ($m:expr) => {{
            let m = $m;
            keep(&Measurement::<T, InsState<T>, 15, _>::linearize(
                &m,
                ins.state(),
            ));
            keep(&Measurement::<T, InsState<T>, 15, _>::noise(&m));
            let outcome = ins.update(&m, &opts);
            keep(&outcome);
            outcome
        }};
    }
    ins_update!(GnssPosition::new(v, w, a));
    match GnssPosition::with_sigmas(w, v, b, c) {
        Ok(fix) => {
            ins_update!(fix);
        }
        Err(e) => keep(&e),
    }
    ins_update!(GnssVelocity::new(w, b));
    ins_update!(ZeroVelocity::new(c));
    ins_update!(LateralVelocity::new(c));
    ins_update!(BaroAltitude::new(h, d));
    ins_update!(Magnetometer::new(v, w, d));
    ins_update!(GravityDirection::new(w, g));
    ins_update!(Heading::new(c, g));
    ins_update!(AccelerometerAtRest::new(v, a));
    ins_update!(ZeroRate::new(v, a));
    ins_update!(MagneticHeading::new(v, w, d));
    // The outcome's accessors, once (on the last outcome).
    if let Ok(outcome) = ins_update!(cam) {
        keep(&(outcome.nis(), outcome.is_accepted()));
    }
    // What a navigator does to the filter besides updates: widen, reset.
    keep(&ins.widen_velocity(d));
    keep(&ins.widen_biases(g, h));
    keep(&ins.reset_position(w, e));
    keep(&ins.reset_velocity(v, f));
    keep(&ins.reset_heading(a, g));
    keep(&ins);
}

/// The attitude-only filter (its own frame: the 15-state filter's large values are not on it).
#[inline(never)]
fn ahrs<T: Real>(x: &Seed<T>, config: &FilterConfig<T>, opts: &UpdateOptions<T>) {
    let [a, b, c, d, e, f, g, _] = *x;
    let (v, w) = (Vector3::new(a, b, c), Vector3::new(d, e, f));
    let st = bb(AhrsState::<T>::identity());
    keep(&st.oplus(&SVector::<T, 6>::repeat(g)));
    let mut ahrs = match Ahrs::new(st, SMatrix::<T, 6, 6>::from_diagonal_element(b), *config) {
        Ok(f) => f,
        Err(e) => {
            keep(&e);
            return;
        }
    };
    keep(&(
        ahrs.state(),
        ahrs.covariance(),
        ahrs.config(),
        ahrs.sigmas(),
    ));
    keep(&ahrs.predict(&ImuSample {
        gyro: v,
        accel: v,
        dt: g,
    }));
    macro_rules! ahrs_update {
        ($m:expr) => {{
            let m = $m;
            keep(&ahrs.update(&m, opts));
        }};
    }
    ahrs_update!(Magnetometer::new(v, w, d));
    ahrs_update!(GravityDirection::new(w, g));
    ahrs_update!(Heading::new(c, g));
    ahrs_update!(ZeroRate::new(v, a));
    ahrs_update!(MagneticHeading::new(v, w, d));
    keep(&ahrs.widen_attitude(a, b));
    keep(&ahrs);
}

/// The attitude filter with both IMU biases (the attitude navigator's), with its own models.
#[inline(never)]
fn ahrs_accel_bias<T: Real>(x: &Seed<T>, config: &FilterConfig<T>, opts: &UpdateOptions<T>) {
    let [a, b, c, d, e, f, g, _] = *x;
    let (v, w) = (Vector3::new(a, b, c), Vector3::new(d, e, f));
    let st = bb(AhrsAccelBiasState::<T>::identity());
    keep(&st.oplus(&SVector::<T, 12>::repeat(g)));
    let p = SMatrix::<T, 12, 12>::from_diagonal_element(b);
    let mut filter = match AhrsAccelBias::new(st, p, *config) {
        Ok(f) => f,
        Err(e) => {
            keep(&e);
            return;
        }
    };
    keep(&(filter.state(), filter.covariance(), filter.sigmas()));
    keep(&filter.predict(&ImuSample {
        gyro: v,
        accel: w,
        dt: g,
    }));
    keep(&filter.widen_attitude(a, b));
    keep(&filter.integrate_velocity(&v, &Matrix3::from_diagonal(&w), c));
    keep(&filter.restart_velocity(w, d));
    keep(&filter.update(&ZeroVelocity::new(e), opts));
    let al = Alignment {
        attitude: So3::exp(&v),
        gyro_bias: w,
        heading_from_magnetometer: bb(false),
    };
    let sigmas = bb(InitialSigmas::default());
    keep(&AhrsAccelBias::from_alignment(&al, &sigmas, *config));
    keep(&filter.restart_from_alignment(&al, &sigmas));
    keep(&filter.update(&ZeroRate::new(v, a), opts));
    keep(&filter.update(&AccelerometerAtRest::new(w, a), opts));
    keep(&filter.update(&MagneticHeading::new(v, w, d), opts));
    keep(&filter.update(&GravityDirection::new(w, g), opts));
    keep(&filter.update(&Magnetometer::new(v, w, d), opts));
    keep(&filter);
    // The INS started from this filter (the INS navigator's start-up).
    let mut ins = Ins::from_attitude_filter(&filter, &So3::exp(&w), v, w, a, b);
    if let Ok(ins) = ins.as_mut() {
        keep(&ins.restart_from_attitude_filter(&filter, &So3::exp(&v), w, v, b, a));
    }
    keep(&ins);
}

/// The attitude navigator on an opaque state (`black_box` after construction: every phase and
/// branch of its calls is reachable) and opaque samples; the running mean it is built on.
#[inline(never)]
fn nav<T: Real>(x: &Seed<T>, config: &FilterConfig<T>) {
    let [a, b, c, d, e, f, g, h] = *x;
    let (v, w) = (Vector3::new(a, b, c), Vector3::new(d, e, f));
    let mut cfg = AttitudeConfig::new(*config);
    cfg.magnetometer = bb(Some(MagneticConfig::new(g, bb(Some(w)))));
    let cfg = bb(cfg);
    keep(&cfg.validate());
    let nav = match AttitudeNavigator::new(cfg) {
        Ok(n) => n,
        Err(e) => {
            keep(&e);
            return;
        }
    };
    let mut nav = bb(nav);
    let t = bb(1_000_000_000u64);
    keep(&nav.imu(t, &v, &w));
    keep(&nav.magnetometer(t, &w));
    keep(&nav.estimate());
    keep(&(
        nav.config(),
        nav.filter(),
        nav.report(),
        nav.counters(),
        nav.magnetic_reference(),
    ));
    keep(&bb(Validity::Valid).is_valid());
    let mut mean = VectorMean::<T>::default();
    mean.add(&v);
    mean.add(&bb(w));
    keep(&(mean.count(), mean.mean(), mean.scatter_sq()));
    keep(&(T::from_count(bb(7)), h.to_count()));
}

/// The INS navigator on an opaque state (`black_box` after construction, as the attitude
/// navigator: every phase, aligning or running, and every branch of its calls is reachable),
/// with a magnetometer and a barometer configured, and opaque samples.
#[inline(never)]
fn ins_nav<T: Real>(x: &Seed<T>, config: &FilterConfig<T>) {
    let [a, b, c, d, e, f, g, h] = *x;
    let (v, w) = (Vector3::new(a, b, c), Vector3::new(d, e, f));
    let mut attitude = AttitudeConfig::new(*config);
    attitude.magnetometer = bb(Some(MagneticConfig::new(g, bb(Some(w)))));
    let mut cfg = InsConfig::new(attitude);
    cfg.barometer_sigma = bb(Some(h));
    cfg.gnss_lever_arm = v;
    cfg.gyro_stuck_s = a;
    let cfg = bb(cfg);
    keep(&cfg.validate());
    let nav = match InsNavigator::<T>::new(cfg) {
        Ok(n) => n,
        Err(e) => {
            keep(&e);
            return;
        }
    };
    let mut nav = bb(nav);
    let t = bb(1_000_000_000u64);
    keep(&nav.imu(t, &v, &w));
    let fix = GnssFix::new(w, bb(Some(v)), a, b);
    keep(&nav.gnss(t, &fix));
    keep(&nav.gnss(t, &fix.with_vertical_sigma(c)));
    keep(&nav.magnetometer(t, &w));
    keep(&nav.barometer(t, h));
    keep(&nav.estimate());
    keep(&(
        nav.config(),
        nav.report(),
        nav.counters(),
        nav.filter(),
        nav.aligning(),
    ));
}

#[inline(never)]
fn gn<T: Real>(x: &Seed<T>) {
    let [a, b, c, d, e, f, g, h] = *x;
    let v = Vector3::new(a, b, c);
    let w = Vector3::new(d, e, f);
    let z = Vector2::new(e, f);
    let camera = PinholeCamera::<T>::new(h, h, e, f);
    keep(&camera.is_valid());
    keep(&camera.project(&v, g));
    keep(&camera.project_jac(&v, g));
    keep(&camera.unproject(&z));
    let pts_a = [v; 24];
    let px_a = [z; 24];
    let (pts, px) = (bb(&pts_a[..]), bb(&px_a[..]));
    let pose = Se3::<T>::exp(&Vector6::repeat(a));
    let pnp_opts = PnpOptions::<T>::default()
        .with_loss(bb(Loss::Huber(f)))
        .with_sigma(d);
    match solve_pnp(pts, px, &camera, &pose, &bb(pnp_opts)) {
        Ok(s) => {
            let inl = s.inliers;
            keep(&(
                inl.contains(bb(3)),
                inl.count(),
                inl.len(),
                inl.is_empty(),
                inl.bits(),
            ));
            for x in inl.iter() {
                keep(&x);
            }
            keep(&s);
        }
        Err(e) => {
            keep(&e);
        }
    }
    keep(&check_point_spread(pts));
    let m3 = Matrix3::new(a, b, c, d, e, f, g, h, a);
    keep(&reprojection_error(&camera, &m3, &v, &w, &z, b, g));
    let problem = PnpProblem {
        world_points: pts,
        pixels: px,
        camera,
        inv_sigma: b,
        min_depth: g,
    };
    let sopts = bb(SolverOptions::<T>::default());
    keep(&sopts.is_valid());
    // Either method, by an opaque choice (one call reaches both).
    let mut chosen = sopts;
    if bb(false) {
        chosen.method = bb(Method::GaussNewton);
    }
    keep(&solve::<T, Se3<T>, _, 6, 2>(&problem, &pose, &chosen));

    let poses = [pose; 4];
    keep(&triangulate(
        bb(&poses[..]),
        bb(&px_a[..4]),
        &camera,
        &bb(TriangulationOptions::<T>::default()),
    ));
    keep(&point_reprojection_error(&camera, &pose, &v, &z, b, g));
    let pairs = [VectorPair {
        body: v,
        world: w,
        sigma: g,
    }; 3];
    let start = So3::exp(&w);
    keep(&solve_rotation_from_vectors(
        bb(&pairs[..]),
        bb(Some(&start)),
        &sopts,
    ));
    keep(&vector_pair_error(&start, &v, &w, b));

    let m6 = SMatrix::<T, 6, 6>::from_diagonal_element(d);
    if let Ok(fac) = Factor::new(&m6) {
        keep(&fac.solve(&SVector::<T, 6>::repeat(c)));
        keep(&fac.inverse());
    }
    let mut ne = NormalEquations::<T, 6>::zeros();
    ne.add::<2>(
        &bb(Loss::Cauchy(b)),
        &SVector::<T, 2>::repeat(d),
        &SMatrix::<T, 2, 6>::repeat(a),
    );
    keep(&ne);
    let l = bb(Loss::<T>::Huber(c));
    keep(&(l.is_valid(), l.scaled(f), l.evaluate(e)));
    let xi = SVector::<T, 6>::repeat(a);
    let prod = Product::<So3<T>, SVector<T, 3>, 3, 3>::new(start, v);
    keep(&Manifold::<T, 6>::oplus(&prod, &xi));
    keep(&Manifold::<T, 6>::all_finite(&prod));
    keep(&Product::<So3<T>, SVector<T, 3>, 3, 3>::split::<T, 6>(&xi));
}

/// Runs every harness in precision `T` on the opaque seed.
fn api<T: Real>() {
    // Literals through `T::lit`, which folds at compile time (no f64 arithmetic in f32 code).
    let l = T::lit;
    let seed: Seed<T> = [
        l(0.1),
        l(0.2),
        l(0.3),
        l(0.5),
        l(-1.0),
        l(2.0),
        l(0.01),
        l(400.0),
    ];
    let x = bb(&seed);
    lie::<T>(x);
    eskf::<T>(x);
    gn::<T>(x);
}

#[entry]
fn main() -> ! {
    api::<f32>();
    // The f32 kernels behind `Real` (public for users who want them directly). `Real::to_f64` is
    // left out: it is the one entry point that is f64 by design (host tools and tests).
    keep(&estimator_core::scalar::sincos_f32(bb(0.5)));
    keep(&estimator_core::scalar::atan2_f32(bb(0.5), bb(-0.25)));
    keep(&estimator_core::scalar::sqrt_f32(bb(0.5)));
    // Self-test of the check itself: a reachable panic must make the link fail.
    #[cfg(feature = "selftest-panic")]
    {
        let a = [1u8, 2, 3, 4];
        bb(bb(&a[..])[bb(7usize)]);
    }
    #[cfg(feature = "f64")]
    api::<f64>();
    loop {
        core::hint::spin_loop();
    }
}

#[path = "../no_panic_handler.rs"]
mod no_panic_handler;

#[cfg(target_arch = "arm")]
#[path = "../vectors.rs"]
mod vectors;

#[path = "../mem.rs"]
mod mem;

//! Link-time no-panic check.
//!
//! Calls every public entry point of `estimator-core` (f32; f64 too with `--features f64`) with
//! opaque inputs (`core::hint::black_box`: the optimizer knows nothing of lengths, values or
//! enum variants), and keeps every result alive. The panic handler calls a function that exists
//! nowhere, so the link fails (`undefined symbol: __estimator_core_panic_path_reachable`) as soon
//! as any panic path survives optimization. With `--features locate-panics` the handler is a
//! plain loop instead: the binary links, and `.ci/firmware.sh` lists which functions call into
//! `core::panicking` (the culprits).
//!
//! This binary is never run; it is also the "firmware calling the whole public API" whose flash
//! footprint the README reports (opt-level "s").
#![no_std]
#![no_main]
#![allow(unused_must_use)] // results are kept alive with black_box, not inspected

use core::hint::black_box as bb;
use cortex_m_rt::entry;
use estimator_core::eskf::{
    align_at_rest, AccelerometerAtRest, Ahrs, AhrsState, BaroAltitude, CameraLandmark, ErrorState,
    FilterConfig, Gate, GateProbability, GnssPosition, GnssVelocity, GravityDirection, Heading,
    ImuNoise, ImuSample, InitialSigmas, Ins, InsState, Magnetometer, MagnetometerWindow,
    Measurement, PinholeIntrinsics, UpdateOptions, ZeroVelocity,
};
use estimator_core::gn::{
    check_point_spread, point_reprojection_error, reprojection_error, solve, solve_pnp,
    solve_rotation_from_vectors, triangulate, vector_pair_error, Factor, Loss, Manifold, Method,
    NormalEquations, PinholeCamera, PnpOptions, PnpProblem, Product, SolverOptions,
    TriangulationOptions, VectorPair,
};
use estimator_core::lie::{skew, LieGroup, Se2, Se3, So2, So3};
use estimator_core::Real;
use nalgebra::{
    Matrix2, Matrix3, Matrix4, Quaternion, SMatrix, SVector, UnitQuaternion, Vector2, Vector3,
    Vector6,
};

/// An opaque value of type `T`.
#[inline(always)]
fn o<T: Real>(x: f64) -> T {
    bb(T::lit(x))
}

fn v3<T: Real>() -> Vector3<T> {
    bb(Vector3::new(o(0.1), o(0.2), o(0.3)))
}

fn m3<T: Real>() -> Matrix3<T> {
    bb(Matrix3::identity())
}

/// Every method of `LieGroup`, on opaque inputs.
#[inline(never)]
fn group<T: Real, G: LieGroup<T>>(a: G, b: G, tau: G::Tangent, p: G::Point, m: G::Matrix) {
    let (a, b, tau, p, m) = (bb(a), bb(b), bb(tau), bb(p), bb(m));
    bb(G::identity());
    bb(G::exp(&tau));
    bb(a.log());
    bb(G::hat(&tau));
    bb(G::vee(&m));
    bb(a.compose(&b));
    bb(a.inverse());
    bb(a.between(&b));
    bb(a.act(&p));
    bb(a.rplus(&tau));
    bb(a.rminus(&b));
    bb(a.adjoint());
    bb(G::right_jacobian(&tau));
    bb(G::left_jacobian(&tau));
    bb(G::right_jacobian_inv(&tau));
    bb(G::left_jacobian_inv(&tau));
    bb(G::exp_jac(&tau));
    bb(a.log_jac());
    bb(a.inverse_jac());
    bb(a.compose_jac(&b));
    bb(a.act_jac(&p));
    bb(a.rplus_jac(&tau));
    bb(a.rminus_jac(&b));
    bb(a.between_jac(&b));
    bb(a.matrix());
    bb(a.normalize());
    bb(G::try_from_matrix(&m));
    bb(a.interpolate(&b, o(0.3)));
    bb(a.is_finite());
}

#[inline(never)]
fn lie<T: Real>() {
    // SO(2), SE(2).
    let s2 = So2::<T>::from_angle(o(0.4));
    bb(So2::<T>::from_cos_sin(o(0.6), o(0.8)));
    bb((
        s2.angle(),
        s2.cos(),
        s2.sin(),
        s2.rotation_matrix(),
        s2.cast::<f32>(),
    ));
    group::<T, So2<T>>(
        s2,
        So2::from_angle(o(-1.0)),
        bb(nalgebra::Vector1::new(o(0.2))),
        bb(Vector2::new(o(1.0), o(2.0))),
        bb(Matrix2::identity()),
    );
    let e2 = Se2::<T>::new(o(1.0), o(2.0), o(0.3));
    let e2b = Se2::from_parts(s2, bb(Vector2::new(o(0.5), o(0.1))));
    bb((e2.rotation(), e2.translation(), e2.cast::<f32>()));
    group::<T, Se2<T>>(
        e2,
        e2b,
        bb(nalgebra::Vector3::new(o(0.1), o(0.2), o(0.3))),
        bb(Vector2::new(o(1.0), o(2.0))),
        m3(),
    );
    // SO(3), SE(3).
    let q = bb(Quaternion::new(o(1.0), o(0.1), o(0.2), o(0.3)));
    bb(So3::<T>::from_quaternion(&q));
    bb(So3::<T>::from_wxyz(o(1.0), o(0.0), o(0.0), o(0.0)));
    let r = So3::<T>::from_unit_quaternion(bb(UnitQuaternion::identity()));
    bb((r.quaternion(), r.cast::<f32>(), r.rotation_matrix()));
    bb(So3::<T>::from_rotation_matrix(&m3()));
    group::<T, So3<T>>(r, So3::exp(&v3()), v3(), v3(), m3());
    let t = Se3::<T>::from_parts(r, v3());
    bb((t.rotation(), t.translation(), t.cast::<f32>()));
    group::<T, Se3<T>>(
        t,
        Se3::exp(&bb(Vector6::repeat(o(0.1)))),
        bb(Vector6::repeat(o(0.2))),
        v3(),
        bb(Matrix4::identity()),
    );
    bb(skew(&v3::<T>()));
    bb(o::<T>(0.7).sincos());
}

#[inline(never)]
fn eskf<T: Real>() {
    let config = FilterConfig::<T> {
        imu_noise: bb(ImuNoise::mems()),
        gravity: v3(),
        max_dt: o(0.1),
    };
    let config = bb(config);
    bb(config.validate());
    bb(FilterConfig::<T>::default());
    let imu = bb(ImuSample {
        gyro: v3(),
        accel: v3(),
        dt: o(0.01),
    });
    let opts = bb(UpdateOptions::ekf(bb(Gate::Probability(bb(
        GateProbability::P99,
    )))));
    let iter = bb(UpdateOptions::iterated(
        bb(Gate::Threshold(o(9.0))),
        bb(3),
        o(1e-6),
    ));
    bb(UpdateOptions::<T>::default());
    for g in [
        bb(Gate::<T>::Off),
        bb(Gate::Probability(GateProbability::P95)),
    ] {
        bb(g.threshold(bb(3)));
    }
    bb(GateProbability::P999.quantile::<T>(bb(9)));
    bb(bb(GateProbability::P95).z_score());

    // Alignment and initial covariance.
    let acc = [v3::<T>(); 8];
    let mags = [v3::<T>(); 8];
    let win = MagnetometerWindow {
        samples: bb(&mags[..]),
        reference: v3(),
    };
    let align = align_at_rest(bb(&acc[..]), bb(&acc[..]), &v3(), bb(Some(&win)), o(0.5));
    bb(&align);
    let sigmas = bb(InitialSigmas::<T>::default());
    bb(sigmas.attitude_covariance(&So3::exp(&v3()), &v3()));

    // The 15-state filter.
    let state = bb(InsState::<T>::identity());
    bb(state.oplus(&bb(SVector::<T, 15>::repeat(o(0.01)))));
    bb(ErrorState::is_finite(&state));
    bb(ErrorState::attitude(&state));
    let mut ins = match Ins::new(state, bb(SMatrix::<T, 15, 15>::identity()), config) {
        Ok(f) => f,
        Err(e) => {
            bb(e);
            return;
        }
    };
    if let Ok(a) = &align {
        bb(Ins::from_alignment(a, v3(), &sigmas, config));
        bb(Ahrs::from_alignment(a, &sigmas, config));
    }
    bb((ins.state(), ins.covariance(), ins.config(), ins.sigmas()));
    bb(ins.predict(&imu));
    let intr = bb(PinholeIntrinsics {
        fx: o(400.0),
        fy: o(400.0),
        cx: o(320.0),
        cy: o(240.0),
    });
    let cam = bb(CameraLandmark::new(
        bb(Vector2::new(o(300.0), o(200.0))),
        v3(),
        intr,
        bb(Se3::identity()),
        o(1.0),
    ));
    bb(cam.project(ins.state()));
    macro_rules! ins_update {
        ($m:expr) => {{
            let m = bb($m);
            bb(Measurement::<T, InsState<T>, 15, _>::linearize(
                &m,
                ins.state(),
            ));
            bb(Measurement::<T, InsState<T>, 15, _>::noise(&m));
            match bb(ins.update(&m, &opts)) {
                Ok(outcome) => {
                    bb((outcome.nis(), outcome.is_accepted()));
                }
                Err(e) => {
                    bb(e);
                }
            }
            bb(ins.update(&m, &iter));
        }};
    }
    ins_update!(GnssPosition::new(v3(), v3(), o(0.1)));
    ins_update!(GnssVelocity::new(v3(), o(0.1)));
    ins_update!(ZeroVelocity::new(o(0.1)));
    ins_update!(BaroAltitude::new(o(10.0), o(0.5)));
    ins_update!(Magnetometer::new(v3(), v3(), o(0.5)));
    ins_update!(GravityDirection::new(v3(), o(0.05)));
    ins_update!(Heading::new(o(0.3), o(0.05)));
    ins_update!(AccelerometerAtRest::new(v3(), o(0.1)));
    ins_update!(cam);
    bb(&ins);

    // The attitude-only filter.
    let st = bb(AhrsState::<T>::identity());
    bb(st.oplus(&bb(SVector::<T, 6>::repeat(o(0.01)))));
    let mut ahrs = match Ahrs::new(st, bb(SMatrix::<T, 6, 6>::identity()), config) {
        Ok(f) => f,
        Err(e) => {
            bb(e);
            return;
        }
    };
    bb((
        ahrs.state(),
        ahrs.covariance(),
        ahrs.config(),
        ahrs.sigmas(),
    ));
    bb(ahrs.predict(&v3(), o(0.01)));
    macro_rules! ahrs_update {
        ($m:expr) => {{
            let m = bb($m);
            bb(ahrs.update(&m, &opts));
            bb(ahrs.update(&m, &iter));
        }};
    }
    ahrs_update!(Magnetometer::new(v3(), v3(), o(0.5)));
    ahrs_update!(GravityDirection::new(v3(), o(0.05)));
    ahrs_update!(Heading::new(o(0.3), o(0.05)));
    bb(&ahrs);
}

#[inline(never)]
fn gn<T: Real>() {
    let camera = bb(PinholeCamera::<T>::new(
        o(400.0),
        o(400.0),
        o(320.0),
        o(240.0),
    ));
    bb(camera.is_valid());
    bb(camera.project(&v3(), o(1e-3)));
    bb(camera.project_jac(&v3(), o(1e-3)));
    bb(camera.unproject(&bb(Vector2::new(o(1.0), o(2.0)))));
    let pts_a = [v3::<T>(); 24];
    let px_a = [bb(Vector2::new(o(300.0), o(200.0))); 24];
    let (pts, px) = (bb(&pts_a[..]), bb(&px_a[..]));
    let pose = bb(Se3::<T>::identity());
    let pnp_opts = bb(PnpOptions::<T>::default()
        .with_loss(bb(Loss::Huber(o(2.0))))
        .with_sigma(o(0.5)));
    match bb(solve_pnp(pts, px, &camera, &pose, &pnp_opts)) {
        Ok(s) => {
            let inl = s.inliers;
            bb((
                inl.contains(bb(3)),
                inl.count(),
                inl.len(),
                inl.is_empty(),
                inl.bits(),
            ));
            for x in inl.iter() {
                bb(x);
            }
        }
        Err(e) => {
            bb(e);
        }
    }
    bb(check_point_spread(pts));
    bb(reprojection_error(
        &camera,
        &m3(),
        &v3(),
        &v3(),
        &bb(Vector2::new(o(1.0), o(2.0))),
        o(1.0),
        o(1e-3),
    ));
    let problem = bb(PnpProblem {
        world_points: pts,
        pixels: px,
        camera,
        inv_sigma: o(1.0),
        min_depth: o(1e-3),
    });
    let sopts = bb(SolverOptions::<T>::default());
    bb(sopts.is_valid());
    bb(solve::<T, Se3<T>, _, 6, 2>(&problem, &pose, &sopts));
    let mut gauss = sopts;
    gauss.method = bb(Method::GaussNewton);
    bb(solve::<T, Se3<T>, _, 6, 2>(&problem, &pose, &bb(gauss)));

    let poses = [pose; 4];
    bb(triangulate(
        bb(&poses[..]),
        bb(&px_a[..4]),
        &camera,
        &bb(TriangulationOptions::<T>::default()),
    ));
    bb(point_reprojection_error(
        &camera,
        &pose,
        &v3(),
        &bb(Vector2::new(o(1.0), o(2.0))),
        o(1.0),
        o(1e-3),
    ));
    let pairs = [bb(VectorPair {
        body: v3::<T>(),
        world: v3(),
        sigma: o(0.01),
    }); 3];
    bb(solve_rotation_from_vectors(
        bb(&pairs[..]),
        bb(Some(&So3::identity())),
        &sopts,
    ));
    bb(vector_pair_error(
        &So3::<T>::identity(),
        &v3(),
        &v3(),
        o(1.0),
    ));

    let a = bb(SMatrix::<T, 6, 6>::identity());
    if let Ok(f) = bb(Factor::new(&a)) {
        bb(f.solve(&bb(SVector::<T, 6>::repeat(o(1.0)))));
        bb(f.inverse());
    }
    let mut ne = NormalEquations::<T, 6>::zeros();
    ne.add::<2>(
        &bb(Loss::Cauchy(o(1.0))),
        &bb(SVector::<T, 2>::repeat(o(0.5))),
        &bb(SMatrix::<T, 2, 6>::repeat(o(0.1))),
    );
    bb(&ne);
    for l in [bb(Loss::<T>::LeastSquares), bb(Loss::Huber(o(1.0)))] {
        bb((l.is_valid(), l.scaled(o(2.0)), l.evaluate(o(3.0))));
    }
    let prod = Product::<So3<T>, SVector<T, 3>, 3, 3>::new(So3::identity(), v3());
    bb(Manifold::<T, 6>::oplus(
        &bb(prod),
        &bb(SVector::<T, 6>::repeat(o(0.1))),
    ));
    bb(Manifold::<T, 6>::all_finite(&prod));
    bb(Product::<So3<T>, SVector<T, 3>, 3, 3>::split::<T, 6>(&bb(
        SVector::<T, 6>::repeat(o(0.1)),
    )));
}

#[entry]
fn main() -> ! {
    lie::<f32>();
    eskf::<f32>();
    gn::<f32>();
    bb(estimator_core::scalar::sincos_f32(bb(0.5)));
    // Self-test of the check itself: a reachable panic must make the link fail.
    #[cfg(feature = "selftest-panic")]
    {
        let a = [1u8, 2, 3, 4];
        bb(bb(&a[..])[bb(7usize)]);
    }
    #[cfg(feature = "f64")]
    {
        lie::<f64>();
        eskf::<f64>();
        gn::<f64>();
    }
    loop {
        cortex_m::asm::nop();
    }
}

#[cfg(not(feature = "locate-panics"))]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    extern "C" {
        /// Defined nowhere: referencing it makes the link fail if a panic is reachable.
        fn __estimator_core_panic_path_reachable() -> !;
    }
    // SAFETY: never executed when the binary links (the symbol does not exist).
    unsafe { __estimator_core_panic_path_reachable() }
}

#[cfg(feature = "locate-panics")]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {
        cortex_m::asm::nop();
    }
}

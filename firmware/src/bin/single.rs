//! One public entry point of estimator-core alone in a firmware: the way a user's firmware holds
//! one call, with one call site for LTO to inline or not. The entry is chosen when the binary is
//! built, by name, in the environment variable `SINGLE_ENTRY` (one of [`ENTRIES`], [`AUXILIARY`]
//! or `<group>-<method>` of [`GROUPS`] × [`GROUP_OPS`]; `f64` with `--features f64`, else `f32`):
//!
//! ```sh
//! SINGLE_ENTRY=ins-gnss-position cargo build --profile release-s --bin single
//! ```
//!
//! The binary links only if no panic path is reachable from that call and what builds its
//! arguments (the filter's constructor). `.ci/firmware.sh` links every entry over the matrix of
//! opt-levels, CPU models and scalar types (the small ones over the two builds firmware ships,
//! all of them with `FIRMWARE_SINGLE_FULL=1`). An unknown name fails the build; without the
//! variable the binary calls nothing.
#![no_std]
#![no_main]

#[allow(dead_code)] // `input3` is for `f32` only; this binary builds its own
#[path = "../footprint/mod.rs"]
mod footprint;

use cortex_m_rt::entry;
use estimator_core::eskf::{
    align_at_rest, AccelerometerAtRest, Ahrs, AhrsAccelBias, AhrsAccelBiasState, AhrsState,
    Alignment, BaroAltitude, CameraLandmark, ErrorState, FilterConfig, Gate, GateProbability,
    GnssPosition, GnssVelocity, GravityDirection, Heading, ImuNoise, ImuSample, InitialSigmas, Ins,
    InsState, MagneticHeading, Magnetometer, Measurement, PinholeIntrinsics, UpdateOptions,
    UpdateOutcome, ZeroRate, ZeroVelocity,
};
use estimator_core::gn::{
    check_point_spread, point_reprojection_error, reprojection_error, solve, solve_pnp,
    solve_rotation_from_vectors, triangulate, vector_pair_error, Factor, Loss, Manifold,
    NormalEquations, PinholeCamera, PnpOptions, PnpProblem, Product, ResidualBlock, SolveError,
    SolverOptions, TriangulationOptions, VectorPair,
};
use estimator_core::lie::{LieGroup, Se2, Se3, So2, So3};
use estimator_core::nav::{
    AttitudeConfig, AttitudeNavigator, GnssFix, InsConfig, InsNavigator, MagneticConfig, VectorMean,
};
use estimator_core::Real;
use footprint::keep;
use nalgebra::{
    Matrix3, Quaternion, SMatrix, SVector, UnitQuaternion, Vector1, Vector2, Vector3, Vector6,
};

/// The scalar type of the build.
#[cfg(not(feature = "f64"))]
type F = f32;
/// The scalar type of the build.
#[cfg(feature = "f64")]
type F = f64;

/// An opaque number of the build's scalar type ([`footprint::input`]).
#[inline(always)]
fn x(i: usize) -> F {
    F::from(footprint::input(i))
}

/// Three opaque numbers from `i` on.
#[inline(always)]
fn x3(i: usize) -> Vector3<F> {
    Vector3::new(x(i), x(i + 1), x(i + 2))
}

/// Every entry this binary can hold besides the group operations ([`GROUPS`] × [`GROUP_OPS`]):
/// the calls a firmware main loop makes (each filter's prediction and each of its measurement
/// models, both navigators' sensor calls), the constructors that start them, and the solvers.
const ENTRIES: [&str; 66] = [
    "ins-new",
    "ins-from-alignment",
    "ins-predict",
    "ins-gnss-position",
    "ins-gnss-velocity",
    "ins-zero-velocity",
    "ins-baro",
    "ins-magnetometer",
    "ins-gravity",
    "ins-heading",
    "ins-accel-at-rest",
    "ins-zero-rate",
    "ins-magnetic-heading",
    "ins-camera",
    "ins-widen-reset",
    "ahrs-new",
    "ahrs-predict",
    "ahrs-magnetometer",
    "ahrs-gravity",
    "ahrs-heading",
    "ahrs-zero-rate",
    "ahrs-magnetic-heading",
    "ahrs-widen-attitude",
    "aab-from-alignment",
    "aab-predict",
    "aab-zero-rate",
    "aab-accel-at-rest",
    "aab-magnetic-heading",
    "aab-gravity",
    "aab-magnetometer",
    "aab-integrate-velocity",
    "aab-zero-velocity",
    "aab-restart-velocity",
    "align-at-rest",
    "attitude-navigator-imu",
    "attitude-navigator-magnetometer",
    "ins-navigator-imu",
    "ins-navigator-gnss",
    "ins-navigator-magnetometer-barometer",
    "solve-pnp",
    "solve",
    "triangulate",
    "solve-rotation-from-vectors",
    "factor",
    "normal-equations-add",
    "loss-evaluate",
    "camera-project",
    "camera-project-jac",
    "camera-unproject",
    "reprojection-error",
    "point-reprojection-error",
    "vector-pair-error",
    "check-point-spread",
    "so2-from-cos-sin",
    "so3-from-quaternion",
    "so3-from-rotation-matrix",
    "so3-renormalize",
    "gate-threshold",
    "gate-quantile",
    "filter-config-validate",
    "attitude-navigator-estimate",
    "ins-navigator-estimate",
    "vector-mean",
    "sincos-f32",
    "atan2-f32",
    "sqrt-f32",
];

/// Every other public function, each an entry: the readouts, the value constructors and
/// configurations, the start-up paths besides the main ones, the models' own linearizations, the
/// trait methods (state `⊕`, manifolds, a user's residual blocks, the scalar trait). Small
/// functions, linked like the group operations (`.ci/firmware.sh`).
const AUXILIARY: [&str; 46] = [
    "ins-accessors",
    "ahrs-accessors",
    "aab-accessors",
    "ins-from-attitude-filter",
    "ins-restart-from-attitude-filter",
    "ins-widen-attitude",
    "ahrs-from-alignment",
    "aab-new",
    "aab-restart-from-alignment",
    "aab-widen-attitude",
    "initial-sigmas-attitude-covariance",
    "update-options",
    "update-outcome",
    "config-constructors",
    "attitude-config-validate",
    "ins-config-validate",
    "attitude-navigator-new",
    "ins-navigator-new",
    "attitude-navigator-accessors",
    "ins-navigator-accessors",
    "gnss-position-linearize",
    "gnss-velocity-linearize",
    "zero-velocity-linearize",
    "baro-linearize",
    "magnetometer-linearize",
    "gravity-linearize",
    "heading-linearize",
    "accel-at-rest-linearize",
    "zero-rate-linearize",
    "magnetic-heading-linearize",
    "camera-landmark-linearize",
    "state-oplus",
    "se2-new",
    "so2-from-angle",
    "so3-from-wxyz",
    "so3-from-unit-quaternion",
    "lie-cast",
    "lie-accessors",
    "skew",
    "camera-is-valid",
    "manifold-oplus",
    "solve-residual-blocks",
    "pnp-options",
    "pnp-inliers",
    "solver-options-is-valid",
    "real-methods",
];

/// A user's residual block on `SO(3) × R³`: the error `e = [R ⊖ R̂; p − p̂] = [Log(R̂ᵀR); p − p̂]`
/// of a prior with unit sigmas, and its Jacobian `[J_r⁻¹(e_θ) 0; 0 I]` (right perturbation).
#[derive(Clone, Copy)]
struct Prior {
    rotation: So3<F>,
    point: Vector3<F>,
}

impl ResidualBlock<F, Product<So3<F>, Vector3<F>, 3, 3>, 6, 6> for Prior {
    fn evaluate(
        &self,
        state: &Product<So3<F>, Vector3<F>, 3, 3>,
    ) -> Result<(Vector6<F>, SMatrix<F, 6, 6>), SolveError> {
        let (e_theta, j_theta, _) = state.a.rminus_jac(&self.rotation);
        let mut e = Vector6::zeros();
        e.fixed_rows_mut::<3>(0).copy_from(&e_theta);
        e.fixed_rows_mut::<3>(3).copy_from(&(state.b - self.point));
        let mut j = SMatrix::<F, 6, 6>::identity();
        j.fixed_view_mut::<3, 3>(0, 0).copy_from(&j_theta);
        Ok((e, j))
    }
}

/// The groups whose every [`LieGroup`] method is an entry, `<group>-<method>`.
const GROUPS: [&str; 4] = ["so2", "se2", "so3", "se3"];

/// The [`LieGroup`] methods, each an entry for each of [`GROUPS`].
const GROUP_OPS: [&str; 29] = [
    "identity",
    "exp",
    "log",
    "hat",
    "vee",
    "compose",
    "inverse",
    "between",
    "act",
    "rplus",
    "rminus",
    "adjoint",
    "right_jacobian",
    "left_jacobian",
    "right_jacobian_inv",
    "left_jacobian_inv",
    "exp_jac",
    "log_jac",
    "inverse_jac",
    "compose_jac",
    "act_jac",
    "rplus_jac",
    "rminus_jac",
    "between_jac",
    "matrix",
    "normalize",
    "try_from_matrix",
    "interpolate",
    "is_finite",
];

/// The entry chosen at build time, or `""`.
const ENTRY: &str = match option_env!("SINGLE_ENTRY") {
    Some(e) => e,
    None => "",
};

/// `a == b`, at compile time.
const fn same(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

/// `entry` is `group-op`.
const fn same_op(entry: &str, group: &str, op: &str) -> bool {
    let (e, g, o) = (entry.as_bytes(), group.as_bytes(), op.as_bytes());
    if e.len() != g.len() + 1 + o.len() {
        return false;
    }
    let mut i = 0;
    while i < e.len() {
        let c = if i < g.len() {
            g[i]
        } else if i == g.len() {
            b'-'
        } else {
            o[i - g.len() - 1]
        };
        if e[i] != c {
            return false;
        }
        i += 1;
    }
    true
}

/// `entry` is empty, one of [`ENTRIES`] or [`AUXILIARY`], or a group operation.
const fn known(entry: &str) -> bool {
    let mut i = 0;
    while i < ENTRIES.len() {
        if same(entry, ENTRIES[i]) {
            return true;
        }
        i += 1;
    }
    let mut i = 0;
    while i < AUXILIARY.len() {
        if same(entry, AUXILIARY[i]) {
            return true;
        }
        i += 1;
    }
    let mut g = 0;
    while g < GROUPS.len() {
        let mut o = 0;
        while o < GROUP_OPS.len() {
            if same_op(entry, GROUPS[g], GROUP_OPS[o]) {
                return true;
            }
            o += 1;
        }
        g += 1;
    }
    entry.is_empty()
}

const _: () = assert!(known(ENTRY), "SINGLE_ENTRY names no entry");

/// Every [`LieGroup`] method of the group `$g` (tangent `N`, points `D`, matrices `M × M`), each
/// alone when the binary is built for `<$name>-<method>`, on opaque inputs (the second element
/// and the matrix made from opaque numbers too). Each condition is a constant.
macro_rules! group_ops {
    ($g:ty, $name:literal, $n:literal, $d:literal, $m:literal) => {{
        let tau = SVector::<F, $n>::from_fn(|i, _| x(i));
        let a = || <$g>::exp(&tau);
        let b = || <$g>::exp(&(tau * x(6)));
        let p = SVector::<F, $d>::from_fn(|i, _| x(i + 3));
        let m = SMatrix::<F, $m, $m>::from_fn(|i, j| x(i + 2 * j));
        macro_rules! op {
            ($op:literal, $call:expr) => {{
                const ON: bool = same_op(ENTRY, $name, $op);
                if ON {
                    keep(&$call);
                }
            }};
        }
        op!("identity", <$g>::identity());
        op!("exp", <$g>::exp(&tau));
        op!("log", a().log());
        op!("hat", <$g>::hat(&tau));
        op!("vee", <$g>::vee(&m));
        op!("compose", a().compose(&b()));
        op!("inverse", a().inverse());
        op!("between", a().between(&b()));
        op!("act", a().act(&p));
        op!("rplus", a().rplus(&tau));
        op!("rminus", a().rminus(&b()));
        op!("adjoint", a().adjoint());
        op!("right_jacobian", <$g>::right_jacobian(&tau));
        op!("left_jacobian", <$g>::left_jacobian(&tau));
        op!("right_jacobian_inv", <$g>::right_jacobian_inv(&tau));
        op!("left_jacobian_inv", <$g>::left_jacobian_inv(&tau));
        op!("exp_jac", <$g>::exp_jac(&tau));
        op!("log_jac", a().log_jac());
        op!("inverse_jac", a().inverse_jac());
        op!("compose_jac", a().compose_jac(&b()));
        op!("act_jac", a().act_jac(&p));
        op!("rplus_jac", a().rplus_jac(&tau));
        op!("rminus_jac", a().rminus_jac(&b()));
        op!("between_jac", a().between_jac(&b()));
        op!("matrix", a().matrix());
        op!("normalize", a().normalize());
        op!("try_from_matrix", <$g>::try_from_matrix(&m));
        op!("interpolate", a().interpolate(&b(), x(6)));
        op!("is_finite", a().is_finite());
    }};
}

/// Runs the block when the binary is built for entry `$name` (a constant condition: the other
/// blocks are not compiled into the binary).
macro_rules! only {
    ($name:literal, $body:block) => {{
        const ON: bool = same(ENTRY, $name);
        const _: () = assert!(known($name), "not in ENTRIES");
        if ON $body
    }};
}

#[entry]
fn main() -> ! {
    let config = FilterConfig::<F>::default();
    let options = UpdateOptions::<F>::default();
    let ins_new = || {
        Ins::new(
            InsState::identity(),
            SMatrix::<F, 15, 15>::identity() * x(7),
            config,
        )
    };
    let ahrs_new = || {
        Ahrs::new(
            AhrsState::identity(),
            SMatrix::<F, 6, 6>::identity() * x(7),
            config,
        )
    };
    let aab_new = || {
        AhrsAccelBias::new(
            AhrsAccelBiasState::identity(),
            SMatrix::<F, 12, 12>::identity() * x(7),
            config,
        )
    };
    let alignment = || Alignment {
        attitude: So3::exp(&x3(0)),
        gyro_bias: x3(1),
        heading_from_magnetometer: false,
    };
    let mut ins = ins_new();
    let mut ahrs = ahrs_new();
    let mut aab = aab_new();
    let mut att_nav = AttitudeNavigator::<F>::new({
        let mut c = AttitudeConfig::new(config);
        c.magnetometer = Some(MagneticConfig::new(x(6), Some(x3(4))));
        c
    });
    let mut ins_nav = InsNavigator::<F>::new({
        let mut a = AttitudeConfig::new(config);
        a.magnetometer = Some(MagneticConfig::new(x(6), Some(x3(4))));
        let mut c = InsConfig::new(a);
        c.barometer_sigma = Some(x(6));
        c
    });
    let mut t: u64 = 1_000_000_000;
    loop {
        t += 5_000_000;
        let imu = ImuSample {
            gyro: x3(0),
            accel: x3(1),
            dt: x(7),
        };
        only!("ins-new", { keep(&ins_new()) });
        only!("ins-from-alignment", {
            keep(&Ins::from_alignment(
                &alignment(),
                x3(2),
                &InitialSigmas::default(),
                config,
            ));
        });
        macro_rules! ins_call {
            ($name:literal, $f:ident => $call:expr) => {
                only!($name, {
                    if let Ok($f) = &mut ins {
                        keep(&$call);
                    }
                })
            };
        }
        ins_call!("ins-predict", f => f.predict(&imu));
        ins_call!("ins-gnss-position", f => f.update(&GnssPosition::new(x3(2), x3(5), x(6)), &options));
        ins_call!("ins-gnss-velocity", f => f.update(&GnssVelocity::new(x3(2), x(6)), &options));
        ins_call!("ins-zero-velocity", f => f.update(&ZeroVelocity::new(x(6)), &options));
        ins_call!("ins-baro", f => f.update(&BaroAltitude::new(x(3), x(6)), &options));
        ins_call!("ins-magnetometer", f => f.update(&Magnetometer::new(x3(4), x3(1), x(7)), &options));
        ins_call!("ins-gravity", f => f.update(&GravityDirection::new(x3(1), x(7)), &options));
        ins_call!("ins-heading", f => f.update(&Heading::new(x(2), x(7)), &options));
        ins_call!("ins-accel-at-rest", f => f.update(&AccelerometerAtRest::new(x3(1), x(7)), &options));
        ins_call!("ins-zero-rate", f => f.update(&ZeroRate::new(x3(0), x(7)), &options));
        ins_call!("ins-magnetic-heading", f => f.update(&MagneticHeading::new(x3(4), x3(1), x(7)), &options));
        ins_call!("ins-camera", f => {
            let intrinsics = PinholeIntrinsics { fx: x(6), fy: x(6), cx: x(4), cy: x(5) };
            let camera = Se3::exp(&Vector6::repeat(x(0)));
            f.update(&CameraLandmark::new(Vector2::new(x(3), x(4)), x3(0), intrinsics, camera, x(1)), &options)
        });
        ins_call!("ins-widen-reset", f => (
            f.widen_velocity(x(3)),
            f.widen_biases(x(6), x(7)),
            f.reset_position(x3(3), x(4)),
            f.reset_velocity(x3(0), x(5)),
        ));
        only!("ahrs-new", { keep(&ahrs_new()) });
        macro_rules! ahrs_call {
            ($name:literal, $f:ident => $call:expr) => {
                only!($name, {
                    if let Ok($f) = &mut ahrs {
                        keep(&$call);
                    }
                })
            };
        }
        ahrs_call!("ahrs-predict", f => f.predict(&imu));
        ahrs_call!("ahrs-magnetometer", f => f.update(&Magnetometer::new(x3(4), x3(1), x(7)), &options));
        ahrs_call!("ahrs-gravity", f => f.update(&GravityDirection::new(x3(1), x(7)), &options));
        ahrs_call!("ahrs-heading", f => f.update(&Heading::new(x(2), x(7)), &options));
        ahrs_call!("ahrs-zero-rate", f => f.update(&ZeroRate::new(x3(0), x(7)), &options));
        ahrs_call!("ahrs-magnetic-heading", f => f.update(&MagneticHeading::new(x3(4), x3(1), x(7)), &options));
        ahrs_call!("ahrs-widen-attitude", f => f.widen_attitude(x(0), x(1)));
        only!("aab-from-alignment", {
            keep(&AhrsAccelBias::from_alignment(
                &alignment(),
                &InitialSigmas::default(),
                config,
            ));
        });
        macro_rules! aab_call {
            ($name:literal, $f:ident => $call:expr) => {
                only!($name, {
                    if let Ok($f) = &mut aab {
                        keep(&$call);
                    }
                })
            };
        }
        aab_call!("aab-predict", f => f.predict(&imu));
        aab_call!("aab-zero-rate", f => f.update(&ZeroRate::new(x3(0), x(7)), &options));
        aab_call!("aab-accel-at-rest", f => f.update(&AccelerometerAtRest::new(x3(1), x(7)), &options));
        aab_call!("aab-magnetic-heading", f => f.update(&MagneticHeading::new(x3(4), x3(1), x(7)), &options));
        aab_call!("aab-gravity", f => f.update(&GravityDirection::new(x3(1), x(7)), &options));
        aab_call!("aab-magnetometer", f => f.update(&Magnetometer::new(x3(4), x3(1), x(7)), &options));
        aab_call!("aab-integrate-velocity", f => f.integrate_velocity(&x3(1), &Matrix3::from_diagonal(&x3(4)), x(7)));
        aab_call!("aab-zero-velocity", f => f.update(&ZeroVelocity::new(x(7)), &options));
        aab_call!("aab-restart-velocity", f => f.restart_velocity(x3(0), x(7)));
        only!("align-at-rest", {
            let samples = [x3(1); 8];
            let gyro = [x3(0); 8];
            keep(&align_at_rest(&samples, &gyro, &config.gravity, None, x(7)));
        });
        only!("attitude-navigator-imu", {
            if let Ok(n) = &mut att_nav {
                keep(&n.imu(t, &x3(0), &x3(1)));
            }
        });
        only!("attitude-navigator-magnetometer", {
            if let Ok(n) = &mut att_nav {
                keep(&n.magnetometer(t, &x3(4)));
            }
        });
        only!("ins-navigator-imu", {
            if let Ok(n) = &mut ins_nav {
                keep(&n.imu(t, &x3(0), &x3(1)));
            }
        });
        only!("ins-navigator-gnss", {
            if let Ok(n) = &mut ins_nav {
                keep(&n.gnss(t, &GnssFix::new(x3(2), Some(x3(3)), x(6), x(7))));
            }
        });
        only!("ins-navigator-magnetometer-barometer", {
            if let Ok(n) = &mut ins_nav {
                keep(&(n.magnetometer(t, &x3(4)), n.barometer(t, x(3))));
            }
        });
        group_ops!(So2<F>, "so2", 1, 2, 2);
        group_ops!(Se2<F>, "se2", 3, 2, 3);
        group_ops!(So3<F>, "so3", 3, 3, 3);
        group_ops!(Se3<F>, "se3", 6, 3, 4);
        let camera = PinholeCamera::new(x(6), x(6), x(4), x(5));
        let pose = Se3::exp(&Vector6::repeat(x(0)));
        let points = [x3(0); 12];
        let pixels = [Vector2::new(x(4), x(5)); 12];
        only!("solve-pnp", {
            keep(&solve_pnp(
                &points,
                &pixels,
                &camera,
                &pose,
                &PnpOptions::default(),
            ));
        });
        only!("solve", {
            let problem = PnpProblem {
                world_points: &points,
                pixels: &pixels,
                camera,
                inv_sigma: x(1),
                min_depth: x(7),
            };
            keep(&solve::<F, Se3<F>, _, 6, 2>(
                &problem,
                &pose,
                &SolverOptions::default(),
            ));
        });
        only!("triangulate", {
            let poses = [pose; 4];
            keep(&triangulate(
                &poses,
                &pixels[..4],
                &camera,
                &TriangulationOptions::default(),
            ));
        });
        only!("solve-rotation-from-vectors", {
            let pairs = [VectorPair {
                body: x3(0),
                world: x3(3),
                sigma: x(6),
            }; 3];
            keep(&solve_rotation_from_vectors(
                &pairs,
                None,
                &SolverOptions::default(),
            ));
        });
        only!("factor", {
            if let Ok(f) = Factor::new(&SMatrix::<F, 6, 6>::from_fn(|i, j| x(i + j))) {
                keep(&(f.solve(&SVector::<F, 6>::repeat(x(2))), f.inverse()));
            }
        });
        only!("normal-equations-add", {
            let mut ne = NormalEquations::<F, 6>::zeros();
            ne.add::<2>(
                &Loss::Cauchy(x(1)),
                &SVector::<F, 2>::repeat(x(3)),
                &SMatrix::<F, 2, 6>::from_fn(|i, j| x(i + j)),
            );
            keep(&ne);
        });
        only!("loss-evaluate", {
            let loss = Loss::Huber(x(2));
            keep(&(loss.is_valid(), loss.scaled(x(5)).evaluate(x(4))));
        });
        only!("camera-project", { keep(&camera.project(&x3(0), x(6))) });
        only!("camera-project-jac", {
            keep(&camera.project_jac(&x3(0), x(6)))
        });
        only!("camera-unproject", {
            keep(&camera.unproject(&Vector2::new(x(4), x(5))))
        });
        let m3 = Matrix3::from_fn(|i, j| x(i + 3 * j));
        only!("reprojection-error", {
            let z = Vector2::new(x(4), x(5));
            keep(&reprojection_error(
                &camera,
                &m3,
                &x3(0),
                &x3(3),
                &z,
                x(1),
                x(6),
            ));
        });
        only!("point-reprojection-error", {
            let z = Vector2::new(x(4), x(5));
            keep(&point_reprojection_error(
                &camera,
                &pose,
                &x3(0),
                &z,
                x(1),
                x(6),
            ));
        });
        only!("vector-pair-error", {
            keep(&vector_pair_error(&So3::exp(&x3(3)), &x3(0), &x3(3), x(1)));
        });
        only!("check-point-spread", { keep(&check_point_spread(&points)) });
        only!("so2-from-cos-sin", { keep(&So2::from_cos_sin(x(1), x(2))) });
        only!("so3-from-quaternion", {
            keep(&So3::from_quaternion(&Quaternion::new(
                x(3),
                x(0),
                x(1),
                x(2),
            )));
        });
        only!("so3-from-rotation-matrix", {
            keep(&So3::from_rotation_matrix(&m3))
        });
        only!("so3-renormalize", { keep(&So3::exp(&x3(0)).renormalize()) });
        only!("gate-threshold", {
            keep(&Gate::<F>::Probability(GateProbability::P95).threshold(3));
        });
        only!("gate-quantile", {
            keep(&(
                GateProbability::P999.quantile::<F>(9),
                GateProbability::P95.z_score(),
            ));
        });
        only!("filter-config-validate", {
            let c = FilterConfig::<F> {
                gravity: x3(3),
                max_dt: x(7),
                ..config
            };
            keep(&c.validate());
        });
        only!("attitude-navigator-estimate", {
            if let Ok(n) = &att_nav {
                keep(&n.estimate());
            }
        });
        only!("ins-navigator-estimate", {
            if let Ok(n) = &ins_nav {
                keep(&n.estimate());
            }
        });
        only!("vector-mean", {
            let mut mean = VectorMean::<F>::default();
            mean.add(&x3(0));
            mean.add(&x3(3));
            keep(&(mean.count(), mean.mean(), mean.scatter_sq()));
        });
        only!("sincos-f32", {
            keep(&estimator_core::scalar::sincos_f32(footprint::input(0)))
        });
        only!("atan2-f32", {
            keep(&estimator_core::scalar::atan2_f32(
                footprint::input(1),
                footprint::input(2),
            ));
        });
        only!("sqrt-f32", {
            keep(&estimator_core::scalar::sqrt_f32(footprint::input(3)))
        });
        // The auxiliary entries ([`AUXILIARY`]).
        macro_rules! readouts {
            ($name:literal, $f:expr) => {
                only!($name, {
                    if let Ok(f) = &$f {
                        keep(&(f.state(), f.covariance(), f.config(), f.sigmas()));
                    }
                })
            };
        }
        readouts!("ins-accessors", ins);
        readouts!("ahrs-accessors", ahrs);
        readouts!("aab-accessors", aab);
        only!("ins-from-attitude-filter", {
            if let Ok(a) = &aab {
                keep(&Ins::from_attitude_filter(
                    a,
                    &So3::exp(&x3(2)),
                    x3(3),
                    x3(4),
                    x(5),
                    x(6),
                ));
            }
        });
        only!("ins-restart-from-attitude-filter", {
            if let (Ok(f), Ok(a)) = (&mut ins, &aab) {
                keep(&f.restart_from_attitude_filter(
                    a,
                    &So3::exp(&x3(2)),
                    x3(3),
                    x3(4),
                    x(5),
                    x(6),
                ));
            }
        });
        ins_call!("ins-widen-attitude", f => f.widen_attitude(x(0), x(1)));
        only!("ahrs-from-alignment", {
            keep(&Ahrs::from_alignment(
                &alignment(),
                &InitialSigmas::default(),
                config,
            ));
        });
        only!("aab-new", { keep(&aab_new()) });
        aab_call!("aab-restart-from-alignment", f => f.restart_from_alignment(&alignment(), &InitialSigmas::default()));
        aab_call!("aab-widen-attitude", f => f.widen_attitude(x(0), x(1)));
        only!("initial-sigmas-attitude-covariance", {
            let sigmas = InitialSigmas {
                tilt: x(1),
                yaw: x(2),
                ..InitialSigmas::default()
            };
            keep(&sigmas.attitude_covariance(&So3::exp(&x3(0)), &x3(3)));
        });
        only!("update-options", {
            keep(&(
                UpdateOptions::ekf(Gate::Threshold(x(1))),
                UpdateOptions::iterated(Gate::Probability(GateProbability::P99), 4, x(2)),
            ));
        });
        only!("update-outcome", {
            let outcome = if x(1) > x(2) {
                UpdateOutcome::Accepted {
                    nis: x(3),
                    iterations: 1,
                }
            } else {
                UpdateOutcome::Rejected {
                    nis: x(4),
                    threshold: x(5),
                }
            };
            keep(&(outcome.nis(), outcome.is_accepted()));
        });
        only!("config-constructors", {
            let filter = FilterConfig::<F> {
                imu_noise: ImuNoise::mems(),
                ..FilterConfig::default()
            };
            let attitude = AttitudeConfig::new(filter);
            keep(&(
                attitude,
                MagneticConfig::new(x(1), Some(x3(2))),
                InsConfig::new(attitude),
                InitialSigmas::<F>::default(),
                GnssFix::new(x3(2), None, x(5), x(6)),
            ));
        });
        only!("attitude-config-validate", {
            let mut c = AttitudeConfig::new(config);
            c.startup_s = x(1);
            c.magnetometer = Some(MagneticConfig::new(x(2), Some(x3(3))));
            keep(&c.validate());
        });
        only!("ins-config-validate", {
            let mut c = InsConfig::new(AttitudeConfig::new(config));
            c.horizon_s = x(1);
            c.barometer_sigma = Some(x(2));
            keep(&c.validate());
        });
        only!("attitude-navigator-new", {
            let mut c = AttitudeConfig::new(config);
            c.startup_s = x(1);
            keep(&AttitudeNavigator::<F>::new(c));
        });
        only!("ins-navigator-new", {
            let mut c = InsConfig::new(AttitudeConfig::new(config));
            c.horizon_s = x(1);
            keep(&InsNavigator::<F>::new(c));
        });
        only!("attitude-navigator-accessors", {
            if let Ok(n) = &att_nav {
                keep(&(
                    n.config(),
                    n.filter(),
                    n.report(),
                    n.report().tilt.is_valid(),
                    n.counters(),
                    n.magnetic_reference(),
                ));
            }
        });
        only!("ins-navigator-accessors", {
            if let Ok(n) = &ins_nav {
                keep(&(
                    n.config(),
                    n.report(),
                    n.counters(),
                    n.filter(),
                    n.aligning(),
                ));
            }
        });
        let state = InsState {
            attitude: So3::exp(&x3(0)),
            velocity: x3(1),
            position: x3(2),
            gyro_bias: x3(3),
            accel_bias: x3(4),
        };
        macro_rules! linearize {
            ($name:literal, $model:expr, $m:literal) => {
                only!($name, {
                    let model = $model;
                    keep(&(
                        Measurement::<F, InsState<F>, 15, $m>::linearize(&model, &state),
                        Measurement::<F, InsState<F>, 15, $m>::noise(&model),
                    ));
                })
            };
        }
        linearize!(
            "gnss-position-linearize",
            GnssPosition::new(x3(2), x3(5), x(6)),
            3
        );
        linearize!("gnss-velocity-linearize", GnssVelocity::new(x3(2), x(6)), 3);
        linearize!("zero-velocity-linearize", ZeroVelocity::new(x(6)), 3);
        linearize!("baro-linearize", BaroAltitude::new(x(3), x(6)), 1);
        linearize!(
            "magnetometer-linearize",
            Magnetometer::new(x3(4), x3(1), x(7)),
            3
        );
        linearize!("gravity-linearize", GravityDirection::new(x3(1), x(7)), 3);
        linearize!("heading-linearize", Heading::new(x(2), x(7)), 1);
        linearize!(
            "accel-at-rest-linearize",
            AccelerometerAtRest::new(x3(1), x(7)),
            3
        );
        linearize!("zero-rate-linearize", ZeroRate::new(x3(0), x(7)), 3);
        linearize!(
            "magnetic-heading-linearize",
            MagneticHeading::new(x3(4), x3(1), x(7)),
            1
        );
        only!("camera-landmark-linearize", {
            let intrinsics = PinholeIntrinsics {
                fx: x(6),
                fy: x(6),
                cx: x(4),
                cy: x(5),
            };
            let camera = Se3::exp(&Vector6::repeat(x(0)));
            let model =
                CameraLandmark::new(Vector2::new(x(3), x(4)), x3(0), intrinsics, camera, x(1));
            keep(&(
                model.project(&state),
                model.linearize(&state),
                model.noise(),
            ));
        });
        only!("state-oplus", {
            let ahrs_state = AhrsState {
                attitude: state.attitude,
                gyro_bias: state.gyro_bias,
            };
            let aab_state = AhrsAccelBiasState {
                attitude: state.attitude,
                gyro_bias: state.gyro_bias,
                accel_bias: state.accel_bias,
                velocity: state.velocity,
            };
            let dx = SVector::<F, 15>::from_fn(|i, _| x(i % 8));
            keep(&(
                state.oplus(&dx),
                ahrs_state.oplus(&dx.fixed_rows::<6>(0).into_owned()),
                aab_state.oplus(&dx.fixed_rows::<12>(0).into_owned()),
                state.is_finite(),
                ErrorState::attitude(&aab_state),
            ));
        });
        only!("se2-new", {
            keep(&(
                Se2::new(x(0), x(1), x(2)),
                Se2::from_parts(So2::from_angle(x(3)), Vector2::new(x(4), x(5))),
            ));
        });
        only!("so2-from-angle", { keep(&So2::from_angle(x(2))) });
        only!("so3-from-wxyz", {
            keep(&So3::from_wxyz(x(3), x(0), x(1), x(2)))
        });
        only!("so3-from-unit-quaternion", {
            keep(&So3::from_unit_quaternion(UnitQuaternion::new_unchecked(
                Quaternion::new(x(3), x(0), x(1), x(2)),
            )));
        });
        only!("lie-cast", {
            keep(&(
                So2::<F>::from_angle(x(0)).cast::<f32>(),
                Se2::<F>::new(x(0), x(1), x(2)).cast::<f32>(),
                So3::<F>::exp(&x3(0)).cast::<f32>(),
                Se3::<F>::exp(&Vector6::repeat(x(1))).cast::<f32>(),
            ));
        });
        only!("lie-accessors", {
            let so2 = So2::from_angle(x(0));
            let se2 = Se2::new(x(0), x(1), x(2));
            let so3 = So3::exp(&x3(0));
            let se3 = Se3::from_parts(so3, x3(3));
            keep(&(
                (so2.angle(), so2.cos(), so2.sin(), so2.rotation_matrix()),
                (se2.rotation(), se2.translation()),
                (so3.quaternion(), so3.rotation_matrix()),
                (se3.rotation(), se3.translation()),
            ));
        });
        only!("skew", { keep(&estimator_core::lie::skew(&x3(0))) });
        only!("camera-is-valid", { keep(&camera.is_valid()) });
        only!("manifold-oplus", {
            let product = Product::<So3<F>, Vector3<F>, 3, 3>::new(So3::exp(&x3(0)), x3(3));
            let xi = Vector6::from_fn(|i, _| x(i));
            let moved: Product<So3<F>, Vector3<F>, 3, 3> = product.oplus(&xi);
            keep(&(
                Manifold::<F, 6>::all_finite(&moved),
                Manifold::<F, 1>::oplus(&So2::from_angle(x(1)), &Vector1::new(x(2))),
                Product::<So3<F>, Vector3<F>, 3, 3>::split(&xi),
            ));
        });
        only!("solve-residual-blocks", {
            let blocks = [
                Prior {
                    rotation: So3::exp(&x3(0)),
                    point: x3(3),
                },
                Prior {
                    rotation: So3::exp(&x3(1)),
                    point: x3(4),
                },
            ];
            let start = Product::new(So3::exp(&x3(2)), x3(5));
            keep(&solve::<F, _, [Prior], 6, 6>(
                &blocks[..],
                &start,
                &SolverOptions::default(),
            ));
            keep(&NormalEquations::<F, 6>::build::<_, [Prior], 6>(
                &blocks[..],
                &start,
                &Loss::Huber(x(6)),
            ));
        });
        only!("pnp-options", {
            keep(
                &PnpOptions::<F>::default()
                    .with_loss(Loss::Cauchy(x(1)))
                    .with_sigma(x(2)),
            );
        });
        only!("pnp-inliers", {
            if let Ok(solution) =
                solve_pnp(&points, &pixels, &camera, &pose, &PnpOptions::default())
            {
                let inliers = solution.inliers;
                keep(&(
                    inliers.contains(footprint::input(0) as usize),
                    inliers.count(),
                    inliers.len(),
                    inliers.is_empty(),
                    inliers.bits(),
                    inliers.iter().filter(|&b| b).count(),
                ));
            }
        });
        only!("solver-options-is-valid", {
            let options = SolverOptions::<F> {
                step_tolerance: x(1),
                ..SolverOptions::default()
            };
            keep(&options.is_valid());
        });
        only!("real-methods", {
            keep(&(
                F::lit(0.5) * x(0),
                x(1).sincos(),
                x(2).arctan2(x(3)),
                F::from_count(footprint::input(4) as u32),
                x(5).to_count(),
                estimator_core::scalar::taylor_cutoff(
                    f64::from(footprint::input(7)),
                    f64::from(footprint::input(6)),
                    f64::from(footprint::input(5)),
                    footprint::input(4) as u32,
                ),
            ));
        });
        keep(&t);
    }
}

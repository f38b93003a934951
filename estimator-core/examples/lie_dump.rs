//! Dumps f64 values of the Lie-group operations as JSON lines, for the external cross-check in
//! `tools/crosscheck/sophus_crosscheck.py` (against Sophus and a 50-digit mpmath reference).
//!
//! Run: `cargo run --release -q -p estimator-core --example lie_dump`
//!
//! Every line is one JSON object. `"kind": "single"` lines carry, for a tangent `tau`:
//! `exp` (= `exp(tau).matrix()`), `log` (= `log(exp(tau))`), `adj` (= `exp(tau).adjoint()`),
//! `jr`, `jl`, `jr_inv`, `jl_inv` (the Jacobians at `tau`). `"kind": "pair"` lines carry two
//! tangents `tau_a`, `tau_b` and `compose` (= `(exp(a)·exp(b)).matrix()`) and `between_log`
//! (= `log(exp(a)⁻¹·exp(b))`). Matrices are row-major nested lists. Numbers are printed with 17
//! significant digits (`{:.16e}`), which round-trips f64 exactly. The inputs are deterministic
//! (splitmix64 seeded with a constant) and grouped in classes `random`, `tiny` (rotation angle
//! 1e-9…1e-4, or exactly 0) and `near_pi` (rotation angle π ∓ d, d in 1e-6…1e-2).

use core::f64::consts::PI;

use estimator_core::lie::{MatrixLieGroup, Se2, Se3, So2, So3};
use nalgebra::{SMatrix, SVector, Vector3};

/// splitmix64 (Steele, Lea, Flood 2014): small, deterministic, good enough for test inputs.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[lo, hi)`.
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        let u = (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64);
        lo + (hi - lo) * u
    }

    /// A uniformly distributed unit 3-vector.
    fn unit3(&mut self) -> Vector3<f64> {
        loop {
            let v = Vector3::new(
                self.uniform(-1.0, 1.0),
                self.uniform(-1.0, 1.0),
                self.uniform(-1.0, 1.0),
            );
            let n = v.norm();
            if n > 0.1 && n <= 1.0 {
                return v / n;
            }
        }
    }
}

fn num(x: f64) -> String {
    if x.is_finite() {
        format!("{:.16e}", x)
    } else {
        // Not valid JSON numbers; Python's json module reads these tokens.
        if x.is_nan() {
            "NaN".into()
        } else if x > 0.0 {
            "Infinity".into()
        } else {
            "-Infinity".into()
        }
    }
}

fn vec_json<const N: usize>(v: &SVector<f64, N>) -> String {
    let items: Vec<String> = v.iter().map(|&x| num(x)).collect();
    format!("[{}]", items.join(","))
}

fn mat_json<const R: usize, const C: usize>(m: &SMatrix<f64, R, C>) -> String {
    let rows: Vec<String> = (0..R)
        .map(|i| {
            let items: Vec<String> = (0..C).map(|j| num(m[(i, j)])).collect();
            format!("[{}]", items.join(","))
        })
        .collect();
    format!("[{}]", rows.join(","))
}

fn single<G, const N: usize, const D: usize, const M: usize>(
    group: &str,
    class: &str,
    id: usize,
    tau: &SVector<f64, N>,
) where
    G: MatrixLieGroup<f64, N, D, M>,
{
    let g = G::exp(tau);
    println!(
        "{{\"group\":\"{group}\",\"class\":\"{class}\",\"kind\":\"single\",\"id\":{id},\
         \"tau\":{},\"exp\":{},\"log\":{},\"adj\":{},\"jr\":{},\"jl\":{},\"jr_inv\":{},\
         \"jl_inv\":{}}}",
        vec_json(tau),
        mat_json(&g.matrix()),
        vec_json(&g.log()),
        mat_json(&g.adjoint()),
        mat_json(&G::right_jacobian(tau)),
        mat_json(&G::left_jacobian(tau)),
        mat_json(&G::right_jacobian_inv(tau)),
        mat_json(&G::left_jacobian_inv(tau)),
    );
}

fn pair<G, const N: usize, const D: usize, const M: usize>(
    group: &str,
    class: &str,
    id: usize,
    ta: &SVector<f64, N>,
    tb: &SVector<f64, N>,
) where
    G: MatrixLieGroup<f64, N, D, M>,
{
    let (a, b) = (G::exp(ta), G::exp(tb));
    println!(
        "{{\"group\":\"{group}\",\"class\":\"{class}\",\"kind\":\"pair\",\"id\":{id},\
         \"tau_a\":{},\"tau_b\":{},\"compose\":{},\"between_log\":{}}}",
        vec_json(ta),
        vec_json(tb),
        mat_json(&a.compose(&b).matrix()),
        vec_json(&a.between(&b).log()),
    );
}

/// Tiny rotation angles (and exactly zero).
const TINY: [f64; 9] = [0.0, 1e-9, 3e-9, 1e-8, 1e-7, 1e-6, 1e-5, 3e-5, 1e-4];
/// Distances from π.
const NEAR_PI: [f64; 5] = [1e-6, 1e-5, 1e-4, 1e-3, 1e-2];
const N_RANDOM: usize = 40;

/// Rotation parts (3-D), translation parts drawn separately by the caller.
fn rot3_cases(rng: &mut SplitMix64) -> Vec<(&'static str, Vector3<f64>)> {
    let mut out = Vec::new();
    for _ in 0..N_RANDOM {
        // Components in [-2, 2): angles up to ~3.5 (beyond π, so log wraps too).
        let w = Vector3::new(
            rng.uniform(-2.0, 2.0),
            rng.uniform(-2.0, 2.0),
            rng.uniform(-2.0, 2.0),
        );
        out.push(("random", w));
    }
    for &t in &TINY {
        out.push(("tiny", rng.unit3() * t));
    }
    for &d in &NEAR_PI {
        // Below π and just beyond it (the latter's log is the angle π − d about −axis).
        out.push(("near_pi", rng.unit3() * (PI - d)));
        out.push(("near_pi", rng.unit3() * (PI + d)));
    }
    // A near-π case along a coordinate axis (largest quaternion component branch).
    out.push(("near_pi", Vector3::new(0.0, 0.0, PI - 1e-6)));
    out.push(("near_pi", Vector3::new(PI - 1e-3, 0.0, 0.0)));
    out
}

fn rot2_cases(rng: &mut SplitMix64) -> Vec<(&'static str, f64)> {
    let mut out = Vec::new();
    for _ in 0..N_RANDOM {
        out.push(("random", rng.uniform(-3.5, 3.5)));
    }
    for &t in &TINY {
        let s = if rng.uniform(-1.0, 1.0) < 0.0 {
            -1.0
        } else {
            1.0
        };
        out.push(("tiny", s * t));
    }
    for &d in &NEAR_PI {
        out.push(("near_pi", PI - d));
        out.push(("near_pi", PI + d));
        out.push(("near_pi", -(PI - d)));
    }
    out
}

fn main() {
    let mut rng = SplitMix64(0x5EED_1234_ABCD_0001);

    // ---- SO(3) ----
    let cases = rot3_cases(&mut rng);
    for (i, (class, w)) in cases.iter().enumerate() {
        single::<So3<f64>, 3, 3, 3>("SO3", class, i, w);
    }
    // Pairs: random; tiny between (b = a + tiny); near-π between (same axis, −π/2 and π/2 ∓ d).
    let mut id = 0;
    for _ in 0..N_RANDOM / 2 {
        let a = cases[id % N_RANDOM].1;
        let b = cases[(id + 7) % N_RANDOM].1;
        pair::<So3<f64>, 3, 3, 3>("SO3", "random", id, &a, &b);
        id += 1;
    }
    for &t in &TINY[1..] {
        let a = cases[id % N_RANDOM].1;
        let b = a + rng.unit3() * t;
        pair::<So3<f64>, 3, 3, 3>("SO3", "tiny", id, &a, &b);
        id += 1;
    }
    for &d in &NEAR_PI {
        for sgn in [-1.0, 1.0] {
            let n = rng.unit3();
            let a = n * (-PI / 2.0);
            let b = n * (PI / 2.0 + sgn * d);
            pair::<So3<f64>, 3, 3, 3>("SO3", "near_pi", id, &a, &b);
            id += 1;
        }
    }

    // ---- SE(3) ----  tangent [v; ω]
    let trans = |rng: &mut SplitMix64| {
        Vector3::new(
            rng.uniform(-3.0, 3.0),
            rng.uniform(-3.0, 3.0),
            rng.uniform(-3.0, 3.0),
        )
    };
    let join =
        |v: Vector3<f64>, w: Vector3<f64>| nalgebra::Vector6::new(v.x, v.y, v.z, w.x, w.y, w.z);
    let mut se3_cases = Vec::new();
    for (class, w) in rot3_cases(&mut rng) {
        let v = trans(&mut rng);
        se3_cases.push((class, join(v, w)));
    }
    // Pure translation, and tiny rotation with tiny translation.
    se3_cases.push((
        "tiny",
        join(Vector3::new(1.5, -0.25, 2.0), Vector3::zeros()),
    ));
    se3_cases.push(("tiny", join(trans(&mut rng) * 1e-7, rng.unit3() * 1e-8)));
    for (i, (class, xi)) in se3_cases.iter().enumerate() {
        single::<Se3<f64>, 6, 3, 4>("SE3", class, i, xi);
    }
    let mut id = 0;
    for _ in 0..N_RANDOM / 2 {
        let a = se3_cases[id % N_RANDOM].1;
        let b = se3_cases[(id + 7) % N_RANDOM].1;
        pair::<Se3<f64>, 6, 3, 4>("SE3", "random", id, &a, &b);
        id += 1;
    }
    for &t in &TINY[1..] {
        let a = se3_cases[id % N_RANDOM].1;
        let b = a + join(trans(&mut rng) * 0.1, rng.unit3() * t);
        pair::<Se3<f64>, 6, 3, 4>("SE3", "tiny", id, &a, &b);
        id += 1;
    }
    for &d in &NEAR_PI {
        for sgn in [-1.0, 1.0] {
            let n = rng.unit3();
            let a = join(trans(&mut rng), n * (-PI / 2.0));
            let b = join(trans(&mut rng), n * (PI / 2.0 + sgn * d));
            pair::<Se3<f64>, 6, 3, 4>("SE3", "near_pi", id, &a, &b);
            id += 1;
        }
    }

    // ---- SO(2) ----
    let cases2 = rot2_cases(&mut rng);
    let v1 = |x: f64| nalgebra::Vector1::new(x);
    for (i, (class, t)) in cases2.iter().enumerate() {
        single::<So2<f64>, 1, 2, 2>("SO2", class, i, &v1(*t));
    }
    let mut id = 0;
    for _ in 0..N_RANDOM / 2 {
        let a = cases2[id % N_RANDOM].1;
        let b = cases2[(id + 7) % N_RANDOM].1;
        pair::<So2<f64>, 1, 2, 2>("SO2", "random", id, &v1(a), &v1(b));
        id += 1;
    }
    for &t in &TINY[1..] {
        let a = cases2[id % N_RANDOM].1;
        pair::<So2<f64>, 1, 2, 2>("SO2", "tiny", id, &v1(a), &v1(a + t));
        id += 1;
    }
    for &d in &NEAR_PI {
        for sgn in [-1.0, 1.0] {
            let (a, b) = (-PI / 2.0, PI / 2.0 + sgn * d);
            pair::<So2<f64>, 1, 2, 2>("SO2", "near_pi", id, &v1(a), &v1(b));
            id += 1;
        }
    }

    // ---- SE(2) ----  tangent [v_x, v_y, ω]
    let mut se2_cases = Vec::new();
    for (class, t) in rot2_cases(&mut rng) {
        let v = (rng.uniform(-3.0, 3.0), rng.uniform(-3.0, 3.0));
        se2_cases.push((class, Vector3::new(v.0, v.1, t)));
    }
    se2_cases.push(("tiny", Vector3::new(1.5, -0.25, 0.0)));
    for (i, (class, tau)) in se2_cases.iter().enumerate() {
        single::<Se2<f64>, 3, 2, 3>("SE2", class, i, tau);
    }
    let mut id = 0;
    for _ in 0..N_RANDOM / 2 {
        let a = se2_cases[id % N_RANDOM].1;
        let b = se2_cases[(id + 7) % N_RANDOM].1;
        pair::<Se2<f64>, 3, 2, 3>("SE2", "random", id, &a, &b);
        id += 1;
    }
    for &t in &TINY[1..] {
        let a = se2_cases[id % N_RANDOM].1;
        let b = a + Vector3::new(rng.uniform(-0.3, 0.3), rng.uniform(-0.3, 0.3), t);
        pair::<Se2<f64>, 3, 2, 3>("SE2", "tiny", id, &a, &b);
        id += 1;
    }
    for &d in &NEAR_PI {
        for sgn in [-1.0, 1.0] {
            let a = Vector3::new(rng.uniform(-3.0, 3.0), rng.uniform(-3.0, 3.0), -PI / 2.0);
            let b = Vector3::new(
                rng.uniform(-3.0, 3.0),
                rng.uniform(-3.0, 3.0),
                PI / 2.0 + sgn * d,
            );
            pair::<Se2<f64>, 3, 2, 3>("SE2", "near_pi", id, &a, &b);
            id += 1;
        }
    }
}

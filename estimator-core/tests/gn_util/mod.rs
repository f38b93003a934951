//! Shared helpers of the `gn_*` tests: a deterministic PRNG (splitmix64 + Box-Muller), random
//! rotations and synthetic PnP problems, Richardson finite differences.
#![allow(dead_code)]

use estimator_core::gn::PinholeCamera;
use estimator_core::lie::{LieGroup, Se3, So3};
use nalgebra::{SMatrix, SVector, Vector2, Vector3, Vector6};

/// splitmix64 with Box-Muller normals.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(seed ^ 0x9E37_79B9_7F4A_7C15)
    }
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.uniform()
    }
    pub fn normal(&mut self) -> f64 {
        let u1 = self.uniform().max(1e-300);
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }
    pub fn unit3(&mut self) -> Vector3<f64> {
        loop {
            let v = Vector3::new(self.normal(), self.normal(), self.normal());
            let n = v.norm();
            if n > 1e-6 {
                return v / n;
            }
        }
    }
    pub fn rotation(&mut self) -> So3<f64> {
        So3::exp(&(self.unit3() * self.range(0.0, std::f64::consts::PI)))
    }
    pub fn pose(&mut self) -> Se3<f64> {
        let t = Vector3::new(self.normal(), self.normal(), self.normal()) * 2.0;
        Se3::from_parts(self.rotation(), t)
    }
}

pub fn camera() -> PinholeCamera<f64> {
    PinholeCamera::new(500.0, 500.0, 320.0, 240.0)
}

/// A synthetic PnP problem in f64.
pub struct PnpCase {
    pub truth: Se3<f64>,
    pub guess: Se3<f64>,
    pub world: Vec<Vector3<f64>>,
    pub pixels: Vec<Vector2<f64>>,
    pub outlier: Vec<bool>,
}

/// `n` points uniformly in the 640×480 image at depths 2–8 m, truth a random pose, pixels with
/// N(0, σ²) noise per axis, a fraction `outliers` of them replaced by uniform pixels in the image;
/// the guess is the truth moved by 20° about a random axis and 0.5 m along a random direction.
pub fn pnp_case(rng: &mut Rng, n: usize, sigma: f64, outliers: f64) -> PnpCase {
    let cam = camera();
    let truth = rng.pose();
    let world_from_camera = truth.inverse();
    let mut world = Vec::with_capacity(n);
    let mut pixels = Vec::with_capacity(n);
    let mut outlier = Vec::with_capacity(n);
    let n_out = (outliers * n as f64).round() as usize;
    for k in 0..n {
        let u = rng.range(0.0, 640.0);
        let v = rng.range(0.0, 480.0);
        let d = rng.range(2.0, 8.0);
        let x = cam.unproject(&Vector2::new(u, v)) * d;
        world.push(world_from_camera.act(&x));
        if k < n_out {
            pixels.push(Vector2::new(rng.range(0.0, 640.0), rng.range(0.0, 480.0)));
            outlier.push(true);
        } else {
            pixels.push(Vector2::new(
                u + sigma * rng.normal(),
                v + sigma * rng.normal(),
            ));
            outlier.push(false);
        }
    }
    let guess = perturb(rng, &truth, 20f64.to_radians(), 0.5);
    PnpCase {
        truth,
        guess,
        world,
        pixels,
        outlier,
    }
}

/// `truth ⊕ [0.5 m · u; 20° · a]`-like perturbation: rotation `angle` about a random axis,
/// translation `dist` along a random direction (applied on the camera side).
pub fn perturb(rng: &mut Rng, truth: &Se3<f64>, angle: f64, dist: f64) -> Se3<f64> {
    let dr = So3::exp(&(rng.unit3() * angle));
    let dt = rng.unit3() * dist;
    Se3::from_parts(
        dr.compose(&truth.rotation()),
        dr.act(&truth.translation()) + dt,
    )
}

pub fn cast_v3(v: &[Vector3<f64>]) -> Vec<Vector3<f32>> {
    v.iter().map(|p| p.cast::<f32>()).collect()
}
pub fn cast_v2(v: &[Vector2<f64>]) -> Vec<Vector2<f32>> {
    v.iter().map(|p| p.cast::<f32>()).collect()
}

/// Rotation angle between two poses, degrees, and translation distance, metres.
pub fn pose_error(a: &Se3<f64>, b: &Se3<f64>) -> (f64, f64) {
    let d = a
        .rotation()
        .between(&b.rotation())
        .log()
        .norm()
        .to_degrees();
    (d, (a.translation() - b.translation()).norm())
}

/// Richardson-extrapolated central difference of `f` at `ξ = 0`, column by column:
/// `D = (4 D(h/2) − D(h))/3`, truncation `O(h⁴)`.
pub fn fd_jacobian<const K: usize, const N: usize>(
    f: impl Fn(&SVector<f64, N>) -> SVector<f64, K>,
    h: f64,
) -> SMatrix<f64, K, N> {
    let mut j = SMatrix::<f64, K, N>::zeros();
    for c in 0..N {
        let d = |h: f64| {
            let mut e = SVector::<f64, N>::zeros();
            e[c] = h;
            (f(&e) - f(&-e)) / (2.0 * h)
        };
        let col = (d(h * 0.5) * 4.0 - d(h)) / 3.0;
        j.set_column(c, &col);
    }
    j
}

/// `δ = b ⊖ a` for SE(3) and the NEES `δᵀ P⁻¹ δ`.
pub fn nees(est: &Se3<f64>, truth: &Se3<f64>, cov: &SMatrix<f64, 6, 6>) -> f64 {
    let d: Vector6<f64> = truth.rminus(est);
    let inv = cov.try_inverse().expect("covariance invertible");
    (d.transpose() * inv * d)[(0, 0)]
}

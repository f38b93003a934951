//! Shared helpers of the `gn_*` tests: random rotations and synthetic PnP problems, on the
//! shared `support` module (random stream, finite differences).
#![allow(dead_code)]

use estimator_core::gn::PinholeCamera;
use estimator_core::lie::{LieGroup, Se3, So3};
use nalgebra::{SMatrix, Vector2, Vector3, Vector6};

pub use crate::support::{fd_jacobian, Rng};

/// Random rotations and poses on the shared stream.
pub trait RngExt {
    /// A rotation of uniformly distributed axis and angle in `[0, π)`.
    fn rotation(&mut self) -> So3<f64>;
    /// A pose: such a rotation, and a translation of `N(0, 2² I)`.
    fn pose(&mut self) -> Se3<f64>;
}

impl RngExt for Rng {
    fn rotation(&mut self) -> So3<f64> {
        So3::exp(&(self.unit3() * self.range(0.0, std::f64::consts::PI)))
    }
    fn pose(&mut self) -> Se3<f64> {
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

/// `δ = b ⊖ a` for SE(3) and the NEES `δᵀ P⁻¹ δ`.
pub fn nees(est: &Se3<f64>, truth: &Se3<f64>, cov: &SMatrix<f64, 6, 6>) -> f64 {
    let d: Vector6<f64> = truth.rminus(est);
    crate::support::nees(&d, cov)
}

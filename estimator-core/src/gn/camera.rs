//! The pinhole camera `z = K π(x)`, with the projection `π(x, y, z) = (x/z, y/z)` of section 4
//! of *Lie Groups and Smooth Manifolds for Robotic State Estimation* (`z_ij = π(T_i p_j)`), and
//! its Jacobian.

use crate::Real;
use nalgebra::{Matrix2x3, Vector2, Vector3};

/// Pinhole intrinsics: `u = fx·x/z + cx`, `v = fy·y/z + cy` (pixels), no distortion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PinholeCamera<T: Real> {
    /// Focal length along `u`, pixels.
    pub fx: T,
    /// Focal length along `v`, pixels.
    pub fy: T,
    /// Principal point `u`, pixels.
    pub cx: T,
    /// Principal point `v`, pixels.
    pub cy: T,
}

impl<T: Real> PinholeCamera<T> {
    /// `(fx, fy, cx, cy)`.
    #[must_use]
    pub fn new(fx: T, fy: T, cx: T, cy: T) -> Self {
        Self { fx, fy, cx, cy }
    }

    /// `true` when all four numbers are finite and both focal lengths positive.
    #[must_use]
    pub fn is_valid(&self) -> bool {
        super::all_positive(&[self.fx, self.fy]) && self.cx.is_finite() && self.cy.is_finite()
    }

    /// `K π(x)` for a point `x` in the camera frame; `None` unless `x.z > min_depth`.
    #[must_use]
    pub fn project(&self, x: &Vector3<T>, min_depth: T) -> Option<Vector2<T>> {
        let in_front = x.z > min_depth;
        if !in_front {
            return None;
        }
        let iz = T::one() / x.z;
        Some(Vector2::new(
            self.fx * x.x * iz + self.cx,
            self.fy * x.y * iz + self.cy,
        ))
    }

    /// `(K π(x), ∂(K π)/∂x)` with
    /// `∂(K π)/∂x = [[fx/z, 0, −fx x/z²], [0, fy/z, −fy y/z²]]`; `None` unless `x.z > min_depth`.
    #[must_use]
    pub fn project_jac(&self, x: &Vector3<T>, min_depth: T) -> Option<(Vector2<T>, Matrix2x3<T>)> {
        let in_front = x.z > min_depth;
        if !in_front {
            return None;
        }
        let iz = T::one() / x.z;
        let (a, b) = (x.x * iz, x.y * iz);
        let (fu, fv) = (self.fx * iz, self.fy * iz);
        Some((
            Vector2::new(self.fx * a + self.cx, self.fy * b + self.cy),
            Matrix2x3::new(fu, T::zero(), -fu * a, T::zero(), fv, -fv * b),
        ))
    }

    /// The ray `K⁻¹ [u, v, 1]ᵀ = ((u − cx)/fx, (v − cy)/fy, 1)` of a pixel, in the camera frame.
    #[must_use]
    pub fn unproject(&self, z: &Vector2<T>) -> Vector3<T> {
        Vector3::new(
            (z.x - self.cx) / self.fx,
            (z.y - self.cy) / self.fy,
            T::one(),
        )
    }
}

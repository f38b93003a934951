//! A known world landmark seen by a camera on the body.

use crate::eskf::error::EskfError;
use crate::eskf::state::InsState;
use crate::eskf::update::{Linearization, Measurement};
use crate::kernels::{all_finite, mat3};
use crate::lie::{skew, LieGroup, Se3};
use crate::Real;
use nalgebra::{Matrix2, Matrix3, SMatrix, Vector2, Vector3};

/// Pinhole intrinsics: `u = f_x x/z + c_x`, `v = f_y y/z + c_y` (pixels). The same type as the
/// solver's camera ([`crate::gn::PinholeCamera`]), so one calibration serves both.
pub type PinholeIntrinsics<T> = crate::gn::PinholeCamera<T>;

/// A known world landmark seen by a camera rigidly mounted on the body: `z = π(T_cw ℓ)` (the
/// observation `z_ij = π(T_i p_j)` of *Lie Groups and Smooth Manifolds for Robotic State
/// Estimation*, §4), with `T_cw = T_bc⁻¹·T_wb⁻¹` from the body pose `(R, p)` and the extrinsic
/// `T_bc` (`body_from_camera`).
///
/// `q = Rᵀ(ℓ − p)` (landmark in the body), `c = R_bcᵀ(q − t_bc)` (in the camera),
/// `∂q/∂δθ = [q]×`, `∂q/∂δp = −Rᵀ`, `∂c = R_bcᵀ ∂q`,
/// `∂π/∂c = [f_x/z, 0, −f_x x/z²; 0, f_y/z, −f_y y/z²]`. A depth `z ≤ min_depth` is an error.
///
/// ```
/// use estimator_core::eskf::{CameraLandmark, FilterConfig, Ins, InsState, PinholeIntrinsics, UpdateOptions};
/// use estimator_core::lie::{LieGroup, Se3};
/// use nalgebra::{SMatrix, Vector2, Vector3};
///
/// let mut ins = Ins::new(InsState::identity(), SMatrix::identity() * 0.01, FilterConfig::<f64>::default()).unwrap();
/// let camera = PinholeIntrinsics { fx: 400.0, fy: 400.0, cx: 320.0, cy: 240.0 };
/// // Camera looking along body z; the landmark 4 m ahead of it, seen at the image centre.
/// let seen = CameraLandmark::new(Vector2::new(320.0, 240.0), Vector3::new(0.0, 0.0, 4.0), camera, Se3::identity(), 1.0);
/// let (pixel, _) = seen.project(ins.state()).unwrap();
/// assert!((pixel - Vector2::new(320.0, 240.0)).norm() < 1e-9);
/// ins.update(&seen, &UpdateOptions::default()).unwrap();
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraLandmark<T: Real> {
    /// Observed pixel `(u, v)`.
    pub pixel: Vector2<T>,
    /// Landmark position, world frame, m.
    pub landmark: Vector3<T>,
    /// Intrinsics.
    pub intrinsics: PinholeIntrinsics<T>,
    /// `T_bc`: body from camera.
    pub body_from_camera: Se3<T>,
    /// `R`, px².
    pub noise: Matrix2<T>,
    /// Smallest accepted depth in the camera, m (e.g. `0.01`); positive
    /// ([`EskfError::InvalidOption`] otherwise: at zero depth the projection is singular).
    pub min_depth: T,
}

/// The pixel `(u, v)`, the landmark in the camera `c` and in the body `q`.
type Projection<T> = (Vector2<T>, Vector3<T>, Vector3<T>);

impl<T: Real> CameraLandmark<T> {
    /// Isotropic pixel noise `σ² I`, minimum depth 1 cm.
    #[must_use]
    pub fn new(
        pixel: Vector2<T>,
        landmark: Vector3<T>,
        intrinsics: PinholeIntrinsics<T>,
        body_from_camera: Se3<T>,
        sigma_px: T,
    ) -> Self {
        Self {
            pixel,
            landmark,
            intrinsics,
            body_from_camera,
            noise: Matrix2::from_diagonal_element(sigma_px * sigma_px),
            min_depth: T::lit(0.01),
        }
    }

    /// The predicted pixel and the landmark in the camera frame, or [`EskfError::BehindCamera`].
    pub fn project(&self, x: &InsState<T>) -> Result<(Vector2<T>, Vector3<T>), EskfError> {
        self.project_parts(x).map(|(u, c, _)| (u, c))
    }

    /// [`Self::project`], and the landmark in the body `q` (the linearization needs it too).
    fn project_parts(&self, x: &InsState<T>) -> Result<Projection<T>, EskfError> {
        let q = x.attitude.inverse().act(&(self.landmark - x.position));
        let c = self
            .body_from_camera
            .rotation()
            .inverse()
            .act(&(q - self.body_from_camera.translation()));
        // False for a NaN depth too.
        let in_front = c.z > self.min_depth;
        if !in_front {
            return Err(EskfError::BehindCamera);
        }
        let k = &self.intrinsics;
        let u = Vector2::new(k.fx * c.x / c.z + k.cx, k.fy * c.y / c.z + k.cy);
        Ok((u, c, q))
    }
}

impl<T: Real> Measurement<T, InsState<T>, 15, 2> for CameraLandmark<T> {
    fn linearize(&self, x: &InsState<T>) -> Result<Linearization<T, 15, 2>, EskfError> {
        let k = &self.intrinsics;
        if !(all_finite(self.pixel.as_slice())
            && all_finite(self.landmark.as_slice())
            && all_finite(&[k.fx, k.fy, k.cx, k.cy, self.min_depth])
            && self.body_from_camera.is_finite())
        {
            return Err(EskfError::NonFinite);
        }
        if self.min_depth <= T::zero() {
            return Err(EskfError::InvalidOption);
        }
        let (uv, c, q) = self.project_parts(x)?;
        let r_cb = self
            .body_from_camera
            .rotation()
            .rotation_matrix()
            .transpose();
        let r_t = x.attitude.rotation_matrix().transpose();
        let iz = T::one() / c.z;
        let z = T::zero();
        // ∂π/∂c, with a zero third row so that the 3×3 product serves.
        let d_pi = Matrix3::new(
            k.fx * iz,
            z,
            -k.fx * c.x * iz * iz,
            z,
            k.fy * iz,
            -k.fy * c.y * iz * iz,
            z,
            z,
            z,
        );
        let d_c = mat3::mul(&d_pi, &r_cb);
        let d_attitude = mat3::mul(&d_c, &skew(&q));
        let d_position = -mat3::mul(&d_c, &r_t);
        let mut jacobian = SMatrix::<T, 2, 15>::zeros();
        for (col, block) in [(0, &d_attitude), (6, &d_position)] {
            // Column-major data, not `column_iter` (views whose bounds check an opt-level "z"
            // build may keep).
            for (c, src) in block.data.0.iter().enumerate() {
                for (r, v) in src.iter().take(2).enumerate() {
                    if let Some(e) = jacobian.get_mut((r, col + c)) {
                        *e = *v;
                    }
                }
            }
        }
        Ok(Linearization {
            residual: self.pixel - uv,
            jacobian,
        })
    }

    fn noise(&self) -> Matrix2<T> {
        self.noise
    }
}

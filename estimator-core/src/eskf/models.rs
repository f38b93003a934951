//! Measurement models `z = h(x) + n`, each with its right Jacobian `H = ∂h(x ⊕ δx)/∂δx`.
//!
//! Derivations use `R·exp(δθ^) ≈ R(I + [δθ]×)`, hence `(R exp(δθ^))ᵀ a ≈ Rᵀa + [Rᵀa]× δθ` and
//! `R exp(δθ^) b ≈ R b − R[b]× δθ` (seed Theorem 5.1 / Example 5.2: the action Jacobian
//! `R[−b]×`).

use super::error::EskfError;
use super::imu::{finite, greater, mm, set_blk_rc, tr33};
use super::state::{ErrorState, InsState};
use super::update::{Linearization, Measurement};
use crate::lie::{skew, LieGroup, Se3, So3};
use crate::Real;
use nalgebra::{Matrix1, Matrix2, Matrix3, SMatrix, Vector1, Vector2, Vector3};

/// `σ² I` (written out: nalgebra's `identity() * s` is a generic loop at opt-level "s").
#[cfg_attr(estimator_compact, inline(never))]
fn iso3<T: Real>(sigma: T) -> Matrix3<T> {
    let (s, z) = (sigma * sigma, T::zero());
    Matrix3::new(s, z, z, z, s, z, z, z, s)
}

/// The `M × N` Jacobian that is zero except for the given blocks: the first `M` rows of each
/// `(column, block)` go to columns `column..column + 3`. One helper for every model, so that
/// each shape has one copy of the loop.
pub(crate) fn jacobian<T: Real, const M: usize, const N: usize>(
    blocks: &[(usize, &Matrix3<T>)],
) -> SMatrix<T, M, N> {
    let mut h = SMatrix::<T, M, N>::zeros();
    for (col, b) in blocks {
        for c in 0..3 {
            for r in 0..M {
                if let (Some(d), Some(s)) = (h.get_mut((r, col + c)), b.get((r, c))) {
                    *d = *s;
                }
            }
        }
    }
    h
}

/// The linearization of a three-row model that sees only the attitude, from its residual and
/// attitude block: one copy per filter shared by the direction models ([`Magnetometer`],
/// [`GravityDirection`]).
fn attitude_only<T: Real, const N: usize>(
    parts: Result<(Vector3<T>, Matrix3<T>), EskfError>,
) -> Result<Linearization<T, N, 3>, EskfError> {
    let (residual, h_att) = parts?;
    // The block stored into the result's own Jacobian (not built aside and copied in).
    let mut lin = Linearization {
        residual,
        jacobian: SMatrix::zeros(),
    };
    set_blk_rc(&mut lin.jacobian, 0, 0, &h_att);
    Ok(lin)
}

/// Sets the identity block in columns `col..col + 3` of `h` (the models that observe a vector
/// state directly).
fn set_identity<T: Real, const N: usize>(h: &mut SMatrix<T, 3, N>, col: usize) {
    for k in 0..3 {
        if let Some(e) = h.get_mut((k, col + k)) {
            *e = T::one();
        }
    }
}

/// A world vector `v` seen in the body, `Rᵀ v`, and its attitude Jacobian `[Rᵀ v]×` (module
/// docs: `(R exp(δθ^))ᵀ v ≈ Rᵀ v + [Rᵀ v]× δθ`). Shared by the direction models (one copy).
fn in_body<T: Real>(attitude: &So3<T>, v: &Vector3<T>) -> (Vector3<T>, Matrix3<T>) {
    let b = attitude.inverse().act(v);
    (b, skew(&b))
}

/// `a − b`, entry by entry (the same differences as nalgebra's `a - b`, without its generic
/// loop).
#[cfg_attr(estimator_compact, inline(never))]
pub(crate) fn sub3<T: Real>(a: &Vector3<T>, b: &Vector3<T>) -> Vector3<T> {
    Vector3::new(a.x - b.x, a.y - b.y, a.z - b.z)
}

/// `a + b`, entry by entry.
#[cfg_attr(estimator_compact, inline(never))]
pub(crate) fn add3<T: Real>(a: &Vector3<T>, b: &Vector3<T>) -> Vector3<T> {
    Vector3::new(a.x + b.x, a.y + b.y, a.z + b.z)
}

/// `v / s`, entry by entry.
#[cfg_attr(estimator_compact, inline(never))]
pub(crate) fn div3<T: Real>(v: &Vector3<T>, s: T) -> Vector3<T> {
    Vector3::new(v.x / s, v.y / s, v.z / s)
}

/// `−v`, entry by entry.
#[cfg_attr(estimator_compact, inline(never))]
pub(crate) fn neg3<T: Real>(v: &Vector3<T>) -> Vector3<T> {
    Vector3::new(-v.x, -v.y, -v.z)
}

/// `a · b = a_x b_x + a_y b_y + a_z b_z`, summed left to right: the products and sums of
/// nalgebra's `dot` (and `norm_squared`, which adds that to a leading zero: `0 + s = s` for a sum
/// of squares), without its generic code.
#[cfg_attr(estimator_compact, inline(never))]
pub(crate) fn dot3<T: Real>(a: &Vector3<T>, b: &Vector3<T>) -> T {
    a.x * b.x + a.y * b.y + a.z * b.z
}

/// `‖v‖ = √(v · v)`, as nalgebra's `norm`.
pub(crate) fn norm3<T: Real>(v: &Vector3<T>) -> T {
    dot3(v, v).sqrt_rn()
}

/// GNSS antenna position in the world frame, with the antenna at `lever_arm` in the body frame.
///
/// `h(x) = p + R ℓ`; `H = [−R[ℓ]×, 0, I, 0, 0]` (blocks δθ, δv, δp, δb_g, δb_a).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GnssPosition<T: Real> {
    /// Measured antenna position `z`, world frame, m.
    pub position: Vector3<T>,
    /// Antenna position `ℓ` in the body frame, m.
    pub lever_arm: Vector3<T>,
    /// `R`, m².
    pub noise: Matrix3<T>,
}

impl<T: Real> GnssPosition<T> {
    /// Isotropic noise `σ² I`.
    #[must_use]
    pub fn new(position: Vector3<T>, lever_arm: Vector3<T>, sigma: T) -> Self {
        Self {
            position,
            lever_arm,
            noise: iso3(sigma),
        }
    }
}

impl<T: Real> Measurement<T, InsState<T>, 15, 3> for GnssPosition<T> {
    #[cfg_attr(estimator_compact, inline(never))]
    fn linearize(&self, x: &InsState<T>) -> Result<Linearization<T, 15, 3>, EskfError> {
        if !(finite(&self.position) && finite(&self.lever_arm)) {
            return Err(EskfError::NonFinite);
        }
        let (rl, d_att, _) = x.attitude.act_jac(&self.lever_arm);
        let mut lin = Linearization {
            residual: sub3(&self.position, &add3(&x.position, &rl)),
            jacobian: SMatrix::zeros(),
        };
        set_blk_rc(&mut lin.jacobian, 0, 0, &d_att);
        set_identity(&mut lin.jacobian, 6);
        Ok(lin)
    }
    fn noise(&self) -> Matrix3<T> {
        self.noise
    }
}

/// GNSS velocity in the world frame (lever arm neglected): `h(x) = v`, `H = [0, I, 0, 0, 0]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GnssVelocity<T: Real> {
    /// Measured velocity, world frame, m/s.
    pub velocity: Vector3<T>,
    /// `R`, (m/s)².
    pub noise: Matrix3<T>,
}

impl<T: Real> GnssVelocity<T> {
    /// Isotropic noise `σ² I`.
    #[must_use]
    pub fn new(velocity: Vector3<T>, sigma: T) -> Self {
        Self {
            velocity,
            noise: iso3(sigma),
        }
    }
}

impl<T: Real> Measurement<T, InsState<T>, 15, 3> for GnssVelocity<T> {
    #[cfg_attr(estimator_compact, inline(never))]
    fn linearize(&self, x: &InsState<T>) -> Result<Linearization<T, 15, 3>, EskfError> {
        if !finite(&self.velocity) {
            return Err(EskfError::NonFinite);
        }
        let mut lin = Linearization {
            residual: sub3(&self.velocity, &x.velocity),
            jacobian: SMatrix::zeros(),
        };
        set_identity(&mut lin.jacobian, 3);
        Ok(lin)
    }
    fn noise(&self) -> Matrix3<T> {
        self.noise
    }
}

/// Zero-velocity update: `z = 0`, `h(x) = v`, `H = [0, I, 0, 0, 0]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ZeroVelocity<T: Real> {
    /// `R`, (m/s)².
    pub noise: Matrix3<T>,
}

impl<T: Real> ZeroVelocity<T> {
    /// Isotropic noise `σ² I`.
    #[must_use]
    pub fn new(sigma: T) -> Self {
        Self { noise: iso3(sigma) }
    }
}

impl<T: Real> Measurement<T, InsState<T>, 15, 3> for ZeroVelocity<T> {
    #[cfg_attr(estimator_compact, inline(never))]
    fn linearize(&self, x: &InsState<T>) -> Result<Linearization<T, 15, 3>, EskfError> {
        let mut lin = Linearization {
            residual: neg3(&x.velocity),
            jacobian: SMatrix::zeros(),
        };
        set_identity(&mut lin.jacobian, 3);
        Ok(lin)
    }
    fn noise(&self) -> Matrix3<T> {
        self.noise
    }
}

/// Barometric altitude (world `z`, up): `h(x) = p_z + offset`, `H = e₃ᵀ` on `δp`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BaroAltitude<T: Real> {
    /// Measured altitude, m.
    pub altitude: T,
    /// Known offset between the barometric and the world altitude datum, m.
    pub offset: T,
    /// `R = σ²`, m².
    pub noise: Matrix1<T>,
}

impl<T: Real> BaroAltitude<T> {
    /// Zero offset, noise `σ²`.
    #[must_use]
    pub fn new(altitude: T, sigma: T) -> Self {
        Self {
            altitude,
            offset: T::zero(),
            noise: Matrix1::new(sigma * sigma),
        }
    }
}

impl<T: Real> Measurement<T, InsState<T>, 15, 1> for BaroAltitude<T> {
    #[cfg_attr(estimator_compact, inline(never))]
    fn linearize(&self, x: &InsState<T>) -> Result<Linearization<T, 15, 1>, EskfError> {
        if !(self.altitude.is_finite() && self.offset.is_finite()) {
            return Err(EskfError::NonFinite);
        }
        let mut lin = Linearization {
            residual: Vector1::new(self.altitude - (x.position.z + self.offset)),
            jacobian: SMatrix::<T, 1, 15>::zeros(),
        };
        if let Some(e) = lin.jacobian.get_mut((0, 8)) {
            *e = T::one();
        }
        Ok(lin)
    }
    fn noise(&self) -> Matrix1<T> {
        self.noise
    }
}

/// Three-axis magnetometer against a world reference field: `h(x) = Rᵀ m_w`,
/// `H = [[Rᵀ m_w]×, 0, …]` (only the attitude columns are nonzero). For both filters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Magnetometer<T: Real> {
    /// Measured field, body frame (any unit, the same as `reference`).
    pub field: Vector3<T>,
    /// The world reference field `m_w`.
    pub reference: Vector3<T>,
    /// `R`, unit².
    pub noise: Matrix3<T>,
}

impl<T: Real> Magnetometer<T> {
    /// Isotropic noise `σ² I`.
    #[must_use]
    pub fn new(field: Vector3<T>, reference: Vector3<T>, sigma: T) -> Self {
        Self {
            field,
            reference,
            noise: iso3(sigma),
        }
    }

    /// The residual `z − Rᵀ m_w` and the attitude block `[Rᵀ m_w]×`: the part that does not
    /// depend on the filter (one copy for both).
    fn attitude_parts(&self, attitude: &So3<T>) -> Result<(Vector3<T>, Matrix3<T>), EskfError> {
        if !(finite(&self.field) && finite(&self.reference)) {
            return Err(EskfError::NonFinite);
        }
        if dot3(&self.field, &self.field) <= T::zero()
            || dot3(&self.reference, &self.reference) <= T::zero()
        {
            return Err(EskfError::ZeroNorm);
        }
        let b = in_body(attitude, &self.reference);
        Ok((sub3(&self.field, &b.0), b.1))
    }
}

impl<T: Real, S: ErrorState<T, N>, const N: usize> Measurement<T, S, N, 3> for Magnetometer<T> {
    #[cfg_attr(estimator_compact, inline(never))]
    fn linearize(&self, x: &S) -> Result<Linearization<T, N, 3>, EskfError> {
        attitude_only(self.attitude_parts(x.attitude()))
    }
    fn noise(&self) -> Matrix3<T> {
        self.noise
    }
}

/// Accelerometer gravity direction (tilt aiding, for a body near rest):
/// `z = f_m/‖f_m‖`, `h(x) = Rᵀ u` with `u` the world up direction, `H = [[Rᵀ u]×, 0, …]`.
/// For both filters.
///
/// The model neglects the accelerometer bias and any non-gravitational acceleration; both are
/// time-correlated errors (`‖b_a‖/g`, `‖a‖/g` radians), so `σ` must cover them, or repeated
/// updates make the filter overconfident. In the 15-state filter, which estimates `b_a`, prefer
/// [`ZeroVelocity`] at rest.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GravityDirection<T: Real> {
    /// Measured specific force `f_m`, body frame (normalized inside).
    pub accel: Vector3<T>,
    /// World direction the accelerometer reads at rest (`−g/‖g‖`, `[0, 0, 1]` in ENU).
    pub up: Vector3<T>,
    /// `R` on the unit direction (rad², small-angle).
    pub noise: Matrix3<T>,
}

impl<T: Real> GravityDirection<T> {
    /// ENU up `[0, 0, 1]`, isotropic noise `σ² I` (σ in radians of tilt).
    #[must_use]
    pub fn new(accel: Vector3<T>, sigma: T) -> Self {
        Self {
            accel,
            up: Vector3::z(),
            noise: iso3(sigma),
        }
    }

    /// The residual `f_m/‖f_m‖ − Rᵀ u` and the attitude block `[Rᵀ u]×` (one copy for both
    /// filters).
    fn attitude_parts(&self, attitude: &So3<T>) -> Result<(Vector3<T>, Matrix3<T>), EskfError> {
        if !(finite(&self.accel) && finite(&self.up)) {
            return Err(EskfError::NonFinite);
        }
        let (na, nu) = (norm3(&self.accel), norm3(&self.up));
        if !(na > T::zero() && nu > T::zero()) {
            return Err(EskfError::ZeroNorm);
        }
        let b = in_body(attitude, &div3(&self.up, nu));
        Ok((sub3(&div3(&self.accel, na), &b.0), b.1))
    }
}

impl<T: Real, S: ErrorState<T, N>, const N: usize> Measurement<T, S, N, 3> for GravityDirection<T> {
    #[cfg_attr(estimator_compact, inline(never))]
    fn linearize(&self, x: &S) -> Result<Linearization<T, N, 3>, EskfError> {
        attitude_only(self.attitude_parts(x.attitude()))
    }
    fn noise(&self) -> Matrix3<T> {
        self.noise
    }
}

/// The accelerometer of a body at rest (15-state filter): `h(x) = Rᵀ(−g) + b_a`,
/// `H = [[Rᵀ(−g)]×, 0, 0, 0, I]`. Unlike [`GravityDirection`] it models the accelerometer bias,
/// so repeated updates at rest stay consistent (tilt and horizontal bias are separated only as
/// far as the data allow).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AccelerometerAtRest<T: Real> {
    /// Measured specific force `f_m`, body frame, m/s².
    pub accel: Vector3<T>,
    /// World gravity `g` (`[0, 0, −9.81]`).
    pub gravity: Vector3<T>,
    /// `R`, (m/s²)².
    pub noise: Matrix3<T>,
}

impl<T: Real> AccelerometerAtRest<T> {
    /// ENU gravity `[0, 0, −9.81]`, isotropic noise `σ² I`.
    #[must_use]
    pub fn new(accel: Vector3<T>, sigma: T) -> Self {
        Self {
            accel,
            gravity: Vector3::new(T::zero(), T::zero(), T::lit(-9.81)),
            noise: iso3(sigma),
        }
    }
}

impl<T: Real> Measurement<T, InsState<T>, 15, 3> for AccelerometerAtRest<T> {
    #[cfg_attr(estimator_compact, inline(never))]
    fn linearize(&self, x: &InsState<T>) -> Result<Linearization<T, 15, 3>, EskfError> {
        if !(finite(&self.accel) && finite(&self.gravity)) {
            return Err(EskfError::NonFinite);
        }
        if dot3(&self.accel, &self.accel) <= T::zero() {
            return Err(EskfError::ZeroNorm);
        }
        let b = in_body(&x.attitude, &neg3(&self.gravity));
        let mut lin = Linearization {
            residual: sub3(&self.accel, &add3(&b.0, &x.accel_bias)),
            jacobian: SMatrix::zeros(),
        };
        set_blk_rc(&mut lin.jacobian, 0, 0, &b.1);
        set_identity(&mut lin.jacobian, 12);
        Ok(lin)
    }
    fn noise(&self) -> Matrix3<T> {
        self.noise
    }
}

/// Heading (yaw about world `z`) of the body `x` axis: `h(x) = ψ = atan2(R₂₁, R₁₁)`.
///
/// With `(c_x, c_y)` the first two entries of `R e₁` and `d(R e₁) = −R[e₁]× δθ`,
/// `H = (c_x ∂c_y − c_y ∂c_x)/(c_x² + c_y²)` on the attitude columns; the residual is wrapped
/// to `(−π, π]`. Singular (an error) when the body `x` axis is vertical. For both filters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Heading<T: Real> {
    /// Measured yaw, rad (counter-clockwise from world `x` = east).
    pub yaw: T,
    /// `R = σ²`, rad².
    pub noise: Matrix1<T>,
}

impl<T: Real> Heading<T> {
    /// Noise `σ²`.
    #[must_use]
    pub fn new(yaw: T, sigma: T) -> Self {
        Self {
            yaw,
            noise: Matrix1::new(sigma * sigma),
        }
    }

    /// The wrapped residual and the attitude row, one copy for both filters. With
    /// `R e₁ = (c_x, c_y, ·)` and `∂(R e₁)/∂δθ = −R[e₁]× = [0, −R e₃, R e₂]`
    /// (columns; `[e₁]× = [0, e₃, −e₂]`), the row `(c_x ∂c_y − c_y ∂c_x)/(c_x² + c_y²)` is
    /// `(0, c_y R₁₃ − c_x R₂₃, c_x R₂₂ − c_y R₁₂)/(c_x² + c_y²)`.
    fn attitude_parts(&self, attitude: &So3<T>) -> Result<(T, [T; 3]), EskfError> {
        if !self.yaw.is_finite() {
            return Err(EskfError::NonFinite);
        }
        let r = attitude.rotation_matrix();
        let (cx, cy) = (r.m11, r.m21);
        let n2 = cx * cx + cy * cy;
        if !greater(n2, T::lit(1e-6)) {
            return Err(EskfError::SingularGeometry);
        }
        let row = [
            T::zero(),
            (cy * r.m13 - cx * r.m23) / n2,
            (cx * r.m22 - cy * r.m12) / n2,
        ];
        let psi = cy.arctan2(cx);
        let (s, c) = (self.yaw - psi).sincos();
        Ok((s.arctan2(c), row))
    }
}

impl<T: Real, S: ErrorState<T, N>, const N: usize> Measurement<T, S, N, 1> for Heading<T> {
    #[cfg_attr(estimator_compact, inline(never))]
    fn linearize(&self, x: &S) -> Result<Linearization<T, N, 1>, EskfError> {
        // Read inside the `Result` (not moved out of it by `?`).
        let parts = self.attitude_parts(x.attitude());
        let (residual, row) = match &parts {
            Ok(p) => p,
            Err(e) => return Err(*e),
        };
        // The row's three entries in the attitude columns 0..3, zero elsewhere.
        let mut jacobian = SMatrix::<T, 1, N>::zeros();
        for (d, s) in jacobian.as_mut_slice().iter_mut().zip(row) {
            *d = *s;
        }
        Ok(Linearization {
            residual: Vector1::new(*residual),
            jacobian,
        })
    }
    fn noise(&self) -> Matrix1<T> {
        self.noise
    }
}

/// Pinhole intrinsics: `u = f_x x/z + c_x`, `v = f_y y/z + c_y` (pixels). The same type as the
/// solver's camera ([`crate::gn::PinholeCamera`]), so one calibration serves both.
pub type PinholeIntrinsics<T> = crate::gn::PinholeCamera<T>;

/// A known world landmark seen by a camera rigidly mounted on the body:
/// `z = π(T_cw p)` (seed `z_ij = π(T_i p_j)`), with `T_cw = T_bcᵀ·T_wbᵀ` from the body pose
/// `(R, p)` and the extrinsic `T_bc` (`body_from_camera`).
///
/// `q = Rᵀ(ℓ − p)` (landmark in the body), `c = R_bcᵀ(q − t_bc)` (in the camera),
/// `∂q/∂δθ = [q]×`, `∂q/∂δp = −Rᵀ`, `∂c = R_bcᵀ ∂q`,
/// `∂π/∂c = [f_x/z, 0, −f_x x/z²; 0, f_y/z, −f_y y/z²]`. A depth `z ≤ min_depth` is an error.
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
    /// Smallest accepted depth in the camera, m (e.g. `0.01`).
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
            noise: {
                // `I·σ²` entry by entry (the products of nalgebra's `identity() * σ²`).
                let s = sigma_px * sigma_px;
                let (d, o) = (T::one() * s, T::zero() * s);
                Matrix2::new(d, o, o, d)
            },
            min_depth: T::lit(0.01),
        }
    }

    /// The predicted pixel and the landmark in the camera frame, or [`EskfError::BehindCamera`].
    pub fn project(&self, x: &InsState<T>) -> Result<(Vector2<T>, Vector3<T>), EskfError> {
        self.project_parts(x).map(|(u, c, _)| (u, c))
    }

    /// [`Self::project`], and the landmark in the body `q` (the linearization needs it too).
    fn project_parts(&self, x: &InsState<T>) -> Result<Projection<T>, EskfError> {
        let q = x.attitude.inverse().act(&sub3(&self.landmark, &x.position));
        let rbc = self.body_from_camera.rotation();
        let c = rbc
            .inverse()
            .act(&sub3(&q, &self.body_from_camera.translation()));
        if !greater(c.z, self.min_depth) {
            return Err(EskfError::BehindCamera);
        }
        let k = &self.intrinsics;
        let u = Vector2::new(k.fx * c.x / c.z + k.cx, k.fy * c.y / c.z + k.cy);
        Ok((u, c, q))
    }
}

impl<T: Real> Measurement<T, InsState<T>, 15, 2> for CameraLandmark<T> {
    #[cfg_attr(estimator_compact, inline(never))]
    fn linearize(&self, x: &InsState<T>) -> Result<Linearization<T, 15, 2>, EskfError> {
        let k = &self.intrinsics;
        let all = [k.fx, k.fy, k.cx, k.cy, self.min_depth];
        if !(finite(&self.pixel)
            && finite(&self.landmark)
            && super::imu::sum_times_zero_is_zero(&all)
            && self.body_from_camera.is_finite())
        {
            return Err(EskfError::NonFinite);
        }
        // Read inside the `Result`, not moved out of it (no copy of the parts at opt-level "s").
        let parts = self.project_parts(x);
        let (uv, c, q) = match &parts {
            Ok(p) => p,
            Err(e) => return Err(*e),
        };
        let rcb = tr33(&self.body_from_camera.rotation().rotation_matrix());
        let rt = tr33(&x.attitude.rotation_matrix());
        let iz = T::one() / c.z;
        let z = T::zero();
        // ∂π/∂c with a zero third row, so that the 3×3 `mm` serves (rows 0, 1 are used).
        let jpi = Matrix3::new(
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
        let jc = mm(&jpi, &rcb);
        // −(J_c Rᵀ), negated entry by entry over the storage (nalgebra's `-m` is a generic loop).
        let mut jp = mm(&jc, &rt);
        for e in jp.as_mut_slice() {
            *e = -*e;
        }
        Ok(Linearization {
            residual: Vector2::new(self.pixel.x - uv.x, self.pixel.y - uv.y),
            // The blocks by reference (no copies into the list).
            jacobian: jacobian(&[(0, &mm(&jc, &skew(q))), (6, &jp)]),
        })
    }
    fn noise(&self) -> Matrix2<T> {
        self.noise
    }
}

//! Fixed-size matrix Lie groups SO(2), SE(2), SO(3), SE(3) with every Jacobian.
//!
//! The mathematics follows *Lie Groups and Smooth Manifolds for Robotic State Estimation*
//! ("the paper" below); equation, definition and theorem numbers refer to it.
//!
//! # Conventions (one, everywhere)
//!
//! * **Scalar.** Every type is generic over `T:`[`Real`] and works for `f32` and `f64`.
//! * **Hat and vee** (the paper, eq. 3.2): `τ^ = Σᵢ τᵢ Gⁱ`, with the generators `Gⁱ = hat(eᵢ)`
//!   listed on each group; `vee` is its inverse on the Lie algebra.
//! * **Exponential** (the paper, §3): `exp(τ^) = Σ_k (τ^)^k / k!`, evaluated in closed form.
//! * **Right (local) perturbation** (the paper, eq. 4.5): `a ⊕ τ = a · exp(τ^)` and
//!   `b ⊖ a = log(a⁻¹ · b)`. In code, `a.rplus(&τ)` is `a ⊕ τ` and `b.rminus(&a)` is `b ⊖ a`, so
//!   `a.rplus(&b.rminus(&a)) == b`.
//! * **Jacobians** are right Jacobians of that chart (the paper, Definition 4.6: `F_a` with
//!   `f(a·exp(τ^)) ≈ f(a) + F_a τ`): for `f: G → M`, `f(a ⊕ τ) ⊖ f(a) ≈ J τ`, the rows in `M`'s
//!   tangent, the columns in `G`'s tangent (for a vector-valued `f`, `⊕`/`⊖` are `+`/`−`). Names
//!   with `left` are the left-chart ones: `J_l(τ) = J_r(−τ)`.
//! * **Adjoint**: `a · exp(τ) = exp(Ad_a τ) · a`.
//! * **Tangent order**: SO(2) `θ`; SE(2) `[v_x, v_y, ω]`; SO(3) `ω`; SE(3) `ξ = [v; ω]`,
//!   translation part first, as the paper's twist `ξ = (v, ω)` (§3).
//! * **Quaternions**: Hamilton, `q = w + xi + yj + zk`, written `[w, x, y, z]`; unit norm is
//!   restored on input, and `w ≥ 0` is not required (`q` and `−q` are the same rotation).
//! * **Frames**: `a_from_b` maps coordinates in frame `b` into frame `a`; `act` applies that map.
//!
//! # Operations
//!
//! Every operation exists without Jacobians and, as `*_jac`, returning its value and one Jacobian
//! per argument in argument order (`self` first):
//!
//! | operation | value | Jacobians (right chart) |
//! |---|---|---|
//! | `exp_jac(τ)` | `exp(τ)` | `J_r(τ)` |
//! | `log_jac()` | `τ = log(a)` | `J_r⁻¹(τ)` |
//! | `inverse_jac()` | `a⁻¹` | `−Ad_a` |
//! | `compose_jac(b)` | `a·b` | `Ad_b⁻¹`, `I` |
//! | `between_jac(b)` | `a⁻¹·b` | `−Ad_{b⁻¹a}`, `I` |
//! | `rplus_jac(τ)` | `a ⊕ τ` | `Ad_{exp(τ)}⁻¹`, `J_r(τ)` |
//! | `rminus_jac(b)` | `τ = a ⊖ b` | `J_r⁻¹(τ)`, `−J_l⁻¹(τ)` |
//! | `act_jac(p)` | `a·p` | `a·[H(p) | I]` (the paper, Theorem 5.1), `R` |
//!
//! # Numerics
//!
//! Closed forms with series below per-coefficient cutoffs derived from the scalar's epsilon (see
//! the `trig` kernel); `1 − cos θ` is computed as `2 sin²(θ/2)`; the SO(3) logarithm goes through
//! the quaternion with `θ = 2·atan2(‖v‖, |w|)`, well conditioned up to and at `θ = π`. Non-finite
//! inputs propagate as non-finite values (never a panic); [`LieGroup::is_finite`] tells.
//!
//! # Example
//!
//! ```
//! use estimator_core::lie::{LieGroup, Se3, So3};
//! use nalgebra::{Vector3, Vector6};
//!
//! // a ⊕ τ = a·exp(τ^), and b ⊖ a = log(a⁻¹·b) undoes it.
//! let a = So3::exp(&Vector3::new(0.1, -0.4, 0.9));
//! let tau = Vector3::new(0.02, 0.03, -0.01);
//! let b = a.rplus(&tau);
//! assert!((b.rminus(&a) - tau).amax() < 1e-15);
//!
//! // The same on SE(3), whose tangent is ξ = [v; ω].
//! let t = Se3::exp(&Vector6::new(1.0, 2.0, 3.0, 0.1, 0.2, 0.3));
//! let xi = Vector6::new(0.01, 0.0, -0.02, 0.0, 0.03, 0.0);
//! assert!((t.rplus(&xi).rminus(&t) - xi).amax() < 1e-15);
//! ```

mod se2;
mod se3;
mod so2;
mod so3;
mod trig;

pub use se2::Se2;
pub use se3::Se3;
pub use so2::So2;
pub use so3::So3;

pub use crate::scalar::Real;

use crate::kernels::slice::dot;
use nalgebra::{Const, DimMin, Matrix3, SMatrix, SVector, Vector3};

/// A matrix Lie group acting on points, with the operations and Jacobians of the module docs.
///
/// Implemented by [`So2`], [`Se2`], [`So3`], [`Se3`]. Generic code that needs arithmetic on the
/// tangent and Jacobian types uses [`MatrixLieGroup`], which fixes them to nalgebra's fixed-size
/// matrices.
///
/// The default methods implement the Jacobians of the module docs from the group operations, the
/// adjoint and `J_r`, `J_r⁻¹`; a group overrides one only where it shares work between the value
/// and its Jacobians (one trigonometric kernel for `exp` and `J_r`, say).
///
/// # Example
///
/// Generic code over any group: the Jacobian of `a·b` with respect to `a` is `Ad_{b⁻¹}`, checked
/// here by a central difference through `⊕` and `⊖` (the paper's Definition 4.6).
///
/// ```
/// use estimator_core::lie::{LieGroup, MatrixLieGroup, Se2, So3};
/// use nalgebra::{SVector, Vector3};
///
/// fn check<G: MatrixLieGroup<f64, N, D, M>, const N: usize, const D: usize, const M: usize>(
///     a: G,
///     b: G,
/// ) {
///     let (ab, ja, jb) = a.compose_jac(&b);
///     assert_eq!(jb, nalgebra::SMatrix::<f64, N, N>::identity());
///     let h = 1e-6;
///     for i in 0..N {
///         let mut d = SVector::<f64, N>::zeros();
///         d[i] = h;
///         let col = (a.rplus(&d).compose(&b).rminus(&ab) - a.rplus(&-d).compose(&b).rminus(&ab))
///             / (2.0 * h);
///         assert!((col - ja.column(i)).amax() < 1e-8);
///     }
/// }
///
/// let (a, b) = (So3::exp(&Vector3::new(0.3, -0.2, 1.0)), So3::exp(&Vector3::new(-1.1, 0.4, 0.2)));
/// check::<So3<f64>, 3, 3, 3>(a, b);
/// check::<Se2<f64>, 3, 2, 3>(Se2::new(1.0, -2.0, 0.5), Se2::new(0.3, 0.7, -2.0));
/// ```
pub trait LieGroup<T: Real>: Copy + core::fmt::Debug + PartialEq + Sized {
    /// Degrees of freedom: the dimension of the tangent space.
    const DOF: usize;
    /// Dimension of the points the group acts on.
    const DIM: usize;

    /// Tangent vector `τ ∈ R^DOF`, in the order given in the module docs.
    type Tangent: Copy
        + core::fmt::Debug
        + PartialEq
        + core::ops::Neg<Output = Self::Tangent>
        + core::ops::Mul<T, Output = Self::Tangent>;
    /// `DOF × DOF` Jacobian.
    type Jacobian: Copy + core::fmt::Debug + PartialEq + core::ops::Neg<Output = Self::Jacobian>;
    /// A point of `R^DIM`.
    type Point: Copy + core::fmt::Debug + PartialEq;
    /// The matrix representation (rotation or homogeneous), also the type of Lie-algebra elements.
    type Matrix: Copy + core::fmt::Debug + PartialEq;
    /// `DIM × DOF`: Jacobian of `a·p` with respect to `a`.
    type ActJacobian: Copy + core::fmt::Debug + PartialEq;
    /// `DIM × DIM`: Jacobian of `a·p` with respect to `p`.
    type PointJacobian: Copy + core::fmt::Debug + PartialEq;

    /// The identity element `e`.
    #[must_use]
    fn identity() -> Self;

    /// `exp(τ^)`, the exponential map (the paper, §3): `exp(τ^) = Σ_k (τ^)^k / k!`.
    #[must_use]
    fn exp(tau: &Self::Tangent) -> Self;

    /// `log(a)^∨`, the inverse of [`LieGroup::exp`] on its principal domain (rotation angle in
    /// `[0, π]`).
    #[must_use]
    fn log(&self) -> Self::Tangent;

    /// `τ^ = Σᵢ τᵢ Gⁱ` (the paper, eq. 3.2).
    #[must_use]
    fn hat(tau: &Self::Tangent) -> Self::Matrix;

    /// The inverse of [`LieGroup::hat`]: reads the coordinates of a Lie-algebra element (only the
    /// entries that `hat` writes with a `+` sign are read).
    #[must_use]
    fn vee(m: &Self::Matrix) -> Self::Tangent;

    /// The group product `a·b`.
    #[must_use]
    fn compose(&self, b: &Self) -> Self;

    /// The inverse `a⁻¹`.
    #[must_use]
    fn inverse(&self) -> Self;

    /// The group action `a·p` (the paper, §5).
    #[must_use]
    fn act(&self, p: &Self::Point) -> Self::Point;

    /// The adjoint matrix `Ad_a`, with `a·exp(τ) = exp(Ad_a τ)·a`.
    #[must_use]
    fn adjoint(&self) -> Self::Jacobian;

    /// The right Jacobian `J_r(τ)`: `exp(τ + δ) ≈ exp(τ)·exp(J_r(τ) δ)`.
    #[must_use]
    fn right_jacobian(tau: &Self::Tangent) -> Self::Jacobian;

    /// `J_r(τ)⁻¹`: `log(exp(τ)·exp(δ)) ≈ τ + J_r⁻¹(τ) δ`.
    #[must_use]
    fn right_jacobian_inv(tau: &Self::Tangent) -> Self::Jacobian;

    /// The matrix representation: a rotation matrix for SO(n), homogeneous for SE(n).
    #[must_use]
    fn matrix(&self) -> Self::Matrix;

    /// Re-projects onto the group (unit quaternion or unit complex number), removing round-off
    /// drift after many compositions.
    #[must_use]
    fn normalize(&self) -> Self;

    /// From a rotation or homogeneous matrix; `None` where it is not close to the group
    /// (non-finite entries, determinant ≤ 0, or an orthogonality error `‖RᵀR − I‖_F` above
    /// [`ORTHOGONALITY_TOLERANCE`]). A matrix within that bound is projected onto the group.
    #[must_use]
    fn try_from_matrix(m: &Self::Matrix) -> Option<Self>;

    /// `true` when every stored number is finite.
    #[must_use]
    fn is_finite(&self) -> bool;

    /// `exp(τ)` and `J_r(τ)`, sharing the trigonometric coefficients.
    #[must_use]
    fn exp_jac(tau: &Self::Tangent) -> (Self, Self::Jacobian) {
        (Self::exp(tau), Self::right_jacobian(tau))
    }

    /// `τ = log(a)` and `J_r⁻¹(τ)`, sharing the trigonometric coefficients.
    #[must_use]
    fn log_jac(&self) -> (Self::Tangent, Self::Jacobian) {
        let tau = self.log();
        (tau, Self::right_jacobian_inv(&tau))
    }

    /// The left Jacobian `J_l(τ) = J_r(−τ)`: `exp(τ + δ) ≈ exp(J_l(τ) δ)·exp(τ)`.
    #[must_use]
    fn left_jacobian(tau: &Self::Tangent) -> Self::Jacobian {
        Self::right_jacobian(&-*tau)
    }

    /// `J_l(τ)⁻¹ = J_r(−τ)⁻¹`.
    #[must_use]
    fn left_jacobian_inv(tau: &Self::Tangent) -> Self::Jacobian {
        Self::right_jacobian_inv(&-*tau)
    }

    /// `a⁻¹·b`.
    #[must_use]
    fn between(&self, b: &Self) -> Self {
        self.inverse().compose(b)
    }

    /// `a ⊕ τ = a·exp(τ^)` (the paper, eq. 4.5).
    #[must_use]
    fn rplus(&self, tau: &Self::Tangent) -> Self {
        self.compose(&Self::exp(tau))
    }

    /// `a ⊖ b = log(b⁻¹·a)`, so that `b ⊕ (a ⊖ b) = a`.
    #[must_use]
    fn rminus(&self, b: &Self) -> Self::Tangent {
        b.between(self).log()
    }

    /// `a ⊕ s·(b ⊖ a)`: `s = 0` gives `a`, `s = 1` gives `b`, along the geodesic.
    #[must_use]
    fn interpolate(&self, b: &Self, s: T) -> Self {
        self.rplus(&(b.rminus(self) * s))
    }

    /// `(a⁻¹, −Ad_a)`.
    #[must_use]
    fn inverse_jac(&self) -> (Self, Self::Jacobian) {
        (self.inverse(), -self.adjoint())
    }

    /// `(a·b, Ad_b⁻¹ = Ad_{b⁻¹}, I)`.
    #[must_use]
    fn compose_jac(&self, b: &Self) -> (Self, Self::Jacobian, Self::Jacobian) {
        // `I` as `Ad_e` (the trait knows no identity matrix): a constant once compiled.
        (
            self.compose(b),
            b.inverse().adjoint(),
            Self::identity().adjoint(),
        )
    }

    /// `(z = a⁻¹·b, −Ad_{z⁻¹}, I)`.
    #[must_use]
    fn between_jac(&self, b: &Self) -> (Self, Self::Jacobian, Self::Jacobian) {
        let z = self.between(b);
        (z, -z.inverse().adjoint(), Self::identity().adjoint())
    }

    /// `(a ⊕ τ, Ad_{exp(τ)}⁻¹, J_r(τ))`.
    #[must_use]
    fn rplus_jac(&self, tau: &Self::Tangent) -> (Self, Self::Jacobian, Self::Jacobian) {
        let (e, jr) = Self::exp_jac(tau);
        (self.compose(&e), e.inverse().adjoint(), jr)
    }

    /// `(τ = a ⊖ b, J_r⁻¹(τ), −J_l⁻¹(τ))`.
    #[must_use]
    fn rminus_jac(&self, b: &Self) -> (Self::Tangent, Self::Jacobian, Self::Jacobian) {
        let tau = self.rminus(b);
        (
            tau,
            Self::right_jacobian_inv(&tau),
            -Self::left_jacobian_inv(&tau),
        )
    }

    /// `(a·p, ∂(a·p)/∂a, ∂(a·p)/∂p)`: the paper's Theorem 5.1, `F_(a,p) = a·[H(p) | I]` with
    /// `τ^ p = H(p) τ`.
    #[must_use]
    fn act_jac(&self, p: &Self::Point) -> (Self::Point, Self::ActJacobian, Self::PointJacobian);
}

/// A [`LieGroup`] whose tangent, Jacobian, point and matrix types are nalgebra's fixed-size types
/// of `N` degrees of freedom, acting on `R^D`, represented by `M × M` matrices. Implemented for
/// every group automatically; generic code (solvers, test batteries) bounds on this.
pub trait MatrixLieGroup<T: Real, const N: usize, const D: usize, const M: usize>:
    LieGroup<
    T,
    Tangent = SVector<T, N>,
    Jacobian = SMatrix<T, N, N>,
    Point = SVector<T, D>,
    Matrix = SMatrix<T, M, M>,
    ActJacobian = SMatrix<T, D, N>,
    PointJacobian = SMatrix<T, D, D>,
>
{
}

impl<T: Real, G, const N: usize, const D: usize, const M: usize> MatrixLieGroup<T, N, D, M> for G where
    G: LieGroup<
        T,
        Tangent = SVector<T, N>,
        Jacobian = SMatrix<T, N, N>,
        Point = SVector<T, D>,
        Matrix = SMatrix<T, M, M>,
        ActJacobian = SMatrix<T, D, N>,
        PointJacobian = SMatrix<T, D, D>,
    >
{
}

/// Largest orthogonality error `‖RᵀR − I‖_F` (Frobenius) that [`LieGroup::try_from_matrix`]
/// accepts and projects; larger is "not near the group".
pub const ORTHOGONALITY_TOLERANCE: f64 = 1e-3;

/// `[ω]×`, the skew-symmetric matrix with `[ω]× p = ω × p`: the SO(3) hat `ω^ = Σᵢ ωᵢ Gⁱ`
/// (the paper, eq. 3.2, with the generators of Example 5.2).
#[must_use]
pub fn skew<T: Real>(w: &Vector3<T>) -> Matrix3<T> {
    let z = T::zero();
    Matrix3::new(z, -w.z, w.y, w.z, z, -w.x, -w.y, w.x, z)
}

/// `s·I + p[ω]× + q[ω]×²`, the shape of the SO(3) series (`J_r = I − b[ω]× + c[ω]×²`,
/// `J_r⁻¹ = I + ½[ω]× + d[ω]×²`, see the SO(3) module docs), entry by entry with
/// `[ω]×² = ωωᵀ − ‖ω‖² I` (diagonal `−(ω_y² + ω_z²)` etc., a sum of squares that cannot
/// cancel).
///
/// The signs are exact: `[−ω]× = −[ω]×` and `[−ω]×² = [ω]×²`, so the transposed matrix
/// `J(ω)ᵀ = J(−ω)` is `p → −p`, and `−J` is `(s, p, q) → (−s, −p, −q)`.
#[must_use]
pub(crate) fn skew_poly<T: Real>(s: T, p: T, q: T, w: &Vector3<T>) -> Matrix3<T> {
    let (x, y, z) = (w.x, w.y, w.z);
    let (xx, yy, zz) = (x * x, y * y, z * z);
    let (qxy, qxz, qyz) = (q * x * y, q * x * z, q * y * z);
    let (px, py, pz) = (p * x, p * y, p * z);
    Matrix3::new(
        s - q * (yy + zz),
        qxy - pz,
        qxz + py,
        qxy + pz,
        s - q * (xx + zz),
        qyz - px,
        qxz - py,
        qyz + px,
        s - q * (xx + yy),
    )
}

/// `true` when `m` is within [`ORTHOGONALITY_TOLERANCE`] of SO(N): `‖mᵀm − I‖_F ≤ tol` and
/// `det m > 0`. `false` for a non-finite entry, whose square makes the error infinite or NaN.
pub(crate) fn near_rotation<T: Real, const N: usize>(m: &SMatrix<T, N, N>) -> bool
where
    Const<N>: DimMin<Const<N>, Output = Const<N>>,
{
    // ‖mᵀm − I‖²_F over the columns as arrays: (mᵀm)_ij = cᵢ·cⱼ (no nalgebra view, whose
    // index assertion is a panic path wherever it is not inlined).
    let cols = &m.data.0;
    let err = cols.iter().enumerate().fold(T::zero(), |acc, (i, ci)| {
        cols.iter().enumerate().fold(acc, |acc, (j, cj)| {
            let e = dot(ci, cj) - if i == j { T::one() } else { T::zero() };
            acc + e * e
        })
    });
    let tol = T::lit(ORTHOGONALITY_TOLERANCE);
    // Written so that NaN (which compares false) is rejected too.
    err <= tol * tol && m.determinant() > T::zero()
}

//! Fixed-size matrix Lie groups SO(2), SE(2), SO(3), SE(3) with every Jacobian.
//!
//! # Conventions (one, everywhere)
//!
//! * **Scalar.** Every type is generic over `T:`[`Real`] and works for `f32` and `f64`.
//! * **Hat and vee** (seed paper eq. 3.2): `τ^ = Σᵢ τᵢ Gⁱ`, with the generators `Gⁱ = hat(eᵢ)`
//!   listed on each group; `vee` is its inverse on the Lie algebra.
//! * **Exponential** (seed §3): `exp(τ) = Σ_k (τ^)^k / k!`, evaluated in closed form.
//! * **Right (local) perturbation** (seed eq. 4.5): `a ⊕ τ = a · exp(τ^)` and
//!   `b ⊖ a = log(a⁻¹ · b)`. In code, `a.rplus(&τ)` is `a ⊕ τ` and `b.rminus(&a)` is `b ⊖ a`, so
//!   `a.rplus(&b.rminus(&a)) == b`.
//! * **Jacobians** are right Jacobians of that chart (seed Def. 4.6): for `f: G → M`,
//!   `f(a ⊕ τ) ⊖ f(a) ≈ J τ`, the rows in `M`'s tangent, the columns in `G`'s tangent (for a
//!   vector-valued `f`, `⊕`/`⊖` are `+`/`−`). Names with `left` are the left-chart ones:
//!   `J_l(τ) = J_r(−τ)`.
//! * **Adjoint**: `a · exp(τ) = exp(Ad_a τ) · a`.
//! * **Tangent order**: SO(2) `θ`; SE(2) `[v_x, v_y, ω]`; SO(3) `ω`; SE(3) `ξ = [v; ω]`, translation
//!   part first, as the seed's twist `(v, ω)`.
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
//! | `act_jac(p)` | `a·p` | `R·[H(p) | I]`-type blocks (seed Theorem 5.1), `R` |
//!
//! # Numerics
//!
//! Closed forms with series below per-coefficient cutoffs derived from the scalar's epsilon (see
//! the `trig` kernel); `1 − cos θ` is computed as `2 sin²(θ/2)`; the SO(3) logarithm goes through
//! the quaternion with `θ = 2·atan2(‖v‖, |w|)`, well conditioned up to and at `θ = π`. Non-finite
//! inputs propagate as non-finite values (never a panic); [`LieGroup::is_finite`] tells.

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

use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

/// A matrix Lie group acting on points, with the operations and Jacobians of the module docs.
///
/// Implemented by [`So2`], [`Se2`], [`So3`], [`Se3`]. Generic code that needs arithmetic on the
/// tangent and Jacobian types uses [`MatrixLieGroup`], which fixes them to nalgebra's fixed-size
/// matrices.
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

    /// `exp(τ^)`, the exponential map (seed §3).
    #[must_use]
    fn exp(tau: &Self::Tangent) -> Self;

    /// `log(a)^∨`, the inverse of [`LieGroup::exp`] on its principal domain (rotation angle in
    /// `[0, π]`).
    #[must_use]
    fn log(&self) -> Self::Tangent;

    /// `τ^ = Σᵢ τᵢ Gⁱ` (seed eq. 3.2).
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

    /// The group action `a·p` (seed §5).
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
    #[cfg_attr(estimator_compact, inline(never))]
    fn between(&self, b: &Self) -> Self {
        self.inverse().compose(b)
    }

    /// `a ⊕ τ = a·exp(τ)` (seed eq. 4.5).
    #[must_use]
    #[cfg_attr(estimator_compact, inline(never))]
    fn rplus(&self, tau: &Self::Tangent) -> Self {
        self.compose(&Self::exp(tau))
    }

    /// `a ⊖ b = log(b⁻¹·a)`, so that `b ⊕ (a ⊖ b) = a`.
    #[must_use]
    #[cfg_attr(estimator_compact, inline(never))]
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
        // Ad_e = I, and it constant-folds.
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
        // Not destructured: `exp_jac`'s pair is read where it was returned (no copy of it).
        let sj = Self::exp_jac(tau);
        (self.compose(&sj.0), sj.0.inverse().adjoint(), sj.1)
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

    /// `(a·p, ∂(a·p)/∂a, ∂(a·p)/∂p)`: seed Theorem 5.1, `F = a·[H(p) | I]`.
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

/// `[ω]×`, the skew-symmetric matrix with `[ω]× p = ω × p` (SO(3) hat, seed Example 5.2).
#[cfg_attr(not(estimator_compact), inline)]
#[cfg_attr(estimator_compact, inline(never))]
#[must_use]
pub fn skew<T: Real>(w: &Vector3<T>) -> Matrix3<T> {
    let z = T::zero();
    Matrix3::new(z, -w.z, w.y, w.z, z, -w.x, -w.y, w.x, z)
}

/// `s·I + p[ω]× + q[ω]×²`, the shape of the SO(3) series (`J_r = I − b[ω]× + c[ω]×²`,
/// `J_r⁻¹ = I + ½[ω]× + d[ω]×²`, see the SO(3) module docs), written out entry by entry with
/// `[ω]×² = ωωᵀ − ‖ω‖² I` (diagonal `−(ω_y² + ω_z²)` etc., no cancellation): no product of skew
/// matrices and no 3×3 temporaries.
///
/// The signs are exact: `[−ω]× = −[ω]×` and `[−ω]×² = [ω]×²`, so `J(−ω) = J(ω)ᵀ` is `p → −p`
/// (the transposed and left Jacobians) and `−J` is `(s, p, q) → (−s, −p, −q)`, each bit for bit
/// the transposed or negated matrix.
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

pub(crate) use crate::scalar::{all_finite, positive_finite};

/// `m ← −m`, entry by entry: the same bits as `-m`. Out of line under `estimator_compact`: one
/// short loop shared by every negated Jacobian instead of an unrolled load, negate and store per
/// entry at each `-jacobian` (at opt-level 3 it inlines and unrolls as `-m` did).
#[cfg_attr(estimator_compact, inline(never))]
pub(crate) fn negate<T: Real, const R: usize, const C: usize>(m: &mut SMatrix<T, R, C>) {
    for x in m.as_mut_slice() {
        *x = -*x;
    }
}

/// The `N × N` identity. Out of line under `estimator_compact`: one copy per size instead of a
/// store per entry at each Jacobian that is `I` (the same matrix either way).
#[cfg_attr(estimator_compact, inline(never))]
#[must_use]
pub(crate) fn eye<T: Real, const N: usize>() -> SMatrix<T, N, N> {
    SMatrix::identity()
}

/// `‖MᵀM − I‖²_F`, the orthogonality error of [`LieGroup::try_from_matrix`]: entry `(i, j)` of
/// `MᵀM` is the dot product of columns `i` and `j`. The same operations in the same order as
/// `(m.transpose() * m - I).norm_squared()`, without the two `N × N` temporaries.
#[must_use]
pub(crate) fn orthogonality_error<T: Real, const N: usize>(m: &SMatrix<T, N, N>) -> T {
    let mut err = T::zero();
    for (j, cj) in m.column_iter().enumerate() {
        let mut col = T::zero();
        for (i, ci) in m.column_iter().enumerate() {
            let d = ci.dot(&cj) - if i == j { T::one() } else { T::zero() };
            col += d * d;
        }
        err += col;
    }
    err
}

/// `M ← M[p]×` with `p` by component: each row is replaced by `rᵢ × p` once read (row `i` of
/// the product depends on row `i` of `M` only): row `i` of `R[p]×` is `rᵢᵀ[p]× = (rᵢ × p)ᵀ`,
/// with no zero products of a full multiplication by the skew matrix and no 3×3 temporary.
pub(crate) fn mul_skew_in_place<T: Real>(m: &mut Matrix3<T>, x: T, y: T, z: T) {
    // Column-major storage: row `i` is entry `i` of each of the three columns. A loop over the
    // rows (one copy of the body when built for size), no indexing.
    let (c1, rest) = m.as_mut_slice().split_at_mut(3);
    let (c2, c3) = rest.split_at_mut(3);
    for ((a, b), c) in c1.iter_mut().zip(c2.iter_mut()).zip(c3.iter_mut()) {
        let (ra, rb, rc) = (*a, *b, *c);
        *a = rb * z - rc * y;
        *b = rc * x - ra * z;
        *c = ra * y - rb * x;
    }
}

#[cfg(test)]
mod rewrites;

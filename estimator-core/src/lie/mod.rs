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
        let (step, jr) = Self::exp_jac(tau);
        (self.compose(&step), step.inverse().adjoint(), jr)
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

pub(crate) use crate::scalar::all_finite;

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

/// `R[p]×`, row by row: row `i` is `rᵢᵀ[p]× = (rᵢ × p)ᵀ` for the row `rᵢ` of `R` (no zero
/// products of a full 3×3 multiplication by the skew matrix, no 3×3 temporary).
#[must_use]
pub(crate) fn mul_skew<T: Real>(r: &Matrix3<T>, p: &Vector3<T>) -> Matrix3<T> {
    let row = |a: T, b: T, c: T| (b * p.z - c * p.y, c * p.x - a * p.z, a * p.y - b * p.x);
    let (a1, a2, a3) = row(r.m11, r.m12, r.m13);
    let (b1, b2, b3) = row(r.m21, r.m22, r.m23);
    let (c1, c2, c3) = row(r.m31, r.m32, r.m33);
    Matrix3::new(a1, a2, a3, b1, b2, b3, c1, c2, c3)
}

/// The size-driven rewrites (scalar forms, one-path Shepperd, shared helpers) against the
/// straightforward nalgebra expressions they replace: the same bits, `f32` and `f64`.
#[cfg(test)]
mod rewrites {
    use super::trig::AngleCoeffs;
    use super::*;
    use nalgebra::{Matrix2, Quaternion, UnitQuaternion};

    /// Deterministic numbers in `[-1, 1)` (64-bit LCG).
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((self.0 >> 11) as f64) / ((1u64 << 52) as f64) - 1.0
        }
    }

    /// The same numbers: equal bits, except that `0.0` and `−0.0` count as equal (the old
    /// `−(…)` of a whole block also negated its structural zeros) and any two `NaN`s do.
    fn same<T: Real>(a: &[T], b: &[T]) -> bool {
        a.len() == b.len()
            && a.iter().zip(b).all(|(x, y)| {
                let (x, y) = (x.to_f64(), y.to_f64());
                x.to_bits() == y.to_bits() || x == y || (x.is_nan() && y.is_nan())
            })
    }

    /// Rotation matrices of every Shepperd branch (angles up to and at π about each axis and
    /// random axes), perturbed ones, and arbitrary matrices.
    fn for_each_matrix<T: Real>(mut f: impl FnMut(&Matrix3<T>)) {
        let mut rng = Lcg(7);
        for i in 0..400 {
            let axis = match i % 4 {
                0 => Vector3::new(1.0, 0.0, 0.0),
                1 => Vector3::new(0.0, 1.0, 0.0),
                2 => Vector3::new(0.0, 0.0, 1.0),
                _ => Vector3::new(rng.next(), rng.next(), rng.next()),
            };
            let angle = core::f64::consts::PI * (1.0 - (f64::from(i) / 400.0).powi(3));
            let r = UnitQuaternion::from_scaled_axis(axis.normalize() * angle);
            let m = *r.to_rotation_matrix().matrix();
            let noise = if i % 3 == 0 { 1e-4 } else { 0.0 };
            f(&m.map(|x| T::lit(x + noise * rng.next())));
            f(&Matrix3::from_fn(|_, _| T::lit(rng.next())));
        }
    }

    /// Vectors of magnitudes from `1e-6` to `100`.
    fn for_each_vector<T: Real>(seed: u64, mut f: impl FnMut(&Vector3<T>)) {
        let mut rng = Lcg(seed);
        for i in 0..100 {
            let s = [1e-6, 1e-2, 1.0, 3.0, 100.0][i % 5];
            f(&Vector3::new(rng.next(), rng.next(), rng.next()).map(|x| T::lit(s * x)));
        }
    }

    fn for_each_quaternion<T: Real>(mut f: impl FnMut(&UnitQuaternion<T>)) {
        let mut rng = Lcg(13);
        for _ in 0..100 {
            let q = Quaternion::new(rng.next(), rng.next(), rng.next(), rng.next());
            let q = Quaternion::from(q.coords.map(T::lit));
            f(&UnitQuaternion::new_unchecked(q * (T::one() / q.norm())));
        }
    }

    /// The four written-out branches of Shepperd's method (before the one-path form).
    fn shepperd_branches<T: Real>(m: &Matrix3<T>) -> Option<So3<T>> {
        let one = T::one();
        let quarter = T::lit(0.25);
        let trace = m.m11 + m.m22 + m.m33;
        let (w, x, y, z);
        if trace > T::zero() {
            let s = (trace + one).sqrt() * T::lit(2.0);
            w = quarter * s;
            x = (m.m32 - m.m23) / s;
            y = (m.m13 - m.m31) / s;
            z = (m.m21 - m.m12) / s;
        } else if m.m11 > m.m22 && m.m11 > m.m33 {
            let s = (one + m.m11 - m.m22 - m.m33).sqrt() * T::lit(2.0);
            w = (m.m32 - m.m23) / s;
            x = quarter * s;
            y = (m.m12 + m.m21) / s;
            z = (m.m13 + m.m31) / s;
        } else if m.m22 > m.m33 {
            let s = (one + m.m22 - m.m11 - m.m33).sqrt() * T::lit(2.0);
            w = (m.m13 - m.m31) / s;
            x = (m.m12 + m.m21) / s;
            y = quarter * s;
            z = (m.m23 + m.m32) / s;
        } else {
            let s = (one + m.m33 - m.m11 - m.m22).sqrt() * T::lit(2.0);
            w = (m.m21 - m.m12) / s;
            x = (m.m13 + m.m31) / s;
            y = (m.m23 + m.m32) / s;
            z = quarter * s;
        }
        So3::from_wxyz(w, x, y, z)
    }

    fn so3_try_from_matrix_before<T: Real>(m: &Matrix3<T>) -> Option<So3<T>> {
        if !all_finite(m.as_slice()) {
            return None;
        }
        let err = (m.transpose() * m - Matrix3::<T>::identity()).norm_squared();
        let tol = T::lit(ORTHOGONALITY_TOLERANCE);
        if !(err <= tol * tol && m.determinant() > T::zero()) {
            return None;
        }
        shepperd_branches(m)
    }

    fn so3_matrices<T: Real>() {
        let mut accepted = 0;
        let mut branch = [0usize; 4];
        for_each_matrix::<T>(|m| {
            let err = (m.transpose() * m - Matrix3::<T>::identity()).norm_squared();
            assert!(same(&[orthogonality_error(m)], &[err]));
            let m2 = m.fixed_view::<2, 2>(0, 0).into_owned();
            let err2 = (m2.transpose() * m2 - Matrix2::<T>::identity()).norm_squared();
            assert!(same(&[orthogonality_error(&m2)], &[err2]));
            let got = So3::try_from_matrix(m).map(|r| r.quaternion().coords);
            let want = so3_try_from_matrix_before(m).map(|r| r.quaternion().coords);
            assert_eq!(got.is_some(), want.is_some());
            if let (Some(g), Some(w)) = (got, want) {
                assert!(same(g.as_slice(), w.as_slice()), "{m}");
                accepted += 1;
                // Which component Shepperd took by the square root: the largest here.
                let k = g.iamax();
                if let Some(b) = branch.get_mut((k + 1) % 4) {
                    *b += 1;
                }
            }
        });
        assert!(accepted > 300, "{accepted}");
        assert!(branch.iter().all(|&n| n > 20), "{branch:?}");
    }

    fn so3_act<T: Real>() {
        for_each_quaternion::<T>(|q| {
            let r = So3::from_unit_quaternion(*q);
            for_each_vector::<T>(17, |p| {
                assert!(same(r.act(p).as_slice(), q.transform_vector(p).as_slice()));
                let m = r.rotation_matrix();
                let (rp, h, jp) = r.act_jac(p);
                assert!(same(rp.as_slice(), (m * p).as_slice()));
                assert!(same(h.as_slice(), mul_skew(&m, &-p).as_slice()));
                assert!(same(jp.as_slice(), m.as_slice()));
            });
        });
    }

    /// SE(3)'s `Q` block as it was: nalgebra vectors and an outer product.
    fn q_block_before<T: Real>(k: &AngleCoeffs<T>, v: &Vector3<T>, w: &Vector3<T>) -> Matrix3<T> {
        let se = k.se();
        let dot = w.dot(v);
        let s = v * k.b - w * (dot * (k.c + se.e + se.e));
        let alpha = v * k.c + w * (T::lit(0.5) * se.f * dot);
        let g = dot * (k.c + k.c + se.f * k.theta_sq);
        let aw = alpha * w.transpose();
        aw + aw.transpose() + skew(&s) - Matrix3::from_diagonal_element(g)
    }

    fn upper_before<T: Real>(diag: &Matrix3<T>, upper: &Matrix3<T>) -> SMatrix<T, 6, 6> {
        let mut m = SMatrix::<T, 6, 6>::zeros();
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(diag);
        m.fixed_view_mut::<3, 3>(0, 3).copy_from(upper);
        m.fixed_view_mut::<3, 3>(3, 3).copy_from(diag);
        m
    }

    fn split<T: Real>(xi: &SVector<T, 6>) -> (Vector3<T>, Vector3<T>) {
        (
            xi.fixed_rows::<3>(0).into_owned(),
            xi.fixed_rows::<3>(3).into_owned(),
        )
    }

    fn se3_jr_before<T: Real>(k: &AngleCoeffs<T>, xi: &SVector<T, 6>) -> SMatrix<T, 6, 6> {
        let (v, w) = split(xi);
        upper_before(
            &skew_poly(T::one(), -k.b, k.c, &w),
            &q_block_before(k, &-v, &-w),
        )
    }

    fn se3_jr_inv_before<T: Real>(k: &AngleCoeffs<T>, xi: &SVector<T, 6>) -> SMatrix<T, 6, 6> {
        let (v, w) = split(xi);
        let jinv = skew_poly(T::one(), T::lit(0.5), k.d(), &w);
        let q = q_block_before(k, &-v, &-w);
        upper_before(&jinv, &-(jinv * q * jinv))
    }

    fn se3_jacobians<T: Real>() {
        let mut rng = Lcg(19);
        for_each_vector::<T>(23, |v| {
            // Rotation angles from the series range to beyond π.
            let scale = [1e-5, 1e-3, 0.1, 0.5, 1.0, 2.0, 3.1, 3.2, 5.0][rng.0 as usize % 9];
            let w = Vector3::new(rng.next(), rng.next(), rng.next()).map(|x| T::lit(scale * x));
            let xi = SVector::<T, 6>::new(v.x, v.y, v.z, w.x, w.y, w.z);
            let k = AngleCoeffs::from_theta_sq(w.norm_squared());
            let m = |a: &SMatrix<T, 6, 6>, b: &SMatrix<T, 6, 6>| same(a.as_slice(), b.as_slice());
            assert!(m(&Se3::right_jacobian(&xi), &se3_jr_before(&k, &xi)));
            assert!(m(&Se3::left_jacobian(&xi), &se3_jr_before(&k, &-xi)));
            assert!(m(
                &Se3::right_jacobian_inv(&xi),
                &se3_jr_inv_before(&k, &xi)
            ));
            assert!(m(
                &Se3::left_jacobian_inv(&xi),
                &se3_jr_inv_before(&k, &-xi)
            ));
            assert!(m(&Se3::exp_jac(&xi).1, &se3_jr_before(&k, &xi)));
            // log_jac and rminus_jac: the kernel of the logarithm's angle.
            let a = Se3::exp(&xi);
            let b = Se3::exp(&(xi * T::lit(0.3)));
            let (tau, j) = a.log_jac();
            let kl = a.rotation().log_with_coeffs().1;
            assert!(m(&j, &se3_jr_inv_before(&kl, &tau)));
            let (tau, jr, jl) = a.rminus_jac(&b);
            let kl = b.between(&a).rotation().log_with_coeffs().1;
            assert!(m(&jr, &se3_jr_inv_before(&kl, &tau)));
            assert!(m(&jl, &-se3_jr_inv_before(&kl, &-tau)));
        });
    }

    fn se3_adjoint_before<T: Real>(a: &Se3<T>) -> SMatrix<T, 6, 6> {
        let r = a.rotation().rotation_matrix();
        let tr = mul_skew(&r.transpose(), &-a.translation()).transpose();
        upper_before(&r, &tr)
    }

    fn se3_values<T: Real>() {
        let mut rng = Lcg(29);
        for_each_vector::<T>(31, |v| {
            let scale = [1e-5, 1e-3, 0.1, 1.0, 3.1, 5.0][rng.0 as usize % 6];
            let w = Vector3::new(rng.next(), rng.next(), rng.next()).map(|x| T::lit(scale * x));
            let xi = SVector::<T, 6>::new(v.x, v.y, v.z, w.x, w.y, w.z);
            let k = AngleCoeffs::from_theta_sq(w.norm_squared());
            let a = Se3::exp(&xi);
            let wv = w.cross(v);
            let t = v + wv * k.b + w.cross(&wv) * k.c;
            assert!(same(a.translation().as_slice(), t.as_slice()));
            // log: J_l⁻¹(ω) t with the logarithm's kernel.
            let (w, kl) = a.rotation().log_with_coeffs();
            let t = a.translation();
            let wt = w.cross(&t);
            let v_log = t - wt * T::lit(0.5) + w.cross(&wt) * kl.d();
            let xi_log = a.log();
            assert!(same(&xi_log.as_slice()[..3], v_log.as_slice()));
            assert!(same(&xi_log.as_slice()[3..], w.as_slice()));
            // Adjoint, and −Ad in inverse_jac and between_jac.
            let b = Se3::exp(&(xi * T::lit(-0.7)));
            let m = |a: &SMatrix<T, 6, 6>, b: &SMatrix<T, 6, 6>| same(a.as_slice(), b.as_slice());
            assert!(m(&a.adjoint(), &se3_adjoint_before(&a)));
            assert!(m(&a.inverse_jac().1, &-se3_adjoint_before(&a)));
            let z = a.between(&b);
            assert!(m(&a.between_jac(&b).1, &-se3_adjoint_before(&z.inverse())));
            // act_jac: [R | −R[p]×], R p + t.
            let p = xi.fixed_rows::<3>(0) * T::lit(3.0);
            let r = a.rotation().rotation_matrix();
            let mut j = SMatrix::<T, 3, 6>::zeros();
            j.fixed_view_mut::<3, 3>(0, 0).copy_from(&r);
            j.fixed_view_mut::<3, 3>(0, 3).copy_from(&mul_skew(&r, &-p));
            let (ap, ja, jp) = a.act_jac(&p.into_owned());
            assert!(same(ap.as_slice(), (r * p + a.translation()).as_slice()));
            assert!(same(ja.as_slice(), j.as_slice()));
            assert!(same(jp.as_slice(), r.as_slice()));
        });
    }

    #[test]
    fn se3_rewrites_are_bit_identical() {
        se3_values::<f32>();
        se3_values::<f64>();
        se3_jacobians::<f32>();
        se3_jacobians::<f64>();
    }

    fn so3_jacobians<T: Real>() {
        let m = |a: &Matrix3<T>, b: &Matrix3<T>| same(a.as_slice(), b.as_slice());
        for_each_vector::<T>(37, |w| {
            let jr = So3::right_jacobian(w);
            let jr_inv = So3::right_jacobian_inv(w);
            assert!(m(&So3::left_jacobian(w), &jr.transpose()));
            assert!(m(&So3::left_jacobian_inv(w), &jr_inv.transpose()));
            let a = So3::exp(w);
            let b = So3::exp(&(w * T::lit(-0.4)));
            let (tau, jr, jl) = a.rminus_jac(&b);
            let k = b.between(&a).log_with_coeffs().1;
            let jr_inv_k = skew_poly(T::one(), T::lit(0.5), k.d(), &tau);
            assert!(m(&jr, &jr_inv_k));
            assert!(m(&jl, &-jr_inv_k.transpose()));
        });
    }

    /// SO(3)'s logarithm as it was: the principal quaternion with `v` negated when `w < 0`.
    fn so3_log_before<T: Real>(q: &UnitQuaternion<T>) -> (Vector3<T>, T, T, T) {
        use super::trig::{poly, Cutoff};
        let (w, v) = if q.w < T::zero() {
            (-q.w, -q.imag())
        } else {
            (q.w, q.imag())
        };
        let n2 = v.norm_squared();
        let n = n2.sqrt();
        let scale = if n2 < T::lit(Cutoff::<T>::ATAN_RATIO) * w * w {
            let r2 = n2 / (w * w);
            T::lit(2.0) / w * poly(r2, [T::lit(1.0), T::lit(-1.0 / 3.0), T::lit(1.0 / 5.0)])
        } else {
            T::lit(2.0) * n.atan2(w) / n
        };
        (v * scale, scale * n, n, w)
    }

    fn so3_log_and_normalize<T: Real>() {
        let check = |q: &UnitQuaternion<T>| {
            for q in [*q, UnitQuaternion::new_unchecked(-q.into_inner())] {
                let (w, k) = So3::from_unit_quaternion(q).log_with_coeffs();
                let (w0, theta, sin_half, cos_half) = so3_log_before(&q);
                assert!(same(w.as_slice(), w0.as_slice()));
                assert!(same(
                    &[k.theta, k.sin_half, k.cos_half],
                    &[theta, sin_half, cos_half]
                ));
                // from_quaternion of a scaled copy: `q · (1/‖q‖)`.
                let big = q.into_inner() * T::lit(3.5);
                let n = So3::from_quaternion(&big).map(|r| r.quaternion().into_inner());
                let want = big * (T::one() / big.coords.norm_squared().sqrt());
                assert!(n.is_some_and(|n| same(n.coords.as_slice(), want.coords.as_slice())));
            }
        };
        for_each_quaternion::<T>(check);
        for_each_vector::<T>(41, |w| check(&So3::exp(w).quaternion()));
    }

    #[test]
    fn so3_rewrites_are_bit_identical() {
        so3_log_and_normalize::<f32>();
        so3_log_and_normalize::<f64>();
        so3_jacobians::<f32>();
        so3_jacobians::<f64>();
        so3_matrices::<f32>();
        so3_matrices::<f64>();
        so3_act::<f32>();
        so3_act::<f64>();
    }
}

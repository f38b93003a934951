//! Checks and read-outs of a covariance matrix.

use super::config::FilterConfig;
use super::error::EskfError;
use super::state::ErrorState;
use crate::kernels::block::{add_scaled_identity, block};
use crate::kernels::cholesky::factor_in_place;
use crate::kernels::slice::symmetrize;
use crate::kernels::{all_finite, larger, usable_variance};
use crate::Real;
use nalgebra::{Matrix3, SMatrix, SVector};

/// `A` is finite, symmetric to `10⁻⁶` of its largest entry, and positive definite: the Cholesky
/// factor of its symmetric part `½(A + Aᵀ)` exists.
///
/// The symmetric part, not the lower triangle as given: `xᵀ A x = xᵀ ½(A + Aᵀ) x`, and it is the
/// matrix the filter goes on to use (the update symmetrizes `S = H P Hᵀ + R`). Where the small
/// entries of an `A` symmetric only to `10⁻⁶` of its largest differ, the lower triangle can be
/// definite and the symmetric part not.
pub(crate) fn is_spd<T: Real, const M: usize>(a: &SMatrix<T, M, M>) -> bool {
    is_usable_spd(a, T::zero())
}

/// The smallest fraction of a variable's variance, `256 N ε` for a filter of `N` states (the
/// update's noise floor), that the other variables of a starting `P` may leave unexplained:
/// below it the matrix is singular to the resolution the filter keeps (a correlation above
/// `√(1 − 256 N ε)`, 0.99977 in `f32` for 15 states), and an update's rounding can leave it
/// indefinite.
pub(crate) fn usable_pivot<T: Real, const N: usize>() -> T {
    T::lit(256.0 * N as f64 * T::EPSILON_F64)
}

/// [`is_spd`], with every Cholesky pivot `d_j` above `relative_pivot · A_jj` (each variable
/// keeps that fraction of its variance unexplained by the variables before it).
pub(crate) fn is_usable_spd<T: Real, const M: usize>(
    a: &SMatrix<T, M, M>,
    relative_pivot: T,
) -> bool {
    let mut l = *a;
    symmetrize(l.as_mut_slice(), M);
    is_symmetric(a.as_slice(), M) && factor_in_place(l.as_mut_slice(), M, relative_pivot)
}

/// [`is_spd`] for a filter's start, and every Cholesky pivot after the attitude rows,
/// `d_j = L_jj²` for `j ≥ 3`, above [`usable_pivot`] of `P_jj` (to the rounding of `L_jj²`, a
/// few ε of a threshold of `256 N ε`). Those pivots are the ones of the Schur complement
/// `P_xx − P_xθ P_θθ⁻¹ P_θx`: each state other than the attitude judged given the attitude,
/// the same in any frame of the attitude error. The attitude block's own resolution is the
/// attitude floor's ([`attitude_floor`]), which the caller has added.
fn is_usable_start<T: Real, const N: usize>(p: &SMatrix<T, N, N>) -> bool {
    let mut l = *p;
    symmetrize(l.as_mut_slice(), N);
    let pivot = usable_pivot::<T, N>();
    let diagonal = |m: &SMatrix<T, N, N>, j: usize| m.get((j, j)).copied().unwrap_or_else(T::zero);
    is_symmetric(p.as_slice(), N)
        && factor_in_place(l.as_mut_slice(), N, T::zero())
        && (3..N).all(|j| {
            let l_jj = diagonal(&l, j);
            l_jj * l_jj > pivot * diagonal(p, j)
        })
}

/// The column-major `n × n` storage `a` is finite and symmetric to `10⁻⁶` of its largest entry
/// (one compiled copy for every size).
fn is_symmetric<T: Real>(a: &[T], n: usize) -> bool {
    if a.len() != n * n || !all_finite(a) {
        return false;
    }
    let tol = a.iter().fold(T::zero(), |m, x| m.max(x.abs())) * T::lit(1e-6);
    let at = |k: usize| a.get(k).copied().unwrap_or_else(T::zero);
    (0..n).all(|j| (j + 1..n).all(|i| (at(j * n + i) - at(i * n + j)).abs() <= tol))
}

/// The checks every filter constructor makes on a given start: a valid configuration, a finite
/// state and a symmetric positive definite covariance, usable by the filter (no variance above
/// [`Real::VARIANCE_CEILING_F64`], every Cholesky pivot after the attitude rows above
/// [`usable_pivot`] of its diagonal). The attitude block must have had its floor added
/// ([`attitude_floor`]): that floor, not the pivot test, is its resolution. With the heading
/// unknown and the tilt known, every entry of a body-frame attitude block is of the heading's
/// size and the tilt is in their differences, a block the pivot test would refuse however well
/// the tilt is known, and one the filters keep themselves.
pub(crate) fn check_start<T: Real, S: ErrorState<T, N>, const N: usize>(
    state: &S,
    covariance: &SMatrix<T, N, N>,
    config: &FilterConfig<T>,
) -> Result<(), EskfError> {
    config.validate()?;
    if !state.is_finite() {
        return Err(EskfError::NonFinite);
    }
    let variances_usable =
        (0..N).all(|k| covariance.get((k, k)).is_some_and(|d| usable_variance(*d)));
    if !(variances_usable && is_usable_start(covariance)) {
        return Err(EskfError::CovarianceNotPositiveDefinite);
    }
    Ok(())
}

/// `√max(P_ii, 0)` for each `i`: the 1-σ of each error-state component.
pub(crate) fn sigmas<T: Real, const N: usize>(p: &SMatrix<T, N, N>) -> SVector<T, N> {
    p.diagonal().map(|d| d.max(T::zero()).sqrt_rn())
}

/// The attitude floor, `f = 16 ε`: the smallest eigenvalue the attitude block of `P` is kept
/// at, as a fraction of its trace.
///
/// The attitude error is in the body frame, so when the heading is unknown (σ_ψ of radians)
/// and the tilt known (σ of milliradians) every entry of the block is of the heading's size and
/// the tilt lives in their differences. Rounding moves each entry by a few `ε·tr(P_θθ)` per
/// call, so a tilt variance below about that is not representable: in `f32` (ε = 1.2e-7) it
/// leaves `P` indefinite within seconds. The floor is the smallest margin over that rounding.
const ATTITUDE_FLOOR: f64 = 16.0;

/// The attitude floor of the block `A = P_θθ` (the top-left 3 × 3 of `P`): `f·tr A`
/// ([`ATTITUDE_FLOOR`]) when the smallest eigenvalue of `A` may be below that, else zero. The
/// caller adds it to the diagonal of `A`, keeping the block representable in the scalar.
///
/// Two tests, the second only when the first cannot tell:
///
/// 1. `λ_min ≥ det A / (λ₁ λ₂) ≥ 4 det A / (tr A)²` (the two larger eigenvalues have a product
///    at most `(tr A / 2)²`): a determinant, not an eigen-decomposition. It settles every block
///    whose eigenvalues are of one size (a known heading), but not one where the heading's
///    eigenvalue is `10⁵` of the tilt's: there `(tr A)²` overstates `λ₁ λ₂` by that ratio, and
///    the determinant itself, products of the heading's size cancelling to the tilt's, has
///    lost the tilt to rounding in `f32`.
/// 2. [`schur_floor`]: the Schur complement of `A` on its largest diagonal entry, computed
///    from differences of the heading's size, which holds the tilt to `ε tr A / λ_min`.
///
/// It may floor a block whose smallest eigenvalue is larger; that changes it by at most
/// `f·tr A`, below the block's own rounding. Adding `c I` to a positive semi-definite block of
/// a positive semi-definite `P` keeps `P` so, and `c I` is the same in every frame: the tilt and
/// the heading are widened alike. In `f64` the floor is `3.6e-15 tr A`: it never acts on a
/// usable filter. In `f32` it acts when a variance comes within about `4f` of the trace (with an
/// unknown heading, σ_ψ = 2.4 rad, a tilt σ of about 7 mrad); test 1 alone floored every
/// prediction of a filter without a heading, a random walk of the tilt of `f tr A` per sample.
#[inline(never)] // one copy per scalar type, not one per filter and call site
pub(crate) fn attitude_floor<T: Real>(a: &Matrix3<T>) -> T {
    let tr = a.m11 + a.m22 + a.m33;
    let floor = attitude_resolution(a);
    // The symmetric block's determinant by cofactors of its first row (upper triangle only).
    let det = a.m11 * (a.m22 * a.m33 - a.m23 * a.m23) - a.m12 * (a.m12 * a.m33 - a.m23 * a.m13)
        + a.m13 * (a.m12 * a.m23 - a.m22 * a.m13);
    if det * T::lit(4.0) > floor * tr * tr {
        return T::zero();
    }
    schur_floor(a, floor)
}

/// Test 2 of [`attitude_floor`]: `floor`, unless the Schur complement of `A` on its largest
/// diagonal entry `a_kk`, the 2 × 2 block `S = A_rr − a_rk a_rkᵀ / a_kk` (`r` the other two
/// axes; the second and third pivots of a Cholesky factorization), has `det S > 4 floor tr S`.
///
/// The eigenvalues of `S` bound `A`'s from above (`S⁻¹` is a block of `A⁻¹`):
/// `λ_min(S) ≤ λ_min(A) / (1 − v_k²)` with `v` the eigenvector of `λ_min(A)`, and `v_k² ≤ 3/4`
/// when `a_kk` is the largest diagonal entry and `λ_min` far below the other two eigenvalues
/// (the only case the floor is for); with `λ_min(S) ≥ det S / tr S`, `det S > 4 floor tr S`
/// keeps `λ_min(A)` above the floor. Written without the division, with `M = a_kk S`:
/// `tr M > 0` and `det M > 4 floor a_kk tr M`; the trace test is what makes `det M > 0` mean
/// two positive eigenvalues rather than two negative ones (a tilt of σ = 10⁻⁶ rad beside a
/// heading of σ = 0.087 rad, rounded in `f32`, gave both entries of `M` below zero). Inlined into [`attitude_floor`], a leaf: a call of its own
/// would add its frame at the deepest point of every update.
#[inline(always)]
fn schur_floor<T: Real>(a: &Matrix3<T>, floor: T) -> T {
    // (pivot, the two other diagonal entries, their covariances with the pivot, their own).
    let (p, d1, d2, c1, c2, c12) = if a.m11 >= a.m22 && a.m11 >= a.m33 {
        (a.m11, a.m22, a.m33, a.m12, a.m13, a.m23)
    } else if a.m22 >= a.m33 {
        (a.m22, a.m11, a.m33, a.m12, a.m23, a.m13)
    } else {
        (a.m33, a.m11, a.m22, a.m13, a.m23, a.m12)
    };
    let m11 = d1 * p - c1 * c1;
    let m22 = d2 * p - c2 * c2;
    let m12 = c12 * p - c1 * c2;
    let tr_m = m11 + m22;
    // Both of M's eigenvalues are positive only if its trace and determinant are: a rounded M
    // with two negative pivots has a positive determinant too. A block without a positive
    // diagonal (or with a NaN) fails a comparison: floored.
    if p > T::zero() && tr_m > T::zero() && m11 * m22 - m12 * m12 > T::lit(4.0) * floor * p * tr_m {
        T::zero()
    } else {
        floor
    }
}

/// Adds [`attitude_floor`] of the attitude block `P_θθ` to its diagonal, as every prediction
/// and a filter's start do.
#[inline(always)]
pub(crate) fn floor_attitude<T: Real, const N: usize>(p: &mut SMatrix<T, N, N>) {
    let floor = attitude_floor(&block(p, 0, 0));
    add_scaled_identity(p, 0, 0, floor);
}

/// `f tr A` ([`ATTITUDE_FLOOR`]): the attitude floor itself, whatever the block's smallest
/// eigenvalue. The widening adds it always: it scales the attitude rows up (a heading of
/// σ = 10⁻³ rad to σ = 2.5 rad) and leaves their covariance with the other states as it was,
/// so a tilt well known on its own can be known to `10⁻⁸` of the new rows given the gyro bias
/// it is correlated with: the block passes the test of [`attitude_floor`] and `P` is not
/// positive definite in `f32`. `f tr A · I` raises the variance of every attitude combination,
/// given all the other states, by `f tr A`.
pub(crate) fn attitude_resolution<T: Real>(a: &Matrix3<T>) -> T {
    (a.m11 + a.m22 + a.m33) * T::lit(ATTITUDE_FLOOR * T::EPSILON_F64)
}

/// The growth floor, `f = 64 N ε`: the part of each variance's growth in a prediction that is
/// made independent of every other state.
const GROWTH_FLOOR: f64 = 64.0;

/// The mixing floor's `64 ε`, of the size of the products that feed the velocity and the
/// position ([`floor_mixing`]): the rounding of the rotation that mixes their axes, with a
/// margin.
pub(crate) const GROWTH_MIXING: f64 = 64.0;

/// And `2 ε` of each variance: the rounding of one prediction, twice over.
const GROWTH_ROUNDING: f64 = 2.0;

/// Floors the first `K` variances of a predicted `P` (θ; v; p): adds
/// `f max(P⁺_kk − before[k], 0) + 2 ε P⁺_kk` (`before[k]` its value before the prediction)
/// ([`GROWTH_FLOOR`], [`GROWTH_ROUNDING`]).
///
/// A prediction integrates: `p⁺ = p + v dt`, `v⁺ = v + a dt`, `θ⁺ = ΔRᵀ θ − J_r dt b_g`. The
/// variance it adds comes from other states and may be wholly correlated with them (a velocity
/// of σ = 10⁸ m/s beside a position of 10⁻⁶ m; an acceleration of 10²⁰ m/s² turning the
/// attitude's variance into the velocity's). When it dominates, the smallest eigenvalue of the
/// correlation matrix falls below the rounding of `F P Fᵀ` (a few `ε` per entry) and `P⁺` is
/// indefinite; prediction after prediction it falls by the growth factor each time. A fraction
/// `f` of each growth made independent keeps every state's variance, given all the others, at
/// least about `f/3` of its variance across predictions whose growth is large.
///
/// The rotation `R [f]× dt` that feeds `v` and `p` mixes their axes: [`floor_mixing`] covers
/// that. The attitude needs no such term: its growth `J_r dt P_bg J_rᵀ dt` keeps at least
/// `(2/π)²` of its products' size, as the prediction refuses a step that turns by π or more,
/// and `ΔRᵀ`'s rounding is the attitude floor's.
///
/// When the growth per step is small beside the variance (an attitude of σ = 60 rad fed by a
/// gyro bias of σ = 3.7 rad/s, 500 steps), the rounding of each step, a few `ε` of the
/// variance, outruns the first term; `2 ε P⁺_kk` more covers that, on every variance, growing
/// or not: a variance can shrink in a prediction through its correlation (`−2 dt P_θb` when
/// the attitude is correlated with the gyro bias) while the rounding of the step is still
/// there (in `f32`, an attitude widened to a heading of σ = π then sheared by a gyro bias of
/// σ = 0.1 rad/s went indefinite within 20 predictions when only growing variances had it). In
/// `f64` the two are `2.1e-13` of the growth and `4.4e-16` of the variance per step; in
/// `f32`, `1.1e-4` and `2.4e-7`: at 200 Hz a variance left
/// 600 s without a measurement ends 2.9 % larger.
pub(crate) fn floor_growth<T: Real, const N: usize, const K: usize>(
    p: &mut SMatrix<T, N, N>,
    before: &[T; K],
) {
    for (k, own) in before.iter().enumerate() {
        if let Some(d) = p.get_mut((k, k)) {
            *d += growth_floor::<T, N>(*d, *own);
        }
    }
}

/// What [`floor_growth`] adds to one variance of a filter of `N` states that a prediction took
/// from `before` to `after`: `f max(after − before, 0) + 2 ε after`.
#[inline(always)]
pub(crate) fn growth_floor<T: Real, const N: usize>(after: T, before: T) -> T {
    let f = T::lit(GROWTH_FLOOR * T::EPSILON_F64 * N as f64);
    let rounding = T::lit(GROWTH_ROUNDING * T::EPSILON_F64);
    larger(after - before, T::zero()) * f + after * rounding
}

/// The mixing floor of the 15-state prediction: adds `64 ε M` to each velocity variance and
/// `64 ε (dt/2)² M` to each position variance ([`GROWTH_MIXING`]), with
/// `M = dt² (‖f‖² tr P_θθ + tr P_ba)` the size of the products `R [f]× dt P_θθ` and
/// `R dt P_ba` that feed them (`P` before the prediction).
///
/// `R [f]×` mixes the three axes, so the rounding of each velocity and position variance is a
/// few `ε` of those products, not of its own result: where `f` lies along a direction in which
/// the attitude is well known (`[f]× θ` then nearly zero: a specific force of 10²⁰ m/s² nearly
/// vertical, or of 2·10³³ m/s² along the body diagonal after the attitude was measured across
/// it), the result is 10⁻⁷ of the products and its rounding far above the growth floor: the
/// correlation matrix came out at `−2e-12` and `−1e-13` in `f64`. In `f32` at rest with the
/// heading unknown the term is `2e-7 m²/s²` per 5 ms step, about the accelerometer noise's.
pub(crate) fn floor_mixing<T: Real>(p: &mut SMatrix<T, 15, 15>, m: T, dt: T) {
    let mixing = T::lit(GROWTH_MIXING * T::EPSILON_F64) * m;
    let half_dt = dt * T::lit(0.5);
    for k in 3..6 {
        if let Some(d) = p.get_mut((k, k)) {
            *d += mixing;
        }
    }
    for k in 6..9 {
        if let Some(d) = p.get_mut((k, k)) {
            *d += mixing * half_dt * half_dt;
        }
    }
}

/// The first `K` diagonal entries of `P`.
pub(crate) fn leading_diagonal<T: Real, const N: usize, const K: usize>(
    p: &SMatrix<T, N, N>,
) -> [T; K] {
    core::array::from_fn(|k| p.get((k, k)).copied().unwrap_or_else(T::zero))
}

/// Scales the attitude rows and columns of `P` by `s = π / σ_max` when the largest attitude
/// variance `σ_max²` is above π²: an attitude error of σ = π is no information, and the
/// variance beyond it only costs the filter its resolution (a heading of σ = 3e7 rad beside
/// biases of 1e-5 leaves nothing of the tilt in `f32`). `S P S` with `S = diag(s I₃, I)` keeps
/// `P` positive definite and every correlation as it was.
#[inline(always)]
pub(crate) fn cap_attitude<T: Real, const N: usize>(p: &mut SMatrix<T, N, N>) {
    // The trace bounds the largest variance: one comparison on the usual path.
    let tr = p.get((0, 0)).copied().unwrap_or_else(T::zero)
        + p.get((1, 1)).copied().unwrap_or_else(T::zero)
        + p.get((2, 2)).copied().unwrap_or_else(T::zero);
    if tr > T::pi() * T::pi() {
        scale_attitude(p);
    }
}

/// The scaling of [`cap_attitude`], out of line (rarely taken).
#[cold]
#[inline(never)]
fn scale_attitude<T: Real, const N: usize>(p: &mut SMatrix<T, N, N>) {
    let pi2 = T::pi() * T::pi();
    let largest = (0..3).fold(T::zero(), |m, k| {
        crate::kernels::larger(m, p.get((k, k)).copied().unwrap_or_else(T::zero))
    });
    if largest > pi2 {
        let s = (pi2 / largest).sqrt_rn();
        for (j, col) in p.data.0.iter_mut().enumerate() {
            for (i, e) in col.iter_mut().enumerate() {
                if i < 3 {
                    *e *= s;
                }
                if j < 3 {
                    *e *= s;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The body-frame attitude block of a heading of 1σ `heading` about the body axis `u` and a
    /// tilt of 1σ `tilt` on the two axes across it.
    fn heading_and_tilt(u: nalgebra::Vector3<f32>, heading: f32, tilt: f32) -> Matrix3<f32> {
        let u = u.normalize();
        Matrix3::identity() * (tilt * tilt) + u * u.transpose() * (heading * heading - tilt * tilt)
    }

    /// With the heading unknown (σ = 2.4 rad about a tipped axis), a tilt known to 10 mrad is
    /// far above the block's rounding (`ε tr A` = 8·10⁻⁷ against a variance of 10⁻⁴): no floor,
    /// where a test through `det A` floors it. A tilt of 1 mrad (10⁻⁶, within `4·16 ε tr A`
    /// = 3.5·10⁻⁵) is floored; a known heading is not.
    #[test]
    fn the_floor_acts_on_the_tilt_only_where_rounding_reaches_it() {
        let axes = [
            nalgebra::Vector3::new(1.0f32, 1.0, 0.0),
            nalgebra::Vector3::new(0.2, -0.3, 1.0),
            nalgebra::Vector3::new(0.0, 0.0, 1.0),
            nalgebra::Vector3::new(1.0, 0.0, 0.0),
        ];
        for u in axes {
            let a = heading_and_tilt(u, 2.4, 1e-2);
            let (tr, floor) = (a.trace(), attitude_resolution(&a));
            assert!(
                a.determinant() * 4.0 <= floor * tr * tr,
                "a test through det A cannot tell ({u:?})"
            );
            assert_eq!(attitude_floor(&a), 0.0, "a 10 mrad tilt is kept ({u:?})");
            let fine = heading_and_tilt(u, 2.4, 1e-3);
            assert_eq!(
                attitude_floor(&fine),
                attitude_resolution(&fine),
                "1 mrad ({u:?})"
            );
        }
        // A known heading: no floor.
        let known = heading_and_tilt(nalgebra::Vector3::z(), 2e-2, 1e-2);
        assert_eq!(attitude_floor(&known), 0.0);
    }

    /// A fuzzing finding: the `f32` block of an alignment with a tilt of σ = 10⁻⁶ rad and a
    /// heading of σ = 0.087 rad about the body axis (0, 0.87, −0.49) (its x axis nearly level).
    /// Its Schur complement on the largest entry rounds to `M = [4·10⁻²², 0; 0, −9·10⁻¹³]`:
    /// one entry below zero (the exact block is definite, but `f32` cannot hold the tilt next
    /// to the heading), a positive-determinant `M` of two negative pivots for the other shape
    /// of the same rounding. The block as stored is indefinite (smallest eigenvalue
    /// −9·10⁻¹¹ rad², below the floor 1.5·10⁻⁸): it must be floored, and the floored block is
    /// positive definite.
    #[test]
    fn a_tilt_lost_to_rounding_beside_the_heading_is_floored() {
        let a = Matrix3::new(
            1.006_996_4e-12f32,
            7.654_305e-8,
            -4.254_263_4e-8,
            7.654_305e-8,
            0.005_818_133_7,
            -0.003_233_719_2,
            -4.254_263_4e-8,
            -0.003_233_719_2,
            0.001_797_301_2,
        );
        let exact = a.cast::<f64>().symmetric_eigenvalues().min();
        assert!(exact < 0.0, "the stored block is indefinite: {exact}");
        assert_eq!(attitude_floor(&a), attitude_resolution(&a));
        let floored = a + Matrix3::from_diagonal_element(attitude_floor(&a));
        let smallest = floored.cast::<f64>().symmetric_eigenvalues().min();
        assert!(
            smallest > 0.5 * f64::from(attitude_resolution(&a)),
            "{smallest}"
        );
    }

    /// A start whose attitude block is singular to the pivot test but floored (heading unknown,
    /// tilt known, body pitched) is usable; one whose velocity is the position's to a
    /// correlation of `1 − 10⁻⁶` (a pivot of `2·10⁻⁶` of its variance, below `256·15·ε` =
    /// `4.6·10⁻⁴` in `f32`) is not, whatever the attitude.
    #[test]
    fn start_is_judged_given_the_attitude() {
        let mut p = SMatrix::<f32, 15, 15>::identity();
        // Body-frame attitude block of a heading of σ = π about the body axis (1, 1, 0)/√2 and a
        // tilt of σ = 10⁻³ rad: every entry of the heading's size.
        let u = nalgebra::Vector3::new(1.0f32, 1.0, 0.0).normalize();
        let heading = core::f32::consts::PI * core::f32::consts::PI;
        let a = Matrix3::identity() * 1e-6 + u * u.transpose() * (heading - 1e-6);
        let a = a + Matrix3::from_diagonal_element(attitude_floor(&a));
        p.fixed_view_mut::<3, 3>(0, 0).copy_from(&a);
        assert!(
            !is_usable_spd(&p, usable_pivot::<f32, 15>()),
            "the whole-P test refuses it"
        );
        assert!(is_usable_start(&p));
        for k in 0..3 {
            p[(3 + k, 6 + k)] = 1.0 - 1e-6;
            p[(6 + k, 3 + k)] = 1.0 - 1e-6;
        }
        assert!(is_spd(&p), "positive definite");
        assert!(!is_usable_start(&p), "velocity known given the position");
    }
}

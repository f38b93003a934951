//! Checks and read-outs of a covariance matrix.

use super::config::FilterConfig;
use super::error::EskfError;
use super::state::ErrorState;
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
/// [`Real::VARIANCE_CEILING_F64`], every Cholesky pivot above [`usable_pivot`] of its diagonal).
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
    if !(variances_usable && is_usable_spd(covariance, usable_pivot::<T, N>())) {
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
/// The test is the bound `λ_min ≥ det A / (λ₁ λ₂) ≥ 4 det A / (tr A)²` (the two larger
/// eigenvalues have a product at most `(tr A / 2)²`), so it costs a determinant, not an
/// eigen-decomposition. It may floor a block whose smallest eigenvalue is larger; that changes
/// it by at most `f·tr A`, below the block's own rounding. Adding `c I` to a positive
/// semi-definite block of a positive semi-definite `P` keeps `P` so, and `c I` is the same in
/// every frame: the tilt and the heading are widened alike. In `f64` the floor is
/// `3.6e-15 tr A`: it never acts on a usable filter. In `f32` it acts only when the heading is
/// unknown, and then keeps the tilt's σ at least `√(f tr A)`: 3.4 mrad when σ_ψ = 2.4 rad.
#[inline(never)] // one copy per scalar type, not one per filter and call site
pub(crate) fn attitude_floor<T: Real>(a: &Matrix3<T>) -> T {
    let tr = a.m11 + a.m22 + a.m33;
    let floor = tr * T::lit(ATTITUDE_FLOOR * T::EPSILON_F64);
    // The symmetric block's determinant by cofactors of its first row (upper triangle only).
    let det = a.m11 * (a.m22 * a.m33 - a.m23 * a.m23) - a.m12 * (a.m12 * a.m33 - a.m23 * a.m13)
        + a.m13 * (a.m12 * a.m23 - a.m22 * a.m13);
    if det * T::lit(4.0) <= floor * tr * tr {
        floor
    } else {
        T::zero()
    }
}

/// The growth floor, `f = 64 N ε`: the part of each variance's growth in a prediction that is
/// made independent of every other state.
const GROWTH_FLOOR: f64 = 64.0;

/// With it, `64 ε` of the growth of the variance's block (v or p), on each of the block's
/// variances: the rounding of the rotation that mixes the block's axes, with a margin.
const GROWTH_MIXING: f64 = 64.0;

/// And `2 ε` of each growing variance: the rounding of one prediction, twice over.
const GROWTH_ROUNDING: f64 = 2.0;

/// Floors the first `K` variances of a predicted `P` (θ; v; p): where `P⁺_kk` grew from its
/// value before the prediction (`before[k]`), adds `f (P⁺_kk − before[k]) + 2 ε P⁺_kk`, and
/// to every variance of the blocks v and p `64 ε G`, `G` the block's growth
/// `Σ_k max(P⁺_kk − before[k], 0)` ([`GROWTH_FLOOR`], [`GROWTH_ROUNDING`], [`GROWTH_MIXING`]).
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
/// The rotation `R [f]× dt` that feeds `v` and `p` mixes their three axes, so the rounding of
/// each axis is a few `ε` of the products the whole block goes through, not of its own result.
/// Where `R f` lies along one axis (a specific force of 10²⁰ m/s² nearly vertical), that
/// axis's variance grows by 10⁻¹⁰ of the others' and its rounding, a few `ε` of theirs, is far
/// above `f` times its own growth: in `f64` the correlation matrix came out at `−2e-12` with
/// the first term alone. `64 ε G` covers it (at `16 ε G` a specific force of 2·10³³ m/s²
/// along the body diagonal still left it at `−7e-15`). The attitude needs no such term: its growth
/// `J_r dt P_bg J_rᵀ dt` keeps at least `(2/π)²` of its products' size, as the prediction
/// refuses a step that turns by π or more, and `ΔRᵀ`'s rounding is the attitude floor's.
///
/// When the growth per step is small beside the variance (an attitude of σ = 60 rad fed by a
/// gyro bias of σ = 3.7 rad/s, 500 steps), the rounding of each step, a few `ε` of the
/// variance, outruns the first term; `2 ε P⁺_kk` more on each growing variance covers that. In
/// `f64` the three are `2.1e-13` of the growth, `1.4e-14` of the block's and `4.4e-16` of the
/// variance per step; in `f32`, `1.1e-4`, `7.6e-6` and `2.4e-7`: at 200 Hz a variance that
/// grows for 600 s without a measurement ends 2.9 % larger.
pub(crate) fn floor_growth<T: Real, const N: usize, const K: usize>(
    p: &mut SMatrix<T, N, N>,
    before: &[T; K],
) {
    let f = T::lit(GROWTH_FLOOR * T::EPSILON_F64 * N as f64);
    let mixing = T::lit(GROWTH_MIXING * T::EPSILON_F64);
    let rounding = T::lit(GROWTH_ROUNDING * T::EPSILON_F64);
    // The growth of the blocks v and p, before the variances' own floors (none when K = 3).
    let mut block_growth = [T::zero(); 3];
    for block in 1..K / 3 {
        for k in 3 * block..3 * block + 3 {
            if let (Some(d), Some(b), Some(g)) =
                (p.get((k, k)), before.get(k), block_growth.get_mut(block))
            {
                *g += larger(*d - *b, T::zero());
            }
        }
    }
    for (k, own) in before.iter().enumerate() {
        if let Some(d) = p.get_mut((k, k)) {
            let grown = *d - *own;
            if grown > T::zero() {
                *d += grown * f + *d * rounding;
            }
        }
    }
    for block in 1..K / 3 {
        for k in 3 * block..3 * block + 3 {
            if let (Some(d), Some(g)) = (p.get_mut((k, k)), block_growth.get(block)) {
                *d += *g * mixing;
            }
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

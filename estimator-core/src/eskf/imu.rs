//! IMU samples, noise model, and the prediction step (nominal integration, block-sparse `F P Fᵀ + Q`).
//!
//! See the module docs of [`crate::eskf`] for the equations.

use super::error::EskfError;
use super::state::{AhrsState, InsState};
use crate::lie::{skew, LieGroup, So3};
use crate::Real;
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

/// One IMU sample: body angular rate `ω_m` (rad/s), specific force `f_m` (m/s²), and the interval
/// `dt` (s) over which both are taken as constant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuSample<T: Real> {
    /// Measured angular rate `ω_m`, body frame, rad/s.
    pub gyro: Vector3<T>,
    /// Measured specific force `f_m`, body frame, m/s².
    pub accel: Vector3<T>,
    /// Time step `dt > 0`, s.
    pub dt: T,
}

/// Continuous-time IMU noise in Kalibr units.
///
/// White noise densities `σ_g` (rad/s/√Hz) and `σ_a` (m/s²/√Hz); bias random walks `σ_bg`
/// (rad/s²/√Hz) and `σ_ba` (m/s³/√Hz). The discrete covariances over `dt` are `σ² dt` for the
/// integrated quantities (see the module docs for `Q`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuNoise<T: Real> {
    /// `σ_g`, rad/s/√Hz.
    pub gyroscope_noise_density: T,
    /// `σ_bg`, rad/s²/√Hz.
    pub gyroscope_random_walk: T,
    /// `σ_a`, m/s²/√Hz.
    pub accelerometer_noise_density: T,
    /// `σ_ba`, m/s³/√Hz.
    pub accelerometer_random_walk: T,
}

impl<T: Real> ImuNoise<T> {
    /// A consumer MEMS IMU (BMI088-class): `σ_g = 1.7e-4`, `σ_bg = 2e-5`, `σ_a = 2e-3`,
    /// `σ_ba = 3e-4`.
    #[must_use]
    pub fn mems() -> Self {
        Self {
            gyroscope_noise_density: T::lit(1.7e-4),
            gyroscope_random_walk: T::lit(2.0e-5),
            accelerometer_noise_density: T::lit(2.0e-3),
            accelerometer_random_walk: T::lit(3.0e-4),
        }
    }

    pub(crate) fn is_valid(&self) -> bool {
        let all = [
            self.gyroscope_noise_density,
            self.gyroscope_random_walk,
            self.accelerometer_noise_density,
            self.accelerometer_random_walk,
        ];
        // Finite (the shared out-of-line check) and not below zero (false for NaN).
        all_finite(&all) && all.iter().all(|x| *x >= T::zero())
    }
}

/// Filter configuration shared by both filters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilterConfig<T: Real> {
    /// IMU noise (Kalibr units).
    pub imu_noise: ImuNoise<T>,
    /// Gravity `g` in the world frame (ENU, z up): default `[0, 0, −9.81]`.
    pub gravity: Vector3<T>,
    /// Largest accepted `dt` (s); larger gives [`EskfError::DtTooLarge`]. Default 0.1 s.
    pub max_dt: T,
}

impl<T: Real> Default for FilterConfig<T> {
    fn default() -> Self {
        Self {
            imu_noise: ImuNoise::mems(),
            gravity: Vector3::new(T::zero(), T::zero(), T::lit(-9.81)),
            max_dt: T::lit(0.1),
        }
    }
}

impl<T: Real> FilterConfig<T> {
    /// `Ok` when every number is finite, the noise densities are `≥ 0` and `max_dt > 0`.
    pub fn validate(&self) -> Result<(), EskfError> {
        if !(finite(&self.gravity) && self.max_dt.is_finite()) {
            return Err(EskfError::NonFinite);
        }
        if !self.imu_noise.is_valid() {
            return Err(EskfError::NoiseNotPositiveDefinite);
        }
        if self.max_dt <= T::zero() {
            return Err(EskfError::InvalidOption);
        }
        Ok(())
    }
}

pub(crate) fn check_dt<T: Real>(dt: T, max_dt: T) -> Result<(), EskfError> {
    if !dt.is_finite() {
        Err(EskfError::NonFinite)
    } else if dt <= T::zero() {
        Err(EskfError::NonPositiveDt)
    } else if dt > max_dt {
        Err(EskfError::DtTooLarge)
    } else {
        Ok(())
    }
}

/// `true` when every entry of `m` is finite; inlined, so that the check unrolls over values
/// still in registers (the update's and the predictions' instruction counts at opt-level 3 are
/// budgeted).
#[inline(always)]
pub(crate) fn finite_vec<T: Real, const R: usize, const C: usize>(m: &SMatrix<T, R, C>) -> bool {
    sum_times_zero_is_zero(m.as_slice())
}

/// `true` when every entry of `m` is finite, through one out-of-line loop for every shape (for
/// the measurement models and the start-up, where size matters more than speed).
#[inline]
pub(crate) fn finite<T: Real, const R: usize, const C: usize>(m: &SMatrix<T, R, C>) -> bool {
    all_finite(m.as_slice())
}

/// Not inlined: one copy of the loop for every matrix shape.
#[inline(never)]
fn all_finite<T: Real>(s: &[T]) -> bool {
    sum_times_zero_is_zero(s)
}

/// `true` when every element of `s` is finite: `Σ x·0 = 0`.
///
/// `x · 0` is `±0` for a finite `x` and NaN for `±∞` or NaN (IEEE 754-2008 §7.2: `0 · ∞` is an
/// invalid operation), and NaN propagates through the sum (`−0 = +0` in the comparison): two
/// instructions per element and no branch. Over the contiguous storage: nalgebra's strided
/// `iter()` costs ~170 instructions per element on a Cortex-M4.
#[cfg_attr(not(estimator_compact), inline(always))]
#[cfg_attr(estimator_compact, inline(never))]
pub(crate) fn sum_times_zero_is_zero<T: Real>(s: &[T]) -> bool {
    let z = T::zero();
    s.iter().fold(z, |acc, x| acc + *x * z) == z
}

/// Block `(i, j)` (3×3, offsets `3i, 3j`) of an `R × C` matrix (zero outside the matrix),
/// read as three column pieces of the column-major storage.
pub(crate) fn blk_rc<T: Real, const R: usize, const C: usize>(
    m: &SMatrix<T, R, C>,
    i: usize,
    j: usize,
) -> Matrix3<T> {
    let col = |c: usize| {
        let s = R * (3 * j + c) + 3 * i;
        match m.as_slice().get(s..s + 3) {
            Some(&[a, b, c]) if 3 * i + 3 <= R => [a, b, c],
            _ => [T::zero(); 3],
        }
    };
    let ([a0, a1, a2], [b0, b1, b2], [c0, c1, c2]) = (col(0), col(1), col(2));
    Matrix3::new(a0, b0, c0, a1, b1, c1, a2, b2, c2)
}

/// Writes block `(i, j)` of an `R × C` matrix, column piece by column piece (nothing outside
/// the matrix). Built for size, through one out-of-line copy over the storage
/// ([`set_blk_rows`]) for every shape.
#[cfg(estimator_compact)]
#[inline(always)]
pub(crate) fn set_blk_rc<T: Real, const R: usize, const C: usize>(
    m: &mut SMatrix<T, R, C>,
    i: usize,
    j: usize,
    v: &Matrix3<T>,
) {
    set_blk_rows(m.as_mut_slice(), R, i, j, v);
}

/// Writes block `(i, j)` of an `R × C` matrix (see the build for size above); at opt-level 2
/// or 3 specialised for each shape, with which the prediction's instruction counts are budgeted.
#[cfg(not(estimator_compact))]
pub(crate) fn set_blk_rc<T: Real, const R: usize, const C: usize>(
    m: &mut SMatrix<T, R, C>,
    i: usize,
    j: usize,
    v: &Matrix3<T>,
) {
    if 3 * i + 3 > R {
        return;
    }
    for (c, src) in v.as_slice().chunks_exact(3).enumerate() {
        let s = R * (3 * j + c) + 3 * i;
        if let Some(dst) = m.as_mut_slice().get_mut(s..s + 3) {
            for (d, x) in dst.iter_mut().zip(src) {
                *d = *x;
            }
        }
    }
}

/// [`set_blk_rc`] on the column-major storage `m` of a matrix with `rows` rows (the same
/// stores).
#[cfg(estimator_compact)]
#[inline(never)]
fn set_blk_rows<T: Real>(m: &mut [T], rows: usize, i: usize, j: usize, v: &Matrix3<T>) {
    if 3 * i + 3 > rows {
        return;
    }
    for (c, src) in v.as_slice().chunks_exact(3).enumerate() {
        let s = rows * (3 * j + c) + 3 * i;
        if let Some(dst) = m.get_mut(s..s + 3) {
            for (d, x) in dst.iter_mut().zip(src) {
                *d = *x;
            }
        }
    }
}

/// Block `(i, j)` of a square matrix.
#[cfg_attr(not(estimator_compact), inline)]
#[cfg_attr(estimator_compact, inline(never))]
pub(crate) fn blk<T: Real, const N: usize>(m: &SMatrix<T, N, N>, i: usize, j: usize) -> Matrix3<T> {
    blk_rc(m, i, j)
}

/// Writes block `(i, j)` of a square matrix.
#[inline]
pub(crate) fn set_blk<T: Real, const N: usize>(
    m: &mut SMatrix<T, N, N>,
    i: usize,
    j: usize,
    v: &Matrix3<T>,
) {
    set_blk_rc(m, i, j, v);
}

/// Adds `s` to the diagonal of block `(i, i)`.
#[cfg_attr(estimator_compact, inline(never))]
pub(crate) fn add_diag<T: Real, const N: usize>(m: &mut SMatrix<T, N, N>, i: usize, s: T) {
    add_cross(m, i, i, s);
}

/// Adds `s` to the diagonal of block `(i, j)`, and of block `(j, i)` when `i ≠ j`.
fn add_cross<T: Real, const N: usize>(m: &mut SMatrix<T, N, N>, i: usize, j: usize, s: T) {
    for k in 0..3 {
        if let Some(x) = m.get_mut((3 * i + k, 3 * j + k)) {
            *x += s;
        }
        if i != j {
            if let Some(x) = m.get_mut((3 * j + k, 3 * i + k)) {
                *x += s;
            }
        }
    }
}

/// `(a + aᵀ)/2`: the symmetric part of a diagonal block (removes the rounding asymmetry).
/// Built for size, entry by entry over the storage: `(a_ij + a_ji)·½`, the sums and products
/// of nalgebra's `(a + aᵀ) * ½` without its generic loops.
#[cfg(estimator_compact)]
#[inline(never)]
pub(crate) fn sym<T: Real>(a: &Matrix3<T>) -> Matrix3<T> {
    let s = a.as_slice();
    let mut out = *a;
    for (j, col) in out.as_mut_slice().chunks_exact_mut(3).enumerate() {
        for (i, e) in col.iter_mut().enumerate() {
            *e = (*e + s.get(3 * i + j).copied().unwrap_or_else(T::zero)) * T::lit(0.5);
        }
    }
    out
}

/// `(a + aᵀ)/2` (see the build for size above); at opt-level 2 or 3 nalgebra's expression, with
/// which the prediction's instruction counts are budgeted.
#[cfg(not(estimator_compact))]
pub(crate) fn sym<T: Real>(a: &Matrix3<T>) -> Matrix3<T> {
    (a + a.transpose()) * T::lit(0.5)
}

/// A block column: the `15 × 3` column-major storage of block columns `3j..3j+3` of a 15-row
/// matrix (contiguous in nalgebra's column-major layout), or `None` past the end.
#[inline]
fn block_column<T: Real>(s: &[T], j: usize) -> Option<&[T; 45]> {
    s.get(45 * j..45 * j + 45)?.try_into().ok()
}

/// Block `k` (rows `3k..3k+3`) of a block column.
#[cfg_attr(estimator_compact, inline(never))]
fn col_blk<T: Real>(q: &[T; 45], k: usize) -> Matrix3<T> {
    let g = |r: usize, c: usize| q.get(15 * c + 3 * k + r).copied().unwrap_or_else(T::zero);
    Matrix3::new(
        g(0, 0),
        g(0, 1),
        g(0, 2),
        g(1, 0),
        g(1, 1),
        g(1, 2),
        g(2, 0),
        g(2, 1),
        g(2, 2),
    )
}

/// The nonzero blocks of the block rows θ, v, p (0, 1, 2) of `F` (module docs; block indices
/// θ=0, v=1, p=2, b_g=3, b_a=4):
///   `F00 = ΔRᵀ`, `F03 = −J_r(ω dt) dt`,
///   `F10 = A = −R[f]× dt`, `F11 = I`, `F14 = B = −R dt`,
///   `F20 = ½ A dt`, `F21 = I dt`, `F22 = I`, `F24 = ½ B dt`,
/// with `A = B [f]×`. Block rows 3 and 4 are identity rows.
struct FRows<T: Real> {
    f00: Matrix3<T>,
    f03: Matrix3<T>,
    b: Matrix3<T>,
    fx: Matrix3<T>,
    dt: T,
}

impl<T: Real> FRows<T> {
    /// Block rows 0..2 of `F Q` for a block column `Q = (Q₀, …, Q₄)`:
    /// `(F Q)₀ = F00 Q₀ + F03 Q₃` (only when `rot`, else zero), `(F Q)₁ = Q₁ + C`,
    /// `(F Q)₂ = Q₂ + dt (Q₁ + ½ C)`, with `C = A Q₀ + B Q₄ = B([f]× Q₀ + Q₄)`.
    ///
    /// Written into `out` (no copies of the blocks through a returned array).
    fn apply(&self, q: &[T; 45], rot: bool, out: &mut [Matrix3<T>; 3]) {
        let (q0, q1) = (col_blk(q, 0), col_blk(q, 1));
        let c = mm(&self.b, &add33(&mm(&self.fx, &q0), &col_blk(q, 4)));
        let [top, v, p] = out;
        *top = if rot {
            add33(&mm(&self.f00, &q0), &mm(&self.f03, &col_blk(q, 3)))
        } else {
            Matrix3::zeros()
        };
        *p = row_p(col_blk(q, 2), &q1, &c, self.dt);
        *v = add33(&q1, &c);
    }
}

/// `q2 + (q1 + c·½)·dt` entry by entry over the storage when built for size: the operations of
/// nalgebra's `q2 + (q1 + c * ½) * dt` without its generic loops.
#[cfg(estimator_compact)]
#[inline(always)]
pub(crate) fn row_p<T: Real>(
    mut q2: Matrix3<T>,
    q1: &Matrix3<T>,
    c: &Matrix3<T>,
    dt: T,
) -> Matrix3<T> {
    let (q1, c) = (q1.as_slice(), c.as_slice());
    for (k, e) in q2.as_mut_slice().iter_mut().enumerate() {
        if let (Some(a), Some(b)) = (q1.get(k), c.get(k)) {
            *e += (*a + *b * T::lit(0.5)) * dt;
        }
    }
    q2
}

/// `q2 + (q1 + c·½)·dt`; at opt-level 2 or 3 nalgebra's expression, with which the prediction's
/// instruction counts are budgeted.
#[cfg(not(estimator_compact))]
#[inline(always)]
pub(crate) fn row_p<T: Real>(q2: Matrix3<T>, q1: &Matrix3<T>, c: &Matrix3<T>, dt: T) -> Matrix3<T> {
    q2 + (q1 + c * T::lit(0.5)) * dt
}

/// The 15-state prediction; writes only after every check passed.
///
/// Nominal: `ω = ω_m − b_g`, `f = f_m − b_a`, `a = R f + g`, `ΔR = exp(ω dt)`,
/// `R⁺ = R ΔR`, `v⁺ = v + a dt`, `p⁺ = p + v dt + ½ a dt²`.
/// Covariance: `P⁺ = F P Fᵀ + Q` with the nonzero blocks of `F` written out (module docs).
pub(crate) fn predict_ins<T: Real>(
    x: &mut InsState<T>,
    p: &mut SMatrix<T, 15, 15>,
    imu: &ImuSample<T>,
    cfg: &FilterConfig<T>,
) -> Result<(), EskfError> {
    if !(finite_vec(&imu.gyro) && finite_vec(&imu.accel)) {
        return Err(EskfError::NonFinite);
    }
    let dt = imu.dt;
    check_dt(dt, cfg.max_dt)?;
    let half = T::lit(0.5);

    // `a + b·(−1)` is `a − b` exactly (IEEE 754 negation is exact).
    let omega = axpy(&imu.gyro, &x.gyro_bias, -T::one());
    let f = axpy(&imu.accel, &x.accel_bias, -T::one());
    // Read in place (`e.0`, `e.1`), not destructured into copies at opt-level "s".
    let e = So3::exp_jac(&(omega * dt));
    let (dr, jr) = (&e.0, e.1);
    let r = x.attitude.rotation_matrix();
    let a = super::models::add3(&mv(&r, &f), &cfg.gravity);
    let new_x = InsState {
        attitude: x.attitude.compose(dr).renormalize(),
        velocity: axpy(&x.velocity, &a, dt),
        position: axpy(&axpy(&x.position, &x.velocity, dt), &a, half * dt * dt),
        gyro_bias: x.gyro_bias,
        accel_bias: x.accel_bias,
    };

    // F03 = J_r·(−dt) and B = R·(−dt) scaled in place (no copies into the struct).
    let mut fr = FRows {
        f00: tr33(&dr.rotation_matrix()),
        f03: jr,
        b: r,
        fx: skew(&f),
        dt,
    };
    scale(&mut fr.f03, -dt);
    scale(&mut fr.b, -dt);
    let f_finite =
        finite_vec(&fr.f00) && finite_vec(&fr.f03) && finite_vec(&fr.b) && finite_vec(&fr.fx);
    // Two passes of the same kernel, `FRows::apply` (the nonzero blocks of F's rows θ, v, p
    // applied to a 15 × 3 block column), from one call site, so that every opt-level inlines it
    // exactly once:
    // * t = 0..5, F P: block column j = t of P gives M_ij = (F P)_ij, i = 0..2, stored as
    //   L_ji = M_ijᵀ in L = (F P)ᵀ = P Fᵀ (a 15 × 9 temporary). Rows 3 and 4 of F are identity
    //   rows, so (F P)_3j = P_3j and (F P)_4j = P_4j need no storage.
    // * t = 5..8, N = F P Fᵀ = F L: block column i = t − 5 of N is F applied to block column i of
    //   L. Only the blocks on and below the diagonal are kept (N_ki, k ≥ i; N is symmetric), in
    //   place of L_ki: block column i of L is read once, and later columns are untouched.
    //   N_3i = L_3i and N_4i = L_4i (identity rows of F) are already there.
    let mut l = SMatrix::<T, 15, 9>::zeros();
    let mut out = [Matrix3::<T>::zeros(); 3];
    for t in 0..8 {
        let (src, j) = if t < 5 {
            (p.as_slice(), t)
        } else {
            (l.as_slice(), t - 5)
        };
        let Some(q) = block_column(src, j) else {
            continue;
        };
        // Row θ of F Q: for every column of F P, but of F L only N_00 (N_0i, i > 0, lies above
        // the diagonal).
        fr.apply(q, t <= 5, &mut out);
        for (i, m) in out.iter().enumerate() {
            if t < 5 {
                set_blk_rc(&mut l, j, i, &tr33(m));
            } else if i == j {
                set_blk_rc(&mut l, i, j, &sym(m));
            } else if i > j {
                set_blk_rc(&mut l, i, j, m);
            }
        }
    }
    // F and P are finite, so N = F P Fᵀ can only fail by overflow, and for a positive
    // semi-definite N, |N_ij| ≤ √(N_ii N_jj): a finite diagonal bounds every entry.
    // The diagonal of N is the diagonal of L's top 9 × 9.
    let d_ok = (0..9).fold(true, |acc, k| {
        acc & l.get((k, k)).is_some_and(|d| d.is_finite())
    });
    if !(f_finite && new_x.is_finite_ins() && d_ok) {
        return Err(EskfError::NonFinite);
    }
    // Write the lower blocks and their transposes; P_33, P_34, P_44 are unchanged before Q.
    write_lower(p, &l);
    let n = &cfg.imu_noise;
    let qa = n.accelerometer_noise_density * n.accelerometer_noise_density * dt;
    add_diag(
        p,
        0,
        n.gyroscope_noise_density * n.gyroscope_noise_density * dt,
    );
    add_diag(p, 1, qa);
    add_cross(p, 1, 2, qa * dt * half);
    add_diag(p, 2, qa * dt * dt * T::lit(0.25));
    add_diag(p, 3, n.gyroscope_random_walk * n.gyroscope_random_walk * dt);
    add_diag(
        p,
        4,
        n.accelerometer_random_walk * n.accelerometer_random_walk * dt,
    );
    *x = new_x;
    Ok(())
}

/// Writes the blocks `N_ki = L_ki`, `k ≥ i`, of block columns 0..3 of `L` into `P`, with
/// `N_ik = N_kiᵀ` above them. Built for size, entry by entry over `L`'s storage: column `c`
/// (block column `c/3`) from the diagonal block's first row down, each entry also mirrored
/// above the diagonal block (`N_ii`, symmetric, is in `L` whole); the same stores as the block
/// loop below.
#[cfg(estimator_compact)]
#[inline(always)]
pub(crate) fn write_lower<T: Real>(p: &mut SMatrix<T, 15, 15>, l: &SMatrix<T, 15, 9>) {
    let ps = p.as_mut_slice();
    for (c, lc) in l.as_slice().chunks_exact(15).enumerate() {
        let start = c - c % 3;
        for (r, v) in lc.iter().enumerate().skip(start) {
            if let Some(e) = ps.get_mut(15 * c + r) {
                *e = *v;
            }
            if r >= start + 3 {
                if let Some(e) = ps.get_mut(15 * r + c) {
                    *e = *v;
                }
            }
        }
    }
}

/// The blocks of `L` into `P` (see the build for size above), block by block: at opt-level 2
/// or 3 the copies unroll (the prediction's instruction count is budgeted).
#[cfg(not(estimator_compact))]
#[inline(always)]
pub(crate) fn write_lower<T: Real>(p: &mut SMatrix<T, 15, 15>, l: &SMatrix<T, 15, 9>) {
    for i in 0..3 {
        for k in i..5 {
            let n = blk_rc(l, k, i);
            set_blk(p, k, i, &n);
            if k > i {
                set_blk(p, i, k, &tr33(&n));
            }
        }
    }
}

impl<T: Real> InsState<T> {
    fn is_finite_ins(&self) -> bool {
        super::state::ErrorState::<T, 15>::is_finite(self)
    }
}

/// The attitude-only prediction: `R⁺ = R exp((ω_m − b_g) dt)`,
/// `P⁺ = F P Fᵀ + Q`, `F = [ΔRᵀ, −J_r dt; 0, I]`, `Q = diag(σ_g² dt I, σ_bg² dt I)`.
pub(crate) fn predict_ahrs<T: Real>(
    x: &mut AhrsState<T>,
    p: &mut SMatrix<T, 6, 6>,
    gyro: &Vector3<T>,
    dt: T,
    cfg: &FilterConfig<T>,
) -> Result<(), EskfError> {
    if !finite_vec(gyro) {
        return Err(EskfError::NonFinite);
    }
    check_dt(dt, cfg.max_dt)?;
    // Read in place (`e.0`, `e.1`), not destructured into copies at opt-level "s".
    let e = So3::exp_jac(&(axpy(gyro, &x.gyro_bias, -T::one()) * dt));
    let (dr, jr) = (&e.0, e.1);
    // F00 = ΔRᵀ, so F00ᵀ = ΔR (no transpose pass).
    let f00t = dr.rotation_matrix();
    let f00 = tr33(&f00t);
    let f01 = scaled(jr, -dt);
    let p00 = blk(p, 0, 0);
    let p01 = blk(p, 0, 1);
    let p11 = blk(p, 1, 1);
    // M0j = F00 P0j + F01 P1j; P⁺00 = M00 F00ᵀ + M01 F01ᵀ; P⁺01 = M01; P⁺11 = P11.
    let m00 = add33(&mm(&f00, &p00), &mm(&f01, &tr33(&p01)));
    let m01 = add33(&mm(&f00, &p01), &mm(&f01, &p11));
    // N00 = M00 F00ᵀ + M01 F01ᵀ is symmetric: its upper triangle, mirrored (exactly symmetric
    // without a separate symmetrization; at opt-level 3 the unused lower products are dead).
    let n = add33(&mm(&m00, &f00t), &mm(&m01, &tr33(&f01)));
    let n00 = Matrix3::new(
        n.m11, n.m12, n.m13, n.m12, n.m22, n.m23, n.m13, n.m23, n.m33,
    );
    let att = x.attitude.compose(dr).renormalize();
    if !(finite_vec(&n00) && finite_vec(&m01) && att.is_finite()) {
        return Err(EskfError::NonFinite);
    }
    set_blk(p, 0, 0, &n00);
    set_blk(p, 0, 1, &m01);
    set_blk(p, 1, 0, &tr33(&m01));
    let n = &cfg.imu_noise;
    add_diag(
        p,
        0,
        n.gyroscope_noise_density * n.gyroscope_noise_density * dt,
    );
    add_diag(p, 1, n.gyroscope_random_walk * n.gyroscope_random_walk * dt);
    x.attitude = att;
    Ok(())
}

/// `m·s`, entry by entry over the storage (one small loop at opt-level "s").
fn scaled<T: Real>(mut m: Matrix3<T>, s: T) -> Matrix3<T> {
    scale(&mut m, s);
    m
}

/// `m ← m·s`, entry by entry over the storage.
fn scale<T: Real>(m: &mut Matrix3<T>, s: T) {
    for x in m.as_mut_slice() {
        *x *= s;
    }
}

/// `√max(P_ii, 0)` for each `i`: a filter's 1-σ, entry by entry over the storage (nalgebra's
/// `diagonal().map(..)` without its generic loops).
pub(crate) fn sigmas<T: Real, const N: usize>(p: &SMatrix<T, N, N>) -> SVector<T, N> {
    let mut out = SVector::<T, N>::zeros();
    for (i, e) in out.as_mut_slice().iter_mut().enumerate() {
        let d = p
            .as_slice()
            .get(i * (N + 1))
            .copied()
            .unwrap_or_else(T::zero);
        *e = d.max(T::zero()).sqrt_rn();
    }
    out
}

/// `mᵀ` for a 3×3 matrix, entry by entry (built for size: out of line, where nalgebra's
/// `transpose` is a generic loop inlined at every site).
#[cfg(estimator_compact)]
#[inline(never)]
pub(crate) fn tr33<T: Real>(m: &Matrix3<T>) -> Matrix3<T> {
    Matrix3::new(
        m.m11, m.m21, m.m31, m.m12, m.m22, m.m32, m.m13, m.m23, m.m33,
    )
}

/// `mᵀ`; at opt-level 2 or 3 nalgebra's `transpose`, with which the instruction counts are
/// budgeted.
#[cfg(not(estimator_compact))]
#[inline(always)]
pub(crate) fn tr33<T: Real>(m: &Matrix3<T>) -> Matrix3<T> {
    m.transpose()
}

/// `r f`, entry by entry (the sums of nalgebra's `r * f`, without its generic product loop).
#[cfg_attr(estimator_compact, inline(never))]
pub(crate) fn mv<T: Real>(r: &Matrix3<T>, f: &Vector3<T>) -> Vector3<T> {
    Vector3::new(
        r.m11 * f.x + r.m12 * f.y + r.m13 * f.z,
        r.m21 * f.x + r.m22 * f.y + r.m23 * f.z,
        r.m31 * f.x + r.m32 * f.y + r.m33 * f.z,
    )
}

/// `a + b` for 3×3 matrices, entry by entry over the storage (nalgebra's sum is a generic
/// loop at opt-level "s").
#[cfg_attr(estimator_compact, inline(never))]
pub(crate) fn add33<T: Real>(a: &Matrix3<T>, b: &Matrix3<T>) -> Matrix3<T> {
    let mut out = *a;
    for (o, x) in out.as_mut_slice().iter_mut().zip(b.as_slice()) {
        *o += *x;
    }
    out
}

/// `y + x·a`, entry by entry (one small function for the nominal integration).
#[cfg_attr(estimator_compact, inline(never))]
pub(crate) fn axpy<T: Real>(y: &Vector3<T>, x: &Vector3<T>, a: T) -> Vector3<T> {
    Vector3::new(y.x + x.x * a, y.y + x.y * a, y.z + x.z * a)
}

/// `a > b`, false for NaN (named so that `!greater(a, b)` reads as "not above, or NaN").
#[inline(always)]
pub(crate) fn greater<T: Real>(a: T, b: T) -> bool {
    a > b
}

/// `a · b` for 3×3 matrices: `(a b)_rc = a_r0 b_0c + a_r1 b_1c + a_r2 b_2c`, column by column
/// (nalgebra's generic product is not unrolled for a generic scalar). A loop over the columns
/// of `b`, so that opt-level "s" keeps it small; opt-level 3 unrolls it completely. No inline
/// hint: opt-level "s" then keeps one out-of-line copy, opt-level 3 still inlines it.
pub(crate) fn mm<T: Real>(a: &Matrix3<T>, b: &Matrix3<T>) -> Matrix3<T> {
    let (r0, r1, r2) = (
        (a.m11, a.m12, a.m13),
        (a.m21, a.m22, a.m23),
        (a.m31, a.m32, a.m33),
    );
    let mut out = Matrix3::zeros();
    for (oc, bc) in out
        .as_mut_slice()
        .chunks_exact_mut(3)
        .zip(b.as_slice().chunks_exact(3))
    {
        if let ([o0, o1, o2], [b0, b1, b2]) = (oc, bc) {
            *o0 = r0.0 * *b0 + r0.1 * *b1 + r0.2 * *b2;
            *o1 = r1.0 * *b0 + r1.1 * *b1 + r1.2 * *b2;
            *o2 = r2.0 * *b0 + r2.1 * *b1 + r2.2 * *b2;
        }
    }
    out
}

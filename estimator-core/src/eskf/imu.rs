//! IMU samples, noise model, and the prediction step (nominal integration, block-sparse `F P Fᵀ + Q`).
//!
//! See the module docs of [`crate::eskf`] for the equations.

use super::error::EskfError;
use super::state::{AhrsState, InsState};
use crate::lie::{skew, LieGroup, So3};
use crate::Real;
use nalgebra::{Matrix3, SMatrix, Vector3};

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
        [
            self.gyroscope_noise_density,
            self.gyroscope_random_walk,
            self.accelerometer_noise_density,
            self.accelerometer_random_walk,
        ]
        .iter()
        .all(|x| x.is_finite() && *x >= T::zero())
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
        if !(self.gravity.iter().all(|x| x.is_finite()) && self.max_dt.is_finite()) {
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

pub(crate) fn finite_vec<T: Real, const R: usize, const C: usize>(m: &SMatrix<T, R, C>) -> bool {
    // Branch-free and-reduction; `all` would branch per element.
    // Over the contiguous storage: nalgebra's strided `iter()` costs ~170 instructions per
    // element on a Cortex-M4 (fully unrolled with pointer selects), the slice ~4.
    m.as_slice().iter().fold(true, |acc, x| acc & x.is_finite())
}

/// Block `(i, j)` (3×3, offsets `3i, 3j`) of an `R × C` matrix, read element by element (with
/// constant `i, j` the bounds checks fold away; nalgebra's `into_owned` goes through an iterator).
#[inline(always)]
pub(crate) fn blk_rc<T: Real, const R: usize, const C: usize>(
    m: &SMatrix<T, R, C>,
    i: usize,
    j: usize,
) -> Matrix3<T> {
    let g = |r: usize, c: usize| {
        m.get((3 * i + r, 3 * j + c))
            .copied()
            .unwrap_or_else(T::zero)
    };
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

/// Writes block `(i, j)` of an `R × C` matrix element by element.
#[inline(always)]
pub(crate) fn set_blk_rc<T: Real, const R: usize, const C: usize>(
    m: &mut SMatrix<T, R, C>,
    i: usize,
    j: usize,
    v: &Matrix3<T>,
) {
    for c in 0..3 {
        for r in 0..3 {
            if let (Some(d), Some(s)) = (m.get_mut((3 * i + r, 3 * j + c)), v.get((r, c))) {
                *d = *s;
            }
        }
    }
}

/// Block `(i, j)` of a square matrix.
#[inline(always)]
pub(crate) fn blk<T: Real, const N: usize>(m: &SMatrix<T, N, N>, i: usize, j: usize) -> Matrix3<T> {
    blk_rc(m, i, j)
}

/// Writes block `(i, j)` of a square matrix.
#[inline(always)]
pub(crate) fn set_blk<T: Real, const N: usize>(
    m: &mut SMatrix<T, N, N>,
    i: usize,
    j: usize,
    v: &Matrix3<T>,
) {
    set_blk_rc(m, i, j, v);
}

/// Block `(i, j)` of a `9 × 15` block-row matrix.
#[inline(always)]
fn blk9<T: Real>(m: &SMatrix<T, 9, 15>, i: usize, j: usize) -> Matrix3<T> {
    blk_rc(m, i, j)
}

/// Writes block `(i, j)` of a `9 × 15` block-row matrix.
#[inline(always)]
fn set_blk9<T: Real>(m: &mut SMatrix<T, 9, 15>, i: usize, j: usize, v: &Matrix3<T>) {
    set_blk_rc(m, i, j, v);
}

/// Adds `s` to the diagonal of block `(i, i)`.
#[inline(always)]
pub(crate) fn add_diag<T: Real, const N: usize>(m: &mut SMatrix<T, N, N>, i: usize, s: T) {
    for k in 3 * i..3 * i + 3 {
        if let Some(x) = m.get_mut((k, k)) {
            *x += s;
        }
    }
}

/// Adds `s` to the diagonals of blocks `(i, j)` and `(j, i)`.
#[inline(always)]
fn add_cross<T: Real, const N: usize>(m: &mut SMatrix<T, N, N>, i: usize, j: usize, s: T) {
    for k in 0..3 {
        if let Some(x) = m.get_mut((3 * i + k, 3 * j + k)) {
            *x += s;
        }
        if let Some(x) = m.get_mut((3 * j + k, 3 * i + k)) {
            *x += s;
        }
    }
}

/// Runs `$body` five times with `$i` bound to the constants 0..4 (the 3×3 block indices).
macro_rules! unroll5 {
    ($i:ident => $body:block) => {{
        {
            let $i: usize = 0;
            $body
        }
        {
            let $i: usize = 1;
            $body
        }
        {
            let $i: usize = 2;
            $body
        }
        {
            let $i: usize = 3;
            $body
        }
        {
            let $i: usize = 4;
            $body
        }
    }};
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

    let omega = imu.gyro - x.gyro_bias;
    let f = imu.accel - x.accel_bias;
    let (dr, jr) = So3::exp_jac(&(omega * dt));
    let r = x.attitude.rotation_matrix();
    let a = r * f + cfg.gravity;
    let new_x = InsState {
        attitude: x.attitude.compose(&dr).renormalize(),
        velocity: x.velocity + a * dt,
        position: x.position + x.velocity * dt + a * (half * dt * dt),
        gyro_bias: x.gyro_bias,
        accel_bias: x.accel_bias,
    };

    // Nonzero blocks of F (block indices θ=0, v=1, p=2, b_g=3, b_a=4):
    //   F00 = ΔRᵀ, F03 = −J_r(ω dt) dt,
    //   F10 = A = −R[f]× dt, F11 = I, F14 = B = −R dt,
    //   F20 = ½ A dt, F21 = I dt, F22 = I, F24 = ½ B dt, F33 = I, F44 = I.
    // With A = B [f]×, the v-row of F·P is P1j + B([f]× P0j + P4j).
    let f00 = dr.rotation_matrix().transpose();
    let f03 = jr * (-dt);
    let b = r * (-dt);
    let fx = skew(&f);

    let f_finite = finite_vec(&f00) && finite_vec(&f03) && finite_vec(&b) && finite_vec(&fx);
    // M = F P for the block rows 0..2 (rows 3 and 4 of F are identity rows: M_3j = P_3j,
    // M_4j = P_4j), block column by block column.
    let mut m = SMatrix::<T, 9, 15>::zeros();
    unroll5!(j => {
        let p0 = blk(p, 0, j);
        let p1 = blk(p, 1, j);
        let p3 = blk(p, 3, j);
        let p4 = blk(p, 4, j);
        let c = mm(&b, &(mm(&fx, &p0) + p4));
        set_blk9(&mut m, 0, j, &(mm(&f00, &p0) + mm(&f03, &p3)));
        set_blk9(&mut m, 1, j, &(p1 + c));
        set_blk9(&mut m, 2, j, &(blk(p, 2, j) + (p1 + c * half) * dt));
    });
    // N = M Fᵀ, only the blocks on and above the diagonal (j ≥ i):
    //   N_i0 = M_i0 F00ᵀ + M_i3 F03ᵀ, N_i1 = M_i1 + D_i with D_i = (M_i4 − M_i0 [f]×) Bᵀ,
    //   N_i2 = M_i2 + dt (M_i1 + ½ D_i), N_i3 = M_i3, N_i4 = M_i4.
    // Row i of N needs only row i of M, so each row overwrites its own blocks in place.
    let f00t = f00.transpose();
    let f03t = f03.transpose();
    let bt = b.transpose();
    let sym = |a: Matrix3<T>| (a + a.transpose()) * half;
    {
        let (m0, m1, m2) = (blk9(&m, 0, 0), blk9(&m, 0, 1), blk9(&m, 0, 2));
        let (m3, m4) = (blk9(&m, 0, 3), blk9(&m, 0, 4));
        let d = mm(&(m4 - mm(&m0, &fx)), &bt);
        set_blk9(&mut m, 0, 0, &sym(mm(&m0, &f00t) + mm(&m3, &f03t)));
        set_blk9(&mut m, 0, 1, &(m1 + d));
        set_blk9(&mut m, 0, 2, &(m2 + (m1 + d * half) * dt));
    }
    {
        let (m0, m1, m2, m4) = (
            blk9(&m, 1, 0),
            blk9(&m, 1, 1),
            blk9(&m, 1, 2),
            blk9(&m, 1, 4),
        );
        let d = mm(&(m4 - mm(&m0, &fx)), &bt);
        set_blk9(&mut m, 1, 1, &sym(m1 + d));
        set_blk9(&mut m, 1, 2, &(m2 + (m1 + d * half) * dt));
    }
    {
        let (m0, m1, m2, m4) = (
            blk9(&m, 2, 0),
            blk9(&m, 2, 1),
            blk9(&m, 2, 2),
            blk9(&m, 2, 4),
        );
        let d = mm(&(m4 - mm(&m0, &fx)), &bt);
        set_blk9(&mut m, 2, 2, &sym(m2 + (m1 + d * half) * dt));
    }
    // F and P are finite, so N = F P Fᵀ can only fail by overflow, and for a positive
    // semi-definite N, |N_ij| ≤ √(N_ii N_jj): a finite diagonal bounds every entry.
    if !(f_finite && new_x.is_finite_ins() && finite_vec(&m.fixed_view::<9, 9>(0, 0).diagonal())) {
        return Err(EskfError::NonFinite);
    }
    // Write the upper blocks and their transposes; P_33, P_34, P_44 are unchanged before Q.
    unroll5!(j => {
        for i in 0..3 {
            if i <= j {
                let n = blk9(&m, i, j);
                set_blk(p, i, j, &n);
                if i < j {
                    set_blk(p, j, i, &n.transpose());
                }
            }
        }
    });
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
    let (dr, jr) = So3::exp_jac(&((gyro - x.gyro_bias) * dt));
    let f00 = dr.rotation_matrix().transpose();
    let f01 = jr * (-dt);
    let p00 = blk(p, 0, 0);
    let p01 = blk(p, 0, 1);
    let p11 = blk(p, 1, 1);
    // M0j = F00 P0j + F01 P1j; P⁺00 = M00 F00ᵀ + M01 F01ᵀ; P⁺01 = M01; P⁺11 = P11.
    let m00 = mm(&f00, &p00) + mm(&f01, &p01.transpose());
    let m01 = mm(&f00, &p01) + mm(&f01, &p11);
    // N00 = M00 F00ᵀ + M01 F01ᵀ is symmetric: compute its upper triangle and mirror it (half
    // the products, and exactly symmetric without a separate symmetrization).
    let row = |m: &Matrix3<T>, i: usize| match i {
        0 => (m.m11, m.m12, m.m13),
        1 => (m.m21, m.m22, m.m23),
        _ => (m.m31, m.m32, m.m33),
    };
    let dot = |a: (T, T, T), b: (T, T, T)| a.0 * b.0 + a.1 * b.1 + a.2 * b.2;
    let entry =
        |i: usize, j: usize| dot(row(&m00, i), row(&f00, j)) + dot(row(&m01, i), row(&f01, j));
    let (n11, n12, n13, n22, n23, n33) = (
        entry(0, 0),
        entry(0, 1),
        entry(0, 2),
        entry(1, 1),
        entry(1, 2),
        entry(2, 2),
    );
    let n00 = Matrix3::new(n11, n12, n13, n12, n22, n23, n13, n23, n33);
    let att = x.attitude.compose(&dr).renormalize();
    if !(finite_vec(&n00) && finite_vec(&m01) && att.is_finite()) {
        return Err(EskfError::NonFinite);
    }
    set_blk(p, 0, 0, &n00);
    set_blk(p, 0, 1, &m01);
    set_blk(p, 1, 0, &m01.transpose());
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

/// `a > b`, false for NaN (named so that `!greater(a, b)` reads as "not above, or NaN").
#[inline(always)]
pub(crate) fn greater<T: Real>(a: T, b: T) -> bool {
    a > b
}

/// `a · b` for 3×3 matrices, written out (nalgebra's generic product is not unrolled for a
/// generic scalar).
#[inline(always)]
pub(crate) fn mm<T: Real>(a: &Matrix3<T>, b: &Matrix3<T>) -> Matrix3<T> {
    let r = |i: (T, T, T), j: (T, T, T)| i.0 * j.0 + i.1 * j.1 + i.2 * j.2;
    let (a1, a2, a3) = (
        (a.m11, a.m12, a.m13),
        (a.m21, a.m22, a.m23),
        (a.m31, a.m32, a.m33),
    );
    let (b1, b2, b3) = (
        (b.m11, b.m21, b.m31),
        (b.m12, b.m22, b.m32),
        (b.m13, b.m23, b.m33),
    );
    Matrix3::new(
        r(a1, b1),
        r(a1, b2),
        r(a1, b3),
        r(a2, b1),
        r(a2, b2),
        r(a2, b3),
        r(a3, b1),
        r(a3, b2),
        r(a3, b3),
    )
}

//! The prediction step: nominal integration of one IMU sample and the block-sparse covariance
//! propagation `P⁺ = F P Fᵀ + Q` (equations in the [`crate::eskf`] module docs).

use super::config::{check_dt, FilterConfig, ImuSample};
use super::covariance::{
    cap_attitude, floor_attitude, floor_growth, floor_mixing, leading_diagonal,
};
use super::error::EskfError;
use super::state::{sealed::Sealed, AhrsAccelBiasState, AhrsState, ErrorState, InsState};
use crate::kernels::block::{add_scaled_identity, block, block_in, set_block};
use crate::kernels::{all_finite, mat3, positive_variance};
use crate::lie::{skew, LieGroup, So3};
use crate::Real;
use nalgebra::{Matrix3, SMatrix, Vector3};

/// The nonzero blocks of the block rows θ, v, p (0, 1, 2) of the 15-state `F` (block indices
/// θ=0, v=1, p=2, b_g=3, b_a=4):
///
/// ```text
/// F00 = ΔRᵀ,  F03 = −J_r(ω dt) dt,
/// F10 = A = −R[f]× dt,  F11 = I,  F14 = B = −R dt,
/// F20 = ½ A dt,  F21 = I dt,  F22 = I,  F24 = ½ B dt,
/// ```
///
/// with `A = B [f]×`. Block rows 3 and 4 are identity rows.
struct FRows<T: Real> {
    f00: Matrix3<T>,
    f03: Matrix3<T>,
    b: Matrix3<T>,
    fx: Matrix3<T>,
    dt: T,
}

impl<T: Real> FRows<T> {
    /// Block rows 0..2 of `F Q` for one block column `Q₀ … Q₄` of a 15-row matrix, its blocks
    /// read through `q`: `(F Q)₀ = F00 Q₀ + F03 Q₃` (when `rot`, else zero),
    /// `(F Q)₁ = Q₁ + C`, `(F Q)₂ = Q₂ + dt (Q₁ + ½ C)`, with `C = A Q₀ + B Q₄ = B([f]× Q₀ + Q₄)`.
    fn apply(&self, q: impl Fn(usize) -> Matrix3<T>, rot: bool) -> [Matrix3<T>; 3] {
        let (q0, q1) = (q(0), q(1));
        let c = mat3::mul(&self.b, &(mat3::mul(&self.fx, &q0) + q(4)));
        let top = if rot {
            mat3::mul(&self.f00, &q0) + mat3::mul(&self.f03, &q(3))
        } else {
            Matrix3::zeros()
        };
        [top, q1 + c, q(2) + (q1 + c * T::lit(0.5)) * self.dt]
    }
}

/// The 15-state prediction: [`predict_ins_finite`] after the sample's finiteness check.
fn predict_ins<T: Real>(
    x: &mut InsState<T>,
    p: &mut SMatrix<T, 15, 15>,
    imu: &ImuSample<T>,
    cfg: &FilterConfig<T>,
) -> Result<(), EskfError> {
    if !(all_finite(imu.gyro.as_slice()) && all_finite(imu.accel.as_slice())) {
        return Err(EskfError::NonFinite);
    }
    predict_ins_finite(x, p, imu, cfg)
}

/// The 15-state prediction of a sample whose gyro and accelerometer are finite (checked by
/// the caller: [`predict_ins`], or the INS navigator, which has checked every sample it
/// integrates); writes only after every other check passed. Out of line: one copy for both.
///
/// Nominal: `ω = ω_m − b_g`, `f = f_m − b_a`, `a = R f + g`, `ΔR = exp(ω dt)`,
/// `R⁺ = R ΔR`, `v⁺ = v + a dt`, `p⁺ = p + v dt + ½ a dt²`.
/// Covariance: `P⁺ = F P Fᵀ + Q` with the nonzero blocks of `F` ([`FRows`]).
#[inline(never)]
pub(crate) fn predict_ins_finite<T: Real>(
    x: &mut InsState<T>,
    p: &mut SMatrix<T, 15, 15>,
    imu: &ImuSample<T>,
    cfg: &FilterConfig<T>,
) -> Result<(), EskfError> {
    let dt = imu.dt;
    check_dt(dt, cfg.max_dt)?;
    let half = T::lit(0.5);

    let omega = imu.gyro - x.gyro_bias;
    let f = imu.accel - x.accel_bias;
    let turn = omega * dt;
    if !within_one_turn(&turn) {
        return Err(EskfError::NumericalFailure);
    }
    let (dr, jr) = So3::exp_jac(&turn);
    let r = x.attitude.rotation_matrix();
    let a = mat3::mul_vec(&r, &f) + cfg.gravity;
    let new_x = InsState {
        attitude: x.attitude.compose(&dr).renormalize(),
        velocity: mat3::axpy(&x.velocity, dt, &a),
        position: mat3::axpy(
            &mat3::axpy(&x.position, dt, &x.velocity),
            half * dt * dt,
            &a,
        ),
        gyro_bias: x.gyro_bias,
        accel_bias: x.accel_bias,
    };

    let fr = FRows {
        f00: dr.rotation_matrix().transpose(),
        f03: jr * -dt,
        b: r * -dt,
        fx: skew(&f),
        dt,
    };
    // Two passes of one kernel, `FRows::apply` (F's block rows θ, v, p applied to a 15 × 3
    // block column):
    // * F P: block column j of P gives M_ij = (F P)_ij, i = 0..2, kept as L_ji = M_ijᵀ in
    //   L = (F P)ᵀ = P Fᵀ (15 × 9). Rows 3 and 4 of F are identity rows, so (F P)_3j = P_3j
    //   and (F P)_4j = P_4j need no storage.
    // * N = F P Fᵀ = F L: block column i of N is F applied to block column i of L; only the
    //   blocks on and below the diagonal are used (N is symmetric), and row θ only for N_00.
    let mut l = SMatrix::<T, 15, 9>::zeros();
    for j in 0..5 {
        let m = fr.apply(|k| block_in(p.as_slice(), 15, k, j), true);
        for (i, mi) in m.iter().enumerate() {
            set_block(&mut l, j, i, &mi.transpose());
        }
    }
    // In place: block column i of L is read whole before its blocks k ≥ i (k < 3) are
    // replaced by N_ki; the blocks k = 3, 4 stay L_ki = N_ki.
    for i in 0..3 {
        let m = fr.apply(|k| block(&l, k, i), i == 0);
        for (k, mk) in m.iter().enumerate().skip(i) {
            if k == i {
                set_block(&mut l, k, i, &((mk + mk.transpose()) * half));
            } else {
                set_block(&mut l, k, i, mk);
            }
        }
    }
    // P is finite (an invariant of the filter), so N = F P Fᵀ is finite exactly when its
    // diagonal is: a non-finite entry of row i of F makes N_ii = Σ_kl F_ik P_kl F_il infinite
    // or NaN, and for a positive semi-definite N, |N_ij| ≤ √(N_ii N_jj) bounds every other
    // entry. It must also be positive (P is positive definite and F invertible): rounding in
    // an extreme step (a huge `dt` times a huge rate) can leave it zero or negative, and such
    // a P is refused, not stored; so is one above the variance ceiling (`√MAX`), beyond which
    // the products of an update overflow or lose the state's resolution.
    let diagonal_finite = (0..9).all(|k| l.get((k, k)).is_some_and(|d| positive_variance(*d)));
    let n = &cfg.imu_noise;
    let rw = |s: T| s * s * dt;
    let (q_bg, q_ba) = (rw(n.gyroscope_random_walk), rw(n.accelerometer_random_walk));
    let walks_usable = walk_usable(p, 3, q_bg) && walk_usable(p, 4, q_ba);
    // The variances of θ, v, p before the prediction, for the growth floor, and the size of
    // the products that feed v and p, for the mixing floor (at most the ceiling once floored).
    let before: [T; 9] = leading_diagonal(p);
    let diag = |k: usize| p.get((k, k)).copied().unwrap_or_else(T::zero);
    let products = dt
        * dt
        * (f.dot(&f) * (before[0] + before[1] + before[2]) + diag(12) + diag(13) + diag(14));
    let products_usable = products <= T::lit(T::VARIANCE_CEILING_F64);
    if !(diagonal_finite && walks_usable && products_usable && new_x.is_finite()) {
        return Err(EskfError::NonFinite);
    }
    // The lower blocks N_ki (k ≥ i, i < 3) and their transposes; P_33, P_34, P_44 are
    // unchanged before Q.
    for i in 0..3 {
        for k in i..5 {
            let n = block(&l, k, i);
            set_block(p, k, i, &n);
            if k > i {
                set_block(p, i, k, &n.transpose());
            }
        }
    }
    // Q from the continuous-time densities (module docs).
    let qa = n.accelerometer_noise_density * n.accelerometer_noise_density * dt;
    let qg = n.gyroscope_noise_density * n.gyroscope_noise_density * dt;
    add_scaled_identity(p, 0, 0, qg);
    add_scaled_identity(p, 1, 1, qa);
    add_scaled_identity(p, 1, 2, qa * dt * half);
    add_scaled_identity(p, 2, 2, qa * dt * dt * T::lit(0.25));
    add_scaled_identity(p, 3, 3, q_bg);
    add_scaled_identity(p, 4, 4, q_ba);
    floor_growth(p, &before);
    floor_mixing(p, products, dt);
    floor_attitude(p);
    cap_attitude(p);
    *x = new_x;
    Ok(())
}

/// The variances of block `block` of `P` (a bias: its row of `F` is the identity) after
/// their random walk `q = σ² dt` stay usable: their sum `tr P_bb + 3 q` at most the variance
/// ceiling ([`positive_variance`]; the variances are positive, so each is then at most it too).
/// Checked before anything is written, as `F P Fᵀ`'s diagonal is, so that a bias left
/// without a measurement is refused at the ceiling instead of growing to overflow.
#[inline(always)]
fn walk_usable<T: Real, const N: usize>(p: &SMatrix<T, N, N>, block: usize, q: T) -> bool {
    let at = |k: usize| p.get((k, k)).copied().unwrap_or_else(T::zero);
    let k = 3 * block;
    positive_variance(at(k) + at(k + 1) + at(k + 2) + q * T::lit(3.0))
}

/// `|ω dt| < π` (false for NaN): the step's rotation is one the exponential map gives
/// uniquely. Beyond it the sample cannot say how the body turned (a rate of `π/dt` or more is
/// aliased), and `J_r(ω dt)`, whose smallest singular value is `|sin(θ/2)/(θ/2)|`, tends to the
/// rank-one `ω̂ ω̂ᵀ` (singular at `2π`): the attitude's growth `J_r dt P_bg J_rᵀ dt` then
/// cancels to far below the rounding of its products (a gyro bias of σ = 10²⁹ rad/s left `P`
/// indefinite).
#[inline(always)]
fn within_one_turn<T: Real>(turn: &Vector3<T>) -> bool {
    turn.dot(turn) < T::pi() * T::pi()
}

/// The attitude-only prediction for the attitude states (`N = 6`: `(R, b_g)`; `N = 12`:
/// `(R, b_g, b_a, v)`): `R⁺ = R exp((ω_m − b_g) dt)`, `P⁺ = F P Fᵀ + Q` with
/// `F = [ΔRᵀ, −J_r dt, 0, 0; 0, I, 0, 0; 0, 0, I, 0; 0, 0, 0, I]` and
/// `Q = diag(σ_g² dt I, σ_bg² dt I, σ_ba² dt I, 0)` (the velocity moves by the block
/// integration of [`AhrsAccelBias::integrate_velocity`](super::AhrsAccelBias::integrate_velocity)).
/// Only the gyro and `dt` of the sample are read. Block row 0 of `F P` is
/// `M0j = F00 P0j + F01 P1j`; then `P⁺00 = M00 F00ᵀ + M01 F01ᵀ`, `P⁺0j = M0j` (`j ≥ 1`), and
/// the other blocks are unchanged.
fn predict_attitude<T: Real, const N: usize>(
    attitude: &mut So3<T>,
    gyro_bias: &Vector3<T>,
    p: &mut SMatrix<T, N, N>,
    imu: &ImuSample<T>,
    cfg: &FilterConfig<T>,
) -> Result<(), EskfError> {
    let dt = imu.dt;
    check_dt(dt, cfg.max_dt)?;
    // A non-finite gyro fails the turn's comparison too: it is told apart there, off the
    // usual path.
    let turn = (imu.gyro - gyro_bias) * dt;
    if !within_one_turn(&turn) {
        return Err(if all_finite(imu.gyro.as_slice()) {
            EskfError::NumericalFailure
        } else {
            EskfError::NonFinite
        });
    }
    let (dr, jr) = So3::exp_jac(&turn);
    // F00 = ΔRᵀ, so F00ᵀ = ΔR.
    let f00t = dr.rotation_matrix();
    let f00 = f00t.transpose();
    let f01 = jr * -dt;
    let (p00, p01, p11) = (block(p, 0, 0), block(p, 0, 1), block(p, 1, 1));
    let before = [p00.m11, p00.m22, p00.m33];
    let m00 = mat3::mul(&f00, &p00) + mat3::mul(&f01, &p01.transpose());
    let m01 = mat3::mul(&f00, &p01) + mat3::mul(&f01, &p11);
    // N00 is symmetric: its upper triangle, mirrored.
    let n = mat3::mul(&m00, &f00t) + mat3::mul(&m01, &f01.transpose());
    let n00 = Matrix3::new(
        n.m11, n.m12, n.m13, n.m12, n.m22, n.m23, n.m13, n.m23, n.m33,
    );
    let next = attitude.compose(&dr).renormalize();
    // As in the 15-state prediction: an overflow shows on the diagonal of N00, which bounds
    // M01 and M02 through the positive semi-definite P⁺; a diagonal that rounding left at zero
    // or below is refused too.
    let diagonal_finite = (0..3).all(|k| n00.get((k, k)).is_some_and(|d| positive_variance(*d)));
    let n = &cfg.imu_noise;
    let q_bg = n.gyroscope_random_walk * n.gyroscope_random_walk * dt;
    let q_ba = n.accelerometer_random_walk * n.accelerometer_random_walk * dt;
    let walks_usable = walk_usable(p, 1, q_bg) && (N < 9 || walk_usable(p, 2, q_ba));
    // `next` needs no check: the attitude is finite (an invariant of the filter) and the turn
    // is finite and below π, so `exp`, the product and the renormalization are finite.
    if !(diagonal_finite && walks_usable) {
        return Err(EskfError::NonFinite);
    }
    set_block(p, 0, 0, &n00);
    set_block(p, 0, 1, &m01);
    set_block(p, 1, 0, &m01.transpose());
    // The columns of the states the gyro does not move (the accelerometer bias, the
    // velocity), when there are any (`N` is a constant: the 6-state filter compiles without).
    for j in 2..N / 3 {
        let m0j = mat3::mul(&f00, &block(p, 0, j)) + mat3::mul(&f01, &block(p, 1, j));
        set_block(p, 0, j, &m0j);
        set_block(p, j, 0, &m0j.transpose());
    }
    add_scaled_identity(
        p,
        0,
        0,
        n.gyroscope_noise_density * n.gyroscope_noise_density * dt,
    );
    add_scaled_identity(p, 1, 1, q_bg);
    add_scaled_identity(p, 2, 2, q_ba);
    floor_growth(p, &before);
    floor_attitude(p);
    cap_attitude(p);
    *attitude = next;
    Ok(())
}

impl<T: Real> Sealed<T, 15> for InsState<T> {
    fn propagate(
        &mut self,
        p: &mut SMatrix<T, 15, 15>,
        imu: &ImuSample<T>,
        config: &FilterConfig<T>,
    ) -> Result<(), EskfError> {
        predict_ins(self, p, imu, config)
    }
}

impl<T: Real> Sealed<T, 6> for AhrsState<T> {
    fn propagate(
        &mut self,
        p: &mut SMatrix<T, 6, 6>,
        imu: &ImuSample<T>,
        config: &FilterConfig<T>,
    ) -> Result<(), EskfError> {
        predict_attitude(&mut self.attitude, &self.gyro_bias, p, imu, config)
    }
}

impl<T: Real> Sealed<T, 12> for AhrsAccelBiasState<T> {
    fn propagate(
        &mut self,
        p: &mut SMatrix<T, 12, 12>,
        imu: &ImuSample<T>,
        config: &FilterConfig<T>,
    ) -> Result<(), EskfError> {
        predict_attitude(&mut self.attitude, &self.gyro_bias, p, imu, config)
    }
}

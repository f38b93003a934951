//! Steps 3–4 of the [update](super): the posterior covariance `P − W Wᵀ`, the injection
//! `x⁺ = x̂ ⊕ δx` and the covariance reset.

use super::work::{attitude_part, Work};
use crate::eskf::covariance::attitude_floor;
use crate::eskf::error::EskfError;
use crate::eskf::state::ErrorState;
use crate::kernels::block::{block, copy};
use crate::kernels::{mat3, positive_variance};
use crate::lie::{LieGroup, So3};
use crate::Real;
use nalgebra::{Matrix3, SMatrix, Vector3};

/// The posterior covariance, injection and reset; writes `x` and `P` only when every check
/// passed.
///
/// With the optimal gain the Joseph form `P⁺ = (I − KH)P(I − KH)ᵀ + K R Kᵀ` is
/// `P − U S⁻¹ Uᵀ = P − W Wᵀ = P − Σ_c w_c w_cᵀ` (`U = P Hᵀ`, `W = U L⁻ᵀ`, [`super::gain`]):
/// `m` symmetric rank-one downdates, exactly symmetric, computed in place on the upper
/// triangle and mirrored, without an `N × N` temporary. `(W Wᵀ)_jj ≤ P_jj`, so no term is
/// larger than `P` and the rounding stays a few `ε √(P_ii P_jj)` per entry; the expanded
/// Joseph form `P + V Kᵀ + K Vᵀ` (`V = ½ K S − U`) has terms that grow with the condition of
/// `S`, and left `P` indefinite where two rows of `H` were nearly parallel. Then
/// `P⁺ ← G P⁺ Gᵀ`, `G = blockdiag(J_r(δθ), I)`: only the attitude rows and columns change. The
/// new attitude block gets its floor ([`attitude_floor`]). A correction with `|δθ| ≥ π` is
/// refused: there `exp` is no longer one-to-one and `J_r(δθ)` approaches singularity (at `2π`).
#[inline(never)]
pub(super) fn commit<T, S, const N: usize, const C: usize>(
    x: &mut S,
    p: &mut SMatrix<T, N, N>,
    w: &mut Work<T, N, C>,
) -> Result<(), EskfError>
where
    T: Real,
    S: ErrorState<T, N>,
{
    let new_x = x.oplus(&w.dx);
    let half = T::lit(0.5);
    let wcols = &w.g.w.data.0;
    // The checks, before anything is written. W and P are finite, so P⁺ can only fail by
    // overflow or by rounding below zero; for a positive semi-definite P⁺,
    // |P⁺_ij| ≤ √(P⁺_ii P⁺_jj), so a finite positive diagonal bounds every entry. From row 3
    // on, P⁺_jj = P_jj − Σ_c w_cj² (the reset leaves it); the attitude block is G₀ M G₀ᵀ,
    // M = P₀₀ − Σ_c (w_c w_cᵀ)₀₀, G₀ = J_r(δθ), made exactly symmetric.
    let mut m00 = block(p, 0, 0);
    for wc in wcols.iter() {
        let a = attitude_part(wc);
        m00 -= a * a.transpose();
    }
    let dtheta = attitude_part(w.dx.as_slice());
    let turn_squared = dtheta.dot(&dtheta);
    let (attitude_reset, other_reset) = reset_floors::<T, N>(turn_squared, &m00);
    let diagonal_ok = p.data.0.iter().enumerate().skip(3).all(|(j, pc)| {
        let d = wcols
            .iter()
            .fold(T::zero(), |acc, wc| acc + at(wc, j) * at(wc, j));
        let v = at(pc, j) - d;
        positive_variance(v + v * other_reset)
    });
    let gr: Matrix3<T> = So3::right_jacobian(&dtheta);
    let c00 = mat3::mul(&mat3::mul(&gr, &m00), &gr.transpose());
    let c00 = (c00 + c00.transpose()) * half;
    let c00 = c00 + Matrix3::from_diagonal_element(attitude_floor(&c00) + attitude_reset);
    let diagonal_ok = diagonal_ok && positive_variance(c00.m11) && positive_variance(c00.m22);
    // The correction stays inside the chart: below π the exponential map is one-to-one and
    // J_r(δθ) regular; at 2π it is singular, and the reset G P Gᵀ with it is not definite.
    let in_chart = turn_squared < T::pi() * T::pi();
    if !(in_chart && new_x.is_finite() && diagonal_ok && positive_variance(c00.m33)) {
        return Err(EskfError::NumericalFailure);
    }
    // The upper triangle (column j holds rows 0..=j): P_ij −= Σ_c w_ci w_cj; then the attitude
    // rows of the columns from 3 on multiplied by J_r(δθ), the attitude block replaced by
    // `c00`, and the upper triangle mirrored below.
    let cols = &mut p.data.0;
    downdate_upper(cols, wcols);
    for (j, pc) in cols.iter_mut().enumerate().skip(3) {
        if let Some(v) = pc.get_mut(j) {
            *v += *v * other_reset;
        }
    }
    for (pc, c) in cols.iter_mut().zip(c00.data.0.iter()) {
        if let Some(head) = pc.get_mut(0..3) {
            copy(head, c);
        }
    }
    for pc in cols.iter_mut().skip(3) {
        if let Some(head) = pc.first_chunk_mut::<3>() {
            *head = mat3::mul_vec(&gr, &Vector3::from(*head)).into();
        }
    }
    for j in 1..N {
        let Some((left, right)) = cols.split_at_mut_checked(j) else {
            break;
        };
        let Some(col_j) = right.first() else {
            break;
        };
        for (col_i, upper) in left.iter_mut().zip(col_j.iter()) {
            if let Some(e) = col_i.get_mut(j) {
                *e = *upper;
            }
        }
    }
    *x = new_x;
    Ok(())
}

/// The reset's floors `(8 N ε φ tr M, 16 ε φ)`, `φ = |δθ|`, `M` the attitude block before the
/// reset: the first is added to each attitude variance, the second times each other variance
/// to it ([`RESET_FLOOR_ATTITUDE`], [`RESET_FLOOR_OTHER`]).
///
/// The reset multiplies the attitude rows by `J_r(δθ) = I − α [δθ]× + β [δθ]×²`
/// (`α = (1 − cos φ)/φ²`, `β = (φ − sin φ)/φ³`), so `J_r = I + D` with
/// `|D_ik| ≤ φ/2 + φ²/6 ≤ 1.03 φ` for `φ < π`. It mixes the attitude rows: the product
/// `Σ_k J_ik P_kj` rounds by up to `3 ε Σ_k |J_ik| |P_kj|`, and beyond the row's own term
/// (a few `ε` of the row, as any step) that is `e_ij ≤ 3 ε · 1.03 φ Σ_{k≠i} √(P_kk P_jj) ≤
/// 4.4 ε φ √(tr M · P_jj)`. A large row rotated into a small one (a heading of σ = π turned by
/// a correction into a tilt of σ = 10⁻⁶ rad, its cross-covariance with a gyro bias of
/// σ = 10²⁹ rad/s coming along) brings that rounding with it, far above the small row's own
/// resolution. Each cross term is bounded by `2 |e_ij x_i x_j| ≤ e_ij (τ x_i² + x_j²/τ)`,
/// `τ = √(tr M / P_jj)`: over the `3 (N − 3)` pairs this is a diagonal of `4.4 (N − 3) ε φ tr M`
/// on each attitude variance and `13 ε φ P_jj` on each other, which the floors cover with a
/// margin (and the `3 × 3` block's own mixing with it). In `f32` a correction of 1 mrad with an
/// attitude trace of `3·10⁻⁴` adds `3·10⁻¹²` rad²; the floors act only on large corrections.
#[inline(always)]
fn reset_floors<T: Real, const N: usize>(turn_squared: T, m: &Matrix3<T>) -> (T, T) {
    let phi = turn_squared.max(T::zero()).sqrt_rn();
    let trace = (m.m11 + m.m22 + m.m33).max(T::zero());
    let attitude = T::lit(RESET_FLOOR_ATTITUDE * N as f64 * T::EPSILON_F64) * phi * trace;
    let other = T::lit(RESET_FLOOR_OTHER * T::EPSILON_F64) * phi;
    (attitude, other)
}

/// The reset floor on each attitude variance, `8 N ε φ tr M` ([`reset_floors`]).
const RESET_FLOOR_ATTITUDE: f64 = 8.0;

/// The reset floor on each other variance, `16 ε φ P_jj` ([`reset_floors`]).
const RESET_FLOOR_OTHER: f64 = 16.0;

/// `P_ij −= Σ_c w_ci w_cj` on the upper triangle (`i ≤ j`) of the columns `cols`, over all `C`
/// columns of `w` (those past the active rows are zero and take nothing). Each column of `P` is
/// swept once with its `C` entries `w_cj` in registers: with `C` a constant the sum over `c`
/// unrolls. A model with fewer rows pays for the zero columns so that one copy serves every
/// row count.
#[inline(always)]
fn downdate_upper<T: Real, const N: usize, const C: usize>(
    cols: &mut [[T; N]; N],
    w: &[[T; N]; C],
) {
    for (j, pc) in cols.iter_mut().enumerate() {
        let mut wj = [T::zero(); C];
        for (a, wc) in wj.iter_mut().zip(w) {
            *a = at(wc, j);
        }
        for (i, e) in pc.iter_mut().enumerate().take(j + 1) {
            let mut acc = *e;
            for (wc, a) in w.iter().zip(wj.iter()) {
                acc -= at(wc, i) * *a;
            }
            *e = acc;
        }
    }
}

/// `s[i]`, or zero past the end (never reached: every caller indexes below the length).
#[inline(always)]
fn at<T: Real>(s: &[T], i: usize) -> T {
    s.get(i).copied().unwrap_or_else(T::zero)
}

#[cfg(test)]
mod tests {
    use crate::eskf::update::update;
    use crate::eskf::{AhrsAccelBiasState, Gate, Magnetometer, UpdateOptions, UpdateOutcome};
    use crate::lie::So3;
    use nalgebra::{Matrix3, Quaternion, SMatrix, Vector3};

    /// A fuzzing finding: an attitude at its cap (σ = π) about two axes, a tilt of σ = 2.5 μrad
    /// about the third, correlated with a gyro bias of σ = 2.4·10²⁹ rad/s; a magnetometer
    /// update turns the estimate by about 0.02 rad about the first axis, and its reset rotates
    /// a capped row into the small one. Without the reset's floors the smallest eigenvalue of
    /// the correlation matrix went from 6.4e-14 to −3.3e-16.
    #[test]
    fn reset_of_a_turning_correction_keeps_covariance_positive_definite() {
        #[rustfmt::skip]
        let p9: [f64; 81] = [
            9.869604401089358, 2.2295544065344304e-19, -1.4928154090486902e-9, -7.6969020012945e29, -4081956728395546.0, 1.154535300283212e20, 0.0, 0.0, 0.0,
            2.2295544065344304e-19, 9.869604401089358, 1.492815408822072e-9, 4081922244754491.5, -7.6969020012945e29, -1.1545353001036484e20, 0.0, 0.0, 0.0,
            -1.4928154090486902e-9, 1.492815408822072e-9, 6.314225676018066e-12, 1.1641858622219449e20, -1.1641858620452019e20, -4.924207114946038e17, 0.0, 0.0, 0.0,
            -7.6969020012945e29, 4081922244754491.5, 1.1641858622219449e20, 6.002500000000001e58, 1.3332672440009973e39, -9.003750000694461e48, 0.0, 0.0, 0.0,
            -4081956728395546.0, -7.6969020012945e29, -1.1641858620452019e20, 1.3332672440009973e39, 6.002500000000001e58, 9.003749999294023e48, 0.0, 0.0, 0.0,
            1.154535300283212e20, -1.1545353001036484e20, -4.924207114946038e17, -9.003750000694461e48, 9.003749999294023e48, 3.8401883231869424e46, 0.0, 0.0, 0.0,
            0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.00813766360325104, 0.0, 0.0,
            0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.00813766360325104, 0.0,
            0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.00813766360325104,
        ];
        // The finding's 9 × 9 P (attitude and both biases), the velocity apart from it.
        let mut p = SMatrix::<f64, 12, 12>::identity();
        p.fixed_view_mut::<9, 9>(0, 0)
            .copy_from(&SMatrix::<f64, 9, 9>::from_column_slice(&p9));
        assert!(p.cholesky().is_some(), "the prior is positive definite");
        let q = Quaternion::new(
            1.0,
            -1.512538241933422e-10,
            -1.5125382419259642e-10,
            -1.4999469664614946e-10,
        );
        let mut x = AhrsAccelBiasState {
            attitude: So3::from_quaternion(&q).expect("unit quaternion"),
            gyro_bias: Vector3::new(
                1.9556127174640166e17,
                1.9556127168894973e17,
                -827173880672355.0,
            ),
            accel_bias: Vector3::zeros(),
            velocity: Vector3::zeros(),
        };
        let model = Magnetometer {
            field: Vector3::new(
                -0.04196078431372549,
                0.07522850385290303,
                9.016556038757906e-5,
            ),
            reference: Vector3::new(-0.75, 0.0008787670710307461, -29.25),
            noise: Matrix3::from_diagonal(&Vector3::new(
                855.5625,
                857003.0663531731,
                929264.1059545241,
            )),
        };
        let options = UpdateOptions::iterated(Gate::Off, 2, 0.8506446936751355);
        let outcome = update(&mut x, &mut p, &model, &options);
        assert!(
            matches!(outcome, Ok(UpdateOutcome::Accepted { .. })),
            "{outcome:?}"
        );
        assert!(
            p.cholesky().is_some(),
            "posterior not positive definite: {:?}",
            p.diagonal()
        );
    }
}

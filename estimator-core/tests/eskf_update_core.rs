//! The shared update core against the textbook update, written densely here.
//!
//! Measurements with up to three rows go through one core padded to three rows (zero rows in
//! `H` and `r`, identity in `R`); larger ones through a core of their own size. Both must give
//! exactly what the dense formulas give: `S = H P Hᵀ + R`, `NIS = rᵀ S⁻¹ r`,
//! `K = P Hᵀ S⁻¹`, `δx = K r`, `P_J = (I − KH) P (I − KH)ᵀ + K R Kᵀ`, `x⁺ = x ⊕ δx`,
//! `P⁺ = G P_J Gᵀ` with `G = blockdiag(J_r(δθ), I)`. The test models return a fixed `(r, H)`
//! with every column of `H` used and a correlated `P` and `R`, so every block of the core (and
//! every padded row) is exercised.

mod eskf_common;
mod support;

use eskf_common::Rng;
use estimator_core::eskf::*;
use estimator_core::lie::{LieGroup, So3};
use nalgebra::{SMatrix, SVector, Vector3};

/// A matrix of uniform entries in `[-scale, scale)`.
fn matrix<const R: usize, const C: usize>(rng: &mut Rng, scale: f64) -> SMatrix<f64, R, C> {
    SMatrix::from_fn(|_, _| (2.0 * rng.uniform() - 1.0) * scale)
}

/// `A Aᵀ + d I`: symmetric positive definite with correlated entries.
fn spd<const D: usize>(rng: &mut Rng, scale: f64, d: f64) -> SMatrix<f64, D, D> {
    let a = matrix::<D, D>(rng, scale);
    a * a.transpose() + SMatrix::identity() * d
}

/// A measurement that returns a fixed residual and Jacobian (the update uses nothing else of
/// the model for a single, non-iterated step).
struct Fixed<const N: usize, const M: usize> {
    r: SVector<f64, M>,
    h: SMatrix<f64, M, N>,
    noise: SMatrix<f64, M, M>,
}

impl<S, const N: usize, const M: usize> Measurement<f64, S, N, M> for Fixed<N, M> {
    fn linearize(&self, _x: &S) -> Result<Linearization<f64, N, M>, EskfError> {
        Ok(Linearization {
            residual: self.r,
            jacobian: self.h,
        })
    }

    fn noise(&self) -> SMatrix<f64, M, M> {
        self.noise
    }
}

/// The dense textbook update: `(NIS, δx, P⁺)` (see the module docs).
fn textbook<const N: usize, const M: usize>(
    p: &SMatrix<f64, N, N>,
    m: &Fixed<N, M>,
) -> (f64, SVector<f64, N>, SMatrix<f64, N, N>) {
    let s = m.h * p * m.h.transpose() + m.noise;
    let s_inv = s.try_inverse().expect("S invertible");
    let nis = (m.r.transpose() * s_inv * m.r).x;
    let k = p * m.h.transpose() * s_inv;
    let dx = k * m.r;
    let a = SMatrix::<f64, N, N>::identity() - k * m.h;
    let pj = a * p * a.transpose() + k * m.noise * k.transpose();
    let mut g = SMatrix::<f64, N, N>::identity();
    let jr = So3::right_jacobian(&Vector3::new(dx[0], dx[1], dx[2]));
    g.fixed_view_mut::<3, 3>(0, 0).copy_from(&jr);
    (nis, dx, g * pj * g.transpose())
}

fn model<const N: usize, const M: usize>(rng: &mut Rng) -> Fixed<N, M> {
    Fixed {
        r: matrix::<M, 1>(rng, 0.2),
        h: matrix::<M, N>(rng, 1.0),
        noise: spd::<M>(rng, 0.1, 0.05),
    }
}

fn ins_with(p: SMatrix<f64, 15, 15>) -> Ins<f64> {
    let state = InsState {
        attitude: So3::exp(&Vector3::new(0.3, -0.2, 1.1)),
        velocity: Vector3::new(1.0, -2.0, 0.5),
        position: Vector3::new(10.0, 20.0, -3.0),
        gyro_bias: Vector3::new(0.01, 0.0, -0.02),
        accel_bias: Vector3::new(0.1, 0.05, 0.0),
    };
    Ins::new(state, p, FilterConfig::default()).expect("valid start")
}

/// Updates `Ins<f64>` with a random `M`-row model and compares with [`textbook`].
fn check_ins<const M: usize>(seed: u64) {
    let mut rng = Rng::new(seed);
    let p = spd::<15>(&mut rng, 0.1, 0.01);
    let m = model::<15, M>(&mut rng);
    let mut f = ins_with(p);
    let x0 = *f.state();
    let out = f
        .update(&m, &UpdateOptions::ekf(Gate::Off))
        .expect("update");
    let (nis, dx, p_ref) = textbook(&p, &m);
    assert!(out.is_accepted(), "M = {M}: {out:?}");
    assert!(
        (out.nis() - nis).abs() <= 1e-12 * nis.max(1.0),
        "M = {M} NIS"
    );
    let x_ref = x0.oplus(&dx);
    let x = f.state();
    let err = (x.velocity - x_ref.velocity).amax()
        + (x.position - x_ref.position).amax()
        + (x.gyro_bias - x_ref.gyro_bias).amax()
        + (x.accel_bias - x_ref.accel_bias).amax()
        + (x.attitude.rotation_matrix() - x_ref.attitude.rotation_matrix()).amax();
    assert!(err <= 1e-12, "M = {M}: state differs by {err:e}");
    let perr = (f.covariance() - p_ref).amax();
    assert!(
        perr <= 1e-12 * p_ref.amax(),
        "M = {M}: P differs by {perr:e}"
    );
    assert_eq!(*f.covariance(), f.covariance().transpose(), "P⁺ symmetric");
}

#[test]
fn ins_update_equals_the_dense_textbook_update_for_every_row_count() {
    for seed in 1..=8 {
        check_ins::<1>(seed);
        check_ins::<2>(seed);
        check_ins::<3>(seed); // the padded core at full capacity
        check_ins::<4>(seed); // past the capacity: a core of its own size
        check_ins::<6>(seed);
    }
}

#[test]
fn ahrs_update_equals_the_dense_textbook_update() {
    fn check<const M: usize>(seed: u64) {
        let mut rng = Rng::new(seed);
        let p = spd::<6>(&mut rng, 0.1, 0.01);
        let m = model::<6, M>(&mut rng);
        let x0 = AhrsState {
            attitude: So3::exp(&Vector3::new(-0.4, 0.2, 2.0)),
            gyro_bias: Vector3::new(0.01, -0.01, 0.0),
        };
        let mut f = Ahrs::new(x0, p, FilterConfig::default()).expect("valid start");
        let out = f
            .update(&m, &UpdateOptions::ekf(Gate::Off))
            .expect("update");
        let (nis, dx, p_ref) = textbook(&p, &m);
        assert!(
            (out.nis() - nis).abs() <= 1e-12 * nis.max(1.0),
            "M = {M} NIS"
        );
        let x_ref = x0.oplus(&dx);
        let err = (f.state().attitude.rotation_matrix() - x_ref.attitude.rotation_matrix()).amax()
            + (f.state().gyro_bias - x_ref.gyro_bias).amax();
        assert!(err <= 1e-12, "M = {M}: state differs by {err:e}");
        let perr = (f.covariance() - p_ref).amax();
        assert!(
            perr <= 1e-12 * p_ref.amax(),
            "M = {M}: P differs by {perr:e}"
        );
    }
    for seed in 11..=18 {
        check::<1>(seed);
        check::<3>(seed);
        check::<5>(seed);
    }
}

#[test]
fn the_gate_uses_the_model_dimension_not_the_core_capacity() {
    // A residual far outside: NIS ≫ any threshold; the reported threshold is χ²_M(0.99).
    fn threshold<const M: usize>() -> f64 {
        let mut rng = Rng::new(99);
        let mut m = model::<15, M>(&mut rng);
        m.r = SVector::repeat(1e3);
        let mut f = ins_with(spd::<15>(&mut rng, 0.1, 0.01));
        let before = f;
        let out = f
            .update(
                &m,
                &UpdateOptions::ekf(Gate::Probability(GateProbability::P99)),
            )
            .expect("update");
        assert_eq!(f, before, "a rejected update leaves the filter unchanged");
        match out {
            UpdateOutcome::Rejected { threshold, .. } => threshold,
            other => panic!("M = {M}: expected a rejection, got {other:?}"),
        }
    }
    // χ²_M(0.99) quantiles to the table's accuracy.
    let expected = [(6.635, threshold::<1>()), (9.210, threshold::<2>())];
    let more = [(11.345, threshold::<3>()), (16.812, threshold::<6>())];
    for (want, got) in expected.iter().chain(more.iter()) {
        assert!(
            (got - want).abs() < 0.01 * want,
            "threshold {got} vs χ² {want}"
        );
    }
}

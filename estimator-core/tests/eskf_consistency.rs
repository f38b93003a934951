//! Filter consistency: NEES of the 15-state filter over many seeds against chi-square bounds.
//!
//! Each run starts from the truth displaced by a draw from the initial covariance `P₀` (so the
//! initial error really is `N(0, P₀)`), then 30 s of hand-held motion at 200 Hz with GNSS 1 m at
//! 5 Hz and a magnetometer at 50 Hz, generated with exactly the filter's noise model. At each
//! snapshot the mean NEES over `R` runs, times `R`, is chi-square with `15R` dof if the filter
//! is consistent: it must lie in the two-sided 99.9 % band (Wilson–Hilferty quantiles). The same
//! for the AHRS (6 dof) and for the time-averaged NIS of the GNSS updates (3 dof).

mod eskf_common;
mod support;

use eskf_common::*;
use estimator_core::eskf::*;
use estimator_core::lie::LieGroup;
use nalgebra::{SMatrix, SVector, Vector3};
use support::{chi2_quantile, nees};

const RUNS: usize = 30;
const DT: f64 = 0.005;
const SNAP_EVERY: usize = 1000; // 5 s
const STEPS: usize = 6000; // 30 s

fn p0() -> SMatrix<f64, 15, 15> {
    let s = [
        0.02, 0.02, 0.05, 0.05, 0.05, 0.05, 1.0, 1.0, 1.0, 0.003, 0.003, 0.003, 0.02, 0.02, 0.02,
    ];
    SMatrix::from_diagonal(&SVector::from_fn(|i, _| s[i] * s[i]))
}

fn band(dof: f64) -> (f64, f64) {
    (chi2_quantile(dof, -3.29), chi2_quantile(dof, 3.29))
}

#[test]
fn ins_nees_and_nis_within_chi_square_bounds() {
    let snaps = STEPS / SNAP_EVERY;
    let mut nees_sum = vec![0.0; snaps];
    let (mut nis_sum, mut nis_n) = (0.0, 0usize);
    for seed in 0..RUNS as u64 {
        let mut sim = Sim::new(100 + seed, DT, Motion::hand_held(0.0), ImuNoise::mems());
        let p = p0();
        let start = sim.truth.oplus(&(-sim.rng.gaussian(&p)));
        let mut f = Ins::new(start, p, FilterConfig::default()).expect("filter");
        let opts = UpdateOptions::ekf(Gate::Off);
        for k in 1..=STEPS {
            let s = sim.step();
            f.predict(&s).expect("predict");
            if k % 4 == 0 {
                let m = sim.mag(0.5);
                f.update(&Magnetometer::new(m, mag_reference(), 0.5), &opts)
                    .expect("mag");
            }
            if k % 40 == 0 {
                let z = sim.gnss(1.0);
                let out = f
                    .update(&GnssPosition::new(z, Vector3::zeros(), 1.0), &opts)
                    .expect("gnss");
                nis_sum += out.nis();
                nis_n += 1;
            }
            if k % SNAP_EVERY == 0 {
                let e = ins_error(&sim.truth, f.state());
                nees_sum[k / SNAP_EVERY - 1] += nees(&e, f.covariance());
            }
        }
    }
    let r = RUNS as f64;
    let (lo, hi) = band(15.0 * r);
    for (i, s) in nees_sum.iter().enumerate() {
        println!(
            "INS t = {:>2} s: mean NEES {:.2} (band [{:.2}, {:.2}], dof 15)",
            (i + 1) * SNAP_EVERY / 200,
            s / r,
            lo / r,
            hi / r
        );
        assert!(*s >= lo && *s <= hi, "NEES {} outside band", s / r);
    }
    let nis_mean = nis_sum / nis_n as f64;
    let (lo, hi) = band(3.0 * nis_n as f64);
    println!(
        "GNSS NIS mean {:.3} over {nis_n} updates (band [{:.3}, {:.3}])",
        nis_mean,
        lo / nis_n as f64,
        hi / nis_n as f64
    );
    assert!(nis_sum >= lo && nis_sum <= hi);
}

#[test]
fn ahrs_nees_within_chi_square_bounds() {
    let snaps = STEPS / SNAP_EVERY;
    let mut nees_sum = vec![0.0; snaps];
    let p0 = SMatrix::<f64, 6, 6>::from_diagonal(&SVector::from([
        0.03f64.powi(2),
        0.03f64.powi(2),
        0.05f64.powi(2),
        0.01f64.powi(2),
        0.01f64.powi(2),
        0.01f64.powi(2),
    ]));
    for seed in 0..RUNS as u64 {
        let mut sim = Sim::new(500 + seed, DT, Motion::hand_held(0.0), ImuNoise::mems());
        let truth = AhrsState {
            attitude: sim.truth.attitude,
            gyro_bias: sim.truth.gyro_bias,
        };
        let start = truth.oplus(&(-sim.rng.gaussian(&p0)));
        let mut f = Ahrs::new(start, p0, FilterConfig::default()).expect("filter");
        let opts = UpdateOptions::ekf(Gate::Off);
        for k in 1..=STEPS {
            let s = sim.step();
            f.predict(&s).expect("predict");
            if k % 4 == 0 {
                let m = sim.mag(0.5);
                f.update(&Magnetometer::new(m, mag_reference(), 0.5), &opts)
                    .expect("mag");
            }
            if k % SNAP_EVERY == 0 {
                let t = &sim.truth;
                let mut e = SVector::<f64, 6>::zeros();
                e.fixed_rows_mut::<3>(0)
                    .copy_from(&t.attitude.rminus(&f.state().attitude));
                e.fixed_rows_mut::<3>(3)
                    .copy_from(&(t.gyro_bias - f.state().gyro_bias));
                nees_sum[k / SNAP_EVERY - 1] += nees(&e, f.covariance());
            }
        }
    }
    let r = RUNS as f64;
    let (lo, hi) = band(6.0 * r);
    for (i, s) in nees_sum.iter().enumerate() {
        println!(
            "AHRS snapshot {i}: mean NEES {:.2} (band [{:.2}, {:.2}], dof 6)",
            s / r,
            lo / r,
            hi / r
        );
        assert!(*s >= lo && *s <= hi, "NEES {} outside band", s / r);
    }
}

//! 10⁶ IMU steps at 1 kHz in f32 with periodic GNSS, magnetometer and barometer updates: the
//! covariance stays symmetric positive definite, the quaternion normalized, every value finite,
//! and the errors stay small. Ignored by default; CI runs it in release:
//! `cargo test --release -p estimator-core --test eskf_long_run -- --ignored`.

mod eskf_common;
mod support;

use eskf_common::*;
use estimator_core::eskf::*;
use nalgebra::{Cholesky, SMatrix, Vector3};

#[test]
#[ignore = "10⁶ steps: run in release with --ignored"]
fn long_run_f32_million_steps() {
    let dt = 0.001;
    let mut sim = Sim::new(2024, dt, Motion::hand_held(0.0), ImuNoise::mems());
    let p0 = SMatrix::<f32, 15, 15>::from_diagonal(&nalgebra::SVector::from([
        1e-3, 1e-3, 1e-3, 1e-2, 1e-2, 1e-2, 1.0, 1.0, 1.0, 1e-5, 1e-5, 1e-5, 4e-4, 4e-4, 4e-4,
    ]));
    let mut f = Ins::new(
        {
            let mut s = ins_state_f32(&sim.truth);
            s.gyro_bias = Vector3::zeros();
            s.accel_bias = Vector3::zeros();
            s
        },
        p0,
        FilterConfig::default(),
    )
    .expect("filter");
    let opts = UpdateOptions::default();
    let (mut accepted, mut rejected) = (0usize, 0usize);
    let mut worst_q = 0.0f32;
    let mut worst_att = 0.0f64;
    let mut worst_pos = 0.0f64;
    let mut count = |o: UpdateOutcome<f32>| {
        if o.is_accepted() {
            accepted += 1;
        } else {
            rejected += 1;
        }
    };
    for k in 1..=1_000_000usize {
        let s = sim.step();
        f.predict(&cast_imu(&s)).expect("predict");
        if k % 20 == 0 {
            let m = sim.mag(0.5);
            count(
                f.update(
                    &Magnetometer::new(cast3(&m), cast3(&mag_reference()), 0.5),
                    &opts,
                )
                .expect("mag"),
            );
        }
        if k % 100 == 0 {
            let h = sim.truth.position.z + 0.3 * sim.rng.normal();
            count(
                f.update(&BaroAltitude::new(h as f32, 0.3), &opts)
                    .expect("baro"),
            );
        }
        if k % 200 == 0 {
            let z = sim.gnss(1.0);
            count(
                f.update(&GnssPosition::new(cast3(&z), Vector3::zeros(), 1.0), &opts)
                    .expect("gnss"),
            );
        }
        if k % 1000 == 0 {
            let p = f.covariance();
            assert!(p.iter().all(|x| x.is_finite()), "non-finite P at {k}");
            assert_eq!(*p, p.transpose(), "asymmetric P at {k}");
            assert!(
                Cholesky::new(*p).is_some(),
                "P not positive definite (f32) at {k}"
            );
            assert!(Cholesky::new(to_f64_mat(p)).is_some(), "P not PD at {k}");
            let q = f.state().attitude.quaternion();
            let qn = (q.coords.norm() - 1.0).abs();
            worst_q = worst_q.max(qn);
            assert!(qn < 1e-5, "quaternion norm off by {qn} at {k}");
            let est = ins_state_f64(f.state());
            let e = ins_error(&sim.truth, &est);
            assert!(e.iter().all(|x| x.is_finite()));
            if k > 60_000 {
                worst_att = worst_att.max(e.fixed_rows::<3>(0).norm().to_degrees());
                worst_pos = worst_pos.max(e.fixed_rows::<3>(6).norm());
            }
        }
    }
    println!(
        "long run: {accepted} accepted, {rejected} rejected, worst |‖q‖−1| {worst_q:e}, worst attitude error after 60 s {worst_att:.3}°, worst position error {worst_pos:.3} m"
    );
    assert!(worst_att < 3.0 && worst_pos < 4.0);
    assert!(rejected * 100 < accepted);
}

fn ins_state_f32(s: &InsState<f64>) -> InsState<f32> {
    InsState {
        attitude: s.attitude.cast::<f32>(),
        velocity: cast3(&s.velocity),
        position: cast3(&s.position),
        gyro_bias: cast3(&s.gyro_bias),
        accel_bias: cast3(&s.accel_bias),
    }
}

//! The attitude navigator over a simulated dataset, sample by sample, scored against its truth:
//! shared by the tests of what it learns online (hard iron, magnetometer delay).

use estimator_core::eskf::FilterConfig;
use estimator_core::lie::So3;
use estimator_core::nav::{AttitudeConfig, AttitudeNavigator, MagneticConfig};
use host_sim::dataset::read::{Dataset, Event, TruthStream};
use nalgebra::Vector3;
use std::path::Path;

/// The navigator as host-sim's replay sets it up for its simulator (f32, instantaneous samples;
/// the dataset's magnetometer, its configuration then passed to `magnetic`), driven over the
/// dataset at `ds`. Returns the navigator after the last sample and the RMSE, degrees, of
/// `error(truth, estimate)` (rad) over the IMU samples at least `from_s` after the first that
/// have a truth row at their stamp.
pub fn drive(
    ds: &Path,
    magnetic: impl FnOnce(&mut MagneticConfig<f32>),
    from_s: f64,
    error: impl Fn(&So3<f64>, &So3<f64>) -> f64,
) -> (AttitudeNavigator<f32>, f64) {
    let data = Dataset::open(ds).expect("dataset");
    let mag = data.mag.as_ref().expect("a magnetometer");
    let mut config = AttitudeConfig::<f32>::new(FilterConfig::default());
    config.instantaneous_imu = true;
    let r = mag.reference_field;
    let mut mc = MagneticConfig::new(
        mag.sigma as f32,
        Some(Vector3::new(r.x as f32, r.y as f32, r.z as f32)),
    );
    magnetic(&mut mc);
    config.magnetometer = Some(mc);
    let mut nav = AttitudeNavigator::new(config).expect("navigator");
    let f32v = |v: &Vector3<f64>| Vector3::new(v.x as f32, v.y as f32, v.z as f32);
    let mut truth = TruthStream::open(ds).expect("truth");
    let mut row = truth.next_truth().expect("truth row");
    let (mut sum_sq, mut count) = (0.0, 0u32);
    let mut first: Option<u64> = None;
    let from_ns = (from_s * 1e9) as u64;
    for ev in data.events().expect("events") {
        match ev.expect("event") {
            Event::Imu { t_ns, gyro, accel } => {
                let _ = nav.imu(t_ns, &f32v(&gyro), &f32v(&accel));
                while row.as_ref().is_some_and(|r| r.t_ns < t_ns) {
                    row = truth.next_truth().expect("truth row");
                }
                let t0 = *first.get_or_insert(t_ns);
                let late = t_ns >= t0 + from_ns;
                if let (Some(r), Some(e), true) = (row.as_ref(), nav.estimate(), late) {
                    if r.t_ns == t_ns {
                        let q = e.attitude.quaternion();
                        let est = So3::<f64>::from_wxyz(
                            f64::from(q.w),
                            f64::from(q.i),
                            f64::from(q.j),
                            f64::from(q.k),
                        )
                        .expect("unit quaternion");
                        let err = error(&r.attitude, &est);
                        sum_sq += err * err;
                        count += 1;
                    }
                }
            }
            Event::Mag { t_ns, field } => {
                let _ = nav.magnetometer(t_ns, &f32v(&field));
            }
            _ => {}
        }
    }
    assert!(count > 0);
    (nav, (sum_sq / f64::from(count)).sqrt().to_degrees())
}

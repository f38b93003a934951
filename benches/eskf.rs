//! Criterion benchmarks of the error-state filter: ns per predict and per update of each model,
//! f32 and f64. Update benchmarks start each iteration from a copy of the same filter (the copy,
//! ~1 KB for the 15-state f32 filter, is included in the time).

use criterion::{criterion_group, criterion_main, Criterion};
use estimator_core::eskf::*;
use estimator_core::lie::{LieGroup, Se3, So3};
use estimator_core::Real;
use nalgebra::{SMatrix, Vector2, Vector3};
use std::hint::black_box;

fn v<T: Real>(x: f64, y: f64, z: f64) -> Vector3<T> {
    Vector3::new(T::lit(x), T::lit(y), T::lit(z))
}

fn ins<T: Real>() -> Ins<T> {
    let s = InsState {
        attitude: So3::exp(&v(0.1, -0.2, 0.7)),
        velocity: v(0.5, 0.1, 0.0),
        position: v(1.0, 2.0, 3.0),
        gyro_bias: v(0.001, 0.0, -0.001),
        accel_bias: v(0.01, 0.0, 0.0),
    };
    let mut p = SMatrix::<T, 15, 15>::identity() * T::lit(0.01);
    p[(0, 3)] = T::lit(0.001);
    p[(3, 0)] = T::lit(0.001);
    Ins::new(s, p, FilterConfig::default()).expect("filter")
}

fn ahrs<T: Real>() -> Ahrs<T> {
    Ahrs::new(
        AhrsState {
            attitude: So3::exp(&v(0.1, -0.2, 0.7)),
            gyro_bias: v(0.001, 0.0, -0.001),
        },
        SMatrix::<T, 6, 6>::identity() * T::lit(0.01),
        FilterConfig::default(),
    )
    .expect("filter")
}

fn bench_update<T: Real, Mo, const M: usize>(
    c: &mut Criterion,
    name: &str,
    f0: &Ins<T>,
    model: &Mo,
    opts: &UpdateOptions<T>,
) where
    Mo: Measurement<T, InsState<T>, 15, M>,
{
    c.bench_function(name, |b| {
        b.iter(|| {
            let mut f = *black_box(f0);
            let out = f.update(black_box(model), opts);
            black_box((f, out))
        })
    });
}

fn suite<T: Real>(c: &mut Criterion, tag: &str) {
    let imu = ImuSample {
        gyro: v::<T>(0.1, -0.05, 0.2),
        accel: v::<T>(0.2, 0.1, 9.8),
        dt: T::lit(0.005),
    };
    // Predict runs on one filter, restarted every 1000 steps so that P never grows far.
    let f_start = ins::<T>();
    let mut f = f_start;
    let mut n = 0u32;
    c.bench_function(&format!("eskf/{tag}/ins_predict"), |b| {
        b.iter(|| {
            n += 1;
            if n.is_multiple_of(1000) {
                f = f_start;
            }
            let r = f.predict(black_box(&imu));
            black_box(r)
        })
    });
    let a_start = ahrs::<T>();
    let mut a = a_start;
    let g = imu.gyro;
    c.bench_function(&format!("eskf/{tag}/ahrs_predict"), |b| {
        b.iter(|| {
            n += 1;
            if n.is_multiple_of(1000) {
                a = a_start;
            }
            let r = a.predict(black_box(&ImuSample {
                gyro: g,
                accel: Vector3::zeros(),
                dt: T::lit(0.005),
            }));
            black_box(r)
        })
    });

    let f0 = ins::<T>();
    let s = *f0.state();
    let ekf = UpdateOptions::<T>::ekf(Gate::Probability(GateProbability::P999));
    let z = s.position + v(0.3, -0.2, 0.1);
    bench_update(
        c,
        &format!("eskf/{tag}/gnss_position"),
        &f0,
        &GnssPosition::new(z, v(0.1, 0.0, 0.05), T::lit(1.0)),
        &ekf,
    );
    bench_update(
        c,
        &format!("eskf/{tag}/gnss_velocity"),
        &f0,
        &GnssVelocity::new(s.velocity + v(0.05, 0.0, 0.0), T::lit(0.1)),
        &ekf,
    );
    let mref = v::<T>(0.0, 22.0, -42.0);
    let mb = s.attitude.inverse().act(&mref) + v(0.3, -0.2, 0.1);
    bench_update(
        c,
        &format!("eskf/{tag}/magnetometer"),
        &f0,
        &Magnetometer::new(mb, mref, T::lit(0.5)),
        &ekf,
    );
    let up = s.attitude.inverse().act(&v(0.0, 0.0, 9.81));
    bench_update(
        c,
        &format!("eskf/{tag}/gravity"),
        &f0,
        &GravityDirection::new(up, T::lit(0.2)),
        &ekf,
    );
    bench_update(
        c,
        &format!("eskf/{tag}/baro"),
        &f0,
        &BaroAltitude::new(T::lit(3.2), T::lit(0.5)),
        &ekf,
    );
    bench_update(
        c,
        &format!("eskf/{tag}/zupt"),
        &f0,
        &ZeroVelocity::new(T::lit(0.5)),
        &ekf,
    );
    bench_update(
        c,
        &format!("eskf/{tag}/heading"),
        &f0,
        &Heading::new(T::lit(0.75), T::lit(0.05)),
        &ekf,
    );
    let k = PinholeIntrinsics {
        fx: T::lit(400.0),
        fy: T::lit(400.0),
        cx: T::lit(320.0),
        cy: T::lit(240.0),
    };
    let landmark = s.position + s.attitude.act(&v(0.05, -0.03, 0.3));
    let cam = CameraLandmark::new(
        Vector2::new(T::lit(390.0), T::lit(200.0)),
        landmark,
        k,
        Se3::identity(),
        T::lit(1.0),
    );
    bench_update(c, &format!("eskf/{tag}/camera_ekf"), &f0, &cam, &ekf);
    let iekf = UpdateOptions::<T>::iterated(Gate::Off, 5, T::lit(1e-5));
    bench_update(c, &format!("eskf/{tag}/camera_iekf5"), &f0, &cam, &iekf);

    let a0 = ahrs::<T>();
    let sa = *a0.state();
    let mb = sa.attitude.inverse().act(&mref) + v(0.3, -0.2, 0.1);
    let mag = Magnetometer::new(mb, mref, T::lit(0.5));
    c.bench_function(&format!("eskf/{tag}/ahrs_magnetometer"), |b| {
        b.iter(|| {
            let mut f = *black_box(&a0);
            let out = f.update(black_box(&mag), &ekf);
            black_box((f, out))
        })
    });
    let grav = GravityDirection::new(sa.attitude.inverse().act(&v(0.0, 0.0, 9.81)), T::lit(0.2));
    c.bench_function(&format!("eskf/{tag}/ahrs_gravity"), |b| {
        b.iter(|| {
            let mut f = *black_box(&a0);
            let out = f.update(black_box(&grav), &ekf);
            black_box((f, out))
        })
    });
    let f0c = f0;
    c.bench_function(&format!("eskf/{tag}/ins_copy_only"), |b| {
        b.iter(|| black_box(*black_box(&f0c)))
    });
}

fn benches(c: &mut Criterion) {
    suite::<f32>(c, "f32");
    suite::<f64>(c, "f64");
}

criterion_group!(eskf, benches);
criterion_main!(eskf);

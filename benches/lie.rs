//! ns per call of the Lie-group operations, `f32` and `f64`, beside nalgebra's own equivalents
//! measured in the same run (`UnitQuaternion::from_scaled_axis`, `scaled_axis`, the quaternion
//! product, the rotation of a vector), so the ratio is visible.
//!
//! Run: `cargo bench --bench lie` (add `-- --quick` for a shorter run).

use criterion::{criterion_group, criterion_main, Criterion};
use estimator_core::lie::{LieGroup, Se3, So3};
use estimator_core::Real;
use nalgebra::{UnitQuaternion, Vector3, Vector6};
use std::hint::black_box;

fn so3_ops<T: Real>(c: &mut Criterion, name: &str) {
    let lit = |x: f64| T::lit(x);
    let w = Vector3::new(lit(0.3), lit(-0.7), lit(1.1));
    let w2 = Vector3::new(lit(-1.2), lit(0.4), lit(0.25));
    let p = Vector3::new(lit(0.5), lit(-2.0), lit(1.5));
    let a = So3::exp(&w);
    let b = So3::exp(&w2);
    let qa = UnitQuaternion::from_scaled_axis(w);
    let qb = UnitQuaternion::from_scaled_axis(w2);

    let mut g = c.benchmark_group(format!("so3_{name}"));
    g.bench_function("exp", |bch| bch.iter(|| So3::exp(black_box(&w))));
    g.bench_function("exp_jac", |bch| bch.iter(|| So3::exp_jac(black_box(&w))));
    g.bench_function("log", |bch| bch.iter(|| black_box(&a).log()));
    g.bench_function("log_jac", |bch| bch.iter(|| black_box(&a).log_jac()));
    g.bench_function("compose", |bch| {
        bch.iter(|| black_box(&a).compose(black_box(&b)))
    });
    g.bench_function("compose_jac", |bch| {
        bch.iter(|| black_box(&a).compose_jac(black_box(&b)))
    });
    g.bench_function("act", |bch| bch.iter(|| black_box(&a).act(black_box(&p))));
    g.bench_function("act_jac", |bch| {
        bch.iter(|| black_box(&a).act_jac(black_box(&p)))
    });
    g.bench_function("rplus", |bch| {
        bch.iter(|| black_box(&a).rplus(black_box(&w2)))
    });
    g.bench_function("rminus", |bch| {
        bch.iter(|| black_box(&a).rminus(black_box(&b)))
    });
    g.bench_function("right_jacobian_inv", |bch| {
        bch.iter(|| So3::right_jacobian_inv(black_box(&w)))
    });
    g.bench_function("nalgebra_from_scaled_axis", |bch| {
        bch.iter(|| UnitQuaternion::from_scaled_axis(black_box(w)))
    });
    g.bench_function("nalgebra_scaled_axis", |bch| {
        bch.iter(|| black_box(&qa).scaled_axis())
    });
    g.bench_function("nalgebra_quaternion_product", |bch| {
        bch.iter(|| black_box(qa) * black_box(qb))
    });
    g.bench_function("nalgebra_rotate_vector", |bch| {
        bch.iter(|| black_box(qa) * black_box(p))
    });
    g.finish();
}

fn se3_ops<T: Real>(c: &mut Criterion, name: &str) {
    let lit = |x: f64| T::lit(x);
    let xi = Vector6::new(lit(1.0), lit(-2.0), lit(0.5), lit(0.3), lit(-0.7), lit(1.1));
    let xi2 = Vector6::new(
        lit(-0.3),
        lit(0.7),
        lit(2.0),
        lit(-1.2),
        lit(0.4),
        lit(0.25),
    );
    let p = Vector3::new(lit(0.5), lit(-2.0), lit(1.5));
    let a = Se3::exp(&xi);
    let b = Se3::exp(&xi2);
    let mut g = c.benchmark_group(format!("se3_{name}"));
    g.bench_function("exp", |bch| bch.iter(|| Se3::exp(black_box(&xi))));
    g.bench_function("exp_jac", |bch| bch.iter(|| Se3::exp_jac(black_box(&xi))));
    g.bench_function("log", |bch| bch.iter(|| black_box(&a).log()));
    g.bench_function("log_jac", |bch| bch.iter(|| black_box(&a).log_jac()));
    g.bench_function("compose", |bch| {
        bch.iter(|| black_box(&a).compose(black_box(&b)))
    });
    g.bench_function("compose_jac", |bch| {
        bch.iter(|| black_box(&a).compose_jac(black_box(&b)))
    });
    g.bench_function("act", |bch| bch.iter(|| black_box(&a).act(black_box(&p))));
    g.bench_function("act_jac", |bch| {
        bch.iter(|| black_box(&a).act_jac(black_box(&p)))
    });
    g.finish();
}

fn benches(c: &mut Criterion) {
    so3_ops::<f32>(c, "f32");
    so3_ops::<f64>(c, "f64");
    se3_ops::<f32>(c, "f32");
    se3_ops::<f64>(c, "f64");
}

criterion_group!(lie, benches);
criterion_main!(lie);

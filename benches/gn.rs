//! Criterion benchmarks of `estimator_core::gn`: µs per PnP solve at 6, 20 and 100 points in
//! `f32` and `f64`, and the mean over a 200-problem mix of 6..=100 points, every solve from a
//! guess 20° and 0.5 m off the truth (1 px noise; with and without 20 % gross outliers).
//!
//! Run: `cargo bench --bench gn`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use estimator_core::gn::{solve_pnp, Loss, PinholeCamera, PnpOptions};
use estimator_core::lie::{LieGroup, Se3, So3};
use estimator_core::Real;
use nalgebra::{Vector2, Vector3};
use std::hint::black_box;

/// splitmix64 + Box-Muller (no rand crate in the workspace).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.next()
    }
    fn normal(&mut self) -> f64 {
        let u1 = self.next().max(1e-300);
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * self.next()).cos()
    }
    fn unit3(&mut self) -> Vector3<f64> {
        let v = Vector3::new(self.normal(), self.normal(), self.normal());
        v / v.norm().max(1e-9)
    }
}

struct Case<T: Real> {
    world: Vec<Vector3<T>>,
    pixels: Vec<Vector2<T>>,
    guess: Se3<T>,
}

fn camera<T: Real>() -> PinholeCamera<T> {
    PinholeCamera::new(T::lit(500.0), T::lit(500.0), T::lit(320.0), T::lit(240.0))
}

fn case<T: Real>(rng: &mut Rng, n: usize, outliers: f64) -> Case<T> {
    let cam = camera::<f64>();
    let truth = Se3::from_parts(
        So3::exp(&(rng.unit3() * rng.range(0.0, 3.1))),
        Vector3::new(rng.normal(), rng.normal(), rng.normal()) * 2.0,
    );
    let wfc = truth.inverse();
    let n_out = (outliers * n as f64).round() as usize;
    let mut world = Vec::new();
    let mut pixels = Vec::new();
    for k in 0..n {
        let (u, v, d) = (
            rng.range(0.0, 640.0),
            rng.range(0.0, 480.0),
            rng.range(2.0, 8.0),
        );
        let p = wfc.act(&(cam.unproject(&Vector2::new(u, v)) * d));
        world.push(p.map(|x| T::lit(x)));
        let z = if k < n_out {
            Vector2::new(rng.range(0.0, 640.0), rng.range(0.0, 480.0))
        } else {
            Vector2::new(u + rng.normal(), v + rng.normal())
        };
        pixels.push(z.map(|x| T::lit(x)));
    }
    let dr = So3::exp(&(rng.unit3() * 20f64.to_radians()));
    let guess = Se3::from_parts(
        dr.compose(&truth.rotation()),
        dr.act(&truth.translation()) + rng.unit3() * 0.5,
    );
    Case {
        world,
        pixels,
        guess: guess.cast(),
    }
}

fn bench_precision<T: Real>(c: &mut Criterion, name: &str) {
    let cam = camera::<T>();
    let plain = PnpOptions::<T>::default();
    let robust = plain.with_loss(Loss::Cauchy(T::lit(2.0)));
    let mut group = c.benchmark_group(format!("pnp_{name}"));
    for &n in &[6usize, 20, 100] {
        let mut rng = Rng(n as u64);
        let cases: Vec<Case<T>> = (0..32).map(|_| case(&mut rng, n, 0.0)).collect();
        let mut k = 0;
        group.bench_with_input(BenchmarkId::new("least_squares", n), &n, |b, _| {
            b.iter(|| {
                let cs = &cases[k % cases.len()];
                k += 1;
                black_box(solve_pnp(&cs.world, &cs.pixels, &cam, &cs.guess, &plain))
            })
        });
    }
    for (label, outliers, opts) in [
        ("mix200_least_squares", 0.0, plain),
        ("mix200_cauchy_20pct_outliers", 0.2, robust),
    ] {
        let mut rng = Rng(200);
        let cases: Vec<Case<T>> = (0..200)
            .map(|_| {
                let n = 6 + (rng.next() * 95.0) as usize;
                case(&mut rng, n, outliers)
            })
            .collect();
        // One iteration = the whole 200-problem mix; µs per solve = reported time / 200.
        group.bench_function(label, |b| {
            b.iter(|| {
                for cs in &cases {
                    let _ = black_box(solve_pnp(&cs.world, &cs.pixels, &cam, &cs.guess, &opts));
                }
            })
        });
    }
    group.finish();
}

fn benches(c: &mut Criterion) {
    bench_precision::<f64>(c, "f64");
    bench_precision::<f32>(c, "f32");
}

criterion_group!(gn, benches);
criterion_main!(gn);

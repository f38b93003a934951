//! What every test of `estimator-core` shares: one deterministic random stream, the
//! finite-difference Jacobian the analytic Jacobians are checked against, and the normalized
//! estimation error squared (NEES) with its chi-square bands.
//!
//! Each test binary declares `mod support;`; helpers for one family of tests (motion and sensor
//! generators, synthetic PnP problems) live beside it and build on this module.
#![allow(dead_code)] // every test binary uses a different part

use nalgebra::{RealField, SMatrix, SVector, Vector3};

/// xorshift64* (Vigna, 2016) with Box–Muller normals: deterministic, seedable, and enough for
/// test data (not for cryptography).
pub struct Rng {
    s: u64,
    spare: Option<f64>,
}

impl Rng {
    /// A stream for `seed` (any value, zero included).
    pub fn new(seed: u64) -> Self {
        Self {
            s: seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1,
            spare: None,
        }
    }

    /// 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.s ^= self.s >> 12;
        self.s ^= self.s << 25;
        self.s ^= self.s >> 27;
        self.s.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in `(0, 1)` (never 0, so `ln` is finite).
    pub fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    /// Uniform in `(a, b)`.
    pub fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.uniform()
    }

    /// Standard normal.
    pub fn normal(&mut self) -> f64 {
        if let Some(z) = self.spare.take() {
            return z;
        }
        let (u1, u2) = (self.uniform(), self.uniform());
        let r = (-2.0 * u1.ln()).sqrt();
        let t = core::f64::consts::TAU * u2;
        self.spare = Some(r * t.sin());
        r * t.cos()
    }

    /// Three independent normals times `sigma`.
    pub fn vec3(&mut self, sigma: f64) -> Vector3<f64> {
        Vector3::new(self.normal(), self.normal(), self.normal()) * sigma
    }

    /// A uniformly distributed unit vector.
    pub fn unit3(&mut self) -> Vector3<f64> {
        loop {
            let v = self.vec3(1.0);
            let n = v.norm();
            if n > 1e-6 {
                return v / n;
            }
        }
    }

    /// A sample of `N(0, P)`: `L z`, `P = L Lᵀ`, `z ~ N(0, I)`.
    pub fn gaussian<const N: usize>(&mut self, p: &SMatrix<f64, N, N>) -> SVector<f64, N> {
        let l = nalgebra::Cholesky::new(*p).expect("P spd").l();
        l * SVector::<f64, N>::from_fn(|_, _| self.normal())
    }
}

/// The Jacobian of `f` at `ξ = 0` by Richardson-extrapolated central differences, column by
/// column: `D(h) = (f(h e_c) − f(−h e_c))/2h`, `J ≈ (4 D(h/2) − D(h))/3` (truncation `O(h⁴)`).
pub fn fd_jacobian<T: RealField + Copy, const K: usize, const N: usize>(
    f: impl Fn(&SVector<T, N>) -> SVector<T, K>,
    h: f64,
) -> SMatrix<T, K, N> {
    let lit = |x: f64| -> T { nalgebra::convert(x) };
    let mut j = SMatrix::<T, K, N>::zeros();
    for c in 0..N {
        let d = |h: f64| {
            let mut e = SVector::<T, N>::zeros();
            e[c] = lit(h);
            (f(&e) - f(&-e)) / lit(2.0 * h)
        };
        j.set_column(c, &((d(h * 0.5) * lit(4.0) - d(h)) / lit(3.0)));
    }
    j
}

/// The normalized estimation error squared `eᵀ P⁻¹ e` (chi-square with `N` degrees of freedom
/// for a consistent estimator).
pub fn nees<const N: usize>(e: &SVector<f64, N>, p: &SMatrix<f64, N, N>) -> f64 {
    let c = nalgebra::Cholesky::new(*p).expect("P spd");
    e.dot(&c.solve(e))
}

/// The chi-square quantile for `k` degrees of freedom at the standard-normal quantile `z`
/// (Wilson–Hilferty: `k (1 − 2/9k + z √(2/9k))³`, relative error below 1 % for `k ≥ 3`).
pub fn chi2_quantile(k: f64, z: f64) -> f64 {
    let c = 2.0 / (9.0 * k);
    k * (1.0 - c + z * c.sqrt()).powi(3)
}

/// The two-sided 95 % band of the mean of `runs` independent NEES values of dimension `dof`
/// (the sum is chi-square with `runs·dof` degrees of freedom).
pub fn mean_nees_band(runs: usize, dof: usize) -> (f64, f64) {
    let k = (runs * dof) as f64;
    let n = runs as f64;
    (
        chi2_quantile(k, -1.959_964) / n,
        chi2_quantile(k, 1.959_964) / n,
    )
}

//! The size-driven rewrites of `gn` (scalar forms, shared helpers) against the straightforward
//! nalgebra code they replace: the same bits (and the same errors), `f32` and `f64`.

use super::rotation::{triad, triad_start, unit};
use super::*;
use crate::scalar::non_negative_finite;
use crate::test_support::{every_class, same_bits as same, Lcg};
use crate::Real;
use nalgebra::Vector3;

/// [`check_point_spread`] before the scalar sums: nalgebra's `sum += p`, `sum * inv_n`, `p − mean`.
fn check_point_spread_before<T: Real>(points: &[Vector3<T>]) -> Result<(), SolveError> {
    let n = points.len();
    if n == 0 {
        return Err(SolveError::DegenerateGeometry);
    }
    let count = T::from_usize(n).unwrap_or_else(T::one);
    let inv_n = T::one() / count;
    let mut sum = Vector3::zeros();
    for p in points {
        sum += p;
    }
    let mean = sum * inv_n;
    let [mut s11, mut s22, mut s33, mut s12, mut s13, mut s23] = [T::zero(); 6];
    for p in points {
        let d = p - mean;
        s11 += d.x * d.x;
        s22 += d.y * d.y;
        s33 += d.z * d.z;
        s12 += d.x * d.y;
        s13 += d.x * d.z;
        s23 += d.y * d.z;
    }
    let tr = s11 + s22 + s33;
    let i2 = s11 * s22 - s12 * s12 + s11 * s33 - s13 * s13 + s22 * s33 - s23 * s23;
    let scale = mean.x * mean.x + mean.y * mean.y + mean.z * mean.z + T::one();
    let spread = tr > T::lit(1e-12) * count * scale;
    let not_collinear = i2 > T::lit(1e-10) * tr * tr;
    if spread && not_collinear {
        Ok(())
    } else {
        Err(SolveError::DegenerateGeometry)
    }
}

/// Point sets of every kind: spread, nearly collinear, nearly coincident, far from the origin,
/// with non-finite entries, and the empty set.
fn point_spread<T: Real>() {
    let mut rng = Lcg(3);
    let (mut ok, mut degenerate) = (0, 0);
    for i in 0..600 {
        let n = i % 9;
        let offset = rng.vector::<T>([0.0, 1.0, 1e3, 1e6][i % 4]);
        let dir = rng.vector::<T>(1.0);
        let mut pts = [Vector3::<T>::zeros(); 8];
        for (k, p) in pts.iter_mut().enumerate().take(n) {
            let along = dir * T::lit(k as f64);
            let across = rng.vector::<T>([1.0, 1e-4, 1e-6, 1e-9, 0.0][i % 5]);
            *p = offset + along + across;
        }
        if i % 97 == 5 {
            pts[0].y = T::lit(f64::NAN);
        }
        if i % 89 == 7 {
            pts[1].x = T::lit(f64::INFINITY);
        }
        let pts = &pts[..n];
        let got = check_point_spread(pts);
        assert_eq!(got, check_point_spread_before(pts), "{i}");
        if got.is_ok() {
            ok += 1;
        } else {
            degenerate += 1;
        }
    }
    assert!(ok > 100 && degenerate > 100, "{ok} {degenerate}");
}

#[test]
fn check_point_spread_is_the_nalgebra_form() {
    point_spread::<f32>();
    point_spread::<f64>();
}

/// The TRIAD start of [`solve_rotation_from_vectors`] before [`triad_start`]: the unit vectors of
/// the first pair and of the best pair carried through the loop.
fn triad_start_before<T: Real>(pairs: &[VectorPair<T>]) -> Result<crate::lie::So3<T>, SolveError> {
    let mut first: Option<(Vector3<T>, Vector3<T>)> = None;
    let mut best: Option<(T, Vector3<T>, Vector3<T>)> = None;
    for p in pairs {
        let b = unit(&p.body).ok_or(SolveError::DegenerateGeometry)?;
        let w = unit(&p.world).ok_or(SolveError::DegenerateGeometry)?;
        match first {
            None => first = Some((b, w)),
            Some((b1, _)) => {
                let s = b1.cross(&b).norm();
                if best.as_ref().is_none_or(|(sb, _, _)| s > *sb) {
                    best = Some((s, b, w));
                }
            }
        }
    }
    let ((b1, w1), (_, b2, w2)) = first.zip(best).ok_or(SolveError::DegenerateGeometry)?;
    triad(&b1, &b2, &w1, &w2).ok_or(SolveError::DegenerateGeometry)
}

/// Pair sets of 0 to 6 pairs: random, with repeated (tied) and parallel directions, zero
/// vectors on either side, tiny and huge magnitudes.
fn rotation_start<T: Real>() {
    let mut rng = Lcg(11);
    let (mut ok, mut degenerate) = (0, 0);
    for i in 0..1500 {
        let n = i % 7;
        let mut pairs = [VectorPair {
            body: Vector3::<T>::zeros(),
            world: Vector3::zeros(),
            sigma: T::one(),
        }; 6];
        let scale = [1.0, 1e-20, 1e20, 3.0][i % 4];
        for p in pairs.iter_mut().take(n) {
            p.body = rng.vector(scale);
            p.world = rng.vector(1.0);
        }
        match i % 11 {
            // A tie: two pairs with the same body direction.
            1 if n >= 3 => pairs[2].body = pairs[1].body * T::lit(2.0),
            // All body directions parallel.
            2 => {
                for k in 1..n {
                    pairs[k].body = pairs[0].body * T::lit(k as f64 + 0.5);
                }
            }
            // World directions parallel.
            3 if n >= 2 => pairs[1].world = -pairs[0].world,
            // Zero vectors, first pair or later ones.
            4 if n >= 1 => pairs[0].world = Vector3::zeros(),
            5 if n >= 1 => pairs[n - 1].body = Vector3::zeros(),
            6 if n >= 2 => pairs[1].world = Vector3::zeros(),
            _ => {}
        }
        let pairs = &pairs[..n];
        let got = triad_start(pairs);
        let want = triad_start_before(pairs);
        match (got, want) {
            (Ok(g), Ok(w)) => {
                assert!(same(
                    g.quaternion().coords.as_slice(),
                    w.quaternion().coords.as_slice()
                ));
                ok += 1;
            }
            (g, w) => {
                assert_eq!(g.err(), w.err(), "{i}");
                degenerate += 1;
            }
        }
    }
    assert!(ok > 300 && degenerate > 300, "{ok} {degenerate}");
}

#[test]
fn triad_start_is_the_carried_form() {
    rotation_start::<f32>();
    rotation_start::<f64>();
}

/// `all_positive` and `all_non_negative` (size form: `x · 0 = 0` as the finiteness test)
/// against `x > 0 && x.is_finite()` and `x ≥ 0 && x.is_finite()` on every class of number.
fn sign_checks<T: Real>() {
    let mut xs = every_class().to_vec();
    let mut rng = Lcg(29);
    xs.extend((0..200).map(|_| (rng.next() - 0.5) * 10f64.powf(80.0 * rng.next() - 40.0)));
    for x in xs.into_iter().map(T::lit) {
        let positive = x > T::zero() && x.is_finite();
        let non_negative = x >= T::zero() && x.is_finite();
        assert_eq!(all_positive(&[x]), positive, "{x:?}");
        assert_eq!(all_non_negative(&[x]), non_negative, "{x:?}");
        assert_eq!(non_negative_finite(x), non_negative, "{x:?}");
        assert_eq!(all_positive(&[T::one(), x]), positive, "{x:?}");
        assert_eq!(all_non_negative(&[x, T::one()]), non_negative, "{x:?}");
    }
}

#[test]
fn sign_checks_are_the_class_tests() {
    sign_checks::<f32>();
    sign_checks::<f64>();
}

/// `unit` (through `normalized`) against its former body: `n = ‖v‖`, `v / n` if `n` is finite
/// and positive.
fn unit_cases<T: Real>() {
    let mut rng = Lcg(41);
    for i in 0..2000 {
        let mut d = rng.vector::<T>([1.0, 1e-30, 1e30, 1e38, 1e300, 1e-300][i % 6]);
        match i % 13 {
            1 => d.x = T::lit(f64::INFINITY),
            2 => d.y = T::lit(f64::NAN),
            3 => d = Vector3::zeros(),
            4 => d.z = T::lit(-0.0),
            _ => {}
        }
        let n = d.norm();
        let old = (n.is_finite() && n > T::zero()).then(|| d / n);
        match (unit(&d), old) {
            (Some(u), Some(o)) => assert!(same(u.as_slice(), o.as_slice()), "{d:?}"),
            (u, o) => assert!(u.is_none() && o.is_none(), "{d:?}"),
        }
        let (u, m) = super::rotation::normalized(&d);
        assert!(same(u.as_slice(), (d / d.norm()).as_slice()) && same(&[m], &[n]));
    }
}

#[test]
fn unit_is_the_division_by_the_norm() {
    unit_cases::<f32>();
    unit_cases::<f64>();
}

/// `mul_transpose(w, b)` (TRIAD's `W Bᵀ`) against nalgebra's `w * b.transpose()`: random
/// entries of every magnitude, signed zeros and infinities.
fn mul_transpose_cases<T: Real>() {
    let mut rng = Lcg(17);
    for i in 0..3000 {
        let mut m = [nalgebra::Matrix3::<T>::zeros(); 2];
        for (h, x) in m.iter_mut().flat_map(|m| m.iter_mut()).enumerate() {
            let scale = [1.0, 1e-30, 1e30, 1e200, 1e-200][(i + h) % 5];
            *x = T::lit((rng.next() - 0.5) * scale);
            match (i * 7 + h * 3) % 23 {
                0 => *x = T::zero(),
                1 => *x = T::lit(-0.0),
                2 if i % 5 == 0 => *x = T::lit(f64::INFINITY),
                3 if i % 7 == 0 => *x = T::lit(f64::NEG_INFINITY),
                _ => {}
            }
        }
        let [w, b] = m;
        let got = super::rotation::mul_transpose(&w, &b);
        let want = w * b.transpose();
        assert!(same(got.as_slice(), want.as_slice()), "{w:?} {b:?}");
    }
}

#[test]
fn mul_transpose_is_the_nalgebra_product() {
    mul_transpose_cases::<f32>();
    mul_transpose_cases::<f64>();
}

/// `Product::split` (slice copies) against its former body: entry by entry through `get`, zero
/// past the end of `ξ`, entries beyond `NA + NB` ignored.
fn split_before<T: Real, const NA: usize, const NB: usize, const N: usize>(
    xi: &nalgebra::SVector<T, N>,
) -> (nalgebra::SVector<T, NA>, nalgebra::SVector<T, NB>) {
    let mut xa = nalgebra::SVector::<T, NA>::zeros();
    let mut xb = nalgebra::SVector::<T, NB>::zeros();
    for (k, d) in xa.iter_mut().enumerate() {
        *d = xi.get(k).copied().unwrap_or_else(T::zero);
    }
    for (k, d) in xb.iter_mut().enumerate() {
        *d = xi.get(NA + k).copied().unwrap_or_else(T::zero);
    }
    (xa, xb)
}

fn split_case<T: Real, const NA: usize, const NB: usize, const N: usize>(rng: &mut Lcg) {
    let mut xi = nalgebra::SVector::<T, N>::from_fn(|_, _| T::lit(rng.next() - 0.5));
    if let Some(x) = xi.get_mut(0) {
        *x = T::lit(-0.0);
    }
    let (a, b) = Product::<(), (), NA, NB>::split::<T, N>(&xi);
    let (a0, b0) = split_before::<T, NA, NB, N>(&xi);
    assert!(same(a.as_slice(), a0.as_slice()) && same(b.as_slice(), b0.as_slice()));
}

#[test]
fn split_is_the_indexed_copy() {
    let mut rng = Lcg(5);
    for _ in 0..20 {
        split_case::<f64, 3, 3, 6>(&mut rng);
        split_case::<f32, 3, 3, 6>(&mut rng);
        split_case::<f64, 2, 4, 6>(&mut rng);
        split_case::<f64, 3, 3, 4>(&mut rng);
        split_case::<f32, 1, 3, 8>(&mut rng);
        split_case::<f64, 4, 2, 3>(&mut rng);
        split_case::<f64, 0, 2, 2>(&mut rng);
    }
}

/// `reprojection_error`'s former body: `Jπ/σ` as a full 2×3 matrix times `R` (nalgebra's
/// product), then the rotation block as `p × b` per row.
#[allow(clippy::type_complexity)]
fn reprojection_error_before<T: Real>(
    camera: &PinholeCamera<T>,
    r: &nalgebra::Matrix3<T>,
    t: &Vector3<T>,
    p: &Vector3<T>,
    z: &nalgebra::Vector2<T>,
    inv_sigma: T,
    min_depth: T,
) -> Option<(nalgebra::Vector2<T>, nalgebra::Matrix2x6<T>)> {
    let x = super::pnp::camera_point(r, t, p);
    let (uv, jp) = camera.project_jac(&x, min_depth)?;
    let b = jp * inv_sigma * r;
    let mut j = nalgebra::Matrix2x6::zeros();
    j.fixed_view_mut::<2, 3>(0, 0).copy_from(&b);
    for i in 0..2 {
        let c = p.cross(&Vector3::new(b[(i, 0)], b[(i, 1)], b[(i, 2)]));
        for k in 0..3 {
            j[(i, 3 + k)] = c[k];
        }
    }
    let e = nalgebra::Vector2::new((uv.x - z.x) * inv_sigma, (uv.y - z.y) * inv_sigma);
    Some((e, j))
}

/// `reprojection_error` (the structural zeros of `Jπ` left out of `(Jπ/σ) R`) against the full
/// product: the same values on finite inputs, up to the sign of a zero.
fn reprojection_cases<T: Real>() {
    let mut rng = Lcg(29);
    for i in 0..3000 {
        let mut r = nalgebra::Matrix3::<T>::zeros();
        for (h, x) in r.iter_mut().enumerate() {
            *x = T::lit(rng.next());
            match (i * 5 + h) % 17 {
                0 => *x = T::zero(),
                1 => *x = T::lit(-0.0),
                _ => {}
            }
        }
        let t = rng.vector::<T>(1.0) + Vector3::new(T::zero(), T::zero(), T::lit(4.0));
        let mut p = rng.vector::<T>([1.0, 1e-20, 1e10][i % 3]);
        if i % 11 == 0 {
            p.y = T::lit(-0.0);
        }
        let z = nalgebra::Vector2::new(T::lit(300.0 * rng.next()), T::lit(200.0 * rng.next()));
        let cam = PinholeCamera::new(
            T::lit(500.0 + rng.next()),
            T::lit(480.0),
            T::lit(320.0),
            T::lit(240.0),
        );
        let s = T::lit([0.5, 2.0, 1e-30, 0.0][i % 4]);
        let md = T::lit([0.1, 10.0][i % 2]);
        let got = reprojection_error(&cam, &r, &t, &p, &z, s, md);
        let want = reprojection_error_before(&cam, &r, &t, &p, &z, s, md);
        match (got, want) {
            (Some((ge, gj)), Some((we, wj))) => {
                assert!(same(ge.as_slice(), we.as_slice()), "{r:?} {p:?}");
                assert!(
                    crate::test_support::same_up_to_zero_sign(gj.as_slice(), wj.as_slice()),
                    "{r:?} {p:?} {gj:?} {wj:?}"
                );
            }
            (g, w) => assert!(g.is_none() && w.is_none()),
        }
    }
}

#[test]
fn reprojection_error_is_the_full_product_up_to_zero_signs() {
    reprojection_cases::<f32>();
    reprojection_cases::<f64>();
}

/// [`linalg::cholesky_in_place`] with its former up-front test of the diagonal (every `A[j, j]`
/// positive, else [`SolveError::NotPositiveDefinite`] before any column is touched).
fn cholesky_with_diagonal_test<T: Real>(a: &mut [T], n: usize) -> Result<(), SolveError> {
    if n > 0 && crate::scalar::all_finite(a) {
        let diagonal_positive = (0..n).all(|j| a.get(j * n + j).is_some_and(|&d| d > T::zero()));
        if !diagonal_positive {
            return Err(SolveError::NotPositiveDefinite);
        }
    }
    linalg::cholesky_in_place(a, n)
}

/// Symmetric matrices of sizes 1 to 6: Gram matrices (positive definite), the same with a
/// diagonal entry made zero, `−0`, negative, tiny or non-finite, and arbitrary symmetric ones;
/// the factorization without the diagonal test gives the same result and, on success, the same
/// bits.
fn cholesky_cases<T: Real>() {
    let mut rng = Lcg(17);
    let specials = every_class();
    let (mut ok, mut refused) = (0, 0);
    for i in 0..3000 {
        let n = 1 + i % 6;
        let mut a = [T::zero(); 36];
        let a = &mut a[..n * n];
        if i % 3 == 0 {
            // Arbitrary symmetric.
            for r in 0..n {
                for c in 0..=r {
                    let x = T::lit(rng.next());
                    a[c * n + r] = x;
                    a[r * n + c] = x;
                }
            }
        } else {
            // Gram matrix `Σ vₖ vₖᵀ` of `n + 2` random vectors, the last one `1e-3` long
            // (mostly positive definite, some nearly singular).
            let mut v = [[0.0f64; 6]; 8];
            for (k, vk) in v.iter_mut().enumerate().take(n + 2) {
                for x in vk.iter_mut().take(n) {
                    *x = rng.next() * if k == n + 1 { 1e-3 } else { 1.0 };
                }
            }
            for r in 0..n {
                for c in 0..n {
                    let s: f64 = v.iter().take(n + 2).map(|vk| vk[r] * vk[c]).sum();
                    a[c * n + r] = T::lit(s);
                }
            }
        }
        let j = i % n;
        match i % 7 {
            1 => a[j * n + j] = T::zero(),
            2 => a[j * n + j] = T::lit(-0.0),
            3 => a[j * n + j] = T::lit(-rng.next().abs()),
            4 => a[j * n + j] = T::lit(1e-300),
            5 => a[j * n + j] = T::lit(specials[i % specials.len()]),
            _ => {}
        }
        let mut before = [T::zero(); 36];
        let before = &mut before[..n * n];
        before.copy_from_slice(a);
        let want = cholesky_with_diagonal_test(before, n);
        let got = linalg::cholesky_in_place(a, n);
        assert_eq!(got, want, "{i}");
        if got.is_ok() {
            assert!(same(a, before), "{i}");
            ok += 1;
        } else {
            refused += 1;
        }
    }
    assert!(ok > 500 && refused > 500, "{ok} {refused}");
}

#[test]
fn cholesky_without_the_diagonal_test_is_the_same() {
    cholesky_cases::<f32>();
    cholesky_cases::<f64>();
}

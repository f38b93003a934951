//! Rotation from paired direction observations (gravity and magnetic field against their world
//! references): the Jacobian against finite differences, recovery within the returned
//! covariance in f32 and f64, TRIAD start and explicit guess, every error path.
//!
//! NEES tolerances as in `gn_triangulation.rs` (3 degrees of freedom).

mod gn_util;
mod support;

use estimator_core::gn::{
    solve_rotation_from_vectors, vector_pair_error, Loss, SolveError, SolverOptions, VectorPair,
};
use estimator_core::lie::{LieGroup, So3};
use gn_util::*;
use nalgebra::{Matrix3, Vector3};

const CHI2_3_999: f64 = 16.266;

fn world_refs() -> [Vector3<f64>; 2] {
    // Gravity down, and a magnetic field inclined 60° (ENU).
    [
        Vector3::new(0.0, 0.0, -1.0),
        Vector3::new(0.0, 0.5, -(0.75f64).sqrt()),
    ]
}

/// Body directions of the world references under `world_from_body`, each perturbed by an
/// isotropic angular noise of σ rad, scaled to non-unit lengths (only directions matter).
fn pairs(rng: &mut Rng, r: &So3<f64>, refs: &[Vector3<f64>], sigma: f64) -> Vec<VectorPair<f64>> {
    refs.iter()
        .enumerate()
        .map(|(k, w)| {
            let b = r.inverse().act(w);
            let noisy =
                (b + Vector3::new(rng.normal(), rng.normal(), rng.normal()) * sigma).normalize();
            VectorPair {
                body: noisy * (9.81 * (k + 1) as f64),
                world: *w * 3.0,
                sigma,
            }
        })
        .collect()
}

#[test]
fn vector_pair_jacobian_matches_finite_differences() {
    let mut rng = Rng::new(40);
    for _ in 0..200 {
        let r = rng.rotation();
        let (b, w) = (rng.unit3(), rng.unit3());
        let (e, j) = vector_pair_error(&r, &b, &w, 2.0);
        let f = |d: &Vector3<f64>| vector_pair_error(&r.rplus(d), &b, &w, 2.0).0;
        assert_eq!(f(&Vector3::zeros()), e);
        let fd = fd_jacobian(f, 1e-3);
        // Richardson, h = 1e-3: truncation O(h⁴) ≈ 1e-12, rounding 2ε/h ≈ 5e-13.
        assert!((fd - j).amax() <= 1e-9, "{}", (fd - j).amax());
    }
}

#[test]
fn recovers_rotation_within_its_covariance_f32_f64() {
    let mut rng = Rng::new(41);
    let refs = world_refs();
    let extra = [refs[0], refs[1], Vector3::new(1.0, 0.0, 0.0)];
    let (mut n64, mut n32) = (vec![], vec![]);
    for trial in 0..300 {
        let truth = rng.rotation();
        let sigma = [0.002, 0.01, 0.03][trial % 3];
        let use_refs: &[Vector3<f64>] = if trial % 2 == 0 { &refs } else { &extra };
        let p = pairs(&mut rng, &truth, use_refs, sigma);
        // Alternate between the TRIAD start and a guess 20° off.
        let guess = So3::exp(&(rng.unit3() * 20f64.to_radians())).compose(&truth);
        let g = if trial % 4 < 2 { None } else { Some(&guess) };
        let s = solve_rotation_from_vectors(&p, g, &SolverOptions::default()).unwrap();
        let d = truth.rminus(&s.world_from_body);
        n64.push((d.transpose() * s.covariance.try_inverse().unwrap() * d)[(0, 0)]);

        let p32: Vec<VectorPair<f32>> = p
            .iter()
            .map(|q| VectorPair {
                body: q.body.cast(),
                world: q.world.cast(),
                sigma: q.sigma as f32,
            })
            .collect();
        let g32 = guess.cast::<f32>();
        let s = solve_rotation_from_vectors(
            &p32,
            if trial % 4 < 2 { None } else { Some(&g32) },
            &SolverOptions::default(),
        )
        .unwrap();
        let d = truth.rminus(&s.world_from_body.cast::<f64>());
        let cov: Matrix3<f64> = s.covariance.cast();
        n32.push((d.transpose() * cov.try_inverse().unwrap() * d)[(0, 0)]);
    }
    for (what, v) in [("f64", &n64), ("f32", &n32)] {
        let m = v.len() as f64;
        let mean = v.iter().sum::<f64>() / m;
        let over = v.iter().filter(|&&x| x > CHI2_3_999).count();
        assert!(
            (mean - 3.0).abs() <= 4.0 * (6.0 / m).sqrt() + 0.45,
            "{what}: mean NEES {mean}"
        );
        assert!(over as f64 <= (0.005 * m).max(2.0), "{what}: {over} over");
    }
}

/// Noise-free pairs: exact to rounding from TRIAD alone and after the solve.
#[test]
fn exact_pairs_give_exact_rotation() {
    let mut rng = Rng::new(42);
    for _ in 0..100 {
        let truth = rng.rotation();
        let p = pairs(&mut rng, &truth, &world_refs(), 0.0);
        let p: Vec<_> = p
            .into_iter()
            .map(|q| VectorPair { sigma: 1e-3, ..q })
            .collect();
        let s = solve_rotation_from_vectors(&p, None, &SolverOptions::default()).unwrap();
        assert!(truth.rminus(&s.world_from_body).norm() <= 1e-12);
        let robust = SolverOptions {
            loss: Loss::Huber(3.0),
            ..SolverOptions::default()
        };
        let s = solve_rotation_from_vectors(&p, None, &robust).unwrap();
        assert!(truth.rminus(&s.world_from_body).norm() <= 1e-12);
    }
}

/// The TRIAD start pairs the first observation with the one most perpendicular to it: with a
/// second pair within `1e-9` rad of the first (parallel for TRIAD, whose threshold is
/// `‖u × v‖ ≤ 1e-6`) and a third one 60° away, the start comes from the third and the solve is
/// exact to rounding. Zero vectors in any pair, on either side, are refused.
#[test]
fn triad_starts_from_the_most_perpendicular_pair() {
    let mut rng = Rng::new(44);
    let [down, field] = world_refs();
    let near_down = So3::exp(&(rng.unit3() * 1e-9)).act(&down);
    for _ in 0..50 {
        let truth = rng.rotation();
        let p: Vec<_> = [down, near_down, field]
            .iter()
            .map(|w| VectorPair {
                body: truth.inverse().act(w),
                world: *w,
                sigma: 1e-3,
            })
            .collect();
        let s = solve_rotation_from_vectors(&p, None, &SolverOptions::default()).unwrap();
        assert!(truth.rminus(&s.world_from_body).norm() <= 1e-12);
        for k in 0..3 {
            for world_side in [false, true] {
                let mut bad = p.clone();
                let v = if world_side {
                    &mut bad[k].world
                } else {
                    &mut bad[k].body
                };
                *v = Vector3::zeros();
                assert_eq!(
                    solve_rotation_from_vectors(&bad, None, &SolverOptions::default()).unwrap_err(),
                    SolveError::DegenerateGeometry
                );
            }
        }
    }
}

#[test]
fn rotation_error_paths() {
    let mut rng = Rng::new(43);
    let truth = rng.rotation();
    let p = pairs(&mut rng, &truth, &world_refs(), 0.01);
    let o = SolverOptions::default();
    assert_eq!(
        solve_rotation_from_vectors(&p[..1], None, &o).unwrap_err(),
        SolveError::TooFewObservations { needed: 2, got: 1 }
    );
    let mut bad = p.clone();
    bad[1].world.x = f64::NAN;
    assert_eq!(
        solve_rotation_from_vectors(&bad, None, &o).unwrap_err(),
        SolveError::NonFiniteInput
    );
    let mut bad = p.clone();
    bad[0].sigma = 0.0;
    assert_eq!(
        solve_rotation_from_vectors(&bad, None, &o).unwrap_err(),
        SolveError::InvalidOptions
    );
    let o_bad = SolverOptions {
        step_tolerance: -1.0,
        ..o
    };
    assert_eq!(
        solve_rotation_from_vectors(&p, None, &o_bad).unwrap_err(),
        SolveError::InvalidOptions
    );
    let mut bad = p.clone();
    bad[1].body = Vector3::zeros();
    assert_eq!(
        solve_rotation_from_vectors(&bad, None, &o).unwrap_err(),
        SolveError::DegenerateGeometry
    );
    // Parallel observations: rotation about the common axis unobservable.
    let mut bad = p.clone();
    bad[1].body = bad[0].body * 2.0;
    bad[1].world = bad[0].world * 0.5;
    assert_eq!(
        solve_rotation_from_vectors(&bad, None, &o).unwrap_err(),
        SolveError::DegenerateGeometry
    );
    // Parallel in the world only (TRIAD refuses).
    let mut bad = p.clone();
    bad[1].world = -bad[0].world;
    assert_eq!(
        solve_rotation_from_vectors(&bad, None, &o).unwrap_err(),
        SolveError::DegenerateGeometry
    );
    let nan_guess = So3::from_unit_quaternion(nalgebra::UnitQuaternion::new_unchecked(
        nalgebra::Quaternion::new(f64::NAN, 0.0, 0.0, 0.0),
    ));
    assert_eq!(
        solve_rotation_from_vectors(&p, Some(&nan_guess), &o).unwrap_err(),
        SolveError::NonFiniteGuess
    );
}

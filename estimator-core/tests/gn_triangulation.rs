//! Triangulation: the Jacobian against finite differences, recovery within the returned
//! covariance in f32 and f64, a robust loss with outlying views, and every error path.
//!
//! NEES tolerances as in `gn_pnp.rs`, for 3 degrees of freedom: mean `3 ± (4·√(6/M) + 0.45)`,
//! at most `max(2, 0.005 M)` trials above the χ²(3) 99.9 % quantile 16.27.

mod gn_util;
mod support;

use estimator_core::gn::{
    point_reprojection_error, triangulate, Loss, PinholeCamera, SolveError, TriangulationOptions,
};
use estimator_core::lie::{LieGroup, Se3, So3};
use gn_util::*;
use nalgebra::{Matrix3, Vector2, Vector3};

const CHI2_3_999: f64 = 16.266;

/// A camera at `p + d·u` looking at `p`, turned by a few degrees so `p` is not on the axis.
fn look_at(rng: &mut Rng, p: &Vector3<f64>, u: &Vector3<f64>, d: f64) -> Se3<f64> {
    let c = p + u * d;
    let z = (p - c).normalize();
    let x = z.cross(&Vector3::new(0.3, 0.9, 0.1)).normalize();
    let y = z.cross(&x);
    let r = Matrix3::from_rows(&[x.transpose(), y.transpose(), z.transpose()]);
    let r = So3::from_rotation_matrix(&r).unwrap();
    let tilt = So3::exp(&(rng.unit3() * 5f64.to_radians()));
    let rot = tilt.compose(&r);
    Se3::from_parts(rot, -rot.act(&c))
}

struct TriCase {
    point: Vector3<f64>,
    poses: Vec<Se3<f64>>,
    pixels: Vec<Vector2<f64>>,
}

/// `n` views from directions within about 35° of a random axis, 3–6 m away, noise σ px.
fn tri_case(rng: &mut Rng, n: usize, sigma: f64) -> TriCase {
    let point = Vector3::new(rng.normal(), rng.normal(), rng.normal());
    let axis = rng.unit3();
    let cam = camera();
    let mut poses = vec![];
    let mut pixels = vec![];
    for _ in 0..n {
        let u = (axis + rng.unit3() * 0.6).normalize();
        let d = rng.range(3.0, 6.0);
        let pose = look_at(rng, &point, &u, d);
        let z = cam.project(&pose.act(&point), 1e-3).unwrap();
        pixels.push(z + Vector2::new(rng.normal(), rng.normal()) * sigma);
        poses.push(pose);
    }
    TriCase {
        point,
        poses,
        pixels,
    }
}

/// `∂e/∂p` against Richardson central differences (`h = 1e-4` m; tolerance `1e-7` relative).
#[test]
fn point_jacobian_matches_finite_differences() {
    let mut rng = Rng::new(30);
    let cam = camera();
    for _ in 0..200 {
        let c = tri_case(&mut rng, 1, 1.0);
        let p = c.point + Vector3::new(rng.normal(), rng.normal(), rng.normal()) * 0.1;
        let (e, j) =
            point_reprojection_error(&cam, &c.poses[0], &p, &c.pixels[0], 0.7, 1e-3).unwrap();
        let f = |d: &Vector3<f64>| {
            point_reprojection_error(&cam, &c.poses[0], &(p + d), &c.pixels[0], 0.7, 1e-3)
                .unwrap()
                .0
        };
        assert_eq!(f(&Vector3::zeros()), e);
        let fd = fd_jacobian(f, 1e-4);
        assert!(
            (fd - j).amax() <= 1e-7 * j.amax().max(1.0),
            "{}",
            (fd - j).amax()
        );
    }
}

#[test]
fn recovers_the_landmark_within_its_covariance_f32_f64() {
    let mut rng = Rng::new(31);
    let cam32 = PinholeCamera::new(500.0f32, 500.0, 320.0, 240.0);
    let (mut n64, mut n32) = (vec![], vec![]);
    for &n in &[2usize, 3, 5, 10] {
        for &sigma in &[0.5, 1.0, 2.0] {
            for _ in 0..25 {
                let c = tri_case(&mut rng, n, sigma);
                let o = TriangulationOptions {
                    sigma_px: sigma,
                    ..TriangulationOptions::default()
                };
                let s = triangulate(&c.poses, &c.pixels, &camera(), &o).unwrap();
                n64.push(support::nees(&(s.point - c.point), &s.covariance));
                let poses32: Vec<Se3<f32>> = c.poses.iter().map(|p| p.cast()).collect();
                let o32 = TriangulationOptions {
                    sigma_px: sigma as f32,
                    ..TriangulationOptions::default()
                };
                let s = triangulate(&poses32, &cast_v2(&c.pixels), &cam32, &o32).unwrap();
                let d = s.point.cast::<f64>() - c.point;
                n32.push(support::nees(&d, &s.covariance.cast()));
            }
        }
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

/// Ten views, two of them with pixels 40–80 px off: Cauchy stays within its covariance, plain
/// least squares does not.
#[test]
fn cauchy_rejects_outlying_views() {
    let mut rng = Rng::new(32);
    let mut plain_bad = 0;
    for _ in 0..30 {
        let mut c = tri_case(&mut rng, 10, 1.0);
        for k in 0..2 {
            c.pixels[k] += rng.unit3().xy().normalize() * rng.range(40.0, 80.0);
        }
        let o = TriangulationOptions {
            loss: Loss::Cauchy(2.0),
            ..TriangulationOptions::default()
        };
        let s = triangulate(&c.poses, &c.pixels, &camera(), &o).unwrap();
        assert!(support::nees(&(s.point - c.point), &s.covariance) <= CHI2_3_999);
        let p = triangulate(
            &c.poses,
            &c.pixels,
            &camera(),
            &TriangulationOptions::default(),
        )
        .unwrap();
        if support::nees(&(p.point - c.point), &p.covariance) > CHI2_3_999 {
            plain_bad += 1;
        }
    }
    assert!(
        plain_bad >= 20,
        "plain least squares held in {} of 30",
        30 - plain_bad
    );
}

#[test]
fn triangulation_error_paths() {
    let mut rng = Rng::new(33);
    let c = tri_case(&mut rng, 4, 1.0);
    let cam = camera();
    let o = TriangulationOptions::default();
    assert_eq!(
        triangulate(&c.poses, &c.pixels[..3], &cam, &o).unwrap_err(),
        SolveError::LengthMismatch
    );
    assert_eq!(
        triangulate(&c.poses[..1], &c.pixels[..1], &cam, &o).unwrap_err(),
        SolveError::TooFewObservations { needed: 2, got: 1 }
    );
    assert_eq!(
        triangulate(
            &c.poses,
            &c.pixels,
            &PinholeCamera::new(0.0, 1.0, 0.0, 0.0),
            &o
        )
        .unwrap_err(),
        SolveError::InvalidCamera
    );
    for bad in [
        TriangulationOptions { sigma_px: 0.0, ..o },
        TriangulationOptions {
            loss: Loss::Huber(-2.0),
            ..o
        },
        TriangulationOptions {
            min_depth: f64::NAN,
            ..o
        },
    ] {
        assert_eq!(
            triangulate(&c.poses, &c.pixels, &cam, &bad).unwrap_err(),
            SolveError::InvalidOptions
        );
    }
    let mut z = c.pixels.clone();
    z[1].y = f64::NAN;
    assert_eq!(
        triangulate(&c.poses, &z, &cam, &o).unwrap_err(),
        SolveError::NonFiniteInput
    );
    let mut poses = c.poses.clone();
    poses[0] = Se3::from_parts(poses[0].rotation(), Vector3::new(f64::INFINITY, 0.0, 0.0));
    assert_eq!(
        triangulate(&poses, &c.pixels, &cam, &o).unwrap_err(),
        SolveError::NonFiniteInput
    );
    // No baseline: every view from the same centre (rays parallel).
    let centre = Vector3::new(0.0, 0.0, -5.0);
    let poses: Vec<Se3<f64>> = (0..4)
        .map(|_| {
            let r = So3::exp(&(rng.unit3() * 0.05));
            Se3::from_parts(r, -r.act(&centre))
        })
        .collect();
    let pixels: Vec<Vector2<f64>> = poses
        .iter()
        .map(|p| cam.project(&p.act(&Vector3::zeros()), 1e-3).unwrap())
        .collect();
    assert_eq!(
        triangulate(&poses, &pixels, &cam, &o).unwrap_err(),
        SolveError::DegenerateGeometry
    );
    // The second camera turned around: the rays meet behind it.
    let mut poses = c.poses.clone();
    let flip = Se3::from_parts(
        So3::exp(&Vector3::new(0.0, std::f64::consts::PI, 0.0)),
        Vector3::zeros(),
    );
    poses[1] = flip.compose(&poses[1]);
    let z2 = vec![c.pixels[0], c.pixels[1]];
    assert_eq!(
        triangulate(&poses[..2], &z2, &cam, &o).unwrap_err(),
        SolveError::PointBehindCamera
    );
}

//! Footprint: camera pose from known landmarks (`solve_pnp`, robust Levenberg-Marquardt on
//! SE(3)). See `src/footprint/mod.rs`.
#![no_std]
#![no_main]

#[path = "../footprint/mod.rs"]
mod footprint;

use cortex_m_rt::entry;
use estimator_core::gn::{solve_pnp, PinholeCamera, PnpOptions};
use estimator_core::lie::{LieGroup, Se3};
use footprint::{input, input3, keep};
use nalgebra::{Vector2, Vector3};

#[entry]
fn main() -> ! {
    let camera = PinholeCamera::new(400.0, 400.0, 320.0, 240.0);
    let options = PnpOptions::default();
    let mut pose = Se3::identity();
    loop {
        let points: [Vector3<f32>; 12] =
            core::array::from_fn(|i| input3(i) + Vector3::new(0.0, 0.0, 4.0));
        let pixels: [Vector2<f32>; 12] =
            core::array::from_fn(|i| Vector2::new(input(i) * 100.0, input(i + 3) * 100.0));
        let n = (input(4) as usize).min(12);
        let (points, pixels) = (
            points.get(..n).unwrap_or(&[]),
            pixels.get(..n).unwrap_or(&[]),
        );
        if let Ok(solution) = solve_pnp(points, pixels, &camera, &pose, &options) {
            pose = solution.camera_from_world;
        }
        keep(&pose);
    }
}

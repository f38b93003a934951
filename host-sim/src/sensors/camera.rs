//! A pinhole camera observing known landmarks: intrinsics, extrinsics, field of view, pixel
//! noise and outliers, landmarks in front of it only.
//!
//! With `body_from_camera = T_BS` and the true `world_from_body`, a landmark `p_w` is at
//! `x = (T_wb T_BS)⁻¹ p_w` in the camera frame and is seen at `z = K π(x) + σ n`,
//! `π(x, y, z) = (x/z, y/z)`, when `z > 0.1 m` and the pixel is inside the image: the landmark
//! measurement `z_ij = h(T_i, p_j) = π(T_i p_j)` of *Lie Groups and Smooth Manifolds for Robotic
//! State Estimation* (§4), with `T_i = (T_wb T_BS)⁻¹` (camera from world), then the intrinsics
//! `K`. An outlier replaces the pixel by a uniform one. Defaults: a 752×480 global shutter camera
//! like EuRoC's cam0 (fu = fv = 458, cu = 367, cv = 248), looking forward along the body x axis,
//! 10 Hz, 1 px noise.

use super::Noise;
use crate::trajectory::Kinematics;
use estimator_core::lie::{LieGroup, Se3, So3};
use nalgebra::{Matrix3, Vector2, Vector3};
use serde::{Deserialize, Serialize};

/// Camera parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
#[serde(deny_unknown_fields)]
pub struct CameraConfig {
    /// Frame rate, Hz.
    pub rate_hz: f64,
    /// `[fu, fv, cu, cv]`, px.
    pub intrinsics: [f64; 4],
    /// `[width, height]`, px.
    pub resolution: [u32; 2],
    /// `T_BS`: body-from-camera, 4×4 row-major.
    pub t_bs: [f64; 16],
    /// Pixel noise 1σ, px.
    pub sigma_px: f64,
    /// Probability that an observation is an outlier.
    pub outlier_probability: f64,
    /// Number of landmarks scattered around the trajectory.
    pub landmarks: usize,
    /// Half-size of the box the landmarks fill, m.
    pub landmark_box_m: f64,
}

impl Default for CameraConfig {
    fn default() -> Self {
        // Camera z (optical axis) along body x, camera x along −body y, camera y along −body z.
        #[rustfmt::skip]
        let t_bs = [
            0.0, 0.0, 1.0, 0.05,
            -1.0, 0.0, 0.0, 0.0,
            0.0, -1.0, 0.0, 0.0,
            0.0, 0.0, 0.0, 1.0,
        ];
        Self {
            rate_hz: 10.0,
            intrinsics: [458.0, 458.0, 367.0, 248.0],
            resolution: [752, 480],
            t_bs,
            sigma_px: 1.0,
            outlier_probability: 0.0,
            landmarks: 300,
            landmark_box_m: 20.0,
        }
    }
}

impl CameraConfig {
    /// `T_BS` as a group element (`None` if the matrix is not a rigid motion).
    #[must_use]
    pub fn body_from_camera(&self) -> Option<Se3<f64>> {
        let m = nalgebra::Matrix4::from_row_slice(&self.t_bs);
        Se3::try_from_matrix(&m)
    }
}

/// One observation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Observation {
    /// Landmark id.
    pub id: usize,
    /// Pixel `(u, v)`.
    pub pixel: Vector2<f64>,
}

/// The camera model with its landmark map.
#[derive(Clone, Debug)]
pub struct Camera {
    cfg: CameraConfig,
    noise: Noise,
    body_from_camera: Se3<f64>,
    /// Landmarks in the world frame.
    pub landmarks: Vec<Vector3<f64>>,
}

impl Camera {
    /// A camera with `cfg.landmarks` landmarks drawn uniformly in a box centred on `centre`.
    #[must_use]
    pub fn new(cfg: CameraConfig, mut noise: Noise, centre: Vector3<f64>) -> Self {
        let half = cfg.landmark_box_m;
        let landmarks = (0..cfg.landmarks)
            .map(|_| {
                centre
                    + Vector3::new(
                        (noise.uniform() * 2.0 - 1.0) * half,
                        (noise.uniform() * 2.0 - 1.0) * half,
                        (noise.uniform() * 2.0 - 1.0) * half * 0.3,
                    )
            })
            .collect();
        let body_from_camera = cfg
            .body_from_camera()
            .unwrap_or_else(|| Se3::from_parts(So3::identity(), Vector3::zeros()));
        Self {
            cfg,
            noise,
            body_from_camera,
            landmarks,
        }
    }

    /// The configuration.
    #[must_use]
    pub fn config(&self) -> &CameraConfig {
        &self.cfg
    }

    /// The observations of one frame.
    pub fn sample(&mut self, k: &Kinematics) -> Vec<Observation> {
        let c = &self.cfg;
        let world_from_camera =
            Se3::from_parts(k.attitude, k.position).compose(&self.body_from_camera);
        let camera_from_world = world_from_camera.inverse();
        let [fu, fv, cu, cv] = c.intrinsics;
        let kmat = Matrix3::new(fu, 0.0, cu, 0.0, fv, cv, 0.0, 0.0, 1.0);
        let (w, h) = (c.resolution[0] as f64, c.resolution[1] as f64);
        let mut out = Vec::new();
        for (id, p) in self.landmarks.iter().enumerate() {
            let x = camera_from_world.act(p);
            let n = self.noise.normal3();
            let (outlier, ru, rv) = (
                self.noise.uniform() < c.outlier_probability,
                self.noise.uniform(),
                self.noise.uniform(),
            );
            if x.z <= 0.1 {
                continue;
            }
            let uvw = kmat * (x / x.z);
            let mut pixel = Vector2::new(uvw.x, uvw.y);
            if !(0.0..w).contains(&pixel.x) || !(0.0..h).contains(&pixel.y) {
                continue;
            }
            pixel += Vector2::new(n.x, n.y) * c.sigma_px;
            if outlier {
                pixel = Vector2::new(ru * w, rv * h);
            }
            out.push(Observation { id, pixel });
        }
        out
    }
}

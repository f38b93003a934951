//! One aiding block: the samples of one block, averaged in a frame the gyro carries along.
//!
//! Every accelerometer and magnetometer sample is rotated into the frame of the current
//! estimate `R̂ᵢ` when it arrives and summed there. Inside a block the estimate only moves by
//! the gyro (the updates wait for the block's end), so at the end `R̂ₑᵀ R̂ᵢ` is the rotation the
//! gyro measured between sample `i` and the end, and `R̂ₑᵀ · mean(R̂ᵢ fᵢ)` is the block's mean
//! specific force seen in the body at the end, without any attitude error in it.

use crate::lie::LieGroup;
use crate::nav::mean::VectorMean;
use crate::Real;
use nalgebra::{Matrix3, Vector3};

/// The sums of one block.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Block<T: Real> {
    /// `R̂ᵢ fᵢ`: specific force in the estimate's world frame.
    pub(super) accel: VectorMean<T>,
    /// `Σ R̂ᵢ`: the bias turns with the body, so the block mean sees `R̂ₑᵀ mean(R̂ᵢ) b_a`.
    pub(super) frames: Matrix3<T>,
    /// Raw gyro `ωᵢ`, body frame.
    pub(super) gyro: VectorMean<T>,
    /// `R̂ᵢ mᵢ`: field in the estimate's world frame.
    pub(super) mag: VectorMean<T>,
    /// Length so far, ns.
    pub(super) elapsed_ns: u32,
    /// An accelerometer sample of the block was at the rail.
    pub(super) clipped: bool,
}

/// The statistics of a finished block, seen in the body at its end.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct BlockStats<T: Real> {
    /// IMU samples in it.
    pub(super) n: u32,
    /// Length, s.
    pub(super) duration: T,
    /// Mean specific force, body frame at the end.
    pub(super) accel_body: Vector3<T>,
    /// `M = R̂ₑᵀ mean(R̂ᵢ)`: the mean accelerometer bias over the block, seen at its end, is
    /// `M b_a`.
    pub(super) bias_map: Matrix3<T>,
    /// Its norm.
    pub(super) accel_norm: T,
    /// Total variance of the world-frame specific force about its mean, (m/s²)².
    pub(super) accel_scatter_sq: T,
    /// Mean raw gyro, rad/s.
    pub(super) gyro_mean: Vector3<T>,
    /// Total variance of the gyro about its mean, (rad/s)².
    pub(super) gyro_scatter_sq: T,
    /// The magnetometer samples of the block, if any.
    pub(super) mag: Option<MagStats<T>>,
}

/// The magnetometer part of a finished block.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct MagStats<T: Real> {
    /// Mean field in the body frame at the end.
    pub(super) body: Vector3<T>,
    /// Samples.
    pub(super) n: u32,
    /// Total variance of the world-frame field about its mean: a field fixed in the world
    /// shows only the white noise, one that turns with the body (a magnet on it) shows more.
    pub(super) scatter_sq: T,
}

impl<T: Real> BlockStats<T> {
    /// The RMS rate of the block about `bias`, rad/s.
    pub(super) fn rate(&self, bias: &Vector3<T>) -> T {
        let w = self.gyro_mean - bias;
        (self.gyro_scatter_sq + w.dot(&w)).sqrt_rn()
    }

    /// The rotation of the block, rad: its RMS rate about `bias` times the duration.
    pub(super) fn rotation(&self, bias: &Vector3<T>) -> T {
        self.rate(bias) * self.duration
    }
}

impl<T: Real> Default for Block<T> {
    fn default() -> Self {
        Self {
            accel: VectorMean::default(),
            frames: Matrix3::zeros(),
            gyro: VectorMean::default(),
            mag: VectorMean::default(),
            elapsed_ns: 0,
            clipped: false,
        }
    }
}

impl<T: Real> Block<T> {
    /// The world-frame sums the velocity integrates (`AhrsAccelBias::integrate_velocity`):
    /// `Σ R̂ᵢ fᵢ Δt` and `Σ R̂ᵢ Δt` over the block, as its means times its length (the samples
    /// of a block are evenly spaced), and its length `T`, s; `None` for a block without IMU
    /// samples.
    pub(super) fn world_sums(&self) -> Option<(Vector3<T>, Matrix3<T>, T)> {
        let force = self.accel.mean()?;
        let t = self.duration();
        let frames = self.frames * (t / T::from_count(self.accel.count().max(1)));
        Some((force * t, frames, t))
    }

    /// Length so far, s.
    fn duration(&self) -> T {
        T::from_count(self.elapsed_ns) * T::lit(1e-9)
    }

    /// The statistics, with `end` the estimate's attitude at the end (`R̂ₑ`); `None` for a
    /// block without IMU samples.
    pub(super) fn stats(&self, end: &crate::lie::So3<T>) -> Option<BlockStats<T>> {
        let (Some(a), Some(w)) = (self.accel.mean(), self.gyro.mean()) else {
            return None;
        };
        let to_body = end.inverse();
        let accel_body = to_body.act(&a);
        let bias_map = crate::kernels::mat3::mul(
            &to_body.rotation_matrix(),
            &(self.frames / T::from_count(self.accel.count().max(1))),
        );
        let mag = self.mag.mean().map(|m| MagStats {
            body: to_body.act(&m),
            n: self.mag.count(),
            scatter_sq: self.mag.scatter_sq(),
        });
        Some(BlockStats {
            n: self.accel.count(),
            duration: self.duration(),
            accel_norm: crate::kernels::mat3::norm(&accel_body),
            accel_body,
            bias_map,
            accel_scatter_sq: self.accel.scatter_sq(),
            gyro_mean: w,
            gyro_scatter_sq: self.gyro.scatter_sq(),
            mag,
        })
    }
}

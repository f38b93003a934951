//! What an INS navigator is told about its sensors.

use crate::kernels::{all_finite, non_negative_finite, positive_finite};
use crate::nav::attitude::AttitudeConfig;
use crate::nav::error::NavError;
use crate::Real;
use nalgebra::Vector3;

/// The INS navigator's configuration. The IMU, the magnetometer and the start-up come from
/// `attitude` (the navigator aligns with an [`AttitudeNavigator`](crate::nav::AttitudeNavigator)
/// until its first position fix); the rest is the INS's own.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InsConfig<T: Real> {
    /// The attitude navigator of the alignment, and through it the filter configuration (IMU
    /// noise, gravity, `max_dt`: an IMU interval longer than that is a gap) and the
    /// magnetometer (`attitude.magnetometer`: its sigma, its reference field).
    pub attitude: AttitudeConfig<T>,
    /// How far in the past a measurement may be stamped, s (0.3): the filter runs this far
    /// behind the newest IMU sample, and an output predictor carries its estimate to the
    /// present. The IMU buffer must hold `horizon_s × IMU rate` samples.
    pub horizon_s: T,
    /// GNSS antenna position in the body frame, m.
    pub gnss_lever_arm: Vector3<T>,
    /// The barometer's white noise per sample, m (1σ); `None`: no barometer.
    pub barometer_sigma: Option<T>,
    /// The accelerometer's range, m/s² (0: unknown): a sample with an axis at or beyond 99.9 %
    /// of it is taken as clipped, and the velocity is widened by what the clipping may hide.
    pub accelerometer_range: T,
    /// The gyro's range, rad/s (0: unknown), as `accelerometer_range`.
    pub gyro_range: T,
    /// A gyro axis that repeats its value exactly for this long while the others change, s,
    /// is taken as stuck (0: never). A real gyro's noise makes exact repeats rare, but a
    /// coarse quantization at rest makes them common: keep it well above the sample period.
    pub gyro_stuck_s: T,
    /// Consecutive rejected GNSS fixes for this long, s, reset position and velocity to the
    /// fixes (10 s): the filter's estimate is then taken for the wrong one.
    pub gnss_reset_s: T,
    /// Position valid below this 1σ, m (horizontal, the larger axis).
    pub position_valid_sigma: T,
    /// Velocity valid below this 1σ, m/s.
    pub velocity_valid_sigma: T,
    /// Attitude (tilt) valid below this 1σ, rad.
    pub tilt_valid_sigma: T,
    /// Heading valid below this 1σ, rad.
    pub heading_valid_sigma: T,
    /// Gyro bias valid below this 1σ, rad/s.
    pub gyro_bias_valid_sigma: T,
    /// Accelerometer bias valid below this 1σ, m/s².
    pub accel_bias_valid_sigma: T,
    /// How the vehicle moves against its body: whether its track lies along its body `x` axis
    /// (a car, a rover), which without a magnetometer is what finds the heading of a slow
    /// ground vehicle from its GNSS track (`nav/ins/yaw.rs`). [`Travel::Detect`] by default.
    pub travel: Travel<T>,
}

/// How a vehicle moves against its body ([`InsConfig::travel`]).
///
/// A vehicle that does not move sideways has, in its body frame, the velocity
/// `v_b = (v_x, v_y, v_z)` with `v_y ≈ 0` (`|v_y| ≤` a few `σ_l`): its GNSS track then gives its
/// heading to `σ_l/‖v‖` at any speed above the velocity's noise, not only while it accelerates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Travel<T: Real> {
    /// Learned from the GNSS track (`nav/ins/track_axis.rs`): the vehicle is taken to travel
    /// along its body `x` axis while its GNSS velocities, seen in the INS's heading frame, lie
    /// on one axis (the lateral RMS at most half the speed), with the lateral 1σ they show;
    /// a turn of the body under its track takes it back. The default: a vehicle without a
    /// magnetometer is most often a ground vehicle, and a body whose track turns under it is
    /// told apart as soon as it does.
    Detect,
    /// A vehicle that may move sideways (a multirotor, a hand-held device): the heading from
    /// the accelerations alone.
    Sideways,
    /// A vehicle that does not move sideways, with the 1σ of its lateral body velocity, m/s
    /// (slip, crab on rough ground), `> 0`.
    Forward {
        /// 1σ of the lateral body velocity, m/s.
        lateral_sigma: T,
    },
}

impl<T: Real> InsConfig<T> {
    /// Defaults around an attitude configuration: a 0.3 s horizon, no lever arm, no
    /// barometer, ranges unknown (learned), a gyro axis stuck after 0.1 s, reset after 10 s of
    /// rejected fixes;
    /// valid below 10 m, 1 m/s, 5° tilt, 10° heading, 0.05 °/s gyro bias, 0.05 m/s²
    /// accelerometer bias.
    #[must_use]
    pub fn new(attitude: AttitudeConfig<T>) -> Self {
        Self {
            attitude,
            horizon_s: T::lit(0.3),
            gnss_lever_arm: Vector3::zeros(),
            barometer_sigma: None,
            accelerometer_range: T::zero(),
            gyro_range: T::zero(),
            gyro_stuck_s: T::lit(0.1),
            gnss_reset_s: T::lit(10.0),
            position_valid_sigma: T::lit(10.0),
            velocity_valid_sigma: T::lit(1.0),
            tilt_valid_sigma: T::lit(5.0_f64.to_radians()),
            heading_valid_sigma: T::lit(10.0_f64.to_radians()),
            gyro_bias_valid_sigma: T::lit(0.05_f64.to_radians()),
            accel_bias_valid_sigma: T::lit(0.05),
            travel: Travel::Detect,
        }
    }

    /// `Ok` when every value is in its domain: the attitude configuration valid; `horizon_s`
    /// in `[0, 10]` s; the lever arm finite; ranges, stuck time and
    /// thresholds not negative; `gnss_reset_s` positive; a barometer sigma between 1 mm and
    /// 1 km; a lateral velocity sigma between 1 mm/s and 100 m/s.
    ///
    /// # Errors
    /// [`NavError::InvalidConfig`] (or the attitude configuration's error).
    pub fn validate(&self) -> Result<(), NavError> {
        self.attitude.validate()?;
        let horizon = non_negative_finite(self.horizon_s) && self.horizon_s <= T::lit(10.0);
        let baro = self
            .barometer_sigma
            .is_none_or(|s| crate::nav::sample::within_limits(s, 1e-3, 1e3));
        let lateral = match self.travel {
            Travel::Forward { lateral_sigma } => {
                crate::nav::sample::within_limits(lateral_sigma, 1e-3, 1e2)
            }
            Travel::Detect | Travel::Sideways => true,
        };
        let non_negative = [
            self.accelerometer_range,
            self.gyro_range,
            self.gyro_stuck_s,
            self.position_valid_sigma,
            self.velocity_valid_sigma,
            self.tilt_valid_sigma,
            self.heading_valid_sigma,
            self.gyro_bias_valid_sigma,
            self.accel_bias_valid_sigma,
        ]
        .iter()
        .all(|x| non_negative_finite(*x));
        let ok = horizon
            && baro
            && lateral
            && non_negative
            && positive_finite(self.gnss_reset_s)
            && self.gnss_reset_s <= T::lit(3600.0)
            && self.gyro_stuck_s <= T::lit(3600.0)
            && all_finite(self.gnss_lever_arm.as_slice());
        if ok {
            Ok(())
        } else {
            Err(NavError::InvalidConfig)
        }
    }
}

//! Footprint: the inertial navigator (`InsNavigator`) in a main loop: an IMU sample, a
//! magnetometer sample, a GNSS fix (position and velocity) and a barometer altitude per pass,
//! the estimate and the report read out. What a firmware for a GNSS-aided vehicle links. See
//! `src/footprint/mod.rs`.
#![no_std]
#![no_main]

#[path = "../footprint/mod.rs"]
mod footprint;

use estimator_core::eskf::FilterConfig;
use estimator_core::nav::{AttitudeConfig, GnssFix, InsConfig, InsNavigator, MagneticConfig};
use footprint::{entry, input, input3, keep};
use nalgebra::Vector3;

#[entry]
fn main() -> ! {
    let mut attitude = AttitudeConfig::new(FilterConfig::default());
    attitude.magnetometer = Some(MagneticConfig::new(
        input(7),
        Some(Vector3::new(0.0, 0.2, -0.4)),
    ));
    let mut config = InsConfig::new(attitude);
    config.barometer_sigma = Some(input(6));
    let Ok(mut ins) = InsNavigator::<f32>::new(config) else {
        footprint::idle();
    };
    let mut t_ns: u64 = 0;
    loop {
        t_ns += 5_000_000;
        keep(&ins.imu(t_ns, &input3(0), &input3(1)));
        keep(&ins.magnetometer(t_ns, &input3(2)));
        let fix = GnssFix::new(input3(3), Some(input3(4)), input(6), input(4));
        keep(&ins.gnss(t_ns - 1_000_000, &fix));
        keep(&ins.barometer(t_ns, input(5)));
        keep(&ins.estimate());
    }
}

//! Footprint: the attitude navigator (`AttitudeNavigator`, with its magnetometer) in a main loop:
//! one IMU sample and one magnetometer sample per pass, the estimate and the report read out.
//! What a firmware that needs only attitude links. See `src/footprint/mod.rs`.
#![no_std]
#![no_main]

#[path = "../footprint/mod.rs"]
mod footprint;

use estimator_core::eskf::FilterConfig;
use estimator_core::nav::{AttitudeConfig, AttitudeNavigator, MagneticConfig};
use footprint::{entry, input, input3, keep};
use nalgebra::Vector3;

#[entry]
fn main() -> ! {
    let mut config = AttitudeConfig::new(FilterConfig::default());
    config.magnetometer = Some(MagneticConfig::new(
        input(7),
        Some(Vector3::new(0.0, 0.2, -0.4)),
    ));
    let Ok(mut nav) = AttitudeNavigator::<f32>::new(config) else {
        footprint::idle();
    };
    let mut t_ns: u64 = 0;
    loop {
        t_ns += 5_000_000;
        keep(&nav.imu(t_ns, &input3(0), &input3(1)));
        keep(&nav.magnetometer(t_ns, &input3(2)));
        keep(&nav.estimate());
    }
}

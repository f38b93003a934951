//! Footprint: a GNSS-aided inertial navigator (the 15-state filter) fed by an IMU, GNSS position
//! and velocity, a barometer and a magnetometer. See `src/footprint/mod.rs`.
#![no_std]
#![no_main]

#[path = "../footprint/mod.rs"]
mod footprint;

use cortex_m_rt::entry;
use estimator_core::eskf::{
    BaroAltitude, FilterConfig, GnssPosition, GnssVelocity, ImuSample, Ins, InsState, Magnetometer,
    UpdateOptions,
};
use footprint::{input, input3, keep};
use nalgebra::{SMatrix, Vector3};

#[entry]
fn main() -> ! {
    let start = InsState::identity();
    let p0 = SMatrix::<f32, 15, 15>::identity() * input(7);
    let Ok(mut ins) = Ins::new(start, p0, FilterConfig::default()) else {
        loop {
            cortex_m::asm::wfi();
        }
    };
    let options = UpdateOptions::default();
    let reference = Vector3::new(0.2, 0.0, -0.4);
    let lever_arm = Vector3::new(0.1, 0.0, 0.05);
    loop {
        let imu = ImuSample {
            gyro: input3(0),
            accel: input3(1),
            dt: input(7),
        };
        keep(&ins.predict(&imu));
        keep(&ins.update(&GnssPosition::new(input3(2), lever_arm, input(6)), &options));
        keep(&ins.update(&GnssVelocity::new(input3(3), input(4)), &options));
        keep(&ins.update(&BaroAltitude::new(input(5), input(6)), &options));
        keep(&ins.update(&Magnetometer::new(input3(4), reference, input(7)), &options));
        keep(ins.state());
    }
}

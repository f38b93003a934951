//! A starting point for your firmware: the attitude navigator and the INS navigator of
//! `estimator-core` in a main loop, fed one timestamped sample at a time, every outcome handled,
//! the estimate printed once a second.
//!
//! This one file is the whole program: it builds unchanged as the `src/main.rs` of a fresh
//! `cortex-m-rt` crate (steps in `firmware/README.md`, "Starting your own firmware"; its
//! dependencies: `cortex-m`, `cortex-m-rt`, `cortex-m-semihosting` and `estimator-core`, plus a
//! `memory.x` for your chip). It carries its own panic handler. Three parts are stand-ins, each
//! marked "REPLACE":
//!
//! * [`Board`]: a simulated sensor source. Replace it with your drivers (IMU, magnetometer,
//!   GNSS receiver) and your clock.
//! * `report!` and `finish`: output and exit over semihosting, which needs a debugger (or
//!   QEMU) attached; on a board running alone a semihosting call stops the core. Replace them
//!   with your telemetry (UART, RTT, a log crate) and with what your product does at the end.
//! * the self-check at the end of `main`: it compares the estimate with the stand-in's truth.
//!   Your firmware runs forever instead, and has no truth to compare with.
//!
//! In this repository CI builds it for the Cortex-M4F and runs it under QEMU
//! (`firmware/src/bin/starter.rs` adds the board's vector table around this file; by hand:
//! `cargo build-m4 --release --bin starter` in `firmware/`, then
//! `qemu-system-arm -machine mps2-an386 -cpu cortex-m4 -nographic -monitor none -serial none
//! -semihosting-config enable=on,target=native -kernel target/thumbv7em-none-eabihf/release/starter`).
//! It exits with status 0 when, after 10 s, the attitude navigator reports a valid tilt and
//! heading within 2° of the stand-in's truth and the INS navigator a valid position within 2 m
//! of it; `firmware/tools/starter-check.sh` builds it as a fresh crate's `src/main.rs`.
//!
//! * `AttitudeNavigator` owns its `AhrsAccelBias` filter, its start-up, what it fuses and when,
//!   rest detection and magnetic disturbances; the loop only passes samples and reads reports.
//! * `InsNavigator` owns the 15-state filter: it aligns until the first fix, fuses every
//!   measurement at the time it was valid (a fix read now describes the time the receiver's
//!   latency ago: stamp it with that time), handles frozen, jumping and drifting fixes and IMU
//!   faults, and reports each quantity's validity after every call. A device with GNSS needs only
//!   this one; the attitude navigator is for a device without.
//! * The noise values come from the sensor (`host-sim calibrate` measures them from a static
//!   recording); the navigator's other parameters are explained in the `nav` module docs of
//!   `estimator-core` (its tuning guide).
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use cortex_m_semihosting::{debug, hprintln};
use estimator_core::eskf::{FilterConfig, ImuNoise};
use estimator_core::lie::{LieGroup, So3};
// estimator-core re-exports the nalgebra it is built with: no version to keep in step.
use estimator_core::nalgebra::Vector3;
use estimator_core::nav::{
    AttitudeConfig, AttitudeNavigator, GnssFix, InsConfig, InsNavigator, MagneticConfig, NavError,
};

/// REPLACE with your telemetry: one line of output (here over semihosting, which needs a
/// debugger or QEMU attached).
macro_rules! report {
    ($($arg:tt)*) => {
        hprintln!($($arg)*)
    };
}

const IMU_HZ: u64 = 200;
const STEP_NS: u64 = 1_000_000_000 / IMU_HZ;
/// The world magnetic field, µT, ENU (north along `y`, pointing down).
const FIELD: [f32; 3] = [0.0, 20.0, -45.0];
/// The stand-in receiver's latency: a fix arrives this long after the time it describes, ns.
const GNSS_LATENCY_NS: u64 = 200_000_000;

/// REPLACE with your drivers: this is a stand-in sensor source, not hardware. It simulates a
/// level body at rest for 2 s, then turning about the vertical at 10 °/s, read by an IMU at
/// 200 Hz, a magnetometer at 50 Hz and GNSS at 5 Hz, with a small deterministic noise. Your
/// version reads the sensors (or their interrupt-filled queues) and stamps each sample with
/// your clock, in nanoseconds.
struct Board {
    k: u64,
}

impl Board {
    /// The yaw of the stand-in's body at sample `k`, rad.
    fn yaw(k: u64) -> f32 {
        let t = k as f32 / IMU_HZ as f32;
        if t < 2.0 {
            0.0
        } else {
            0.174_532_93 * (t - 2.0)
        }
    }

    /// A noise in `[−s, s]`.
    fn noise(&self, axis: u32, s: f32) -> f32 {
        let x = self
            .k
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(u64::from(axis).wrapping_mul(1_442_695_040_888_963_407))
            >> 40;
        ((x as u32) as f32 / 16_777_216.0 - 0.5) * 2.0 * s
    }

    fn noise3(&self, axis: u32, s: f32) -> Vector3<f32> {
        Vector3::new(
            self.noise(axis, s),
            self.noise(axis + 1, s),
            self.noise(axis + 2, s),
        )
    }

    /// The next IMU sample: time (ns), gyro (rad/s), accelerometer (m/s²).
    fn imu(&mut self) -> (u64, Vector3<f32>, Vector3<f32>) {
        self.k += 1;
        let rate = if Self::yaw(self.k) > 0.0 {
            0.174_532_93
        } else {
            0.0
        };
        let gyro = Vector3::new(0.002, -0.001, rate) + self.noise3(0, 0.003);
        let accel = Vector3::new(0.0, 0.0, 9.81) + self.noise3(3, 0.03);
        (self.t_ns(), gyro, accel)
    }

    /// A magnetometer sample (µT), every fourth IMU sample.
    fn magnetometer(&self) -> Option<Vector3<f32>> {
        let attitude = So3::exp(&Vector3::new(0.0, 0.0, Self::yaw(self.k)));
        self.k
            .is_multiple_of(4)
            .then(|| attitude.inverse().act(&Vector3::from(FIELD)) + self.noise3(6, 0.3))
    }

    /// A GNSS position fix (m, ENU), every fortieth IMU sample.
    fn gnss(&self) -> Option<Vector3<f32>> {
        self.k.is_multiple_of(40).then(|| self.noise3(9, 0.5))
    }

    fn t_ns(&self) -> u64 {
        1_000_000_000 + self.k * STEP_NS
    }
}

#[entry]
fn main() -> ! {
    let filter = FilterConfig {
        imu_noise: ImuNoise {
            gyroscope_noise_density: 2e-4,
            gyroscope_random_walk: 2e-5,
            accelerometer_noise_density: 2e-3,
            accelerometer_random_walk: 3e-3,
        },
        ..FilterConfig::default()
    };
    let mut config = AttitudeConfig::new(filter);
    config.magnetometer = Some(MagneticConfig::new(0.3, Some(Vector3::from(FIELD))));
    let Ok(mut nav) = AttitudeNavigator::new(config) else {
        finish(false, "navigator configuration refused");
    };
    // The INS navigator: the same attitude configuration (it aligns with it until the first fix).
    let Ok(mut ins) = InsNavigator::<f32>::new(InsConfig::new(config)) else {
        finish(false, "INS navigator configuration refused");
    };
    let mut board = Board { k: 0 };

    while board.k < 10 * IMU_HZ {
        let (t_ns, gyro, accel) = board.imu();
        match nav.imu(t_ns, &gyro, &accel) {
            Ok(report) => {
                if let Some(event) = report.event {
                    report!("{} ms navigator: {:?}", t_ns / 1_000_000, event);
                }
            }
            // Refused: the navigator is as it was; the next sample is taken normally.
            Err(e) => report!("IMU sample refused: {}", e),
        }
        if let Some(field) = board.magnetometer() {
            if let Err(e) = nav.magnetometer(t_ns, &field) {
                report!("magnetometer sample refused: {}", e);
            }
        }
        match ins.imu(t_ns, &gyro, &accel) {
            Ok(report) => {
                if let Some(event) = report.event {
                    report!("{} ms INS: {:?}", t_ns / 1_000_000, event);
                }
            }
            Err(e) => report!("INS: IMU sample refused: {}", e),
        }
        if let Some(field) = board.magnetometer() {
            if let Err(e) = ins.magnetometer(t_ns, &field) {
                report!("INS: magnetometer sample refused: {}", e);
            }
        }
        if let Some(position) = board.gnss() {
            // The stand-in's receiver delivers its fix 0.2 s after the time it describes.
            let fix = GnssFix::new(position, Some(Vector3::zeros()), 1.0, 0.1);
            match ins.gnss(t_ns.saturating_sub(GNSS_LATENCY_NS), &fix) {
                Ok(_) => {}
                // Older than the horizon (a fix before the filter's start): dropped.
                Err(NavError::TooOld) => report!("GNSS fix older than the horizon"),
                Err(e) => report!("GNSS fix refused: {}", e),
            }
        }
        if board.k.is_multiple_of(IMU_HZ) {
            if let Some(e) = nav.estimate() {
                let (roll, pitch, yaw) = e.attitude.quaternion().euler_angles();
                // Millidegrees: integers print without the float formatter.
                let mdeg = |x: f32| (x * 57_295.78) as i32;
                report!(
                    "{} s roll {} pitch {} yaw {} mdeg, 1σ heading {} mdeg",
                    board.k / IMU_HZ,
                    mdeg(roll),
                    mdeg(pitch),
                    mdeg(yaw),
                    mdeg(e.sigma_heading)
                );
            }
        }
    }
    // REPLACE: the self-check against the stand-in's truth (your firmware keeps looping).
    // The check: valid, and within 2° of the stand-in's truth.
    let report = *nav.report();
    let ok = match nav.estimate() {
        Some(e) => {
            let truth = So3::exp(&Vector3::new(0.0, 0.0, Board::yaw(board.k)));
            let error = e.attitude.inverse().compose(&truth).log().norm();
            let position_ok = ins
                .estimate()
                .is_some_and(|e| e.state.position.norm() < 2.0)
                && ins.report().validity.position.is_valid();
            report.tilt.is_valid() && report.heading.is_valid() && error < 0.035 && position_ok
        }
        None => false,
    };
    finish(
        ok,
        "after 10 s: attitude within 2°, tilt and heading valid; INS position valid within 2 m",
    )
}

/// REPLACE with what your firmware does at the end: prints the verdict and exits with its
/// status through semihosting (QEMU's exit code; a debugger ends the session).
fn finish(ok: bool, what: &str) -> ! {
    report!("{} {}", if ok { "PASS" } else { "FAIL" }, what);
    debug::exit(if ok {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    loop {
        cortex_m::asm::nop();
    }
}

/// On a panic: prints it and exits with a failure. estimator-core itself has no panic path
/// (checked at link time in its CI); this handler is for the rest of your firmware. REPLACE it
/// with yours, or delete it and depend on `panic-halt` (`use panic_halt as _;`).
#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    report!("PANIC {}", info);
    debug::exit(debug::EXIT_FAILURE);
    loop {
        cortex_m::asm::nop();
    }
}

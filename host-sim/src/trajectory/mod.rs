//! Smooth ground-truth trajectories with exact derivatives.
//!
//! A trajectory is a position `p(τ)` and ZYX Euler angles `(φ, θ, ψ)(τ)` (roll, pitch, yaw), each a
//! sum of sinusoids and a linear term in a warped time `τ(t)`, plus optionally a circular [`Track`]
//! in `x, y` whose along-track phase `α(τ)` is itself such a signal (a vehicle driving a circle
//! at a varying speed). The warp holds `τ = 0` during the initial static period and then
//! accelerates smoothly to `τ̇ = 1` (a quintic smoothstep on `τ̇`, so position, velocity and
//! acceleration are continuous), which makes every trajectory start at rest whatever its shape. Derivatives follow from the chain rule, never from differencing:
//!
//! * `ṗ = p'(τ) τ̇`, `p̈ = p''(τ) τ̇² + p'(τ) τ̈`;
//! * a track adds `r (sin α, −cos α)` to `(x, y)`, so `(x, y)' = r α' (cos α, sin α)` and
//!   `(x, y)'' = r α'' (cos α, sin α) + r α'² (−sin α, cos α)`;
//! * `R = R_z(ψ) R_y(θ) R_x(φ)` maps body into world (`world_from_body`);
//! * body angular rate `ω_b = [φ̇ − ψ̇ sθ, θ̇ cφ + ψ̇ cθ sφ, −θ̇ sφ + ψ̇ cθ cφ]`.
//!
//! The IMU then measures `ω_b` and the specific force `Rᵀ(p̈ − g)` exactly (see `sensors`).

use estimator_core::lie::{LieGroup, So3};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// One term of a scalar signal: `amplitude · sin(2π·frequency_hz·τ + phase)`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sine {
    /// Amplitude (m or rad).
    pub amplitude: f64,
    /// Frequency in Hz.
    pub frequency_hz: f64,
    /// Phase in rad.
    #[serde(default)]
    pub phase: f64,
}

/// A scalar signal `offset + rate·τ + Σ sines`, with its first two derivatives.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Signal {
    /// Constant offset.
    #[serde(default)]
    pub offset: f64,
    /// Linear rate (unit per second).
    #[serde(default)]
    pub rate: f64,
    /// Sinusoidal terms.
    #[serde(default)]
    pub sines: Vec<Sine>,
}

impl Signal {
    /// A constant.
    #[must_use]
    pub fn constant(offset: f64) -> Self {
        Self {
            offset,
            ..Self::default()
        }
    }

    /// `(s, s', s'')` at `τ`.
    #[must_use]
    pub fn eval(&self, tau: f64) -> (f64, f64, f64) {
        let mut v = self.offset + self.rate * tau;
        let mut d1 = self.rate;
        let mut d2 = 0.0;
        for s in &self.sines {
            let w = 2.0 * std::f64::consts::PI * s.frequency_hz;
            let (sn, cs) = (w * tau + s.phase).sin_cos();
            v += s.amplitude * sn;
            d1 += s.amplitude * w * cs;
            d2 -= s.amplitude * w * w * sn;
        }
        (v, d1, d2)
    }

    fn with(mut self, amplitude: f64, frequency_hz: f64, phase: f64) -> Self {
        self.sines.push(Sine {
            amplitude,
            frequency_hz,
            phase,
        });
        self
    }
}

/// A circle of radius `r` about the origin of `x, y`, driven along: `(x, y) += r (sin α, −cos α)`
/// with the along-track phase `α(τ)` a [`Signal`] (module docs). The direction of travel is `α`
/// (for `α' > 0`, counter-clockwise) and the speed along the track `r α'(τ) τ̇`, so a yaw equal
/// to `α` keeps the body's x axis along the track. Move the circle with the position's offsets.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Track {
    /// Radius, m.
    pub radius: f64,
    /// Along-track phase `α`, rad.
    pub phase: Signal,
}

impl Track {
    /// `(x, y)` and their first two derivatives in `τ`, as `[(x, x', x''), (y, y', y'')]`.
    fn eval(&self, tau: f64) -> [(f64, f64, f64); 2] {
        let r = self.radius;
        let (a, d1, d2) = self.phase.eval(tau);
        let (sn, cs) = a.sin_cos();
        [
            (r * sn, r * d1 * cs, r * (d2 * cs - d1 * d1 * sn)),
            (-r * cs, r * d1 * sn, r * (d2 * sn + d1 * d1 * cs)),
        ]
    }
}

/// The true state at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Kinematics {
    /// Time since the start of the trajectory, s.
    pub t: f64,
    /// Position in the world frame (ENU), m.
    pub position: Vector3<f64>,
    /// Velocity in the world frame, m/s.
    pub velocity: Vector3<f64>,
    /// Acceleration in the world frame, m/s².
    pub acceleration: Vector3<f64>,
    /// `world_from_body` rotation.
    pub attitude: So3<f64>,
    /// Angular rate of the body relative to the world, in body axes, rad/s.
    pub omega_body: Vector3<f64>,
}

/// An analytic trajectory: see the module docs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Trajectory {
    /// Length of the initial static period, s.
    pub static_s: f64,
    /// Duration of the smooth start after it, s.
    pub ramp_s: f64,
    /// `x, y, z` of the position, m.
    pub position: [Signal; 3],
    /// Roll, pitch, yaw (ZYX), rad.
    pub euler: [Signal; 3],
    /// A circular track added to `x, y`, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub track: Option<Track>,
}

impl Trajectory {
    /// Warped time `(τ, τ̇, τ̈)` at `t` (module docs).
    fn warp(&self, t: f64) -> (f64, f64, f64) {
        let t = t - self.static_s;
        if t <= 0.0 {
            return (0.0, 0.0, 0.0);
        }
        let r = self.ramp_s.max(1e-9);
        if t >= r {
            // ∫₀¹ S = 1/2.
            return (0.5 * r + (t - r), 1.0, 0.0);
        }
        let u = t / r;
        let (u2, u3) = (u * u, u * u * u);
        let s = u3 * (10.0 - 15.0 * u + 6.0 * u2);
        let ds = 30.0 * u2 * (1.0 - u) * (1.0 - u);
        let integral = u2 * u2 * (2.5 - 3.0 * u + u2);
        (r * integral, s, ds / r)
    }

    /// The state at time `t` (s).
    #[must_use]
    pub fn at(&self, t: f64) -> Kinematics {
        let (tau, dtau, ddtau) = self.warp(t);
        let mut position = Vector3::zeros();
        let mut velocity = Vector3::zeros();
        let mut acceleration = Vector3::zeros();
        let track = self.track.as_ref().map(|t| t.eval(tau));
        for (i, s) in self.position.iter().enumerate() {
            let (mut v, mut d1, mut d2) = s.eval(tau);
            if let Some((tv, t1, t2)) = track.and_then(|t| t.get(i).copied()) {
                v += tv;
                d1 += t1;
                d2 += t2;
            }
            position[i] = v;
            velocity[i] = d1 * dtau;
            acceleration[i] = d2 * dtau * dtau + d1 * ddtau;
        }
        let mut ang = [0.0; 3];
        let mut rate = [0.0; 3];
        for (i, s) in self.euler.iter().enumerate() {
            let (v, d1, _) = s.eval(tau);
            ang[i] = v;
            rate[i] = d1 * dtau;
        }
        let [roll, pitch, yaw] = ang;
        let [droll, dpitch, dyaw] = rate;
        let attitude = So3::exp(&(Vector3::z() * yaw))
            .compose(&So3::exp(&(Vector3::y() * pitch)))
            .compose(&So3::exp(&(Vector3::x() * roll)));
        let (sr, cr) = roll.sin_cos();
        let (sp, cp) = pitch.sin_cos();
        let omega_body = Vector3::new(
            droll - dyaw * sp,
            dpitch * cr + dyaw * cp * sr,
            -dpitch * sr + dyaw * cp * cr,
        );
        Kinematics {
            t,
            position,
            velocity,
            acceleration,
            attitude,
            omega_body,
        }
    }
}

/// The built-in trajectory shapes (`static_s` of rest first in every one).
#[must_use]
pub fn builtin(shape: &str, static_s: f64) -> Option<Trajectory> {
    let zero = || Signal::constant(0.0);
    let ramp_s = 2.0;
    let t = match shape {
        "static" => Trajectory {
            static_s,
            ramp_s,
            position: [zero(), zero(), Signal::constant(1.0)],
            euler: [
                Signal::constant(0.02),
                Signal::constant(-0.03),
                Signal::constant(0.5),
            ],
            track: None,
        },
        // Hover with small attitude oscillations and a 23–27 Hz vibration of 0.1 mm (about 0.25 g).
        "hover" => Trajectory {
            static_s,
            ramp_s,
            position: [
                zero().with(0.3, 0.05, 0.0).with(0.0001, 25.0, 0.0),
                zero().with(0.3, 0.07, 1.0).with(0.0001, 27.0, 0.5),
                Signal::constant(1.5)
                    .with(0.2, 0.04, 0.0)
                    .with(0.00015, 23.0, 0.2),
            ],
            euler: [
                zero().with(0.05, 0.3, 0.0),
                zero().with(0.05, 0.25, 1.0),
                Signal::constant(0.3).with(0.4, 0.03, 0.0),
            ],
            track: None,
        },
        // Figure-eight flight at ~3 m/s with banking.
        "figure8" => {
            let f = 1.0 / 20.0;
            Trajectory {
                static_s,
                ramp_s,
                position: [
                    zero().with(10.0, f, 0.0),
                    zero().with(5.0, 2.0 * f, 0.0),
                    Signal::constant(2.0).with(0.5, f, 0.5),
                ],
                euler: [
                    zero().with(0.25, f, 0.0),
                    zero().with(0.15, 2.0 * f, 0.3),
                    Signal::constant(0.4).with(1.0, f, 1.2),
                ],
                track: None,
            }
        }
        // A car-like planar drive: a circle of radius 15 m at ~2.5 m/s with the heading along
        // the track (yaw = ωτ), and a lane-change wiggle.
        "car" => {
            let radius = 15.0;
            let f = 2.5 / (2.0 * std::f64::consts::PI * radius);
            let w = 2.0 * std::f64::consts::PI * f;
            Trajectory {
                static_s,
                ramp_s,
                position: [
                    zero().with(radius, f, 0.0),
                    Signal::constant(radius).with(radius, f, std::f64::consts::FRAC_PI_2 * 3.0),
                    Signal::constant(0.3),
                ],
                euler: [
                    zero().with(0.02, 0.5, 0.0),
                    zero().with(0.01, 0.7, 0.0),
                    Signal {
                        offset: 0.0,
                        rate: w,
                        sines: vec![],
                    }
                    .with(0.05, 0.2, 0.0),
                ],
                track: None,
            }
        }
        // A slow rover on rough ground: a 15 m circle (a `Track`) at 0.35 m/s on average, the
        // along-track phase α = Ωτ + two sines taking the speed over 0.23–0.47 m/s; yaw = α plus
        // a 1° crab. Terrain waves of height h at frequency f come with the pitch of their slope
        // at the mean speed, θ = −ż/v̄ (8° and 5°, body z velocity near zero); roll 8° and 5°.
        "rover" => {
            use std::f64::consts::{FRAC_PI_2, TAU};
            let deg = std::f64::consts::PI / 180.0;
            let (radius, speed) = (15.0, 0.35);
            // A speed swing of `dv` m/s at `f` Hz is a phase sine of dv / (r·2πf) rad.
            let swing = |dv: f64, f: f64| dv / (radius * TAU * f);
            let phase = Signal {
                offset: 0.0,
                rate: speed / radius,
                sines: vec![],
            }
            .with(swing(0.08, 0.02), 0.02, 0.0)
            .with(swing(0.04, 0.07), 0.07, 1.0);
            // Height h·sin(2πfτ + p) for a pitch amplitude θ: h = θ·v̄ / 2πf.
            let terrain = [(8.0 * deg, 0.05, 0.3), (5.0 * deg, 0.2, 2.0)];
            let mut height = Signal::constant(0.5);
            let mut pitch = zero();
            for (theta, f, p) in terrain {
                height = height.with(theta * speed / (TAU * f), f, p);
                pitch = pitch.with(-theta, f, p + FRAC_PI_2);
            }
            let yaw = phase.clone().with(1.0 * deg, 0.1, 0.5);
            Trajectory {
                static_s,
                ramp_s,
                position: [zero(), Signal::constant(radius), height],
                euler: [
                    zero().with(8.0 * deg, 0.07, 0.0).with(5.0 * deg, 0.29, 1.3),
                    pitch,
                    yaw,
                ],
                track: Some(Track { radius, phase }),
            }
        }
        // The rover driving back and forth: its speed along the track swings by 0.6 m/s every
        // 200 s about 0.35 m/s, so that it reverses (down to -0.25 m/s) for about a third of
        // each swing, its body x axis still along the track's forward direction.
        "rover_reversing" => {
            let mut t = builtin("rover", static_s)?;
            let radius = 15.0;
            let reverse = 0.6 / (radius * std::f64::consts::TAU * 0.005);
            let phase = Signal {
                offset: 0.0,
                rate: 0.35 / radius,
                sines: vec![],
            }
            .with(reverse, 0.005, 0.0);
            t.euler[2] = phase.clone().with(1.0_f64.to_radians(), 0.1, 0.5);
            t.track = Some(Track { radius, phase });
            t
        }
        // Aggressive coning: roll and pitch in quadrature at 2 Hz, 0.3 rad.
        "coning" => Trajectory {
            static_s,
            ramp_s,
            position: [zero(), zero(), Signal::constant(1.0)],
            euler: [
                zero().with(0.3, 2.0, std::f64::consts::FRAC_PI_2),
                zero().with(0.3, 2.0, 0.0),
                Signal::constant(0.2),
            ],
            track: None,
        },
        // Pitch through ±90°: pitch amplitude 1.9 rad.
        "pitch90" => Trajectory {
            static_s,
            ramp_s,
            position: [
                zero().with(2.0, 0.05, 0.0),
                zero().with(2.0, 0.05, std::f64::consts::FRAC_PI_2),
                Signal::constant(1.5),
            ],
            euler: [
                zero().with(0.1, 0.13, 0.0),
                zero().with(1.9, 0.08, 0.0),
                Signal::constant(0.7).with(0.5, 0.05, 0.0),
            ],
            track: None,
        },
        // Hand-held-like motion: several incommensurate frequencies on every axis.
        "handheld" => Trajectory {
            static_s,
            ramp_s,
            position: [
                zero()
                    .with(0.6, 0.11, 0.0)
                    .with(0.1, 0.7, 0.4)
                    .with(1.5, 0.031, 0.0),
                zero()
                    .with(0.5, 0.13, 1.0)
                    .with(0.1, 0.9, 0.1)
                    .with(1.2, 0.027, 0.3),
                Signal::constant(1.2)
                    .with(0.2, 0.17, 0.5)
                    .with(0.05, 1.1, 0.0),
            ],
            euler: [
                zero().with(0.4, 0.21, 0.0).with(0.1, 0.9, 0.3),
                zero().with(0.35, 0.17, 1.0).with(0.1, 1.3, 0.2),
                Signal::constant(0.3)
                    .with(1.2, 0.05, 0.0)
                    .with(0.2, 0.6, 0.7),
            ],
            track: None,
        },
        // The hand-held rotations, in place (no linear acceleration).
        "rotate" => {
            let mut t = builtin("handheld", static_s)?;
            t.position = [zero(), zero(), Signal::constant(1.2)];
            t
        }
        _ => return None,
    };
    Some(t)
}

/// Names of the built-in shapes.
pub const SHAPES: [&str; 10] = [
    "static",
    "hover",
    "figure8",
    "car",
    "rover",
    "rover_reversing",
    "coning",
    "pitch90",
    "handheld",
    "rotate",
];

#[cfg(test)]
mod tests {
    use super::*;

    /// The analytic derivatives agree with central differences of the analytic values.
    #[test]
    fn derivatives_match_differences() {
        for shape in SHAPES {
            let traj = builtin(shape, 1.0).expect("builtin");
            for &t in &[0.5, 1.3, 2.7, 5.0, 17.3, 41.0] {
                // Small step: the 25 Hz vibration has large third derivatives (truncation ∝ h²).
                let h = 1e-6;
                let k = traj.at(t);
                let (a, b) = (traj.at(t - h), traj.at(t + h));
                let v_fd = (b.position - a.position) / (2.0 * h);
                let a_fd = (b.velocity - a.velocity) / (2.0 * h);
                assert!((v_fd - k.velocity).amax() < 1e-6, "{shape} v at {t}");
                assert!((a_fd - k.acceleration).amax() < 1e-5, "{shape} a at {t}");
                // ω_b from the rotation: log(R(t−h)ᵀ R(t+h)) / 2h.
                let w_fd = a.attitude.between(&b.attitude).log() / (2.0 * h);
                assert!(
                    (w_fd - k.omega_body).amax() < 1e-6,
                    "{shape} ω at {t}: {w_fd:?} vs {:?}",
                    k.omega_body
                );
            }
            // At rest during the static period.
            let k = traj.at(0.5);
            assert_eq!(k.velocity, Vector3::zeros());
            assert_eq!(k.acceleration, Vector3::zeros());
            assert_eq!(k.omega_body, Vector3::zeros());
        }
    }
}

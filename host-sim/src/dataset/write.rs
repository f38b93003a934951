//! `host-sim simulate`: a scenario and a seed into a dataset folder, byte-for-byte reproducible.
//!
//! Each sensor is sampled at its own exact times `start + round(j·10⁹/rate)` ns from the analytic
//! trajectory, those in `[record_from_s, duration_s]` (see [`Scenario::record_from_s`]); the IMU
//! loop also writes the ground truth. The folder is written under a temporary name and renamed
//! when complete, so a failed run leaves nothing that looks finished.
//!
//! A scenario with faults also gets `faults.csv` at the dataset root, one interval of the rows
//! each fault changes a line ([`faults`], read back by [`super::read::read_faults`]); other tools
//! ignore the file, and a scenario without faults gets none.

use super::read::FaultInterval;
use super::DatasetError;
use crate::scenario::Scenario;
use crate::sensors::baro::Baro;
use crate::sensors::camera::Camera;
use crate::sensors::gnss::Gnss;
use crate::sensors::imu::Imu;
use crate::sensors::mag::Mag;
use crate::sensors::Noise;
use crate::trajectory::Trajectory;
use nalgebra::Vector3;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// Stream ids: one random stream per sensor.
const STREAM_IMU: u64 = 1;
const STREAM_MAG: u64 = 2;
const STREAM_GNSS: u64 = 3;
const STREAM_CAMERA: u64 = 4;
const STREAM_BARO: u64 = 5;

/// Timestamp in ns of sample `j` of a `rate_hz` stream.
#[must_use]
pub fn stamp_ns(start_ns: u64, j: u64, rate_hz: f64) -> u64 {
    start_ns + (j as f64 * 1e9 / rate_hz).round() as u64
}

fn samples(duration_s: f64, rate_hz: f64) -> u64 {
    (duration_s * rate_hz).floor() as u64 + 1
}

/// The indices `j` of the samples of a `rate_hz` stream that `sc` records: those stamped from
/// `record_from_s` to `duration_s`.
fn recorded(sc: &Scenario, rate_hz: f64) -> std::ops::Range<u64> {
    let from_ns = (sc.record_from_s.max(0.0) * 1e9).round() as u64;
    let mut j = (sc.record_from_s.max(0.0) * rate_hz).ceil() as u64;
    // Settle the rounding of the stamps: the first j stamped at or after the start.
    while j > 0 && stamp_ns(0, j - 1, rate_hz) >= from_ns {
        j -= 1;
    }
    while stamp_ns(0, j, rate_hz) < from_ns {
        j += 1;
    }
    j..samples(sc.duration_s, rate_hz)
}

struct Out {
    dir: PathBuf,
}

impl Out {
    fn create(&self, rel: &str) -> Result<BufWriter<File>, DatasetError> {
        let path = self.dir.join(rel);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).map_err(|e| DatasetError::file(parent, e))?;
        }
        File::create(&path)
            .map(BufWriter::new)
            .map_err(|e| DatasetError::file(&path, e))
    }

    fn write(&self, rel: &str, text: &str) -> Result<(), DatasetError> {
        let mut f = self.create(rel)?;
        f.write_all(text.as_bytes())
            .and_then(|()| f.flush())
            .map_err(|e| DatasetError::file(&self.dir.join(rel), e))
    }
}

fn io(path: &Path) -> impl Fn(std::io::Error) -> DatasetError + '_ {
    move |e| DatasetError::file(path, e)
}

/// Writes the dataset of `scenario` with `seed` into the folder `dir` (created if absent; the
/// command line gives it a fresh folder, see [`crate::output`]).
pub fn simulate(scenario: &Scenario, seed: u64, dir: &Path) -> Result<(), DatasetError> {
    let traj = scenario
        .trajectory()
        .map_err(|e| DatasetError::file(dir, e))?;
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    let out = Out {
        dir: dir.to_path_buf(),
    };
    write_all(scenario, &traj, seed, &out)?;
    let replay = toml::to_string(&scenario.replay).map_err(|e| DatasetError::file(dir, e))?;
    out.write("replay.toml", &format!("# How host-sim runs the filter on this dataset (host-sim replay reads it when no --config is given).\n{replay}"))?;
    let faults = faults(scenario);
    if !faults.is_empty() {
        let mut text = String::from("#start [ns],end [ns],sensor,kind\n");
        for f in &faults {
            text += &format!("{},{},{},{}\n", f.start_ns, f.end_ns, f.sensor, f.kind);
        }
        out.write("faults.csv", &text)?;
    }
    Ok(())
}

/// The faults of `scenario` as `faults.csv` lists them, ordered by start: for each, the
/// interval `[start_ns, end_ns)` of the timestamps of the rows it changes, in the dataset's clock
/// (the scenario's `start_ns` plus its times in seconds). GNSS steps and freezes go by the state time
/// of a fix, so their rows are stamped one latency later (see [`crate::sensors::gnss`]); GNSS
/// outliers, drawn fix by fix, are one `gnss,outliers` row from the first fix to just after the
/// last. Sensors the scenario does not have contribute nothing.
#[must_use]
pub fn faults(scenario: &Scenario) -> Vec<FaultInterval> {
    let t0 = scenario.start_ns;
    // Seconds to the dataset's clock, as `stamp_ns` does (validated times are non-negative).
    let ns = |s: f64| t0 + (s * 1e9).round() as u64;
    let mut rows = Vec::new();
    let mut add = |start: f64, end: f64, sensor: &str, kind: &str| {
        rows.push(FaultInterval {
            start_ns: ns(start),
            end_ns: ns(end),
            sensor: sensor.into(),
            kind: kind.into(),
        });
    };
    let imu = &scenario.imu;
    for f in &imu.accel_clip {
        add(f[0], f[1], "imu", "clip");
    }
    for f in &imu.gyro_stuck {
        add(f[0], f[1], "imu", "stuck");
    }
    if let Some(c) = &scenario.mag {
        for f in &c.disturbances {
            add(f[0], f[1], "mag", "disturbance");
        }
        for f in &c.rotated {
            add(f[0], f[1], "mag", "rotated");
        }
    }
    if let Some(c) = &scenario.gnss {
        for f in &c.outages {
            add(f[0], f[1], "gnss", "outage");
        }
        // A fix stamped t has state time max(t − latency, 0): a time after 0 moves by the
        // latency, 0 itself covers the fixes stamped before the latency too.
        let stamped = |s: f64| if s > 0.0 { s + c.latency_s } else { s };
        for f in &c.steps {
            add(stamped(f[0]), stamped(f[1]), "gnss", "step");
        }
        for f in &c.frozen {
            add(stamped(f[0]), stamped(f[1]), "gnss", "frozen");
        }
    }
    if let Some(c) = &scenario.baro {
        for f in &c.steps {
            add(f[0], f[1], "baro", "step");
        }
    }
    if let Some(c) = scenario
        .gnss
        .as_ref()
        .filter(|c| c.outlier_probability > 0.0 && !recorded(scenario, c.rate_hz).is_empty())
    {
        let fixes = recorded(scenario, c.rate_hz);
        rows.push(FaultInterval {
            start_ns: stamp_ns(t0, fixes.start, c.rate_hz),
            end_ns: stamp_ns(t0, fixes.end - 1, c.rate_hz) + 1,
            sensor: "gnss".into(),
            kind: "outliers".into(),
        });
    }
    rows.sort_by_key(|f| (f.start_ns, f.end_ns));
    rows
}

fn write_all(sc: &Scenario, traj: &Trajectory, seed: u64, out: &Out) -> Result<(), DatasetError> {
    let gravity = Vector3::from(sc.gravity);
    let t0 = sc.start_ns;
    let at = |t: f64| traj.at(t);

    // IMU and ground truth.
    let c = &sc.imu;
    out.write(
        "imu0/sensor.yaml",
        &format!(
            "sensor_type: imu\nrate_hz: {}\ngyroscope_noise_density: {:e}\ngyroscope_random_walk: {:e}\naccelerometer_noise_density: {:e}\naccelerometer_random_walk: {:e}\n",
            c.rate_hz, c.gyroscope_noise_density, c.gyroscope_random_walk, c.accelerometer_noise_density, c.accelerometer_random_walk
        ),
    )?;
    let mut imu = Imu::new(c.clone(), gravity, Noise::new(seed, STREAM_IMU));
    let imu_path = out.dir.join("imu0/data.csv");
    let gt_path = out.dir.join("state_groundtruth_estimate0/data.csv");
    let mut fi = out.create("imu0/data.csv")?;
    let mut fg = out.create("state_groundtruth_estimate0/data.csv")?;
    writeln!(fi, "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]").map_err(io(&imu_path))?;
    writeln!(fg, "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], b_a_RS_S_z [m s^-2]").map_err(io(&gt_path))?;
    for j in recorded(sc, c.rate_hz) {
        let ns = stamp_ns(t0, j, c.rate_hz);
        let k = at((ns - t0) as f64 * 1e-9);
        let s = imu.sample(&k);
        writeln!(
            fi,
            "{ns},{:.9},{:.9},{:.9},{:.9},{:.9},{:.9}",
            s.gyro.x, s.gyro.y, s.gyro.z, s.accel.x, s.accel.y, s.accel.z
        )
        .map_err(io(&imu_path))?;
        let q = k.attitude.quaternion();
        let (p, v, bg, ba) = (k.position, k.velocity, s.gyro_bias, s.accel_bias);
        writeln!(
            fg,
            "{ns},{:.9},{:.9},{:.9},{:.12},{:.12},{:.12},{:.12},{:.9},{:.9},{:.9},{:.9},{:.9},{:.9},{:.9},{:.9},{:.9}",
            p.x, p.y, p.z, q.w, q.i, q.j, q.k, v.x, v.y, v.z, bg.x, bg.y, bg.z, ba.x, ba.y, ba.z
        )
        .map_err(io(&gt_path))?;
    }
    fi.flush().map_err(io(&imu_path))?;
    fg.flush().map_err(io(&gt_path))?;

    if let Some(c) = &sc.mag {
        let r = c.reference_field;
        out.write(
            "mag0/sensor.yaml",
            &format!(
                "sensor_type: magnetometer\nrate_hz: {}\nsigma: {:e}\nreference_field: [{:.6}, {:.6}, {:.6}]\n",
                c.rate_hz, c.sigma, r[0], r[1], r[2]
            ),
        )?;
        let path = out.dir.join("mag0/data.csv");
        let mut f = out.create("mag0/data.csv")?;
        writeln!(f, "#timestamp [ns],m_x [uT],m_y [uT],m_z [uT]").map_err(io(&path))?;
        let mut mag = Mag::new(c.clone(), Noise::new(seed, STREAM_MAG));
        for j in recorded(sc, c.rate_hz) {
            let ns = stamp_ns(t0, j, c.rate_hz);
            let m = mag.sample(&at(((ns - t0) as f64 * 1e-9 - c.delay_s).max(0.0)));
            writeln!(f, "{ns},{:.6},{:.6},{:.6}", m.x, m.y, m.z).map_err(io(&path))?;
        }
        f.flush().map_err(io(&path))?;
    }

    if let Some(c) = &sc.gnss {
        // The rows' `sigma_p` is one σ for every axis (the larger of the two, for readers that
        // take one); a receiver with a separate vertical σ says both here, where a reader that
        // does not know the keys ignores them.
        let sigmas = if c.sigma_horizontal == c.sigma_vertical {
            String::new()
        } else {
            format!(
                "sigma_p_horizontal: {}\nsigma_p_up: {}\n",
                c.sigma_horizontal, c.sigma_vertical
            )
        };
        out.write(
            "gnss0/sensor.yaml",
            &format!(
                "sensor_type: gnss\nrate_hz: {}\nlever_arm: [{}, {}, {}]\nlatency_s: {}\n{sigmas}",
                c.rate_hz, c.lever_arm[0], c.lever_arm[1], c.lever_arm[2], c.latency_s
            ),
        )?;
        let path = out.dir.join("gnss0/data.csv");
        let mut f = out.create("gnss0/data.csv")?;
        writeln!(f, "#timestamp [ns],p_x [m],p_y [m],p_z [m],v_x [m s^-1],v_y [m s^-1],v_z [m s^-1],sigma_p [m],sigma_v [m s^-1]").map_err(io(&path))?;
        let mut gnss = Gnss::new(c.clone(), Noise::new(seed, STREAM_GNSS));
        for j in recorded(sc, c.rate_hz) {
            let ns = stamp_ns(t0, j, c.rate_hz);
            let t = (ns - t0) as f64 * 1e-9;
            if let Some(fix) = gnss.sample(&at((t - c.latency_s).max(0.0)), t) {
                let (p, v) = (fix.position, fix.velocity);
                writeln!(
                    f,
                    "{ns},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{:.3},{:.3}",
                    p.x, p.y, p.z, v.x, v.y, v.z, fix.sigma_p, fix.sigma_v
                )
                .map_err(io(&path))?;
            }
        }
        f.flush().map_err(io(&path))?;
    }

    if let Some(c) = &sc.baro {
        out.write(
            "baro0/sensor.yaml",
            &format!(
                "sensor_type: barometer\nrate_hz: {}\nsigma: {:e}\n",
                c.rate_hz, c.sigma
            ),
        )?;
        let path = out.dir.join("baro0/data.csv");
        let mut f = out.create("baro0/data.csv")?;
        writeln!(f, "#timestamp [ns],altitude [m]").map_err(io(&path))?;
        let mut baro = Baro::new(c.clone(), Noise::new(seed, STREAM_BARO));
        for j in recorded(sc, c.rate_hz) {
            let ns = stamp_ns(t0, j, c.rate_hz);
            let h = baro.sample(&at((ns - t0) as f64 * 1e-9));
            writeln!(f, "{ns},{h:.4}").map_err(io(&path))?;
        }
        f.flush().map_err(io(&path))?;
    }

    if let Some(c) = &sc.camera {
        let [fu, fv, cu, cv] = c.intrinsics;
        let d = c
            .t_bs
            .iter()
            .map(|x| format!("{x}"))
            .collect::<Vec<_>>()
            .join(", ");
        out.write(
            "cam0/sensor.yaml",
            &format!(
                "sensor_type: camera\nrate_hz: {}\nintrinsics: [{fu}, {fv}, {cu}, {cv}]\nresolution: [{}, {}]\nsigma_px: {}\nT_BS:\n  cols: 4\n  rows: 4\n  data: [{d}]\n",
                c.rate_hz, c.resolution[0], c.resolution[1], c.sigma_px
            ),
        )?;
        let centre = at(sc.record_from_s).position;
        let mut cam = Camera::new(c.clone(), Noise::new(seed, STREAM_CAMERA), centre);
        let lpath = out.dir.join("cam0/landmarks.csv");
        let mut fl = out.create("cam0/landmarks.csv")?;
        writeln!(fl, "id,x [m],y [m],z [m]").map_err(io(&lpath))?;
        for (id, p) in cam.landmarks.iter().enumerate() {
            writeln!(fl, "{id},{:.6},{:.6},{:.6}", p.x, p.y, p.z).map_err(io(&lpath))?;
        }
        fl.flush().map_err(io(&lpath))?;
        let path = out.dir.join("cam0/observations.csv");
        let mut f = out.create("cam0/observations.csv")?;
        writeln!(f, "#timestamp [ns],id,u [px],v [px]").map_err(io(&path))?;
        for j in recorded(sc, c.rate_hz) {
            let ns = stamp_ns(t0, j, c.rate_hz);
            for o in cam.sample(&at((ns - t0) as f64 * 1e-9)) {
                writeln!(f, "{ns},{},{:.3},{:.3}", o.id, o.pixel.x, o.pixel.y)
                    .map_err(io(&path))?;
            }
        }
        f.flush().map_err(io(&path))?;
    }
    Ok(())
}

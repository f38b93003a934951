//! host-sim's dataset folder (EuRoC / ASL layout) from Python: read into arrays, simulated, and
//! replayed by host-sim itself (the reference the batched functions are checked against).

use crate::arrays::matrix;
use crate::config::{object_to_py, settings_dict, to_py, Settings};
use host_sim::dataset::read::{movement, Dataset, Event, TruthStream};
use host_sim::output::Staging;
use host_sim::replay::SensorParameters;
use host_sim::scenario::Scenario;
use numpy::PyArray1;
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::{Path, PathBuf};

fn err(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

fn times<'py>(py: Python<'py>, t: Vec<u64>) -> PyResult<Bound<'py, PyAny>> {
    let t = t
        .into_iter()
        .map(|x| i64::try_from(x).map_err(|_| err(format!("timestamp {x} ns beyond int64"))))
        .collect::<PyResult<Vec<i64>>>()?;
    Ok(PyArray1::from_vec(py, t).into_any())
}

/// GNSS fixes as columns.
#[derive(Default)]
struct Gnss {
    t: Vec<u64>,
    p: Vec<f64>,
    v: Vec<f64>,
    sigma_p: Vec<f64>,
    sigma_p_up: Vec<f64>,
    sigma_v: Vec<f64>,
}

/// `read_dataset(path)`: see the Python docstring.
#[pyfunction]
pub fn read_dataset(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, PyDict>> {
    // A EuRoC sequence's folder (holding mav0/) is read as its mav0/, as host-sim does.
    let dir = host_sim::dataset::locate(&path).dir;
    let cfg = host_sim::bench::replay_config(None, &dir).map_err(err)?;
    let ds = Dataset::open_with_magnetometer(&dir, cfg.use_magnetometer).map_err(err)?;
    let (mut imu_t, mut gyr, mut acc) = (Vec::new(), Vec::new(), Vec::new());
    let (mut mag_t, mut mag) = (Vec::new(), Vec::new());
    let (mut baro_t, mut baro) = (Vec::new(), Vec::new());
    let mut gnss = Gnss::default();
    // host-sim's own event stream: the same rows, parsed the same way, as its replay takes.
    for ev in ds.events().map_err(err)?.with_max_dt(cfg.max_dt) {
        match ev.map_err(err)? {
            Event::Imu { t_ns, gyro, accel } => {
                imu_t.push(t_ns);
                gyr.extend_from_slice(gyro.as_slice());
                acc.extend_from_slice(accel.as_slice());
            }
            Event::Mag { t_ns, field } => {
                mag_t.push(t_ns);
                mag.extend_from_slice(field.as_slice());
            }
            Event::Gnss {
                t_ns,
                position,
                velocity,
                sigma_p,
                sigma_p_up,
                sigma_v,
            } => {
                gnss.t.push(t_ns);
                gnss.p.extend_from_slice(position.as_slice());
                // A fix without a velocity: a row of NaN.
                gnss.v
                    .extend_from_slice(&velocity.map_or([f64::NAN; 3], |v| [v.x, v.y, v.z]));
                gnss.sigma_p.push(sigma_p);
                gnss.sigma_p_up.push(sigma_p_up);
                gnss.sigma_v.push(if velocity.is_some() {
                    sigma_v
                } else {
                    f64::NAN
                });
            }
            Event::Baro { t_ns, altitude } => {
                baro_t.push(t_ns);
                baro.push(altitude);
            }
            Event::Camera { .. } => {}
        }
    }
    let d = PyDict::new(py);
    d.set_item("path", dir.display().to_string())?;
    d.set_item("imu_t", times(py, imu_t)?)?;
    d.set_item("gyr", matrix(py, gyr, 3)?)?;
    d.set_item("acc", matrix(py, acc, 3)?)?;
    if ds.mag.is_some() {
        d.set_item("mag_t", times(py, mag_t)?)?;
        d.set_item("mag", matrix(py, mag, 3)?)?;
    } else {
        d.set_item("mag_t", py.None())?;
        d.set_item("mag", py.None())?;
    }
    if ds.has_groundtruth {
        let mut stream = TruthStream::open(&dir).map_err(err)?;
        let (mut tt, mut q, mut p) = (Vec::new(), Vec::new(), Vec::new());
        while let Some(row) = stream.next_truth().map_err(err)? {
            tt.push(row.t_ns);
            let r = row.attitude.quaternion();
            q.extend_from_slice(&[r.w, r.i, r.j, r.k]);
            p.extend_from_slice(row.position.as_slice());
        }
        d.set_item("truth_t", times(py, tt)?)?;
        d.set_item("truth_q", matrix(py, q, 4)?)?;
        d.set_item("truth_p", matrix(py, p, 3)?)?;
    } else {
        for k in ["truth_t", "truth_q", "truth_p"] {
            d.set_item(k, py.None())?;
        }
    }
    match movement(&dir).map_err(err)? {
        Some(iv) => {
            let flat: Vec<u64> = iv.iter().flat_map(|&(a, b)| [a, b]).collect();
            let t = times(py, flat)?;
            d.set_item("movement", t.call_method1("reshape", ((iv.len(), 2),))?)?;
        }
        None => d.set_item("movement", py.None())?,
    }
    d.set_item("has_gnss", ds.gnss.is_some())?;
    if ds.gnss.is_some() {
        d.set_item("gnss_t", times(py, gnss.t)?)?;
        d.set_item("gnss_p", matrix(py, gnss.p, 3)?)?;
        d.set_item("gnss_v", matrix(py, gnss.v, 3)?)?;
        d.set_item("gnss_sigma_p", PyArray1::from_vec(py, gnss.sigma_p))?;
        d.set_item("gnss_sigma_p_up", PyArray1::from_vec(py, gnss.sigma_p_up))?;
        d.set_item("gnss_sigma_v", PyArray1::from_vec(py, gnss.sigma_v))?;
    } else {
        for k in [
            "gnss_t",
            "gnss_p",
            "gnss_v",
            "gnss_sigma_p",
            "gnss_sigma_p_up",
            "gnss_sigma_v",
        ] {
            d.set_item(k, py.None())?;
        }
    }
    if ds.baro.is_some() {
        d.set_item("baro_t", times(py, baro_t)?)?;
        d.set_item("baro", PyArray1::from_vec(py, baro))?;
    } else {
        d.set_item("baro_t", py.None())?;
        d.set_item("baro", py.None())?;
    }
    // The keyword arguments that configure run_attitude as host-sim replay configures itself.
    let s = Settings {
        sensors: SensorParameters::from_dataset(&ds),
        replay: cfg,
    };
    d.set_item("config", settings_dict(py, &s)?)?;
    Ok(d)
}

fn staged(out: &Path, what: &str) -> PyResult<Staging> {
    Staging::new(out, false, what).map_err(|e| PyOSError::new_err(e.to_string()))
}

/// `simulate(scenario, seed, out)`: host-sim's `simulate`, writing a dataset folder.
#[pyfunction]
pub fn simulate(scenario: &str, seed: u64, out: PathBuf) -> PyResult<()> {
    let sc = Scenario::load(scenario).map_err(err)?;
    let staging = staged(&out, "simulate")?;
    host_sim::dataset::write::simulate(&sc, seed, staging.dir()).map_err(err)?;
    staging
        .commit()
        .map_err(|e| PyOSError::new_err(e.to_string()))
}

/// `replay(dataset, out)`: host-sim's `replay` (its configuration from the dataset's
/// `replay.toml`, else the defaults); returns `metrics.json` as a dict.
#[pyfunction]
pub fn replay(py: Python<'_>, dataset: PathBuf, out: PathBuf) -> PyResult<Bound<'_, PyAny>> {
    let dir = host_sim::dataset::locate(&dataset).dir;
    let cfg = host_sim::bench::replay_config(None, &dir).map_err(err)?;
    let title = dir
        .file_name()
        .map_or("dataset".into(), |n| n.to_string_lossy().into_owned());
    let staging = staged(&out, "replay")?;
    let m = py
        .detach(|| {
            host_sim::replay::replay(&dir, staging.dir(), &cfg, &title).map_err(|e| e.to_string())
        })
        .map_err(err)?;
    staging
        .commit()
        .map_err(|e| PyOSError::new_err(e.to_string()))?;
    let json = serde_json::to_value(&m).map_err(err)?;
    match &json {
        serde_json::Value::Object(o) => Ok(object_to_py(py, o)?.into_any()),
        other => to_py(py, other),
    }
}

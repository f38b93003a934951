//! The attitude navigator: sample by sample (`AttitudeNavigator`) and batched over arrays
//! (`run_attitude`), fed and read exactly as `host-sim replay` feeds and reads it.

use crate::arrays::{self, lit3, matrix};
use crate::config::{self, Settings};
use estimator_core::nav::{AttitudeNavigator, AttitudeReport, NavError, Reason, Validity};
use estimator_core::Real;
use host_sim::replay::navigator_config;
use numpy::PyArray1;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The validity codes of the `*_reason` arrays: index 0 is valid, the rest why not.
pub const REASONS: [&str; 9] = [
    "valid",
    "starting",
    "uncertain",
    "no_magnetometer",
    "heading_unresolved",
    "no_fix",
    "fixes_disagree",
    "reset",
    "imu_fault",
];

fn reason_code(v: Validity) -> u8 {
    match v {
        Validity::Valid => 0,
        Validity::Invalid(r) => match r {
            Reason::Starting => 1,
            Reason::Uncertain => 2,
            Reason::NoMagnetometer => 3,
            Reason::HeadingUnresolved => 4,
            Reason::NoFix => 5,
            Reason::FixesDisagree => 6,
            Reason::Reset => 7,
            Reason::ImuFault => 8,
        },
    }
}

pub(crate) fn nav_error(e: &NavError) -> PyErr {
    PyValueError::new_err(format!("refused by the navigator: {e}"))
}

/// The filter's state after the last call, as host-sim writes it to `estimate.csv`.
struct Row {
    q: [f64; 4],
    sigma: [f64; 3],
    gyro_bias: [f64; 3],
    accel_bias: [f64; 3],
}

fn row<T: Real>(nav: &AttitudeNavigator<T>) -> Option<Row> {
    let f = nav.filter()?;
    let s = f.state();
    let p = f.covariance();
    // The stored numbers converted as they are, as host-sim's `So3::cast` does.
    let q = s.attitude.cast::<f64>().quaternion();
    Some(Row {
        q: [q.w, q.i, q.j, q.k],
        sigma: [0, 1, 2].map(|i| p[(i, i)].to_f64().max(0.0).sqrt()),
        gyro_bias: [0, 1, 2].map(|i| s.gyro_bias[i].to_f64()),
        accel_bias: [0, 1, 2].map(|i| s.accel_bias[i].to_f64()),
    })
}

/// One navigator in either precision.
enum Nav {
    F32(Box<AttitudeNavigator<f32>>),
    F64(Box<AttitudeNavigator<f64>>),
}

fn build(s: &Settings, with_magnetometer: bool) -> PyResult<Nav> {
    let err = |e: NavError| PyValueError::new_err(format!("configuration: {e}"));
    match s.replay.precision.as_str() {
        "f32" => Ok(Nav::F32(Box::new(
            AttitudeNavigator::new(navigator_config(&s.sensors, &s.replay, with_magnetometer))
                .map_err(err)?,
        ))),
        "f64" => Ok(Nav::F64(Box::new(
            AttitudeNavigator::new(navigator_config(&s.sensors, &s.replay, with_magnetometer))
                .map_err(err)?,
        ))),
        other => Err(PyValueError::new_err(format!(
            "precision '{other}' (use 'f32' or 'f64')"
        ))),
    }
}

fn report_dict<'py, T: Real>(
    py: Python<'py>,
    r: &AttitudeReport<T>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("t_ns", r.t_ns)?;
    d.set_item("tilt_valid", r.tilt.is_valid())?;
    d.set_item("heading_valid", r.heading.is_valid())?;
    d.set_item("tilt_reason", REASONS[usize::from(reason_code(r.tilt))])?;
    d.set_item(
        "heading_reason",
        REASONS[usize::from(reason_code(r.heading))],
    )?;
    d.set_item("at_rest", r.at_rest)?;
    d.set_item("magnetic", format!("{:?}", r.magnetic).to_lowercase())?;
    d.set_item("event", r.event.map(|e| format!("{e:?}")))?;
    d.set_item("clipped", r.clipped)?;
    Ok(d)
}

fn estimate_dict<'py, T: Real>(
    py: Python<'py>,
    nav: &AttitudeNavigator<T>,
) -> PyResult<Option<Bound<'py, PyDict>>> {
    let (Some(r), Some(e)) = (row(nav), nav.estimate()) else {
        return Ok(None);
    };
    let d = report_dict(py, nav.report())?;
    d.set_item("quaternion", r.q.to_vec())?;
    d.set_item("sigma", r.sigma.to_vec())?;
    d.set_item("sigma_tilt", e.sigma_tilt.to_f64())?;
    d.set_item("sigma_heading", e.sigma_heading.to_f64())?;
    d.set_item("gyro_bias", r.gyro_bias.to_vec())?;
    d.set_item("accel_bias", r.accel_bias.to_vec())?;
    Ok(Some(d))
}

/// `AttitudeNavigator(config=None, **kwargs)`: the attitude navigator, one sample at a time.
#[pyclass(name = "AttitudeNavigator", module = "estimator._estimator")]
pub struct PyAttitudeNavigator {
    nav: Nav,
}

pub(crate) fn vector(name: &str, v: &Bound<'_, PyAny>) -> PyResult<[f64; 3]> {
    let xs: Vec<f64> = v
        .extract()
        .map_err(|_| PyTypeError::new_err(format!("{name}: expected 3 numbers")))?;
    match xs.as_slice() {
        [x, y, z] => {
            if let Some(j) = xs.iter().position(|c| !c.is_finite()) {
                return Err(PyValueError::new_err(format!(
                    "{name}[{j}] is {}: every value must be finite",
                    xs[j]
                )));
            }
            Ok([*x, *y, *z])
        }
        _ => Err(PyValueError::new_err(format!(
            "{name}: {} values, expected 3",
            xs.len()
        ))),
    }
}

/// The settings of a navigator's constructor: `config` updated by the keywords.
pub(crate) fn merged_settings(
    config: Option<&Bound<'_, PyDict>>,
    kwargs: Option<&Bound<'_, PyDict>>,
) -> PyResult<Settings> {
    let merged = match (config, kwargs) {
        (Some(c), Some(k)) => {
            let m = c.copy()?;
            m.update(k.as_mapping())?;
            Some(m)
        }
        (Some(c), None) => Some(c.clone()),
        (None, k) => k.cloned(),
    };
    config::settings(merged.as_ref())
}

#[pymethods]
impl PyAttitudeNavigator {
    #[new]
    #[pyo3(signature = (config=None, **kwargs))]
    fn new(
        config: Option<&Bound<'_, PyDict>>,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let s = merged_settings(config, kwargs)?;
        Ok(Self {
            nav: build(&s, true)?,
        })
    }

    /// Takes one IMU sample; returns the report (validity) after it.
    fn imu<'py>(
        &mut self,
        py: Python<'py>,
        t_ns: u64,
        gyr: &Bound<'py, PyAny>,
        acc: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (g, a) = (vector("gyr", gyr)?, vector("acc", acc)?);
        match &mut self.nav {
            Nav::F32(n) => {
                let r = n
                    .imu(t_ns, &lit3(&g), &lit3(&a))
                    .map_err(|e| nav_error(&e))?;
                report_dict(py, &r)
            }
            Nav::F64(n) => {
                let r = n
                    .imu(t_ns, &lit3(&g), &lit3(&a))
                    .map_err(|e| nav_error(&e))?;
                report_dict(py, &r)
            }
        }
    }

    /// Takes one magnetometer sample; returns the report after it.
    fn magnetometer<'py>(
        &mut self,
        py: Python<'py>,
        t_ns: u64,
        mag: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let m = vector("mag", mag)?;
        match &mut self.nav {
            Nav::F32(n) => {
                let r = n.magnetometer(t_ns, &lit3(&m)).map_err(|e| nav_error(&e))?;
                report_dict(py, &r)
            }
            Nav::F64(n) => {
                let r = n.magnetometer(t_ns, &lit3(&m)).map_err(|e| nav_error(&e))?;
                report_dict(py, &r)
            }
        }
    }

    /// The estimate after the last sample, `None` before the navigator started.
    fn estimate<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        match &self.nav {
            Nav::F32(n) => estimate_dict(py, n),
            Nav::F64(n) => estimate_dict(py, n),
        }
    }
}

/// The per-sample outputs of a batched run.
struct Outputs {
    q: Vec<f64>,
    sigma: Vec<f64>,
    gyro_bias: Vec<f64>,
    accel_bias: Vec<f64>,
    estimated: Vec<bool>,
    tilt_valid: Vec<bool>,
    heading_valid: Vec<bool>,
    tilt_reason: Vec<u8>,
    heading_reason: Vec<u8>,
    at_rest: Vec<bool>,
    imu_accepted: Vec<bool>,
    mag_accepted: Vec<bool>,
}

/// The samples of a batched run, checked.
struct Inputs {
    t: Vec<u64>,
    gyr: Vec<[f64; 3]>,
    acc: Vec<[f64; 3]>,
    mag_t: Vec<u64>,
    mag: Vec<[f64; 3]>,
}

/// Feeds every sample in time order, the IMU first at equal times (host-sim's event stream),
/// going on past refused samples as host-sim's replay does.
fn run<T: Real>(mut nav: AttitudeNavigator<T>, inp: &Inputs) -> Outputs {
    let n = inp.t.len();
    let mut o = Outputs {
        q: vec![f64::NAN; 4 * n],
        sigma: vec![f64::NAN; 3 * n],
        gyro_bias: vec![f64::NAN; 3 * n],
        accel_bias: vec![f64::NAN; 3 * n],
        estimated: vec![false; n],
        tilt_valid: vec![false; n],
        heading_valid: vec![false; n],
        tilt_reason: vec![0; n],
        heading_reason: vec![0; n],
        at_rest: vec![false; n],
        imu_accepted: vec![false; n],
        mag_accepted: vec![false; inp.mag_t.len()],
    };
    let (mut i, mut k) = (0, 0);
    while i < n || k < inp.mag_t.len() {
        let mag_next = k < inp.mag_t.len() && (i >= n || inp.mag_t[k] < inp.t[i]);
        if mag_next {
            o.mag_accepted[k] = nav.magnetometer(inp.mag_t[k], &lit3(&inp.mag[k])).is_ok();
            k += 1;
            continue;
        }
        o.imu_accepted[i] = nav
            .imu(inp.t[i], &lit3(&inp.gyr[i]), &lit3(&inp.acc[i]))
            .is_ok();
        let r = nav.report();
        o.tilt_valid[i] = r.tilt.is_valid();
        o.heading_valid[i] = r.heading.is_valid();
        o.tilt_reason[i] = reason_code(r.tilt);
        o.heading_reason[i] = reason_code(r.heading);
        o.at_rest[i] = r.at_rest;
        if let Some(row) = row(&nav) {
            o.estimated[i] = true;
            o.q[4 * i..4 * i + 4].copy_from_slice(&row.q);
            o.sigma[3 * i..3 * i + 3].copy_from_slice(&row.sigma);
            o.gyro_bias[3 * i..3 * i + 3].copy_from_slice(&row.gyro_bias);
            o.accel_bias[3 * i..3 * i + 3].copy_from_slice(&row.accel_bias);
        }
        i += 1;
    }
    o
}

/// `run_attitude(t, gyr, acc, mag=None, mag_t=None, **config)`: see the Python docstring.
#[pyfunction]
#[pyo3(signature = (t, gyr, acc, mag=None, mag_t=None, **config))]
pub fn run_attitude<'py>(
    py: Python<'py>,
    t: &Bound<'py, PyAny>,
    gyr: &Bound<'py, PyAny>,
    acc: &Bound<'py, PyAny>,
    mag: Option<&Bound<'py, PyAny>>,
    mag_t: Option<&Bound<'py, PyAny>>,
    config: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    // Everything is checked before the navigator sees a sample.
    let s = config::settings(config)?;
    let t = arrays::times("t", t)?;
    let n = t.len();
    let gyr = arrays::vec3s("gyr", gyr, Some(n))?;
    let acc = arrays::vec3s("acc", acc, Some(n))?;
    let (mag_t, mag) = match (mag_t, mag) {
        (Some(mt), Some(m)) => {
            let mt = arrays::times("mag_t", mt)?;
            let m = arrays::vec3s("mag", m, Some(mt.len()))?;
            (mt, m)
        }
        (None, None) => (Vec::new(), Vec::new()),
        (None, Some(_)) => return Err(PyValueError::new_err("mag given without mag_t")),
        (Some(_), None) => return Err(PyValueError::new_err("mag_t given without mag")),
    };
    let with_mag = !mag_t.is_empty() && s.replay.use_magnetometer;
    let mag_len = mag_t.len();
    let inp = Inputs {
        t,
        gyr,
        acc,
        mag_t: if with_mag { mag_t } else { Vec::new() },
        mag: if with_mag { mag } else { Vec::new() },
    };
    let nav = build(&s, with_mag)?;
    // The run holds no Python object: other threads may go on meanwhile.
    let mut o = py.detach(move || match nav {
        Nav::F32(nav) => run(*nav, &inp),
        Nav::F64(nav) => run(*nav, &inp),
    });
    // Magnetometer samples left out (`use_magnetometer = False`) were not accepted.
    o.mag_accepted.resize(mag_len, false);
    let d = PyDict::new(py);
    d.set_item("quaternion", matrix(py, o.q, 4)?)?;
    d.set_item("sigma", matrix(py, o.sigma, 3)?)?;
    d.set_item("gyro_bias", matrix(py, o.gyro_bias, 3)?)?;
    d.set_item("accel_bias", matrix(py, o.accel_bias, 3)?)?;
    d.set_item("estimated", PyArray1::from_vec(py, o.estimated))?;
    d.set_item("tilt_valid", PyArray1::from_vec(py, o.tilt_valid))?;
    d.set_item("heading_valid", PyArray1::from_vec(py, o.heading_valid))?;
    d.set_item("tilt_reason", PyArray1::from_vec(py, o.tilt_reason))?;
    d.set_item("heading_reason", PyArray1::from_vec(py, o.heading_reason))?;
    d.set_item("at_rest", PyArray1::from_vec(py, o.at_rest))?;
    d.set_item("imu_accepted", PyArray1::from_vec(py, o.imu_accepted))?;
    d.set_item("mag_accepted", PyArray1::from_vec(py, o.mag_accepted))?;
    Ok(d)
}

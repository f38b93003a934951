//! The INS navigator batched over arrays (`run_ins`), fed and read as `host-sim replay` feeds
//! and reads it on a GNSS dataset.

use crate::arrays::{self, lit3, matrix};
use crate::attitude::{merged_settings, nav_error, vector};
use crate::config::{self, Settings};
use estimator_core::nav::{GnssFix, InsEstimate, InsReport, NavError, Validity};
use estimator_core::Real;
use host_sim::replay::{ins_config, ReplayInsNavigator as Nav, HORIZON_SAMPLES};
use nalgebra::Vector3;
use numpy::PyArray1;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

struct Fix {
    t: u64,
    p: [f64; 3],
    v: Option<[f64; 3]>,
    sigma_p: f64,
    sigma_p_up: f64,
    sigma_v: f64,
}

struct Inputs {
    t: Vec<u64>,
    gyr: Vec<[f64; 3]>,
    acc: Vec<[f64; 3]>,
    fixes: Vec<Fix>,
    mag_t: Vec<u64>,
    mag: Vec<[f64; 3]>,
    baro_t: Vec<u64>,
    baro: Vec<f64>,
    latency_ns: u64,
}

#[derive(Default)]
struct Outputs {
    q: Vec<f64>,
    p: Vec<f64>,
    v: Vec<f64>,
    sigma: Vec<f64>,
    gyro_bias: Vec<f64>,
    accel_bias: Vec<f64>,
    estimated: Vec<bool>,
    valid: [Vec<bool>; 6],
    imu_accepted: Vec<bool>,
    gnss_accepted: Vec<bool>,
}

fn valid(v: Validity) -> bool {
    v.is_valid()
}

/// Feeds every sample in host-sim's event order (by time; at equal times IMU, magnetometer,
/// GNSS, barometer), each fix stamped with its time minus the latency; goes on past refused
/// samples as host-sim's replay does.
fn run<T: Real>(nav: &mut Nav<T>, inp: &Inputs) -> Outputs {
    let n = inp.t.len();
    let nan = |k: usize| vec![f64::NAN; k * n];
    let mut o = Outputs {
        q: nan(4),
        p: nan(3),
        v: nan(3),
        sigma: nan(15),
        gyro_bias: nan(3),
        accel_bias: nan(3),
        estimated: vec![false; n],
        valid: std::array::from_fn(|_| vec![false; n]),
        imu_accepted: vec![false; n],
        gnss_accepted: vec![false; inp.fixes.len()],
    };
    let (mut i, mut m, mut g, mut b) = (0, 0, 0, 0);
    loop {
        // The source with the earliest time; the first in this order at equal times.
        let heads = [
            inp.t.get(i).copied(),
            inp.mag_t.get(m).copied(),
            inp.fixes.get(g).map(|f| f.t),
            inp.baro_t.get(b).copied(),
        ];
        let mut best: Option<(u64, usize)> = None;
        for (k, h) in heads.iter().enumerate() {
            if let Some(t) = h {
                if best.is_none_or(|(bt, _)| *t < bt) {
                    best = Some((*t, k));
                }
            }
        }
        let Some((_, which)) = best else { break };
        match which {
            0 => {
                o.imu_accepted[i] = nav
                    .imu(inp.t[i], &lit3(&inp.gyr[i]), &lit3(&inp.acc[i]))
                    .is_ok();
                let v = nav.report().validity;
                let flags = [
                    v.tilt,
                    v.heading,
                    v.velocity,
                    v.position,
                    v.gyro_bias,
                    v.accel_bias,
                ];
                for (k, f) in flags.into_iter().enumerate() {
                    o.valid[k][i] = valid(f);
                }
                if let Some(e) = nav.estimate() {
                    o.estimated[i] = true;
                    let q = e.state.attitude.cast::<f64>().quaternion();
                    o.q[4 * i..4 * i + 4].copy_from_slice(&[q.w, q.i, q.j, q.k]);
                    let s = &e.state;
                    for k in 0..3 {
                        o.p[3 * i + k] = s.position[k].to_f64();
                        o.v[3 * i + k] = s.velocity[k].to_f64();
                        o.gyro_bias[3 * i + k] = s.gyro_bias[k].to_f64();
                        o.accel_bias[3 * i + k] = s.accel_bias[k].to_f64();
                    }
                    for (blk, c) in e.covariance.iter().enumerate() {
                        for k in 0..3 {
                            o.sigma[15 * i + 3 * blk + k] = c[(k, k)].to_f64().max(0.0).sqrt();
                        }
                    }
                }
                i += 1;
            }
            1 => {
                let _ = nav.magnetometer(inp.mag_t[m], &lit3(&inp.mag[m]));
                m += 1;
            }
            2 => {
                let f = &inp.fixes[g];
                let fix = GnssFix::new(
                    lit3(&f.p),
                    f.v.as_ref().map(lit3),
                    T::lit(f.sigma_p),
                    T::lit(f.sigma_v),
                )
                .with_vertical_sigma(T::lit(f.sigma_p_up));
                o.gnss_accepted[g] = nav.gnss(f.t.saturating_sub(inp.latency_ns), &fix).is_ok();
                g += 1;
            }
            _ => {
                let _ = nav.barometer(inp.baro_t[b], T::lit(inp.baro[b]));
                b += 1;
            }
        }
    }
    o
}

fn pair<'py>(
    a: Option<&Bound<'py, PyAny>>,
    b: Option<&Bound<'py, PyAny>>,
    names: (&str, &str),
) -> PyResult<Option<(Bound<'py, PyAny>, Bound<'py, PyAny>)>> {
    match (a, b) {
        (Some(a), Some(b)) => Ok(Some((a.clone(), b.clone()))),
        (None, None) => Ok(None),
        _ => Err(PyValueError::new_err(format!(
            "{} and {} go together (both or neither)",
            names.0, names.1
        ))),
    }
}

/// `run_ins(...)`: see the Python docstring.
#[pyfunction]
#[pyo3(signature = (t, gyr, acc, gnss_t, gnss_p, gnss_sigma_p, gnss_v=None, gnss_sigma_v=None, gnss_sigma_p_up=None, mag=None, mag_t=None, baro=None, baro_t=None, **config))]
#[allow(clippy::too_many_arguments)]
pub fn run_ins<'py>(
    py: Python<'py>,
    t: &Bound<'py, PyAny>,
    gyr: &Bound<'py, PyAny>,
    acc: &Bound<'py, PyAny>,
    gnss_t: &Bound<'py, PyAny>,
    gnss_p: &Bound<'py, PyAny>,
    gnss_sigma_p: &Bound<'py, PyAny>,
    gnss_v: Option<&Bound<'py, PyAny>>,
    gnss_sigma_v: Option<&Bound<'py, PyAny>>,
    gnss_sigma_p_up: Option<&Bound<'py, PyAny>>,
    mag: Option<&Bound<'py, PyAny>>,
    mag_t: Option<&Bound<'py, PyAny>>,
    baro: Option<&Bound<'py, PyAny>>,
    baro_t: Option<&Bound<'py, PyAny>>,
    config: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    // Everything is checked before the navigator sees a sample.
    let s: Settings = config::settings(config)?;
    let t = arrays::times("t", t)?;
    let n = t.len();
    let gyr = arrays::vec3s("gyr", gyr, Some(n))?;
    let acc = arrays::vec3s("acc", acc, Some(n))?;
    let gnss_t = arrays::times("gnss_t", gnss_t)?;
    let k = gnss_t.len();
    let gnss_p = arrays::vec3s("gnss_p", gnss_p, Some(k))?;
    let sigma_p = arrays::floats("gnss_sigma_p", gnss_sigma_p, k)?;
    let velocity = match pair(gnss_v, gnss_sigma_v, ("gnss_v", "gnss_sigma_v"))? {
        Some((v, sv)) => {
            let v = arrays::nan_rows("gnss_v", &v, 3, k)?;
            // NaN where the fix has no velocity (a NaN row of gnss_v).
            let sv = arrays::floats_or_nan("gnss_sigma_v", &sv, k, true)?;
            if let Some(i) = (0..k).find(|&i| v[i].is_some() && (sv[i].is_nan() || sv[i] <= 0.0)) {
                return Err(PyValueError::new_err(format!(
                    "gnss_sigma_v[{i}] is {}: a fix with a velocity needs a 1σ > 0",
                    sv[i]
                )));
            }
            Some((v, sv))
        }
        None => None,
    };
    let sigma_up = gnss_sigma_p_up
        .map(|u| arrays::floats("gnss_sigma_p_up", u, k))
        .transpose()?;
    for (name, values) in [
        ("gnss_sigma_p", Some(&sigma_p)),
        ("gnss_sigma_p_up", sigma_up.as_ref()),
    ] {
        if let Some(i) = values.and_then(|v| v.iter().position(|x| *x <= 0.0)) {
            return Err(PyValueError::new_err(format!("{name}[{i}] must be > 0")));
        }
    }
    let (mag_t, mag) = match pair(mag_t, mag, ("mag_t", "mag"))? {
        Some((mt, m)) => {
            let mt = arrays::times("mag_t", &mt)?;
            let m = arrays::vec3s("mag", &m, Some(mt.len()))?;
            (mt, m)
        }
        None => (Vec::new(), Vec::new()),
    };
    let (baro_t, baro) = match pair(baro_t, baro, ("baro_t", "baro"))? {
        Some((bt, b)) => {
            let bt = arrays::times("baro_t", &bt)?;
            let b = arrays::floats("baro", &b, bt.len())?;
            (bt, b)
        }
        None => (Vec::new(), Vec::new()),
    };
    // The horizon must fit host-sim's ring of IMU intervals (its check, at the data's rate).
    if n >= 2 {
        let rate_hz = (n - 1) as f64 / ((t[n - 1] - t[0]) as f64 * 1e-9);
        if s.replay.horizon_s * rate_hz > HORIZON_SAMPLES {
            return Err(PyValueError::new_err(format!(
                "horizon_s = {} holds {:.0} IMU samples at {rate_hz:.0} Hz; at most {HORIZON_SAMPLES}",
                s.replay.horizon_s,
                s.replay.horizon_s * rate_hz
            )));
        }
    }
    let fixes = (0..k)
        .map(|i| {
            let v = velocity
                .as_ref()
                .and_then(|(v, sv)| v[i].map(|r| ([r[0], r[1], r[2]], sv[i])));
            Fix {
                t: gnss_t[i],
                p: gnss_p[i],
                v: v.map(|(r, _)| r),
                sigma_p: sigma_p[i],
                sigma_p_up: sigma_up.as_ref().map_or(sigma_p[i], |u| u[i]),
                // host-sim's fix without a velocity has a velocity 1σ of 0.
                sigma_v: v.map_or(0.0, |(_, sv)| sv),
            }
        })
        .collect();
    let latency_ns = s.sensors.gnss_latency_ns(&s.replay);
    let with_mag = !mag_t.is_empty() && s.replay.use_magnetometer;
    let mag_len = mag_t.len();
    let with_baro = !baro_t.is_empty();
    let inp = Inputs {
        t,
        gyr,
        acc,
        fixes,
        mag_t: if with_mag { mag_t } else { Vec::new() },
        mag: if with_mag { mag } else { Vec::new() },
        baro_t,
        baro,
        latency_ns,
    };
    let err = |e| PyValueError::new_err(format!("configuration: {e}"));
    let o = match s.replay.precision.as_str() {
        "f32" => {
            let nav = Box::new(
                Nav::<f32>::new(ins_config(&s.sensors, &s.replay, with_mag, with_baro))
                    .map_err(err)?,
            );
            py.detach(move || {
                let mut nav = nav;
                run(&mut nav, &inp)
            })
        }
        "f64" => {
            let nav = Box::new(
                Nav::<f64>::new(ins_config(&s.sensors, &s.replay, with_mag, with_baro))
                    .map_err(err)?,
            );
            py.detach(move || {
                let mut nav = nav;
                run(&mut nav, &inp)
            })
        }
        other => {
            return Err(PyValueError::new_err(format!(
                "precision '{other}' (use 'f32' or 'f64')"
            )))
        }
    };
    let d = PyDict::new(py);
    d.set_item("quaternion", matrix(py, o.q, 4)?)?;
    d.set_item("position", matrix(py, o.p, 3)?)?;
    d.set_item("velocity", matrix(py, o.v, 3)?)?;
    d.set_item("sigma", matrix(py, o.sigma, 15)?)?;
    d.set_item("gyro_bias", matrix(py, o.gyro_bias, 3)?)?;
    d.set_item("accel_bias", matrix(py, o.accel_bias, 3)?)?;
    d.set_item("estimated", PyArray1::from_vec(py, o.estimated))?;
    let names = [
        "tilt_valid",
        "heading_valid",
        "velocity_valid",
        "position_valid",
        "gyro_bias_valid",
        "accel_bias_valid",
    ];
    for (name, v) in names.into_iter().zip(o.valid) {
        d.set_item(name, PyArray1::from_vec(py, v))?;
    }
    d.set_item("imu_accepted", PyArray1::from_vec(py, o.imu_accepted))?;
    d.set_item("gnss_accepted", PyArray1::from_vec(py, o.gnss_accepted))?;
    d.set_item("magnetometer_used", with_mag && mag_len > 0)?;
    Ok(d)
}

/// One INS navigator in either precision.
enum InsNav {
    F32(Box<Nav<f32>>),
    F64(Box<Nav<f64>>),
}

/// The report after a call: each quantity's validity.
fn ins_report_dict<'py, T: Real>(
    py: Python<'py>,
    r: &InsReport<T>,
) -> PyResult<Bound<'py, PyDict>> {
    let v = r.validity;
    let d = PyDict::new(py);
    d.set_item("t_ns", r.t_ns)?;
    for (name, f) in [
        ("tilt_valid", v.tilt),
        ("heading_valid", v.heading),
        ("velocity_valid", v.velocity),
        ("position_valid", v.position),
        ("gyro_bias_valid", v.gyro_bias),
        ("accel_bias_valid", v.accel_bias),
    ] {
        d.set_item(name, valid(f))?;
    }
    d.set_item("event", r.event.map(|e| format!("{e:?}")))?;
    Ok(d)
}

/// The estimate: attitude (w, x, y, z; world ENU from body), position m and velocity m/s
/// (ENU), biases, and the 15 sigmas (attitude rad, velocity, position, gyro bias, accelerometer
/// bias), as `run_ins` gives them per sample.
fn ins_estimate_dict<'py, T: Real>(
    py: Python<'py>,
    e: &InsEstimate<T>,
) -> PyResult<Bound<'py, PyDict>> {
    let s = &e.state;
    let q = s.attitude.cast::<f64>().quaternion();
    let f = |v: &Vector3<T>| [v.x.to_f64(), v.y.to_f64(), v.z.to_f64()];
    let mut sigma = [0.0; 15];
    for (blk, c) in e.covariance.iter().enumerate() {
        for k in 0..3 {
            sigma[3 * blk + k] = c[(k, k)].to_f64().max(0.0).sqrt();
        }
    }
    let d = PyDict::new(py);
    d.set_item("quaternion", [q.w, q.i, q.j, q.k].to_vec())?;
    d.set_item("position", f(&s.position).to_vec())?;
    d.set_item("velocity", f(&s.velocity).to_vec())?;
    d.set_item("gyro_bias", f(&s.gyro_bias).to_vec())?;
    d.set_item("accel_bias", f(&s.accel_bias).to_vec())?;
    d.set_item("sigma", sigma.to_vec())?;
    Ok(d)
}

/// `InsNavigator(config=None, magnetometer=False, barometer=False, **kwargs)`: the INS
/// navigator, one sample at a time, configured as `run_ins` configures it.
#[pyclass(name = "InsNavigator", module = "estimator._estimator")]
pub struct PyInsNavigator {
    nav: InsNav,
    latency_ns: u64,
}

/// Runs `$body` with `$n` the navigator of either precision and `$T` its scalar.
macro_rules! with_nav {
    ($self:expr, $n:ident, $T:ident, $body:expr) => {
        match &mut $self.nav {
            InsNav::F32($n) => {
                type $T = f32;
                $body
            }
            InsNav::F64($n) => {
                type $T = f64;
                $body
            }
        }
    };
}

#[pymethods]
impl PyInsNavigator {
    #[new]
    #[pyo3(signature = (config=None, magnetometer=false, barometer=false, **kwargs))]
    fn new(
        config: Option<&Bound<'_, PyDict>>,
        magnetometer: bool,
        barometer: bool,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let s = merged_settings(config, kwargs)?;
        let with_mag = magnetometer && s.replay.use_magnetometer;
        let err = |e: NavError| PyValueError::new_err(format!("configuration: {e}"));
        let nav = match s.replay.precision.as_str() {
            "f32" => InsNav::F32(Box::new(
                Nav::new(ins_config(&s.sensors, &s.replay, with_mag, barometer)).map_err(err)?,
            )),
            "f64" => InsNav::F64(Box::new(
                Nav::new(ins_config(&s.sensors, &s.replay, with_mag, barometer)).map_err(err)?,
            )),
            other => {
                return Err(PyValueError::new_err(format!(
                    "precision '{other}' (use 'f32' or 'f64')"
                )))
            }
        };
        Ok(Self {
            nav,
            latency_ns: s.sensors.gnss_latency_ns(&s.replay),
        })
    }

    /// Takes one IMU sample; returns the report (validity per quantity) after it.
    fn imu<'py>(
        &mut self,
        py: Python<'py>,
        t_ns: u64,
        gyr: &Bound<'py, PyAny>,
        acc: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (g, a) = (vector("gyr", gyr)?, vector("acc", acc)?);
        with_nav!(self, n, T, {
            let r = n
                .imu(t_ns, &lit3::<T>(&g), &lit3::<T>(&a))
                .map_err(|e| nav_error(&e))?;
            ins_report_dict(py, &r)
        })
    }

    /// Takes one GNSS fix stamped `t_ns` (minus the configured `gnss_latency_s`, as `run_ins`
    /// and host-sim stamp it).
    #[pyo3(signature = (t_ns, position, sigma_p, velocity=None, sigma_v=None, sigma_p_up=None))]
    #[allow(clippy::too_many_arguments)]
    fn gnss(
        &mut self,
        t_ns: u64,
        position: &Bound<'_, PyAny>,
        sigma_p: f64,
        velocity: Option<&Bound<'_, PyAny>>,
        sigma_v: Option<f64>,
        sigma_p_up: Option<f64>,
    ) -> PyResult<()> {
        let p = vector("position", position)?;
        let v = velocity.map(|v| vector("velocity", v)).transpose()?;
        if v.is_some() != sigma_v.is_some() {
            return Err(PyValueError::new_err(
                "velocity and sigma_v go together (both or neither)",
            ));
        }
        let t = t_ns.saturating_sub(self.latency_ns);
        with_nav!(self, n, T, {
            let fix = GnssFix::new(
                lit3::<T>(&p),
                v.as_ref().map(lit3::<T>),
                T::lit(sigma_p),
                T::lit(sigma_v.unwrap_or(0.0)),
            )
            .with_vertical_sigma(T::lit(sigma_p_up.unwrap_or(sigma_p)));
            n.gnss(t, &fix).map(drop).map_err(|e| nav_error(&e))
        })
    }

    /// Takes one magnetometer sample (µT, body frame).
    fn magnetometer(&mut self, t_ns: u64, mag: &Bound<'_, PyAny>) -> PyResult<()> {
        let m = vector("mag", mag)?;
        with_nav!(self, n, T, {
            n.magnetometer(t_ns, &lit3::<T>(&m))
                .map(drop)
                .map_err(|e| nav_error(&e))
        })
    }

    /// Takes one barometric altitude (m, up).
    fn barometer(&mut self, t_ns: u64, altitude: f64) -> PyResult<()> {
        with_nav!(self, n, T, {
            n.barometer(t_ns, T::lit(altitude))
                .map(drop)
                .map_err(|e| nav_error(&e))
        })
    }

    /// The estimate after the last sample, `None` before the INS started.
    fn estimate<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        match &self.nav {
            InsNav::F32(n) => n.estimate().map(|e| ins_estimate_dict(py, &e)).transpose(),
            InsNav::F64(n) => n.estimate().map(|e| ins_estimate_dict(py, &e)).transpose(),
        }
    }
}

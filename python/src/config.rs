//! The navigator's configuration from Python keyword arguments: host-sim's replay options
//! (`ReplayConfig`, the keys of a dataset's `replay.toml`) plus the sensor parameters host-sim
//! reads from a dataset's `sensor.yaml` files (`SensorParameters`), turned into a navigator's
//! configuration by host-sim's own `navigator_config` and `ins_config`, so that the same data
//! gives the same numbers.

use host_sim::replay::{ReplayConfig, SensorParameters};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyList};
use serde_json::{Map, Number, Value};

/// The sensor keys (not in `ReplayConfig`).
const SENSOR_KEYS: [&str; 9] = [
    "gyroscope_noise_density",
    "gyroscope_random_walk",
    "accelerometer_noise_density",
    "accelerometer_random_walk",
    "mag_sigma",
    "mag_reference",
    "gnss_lever_arm",
    "gnss_latency_s",
    "baro_sigma",
];

/// Everything a navigator is configured from.
#[derive(Clone, Debug, Default)]
pub struct Settings {
    pub replay: ReplayConfig,
    pub sensors: SensorParameters,
}

/// The settings from keyword arguments (`None`: the defaults), every key checked.
pub fn settings(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Settings> {
    let mut s = Settings::default();
    let mut replay = serde_json::to_value(&s.replay)
        .map_err(|e| PyValueError::new_err(format!("config: {e}")))?;
    let Some(kwargs) = kwargs else {
        return Ok(s);
    };
    let p = &mut s.sensors;
    for (k, v) in kwargs.iter() {
        let key: String = k
            .extract()
            .map_err(|_| PyTypeError::new_err("config: keys must be strings"))?;
        match key.as_str() {
            "gyroscope_noise_density" => p.imu_noise.gyroscope_noise_density = number(&key, &v)?,
            "gyroscope_random_walk" => p.imu_noise.gyroscope_random_walk = number(&key, &v)?,
            "accelerometer_noise_density" => {
                p.imu_noise.accelerometer_noise_density = number(&key, &v)?;
            }
            "accelerometer_random_walk" => {
                p.imu_noise.accelerometer_random_walk = number(&key, &v)?
            }
            "mag_sigma" => p.mag_sigma = number(&key, &v)?,
            "gnss_latency_s" => p.gnss_latency_s = number(&key, &v)?,
            "baro_sigma" => p.baro_sigma = number(&key, &v)?,
            "gnss_lever_arm" => {
                let r: Vec<f64> = v.extract().map_err(|_| {
                    PyTypeError::new_err("gnss_lever_arm: expected 3 numbers (m, body frame)")
                })?;
                match r.as_slice() {
                    [x, y, z] if r.iter().all(|c| c.is_finite()) => {
                        p.gnss_lever_arm = [*x, *y, *z];
                    }
                    _ => {
                        return Err(PyValueError::new_err(format!(
                            "gnss_lever_arm: {r:?}, expected 3 finite numbers (m, body frame)"
                        )))
                    }
                }
            }
            "mag_reference" => {
                p.mag_reference = if v.is_none() {
                    None
                } else {
                    let r: Vec<f64> = v.extract().map_err(|_| {
                        PyTypeError::new_err("mag_reference: expected 3 numbers (µT, ENU) or None")
                    })?;
                    match r.as_slice() {
                        [x, y, z] if r.iter().all(|c| c.is_finite()) => Some([*x, *y, *z]),
                        _ => {
                            return Err(PyValueError::new_err(format!(
                                "mag_reference: {r:?}, expected 3 finite numbers (µT, ENU)"
                            )))
                        }
                    }
                };
            }
            _ => {
                let slot = replay.get_mut(&key).ok_or_else(|| {
                    PyTypeError::new_err(format!(
                        "unknown configuration key '{key}' (see estimator.default_config())"
                    ))
                })?;
                *slot = to_json(&key, &v)?;
            }
        }
    }
    s.replay = serde_json::from_value(replay.clone()).map_err(|e| {
        // serde names the type, not the key: find the key that alone fails.
        let bad = kwargs.keys().iter().find_map(|k| {
            let key: String = k.extract().ok()?;
            let mut one = serde_json::to_value(ReplayConfig::default()).ok()?;
            *one.get_mut(&key)? = replay.get(&key)?.clone();
            serde_json::from_value::<ReplayConfig>(one)
                .is_err()
                .then_some(key)
        });
        PyValueError::new_err(match bad {
            Some(key) => format!("config: {key}: {e}"),
            None => format!("config: {e}"),
        })
    })?;
    s.replay
        .validate()
        .map_err(|e| PyValueError::new_err(format!("config: {e}")))?;
    let p = &s.sensors;
    let n = &p.imu_noise;
    for (key, v) in [
        ("gyroscope_noise_density", n.gyroscope_noise_density),
        ("gyroscope_random_walk", n.gyroscope_random_walk),
        ("accelerometer_noise_density", n.accelerometer_noise_density),
        ("accelerometer_random_walk", n.accelerometer_random_walk),
    ] {
        if v < 0.0 {
            return Err(PyValueError::new_err(format!("{key} is {v}, must be ≥ 0")));
        }
    }
    if p.gnss_latency_s < 0.0 {
        return Err(PyValueError::new_err(format!(
            "gnss_latency_s is {}, must be ≥ 0",
            p.gnss_latency_s
        )));
    }
    if p.baro_sigma <= 0.0 {
        return Err(PyValueError::new_err(format!(
            "baro_sigma is {}, must be > 0",
            p.baro_sigma
        )));
    }
    if p.mag_sigma <= 0.0 {
        return Err(PyValueError::new_err(format!(
            "mag_sigma is {}, must be > 0",
            p.mag_sigma
        )));
    }
    Ok(s)
}

fn number(key: &str, v: &Bound<'_, PyAny>) -> PyResult<f64> {
    if v.is_instance_of::<PyBool>() {
        return Err(PyTypeError::new_err(format!(
            "{key}: expected a number, got a bool"
        )));
    }
    let x: f64 = v
        .extract()
        .map_err(|_| PyTypeError::new_err(format!("{key}: expected a number")))?;
    if x.is_finite() {
        Ok(x)
    } else {
        Err(PyValueError::new_err(format!(
            "{key} is {x}, must be finite"
        )))
    }
}

/// A Python value as JSON, for `ReplayConfig`'s own checks of its types.
fn to_json(key: &str, v: &Bound<'_, PyAny>) -> PyResult<Value> {
    if v.is_instance_of::<PyBool>() {
        return Ok(Value::Bool(v.extract()?));
    }
    if let Ok(i) = v.extract::<i64>() {
        return Ok(Value::from(i));
    }
    if let Ok(x) = v.extract::<f64>() {
        return Number::from_f64(x)
            .map(Value::Number)
            .ok_or_else(|| PyValueError::new_err(format!("{key} is {x}, must be finite")));
    }
    if let Ok(s) = v.extract::<String>() {
        return Ok(Value::String(s));
    }
    if let Ok(xs) = v.extract::<Vec<f64>>() {
        let items = xs
            .iter()
            .map(|&x| {
                Number::from_f64(x)
                    .map(Value::Number)
                    .ok_or_else(|| PyValueError::new_err(format!("{key}: {x} is not finite")))
            })
            .collect::<PyResult<Vec<_>>>()?;
        return Ok(Value::Array(items));
    }
    Err(PyTypeError::new_err(format!(
        "{key}: expected a bool, number, string or list of numbers"
    )))
}

/// A JSON value as a Python object.
pub fn to_py<'py>(py: Python<'py>, v: &Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => PyBool::new(py, *b).to_owned().into_any(),
        Value::Number(n) => match (n.as_i64(), n.as_f64()) {
            (Some(i), _) => i.into_pyobject(py)?.into_any(),
            (None, Some(x)) => x.into_pyobject(py)?.into_any(),
            _ => f64::NAN.into_pyobject(py)?.into_any(),
        },
        Value::String(s) => s.into_pyobject(py)?.into_any(),
        Value::Array(a) => {
            let list = PyList::empty(py);
            for x in a {
                list.append(to_py(py, x)?)?;
            }
            list.into_any()
        }
        Value::Object(o) => object_to_py(py, o)?.into_any(),
    })
}

pub fn object_to_py<'py>(py: Python<'py>, o: &Map<String, Value>) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (k, x) in o {
        d.set_item(k, to_py(py, x)?)?;
    }
    Ok(d)
}

/// The keyword arguments that reproduce `s` (every key, with its value).
pub fn settings_dict<'py>(py: Python<'py>, s: &Settings) -> PyResult<Bound<'py, PyDict>> {
    let replay = serde_json::to_value(&s.replay)
        .map_err(|e| PyValueError::new_err(format!("config: {e}")))?;
    let d = match &replay {
        Value::Object(o) => object_to_py(py, o)?,
        _ => PyDict::new(py),
    };
    let p = &s.sensors;
    let n = &p.imu_noise;
    d.set_item(SENSOR_KEYS[0], n.gyroscope_noise_density)?;
    d.set_item(SENSOR_KEYS[1], n.gyroscope_random_walk)?;
    d.set_item(SENSOR_KEYS[2], n.accelerometer_noise_density)?;
    d.set_item(SENSOR_KEYS[3], n.accelerometer_random_walk)?;
    d.set_item(SENSOR_KEYS[4], p.mag_sigma)?;
    d.set_item(SENSOR_KEYS[5], p.mag_reference.map(|r| r.to_vec()))?;
    d.set_item(SENSOR_KEYS[6], p.gnss_lever_arm.to_vec())?;
    d.set_item(SENSOR_KEYS[7], p.gnss_latency_s)?;
    d.set_item(SENSOR_KEYS[8], p.baro_sigma)?;
    Ok(d)
}

/// `default_config()`: every configuration key with its default value.
#[pyfunction]
pub fn default_config(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    settings_dict(py, &Settings::default())
}

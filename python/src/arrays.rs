//! Checked conversion of NumPy arguments: dtype, shape, length, finiteness and time order are
//! all verified, and the first fault is reported with the argument's name and the index.

use estimator_core::Real;
use nalgebra::Vector3;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;

fn value_error(msg: String) -> PyErr {
    PyValueError::new_err(msg)
}

/// A float64 array of shape `(n, cols)` (`n` given, or any when `None`), every value finite.
pub fn rows(
    name: &str,
    obj: &Bound<'_, PyAny>,
    cols: usize,
    n: Option<usize>,
) -> PyResult<Vec<[f64; 4]>> {
    let arr = obj.cast::<PyArrayDyn<f64>>().map_err(|_| {
        PyTypeError::new_err(format!(
            "{name}: expected a float64 numpy array, got {}",
            type_name(obj)
        ))
    })?;
    let ro = arr.readonly();
    let shape = ro.shape().to_vec();
    let expected = n.map_or_else(|| "N".to_string(), |n| n.to_string());
    if shape.len() != 2 || shape[1] != cols || cols > 4 || n.is_some_and(|n| shape[0] != n) {
        return Err(value_error(format!(
            "{name}: shape {shape:?}, expected ({expected}, {cols})"
        )));
    }
    let view = ro.as_array();
    let mut out = Vec::with_capacity(shape[0]);
    for (i, row) in view.outer_iter().enumerate() {
        let mut r = [0.0; 4];
        for (j, v) in row.iter().enumerate() {
            if !v.is_finite() {
                return Err(value_error(format!(
                    "{name}[{i}, {j}] is {v}: every value must be finite"
                )));
            }
            r[j] = *v;
        }
        out.push(r);
    }
    Ok(out)
}

/// As [`rows`] for three columns.
pub fn vec3s(name: &str, obj: &Bound<'_, PyAny>, n: Option<usize>) -> PyResult<Vec<[f64; 3]>> {
    Ok(rows(name, obj, 3, n)?
        .into_iter()
        .map(|r| [r[0], r[1], r[2]])
        .collect())
}

/// An int64 array of nanosecond timestamps: one-dimensional, non-negative and strictly
/// increasing (as host-sim's dataset reader requires of every sensor file).
pub fn times(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<Vec<u64>> {
    let arr = obj.cast::<PyArrayDyn<i64>>().map_err(|_| {
        PyTypeError::new_err(format!(
            "{name}: expected an int64 numpy array of nanoseconds, got {}",
            type_name(obj)
        ))
    })?;
    let ro = arr.readonly();
    if ro.ndim() != 1 {
        return Err(value_error(format!(
            "{name}: shape {:?}, expected (N,)",
            ro.shape()
        )));
    }
    let mut out: Vec<u64> = Vec::with_capacity(ro.len());
    for (i, &v) in ro.as_array().iter().enumerate() {
        let t = u64::try_from(v)
            .map_err(|_| value_error(format!("{name}[{i}] is {v}: times must be ≥ 0 ns")))?;
        if let Some(&prev) = out.last() {
            if t <= prev {
                return Err(value_error(format!(
                    "{name}[{i}] = {t} is not after {name}[{}] = {prev}: times must be strictly increasing",
                    i - 1
                )));
            }
        }
        out.push(t);
    }
    Ok(out)
}

fn type_name(obj: &Bound<'_, PyAny>) -> String {
    if let Ok(dtype) = obj.getattr("dtype") {
        return format!("an array of dtype {dtype}");
    }
    obj.get_type()
        .name()
        .map_or_else(|_| "an unknown type".into(), |n| n.to_string())
}

/// A float64 array of shape `(n,)`, every value finite.
pub fn floats(name: &str, obj: &Bound<'_, PyAny>, n: usize) -> PyResult<Vec<f64>> {
    floats_or_nan(name, obj, n, false)
}

/// As [`floats`]; with `allow_nan`, NaN too (an absent value).
pub fn floats_or_nan(
    name: &str,
    obj: &Bound<'_, PyAny>,
    n: usize,
    allow_nan: bool,
) -> PyResult<Vec<f64>> {
    let arr = obj.cast::<PyArrayDyn<f64>>().map_err(|_| {
        PyTypeError::new_err(format!(
            "{name}: expected a float64 numpy array, got {}",
            type_name(obj)
        ))
    })?;
    let ro = arr.readonly();
    if ro.shape() != [n] {
        return Err(value_error(format!(
            "{name}: shape {:?}, expected ({n},)",
            ro.shape()
        )));
    }
    let mut out = Vec::with_capacity(n);
    for (i, v) in ro.as_array().iter().enumerate() {
        if !(v.is_finite() || allow_nan && v.is_nan()) {
            return Err(value_error(format!(
                "{name}[{i}] is {v}: every value must be finite"
            )));
        }
        out.push(*v);
    }
    Ok(out)
}

/// Rows of `cols` (≤ 4) values, each either all finite or all NaN (`None`: absent).
pub fn nan_rows(
    name: &str,
    obj: &Bound<'_, PyAny>,
    cols: usize,
    n: usize,
) -> PyResult<Vec<Option<[f64; 4]>>> {
    let arr = obj.cast::<PyArrayDyn<f64>>().map_err(|_| {
        PyTypeError::new_err(format!(
            "{name}: expected a float64 numpy array, got {}",
            type_name(obj)
        ))
    })?;
    let ro = arr.readonly();
    let shape = ro.shape().to_vec();
    if shape.len() != 2 || shape[0] != n || shape[1] != cols || cols > 4 {
        return Err(value_error(format!(
            "{name}: shape {shape:?}, expected ({n}, {cols})"
        )));
    }
    let mut out = Vec::with_capacity(n);
    for (i, row) in ro.as_array().outer_iter().enumerate() {
        if row.iter().all(|v| v.is_nan()) {
            out.push(None);
            continue;
        }
        let mut r = [0.0; 4];
        for (j, v) in row.iter().enumerate() {
            if !v.is_finite() {
                return Err(value_error(format!(
                    "{name}[{i}, {j}] is {v}: a row is either finite or all NaN (absent)"
                )));
            }
            r[j] = *v;
        }
        out.push(Some(r));
    }
    Ok(out)
}

/// A checked `[f64; 3]` in the navigator's scalar.
pub fn lit3<T: Real>(v: &[f64; 3]) -> Vector3<T> {
    Vector3::new(T::lit(v[0]), T::lit(v[1]), T::lit(v[2]))
}

/// A `(len / cols, cols)` float64 array of an output, row by row.
pub fn matrix<'py>(py: Python<'py>, v: Vec<f64>, cols: usize) -> PyResult<Bound<'py, PyAny>> {
    let rows = v.len() / cols;
    let a = Array2::from_shape_vec((rows, cols), v)
        .map_err(|e| PyValueError::new_err(format!("output shape: {e}")))?;
    Ok(a.into_pyarray(py).into_any())
}

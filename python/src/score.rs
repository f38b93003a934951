//! host-sim's scoring (`metrics.json`: BROAD's RMSEs, the attitude RMSE, ATE and RPE) of
//! estimates given as arrays, each estimate scored against the truth at its time as host-sim's
//! replay does (interpolated between the rows around it; nothing where rows are lost).

use crate::arrays;
use crate::config::{object_to_py, to_py};
use estimator_core::lie::So3;
use host_sim::dataset::read::Truth;
use host_sim::metrics::trajectory::Delta;
use host_sim::metrics::{Estimate, Scorer};
use host_sim::replay::TruthCursor;
use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::convert::Infallible;

fn attitude(q: &[f64; 4]) -> So3<f64> {
    // Taken as given (no re-normalization), as host-sim holds the estimate it writes.
    So3::from_unit_quaternion(UnitQuaternion::new_unchecked(Quaternion::new(
        q[0], q[1], q[2], q[3],
    )))
}

/// `score(t, quaternion, truth_t, truth_q, ...)`: see the Python docstring.
#[pyfunction]
#[pyo3(signature = (t, quaternion, truth_t, truth_q, movement=None, sigma=None, position=None, truth_p=None, rpe_delta=1.0, rpe_delta_unit="s"))]
#[allow(clippy::too_many_arguments)]
pub fn score<'py>(
    py: Python<'py>,
    t: &Bound<'py, PyAny>,
    quaternion: &Bound<'py, PyAny>,
    truth_t: &Bound<'py, PyAny>,
    truth_q: &Bound<'py, PyAny>,
    movement: Option<&Bound<'py, PyAny>>,
    sigma: Option<&Bound<'py, PyAny>>,
    position: Option<&Bound<'py, PyAny>>,
    truth_p: Option<&Bound<'py, PyAny>>,
    rpe_delta: f64,
    rpe_delta_unit: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let t = arrays::times("t", t)?;
    let n = t.len();
    // Rows without an estimate (NaN: before the navigator started) are not scored, as host-sim
    // writes none for them; any other non-finite value is an error.
    let q = arrays::nan_rows("quaternion", quaternion, 4, n)?;
    let truth_t = arrays::times("truth_t", truth_t)?;
    let m = truth_t.len();
    let truth_q = arrays::rows("truth_q", truth_q, 4, Some(m))?;
    let sigma = sigma
        .map(|s| arrays::nan_rows("sigma", s, 3, n))
        .transpose()?;
    let (position, truth_p) = match (position, truth_p) {
        (Some(p), Some(tp)) => (
            Some(arrays::nan_rows("position", p, 3, n)?),
            Some(arrays::vec3s("truth_p", tp, Some(m))?),
        ),
        (None, None) => (None, None),
        _ => {
            return Err(PyValueError::new_err(
                "position and truth_p go together (both or neither)",
            ))
        }
    };
    let movement = match movement {
        Some(mv) => Some(intervals(mv)?),
        None => None,
    };
    if !(rpe_delta.is_finite() && rpe_delta > 0.0) {
        return Err(PyValueError::new_err(format!(
            "rpe_delta is {rpe_delta}, must be > 0"
        )));
    }
    let delta = match rpe_delta_unit {
        "s" => Delta::Seconds(rpe_delta),
        "m" => Delta::Metres(rpe_delta),
        other => {
            return Err(PyValueError::new_err(format!(
                "rpe_delta_unit '{other}' (use 's' or 'm')"
            )))
        }
    };
    let mut truth = Vec::with_capacity(m);
    for (i, r) in truth_q.iter().enumerate() {
        let att = So3::from_wxyz(r[0], r[1], r[2], r[3]).ok_or_else(|| {
            PyValueError::new_err(format!("truth_q[{i}] is a quaternion of zero norm"))
        })?;
        truth.push(Truth {
            t_ns: truth_t[i],
            position: truth_p
                .as_ref()
                .map_or_else(Vector3::zeros, |p| Vector3::from(p[i])),
            attitude: att,
            velocity: Vector3::zeros(),
            gyro_bias: Vector3::zeros(),
            accel_bias: Vector3::zeros(),
        });
    }

    let mut scorer = Scorer::default();
    scorer.set_movement(movement);
    if let Some(first) = truth_t.first() {
        scorer.set_truth_start(*first);
    }
    scorer.rpe_delta = Some(delta);
    // host-sim's own truth lookup, over the arrays' rows.
    let mut cursor = TruthCursor::new(truth.iter().copied().map(Ok::<_, Infallible>));
    for (i, &t_ns) in t.iter().enumerate() {
        let Some(qi) = q[i] else { continue };
        let Ok(Some(tr)) = cursor.at(t_ns) else {
            continue;
        };
        // The attitude covariance from the per-axis sigma, for the NEES (host-sim has the
        // whole 3×3 block); unit where none is given.
        let att_cov = sigma
            .as_ref()
            .and_then(|s| s[i])
            .map_or_else(Matrix3::identity, |s| {
                Matrix3::from_diagonal(&Vector3::new(s[0] * s[0], s[1] * s[1], s[2] * s[2]))
            });
        let pos = position.as_ref().and_then(|p| p[i]);
        let e = Estimate {
            t_ns,
            position: pos.map_or_else(Vector3::zeros, |p| Vector3::new(p[0], p[1], p[2])),
            attitude: attitude(&qi),
            velocity: Vector3::zeros(),
            gyro_bias: Vector3::zeros(),
            accel_bias: Vector3::zeros(),
            cov: [
                Some(att_cov),
                None,
                pos.map(|_| Matrix3::identity()),
                None,
                None,
            ],
            valid: None,
        };
        scorer.add(&e, &tr);
    }
    let json =
        serde_json::to_value(scorer.metrics()).map_err(|e| PyValueError::new_err(e.to_string()))?;
    match &json {
        serde_json::Value::Object(o) => Ok(object_to_py(py, o)?.into_any()),
        other => to_py(py, other),
    }
}

/// Movement intervals: int64 `(K, 2)` of `[start, end]` ns, ordered and disjoint.
fn intervals(obj: &Bound<'_, PyAny>) -> PyResult<Vec<(u64, u64)>> {
    use numpy::{PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
    let arr = obj.cast::<PyArrayDyn<i64>>().map_err(|_| {
        pyo3::exceptions::PyTypeError::new_err("movement: expected an int64 numpy array of ns")
    })?;
    let ro = arr.readonly();
    let shape = ro.shape().to_vec();
    if shape.len() != 2 || shape[1] != 2 {
        return Err(PyValueError::new_err(format!(
            "movement: shape {shape:?}, expected (K, 2)"
        )));
    }
    let mut out: Vec<(u64, u64)> = Vec::with_capacity(shape[0]);
    for (i, row) in ro.as_array().outer_iter().enumerate() {
        let (a, b) = (row[0], row[1]);
        let (Ok(a), Ok(b)) = (u64::try_from(a), u64::try_from(b)) else {
            return Err(PyValueError::new_err(format!(
                "movement[{i}] = [{a}, {b}]: times must be ≥ 0 ns"
            )));
        };
        if a > b || out.last().is_some_and(|&(_, e)| a <= e) {
            return Err(PyValueError::new_err(format!(
                "movement[{i}] = [{a}, {b}]: intervals must be ordered, disjoint, start ≤ end"
            )));
        }
        out.push((a, b));
    }
    Ok(out)
}

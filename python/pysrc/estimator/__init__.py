"""Attitude and inertial navigation from estimator-core, over NumPy arrays.

Conventions (every function and class):

* Times are ``int64`` nanoseconds on one clock, strictly increasing per sensor.
* The world frame is ENU (x east, y north, z up); the body frame is the IMU's.
* Quaternions are Hamilton ``(w, x, y, z)``, rotating body to world (``world_from_body``).
* Gyro in rad/s, accelerometer (specific force) in m/s², magnetometer in µT, all in the body
  frame; angles and sigmas in radians unless a name ends in ``_deg``.

The navigators run in ``f32`` by default, like host-sim's replay (``precision="f32"``), and are
configured by the keys of :func:`default_config` (host-sim's ``replay.toml`` keys plus the
sensor parameters of a dataset's ``sensor.yaml`` files).

Bad input (wrong dtype, shape or length, NaN, unsorted times, unknown configuration keys)
raises ``TypeError`` or ``ValueError`` naming the argument and the index, before anything runs.
"""

from __future__ import annotations

from typing import Any, Dict, NamedTuple, Optional

import numpy as np

from . import _estimator
from ._estimator import REASONS, default_config

__all__ = [
    "AttitudeEstimate",
    "AttitudeNavigator",
    "InsNavigator",
    "AttitudeRun",
    "Dataset",
    "InsRun",
    "REASONS",
    "default_config",
    "read_dataset",
    "replay",
    "run_attitude",
    "run_ins",
    "score",
    "simulate",
]


def _floats(name: str, x: Any) -> np.ndarray:
    """``x`` as a C-contiguous float64 array; TypeError for non-real dtypes."""
    a = np.asarray(x)
    if a.dtype.kind not in "fiu":
        raise TypeError(f"{name}: dtype {a.dtype} is not a real number type")
    return np.ascontiguousarray(a, dtype=np.float64)


def _times(name: str, x: Any) -> np.ndarray:
    """``x`` as an int64 array of nanoseconds; TypeError for non-integer dtypes."""
    a = np.asarray(x)
    if a.dtype.kind not in "iu":
        raise TypeError(
            f"{name}: dtype {a.dtype}, expected integer nanoseconds (int64)"
        )
    if a.dtype.kind == "u" and a.size and int(a.max()) > np.iinfo(np.int64).max:
        i = int(np.argmax(a))
        raise ValueError(f"{name}[{i}] = {a[i]} ns is beyond int64")
    return np.ascontiguousarray(a, dtype=np.int64)


def _t_ns(t_ns: Any) -> int:
    """One timestamp: an integer number of ns, ≥ 0."""
    if isinstance(t_ns, (bool, np.bool_)) or not isinstance(t_ns, (int, np.integer)):
        raise TypeError(f"t_ns: {t_ns!r} is not an integer number of nanoseconds")
    if t_ns < 0 or t_ns > np.iinfo(np.uint64).max:
        raise ValueError(f"t_ns: {t_ns} is outside [0, 2**64) ns")
    return int(t_ns)


class AttitudeRun(NamedTuple):
    """Per IMU sample (N rows), the navigator's output after that sample.

    Rows before the navigator started (``estimated`` false) hold NaN.
    """

    t: np.ndarray
    """(N,) int64, ns: the IMU times."""
    quaternion: np.ndarray
    """(N, 4) float64: (w, x, y, z), world (ENU) from body."""
    sigma: np.ndarray
    """(N, 3) float64, rad: 1σ of the attitude error per axis (the filter's error state)."""
    gyro_bias: np.ndarray
    """(N, 3) float64, rad/s, body frame."""
    accel_bias: np.ndarray
    """(N, 3) float64, m/s², body frame."""
    estimated: np.ndarray
    """(N,) bool: the navigator has started (host-sim writes a row of estimate.csv)."""
    tilt_valid: np.ndarray
    """(N,) bool: the tilt (roll, pitch) is within its configured 1σ limit."""
    heading_valid: np.ndarray
    """(N,) bool: the heading is valid."""
    tilt_reason: np.ndarray
    """(N,) uint8: index into :data:`REASONS` (0: valid)."""
    heading_reason: np.ndarray
    """(N,) uint8: index into :data:`REASONS` (0: valid)."""
    at_rest: np.ndarray
    """(N,) bool: the navigator found the body at rest."""
    imu_accepted: np.ndarray
    """(N,) bool: false where the navigator refused the sample (out of range...)."""
    mag_accepted: np.ndarray
    """(M,) bool per magnetometer sample (empty without a magnetometer)."""


class AttitudeEstimate(NamedTuple):
    """The attitude navigator's estimate after its last sample."""

    t_ns: int
    """ns: the time of the last sample."""
    quaternion: tuple
    """(w, x, y, z), world (ENU) from body."""
    sigma: tuple
    """rad: 1σ of the attitude error per axis."""
    sigma_tilt: float
    """rad: 1σ of the tilt (the larger horizontal axis)."""
    sigma_heading: float
    """rad: 1σ of the heading."""
    gyro_bias: tuple
    """rad/s, body frame."""
    accel_bias: tuple
    """m/s², body frame."""
    tilt_valid: bool
    heading_valid: bool
    tilt_reason: str
    """one of :data:`REASONS`."""
    heading_reason: str
    at_rest: bool
    magnetic: str
    """the magnetometer's state (not_configured, waiting, fused, disturbed, rejected, stuck)."""
    event: Optional[str]
    clipped: bool


class AttitudeNavigator:
    """The attitude navigator (AHRS), one timestamped sample at a time.

    ``AttitudeNavigator(config=None, **kwargs)``: the configuration keys of
    :func:`default_config`, as a dict and/or keywords. A magnetometer is configured unless
    ``use_magnetometer=False``.
    """

    def __init__(self, config: Optional[Dict[str, Any]] = None, **kwargs: Any) -> None:
        self._nav = _estimator.AttitudeNavigator(config, **kwargs)

    def imu(self, t_ns: int, gyr: Any, acc: Any) -> Dict[str, Any]:
        """One IMU sample: ``gyr`` (3,) rad/s and ``acc`` (3,) m/s² (specific force), body frame.

        Returns the report (validity, rest, magnetometer state). A sample the navigator
        refuses (time not after the previous one, NaN, a zero accelerometer...) raises
        ValueError and leaves the navigator unchanged.
        """
        return self._nav.imu(_t_ns(t_ns), gyr, acc)

    def magnetometer(self, t_ns: int, mag: Any) -> Dict[str, Any]:
        """One magnetometer sample ``mag`` (3,) µT, body frame; as :meth:`imu`."""
        return self._nav.magnetometer(_t_ns(t_ns), mag)

    def estimate(self) -> Optional[AttitudeEstimate]:
        """The estimate after the last sample; ``None`` before the navigator started."""
        d = self._nav.estimate()
        if d is None:
            return None
        return AttitudeEstimate(
            **{k: (tuple(v) if isinstance(v, list) else v) for k, v in d.items()}
        )


def run_attitude(
    t: Any,
    gyr: Any,
    acc: Any,
    mag: Any = None,
    mag_t: Any = None,
    **config: Any,
) -> AttitudeRun:
    """Runs the attitude navigator over whole recordings, as ``host-sim replay`` does.

    Args:
        t: (N,) int64 ns, the IMU times, strictly increasing.
        gyr: (N, 3) rad/s, body frame.
        acc: (N, 3) m/s², specific force, body frame.
        mag: (M, 3) µT, body frame, or None (no magnetometer).
        mag_t: (M,) int64 ns, strictly increasing; with ``mag``.
        **config: keys of :func:`default_config` (``read_dataset(...).config`` reproduces
            host-sim's configuration for a dataset).

    The samples are fed in time order, the IMU first at equal times. Every input is checked
    before the run: TypeError for a wrong dtype, ValueError naming the argument and the index
    for a wrong shape or length, a NaN or infinite value, or times not strictly increasing.
    """
    t = _times("t", t)
    gyr = _floats("gyr", gyr)
    acc = _floats("acc", acc)
    if mag is not None:
        mag = _floats("mag", mag)
    if mag_t is not None:
        mag_t = _times("mag_t", mag_t)
    d = _estimator.run_attitude(t, gyr, acc, mag, mag_t, **config)
    return AttitudeRun(t=t, **d)


class InsRun(NamedTuple):
    """Per IMU sample (N rows), the INS navigator's output after that sample.

    Rows before the navigator started (``estimated`` false) hold NaN.
    """

    t: np.ndarray
    """(N,) int64, ns: the IMU times."""
    quaternion: np.ndarray
    """(N, 4) float64: (w, x, y, z), world (ENU) from body."""
    position: np.ndarray
    """(N, 3) m, world (ENU): the IMU's position."""
    velocity: np.ndarray
    """(N, 3) m/s, world (ENU)."""
    sigma: np.ndarray
    """(N, 15) 1σ of the error state: attitude (rad, 3), velocity (m/s, 3), position (m, 3),
    gyro bias (rad/s, 3), accelerometer bias (m/s², 3)."""
    gyro_bias: np.ndarray
    """(N, 3) rad/s, body frame."""
    accel_bias: np.ndarray
    """(N, 3) m/s², body frame."""
    estimated: np.ndarray
    """(N,) bool: the navigator has started (host-sim writes a row of estimate.csv)."""
    tilt_valid: np.ndarray
    heading_valid: np.ndarray
    velocity_valid: np.ndarray
    position_valid: np.ndarray
    gyro_bias_valid: np.ndarray
    accel_bias_valid: np.ndarray
    imu_accepted: np.ndarray
    """(N,) bool: false where the navigator refused the sample."""
    gnss_accepted: np.ndarray
    """(G,) bool per fix: false where the navigator refused it."""
    magnetometer_used: bool


class InsNavigator:
    """The INS navigator, one timestamped sample at a time, configured as :func:`run_ins`.

    ``InsNavigator(config=None, magnetometer=False, barometer=False, **kwargs)``: the
    configuration keys of :func:`default_config`; ``magnetometer`` and ``barometer`` say which
    of those sensors will be given. A sample the navigator refuses raises ValueError and leaves
    it unchanged.
    """

    def __init__(
        self,
        config: Optional[Dict[str, Any]] = None,
        magnetometer: bool = False,
        barometer: bool = False,
        **kwargs: Any,
    ) -> None:
        self._nav = _estimator.InsNavigator(config, magnetometer, barometer, **kwargs)

    def imu(self, t_ns: int, gyr: Any, acc: Any) -> Dict[str, Any]:
        """One IMU sample: ``gyr`` (3,) rad/s, ``acc`` (3,) m/s², body frame. Returns the
        validity of each quantity after it."""
        return self._nav.imu(_t_ns(t_ns), gyr, acc)

    def gnss(
        self,
        t_ns: int,
        position: Any,
        sigma_p: float,
        velocity: Any = None,
        sigma_v: Optional[float] = None,
        sigma_p_up: Optional[float] = None,
    ) -> None:
        """One fix: ``position`` (3,) m ENU with horizontal 1σ ``sigma_p`` (m) and vertical
        ``sigma_p_up`` (default ``sigma_p``), ``velocity`` (3,) m/s with ``sigma_v``, or
        neither. ``t_ns`` is the row's time; the configured ``gnss_latency_s`` is taken off."""
        self._nav.gnss(_t_ns(t_ns), position, float(sigma_p), velocity, sigma_v, sigma_p_up)

    def magnetometer(self, t_ns: int, mag: Any) -> None:
        """One magnetometer sample ``mag`` (3,) µT, body frame."""
        self._nav.magnetometer(_t_ns(t_ns), mag)

    def barometer(self, t_ns: int, altitude: float) -> None:
        """One barometric altitude, m (up)."""
        self._nav.barometer(_t_ns(t_ns), float(altitude))

    def estimate(self) -> Optional[Dict[str, Any]]:
        """The estimate after the last sample (``quaternion`` w, x, y, z world ENU from body;
        ``position`` m, ``velocity`` m/s, ``gyro_bias``, ``accel_bias``, ``sigma`` the 15
        sigmas as in :func:`run_ins`); ``None`` before the INS started."""
        return self._nav.estimate()


def run_ins(
    t: Any,
    gyr: Any,
    acc: Any,
    gnss_t: Any,
    gnss_p: Any,
    gnss_sigma_p: Any,
    gnss_v: Any = None,
    gnss_sigma_v: Any = None,
    gnss_sigma_p_up: Any = None,
    mag: Any = None,
    mag_t: Any = None,
    baro: Any = None,
    baro_t: Any = None,
    **config: Any,
) -> InsRun:
    """Runs the INS navigator over whole recordings, as ``host-sim replay`` does on a GNSS
    dataset.

    Args:
        t, gyr, acc: as :func:`run_attitude`.
        gnss_t: (G,) int64 ns, each fix's time as received; the navigator takes it as valid
            ``config["gnss_latency_s"]`` earlier.
        gnss_p: (G, 3) m, antenna position, world (ENU); the antenna sits at
            ``config["gnss_lever_arm"]`` (m, body frame).
        gnss_sigma_p: (G,) m, horizontal position 1σ (> 0).
        gnss_v: (G, 3) m/s, world (ENU), NaN rows for fixes without a velocity; with
            ``gnss_sigma_v`` (G,) m/s.
        gnss_sigma_p_up: (G,) m, vertical position 1σ (default ``gnss_sigma_p``).
        mag, mag_t: as :func:`run_attitude` (the INS fuses the whole field).
        baro: (B,) m, barometric altitude, at ``baro_t`` (B,) int64 ns; 1σ
            ``config["baro_sigma"]``.
        **config: keys of :func:`default_config`.

    Samples are fed in time order; at equal times IMU, magnetometer, GNSS, barometer. Every
    input is checked first, as in :func:`run_attitude`.
    """
    t = _times("t", t)
    args: Dict[str, Any] = {
        "gyr": _floats("gyr", gyr),
        "acc": _floats("acc", acc),
        "gnss_t": _times("gnss_t", gnss_t),
        "gnss_p": _floats("gnss_p", gnss_p),
        "gnss_sigma_p": _floats("gnss_sigma_p", gnss_sigma_p),
    }
    optional = {
        "gnss_v": (gnss_v, _floats),
        "gnss_sigma_v": (gnss_sigma_v, _floats),
        "gnss_sigma_p_up": (gnss_sigma_p_up, _floats),
        "mag": (mag, _floats),
        "mag_t": (mag_t, _times),
        "baro": (baro, _floats),
        "baro_t": (baro_t, _times),
    }
    for name, (value, conv) in optional.items():
        args[name] = None if value is None else conv(name, value)
    d = _estimator.run_ins(t, **args, **config)
    return InsRun(t=t, **d)


class Dataset(NamedTuple):
    """A dataset folder (host-sim's EuRoC / ASL layout) as arrays."""

    path: str
    """the folder read (a EuRoC sequence's ``mav0/``)."""
    imu_t: np.ndarray
    """(N,) int64 ns."""
    gyr: np.ndarray
    """(N, 3) rad/s, body frame."""
    acc: np.ndarray
    """(N, 3) m/s², body frame."""
    mag_t: Optional[np.ndarray]
    """(M,) int64 ns, or None without a magnetometer (or with ``use_magnetometer = false``)."""
    mag: Optional[np.ndarray]
    """(M, 3) µT, body frame."""
    truth_t: Optional[np.ndarray]
    """(K,) int64 ns, or None without ground truth."""
    truth_q: Optional[np.ndarray]
    """(K, 4) (w, x, y, z), world (ENU) from body."""
    truth_p: Optional[np.ndarray]
    """(K, 3) m, world (ENU)."""
    movement: Optional[np.ndarray]
    """(J, 2) int64 ns, BROAD's movement intervals [start, end] (``movement.csv``), or None."""
    has_gnss: bool
    """the dataset has GNSS: host-sim replays it with the INS navigator (:func:`run_ins`)."""
    gnss_t: Optional[np.ndarray]
    """(G,) int64 ns, each fix's row time (the receiver's latency, ``config["gnss_latency_s"]``,
    not taken off)."""
    gnss_p: Optional[np.ndarray]
    """(G, 3) m, antenna position, world (ENU)."""
    gnss_v: Optional[np.ndarray]
    """(G, 3) m/s, world (ENU); NaN rows where the fix has no velocity."""
    gnss_sigma_p: Optional[np.ndarray]
    """(G,) m, horizontal position 1σ."""
    gnss_sigma_p_up: Optional[np.ndarray]
    """(G,) m, vertical position 1σ."""
    gnss_sigma_v: Optional[np.ndarray]
    """(G,) m/s, velocity 1σ (NaN without a velocity)."""
    baro_t: Optional[np.ndarray]
    """(B,) int64 ns."""
    baro: Optional[np.ndarray]
    """(B,) m, barometric altitude."""
    config: Dict[str, Any]
    """keyword arguments of :func:`run_attitude` that configure it as host-sim replay does."""


def read_dataset(path: Any) -> Dataset:
    """Reads a dataset folder with host-sim's reader (the rows host-sim's replay takes).

    Its ``replay.toml`` (if any) and ``sensor.yaml`` files give ``config``.
    Raises ValueError for a malformed dataset, naming the file and line.
    """
    return Dataset(**_estimator.read_dataset(str(path)))


def score(
    t: Any,
    quaternion: Any,
    truth_t: Any,
    truth_q: Any,
    movement: Any = None,
    sigma: Any = None,
    position: Any = None,
    truth_p: Any = None,
    rpe_delta: float = 1.0,
    rpe_delta_unit: str = "s",
) -> Dict[str, Any]:
    """host-sim's metrics (its ``metrics.json`` as a dict) of estimates against the truth.

    Args:
        t: (N,) int64 ns of the estimates.
        quaternion: (N, 4) (w, x, y, z) world from body; rows all NaN are not scored.
        truth_t: (K,) int64 ns; truth_q: (K, 4) (w, x, y, z). Each estimate is scored against
            the truth interpolated at its time (slerp), not where truth rows are lost.
        movement: (J, 2) int64 ns, BROAD's movement intervals; gives ``broad``:
            ``total_deg``, ``heading_deg``, ``inclination_deg`` (RMSEs over the samples inside
            them) and ``inside_3sigma`` (from ``sigma``'s diagonal).
        sigma: (N, 3) rad, per-axis attitude 1σ, for the NEES.
        position, truth_p: (N, 3) and (K, 3) m, world: give ``ate`` (after an SE(3)
            alignment), ``ate_by_alignment`` and ``rpe`` (over ``rpe_delta`` in
            ``rpe_delta_unit``, ``"s"`` or ``"m"``).

    Also ``attitude_rmse_deg``, ``attitude_rmse_yaw_aligned_deg`` and ``samples_scored``.
    """
    t = _times("t", t)
    quaternion = _floats("quaternion", quaternion)
    truth_t = _times("truth_t", truth_t)
    truth_q = _floats("truth_q", truth_q)
    if movement is not None:
        movement = _times("movement", movement)
    if sigma is not None:
        sigma = _floats("sigma", sigma)
    if position is not None:
        position = _floats("position", position)
    if truth_p is not None:
        truth_p = _floats("truth_p", truth_p)
    return _estimator.score(
        t,
        quaternion,
        truth_t,
        truth_q,
        movement,
        sigma,
        position,
        truth_p,
        float(rpe_delta),
        rpe_delta_unit,
    )


def simulate(scenario: str, seed: int, out: Any) -> None:
    """host-sim's simulator: writes scenario ``scenario`` (``host-sim scenarios`` lists them)
    with ``seed`` as a dataset folder ``out`` (which must not exist)."""
    _estimator.simulate(scenario, int(seed), str(out))


def replay(dataset: Any, out: Any) -> Dict[str, Any]:
    """``host-sim replay DATASET --out OUT``: writes host-sim's outputs (``estimate.csv``...)
    to ``out`` (which must not exist) and returns its ``metrics.json`` as a dict."""
    return _estimator.replay(str(dataset), str(out))

"""Type stubs of the estimator package (see __init__.py for the full documentation).

Units and frames: times int64 ns; world ENU; quaternions (w, x, y, z) world from body;
gyro rad/s, accelerometer m/s², magnetometer µT, body frame; angles and sigmas rad.
"""

from typing import Any, Dict, List, NamedTuple, Optional, Tuple, Union
import os

import numpy as np
import numpy.typing as npt

_PathLike = Union[str, "os.PathLike[str]"]
_Floats = npt.ArrayLike
_Times = npt.ArrayLike

REASONS: List[str]

def default_config() -> Dict[str, Any]: ...

class AttitudeRun(NamedTuple):
    t: npt.NDArray[np.int64]  # (N,) ns
    quaternion: npt.NDArray[np.float64]  # (N, 4) w, x, y, z; world (ENU) from body; NaN before start
    sigma: npt.NDArray[np.float64]  # (N, 3) rad, attitude error 1σ per axis
    gyro_bias: npt.NDArray[np.float64]  # (N, 3) rad/s, body
    accel_bias: npt.NDArray[np.float64]  # (N, 3) m/s², body
    estimated: npt.NDArray[np.bool_]  # (N,)
    tilt_valid: npt.NDArray[np.bool_]  # (N,)
    heading_valid: npt.NDArray[np.bool_]  # (N,)
    tilt_reason: npt.NDArray[np.uint8]  # (N,) index into REASONS
    heading_reason: npt.NDArray[np.uint8]  # (N,) index into REASONS
    at_rest: npt.NDArray[np.bool_]  # (N,)
    imu_accepted: npt.NDArray[np.bool_]  # (N,)
    mag_accepted: npt.NDArray[np.bool_]  # (M,)

class AttitudeEstimate(NamedTuple):
    t_ns: int
    quaternion: Tuple[float, float, float, float]  # w, x, y, z; world (ENU) from body
    sigma: Tuple[float, float, float]  # rad
    sigma_tilt: float  # rad
    sigma_heading: float  # rad
    gyro_bias: Tuple[float, float, float]  # rad/s, body
    accel_bias: Tuple[float, float, float]  # m/s², body
    tilt_valid: bool
    heading_valid: bool
    tilt_reason: str
    heading_reason: str
    at_rest: bool
    magnetic: str
    event: Optional[str]
    clipped: bool

class AttitudeNavigator:
    def __init__(self, config: Optional[Dict[str, Any]] = ..., **kwargs: Any) -> None: ...
    def imu(self, t_ns: int, gyr: _Floats, acc: _Floats) -> Dict[str, Any]: ...
    def magnetometer(self, t_ns: int, mag: _Floats) -> Dict[str, Any]: ...
    def estimate(self) -> Optional[AttitudeEstimate]: ...

class InsNavigator:
    def __init__(
        self,
        config: Optional[Dict[str, Any]] = ...,
        magnetometer: bool = ...,
        barometer: bool = ...,
        **kwargs: Any,
    ) -> None: ...
    def imu(self, t_ns: int, gyr: _Floats, acc: _Floats) -> Dict[str, Any]: ...
    def gnss(
        self,
        t_ns: int,
        position: _Floats,
        sigma_p: float,
        velocity: Optional[_Floats] = ...,
        sigma_v: Optional[float] = ...,
        sigma_p_up: Optional[float] = ...,
    ) -> None: ...
    def magnetometer(self, t_ns: int, mag: _Floats) -> None: ...
    def barometer(self, t_ns: int, altitude: float) -> None: ...
    def estimate(self) -> Optional[Dict[str, Any]]: ...

def run_attitude(
    t: _Times,
    gyr: _Floats,
    acc: _Floats,
    mag: Optional[_Floats] = ...,
    mag_t: Optional[_Times] = ...,
    **config: Any,
) -> AttitudeRun: ...

class InsRun(NamedTuple):
    t: npt.NDArray[np.int64]  # (N,) ns
    quaternion: npt.NDArray[np.float64]  # (N, 4) w, x, y, z; world (ENU) from body
    position: npt.NDArray[np.float64]  # (N, 3) m, world (ENU)
    velocity: npt.NDArray[np.float64]  # (N, 3) m/s, world (ENU)
    sigma: npt.NDArray[np.float64]  # (N, 15) attitude rad, velocity m/s, position m, biases
    gyro_bias: npt.NDArray[np.float64]  # (N, 3) rad/s, body
    accel_bias: npt.NDArray[np.float64]  # (N, 3) m/s², body
    estimated: npt.NDArray[np.bool_]
    tilt_valid: npt.NDArray[np.bool_]
    heading_valid: npt.NDArray[np.bool_]
    velocity_valid: npt.NDArray[np.bool_]
    position_valid: npt.NDArray[np.bool_]
    gyro_bias_valid: npt.NDArray[np.bool_]
    accel_bias_valid: npt.NDArray[np.bool_]
    imu_accepted: npt.NDArray[np.bool_]
    gnss_accepted: npt.NDArray[np.bool_]  # (G,)
    magnetometer_used: bool

def run_ins(
    t: _Times,
    gyr: _Floats,
    acc: _Floats,
    gnss_t: _Times,
    gnss_p: _Floats,
    gnss_sigma_p: _Floats,
    gnss_v: Optional[_Floats] = ...,
    gnss_sigma_v: Optional[_Floats] = ...,
    gnss_sigma_p_up: Optional[_Floats] = ...,
    mag: Optional[_Floats] = ...,
    mag_t: Optional[_Times] = ...,
    baro: Optional[_Floats] = ...,
    baro_t: Optional[_Times] = ...,
    **config: Any,
) -> InsRun: ...

class Dataset(NamedTuple):
    path: str
    imu_t: npt.NDArray[np.int64]  # (N,) ns
    gyr: npt.NDArray[np.float64]  # (N, 3) rad/s, body
    acc: npt.NDArray[np.float64]  # (N, 3) m/s², body
    mag_t: Optional[npt.NDArray[np.int64]]  # (M,) ns
    mag: Optional[npt.NDArray[np.float64]]  # (M, 3) µT, body
    truth_t: Optional[npt.NDArray[np.int64]]  # (K,) ns
    truth_q: Optional[npt.NDArray[np.float64]]  # (K, 4) w, x, y, z; world (ENU) from body
    truth_p: Optional[npt.NDArray[np.float64]]  # (K, 3) m, world (ENU)
    movement: Optional[npt.NDArray[np.int64]]  # (J, 2) ns, [start, end]
    has_gnss: bool
    gnss_t: Optional[npt.NDArray[np.int64]]  # (G,) ns, as received
    gnss_p: Optional[npt.NDArray[np.float64]]  # (G, 3) m, world (ENU)
    gnss_v: Optional[npt.NDArray[np.float64]]  # (G, 3) m/s, world (ENU); NaN rows: none
    gnss_sigma_p: Optional[npt.NDArray[np.float64]]  # (G,) m
    gnss_sigma_p_up: Optional[npt.NDArray[np.float64]]  # (G,) m
    gnss_sigma_v: Optional[npt.NDArray[np.float64]]  # (G,) m/s
    baro_t: Optional[npt.NDArray[np.int64]]  # (B,) ns
    baro: Optional[npt.NDArray[np.float64]]  # (B,) m
    config: Dict[str, Any]

def read_dataset(path: _PathLike) -> Dataset: ...
def score(
    t: _Times,
    quaternion: _Floats,
    truth_t: _Times,
    truth_q: _Floats,
    movement: Optional[_Times] = ...,
    sigma: Optional[_Floats] = ...,
    position: Optional[_Floats] = ...,
    truth_p: Optional[_Floats] = ...,
    rpe_delta: float = ...,
    rpe_delta_unit: str = ...,
) -> Dict[str, Any]: ...
def simulate(scenario: str, seed: int, out: _PathLike) -> None: ...
def replay(dataset: _PathLike, out: _PathLike) -> Dict[str, Any]: ...

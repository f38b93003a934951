"""The native module (Rust, PyO3); use the package `estimator`, which checks dtypes first."""

from typing import Any, Dict, List, Optional

import numpy as np
import numpy.typing as npt

REASONS: List[str]

def default_config() -> Dict[str, Any]: ...

class AttitudeNavigator:
    def __init__(self, config: Optional[Dict[str, Any]] = ..., **kwargs: Any) -> None: ...
    def imu(self, t_ns: int, gyr: Any, acc: Any) -> Dict[str, Any]: ...
    def magnetometer(self, t_ns: int, mag: Any) -> Dict[str, Any]: ...
    def estimate(self) -> Optional[Dict[str, Any]]: ...

class InsNavigator:
    def __init__(
        self,
        config: Optional[Dict[str, Any]] = ...,
        magnetometer: bool = ...,
        barometer: bool = ...,
        **kwargs: Any,
    ) -> None: ...
    def imu(self, t_ns: int, gyr: Any, acc: Any) -> Dict[str, Any]: ...
    def gnss(
        self,
        t_ns: int,
        position: Any,
        sigma_p: float,
        velocity: Any = ...,
        sigma_v: Optional[float] = ...,
        sigma_p_up: Optional[float] = ...,
    ) -> None: ...
    def magnetometer(self, t_ns: int, mag: Any) -> None: ...
    def barometer(self, t_ns: int, altitude: float) -> None: ...
    def estimate(self) -> Optional[Dict[str, Any]]: ...

def run_attitude(
    t: npt.NDArray[np.int64],
    gyr: npt.NDArray[np.float64],
    acc: npt.NDArray[np.float64],
    mag: Optional[npt.NDArray[np.float64]] = ...,
    mag_t: Optional[npt.NDArray[np.int64]] = ...,
    **config: Any,
) -> Dict[str, Any]: ...
def run_ins(t: npt.NDArray[np.int64], gyr: Any, acc: Any, gnss_t: Any, gnss_p: Any, gnss_sigma_p: Any, gnss_v: Any = ..., gnss_sigma_v: Any = ..., gnss_sigma_p_up: Any = ..., mag: Any = ..., mag_t: Any = ..., baro: Any = ..., baro_t: Any = ..., **config: Any) -> Dict[str, Any]: ...
def read_dataset(path: str) -> Dict[str, Any]: ...
def score(
    t: npt.NDArray[np.int64],
    quaternion: npt.NDArray[np.float64],
    truth_t: npt.NDArray[np.int64],
    truth_q: npt.NDArray[np.float64],
    movement: Optional[npt.NDArray[np.int64]] = ...,
    sigma: Optional[npt.NDArray[np.float64]] = ...,
    position: Optional[npt.NDArray[np.float64]] = ...,
    truth_p: Optional[npt.NDArray[np.float64]] = ...,
    rpe_delta: float = ...,
    rpe_delta_unit: str = ...,
) -> Dict[str, Any]: ...
def simulate(scenario: str, seed: int, out: str) -> None: ...
def replay(dataset: str, out: str) -> Dict[str, Any]: ...

"""Datasets for the tests: one host-sim simulates here (always), and BROAD trials from the
shared data folder when present."""

import os
from pathlib import Path

import pytest

import estimator

REPO = Path(__file__).resolve().parents[2]
# The shared data lies beside the repository; ESTIMATOR_DATASETS overrides it.
SHARED = Path(os.environ.get("ESTIMATOR_DATASETS", REPO.parent / "shared" / "datasets"))
BROAD_TRIAL = "01_undisturbed_slow_rotation_A"


@pytest.fixture(scope="session")
def simulated(tmp_path_factory):
    """A 60 s hand-held attitude dataset written by host-sim, and host-sim's replay of it."""
    root = tmp_path_factory.mktemp("sim")
    ds, out = root / "dataset", root / "replay"
    estimator.simulate("handheld_ahrs", 7, ds)
    metrics = estimator.replay(ds, out)
    return ds, out, metrics


@pytest.fixture(scope="session")
def broad(tmp_path_factory):
    """A BROAD trial from the shared datasets, and host-sim's replay of it."""
    ds = SHARED / "broad" / BROAD_TRIAL
    if not (ds / "imu0" / "data.csv").is_file():
        pytest.skip(f"BROAD trial not found at {ds} (set ESTIMATOR_DATASETS to the datasets folder)")
    out = tmp_path_factory.mktemp("broad") / "replay"
    metrics = estimator.replay(ds, out)
    return ds, out, metrics


@pytest.fixture(scope="session")
def simulated_ins(tmp_path_factory):
    """A 60 s flight with IMU, magnetometer and GNSS written by host-sim, and its replay."""
    root = tmp_path_factory.mktemp("sim_ins")
    ds, out = root / "dataset", root / "replay"
    estimator.simulate("default", 3, ds)
    metrics = estimator.replay(ds, out)
    return ds, out, metrics

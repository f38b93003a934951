"""Bad input raises a Python exception naming the argument (and index), never crashes."""

import numpy as np
import pytest

import estimator
from estimator import _estimator

N = 400


def good():
    t = np.arange(N, dtype=np.int64) * 5_000_000
    gyr = np.zeros((N, 3))
    acc = np.tile([0.0, 0.0, 9.81], (N, 1))
    mag_t = t[::4].copy()
    mag = np.tile([0.0, 20.0, -45.0], (len(mag_t), 1))
    return t, gyr, acc, mag, mag_t


def test_good_input_runs():
    r = estimator.run_attitude(*good())
    assert r.quaternion.shape == (N, 4)


@pytest.mark.parametrize(
    "change, error, words",
    [
        (lambda a: a.update(t=a["t"].astype(float)), TypeError, ["t", "integer"]),
        (lambda a: a.update(gyr=np.array([["a"] * 3] * N)), TypeError, ["gyr"]),
        (lambda a: a.update(gyr=np.zeros((N, 4))), ValueError, ["gyr", "shape"]),
        (lambda a: a.update(gyr=np.zeros(3 * N)), ValueError, ["gyr", "shape"]),
        (lambda a: a.update(acc=a["acc"][:-1]), ValueError, ["acc", f"({N}, 3)"]),
        (lambda a: a["acc"].__setitem__((5, 1), np.nan), ValueError, ["acc[5, 1]", "NaN"]),
        (lambda a: a["gyr"].__setitem__((9, 2), np.inf), ValueError, ["gyr[9, 2]", "inf"]),
        (lambda a: a["mag"].__setitem__((3, 0), np.nan), ValueError, ["mag[3, 0]"]),
        (lambda a: a["t"].__setitem__(7, a["t"][6]), ValueError, ["t[7]", "increasing"]),
        (lambda a: a["t"].__setitem__(0, -1), ValueError, ["t[0]"]),
        (lambda a: a["mag_t"].__setitem__(4, 0), ValueError, ["mag_t[4]"]),
        (lambda a: a.update(mag=a["mag"][:-2]), ValueError, ["mag", "shape"]),
        (lambda a: a.update(mag_t=None), ValueError, ["mag_t"]),
    ],
)
def test_bad_arrays(change, error, words):
    t, gyr, acc, mag, mag_t = good()
    args = dict(t=t, gyr=gyr, acc=acc, mag=mag, mag_t=mag_t)
    change(args)
    with pytest.raises(error) as e:
        estimator.run_attitude(**args)
    for w in words:
        assert w in str(e.value), (w, str(e.value))


def test_native_module_checks_dtypes_itself():
    t, gyr, acc, mag, mag_t = good()
    with pytest.raises(TypeError, match="gyr"):
        _estimator.run_attitude(t, gyr.astype(np.float32), acc)
    with pytest.raises(TypeError, match="t"):
        _estimator.run_attitude(t.astype(np.uint32), gyr, acc)
    with pytest.raises(TypeError, match="acc"):
        _estimator.run_attitude(t, gyr, [[0, 0, 9.81]] * N)


@pytest.mark.parametrize(
    "config, error, words",
    [
        ({"no_such_key": 1}, TypeError, ["no_such_key"]),
        ({"block_s": -1.0}, ValueError, ["block_s"]),
        ({"block_s": "long"}, ValueError, ["block_s"]),
        ({"precision": "f16"}, ValueError, ["f16"]),
        ({"mag_sigma": float("nan")}, ValueError, ["mag_sigma"]),
        ({"mag_reference": [1.0, 2.0]}, ValueError, ["mag_reference"]),
        ({"gyroscope_noise_density": -1.0}, ValueError, ["gyroscope_noise_density"]),
    ],
)
def test_bad_config(config, error, words):
    with pytest.raises(error) as e:
        estimator.run_attitude(*good(), **config)
    for w in words:
        assert w in str(e.value)
    with pytest.raises(error):
        estimator.AttitudeNavigator(config)


def test_default_config_round_trips():
    cfg = estimator.default_config()
    assert cfg["precision"] == "f32" and cfg["block_s"] == 0.25
    r1 = estimator.run_attitude(*good(), **cfg)
    r2 = estimator.run_attitude(*good())
    np.testing.assert_array_equal(r1.quaternion, r2.quaternion)


def test_navigator_refuses_and_stays_unchanged():
    t, gyr, acc, _, _ = good()
    nav = estimator.AttitudeNavigator()
    for i in range(N):
        nav.imu(t[i], gyr[i], acc[i])
    before = nav.estimate()
    assert before is not None
    with pytest.raises(ValueError, match="refused"):
        nav.imu(t[-1], gyr[0], acc[0])  # not after the previous sample
    with pytest.raises(ValueError, match=r"gyr\[1\]"):
        nav.imu(t[-1] + 5_000_000, [0.0, float("nan"), 0.0], acc[0])
    with pytest.raises(ValueError, match="acc"):
        nav.imu(t[-1] + 5_000_000, gyr[0], [0.0, 9.81])
    with pytest.raises(TypeError, match="mag"):
        nav.magnetometer(t[-1], "north")
    with pytest.raises(ValueError, match="t_ns"):
        nav.imu(-1, gyr[0], acc[0])
    with pytest.raises(TypeError, match="t_ns"):
        nav.imu(1.5e9, gyr[0], acc[0])
    assert nav.estimate() == before


def test_score_bad_input():
    t = np.arange(10, dtype=np.int64)
    q = np.tile([1.0, 0, 0, 0], (10, 1))
    q_bad = q.copy()
    q_bad[3, 1] = np.nan  # partly NaN: neither an estimate nor none
    with pytest.raises(ValueError, match=r"quaternion\[3, 1\]"):
        estimator.score(t, q_bad, t, q)
    with pytest.raises(ValueError, match="truth_q"):
        estimator.score(t, q, t, q[:-1])
    with pytest.raises(ValueError, match="movement"):
        estimator.score(t, q, t, q, movement=np.array([[5, 2]]))
    with pytest.raises(ValueError, match="truth_p"):
        estimator.score(t, q, t, q, position=q[:, :3])
    with pytest.raises(ValueError, match="rpe_delta_unit"):
        estimator.score(t, q, t, q, rpe_delta_unit="h")


def test_missing_dataset(tmp_path):
    with pytest.raises(ValueError, match="imu0"):
        estimator.read_dataset(tmp_path / "nothing")
    with pytest.raises(ValueError, match="scenario|unknown|no_such"):
        estimator.simulate("no_such_scenario", 1, tmp_path / "x")
    assert not (tmp_path / "x").exists()


def ins_good():
    t, gyr, acc, _, _ = good()
    gnss_t = t[::40].copy()
    g = len(gnss_t)
    return dict(
        t=t,
        gyr=gyr,
        acc=acc,
        gnss_t=gnss_t,
        gnss_p=np.zeros((g, 3)),
        gnss_sigma_p=np.ones(g),
        gnss_v=np.zeros((g, 3)),
        gnss_sigma_v=np.full(g, 0.1),
    )


def test_ins_good_input_runs():
    r = estimator.run_ins(**ins_good())
    assert r.position.shape == (N, 3) and r.sigma.shape == (N, 15)
    assert r.gnss_accepted.shape == (len(ins_good()["gnss_t"]),)


@pytest.mark.parametrize(
    "change, error, words",
    [
        (lambda a: a.update(gnss_p=a["gnss_p"][:-1]), ValueError, ["gnss_p", "shape"]),
        (lambda a: a["gnss_sigma_p"].__setitem__(2, 0.0), ValueError, ["gnss_sigma_p[2]"]),
        (lambda a: a["gnss_sigma_p"].__setitem__(1, np.nan), ValueError, ["gnss_sigma_p[1]"]),
        (lambda a: a["gnss_v"].__setitem__((3, 1), np.nan), ValueError, ["gnss_v[3, 1]"]),
        (lambda a: a["gnss_sigma_v"].__setitem__(4, np.nan), ValueError, ["gnss_sigma_v[4]"]),
        (lambda a: a["gnss_t"].__setitem__(2, a["gnss_t"][1]), ValueError, ["gnss_t[2]"]),
        (lambda a: a.update(gnss_sigma_v=None), ValueError, ["gnss_sigma_v"]),
        (lambda a: a.update(baro=np.zeros(3)), ValueError, ["baro_t"]),
        (lambda a: a.update(gnss_t=a["gnss_t"].astype(float)), TypeError, ["gnss_t"]),
        (lambda a: a.update(horizon_s=5.0), ValueError, ["horizon_s"]),
    ],
)
def test_ins_bad_input(change, error, words):
    args = ins_good()
    change(args)
    with pytest.raises(error) as e:
        estimator.run_ins(**args)
    for w in words:
        assert w in str(e.value), (w, str(e.value))


def test_ins_fix_without_velocity_is_a_nan_row():
    args = ins_good()
    args["gnss_v"][2] = np.nan
    args["gnss_sigma_v"][2] = np.nan
    r = estimator.run_ins(**args)
    assert r.gnss_accepted.all()

"""What the navigator does on synthetic motions with a known answer."""

import math

import numpy as np
import pytest

import estimator

RATE = 200
FIELD = np.array([0.0, 20.0, -45.0])  # µT, ENU: north and down


def rot_x(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def rot_z(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def static(seconds, world_from_body, gyro_bias=(0, 0, 0), seed=1):
    """A body at rest: specific force and field in the body frame, with white noise."""
    n = seconds * RATE
    rng = np.random.default_rng(seed)
    t = 1_000_000_000 + np.arange(n, dtype=np.int64) * (1_000_000_000 // RATE)
    r = np.asarray(world_from_body)
    acc = np.tile(r.T @ np.array([0, 0, 9.81]), (n, 1)) + rng.normal(0, 0.02, (n, 3))
    gyr = np.tile(np.asarray(gyro_bias, float), (n, 1)) + rng.normal(0, 0.002, (n, 3))
    mag_t = t[::4]
    mag = np.tile(r.T @ FIELD, (len(mag_t), 1)) + rng.normal(0, 0.3, (len(mag_t), 3))
    return t, gyr, acc, mag_t, mag


def euler_from_q(q):
    """(roll, pitch, yaw) of a world-from-body quaternion (w, x, y, z), ZYX."""
    w, x, y, z = q
    roll = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x))))
    yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return roll, pitch, yaw


def test_starts_after_its_window_and_finds_the_tilt():
    roll = math.radians(30)
    t, gyr, acc, _, _ = static(10, rot_x(roll))
    r = estimator.run_attitude(t, gyr, acc)
    # No estimate during the 1 s start-up window, one after it.
    assert not r.estimated[: RATE - 1].any()
    assert r.estimated[2 * RATE :].all()
    assert np.isnan(r.quaternion[0]).all()
    est_roll, est_pitch, _ = euler_from_q(r.quaternion[-1])
    assert est_roll == pytest.approx(roll, abs=math.radians(0.5))
    assert est_pitch == pytest.approx(0.0, abs=math.radians(0.5))
    assert r.tilt_valid[-1]
    # Without a magnetometer the heading is only relative to the start.
    assert not r.heading_valid[-1]
    assert estimator.REASONS[r.heading_reason[-1]] == "no_magnetometer"
    assert estimator.REASONS[r.tilt_reason[0]] == "starting"
    np.testing.assert_allclose(np.linalg.norm(r.quaternion[r.estimated], axis=1), 1, atol=1e-6)
    # Tilt is known to a fraction of a degree; the heading, unobserved, stays wide.
    assert (r.sigma[-1] > 0).all() and r.sigma[-1].min() < math.radians(1)
    assert r.sigma[-1].max() > math.radians(10)
    assert r.at_rest[-1] and r.imu_accepted.all()


def test_magnetometer_gives_the_heading():
    yaw = math.radians(70)
    t, gyr, acc, mag_t, mag = static(20, rot_z(yaw))
    r = estimator.run_attitude(t, gyr, acc, mag, mag_t, mag_reference=FIELD.tolist(), mag_sigma=0.3)
    _, _, est_yaw = euler_from_q(r.quaternion[-1])
    assert est_yaw == pytest.approx(yaw, abs=math.radians(2))
    assert r.heading_valid[-1] and r.mag_accepted.all()
    # The same data without the magnetometer: fused or not, as asked.
    off = estimator.run_attitude(t, gyr, acc, mag, mag_t, use_magnetometer=False)
    assert not off.heading_valid[-1]


def test_gyro_bias_is_learned_at_rest():
    bias = (0.01, -0.02, 0.005)  # rad/s
    t, gyr, acc, mag_t, mag = static(30, np.eye(3), gyro_bias=bias)
    r = estimator.run_attitude(t, gyr, acc, mag, mag_t, mag_reference=FIELD.tolist())
    np.testing.assert_allclose(r.gyro_bias[-1], bias, atol=0.002)
    # And the attitude does not drift with it.
    roll, pitch, yaw = euler_from_q(r.quaternion[-1])
    assert max(abs(roll), abs(pitch), abs(yaw)) < math.radians(2)


def test_sample_by_sample_equals_batched():
    t, gyr, acc, mag_t, mag = static(3, rot_x(0.2))
    cfg = {"mag_reference": FIELD.tolist()}
    batched = estimator.run_attitude(t, gyr, acc, mag, mag_t, **cfg)
    nav = estimator.AttitudeNavigator(cfg)
    assert nav.estimate() is None
    k = 0
    for i in range(len(t)):
        while k < len(mag_t) and mag_t[k] < t[i]:
            nav.magnetometer(mag_t[k], mag[k])
            k += 1
        report = nav.imu(t[i], gyr[i], acc[i])
        assert report["tilt_valid"] == batched.tilt_valid[i]
    e = nav.estimate()
    assert e is not None and e.t_ns == t[-1]
    assert e.quaternion == tuple(batched.quaternion[-1])
    assert e.sigma == tuple(batched.sigma[-1])
    assert 0 < e.sigma_tilt < math.radians(5)
    assert e.tilt_reason == "valid" and e.magnetic in {"fused", "waiting"}


def test_f64_precision_differs_slightly_from_f32():
    t, gyr, acc, _, _ = static(5, rot_x(0.3))
    a = estimator.run_attitude(t, gyr, acc)
    b = estimator.run_attitude(t, gyr, acc, precision="f64")
    assert not np.array_equal(a.quaternion[a.estimated], b.quaternion[b.estimated])
    # Without a magnetometer the heading wanders differently; a few milliradians apart.
    np.testing.assert_allclose(a.quaternion[a.estimated], b.quaternion[b.estimated], atol=1e-2)


def test_refused_samples_are_reported_not_raised():
    t, gyr, acc, _, _ = static(3, np.eye(3))
    acc[300] = 0.0  # an all-zero accelerometer: the navigator refuses it
    r = estimator.run_attitude(t, gyr, acc)
    assert not r.imu_accepted[300] and r.imu_accepted[:300].all() and r.imu_accepted[301:].all()


def test_score_broad_figures_on_a_known_error():
    # The estimate off by a fixed 2° about up (heading) and 1° about east (inclination).
    n = 1000
    t = np.arange(n, dtype=np.int64) * 5_000_000
    truth_q = np.tile([1.0, 0, 0, 0], (n, 1))
    h, i = math.radians(2), math.radians(1)
    err = np.array([math.cos(i / 2), math.sin(i / 2), 0, 0])  # about x
    yaw = np.array([math.cos(h / 2), 0, 0, math.sin(h / 2)])
    w1, x1, y1, z1 = yaw
    w2, x2, y2, z2 = err
    q = np.array(
        [
            w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
            w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
            w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
        ]
    )
    m = estimator.score(t, np.tile(q, (n, 1)), t, truth_q, movement=np.array([[t[100], t[899]]]))
    b = m["broad"]
    assert b["samples"] == 800
    assert b["heading_deg"] == pytest.approx(2.0, abs=0.01)
    assert b["inclination_deg"] == pytest.approx(1.0, abs=0.01)
    assert b["total_deg"] == pytest.approx(math.hypot(2, 1), abs=0.01)
    assert m["samples_scored"] == n


def test_score_ate_and_rpe_with_positions():
    n = 500
    t = np.arange(n, dtype=np.int64) * 10_000_000
    q = np.tile([1.0, 0, 0, 0], (n, 1))
    truth_p = np.stack([np.linspace(0, 10, n), np.zeros(n), np.zeros(n)], axis=1)
    # A constant offset is taken off by the alignment; a 0.1 m lateral wobble is not.
    wobble = 0.1 * np.sign(np.sin(np.arange(n)))
    p = truth_p + np.array([5.0, 0, 0]) + np.stack([np.zeros(n), wobble, np.zeros(n)], axis=1)
    m = estimator.score(t, q, t, q, position=p, truth_p=truth_p)
    assert m["ate"]["rmse"] == pytest.approx(0.1, rel=0.05)
    assert m["rpe"] is not None and m["rpe"]["delta"] == 1.0
    # Without positions there is no ATE.
    assert estimator.score(t, q, t, q)["ate"] is None

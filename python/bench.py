"""Wall time of run_attitude over a 10-minute 200 Hz recording (120,000 IMU samples of gyro and
accelerometer, a magnetometer sample with each), synthetic: a body turning and tilting slowly.

Run: python python/bench.py   (not a test; the target is ≤ 0.5 s)
"""

import time

import numpy as np

import estimator

RATE = 200
N = 10 * 60 * RATE
FIELD = np.array([0.0, 20.0, -45.0])  # µT, ENU


def recording(seed=1):
    rng = np.random.default_rng(seed)
    t = 1_000_000_000 + np.arange(N, dtype=np.int64) * (1_000_000_000 // RATE)
    s = (t - t[0]) * 1e-9
    # Yaw turning back and forth, small roll: rates and the body-frame gravity and field.
    yaw = 1.5 * np.sin(2 * np.pi * s / 40)
    roll = 0.2 * np.sin(2 * np.pi * s / 13)
    gyr = np.zeros((N, 3))
    gyr[:, 0] = np.gradient(roll, s)
    gyr[:, 2] = np.gradient(yaw, s)
    cr, sr, cy, sy = np.cos(roll), np.sin(roll), np.cos(yaw), np.sin(yaw)
    acc = np.stack([np.zeros(N), 9.81 * sr, 9.81 * cr], axis=1)
    # Field in the body frame: R_x(roll)^T R_z(yaw)^T FIELD.
    fx = cy * FIELD[0] + sy * FIELD[1]
    fy0 = -sy * FIELD[0] + cy * FIELD[1]
    fz0 = FIELD[2]
    mag = np.stack([fx, cr * fy0 + sr * fz0, -sr * fy0 + cr * fz0], axis=1)
    gyr += rng.normal(0, 0.003, gyr.shape)
    acc += rng.normal(0, 0.03, acc.shape)
    mag += rng.normal(0, 0.3, mag.shape)
    return t, gyr, acc, mag


def main():
    t, gyr, acc, mag = recording()
    best = float("inf")
    for _ in range(3):
        start = time.perf_counter()
        r = estimator.run_attitude(t, gyr, acc, mag, t, mag_reference=FIELD.tolist())
        best = min(best, time.perf_counter() - start)
    print(
        f"run_attitude: {N} IMU + {N} magnetometer samples (10 min at {RATE} Hz): "
        f"{best:.3f} s wall (best of 3), {best / N * 1e6:.2f} µs per IMU sample; "
        f"heading valid at the end: {bool(r.heading_valid[-1])}"
    )


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""A prototype of tilt from a bounded velocity, scored on BROAD beside VQF 6D (not run by CI).

Why: the attitude navigator fuses 0.5 s block means of the specific force as if their
linear-acceleration errors were independent. They are not: the mean linear acceleration over a
window W is (v_end - v_start)/W, so for a body whose velocity stays bounded (hand-held, worn) the
error of a long mean falls as 1/W, not 1/sqrt(W). This prototype keeps that information in a
velocity error state, the way an INS would, with the body's velocity as the "measurement":

    nominal, per IMU sample:  R <- R Exp((w - b_g) dt),   v~ <- v~ + (R f + g) dt
    error state x = (dtheta, e, db_g), world-frame attitude error (R_true = Exp(dtheta) R),
    e = v~ - v_true:          dtheta' = -R db_g,   e' = [R f]x dtheta
    every T_m seconds:        z = v~ = e + v_true,  v_true ~ N(0, sigma_v^2 I)
    then reset:               R <- Exp(dtheta^) R,  v~ <- v~ - e^,  b_g <- b_g + db_g^

The covariance is propagated once per T_m with the transition accumulated over the samples.
The gyro's scale and cross-axis error (`--gyro-scale`, 0.5 % by default, a calibrated MEMS
gyro's) adds (sigma_s |w|)^2 dt per step to the attitude variance: the error of each second's
turn taken as independent of the next. There is no accelerometer bias state and no rest logic: it isolates the accelerometer side.
sigma_v is the spread of the body's velocity (BROAD's optical truth: 0.03-1.0 m/s RMS per axis);
`--sigma-v adaptive` takes max(0.3, 2 x the running RMS of v~ over 5 s) per axis.

Usage: python3 tools/research/velocity_bound_tilt.py [--sigma-v 1.0|adaptive] [--every 0.5]
Needs NumPy and PyPI `vqf` (the comparison); reads ../shared/datasets/broad relative to the
repository and says so when it is absent. Prints BROAD's inclination RMSE per trial (movement
samples, truth interpolated to each IMU sample) for the prototype and VQF 6D, the mean, and the
means of the odd and even trials in name order.
"""
import argparse
import glob
import os
import sys

try:
    import numpy as np
    from vqf import VQF
except ImportError:
    print("needs NumPy and vqf: python3 -m pip install numpy vqf")
    sys.exit(3)


def load(path):
    return np.loadtxt(path, delimiter=",", comments="#")


def skew(v):
    return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def exp_so3(w):
    th = np.linalg.norm(w)
    if th < 1e-12:
        return np.eye(3) + skew(w)
    k = skew(w / th)
    return np.eye(3) + np.sin(th) * k + 2 * np.sin(th / 2) ** 2 * k @ k


def quat(R):
    w = np.sqrt(max(1e-12, 1 + np.trace(R))) / 2
    return np.array([w, (R[2, 1] - R[1, 2]) / (4 * w), (R[0, 2] - R[2, 0]) / (4 * w),
                     (R[1, 0] - R[0, 1]) / (4 * w)])


def qmul(a, b):
    w1, x1, y1, z1 = a.T
    w2, x2, y2, z2 = b.T
    return np.stack([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2], 1)


def run(imu, yaml, sigma_v, every, scale):
    t = imu[:, 0] * 1e-9
    w, f = imu[:, 1:4], imu[:, 4:7]
    dt = np.median(np.diff(t))
    ng, nbg, na = (yaml["gyroscope_noise_density"], yaml["gyroscope_random_walk"],
                   yaml["accelerometer_noise_density"])
    g = np.array([0.0, 0.0, -9.81])
    up = f[: int(0.5 / dt)].mean(0)
    up /= np.linalg.norm(up)
    axis = np.cross(up, [0, 0, 1])
    s = np.linalg.norm(axis)
    R = exp_so3(axis / s * np.arctan2(s, up[2])) if s > 1e-9 else np.eye(3)
    bg, v, spread = np.zeros(3), np.zeros(3), np.zeros(3)
    P = np.diag([1e-4] * 3 + [0.01] * 3 + [np.radians(0.5) ** 2] * 3)
    Phi, Q, since = np.eye(9), np.zeros((9, 9)), 0.0
    H = np.hstack([np.zeros((3, 3)), np.eye(3), np.zeros((3, 3))])
    out = np.zeros((len(t), 4))
    for k in range(len(t)):
        if k > 0:
            d = t[k] - t[k - 1]
            F = np.zeros((9, 9))
            F[0:3, 6:9] = -R
            F[3:6, 0:3] = skew(R @ f[k])
            A = np.eye(9) + F * d
            q = np.zeros((9, 9))
            # white gyro noise, and the scale error as a density: a second's turn independent of the next
            q[0:3, 0:3] = np.eye(3) * (ng ** 2 + (scale * np.linalg.norm(w[k] - bg)) ** 2) * d
            q[3:6, 3:6] = np.eye(3) * na ** 2 * d
            q[6:9, 6:9] = np.eye(3) * nbg ** 2 * d
            Phi, Q = A @ Phi, A @ Q @ A.T + q
            R = R @ exp_so3((w[k] - bg) * d)
            v = v + (R @ f[k] + g) * d
            since += d
            if since >= every:
                P = Phi @ P @ Phi.T + Q
                Phi, Q, since = np.eye(9), np.zeros((9, 9)), 0.0
                if sigma_v is None:
                    spread += (v * v - spread) * min(1.0, every / 5.0)
                    noise = np.diag(np.maximum(4 * spread, 0.3 ** 2))
                else:
                    noise = np.eye(3) * sigma_v ** 2
                S = H @ P @ H.T + noise
                K = P @ H.T @ np.linalg.inv(S)
                x = K @ v
                P = (np.eye(9) - K @ H) @ P
                P = (P + P.T) / 2
                R = exp_so3(x[0:3]) @ R
                v = v - x[3:6]
                bg = bg + x[6:9]
        out[k] = quat(R)
    return out


def inclination_rmse(trial, imu, q):
    gt = load(os.path.join(trial, "state_groundtruth_estimate0/data.csv"))
    mv = load(os.path.join(trial, "movement.csv")).reshape(-1, 2)
    t = imu[:, 0]
    i = np.searchsorted(gt[:, 0], t).clip(1, len(gt) - 1)
    q0, q1 = gt[i - 1, 4:8].copy(), gt[i, 4:8].copy()
    q1 *= np.sign(np.sum(q0 * q1, 1))[:, None]
    a = ((t - gt[i - 1, 0]) / (gt[i, 0] - gt[i - 1, 0])).clip(0, 1)[:, None]
    qt = (1 - a) * q0 + a * q1
    qt /= np.linalg.norm(qt, axis=1)[:, None]
    e = qmul(q, qt * np.array([1, -1, -1, -1]))
    inc = 2 * np.degrees(np.arctan2(np.hypot(e[:, 1], e[:, 2]), np.hypot(e[:, 0], e[:, 3])))
    inside = np.zeros(len(t), bool)
    for start, end in mv:
        inside |= (t >= start) & (t <= end)
    inside &= (gt[i, 0] - gt[i - 1, 0]) < 20e6  # not across a lost marker
    return float(np.sqrt(np.mean(inc[inside] ** 2)))


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--sigma-v", default="1.0")
    p.add_argument("--every", type=float, default=0.5)
    p.add_argument("--gyro-scale", type=float, default=0.005,
                   help="1 sigma of the gyro's scale and cross-axis error (fraction)")
    p.add_argument("--datasets", default=os.path.join(os.path.dirname(__file__),
                                                      "../../../shared/datasets/broad"))
    a = p.parse_args()
    sigma_v = None if a.sigma_v == "adaptive" else float(a.sigma_v)
    trials = sorted(glob.glob(os.path.join(a.datasets, "[0-9]*")))
    if not trials:
        print(f"no BROAD trials under {a.datasets}: nothing to score")
        return 0
    rows = []
    for trial in trials:
        imu = load(os.path.join(trial, "imu0/data.csv"))
        yaml = {}
        for line in open(os.path.join(trial, "imu0/sensor.yaml")):
            k, _, val = line.partition(":")
            try:
                yaml[k.strip()] = float(val)
            except ValueError:
                pass
        ours = inclination_rmse(trial, imu, run(imu, yaml, sigma_v, a.every, a.gyro_scale))
        dt = float(np.median(np.diff(imu[:, 0]))) * 1e-9
        vqf = VQF(dt).updateBatch(np.ascontiguousarray(imu[:, 1:4]), np.ascontiguousarray(imu[:, 4:7]))
        ref = inclination_rmse(trial, imu, vqf["quat6D"])
        rows.append((ours, ref))
        print(f"{os.path.basename(trial):44s} prototype {ours:6.3f}   VQF 6D {ref:6.3f}", flush=True)
    r = np.array(rows)
    print(f"{'mean':44s} prototype {r[:, 0].mean():6.3f}   VQF 6D {r[:, 1].mean():6.3f}")
    print(f"{'odd / even trials':44s} prototype {r[0::2, 0].mean():.3f} / {r[1::2, 0].mean():.3f}"
          f"   VQF 6D {r[0::2, 1].mean():.3f} / {r[1::2, 1].mean():.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""VQF 6D and real-time VQF 9D on BROAD trials, scored with BROAD's metric as host-sim scores it.

Needs NumPy and the PyPI `vqf` package (BROAD's references.json names vqf 2.1.2):

    pip install numpy vqf

Usage:

    python3 tools/vqf_references.py DIR --out FILE

then give FILE to the bench, which prints its VQF 6D inclination beside the attitude
navigator's without the magnetometer (`inclination_6axis_deg`):

    cargo run --release -p host-sim -- bench ../shared/datasets --references-6d FILE --out OUT

DIR is a folder of BROAD trials in the EuRoC layout of ../shared/datasets/broad, or one trial, or
a folder one level above them (as `host-sim bench` searches: DIR itself, then one and two levels
below). A trial is a folder holding imu0/data.csv and movement.csv; its name is the folder's
name, as the bench keys it.

For each trial, two real-time (causal) VQF filters (Laidig & Seel 2023) with the default
parameters, the sampling time 1 / rate_hz of imu0/sensor.yaml:

* VQF 6D: `VQF(gyrTs, accTs)` fed the gyroscope (rad/s) and the accelerometer (m/s²) only, its
  `getQuat6D()` after every sample (`updateBatch(gyr, acc)`, whose loop is the real-time
  `update` per sample; checked against a Python loop of `updateGyr` / `updateAcc` over the
  first samples of each trial);
* VQF 9D: `VQF(gyrTs, accTs, magTs)` fed the magnetometer too (mag0/data.csv, µT; BROAD's is
  stamped with the IMU's samples and goes through `updateBatch(gyr, acc, mag)`, checked the same
  way; a magnetometer of another rate goes through `updateMag` after the IMU sample it follows,
  magTs from mag0/sensor.yaml), its `getQuat9D()` (earth frame ENU: the horizontal field along
  +y, the frame of the ground truth and of BROAD's published figures).

Each is scored with BROAD's metric exactly as host-sim computes it (host-sim/src/metrics/broad.rs,
and the replay's truth lookup: TruthCursor in host-sim/src/replay/output.rs, TruthSpacing and
TRUTH_GAP_FACTOR in host-sim/src/metrics/mod.rs):

* at every IMU sample whose time lies inside one of movement.csv's intervals (inclusive), the
  estimate after that sample against the truth at that time: the ground-truth row at that time,
  else the slerp between the two rows around it. The dataset keeps every third optical sample
  and leaves out the rows where the optical markers were lost; where the two rows around a
  sample are more than 1.5 times the shortest such interval seen so far apart, rows were lost
  there and the sample is not scored (BROAD's calculateRMSE skips its NaN truth). A sample
  before the first or after the last truth row is not scored either. No alignment of the
  frames: the estimate is compared as it is;
* `e = q_est ⊗ q_true⁻¹` (earth frame), total `2·atan2(‖e_xyz‖, |e_w|)`, heading
  `2·atan2(|e_z|, |e_w|)`, inclination `2·atan2(‖e_xy‖, ‖(e_w, e_z)‖)` (BROAD's `2·acos|e_w|`,
  `2·atan|e_z/e_w|`, `2·acos√(e_w² + e_z²)` in forms exact near zero); the RMSE in degrees of
  each over the scored samples.

VQF 6D's heading is that of its own start (its earth frame turns with nothing), so only its
inclination is a figure (a heading offset of the earth frame leaves the inclination error
unchanged): the file holds `vqf_6d.inclination` and not its total or heading.

FILE has the shape of BROAD's references.json, `{"trials": {NAME: {"vqf_6d": {"inclination": x,
"samples": n}, "vqf_9d": {"total": x, "heading": x, "inclination": x, "samples": n}}}}`, with
what made it (`generator`). The tool never overwrites: an existing FILE is refused. It prints a
table with its 9D figures beside the published `vqf_9d` of the trials' references.json, so that
a reader sees whether it reproduces BROAD's scoring.

Exit status: 0 when written, 1 when a trial fails (nothing written), 2 on bad arguments or an
existing FILE, 3 when NumPy or vqf is missing (one line saying what to install).
"""

import argparse
import json
import math
import os
import re
import sys

INSTALL = "pip install numpy vqf"
MISSING = 3

try:
    import numpy as np
    from vqf import VQF
except ImportError as e:  # pragma: no cover - depends on the machine
    print(f"vqf_references.py: {e}; install with: {INSTALL}", file=sys.stderr)
    sys.exit(MISSING)

def package_version(name):
    try:
        from importlib.metadata import version

        return version(name)
    except Exception:  # noqa: BLE001 - any failure: the version is unknown
        return None


# Samples of each trial on which the batch update is checked against the per-sample one.
LOOP_CHECK_SAMPLES = 2000


class TrialError(Exception):
    """A trial that cannot be read or scored, with the file."""


def is_trial(d):
    return os.path.isfile(os.path.join(d, "imu0", "data.csv")) and os.path.isfile(
        os.path.join(d, "movement.csv")
    )


def subfolders(d):
    out = []
    for name in sorted(os.listdir(d)):
        p = os.path.join(d, name)
        if os.path.isdir(p) and not name.startswith("."):
            out.append(p)
    return out


def find_trials(d):
    """DIR itself when it is a trial, else its subfolders one and two levels deep that are."""
    if is_trial(d):
        return [d]
    found = []
    for sub in subfolders(d):
        if is_trial(sub):
            found.append(sub)
        elif not os.path.isfile(os.path.join(sub, "imu0", "data.csv")):
            found.extend(s for s in subfolders(sub) if is_trial(s))
    return found


def read_csv(path, columns):
    """(timestamps as int64 ns, values as float64 of shape (N, columns - 1))."""
    rows_t, rows_v = [], []
    with open(path) as f:
        for line_no, line in enumerate(f, start=1):
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            parts = line.split(",")
            if len(parts) < columns:
                raise TrialError(f"{path}:{line_no}: {len(parts)} columns, expected {columns}")
            try:
                rows_t.append(int(parts[0]))
                rows_v.append([float(x) for x in parts[1:columns]])
            except ValueError:
                if not rows_t:  # a header without '#'
                    continue
                raise TrialError(f"{path}:{line_no}: not a number") from None
    if not rows_t:
        raise TrialError(f"{path}: no rows")
    return np.array(rows_t, dtype=np.int64), np.array(rows_v, dtype=np.float64)


def read_rate(yaml_path):
    """`rate_hz` of a sensor.yaml."""
    with open(yaml_path) as f:
        for line in f:
            m = re.match(r"\s*rate_hz\s*:\s*([0-9.eE+-]+)", line)
            if m:
                return float(m.group(1))
    raise TrialError(f"{yaml_path}: no rate_hz")


def read_movement(path):
    """movement.csv's intervals (start, end), ns, inclusive."""
    out = []
    with open(path) as f:
        for line_no, line in enumerate(f, start=1):
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            parts = line.split(",")
            try:
                start, end = int(parts[0]), int(parts[1])
            except (ValueError, IndexError):
                if not out and line_no == 1:
                    continue
                raise TrialError(f"{path}:{line_no}: not two integers") from None
            out.append((start, end))
    return out


def quat_mult(a, b):
    """Row-wise Hamilton product of (N, 4) arrays, w x y z."""
    aw, ax, ay, az = a.T
    bw, bx, by, bz = b.T
    return np.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ],
        axis=1,
    )


def quat_conj(q):
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def slerp(a, b, s):
    """Row-wise a·exp(s·log(a⁻¹b)) (the shorter way), as host-sim's So3::interpolate."""
    d = quat_mult(quat_conj(a), b)
    d = np.where(d[:, :1] < 0.0, -d, d)  # the shorter rotation
    vn = np.linalg.norm(d[:, 1:], axis=1)
    angle = 2.0 * np.arctan2(vn, d[:, 0])  # in [0, π]
    half = 0.5 * s * angle
    with np.errstate(invalid="ignore", divide="ignore"):
        axis = np.where(vn[:, None] > 1e-300, d[:, 1:] / vn[:, None], 0.0)
    step = np.concatenate([np.cos(half)[:, None], np.sin(half)[:, None] * axis], axis=1)
    q = quat_mult(a, step)
    return q / np.linalg.norm(q, axis=1)[:, None]


# Rows of the truth farther apart than this many of the shortest row interval seen so far have
# rows lost between them: no time between them is scored (host-sim's TRUTH_GAP_FACTOR).
TRUTH_GAP_FACTOR = 1.5


def truth_at(t_truth, q_truth, t):
    """The truth at the sorted times t, as host-sim's replay looks it up (TruthCursor::at and
    TruthSpacing::between): the row at that time, else the slerp between the two rows around it,
    unless those are more than TRUTH_GAP_FACTOR times the shortest interval of the rows around
    the times looked up so far apart (rows lost between them, as where the optical markers were
    lost); nothing before the first or after the last row.

    Returns (mask of the times that have a truth, their quaternions)."""
    n = len(t_truth)
    # The first row at or after each time.
    j = np.searchsorted(t_truth, t, side="left")
    jj = np.minimum(j, n - 1)
    exact = (j < n) & (t_truth[jj] == t)
    between = (j < n) & ~exact & (j > 0)
    # The spacing is taken in only from the rows around a time between two rows, in time order.
    b_idx = jj[between]
    dt = (t_truth[b_idx] - t_truth[b_idx - 1]).astype(np.float64)
    shortest = np.minimum.accumulate(dt) if len(dt) else dt
    kept = dt <= TRUTH_GAP_FACTOR * shortest
    interpolated = np.zeros(len(t), dtype=bool)
    interpolated[np.flatnonzero(between)[kept]] = True
    has = exact | interpolated
    q = np.zeros((len(t), 4))
    q[exact] = q_truth[jj[exact]]
    if interpolated.any():
        b = jj[interpolated]
        a = b - 1
        ta, tb = t_truth[a], t_truth[b]
        s = (t[interpolated] - ta).astype(np.float64) / (tb - ta).astype(np.float64)
        q[interpolated] = slerp(q_truth[a], q_truth[b], s)
    return has, q[has]


def in_intervals(intervals, t):
    m = np.zeros(len(t), dtype=bool)
    for start, end in intervals:
        m |= (t >= start) & (t <= end)
    return m


def broad_errors(q_est, q_true):
    """Total, heading and inclination error angles (rad) of q_est ⊗ q_true⁻¹, per row."""
    e = quat_mult(q_est, quat_conj(q_true))
    w, x, y, z = np.abs(e[:, 0]), e[:, 1], e[:, 2], np.abs(e[:, 3])
    horizontal = np.hypot(x, y)
    return (
        2.0 * np.arctan2(np.hypot(horizontal, z), w),
        2.0 * np.arctan2(z, w),
        2.0 * np.arctan2(horizontal, np.hypot(w, z)),
    )


def rmse_deg(x):
    return math.degrees(math.sqrt(float(np.mean(x * x)))) if len(x) else None


def normalized(q):
    n = np.linalg.norm(q, axis=1)
    if np.any(n == 0.0):
        raise TrialError("a quaternion of zero norm")
    return q / n[:, None]


def check_batch_is_the_loop(ts, gyr, acc, mag, batch):
    """The batch update equals the real-time per-sample update on the first samples."""
    n = min(LOOP_CHECK_SAMPLES, len(gyr))
    f = VQF(ts, ts, ts) if mag is not None else VQF(ts, ts)
    for i in range(n):
        f.updateGyr(gyr[i])
        f.updateAcc(acc[i])
        if mag is not None:
            f.updateMag(mag[i])
        got = f.getQuat9D() if mag is not None else f.getQuat6D()
        want = batch[i]
        if np.max(np.abs(got - want)) > 1e-9:
            raise TrialError(f"updateBatch differs from the per-sample update at sample {i}")


def score(t_imu, q_est, t_truth, q_truth, movement):
    """BROAD's figures of an estimate after every IMU sample (the truth looked up at every
    sample, as the replay does, then the samples inside movement.csv kept)."""
    has, q_true = truth_at(t_truth, q_truth, t_imu)
    moving = in_intervals(movement, t_imu[has])
    total, heading, incl = broad_errors(q_est[has][moving], q_true[moving])
    return {
        "total": rmse_deg(total),
        "heading": rmse_deg(heading),
        "inclination": rmse_deg(incl),
        "samples": int(np.count_nonzero(moving)),
    }


def run_trial(d):
    imu_path = os.path.join(d, "imu0", "data.csv")
    t_imu, imu = read_csv(imu_path, 7)
    if np.any(np.diff(t_imu) <= 0):
        raise TrialError(f"{imu_path}: timestamps not increasing")
    ts = 1.0 / read_rate(os.path.join(d, "imu0", "sensor.yaml"))
    gyr = np.ascontiguousarray(imu[:, 0:3])  # rad/s
    acc = np.ascontiguousarray(imu[:, 3:6])  # m/s²
    movement = read_movement(os.path.join(d, "movement.csv"))
    gt_path = os.path.join(d, "state_groundtruth_estimate0", "data.csv")
    if not os.path.isfile(gt_path):
        raise TrialError(f"{gt_path}: missing (nothing to score against)")
    t_truth, gt = read_csv(gt_path, 8)
    if np.any(np.diff(t_truth) <= 0):
        raise TrialError(f"{gt_path}: timestamps not increasing")
    q_truth = normalized(gt[:, 3:7])  # q_RS_w, x, y, z: world_from_body

    out = {}
    six = VQF(ts, ts).updateBatch(gyr, acc)["quat6D"]
    check_batch_is_the_loop(ts, gyr, acc, None, six)
    s6 = score(t_imu, six, t_truth, q_truth, movement)
    out["vqf_6d"] = {"inclination": s6["inclination"], "samples": s6["samples"]}

    mag_path = os.path.join(d, "mag0", "data.csv")
    if os.path.isfile(mag_path):
        t_mag, mag = read_csv(mag_path, 4)
        mag = np.ascontiguousarray(mag)  # µT (VQF takes any unit)
        if np.array_equal(t_mag, t_imu):  # BROAD: one magnetometer sample with each IMU sample
            nine = VQF(ts, ts, ts).updateBatch(gyr, acc, mag)["quat9D"]
            check_batch_is_the_loop(ts, gyr, acc, mag, nine)
        else:
            mag_ts = 1.0 / read_rate(os.path.join(d, "mag0", "sensor.yaml"))
            nine = nine_at_own_rate(ts, mag_ts, gyr, acc, t_imu, t_mag, mag)
        out["vqf_9d"] = score(t_imu, nine, t_truth, q_truth, movement)
    return out


def nine_at_own_rate(ts, mag_ts, gyr, acc, t_imu, t_mag, mag):
    """Real-time VQF 9D with a magnetometer of its own rate: after IMU sample i, each
    magnetometer sample stamped after sample i - 1 and up to sample i (the batch's order when
    they share the stamps); getQuat9D after each IMU sample."""
    f = VQF(ts, ts, mag_ts)
    out = np.zeros((len(t_imu), 4))
    k = int(np.searchsorted(t_mag, t_imu[0], side="left"))  # earlier ones have no IMU before
    for i in range(len(t_imu)):
        f.updateGyr(gyr[i])
        f.updateAcc(acc[i])
        while k < len(t_mag) and t_mag[k] <= t_imu[i]:
            f.updateMag(mag[k])
            k += 1
        out[i] = f.getQuat9D()
    return out


def published(d, name):
    """The trial's vqf_9d in the references.json of its parent folder, if any."""
    path = os.path.join(os.path.dirname(os.path.normpath(d)), "references.json")
    try:
        with open(path) as f:
            refs = json.load(f)
    except (OSError, ValueError):
        return None
    return ((refs.get("trials") or {}).get(name) or {}).get("vqf_9d")


def fmt(x, decimals=3):
    return "–" if x is None else f"{x:.{decimals}f}"


def main():
    p = argparse.ArgumentParser(
        description="VQF 6D and real-time VQF 9D on BROAD trials, scored with BROAD's metric "
        "as host-sim scores it; writes the --references-6d file of `host-sim bench`.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="Example:\n  python3 tools/vqf_references.py ../shared/datasets/broad --out out/vqf_6d.json\n"
        "  cargo run --release -p host-sim -- bench ../shared/datasets --references-6d out/vqf_6d.json --out out/bench",
    )
    p.add_argument("dir", help="a folder of BROAD trials (or one trial, or the folder above them)")
    p.add_argument("--out", required=True, help="the JSON file to write (never overwritten)")
    args = p.parse_args()

    if os.path.lexists(args.out):
        print(f"{args.out}: exists; name a new file (nothing was written)", file=sys.stderr)
        return 2
    if not os.path.isdir(args.dir):
        print(f"{args.dir}: not a folder", file=sys.stderr)
        return 2
    trials = find_trials(args.dir)
    if not trials:
        print(
            f"{args.dir}: no BROAD trial (a folder holding imu0/data.csv and movement.csv) in it "
            "or one or two levels below",
            file=sys.stderr,
        )
        return 2
    names = [os.path.basename(os.path.normpath(t)) for t in trials]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        print(f"trials of the same name in different folders: {', '.join(dup)}", file=sys.stderr)
        return 2

    results, failures = {}, []
    for d, name in zip(trials, names):
        print(f"[{len(results) + len(failures) + 1}/{len(trials)}] {d}", file=sys.stderr)
        try:
            results[name] = run_trial(d)
        except (TrialError, OSError) as e:
            failures.append(f"{name}: {e}")
    if failures:
        for f in failures:
            print(f"failed: {f}", file=sys.stderr)
        print("nothing written", file=sys.stderr)
        return 1

    # The table: the 6D inclination, then this tool's 9D beside the published one.
    keys = ("total", "heading", "inclination")
    w = max(len(n) for n in names + ["trial"])

    def cells(values, signed=False):
        if signed:
            return " ".join(f"{('–' if x is None else f'{x:+.3f}'):>8}" for x in values)
        return " ".join(f"{fmt(x):>8}" for x in values)

    def minus(a, b):
        return [None if x is None or y is None else x - y for x, y in zip(a, b)]

    def mean(v):
        return sum(v) / len(v) if v and all(x is not None for x in v) else None

    three = f"{'total':>8} {'heading':>8} {'inclin.':>8}"
    print(f"BROAD RMSE [deg] inside movement.csv, real-time VQF, default parameters (vqf {package_version('vqf')})")
    print(f"{'':<{w}}  {'VQF 6D':>8}  {'VQF 9D, this tool':>26}  {'VQF 9D, references.json':>26}  {'difference':>26}")
    print(f"{'trial':<{w}}  {'inclin.':>8}  {three}  {three}  {three}")
    six_col, mine_rows, pub_rows = [], [], []
    for d, name in zip(trials, names):
        r = results[name]
        nine = r.get("vqf_9d") or {}
        pub = published(d, name) or {}
        mine = [nine.get(k) for k in keys]
        theirs = [pub.get(k) for k in keys]
        six_col.append(r["vqf_6d"]["inclination"])
        mine_rows.append(mine)
        pub_rows.append(theirs)
        print(
            f"{name:<{w}}  {fmt(six_col[-1]):>8}  {cells(mine)}  {cells(theirs)}  {cells(minus(mine, theirs), True)}"
        )
    mine_mean = [mean([row[i] for row in mine_rows]) for i in range(3)]
    pub_mean = [mean([row[i] for row in pub_rows]) for i in range(3)]
    print(
        f"{'mean':<{w}}  {fmt(mean(six_col)):>8}  {cells(mine_mean)}  {cells(pub_mean)}  "
        f"{cells(minus(mine_mean, pub_mean), True)}"
    )

    doc = {
        "metric": "BROAD (Laidig et al. 2021, broad_utils.calculateRMSE) as host-sim computes it "
        "(host-sim/src/metrics/broad.rs): RMSE in degrees over the IMU samples inside movement.csv "
        "(inclusive) of the total rotation angle of q_est * q_true^-1 (earth frame) and its heading "
        "and inclination parts; the estimate after each IMU sample, the truth at its time "
        "(slerp between the ground-truth rows around it; not scored where those are more than 1.5 "
        "times the shortest row interval apart: rows lost); no alignment",
        "references": {
            "vqf_6d": "VQF 6D (Laidig & Seel 2023), PyPI vqf, real-time filter, default parameters, "
            "gyroscope and accelerometer only (getQuat6D); inclination only: its heading is its own start's",
            "vqf_9d": "VQF 9D, PyPI vqf, real-time filter, default parameters, with the magnetometer (getQuat9D)",
        },
        "generator": {
            "tool": "tools/vqf_references.py",
            "command_line": sys.argv,
            "vqf_version": package_version("vqf"),
            "numpy_version": np.__version__,
            "dir": args.dir,
        },
        "trials": results,
    }
    parent = os.path.dirname(os.path.abspath(args.out))
    os.makedirs(parent, exist_ok=True)
    try:
        with open(args.out, "x") as f:  # never overwrites
            json.dump(doc, f, indent=1)
            f.write("\n")
    except FileExistsError:
        print(f"{args.out}: exists; name a new file (nothing was written)", file=sys.stderr)
        return 2
    print(f"written {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Cuts the firmware demo's embedded stream out of host-sim datasets and prints src/stream.rs.

  make_stream.py INS_DATASET AHRS_DATASET CAMERA_DATASET > src/stream.rs

Each argument is a folder in the EuRoC layout written by `host-sim simulate` (the layout is in
the rustdoc of `host_sim::dataset`); `tools/make_stream.sh` makes the three and calls this
script. What it takes:

* INS (15 states): IMU, magnetometer and GNSS samples of WINDOW_S seconds from START_S, with the
  ground truth at both ends and the sensors' parameters (IMU noise densities, the magnetometer's
  reference field and sigma, the GNSS lever arm).
* Attitude only (the attitude navigator): IMU and magnetometer of AHRS_WINDOW_S seconds from
  AHRS_START_S of its own dataset, with the IMU timestamps (ns) and the ground truth at the end.
  The window starts 2 s before the end of host-sim's 5 s at rest (1–6 s) and ends in the
  hand-held motion: the navigator's 1 s start-up, two 0.5 s blocks at rest with the zero-rate
  update (which needs 1.5 s still), then 6 s of motion.
* PnP: the first camera frame at or after START_S, PNP_POINTS of its observations spread over
  the frame (every k-th in file order), their landmarks, the camera's intrinsics, pixel sigma and
  `T_BS`, and the body's true pose at that frame.

Every number is written as an `f32` literal that reads back as the same `f32` (the value rounded
to `f32` once, printed with the fewest digits that round-trip). Measurements carry the index of
the IMU sample with the same timestamp: the demo applies them after integrating up to it.
"""
import csv
import math
import os
import re
import struct
import sys
import textwrap

START_S = 10.0
WINDOW_S = 2.0
AHRS_START_S = 4.0
AHRS_WINDOW_S = 8.0
PNP_POINTS = 20


def f32(x):
    """The f32 nearest to x, as a Rust literal that parses back to it."""
    v = struct.unpack("<f", struct.pack("<f", float(x)))[0]
    if v == 0.0:
        return "-0.0" if math.copysign(1.0, v) < 0 else "0.0"
    for digits in range(6, 10):
        s = "%.*g" % (digits, v)
        if struct.unpack("<f", struct.pack("<f", float(s)))[0] == v:
            break
    if "e" in s:
        mant, exp = s.split("e")
        if "." not in mant:
            mant += ".0"
        s = "%se%d" % (mant, int(exp))
    elif "." not in s:
        s += ".0"
    return s


def arr(values):
    return "[" + ", ".join(f32(v) for v in values) + "]"


def rows(path):
    """Data rows of a CSV file (header skipped), as lists of strings."""
    with open(path, newline="") as f:
        r = csv.reader(f)
        next(r)
        return [row for row in r if row]


def yaml_value(path, key):
    """A scalar or a flow list `[a, b, ...]` of a flat YAML key (host-sim's sensor.yaml)."""
    text = open(path).read()
    m = re.search(r"^\s*%s:\s*(.+)$" % re.escape(key), text, re.M)
    if not m:
        sys.exit("make_stream: %s has no %s" % (path, key))
    v = m.group(1).strip()
    if v.startswith("["):
        return [float(x) for x in v.strip("[]").split(",")]
    return float(v)


def ns(seconds):
    return int(round(seconds * 1e9))


def window(ds, start_s=START_S, window_s=WINDOW_S):
    """IMU rows with timestamps in [start_s, start_s + window_s] (inclusive), and both ends (ns)."""
    imu = rows(os.path.join(ds, "imu0", "data.csv"))
    t0 = ns(start_s)  # timestamps as written: host-sim's datasets start at 1 s
    t1 = t0 + ns(window_s)
    sel = [r for r in imu if t0 <= int(r[0]) <= t1]
    if not sel or int(sel[0][0]) != t0 or int(sel[-1][0]) != t1:
        sys.exit("make_stream: %s has no IMU samples at both ends of the window" % ds)
    return sel, t0, t1


def samples(folder, what, imu, t0, t1, columns):
    """Rows of `folder/data.csv` with timestamps in (t0, t1], each as (the index of the IMU
    sample with the same timestamp, its first `columns` values): the demo applies a measurement
    after integrating up to that sample."""
    index = {int(r[0]): i for i, r in enumerate(imu)}
    out = []
    for r in rows(os.path.join(folder, "data.csv")):
        t = int(r[0])
        if t0 < t <= t1:
            if t not in index:
                sys.exit("make_stream: a %s in %s falls between IMU samples" % (what, folder))
            out.append((index[t], [float(x) for x in r[1 : 1 + columns]]))
    return out


def truth_at(ds, t):
    for r in rows(os.path.join(ds, "state_groundtruth_estimate0", "data.csv")):
        if int(r[0]) == t:
            v = [float(x) for x in r[1:]]
            # p(3) q wxyz(4) v(3) bg(3) ba(3)
            return {"p": v[0:3], "q": v[3:7], "v": v[7:10], "bg": v[10:13], "ba": v[13:16]}
    sys.exit("make_stream: %s has no ground truth at %d ns" % (ds, t))


def truth_rs(name, tr):
    return (
        "pub const %s: Truth = Truth {\n"
        "    attitude_wxyz: %s,\n    velocity: %s,\n    position: %s,\n"
        "    gyro_bias: %s,\n    accel_bias: %s,\n};\n"
        % (name, arr(tr["q"]), arr(tr["v"]), arr(tr["p"]), arr(tr["bg"]), arr(tr["ba"]))
    )


def imu_block(ds, imu, t0, t1):
    y = os.path.join(ds, "imu0", "sensor.yaml")
    rate = yaml_value(y, "rate_hz")
    noise = [
        yaml_value(y, k)
        for k in (
            "gyroscope_noise_density",
            "gyroscope_random_walk",
            "accelerometer_noise_density",
            "accelerometer_random_walk",
        )
    ]
    out = []
    out.append("/// Time between IMU samples, s (%g Hz).\npub const DT: f32 = %s;\n" % (rate, f32(1.0 / rate)))
    out.append(
        "/// IMU noise (`imu0/sensor.yaml`, Kalibr units): gyroscope noise density and random walk,\n"
        "/// accelerometer noise density and random walk.\npub const IMU_NOISE: [f32; 4] = %s;\n"
        % arr(noise)
    )
    out.append(
        "/// IMU samples at `t0 + k·DT` (k = 0..=%d): gyroscope (rad/s) then accelerometer (m/s²),\n"
        "/// body frame, instantaneous values.\npub static IMU: [[f32; 6]; %d] = [\n" % (len(imu) - 1, len(imu))
    )
    for r in imu:
        out.append("    %s,\n" % arr(float(x) for x in r[1:7]))
    out.append("];\n")
    m = os.path.join(ds, "mag0")
    mags = samples(m, "magnetometer sample", imu, t0, t1, 3)
    ref = yaml_value(os.path.join(m, "sensor.yaml"), "reference_field")
    sigma = yaml_value(os.path.join(m, "sensor.yaml"), "sigma")
    out.append(
        "/// Magnetometer reference field (world, µT) and white noise per axis (µT).\n"
        "pub const MAG_REFERENCE: [f32; 3] = %s;\npub const MAG_SIGMA: f32 = %s;\n" % (arr(ref), f32(sigma))
    )
    out.append(
        "/// Magnetometer samples (body, µT), each with the index of the IMU sample of the same time.\n"
        "pub static MAG: [(usize, [f32; 3]); %d] = [\n" % len(mags)
    )
    for i, v in mags:
        out.append("    (%d, %s),\n" % (i, arr(v)))
    out.append("];\n")
    return out


def module(doc, name, uses, body):
    """`pub mod name { use super::{uses}; body }` behind `doc`, its body indented, unformatted."""
    text = " ".join(line[4:] for line in doc.splitlines())
    doc = "".join("/// %s\n" % line for line in textwrap.wrap(text, 90, break_on_hyphens=False))
    out = [doc, "#[rustfmt::skip]\npub mod %s {\n    use super::%s;\n" % (name, uses)]
    out += ["    " + line if line.strip() else line for line in "".join(body).splitlines(True)]
    out.append("}\n")
    return out


def ends(ds, t0, t1):
    """The ground truth at both ends of the window."""
    return [
        "/// Ground truth at the first and the last IMU sample.\n",
        truth_rs("TRUTH_START", truth_at(ds, t0)),
        truth_rs("TRUTH_END", truth_at(ds, t1)),
    ]


def end(ds, t1):
    """The ground truth at the end of the window (the navigator starts on its own)."""
    return ["/// Ground truth at the last IMU sample.\n", truth_rs("TRUTH_END", truth_at(ds, t1))]


def origin(ds, what):
    return "/// %s: `host-sim simulate --scenario %s --seed 1`, %s.\n" % (
        what, os.path.basename(os.path.normpath(ds)), "%s")


def ins_rs(ds):
    imu, t0, t1 = window(ds)
    body = imu_block(ds, imu, t0, t1)
    g = os.path.join(ds, "gnss0")
    lever = yaml_value(os.path.join(g, "sensor.yaml"), "lever_arm")
    fixes = samples(g, "GNSS fix", imu, t0, t1, 8)
    body.append("/// GNSS antenna lever arm (body, m).\npub const GNSS_LEVER_ARM: [f32; 3] = %s;\n" % arr(lever))
    body.append(
        "/// GNSS fixes, each with the index of the IMU sample of the same time.\n"
        "pub const GNSS: [GnssFix; %d] = [\n" % len(fixes)
    )
    for i, v in fixes:
        body.append(
            "    GnssFix { imu_index: %d, position: %s, velocity: %s, sigma_p: %s, sigma_v: %s },\n"
            % (i, arr(v[0:3]), arr(v[3:6]), f32(v[6]), f32(v[7]))
        )
    body.append("];\n")
    body += ends(ds, t0, t1)
    doc = origin(ds, "The 15-state filter's stream") % ("%g–%g s" % (t0 * 1e-9, t1 * 1e-9))
    return module(doc, "ins", "{GnssFix, Truth}", body)


def timestamps(imu):
    """The first IMU timestamp and the interval (ns), after checking that every sample is at
    `T0_NS + k·DT_NS` exactly."""
    t = [int(r[0]) for r in imu]
    dt = t[1] - t[0]
    if any(b - a != dt for a, b in zip(t, t[1:])):
        sys.exit("make_stream: the IMU timestamps of the attitude window are not evenly spaced")
    return [
        "/// IMU sample k is at `T0_NS + k·DT_NS` (ns, the dataset's clock); a magnetometer sample\n"
        "/// has the time of its IMU sample.\n",
        "pub const T0_NS: u64 = %d;\npub const DT_NS: u64 = %d;\n" % (t[0], dt),
    ]


def ahrs_rs(ds):
    imu, t0, t1 = window(ds, AHRS_START_S, AHRS_WINDOW_S)
    body = imu_block(ds, imu, t0, t1) + timestamps(imu) + end(ds, t1)
    doc = origin(ds, "The attitude navigator's stream") % ("%g–%g s" % (t0 * 1e-9, t1 * 1e-9))
    return module(doc, "ahrs", "Truth", body)


def pnp_rs(ds):
    c = os.path.join(ds, "cam0")
    y = os.path.join(c, "sensor.yaml")
    intr = yaml_value(y, "intrinsics")
    sigma = yaml_value(y, "sigma_px")
    tbs = yaml_value(y, "data")
    if len(tbs) != 16:
        sys.exit("make_stream: T_BS of %s is not 4x4" % y)
    obs = rows(os.path.join(c, "observations.csv"))
    t = min(int(r[0]) for r in obs if int(r[0]) >= ns(START_S))
    frame = [r for r in obs if int(r[0]) == t]
    if len(frame) < PNP_POINTS:
        sys.exit("make_stream: the frame at %d ns of %s has %d < %d observations" % (t, ds, len(frame), PNP_POINTS))
    step = len(frame) // PNP_POINTS
    pick = frame[::step][:PNP_POINTS]
    lm = {int(r[0]): [float(x) for x in r[1:4]] for r in rows(os.path.join(c, "landmarks.csv"))}
    tr = truth_at(ds, t)
    body = [
        "/// Pinhole intrinsics `[fx, fy, cx, cy]` (px) and pixel noise (px).\n",
        "pub const INTRINSICS: [f32; 4] = %s;\npub const SIGMA_PX: f32 = %s;\n" % (arr(intr), f32(sigma)),
        "/// `T_BS`, body from camera: rotation (row-major) and translation (m).\n",
        "pub const BODY_FROM_CAMERA_R: [f32; 9] = %s;\n" % arr(tbs[0:3] + tbs[4:7] + tbs[8:11]),
        "pub const BODY_FROM_CAMERA_T: [f32; 3] = %s;\n" % arr([tbs[3], tbs[7], tbs[11]]),
        "/// Landmarks (world, m) and their observed pixels (px); landmark ids\n/// %s.\n"
        % ", ".join(r[1] for r in pick),
        "pub const LANDMARKS: [[f32; 3]; %d] = [\n" % PNP_POINTS,
    ]
    for r in pick:
        body.append("    %s,\n" % arr(lm[int(r[1])]))
    body.append("];\npub const PIXELS: [[f32; 2]; %d] = [\n" % PNP_POINTS)
    for r in pick:
        body.append("    %s,\n" % arr([float(r[2]), float(r[3])]))
    body.append("];\n/// The body's true state at the frame.\n")
    body.append(truth_rs("TRUTH", tr))
    doc = origin(ds, "The PnP problem") % ("the frame at %g s" % (t * 1e-9))
    return module(doc, "pnp", "Truth", body)


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    ins, ahrs, cam = sys.argv[1:4]
    head = [
        "// The demo's embedded stream, cut out of host-sim datasets. GENERATED by\n",
        "// `bash firmware/tools/make_stream.sh` (host-sim simulate, then tools/make_stream.py):\n",
        "// do not edit by hand. Every number is the dataset's value rounded to f32.\n",
        "// Data, not code: a true velocity may happen to be -π m/s.\n",
        "#![allow(clippy::approx_constant)]\n\n",
        "/// A true state from `state_groundtruth_estimate0/data.csv`: attitude `q_RS` (world from\n",
        "/// body, `[w, x, y, z]`), velocity and position (world), gyroscope and accelerometer biases.\n",
        "#[derive(Clone, Copy, Debug)]\n",
        "pub struct Truth {\n",
        "    pub attitude_wxyz: [f32; 4],\n",
        "    pub velocity: [f32; 3],\n",
        "    pub position: [f32; 3],\n",
        "    pub gyro_bias: [f32; 3],\n",
        "    pub accel_bias: [f32; 3],\n",
        "}\n\n",
        "/// A GNSS fix (`gnss0/data.csv`): position (world, m), velocity (world, m/s), their 1-σ.\n",
        "#[derive(Clone, Copy, Debug)]\n",
        "pub struct GnssFix {\n",
        "    /// The IMU sample with the same timestamp: the fix is applied after it.\n",
        "    pub imu_index: usize,\n",
        "    pub position: [f32; 3],\n",
        "    pub velocity: [f32; 3],\n",
        "    pub sigma_p: f32,\n",
        "    pub sigma_v: f32,\n",
        "}\n\n",
    ]
    sys.stdout.write("".join(head + ins_rs(ins) + ["\n"] + ahrs_rs(ahrs) + ["\n"] + pnp_rs(cam)))


if __name__ == "__main__":
    main()

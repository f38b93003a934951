#!/usr/bin/env python3
"""Cross-checks host-sim's trajectory metrics against evo (github.com/MichaelGrupp/evo).

Usage: python tools/evo_check.py [OUT] [--tol 1e-6]

OUT is a host-sim output folder (default: out) holding metrics.json, estimate.tum and
groundtruth.tum. Runs, as a user would:

  evo_ape tum OUT/groundtruth.tum OUT/estimate.tum [-a | --align_origin]
  evo_rpe tum OUT/groundtruth.tum OUT/estimate.tum --delta D --delta_unit {f,m}

with --save_results, and compares every statistic evo saves (rmse, mean, median, std, min, max,
sse) and the number of pairs with metrics.json's ate_by_alignment (none, se3, origin) and rpe,
within a relative tolerance (default 1e-6; errors below 1e-9 m compare absolutely). evo has no
delta in seconds: a delta of D seconds is passed as D x rate frames, which is the same pairing
when the estimate is sampled uniformly (checked). Exits 1 on any disagreement, 2 on bad input,
3 when NumPy or evo is missing (one line saying what to install: `pip install evo`, which brings
NumPy). The evo commands are taken from the folder of this Python interpreter, else from PATH.
"""

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import zipfile

INSTALL = "pip install evo (it brings NumPy), then run this script with that Python"
MISSING = 3

try:
    import numpy as np
except ImportError:
    np = None

STATS = ("rmse", "mean", "median", "std", "min", "max", "sse")
APE_FLAGS = {"none": [], "se3": ["-a"], "origin": ["--align_origin"]}


def evo_command(name):
    here = os.path.join(os.path.dirname(sys.executable), name)
    if os.path.isfile(here):
        return here
    found = shutil.which(name)
    if found is None:
        print(
            f"evo_check: evo's {name} is not beside {sys.executable} nor on PATH: {INSTALL}",
            file=sys.stderr,
        )
        sys.exit(MISSING)
    return found


def run_evo(args, workdir, label):
    """Runs one evo command with --save_results; returns (stats, number of errors)."""
    zpath = os.path.join(workdir, label + ".zip")
    cmd = args + ["--save_results", zpath, "--no_warnings"]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"evo_check: {' '.join(cmd)} failed:\n{done.stdout}{done.stderr}")
    with zipfile.ZipFile(zpath) as z:
        stats = json.loads(z.read("stats.json"))
        with z.open("error_array.npy") as f:
            errors = np.load(f)
    return stats, int(errors.size)


def tum_times(path):
    times = []
    with open(path) as f:
        for line in f:
            line = line.strip()
            if line and not line.startswith("#"):
                times.append(float(line.split()[0]))
    return np.array(times)


def rpe_delta_args(metrics, est_path):
    rpe = metrics["rpe"]
    delta, unit = rpe["delta"], rpe["delta_unit"]
    if unit == "m":
        return ["--delta", repr(delta), "--delta_unit", "m"], f"{delta} m"
    if unit != "s":
        sys.exit(f"evo_check: unknown RPE delta unit {unit!r}")
    dt = np.diff(tum_times(est_path))
    if dt.size == 0:
        sys.exit("evo_check: estimate.tum has fewer than two poses")
    step = float(np.median(dt))
    if np.max(np.abs(dt - step)) > 1e-6:
        sys.exit(
            "evo_check: estimate.tum is not uniformly sampled: a delta in seconds has no "
            "equivalent in frames for evo"
        )
    frames = round(delta / step)
    if frames < 1 or abs(frames * step - delta) > 1e-6:
        sys.exit(f"evo_check: a delta of {delta} s is not a whole number of {step} s steps")
    return ["--delta", str(frames), "--delta_unit", "f"], f"{delta} s = {frames} frames"


def agree(ours, theirs, tol):
    if ours is None or theirs is None:
        return False
    return abs(ours - theirs) <= max(tol * abs(theirs), 1e-9)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", nargs="?", default="out")
    parser.add_argument("--tol", type=float, default=1e-6)
    a = parser.parse_args()
    if np is None:
        print(f"evo_check: NumPy is not installed for {sys.executable}: {INSTALL}", file=sys.stderr)
        return MISSING
    est = os.path.join(a.out, "estimate.tum")
    gt = os.path.join(a.out, "groundtruth.tum")
    try:
        with open(os.path.join(a.out, "metrics.json")) as f:
            metrics = json.load(f)
    except (OSError, ValueError) as e:
        print(f"evo_check: {e}", file=sys.stderr)
        return 2
    if not metrics.get("ate_by_alignment") or not metrics.get("rpe"):
        print("evo_check: metrics.json has no ATE/RPE (no position estimated?)", file=sys.stderr)
        return 2

    ape = evo_command("evo_ape")
    rpe = evo_command("evo_rpe")
    rows = []  # (what, statistic, ours, evo)
    with tempfile.TemporaryDirectory() as work:
        for name, flags in APE_FLAGS.items():
            ours = metrics["ate_by_alignment"].get(name)
            if ours is None:
                print(f"evo_check: metrics.json has no ATE for alignment {name}", file=sys.stderr)
                return 2
            theirs, n = run_evo([ape, "tum", gt, est] + flags, work, "ape_" + name)
            label = f"ATE {name} ({' '.join(['evo_ape'] + flags)})"
            rows.append((label, "pairs", ours["pairs"], n))
            rows += [(label, k, ours[k], theirs[k]) for k in STATS]
        delta_args, delta_text = rpe_delta_args(metrics, est)
        theirs, n = run_evo([rpe, "tum", gt, est] + delta_args, work, "rpe")
        label = f"RPE over {delta_text}"
        rows.append((label, "pairs", metrics["rpe"]["pairs"], n))
        rows += [(label, k, metrics["rpe"][k], theirs[k]) for k in STATS]

    bad = 0
    for what, k, ours, theirs in rows:
        ok = ours == theirs if k == "pairs" else agree(ours, theirs, a.tol)
        bad += not ok
        rel = (
            abs(ours - theirs) / abs(theirs)
            if k != "pairs" and ours is not None and theirs not in (None, 0)
            else 0.0
        )
        print(f"{'ok ' if ok else 'BAD'} {what:<40} {k:<7} host-sim {ours!s:<22} evo {theirs!s:<22} rel {rel:.1e}")
    if bad:
        print(f"evo_check: {bad} figure(s) disagree with evo beyond {a.tol:g} relative")
        return 1
    print(f"evo_check: {len(rows)} figures agree with evo within {a.tol:g} relative")
    return 0


if __name__ == "__main__":
    sys.exit(main())

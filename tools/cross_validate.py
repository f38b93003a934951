#!/usr/bin/env python3
"""Cross-validation of the attitude navigator's data-chosen defaults on BROAD's trials.

A default chosen on the trials it is scored on says little about trials it has not seen. For each
parameter below, one at a time with every other at its default, this replays the BROAD trials
with the parameter on a grid around its default (`host-sim bench --config`), chooses the value
with the lowest mean total RMSE on one half of the trials (the 1st, 3rd, 5th … in name order)
and scores it on the other half, and the reverse:

    python3 tools/cross_validate.py ../shared/datasets [--params heading_noise_deg,...] [--out OUT]

It prints, per parameter, each grid value's mean total RMSE on each half, the value each half
chooses and what it scores on the other half; then the cross-validated mean (each half scored
with the choice of the other, weighted by its number of trials) beside the full-set mean of the
defaults. A default that each half chooses for itself carries over; one that the halves do not
agree on is fitted to the trials it was chosen on, and the cross-validated mean is the honest
figure for it. Writes OUT/cross_validation.json (every figure printed). Needs the release
host-sim, which it builds first (`cargo build --release -p host-sim`); each grid value is one
bench run over all trials (about 10 s on one core for the 14 shared ones).
"""

import argparse
import json
import math
import os
import shutil
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# The parameters whose defaults the tuning table in estimator-core's nav module says are chosen
# by data (replay.toml keys, and their defaults there).
PARAMETERS = {
    "heading_noise_deg": 8.0,
    "gyro_scale_sigma": 0.005,
    "velocity_sigma": 0.3,
    "motion_memory_s": 5.0,
    "accelerometer_bias_sigma": 0.1,
}

# The grid: the default times these factors (a factor of two either side in steps of √2, and
# four either side).
FACTORS = [0.25, 0.5, 1 / math.sqrt(2), 1.0, math.sqrt(2), 2.0, 4.0]


def bench(datasets, config_lines, out):
    """Runs host-sim bench with the given replay.toml lines; returns {trial: total RMSE}."""
    os.makedirs(out, exist_ok=True)
    config = os.path.join(out, "config.toml")
    with open(config, "w", encoding="utf-8") as f:
        f.write("\n".join(config_lines) + "\n")
    run_dir = os.path.join(out, "bench")
    exe = os.path.join(ROOT, "target", "release", "host-sim")
    # --force replaces only what an earlier host-sim run wrote there.
    run = subprocess.run(
        [exe, "bench", datasets, "--out", run_dir, "--config", config, "--force"],
        check=False,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    result = os.path.join(run_dir, "bench.json")
    if run.returncode != 0 or not os.path.exists(result):
        sys.exit(f"host-sim bench failed with {config_lines}: {run.stderr[-2000:]}")
    with open(result, encoding="utf-8") as f:
        tables = json.load(f)["tables"]
    # Only the scores are kept: the run's estimates (about 1 GB per run) are this tool's own
    # output, made by the call above, and go.
    shutil.copy(result, os.path.join(out, "bench.json"))
    shutil.rmtree(run_dir)
    rows = [r for t in tables if t["kind"] == "broad" for r in t["rows"]]
    return {r["dataset"]: r["ours"]["total_deg"] for r in rows if r.get("ours")}


def mean(values):
    return sum(values) / len(values)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("datasets", help="the folder host-sim bench searches (../shared/datasets)")
    parser.add_argument("--params", default=",".join(PARAMETERS), help="comma-separated keys")
    parser.add_argument("--out", default=os.path.join(ROOT, "out", "cross_validation"))
    args = parser.parse_args()
    # Never write into a folder this tool did not make (its marker file says it did).
    marker = os.path.join(args.out, ".cross_validate")
    if os.path.exists(args.out) and not os.path.exists(marker):
        sys.exit(f"{args.out} exists and was not made by this tool: give another --out")
    os.makedirs(args.out, exist_ok=True)
    open(marker, "a", encoding="utf-8").close()
    # The host-sim of this source tree, not an older build.
    subprocess.run(["cargo", "build", "-q", "--release", "-p", "host-sim"], cwd=ROOT, check=True)
    params = [p for p in args.params.split(",") if p]
    unknown = [p for p in params if p not in PARAMETERS]
    if unknown:
        sys.exit(f"unknown parameter(s) {unknown}; known: {list(PARAMETERS)}")

    defaults = bench(args.datasets, [], os.path.join(args.out, "defaults"))
    trials = sorted(defaults)
    if len(trials) < 4:
        sys.exit(f"{len(trials)} BROAD trials found under {args.datasets}: too few to split")
    halves = (trials[0::2], trials[1::2])
    full = mean([defaults[t] for t in trials])
    print(f"{len(trials)} trials; defaults: full-set mean {full:.3f}, halves "
          f"{mean([defaults[t] for t in halves[0]]):.3f} / {mean([defaults[t] for t in halves[1]]):.3f}")

    report = {"trials": trials, "halves": halves, "defaults_full_mean": full, "parameters": {}}
    for name in params:
        default = PARAMETERS[name]
        grid = []
        for factor in FACTORS:
            value = default * factor
            scores = (
                defaults
                if factor == 1.0
                else bench(args.datasets, [f"{name} = {value!r}"], os.path.join(args.out, f"{name}_{factor:.3f}"))
            )
            grid.append((value, [mean([scores[t] for t in h]) for h in halves]))
        print(f"\n{name} (default {default:g}):")
        for value, (a, b) in grid:
            print(f"  {value:10.5g}  half 1 {a:.3f}  half 2 {b:.3f}")
        chosen = [min(grid, key=lambda g, k=k: g[1][k]) for k in (0, 1)]
        # Each half scored with the other's choice.
        held_out = [chosen[1][1][0], chosen[0][1][1]]
        cv = (held_out[0] * len(halves[0]) + held_out[1] * len(halves[1])) / len(trials)
        print(f"  half 1 chooses {chosen[0][0]:g} (scores {chosen[0][1][1]:.3f} on half 2); "
              f"half 2 chooses {chosen[1][0]:g} (scores {chosen[1][1][0]:.3f} on half 1); "
              f"cross-validated mean {cv:.3f} (defaults {full:.3f})")
        report["parameters"][name] = {
            "default": default,
            "grid": [{"value": v, "half_means": list(h)} for v, h in grid],
            "chosen_by_half": [chosen[0][0], chosen[1][0]],
            "held_out_means": held_out,
            "cross_validated_mean": cv,
        }
    with open(os.path.join(args.out, "cross_validation.json"), "w", encoding="utf-8") as f:
        json.dump(report, f, indent=1)
    print(f"\nwritten {os.path.join(args.out, 'cross_validation.json')}")


if __name__ == "__main__":
    main()

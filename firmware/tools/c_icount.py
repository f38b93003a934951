#!/usr/bin/env python3
"""Compares the C interface's per-call instruction counts (firmware/c/bench.c) with the Rust
demo's for the same calls over the same stream (firmware/src/bin/demo.rs: bench_nav_stream and
nav_imu_block_end), both counted by qemu-plugin/icount.c between bench_start and bench_stop.

  c_icount.py C_OUT C_ICOUNT RUST_DEMO_OUT RUST_ICOUNT [EXPECTED_RS] [--max-ratio R] [--no-gate]

C_OUT, C_ICOUNT: bench.c's semihosting output and the plugin's counts; RUST_DEMO_OUT,
RUST_ICOUNT: the demo's (firmware/target/ci/demo-3.txt, icount-3.txt, opt-level 3).
EXPECTED_RS (firmware/target/ci/expected.rs or src/expected.rs): the C run's final attitude and
fused blocks are checked against the host's f32 run of the same stream (the same computation:
the comparison is like for like). Each run's empty window 0 (the markers' cost) is subtracted
from its windows. The two stream runs have one window per call in the same order, so the C
run's tags (i: IMU call, m: magnetometer call) class the Rust windows too.

Exit status 1 if a C figure is more than R (default 1.03) times the Rust one (not with
--no-gate: figures only), or a run is incomplete or not the same run.
"""
import re
import struct
import sys

args = [a for a in sys.argv[1:] if not a.startswith("--")]
gate = "--no-gate" not in sys.argv
max_ratio = 1.03
if "--max-ratio" in sys.argv:
    max_ratio = float(sys.argv[sys.argv.index("--max-ratio") + 1])
    args.remove(sys.argv[sys.argv.index("--max-ratio") + 1])
c_out, c_icount, rust_out, rust_icount = args[:4]
expected = args[4] if len(args) > 4 else None


def counts(path):
    raw = {}
    for line in open(path):
        m = re.match(r"icount (\d+) (\d+)$", line.strip())
        if m:
            raw[int(m.group(1))] = int(m.group(2))
    if 0 not in raw:
        sys.exit(f"c_icount: {path}: no empty window 0 (did the run or the plugin fail?)")
    return {i: v - raw[0] for i, v in raw.items() if i != 0}, raw[0]


def fail(msg):
    print(f"C INSTRUCTION COUNTS: {msg}")
    sys.exit(1)


c_raw, c_overhead = counts(c_icount)
r_raw, r_overhead = counts(rust_icount)
c_text, r_text = open(c_out).read(), open(rust_out).read()

m = re.search(r"^c_bench_group (\d+) (\d+) c_nav_stream imu_samples=(\d+)", c_text, re.M)
if not m:
    fail(f"{c_out}: no c_bench_group line (the C run failed)")
c_first, c_windows, c_samples = map(int, m.groups())
tags = {}
for t in re.finditer(r"^c_bench_tags (\d+) (\S+)$", c_text, re.M):
    for k, code in enumerate(t.group(2)):
        tags[int(t.group(1)) + k] = code
m = re.search(r"^bench_group (\d+) (\d+) nav_stream imu_samples=(\d+)", r_text, re.M)
if not m:
    fail(f"{rust_out}: no nav_stream group (the Rust demo failed)")
r_first, r_windows, r_samples = map(int, m.groups())
if (c_windows, c_samples) != (r_windows, r_samples):
    fail(f"the runs differ: C {c_windows} windows, {c_samples} IMU samples; "
         f"Rust {r_windows}, {r_samples}")
c_stream = [(tags.get(c_first + j), c_raw.get(c_first + j)) for j in range(c_windows)]
r_stream = [r_raw.get(r_first + j) for j in range(r_windows)]
if any(t is None or v is None for t, v in c_stream) or None in r_stream:
    fail("a window of a stream run was not counted")
if sum(t == "i" for t, _ in c_stream) != c_samples:
    fail("the C run's tags do not count its IMU samples")

m = re.search(r"^c_bench (\d+) c_nav_imu_block_end stream_window=(\d+)", c_text, re.M)
c_step = c_raw.get(int(m.group(1))) if m else None
c_step_window = int(m.group(2)) if m else None
m = re.search(r"^bench (\d+) nav_imu_block_end ", r_text, re.M)
r_step = r_raw.get(int(m.group(1))) if m else None
if c_step is None or r_step is None:
    fail("the zero-rate call at rest was not measured in both runs")

# The run is the Rust one: the final attitude and the blocks fused as the host's f32 run.
same = "not checked (no expected.rs given)"
if expected:
    text = open(expected).read()
    host = text[text.index("EXPECTED_F32_HOST"):]
    want_q = [float(x) for x in re.search(r"nav_q: \[([^\]]*)\]", host).group(1).split(",")]
    want_fused = int(re.search(r"nav_fused: (\d+)", host).group(1))
    q = re.search(r"^c_nav_q (.*)$", c_text, re.M)
    fused = re.search(r"^c_nav_fused (\d+)", c_text, re.M)
    if not q or not fused:
        fail(f"{c_out}: no final estimate")
    got_q = [struct.unpack(">f", bytes.fromhex(h))[0] for h in q.group(1).split()]
    diff = max(abs(a - b) for a, b in zip(got_q, want_q))
    if diff > 2e-5 or int(fused.group(1)) != want_fused:
        fail(f"the C run is not the Rust run: attitude max|diff| {diff:.3g} against the host's "
             f"f32 run, {fused.group(1)} blocks fused (want {want_fused})")
    same = (f"the C run ends as the host's f32 run of the same stream (attitude max|diff| "
            f"{diff:.2g}, {want_fused} blocks fused)")


def figures(stream, step):
    imu = [v for t, v in stream if t == "i"]
    mag = [v for t, v in stream if t == "m"]
    everything = [v for _, v in stream]
    mean = lambda xs: (sum(xs) + len(xs) // 2) // len(xs)
    return [
        ("est_attitude_imu, mean over the stream", mean(imu)),
        ("est_attitude_imu, costliest", max(imu)),
        ("est_attitude_magnetometer, mean", mean(mag)),
        ("est_attitude_magnetometer, costliest", max(mag)),
        ("every call per IMU sample (nav_stream_per_imu_sample)",
         (sum(everything) + len(imu) // 2) // len(imu)),
        ("costliest call of the stream (nav_stream_max_call)", max(everything)),
        ("zero-rate call at rest (nav_imu_block_end)", step),
    ]


c_fig = figures(c_stream, c_step)
r_fig = figures([(t, r) for (t, _), r in zip(c_stream, r_stream)], r_step)
print(f"instructions per call, net of the empty window (C {c_overhead}, Rust {r_overhead}); "
      f"the same {c_samples} IMU and {c_windows - c_samples} magnetometer calls")
print(f"{'call':<56} {'C':>7} {'Rust':>7}  ratio")
over = []
for (name, c), (_, r) in zip(c_fig, r_fig):
    ratio = c / r
    flag = "" if ratio <= max_ratio else f"  over {max_ratio:.2f}"
    if flag:
        over.append(name)
    print(f"{name:<56} {c:>7} {r:>7}  {ratio:.3f}{flag}")
if c_step_window is not None and c_raw.get(c_step_window) is not None:
    j = c_step_window - c_first
    print(f"(the zero-rate call within the stream: C {c_raw[c_step_window]}, "
          f"Rust {r_stream[j]})")
print(same)
if not gate:
    sys.exit(0)
if over:
    fail(f"over {max_ratio:.2f} x the Rust figure: " + "; ".join(over))
print(f"C instruction counts: every figure within {max_ratio:.2f} x the Rust demo's")

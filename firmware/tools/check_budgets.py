#!/usr/bin/env python3
"""Collects the firmware figures and checks them against firmware/budgets.txt.

  check_budgets.py BUDGETS DEMO_OUT ICOUNT_OUT [EXTRA...]   check, print the table
  check_budgets.py BUDGETS --allowed CHECK                   exit 0 if CHECK has an allowance

DEMO_OUT: the demo's semihosting output (`bench <i> <name> stack=<bytes>`, `size_of <T> <n>`,
`bench_group <first> <windows> <name> imu_samples=<n> stack=<bytes>`: one window per call of a
run over a stream, giving `icount.<name>_per_imu_sample` (the windows' sum over the IMU samples,
rounded), `icount.<name>_max_call` and `stack.<name>`; `bench_classes <name> <code>:<class> ...`
and `bench_tags <name> <first window> <codes>`: the class of each window of a group, one
character each, giving `icount.<name>_<class>_max`, `icount.<name>_<class>_mean` and
`calls.<name>_<class>`; `bench_stack <name> <bytes>`: a peak stack measured by the demo).
ICOUNT_OUT: the plugin's output (`icount <i> <instructions>`); window 0 is the empty one, whose
count (the marker overhead) is subtracted from the others.
EXTRA: files of `name value` lines (flash sizes measured by the script).
FIRMWARE_STRICT=1: enforce the targets, not the ceilings; no allowances.
`stack.max` is the peak stack of every call but those whose own `stack.<name>` line is a guard
(ceiling above target: the target is not met and that line holds the call).
"""
import os
import re
import sys

strict = os.environ.get("FIRMWARE_STRICT") == "1"


def read_budgets(path):
    budgets, allow = {}, set()
    for raw in open(path):
        line = raw.split("#", 1)[0].split()
        if not line:
            continue
        if line[0] == "allow":
            allow.add(line[1])
        else:
            budgets[line[0]] = (int(line[1]), int(line[2]))
    return budgets, allow


budgets, allow = read_budgets(sys.argv[1])
if sys.argv[2] == "--allowed":
    sys.exit(0 if (sys.argv[3] in allow and not strict) else 1)

names, stack, icount, sizes, extra, groups = {}, {}, {}, {}, {}, []
legends, tags = {}, {}
for line in open(sys.argv[2]):
    m = re.match(r"bench_classes (\S+) (.*)$", line.strip())
    if m:
        legends[m.group(1)] = dict(c.split(":", 1) for c in m.group(2).split())
    m = re.match(r"bench_tags (\S+) (\d+) (\S+)$", line.strip())
    if m:
        for k, code in enumerate(m.group(3)):
            tags[int(m.group(2)) + k] = (m.group(1), code)
    m = re.match(r"bench_stack (\S+) (\d+)$", line.strip())
    if m:
        stack[m.group(1)] = int(m.group(2))
    m = re.match(r"bench (\d+) (\S+) stack=(\d+)", line)
    if m:
        names[int(m.group(1))] = m.group(2)
        stack[m.group(2)] = int(m.group(3))
    m = re.match(r"bench_group (\d+) (\d+) (\S+) imu_samples=(\d+) stack=(\d+)", line)
    if m:
        first, windows, name, samples = int(m.group(1)), int(m.group(2)), m.group(3), int(m.group(4))
        groups.append((first, windows, name, samples))
        stack[name] = int(m.group(5))
    m = re.match(r"size_of (.+) (\d+)$", line.strip())
    if m:
        sizes[m.group(1)] = int(m.group(2))
raw = {}
for line in open(sys.argv[3]):
    m = re.match(r"icount (\d+) (\d+)$", line.strip())
    if m:
        raw[int(m.group(1))] = int(m.group(2))
if not names or 0 not in raw:
    print("check_budgets: no benchmark output (did the demo or the plugin fail?)")
    sys.exit(1)
overhead = raw[0]
for i, name in names.items():
    if i in raw and i != 0:
        icount[name] = raw[i] - overhead
for first, windows, name, samples in groups:
    calls = [raw[i] - overhead for i in range(first, first + windows) if i in raw]
    if len(calls) != windows or samples == 0:
        print(f"check_budgets: {name}: {len(calls)} of {windows} windows counted")
        sys.exit(1)
    icount[name + "_per_imu_sample"] = (sum(calls) + samples // 2) // samples
    icount[name + "_max_call"] = max(calls)
    classes = {}
    for i in range(first, first + windows):
        if tags.get(i, (None,))[0] == name:
            classes.setdefault(tags[i][1], []).append(raw[i] - overhead)
    for code, counts in classes.items():
        cls = legends.get(name, {}).get(code, code)
        icount[f"{name}_{cls}_max"] = max(counts)
        icount[f"{name}_{cls}_mean"] = (sum(counts) + len(counts) // 2) // len(counts)
        extra[f"calls.{name}_{cls}"] = len(counts)
for path in sys.argv[4:]:
    for line in open(path):
        parts = line.split()
        if len(parts) == 2:
            extra[parts[0]] = int(parts[1])

figures = {}
for k, v in icount.items():
    figures["icount." + k] = v
for k, v in stack.items():
    if k != "empty":
        figures["stack." + k] = v
# The peak of every call but those held by a guard of their own (a `stack.<name>` line whose
# ceiling is above its target: the target is not met, that line holds the call).
guarded = {k for k, (target, ceiling) in budgets.items() if ceiling > target}
figures["stack.max"] = max((v for k, v in stack.items() if "stack." + k not in guarded), default=0)
for k, v in sizes.items():
    figures["sizeof." + k] = v
figures.update(extra)

print(f"instruction-count overhead of the empty window: {overhead} (subtracted)")
print(f"{'figure':<36} {'measured':>10} {'target':>10} {'ceiling':>10}  verdict")
failed = 0
for k in sorted(figures):
    v = figures[k]
    if k in budgets:
        target, ceiling = budgets[k]
        limit = target if strict else ceiling
        if v > limit:
            verdict = "FAIL (over " + ("target" if strict else "ceiling") + ")"
            failed += 1
        elif v > target:
            verdict = "over target (allowed ceiling)"
        else:
            verdict = "ok"
        print(f"{k:<36} {v:>10} {target:>10} {limit:>10}  {verdict}")
    else:
        print(f"{k:<36} {v:>10} {'-':>10} {'-':>10}")
missing = [k for k in budgets if k not in figures]
for k in missing:
    print(f"{k:<36} {'missing':>10}  FAIL")
    failed += 1
print(f"budgets: {failed} over")
sys.exit(1 if failed else 0)

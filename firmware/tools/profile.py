#!/usr/bin/env python3
"""Instructions per function inside one measured window.

Usage: profile.py ELF PLUGIN_OUT [N]   (PLUGIN_OUT from the plugin run with profile=<index>)

Maps the `tb <addr> <instructions>` lines of the plugin to the enclosing function symbol
(llvm-nm -n -C) and prints the top N functions (default 25). Note: with LTO most of the filter is
inlined, so the figures are per *emitted* function.
"""
import bisect
import collections
import subprocess
import sys

elf, prof = sys.argv[1], sys.argv[2]
top = int(sys.argv[3]) if len(sys.argv) > 3 else 25
syms = []
for line in subprocess.run(["llvm-nm", "-n", "-C", elf], check=True, capture_output=True,
                           text=True).stdout.splitlines():
    parts = line.split(None, 2)
    if len(parts) == 3 and parts[1] in "tTwW" and not parts[2].startswith("$"):
        syms.append((int(parts[0], 16) & ~1, parts[2]))
syms.sort()
addrs = [a for a, _ in syms]
per = collections.Counter()
total = 0
for line in open(prof):
    if line.startswith("tb "):
        _, a, n = line.split()
        a, n = int(a, 16), int(n)
        i = bisect.bisect_right(addrs, a) - 1
        per[syms[i][1] if i >= 0 else "?"] += n
        total += n
print(f"{total} instructions in the profiled window")
for name, n in per.most_common(top):
    print(f"{n:>9} {100.0 * n / max(total, 1):5.1f}%  {name[:150]}")

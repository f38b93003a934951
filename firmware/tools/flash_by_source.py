#!/usr/bin/env python3
"""Where the flash of a firmware ELF goes, by the estimator-core code that produced it.

Usage: flash_by_source.py ELF [N]

Every instruction's address goes through `llvm-symbolizer --inlining`; its bytes are charged to
the innermost frame of the inline chain that lies in estimator-core (or in the firmware crate),
so code that nalgebra, core or libm inlined into a function counts for that function. Prints the
top N functions (default 40), then the totals per source file. With LTO most of the library is
inlined into a few emitted functions: `llvm-nm --size-sort` alone says little about who is big.
"""
import collections
import re
import subprocess
import sys

elf = sys.argv[1]
top = int(sys.argv[2]) if len(sys.argv) > 2 else 40

listing = subprocess.run(["llvm-objdump", "-d", "--no-show-raw-insn", elf], check=True,
                         capture_output=True, text=True).stdout
insn = re.compile(r"^\s*([0-9a-f]+):\s")
addrs = [int(m.group(1), 16) for line in listing.splitlines() if (m := insn.match(line))]
# Thumb-2 instructions are 2 or 4 bytes; a larger gap is padding or a literal pool (charged 2).
size = {a: (b - a if 0 < b - a <= 4 else 2) for a, b in zip(addrs, addrs[1:])}

symbolized = subprocess.run(
    ["llvm-symbolizer", "--obj=" + elf, "--inlining", "--demangle", "--functions"],
    input="".join(f"{a:#x}\n" for a in size), check=True, capture_output=True, text=True,
).stdout.split("\n\n")

per_fn = collections.Counter()
per_file = collections.Counter()
for addr, block in zip(size, symbolized):
    lines = block.strip().splitlines()
    frames = list(zip(lines[0::2], lines[1::2]))
    own = [f for f in frames if "/estimator-core/" in f[1] or "/firmware/src" in f[1]]
    fn, loc = own[0] if own else (frames[-1] if frames else ("?", "?"))
    fn = re.sub(r"::h[0-9a-f]{16}$", "", fn)
    for _ in range(6):  # drop generic arguments, innermost first
        fn = re.sub(r"<[^<>]*>", "", fn)
    per_fn[fn] += size[addr]
    src = re.sub(r":\d+(:\d+)?$", "", loc)
    src = re.sub(r"^.*/(estimator-core/src/|firmware/src/)", r"\1", src)
    src = re.sub(r"^.*/registry/src/[^/]+/([^/]+)/.*$", r"\1", src)
    src = re.sub(r"^.*/library/([^/]+)/.*$", r"\1", src)
    per_file[src] += size[addr]

print(f"{sum(size.values())} bytes of code; by estimator-core function (inlined code included):")
for name, n in per_fn.most_common(top):
    print(f"{n:8} {name}")
print("by source file:")
for name, n in per_file.most_common():
    print(f"{n:8} {name}")

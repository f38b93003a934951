#!/usr/bin/env python3
"""List the panic call sites of a firmware ELF built with the plain panic handler.

Usage: panic_sites.py ELF [OBJDUMP] [ADDR2LINE]

Disassembles ELF (llvm-objdump -d -C), finds every branch into a panicking function of core
(core::panicking::*, slice index failures, unwrap/expect failures, ...), and prints for each call
site the enclosing symbol and the inlined source chain (llvm-addr2line -f -i -C), innermost
first: the first estimator_core frame in the chain is the culprit. Exit status 1 if any site.
"""
import re
import subprocess
import sys

elf = sys.argv[1]
objdump = sys.argv[2] if len(sys.argv) > 2 else "llvm-objdump"
addr2line = sys.argv[3] if len(sys.argv) > 3 else "llvm-addr2line"

PANICKY = re.compile(
    r"<(core::panicking::[^>]*|core::slice::index::[^>]*fail[^>]*|core::option::(unwrap|expect)_failed"
    r"|core::result::unwrap_failed|core::cell::panic[^>]*|core::num::[^>]*fail[^>]*"
    r"|core::array::[^>]*fail[^>]*|core::str::[^>]*fail[^>]*)>"
)
SYM = re.compile(r"^([0-9a-f]+) <(.*)>:$")
INSN = re.compile(r"^\s*([0-9a-f]+):\s+(\S+)\s+(.*)$")

dis = subprocess.run([objdump, "-d", "-C", "--no-show-raw-insn", elf],
                     check=True, capture_output=True, text=True).stdout
sites = []
current = "?"
current_addr = None
func_addr = {}          # symbol -> address
calls = {}              # callee symbol -> [(call address, caller symbol)]
CALL = re.compile(r"<([^>+]*)>")
for line in dis.splitlines():
    m = SYM.match(line)
    if m and not m.group(2).startswith("$"):
        func_addr[m.group(2)] = m.group(1)
        current = m.group(2)
        continue
    m = INSN.match(line)
    if m and m.group(2).startswith("bl"):
        t = CALL.search(m.group(3))
        if t:
            calls.setdefault(t.group(1), []).append((m.group(1), current))
current = "?"
for line in dis.splitlines():
    m = SYM.match(line)
    if m:
        if not m.group(2).startswith("$"):
            current = m.group(2)
        continue
    m = INSN.match(line)
    if not m:
        continue
    addr, op, rest = m.groups()
    if not op.startswith("b"):
        continue
    t = PANICKY.search(rest)
    if t and not re.match(r"(core::panicking|core::slice::index|core::option|core::result|"
                          r"core::cell|core::num|core::array|core::str|__rustc)", current):
        sites.append((addr, current, t.group(1)))

for addr, fn, target in sites:
    print(f"panic site 0x{addr} in {fn} -> {target}")
    chain = subprocess.run([addr2line, "-f", "-i", "-C", "-e", elf, "0x" + addr],
                           check=False, capture_output=True, text=True).stdout.splitlines()
    for func, loc in zip(chain[0::2], chain[1::2]):
        print(f"    {func}  at {loc}")
    if "estimator_core" not in fn and "nopanic" not in fn:
        # The panic is inside a library function that was not inlined: show who calls it.
        for caddr, caller in calls.get(fn, [])[:12]:
            chain = subprocess.run([addr2line, "-i", "-C", "-e", elf, "0x" + caddr], check=False,
                                   capture_output=True, text=True).stdout.splitlines()
            ours = [c for c in chain if "estimator-core/src" in c][:1]
            print(f"    called from {caller} at {ours[0] if ours else (chain[:1] or ['?'])[0]}")
print(f"{len(sites)} panic call site(s)")
sys.exit(1 if sites else 0)

#!/usr/bin/env python3
"""Prints the bytes of .text that lie between functions (the linker's alignment padding).

  text_padding.py ELF

The functions' own sizes do not depend on where the checkout lives, but their order does: cargo
hashes a path dependency that lies outside the firmware's workspace (../estimator-core) by its
absolute path, the hash enters every symbol name, and the linker places the functions in an
order that follows the names. A function that must start on a 4-byte boundary then gets 0 or 2
bytes of padding before it, so the same source links a few bytes larger or smaller from another
directory (195,568 B against 195,564 B for the demo at opt "s" in two checkouts). This is the
padding of one layout: readme_figures.py accepts a README flash figure that differs from the
measured one by no more than it.
"""
import subprocess
import sys


def main():
    out = subprocess.run(["llvm-nm", "-S", "--numeric-sort", sys.argv[1]],
                         capture_output=True, text=True, check=True).stdout
    end, padding = 0, 0
    for line in out.splitlines():
        parts = line.split()
        if len(parts) < 4 or parts[2] not in ("t", "T"):
            continue
        start, size = int(parts[0], 16), int(parts[1], 16)
        if end and start > end:
            padding += start - end
        end = max(end, start + size)
    print(padding)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Checks that the no-panic harness names every public function of estimator-core.

  api_coverage.py CORE_SRC HARNESS      e.g. ../estimator-core/src src/bin/nopanic.rs

The no-panic check proves only what the harness calls. This lists every `pub fn` of
estimator-core (inherent and free functions; `pub(crate)` and the like are not public) and every
method of its public traits, and fails when one of their names does not occur in the harness: a
function added to the API without a call in `nopanic.rs` fails CI. Left out: the files compiled
for the tests only, the crate-private module `lie/trig.rs`, and the names in EXEMPT (each with
its reason). A name that occurs is taken as called: this is a guard against forgetting, not a
proof (the link itself is the proof for what is called).
"""
import os
import re
import sys

# Files that are not public API: test-only modules, and a private module whose `pub fn` items are
# visible to the crate only (`mod trig;` in lie/mod.rs, nothing re-exported).
PRIVATE_FILES = {"rewrites.rs", "test_support.rs", os.path.join("lie", "trig.rs")}

EXEMPT = {
    # f32 -> f64 by design (host tools and tests); calling it would link f64 soft-float.
    "to_f64": "widens to f64; never on an f32 path",
    # A const fn over f64 for compile-time thresholds; a run-time call is f64 arithmetic.
    "taylor_cutoff": "const fn, evaluated at compile time",
    # Implemented by the user's problem and called by `solve` (which the harness calls with
    # `PnpProblem` and a slice of residual blocks), not an entry point of its own.
    "linearize<F>": "called through solve",
}


def public_functions(src):
    names = {}
    for root, _, files in os.walk(src):
        for f in files:
            if not f.endswith(".rs"):
                continue
            path = os.path.join(root, f)
            rel = os.path.relpath(path, src)
            if f in PRIVATE_FILES or rel in PRIVATE_FILES:
                continue
            text = open(path, encoding="utf-8").read()
            for m in re.finditer(r"^\s*pub(?:\s+const)?\s+fn\s+([a-z_][a-z0-9_]*)", text, re.M):
                names.setdefault(m.group(1), rel)
            # Methods declared in public traits.
            for t in re.finditer(r"^pub trait .*?^}", text, re.M | re.S):
                for m in re.finditer(r"^    fn ([a-z_][a-z0-9_]*(?:<F>)?)", t.group(0), re.M):
                    names.setdefault(m.group(1), rel)
    return names


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    names = public_functions(sys.argv[1])
    harness = open(sys.argv[2], encoding="utf-8").read()
    missing = sorted(
        (n, f) for n, f in names.items() if n not in EXEMPT and not re.search(r"\b%s\b" % re.escape(n), harness)
    )
    print("api coverage: %d public functions and trait methods, %d exempt" % (len(names), len(EXEMPT)))
    for n, f in missing:
        print("  not called by the no-panic harness: %s (estimator-core/src/%s)" % (n, f))
    sys.exit(1 if missing else 0)


if __name__ == "__main__":
    main()

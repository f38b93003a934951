#!/usr/bin/env bash
# Regenerates firmware/src/stream.rs, the demo's embedded stream, from host-sim:
#   bash firmware/tools/make_stream.sh            # writes firmware/src/stream.rs
#   bash firmware/tools/make_stream.sh OUT.rs     # writes OUT.rs instead (CI compares it)
# Three datasets from `host-sim simulate` (seed 1), cut by tools/make_stream.py.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
out=${1:-$root/firmware/src/stream.rs}
data=$(mktemp -d)
trap 'rm -rf "$data"' EXIT
cd "$root"
for s in default handheld_ahrs camera; do
  cargo run -q --release -p host-sim -- simulate --scenario "$s" --seed 1 --out "$data/$s" > /dev/null
done
python3 firmware/tools/make_stream.py "$data/default" "$data/handheld_ahrs" "$data/camera" > "$out.tmp"
mv "$out.tmp" "$out"

#!/usr/bin/env bash
# The Python package (python/): a fresh venv in /tmp, `pip install ./python pytest numpy`, then
# its pytest suite. Prints the time each step took. Run from anywhere: `bash .ci/python.sh`.
#
# The wheel is built with the workspace's release profile into its target/ (CARGO_TARGET_DIR if
# set), so after `cargo build --release -p host-sim` most of host-sim's dependencies are reused.
# ESTIMATOR_PY_FAST=1 builds without LTO and with parallel codegen instead (a cold target dir):
# the tests need the numbers, not the last percent of speed.
set -euo pipefail
cd "$(dirname "$0")/.."

t_all=$SECONDS
timed() {
  local name=$1
  shift
  local t0=$SECONDS
  printf '\n==== python: %s\n' "$name"
  "$@"
  printf '==== python: %s took %d s\n' "$name" $((SECONDS - t0))
}

PY=${PYTHON:-python3}
VENV=$(mktemp -d /tmp/estimator-py-venv.XXXXXX)
trap 'rm -rf "$VENV"' EXIT

if [ "${ESTIMATOR_PY_FAST:-0}" = 1 ]; then
  export CARGO_PROFILE_RELEASE_LTO=false CARGO_PROFILE_RELEASE_CODEGEN_UNITS=16
fi

timed "venv ($("$PY" --version))" "$PY" -m venv "$VENV"
timed "pip install ./python pytest numpy" "$VENV/bin/pip" install -q --disable-pip-version-check ./python pytest numpy
# From outside the source tree, so that the installed package is the one imported.
timed "pytest" bash -c "cd /tmp && '$VENV/bin/python' -m pytest -q -p no:cacheprovider '$PWD/python/tests'"
printf '\n==== python: all steps took %d s\n' $((SECONDS - t_all))

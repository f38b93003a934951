#!/usr/bin/env bash
# Builds firmware/src/starter.rs as the src/main.rs of a fresh cortex-m-rt crate, made from the
# blocks of firmware/README.md, section "Starting your own firmware", that are marked
# `<!-- starter-check: NAME -->` (Cargo.toml, memory.x, .cargo/config.toml; the git form of the
# dependency line). Exits non-zero when a block is missing or the build fails.
#
#   bash firmware/tools/starter-check.sh         # estimator-core by path: this checkout
#   bash firmware/tools/starter-check.sh --git   # by git: a file:// clone of this checkout's HEAD
#                                                # (committed state only)
#
# The crate is built in a temporary directory outside this repository (no workspace or Cargo
# config of ours applies), for thumbv7em-none-eabihf, in the release profile and in the dev
# profile (a user's first `cargo build`). The dependencies come from crates.io; offline, with
# the crates already in Cargo's cache: CARGO_NET_OFFLINE=true. Another toolchain (the MSRV):
# RUSTUP_TOOLCHAIN=1.89. STARTER_CHECK_KEEP=1 keeps the temporary crate.
set -euo pipefail
mode=path
case "${1:-}" in
  "") ;;
  --git) mode=git ;;
  *) echo "usage: $0 [--git]" >&2; exit 2 ;;
esac
REPO=$(cd "$(dirname "$0")/../.." && pwd)
README=$REPO/firmware/README.md
TMP=$(mktemp -d "${TMPDIR:-/tmp}/starter-check.XXXXXX")
if [ "${STARTER_CHECK_KEEP:-0}" = 1 ]; then
  echo "temporary crate kept: $TMP/my-firmware"
else
  trap 'rm -rf "$TMP"' EXIT
fi
CRATE=$TMP/my-firmware
mkdir -p "$CRATE/src" "$CRATE/.cargo"

# The fenced block after `<!-- starter-check: NAME -->`, without the list item's indentation.
block() {
  python3 - "$README" "$1" <<'PY'
import sys
text = open(sys.argv[1], encoding="utf-8").read().splitlines()
marker = "<!-- starter-check: %s -->" % sys.argv[2]
starts = [i for i, line in enumerate(text) if line.strip() == marker]
if len(starts) != 1:
    sys.exit("starter-check: %d blocks marked %r in the README (want 1)" % (len(starts), marker))
i = starts[0] + 1
while i < len(text) and not text[i].strip():
    i += 1
if i == len(text) or not text[i].lstrip().startswith("```"):
    sys.exit("starter-check: no fenced block after %r" % marker)
indent = len(text[i]) - len(text[i].lstrip())
out = []
for line in text[i + 1:]:
    if line.strip() == "```":
        break
    out.append(line[indent:] if line[:indent].strip() == "" else line)
else:
    sys.exit("starter-check: unterminated block after %r" % marker)
print("\n".join(out))
PY
}

block Cargo.toml > "$TMP/Cargo.toml.readme"
block memory.x > "$CRATE/memory.x"
block .cargo/config.toml > "$CRATE/.cargo/config.toml"
if [ "$mode" = path ]; then
  dep="estimator-core = { path = \"$REPO/estimator-core\" }"
else
  if [ -n "$(git -C "$REPO" status --porcelain -- estimator-core Cargo.toml)" ]; then
    echo "note: estimator-core has uncommitted changes; --git builds HEAD without them"
  fi
  git clone -q --bare "$REPO" "$TMP/estimator.git"
  echo "git dependency: file://$TMP/estimator.git at $(git -C "$TMP/estimator.git" rev-parse --short HEAD)"
  dep=$(block "dependency git")
  grep -q "<your clone's URL>" <<< "$dep" \
    || { echo "starter-check: the README's git line has no <your clone's URL> placeholder" >&2; exit 1; }
  dep=${dep//"<your clone's URL>"/file://$TMP/estimator.git}
fi
# The README's dependency line (the path form, for a clone at ../estimator) becomes $dep.
python3 - "$TMP/Cargo.toml.readme" "$dep" > "$CRATE/Cargo.toml" <<'PY'
import sys
lines = open(sys.argv[1], encoding="utf-8").read().splitlines()
hits = [i for i, l in enumerate(lines) if l.startswith("estimator-core = ")]
if len(hits) != 1:
    sys.exit("starter-check: want one `estimator-core = ` line in the README's Cargo.toml, found %d" % len(hits))
lines[hits[0]] = sys.argv[2]
print("\n".join(lines))
PY
cp "$REPO/firmware/src/starter.rs" "$CRATE/src/main.rs"
echo "--- Cargo.toml of the temporary crate"
cat "$CRATE/Cargo.toml"

cd "$CRATE"
cargo --version
TARGET_DIR=${CARGO_TARGET_DIR:-$CRATE/target}
status=0
for profile in release dev; do
  dir=$profile; [ "$profile" = dev ] && dir=debug
  elf=$TARGET_DIR/thumbv7em-none-eabihf/$dir/my-firmware
  rm -f "$elf"
  echo "--- cargo build --profile $profile"
  if cargo build --profile "$profile" && [ -f "$elf" ]; then
    if command -v llvm-size > /dev/null; then llvm-size "$elf"; fi
    echo "starter-check ($mode dependency, $profile): builds for thumbv7em-none-eabihf"
  else
    echo "STARTER CHECK FAILED ($mode dependency, $profile)"
    status=1
  fi
done
exit "$status"

#!/usr/bin/env bash
# CI for estimator-c (the C interface) beyond `cargo test --workspace`, which already runs its
# tests (estimator-c/tests: the error codes, the header against cbindgen and as strict C99, the
# C replay against the Rust navigator bit for bit). Called by .ci/run as `bash .ci/c.sh`.
#
#  1. the header also compiles as C++ (it declares `extern "C"` for C++ users);
#  2. the C firmware example (firmware/c/main.c, the attitude navigator's main loop) built with
#     arm-none-eabi-gcc against libestimator_c.a for the Cortex-M4F and run under QEMU
#     (mps2-an386): it checks its own result and exits non-zero on a wrong one;
#  3. the link-time no-panic check of the library: the firmware links with --gc-sections only if
#     no panic path is reachable (estimator-c/src/lib.rs, the panic handler); a link without
#     --gc-sections keeps core's panic paths and must fail, or the check would be vacuous;
#  4. no f64 soft-float routine (__aeabi_d*, __adddf3, ...: the pattern of .ci/firmware.sh) in the
#     C binaries;
#  5. instruction counts per call (firmware/c/bench.c: est_attitude_imu and
#     est_attitude_magnetometer over the Rust demo's attitude stream, counted by the QEMU plugin
#     firmware/qemu-plugin/icount.c between the same markers as the Rust demo) against the Rust
#     demo's AttitudeNavigator<f32> figures for the same calls at opt-level 3 (the demo of
#     .ci/firmware.sh, in firmware/target, counted again here). The library is built as the Rust figures are:
#     opt-level 3, LTO (`cargo rustc --crate-type staticlib`: a plain `cargo build` of the
#     staticlib+rlib crate gets no LTO), tuned for the Cortex-M4 (`-C target-cpu=cortex-m4`, as
#     firmware's `cargo build-m4`); the C at -O2. Fails if a C figure is more than
#     C_ICOUNT_MAX_RATIO (1.03) times the Rust one. The same counts for the library as step 2
#     builds it (no LTO, plain target CPU) are printed too, not checked: a different build.
set -euo pipefail
cd "$(dirname "$0")/.."

step() { printf '\n==== c: %s (at %d s)\n' "$*" "$SECONDS"; }
status=0
TARGET=thumbv7em-none-eabihf
TD=${CARGO_TARGET_DIR:-target}
OUT=$TD/c-firmware
mkdir -p "$OUT"

step "install: target, arm-none-eabi-gcc, qemu-system-arm"
rustup target add "$TARGET"
need_apt=()
# Only the compiler: the example needs no C library (newlib, libstdc++: about 1 GB unpacked).
command -v arm-none-eabi-gcc >/dev/null || need_apt+=(gcc-arm-none-eabi)
command -v qemu-system-arm >/dev/null || need_apt+=(qemu-system-arm)
if [ ${#need_apt[@]} -gt 0 ]; then
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${need_apt[@]}"
fi
arm-none-eabi-gcc --version | sed -n 1p

step "the header as C++"
if command -v c++ >/dev/null; then
  printf '#include "estimator.h"\nint main() { est_attitude_config c; return est_attitude_config_default(&c); }\n' \
    > "$OUT/header.cpp"
  c++ -std=c++11 -Wall -Wextra -Werror -pedantic -I estimator-c/include -c "$OUT/header.cpp" -o "$OUT/header.o"
  echo "estimator.h compiles as C++11"
else
  echo "skipped: no C++ compiler"
fi

step "libestimator_c.a for $TARGET (release)"
cargo build -p estimator-c --release --target "$TARGET"
LIB=$TD/$TARGET/release/libestimator_c.a

CFLAGS=(-mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard -O2 -std=c99 -Wall -Wextra
  -Werror -pedantic -ffreestanding -ffunction-sections -fdata-sections -nostdlib
  -I estimator-c/include -T firmware/c/link.ld -Wl,-z,noexecstack)
SOURCES=(firmware/c/main.c firmware/c/startup.c "$LIB" -lgcc)

step "C firmware example: build (arm-none-eabi-gcc, no panic path reachable) and run under QEMU"
arm-none-eabi-gcc "${CFLAGS[@]}" -Wl,--gc-sections -o "$OUT/c-demo.elf" "${SOURCES[@]}"
arm-none-eabi-size "$OUT/c-demo.elf"
if timeout 120 qemu-system-arm -machine mps2-an386 -cpu cortex-m4 -nographic -monitor none \
  -serial none -semihosting-config enable=on,target=native -kernel "$OUT/c-demo.elf" \
  > "$OUT/c-demo.txt" 2>&1; then
  cat "$OUT/c-demo.txt"
else
  cat "$OUT/c-demo.txt"
  echo "C FIRMWARE EXAMPLE FAILED: wrong result, fault or QEMU failure (see above)"
  exit 1
fi

step "no-panic self-test: without --gc-sections the link must fail on the panic handler"
if arm-none-eabi-gcc "${CFLAGS[@]}" -o "$OUT/no-gc.elf" "${SOURCES[@]}" 2> "$OUT/no-gc.log"; then
  echo "C NO-PANIC SELF-TEST FAILED: a link keeping core's panic paths succeeded (the check is vacuous)"
  exit 1
elif grep -q __estimator_c_panic_path_reachable "$OUT/no-gc.log"; then
  echo "no-panic self-test: a reachable panic fails the link, as it should"
else
  cat "$OUT/no-gc.log"
  echo "C NO-PANIC SELF-TEST FAILED for another reason than the panic handler"
  exit 1
fi

# Symbols of f64 soft-float routines (libgcc, compiler-builtins / the ARM EABI): .ci/firmware.sh's
# pattern.
F64_RE='(__aeabi_d[a-z0-9]+|__aeabi_[a-z0-9]+2d|__aeabi_f2d|__[a-z]+df[23]|__fix(uns)?df[sd]i|__float(un)?[sd]idf|__extendsfdf2|__truncdfsf2)$'
no_f64() { # ELF...: fails on any f64 soft-float routine linked in
  local elf syms
  for elf in "$@"; do
    syms=$(arm-none-eabi-nm "$elf" | awk '{ print $NF }' | grep -E "$F64_RE" | sort -u | tr '\n' ' ' || true)
    if [ -n "$syms" ]; then
      echo "$elf: $syms"
      echo "C CHECK FAILED: f64 soft-float routines linked into $elf"
      status=1
    else
      echo "$elf: no f64 soft-float routine"
    fi
  done
}
step "no f64 soft-float in the C firmware example"
no_f64 "$OUT/c-demo.elf"

step "instruction counts per call: C (firmware/c/bench.c) against the Rust demo, opt-level 3"
FW=firmware
CI=$FW/target/ci
# The plugin: .ci/firmware.sh's build, or our own.
PLUGIN=$CI/libicount.so
if [ ! -f "$PLUGIN" ]; then
  PLUGIN=$OUT/libicount.so
  gcc -O2 -Wall -shared -fPIC -o "$PLUGIN" $FW/qemu-plugin/icount.c
fi
# Runs ELF under QEMU with the plugin between bench_start and bench_stop: output (stdout and
# the semihosting console) to $2, counts to $3.
run_counted() {
  local elf=$1 log=$2 ic=$3 start stop nm=arm-none-eabi-nm
  start=$($nm "$elf" | awk '$3 == "bench_start" { print "0x" $1 }')
  stop=$($nm "$elf" | awk '$3 == "bench_stop" { print "0x" $1 }')
  timeout 120 qemu-system-arm -machine mps2-an386 -cpu cortex-m4 -nographic -monitor none \
    -serial none -semihosting-config enable=on,target=native \
    -plugin "$PLUGIN,start=$start,stop=$stop,out=$ic" -kernel "$elf" > "$log" 2>&1
}
# The Rust figures: the demo (opt-level 3, Cortex-M4-tuned) in the firmware's own target dir, built
# as .ci/firmware.sh builds it (after it, cargo finds the binary up to date: no build), run here
# under the plugin (under a second).
EXPECTED=$PWD/$CI/expected.rs
if [ -f "$EXPECTED" ]; then
  export FIRMWARE_EXPECTED=$EXPECTED # .ci/firmware.sh's value: the same build
else
  EXPECTED=$PWD/$FW/src/expected.rs
fi
(cd $FW && env -u CARGO_TARGET_DIR cargo build-m4 -q --release --bin demo)
RUST_OUT=$OUT/rust-demo-3.txt RUST_IC=$OUT/rust-icount-3.txt
run_counted $FW/target/$TARGET/release/demo "$RUST_OUT" "$RUST_IC" \
  || echo "note: the Rust demo's own result checks failed (see $RUST_OUT); its counts are still compared"
# The library as the Rust figures are built: LTO (only a staticlib-only build gets it), opt-level
# 3, tuned for the Cortex-M4. Its own target dir: other flags than step 2's build.
CARGO_TARGET_DIR=$TD/c-icount cargo rustc -q -p estimator-c --release --target "$TARGET" \
  --crate-type staticlib --config "target.$TARGET.rustflags=['-C', 'target-cpu=cortex-m4']"
LIB_ICOUNT=$TD/c-icount/$TARGET/release/libestimator_c.a
python3 $FW/tools/c_stream.py $FW/src/stream.rs > "$OUT/ahrs_stream.h"
BENCH=(firmware/c/bench.c firmware/c/startup.c)
# Links with --gc-sections: it fails if a panic path of the library is reachable.
arm-none-eabi-gcc "${CFLAGS[@]}" -I "$OUT" -Wl,--gc-sections -o "$OUT/c-bench.elf" "${BENCH[@]}" "$LIB_ICOUNT" -lgcc
arm-none-eabi-gcc "${CFLAGS[@]}" -I "$OUT" -Wl,--gc-sections -o "$OUT/c-bench-default.elf" "${BENCH[@]}" "$LIB" -lgcc
no_f64 "$OUT/c-bench.elf" "$OUT/c-bench-default.elf"
for v in c-bench c-bench-default; do
  if ! run_counted "$OUT/$v.elf" "$OUT/$v.txt" "$OUT/$v-icount.txt"; then
    grep -v '^c_bench_tags' "$OUT/$v.txt" || true
    echo "C CHECK FAILED: $v.elf: wrong result, fault or QEMU failure (see above)"
    status=1
  fi
done
echo "-- the library built as the Rust figures are (LTO, opt-level 3, -C target-cpu=cortex-m4; C -O2):"
python3 $FW/tools/c_icount.py "$OUT/c-bench.txt" "$OUT/c-bench-icount.txt" "$RUST_OUT" "$RUST_IC" \
  "$EXPECTED" --max-ratio "${C_ICOUNT_MAX_RATIO:-1.03}" || status=1
echo "-- for information, the library as step 2 builds it (cargo build: no LTO, plain target CPU):"
python3 $FW/tools/c_icount.py "$OUT/c-bench-default.txt" "$OUT/c-bench-default-icount.txt" "$RUST_OUT" \
  "$RUST_IC" "$EXPECTED" --no-gate || status=1

if [ "$status" = 0 ]; then
  echo "c: all checks passed"
else
  echo "c: FAILED"
fi
exit "$status"

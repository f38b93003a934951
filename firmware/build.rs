//! Puts memory.x where cortex-m-rt's link.x finds it.
use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").unwrap());
    // cortex-m-rt's link.x includes memory.x; on RISC-V the rustflags name memory-riscv.x
    // (riscv-rt's region aliases) before riscv-rt's link.x.
    fs::copy("memory.x", out.join("memory.x")).unwrap();
    fs::copy("memory-riscv.x", out.join("memory-riscv.x")).unwrap();
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=memory-riscv.x");
    // cortex-m-rt's `device` feature makes link.x include device.x (a PAC's weak aliases for its
    // interrupt handlers). Our table (src/vectors.rs) names DefaultHandler directly: nothing to alias.
    fs::write(
        out.join("device.x"),
        "/* interrupt vectors: src/vectors.rs */\n",
    )
    .unwrap();
    // The expected results the demo checks: src/expected.rs (committed), or the file named by
    // FIRMWARE_EXPECTED (CI regenerates it on the host from the current estimator-core).
    let expected = env::var("FIRMWARE_EXPECTED").unwrap_or_else(|_| "src/expected.rs".into());
    fs::copy(&expected, out.join("expected.rs")).unwrap();
    println!("cargo:rerun-if-env-changed=FIRMWARE_EXPECTED");
    println!("cargo:rerun-if-changed={expected}");
    println!("cargo:rerun-if-changed=build.rs");
    // Size builds link the size-first memory routines of src/mem.rs (Thumb-2 assembly: the
    // ARMv7-M and ARMv8-M Mainline cores; an ARMv6-M core keeps compiler_builtins' routines).
    println!("cargo::rustc-check-cfg=cfg(firmware_size)");
    println!("cargo:rerun-if-env-changed=OPT_LEVEL");
    let target = env::var("TARGET").unwrap_or_default();
    let thumb2 = target.starts_with("thumbv7") || target.starts_with("thumbv8m.main");
    if thumb2 && matches!(env::var("OPT_LEVEL").as_deref(), Ok("s" | "z")) {
        println!("cargo:rustc-cfg=firmware_size");
    }
}

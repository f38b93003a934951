//! Puts the target's memory map where the run-time's link.x finds it.
use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").unwrap());
    // cortex-m-rt's link.x includes memory.x: the memory map of the QEMU machine that runs the
    // target's builds (mps2-an386 for the Cortex-M4F and the M0+, whose builds are only linked;
    // mps2-an505 for the Cortex-M33). No memory.x lies in the crate's root, where the linker
    // would look first. On RISC-V the rustflags name memory-riscv.x (riscv-rt's region
    // aliases) before riscv-rt's link.x.
    let target = env::var("TARGET").unwrap_or_default();
    let memory = if target.starts_with("thumbv8m.main") {
        "memory-an505.x"
    } else {
        "memory-an386.x"
    };
    fs::copy(memory, out.join("memory.x")).unwrap();
    // The demo names the target it was built for.
    println!("cargo:rustc-env=FIRMWARE_TARGET={target}");
    fs::copy("memory-riscv.x", out.join("memory-riscv.x")).unwrap();
    println!("cargo:rustc-link-search={}", out.display());
    for file in ["memory-an386.x", "memory-an505.x", "memory-riscv.x"] {
        println!("cargo:rerun-if-changed={file}");
    }
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
    let thumb2 = target.starts_with("thumbv7") || target.starts_with("thumbv8m.main");
    if thumb2 && matches!(env::var("OPT_LEVEL").as_deref(), Ok("s" | "z")) {
        println!("cargo:rustc-cfg=firmware_size");
    }
}

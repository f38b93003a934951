//! Helpers shared by the integration tests that run the `host-sim` binary.
// Each test crate uses some of these, not all.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// `host-sim ARGS`, stdout and stderr captured.
pub fn host_sim(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(args)
        .output()
        .expect("host-sim runs")
}

/// An empty folder `host-sim-PREFIX-PID-NAME` in the system's temporary folder.
pub fn empty_dir(prefix: &str, name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("host-sim-{prefix}-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("tmp");
    d
}

/// The path as an argument.
pub fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8")
}

/// Copies a folder and everything under it.
pub fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).expect("mkdir");
    for e in std::fs::read_dir(from).expect("read_dir") {
        let e = e.expect("entry");
        let target = to.join(e.file_name());
        if e.path().is_dir() {
            copy_dir(&e.path(), &target);
        } else {
            std::fs::copy(e.path(), &target).expect("copy");
        }
    }
}

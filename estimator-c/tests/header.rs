//! `include/estimator.h` is what cbindgen generates from the source today, and it compiles as
//! strict C99.

mod common;

use common::c_compiler;
use std::path::{Path, PathBuf};
use std::process::Command;

fn crate_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn generate() -> String {
    let dir = crate_dir();
    let config = cbindgen::Config::from_file(dir.join("cbindgen.toml"))
        .unwrap_or_else(|e| panic!("cbindgen.toml: {e}"));
    let bindings = cbindgen::Builder::new()
        .with_crate(&dir)
        .with_config(config)
        .generate()
        .unwrap_or_else(|e| panic!("cbindgen failed: {e}"));
    let mut out = Vec::new();
    bindings.write(&mut out);
    String::from_utf8(out).expect("cbindgen writes UTF-8")
}

#[test]
fn header_is_up_to_date() {
    let path = crate_dir().join("include/estimator.h");
    let generated = generate();
    if std::env::var_os("ESTIMATOR_C_BLESS").is_some() {
        std::fs::write(&path, &generated).expect("write include/estimator.h");
        return;
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "estimator-c/include/estimator.h differs from what cbindgen generates from the source; \
         regenerate it with `ESTIMATOR_C_BLESS=1 cargo test -p estimator-c --test header` and \
         commit it"
    );
}

fn compile_strict(cc: &str, source: &Path, out: &Path) {
    let include = crate_dir().join("include");
    let result = Command::new(cc)
        .args([
            "-std=c99",
            "-Wall",
            "-Wextra",
            "-Werror",
            "-pedantic",
            "-c",
            "-I",
        ])
        .arg(&include)
        .arg(source)
        .arg("-o")
        .arg(out)
        .output()
        .expect("run the C compiler");
    assert!(
        result.status.success(),
        "{} does not compile as strict C99:\n{}",
        source.display(),
        String::from_utf8_lossy(&result.stderr)
    );
}

#[test]
fn header_compiles_as_strict_c99() {
    let Some(cc) = c_compiler() else { return };
    let dir = std::env::temp_dir().join(format!("estimator-c-header-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let source = dir.join("use_header.c");
    // Uses every kind of declaration, so that a type the header leaves undefined fails here.
    std::fs::write(
        &source,
        r#"#include "estimator.h"
int check(void);
int check(void) {
    est_attitude_config a;
    est_ins_config i;
    est_attitude_estimate e;
    est_ins_estimate ie;
    est_attitude_report r;
    est_ins_report ir;
    est_gnss_fix fix;
    est_error err = est_attitude_config_default(&a);
    (void)i; (void)e; (void)ie; (void)r; (void)ir; (void)fix;
    a.magnetometer_fusion = EST_FUSION_VECTOR;
    return (int)err + (int)est_api_version() + (EST_TRAVEL_FORWARD == 2 ? 0 : 1);
}
"#,
    )
    .expect("write the C file");
    compile_strict(&cc, &source, &dir.join("use_header.o"));
    let _ = std::fs::remove_dir_all(&dir);
}

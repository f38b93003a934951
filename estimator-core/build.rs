//! Sets `cfg(estimator_compact)` when the crate is built for size: at opt-level `"s"` or `"z"`,
//! or with the `compact` feature.
//!
//! Under that cfg a few hot kernels are compiled once over a run-time dimension and called,
//! instead of being specialised (inlined) for every constant size: the same source either way,
//! only the inlining differs (see `eskf::update`). Opt-level 2/3 builds keep the specialised
//! copies, which is where the instruction-count budgets are held; an opt-level `"s"` firmware
//! gets the smaller code, which is where the flash budget is held. Rust's `core` makes the same
//! choice under its `optimize_for_size` feature.
fn main() {
    println!("cargo::rustc-check-cfg=cfg(estimator_compact)");
    println!("cargo::rerun-if-env-changed=OPT_LEVEL");
    let opt = std::env::var("OPT_LEVEL").unwrap_or_default();
    let feature = std::env::var_os("CARGO_FEATURE_COMPACT").is_some();
    if feature || opt == "s" || opt == "z" {
        println!("cargo::rustc-cfg=estimator_compact");
    }
}

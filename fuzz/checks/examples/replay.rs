//! Runs one target's checks on files and prints what each breaks, for a look at a crash input
//! without the fuzzer:
//!
//! ```sh
//! cargo run --manifest-path fuzz/checks/Cargo.toml --example replay -- filters fuzz/artifacts/filters/crash-*
//! ```

use estimator_fuzz_checks::{is_known, TARGETS};

fn main() {
    let mut args = std::env::args().skip(1);
    let name = args.next().expect("usage: replay <target> <file>...");
    let run = TARGETS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, run)| *run)
        .unwrap_or_else(|| panic!("no target {name}"));
    for file in args {
        let data = std::fs::read(&file).unwrap_or_else(|e| panic!("{file}: {e}"));
        match std::panic::catch_unwind(|| run(&data)) {
            Ok(Ok(())) => println!("{file}: every promise kept"),
            Ok(Err(f)) if is_known(&f) => println!("{file}: known: {f}"),
            Ok(Err(f)) => println!("{file}: BROKEN: {f}"),
            Err(_) => println!("{file}: BROKEN: no-panic broken by {name}: see the panic above"),
        }
    }
}

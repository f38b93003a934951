//! The `host-sim` command line. The simulator itself is not written yet; until it is, this
//! binary says so and exits with a non-zero status rather than pretending to run.
fn main() {
    eprintln!(
        "host-sim: the simulator is not implemented yet; run `cargo run --release --example lie_tour` for a tour of the Lie-group core"
    );
    std::process::exit(2);
}

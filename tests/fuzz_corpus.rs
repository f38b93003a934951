//! The fuzz targets' checks (`fuzz/checks`) on every file of `fuzz/corpus/<target>/` and
//! `fuzz/regressions/<target>/`, in an ordinary `cargo test`: every file must keep every
//! promise, except the regression files listed in `fuzz/regressions/KNOWN.md`, which may break
//! the promises listed there (printed as known: findings still open, not yet failures).

use estimator_fuzz_checks::{is_known, known, Run, TARGETS};
use std::panic::{self, AssertUnwindSafe};
use std::path::{Path, PathBuf};

fn fuzz_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz")
}

/// The files of `dir`, sorted (none when it does not exist).
fn files(dir: &Path) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut files: Vec<PathBuf> = entries
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    files
}

fn target(name: &str) -> Run {
    TARGETS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, run)| *run)
        .unwrap_or_else(|| panic!("no fuzz target named {name}"))
}

/// A broken promise seen by the replay: whether `KNOWN.md` lists it, and what it is.
struct Broken {
    known: bool,
    text: String,
}

/// `Ok`, or the promise broken and how (a panic breaks `no-panic`, never a known finding).
fn replay(run: Run, file: &Path) -> Result<(), Broken> {
    let data = std::fs::read(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    match panic::catch_unwind(AssertUnwindSafe(|| run(&data))) {
        Ok(Ok(())) => Ok(()),
        Ok(Err(f)) => Err(Broken {
            known: is_known(&f),
            text: f.to_string(),
        }),
        Err(payload) => {
            let message = payload
                .downcast_ref::<&str>()
                .map(|s| (*s).to_owned())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            Err(Broken {
                known: false,
                text: format!("no-panic broken: {message}"),
            })
        }
    }
}

/// Every corpus file of `name` keeps every promise.
fn corpus(name: &str) {
    let run = target(name);
    let dir = fuzz_dir().join("corpus").join(name);
    let files = files(&dir);
    assert!(!files.is_empty(), "no corpus in {}", dir.display());
    let failures: Vec<String> = files
        .iter()
        .filter_map(|f| {
            replay(run, f)
                .err()
                .map(|b| format!("{}: {}", f.display(), b.text))
        })
        .collect();
    assert!(
        failures.is_empty(),
        "{} of {} corpus files of {name} break a promise:\n{}",
        failures.len(),
        files.len(),
        failures.join("\n")
    );
    println!("{name}: {} corpus files keep every promise", files.len());
}

#[test]
fn corpus_filters() {
    corpus("filters");
}

#[test]
fn corpus_navigator() {
    corpus("navigator");
}

#[test]
fn corpus_ins() {
    corpus("ins");
}

#[test]
fn corpus_lie() {
    corpus("lie");
}

#[test]
fn corpus_solver() {
    corpus("solver");
}

#[test]
fn corpus_dataset() {
    corpus("dataset");
}

/// Every regression file keeps every promise, or is listed in `KNOWN.md` with the promise it
/// breaks (printed, not failed).
#[test]
fn regressions() {
    let root = fuzz_dir().join("regressions");
    let mut failures = Vec::new();
    let mut count = 0;
    for (name, run) in TARGETS {
        for file in files(&root.join(name)) {
            count += 1;
            let id = format!(
                "{name}/{}",
                file.file_name().unwrap_or_default().to_string_lossy()
            );
            let listed = known().iter().find(|k| k.file == id);
            match (replay(run, &file), listed) {
                (Ok(()), None) => {}
                (Ok(()), Some(k)) => println!(
                    "{id}: listed in KNOWN.md as breaking {} in {}, but keeps every promise now (fixed: take it out of KNOWN.md)",
                    k.promise, k.call
                ),
                (Err(b), Some(_)) if b.known => {
                    println!("{id}: known finding, still open: {}", b.text);
                }
                (Err(b), _) => failures.push(format!("{id}: {}", b.text)),
            }
        }
    }
    for k in known() {
        if !root.join(&k.file).is_file() {
            failures.push(format!("KNOWN.md lists {}, which does not exist", k.file));
        }
    }
    assert!(count > 0, "no regression files under {}", root.display());
    assert!(
        failures.is_empty(),
        "regression inputs break a promise:\n{}",
        failures.join("\n")
    );
}

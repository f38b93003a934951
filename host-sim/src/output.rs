//! Output folders: host-sim never deletes or overwrites anything it did not create.
//!
//! Every command that writes a folder writes it first into a fresh folder beside the target
//! (`.NAME.host-sim-partial-PID`) and moves it into place only when the run succeeded; a failed
//! run leaves the target as it was and removes only its own partial folder. Each output folder
//! holds a marker file, [`MARKER`], so that a later run can tell a previous host-sim output from
//! a user's folder:
//!
//! | the target | without `--force` | with `--force` |
//! |---|---|---|
//! | absent, or an empty folder | written | written |
//! | a previous host-sim output (holds the marker) | refused | replaced |
//! | anything else (a file, a folder with other files) | refused | refused |
//! | the current folder or one that contains it | refused | refused |

use std::fmt;
use std::path::{Path, PathBuf};

/// The file that marks a folder as written by host-sim.
pub const MARKER: &str = ".host-sim-output";

/// Why an output folder cannot be written.
#[derive(Debug)]
pub enum OutputError {
    /// The target is the current folder or contains it.
    HoldsCurrentFolder(PathBuf),
    /// The target exists and is not a folder.
    NotAFolder(PathBuf),
    /// The target is a non-empty folder that host-sim did not write.
    Foreign(PathBuf),
    /// The target is a previous host-sim output and `--force` was not given.
    Previous(PathBuf),
    /// A file-system operation failed.
    Io(PathBuf, std::io::Error),
}

impl fmt::Display for OutputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::HoldsCurrentFolder(p) => write!(
                f,
                "{}: refusing to write into the current folder or one that contains it; name a new folder with --out",
                p.display()
            ),
            Self::NotAFolder(p) => write!(f, "{}: exists and is not a folder", p.display()),
            Self::Foreign(p) => write!(
                f,
                "{}: is a folder with files host-sim did not write; name a new or empty folder with --out (nothing was changed)",
                p.display()
            ),
            Self::Previous(p) => write!(
                f,
                "{}: holds an earlier host-sim output; pass --force to replace it, or name another folder with --out",
                p.display()
            ),
            Self::Io(p, e) => write!(f, "{}: {e}", p.display()),
        }
    }
}

impl std::error::Error for OutputError {}

/// An output being written: a fresh folder beside the target, moved into place by
/// [`Staging::commit`], removed if dropped before.
#[derive(Debug)]
pub struct Staging {
    target: PathBuf,
    tmp: PathBuf,
    committed: bool,
}

/// What is at `path` now.
enum Existing {
    Nothing,
    EmptyFolder,
    PreviousOutput,
    Other,
}

fn existing(path: &Path) -> Result<Existing, OutputError> {
    let io = |e| OutputError::Io(path.to_path_buf(), e);
    match std::fs::symlink_metadata(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(Existing::Nothing),
        Err(e) => Err(io(e)),
        Ok(m) if !m.is_dir() => Err(OutputError::NotAFolder(path.to_path_buf())),
        Ok(_) => {
            if path.join(MARKER).is_file() {
                return Ok(Existing::PreviousOutput);
            }
            let mut entries = std::fs::read_dir(path).map_err(io)?;
            Ok(if entries.next().is_none() {
                Existing::EmptyFolder
            } else {
                Existing::Other
            })
        }
    }
}

impl Staging {
    /// Checks `target` (see the module docs) and creates the partial folder beside it, with
    /// the marker naming `what` wrote it.
    ///
    /// # Errors
    /// When the target may not be written, or the partial folder cannot be created.
    pub fn new(target: &Path, force: bool, what: &str) -> Result<Self, OutputError> {
        let io = |p: &Path| {
            let p = p.to_path_buf();
            move |e| OutputError::Io(p, e)
        };
        let cwd = std::env::current_dir().map_err(io(Path::new(".")))?;
        let absolute = cwd.join(target);
        let name = match (absolute.file_name(), target.components().next_back()) {
            (Some(n), Some(std::path::Component::Normal(_))) => n.to_owned(),
            _ => return Err(OutputError::HoldsCurrentFolder(target.to_path_buf())),
        };
        if let Ok(real) = absolute.canonicalize() {
            if cwd.starts_with(&real) {
                return Err(OutputError::HoldsCurrentFolder(target.to_path_buf()));
            }
        }
        match existing(target)? {
            Existing::Nothing | Existing::EmptyFolder => {}
            Existing::PreviousOutput if force => {}
            Existing::PreviousOutput => return Err(OutputError::Previous(target.to_path_buf())),
            Existing::Other => return Err(OutputError::Foreign(target.to_path_buf())),
        }
        let parent = absolute.parent().unwrap_or(&cwd).to_path_buf();
        std::fs::create_dir_all(&parent).map_err(io(&parent))?;
        let tmp = parent.join(format!(
            ".{}.host-sim-partial-{}",
            name.to_string_lossy(),
            std::process::id()
        ));
        std::fs::create_dir(&tmp).map_err(io(&tmp))?;
        let staging = Self {
            target: target.to_path_buf(),
            tmp,
            committed: false,
        };
        std::fs::write(
            staging.tmp.join(MARKER),
            format!("written by host-sim {what}\n"),
        )
        .map_err(io(&staging.tmp))?;
        Ok(staging)
    }

    /// The folder to write into.
    #[must_use]
    pub fn dir(&self) -> &Path {
        &self.tmp
    }

    /// Moves the finished output into place: the target, if it is an empty folder or a previous
    /// host-sim output (checked again now), is moved aside, the new output renamed onto it, and
    /// only then the old one removed.
    ///
    /// # Errors
    /// When the target changed since [`Staging::new`] into something host-sim may not replace,
    /// or a rename fails (the target is then as it was).
    pub fn commit(mut self) -> Result<(), OutputError> {
        let target = self.target.clone();
        let io = |e| OutputError::Io(target.clone(), e);
        match existing(&target)? {
            Existing::Nothing => std::fs::rename(&self.tmp, &target).map_err(io)?,
            Existing::Other => return Err(OutputError::Foreign(target.clone())),
            state @ (Existing::EmptyFolder | Existing::PreviousOutput) => {
                let old = self.tmp.with_file_name(
                    self.tmp
                        .file_name()
                        .map(|n| n.to_string_lossy().replace("partial", "old"))
                        .unwrap_or_default(),
                );
                std::fs::rename(&target, &old).map_err(io)?;
                if let Err(e) = std::fs::rename(&self.tmp, &target) {
                    let _ = std::fs::rename(&old, &target);
                    return Err(io(e));
                }
                // The old folder is empty, or holds a previous host-sim output.
                let removed = match state {
                    Existing::EmptyFolder => std::fs::remove_dir(&old),
                    _ => std::fs::remove_dir_all(&old),
                };
                removed.map_err(io)?;
            }
        }
        self.committed = true;
        Ok(())
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        if !self.committed {
            // Only the partial folder this run created.
            let _ = std::fs::remove_dir_all(&self.tmp);
        }
    }
}

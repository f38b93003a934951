//! Output folders: host-sim never deletes or overwrites anything it did not create.
//!
//! Every command that writes a folder writes it first into a fresh folder beside the target
//! (`.NAME.host-sim-partial-PID`) and moves it into place only when the run succeeded; a failed
//! run leaves the target as it was and removes only its own partial folder.
//!
//! Each output folder holds a manifest, [`MARKER`]: the command that wrote it and every file of
//! that output with its size and content hash. A later run tells its own files from a user's by
//! it, and `--force` replaces only those:
//!
//! | the target | without `--force` | with `--force` |
//! |---|---|---|
//! | absent, or an empty folder | written | written |
//! | a previous host-sim output (holds the manifest) | refused | its listed files replaced; every other file or folder inside kept as it is |
//! | a previous output whose listed file was changed since, or where a file of the user's stands where the new output writes | refused | refused, naming the file; nothing changed |
//! | an output of a host-sim that wrote no file list | refused | refused: its files cannot be told from the user's |
//! | anything else (a file, a folder with other files) | refused | refused |
//! | the current folder or one that contains it | refused | refused |
//!
//! So outputs may nest: `out/` from `host-sim run` and `out/car/` from `host-sim replay … --out
//! out/car` are two outputs, and `host-sim run --force` replaces the files of `out/` and keeps
//! `out/car/` (to `out/`'s manifest it is a folder of someone else's), as it keeps a `NOTES.md`
//! a user put beside them.
//!
//! The replacement moves the previous output's listed files aside (into
//! `.NAME.host-sim-old-PID` beside the target), moves the new files in, and only then removes
//! the old ones; if a move fails, what was moved is moved back. Folders the previous output
//! created are removed only when they are left empty.
//!
//! The content hash is 64-bit FNV-1a (Fowler, Noll, Vo), a check against edits, not a
//! cryptographic one.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt;
use std::io::Read as _;
use std::path::{Component, Path, PathBuf};

/// The manifest that marks a folder as written by host-sim and lists its files.
pub const MARKER: &str = ".host-sim-output";

/// The manifest line before the file list; a marker without it comes from a host-sim that did
/// not list its files.
const FILES_HEADER: &str = "# files (size in bytes, FNV-1a 64 of the content, path):";

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
    /// The target is an output of a host-sim that did not list its files.
    Unlisted(PathBuf),
    /// A file the previous output listed was changed (or replaced by a folder) since.
    Modified(PathBuf),
    /// A file or folder of the user's stands where the new output writes.
    InTheWay(PathBuf),
    /// The manifest cannot be read.
    BadManifest(PathBuf, String),
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
                "{}: holds an earlier host-sim output; pass --force to replace its files (any other file in it is kept), or name another folder with --out",
                p.display()
            ),
            Self::Unlisted(p) => write!(
                f,
                "{}: holds an output of an earlier host-sim version that did not list its files, so they cannot be told from yours; move or remove the folder yourself, or name another folder with --out (nothing was changed)",
                p.display()
            ),
            Self::Modified(p) => write!(
                f,
                "{}: was changed since host-sim wrote it; --force replaces only host-sim's own unchanged files: move it away, or name another folder with --out (nothing was changed)",
                p.display()
            ),
            Self::InTheWay(p) => write!(
                f,
                "{}: host-sim did not write this, and the new output would write here; move it away, or name another folder with --out (nothing was changed)",
                p.display()
            ),
            Self::BadManifest(p, why) => write!(
                f,
                "{}: not a manifest host-sim can read ({why}); nothing was changed",
                p.display()
            ),
            Self::Io(p, e) => write!(f, "{}: {e}", p.display()),
        }
    }
}

impl std::error::Error for OutputError {}

/// One file of an output, as its manifest lists it.
#[derive(Clone, Debug, PartialEq, Eq)]
struct Listed {
    size: u64,
    hash: u64,
}

/// 64-bit FNV-1a of a file's content, with its size.
fn fingerprint(path: &Path) -> std::io::Result<Listed> {
    const OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
    const PRIME: u64 = 0x0100_0000_01b3;
    let mut file = std::fs::File::open(path)?;
    let mut buf = vec![0u8; 1 << 16];
    let (mut hash, mut size) = (OFFSET, 0u64);
    loop {
        let n = file.read(&mut buf)?;
        if n == 0 {
            return Ok(Listed { size, hash });
        }
        for &b in buf.get(..n).unwrap_or_default() {
            hash = (hash ^ u64::from(b)).wrapping_mul(PRIME);
        }
        size += n as u64;
    }
}

/// A relative path written with `/` whatever the platform, as the manifest holds it.
fn manifest_path(rel: &Path) -> Option<String> {
    let parts: Option<Vec<&str>> = rel
        .components()
        .map(|c| match c {
            Component::Normal(s) => s.to_str(),
            _ => None,
        })
        .collect();
    parts.map(|p| p.join("/"))
}

/// The manifest's relative path back into a path, refusing anything that leaves the folder.
fn listed_path(text: &str) -> Option<PathBuf> {
    let path = PathBuf::from(text);
    let normal = path.components().all(|c| matches!(c, Component::Normal(_)));
    (normal && !text.is_empty()).then_some(path)
}

/// Every regular file under `dir` (relative paths, the manifest excluded); symbolic links and
/// other non-regular entries are listed too, as files, so that they are never taken for folders.
fn walk(dir: &Path) -> Result<Vec<PathBuf>, OutputError> {
    let mut files = Vec::new();
    let mut stack = vec![PathBuf::new()];
    while let Some(rel) = stack.pop() {
        let here = dir.join(&rel);
        let entries = std::fs::read_dir(&here).map_err(|e| OutputError::Io(here.clone(), e))?;
        for entry in entries {
            let entry = entry.map_err(|e| OutputError::Io(here.clone(), e))?;
            let child = rel.join(entry.file_name());
            let kind = entry
                .file_type()
                .map_err(|e| OutputError::Io(dir.join(&child), e))?;
            if kind.is_dir() {
                stack.push(child);
            } else if child != Path::new(MARKER) {
                files.push(child);
            }
        }
    }
    files.sort();
    Ok(files)
}

/// The manifest of the output in `dir`: its first line, the command, and the file list.
fn manifest_text(what: &str, dir: &Path) -> Result<String, OutputError> {
    let mut text = format!("written by host-sim {what}\n{FILES_HEADER}\n");
    for rel in walk(dir)? {
        let path = dir.join(&rel);
        let listed = fingerprint(&path).map_err(|e| OutputError::Io(path.clone(), e))?;
        let name = manifest_path(&rel).ok_or_else(|| {
            OutputError::BadManifest(path.clone(), "a file name that is not UTF-8".into())
        })?;
        text.push_str(&format!("{}\t{:016x}\t{name}\n", listed.size, listed.hash));
    }
    Ok(text)
}

/// Reads the manifest of a previous output: its files, or [`OutputError::Unlisted`] for a
/// marker without a list.
fn read_manifest(target: &Path) -> Result<BTreeMap<PathBuf, Listed>, OutputError> {
    let path = target.join(MARKER);
    let text = std::fs::read_to_string(&path).map_err(|e| OutputError::Io(path.clone(), e))?;
    let mut lines = text.lines();
    if !lines.any(|l| l == FILES_HEADER) {
        return Err(OutputError::Unlisted(target.to_path_buf()));
    }
    let mut files = BTreeMap::new();
    for (i, line) in lines.enumerate() {
        let bad =
            |why: &str| OutputError::BadManifest(path.clone(), format!("line {}: {why}", i + 3));
        let mut fields = line.splitn(3, '\t');
        let (Some(size), Some(hash), Some(name)) = (fields.next(), fields.next(), fields.next())
        else {
            return Err(bad("expected size, hash and path separated by tabs"));
        };
        let size = size.parse().map_err(|_| bad("the size is not a number"))?;
        let hash = u64::from_str_radix(hash, 16).map_err(|_| bad("the hash is not hexadecimal"))?;
        let rel = listed_path(name).ok_or_else(|| bad("a path outside the folder"))?;
        files.insert(rel, Listed { size, hash });
    }
    Ok(files)
}

/// A previous output checked for replacement: its listed files that are still there, every one
/// unchanged, and the paths of what else the folder holds (the user's).
struct Previous {
    listed: Vec<PathBuf>,
    foreign: BTreeSet<PathBuf>,
}

/// Checks the previous output in `target` (see the module docs).
fn previous(target: &Path) -> Result<Previous, OutputError> {
    let manifest = read_manifest(target)?;
    let mut listed = Vec::new();
    for (rel, expected) in &manifest {
        let path = target.join(rel);
        match std::fs::symlink_metadata(&path) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => continue,
            Err(e) => return Err(OutputError::Io(path, e)),
            Ok(m) if !m.is_file() => return Err(OutputError::Modified(path)),
            Ok(_) => {}
        }
        let found = fingerprint(&path).map_err(|e| OutputError::Io(path.clone(), e))?;
        if &found != expected {
            return Err(OutputError::Modified(path));
        }
        listed.push(rel.clone());
    }
    let foreign = walk(target)?
        .into_iter()
        .filter(|rel| !manifest.contains_key(rel))
        .collect();
    Ok(Previous { listed, foreign })
}

/// An output being written: a fresh folder beside the target, moved into place by
/// [`Staging::commit`], removed if dropped before.
#[derive(Debug)]
pub struct Staging {
    target: PathBuf,
    tmp: PathBuf,
    what: String,
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

/// A sibling of `tmp` with `partial` in its name replaced by `kind`.
fn sibling(tmp: &Path, kind: &str) -> PathBuf {
    tmp.with_file_name(
        tmp.file_name()
            .map(|n| n.to_string_lossy().replace("partial", kind))
            .unwrap_or_default(),
    )
}

/// Moves `from/rel` to `to/rel` for each `rel`, creating the folders on the way (each created
/// folder recorded in `made`); on failure moves back what it moved and names the failure.
fn move_files(
    rels: &[PathBuf],
    from: &Path,
    to: &Path,
    made: &mut Vec<PathBuf>,
) -> Result<(), OutputError> {
    for (i, rel) in rels.iter().enumerate() {
        let (src, dst) = (from.join(rel), to.join(rel));
        let moved = make_parents(to, rel, made).and_then(|()| {
            std::fs::rename(&src, &dst).map_err(|e| OutputError::Io(dst.clone(), e))
        });
        if let Err(e) = moved {
            for back in rels.iter().take(i) {
                let _ = std::fs::rename(to.join(back), from.join(back));
            }
            return Err(e);
        }
    }
    Ok(())
}

/// Creates the folders of `root/rel`'s parent that are missing, recording each in `made`.
fn make_parents(root: &Path, rel: &Path, made: &mut Vec<PathBuf>) -> Result<(), OutputError> {
    let mut dir = root.to_path_buf();
    for part in rel.parent().into_iter().flat_map(Path::components) {
        dir.push(part);
        match std::fs::symlink_metadata(&dir) {
            Ok(m) if m.is_dir() => {}
            Ok(_) => return Err(OutputError::InTheWay(dir)),
            Err(_) => {
                std::fs::create_dir(&dir).map_err(|e| OutputError::Io(dir.clone(), e))?;
                made.push(dir.clone());
            }
        }
    }
    Ok(())
}

/// Removes the folders of `root` on the way to each of `rels` that are left empty, deepest
/// first (`remove_dir` refuses a folder that is not empty, so nothing else can go).
fn remove_empty_parents(root: &Path, rels: &[PathBuf]) {
    let mut dirs = BTreeSet::new();
    for rel in rels {
        let mut p = rel.parent();
        while let Some(d) = p.filter(|d| !d.as_os_str().is_empty()) {
            dirs.insert(d.to_path_buf());
            p = d.parent();
        }
    }
    let mut dirs: Vec<_> = dirs.into_iter().collect();
    dirs.sort_by_key(|d| std::cmp::Reverse(d.components().count()));
    for d in dirs {
        let _ = std::fs::remove_dir(root.join(d));
    }
}

impl Staging {
    /// Checks `target` (see the module docs) and creates the partial folder beside it, for an
    /// output that `what` writes.
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
            (Some(n), Some(Component::Normal(_))) => n.to_owned(),
            _ => return Err(OutputError::HoldsCurrentFolder(target.to_path_buf())),
        };
        if let Ok(real) = absolute.canonicalize() {
            if cwd.starts_with(&real) {
                return Err(OutputError::HoldsCurrentFolder(target.to_path_buf()));
            }
        }
        match existing(target)? {
            Existing::Nothing | Existing::EmptyFolder => {}
            // Checked now, so that a long run does not end in a refusal it could have known.
            Existing::PreviousOutput if force => {
                previous(target)?;
            }
            Existing::PreviousOutput => {
                return Err(match read_manifest(target) {
                    Err(e @ OutputError::Unlisted(_)) => e,
                    _ => OutputError::Previous(target.to_path_buf()),
                })
            }
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
        Ok(Self {
            target: target.to_path_buf(),
            tmp,
            what: what.to_owned(),
            committed: false,
        })
    }

    /// The folder to write into.
    #[must_use]
    pub fn dir(&self) -> &Path {
        &self.tmp
    }

    /// Writes the manifest and moves the finished output into place: onto an absent target by
    /// one rename; into an empty folder or over a previous output (checked again now) file by
    /// file, the previous output's listed files moved aside first and removed last, every other
    /// file kept (see the module docs).
    ///
    /// # Errors
    /// When the target changed since [`Staging::new`] into something host-sim may not replace,
    /// a file of the user's stands where the output writes, or a move fails (the target is then
    /// as it was).
    pub fn commit(mut self) -> Result<(), OutputError> {
        let manifest = manifest_text(&self.what, &self.tmp)?;
        let marker = self.tmp.join(MARKER);
        std::fs::write(&marker, manifest).map_err(|e| OutputError::Io(marker, e))?;
        let target = self.target.clone();
        let io = |e| OutputError::Io(target.clone(), e);
        let old = match existing(&target)? {
            Existing::Nothing => {
                std::fs::rename(&self.tmp, &target).map_err(io)?;
                self.committed = true;
                return Ok(());
            }
            Existing::Other => return Err(OutputError::Foreign(target.clone())),
            Existing::EmptyFolder => Previous {
                listed: Vec::new(),
                foreign: BTreeSet::new(),
            },
            Existing::PreviousOutput => previous(&target)?,
        };
        let mut new_files = walk(&self.tmp)?;
        new_files.push(PathBuf::from(MARKER));
        // A file of the user's where a new file goes, or on the way to one, stops the commit.
        for rel in &new_files {
            if let Some(f) = old
                .foreign
                .iter()
                .find(|f| rel.starts_with(f) || f.starts_with(rel))
            {
                return Err(OutputError::InTheWay(target.join(f)));
            }
        }
        let mut old_files = old.listed.clone();
        if target.join(MARKER).is_file() {
            old_files.push(PathBuf::from(MARKER));
        }
        let aside = sibling(&self.tmp, "old");
        std::fs::create_dir(&aside).map_err(|e| OutputError::Io(aside.clone(), e))?;
        let mut made = Vec::new();
        if let Err(e) = move_files(&old_files, &target, &aside, &mut made) {
            let _ = std::fs::remove_dir_all(&aside);
            return Err(e);
        }
        let mut made_in_target = Vec::new();
        if let Err(e) = move_files(&new_files, &self.tmp, &target, &mut made_in_target) {
            // Put the previous output back as it was.
            let _ = move_files(&old_files, &aside, &target, &mut Vec::new());
            for d in made_in_target.iter().rev() {
                let _ = std::fs::remove_dir(d);
            }
            let _ = std::fs::remove_dir_all(&aside);
            return Err(e);
        }
        self.committed = true;
        // Everything in `aside` is the previous output's own listed files.
        let _ = std::fs::remove_dir_all(&aside);
        let _ = std::fs::remove_dir_all(&self.tmp);
        remove_empty_parents(&target, &old.listed);
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

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("host-sim-output-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn write(dir: &Path, files: &[(&str, &str)]) {
        for (rel, text) in files {
            let p = dir.join(rel);
            std::fs::create_dir_all(p.parent().unwrap()).unwrap();
            std::fs::write(p, text).unwrap();
        }
    }

    /// Stages `files` for `target` and commits.
    fn output(target: &Path, force: bool, files: &[(&str, &str)]) -> Result<(), OutputError> {
        let s = Staging::new(target, force, "test")?;
        write(s.dir(), files);
        s.commit()
    }

    #[test]
    fn fnv1a_matches_its_published_test_vectors() {
        // From the FNV reference test suite (Fowler, Noll, Vo): "" and "a" and "foobar".
        let d = scratch("fnv");
        for (text, hash) in [
            ("", 0xcbf2_9ce4_8422_2325u64),
            ("a", 0xaf63_dc4c_8601_ec8c),
            ("foobar", 0x8594_4171_f739_67e8),
        ] {
            let p = d.join("f");
            std::fs::write(&p, text).unwrap();
            let l = fingerprint(&p).unwrap();
            assert_eq!((l.size, l.hash), (text.len() as u64, hash), "{text:?}");
        }
    }

    #[test]
    fn force_replaces_only_the_listed_files_and_keeps_the_users() {
        let d = scratch("keep");
        let out = d.join("out");
        output(
            &out,
            false,
            &[("a.csv", "1"), ("sub/b.csv", "2"), ("gone/c.csv", "3")],
        )
        .unwrap();
        write(
            &out,
            &[
                ("NOTES.md", "mine"),
                ("sub/mine.txt", "mine too"),
                ("nested/x", "x"),
            ],
        );
        assert!(matches!(
            output(&out, false, &[("a.csv", "9")]),
            Err(OutputError::Previous(_))
        ));
        output(&out, true, &[("a.csv", "new"), ("sub/b.csv", "new b")]).unwrap();
        let read = |r: &str| std::fs::read_to_string(out.join(r)).ok();
        assert_eq!(read("a.csv").as_deref(), Some("new"));
        assert_eq!(read("sub/b.csv").as_deref(), Some("new b"));
        assert_eq!(read("NOTES.md").as_deref(), Some("mine"));
        assert_eq!(read("sub/mine.txt").as_deref(), Some("mine too"));
        assert_eq!(read("nested/x").as_deref(), Some("x"));
        // The previous output's folder, left empty, is gone; nothing else beside the target.
        assert!(!out.join("gone").exists());
        let beside: Vec<_> = std::fs::read_dir(&d)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(beside, vec![std::ffi::OsString::from("out")]);
        // The new manifest lists the new files only.
        let listed = read_manifest(&out).unwrap();
        let names: Vec<_> = listed.keys().cloned().collect();
        assert_eq!(
            names,
            vec![PathBuf::from("a.csv"), PathBuf::from("sub/b.csv")]
        );
    }

    #[test]
    fn a_changed_listed_file_or_a_users_file_in_the_way_is_refused_and_nothing_changes() {
        let d = scratch("refuse");
        let out = d.join("out");
        output(&out, false, &[("a.csv", "1"), ("b.csv", "2")]).unwrap();
        std::fs::write(out.join("a.csv"), "edited").unwrap();
        assert!(matches!(
            output(&out, true, &[("a.csv", "new")]),
            Err(OutputError::Modified(p)) if p.ends_with("a.csv")
        ));
        assert_eq!(
            std::fs::read_to_string(out.join("a.csv")).unwrap(),
            "edited"
        );
        // Restore it; a user's file where the new output writes.
        std::fs::write(out.join("a.csv"), "1").unwrap();
        write(&out, &[("c.csv", "mine")]);
        assert!(matches!(
            output(&out, true, &[("c.csv", "new")]),
            Err(OutputError::InTheWay(p)) if p.ends_with("c.csv")
        ));
        // And a user's file where the new output needs a folder.
        assert!(matches!(
            output(&out, true, &[("c.csv/inner", "new")]),
            Err(OutputError::InTheWay(p)) if p.ends_with("c.csv")
        ));
        for (f, t) in [("a.csv", "1"), ("b.csv", "2"), ("c.csv", "mine")] {
            assert_eq!(std::fs::read_to_string(out.join(f)).unwrap(), t);
        }
        let beside: Vec<_> = std::fs::read_dir(&d)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(beside, vec![std::ffi::OsString::from("out")]);
    }

    #[test]
    fn a_marker_without_a_file_list_is_refused_even_with_force() {
        let d = scratch("legacy");
        let out = d.join("out");
        write(
            &out,
            &[(MARKER, "written by host-sim run\n"), ("a.csv", "1")],
        );
        for force in [false, true] {
            assert!(matches!(
                output(&out, force, &[("a.csv", "new")]),
                Err(OutputError::Unlisted(_))
            ));
        }
        assert_eq!(std::fs::read_to_string(out.join("a.csv")).unwrap(), "1");
    }

    #[test]
    fn a_manifest_path_that_leaves_the_folder_is_refused() {
        let d = scratch("escape");
        let out = d.join("out");
        write(
            &out,
            &[(
                MARKER,
                &format!("written by host-sim run\n{FILES_HEADER}\n1\t0\t../x\n"),
            )],
        );
        write(&d, &[("x", "y")]);
        assert!(matches!(
            output(&out, true, &[("a.csv", "new")]),
            Err(OutputError::BadManifest(..))
        ));
        assert_eq!(std::fs::read_to_string(d.join("x")).unwrap(), "y");
    }
}

//! The output-file policy of `robovec-opt`, in one place (issue 10, item 1): outputs never
//! damage what is at their path, and a run leaves all of its output files or none.
//!
//! **What is at the path decides how it is written.**
//! - *Nothing yet, or a regular file*: the bytes go to a temporary file in the same folder as
//!   the final file (`.NAME.PID.K.robovec-tmp`, created exclusively), are flushed to disk
//!   (`fsync`) and the temporary file is renamed over the path, so a reader sees the old file or
//!   the new one, never half of one. An existing file keeps its permission bits and, where the
//!   process may set them (root), its owner and group. A hard-linked file is replaced at this
//!   name only (its other names keep the old content), as editors that save by rename do.
//! - *A symbolic link* is followed (whole chain): the file it points to is what gets replaced,
//!   the link stays a link. A dangling link creates the file it names.
//! - *A read-only regular file* (no write permission bit at all) is refused with exit 1 before
//!   any work: robovec does not replace a file its owner protected (run as root, a rename would
//!   otherwise succeed silently). Make it writable or choose another path.
//! - *A character device or a FIFO* (`/dev/null`, `/dev/stdout` on a pipe, `mkfifo`) is opened
//!   for writing as it is — no temporary file, no rename, no truncation — and written directly.
//! - *A folder, a block device or a socket* is refused with exit 1 before any work (writing IR
//!   over a disk is never what was meant).
//!
//! **All or nothing.** [`OutputSet`] stages every output of a run (`-o`, `-report`,
//! `-sweep-csv`, `accuracy<worst=…>` files and `-dump-dir` dumps): phase 1 writes each
//! temporary file (dumps as the passes run, so a large model's dumps are on disk, not in
//! memory); [`OutputSet::commit`] renames them all into place (phase 2) and only then writes
//! the devices and FIFOs (phase 3, which cannot be undone). When anything fails before the
//! commit — a pass, the verifier, a write to stderr — dropping the set removes every temporary
//! file and every folder this run created (when empty), so nothing of the run is left. When a
//! rename or a direct write fails during the commit, the diagnostic names each file already
//! written. A run killed by a signal can leave `.robovec-tmp` files behind; no other file is
//! ever touched before the commit.
//!
//! **Never over a file the run reads** (issue 47): the input, the files its front end reads
//! beside it, `-eval`'s inputs, a `-target` file and the files passes read are
//! [protected](OutputSet::protect): staging a file that *is* one of them — compared by identity
//! ([`FileId`]: device and inode, so `./x`, `d/../x`, a symbolic or a hard link to it are the same
//! file) — or a folder that holds one is refused, and the run writes nothing. `robovec-opt`
//! refuses such paths before any work already (bad usage, [`crate::preflight`]); the check here
//! covers the files whose names are known only once a pass made them (`codegen<fpga;out=DIR>`,
//! `accuracy<worst=DIR>`).
//!
//! **Folders written as a whole** (`-report-dir=DIR`, [`OutputSet::stage_folder`]): the files
//! go into a temporary folder beside `DIR` (`.DIR.PID.K.robovec-tmp`), which the commit renames
//! to `DIR`, so a reader sees the old report folder or the new one, never a mix. `DIR` may be
//! missing, an empty folder, or a folder robovec wrote before (a `report.json` or a
//! `study.json`, and nothing but regular files named `*.json`, `*.md`, `*.svg`, `*.csv`,
//! `*.png`, in it or in subfolders up to two levels deep, as a study's `cases/<case>/`); an
//! existing one is renamed
//! aside first (`.DIR.PID.K.robovec-old`), then removed once the new folder is in place, or put
//! back if the rename fails. Anything else — a file, a symbolic link, a folder with other
//! content — is refused before any work (robovec never deletes what it did not write).

use std::fs::{self, File, OpenOptions};
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// How a path is written (see the module doc).
#[derive(Debug)]
enum Kind {
    /// Temporary file in `final_path`'s folder, then rename; `meta` of the file replaced.
    Replace { final_path: PathBuf, existing: Option<fs::Metadata> },
    /// Opened and written as it is (character device, FIFO).
    Direct,
}

/// Classifies `path` and checks it can be written under the policy, without touching it.
///
/// # Errors
/// A one-line message (`error: cannot write `X`: …`) when `path` is a folder, a block device, a
/// socket, a read-only file, a link loop, or its folder does not exist.
fn classify(path: &Path) -> Result<Kind, String> {
    let fail = |why: String| format!("error: cannot write `{}`: {why}", path.display());
    match fs::metadata(path) {
        Ok(m) if m.is_dir() => Err(fail("it is a folder".into())),
        Ok(m) if m.is_file() => {
            if m.permissions().readonly() {
                return Err(fail(format!(
                    "it is read-only (mode {:04o}); robovec does not replace a read-only file: make it writable or choose another path",
                    mode_of(&m)
                )));
            }
            let final_path = fs::canonicalize(path).map_err(|e| fail(e.to_string()))?;
            Ok(Kind::Replace { final_path, existing: Some(m) })
        }
        Ok(m) => match special_kind(&m) {
            Special::Writable => Ok(Kind::Direct),
            Special::Refused(what) => {
                Err(fail(format!("it is a {what}; robovec writes only files, character devices and FIFOs")))
            }
        },
        Err(e) if e.kind() == io::ErrorKind::NotFound => {
            let target = dangling_target(path).map_err(fail)?;
            let name = target.file_name().ok_or_else(|| fail("not a file name".into()))?.to_owned();
            let dir = target.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
            match fs::metadata(dir) {
                Ok(d) if d.is_dir() => {}
                Ok(_) => return Err(fail(format!("`{}` is not a folder", dir.display()))),
                Err(e) => return Err(fail(format!("folder `{}`: {e}", dir.display()))),
            }
            let dir = fs::canonicalize(dir).map_err(|e| fail(format!("folder `{}`: {e}", dir.display())))?;
            Ok(Kind::Replace { final_path: dir.join(name), existing: None })
        }
        Err(e) => Err(fail(e.to_string())),
    }
}

/// For a path that does not resolve: the path itself, or the missing file a (chain of)
/// dangling symbolic link(s) names.
fn dangling_target(path: &Path) -> Result<PathBuf, String> {
    let mut p = path.to_path_buf();
    for _ in 0..40 {
        match fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => {
                let to = fs::read_link(&p).map_err(|e| e.to_string())?;
                p = p.parent().unwrap_or(Path::new("")).join(to);
            }
            Ok(_) => return Err(format!("`{}` changed while being checked", p.display())),
            Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(p),
            Err(e) => return Err(e.to_string()),
        }
    }
    Err("too many levels of symbolic links".into())
}

/// Checks that `path` is usable as an output file (same rules as [`OutputSet::stage`]) without
/// creating or changing anything; for validating options before any work.
///
/// # Errors
/// The one-line message of the refusal.
pub fn check_file(path: &Path) -> Result<(), String> {
    classify(path).map(|_| ())
}

/// Checks that `dir` is a folder or can be created as one (its nearest existing ancestor is a
/// folder), without creating anything.
///
/// # Errors
/// A one-line message naming the obstacle.
pub fn check_folder(dir: &Path) -> Result<(), String> {
    missing_folders(dir).map(|_| ())
}

/// The folders to create for `dir` to exist, outermost last.
fn missing_folders(dir: &Path) -> Result<Vec<PathBuf>, String> {
    let fail = |why: String| format!("error: cannot create folder `{}`: {why}", dir.display());
    let mut missing = Vec::new();
    // The first error that is not "missing" (e.g. no permission), reported if no ancestor
    // explains it better.
    let mut other: Option<io::Error> = None;
    let mut p = dir;
    loop {
        match fs::metadata(p) {
            Ok(m) if m.is_dir() => return other.map_or(Ok(missing), |e| Err(fail(e.to_string()))),
            Ok(_) => return Err(fail(format!("`{}` is not a folder", p.display()))),
            Err(e) => {
                if e.kind() != io::ErrorKind::NotFound && other.is_none() {
                    other = Some(e);
                }
                missing.push(p.to_path_buf());
                match p.parent() {
                    Some(q) if !q.as_os_str().is_empty() => p = q,
                    _ => return other.map_or(Ok(missing), |e| Err(fail(e.to_string()))),
                }
            }
        }
    }
}

/// The path a regular output would finally be written to (symlinks and the folder resolved),
/// for telling whether two options name the same file; `None` for devices, FIFOs and paths
/// that are refused anyway.
pub fn identity(path: &Path) -> Option<PathBuf> {
    match classify(path) {
        Ok(Kind::Replace { final_path, .. }) => Some(final_path),
        _ => None,
    }
}

/// What names one existing file whatever the spelling of its path (`./x`, `d/../x`, a
/// symbolic link to it, a hard link): its device and inode on Unix, its canonical path
/// elsewhere. Two paths with the same `FileId` are one file.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct FileId(FileKey);

#[cfg(unix)]
type FileKey = (u64, u64);
#[cfg(not(unix))]
type FileKey = PathBuf;

/// The [`FileId`] of the file at `path` (symbolic links followed); `None` when there is none
/// (a path to create) and for folders and character devices (`/dev/null` may take any number
/// of outputs, and a device is never damaged by being written: see the module doc).
pub fn file_id(path: &Path) -> Option<FileId> {
    let m = fs::metadata(path).ok()?;
    if m.is_dir() || is_char_device(&m) {
        return None;
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        Some(FileId((m.dev(), m.ino())))
    }
    #[cfg(not(unix))]
    {
        fs::canonicalize(path).ok().map(FileId)
    }
}

/// The [`FileId`] of the regular file stdin reads, when it is one (`robovec-opt - < x.rvir`);
/// `None` for a terminal, a pipe, or where the platform cannot tell.
pub fn stdin_file_id() -> Option<FileId> {
    #[cfg(unix)]
    {
        use std::os::fd::AsFd;
        use std::os::unix::fs::MetadataExt;
        let fd = std::io::stdin().as_fd().try_clone_to_owned().ok()?;
        let m = File::from(fd).metadata().ok()?;
        m.is_file().then(|| FileId((m.dev(), m.ino())))
    }
    #[cfg(not(unix))]
    {
        None
    }
}

#[cfg(unix)]
fn is_char_device(m: &fs::Metadata) -> bool {
    use std::os::unix::fs::FileTypeExt;
    m.file_type().is_char_device()
}

#[cfg(not(unix))]
fn is_char_device(_: &fs::Metadata) -> bool {
    false
}

/// A file the run reads, which no output may replace ([`OutputSet::protect`]).
#[derive(Clone, Debug)]
pub struct ReadFile {
    /// What it is, for messages (`the input`, `-eval's inputs file`).
    pub what: String,
    /// Its path as given.
    pub path: PathBuf,
    /// Its identity (`None`: stdin that is not a regular file; then nothing to protect).
    pub id: Option<FileId>,
}

impl ReadFile {
    /// The file at `path`, read as `what`.
    pub fn new(what: impl Into<String>, path: impl Into<PathBuf>) -> ReadFile {
        let path = path.into();
        ReadFile { what: what.into(), id: file_id(&path), path }
    }

    /// The regular file on stdin, when it is one (see [`stdin_file_id`]); its path is unknown
    /// (empty).
    pub fn stdin() -> ReadFile {
        ReadFile { what: "the input (the file on stdin)".into(), path: PathBuf::new(), id: stdin_file_id() }
    }

    /// True when this file is `dir` or lies inside it (paths resolved; never for stdin).
    pub fn is_inside(&self, dir: &Path) -> bool {
        !self.path.as_os_str().is_empty()
            && crate::preflight::resolved(&self.path).starts_with(crate::preflight::resolved(dir))
    }

    /// What it is and its path, for messages (``the input `robot.urdf` ``).
    pub fn describe(&self) -> String {
        if self.path.as_os_str().is_empty() {
            self.what.clone()
        } else {
            format!("{} `{}`", self.what, self.path.display())
        }
    }
}

enum Special {
    Writable,
    Refused(&'static str),
}

#[cfg(unix)]
fn special_kind(m: &fs::Metadata) -> Special {
    use std::os::unix::fs::FileTypeExt;
    let t = m.file_type();
    if t.is_char_device() || t.is_fifo() {
        Special::Writable
    } else if t.is_block_device() {
        Special::Refused("block device")
    } else if t.is_socket() {
        Special::Refused("socket")
    } else {
        Special::Refused("special file")
    }
}

#[cfg(not(unix))]
fn special_kind(_: &fs::Metadata) -> Special {
    Special::Writable
}

#[cfg(unix)]
fn mode_of(m: &fs::Metadata) -> u32 {
    use std::os::unix::fs::PermissionsExt;
    m.permissions().mode() & 0o7777
}

#[cfg(not(unix))]
fn mode_of(_: &fs::Metadata) -> u32 {
    0o444
}

/// Gives the temporary file the owner (when permitted) and permissions of the file it replaces.
fn copy_owner_and_mode(file: &File, existing: &fs::Metadata) -> io::Result<()> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        // Only root may give a file away; for anyone else the new file is theirs, as with any
        // editor's save.
        let _ = std::os::unix::fs::fchown(file, Some(existing.uid()), Some(existing.gid()));
    }
    file.set_permissions(existing.permissions())
}

/// Checks that `dir` may be replaced as a whole by [`OutputSet::stage_folder`] (see the
/// module doc), without touching it.
///
/// # Errors
/// A one-line message naming the folder and the obstacle.
pub fn check_replaceable_folder(dir: &Path) -> Result<(), String> {
    let fail = |why: String| format!("error: cannot write folder `{}`: {why}", dir.display());
    match fs::symlink_metadata(dir) {
        Err(e) if e.kind() == io::ErrorKind::NotFound => {
            let parent = dir.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
            match fs::metadata(parent) {
                Ok(m) if m.is_dir() => Ok(()),
                Ok(_) => Err(fail(format!("`{}` is not a folder", parent.display()))),
                Err(e) => Err(fail(format!("folder `{}`: {e}", parent.display()))),
            }
        }
        Err(e) => Err(fail(e.to_string())),
        Ok(m) if m.file_type().is_symlink() => Err(fail("it is a symbolic link; give the folder it points to".into())),
        Ok(m) if !m.is_dir() => Err(fail("it exists and is not a folder".into())),
        Ok(_) => {
            let entries: Vec<fs::DirEntry> = fs::read_dir(dir)
                .map_err(|e| fail(e.to_string()))?
                .collect::<Result<_, _>>()
                .map_err(|e| fail(e.to_string()))?;
            if entries.is_empty() {
                return Ok(());
            }
            let has_marker =
                entries.iter().any(|e| FOLDER_MARKERS.iter().any(|m| e.file_name() == *m) && is_our_file(e));
            match foreign_entry(dir, FOLDER_DEPTH).map_err(|e| fail(e.to_string()))? {
                Some(name) => Err(fail(format!(
                    "it holds `{name}`, which robovec did not write; robovec replaces only an empty folder or a report folder it wrote"
                ))),
                None if !has_marker => Err(fail(
                    "it is not empty and has no report.json or study.json; robovec replaces only an empty folder or a report folder it wrote"
                        .into(),
                )),
                None => Ok(()),
            }
        }
    }
}

/// The files that mark a folder robovec wrote: `report.json` (`-report-dir`) or `study.json`
/// (`robovec-gen --study --report-dir`).
const FOLDER_MARKERS: [&str; 2] = ["report.json", "study.json"];

/// How deep a folder robovec wrote may nest (a study's `cases/<case>/` is 2).
const FOLDER_DEPTH: u32 = 2;

/// A regular file (not a link) named like the files robovec writes in a folder.
fn is_our_file(e: &fs::DirEntry) -> bool {
    let name = e.file_name().to_string_lossy().into_owned();
    e.file_type().is_ok_and(|t| t.is_file())
        && [".json", ".md", ".svg", ".csv", ".png"].iter().any(|x| name.ends_with(x))
}

/// The first entry of `dir` (relative path) that robovec would not have written: anything but
/// [`is_our_file`] files and, up to `depth` levels, folders holding only those.
fn foreign_entry(dir: &Path, depth: u32) -> io::Result<Option<String>> {
    for e in fs::read_dir(dir)? {
        let e = e?;
        let name = e.file_name().to_string_lossy().into_owned();
        if is_our_file(&e) {
            continue;
        }
        if depth > 0 && e.file_type().is_ok_and(|t| t.is_dir()) {
            if let Some(inner) = foreign_entry(&e.path(), depth - 1)? {
                return Ok(Some(format!("{name}/{inner}")));
            }
            continue;
        }
        return Ok(Some(name));
    }
    Ok(None)
}

/// A folder staged as a whole, waiting for the commit.
#[derive(Debug)]
struct StagedFolder {
    /// The path as the user gave it.
    shown: PathBuf,
    /// The temporary folder holding the new content.
    tmp: PathBuf,
}

/// One staged output waiting for the commit.
#[derive(Debug)]
struct Staged {
    /// The path as the user gave it (for messages).
    shown: PathBuf,
    /// Where the file ends up (rename target), or `None` for a direct write.
    final_path: Option<PathBuf>,
    /// The temporary file (rename targets).
    tmp: Option<PathBuf>,
    /// The bytes of a direct write.
    data: Vec<u8>,
}

/// Every output file of one run, staged until [`OutputSet::commit`]; dropping an uncommitted
/// set removes its temporary files and the folders it created (see the module doc).
#[derive(Debug, Default)]
pub struct OutputSet {
    staged: Vec<Staged>,
    protected: Vec<ReadFile>,
    folders: Vec<StagedFolder>,
    created_dirs: Vec<PathBuf>,
    counter: u32,
    committed: bool,
}

impl OutputSet {
    /// An empty set.
    pub fn new() -> OutputSet {
        OutputSet::default()
    }

    /// Protects `files` (the files the run reads): staging one of them, or a folder holding
    /// one, is refused from now on (see the module doc).
    pub fn protect(&mut self, files: impl IntoIterator<Item = ReadFile>) {
        self.protected.extend(files.into_iter().filter(|f| f.id.is_some()));
    }

    /// Checks that `path` is not a protected file ([`OutputSet::protect`]), without staging it.
    ///
    /// # Errors
    /// A one-line message naming the path and the file the run reads there.
    pub fn check_not_read(&self, path: &Path) -> Result<(), String> {
        let Some(id) = file_id(path) else { return Ok(()) };
        match self.protected.iter().find(|r| r.id.as_ref() == Some(&id)) {
            Some(r) => Err(format!(
                "error: cannot write `{}`: it is {}, which this run reads; choose another path",
                path.display(),
                r.describe()
            )),
            None => Ok(()),
        }
    }

    /// Creates `dir` and its missing ancestors, remembering the ones this run created (removed
    /// again if the run fails).
    ///
    /// # Errors
    /// A one-line message naming the folder.
    pub fn ensure_folder(&mut self, dir: &Path) -> Result<(), String> {
        let missing = missing_folders(dir)?;
        for d in missing.into_iter().rev() {
            match fs::create_dir(&d) {
                Ok(()) => self.created_dirs.push(d),
                Err(e) if e.kind() == io::ErrorKind::AlreadyExists && d.is_dir() => {}
                Err(e) => return Err(format!("error: cannot create folder `{}`: {e}", d.display())),
            }
        }
        Ok(())
    }

    /// Stages `data` for `path`: a file or a path to create gets its temporary file written now
    /// (phase 1); a device or FIFO keeps the bytes for the commit. Staging the same file again
    /// replaces the earlier bytes (the last write wins).
    ///
    /// # Errors
    /// A one-line message naming the file (refused kind of file, a file the run reads
    /// ([`OutputSet::protect`]), missing folder, I/O error).
    pub fn stage(&mut self, path: &Path, data: &[u8]) -> Result<(), String> {
        self.stage_with(path, &mut |w| w.write_all(data))
    }

    /// Like [`OutputSet::stage`] for a program: the temporary file gets the execute bits
    /// (`rwxr-xr-x` when new; an existing file's mode plus execute wherever it is readable)
    /// before the rename. A device or FIFO is written as it is.
    ///
    /// # Errors
    /// As [`OutputSet::stage`], or when the mode cannot be set.
    pub fn stage_executable(&mut self, path: &Path, data: &[u8]) -> Result<(), String> {
        self.stage(path, data)?;
        #[cfg(unix)]
        if let Some(tmp) = self.staged.last().and_then(|s| s.tmp.clone()) {
            use std::os::unix::fs::PermissionsExt;
            let fail = |e: io::Error| format!("error: cannot write `{}`: {e}", path.display());
            let mode = fs::metadata(&tmp).map_err(fail)?.permissions().mode() & 0o7777;
            let mode = if fs::metadata(path).is_ok_and(|m| m.is_file()) { mode | ((mode & 0o444) >> 2) } else { 0o755 };
            fs::set_permissions(&tmp, fs::Permissions::from_mode(mode)).map_err(fail)?;
        }
        Ok(())
    }

    /// Like [`OutputSet::stage`], with the bytes produced by `write` into the temporary file
    /// through a buffer, so a large output (the printed IR) is never held in memory whole.
    /// A device or FIFO still collects the bytes for the commit (nothing may reach it before).
    ///
    /// # Errors
    /// A one-line message naming the file (refused kind of file, missing folder, I/O error,
    /// or an error returned by `write`).
    pub fn stage_with(
        &mut self,
        path: &Path,
        write: &mut dyn FnMut(&mut dyn Write) -> io::Result<()>,
    ) -> Result<(), String> {
        let fail = |e: io::Error| format!("error: cannot write `{}`: {e}", path.display());
        self.check_not_read(path)?;
        match classify(path)? {
            Kind::Direct => {
                let mut data = Vec::new();
                write(&mut data).map_err(fail)?;
                self.staged.push(Staged { shown: path.into(), final_path: None, tmp: None, data });
                Ok(())
            }
            Kind::Replace { final_path, existing } => {
                if let Some(i) = self.staged.iter().position(|s| s.final_path.as_ref() == Some(&final_path)) {
                    let old = self.staged.remove(i);
                    if let Some(t) = old.tmp {
                        let _ = fs::remove_file(t);
                    }
                }
                let dir = final_path.parent().unwrap_or(Path::new("."));
                let name = final_path.file_name().unwrap_or_default().to_string_lossy().into_owned();
                self.counter += 1;
                let tmp = dir.join(format!(".{name}.{}.{}.robovec-tmp", std::process::id(), self.counter));
                let file = OpenOptions::new().write(true).create_new(true).open(&tmp).map_err(fail)?;
                // From here on the temporary file exists: record it so a failure removes it.
                self.staged.push(Staged {
                    shown: path.into(),
                    final_path: Some(final_path),
                    tmp: Some(tmp),
                    data: Vec::new(),
                });
                if let Some(m) = &existing {
                    copy_owner_and_mode(&file, m).map_err(fail)?;
                }
                let mut buf = io::BufWriter::with_capacity(1 << 16, file);
                write(&mut buf).map_err(fail)?;
                let file = buf.into_inner().map_err(|e| fail(e.into_error()))?;
                file.sync_all().map_err(fail)
            }
        }
    }

    /// Stages the folder `dir` as a whole with `files` (`(file name, bytes)`): they are written
    /// into a temporary folder beside `dir` now, and the commit renames it to `dir` (see the
    /// module doc).
    ///
    /// # Errors
    /// A one-line message: `dir` is not replaceable ([`check_replaceable_folder`]), holds a
    /// protected file ([`OutputSet::protect`]), or a write failed.
    pub fn stage_folder(&mut self, dir: &Path, files: &[(String, Vec<u8>)]) -> Result<(), String> {
        check_replaceable_folder(dir)?;
        if let Some(r) = self.protected.iter().find(|r| r.is_inside(dir)) {
            return Err(format!(
                "error: cannot write folder `{}`: it holds {}, which this run reads; choose another folder",
                dir.display(),
                r.describe()
            ));
        }
        let fail = |e: io::Error| format!("error: cannot write folder `{}`: {e}", dir.display());
        let parent = dir.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
        let name = dir.file_name().ok_or_else(|| fail(io::Error::other("not a folder name")))?.to_string_lossy();
        self.counter += 1;
        let tmp = parent.join(format!(".{name}.{}.{}.robovec-tmp", std::process::id(), self.counter));
        fs::create_dir(&tmp).map_err(fail)?;
        self.folders.push(StagedFolder { shown: dir.into(), tmp: tmp.clone() });
        for (file, bytes) in files {
            // A name may hold subfolders (`cases/23-serial/report.json`), never `..` or a root.
            let rel = Path::new(file);
            if !rel.components().all(|c| matches!(c, std::path::Component::Normal(_))) {
                return Err(fail(io::Error::other(format!("bad file name `{file}` in the folder"))));
            }
            if let Some(sub) = rel.parent().filter(|p| !p.as_os_str().is_empty()) {
                fs::create_dir_all(tmp.join(sub)).map_err(fail)?;
            }
            let mut f = OpenOptions::new().write(true).create_new(true).open(tmp.join(file)).map_err(fail)?;
            f.write_all(bytes).and_then(|()| f.sync_all()).map_err(fail)?;
        }
        Ok(())
    }

    /// Renames a staged folder into place (see the module doc); an existing report folder is
    /// moved aside first and removed after.
    fn commit_folder(&mut self, s: &StagedFolder) -> Result<(), String> {
        let fail = |e: io::Error| format!("error: cannot write folder `{}`: {e}", s.shown.display());
        // Checked again: the folder may have changed since the preflight.
        check_replaceable_folder(&s.shown)?;
        let old = match fs::symlink_metadata(&s.shown) {
            Ok(_) => {
                self.counter += 1;
                let parent = s.tmp.parent().unwrap_or(Path::new("."));
                let name = s.shown.file_name().unwrap_or_default().to_string_lossy().into_owned();
                let old = parent.join(format!(".{name}.{}.{}.robovec-old", std::process::id(), self.counter));
                fs::rename(&s.shown, &old).map_err(fail)?;
                Some(old)
            }
            Err(_) => None,
        };
        if let Err(e) = fs::rename(&s.tmp, &s.shown) {
            if let Some(old) = &old {
                let _ = fs::rename(old, &s.shown);
            }
            return Err(fail(e));
        }
        if let Some(old) = old {
            // Only files robovec wrote are in it (checked above); `remove_dir_all` never follows
            // a symbolic link.
            let _ = fs::remove_dir_all(&old);
        }
        Ok(())
    }

    /// Puts every staged output in place: renames all temporary files and folders (phase 2),
    /// then writes the devices and FIFOs (phase 3). Returns the paths written, in order.
    ///
    /// # Errors
    /// A one-line message naming the file that failed and each file already written.
    pub fn commit(mut self) -> Result<Vec<PathBuf>, String> {
        self.committed = true;
        let staged = std::mem::take(&mut self.staged);
        let (renames, directs): (Vec<Staged>, Vec<Staged>) = staged.into_iter().partition(|s| s.tmp.is_some());
        let mut done: Vec<PathBuf> = Vec::new();
        let already = |done: &[PathBuf]| {
            if done.is_empty() {
                "; no file was written".to_string()
            } else {
                let names: Vec<String> = done.iter().map(|p| format!("`{}`", p.display())).collect();
                format!("; already written: {}", names.join(", "))
            }
        };
        for (i, s) in renames.iter().enumerate() {
            let (Some(tmp), Some(fin)) = (&s.tmp, &s.final_path) else { continue };
            if let Err(e) = fs::rename(tmp, fin) {
                for rest in &renames[i..] {
                    if let Some(t) = &rest.tmp {
                        let _ = fs::remove_file(t);
                    }
                }
                return Err(format!("error: cannot write `{}`: {e}{}", s.shown.display(), already(&done)));
            }
            done.push(s.shown.clone());
        }
        let folders = std::mem::take(&mut self.folders);
        for (i, f) in folders.iter().enumerate() {
            if let Err(e) = self.commit_folder(f) {
                for rest in &folders[i..] {
                    let _ = fs::remove_dir_all(&rest.tmp);
                }
                return Err(format!("{e}{}", already(&done)));
            }
            done.push(f.shown.clone());
        }
        for s in &directs {
            let r = OpenOptions::new()
                .write(true)
                .open(&s.shown)
                .and_then(|mut f| f.write_all(&s.data).and_then(|()| f.flush()));
            if let Err(e) = r {
                return Err(format!("error: cannot write `{}`: {e}{}", s.shown.display(), already(&done)));
            }
            done.push(s.shown.clone());
        }
        Ok(done)
    }
}

impl Drop for OutputSet {
    fn drop(&mut self) {
        if self.committed {
            return;
        }
        for s in &self.staged {
            if let Some(t) = &s.tmp {
                let _ = fs::remove_file(t);
            }
        }
        for f in &self.folders {
            // The temporary folder is this run's own.
            let _ = fs::remove_dir_all(&f.tmp);
        }
        // Innermost first; `remove_dir` leaves a folder that is not empty.
        for d in self.created_dirs.iter().rev() {
            let _ = fs::remove_dir(d);
        }
    }
}

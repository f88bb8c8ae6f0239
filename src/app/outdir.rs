//! A run's claim on its output directory: a lock, so that two runs never write into one
//! directory at once, and a manifest of the files the run writes, so that the next run
//! removes them and nothing else.
//!
//! - **Lock.** `.mecano-lock` in the directory, held with `flock(2)` (`LOCK_EX | LOCK_NB`)
//!   for the whole run or restart. The kernel releases it when the process ends, however
//!   it ends (a crash, SIGKILL), so a lock is never left stuck; the file itself stays,
//!   empty (a run's directory is the same, byte for byte, however often it was resumed).
//!   It is opened without following links: a `.mecano-lock` that is a link (dangling or
//!   not) is refused, and nothing is created where it points.
//! - **Manifest.** `.mecano-manifest`: one plain name per line of every file this run may
//!   write in the directory (histories, `summary.json`, the checkpoint, the VTK
//!   collection), and `vtk/` for the run's frames. It is written before the first of them.
//!   A fresh run removes the *regular files* the previous run's manifest names (never
//!   through a link, never in a subdirectory: an entry with a `/`, `..` or an absolute
//!   path is ignored; a listed name that is a link or a directory is left alone), and
//!   refuses a directory holding files of anyone else unless `--force` is given (they are
//!   then left where they are; subdirectories, e.g. `study/`, are never touched nor
//!   counted). A name the run writes that is held by a link, a directory, a FIFO or a
//!   foreign file is refused, `--force` or not: no file is written over that the previous
//!   run's manifest does not name. `resume` takes the lock and removes nothing.
//! - Every file of the directory is then opened through [`crate::safe_file`]
//!   (`O_NOFOLLOW`, regular files only).
//!
//! Every refusal is bad input (exit code 2): an output path that is a file, `/dev/null`,
//! below a file, not creatable, a directory in use, holding foreign files, or a name of
//! the run taken.

use crate::safe_file;
use std::fs::{self, File};
use std::io;
use std::os::fd::AsRawFd;
use std::path::{Path, PathBuf};

/// Name of the lock file in an output directory.
pub const LOCK_NAME: &str = ".mecano-lock";
/// Name of the manifest in an output directory.
pub const MANIFEST_NAME: &str = ".mecano-manifest";
/// First line of a manifest (its format).
const MANIFEST_HEADER: &str =
    "# mecano-rs output manifest v1: files written by the run in this directory";
/// A manifest entry ending with `/`: a directory of the run whose `frame_*.vtu` it writes.
const VTK_DIR: &str = "vtk/";

/// Why an output directory cannot be used (each one is bad input, exit code 2).
#[derive(Debug, thiserror::Error)]
pub enum OutDirError {
    /// The path exists and is not a directory (a file, `/dev/null`).
    #[error("the output path {0} exists and is not a directory")]
    NotADirectory(PathBuf),
    /// The directory cannot be created or opened (below a file, no permission).
    #[error("the output directory {path} cannot be used: {reason}")]
    Unusable {
        /// The directory.
        path: PathBuf,
        /// The system's reason.
        reason: String,
    },
    /// Another run holds the directory's lock.
    #[error(
        "the output directory {path} is in use by another mecano-rs run (it holds {path}/.mecano-lock): two runs never write into one directory; wait for it to end, or choose another with -o"
    )]
    Busy {
        /// The directory.
        path: PathBuf,
    },
    /// Files not written by a run of this program.
    #[error(
        "the output directory {path} holds files no mecano-rs run wrote there ({list}): a run owns its directory; choose an empty one with -o, or give --force to run there anyway (those files are left as they are)"
    )]
    Foreign {
        /// The directory.
        path: PathBuf,
        /// The first few names, comma separated.
        list: String,
    },
    /// A name the run writes is held by something it must not write over or through.
    #[error(
        "the output directory {path} cannot be used: {why}; a run writes only regular files of its directory that no one else wrote (--force leaves foreign files alone, so it cannot write over them): remove it, or choose another directory with -o"
    )]
    Taken {
        /// The directory.
        path: PathBuf,
        /// What holds the name.
        why: String,
    },
}

/// A claimed output directory: holds the lock until dropped.
#[derive(Debug)]
pub struct OutDir {
    _lock: File,
    dir: PathBuf,
}

fn unusable(dir: &Path, e: &io::Error) -> OutDirError {
    OutDirError::Unusable {
        path: dir.to_path_buf(),
        reason: e.to_string(),
    }
}

/// Largest manifest read, bytes (a run selecting 300,000 files lists some 6 MB).
const MAX_MANIFEST_BYTES: u64 = 64 << 20;

impl OutDir {
    /// Takes the lock of an existing directory (a restart): nothing is removed.
    pub fn lock_existing(dir: &Path) -> Result<Self, OutDirError> {
        if dir.exists() && !dir.is_dir() {
            return Err(OutDirError::NotADirectory(dir.to_path_buf()));
        }
        let lock = lock(dir)?;
        Ok(OutDir {
            _lock: lock,
            dir: dir.to_path_buf(),
        })
    }

    /// Claims `dir` for a fresh run that will write `files` (paths relative to `dir`):
    /// creates it, takes its lock, refuses it when it holds files the previous run's
    /// manifest does not list (unless `force`), or when a name this run writes is taken by
    /// anything but a regular file the previous run wrote (a link, a directory, a foreign
    /// file: also with `force`); removes the regular files the manifest lists, and writes
    /// the new manifest.
    pub fn claim_fresh(dir: &Path, files: &[String], force: bool) -> Result<Self, OutDirError> {
        if dir.exists() && !dir.is_dir() {
            return Err(OutDirError::NotADirectory(dir.to_path_buf()));
        }
        // Refused before anything is written into it (not even the lock file); checked
        // again under the lock, which another run may have held meanwhile. A run starting
        // at the same moment may have written files its manifest (not yet read here)
        // lists: then the lock is held, and the directory is in use, not foreign.
        if dir.is_dir() && !force && refuse_foreign(dir).is_err() {
            if held_by_another(dir) {
                return Err(OutDirError::Busy {
                    path: dir.to_path_buf(),
                });
            }
            // Read again: a run that ended meanwhile has its manifest in place now.
            refuse_foreign(dir)?;
        }
        fs::create_dir_all(dir).map_err(|e| unusable(dir, &e))?;
        let lock = lock(dir)?;
        let old = if force {
            read_manifest(dir).map_err(|e| unusable(dir, &e))?
        } else {
            refuse_foreign(dir)?
        };
        refuse_taken(dir, files, &old)?;
        for entry in &old {
            remove_entry(dir, entry).map_err(|e| unusable(dir, &e))?;
        }
        write_manifest(dir, files).map_err(|e| unusable(dir, &e))?;
        Ok(OutDir {
            _lock: lock,
            dir: dir.to_path_buf(),
        })
    }

    /// The directory.
    pub fn path(&self) -> &Path {
        &self.dir
    }
}

/// The previous run's manifest, or the refusal of a directory holding other files.
fn refuse_foreign(dir: &Path) -> Result<Vec<String>, OutDirError> {
    let old = read_manifest(dir).map_err(|e| unusable(dir, &e))?;
    let foreign = foreign_files(dir, &old).map_err(|e| unusable(dir, &e))?;
    if foreign.is_empty() {
        return Ok(old);
    }
    let mut list: Vec<String> = foreign
        .iter()
        .take(5)
        .map(|n| crate::deck::short(n))
        .collect();
    if foreign.len() > 5 {
        list.push(format!("and {} more", foreign.len() - 5));
    }
    Err(OutDirError::Foreign {
        path: dir.to_path_buf(),
        list: list.join(", "),
    })
}

/// The names this run writes that something other than a regular file of the previous
/// run holds: a link (dangling or not), a directory, a FIFO, or a file the previous run's
/// manifest does not list (which `--force` leaves alone, so it cannot be written over).
/// `vtk/` must be a real directory the previous run wrote, its frames regular files.
fn refuse_taken(dir: &Path, files: &[String], old: &[String]) -> Result<(), OutDirError> {
    let taken = |why: String| {
        Err(OutDirError::Taken {
            path: dir.to_path_buf(),
            why,
        })
    };
    for f in files {
        if f == VTK_DIR {
            let sub = dir.join(VTK_DIR.trim_end_matches('/'));
            if let Some(kind) = safe_file::non_regular_kind(&sub)
                && kind != "a directory"
            {
                return taken(format!("vtk is {kind}"));
            }
            if sub.is_dir() && !old.iter().any(|o| o == VTK_DIR) {
                return taken("vtk/ is a directory no mecano-rs run wrote".into());
            }
            if sub.is_dir() {
                for e in fs::read_dir(&sub).map_err(|e| unusable(dir, &e))? {
                    let e = e.map_err(|e| unusable(dir, &e))?;
                    let name = e.file_name().to_string_lossy().into_owned();
                    let ft = e.file_type().map_err(|e| unusable(dir, &e))?;
                    if is_frame(&name) && !ft.is_file() {
                        return taken(format!(
                            "vtk/{} is not a regular file",
                            crate::deck::short(&name)
                        ));
                    }
                }
            }
            continue;
        }
        let p = dir.join(f);
        if let Some(kind) = safe_file::non_regular_kind(&p) {
            return taken(format!("{f} is {kind}"));
        }
        if p.is_file() && !old.contains(f) {
            return taken(format!(
                "{f} is a file no mecano-rs run wrote (its manifest does not list it), and this run would write over it"
            ));
        }
    }
    Ok(())
}

/// Whether another process holds the lock of `dir` (its lock file exists and cannot be
/// locked now). Takes and drops the lock when free; creates nothing.
fn held_by_another(dir: &Path) -> bool {
    let Ok(file) = safe_file::read_write(&dir.join(LOCK_NAME)) else {
        return false;
    };
    // SAFETY: flock(2) on a descriptor this `File` owns; no memory is shared.
    let rc = unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) };
    rc != 0 && io::Error::last_os_error().raw_os_error() == Some(libc::EWOULDBLOCK)
}

/// Opens (creating) the lock file and takes an exclusive, non-blocking `flock`. Never
/// through a link: a `.mecano-lock` that is a link (dangling or not), a FIFO or a
/// directory is refused, and nothing is created where a link points.
fn lock(dir: &Path) -> Result<File, OutDirError> {
    let path = dir.join(LOCK_NAME);
    let file = safe_file::open_or_create(&path).map_err(|e| unusable(dir, &e))?;
    // SAFETY: flock(2) on a descriptor this `File` owns; no memory is shared.
    let rc = unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) };
    if rc != 0 {
        let e = io::Error::last_os_error();
        if e.raw_os_error() == Some(libc::EWOULDBLOCK) {
            return Err(OutDirError::Busy {
                path: dir.to_path_buf(),
            });
        }
        return Err(unusable(dir, &e));
    }
    Ok(file)
}

/// Whether a manifest entry may name something the run wrote: a plain name of the
/// directory (one component, not `.` or `..`, not the lock or the manifest), or `vtk/`.
/// Anything else (`sub/victim.txt`, `/etc/passwd`, `../x`) is dropped: a manifest never
/// removes anything outside its directory, nor in a subdirectory of it.
fn plain_entry(line: &str) -> bool {
    if line == VTK_DIR {
        return true;
    }
    let mut parts = Path::new(line).components();
    matches!(
        (parts.next(), parts.next()),
        (Some(std::path::Component::Normal(_)), None)
    ) && !line.contains('/')
        && line != LOCK_NAME
        && line != MANIFEST_NAME
}

/// The entries of the manifest in `dir` (empty when there is none), plain names only
/// ([`plain_entry`]). The manifest is read only as a regular file of the directory, and
/// only up to [`MAX_MANIFEST_BYTES`].
fn read_manifest(dir: &Path) -> io::Result<Vec<String>> {
    let path = dir.join(MANIFEST_NAME);
    if fs::symlink_metadata(&path).is_err_and(|e| e.kind() == io::ErrorKind::NotFound) {
        return Ok(Vec::new());
    }
    let bytes = safe_file::read_bounded(&path, MAX_MANIFEST_BYTES)?;
    let text = String::from_utf8_lossy(&bytes);
    Ok(text
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
        .filter(|l| plain_entry(l))
        .map(str::to_string)
        .collect())
}

/// Written to a temporary file, then renamed: a crash leaves the old or the new one.
fn write_manifest(dir: &Path, files: &[String]) -> io::Result<()> {
    let mut text = String::from(MANIFEST_HEADER);
    text.push('\n');
    for f in files {
        text.push_str(f);
        text.push('\n');
    }
    let tmp = dir.join(format!("{MANIFEST_NAME}.tmp"));
    safe_file::write_atomic(&tmp, &dir.join(MANIFEST_NAME), text.as_bytes())
}

/// Names of the entries at the top of `dir` other than directories (regular files,
/// links — to directories too —, FIFOs) that neither the manifest `old` lists nor this
/// module keeps. Real subdirectories do not count.
fn foreign_files(dir: &Path, old: &[String]) -> io::Result<Vec<String>> {
    let mut out = Vec::new();
    for entry in fs::read_dir(dir)? {
        let entry = entry?;
        if entry.file_type()?.is_dir() {
            continue;
        }
        let name = entry.file_name().to_string_lossy().into_owned();
        let ours = name == LOCK_NAME
            || name == MANIFEST_NAME
            || name == format!("{MANIFEST_NAME}.tmp")
            || old.contains(&name);
        if !ours {
            out.push(name);
        }
    }
    out.sort();
    Ok(out)
}

/// A name a run writes in `vtk/`: a run's frame `frame_*.vtu`, a modal analysis's
/// `mode_*.vtu` frame or `mode_*.pvd` series.
fn is_frame(name: &str) -> bool {
    (name.starts_with("frame_") && name.ends_with(".vtu"))
        || (name.starts_with("mode_") && (name.ends_with(".vtu") || name.ends_with(".pvd")))
}

/// Removes one manifest entry: a regular file of the directory (missing is fine; a link,
/// a directory or anything else by that name is left alone), or for `vtk/` — only when it
/// is a real directory — the regular `frame_*.vtu` files in it and the directory once
/// empty.
fn remove_entry(dir: &Path, entry: &str) -> io::Result<()> {
    if entry == VTK_DIR {
        let sub = dir.join(VTK_DIR.trim_end_matches('/'));
        let is_real_dir = fs::symlink_metadata(&sub).is_ok_and(|m| m.file_type().is_dir());
        if !is_real_dir {
            return Ok(());
        }
        for e in fs::read_dir(&sub)? {
            let e = e?;
            let name = e.file_name().to_string_lossy().into_owned();
            if is_frame(&name) && e.file_type()?.is_file() {
                safe_file::remove_regular(&e.path())?;
            }
        }
        // Left in place if something else is in it.
        let _ = fs::remove_dir(&sub);
        return Ok(());
    }
    if !plain_entry(entry) {
        return Ok(());
    }
    let path = dir.join(entry);
    match safe_file::non_regular_kind(&path) {
        Some(_) => Ok(()),
        None => safe_file::remove_regular(&path),
    }
}

/// The files a run writes besides its histories: the summary, the checkpoint, and with a
/// VTK series its collection file and frames (all with their temporary names).
pub fn run_files(histories: Vec<String>, vtk: bool) -> Vec<String> {
    let mut files = histories;
    for f in [
        "summary.json",
        "summary.json.tmp",
        crate::checkpoint::FILE_NAME,
        crate::checkpoint::TMP_NAME,
    ] {
        files.push(f.to_string());
    }
    if vtk {
        let pvd = crate::output::vtk::PVD_NAME;
        files.push(pvd.to_string());
        files.push(format!("{pvd}.tmp"));
        files.push(VTK_DIR.to_string());
    }
    files
}

/// The files a modal analysis writes (`mecano-rs modes`, a deck of `ANALYSIS MODES n`):
/// the table, the shapes, the summary and the ParaView series of each mode in `vtk/`.
pub fn modes_files() -> Vec<String> {
    ["modes.csv", "modes_shapes.csv", "summary.json", VTK_DIR]
        .iter()
        .map(|s| s.to_string())
        .collect()
}

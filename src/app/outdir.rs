//! A run's claim on its output directory: a lock, so that two runs never write into one
//! directory at once, and a manifest of the files the run writes, so that the next run
//! removes them and nothing else.
//!
//! - **Lock.** `.mecano-lock` in the directory, held with `flock(2)` (`LOCK_EX | LOCK_NB`)
//!   for the whole run or restart. The kernel releases it when the process ends, however
//!   it ends (a crash, SIGKILL), so a lock is never left stuck; the file itself stays,
//!   empty (a run's directory is the same, byte for byte, however often it was resumed).
//! - **Manifest.** `.mecano-manifest`: one path per line, relative to the directory, of
//!   every file this run may write (histories, `summary.json`, the checkpoint, the VTK
//!   series). It is written before the first of them. A fresh run removes what the
//!   previous run's manifest lists (and only that), and refuses a directory holding files
//!   of anyone else unless `--force` is given (they are then left where they are;
//!   subdirectories, e.g. `study/`, are never touched nor counted). `resume` takes the
//!   lock and removes nothing.
//!
//! Every refusal is bad input (exit code 2): an output path that is a file, `/dev/null`,
//! below a file, not creatable, a directory in use, or holding foreign files.

use std::fs::{self, File, OpenOptions};
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
    /// manifest does not list (unless `force`), removes those the manifest lists, and
    /// writes the new manifest.
    pub fn claim_fresh(dir: &Path, files: &[String], force: bool) -> Result<Self, OutDirError> {
        if dir.exists() && !dir.is_dir() {
            return Err(OutDirError::NotADirectory(dir.to_path_buf()));
        }
        // Refused before anything is written into it (not even the lock file); checked
        // again under the lock, which another run may have held meanwhile.
        if dir.is_dir() && !force {
            refuse_foreign(dir)?;
        }
        fs::create_dir_all(dir).map_err(|e| unusable(dir, &e))?;
        let lock = lock(dir)?;
        let old = if force {
            read_manifest(dir).map_err(|e| unusable(dir, &e))?
        } else {
            refuse_foreign(dir)?
        };
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
    let mut list: Vec<String> = foreign.iter().take(5).cloned().collect();
    if foreign.len() > 5 {
        list.push(format!("and {} more", foreign.len() - 5));
    }
    Err(OutDirError::Foreign {
        path: dir.to_path_buf(),
        list: list.join(", "),
    })
}

/// Opens (creating) the lock file and takes an exclusive, non-blocking `flock`.
fn lock(dir: &Path) -> Result<File, OutDirError> {
    let path = dir.join(LOCK_NAME);
    let file = OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(false)
        .open(&path)
        .map_err(|e| unusable(dir, &e))?;
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

/// The entries of the manifest in `dir` (empty when there is none). Entries that could
/// leave the directory (absolute, `..`) are dropped: a manifest never removes anything
/// outside its directory.
fn read_manifest(dir: &Path) -> io::Result<Vec<String>> {
    let text = match fs::read_to_string(dir.join(MANIFEST_NAME)) {
        Ok(t) => t,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(e),
    };
    Ok(text
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
        .filter(|l| {
            let p = Path::new(l.trim_end_matches('/'));
            p.components()
                .all(|c| matches!(c, std::path::Component::Normal(_)))
        })
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
    fs::write(&tmp, text)?;
    fs::rename(tmp, dir.join(MANIFEST_NAME))
}

/// Names of the regular files (and links) at the top of `dir` that neither the manifest
/// `old` lists nor this module keeps. Subdirectories do not count.
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

/// Removes one manifest entry: a file (missing is fine), or for `vtk/` the frames in it
/// and the directory once empty.
fn remove_entry(dir: &Path, entry: &str) -> io::Result<()> {
    if entry == VTK_DIR {
        let sub = dir.join(VTK_DIR);
        let Ok(it) = fs::read_dir(&sub) else {
            return Ok(());
        };
        for e in it {
            let e = e?;
            let name = e.file_name().to_string_lossy().into_owned();
            if name.starts_with("frame_") && name.ends_with(".vtu") {
                remove_file(&e.path())?;
            }
        }
        // Left in place if something else is in it.
        let _ = fs::remove_dir(&sub);
        return Ok(());
    }
    if entry.ends_with('/') {
        return Ok(());
    }
    remove_file(&dir.join(entry))
}

fn remove_file(path: &Path) -> io::Result<()> {
    match fs::remove_file(path) {
        Err(e) if e.kind() != io::ErrorKind::NotFound => Err(e),
        _ => Ok(()),
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

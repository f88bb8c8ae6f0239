//! Files of a run's output directory opened so that nothing outside it is ever written
//! (issue 35 §3): every open of a file the run writes, reads back or removes goes through
//! here, never through a symbolic link.
//!
//! - Opens use `O_NOFOLLOW` (a link at the last component fails with `ELOOP`, reported as
//!   "is a symbolic link"), `O_NONBLOCK` (a FIFO planted under a history's name fails at
//!   once or is refused, it is never waited on) and `O_CLOEXEC`; the descriptor is then
//!   checked to be a regular file (`fstat`), so a FIFO or a device is refused too.
//! - Subdirectories the run writes into (`vtk/`) must be real directories, not links.
//! - [`remove_regular`] removes a name only when it is a regular file (`lstat`); a link,
//!   a directory or anything else is left alone and reported.
//! - Reads are bounded ([`read_bounded`]): a name that leads to `/dev/zero` cannot make a
//!   reader allocate without end.
//!
//! The directory itself is the user's choice (`-o`, which may be a link they made): only
//! the names inside it are guarded.

use std::fs::{self, File, OpenOptions};
use std::io::{self, Read, Write};
use std::os::unix::fs::{FileTypeExt, OpenOptionsExt};
use std::path::Path;

/// The error of an open refused because the name is not a regular file.
fn not_regular(path: &Path, what: &str) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidInput,
        format!(
            "{} is {what}, not a regular file: refused (a run writes only regular files of its directory, never through a link)",
            path.display()
        ),
    )
}

/// What a file type is, for messages.
fn kind_of(ft: &fs::FileType) -> &'static str {
    if ft.is_symlink() {
        "a symbolic link"
    } else if ft.is_dir() {
        "a directory"
    } else if ft.is_fifo() {
        "a FIFO"
    } else if ft.is_socket() {
        "a socket"
    } else if ft.is_block_device() || ft.is_char_device() {
        "a device"
    } else {
        "not a regular file"
    }
}

/// Opens `path` with `opts` plus `O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC` and checks that it is
/// a regular file.
fn open_guarded(path: &Path, opts: &mut OpenOptions) -> io::Result<File> {
    let f = opts
        .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK | libc::O_CLOEXEC)
        .open(path)
        .map_err(|e| {
            if e.raw_os_error() == Some(libc::ELOOP) {
                not_regular(path, "a symbolic link")
            } else if e.raw_os_error() == Some(libc::ENXIO) {
                // O_NONBLOCK | O_WRONLY on a FIFO without a reader.
                not_regular(path, "a FIFO")
            } else {
                io::Error::new(e.kind(), format!("{}: {e}", path.display()))
            }
        })?;
    let ft = f.metadata()?.file_type();
    if !ft.is_file() {
        return Err(not_regular(path, kind_of(&ft)));
    }
    Ok(f)
}

/// Creates `path` (or truncates it when it is a regular file), for writing.
pub fn create(path: &Path) -> io::Result<File> {
    open_guarded(
        path,
        OpenOptions::new().write(true).create(true).truncate(true),
    )
}

/// Opens the existing regular file `path` to append to it.
pub fn append(path: &Path) -> io::Result<File> {
    open_guarded(path, OpenOptions::new().append(true))
}

/// Opens the existing regular file `path` for reading and writing.
pub fn read_write(path: &Path) -> io::Result<File> {
    open_guarded(path, OpenOptions::new().read(true).write(true))
}

/// Opens the existing regular file `path` for writing (no truncation).
pub fn write_existing(path: &Path) -> io::Result<File> {
    open_guarded(path, OpenOptions::new().write(true))
}

/// Opens (creating) `path` for reading and writing without truncating it (a lock file).
pub fn open_or_create(path: &Path) -> io::Result<File> {
    open_guarded(
        path,
        OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false),
    )
}

/// Opens the existing regular file `path` for reading.
pub fn open_read(path: &Path) -> io::Result<File> {
    open_guarded(path, OpenOptions::new().read(true))
}

/// Opens `path` for reading as a reader of a run's files does (`compare`, `plot`, `resume`,
/// a sweep's collection): links are followed (a directory of runs may be a user's links),
/// but what is opened must be a regular file — a FIFO or a device under a history's name
/// is refused at once, never waited on or read without end.
pub fn open_regular(path: &Path) -> io::Result<File> {
    let f = OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK | libc::O_CLOEXEC)
        .open(path)
        .map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", path.display())))?;
    let ft = f.metadata()?.file_type();
    if !ft.is_file() {
        return Err(not_regular(path, kind_of(&ft)));
    }
    Ok(f)
}

/// [`open_regular`], read whole as UTF-8 text, refusing more than `max` bytes.
pub fn read_text(path: &Path, max: u64) -> io::Result<String> {
    let mut bytes = Vec::new();
    open_regular(path)?.take(max + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > max {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            format!("{} is longer than {max} bytes: refused", path.display()),
        ));
    }
    String::from_utf8(bytes).map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e))
}

/// The largest JSON or text file a reader of a run's directory takes whole (a summary
/// with its step-resolution table is a few kB; a sweep's statistics a few MB).
pub const MAX_TEXT_BYTES: u64 = 256 << 20;

/// Reads the regular file `path` whole, refusing one longer than `max` bytes (at most
/// `max + 1` bytes are read).
pub fn read_bounded(path: &Path, max: u64) -> io::Result<Vec<u8>> {
    let f = open_read(path)?;
    let mut bytes = Vec::new();
    f.take(max + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > max {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            format!("{} is longer than {max} bytes: refused", path.display()),
        ));
    }
    Ok(bytes)
}

/// Writes `bytes` as the regular file `path` (created or truncated; never through a link).
pub fn write(path: &Path, bytes: &[u8]) -> io::Result<()> {
    create(path)?.write_all(bytes)
}

/// Writes `bytes` to `tmp`, then renames it to `path`: a crash leaves the old or the new
/// file whole. (`rename(2)` replaces the name `path`, never what a link there points to.)
pub fn write_atomic(tmp: &Path, path: &Path, bytes: &[u8]) -> io::Result<()> {
    write(tmp, bytes)?;
    fs::rename(tmp, path)
}

/// Removes `path` when it is a regular file; a missing name is fine. Anything else (a
/// link, a directory, a FIFO) is left alone and reported as an error.
pub fn remove_regular(path: &Path) -> io::Result<()> {
    match fs::symlink_metadata(path) {
        Err(e) if e.kind() == io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(e),
        Ok(m) if m.file_type().is_file() => match fs::remove_file(path) {
            Err(e) if e.kind() != io::ErrorKind::NotFound => Err(e),
            _ => Ok(()),
        },
        Ok(m) => Err(not_regular(path, kind_of(&m.file_type()))),
    }
}

/// Makes sure `path` is a real directory (created when missing; a link to a directory,
/// or anything else by that name, is refused).
pub fn real_dir(path: &Path) -> io::Result<()> {
    match fs::symlink_metadata(path) {
        Err(e) if e.kind() == io::ErrorKind::NotFound => match fs::create_dir(path) {
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => real_dir(path),
            r => r,
        },
        Err(e) => Err(e),
        Ok(m) if m.file_type().is_dir() => Ok(()),
        Ok(m) => Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "{} is {}, not a directory: refused (a run writes only into real directories of its own)",
                path.display(),
                kind_of(&m.file_type())
            ),
        )),
    }
}

/// What `path` is when it exists and is not a regular file (`lstat`: a link is a link).
pub fn non_regular_kind(path: &Path) -> Option<&'static str> {
    match fs::symlink_metadata(path) {
        Ok(m) if !m.file_type().is_file() => Some(kind_of(&m.file_type())),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::fs::symlink;

    fn scratch(name: &str) -> std::path::PathBuf {
        let d =
            std::env::temp_dir().join(format!("mecano_safe_file_{name}_{}", std::process::id()));
        let _ = fs::remove_dir_all(&d);
        fs::create_dir_all(&d).unwrap();
        d
    }

    /// A link, dangling or not, is never opened, written through or removed; its target is
    /// unchanged (and a dangling one's target is not created).
    #[test]
    fn links_are_refused_and_their_targets_untouched() {
        let d = scratch("links");
        let target = d.join("target.txt");
        fs::write(&target, "keep").unwrap();
        symlink(&target, d.join("link")).unwrap();
        symlink(d.join("nowhere"), d.join("dangling")).unwrap();
        for name in ["link", "dangling"] {
            let p = d.join(name);
            let e = create(&p).unwrap_err();
            assert!(e.to_string().contains("symbolic link"), "{e}");
            assert!(append(&p).is_err() && read_write(&p).is_err());
            assert!(open_or_create(&p).is_err() && write(&p, b"x").is_err());
            assert!(remove_regular(&p).is_err());
            assert!(fs::symlink_metadata(&p).is_ok(), "the link itself stays");
        }
        assert_eq!(fs::read_to_string(&target).unwrap(), "keep");
        assert!(!d.join("nowhere").exists());
        // A link to a directory is not a directory of the run.
        fs::create_dir(d.join("real")).unwrap();
        symlink(d.join("real"), d.join("vtk")).unwrap();
        assert!(real_dir(&d.join("vtk")).is_err());
        real_dir(&d.join("new")).unwrap();
        real_dir(&d.join("real")).unwrap();
        let _ = fs::remove_dir_all(&d);
    }

    /// A FIFO under a file's name is refused at once (no reader: the open would block
    /// without O_NONBLOCK), and a bounded read stops at its bound.
    #[test]
    fn fifos_and_devices_are_refused_and_reads_bounded() {
        let d = scratch("fifo");
        let fifo = d.join("node_2.csv");
        let c = std::ffi::CString::new(fifo.as_os_str().as_encoded_bytes()).unwrap();
        // SAFETY: mkfifo(3) on a NUL-terminated path.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        assert!(create(&fifo).is_err());
        assert!(open_read(&fifo).is_err());
        assert!(remove_regular(&fifo).is_err());
        assert!(read_bounded(Path::new("/dev/zero"), 10).is_err());
        fs::write(d.join("small"), "12345").unwrap();
        assert_eq!(read_bounded(&d.join("small"), 5).unwrap(), b"12345");
        assert!(read_bounded(&d.join("small"), 4).is_err());
        let _ = fs::remove_dir_all(&d);
    }
}

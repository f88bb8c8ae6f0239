//! Reading a deck's text from its path (issue 35 §2): a regular file or a pipe (a FIFO, a
//! shell's `<(…)`, `/dev/stdin` on a pipe), never more than the deck size limit plus one
//! byte, never waiting without end.
//!
//! - The path is opened non-blocking and its type read from the descriptor (`fstat`): a
//!   directory, a device (`/dev/zero`, `/dev/urandom`), a socket is refused at once, not
//!   read. A regular file is read up to [`MAX_DECK_BYTES`] + 1 bytes.
//! - A pipe is read as it comes, up to the same bound; a FIFO whose writer sends nothing
//!   within [`PIPE_WAIT`] (none has opened it) is refused rather than waited on forever.

use super::error::{DeckError, DeckErrorKind, DeckErrors};
use super::limits::{self, MAX_DECK_BYTES};
use crate::model::Span;
use std::io::{self, Read};
use std::os::fd::AsRawFd;
use std::os::unix::fs::{FileTypeExt, OpenOptionsExt};
use std::path::Path;
use std::time::{Duration, Instant};

/// How long a deck read from a pipe may wait for its first byte (or its end).
pub const PIPE_WAIT: Duration = Duration::from_secs(10);

/// Why a deck's bytes could not be read.
#[derive(Debug)]
pub(crate) enum ReadError {
    /// The system refused (missing file, no permission, …).
    Io(io::Error),
    /// The path is not a regular file or a pipe: what it is.
    NotAFile(&'static str),
    /// A pipe that gave nothing within the wait.
    Silent(Duration),
}

/// Reads at most `MAX_DECK_BYTES + 1` bytes of the deck at `path` (module docs), waiting at
/// most `wait` for a pipe's writer.
pub(crate) fn read_bytes(path: &Path, wait: Duration) -> Result<Vec<u8>, ReadError> {
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK | libc::O_CLOEXEC)
        .open(path)
        .map_err(ReadError::Io)?;
    let ft = file.metadata().map_err(ReadError::Io)?.file_type();
    let bound = MAX_DECK_BYTES as u64 + 1;
    if ft.is_file() {
        let mut bytes = Vec::new();
        file.take(bound)
            .read_to_end(&mut bytes)
            .map_err(ReadError::Io)?;
        return Ok(bytes);
    }
    if !ft.is_fifo() {
        return Err(ReadError::NotAFile(if ft.is_dir() {
            "a directory"
        } else if ft.is_char_device() || ft.is_block_device() {
            "a device"
        } else if ft.is_socket() {
            "a socket"
        } else {
            "not a regular file"
        }));
    }
    read_pipe(file, bound as usize, wait)
}

/// Reads a pipe (non-blocking descriptor) to its end or to `bound` bytes. `poll(2)` tells
/// when bytes or the end came; a FIFO no writer has opened shows neither (Linux reports
/// POLLHUP only once a writer has come and gone), so the wait is bounded by `wait`.
fn read_pipe(mut file: std::fs::File, bound: usize, wait: Duration) -> Result<Vec<u8>, ReadError> {
    let start = Instant::now();
    let mut bytes = Vec::new();
    let mut buf = vec![0u8; 64 << 10];
    loop {
        let mut fds = libc::pollfd {
            fd: file.as_raw_fd(),
            events: libc::POLLIN,
            revents: 0,
        };
        let left = wait.saturating_sub(start.elapsed());
        if bytes.is_empty() && left.is_zero() {
            return Err(ReadError::Silent(wait));
        }
        // Slices of at most 100 ms: the wait is measured, not trusted to one call.
        let ms = if bytes.is_empty() {
            left.as_millis().clamp(1, 100) as libc::c_int
        } else {
            100
        };
        // SAFETY: poll(2) on one valid pollfd owned by this frame.
        let n = unsafe { libc::poll(&mut fds, 1, ms) };
        if n < 0 {
            let e = io::Error::last_os_error();
            if e.kind() == io::ErrorKind::Interrupted {
                continue;
            }
            return Err(ReadError::Io(e));
        }
        if n == 0 {
            continue;
        }
        match file.read(&mut buf) {
            Ok(0) => return Ok(bytes),
            Ok(k) => {
                let room = bound - bytes.len();
                bytes.extend_from_slice(&buf[..k.min(room)]);
                if bytes.len() >= bound {
                    return Ok(bytes);
                }
            }
            Err(e) if e.kind() == io::ErrorKind::WouldBlock => {}
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(ReadError::Io(e)),
        }
    }
}

/// Reads a text file other than a deck (a sweep's plan) as a deck is read: a regular file
/// or a pipe, at most the deck size limit, UTF-8.
pub fn read_text(path: &Path) -> io::Result<String> {
    let bytes = read_bytes(path, PIPE_WAIT).map_err(|e| match e {
        ReadError::Io(e) => e,
        ReadError::NotAFile(kind) => io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("it is {kind}, not a regular file or a pipe"),
        ),
        ReadError::Silent(w) => io::Error::new(
            io::ErrorKind::TimedOut,
            format!(
                "it is a pipe from which nothing came within {} s",
                w.as_secs()
            ),
        ),
    })?;
    if bytes.len() > MAX_DECK_BYTES {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            format!("larger than {MAX_DECK_BYTES} bytes"),
        ));
    }
    String::from_utf8(bytes).map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e))
}

/// Reads the deck at `path` as text: [`read_bytes`], then the size limit and UTF-8, each
/// failure one error (located at the limit or at the first byte that is not UTF-8).
pub fn read_source(path: &Path) -> Result<String, DeckErrors> {
    read_source_waiting(path, PIPE_WAIT)
}

/// [`read_source`] with the pipe's wait given.
pub(crate) fn read_source_waiting(path: &Path, wait: Duration) -> Result<String, DeckErrors> {
    let name = path.display().to_string();
    let file_error = |kind| DeckErrors::new("", &name, vec![DeckError { kind, span: None }]);
    let io = |reason: String| {
        file_error(DeckErrorKind::Io {
            path: name.clone(),
            reason,
        })
    };
    let bytes = read_bytes(path, wait).map_err(|e| match e {
        ReadError::Io(e) => io(e.to_string()),
        ReadError::NotAFile(kind) => io(format!(
            "it is {kind}: a deck is read from a regular file or a pipe"
        )),
        ReadError::Silent(w) => io(format!(
            "it is a pipe from which nothing came within {} s (a FIFO no program writes to?)",
            w.as_secs()
        )),
    })?;
    let total = bytes.len();
    match String::from_utf8(bytes) {
        Ok(text) if total <= MAX_DECK_BYTES => Ok(text),
        Ok(text) => Err(limits::check_text(&text, total).err().map_or_else(
            || file_error(DeckErrorKind::EmptyDeck),
            |b| DeckErrors::new(&text[..b.cut], &name, vec![b.error]),
        )),
        Err(e) => {
            // Located at the first invalid byte: the text before it is the source of the
            // diagnostic (its lines are checked first, so the snippet stays short).
            let offset = e.utf8_error().valid_up_to();
            let valid = &e.as_bytes()[..offset];
            let text = std::str::from_utf8(valid).unwrap_or_default();
            // A file cut at the size limit may end inside a character: then it is too
            // large, not malformed.
            let cut_inside = total > MAX_DECK_BYTES && offset + 4 > MAX_DECK_BYTES;
            let checked = limits::check_text(text, if cut_inside { total } else { offset });
            let error = checked.err().unwrap_or_else(|| {
                Box::new(limits::Broken {
                    error: DeckError::new(
                        DeckErrorKind::NotUtf8 {
                            path: name.clone(),
                            offset,
                        },
                        Span::new(offset, offset),
                    ),
                    cut: offset,
                })
            });
            Err(DeckErrors::new(
                &text[..error.cut],
                &name,
                vec![error.error],
            ))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn scratch(name: &str) -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("mecano_source_{name}_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn mkfifo(p: &Path) {
        let c = std::ffi::CString::new(p.as_os_str().as_encoded_bytes()).unwrap();
        // SAFETY: mkfifo(3) on a NUL-terminated path.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    }

    fn message(e: DeckErrors) -> String {
        format!("{:?}", miette::Report::new(e))
    }

    /// A device, a directory: refused without reading (`/dev/zero` would never end).
    #[test]
    fn devices_and_directories_are_refused_unread() {
        for (p, says) in [
            ("/dev/zero", "a device"),
            ("/dev/null", "a device"),
            ("/", "a directory"),
        ] {
            let e = message(read_source(Path::new(p)).unwrap_err());
            assert!(
                e.contains(says) && e.contains("regular file or a pipe"),
                "{p}: {e}"
            );
        }
    }

    /// A FIFO no one writes to is refused after the wait (bounded: the loop counts its
    /// own time); one with a writer is read to its end, and one beyond the size limit is
    /// cut at the limit plus one byte and refused as too large.
    #[test]
    fn a_fifo_without_writer_is_refused_and_one_with_a_writer_is_read() {
        let d = scratch("fifo");
        let fifo = d.join("deck.dat");
        mkfifo(&fifo);
        let e = message(read_source_waiting(&fifo, Duration::from_millis(200)).unwrap_err());
        assert!(e.contains("nothing came"), "{e}");
        let text = "TITLE t\nANALYSIS STATIC STEPS 1\n";
        let writer = {
            let fifo = fifo.clone();
            std::thread::spawn(move || {
                let mut f = std::fs::OpenOptions::new().write(true).open(&fifo).unwrap();
                f.write_all(text.as_bytes()).unwrap();
            })
        };
        let got = read_source_waiting(&fifo, Duration::from_secs(60)).unwrap();
        writer.join().unwrap();
        assert_eq!(got, text);
        // A writer that sends more than the limit: refused after limit + 1 bytes.
        let writer = {
            let fifo = fifo.clone();
            std::thread::spawn(move || {
                let mut f = std::fs::OpenOptions::new().write(true).open(&fifo).unwrap();
                let line = vec![b'!'; 1000];
                let mut line = line;
                line.push(b'\n');
                // Stops when the reader closes (EPIPE): never more than it reads.
                while f.write_all(&line).is_ok() {}
            })
        };
        let e = message(read_source_waiting(&fifo, Duration::from_secs(60)).unwrap_err());
        writer.join().unwrap();
        assert!(e.contains("too large") || e.contains("16777216"), "{e}");
        let _ = std::fs::remove_dir_all(&d);
    }
}

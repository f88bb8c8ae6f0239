//! One history file (CSV) written in whole rows.
//!
//! Rows are formatted into a buffer and reach the file only whole, by one `write_all` of
//! the buffer: whatever stops the program between two writes (an abort at a second
//! Ctrl-C, an error) leaves files that end with a complete row. (A SIGKILL or a power cut
//! in the middle of a write can still leave a partial row: a restart cuts every file
//! back to the length its checkpoint recorded.) The format is CSV without quotes (numbers
//! and column names never need them), `\n` after each row, numbers in the shortest form
//! that reads back to the same double (Ryū: Adams, PLDI 2018).

use std::fs::{File, OpenOptions};
use std::io::{self, Seek, SeekFrom, Write};
use std::path::Path;

/// The buffer is written to the file once it holds this many bytes (whole rows).
const FLUSH_AT: usize = 32 * 1024;

/// A CSV history file.
pub(crate) struct Stream {
    file: File,
    /// Whole rows not yet written to the file.
    pending: Vec<u8>,
    /// Bytes in the file.
    written: u64,
    /// File name, for messages and checkpoints.
    pub(crate) name: String,
    header: String,
    num: ryu::Buffer,
}

pub(crate) fn file_name(path: &Path) -> String {
    path.file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
}

impl Stream {
    /// Creates (truncates) the file and writes the header row.
    pub(crate) fn create(path: &Path, header: &str) -> io::Result<Self> {
        let file = File::create(path)?;
        let mut s = Stream {
            file,
            // Room for a flush threshold plus a row: rows never grow it (no allocation).
            pending: Vec::with_capacity(2 * FLUSH_AT),
            written: 0,
            name: file_name(path),
            header: header.to_string(),
            num: ryu::Buffer::new(),
        };
        s.pending.extend_from_slice(header.as_bytes());
        s.pending.push(b'\n');
        Ok(s)
    }

    /// Opens an existing file to append after its first `len` bytes (a restart: what
    /// follows them was written after the checkpoint, and is cut). The file must be at
    /// least `len` bytes long and begin with the header.
    pub(crate) fn reopen(path: &Path, header: &str, len: u64) -> io::Result<Self> {
        let mut file = OpenOptions::new()
            .read(true)
            .write(true)
            .open(path)
            .map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", path.display())))?;
        let actual = file.metadata()?.len();
        if actual < len {
            return Err(io::Error::new(
                io::ErrorKind::UnexpectedEof,
                format!(
                    "{} has {actual} bytes, fewer than the {len} its checkpoint recorded (the file was cut or replaced)",
                    path.display()
                ),
            ));
        }
        let mut head = vec![0u8; header.len() + 1];
        std::io::Read::read_exact(&mut file, &mut head)?;
        if head[..header.len()] != *header.as_bytes() || head[header.len()] != b'\n' {
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!(
                    "{} does not begin with the header `{header}`",
                    path.display()
                ),
            ));
        }
        file.set_len(len)?;
        file.seek(SeekFrom::Start(len))?;
        Ok(Stream {
            file,
            pending: Vec::with_capacity(2 * FLUSH_AT),
            written: len,
            name: file_name(path),
            header: header.to_string(),
            num: ryu::Buffer::new(),
        })
    }

    /// Appends a row; a non-finite value is refused (the row is not written).
    pub(crate) fn row(&mut self, values: &[f64]) -> io::Result<()> {
        if let Some(bad) = values.iter().position(|v| !v.is_finite()) {
            let col = self.header.split(',').nth(bad).unwrap_or("?");
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!(
                    "refusing to write a non-finite value to {} (column {}, `{col}`, t = {})",
                    self.name,
                    bad + 1,
                    values[0]
                ),
            ));
        }
        for (i, v) in values.iter().enumerate() {
            if i > 0 {
                self.pending.push(b',');
            }
            self.pending
                .extend_from_slice(self.num.format_finite(*v).as_bytes());
        }
        self.pending.push(b'\n');
        if self.pending.len() >= FLUSH_AT {
            self.flush()?;
        }
        Ok(())
    }

    /// Writes the buffered rows to the file.
    pub(crate) fn flush(&mut self) -> io::Result<()> {
        if !self.pending.is_empty() {
            self.file.write_all(&self.pending)?;
            self.written += self.pending.len() as u64;
            self.pending.clear();
        }
        Ok(())
    }

    /// Writes the buffered rows and waits until the file's data is on the disk.
    pub(crate) fn sync(&mut self) -> io::Result<()> {
        self.flush()?;
        self.file.sync_data()
    }

    /// Length of the file once the buffered rows are written, bytes.
    pub(crate) fn len(&self) -> u64 {
        self.written + self.pending.len() as u64
    }
}

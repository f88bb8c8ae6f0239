//! One history file (CSV) written in whole rows.
//!
//! Rows are formatted into a buffer and reach the file only whole, by one `write_all` of
//! the buffer: whatever stops the program between two writes (an abort at a second
//! Ctrl-C, an error) leaves files that end with a complete row. (A SIGKILL or a power cut
//! in the middle of a write can still leave a partial row: a restart cuts every file
//! back to the length its checkpoint recorded.) The format is CSV without quotes (numbers
//! and column names never need them), `\n` after each row, numbers in the shortest form
//! that reads back to the same double (Ryū: Adams, PLDI 2018).
//!
//! No file stays open between two writes: each block of rows is written by
//! open-append-close (issue 29: a run selecting 50,000 elements held 50,000 descriptors
//! and stopped at the usual limit of 1024). The block size is chosen by the writer from
//! a memory budget shared by all its streams ([`block_size`]), so the buffers of a large
//! selection stay bounded and never grow (no allocation per row).

use std::fs::File;
use std::io::{self, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

/// The buffer is written to the file once it holds this many bytes (whole rows), for a
/// writer with few streams.
const FLUSH_AT: usize = 32 * 1024;
/// Bytes of row buffers all the streams of one writer may hold together.
const BUDGET: usize = 16 * 1024 * 1024;
/// The smallest block: below it the open-append-close per block costs more than the
/// formatting of its rows.
const MIN_BLOCK: usize = 1024;
/// Longest text of one number: sign, 17 digits, point, exponent `e-308`, and a comma.
const NUMBER_BYTES: usize = 26;

/// The block size of each of `streams` streams: `BUDGET / streams` bytes, between
/// `MIN_BLOCK` and `FLUSH_AT`.
pub(crate) fn block_size(streams: usize) -> usize {
    (BUDGET / streams.max(1)).clamp(MIN_BLOCK, FLUSH_AT)
}

/// A CSV history file.
pub(crate) struct Stream {
    path: PathBuf,
    /// Rows are written to the file once `pending` holds this many bytes.
    block: usize,
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
    fn capacity(block: usize, header: &str) -> usize {
        // Room for a block plus a row: rows never grow it (no allocation).
        block + NUMBER_BYTES * (header.split(',').count() + 1) + header.len() + 1
    }

    /// Creates (truncates) the file and writes the header row with the first block.
    pub(crate) fn create(path: &Path, header: &str, block: usize) -> io::Result<Self> {
        crate::safe_file::create(path)?;
        let mut s = Stream {
            path: path.to_path_buf(),
            block,
            pending: Vec::with_capacity(Self::capacity(block, header)),
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
    pub(crate) fn reopen(path: &Path, header: &str, len: u64, block: usize) -> io::Result<Self> {
        let mut file = crate::safe_file::read_write(path)?;
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
            path: path.to_path_buf(),
            block,
            pending: Vec::with_capacity(Self::capacity(block, header)),
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
        if self.pending.len() >= self.block {
            self.flush()?;
        }
        Ok(())
    }

    fn open(&self) -> io::Result<File> {
        crate::safe_file::append(&self.path)
    }

    /// Writes the buffered rows to the file (opened, appended to, closed).
    pub(crate) fn flush(&mut self) -> io::Result<()> {
        if !self.pending.is_empty() {
            let mut file = self.open()?;
            file.write_all(&self.pending)?;
            self.written += self.pending.len() as u64;
            self.pending.clear();
        }
        Ok(())
    }

    /// Writes the buffered rows and waits until the file's data is on the disk.
    pub(crate) fn sync(&mut self) -> io::Result<()> {
        self.flush()?;
        self.open()?.sync_data()
    }

    /// Length of the file once the buffered rows are written, bytes.
    pub(crate) fn len(&self) -> u64 {
        self.written + self.pending.len() as u64
    }
}

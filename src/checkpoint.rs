//! Checkpoints: the whole state of a run, in its output directory, to go on after a stop.
//!
//! # File format (`checkpoint.bin`, version [`FORMAT_VERSION`])
//! `MECANOCK` (8 bytes), the format version (u32, little-endian), the payload's length
//! (u64, LE), the SHA-256 of the payload (32 bytes), then the payload: a [`Checkpoint`]
//! in postcard (serde's compact binary encoding; doubles as their 8 bytes, so every
//! number comes back bit for bit). The checkpoint names its deck and the SHA-256 of the
//! deck's text: a restart refuses another deck, or the same deck edited.
//!
//! # Written so that a crash never loses both
//! The new checkpoint is written to `checkpoint.bin.tmp`, synced to the disk, renamed over
//! `checkpoint.bin` (an atomic replacement on POSIX file systems), and the directory is
//! synced: at any instant `checkpoint.bin` is the old checkpoint or the new one, whole.
//! The history files are synced before (their lengths at the checkpoint are in it), so
//! the files hold at least what the checkpoint says they hold. A torn or foreign file is
//! recognised by its magic, version, length and checksum, and refused.

use crate::output::WriterState;
use crate::output::vtk::VtkState;
use crate::solver::LoopState;
use crate::solver::state::IntegratorState;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::fs::{self, File};
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// Name of the checkpoint in an output directory.
pub const FILE_NAME: &str = "checkpoint.bin";
/// Name of the checkpoint being written (renamed to [`FILE_NAME`] once whole).
pub const TMP_NAME: &str = "checkpoint.bin.tmp";
/// Version of the file format; a checkpoint of another version is refused.
pub const FORMAT_VERSION: u32 = 1;
const MAGIC: &[u8; 8] = b"MECANOCK";
const HEADER_LEN: usize = 8 + 4 + 8 + 32;

/// The deck a run belongs to.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct DeckIdentity {
    /// The deck's path as the run was given it (what `summary.json` shows).
    pub path: String,
    /// Its absolute path when the run started (a restart from another directory finds it).
    pub absolute: Option<String>,
    /// SHA-256 of the deck's text, lower-case hex.
    pub sha256: String,
}

/// The whole state of a run between two steps.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Checkpoint {
    /// Version of mecano-rs that wrote it.
    pub program: String,
    /// The deck.
    pub deck: DeckIdentity,
    /// Time of the state, s (load factor in statics).
    pub time: f64,
    /// Accepted steps up to it.
    pub step: u64,
    /// The step controller.
    pub control: LoopState,
    /// The integrator, its matrix and LU, the elements' histories.
    pub integrator: IntegratorState,
    /// The history files' lengths and the energy balance's accumulators.
    pub writer: WriterState,
    /// The ParaView series, when the deck writes one.
    pub vtk: Option<VtkState>,
}

/// Why a checkpoint cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum CheckpointError {
    /// No checkpoint in the directory.
    #[error(
        "no checkpoint in {0} (the run stopped before its first one, or ran with --checkpoint 0)"
    )]
    Missing(PathBuf),
    /// The file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The error.
        source: io::Error,
    },
    /// The file is not a checkpoint of this format (or is torn).
    #[error("{path}: not a valid checkpoint: {why}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        why: String,
    },
}

/// SHA-256 of `bytes`, lower-case hex.
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// What `checkpoint.bin` holds: header and payload.
fn encode(c: &Checkpoint) -> io::Result<Vec<u8>> {
    let payload = postcard::to_stdvec(c).map_err(io::Error::other)?;
    let mut out = Vec::with_capacity(HEADER_LEN + payload.len());
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(&Sha256::digest(&payload));
    out.extend_from_slice(&payload);
    Ok(out)
}

fn decode(path: &Path, bytes: &[u8]) -> Result<Checkpoint, CheckpointError> {
    let invalid = |why: String| CheckpointError::Invalid {
        path: path.to_path_buf(),
        why,
    };
    if bytes.len() < HEADER_LEN || &bytes[..8] != MAGIC {
        return Err(invalid("it does not begin with `MECANOCK`".into()));
    }
    let version = u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes"));
    if version != FORMAT_VERSION {
        return Err(invalid(format!(
            "format version {version}, this mecano-rs reads version {FORMAT_VERSION}"
        )));
    }
    let len = u64::from_le_bytes(bytes[12..20].try_into().expect("8 bytes"));
    let payload = &bytes[HEADER_LEN..];
    if payload.len() as u64 != len {
        return Err(invalid(format!(
            "{} bytes of payload, the header says {len} (a torn write?)",
            payload.len()
        )));
    }
    if Sha256::digest(payload)[..] != bytes[20..52] {
        return Err(invalid(
            "its checksum does not match (a damaged file?)".into(),
        ));
    }
    postcard::from_bytes(payload).map_err(|e| invalid(format!("cannot decode it: {e}")))
}

/// Test hook: `MECANO_FAILPOINT=checkpoint:N` kills the process (SIGKILL, as a power cut
/// or a scheduler would) half-way through writing the N-th checkpoint's temporary file,
/// so that tests can check that the previous checkpoint survives. Unset: nothing.
fn failpoint(count: u64) -> bool {
    std::env::var("MECANO_FAILPOINT")
        .ok()
        .and_then(|v| v.strip_prefix("checkpoint:")?.parse::<u64>().ok())
        .is_some_and(|n| n == count)
}

/// Writes `c` as `dir/checkpoint.bin`: temporary file, sync, rename, directory sync
/// (module docs). `count` numbers the checkpoints of the process (for the test hook).
pub fn write(dir: &Path, c: &Checkpoint, count: u64) -> io::Result<()> {
    let bytes = encode(c)?;
    let tmp = dir.join(TMP_NAME);
    let mut f = File::create(&tmp)?;
    if failpoint(count) {
        f.write_all(&bytes[..bytes.len() / 2])?;
        f.sync_all()?;
        // SAFETY: kill(2) on our own pid has no memory-safety preconditions.
        unsafe {
            libc::kill(libc::getpid(), libc::SIGKILL);
        }
    }
    f.write_all(&bytes)?;
    f.sync_all()?;
    drop(f);
    fs::rename(&tmp, dir.join(FILE_NAME))?;
    // The rename is durable once the directory is synced.
    File::open(dir)?.sync_all()
}

/// Reads `dir/checkpoint.bin`.
pub fn read(dir: &Path) -> Result<Checkpoint, CheckpointError> {
    let path = dir.join(FILE_NAME);
    let bytes = match fs::read(&path) {
        Ok(b) => b,
        Err(e) if e.kind() == io::ErrorKind::NotFound => {
            return Err(CheckpointError::Missing(dir.to_path_buf()));
        }
        Err(source) => return Err(CheckpointError::Io { path, source }),
    };
    decode(&path, &bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sha256_of_a_known_text() {
        // FIPS 180-2, appendix B.1: SHA-256("abc").
        assert_eq!(
            sha256_hex(b"abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }
}

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
/// Largest checkpoint read, bytes: a bound for the reader only (a checkpoint is read as a
/// regular file of the directory, never through a link or from a device).
const MAX_BYTES: u64 = 1 << 40;
/// Name of the checkpoint being written (renamed to [`FILE_NAME`] once whole).
pub const TMP_NAME: &str = "checkpoint.bin.tmp";
/// Version of the file format; a checkpoint of another version is refused. (2: the
/// integrator's state names the time integration scheme that wrote it; 3: it holds the
/// energy guard's record, and the step controller its regrowth after a landing, and the
/// stage schemes' index-1 reaction solve's factors; 4: the guard's record holds the largest
/// energies of the oscillations, since its running minimum and over the run; 5: and the
/// energy created above its ceiling at the smallest step; 6: the nodes' orientations at the
/// kept factorisation, whose co-rotated frames the next solve uses; 7: the adaptive ESDIRK
/// steps' drift filter, `CARRY MODES`.)
pub const FORMAT_VERSION: u32 = 7;
const MAGIC: &[u8; 8] = b"MECANOCK";

/// The deck a run belongs to.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DeckIdentity {
    /// The deck's path as the run was given it (what `summary.json` shows).
    pub path: String,
    /// Its absolute path when the run started (a restart from another directory finds it).
    pub absolute: Option<String>,
    /// SHA-256 of the deck's text, lower-case hex.
    pub sha256: String,
    /// The `--refine` factor the run divided every beam by (1: the mesh as written).
    pub refine: u32,
    /// The parameter overrides of the run (`--set`), in command-line order.
    pub set: Vec<(String, f64)>,
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
    Ok(crate::framed::frame(MAGIC, FORMAT_VERSION, &payload))
}

fn decode(path: &Path, bytes: &[u8]) -> Result<Checkpoint, CheckpointError> {
    let invalid = |why: String| CheckpointError::Invalid {
        path: path.to_path_buf(),
        why,
    };
    let payload = crate::framed::unframe(bytes, MAGIC, FORMAT_VERSION).map_err(invalid)?;
    postcard::from_bytes(payload).map_err(|e| invalid(format!("cannot decode it: {e}")))
}

/// Test hook: `MECANO_FAILPOINT=checkpoint:N` kills the process (SIGKILL, as a power cut
/// or a scheduler would) half-way through writing the N-th checkpoint's temporary file,
/// so that tests can check that the previous checkpoint survives. Unset, or a build without
/// the hook ([`crate::failpoint`]): nothing.
fn failpoint(count: u64) -> bool {
    crate::failpoint::var()
        .and_then(|v| v.strip_prefix("checkpoint:")?.parse::<u64>().ok())
        .is_some_and(|n| n == count)
}

/// Writes `c` as `dir/checkpoint.bin`: temporary file, sync, rename, directory sync
/// (module docs). `count` numbers the checkpoints of the process (for the test hook).
pub fn write(dir: &Path, c: &Checkpoint, count: u64) -> io::Result<()> {
    let bytes = encode(c)?;
    let tmp = dir.join(TMP_NAME);
    let mut f = crate::safe_file::create(&tmp)?;
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
    let bytes = match crate::safe_file::read_bounded(&path, MAX_BYTES) {
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

    /// A checkpoint of a small model at its initial state.
    fn sample() -> Vec<u8> {
        let deck = "TITLE t\nMATERIALS\n  1 E 2.1e11 NU 0.3 RHO 7800\nSECTIONS\n  1 A 9e-4 I2 8.3e-8 I3 8.3e-8 J 4.15e-8\nNODES\n  1 0 0 0 FIX ALL\n  2 TO 3 LINE 0.5 0 0  1 0 0\nELEMENTS\n  1 TO 2 BEAM 1 2 MAT 1 SEC 1\nLOADS\n  GRAVITY 0 -9.81 0\nANALYSIS DYNAMIC STEP 1e-3 END 0.01\nOUTPUT NODES 3\n";
        let model = crate::deck::parse_deck(deck, "t.dat").expect("deck parses");
        let mut integ = crate::solver::prepare(&model).expect("builds");
        integ.initialize().expect("initial accelerations");
        let c = Checkpoint {
            program: "test".into(),
            deck: DeckIdentity {
                path: "t.dat".into(),
                absolute: None,
                sha256: sha256_hex(deck.as_bytes()),
                refine: 1,
                set: Vec::new(),
            },
            time: 0.0,
            step: 0,
            control: LoopState {
                h: 1e-3,
                good: 0,
                retry: None,
                regrow: None,
            },
            integrator: integ.save_state().expect("simplicial"),
            writer: WriterState::default(),
            vtk: None,
        };
        encode(&c).unwrap()
    }

    #[test]
    fn a_checkpoint_reads_back_to_the_same_bytes() {
        let b = sample();
        let c = decode(Path::new("c"), &b).unwrap();
        // (Compared as bytes: the state holds NaNs, e.g. "no valid LU step".)
        assert_eq!(encode(&c).unwrap(), b);
    }

    #[test]
    fn torn_damaged_foreign_and_other_version_files_are_refused() {
        let b = sample();
        let why = |bytes: &[u8]| match decode(Path::new("c"), bytes) {
            Err(CheckpointError::Invalid { why, .. }) => why,
            other => panic!("accepted: {:?}", other.map(|c| c.step)),
        };
        assert!(why(&b[..b.len() - 1]).contains("torn"));
        assert!(why(&b[..10]).contains("MECANOCK"));
        let mut d = b.clone();
        let k = d.len() - 7;
        d[k] ^= 0x10;
        assert!(why(&d).contains("checksum"));
        let mut v = b.clone();
        v[8] = 6;
        assert!(why(&v).contains("version 6"));
        let mut m = b;
        m[0] = b'X';
        assert!(why(&m).contains("MECANOCK"));
    }

    #[test]
    fn sha256_of_a_known_text() {
        // FIPS 180-2, appendix B.1: SHA-256("abc").
        assert_eq!(
            sha256_hex(b"abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }
}

//! The reduction cache (issue 38 §3): a superelement's reduced body ([`Body`]: the inertia
//! invariants, the reduced stiffness, the interface places, the kept modes' `ω²`) kept
//! beside its FE model, so that a second run of the same inputs does not reduce again.
//!
//! # Where, and under which key
//! `<FILES>/.mecano-cache/<slot>.bin`. The *slot* (32 hex digits) is the SHA-256 of what
//! the deck says about the reduction — the `INTERFACE` FE numbers, `MODES`, the `RBE2`/
//! `RBE3` clauses (kind, node, set, weights) and the deck places of every interface node
//! (the frame node's and those an RBE is placed at: the bits of their coordinates) — so a
//! deck keeps one file per configuration, and an edit of the FE files overwrites it rather
//! than piling up files. The file holds the full *key*, the SHA-256 of: the slot, the
//! format version [`FORMAT_VERSION`], mecano-rs's version, the SHA-256 of the source that
//! computes a reduction ([`PROGRAM`]: this folder's reading, reduction and invariants,
//! `src/lanczos.rs` and `Cargo.lock`, so that a rebuilt mecano-rs whose reduction could
//! round otherwise never reads an older one's), and the bytes of the four FE files. A
//! file whose key is not the run's is another reduction: the run reduces again and
//! overwrites it.
//!
//! # File format (version [`FORMAT_VERSION`]), as `checkpoint.bin`'s
//! `MECANOSE` (8 bytes), the version (u32, LE), the payload's length (u64, LE), the SHA-256
//! of the payload (32 bytes), then the payload: [`Stored`] in postcard (doubles as their
//! 8 bytes: the body comes back bit for bit, and a run from the cache writes the same
//! histories as the run that reduced). A torn, damaged or foreign file (magic, version,
//! length, checksum, sizes) is ignored with a warning, the body reduced again and the file
//! rewritten: never a panic, never another body.
//!
//! # Written as a run's files are (issue 35)
//! The directory `.mecano-cache` must be a real directory (created when missing; a link
//! there is refused, `crate::safe_file::real_dir`); the file is written to a temporary
//! name of its own (process id and a counter) opened `O_NOFOLLOW`, then renamed over the
//! slot's name (`rename(2)` replaces a name, never what a link there points to). The
//! cache is read `O_NOFOLLOW` too, bounded. A directory that cannot be written (read-only,
//! a link, a file by that name) means no cache, said in a note: never a failure.

use super::invariants::Body;
use crate::model::{RbeKind, SetSpec, SuperelementData};
use nalgebra::{DMatrix, Vector3};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Version of the cache's format; a file of another version is ignored (and rewritten).
pub const FORMAT_VERSION: u32 = 1;
const MAGIC: &[u8; 8] = b"MECANOSE";
/// The cache's directory, inside the superelement's `FILES` directory.
pub const DIR_NAME: &str = ".mecano-cache";
/// Largest cache file read (a body of 2,000 elastic coordinates is ~1 GB).
const MAX_BYTES: u64 = 4 << 30;

/// The source of mecano-rs that computes a reduction from the FE files: a change to any of
/// it makes every older cache another key.
const PROGRAM: [&str; 11] = [
    include_str!("fe.rs"),
    include_str!("mtx.rs"),
    include_str!("rbe.rs"),
    include_str!("reduce.rs"),
    include_str!("sparse.rs"),
    include_str!("invariants.rs"),
    include_str!("mod.rs"),
    include_str!("cache.rs"),
    include_str!("origin.rs"),
    include_str!("../../../lanczos.rs"),
    include_str!("../../../../Cargo.lock"),
];

/// The cache file's payload: the key and the body, matrices column-major.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Stored {
    /// The key it was written under (module docs).
    pub key: [u8; 32],
    /// Elastic coordinates `n`.
    pub n: u64,
    /// `𝕄₀`, `(6 + n)²`.
    pub m0: Vec<f64>,
    /// `[G_1 … G_n]`, `(6 + n) × 3n`.
    pub g: Vec<f64>,
    /// `H`, `3n × 3n`.
    pub h: Vec<f64>,
    /// Mass, kg.
    pub mass: f64,
    /// First moment about the frame node, kg·m.
    pub c0: [f64; 3],
    /// Reduced stiffness, `n × n`.
    pub k: Vec<f64>,
    /// The other interface nodes' places relative to the frame node.
    pub s_iface: Vec<[f64; 3]>,
    /// The kept modes' `ω²`.
    pub omega2: Vec<f64>,
}

/// Where a superelement's reduced body came from (its `summary.json` block).
#[derive(Debug, Clone, PartialEq)]
pub enum Source {
    /// Reduced by this run; written to the cache file, or not (why).
    Computed(Result<PathBuf, String>),
    /// Reduced by this run with `CACHE OFF`.
    Uncached,
    /// Read from the cache file.
    Cache(PathBuf),
    /// Read from an already reduced set (`super::reduced`) in this directory.
    Reduced(PathBuf),
}

impl Source {
    /// The block `summary.json` shows.
    pub fn json(&self) -> serde_json::Value {
        let p = |p: &Path| p.display().to_string();
        match self {
            Source::Computed(Ok(f)) => {
                serde_json::json!({"source": "computed", "cache_file": p(f)})
            }
            Source::Computed(Err(why)) => {
                serde_json::json!({"source": "computed", "cache_file": null, "cache_note": why})
            }
            Source::Uncached => {
                serde_json::json!({"source": "computed", "cache_file": null, "cache_note": "CACHE OFF"})
            }
            Source::Cache(f) => serde_json::json!({"source": "cache", "cache_file": p(f)}),
            Source::Reduced(d) => serde_json::json!({"source": "reduced files", "files": p(d)}),
        }
    }
}

/// A cache entry's place and key.
#[derive(Debug, Clone, PartialEq)]
pub struct Entry {
    /// `<FILES>/.mecano-cache/<slot>.bin`.
    pub path: PathBuf,
    /// The full key.
    pub key: [u8; 32],
}

fn program_hash() -> [u8; 32] {
    static HASH: std::sync::OnceLock<[u8; 32]> = std::sync::OnceLock::new();
    *HASH.get_or_init(|| {
        let mut h = Sha256::new();
        for s in PROGRAM {
            h.update((s.len() as u64).to_le_bytes());
            h.update(s.as_bytes());
        }
        h.finalize().into()
    })
}

/// The entry of a superelement of data `d` whose FE files hold `texts` (`fe::FILES`'
/// order) and whose interface nodes are at `places` (the deck's, `INTERFACE`'s order).
pub fn entry(d: &SuperelementData, texts: &[String; 4], places: &[Vector3<f64>]) -> Entry {
    let mut s = Sha256::new();
    s.update(b"mecano-rs superelement reduction slot\0");
    s.update(d.modes.to_le_bytes());
    s.update((d.interface.len() as u64).to_le_bytes());
    for (a, x) in d.interface.iter().zip(places) {
        s.update(a.to_le_bytes());
        for c in x.iter() {
            s.update(c.to_bits().to_le_bytes());
        }
    }
    s.update((d.rbe.len() as u64).to_le_bytes());
    for r in &d.rbe {
        s.update([match r.kind {
            RbeKind::Rigid => 2u8,
            RbeKind::Average => 3u8,
        }]);
        s.update(r.node.to_le_bytes());
        match &r.set {
            SetSpec::Nodes(v) => {
                s.update([0u8]);
                s.update((v.len() as u64).to_le_bytes());
                v.iter().for_each(|p| s.update(p.to_le_bytes()));
            }
            SetSpec::Within(x) => {
                s.update([1u8]);
                s.update(x.to_bits().to_le_bytes());
            }
        }
        s.update((r.weights.len() as u64).to_le_bytes());
        r.weights
            .iter()
            .for_each(|w| s.update(w.to_bits().to_le_bytes()));
    }
    let slot: [u8; 32] = s.finalize().into();
    let mut k = Sha256::new();
    k.update(slot);
    k.update(FORMAT_VERSION.to_le_bytes());
    k.update(env!("CARGO_PKG_VERSION").as_bytes());
    k.update(program_hash());
    for t in texts {
        k.update((t.len() as u64).to_le_bytes());
        k.update(t.as_bytes());
    }
    let hex: String = slot[..16].iter().map(|b| format!("{b:02x}")).collect();
    Entry {
        path: d.dir.join(DIR_NAME).join(format!("{hex}.bin")),
        key: k.finalize().into(),
    }
}

/// The file's bytes for `body` under `key`.
pub fn encode(key: [u8; 32], body: &Body) -> Vec<u8> {
    let v = |m: &DMatrix<f64>| m.as_slice().to_vec();
    let stored = Stored {
        key,
        n: body.n as u64,
        m0: v(&body.m0),
        g: v(&body.g),
        h: v(&body.h),
        mass: body.mass,
        c0: [body.c0.x, body.c0.y, body.c0.z],
        k: v(&body.k),
        s_iface: body.s_iface.iter().map(|s| [s.x, s.y, s.z]).collect(),
        omega2: body.omega2.clone(),
    };
    let payload = postcard::to_stdvec(&stored).expect("plain data encodes");
    crate::framed::frame(MAGIC, FORMAT_VERSION, &payload)
}

/// The key and body of a cache file's bytes, or why they are not one.
pub fn decode(bytes: &[u8]) -> Result<([u8; 32], Body), String> {
    let payload = crate::framed::unframe(bytes, MAGIC, FORMAT_VERSION)?;
    let s: Stored = postcard::from_bytes(payload).map_err(|e| format!("cannot decode it: {e}"))?;
    let n = usize::try_from(s.n).map_err(|_| "its size does not fit".to_string())?;
    let fits = n < 1 << 20
        && s.m0.len() == (6 + n) * (6 + n)
        && s.g.len() == (6 + n) * 3 * n
        && s.h.len() == 9 * n * n
        && s.k.len() == n * n
        && 6 * s.s_iface.len() + s.omega2.len() == n;
    if !fits {
        return Err("its matrices' sizes do not agree".into());
    }
    let all = [&s.m0, &s.g, &s.h, &s.k, &s.omega2];
    if !all.iter().all(|v| v.iter().all(|x| x.is_finite()))
        || !s.mass.is_finite()
        || s.c0
            .iter()
            .chain(s.s_iface.iter().flatten())
            .any(|x| !x.is_finite())
    {
        return Err("it holds a value that is not finite".into());
    }
    let m = |r: usize, c: usize, v: Vec<f64>| DMatrix::from_vec(r, c, v);
    let body = Body {
        n,
        m0: m(6 + n, 6 + n, s.m0),
        g: m(6 + n, 3 * n, s.g),
        h: m(3 * n, 3 * n, s.h),
        mass: s.mass,
        c0: Vector3::from(s.c0),
        k: m(n, n, s.k),
        s_iface: s.s_iface.into_iter().map(Vector3::from).collect(),
        omega2: s.omega2,
    };
    Ok((s.key, body))
}

/// What reading an entry found.
#[derive(Debug)]
pub enum Lookup {
    /// The body of this key.
    Hit(Box<Body>),
    /// No file, or one of another key (an input or mecano-rs changed).
    Miss,
    /// A file that is not a valid cache (why): to warn about, then overwrite.
    Invalid(String),
}

/// Reads `e`.
pub fn load(e: &Entry) -> Lookup {
    let bytes = match crate::safe_file::read_bounded(&e.path, MAX_BYTES) {
        Ok(b) => b,
        Err(err) if err.kind() == std::io::ErrorKind::NotFound => return Lookup::Miss,
        Err(err) => return Lookup::Invalid(err.to_string()),
    };
    match decode(&bytes) {
        Ok((key, body)) if key == e.key => Lookup::Hit(Box::new(body)),
        Ok(_) => Lookup::Miss,
        Err(why) => Lookup::Invalid(why),
    }
}

/// Writes `body` as `e`: the directory made (a real one), a temporary file of this
/// process opened `O_NOFOLLOW`, renamed over the slot's name (module docs).
pub fn store(e: &Entry, body: &Body) -> Result<(), String> {
    static COUNT: AtomicU64 = AtomicU64::new(0);
    let dir = e.path.parent().expect("a file of the cache directory");
    crate::safe_file::real_dir(dir).map_err(|err| format!("{}: {err}", dir.display()))?;
    let name = e.path.file_name().expect("a file name").to_string_lossy();
    let tmp = dir.join(format!(
        "{name}.{}.{}.tmp",
        std::process::id(),
        COUNT.fetch_add(1, Ordering::Relaxed)
    ));
    let bytes = encode(e.key, body);
    crate::safe_file::write_atomic(&tmp, &e.path, &bytes).map_err(|err| {
        let _ = crate::safe_file::remove_regular(&tmp);
        err.to_string()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn body() -> Body {
        let n = 2;
        let f = |r: usize, c: usize, s: f64| DMatrix::from_fn(r, c, |i, j| s + (i * c + j) as f64);
        Body {
            n,
            m0: f(8, 8, 0.5),
            g: f(8, 6, -1.0),
            h: f(6, 6, 2.0),
            mass: 3.0,
            c0: Vector3::new(0.1, -0.2, 1e-300),
            k: f(2, 2, 7.0),
            s_iface: Vec::new(),
            omega2: vec![1.0, 2.0],
        }
    }

    /// A body reads back bit for bit; torn, damaged, foreign and other-version files are
    /// refused with their reason.
    #[test]
    fn a_body_reads_back_and_damage_is_refused() {
        let b = body();
        let bytes = encode([7; 32], &b);
        let (key, back) = decode(&bytes).expect("decodes");
        assert_eq!(key, [7; 32]);
        assert_eq!(encode(key, &back), bytes);
        let why = |x: &[u8]| decode(x).expect_err("refused");
        assert!(why(&bytes[..bytes.len() - 1]).contains("torn"));
        assert!(why(&bytes[..10]).contains("MECANOSE"));
        let mut d = bytes.clone();
        let k = d.len() - 5;
        d[k] ^= 1;
        assert!(why(&d).contains("checksum"));
        let mut v = bytes;
        v[8] = 9;
        assert!(why(&v).contains("version 9"));
    }

    /// Every input of the key changes it: the files' bytes, the interface, its places, the
    /// modes, each part of an RBE clause. What the deck says picks the file (the slot),
    /// the files' bytes only the key within it.
    #[test]
    fn every_input_changes_the_key() {
        use crate::model::RbeSpec;
        let d = SuperelementData {
            dir: PathBuf::from("fe"),
            modes: 4,
            interface: vec![1, 2],
            modal: Vec::new(),
            rbe: vec![RbeSpec {
                kind: RbeKind::Average,
                node: 2,
                set: SetSpec::Nodes(vec![5, 6, 7]),
                weights: vec![1.0, 2.0, 3.0],
            }],
            cache: true,
        };
        let texts: [String; 4] = ["K".into(), "M".into(), "n".into(), "d".into()];
        let places = [Vector3::zeros(), Vector3::x()];
        let base = entry(&d, &texts, &places);
        assert_eq!(base, entry(&d, &texts, &places), "deterministic");
        assert!(base.path.starts_with("fe/.mecano-cache"));
        let mut keys = vec![base.clone()];
        for i in 0..4 {
            let mut t = texts.clone();
            t[i].push(' ');
            let e = entry(&d, &t, &places);
            assert_eq!(e.path, base.path, "the files' bytes keep the slot");
            keys.push(e);
        }
        let mut p = places;
        p[1].x = f64::from_bits(p[1].x.to_bits() + 1);
        keys.push(entry(&d, &texts, &p));
        type Edit = Box<dyn Fn(&mut SuperelementData)>;
        let edits: Vec<Edit> = vec![
            Box::new(|d| d.modes = 5),
            Box::new(|d| d.interface = vec![2, 1]),
            Box::new(|d| d.rbe[0].kind = RbeKind::Rigid),
            Box::new(|d| d.rbe[0].node = 1),
            Box::new(|d| d.rbe[0].set = SetSpec::Nodes(vec![5, 6, 8])),
            Box::new(|d| d.rbe[0].set = SetSpec::Within(0.1)),
            Box::new(|d| d.rbe[0].weights[2] = 3.5),
            Box::new(|d| d.rbe.clear()),
        ];
        for edit in edits {
            let mut e = d.clone();
            edit(&mut e);
            let k = entry(&e, &texts, &places);
            assert_ne!(k.path, base.path, "the deck's reduction picks the slot");
            keys.push(k);
        }
        for (i, a) in keys.iter().enumerate() {
            for b in &keys[i + 1..] {
                assert_ne!(a.key, b.key);
            }
        }
    }
}

//! Helpers shared by the integration tests (`mod common;` in each test file's root; the groups
//! `tests/<group>/main.rs` declare it once with `#[path = "../common/mod.rs"]`, and their
//! modules `use crate::common;`): the repository's
//! paths, its decks, and scratch directories that are removed when the test ends, whether it
//! passed, failed or panicked (issue 27 §3: no `mecano_*` directory left in the system's
//! temporary folder after a CI run).
//!
//! Each test binary compiles this module on its own, and uses only part of it.
#![allow(dead_code)]

pub mod impact;
pub mod oscillator;

use mecano::deck::load_deck;
use mecano::model::Model;
use std::path::{Path, PathBuf};

/// The repository's root (`CARGO_MANIFEST_DIR`).
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The path of `decks/<name>`; panics (the test fails) when the file does not exist, so a
/// renamed or deleted deck cannot make a test pass by skipping it.
pub fn deck_path(name: &str) -> PathBuf {
    let p = root().join("decks").join(name);
    assert!(p.is_file(), "deck {} is missing", p.display());
    p
}

/// `decks/<name>`, parsed and validated; panics (the test fails) when it is missing or bad.
pub fn deck(name: &str) -> Model {
    let p = deck_path(name);
    load_deck(&p).unwrap_or_else(|e| panic!("{}: {e:?}", p.display()))
}

/// A fresh, empty scratch directory that is removed, with all it holds, when dropped: at the
/// end of the test's scope, or while the test's panic unwinds. Named
/// `mecano_<name>_<pid>_<n>` in the system's temporary folder (`n` makes two guards of one
/// process with the same name distinct).
pub struct TempDir {
    path: PathBuf,
}

impl TempDir {
    /// Creates the directory (removing a stale one of the same name first).
    pub fn new(name: &str) -> TempDir {
        use std::sync::atomic::{AtomicUsize, Ordering};
        static COUNT: AtomicUsize = AtomicUsize::new(0);
        let n = COUNT.fetch_add(1, Ordering::Relaxed);
        let path = std::env::temp_dir().join(format!("mecano_{name}_{}_{n}", std::process::id()));
        let _ = std::fs::remove_dir_all(&path);
        std::fs::create_dir_all(&path)
            .unwrap_or_else(|e| panic!("creating {}: {e}", path.display()));
        TempDir { path }
    }

    /// The directory.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// `self.path().join(p)`.
    pub fn join(&self, p: impl AsRef<Path>) -> PathBuf {
        self.path.join(p)
    }
}

/// A `TempDir` stands where a path is asked for (`&d`, `d.join(..)`, `fs::…(&d)`).
impl std::ops::Deref for TempDir {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.path
    }
}

impl AsRef<std::ffi::OsStr> for TempDir {
    fn as_ref(&self) -> &std::ffi::OsStr {
        self.path.as_os_str()
    }
}

impl AsRef<Path> for TempDir {
    fn as_ref(&self) -> &Path {
        &self.path
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.path);
    }
}

/// Fails the test, saying why, when the binary under test has no failure-injection hook
/// (`MECANO_FAILPOINT`, `src/failpoint.rs`): a build without debug assertions and without the
/// feature `failpoints` (`cargo test --release` alone) would otherwise fail these tests in
/// ways that point elsewhere. The library and the binary are built in the same profile and
/// with the same features as this test, so `mecano::failpoint::ENABLED` speaks for both.
pub fn require_failpoints() {
    if !mecano::failpoint::ENABLED {
        panic!(
            "this test stops runs with MECANO_FAILPOINT, which this build does not have: \
             run it with debug assertions (`cargo test`) or `--features failpoints`"
        );
    }
}

/// Runs `mecano-rs <case>/d.dat -q -o <case>/out` and checks that the deck is refused as
/// input: exit code 2, `expect` in the message, no output directory written. Returns the
/// message, for the caller's check of where it points.
pub fn refused(case: &std::path::Path, name: &str, expect: &str) -> String {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
        .arg(case.join("d.dat"))
        .args(["-q", "-o"])
        .arg(case.join("out"))
        .output()
        .expect("runs");
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(2), "{name}: {err}");
    assert!(err.contains(expect), "{name}: `{expect}` not in: {err}");
    assert!(
        !case.join("out").exists(),
        "{name}: wrote its output directory"
    );
    err
}

//! The output directory is the run's alone (issue 35 §3): files planted in it by someone
//! else — links (dangling or not) under the names a run writes, a foreign file named like
//! a history, a `.mecano-lock` that is a link, a subdirectory or a link named `vtk`, a
//! hostile `.mecano-manifest` naming files in a linked or real subdirectory or outside —
//! never make a run write, create or delete anything outside the directory or in its
//! subdirectories. Each case plants its files beside a decoy tree and compares the decoy's
//! checksums (names, kinds, link targets, contents) before and after.

use crate::common;

use std::collections::BTreeMap;
use std::fs;
use std::os::unix::fs::symlink;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_mecano-rs"));
    c.env_remove("MECANO_FAILPOINT");
    c
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// A spring–mass deck of a few steps, writing node 2, element 1 (and VTK when `vtk`).
fn deck(dir: &Path, vtk: bool) -> PathBuf {
    let src = fs::read_to_string(common::deck_path("spring_mass.dat")).unwrap();
    let out = if vtk {
        "OUTPUT NODES 2 ELEMENTS 1 VTK"
    } else {
        "OUTPUT NODES 2 ELEMENTS 1"
    };
    let text: String = src
        .lines()
        .map(|l| {
            if l.starts_with("ANALYSIS") {
                l.replace("END 3.2", "END 0.005")
            } else if l.starts_with("OUTPUT") {
                out.to_string()
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    let p = dir.join(if vtk { "sm_vtk.dat" } else { "sm.dat" });
    fs::write(&p, text + "\n").unwrap();
    p
}

fn run(deck: &Path, out: &Path, extra: &[&str]) -> Output {
    bin()
        .arg(deck)
        .args(["-q", "--checkpoint", "0", "-o"])
        .arg(out)
        .args(extra)
        .output()
        .expect("the binary runs")
}

/// Every entry under `root` (not following links): its kind and content, or link target.
fn checksums(root: &Path) -> BTreeMap<PathBuf, String> {
    let mut out = BTreeMap::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            let m = fs::symlink_metadata(&p).unwrap();
            let v = if m.file_type().is_symlink() {
                format!("link -> {}", fs::read_link(&p).unwrap().display())
            } else if m.is_dir() {
                stack.push(p.clone());
                "dir".to_string()
            } else {
                let bytes = fs::read(&p).unwrap();
                use std::hash::{Hash, Hasher};
                let mut h = std::collections::hash_map::DefaultHasher::new();
                bytes.hash(&mut h);
                format!("file {} bytes {:x}", bytes.len(), h.finish())
            };
            out.insert(p.strip_prefix(root).unwrap().to_path_buf(), v);
        }
    }
    out
}

/// A scratch folder with `decoy/` (files, a subfolder) beside the output directory `out/`.
struct Scene {
    root: common::TempDir,
    deck: PathBuf,
    vtk_deck: PathBuf,
}

impl Scene {
    fn new(name: &str) -> Scene {
        let root = common::TempDir::new(&format!("hostile_{name}"));
        let decoy = root.join("decoy");
        fs::create_dir_all(decoy.join("inner")).unwrap();
        fs::write(decoy.join("victim.txt"), "precious").unwrap();
        fs::write(decoy.join("node_2.csv"), "not yours").unwrap();
        fs::write(decoy.join("inner/deep.txt"), "deep").unwrap();
        fs::create_dir_all(root.join("out")).unwrap();
        let (deck, vtk_deck) = (deck(&root, false), deck(&root, true));
        Scene {
            root,
            deck,
            vtk_deck,
        }
    }
    fn out(&self) -> PathBuf {
        self.root.join("out")
    }
    fn decoy(&self) -> PathBuf {
        self.root.join("decoy")
    }
    fn sums(&self) -> BTreeMap<PathBuf, String> {
        checksums(&self.decoy())
    }
}

/// Runs `deck` into the scene's `out/` with `extra`, expects `code` and a message holding
/// `says`, and asserts that the decoy tree is unchanged.
fn expect(s: &Scene, deck: &Path, extra: &[&str], code: i32, says: &str) -> Output {
    let before = s.sums();
    let o = run(deck, &s.out(), extra);
    assert_eq!(o.status.code(), Some(code), "{}", text(&o));
    assert!(
        text(&o).contains(says),
        "expected `{says}` in: {}",
        text(&o)
    );
    assert_eq!(s.sums(), before, "the decoy tree changed: {}", text(&o));
    o
}

#[test]
fn a_link_under_a_history_name_is_never_written_through_with_or_without_force() {
    let s = Scene::new("link");
    let out = s.out();
    symlink(s.decoy().join("victim.txt"), out.join("node_2.csv")).unwrap();
    // Without --force: a link no run wrote is foreign.
    expect(&s, &s.deck, &[], 2, "no mecano-rs run wrote");
    // With --force: the name is taken by a link; refused, not written through.
    expect(&s, &s.deck, &["--force"], 2, "symbolic link");
    // A dangling link under a name the run writes: nothing is created where it points.
    fs::remove_file(out.join("node_2.csv")).unwrap();
    symlink(s.decoy().join("created.csv"), out.join("energy.csv")).unwrap();
    expect(&s, &s.deck, &["--force"], 2, "symbolic link");
    assert!(!s.decoy().join("created.csv").exists());
    // A hostile manifest that lists the link does not make it the run's: a listed name
    // that is not a regular file is neither removed nor written through.
    fs::write(
        out.join(".mecano-manifest"),
        "# mecano-rs output manifest v1\nenergy.csv\n",
    )
    .unwrap();
    expect(&s, &s.deck, &[], 2, "symbolic link");
    assert!(fs::symlink_metadata(out.join("energy.csv")).is_ok());
}

#[test]
fn a_foreign_file_named_like_a_history_is_left_alone_with_force() {
    let s = Scene::new("foreign");
    let out = s.out();
    fs::write(out.join("node_2.csv"), "my notes").unwrap();
    expect(&s, &s.deck, &[], 2, "node_2.csv");
    let o = expect(&s, &s.deck, &["--force"], 2, "no mecano-rs run wrote");
    assert!(text(&o).contains("node_2.csv"), "{}", text(&o));
    assert_eq!(
        fs::read_to_string(out.join("node_2.csv")).unwrap(),
        "my notes"
    );
    // A foreign file the run does not write: --force runs beside it and leaves it.
    fs::rename(out.join("node_2.csv"), out.join("notes.txt")).unwrap();
    expect(&s, &s.deck, &["--force"], 0, "");
    assert_eq!(
        fs::read_to_string(out.join("notes.txt")).unwrap(),
        "my notes"
    );
    assert!(out.join("node_2.csv").is_file());
}

#[test]
fn a_hostile_manifest_removes_nothing_outside_the_directory_nor_in_a_subdirectory() {
    let s = Scene::new("manifest");
    let out = s.out();
    // `sub` links to the decoy, `real/` is a real subdirectory of the output directory.
    symlink(s.decoy(), out.join("sub")).unwrap();
    fs::create_dir_all(out.join("real")).unwrap();
    fs::write(out.join("real/inner.txt"), "mine").unwrap();
    symlink(s.decoy().join("victim.txt"), out.join("leaf")).unwrap();
    let decoy = s.decoy();
    let manifest = format!(
        "# mecano-rs output manifest v1\nsub\nleaf\nsub/victim.txt\nreal/inner.txt\nreal\n../decoy/victim.txt\n{}\n{}/inner/deep.txt\n./node_2.csv\nsub/\n.mecano-lock\n",
        decoy.join("victim.txt").display(),
        decoy.display()
    );
    fs::write(out.join(".mecano-manifest"), manifest).unwrap();
    // Every top-level name is listed (the manifest's), so the run goes on: it removes
    // none of them (links and a directory), and nothing through them.
    expect(&s, &s.deck, &[], 0, "");
    assert_eq!(
        fs::read_to_string(out.join("real/inner.txt")).unwrap(),
        "mine"
    );
    assert!(fs::symlink_metadata(out.join("sub")).is_ok());
    assert!(fs::symlink_metadata(out.join("leaf")).is_ok());
    // The run's own manifest lists plain names of its files only.
    let m = fs::read_to_string(out.join(".mecano-manifest")).unwrap();
    assert!(m.lines().skip(1).all(|l| !l.contains('/')), "{m}");
    // A second run removes the first's files and still nothing else (the links are
    // foreign now: --force).
    expect(&s, &s.deck, &["--force"], 0, "");
    assert_eq!(
        fs::read_to_string(out.join("real/inner.txt")).unwrap(),
        "mine"
    );
}

#[test]
fn a_lock_or_manifest_that_is_a_link_is_refused_and_nothing_is_created_where_it_points() {
    let s = Scene::new("lock");
    let out = s.out();
    // A dangling link as the lock: its target must not be created.
    symlink(s.decoy().join("lockfile"), out.join(".mecano-lock")).unwrap();
    expect(&s, &s.deck, &[], 2, "symbolic link");
    expect(&s, &s.deck, &["--force"], 2, "symbolic link");
    assert!(!s.decoy().join("lockfile").exists());
    // A link to an existing file as the lock.
    fs::remove_file(out.join(".mecano-lock")).unwrap();
    symlink(s.decoy().join("victim.txt"), out.join(".mecano-lock")).unwrap();
    expect(&s, &s.deck, &[], 2, "symbolic link");
    // resume takes the lock the same way.
    let before = s.sums();
    let o = bin().arg("resume").arg(&out).output().unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert_eq!(s.sums(), before);
    fs::remove_file(out.join(".mecano-lock")).unwrap();
    // The manifest a link (to a decoy file): refused, the decoy file neither read as a
    // manifest nor replaced.
    symlink(s.decoy().join("victim.txt"), out.join(".mecano-manifest")).unwrap();
    expect(&s, &s.deck, &[], 2, "symbolic link");
    expect(&s, &s.deck, &["--force"], 2, "symbolic link");
    fs::remove_file(out.join(".mecano-manifest")).unwrap();
    // The manifest's temporary name a link: refused, not written through.
    symlink(
        s.decoy().join("victim.txt"),
        out.join(".mecano-manifest.tmp"),
    )
    .unwrap();
    expect(&s, &s.deck, &[], 2, "symbolic link");
}

#[test]
fn a_vtk_name_that_is_a_link_or_a_foreign_directory_is_refused() {
    let s = Scene::new("vtk");
    let out = s.out();
    symlink(s.decoy(), out.join("vtk")).unwrap();
    expect(&s, &s.vtk_deck, &["--force"], 2, "vtk is a symbolic link");
    fs::remove_file(out.join("vtk")).unwrap();
    // A real directory named vtk that no run wrote: its files are not the run's to
    // replace.
    fs::create_dir_all(out.join("vtk")).unwrap();
    fs::write(out.join("vtk/frame_000000.vtu"), "theirs").unwrap();
    expect(
        &s,
        &s.vtk_deck,
        &[],
        2,
        "vtk/ is a directory no mecano-rs run wrote",
    );
    assert_eq!(
        fs::read_to_string(out.join("vtk/frame_000000.vtu")).unwrap(),
        "theirs"
    );
    fs::remove_dir_all(out.join("vtk")).unwrap();
    // The run's own vtk/: a second run replaces its frames; a frame replaced by a link
    // meanwhile is refused.
    expect(&s, &s.vtk_deck, &[], 0, "");
    assert!(out.join("vtk/frame_000000.vtu").is_file());
    expect(&s, &s.vtk_deck, &[], 0, "");
    fs::remove_file(out.join("vtk/frame_000001.vtu")).unwrap();
    symlink(
        s.decoy().join("victim.txt"),
        out.join("vtk/frame_000001.vtu"),
    )
    .unwrap();
    expect(&s, &s.vtk_deck, &[], 2, "not a regular file");
}

#[test]
fn a_checkpoint_that_is_a_link_is_not_read_by_resume() {
    let s = Scene::new("resume");
    let out = s.out();
    // A run stopped at its 2nd step leaves a checkpoint; replace it by a link to a copy.
    common::require_failpoints();
    let o = bin()
        .arg(&s.deck)
        .args(["-q", "-o"])
        .arg(&out)
        .env("MECANO_FAILPOINT", "signal:INT:2")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(130), "{}", text(&o));
    fs::copy(out.join("checkpoint.bin"), s.decoy().join("checkpoint.bin")).unwrap();
    fs::remove_file(out.join("checkpoint.bin")).unwrap();
    symlink(s.decoy().join("checkpoint.bin"), out.join("checkpoint.bin")).unwrap();
    let before = s.sums();
    let o = bin().arg("resume").arg(&out).output().unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("symbolic link"), "{}", text(&o));
    assert_eq!(s.sums(), before);
}

/// A FIFO planted under a run's file name is never waited on by the programs that read a
/// run's directory: `resume` (its summary.json; the fuzzer's case 35:6932 waited for a
/// writer for ever, deaf to Ctrl-C) and `compare` (a history) refuse it at once, exit 2.
#[test]
fn a_fifo_under_a_runs_file_name_is_refused_by_its_readers() {
    let s = Scene::new("fifo_read");
    let out = s.out();
    expect(&s, &s.deck, &[], 0, "");
    let reference = s.root.join("reference");
    fs::create_dir_all(&reference).unwrap();
    for f in ["node_2.csv", "summary.json"] {
        fs::copy(out.join(f), reference.join(f)).unwrap();
    }
    let mkfifo = |p: &Path| {
        let _ = fs::remove_file(p);
        let c = std::ffi::CString::new(p.as_os_str().as_encoded_bytes()).unwrap();
        // SAFETY: mkfifo(3) on a NUL-terminated path.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    };
    mkfifo(&out.join("summary.json"));
    let mut c = bin();
    c.arg("resume").arg(&out);
    let o = crate::resources::within(c, std::time::Duration::from_secs(120));
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    mkfifo(&out.join("node_2.csv"));
    let mut c = bin();
    c.arg("compare")
        .arg(&out)
        .arg(&reference)
        .args(["--nodes", "2"]);
    let o = crate::resources::within(c, std::time::Duration::from_secs(120));
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
}

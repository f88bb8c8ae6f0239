//! The superelement's reduction cache and its already reduced input (issue 38 §3;
//! docs/superelements.md, "Cache" and "Already reduced input"): the flexible pendulum of
//! `decks/superelement/pendulum_se.dat` copied with its FE files into a scratch directory
//! (the cache is written beside the files, never into the repository), run by the binary.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const FE_FILES: [&str; 4] = ["K.mtx", "M.mtx", "nodes.csv", "dofs.csv"];

/// The pendulum deck and its FE files `beam/` copied into `dir/name`.
fn setup(dir: &common::TempDir, name: &str) -> PathBuf {
    let case = dir.join(name);
    let src = common::root().join("decks/superelement");
    std::fs::create_dir_all(case.join("beam")).expect("dir");
    for f in FE_FILES {
        std::fs::copy(src.join("beam").join(f), case.join("beam").join(f)).expect("copy");
    }
    std::fs::copy(src.join("pendulum_se.dat"), case.join("d.dat")).expect("copy");
    case
}

/// Runs `deck` into `case/<out>` with `args`.
fn run(case: &Path, deck: &str, out: &str, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
        .current_dir(case)
        .arg(deck)
        .args(["-q", "--checkpoint", "0", "-o", out])
        .args(args)
        .output()
        .expect("runs")
}

/// A run that must succeed: its superelement's `reduction` block of summary.json, and its
/// standard error.
fn ok(case: &Path, deck: &str, out: &str, args: &[&str]) -> (serde_json::Value, String) {
    let o = run(case, deck, out, args);
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(o.status.success(), "{deck} {args:?}: {err}");
    let s: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(case.join(out).join("summary.json")).expect("summary"),
    )
    .expect("json");
    let red = find(&s, "reduction").expect("a reduction block in summary.json");
    (red, err)
}

/// The first value under `key` anywhere in `v`.
fn find(v: &serde_json::Value, key: &str) -> Option<serde_json::Value> {
    match v {
        serde_json::Value::Object(m) => m
            .get(key)
            .cloned()
            .or_else(|| m.values().find_map(|x| find(x, key))),
        serde_json::Value::Array(a) => a.iter().find_map(|x| find(x, key)),
        _ => None,
    }
}

fn source(red: &serde_json::Value) -> &str {
    red["source"].as_str().expect("source")
}

/// Every history (CSV) of run `a` equal byte for byte to run `b`'s.
fn same_histories(case: &Path, a: &str, b: &str) -> usize {
    let mut n = 0;
    for e in std::fs::read_dir(case.join(a)).expect("dir") {
        let p = e.expect("entry").path();
        if p.extension().is_some_and(|x| x == "csv") {
            let name = p.file_name().expect("name");
            let (x, y) = (
                std::fs::read(&p).expect("read"),
                std::fs::read(case.join(b).join(name)).expect("the same file"),
            );
            assert!(x == y, "{}: {a} and {b} differ", name.to_string_lossy());
            n += 1;
        }
    }
    assert!(n >= 3, "{n} histories");
    n
}

fn cache_files(case: &Path) -> Vec<PathBuf> {
    match std::fs::read_dir(case.join("beam/.mecano-cache")) {
        Ok(d) => d.map(|e| e.expect("entry").path()).collect(),
        Err(_) => Vec::new(),
    }
}

fn replace(p: &Path, from: &str, to: &str) {
    let t = std::fs::read_to_string(p).expect("read");
    assert!(t.contains(from), "{from} not in {}", p.display());
    std::fs::write(p, t.replacen(from, to, 1)).expect("write");
}

/// A second run of the same inputs reads the cache (summary.json says so) and writes the
/// same histories byte for byte; one byte of K, or another mode count, reduces again; an
/// edit of the FE files overwrites the deck's cache file rather than adding one.
#[test]
fn a_second_run_reads_the_cache_and_a_changed_input_does_not() {
    let dir = common::TempDir::new("se_cache");
    let case = setup(&dir, "hit");
    let (first, _) = ok(&case, "d.dat", "out1", &[]);
    assert_eq!(source(&first), "computed");
    let file = first["cache_file"].as_str().expect("written").to_string();
    assert!(case.join(&file).is_file(), "{file}");
    let (second, err) = ok(&case, "d.dat", "out2", &[]);
    assert_eq!(source(&second), "cache", "{second}");
    assert_eq!(second["cache_file"].as_str(), Some(file.as_str()));
    assert!(err.is_empty(), "a clean hit says nothing: {err}");
    let n = same_histories(&case, "out1", "out2");
    eprintln!("cache hit: {n} histories byte-identical to the run that reduced");
    // One byte of K (a digit of an entry): reduced again, the same file overwritten.
    let k = case.join("beam/K.mtx");
    let mut bytes = std::fs::read(&k).expect("K");
    let text = String::from_utf8(bytes.clone()).expect("text");
    let at = text.rfind('\n').expect("lines") - 1;
    assert!(bytes[at].is_ascii_digit() && bytes[at] != b'9');
    bytes[at] += 1;
    std::fs::write(&k, bytes).expect("write");
    let (edited, _) = ok(&case, "d.dat", "out3", &[]);
    assert_eq!(source(&edited), "computed");
    assert_eq!(cache_files(&case).len(), 1, "{:?}", cache_files(&case));
    // Another mode count: another slot, reduced, then read.
    let (two, _) = ok(&case, "d.dat", "out4", &["--set", "modes=2"]);
    assert_eq!(source(&two), "computed");
    assert_ne!(two["cache_file"], edited["cache_file"]);
    assert_eq!(cache_files(&case).len(), 2);
    let (again, _) = ok(&case, "d.dat", "out5", &["--set", "modes=2"]);
    assert_eq!(source(&again), "cache");
    same_histories(&case, "out4", "out5");
    // The edited model's cache is the edited model's.
    let (back, _) = ok(&case, "d.dat", "out6", &[]);
    assert_eq!(source(&back), "cache");
    same_histories(&case, "out3", "out6");
    // A deck that writes VTK needs the basis over the mesh, which the cache does not hold:
    // it reduces (its deformed mesh drawn), and the cache stays the same file.
    replace(
        &case.join("d.dat"),
        "OUTPUT NODES 1 2 ELEMENTS 2",
        "OUTPUT NODES 1 2 ELEMENTS 2 VTK",
    );
    let (vtk, _) = ok(&case, "d.dat", "out7", &[]);
    assert_eq!(source(&vtk), "computed");
    assert_eq!(vtk["cache_file"], back["cache_file"]);
    assert!(case.join("out7/vtk").is_dir());
}

/// A cache file that is torn, damaged or foreign is ignored with a warning, the body
/// reduced again (the same histories as a run without cache) and the file rewritten;
/// `CACHE OFF` writes nothing beside the FE files.
#[test]
fn a_damaged_cache_is_reduced_again_and_rewritten() {
    let dir = common::TempDir::new("se_cache_bad");
    let case = setup(&dir, "bad");
    let (first, _) = ok(&case, "d.dat", "ref", &[]);
    let file = case.join(first["cache_file"].as_str().expect("written"));
    let good = std::fs::read(&file).expect("cache");
    let damages: Vec<(&str, Vec<u8>, &str)> = vec![
        ("torn", good[..good.len() / 2].to_vec(), "torn"),
        ("empty", Vec::new(), "MECANOSE"),
        (
            "flipped",
            {
                let mut b = good.clone();
                let k = b.len() - 9;
                b[k] ^= 0x40;
                b
            },
            "checksum",
        ),
        (
            "version",
            {
                let mut b = good.clone();
                b[8] = 77;
                b
            },
            "version 77",
        ),
    ];
    for (name, bytes, why) in damages {
        std::fs::write(&file, bytes).expect("damage");
        let (red, err) = ok(&case, "d.dat", name, &[]);
        assert_eq!(source(&red), "computed", "{name}");
        assert!(
            err.contains("warning: element 2 (SUPERELEMENT): the reduction cache")
                && err.contains(why),
            "{name}: {err}"
        );
        same_histories(&case, "ref", name);
        assert_eq!(std::fs::read(&file).expect("rewritten"), good, "{name}");
    }
    // CACHE OFF: reduced, nothing written beside the files.
    let off = setup(&dir, "off");
    replace(
        &off.join("d.dat"),
        "INTERFACE 1 1 2 2",
        "INTERFACE 1 1 2 2 CACHE OFF",
    );
    let (red, err) = ok(&off, "d.dat", "out", &[]);
    assert_eq!(source(&red), "computed");
    assert_eq!(red["cache_note"].as_str(), Some("CACHE OFF"));
    assert!(err.is_empty(), "{err}");
    assert!(!off.join("beam/.mecano-cache").exists());
    same_histories(&case, "ref", "../off/out");
}

/// The cache is written as a run's files are (issue 35): a link planted at the cache
/// file's name is neither read nor written through (its target unchanged; the link
/// replaced by the cache), a link or a file at the cache directory's name means no
/// cache, said in a note, and the run goes on.
#[test]
fn the_cache_never_writes_through_a_link() {
    let dir = common::TempDir::new("se_cache_links");
    let case = setup(&dir, "links");
    let (first, _) = ok(&case, "d.dat", "ref", &[]);
    let file = case.join(first["cache_file"].as_str().expect("written"));
    let good = std::fs::read(&file).expect("cache");
    let decoy = dir.join("decoy.bin");
    std::fs::write(&decoy, b"keep").expect("decoy");
    std::fs::remove_file(&file).expect("rm");
    std::os::unix::fs::symlink(&decoy, &file).expect("link");
    let (red, err) = ok(&case, "d.dat", "link_file", &[]);
    assert_eq!(source(&red), "computed");
    assert!(err.contains("symbolic link"), "{err}");
    assert_eq!(std::fs::read(&decoy).expect("decoy"), b"keep");
    let meta = std::fs::symlink_metadata(&file).expect("cache");
    assert!(
        meta.file_type().is_file(),
        "the link is replaced by the cache"
    );
    assert_eq!(std::fs::read(&file).expect("cache"), good);
    // A link at the directory's name: no cache, a note.
    let cache_dir = case.join("beam/.mecano-cache");
    std::fs::remove_dir_all(&cache_dir).expect("rm");
    let decoy_dir = dir.join("decoy_dir");
    std::fs::create_dir(&decoy_dir).expect("decoy dir");
    std::os::unix::fs::symlink(&decoy_dir, &cache_dir).expect("link");
    let (red, err) = ok(&case, "d.dat", "link_dir", &[]);
    assert_eq!(source(&red), "computed");
    assert!(red["cache_file"].is_null(), "{red}");
    assert!(
        err.contains("note: element 2 (SUPERELEMENT): the reduction is not cached"),
        "{err}"
    );
    assert_eq!(std::fs::read_dir(&decoy_dir).expect("decoy").count(), 0);
    same_histories(&case, "ref", "link_dir");
    // A file at the directory's name (as a directory that cannot be made): the same.
    std::fs::remove_file(&cache_dir).expect("rm link");
    std::fs::write(&cache_dir, b"not a directory").expect("file");
    let (red, err) = ok(&case, "d.dat", "file_dir", &[]);
    assert!(
        red["cache_file"].is_null() && err.contains("not cached"),
        "{err}"
    );
    // A read-only FILES directory (not for root, who writes anyway).
    // SAFETY: geteuid(2) has no preconditions.
    if unsafe { libc::geteuid() } != 0 {
        use std::os::unix::fs::PermissionsExt;
        let ro = setup(&dir, "ro");
        let beam = ro.join("beam");
        std::fs::set_permissions(&beam, std::fs::Permissions::from_mode(0o555)).expect("chmod");
        let (red, err) = ok(&ro, "d.dat", "out", &[]);
        std::fs::set_permissions(&beam, std::fs::Permissions::from_mode(0o755)).expect("chmod");
        assert!(
            red["cache_file"].is_null() && err.contains("not cached"),
            "{err}"
        );
    }
}

/// `export --reduced` writes the superelement's reduced set; a deck reading it runs to the
/// same histories as the deck that reduced, byte for byte: every number of the set is
/// written in ryu's shortest form that reads back to the same double, and the interface
/// places relative to a frame node at the origin, so the body read is the body reduced.
#[test]
fn a_reduced_set_runs_as_the_full_model() {
    let dir = common::TempDir::new("se_reduced");
    let case = setup(&dir, "red");
    let o = Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
        .current_dir(&case)
        .args(["export", "d.dat", "--reduced", "2", "-q", "-o", "set"])
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let full = std::fs::read_to_string(case.join("d.dat")).expect("deck");
    std::fs::write(case.join("r.dat"), full.replace("FILES beam", "FILES set")).expect("deck");
    let (red, _) = ok(&case, "r.dat", "from_set", &[]);
    assert_eq!(source(&red), "reduced files");
    let (_, _) = ok(&case, "d.dat", "from_fe", &[]);
    let n = same_histories(&case, "from_fe", "from_set");
    eprintln!("reduced set: {n} histories byte-identical to the full model's");
    assert!(!case.join("set/.mecano-cache").exists());
    // The plate, whose interfaces are an RBE2 and an RBE3 (interface nodes that are not
    // FE nodes, placed at their deck nodes): its set runs without the RBE clauses.
    let plate = dir.join("plate");
    let src = common::root().join("decks/superelement");
    std::fs::create_dir_all(plate.join("plate")).expect("dir");
    for f in FE_FILES {
        std::fs::copy(src.join("plate").join(f), plate.join("plate").join(f)).expect("copy");
    }
    std::fs::copy(src.join("plate_pendulum.dat"), plate.join("p.dat")).expect("copy");
    let o = Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
        .current_dir(&plate)
        .args(["export", "p.dat", "--reduced", "2", "-q", "-o", "set"])
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let deck = std::fs::read_to_string(plate.join("p.dat")).expect("deck");
    let clauses = " RBE2 1000 SET 1 TO 11 RBE3 2000 SET 65 66 76 77";
    assert!(deck.contains(clauses));
    let reduced = deck
        .replace(clauses, "")
        .replace("FILES plate", "FILES set");
    std::fs::write(plate.join("r.dat"), reduced).expect("deck");
    let (red, _) = ok(&plate, "r.dat", "from_set", &[]);
    assert_eq!(source(&red), "reduced files");
    ok(&plate, "p.dat", "from_fe", &[]);
    let n = same_histories(&plate, "from_fe", "from_set");
    eprintln!("reduced plate (RBE2, RBE3): {n} histories byte-identical to the full model's");
}

/// Bad reduced sets: located errors at the card, exit 2, nothing written.
#[test]
fn bad_reduced_sets_are_refused_located() {
    let dir = common::TempDir::new("se_reduced_bad");
    let base = setup(&dir, "base");
    let o = Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
        .current_dir(&base)
        .args(["export", "d.dat", "--reduced", "2", "-q", "-o", "set"])
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    type Edit = Box<dyn Fn(&Path)>;
    let cases: Vec<(&str, Edit, &str)> = vec![
        (
            "malformed",
            Box::new(|c: &Path| replace(&c.join("set/Kr.mtx"), "\n1 1 ", "\n1 x ")),
            "Kr.mtx:4:3: expected a column index, found `x`",
        ),
        (
            "truncated_g",
            Box::new(|c: &Path| {
                let p = c.join("set/G.mtx");
                let t = std::fs::read_to_string(&p).expect("G");
                let cut: Vec<&str> = t.lines().take(20).collect();
                std::fs::write(&p, cut.join("\n")).expect("write");
            }),
            "G.mtx:20:1: truncated",
        ),
        (
            "other_modes",
            Box::new(|c: &Path| replace(&c.join("d.dat"), "modes 4", "modes 2")),
            "Kr.mtx: 10 × 10, but the deck's INTERFACE (2 nodes) and MODES 2 make n = 6·1 + 2 = 8",
        ),
        (
            "negative_mass",
            Box::new(|c: &Path| replace(&c.join("set/body.csv"), "\n7.0", "\n-7.0")),
            "body.csv:2:1: expected a mass > 0 kg, found `-7.019999999999998`",
        ),
        (
            "other_mass",
            Box::new(|c: &Path| replace(&c.join("set/body.csv"), "\n7.0", "\n8.0")),
            "body.csv:2:1: the mass 8.019999999999998 kg is not M0.mtx's first entry",
        ),
        (
            "indefinite",
            Box::new(|c: &Path| {
                // 𝕄₀'s last diagonal entry made negative.
                let p = c.join("set/M0.mtx");
                let t = std::fs::read_to_string(&p).expect("M0");
                let last = t.lines().last().expect("entry").to_string();
                let f: Vec<&str> = last.split(' ').collect();
                assert_eq!(f[0], f[1], "{last}");
                replace(&p, &last, &format!("{} {} -{}", f[0], f[1], f[2]));
            }),
            "M0.mtx: 𝕄₀ is not positive definite",
        ),
        (
            "other_interface",
            Box::new(|c: &Path| replace(&c.join("set/interface.csv"), "\n2,", "\n3,")),
            "lists the interface FE nodes 1, 3, the deck's INTERFACE 1, 2 (the same nodes",
        ),
        (
            "misplaced",
            Box::new(|c: &Path| replace(&c.join("d.dat"), "  2 1 0 0\n", "  2 1.1 0 0\n")),
            "interface FE node 2 is at [1.1, 0.0, 0.0] from the frame node in the deck",
        ),
        (
            "missing_file",
            Box::new(|c: &Path| std::fs::remove_file(c.join("set/H.mtx")).expect("rm")),
            "H.mtx:0:0: cannot read",
        ),
        (
            "rbe",
            Box::new(|c: &Path| {
                replace(
                    &c.join("d.dat"),
                    "INTERFACE 1 1 2 2",
                    "INTERFACE 1 1 2 2 RBE2 2 SET 3",
                )
            }),
            "holds a reduced set: its interfaces were made before the reduction",
        ),
    ];
    for (name, edit, expect) in cases {
        let case = dir.join(name);
        std::fs::create_dir_all(case.join("set")).expect("dir");
        for f in std::fs::read_dir(base.join("set")).expect("set") {
            let p = f.expect("entry").path();
            std::fs::copy(&p, case.join("set").join(p.file_name().expect("name"))).expect("cp");
        }
        let deck = std::fs::read_to_string(base.join("d.dat")).expect("deck");
        std::fs::write(case.join("d.dat"), deck.replace("FILES beam", "FILES set")).expect("w");
        edit(&case);
        let err = common::refused(&case, name, expect);
        assert!(
            err.contains("d.dat: line 15:3: element 2: SUPERELEMENT"),
            "{name}: {err}"
        );
    }
}

/// `CACHE OFF` reads to a model without cache, prints back as itself (the writer), and is
/// refused with anything but ON or OFF after it; the default is ON.
#[test]
fn cache_off_round_trips_through_the_writer() {
    use mecano::deck::{parse_deck, strip_spans, write_deck};
    use mecano::model::ElementKind;
    let deck = |tail: &str| {
        format!(
            "TITLE c\nNODES\n  1 0 0 0\n  2 1 0 0\nELEMENTS\n  1 SUPERELEMENT FILES beam MODES 2 INTERFACE 1 1 2 2{tail}\nANALYSIS DYNAMIC STEP 1e-3 END 1e-2\nEND\n"
        )
    };
    let cache_of = |m: &mecano::model::Model| match &m.elements[0].kind {
        ElementKind::Superelement(d) => d.cache,
        _ => panic!("a superelement"),
    };
    let mut first = parse_deck(&deck(" CACHE OFF"), "c.dat").expect("valid");
    assert!(!cache_of(&first));
    let text = write_deck(&first);
    assert!(text.contains("CACHE OFF"), "{text}");
    let mut second = parse_deck(&text, "written").expect("valid");
    strip_spans(&mut first);
    strip_spans(&mut second);
    assert_eq!(first, second);
    let on = parse_deck(&deck(" CACHE ON"), "c.dat").expect("valid");
    assert!(cache_of(&on) && cache_of(&parse_deck(&deck(""), "c.dat").expect("valid")));
    assert!(!write_deck(&on).contains("CACHE"));
    let bad = parse_deck(&deck(" CACHE MAYBE"), "c.dat").expect_err("refused");
    assert!(
        format!("{bad:?}").contains("ON or OFF after CACHE"),
        "{bad:?}"
    );
}

//! The cases the fuzzer (`benches/fuzz/fuzz.py`, issue 35 §6) found, and the probe's, kept
//! as regression tests: each `tests/deck/fuzz/*.dat` is a deck whose leading comments say
//! how to run it and what must come out:
//!
//! ```text
//! ! args: -q -o out --force        (the deck's path is put first; `--check`, `modes` …)
//! ! expect: 2                      (the exit codes allowed)
//! ! plant: node_2.csv link         (planted in out/ first: link, dangling, file, dir, fifo)
//! ```
//!
//! Each runs through the binary in a sandbox beside a decoy tree, under a time limit far
//! beyond what it takes (a hang fails the test, it does not hang it), and must exit with an
//! allowed code, never panic, and leave the decoy and everything outside `out/` unchanged —
//! the fuzzer's oracle.

use crate::common;

use std::collections::BTreeMap;
use std::fs;
use std::os::unix::fs::symlink;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Far beyond any case (each takes well under a second): only a hang reaches it.
const LIMIT: Duration = Duration::from_secs(120);

struct Case {
    path: PathBuf,
    args: Vec<String>,
    expect: Vec<i32>,
    plants: Vec<(String, String)>,
}

fn cases() -> Vec<Case> {
    let dir = common::root().join("tests/deck/fuzz");
    let mut paths: Vec<PathBuf> = fs::read_dir(&dir)
        .expect("tests/deck/fuzz")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "dat"))
        .collect();
    paths.sort();
    paths
        .into_iter()
        .map(|path| {
            let text = fs::read_to_string(&path).unwrap();
            let (mut args, mut expect, mut plants) = (Vec::new(), Vec::new(), Vec::new());
            for l in text.lines().take_while(|l| l.starts_with('!')) {
                if let Some(a) = l.strip_prefix("! args:") {
                    args = a.split_whitespace().map(str::to_string).collect();
                } else if let Some(e) = l.strip_prefix("! expect:") {
                    expect = e.split_whitespace().map(|c| c.parse().unwrap()).collect();
                } else if let Some(p) = l.strip_prefix("! plant:") {
                    let mut w = p.split_whitespace();
                    plants.push((w.next().unwrap().into(), w.next().unwrap().into()));
                }
            }
            assert!(
                !expect.is_empty(),
                "{}: no `! expect:` line",
                path.display()
            );
            Case {
                path,
                args,
                expect,
                plants,
            }
        })
        .collect()
}

/// Every entry under `root` (not following links): its kind and content or target.
fn checksums(root: &Path) -> BTreeMap<PathBuf, String> {
    let mut out = BTreeMap::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            let m = fs::symlink_metadata(&p).unwrap();
            let v = if m.file_type().is_symlink() {
                format!("link {}", fs::read_link(&p).unwrap().display())
            } else if m.is_dir() {
                stack.push(p.clone());
                "dir".into()
            } else {
                format!("{:?}", fs::read(&p).unwrap())
            };
            out.insert(p.strip_prefix(root).unwrap().to_path_buf(), v);
        }
    }
    out
}

fn plant(out: &Path, decoy: &Path, name: &str, kind: &str) {
    fs::create_dir_all(out).unwrap();
    let p = out.join(name);
    match kind {
        "link" => symlink(decoy.join("victim.txt"), &p).unwrap(),
        "dangling" => symlink(decoy.join(format!("nowhere_{name}")), &p).unwrap(),
        "dirlink" => symlink(decoy.join("inner"), &p).unwrap(),
        "file" => fs::write(&p, "foreign\n").unwrap(),
        "dir" => fs::create_dir_all(p.join("deep")).unwrap(),
        "fifo" => {
            let c = std::ffi::CString::new(p.as_os_str().as_encoded_bytes()).unwrap();
            // SAFETY: mkfifo(3) on a NUL-terminated path.
            assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        }
        "manifest" => fs::write(
            &p,
            format!(
                "# mecano-rs output manifest v1\nsub/victim.txt\n../decoy/victim.txt\n{}\nnode_2.csv\nvtk/\n",
                decoy.join("victim.txt").display()
            ),
        )
        .unwrap(),
        _ => panic!("unknown plant {kind}"),
    }
}

#[test]
fn the_fuzzers_cases_end_as_expected_and_touch_nothing_outside() {
    let all = cases();
    assert!(all.len() >= 10, "{} cases", all.len());
    for case in &all {
        let name = case
            .path
            .file_name()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        let sandbox = common::TempDir::new(&format!("fuzz_{}", name.trim_end_matches(".dat")));
        fs::copy(&case.path, sandbox.join("deck.dat")).unwrap();
        let decoy = sandbox.join("decoy");
        fs::create_dir_all(decoy.join("inner")).unwrap();
        fs::write(decoy.join("victim.txt"), "precious\n").unwrap();
        fs::write(decoy.join("inner/deep.txt"), "deep\n").unwrap();
        for (n, k) in &case.plants {
            plant(&sandbox.join("out"), &decoy, n, k);
        }
        let before = checksums(&decoy);
        let mut args: Vec<String> = case.args.clone();
        // `modes` comes before the deck; everything else after it; `resume` takes no deck.
        if args.first().is_none_or(|a| a != "resume") {
            let at = usize::from(args.first().is_some_and(|a| a == "modes"));
            args.insert(at, "deck.dat".into());
        }
        let mut child = Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
            .args(&args)
            .current_dir(sandbox.path())
            .env_remove("MECANO_FAILPOINT")
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let t0 = Instant::now();
        while child.try_wait().unwrap().is_none() {
            if t0.elapsed() > LIMIT {
                let _ = child.kill();
                panic!("{name}: still running after {LIMIT:?} (a hang): {args:?}");
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        let o = child.wait_with_output().unwrap();
        let text = format!(
            "{}{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        );
        let code = o.status.code();
        assert!(
            code.is_some_and(|c| case.expect.contains(&c)),
            "{name}: exit {code:?}, expected {:?}: {args:?}\n{text:.3000}",
            case.expect
        );
        assert!(!text.contains("panicked"), "{name}: {text:.3000}");
        assert_eq!(checksums(&decoy), before, "{name}: the decoy changed");
        let mut entries: Vec<String> = fs::read_dir(sandbox.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        entries.sort();
        entries.retain(|e| !["deck.dat", "decoy", "out"].contains(&e.as_str()));
        assert!(
            entries.is_empty(),
            "{name}: written beside out/: {entries:?}"
        );
    }
}

//! No hang, no abort (issue 35 §1, §2): values whose physical scale overflows are refused
//! as input, located (file:line:col), exit 2 — in runs, `--check` and `modes`, each within
//! a subprocess time limit far beyond what it takes (a hang fails the test, it does not
//! hang it); a model too large for the memory given is refused with the figure; the
//! allocations of a model that passes the estimate are fallible, so that running out of
//! address space is an error, not SIGABRT; a deck path that is a device or a directory is
//! refused unread.

use crate::common;

use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn bin() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_mecano-rs"));
    c.env_remove("MECANO_FAILPOINT");
    c
}

/// Standard output and error, with miette's wrapping undone (its `│` margins and line
/// breaks become single blanks), so that a phrase can be looked for whole.
fn text(o: &Output) -> String {
    let raw = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    raw.replace('│', " ")
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
}

/// Runs `cmd` to its end, or kills it and fails the test after `limit` (a hang).
pub fn within(mut cmd: Command, limit: Duration) -> Output {
    let mut child = cmd
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary starts");
    let t0 = Instant::now();
    loop {
        if child.try_wait().expect("wait").is_some() {
            return child.wait_with_output().expect("output");
        }
        if t0.elapsed() > limit {
            let _ = child.kill();
            let o = child.wait_with_output().expect("output");
            panic!("still running after {limit:?} (a hang): {}", text(&o));
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// A limit no refusal comes near (each takes well under a second): generous, so that a
/// loaded machine never fails it; a hang fails it.
const LIMIT: Duration = Duration::from_secs(120);

fn scratch(name: &str) -> common::TempDir {
    common::TempDir::new(&format!("resources_{name}"))
}

fn deck_text(name: &str) -> String {
    fs::read_to_string(common::deck_path(name)).unwrap()
}

/// `text` with `from` replaced by `to` (which must occur), written as `dir/name`.
fn variant(dir: &Path, name: &str, text: &str, from: &str, to: &str) -> PathBuf {
    assert!(text.contains(from), "{from}");
    let p = dir.join(name);
    fs::write(&p, text.replacen(from, to, 1)).unwrap();
    p
}

/// The line and column `mecano-rs` locates an error at, as `name:LINE:COL`.
fn located(out: &str, name: &str, line: usize) -> bool {
    out.contains(&format!("{name}:{line}:"))
}

/// 1e308 in a stiffness (BUSHING, SPRING, PROPERTIES EA), a coordinate, gravity, a moment
/// or a SINE frequency: each overflowed at run time (the step-resolution modes' loop never
/// ended on the stiffnesses, whatever the signal; the others failed with exit 1, some
/// blaming a "singular mass matrix"). Now refused as input at its field, exit 2, by a run,
/// `--check` and `modes` alike.
#[test]
fn values_whose_scale_overflows_are_refused_as_input_located() {
    let d = scratch("scale");
    let bushing = deck_text("bushing_mass.dat");
    let spring = deck_text("spring_mass.dat");
    let rotating = deck_text("rotating_cantilever.dat");
    let pendulum = deck_text("pendulum.dat");
    let cases = [
        variant(&d, "bushing.dat", &bushing, "K 1000 2000", "K 1e308 2000"),
        variant(&d, "spring.dat", &spring, "k 800", "k 1e308"),
        variant(&d, "ea.dat", &rotating, "EA 1e7", "EA 1e308"),
        variant(&d, "coord.dat", &pendulum, "24  0 -1.8 0", "24  0 -1e308 0"),
        variant(
            &d,
            "gravity.dat",
            &pendulum,
            "GRAVITY 0 -9.81 0",
            "GRAVITY 0 -1e308 0",
        ),
        variant(
            &d,
            "moment.dat",
            &pendulum,
            "0 0 -1000  FUNCTION 1",
            "0 0 -1e308  FUNCTION 1",
        ),
        variant(
            &d,
            "sine.dat",
            &pendulum,
            "1 TABLE  0 0  0.01 1  0.02 0",
            "1 SINE 1 FREQ 1e308",
        ),
        variant(&d, "tiny.dat", &pendulum, "STEP 1e-4", "STEP 1e-300"),
    ];
    for deck in &cases {
        let name = deck.file_name().unwrap().to_string_lossy().into_owned();
        for args in [vec!["--check"], vec!["-q", "-o"], vec!["modes", "-q", "-o"]] {
            let mut c = bin();
            let out = d.join(format!("out_{name}"));
            match args[0] {
                "--check" => c.arg("--check").arg(deck),
                "modes" => c.args(["modes", "-q", "-o"]).arg(&out).arg(deck),
                _ => c.args(["-q", "-o"]).arg(&out).arg(deck),
            };
            let o = within(c, LIMIT);
            let t = text(&o);
            assert_eq!(o.status.code(), Some(2), "{name} {args:?}: {t}");
            assert!(
                t.contains("out of range") && t.contains("1e-100 to 1e100"),
                "{name} {args:?}: {t}"
            );
            // Located: the deck's name with a line and column.
            assert!(t.contains(&format!("{name}:")), "{name} {args:?}: {t}");
            assert!(!out.exists(), "{name} {args:?}: nothing is written");
        }
    }
    // The pendulum's coordinate is on its line 23 (`24  0 -1e308 0`).
    let o = within(
        {
            let mut c = bin();
            c.arg("--check").arg(d.join("coord.dat"));
            c
        },
        LIMIT,
    );
    let line = pendulum
        .lines()
        .position(|l| l.contains("24  0 -1.8 0"))
        .unwrap()
        + 1;
    assert!(located(&text(&o), "coord.dat", line), "{}", text(&o));
}

/// A model beyond `--max-memory` is refused before it is built, with the figure and the
/// place that asks for it; the process stays small (the refusal costs a parse).
#[test]
fn a_model_beyond_max_memory_is_refused_with_its_figure() {
    let d = scratch("memory");
    let pendulum = deck_text("pendulum.dat");
    let deck = variant(
        &d,
        "divided.dat",
        &pendulum,
        "2 TO 11  BEAM 2 3  MAT 1 SEC 1",
        "2 TO 11  BEAM 2 3  MAT 1 SEC 1 DIVIDE 1000000",
    );
    for args in [
        vec!["--check", "--max-memory", "1G"],
        vec!["-q", "--max-memory", "1G"],
        vec!["modes", "-q", "--max-memory", "1G"],
    ] {
        let mut c = bin();
        c.args(&args).arg(&deck);
        let o = within(c, LIMIT);
        let t = text(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {t}");
        assert!(
            t.contains("DIVIDE 1000000")
                && t.contains("GB")
                && t.contains("1.074 GB of --max-memory"),
            "{args:?}: {t}"
        );
        assert!(t.contains("divided.dat:34:3"), "{args:?}: {t}");
    }
    // --refine of the pendulum by a million: refused with the figure, whatever the machine
    // (its 20 million elements need some 180 GB).
    let mut c = bin();
    c.args(["--check", "--refine", "1000000", "--max-memory", "64G"])
        .arg(common::deck_path("pendulum.dat"));
    let o = within(c, LIMIT);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("refined 1000000 times"), "{}", text(&o));
    // A bad size is refused by the command line.
    let mut c = bin();
    c.args(["--check", "--max-memory", "lots"])
        .arg(common::deck_path("pendulum.dat"));
    let o = within(c, LIMIT);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
}

/// With the estimate lifted (`--max-memory 1000T`) and the address space limited to 1 GiB
/// (setrlimit), dividing the pendulum's bars a million times each runs out of memory: the
/// generated nodes and elements are reserved fallibly, so it is an error naming the
/// allocation (exit 2), not an abort (SIGABRT, exit 134).
#[test]
fn running_out_of_address_space_is_an_error_not_an_abort() {
    let d = scratch("rlimit");
    let pendulum = deck_text("pendulum.dat");
    let deck = variant(
        &d,
        "divided.dat",
        &pendulum,
        "2 TO 11  BEAM 2 3  MAT 1 SEC 1",
        "2 TO 11  BEAM 2 3  MAT 1 SEC 1 DIVIDE 1000000",
    );
    for extra in [vec![], vec!["--refine", "1000000"]] {
        let mut c = bin();
        let src = if extra.is_empty() {
            deck.clone()
        } else {
            common::deck_path("pendulum.dat")
        };
        c.args(["--check", "--max-memory", "1000T"])
            .args(&extra)
            .arg(src);
        // SAFETY: setrlimit(2) between fork and exec touches no memory of the parent.
        unsafe {
            use std::os::unix::process::CommandExt;
            c.pre_exec(|| {
                let lim = libc::rlimit {
                    rlim_cur: 1 << 30,
                    rlim_max: 1 << 30,
                };
                if libc::setrlimit(libc::RLIMIT_AS, &lim) != 0 {
                    return Err(std::io::Error::last_os_error());
                }
                Ok(())
            });
        }
        let o = within(c, LIMIT);
        let t = text(&o);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {t}");
        assert!(t.contains("could not be allocated"), "{extra:?}: {t}");
    }
}

/// A deck path that is a device or a directory is refused unread (`/dev/zero` was read
/// until the kernel killed the process, 25 GB).
#[test]
fn a_deck_path_that_is_not_a_file_or_a_pipe_is_refused() {
    for (p, says) in [
        ("/dev/zero", "a device"),
        ("/dev/urandom", "a device"),
        ("/", "a directory"),
    ] {
        for check in [true, false] {
            let mut c = bin();
            if check {
                c.arg("--check");
            } else {
                c.args(["modes", "-q"]);
            }
            c.arg(p);
            let o = within(c, LIMIT);
            assert_eq!(o.status.code(), Some(2), "{p}: {}", text(&o));
            assert!(text(&o).contains(says), "{p}: {}", text(&o));
        }
    }
}

/// A phase that polls no flag (the dense eigen-solver's QR of `--check`'s step-resolution
/// table: ~10 s on this deck) ends at once on SIGINT, also when the process was started
/// with SIGINT ignored, as a script's background job is (`main` gives SIGINT and SIGTERM
/// their default action back). Before, it ran to its end through the signal (the fuzzer's
/// case 17:6222, 15 s).
#[test]
fn check_ends_on_sigint_even_when_started_with_it_ignored() {
    use std::os::unix::process::CommandExt;
    let deck = common::root().join("tests/data/slow_check/deck.dat");
    let mut c = bin();
    c.arg("--check").arg(&deck);
    // SAFETY: `signal` with `SIG_IGN` in the forked child before exec: async-signal-safe.
    unsafe {
        c.pre_exec(|| {
            libc::signal(libc::SIGINT, libc::SIG_IGN);
            Ok(())
        });
    }
    let mut child = c
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("starts");
    // Into the deck's reading and the model's checks, before the QR's end.
    std::thread::sleep(Duration::from_millis(300));
    let t0 = Instant::now();
    // SAFETY: kill(2) on our own child's pid.
    unsafe {
        libc::kill(child.id() as i32, libc::SIGINT);
    }
    let limit = Duration::from_secs(5);
    loop {
        if let Some(status) = child.try_wait().expect("wait") {
            use std::os::unix::process::ExitStatusExt;
            // Ended by the signal itself (the QR alone takes seconds: it cannot have
            // finished first).
            assert_eq!(status.signal(), Some(libc::SIGINT), "{status:?}");
            break;
        }
        if t0.elapsed() > limit {
            let _ = child.kill();
            panic!("--check sat through SIGINT for {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

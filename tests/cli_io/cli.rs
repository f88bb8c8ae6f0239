//! The command line: a deck with errors exits with code 2 and writes nothing.

use crate::common;

use std::process::Command;

#[test]
fn a_bad_deck_exits_with_code_2_and_creates_no_output_directory() {
    let tmp = common::TempDir::new("cli");
    std::fs::create_dir_all(&tmp).unwrap();
    let deck = tmp.join("bad.dat");
    std::fs::write(
        &deck,
        "TITLE bad\nNODES\n  1 0 0 0\nELEMENTS\n  2 BEAM 1 7 MAT 1 SEC 1\n",
    )
    .unwrap();
    let out_dir = tmp.join("out");
    let out = Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
        .arg(&deck)
        .arg("-o")
        .arg(&out_dir)
        .output()
        .expect("binary runs");
    let err = String::from_utf8_lossy(&out.stderr);
    println!("{err}");
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("undefined node 7"), "{err}");
    assert!(
        !out_dir.exists(),
        "an output directory was created for a bad deck"
    );
    // Without -o: the default out/<deck name>/ is not created either (run from tmp).
    let out = Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
        .arg("bad.dat")
        .current_dir(&tmp)
        .output()
        .expect("binary runs");
    assert_eq!(out.status.code(), Some(2));
    assert!(!tmp.join("out").exists());
    let _ = std::fs::remove_dir_all(&tmp);
}

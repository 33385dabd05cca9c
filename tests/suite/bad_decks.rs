//! Every class of bad input is reported as `file:line:col: message` and exits
//! non-zero before any output exists (issue: engine core).
//!
//! Each `tests/decks/bad/*.in` starts with `# expect: MESSAGE`, the exact
//! error the deck must produce (paths relative to the repository root).

use std::path::Path;
use std::process::Command;

use cellmd::deck::validate_file;

fn bad_decks() -> Vec<(String, String)> {
    let mut decks = Vec::new();
    for entry in std::fs::read_dir("tests/decks/bad").unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "in") {
            let text = std::fs::read_to_string(&path).unwrap();
            let expected = text
                .lines()
                .next()
                .and_then(|l| l.strip_prefix("# expect: "))
                .unwrap_or_else(|| panic!("{} lacks a `# expect: MESSAGE` first line", path.display()))
                .to_string();
            decks.push((path.to_str().unwrap().to_string(), expected));
        }
    }
    decks.sort();
    decks
}

#[test]
fn every_bad_deck_fails_with_its_expected_message() {
    let decks = bad_decks();
    assert!(decks.len() >= 25, "only {} bad decks", decks.len());
    let mut mismatches = Vec::new();
    for (path, expected) in &decks {
        match validate_file(Path::new(path), &[]) {
            Ok(_) => mismatches.push(format!("{path}: validated, expected `{expected}`")),
            Err(e) if e.to_string() != *expected => mismatches.push(format!("{path}:\n  got      {e}\n  expected {expected}")),
            Err(_) => {}
        }
    }
    assert!(mismatches.is_empty(), "{}", mismatches.join("\n"));
}

#[test]
fn the_cli_exits_non_zero_and_writes_nothing() {
    let out = tempfile::tempdir().unwrap();
    for (path, expected) in bad_decks() {
        for sub in ["check", "run"] {
            let mut cmd = Command::new(env!("CARGO_BIN_EXE_cellmd"));
            cmd.arg(sub).arg(&path);
            if sub == "run" {
                cmd.arg("-o").arg(out.path());
            }
            let result = cmd.output().unwrap();
            assert!(!result.status.success(), "{sub} {path} succeeded");
            let stderr = String::from_utf8_lossy(&result.stderr);
            assert!(stderr.contains(&expected), "{sub} {path}: stderr lacks `{expected}`:\n{stderr}");
        }
    }
    let written: Vec<_> = std::fs::read_dir(out.path()).unwrap().collect();
    assert!(written.is_empty(), "bad decks wrote {written:?}");
}

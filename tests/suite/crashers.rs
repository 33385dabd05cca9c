//! Every input that ever crashed, hung or passed silently (issue 21's fuzz
//! findings) now ends quickly with its diagnosis and the right exit status.
//!
//! Committed cases are `tests/decks/crashers/*.in`, each starting with
//! `# expect: TEXT` (in stderr; empty for a run that must succeed) and
//! `# exit: STATUS`; inputs too large to commit (a 1 MB line, 40 000 nested
//! parentheses, a FIFO) are generated here. Parse-time findings with exact
//! messages (duplicate bonds, box overflow, coincident particles, `/dev/zero`
//! as a topology, doubling variables) are bad decks in `tests/decks/bad/`.

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The bad decks' directory, with a valid topology and force field.
const BAD: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/decks/bad");

/// Generous: every case takes well under a second in the test profile.
const LIMIT: Duration = Duration::from_secs(60);

struct Outcome {
    status: i32,
    stderr: String,
    seconds: f64,
}

/// `cellmd ARGS` with a time limit (a hang fails the test instead of blocking it).
fn cellmd(args: &[&str]) -> Outcome {
    let started = Instant::now();
    let mut child = Command::new(env!("CARGO_BIN_EXE_cellmd")).args(args).stdout(Stdio::null()).stderr(Stdio::piped()).spawn().unwrap();
    let stderr = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || std::io::read_to_string(stderr).unwrap_or_default());
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            let stderr = reader.join().unwrap();
            assert!(!stderr.contains("panicked"), "cellmd {args:?} panicked:\n{stderr}");
            return Outcome { status: status.code().unwrap_or(-1), stderr, seconds: started.elapsed().as_secs_f64() };
        }
        if started.elapsed() > LIMIT {
            child.kill().unwrap();
            panic!("cellmd {args:?} hung (killed after {LIMIT:?})");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}

fn header<'a>(text: &'a str, key: &str) -> &'a str {
    text.lines().find_map(|l| l.strip_prefix(key)).unwrap_or_else(|| panic!("no `{key}` line"))
}

#[test]
fn committed_crashers_are_diagnosed() {
    let mut decks: Vec<_> = std::fs::read_dir("tests/decks/crashers")
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "in"))
        .collect();
    decks.sort();
    assert!(decks.len() >= 5, "{decks:?}");
    let out = tempfile::tempdir().unwrap();
    for deck in decks {
        let text = std::fs::read_to_string(&deck).unwrap();
        let (expected, status) = (header(&text, "# expect: "), header(&text, "# exit: ").parse::<i32>().unwrap());
        let got = cellmd(&["run", "--quiet", deck.to_str().unwrap(), "-o", out.path().to_str().unwrap()]);
        assert_eq!(got.status, status, "{}:\n{}", deck.display(), got.stderr);
        assert!(got.stderr.contains(expected), "{}: stderr lacks `{expected}`:\n{}", deck.display(), got.stderr);
    }
    // The image counter beyond i32, in the dump and the restart.
    let dump = std::fs::read_to_string(out.path().join("image_overflow.dump")).unwrap();
    assert!(dump.lines().any(|l| l == "1 3 2200000000"), "{dump}");
    let restart = std::fs::read_to_string(out.path().join("image_overflow.restart")).unwrap();
    assert!(restart.contains("2200000000"), "{restart}");
}

/// LAMMPS input that `cellmd import-lammps` once accepted silently or
/// refused without a place (`tests/suite/lammps_mutations.rs` found them):
/// `tests/decks/crashers/*.lmp`, each a script reading the data file its
/// `read_data` names, with the same `# expect:` and `# exit:` lines; the
/// import writes nothing.
#[test]
fn committed_lammps_crashers_are_diagnosed() {
    let mut scripts: Vec<_> = std::fs::read_dir("tests/decks/crashers")
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "lmp"))
        .collect();
    scripts.sort();
    assert!(!scripts.is_empty());
    let out = tempfile::tempdir().unwrap();
    for script in scripts {
        let text = std::fs::read_to_string(&script).unwrap();
        let (expected, status) = (header(&text, "# expect: "), header(&text, "# exit: ").parse::<i32>().unwrap());
        let dir = out.path().join(script.file_stem().unwrap());
        let got = cellmd(&["import-lammps", script.to_str().unwrap(), "-o", dir.to_str().unwrap()]);
        assert_eq!(got.status, status, "{}:\n{}", script.display(), got.stderr);
        assert!(got.stderr.contains(expected), "{}: stderr lacks `{expected}`:\n{}", script.display(), got.stderr);
        assert_eq!(dir.exists(), status == 0, "{}: the import wrote {}", script.display(), if status == 0 { "nothing" } else { "files" });
        if status == 0 {
            let check = cellmd(&["check", dir.join("system.in").to_str().unwrap()]);
            assert_eq!(check.status, 0, "{}: the imported deck is refused:\n{}", script.display(), check.stderr);
        }
    }
}

/// Inputs too large (or too strange) to commit, each with the start of its
/// expected message and exit status.
#[test]
fn generated_crashers_are_diagnosed_quickly() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, bytes: &[u8]| {
        let path = dir.path().join(name);
        std::fs::write(&path, bytes).unwrap();
        path.to_str().unwrap().to_string()
    };
    let nested = |open: &str, close: &str, n: usize| format!("variable v equal {}1{}\n", open.repeat(n), close.repeat(n));
    let too_deep = "found an expression nested more than 64 deep";
    let secret: String = (0..50).map(|i| format!("secret{i} line\n")).collect();
    let cases: Vec<(String, String, i32)> = vec![
        // The renderer panicked on a column beyond 65 536.
        (write("wide.in", format!("{}x\n", " ".repeat(65_536)).as_bytes()), ":1:65537: found unknown command `x`".into(), 1),
        (write("parens.in", nested("(", ")", 40_000).as_bytes()), too_deep.into(), 1),
        (write("minus.in", nested("-", "", 60_000).as_bytes()), too_deep.into(), 1),
        (write("powers.in", format!("variable v equal 1{}\n", "^1".repeat(60_000)).as_bytes()), too_deep.into(), 1),
        // Quadratic lexing: 26 s for a 1 MB line.
        (write("long.in", format!("units lj\nprint {}\n", "x ".repeat(500_000)).as_bytes()), ":2:1: `print` needs a system".into(), 1),
        (write("latin1.in", b"units lj\nprint caf\xe9\n"), ":2:10: found byte 0xE9, which is not UTF-8".into(), 1),
        // A password file named as a topology, a force field or an include: no byte of it.
        (
            write(
                "topology.in",
                format!("units lj\ntopology {}\n", write("passwd", format!("root:x:0:0:{}\n{secret}", "r".repeat(300)).as_bytes()))
                    .as_bytes(),
            ),
            "passwd:1:1: found `…` before any section".into(),
            1,
        ),
        (
            write("forcefield.in", format!("units lj\ntopology {BAD}/base.top\nforcefield {}/passwd\n", dir.path().display()).as_bytes()),
            "passwd:1:1: found `…`, expected `include`".into(),
            1,
        ),
        // 2 000 nested `if`s overflowed the stack (exit 134); 1 500 passed.
        (
            write("nested_ifs.in", format!("units lj\n{}run 1\n{}", "if 1 then\n".repeat(2000), "endif\n".repeat(2000)).as_bytes()),
            ":102:1: found `if` at nesting depth 101, expected at most 100".into(),
            1,
        ),
        // Two nested loops of 10⁵ never finished `check` (and a `print` in them took GBs).
        (
            write(
                "nested_loops.in",
                format!("units lj\ntopology {BAD}/base.top\nforcefield {BAD}/base.ff\nloop i 1 100000\nloop j 1 100000\nprint ${{i}} ${{j}}\nendloop\nendloop\n")
                    .as_bytes(),
            ),
            ":5:10: found more than 100000 loop iterations in this deck".into(),
            1,
        ),
        // Terminal escapes in a comment were accepted and echoed raw.
        (
            write("escape.in", b"units lj # \x1b]0;owned\x07\x1b[2J\n"),
            ":1:12: found control character `\\u{1b}` in a comment".into(),
            1,
        ),
    ];
    for (deck, expected, status) in &cases {
        let got = cellmd(&["check", deck]);
        assert_eq!(got.status, *status, "{deck}:\n{}", got.stderr);
        assert!(got.stderr.contains(expected.as_str()), "{deck}: stderr lacks `{expected}`:\n{}", got.stderr);
        assert!(!got.stderr.contains("secret") && !got.stderr.contains("root:"), "{deck} echoed a file:\n{}", got.stderr);
        assert!(!got.stderr.contains('\x1b') && !got.stderr.contains('\x07'), "{deck}: a raw control character in\n{}", got.stderr);
        // The headline is our message (its quotes clipped); every other line is the file's.
        let mut quoted = got.stderr.lines().filter(|l| !l.trim_start().starts_with('×'));
        assert!(quoted.all(|l| l.chars().count() < 400), "{deck}: a long line in\n{}", got.stderr);
        assert!(got.seconds < 20.0, "{deck}: {} s", got.seconds);
    }
    // A FIFO blocked forever.
    #[cfg(unix)]
    {
        let fifo = dir.path().join("fifo.top");
        assert!(Command::new("mkfifo").arg(&fifo).status().unwrap().success());
        let deck = write("fifo.in", format!("units lj\ntopology {}\n", fifo.display()).as_bytes());
        let got = cellmd(&["check", &deck]);
        assert_eq!(got.status, 1, "{}", got.stderr);
        assert!(got.stderr.contains("it is a FIFO (named pipe); expected a regular file"), "{}", got.stderr);
        let got = cellmd(&["check", fifo.to_str().unwrap()]);
        assert!(got.stderr.contains("it is a FIFO (named pipe); expected a regular file"), "{}", got.stderr);
    }
}

/// `cellmd ARGS` with stdout connected to `stdout`; returns the exit status
/// and stderr.
fn cellmd_writing_to(args: &[&str], stdout: impl Into<Stdio>) -> (i32, String) {
    let got = Command::new(env!("CARGO_BIN_EXE_cellmd")).args(args).stdout(stdout).stderr(Stdio::piped()).output().unwrap();
    (got.status.code().unwrap_or(-1), String::from_utf8_lossy(&got.stderr).into_owned())
}

/// `cellmd list | head -3` and friends: every subcommand but `run` (which
/// tests/suite/survive.rs covers) ends quietly with its own exit status when the
/// reader of its stdout has gone. The pipe's read end is closed before the
/// command starts, so its first line already meets a departed reader.
#[test]
fn every_subcommand_ends_quietly_when_its_reader_has_gone() {
    let dir = tempfile::tempdir().unwrap();
    let shell = dir.path().join("cell.top");
    let cases: [(&[&str], i32); 5] = [
        (&["list"], 0),
        (&["list", "harmonic"], 0),
        (&["check", "inputs/dimer.in"], 0),
        (&["build", "icosphere", "--level", "1", "--radius", "5", "-o", shell.to_str().unwrap()], 0),
        // The command's own verdict survives the closed pipe.
        (&["list", "no_such_interaction"], 2),
    ];
    for (args, expected) in cases {
        let (reader, writer) = std::io::pipe().unwrap();
        drop(reader);
        let (status, stderr) = cellmd_writing_to(args, writer);
        assert!(!stderr.contains("panicked") && !stderr.contains("Broken pipe"), "cellmd {args:?}:\n{stderr}");
        assert_eq!(status, expected, "cellmd {args:?}:\n{stderr}");
    }
}

/// Any other failure to write stdout (here a full disk, `/dev/full`) is an
/// output error: named, exit status 6.
#[test]
fn a_failing_stdout_is_an_output_error() {
    let full = std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
    let (status, stderr) = cellmd_writing_to(&["list"], full);
    assert_eq!(status, 6, "{stderr}");
    assert!(stderr.contains("cannot write to stdout: No space left on device"), "{stderr}");
}

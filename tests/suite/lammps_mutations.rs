//! A fast, deterministic mutation fuzzer over the LAMMPS decks of
//! `tests/lammps/` (`in.lammps` and the data file it reads), as
//! `cellmd import-lammps` reads them.
//!
//! Each mutant changes the data file, the script or both with a seeded
//! generator: the file cut at any byte (a multi-byte character split
//! included), bytes flipped, a header count made huge, negative or zero, a
//! number made NaN, infinite, huge or subnormal, a section (or a command)
//! removed or doubled, and the line and word mutations of
//! [`super::mutations`]. The mutant pair is written to a scratch directory
//! and imported from its script. No mutant may panic or hang; a refused one
//! must fail with `file:line:col: message`, naming one of the two files
//! with its line and column inside it; an accepted one is silent success
//! unless what it wrote is a deck cellmd accepts and can compute forces on
//! (finite ones). One mutant in [`CLI_EVERY`] is also imported by the
//! command line, which must exit 2 with the same error, or 0.
//! A failure names the deck, the seed and the mutant's files, kept in the
//! scratch directory under their seed; reproducers of the bugs this found
//! are `tests/decks/crashers/*.lmp` (`super::crashers`).

use std::path::{Path, PathBuf};
use std::sync::mpsc;

use super::mutations::{mutate, watch_for_hangs, Rng};
use cellmd::deck::validate_file;
use cellmd::export::import_lammps::read_files;
use cellmd::run::{RunOptions, Simulation};

/// The decks mutated: each directory's `in.lammps` and the data file it reads.
const DECKS: &[&str] = &["molecular", "full_lepton", "small_box"];
/// Mutants per deck.
const MUTANTS: u64 = 300;
/// One mutant in this many also goes through `cellmd import-lammps`.
const CLI_EVERY: u64 = 25;

/// Silent successes the fuzz still finds, not yet fixed in the importer:
/// the mutant imports, and cellmd refuses the deck it wrote (at a place in
/// it). Each is counted and printed; any other refusal fails the test.
const KNOWN_GAPS: &[&str] = &[
    // A bond or angle type that bonds use with no coefficients (LAMMPS stops: "All bond coeffs are not set"):
    // the import notes it, and the topology names a type the force field lacks.
    "expected one defined in the force field",
    // A mass or damping LAMMPS accepts whose drag (m/damp) cellmd refuses.
    "expected `drag` > 0",
    // A coefficient finite in LAMMPS whose conversion overflows (ε/σ² = inf).
    "(a finite number)",
    // A Lepton expression that no longer uses one of its parameters.
    "is not used in the expression",
];

/// Header counts and numbers that have broken readers before, or might.
const HUGE: &[&str] =
    &["18446744073709551615", "18446744073709551616", "9223372036854775807", "4294967297", "1000000000000", "-1", "0", "1e6"];
const NUMBERS: &[&str] = &["nan", "NaN", "inf", "-inf", "1e308", "-1e308", "1e-320", "-0", "0", "1e400", "0x10", "1,5", ""];

/// The byte offsets of the starts of `text`'s lines.
fn line_starts(text: &str) -> Vec<usize> {
    std::iter::once(0).chain(text.match_indices('\n').map(|(i, _)| i + 1)).filter(|&i| i < text.len()).collect()
}

/// Whether a line (comment stripped) is a section or a command: it starts
/// with a letter (data files' counts and box lines start with a number).
fn is_head(line: &str) -> bool {
    line.trim_start().chars().next().is_some_and(|c| c.is_ascii_alphabetic())
}

/// One mutation of a LAMMPS file, as bytes (it may be no longer UTF-8).
fn mutate_lammps(text: &str, rng: &mut Rng) -> Vec<u8> {
    let lines: Vec<&str> = text.split_inclusive('\n').collect();
    let words: Vec<(usize, usize)> = {
        // Byte ranges of the whitespace-separated words.
        let mut out = Vec::new();
        let mut start = None;
        for (i, c) in text.char_indices().chain(std::iter::once((text.len(), ' '))) {
            match (c.is_whitespace(), start) {
                (false, None) => start = Some(i),
                (true, Some(s)) => {
                    out.push((s, i));
                    start = None;
                }
                _ => {}
            }
        }
        out
    };
    let replace = |range: (usize, usize), by: &str| [&text.as_bytes()[..range.0], by.as_bytes(), &text.as_bytes()[range.1..]].concat();
    match rng.below(8) {
        0 => text.as_bytes()[..rng.below(text.len() + 1)].to_vec(),
        1 => {
            let mut bytes = text.as_bytes().to_vec();
            for _ in 0..1 + rng.below(4) {
                let at = rng.below(bytes.len());
                bytes[at] ^= 1 << rng.below(8);
            }
            bytes
        }
        2 => {
            // A header count (`36 atoms`), or any number, made huge, negative or zero.
            let counts: Vec<(usize, usize)> =
                words.iter().copied().filter(|&(s, e)| text[s..e].parse::<u64>().is_ok() && line_starts(text).contains(&s)).collect();
            let pick = if counts.is_empty() { words[rng.below(words.len())] } else { counts[rng.below(counts.len())] };
            replace(pick, HUGE[rng.below(HUGE.len())])
        }
        3 => {
            let numbers: Vec<(usize, usize)> = words.iter().copied().filter(|&(s, e)| text[s..e].parse::<f64>().is_ok()).collect();
            let pick = if numbers.is_empty() { words[rng.below(words.len())] } else { numbers[rng.below(numbers.len())] };
            replace(pick, NUMBERS[rng.below(NUMBERS.len())])
        }
        4 | 5 => {
            // A section (its head to the next head) or a command, removed or doubled.
            let heads: Vec<usize> = (1..lines.len()).filter(|&k| is_head(lines[k])).collect();
            let Some(&from) = heads.get(rng.below(heads.len())) else { return text.as_bytes().to_vec() };
            let to = heads.iter().copied().find(|&k| k > from).unwrap_or(lines.len());
            let mut out: Vec<&str> = lines[..to].to_vec();
            if rng.below(2) == 0 {
                out.truncate(from);
            } else {
                out.extend_from_slice(&lines[from..to]);
            }
            out.extend_from_slice(&lines[to..]);
            out.concat().into_bytes()
        }
        _ => mutate(text, rng).into_bytes(),
    }
}

/// `message`'s place, if it is `path:line:col: …` inside `bytes`.
fn place_inside(message: &str, path: &Path, bytes: &[u8]) -> Option<Result<(), String>> {
    let rest = message.strip_prefix(&format!("{}:", path.display()))?;
    let mut parts = rest.splitn(3, ':');
    let (line, col) = (parts.next()?.parse::<usize>().ok(), parts.next()?.parse::<usize>().ok());
    let (Some(line), Some(col), Some(text)) = (line, col, parts.next()) else {
        return Some(Err(format!("not `file:line:col: message`: {message}")));
    };
    if !text.starts_with(' ') || text.trim().is_empty() || line == 0 || col == 0 {
        return Some(Err(format!("not `file:line:col: message`: {message}")));
    }
    let text = String::from_utf8_lossy(bytes);
    let lines: Vec<&str> = text.split('\n').collect();
    let Some(l) = lines.get(line - 1) else { return Some(Err(format!("line {line} of {} lines: {message}", lines.len()))) };
    if col > l.chars().count() + 1 {
        return Some(Err(format!("column {col} of a {}-character line: {message}", l.chars().count())));
    }
    Some(Ok(()))
}

/// Imports the mutant `script` (reading `data`) from `dir`: whether it was
/// refused; `Err` says what is wrong with how it ended.
fn check(dir: &Path, script: &Path, data: &Path) -> Result<bool, String> {
    let read = |p: &Path| std::fs::read(p).unwrap_or_default();
    let imported = match read_files(script, None) {
        Err(e) => {
            let first = e.lines().next().unwrap_or_default();
            return [script, data]
                .iter()
                .find_map(|p| place_inside(first, p, &read(p)))
                .unwrap_or_else(|| Err(format!("an error that names neither file at a place: {e}")))
                .map(|()| true);
        }
        Ok(imported) => imported,
    };
    let out = dir.join("imported");
    imported.write(&out).map_err(|e| format!("cannot write the import: {e}"))?;
    let plan = match validate_file(&out.join("system.in"), &[]) {
        Ok(plan) => plan,
        Err(e) if KNOWN_GAPS.iter().any(|gap| e.message.contains(gap)) => return Err(format!("{KNOWN}{e}")),
        Err(e) => return Err(format!("imported, but cellmd refuses the deck: {e}")),
    };
    let mut sim = Simulation::before_first_run(&plan, RunOptions { output_dir: out.clone(), ..Default::default() })
        .map_err(|e| format!("imported, but the system does not start: {e}"))?;
    let forces = sim.current_forces().map_err(|e| format!("imported, but its forces fail: {e}"))?;
    if !forces.total_energy().is_finite() || forces.forces.iter().any(|f| !f.is_finite()) {
        return Err("imported, but its energy or forces are not finite".into());
    }
    Ok(false)
}

/// The start of a failure that is one of the [`KNOWN_GAPS`].
const KNOWN: &str = "a known gap: ";

/// The same mutant through the command line: exit 2 with `error` (the
/// in-process error's first line), or 0 when it was accepted.
fn check_cli(script: &Path, out: &Path, refused: bool, error: Option<&str>) -> Result<(), String> {
    let got = std::process::Command::new(env!("CARGO_BIN_EXE_cellmd"))
        .args(["import-lammps", script.to_str().unwrap(), "-o", out.to_str().unwrap()])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&got.stderr);
    match (refused, got.status.code()) {
        (true, Some(2)) if error.is_some_and(|e| stderr.contains(e)) => Ok(()),
        (false, Some(0)) => Ok(()),
        (_, status) => Err(format!("the command line exited {status:?} (refused in-process: {refused}):\n{stderr}")),
    }
}

#[test]
fn mutants_of_the_lammps_decks_fail_at_a_place_or_import_a_deck_that_runs() {
    let (progress, done) = mpsc::channel::<Option<String>>();
    let worker = std::thread::Builder::new()
        .stack_size(8 << 20)
        .spawn(move || {
            let scratch = tempfile::tempdir().unwrap();
            let (mut failures, mut refused, mut total, mut known) = (Vec::new(), 0, 0, 0);
            for (n, name) in DECKS.iter().enumerate() {
                let dir = Path::new("tests/lammps").join(name);
                let script_text = std::fs::read_to_string(dir.join("in.lammps")).unwrap();
                let data_name = script_text.lines().find_map(|l| l.strip_prefix("read_data")).unwrap().split_whitespace().next().unwrap();
                let data_text = std::fs::read_to_string(dir.join(data_name)).unwrap();
                for seed in 0..MUTANTS {
                    let mut rng = Rng(seed ^ ((n as u64 + 100) << 32));
                    // The data file (half the time), the script, or both.
                    let (mut script, mut data) = (script_text.clone().into_bytes(), data_text.clone().into_bytes());
                    match rng.below(4) {
                        0 | 1 => data = mutate_lammps(&data_text, &mut rng),
                        2 => script = mutate_lammps(&script_text, &mut rng),
                        _ => {
                            data = mutate_lammps(&data_text, &mut rng);
                            script = mutate_lammps(&script_text, &mut rng);
                        }
                    }
                    let case = scratch.path().join(format!("{name}.{seed}"));
                    std::fs::create_dir_all(&case).unwrap();
                    let (script_path, data_path): (PathBuf, PathBuf) = (case.join("in.lammps"), case.join(data_name));
                    std::fs::write(&script_path, &script).unwrap();
                    std::fs::write(&data_path, &data).unwrap();
                    let what = format!("{name} seed {seed} ({})", case.display());
                    progress.send(Some(what.clone())).unwrap();
                    let outcome = std::panic::catch_unwind(|| check(&case, &script_path, &data_path)).unwrap_or_else(|panic| {
                        let text = panic.downcast_ref::<String>().cloned().or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()));
                        Err(format!("panicked: {}", text.unwrap_or_default()))
                    });
                    let outcome = outcome.and_then(|was_refused| {
                        if seed % CLI_EVERY == 0 {
                            let error = read_files(&script_path, None).err().map(|e| e.lines().next().unwrap_or_default().to_string());
                            check_cli(&script_path, &case.join("cli"), was_refused, error.as_deref())?;
                        }
                        Ok(was_refused)
                    });
                    total += 1;
                    match outcome {
                        Ok(was_refused) => {
                            refused += usize::from(was_refused);
                            std::fs::remove_dir_all(&case).unwrap();
                        }
                        Err(why) if why.starts_with(KNOWN) => {
                            known += 1;
                            eprintln!("{what}: {why}");
                            std::fs::remove_dir_all(&case).unwrap();
                        }
                        Err(why) => failures.push(format!("{what}: {why}")),
                    }
                }
            }
            progress.send(None).unwrap();
            // Kept for the report: the failing mutants' files.
            let kept = scratch.keep();
            eprintln!("{known} of {total} mutants imported into a deck cellmd refuses, each a known gap");
            (failures, refused, total, kept)
        })
        .unwrap();
    watch_for_hangs(&done);
    let (failures, refused, total, kept) = worker.join().unwrap();
    eprintln!("{refused} of {total} LAMMPS mutants refused, the others imported and ran");
    if failures.is_empty() {
        std::fs::remove_dir_all(&kept).unwrap();
    }
    assert!(failures.is_empty(), "{} of {total} mutants failed badly:\n{}", failures.len(), failures.join("\n"));
    // The mutants reach both the error paths and the readers' ends.
    assert!(refused > total / 4 && refused < total, "{refused} of {total} mutants refused");
}

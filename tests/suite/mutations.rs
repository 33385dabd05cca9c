//! A fast, deterministic mutation fuzzer over the input corpus, inside the
//! test suite (the coverage-guided fuzz targets in `fuzz/` run separately,
//! `scripts/fuzz`).
//!
//! Every deck, topology and force field of `tests/decks/bad/` and the example
//! decks of `inputs/` (with their force fields, and their topologies up to
//! [`MAX_TOPOLOGY_BYTES`]) is mutated with a seeded generator — words
//! replaced by extreme or syntactic values, lines deleted, duplicated or
//! swapped, control and multi-byte characters inserted, the file truncated —
//! and parsed (decks validated in their own directory). No mutant may panic
//! or hang, and every error must be `file:line:col: message` with its line and
//! column inside the file it names, rendered as the CLI renders it. A
//! failure names the file and the seed.
//!
//! Restarts (`tests/decks/bad/*.restart`, and a checkpoint written here that
//! carries its deck) are mutated as text and as JSON values — numbers made
//! extreme, arrays cut or grown, keys dropped — then read by a deck's
//! `read_state` or continued (`cellmd run --continue`): a mutant is refused
//! with the file and field it breaks, or it runs, and a run it starts ends
//! with finite positions or a clean error, never a panic.

use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Duration;

use cellmd::deck::{validate, validate_file_with, ValidateOptions};
use cellmd::forcefield::{check_pair_types, load_forcefield, ForceField};
use cellmd::input::{replaying, InputError, SourceFile};
use cellmd::output::read_state;
use cellmd::run::{RunOptions, Simulation};
use cellmd::topology::parse_topology;
use cellmd::units::UnitSystem;
use serde_json::Value;

/// Mutants per file: fewer of the example decks, whose validation reads
/// their (large) topologies.
fn mutants(path: &Path) -> u64 {
    if path.starts_with("inputs") {
        12
    } else {
        24
    }
}
/// Larger topologies are left out (their parse time, not their grammar, would dominate).
const MAX_TOPOLOGY_BYTES: u64 = 100_000;
/// The longest any one mutant may take before it counts as a hang.
pub(crate) const HANG: Duration = Duration::from_secs(30);

/// Waits for a worker's progress messages (`Some(case)` as it starts each,
/// `None` when it is done) and panics naming the case it is stuck in when
/// none comes within [`HANG`].
pub(crate) fn watch_for_hangs(done: &mpsc::Receiver<Option<String>>) {
    let mut current = String::from("the start");
    loop {
        match done.recv_timeout(HANG) {
            Ok(Some(what)) => current = what,
            Ok(None) => break,
            Err(_) => panic!("{current}: no result after {HANG:?} (a hang?)"),
        }
    }
}

/// SplitMix64: small, seedable, the same on every platform.
pub(crate) struct Rng(pub(crate) u64);

impl Rng {
    pub(crate) fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    pub(crate) fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Values that have broken parsers before, or might.
const WORDS: &[&str] = &[
    "0",
    "-0",
    "-1",
    "1e308",
    "-1e308",
    "1e-320",
    "1e300",
    "nan",
    "inf",
    "-inf",
    "18446744073709551616",
    "4294967297",
    "9223372036854775808",
    "1:1000000000000",
    "3:2",
    "${x}",
    "${",
    "}",
    "&",
    "#",
    "\"",
    "(",
    ")",
    "((((1",
    "-----1",
    "2^2^2^2",
    "[",
    "]",
    "[ bonds ]",
    "[ particles ]",
    "[ box ]",
    "include",
    "run",
    "all",
    "p",
    "f",
    "é",
    "\u{202e}",
    "x y z",
];
const CHARS: &[char] = &['\0', '\r', '\t', '"', '#', '&', '\u{7f}', 'é', '€', '\u{feff}', ' ', '\n', '$', '{', '}', ':'];

pub(crate) fn mutate(text: &str, rng: &mut Rng) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    for _ in 0..1 + rng.below(3) {
        if lines.is_empty() {
            lines.push(String::new());
        }
        let l = rng.below(lines.len());
        match rng.below(8) {
            0 | 1 => {
                let mut words: Vec<String> = lines[l].split(' ').map(str::to_string).collect();
                let w = rng.below(words.len());
                words[w] = WORDS[rng.below(WORDS.len())].to_string();
                lines[l] = words.join(" ");
            }
            2 => {
                lines.remove(l);
            }
            3 => {
                let copy = lines[l].clone();
                lines.insert(rng.below(lines.len() + 1), copy);
            }
            4 => {
                let m = rng.below(lines.len());
                lines.swap(l, m);
            }
            5 => {
                let chars: Vec<char> = lines[l].chars().collect();
                let at = rng.below(chars.len() + 1);
                let c = CHARS[rng.below(CHARS.len())];
                lines[l] = chars[..at].iter().chain(std::iter::once(&c)).chain(&chars[at..]).collect();
            }
            6 => {
                let words: Vec<&str> = text.split_whitespace().collect();
                if let Some(word) = words.get(rng.below(words.len())) {
                    let n = 1 + rng.below(40);
                    lines[l] = format!("{} {}", lines[l], vec![*word; n].join(" "));
                }
            }
            _ => {
                let chars: Vec<char> = lines[l].chars().collect();
                lines[l] = chars[..rng.below(chars.len() + 1)].iter().collect();
                lines.truncate(l + 1);
            }
        }
    }
    let mut out = lines.join("\n");
    if rng.below(4) > 0 {
        out.push('\n');
    }
    out
}

#[derive(Clone, Copy)]
enum Language {
    Deck,
    Topology,
    ForceField,
    /// A restart read by a deck's `read_state`.
    Restart,
    /// A restart that carries its deck, continued.
    Continue,
}

impl Language {
    fn name(self) -> &'static str {
        match self {
            Language::Deck => "deck",
            Language::Topology => "topology",
            Language::ForceField => "force field",
            Language::Restart => "restart (read_state)",
            Language::Continue => "restart (--continue)",
        }
    }
}

/// Values that have broken restart readers before, or might.
fn extreme_values() -> Vec<Value> {
    serde_json::from_str(
        r#"[0, -0.0, -1, 1e308, -1e308, 1e-320, 0.5, 18446744073709551615, -9223372036854775808, 9007199254740993,
        4294967296, null, true, "x", [], {}, [0, 0], [1e308, 0, 0]]"#,
    )
    .unwrap()
}

/// Mutates one value of a JSON document: replaced by an extreme value, or
/// (an array) shortened, lengthened or emptied, or (an object) a key dropped.
fn mutate_json(v: &mut Value, rng: &mut Rng) {
    fn count(v: &Value) -> usize {
        1 + match v {
            Value::Array(a) => a.iter().map(count).sum(),
            Value::Object(o) => o.values().map(count).sum(),
            _ => 0,
        }
    }
    fn nth<'a>(v: &'a mut Value, k: &mut usize) -> Option<&'a mut Value> {
        if *k == 0 {
            return Some(v);
        }
        *k -= 1;
        match v {
            Value::Array(a) => a.iter_mut().find_map(|x| nth(x, k)),
            Value::Object(o) => o.values_mut().find_map(|x| nth(x, k)),
            _ => None,
        }
    }
    let mut k = rng.below(count(v));
    let target = nth(v, &mut k).expect("k below the count");
    let values = extreme_values();
    match (target, rng.below(4)) {
        (Value::Array(a), 0) if !a.is_empty() => {
            a.pop();
        }
        (Value::Array(a), 1) if !a.is_empty() => {
            let copy = a[rng.below(a.len())].clone();
            a.push(copy);
        }
        (Value::Array(a), 2) => a.clear(),
        (Value::Object(o), 0 | 1) if !o.is_empty() => {
            let key = o.keys().nth(rng.below(o.len())).unwrap().clone();
            o.remove(&key);
        }
        (target, _) => *target = values[rng.below(values.len())].clone(),
    }
}

/// Parses a mutant: whether it failed (cleanly); `Err` describes what is
/// wrong with how it failed.
fn check(language: Language, path: &Path, text: &str, scratch: &Path) -> Result<bool, String> {
    let shown = path.display().to_string();
    let result: Result<(), InputError> = match language {
        Language::Deck => validate(&SourceFile::new(shown.clone(), text), path.parent().unwrap(), &[]).map(|_| ()),
        Language::Topology => parse_topology(&SourceFile::new(shown.clone(), text)).map(|_| ()),
        Language::ForceField => {
            // Written to a scratch file: the force-field reader takes a path.
            let file = scratch.join(path.file_name().unwrap());
            std::fs::write(&file, text).unwrap();
            let mut ff = ForceField::default();
            load_forcefield(&file, None, UnitSystem::Cell, &mut ff, &mut Vec::new()).and_then(|()| check_pair_types(&ff))
        }
        Language::Restart | Language::Continue => unreachable!("restarts are checked by check_restart"),
    };
    let Err(e) = result else { return Ok(false) };
    check_error(&e, path, text, scratch)?;
    Ok(true)
}

/// The error of a mutant: `file:line:col: message`, rendered as the CLI
/// renders it, its position inside the mutant when it names the mutant.
fn check_error(e: &InputError, path: &Path, text: &str, scratch: &Path) -> Result<(), String> {
    let message = e.to_string();
    // Rendered as the CLI renders it (this panicked past column 65 536).
    let mut report = String::new();
    miette::GraphicalReportHandler::new().render_report(&mut report, e).map_err(|_| format!("not rendered: {message}"))?;
    if !message.starts_with(&format!("{}:{}:{}: ", e.path, e.line, e.col)) || e.message.is_empty() || e.line == 0 || e.col == 0 {
        return Err(format!("not `file:line:col: message`: {message}"));
    }
    // An error in the mutant itself points inside it.
    let named = Path::new(&e.path);
    if named == path || named.file_name() == path.file_name() && named.starts_with(scratch) {
        let lines: Vec<&str> = text.split('\n').collect();
        let line = lines.get(e.line as usize - 1).ok_or_else(|| format!("line {} of {} lines: {message}", e.line, lines.len()))?;
        if e.col as usize > line.chars().count() + 1 {
            return Err(format!("column {} of a {}-character line: {message}", e.col, line.chars().count()));
        }
    }
    Ok(())
}

/// A deck of the restart system (`tests/decks/bad/restart.top`) reading `restart`.
fn restart_deck(restart: &Path) -> String {
    format!(
        "units lj\ntopology restart.top\nforcefield base.ff\nbox x -5 5 f y -5 5 p z -5 5 f\ntimestep 0.01\nread_state {}\nrun 5\n",
        restart.display()
    )
}

/// A run a mutant restart started: it ends with finite positions or a clean error.
fn check_run(run: Result<Simulation, cellmd::run::RunError>) -> Result<(), String> {
    match run {
        Ok(sim) if sim.state.positions.iter().all(|x| x.is_finite()) => Ok(()),
        Ok(sim) => Err(format!("ran to step {} with non-finite positions", sim.state.step)),
        Err(e) if e.to_string().is_empty() => Err("an empty run error".into()),
        Err(_) => Ok(()),
    }
}

/// Reads (and, if accepted, runs) a mutant restart: whether it was refused.
fn check_restart(language: Language, text: &str, scratch: &Path) -> Result<bool, String> {
    let file = scratch.join("mutant.restart");
    std::fs::write(&file, text).unwrap();
    let options = RunOptions { output_dir: scratch.join("out"), ..Default::default() };
    std::fs::create_dir_all(&options.output_dir).unwrap();
    let refused = |e: String| {
        let shown = file.display().to_string();
        if !e.starts_with(&shown) || e.len() <= shown.len() + 2 {
            return Err(format!("a restart error that does not start with its file: {e}"));
        }
        Ok(true)
    };
    match language {
        Language::Restart => {
            let deck = Path::new("tests/decks/bad/restart_mutant.in");
            let plan = match validate(&SourceFile::new(deck.display().to_string(), restart_deck(&file)), Path::new("tests/decks/bad"), &[])
            {
                Ok(plan) => plan,
                Err(e) => {
                    check_error(&e, deck, &restart_deck(&file), scratch)?;
                    return Ok(true);
                }
            };
            check_run(Simulation::execute(plan, options)).map(|()| false)
        }
        _ => {
            let data = match read_state(&file) {
                Ok(data) => data,
                Err(e) => return refused(e),
            };
            let Some(resume) = data.resume.clone() else { return Ok(true) };
            let plan = replaying(&resume.inputs.files, || {
                validate_file_with(Path::new(&resume.inputs.deck), &resume.inputs.vars, ValidateOptions::default())
            });
            let plan = match plan {
                Ok(plan) => plan,
                Err(_) => return Ok(true),
            };
            match Simulation::resume(plan, data, &file, options) {
                Err(cellmd::run::RunError::Setup(e)) if e.starts_with(&file.display().to_string()) => Ok(true),
                run => check_run(run).map(|()| false),
            }
        }
    }
}

/// A checkpoint of a small kinetic run that carries its deck, as text.
fn checkpoint_with_deck(scratch: &Path) -> String {
    let dir = scratch.join("checkpoint");
    std::fs::create_dir_all(&dir).unwrap();
    for name in ["restart.top", "base.ff"] {
        std::fs::copy(Path::new("tests/decks/bad").join(name), dir.join(name)).unwrap();
    }
    let deck = "units lj\ntopology restart.top\nforcefield base.ff\nbox x -5 5 f y -5 5 p z -5 5 f\ntimestep 0.01\ntemperature 0.1\n\
                write_state ck.*.restart every 10\nrun 20\nrun 10\n";
    std::fs::write(dir.join("deck.in"), deck).unwrap();
    let plan = cellmd::deck::validate_file(&dir.join("deck.in"), &[]).unwrap();
    Simulation::execute(plan, RunOptions { output_dir: dir.clone(), ..Default::default() }).unwrap();
    let text = std::fs::read_to_string(dir.join("ck.10.restart")).unwrap();
    // Pretty, so that the line mutations cut arrays and objects apart too.
    serde_json::to_string_pretty(&serde_json::from_str::<Value>(&text).unwrap()).unwrap()
}

fn corpus() -> Vec<(Language, PathBuf)> {
    let mut files = Vec::new();
    for dir in ["tests/decks/bad", "inputs", "forcefields", "topologies"] {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            let language = match path.extension().and_then(|e| e.to_str()) {
                Some("in") => Language::Deck,
                Some("ff") => Language::ForceField,
                Some("top") if std::fs::metadata(&path).unwrap().len() <= MAX_TOPOLOGY_BYTES => Language::Topology,
                Some("restart") => Language::Restart,
                _ => continue,
            };
            files.push((language, path));
        }
    }
    files.sort_by(|a, b| a.1.cmp(&b.1));
    files
}

#[test]
fn mutants_of_every_input_fail_cleanly_or_parse() {
    let files = corpus();
    assert!(files.len() > 100, "{} files", files.len());
    let (progress, done) = mpsc::channel::<Option<String>>();
    let worker = std::thread::Builder::new()
        .stack_size(8 << 20)
        .spawn(move || {
            let scratch = tempfile::tempdir().unwrap();
            let (mut failures, mut refused, mut seconds) = (Vec::new(), 0, std::collections::BTreeMap::new());
            let mut by_language: std::collections::BTreeMap<&str, (usize, usize)> = Default::default();
            let mut files = files;
            let checkpoint = scratch.path().join("checkpoint.restart");
            std::fs::write(&checkpoint, checkpoint_with_deck(scratch.path())).unwrap();
            files.push((Language::Continue, checkpoint));
            let mut total = 0;
            for (n, (language, path)) in files.iter().enumerate() {
                let text = std::fs::read_to_string(path).unwrap();
                let started = std::time::Instant::now();
                let restart = matches!(language, Language::Restart | Language::Continue);
                // Restarts are mutated as text and, as many again, as JSON values.
                let count = mutants(path) * if restart { 2 } else { 1 };
                total += count as usize;
                for seed in 0..count {
                    let mut rng = Rng(seed ^ ((n as u64) << 32));
                    let mutant = match serde_json::from_str::<Value>(&text) {
                        Ok(mut value) if restart && seed % 2 == 1 => {
                            for _ in 0..1 + rng.below(3) {
                                mutate_json(&mut value, &mut rng);
                            }
                            serde_json::to_string_pretty(&value).unwrap()
                        }
                        _ => mutate(&text, &mut rng),
                    };
                    let what = format!("{} seed {seed}", path.display());
                    progress.send(Some(what.clone())).unwrap();
                    let outcome = std::panic::catch_unwind(|| match language {
                        Language::Restart | Language::Continue => check_restart(*language, &mutant, scratch.path()),
                        _ => check(*language, path, &mutant, scratch.path()),
                    })
                    .unwrap_or_else(|panic| {
                        let text = panic.downcast_ref::<String>().cloned().or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()));
                        Err(format!("panicked: {}", text.unwrap_or_default()))
                    });
                    match outcome {
                        Ok(failed) => {
                            refused += usize::from(failed);
                            let counts = by_language.entry(language.name()).or_default();
                            *counts = (counts.0 + usize::from(failed), counts.1 + 1);
                        }
                        Err(why) => failures.push(format!("{what}: {why}")),
                    }
                }
                *seconds.entry(path.parent().unwrap().display().to_string()).or_insert(0.0) += started.elapsed().as_secs_f64();
            }
            progress.send(None).unwrap();
            eprintln!("(refused, mutants) by language: {by_language:?}");
            (failures, refused, total, seconds)
        })
        .unwrap();
    watch_for_hangs(&done);
    let (failures, refused, total, seconds) = worker.join().unwrap();
    eprintln!("{refused} of {total} mutants refused, the others parsed; seconds by folder: {seconds:?}");
    assert!(failures.is_empty(), "{} mutants failed badly:\n{}", failures.len(), failures.join("\n"));
    // The mutants reach both the error paths and the parsers' ends.
    assert!(refused > total / 3 && refused < total, "{refused} of {total} mutants refused");
}

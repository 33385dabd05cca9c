//! The manual (the mdBook in `docs/`) stays true: its reference and gallery
//! pages are what `cellmd docs` generates from the registries, the deck's
//! command table and `inputs/` (so a registered type, rule or command
//! without its page fails here); its index tables list every registry entry
//! once; its first simulation shows the committed files; and no page speaks
//! in the project's internal names for papers or tasks.

use std::path::{Path, PathBuf};

use cellmd::interactions::REGISTRY;
use cellmd::kinetics::RULES;
use cellmd::manual;

const BOOK: &str = "docs/src";

fn page(path: &str) -> String {
    std::fs::read_to_string(Path::new(BOOK).join(path)).unwrap_or_else(|e| panic!("{BOOK}/{path}: {e}"))
}

/// Asserts that each `file` is shown verbatim in `doc`: the first ```text
/// block after the marker "(`file`)".
pub fn assert_shows_the_committed_files(doc: &str, files: &[&str]) {
    let text = std::fs::read_to_string(doc).unwrap();
    for file in files {
        let marker = format!("(`{file}`)");
        let start = text.find(&marker).unwrap_or_else(|| panic!("{doc} does not show {file}"));
        let block = &text[start..];
        let body_start = block.find("```text\n").unwrap() + "```text\n".len();
        let body_end = body_start + block[body_start..].find("```").unwrap();
        assert_eq!(&block[body_start..body_end], std::fs::read_to_string(file).unwrap(), "{doc}'s {file} differs from the file");
    }
}

/// The relative link targets of a Markdown text (`[..](target)`, not
/// `http…`, `mailto:` or a bare `#anchor`).
pub fn relative_links(text: &str) -> Vec<String> {
    let mut links = Vec::new();
    let mut rest = text;
    while let Some(at) = rest.find("](") {
        rest = &rest[at + 2..];
        let Some(end) = rest.find(')') else { break };
        let target = &rest[..end];
        if !target.contains("://") && !target.starts_with("mailto:") && !target.starts_with('#') && !target.contains(' ') {
            links.push(target.to_string());
        }
    }
    links
}

#[test]
fn generated_pages_are_current() {
    let decks = manual::read_decks(Path::new(BOOK), Path::new("inputs")).unwrap();
    assert!(decks.len() > 20, "found {} decks in inputs/", decks.len());
    let generated = manual::generate(&decks);
    let problems = manual::check(Path::new(BOOK), &generated).unwrap();
    assert!(problems.is_empty(), "the manual's generated pages differ from the code; run `cargo run -- docs`:\n{}", problems.join("\n"));
}

#[test]
fn a_left_over_or_edited_page_is_reported() {
    let dir = tempfile::tempdir().unwrap();
    let book = dir.path();
    let decks = manual::read_decks(Path::new(BOOK), Path::new("inputs")).unwrap();
    let generated = manual::generate(&decks);
    std::fs::write(book.join("SUMMARY.md"), page("SUMMARY.md")).unwrap();
    manual::write(book, &generated).unwrap();
    assert!(manual::check(book, &generated).unwrap().is_empty());
    std::fs::write(book.join("reference/interactions/no_such_law.md"), "# no_such_law\n").unwrap();
    std::fs::write(book.join("reference/commands/run.md"), "# run\n").unwrap();
    std::fs::remove_file(book.join("reference/kinetics/slip.md")).unwrap();
    let problems = manual::check(book, &generated).unwrap().join("\n");
    for expected in ["no_such_law.md: no registry entry", "reference/commands/run.md: stale", "reference/kinetics/slip.md: missing"] {
        assert!(problems.contains(expected), "expected `{expected}` in\n{problems}");
    }
}

#[test]
fn interaction_table_matches_the_registry() {
    let text = page("reference/interactions.md");
    let rows: Vec<&str> = text.lines().filter(|l| l.starts_with("| [`")).collect();
    for i in REGISTRY {
        let row = format!("| [`{0}`](interactions/{0}.md) | {1} | {2} |", i.name(), i.kind().keyword(), i.summary().replace('|', "\\|"));
        assert!(rows.contains(&row.as_str()), "the interaction index lacks the row\n{row}");
        assert!(Path::new(BOOK).join(format!("reference/interactions/{}.md", i.name())).exists(), "{} has no page", i.name());
    }
    assert_eq!(rows.len(), REGISTRY.len(), "the interaction index lists interactions that are not registered");
}

#[test]
fn kinetic_rule_table_matches_the_registry() {
    let text = page("reference/kinetics.md");
    let rows: Vec<&str> = text.lines().filter(|l| l.starts_with("| [`")).collect();
    let missing: Vec<String> = RULES
        .iter()
        .map(|r| format!("| [`{0}`](kinetics/{0}.md) | {1} |", r.name(), r.summary().replace('|', "\\|")))
        .filter(|row| !rows.contains(&row.as_str()))
        .collect();
    assert!(missing.is_empty(), "the kinetic rule index lacks the rows\n{}", missing.join("\n"));
    assert_eq!(rows.len(), RULES.len(), "the kinetic rule index lists rules that are not registered");
}

#[test]
fn first_simulation_is_the_committed_files() {
    assert_shows_the_committed_files(
        &format!("{BOOK}/getting-started/first-simulation.md"),
        &["topologies/dimer.top", "forcefields/dimer.ff", "inputs/dimer.in"],
    );
}

#[test]
fn install_page_keeps_the_two_commands() {
    let text = page("getting-started/install.md");
    assert!(text.contains("```sh\nbash scripts/test-all\n```"));
    assert!(text.contains("```sh\ncargo run --release -- run inputs/quickstart.in -o out\n```"));
}

/// Every Markdown page of the book, and the README.
fn documents() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() && !path.is_symlink() {
                walk(&path, out);
            } else if path.extension().is_some_and(|e| e == "md") {
                out.push(path);
            }
        }
    }
    let mut out = vec![PathBuf::from("README.md")];
    walk(Path::new(BOOK), &mut out);
    out
}

/// The first internal name in `line` that a reader cannot resolve: the
/// project's numbered seed papers ("seed 001") and its task tracker
/// ("issue 19", "#19"), or the specification's private names.
fn internal_name(line: &str) -> Option<&'static str> {
    let lower = line.to_lowercase();
    let digits_after = |word: &str, count: usize| {
        lower.match_indices(word).any(|(at, _)| {
            let rest = lower[at + word.len()..].trim_start_matches('#');
            rest.len() >= count && rest.bytes().take(count).all(|b| b.is_ascii_digit())
        })
    };
    let tracker = lower.match_indices('#').any(|(at, _)| {
        let rest = &lower.as_bytes()[at + 1..];
        rest.len() >= 2 && rest[0].is_ascii_digit() && rest[1].is_ascii_digit()
    });
    if digits_after("seed ", 3) {
        Some("seed NNN")
    } else if digits_after("issue ", 1) || tracker {
        Some("an issue number")
    } else if lower.contains("the pi's") || lower.contains("ffn_cellsim") {
        Some("a private name")
    } else {
        None
    }
}

#[test]
fn pages_cite_papers_not_internal_names() {
    let mut found = Vec::new();
    for doc in documents() {
        let text = std::fs::read_to_string(&doc).unwrap();
        for (n, line) in text.lines().enumerate() {
            if let Some(what) = internal_name(line) {
                found.push(format!("{}:{}: {what} in: {}", doc.display(), n + 1, line.trim()));
            }
        }
    }
    assert!(found.is_empty(), "pages use internal names (cite papers by authors and year):\n{}", found.join("\n"));
    assert!(documents().len() > 40, "found {} pages", documents().len());
}

#[test]
fn the_internal_name_check_can_fail() {
    for line in ["as Seed 001 reports", "see issue #19", "the sweep of #20", "(issue 8, round 3)", "the PI's law"] {
        assert!(internal_name(line).is_some(), "`{line}` passed");
    }
    for line in ["a seed 7 run", "[Protocols](protocols.md#ramps)", "| # | checkpoint |", "Prakash, Bull & Prakash (2022)"] {
        assert_eq!(internal_name(line), None, "`{line}` was refused");
    }
}

//! The pages of the user manual (the mdBook in `docs/`) that are generated
//! from the code, so that they cannot drift from it: one reference page per
//! interaction type ([`crate::interactions::REGISTRY`]), per kinetic rule
//! ([`crate::kinetics::RULES`]) and per deck command (the deck's command
//! table, [`crate::deck::command_docs`]), each kind with an index table, and
//! one examples-gallery page per deck of `inputs/`. `cellmd docs` writes them
//! and rewrites the generated parts of `SUMMARY.md` (between the
//! `<!-- generated: KIND -->` and `<!-- end generated: KIND -->` markers);
//! `cellmd docs --check` lists every page that is missing, stale or left
//! over, and `tests/suite/docs.rs` fails on any.
//!
//! A page's text is the entry's own documentation as `cellmd list NAME`
//! prints it (title, summary, parameter table from the schema, the `.md`
//! beside its file), in the `cell` unit system.

use std::collections::BTreeMap;
use std::fs;
use std::io;
use std::path::{Component, Path, PathBuf};

use crate::deck::command_docs;
use crate::interactions::{documentation, REGISTRY};
use crate::kinetics::RULES;
use crate::units::UnitSystem;

/// The folders (under the book's source) whose every file is generated.
const GENERATED_DIRS: [&str; 4] = ["reference/interactions", "reference/kinetics", "reference/commands", "examples"];

/// The generated pages, path (relative to the book's source) → text, and the
/// generated sections of `SUMMARY.md`, marker name → lines.
pub struct Manual {
    pub pages: BTreeMap<PathBuf, String>,
    pub summary: BTreeMap<&'static str, String>,
}

/// Generates every page; `decks` are the example decks (`inputs/*.in`),
/// named relative to the book's source as its `{{#include}}` reads them.
pub fn generate(decks: &[(String, PathBuf, String)]) -> Manual {
    let mut pages = BTreeMap::new();
    let mut summary = BTreeMap::new();

    let mut index = String::from(
        "# Interaction types\n\nEvery interaction type of the registry, with its kind (the force-field keyword that \
         introduces it). Generated from the code by `cellmd docs`.\n\n| name | kind | summary |\n|---|---|---|\n",
    );
    let mut toc = String::from("- [Interaction types](reference/interactions.md)\n");
    for i in REGISTRY {
        index += &format!("| [`{0}`](interactions/{0}.md) | {1} | {2} |\n", i.name(), i.kind().keyword(), cell(i.summary()));
        toc += &format!("  - [{0}](reference/interactions/{0}.md)\n", i.name());
        pages.insert(PathBuf::from(format!("reference/interactions/{}.md", i.name())), page(&documentation(*i, UnitSystem::Cell)));
    }
    pages.insert(PathBuf::from("reference/interactions.md"), index);

    let mut index = String::from(
        "# Kinetic rules\n\nEvery kinetic rule of the registry (`kinetics` lines of a force field act on a bond type's \
         bonds after each force pass). Generated from the code by `cellmd docs`.\n\n| name | summary |\n|---|---|\n",
    );
    toc += "- [Kinetic rules](reference/kinetics.md)\n";
    for r in RULES {
        index += &format!("| [`{0}`](kinetics/{0}.md) | {1} |\n", r.name(), cell(r.summary()));
        toc += &format!("  - [{0}](reference/kinetics/{0}.md)\n", r.name());
        pages.insert(PathBuf::from(format!("reference/kinetics/{}.md", r.name())), page(&documentation(*r, UnitSystem::Cell)));
    }
    pages.insert(PathBuf::from("reference/kinetics.md"), index);

    let mut index = String::from(
        "# Deck commands\n\nEvery command a deck accepts, in the order the \"unknown command\" error lists them. \
         `setup` commands define the system and must come before its first use; `block` words structure the deck. \
         Generated from the deck's command table by `cellmd docs`.\n\n| command | kind | usage |\n|---|---|---|\n",
    );
    toc += "- [Deck commands](reference/commands.md)\n";
    for c in command_docs() {
        index += &format!("| [`{0}`](commands/{0}.md) | {1} | `{2}` |\n", c.name, c.kind, cell(c.usage));
        toc += &format!("  - [{0}](reference/commands/{0}.md)\n", c.name);
        let text = format!("# {} (deck {})\n\n```text\n{}\n```\n\n{}\n", c.name, c.kind, c.usage.replace(" | ", "\n"), c.doc);
        pages.insert(PathBuf::from(format!("reference/commands/{}.md", c.name)), text);
    }
    pages.insert(PathBuf::from("reference/commands.md"), index);
    summary.insert("reference", toc);

    let mut index = String::from(
        "# Examples gallery\n\nEvery example deck of `inputs/` (each one runs, shortened, in the test suite), with the \
         description from its own header. Run one with `cellmd run inputs/NAME.in -o out`.\n\n| deck | what it is |\n|---|---|\n",
    );
    let mut toc = String::from("- [Examples gallery](examples/index.md)\n");
    for (name, include, text) in decks {
        let about = header(text);
        let first = about.split(". ").next().unwrap_or("").trim_end_matches('.');
        index += &format!("| [`{name}`]({name}.md) | {} |\n", cell(first));
        toc += &format!("  - [{name}](examples/{name}.md)\n");
        let run = format!("cellmd run inputs/{name}.in -o out");
        let text = format!(
            "# {name}\n\n{about}\n\n```sh\n{run}\n```\n\nThe deck (`inputs/{name}.in`):\n\n```text\n{{{{#include {}}}}}\n```\n",
            include.display()
        );
        pages.insert(PathBuf::from(format!("examples/{name}.md")), text);
    }
    pages.insert(PathBuf::from("examples/index.md"), index);
    summary.insert("examples", toc);
    Manual { pages, summary }
}

/// An entry's documentation as a page: its `#` title stays the only one.
fn page(doc: &str) -> String {
    format!("{}\n", doc.trim_end())
}

/// Text for one cell of a Markdown table.
fn cell(text: &str) -> String {
    text.replace('|', "\\|")
}

/// A deck's leading comment block as Markdown paragraphs (blank comment
/// lines separate them).
fn header(deck: &str) -> String {
    let mut text = String::new();
    for line in deck.lines() {
        let Some(comment) = line.strip_prefix('#') else { break };
        let comment = comment.trim();
        if comment.is_empty() {
            text += "\n\n";
        } else {
            if !text.is_empty() && !text.ends_with('\n') {
                text.push(' ');
            }
            text += comment;
        }
    }
    // A `<` in prose (`<f>`, `x < d`) would open an HTML tag in Markdown.
    text.trim().replace('<', "&lt;")
}

/// The example decks of `inputs` (`*.in`, by name), each with its path as
/// seen from `book/examples/` and its text.
pub fn read_decks(book: &Path, inputs: &Path) -> io::Result<Vec<(String, PathBuf, String)>> {
    let mut decks = Vec::new();
    for entry in fs::read_dir(inputs)? {
        let path = entry?.path();
        if path.extension().is_some_and(|e| e == "in") {
            let name = path.file_stem().unwrap_or_default().to_string_lossy().into_owned();
            let include = relative(&path, &book.join("examples"))?;
            decks.push((name, include, fs::read_to_string(&path)?));
        }
    }
    decks.sort();
    Ok(decks)
}

/// `path` relative to the directory `from` (both made absolute first).
fn relative(path: &Path, from: &Path) -> io::Result<PathBuf> {
    let cwd = std::env::current_dir()?;
    let absolute = |p: &Path| {
        let mut parts: Vec<std::ffi::OsString> = Vec::new();
        for c in cwd.join(p).components() {
            match c {
                Component::ParentDir => {
                    parts.pop();
                }
                Component::Normal(n) => parts.push(n.to_os_string()),
                Component::CurDir | Component::RootDir | Component::Prefix(_) => {}
            }
        }
        parts
    };
    let (path, from) = (absolute(path), absolute(from));
    let common = path.iter().zip(&from).take_while(|(a, b)| a == b).count();
    let mut out = PathBuf::new();
    for _ in common..from.len() {
        out.push("..");
    }
    for part in &path[common..] {
        out.push(part);
    }
    Ok(out)
}

/// `SUMMARY.md` with its generated sections replaced; an error names a
/// marker that is missing.
fn summary_with(summary: &str, manual: &Manual) -> Result<String, String> {
    let mut text = summary.to_string();
    for (name, lines) in &manual.summary {
        let (begin, end) = (format!("<!-- generated: {name} -->\n"), format!("<!-- end generated: {name} -->"));
        let start = text.find(&begin).ok_or_else(|| format!("SUMMARY.md lacks the marker `{}`", begin.trim()))? + begin.len();
        let stop = start + text[start..].find(&end).ok_or_else(|| format!("SUMMARY.md lacks the marker `{end}`"))?;
        text.replace_range(start..stop, lines);
    }
    Ok(text)
}

/// What differs between the book's source and the generated pages: one
/// line per missing, stale or left-over page (empty when up to date).
pub fn check(book: &Path, manual: &Manual) -> Result<Vec<String>, String> {
    let mut problems = Vec::new();
    for (path, text) in &manual.pages {
        match fs::read_to_string(book.join(path)) {
            Ok(found) if &found == text => {}
            Ok(_) => problems.push(format!("{}: stale (run `cellmd docs`)", path.display())),
            Err(_) => problems.push(format!("{}: missing (run `cellmd docs`)", path.display())),
        }
    }
    for path in leftovers(book, manual).map_err(|e| e.to_string())? {
        problems.push(format!("{}: no registry entry, command or deck has this page (run `cellmd docs`)", path.display()));
    }
    let summary_path = book.join("SUMMARY.md");
    let summary = fs::read_to_string(&summary_path).map_err(|e| format!("{}: {e}", summary_path.display()))?;
    if summary_with(&summary, manual)? != summary {
        problems.push("SUMMARY.md: its generated sections are stale (run `cellmd docs`)".into());
    }
    Ok(problems)
}

/// Files of the generated folders that no generated page is.
fn leftovers(book: &Path, manual: &Manual) -> io::Result<Vec<PathBuf>> {
    let mut found = Vec::new();
    for dir in GENERATED_DIRS {
        let Ok(entries) = fs::read_dir(book.join(dir)) else { continue };
        for entry in entries {
            let path = Path::new(dir).join(entry?.file_name());
            if !manual.pages.contains_key(&path) {
                found.push(path);
            }
        }
    }
    found.sort();
    Ok(found)
}

/// Writes every generated page, removes left-over ones and rewrites the
/// generated sections of `SUMMARY.md`; returns how many files changed.
pub fn write(book: &Path, manual: &Manual) -> Result<usize, String> {
    let failed = |path: &Path, e: io::Error| format!("{}: {e}", path.display());
    let mut changed = 0;
    for path in leftovers(book, manual).map_err(|e| e.to_string())? {
        fs::remove_file(book.join(&path)).map_err(|e| failed(&path, e))?;
        changed += 1;
    }
    for (path, text) in &manual.pages {
        let full = book.join(path);
        if fs::read_to_string(&full).ok().as_deref() != Some(text.as_str()) {
            fs::create_dir_all(full.parent().unwrap_or(book)).map_err(|e| failed(&full, e))?;
            fs::write(&full, text).map_err(|e| failed(&full, e))?;
            changed += 1;
        }
    }
    let summary_path = book.join("SUMMARY.md");
    let summary = fs::read_to_string(&summary_path).map_err(|e| failed(&summary_path, e))?;
    let updated = summary_with(&summary, manual)?;
    if updated != summary {
        fs::write(&summary_path, updated).map_err(|e| failed(&summary_path, e))?;
        changed += 1;
    }
    Ok(changed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_entry_and_command_has_a_page_and_an_index_row() {
        let manual = generate(&[("dimer".into(), PathBuf::from("../../../inputs/dimer.in"), "# Two beads.\n# On a wall.\nrun 1\n".into())]);
        for i in REGISTRY {
            let page = &manual.pages[&PathBuf::from(format!("reference/interactions/{}.md", i.name()))];
            assert!(page.starts_with(&format!("# {} (", i.name())) && page.contains("## Parameters"));
            assert!(manual.pages[&PathBuf::from("reference/interactions.md")].contains(&format!("[`{0}`](interactions/{0}.md)", i.name())));
        }
        for r in RULES {
            assert!(manual.pages.contains_key(&PathBuf::from(format!("reference/kinetics/{}.md", r.name()))));
        }
        for c in command_docs() {
            assert!(
                manual.pages[&PathBuf::from(format!("reference/commands/{}.md", c.name))].contains(c.usage.split(" | ").next().unwrap())
            );
        }
        let example = &manual.pages[&PathBuf::from("examples/dimer.md")];
        assert!(example.contains("Two beads. On a wall.") && example.contains("{{#include ../../../inputs/dimer.in}}"));
    }

    #[test]
    fn summary_sections_are_replaced_between_their_markers_and_a_missing_marker_is_named() {
        let manual = generate(&[]);
        let summary = "# S\n<!-- generated: reference -->\nSTALE LINE\n<!-- end generated: reference -->\n<!-- generated: examples -->\n<!-- end generated: examples -->\n";
        let text = summary_with(summary, &manual).unwrap();
        assert!(!text.contains("STALE LINE") && text.contains("- [harmonic](reference/interactions/harmonic.md)"));
        assert_eq!(summary_with(&text, &manual).unwrap(), text);
        let error = summary_with("# S\n", &manual).unwrap_err();
        assert!(error.contains("<!-- generated: examples -->"), "{error}");
    }

    #[test]
    fn a_deck_header_becomes_paragraphs() {
        assert_eq!(header("# One\n# two <f>.\n#\n# Three\nunits cell\n# not this"), "One two &lt;f>.\n\nThree");
        assert_eq!(
            relative(Path::new("/a/b/inputs/x.in"), Path::new("/a/b/docs/src/examples")).unwrap(),
            PathBuf::from("../../../inputs/x.in")
        );
    }
}

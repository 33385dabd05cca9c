//! The manual's deck snippets run: each deck, force field or builder
//! command that a page of `docs/src` shows is read from the page here and
//! run (shortened where the page's run is long), so a page cannot keep a
//! command the code no longer accepts. Snippets that show a committed file
//! are held to it in `docs.rs`.

use std::path::Path;
use std::process::Command;

use crate::common::Case;

const BOOK: &str = "docs/src";

fn page(path: &str) -> String {
    std::fs::read_to_string(Path::new(BOOK).join(path)).unwrap_or_else(|e| panic!("{BOOK}/{path}: {e}"))
}

/// The body of the first fenced block of language `lang` after `marker` in `text`.
fn block_after(text: &str, marker: &str, lang: &str) -> String {
    let start = text.find(marker).unwrap_or_else(|| panic!("no `{marker}` on the page"));
    let fence = format!("```{lang}\n");
    let rest = &text[start..];
    let body = rest.find(&fence).unwrap_or_else(|| panic!("no ```{lang} block after `{marker}`")) + fence.len();
    let end = body + rest[body..].find("```").unwrap();
    rest[body..end].to_string()
}

/// The first fenced `text` block of `text` that starts with `first`.
fn block_starting(text: &str, first: &str) -> String {
    text.split("```text\n")
        .skip(1)
        .map(|b| &b[..b.find("```").unwrap()])
        .find(|b| b.starts_with(first))
        .unwrap_or_else(|| panic!("no text block starting with `{first}`"))
        .to_string()
}

/// Runs a `cellmd …` command line of the manual in `dir`.
fn cellmd(line: &str, dir: &Path) {
    let args: Vec<&str> = line.split_whitespace().collect();
    assert_eq!(args[0], "cellmd", "not a cellmd command: {line}");
    let out = Command::new(env!("CARGO_BIN_EXE_cellmd")).args(&args[1..]).current_dir(dir).output().unwrap();
    assert!(out.status.success(), "`{line}` failed:\n{}", String::from_utf8_lossy(&out.stderr));
}

/// The largest |r − ℓ|/ℓ over the bonds of the run.
fn worst_length_error(sim: &cellmd::run::Simulation, length: f64) -> f64 {
    let x = &sim.state.positions;
    sim.model.bonds.iter().map(|&[i, j]| ((x[j as usize] - x[i as usize]).length() / length - 1.0).abs()).fold(0.0, f64::max)
}

/// Fibres and constraints: the thermal actin fibre at 10 ms steps, built,
/// force field and deck as the page shows them, run in full (1 000 steps,
/// a tenth of a second): the segments stay at 0.1 µm within the deck's
/// tolerance 1e-8 and the fibre bends.
#[test]
fn the_fibre_example_runs_with_its_segments_held() {
    let text = page("user-guide/fibres-and-constraints.md");
    let ff = block_after(&text, "(`fibre.ff`)", "text");
    let deck = block_after(&text, "(`fibre.in`)", "text");
    let case = Case::new(&[("fibre.ff", &ff), ("deck.in", &deck)]);
    cellmd(block_after(&text, "## Example: a thermal actin fibre", "sh").trim(), case.output_dir());
    let sim = case.run();
    assert_eq!(sim.state.step, 1000);
    assert_eq!(sim.model.bonds.len(), 50);
    let error = worst_length_error(&sim, 0.1);
    assert!(error < 1e-8, "a segment is off its length by {error:e}");
    let x = &sim.state.positions;
    let straightness = (x[50] - x[0]).length() / 5.0;
    assert!(straightness < 0.999, "the thermal fibre did not bend: R/L = {straightness}");
}

/// Coming from Cytosim: the worked example's cellmd files are what
/// `bench/cytosim` writes for the free-fibre system (after their first,
/// comment, line), its Cytosim config lines are lines of the harness's
/// config in order, and the deck runs (3 steps instead of 10 000) with
/// the segments held to its tolerance.
#[test]
fn the_cytosim_worked_example_is_what_the_harness_writes_and_runs() {
    let text = page("coming-from/cytosim.md");
    let work = tempfile::tempdir().unwrap();
    let script = "import sys\nfrom cytosim_bench import systems, writers\ns = systems.free_fibres()\n\
                  writers.write_cellmd(s, 'constrained-implicit', 0.001, sys.argv[1])\n\
                  open(sys.argv[1] + '/config.cym', 'w').write(writers.cytosim_config(s, 0.001, 1))\n";
    let out = Command::new("python3").args(["-c", script]).arg(work.path()).current_dir("bench").output().expect("python3 runs");
    assert!(out.status.success(), "the harness's writers failed:\n{}", String::from_utf8_lossy(&out.stderr));
    let written = |name: &str| std::fs::read_to_string(work.path().join(name)).unwrap();
    let after_first = |t: &str| t.split_once('\n').map(|(_, rest)| rest.to_string()).unwrap();
    let (ff, deck) = (block_starting(&text, "# system.ff"), block_starting(&text, "# system.in"));
    assert_eq!(after_first(&ff), after_first(&written("system.ff")), "the page's system.ff is not the harness's");
    assert_eq!(after_first(&deck), after_first(&written("system.in")), "the page's system.in is not the harness's");
    let config = written("config.cym");
    let mut lines = config.lines();
    for line in block_starting(&text, "% (a)").lines() {
        assert!(lines.any(|l| l == line), "the page's Cytosim config line `{line}` is not in the harness's config (in order)");
    }
    let short = deck.replace("run 10000", "run 3");
    assert_ne!(short, deck, "the deck's run line changed");
    let case = Case::new(&[("system.ff", &ff), ("system.top", &written("system.top")), ("deck.in", &short)]);
    let sim = case.run();
    assert_eq!((sim.state.step, sim.model.len()), (3, 2550));
    let error = worst_length_error(&sim, 0.1);
    assert!(error < 1e-6, "a segment is off its length by {error:e}");
}

/// Expressions and control flow: both loops of the page, on the dimer of
/// the first simulation (the plate a group of one bead, the cells all of
/// them), each `run` shortened to 2 steps.
#[test]
fn the_expression_page_loops_run() {
    let text = page("user-guide/expressions.md");
    let top = std::fs::read_to_string("topologies/dimer.top").unwrap();
    let ff = std::fs::read_to_string("forcefields/dimer.ff").unwrap();
    for first in ["loop k 1 100", "loop k 1 40"] {
        let snippet = block_starting(&text, first).replace("run 200", "run 2").replace("run 5000", "run 2");
        assert!(!snippet.contains("run 200") && snippet.contains("run 2"), "{snippet}");
        let deck = format!(
            "units cell\ntopology t.top\nforcefield f.ff\ntemperature 298\ntimestep 1e-6\ngroup plate id 1\ngroup cells all\n{snippet}"
        );
        let sim = Case::new(&[("t.top", &top), ("f.ff", &ff), ("deck.in", &deck)]).run();
        assert!(sim.state.step >= 2, "`{first}` ran {} steps", sim.state.step);
    }
}

/// The lines of `text` without `#` comments and blank lines.
fn without_comments(text: &str) -> Vec<String> {
    text.lines().map(|l| l.split('#').next().unwrap().split_whitespace().collect::<Vec<_>>().join(" ")).filter(|l| !l.is_empty()).collect()
}

/// Cells: the page's builder command writes the committed single-cell
/// topology byte for byte, and its force field is the committed one
/// without comments.
#[test]
fn the_cell_page_builds_the_committed_cell() {
    let text = page("user-guide/cells.md");
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("topologies")).unwrap();
    cellmd(block_after(&text, "```sh\ncellmd build icosphere", "sh").trim(), dir.path());
    let built = std::fs::read_to_string(dir.path().join("topologies/single_cell.top")).unwrap();
    assert_eq!(
        built,
        std::fs::read_to_string("topologies/single_cell.top").unwrap(),
        "the page's command does not write the committed cell"
    );
    let ff = block_after(&text, "(`forcefields/single_cell.ff`, comments left out)", "text");
    assert_eq!(without_comments(&ff), without_comments(&std::fs::read_to_string("forcefields/single_cell.ff").unwrap()));
}

/// Composed systems: the page's four `topology` lines are those of
/// `inputs/composed_cell.in`, and the ids its comments give are where
/// each part starts (the particle counts of the parts).
#[test]
fn the_composed_cell_page_names_the_committed_parts() {
    let text = page("user-guide/composed-systems.md");
    let shown = block_starting(&text, "topology ");
    let deck = std::fs::read_to_string("inputs/composed_cell.in").unwrap();
    let lines = |t: &str| without_comments(t).into_iter().filter(|l| l.starts_with("topology ")).collect::<Vec<_>>();
    assert_eq!(lines(&shown), lines(&deck));
    let count = |part: &str| {
        let top = std::fs::read_to_string(format!("topologies/composed_cell/{part}.top")).unwrap();
        let particles = top.split("[ particles ]").nth(1).unwrap().split("\n[").next().unwrap().to_string();
        without_comments(&particles).len()
    };
    let membrane = count("membrane");
    assert!(shown.contains(&format!("# ids 1 … {membrane}, body 1")), "the membrane has {membrane} particles");
    assert!(shown.contains(&format!("# ids follow: {} …", membrane + 1)));
}

/// Force-field lines shown alone on their pages (contact, custom laws,
/// kinetics, volume elements) are read by the force-field parser: their
/// laws and parameters are what the code accepts.
#[test]
fn force_field_fragments_of_the_pages_parse() {
    let fragments = [
        ("user-guide/contact.md", "contact cell cell contact_barrier"),
        ("user-guide/contact.md", "contact cell cell contact_adhesion"),
        ("user-guide/custom.md", "bond  spring custom"),
        ("user-guide/kinetics.md", "bond clutch harmonic"),
        ("user-guide/solids.md", "tetra solid neo_hookean"),
    ];
    let dir = tempfile::tempdir().unwrap();
    for (name, first) in fragments {
        let path = dir.path().join("f.ff");
        std::fs::write(&path, block_starting(&page(name), first)).unwrap();
        let mut ff = cellmd::forcefield::ForceField::default();
        let read = cellmd::forcefield::load_forcefield(&path, None, cellmd::units::UnitSystem::Cell, &mut ff, &mut Vec::new());
        assert!(read.is_ok(), "{name}: `{first}…` is refused: {:?}", read.err());
    }
}

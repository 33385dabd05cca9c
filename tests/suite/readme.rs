//! The README stays true: its two commands are CI's and the main job's,
//! its example is the files in the repository, and it stays one screen of
//! a manual whose pages are in `docs/` (their checks: `docs.rs`).

use super::docs::assert_shows_the_committed_files;

fn readme() -> String {
    std::fs::read_to_string("README.md").unwrap()
}

#[test]
fn ci_runs_the_readme_test_command() {
    let text = readme();
    assert!(text.contains("```sh\nbash scripts/test-all\n```"));
    assert!(text.contains("```sh\ncargo run --release -- run inputs/quickstart.in -o out\n```"));
    assert!(std::fs::read_to_string(".ci/run").unwrap().contains("exec bash scripts/test-all"));
}

#[test]
fn readme_example_is_the_committed_files() {
    assert_shows_the_committed_files("README.md", &["forcefields/dimer.ff", "inputs/dimer.in"]);
}

#[test]
fn readme_is_one_screen_and_links_only_to_files_that_exist() {
    let text = readme();
    let lines = text.lines().count();
    assert!(lines <= 250, "README.md has {lines} lines, expected at most 250 (the rest belongs in docs/)");
    let links = super::docs::relative_links(&text);
    assert!(links.len() >= 10, "README.md links to {} pages of the manual, expected its parts", links.len());
    for link in links {
        let path = link.split('#').next().unwrap();
        assert!(std::path::Path::new(path).exists(), "README.md links to `{link}`, which does not exist");
    }
}

//! The README stays true: its tables of interaction types and of kinetic
//! rules are the registries, its worked example is the files in the
//! repository, and its test command is CI's.

use cellmd::interactions::REGISTRY;
use cellmd::kinetics::RULES;

fn readme() -> String {
    std::fs::read_to_string("README.md").unwrap()
}

#[test]
fn interaction_table_matches_the_registry() {
    let text = readme();
    let rows: Vec<&str> = text.lines().filter(|l| l.starts_with("| `") && l.matches('|').count() == 4).collect();
    let expected: Vec<String> = REGISTRY.iter().map(|i| format!("| `{}` | {} | {} |", i.name(), i.kind().keyword(), i.summary())).collect();
    for row in &expected {
        assert!(rows.contains(&row.as_str()), "README lacks the row\n{row}");
    }
    let listed = rows.iter().filter(|r| REGISTRY.iter().any(|i| r.starts_with(&format!("| `{}` |", i.name())))).count();
    assert_eq!(listed, REGISTRY.len(), "README lists interactions that are not registered");
}

#[test]
fn kinetic_rule_table_matches_the_registry() {
    let text = readme();
    let rows: Vec<&str> = text.lines().filter(|l| l.starts_with("| `") && l.replace("\\|", "").matches('|').count() == 3).collect();
    let expected: Vec<String> = RULES.iter().map(|r| format!("| `{}` | {} |", r.name(), r.summary().replace('|', "\\|"))).collect();
    let missing: Vec<&String> = expected.iter().filter(|row| !rows.contains(&row.as_str())).collect();
    assert!(missing.is_empty(), "README lacks the rows\n{}", missing.iter().map(|r| r.as_str()).collect::<Vec<_>>().join("\n"));
    let listed = rows.iter().filter(|r| RULES.iter().any(|k| r.starts_with(&format!("| `{}` |", k.name())))).count();
    assert_eq!(listed, RULES.len(), "README lists kinetic rules that are not registered");
}

#[test]
fn worked_example_is_the_committed_files() {
    let text = readme();
    for file in ["topologies/dimer.top", "forcefields/dimer.ff", "inputs/dimer.in"] {
        let marker = format!("(`{file}`)");
        let start = text.find(&marker).unwrap_or_else(|| panic!("README does not show {file}"));
        let block = &text[start..];
        let body_start = block.find("```text\n").unwrap() + "```text\n".len();
        let body_end = body_start + block[body_start..].find("```").unwrap();
        assert_eq!(&block[body_start..body_end], std::fs::read_to_string(file).unwrap(), "README's {file} differs from the file");
    }
}

#[test]
fn ci_runs_the_readme_test_command() {
    let text = readme();
    assert!(text.contains("```sh\nbash scripts/test-all\n```"));
    assert!(text.contains("```sh\ncargo run --release -- run inputs/quickstart.in -o out\n```"));
    assert!(std::fs::read_to_string(".ci/run").unwrap().contains("exec bash scripts/test-all"));
}

//! Every deck in `inputs/` runs (shortened through its `steps`,
//! `fire_iterations` and, for quasi-static decks, `relax_steps` (steps per
//! relaxation phase) variables) and writes outputs that read back.

use std::path::Path;

use cellmd::deck::validate_file;
use cellmd::run::{RunOptions, Simulation};

fn shortened() -> Vec<(String, String)> {
    vec![("steps".into(), "200".into()), ("fire_iterations".into(), "100".into()), ("relax_steps".into(), "4".into())]
}

#[test]
fn every_input_deck_runs_shortened() {
    let mut decks = 0;
    for entry in std::fs::read_dir("inputs").unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "in") {
            continue;
        }
        let out = tempfile::tempdir().unwrap();
        let plan = validate_file(&path, &shortened()).unwrap_or_else(|e| panic!("{e}"));
        Simulation::execute(plan, RunOptions { output_dir: out.path().to_path_buf(), ..Default::default() })
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        decks += 1;
    }
    assert!(decks >= 1);
}

#[test]
fn quickstart_writes_thermo_and_a_foxglove_mcap() {
    let out = tempfile::tempdir().unwrap();
    let plan = validate_file(Path::new("inputs/quickstart.in"), &shortened()).unwrap();
    let sim = Simulation::execute(plan, RunOptions { output_dir: out.path().to_path_buf(), ..Default::default() }).unwrap();
    assert_eq!(sim.state.step, 400);

    let thermo = std::fs::read_to_string(out.path().join("quickstart.thermo.csv")).unwrap();
    let mut lines = thermo.lines();
    assert_eq!(lines.next().unwrap().split(',').next().unwrap(), "step[-]");
    assert!(thermo.contains("pe[pN·µm]") && thermo.contains("press[Pa]"));
    // Rows at 0 and 200 for each run (the second run starts at 200), every 1000 steps otherwise.
    let steps: Vec<u64> = lines.filter(|l| !l.starts_with("step")).map(|l| l.split(',').next().unwrap().parse().unwrap()).collect();
    assert_eq!(steps, vec![0, 200, 200, 400]);

    let bytes = std::fs::read(out.path().join("quickstart.mcap")).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().expect("finished MCAP has a summary");
    let topics: Vec<&str> = summary.channels.values().map(|c| c.topic.as_str()).collect();
    for topic in ["/cellmd/topology", "/cellmd/frame", "/cellmd/bond_state", "/scene"] {
        assert!(topics.contains(&topic), "{topic} missing from {topics:?}");
    }
    let scene_schema = summary.channels.values().find(|c| c.topic == "/scene").unwrap().schema.as_ref().unwrap().name.clone();
    assert_eq!(scene_schema, "foxglove.SceneUpdate");
    // The dump opens at step 0 (minimisation does not advance the step) and
    // writes every 500 steps, so the shortened 400-step deck has one frame.
    let frames: Vec<serde_json::Value> = mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(|m| m.unwrap())
        .filter(|m| m.channel.topic == "/cellmd/frame")
        .map(|m| cellmd::output::mcap_messages::message_json(&m).unwrap())
        .collect();
    assert_eq!(frames.len(), 1);
    let positions = frames[0]["positions"].as_array().unwrap();
    assert_eq!(positions.len(), 3 * sim.model.len());
}

//! Restart files of arbitrary bytes, read by a deck's `read_state` on the
//! restart system of the bad decks (tests/decks/bad/restart.top): a file is
//! refused at `check` with `file:line:col` and the restart's field, or it is
//! accepted, and then a few steps from it end with finite positions or a
//! clean error. Seeds: tests/decks/bad/*.restart (scripts/fuzz).
#![no_main]

use std::path::Path;

use cellmd::run::{RunOptions, Simulation};
use libfuzzer_sys::fuzz_target;

mod common;

fuzz_target!(|data: &[u8]| {
    let dir = tempfile::tempdir().unwrap();
    let restart = dir.path().join("fuzz.restart");
    std::fs::write(&restart, data).unwrap();
    let deck = format!(
        "units lj\ntopology restart.top\nforcefield base.ff\nbox x -5 5 f y -5 5 p z -5 5 f\ntimestep 0.01\nread_state {}\nrun 3\n",
        restart.display()
    );
    let bad = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/decks/bad"));
    match cellmd::deck::validate(&cellmd::input::SourceFile::new("fuzz.in", deck), bad, &[]) {
        Err(e) => {
            assert!(e.message.contains(&restart.display().to_string()), "{e}");
            common::check_error(e);
        }
        Ok(plan) => {
            let options = RunOptions { output_dir: dir.path().to_path_buf(), ..Default::default() };
            if let Ok(sim) = Simulation::execute(plan, options) {
                assert!(sim.state.positions.iter().all(|x| x.is_finite()), "a run from an accepted restart went non-finite");
            }
        }
    }
});

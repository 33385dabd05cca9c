//! Runs that survive kills (issue 21): SIGTERM/SIGINT and a closed stdout
//! stop a run cleanly (outputs finalised, a restart written, exit status 5),
//! `cellmd run --continue` finishes it bit for bit with no deck on disk,
//! periodic checkpoints, confined outputs, output errors with their own
//! status, and the run log.

use crate::common;

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::{assert_complete_csv, seeded_fraction, state_bits, Case};
use cellmd::output::read_state;
use cellmd::run::{OUTPUT_ERROR_STATUS, STOPPED_STATUS};

fn cellmd() -> Command {
    Command::new(env!("CARGO_BIN_EXE_cellmd"))
}

/// Bonds that break, rebind and form (the system of the kinetics tests),
/// with every kind of output; `steps` steps, then the final state is saved.
fn kinetics_case(steps: u64) -> Case {
    let (top, ff) = common::kinetic_sites();
    let deck = format!(
        "units lj\ntopology t.top\nforcefield f.ff\nbox x -5 45 f y -5 35 f z -5 5 f\nneighbor skin 0.2\ntemperature 1\ntimestep 2e-4\nseed 3\n\
         thermo 20 step time pe breaks rebinds forms\nthermo_file thermo.csv\nevents events.csv\n\
         dump m every 50 mcap traj.mcap\ndump l every 50 lammps traj.dump\nrun {steps}\nwrite_state final.restart\n"
    );
    Case::new(&[("t.top", &top), ("f.ff", ff), ("deck.in", &deck)])
}

/// The MCAP has its summary (indexed readers open it) and every message reads.
fn assert_finalised_mcap(path: &Path) -> u64 {
    let bytes = std::fs::read(path).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().expect("a summary section: the MCAP was finished");
    let mut messages = 0;
    for message in mcap::MessageStream::new(&bytes).unwrap() {
        message.unwrap();
        messages += 1;
    }
    assert_eq!(summary.stats.expect("statistics").message_count, messages);
    messages
}

/// Waits until the thermo CSV has `rows` data rows (the run is stepping).
fn wait_for_rows(path: &Path, rows: usize, child: &mut std::process::Child) {
    let started = Instant::now();
    loop {
        let text = std::fs::read_to_string(path).unwrap_or_default();
        if text.lines().count() > rows {
            return;
        }
        assert!(child.try_wait().unwrap().is_none(), "the run ended before it was killed; lengthen it");
        assert!(started.elapsed() < Duration::from_secs(120), "no thermo rows after two minutes");
        std::thread::sleep(Duration::from_millis(5));
    }
}

#[test]
fn a_run_killed_at_a_random_moment_finalises_its_outputs_and_continues_bit_for_bit() {
    let steps = 6000;
    let whole = kinetics_case(steps);
    let status = cellmd().args(["run", "deck.in", "--quiet", "-o", "whole"]).current_dir(whole.output_dir()).status().unwrap();
    assert!(status.success());
    let reference = state_bits(&whole.path("whole/final.restart"));
    assert_eq!(reference.4, steps);
    assert!(reference.3.breaks > 20 && reference.3.forms > 20, "too few events to test: {:?}", reference.3);

    let killed = kinetics_case(steps);
    let mut child = cellmd()
        .args(["run", "deck.in", "--quiet", "-o", "killed"])
        .current_dir(killed.output_dir())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    wait_for_rows(&killed.path("killed/thermo.csv"), 2, &mut child);
    // A seeded random moment within the next ~half of the run.
    std::thread::sleep(Duration::from_secs_f64(0.4 * seeded_fraction(21)));
    let pid = child.id().to_string();
    assert!(Command::new("kill").args(["-TERM", &pid]).status().unwrap().success());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(i32::from(STOPPED_STATUS)), "{stderr}");
    assert!(stderr.contains("stopped after step") && stderr.contains("SIGTERM"), "{stderr}");

    let dir = killed.path("killed");
    let restart = dir.join("deck.restart");
    let stopped_at = read_state(&restart).unwrap().step;
    assert!(stopped_at > 0 && stopped_at < steps, "stopped at step {stopped_at} of {steps}");
    assert!(assert_complete_csv(&dir.join("thermo.csv")) as u64 >= stopped_at / 20);
    assert!(assert_finalised_mcap(&dir.join("traj.mcap")) > 0);
    let dump = std::fs::read_to_string(dir.join("traj.dump")).unwrap();
    let frames = dump.matches("ITEM: TIMESTEP").count();
    assert_eq!(dump.lines().count(), frames * (9 + 600), "the LAMMPS dump ends on a frame boundary");
    assert!(!dir.join("final.restart").exists());

    // No input of the original run is needed to continue it.
    for input in ["deck.in", "t.top", "f.ff"] {
        std::fs::remove_file(killed.path(input)).unwrap();
    }
    let resumed = cellmd()
        .args(["run", "--quiet", "--continue", "killed/deck.restart", "-o", "resumed"])
        .current_dir(killed.output_dir())
        .output()
        .unwrap();
    assert!(resumed.status.success(), "{}", String::from_utf8_lossy(&resumed.stderr));
    let continued = state_bits(&killed.path("resumed/final.restart"));
    assert_eq!(continued.4, steps);
    assert_eq!(continued.3, reference.3, "cumulative counters go on from the restart");
    assert_eq!(continued.2, reference.2, "bond state");
    assert_eq!(continued.1, reference.1, "image counters");
    assert!(continued.0 == reference.0, "positions differ from the uninterrupted run's (stopped at step {stopped_at})");
    assert!(assert_complete_csv(&killed.path("resumed/thermo.csv")) > 0);
}

#[test]
fn a_closed_stdout_ends_the_run_quietly_with_its_outputs_finalised() {
    let case = kinetics_case(200_000);
    let mut child = cellmd()
        .args(["run", "deck.in", "-o", "out"])
        .current_dir(case.output_dir())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // `| head -2`: read two lines, then close the pipe.
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    for _ in 0..2 {
        stdout.read_line(&mut String::new()).unwrap();
    }
    drop(stdout);
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked") && !stderr.contains("Broken pipe"), "{stderr}");
    assert_eq!(out.status.code(), Some(i32::from(STOPPED_STATUS)), "{stderr}");
    let dir = case.path("out");
    assert_complete_csv(&dir.join("thermo.csv"));
    assert_finalised_mcap(&dir.join("traj.mcap"));
    assert!(read_state(&dir.join("deck.restart")).unwrap().step < 200_000);
}

#[test]
fn sigint_stops_like_sigterm() {
    let case = kinetics_case(200_000);
    let mut child = cellmd()
        .args(["run", "deck.in", "--quiet", "-o", "out"])
        .current_dir(case.output_dir())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    wait_for_rows(&case.path("out/thermo.csv"), 1, &mut child);
    assert!(Command::new("kill").args(["-INT", &child.id().to_string()]).status().unwrap().success());
    assert_eq!(child.wait().unwrap().code(), Some(i32::from(STOPPED_STATUS)));
    assert!(read_state(&case.path("out/deck.restart")).unwrap().resume.is_some());
}

/// A small periodic bead-spring system for in-process runs.
fn chains_case(extra: &str) -> Case {
    let mut top = String::from("[ particles ]\n");
    let mut bonds = String::from("[ bonds ]\n");
    for c in 0..20 {
        for b in 0..10 {
            let id = c * 10 + b + 1;
            top += &format!("{id} p {} {} {}\n", (c % 5) as f64 * 1.4, (c / 5) as f64 * 1.4, b as f64 * 0.97);
            if b > 0 {
                bonds += &format!("s {} {}\n", id - 1, id);
            }
        }
    }
    let ff = "particle p drag 1\nbond s harmonic k 50 r0 1\npair p p wca epsilon 1 sigma 0.8\n";
    let deck = format!(
        "units lj\ntopology t.top\nforcefield f.ff\nbox x 0 7 p y 0 7 p z 0 9.7 p\nneighbor skin 0.3\ntemperature 1.0\ntimestep 0.0005\nseed 99\n{extra}"
    );
    Case::new(&[("t.top", &top), ("f.ff", ff), ("deck.in", &deck)])
}

#[test]
fn periodic_checkpoints_keep_the_last_k_and_each_continues_the_run() {
    // A later `write_state … every` replaces the earlier one.
    let case = chains_case(
        "write_state ck.*.restart every 50 keep 2\nrun 300\nwrite_state last.restart every 100\nrun 100\nwrite_state final.restart\n",
    );
    case.run();
    for (step, kept) in [(0, false), (150, false), (200, false), (250, true), (300, true), (350, false), (400, false)] {
        assert_eq!(case.path(&format!("ck.{step}.restart")).exists(), kept, "ck.{step}.restart");
    }
    assert_eq!(read_state(&case.path("ck.250.restart")).unwrap().step, 250);
    assert_eq!(read_state(&case.path("last.restart")).unwrap().step, 400);
    let reference = state_bits(&case.path("final.restart"));
    for checkpoint in ["ck.250.restart", "ck.300.restart"] {
        let out =
            cellmd().args(["run", "--quiet", "--continue", checkpoint, "-o", "resumed"]).current_dir(case.output_dir()).output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        assert!(state_bits(&case.path("resumed/final.restart")) == reference, "continued from {checkpoint}");
    }
}

/// A deck that starts from a restart file continues without it: the state
/// comes from the checkpoint.
#[test]
fn a_run_that_read_a_state_continues_without_that_file() {
    let first = chains_case("run 50\nwrite_state half.restart\n");
    first.run();
    let case = chains_case("read_state half.restart\nwrite_state ck.*.restart every 50\nrun 100\nwrite_state final.restart\n");
    std::fs::copy(first.path("half.restart"), case.path("half.restart")).unwrap();
    case.run();
    let reference = state_bits(&case.path("final.restart"));
    assert_eq!(reference.4, 150);
    for input in ["deck.in", "t.top", "f.ff", "half.restart"] {
        std::fs::remove_file(case.path(input)).unwrap();
    }
    let out =
        cellmd().args(["run", "--quiet", "--continue", "ck.100.restart", "-o", "resumed"]).current_dir(case.output_dir()).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(state_bits(&case.path("resumed/final.restart")) == reference);
}

#[test]
fn outputs_stay_under_the_output_directory_unless_allowed() {
    let outside = tempfile::tempdir().unwrap();
    let target = outside.path().join("thermo.csv");
    let case = chains_case(&format!("thermo 10\nthermo_file {}\nrun 20\n", target.display()));
    let check = cellmd().args(["check", "deck.in"]).current_dir(case.output_dir()).output().unwrap();
    assert_eq!(check.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&check.stderr);
    assert!(stderr.contains("deck.in:10:13: found output path") && stderr.contains("--allow-outside"), "{stderr}");
    let run = cellmd().args(["run", "deck.in", "-o", "out"]).current_dir(case.output_dir()).output().unwrap();
    assert_eq!(run.status.code(), Some(1));
    assert!(!target.exists());
    let allowed = cellmd().args(["run", "deck.in", "-o", "out", "--allow-outside"]).current_dir(case.output_dir()).output().unwrap();
    assert!(allowed.status.success(), "{}", String::from_utf8_lossy(&allowed.stderr));
    assert_eq!(assert_complete_csv(&target), 3);
}

#[test]
fn an_output_that_cannot_be_written_has_its_own_status_and_names_file_and_step() {
    let case = chains_case("run 10\ndump d every 5 xyz no/such/dir/t.xyz\nrun 10\n");
    let out = cellmd().args(["run", "deck.in", "-o", "out"]).current_dir(case.output_dir()).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(i32::from(OUTPUT_ERROR_STATUS)), "{stderr}");
    assert!(stderr.contains("no/such/dir/t.xyz") && stderr.contains("(at step 10)"), "{stderr}");
}

#[test]
fn the_run_log_records_what_ran_and_where_the_time_went() {
    let case = chains_case("thermo 50\nrun 200\n");
    let out =
        cellmd().args(["run", "deck.in", "--quiet", "-o", "out", "--var", "unused=1"]).current_dir(case.output_dir()).output().unwrap();
    assert!(out.status.success());
    let log = std::fs::read_to_string(case.path("out/deck.log")).unwrap();
    for expected in [
        concat!("cellmd ", env!("CARGO_PKG_VERSION"), " (git "),
        "command: ",
        "run deck.in --quiet -o out --var unused=1",
        "variable override: unused=1",
        "---- deck.in (",
        "bond s harmonic k 50 r0 1",
        "---- f.ff (",
        "run 200 from step 0 on the CPU",
        "timestep 5e-4, temperature (kT) 1e0, seed 99",
        "pair p p wca epsilon 1e0 [ε] sigma 8e-1 [σ]",
        "finished at step 200",
        "Section   |  time (s)  | %total",
        "Force     |",
        "Neigh     |",
        "Total     |",
    ] {
        assert!(log.contains(expected), "the log lacks `{expected}`:\n{log}");
    }
}

/// A GPU run in a shell without `XDG_RUNTIME_DIR` (batch jobs, containers)
/// prints no "XDG_RUNTIME_DIR is invalid" from the Vulkan driver. Like the
/// other GPU tests it needs an adapter (CI: Mesa's llvmpipe).
#[test]
fn a_headless_gpu_run_prints_no_driver_errors() {
    let case = chains_case("device gpu\nrun 20\n");
    let out = cellmd().args(["run", "deck.in", "-o", "out"]).env_remove("XDG_RUNTIME_DIR").current_dir(case.output_dir()).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "the GPU run failed (is a Vulkan driver such as mesa-vulkan-drivers installed?):\n{stderr}");
    assert!(String::from_utf8_lossy(&out.stdout).contains("device: GPU"));
    assert!(!stderr.contains("XDG_RUNTIME_DIR"), "{stderr}");
}

/// On the GPU the stop is seen at the next synchronisation (at most 1000
/// steps away; here every thermo row): the positions are read back, the
/// outputs finalised and the restart written at that step.
#[test]
fn a_gpu_run_stops_at_its_next_synchronisation_with_its_outputs_finalised() {
    let case = chains_case("device gpu\nthermo 100 step xu/all\nthermo_file thermo.csv\ndump m every 500 mcap traj.mcap\nrun 100000000\n");
    let mut child = cellmd()
        .args(["run", "deck.in", "--quiet", "-o", "out"])
        .current_dir(case.output_dir())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    wait_for_rows(&case.path("out/thermo.csv"), 2, &mut child);
    assert!(Command::new("kill").args(["-TERM", &child.id().to_string()]).status().unwrap().success());
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(i32::from(STOPPED_STATUS)), "{}", String::from_utf8_lossy(&out.stderr));
    let data = read_state(&case.path("out/deck.restart")).unwrap();
    assert!(data.step >= 100 && data.step.is_multiple_of(100), "stopped at step {}", data.step);
    assert!(assert_complete_csv(&case.path("out/thermo.csv")) as u64 > data.step / 100);
    // The restart holds the positions of its step (read back), not older ones.
    let text = std::fs::read_to_string(case.path("out/thermo.csv")).unwrap();
    let last: Vec<f64> = text.lines().last().unwrap().split(',').map(|f| f.parse().unwrap()).collect();
    assert_eq!(last[0] as u64, data.step);
    let xu = data.positions.iter().zip(&data.images).map(|(x, i)| x.x + 7.0 * i[0] as f64).sum::<f64>() / data.positions.len() as f64;
    assert!((xu - last[1]).abs() <= 1e-9 * xu.abs().max(1.0), "restart x̄u {xu} vs thermo {}", last[1]);
    assert_finalised_mcap(&case.path("out/traj.mcap"));
}

//! Runs that lose nothing (issue 45): after a SIGKILL at any moment, a double
//! SIGTERM or a full disk, every output ends at its last whole record (MCAP:
//! every message of its whole chunks recovered by streaming readers; dumps:
//! whole frames; CSVs: whole rows) and `--continue` from the last checkpoint
//! reaches the uninterrupted state bit for bit; no output is written through
//! a link inside `-o`; a restart is checked before `--continue` opens any
//! output.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::{self, seeded_fraction, state_bits, Case};
use cellmd::run::OUTPUT_ERROR_STATUS;

fn cellmd() -> Command {
    Command::new(env!("CARGO_BIN_EXE_cellmd"))
}

/// Particles and topology bonds of [`all_outputs_case`].
const PARTICLES: usize = 600;
const BONDS: usize = 300;

/// Bonds that break, rebind and form, with every kind of output written
/// as the run goes: thermo rows, the event log, a dump of each format and
/// checkpoints every 500 steps; the final state is saved.
fn all_outputs_case(steps: u64) -> Case {
    let (top, ff) = common::kinetic_sites();
    let deck = format!(
        "units lj\ntopology t.top\nforcefield f.ff\nbox x -5 45 f y -5 35 f z -5 5 f\nneighbor skin 0.2\ntemperature 1\ntimestep 2e-4\nseed 3\n\
         thermo 20 step time pe breaks rebinds forms\nthermo_file thermo.csv\nevents events.csv\n\
         dump m every 50 mcap traj.mcap\ndump x every 50 xyz traj.xyz\ndump l every 50 lammps traj.dump\n\
         dump d every 50 dcd traj.dcd\ndump b every 50 bonds bonds.csv\n\
         write_state ck.*.restart every 500\nrun {steps}\nwrite_state final.restart\n"
    );
    Case::new(&[("t.top", &top), ("f.ff", ff), ("deck.in", &deck)])
}

/// The lines of a text output, which must end with a line break (or be empty).
fn whole_lines(path: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(text.is_empty() || text.ends_with('\n'), "{} ends inside a line", path.display());
    text.lines().map(str::to_string).collect()
}

/// Rows of a CSV, each with the header's number of fields.
fn whole_rows(path: &Path) -> usize {
    let lines = whole_lines(path);
    let Some((header, rows)) = lines.split_first() else { return 0 };
    let columns = header.split(',').count();
    for row in rows {
        assert_eq!(row.split(',').count(), columns, "a partial row in {}: {row}", path.display());
    }
    rows.len()
}

/// Frames of an extended XYZ file, each whole.
fn xyz_frames(path: &Path) -> usize {
    let lines = whole_lines(path);
    assert_eq!(lines.len() % (PARTICLES + 2), 0, "{}: {} lines is not whole frames", path.display(), lines.len());
    for frame in lines.chunks(PARTICLES + 2) {
        assert_eq!(frame[0], PARTICLES.to_string());
        assert!(frame[1].starts_with("Lattice="));
        // The columns of Properties=: species, pos (3), Z, type_name, id.
        assert!(frame[2..].iter().all(|l| l.split(' ').count() == 7), "a partial line in {}", path.display());
    }
    lines.len() / (PARTICLES + 2)
}

/// Frames of a LAMMPS dump, each whole.
fn lammps_frames(path: &Path) -> usize {
    let lines = whole_lines(path);
    let frames = lines.iter().filter(|l| *l == "ITEM: TIMESTEP").count();
    assert_eq!(lines.len(), frames * (9 + PARTICLES), "{} does not end on a frame boundary", path.display());
    frames
}

/// Frames of a DCD file: its length is the header and whole frames, and
/// the header counts them (or, killed between the two writes, one fewer).
fn dcd_frames(path: &Path) -> usize {
    let bytes = std::fs::read(path).unwrap();
    let header = (8 + 84) + (8 + 164) + (8 + 4);
    let frame = (8 + 48) + 3 * (8 + 4 * PARTICLES);
    assert!(
        bytes.len() >= header && (bytes.len() - header).is_multiple_of(frame),
        "{}: {} bytes is not whole frames",
        path.display(),
        bytes.len()
    );
    let frames = (bytes.len() - header) / frame;
    let counted = i32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize;
    assert!(counted == frames || counted + 1 == frames, "the header counts {counted} of {frames} frames");
    frames
}

/// The `/cellmd/frame` messages Rust's MCAP reader recovers by streaming
/// (every message before the cut; a killed file has no footer).
fn mcap_frames(path: &Path) -> usize {
    let bytes = std::fs::read(path).unwrap();
    let mut frames = 0;
    for message in mcap::MessageStream::new_with_options(&bytes, mcap::read::Options::IgnoreEndMagic.into()).unwrap() {
        let Ok(message) = message else { break };
        if message.channel.topic == "/cellmd/frame" {
            cellmd::output::mcap_messages::message_json(&message).unwrap();
            frames += 1;
        }
    }
    frames
}

/// A Python with the `mcap` package: the reference venv's, if installed.
fn python_with_mcap() -> Option<PathBuf> {
    let venv = match std::env::var_os("CELLMD_VENV") {
        Some(v) => PathBuf::from(v),
        None => PathBuf::from(std::env::var_os("HOME")?).join(".cache/cellmd/reference-venv"),
    };
    Some(venv.join("bin/python")).filter(|p| p.is_file())
}

/// The same count by the Python `mcap` package's streaming reader.
const PYTHON_MCAP_FRAMES: &str = r#"
import sys
from mcap.reader import NonSeekingReader
frames = 0
with open(sys.argv[1], "rb") as f:
    try:
        for schema, channel, message in NonSeekingReader(f).iter_messages(log_time_order=False):
            frames += channel.topic == "/cellmd/frame"
    except Exception:
        pass
print(frames)
"#;

/// Checks every output of [`all_outputs_case`] in `dir` for whole records
/// (those that exist: a kill may come before some are opened); returns the
/// frames of the XYZ dump.
fn assert_outputs_whole(dir: &Path) -> usize {
    let exists = |name: &str| dir.join(name).exists();
    if exists("thermo.csv") {
        common::assert_complete_csv(&dir.join("thermo.csv"));
    }
    if exists("events.csv") {
        whole_rows(&dir.join("events.csv"));
    }
    if exists("bonds.csv") {
        assert_eq!(whole_rows(&dir.join("bonds.csv")) % BONDS, 0, "bonds.csv ends inside a frame");
    }
    let xyz = if exists("traj.xyz") { xyz_frames(&dir.join("traj.xyz")) } else { 0 };
    if exists("traj.dump") {
        lammps_frames(&dir.join("traj.dump"));
    }
    if exists("traj.dcd") {
        dcd_frames(&dir.join("traj.dcd"));
    }
    if exists("traj.mcap") {
        let path = dir.join("traj.mcap");
        let frames = mcap_frames(&path);
        // The dumps are written one after the other: at most one frame apart.
        assert!(frames + 1 >= xyz && frames <= xyz + 1, "{frames} MCAP frames recovered, {xyz} XYZ frames written");
        if let Some(python) = python_with_mcap() {
            let out = Command::new(python).arg("-c").arg(PYTHON_MCAP_FRAMES).arg(&path).output().unwrap();
            let theirs: usize = String::from_utf8_lossy(&out.stdout).trim().parse().unwrap_or_else(|_| panic!("{out:?}"));
            assert_eq!(theirs, frames, "Python's mcap recovers {theirs} frames, Rust's {frames}");
        }
    }
    xyz
}

/// The newest checkpoint in `dir`, if any.
fn last_checkpoint(dir: &Path) -> Option<PathBuf> {
    let step = |p: &Path| p.file_name()?.to_str()?.strip_prefix("ck.")?.strip_suffix(".restart")?.parse::<u64>().ok();
    let entries = std::fs::read_dir(dir).ok()?;
    entries.map(|e| e.unwrap().path()).filter(|p| step(p).is_some()).max_by_key(|p| step(p))
}

/// Continues `dir`'s newest checkpoint into `resumed`; the final state must
/// be `reference`, bit for bit. Returns the checkpoint's step (None: none written yet).
fn continue_matches(
    case: &Case,
    dir: &Path,
    resumed: &str,
    reference: &(Vec<u64>, String, String, cellmd::output::restart::Counters, u64),
) -> Option<u64> {
    let checkpoint = last_checkpoint(dir)?;
    let out = cellmd()
        .args(["run", "--quiet", "--continue"])
        .arg(&checkpoint)
        .args(["-o", resumed])
        .current_dir(case.output_dir())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let continued = state_bits(&case.path(&format!("{resumed}/final.restart")));
    assert!(continued == *reference, "continued from {} the state differs from the uninterrupted run's", checkpoint.display());
    Some(cellmd::output::read_state(&checkpoint).unwrap().step)
}

#[test]
fn sigkill_or_a_double_sigterm_at_random_moments_leave_whole_records_and_continue_bit_for_bit() {
    let steps = 3000;
    let case = all_outputs_case(steps);
    let started = Instant::now();
    let status = cellmd().args(["run", "deck.in", "--quiet", "-o", "whole"]).current_dir(case.output_dir()).status().unwrap();
    let seconds = started.elapsed().as_secs_f64();
    assert!(status.success());
    let reference = state_bits(&case.path("whole/final.restart"));
    assert_eq!(assert_outputs_whole(&case.path("whole")), (steps / 50 + 1) as usize);
    let mut continued = Vec::new();
    // Seeded moments spread over the whole run (the start included); the last trial is a double SIGTERM.
    let trials = 5;
    for trial in 0..trials {
        let dir = format!("killed{trial}");
        let mut child = cellmd()
            .args(["run", "deck.in", "--quiet", "-o", &dir])
            .current_dir(case.output_dir())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let at = seconds * (0.05 + 0.9 * seeded_fraction(45 + trial));
        std::thread::sleep(Duration::from_secs_f64(at));
        let pid = child.id().to_string();
        if trial + 1 < trials {
            assert!(Command::new("kill").args(["-KILL", &pid]).status().unwrap().success());
        } else {
            for _ in 0..2 {
                assert!(Command::new("kill").args(["-TERM", &pid]).status().unwrap().success());
            }
        }
        child.wait().unwrap();
        assert_outputs_whole(&case.path(&dir));
        if let Some(step) = continue_matches(&case, &case.path(&dir), &format!("resumed{trial}"), &reference) {
            continued.push(step);
        }
    }
    assert!(!continued.is_empty(), "no trial wrote a checkpoint before it was killed");
}

/// A tmpfs of `size` mounted on `dir` (needs root), unmounted when dropped.
struct Tmpfs(PathBuf);

impl Tmpfs {
    fn mount(dir: &Path, size: &str) -> Option<Tmpfs> {
        std::fs::create_dir_all(dir).unwrap();
        let mounted =
            Command::new("mount").args(["-t", "tmpfs", "-o", &format!("size={size}"), "tmpfs"]).arg(dir).stderr(Stdio::null()).status();
        mounted.is_ok_and(|s| s.success()).then(|| Tmpfs(dir.to_path_buf()))
    }
}

impl Drop for Tmpfs {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(&self.0).status();
    }
}

/// A full disk (a small tmpfs, where this user may mount one) and a file
/// size limit (`ulimit -f`, as a write shim that works for any user) stop
/// the run with the output error status; every output is whole up to the
/// write that failed, and the last checkpoint continues bit for bit.
#[test]
fn a_full_disk_leaves_whole_records_and_the_last_checkpoint_continues() {
    let steps = 3000;
    let case = all_outputs_case(steps);
    let status = cellmd().args(["run", "deck.in", "--quiet", "-o", "whole"]).current_dir(case.output_dir()).status().unwrap();
    assert!(status.success());
    let reference = state_bits(&case.path("whole/final.restart"));
    let mut tried = 0;
    let tmpfs = Tmpfs::mount(&case.path("full"), "1m");
    if tmpfs.is_some() {
        let out = cellmd().args(["run", "deck.in", "--quiet", "-o", "full"]).current_dir(case.output_dir()).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(i32::from(OUTPUT_ERROR_STATUS)), "{stderr}");
        assert!(stderr.contains("No space left on device"), "{stderr}");
        assert!(assert_outputs_whole(&case.path("full")) > 0);
        // Copied off the full disk: the continued run writes elsewhere.
        continue_matches(&case, &case.path("full"), "resumed_full", &reference).expect("a checkpoint before the disk filled");
        tried += 1;
    } else {
        eprintln!("NOTE: cannot mount a tmpfs here; the full disk is tested through the file size limit only");
    }
    drop(tmpfs);
    // Each file at most 256 KiB (512-byte blocks); SIGXFSZ ignored so the write fails with EFBIG.
    let shim = format!("trap '' XFSZ; ulimit -f 512; exec {} run deck.in --quiet -o limited", env!("CARGO_BIN_EXE_cellmd"));
    let out = Command::new("sh").arg("-c").arg(&shim).current_dir(case.output_dir()).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(i32::from(OUTPUT_ERROR_STATUS)), "{stderr}");
    assert!(stderr.contains("File too large"), "{stderr}");
    assert!(assert_outputs_whole(&case.path("limited")) > 0);
    continue_matches(&case, &case.path("limited"), "resumed_limited", &reference).expect("a checkpoint before the limit");
    tried += 1;
    assert!(tried >= 1);
}

/// A small periodic system for the link and restart checks.
fn small_case(extra: &str) -> Case {
    let mut top = String::from("[ particles ]\n");
    for i in 0..40 {
        top += &format!("{} p {} {} {}\n", i + 1, (i % 4) as f64 * 1.5, ((i / 4) % 4) as f64 * 1.5, (i / 16) as f64 * 1.5);
    }
    let ff = "particle p drag 1\npair p p wca epsilon 1 sigma 0.8\n";
    let deck =
        format!("units lj\ntopology t.top\nforcefield f.ff\nbox x 0 6 p y 0 6 p z 0 6 p\ntemperature 1\ntimestep 0.001\nseed 5\n{extra}");
    Case::new(&[("t.top", &top), ("f.ff", ff), ("deck.in", &deck)])
}

#[cfg(unix)]
#[test]
fn outputs_are_never_written_through_a_link_inside_the_output_directory() {
    use std::os::unix::fs::symlink;
    let outside = tempfile::tempdir().unwrap();
    let victim = outside.path().join("victim");
    std::fs::write(&victim, "keep").unwrap();
    // (deck lines, planted link inside -o, its target, whether the run must fail, what the error names)
    let cases = [
        ("dump d every 5 xyz t.xyz\nrun 10\n", "t.xyz", &victim, true, "t.xyz` is a symbolic link"),
        ("thermo 5\nthermo_file thermo.csv\nrun 10\n", "thermo.csv", &victim, true, "thermo.csv` is a symbolic link"),
        ("events e.csv\nrun 10\n", "e.csv", &victim, true, "e.csv` is a symbolic link"),
        ("run 10\n", "deck.log", &victim, true, "deck.log` is a symbolic link"),
        (
            "dump d every 5 lammps sub/t.dump\nrun 10\n",
            "sub",
            &outside.path().to_path_buf(),
            true,
            "sub` is a symbolic link or not a directory",
        ),
        ("run 10\nwrite_state s.restart\n", "s.restart", &victim, true, "s.restart` is a symbolic link"),
        // A stale (here planted) temporary is removed, never written through.
        ("run 10\nwrite_state s.restart\n", "s.restart.tmp", &victim, false, ""),
    ];
    for (lines, link, target, fails, names) in cases {
        let case = small_case(lines);
        let out_dir = case.path("out");
        std::fs::create_dir(&out_dir).unwrap();
        symlink(target, out_dir.join(link)).unwrap();
        let out = cellmd().args(["run", "deck.in", "--quiet", "-o", "out"]).current_dir(case.output_dir()).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        if fails {
            assert_eq!(out.status.code(), Some(i32::from(OUTPUT_ERROR_STATUS)), "{link}: {stderr}");
            assert!(stderr.contains(names) && stderr.contains("cellmd writes no output through links"), "{link}: {stderr}");
        } else {
            assert!(out.status.success(), "{link}: {stderr}");
            assert!(cellmd::output::read_state(&out_dir.join("s.restart")).is_ok());
            assert!(!out_dir.join("s.restart.tmp").exists());
        }
        assert_eq!(std::fs::read_to_string(&victim).unwrap(), "keep", "{link}: written through the link");
        assert_eq!(std::fs::read_dir(outside.path()).unwrap().count(), 1, "{link}: a file appeared outside -o");
    }
}

/// A restart whose place in the deck or whose state does not fit is bad
/// input to `--continue` (status 1): refused before any output, the run
/// log included, is opened.
#[test]
fn a_restart_that_does_not_fit_is_refused_before_any_output() {
    let case = small_case("write_state ck.*.restart every 20\nrun 100\nwrite_state final.restart\n");
    let out = cellmd().args(["run", "deck.in", "--quiet", "-o", "."]).current_dir(case.output_dir()).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(case.path("ck.40.restart")).unwrap();
    let good: serde_json::Value = serde_json::from_str(&text).unwrap();
    let spoilt = |name: &str, spoil: &dyn Fn(&mut serde_json::Value)| {
        let mut v = good.clone();
        spoil(&mut v);
        std::fs::write(case.path(name), v.to_string()).unwrap();
        name.to_string()
    };
    let cases = [
        (
            spoilt("far.restart", &|v| v["resume"]["run_end"] = 1_000_000.into()),
            "far.restart: resume.run_end: found 1000000, expected at most 140 (step 40 + the 100 steps of its `run`)",
        ),
        (spoilt("beyond.restart", &|v| v["resume"]["action"] = 99.into()), "beyond.restart: resume.action: found 99, expected at most"),
        (
            spoilt("not_run.restart", &|v| v["resume"]["action"] = 0.into()),
            "not_run.restart: resume.run_end: found 100, expected none (action 0 is not a `run`)",
        ),
        (spoilt("order.restart", &|v| v["ids"][0] = 2.into()), "order.restart: ids[0]: found id 2, expected id 1"),
        (
            spoilt("flipped.restart", &|v| {
                v["box"]["periodic"][2] = false.into();
                v["images"] = serde_json::json!(vec![[0, 0, 0]; 40]);
            }),
            "flipped.restart: box.periodic: found [true, true, false]",
        ),
        (spoilt("time.restart", &|v| v["time"] = (-1.0).into()), "time.restart: time: found -1e0, expected a finite time >= 0"),
    ];
    for (restart, expected) in cases {
        let out =
            cellmd().args(["run", "--quiet", "--continue", &restart, "-o", "resumed"]).current_dir(case.output_dir()).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{restart}: {stderr}");
        assert!(stderr.contains(expected), "{restart}: stderr lacks `{expected}`:\n{stderr}");
        let written: Vec<_> = std::fs::read_dir(case.path("resumed")).map(|d| d.collect()).unwrap_or_default();
        assert!(written.is_empty(), "{restart}: outputs were opened: {written:?}");
    }
}

/// The files `cellmd export-lammps` and `cellmd import-lammps` write.
const EXPORTED: [&str; 2] = ["data.lammps", "in.lammps"];
const IMPORTED: [&str; 3] = ["system.top", "system.ff", "system.in"];

/// `dir`'s `names` must each hold `old` or exactly the reference's bytes
/// (from `reference`), and no temporary may be left when `clean`; returns
/// how many hold the new bytes.
fn old_or_new(dir: &Path, reference: &Path, names: &[&str], clean: bool) -> usize {
    let mut new = 0;
    for name in names {
        let got = std::fs::read(dir.join(name)).unwrap_or_else(|e| panic!("{}: {e}", dir.join(name).display()));
        if got != b"old\n" {
            assert!(
                got == std::fs::read(reference.join(name)).unwrap(),
                "{}: neither the old file nor the whole new one",
                dir.join(name).display()
            );
            new += 1;
        }
        assert!(!clean || !dir.join(format!("{name}.tmp")).exists(), "{name}.tmp left in {}", dir.display());
    }
    new
}

/// `dir` (created) with each of `names` holding `old`.
fn plant_old(dir: &Path, names: &[&str]) {
    std::fs::create_dir_all(dir).unwrap();
    for name in names {
        std::fs::write(dir.join(name), "old\n").unwrap();
    }
}

/// A command that writes files: its reference run's directory, its
/// arguments for an output directory, and the files it writes there.
type WritingCommand<'a> = (&'a str, &'a dyn Fn(&str) -> Vec<String>, &'a [&'a str]);

/// `cellmd export-lammps` and `import-lammps` write each file atomically:
/// killed at seeded moments, on a full disk (a small tmpfs where one can be
/// mounted) and past a file size limit, every file they write holds its old
/// contents or the whole new ones, and a failed write exits with the output
/// error status naming the file, leaving no temporary behind.
#[test]
fn export_and_import_leave_each_file_old_or_whole_after_a_kill_or_a_full_disk() {
    // 64 000 particles: files of megabytes, written over a measurable time.
    let case = Case::new(&[
        ("t.top", &common::grid_topology(40, 1.0)),
        ("f.ff", "particle p drag 1\npair p p wca epsilon 1 sigma 0.8\n"),
        (
            "deck.in",
            "units lj\ntopology t.top\nforcefield f.ff\nbox x -1 40 p y -1 40 p z -1 40 p\ntemperature 1\ntimestep 0.001\nrun 10\n",
        ),
    ]);
    let export = |dir: &str| -> Vec<String> { vec!["export-lammps".into(), "deck.in".into(), dir.into()] };
    let import = |dir: &str| -> Vec<String> { vec!["import-lammps".into(), "ref/in.lammps".into(), "-o".into(), dir.into()] };
    let timed = |args: &[String]| {
        let started = Instant::now();
        let out = cellmd().args(args).current_dir(case.output_dir()).output().unwrap();
        assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
        started.elapsed().as_secs_f64()
    };
    let commands: [WritingCommand; 2] = [("ref", &export, &EXPORTED), ("imp_ref", &import, &IMPORTED)];
    let seconds: Vec<f64> = commands.iter().map(|(reference, args, _)| timed(&args(reference))).collect();
    let mut replaced = 0;
    for (k, (reference, args, names)) in commands.iter().enumerate() {
        let reference = case.path(reference);
        for trial in 0..4 {
            let dir = format!("killed{k}.{trial}");
            plant_old(&case.path(&dir), names);
            let mut child =
                cellmd().args(args(&dir)).current_dir(case.output_dir()).stdout(Stdio::null()).stderr(Stdio::null()).spawn().unwrap();
            std::thread::sleep(Duration::from_secs_f64(seconds[k] * (0.2 + 0.8 * seeded_fraction(450 + 10 * k as u64 + trial))));
            assert!(Command::new("kill").args(["-KILL", &child.id().to_string()]).status().unwrap().success());
            child.wait().unwrap();
            // A kill may leave the temporary of the file being written; never a part of a named file.
            replaced += old_or_new(&case.path(&dir), &reference, names, false);
        }
        // A file size limit of 256 KiB (SIGXFSZ ignored, so the write fails with EFBIG).
        let dir = format!("limited{k}");
        plant_old(&case.path(&dir), names);
        let shim = format!("trap '' XFSZ; ulimit -f 512; exec {} \"$@\"", env!("CARGO_BIN_EXE_cellmd"));
        let out = Command::new("sh").arg("-c").arg(&shim).arg("sh").args(args(&dir)).current_dir(case.output_dir()).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(i32::from(OUTPUT_ERROR_STATUS)), "{stderr}");
        assert!(stderr.contains(&format!("{dir}/{}: File too large", names[0])), "{stderr}");
        assert_eq!(old_or_new(&case.path(&dir), &reference, names, true), 0);
        // A full disk.
        let dir = format!("full{k}");
        if let Some(tmpfs) = Tmpfs::mount(&case.path(&dir), "256k") {
            plant_old(&case.path(&dir), names);
            let out = cellmd().args(args(&dir)).current_dir(case.output_dir()).output().unwrap();
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(i32::from(OUTPUT_ERROR_STATUS)), "{stderr}");
            assert!(stderr.contains(&format!("{dir}/{}: No space left on device", names[0])), "{stderr}");
            assert_eq!(old_or_new(&case.path(&dir), &reference, names, true), 0);
            drop(tmpfs);
        } else {
            eprintln!("NOTE: cannot mount a tmpfs here; the full disk is tested through the file size limit only");
        }
    }
    eprintln!("export {:.2} s, import {:.2} s; {replaced} files replaced whole before the kills", seconds[0], seconds[1]);
}

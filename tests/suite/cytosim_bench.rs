//! `bench/cytosim --smoke`: the Cytosim side-by-side harness without Cytosim.
//! It writes every system's Cytosim config and parses it back against the
//! system's description, reads a report in Cytosim's `report fiber:points`
//! format, and runs the cellmd side (the springs variants) at two fibres for
//! 0.02 s through the observables; a mismatch or a failed run exits non-zero.

use std::process::Command;

#[test]
fn cytosim_harness_smoke_writes_both_engines_inputs_and_runs_cellmd() {
    let root = env!("CARGO_MANIFEST_DIR");
    let work = tempfile::tempdir().unwrap();
    let out = Command::new("python3")
        .arg(format!("{root}/bench/cytosim"))
        .args(["--smoke", "--cellmd", env!("CARGO_BIN_EXE_cellmd"), "--work"])
        .arg(work.path())
        .output()
        .expect("python3 runs bench/cytosim");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "bench/cytosim --smoke failed ({}):\n{stdout}\n{stderr}", out.status);
    assert!(stdout.contains("smoke: ok"), "{stdout}");
    for system in ["free", "buckling", "bundle"] {
        assert!(stdout.contains(&format!("{system}: cellmd springs-implicit dt=0.001")), "{system} did not run:\n{stdout}");
    }
}

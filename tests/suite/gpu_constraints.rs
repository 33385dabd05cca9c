//! `constrain` on the device (src/gpu/shake.rs) against the CPU's f64
//! projection, on whatever Vulkan adapter exists (CI: Mesa's llvmpipe).

use crate::common;

use cellmd::gpu::shake::F32_TOLERANCE;
use cellmd::gpu::DevicePreference;
use cellmd::run::{RunOptions, Simulation};

const SEGMENT: f64 = 0.1;

/// The largest |r − r0|/r0 the device may leave: its tolerance, plus the
/// f32 rounding of the length it measures that by (the separation rounded
/// once, then its norm: a few ε_f32; 4 taken).
fn device_length_bound() -> f64 {
    F32_TOLERANCE + 4.0 * f32::EPSILON as f64
}

/// A chain of `n` segments of 0.1 µm along x, its first `anchors` beads
/// fixed, its tip pulled by (fx, fy) pN; segments constrained (soft
/// harmonic bonds, k = 10, that alone would stretch), `extra` deck lines
/// before the run.
fn chain(n: usize, anchors: usize, dt: f64, steps: u64, load: (f64, f64), extra: &str) -> common::Case {
    let (top, ff) = common::chain_of_rods(n, anchors);
    let deck = format!(
        "topology t.top\nforcefield f.ff\nbox x -2 2 f y -2 2 f z -2 2 f\ngroup tip id {}\n\
         external load tip constant_force fx {} fy {}\n{extra}\ntimestep {dt}\nthermo 0 step pe ctension/rod\nrun {steps}\n",
        n + 1,
        load.0,
        load.1
    );
    common::Case::new(&[("t.top", &top), ("f.ff", ff), ("deck.in", &deck)])
}

fn run(case: &common::Case, device: DevicePreference) -> Result<Simulation, String> {
    let options = RunOptions { output_dir: case.output_dir().to_path_buf(), device: Some(device), ..Default::default() };
    Simulation::execute(case.plan(), options).map_err(|e| e.to_string())
}

/// Runs `case` on the CPU and the GPU: both runs, the tip's path on the
/// CPU, the largest GPU − CPU position difference, and its bound: what two
/// projections that each stop within F32_TOLERANCE·r0 of every length can
/// differ by along a chain of ten segments (10·F32_TOLERANCE·r0; an
/// overdamped step does not integrate an earlier step's difference), plus
/// the f32 rounding of forces and steps (1e-5 of the path, as the
/// unconstrained decks in tests/suite/gpu.rs).
fn cantilever_on_both(case: &common::Case) -> (Simulation, Simulation, f64, f64, f64) {
    let cpu = run(case, DevicePreference::Cpu).unwrap();
    let gpu = run(case, DevicePreference::Gpu).unwrap();
    let start = case.plan().positions;
    let path = cpu.state.positions.iter().zip(&start).map(|(a, b)| (*a - *b).length()).fold(0.0, f64::max);
    let apart = cpu.state.positions.iter().zip(&gpu.state.positions).map(|(a, b)| (*a - *b).length()).fold(0.0, f64::max);
    let bound = 10.0 * F32_TOLERANCE * SEGMENT + 1e-5 * path;
    (cpu, gpu, path, apart, bound)
}

fn worst_length_error(sim: &Simulation) -> f64 {
    let x = &sim.state.positions;
    sim.model.bonds.iter().map(|&[i, j]| ((x[j as usize] - x[i as usize]).length() / SEGMENT - 1.0).abs()).fold(0.0, f64::max)
}

/// A chain pulled straight along its axis from a free end: every segment
/// carries the load. Each step stretches a segment by 2·load·dt/γ = 1e-3 µm
/// before the projection; the device leaves each length within
/// F32_TOLERANCE·r0 = 1e-7 µm of r0, this step and the last, so each
/// tension is the load to 2·F32_TOLERANCE·r0/(1e-3 µm) = 2e-4 relative.
#[test]
fn constraint_tension_carries_the_axial_load_on_the_gpu() {
    let load = 0.5;
    let (dt, drag) = (1e-5, 0.01);
    let case = chain(10, 1, dt, 50, (load, 0.0), "constrain rod method shake tolerance 1e-10");
    let gpu = run(&case, DevicePreference::Gpu).unwrap();
    let cpu_sweeps = run(&case, DevicePreference::Cpu).unwrap().constraints.iterations;
    let c = &gpu.constraints;
    assert_eq!(c.tension.len(), 10);
    let stretch = 2.0 * load * dt / drag;
    let bound = 2.0 * F32_TOLERANCE * SEGMENT / stretch;
    let worst = c.tension.iter().map(|t| (t / load - 1.0).abs()).fold(0.0, f64::max);
    println!(
        "tensions {:?}: worst relative error {worst:.2e} (bound {bound:.1e}), {} sweeps a step (CPU {cpu_sweeps})",
        c.tension, c.iterations
    );
    assert!(worst < bound, "a segment's tension is off the load by {worst:e} (bound {bound:e})");
    assert!(c.iterations >= 1);
    let error = worst_length_error(&gpu);
    assert!(error <= device_length_bound(), "a segment is off r0 by {error:e} of r0");
}

/// A clamped cantilever bent by a transverse load, its middle bead held in
/// y, 2 000 steps: the device keeps every length within its tolerance (as
/// it measures it), and its chain follows the CPU's (projected to 1e-10)
/// within the bound of [`cantilever_on_both`].
#[test]
fn a_constrained_cantilever_bends_on_the_gpu_like_on_the_cpu() {
    let limit = 0.01 * 1e-3 / (8.0 * 0.01);
    // Bead 6 is held in y (`freeze`): the projection must not move it there.
    let case = chain(10, 2, 0.4 * limit, 2_000, (0.0, 0.02), "constrain rod method shake tolerance 1e-10\ngroup mid id 6\nfreeze mid y");
    let (cpu, gpu, path, apart, bound) = cantilever_on_both(&case);
    println!(
        "tip moved {path:.4e} µm; GPU − CPU {apart:.3e} µm (bound {bound:.2e}); worst |r − r0|/r0 GPU {:.2e}, CPU {:.2e}",
        worst_length_error(&gpu),
        worst_length_error(&cpu)
    );
    assert!(path > 0.01, "the load barely bent the filament ({path:e} µm)");
    assert!(apart < bound, "GPU and CPU chains part by {apart:e} µm (bound {bound:e})");
    assert!(worst_length_error(&gpu) <= device_length_bound());
    assert_eq!(gpu.state.positions[5].y, 0.0, "the projection moved a held coordinate");
}

/// One sweep cannot straighten a chain pulled hard: the device halts the run
/// at the step the CPU does, with the CPU's message, and keeps the state
/// before it.
#[test]
fn an_unmet_constraint_stops_the_gpu_run_like_the_cpu_run() {
    let case = chain(10, 1, 1e-5, 5, (50.0, 20.0), "constrain rod method shake tolerance 1e-8 max_iterations 1");
    let cpu = run(&case, DevicePreference::Cpu).err().expect("the CPU run fails");
    let gpu = run(&case, DevicePreference::Gpu).err().expect("the GPU run fails");
    println!("CPU: {cpu}\nGPU: {gpu}");
    for message in [&cpu, &gpu] {
        assert!(message.contains("constraint of bond") && message.contains("not met after 1 sweeps at step 1:"), "{message}");
    }
    assert!(gpu.contains(&format!("> tolerance {F32_TOLERANCE:e}")), "{gpu}");
}

/// With `integrator implicit` the device solves the constrained step (projected
/// CG, an inner CG for JD⁻¹Jᵀ) and then projects, as the CPU: the clamped
/// cantilever at 100× the explicit limit reaches the CPU's equilibrium
/// within the explicit test's bound, and a chain pulled along its axis
/// carries the load in every constraint (the solve's λ plus SHAKE's share)
/// within ten times the implicit solve's relative tolerance (its λ is
/// exact to about that; measured 2.5e-7).
#[test]
fn the_constrained_implicit_step_runs_on_the_gpu_like_on_the_cpu() {
    let limit = 0.01 * 1e-3 / (8.0 * 0.01);
    let case = chain(10, 2, 100.0 * limit, 1_000, (0.0, 0.02), "constrain rod method shake tolerance 1e-10\nintegrator implicit");
    let (cpu, gpu, path, apart, bound) = cantilever_on_both(&case);
    println!(
        "implicit cantilever: tip moved {path:.4e} µm; GPU − CPU {apart:.3e} µm (bound {bound:.2e}); worst |r − r0|/r0 GPU {:.2e}; \
         last solve GPU {} iterations, CPU {}",
        worst_length_error(&gpu),
        gpu.reports.last_solve.iterations,
        cpu.reports.last_solve.iterations
    );
    assert!(path > 0.05, "the load barely bent the filament ({path:e} µm)");
    assert!(apart < bound, "GPU and CPU equilibria part by {apart:e} µm (bound {bound:e})");
    assert!(worst_length_error(&gpu) <= device_length_bound());

    let load = 0.5;
    let pulled = chain(10, 1, 1e-2, 50, (load, 0.0), "constrain rod method shake tolerance 1e-10\nintegrator implicit");
    let gpu = run(&pulled, DevicePreference::Gpu).unwrap();
    let worst = gpu.constraints.tension.iter().map(|t| (t / load - 1.0).abs()).fold(0.0, f64::max);
    println!("implicit pull: tensions {:?}, worst relative error {worst:.2e}", gpu.constraints.tension);
    assert_eq!(gpu.constraints.tension.len(), 10);
    let bound = 10.0 * cellmd::gpu::implicit::F32_TOLERANCE;
    assert!(worst < bound, "a segment's tension is off the load by {worst:e} (bound {bound:e})");
}

/// The projection has no float atomics and a fixed order: the same run
/// twice gives the same bits, tensions included.
#[test]
fn the_same_constrained_gpu_run_twice_gives_the_same_bits() {
    let case = chain(10, 2, 5e-5, 200, (0.0, 0.02), "constrain rod method shake");
    let first = run(&case, DevicePreference::Gpu).unwrap();
    let second = run(&case, DevicePreference::Gpu).unwrap();
    assert_eq!(common::position_bits(&first), common::position_bits(&second));
    let bits = |s: &Simulation| s.constraints.tension.iter().map(|t| t.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&first), bits(&second));
    assert!(first.constraints.tension.iter().any(|&t| t != 0.0));
}

/// `cellmd profile-gpu` times the implicit step and the projection of a
/// constrained implicit deck in their own rows, each a positive share.
#[test]
fn profile_gpu_times_the_implicit_step_and_the_projection() {
    let case = chain(10, 2, 1e-2, 10, (0.0, 0.02), "constrain rod method shake\nintegrator implicit");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_cellmd"))
        .current_dir(case.output_dir())
        .args(["profile-gpu", "deck.in", "--repetitions", "3"])
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .unwrap();
    let table = String::from_utf8_lossy(&out.stdout);
    println!("{table}{}", String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success());
    for row in ["integration / implicit", "constraint projection"] {
        let line = table.lines().find(|l| l.starts_with(row)).unwrap_or_else(|| panic!("no `{row}` row"));
        let share: f64 = line.split_whitespace().last().unwrap().trim_end_matches('%').parse().unwrap();
        assert!(share > 0.0, "{line}");
    }
}

/// Chains of constraints under the default `method fibre` are solved fibre
/// by fibre, which only the CPU does: `device gpu` refuses them with the
/// reason and the way out, `device auto` runs them on the CPU.
#[test]
fn fibres_solved_fibre_by_fibre_are_refused_on_the_gpu_with_the_way_out() {
    let case = chain(10, 2, 5e-5, 20, (0.0, 0.02), "constrain rod");
    let refused = run(&case, DevicePreference::Gpu).err().expect("the GPU refuses");
    println!("{refused}");
    assert!(refused.contains("fibre by fibre on the CPU backend only") && refused.contains("method shake"), "{refused}");
    let auto = run(&case, DevicePreference::Auto).unwrap();
    let cpu = run(&case, DevicePreference::Cpu).unwrap();
    assert_eq!(common::position_bits(&auto), common::position_bits(&cpu));
}

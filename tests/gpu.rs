//! The GPU backend against the CPU f64 backend, on whatever Vulkan adapter
//! exists (CI: Mesa's llvmpipe). A missing adapter fails these tests with
//! a message saying what to install; they never pass vacuously.

mod common;

use cellmd::backend::{CpuBackend, Forces};
use cellmd::deck::{Action, Plan};
use cellmd::run::{RunOptions, Simulation};
use cellmd::gpu::backend::StepSettings;
use cellmd::gpu::{GpuBackend, GpuContext};
use cellmd::integrate::overdamped::OverdampedSettings;
use cellmd::system::State;
use common::random_case;
use glam::DVec3;

fn context() -> GpuContext {
    GpuContext::open(false).unwrap_or_else(|e| {
        panic!("the GPU tests need a Vulkan adapter; `scripts/test-all` installs Mesa's software driver (mesa-vulkan-drivers): {e}")
    })
}

fn initial_state(plan: &Plan) -> State {
    let mut state = State::new(plan.positions.clone());
    for (x, image) in state.positions.iter_mut().zip(state.images.iter_mut()) {
        plan.sim_box.wrap(x, image);
    }
    state
}

fn settings(skin: f64, dt: f64, kt: f64) -> StepSettings {
    StepSettings { dt, kt, seed: 7, skin, neighbor_every: 1, neighbor_check: true, integrator: OverdampedSettings::default() }
}

/// Every unexcluded pair closer than `range` (minimum image), by brute force.
fn brute_force_pairs(plan: &Plan, state: &State, range: f64) -> Vec<Vec<(u32, f64)>> {
    let excluded = plan.model.excluded_pairs(None);
    let n = state.len();
    let images = plan.sim_box.images();
    (0..n)
        .map(|i| {
            (0..n)
                .filter(|&j| j != i)
                .filter(|&j| !excluded.contains(&(i.min(j) as u32, i.max(j) as u32)))
                .map(|j| (j as u32, images.minimum_image(state.positions[j] - state.positions[i]).length()))
                .filter(|&(_, r)| r < range * (1.0 + 1e-5))
                .collect()
        })
        .collect()
}

/// The GPU list holds every pair closer than the range and nothing beyond it
/// (pairs within f32 rounding of the range may go either way).
fn assert_same_pairs(gpu: &[Vec<u32>], brute: &[Vec<(u32, f64)>], range: f64, what: &str) -> usize {
    let mut total = 0;
    for (i, (ours, theirs)) in gpu.iter().zip(brute).enumerate() {
        for &(j, r) in theirs {
            if r < range * (1.0 - 1e-5) {
                assert!(ours.binary_search(&j).is_ok(), "{what}: pair ({i}, {j}) at r = {r} (range {range}) missing from the GPU list");
            }
        }
        for &j in ours {
            let r = theirs.iter().find(|&&(k, _)| k == j).map_or(f64::INFINITY, |&(_, r)| r);
            assert!(r < range * (1.0 + 1e-5), "{what}: GPU list of {i} holds {j} at r = {r}, beyond the range {range}");
        }
        let mut sorted = ours.clone();
        sorted.dedup();
        assert_eq!(sorted.len(), ours.len(), "{what}: duplicate neighbours of {i}");
        total += ours.len();
    }
    total
}

#[test]
fn gpu_neighbour_list_equals_brute_force_pair_set() {
    for periodic in [true, false] {
        for special in ["", "special_bonds 0 0 1\n"] {
            let case = random_case(periodic, special);
            let plan = case.plan();
            let state = initial_state(&plan);
            let skin = 0.4;
            let mut gpu = GpuBackend::new(&context(), &plan.model, &state, &plan.sim_box, &settings(skin, 1e-3, 0.0)).unwrap();
            gpu.evaluate();
            let range = plan.model.max_pair_cutoff() + skin;
            let pairs =
                assert_same_pairs(&gpu.neighbor_lists(), &brute_force_pairs(&plan, &state, range), range, &format!("periodic {periodic}"));
            eprintln!("periodic {periodic} {special:?}: {pairs} entries, capacity {}", gpu.neighbor_capacity());
            assert!(pairs > 1000, "only {pairs} neighbour entries: the test would be vacuous");
        }
    }
}

/// Largest |ΔF| over the largest |F|, and the relative energy difference.
fn compare_forces(cpu: &Forces, gpu: &[(DVec3, f64)]) -> (f64, f64) {
    let scale = cpu.forces.iter().map(|f| f.length()).fold(0.0, f64::max);
    let worst = cpu.forces.iter().zip(gpu).map(|(c, (g, _))| (*c - *g).length()).fold(0.0, f64::max);
    let energy: f64 = gpu.iter().map(|(_, e)| e).sum();
    let total = cpu.total_energy();
    (worst / scale, (energy - total).abs() / total.abs().max(1e-300))
}

#[test]
fn gpu_forces_match_cpu_on_the_mixed_random_system() {
    for periodic in [true, false] {
        let case = random_case(periodic, "");
        let plan = case.plan();
        let state = initial_state(&plan);
        let mut cpu = CpuBackend::new(&plan.model, &state, &plan.sim_box, 0.4).unwrap();
        let mut forces = Forces::default();
        cpu.compute(&plan.model, &state, &plan.sim_box, &mut forces);
        let mut gpu = GpuBackend::new(&context(), &plan.model, &state, &plan.sim_box, &settings(0.4, 1e-3, 0.0)).unwrap();
        gpu.evaluate();
        let (force_error, energy_error) = compare_forces(&forces, &gpu.forces_and_energies());
        eprintln!("periodic {periodic}: force error {force_error:e}, energy error {energy_error:e}");
        assert!(force_error < 1e-5, "periodic {periodic}: force error {force_error:e}");
        assert!(energy_error < 1e-5, "periodic {periodic}: energy error {energy_error:e}");
    }
}

fn golden_documents() -> Vec<(std::path::PathBuf, cellmd::compare::golden::Document)> {
    let mut files: Vec<_> = std::fs::read_dir("reference")
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "yaml"))
        .collect();
    files.sort();
    files
        .into_iter()
        .flat_map(|path| {
            let text = std::fs::read_to_string(&path).unwrap();
            cellmd::compare::golden::parse(&text).unwrap().into_iter().map(move |d| (path.clone(), d))
        })
        .collect()
}

/// The model with the deck's `external` and `coeff` commands before its first `run` applied.
fn model_before_first_run(plan: &Plan) -> cellmd::system::Model {
    let mut sim = Simulation::new(plan, RunOptions::default());
    for action in plan.actions.iter().take_while(|a| !matches!(a, Action::Run(_))) {
        if matches!(action, Action::External(_) | Action::Unexternal(_) | Action::Coeff { .. }) {
            sim.apply(action).unwrap();
        }
    }
    sim.model
}

/// Every interaction type's golden cases (LAMMPS-checked configurations):
/// GPU forces and energies against the CPU f64 backend within the
/// `gpu_epsilon` declared in its reference file.
#[test]
fn gpu_matches_cpu_on_every_golden_case() {
    let context = context();
    let docs = golden_documents();
    assert!(docs.len() >= 28, "expected two cases for each of 14 interaction types");
    for (path, doc) in docs {
        let deck = std::path::Path::new("reference").join(doc.get("deck").unwrap());
        let epsilon: f64 = doc
            .get("gpu_epsilon")
            .unwrap_or_else(|| panic!("{}: no gpu_epsilon", path.display()))
            .parse()
            .unwrap();
        assert!(doc.get("gpu_epsilon_reason").is_some_and(|r| !r.is_empty()), "{}: no gpu_epsilon_reason", path.display());
        let plan = cellmd::deck::validate_file(&deck, &[]).unwrap();
        let model = model_before_first_run(&plan);
        let state = initial_state(&plan);
        let mut cpu = CpuBackend::new(&model, &state, &plan.sim_box, 0.3).unwrap();
        let mut forces = Forces::default();
        cpu.compute(&model, &state, &plan.sim_box, &mut forces);
        let mut gpu = GpuBackend::new(&context, &model, &state, &plan.sim_box, &settings(0.3, 1e-3, 0.0)).unwrap();
        gpu.evaluate();
        let (force_error, energy_error) = compare_forces(&forces, &gpu.forces_and_energies());
        println!("{:40} force {force_error:.2e}  energy {energy_error:.2e}  (gpu_epsilon {epsilon:e})", deck.display());
        assert!(force_error <= epsilon && energy_error <= epsilon, "{}: GPU differs from the CPU: force {force_error:e}, energy {energy_error:e} > {epsilon:e}", deck.display());
    }
}

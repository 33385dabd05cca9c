//! The GPU backend against the CPU f64 backend, on whatever Vulkan adapter
//! exists (CI: Mesa's llvmpipe). A missing adapter fails these tests with
//! a message saying what to install; they never pass vacuously.

use crate::common;

use crate::common::{
    assert_clamped_runs_agree, contact_case, random_case, CONTACT_ADHESION, CONTACT_BARRIER, CONTACT_GPU_EPSILON, CONTACT_SHELLS,
};
use cellmd::backend::{CpuBackend, Forces};
use cellmd::deck::{Action, Plan};
use cellmd::gpu::backend::StepSettings;
use cellmd::gpu::implicit::F32_TOLERANCE;
use cellmd::gpu::{DevicePreference, GpuBackend, GpuContext};
use cellmd::integrate::context::StepContext;
use cellmd::integrate::overdamped::OverdampedSettings;
use cellmd::integrate::Integrator;
use cellmd::rng::Noise;
use cellmd::run::{RunOptions, Simulation};
use cellmd::system::State;
use glam::DVec3;

fn context() -> GpuContext {
    GpuContext::open(false).unwrap_or_else(|e| {
        panic!("the GPU tests need a Vulkan adapter; `scripts/test-all` installs Mesa's software driver (mesa-vulkan-drivers): {e}")
    })
}

/// The plan's initial state, with bond state where bonds have one (per-bond rest lengths).
fn initial_state(plan: &Plan) -> State {
    let mut state = State::new(plan.positions.clone());
    for (x, image) in state.positions.iter_mut().zip(state.images.iter_mut()) {
        plan.sim_box.wrap(x, image);
    }
    state.bonds = cellmd::kinetics_engine::initial_bond_state(&plan.model);
    state
}

fn settings(skin: f64, dt: f64, kt: f64) -> StepSettings {
    StepSettings { context: StepContext { dt, kt, seed: 7, ..Default::default() }, skin, neighbor_every: 1, neighbor_check: true }
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
            gpu.evaluate().unwrap();
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

/// CPU (f64) and GPU forces of `model` at `state` against each other:
/// (largest force difference, energy difference), relative as in [`compare_forces`].
fn gpu_vs_cpu(model: &cellmd::system::Model, state: &State, sim_box: &cellmd::system::SimBox, skin: f64) -> (f64, f64) {
    let mut cpu = CpuBackend::new(model, state, sim_box, skin).unwrap();
    let mut forces = Forces::default();
    cpu.compute(model, state, sim_box, &mut forces);
    let mut gpu = GpuBackend::new(&context(), model, state, sim_box, &settings(skin, 1e-3, 0.0)).unwrap();
    gpu.evaluate().unwrap();
    compare_forces(&forces, &gpu.forces_and_energies())
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
        gpu.evaluate().unwrap();
        let (force_error, energy_error) = compare_forces(&forces, &gpu.forces_and_energies());
        eprintln!("periodic {periodic}: force error {force_error:e}, energy error {energy_error:e}");
        assert!(force_error < 1e-5, "periodic {periodic}: force error {force_error:e}");
        assert!(energy_error < 1e-5, "periodic {periodic}: energy error {energy_error:e}");
    }
}

/// Fractional `special_bonds` weights with pair rules: on five random-walk
/// chains of 40 beads (steps of 0.45, so 1-2, 1-3 and most 1-4 neighbours
/// lie within the pair cutoffs), bonded neighbours (1-2 at 0.5, 1-3 at
/// 0.25, 1-4 at 0.8) interact through their pair rules scaled by the
/// weight, from each particle's own list on the GPU. Forces and energies
/// within 1e-5 of the CPU's, relative to the largest force (as for the
/// mixed random system: the same f32 pair evaluators, plus one rounding of
/// w); the weighted pairs matter: with weights 0 0 0 the CPU's forces
/// differ by more than 1e-2 of the largest.
#[test]
fn fractional_special_bonds_weights_run_on_the_gpu_like_on_the_cpu() {
    let mut next = common::uniform(0x5BEC1A1);
    let mut top = String::from("[ particles ]\n");
    let mut bonds = String::from("[ bonds ]\n");
    for chain in 0..5 {
        let mut x = DVec3::new(4.0, 4.0, 4.0) + DVec3::new(next(), next(), next()) * 2.0 - 1.0;
        for bead in 1..=40 {
            let id = 40 * chain + bead;
            let ty = if bead % 4 == 0 { "b" } else { "a" };
            top += &format!("{id} {ty} {} {} {}\n", x.x, x.y, x.z);
            if bead > 1 {
                bonds += &format!("s {} {id}\n", id - 1);
            }
            let step = DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5).normalize() * 0.45;
            // Reflected at 0.5 from the box faces.
            x = (x + step).to_array().map(|c| if !(0.5..=7.5).contains(&c) { c - 2.0 * (c - c.clamp(0.5, 7.5)) } else { c }).into();
        }
    }
    top += &bonds;
    let ff = "particle a drag 1\nparticle b drag 2\nbond s harmonic k 2 r0 0.45\n\
              pair a a soft A 1 rc 0.9\npair a b soft_repulsion k 5 sigma 0.5\npair b b soft A 2 rc 0.8\n";
    let cpu_forces = |special: &str| {
        let deck = format!("units lj\n{special}topology t.top\nforcefield f.ff\nbox x 0 8 f y 0 8 f z 0 8 f\nneighbor skin 0.4\n");
        let plan = common::Case::new(&[("t.top", &top), ("f.ff", ff), ("deck.in", &deck)]).plan();
        let state = initial_state(&plan);
        let mut cpu = CpuBackend::new(&plan.model, &state, &plan.sim_box, 0.4).unwrap();
        let mut forces = Forces::default();
        cpu.compute(&plan.model, &state, &plan.sim_box, &mut forces);
        (plan, state, forces)
    };
    let (plan, state, forces) = cpu_forces("special_bonds lj 0.5 0.25 0.8\n");
    let sim = Simulation::before_first_run(&plan, RunOptions::default()).unwrap();
    assert_eq!(sim.cpu_only_feature(), None);
    let (force_error, energy_error) = gpu_vs_cpu(&plan.model, &state, &plan.sim_box, 0.4);
    println!("special_bonds: force error {force_error:e}, energy error {energy_error:e}");
    assert!(force_error < 1e-5 && energy_error < 1e-5, "force error {force_error:e}, energy error {energy_error:e}");
    let (_, _, without) = cpu_forces("special_bonds lj 0 0 0\n");
    let scale = forces.forces.iter().map(|f| f.length()).fold(0.0, f64::max);
    let change = forces.forces.iter().zip(&without.forces).map(|(a, b)| (*a - *b).length()).fold(0.0, f64::max);
    println!("special_bonds: the weighted pairs change the forces by {:.3e} of the largest", change / scale);
    assert!(change > 1e-2 * scale, "the weighted pairs change the forces by only {change:e}: the test would be vacuous");
}

/// The `field` external with constant parameters runs on the GPU (its
/// evaluator `shaders/interactions/field.wgsl`) like on the CPU.
#[test]
fn a_field_external_runs_on_the_gpu_like_on_the_cpu() {
    let case = random_case(false, "");
    let deck = std::fs::read_to_string(case.path("deck.in")).unwrap();
    std::fs::write(case.path("deck.in"), format!("{deck}external trap all field fx 0.5 fy -0.25 fz 1 e 2\n")).unwrap();
    let plan = case.plan();
    let sim = Simulation::before_first_run(&plan, RunOptions::default()).unwrap();
    assert_eq!(sim.model.externals.len(), 1);
    assert_eq!(sim.cpu_only_feature(), None);
    let (force_error, energy_error) = gpu_vs_cpu(&sim.model, &initial_state(&plan), &plan.sim_box, 0.4);
    eprintln!("field external: force error {force_error:e}, energy error {energy_error:e}");
    assert!(force_error < 1e-5 && energy_error < 1e-5, "force error {force_error:e}, energy error {energy_error:e}");
}

/// A stiff wall near z = 0 in a box from −1000: the GPU's unwrapped
/// positions keep f32's precision at the particles' own coordinates (box_lo +
/// x summed in fixed point, rounded once), so the wall forces (up to 300 pN
/// at 0.3 µm inside a k = 1000 wall) match the CPU's within 1e-6 of the
/// largest. Rounded at the box's scale (ulp 6.1e-5 µm at 1000) they were off
/// by up to 3e-2 pN, 1e-4 of it: spheroid_spreading.in's dish wall set its
/// clamped steps' length 1.2e-5 apart from the CPU's.
#[test]
fn a_stiff_wall_far_from_the_box_corner_pushes_as_on_the_cpu() {
    let mut next = common::uniform(0xD15C);
    let mut top = String::from("[ particles ]\n");
    for id in 1..=200 {
        top += &format!("{id} a {} {} {}\n", 20.0 * next() - 10.0, 20.0 * next() - 10.0, 0.3 * next());
    }
    let deck = "units lj\ntopology t.top\nforcefield f.ff\nbox x -1000 1000 f y -1000 1000 f z -1000 1000 f\n\
                external dish all wall nz 1 d 0.3 k 1000\n";
    let case = common::Case::new(&[("t.top", &top), ("f.ff", "particle a drag 1\n"), ("deck.in", deck)]);
    let plan = case.plan();
    let model = Simulation::before_first_run(&plan, RunOptions::default()).unwrap().model;
    let state = initial_state(&plan);
    let mut cpu = CpuBackend::new(&model, &state, &plan.sim_box, 0.1).unwrap();
    let mut forces = Forces::default();
    cpu.compute(&model, &state, &plan.sim_box, &mut forces);
    let mut gpu = GpuBackend::new(&context(), &model, &state, &plan.sim_box, &settings(0.1, 1e-3, 0.0)).unwrap();
    gpu.evaluate().unwrap();
    let largest = forces.forces.iter().map(|f| f.length()).fold(0.0, f64::max);
    let worst = forces.forces.iter().zip(gpu.forces_and_energies()).map(|(c, (g, _))| (*c - g).length()).fold(0.0, f64::max) / largest;
    println!("wall forces up to {largest:e}: GPU − CPU ≤ {worst:e} of it");
    assert!(largest > 100.0, "the wall pushes with only {largest:e}: the test would be vacuous");
    assert!(worst < 1e-6, "GPU − CPU {worst:e} of the largest wall force");
}

/// Externals with expression parameters (formulas of x, y, z and t): a
/// `field` trap whose centre moves with t, a `wall` whose offset `d` moves
/// with t and a `custom` external that reads t, on 60 free particles for
/// 2000 steps (t from 0 to 2). Forces and energies at the start within
/// 1e-5 of the CPU's (f32: a formula takes ≤ 6 roundings of terms ≤ 10,
/// relative to forces ≥ 1), and positions within 1e-5 of the distance
/// travelled: each step's force carries ≈ 10·u·|x| ≈ 6e-6 (x and t rounded
/// to f32 once, u = 2⁻²⁴, |x| ≤ 10), the traps contract, so the error stays
/// at that level instead of adding up, while the particles travel ≥ 1.
/// The time must reach the kernels: a GPU without it would lag the moving
/// traps by up to 1 (tested: the deviation bound is 1e-5 × the path).
#[test]
fn externals_with_expression_parameters_run_on_the_gpu_like_on_the_cpu() {
    let mut next = common::uniform(0x51F15E);
    let mut top = String::from("[ particles ]\n");
    for id in 1..=60 {
        top += &format!("{id} a {} {} {}\n", 4.0 * next() - 2.0, 4.0 * next() - 2.0, 4.0 * next());
    }
    let ff = "particle a drag 1\n";
    let deck = "units lj\ntopology t.top\nforcefield f.ff\nbox x -10 10 f y -10 10 f z -10 10 f\n\
                external trap all field fx \"-2*(x - 1 - 0.5*t)\" fy \"-2*y\" fz 0 e \"(x - 1 - 0.5*t)^2 + y^2\"\n\
                external floor all wall nz 1 d \"0.5 + 1.5*t\" k 20\n\
                external spin all custom \"0.5*(z - 2 + t*t/4)^2*k\" k 3\n\
                timestep 1e-3\nthermo 0 step pe\nrun 2000\n";
    let case = common::Case::new(&[("t.top", &top), ("f.ff", ff), ("deck.in", deck)]);
    let plan = case.plan();
    let sim = Simulation::before_first_run(&plan, RunOptions::default()).unwrap();
    assert_eq!(sim.cpu_only_feature(), None);
    assert!(sim.model.externals.iter().all(|e| !e.expressions.is_empty()), "every external has an expression parameter");
    let (force_error, energy_error) = gpu_vs_cpu(&sim.model, &initial_state(&plan), &plan.sim_box, 0.3);
    println!("expression externals at t = 0: force error {force_error:e}, energy error {energy_error:e}");
    assert!(force_error < 1e-5 && energy_error < 1e-5, "force error {force_error:e}, energy error {energy_error:e}");

    let path = case.path("deck.in");
    let (start, gpu) = run_deck_deterministic(&path, DevicePreference::Gpu, 2000, false).unwrap();
    let (_, cpu) = run_deck_deterministic(&path, DevicePreference::Cpu, 2000, false).unwrap();
    assert!((gpu.time - 2.0).abs() < 1e-9 && gpu.time == cpu.time, "t = {} on the GPU, {} on the CPU", gpu.time, cpu.time);
    let travelled = (0..start.len()).map(|i| (cpu.positions[i] - start.positions[i]).length()).fold(0.0, f64::max);
    let deviation = (0..start.len()).map(|i| (cpu.positions[i] - gpu.positions[i]).length()).fold(0.0, f64::max);
    println!("expression externals: GPU − CPU {deviation:.3e} after travelling up to {travelled:.3e}");
    assert!(travelled > 1.0, "the traps did not move the particles ({travelled:e})");
    assert!(deviation <= 1e-5 * travelled, "GPU − CPU {deviation:e} > 1e-5 × {travelled:e}");
}

/// `custom` bonds, angles, pairs and an external run on the GPU from WGSL
/// generated from their expression trees: forces and energies against the
/// CPU f64 backend within 1e-3 (f32 forces, and WGSL bounds `sin`, `cos`,
/// `acos` loosely, as for the built-in `soft` and `harmonic_angle`).
#[test]
fn custom_terms_run_on_the_gpu_like_on_the_cpu() {
    let deck = std::fs::read_to_string("reference/custom/random.in").unwrap();
    let dir = tempfile::tempdir().unwrap();
    for file in ["random.top", "custom.ff"] {
        std::fs::copy(format!("reference/custom/{file}"), dir.path().join(file)).unwrap();
    }
    let deck = deck.replace("run 100", "external push all custom \"-f*x + k*(y-3)^2\" f 0.5 k 0.2\nrun 1");
    std::fs::write(dir.path().join("deck.in"), deck).unwrap();
    let plan = cellmd::deck::validate_file(&dir.path().join("deck.in"), &[]).unwrap();
    let sim = Simulation::before_first_run(&plan, RunOptions::default()).unwrap();
    assert_eq!(sim.cpu_only_feature(), None);
    let state = initial_state(&plan);
    let mut cpu = CpuBackend::new(&sim.model, &state, &plan.sim_box, 0.3).unwrap();
    let mut forces = Forces::default();
    cpu.compute(&sim.model, &state, &plan.sim_box, &mut forces);
    let mut gpu = GpuBackend::new(&context(), &sim.model, &state, &plan.sim_box, &settings(0.3, 1e-3, 0.0)).unwrap();
    gpu.evaluate().unwrap();
    let (force_error, energy_error) = compare_forces(&forces, &gpu.forces_and_energies());
    eprintln!("custom terms: force error {force_error:e}, energy error {energy_error:e}");
    assert!(force_error < 1e-3 && energy_error < 1e-3, "force error {force_error:e}, energy error {energy_error:e}");
}

fn golden_documents() -> Vec<(std::path::PathBuf, cellmd::compare::golden::Document)> {
    let mut files: Vec<_> =
        std::fs::read_dir("reference").unwrap().map(|e| e.unwrap().path()).filter(|p| p.extension().is_some_and(|e| e == "yaml")).collect();
    files.sort();
    files
        .into_iter()
        .flat_map(|path| {
            let text = std::fs::read_to_string(&path).unwrap();
            cellmd::compare::golden::parse(&text).unwrap().into_iter().map(move |d| (path.clone(), d))
        })
        .collect()
}

/// The GPU tolerance of the per-face surface laws (their golden files,
/// written by reference/openmm_surfaces.py, declare none), relative to the
/// largest force (and energy), from f32 arithmetic with u = 2⁻²⁴ ≈ 6e-8:
/// a face's edge vectors are rounded once, its area, normal and gradients
/// take about 16 more roundings (≈ 1e-6 relative to the face's own force);
/// a node sums 5–7 faces whose forces exceed their sum by up to ~10 on the
/// golden meshes (cancellation between the faces around a node) → ≈ 1e-5;
/// the pressure of turgor is K·(V − V0)/V0 with V summed in f32 over the
/// body's faces (relative error ≈ log₂(F)·u ≈ 5e-7, times K/|ΔP| ≤ 20 on
/// the golden cases) → ≈ 1e-5. Twice that sum, with margin: 5e-5.
const SURFACE_GPU_EPSILON: f64 = 5e-5;

/// `helfrich_bending`'s tolerance: its bending angles come from WGSL's
/// `atan2`, which is only bound to 4096 ulp (2.4e-4 relative on θ, as for
/// `harmonic_angle`'s gpu_epsilon), and θ enters the forces both directly
/// (θ·∂ℓ) and through ∂E/∂M_i: 1e-3.
const HELFRICH_GPU_EPSILON: f64 = 1e-3;

/// The GPU tolerance of the volume-element laws (their golden files,
/// written by reference/openmm_solids.py, declare none), relative to the
/// largest force (and energy), from f32 arithmetic with u = 2⁻²⁴ ≈ 6e-8:
/// the edge matrix D_s is rounded once and D_m⁻¹ once (its condition number
/// is ≤ 10 on the golden meshes), so F = D_s·D_m⁻¹ carries ≈ 3·10·u ≈ 2e-6;
/// J, F⁻ᵀ (cross products) and P take a few more roundings each, and
/// μ(F − F⁻ᵀ) loses the digits of its cancellation, ≈ 1/strain ≤ 10 on the
/// golden cases (strains ≥ 0.1) → ≈ 2e-5 on an element's force; a node sums
/// its elements (≤ 24), whose forces exceed their sum by a factor of a few
/// on the golden meshes, but the errors are independent and add in
/// quadrature; with margin: 1e-4. The energy, V_0·W summed in f32 over the
/// elements, is well within that.
const TETRA_GPU_EPSILON: f64 = 1e-4;

/// The GPU tolerance of a deck with surface terms.
fn surface_gpu_epsilon(plan: &Plan) -> f64 {
    if plan.model.body_rules.iter().any(|t| t.interaction.name() == "helfrich_bending") {
        HELFRICH_GPU_EPSILON
    } else {
        SURFACE_GPU_EPSILON
    }
}

/// Every interaction type's golden cases (LAMMPS-checked configurations):
/// GPU forces and energies against the CPU f64 backend within the
/// `gpu_epsilon` declared in its reference file ([`SURFACE_GPU_EPSILON`]
/// and [`HELFRICH_GPU_EPSILON`] for the surface laws,
/// [`TETRA_GPU_EPSILON`] for the volume elements).
#[test]
fn gpu_matches_cpu_on_every_golden_case() {
    let context = context();
    let docs = golden_documents();
    let mut compared = 0;
    for (path, doc) in docs {
        let deck = std::path::Path::new("reference").join(doc.get("deck").unwrap());
        let plan = cellmd::deck::validate_file(&deck, &[]).unwrap();
        if plan.model.bond_kinetics.iter().any(|k| !k.rules.is_empty()) || !plan.model.bind_rules.is_empty() {
            // Bond-breaking and formation cases record bond sets, not a force
            // tolerance; the GPU's kinetics are checked against the CPU's events
            // in `kinetics_decks_give_the_same_events_on_the_gpu`.
            assert!(doc.get("gpu_epsilon").is_none(), "{}: a kinetics case declares a gpu_epsilon", path.display());
            continue;
        }
        let epsilon = if !plan.model.tetras.is_empty() {
            assert!(doc.get("gpu_epsilon").is_none(), "{}: declares a gpu_epsilon besides the volume-element tolerance", path.display());
            TETRA_GPU_EPSILON
        } else if plan.model.has_surface_terms() {
            assert!(doc.get("gpu_epsilon").is_none(), "{}: declares a gpu_epsilon besides the surface tolerances", path.display());
            surface_gpu_epsilon(&plan)
        } else {
            assert!(doc.get("gpu_epsilon_reason").is_some_and(|r| !r.is_empty()), "{}: no gpu_epsilon_reason", path.display());
            doc.get("gpu_epsilon").unwrap_or_else(|| panic!("{}: no gpu_epsilon", path.display())).parse().unwrap()
        };
        let sim = Simulation::before_first_run(&plan, RunOptions::default()).unwrap();
        // The volume-element decks deform their rest-shape topology with
        // `displace_atoms` (at rest, both backends' forces are round-off).
        let state = if plan.model.tetras.is_empty() { initial_state(&plan) } else { sim.state.clone() };
        let model = sim.model;
        let mut cpu = CpuBackend::new(&model, &state, &plan.sim_box, 0.3).unwrap();
        let mut forces = Forces::default();
        cpu.compute(&model, &state, &plan.sim_box, &mut forces);
        let mut gpu = GpuBackend::new(&context, &model, &state, &plan.sim_box, &settings(0.3, 1e-3, 0.0)).unwrap();
        gpu.evaluate().unwrap();
        let (force_error, energy_error) = compare_forces(&forces, &gpu.forces_and_energies());
        println!("{:40} force {force_error:.2e}  energy {energy_error:.2e}  (gpu_epsilon {epsilon:e})", deck.display());
        assert!(
            force_error <= epsilon && energy_error <= epsilon,
            "{}: GPU differs from the CPU: force {force_error:e}, energy {energy_error:e} > {epsilon:e}",
            deck.display()
        );
        compared += 1;
    }
    assert!(compared >= 44, "only {compared} golden cases compared: expected two for each of 22 interaction types");
}

#[test]
fn dispatches_split_along_y_give_the_same_list() {
    let case = random_case(true, "");
    let plan = case.plan();
    let state = initial_state(&plan);
    let mut wide = GpuBackend::new(&context(), &plan.model, &state, &plan.sim_box, &settings(0.4, 1e-3, 0.0)).unwrap();
    wide.evaluate().unwrap();
    let mut narrow = GpuBackend::new(&context(), &plan.model, &state, &plan.sim_box, &settings(0.4, 1e-3, 0.0)).unwrap();
    narrow.limit_dispatch_width(1); // 400 particles: 2 workgroups, dispatched as 1 × 2
    narrow.evaluate().unwrap();
    assert_eq!(wide.neighbor_lists(), narrow.neighbor_lists());
    assert_eq!(wide.forces_and_energies(), narrow.forces_and_energies());
}

/// A dense cluster in a large box: the first list capacity, sized from the
/// mean density, overflows; the backend grows it and loses no neighbour.
#[test]
fn neighbour_list_overflow_grows_the_list_and_drops_nothing() {
    let mut top = String::from("[ particles ]\n");
    let mut seed = 12345u64;
    let mut next = || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    for id in 1..=600 {
        top += &format!("{id} a {} {} {}\n", 1.0 + 1.5 * next(), 1.0 + 1.5 * next(), 1.0 + 1.5 * next());
    }
    let ff = "particle a drag 1\npair a a soft A 0.01 rc 0.5\n";
    let deck = "units lj\ntopology t.top\nforcefield f.ff\nbox x 0 40 p y 0 40 p z 0 40 p\nneighbor skin 0.2\n";
    let case = common::Case::new(&[("t.top", &top), ("f.ff", ff), ("deck.in", deck)]);
    let plan = case.plan();
    let state = initial_state(&plan);
    let mut gpu = GpuBackend::new(&context(), &plan.model, &state, &plan.sim_box, &settings(0.2, 1e-3, 0.0)).unwrap();
    let first_capacity = gpu.neighbor_capacity();
    gpu.evaluate().unwrap();
    assert!(gpu.neighbor_list_growths() >= 1, "capacity {first_capacity} did not overflow: the test would be vacuous");
    let range = 0.7;
    assert_same_pairs(&gpu.neighbor_lists(), &brute_force_pairs(&plan, &state, range), range, "clustered");
    let most = gpu.neighbor_lists().iter().map(|l| l.len()).max().unwrap();
    assert!(most as u32 > first_capacity, "largest list {most} fits the first capacity {first_capacity}");
    assert!(most as u32 <= gpu.neighbor_capacity());
}

/// Particles diffuse across the periodic faces; the list rebuilt on the GPU
/// still equals the brute-force pair set at the read-back positions.
/// The random mixture with soft pairs only (its LJ overlaps would blow a run up).
fn soft_random_case() -> common::Case {
    let case = random_case(true, "");
    let ff = "particle a drag 1\nparticle b drag 2\nbond s harmonic k 2 r0 0.5\nangle t cosine_angle K 0.3\n\
              pair a a soft A 1 rc 0.9\npair a b soft A 1 rc 0.7\npair a b soft_repulsion k 5 sigma 0.5\n";
    std::fs::write(case.path("f.ff"), ff).unwrap();
    case
}

#[test]
fn neighbour_list_after_particles_cross_the_boundaries() {
    let case = soft_random_case();
    let plan = case.plan();
    let mut state = initial_state(&plan);
    let mut gpu = GpuBackend::new(&context(), &plan.model, &state, &plan.sim_box, &settings(0.4, 1e-3, 1.0)).unwrap();
    assert_eq!(gpu.run(0, 300), Ok(300));
    gpu.download(&mut state);
    let crossed = state.images.iter().filter(|i| i.iter().any(|&k| k != 0)).count();
    assert!(crossed >= 10, "only {crossed} particles crossed a face");
    assert!(gpu.neighbor_builds() >= 3, "{} builds: the displacement trigger never fired", gpu.neighbor_builds());
    gpu.evaluate().unwrap();
    let range = plan.model.max_pair_cutoff() + 0.4;
    assert_same_pairs(&gpu.neighbor_lists(), &brute_force_pairs(&plan, &state, range), range, "after crossing");
}

#[test]
fn the_same_gpu_run_twice_gives_the_same_bits() {
    let case = soft_random_case();
    let plan = case.plan();
    let run = || {
        let mut state = initial_state(&plan);
        let mut gpu = GpuBackend::new(&context(), &plan.model, &state, &plan.sim_box, &settings(0.4, 1e-3, 0.5)).unwrap();
        assert_eq!(gpu.run(0, 400), Ok(400));
        gpu.download(&mut state);
        (state.positions, state.images, gpu.forces_and_energies())
    };
    let (a, b) = (run(), run());
    assert!(a.0.iter().zip(&b.0).all(|(x, y)| x.to_array().map(f64::to_bits) == y.to_array().map(f64::to_bits)), "positions differ");
    assert_eq!(a.1, b.1);
    assert!(a
        .2
        .iter()
        .zip(&b.2)
        .all(|(x, y)| x.0.to_array().map(f64::to_bits) == y.0.to_array().map(f64::to_bits) && x.1.to_bits() == y.1.to_bits()));
}

/// The golden decks of the surface laws (one to three bodies, periodic and
/// not) at kT = 0 for 2000 steps: GPU positions within their force tolerance
/// ([`surface_gpu_epsilon`]) of the distance the nodes travelled. Each step's
/// displacement dt·F/γ carries the force's relative error (≤ that epsilon,
/// see there) plus one f32 rounding; the relaxations contract, so the errors
/// add up to at most epsilon × the path, which at kT = 0 is the distance
/// travelled.
#[test]
fn surface_golden_decks_run_on_the_gpu_like_on_the_cpu() {
    let mut compared = 0;
    for law in ["turgor", "turgor_log", "surface_tension", "area_conservation", "surface_shear", "helfrich_bending"] {
        for case in ["random", "small"] {
            let deck = std::path::Path::new("reference").join(law).join(format!("{case}.in"));
            let (start, gpu) = run_deck_deterministic(&deck, DevicePreference::Gpu, 2000, false).unwrap();
            let (_, cpu) = run_deck_deterministic(&deck, DevicePreference::Cpu, 2000, false).unwrap();
            let plan = cellmd::deck::validate_file(&deck, &[]).unwrap();
            let (sim_box, epsilon) = (plan.sim_box, surface_gpu_epsilon(&plan));
            let unwrap = |s: &State, i: usize| sim_box.unwrap(s.positions[i], s.images[i]);
            let travelled = (0..start.len()).map(|i| (unwrap(&cpu, i) - unwrap(&start, i)).length()).fold(0.0, f64::max);
            let deviation = (0..start.len()).map(|i| (unwrap(&cpu, i) - unwrap(&gpu, i)).length()).fold(0.0, f64::max);
            println!("{:40} GPU − CPU {deviation:.3e} after travelling up to {travelled:.3e}", deck.display());
            assert!(travelled > 1e-3, "{}: nothing moved ({travelled:e})", deck.display());
            assert!(deviation <= epsilon * travelled, "{}: GPU − CPU {deviation:e} > {epsilon:e} × {travelled:e}", deck.display());
            compared += 1;
        }
    }
    assert_eq!(compared, 12);
}

/// Two bodies carrying all six surface laws, with noise: the same GPU run
/// twice gives the same bits (fixed-order sums, no float atomics).
#[test]
fn the_same_surface_run_twice_gives_the_same_bits() {
    let top = std::fs::read_to_string("reference/area_conservation/random.top").unwrap();
    let ff = "particle a drag 1\nparticle b drag 2.5\n\
              body cell turgor k 50 dp0 2 v0 60\nbody cell surface_tension gamma 1.5\nbody cell area_conservation ka 20 kl 10 a0 65\n\
              body cell helfrich_bending kappa 0.2 c0 0.5\n\
              body nucleus turgor_log k 80 v0 40\nbody nucleus surface_shear k 0.5\nbody nucleus area_conservation kl 15 a0 41\n";
    let deck = "units lj\ntopology t.top\nforcefield f.ff\nbox x 0.0 12.0 p y 0.0 12.0 p z 0.0 12.0 p\n";
    let case = common::Case::new(&[("t.top", &top), ("f.ff", ff), ("deck.in", deck)]);
    let plan = case.plan();
    assert_eq!(plan.model.bodies.len(), 2);
    let run = || {
        let mut state = initial_state(&plan);
        let mut gpu = GpuBackend::new(&context(), &plan.model, &state, &plan.sim_box, &settings(0.3, 1e-4, 0.05)).unwrap();
        assert_eq!(gpu.run(0, 500), Ok(500));
        gpu.download(&mut state);
        (state.positions, gpu.forces_and_energies())
    };
    let (a, b) = (run(), run());
    let start = initial_state(&plan).positions;
    let moved = a.0.iter().zip(&start).map(|(x, y)| (*x - *y).length()).fold(0.0, f64::max);
    assert!(moved > 1e-3, "nothing moved ({moved:e}): the test would be vacuous");
    assert!(a.0.iter().zip(&b.0).all(|(x, y)| x.to_array().map(f64::to_bits) == y.to_array().map(f64::to_bits)), "positions differ");
    assert!(a
        .1
        .iter()
        .zip(&b.1)
        .all(|(x, y)| x.0.to_array().map(f64::to_bits) == y.0.to_array().map(f64::to_bits) && x.1.to_bits() == y.1.to_bits()));
}

/// An elastic ball (`cellmd build ball`, 125 nodes, 384 linear tetrahedra)
/// squeezed between two walls for 2000 explicit steps, once per volume law:
/// the GPU's positions stay within [`TETRA_GPU_EPSILON`] of the distance
/// the nodes travelled (each step's displacement carries the force's
/// relative error; the relaxation contracts, so the errors add up to at
/// most epsilon × the path). The same GPU run twice gives the same bits.
#[test]
fn a_squeezed_ball_runs_on_the_gpu_like_on_the_cpu() {
    let top = common::small_ball();
    let deck = "units cell\ntopology ball.top\nforcefield ball.ff\nbox x -8 8 f y -8 8 f z -8 8 f\n\
                external bottom all wall nz 1 d -4.6 k 1000\nexternal top all wall nz -1 d -4.6 k 1000\n\
                integrator overdamped\ntimestep 1e-4\nthermo 0 step pe\nrun 2000\n";
    for law in ["neo_hookean", "linear_elastic"] {
        let ff = format!("particle node drag 1\ntetra solid {law} e 1000 nu 0.3\n");
        let case = common::Case::new(&[("ball.top", &top), ("ball.ff", &ff), ("deck.in", deck)]);
        let path = case.path("deck.in");
        let (start, gpu) = run_deck_deterministic(&path, DevicePreference::Gpu, 2000, false).unwrap();
        let (_, again) = run_deck_deterministic(&path, DevicePreference::Gpu, 2000, false).unwrap();
        let (_, cpu) = run_deck_deterministic(&path, DevicePreference::Cpu, 2000, false).unwrap();
        assert_eq!(start.len(), 125);
        let travelled = (0..start.len()).map(|i| (cpu.positions[i] - start.positions[i]).length()).fold(0.0, f64::max);
        let deviation = (0..start.len()).map(|i| (cpu.positions[i] - gpu.positions[i]).length()).fold(0.0, f64::max);
        println!("ball, {law}: GPU − CPU {deviation:.3e} after travelling up to {travelled:.3e}");
        assert!(travelled > 0.1, "{law}: the walls did not squeeze the ball ({travelled:e})");
        assert!(deviation <= TETRA_GPU_EPSILON * travelled, "{law}: GPU − CPU {deviation:e} > {TETRA_GPU_EPSILON:e} × {travelled:e}");
        let bits = |s: &State| s.positions.iter().flat_map(|x| x.to_array().map(f64::to_bits)).collect::<Vec<_>>();
        assert_eq!(bits(&gpu), bits(&again), "{law}: two GPU runs differ");
    }
}

/// A custom body term has no GPU kernel: the GPU backend and `device gpu`
/// refuse it with the reason.
#[test]
fn a_custom_body_term_is_refused_by_the_gpu() {
    let top = std::fs::read_to_string("reference/turgor/small.top").unwrap();
    let ff = "particle a drag 1\nbody cell custom \"0.5*K*(V-V0)^2/V0 + gamma*A\" K 100 V0 8 gamma 2\n";
    let deck = "units lj\ntopology t.top\nforcefield f.ff\nbox x -10 10 f y -10 10 f z -10 10 f\ntimestep 1e-4\nrun 10\n";
    let case = common::Case::new(&[("t.top", &top), ("f.ff", ff), ("deck.in", deck)]);
    let plan = case.plan();
    let state = initial_state(&plan);
    let refusal = GpuBackend::new(&context(), &plan.model, &state, &plan.sim_box, &settings(0.3, 1e-4, 0.0)).err().unwrap_or_default();
    assert!(refusal.contains("no kernels for custom surface terms of bodies"), "{refusal}");
    let why = Simulation::before_first_run(&plan, RunOptions::default()).unwrap().cpu_only_feature();
    assert_eq!(why, Some("custom surface terms of bodies (`custom` body lines) run on the CPU backend only"));
}

/// The device's steps are backward Euler: `theta` ½ (the trapezoidal rule)
/// keeps a run on the CPU, with the reason, instead of being ignored there.
#[test]
fn theta_other_than_one_keeps_a_run_on_the_cpu() {
    let top = "[ particles ]\n1 a 0.2 0.3 0.4\n2 a 1.1 1.6 2.0\n";
    let ff = "particle a drag 1\n";
    let deck = |integrator: &str| {
        format!("units lj\ntopology t.top\nforcefield f.ff\nbox x 0 3 f y 0 3 f z 0 3 f\n{integrator}\ntimestep 1e-4\nrun 10\n")
    };
    for (integrator, refused) in
        [("integrator implicit theta 0.5", true), ("integrator overdamped theta 0.5", true), ("integrator implicit theta 1", false)]
    {
        let case = common::Case::new(&[("t.top", top), ("f.ff", ff), ("deck.in", &deck(integrator))]);
        let why = Simulation::before_first_run(&case.plan(), RunOptions::default()).unwrap().cpu_only_feature();
        if refused {
            assert_eq!(
                why,
                Some("steps with `theta` other than 1 (the device's steps are backward Euler) run on the CPU backend only"),
                "{integrator}"
            );
            assert!(refused_by_the_gpu(&format!("device gpu: {}; use `device cpu` or `device auto`", why.unwrap())));
        } else {
            assert_eq!(why, None, "{integrator}");
        }
    }
}

/// A periodic box shorter than twice the pair range (pairs through several
/// images, which the CPU's list walks) has no GPU kernel: the GPU backend
/// and `device gpu` refuse it rather than use the minimum image alone.
#[test]
fn a_box_shorter_than_twice_the_pair_range_is_refused_by_the_gpu() {
    let top = "[ particles ]\n1 a 0.2 0.3 0.4\n2 a 1.1 1.6 2.0\n3 a 2.4 0.9 1.3\n";
    let ff = "particle a drag 1\npair a a soft A 1 rc 1.5\n";
    let small = "units lj\ntopology t.top\nforcefield f.ff\nbox x 0 3 p y 0 3 p z 0 3 p\nneighbor skin 0.3\ntimestep 1e-4\nrun 10\n";
    let case = common::Case::new(&[("t.top", top), ("f.ff", ff), ("deck.in", small)]);
    let plan = case.plan();
    let state = initial_state(&plan);
    let refusal = GpuBackend::new(&context(), &plan.model, &state, &plan.sim_box, &settings(0.3, 1e-4, 0.0)).err().unwrap_or_default();
    assert!(refusal.contains("several periodic images") && refusal.contains("= 3.6"), "{refusal}");
    let why = Simulation::before_first_run(&plan, RunOptions::default()).unwrap().cpu_only_feature();
    assert!(why.is_some_and(|w| w.starts_with("pairs through several periodic images")), "{why:?}");
    // With edges of 2·(cutoff + skin) the minimum image is the only one: the GPU takes it.
    std::fs::write(case.path("deck.in"), small.replace("0 3 p", "0 3.6 p")).unwrap();
    let plan = case.plan();
    let state = initial_state(&plan);
    GpuBackend::new(&context(), &plan.model, &state, &plan.sim_box, &settings(0.3, 1e-4, 0.0)).unwrap();
    assert_eq!(Simulation::before_first_run(&plan, RunOptions::default()).unwrap().cpu_only_feature(), None);
}

/// A body wider than half the periodic box has no consistent minimum
/// images from one node: the GPU halts with the body named instead of
/// computing a wrong volume (the CPU unwraps it along its edges).
#[test]
fn a_body_spanning_half_the_periodic_box_halts_the_gpu_with_its_id() {
    let top = std::fs::read_to_string("reference/turgor/small.top").unwrap();
    let ff = std::fs::read_to_string("reference/turgor/small.ff").unwrap();
    // The body spans 2.7 along x: wider than the box itself.
    let narrow = "units lj\ntopology t.top\nforcefield f.ff\nbox x -1 1 p y -5 5 p z -5 5 p\n";
    let case = common::Case::new(&[("t.top", &top), ("f.ff", &ff), ("deck.in", narrow)]);
    let plan = case.plan();
    let state = initial_state(&plan);
    let mut gpu = GpuBackend::new(&context(), &plan.model, &state, &plan.sim_box, &settings(0.3, 1e-4, 0.0)).unwrap();
    let message = gpu.evaluate().unwrap_err();
    assert!(message.starts_with("body 1 spans more than half of the periodic box"), "{message}");
    match gpu.run(0, 10) {
        Err(cellmd::gpu::GpuHalt::Capacity { step: 0, message }) => assert!(message.starts_with("body 1 spans"), "{message}"),
        other => panic!("expected the span halt at step 0, got {other:?}"),
    }
    // In a box wide enough the same body runs.
    std::fs::write(case.path("deck.in"), narrow.replace("x -1 1", "x -5 5")).unwrap();
    let plan = case.plan();
    let state = initial_state(&plan);
    let mut gpu = GpuBackend::new(&context(), &plan.model, &state, &plan.sim_box, &settings(0.3, 1e-4, 0.0)).unwrap();
    gpu.evaluate().unwrap();
}

/// Runs a deck's actions up to its last `run`, or to the first `minimize`
/// after a `run`, with every `temperature` set to 0 and every `run` made
/// `steps` long, on the given device; returns the final state. A `minimize`
/// after a run ends the comparison (the device's FIRE is checked in
/// tests/suite/gpu_minimize.rs): FIRE amplifies differences: `inputs/tensegrity_cell.in`'s
/// closing `minimize` (100 iterations here) turns a GPU − CPU difference of
/// 2.3e-7 after its run into 1.2e-3, and the f32-rounded start's 2.2e-7 into
/// 7.3e-5; `inputs/cell_compression.in`, whose stages are minimisations
/// between runs, differed by 2.7e-2 after the second.
fn run_deck_deterministic(
    deck: &std::path::Path,
    device: DevicePreference,
    horizon: impl Into<Horizon>,
    round_start_to_f32: bool,
) -> Result<(State, State), String> {
    let Horizon { steps, first_run_only } = horizon.into();
    let plan = cellmd::deck::validate_file(deck, &[("steps".into(), "10".into()), ("fire_iterations".into(), "100".into())])
        .map_err(|e| e.to_string())?;
    let dir = tempfile::tempdir().unwrap();
    let options = RunOptions { output_dir: dir.path().to_path_buf(), device: Some(device), ..Default::default() };
    let mut sim = Simulation::new(&plan, options);
    if round_start_to_f32 {
        sim.state.positions.iter_mut().for_each(|x| *x = x.as_vec3().as_dvec3());
    }
    let start = sim.state.clone();
    let first_run = plan.actions.iter().position(|a| matches!(a, Action::Run(_))).unwrap_or(plan.actions.len());
    let last_run = match first_run_only {
        true => first_run + 1,
        false => plan.actions.iter().rposition(|a| matches!(a, Action::Run(_))).map_or(plan.actions.len(), |k| k + 1),
    };
    let minimize_after_run =
        plan.actions.iter().skip(first_run).position(|a| matches!(a, Action::Minimize(_))).map_or(plan.actions.len(), |k| first_run + k);
    for action in &plan.actions[..last_run.min(minimize_after_run)] {
        let action = match action {
            Action::Temperature(_) => Action::Temperature(0.0),
            Action::Run(_) => Action::Run(steps),
            other => other.clone(),
        };
        sim.apply(&action).map_err(|e| e.to_string())?;
    }
    sim.close_outputs().map_err(|e| e.to_string())?;
    Ok((start, sim.state))
}

/// How far [`run_deck_deterministic`] takes a deck: `steps` for each of its
/// `run`s, or for its first `run` only (a plain step count: every run).
#[derive(Clone, Copy)]
struct Horizon {
    steps: u64,
    first_run_only: bool,
}

impl From<u64> for Horizon {
    fn from(steps: u64) -> Self {
        Horizon { steps, first_run_only: false }
    }
}

/// An upper bound on the condition number of the implicit step's matrix
/// A = γ/dt·I + K̃ at the deck's start (Gershgorin: λ_max ≤ the largest row
/// sum of |A|; λ_min ≥ the smallest γ/dt of a mobile particle, K̃ ⪰ 0).
fn implicit_condition_bound(sim: &Simulation) -> f64 {
    let (model, state, sim_box) = (&sim.model, &sim.state, &sim.sim_box);
    let mut backend = CpuBackend::new(model, state, sim_box, 0.0).unwrap();
    backend.compute(model, state, sim_box, &mut Forces::default());
    let mut rows = vec![0.0f64; 3 * model.len()];
    for b in &backend.stiffness(model, state, sim_box).blocks {
        for (r, row) in rows[3 * b.i as usize..3 * b.i as usize + 3].iter_mut().enumerate() {
            *row += (0..3).map(|c| b.block.col(c)[r].abs()).sum::<f64>();
        }
    }
    let drag = model.types.iter().map(|&t| model.type_drag[t as usize] / sim.settings.dt).filter(|d| d.is_finite());
    let (lo, hi) = drag.fold((f64::INFINITY, 0.0f64), |(lo, hi), d| (lo.min(d), hi.max(d)));
    (hi + rows.iter().copied().fold(0.0, f64::max)) / lo
}

/// Every `inputs/` deck without bond kinetics that the GPU runs (all but those
/// with custom body terms, constraints the device cannot project
/// (src/gpu/shake.rs), or an implicit step the device cannot
/// solve (src/gpu/implicit.rs), which it refuses with the message of
/// `Simulation::cpu_only_feature`): at kT = 0, GPU positions stay within
/// 1e-5 of the distance the particles travelled, after 10⁴ steps per `run`
/// (10³ for decks of more than 300 particles; measured on llvmpipe: ≤ 1.8e-6 of the path, within the spread
/// between two CPU runs whose starts differ by f32 rounding, ≤ 5.3e-6); over a tenth, a hundredth … of the steps where that
/// spread itself exceeds the bound (a chaotic deck: adhesive_doublet.in, 10
/// steps) or the deck's prescribed
/// motion wrecks it within the horizon (tensegrity_substrate.in). An implicit deck
/// (buckling_filament.in) is compared over 10² steps, within κ(A)·(the device's
/// CG tolerance + 8ε_f32) of the distance travelled ([`implicit_condition_bound`]):
/// its f32 solve is only that exact (measured: 2.5e-6 of the path). For the
/// quasi-static Newton steps of a `solver cholesky` deck (force_dipole.in,
/// hertz_*.in; γ/dt = 1e-6) that bound says nothing (κ(A) ~ 10⁸): such a deck
/// takes one step of its first stage here, and its check is that the
/// GPU's end state is the CPU's equilibrium
/// (tests/suite/gpu_implicit.rs, `newton_steps_of_a_cholesky_deck_reach_the_cpu_equilibrium_on_the_gpu`).
#[test]
fn every_input_deck_runs_on_the_gpu_like_on_the_cpu() {
    let mut decks: Vec<_> =
        std::fs::read_dir("inputs").unwrap().map(|e| e.unwrap().path()).filter(|p| p.extension().is_some_and(|e| e == "in")).collect();
    decks.sort();
    let (mut compared, mut refused) = (0, 0);
    for deck in decks {
        let started = std::time::Instant::now();
        let plan = cellmd::deck::validate_file(&deck, &[("steps".into(), "10".into()), ("fire_iterations".into(), "10".into())]).unwrap();
        let setup = Simulation::before_first_run(&plan, RunOptions::default()).unwrap();
        if let Some(why) = setup.cpu_only_feature() {
            // A CPU-only feature: the GPU must refuse the deck with the reason.
            let dir = tempfile::tempdir().unwrap();
            let options = RunOptions { output_dir: dir.path().to_path_buf(), device: Some(DevicePreference::Gpu), ..Default::default() };
            let refusal = Simulation::execute(plan.clone(), options).err().map(|e| e.to_string()).unwrap_or_default();
            assert!(refusal.contains(why), "{}: expected the GPU to refuse with {why:?}, got {refusal:?}", deck.display());
            println!("{:40} refused: {why}", deck.display());
            refused += 1;
            continue;
        }
        if setup.model.has_kinetics() {
            // Bond kinetics need kT > 0: see `kinetics_decks_give_the_same_events_on_the_gpu`.
            continue;
        }
        if plan.actions.iter().all(|a| !matches!(a, Action::Run(n) if *n > 0)) {
            // Only `minimize` and `run 0` (thermo rows), e.g. cell_compression's
            // quasi-static stages: the deck takes no step for the GPU to take.
            continue;
        }
        // An implicit deck's GPU step solves in one workgroup with ~10² CG iterations
        // (0.15 s a step on llvmpipe, src/gpu/implicit.rs): compared over 10² steps (CI time).
        // Explicit decks of more than 300 particles start at 10³ steps, the
        // others at 10⁴, for CI time: on llvmpipe a step costs its dispatches
        // whatever the size (composed_cell's 10⁴ steps took 46 s of the test's
        // 299 s, single_cell's 26 s; `cargo test --release`, 2-core AMD EPYC), and
        // the whole test took 37 min on the loaded 2-core machine with 10⁴ for all.
        // An implicit step's f32 solve is exact to about κ(A)·(its tolerance + 8ε_f32)
        // relative (src/gpu/implicit.rs), its explicit steps to the 1e-5 below.
        let bound = match setup.settings.integrator {
            Integrator::Implicit(..) => (implicit_condition_bound(&setup) * (F32_TOLERANCE + 8.0 * f32::EPSILON as f64)).max(1e-5),
            Integrator::Overdamped(_) => 1e-5,
        };
        // Quasi-static Newton steps (the `solver cholesky` decks: force_dipole,
        // hertz_*; κ(A) ~ 10⁸, so the bound above is vacuous and their check is
        // the equilibrium tests of tests/suite/gpu_implicit.rs) take one step of their
        // first stage only here: the device runs them (10 steps a stage took
        // 107 s for force_dipole and 176 s for hertz_ball, one step in each of
        // hertz_block's 5 stages 36 s; `cargo test --release`, llvmpipe, 2 cores).
        // Implicit decks of more than 1 000 particles (0.7–2 s a step on
        // llvmpipe) are compared over 10 steps.
        let horizon = match setup.settings.integrator {
            Integrator::Implicit(..) if bound >= 1.0 => 1,
            Integrator::Implicit(..) if setup.model.len() > 1000 => 10,
            Integrator::Implicit(..) => 100,
            Integrator::Overdamped(_) if setup.model.len() > 300 => 1_000,
            Integrator::Overdamped(_) => 10_000,
        };
        // The shortest horizon on the GPU first (cheap on llvmpipe): it finds
        // the decks refused at a later run before any long run.
        let first_run_only = bound >= 1.0;
        let stage = |steps: u64| Horizon { steps, first_run_only };
        let first = horizon.min(100);
        match run_deck_deterministic(&deck, DevicePreference::Gpu, stage(first), false) {
            Ok((_, shortest)) => {
                // The horizon is chosen from the CPU runs before the GPU runs it,
                // cut by tenths while
                // - the deck's CPU run itself moves more than the bound when its
                //   start is rounded to f32: it is chaotic over that horizon
                //   (cell_contact.in: the contact step clamp makes every clamped
                //   step's length hinge on one pair; adhesive_doublet.in: a node's
                //   nearest face, where adhesion pulls it, can jump; its CPU runs
                //   part by 7.0e-5 after 0.75 µm in 10³ steps and by 5.8e-4 after
                //   0.31 µm in 10², and meet again at rest by 10⁴), down to 10 steps;
                // - its prescribed motion wrecks it on the CPU (tensegrity_substrate.in:
                //   its adhesions slide 1 µm per 50-step stage, and the cell blows up
                //   near step 10³, at a step that hinges on f32 rounding); after such a
                //   failure a GPU failure at the shorter horizon cuts it again.
                let mut steps = horizon;
                let mut wrecked = false;
                let mut comparable = true;
                loop {
                    let runs = run_deck_deterministic(&deck, DevicePreference::Cpu, stage(steps), false).and_then(|(start, cpu)| {
                        run_deck_deterministic(&deck, DevicePreference::Cpu, stage(steps), true).map(|(_, cpu32)| (start, cpu, cpu32))
                    });
                    let (start, cpu, cpu32) = match runs {
                        Ok(runs) => runs,
                        Err(e) if steps > 100 => {
                            println!("{:40} fails within {steps} steps on the CPU ({e}): a tenth of the steps", deck.display());
                            (wrecked, steps) = (true, steps / 10);
                            continue;
                        }
                        Err(e) => panic!("{}: {e}", deck.display()),
                    };
                    let sim_box = cellmd::deck::validate_file(&deck, &[("steps".into(), "10".into())]).unwrap().sim_box;
                    let unwrap = |s: &State, i: usize| sim_box.unwrap(s.positions[i], s.images[i]);
                    let travelled = (0..start.len()).map(|i| (unwrap(&cpu, i) - unwrap(&start, i)).length()).fold(0.0, f64::max);
                    let sensitivity = (0..start.len()).map(|i| (unwrap(&cpu, i) - unwrap(&cpu32, i)).length()).fold(0.0, f64::max);
                    // A thermal deck started at its energy minimum (thermal_filament.in: a straight
                    // chain) moves at kT = 0 by less than f32 resolves its positions: nothing to
                    // compare with an f32 backend.
                    let extent = start.positions.iter().map(|x| x.abs().max_element()).fold(0.0, f64::max);
                    if travelled < f32::EPSILON as f64 * extent {
                        println!("{:40} moves less than f32 resolves at kT = 0: not compared", deck.display());
                        comparable = false;
                        break;
                    }
                    if sensitivity > 1e-5 * travelled && steps > 10 {
                        println!("{:40} {steps} steps: CPU from f32-rounded start − CPU {sensitivity:.3e} after travelling up to {travelled:.3e}: chaotic, a tenth of the steps", deck.display());
                        steps /= 10;
                        continue;
                    }
                    let gpu = if steps == first {
                        shortest.clone()
                    } else {
                        match run_deck_deterministic(&deck, DevicePreference::Gpu, stage(steps), false) {
                            Ok((_, gpu)) => gpu,
                            // Wrecked on the CPU within 10× the steps (tried now where the
                            // horizon started below that: a deck of more than 300 particles).
                            Err(e)
                                if wrecked || run_deck_deterministic(&deck, DevicePreference::Cpu, stage(10 * steps), false).is_err() =>
                            {
                                println!(
                                    "{:40} fails within {steps} steps on the GPU ({e}), as within {} on the CPU: a tenth of the steps",
                                    deck.display(),
                                    10 * steps
                                );
                                steps /= 10;
                                continue;
                            }
                            Err(e) => panic!("{}: {e}", deck.display()),
                        }
                    };
                    let deviation = (0..start.len()).map(|i| (unwrap(&cpu, i) - unwrap(&gpu, i)).length()).fold(0.0, f64::max);
                    println!(
                        "{:40} {} particles, {steps} steps: GPU − CPU {deviation:.3e} after travelling up to {travelled:.3e}; CPU from f32-rounded start − CPU {sensitivity:.3e} ({:.0} s)",
                        deck.display(),
                        start.len(),
                        started.elapsed().as_secs_f64()
                    );
                    assert_eq!(cpu.step, gpu.step);
                    assert!(travelled > 0.0, "{}: nothing moved", deck.display());
                    assert!(deviation <= bound * travelled, "{}: GPU − CPU {deviation:e} > {bound:e} × {travelled:e}", deck.display());
                    break;
                }
                compared += usize::from(comparable);
            }
            // A CPU-only feature that starts after the first run (a `ramp`
            // between runs): the GPU must refuse that run with its reason.
            Err(e) if refused_by_the_gpu(&e) => {
                println!("{:40} refused at a later run: {e}", deck.display());
                refused += 1
            }
            Err(e) => panic!("{}: {e}", deck.display()),
        }
    }
    println!("{compared} decks compared, {refused} refused for CPU-only features");
    assert!(compared >= 5, "only {compared} decks compared");
    // Issue #15: every deck in inputs/ runs with `--device gpu`.
    assert_eq!(refused, 0, "decks refused by the GPU");
}

/// Whether a run's error is the GPU refusing a CPU-only feature
/// (`Simulation::cpu_only_feature`), e.g. one that starts after the first run.
fn refused_by_the_gpu(error: &str) -> bool {
    error.starts_with("device gpu: ") && error.ends_with("run on the CPU backend only; use `device cpu` or `device auto`")
}

/// Double-single positions: a particle pushed by a constant force takes 10⁴
/// equal f32 steps; its position must be their exact sum (an f32 position
/// would drift by up to ½ ulp per step: ~1e-3 here).
#[test]
fn positions_do_not_drift_through_f32_rounding() {
    let top = "[ particles ]\n1 a 3.3 7.1 0.7\n2 a 9.9 1.3 5.5\n";
    let ff = "particle a drag 3\n";
    let deck = "units lj\ntopology t.top\nforcefield f.ff\nbox x 0 20 p y 0 20 p z 0 20 p\n";
    let case = common::Case::new(&[("t.top", top), ("f.ff", ff), ("deck.in", deck)]);
    let plan = case.plan();
    let mut sim = Simulation::new(&plan, RunOptions::default());
    let external = "external push all constant_force fx 0.37 fy -0.011 fz 0.0123\n";
    std::fs::write(case.path("deck.in"), format!("{deck}{external}")).unwrap();
    let plan = case.plan();
    let Action::External(push) = plan.actions.last().unwrap().clone() else { panic!("external action") };
    sim.model.externals.push(push);
    let mut state = initial_state(&plan);
    let start = state.clone();
    let dt = 1e-3;
    let mut gpu = GpuBackend::new(&context(), &sim.model, &state, &plan.sim_box, &settings(0.0, dt, 0.0)).unwrap();
    let steps = 10_000;
    assert_eq!(gpu.run(0, steps), Ok(steps));
    gpu.download(&mut state);
    let step_f32 = [0.37f32 * (dt / 3.0) as f32, -0.011f32 * (dt / 3.0) as f32, 0.0123f32 * (dt / 3.0) as f32];
    let mut worst: f64 = 0.0;
    for i in 0..2 {
        let expected = start.positions[i] + steps as f64 * DVec3::new(step_f32[0] as f64, step_f32[1] as f64, step_f32[2] as f64);
        let got = plan.sim_box.unwrap(state.positions[i], state.images[i]);
        worst = worst.max((got - expected).length());
    }
    println!("fixed-point drift after {steps} steps: {worst:e}");
    assert!(worst < 1e-9, "position drift {worst:e} after {steps} steps");
}

/// Free particles and particles tethered to fixed anchors (harmonic, r0 = 0)
/// at kT > 0, for `steps` steps on the CPU or the GPU.
fn thermal_case() -> common::Case {
    let mut top = String::from("[ particles ]\n");
    let mut bonds = String::from("[ bonds ]\n");
    let n = 1500;
    for k in 0..n {
        let (x, y, z) = ((k % 15) as f64 * 4.0 + 2.0, ((k / 15) % 10) as f64 * 4.0 + 2.0, (k / 150) as f64 * 4.0 + 2.0);
        top += &format!("{} free {x} {y} {z}\n", 3 * k + 1);
        top += &format!("{} bead {} {y} {z}\n", 3 * k + 2, x + 1.0);
        top += &format!("{} anchor {} {y} {z}\n", 3 * k + 3, x + 1.0 + 1e-3);
        bonds += &format!("tether {} {}\n", 3 * k + 2, 3 * k + 3);
    }
    let ff = "particle free drag 2\nparticle bead drag 2\nparticle anchor fixed\nbond tether harmonic k 40 r0 0\n";
    let deck = "units lj\ntopology t.top\nforcefield f.ff\nbox x 0 60 p y 0 40 p z 0 40 p\n";
    common::Case::new(&[("t.top", &(top + &bonds)), ("f.ff", ff), ("deck.in", deck)])
}

/// Mean squared displacement of the free particles and mean squared
/// extension of the tethers after `steps` steps.
fn thermal_statistics(device: DevicePreference, steps: u64, kt: f64, dt: f64, noise: Noise) -> (f64, f64, State) {
    let integrator = OverdampedSettings { noise, ..Default::default() };
    let case = thermal_case();
    let plan = case.plan();
    let start = initial_state(&plan);
    let mut state = start.clone();
    match device {
        DevicePreference::Gpu => {
            let mut settings = settings(0.5, dt, kt);
            settings.context.noise = integrator.noise;
            let mut gpu = GpuBackend::new(&context(), &plan.model, &state, &plan.sim_box, &settings).unwrap();
            assert_eq!(gpu.run(0, steps), Ok(steps));
            gpu.download(&mut state);
        }
        _ => {
            let mut sim = Simulation::new(&plan, RunOptions::default());
            for action in [
                Action::Temperature(kt),
                Action::Timestep(dt),
                Action::Seed(7),
                Action::Integrator(Integrator::Overdamped(integrator)),
                Action::Run(steps),
            ] {
                sim.apply(&action).unwrap();
            }
            state = sim.state;
        }
    }
    let unwrap = |s: &State, i: usize| plan.sim_box.unwrap(s.positions[i], s.images[i]);
    let n = state.len() / 3;
    let msd = (0..n).map(|k| (unwrap(&state, 3 * k) - unwrap(&start, 3 * k)).length_squared()).sum::<f64>() / n as f64;
    let extension = (0..n).map(|k| (unwrap(&state, 3 * k + 1) - unwrap(&state, 3 * k + 2)).length_squared()).sum::<f64>() / n as f64;
    (msd, extension, state)
}

/// kT > 0, uniform and Gaussian noise: the GPU and the CPU reproduce the same statistics (free MSD = 6Dt;
/// tether ⟨d²⟩ = 3 × the exact variance of the discrete Ornstein–Uhlenbeck
/// step), and their first steps are the same numbers: the Philox words are
/// identical, the f32 noise differs from the CPU's f64 noise by < 2⁻²⁴·√12.
#[test]
fn thermal_runs_have_the_same_statistics_and_the_same_first_steps() {
    let (kt, dt, gamma, k): (f64, f64, f64, f64) = (0.5, 1e-3, 2.0, 40.0);
    let steps = 400;
    let a = k * dt / gamma;
    let per_axis = (2.0 * kt * dt / gamma) / (1.0 - (1.0 - a) * (1.0 - a));
    // Tethers start at 1e-3 and relax for 400 steps: (1 − a)^800 ≈ 3e-4 of the start remains.
    let expected_extension = 3.0 * per_axis * (1.0 - (1.0 - a).powi(2 * steps as i32));
    let expected_msd = 6.0 * kt / gamma * dt * steps as f64;
    let n: f64 = 1500.0;
    for (device, noise) in [
        (DevicePreference::Cpu, Noise::Uniform),
        (DevicePreference::Gpu, Noise::Uniform),
        (DevicePreference::Cpu, Noise::Gaussian),
        (DevicePreference::Gpu, Noise::Gaussian),
    ] {
        let (msd, extension, _) = thermal_statistics(device, steps, kt, dt, noise);
        // Relative standard error of a mean of n squared Gaussian norms (3 dof): √(2/3n).
        let sigma = (2.0 / (3.0 * n)).sqrt();
        println!("{device:?} {noise:?}: MSD {msd:.5} (6Dt = {expected_msd:.5}), ⟨d²⟩ {extension:.6} (exact {expected_extension:.6}), σ {sigma:.3}");
        assert!((msd / expected_msd - 1.0).abs() < 4.0 * sigma, "{device:?}: MSD {msd} vs {expected_msd}");
        assert!((extension / expected_extension - 1.0).abs() < 4.0 * sigma, "{device:?}: ⟨d²⟩ {extension} vs {expected_extension}");
    }
    let (_, _, cpu) = thermal_statistics(DevicePreference::Cpu, 3, kt, dt, Noise::Uniform);
    let (_, _, gpu) = thermal_statistics(DevicePreference::Gpu, 3, kt, dt, Noise::Uniform);
    let amplitude = (2.0 * kt * dt / gamma).sqrt();
    let worst = cpu.positions.iter().zip(&gpu.positions).map(|(c, g)| (*c - *g).abs().max_element()).fold(0.0, f64::max);
    println!("first 3 steps: largest GPU − CPU component {worst:e} (noise amplitude {amplitude:e})");
    assert!(worst < 3.0 * 4.0 * amplitude * 2f64.powi(-22), "GPU − CPU after 3 steps {worst:e}: the noise streams differ");
}

/// The volume of a thermal cell (kT = 0.5, lj units; a level-1 icosphere of
/// radius 3 whose edges rest as built, under `turgor` K = 50 at its built
/// volume V0 = 98.8): V fluctuates by about √(kT·V0/K) ≈ 1.0 (edges add a
/// little stiffness; measured var V 1.01 ± 0.04 on the CPU, 0.94 ± 0.03 on the
/// GPU, ⟨V⟩ 97.54 ± 0.07 and 97.53 ± 0.06). The GPU (seed 2) and the CPU (seed 1), 10⁴ steps
/// each sampled every 10 (the volume relaxes in ≈ 7 steps), give the same
/// ⟨V⟩ and var V within 4 standard errors of their difference, each error
/// from 10 blocks of the run's samples. Independent seeds: with the same
/// seed the two runs would be one trajectory.
#[test]
fn a_thermal_cell_has_the_same_volume_statistics_on_the_gpu() {
    let args = cellmd::build::IcosphereArgs {
        level: 1,
        radius: 3.0,
        centre: vec![0.0; 3],
        shell: cellmd::build::ShellOptions::default(),
        body_id: 1,
        first_id: 1,
        box_half_width: None,
        rest_from_geometry: true,
        output: "cell.top".into(),
    };
    let built = cellmd::build::icosphere(&args).unwrap();
    let v0 = built.shells[0].volume;
    let ff = format!("particle node drag 1\nbond edge harmonic k 20 r0 1\nbody cell turgor k 50 dp0 0 v0 {v0}\n");
    let samples = |device: DevicePreference, seed: u32| {
        let deck = format!(
            "units lj\ntopology cell.top\nforcefield cell.ff\nbox x -20 20 f y -20 20 f z -20 20 f\n\
             temperature 0.5\ntimestep 1e-3\nseed {seed}\nthermo 10 step volume/cell\nthermo_file v.csv\nrun 10200\n"
        );
        let case = common::Case::new(&[("cell.top", &built.text), ("cell.ff", &ff), ("deck.in", &deck)]);
        let options = RunOptions { output_dir: case.output_dir().to_path_buf(), device: Some(device), ..Default::default() };
        Simulation::execute(case.plan(), options).unwrap();
        let text = std::fs::read_to_string(case.output_dir().join("v.csv")).unwrap();
        // The first 200 steps relax the start; then 1000 rows.
        text.lines().skip(1 + 20).take(1000).map(|l| l.split(',').nth(1).unwrap().parse::<f64>().unwrap()).collect::<Vec<f64>>()
    };
    // Mean and variance, each with its standard error from 10 blocks.
    let statistics = |v: &[f64]| {
        let blocks: Vec<(f64, f64)> = v
            .chunks(v.len() / 10)
            .map(|b| {
                let mean = b.iter().sum::<f64>() / b.len() as f64;
                (mean, b.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (b.len() - 1) as f64)
            })
            .collect();
        let of = |f: fn(&(f64, f64)) -> f64| {
            let values: Vec<f64> = blocks.iter().map(f).collect();
            let mean = values.iter().sum::<f64>() / values.len() as f64;
            let spread = values.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (values.len() - 1) as f64;
            (mean, (spread / values.len() as f64).sqrt())
        };
        (of(|b| b.0), of(|b| b.1))
    };
    let (cpu, gpu) = (statistics(&samples(DevicePreference::Cpu, 1)), statistics(&samples(DevicePreference::Gpu, 2)));
    println!(
        "V0 {v0:.4}; CPU ⟨V⟩ {:.4} ± {:.4}, var {:.4} ± {:.4}; GPU ⟨V⟩ {:.4} ± {:.4}, var {:.4} ± {:.4}",
        cpu.0 .0, cpu.0 .1, cpu.1 .0, cpu.1 .1, gpu.0 .0, gpu.0 .1, gpu.1 .0, gpu.1 .1
    );
    for ((c, c_se), (g, g_se), what) in [(cpu.0, gpu.0, "⟨V⟩"), (cpu.1, gpu.1, "var V")] {
        assert!((c - g).abs() < 4.0 * (c_se * c_se + g_se * g_se).sqrt(), "{what}: CPU {c} ± {c_se}, GPU {g} ± {g_se}");
    }
    // The fluctuations are resolved (far above f32's resolution of V) and of the expected size.
    assert!(cpu.1 .0 > 0.25 && cpu.1 .0 < 0.5 * v0 / 50.0 * 1.5, "var V {} (kT·V0/K = {})", cpu.1 .0, 0.5 * v0 / 50.0);
}

/// A neighbour list larger than one storage binding is bound in chunks of
/// particles (nb_build and forces dispatched per chunk): with the binding
/// capped so that the 400-particle random system takes several chunks, the
/// list, the forces and ten steps are bit for bit those of the unchunked
/// list, and the list still equals the brute-force pair set. A cap below
/// 64 particles' rows is refused with a message (wgpu would abort).
#[test]
fn a_neighbour_list_beyond_one_binding_is_bound_in_chunks() {
    let case = soft_random_case();
    let plan = case.plan();
    let state = initial_state(&plan);
    let skin = 0.4;
    let new = || GpuBackend::new(&context(), &plan.model, &state, &plan.sim_box, &settings(skin, 1e-3, 0.0)).unwrap();
    let (mut whole, mut chunked) = (new(), new());
    let row = 4 * (1 + chunked.neighbor_capacity() as u64);
    chunked.limit_neighbor_binding(150 * row).unwrap(); // 128 particles per chunk: 4 chunks, the last partial
    assert_eq!((whole.neighbor_chunks(), chunked.neighbor_chunks()), (1, 4));
    whole.evaluate().unwrap();
    chunked.evaluate().unwrap();
    assert_eq!(whole.neighbor_lists(), chunked.neighbor_lists());
    assert_eq!(whole.forces_and_energies(), chunked.forces_and_energies());
    let range = plan.model.max_pair_cutoff() + skin;
    assert_same_pairs(&chunked.neighbor_lists(), &brute_force_pairs(&plan, &state, range), range, "chunked");
    whole.run(0, 10).unwrap();
    chunked.run(0, 10).unwrap();
    let (mut a, mut b) = (state.clone(), state.clone());
    whole.download(&mut a);
    chunked.download(&mut b);
    assert_eq!(a.positions, b.positions);
    let refused = chunked.limit_neighbor_binding(63 * row).unwrap_err();
    assert!(refused.contains("neighbour list") && refused.contains("64 particles"), "{refused}");
}

/// The 100 000 dense particles below need a neighbour list of about 150 MiB
/// (more than llvmpipe's 128 MiB bindings): the list is chunked where it must
/// be, and the forces match the CPU's.
#[test]
fn a_large_dense_system_runs_with_its_list_chunked_where_needed() {
    let context = context();
    let n = 100_000;
    let l = 10.0f64;
    let mut top = String::from("[ particles ]\n");
    let mut seed = 99u64;
    let mut next = || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 * l
    };
    for id in 1..=n {
        top += &format!("{id} a {} {} {}\n", next(), next(), next());
    }
    let deck = format!("units lj\ntopology t.top\nforcefield f.ff\nbox x 0 {l} p y 0 {l} p z 0 {l} p\n");
    let case = common::Case::new(&[("t.top", &top), ("f.ff", "particle a drag 1\npair a a soft A 1 rc 0.9\n"), ("deck.in", &deck)]);
    let plan = case.plan();
    let state = initial_state(&plan);
    let mut gpu = GpuBackend::new(&context, &plan.model, &state, &plan.sim_box, &settings(0.1, 1e-3, 0.0)).unwrap();
    gpu.evaluate().unwrap();
    let bytes = 4 * n as u64 * (1 + gpu.neighbor_capacity() as u64);
    let limit = context.limits.max_storage_buffer_binding_size;
    eprintln!(
        "list {:.0} MiB, binding limit {:.0} MiB, {} chunks",
        bytes as f64 / 1048576.0,
        limit as f64 / 1048576.0,
        gpu.neighbor_chunks()
    );
    assert_eq!(gpu.neighbor_chunks() > 1, bytes > limit);
    let mut cpu = CpuBackend::new(&plan.model, &state, &plan.sim_box, 0.1).unwrap();
    let mut forces = Forces::default();
    cpu.compute(&plan.model, &state, &plan.sim_box, &mut forces);
    let (force_error, energy_error) = compare_forces(&forces, &gpu.forces_and_energies());
    eprintln!("force error {force_error:e}, energy error {energy_error:e}");
    assert!(force_error < 1e-5 && energy_error < 1e-5, "force error {force_error:e}, energy error {energy_error:e}");
}

/// Every `inputs/` deck with bond kinetics, 400 steps per `run` at its own temperature
/// on the CPU and on the GPU: the GPU steps, and each step's events are decided
/// on the device (src/gpu/kinetics.rs: f32 tensions) or, for rules it lacks, by
/// the host from the read-back positions, with the same Philox numbers, so the
/// event logs, ages and rest lengths are identical, and positions agree within 1e-5 of the distance travelled
/// (the noise is the same Philox stream, converted to f32 on the GPU) plus
/// 1e-12 for fixed particles.
#[test]
fn kinetics_decks_give_the_same_events_on_the_gpu() {
    let mut decks: Vec<_> =
        std::fs::read_dir("inputs").unwrap().map(|e| e.unwrap().path()).filter(|p| p.extension().is_some_and(|e| e == "in")).collect();
    decks.sort();
    let (mut compared, mut all_events) = (0, 0);
    for deck in decks {
        // aggregate (8 100 particles) and spheroid_spreading (3 805) form their
        // bonds on the device (src/gpu/bind.rs); collagen_two_cells steps one GPU
        // step per segment (host kinetics: `plastic`). Decks over 3 000 particles
        // run 50 steps a run, which keeps CI time in bounds and still crosses the
        // contact, step and sync paths. collagen_two_cells is compared over 7 of its 10 stages: in the
        // 8th, plastic resets crush a fibre segment below the 1.1 µm its
        // explicit step needs with `bend` 400 at dt 1e-3 (l > √(3K·dt/γ)), and
        // from its step 389 a difference grows sevenfold a step on the CPU too.
        let steps = |n: u32| {
            let mut overrides = vec![("steps".into(), n.to_string()), ("fire_iterations".into(), "10".into())];
            if deck.ends_with("collagen_two_cells.in") {
                overrides.push(("stages".into(), "7".into()));
            }
            overrides
        };
        let mut plan = cellmd::deck::validate_file(&deck, &steps(400)).unwrap();
        if plan.model.len() > 3000 {
            plan = cellmd::deck::validate_file(&deck, &steps(50)).unwrap();
        }
        let setup = Simulation::before_first_run(&plan, RunOptions::default()).unwrap();
        if !setup.model.has_kinetics() || setup.cpu_only_feature().is_some() {
            // No kinetics, or refused by the GPU (checked in `every_input_deck_runs_on_the_gpu_like_on_the_cpu`).
            continue;
        }
        if deck.ends_with("network_shear.in") {
            // Quasi-static Newton steps of a floppy network (1.7 s a step on llvmpipe):
            // tests/suite/gpu_implicit.rs, `network_shear_stages_reach_the_cpu_equilibrium_on_the_gpu`.
            continue;
        }
        let Some((gpu, gpu_events)) = run_kinetics_deck(&plan, DevicePreference::Gpu) else {
            println!("{:40} refused at a later run", deck.display());
            continue;
        };
        let (cpu, cpu_events) = run_kinetics_deck(&plan, DevicePreference::Cpu).expect("the CPU runs every deck");
        let start = Simulation::new(&plan, RunOptions::default()).state;
        let unwrap = |s: &State, i: usize| plan.sim_box.unwrap(s.positions[i], s.images[i]);
        let travelled = (0..start.len()).map(|i| (unwrap(&cpu, i) - unwrap(&start, i)).length()).fold(0.0, f64::max);
        let deviation = (0..start.len()).map(|i| (unwrap(&cpu, i) - unwrap(&gpu, i)).length()).fold(0.0, f64::max);
        let events = cpu_events.iter().map(|e| e.lines().count() - 1).sum::<usize>();
        println!("{:40} {events} events logged; GPU − CPU {deviation:.3e} after travelling up to {travelled:.3e}", deck.display());
        all_events += events;
        // The same events (step, kind, bond, particles) where the deck logs them
        // (`events`); tension and length as measured at the read-back positions,
        // within the positions' 1e-5.
        assert_eq!(cpu_events.len(), gpu_events.len(), "{}: event logs", deck.display());
        let rows = |log: &str| log.lines().skip(1).map(|l| l.split(',').map(String::from).collect::<Vec<_>>()).collect::<Vec<_>>();
        for (cpu_log, gpu_log) in cpu_events.iter().zip(&gpu_events) {
            let (cpu_rows, gpu_rows) = (rows(cpu_log), rows(gpu_log));
            assert_eq!(cpu_rows.len(), gpu_rows.len(), "{}: event counts", deck.display());
            for (c, g) in cpu_rows.iter().zip(&gpu_rows) {
                assert_eq!((&c[..7], &c[9]), (&g[..7], &g[9]), "{}: event {c:?} on the CPU, {g:?} on the GPU", deck.display());
                for k in [7, 8] {
                    let (x, y): (f64, f64) = (c[k].parse().unwrap(), g[k].parse().unwrap());
                    assert!((x - y).abs() <= 1e-5 * x.abs().max(1.0), "{}: event {c:?} on the CPU, {g:?} on the GPU", deck.display());
                }
            }
        }
        let (cb, gb) = (cpu.bonds.as_ref().unwrap(), gpu.bonds.as_ref().unwrap());
        assert!(cb.bound == gb.bound, "{}: bound bonds differ", deck.display());
        // Ages sum the steps' lengths: bit for bit unless the contact step clamp
        // shortened steps, whose fractions the GPU computes from f32 geometry
        // (then within the clock's relative difference, bounded by the positions' 1e-5).
        if cpu.time == gpu.time {
            assert!(cb.age == gb.age, "{}: ages differ", deck.display());
        } else {
            let worst = cb.age.iter().zip(&gb.age).map(|(c, g)| (c - g).abs() / c.abs().max(f64::MIN_POSITIVE)).fold(0.0, f64::max);
            println!(
                "{:40} clock {:e} s on the CPU, {:e} s on the GPU; ages within {worst:.1e} relative",
                deck.display(),
                cpu.time,
                gpu.time
            );
            assert!(worst <= 1e-5, "{}: ages differ by {worst:e} relative", deck.display());
        }
        for (c, g) in cb.rest.iter().zip(&gb.rest) {
            assert!(
                c.zip(*g).is_none_or(|(c, g)| (c - g).abs() <= 1e-5 * c.abs()) && c.is_some() == g.is_some(),
                "{}: rest lengths",
                deck.display()
            );
        }
        // 1e-12 absolute: fixed particles come back through the GPU's fixed point (unit 2⁻⁵² of the box).
        assert!(deviation <= 1e-5 * travelled + 1e-12, "{}: GPU − CPU {deviation:e} > 1e-5 × {travelled:e}", deck.display());
        compared += 1;
    }
    assert!(compared >= 3, "only {compared} kinetics decks compared");
    assert!(all_events >= 100, "only {all_events} events to compare");
}

/// Runs a kinetics deck on `device`; returns its final state with the event
/// logs' texts, or None where the GPU refuses a CPU-only feature that starts
/// after the first run (checked in `every_input_deck_runs_on_the_gpu_like_on_the_cpu`).
fn run_kinetics_deck(plan: &Plan, device: DevicePreference) -> Option<(State, Vec<String>)> {
    let dir = tempfile::tempdir().unwrap();
    let options = RunOptions { output_dir: dir.path().to_path_buf(), device: Some(device), ..Default::default() };
    let sim = match Simulation::execute(plan.clone(), options) {
        Ok(sim) => sim,
        Err(e) if device == DevicePreference::Gpu && refused_by_the_gpu(&e.to_string()) => return None,
        Err(e) => panic!("{} on {device:?}: {e}", plan.deck_path.display()),
    };
    let events: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().ends_with(".events.csv"))
        .map(|p| std::fs::read_to_string(p).unwrap())
        .collect();
    Some((sim.state, events))
}

/// Bonds whose law changes every step — motors shortening their rest length at
/// v0·(1 − F/Fs) and maturing stiffness — follow the CPU on the GPU at kT = 0:
/// positions within 1e-5 of the distance travelled, rest lengths and scales
/// within 1e-5.
#[test]
fn evolving_bonds_follow_the_cpu_on_the_gpu() {
    let mut top = String::from("[ particles ]\n");
    let mut bonds = String::from("[ bonds ]\n");
    for m in 0..60 {
        let (x, y) = ((m % 10) as f64 * 3.0, (m / 10) as f64 * 3.0);
        top += &format!("{} anchor {x} {y} 0\n{} bead {x} {y} {}\n", 2 * m + 1, 2 * m + 2, 1.0 + 0.01 * m as f64);
        bonds += &format!("myosin {} {}\n", 2 * m + 1, 2 * m + 2);
    }
    let ff = "particle anchor fixed\nparticle bead drag 1\n\
              bond myosin harmonic k 5 r0 1 kinetics motor v0 0.2 fs 2 kinetics maturation tau 0.5\n\
              pair bead bead wca epsilon 1 sigma 0.5\n";
    let deck = "units lj\ntopology t.top\nforcefield f.ff\nbox x -5 35 f y -5 25 f z -5 5 f\ngroup beads type bead\n\
                external pull beads constant_force fz 0.5\ntimestep 1e-3\nrun 1000\n";
    let case = common::Case::new(&[("t.top", &(top + &bonds)), ("f.ff", ff), ("deck.in", deck)]);
    let plan = case.plan();
    let run = |device: DevicePreference| {
        let options = RunOptions { output_dir: case.output_dir().to_path_buf(), device: Some(device), ..Default::default() };
        Simulation::execute(plan.clone(), options).unwrap().state
    };
    let (start, cpu, gpu) = (Simulation::new(&plan, RunOptions::default()).state, run(DevicePreference::Cpu), run(DevicePreference::Gpu));
    let travelled = (0..start.len()).map(|i| (cpu.positions[i] - start.positions[i]).length()).fold(0.0, f64::max);
    let deviation = (0..start.len()).map(|i| (cpu.positions[i] - gpu.positions[i]).length()).fold(0.0, f64::max);
    println!("GPU − CPU {deviation:.3e} after travelling up to {travelled:.3e}");
    assert!(travelled > 0.1, "the beads barely moved: {travelled}");
    assert!(deviation <= 1e-5 * travelled, "GPU − CPU {deviation:e} > 1e-5 × {travelled:e}");
    let (cb, gb) = (cpu.bonds.unwrap(), gpu.bonds.unwrap());
    let start_rest = start.bonds.unwrap().rest[0].unwrap();
    for b in 0..cb.len() {
        let (c, g) = (cb.rest[b].unwrap(), gb.rest[b].unwrap());
        assert!(c < start_rest - 0.05, "bond {b}: the motor did not shorten it ({c})");
        assert!((c - g).abs() <= 1e-5 * c, "bond {b}: rest length {c} on the CPU, {g} on the GPU");
        assert!((cb.scale[b] - gb.scale[b]).abs() <= 1e-5 * cb.scale[b], "bond {b}: scale");
    }
}

/// Bonds with their own rest lengths (the LAMMPS-checked `per_bond_r0`
/// case): the GPU's forces at the start agree with the CPU's and differ from
/// those with every bond at its type's r0, and a 2000-step run stays within
/// 1e-5 of the distance travelled of the CPU's.
#[test]
fn per_bond_rest_lengths_match_the_cpu_on_the_gpu() {
    let deck = std::path::Path::new("reference/per_bond_r0/random.in");
    let plan = cellmd::deck::validate_file(deck, &[]).unwrap();
    let state = initial_state(&plan);
    assert!(state.bonds.is_some() && !plan.model.has_kinetics());
    let evaluate = |state: &State| {
        let mut cpu = CpuBackend::new(&plan.model, state, &plan.sim_box, 0.3).unwrap();
        let mut forces = Forces::default();
        cpu.compute(&plan.model, state, &plan.sim_box, &mut forces);
        let mut gpu = GpuBackend::new(&context(), &plan.model, state, &plan.sim_box, &settings(0.3, 1e-3, 0.0)).unwrap();
        gpu.evaluate().unwrap();
        (forces, gpu.forces_and_energies())
    };
    let (cpu, gpu) = evaluate(&state);
    let (force_error, energy_error) = compare_forces(&cpu, &gpu);
    let (_, type_r0_gpu) = evaluate(&State { bonds: None, ..state.clone() });
    let (difference, _) = compare_forces(&cpu, &type_r0_gpu);
    println!("per-bond r0: GPU − CPU force {force_error:.2e}, energy {energy_error:.2e}; at the types' r0 instead: {difference:.2e}");
    assert!(force_error < 1e-5 && energy_error < 1e-5, "force {force_error:e}, energy {energy_error:e}");
    assert!(difference > 1e-2, "the per-bond r0 change the forces by only {difference:e}");
    let (start, cpu) = run_deck_deterministic(deck, DevicePreference::Cpu, 2000, false).unwrap();
    let (_, gpu) = run_deck_deterministic(deck, DevicePreference::Gpu, 2000, false).unwrap();
    let unwrap = |s: &State, i: usize| plan.sim_box.unwrap(s.positions[i], s.images[i]);
    let travelled = (0..start.len()).map(|i| (unwrap(&cpu, i) - unwrap(&start, i)).length()).fold(0.0, f64::max);
    let deviation = (0..start.len()).map(|i| (unwrap(&cpu, i) - unwrap(&gpu, i)).length()).fold(0.0, f64::max);
    println!("per-bond r0, 2000 steps: GPU − CPU {deviation:.3e} after travelling up to {travelled:.3e}");
    assert!(travelled > 0.1 && deviation <= 1e-5 * travelled, "GPU − CPU {deviation:e} after {travelled:e}");
}

/// `--device auto` announces its choice at start — a hardware adapter when
/// one exists, otherwise the CPU with the adapters it passed over (CI: only
/// llvmpipe, so the CPU) — and the run it then makes is bit for bit the run
/// of the device it announced.
#[test]
fn device_auto_announces_its_choice_and_runs_on_it() {
    let deck = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("inputs/dimer.in");
    let run = |device: &str| {
        let dir = tempfile::tempdir().unwrap();
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_cellmd"))
            .args(["run", deck.to_str().unwrap(), "-o", dir.path().to_str().unwrap(), "--device", device])
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
        assert!(out.status.success(), "--device {device}: {stdout}{}", String::from_utf8_lossy(&out.stderr));
        // Every output but the run log, which records the command line and wall times.
        let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_none_or(|x| x != "log"))
            .map(|p| (p.file_name().unwrap().to_string_lossy().into_owned(), std::fs::read(&p).unwrap()))
            .collect();
        files.sort();
        (stdout, files)
    };
    let (auto_said, auto_files) = run("auto");
    let announcement = auto_said.lines().find(|l| l.starts_with("device")).unwrap_or_else(|| panic!("no device line in:\n{auto_said}"));
    println!("{announcement}");
    let (_, announced_files) = match GpuContext::open(true) {
        Ok(hardware) => {
            assert_eq!(announcement, format!("device: GPU {}", hardware.describe()));
            run("gpu")
        }
        Err(e) => {
            assert_eq!(announcement, format!("device auto: {e}; running on the CPU"));
            assert!(e.contains(&context().info.name), "the fallback should name the adapters it passed over: {e}");
            run("cpu")
        }
    };
    assert!(!auto_files.is_empty());
    assert!(auto_files == announced_files, "the auto run differs from the run on the device it announced");
}

/// `contact_barrier` on the GPU against the CPU f64 backend, forces and
/// energies within [`CONTACT_GPU_EPSILON`] (its derivation is this case).
#[test]
fn contact_barrier_forces_match_the_cpu() {
    for ff in [CONTACT_BARRIER.to_string(), format!("{CONTACT_SHELLS}{CONTACT_BARRIER}")] {
        let (force_error, energy_error, pairs, _) = contact_forces_gpu_vs_cpu(&ff, 0.03);
        println!(
            "{} force-field lines: {pairs} particles with a force; force error {force_error:.2e}, energy error {energy_error:.2e}",
            ff.lines().count()
        );
        assert!(pairs > 20, "only {pairs} particles feel a force: the test would be vacuous");
        assert!(
            force_error <= CONTACT_GPU_EPSILON && energy_error <= CONTACT_GPU_EPSILON,
            "force {force_error:e}, energy {energy_error:e}"
        );
    }
}

/// The contact step clamp on the GPU: cells pushed together by 50 pN per
/// node at dt = 1e-2 s (0.5 µm a step unclamped, five times d̂), 10 steps.
/// At kT = 0 the GPU clamps the same steps as the CPU, its clock advances by
/// the same shortened steps, and its positions follow the CPU's within 1e-4
/// of the distance travelled (each step's s and displacement carry the
/// forces' and distances' relative error, ≤ CONTACT_GPU_EPSILON); the cells
/// never interpenetrate. (Longer runs at this dt chatter against the barrier
/// and amplify any difference: measured GPU − CPU 6.7e-7 µm after 10 steps,
/// 1.8e-4 after 20, 1.7e-2 after 40, every step clamped.) With noise, the
/// same GPU run twice (60 steps) gives the same bits.
#[test]
fn the_contact_step_clamp_runs_on_the_gpu_like_on_the_cpu() {
    let run = |device: DevicePreference, kt: f64, steps: u64| {
        let case = contact_case(
            &format!("{CONTACT_SHELLS}{CONTACT_BARRIER}"),
            0.1,
            50.0,
            &format!("temperature {kt}\nseed 7\ntimestep 1e-2\nrun 0\n"),
        );
        let options = RunOptions { output_dir: case.output_dir().to_path_buf(), device: Some(device), ..Default::default() };
        let mut sim = Simulation::before_first_run(&case.plan(), options).unwrap();
        let start = sim.state.clone();
        sim.run(steps).unwrap();
        (start, sim)
    };
    let (start, cpu) = run(DevicePreference::Cpu, 0.0, 10);
    let (_, gpu) = run(DevicePreference::Gpu, 0.0, 10);
    assert_clamped_runs_agree(&start, &cpu, &gpu, 6);
    let (_, a) = run(DevicePreference::Gpu, 0.0041, 60);
    let (_, b) = run(DevicePreference::Gpu, 0.0041, 60);
    let bits = |s: &Simulation| s.state.positions.iter().map(|x| x.to_array().map(f64::to_bits)).collect::<Vec<_>>();
    assert!(
        bits(&a) == bits(&b) && a.state.time == b.state.time && a.reports.contact_clamps == b.reports.contact_clamps,
        "two GPU runs differ"
    );
    assert!(a.reports.contact_clamps > 0);
}

/// A GPU blow-up near a contact names the step, the particle and the
/// contact term as the CPU does: cells 0.01 µm apart, where the barrier
/// pushes with ≈ 250 pN and even the clamped step (0.4 × 0.01 µm) exceeds
/// `max_displacement` 1e-3 µm; and cells 0.1 µm apart under adhesion alone,
/// whose pull (≈ 13 pN at the rim, unpushed) takes a step of ≈ 0.013 µm.
/// Many particles' steps are refused at once, in several workgroups: three
/// GPU runs each name the lowest, whatever order the workgroups ran in
/// (before `commit` raised the halt, one run in four on llvmpipe named a
/// later particle, whose workgroup had run first).
#[test]
fn a_contact_blowup_on_the_gpu_names_the_step_particle_and_term() {
    let settings = "integrator overdamped max_displacement 1e-3\ntemperature 0\ntimestep 1e-3\nrun 50\n";
    for (ff, gap, push, term) in [(CONTACT_BARRIER, 0.01, 1.0, "contact_barrier"), (CONTACT_ADHESION, 0.1, 0.0, "contact_adhesion")] {
        let blowup = |device: DevicePreference| {
            let case = contact_case(ff, gap, push, settings);
            let options = RunOptions { output_dir: case.output_dir().to_path_buf(), device: Some(device), ..Default::default() };
            match Simulation::execute(case.plan(), options) {
                Ok(_) => panic!("{device:?}: the run should blow up"),
                Err(e) => e,
            }
        };
        let cpu = blowup(DevicePreference::Cpu);
        let cellmd::run::RunError::Blowup { step: cpu_step, particle_id: cpu_particle, .. } = &cpu else { panic!("{cpu}") };
        for _ in 0..3 {
            let gpu = blowup(DevicePreference::Gpu);
            println!("CPU: {cpu}\nGPU: {gpu}");
            let cellmd::run::RunError::Blowup { step, particle_id, culprit, .. } = &gpu else { panic!("{gpu}") };
            assert_eq!((step, particle_id), (cpu_step, cpu_particle), "GPU: {gpu}\nCPU: {cpu}");
            let culprit = culprit.as_ref().unwrap();
            assert_eq!((culprit.kind, culprit.interaction), ("contact", term), "{gpu}");
        }
    }
}

/// A face edge that grows past the contact search's reach (1.5 × the
/// longest edge at the start) does not let contacts go unseen: the device
/// halts, and the host builds the backend anew from that state with the
/// reach of the faces now, and the run goes on (one node of a cell without
/// edge springs pulled away by 100 pN, 0.04 µm a step, for 40 steps: 1.6 µm,
/// which stopped the run before the backend was rebuilt). The run ends
/// where the CPU's does, within 1e-5 of the distance travelled (measured:
/// 1.1e-7 after 1.6 µm).
#[test]
fn a_face_that_outgrows_the_contact_search_rebuilds_the_gpu_backend() {
    let settings = "group tip id 1\nexternal pull tip constant_force fx -100\ntemperature 0\ntimestep 1e-3\nrun 40\n";
    let case = contact_case(CONTACT_BARRIER, 0.1, 0.0, settings);
    let run = |device: DevicePreference| {
        let options = RunOptions { output_dir: case.output_dir().to_path_buf(), device: Some(device), ..Default::default() };
        Simulation::execute(case.plan(), options).unwrap_or_else(|e| panic!("{device:?}: {e}")).state
    };
    let start = Simulation::new(&case.plan(), RunOptions::default()).state;
    let (cpu, gpu) = (run(DevicePreference::Cpu), run(DevicePreference::Gpu));
    let travelled = (0..start.len()).map(|i| (cpu.positions[i] - start.positions[i]).length()).fold(0.0, f64::max);
    let deviation = (0..start.len()).map(|i| (cpu.positions[i] - gpu.positions[i]).length()).fold(0.0, f64::max);
    println!("GPU − CPU {deviation:.3e} after travelling up to {travelled:.3e}");
    assert_eq!(gpu.step, 40);
    assert!(travelled > 1.0, "the node hardly moved: {travelled}");
    assert!(deviation <= 1e-5 * travelled, "GPU − CPU {deviation:e} > 1e-5 × {travelled:e}");
}

/// CPU (f64) and GPU forces of the two cells of [`contact_case`] `gap` apart
/// under `ff`: (force error, energy error, particles with a force, the CPU's
/// energy of `contact_adhesion`).
fn contact_forces_gpu_vs_cpu(ff: &str, gap: f64) -> (f64, f64, usize, f64) {
    let case = contact_case(ff, gap, 1.0, "timestep 1e-3\nrun 0\n");
    let plan = case.plan();
    let model = Simulation::before_first_run(&plan, RunOptions::default()).unwrap().model;
    let state = initial_state(&plan);
    let mut cpu = CpuBackend::new(&model, &state, &plan.sim_box, 0.3).unwrap();
    let mut forces = Forces::default();
    cpu.compute(&model, &state, &plan.sim_box, &mut forces);
    let pushed = forces.forces.iter().filter(|f| f.length() > 0.0).count();
    let mut gpu = GpuBackend::new(&context(), &model, &state, &plan.sim_box, &settings(0.3, 1e-3, 0.0)).unwrap();
    gpu.evaluate().unwrap();
    let (force_error, energy_error) = compare_forces(&forces, &gpu.forces_and_energies());
    let adhesion = cellmd::interactions::REGISTRY.iter().position(|i| i.name() == "contact_adhesion").unwrap();
    (force_error, energy_error, pushed, forces.energy_by_interaction[adhesion])
}

/// `contact_adhesion` on the GPU (src/gpu/adhesion.rs) against the CPU f64
/// backend: the cells of [`contact_forces_gpu_vs_cpu`] 0.03 µm apart, so
/// that nodes lie in full contact (d < d_on), across the switch and beyond
/// it; the adhesion alone, with the barrier, and with the cells' surface
/// terms. Tolerance from f32 arithmetic (u = 2⁻²⁴ ≈ 6e-8): d is off by
/// ≈ 4e-7 µm (as in [`CONTACT_GPU_EPSILON`]'s derivation), which moves s′ by
/// |s″|·δd ≤ (5.8/width²)·δd, 3.1·δd/width ≈ 4e-6 of its largest value
/// 1.9/width (width 0.35 µm), and s by less; B_k and the area part are sums
/// of ≈ 6 face areas and area gradients, each ≈ 16 roundings from its edge
/// vectors (≈ 1e-6), which cancel around a node by up to ≈ 10 on these
/// meshes (as [`SURFACE_GPU_EPSILON`]'s) → ≈ 1e-5 of the largest force;
/// the barrier's part keeps its own 1e-4. So 1e-4, [`CONTACT_GPU_EPSILON`].
/// The energy, ε·Σ A_t·P_t summed in f32, is well within it.
#[test]
fn contact_adhesion_forces_match_the_cpu() {
    for ff in [
        CONTACT_ADHESION.to_string(),
        format!("{CONTACT_BARRIER}{CONTACT_ADHESION}"),
        format!("{CONTACT_SHELLS}{CONTACT_BARRIER}{CONTACT_ADHESION}"),
    ] {
        let (force_error, energy_error, pushed, adhesion) = contact_forces_gpu_vs_cpu(&ff, 0.03);
        println!(
            "{} force-field lines: {pushed} particles with a force, adhesion energy {adhesion:.4e}; force error {force_error:.2e}, energy error {energy_error:.2e}",
            ff.lines().count()
        );
        // −50 pN/µm × the area in contact: ≈ 0.6 µm² of faces whose corners all feel the switch.
        assert!(adhesion < -10.0, "adhesion energy {adhesion}: the test would be vacuous");
        assert!(
            force_error <= CONTACT_GPU_EPSILON && energy_error <= CONTACT_GPU_EPSILON,
            "force {force_error:e}, energy {energy_error:e}"
        );
    }
}

/// Two cells 0.1 µm apart left to adhere (barrier, adhesion and the cells'
/// surface terms; no push): at kT = 0 the GPU follows the CPU over 8 steps
/// (7 clamped) within [`CONTACT_GPU_EPSILON`] of the distance travelled
/// (each step's displacement carries the forces' relative error; measured
/// 9.8e-7 µm after 0.107 µm), with the same clock and clamped steps. (As in
/// the clamp test, longer runs chatter against the clamp and amplify any
/// difference: measured 2.4e-4 µm after 20 steps, 18 clamped.) With noise,
/// the same GPU run twice (40 steps) gives the same bits.
#[test]
fn adhesion_runs_on_the_gpu_like_on_the_cpu_and_twice_alike() {
    const STEPS: u64 = 8;
    let run = |device: DevicePreference, kt: f64, steps: u64| {
        let ff = format!("{CONTACT_SHELLS}{CONTACT_BARRIER}{CONTACT_ADHESION}");
        let case = contact_case(&ff, 0.1, 0.0, &format!("temperature {kt}\nseed 7\ntimestep 1e-3\nrun 0\n"));
        let options = RunOptions { output_dir: case.output_dir().to_path_buf(), device: Some(device), ..Default::default() };
        let mut sim = Simulation::before_first_run(&case.plan(), options).unwrap();
        let start = sim.state.clone();
        sim.run(steps).unwrap();
        (start, sim)
    };
    let (start, cpu) = run(DevicePreference::Cpu, 0.0, STEPS);
    let (_, gpu) = run(DevicePreference::Gpu, 0.0, STEPS);
    let travelled = assert_clamped_runs_agree(&start, &cpu, &gpu, 1);
    assert!(travelled > 1e-3, "the cells hardly moved: {travelled:e}");
    let (_, a) = run(DevicePreference::Gpu, 0.0041, 40);
    let (_, b) = run(DevicePreference::Gpu, 0.0041, 40);
    let bits = |s: &Simulation| s.state.positions.iter().map(|x| x.to_array().map(f64::to_bits)).collect::<Vec<_>>();
    assert!(
        bits(&a) == bits(&b) && a.state.time == b.state.time && a.reports.contact_clamps == b.reports.contact_clamps,
        "two GPU runs differ"
    );
}

/// Runs `deck` (with topology `top` and force field `ff`) on `device`;
/// returns the start and the final state.
fn protocol_run(top: &str, ff: &str, deck: &str, device: DevicePreference) -> (State, State) {
    let case = common::Case::new(&[("t.top", top), ("f.ff", ff), ("deck.in", deck)]);
    let plan = case.plan();
    let options = RunOptions { output_dir: case.output_dir().to_path_buf(), device: Some(device), ..Default::default() };
    let start = Simulation::new(&plan, RunOptions::default()).state;
    (start, Simulation::execute(plan, options).unwrap_or_else(|e| panic!("{device:?}: {e}")).state)
}

/// Ramps on the GPU (src/gpu/protocol.rs): 20 beads tethered to fixed
/// anchors, the tethers' r0 ramped from 1 to 2 and a pulling force from 0 to
/// 0.5 over a 2000-step run, with thermo every 250 steps, compared at step 700
/// (a segment of the run) and at its end. The device takes each step's value
/// from a table of the CPU's f64 values rounded to f32 (relative 2⁻²⁴ ≈ 6e-8,
/// like every other f32 parameter), so the positions follow the CPU within
/// 1e-5 of the distance travelled, the bound of every GPU-vs-CPU trajectory
/// here (the tethers contract, so per-step f32 errors ≈ 1e-7 do not add up).
/// The beads lag the ramp by ≈ τ·ṙ0 = 0.05 (τ = γ/k = 0.1 s): a GPU that took
/// the end value at once, or kept the start value, would be off by ≥ 0.05.
#[test]
fn ramps_run_on_the_gpu_like_on_the_cpu() {
    let mut top = String::from("[ particles ]\n");
    let mut bonds = String::from("[ bonds ]\n");
    for k in 0..20 {
        let (x, y) = ((k % 5) as f64 * 4.0, (k / 5) as f64 * 4.0);
        top += &format!("{} anchor {x} {y} 0\n{} bead {x} {y} 1\n", 2 * k + 1, 2 * k + 2);
        bonds += &format!("tether {} {}\n", 2 * k + 1, 2 * k + 2);
    }
    let ff = "particle anchor fixed\nparticle bead drag 1\nbond tether harmonic k 10 r0 1\n";
    let deck = "units lj\ntopology t.top\nforcefield f.ff\nbox x -5 25 f y -5 20 f z -5 10 f\ngroup beads type bead\n\
                external pull beads constant_force fx 0 fy 0 fz 0\ntimestep 1e-3\nthermo 250 step pe\n\
                ramp bond tether r0 1 2\nramp external pull fx 0 0.5\nrun 2000\n";
    let case = common::Case::new(&[("t.top", &(top + &bonds)), ("f.ff", ff), ("deck.in", deck)]);
    let run = |device: DevicePreference| {
        let options = RunOptions { output_dir: case.output_dir().to_path_buf(), device: Some(device), ..Default::default() };
        let mut sim = Simulation::before_first_run(&case.plan(), options).unwrap();
        let start = sim.state.clone();
        let run = sim.begin_run(2000).unwrap();
        assert_eq!(run.on_gpu(), device == DevicePreference::Gpu);
        sim.advance(&run, 700).unwrap();
        let middle = sim.state.clone();
        sim.advance(&run, 2000).unwrap();
        sim.end_run(run).unwrap();
        [start, middle, sim.state]
    };
    let ([start, cpu_middle, cpu], [_, gpu_middle, gpu]) = (run(DevicePreference::Cpu), run(DevicePreference::Gpu));
    for (stage, cpu, gpu) in [("step 700", cpu_middle, gpu_middle), ("step 2000", cpu, gpu)] {
        let travelled = (0..start.len()).map(|i| (cpu.positions[i] - start.positions[i]).length()).fold(0.0, f64::max);
        let deviation = (0..start.len()).map(|i| (cpu.positions[i] - gpu.positions[i]).length()).fold(0.0, f64::max);
        let length = (cpu.positions[1] - cpu.positions[0]).length();
        println!("ramps, {stage}: GPU − CPU {deviation:.3e} after travelling up to {travelled:.3e}; a tether's length {length:.4}");
        assert!(travelled > 0.3, "the ramps hardly moved the beads: {travelled}");
        assert!(deviation <= 1e-5 * travelled, "{stage}: GPU − CPU {deviation:e} > 1e-5 × {travelled:e}");
    }
}

/// `freeze` and `move` on the GPU (src/gpu/protocol.rs) at kT = 0.5, 1000
/// steps in a periodic box: 20 particles frozen along x and z, 10 moved at a
/// constant velocity (across the periodic boundary), 10 moved by a velocity
/// field of x, z and t, and 20 free particles tethered to frozen and moved
/// ones. Frozen coordinates keep their bits (position and image counter) on
/// the CPU, and their fixed-point bits on the GPU; a constant velocity's path is the CPU's and x0 + v·t to
/// 3e-12 (v·dt is rounded once to the fixed point's unit 2⁻⁴⁸ here and added
/// 1000 times: ≤ 1.8e-12; the CPU's 1000 f64 additions: ≤ 9e-13); everything else
/// within 1e-5 of the distance travelled (f32 forces, noise and field values,
/// relative ≈ 1e-7 a step). Two GPU runs give the same bits.
#[test]
fn freeze_and_move_run_on_the_gpu_like_on_the_cpu() {
    let mut next = common::uniform(0xF2EE2E);
    let mut top = String::from("[ particles ]\n");
    for id in 1..=60 {
        top += &format!("{id} a {} {} {}\n", 10.0 * next(), 10.0 * next(), 10.0 * next());
    }
    top += "[ bonds ]\n";
    for k in 0..20 {
        top += &format!("spring {} {}\n", 41 + k, 1 + k);
    }
    for k in 0..10 {
        top += &format!("spring {} {}\n", 41 + k, 21 + k);
    }
    let ff = "particle a drag 1\nbond spring harmonic k 5 r0 1\n";
    let deck = "units lj\ntopology t.top\nforcefield f.ff\nbox x 0 10 p y 0 10 p z 0 10 p\n\
                group frozen id 1:20\ngroup moved id 21:30\ngroup swirled id 31:40\n\
                freeze frozen x z\nmove moved linear 3 -2 7\nmove swirled velocity \"0.5*sin(2*t)\" \"-0.1*z\" \"0.2 + 0.01*x\"\n\
                temperature 0.5\nseed 3\ntimestep 1e-3\nthermo 300 step pe\nrun 1000\n";
    let (start, cpu) = protocol_run(&top, ff, deck, DevicePreference::Cpu);
    let (_, gpu) = protocol_run(&top, ff, deck, DevicePreference::Gpu);
    let (_, again) = protocol_run(&top, ff, deck, DevicePreference::Gpu);
    // The GPU's positions are fixed point (unit 2⁻⁴⁸ in this box): a frozen
    // coordinate comes back as its start rounded to that unit, ≤ 2⁻⁴⁹ away.
    for (what, end, unit) in [("CPU", &cpu, 0.0), ("GPU", &gpu, 2f64.powi(-49))] {
        for i in 0..20 {
            for a in [0, 2] {
                let moved = (end.positions[i][a] - start.positions[i][a]).abs();
                assert!(moved <= unit, "{what}: frozen particle {i} moved by {moved:e} along {a}");
                assert_eq!(end.images[i][a], start.images[i][a], "{what}: frozen particle {i} changed image");
            }
            assert_ne!(end.positions[i].y, start.positions[i].y, "{what}: particle {i} is frozen along y only");
        }
    }
    let unwrap = |s: &State, i: usize| DVec3::from_array([0, 1, 2].map(|a| s.positions[i][a] + 10.0 * s.images[i][a] as f64));
    let moved = (20..30).map(|i| (unwrap(&cpu, i) - unwrap(&gpu, i)).length()).fold(0.0, f64::max);
    let expected = (20..30).map(|i| (unwrap(&gpu, i) - unwrap(&start, i) - DVec3::new(3.0, -2.0, 7.0)).length()).fold(0.0, f64::max);
    assert!((20..30).any(|i| gpu.images[i] != start.images[i]), "no moved particle crossed the box");
    println!("moved at a constant velocity: GPU − CPU {moved:.3e}, GPU − (x0 + v·t) {expected:.3e}");
    assert!(moved <= 3e-12 && expected <= 3e-12, "constant velocity: GPU − CPU {moved:e}, GPU − exact {expected:e}");
    let travelled = (20..60).map(|i| (unwrap(&cpu, i) - unwrap(&start, i)).length()).fold(0.0, f64::max);
    let deviation = (0..60).map(|i| (unwrap(&cpu, i) - unwrap(&gpu, i)).length()).fold(0.0, f64::max);
    println!("freeze and move: GPU − CPU {deviation:.3e} after travelling up to {travelled:.3e}");
    assert!(travelled > 1.0);
    assert!(deviation <= 1e-5 * travelled, "GPU − CPU {deviation:e} > 1e-5 × {travelled:e}");
    let bits = |s: &State| s.positions.iter().map(|x| x.to_array().map(f64::to_bits)).collect::<Vec<_>>();
    assert!(bits(&gpu) == bits(&again), "two GPU runs differ");
}

/// The clock inside one GPU chunk (integrate.wgsl `sim_time`): the contact
/// step clamp shortens most of 10 steps of dt = 1e-2 s (see
/// `the_contact_step_clamp_runs_on_the_gpu_like_on_the_cpu`), while a field
/// pushing every node along x grows with t (200·t pN). The kernels' time is
/// the call's start plus the fractions of dt the steps took, summed on the
/// device, so the GPU's force at each step is the CPU's and the positions
/// follow it within the contact test's bound. A clock adding whole steps
/// would run ahead by Σ(1 − s)·dt, here > 0.05 s: 10 pN against the 50 pN
/// push, far beyond the bound.
#[test]
fn formulas_of_t_see_the_clamped_clock_inside_a_gpu_chunk() {
    let run = |device: DevicePreference| {
        let settings = "external tick all field fx \"200*t\" fy 0 fz 0 e 0\ntemperature 0\ntimestep 1e-2\nrun 0\n";
        let case = contact_case(&format!("{CONTACT_SHELLS}{CONTACT_BARRIER}"), 0.1, 50.0, settings);
        let options = RunOptions { output_dir: case.output_dir().to_path_buf(), device: Some(device), ..Default::default() };
        let mut sim = Simulation::before_first_run(&case.plan(), options).unwrap();
        let start = sim.state.clone();
        sim.run(10).unwrap();
        (start, sim)
    };
    let ((start, cpu), (_, gpu)) = (run(DevicePreference::Cpu), run(DevicePreference::Gpu));
    let unwrap = |s: &State, i: usize| cpu.sim_box.unwrap(s.positions[i], s.images[i]);
    let travelled = (0..start.len()).map(|i| (unwrap(&cpu.state, i) - unwrap(&start, i)).length()).fold(0.0, f64::max);
    let deviation = (0..start.len()).map(|i| (unwrap(&cpu.state, i) - unwrap(&gpu.state, i)).length()).fold(0.0, f64::max);
    println!(
        "{} clamped steps, t = {:.4e} s (whole steps: 0.1 s); GPU − CPU {deviation:.3e} after {travelled:.3e}",
        cpu.reports.contact_clamps, cpu.state.time
    );
    assert!(cpu.state.time < 0.05, "the clamp shortened the steps too little for the test: t = {}", cpu.state.time);
    assert_eq!(gpu.reports.contact_clamps, cpu.reports.contact_clamps);
    assert!(deviation <= CONTACT_GPU_EPSILON * travelled, "GPU − CPU {deviation:e} > {CONTACT_GPU_EPSILON:e} × {travelled:e}");
}

/// A driven indenter on the GPU (`indent … until`, src/gpu/protocol.rs): a
/// sphere (R = 2, K = 50) moves down at 5 per unit time onto 25 beads on
/// springs, with thermo every 100 steps, until its load reaches 20. The
/// device sums the load over the members after every step's forces (f32,
/// relative error ≈ 1e-6) and stops where the CPU does: the load grows by
/// ≈ 1 % a step near the target, so only a crossing within ≈ 1e-6 of the
/// target (odds ≈ 1e-4) could stop a step apart. The centre ends bit-identical
/// (the same f64 sums, the same number of them); positions within 1e-5 of
/// the distance travelled. The stop is neither the first step nor the last.
#[test]
fn a_driven_indenter_stops_on_the_gpu_at_the_cpus_step() {
    let mut top = String::from("[ particles ]\n");
    let mut bonds = String::from("[ bonds ]\n");
    for k in 0..25 {
        let (x, y) = ((k % 5) as f64 - 2.0, (k / 5) as f64 - 2.0);
        top += &format!("{} anchor {x} {y} -1\n{} bead {x} {y} 0\n", 2 * k + 1, 2 * k + 2);
        bonds += &format!("spring {} {}\n", 2 * k + 1, 2 * k + 2);
    }
    let ff = "particle anchor fixed\nparticle bead drag 1\nbond spring harmonic k 20 r0 1\n";
    let deck = "units lj\ntopology t.top\nforcefield f.ff\nbox x -6 6 f y -6 6 f z -6 6 f\ngroup beads type bead\n\
                external tip beads indenter r 2 k 50 x 0 y 0 z 2.5\nindent tip velocity 0 0 -5 until 20\n\
                timestep 1e-3\nthermo 100 step load/tip\nrun 600\n";
    let case = common::Case::new(&[("t.top", &(top + &bonds)), ("f.ff", ff), ("deck.in", deck)]);
    let run = |device: DevicePreference| {
        let options = RunOptions { output_dir: case.output_dir().to_path_buf(), device: Some(device), ..Default::default() };
        let sim = Simulation::execute(case.plan(), options).unwrap_or_else(|e| panic!("{device:?}: {e}"));
        let centre_z = sim.model.externals[0].term.params[2];
        (sim.state, centre_z)
    };
    let ((cpu, cpu_z), (gpu, gpu_z)) = (run(DevicePreference::Cpu), run(DevicePreference::Gpu));
    let moved = ((2.5 - cpu_z) / 5e-3).round();
    println!("the CPU's indenter stopped after {moved} steps at z = {cpu_z}, the GPU's at z = {gpu_z}");
    assert!(moved > 100.0 && moved < 600.0, "the indenter should stop mid-run, after touching the beads: {moved} steps");
    assert_eq!(cpu_z.to_bits(), gpu_z.to_bits(), "the GPU's indenter stopped at another step");
    let start = Simulation::new(&case.plan(), RunOptions::default()).state;
    let travelled = (0..start.len()).map(|i| (cpu.positions[i] - start.positions[i]).length()).fold(0.0, f64::max);
    let deviation = (0..start.len()).map(|i| (cpu.positions[i] - gpu.positions[i]).length()).fold(0.0, f64::max);
    println!("indenter: GPU − CPU {deviation:.3e} after travelling up to {travelled:.3e}");
    assert!(travelled > 0.1 && deviation <= 1e-5 * travelled, "GPU − CPU {deviation:e} after {travelled:e}");
}

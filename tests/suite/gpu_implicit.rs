//! `integrator implicit` on the device (src/gpu/implicit.rs) against the
//! CPU's f64 step, on whatever Vulkan adapter exists (CI: Mesa's llvmpipe).

use crate::common;

use crate::common::{assert_clamped_runs_agree, contact_case, CONTACT_ADHESION, CONTACT_BARRIER, CONTACT_SHELLS};
use cellmd::backend::{CpuBackend, Forces};
use cellmd::gpu::implicit::F32_TOLERANCE;
use cellmd::gpu::DevicePreference;
use cellmd::run::{RunOptions, Simulation};
use cellmd::system::State;
use glam::DVec3;

/// A bent 12-bead filament (stiff harmonic bonds, wlc_bending angles),
/// anchored at its left end, its right end pushed into a wall, at `kt`,
/// `steps` implicit steps of 1e-3 s (γ/dt = 3.5 pN/µm against bonds of
/// 2000 pN/µm: 40× the explicit limit).
fn filament(steps: u64, kt: f64) -> common::Case {
    filament_with(steps, kt, "", false)
}

/// [`filament`] with `protocols` (deck lines) before its run, and with
/// `obstacles`: fixed posts beside the beads that push them by
/// `soft_repulsion` and fixed pillars above them by `wca`, overlapping at
/// the start (pair terms with stiffness).
fn filament_with(steps: u64, kt: f64, protocols: &str, obstacles: bool) -> common::Case {
    let mut top = String::from("[ particles ]\n");
    for k in 0..12 {
        let x = 0.3 * k as f64;
        let y = 0.05 * (std::f64::consts::PI * x / 3.3).sin() + 0.01 * (k % 3) as f64;
        top += &format!("{} {} {x} {y} {}\n", k + 1, if k == 0 { "anchor" } else { "bead" }, 0.002 * k as f64);
    }
    if obstacles {
        for k in 1..11 {
            let x = 0.3 * k as f64 + 0.1;
            top += &format!("{} post {x} -0.2 0\n{} pillar {x} 0.05 0.24\n", 11 + 2 * k, 12 + 2 * k);
        }
    }
    top += "[ bonds ]\n";
    for k in 1..12 {
        top += &format!("rod {k} {}\n", k + 1);
    }
    top += "[ angles ]\n";
    for k in 1..11 {
        top += &format!("bend {k} {} {}\n", k + 1, k + 2);
    }
    let mut ff = String::from(
        "particle bead drag 0.0035\nparticle anchor fixed\n\
         bond rod harmonic k 2000 r0 0.31\nangle bend wlc_bending kappa 2 l0 0.3\n",
    );
    if obstacles {
        ff += "particle post fixed\nparticle pillar fixed\n\
               pair bead post soft_repulsion k 500 sigma 0.3\npair bead pillar wca epsilon 0.05 sigma 0.25\n";
    }
    let deck = format!(
        "units cell\ntopology t.top\nforcefield f.ff\nbox x -5 10 f y -5 5 f z -5 5 f\ngroup tip id 12\n\
         external push tip constant_force fx -2 fy 0.5\nexternal stop tip wall nx -1 d -3.28 k 1000\n\
         {protocols}integrator implicit\ntimestep 1e-3\ntemperature {kt}\nseed 3\nrun {steps}\n"
    );
    common::Case::new(&[("t.top", &top), ("f.ff", &ff), ("deck.in", &deck)])
}

fn run(case: &common::Case, device: DevicePreference) -> Simulation {
    let options = RunOptions { output_dir: case.output_dir().to_path_buf(), device: Some(device), ..Default::default() };
    Simulation::execute(case.plan(), options).unwrap_or_else(|e| panic!("{device:?}: {e}"))
}

/// One implicit step: the GPU's Δx equals the CPU's within the bound of an
/// inexact solve. With A = γ/dt·I + K̃ ⪰ γ/dt·I, an error δ in the solve
/// (relative residual ≤ F32_TOLERANCE) and in A and b (f32 rounding of the
/// forces and blocks, a few ε_f32 relative) moves Δx by at most
/// κ(A)·(F32_TOLERANCE + 8·ε_f32)·|Δx|, with κ(A) ≤ (γ/dt + max row sum of
/// |K̃|)/(γ/dt) (Gershgorin), computed here from the CPU's blocks.
#[test]
fn one_implicit_step_on_the_gpu_matches_the_cpu() {
    one_step_matches(&filament(1, 0.0));
}

/// The same with protocols: bead 6 held in y (`freeze`), bead 9 moved at
/// 0.5 µm/s along z (`move`), and the bending stiffness ramped: the held
/// coordinates are identity rows of the solve on both, put back (or moved
/// with their group) after it; the bound is the one above.
#[test]
fn one_implicit_step_with_held_and_moved_beads_matches_the_cpu() {
    let protocols = "group mid id 6\nfreeze mid y\ngroup pushed id 9\nmove pushed linear 0 0 0.5\nramp angle bend kappa 2 4\n";
    let case = filament_with(1, 0.0, protocols, false);
    let gpu = one_step_matches(&case);
    let start = case.plan().positions;
    // Unmoved, to the device's fixed-point quantum (2⁻⁵² of the 15 µm box).
    let quantum = 15.0 * 2f64.powi(-52);
    assert!((gpu.state.positions[5].y - start[5].y).abs() <= 4.0 * quantum, "the held coordinate moved");
    let moved = gpu.state.positions[8] - start[8];
    assert!((moved - DVec3::new(0.0, 0.0, 0.5e-3)).length() < 1e-9, "the moved bead went {moved}");
}

/// The same with excluded volume: fixed posts push the beads by
/// `soft_repulsion` and fixed pillars by `wca`, both overlapping the beads at
/// the start, so pair blocks take part in the solve (gathered from the
/// neighbour list); the bound is the one above, κ(A) from the CPU's blocks
/// with the pairs'.
#[test]
fn one_implicit_step_with_pair_terms_matches_the_cpu() {
    let case = filament_with(1, 0.0, "", true);
    let plan = case.plan();
    let mut backend = CpuBackend::new(&plan.model, &State::new(plan.positions.clone()), &plan.sim_box, 0.3).unwrap();
    let mut forces = Forces::default();
    backend.compute(&plan.model, &State::new(plan.positions.clone()), &plan.sim_box, &mut forces);
    let acting =
        |law: &str| forces.energy_by_interaction[cellmd::interactions::REGISTRY.iter().position(|i| i.name() == law).unwrap()] > 0.0;
    assert!(acting("soft_repulsion") && acting("wca"), "both pair laws must act at the start: {:?}", forces.energy_by_interaction);
    one_step_matches(&case);
}

/// The same with volume elements: a neo-Hookean ball (`cellmd build ball
/// --cells 4`, 125 nodes, 384 elements) squeezed by two walls 5 % into it,
/// then a St Venant–Kirchhoff one: each element's block is its exact 12×12
/// Hessian from the law's `NAME_tetra_hessian`, projected on the device;
/// the bound is the one above, κ(A) from the CPU's blocks.
#[test]
fn one_implicit_step_with_volume_elements_matches_the_cpu() {
    let top = common::small_ball();
    for law in ["neo_hookean", "linear_elastic"] {
        let ff = format!("particle node drag 1\ntetra solid {law} e 1000 nu 0.3\n");
        let deck = "units cell\ntopology t.top\nforcefield f.ff\nbox x -8 8 f y -8 8 f z -8 8 f\n\
                    external bottom all wall nz 1 d -4.75 k 1e4\nexternal top all wall nz -1 d -4.75 k 1e4\n\
                    integrator implicit\ntimestep 1e-3\nrun 1\n";
        let case = common::Case::new(&[("t.top", &top), ("f.ff", &ff), ("deck.in", deck)]);
        println!("{law}:");
        one_step_matches(&case);
    }
}

/// The same with surface terms: two bodies (the area_conservation golden
/// case, a cell and its nucleus), the cell under turgor, surface tension and
/// global and local area elasticity, the nucleus under turgor_log, surface
/// shear and local area elasticity, 40 and 16 times the drag γ/dt: each
/// face's stencils (`NAME_face_hessian`) projected term by term on the
/// device, and the bodies' Gauss–Newton terms (K/V0)·∇V∇Vᵀ, (K/V)·∇V∇Vᵀ and
/// (k_a/A0)·∇A∇Aᵀ applied rank one; the bound is the one above, κ(A) from the
/// CPU's blocks and rank-one terms.
#[test]
fn one_implicit_step_with_surface_terms_matches_the_cpu() {
    let top = std::fs::read_to_string("reference/area_conservation/random.top").unwrap();
    let ff = "particle a drag 0.01\nparticle b drag 0.025\n\
              body cell turgor k 50 dp0 2 v0 60\nbody cell surface_tension gamma 1.5\nbody cell area_conservation ka 20 kl 10 a0 65\n\
              body nucleus turgor_log k 80 v0 40\nbody nucleus surface_shear k 0.5\nbody nucleus area_conservation kl 15 a0 41\n";
    let deck =
        "units cell\ntopology t.top\nforcefield f.ff\nbox x -4 10 f y -4 10 f z -4 10 f\nintegrator implicit\ntimestep 1e-3\nrun 1\n";
    let case = common::Case::new(&[("t.top", &top), ("f.ff", ff), ("deck.in", deck)]);
    one_step_matches(&case);
}

/// The same with Helfrich bending (κ = 0.5, C0 = 0.5, on both bodies of the
/// case above, with surface tension): per node the generalised
/// Gauss–Newton term (4κ/A_i)·g gᵀ over its one-ring, g·v summed per node
/// from its edges and faces before each product and gathered through the
/// edge and face-corner slots; the bound is the one above.
#[test]
fn one_implicit_step_with_helfrich_bending_matches_the_cpu() {
    let top = std::fs::read_to_string("reference/area_conservation/random.top").unwrap();
    let ff = "particle a drag 0.01\nparticle b drag 0.025\n\
              body cell helfrich_bending kappa 0.5 c0 0.5\nbody cell surface_tension gamma 1.5\n\
              body nucleus helfrich_bending kappa 0.5 c0 0.5\nbody nucleus surface_tension gamma 1.5\n";
    let deck =
        "units cell\ntopology t.top\nforcefield f.ff\nbox x -4 10 f y -4 10 f z -4 10 f\nintegrator implicit\ntimestep 1e-3\nrun 1\n";
    let case = common::Case::new(&[("t.top", &top), ("f.ff", ff), ("deck.in", deck)]);
    one_step_matches(&case);
}

/// The same with a rigid spherical indenter (`indenter`, K = 10⁴ pN/µm²,
/// 0.2 µm into the ball's top) instead of the walls: its block is the
/// positive part 2K(R − r)·ûûᵀ of its Hessian, as the CPU's projection
/// keeps it; the bound is the one above (measured 9.0e-7 µm for
/// |Δx| = 5.9e-2; with the indenter's block zeroed, 7.0e-2 off). No wall
/// touches the ball: a wall whose plane passes exactly through nodes (depth
/// 0) has a kink there, where the CPU's central difference gives k/2 and
/// the device's exact block 0 (a floor at the ball's bottom put the GPU
/// 4.1e-4 µm off).
#[test]
fn one_implicit_step_with_an_indenter_matches_the_cpu() {
    let top = common::small_ball();
    let ff = "particle node drag 1\ntetra solid neo_hookean e 1000 nu 0.3\n";
    let deck = "units cell\ntopology t.top\nforcefield f.ff\nbox x -8 8 f y -8 8 f z -8 12 f\n\
                external tip all indenter k 1e4 r 3 x 0 y 0 z 7.8\n\
                integrator implicit\ntimestep 1e-3\nrun 1\n";
    let case = common::Case::new(&[("t.top", &top), ("f.ff", ff), ("deck.in", deck)]);
    one_step_matches(&case);
}

/// The same with contact between bodies: the two pressurised cells of
/// [`contact_case`] 0.06 µm apart across the periodic boundary, under the
/// barrier (d̂ = 0.1 µm) and adhesion (switch 0.05–0.4 µm), so that many
/// node–face pairs are in range of both; dt = 2e-4 s, short enough that the
/// contact clamp leaves the step whole (at 1e-3 s the adhesion's pull moves
/// nodes 2.4 times farther than it allows). The
/// device applies each pair's Gauss–Newton term max(Σ b″, 0)·g gᵀ and each
/// node's adhesion term max(ε·s″·B, 0)·g gᵀ at its nearest face matrix-free,
/// as the CPU's blocks; the bound is the one above (κ(A) from the CPU's
/// blocks, contact included). The step is not clamped, on either device.
#[test]
fn one_implicit_step_with_contact_matches_the_cpu() {
    let ff = format!("{CONTACT_SHELLS}{CONTACT_BARRIER}{CONTACT_ADHESION}");
    let case = contact_case(&ff, 0.06, 1.0, "integrator implicit\ntimestep 2e-4\nrun 1\n");
    let gpu = one_step_matches(&case);
    assert_eq!(gpu.reports.contact_clamps, 0, "a clamped step would test the clamp, not the blocks");
}

/// The implicit step's contact clamp on the device: the cells of
/// [`contact_case`] 0.1 µm apart pushed together by 50 pN per node at
/// dt = 1e-2 s (0.5 µm a step without the barrier, five times d̂), 10
/// steps. The solve's step is shortened to s·Δx, s = min(1, min_i L_i/|Δx_i|)
/// (L_i = 0.4 × particle i's closest contact distance), on the device by a
/// min-reduction after the solve: the same steps are clamped as on the CPU,
/// the clock advances by the same shortened steps, the positions follow the
/// CPU's within the explicit clamp's tolerance (`CONTACT_GPU_EPSILON` = 1e-4
/// of the distance travelled; measured 1.4e-5), and the cells stay apart.
#[test]
fn the_implicit_contact_clamp_runs_on_the_gpu_like_on_the_cpu() {
    clamped_contact_runs_agree("integrator implicit");
}

/// The clamp test above with `integrator` the deck's integrator line.
fn clamped_contact_runs_agree(integrator: &str) {
    let run = |device: DevicePreference| {
        let ff = format!("{CONTACT_SHELLS}{CONTACT_BARRIER}");
        let case = contact_case(&ff, 0.1, 50.0, &format!("{integrator}\ntemperature 0\ntimestep 1e-2\nrun 10\n"));
        let options = RunOptions { output_dir: case.output_dir().to_path_buf(), device: Some(device), ..Default::default() };
        let start = Simulation::new(&case.plan(), RunOptions::default()).state;
        (start, Simulation::execute(case.plan(), options).unwrap_or_else(|e| panic!("{device:?}: {e}")))
    };
    let ((start, cpu), (_, gpu)) = (run(DevicePreference::Cpu), run(DevicePreference::Gpu));
    assert_clamped_runs_agree(&start, &cpu, &gpu, 1);
}

/// `gpu_workgroups all`: the split solve (src/gpu/implicit_split.rs), each
/// phase of CG a dispatch over every workgroup, its sums per workgroup and
/// then over workgroups. One step meets the bound of the one-workgroup
/// solve on the filament (bonds, angles, externals), in more iterations
/// than the first budget (32), so the step was taken again with a larger
/// one; the clamp test's pressurised cells (turgor: the bodies' dots a pass
/// of their own; the contact rows; the clamp's minimum over workgroups)
/// are clamped at the same steps as on the CPU and follow it; and the same
/// thermal run twice gives the same bits.
#[test]
fn the_split_solve_matches_the_cpu() {
    let split = |case: common::Case| {
        let deck = std::fs::read_to_string(case.path("deck.in")).unwrap();
        std::fs::write(case.path("deck.in"), deck.replace("integrator implicit\n", "integrator implicit gpu_workgroups all\n")).unwrap();
        case
    };
    let filament_step = one_step_matches(&split(filament(1, 0.0)));
    // The filament's step outran the first budget: it was taken again with a larger one.
    assert!(filament_step.reports.last_solve.iterations > 32, "{} iterations", filament_step.reports.last_solve.iterations);
    clamped_contact_runs_agree("integrator implicit gpu_workgroups all");
    let thermal = split(filament(30, 4.1e-3));
    let (a, b) = (run(&thermal, DevicePreference::Gpu), run(&thermal, DevicePreference::Gpu));
    assert_eq!(common::position_bits(&a), common::position_bits(&b));
}

/// Newton steps of a `solver cholesky` deck with volume elements:
/// `inputs/hertz_octant.in` (one stage, 8 quasi-static steps to δ = 0.1·R)
/// on the octant of `cellmd build ball --cells 8` (125 nodes, 384 elements),
/// its plate a wall of k = 10⁵ pN/µm, solved by the device's f32 CG. The
/// device resolves a plate force to k·ε_f32·(|d| + |x|) ≤ 2k·ε_f32·R (the
/// depth d − n̂·x rounded in f32); the plate is the stiffest term a contact
/// node has, so the equilibria differ by about that force over k, 2ε_f32·R
/// per node, and the plate's load by that force per contact node.
#[test]
fn newton_steps_with_volume_elements_reach_the_cpu_equilibrium_on_the_gpu() {
    let args = cellmd::build::BallArgs { cells: 8, octant: true, ..Default::default() };
    let dir = tempfile::tempdir().unwrap();
    let top = dir.path().join("octant.top");
    std::fs::write(&top, cellmd::build::ball(&args).unwrap().text).unwrap();
    let vars = [
        ("topology".to_string(), top.display().to_string()),
        ("stages".to_string(), "1".to_string()),
        ("relax_steps".to_string(), "8".to_string()),
    ];
    let plan = cellmd::deck::validate_file(std::path::Path::new("inputs/hertz_octant.in"), &vars).unwrap_or_else(|e| panic!("{e}"));
    let run_on = |device| {
        let options = RunOptions { output_dir: dir.path().to_path_buf(), device: Some(device), ..Default::default() };
        Simulation::execute(plan.clone(), options).unwrap_or_else(|e| panic!("{device:?}: {e}"))
    };
    let (mut cpu, mut gpu) = (run_on(DevicePreference::Cpu), run_on(DevicePreference::Gpu));
    let start = &plan.positions;
    let moved = cpu.state.positions.iter().zip(start).map(|(x, y)| (*x - *y).length()).fold(0.0, f64::max);
    let apart = cpu.state.positions.iter().zip(&gpu.state.positions).map(|(x, y)| (*x - *y).length()).fold(0.0, f64::max);
    let columns =
        plan.actions.iter().find_map(|a| if let cellmd::deck::Action::Thermo { columns, .. } = a { Some(columns.clone()) } else { None });
    let plate = columns.unwrap().into_iter().find(|c| cellmd::run::thermo::column_label(c, &plan.model) == "fz/top").unwrap();
    let (load_cpu, load_gpu) = (cpu.thermo_value(&plate).unwrap(), gpu.thermo_value(&plate).unwrap());
    let (k, radius, eps) = (1e5, 5.0, f32::EPSILON as f64);
    let contact = cpu.state.positions.iter().filter(|x| x.z > 0.9 * radius - 1e-3).count() as f64;
    let (position_bound, load_bound) = (2.0 * eps * radius, contact * 2.0 * k * eps * radius);
    println!(
        "moved {moved:.4e} µm, GPU − CPU {apart:.3e} µm (bound {position_bound:.3e}); load CPU {load_cpu:.6} GPU {load_gpu:.6} pN \
         (bound ±{load_bound:.3e}, {contact} nodes in contact)"
    );
    assert!(moved > 0.1, "the plate moved nothing: {moved:e}");
    assert!(apart <= position_bound, "GPU − CPU {apart:e} µm > {position_bound:e}");
    assert!((load_gpu - load_cpu).abs() <= load_bound, "loads GPU {load_gpu} and CPU {load_cpu}");
}

/// Runs `case` (one implicit step) on both devices and asserts the bound
/// above; returns the GPU's run.
fn one_step_matches(case: &common::Case) -> Simulation {
    let plan = case.plan();
    let start = State::new(plan.positions.clone());
    let cpu = run(case, DevicePreference::Cpu);
    let gpu = run(case, DevicePreference::Gpu);
    let images = plan.sim_box.images();
    let dx = |s: &State| -> Vec<DVec3> { s.positions.iter().zip(&start.positions).map(|(a, b)| images.minimum_image(*a - *b)).collect() };
    let (dc, dg) = (dx(&cpu.state), dx(&gpu.state));
    let norm = |v: &[DVec3]| v.iter().map(|d| d.length_squared()).sum::<f64>().sqrt();
    let error = norm(&dc.iter().zip(&dg).map(|(c, g)| *c - *g).collect::<Vec<_>>());
    let kappa = condition_bound(&plan, &start);
    let bound = kappa * (F32_TOLERANCE + 8.0 * f32::EPSILON as f64) * norm(&dc);
    println!(
        "|Δx| {:.4e}, GPU − CPU {error:.3e} (bound {bound:.3e}, κ ≤ {kappa:.0}); iterations GPU {} CPU {}, residual GPU {:.2e}",
        norm(&dc),
        gpu.reports.last_solve.iterations,
        cpu.reports.last_solve.iterations,
        gpu.reports.last_solve.relative_residual
    );
    assert!(norm(&dc) > 1e-3, "the step moved nothing: {:e}", norm(&dc));
    assert!(gpu.reports.last_solve.iterations > 1 && gpu.reports.last_solve.relative_residual <= F32_TOLERANCE);
    assert!(error <= bound, "GPU − CPU {error:e} > {bound:e}");
    gpu
}

/// κ(A) ≤ (γ/dt + max row sum of |K̃|)/(γ/dt) by Gershgorin, from the CPU's
/// stiffness at `state` (dt: the deck's time step).
fn condition_bound(plan: &cellmd::deck::Plan, state: &State) -> f64 {
    let dt = plan.actions.iter().find_map(|a| if let cellmd::deck::Action::Timestep(dt) = a { Some(*dt) } else { None }).unwrap();
    let model = &plan.model;
    let mut backend = CpuBackend::new(model, state, &plan.sim_box, 0.0).unwrap();
    backend.compute(model, state, &plan.sim_box, &mut Forces::default());
    let stiffness = backend.stiffness(model, state, &plan.sim_box);
    let mut rows = vec![0.0f64; 3 * model.len()];
    for b in &stiffness.blocks {
        for r in 0..3 {
            rows[3 * b.i as usize + r] += (0..3).map(|c| b.block.col(c)[r].abs()).sum::<f64>();
        }
    }
    // A body's rank-one term w·g gᵀ: row (i, r) sums w·|g_i,r|·Σ_j ‖g_j‖₁.
    for term in &stiffness.rank_one {
        let total: f64 = term.gradient.iter().map(|g| g.abs().element_sum()).sum();
        for (&i, g) in term.particles.iter().zip(&term.gradient) {
            for r in 0..3 {
                rows[3 * i as usize + r] += term.weight * g[r].abs() * total;
            }
        }
    }
    let drag = model.type_drag.iter().copied().filter(|g| g.is_finite()).fold(f64::INFINITY, f64::min) / dt;
    (drag + rows.iter().cloned().fold(0.0, f64::max)) / drag
}

/// Bond kinetics with the implicit step: each bead of the filament of
/// [`filament_with`] (with its posts) is tethered to its post by a `slip`
/// bond (k = 5 pN/µm, k0 = 10 /s, x_β = 0.2 nm) at 30 K, 40 steps; the device
/// decides each step's events from its f32 tensions with the CPU's Philox
/// numbers, and an unbound tether's block is zero on both. The same tethers
/// break at the same steps with the same ages, and the positions agree
/// within the one-step bound over the path (κ(A) at the start, which only
/// falls as tethers break).
#[test]
fn bond_kinetics_with_the_implicit_step_match_the_cpu() {
    let case = filament_with(40, 30.0, "", true);
    let top = std::fs::read_to_string(case.path("t.top")).unwrap();
    let tethers: String = (1..11).map(|k| format!("tether {} {}\n", k + 1, 11 + 2 * k)).collect();
    std::fs::write(case.path("t.top"), top.replace("[ bonds ]\n", &format!("[ bonds ]\n{tethers}"))).unwrap();
    let ff = std::fs::read_to_string(case.path("f.ff")).unwrap();
    std::fs::write(case.path("f.ff"), ff + "bond tether harmonic k 5 r0 0.2 kinetics slip k0 10 x_beta 0.0002\n").unwrap();
    let plan = case.plan();
    let start = State::new(plan.positions.clone());
    let (cpu, gpu) = (run(&case, DevicePreference::Cpu), run(&case, DevicePreference::Gpu));
    let (cb, gb) = (cpu.state.bonds.as_ref().unwrap(), gpu.state.bonds.as_ref().unwrap());
    let broken = cb.bound.iter().filter(|b| !**b).count();
    let travelled = cpu.state.positions.iter().zip(&start.positions).map(|(x, y)| (*x - *y).length()).fold(0.0, f64::max);
    let apart = cpu.state.positions.iter().zip(&gpu.state.positions).map(|(x, y)| (*x - *y).length()).fold(0.0, f64::max);
    let bound = condition_bound(&plan, &start) * (F32_TOLERANCE + 8.0 * f32::EPSILON as f64) * travelled;
    println!("{broken} of 10 tethers broken; GPU − CPU {apart:.3e} µm after {travelled:.3e} (bound {bound:.3e})");
    assert!((2..10).contains(&broken), "{broken} tethers broken");
    assert_eq!(cb.bound, gb.bound, "bound tethers");
    assert!(cb.age == gb.age, "tether ages");
    assert!(apart <= bound, "GPU − CPU {apart:e} > {bound:e}");
}

/// At kT > 0 the same implicit run twice gives the same bits (no float
/// atomics; fixed-order gathers and reduction trees).
#[test]
fn the_same_implicit_gpu_run_twice_gives_the_same_bits() {
    let case = filament(30, 4.1e-3);
    let (a, b) = (run(&case, DevicePreference::Gpu), run(&case, DevicePreference::Gpu));
    let bits = |s: &Simulation| s.state.positions.iter().flat_map(|x| x.to_array().map(f64::to_bits)).collect::<Vec<_>>();
    assert_eq!(bits(&a), bits(&b));
    let moved = a.state.positions.iter().zip(&filament(0, 0.0).plan().positions).map(|(x, y)| (*x - *y).length()).fold(0.0, f64::max);
    assert!(moved > 1e-3, "nothing moved: {moved:e}");
}

/// A law without a device stiffness block is refused with the reason; so is
/// `gpu_workgroups all` with constrained bonds.
#[test]
fn implicit_decks_the_device_cannot_solve_are_refused_with_the_reason() {
    let case = filament(1, 0.0);
    let options = RunOptions { output_dir: case.output_dir().to_path_buf(), device: Some(DevicePreference::Gpu), ..Default::default() };
    let ff = std::fs::read_to_string(case.path("f.ff")).unwrap();
    std::fs::write(case.path("f.ff"), ff.replace("harmonic k 2000 r0 0.31", "fene K 30 R0 1.5 epsilon 0 sigma 1")).unwrap();
    let refused = Simulation::execute(case.plan(), options).err().map(|e| e.to_string()).unwrap_or_default();
    assert!(refused.contains("has no GPU stiffness block"), "{refused}");
    // The projected solve of constrained bonds runs in one workgroup only.
    let case = filament(1, 0.0);
    let options = RunOptions { output_dir: case.output_dir().to_path_buf(), device: Some(DevicePreference::Gpu), ..Default::default() };
    let deck = std::fs::read_to_string(case.path("deck.in")).unwrap();
    std::fs::write(
        case.path("deck.in"),
        deck.replace("integrator implicit\n", "constrain rod method shake reshape yes\nintegrator implicit gpu_workgroups all\n"),
    )
    .unwrap();
    let refused = Simulation::execute(case.plan(), options).err().map(|e| e.to_string()).unwrap_or_default();
    assert!(refused.contains("`gpu_workgroups all` with `constrain`"), "{refused}");
}

/// `solver cholesky` on the device: `inputs/force_dipole.in` (8 quasi-static
/// Newton steps at γ/dt = 1e-6 pN/µm) on a diluted lattice of radius 10 µm,
/// solved by the device's f32 CG. Its end state is the CPU's equilibrium:
/// the CPU's f64 forces there are at most what the device cannot resolve,
/// 6·k·a·ε_f32 (each bond's force rounds its separation a = 1 µm to f32, an
/// error k·a·ε_f32 with the links' k = 100 pN/µm; up to 6 bonds a node),
/// and, the lattice being linear at these strains, the positions agree with
/// the CPU's Cholesky run within that force relative to the dipole's, times
/// the largest displacement the dipole causes.
#[test]
fn newton_steps_of_a_cholesky_deck_reach_the_cpu_equilibrium_on_the_gpu() {
    let args = cellmd::build::LatticeArgs {
        radius: 10.0,
        spacing: 1.0,
        bond_probability: 0.8,
        bending: true,
        dipole: true,
        common: cellmd::build::Common { seed: 1, output: "lattice.top".into(), rest_from_geometry: false },
        ..Default::default()
    };
    let built = cellmd::build::lattice(&args).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let top = dir.path().join("lattice.top");
    std::fs::write(&top, &built.text).unwrap();
    let vars = [("topology".to_string(), top.display().to_string())];
    let plan = cellmd::deck::validate_file(std::path::Path::new("inputs/force_dipole.in"), &vars).unwrap_or_else(|e| panic!("{e}"));
    let start = plan.positions.clone();
    let run_on = |device| {
        let options = RunOptions { output_dir: dir.path().to_path_buf(), device: Some(device), ..Default::default() };
        Simulation::execute(plan.clone(), options).unwrap_or_else(|e| panic!("{device:?}: {e}"))
    };
    let (cpu, gpu) = (run_on(DevicePreference::Cpu), run_on(DevicePreference::Gpu));
    let model = &plan.model;
    let mut backend = CpuBackend::new(model, &gpu.state, &plan.sim_box, 0.0).unwrap();
    let mut forces = Forces::default();
    backend.compute(model, &gpu.state, &plan.sim_box, &mut forces);
    let free: Vec<usize> = (0..model.len()).filter(|&i| model.type_drag[model.types[i] as usize].is_finite()).collect();
    let residual = free.iter().map(|&i| forces.forces[i].length()).fold(0.0, f64::max);
    // fibre_lattice.ff: links k 100 r0 1 (built at length 1), the dipole k 1 r0 0 (built at length 2).
    let length = |x: &[DVec3], [i, j]: [u32; 2]| (x[j as usize] - x[i as usize]).length();
    let dipole = model.bonds.iter().find(|&&b| length(&start, b) > 1.5).map(|&b| length(&gpu.state.positions, b)).unwrap();
    let moved = cpu.state.positions.iter().zip(&start).map(|(x, y)| (*x - *y).length()).fold(0.0, f64::max);
    let apart = cpu.state.positions.iter().zip(&gpu.state.positions).map(|(x, y)| (*x - *y).length()).fold(0.0, f64::max);
    let residual_bound = 6.0 * 100.0 * 1.0 * f32::EPSILON as f64;
    println!(
        "dipole {dipole:.4} pN, moved {moved:.4e} µm; GPU end: f64 residual {residual:.3e} pN (bound {residual_bound:.3e}), \
         GPU − CPU {apart:.3e} µm; iterations GPU {} CPU {}",
        gpu.reports.last_solve.iterations, cpu.reports.last_solve.iterations
    );
    assert!(moved > 1e-3, "the dipole moved nothing: {moved:e}");
    assert!(residual <= residual_bound, "the GPU's end state is not an equilibrium: |F| {residual:e} > {residual_bound:e}");
    let bound = residual_bound / dipole * moved;
    assert!(apart <= bound, "GPU − CPU {apart:e} µm > {bound:e}");
}

/// Wall-clock time of `inputs/buckling_filament.in` (1500 implicit steps) on
/// the CPU and on the GPU: `cargo test --test suite gpu_implicit::buckling -- --ignored --nocapture`.
#[test]
#[ignore]
fn buckling_filament_timing() {
    let deck = std::path::Path::new("inputs/buckling_filament.in");
    for device in [DevicePreference::Cpu, DevicePreference::Gpu] {
        let dir = tempfile::tempdir().unwrap();
        let plan = cellmd::deck::validate_file(deck, &[]).unwrap();
        let options = RunOptions { output_dir: dir.path().to_path_buf(), device: Some(device), ..Default::default() };
        let started = std::time::Instant::now();
        let sim = Simulation::execute(plan, options).unwrap();
        let seconds = started.elapsed().as_secs_f64();
        println!("{device:?}: {} steps in {seconds:.2} s, last solve {} iterations", sim.state.step, sim.reports.last_solve.iterations);
    }
}

/// Free particles and particles tethered to fixed anchors (harmonic, r0 = 0)
/// at kT = 0.5 (lj units), `steps` implicit steps of `dt` on `device`:
/// the free particles' mean squared displacement and the tethers' mean
/// squared extension.
fn thermal_tethers(device: DevicePreference, steps: u64, dt: f64) -> (f64, f64) {
    let mut top = String::from("[ particles ]\n");
    let mut bonds = String::from("[ bonds ]\n");
    let n = 1500;
    for k in 0..n {
        let (x, y, z) = ((k % 15) as f64 * 4.0 + 2.0, ((k / 15) % 10) as f64 * 4.0 + 2.0, (k / 150) as f64 * 4.0 + 2.0);
        top += &format!(
            "{} free {x} {y} {z}\n{} bead {} {y} {z}\n{} anchor {} {y} {z}\n",
            3 * k + 1,
            3 * k + 2,
            x + 1.0,
            3 * k + 3,
            x + 1.001
        );
        bonds += &format!("tether {} {}\n", 3 * k + 2, 3 * k + 3);
    }
    let ff = "particle free drag 2\nparticle bead drag 2\nparticle anchor fixed\nbond tether harmonic k 100 r0 0\n";
    let deck = format!(
        "units lj\ntopology t.top\nforcefield f.ff\nbox x 0 60 p y 0 40 p z 0 40 p\n\
         integrator implicit\ntemperature 0.5\ntimestep {dt}\nseed 7\nrun {steps}\n"
    );
    let case = common::Case::new(&[("t.top", &(top + &bonds)), ("f.ff", ff), ("deck.in", &deck)]);
    let plan = case.plan();
    let sim = run(&case, device);
    let unwrap = |s: &State, i: usize| plan.sim_box.unwrap(s.positions[i], s.images[i]);
    let start = State::new(plan.positions.clone());
    let msd = (0..n).map(|k| (unwrap(&sim.state, 3 * k) - start.positions[3 * k]).length_squared()).sum::<f64>() / n as f64;
    let extension =
        (0..n).map(|k| (unwrap(&sim.state, 3 * k + 1) - unwrap(&sim.state, 3 * k + 2)).length_squared()).sum::<f64>() / n as f64;
    (msd, extension)
}

/// kT > 0 with the implicit step at k·dt/γ = 5 (five times the explicit
/// step's stability limit of 2 for a tether): on both devices the free
/// particles diffuse as 6Dt (their step is the explicit one), and each
/// tether's extension has the exact stationary variance of the implicit
/// step's own recursion x ← (1 − a′)x + b·ξ, a′ = k/(γ/dt + k),
/// b = √(2kT·γ/dt)/(γ/dt + k): per axis b²/(1 − (1 − a′)²), here 0.29·kT/k
/// (kT/k is the continuous value: the implicit step's stiff modes are
/// colder). Within 4 relative standard errors √(2/(3n)) of a mean of n
/// squared 3-D Gaussian norms.
#[test]
fn thermal_implicit_runs_have_the_exact_statistics_on_both_devices() {
    let (kt, gamma, k, dt): (f64, f64, f64, f64) = (0.5, 2.0, 100.0, 0.1);
    let steps = 60;
    let drag = gamma / dt;
    let a = k / (drag + k);
    let b2 = 2.0 * kt * drag / ((drag + k) * (drag + k));
    let expected_extension = 3.0 * b2 / (1.0 - (1.0 - a) * (1.0 - a));
    let expected_msd = 6.0 * kt / gamma * dt * steps as f64;
    let sigma = (2.0 / (3.0 * 1500.0f64)).sqrt();
    for device in [DevicePreference::Cpu, DevicePreference::Gpu] {
        let (msd, extension) = thermal_tethers(device, steps, dt);
        println!(
            "{device:?}: MSD {msd:.5} (6Dt {expected_msd:.5}), ⟨d²⟩ {extension:.6} (exact {expected_extension:.6}; kT/k·3 = {:.6}), σ {sigma:.3}",
            3.0 * kt / k
        );
        assert!((msd / expected_msd - 1.0).abs() < 4.0 * sigma, "{device:?}: MSD {msd} vs {expected_msd}");
        assert!((extension / expected_extension - 1.0).abs() < 4.0 * sigma, "{device:?}: ⟨d²⟩ {extension} vs {expected_extension}");
    }
}

/// `inputs/network_shear.in` on the device: its `plastic` crosslinks decided
/// by the host from read-back positions, every step (damped at γ/dt = 1
/// pN/µm, then quasi-static Newton steps at 1e-6) solved by the device's f32
/// CG; the first shear stage, 4 + 4 steps (the whole deck takes ~1.7 s a
/// step on llvmpipe; two stages took 60 s of CI's test binary, one leaves
/// 284 rest lengths reset and the worst residual at 0.75 of what f32
/// resolves there). The crosslinks' rest lengths, reset by the
/// first tiny step, agree within 1e-5 relative (as in tests/suite/gpu.rs's
/// kinetics test). The end state is an equilibrium of the CPU's f64 forces
/// to what f32 resolves: a bond's force rounds its separation d to f32, an
/// error k·|d|·ε_f32 (network_shear.ff: k = 50 000 pN/µm for segments and
/// crosslinks), summed over each node's bonds. Positions are not compared
/// with the CPU's: the Mikado network is floppy (measured: GPU − CPU
/// 1.5e-4 µm after 1.4e-3 µm in three stages, where forces agree to 1e-3 pN).
#[test]
fn network_shear_stages_reach_the_cpu_equilibrium_on_the_gpu() {
    let vars = [("stages".to_string(), "1".to_string()), ("relax_steps".to_string(), "4".to_string())];
    let plan = cellmd::deck::validate_file(std::path::Path::new("inputs/network_shear.in"), &vars).unwrap_or_else(|e| panic!("{e}"));
    let dir = tempfile::tempdir().unwrap();
    let run_on = |device| {
        let options = RunOptions { output_dir: dir.path().to_path_buf(), device: Some(device), ..Default::default() };
        Simulation::execute(plan.clone(), options).unwrap_or_else(|e| panic!("{device:?}: {e}"))
    };
    let (cpu, gpu) = (run_on(DevicePreference::Cpu), run_on(DevicePreference::Gpu));
    let model = &plan.model;
    let (cpu_rest, gpu_rest) = (&cpu.state.bonds.as_ref().unwrap().rest, &gpu.state.bonds.as_ref().unwrap().rest);
    let reset = cpu_rest.iter().filter(|r| r.is_some()).count();
    assert!(reset > 100, "only {reset} crosslinks reset their rest length");
    for (c, g) in cpu_rest.iter().zip(gpu_rest) {
        assert!(c.is_some() == g.is_some() && c.zip(*g).is_none_or(|(c, g)| (c - g).abs() <= 1e-5 * c.abs()), "rest lengths {c:?} {g:?}");
    }
    let x = &gpu.state.positions;
    let mut backend = CpuBackend::new(model, &gpu.state, &plan.sim_box, 0.0).unwrap();
    let mut forces = Forces::default();
    backend.compute(model, &gpu.state, &plan.sim_box, &mut forces);
    let mut resolution = vec![0.0; model.len()];
    for &[i, j] in &model.bonds {
        let d = plan.sim_box.minimum_image(x[j as usize] - x[i as usize]).length();
        for end in [i, j] {
            resolution[end as usize] += 50_000.0 * d * f32::EPSILON as f64;
        }
    }
    let free = (0..model.len()).filter(|&i| model.type_drag[model.types[i] as usize].is_finite());
    let (worst, at) = free.map(|i| (forces.forces[i].length() / resolution[i], i)).fold((0.0, 0), |a, b| if b.0 > a.0 { b } else { a });
    println!(
        "{reset} rest lengths reset; GPU end: f64 residual {:.3e} pN at particle {at}, {worst:.2} of what f32 resolves there ({:.3e} pN)",
        forces.forces[at].length(),
        resolution[at]
    );
    assert!(
        worst <= 1.0,
        "the GPU's end state is not an equilibrium: particle {at}, |F| {:e} > {:e}",
        forces.forces[at].length(),
        resolution[at]
    );
}

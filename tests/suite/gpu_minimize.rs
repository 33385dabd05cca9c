//! `minimize` (FIRE) on the device (src/gpu/fire.rs) against analytic minima
//! and the CPU's f64 FIRE, on whatever Vulkan adapter exists (CI: Mesa's
//! llvmpipe).

use crate::common;

use cellmd::deck::Action;
use cellmd::gpu::DevicePreference;
use cellmd::run::{RunOptions, Simulation};
use glam::DVec3;

fn run(case: &common::Case, device: DevicePreference) -> Simulation {
    let options = RunOptions { output_dir: case.output_dir().to_path_buf(), device: Some(device), ..Default::default() };
    Simulation::execute(case.plan(), options).unwrap_or_else(|e| panic!("{device:?}: {e}"))
}

const K: f64 = 4.0;
const PULL: f64 = 2.0;
const FTOL: f64 = 1e-6;

/// Two springs (k = 4, r0 = 1) from fixed anchors, each bead pulled by 2 pN
/// along x; the second bead is held in z (`freeze`) at 0.3 above its
/// anchor. 1 000 filler particles far away (no force on them) make the
/// power and norms sums span several workgroups.
fn springs() -> common::Case {
    let mut top = String::from("[ particles ]\n1 anchor 0 0 0\n2 bead 1.5 0.2 0\n3 anchor 0 5 0\n4 bead 1.2 4.7 0.3\n");
    for k in 0..1000 {
        top += &format!("{} filler {} {} -5\n", 5 + k, -9.0 + 0.5 * (k % 36) as f64, -9.0 + 0.5 * (k / 36) as f64);
    }
    top += "[ bonds ]\nspring 1 2\nspring 3 4\n";
    let ff = format!("particle anchor fixed\nparticle bead drag 0.01\nparticle filler drag 0.01\nbond spring harmonic k {K} r0 1\n");
    let deck = format!(
        "topology t.top\nforcefield f.ff\nbox x -10 10 f y -10 10 f z -10 10 f\ngroup beads type bead\ngroup held id 4\n\
         external pull beads constant_force fx {PULL}\nfreeze held z\ntimestep 1e-3\n\
         minimize ftol {FTOL} maxiter 100000\n"
    );
    common::Case::new(&[("t.top", &top), ("f.ff", &ff), ("deck.in", &deck)])
}

/// The analytic minima: the free bead at (1 + PULL/K, 0, 0); the held one at
/// z = 0.3 above its anchor, y = 0, and x solving K·(r − 1)·x/r = PULL with
/// r = √(x² + 0.09) (Newton in f64). Each bead lands within
/// (ftol + f32 rounding of its forces)/k_min of its minimum, k_min the
/// softest stiffness there: the spring's transverse tension/r.
#[test]
fn fire_on_the_gpu_reaches_the_analytic_minima_and_keeps_held_axes() {
    let gpu = run(&springs(), DevicePreference::Gpu);
    let report = gpu.reports.last_minimize.clone().expect("a minimisation");
    println!("{report:?}");
    assert!(report.converged, "{report:?}");
    let x = &gpu.state.positions;
    assert_eq!(x[0], DVec3::ZERO);
    assert_eq!(x[2], DVec3::new(0.0, 5.0, 0.0));
    // Positions come back through the device's fixed point, whose quantum
    // in this 20 µm box is 20·2⁻⁵² = 4.4e-15 µm: "unmoved" is within a few.
    let quantum = 20.0 * 2f64.powi(-52);
    assert!((x[3].z - 0.3).abs() <= 4.0 * quantum, "the held coordinate moved to {}", x[3].z);
    let mut held_x = 1.5;
    for _ in 0..50 {
        let r = (held_x * held_x + 0.09f64).sqrt();
        let g = K * (r - 1.0) * held_x / r - PULL;
        let dg = K * (1.0 - 1.0 / r) + K * held_x * held_x / (r * r * r);
        held_x -= g / dg;
    }
    let rounding = 8.0 * f32::EPSILON as f64 * PULL;
    for (bead, minimum, r) in [(1, DVec3::new(1.0 + PULL / K, 0.0, 0.0), 1.0 + PULL / K), (3, DVec3::new(held_x, 5.0, 0.3), 0.0)] {
        let r = if r > 0.0 { r } else { (held_x * held_x + 0.09f64).sqrt() };
        let k_min = (K * (r - 1.0) / r).min(K);
        let bound = (FTOL + rounding) / k_min;
        let off = (x[bead] - minimum).length();
        println!("bead {}: {:?}, minimum {minimum:?}: off by {off:.2e} (bound {bound:.2e})", bead + 1, x[bead]);
        assert!(off < bound, "bead {} off its minimum by {off:e} (bound {bound:e})", bead + 1);
    }
    let start = springs().plan().positions;
    assert!(x[4..].iter().zip(&start[4..]).all(|(a, b)| (*a - *b).abs().max_element() <= 4.0 * quantum), "a particle without force moved");
}

/// The same minimisation twice on the device gives the same bits (fixed
/// reduction trees, no float atomics).
#[test]
fn the_same_gpu_minimisation_twice_gives_the_same_bits() {
    let case = springs();
    let (first, second) = (run(&case, DevicePreference::Gpu), run(&case, DevicePreference::Gpu));
    assert_eq!(common::position_bits(&first), common::position_bits(&second));
    assert_eq!(first.reports.last_minimize.map(|r| r.iterations), second.reports.last_minimize.map(|r| r.iterations));
}

/// The tensegrity cell on its substrate (inputs/tensegrity_substrate.in),
/// its first spreading stage and relaxation: the device's endpoint is
/// converged by the CPU's f64 forces, at the energy of the CPU's FIRE, in
/// a number of iterations of the same order (the paths part by rounding
/// where FIRE's power changes sign).
#[test]
fn the_tensegrity_stage_relaxes_on_the_gpu_like_on_the_cpu() {
    let vars = [("max_stages".into(), "1".into()), ("steps".into(), "0".into())];
    let plan = cellmd::deck::validate_file(std::path::Path::new("inputs/tensegrity_substrate.in"), &vars).unwrap();
    let first_minimize = |device: DevicePreference| {
        let dir = tempfile::tempdir().unwrap();
        let options = RunOptions { output_dir: dir.path().to_path_buf(), device: Some(device), ..Default::default() };
        let mut sim = Simulation::before_first_run(&plan, options).unwrap();
        for action in &plan.actions {
            let minimize = matches!(action, Action::Minimize(_));
            sim.apply(action).unwrap();
            if minimize {
                return sim;
            }
        }
        panic!("no minimize in the deck");
    };
    let cpu = first_minimize(DevicePreference::Cpu);
    let gpu = first_minimize(DevicePreference::Gpu);
    let (c, g) = (cpu.reports.last_minimize.clone().unwrap(), gpu.reports.last_minimize.clone().unwrap());
    let apart = cpu.state.positions.iter().zip(&gpu.state.positions).map(|(a, b)| (*a - *b).length()).fold(0.0, f64::max);
    println!("CPU {c:?}\nGPU {g:?}\nlargest position difference {apart:.3e} µm, energy difference {:.3e}", (g.energy / c.energy - 1.0));
    assert!(c.converged && g.converged);
    assert!(
        (g.iterations as f64 / c.iterations as f64 - 1.0).abs() < 0.5,
        "{} GPU iterations against {} on the CPU",
        g.iterations,
        c.iterations
    );
    // E(x_gpu) − E(x_cpu) = −½·Σ(F_cpu + F_gpu)·Δx to third order in Δx
    // (the forces are the CPU's f64 ones at both ends; a fixed particle or a
    // held axis has Δx = 0): asserted within twice the sum of its terms' sizes.
    let first_order: f64 = (0..cpu.state.len())
        .map(|i| {
            (0.5 * (cpu.backend.forces.forces[i] + gpu.backend.forces.forces[i]).dot(gpu.state.positions[i] - cpu.state.positions[i])).abs()
        })
        .sum();
    println!("|ΔE| {:.3e} pN·µm, bound {:.3e}", (g.energy - c.energy).abs(), 2.0 * first_order);
    assert!((g.energy - c.energy).abs() < 2.0 * first_order, "energies part by {:e}", g.energy - c.energy);
}

/// What the device cannot step (here `integrator implicit solver
/// cholesky`) does not keep `minimize` off it: only the forces and FIRE's
/// moves decide, so the deck's minimisation runs on the GPU, the same bits
/// as without that line.
#[test]
fn minimize_runs_on_the_gpu_whatever_the_integrator() {
    let case = springs();
    let plain = run(&case, DevicePreference::Gpu);
    let deck = std::fs::read_to_string(case.path("deck.in")).unwrap();
    std::fs::write(case.path("deck.in"), deck.replace("timestep 1e-3\n", "timestep 1e-3\nintegrator implicit solver cholesky\n")).unwrap();
    let cholesky = run(&case, DevicePreference::Gpu);
    assert!(cholesky.reports.last_minimize.as_ref().is_some_and(|r| r.converged));
    assert_eq!(common::position_bits(&plain), common::position_bits(&cholesky));
}

/// FIRE with contact between bodies on the device: the meshed cells of
/// [`common::squeezed_cells`] between plates in a tube (the FIRE test of
/// tests/suite/contact.rs), relaxed to max |F| < 10⁻² pN. Each move is scaled by
/// the contact step clamp s = min(1, min_i L_i/|Δx_i|) (L_i = 0.4 × the
/// closest contact distance the contact pass keeps), min-reduced on the
/// device: both devices converge, both clamp moves, the cells stay apart,
/// and the device's endpoint has the energy of the CPU's within twice the
/// first-order bound of the tensegrity test above.
#[test]
fn fire_with_contact_relaxes_on_the_gpu_like_on_the_cpu() {
    let case = common::squeezed_cells("temperature 0\ntimestep 1e-3\nminimize ftol 1e-2 maxiter 30000 dmax 0.05\n");
    let (cpu, gpu) = (run(&case, DevicePreference::Cpu), run(&case, DevicePreference::Gpu));
    let (c, g) = (cpu.reports.last_minimize.clone().unwrap(), gpu.reports.last_minimize.clone().unwrap());
    let images = cpu.sim_box.images();
    let apart =
        cpu.state.positions.iter().zip(&gpu.state.positions).map(|(a, b)| images.minimum_image(*a - *b).length()).fold(0.0, f64::max);
    println!(
        "CPU {c:?}, mindist {:.4e}\nGPU {g:?}, mindist {:.4e}\nlargest position difference {apart:.3e} µm",
        cpu.min_contact_distance(),
        gpu.min_contact_distance()
    );
    assert!(c.converged && g.converged);
    assert!(c.clamped > 0 && g.clamped > 0, "the clamp never acted: CPU {}, GPU {}", c.clamped, g.clamped);
    assert!(gpu.min_contact_distance() > 0.0 && gpu.min_contact_distance() < 0.1);
    let first_order: f64 = (0..cpu.state.len())
        .map(|i| {
            let dx = images.minimum_image(gpu.state.positions[i] - cpu.state.positions[i]);
            (0.5 * (cpu.backend.forces.forces[i] + gpu.backend.forces.forces[i]).dot(dx)).abs()
        })
        .sum();
    println!("|ΔE| {:.3e} pN·µm, bound {:.3e}", (g.energy - c.energy).abs(), 2.0 * first_order);
    assert!((g.energy - c.energy).abs() < 2.0 * first_order, "energies part by {:e}", g.energy - c.energy);
}

//! Bond kinetics decided on the device (src/gpu/kinetics.rs), on whatever
//! Vulkan adapter exists (CI: Mesa's llvmpipe). The CPU comparison of event
//! logs and ages is `kinetics_decks_give_the_same_events_on_the_gpu` in
//! tests/suite/gpu.rs; here: no per-step read-back, the same bits twice, the
//! breaking statistics against the closed-form rates, and the models whose
//! kinetics stay on the host.

use crate::common;

use cellmd::gpu::backend::StepSettings;
use cellmd::gpu::kinetics::{refusal, DeviceDecisions};
use cellmd::gpu::{DevicePreference, GpuBackend, GpuContext};
use cellmd::kinetics_engine::EventKind;
use cellmd::run::{RunOptions, Simulation};
use cellmd::system::BondState;

fn context() -> GpuContext {
    GpuContext::open(false).unwrap_or_else(|e| {
        panic!("the GPU tests need a Vulkan adapter; `scripts/test-all` installs Mesa's software driver (mesa-vulkan-drivers): {e}")
    })
}

/// The catch-slip sweep deck (8 × 400 bonds held at 0, 4, …, 28 pN between
/// fixed particles) ready to run: its simulation and step settings.
fn sweep() -> (Simulation, StepSettings) {
    let plan = cellmd::deck::validate_file(std::path::Path::new("inputs/catch_slip_sweep.in"), &[]).unwrap();
    let sim = Simulation::before_first_run(&plan, RunOptions::default()).unwrap();
    let settings = sim.step_settings();
    (sim, settings)
}

/// `steps` steps on the device from the deck's start: the decisions, the
/// bond state after them, and the read-backs the run itself took.
fn run_on_device(sim: &Simulation, settings: &StepSettings, steps: u64) -> (DeviceDecisions, BondState, u64) {
    assert!(refusal(&sim.model).is_none(), "{:?}", refusal(&sim.model));
    let mut gpu = GpuBackend::with_device_kinetics(&context(), &sim.model, &sim.state, &sim.sim_box, settings, &[]).unwrap();
    let before = gpu.read_backs();
    assert_eq!(gpu.run(sim.state.step, steps), Ok(steps));
    let reads = gpu.read_backs() - before;
    let decided = gpu.drain_kinetics();
    let mut bonds = sim.state.bonds.clone().unwrap();
    gpu.download_bond_state(&mut bonds);
    (decided, bonds, reads)
}

/// 300 steps with kinetics are one GPU segment: the run reads back only its
/// status words once (no per-step synchronisation), yet the device decided
/// events at many different steps, in step then bond order, and its bound
/// flags agree with the events.
#[test]
fn a_kinetics_segment_reads_nothing_back_per_step() {
    let (sim, settings) = sweep();
    let (decided, bonds, reads) = run_on_device(&sim, &settings, 300);
    assert_eq!(reads, 1, "read-backs during a 300-step segment");
    let steps: std::collections::BTreeSet<u64> = decided.events.iter().map(|e| e.step).collect();
    println!("{} events at {} steps", decided.events.len(), steps.len());
    assert!(steps.len() > 50, "events at only {} steps", steps.len());
    assert!(decided.events.windows(2).all(|w| (w[0].step, w[0].bond) < (w[1].step, w[1].bond)), "events out of order");
    assert!(decided.events.iter().all(|e| e.kind == EventKind::Break && (0..300).contains(&e.step)));
    let broken = bonds.bound.iter().filter(|&&b| !b).count();
    assert_eq!(broken, decided.events.len(), "unbound bonds and break events");
    for e in &decided.events {
        assert!(!bonds.bound[e.bond]);
        // The age at the break is the steps bound times dt (one step at least).
        let steps_bound = e.age / settings.context.dt;
        assert!((steps_bound - (e.step + 1) as f64).abs() < 1e-6, "bond {} broke at step {} with age {}", e.bond, e.step, e.age);
    }
}

/// The same device run twice gives the same bits: events (with their f32
/// tensions and lengths), bound flags and ages.
#[test]
fn device_kinetics_repeat_bit_for_bit() {
    let (sim, settings) = sweep();
    let (a, bonds_a, _) = run_on_device(&sim, &settings, 200);
    let (b, bonds_b, _) = run_on_device(&sim, &settings, 200);
    assert!(!a.events.is_empty());
    let bits = |d: &DeviceDecisions| {
        d.events.iter().map(|e| (e.step, e.bond, e.force.to_bits(), e.length.to_bits(), e.age.to_bits())).collect::<Vec<_>>()
    };
    assert_eq!(bits(&a), bits(&b));
    assert_eq!(bonds_a.bound, bonds_b.bound);
    assert_eq!(bonds_a.age.iter().map(|x| x.to_bits()).collect::<Vec<_>>(), bonds_b.age.iter().map(|x| x.to_bits()).collect::<Vec<_>>());
}

/// Breaks in 1000 steps per held force against the closed-form catch-slip
/// rate k(F) = kc0·e^(−F·xc/kT) + ks0·e^(F·xs/kT) (catch_slip_sweep.ff):
/// bond b survives the run with probability exp(−k(F_b)·T), so a force's
/// break count is a sum of Bernoulli variables, within 4.5 standard
/// deviations of its mean (+1 for the discreteness), for each of the eight
/// forces; the steps of the breaks follow the exponential law conditioned on
/// breaking within the run (Kolmogorov–Smirnov, α = 0.001); the tension each
/// break reports is the held force within f32 rounding (1e-4 pN of up to 28 pN).
#[test]
fn device_breaks_follow_the_catch_slip_rate() {
    let (sim, settings) = sweep();
    let steps = 1000;
    let (decided, _, _) = run_on_device(&sim, &settings, steps);
    let kt = sim.settings.kt;
    let rate = |f: f64| 10.0 * (-f * 0.002 / kt).exp() + 0.05 * (f * 0.001 / kt).exp();
    let held = |b: usize| {
        let [i, j] = sim.model.bonds[b];
        let r = (sim.state.positions[j as usize] - sim.state.positions[i as usize]).length();
        1000.0 * (r - 0.05)
    };
    let types = sim.model.bond_types.len();
    let (mut mean, mut var, mut breaks) = (vec![0.0; types], vec![0.0; types], vec![0usize; types]);
    let mut steps_of = vec![Vec::new(); types];
    for b in 0..sim.model.bonds.len() {
        let q = 1.0 - (-rate(held(b)) * steps as f64 * settings.context.dt).exp();
        let t = sim.model.bond_type[b] as usize;
        mean[t] += q;
        var[t] += q * (1.0 - q);
    }
    for e in &decided.events {
        breaks[sim.model.bond_type[e.bond] as usize] += 1;
        steps_of[sim.model.bond_type[e.bond] as usize].push(e.step);
        assert!((e.force - held(e.bond)).abs() < 1e-4, "bond {}: tension {} held at {}", e.bond, e.force, held(e.bond));
    }
    for t in 0..types {
        let label = &sim.model.bond_types[t].label.text;
        // Every bond of a type is held at the same force.
        let first = (0..sim.model.bonds.len()).find(|&b| sim.model.bond_type[b] as usize == t).unwrap();
        let ks = common::ks_exponential_steps(&steps_of[t], rate(held(first)) * settings.context.dt, Some(steps));
        println!("{label}: {} breaks, expected {:.1} ± {:.1}; KS D√N {ks:.2}", breaks[t], mean[t], var[t].sqrt());
        assert!(ks < 1.95, "{label}: break steps not exponential, KS D√N = {ks}");
        assert!(
            (breaks[t] as f64 - mean[t]).abs() <= 4.5 * var[t].sqrt() + 1.0,
            "{label}: {} breaks, expected {:.1} ± {:.1}",
            breaks[t],
            mean[t],
            var[t].sqrt()
        );
    }
}

/// Models whose kinetics stay on the host say why; the others pass.
#[test]
fn unported_rules_keep_kinetics_on_the_host() {
    let reason = |deck: &str| {
        let plan = cellmd::deck::validate_file(std::path::Path::new(deck), &[]).unwrap();
        refusal(&plan.model)
    };
    assert_eq!(reason("inputs/catch_slip_sweep.in"), None);
    let motor = reason("inputs/contractile_network.in").unwrap();
    assert!(motor.contains("motor"), "{motor}");
    // `bind` formation runs on the device (tests/suite/gpu_bind.rs), but not `partner nearest`.
    assert_eq!(reason("inputs/aggregate.in"), None);
}

/// A broken bond stops excluding its pair, also across GPU segments: 30
/// pairs bonded below their WCA range break at step 0 (strain over the
/// threshold) and then repel; with thermo every step (one-step segments) the
/// GPU follows the CPU within 1e-5 of the distance travelled (f32 forces).
#[test]
fn a_broken_bond_releases_its_pair_on_the_device() {
    let mut top = String::from("[ particles ]\n");
    let mut bonds = String::from("[ bonds ]\n");
    for m in 0..30 {
        let (x, y) = ((m % 6) as f64 * 3.0, (m / 6) as f64 * 3.0);
        top += &format!("{} bead {x} {y} 0\n{} bead {} {y} 0.01\n", 2 * m + 1, 2 * m + 2, x + 0.54 + 0.0005 * m as f64);
        bonds += &format!("link {} {}\n", 2 * m + 1, 2 * m + 2);
    }
    let ff = "particle bead drag 1\nbond link harmonic k 5 r0 0.45 kinetics threshold strain 0.1\npair bead bead wca epsilon 1 sigma 0.5\n";
    let deck = "units lj\ntopology t.top\nforcefield f.ff\nbox x -5 25 f y -5 20 f z -5 5 f\ntimestep 1e-3\nthermo 1 step\nrun 40\n";
    let case = common::Case::new(&[("t.top", &(top + &bonds)), ("f.ff", ff), ("deck.in", deck)]);
    let plan = case.plan();
    assert_eq!(refusal(&plan.model), None);
    let run = |device: DevicePreference| {
        let options = RunOptions { output_dir: case.output_dir().to_path_buf(), device: Some(device), ..Default::default() };
        Simulation::execute(plan.clone(), options).unwrap().state
    };
    let (start, cpu, gpu) = (Simulation::new(&plan, RunOptions::default()).state, run(DevicePreference::Cpu), run(DevicePreference::Gpu));
    assert!(gpu.bonds.as_ref().unwrap().bound.iter().all(|&b| !b), "every bond broke");
    let travelled = (0..start.len()).map(|i| (cpu.positions[i] - start.positions[i]).length()).fold(0.0, f64::max);
    let deviation = (0..start.len()).map(|i| (cpu.positions[i] - gpu.positions[i]).length()).fold(0.0, f64::max);
    println!("GPU − CPU {deviation:.3e} after travelling up to {travelled:.3e}");
    assert!(travelled > 0.003, "the pairs barely moved: {travelled}");
    assert!(deviation <= 1e-5 * travelled, "GPU − CPU {deviation:e} > 1e-5 × {travelled:e}");
}

/// Device kinetics with contact (the step clamp of src/gpu/contact.rs): two
/// level-2 cells 0.1 µm apart pushed together by 50 pN per node at
/// dt = 1e-2 s (0.5 µm a step unclamped, five times d̂), so the clamp
/// shortens steps to s·dt; their 960 mesh edges are slip bonds with a
/// force-free rate k0 = 5/s (x_beta 0), and every node feels a field force
/// 10·t pN along x. Over 20 steps:
/// - every age the device reports, at each break and after the run, is the
///   host clock's sum of step lengths f64(s_k)·dt over the steps the bond
///   was bound, bit for bit (the device's integer f64 product and sum);
/// - bond b survives with probability exp(−k0·T), T = Σ s_k·dt the run's
///   actual length, so the break count is binomial: within 4.5σ (+1) of
///   n·(1 − exp(−k0·T)), and that mean is more than 9σ from the one with
///   whole steps (T = 20·dt), so a device that ignored the clamp fails;
/// - the kernels' time at the last force pass (step 19) is Σ_{k<19} s_k·dt:
///   ΣF_x = 324·10·t, since every other force sums to zero (pairs, closed
///   shells and opposite pushes; f32 round-off ≈ 1e-2 pN of ΣF_x ≳ 300 pN),
///   within 1e-3·t, while 19·dt is off by more than ten times that.
#[test]
fn device_kinetics_with_contact_take_the_clamped_step_lengths() {
    let top = common::two_cells_with_edges(2, 2.0, 0.1, Some("edge"));
    let ff = "particle node drag 1\nbond edge harmonic k 20 r0 0.6 kinetics slip k0 5 x_beta 0\n\
              body cell turgor k 1000 dp0 100 v0 32.4\nbody cell surface_tension gamma 100\n\
              contact cell cell contact_barrier dhat 0.1 kappa 200\n";
    let deck = "units cell\ntopology cells.top\nforcefield cells.ff\nbox x 0 20 p y -10 10 f z -10 10 f\n\
                group left id 1:162\ngroup right id 163:324\n\
                external push_left left constant_force fx 50\nexternal push_right right constant_force fx -50\n\
                external clock all field fx \"10*t\" fy 0 fz 0 e \"-10*t*x\"\n\
                temperature 0.0041\nseed 7\ntimestep 1e-2\nrun 0\n";
    let case = common::Case::new(&[("cells.top", &top), ("cells.ff", ff), ("deck.in", deck)]);
    let sim = Simulation::before_first_run(&case.plan(), RunOptions::default()).unwrap();
    assert!(sim.model.has_contact_terms());
    let settings = sim.step_settings();
    let steps = 20u64;
    let mut gpu = GpuBackend::with_device_kinetics(&context(), &sim.model, &sim.state, &sim.sim_box, &settings, &[]).unwrap();
    assert_eq!(gpu.run(0, steps), Ok(steps));
    let decided = gpu.drain_kinetics();
    let mut bonds = sim.state.bonds.clone().unwrap();
    gpu.download_bond_state(&mut bonds);
    let dt = settings.context.dt;
    let lengths: Vec<f64> = (0..steps).map(|k| gpu.step_fraction(k) * dt).collect();
    let clamped = (0..steps).filter(|&k| gpu.step_fraction(k) < 1.0).count();
    let aged = |last: u64| lengths[..=last as usize].iter().fold(0.0, |age, l| age + l);
    let mut broke_at = vec![None; bonds.len()];
    for e in &decided.events {
        assert_eq!(e.kind, EventKind::Break);
        assert_eq!(e.age.to_bits(), aged(e.step).to_bits(), "bond {} broke at step {} with age {}", e.bond, e.step, e.age);
        broke_at[e.bond] = Some(e.step);
    }
    for (b, broke) in broke_at.iter().enumerate() {
        assert_eq!(bonds.bound[b], broke.is_none(), "bond {b}");
        let expected = aged(broke.unwrap_or(steps - 1));
        assert_eq!(
            bonds.age[b].to_bits(),
            expected.to_bits(),
            "bond {b}: age {} on the device, {expected} on the host clock",
            bonds.age[b]
        );
    }
    let total: f64 = lengths.iter().sum();
    let survival = |t: f64| (-5.0 * t).exp();
    let n = bonds.len() as f64;
    let (mean, sigma) = (n * (1.0 - survival(total)), (n * survival(total) * (1.0 - survival(total))).sqrt());
    let whole = n * (1.0 - survival(steps as f64 * dt));
    let breaks = decided.events.len() as f64;
    println!("{clamped} of {steps} steps clamped, T = {total:.4e} s; {breaks} breaks of {n} bonds, expected {mean:.1} ± {sigma:.1} ({whole:.1} with whole steps)");
    assert!(clamped >= 10, "the clamp hardly acted: {clamped} steps");
    assert!((whole - mean).abs() > 9.0 * sigma, "the clamp changes the expected breaks too little for the test to tell");
    assert!((breaks - mean).abs() <= 4.5 * sigma + 1.0, "{breaks} breaks, expected {mean:.1} ± {sigma:.1}");
    let force_x: f64 = gpu.forces_and_energies().iter().map(|(f, _)| f.x).sum();
    let time = force_x / (10.0 * sim.model.len() as f64);
    let expected = lengths[..steps as usize - 1].iter().sum::<f64>();
    println!("kernel time at the last force pass {time:.6e} s, host clock {expected:.6e} s, whole steps {:.6e} s", (steps - 1) as f64 * dt);
    assert!(((steps - 1) as f64 * dt - expected).abs() > 1e-2 * expected, "the clamp shortened the run too little for the test to tell");
    assert!((time - expected).abs() <= 1e-3 * expected, "kernel time {time:e}, host clock {expected:e}");
}

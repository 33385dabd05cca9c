//! Bond kinetics decided on the device (src/gpu/kinetics.rs), on whatever
//! Vulkan adapter exists (CI: Mesa's llvmpipe). The CPU comparison of event
//! logs and ages is `kinetics_decks_give_the_same_events_on_the_gpu` in
//! tests/gpu.rs; here: no per-step read-back, the same bits twice, the
//! breaking statistics against the closed-form rates, and the models whose
//! kinetics stay on the host.

mod common;

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
    let settings = StepSettings {
        context: sim.step_context(),
        skin: sim.neighbor.skin,
        neighbor_every: sim.neighbor.every,
        neighbor_check: sim.neighbor.check,
    };
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
/// forces; the tension each break reports is the held force within f32
/// rounding (1e-4 pN of up to 28 pN).
#[test]
fn device_breaks_follow_the_catch_slip_rate() {
    let (sim, settings) = sweep();
    let steps = 1000;
    let (decided, _, _) = run_on_device(&sim, &settings, steps);
    let kt = sim.kt;
    let rate = |f: f64| 10.0 * (-f * 0.002 / kt).exp() + 0.05 * (f * 0.001 / kt).exp();
    let held = |b: usize| {
        let [i, j] = sim.model.bonds[b];
        let r = (sim.state.positions[j as usize] - sim.state.positions[i as usize]).length();
        1000.0 * (r - 0.05)
    };
    let types = sim.model.bond_types.len();
    let (mut mean, mut var, mut breaks) = (vec![0.0; types], vec![0.0; types], vec![0usize; types]);
    for b in 0..sim.model.bonds.len() {
        let q = 1.0 - (-rate(held(b)) * steps as f64 * settings.context.dt).exp();
        let t = sim.model.bond_type[b] as usize;
        mean[t] += q;
        var[t] += q * (1.0 - q);
    }
    for e in &decided.events {
        breaks[sim.model.bond_type[e.bond] as usize] += 1;
        assert!((e.force - held(e.bond)).abs() < 1e-4, "bond {}: tension {} held at {}", e.bond, e.force, held(e.bond));
    }
    for t in 0..types {
        let label = &sim.model.bond_types[t].label.text;
        println!("{label}: {} breaks, expected {:.1} ± {:.1}", breaks[t], mean[t], var[t].sqrt());
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

//! `bind` formation on the device (src/gpu/bind.rs), on whatever Vulkan
//! adapter exists (CI: Mesa's llvmpipe): the same bonds, indices and events
//! as the CPU's formation (src/kinetics_engine/formation.rs), also where the
//! device leaves a step's formation to the host; and the rules it refuses.

use crate::common;

use cellmd::gpu::kinetics::refusal;
use cellmd::gpu::DevicePreference;
use cellmd::run::{RunOptions, Simulation};

/// 800 particles of types a and b (alternating) at reproducible
/// pseudo-random places in a periodic 7 µm box.
fn scattered_particles() -> String {
    let mut seed = 0x2545_F491_4F6C_DD1Du64;
    let mut uniform = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 7.0
    };
    let mut top = String::from("[ particles ]\n");
    for i in 0..800 {
        let t = if i % 2 == 0 { "a" } else { "b" };
        top += &format!("{} {t} {:.6} {:.6} {:.6}\n", i + 1, uniform(), uniform(), uniform());
    }
    top
}

/// Runs `plan` on `device` in a fresh directory: the simulation at its end
/// and the text of its event log `log`.
fn run_logged(plan: &cellmd::deck::Plan, device: DevicePreference, log: &str) -> (Simulation, String) {
    let dir = tempfile::tempdir().unwrap();
    let options = RunOptions { output_dir: dir.path().to_path_buf(), device: Some(device), ..Default::default() };
    let sim = Simulation::execute(plan.clone(), options).unwrap();
    (sim, std::fs::read_to_string(dir.path().join(log)).unwrap())
}

/// A churning a–b network at 298 K: pairs closer than 0.5 µm bind at
/// k_on = 50/s (p ≈ 0.05 a step), up to two bonds per particle, and the soft
/// bonds slip off at 10/s, so within 1 000 steps bonds form, break and
/// rebind by the thousand (a pair that meets again rebinds its old bond, in
/// the step it broke too) and particles meet more partners than the
/// device's slots hold, so some steps' formation falls to the host. The
/// GPU's event log matches the CPU's: every event's step, time, kind, bond
/// index, type and particles, its age bit for bit, its tension and length
/// within 1e-5 (f32 geometry); the bound flags and ages at the end are the
/// same, and positions agree within 1e-5 of the distance travelled.
#[test]
fn bind_forms_the_cpus_bonds_on_the_device() {
    let ff = "particle a drag 0.005\nparticle b drag 0.005\n\
              bond link harmonic k 0.05 r0 0.3 kinetics slip k0 10 x_beta 0\n\
              bind a b link k_on 50 capture 0.5 max_bonds 2\n";
    let deck = "units cell\ntopology t.top\nforcefield f.ff\nbox x 0 7 p y 0 7 p z 0 7 p\n\
                temperature 298\ntimestep 1e-3\nseed 3\nevents churn.events.csv\nthermo 250 step forms breaks rebinds\nrun 1000\n";
    let case = common::Case::new(&[("t.top", &scattered_particles()), ("f.ff", ff), ("deck.in", deck)]);
    let plan = case.plan();
    assert_eq!(refusal(&plan.model), None);
    let (gpu, gpu_log) = run_logged(&plan, DevicePreference::Gpu, "churn.events.csv");
    let (cpu, cpu_log) = run_logged(&plan, DevicePreference::Cpu, "churn.events.csv");
    let rows = |log: &str| log.lines().skip(1).map(|l| l.split(',').map(String::from).collect::<Vec<_>>()).collect::<Vec<_>>();
    let (cpu_rows, gpu_rows) = (rows(&cpu_log), rows(&gpu_log));
    let count = |kind: &str| cpu_rows.iter().filter(|r| r[2] == kind).count();
    let (forms, breaks, rebinds) = (count("form"), count("break"), count("rebind"));
    println!(
        "{forms} forms, {breaks} breaks, {rebinds} rebinds on the CPU; {} events on the GPU, {} steps' formation on the host",
        gpu_rows.len(),
        gpu.kinetics.host_formations
    );
    assert!(forms > 1000 && breaks > 1000 && rebinds > 500, "too little churn to compare");
    assert!(gpu.kinetics.host_formations > 0, "no step's formation fell to the host: the path is not tested");
    assert_eq!(cpu_rows.len(), gpu_rows.len(), "event counts");
    for (c, g) in cpu_rows.iter().zip(&gpu_rows) {
        assert_eq!((&c[..7], &c[9]), (&g[..7], &g[9]), "event {c:?} on the CPU, {g:?} on the GPU");
        for k in [7, 8] {
            let (x, y): (f64, f64) = (c[k].parse().unwrap(), g[k].parse().unwrap());
            assert!((x - y).abs() <= 1e-5 * x.abs().max(1.0), "event {c:?} on the CPU, {g:?} on the GPU");
        }
    }
    let (cb, gb) = (cpu.state.bonds.as_ref().unwrap(), gpu.state.bonds.as_ref().unwrap());
    assert_eq!(cpu.model.bonds, gpu.model.bonds, "the formed bonds");
    assert!(cb.bound == gb.bound && cb.age == gb.age, "bound flags and ages");
    let start = Simulation::new(&plan, RunOptions::default()).state;
    let unwrap = |s: &cellmd::system::State, i: usize| plan.sim_box.unwrap(s.positions[i], s.images[i]);
    let travelled = (0..start.len()).map(|i| (unwrap(&cpu.state, i) - unwrap(&start, i)).length()).fold(0.0, f64::max);
    let deviation = (0..start.len()).map(|i| (unwrap(&cpu.state, i) - unwrap(&gpu.state, i)).length()).fold(0.0, f64::max);
    println!("GPU − CPU {deviation:.3e} after travelling up to {travelled:.3e}");
    assert!(deviation <= 1e-5 * travelled, "GPU − CPU {deviation:e} > 1e-5 × {travelled:e}");
}

/// Bonds of a `bind` type without kinetic rules count on the device too:
/// 20 a–b pairs start bound by permanent `link` bonds (max_bonds 1), so those
/// 40 particles never bind again; on both backends the other particles form
/// the same bonds in the same steps, and no particle holds two.
#[test]
fn permanent_bonds_of_a_bind_type_count_on_the_device() {
    let mut top = scattered_particles();
    top += "[ bonds ]\n";
    for m in 0..20 {
        top += &format!("link {} {}\n", 2 * m + 1, 2 * m + 2);
    }
    let ff = "particle a drag 0.005\nparticle b drag 0.005\nbond link harmonic k 0.05 r0 0.3\n\
              bind a b link k_on 50 capture 0.5 max_bonds 1\n";
    let deck = "units cell\ntopology t.top\nforcefield f.ff\nbox x 0 7 p y 0 7 p z 0 7 p\n\
                temperature 298\ntimestep 1e-3\nseed 5\nevents e.events.csv\nrun 300\n";
    let case = common::Case::new(&[("t.top", &top), ("f.ff", ff), ("deck.in", deck)]);
    let plan = case.plan();
    assert_eq!(refusal(&plan.model), None);
    let (gpu, gpu_log) = run_logged(&plan, DevicePreference::Gpu, "e.events.csv");
    let (cpu, cpu_log) = run_logged(&plan, DevicePreference::Cpu, "e.events.csv");
    let key = |log: &str| log.lines().skip(1).map(|l| l.split(',').take(7).collect::<Vec<_>>().join(",")).collect::<Vec<_>>();
    let forms = key(&cpu_log).len();
    println!("{forms} bonds formed on the CPU, {} on the GPU", key(&gpu_log).len());
    assert!(forms > 50, "only {forms} bonds formed");
    assert_eq!(key(&cpu_log), key(&gpu_log), "event logs");
    assert_eq!(cpu.model.bonds, gpu.model.bonds);
    let mut held = vec![0; gpu.model.len()];
    for &[i, j] in &gpu.model.bonds {
        held[i as usize] += 1;
        held[j as usize] += 1;
    }
    assert!(held.iter().all(|&h| h <= 1), "a particle holds two links on the GPU");
}

/// The `bind` rules the device does not take say why; the others pass.
#[test]
fn bind_rules_the_device_refuses_say_why() {
    let reason = |ff: &str| {
        let top = "[ particles ]\n1 a 0 0 0\n2 b 1 0 0\n3 a 2 0 0\n[ bonds ]\nrod 1 3\n";
        let deck = "units cell\ntopology t.top\nforcefield f.ff\nbox x -5 5 f y -5 5 f z -5 5 f\ntimestep 1e-3\nrun 0\n";
        let case = common::Case::new(&[("t.top", top), ("f.ff", ff), ("deck.in", deck)]);
        refusal(&case.plan().model)
    };
    let base =
        "particle a drag 1\nparticle b drag 1\nbond rod harmonic k 1 r0 2\nbond link harmonic k 1 r0 1 kinetics slip k0 1 x_beta 0\n";
    assert_eq!(reason(&format!("{base}bind a b link k_on 1 capture 1\n")), None);
    let nearest = reason(&format!("{base}bind a b link k_on 1 capture 1 partner nearest\n")).unwrap();
    assert!(nearest.contains("partner nearest"), "{nearest}");
    let pairs = reason(&format!("{base}bind a b link k_on 1 capture 1\npair a b wca epsilon 1 sigma 0.5\n")).unwrap();
    assert!(pairs.contains("pair terms"), "{pairs}");
    let bonded = reason(&format!("{base}bind a a link k_on 1 capture 3\n")).unwrap();
    assert!(bonded.contains("`rod` already joins"), "{bonded}");
    assert_eq!(reason(base), None);
    let plan = cellmd::deck::validate_file(std::path::Path::new("inputs/aggregate.in"), &[]).unwrap();
    assert_eq!(refusal(&plan.model), None, "aggregate.in's junctions form on the device");
}

/// With `bind` on the device the neighbour list keeps bonded pairs, so it
/// does not depend on the bonds: the churning network's breaks and rebinds
/// (in nearly every step) must not rebuild it. Its builds are then those that
/// motion asks for — here only the first (γ = 0.5 pN·s/µm: the particles
/// diffuse about 0.1 µm in the 200 steps, against a skin/2 of 0.5 µm).
/// Measured: 1 build; 167 when every step with events forced one.
#[test]
fn bonds_forming_and_breaking_do_not_rebuild_the_device_list() {
    use cellmd::gpu::{GpuBackend, GpuContext};
    let ff = "particle a drag 0.5\nparticle b drag 0.5\n\
              bond link harmonic k 0.05 r0 0.3 kinetics slip k0 10 x_beta 0\n\
              bind a b link k_on 50 capture 0.5 max_bonds 2\n";
    let deck = "units cell\ntopology t.top\nforcefield f.ff\nbox x 0 7 p y 0 7 p z 0 7 p\nneighbor skin 1\n\
                temperature 298\ntimestep 1e-3\nseed 3\nrun 0\n";
    let case = common::Case::new(&[("t.top", &scattered_particles()), ("f.ff", ff), ("deck.in", deck)]);
    let sim = Simulation::before_first_run(&case.plan(), RunOptions::default()).unwrap();
    let settings = sim.step_settings();
    let context = GpuContext::open(false).expect("a Vulkan adapter (scripts/test-all installs Mesa's)");
    let mut gpu = GpuBackend::with_device_kinetics(&context, &sim.model, &sim.state, &sim.sim_box, &settings, &[]).unwrap();
    let steps = 200;
    // A step whose formation falls to the host (a full slot list) ends the run there.
    let done = match gpu.run(0, steps) {
        Ok(done) => done,
        Err(cellmd::gpu::GpuHalt::Formation { step }) => step,
        Err(halt) => panic!("{halt:?}"),
    };
    let events = gpu.drain_kinetics().events;
    let eventful = events.iter().map(|e| e.step).collect::<std::collections::BTreeSet<_>>().len();
    println!("{done} steps, {} events in {eventful} steps, {} neighbour-list builds", events.len(), gpu.neighbor_builds());
    assert!(done >= 100 && eventful > done as usize / 2, "the network barely churned: events in {eventful} of {done} steps");
    assert!(gpu.neighbor_builds() <= 2, "{} builds", gpu.neighbor_builds());
}

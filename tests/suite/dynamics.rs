//! Overdamped dynamics and FIRE against exact results (issue: engine core, Dynamics).

use crate::common::{grid_topology, Case};

/// Free diffusion: MSD = 6·D·t with D = kT/γ, within 4 standard errors.
#[test]
fn free_diffusion_msd_is_6dt() {
    let n_side = 12; // 1728 particles
    let top = grid_topology(n_side, 1.0);
    let (kt, gamma, dt, steps) = (1.0, 2.0, 0.01, 1000u64);
    let deck = format!(
        "units lj\ntopology t.top\nforcefield f.ff\nbox x -1000 1000 f y -1000 1000 f z -1000 1000 f\n\
         temperature {kt}\ntimestep {dt}\nseed 11\nrun {steps}\n"
    );
    let case = Case::new(&[("t.top", &top), ("f.ff", &format!("particle p drag {gamma}\n")), ("deck.in", &deck)]);
    let plan = case.plan();
    let sim = case.run();
    let n = sim.model.len() as f64;
    let msd: f64 = sim
        .state
        .positions
        .iter()
        .zip(&sim.state.images)
        .zip(&plan.positions)
        .map(|((x, image), x0)| (sim.sim_box.unwrap(*x, *image) - *x0).length_squared())
        .sum::<f64>()
        / n;
    let expected = 6.0 * (kt / gamma) * dt * steps as f64;
    // |Δr|² = σ²χ²₃ per particle: relative standard error √(2/3)/√N.
    let standard_error = expected * (2.0f64 / 3.0).sqrt() / n.sqrt();
    assert!((msd - expected).abs() < 4.0 * standard_error, "MSD {msd}, expected {expected} ± {standard_error}");
}

/// Gaussian noise gives the same diffusion constant.
#[test]
fn gaussian_noise_diffuses_at_the_same_rate() {
    let top = grid_topology(10, 1.0);
    let deck = "units lj\ntopology t.top\nforcefield f.ff\nbox x -1000 1000 f y -1000 1000 f z -1000 1000 f\n\
                temperature 0.5\ntimestep 0.02\nintegrator overdamped noise gaussian\nseed 3\nrun 500\n";
    let case = Case::new(&[("t.top", &top), ("f.ff", "particle p drag 1\n"), ("deck.in", deck)]);
    let plan = case.plan();
    let sim = case.run();
    let n = sim.model.len() as f64;
    let msd: f64 = sim.state.positions.iter().zip(&plan.positions).map(|(x, x0)| (*x - *x0).length_squared()).sum::<f64>() / n;
    let expected = 6.0 * 0.5 * 0.02 * 500.0;
    let standard_error = expected * (2.0f64 / 3.0).sqrt() / n.sqrt();
    assert!((msd - expected).abs() < 4.0 * standard_error, "MSD {msd}, expected {expected} ± {standard_error}");
}

/// Two opposed walls make an exact harmonic trap E = ½k·z²: ⟨z²⟩ = kT/k.
///
/// Euler–Maruyama's stationary variance of this Ornstein–Uhlenbeck process is
/// kT/(k·(1 − k·dt/(2γ))); with k·dt/γ = 0.002 that differs from kT/k by 0.1 %.
#[test]
fn harmonic_trap_reaches_equipartition() {
    let (kt, k, gamma, dt) = (0.8, 4.0, 1.0, 5e-4);
    let n_side = 10; // 1000 independent particles
    let mut top = String::from("[ particles ]\n");
    for id in 1..=n_side * n_side * n_side {
        top += &format!("{id} p {} {} 0\n", (id % 37) as f64, (id / 37) as f64);
    }
    // Relaxation time γ/k = 0.25; equilibrate 10 τ, then sample every τ.
    let tau_steps = (gamma / k / dt) as u64;
    let mut deck = format!(
        "units lj\ntopology t.top\nforcefield f.ff\nbox x -1000 1000 f y -1000 1000 f z -1000 1000 f\n\
         external up all wall nz 1 d 0 k {k}\nexternal down all wall nz -1 d 0 k {k}\n\
         temperature {kt}\ntimestep {dt}\nseed 5\nrun {}\n",
        10 * tau_steps
    );
    let samples = 40;
    for s in 0..samples {
        deck += &format!("run {tau_steps}\nwrite_state s{s}.state\n");
    }
    let case = Case::new(&[("t.top", &top), ("f.ff", &format!("particle p drag {gamma}\n")), ("deck.in", &deck)]);
    case.run();
    let mut values = Vec::new();
    for s in 0..samples {
        let data = cellmd::output::restart::read_state(&case.path(&format!("s{s}.state"))).unwrap();
        values.extend(data.to_state().positions.iter().map(|x| x.z * x.z));
    }
    let mean = values.iter().sum::<f64>() / values.len() as f64;
    let expected = kt / (k * (1.0 - k * dt / (2.0 * gamma)));
    // z² of a Gaussian has variance 2σ⁴; samples one relaxation time apart are
    // correlated by e^(−2) in z², so inflate the error by √((1+e⁻²)/(1−e⁻²)).
    let correlation = (-2.0f64).exp();
    let standard_error = expected * 2f64.sqrt() * ((1.0 + correlation) / (1.0 - correlation)).sqrt() / (values.len() as f64).sqrt();
    assert!((mean - expected).abs() < 4.0 * standard_error, "<z²> = {mean}, expected {expected} ± {standard_error}");
}

/// kT = 0: a stretched harmonic dimer relaxes as r − r0 = (r(0) − r0)·e^(−2kt/γ).
#[test]
fn dimer_relaxation_matches_the_exact_exponential() {
    let (k, gamma, r0, stretch, dt, steps) = (3.0, 1.5, 1.0, 0.5, 1e-4, 5000u64);
    let top = format!("[ particles ]\n1 p 0 0 0\n2 p {} 0 0\n[ bonds ]\ns 1 2\n", r0 + stretch);
    let ff = format!("particle p drag {gamma}\nbond s harmonic k {k} r0 {r0}\n");
    let deck = format!("units lj\ntopology t.top\nforcefield f.ff\nbox x -10 10 f y -10 10 f z -10 10 f\ntimestep {dt}\nrun {steps}\n");
    let case = Case::new(&[("t.top", &top), ("f.ff", &ff), ("deck.in", &deck)]);
    let sim = case.run();
    let r = (sim.state.positions[1] - sim.state.positions[0]).length();
    let rate = 2.0 * k / gamma;
    let t = dt * steps as f64;
    // The Euler map is exactly (1 − rate·dt)^n …
    let discrete = r0 + stretch * (1.0 - rate * dt).powi(steps as i32);
    assert!((r - discrete).abs() < 1e-12, "r = {r}, Euler map gives {discrete}");
    // … which converges to the exponential with error ≈ n·(rate·dt)²/2 relative.
    let exact = r0 + stretch * (-rate * t).exp();
    let expected_error = stretch * (-rate * t).exp() * steps as f64 * (rate * dt).powi(2) / 2.0;
    assert!((r - exact).abs() < 1.1 * expected_error, "r = {r}, exact {exact}, allowed {expected_error}");
    // The centre of mass does not move.
    let centre = (sim.state.positions[0] + sim.state.positions[1]) / 2.0;
    assert!((centre.x - (r0 + stretch) / 2.0).abs() < 1e-14);
}

/// FIRE brings a randomly stretched network to zero force.
#[test]
fn fire_converges_a_stretched_network() {
    // A 6×6×6 cubic lattice, spacing 1.3 (rest length 1: stretched by 30 %), with
    // deterministic pseudo-random perturbations, held by nothing: it must contract.
    let n = 6;
    let index = |i: usize, j: usize, k: usize| i * n * n + j * n + k + 1;
    let mut top = String::from("[ particles ]\n");
    let mut seed = 12345u64;
    let mut jitter = || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((seed >> 33) as f64 / (1u64 << 31) as f64 - 0.5) * 0.3
    };
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                top += &format!(
                    "{} p {} {} {}\n",
                    index(i, j, k),
                    1.3 * i as f64 + jitter(),
                    1.3 * j as f64 + jitter(),
                    1.3 * k as f64 + jitter()
                );
            }
        }
    }
    top += "[ bonds ]\n";
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                if i + 1 < n {
                    top += &format!("s {} {}\n", index(i, j, k), index(i + 1, j, k));
                }
                if j + 1 < n {
                    top += &format!("s {} {}\n", index(i, j, k), index(i, j + 1, k));
                }
                if k + 1 < n {
                    top += &format!("s {} {}\n", index(i, j, k), index(i, j, k + 1));
                }
            }
        }
    }
    let ff = "particle p drag 1\nbond s harmonic k 10 r0 1\npair p p soft_repulsion k 10 sigma 0.5\n";
    let deck = "units lj\ntopology t.top\nforcefield f.ff\nbox x -20 20 f y -20 20 f z -20 20 f\nneighbor skin 0.3\ntimestep 0.01\nminimize ftol 1e-8 maxiter 20000\n";
    let case = Case::new(&[("t.top", &top), ("f.ff", ff), ("deck.in", deck)]);
    let mut sim = case.run();
    let report = sim.reports.last_minimize.clone().unwrap();
    assert!(report.converged, "{report:?}");
    // Independently recompute the forces at the final state.
    sim.apply(&cellmd::deck::Action::Run(0)).unwrap();
    let (fmax, _) = sim.backend.forces.max_force();
    assert!(fmax < 1e-8, "max |F| = {fmax}");
    // A stretched network that is free relaxes to (nearly) unstretched bonds.
    let mean_bond: f64 =
        sim.model.bonds.iter().map(|&[i, j]| (sim.state.positions[j as usize] - sim.state.positions[i as usize]).length()).sum::<f64>()
            / sim.model.bonds.len() as f64;
    assert!((mean_bond - 1.0).abs() < 0.05, "mean bond length {mean_bond}");
}

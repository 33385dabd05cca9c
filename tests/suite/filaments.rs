//! Filament mechanics of the bead–spring–bending model against continuum
//! oracles (issue 6): the worm-like-chain bending energy of an arc, and the
//! Euler buckling load from the linear stability of the engine's own forces.

use crate::common::{self, Case};
use cellmd::backend::{CpuBackend, Forces};
use cellmd::deck::Plan;
use cellmd::system::State;
use faer::{Mat, Side};
use glam::DVec3;

/// A filament of `segments` segments given by its bead positions, with
/// bending modulus `kappa` (pN·µm²) and bonds of stiffness `k` (pN/µm).
fn filament_case(beads: &[DVec3], segment: f64, kappa: f64, k: f64) -> Case {
    let mut top = String::from("[ particles ]\n");
    for (i, x) in beads.iter().enumerate() {
        top += &format!("{} bead {} {} {}\n", i + 1, x.x, x.y, x.z);
    }
    top += "[ bonds ]\n";
    for i in 1..beads.len() {
        top += &format!("rod {i} {}\n", i + 1);
    }
    top += "[ angles ]\n";
    for i in 1..beads.len() - 1 {
        top += &format!("bend {i} {} {}\n", i + 1, i + 2);
    }
    let ff = format!("particle bead drag 0.01\nbond rod harmonic k {k} r0 {segment}\nangle bend wlc_bending kappa {kappa} l0 {segment}\n");
    let deck = "topology t.top\nforcefield f.ff\nbox x -100 100 f y -100 100 f z -100 100 f\n";
    Case::new(&[("t.top", &top), ("f.ff", &ff), ("deck.in", deck)])
}

fn forces_at(plan: &Plan, positions: &[DVec3]) -> Forces {
    let state = State::new(positions.to_vec());
    let mut backend = CpuBackend::new(&plan.model, &state, &plan.sim_box, 0.0).unwrap();
    let mut forces = Forces::default();
    backend.compute(&plan.model, &state, &plan.sim_box, &mut forces);
    forces
}

/// Beads on a circle of radius R, one chord `segment` apart.
fn arc(segments: usize, segment: f64, radius: f64) -> Vec<DVec3> {
    let phi = 2.0 * (segment / (2.0 * radius)).asin();
    (0..=segments).map(|i| radius * DVec3::new((i as f64 * phi).cos(), (i as f64 * phi).sin(), 0.0)).collect()
}

/// The bending energy of a quarter circle approaches κL/2R²: p segments have
/// p − 1 joints, so the discrete energy times p/(p − 1) (the end
/// correction) must be within 0.5 % of the continuum from p = 8 on.
#[test]
fn wlc_bending_energy_of_an_arc_is_kappa_l_over_2r2() {
    let (kappa, radius) = (0.07, 2.0);
    let length = std::f64::consts::FRAC_PI_2 * radius;
    println!("| segments p | E·p/(p−1) / (κL/2R²) − 1 |");
    let mut previous = f64::INFINITY;
    for p in [4, 8, 16, 32, 64] {
        let phi = length / radius / p as f64;
        let segment = 2.0 * radius * (phi / 2.0).sin();
        let beads = arc(p, segment, radius);
        let case = filament_case(&beads, segment, kappa, 1000.0);
        let plan = case.plan();
        let forces = forces_at(&plan, &beads);
        let bending = forces.energy_by_interaction[cellmd::interactions::REGISTRY.iter().position(|i| i.name() == "wlc_bending").unwrap()];
        let continuum = kappa * length / (2.0 * radius * radius);
        let error = bending * p as f64 / (p as f64 - 1.0) / continuum - 1.0;
        println!("| {p} | {error:+.3e} |");
        if p >= 8 {
            assert!(error.abs() < 0.005, "p = {p}: relative error {error}");
        }
        assert!(error.abs() < previous, "p = {p}: the error {error} does not fall with refinement");
        previous = error.abs();
    }
}

/// The smallest eigenvalue of the stiffness of a straight, pinned–pinned
/// filament compressed by P at its ends (bead 0 pinned, the last bead free
/// only along the axis), from central differences of the engine's forces
/// at the compressed equilibrium.
fn smallest_stiffness_eigenvalue(segments: usize, length: f64, kappa: f64, k: f64, load: f64) -> f64 {
    let segment = length / segments as f64;
    // Straight equilibrium: every bond carries the compression P.
    let compressed = segment - load / k;
    let beads: Vec<DVec3> = (0..=segments).map(|i| DVec3::new(i as f64 * compressed, 0.0, 0.0)).collect();
    let case = filament_case(&beads, segment, kappa, k);
    let plan = case.plan();
    // Free coordinates: x of the last bead, and x, y, z of the interior beads.
    let mut dofs: Vec<(usize, usize)> = Vec::new();
    for bead in 1..segments {
        for axis in 0..3 {
            dofs.push((bead, axis));
        }
    }
    dofs.push((segments, 0));
    let h = 1e-6 * segment;
    let n = dofs.len();
    let mut hessian = Mat::<f64>::zeros(n, n);
    for (c, &(bead, axis)) in dofs.iter().enumerate() {
        let mut plus = beads.clone();
        let mut minus = beads.clone();
        plus[bead][axis] += h;
        minus[bead][axis] -= h;
        let (fp, fm) = (forces_at(&plan, &plus), forces_at(&plan, &minus));
        for (r, &(b, a)) in dofs.iter().enumerate() {
            // The end loads are constant forces: they add nothing to the Hessian.
            hessian[(r, c)] = -(fp.forces[b][a] - fm.forces[b][a]) / (2.0 * h);
        }
    }
    let symmetric = Mat::<f64>::from_fn(n, n, |r, c| 0.5 * (hessian[(r, c)] + hessian[(c, r)]));
    let eigen = symmetric.self_adjoint_eigen(Side::Lower).unwrap();
    eigen.S().column_vector()[0]
}

/// The load at which the straight filament loses stability, by bisection.
fn critical_load(segments: usize, length: f64, kappa: f64, k: f64) -> f64 {
    let euler = std::f64::consts::PI.powi(2) * kappa / (length * length);
    let (mut stable, mut unstable) = (0.5 * euler, 1.5 * euler);
    assert!(smallest_stiffness_eigenvalue(segments, length, kappa, k, stable) > 0.0);
    assert!(smallest_stiffness_eigenvalue(segments, length, kappa, k, unstable) < 0.0);
    for _ in 0..40 {
        let mid = 0.5 * (stable + unstable);
        if smallest_stiffness_eigenvalue(segments, length, kappa, k, mid) > 0.0 {
            stable = mid;
        } else {
            unstable = mid;
        }
    }
    0.5 * (stable + unstable)
}

/// Euler buckling: the discrete critical load converges to π²κ/L² as the
/// segmentation refines, for a microtubule (κ = 20 pN·µm², L = 10 µm) and
/// actin (Lp = 17 µm, κ = 17 µm·kT(298 K), L = 2 µm), with bonds stiff
/// enough (k·L²/κ ≥ 1e5) that extensibility shifts the load by < 1e-4.
#[test]
fn euler_buckling_load_converges_to_pi2_kappa_over_l2() {
    let kt = 4.114e-3;
    println!("| filament | segments | P_c (pN) | π²κ/L² (pN) | P_c/(π²κ/L²) − 1 |");
    for (name, kappa, length) in [("microtubule", 20.0, 10.0), ("actin", 17.0 * kt, 2.0)] {
        let euler = std::f64::consts::PI.powi(2) * kappa / (length * length);
        let k = 1e5 * kappa / (length * length) * 10.0;
        let mut errors = Vec::new();
        for segments in [4, 8, 16, 32] {
            let load = critical_load(segments, length, kappa, k);
            let error = load / euler - 1.0;
            println!("| {name} | {segments} | {load:.6} | {euler:.6} | {error:+.3e} |");
            errors.push(error.abs());
        }
        // Second-order convergence of the discrete bending stencil: the error
        // falls about fourfold per doubling, and is below 0.1 % at 32 segments.
        for w in errors.windows(2) {
            assert!((3.0..5.0).contains(&(w[0] / w[1])), "{name}: errors {errors:?} do not fall fourfold per doubling");
        }
        assert!(errors[3] < 1e-3, "{name}: {:e} off π²κ/L² at 32 segments", errors[3]);
    }
}

/// Thermal filaments (kT = 1, LJ units): 1000 chains of 4 segments with
/// ℓ = 1, κ = 4 (Lp = 4 = L) and bonds k = 200, started from the exact
/// equilibrium ensemble (bond lengths 1) and run for 0.8 relaxation times
/// of the slowest bending mode (the joint angles relax in ~1 % of that). The
/// time step 5e-4 keeps Euler–Maruyama's O(dt) bias of the stiffest bending
/// modes (variance × 1/(1 − k·dt/2γ)) near 1.5 % of 1 − ⟨cos θ⟩, about one
/// standard error: at dt = 1.5e-3 the bias was measured at 4 % (2.3σ). The bending energy (κ/ℓ)(1 − cos θ) depends on the
/// angles only, so each joint's cos θ has the density ∝ exp(a·cos θ),
/// a = κ/(ℓ·kT): ⟨cos θ⟩ = coth a − 1/a, and the tangents at lag k correlate
/// as ⟨cos θ⟩^k (the exp(−s/Lp) decay of the chain); the mean-square end-to-end distance
/// of the discrete chain is N⟨ℓ²⟩ + 2⟨ℓ⟩²Σ_{k≥1}(N − k)⟨cos θ⟩^k. Checks the
/// noise amplitude, the bending law and the integrator together.
#[test]
fn thermal_filaments_keep_the_worm_like_chain_statistics() {
    let (chains, segments, kappa, k_bond) = (1000, 4, 4.0f64, 200.0);
    let a = kappa; // κ/(ℓ·kT) with ℓ = kT = 1
    let top = common::worm_like_chains(chains, segments, a, 0x2545F4914F6CDD1D);
    let ff = format!("particle bead drag 1\nbond rod harmonic k {k_bond} r0 1\nangle bend wlc_bending kappa {kappa} l0 1\n");
    let deck = "units lj\ntopology t.top\nforcefield f.ff\nbox x -10 110 f y -10 110 f z -10 110 f\n\
                temperature 1\nseed 11\ntimestep 0.0005\nrun 8000\n";
    let case = Case::new(&[("t.top", &top), ("f.ff", &ff), ("deck.in", deck)]);
    let options = cellmd::run::RunOptions { output_dir: case.output_dir().to_path_buf(), ..Default::default() };
    let sim = cellmd::run::Simulation::execute(case.plan(), options).unwrap();
    let x = &sim.state.positions;
    let per = segments + 1;
    let (mut cos_sum, mut joints, mut r2, mut l1, mut l2) = (0.0, 0.0, 0.0, 0.0, 0.0);
    // Tangent correlation ⟨t_i·t_{i+k}⟩ at every lag k (sum, sum of squares, count).
    let mut lags = vec![(0.0, 0.0, 0.0); segments];
    for c in 0..chains {
        let b: Vec<DVec3> = (0..segments).map(|s| x[c * per + s + 1] - x[c * per + s]).collect();
        for w in b.windows(2) {
            cos_sum += w[0].normalize().dot(w[1].normalize());
            joints += 1.0;
        }
        for k in 1..segments {
            for i in 0..segments - k {
                let c = b[i].normalize().dot(b[i + k].normalize());
                lags[k].0 += c;
                lags[k].1 += c * c;
                lags[k].2 += 1.0;
            }
        }
        r2 += (x[c * per + segments] - x[c * per]).length_squared();
        l1 += b.iter().map(|v| v.length()).sum::<f64>();
        l2 += b.iter().map(|v| v.length_squared()).sum::<f64>();
    }
    let mean_cos = cos_sum / joints;
    let exact_cos = 1.0 / a.tanh() - 1.0 / a;
    let (mean_l, mean_l2) = (l1 / (chains * segments) as f64, l2 / (chains * segments) as f64);
    let n = segments as f64;
    let exact_r2 = n * mean_l2 + 2.0 * mean_l * mean_l * (1..segments).map(|k| (n - k as f64) * exact_cos.powi(k as i32)).sum::<f64>();
    let r2 = r2 / chains as f64;
    // Standard errors: Var(cos θ) = 1 − 2⟨cos⟩/a − ⟨cos⟩², over the joints; ⟨R²⟩ from its sample spread is ≈ 1.5 %.
    let sigma_cos = ((1.0 - 2.0 * exact_cos / a - exact_cos * exact_cos) / joints).sqrt();
    println!("⟨cos θ⟩ = {mean_cos:.5} (exact {exact_cos:.5}, σ {sigma_cos:.5}); ⟨R²⟩ = {r2:.4} (exact {exact_r2:.4})");
    assert!((mean_cos - exact_cos).abs() < 4.0 * sigma_cos, "⟨cos θ⟩ {mean_cos} vs {exact_cos} ± {sigma_cos}");
    assert!((r2 / exact_r2 - 1.0).abs() < 0.05, "⟨R²⟩ {r2} vs {exact_r2}");
    // The tangents decorrelate as ⟨cos θ⟩^k = exp(−kℓ/Lp), Lp = −ℓ/ln⟨cos θ⟩
    // (→ κ/kT for stiff chains), at every lag; standard error from the sample spread.
    for (k, &(sum, squares, count)) in lags.iter().enumerate().skip(1) {
        let mean = sum / count;
        let sigma = ((squares / count - mean * mean) / count).sqrt();
        let exact = exact_cos.powi(k as i32);
        println!("lag {k}: ⟨t·t⟩ = {mean:.5} (exact {exact:.5}, σ {sigma:.5})");
        assert!((mean - exact).abs() < 4.0 * sigma, "lag {k}: ⟨t_i·t_i+k⟩ {mean} vs {exact} ± {sigma}");
    }
}

//! The CPU backend (neighbour list, images, exclusions, gather) against a
//! brute-force O(N²) evaluation written independently here.

use crate::common::{random_case, Case};
use cellmd::backend::{CpuBackend, Forces};
use cellmd::deck::validate_file;
use cellmd::interactions::{lookup, Law, REGISTRY};
use cellmd::system::State;
use glam::DVec3;

fn brute_force(case: &Case) -> (Forces, Vec<DVec3>) {
    let plan = validate_file(&case.path("deck.in"), &[]).unwrap();
    let model = &plan.model;
    let sim_box = plan.sim_box;
    let mut state = State::new(plan.positions.clone());
    for (x, im) in state.positions.iter_mut().zip(state.images.iter_mut()) {
        sim_box.wrap(x, im);
    }
    let x = &state.positions;
    let n = model.len();
    let mut forces = vec![DVec3::ZERO; n];
    let mut energy = vec![0.0; REGISTRY.len()];
    let mut virial = [0.0; 6];
    let excluded = model.excluded_pairs(None);
    let mut add_virial = |r: DVec3, f: DVec3| {
        let w = [r.x * f.x, r.y * f.y, r.z * f.z, r.x * f.y, r.x * f.z, r.y * f.z];
        for k in 0..6 {
            virial[k] += w[k];
        }
    };
    let reg = |name: &str| REGISTRY.iter().position(|i| i.name() == name).unwrap();
    for i in 0..n {
        for j in i + 1..n {
            if excluded.contains(&(i as u32, j as u32)) {
                continue;
            }
            let d = sim_box.minimum_image(x[j] - x[i]);
            let r = d.length();
            for &rule in model.pair_rules_between(model.types[i], model.types[j]) {
                let term = &model.pair_rules[rule as usize];
                let Law::Radial { eval, range, .. } = term.interaction.law() else { unreachable!() };
                if r < range(&term.params) {
                    let out = eval(&term.params, r);
                    let f_i = out.de_dr * d / r;
                    forces[i] += f_i;
                    forces[j] -= f_i;
                    energy[reg(term.interaction.name())] += out.energy;
                    add_virial(-d, f_i);
                }
            }
        }
    }
    let harmonic = lookup("harmonic").unwrap();
    for (b, &[i, j]) in model.bonds.iter().enumerate() {
        let term = &model.bond_types[model.bond_type[b] as usize];
        let Law::Radial { eval, .. } = harmonic.law() else { unreachable!() };
        let d = sim_box.minimum_image(x[j as usize] - x[i as usize]);
        let out = eval(&term.params, d.length());
        let f_j = -out.de_dr * d / d.length();
        forces[j as usize] += f_j;
        forces[i as usize] -= f_j;
        energy[reg("harmonic")] += out.energy;
        add_virial(d, f_j);
    }
    for (a, &[i, j, k]) in model.angles.iter().enumerate() {
        let term = &model.angle_types[model.angle_type[a] as usize];
        let Law::ThreeBody(eval) = term.interaction.law() else { unreachable!() };
        let xj = x[j as usize];
        let xi = xj + sim_box.minimum_image(x[i as usize] - xj);
        let xk = xj + sim_box.minimum_image(x[k as usize] - xj);
        let out = eval(&term.params, [xi, xj, xk]);
        for (p, f) in [i, j, k].iter().zip(out.forces) {
            forces[*p as usize] += f;
        }
        energy[reg("cosine_angle")] += out.energy;
        add_virial(xi - xj, out.forces[0]);
        add_virial(xk - xj, out.forces[2]);
    }
    (Forces { forces, energy_by_interaction: energy, virial }, state.positions.clone())
}

fn compare(periodic: bool, special: &str) {
    let case = random_case(periodic, special);
    let plan = validate_file(&case.path("deck.in"), &[]).unwrap();
    let (expected, positions) = brute_force(&case);
    let mut state = State::new(plan.positions.clone());
    for (x, im) in state.positions.iter_mut().zip(state.images.iter_mut()) {
        plan.sim_box.wrap(x, im);
    }
    assert_eq!(state.positions, positions);
    let mut backend = CpuBackend::new(&plan.model, &state, &plan.sim_box, 0.4).unwrap();
    let mut got = Forces::default();
    backend.compute(&plan.model, &state, &plan.sim_box, &mut got);
    let scale = expected.forces.iter().map(|f| f.length()).fold(0.0, f64::max);
    for (i, (a, b)) in got.forces.iter().zip(&expected.forces).enumerate() {
        assert!((*a - *b).length() <= 1e-12 * scale, "particle {i}: {a} vs {b}");
    }
    for (k, (a, b)) in got.energy_by_interaction.iter().zip(&expected.energy_by_interaction).enumerate() {
        assert!((a - b).abs() <= 1e-12 * b.abs().max(1.0), "{}: {a} vs {b}", REGISTRY[k].name());
    }
    for k in 0..6 {
        assert!((got.virial[k] - expected.virial[k]).abs() <= 1e-11 * expected.virial[k].abs().max(1.0), "virial {k}");
    }
    // The system is dense enough that every pair interaction contributes.
    for name in ["lj", "soft", "soft_repulsion", "harmonic", "cosine_angle"] {
        let k = REGISTRY.iter().position(|i| i.name() == name).unwrap();
        assert!(expected.energy_by_interaction[k] != 0.0, "{name} never acted");
    }
}

#[test]
fn periodic_random_system_matches_brute_force() {
    compare(true, "");
}

#[test]
fn fixed_box_random_system_matches_brute_force() {
    compare(false, "");
}

#[test]
fn special_bonds_exclusions_match_brute_force() {
    compare(true, "special_bonds 0 0 0\n");
    compare(true, "special_bonds 1 1 1\n");
}

#[test]
fn forces_only_pass_gives_the_same_bits_and_leaves_energies() {
    let case = random_case(true, "");
    let plan = validate_file(&case.path("deck.in"), &[]).unwrap();
    let mut state = State::new(plan.positions.clone());
    for (x, im) in state.positions.iter_mut().zip(state.images.iter_mut()) {
        plan.sim_box.wrap(x, im);
    }
    let mut backend = CpuBackend::new(&plan.model, &state, &plan.sim_box, 0.4).unwrap();
    let mut full = Forces::default();
    backend.compute(&plan.model, &state, &plan.sim_box, &mut full);
    let mut forces_only = full.clone();
    forces_only.forces.iter_mut().for_each(|f| *f = DVec3::NAN);
    backend.compute_forces(&plan.model, &state, &plan.sim_box, &mut forces_only);
    let bits = |f: &Forces| f.forces.iter().map(|v| v.to_array().map(f64::to_bits)).collect::<Vec<_>>();
    assert_eq!(bits(&full), bits(&forces_only));
    assert_eq!(full.energy_by_interaction, forces_only.energy_by_interaction);
    assert_eq!(full.virial, forces_only.virial);
}

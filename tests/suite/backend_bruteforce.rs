//! The CPU backend (neighbour list, images, exclusions, gather) against a
//! brute-force O(N²) evaluation written independently here.

use crate::common::{random_case, Case};
use cellmd::backend::{CpuBackend, Forces};
use cellmd::deck::validate_file;
use cellmd::interactions::{lookup, Law, REGISTRY};
use cellmd::system::{Model, State};
use glam::DVec3;

/// Adds the pair terms of particles i and j at separation d = x_j − x_i
/// (one image of the pair): the forces in full, the energy (per
/// interaction) and the virial r_ij ⊗ f_ij times `weight`.
fn add_pair_terms(model: &Model, (i, j): (usize, usize), d: DVec3, weight: f64, out: &mut Forces) {
    let r = d.length();
    for &rule in model.pair_rules_between(model.types[i], model.types[j]) {
        let term = &model.pair_rules[rule as usize];
        let Law::Radial { eval, range, .. } = term.interaction.law() else { unreachable!() };
        if r < range(&term.params) {
            let e = eval(&term.params, r);
            let f_i = e.de_dr * d / r;
            out.forces[i] += f_i;
            out.forces[j] -= f_i;
            let column = REGISTRY.iter().position(|k| k.name() == term.interaction.name()).unwrap();
            out.energy_by_interaction[column] += weight * e.energy;
            let w = [-d.x * f_i.x, -d.y * f_i.y, -d.z * f_i.z, -d.x * f_i.y, -d.x * f_i.z, -d.y * f_i.z];
            for (v, w) in out.virial.iter_mut().zip(w) {
                *v += weight * w;
            }
        }
    }
}

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
    let mut out = Forces { forces: vec![DVec3::ZERO; n], energy_by_interaction: vec![0.0; REGISTRY.len()], virial: [0.0; 6] };
    let excluded = model.excluded_pairs(None);
    for i in 0..n {
        for j in i + 1..n {
            if !excluded.contains(&(i as u32, j as u32)) {
                add_pair_terms(model, (i, j), sim_box.minimum_image(x[j] - x[i]), 1.0, &mut out);
            }
        }
    }
    let Forces { mut forces, energy_by_interaction: mut energy, mut virial } = out;
    let mut add_virial = |r: DVec3, f: DVec3| {
        let w = [r.x * f.x, r.y * f.y, r.z * f.z, r.x * f.y, r.x * f.z, r.y * f.z];
        for k in 0..6 {
            virial[k] += w[k];
        }
    };
    let reg = |name: &str| REGISTRY.iter().position(|i| i.name() == name).unwrap();
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

/// A box with periodic edges shorter than twice the cutoff (1.1, 1.7 and
/// 2.3 against lj's 2.5, soft's 1.2 and the 0.4 skin): the backend's pair
/// energies, forces and virial against a brute-force sum over a wide block
/// of images (every j + s·L within the cutoff, i's own images counted ½
/// each, a bonded pair excluded at its minimum image only).
#[test]
fn small_periodic_box_matches_brute_force_over_images() {
    let lengths = DVec3::new(1.1, 1.7, 2.3);
    let mut next = crate::common::uniform(0x51CE);
    let n = 12;
    let mut top = String::from("[ particles ]\n");
    for id in 1..=n {
        let ty = if id % 3 == 0 { "b" } else { "a" };
        top += &format!("{id} {ty} {} {} {}\n", next() * lengths.x, next() * lengths.y, next() * lengths.z);
    }
    top += "[ bonds ]\ns 1 2\ns 2 3\ns 4 5\n";
    let ff = "particle a drag 1\nparticle b drag 2\nbond s harmonic k 2 r0 0.5\n\
              pair a a lj epsilon 0.01 sigma 0.25 rc 2.5\npair a b soft A 0.3 rc 1.2\npair b b lj epsilon 0.02 sigma 0.2 rc 2.0\n";
    let deck = format!(
        "units lj\ntopology t.top\nforcefield f.ff\nbox x 0 {} p y 0 {} p z 0 {} p\nneighbor skin 0.4\n",
        lengths.x, lengths.y, lengths.z
    );
    let case = Case::new(&[("t.top", &top), ("f.ff", ff), ("deck.in", &deck)]);
    let plan = validate_file(&case.path("deck.in"), &[]).unwrap();
    let model = &plan.model;
    let state = State::new(plan.positions.clone());
    let x = &state.positions;
    let excluded = model.excluded_pairs(None);
    let mut want = Forces { forces: vec![DVec3::ZERO; n], energy_by_interaction: vec![0.0; REGISTRY.len()], virial: [0.0; 6] };
    let k = 4;
    for i in 0..n {
        for j in i..n {
            let d0 = plan.sim_box.minimum_image(x[j] - x[i]);
            let is_excluded = excluded.contains(&(i as u32, j as u32));
            for sx in -k..=k {
                for sy in -k..=k {
                    for sz in -k..=k {
                        let s = DVec3::new(sx as f64, sy as f64, sz as f64);
                        if (i == j || is_excluded) && s == DVec3::ZERO {
                            continue;
                        }
                        let weight = if i == j { 0.5 } else { 1.0 };
                        add_pair_terms(model, (i, j), d0 + s * lengths, weight, &mut want);
                    }
                }
            }
        }
    }
    let Forces { forces, energy_by_interaction, virial } = want;
    let energy: f64 = energy_by_interaction.iter().sum();
    let mut backend = CpuBackend::new(model, &state, &plan.sim_box, 0.4).unwrap();
    let mut got = Forces::default();
    backend.compute(model, &state, &plan.sim_box, &mut got);
    let pair_energy: f64 =
        ["lj", "soft"].iter().map(|name| got.energy_by_interaction[REGISTRY.iter().position(|i| i.name() == *name).unwrap()]).sum();
    assert!(energy.abs() > 0.1, "energy {energy}: the test needs pairs");
    assert!((pair_energy - energy).abs() <= 1e-12 * energy.abs(), "pair energy {pair_energy} vs {energy}");
    // Bond forces and virial: the backend's minus the pairs' brute force leaves the bonds',
    // which a fixed large box gives alone.
    let bonds_only = |with_pairs: &str| {
        let ff = "particle a drag 1\nparticle b drag 2\nbond s harmonic k 2 r0 0.5\n".to_string() + with_pairs;
        let c = Case::new(&[("t.top", &top), ("f.ff", &ff), ("deck.in", &deck)]);
        let p = validate_file(&c.path("deck.in"), &[]).unwrap();
        let mut b = CpuBackend::new(&p.model, &state, &p.sim_box, 0.4).unwrap();
        let mut f = Forces::default();
        b.compute(&p.model, &state, &p.sim_box, &mut f);
        f
    };
    let bonds = bonds_only("");
    let scale = forces.iter().map(|f| f.length()).fold(0.0, f64::max);
    for (i, want) in forces.iter().enumerate() {
        let ours = got.forces[i] - bonds.forces[i];
        assert!((ours - *want).length() <= 1e-12 * scale, "particle {i}: {ours} vs {want}");
    }
    let vscale = virial.iter().map(|v| v.abs()).fold(0.0, f64::max);
    for (c, want) in virial.iter().enumerate() {
        let ours = got.virial[c] - bonds.virial[c];
        assert!((ours - want).abs() <= 1e-12 * vscale, "virial {c}: {ours} vs {want}");
    }
}

//! Contractile network stress against connectivity (seed 000, checkpoint
//! 12): `inputs/contractile_lattice.in` on diluted triangular lattices of
//! radius 8 a (about 230 nodes) whose every link is contractile (rest length
//! (1 − ε)·a, ε = 1 %), clamped at the rim and relaxed at T = 0.
//!
//! Oracles: (1) the full lattice (p = 1) cannot move — every free node has
//! six equal tensions k·ε·a — so its stress is exactly
//! σ_full = n_bonds·k·ε/(√3·N); (2) rigidity percolation (Jacobs & Thorpe,
//! Phys. Rev. Lett. 75, 4051 (1995): p_c = 0.660, z_c = 3.96 for central
//! forces on the triangular lattice): a floppy network lets its links
//! shorten and holds almost no stress, a rigid one holds a finite share of
//! the affine σ. Seed 000 reports the floppy→rigid rise for the elastic
//! modulus; here it is the clamp's contractile stress that rises, from ≈ 0
//! below z_c to the affine value at z = 6.
//!
//! `cargo test --test suite contractile_lattice:: -- --nocapture` prints the table;
//! studies/contractile_lattice/ sweeps larger discs and more seeds.

use crate::common;

use cellmd::build::{Common, LatticeArgs};
use cellmd::deck::ThermoColumn;

const DECK: &str = "inputs/contractile_lattice.in";
const STRAIN: f64 = 0.01;
/// The force field's link stiffness (pN/µm).
const K: f64 = 100.0;

/// One relaxed disc: its stress and the full lattice's (same disc, p = 1).
struct Point {
    z: f64,
    sigma: f64,
}

/// Relaxes the disc of bond probability `p` and returns z (bonds per free
/// node), σ (pN/µm) and the bond and node counts.
fn relax(p: f64, seed: u64) -> (Point, usize, usize) {
    let args = LatticeArgs {
        radius: 8.0,
        spacing: 1.0,
        bond_probability: p,
        common: Common { seed, output: "lattice.top".into(), rest_from_geometry: false },
        ..LatticeArgs::default()
    };
    let (mut sim, built) = common::run_deck_on_lattice(DECK, &args, &[("strain", STRAIN.to_string())]);
    let volume = sim.sim_box.lengths().x * sim.sim_box.lengths().y * sim.sim_box.lengths().z;
    let trace = sim.thermo_value(&ThermoColumn::Pressure(0)).unwrap() + sim.thermo_value(&ThermoColumn::Pressure(1)).unwrap();
    let area = built.particles as f64 * 3f64.sqrt() / 2.0;
    let z = connectivity(&built.summary());
    (Point { z, sigma: -trace * volume / (2.0 * area) }, built.bonds, built.particles)
}

/// The builder's printed connectivity (bonds per free node).
fn connectivity(summary: &str) -> f64 {
    let tail = summary.split("connectivity z = ").nth(1).unwrap();
    tail.split_whitespace().next().unwrap().parse().unwrap()
}

#[test]
fn contractile_stress_rises_from_floppy_to_rigid_and_is_exact_on_the_full_lattice() {
    let (full, bonds, nodes) = relax(1.0, 1);
    let exact = bonds as f64 * K * STRAIN / (3f64.sqrt() * nodes as f64);
    println!("full lattice: z = {:.3}, σ = {:.9e} pN/µm, exact {exact:.9e}", full.z, full.sigma);
    assert!((full.sigma / exact - 1.0).abs() < 1e-9, "σ = {}, exact {exact}", full.sigma);

    let probabilities = [0.5, 0.6, 0.7, 0.8, 0.9];
    let seeds = [1, 2, 3];
    println!("| p | z (mean of {} seeds) | σ/σ_full per seed | mean |", seeds.len());
    let mut means = Vec::new();
    for p in probabilities {
        let points: Vec<Point> = seeds.iter().map(|&s| relax(p, s).0).collect();
        let ratios: Vec<f64> = points.iter().map(|q| q.sigma / full.sigma).collect();
        let z = points.iter().map(|q| q.z).sum::<f64>() / points.len() as f64;
        let mean = ratios.iter().sum::<f64>() / ratios.len() as f64;
        println!("| {p} | {z:.3} | {} | {mean:.4} |", ratios.iter().map(|r| format!("{r:.4}")).collect::<Vec<_>>().join(" "));
        means.push((z, mean));
    }
    for w in means.windows(2) {
        assert!(w[1].1 > w[0].1, "the mean stress falls with connectivity: {means:?}");
    }
    let (floppy, rigid) = (means[0], means[means.len() - 1]);
    assert!(floppy.0 < 3.96 && floppy.1 < 0.05, "below z_c the network holds {:.3} of σ_full", floppy.1);
    assert!(rigid.0 > 3.96 && rigid.1 > 0.5, "above z_c the network holds only {:.3} of σ_full", rigid.1);
}

//! Measurements (issue #6): per-particle stress, per-bond tension, method of
//! planes, cortical tension, filament statistics — each against an exact
//! identity or an analytic case.
//!
//! Print the Young–Laplace table with
//! `cargo test --release --test suite measure:: -- --nocapture`.

use std::f64::consts::PI;

use crate::common::{random_case, Case};
use cellmd::build::{icosphere_cell, IcosphereCell};
use cellmd::deck::ThermoColumn;
use cellmd::measure::von_mises;
use cellmd::run::Simulation;
use glam::DVec3;

/// Σ_i W_i over particles.
fn total(w: &[[f64; 6]]) -> [f64; 6] {
    let mut t = [0.0; 6];
    for wi in w {
        (0..6).for_each(|k| t[k] += wi[k]);
    }
    t
}

/// Asserts Σ_i W_i equals the thermo virial to 1e-12 of the per-particle magnitudes.
fn assert_virial_sums(sim: &mut Simulation) {
    let w = sim.particle_virial().unwrap();
    let global = sim.current_forces().unwrap().virial;
    let sum = total(&w);
    let scale: f64 = w.iter().flatten().map(|v| v.abs()).sum();
    assert!(scale > 0.0, "no virial at all: the check would be empty");
    for k in 0..6 {
        assert!((sum[k] - global[k]).abs() <= 1e-12 * scale, "component {k}: Σ W_i = {:e}, thermo W = {:e}", sum[k], global[k]);
    }
}

fn with_timestep(case: Case) -> Case {
    let deck = std::fs::read_to_string(case.path("deck.in")).unwrap();
    std::fs::write(case.path("deck.in"), deck + "timestep 0.001\n").unwrap();
    case
}

#[test]
fn per_particle_virial_sums_to_the_thermo_virial() {
    for periodic in [false, true] {
        // 400 particles with bonds, angles and three pair rules.
        let mut sim = with_timestep(random_case(periodic, "")).run();
        assert!(sim.current_forces().unwrap().virial.iter().all(|w| *w != 0.0));
        assert_virial_sums(&mut sim);
    }
}

/// Two particles, one harmonic bond along û = (1, 2, 2)/3 stretched to r.
fn dimer_case(r: f64, extra: &str) -> Case {
    let u = DVec3::new(1.0, 2.0, 2.0) / 3.0;
    let b = DVec3::new(1.0, 1.5, 2.0) + r * u;
    let top = format!("[ particles ]\n1 p 1 1.5 2\n2 p {:?} {:?} {:?}\n[ bonds ]\ns 1 2\n", b.x, b.y, b.z);
    let ff = "particle p drag 1\nbond s harmonic k 10 r0 1\n";
    let deck = format!("units cell\ntopology t.top\nforcefield f.ff\nbox x -10 10 f y -10 10 f z -10 10 f\ntimestep 0.001\n{extra}");
    Case::new(&[("t.top", &top), ("f.ff", ff), ("deck.in", &deck)])
}

/// Per-atom lines of the single frame of a LAMMPS dump: (header names, rows).
fn read_dump(path: &std::path::Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let header: Vec<String> = lines[8].strip_prefix("ITEM: ATOMS ").unwrap().split(' ').map(String::from).collect();
    let rows = lines[9..].iter().map(|l| l.split(' ').map(|c| c.parse().unwrap()).collect()).collect();
    (header, rows)
}

/// A bond of tension T = k(r − r0) along û: W_i = −½·r·T·û⊗û on each end;
/// the dump's stress is its negative (LAMMPS sign) and von Mises = ½·r·T.
#[test]
fn a_stretched_bond_gives_the_analytic_stress_in_the_dump() {
    let (r, k, r0) = (1.3, 10.0, 1.0);
    let t = k * (r - r0);
    let u = [1.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0];
    let pairs = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)];
    let case = dimer_case(r, "dump s every 1 lammps s.lammpstrj columns id sxx syy szz sxy sxz syz vonmises wxx\nrun 0\n");
    let mut sim = case.run();
    let w = sim.particle_virial().unwrap();
    for wi in &w {
        for (c, &(a, b)) in pairs.iter().enumerate() {
            let exact = -0.5 * r * t * u[a] * u[b];
            assert!((wi[c] - exact).abs() < 1e-12, "W[{c}] = {} vs {exact}", wi[c]);
        }
    }
    assert_virial_sums(&mut sim);
    let (header, rows) = read_dump(&case.path("s.lammpstrj"));
    assert_eq!(header.join(" "), "id sxx syy szz sxy sxz syz vonmises wxx");
    assert_eq!(rows.len(), 2);
    for row in &rows {
        for (c, &(a, b)) in pairs.iter().enumerate() {
            assert!((row[1 + c] - 0.5 * r * t * u[a] * u[b]).abs() < 1e-12, "{row:?}");
        }
        assert!((row[7] - 0.5 * r * t).abs() < 1e-12, "uniaxial: von Mises = |S| = ½rT, got {}", row[7]);
        assert_eq!(row[8], -row[1], "wxx = −sxx");
    }
}

/// A particle bonded to six neighbours on ±x, ±y, ±z, all bonds equally
/// stretched: its own share of the virial is hydrostatic, W = −r·T·I, and
/// its von Mises stress vanishes; each neighbour's is uniaxial.
#[test]
fn von_mises_of_a_hydrostatic_star_is_zero() {
    let r = 1.2;
    let mut top = String::from("[ particles ]\n1 p 0 0 0\n");
    let dirs = [DVec3::X, -DVec3::X, DVec3::Y, -DVec3::Y, DVec3::Z, -DVec3::Z];
    for (k, d) in dirs.iter().enumerate() {
        top += &format!("{} p {:?} {:?} {:?}\n", k + 2, r * d.x, r * d.y, r * d.z);
    }
    top += "[ bonds ]\n";
    for k in 0..6 {
        top += &format!("s 1 {}\n", k + 2);
    }
    let ff = "particle p drag 1\nbond s harmonic k 10 r0 1\n";
    let deck = "units cell\ntopology t.top\nforcefield f.ff\nbox x -10 10 f y -10 10 f z -10 10 f\ntimestep 0.001\n";
    let mut sim = Case::new(&[("t.top", &top), ("f.ff", ff), ("deck.in", deck)]).run();
    let w = sim.particle_virial().unwrap();
    let t = 10.0 * (r - 1.0);
    for c in 0..3 {
        assert!((w[0][c] + r * t).abs() < 1e-12, "{:?}", w[0]);
        assert!(w[0][3 + c].abs() < 1e-12);
    }
    assert!(von_mises(&w[0]) < 1e-12 * r * t, "hydrostatic von Mises {}", von_mises(&w[0]));
    assert!((von_mises(&w[1]) - 0.5 * r * t).abs() < 1e-12);
    assert_virial_sums(&mut sim);
}

/// A chain of `n` beads along x from `x0`, harmonic bonds (k = 50, r0 = 1),
/// pulled apart by ±F on its end beads and relaxed by FIRE; `ff_extra` and
/// `deck_extra` add terms and commands.
fn pulled_chain(n: usize, x0: f64, f: f64, ff_extra: &str, box_x: &str, deck_extra: &str) -> Case {
    let mut top = String::from("[ particles ]\n");
    for i in 0..n {
        top += &format!("{} b {:?} 0.5 0.25\n", i + 1, x0 + i as f64);
    }
    top += "[ bonds ]\n";
    for i in 1..n {
        top += &format!("fil {i} {}\n", i + 1);
    }
    let ff = format!("particle b drag 1\nbond fil harmonic k 50 r0 1\n{ff_extra}");
    let deck = format!(
        "units cell\ntopology t.top\nforcefield f.ff\nbox {box_x} y -10 10 f z -10 10 f\ntimestep 0.001\n\
         group left id 1\ngroup right id {n}\nexternal pull_l left constant_force fx {:?}\nexternal pull_r right constant_force fx {f:?}\n\
         minimize ftol 1e-10 maxiter 100000\n{deck_extra}",
        -f
    );
    Case::new(&[("t.top", &top), ("f.ff", &ff), ("deck.in", &deck)])
}

/// Bonds only: every bond carries T = F and has length r0 + F/k; the
/// per-bond CSV dump and the thermo filament columns read that back.
#[test]
fn a_pulled_chain_has_the_analytic_tension_length_and_shape() {
    let (n, f, k, r0) = (11, 5.0, 50.0, 1.0);
    let deck = "thermo 0 step e2e/fil tcorr/fil/3 tension/fil\nthermo_file t.csv\ndump b every 1 bonds b.csv\nrun 0\n";
    let case = pulled_chain(n, 0.0, f, "", "x -20 20 f", deck);
    let mut sim = case.run();
    let (tension, length) = sim.bond_tensions().unwrap();
    assert_eq!(tension.len(), n - 1);
    for (t, l) in tension.iter().zip(&length) {
        assert!((t - f).abs() < 1e-8, "tension {t} vs F = {f}");
        assert!((l - (r0 + f / k)).abs() < 1e-9, "length {l}");
        assert!((t - k * (l - r0)).abs() < 1e-12, "T = k(r − r0)");
    }
    let csv = std::fs::read_to_string(case.path("b.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next().unwrap(), "step,time[s],bond,type,id1,id2,length[µm],tension[pN],x[µm],y[µm],z[µm]");
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), n - 1);
    for (b, row) in rows.iter().enumerate() {
        assert_eq!(row[2..6], [b.to_string().as_str(), "fil", (b + 1).to_string().as_str(), (b + 2).to_string().as_str()]);
        assert_eq!(row[7].parse::<f64>().unwrap(), tension[b]);
        let mid: f64 = row[8].parse().unwrap();
        let exact = 5.0 + (b as f64 + 0.5 - 5.0) * (r0 + f / k);
        assert!((mid - exact).abs() < 1e-6, "midpoint {mid} vs {exact}");
    }
    let e2e = (n - 1) as f64 * (r0 + f / k);
    assert!((sim.thermo_value(&ThermoColumn::EndToEnd(0)).unwrap() - e2e).abs() < 1e-8);
    assert!((sim.thermo_value(&ThermoColumn::TangentCorrelation { bond_type: 0, lag: 3 }).unwrap() - 1.0).abs() < 1e-15);
    assert!(sim.thermo_value(&ThermoColumn::TangentCorrelation { bond_type: 0, lag: n - 1 }).unwrap().is_nan(), "no pair 10 bonds apart");
    // The thermo file has the same values under documented headers.
    let thermo = std::fs::read_to_string(case.path("t.csv")).unwrap();
    let mut lines = thermo.lines();
    assert_eq!(lines.next().unwrap(), "step[-],e2e/fil[µm],tcorr/fil/3[-],tension/fil[pN]");
    let values: Vec<f64> = lines.last().unwrap().split(',').map(|v| v.parse().unwrap()).collect();
    assert!((values[1] - e2e).abs() < 1e-8 && (values[2] - 1.0).abs() < 1e-15);
    assert!((values[3] - (n - 1) as f64 * f).abs() < 1e-6);
}

/// Method of planes: with 1–3 pair repulsion added, bonds no longer carry F
/// each, but bonds and pairs together transmit exactly F across every plane
/// between the ends — on a periodic axis too, where the chain crosses the
/// box face; nothing crosses a plane beyond the ends.
#[test]
fn a_pulled_chain_transmits_its_end_force_across_every_plane() {
    let f = 4.0;
    // The chain runs from x = 15 across the periodic face at 20 to about x = 4 (wrapped).
    let case =
        pulled_chain(9, 15.0, f, "pair b b soft_repulsion k 20 sigma 2.5\n", "x 0 20 p", "thermo 0 step planetension/x/16.5\nrun 0\n");
    let mut sim = case.run();
    let (tension, _) = sim.bond_tensions().unwrap();
    assert!(tension.iter().all(|t| (t - f).abs() > 0.1), "pairs must carry part of the load: bond tensions {tension:?}");
    for pos in [15.2, 16.5, 19.99, 0.0, 0.5, 20.5, -19.5, 2.7] {
        let t = sim.thermo_value(&ThermoColumn::PlaneTension { axis: 0, pos }).unwrap();
        assert!((t - f).abs() < 1e-7 * f, "plane x = {pos}: {t} vs F = {f}");
    }
    for pos in [10.0, 14.0] {
        assert_eq!(sim.thermo_value(&ThermoColumn::PlaneTension { axis: 0, pos }).unwrap(), 0.0);
    }
    // Planes normal to y cut nothing (the chain lies at y = 0.5).
    assert_eq!(sim.thermo_value(&ThermoColumn::PlaneTension { axis: 1, pos: 0.0 }).unwrap(), 0.0);
}

/// ∫ planetension(x) dx over a periodic box is −W_xx exactly: each segment
/// transmits −f_x·sign(d_x) across the |d_x| of planes it spans. The
/// integrand is piecewise constant between particle coordinates, so the
/// integral is exact from one sample per interval.
#[test]
fn plane_tension_integrates_to_the_virial() {
    let mut sim = with_timestep(random_case(true, "")).run();
    let w = sim.current_forces().unwrap().virial;
    for axis in 0..3 {
        let (lo, hi) = (sim.sim_box.lo[axis], sim.sim_box.hi[axis]);
        let mut cuts: Vec<f64> = sim.state.positions.iter().map(|x| lo + (x[axis] - lo).rem_euclid(hi - lo)).collect();
        cuts.push(lo);
        cuts.push(hi);
        cuts.sort_by(f64::total_cmp);
        let mut integral = 0.0;
        for pair in cuts.windows(2) {
            if pair[1] > pair[0] {
                let pos = 0.5 * (pair[0] + pair[1]);
                integral += (pair[1] - pair[0]) * sim.thermo_value(&ThermoColumn::PlaneTension { axis, pos }).unwrap();
            }
        }
        let scale = w[axis].abs().max(1.0);
        assert!((integral + w[axis]).abs() < 1e-9 * scale, "axis {axis}: ∫ = {integral:e}, −W = {:e}", -w[axis]);
    }
}

/// A shell of edge springs (icosphere, level `level`) inflated by turgor and
/// relaxed: its cortical tension γ from the method of planes against
/// Young–Laplace ΔP·R/2.
fn shell_gamma(level: u32) -> (f64, f64, usize) {
    let cell = icosphere_cell(&IcosphereCell { level, radius: 5.0, ..Default::default() });
    let [_, mean_edge, _] = cell.shells[0].edge_lengths;
    let ff = format!(
        "particle node drag 1\nbond edge harmonic k 1000 r0 {:?}\nbody cell turgor k 200 dp0 100 v0 {:?}\n",
        0.8 * mean_edge,
        cell.shells[0].volume
    );
    let deck = "units cell\ntopology cell.top\nforcefield cell.ff\nbox x -40 40 f y -40 40 f z -40 40 f\ntimestep 1e-4\n\
                minimize ftol 1e-7 maxiter 200000\n";
    let case = Case::new(&[("cell.top", &cell.text), ("cell.ff", &ff), ("deck.in", deck)]);
    let mut sim = case.run();
    assert!(sim.reports.last_minimize.as_ref().unwrap().converged, "FIRE did not converge");
    let v = sim.thermo_value(&ThermoColumn::BodyVolume(0)).unwrap();
    let dp = 100.0 + 200.0 * (cell.shells[0].volume - v) / cell.shells[0].volume;
    let (_, r) = cellmd::measure::planes::body_centre_and_radius(&sim.model, 0, &sim.state.positions, &sim.sim_box);
    let gamma = sim.thermo_value(&ThermoColumn::CorticalTension(0)).unwrap();
    assert_virial_sums(&mut sim);
    (gamma, dp * r / 2.0, cell.shells[0].nodes)
}

/// Young–Laplace through the method of planes: at level 3 (642 nodes) the
/// estimator is within 1 % of ΔP·R/2 (the table in docs/src/user-guide/thermo.md gives the
/// numbers), and the error falls from level 2 to level 3.
#[test]
fn pressurised_shell_cortical_tension_matches_young_laplace() {
    println!("| level | nodes | γ (pN/µm) | ΔP·R/2 (pN/µm) | γ/(ΔP·R/2) − 1 |");
    println!("|---|---|---|---|---|");
    let mut errors = Vec::new();
    for level in [2, 3] {
        let (gamma, laplace, nodes) = shell_gamma(level);
        let error = gamma / laplace - 1.0;
        println!("| {level} | {nodes} | {gamma:.4} | {laplace:.4} | {error:+.2e} |");
        errors.push(error.abs());
    }
    assert!(errors[1] < 0.01, "level 3: |γ/(ΔP·R/2) − 1| = {:.3e}", errors[1]);
    assert!(errors[1] < errors[0], "the discretisation error falls with refinement: {errors:?}");
    let _ = PI;
}

/// Bonds on an exact circular arc, turning by θ per bond: the tangent
/// correlation at lag L is cos(L·θ) and the end-to-end distance the chord.
#[test]
fn an_arc_has_cosine_tangent_correlation_and_chord_end_to_end() {
    let (n, radius, theta) = (13usize, 4.0, 0.2);
    let mut top = String::from("[ particles ]\n");
    for i in 0..n {
        let phi = i as f64 * theta;
        top += &format!("{} b {:?} {:?} 0\n", i + 1, radius * phi.cos(), radius * phi.sin());
    }
    top += "[ bonds ]\n";
    // Listed out of order and reversed: chains follow connectivity, not file order.
    for i in (1..n).rev() {
        top += &format!("fil {} {i}\n", i + 1);
    }
    let ff = "particle b drag 1\nbond fil harmonic k 1 r0 1\n";
    let deck = "units cell\ntopology t.top\nforcefield f.ff\nbox x -10 10 f y -10 10 f z -10 10 f\ntimestep 0.001\n";
    let mut sim = Case::new(&[("t.top", &top), ("f.ff", ff), ("deck.in", deck)]).run();
    for lag in [0, 1, 2, 5, 11] {
        let c = sim.thermo_value(&ThermoColumn::TangentCorrelation { bond_type: 0, lag }).unwrap();
        assert!((c - (lag as f64 * theta).cos()).abs() < 1e-12, "lag {lag}: {c}");
    }
    let chord = 2.0 * radius * (0.5 * (n - 1) as f64 * theta).sin();
    assert!((sim.thermo_value(&ThermoColumn::EndToEnd(0)).unwrap() - chord).abs() < 1e-12);
}

//! Cells as pressurised triangulated shells (issue #7): the validation table.
//!
//! - **Young–Laplace**: an icosphere cell with `turgor` and `surface_tension`
//!   minimised by FIRE settles where ΔP(V) = K·(V0 − V)/V0 = 2γ/R; its radius
//!   R_V = (3V/4π)^⅓ against the continuum solution, level by level.
//! - **Helfrich**: `helfrich_bending` of an icosphere → 8πκ with refinement.
//! - **Volume conservation at kT = 0**: an ellipsoidal cell rounds up under
//!   surface tension while stiff turgor holds its volume.
//! - the `body` terms through the engine: thread-count independence, the
//!   `cellmd build icosphere` command (the GPU's surface kernels: tests/suite/gpu.rs).
//!
//! Each table is printed (`cargo test --release --test suite shells:: -- --nocapture`)
//! and reported in docs/src/user-guide/cells.md.

use std::f64::consts::PI;

use crate::common::{merge_topologies, position_bits, stretch_particles, Case};
use cellmd::build::{icosphere_cell, IcosphereCell};
use cellmd::deck::validate_file;
use cellmd::run::{RunOptions, Simulation};
use glam::DVec3;

/// Enclosed volume and area of body 0 of a simulation.
fn volume_and_area(sim: &Simulation) -> (f64, f64) {
    sim.model.body_volume_and_area(0, &sim.state.positions, &sim.sim_box.images())
}

/// A one-cell case: an icosphere of `level` and radius `radius` (no edge
/// bonds), the force field `ff` (with `particle node drag 1`) and deck lines `commands`.
fn cell_case(level: u32, radius: f64, ff: &str, commands: &str) -> Case {
    let cell = icosphere_cell(&IcosphereCell { level, radius, bond_type: None, ..Default::default() });
    let deck =
        format!("units cell\ntopology cell.top\nforcefield cell.ff\nbox x -40 40 f y -40 40 f z -40 40 f\ntemperature 0\n{commands}");
    Case::new(&[("cell.top", &cell.text), ("cell.ff", &format!("particle node drag 1\n{ff}")), ("deck.in", &deck)])
}

/// The continuum radius R where ΔP0 + K(1 − R³/R0³) = 2γ/R: the larger
/// root (the stable one, where the pressure falls as the cell grows), by
/// bisection between a radius where the pressure wins and one where tension does.
fn laplace_radius(k: f64, dp0: f64, r0: f64, gamma: f64) -> f64 {
    let f = |r: f64| dp0 + k * (1.0 - (r / r0).powi(3)) - 2.0 * gamma / r;
    let (mut lo, mut hi) = (r0, r0);
    while f(hi) >= 0.0 {
        hi *= 1.1;
    }
    while f(lo) <= 0.0 {
        lo *= 0.99;
        assert!(lo > 1e-3 * r0, "tension wins at every radius: no equilibrium");
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Young–Laplace: K = 1000 Pa, γ = 300 pN/µm, V0 = 4π·5³/3 µm³ (ΔP0 = 0):
/// the continuum cell shrinks to R* = 4.78 µm (12.5 % less volume). For the
/// FIRE-relaxed icosphere, both the volume radius R_V against R* and the
/// turgor pressure ΔP against 2γ/R_V converge with the level (the error
/// falls each level) and are within 1 % from level 3 on. At the minimum
/// ΔP = 2γA/(3V) holds exactly (uniform scaling): the check that FIRE has
/// converged; the polyhedron's A/V exceeds the sphere's 3/R_V, which is
/// the discretisation error.
#[test]
fn young_laplace_radius_converges_with_refinement() {
    let (k, gamma, r0): (f64, f64, f64) = (1000.0, 300.0, 5.0);
    let v0 = 4.0 / 3.0 * PI * r0.powi(3);
    let r_star = laplace_radius(k, 0.0, r0, gamma);
    println!("Young–Laplace: K = {k} Pa, γ = {gamma} pN/µm, V0 = {v0:.4} µm³ (R0 = {r0} µm): continuum R* = {r_star:.6} µm");
    println!("| level | nodes | R_V (µm) | R_V/R* − 1 | ΔP = K(V0 − V)/V0 (Pa) | 2γ/R_V (Pa) | ΔP/(2γ/R_V) − 1 | ΔP·3V/(2γA) − 1 | FIRE iterations |");
    println!("|---|---|---|---|---|---|---|---|---|");
    let (mut last_error, mut last_laplace) = (f64::INFINITY, f64::INFINITY);
    for level in 1..=4 {
        let ff = format!("body cell turgor k {k} v0 {v0:?}\nbody cell surface_tension gamma {gamma}\n");
        let case = cell_case(level, r0, &ff, "timestep 3e-3\nminimize ftol 1e-5 maxiter 200000 dmax 0.01\n");
        let sim = case.run();
        let report = sim.reports.last_minimize.clone().unwrap();
        assert!(report.converged, "level {level}: FIRE did not converge: {report:?}");
        let (v, area) = volume_and_area(&sim);
        let r_v = (3.0 * v / (4.0 * PI)).cbrt();
        let pressure = k * (v0 - v) / v0;
        let error = r_v / r_star - 1.0;
        let identity = pressure * 3.0 * v / (2.0 * gamma * area) - 1.0;
        let laplace = pressure / (2.0 * gamma / r_v) - 1.0;
        println!(
            "| {level} | {} | {r_v:.6} | {error:+.3e} | {pressure:.4} | {:.4} | {laplace:+.3e} | {identity:+.1e} | {} |",
            sim.model.len(),
            2.0 * gamma / r_v,
            report.iterations
        );
        assert!(identity.abs() < 1e-6, "level {level}: ΔP·3V/(2γA) − 1 = {identity:e}: not at the minimum");
        assert!(error.abs() < last_error.abs(), "level {level}: error {error:e} did not shrink from {last_error:e}");
        assert!(laplace.abs() < last_laplace.abs(), "level {level}: ΔP/(2γ/R_V) − 1 = {laplace:e} did not shrink from {last_laplace:e}");
        if level >= 3 {
            assert!(error.abs() < 0.01, "level {level}: R_V = {r_v} vs R* = {r_star}: {error:e}");
            assert!(laplace.abs() < 0.01, "level {level}: ΔP = {pressure} vs 2γ/R_V = {}: {laplace:e}", 2.0 * gamma / r_v);
        }
        (last_error, last_laplace) = (error, laplace);
    }
}

/// Helfrich: Jülicher's bending energy of an icosphere (any radius) → 8πκ,
/// through the engine (`pe/helfrich_bending` of a deck).
#[test]
fn helfrich_energy_of_a_sphere_converges_to_8_pi_kappa() {
    let kappa = 0.08;
    println!("Helfrich sphere: κ = {kappa} pN·µm, 8πκ = {:.6} pN·µm", 8.0 * PI * kappa);
    println!("| level | nodes | E (pN·µm) | E/(8πκ) − 1 |");
    println!("|---|---|---|---|");
    let index = cellmd::interactions::REGISTRY.iter().position(|i| i.name() == "helfrich_bending").unwrap();
    let mut errors = Vec::new();
    for level in 1..=5 {
        let case = cell_case(level, 3.0, &format!("body cell helfrich_bending kappa {kappa}\n"), "timestep 1e-3\nrun 0\n");
        let mut sim = Simulation::new(&case.plan(), RunOptions::default());
        let energy = sim.current_forces().unwrap().energy_by_interaction[index];
        let error = energy / (8.0 * PI * kappa) - 1.0;
        println!("| {level} | {} | {energy:.6} | {error:+.3e} |", sim.model.len());
        errors.push(error);
    }
    for w in errors.windows(2) {
        assert!(w[1].abs() < w[0].abs(), "the error did not shrink: {errors:?}");
    }
    assert!(errors[2].abs() < 0.01, "level 3: {:e}", errors[2]);
}

/// Volume at kT = 0: an ellipsoidal cell (axes 6.5, 5, 4 µm, level 3) with
/// surface tension γ = 300 pN/µm rounds up while turgor with K = 10⁵ Pa
/// holds its volume. The only volume change allowed is the compression by
/// the Laplace pressure, 1 − V/V0 = ΔP/K ≤ 2γA/(3VK) (A/V largest at the
/// start): V/V0 must stay within [1 − 2γA(0)/(3V0K), 1] at every sample, and
/// end at the Young–Laplace volume of the final sphere to 2·10⁻⁵, with the
/// cell round (R_max/R_min − 1 below 2 % from 63 %).
#[test]
fn volume_is_conserved_at_zero_temperature_while_the_cell_rounds_up() {
    let (k, gamma): (f64, f64) = (1e5, 300.0);
    let mut cell = icosphere_cell(&IcosphereCell { level: 3, radius: 5.0, bond_type: None, ..Default::default() });
    cell.text = stretch_particles(&cell.text, DVec3::new(1.3, 1.0, 0.8));
    let probe = Case::new(&[
        ("cell.top", &cell.text),
        ("cell.ff", "particle node drag 1\nbody cell surface_tension gamma 1\n"),
        ("deck.in", "units cell\ntopology cell.top\nforcefield cell.ff\nbox x -40 40 f y -40 40 f z -40 40 f\ntimestep 1e-3\nrun 0\n"),
    ]);
    let (v0, a0) = volume_and_area(&Simulation::new(&probe.plan(), RunOptions::default()));
    let bound = 2.0 * gamma * a0 / (3.0 * v0 * k);
    let ff = format!("particle node drag 1\nbody cell turgor k {k} v0 {v0:?}\nbody cell surface_tension gamma {gamma}\n");
    let case = Case::new(&[
        ("cell.top", &cell.text),
        ("cell.ff", &ff),
        // The breathing mode's stiffness per node is K·A²/(N·V0) ≈ 3·10⁴ pN/µm:
        // dt·k/γ_drag ≈ 0.9 < 1 keeps the overdamped step monotone.
        (
            "deck.in",
            "units cell\ntopology cell.top\nforcefield cell.ff\nbox x -40 40 f y -40 40 f z -40 40 f\ntemperature 0\ntimestep 3e-5\n",
        ),
    ]);
    let mut sim = Simulation::new(&case.plan(), RunOptions::default());
    for action in case.plan().actions {
        sim.apply(&action).unwrap();
    }
    let aspect = |sim: &Simulation| {
        let centre = sim.state.positions.iter().sum::<DVec3>() / sim.model.len() as f64;
        let r: Vec<f64> = sim.state.positions.iter().map(|p| (*p - centre).length()).collect();
        r.iter().copied().fold(0.0, f64::max) / r.iter().copied().fold(f64::INFINITY, f64::min) - 1.0
    };
    let r_final = (3.0 * v0 / (4.0 * PI)).cbrt();
    let r_eq = laplace_radius(k, 0.0, r_final, gamma);
    let v_eq = 4.0 / 3.0 * PI * r_eq.powi(3) / v0;
    let start = aspect(&sim);
    println!("volume at kT = 0: K = {k} Pa, γ = {gamma} pN/µm, V0 = {v0:.4} µm³; Young–Laplace V/V0 = {v_eq:.7}; bound 2γA(0)/(3V0K) = {bound:.3e}");
    println!("| step | R_max/R_min − 1 | V/V0 − 1 |");
    println!("|---|---|---|");
    let (mut lowest, mut highest) = (f64::INFINITY, f64::NEG_INFINITY);
    for chunk in 0..=40 {
        if chunk > 0 {
            sim.run(250).unwrap();
        }
        let ratio = volume_and_area(&sim).0 / v0;
        lowest = lowest.min(ratio);
        highest = highest.max(ratio);
        if chunk % 5 == 0 {
            println!("| {} | {:.4e} | {:+.3e} |", sim.state.step, aspect(&sim), ratio - 1.0);
        }
    }
    let end = aspect(&sim);
    let final_ratio = volume_and_area(&sim).0 / v0;
    println!(
        "range of V/V0 − 1 over the run: [{:+.3e}, {:+.3e}]; final − Young–Laplace: {:+.2e}",
        lowest - 1.0,
        highest - 1.0,
        final_ratio - v_eq
    );
    assert!(start > 0.6 && end < 0.02, "the cell did not round up: R_max/R_min − 1 = {start} → {end}");
    assert!(lowest >= 1.0 - bound && highest <= 1.0 + 1e-12, "V/V0 left [1 − {bound:e}, 1]: [{lowest}, {highest}]");
    assert!((final_ratio - v_eq).abs() < 2e-5, "final V/V0 = {final_ratio}, Young–Laplace {v_eq}");
}

/// Surface terms keep runs bit-identical on 1 and 2 threads (per-body slots
/// gathered in a fixed order). (On the GPU: `tests/suite/gpu.rs`.)
#[test]
fn body_terms_are_deterministic_on_any_thread_count() {
    let ff = "body cell turgor k 500 dp0 50 v0 400\nbody cell surface_tension gamma 100\nbody cell helfrich_bending kappa 0.5\nbody cell area_conservation kl 200 a0 300\n";
    let case = cell_case(3, 5.0, ff, "temperature 300\ntimestep 1e-4\nseed 5\nrun 200\n");
    let plan = case.plan();
    let (one, two) = (case.run_with_threads(1), case.run_with_threads(2));
    assert_eq!(position_bits(&one), position_bits(&two));
    assert!(one.state.positions.iter().zip(&plan.positions).any(|(a, b)| (*a - *b).length() > 1e-3));
}

/// A cell may straddle a periodic boundary: its terms see it whole.
#[test]
fn a_cell_across_a_periodic_boundary_feels_the_same_forces() {
    let ff = "body cell turgor k 500 dp0 50 v0 400\nbody cell surface_tension gamma 100\nbody cell helfrich_bending kappa 0.5 c0 0.3\nbody cell area_conservation ka 100 kl 200 a0 300\n";
    let energies = |box_line: &str| {
        let case = cell_case(2, 5.0, ff, "timestep 1e-4\nrun 0\n");
        let deck = std::fs::read_to_string(case.path("deck.in")).unwrap().replace("box x -40 40 f y -40 40 f z -40 40 f", box_line);
        std::fs::write(case.path("deck.in"), deck).unwrap();
        let mut sim = Simulation::new(&case.plan(), RunOptions::default());
        let f = sim.current_forces().unwrap().clone();
        (f.total_energy(), f.forces, f.virial)
    };
    let (e_free, f_free, w_free) = energies("box x -40 40 f y -40 40 f z -40 40 f");
    // The cell (radius 5 at the origin) cut by the faces x = 2, y = −3, z = 1 of a 12 µm periodic box.
    let (e_periodic, f_periodic, w_periodic) = energies("box x 2 14 p y -3 9 p z 1 13 p");
    assert!((e_free - e_periodic).abs() < 1e-12 * e_free.abs());
    let scale = f_free.iter().map(|f| f.length()).fold(0.0, f64::max);
    for (a, b) in f_free.iter().zip(&f_periodic) {
        assert!((*a - *b).length() < 1e-12 * scale);
    }
    for (a, b) in w_free.iter().zip(&w_periodic) {
        assert!((a - b).abs() < 1e-10 * w_free.iter().map(|w| w.abs()).fold(0.0, f64::max));
    }
}

/// `cellmd build icosphere` writes a topology a deck runs with, and the
/// thermo columns `volume/cell` and `area/cell` report it.
#[test]
fn cellmd_build_icosphere_writes_a_runnable_cell() {
    let case = Case::new(&[
        ("cell.ff", "particle node drag 1\nbond edge harmonic k 10 r0 0.75\nbody cell turgor k 1000 v0 519.0926\nbody cell surface_tension gamma 10\n"),
        ("deck.in", "units cell\ntopology cell.top\nforcefield cell.ff\ntimestep 1e-3\nthermo 10 step pe pe/turgor volume/cell area/cell\nthermo_file t.csv\nrun 10\n"),
    ]);
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_cellmd"))
        .args(["build", "icosphere", "--level", "3", "--radius", "5", "--centre", "1", "-2", "3", "--box", "12", "-o"])
        .arg(case.path("cell.top"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(said.contains("642 nodes, 1920 edges, 1280 faces; enclosed volume 5.190926"), "{said}");
    let sim = case.run();
    assert_eq!(sim.model.len(), 642);
    assert_eq!(sim.model.bonds.len(), 1920);
    let csv = std::fs::read_to_string(case.path("t.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next().unwrap(), "step[-],pe[pN·µm],pe/turgor[pN·µm],volume/cell[µm³],area/cell[µm²]");
    let first: Vec<f64> = lines.next().unwrap().split(',').map(|v| v.parse().unwrap()).collect();
    assert!((first[3] - 519.0926).abs() < 1e-3 && (first[4] - 312.6623).abs() < 1e-3, "{first:?}");
    let plan = validate_file(&case.path("deck.in"), &[]).unwrap();
    assert!(plan.sim_box.periodic.iter().all(|p| !p));
}

/// The single-cell deck of `inputs/` (shortened) writes an MCAP whose
/// Foxglove scene draws the cell's 1280 faces, and its thermo file follows
/// the cell's volume: it shrinks towards the Laplace balance and stays within
/// 5 % of V0.
#[test]
fn single_cell_deck_writes_a_foxglove_scene_of_its_surface() {
    let out = tempfile::tempdir().unwrap();
    let plan = validate_file(std::path::Path::new("inputs/single_cell.in"), &[("steps".into(), "1000".into())]).unwrap();
    Simulation::execute(plan, RunOptions { output_dir: out.path().to_path_buf(), ..Default::default() }).unwrap();
    let bytes = std::fs::read(out.path().join("single_cell.mcap")).unwrap();
    let scenes: Vec<foxglove::schemas::SceneUpdate> = mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(|m| m.unwrap())
        .filter(|m| m.channel.topic == "/scene")
        .map(|m| prost::Message::decode(&m.data[..]).unwrap())
        .collect();
    assert_eq!(scenes.len(), 2);
    assert_eq!(scenes[1].entities[0].triangles[0].points.len(), 3 * 1280);
    let csv = std::fs::read_to_string(out.path().join("single_cell.thermo.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let column = header.iter().position(|h| h.starts_with("volume/cell")).unwrap();
    let volumes: Vec<f64> = csv.lines().skip(1).map(|l| l.split(',').nth(column).unwrap().parse().unwrap()).collect();
    assert!(volumes.windows(2).all(|w| w[1] < w[0]), "{volumes:?}");
    assert!(volumes.iter().all(|v| (v / 519.0926 - 1.0).abs() < 0.05), "{volumes:?}");
}

/// Cell–cell junctions: two touching cells whose nodes may bind (`bind node
/// node junction … between bodies`) form junction bonds only across the two
/// bodies, although neighbouring nodes of one cell are closer than the capture
/// radius; pulled apart, the slip junctions break and the cells separate.
#[test]
fn junctions_bind_only_across_cells_and_break_when_pulled_apart() {
    let (radius, gap, capture) = (1.0, 0.1, 0.4);
    let cell = |body_id: u64, first_id: u64, x: f64| {
        icosphere_cell(&IcosphereCell {
            level: 2,
            radius,
            centre: DVec3::new(x, 0.0, 0.0),
            bond_type: Some("edge".into()),
            body_id,
            first_id,
            ..Default::default()
        })
    };
    let (a, b) = (cell(1, 1, -(radius + 0.5 * gap)), cell(2, 163, radius + 0.5 * gap));
    assert!(a.shells[0].edge_lengths[0] < capture, "nodes of one cell lie within capture of each other");
    let ff = format!(
        "particle node drag 1\nbody cell turgor k 100 v0 {v}\nbody cell surface_tension gamma 1\nbond edge harmonic k 100 r0 {edge}\n\
         bond junction harmonic k 10 r0 0.25 kinetics slip k0 0.01 x_beta 0.005\n\
         bind node node junction k_on 200 capture {capture} between bodies\n",
        v = a.shells[0].volume,
        edge = a.shells[0].edge_lengths[1]
    );
    let deck = "units cell\ntopology cells.top\nforcefield cells.ff\nbox x -10 10 f y -10 10 f z -10 10 f\ntemperature 298\n\
                timestep 1e-3\nseed 4\nevents events.csv\ngroup left id 1:162\ngroup right id 163:324\nrun 100\n\
                external apart_l left constant_force fx -1\nexternal apart_r right constant_force fx 1\nrun 3000\n";
    let c = Case::new(&[("cells.top", &merge_topologies(&[&a.text, &b.text])), ("cells.ff", &ff), ("deck.in", deck)]);
    let sim = c.run();
    let log = std::fs::read_to_string(c.path("events.csv")).unwrap();
    let mut formed = 0;
    for row in log.lines().skip(1) {
        let f: Vec<&str> = row.split(',').collect();
        let (i, j): (u64, u64) = (f[5].parse().unwrap(), f[6].parse().unwrap());
        assert!((i <= 162) != (j <= 162), "{} between particles {i} and {j} of one cell", f[2]);
        formed += (f[2] == "form") as u32;
    }
    assert!(formed >= 3, "only {formed} junctions formed");
    assert!(sim.kinetics.engine.breaks >= formed as u64, "{} of {formed} junctions broke", sim.kinetics.engine.breaks);
    let bound = sim.state.bonds.as_ref().unwrap().bound[sim.model.topology_bonds..].iter().filter(|&&b| b).count();
    assert_eq!(bound, 0, "junctions still bound after the pull");
    let centre = |lo: usize, hi: usize| sim.state.positions[lo..hi].iter().fold(DVec3::ZERO, |s, x| s + *x) / (hi - lo) as f64;
    let separation = (centre(162, 324) - centre(0, 162)).x;
    assert!(separation > 2.0 * radius + gap + capture, "cells {separation} µm apart");
}

//! Young–Dupré doublet (issue #7): two cells with surface tension γ, stiff
//! turgor, the contact barrier and `contact_adhesion` w relax at kT = 0 to
//! a contact angle θ that Young–Dupré puts at cos θ = 1 − w/γ.
//!
//! **Setup.** Two icosphere meshes of level L (R = 2 µm: a sphere's volume),
//! γ = 100 pN/µm, turgor K = 2000 Pa with ΔP0 = 2γA/(3V) (each cell alone is
//! in equilibrium at its initial volume), `surface_shear` with shear
//! modulus μ = 2γ (k = μ·a, a the mean face area: keeps the fluid surface's
//! triangulation even without adding tension). The discretisation lengths
//! follow the mesh edge ℓ: barrier d̂ = ℓ/6 with κ such that the barrier
//! carries the pressure load of a node at d ≈ d̂/2, switch d_on = d̂,
//! d_off = d̂ + ℓ. Each doublet starts as two truncated spheres (mapped
//! area-preservingly from the icosphere, so faces keep their proportions) at
//! θ0 = θ_YD − 10° and at θ_YD + 10°: the contact spreads (advancing angle)
//! or recedes (receding angle) until the angle changes by less than 0.01°
//! per 0.1 s.
//!
//! **Measurement.** Per cell, a least-squares sphere (centre c, radius R)
//! through the free nodes (farther than d_off from the other cell) and the
//! contact plane at height h = ⟨(x − c)·n̂⟩ over the contact nodes (closer
//! than d_on), n̂ the unit vector from c to the other cell's centre; for a
//! truncated sphere cos θ = h/R (θ = 0 for two touching spheres, 90° for
//! hemispheres). θ is the mean of the two cells.
//!
//! **Discretisation.** The rim of the contact moves only as nodes zip into
//! or out of contact, so it can pin: the advancing and receding angles
//! differ (contact-angle hysteresis of the mesh) and their midpoint is the
//! estimate. Across the adhesion switch the tension falls from γ to γ − w
//! within one edge, which pulls nodes along the surface; the shear
//! regulariser carries that pull (at some cost in angle: it resists the
//! spreading), where `area_conservation kl 100`, used before, let faces
//! collapse at w/γ = 0.75. Measured (table in docs/src/user-guide/contact.md): |midpoint − θ_YD| ≤ 2.6°
//! at level 2 and ≤ 1.5° at level 3, bands ≤ 2.8°, smallest face ≥ 0.40 of
//! the mean. `cargo test --release --test suite doublet:: -- --ignored --nocapture`
//! prints the table for levels 2 and 3.
//!
//! The CI test runs level 2 for w/γ = 0.1, 0.25, 0.5, 0.75: the midpoint is
//! within 3° of θ_YD (the level-2 error measured, ≤ 2.63°), each band is at
//! most 4° wide (measured ≤ 2.8°), the midpoints rise with w, and the mesh
//! stays healthy (smallest face ≥ 0.4 of the mean; measured ≥ 0.48). Seed
//! 000's factor-2 reading (cos θ = 1 − w/(2γ): 18.2°, 29.0°, 41.4°, 51.3°)
//! fails it.
//!
//! **Implicit step** (issue #6: `contact_adhesion`'s stiffness blocks). The
//! advancing doublet at w/γ = 0.25, regularised by `area_conservation kl
//! 100` as when the manual's table was measured, relaxed by `integrator
//! implicit` at 10× the explicit dt settles within 0.5° of the explicit
//! angle (measured 38.944° vs 38.835°; 38.948° before the blocks), and at
//! 1000× (0.27 s) within 5° (measured +4.61°; before the blocks it did not
//! settle within 100 steps). With `surface_shear` instead, the 10× run
//! settles at 37.50° against the explicit 38.83° (−1.3°: the shear-held rim
//! pins on the path the larger steps take). `-- --ignored
//! implicit_doublet_time_step_table` prints the sweep from 1× to 30000×.

use std::f64::consts::PI;

use crate::common::Case;
use cellmd::mesh::{point_triangle, triangle_area};
use cellmd::run::{RunOptions, Simulation};
use glam::{DMat4, DVec3, DVec4};

const RADIUS: f64 = 2.0;
const GAMMA: f64 = 100.0;
const TURGOR_K: f64 = 2000.0;
/// Shear modulus of the `surface_shear` mesh regulariser, pN/µm (2γ).
const MU: f64 = 200.0;
/// Per-face area modulus of the `area_conservation` regulariser that the
/// implicit-step tests keep (their table in the manual was measured with it), pN/µm.
const KL: f64 = 100.0;

/// How the fluid surface's triangulation is kept even.
#[derive(Clone, Copy, Debug)]
enum Regulariser {
    /// `surface_shear` with μ = [`MU`]: the Young–Dupré sweep.
    Shear,
    /// `area_conservation kl` [`KL`]: the implicit-step tests.
    FaceArea,
}

impl Regulariser {
    /// The force-field line for a body of area `a0` with `faces` faces.
    fn line(self, a0: f64, faces: usize) -> String {
        match self {
            Regulariser::Shear => format!("body cell surface_shear k {:?}\n", MU * a0 / faces as f64),
            Regulariser::FaceArea => format!("body cell area_conservation kl {KL} a0 {a0:?}\n"),
        }
    }
}

/// The discretisation lengths and the time step of a level.
#[derive(Clone, Copy, Debug)]
struct Lengths {
    edge: f64,
    dhat: f64,
    kappa: f64,
    dt: f64,
}

impl Lengths {
    fn of(level: u32) -> Self {
        let faces = 20.0 * 4f64.powi(level as i32);
        let nodes = faces / 2.0 + 2.0;
        // The edge of equilateral faces of equal area covering the sphere.
        let edge = (4.0 * PI * RADIUS * RADIUS / faces * 4.0 / 3f64.sqrt()).sqrt();
        let dhat = edge / 6.0;
        // Pressure load of a node; the barrier pushes ≈ 0.6·κ·d̂ at d̂/2 with a
        // stiffness ≈ 10.7·load/d̂ there, which sets the step (drag 1 pN·s/µm).
        let load = 2.0 * GAMMA / RADIUS * 4.0 * PI * RADIUS * RADIUS / nodes;
        Self { edge, dhat, kappa: load / (0.6 * dhat), dt: 0.9 * dhat / (10.7 * load) }
    }
}

/// Two level-`level` icosphere meshes as truncated spheres of contact angle
/// `theta0` facing each other across the plane x = 0, `gap` apart, mapped
/// area-preservingly: a node at polar angle α from +x keeps its azimuth and
/// goes where the area fraction (1 − cos α)/2 of the truncated sphere lies
/// (the contact disk first, then the spherical part from its rim), so face
/// areas keep the icosphere's proportions. The sphere radius ρ is such that
/// the truncated sphere encloses 4πR³/3. Cell 2 is the mirror image of cell
/// 1 (faces rewound outward).
fn doublet_topology(level: u32, theta0: f64, gap: f64) -> String {
    let (directions, faces) = cellmd::mesh::icosphere(level, 1.0);
    let c = theta0.cos();
    let rho = RADIUS * (4.0 / 3.0 / (4.0 / 3.0 - (1.0 - c).powi(2) * (2.0 + c) / 3.0)).cbrt();
    let (disk, cap) = (PI * (rho * theta0.sin()).powi(2), 2.0 * PI * rho * rho * (1.0 + c));
    let centre = DVec3::new(-0.5 * gap - rho * c, 0.0, 0.0);
    let cell: Vec<DVec3> = directions
        .iter()
        .map(|u| {
            let fraction = (1.0 - u.x) / 2.0 * (disk + cap);
            let radial = DVec3::new(0.0, u.y, u.z).normalize_or_zero();
            if fraction <= disk {
                DVec3::new(-0.5 * gap, 0.0, 0.0) + radial * (fraction / PI).sqrt()
            } else {
                // The spherical zone from the rim (polar angle θ0 about the centre) outwards.
                let cos_beta = c - (fraction - disk) / (2.0 * PI * rho * rho);
                centre + rho * (DVec3::new(cos_beta, 0.0, 0.0) + (1.0 - cos_beta * cos_beta).max(0.0).sqrt() * radial)
            }
        })
        .collect();
    let n = cell.len();
    let mut text = String::from("[ particles ]\n");
    for (body, sign) in [(1, 1.0), (2, -1.0)] {
        for (k, x) in cell.iter().enumerate() {
            text += &format!("{} node {:?} {:?} {:?} {body}\n", (body - 1) * n + k + 1, sign * x.x, x.y, x.z);
        }
    }
    text += "[ bodies ]\n1 cell\n2 cell\n[ triangles ]\n";
    for f in &faces {
        text += &format!("1 {} {} {}\n", f[0] + 1, f[1] + 1, f[2] + 1);
    }
    for f in &faces {
        let [a, b, c] = f.map(|k| k as usize + n + 1);
        text += &format!("2 {a} {c} {b}\n");
    }
    text
}

/// Smallest distance from each node of body `a` to a face of body `b`, by brute force.
fn distances(sim: &Simulation, a: usize, b: usize) -> Vec<f64> {
    let x = &sim.state.positions;
    let faces = &sim.model.bodies[b];
    let corners: Vec<[DVec3; 3]> = faces.mesh.triangles().iter().map(|t| t.map(|k| x[faces.nodes[k as usize] as usize])).collect();
    sim.model.bodies[a]
        .nodes
        .iter()
        .map(|&p| corners.iter().map(|c| point_triangle(x[p as usize], *c).distance).fold(f64::INFINITY, f64::min))
        .collect()
}

/// Least-squares sphere through `points` (|x|² = 2c·x + k, linear in c and k): centre and radius.
fn fit_sphere(points: &[DVec3]) -> (DVec3, f64) {
    let (mut normal, mut rhs) = (DMat4::ZERO, DVec4::ZERO);
    for p in points {
        let row = DVec4::new(2.0 * p.x, 2.0 * p.y, 2.0 * p.z, 1.0);
        for i in 0..4 {
            *normal.col_mut(i) += row * row[i];
        }
        rhs += row * p.length_squared();
    }
    let s = normal.inverse() * rhs;
    let centre = DVec3::new(s.x, s.y, s.z);
    (centre, (s.w + centre.length_squared()).sqrt())
}

/// cos θ of each cell (see the module docs): nodes closer than `on` to the
/// other cell are in contact, those from `off` on are free.
fn cos_contact_angles(sim: &Simulation, on: f64, off: f64) -> [f64; 2] {
    let x = &sim.state.positions;
    let fits: Vec<(DVec3, f64, Vec<f64>)> = (0..2)
        .map(|a| {
            let d = distances(sim, a, 1 - a);
            let free: Vec<DVec3> =
                sim.model.bodies[a].nodes.iter().zip(&d).filter(|(_, d)| **d >= off).map(|(p, _)| x[*p as usize]).collect();
            let (c, r) = fit_sphere(&free);
            (c, r, d)
        })
        .collect();
    [0, 1].map(|a| {
        let (c, r, d) = &fits[a];
        let axis = (fits[1 - a].0 - *c).normalize();
        let heights: Vec<f64> =
            sim.model.bodies[a].nodes.iter().zip(d).filter(|(_, d)| **d < on).map(|(p, _)| (x[*p as usize] - *c).dot(axis)).collect();
        assert!(!heights.is_empty(), "cell {a} has no node in contact");
        heights.iter().sum::<f64>() / heights.len() as f64 / r
    })
}

/// The smallest face area over the mean, over both cells (mesh health).
fn smallest_face_ratio(sim: &Simulation) -> f64 {
    let x = &sim.state.positions;
    let areas: Vec<f64> = sim
        .model
        .bodies
        .iter()
        .flat_map(|b| b.mesh.triangles().iter().map(|t| triangle_area(t.map(|k| x[b.nodes[k as usize] as usize]))))
        .collect();
    areas.iter().copied().fold(f64::INFINITY, f64::min) * areas.len() as f64 / areas.iter().sum::<f64>()
}

/// A relaxed doublet: its contact angle, the steps it took and its mesh health.
#[derive(Clone, Copy, Debug)]
struct Relaxed {
    theta: f64,
    asymmetry: f64,
    steps: u64,
    smallest_face: f64,
}

/// Relaxes the doublet of `level` with w = `w_over_gamma`·γ from contact angle `theta0` (degrees).
fn relax(level: u32, w_over_gamma: f64, theta0: f64) -> Relaxed {
    relax_with(level, w_over_gamma, theta0, Regulariser::Shear, "", Lengths::of(level).dt).unwrap_or_else(|e| panic!("{e}"))
}

/// [`relax`] with deck lines `integrator` (e.g. `integrator implicit`) at time step `dt`: an error
/// where the run fails or does not settle.
fn relax_with(level: u32, w_over_gamma: f64, theta0: f64, regulariser: Regulariser, integrator: &str, dt: f64) -> Result<Relaxed, String> {
    let l = Lengths::of(level);
    let (on, off) = (l.dhat, l.dhat + l.edge);
    let top = doublet_topology(level, theta0.to_radians(), 0.5 * l.dhat);
    let deck = |ff: &str| {
        format!("units cell\ntopology cells.top\nforcefield cells.ff\nbox x -20 20 f y -20 20 f z -20 20 f\n{integrator}\ntemperature 0\ntimestep {dt:?}\nrun 0\n{ff}")
    };
    let probe = Case::new(&[
        ("cells.top", &top),
        ("cells.ff", "particle node drag 1\nbody cell surface_tension gamma 1\n"),
        ("deck.in", &deck("")),
    ]);
    let sim = Simulation::new(&probe.plan(), RunOptions::default());
    let (v0, a0) = sim.model.body_volume_and_area(0, &sim.state.positions, &sim.sim_box.images());
    let ff = format!(
        "particle node drag 1\nbody cell turgor k {TURGOR_K} dp0 {:?} v0 {v0:?}\nbody cell surface_tension gamma {GAMMA}\n\
         {}contact cell cell contact_barrier dhat {:?} kappa {:?}\n\
         contact cell cell contact_adhesion w {:?} d_on {on:?} d_off {off:?}\n",
        2.0 * GAMMA * a0 / (3.0 * v0),
        regulariser.line(a0, sim.model.bodies[0].mesh.triangles().len()),
        l.dhat,
        l.kappa,
        w_over_gamma * GAMMA,
    );
    let case = Case::new(&[("cells.top", &top), ("cells.ff", &ff), ("deck.in", &deck(""))]);
    let mut sim =
        Simulation::before_first_run(&case.plan(), RunOptions { output_dir: case.output_dir().to_path_buf(), ..Default::default() })
            .map_err(|e| e.to_string())?;
    // Chunks of 0.1 s until θ changes by less than 0.01° per chunk (at most 10 s).
    let chunk = (0.1 / dt).round().max(1.0) as u64;
    let angle = |sim: &Simulation| {
        let [a, b] = cos_contact_angles(sim, on, off);
        (0.5 * (a.acos() + b.acos()).to_degrees(), (a.acos() - b.acos()).to_degrees().abs())
    };
    let mut last = angle(&sim).0;
    for _ in 0..100 {
        sim.run(chunk).map_err(|e| e.to_string())?;
        let (theta, asymmetry) = angle(&sim);
        if (theta - last).abs() < 0.01 {
            return Ok(Relaxed { theta, asymmetry, steps: sim.state.step, smallest_face: smallest_face_ratio(&sim) });
        }
        last = theta;
    }
    Err(format!("level {level}, w/γ = {w_over_gamma}, from {theta0}°: not relaxed after {} steps (θ = {last:.2}°)", sim.state.step))
}

/// The oracle: θ with cos θ = 1 − w/γ, in degrees.
fn young_dupre(w_over_gamma: f64) -> f64 {
    (1.0 - w_over_gamma).acos().to_degrees()
}

/// One row of the table: the advancing and receding angles from 10° below and above.
fn sweep_row(level: u32, w_over_gamma: f64) -> (f64, Relaxed, Relaxed) {
    let oracle = young_dupre(w_over_gamma);
    let (advancing, receding) = (relax(level, w_over_gamma, oracle - 10.0), relax(level, w_over_gamma, oracle + 10.0));
    println!(
        "| {level} | {w_over_gamma} | {oracle:.2} | {:.2} | {:.2} | {:.2} | {:+.2} | {}, {} | {:.2} |",
        advancing.theta,
        receding.theta,
        0.5 * (advancing.theta + receding.theta),
        0.5 * (advancing.theta + receding.theta) - oracle,
        advancing.steps,
        receding.steps,
        advancing.smallest_face.min(receding.smallest_face)
    );
    (oracle, advancing, receding)
}

const HEADER: &str = "| level | w/γ | θ_YD (°) | θ advancing (°) | θ receding (°) | midpoint (°) | midpoint − θ_YD (°) | steps | smallest face / mean |\n|---|---|---|---|---|---|---|---|---|";

#[test]
#[ignore]
fn young_dupre_sweep_table() {
    println!("{HEADER}");
    for level in [2, 3] {
        for w in [0.1, 0.25, 0.5, 0.75] {
            sweep_row(level, w);
        }
    }
}

#[test]
fn doublet_contact_angles_follow_young_dupre() {
    let mut last = 0.0;
    for w in [0.1, 0.25, 0.5, 0.75] {
        let (oracle, advancing, receding) = sweep_row(2, w);
        let midpoint = 0.5 * (advancing.theta + receding.theta);
        for (start, r) in [("advancing", advancing), ("receding", receding)] {
            assert!(r.smallest_face > 0.4, "w/γ = {w}, {start}: a face shrank to {:.3} of the mean", r.smallest_face);
            assert!(r.asymmetry < 1.0, "w/γ = {w}, {start}: the two cells differ by {:.2}°", r.asymmetry);
        }
        assert!((midpoint - oracle).abs() < 3.0, "w/γ = {w}: midpoint {midpoint:.2}° vs Young–Dupré {oracle:.2}°");
        assert!((receding.theta - advancing.theta).abs() < 4.0, "w/γ = {w}: band {:.2}°–{:.2}°", advancing.theta, receding.theta);
        assert!(midpoint > last, "w/γ = {w}: the angle did not grow with adhesion ({midpoint:.2}° after {last:.2}°)");
        last = midpoint;
    }
}

/// The doublet of the implicit-step tests — w/γ = 0.25 from θ_YD − 10° at
/// level 2 (the advancing case) with the face-area regulariser — relaxed
/// with deck line `integrator` at `factor` × the explicit time step, or why
/// it failed.
fn face_area_doublet(integrator: &str, factor: f64) -> Result<Relaxed, String> {
    let w = 0.25;
    relax_with(2, w, young_dupre(w) - 10.0, Regulariser::FaceArea, integrator, factor * Lengths::of(2).dt)
}

/// The explicit reference of the implicit-step tests.
fn explicit_doublet() -> Relaxed {
    face_area_doublet("", 1.0).unwrap_or_else(|e| panic!("{e}"))
}

/// The implicit step at `factor` × the explicit time step, solved to a
/// relative residual of 1e-13: at 1000× the default 1e-10 left the settled
/// angle hinging on where CG starts (43.44° from the explicit step, 43.97°
/// from the Jacobi step, which it starts from now); at 1e-13 it settles at
/// 43.44° (the table's 1000× column was measured at the default 1e-10).
fn implicit_doublet(factor: f64) -> Result<Relaxed, String> {
    face_area_doublet("integrator implicit tolerance 1e-13 max_iterations 10000", factor)
}

#[test]
#[ignore]
fn implicit_doublet_time_step_table() {
    let explicit = explicit_doublet();
    println!("explicit dt {:.3e} s: θ = {:.3}°, {} steps", Lengths::of(2).dt, explicit.theta, explicit.steps);
    for factor in [1.0, 3.0, 10.0, 30.0, 100.0, 300.0, 1000.0, 3000.0, 10000.0, 30000.0] {
        match implicit_doublet(factor) {
            Ok(r) => println!(
                "implicit {factor}× : θ = {:.3}° ({:+.3}°), {} steps, smallest face {:.2}",
                r.theta,
                r.theta - explicit.theta,
                r.steps,
                r.smallest_face
            ),
            Err(e) => println!("implicit {factor}×: {e}"),
        }
    }
}

/// With the adhesion's stiffness blocks the implicit step settles the doublet
/// where it did before them (10× the explicit dt) at the explicit angle, and
/// at 1000× (0.27 s), where without them θ still moved by more than 0.01° a
/// step after 100 steps. The settled angle depends on the path the pinned
/// rim takes, down to round-off: with the matrix products' terms added in
/// another order (the drag diagonal apart from the blocks) the 10× run
/// settled at 40.415° instead of 38.976°, so this test also holds the
/// implicit step's arithmetic to a fixed order.
#[test]
fn the_implicit_step_settles_the_doublet_at_the_explicit_angle() {
    let explicit = explicit_doublet();
    for (factor, tolerance) in [(10.0, 0.5), (1000.0, 5.0)] {
        let r = implicit_doublet(factor).unwrap_or_else(|e| panic!("{factor}× the explicit dt: {e}"));
        println!("{factor}× dt: θ = {:.3}° vs explicit {:.3}°, {} steps", r.theta, explicit.theta, r.steps);
        assert!((r.theta - explicit.theta).abs() < tolerance, "{factor}×: θ = {:.3}° vs explicit {:.3}°", r.theta, explicit.theta);
        assert!(r.smallest_face > 0.25 && r.asymmetry < 1.0, "{factor}×: {r:?}");
    }
}

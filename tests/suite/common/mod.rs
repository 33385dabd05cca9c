//! Helpers for integration tests: write a deck with its topology and force field
//! into a temporary directory, validate it and run it.

#![allow(dead_code)]

use std::path::{Path, PathBuf};

use cellmd::deck::{validate_file, Plan};
use cellmd::run::{RunOptions, Simulation};

pub struct Case {
    pub dir: tempfile::TempDir,
}

impl Case {
    /// Runs the deck on a pool of `threads` worker threads.
    pub fn run_with_threads(&self, threads: usize) -> Simulation {
        let plan = self.plan();
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| Simulation::execute(plan, RunOptions { output_dir: self.dir.path().to_path_buf(), ..Default::default() }).unwrap())
    }

    /// Files as (name, contents); the deck is `deck.in`.
    pub fn new(files: &[(&str, &str)]) -> Self {
        let dir = tempfile::tempdir().unwrap();
        for (name, text) in files {
            std::fs::write(dir.path().join(name), text).unwrap();
        }
        Self { dir }
    }

    pub fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    pub fn plan(&self) -> Plan {
        validate_file(&self.path("deck.in"), &[]).unwrap_or_else(|e| panic!("{e}"))
    }

    pub fn run(&self) -> Simulation {
        let plan = self.plan();
        Simulation::execute(plan, RunOptions { output_dir: self.dir.path().to_path_buf(), ..Default::default() })
            .unwrap_or_else(|e| panic!("{e}"))
    }

    pub fn output_dir(&self) -> &Path {
        self.dir.path()
    }
}

/// A topology of `n` free particles of type `p` on a cubic grid of spacing `a`.
pub fn grid_topology(n_side: usize, a: f64) -> String {
    let mut top = String::from("[ particles ]\n");
    let mut id = 1;
    for i in 0..n_side {
        for j in 0..n_side {
            for k in 0..n_side {
                top += &format!("{id} p {} {} {}\n", i as f64 * a, j as f64 * a, k as f64 * a);
                id += 1;
            }
        }
    }
    top
}

/// A xorshift64 generator of uniform numbers in [0, 1) from `seed`: test
/// geometries that are random-looking but the same on every machine.
pub fn uniform(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Topology sections over particles 1..=n: `s` bonds (1 2), (3 4), … and
/// `t` angles (1 2 3), (5 6 7), ….
pub fn pairs_and_triples(n: u64) -> String {
    let mut top = String::from("[ bonds ]\n");
    for id in (1..n).step_by(2) {
        top += &format!("s {id} {}\n", id + 1);
    }
    top += "[ angles ]\n";
    for id in (1..n - 2).step_by(4) {
        top += &format!("t {id} {} {}\n", id + 1, id + 2);
    }
    top
}

/// 400 particles of two types in a box of edge 8 (some right at the faces),
/// with bonds, angles and three pair rules; `special` is inserted into the deck.
pub fn random_case(periodic: bool, special: &str) -> Case {
    let mut next = uniform(0x9E3779B97F4A7C15);
    let (n, l) = (400, 8.0);
    let mut top = String::from("[ particles ]\n");
    for id in 1..=n {
        let ty = if id % 3 == 0 { "b" } else { "a" };
        // Some particles sit right at the box faces.
        let x = if id % 50 == 0 { l - 1e-9 } else { next() * l };
        top += &format!("{id} {ty} {x} {} {}\n", next() * l, next() * l);
    }
    top += &pairs_and_triples(n);
    let ff = "particle a drag 1\nparticle b drag 2\nbond s harmonic k 2 r0 0.5\nangle t cosine_angle K 0.3\n\
              pair a a lj epsilon 1 sigma 0.3 rc 0.9\npair a b soft A 1 rc 0.7\npair a b soft_repulsion k 5 sigma 0.5\n";
    let b = if periodic { "p" } else { "f" };
    let deck = format!("units lj\ntopology t.top\nforcefield f.ff\n{special}box x 0 {l} {b} y 0 {l} {b} z 0 {l} {b}\nneighbor skin 0.4\n");
    Case::new(&[("t.top", &top), ("f.ff", ff), ("deck.in", &deck)])
}

/// The positions of [`grid_topology`], in id order.
pub fn grid_positions(n_side: usize, a: f64) -> Vec<glam::DVec3> {
    let mut out = Vec::new();
    for i in 0..n_side {
        for j in 0..n_side {
            for k in 0..n_side {
                out.push(glam::DVec3::new(i as f64 * a, j as f64 * a, k as f64 * a));
            }
        }
    }
    out
}

/// Topology texts merged section by section (each section once, in the
/// order first seen; comment lines above the first section kept).
pub fn merge_topologies(texts: &[&str]) -> String {
    let mut sections: Vec<(String, String)> = vec![(String::new(), String::new())];
    for text in texts {
        let mut current = 0;
        for line in text.lines() {
            if line.starts_with('[') {
                current = sections.iter().position(|(name, _)| name == line).unwrap_or_else(|| {
                    sections.push((line.to_string(), String::new()));
                    sections.len() - 1
                });
            } else if !(current > 0 && line.starts_with('#')) {
                sections[current].1 += &format!("{line}\n");
            }
        }
    }
    sections.iter().map(|(name, body)| if name.is_empty() { body.clone() } else { format!("{name}\n{body}") }).collect()
}

/// A straight chain of `n` segments of 0.1 µm along x, its first `anchors`
/// beads `anchor` (fixed), the rest `bead`, with `rod` bonds and `bend`
/// angles, and its force field (soft harmonic rods, k = 10, that alone
/// would stretch under a load; `wlc_bending`): the filament of the
/// `constrain` tests (tests/suite/constraints.rs, tests/suite/gpu_constraints.rs).
pub fn chain_of_rods(n: usize, anchors: usize) -> (String, &'static str) {
    let mut top = String::from("[ particles ]\n");
    for k in 0..=n {
        top += &format!("{} {} {} 0 0\n", k + 1, if k < anchors { "anchor" } else { "bead" }, k as f64 * 0.1);
    }
    top += "[ bonds ]\n";
    for k in 1..=n {
        top += &format!("rod {k} {}\n", k + 1);
    }
    top += "[ angles ]\n";
    for k in 1..n {
        top += &format!("bend {k} {} {}\n", k + 1, k + 2);
    }
    let ff = "particle anchor fixed\nparticle bead drag 0.01\nbond rod harmonic k 10 r0 0.1\nangle bend wlc_bending kappa 0.01 l0 0.1\n";
    (top, ff)
}

/// `cellmd build ball --radius 5 --cells 4` (125 nodes of type `node`, 384
/// elements of tetra type `solid`), centred at the origin.
pub fn small_ball() -> String {
    cellmd::build::ball(&cellmd::build::BallArgs::default()).unwrap().text
}

/// The bits of every position (for bit-identity checks).
pub fn position_bits(sim: &Simulation) -> Vec<[u64; 3]> {
    sim.state.positions.iter().map(|x| x.to_array().map(f64::to_bits)).collect()
}

/// Two level-`level` icosphere cells (no edge bonds) of radius `radius`,
/// centres on the x axis a `gap` apart at their surfaces; bodies 1 and 2.
pub fn two_cells(level: u32, radius: f64, gap: f64) -> String {
    two_cells_with_edges(level, radius, gap, None)
}

/// As [`two_cells`], with the mesh edges as bonds of type `edges`.
pub fn two_cells_with_edges(level: u32, radius: f64, gap: f64, edges: Option<&str>) -> String {
    use cellmd::build::{icosphere_cell, IcosphereCell};
    let half = radius + gap / 2.0;
    let left = IcosphereCell {
        level,
        radius,
        centre: glam::DVec3::new(-half, 0.0, 0.0),
        bond_type: edges.map(String::from),
        ..Default::default()
    };
    let nodes = icosphere_cell(&left).shells[0].nodes as u64;
    let right = IcosphereCell { centre: glam::DVec3::new(half, 0.0, 0.0), body_id: 2, first_id: nodes + 1, ..left.clone() };
    merge_topologies(&[&icosphere_cell(&left).text, &icosphere_cell(&right).text])
}

/// A topology text with every particle's position scaled by `scale` (axis by
/// axis about the origin): an icosphere cell becomes an ellipsoid.
pub fn stretch_particles(text: &str, scale: glam::DVec3) -> String {
    let mut out = String::new();
    let mut in_particles = false;
    for line in text.lines() {
        if line.starts_with('[') {
            in_particles = line == "[ particles ]";
        }
        let f: Vec<&str> = line.split_whitespace().collect();
        if in_particles && f.len() >= 5 && !line.starts_with('#') {
            let x = glam::DVec3::new(f[2].parse().unwrap(), f[3].parse().unwrap(), f[4].parse().unwrap()) * scale;
            out += &format!("{} {} {:?} {:?} {:?} {}\n", f[0], f[1], x.x, x.y, x.z, f[5..].join(" "));
        } else {
            out += line;
            out += "\n";
        }
    }
    out
}

/// Fixed sites under free beads, 300 of each on a 20 × 15 grid, each bead
/// bonded to its site by a slip bond that rebinds and contracts (`motor`),
/// and forming (and losing) bonds to the neighbouring sites within reach:
/// the system of the kinetics tests. Returns the topology and force field
/// for a deck in `units lj` with `box x -5 45 f y -5 35 f z -5 5 f`.
pub fn kinetic_sites() -> (String, &'static str) {
    let mut top = String::from("[ particles ]\n");
    let mut bonds = String::from("[ bonds ]\n");
    for m in 0..300 {
        let (x, y) = ((m % 20) as f64 * 2.0, (m / 20) as f64 * 2.0);
        top += &format!("{} a {x} {y} 0\n{} bead {x} {y} 0.5\n", 2 * m + 1, 2 * m + 2);
        bonds += &format!("b {} {}\n", 2 * m + 1, 2 * m + 2);
    }
    let ff = "particle a fixed\nparticle bead drag 1\nbond b harmonic k 20 r0 0.5 kinetics slip k0 0.5 x_beta 0.2 kinetics rebind k_on 2 capture 1 kinetics motor v0 0.1 fs 3\n\
              bond x harmonic k 5 r0 1.5 kinetics slip k0 1 x_beta 0.1\nbind a bead x k_on 0.5 capture 2.2 max_bonds 2\npair bead bead wca epsilon 1 sigma 0.3\n";
    (top + &bonds, ff)
}

/// Runs the repository deck `deck` (e.g. `inputs/force_dipole.in`) on the
/// lattice of `args`, built into a temporary directory and passed as the
/// deck's `topology` variable, with further `--var` overrides `vars`.
/// Returns the finished simulation and what the builder wrote.
pub fn run_deck_on_lattice(deck: &str, args: &cellmd::build::LatticeArgs, vars: &[(&str, String)]) -> (Simulation, cellmd::build::Built) {
    let built = cellmd::build::lattice(args).unwrap_or_else(|e| panic!("{e}"));
    let dir = tempfile::tempdir().unwrap();
    let top = dir.path().join("lattice.top");
    std::fs::write(&top, &built.text).unwrap();
    let mut all = vec![("topology".to_string(), top.display().to_string())];
    all.extend(vars.iter().map(|(k, v)| (k.to_string(), v.clone())));
    let plan = validate_file(Path::new(deck), &all).unwrap_or_else(|e| panic!("{e}"));
    let sim = Simulation::execute(plan, RunOptions { output_dir: dir.path().to_path_buf(), ..Default::default() })
        .unwrap_or_else(|e| panic!("{e}"));
    if let Some(report) = &sim.reports.last_minimize {
        assert!(report.converged, "FIRE did not converge: {report:?}");
    }
    (sim, built)
}

/// Kolmogorov–Smirnov statistic D·√N of break steps against the exact law
/// P(s ≤ m) = 1 − exp(−k·dt·(m + 1)), or, for breaks observed only before
/// step `horizon`, the same law conditioned on s < horizon; compared at each
/// distinct step (the data are discrete). The critical value at α = 0.001
/// is 1.95.
pub fn ks_exponential_steps(steps: &[u64], rate_dt: f64, horizon: Option<u64>) -> f64 {
    let mut s = steps.to_vec();
    s.sort_unstable();
    let nn = s.len() as f64;
    let cdf = |m: u64| 1.0 - (-rate_dt * (m as f64 + 1.0)).exp();
    let within = horizon.map_or(1.0, |h| cdf(h - 1));
    let mut d: f64 = 0.0;
    for (i, &m) in s.iter().enumerate() {
        if s.get(i + 1) != Some(&m) {
            d = d.max(((i + 1) as f64 / nn - cdf(m) / within).abs());
        }
    }
    d * nn.sqrt()
}

/// Two 162-node icosphere cells (R = 2 µm, `gap` apart, nodes of drag 1)
/// with force-field lines `ff`, pushed together by `push` pN per node, in a
/// box periodic along x with the cells straddling its boundary (so the
/// contact search works across it).
pub fn contact_case(ff: &str, gap: f64, push: f64, settings: &str) -> Case {
    let top = two_cells(2, 2.0, gap);
    let deck = format!(
        "units cell\ntopology cells.top\nforcefield cells.ff\nbox x 0 20 p y -10 10 f z -10 10 f\n\
         group left id 1:162\ngroup right id 163:324\n\
         external push_left left constant_force fx {push}\nexternal push_right right constant_force fx -{push}\n{settings}"
    );
    Case::new(&[("cells.top", &top), ("cells.ff", &format!("particle node drag 1\n{ff}")), ("deck.in", &deck)])
}

pub const CONTACT_BARRIER: &str = "contact cell cell contact_barrier dhat 0.1 kappa 200\n";
pub const CONTACT_SHELLS: &str = "body cell turgor k 1000 dp0 100 v0 32.4\nbody cell surface_tension gamma 100\n";

/// Adhesion whose switch (0.05–0.4 µm) reaches four times beyond the barrier's d̂.
pub const CONTACT_ADHESION: &str = "contact cell cell contact_adhesion w 50 d_on 0.05 d_off 0.4\n";

/// How closely GPU contact follows the CPU f64 backend (`contact_barrier`,
/// tests/suite/gpu.rs): two cells 0.03 µm apart (many node–face pairs within d̂ = 0.1 µm,
/// in every Voronoi region), the barrier alone and with the cells' surface
/// terms. Tolerance from f32 arithmetic (u = 2⁻²⁴ ≈ 6e-8): a pair's
/// separations from the face's first corner (≤ ℓ + d̂ ≈ 0.6 µm) are rounded
/// once, the closest point and d take ≈ 10 more roundings, so d is off by
/// ≈ 10u·0.6 µm ≈ 4e-7 µm, 1.2e-5 of the smallest d (0.03 µm); the force
/// b′(d) changes by d·|b″/b′| ≤ 3 times that relative change, ≈ 4e-5; the
/// energy by d·|b′/b| ≤ 3 times, also ≈ 4e-5. A particle sums a few pairs of
/// the same sign, so relative to the largest force and the total energy: 1e-4.
pub const CONTACT_GPU_EPSILON: f64 = 1e-4;

/// Asserts that a contact-clamped run on the GPU followed the CPU's from
/// `start`: the same clamped steps (at least `min_clamps`), the clock within
/// [`CONTACT_GPU_EPSILON`] relative, the unwrapped positions within it of the
/// largest distance travelled, and the cells apart (0 < mindist < d̂ = 0.1 µm).
/// Returns that distance.
pub fn assert_clamped_runs_agree(start: &cellmd::system::State, cpu: &Simulation, gpu: &Simulation, min_clamps: u64) -> f64 {
    let unwrap = |s: &cellmd::system::State, i: usize| cpu.sim_box.unwrap(s.positions[i], s.images[i]);
    let travelled = (0..start.len()).map(|i| (unwrap(&cpu.state, i) - unwrap(start, i)).length()).fold(0.0, f64::max);
    let deviation = (0..start.len()).map(|i| (unwrap(&cpu.state, i) - unwrap(&gpu.state, i)).length()).fold(0.0, f64::max);
    println!(
        "CPU: {} clamped steps, t = {:.6e} s, mindist {:.4e}; GPU: {} clamped, t = {:.6e} s, mindist {:.4e}; GPU − CPU {deviation:.3e} after {travelled:.3e}",
        cpu.reports.contact_clamps, cpu.state.time, cpu.min_contact_distance(), gpu.reports.contact_clamps, gpu.state.time, gpu.min_contact_distance()
    );
    assert!(cpu.reports.contact_clamps >= min_clamps, "the clamp hardly acted: {} steps", cpu.reports.contact_clamps);
    assert_eq!(gpu.reports.contact_clamps, cpu.reports.contact_clamps);
    let (t_cpu, t_gpu) = (cpu.state.time, gpu.state.time);
    assert!((t_gpu - t_cpu).abs() <= CONTACT_GPU_EPSILON * t_cpu, "{t_gpu} vs {t_cpu}");
    assert!(deviation <= CONTACT_GPU_EPSILON * travelled, "GPU − CPU {deviation:e} > {CONTACT_GPU_EPSILON:e} × {travelled:e}");
    assert!(gpu.min_contact_distance() > 0.0 && gpu.min_contact_distance() < 0.1);
    travelled
}

/// Two meshed cells (edge springs, k = 20 pN/µm) under [`CONTACT_SHELLS`] and
/// [`CONTACT_BARRIER`], 0.1 µm apart, squeezed between plates at x = ±3.6 µm
/// inside a square tube of half-width 2.3 µm (so they cannot slide past each
/// other): a bounded energy with a minimum where the barrier is active.
pub fn squeezed_cells(settings: &str) -> Case {
    let top = two_cells_with_edges(2, 2.0, 0.1, Some("edge"));
    let ff = format!("particle node drag 1\n{CONTACT_SHELLS}{CONTACT_BARRIER}bond edge harmonic k 20 r0 0.37\n");
    let deck = format!(
        "units cell\ntopology cells.top\nforcefield cells.ff\nbox x -10 10 f y -10 10 f z -10 10 f\ngroup both id 1:324\n\
         external wy0 both wall ny 1 d -2.3 k 100\nexternal wy1 both wall ny -1 d -2.3 k 100\n\
         external wz0 both wall nz 1 d -2.3 k 100\nexternal wz1 both wall nz -1 d -2.3 k 100\n\
         external px0 both wall nx 1 d -3.6 k 1000\nexternal px1 both wall nx -1 d -3.6 k 1000\n{settings}"
    );
    Case::new(&[("cells.top", &top), ("cells.ff", &ff), ("deck.in", &deck)])
}

/// `chains` discrete worm-like chains of `segments` unit segments drawn from
/// their exact equilibrium ensemble (each joint's cos θ from exp(a·cos θ),
/// a = κ/(ℓ·kT), azimuth uniform; a = 0: freely jointed), started on a
/// 10-spaced grid, as topology sections: particles `bead`, bonds `rod`,
/// angles `bend` (none when `a` = 0).
pub fn worm_like_chains(chains: usize, segments: usize, a: f64, seed: u64) -> String {
    use glam::DVec3;
    let mut uniform = uniform(seed);
    let mut top = String::from("[ particles ]\n");
    let mut bonds = String::from("[ bonds ]\n");
    let mut angles = String::from("[ angles ]\n");
    let mut id = 0;
    for c in 0..chains {
        let mut x = DVec3::new((c % 10) as f64 * 10.0, ((c / 10) % 10) as f64 * 10.0, (c / 100) as f64 * 10.0);
        let mut t = DVec3::X;
        for s in 0..=segments {
            id += 1;
            top += &format!("{id} bead {} {} {}\n", x.x, x.y, x.z);
            if s > 0 {
                bonds += &format!("rod {} {id}\n", id - 1);
            }
            if s > 1 && a > 0.0 {
                angles += &format!("bend {} {} {id}\n", id - 2, id - 1);
            }
            if s > 0 {
                let u = uniform();
                let cos = if a > 0.0 { 1.0 + (u + (1.0 - u) * (-2.0 * a).exp()).ln() / a } else { 2.0 * u - 1.0 };
                let cos = cos.clamp(-1.0, 1.0);
                let phi = std::f64::consts::TAU * uniform();
                let (e1, e2) = t.any_orthonormal_pair();
                t = (cos * t + (1.0 - cos * cos).sqrt() * (phi.cos() * e1 + phi.sin() * e2)).normalize();
            }
            x += t;
        }
    }
    top + &bonds + &angles
}

/// A fixed seed's pseudo-random fraction in [0, 1) (splitmix64).
pub fn seeded_fraction(seed: u64) -> f64 {
    let mut z = seed.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
}

/// Bits of every position, image counter, bond state and counter of a restart.
pub fn state_bits(path: &Path) -> (Vec<u64>, String, String, cellmd::output::restart::Counters, u64) {
    let data = cellmd::output::read_state(path).unwrap_or_else(|e| panic!("{e}"));
    let bits = data.positions.iter().flat_map(|x| x.to_array().map(f64::to_bits)).collect();
    (bits, serde_json::to_string(&data.images).unwrap(), serde_json::to_string(&data.bonds).unwrap(), data.counters, data.step)
}

/// Every line of a thermo CSV is whole: a header, then rows with one number per column.
pub fn assert_complete_csv(path: &Path) -> usize {
    let text = std::fs::read_to_string(path).unwrap();
    assert!(text.ends_with('\n'), "{} ends inside a line", path.display());
    let mut lines = text.lines();
    let columns = lines.next().expect("a header").split(',').count();
    let mut rows = 0;
    for line in lines {
        let fields: Vec<&str> = line.split(',').collect();
        assert_eq!(fields.len(), columns, "a partial line in {}: {line}", path.display());
        assert!(fields.iter().all(|f| f.parse::<f64>().is_ok()), "not numbers: {line}");
        rows += 1;
    }
    rows
}

/// A deterministic direction-like jitter of particle `k` (components in
/// [−1, 1], no symmetric ties between particles) for generic test configurations.
pub fn jitter(k: usize) -> glam::DVec3 {
    let k = k as f64;
    glam::DVec3::new((12.9898 * k).sin(), (78.233 * k + 1.0).sin(), (37.719 * k + 2.0).sin())
}

/// The CPU backend's total energy and forces as a function of all
/// positions (contacts found again at each call), for F = −∇E checks.
pub fn cpu_energy_and_forces(plan: &Plan) -> impl Fn(&[glam::DVec3]) -> (f64, Vec<glam::DVec3>) + '_ {
    use cellmd::backend::{CpuBackend, Forces};
    use cellmd::system::State;
    let state = std::cell::RefCell::new(State::new(plan.positions.clone()));
    let backend = std::cell::RefCell::new(CpuBackend::new(&plan.model, &state.borrow(), &plan.sim_box, 0.0).unwrap());
    move |x: &[glam::DVec3]| {
        let (mut state, mut backend) = (state.borrow_mut(), backend.borrow_mut());
        state.positions.copy_from_slice(x);
        backend.update_contacts(&plan.model, &state, &plan.sim_box).unwrap();
        let mut out = Forces::default();
        backend.compute(&plan.model, &state, &plan.sim_box, &mut out);
        (out.total_energy(), out.forces)
    }
}

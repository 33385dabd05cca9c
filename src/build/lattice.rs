//! `cellmd build lattice`: a diluted triangular lattice of fibres, the
//! fibre-network model of Broedersz, Mao, Lubensky & MacKintosh (Nat. Phys.
//! 7, 983, 2011) and of rigidity percolation (Jacobs & Thorpe, Phys. Rev.
//! Lett. 75, 4051, 1995).
//!
//! # Geometry
//!
//! Nodes sit on the triangular lattice of spacing a (`--spacing`, µm),
//! node (i, j) at ((i + j/2)·a, j·a·√3/2, 0) + `--centre`, inside the disc
//! |r| ≤ R (`--radius`). The nodes of the outermost ring, |r| > R − a, take
//! `--rim-type` [rim] (declare it `fixed`: a clamped boundary); the others
//! `--particle-type` [node]. Ids run row by row from −y, each row from −x.
//!
//! Each nearest-neighbour pair is joined by a bond of `--bond-type` [link]
//! with probability p (`--bond-probability`, default 1: the full lattice,
//! connectivity z = 6), drawn once per lattice edge from `--seed` (Philox
//! keyed by the edge's lattice position and direction, so a larger disc keeps
//! the bonds of a smaller one and a larger p keeps those of a smaller p).
//! Pairs of two rim nodes are never joined: both are fixed, such a bond
//! would carry a load that nothing else feels. The summary prints the mean
//! connectivity z of the free nodes (bonds per free node; 6p in the bulk).
//!
//! `--bending` makes the straight lines of the lattice fibres: an angle term
//! of `--angle-type` [bend] on every pair of collinear consecutive bonds that
//! are both present (vertex in the middle), the `wlc_bending` form with
//! l0 = a. `--dipole` adds one bond of `--dipole-bond-type` [dipole] between
//! the nodes at (−a, 0) and (a, 0) from the centre: a contractile element (a
//! myosin minifilament) whose tension pulls them together, a force dipole
//! of length 2a centred on the node at the centre.
//!
//! A fixed cubic `[ box ]` of half-width R + a around the centre holds the
//! disc; the thermo pressure's volume is that box's, (2R + 2a)³.

use std::f64::consts::PI;

use glam::DVec3;

use super::{positive, stream, vec3, Built, Common, Draws, Writer};

/// Command-line options of `cellmd build lattice`.
#[derive(clap::Args, Clone, Debug)]
pub struct LatticeArgs {
    /// Radius of the disc of nodes (µm).
    #[arg(allow_negative_numbers = true, long)]
    pub radius: f64,
    /// Lattice spacing a, the bonds' length (µm).
    #[arg(allow_negative_numbers = true, long)]
    pub spacing: f64,
    /// Probability that a nearest-neighbour pair is bonded (z = 6p in the bulk).
    #[arg(allow_negative_numbers = true, long, default_value_t = 1.0)]
    pub bond_probability: f64,
    /// Angle terms on collinear consecutive bonds: the lattice lines become bending-stiff fibres.
    #[arg(long)]
    pub bending: bool,
    /// A bond between the nodes at (−a, 0) and (a, 0) from the centre: a contractile force dipole.
    #[arg(long)]
    pub dipole: bool,
    /// Middle of the disc, which lies in the plane z = Z.
    #[arg(long, num_args = 3, value_names = ["X", "Y", "Z"], allow_negative_numbers = true, default_values_t = [0.0, 0.0, 0.0])]
    pub centre: Vec<f64>,
    /// Particle type of the free nodes.
    #[arg(long, default_value = "node")]
    pub particle_type: String,
    /// Particle type of the outermost ring of nodes (|r| > R − a), to be declared `fixed`.
    #[arg(long, default_value = "rim")]
    pub rim_type: String,
    /// Bond type of the lattice's links.
    #[arg(long, default_value = "link")]
    pub bond_type: String,
    /// Angle type of the fibres' bending (with --bending).
    #[arg(long, default_value = "bend")]
    pub angle_type: String,
    /// Bond type of the force dipole (with --dipole).
    #[arg(long, default_value = "dipole")]
    pub dipole_bond_type: String,
    #[command(flatten)]
    pub common: Common,
}

impl Default for LatticeArgs {
    fn default() -> Self {
        Self {
            radius: 5.0,
            spacing: 1.0,
            bond_probability: 1.0,
            bending: false,
            dipole: false,
            centre: vec![0.0; 3],
            particle_type: "node".into(),
            rim_type: "rim".into(),
            bond_type: "link".into(),
            angle_type: "bend".into(),
            dipole_bond_type: "dipole".into(),
            common: Common { seed: 1, output: "lattice.top".into(), rest_from_geometry: false },
        }
    }
}

/// The three lattice directions (i, j) steps whose bonds a node owns.
const DIRECTIONS: [(i64, i64); 3] = [(1, 0), (0, 1), (-1, 1)];

/// Offset that makes lattice indices non-negative in a Philox item.
const INDEX_OFFSET: i64 = 1 << 20;

/// The largest --radius in spacings (about 14.5 million nodes).
const MAX_SPACINGS: i64 = 2000;

/// `cellmd build lattice`: see the module documentation.
pub fn lattice(a: &LatticeArgs) -> Result<Built, String> {
    let radius = positive("--radius", a.radius)?;
    let spacing = positive("--spacing", a.spacing)?;
    let p = a.bond_probability;
    if !(0.0..=1.0).contains(&p) {
        return Err(format!("expected --bond-probability in [0, 1], found {p}"));
    }
    let n_max = (radius / spacing).floor() as i64;
    if n_max < 3 {
        return Err(format!("expected --radius at least 3 spacings, found {radius} with --spacing {spacing}"));
    }
    if n_max > MAX_SPACINGS {
        return Err(format!("expected --radius at most {MAX_SPACINGS} spacings, found {radius} with --spacing {spacing}"));
    }
    let centre = vec3("--centre", &a.centre)?;
    let at = |i: i64, j: i64| DVec3::new((i as f64 + 0.5 * j as f64) * spacing, j as f64 * spacing * 3f64.sqrt() / 2.0, 0.0);
    let inside = |i: i64, j: i64| at(i, j).length() <= radius;
    let rim = |i: i64, j: i64| at(i, j).length() > radius - spacing;
    let mut w = Writer::new(1);
    let mut ids = std::collections::HashMap::new();
    let span = 2 * n_max + 2;
    for j in -span..=span {
        for i in -span..=span {
            if inside(i, j) {
                let type_name = if rim(i, j) { &a.rim_type } else { &a.particle_type };
                ids.insert((i, j), w.particle(type_name, centre + at(i, j), None));
            }
        }
    }
    let draws = Draws::new(a.common.seed, stream::LATTICE);
    let present = |i: i64, j: i64, d: usize| -> bool {
        let (di, dj) = DIRECTIONS[d];
        if !(ids.contains_key(&(i, j)) && ids.contains_key(&(i + di, j + dj))) || (rim(i, j) && rim(i + di, j + dj)) {
            return false;
        }
        let item = (((i + INDEX_OFFSET) as u64) << 32) | (j + INDEX_OFFSET) as u64;
        p >= 1.0 || draws.uniform(item, d as u32) < p
    };
    let mut keys: Vec<(i64, i64)> = ids.keys().copied().collect();
    keys.sort_by_key(|&(i, j)| (j, i));
    let (mut bonds, mut free_ends) = (0usize, 0usize);
    for &(i, j) in &keys {
        for (d, (di, dj)) in DIRECTIONS.iter().enumerate() {
            if present(i, j, d) {
                w.bond(&a.bond_type, ids[&(i, j)], ids[&(i + di, j + dj)]);
                bonds += 1;
                free_ends += usize::from(!rim(i, j)) + usize::from(!rim(i + di, j + dj));
            }
        }
    }
    let mut angles = 0usize;
    if a.bending {
        for &(i, j) in &keys {
            for (d, (di, dj)) in DIRECTIONS.iter().enumerate() {
                if present(i - di, j - dj, d) && present(i, j, d) {
                    w.angle(&a.angle_type, ids[&(i - di, j - dj)], ids[&(i, j)], ids[&(i + di, j + dj)]);
                    angles += 1;
                }
            }
        }
    }
    if a.dipole {
        w.bond(&a.dipole_bond_type, ids[&(-1, 0)], ids[&(1, 0)]);
    }
    w.set_rest_from_geometry(a.common.rest_from_geometry);
    let nodes = keys.len();
    let rims = keys.iter().filter(|&&(i, j)| rim(i, j)).count();
    let free = nodes - rims;
    w.fixed_cube(centre, radius + spacing)?;
    let mut lines = vec![
        format!(
            "{nodes} nodes in a disc of radius {radius} (spacing a = {spacing}), {rims} `{}` on the rim (|r| > R − a: declare `fixed`), {free} `{}`",
            a.rim_type, a.particle_type
        ),
        format!(
            "{bonds} bonds `{}` of r0 = a = {spacing:e} (bond probability {p}); connectivity z = {:.6} bonds per free node (6p = {:.6} in the bulk)",
            a.bond_type,
            free_ends as f64 / free.max(1) as f64,
            6.0 * p
        ),
        format!(
            "area per node √3a²/2 = {:.6e} µm², disc area πR² = {:.6e} µm²; fixed box half-width R + a = {}",
            3f64.sqrt() / 2.0 * spacing * spacing,
            PI * radius * radius,
            radius + spacing
        ),
    ];
    if a.bending {
        lines.push(format!(
            "{angles} angles `{}` on collinear bond pairs (fibres along the lattice lines): `angle {} wlc_bending kappa κ l0 {spacing:e}`",
            a.angle_type, a.angle_type
        ));
    }
    if a.dipole {
        lines.push(format!(
            "force dipole: one bond `{}` between nodes {} and {} (at ∓a along x from the centre, length 2a = {:e})",
            a.dipole_bond_type,
            ids[&(-1, 0)],
            ids[&(1, 0)],
            2.0 * spacing
        ));
    }
    Ok(w.finish(
        &format!("Diluted triangular lattice: disc of radius {radius}, bond probability {p}, seed {}", a.common.seed),
        "lattice",
        lines,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn full_lattice_has_six_bonds_per_bulk_node_and_dilution_removes_about_one_minus_p() {
        let full = lattice(&LatticeArgs { radius: 8.0, ..Default::default() }).unwrap();
        let half = lattice(&LatticeArgs { radius: 8.0, bond_probability: 0.5, ..Default::default() }).unwrap();
        let ratio = half.bonds as f64 / full.bonds as f64;
        assert!((ratio - 0.5).abs() < 0.08, "{ratio}");
        assert!(full.summary().contains("connectivity z = 6.000000 "), "{}", full.summary());
        let none = lattice(&LatticeArgs { bond_probability: 0.0, dipole: true, ..Default::default() }).unwrap();
        assert_eq!(none.bonds, 1);
    }

    #[test]
    fn a_larger_probability_keeps_the_bonds_of_a_smaller_one() {
        let bonds = |p: f64| -> Vec<String> {
            let t = lattice(&LatticeArgs { radius: 6.0, bond_probability: p, ..Default::default() }).unwrap().text;
            t.lines().filter(|l| l.starts_with("link ")).map(str::to_string).collect()
        };
        let (low, high) = (bonds(0.4), bonds(0.7));
        assert!(low.len() < high.len());
        assert!(low.iter().all(|b| high.contains(b)));
    }

    #[test]
    fn bad_options_are_refused() {
        assert!(lattice(&LatticeArgs { bond_probability: 1.5, ..Default::default() }).is_err());
        assert!(lattice(&LatticeArgs { radius: 2.0, ..Default::default() }).is_err());
        assert!(lattice(&LatticeArgs { spacing: -1.0, ..Default::default() }).is_err());
    }
}

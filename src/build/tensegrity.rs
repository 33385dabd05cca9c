//! `cellmd build tensegrity`: a tensegrity cell, the discrete-element model of
//! an adherent mesenchymal stem cell of Vassaux & Milan (Biomech. Model.
//! Mechanobiol. 16, 1295, 2017) reduced to what a force field of cables and
//! springs needs.
//!
//! # Geometry
//!
//! - **Cortex** (Vassaux & Milan's cell membrane with its actomyosin cortex): an
//!   icosphere of `--level` n (10·4ⁿ + 2 nodes) and `--radius` R (µm) around
//!   `--centre`; its mesh edges are bonds of `--bond-type` (default `edge`):
//!   give them the `cable` law with a pre-strain τ > 0 (the contractile
//!   cortex). Node and bond types as for `cellmd build icosphere`.
//! - **Nucleus** (`--nucleus RN`, µm): a concentric icosphere of the same
//!   level, edges of `--nucleus-bond-type` (Vassaux & Milan's nuclear membrane; a
//!   `spring` law carries the compression the struts put on it). Without a
//!   nucleus a single **centrosome** node (`--centrosome-type`) sits at the
//!   centre instead.
//! - Vassaux & Milan's membranes are nets of cables and springs, not surfaces, so
//!   the shells are written as nodes and edges alone; `--bodies` also writes
//!   them as closed bodies with outward-wound faces (the cortex body 1 of
//!   `--body-type`, the nucleus body 2 of `--nucleus-body-type`), for `body`
//!   terms such as `turgor` (the cytosol's and the nucleoplasm's resistance
//!   to compression, which Vassaux & Milan model with packed particles).
//! - **Radial elements**: the cortex and the nucleus share their directions
//!   (node k of both lies on the same ray), so elements joining a cortex node
//!   to the nucleus node on its ray (or to the centrosome) all have length
//!   L = R − RN (R without a nucleus), and each bond type one rest length:
//!   - a **microtubule** strut on M of the rays (`--strut-type`, default
//!     `microtubule`; give it the `spring` law, which carries compression);
//!   - a **stress fibre** on the ray of each focal adhesion: a chain of
//!     `--fibre-segments` m cables (`--stress-fibre-type`, default
//!     `stress_fibre`, each L/m long) with m − 1 beads (`--fibre-bead-type`)
//!     between, running from the adhesion towards the nucleus centre as Vassaux
//!     & Milan grow their fibres. A ray may carry a strut too (microtubules reach
//!     focal adhesions), and some rays carry neither.
//! - **Actin cables** (`--cable-type`, default `actin`; with a nucleus): the
//!   model's microfilament and intermediate-filament networks joining the
//!   cortex to the nucleus, here a cable from every cortex node to the
//!   nucleus node on each neighbouring ray (two per mesh edge, crossing). Not
//!   radial, they brace the cortex against turning about the nucleus — with
//!   radial elements alone a twist of one shell against the other shortens
//!   every ray, a mechanism through which the pre-stressed cortex collapses.
//!   Their lengths spread with the mesh's edge angles; the summary prints it.
//! - **Focal adhesions** (`--focal-adhesions F`, default 0): the F cortex nodes
//!   lowest in z (the ventral side; ties by node order) take the particle
//!   type `--adhesion-type` (default `focal_adhesion`), so the force field can
//!   fix them (`particle focal_adhesion fixed`) or hold them on a substrate.
//! - **Which rays carry microtubules** (`--microtubules M`, default half of
//!   the rays): Vassaux & Milan draw their microtubules around a
//!   centrosome direction c, itself uniform on the sphere, with an angular
//!   spread σ² = π/2. Here c is drawn from `--seed`, and M rays are drawn
//!   without replacement with weights w_k = exp(−θ_k²/(2σ²)), θ_k the angle
//!   of ray k from c and σ = `--spread` (rad, default √(π/2)): each ray gets
//!   the key ln(u_k)/w_k from its own uniform u_k and the M largest keys win
//!   (Efraimidis–Spirakis), so the struts cluster around c and a large σ
//!   spreads them evenly.
//!
//! Particle ids: the cortex nodes (1 … N), the nucleus nodes or the
//! centrosome, then the stress-fibre beads fibre by fibre. Bonds: the cortex
//! edges, the nucleus edges, the radial elements ray by ray, then the actin
//! cables edge by edge. `--box HALF_WIDTH` adds a fixed cubic `[ box ]`
//! around the centre.
//!
//! # The self-stressed state
//!
//! With pre-strained cables (τ > 0) the cortex pulls every node inwards and
//! the actin cables pull the cortex towards the nucleus; the struts push back,
//! so at equilibrium the cables are in tension and the struts in compression
//! with no load from outside: the structure holds its shape by prestress
//! (Vassaux & Milan 2017, after Ingber's cellular tensegrity). Without pre-strain the
//! same structure built at its rest lengths carries no force at all: exactly
//! so with `--rest-from-geometry` (each bond's length as built is its own
//! r0, e.g. the actin cables, whose lengths spread), and τ then pre-strains
//! every cable relative to its own length.
//!
//! It holds only while its cables stay taut, and nothing here resists a
//! change of volume: struts pivot about their ends, so a pre-stressed cable
//! cortex can fold up, and the spring nucleus, a triangulated shell without
//! bending stiffness, buckles inwards under the struts. Vassaux & Milan fill
//! the cell with packed cytosol particles and the nucleus with nucleoskeleton
//! particles; here `--bodies` lets the force field give both shells a
//! `turgor` term instead. In the level-2 cell of `tests/suite/build.rs` (a strut on
//! every ray, 12 fixed adhesions) every cable stays taut and every strut
//! compressed with turgor (100 Pa cytosol, 5 kPa nucleus); without it a
//! manual run ended with 237 of the 480 cortex cables slack and the cortex
//! crumpled. A strut distribution clustered around the centrosome also
//! pushes the nucleus off centre unless something holds it.
//!
//! For level 0 (an icosahedron: all edges equal, all nodes alike, the rays of
//! neighbours at cos θ = 1/√5) with a strut on every ray, symmetry keeps the
//! shells icosahedra of radii R′ and RN′, and the equilibrium reduces to two
//! equations. Each cortex node balances the strut's push
//! C = k_s·(L − (R′ − RN′))/L against its five edges' pull Q·T_c
//! (Q = 5/(2 sin 72°): each edge pulls inwards with the fraction q/2 of its
//! tension, q = 1/sin 72° the edge over the radius) and its five actin
//! cables', 5·T_a·(R′ − RN′/√5)/d′; each nucleus node balances C against its
//! compressed edges, Q·k_n·(1 − RN′/RN), and the cables' outward pull
//! 5·T_a·(R′/√5 − RN′)/d′ (d′ the cable length, T_c and T_a the `cable`
//! tensions at R′ and d′). `tests/suite/build.rs` solves these by Newton's method
//! and checks the engine's relaxed structure against them.
//!
//! The summary prints the counts, the radial length L (r0 of the struts, and
//! L/m of the fibre cables), the actin cables' lengths, both shells' edge
//! lengths and volumes, the centrosome direction and how closely the struts
//! follow it.

use std::f64::consts::FRAC_PI_2;

use glam::DVec3;

use super::icosphere::{unit_icosphere, ShellOptions, ShellSpec};
use super::substrate::SubstrateOptions;
use super::{min_mean_max, positive, stream, vec3, Built, Common, Draws, Writer};

/// Command-line options of `cellmd build tensegrity`.
#[derive(clap::Args, Clone, Debug)]
pub struct TensegrityArgs {
    /// Radius of the cortex (µm).
    #[arg(allow_negative_numbers = true, long)]
    pub radius: f64,
    /// Icosphere subdivision level of the cortex and the nucleus (10·4ⁿ + 2 nodes each).
    #[arg(long, default_value_t = 2)]
    pub level: u32,
    /// Centre of the cell.
    #[arg(long, num_args = 3, value_names = ["X", "Y", "Z"], allow_negative_numbers = true, default_values_t = [0.0, 0.0, 0.0])]
    pub centre: Vec<f64>,
    // The cortex's and the nucleus' types; without --nucleus a centrosome node takes its place.
    #[command(flatten)]
    pub shell: ShellOptions,
    /// Also write the cortex and the nucleus as bodies (closed surfaces with faces) for `body` terms.
    #[arg(long)]
    pub bodies: bool,
    /// Microtubule struts [default: half of the rays].
    #[arg(long)]
    pub microtubules: Option<u32>,
    /// Angular spread σ (rad) of the microtubules around the centrosome direction [default: √(π/2), Vassaux & Milan's σ² = π/2].
    #[arg(allow_negative_numbers = true, long)]
    pub spread: Option<f64>,
    /// Focal adhesions: the cortex nodes lowest in z, each the foot of a stress fibre.
    #[arg(long, default_value_t = 0)]
    pub focal_adhesions: u32,
    /// Cables per stress fibre (with one bead fewer between them).
    #[arg(long, default_value_t = 4)]
    pub fibre_segments: u32,
    #[command(flatten)]
    pub types: TensegrityTypes,
    // `--substrate flat|R` and its options: a rigid substrate under the cell.
    #[command(flatten)]
    pub substrate: SubstrateOptions,
    /// Also write a fixed (non-periodic) cubic `[ box ]` of this half-width around the centre.
    #[arg(allow_negative_numbers = true, long = "box", value_name = "HALF_WIDTH")]
    pub box_half_width: Option<f64>,
    #[command(flatten)]
    pub common: Common,
}

impl Default for TensegrityArgs {
    fn default() -> Self {
        Self {
            radius: 10.0,
            level: 2,
            centre: vec![0.0; 3],
            shell: ShellOptions { nucleus: Some(5.0), ..ShellOptions::default() },
            bodies: false,
            microtubules: None,
            spread: None,
            focal_adhesions: 0,
            fibre_segments: 4,
            types: TensegrityTypes::default(),
            substrate: SubstrateOptions::default(),
            box_half_width: None,
            common: Common { seed: 1, output: "tensegrity.top".into(), rest_from_geometry: false },
        }
    }
}

/// The bond and particle types of `cellmd build tensegrity`'s struts, cables,
/// stress fibres, focal adhesions and centrosome.
#[derive(clap::Args, Clone, Debug)]
pub struct TensegrityTypes {
    /// Bond type of the microtubule struts.
    #[arg(long, default_value = "microtubule")]
    pub strut_type: String,
    /// Bond type of the actin cables from cortex to nucleus.
    #[arg(long, default_value = "actin")]
    pub cable_type: String,
    /// Bond type of the stress-fibre cables.
    #[arg(long, default_value = "stress_fibre")]
    pub stress_fibre_type: String,
    /// Particle type of the beads inside stress fibres.
    #[arg(long, default_value = "fibre_bead")]
    pub fibre_bead_type: String,
    /// Particle type of the focal adhesions.
    #[arg(long, default_value = "focal_adhesion")]
    pub adhesion_type: String,
    /// Particle type of the centrosome node (without --nucleus).
    #[arg(long, default_value = "centrosome")]
    pub centrosome_type: String,
}

impl Default for TensegrityTypes {
    fn default() -> Self {
        Self {
            strut_type: "microtubule".into(),
            cable_type: "actin".into(),
            stress_fibre_type: "stress_fibre".into(),
            fibre_bead_type: "fibre_bead".into(),
            adhesion_type: "focal_adhesion".into(),
            centrosome_type: "centrosome".into(),
        }
    }
}

/// The cortex nodes of the focal adhesions: the `adhesions` lowest in z (ties by index).
fn lowest(unit: &[DVec3], adhesions: usize) -> Vec<bool> {
    let mut order: Vec<usize> = (0..unit.len()).collect();
    order.sort_by(|&i, &j| unit[i].z.total_cmp(&unit[j].z).then(i.cmp(&j)));
    let mut chosen = vec![false; unit.len()];
    for &k in &order[..adhesions] {
        chosen[k] = true;
    }
    chosen
}

/// The rays that carry a microtubule: `struts` of the `unit` directions,
/// drawn without replacement with weights exp(−θ²/(2σ²)) of their angle θ
/// from `towards` (keys ln(u)/w, the largest win).
fn draw_struts(unit: &[DVec3], struts: usize, towards: DVec3, sigma: f64, draws: &Draws) -> Vec<bool> {
    let mut keys: Vec<(f64, usize)> = (0..unit.len())
        .map(|k| {
            let theta = unit[k].angle_between(towards);
            (draws.uniform(k as u64, 1).ln() * (theta * theta / (2.0 * sigma * sigma)).exp(), k)
        })
        .collect();
    keys.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    let mut chosen = vec![false; unit.len()];
    for &(_, k) in &keys[..struts] {
        chosen[k] = true;
    }
    chosen
}

/// `x` rounded to 4 decimals, a rounding error around 0 printed as 0 (not −0).
fn four_places(x: f64) -> f64 {
    (x * 1e4).round() / 1e4 + 0.0
}

/// `cellmd build tensegrity`: a cortex shell, a nucleus shell (or a
/// centrosome node), radial microtubule struts and, from each focal
/// adhesion, a stress fibre, and actin cables from each cortex node to the
/// nucleus nodes on its neighbours' rays — every component its own bond type. The construction and its self-stressed
/// equilibrium are in the module documentation (`src/build/tensegrity.rs`).
pub fn tensegrity(a: &TensegrityArgs) -> Result<Built, String> {
    let radius = positive("--radius", a.radius)?;
    let centre = vec3("--centre", &a.centre)?;
    if a.level > 6 {
        return Err(format!("expected --level <= 6, found {}", a.level));
    }
    let nucleus = a.shell.nucleus(radius)?;
    let sigma = positive("--spread", a.spread.unwrap_or(FRAC_PI_2.sqrt()))?;
    if a.fibre_segments == 0 {
        return Err("expected --fibre-segments >= 1, found 0".into());
    }
    let (unit, mesh) = unit_icosphere(a.level);
    let rays = unit.len();
    let adhesions = a.focal_adhesions as usize;
    if adhesions > rays {
        return Err(format!("expected --focal-adhesions <= {rays} (the cortex nodes), found {adhesions}"));
    }
    let struts = a.microtubules.map_or(rays / 2, |m| m as usize);
    if struts > rays {
        return Err(format!("expected --microtubules <= {rays} (the cortex nodes), found {struts}"));
    }
    let draws = Draws::new(a.common.seed, stream::TENSEGRITY);
    let towards = draws.unit_vector(0, 0);
    let (fibre, strut) = (lowest(&unit, adhesions), draw_struts(&unit, struts, towards, sigma, &draws));

    let mut w = Writer::new(1);
    w.set_rest_from_geometry(a.common.rest_from_geometry);
    let (cortex_bond, _) = a.shell.bond_types();
    let cortex = ShellSpec {
        mesh: &mesh,
        unit: &unit,
        radius,
        centre,
        particle_type: &a.shell.particle_type,
        body_type: &a.shell.body_type,
        bond_type: cortex_bond.as_deref(),
        body_id: a.bodies.then_some(1),
    }
    .write(&mut w);
    let body = |id: u64| if a.bodies { format!("body {id}, ") } else { String::new() };
    let mut lines = vec![format!("cortex ({}radius {radius:?}): {}", body(1), cortex.summary())];
    let inner: Vec<u64> = match &nucleus {
        Some(n) => {
            let first = w.next_id();
            let shell = ShellSpec {
                mesh: &mesh,
                unit: &unit,
                radius: n.radius,
                centre,
                particle_type: &n.particle_type,
                body_type: &n.body_type,
                bond_type: n.bond_type.as_deref(),
                body_id: a.bodies.then_some(2),
            }
            .write(&mut w);
            lines.push(format!("nucleus ({}radius {:?}): {}", body(2), n.radius, shell.summary()));
            (first..first + rays as u64).collect()
        }
        None => {
            lines.push(format!("no nucleus: the rays meet at a centrosome node `{}` at the centre", a.types.centrosome_type));
            vec![w.particle(&a.types.centrosome_type, centre, None); rays]
        }
    };
    let length = radius - nucleus.as_ref().map_or(0.0, |n| n.radius);
    let m = a.fibre_segments as usize;
    for k in 0..rays {
        let outer = k as u64 + 1;
        if strut[k] {
            w.bond(&a.types.strut_type, inner[k], outer);
        }
        if fibre[k] {
            w.set_type(outer, &a.types.adhesion_type);
            let (from, to) = (w.position(outer), w.position(inner[k]));
            let mut chain = vec![outer];
            chain.extend((1..m).map(|s| w.particle(&a.types.fibre_bead_type, from.lerp(to, s as f64 / m as f64), None)));
            chain.push(inner[k]);
            for pair in chain.windows(2) {
                w.bond(&a.types.stress_fibre_type, pair[0], pair[1]);
            }
        }
    }
    let mut actin = Vec::new();
    if nucleus.is_some() {
        for e in mesh.edges() {
            let [i, j] = e.ends.map(|k| k as usize);
            for (outer, towards_inner) in [(i, j), (j, i)] {
                let (x, y) = (outer as u64 + 1, inner[towards_inner]);
                actin.push((w.position(y) - w.position(x)).length());
                w.bond(&a.types.cable_type, x, y);
            }
        }
    }
    let lowest = (1..=rays as u64).map(|id| w.position(id).z).fold(f64::INFINITY, f64::min);
    lines.extend(a.substrate.write(&mut w, centre, lowest, radius, "the cell")?);
    if let Some(h) = a.box_half_width {
        w.fixed_cube(centre, h)?;
    }
    lines.push(format!(
        "radial elements of length L = {length:?} (r0): {struts} microtubule struts `{}`, {adhesions} stress fibres `{}` of {m} cables of L/{m} = {:?} (r0) from the focal adhesions `{}` (the {adhesions} cortex nodes lowest in z)",
        a.types.strut_type,
        a.types.stress_fibre_type,
        length / m as f64,
        a.types.adhesion_type
    ));
    if !actin.is_empty() {
        let [lo, mean, hi] = min_mean_max(&actin);
        lines.push(format!(
            "{} actin cables `{}` from each cortex node to the nucleus nodes of its neighbours' rays: length min {lo:.6e} mean {mean:.6e} max {hi:.6e} (for r0)",
            actin.len(),
            a.types.cable_type
        ));
    }
    let struts_cos: Vec<f64> = (0..rays).filter(|&k| strut[k]).map(|k| unit[k].dot(towards)).collect();
    lines.push(format!(
        "centrosome direction ({:.6}, {:.6}, {:.6}) from seed {}; struts drawn with spread {sigma:.6} rad: mean cos to it {:.4} (all rays: {:.4})",
        towards.x,
        towards.y,
        towards.z,
        a.common.seed,
        four_places(struts_cos.iter().sum::<f64>() / struts_cos.len().max(1) as f64),
        four_places(unit.iter().map(|u| u.dot(towards)).sum::<f64>() / rays as f64)
    ));
    lines.push(format!(
        "self-stress: cables (`{}`, `{}`, `{}`) with pre-strain tau > 0 put the struts `{}` (spring law) in compression",
        a.shell.bond_type, a.types.cable_type, a.types.stress_fibre_type, a.types.strut_type
    ));
    let title = format!("Tensegrity cell: radius {radius:?}, icosphere level {}, seed {}", a.level, a.common.seed);
    Ok(w.finish(&title, "tensegrity", lines))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::build::testing::{bonds_of, parse};

    #[test]
    fn struts_and_fibres_are_radial_and_actin_cables_cross_to_the_neighbours_rays() {
        let a = TensegrityArgs {
            focal_adhesions: 10,
            centre: vec![1.0, 2.0, 12.0],
            box_half_width: Some(12.0),
            bodies: true,
            ..TensegrityArgs::default()
        };
        let built = tensegrity(&a).unwrap();
        let top = parse(&built);
        // 162 cortex and 162 nucleus nodes, 10 fibres of 3 beads; 81 struts (half the rays), two cables per edge.
        assert_eq!(top.ids.len(), 324 + 30);
        assert_eq!((built.bodies, built.triangles), (2, 640));
        assert_eq!(bonds_of(&top, "edge").count(), 480);
        assert_eq!(bonds_of(&top, "nucleus_edge").count(), 480);
        assert_eq!(bonds_of(&top, "microtubule").count(), 81);
        assert_eq!(bonds_of(&top, "actin").count(), 960);
        assert_eq!(bonds_of(&top, "stress_fibre").count(), 40);
        let c = DVec3::new(1.0, 2.0, 12.0);
        for [x, y] in bonds_of(&top, "microtubule") {
            // Radial: on one ray from the centre, 5 µm long.
            assert!(((x - y).length() - 5.0).abs() < 1e-12);
            assert!((x - c).normalize().dot((y - c).normalize()) > 1.0 - 1e-12);
        }
        // An actin cable joins a cortex node to the nucleus node on a
        // neighbour's ray: that ray's cortex node is one edge away.
        let longest_edge = bonds_of(&top, "edge").map(|[x, y]| (x - y).length()).fold(0.0, f64::max);
        for [x, y] in bonds_of(&top, "actin") {
            assert!(((x - c).length() - 10.0).abs() < 1e-12 && ((y - c).length() - 5.0).abs() < 1e-12);
            let d = (c + (y - c) * 2.0 - x).length();
            assert!(d > 0.5 * longest_edge && d < longest_edge + 1e-12, "{d}");
        }
        assert!(bonds_of(&top, "stress_fibre").all(|[x, y]| ((x - y).length() - 1.25).abs() < 1e-12));
        // The focal adhesions are the lowest cortex nodes: none lower than any other cortex node.
        let adhesion = |k: usize| top.type_names[k].text == "focal_adhesion";
        let top_fa = (0..162).filter(|&k| adhesion(k)).map(|k| top.positions[k].z).fold(f64::NEG_INFINITY, f64::max);
        let low_other = (0..162).filter(|&k| !adhesion(k)).map(|k| top.positions[k].z).fold(f64::INFINITY, f64::min);
        assert_eq!((0..162).filter(|&k| adhesion(k)).count(), 10);
        assert!(top_fa <= low_other, "{top_fa} {low_other}");
        // On the ventral cap: 10 of 162 nodes of equal area span cos θ > 1 − 2·10/162 ≈ 0.88.
        assert!(top_fa < c.z - 8.0, "{top_fa}");
        assert!(built.summary().contains("radial elements of length L = 5.0 (r0): 81 microtubule struts"), "{}", built.summary());
        assert!(built.summary().contains("960 actin cables `actin`"), "{}", built.summary());
        assert!(built.summary().starts_with("cortex (body 1, radius 10.0): 162 nodes"), "{}", built.summary());
        // Without --bodies: the same nodes and bonds, no bodies or faces.
        let bare = tensegrity(&TensegrityArgs { bodies: false, ..a }).unwrap();
        assert_eq!((bare.particles, bare.bonds, bare.bodies, bare.triangles), (built.particles, built.bonds, 0, 0));
        assert!(parse(&bare).body_of.iter().all(Option::is_none));
    }

    #[test]
    fn the_struts_cluster_around_the_centrosome_by_seed() {
        let a = |seed, spread| TensegrityArgs {
            spread,
            common: Common { seed, output: "t.top".into(), rest_from_geometry: false },
            microtubules: Some(40),
            ..TensegrityArgs::default()
        };
        let built = tensegrity(&a(5, None)).unwrap();
        assert_eq!(tensegrity(&a(5, None)).unwrap().text, built.text);
        assert_ne!(tensegrity(&a(6, None)).unwrap().text, built.text);
        // Mean cosine of the struts to the centrosome direction. Uniformly
        // random rays would give 0 ± 0.09 (1/√3 over √40); Vassaux & Milan's spread
        // must lie clearly above that, and a narrow spread takes the cap of
        // the 40 nearest rays, whose mean cosine is (1 + cos θ_cap)/2 with
        // cos θ_cap = 1 − 2·40/162 (equal area per ray).
        let cosine = |t: &Built| -> f64 {
            let line = t.lines.iter().find(|l| l.starts_with("centrosome direction")).unwrap();
            line.split("mean cos to it ").nth(1).unwrap().split(' ').next().unwrap().parse().unwrap()
        };
        let (wide, narrow) = (cosine(&built), cosine(&tensegrity(&a(5, Some(0.3))).unwrap()));
        let cap = (2.0 - 80.0 / 162.0) / 2.0;
        assert!(wide > 3.0 / (3f64 * 40.0).sqrt() && wide < narrow, "{wide} {narrow}");
        assert!((narrow - cap).abs() < 0.05, "{narrow} {cap}");
        let draws = Draws::new(5, stream::TENSEGRITY);
        let (unit, _) = unit_icosphere(2);
        let c = draws.unit_vector(0, 0);
        let strut = draw_struts(&unit, 40, c, 0.3, &draws);
        let mean = (0..unit.len()).filter(|&k| strut[k]).map(|k| unit[k].dot(c)).sum::<f64>() / 40.0;
        assert!((mean - narrow).abs() < 1e-4, "{mean} {narrow}");
    }

    #[test]
    fn without_a_nucleus_the_rays_meet_at_the_centrosome() {
        let a = TensegrityArgs { level: 0, shell: ShellOptions::default(), microtubules: Some(12), ..TensegrityArgs::default() };
        let built = tensegrity(&a).unwrap();
        let top = parse(&built);
        assert_eq!(top.ids.len(), 13);
        assert_eq!(top.type_names[12].text, "centrosome");
        assert_eq!(top.positions[12], DVec3::ZERO);
        let struts: Vec<_> = top.bonds.iter().filter(|b| b.type_name.text == "microtubule").collect();
        assert_eq!(struts.len(), 12);
        assert!(struts.iter().all(|b| b.particles[0] == 12));
        assert_eq!(top.bonds.len(), 12 + 30);
        assert!(bonds_of(&top, "microtubule").all(|[x, y]| ((x - y).length() - 10.0).abs() < 1e-12));
    }

    #[test]
    fn the_committed_tensegrity_cell_is_what_the_builder_writes() {
        let a = TensegrityArgs {
            centre: vec![0.0, 0.0, 10.0],
            microtubules: Some(162),
            focal_adhesions: 30,
            fibre_segments: 3,
            bodies: true,
            common: Common { seed: 3, output: "t.top".into(), rest_from_geometry: false },
            ..TensegrityArgs::default()
        };
        let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/topologies/tensegrity_cell.top")).unwrap();
        assert_eq!(tensegrity(&a).unwrap().text, text);
    }

    #[test]
    fn bad_options_say_what_was_expected() {
        let a = TensegrityArgs::default();
        assert_eq!(tensegrity(&TensegrityArgs { radius: -1.0, ..a.clone() }).unwrap_err(), "expected --radius > 0, found -1");
        assert_eq!(
            tensegrity(&TensegrityArgs { microtubules: Some(200), ..a.clone() }).unwrap_err(),
            "expected --microtubules <= 162 (the cortex nodes), found 200"
        );
        assert!(tensegrity(&TensegrityArgs { focal_adhesions: 163, ..a.clone() }).unwrap_err().contains("--focal-adhesions <= 162"));
        assert_eq!(tensegrity(&TensegrityArgs { fibre_segments: 0, ..a.clone() }).unwrap_err(), "expected --fibre-segments >= 1, found 0");
        assert_eq!(tensegrity(&TensegrityArgs { spread: Some(0.0), ..a.clone() }).unwrap_err(), "expected --spread > 0, found 0");
        let big = TensegrityArgs { shell: ShellOptions { nucleus: Some(10.0), ..ShellOptions::default() }, ..a };
        assert_eq!(tensegrity(&big).unwrap_err(), "expected 0 < --nucleus RADIUS < --radius 10, found 10");
    }
}

//! `cellmd build filopodium`: see [`filopodium`](fn@super::filopodium) for the construction.

use std::f64::consts::TAU;

use glam::DVec3;

use super::{positive, stream, vec3, Built, Chain, Common, CrosslinkerTypes, Crosslinks, Draws, Writer};

/// Command-line options of `cellmd build filopodium`.
#[derive(clap::Args, Clone, Debug)]
pub struct FilopodiumArgs {
    /// Number of filaments in the bundle.
    #[arg(long)]
    pub filaments: u32,
    #[command(flatten)]
    pub chain: Chain,
    /// Distance between neighbouring filaments (µm; fascin bundles: ~0.012).
    #[arg(allow_negative_numbers = true, long)]
    pub spacing: f64,
    /// Centre of the bundle's base.
    #[arg(long, num_args = 3, value_names = ["X", "Y", "Z"], allow_negative_numbers = true, default_values_t = [0.0, 0.0, 0.0])]
    pub base: Vec<f64>,
    /// Direction of the bundle [default: +z].
    #[arg(long, num_args = 3, value_names = ["X", "Y", "Z"], allow_negative_numbers = true)]
    pub direction: Option<Vec<f64>>,
    /// A crosslink site every this many beads (from the first).
    #[arg(long, default_value_t = 1)]
    pub crosslink_every: u32,
    /// Probability that a crosslink site between neighbours is taken.
    #[arg(allow_negative_numbers = true, long, default_value_t = 1.0)]
    pub crosslink_probability: f64,
    /// Crosslinker bond types and the fraction of crosslinks each takes, `NAME:FRACTION,…`.
    #[arg(long, default_value = "fascin")]
    pub crosslinker_types: CrosslinkerTypes,
    /// Also write a fixed (non-periodic) cubic `[ box ]` of this half-width around the bundle's midpoint.
    #[arg(allow_negative_numbers = true, long = "box", value_name = "HALF_WIDTH")]
    pub box_half_width: Option<f64>,
    #[command(flatten)]
    pub common: Common,
}

impl Default for FilopodiumArgs {
    fn default() -> Self {
        Self {
            filaments: 7,
            chain: Chain { length: 2.0, segments: Some(20), ..Chain::default() },
            spacing: 0.02,
            base: vec![0.0; 3],
            direction: None,
            crosslink_every: 1,
            crosslink_probability: 1.0,
            crosslinker_types: "fascin".parse().unwrap(),
            box_half_width: None,
            common: Common { seed: 1, output: "filopodium.top".into(), rest_from_geometry: false },
        }
    }
}

/// The `count` hexagonal-lattice sites (unit spacing) nearest the origin, in
/// order of distance, then angle in [0, 2π).
pub(crate) fn hexagonal_sites(count: usize) -> Vec<(f64, f64)> {
    let reach = ((count as f64).sqrt() as i64) + 2;
    let mut sites: Vec<(i64, f64, f64, f64)> = Vec::new();
    for i in -reach..=reach {
        for j in -reach..=reach {
            let (x, y) = (i as f64 + 0.5 * j as f64, 0.75f64.sqrt() * j as f64);
            // i² + ij + j² is the exact squared distance in units of a².
            sites.push((i * i + i * j + j * j, y.atan2(x).rem_euclid(TAU), x, y));
        }
    }
    sites.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
    sites.into_iter().take(count).map(|s| (s.2, s.3)).collect()
}

/// `cellmd build filopodium`: a bundle of N parallel filaments on a
/// hexagonal lattice of spacing a (the N lattice sites nearest the axis,
/// in order of distance, then angle), all from the base plane through
/// `--base` along `--direction` (default +z). Neighbouring filaments (sites
/// a apart) are crosslinked, fascin-like, between beads of the same index
/// every `--crosslink-every` beads, each such site taken with probability
/// `--crosslink-probability` drawn from `--seed` (1: every site), its bond
/// type drawn from `--crosslinker-types`. A crosslink is perpendicular to the
/// filaments, of length a: its rest length.
pub fn filopodium(a: &FilopodiumArgs) -> Result<Built, String> {
    let (n, ell) = a.chain.segmentation()?;
    let spacing = positive("--spacing", a.spacing)?;
    let base = vec3("--base", &a.base)?;
    let axis = match &a.direction {
        Some(d) => {
            let d = vec3("--direction", d)?;
            positive("the length of --direction", d.length())?;
            d.normalize()
        }
        None => DVec3::Z,
    };
    if a.filaments == 0 || a.filaments > 100_000 {
        return Err(format!("expected 1 <= --filaments <= 100000, found {}", a.filaments));
    }
    if a.crosslink_every == 0 {
        return Err("expected --crosslink-every >= 1, found 0".into());
    }
    let p = a.crosslink_probability;
    if !(0.0..=1.0).contains(&p) {
        return Err(format!("expected 0 <= --crosslink-probability <= 1, found {p}"));
    }
    let (_, bending) = a.chain.bending_line(ell, 17.0)?;
    let draws = Draws::new(a.common.seed, stream::FILOPODIUM);
    let e1 = axis.any_orthonormal_vector();
    let e2 = axis.cross(e1);
    let sites = hexagonal_sites(a.filaments as usize);
    let mut w = Writer::new(1);
    w.set_rest_from_geometry(a.common.rest_from_geometry);
    let mut filaments = Vec::new();
    for &(x, y) in &sites {
        let foot = base + (e1 * x + e2 * y) * spacing;
        let points: Vec<DVec3> = (0..=n).map(|k| foot + axis * (k as f64 * ell)).collect();
        filaments.push(a.chain.write(&mut w, &points));
    }
    let mut pairs = Vec::new();
    let mut neighbours = 0u64;
    for f in 0..sites.len() {
        for g in f + 1..sites.len() {
            let d2 = (sites[f].0 - sites[g].0).powi(2) + (sites[f].1 - sites[g].1).powi(2);
            if (d2 - 1.0).abs() > 1e-9 {
                continue;
            }
            for k in (0..=n).step_by(a.crosslink_every as usize) {
                if p >= 1.0 || draws.uniform(neighbours * (n as u64 + 1) + k as u64, 0) < p {
                    let (i, j) = (filaments[f][k], filaments[g][k]);
                    pairs.push((i, j, (w.position(j) - w.position(i)).length()));
                }
            }
            neighbours += 1;
        }
    }
    let links = Crosslinks::from_pairs(pairs, &a.crosslinker_types, &draws, 1);
    links.write(&mut w, &a.crosslinker_types);
    if let Some(h) = a.box_half_width {
        w.fixed_cube(base + axis * (0.5 * a.chain.length), h)?;
    }
    let lines = vec![
        format!(
            "{} filaments × {} beads on a hexagonal lattice of spacing {spacing:?} ({neighbours} neighbour pairs); {} bonds `{}` of r0 = ℓ = {ell:.12e}, {} angles `{}` each",
            a.filaments,
            n + 1,
            n,
            a.chain.bond_type,
            n.saturating_sub(1),
            a.chain.angle_type
        ),
        format!("{} every {} beads with probability {p}", links.summary(&a.crosslinker_types), a.crosslink_every),
        bending,
    ];
    Ok(w.finish(&format!("Filopodium: a hexagonal bundle of {} filaments, seed {}", a.filaments, a.common.seed), "filopodium", lines))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::build::testing::{bonds_of, parse};

    #[test]
    fn the_lattice_fills_shells_in_order() {
        let s = hexagonal_sites(19);
        assert_eq!(s[0], (0.0, 0.0));
        let r: Vec<f64> = s.iter().map(|(x, y)| (x * x + y * y).sqrt()).collect();
        assert!(r[1..7].iter().all(|r| (r - 1.0).abs() < 1e-12));
        assert!(r[7..13].iter().all(|r| (r - 3f64.sqrt()).abs() < 1e-12));
        assert!(r[13..19].iter().all(|r| (r - 2.0).abs() < 1e-12));
    }

    #[test]
    fn neighbours_are_crosslinked_at_the_spacing() {
        let a = FilopodiumArgs {
            crosslink_every: 5,
            direction: Some(vec![1.0, 1.0, 0.0]),
            box_half_width: Some(3.0),
            ..FilopodiumArgs::default()
        };
        let built = filopodium(&a).unwrap();
        let top = parse(&built);
        assert_eq!(top.ids.len(), 7 * 21);
        // 7 sites: 6 spokes + 6 ring edges = 12 neighbour pairs, beads 0, 5, …, 20.
        let links: Vec<_> = bonds_of(&top, "fascin").collect();
        assert_eq!(links.len(), 12 * 5);
        let axis = DVec3::new(1.0, 1.0, 0.0).normalize();
        for [x, y] in &links {
            assert!(((*x - *y).length() - 0.02).abs() < 1e-12);
            assert!((*x - *y).dot(axis).abs() < 1e-12);
        }
        // Filaments are parallel to the axis.
        for f in 0..7 {
            let d = top.positions[21 * f + 20] - top.positions[21 * f];
            assert!((d - axis * 2.0).length() < 1e-12);
        }
    }

    #[test]
    fn the_probability_thins_the_crosslinks_by_seed() {
        let a = |seed| FilopodiumArgs {
            filaments: 19,
            crosslink_probability: 0.5,
            crosslinker_types: "fascin:0.7,fimbrin:0.3".parse().unwrap(),
            common: Common { seed, output: "f.top".into(), rest_from_geometry: false },
            ..FilopodiumArgs::default()
        };
        let built = filopodium(&a(1)).unwrap();
        let top = parse(&built);
        // 19 sites: 42 neighbour pairs × 21 beads = 882 sites, half taken.
        let links = top.bonds.len() - 19 * 20;
        assert!((300..580).contains(&links), "{links}");
        assert!(bonds_of(&top, "fimbrin").count() > 50);
        assert_eq!(filopodium(&a(1)).unwrap().text, built.text);
        assert_ne!(filopodium(&a(2)).unwrap().text, built.text);
        assert_eq!(filopodium(&FilopodiumArgs { spacing: -0.1, ..a(1) }).unwrap_err(), "expected --spacing > 0, found -0.1");
        assert!(filopodium(&FilopodiumArgs { crosslink_probability: 2.0, ..a(1) }).unwrap_err().contains("probability"));
    }
}

//! `cellmd build aster`: see [`aster`](fn@super::aster) for the construction.

use std::f64::consts::PI;

use glam::DVec3;

use super::{positive, stream, vec3, Built, Chain, Common, Draws, Writer};

/// Command-line options of `cellmd build aster`.
#[derive(clap::Args, Clone, Debug)]
pub struct AsterArgs {
    /// Number of microtubules.
    #[arg(long)]
    pub microtubules: u32,
    #[command(flatten)]
    pub chain: Chain,
    /// Position of the centrosome node.
    #[arg(long, num_args = 3, value_names = ["X", "Y", "Z"], allow_negative_numbers = true, default_values_t = [0.0, 0.0, 0.0])]
    pub centre: Vec<f64>,
    /// Distance from the centre node to each microtubule's first bead [default: the segment length].
    #[arg(allow_negative_numbers = true, long)]
    pub core_radius: Option<f64>,
    /// Particle type of the centre node.
    #[arg(long, default_value = "centrosome")]
    pub centre_type: String,
    /// Bond type between the centre node and each first bead.
    #[arg(long, default_value = "anchor")]
    pub anchor_bond_type: String,
    /// Angle type of centre–first–second bead (radial clamp); none if not given.
    #[arg(long)]
    pub anchor_angle_type: Option<String>,
    /// Also write a fixed (non-periodic) cubic `[ box ]` of this half-width around the centre.
    #[arg(allow_negative_numbers = true, long = "box", value_name = "HALF_WIDTH")]
    pub box_half_width: Option<f64>,
    #[command(flatten)]
    pub common: Common,
}

impl Default for AsterArgs {
    fn default() -> Self {
        Self {
            microtubules: 20,
            chain: Chain { length: 5.0, segments: Some(10), particle_type: "tubulin".into(), ..Chain::default() },
            centre: vec![0.0; 3],
            core_radius: None,
            centre_type: "centrosome".into(),
            anchor_bond_type: "anchor".into(),
            anchor_angle_type: None,
            box_half_width: None,
            common: Common { seed: 1, output: "aster.top".into(), rest_from_geometry: false },
        }
    }
}

/// Fibonacci-lattice direction `k` of `m`.
fn fibonacci(k: u32, m: u32) -> DVec3 {
    let z = 1.0 - (2 * k + 1) as f64 / m as f64;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (s, c) = (k as f64 * PI * (3.0 - 5f64.sqrt())).sin_cos();
    DVec3::new(r * c, r * s, z)
}

/// `cellmd build aster`: M microtubules radiating from a centrosome node.
/// Their directions are the Fibonacci lattice on the sphere (M points of
/// equal area: zₖ = 1 − (2k + 1)/M, φₖ = k·π(3 − √5)), turned as a whole by
/// a rotation uniform on SO(3) drawn from `--seed`, so the directions are
/// evenly spread for any M and the aster's orientation is random. Each
/// microtubule is a straight bead chain from `--core-radius` out to
/// core + L, its first bead bonded to the centre node (`--anchor-bond-type`,
/// rest length the core radius); `--anchor-angle-type` also writes the angle
/// centre–first–second bead, to clamp the microtubule radially (e.g.
/// `harmonic_angle theta0 180`). The default persistence length is 5.2 mm
/// (microtubules).
pub fn aster(a: &AsterArgs) -> Result<Built, String> {
    let (n, ell) = a.chain.segmentation()?;
    let centre = vec3("--centre", &a.centre)?;
    let core = positive("--core-radius", a.core_radius.unwrap_or(ell))?;
    if a.microtubules == 0 {
        return Err("expected --microtubules >= 1, found 0".into());
    }
    let (_, bending) = a.chain.bending_line(ell, 5200.0)?;
    let turn = Draws::new(a.common.seed, stream::ASTER).rotation(0, 0);
    let mut w = Writer::new(1);
    w.set_rest_from_geometry(a.common.rest_from_geometry);
    let hub = w.particle(&a.centre_type, centre, None);
    for k in 0..a.microtubules {
        let d = (turn * fibonacci(k, a.microtubules)).normalize();
        let points: Vec<DVec3> = (0..=n).map(|j| centre + d * (core + j as f64 * ell)).collect();
        let ids = a.chain.write(&mut w, &points);
        w.bond(&a.anchor_bond_type, hub, ids[0]);
        if let Some(t) = &a.anchor_angle_type {
            w.angle(t, hub, ids[0], ids[1]);
        }
    }
    if let Some(h) = a.box_half_width {
        w.fixed_cube(centre, h)?;
    }
    let lines = vec![
        format!(
            "1 centre node `{}` and {} microtubules × {} beads ({} bonds `{}` of r0 = ℓ = {ell:.12e}, {} angles `{}` each); core radius (r0 of `{}`) {core:?}, reach {:?}",
            a.centre_type,
            a.microtubules,
            n + 1,
            n,
            a.chain.bond_type,
            n.saturating_sub(1),
            a.chain.angle_type,
            a.anchor_bond_type,
            core + a.chain.length
        ),
        bending,
    ];
    Ok(w.finish(&format!("Aster: {} microtubules of length {:?}, seed {}", a.microtubules, a.chain.length, a.common.seed), "aster", lines))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::build::testing::parse;

    #[test]
    fn microtubules_radiate_from_the_centre_evenly() {
        let a = AsterArgs {
            centre: vec![1.0, -1.0, 2.0],
            anchor_angle_type: Some("clamp".into()),
            box_half_width: Some(8.0),
            ..AsterArgs::default()
        };
        let built = aster(&a).unwrap();
        let top = parse(&built);
        assert_eq!(top.ids.len(), 1 + 20 * 11);
        assert_eq!(top.bonds.len(), 20 * 11);
        assert_eq!(top.angles.len(), 20 * 10);
        let c = DVec3::new(1.0, -1.0, 2.0);
        assert_eq!(top.positions[0], c);
        let mut dirs = Vec::new();
        for m in 0..20 {
            let beads = &top.positions[1 + 11 * m..1 + 11 * (m + 1)];
            let d = (beads[0] - c).normalize();
            for (j, p) in beads.iter().enumerate() {
                // Radial: on the ray from the centre, at core + jℓ.
                assert!((*p - c - d * (0.5 + 0.5 * j as f64)).length() < 1e-12);
            }
            dirs.push(d);
        }
        // Evenly spread: no two closer than ~ the lattice spacing, and they sum to ~0.
        let closest = (0..20).flat_map(|i| (0..i).map(move |j| (i, j))).map(|(i, j)| dirs[i].angle_between(dirs[j])).fold(PI, f64::min);
        assert!(closest > 0.5, "closest directions {closest} rad apart");
        assert!(dirs.iter().sum::<DVec3>().length() < 0.5);
        let anchors = top.bonds.iter().filter(|b| b.type_name.text == "anchor");
        assert!(anchors.clone().count() == 20 && anchors.into_iter().all(|b| b.particles[0] == 0));
        assert_eq!(top.angles.iter().filter(|t| t.type_name.text == "clamp" && t.particles[0] == 0).count(), 20);
        assert!(built.summary().contains("κ = Lp·kT = 2.139"), "{}", built.summary());
    }

    #[test]
    fn the_seed_turns_the_aster() {
        let a = |seed| AsterArgs { common: Common { seed, output: "a.top".into(), rest_from_geometry: false }, ..AsterArgs::default() };
        assert_eq!(aster(&a(2)).unwrap().text, aster(&a(2)).unwrap().text);
        assert_ne!(aster(&a(2)).unwrap().text, aster(&a(3)).unwrap().text);
        assert_eq!(aster(&AsterArgs { microtubules: 0, ..a(1) }).unwrap_err(), "expected --microtubules >= 1, found 0");
        assert_eq!(aster(&AsterArgs { core_radius: Some(-1.0), ..a(1) }).unwrap_err(), "expected --core-radius > 0, found -1");
    }
}

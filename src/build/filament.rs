//! `cellmd build filament`: see [`filament`](fn@super::filament) for the construction.

use glam::DVec3;

use super::{positive, stream, vec3, Built, Chain, Common, Draws, Writer};

/// Command-line options of `cellmd build filament`.
#[derive(clap::Args, Clone, Debug)]
pub struct FilamentArgs {
    #[command(flatten)]
    pub chain: Chain,
    /// Position of the first bead.
    #[arg(long, num_args = 3, value_names = ["X", "Y", "Z"], allow_negative_numbers = true, default_values_t = [0.0, 0.0, 0.0])]
    pub start: Vec<f64>,
    /// Direction of the filament (normalised) [default: +x].
    #[arg(long, num_args = 3, value_names = ["X", "Y", "Z"], allow_negative_numbers = true, conflicts_with = "random_direction")]
    pub direction: Option<Vec<f64>>,
    /// Draw the direction uniformly on the sphere from --seed.
    #[arg(long)]
    pub random_direction: bool,
    /// Also write a fixed (non-periodic) cubic `[ box ]` of this half-width around the filament's midpoint.
    #[arg(allow_negative_numbers = true, long = "box", value_name = "HALF_WIDTH")]
    pub box_half_width: Option<f64>,
    #[command(flatten)]
    pub common: Common,
}

impl Default for FilamentArgs {
    fn default() -> Self {
        Self {
            chain: Chain::default(),
            start: vec![0.0; 3],
            direction: None,
            random_direction: false,
            box_half_width: None,
            common: Common { seed: 1, output: "filament.top".into(), rest_from_geometry: false },
        }
    }
}

/// `cellmd build filament`: one straight bead chain of contour length L from
/// `--start` along `--direction` (default +x; `--random-direction` draws one
/// uniformly on the sphere from `--seed`), n segments of ℓ = L/n, bonds
/// between neighbours and a bending angle on every consecutive triple. The
/// summary prints κ = Lp·kT and the per-angle stiffness κ/ℓ that
/// `wlc_bending` (`kappa κ l0 ℓ`) and `cosine_angle` (`K κ/ℓ`) need.
pub fn filament(a: &FilamentArgs) -> Result<Built, String> {
    let (n, ell) = a.chain.segmentation()?;
    let start = vec3("--start", &a.start)?;
    let direction = match (&a.direction, a.random_direction) {
        (_, true) => Draws::new(a.common.seed, stream::FILAMENT).unit_vector(0, 0),
        (Some(d), false) => {
            let d = vec3("--direction", d)?;
            positive("the length of --direction", d.length())?;
            d.normalize()
        }
        (None, false) => DVec3::X,
    };
    let (_, bending) = a.chain.bending_line(ell, 17.0)?;
    let points: Vec<DVec3> = (0..=n).map(|k| start + direction * (k as f64 * ell)).collect();
    let mut w = Writer::new(1);
    w.set_rest_from_geometry(a.common.rest_from_geometry);
    a.chain.write(&mut w, &points);
    if let Some(h) = a.box_half_width {
        w.fixed_cube(start + direction * (0.5 * a.chain.length), h)?;
    }
    let lines = vec![
        format!(
            "1 filament: {} beads, {n} bonds `{}` of rest length r0 = ℓ = {ell:.12e}, {} angles `{}`; contour length {:?}, direction ({:.6}, {:.6}, {:.6})",
            n + 1,
            a.chain.bond_type,
            n.saturating_sub(1),
            a.chain.angle_type,
            a.chain.length,
            direction.x,
            direction.y,
            direction.z
        ),
        bending,
    ];
    Ok(w.finish(&format!("Straight filament of length {:?} in {n} segments", a.chain.length), "filament", lines))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::build::testing::parse;

    #[test]
    fn a_filament_is_a_straight_chain_with_bonds_and_angles() {
        let a = FilamentArgs {
            chain: Chain { length: 3.0, segments: None, segment_length: Some(0.1), ..Chain::default() },
            start: vec![1.0, 2.0, 3.0],
            direction: Some(vec![0.0, 3.0, 4.0]),
            box_half_width: Some(5.0),
            ..FilamentArgs::default()
        };
        let built = filament(&a).unwrap();
        assert_eq!((built.particles, built.bonds, built.angles), (31, 30, 29));
        let top = parse(&built);
        let d = DVec3::new(0.0, 0.6, 0.8);
        for (k, p) in top.positions.iter().enumerate() {
            assert!((*p - DVec3::new(1.0, 2.0, 3.0) - d * (0.1 * k as f64)).length() < 1e-12);
        }
        for b in &top.bonds {
            let [i, j] = b.particles;
            assert_eq!(j, i + 1);
            assert!(((top.positions[j as usize] - top.positions[i as usize]).length() - 0.1).abs() < 1e-12);
        }
        assert!(top.angles.iter().all(|t| t.particles[1] == t.particles[0] + 1 && t.particles[2] == t.particles[1] + 1));
        assert!(top.box_axes.is_some());
        // κ = 17 µm × kT(298 K) = 0.06994 pN·µm²; K = κ/ℓ.
        let s = built.summary();
        assert!(s.contains("κ = Lp·kT = 6.994368e-2 pN·µm²"), "{s}");
        assert!(s.contains("`angle bend wlc_bending kappa 6.994368e-2 l0 1.000000e-1`"), "{s}");
        assert!(s.contains("`angle bend cosine_angle K 6.994368e-1`"), "{s}");
    }

    #[test]
    fn random_directions_follow_the_seed_only() {
        let a = |seed| FilamentArgs {
            random_direction: true,
            common: Common { seed, output: "f.top".into(), rest_from_geometry: false },
            ..FilamentArgs::default()
        };
        assert_eq!(filament(&a(3)).unwrap().text, filament(&a(3)).unwrap().text);
        assert_ne!(filament(&a(3)).unwrap().text, filament(&a(4)).unwrap().text);
        let straight =
            |seed| FilamentArgs { common: Common { seed, output: "f.top".into(), rest_from_geometry: false }, ..FilamentArgs::default() };
        assert_eq!(filament(&straight(3)).unwrap().text, filament(&straight(4)).unwrap().text);
    }

    #[test]
    fn bad_options_say_what_was_expected() {
        let bad = |chain: Chain| filament(&FilamentArgs { chain, ..FilamentArgs::default() }).unwrap_err();
        assert_eq!(bad(Chain { length: -2.0, ..Chain::default() }), "expected --length > 0, found -2");
        assert_eq!(bad(Chain { segments: Some(0), ..Chain::default() }), "expected --segments >= 1, found 0");
        assert_eq!(bad(Chain { persistence_length: Some(0.0), ..Chain::default() }), "expected --persistence-length > 0, found 0");
        let zero = FilamentArgs { direction: Some(vec![0.0; 3]), ..FilamentArgs::default() };
        assert!(filament(&zero).unwrap_err().contains("length of --direction"));
        let small_box = FilamentArgs { box_half_width: Some(0.1), ..FilamentArgs::default() };
        assert!(filament(&small_box).unwrap_err().contains("to hold every particle"));
    }
}

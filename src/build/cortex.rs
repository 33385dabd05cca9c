//! `cellmd build cortex`: see [`cortex`](fn@super::cortex) for the construction.

use glam::DVec3;

use super::{closest_pairs, positive, stream, vec3, Built, Chain, Common, CrosslinkerTypes, Crosslinks, Draws, Writer};

/// Command-line options of `cellmd build cortex`.
#[derive(clap::Args, Clone, Debug)]
pub struct CortexArgs {
    /// Radius of the sphere the filaments lie on (µm).
    #[arg(allow_negative_numbers = true, long)]
    pub radius: f64,
    /// Number of filaments.
    #[arg(long)]
    pub filaments: u32,
    #[command(flatten)]
    pub chain: Chain,
    /// Centre of the sphere.
    #[arg(long, num_args = 3, value_names = ["X", "Y", "Z"], allow_negative_numbers = true, default_values_t = [0.0, 0.0, 0.0])]
    pub centre: Vec<f64>,
    /// Crosslink beads of different filaments closer than this (µm); no crosslinks if not given.
    #[arg(allow_negative_numbers = true, long)]
    pub capture: Option<f64>,
    /// Crosslinker bond types and the fraction of crosslinks each takes, `NAME:FRACTION,…`.
    #[arg(long, default_value = "crosslink")]
    pub crosslinker_types: CrosslinkerTypes,
    /// Also write a fixed (non-periodic) cubic `[ box ]` of this half-width around the centre.
    #[arg(allow_negative_numbers = true, long = "box", value_name = "HALF_WIDTH")]
    pub box_half_width: Option<f64>,
    #[command(flatten)]
    pub common: Common,
}

impl Default for CortexArgs {
    fn default() -> Self {
        Self {
            radius: 5.0,
            filaments: 40,
            chain: Chain { length: 3.0, segments: Some(15), ..Chain::default() },
            centre: vec![0.0; 3],
            capture: None,
            crosslinker_types: CrosslinkerTypes::default(),
            box_half_width: None,
            common: Common { seed: 1, output: "cortex.top".into(), rest_from_geometry: false },
        }
    }
}

/// `cellmd build cortex`: N filaments lying on a sphere of radius R (the
/// actin cortex under a cell's membrane). Each is a great-circle arc of
/// contour length L (< πR) centred on a point p uniform on the sphere, along
/// a tangent t ⊥ p at an angle uniform in [0, 2π): bead j sits at
/// `centre + R·û(s_j)` with `u(s) = p cos(s/R) + t sin(s/R)`, s_j = −L/2 + jℓ
/// (normalised, so every bead lies on the sphere to rounding). Consecutive
/// beads are a chord `2R·sin(ℓ/2R)` apart: the bond rest length and `l0` to
/// use. With `--capture D` the filaments are crosslinked as in `network`: the
/// closest pair of beads of two filaments, if closer than D, is bonded.
pub fn cortex(a: &CortexArgs) -> Result<Built, String> {
    let (n, ell) = a.chain.segmentation()?;
    let r = positive("--radius", a.radius)?;
    let centre = vec3("--centre", &a.centre)?;
    if a.chain.length >= std::f64::consts::PI * r {
        return Err(format!("expected --length below half a great circle (π·R = {}), found {}", std::f64::consts::PI * r, a.chain.length));
    }
    if a.filaments == 0 {
        return Err("expected --filaments >= 1, found 0".into());
    }
    let capture = a.capture.map(|c| positive("--capture", c)).transpose()?;
    let chord = 2.0 * r * (ell / (2.0 * r)).sin();
    let (_, bending) = a.chain.bending_line(chord, 17.0)?;
    let draws = Draws::new(a.common.seed, stream::CORTEX);
    let mut w = Writer::new(1);
    w.set_rest_from_geometry(a.common.rest_from_geometry);
    let mut filaments = Vec::new();
    for f in 0..a.filaments as u64 {
        let p = draws.unit_vector(f, 0);
        let e1 = p.any_orthonormal_vector();
        let e2 = p.cross(e1);
        let (s, c) = (std::f64::consts::TAU * draws.uniform(f, 1)).sin_cos();
        let t = (e1 * c + e2 * s).normalize();
        let points: Vec<DVec3> = (0..=n)
            .map(|j| {
                let (sa, ca) = ((j as f64 * ell - 0.5 * a.chain.length) / r).sin_cos();
                centre + (p * ca + t * sa).normalize() * r
            })
            .collect();
        let ids = a.chain.write(&mut w, &points);
        filaments.push((ids, points));
    }
    let mut lines = vec![format!(
        "{} filaments × {} beads on a sphere of radius {r:?} ({} bonds `{}` of chord r0 = 2R·sin(ℓ/2R) = {chord:.12e} for arc ℓ = {ell:.12e}, {} angles `{}` each)",
        a.filaments,
        n + 1,
        n,
        a.chain.bond_type,
        n.saturating_sub(1),
        a.chain.angle_type
    )];
    if let Some(capture) = capture {
        let links = Crosslinks::from_pairs(closest_pairs(&filaments, capture, |d| d), &a.crosslinker_types, &draws, 2);
        links.write(&mut w, &a.crosslinker_types);
        lines.push(format!("{} within capture {capture:?}", links.summary(&a.crosslinker_types)));
    }
    lines.push(bending);
    if let Some(h) = a.box_half_width {
        w.fixed_cube(centre, h)?;
    }
    Ok(w.finish(
        &format!("Cortex: {} great-circle filaments on a sphere of radius {r:?}, seed {}", a.filaments, a.common.seed),
        "cortex",
        lines,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::build::testing::{bonds_of, parse};

    #[test]
    fn beads_lie_on_the_sphere_along_great_circles() {
        let c = DVec3::new(3.0, -2.0, 1.0);
        let a = CortexArgs { centre: c.to_array().to_vec(), capture: Some(0.15), ..CortexArgs::default() };
        let built = cortex(&a).unwrap();
        let top = parse(&built);
        assert_eq!(top.ids.len(), 40 * 16);
        assert_eq!(top.angles.len(), 40 * 14);
        for p in &top.positions {
            assert!(((*p - c).length() / 5.0 - 1.0).abs() < 1e-12);
        }
        let chord = 10.0 * (0.2f64 / 10.0).sin();
        for [x, y] in bonds_of(&top, "segment") {
            assert!(((x - y).length() - chord).abs() < 1e-12);
        }
        // Each filament lies in a plane through the centre (a great circle).
        for f in 0..40 {
            let beads = &top.positions[16 * f..16 * (f + 1)];
            let normal = (beads[0] - c).cross(beads[15] - c).normalize();
            assert!(beads.iter().all(|p| (*p - c).dot(normal).abs() < 1e-12));
        }
        let crosslinks: Vec<_> = bonds_of(&top, "crosslink").collect();
        assert!(!crosslinks.is_empty());
        assert!(crosslinks.iter().all(|[x, y]| (*x - *y).length() < 0.15));
        assert_eq!(crosslinks.len() + 40 * 15, top.bonds.len());
    }

    #[test]
    fn determinism_and_errors() {
        let a = |seed| CortexArgs { common: Common { seed, output: "c.top".into(), rest_from_geometry: false }, ..CortexArgs::default() };
        assert_eq!(cortex(&a(1)).unwrap().text, cortex(&a(1)).unwrap().text);
        assert_ne!(cortex(&a(1)).unwrap().text, cortex(&a(2)).unwrap().text);
        assert!(!cortex(&a(1)).unwrap().text.contains("crosslink "));
        assert!(cortex(&CortexArgs { chain: Chain { length: 16.0, ..Chain::default() }, ..a(1) })
            .unwrap_err()
            .contains("half a great circle"));
        assert_eq!(cortex(&CortexArgs { capture: Some(0.0), ..a(1) }).unwrap_err(), "expected --capture > 0, found 0");
        assert_eq!(cortex(&CortexArgs { radius: -1.0, ..a(1) }).unwrap_err(), "expected --radius > 0, found -1");
    }
}

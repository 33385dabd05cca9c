//! A rigid substrate under a cell, as the particles of Vassaux & Milan
//! (Biomech. Model. Mechanobiol. 16, 1295, 2017), whose mesenchymal stem
//! cells spread on cut spherical surfaces of curvature radius ±75 … ±500 µm.
//!
//! The substrate is one layer of particles (give their type `fixed` in the
//! force field, and a contact pair rule against the cell's particles) on a
//! sphere of signed curvature radius `R` touching the point `bottom`
//! directly under the cell:
//! - `R > 0`, **concave** (a dish): the centre of curvature lies above,
//!   at `bottom + R·ẑ`, and the surface rises away from the axis,
//!   z(ρ) = z_b + R − √(R² − ρ²);
//! - `R < 0`, **convex** (a dome; Vassaux & Milan's sign): the centre lies
//!   below, at `bottom + R·ẑ`, z(ρ) = z_b + R + √(R² − ρ²);
//! - `R = ∞` (`flat`): the plane z = z_b.
//!
//! Particles sit on a hexagonal lattice of the given spacing in the (x, y)
//! projection, lifted onto the surface, out to the in-plane radius `extent`;
//! at slope angle α the spacing along the surface grows by 1/cos α (at most
//! 1.09 for ρ ≤ 30 µm on R = 75 µm). Every particle's distance from the
//! centre of curvature is |R| to rounding.
//!
//! [`SubstrateOptions`] are the command-line options of the builders that
//! can put their structure on such a substrate: `tensegrity` (one cell) and
//! `cells --layout spheroid` (a spheroid spreading on a ligand-coated dish,
//! Douezan et al., PNAS 108, 7315, 2011).

use glam::DVec3;

use super::{positive, Writer};

/// `--substrate flat|R` and its lattice: a rigid substrate under the built structure.
#[derive(clap::Args, Clone, Debug)]
pub struct SubstrateOptions {
    /// Also write a substrate under the structure: `flat` or its signed curvature radius in µm (> 0 concave, < 0 convex).
    #[arg(allow_negative_numbers = true, long, value_name = "flat|RADIUS")]
    pub substrate: Option<String>,
    /// Spacing of the substrate's hexagonal particle lattice (µm).
    #[arg(long, default_value_t = 1.0)]
    pub substrate_spacing: f64,
    /// In-plane radius of the substrate around the structure's axis (µm) [default: 3 × the cell's or spheroid's radius].
    #[arg(long)]
    pub substrate_extent: Option<f64>,
    /// Distance from the lowest node down to the substrate's particles (µm; 1 = two 0.5 µm particles touching).
    #[arg(long, default_value_t = 1.0)]
    pub substrate_gap: f64,
    /// Particle type of the substrate (give it `fixed` in the force field).
    #[arg(long, default_value = "substrate")]
    pub substrate_type: String,
}

impl Default for SubstrateOptions {
    fn default() -> Self {
        Self { substrate: None, substrate_spacing: 1.0, substrate_extent: None, substrate_gap: 1.0, substrate_type: "substrate".into() }
    }
}

impl SubstrateOptions {
    /// Writes the substrate, if `--substrate` asks for one, `--substrate-gap`
    /// below `lowest` on the vertical axis through `axis`, for a structure
    /// (`what`) of radius `radius`; returns the summary line.
    pub(super) fn write(&self, w: &mut Writer, axis: DVec3, lowest: f64, radius: f64, what: &str) -> Result<Option<String>, String> {
        let Some(text) = &self.substrate else { return Ok(None) };
        let curvature = parse_curvature(text, radius)?;
        let spacing = positive("--substrate-spacing", self.substrate_spacing)?;
        let extent = positive("--substrate-extent", self.substrate_extent.unwrap_or(3.0 * radius))?;
        let gap = positive("--substrate-gap", self.substrate_gap)?;
        if curvature.is_finite() && extent >= curvature.abs() {
            return Err(format!("expected --substrate-extent < |curvature radius| {}, found {extent}", curvature.abs()));
        }
        let bottom = DVec3::new(axis.x, axis.y, lowest - gap);
        let points = substrate(bottom, curvature, spacing, extent);
        for &p in &points {
            w.particle(&self.substrate_type, p, None);
        }
        let shape = match curvature {
            c if c.is_infinite() => "flat".to_string(),
            c if c > 0.0 => format!("concave, curvature radius {c:?} µm"),
            c => format!("convex, curvature radius {c:?} µm"),
        };
        Ok(Some(format!(
            "substrate `{}` ({shape}): {} particles {spacing:?} µm apart out to {extent:?} µm from the axis, touching z = {:?} under {what}",
            self.substrate_type,
            points.len(),
            bottom.z
        )))
    }
}

/// The signed curvature radius of `--substrate`: `flat` or a number (µm)
/// of magnitude above `least` (the cell's radius).
fn parse_curvature(text: &str, least: f64) -> Result<f64, String> {
    if text == "flat" {
        return Ok(f64::INFINITY);
    }
    let r: f64 = text.parse().map_err(|_| format!("expected --substrate `flat` or a curvature radius in µm, found `{text}`"))?;
    if !r.is_finite() || r.abs() <= least {
        return Err(format!(
            "expected --substrate `flat` or a curvature radius of magnitude > {least} µm (the structure's radius; > 0 concave, < 0 convex), found {text}"
        ));
    }
    Ok(r)
}

/// The substrate's particle positions: the surface of signed curvature
/// radius `curvature` through `bottom`, lattice `spacing`, in-plane radius
/// `extent` around the axis through `bottom`.
pub fn substrate(bottom: DVec3, curvature: f64, spacing: f64, extent: f64) -> Vec<DVec3> {
    let rows = (extent / (spacing * 3f64.sqrt() / 2.0)).floor() as i64;
    let columns = (extent / spacing).floor() as i64 + 1;
    let mut points = Vec::new();
    for row in -rows..=rows {
        let y = row as f64 * spacing * 3f64.sqrt() / 2.0;
        let shift = if row.rem_euclid(2) == 1 { 0.5 * spacing } else { 0.0 };
        for column in -columns..=columns {
            let x = column as f64 * spacing + shift;
            let rho2 = x * x + y * y;
            if rho2 > extent * extent {
                continue;
            }
            points.push(bottom + DVec3::new(x, y, height(curvature, rho2)));
        }
    }
    points
}

/// The surface's height above its lowest (concave) or highest (convex)
/// point at squared distance `rho2` from the axis.
fn height(curvature: f64, rho2: f64) -> f64 {
    if curvature.is_infinite() {
        0.0
    } else {
        curvature - curvature.signum() * (curvature * curvature - rho2).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn particles_lie_on_the_sphere_of_the_curvature_through_the_bottom() {
        let bottom = DVec3::new(1.0, -2.0, 3.0);
        for r in [75.0, -75.0, 500.0, -150.0] {
            let points = substrate(bottom, r, 1.0, 30.0);
            let centre = bottom + DVec3::Z * r;
            for p in &points {
                assert!(((*p - centre).length() - r.abs()).abs() < 1e-9, "R = {r}: {p}");
                assert!(((*p - bottom).truncate().length()) <= 30.0 + 1e-12);
            }
            // Concave rises away from the axis, convex falls.
            let rim = points.iter().map(|p| p.z - bottom.z).fold(0.0f64, |m, z| if z.abs() > m.abs() { z } else { m });
            assert_eq!(rim.signum(), r.signum(), "R = {r}");
            assert!(points.contains(&bottom), "the lattice has a node at the bottom");
        }
        let flat = substrate(bottom, f64::INFINITY, 1.0, 10.0);
        assert!(flat.iter().all(|p| p.z == bottom.z));
        // Hexagonal: about 2/√3 particles per spacing² on the disc.
        let expected = std::f64::consts::PI * 100.0 * 2.0 / 3f64.sqrt();
        assert!((flat.len() as f64 / expected - 1.0).abs() < 0.05, "{} vs {expected}", flat.len());
        // Every particle's nearest neighbour is one spacing away.
        let nearest = flat[..50].iter().map(|p| flat.iter().filter(|q| *q != p).map(|q| (*q - *p).length()).fold(f64::MAX, f64::min));
        assert!(nearest.into_iter().all(|d| (d - 1.0).abs() < 1e-12));
    }

    #[test]
    fn a_curvature_is_flat_or_larger_than_the_cell() {
        assert_eq!(parse_curvature("flat", 10.0), Ok(f64::INFINITY));
        assert_eq!(parse_curvature("-75", 10.0), Ok(-75.0));
        assert!(parse_curvature("5", 10.0).unwrap_err().contains("magnitude > 10"));
        assert!(parse_curvature("inf", 10.0).is_err());
        assert!(parse_curvature("dish", 10.0).unwrap_err().contains("found `dish`"));
    }
}

//! `cellmd build branched`: see [`branched`](fn@super::branched) for the construction.

use glam::DVec3;

use super::{positive, stream, vec3, Built, Chain, Common, Draws, Writer};

/// Command-line options of `cellmd build branched`.
#[derive(clap::Args, Clone, Debug)]
pub struct BranchedArgs {
    /// Number of mother filaments.
    #[arg(long)]
    pub mothers: u32,
    /// Mother filaments: --length etc.; daughters share the segment length and types.
    #[command(flatten)]
    pub chain: Chain,
    /// Daughters per mother.
    #[arg(long, default_value_t = 2)]
    pub branches: u32,
    /// Contour length of each daughter (rounded to whole segments of the mother's ℓ).
    #[arg(allow_negative_numbers = true, long)]
    pub branch_length: f64,
    /// Mean branch angle to the mother (degrees).
    #[arg(allow_negative_numbers = true, long, default_value_t = 70.0)]
    pub branch_angle: f64,
    /// Branch angles are uniform in angle ± spread (degrees).
    #[arg(allow_negative_numbers = true, long, default_value_t = 7.0)]
    pub spread: f64,
    /// Bond type from the branch bead on the mother to the daughter's first bead.
    #[arg(long, default_value = "branch")]
    pub branch_bond_type: String,
    /// Angle type (mother bead j + 1, branch bead j, daughter's first bead) holding the branch angle.
    #[arg(long, default_value = "branch_angle")]
    pub branch_angle_type: String,
    /// Centre of the region holding the mothers' centres.
    #[arg(long, num_args = 3, value_names = ["X", "Y", "Z"], allow_negative_numbers = true, default_values_t = [0.0, 0.0, 0.0])]
    pub centre: Vec<f64>,
    /// Half-width of the cube holding the mothers' centres [default: the mother length].
    #[arg(allow_negative_numbers = true, long)]
    pub extent: Option<f64>,
    /// Also write a fixed (non-periodic) cubic `[ box ]` of this half-width around the centre.
    #[arg(allow_negative_numbers = true, long = "box", value_name = "HALF_WIDTH")]
    pub box_half_width: Option<f64>,
    #[command(flatten)]
    pub common: Common,
}

impl Default for BranchedArgs {
    fn default() -> Self {
        Self {
            mothers: 10,
            chain: Chain { length: 2.0, segments: Some(20), ..Chain::default() },
            branches: 2,
            branch_length: 1.0,
            branch_angle: 70.0,
            spread: 7.0,
            branch_bond_type: "branch".into(),
            branch_angle_type: "branch_angle".into(),
            centre: vec![0.0; 3],
            extent: None,
            box_half_width: None,
            common: Common { seed: 1, output: "branched.top".into(), rest_from_geometry: false },
        }
    }
}

/// `cellmd build branched`: an Arp2/3 branched network. N mother filaments
/// (centres uniform in the cube of half-width `--extent` around `--centre`,
/// directions uniform on the sphere) each carry B daughters at distinct
/// beads drawn from `--seed` (never the last: the branch angle needs the
/// next mother bead). A daughter leaves its branch bead j at the angle
/// θ = `--branch-angle` ± `--spread` (uniform in that range; 70 ± 7° after
/// Mullins et al. 1998) to the mother's forward direction, azimuth uniform
/// around it, and is a straight chain of the mother's segment length.
/// Written terms:
///
/// - `--branch-bond-type` between mother bead j and the daughter's first bead (rest length ℓ);
/// - `--branch-angle-type` on (mother bead j + 1, j, daughter's first bead), vertex j:
///   holds the branch angle, e.g. `angle arp23 harmonic_angle k 2 theta0 70`;
/// - the daughter's own bending angles, starting at (j, first, second bead).
///
/// One generation: daughters do not branch.
pub fn branched(a: &BranchedArgs) -> Result<Built, String> {
    let (n, ell) = a.chain.segmentation()?;
    let centre = vec3("--centre", &a.centre)?;
    let lb = positive("--branch-length", a.branch_length)?;
    let nb = (lb / ell).round().max(1.0) as usize;
    let extent = positive("--extent", a.extent.unwrap_or(a.chain.length))?;
    if a.mothers == 0 {
        return Err("expected --mothers >= 1, found 0".into());
    }
    if !(a.spread.is_finite()
        && a.spread >= 0.0
        && a.branch_angle.is_finite()
        && a.spread < a.branch_angle
        && a.branch_angle + a.spread < 180.0)
    {
        return Err(format!(
            "expected 0 <= --spread < --branch-angle and --branch-angle + --spread < 180 (degrees), found angle {} spread {}",
            a.branch_angle, a.spread
        ));
    }
    if a.branches as usize > n {
        return Err(format!("expected --branches <= {n} (the mother's beads that have a next bead), found {}", a.branches));
    }
    let (_, bending) = a.chain.bending_line(ell, 17.0)?;
    let draws = Draws::new(a.common.seed, stream::BRANCHED);
    let mut w = Writer::new(1);
    w.set_rest_from_geometry(a.common.rest_from_geometry);
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for m in 0..a.mothers as u64 {
        let [ux, uy] = draws.uniform2(m, 0);
        let uz = draws.uniform(m, 1);
        let c = centre + (DVec3::new(ux, uy, uz) * 2.0 - 1.0) * extent;
        let t = draws.unit_vector(m, 2);
        let points: Vec<DVec3> = (0..=n).map(|k| c + t * (k as f64 * ell - 0.5 * a.chain.length)).collect();
        let mother = a.chain.write(&mut w, &points);
        let e1 = t.any_orthonormal_vector();
        let e2 = t.cross(e1);
        for (b, &j) in draws.choose(m, 3, n, a.branches as usize).iter().enumerate() {
            let item = m * 1_000_000 + b as u64;
            let [u_angle, u_azimuth] = draws.uniform2(item, 4);
            let theta = (a.branch_angle + a.spread * (2.0 * u_angle - 1.0)).to_radians();
            let (sp, cp) = (std::f64::consts::TAU * u_azimuth).sin_cos();
            let d = (t * theta.cos() + (e1 * cp + e2 * sp) * theta.sin()).normalize();
            let actual = t.angle_between(d).to_degrees();
            (lo, hi) = (lo.min(actual), hi.max(actual));
            let daughter_points: Vec<DVec3> = (1..=nb).map(|k| points[j] + d * (k as f64 * ell)).collect();
            let daughter = a.chain.write(&mut w, &daughter_points);
            w.bond(&a.branch_bond_type, mother[j], daughter[0]);
            w.angle(&a.branch_angle_type, mother[j + 1], mother[j], daughter[0]);
            if nb >= 2 {
                w.angle(&a.chain.angle_type, mother[j], daughter[0], daughter[1]);
            }
        }
    }
    if let Some(h) = a.box_half_width {
        w.fixed_cube(centre, h)?;
    }
    let branches = a.mothers * a.branches;
    let mut lines = vec![format!(
        "{} mothers × {} beads and {branches} daughters × {nb} beads (length {:?}); bonds `{}` and `{}` of r0 = ℓ = {ell:.12e}; angles `{}` (bending) and `{}` (branch)",
        a.mothers,
        n + 1,
        nb as f64 * ell,
        a.chain.bond_type,
        a.branch_bond_type,
        a.chain.angle_type,
        a.branch_angle_type
    )];
    if branches > 0 {
        lines.push(format!(
            "branch angles {} ± {} degrees (drawn: min {lo:.4} max {hi:.4}): `angle {} harmonic_angle k K theta0 {}`",
            a.branch_angle, a.spread, a.branch_angle_type, a.branch_angle
        ));
    }
    lines.push(bending);
    Ok(w.finish(
        &format!("Arp2/3 branched network: {} mothers, {} branches each, seed {}", a.mothers, a.branches, a.common.seed),
        "branched",
        lines,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::build::testing::parse;

    #[test]
    fn daughters_leave_their_mothers_at_the_branch_angle() {
        for spread in [0.0, 7.0] {
            let a = BranchedArgs { spread, mothers: 12, branches: 3, ..BranchedArgs::default() };
            let built = branched(&a).unwrap();
            let top = parse(&built);
            // 12 × (21 + 3 × 10) beads.
            assert_eq!(top.ids.len(), 12 * (21 + 30));
            let branch_angles: Vec<_> = top.angles.iter().filter(|t| t.type_name.text == "branch_angle").collect();
            assert_eq!(branch_angles.len(), 36);
            for t in &branch_angles {
                let [i, j, k] = t.particles.map(|p| top.positions[p as usize]);
                let angle = (i - j).angle_between(k - j).to_degrees();
                assert!((angle - 70.0).abs() <= spread + 1e-9, "branch at {angle}° (spread {spread})");
                // The first daughter bead is bonded to the branch bead, ℓ away.
                assert!(top.bonds.iter().any(|b| b.type_name.text == "branch" && b.particles == [t.particles[1], t.particles[2]]));
                assert!(((k - j).length() - 0.1).abs() < 1e-12);
            }
            let bends = top.angles.iter().filter(|t| t.type_name.text == "bend").count();
            assert_eq!(bends, 12 * 19 + 36 * 9);
            assert_eq!(top.bonds.len(), 12 * 20 + 36 * 10);
        }
    }

    #[test]
    fn the_spread_is_used_and_the_seed_decides() {
        let a = |seed| BranchedArgs {
            mothers: 30,
            common: Common { seed, output: "b.top".into(), rest_from_geometry: false },
            ..BranchedArgs::default()
        };
        let built = branched(&a(4)).unwrap();
        assert!(built.summary().contains("branch angles 70 ± 7 degrees"));
        let top = parse(&built);
        let angles: Vec<f64> = top
            .angles
            .iter()
            .filter(|t| t.type_name.text == "branch_angle")
            .map(|t| {
                let [i, j, k] = t.particles.map(|p| top.positions[p as usize]);
                (i - j).angle_between(k - j).to_degrees()
            })
            .collect();
        assert!(angles.iter().any(|x| *x < 67.0) && angles.iter().any(|x| *x > 73.0), "{angles:?}");
        assert_eq!(branched(&a(4)).unwrap().text, built.text);
        assert_ne!(branched(&a(5)).unwrap().text, built.text);
        assert!(branched(&BranchedArgs { branches: 21, ..a(1) }).unwrap_err().contains("expected --branches <= 20"));
        assert!(branched(&BranchedArgs { spread: -1.0, ..a(1) }).unwrap_err().contains("0 <= --spread"));
        assert_eq!(branched(&BranchedArgs { branch_length: 0.0, ..a(1) }).unwrap_err(), "expected --branch-length > 0, found 0");
    }
}

//! `cellmd build network`: see [`network`](fn@super::network) for the construction.

use glam::DVec3;

use super::{closest_pairs, positive, stream, Built, Chain, Common, CrosslinkerTypes, Crosslinks, Draws, Writer};

/// Command-line options of `cellmd build network`.
#[derive(clap::Args, Clone, Debug)]
pub struct NetworkArgs {
    /// Number of filaments.
    #[arg(long)]
    pub filaments: u32,
    #[command(flatten)]
    pub chain: Chain,
    /// Edge lengths of the periodic box [0, LX) × [0, LY) × [0, LZ).
    #[arg(allow_negative_numbers = true, long = "box", num_args = 3, value_names = ["LX", "LY", "LZ"], required = true)]
    pub box_lengths: Vec<f64>,
    /// Filaments in the plane z = LZ/2 (a 2D Mikado network).
    #[arg(long)]
    pub planar: bool,
    /// Beads of different filaments closer than this are crosslinked (µm).
    #[arg(allow_negative_numbers = true, long)]
    pub capture: f64,
    /// Crosslinker bond types and the fraction of crosslinks each takes, `NAME:FRACTION,…`.
    #[arg(long, default_value = "crosslink")]
    pub crosslinker_types: CrosslinkerTypes,
    #[command(flatten)]
    pub common: Common,
}

impl Default for NetworkArgs {
    fn default() -> Self {
        Self {
            filaments: 50,
            chain: Chain { length: 2.0, segments: Some(20), ..Chain::default() },
            box_lengths: vec![5.0, 5.0, 5.0],
            planar: true,
            capture: 0.1,
            crosslinker_types: CrosslinkerTypes::default(),
            common: Common { seed: 1, output: "network.top".into() },
        }
    }
}

/// `cellmd build network`: a crosslinked Mikado network (issue #6, and
/// issue #7's random fibre network of the ECM). N straight filaments of
/// contour length L with centres uniform in the periodic box `[0, LX) ×
/// [0, LY) × [0, LZ)` and directions uniform on the sphere (or, with
/// `--planar`, in the plane z = LZ/2 with directions uniform in it). Where
/// two filaments come within `--capture` of each other, their closest pair of
/// beads (minimum image) is crosslinked by one bond: one crosslink per pair
/// of filaments. Each crosslink's bond type is drawn from
/// `--crosslinker-types NAME:FRACTION,…` so each type can carry its own
/// stiffness in the force field. Positions are written wrapped into the box;
/// bonds across the boundary are measured by minimum image, as the engine
/// does.
pub fn network(a: &NetworkArgs) -> Result<Built, String> {
    let (n, ell) = a.chain.segmentation()?;
    let l = match a.box_lengths[..] {
        [x, y, z] => DVec3::new(positive("--box LX", x)?, positive("--box LY", y)?, positive("--box LZ", z)?),
        _ => return Err(format!("expected --box LX LY LZ, found {:?}", a.box_lengths)),
    };
    let capture = positive("--capture", a.capture)?;
    let half = if a.planar { l.x.min(l.y) } else { l.min_element() } / 2.0;
    if capture >= half || ell >= half {
        return Err(format!(
            "expected --capture ({capture}) and the segment length ({ell}) below half the smallest box edge ({half}) for minimum-image separations"
        ));
    }
    if a.filaments == 0 {
        return Err("expected --filaments >= 1, found 0".into());
    }
    let (_, bending) = a.chain.bending_line(ell, 17.0)?;
    let draws = Draws::new(a.common.seed, stream::NETWORK);
    let mut w = Writer::new(1);
    let mut filaments = Vec::with_capacity(a.filaments as usize);
    for f in 0..a.filaments as u64 {
        let [ux, uy] = draws.uniform2(f, 0);
        let [uz, phi] = draws.uniform2(f, 1);
        let (centre, direction) = if a.planar {
            let (s, c) = (std::f64::consts::TAU * phi).sin_cos();
            (DVec3::new(ux * l.x, uy * l.y, 0.5 * l.z), DVec3::new(c, s, 0.0))
        } else {
            (DVec3::new(ux, uy, uz) * l, draws.unit_vector(f, 2))
        };
        let points: Vec<DVec3> = (0..=n).map(|k| centre + direction * (k as f64 * ell - 0.5 * a.chain.length)).collect();
        let ids = a.chain.write(&mut w, &points);
        filaments.push((ids, points));
    }
    let periodic = |d: DVec3| d - l * (d / l).round();
    let pairs = closest_pairs(&filaments, capture, periodic);
    let links = Crosslinks::from_pairs(pairs, &a.crosslinker_types, &draws, 2);
    links.write(&mut w, &a.crosslinker_types);
    w.set_box([(0.0, l.x, true), (0.0, l.y, true), (0.0, l.z, true)]);
    w.wrap_periodic();
    let lines = vec![
        format!(
            "{} filaments × {} beads ({} bonds `{}` of r0 = ℓ = {ell:.12e}, {} angles `{}` each); contour length {:?}; {} box {} × {} × {}",
            a.filaments,
            n + 1,
            n,
            a.chain.bond_type,
            n.saturating_sub(1),
            a.chain.angle_type,
            a.chain.length,
            if a.planar { "planar, periodic" } else { "periodic" },
            l.x,
            l.y,
            l.z
        ),
        format!(
            "{} within capture {capture:?}; {:.4} crosslinks per filament",
            links.summary(&a.crosslinker_types),
            2.0 * links.links.len() as f64 / a.filaments as f64
        ),
        bending,
    ];
    Ok(w.finish(&format!("Mikado network: {} random straight filaments, seed {}", a.filaments, a.common.seed), "network", lines))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::build::testing::{bonds_of, parse};

    fn args(seed: u64) -> NetworkArgs {
        NetworkArgs {
            crosslinker_types: "xl_stiff:0.5,xl_soft:0.5".parse().unwrap(),
            common: Common { seed, output: "n.top".into() },
            ..NetworkArgs::default()
        }
    }

    #[test]
    fn crosslinks_join_different_filaments_within_the_capture_distance() {
        let a = args(11);
        let built = network(&a).unwrap();
        let top = parse(&built);
        assert_eq!(top.ids.len(), 50 * 21);
        let beads_per = 21u32;
        let segments = top.bonds.iter().filter(|b| b.type_name.text == "segment").count();
        assert_eq!((segments, top.angles.len()), (50 * 20, 50 * 19));
        let l = DVec3::splat(5.0);
        let min_image = |d: DVec3| d - l * (d / l).round();
        let (mut stiff, mut soft) = (0, 0);
        for b in top.bonds.iter().filter(|b| b.type_name.text != "segment") {
            let [i, j] = b.particles;
            assert_ne!(i / beads_per, j / beads_per, "a crosslink within one filament");
            let d = min_image(top.positions[j as usize] - top.positions[i as usize]).length();
            assert!(d < a.capture, "crosslink of length {d}");
            match b.type_name.text.as_str() {
                "xl_stiff" => stiff += 1,
                "xl_soft" => soft += 1,
                other => panic!("bond type {other}"),
            }
        }
        // 50 filaments of 2 µm in a 5 µm square cross ≈ N²L²/(πA) ≈ 127 times.
        assert!(stiff + soft > 30 && stiff > 5 && soft > 5, "{stiff} {soft}");
        assert_eq!(built.bonds, segments + stiff + soft);
        // Positions are wrapped into the box; segments have length ℓ through minimum image.
        assert!(top.positions.iter().all(|p| p.min_element() >= 0.0 && p.x < 5.0 && p.y < 5.0 && (p.z - 2.5).abs() < 1e-12));
        for [x, y] in bonds_of(&top, "segment") {
            assert!((min_image(y - x).length() - 0.1).abs() < 1e-12);
        }
        assert!(built.summary().contains(&format!("{} crosslinks (xl_stiff {stiff}, xl_soft {soft})", stiff + soft)));
    }

    #[test]
    fn same_seed_same_network_and_three_dimensions_too() {
        assert_eq!(network(&args(5)).unwrap().text, network(&args(5)).unwrap().text);
        assert_ne!(network(&args(5)).unwrap().text, network(&args(6)).unwrap().text);
        let a = NetworkArgs { planar: false, filaments: 200, capture: 0.2, ..args(5) };
        let top = parse(&network(&a).unwrap());
        assert!(top.positions.iter().any(|p| (p.z - 2.5).abs() > 1.0));
        assert!(top.bonds.len() > 200 * 20);
    }

    #[test]
    fn bad_options_say_what_was_expected() {
        let err = |a: NetworkArgs| network(&a).unwrap_err();
        assert_eq!(err(NetworkArgs { capture: 0.0, ..args(1) }), "expected --capture > 0, found 0");
        assert_eq!(err(NetworkArgs { capture: -1.0, ..args(1) }), "expected --capture > 0, found -1");
        assert!(err(NetworkArgs { capture: 3.0, ..args(1) }).contains("below half the smallest box edge"));
        assert_eq!(err(NetworkArgs { box_lengths: vec![5.0, -5.0, 5.0], ..args(1) }), "expected --box LY > 0, found -5");
        assert_eq!(err(NetworkArgs { filaments: 0, ..args(1) }), "expected --filaments >= 1, found 0");
    }
}

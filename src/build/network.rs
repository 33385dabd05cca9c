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
    /// Pin each crosslink: its bead is also bonded (same type) to the nearer
    /// neighbour of its partner, a triangle that keeps the two filaments from
    /// sliding past each other while they still turn freely about it.
    #[arg(long)]
    pub pin_crosslinks: bool,
    /// Make this axis a fixed (non-periodic) boundary: a slab between the faces
    /// 0 and L, filaments cut at them, each cut end anchored (for shear).
    #[arg(long, value_enum)]
    pub slab: Option<SlabAxis>,
    /// Particle type of the cut ends at the face 0 of `--slab` (the base).
    #[arg(long, default_value = "base", requires = "slab")]
    pub base_type: String,
    /// Particle type of the cut ends at the face L of `--slab` (the plate).
    #[arg(long, default_value = "plate", requires = "slab")]
    pub plate_type: String,
    #[command(flatten)]
    pub common: Common,
}

/// The axis of a `--slab`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum SlabAxis {
    X,
    Y,
    Z,
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
            pin_crosslinks: false,
            slab: None,
            base_type: "base".into(),
            plate_type: "plate".into(),
            common: Common { seed: 1, output: "network.top".into(), rest_from_geometry: false },
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
/// of filaments (with `--pin-crosslinks`, a second bond of the same type
/// joins the bead to its partner's nearer neighbour: a pin joint rather than
/// a link that can swing). Each crosslink's bond type is drawn from
/// `--crosslinker-types NAME:FRACTION,…` so each type can carry its own
/// stiffness in the force field. Positions are written wrapped into the box;
/// bonds across the boundary are measured by minimum image, as the engine
/// does.
///
/// With `--slab AXIS` that axis is a fixed boundary instead: the same
/// periodic network cut open at the faces 0 and L_AXIS, so the filament
/// density stays uniform up to the faces. A filament that crossed the face
/// becomes two pieces, each moved into the box (pieces of one bead are
/// dropped); a piece's end bead whose neighbour was cut away beyond the face
/// 0 takes `--base-type`, beyond the face L `--plate-type`. Declared `fixed` in the force field,
/// the base beads anchor the network and the plate beads form a rigid plate
/// that `displace_atoms` moves: simple shear of a slab of thickness ≈ L_AXIS,
/// periodic along the other axes. Crosslink separations are then minimum-image
/// along the periodic axes only.
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
    let slab = a.slab.map(|axis| axis as usize);
    if a.planar && slab == Some(2) {
        return Err("expected --slab x or y for a --planar network (its filaments lie in the plane z = LZ/2)".into());
    }
    let periodic = [0, 1, 2].map(|axis| slab != Some(axis));
    let (_, bending) = a.chain.bending_line(ell, 17.0)?;
    let draws = Draws::new(a.common.seed, stream::NETWORK);
    let mut w = Writer::new(1);
    w.set_rest_from_geometry(a.common.rest_from_geometry);
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
        let Some(axis) = slab else {
            let ids = a.chain.write(&mut w, &points);
            filaments.push((ids, points));
            continue;
        };
        // The periodic network cut open along `axis`: each run of beads in
        // one periodic image is a piece, moved into the box.
        let image = |p: &DVec3| (p[axis] / l[axis]).floor();
        let mut start = 0;
        while start < points.len() {
            let here = image(&points[start]);
            let end = start + points[start..].iter().take_while(|p| image(p) == here).count();
            if end - start >= 2 {
                let end_type = |neighbour: Option<&DVec3>| match neighbour {
                    None => a.chain.particle_type.as_str(),
                    Some(p) if image(p) < here => a.base_type.as_str(),
                    Some(_) => a.plate_type.as_str(),
                };
                let ends = [end_type(start.checked_sub(1).map(|k| &points[k])), end_type(points.get(end))];
                let mut shift = DVec3::ZERO;
                shift[axis] = here * l[axis];
                let piece: Vec<DVec3> = points[start..end].iter().map(|p| *p - shift).collect();
                let ids = a.chain.write_with_ends(&mut w, &piece, ends);
                filaments.push((ids, piece));
            }
            start = end;
        }
    }
    let images = DVec3::from_array(periodic.map(f64::from)) * l;
    let minimum_image = |d: DVec3| d - images * (d / l).round();
    let pairs = closest_pairs(&filaments, capture, minimum_image);
    let links = Crosslinks::from_pairs(pairs, &a.crosslinker_types, &draws, 2);
    links.write(&mut w, &a.crosslinker_types);
    let pins = a.pin_crosslinks.then(|| links.pins(&filaments, minimum_image));
    if let Some(pins) = &pins {
        pins.write(&mut w, &a.crosslinker_types);
    }
    w.set_box([0, 1, 2].map(|axis| (0.0, l[axis], periodic[axis])));
    w.wrap_periodic();
    let mut lines = vec![
        format!(
            "{} filaments × {} beads ({} bonds `{}` of r0 = ℓ = {ell:.12e}, {} angles `{}` each); contour length {:?}; {} box {} × {} × {}",
            a.filaments,
            n + 1,
            n,
            a.chain.bond_type,
            n.saturating_sub(1),
            a.chain.angle_type,
            a.chain.length,
            match (a.planar, slab.is_some()) {
                (true, false) => "planar, periodic",
                (true, true) => "planar, slab",
                (false, false) => "periodic",
                (false, true) => "slab",
            },
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
    if let Some(pins) = &pins {
        lines
            .push(format!("pinned: each crosslink's bead also bonded to its partner's nearer neighbour ({} more bonds)", pins.links.len()));
    }
    if let Some(axis) = slab {
        let name = ["x", "y", "z"][axis];
        let count = |t: &str| w.count_type(t);
        lines.push(format!(
            "slab: {name} fixed at 0 and {}, the filaments cut there into {} pieces; {} `{}` beads at {name} = 0 and {} `{}` beads at {name} = {} (cut ends: declare both `fixed`, move the plate with `displace_atoms`)",
            l[axis],
            filaments.len(),
            count(&a.base_type),
            a.base_type,
            count(&a.plate_type),
            a.plate_type,
            l[axis]
        ));
    }
    Ok(w.finish(&format!("Mikado network: {} random straight filaments, seed {}", a.filaments, a.common.seed), "network", lines))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::build::testing::{bonds_of, parse};

    fn args(seed: u64) -> NetworkArgs {
        NetworkArgs {
            crosslinker_types: "xl_stiff:0.5,xl_soft:0.5".parse().unwrap(),
            common: Common { seed, output: "n.top".into(), rest_from_geometry: false },
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

    /// A planar slab along y: every bead inside 0 ≤ y < LY, the box fixed
    /// along y only, cut ends typed by the face they were cut at (within one
    /// segment of it), no crosslink reaching across the fixed axis, free ends
    /// keep the bead type.
    #[test]
    fn a_slab_cuts_filaments_at_its_faces_and_types_the_cut_ends() {
        let a = NetworkArgs { slab: Some(SlabAxis::Y), ..args(3) };
        let built = network(&a).unwrap();
        let top = parse(&built);
        assert_eq!(top.box_axes.as_ref().map(|b| [0, 1, 2].map(|a| b[a].periodic)), Some([true, false, true]));
        assert!(top.positions.iter().all(|p| (0.0..5.0).contains(&p.y)));
        let of_type =
            |name: &str| top.type_names.iter().zip(&top.positions).filter(|(t, _)| t.text == name).map(|(_, p)| *p).collect::<Vec<_>>();
        let (base, plate) = (of_type("base"), of_type("plate"));
        assert!(base.len() >= 5 && plate.len() >= 5, "{} base, {} plate beads", base.len(), plate.len());
        assert!(base.iter().all(|p| p.y < 0.1) && plate.iter().all(|p| p.y > 4.9));
        assert!(of_type("bead").len() + base.len() + plate.len() == top.positions.len());
        for b in top.bonds.iter().filter(|b| b.type_name.text != "segment") {
            let [i, j] = b.particles.map(|k| top.positions[k as usize]);
            assert!((j.y - i.y).abs() < a.capture, "a crosslink across the fixed axis: {i} {j}");
        }
        assert!(built.summary().contains(&format!("{} `base` beads at y = 0 and {} `plate` beads at y = 5", base.len(), plate.len())));
        // The same filaments as the periodic network, less the beads of one-bead pieces (at most one per cut end).
        let whole = parse(&network(&args(3)).unwrap()).positions.len();
        assert!(top.positions.len() <= whole && top.positions.len() + base.len() + plate.len() >= whole);
    }

    /// Pinned: every crosslink i–j comes with a bond i–j' of its type, j' the
    /// neighbour of j on j's filament nearer to i.
    #[test]
    fn pinned_crosslinks_bond_the_bead_to_its_partners_nearer_neighbour() {
        let plain = parse(&network(&args(4)).unwrap());
        let pinned = parse(&network(&NetworkArgs { pin_crosslinks: true, ..args(4) }).unwrap());
        let d =
            |i: u32, j: u32| (pinned.positions[j as usize] - pinned.positions[i as usize]).map(|c| c - 5.0 * (c / 5.0).round()).length();
        let crosslinks = |t: &crate::topology::Topology| t.bonds.iter().filter(|b| b.type_name.text != "segment").count();
        let n = crosslinks(&plain);
        assert_eq!(crosslinks(&pinned), 2 * n);
        let links: Vec<[u32; 2]> = pinned.bonds.iter().filter(|b| b.type_name.text != "segment").map(|b| b.particles).collect();
        for (&[i, j], &[pi, pj]) in links[..n].iter().zip(&links[n..]) {
            assert_eq!(pi, i);
            let beads_per = 21;
            assert_eq!(pj / beads_per, j / beads_per, "the pin joins another filament");
            assert_eq!(pj.abs_diff(j), 1, "the pin's partner is not next to j");
            let other = if pj > j { j.checked_sub(1) } else { Some(j + 1) };
            if let Some(o) = other.filter(|&o| o / beads_per == j / beads_per) {
                assert!(d(i, pj) <= d(i, o), "the pin took the farther neighbour");
            }
        }
    }

    #[test]
    fn bad_options_say_what_was_expected() {
        let err = |a: NetworkArgs| network(&a).unwrap_err();
        assert_eq!(err(NetworkArgs { capture: 0.0, ..args(1) }), "expected --capture > 0, found 0");
        assert_eq!(err(NetworkArgs { capture: -1.0, ..args(1) }), "expected --capture > 0, found -1");
        assert!(err(NetworkArgs { capture: 3.0, ..args(1) }).contains("below half the smallest box edge"));
        assert_eq!(err(NetworkArgs { box_lengths: vec![5.0, -5.0, 5.0], ..args(1) }), "expected --box LY > 0, found -5");
        assert_eq!(err(NetworkArgs { filaments: 0, ..args(1) }), "expected --filaments >= 1, found 0");
        assert_eq!(
            err(NetworkArgs { slab: Some(SlabAxis::Z), ..args(1) }),
            "expected --slab x or y for a --planar network (its filaments lie in the plane z = LZ/2)"
        );
    }
}

//! `cellmd build cells`: see [`cells`](fn@super::cells) for the construction.

use std::path::PathBuf;

use glam::DVec3;

use super::icosphere::{unit_icosphere, ShellOptions, ShellSpec};
use super::substrate::SubstrateOptions;
use super::{positive, stream, vec3, Built, Common, Draws, Writer};

/// How `cells` arranges the cells.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// A ball of cells (FCC packing).
    Spheroid,
    /// A confluent monolayer (hexagonal packing in a periodic box).
    Layer,
}

/// Command-line options of `cellmd build cells`.
#[derive(clap::Args, Clone, Debug)]
pub struct CellsArgs {
    /// Number of cells [default for `layer`: as many as fit].
    #[arg(long)]
    pub count: Option<u32>,
    /// Radius of each cell (µm).
    #[arg(allow_negative_numbers = true, long)]
    pub radius: f64,
    /// Icosphere subdivision level of each cell (10·4ⁿ + 2 nodes).
    #[arg(long, default_value_t = 2)]
    pub level: u32,
    #[arg(long, value_enum)]
    pub layout: Layout,
    /// Smallest gap between neighbouring cells' spheres (µm).
    #[arg(allow_negative_numbers = true, long, default_value_t = 0.0)]
    pub gap: f64,
    /// `spheroid`: radius of the sphere holding the cells.
    #[arg(allow_negative_numbers = true, long)]
    pub spheroid_radius: Option<f64>,
    /// `spheroid`: its centre.
    #[arg(long, num_args = 3, value_names = ["X", "Y", "Z"], allow_negative_numbers = true, default_values_t = [0.0, 0.0, 0.0])]
    pub centre: Vec<f64>,
    /// `layer`: edge lengths of the periodic box [0, LX) × [0, LY); `spheroid`: the half-width of a fixed cubic box around the centre (one number).
    #[arg(allow_negative_numbers = true, long = "box", num_args = 1..=2, value_names = ["LX", "LY"])]
    pub box_size: Vec<f64>,
    // The cells' (and nuclei's) types; `--nucleus RADIUS` puts a nucleus in every cell.
    #[command(flatten)]
    pub shell: ShellOptions,
    // `--layout spheroid`: `--substrate flat|R` puts a rigid substrate under the spheroid.
    #[command(flatten)]
    pub substrate: SubstrateOptions,
    #[command(flatten)]
    pub common: Common,
}

impl Default for CellsArgs {
    fn default() -> Self {
        Self {
            count: Some(13),
            radius: 1.0,
            level: 1,
            layout: Layout::Spheroid,
            gap: 0.1,
            spheroid_radius: Some(4.0),
            centre: vec![0.0; 3],
            box_size: Vec::new(),
            shell: ShellOptions::default(),
            substrate: SubstrateOptions::default(),
            common: Common { seed: 1, output: PathBuf::from("cells.top"), rest_from_geometry: false },
        }
    }
}

/// FCC sites of nearest-neighbour distance `d`, turned by `turn`, with |c| ≤ `reach`, nearest first.
fn fcc_sites(d: f64, reach: f64, turn: glam::DQuat) -> Vec<DVec3> {
    let a = d / 2f64.sqrt();
    let m = (reach / a).ceil() as i64 + 1;
    let mut sites: Vec<(i64, DVec3)> = Vec::new();
    for i in -m..=m {
        for j in -m..=m {
            for k in -m..=m {
                if (i + j + k).rem_euclid(2) == 0 {
                    let c = turn * (DVec3::new(i as f64, j as f64, k as f64) * a);
                    if c.length() <= reach {
                        sites.push((i * i + j * j + k * k, c));
                    }
                }
            }
        }
    }
    // Exact squared lattice norm first, then position, so ties are ordered the same everywhere.
    sites.sort_by(|x, y| x.0.cmp(&y.0).then(x.1.x.total_cmp(&y.1.x)).then(x.1.y.total_cmp(&y.1.y)).then(x.1.z.total_cmp(&y.1.z)));
    sites.into_iter().map(|s| s.1).collect()
}

/// `cellmd build cells`: many icosphere cells (issue #7), each a closed body
/// of its own (ids 1, 2, …; with `--nucleus`, cell k is body 2k − 1 and its
/// nucleus body 2k), packed without overlap: centres at least 2R + `--gap`
/// apart.
///
/// - `--layout spheroid`: centres on a face-centred cubic lattice of
///   nearest-neighbour distance d = 2R + gap, turned by a rotation uniform on
///   SO(3) drawn from `--seed`; the N sites nearest the centre whose cells
///   lie inside the sphere of `--spheroid-radius` (|c| + R ≤ S).
/// - `--layout layer`: a confluent monolayer on a hexagonal lattice in the
///   periodic box `--box LX LY` (z fixed, `[0, 2R + gap]`, cells at
///   z = R + gap/2): nx = ⌊LX/d⌋ columns and ny = ⌊LY/(d·√3/2)⌋ rows (made even
///   so the lattice is periodic), stretched to fill the box; with fewer than
///   nx·ny cells, `--seed` draws which sites are taken. Node positions are
///   written wrapped into the box.
///
/// `--substrate flat|R` (spheroid only) writes a rigid substrate of fixed
/// particles `--substrate-gap` below the lowest node, centred under the
/// spheroid's centre, out to `--substrate-extent` [3 × the spheroid's
/// radius] (see the substrate module): a spheroid spreading on a
/// ligand-coated dish (the wetting assay of Douezan et al., PNAS 108, 7315, 2011;
/// `inputs/spheroid_spreading.in`).
///
/// More cells than fit is an error that says how many do.
pub fn cells(a: &CellsArgs) -> Result<Built, String> {
    let r = positive("--radius", a.radius)?;
    if !(a.gap.is_finite() && a.gap >= 0.0) {
        return Err(format!("expected --gap >= 0, found {}", a.gap));
    }
    if a.level > 6 {
        return Err(format!("expected --level <= 6, found {}", a.level));
    }
    let nucleus = a.shell.nucleus(r)?;
    if a.count == Some(0) {
        return Err("expected --count >= 1, found 0".into());
    }
    let d = 2.0 * r + a.gap;
    let draws = Draws::new(a.common.seed, stream::CELLS);
    let mut periodic_box = None;
    let mut fixed_box = None;
    let mut under = None;
    let (centres, where_) = match a.layout {
        Layout::Spheroid => {
            let s = positive("--spheroid-radius", a.spheroid_radius.ok_or("expected --spheroid-radius S with --layout spheroid")?)?;
            let count = a.count.ok_or("expected --count N with --layout spheroid")? as usize;
            let centre = vec3("--centre", &a.centre)?;
            match a.box_size[..] {
                [] => {}
                [h] => fixed_box = Some((centre, h)),
                _ => return Err("expected --box HALF_WIDTH (one number) with --layout spheroid".into()),
            }
            let sites = if s >= r { fcc_sites(d, s - r, draws.rotation(0, 0)) } else { Vec::new() };
            if count > sites.len() {
                return Err(format!(
                    "too many cells: at most {} cells of radius {r} with gap {} fit in a spheroid of radius {s}, found --count {count}",
                    sites.len(),
                    a.gap
                ));
            }
            under = Some((centre, s));
            (sites[..count].iter().map(|c| *c + centre).collect::<Vec<_>>(), format!("in a spheroid of radius {s:?} (FCC, turned by seed)"))
        }
        Layout::Layer => {
            if a.substrate.substrate.is_some() {
                return Err("expected --substrate only with --layout spheroid".into());
            }
            let [lx, ly] = match a.box_size[..] {
                [x, y] => [positive("--box LX", x)?, positive("--box LY", y)?],
                _ => return Err(format!("expected --box LX LY with --layout layer, found {:?}", a.box_size)),
            };
            let nx = (lx / d).floor() as usize;
            let mut ny = (ly / (d * 0.75f64.sqrt())).floor() as usize;
            if ny >= 2 {
                ny -= ny % 2;
            } else if ly < d {
                ny = 0;
            }
            let fit = nx * ny;
            let count = a.count.map_or(fit, |c| c as usize);
            if count > fit || fit == 0 {
                return Err(format!(
                    "too many cells: at most {fit} cells of radius {r} with gap {} fit in the layer {lx} × {ly}, found --count {count}",
                    a.gap
                ));
            }
            let (sx, sy) = (lx / nx as f64, ly / ny as f64);
            let z = r + 0.5 * a.gap;
            let taken = if count == fit { (0..fit).collect() } else { draws.choose(0, 2, fit, count) };
            periodic_box = Some([(0.0, lx, true), (0.0, ly, true), (0.0, 2.0 * r + a.gap, false)]);
            let centres = taken.iter().map(|&s| {
                let (i, j) = (s % nx, s / nx);
                DVec3::new((i as f64 + 0.5 * (j % 2) as f64 + 0.25) * sx, (j as f64 + 0.5) * sy, z)
            });
            (centres.collect(), format!("in a confluent layer of {count} of {fit} sites ({nx} × {ny}) in the periodic box {lx:?} × {ly:?}"))
        }
    };
    let (unit, mesh) = unit_icosphere(a.level);
    let mut w = Writer::new(1);
    w.set_rest_from_geometry(a.common.rest_from_geometry);
    let per_cell = if nucleus.is_some() { 2 } else { 1 };
    let cell_bond = a.shell.bond_types().0;
    for (k, c) in centres.iter().enumerate() {
        let body = per_cell * k as u64 + 1;
        ShellSpec {
            mesh: &mesh,
            unit: &unit,
            radius: r,
            centre: *c,
            particle_type: &a.shell.particle_type,
            body_type: &a.shell.body_type,
            bond_type: cell_bond.as_deref(),
            body_id: Some(body),
        }
        .write(&mut w);
        if let Some(n) = &nucleus {
            ShellSpec {
                mesh: &mesh,
                unit: &unit,
                radius: n.radius,
                centre: *c,
                particle_type: &n.particle_type,
                body_type: &n.body_type,
                bond_type: n.bond_type.as_deref(),
                body_id: Some(body + 1),
            }
            .write(&mut w);
        }
    }
    let mut substrate = None;
    if let Some((centre, s)) = under {
        let lowest = (1..w.next_id()).map(|id| w.position(id).z).fold(f64::INFINITY, f64::min);
        substrate = a.substrate.write(&mut w, centre, lowest, s, "the spheroid")?;
    }
    if let Some(axes) = periodic_box {
        w.set_box(axes);
        w.wrap_periodic();
    }
    if let Some((c, h)) = fixed_box {
        w.fixed_cube(c, h)?;
    }
    let mut lines = vec![format!(
        "{} cells of radius {r:?} {where_}, centres >= {d:?} apart (gap {:?}){}",
        centres.len(),
        a.gap,
        nucleus.as_ref().map_or(String::new(), |n| format!(", each with a nucleus of radius {:?}", n.radius))
    )];
    lines.push(format!("each cell: {}", w.shells[0].summary()));
    if nucleus.is_some() {
        lines.push(format!("each nucleus: {}", w.shells[1].summary()));
    }
    lines.extend(substrate);
    let title = format!("{} icosphere cells (level {}), {:?} layout, seed {}", centres.len(), a.level, a.layout, a.common.seed)
        .replace("Spheroid", "spheroid")
        .replace("Layer", "layer");
    Ok(w.finish(&title, "cells", lines))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::build::testing::parse;

    /// Cell centres (mean of each cell body's nodes, unwrapped by `min_image`).
    fn centres(built: &Built, nodes: usize, per_cell: usize, min_image: impl Fn(DVec3) -> DVec3) -> Vec<DVec3> {
        let top = parse(built);
        let cells = top.ids.len() / (nodes * per_cell);
        (0..cells)
            .map(|k| {
                let x = &top.positions[k * nodes * per_cell..(k * per_cell + 1) * nodes];
                x.iter().map(|p| x[0] + min_image(*p - x[0])).sum::<DVec3>() / nodes as f64
            })
            .collect()
    }

    fn closest(c: &[DVec3], min_image: impl Fn(DVec3) -> DVec3) -> f64 {
        (0..c.len()).flat_map(|i| (0..i).map(move |j| (i, j))).map(|(i, j)| min_image(c[i] - c[j]).length()).fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn a_spheroid_packs_cells_without_overlap_inside_its_sphere() {
        let a = CellsArgs { shell: ShellOptions { nucleus: Some(0.5), ..ShellOptions::default() }, ..CellsArgs::default() };
        let built = cells(&a).unwrap();
        assert_eq!((built.bodies, built.particles), (26, 13 * 2 * 42));
        let c = centres(&built, 42, 2, |d| d);
        assert_eq!(c.len(), 13);
        assert!(closest(&c, |d| d) >= 2.1 - 1e-9);
        assert!(c.iter().all(|c| c.length() + 1.0 <= 4.0 + 1e-9));
        let top = parse(&built);
        assert_eq!(top.bodies[1].1.text, "nucleus");
        assert_eq!(cells(&a).unwrap().text, built.text);
        assert_ne!(
            cells(&CellsArgs { common: Common { seed: 2, output: "c.top".into(), rest_from_geometry: false }, ..a.clone() }).unwrap().text,
            built.text
        );
        let err = cells(&CellsArgs { count: Some(500), ..a.clone() }).unwrap_err();
        assert!(err.starts_with("too many cells: at most ") && err.contains("spheroid of radius 4"), "{err}");
    }

    #[test]
    fn a_layer_is_a_periodic_hexagonal_monolayer() {
        let a = CellsArgs { layout: Layout::Layer, count: None, box_size: vec![10.0, 10.0], spheroid_radius: None, ..CellsArgs::default() };
        let built = cells(&a).unwrap();
        // d = 2.1: 4 columns, ⌊10/1.8187⌋ = 5 → 4 rows.
        assert_eq!(built.bodies, 16);
        let l = DVec3::new(10.0, 10.0, 0.0);
        let min_image = |d: DVec3| d - l * (d / DVec3::new(10.0, 10.0, 1.0)).round();
        let c = centres(&built, 42, 1, min_image);
        assert!(closest(&c, min_image) >= 2.1 - 1e-9, "{}", closest(&c, min_image));
        assert!(c.iter().all(|c| (c.z - 1.05).abs() < 1e-12));
        let top = parse(&built);
        assert!(top.positions.iter().all(|p| (0.0..10.0).contains(&p.x) && (0.0..10.0).contains(&p.y)));
        let some = cells(&CellsArgs { count: Some(10), ..a.clone() }).unwrap();
        assert_eq!(some.bodies, 10);
        assert_ne!(
            cells(&CellsArgs {
                count: Some(10),
                common: Common { seed: 9, output: "c.top".into(), rest_from_geometry: false },
                ..a.clone()
            })
            .unwrap()
            .text,
            some.text
        );
        let err = cells(&CellsArgs { count: Some(17), ..a.clone() }).unwrap_err();
        assert_eq!(err, "too many cells: at most 16 cells of radius 1 with gap 0.1 fit in the layer 10 × 10, found --count 17");
        assert!(cells(&CellsArgs { box_size: vec![1.0, 1.0], ..a }).unwrap_err().starts_with("too many cells: at most 0"));
    }

    #[test]
    fn a_spheroid_sits_on_its_substrate_and_a_layer_has_none() {
        let substrate =
            SubstrateOptions { substrate: Some("flat".into()), substrate_spacing: 2.0, substrate_gap: 0.5, ..SubstrateOptions::default() };
        let a = CellsArgs { centre: vec![1.0, 2.0, 10.0], substrate, ..CellsArgs::default() };
        let built = cells(&a).unwrap();
        let top = parse(&built);
        let cells_only = 13 * 42;
        let lowest = top.positions[..cells_only].iter().map(|p| p.z).fold(f64::INFINITY, f64::min);
        let sites = &top.positions[cells_only..];
        assert!(!sites.is_empty() && sites.iter().all(|p| p.z == lowest - 0.5));
        // Out to 3 × the spheroid's radius around its axis, one site on the axis.
        assert!(sites.iter().all(|p| (p.truncate() - glam::DVec2::new(1.0, 2.0)).length() <= 12.0 + 1e-9));
        assert!(sites.iter().any(|p| p.x == 1.0 && p.y == 2.0));
        assert!(top.type_names[cells_only..].iter().all(|t| t.text == "substrate"));
        assert_eq!(built.bodies, 13);
        let layer = CellsArgs { layout: Layout::Layer, count: None, box_size: vec![10.0, 10.0], spheroid_radius: None, ..a };
        assert_eq!(cells(&layer).unwrap_err(), "expected --substrate only with --layout spheroid");
    }
}

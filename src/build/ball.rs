//! `cellmd build ball`: an elastic ball meshed with linear tetrahedra, for
//! the volume laws (`neo_hookean`, `linear_elastic`).
//!
//! The cube [−1, 1]³ is cut into n³ lattice cells (n = `--cells`, even),
//! each split into the six Kuhn tetrahedra around its diagonal from the
//! corner nearest the centre to the farthest (the split mirrored into each
//! octant: a mirror keeps the diagonals of the faces on the mirror planes,
//! so faces still match), and mapped onto the ball of
//! radius R by the cubed-sphere map: a point p with s = max|p_a| on the face
//! of dominant axis a, face coordinates u = p_b/s, v = p_c/s, goes to
//! R·s·d/|d| with d_a = sign(p_a), d_b = tan(πu/4), d_c = tan(πv/4). The map
//! is continuous, takes each cube shell s to the sphere of radius R·s and the
//! cube's surface onto the sphere (nodes *on* it, equal-angle spacing), and is
//! monotone along every ray, so no element is inverted. The summary prints
//! the mesh quality q = 6√2·V/ℓ_rms³ (1 for a regular tetrahedron, 0.66
//! for a Kuhn tetrahedron of a cube; distorted most near the cube's corners,
//! where three faces of a cell map onto one patch of the sphere: every
//! element there keeps the cell's inner corner, so none lies flat on it),
//! the element volumes and the total volume against 4πR³/3.
//!
//! `--octant` keeps one eighth of that mesh, the cells and nodes at or above
//! the centre along every axis: the split is mirrored into each octant, so
//! the octant is exactly the part of the full mesh that a load symmetric
//! about the three planes through the centre deforms in mirror image. The
//! nodes on those symmetry planes get the type `TYPE_AXES`, AXES the
//! coordinates the planes fix (`node_x` on x = cx only, `node_xz` on the
//! edge where x = cx and z = cz meet, `node_xyz` the centre): a deck holds
//! them with `freeze` (mirror-symmetric boundary conditions) and so solves
//! the whole ball's symmetric problem on an eighth of the nodes.

use std::f64::consts::{FRAC_PI_4, PI};
use std::path::PathBuf;

use glam::DVec3;

use super::kuhn::{graded, Elements};
use super::{positive, vec3, Built, Writer};

/// Command-line options of `cellmd build ball`.
#[derive(clap::Args, Clone, Debug)]
pub struct BallArgs {
    /// Radius of the ball (length units).
    #[arg(allow_negative_numbers = true, long)]
    pub radius: f64,
    /// Lattice cells across the diameter (even, ≥ 2): (n + 1)³ nodes and 6n³ tetrahedra.
    #[arg(long)]
    pub cells: u32,
    /// Centre of the ball.
    #[arg(long, num_args = 3, value_names = ["X", "Y", "Z"], allow_negative_numbers = true, default_values_t = [0.0, 0.0, 0.0])]
    pub centre: Vec<f64>,
    /// Particle type of the nodes.
    #[arg(long, default_value = "node")]
    pub particle_type: String,
    /// Keep one octant (x, y, z ≥ centre) and type the nodes on its symmetry planes TYPE_x, TYPE_xy, …
    #[arg(long)]
    pub octant: bool,
    /// The radial spacing of the shells next to the centre; the spacings beyond the core grow by a constant ratio (default: uniform shells).
    #[arg(allow_negative_numbers = true, long)]
    pub spacing: Option<f64>,
    /// How many shells from the centre keep --spacing (a uniform core) before the growth starts.
    #[arg(long, default_value_t = 0, requires = "spacing")]
    pub core_cells: u32,
    /// Particle type of the nodes on the sphere (default: --particle-type, or the symmetry plane's).
    #[arg(long)]
    pub surface_type: Option<String>,
    /// Tetra type of the elements (what a `tetra` line of the force field names).
    #[arg(long, default_value = "solid")]
    pub tetra_type: String,
    /// The topology file to write.
    #[arg(short, long)]
    pub output: PathBuf,
}

/// The command line's defaults, for the library's callers: radius 5, 4
/// cells across, centred at the origin, `node` particles, `solid` elements.
impl Default for BallArgs {
    fn default() -> Self {
        Self {
            radius: 5.0,
            cells: 4,
            centre: vec![0.0; 3],
            particle_type: "node".into(),
            octant: false,
            spacing: None,
            core_cells: 0,
            surface_type: None,
            tetra_type: "solid".into(),
            output: "ball.top".into(),
        }
    }
}

/// The cubed-sphere image of lattice point `p` ∈ [−1, 1]³ on the unit ball.
fn cube_to_ball(p: DVec3) -> DVec3 {
    let s = p.abs().max_element();
    if s == 0.0 {
        return DVec3::ZERO;
    }
    let a = if p.x.abs() == s {
        0
    } else if p.y.abs() == s {
        1
    } else {
        2
    };
    let mut d = DVec3::ZERO;
    for b in 0..3 {
        d[b] = if b == a { p[b].signum() } else { (FRAC_PI_4 * p[b] / s).tan() };
    }
    s * d.normalize()
}

/// Builds the ball (see the module docs).
pub fn ball(args: &BallArgs) -> Result<Built, String> {
    let radius = positive("--radius", args.radius)?;
    let centre = vec3("--centre", &args.centre)?;
    let n = args.cells as usize;
    if n < 2 || !n.is_multiple_of(2) || n > 256 {
        return Err(format!("expected --cells an even number in [2, 256], found {n}"));
    }
    let spacing = args.spacing.map(|h| positive("--spacing", h)).transpose()?;
    let core = args.core_cells as usize;
    if spacing.is_some() && core >= n / 2 {
        return Err(format!("expected --core-cells < --cells/2 = {} (the shells beyond the core reach the sphere), found {core}", n / 2));
    }
    let (shells, ratio) = graded("--radius", radius, n / 2, spacing, core)?;
    let side = n + 1;
    let index = |i: usize, j: usize, k: usize| (i * side + j) * side + k;
    // The octant keeps lattice indices ≥ n/2 along every axis.
    let low = if args.octant { n / 2 } else { 0 };
    let mut writer = Writer::new(1);
    let mut x = vec![DVec3::ZERO; side * side * side];
    let mut id = vec![0u64; side * side * side];
    let mut count = 0;
    for i in low..side {
        for j in low..side {
            for k in low..side {
                let p = DVec3::new(i as f64, j as f64, k as f64) * (2.0 / n as f64) - DVec3::ONE;
                let v = index(i, j, k);
                // The lattice shell: max |p_a| in lattice steps.
                let shell = [i, j, k].map(|c| c.abs_diff(n / 2)).into_iter().max().unwrap();
                x[v] = match spacing {
                    None => centre + radius * cube_to_ball(p),
                    Some(_) if shell == 0 => centre,
                    Some(_) => centre + shells[shell] * cube_to_ball(p).normalize(),
                };
                let held: String =
                    [(i, 'x'), (j, 'y'), (k, 'z')].iter().filter(|&&(c, _)| args.octant && c == n / 2).map(|&(_, a)| a).collect();
                let type_name = match (&args.surface_type, held.is_empty()) {
                    (Some(surface), _) if shell == n / 2 => surface.clone(),
                    (_, true) => args.particle_type.clone(),
                    (_, false) => format!("{}_{held}", args.particle_type),
                };
                id[v] = writer.particle(&type_name, x[v], None);
                count += 1;
            }
        }
    }
    let mut elements = Elements::default();
    for i in low..n {
        for j in low..n {
            for k in low..n {
                // Along each axis, from the cell's side nearer the centre outwards.
                let upward = [i, j, k].map(|c| 2 * c >= n);
                elements.cell(&mut writer, &args.tetra_type, ([i, j, k], upward), |[a, b, c]| index(a, b, c), (&x, &id));
            }
        }
    }
    let total = elements.total_volume();
    let (part, share, exact) = if args.octant { ("octant of a ball", 8.0, "πR³/6") } else { ("ball", 1.0, "4πR³/3") };
    let sphere = 4.0 / 3.0 * PI * radius.powi(3) / share;
    let mut lines = vec![
        format!(
            "{part} of radius {radius} at {centre}: {count} nodes, {} tetrahedra (cubed-sphere map of a {n}³ lattice, 6 per cell)",
            elements.count()
        ),
        format!("volume {total:.6e} ({:.3} % below {exact}, the sphere inscribed by the surface faces)", 100.0 * (sphere - total) / sphere),
        elements.summary(),
        format!("force field: tetra {} neo_hookean e E nu ν   (or linear_elastic; E in pN/µm²)", args.tetra_type),
    ];
    if args.octant {
        let t = &args.particle_type;
        lines.push(format!("symmetry planes: hold {t}_x {t}_xy {t}_xz {t}_xyz along x, {t}_y {t}_xy {t}_yz {t}_xyz along y, {t}_z {t}_xz {t}_yz {t}_xyz along z (`freeze`)"));
    }
    if let Some(h) = spacing {
        lines.push(format!(
            "shells graded from the centre: {core} of spacing {h}, then growing by {ratio:.4} to {:.4e} at the sphere",
            shells[n / 2] - shells[n / 2 - 1]
        ));
    }
    if let Some(surface) = &args.surface_type {
        lines.push(format!("the nodes on the sphere: type {surface}"));
    }
    let mut command = format!("ball --radius {radius} --cells {n}{}", if args.octant { " --octant" } else { "" });
    if let Some(h) = spacing {
        command += &format!(" --spacing {h} --core-cells {core}");
    }
    if let Some(surface) = &args.surface_type {
        command += &format!(" --surface-type {surface}");
    }
    Ok(writer.finish("Elastic ball of linear tetrahedra", &command, lines))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::tetra_edges;

    fn args(cells: u32) -> BallArgs {
        BallArgs { radius: 2.0, cells, centre: vec![0.5, 0.0, -1.0], ..Default::default() }
    }

    #[test]
    fn the_octant_is_the_full_mesh_above_the_centre_with_its_symmetry_planes_typed() {
        let full = ball(&args(8)).unwrap();
        let octant = ball(&BallArgs { octant: true, ..args(8) }).unwrap();
        assert_eq!((octant.particles, octant.tetrahedra), (125, 6 * 64));
        let parse = |b: &Built| crate::topology::parse_topology(&crate::input::SourceFile::new("ball.top", &b.text)).unwrap();
        let (full, octant) = (parse(&full), parse(&octant));
        let centre = DVec3::new(0.5, 0.0, -1.0);
        // Every octant element is a full-mesh element (same corners, same order).
        let key = |top: &crate::topology::Topology, t: [u32; 4]| t.map(|p| top.positions[p as usize].to_array().map(f64::to_bits));
        let elements: std::collections::HashSet<_> = full.tetrahedra.iter().map(|t| key(&full, t.particles)).collect();
        for t in &octant.tetrahedra {
            assert!(elements.contains(&key(&octant, t.particles)), "octant element {:?} not in the full mesh", t.particles);
        }
        let volume = |top: &crate::topology::Topology| -> f64 {
            top.tetrahedra.iter().map(|t| tetra_edges(t.particles.map(|p| top.positions[p as usize])).determinant() / 6.0).sum()
        };
        assert!((8.0 * volume(&octant) - volume(&full)).abs() < 1e-12 * volume(&full));
        for (p, x) in octant.positions.iter().enumerate() {
            let d = *x - centre;
            assert!(d.min_element() > -1e-12, "node {p} below the centre: {d}");
            let held: String = [(d.x, 'x'), (d.y, 'y'), (d.z, 'z')].iter().filter(|a| a.0 == 0.0).map(|a| a.1).collect();
            let expected = if held.is_empty() { "node".to_string() } else { format!("node_{held}") };
            assert_eq!(octant.type_names[p].text, expected, "node {p} at {d}");
        }
    }

    #[test]
    fn the_ball_is_a_positive_conforming_mesh_of_the_sphere() {
        for cells in [2, 4, 8] {
            let built = ball(&args(cells)).unwrap();
            let n = cells as usize;
            assert_eq!((built.particles, built.tetrahedra), ((n + 1).pow(3), 6 * n.pow(3)));
            let top = crate::topology::parse_topology(&crate::input::SourceFile::new("ball.top", &built.text)).unwrap();
            // Every face of an element is shared by two elements or lies on the sphere.
            let mut faces = std::collections::HashMap::new();
            let mut total = 0.0;
            for t in &top.tetrahedra {
                let at = t.particles.map(|p| top.positions[p as usize]);
                let v = tetra_edges(at).determinant() / 6.0;
                assert!(v > 0.0, "inverted element {:?}", t.particles);
                total += v;
                for skip in 0..4 {
                    let mut face: Vec<u32> = (0..4).filter(|&k| k != skip).map(|k| t.particles[k]).collect();
                    face.sort_unstable();
                    *faces.entry(face).or_insert(0) += 1;
                }
            }
            let centre = DVec3::new(0.5, 0.0, -1.0);
            for (face, count) in &faces {
                assert!(*count <= 2, "face {face:?} in {count} elements");
                if *count == 1 {
                    for &p in face {
                        assert!(((top.positions[p as usize] - centre).length() - 2.0).abs() < 1e-12, "open face {face:?} inside the ball");
                    }
                }
            }
            let sphere = 4.0 / 3.0 * PI * 8.0;
            assert!(total < sphere && total > 0.75 * sphere, "{cells}: volume {total} vs {sphere}");
        }
    }

    #[test]
    fn refinement_fills_the_sphere() {
        let volume = |cells| ball(&args(cells)).unwrap().lines[1].clone();
        assert!(volume(16).contains("% below"), "{}", volume(16));
        let gap = |cells: u32| -> f64 {
            let line = volume(cells);
            line.split('(').nth(1).unwrap().split(' ').next().unwrap().parse().unwrap()
        };
        assert!(gap(16) < gap(8) / 3.0 && gap(16) < 1.0, "{} vs {}", gap(16), gap(8));
    }

    #[test]
    fn graded_shells_keep_the_core_grow_outwards_and_type_the_sphere() {
        let graded_args = BallArgs { octant: true, spacing: Some(0.1), core_cells: 2, surface_type: Some("rim".into()), ..args(8) };
        let built = ball(&graded_args).unwrap();
        let top = crate::topology::parse_topology(&crate::input::SourceFile::new("ball.top", &built.text)).unwrap();
        let centre = DVec3::new(0.5, 0.0, -1.0);
        let (shells, _) = graded("--radius", 2.0, 4, Some(0.1), 2).unwrap();
        assert_eq!((shells[1], shells[2], shells[4]), (0.1, 0.2, 2.0));
        for (p, x) in top.positions.iter().enumerate() {
            let r = (*x - centre).length();
            let k = shells.iter().position(|t| (t - r).abs() < 1e-12).unwrap_or_else(|| panic!("node {p} at r = {r} off the shells"));
            assert_eq!(top.type_names[p].text == "rim", k == 4, "node {p} at r = {r}");
        }
        for t in &top.tetrahedra {
            assert!(tetra_edges(t.particles.map(|p| top.positions[p as usize])).determinant() > 0.0, "inverted element {:?}", t.particles);
        }
        assert!(ball(&BallArgs { core_cells: 4, ..graded_args }).unwrap_err().contains("expected --core-cells < --cells/2 = 4"));
    }

    #[test]
    fn bad_options_are_refused() {
        assert!(ball(&args(3)).unwrap_err().contains("even"));
        assert!(ball(&BallArgs { radius: 0.0, ..args(4) }).unwrap_err().contains("--radius > 0"));
    }
}

//! `cellmd build block`: an elastic block meshed with linear tetrahedra and
//! graded towards the centre of its top face, where a contact lies (a rigid
//! sphere, the `indenter`, pressed into a half-space cut to a finite size).
//!
//! The block spans cx ± L along x, cy ± L along y and cz − H ≤ z ≤ cz
//! (L = `--half-width`, H = `--depth`, (cx, cy, cz) = `--centre`, the centre
//! of the top face). Along each axis the node coordinates, measured from
//! that centre (|x − cx|, |y − cy|, cz − z), run through one sequence
//! 0 = t_0 < t_1 < … < t_n of n = `--cells` spacings: uniform (L/n, H/n)
//! by default; with `--spacing` h, the first `--core-cells` m spacings are h
//! (a uniform core for the contact) and the others grow by a constant
//! ratio q ≥ 1, solved so that the sequence ends at L (along z at H, its own
//! ratio). The lattice of 2n × 2n × n cells is split into six Kuhn
//! tetrahedra per cell, the split mirrored about the planes x = cx and
//! y = cy (as `ball` mirrors its octants), so the mesh is symmetric about
//! them. The summary prints the ratios, the element volumes, the mesh
//! quality 6√2·V/ℓ_rms³ (a graded lattice has long thin cells where a
//! fine spacing along one axis meets a coarse one along another) and the
//! total volume, exact for a box.
//!
//! The nodes of the base (z = cz − H) get the type `TYPE_base`, for a deck
//! to hold with `freeze … x y z`. `--quarter` keeps the quarter x ≥ cx,
//! y ≥ cy: a load symmetric about the two planes deforms it in mirror image,
//! so the nodes on them, typed `TYPE_x` (x = cx), `TYPE_y` and `TYPE_xy`
//! (their edge; base nodes stay `TYPE_base`), are held along the plane's
//! normal with `freeze`, and the quarter solves the whole block's problem
//! on a quarter of the nodes.

use std::path::PathBuf;

use glam::DVec3;

use super::kuhn::{graded, Elements};
use super::{positive, vec3, Built, Writer};

/// Command-line options of `cellmd build block`.
#[derive(clap::Args, Clone, Debug)]
pub struct BlockArgs {
    /// Half the block's width: it spans the centre's x ± L and y ± L (length units).
    #[arg(allow_negative_numbers = true, long)]
    pub half_width: f64,
    /// Depth of the block below its top face (default: the half-width).
    #[arg(allow_negative_numbers = true, long)]
    pub depth: Option<f64>,
    /// Spacings from the top face's centre to each side and to the base, n in [1, 128]: (2n + 1)²(n + 1) nodes, 24n³ tetrahedra (quarter: (n + 1)³, 6n³).
    #[arg(long)]
    pub cells: u32,
    /// The spacing next to the top face's centre; the spacings beyond the core grow by a constant ratio (default: uniform spacings).
    #[arg(allow_negative_numbers = true, long)]
    pub spacing: Option<f64>,
    /// How many spacings from the centre keep --spacing (a uniform core) before the growth starts.
    #[arg(long, default_value_t = 0, requires = "spacing")]
    pub core_cells: u32,
    /// Centre of the top face.
    #[arg(long, num_args = 3, value_names = ["X", "Y", "Z"], allow_negative_numbers = true, default_values_t = [0.0, 0.0, 0.0])]
    pub centre: Vec<f64>,
    /// Particle type of the nodes.
    #[arg(long, default_value = "node")]
    pub particle_type: String,
    /// Keep the quarter x, y ≥ centre and type the nodes on its symmetry planes TYPE_x, TYPE_y, TYPE_xy.
    #[arg(long)]
    pub quarter: bool,
    /// Tetra type of the elements (what a `tetra` line of the force field names).
    #[arg(long, default_value = "solid")]
    pub tetra_type: String,
    /// The topology file to write.
    #[arg(short, long)]
    pub output: PathBuf,
}

/// Builds the block (see the module docs).
pub fn block(args: &BlockArgs) -> Result<Built, String> {
    let half_width = positive("--half-width", args.half_width)?;
    let depth = positive("--depth", args.depth.unwrap_or(half_width))?;
    let centre = vec3("--centre", &args.centre)?;
    let n = args.cells as usize;
    if !(1..=128).contains(&n) {
        return Err(format!("expected --cells in [1, 128], found {n}"));
    }
    let spacing = args.spacing.map(|h| positive("--spacing", h)).transpose()?;
    let core = args.core_cells as usize;
    if core >= n && spacing.is_some() {
        return Err(format!("expected --core-cells < --cells {n} (the spacings beyond the core reach the sides), found {core}"));
    }
    let (across, q_side) = graded("--half-width", half_width, n, spacing, core)?;
    let (down, q_depth) = graded("--depth", depth, n, spacing, core)?;
    // Lattice index i ∈ [0, 2n] along x and y (n at the centre), k ∈ [0, n] downwards.
    let side = 2 * n + 1;
    let index = |i: usize, j: usize, k: usize| (i * side + j) * (n + 1) + k;
    let offset = |i: usize| if i >= n { across[i - n] } else { -across[n - i] };
    let low = if args.quarter { n } else { 0 };
    let t = &args.particle_type;
    let mut writer = Writer::new(1);
    let mut x = vec![DVec3::ZERO; side * side * (n + 1)];
    let mut id = vec![0u64; x.len()];
    let mut count = 0;
    for i in low..side {
        for j in low..side {
            for (k, depth) in down.iter().enumerate().take(n + 1) {
                let v = index(i, j, k);
                x[v] = centre + DVec3::new(offset(i), offset(j), -depth);
                let held: String = [(i, 'x'), (j, 'y')].iter().filter(|&&(c, _)| args.quarter && c == n).map(|&(_, a)| a).collect();
                let type_name = match (k == n, held.is_empty()) {
                    (true, _) => format!("{t}_base"),
                    (false, true) => t.clone(),
                    (false, false) => format!("{t}_{held}"),
                };
                id[v] = writer.particle(&type_name, x[v], None);
                count += 1;
            }
        }
    }
    let mut elements = Elements::default();
    for i in low..2 * n {
        for j in low..2 * n {
            for k in 0..n {
                // Mirrored about the centre planes along x and y; the same way along z.
                elements.cell(&mut writer, &args.tetra_type, ([i, j, k], [i >= n, j >= n, true]), |[a, b, c]| index(a, b, c), (&x, &id));
            }
        }
    }
    let total = elements.total_volume();
    let share = if args.quarter { 1.0 } else { 4.0 };
    let exact = share * half_width * half_width * depth;
    let part = if args.quarter { "quarter (x, y ≥ centre) of a block" } else { "block" };
    let mut lines = vec![
        format!(
            "{part} {}×{}×{depth} below the top face centred at {centre}: {count} nodes, {} tetrahedra (6 per lattice cell)",
            2.0 * half_width,
            2.0 * half_width,
            elements.count()
        ),
        format!(
            "spacings from the top face's centre: {:.4e} at the centre, {:.4e} at the sides, {:.4e} at the base; growth ratio {q_side:.4} across, {q_depth:.4} down",
            across[1],
            across[n] - across[n - 1],
            down[n] - down[n - 1]
        ),
        format!("volume {total:.6e} (exact {exact:.6e})"),
        elements.summary(),
        format!("force field: tetra {} neo_hookean e E nu ν   (or linear_elastic; E in pN/µm²)", args.tetra_type),
        format!("base: hold {t}_base along x y z (`freeze`)"),
    ];
    if args.quarter {
        lines.push(format!("symmetry planes: hold {t}_x {t}_xy along x, {t}_y {t}_xy along y (`freeze`)"));
    }
    let mut command = format!("block --half-width {half_width} --depth {depth} --cells {n}");
    if let Some(h) = spacing {
        command += &format!(" --spacing {h} --core-cells {core}");
    }
    if args.quarter {
        command += " --quarter";
    }
    Ok(writer.finish("Elastic block of linear tetrahedra", &command, lines))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::tetra_edges;
    use crate::topology::{parse_topology, Topology};

    fn args() -> BlockArgs {
        BlockArgs {
            half_width: 10.0,
            depth: Some(6.0),
            cells: 4,
            spacing: Some(0.5),
            core_cells: 1,
            centre: vec![1.0, -2.0, 3.0],
            particle_type: "node".into(),
            quarter: false,
            tetra_type: "solid".into(),
            output: "block.top".into(),
        }
    }

    fn parse(b: &Built) -> Topology {
        parse_topology(&crate::input::SourceFile::new("block.top", &b.text)).unwrap()
    }

    #[test]
    fn graded_spacings_keep_the_core_and_grow_by_one_ratio_to_the_side() {
        let (t, q) = graded("--half-width", 10.0, 4, Some(0.5), 1).unwrap();
        assert_eq!((t.len(), t[0], t[1], t[4]), (5, 0.0, 0.5, 10.0));
        let steps: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
        assert!((steps[1] / steps[0] - q).abs() < 1e-12 && (steps[3] / steps[2] - q).abs() < 1e-9, "{steps:?} {q}");
        assert!((0.5 * (q + q * q + q * q * q) - 9.5).abs() < 1e-9);
        let (uniform, one) = graded("--depth", 6.0, 3, None, 0).unwrap();
        assert_eq!((uniform, one), (vec![0.0, 2.0, 4.0, 6.0], 1.0));
    }

    #[test]
    fn the_block_is_a_positive_conforming_mesh_of_the_box() {
        let built = block(&args()).unwrap();
        assert_eq!((built.particles, built.tetrahedra), (81 * 5, 6 * 8 * 8 * 4));
        let top = parse(&built);
        let c = DVec3::new(1.0, -2.0, 3.0);
        let mut faces = std::collections::HashMap::new();
        let mut total = 0.0;
        for t in &top.tetrahedra {
            let v = tetra_edges(t.particles.map(|p| top.positions[p as usize])).determinant() / 6.0;
            assert!(v > 0.0, "inverted element {:?}", t.particles);
            total += v;
            for skip in 0..4 {
                let mut face: Vec<u32> = (0..4).filter(|&k| k != skip).map(|k| t.particles[k]).collect();
                face.sort_unstable();
                *faces.entry(face).or_insert(0) += 1;
            }
        }
        assert!((total - 20.0 * 20.0 * 6.0).abs() < 1e-9 * total, "{total}");
        // A face in one element only lies on the box's boundary.
        for (face, count) in &faces {
            assert!(*count <= 2, "face {face:?} in {count} elements");
            if *count == 1 {
                let d: Vec<DVec3> = face.iter().map(|&p| top.positions[p as usize] - c).collect();
                let on = |f: &dyn Fn(DVec3) -> bool| d.iter().all(|&p| f(p));
                let boundary = on(&|p| (p.x.abs() - 10.0).abs() < 1e-12)
                    || on(&|p| (p.y.abs() - 10.0).abs() < 1e-12)
                    || on(&|p| p.z.abs() < 1e-12)
                    || on(&|p| (p.z + 6.0).abs() < 1e-12);
                assert!(boundary, "open face {face:?} inside the block");
            }
        }
        for (p, x) in top.positions.iter().enumerate() {
            let expected = if (x.z - c.z + 6.0).abs() < 1e-12 { "node_base" } else { "node" };
            assert_eq!(top.type_names[p].text, expected, "node {p} at {x}");
        }
    }

    #[test]
    fn the_quarter_is_the_block_beyond_the_centre_planes_with_them_typed() {
        let full = parse(&block(&args()).unwrap());
        let built = block(&BlockArgs { quarter: true, ..args() }).unwrap();
        assert_eq!((built.particles, built.tetrahedra), (125, 6 * 64));
        let quarter = parse(&built);
        let key = |top: &Topology, t: [u32; 4]| t.map(|p| top.positions[p as usize].to_array().map(f64::to_bits));
        let elements: std::collections::HashSet<_> = full.tetrahedra.iter().map(|t| key(&full, t.particles)).collect();
        for t in &quarter.tetrahedra {
            assert!(elements.contains(&key(&quarter, t.particles)), "quarter element {:?} not in the block", t.particles);
        }
        let c = DVec3::new(1.0, -2.0, 3.0);
        for (p, x) in quarter.positions.iter().enumerate() {
            let d = *x - c;
            assert!(d.x >= 0.0 && d.y >= 0.0, "node {p} outside the quarter: {d}");
            let held: String = [(d.x, 'x'), (d.y, 'y')].iter().filter(|a| a.0 == 0.0).map(|a| a.1).collect();
            let expected = match ((d.z + 6.0).abs() < 1e-12, held.is_empty()) {
                (true, _) => "node_base".to_string(),
                (false, true) => "node".to_string(),
                (false, false) => format!("node_{held}"),
            };
            assert_eq!(quarter.type_names[p].text, expected, "node {p} at {d}");
        }
    }

    #[test]
    fn bad_options_are_refused() {
        let err = |a: BlockArgs| block(&a).unwrap_err();
        assert!(err(BlockArgs { half_width: -1.0, ..args() }).contains("expected --half-width > 0, found -1"));
        assert!(err(BlockArgs { depth: Some(0.0), ..args() }).contains("expected --depth > 0, found 0"));
        assert!(err(BlockArgs { cells: 0, ..args() }).contains("expected --cells in [1, 128], found 0"));
        assert!(err(BlockArgs { spacing: Some(f64::NAN), ..args() }).contains("expected --spacing > 0"));
        assert!(err(BlockArgs { core_cells: 4, ..args() }).contains("expected --core-cells < --cells 4"));
        assert!(err(BlockArgs { spacing: Some(3.0), ..args() }).contains("the spacings cannot shrink outwards"));
        assert!(err(BlockArgs { spacing: Some(0.01), ..args() }).contains("growth ratio of the spacings ≤ 4"));
        assert!(err(BlockArgs { centre: vec![0.0, f64::INFINITY, 0.0], ..args() }).contains("--centre"));
    }
}

//! `cellmd build sheet`: a 2D epithelial cell sheet, the tissue of Prakash,
//! Bull & Prakash (Nat. Phys. 18, 444, 2022, and its Supplementary
//! Information: fracture of *Trichoplax* epithelia), as explicit particles
//! and bonds.
//!
//! # Geometry
//!
//! `--rows NY` rows of `--columns NX` cells tile the plane z = Z (`--centre
//! X Y Z`, the middle of the patch) as hexagons: cell (i, j) (column i, row j)
//! is centred at ((i + ½·(j mod 2))·D, j·D·√3/2) before the patch is centred,
//! D = `--cell-size` (µm) being the distance between neighbouring centres —
//! the hexagon's width across flats; its corners lie at R = D/√3 from the
//! centre at 30° + k·60°, so its area is (√3/2)·D² and its perimeter 2√3·D.
//! Each cell has up to six neighbours, one across each side.
//!
//! `--jitter J` (a fraction of D, default 0) moves each corner of the
//! honeycomb by a displacement uniform in a disc of radius J·D, drawn once per
//! corner from `--seed` (Philox keyed by the corner's lattice position, so a
//! larger patch keeps the corners of a smaller one); the three cells meeting
//! at a corner share the move, so the cells still tile the plane, as irregular
//! convex hexagons. A jitter that makes a cell non-convex is refused.
//!
//! With `--nodes-per-edge N` ≥ 1 (default 1) each cell is its own polygon:
//!
//! - its hexagon is shrunk by half the junction gap G (`--gap`, µm, default
//!   D/20): every side moves inward by G/2, parallel to itself;
//! - a **ring** of 6N nodes (`--particle-type`, default `node`) runs
//!   counter-clockwise around it: each corner and N − 1 nodes evenly between
//!   it and the next; consecutive nodes are joined by **edge** bonds
//!   (`--edge-bond-type`, default `edge`): the cortex;
//! - a **centre** node (`--centre-type`, default `cell_centre`, at the
//!   polygon's area centroid) is joined to every ring node by a **spoke**
//!   (`--spoke-bond-type`, default `spoke`): the cytoplasm's resistance to a
//!   change of area;
//! - across each side shared with a neighbour, the N + 1 nodes of that side
//!   (corners included) are paired with the neighbour's nodes at the same
//!   place along the side by **junction** bonds (`--junction-bond-type`,
//!   default `junction`), of length G on a regular lattice. A corner node thus
//!   has a junction to each of the two neighbours that share it (a
//!   tricellular junction).
//!
//! With `--nodes-per-edge 0` each cell is a single particle of `--centre-type`
//! at its hexagon's centroid and the junctions join neighbouring cells'
//! particles (length D on a regular lattice): their reduced model.
//!
//! Particle ids run cell by cell, rows from the bottom (−y) and each row from
//! left (−x): cell (i, j) is the (j·NX + i)-th, its centre node first and then
//! its ring from the corner at 30°. Bonds are written by type: all edges,
//! then all spokes, then all junctions. `--box HALF_WIDTH` adds a fixed cubic
//! `[ box ]` around the centre. The summary gives the counts and the shortest,
//! mean and longest edge, spoke and junction (their r0), and the mean ring
//! area A0 and perimeter P0.
//!
//! # Why this representation
//!
//! Prakash et al. write a cell's energy as a vertex model plus its junctions,
//! ε_i = k_A(A_i − A0)² + Γ·P_i² + α·P_i + Σ_j δ_ij·ε_junction, where
//! δ_ij ∈ {0, 1} says whether the junction between cells i and j is bound,
//! breaks at a force (or strain) threshold and rebinds with maturation
//! N(t) = N0(1 − e^(−t/τ_mature)). A vertex model shares the vertices and
//! edges of neighbouring cells, so a junction cannot be a thing that breaks.
//! Here every cell keeps its own boundary, and what holds two cells together
//! is a separate bond type — the δ_ij of Prakash et al. made explicit — to which the
//! force field gives that kinetics:
//!
//! ```text
//! bond junction harmonic k 20 r0 0.15 kinetics threshold force 2 kinetics rebind k_on 1 capture 0.3 kinetics maturation tau 10
//! ```
//!
//! The vertex-model terms become bonds of the ring. For n = 6N equal edges
//! of length P/n, edge bonds of spring constant k_e (pN/µm) and rest length
//! ℓ_r sum to Σ ½k_e(P/n − ℓ_r)² = Γ(P − P0)² with Γ = k_e/(2n) and
//! P0 = n·ℓ_r, i.e. Γ·P² + α·P up to a constant with α = −2Γ·P0 (`harmonic`:
//! k_e = k, ℓ_r = r0; `spring`/`cable` with pre-strain τ: k_e = k/r0,
//! ℓ_r = r0(1 − τ), a contractile cortex). The spokes stand for the area term
//! linearised, as Prakash et al.'s second model linearises the vertex energy into
//! springs: on a regular n-gon with spokes of length s0 (A0 = (n/2)s0²·sin(2π/n)),
//! harmonic spokes of constant k_s resist a uniform dilation as
//! k_A(A − A0)² with k_A = k_s/(2n·s0²·sin²(2π/n)). Their phase diagram
//! comes from its reduced model, cells as particles joined by junction
//! springs, which `--nodes-per-edge 0` writes.
//!
//! A bond type's `r0` is one rest length for all its bonds. With N = 1 — each
//! cell the vertex model's hexagon, with its own copy of the shared corners —
//! a regular sheet has all edges, all spokes and all junctions equal, so it
//! is at rest as built. With N ≥ 2 the spokes to the corners are longer than
//! those to the sides' middles (R against √3/2·R), and one r0 leaves the ring
//! pre-stressed: it rounds up. A jittered sheet has a spread of lengths of
//! every type; the summary prints it (the force field takes the mean as r0).
//! `--rest-from-geometry` instead writes each bond's length as built as its
//! own r0 (`type i j r0`), so any sheet starts force-free; a pre-strain
//! (`spring`/`cable` τ) still acts on top of it.

use std::collections::BTreeMap;
use std::f64::consts::TAU;

use glam::{DVec2, DVec3};

use super::{min_mean_max, positive, stream, vec3, Built, Common, Draws, Writer};

/// Command-line options of `cellmd build sheet`.
#[derive(clap::Args, Clone, Debug)]
pub struct SheetArgs {
    /// Rows of cells (along y).
    #[arg(long)]
    pub rows: u32,
    /// Cells per row (along x).
    #[arg(long)]
    pub columns: u32,
    /// Distance between neighbouring cell centres, the hexagon's width across flats (µm).
    #[arg(allow_negative_numbers = true, long)]
    pub cell_size: f64,
    /// Ring nodes per hexagon side (a corner and N − 1 between corners), 6N per cell; 0 writes each cell as one particle.
    #[arg(long, default_value_t = 1)]
    pub nodes_per_edge: u32,
    /// Gap between neighbouring cells' rings, the junction length (µm) [default: cell size / 20].
    #[arg(allow_negative_numbers = true, long)]
    pub gap: Option<f64>,
    /// Random move of each hexagon corner, uniform in a disc of radius JITTER × cell size, drawn from --seed.
    #[arg(allow_negative_numbers = true, long, default_value_t = 0.0)]
    pub jitter: f64,
    /// Middle of the patch; the sheet lies in the plane z = Z.
    #[arg(long, num_args = 3, value_names = ["X", "Y", "Z"], allow_negative_numbers = true, default_values_t = [0.0, 0.0, 0.0])]
    pub centre: Vec<f64>,
    /// Particle type of the ring nodes.
    #[arg(long, default_value = "node")]
    pub particle_type: String,
    /// Particle type of each cell's centre node (the whole cell with --nodes-per-edge 0).
    #[arg(long, default_value = "cell_centre")]
    pub centre_type: String,
    /// Bond type between consecutive ring nodes (cortex).
    #[arg(long, default_value = "edge")]
    pub edge_bond_type: String,
    /// Bond type from the centre node to each ring node (area elasticity).
    #[arg(long, default_value = "spoke")]
    pub spoke_bond_type: String,
    /// Bond type between neighbouring cells (cell–cell junctions).
    #[arg(long, default_value = "junction")]
    pub junction_bond_type: String,
    /// Also write a fixed (non-periodic) cubic `[ box ]` of this half-width around the centre.
    #[arg(allow_negative_numbers = true, long = "box", value_name = "HALF_WIDTH")]
    pub box_half_width: Option<f64>,
    #[command(flatten)]
    pub common: Common,
}

impl Default for SheetArgs {
    fn default() -> Self {
        Self {
            rows: 4,
            columns: 5,
            cell_size: 3.0,
            nodes_per_edge: 1,
            gap: None,
            jitter: 0.0,
            centre: vec![0.0; 3],
            particle_type: "node".into(),
            centre_type: "cell_centre".into(),
            edge_bond_type: "edge".into(),
            spoke_bond_type: "spoke".into(),
            junction_bond_type: "junction".into(),
            box_half_width: None,
            common: Common { seed: 1, output: "sheet.top".into(), rest_from_geometry: false },
        }
    }
}

/// A hexagon's corners in lattice units (x in D/2, y in D/(2√3)), counter-clockwise from 30°.
const CORNERS: [(i64, i64); 6] = [(1, 1), (0, 2), (-1, 1), (-1, -1), (0, -2), (1, -1)];

/// A point of the lattice in µm (before centring).
fn lattice_point((x, y): (i64, i64), d: f64) -> DVec2 {
    DVec2::new(x as f64 * d / 2.0, y as f64 * d / (2.0 * 3f64.sqrt()))
}

/// Area and area centroid of a polygon (shoelace).
fn area_centroid(p: &[DVec2]) -> (f64, DVec2) {
    let (mut a, mut c) = (0.0, DVec2::ZERO);
    for (k, &x) in p.iter().enumerate() {
        let y = p[(k + 1) % p.len()];
        let cross = x.perp_dot(y);
        a += cross;
        c += (x + y) * cross;
    }
    (a / 2.0, c / (3.0 * a))
}

/// The hexagon with every side moved inward by `h`, or `None` if it is not
/// convex and counter-clockwise or a side would vanish.
fn inset(p: &[DVec2; 6], h: f64) -> Option<[DVec2; 6]> {
    let e: Vec<DVec2> = (0..6).map(|k| (p[(k + 1) % 6] - p[k]).normalize()).collect();
    if (0..6).any(|k| e[k].perp_dot(e[(k + 1) % 6]) <= 0.0) {
        return None;
    }
    // Corner k is where the lines of sides k − 1 and k, each moved by h along its inward normal, meet.
    let q: [DVec2; 6] = std::array::from_fn(|k| {
        let (a, b) = (e[(k + 5) % 6], e[k]);
        p[k] + (a.perp() + b.perp()) * (h / (1.0 + a.dot(b)))
    });
    (0..6).all(|k| (q[(k + 1) % 6] - q[k]).dot(e[k]) > 0.0).then_some(q)
}

/// `cellmd build sheet`: a patch of `--rows` × `--columns` hexagonal cells in
/// a plane, each a ring of nodes with edge bonds and a centre node with
/// spokes (or one particle with `--nodes-per-edge 0`), neighbouring cells
/// joined by junction bonds; `--jitter` makes the hexagons irregular. The
/// construction and why it suits Prakash et al.'s junction model are in the module
/// documentation (`src/build/sheet.rs`).
pub fn sheet(a: &SheetArgs) -> Result<Built, String> {
    let d = positive("--cell-size", a.cell_size)?;
    let centre = vec3("--centre", &a.centre)?;
    let (nx, ny) = (a.columns as usize, a.rows as usize);
    if nx == 0 || ny == 0 || nx * ny > 1_000_000 {
        return Err(format!("expected --rows and --columns >= 1 with at most 1 000 000 cells, found {ny} × {nx}"));
    }
    if !(a.jitter.is_finite() && (0.0..0.5).contains(&a.jitter)) {
        return Err(format!("expected 0 <= --jitter < 0.5, found {}", a.jitter));
    }
    let n = a.nodes_per_edge as usize;
    if n > 1000 {
        return Err(format!("expected --nodes-per-edge <= 1000, found {n}"));
    }
    let gap = match (n, a.gap) {
        (0, Some(_)) => return Err("expected no --gap with --nodes-per-edge 0 (cells as single particles have no rings)".into()),
        (0, None) => 0.0,
        (_, g) => positive("--gap", g.unwrap_or(d / 20.0))?,
    };
    let draws = Draws::new(a.common.seed, stream::SHEET);
    let keys: Vec<(i64, i64)> = (0..ny).flat_map(|j| (0..nx).map(move |i| (2 * i as i64 + (j % 2) as i64, 3 * j as i64))).collect();
    let index: BTreeMap<(i64, i64), usize> = keys.iter().enumerate().map(|(k, &key)| (key, k)).collect();
    let shift = centre.truncate() - keys.iter().map(|&key| lattice_point(key, d)).sum::<DVec2>() / keys.len() as f64;
    let corner = |(x, y): (i64, i64)| {
        // Corner lattice coordinates are >= (−1, −2): shifted, they key the draw.
        let [u, v] = draws.uniform2((((x + 2) as u64) << 32) | (y + 2) as u64, 0);
        let (s, c) = (TAU * v).sin_cos();
        lattice_point((x, y), d) + shift + DVec2::new(c, s) * (a.jitter * d * u.sqrt())
    };
    let mut w = Writer::new(1);
    w.set_rest_from_geometry(a.common.rest_from_geometry);
    let at = |p: DVec2| DVec3::new(p.x, p.y, centre.z);
    // Per cell: its particle ids (centre first, then the ring).
    let mut cells: Vec<Vec<u64>> = Vec::with_capacity(keys.len());
    let (mut areas, mut perimeters) = (Vec::new(), Vec::new());
    for (k, &(cx, cy)) in keys.iter().enumerate() {
        let hexagon: [DVec2; 6] = std::array::from_fn(|c| corner((cx + CORNERS[c].0, cy + CORNERS[c].1)));
        let Some(ring) = inset(&hexagon, gap / 2.0) else {
            return Err(format!(
                "expected --jitter and --gap small enough that every cell stays a convex hexagon: cell {} (row {}, column {}) does not (jitter {}, gap {gap})",
                k + 1,
                k / nx,
                k % nx,
                a.jitter
            ));
        };
        if n == 0 {
            cells.push(vec![w.particle(&a.centre_type, at(area_centroid(&hexagon).1), None)]);
            continue;
        }
        let (area, middle) = area_centroid(&ring);
        areas.push(area);
        perimeters.push((0..6).map(|c| (ring[(c + 1) % 6] - ring[c]).length()).sum::<f64>());
        let mut ids = vec![w.particle(&a.centre_type, at(middle), None)];
        for c in 0..6 {
            for s in 0..n {
                ids.push(w.particle(&a.particle_type, at(ring[c].lerp(ring[(c + 1) % 6], s as f64 / n as f64)), None));
            }
        }
        cells.push(ids);
    }
    let mut lengths: [Vec<f64>; 3] = Default::default();
    let mut bond = |w: &mut Writer, kind: usize, i: u64, j: u64| {
        lengths[kind].push((w.position(j) - w.position(i)).length());
        w.bond([&a.edge_bond_type, &a.spoke_bond_type, &a.junction_bond_type][kind], i, j);
    };
    if n > 0 {
        for ids in &cells {
            let ring = &ids[1..];
            for k in 0..ring.len() {
                bond(&mut w, 0, ring[k], ring[(k + 1) % ring.len()]);
            }
        }
        for ids in &cells {
            for &node in &ids[1..] {
                bond(&mut w, 1, ids[0], node);
            }
        }
    }
    // Ring node `s` (0..=n) of side `c`, from corner c towards corner c + 1 (1 + for the centre).
    let side_node = |c: usize, s: usize| 1 + if s == n { (c + 1) % 6 * n } else { c * n + s };
    let mut neighbours = 0;
    for (k, &(cx, cy)) in keys.iter().enumerate() {
        for c in 0..6 {
            let (a1, b1) = (CORNERS[c], CORNERS[(c + 1) % 6]);
            let Some(&m) = index.get(&(cx + a1.0 + b1.0, cy + a1.1 + b1.1)).filter(|&&m| m > k) else { continue };
            neighbours += 1;
            if n == 0 {
                bond(&mut w, 2, cells[k][0], cells[m][0]);
                continue;
            }
            // The neighbour's side (c + 3) mod 6 runs the other way along the shared side.
            for s in 0..=n {
                bond(&mut w, 2, cells[k][side_node(c, s)], cells[m][side_node((c + 3) % 6, n - s)]);
            }
        }
    }
    if let Some(h) = a.box_half_width {
        w.fixed_cube(centre, h)?;
    }
    w.set_bonds_comment("# type  i  j   (ring edges, then spokes, then junctions)");
    let spread = |v: &[f64]| {
        let [lo, mean, hi] = min_mean_max(v);
        format!("min {lo:.6e} mean {mean:.6e} max {hi:.6e}")
    };
    let mut lines = vec![format!(
        "{} cells ({ny} rows × {nx} columns) on a hexagonal lattice of spacing {d:?} in the plane z = {:?}, corners jittered by up to {:?}; {neighbours} neighbouring pairs",
        keys.len(),
        centre.z,
        a.jitter * d
    )];
    if n == 0 {
        lines.push(format!("each cell one particle `{}`", a.centre_type));
    } else {
        lines.push(format!(
            "each cell a ring of {} nodes `{}` with {} edges `{}` and a centre node `{}` with {} spokes `{}`; ring area A0 mean {:.6e}, perimeter P0 mean {:.6e}",
            6 * n,
            a.particle_type,
            6 * n,
            a.edge_bond_type,
            a.centre_type,
            6 * n,
            a.spoke_bond_type,
            min_mean_max(&areas)[1],
            min_mean_max(&perimeters)[1]
        ));
        lines.push(format!("edge length {} (for r0)", spread(&lengths[0])));
        lines.push(format!("spoke length {} (for r0)", spread(&lengths[1])));
    }
    if !lengths[2].is_empty() {
        lines.push(format!(
            "{} junctions `{}`: length {} (for r0; gap {gap:?})",
            lengths[2].len(),
            a.junction_bond_type,
            spread(&lengths[2])
        ));
    }
    let per_cell = if n == 0 { 1 } else { 6 * n + 1 };
    let title = format!("Cell sheet: {ny} × {nx} hexagonal cells of size {d:?}, {per_cell} particles each, seed {}", a.common.seed);
    Ok(w.finish(&title, "sheet", lines))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::build::testing::{bonds_of, parse};

    #[test]
    fn a_regular_sheet_has_its_counts_and_junctions_of_the_gap() {
        let a = SheetArgs { centre: vec![1.0, -2.0, 0.5], box_half_width: Some(20.0), nodes_per_edge: 2, ..SheetArgs::default() };
        let built = sheet(&a).unwrap();
        let top = parse(&built);
        // 4 rows of 5: 20 cells of 1 + 12 nodes; neighbouring pairs: 4 × 4 in rows,
        // and 2 × 5 − 1 = 9 between each of the 3 pairs of consecutive rows.
        let (cells, pairs) = (20, 4 * 4 + 3 * 9);
        assert_eq!(top.ids.len(), cells * 13);
        assert_eq!(bonds_of(&top, "edge").count(), cells * 12);
        assert_eq!(bonds_of(&top, "spoke").count(), cells * 12);
        assert_eq!(bonds_of(&top, "junction").count(), pairs * 3);
        assert!(built.summary().contains(&format!("{pairs} neighbouring pairs")), "{}", built.summary());
        // Every junction spans the gap D/20 = 0.15 exactly, across the shared side.
        for [x, y] in bonds_of(&top, "junction") {
            assert!(((x - y).length() - 0.15).abs() < 1e-12, "{}", (x - y).length());
        }
        // Ring edges are a third of the shrunk side, spokes reach the ring.
        let side = (3.0 - 0.15) / 3f64.sqrt();
        for [x, y] in bonds_of(&top, "edge") {
            assert!(((x - y).length() - side / 2.0).abs() < 1e-12);
        }
        for [x, y] in bonds_of(&top, "spoke") {
            let r = (x - y).length();
            assert!(r > side * 0.75f64.sqrt() - 1e-12 && r < side + 1e-12, "{r}");
        }
        // Centred, flat, each ring a hexagon of area (√3/2)(D − G)².
        let mean = top.positions.iter().sum::<DVec3>() / top.positions.len() as f64;
        assert!((mean - DVec3::new(1.0, -2.0, 0.5)).length() < 1e-12, "{mean}");
        assert!(top.positions.iter().all(|p| p.z == 0.5));
        let ring: Vec<DVec2> = top.positions[1..13].iter().map(|p| p.truncate()).collect();
        let (area, centroid) = area_centroid(&ring);
        assert!((area - 0.75f64.sqrt() * 2.85 * 2.85).abs() < 1e-12);
        assert!((centroid - top.positions[0].truncate()).length() < 1e-12);
        // One node per side: the hexagon itself, every edge and spoke alike (a sheet at rest).
        let hexagons = parse(&sheet(&SheetArgs { nodes_per_edge: 1, ..a }).unwrap());
        assert_eq!((hexagons.ids.len(), hexagons.bonds.len()), (cells * 7, cells * 12 + pairs * 2));
        assert!(bonds_of(&hexagons, "edge").chain(bonds_of(&hexagons, "spoke")).all(|[x, y]| ((x - y).length() - side).abs() < 1e-12));
    }

    #[test]
    fn the_jitter_moves_shared_corners_together_and_follows_the_seed() {
        let a = |seed, jitter| SheetArgs {
            jitter,
            common: Common { seed, output: "s.top".into(), rest_from_geometry: false },
            ..SheetArgs::default()
        };
        let built = sheet(&a(3, 0.1)).unwrap();
        assert_eq!(sheet(&a(3, 0.1)).unwrap().text, built.text);
        assert_ne!(sheet(&a(4, 0.1)).unwrap().text, built.text);
        // Without jitter the seed changes nothing but the title.
        let body = |seed| sheet(&a(seed, 0.0)).unwrap().text.lines().filter(|l| !l.starts_with('#')).collect::<Vec<_>>().join("\n");
        assert_eq!(body(3), body(4));
        // The three cells at a corner share its move, so they still tile the
        // plane: with a vanishing gap every junction closes to nothing, while
        // the rings' edges are no longer all alike.
        let tight = parse(&sheet(&SheetArgs { gap: Some(1e-9), ..a(3, 0.1) }).unwrap());
        assert!(bonds_of(&tight, "junction").all(|[x, y]| (x - y).length() < 1e-8));
        let edges: Vec<f64> = bonds_of(&tight, "edge").map(|[x, y]| (x - y).length()).collect();
        let [lo, _, hi] = min_mean_max(&edges);
        assert!(hi - lo > 0.05, "{lo} {hi}");
        let err = sheet(&a(3, 0.45)).unwrap_err();
        assert!(err.starts_with("expected --jitter and --gap small enough that every cell stays a convex hexagon"), "{err}");
    }

    #[test]
    fn single_particle_cells_are_joined_centre_to_centre() {
        let a = SheetArgs { nodes_per_edge: 0, rows: 3, columns: 3, ..SheetArgs::default() };
        let built = sheet(&a).unwrap();
        let top = parse(&built);
        assert_eq!(top.ids.len(), 9);
        // 3 × 2 in rows, 2 × 3 − 1 = 5 between each pair of rows.
        assert_eq!(top.bonds.len(), 6 + 2 * 5);
        assert!(bonds_of(&top, "junction").all(|[x, y]| ((x - y).length() - 3.0).abs() < 1e-12));
        assert!(built.summary().contains("each cell one particle `cell_centre`"));
        assert!(sheet(&SheetArgs { gap: Some(0.1), ..a.clone() }).unwrap_err().contains("no --gap with --nodes-per-edge 0"));
    }

    #[test]
    fn the_committed_sheet_is_what_the_builder_writes() {
        let a = SheetArgs { rows: 8, columns: 12, ..SheetArgs::default() };
        let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/topologies/sheet.top")).unwrap();
        assert_eq!(sheet(&a).unwrap().text, text);
    }

    #[test]
    fn bad_options_say_what_was_expected() {
        let a = SheetArgs::default();
        assert_eq!(sheet(&SheetArgs { cell_size: 0.0, ..a.clone() }).unwrap_err(), "expected --cell-size > 0, found 0");
        assert!(sheet(&SheetArgs { rows: 0, ..a.clone() }).unwrap_err().starts_with("expected --rows and --columns >= 1"));
        assert_eq!(sheet(&SheetArgs { jitter: 0.5, ..a.clone() }).unwrap_err(), "expected 0 <= --jitter < 0.5, found 0.5");
        assert_eq!(sheet(&SheetArgs { gap: Some(-1.0), ..a.clone() }).unwrap_err(), "expected --gap > 0, found -1");
        assert!(sheet(&SheetArgs { gap: Some(3.5), ..a.clone() }).unwrap_err().contains("convex hexagon"));
    }
}

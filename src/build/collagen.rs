//! `cellmd build collagen`: a planar collagen fibre network with contractile
//! cells in holes, the model of Ouyang et al. ("Cell remote mechanics
//! regulates large-spatial isotropic matrix modeling with dynamic
//! simulations", bioRxiv 2022; issue #19), as explicit particles and bonds.
//!
//! # Geometry
//!
//! Everything lies in the plane z = 0, in the rectangle `--size W H` centred
//! on the origin.
//!
//! - **Cells** (`--layout`): `pair`, two centres at (±D/2, 0); `square`, four
//!   at (±D/2, ±D/2); `random`, `--cells N` centres uniform in the rectangle
//!   shrunk by R + ℓ from each side, drawn in turn (Philox keyed by the
//!   attempt) and kept when at least D from every centre kept before. D is
//!   `--separation` (the centre-to-centre distance; for `random` the smallest
//!   one), R `--cell-radius`, ℓ `--node-spacing`.
//! - Each cell is a **hub** node (`--hub-type`, at the centre) and a **ring**
//!   of `--ring-nodes` n nodes (`--ring-type`, default 83 as in the paper) at
//!   radius R, node k at angle 2πk/n; consecutive ring nodes are joined by
//!   **cortex** bonds (length 2R·sin(π/n)), the hub to each ring node by a
//!   **spoke** (length R). A deck contracts the cell by ramping the two
//!   types' `r0` (5 % per stage in the paper), and holds it in place by
//!   freezing the hub (the paper fixes the cell nodes) or lets it move.
//! - **Fibres**: N = round(ρ·(W + L)(H + L)/L) straight fibres of length L
//!   (`--fibre-length`), centres uniform in the rectangle grown by L/2 on each
//!   side and directions uniform in the plane, cut at the rectangle's edge:
//!   the fibre length per area inside is ρ (`--density`, µm⁻¹) on average.
//!   Where two fibres cross, the crossing is one node that both share: a
//!   **crosslink**, as in the paper's network (crossings per unit fibre
//!   length 2ρ/π, so crosslinks are π/(2ρ) apart along a fibre on average).
//!   A crossing closer than ℓ/2 along either fibre to a crosslink found
//!   before joins that one (the fibre kinks slightly through it), so no
//!   fibre bond is much shorter than ℓ/2 and one spring constant suits all
//!   (a segment's k = EA/length within a factor of about 2): with very short
//!   bonds among long ones, equal k would give the short ones the large
//!   strains, and `plastic` would reset them at every step.
//! - **Holes**: the parts of fibres inside a cell's circle are removed (the
//!   paper removes the network under the cells); where a fibre crosses the
//!   circle it is attached to the ring node nearest the crossing.
//! - A fibre end cut at the rectangle's edge is an **anchor** node
//!   (`--anchor-type`): the force field makes that type `fixed`, the rest of
//!   a large gel. A free fibre end beyond its last crosslink carries no load
//!   and is trimmed; so is, repeatedly, any node left with a single bond,
//!   and any piece of network attached to neither an anchor nor a cell.
//! - Between consecutive crosslinks, anchors and ring attachments each fibre
//!   is split into the fewest equal bonds no longer than ℓ (`--node-spacing`):
//!   **fibre** bonds (`--fibre-bond-type`) between network nodes
//!   (`--node-type`). Fibre lengths differ, so every fibre bond line carries
//!   its length as built as its own r0 (the network starts force-free);
//!   `--rest-from-geometry` does the same for the cortex and spokes (whose
//!   type r0 a contraction ramp needs, so it is off by default).
//! - **Angles** (`--angle-type`, default `bend`) at every node where a fibre
//!   runs on straight (θ = 180° as built; not at a kinked, joined crosslink):
//!   fibres are rods. Without bending a network of freely jointed segments
//!   is floppy (its mean coordination is below 4, the isostatic value in 2D)
//!   and folds without ever compressing a fibre.
//!
//! Particle ids run cell by cell (hub, then its ring from angle 0
//! counter-clockwise: cell c, from 0, owns ids c(n + 1) + 1 … (c + 1)(n + 1)),
//! then the network nodes. Bonds: cortex, spokes, then fibres; then the
//! angles. Two fibres through the same joined crosslinks share those bonds
//! and angles (each listed once). The summary
//! gives the cell centres, the counts, the fibre length per area of the
//! network as written (outside the holes), the bond lengths and the cortex and
//! spoke lengths for their r0.
//!
//! The fibre law (tension 100× stiffer than compression, `asymmetric`), the
//! crosslink reconstruction (`plastic`, threshold 0.5) and the contraction
//! protocol belong to the force field and the deck
//! (`forcefields/collagen.ff`, `inputs/collagen_two_cells.in`).

use std::f64::consts::{PI, TAU};

use glam::{DVec2, DVec3};

use self::graph::{End, Graph, Kind};
use super::{min_mean_max, positive, stream, Built, Common, Draws, Writer};

mod graph;

/// Where the cells sit.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum CellLayout {
    /// Two cells --separation apart along x.
    Pair,
    /// Four cells on the corners of a square of side --separation.
    Square,
    /// --cells cells placed at random, at least --separation apart.
    Random,
}

impl CellLayout {
    fn name(self) -> &'static str {
        match self {
            Self::Pair => "pair",
            Self::Square => "square",
            Self::Random => "random",
        }
    }
}

/// Command-line options of `cellmd build collagen`.
#[derive(clap::Args, Clone, Debug)]
pub struct CollagenArgs {
    /// Where the cells sit.
    #[arg(long, value_enum, default_value_t = CellLayout::Pair)]
    pub layout: CellLayout,
    /// Number of cells of `--layout random`.
    #[arg(long)]
    pub cells: Option<u32>,
    /// Centre-to-centre distance of neighbouring cells (µm; `random`: the smallest allowed).
    #[arg(allow_negative_numbers = true, long)]
    pub separation: f64,
    /// Radius of each cell's ring and of the hole under it (µm).
    #[arg(allow_negative_numbers = true, long)]
    pub cell_radius: f64,
    /// Nodes per cell ring.
    #[arg(long, default_value_t = 83)]
    pub ring_nodes: u32,
    /// Width and height of the network's rectangle, centred on the origin (µm).
    #[arg(allow_negative_numbers = true, long, num_args = 2, value_names = ["W", "H"], required = true)]
    pub size: Vec<f64>,
    /// Fibre length per area ρ (µm⁻¹); crosslinks are π/(2ρ) apart along a fibre on average.
    #[arg(allow_negative_numbers = true, long)]
    pub density: f64,
    /// Length of each straight fibre before it is cut (µm).
    #[arg(allow_negative_numbers = true, long)]
    pub fibre_length: f64,
    /// Longest bond along a fibre (µm): fibres are split between crosslinks into bonds no longer than this.
    #[arg(allow_negative_numbers = true, long)]
    pub node_spacing: f64,
    #[command(flatten)]
    pub types: CollagenTypes,
    #[command(flatten)]
    pub common: Common,
}

impl Default for CollagenArgs {
    fn default() -> Self {
        Self {
            layout: CellLayout::Pair,
            cells: None,
            separation: 60.0,
            cell_radius: 10.0,
            ring_nodes: 83,
            size: vec![120.0, 80.0],
            density: 0.6,
            fibre_length: 20.0,
            node_spacing: 3.0,
            types: CollagenTypes::default(),
            common: Common { seed: 1, output: "collagen.top".into(), rest_from_geometry: false },
        }
    }
}

/// The particle, bond and angle types of `cellmd build collagen`'s fibre
/// nodes, anchors, cell rings, hubs, fibres, cortices, spokes and bends.
#[derive(clap::Args, Clone, Debug)]
pub struct CollagenTypes {
    /// Particle type of the fibre nodes (crosslinks and the nodes between them).
    #[arg(long, default_value = "node")]
    pub node_type: String,
    /// Particle type of the fibre ends cut at the rectangle's edge (made `fixed` by the force field).
    #[arg(long, default_value = "anchor")]
    pub anchor_type: String,
    /// Particle type of the cells' ring nodes.
    #[arg(long, default_value = "ring")]
    pub ring_type: String,
    /// Particle type of each cell's centre node.
    #[arg(long, default_value = "hub")]
    pub hub_type: String,
    /// Bond type of the fibre segments (and of a fibre's attachment to a ring node).
    #[arg(long, default_value = "fibre")]
    pub fibre_bond_type: String,
    /// Bond type between consecutive ring nodes.
    #[arg(long, default_value = "cortex")]
    pub cortex_bond_type: String,
    /// Bond type from a cell's hub to each of its ring nodes.
    #[arg(long, default_value = "spoke")]
    pub spoke_bond_type: String,
    /// Angle type along each fibre where it runs straight (bending; vertex in the middle).
    #[arg(long, default_value = "bend")]
    pub angle_type: String,
}

impl Default for CollagenTypes {
    fn default() -> Self {
        Self {
            node_type: "node".into(),
            anchor_type: "anchor".into(),
            ring_type: "ring".into(),
            hub_type: "hub".into(),
            fibre_bond_type: "fibre".into(),
            cortex_bond_type: "cortex".into(),
            spoke_bond_type: "spoke".into(),
            angle_type: "bend".into(),
        }
    }
}

/// Draw purposes of the generator.
const CENTRE: u32 = 0;
const FIBRE_CENTRE: u32 = 1;
const FIBRE_ANGLE: u32 = 2;

/// At most this many fibres (crossings are found pair by pair).
const MAX_FIBRES: usize = 20_000;

/// The part `[t0, t1]` of the segment `a + t·d`, t ∈ [0, 1], inside the
/// rectangle |x| ≤ hw, |y| ≤ hh (Liang–Barsky), if any.
fn clip(a: DVec2, d: DVec2, hw: f64, hh: f64) -> Option<(f64, f64)> {
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [(-d.x, a.x + hw), (d.x, hw - a.x), (-d.y, a.y + hh), (d.y, hh - a.y)] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else if p < 0.0 {
            t0 = t0.max(q / p);
        } else {
            t1 = t1.min(q / p);
        }
    }
    (t0 < t1).then_some((t0, t1))
}

/// The parameters t along `a + t·d` where the line crosses the circle of
/// radius `r` about `c`, entering and leaving, if it does.
fn circle_crossing(a: DVec2, d: DVec2, c: DVec2, r: f64) -> Option<(f64, f64)> {
    let f = a - c;
    let (qa, qb, qc) = (d.length_squared(), 2.0 * f.dot(d), f.length_squared() - r * r);
    let disc = qb * qb - 4.0 * qa * qc;
    (disc > 0.0).then(|| ((-qb - disc.sqrt()) / (2.0 * qa), (-qb + disc.sqrt()) / (2.0 * qa)))
}

/// The cell centres of the layout, checked to fit the rectangle.
fn centres(a: &CollagenArgs, d: f64, r: f64, ell: f64, hw: f64, hh: f64) -> Result<Vec<DVec2>, String> {
    if a.layout != CellLayout::Random && a.cells.is_some() {
        return Err(format!("expected --cells only with --layout random (--layout {} places its own)", a.layout.name()));
    }
    if d <= 2.0 * r + ell {
        return Err(format!("expected --separation > 2 × --cell-radius + --node-spacing (cells apart, with network between), found {d}"));
    }
    let fits = |c: DVec2| c.x.abs() + r + ell <= hw && c.y.abs() + r + ell <= hh;
    let placed: Vec<DVec2> = match a.layout {
        CellLayout::Pair => vec![DVec2::new(-d / 2.0, 0.0), DVec2::new(d / 2.0, 0.0)],
        CellLayout::Square => [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].map(|(x, y)| DVec2::new(x, y) * (d / 2.0)).to_vec(),
        CellLayout::Random => {
            let count = a.cells.ok_or("expected --cells N with --layout random")? as usize;
            if !(1..=1000).contains(&count) {
                return Err(format!("expected 1 <= --cells <= 1000, found {count}"));
            }
            let (sx, sy) = (hw - r - ell, hh - r - ell);
            if sx <= 0.0 || sy <= 0.0 {
                return Err(format!("expected --size larger than a cell (2 × ({r} + {ell}) each way), found {} × {}", 2.0 * hw, 2.0 * hh));
            }
            let draws = Draws::new(a.common.seed, stream::COLLAGEN);
            let mut kept: Vec<DVec2> = Vec::with_capacity(count);
            let mut attempt = 0u64;
            while kept.len() < count {
                if attempt == 10_000 * count as u64 {
                    return Err(format!(
                        "expected room for {count} cells at least --separation {d} apart in --size {} × {}: placed {} in {attempt} attempts",
                        2.0 * hw,
                        2.0 * hh,
                        kept.len()
                    ));
                }
                let [u, v] = draws.uniform2(attempt, CENTRE);
                attempt += 1;
                let c = DVec2::new((2.0 * u - 1.0) * sx, (2.0 * v - 1.0) * sy);
                if kept.iter().all(|k| (*k - c).length() >= d) {
                    kept.push(c);
                }
            }
            kept
        }
    };
    if let Some(c) = placed.iter().find(|&&c| !fits(c)) {
        return Err(format!(
            "expected --size to hold every cell with --node-spacing to spare: found {} × {}, but the cell at ({}, {}) reaches beyond it",
            2.0 * hw,
            2.0 * hh,
            c.x,
            c.y
        ));
    }
    Ok(placed)
}

/// `cellmd build collagen`: a planar fibre network with crosslinks as shared
/// nodes, holes under the cells and each cell a ring of nodes with a hub (see
/// the module documentation, `src/build/collagen.rs`).
pub fn collagen(a: &CollagenArgs) -> Result<Built, String> {
    let d = positive("--separation", a.separation)?;
    let r = positive("--cell-radius", a.cell_radius)?;
    let rho = positive("--density", a.density)?;
    let len = positive("--fibre-length", a.fibre_length)?;
    let ell = positive("--node-spacing", a.node_spacing)?;
    let [w, h] = match a.size[..] {
        [w, h] => [positive("--size W", w)?, positive("--size H", h)?],
        _ => return Err(format!("expected --size W H (two numbers), found {:?}", a.size)),
    };
    let n_ring = a.ring_nodes as usize;
    if !(3..=100_000).contains(&n_ring) {
        return Err(format!("expected 3 <= --ring-nodes <= 100000, found {n_ring}"));
    }
    let (hw, hh) = (w / 2.0, h / 2.0);
    let cells = centres(a, d, r, ell, hw, hh)?;
    let n_fibres = (rho * (w + len) * (h + len) / len).round() as usize;
    if n_fibres > MAX_FIBRES {
        return Err(format!("expected at most {MAX_FIBRES} fibres (ρ·(W + L)(H + L)/L), found {n_fibres}: lower --density or --size"));
    }
    if (w * h / (ell * ell)) > 1e7 {
        return Err(format!(
            "expected at most 10 000 000 nodes' worth of area (W·H/ℓ²), found {:.3e}: raise --node-spacing",
            w * h / (ell * ell)
        ));
    }

    let mut g = Graph::default();
    // Rings first: cell c's node k is graph node c·n + k.
    for c in &cells {
        for k in 0..n_ring {
            let (s, co) = (TAU * k as f64 / n_ring as f64).sin_cos();
            g.node(*c + DVec2::new(co, s) * r, Kind::Ring);
        }
    }
    let ring_node = |c: usize, x: DVec2| {
        let phi = (x - cells[c]).to_angle().rem_euclid(TAU);
        c * n_ring + (phi / TAU * n_ring as f64).round() as usize % n_ring
    };

    // Fibres as segments a + t·dir, t ∈ [t0, t1] inside the rectangle.
    let draws = Draws::new(a.common.seed, stream::COLLAGEN);
    let fibres: Vec<(DVec2, DVec2, f64, f64)> = (0..n_fibres as u64)
        .filter_map(|k| {
            let [u, v] = draws.uniform2(k, FIBRE_CENTRE);
            let centre = DVec2::new((u - 0.5) * (w + len), (v - 0.5) * (h + len));
            let dir = DVec2::from_angle(PI * draws.uniform(k, FIBRE_ANGLE)) * len;
            let start = centre - dir / 2.0;
            clip(start, dir, hw, hh).map(|(t0, t1)| (start, dir, t0, t1))
        })
        .collect();
    // Crossings: one shared node each, listed on both fibres by parameter; a
    // crossing closer than ℓ/2 along either fibre to one found before joins
    // that crosslink instead (so no fibre bond is shorter than ℓ/2).
    let mut on_fibre: Vec<Vec<(f64, usize)>> = vec![Vec::new(); fibres.len()];
    let (mut crosslinks, mut merged) = (0, 0);
    for i in 0..fibres.len() {
        let (ai, di, i0, i1) = fibres[i];
        for j in i + 1..fibres.len() {
            let (aj, dj, j0, j1) = fibres[j];
            let denom = di.perp_dot(dj);
            if denom == 0.0 {
                continue;
            }
            let ti = (aj - ai).perp_dot(dj) / denom;
            let tj = (aj - ai).perp_dot(di) / denom;
            let x = ai + di * ti;
            if !(ti > i0 && ti < i1 && tj > j0 && tj < j1) || cells.iter().any(|c| (x - *c).length() <= r) {
                continue;
            }
            let near = |list: &[(f64, usize)], t: f64| list.iter().find(|p| (p.0 - t).abs() * len < ell / 2.0).map(|p| p.1);
            let node = match near(&on_fibre[i], ti).or_else(|| near(&on_fibre[j], tj)) {
                Some(node) => {
                    merged += 1;
                    node
                }
                None => {
                    crosslinks += 1;
                    g.node(x, Kind::Node)
                }
            };
            for (f, t) in [(i, ti), (j, tj)] {
                if on_fibre[f].iter().all(|p| p.1 != node) {
                    on_fibre[f].push((t, node));
                }
            }
        }
    }
    // Each fibre, cut by the holes into pieces; each piece from its first to
    // its last fixed point (anchor, ring, crosslink), free ends trimmed, and
    // an anchor or ring end closer than ℓ/2 to the crosslink next to it left
    // out (the crosslink ends the piece).
    for (f, &(start, dir, t0, t1)) in fibres.iter().enumerate() {
        let mut cuts: Vec<(f64, f64, usize)> =
            cells.iter().enumerate().filter_map(|(c, &x)| circle_crossing(start, dir, x, r).map(|(a, b)| (a, b, c))).collect();
        cuts.sort_by(|x, y| x.0.total_cmp(&y.0));
        let mut pieces: Vec<(f64, End, f64, End)> = Vec::new();
        let mut from = (t0, if t0 > 0.0 { End::Edge } else { End::Free });
        for &(enter, leave, c) in &cuts {
            if enter > from.0 && enter < t1 {
                pieces.push((from.0, from.1, enter, End::Cell(c)));
            }
            if leave > from.0 {
                from = (leave, End::Cell(c));
            }
        }
        if from.0 < t1 {
            pieces.push((from.0, from.1, t1, if t1 < 1.0 { End::Edge } else { End::Free }));
        }
        let mut points = std::mem::take(&mut on_fibre[f]);
        points.sort_by(|x, y| x.0.total_cmp(&y.0));
        for (s0, e0, s1, e1) in pieces {
            // The ends: a ring node, or where an anchor goes (made once kept).
            let end = |t: f64, end: End| match end {
                End::Free => None,
                End::Edge => Some((None, start + dir * t)),
                End::Cell(c) => {
                    let k = ring_node(c, start + dir * t);
                    Some((Some(k), g.nodes[k].0))
                }
            };
            let (first, last) = (end(s0, e0), end(s1, e1));
            let inner: Vec<usize> = points.iter().filter(|p| p.0 > s0 && p.0 < s1).map(|p| p.1).collect();
            let pos = |k: &usize| g.nodes[*k].0;
            let apart = |e: &(Option<usize>, DVec2), next: Option<DVec2>| next.is_none_or(|x| (x - e.1).length() >= ell / 2.0);
            let first = first.filter(|e| apart(e, inner.first().map(pos).or(last.map(|l| l.1))));
            let last = last.filter(|e| apart(e, inner.last().map(pos).or(first.map(|f| f.1))));
            let mut chain: Vec<usize> = Vec::new();
            for (k, x) in first.into_iter().chain(inner.iter().map(|&k| (Some(k), DVec2::ZERO))).chain(last) {
                chain.push(k.unwrap_or_else(|| g.node(x, Kind::Anchor)));
            }
            chain.dedup_by(|x, y| g.nodes[*x].0 == g.nodes[*y].0);
            if chain.len() >= 2 {
                g.fibre(&chain, ell);
            }
        }
    }
    let (keep, keep_edge) = g.prune();

    // Write: per cell its hub and ring, then the network nodes.
    let mut wr = Writer::new(1);
    wr.set_rest_from_geometry(a.common.rest_from_geometry);
    wr.set_own_rest(&a.types.fibre_bond_type);
    let at = |x: DVec2| DVec3::new(x.x, x.y, 0.0);
    let mut id = vec![0u64; g.nodes.len()];
    let mut hubs = Vec::new();
    for (c, &centre) in cells.iter().enumerate() {
        hubs.push(wr.particle(&a.types.hub_type, at(centre), None));
        for k in 0..n_ring {
            id[c * n_ring + k] = wr.particle(&a.types.ring_type, at(g.nodes[c * n_ring + k].0), None);
        }
    }
    let (mut nodes, mut anchors) = (0, 0);
    for (k, &(x, kind)) in g.nodes.iter().enumerate().skip(cells.len() * n_ring) {
        if keep[k] {
            let anchor = kind == Kind::Anchor;
            id[k] = wr.particle(if anchor { &a.types.anchor_type } else { &a.types.node_type }, at(x), None);
            (nodes, anchors) = (nodes + usize::from(!anchor), anchors + usize::from(anchor));
        }
    }
    let cortex = 2.0 * r * (PI / n_ring as f64).sin();
    for c in 0..cells.len() {
        let ring = &id[c * n_ring..(c + 1) * n_ring];
        for k in 0..n_ring {
            wr.bond(&a.types.cortex_bond_type, ring[k], ring[(k + 1) % n_ring]);
        }
    }
    for c in 0..cells.len() {
        for k in 0..n_ring {
            wr.bond(&a.types.spoke_bond_type, hubs[c], id[c * n_ring + k]);
        }
    }
    let mut lengths = Vec::new();
    for (&[p, q], _) in g.edges.iter().zip(&keep_edge).filter(|(_, &k)| k) {
        lengths.push((g.nodes[q].0 - g.nodes[p].0).length());
        wr.bond(&a.types.fibre_bond_type, id[p], id[q]);
    }
    let mut angles = 0;
    for t in g.angles.iter().filter(|t| t.iter().all(|&k| keep[k])) {
        wr.angle(&a.types.angle_type, id[t[0]], id[t[1]], id[t[2]]);
        angles += 1;
    }
    let attached = g.edges.iter().zip(&keep_edge).filter(|(e, &k)| k && e.iter().any(|&v| g.nodes[v].1 == Kind::Ring)).count();
    wr.set_bonds_comment("# type  i  j   (cortex, then spokes, then fibres with their own r0)");
    let area = w * h - cells.len() as f64 * PI * r * r;
    let [lo, mean, hi] = min_mean_max(&lengths);
    let lines = vec![
        format!(
            "{} cells ({} layout, separation {d:?}) of radius {r:?} in the rectangle {w:?} × {h:?} (z = 0) about the origin; centres:{}",
            cells.len(),
            a.layout.name(),
            cells.iter().map(|c| format!(" ({:.6}, {:.6})", c.x, c.y)).collect::<String>()
        ),
        format!(
            "each cell a hub `{}` and a ring of {n_ring} nodes `{}`: cortex `{}` length {cortex:.12e}, spoke `{}` length {r:.12e} (for r0); cell c (from 0) has ids c·{} + 1 (hub) … (c + 1)·{}",
            a.types.hub_type,
            a.types.ring_type,
            a.types.cortex_bond_type,
            a.types.spoke_bond_type,
            n_ring + 1,
            n_ring + 1
        ),
        format!(
            "{n_fibres} fibres of length {len:?} drawn (density {rho:?} µm⁻¹), {} inside the rectangle; {crosslinks} crosslinks outside the holes ({merged} further crossings closer than ℓ/2 joined one)",
            fibres.len()
        ),
        format!(
            "network as written: {nodes} nodes `{}`, {anchors} anchors `{}` at the edge, {} fibre bonds `{}` ({attached} attached to rings), fibre length per area outside the holes {:.6e} µm⁻¹",
            a.types.node_type,
            a.types.anchor_type,
            lengths.len(),
            a.types.fibre_bond_type,
            lengths.iter().sum::<f64>() / area
        ),
        format!("fibre bond length min {lo:.6e} mean {mean:.6e} max {hi:.6e} (node spacing {ell:?}); each fibre bond line ends with its own r0"),
        format!("{angles} angles `{}` along the fibres, at every node where a fibre runs straight on (θ = 180° as built)", a.types.angle_type),
    ];
    let title =
        format!("Collagen network: {} cells, fibres of length {len:?} at density {rho:?} µm⁻¹, seed {}", cells.len(), a.common.seed);
    Ok(wr.finish(&title, "collagen", lines))
}

#[cfg(test)]
mod tests;

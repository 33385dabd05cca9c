//! `cellmd build icosphere`: see [`icosphere`](fn@super::icosphere) for the construction.

use std::path::PathBuf;

use glam::DVec3;

use super::{min_mean_max, positive, vec3, Built, Shell, Writer};
use crate::mesh::{icosphere as icosphere_mesh, SurfaceMesh};

/// Options of an icosphere cell.
#[derive(Clone, Debug)]
pub struct IcosphereCell {
    pub level: u32,
    pub radius: f64,
    pub centre: DVec3,
    pub particle_type: String,
    pub body_type: String,
    /// Bond type of the mesh edges; `None` writes no `[ bonds ]`.
    pub bond_type: Option<String>,
    pub body_id: u64,
    /// Id of the first node (the others follow).
    pub first_id: u64,
    /// Half-width of a fixed (non-periodic) cubic `[ box ]` around the centre; `None` writes no box.
    pub box_half_width: Option<f64>,
    /// A nucleus inside the cell (body `body_id + 1`, nodes after the cell's).
    pub nucleus: Option<Nucleus>,
    /// Write each edge's length as built as its own rest length r0.
    pub rest_from_geometry: bool,
}

/// A nucleus: a concentric icosphere of the cell's level.
#[derive(Clone, Debug)]
pub struct Nucleus {
    pub radius: f64,
    pub particle_type: String,
    pub body_type: String,
    /// Bond type of its mesh edges; `None` writes none.
    pub bond_type: Option<String>,
}

impl Default for IcosphereCell {
    fn default() -> Self {
        Self {
            level: 2,
            radius: 1.0,
            centre: DVec3::ZERO,
            particle_type: "node".into(),
            body_type: "cell".into(),
            bond_type: Some("edge".into()),
            body_id: 1,
            first_id: 1,
            box_half_width: None,
            nucleus: None,
            rest_from_geometry: false,
        }
    }
}

/// The shell options of every generator that writes icosphere cells
/// (`icosphere`, `cells`, `tensegrity`): the types of the cell's nodes, body
/// and mesh edges, and an optional nucleus with types of its own.
#[derive(clap::Args, Clone, Debug)]
pub struct ShellOptions {
    /// Particle type of the cell's nodes.
    #[arg(long, default_value = "node")]
    pub particle_type: String,
    /// Body type of the cell (what `body` lines of the force field name).
    #[arg(long, default_value = "cell")]
    pub body_type: String,
    /// Bond type of the cell's mesh edges (cortex springs).
    #[arg(long, default_value = "edge")]
    pub bond_type: String,
    /// Write no edge bonds (neither the cell's nor the nucleus').
    #[arg(long)]
    pub no_bonds: bool,
    /// Add a nucleus: a concentric icosphere of this radius (< --radius).
    #[arg(allow_negative_numbers = true, long, value_name = "RADIUS")]
    pub nucleus: Option<f64>,
    /// Particle type of the nucleus' nodes.
    #[arg(long, default_value = "nucleus_node")]
    pub nucleus_particle_type: String,
    /// Body type of the nucleus.
    #[arg(long, default_value = "nucleus")]
    pub nucleus_body_type: String,
    /// Bond type of the nucleus' mesh edges.
    #[arg(long, default_value = "nucleus_edge")]
    pub nucleus_bond_type: String,
}

impl Default for ShellOptions {
    fn default() -> Self {
        Self {
            particle_type: "node".into(),
            body_type: "cell".into(),
            bond_type: "edge".into(),
            no_bonds: false,
            nucleus: None,
            nucleus_particle_type: "nucleus_node".into(),
            nucleus_body_type: "nucleus".into(),
            nucleus_bond_type: "nucleus_edge".into(),
        }
    }
}

impl ShellOptions {
    /// The edge bond types of the cell and of the nucleus: `None` with `--no-bonds`.
    pub fn bond_types(&self) -> (Option<String>, Option<String>) {
        let bond = |t: &str| (!self.no_bonds).then(|| t.to_string());
        (bond(&self.bond_type), bond(&self.nucleus_bond_type))
    }

    /// The nucleus for a cell of radius `radius`, checked: 0 < RN < `radius`.
    pub fn nucleus(&self, radius: f64) -> Result<Option<Nucleus>, String> {
        let Some(r) = self.nucleus else { return Ok(None) };
        if !(r.is_finite() && r > 0.0 && r < radius) {
            return Err(format!("expected 0 < --nucleus RADIUS < --radius {radius}, found {r}"));
        }
        Ok(Some(Nucleus {
            radius: r,
            particle_type: self.nucleus_particle_type.clone(),
            body_type: self.nucleus_body_type.clone(),
            bond_type: self.bond_types().1,
        }))
    }
}

/// Command-line options of `cellmd build icosphere`.
#[derive(clap::Args, Clone, Debug)]
pub struct IcosphereArgs {
    /// Subdivision level n: 10·4ⁿ + 2 nodes.
    #[arg(long)]
    pub level: u32,
    /// Radius of the sphere the nodes lie on (length units).
    #[arg(allow_negative_numbers = true, long)]
    pub radius: f64,
    /// Centre of the cell.
    #[arg(long, num_args = 3, value_names = ["X", "Y", "Z"], allow_negative_numbers = true, default_values_t = [0.0, 0.0, 0.0])]
    pub centre: Vec<f64>,
    #[command(flatten)]
    pub shell: ShellOptions,
    /// Body id of the cell (the nucleus, if any, is the next).
    #[arg(long, default_value_t = 1)]
    pub body_id: u64,
    /// Id of the first node; the others follow.
    #[arg(long, default_value_t = 1)]
    pub first_id: u64,
    /// Also write a fixed (non-periodic) cubic `[ box ]` of this half-width around the centre.
    #[arg(allow_negative_numbers = true, long = "box", value_name = "HALF_WIDTH")]
    pub box_half_width: Option<f64>,
    /// Write each bond's length as built as its own rest length r0 (`type i j r0`), so the shell starts force-free.
    #[arg(long)]
    pub rest_from_geometry: bool,
    /// The topology file to write.
    #[arg(short, long)]
    pub output: PathBuf,
}

/// `cellmd build icosphere`: one cell as a closed triangulated shell, the
/// icosphere of subdivision level n (10·4ⁿ + 2 nodes: 12, 42, 162, 642,
/// 2562, …) of a given radius, with its nodes as particles of one body, its
/// faces as that body's outward-wound triangles and, optionally, its edges as
/// bonds (cortex springs). `--nucleus RADIUS` adds a second body, a
/// concentric icosphere of the same level inside it (its own particle, body
/// and bond types).
pub fn icosphere(a: &IcosphereArgs) -> Result<Built, String> {
    positive("--radius", a.radius)?;
    let centre = vec3("--centre", &a.centre)?;
    if a.level > 8 {
        return Err(format!("expected --level <= 8 (2 621 442 nodes), found {}", a.level));
    }
    if a.box_half_width.is_some_and(|h| h.is_nan() || h <= a.radius) {
        return Err(format!("expected --box HALF_WIDTH > the radius {}", a.radius));
    }
    let nucleus = a.shell.nucleus(a.radius)?;
    if a.body_id == 0 || a.first_id == 0 {
        return Err("expected --body-id and --first-id >= 1".into());
    }
    Ok(icosphere_cell(&IcosphereCell {
        level: a.level,
        radius: a.radius,
        centre,
        particle_type: a.shell.particle_type.clone(),
        body_type: a.shell.body_type.clone(),
        bond_type: a.shell.bond_types().0,
        body_id: a.body_id,
        first_id: a.first_id,
        box_half_width: a.box_half_width,
        nucleus,
        rest_from_geometry: a.rest_from_geometry,
    }))
}

/// One closed icosphere shell as written: the unit-radius mesh, scaled and shifted.
pub(crate) struct ShellSpec<'a> {
    pub mesh: &'a SurfaceMesh,
    /// Node positions of the mesh at radius 1 around the origin.
    pub unit: &'a [DVec3],
    pub radius: f64,
    pub centre: DVec3,
    pub particle_type: &'a str,
    pub body_type: &'a str,
    pub bond_type: Option<&'a str>,
    /// The body the shell is: its nodes' body and its faces'; `None` writes
    /// the nodes and edges alone (no body, no faces).
    pub body_id: Option<u64>,
}

impl ShellSpec<'_> {
    /// Adds the shell's nodes, edge bonds, body and faces to `w`.
    pub fn write(&self, w: &mut Writer) -> Shell {
        let x: Vec<DVec3> = self.unit.iter().map(|p| *p * self.radius + self.centre).collect();
        let ids: Vec<u64> = x.iter().map(|p| w.particle(self.particle_type, *p, self.body_id)).collect();
        let lengths: Vec<f64> = self.mesh.edges().iter().map(|e| (x[e.ends[1] as usize] - x[e.ends[0] as usize]).length()).collect();
        if let Some(bond) = self.bond_type {
            for e in self.mesh.edges() {
                w.bond(bond, ids[e.ends[0] as usize], ids[e.ends[1] as usize]);
            }
        }
        if let Some(body) = self.body_id {
            w.body(body, self.body_type);
            for f in self.mesh.triangles() {
                w.triangle(body, f.map(|k| ids[k as usize]));
            }
        }
        let shell = Shell {
            body_id: self.body_id,
            nodes: x.len(),
            edges: self.mesh.edges().len(),
            faces: self.mesh.triangles().len(),
            volume: self.mesh.volume(&x),
            area: self.mesh.area(&x),
            edge_lengths: min_mean_max(&lengths),
        };
        w.shells.push(shell.clone());
        shell
    }
}

/// The unit icosphere of `level` and its mesh.
pub(crate) fn unit_icosphere(level: u32) -> (Vec<DVec3>, SurfaceMesh) {
    let (unit, faces) = icosphere_mesh(level, 1.0);
    let mesh = SurfaceMesh::new(unit.len(), faces).expect("an icosphere is a closed mesh");
    (unit, mesh)
}

/// The icosphere cell as a topology file.
pub fn icosphere_cell(spec: &IcosphereCell) -> Built {
    // Scaled directly (not from the unit sphere) so the nodes are the ones
    // `mesh::icosphere` puts at this radius, bit for bit.
    let (x, faces) = icosphere_mesh(spec.level, spec.radius);
    let mesh = SurfaceMesh::new(x.len(), faces).expect("an icosphere is a closed mesh");
    let mut w = Writer::new(spec.first_id);
    w.set_rest_from_geometry(spec.rest_from_geometry);
    w.set_bonds_comment("# the mesh edges");
    let cell = ShellSpec {
        mesh: &mesh,
        unit: &x,
        radius: 1.0,
        centre: spec.centre,
        particle_type: &spec.particle_type,
        body_type: &spec.body_type,
        bond_type: spec.bond_type.as_deref(),
        body_id: Some(spec.body_id),
    }
    .write(&mut w);
    let mut lines = vec![cell.summary()];
    if let Some(n) = &spec.nucleus {
        let (unit, mesh) = unit_icosphere(spec.level);
        let nucleus = ShellSpec {
            mesh: &mesh,
            unit: &unit,
            radius: n.radius,
            centre: spec.centre,
            particle_type: &n.particle_type,
            body_type: &n.body_type,
            bond_type: n.bond_type.as_deref(),
            body_id: Some(spec.body_id + 1),
        }
        .write(&mut w);
        lines.push(format!("nucleus (body {}, radius {:?}): {}", spec.body_id + 1, n.radius, nucleus.summary()));
    }
    if let Some(h) = spec.box_half_width {
        w.set_box([0, 1, 2].map(|a| (spec.centre[a] - h, spec.centre[a] + h, false)));
    }
    let title = format!(
        "Icosphere cell: subdivision level {}, radius {:?}, centre ({:?}, {:?}, {:?})",
        spec.level, spec.radius, spec.centre.x, spec.centre.y, spec.centre.z
    );
    w.finish(&title, "icosphere", lines)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::build::testing::parse;

    #[test]
    fn icosphere_cells_parse_as_closed_bodies_with_the_expected_counts() {
        for (level, nodes) in [(0, 12), (1, 42), (2, 162), (3, 642)] {
            let spec =
                IcosphereCell { level, radius: 4.0, centre: DVec3::new(1.0, -2.0, 3.0), box_half_width: Some(10.0), ..Default::default() };
            let cell = icosphere_cell(&spec);
            let shell = &cell.shells[0];
            assert_eq!((shell.nodes, shell.edges, shell.faces), (nodes, 3 * (nodes - 2), 2 * (nodes - 2)));
            let top = parse(&cell);
            assert_eq!(top.ids.len(), nodes);
            assert_eq!(top.bonds.len(), shell.edges);
            assert_eq!(top.triangles.len(), shell.faces);
            assert!(top.positions.iter().all(|p| ((*p - spec.centre).length() - 4.0).abs() < 1e-12));
            let sphere = 4.0 / 3.0 * std::f64::consts::PI * 64.0;
            assert!(shell.volume < sphere && shell.volume > 0.6 * sphere);
            // Deterministic: the same options give the same bytes.
            assert_eq!(icosphere_cell(&spec).text, cell.text);
        }
    }

    #[test]
    fn the_committed_single_cell_is_what_the_builder_writes() {
        let spec = IcosphereCell { level: 3, radius: 5.0, centre: DVec3::new(0.0, 0.0, 5.1), ..Default::default() };
        let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/topologies/single_cell.top")).unwrap();
        assert_eq!(icosphere_cell(&spec).text, text);
    }

    #[test]
    fn options_name_the_types_and_ids() {
        let spec = IcosphereCell {
            level: 0,
            first_id: 101,
            body_id: 7,
            particle_type: "cortex".into(),
            body_type: "nucleus".into(),
            bond_type: None,
            ..Default::default()
        };
        let text = icosphere_cell(&spec).text;
        assert!(text.contains("\n101 cortex ") && text.contains("\n112 cortex ") && !text.contains("\n113 cortex "));
        assert!(text.contains("[ bodies ]\n7 nucleus\n") && !text.contains("[ bonds ]") && !text.contains("[ box ]"));
    }

    #[test]
    fn a_nucleus_is_a_second_closed_body_inside_the_cell() {
        let spec = IcosphereCell {
            level: 2,
            radius: 5.0,
            centre: DVec3::new(1.0, 2.0, 3.0),
            nucleus: Some(Nucleus {
                radius: 2.0,
                particle_type: "nnode".into(),
                body_type: "nucleus".into(),
                bond_type: Some("nedge".into()),
            }),
            ..Default::default()
        };
        let built = icosphere_cell(&spec);
        let top = parse(&built);
        assert_eq!((built.particles, built.bodies, built.triangles, built.bonds), (324, 2, 640, 960));
        assert_eq!(top.bodies.iter().map(|(id, t)| (*id, t.text.as_str())).collect::<Vec<_>>(), vec![(1, "cell"), (2, "nucleus")]);
        for (k, p) in top.positions.iter().enumerate() {
            let (r, body) = if k < 162 { (5.0, 1) } else { (2.0, 2) };
            assert_eq!(top.body_of[k], Some(body));
            assert!(((*p - spec.centre).length() / r - 1.0).abs() < 1e-12);
        }
        assert!(built.shells[1].volume < built.shells[0].volume / 10.0);
        assert!(built.summary().contains("nucleus (body 2, radius 2.0): 162 nodes, 480 edges, 320 faces"));
        let args = |nucleus| IcosphereArgs {
            level: 1,
            radius: 3.0,
            centre: vec![0.0; 3],
            shell: ShellOptions { nucleus: Some(nucleus), ..ShellOptions::default() },
            body_id: 1,
            first_id: 1,
            box_half_width: None,
            rest_from_geometry: false,
            output: "x.top".into(),
        };
        assert_eq!(icosphere(&args(3.0)).unwrap_err(), "expected 0 < --nucleus RADIUS < --radius 3, found 3");
        assert!(icosphere(&args(-1.0)).is_err());
        assert_eq!(icosphere(&args(1.0)).unwrap().bodies, 2);
        let bare = IcosphereArgs { shell: ShellOptions { no_bonds: true, ..args(1.0).shell }, ..args(1.0) };
        assert_eq!(bare.shell.bond_types(), (None, None));
        assert_eq!(icosphere(&bare).unwrap().bonds, 0);
    }
}

//! Topology generators (`cellmd build ...`): systems written as ordinary
//! topology files, deterministic for given options.
//!
//! - [`icosphere_cell`]: one cell as a closed triangulated shell, the
//!   icosphere of subdivision level n (10·4ⁿ + 2 nodes: 12, 42, 162, 642,
//!   2562, …) of a given radius, with its nodes as particles of one body,
//!   its faces as that body's outward-wound triangles and, optionally, its
//!   edges as bonds (cortex springs).
//!
//! ```
//! use cellmd::build::{icosphere_cell, IcosphereCell};
//! let cell = icosphere_cell(&IcosphereCell { level: 1, radius: 5.0, ..Default::default() });
//! assert_eq!((cell.nodes, cell.edges, cell.faces), (42, 120, 80));
//! assert!(cell.text.contains("[ triangles ]"));
//! ```

use std::fmt::Write;

use glam::DVec3;

use crate::mesh::{icosphere, SurfaceMesh};

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
        }
    }
}

/// A generated topology and what a force field needs to know about it.
#[derive(Clone, Debug)]
pub struct Built {
    pub text: String,
    pub nodes: usize,
    pub edges: usize,
    pub faces: usize,
    /// Enclosed volume and area of the mesh as written (a polyhedron inscribed
    /// in the sphere: slightly less than 4πR³/3 and 4πR²).
    pub volume: f64,
    pub area: f64,
    /// Shortest, mean and longest edge.
    pub edge_lengths: [f64; 3],
}

impl Built {
    /// The summary printed by `cellmd build` and written atop the file.
    pub fn summary(&self) -> String {
        let [lo, mean, hi] = self.edge_lengths;
        format!(
            "{} nodes, {} edges, {} faces; enclosed volume {:.12e}, area {:.12e}; edge length min {lo:.6e} mean {mean:.6e} max {hi:.6e}",
            self.nodes, self.edges, self.faces, self.volume, self.area
        )
    }
}

/// The icosphere cell as a topology file.
pub fn icosphere_cell(spec: &IcosphereCell) -> Built {
    let (unit, faces) = icosphere(spec.level, spec.radius);
    let x: Vec<DVec3> = unit.iter().map(|p| *p + spec.centre).collect();
    let mesh = SurfaceMesh::new(x.len(), faces).expect("an icosphere is a closed mesh");
    let lengths: Vec<f64> = mesh.edges().iter().map(|e| (x[e.ends[1] as usize] - x[e.ends[0] as usize]).length()).collect();
    let edge_lengths = [
        lengths.iter().copied().fold(f64::INFINITY, f64::min),
        lengths.iter().sum::<f64>() / lengths.len() as f64,
        lengths.iter().copied().fold(0.0, f64::max),
    ];
    let mut built = Built {
        text: String::new(),
        nodes: x.len(),
        edges: mesh.edges().len(),
        faces: mesh.triangles().len(),
        volume: mesh.volume(&x),
        area: mesh.area(&x),
        edge_lengths,
    };
    let id = |k: u32| spec.first_id + k as u64;
    let summary = built.summary();
    let t = &mut built.text;
    writeln!(
        t,
        "# Icosphere cell: subdivision level {}, radius {:?}, centre ({:?}, {:?}, {:?})",
        spec.level, spec.radius, spec.centre.x, spec.centre.y, spec.centre.z
    )
    .unwrap();
    writeln!(t, "# (written by `cellmd build icosphere`)").unwrap();
    writeln!(t, "# {summary}").unwrap();
    if let Some(h) = spec.box_half_width {
        writeln!(t, "[ box ]").unwrap();
        for (axis, c) in ["x", "y", "z"].iter().zip(spec.centre.to_array()) {
            writeln!(t, "{axis} {:?} {:?} f", c - h, c + h).unwrap();
        }
    }
    writeln!(t, "[ particles ]\n# id  type  x  y  z  body").unwrap();
    for (k, p) in x.iter().enumerate() {
        writeln!(t, "{} {} {:?} {:?} {:?} {}", id(k as u32), spec.particle_type, p.x, p.y, p.z, spec.body_id).unwrap();
    }
    if let Some(bond) = &spec.bond_type {
        writeln!(t, "[ bonds ]\n# the mesh edges").unwrap();
        for e in mesh.edges() {
            writeln!(t, "{bond} {} {}", id(e.ends[0]), id(e.ends[1])).unwrap();
        }
    }
    writeln!(t, "[ bodies ]\n{} {}", spec.body_id, spec.body_type).unwrap();
    writeln!(t, "[ triangles ]\n# body  i  j  k   (counter-clockwise seen from outside)").unwrap();
    for f in mesh.triangles() {
        writeln!(t, "{} {} {} {}", spec.body_id, id(f[0]), id(f[1]), id(f[2])).unwrap();
    }
    built
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::input::SourceFile;
    use crate::topology::parse_topology;

    #[test]
    fn icosphere_cells_parse_as_closed_bodies_with_the_expected_counts() {
        for (level, nodes) in [(0, 12), (1, 42), (2, 162), (3, 642)] {
            let spec =
                IcosphereCell { level, radius: 4.0, centre: DVec3::new(1.0, -2.0, 3.0), box_half_width: Some(10.0), ..Default::default() };
            let cell = icosphere_cell(&spec);
            assert_eq!((cell.nodes, cell.edges, cell.faces), (nodes, 3 * (nodes - 2), 2 * (nodes - 2)));
            let top = parse_topology(&SourceFile::new("cell.top", cell.text.clone())).unwrap();
            assert_eq!(top.ids.len(), nodes);
            assert_eq!(top.bonds.len(), cell.edges);
            assert_eq!(top.triangles.len(), cell.faces);
            assert!(top.positions.iter().all(|p| ((*p - spec.centre).length() - 4.0).abs() < 1e-12));
            let sphere = 4.0 / 3.0 * std::f64::consts::PI * 64.0;
            assert!(cell.volume < sphere && cell.volume > 0.6 * sphere);
            // Deterministic: the same options give the same bytes.
            assert_eq!(icosphere_cell(&spec).text, cell.text);
        }
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
}

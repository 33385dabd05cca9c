//! The topology file a generator writes: particles, bonds, angles, bodies,
//! triangles and tetrahedra collected in order and rendered as text.

use std::fmt::Write as _;

use glam::DVec3;

use super::{wrap, Built, Shell};

/// Collects particles and terms and renders them as a topology file.
/// Particle ids are consecutive from `first_id` in order of addition.
#[derive(Clone, Debug)]
pub(crate) struct Writer {
    first_id: u64,
    box_axes: Option<[(f64, f64, bool); 3]>,
    particles: Vec<(String, DVec3, Option<u64>)>,
    bonds: Vec<(String, u64, u64)>,
    bonds_comment: String,
    /// Write each bond's length as built as its rest length (`type i j r0`).
    rest_from_geometry: bool,
    /// Bond types whose bonds always carry their length as built as r0.
    own_rest: Vec<String>,
    angles: Vec<(String, [u64; 3])>,
    bodies: Vec<(u64, String)>,
    triangles: Vec<(u64, [u64; 3])>,
    tetrahedra: Vec<(String, [u64; 4])>,
    pub shells: Vec<Shell>,
}

impl Writer {
    pub fn new(first_id: u64) -> Self {
        Self {
            first_id,
            box_axes: None,
            particles: Vec::new(),
            bonds: Vec::new(),
            bonds_comment: "# type  i  j".into(),
            rest_from_geometry: false,
            own_rest: Vec::new(),
            angles: Vec::new(),
            bodies: Vec::new(),
            triangles: Vec::new(),
            tetrahedra: Vec::new(),
            shells: Vec::new(),
        }
    }

    /// Adds a particle and returns its id.
    pub fn particle(&mut self, type_name: &str, x: DVec3, body: Option<u64>) -> u64 {
        self.particles.push((type_name.to_string(), x, body));
        self.first_id + self.particles.len() as u64 - 1
    }

    /// The id the next particle will get.
    pub fn next_id(&self) -> u64 {
        self.first_id + self.particles.len() as u64
    }

    /// Gives particle `id` another type.
    pub fn set_type(&mut self, id: u64, type_name: &str) {
        self.particles[(id - self.first_id) as usize].0 = type_name.to_string();
    }

    /// Particles of type `type_name` written so far.
    pub fn count_type(&self, type_name: &str) -> usize {
        self.particles.iter().filter(|p| p.0 == type_name).count()
    }

    /// The position of particle `id`.
    pub fn position(&self, id: u64) -> DVec3 {
        self.particles[(id - self.first_id) as usize].1
    }

    pub fn bond(&mut self, type_name: &str, i: u64, j: u64) {
        self.bonds.push((type_name.to_string(), i, j));
    }

    /// An angle term with its vertex at `j`.
    pub fn angle(&mut self, type_name: &str, i: u64, j: u64, k: u64) {
        self.angles.push((type_name.to_string(), [i, j, k]));
    }

    pub fn body(&mut self, id: u64, type_name: &str) {
        self.bodies.push((id, type_name.to_string()));
    }

    pub fn triangle(&mut self, body: u64, ids: [u64; 3]) {
        self.triangles.push((body, ids));
    }

    /// A volume element of type `type_name` on particles `ids`.
    pub fn tetra(&mut self, type_name: &str, ids: [u64; 4]) {
        self.tetrahedra.push((type_name.to_string(), ids));
    }

    /// Whether each bond's line ends with its length as built, its own rest length.
    pub fn set_rest_from_geometry(&mut self, on: bool) {
        self.rest_from_geometry = on;
    }

    /// Bonds of `type_name` carry their length as built as r0 whatever
    /// `set_rest_from_geometry` says (a network whose bonds differ by construction).
    pub fn set_own_rest(&mut self, type_name: &str) {
        self.own_rest.push(type_name.to_string());
    }

    /// Whether a bond of `type_name` is written with its own r0.
    fn writes_rest(&self, type_name: &str) -> bool {
        self.rest_from_geometry || self.own_rest.iter().any(|t| t == type_name)
    }

    /// The length of the bond between `i` and `j` as written: the minimum
    /// image on the `[ box ]`'s periodic axes, as the engine measures it.
    fn bond_length(&self, i: u64, j: u64) -> f64 {
        let mut d = self.position(j) - self.position(i);
        if let Some(axes) = self.box_axes {
            let sim_box =
                crate::system::SimBox::new(DVec3::from_array(axes.map(|a| a.0)), DVec3::from_array(axes.map(|a| a.1)), axes.map(|a| a.2));
            d = sim_box.minimum_image(d);
        }
        d.length()
    }

    pub fn set_bonds_comment(&mut self, comment: &str) {
        self.bonds_comment = comment.to_string();
    }

    /// A `[ box ]` section: `(lo, hi, periodic)` per axis.
    pub fn set_box(&mut self, axes: [(f64, f64, bool); 3]) {
        self.box_axes = Some(axes);
    }

    /// A fixed cubic box of half-width `h` around `centre`, which must hold every particle.
    pub fn fixed_cube(&mut self, centre: DVec3, h: f64) -> Result<(), String> {
        if !(h.is_finite() && h > 0.0) {
            return Err(format!("expected --box HALF_WIDTH > 0, found {h}"));
        }
        let reach = self.particles.iter().map(|p| (p.1 - centre).abs().max_element()).fold(0.0, f64::max);
        if reach >= h {
            return Err(format!(
                "expected --box HALF_WIDTH to hold every particle: found {h}, but a particle lies {reach} from the centre"
            ));
        }
        self.set_box([0, 1, 2].map(|a| (centre[a] - h, centre[a] + h, false)));
        Ok(())
    }

    /// Wraps every position into the box on its periodic axes (`[lo, hi)`).
    pub fn wrap_periodic(&mut self) {
        let Some(axes) = self.box_axes else { return };
        for p in &mut self.particles {
            for (a, &(lo, hi, periodic)) in axes.iter().enumerate() {
                if periodic {
                    p.1[a] = wrap(p.1[a], lo, hi);
                }
            }
        }
    }

    /// The topology text: `title` and the generator's command atop, then the
    /// summary `lines` as comments, then the sections.
    pub fn finish(self, title: &str, command: &str, mut lines: Vec<String>) -> Built {
        if self.rest_from_geometry && !self.bonds.is_empty() {
            lines.push("rest lengths: each bond's r0 is its length as built (--rest-from-geometry, 4th field of [ bonds ]): the type's r0 does not apply to them".into());
        }
        let mut t = String::new();
        writeln!(t, "# {title}\n# (written by `cellmd build {command}`)").unwrap();
        for line in &lines {
            writeln!(t, "# {line}").unwrap();
        }
        if let Some(axes) = self.box_axes {
            writeln!(t, "[ box ]").unwrap();
            for (name, (lo, hi, periodic)) in ["x", "y", "z"].iter().zip(axes) {
                writeln!(t, "{name} {lo:?} {hi:?} {}", if periodic { "p" } else { "f" }).unwrap();
            }
        }
        let with_body = self.particles.iter().any(|p| p.2.is_some());
        writeln!(t, "[ particles ]\n# id  type  x  y  z{}", if with_body { "  body" } else { "" }).unwrap();
        for (k, (type_name, x, body)) in self.particles.iter().enumerate() {
            write!(t, "{} {type_name} {:?} {:?} {:?}", self.first_id + k as u64, x.x, x.y, x.z).unwrap();
            match body {
                Some(b) => writeln!(t, " {b}").unwrap(),
                None => writeln!(t).unwrap(),
            }
        }
        if !self.bonds.is_empty() {
            let r0 = if self.bonds.iter().any(|b| self.writes_rest(&b.0)) { "  [r0]" } else { "" };
            let r0 = if self.rest_from_geometry { "  r0" } else { r0 };
            writeln!(t, "[ bonds ]\n{}{r0}", self.bonds_comment).unwrap();
            for (type_name, i, j) in &self.bonds {
                if self.writes_rest(type_name) {
                    writeln!(t, "{type_name} {i} {j} {:?}", self.bond_length(*i, *j)).unwrap();
                } else {
                    writeln!(t, "{type_name} {i} {j}").unwrap();
                }
            }
        }
        if !self.angles.is_empty() {
            writeln!(t, "[ angles ]\n# type  i  j  k   (vertex j)").unwrap();
            for (type_name, [i, j, k]) in &self.angles {
                writeln!(t, "{type_name} {i} {j} {k}").unwrap();
            }
        }
        if !self.bodies.is_empty() {
            writeln!(t, "[ bodies ]").unwrap();
            for (id, type_name) in &self.bodies {
                writeln!(t, "{id} {type_name}").unwrap();
            }
        }
        if !self.triangles.is_empty() {
            writeln!(t, "[ triangles ]\n# body  i  j  k   (counter-clockwise seen from outside)").unwrap();
            for (body, [i, j, k]) in &self.triangles {
                writeln!(t, "{body} {i} {j} {k}").unwrap();
            }
        }
        if !self.tetrahedra.is_empty() {
            writeln!(t, "[ tetrahedra ]\n# type  i  j  k  l").unwrap();
            for (type_name, [i, j, k, l]) in &self.tetrahedra {
                writeln!(t, "{type_name} {i} {j} {k} {l}").unwrap();
            }
        }
        Built {
            text: t,
            lines,
            particles: self.particles.len(),
            bonds: self.bonds.len(),
            angles: self.angles.len(),
            bodies: self.bodies.len(),
            triangles: self.triangles.len(),
            tetrahedra: self.tetrahedra.len(),
            shells: self.shells,
        }
    }
}

//! A parsed topology: particles, bonds, angles, bodies and their faces, and
//! the box, as the parser (`parse.rs`) builds them and the body checks
//! (`surface.rs`) and composition (`merge.rs`) read them.

use glam::DVec3;

use crate::input::Token;

/// One axis of a `[ box ]` section or deck `box` command.
#[derive(Clone, Debug)]
pub struct BoxAxis {
    pub lo: f64,
    pub hi: f64,
    pub periodic: bool,
}

/// A bonded term: its type name (with position) and internal particle indices.
#[derive(Clone, Debug)]
pub struct TypedTerm<const N: usize> {
    pub type_name: Token,
    pub particles: [u32; N],
}

/// A parsed topology. Particle arrays are indexed by internal index (file order).
#[derive(Clone, Debug, Default)]
pub struct Topology {
    pub path: String,
    pub box_axes: Option<[BoxAxis; 3]>,
    pub ids: Vec<u64>,
    pub type_names: Vec<Token>,
    pub positions: Vec<DVec3>,
    pub body_of: Vec<Option<u64>>,
    pub bonds: Vec<TypedTerm<2>>,
    /// Each bond's own rest length r0 (the optional fourth field of its
    /// `[ bonds ]` line) with its token; `None`: its bond type's `r0`.
    pub bond_rest: Vec<Option<(f64, Token)>>,
    pub angles: Vec<TypedTerm<3>>,
    /// Volume elements: their rest shape is where `positions` place them.
    pub tetrahedra: Vec<TypedTerm<4>>,
    /// (body id, body type name).
    pub bodies: Vec<(u64, Token)>,
    /// (body id, three particle indices).
    pub triangles: Vec<(u64, [u32; 3])>,
    /// The first token of each triangle's line (for errors).
    pub face_tokens: Vec<Token>,
    /// Bonds that repeat an earlier bond (same type, same particles), with
    /// the earlier one's line: allowed only for a bond type with kinetic
    /// rules, where each is a molecule of its own (checked with the force
    /// field, `deck::placement`).
    pub parallel_bonds: Vec<(usize, u32)>,
}

impl Topology {
    /// Each body's triangles (indices into `triangles`, in file order), keyed
    /// by body id: one pass over the triangles, so that per-body work on a
    /// 10 000-cell spheroid is not bodies × triangles.
    pub fn faces_by_body(&self) -> std::collections::HashMap<u64, Vec<usize>> {
        let mut faces: std::collections::HashMap<u64, Vec<usize>> = std::collections::HashMap::new();
        for (t, (body, _)) in self.triangles.iter().enumerate() {
            faces.entry(*body).or_default().push(t);
        }
        faces
    }
}

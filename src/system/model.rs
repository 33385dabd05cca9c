//! The resolved system (OpenMM's `System`): what interacts with what, and how.
//!
//! Built from a parsed topology and force field; every name is resolved here,
//! so an unknown type is reported at its position in the topology file.

use crate::forcefield::{BondTypeKinetics, ForceField, TermType, Typed};
use crate::input::{InputError, Token};
use crate::interactions::{AngleLaw, ContactLaw, ExternalLaw, RadialLaw, SurfaceLaw, TetraLaw, REGISTRY};
use crate::topology::Topology;
use crate::units::UnitSystem;

/// An external field acting on a group of particles (deck `external`).
#[derive(Clone, Debug)]
pub struct External {
    pub term: Typed<ExternalLaw>,
    pub group: String,
    /// Internal indices of the particles it acts on, ascending.
    pub members: Vec<u32>,
    /// Parameters given as expressions of the particle's unwrapped position
    /// `x`, `y`, `z` and the simulated time `t` (parameter index, tree):
    /// they replace `term.params` entries wherever the field is evaluated.
    pub expressions: Vec<(usize, crate::expr::Expr)>,
}

impl External {
    /// The field on a particle at unwrapped position `x` at time `t`. An
    /// expression outside its domain there (e.g. `sqrt(x)` at x < 0) gives
    /// a NaN parameter, so the run stops with a blow-up report naming this
    /// external as the particle's culprit.
    pub fn at(&self, x: glam::DVec3, t: f64) -> crate::interactions::OneBody {
        let ExternalLaw(eval) = self.term.law;
        if self.expressions.is_empty() {
            return eval(&self.term.params, x);
        }
        let mut params = self.term.params.clone();
        for (k, expr) in &self.expressions {
            params[*k] = expr.eval(&mut |r| position_or_time(r, x, t)).unwrap_or(f64::NAN);
        }
        eval(&params, x)
    }
}

/// The value of `x`, `y`, `z` or `t` in an external's parameter expression.
pub fn position_or_time(r: crate::expr::Ref, x: glam::DVec3, t: f64) -> Result<f64, String> {
    match r {
        crate::expr::Ref::Name("x") => Ok(x.x),
        crate::expr::Ref::Name("y") => Ok(x.y),
        crate::expr::Ref::Name("z") => Ok(x.z),
        crate::expr::Ref::Name("t") => Ok(t),
        crate::expr::Ref::Name(other) => Err(format!("found `{other}`, expected x, y, z, t or a numeric deck variable")),
        thermo => Err(format!("found {}, expected x, y, z, t or a numeric deck variable", thermo.quoted())),
    }
}

/// A closed surface of the topology (a cell, a nucleus): its nodes and mesh.
#[derive(Clone, Debug)]
pub struct Body {
    /// The user's body id (`[ bodies ]`).
    pub id: u64,
    /// Index into [`Model::body_type_names`].
    pub body_type: u32,
    /// Local node k of the mesh is particle `nodes[k]` (internal indices, ascending).
    pub nodes: Vec<u32>,
    pub mesh: std::sync::Arc<crate::mesh::SurfaceMesh>,
}

/// Weights of the pair terms between bonded neighbours (LAMMPS
/// `special_bonds lj W12 W13 W14`): for 1-2, 1-3 and 1-4 neighbours along
/// the bonds, 0 leaves the pair out, 1 counts it in full, and a weight in
/// between scales its energy and force.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpecialBonds {
    pub weights: [f64; 3],
}

impl SpecialBonds {
    /// Whether some weight lies strictly between 0 and 1.
    pub fn is_fractional(&self) -> bool {
        self.weights.iter().any(|&w| w > 0.0 && w < 1.0)
    }
}

impl Default for SpecialBonds {
    /// Directly bonded pairs are excluded; 1-3 and 1-4 pairs interact.
    fn default() -> Self {
        Self { weights: [0.0, 1.0, 1.0] }
    }
}

/// The resolved system.
#[derive(Clone, Debug)]
pub struct Model {
    pub units: UnitSystem,
    /// User-facing particle ids, by internal index.
    pub ids: Vec<u64>,
    /// Particle type index (into `type_names`), by internal index.
    pub types: Vec<u32>,
    pub type_names: Vec<String>,
    /// Drag γ per particle type.
    pub type_drag: Vec<f64>,
    /// Radius per particle type (0 if not given).
    pub type_radius: Vec<f64>,
    pub bond_types: Vec<Typed<RadialLaw>>,
    /// Kinetic rules of each bond type (same order as `bond_types`).
    pub bond_kinetics: Vec<BondTypeKinetics>,
    pub bonds: Vec<[u32; 2]>,
    pub bond_type: Vec<u32>,
    /// The topology's per-bond rest lengths (`type i j r0`), by topology
    /// bond; `None`: the bond type's `r0`. Only the source of each bond's
    /// initial [`BondState::rest`](crate::system::BondState); forces read the state.
    pub bond_rest: Vec<Option<f64>>,
    /// How many of `bonds` come from the topology (the rest were formed).
    pub topology_bonds: usize,
    /// Bond formation rules (`bind` lines).
    pub bind_rules: Vec<crate::forcefield::BindRule>,
    pub angle_types: Vec<Typed<AngleLaw>>,
    pub angles: Vec<[u32; 3]>,
    pub angle_type: Vec<u32>,
    /// Volume element types (`tetra` lines).
    pub tetra_types: Vec<Typed<TetraLaw>>,
    /// Volume elements (`[ tetrahedra ]`), their types and rest shapes (the
    /// topology's positions of their corners).
    pub tetras: Vec<[u32; 4]>,
    pub tetra_type: Vec<u32>,
    pub tetra_rest: Vec<crate::mesh::TetraRest>,
    pub pair_rules: Vec<Typed<RadialLaw>>,
    /// The particle types (a, b) each pair rule acts between.
    pub pair_rule_types: Vec<(u32, u32)>,
    /// For type pair (a, b): indices into `pair_rules` (symmetric).
    pub pair_table: Vec<Vec<u32>>,
    pub externals: Vec<External>,
    pub special_bonds: SpecialBonds,
    /// Triangles of closed surfaces (outward-wound), kept for shell terms and output.
    pub triangles: Vec<[u32; 3]>,
    /// The body id of each triangle.
    pub triangle_body: Vec<u64>,
    /// Body types: the names `body` lines of the force field give.
    pub body_type_names: Vec<String>,
    /// Surface terms (`body` lines), each acting on every body of its type.
    pub body_rules: Vec<Typed<SurfaceLaw>>,
    /// The body type of each surface term.
    pub body_rule_type: Vec<u32>,
    /// Node–face contact terms between bodies (`contact` lines).
    pub contact_rules: Vec<Typed<ContactLaw>>,
    /// The body types (a, b) each contact term acts between (symmetric).
    pub contact_rule_types: Vec<(u32, u32)>,
    /// The bodies of the topology, in `[ bodies ]` order.
    pub bodies: Vec<Body>,
}

/// Per-bond rest lengths need a bond law with `r0`, and must give valid
/// parameters when they replace it.
fn check_bond_rest(topology: &Topology, ff: &ForceField, bond_type: &[u32]) -> Result<(), InputError> {
    for (b, rest) in topology.bond_rest.iter().enumerate() {
        let Some((r0, token)) = rest else { continue };
        let t = bond_type[b] as usize;
        let term = &ff.bond_types[t];
        let name = term.interaction.name();
        let Some(k) = ff.bond_kinetics[t].rest_index else {
            return Err(token.error(format!(
                "found a rest length for a bond of type `{}`, whose law `{name}` has no `r0`; expected `type i j` without one",
                term.label.text
            )));
        };
        let mut params = term.params.clone();
        params[k] = *r0;
        term.interaction
            .validate(&params)
            .map_err(|e| token.error(format!("invalid `{name}` parameters with this bond's r0 = {r0}: expected {e}")))?;
    }
    Ok(())
}

fn resolve<L>(name: &Token, table: &[Typed<L>], what: &str) -> Result<u32, InputError> {
    table.iter().position(|t| t.label.text == name.text).map(|i| i as u32).ok_or_else(|| {
        let names: Vec<&str> = table.iter().map(|t| t.label.text.as_str()).collect();
        let listed = if names.is_empty() { "none are defined".to_string() } else { names.join(", ") };
        name.error(format!("found {what} type `{}`, expected one defined in the force field ({listed})", name.text))
    })
}

impl Model {
    /// Resolves a topology against a force field.
    pub fn build(topology: &Topology, ff: &ForceField, units: UnitSystem, special_bonds: SpecialBonds) -> Result<Model, InputError> {
        crate::forcefield::check_pair_types(ff)?;
        let type_names: Vec<String> = ff.particle_types.iter().map(|t| t.name.text.clone()).collect();
        let mut types = Vec::with_capacity(topology.ids.len());
        for name in &topology.type_names {
            let t = ff.particle_type(&name.text).ok_or_else(|| {
                name.error(format!(
                    "found particle type `{}`, expected one defined in the force field ({})",
                    name.text,
                    type_names.join(", ")
                ))
            })?;
            types.push(t as u32);
        }
        let bond_type: Vec<u32> = topology.bonds.iter().map(|b| resolve(&b.type_name, &ff.bond_types, "bond")).collect::<Result<_, _>>()?;
        check_bond_rest(topology, ff, &bond_type)?;
        let bind_rules = ff
            .bind_lines
            .iter()
            .map(|line| {
                let index = |t: &Token| ff.particle_type(&t.text).expect("checked by check_pair_types") as u32;
                Ok(crate::forcefield::BindRule {
                    type_a: index(&line.type_a),
                    type_b: index(&line.type_b),
                    bond_type: resolve(&line.bond_type, &ff.bond_types, "bond")?,
                    k_on: line.k_on,
                    capture: line.capture,
                    max_bonds: line.max_bonds,
                    nearest: line.nearest,
                    between_bodies: line.between_bodies,
                })
            })
            .collect::<Result<_, InputError>>()?;
        let angle_type = topology.angles.iter().map(|a| resolve(&a.type_name, &ff.angle_types, "angle")).collect::<Result<_, _>>()?;
        let tetra_type = topology.tetrahedra.iter().map(|t| resolve(&t.type_name, &ff.tetra_types, "tetra")).collect::<Result<_, _>>()?;
        let tetra_rest = topology
            .tetrahedra
            .iter()
            .map(|t| {
                crate::mesh::TetraRest::new(t.particles.map(|p| topology.positions[p as usize])).map_err(|e| {
                    let ids = t.particles.map(|p| topology.ids[p as usize].to_string()).join("–");
                    t.type_name.error(format!("tetrahedron {ids}: {e}; expected four corners that span a volume"))
                })
            })
            .collect::<Result<_, _>>()?;
        let nt = type_names.len();
        let mut pair_table = vec![Vec::new(); nt * nt];
        let mut pair_rule_types = Vec::with_capacity(ff.pair_rules.len());
        for (index, rule) in ff.pair_rules.iter().enumerate() {
            let a = ff.particle_type(&rule.type_a.text).expect("checked by check_pair_types");
            let b = ff.particle_type(&rule.type_b.text).expect("checked by check_pair_types");
            pair_rule_types.push((a as u32, b as u32));
            pair_table[a * nt + b].push(index as u32);
            if a != b {
                pair_table[b * nt + a].push(index as u32);
            }
        }
        let body_type_names: Vec<String> = ff.body_type_names().into_iter().map(String::from).collect();
        let body_type_index = |t: &Token| body_type_names.iter().position(|n| *n == t.text).expect("named by the force field") as u32;
        let body_rule_type = ff.body_rules.iter().map(|r| body_type_index(&r.body_type)).collect();
        for t in ff.contact_rules.iter().flat_map(|r| [&r.type_a, &r.type_b]) {
            if !topology.bodies.iter().any(|(_, name)| name.text == t.text) {
                let mut listed: Vec<&str> = Vec::new();
                for (_, name) in &topology.bodies {
                    if !listed.contains(&name.text.as_str()) {
                        listed.push(&name.text);
                    }
                }
                let listed = if listed.is_empty() { "it has none".to_string() } else { listed.join(", ") };
                return Err(t.error(format!("found body type `{}`, expected a body type of the topology's [ bodies ] ({listed})", t.text)));
            }
        }
        let contact_rule_types = ff.contact_rules.iter().map(|r| (body_type_index(&r.type_a), body_type_index(&r.type_b))).collect();
        let mut bodies = Vec::with_capacity(topology.bodies.len());
        let faces_by_body = topology.faces_by_body();
        for (id, type_name) in &topology.bodies {
            let body_type = body_type_names.iter().position(|n| *n == type_name.text).ok_or_else(|| {
                let listed = if body_type_names.is_empty() { "none are defined".to_string() } else { body_type_names.join(", ") };
                type_name.error(format!(
                    "found body type `{}`, expected one that `body` or `contact` lines of the force field give terms to ({listed})",
                    type_name.text
                ))
            })?;
            let faces: Vec<[u32; 3]> = faces_by_body.get(id).into_iter().flatten().map(|&t| topology.triangles[t].1).collect();
            let mut nodes: Vec<u32> = faces.iter().flatten().copied().collect();
            nodes.sort_unstable();
            nodes.dedup();
            let local = |p: u32| nodes.binary_search(&p).expect("a node of the body") as u32;
            let local_faces = faces.iter().map(|t| t.map(local)).collect();
            let mesh = crate::mesh::SurfaceMesh::new(nodes.len(), local_faces)
                .map_err(|e| type_name.error(format!("body {id}: {e}; expected a closed, oriented surface")))?;
            bodies.push(Body { id: *id, body_type: body_type as u32, nodes, mesh: std::sync::Arc::new(mesh) });
        }
        Ok(Model {
            units,
            ids: topology.ids.clone(),
            types,
            type_drag: ff.particle_types.iter().map(|t| t.drag).collect(),
            type_radius: ff.particle_types.iter().map(|t| t.radius).collect(),
            type_names,
            bond_types: ff.bond_types.clone(),
            bond_kinetics: ff.bond_kinetics.clone(),
            bonds: topology.bonds.iter().map(|b| b.particles).collect(),
            topology_bonds: topology.bonds.len(),
            bind_rules,
            bond_type,
            bond_rest: topology.bond_rest.iter().map(|r| r.as_ref().map(|(r0, _)| *r0)).collect(),
            angle_types: ff.angle_types.clone(),
            angles: topology.angles.iter().map(|a| a.particles).collect(),
            angle_type,
            tetra_types: ff.tetra_types.clone(),
            tetras: topology.tetrahedra.iter().map(|t| t.particles).collect(),
            tetra_type,
            tetra_rest,
            pair_rules: ff.pair_rules.iter().map(|r| r.term.clone()).collect(),
            pair_rule_types,
            pair_table,
            externals: Vec::new(),
            special_bonds,
            triangles: topology.triangles.iter().map(|t| t.1).collect(),
            triangle_body: topology.triangles.iter().map(|t| t.0).collect(),
            body_type_names,
            body_rules: ff.body_rules.iter().map(|r| r.term.clone()).collect(),
            body_rule_type,
            contact_rules: ff.contact_rules.iter().map(|r| r.term.clone()).collect(),
            contact_rule_types,
            bodies,
        })
    }

    pub fn len(&self) -> usize {
        self.ids.len()
    }

    pub fn is_empty(&self) -> bool {
        self.ids.is_empty()
    }

    /// Whether any bond type has kinetic rules or bind rules (bonds then
    /// carry state, and the kinetics engine runs every step).
    pub fn has_kinetics(&self) -> bool {
        self.bond_kinetics.iter().any(|k| !k.rules.is_empty()) || !self.bind_rules.is_empty()
    }

    /// Whether bonds carry state ([`BondState`](crate::system::BondState)):
    /// with kinetics, or when some bond has its own rest length.
    pub fn has_bond_state(&self) -> bool {
        self.has_kinetics() || self.bond_rest.iter().any(Option::is_some)
    }

    /// The body of each particle ([`crate::forcefield::NO_BODY`] outside bodies).
    pub fn body_of_particles(&self) -> Vec<u32> {
        let mut body = vec![crate::forcefield::NO_BODY; self.len()];
        for (b, nodes) in self.bodies.iter().enumerate() {
            for &i in &nodes.nodes {
                body[i as usize] = b as u32;
            }
        }
        body
    }

    /// Makes the bond list the topology's plus the bonds `formed` in a run.
    pub fn set_formed_bonds(&mut self, formed: &[crate::system::FormedBond]) {
        self.bonds.truncate(self.topology_bonds);
        self.bond_type.truncate(self.topology_bonds);
        for f in formed {
            self.bonds.push(f.particles);
            self.bond_type.push(f.bond_type);
        }
    }

    /// The initial rest length of bonds of a type whose rules evolve it
    /// (motor, ratchet, plastic); `None` when the type's `r0` always applies.
    pub fn evolving_rest_length(&self, bond_type: usize) -> Option<f64> {
        let kinetics = &self.bond_kinetics[bond_type];
        let evolves = kinetics.rules.iter().any(|r| r.rule.needs_rest_length());
        kinetics.rest_index.filter(|_| evolves).map(|k| self.bond_types[bond_type].params[k])
    }

    /// The rest length bond `b` starts a deck with, when it has its own: the
    /// topology's per-bond r0, else its type's `r0` if its rules evolve it;
    /// `None`: the type's `r0` always applies.
    pub fn initial_rest_length(&self, b: usize) -> Option<f64> {
        self.bond_rest.get(b).copied().flatten().or_else(|| self.evolving_rest_length(self.bond_type[b] as usize))
    }

    /// The rest length bond `b` has now, from its state if bonds have one
    /// (NaN if its law has none).
    pub fn rest_length(&self, b: usize, bonds: Option<&crate::system::BondState>) -> f64 {
        let t = self.bond_type[b] as usize;
        bonds.and_then(|s| s.rest[b]).or_else(|| self.bond_kinetics[t].rest_index.map(|k| self.bond_types[t].params[k])).unwrap_or(f64::NAN)
    }

    /// Whether any body has surface terms.
    pub fn has_surface_terms(&self) -> bool {
        self.bodies.iter().any(|b| self.body_rule_type.contains(&b.body_type))
    }

    /// Whether any body has a surface term without a GPU kernel (custom body terms).
    pub fn has_cpu_only_surface_terms(&self) -> bool {
        (0..self.bodies.len()).any(|b| self.rules_of_body(b).any(|r| !self.body_rules[r].interaction.law().runs_on_gpu()))
    }

    /// Whether any volume element carries its volumetric energy on the nodes
    /// ([`crate::interactions::Law::NodalTetra`]; CPU backend only).
    pub fn has_nodal_pressure_tetras(&self) -> bool {
        self.tetra_types.iter().any(|t| t.law.volumetric.is_some())
    }

    /// Whether any contact term acts between bodies.
    pub fn has_contact_terms(&self) -> bool {
        !self.contact_rules.is_empty()
    }

    /// The contact terms (indices into `contact_rules`) between a node of a
    /// body of type `node_type` and a face of a body of type `face_type`.
    pub fn contact_rules_between(&self, node_type: u32, face_type: u32) -> impl Iterator<Item = usize> + '_ {
        (0..self.contact_rules.len()).filter(move |&r| {
            let (a, b) = self.contact_rule_types[r];
            (a, b) == (node_type, face_type) || (b, a) == (node_type, face_type)
        })
    }

    /// Enclosed volume and area of body `b` at positions `x` (made
    /// image-consistent across periodic boundaries first).
    pub fn body_volume_and_area(&self, b: usize, x: &[glam::DVec3], images: &super::Images) -> (f64, f64) {
        let body = &self.bodies[b];
        let mut local = Vec::with_capacity(body.nodes.len());
        body.mesh.unwrap_into(|k| x[body.nodes[k as usize] as usize], |d| images.minimum_image(d), &mut local);
        (body.mesh.volume(&local), body.mesh.area(&local))
    }

    /// The surface terms (indices into `body_rules`) acting on body `b`, in force-field order.
    pub fn rules_of_body(&self, b: usize) -> impl Iterator<Item = usize> + '_ {
        let t = self.bodies[b].body_type;
        (0..self.body_rules.len()).filter(move |&r| self.body_rule_type[r] == t)
    }

    /// Pair rules acting between particle types `a` and `b`.
    #[inline]
    pub fn pair_rules_between(&self, a: u32, b: u32) -> &[u32] {
        &self.pair_table[a as usize * self.type_names.len() + b as usize]
    }

    /// The largest pair cutoff (0 when there are no pair rules).
    pub fn max_pair_cutoff(&self) -> f64 {
        self.pair_rules.iter().map(|r| (r.law.range)(&r.params)).fold(0.0, f64::max)
    }

    /// Pairs left out of the neighbour list by `special_bonds` (i < j): those
    /// whose weight is not 1, following the bonds that are bound (`bound` =
    /// None: all of them).
    pub fn excluded_pairs(&self, bound: Option<&[bool]>) -> Vec<(u32, u32)> {
        self.special_pairs(bound).into_iter().map(|(i, j, _)| (i, j)).collect()
    }

    /// Bonded neighbour pairs (i < j) whose `special_bonds` weight is not 1,
    /// with that weight: the nearest relation along bound bonds (a pair both
    /// 1-2 and 1-3, in a triangle, is 1-2).
    pub fn special_pairs(&self, bound: Option<&[bool]>) -> Vec<(u32, u32, f64)> {
        let n = self.len();
        let mut adjacency: Vec<Vec<u32>> = vec![Vec::new(); n];
        for (b, &[i, j]) in self.bonds.iter().enumerate() {
            if bound.is_some_and(|bound| !bound[b]) {
                continue;
            }
            adjacency[i as usize].push(j);
            adjacency[j as usize].push(i);
        }
        let weights = self.special_bonds.weights;
        let mut pairs = Vec::new();
        for start in 0..n as u32 {
            // Breadth-first to depth 3 along bonds.
            let mut frontier = vec![start];
            let mut seen = vec![start];
            for depth in 1..=3 {
                let mut next = Vec::new();
                for &p in &frontier {
                    for &q in &adjacency[p as usize] {
                        if !seen.contains(&q) {
                            seen.push(q);
                            next.push(q);
                            let w = weights[depth - 1];
                            if w != 1.0 && start < q {
                                pairs.push((start, q, w));
                            }
                        }
                    }
                }
                frontier = next;
            }
        }
        pairs.sort_unstable_by_key(|&(i, j, _)| (i, j));
        pairs.dedup_by_key(|&mut (i, j, _)| (i, j));
        pairs
    }

    /// Index of each interaction type of the registry that this model uses,
    /// in registry order (the `pe/NAME` thermo columns).
    pub fn interactions_in_use(&self) -> Vec<usize> {
        let mut used = vec![false; REGISTRY.len()];
        let mut mark = |t: &TermType| {
            if let Some(k) = REGISTRY.iter().position(|r| r.name() == t.interaction.name()) {
                used[k] = true;
            }
        };
        self.bond_types.iter().for_each(|t| mark(t));
        self.angle_types.iter().for_each(|t| mark(t));
        self.tetra_types.iter().for_each(|t| mark(t));
        self.pair_rules.iter().for_each(|t| mark(t));
        self.externals.iter().for_each(|e| mark(&e.term));
        self.body_rules.iter().for_each(|t| mark(t));
        self.contact_rules.iter().for_each(|t| mark(t));
        (0..REGISTRY.len()).filter(|&k| used[k]).collect()
    }
}

/// Registry index of an interaction (for per-interaction energy accounting).
pub fn registry_index(term: &TermType) -> usize {
    REGISTRY.iter().position(|r| r.name() == term.interaction.name()).expect("term of a registered interaction")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::forcefield::{load_forcefield, ForceField};
    use crate::input::SourceFile;
    use crate::topology::parse_topology;

    /// A branched molecule 1-2-3-4-5 with 6 bonded to 3.
    fn model(special_bonds: SpecialBonds) -> Model {
        let top = parse_topology(&SourceFile::new(
            "t.top",
            "[ particles ]\n1 p 0 0 0\n2 p 1 0 0\n3 p 2 0 0\n4 p 3 0 0\n5 p 4 0 0\n6 p 2 1 0\n[ bonds ]\ns 1 2\ns 2 3\ns 3 4\ns 4 5\ns 3 6\n",
        ))
        .unwrap();
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("f.ff"), "particle p drag 1\nbond s harmonic k 1 r0 1\n").unwrap();
        let mut ff = ForceField::default();
        load_forcefield(&dir.path().join("f.ff"), None, UnitSystem::Lj, &mut ff, &mut Vec::new()).unwrap();
        Model::build(&top, &ff, UnitSystem::Lj, special_bonds).unwrap()
    }

    fn one_based(pairs: Vec<(u32, u32)>) -> Vec<(u32, u32)> {
        pairs.into_iter().map(|(a, b)| (a + 1, b + 1)).collect()
    }

    #[test]
    fn special_bonds_follow_the_bond_graph() {
        let only_12 = SpecialBonds::default();
        assert_eq!(one_based(model(only_12).excluded_pairs(None)), vec![(1, 2), (2, 3), (3, 4), (3, 6), (4, 5)]);
        let only_13 = SpecialBonds { weights: [1.0, 0.0, 1.0] };
        assert_eq!(one_based(model(only_13).excluded_pairs(None)), vec![(1, 3), (2, 4), (2, 6), (3, 5), (4, 6)]);
        let only_14 = SpecialBonds { weights: [1.0, 1.0, 0.0] };
        assert_eq!(one_based(model(only_14).excluded_pairs(None)), vec![(1, 4), (1, 6), (2, 5), (5, 6)]);
        let none = SpecialBonds { weights: [1.0; 3] };
        assert!(model(none).excluded_pairs(None).is_empty());
        // Fractional weights: every pair whose weight is not 1 leaves the neighbour list, with its weight.
        let charmm = SpecialBonds { weights: [0.0, 0.0, 0.5] };
        assert_eq!(
            model(charmm).special_pairs(None).into_iter().filter(|p| p.2 != 0.0).map(|(i, j, w)| (i + 1, j + 1, w)).collect::<Vec<_>>(),
            vec![(1, 4, 0.5), (1, 6, 0.5), (2, 5, 0.5), (5, 6, 0.5)]
        );
        assert_eq!(model(charmm).excluded_pairs(None).len(), 5 + 5 + 4);
    }

    /// `External::at` evaluates expression parameters at the particle's
    /// position and time: a harmonic trap whose centre moves with t, F =
    /// −2(x − c(t)) with energy |x − c(t)|², obeys F = −∇E by central
    /// differences and its closed form; outside a domain the parameter is NaN.
    #[test]
    fn an_external_evaluates_its_expression_parameters_at_each_position_and_time() {
        let label = crate::input::lex(&SourceFile::new("t.in", "trap")).unwrap()[0].tokens[0].clone();
        let field = crate::interactions::lookup("field").unwrap();
        let term = Typed::new(TermType { label, interaction: field, params: vec![0.0; 4] }).unwrap();
        let exprs = ["-2*(x - 0.5*t)", "-2*y", "-2*(z - sin(t))", "(x - 0.5*t)^2 + y^2 + (z - sin(t))^2"];
        let expressions = exprs.iter().enumerate().map(|(k, e)| (k, crate::expr::parse(e).unwrap())).collect();
        let trap = External { term, group: "all".into(), members: vec![0], expressions };
        let h = 1e-5;
        for (x, t) in [(glam::DVec3::new(1.0, 2.0, -1.0), 0.0), (glam::DVec3::new(-0.3, 0.1, 0.7), 2.5)] {
            let at = trap.at(x, t);
            for axis in 0..3 {
                let mut step = glam::DVec3::ZERO;
                step[axis] = h;
                let gradient = (trap.at(x + step, t).energy - trap.at(x - step, t).energy) / (2.0 * h);
                assert!(
                    (at.force[axis] + gradient).abs() < 1e-8,
                    "axis {axis} at {x} t = {t}: F = {} vs −∇E = {}",
                    at.force[axis],
                    -gradient
                );
            }
        }
        let at = trap.at(glam::DVec3::new(2.0, 1.0, 0.0), 2.0);
        assert_eq!(at.force, glam::DVec3::new(-2.0, -2.0, 2.0 * 2f64.sin()));
        assert!((at.energy - (1.0 + 1.0 + 2f64.sin().powi(2))).abs() < 1e-15);
        // Outside an expression's domain the parameter is NaN (the run stops as a blow-up).
        let sqrt = External { expressions: vec![(0, crate::expr::parse("sqrt(x)").unwrap())], ..trap };
        assert!(sqrt.at(glam::DVec3::new(-1.0, 0.0, 0.0), 0.0).force.x.is_nan());
    }
}

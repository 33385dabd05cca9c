//! Composition: several topologies in one system (a deck with several
//! `topology` lines, as LAMMPS' `read_data … add append`).
//!
//! The rule: a later topology's particle ids are shifted by an offset (by
//! default the largest particle id so far, so they follow the earlier ones)
//! and its body ids by the largest body id so far; particle, bond, angle and
//! body type names are shared (the same name is the same type). Every
//! particle, bond, angle, body and triangle keeps its order after those of
//! the earlier topologies. The box is the first one a topology gives (a deck
//! `box` command overrides it).

use super::Topology;

/// A refused [`Topology::append_at`]: particle `id` of the appended topology
/// plus `offset` is taken; `used` is the largest id before it (the least
/// offset that cannot clash).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Clash {
    pub id: u64,
    pub offset: u64,
    pub used: u64,
}

impl Topology {
    /// The largest particle id (0 when empty).
    pub fn max_id(&self) -> u64 {
        self.ids.iter().copied().max().unwrap_or(0)
    }

    /// Appends `other` by the composition rule: its particle ids shifted by
    /// `offset`, by default (`None`, `offset auto`) the largest id so far.
    /// Returns the offset applied.
    pub fn append_at(&mut self, other: Topology, offset: Option<u64>) -> Result<u64, Clash> {
        let used = self.max_id();
        let offset = offset.unwrap_or(used);
        self.append(other, offset).map(|()| offset).map_err(|id| Clash { id, offset, used })
    }

    /// Appends `other` with its particle ids shifted by `id_offset` and its
    /// body ids by the largest body id so far. Returns the first particle id
    /// of `other` that is already in use, if any (nothing is appended then).
    pub fn append(&mut self, other: Topology, id_offset: u64) -> Result<(), u64> {
        let mut ids: Vec<u64> = self.ids.clone();
        ids.sort_unstable();
        if let Some(&clash) = other.ids.iter().find(|&&id| ids.binary_search(&(id + id_offset)).is_ok()) {
            return Err(clash);
        }
        let body_offset = self.bodies.iter().map(|(id, _)| *id).max().unwrap_or(0);
        let base = self.ids.len() as u32;
        let bond_base = self.bonds.len();
        self.parallel_bonds.extend(other.parallel_bonds.iter().map(|&(b, line)| (b + bond_base, line)));
        self.face_tokens.extend(other.face_tokens);
        self.path = if self.path.is_empty() { other.path.clone() } else { format!("{} + {}", self.path, other.path) };
        if self.box_axes.is_none() {
            self.box_axes = other.box_axes;
        }
        self.ids.extend(other.ids.iter().map(|id| id + id_offset));
        self.type_names.extend(other.type_names);
        self.positions.extend(other.positions);
        self.body_of.extend(other.body_of.iter().map(|b| b.map(|b| b + body_offset)));
        self.bonds.extend(other.bonds.into_iter().map(|mut t| {
            t.particles.iter_mut().for_each(|p| *p += base);
            t
        }));
        self.bond_rest.extend(other.bond_rest);
        self.angles.extend(other.angles.into_iter().map(|mut t| {
            t.particles.iter_mut().for_each(|p| *p += base);
            t
        }));
        self.tetrahedra.extend(other.tetrahedra.into_iter().map(|mut t| {
            t.particles.iter_mut().for_each(|p| *p += base);
            t
        }));
        self.bodies.extend(other.bodies.into_iter().map(|(id, name)| (id + body_offset, name)));
        self.triangles.extend(other.triangles.into_iter().map(|(b, t)| (b + body_offset, t.map(|p| p + base))));
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use crate::input::SourceFile;
    use crate::topology::parse_topology;

    fn parse(name: &str, text: &str) -> super::Topology {
        parse_topology(&SourceFile::new(name, text)).unwrap()
    }

    const CELL: &str = "[ particles ]\n1 n 0 0 0 1\n2 n 1 0 0 1\n3 n 0 1 0 1\n4 n 0 0 1 1\n[ bodies ]\n1 cell\n\
                        [ triangles ]\n1 1 3 2\n1 1 2 4\n1 2 3 4\n1 3 1 4\n[ bonds ]\ne 1 2\n";

    #[test]
    fn ids_indices_and_bodies_are_offset() {
        let mut top = parse("a.top", CELL);
        let mut other = parse("b.top", CELL);
        other.positions.iter_mut().for_each(|x| x.x += 5.0);
        let offset = top.max_id();
        top.append(other, offset).unwrap();
        assert_eq!(top.ids, vec![1, 2, 3, 4, 5, 6, 7, 8]);
        assert_eq!(top.body_of[4..], [Some(2); 4]);
        assert_eq!(top.bodies.iter().map(|b| b.0).collect::<Vec<_>>(), vec![1, 2]);
        assert_eq!(top.triangles[4], (2, [4, 6, 5]));
        assert_eq!(top.bonds[1].particles, [4, 5]);
        assert_eq!(top.bonds[1].type_name.text, "e");
        assert_eq!(top.positions[4].x, 5.0);
        assert_eq!(top.path, "a.top + b.top");
        assert_eq!(top.face_tokens.len(), 8, "faces keep their lines for later errors");
    }

    #[test]
    fn a_repeated_bond_of_a_later_topology_is_still_recorded() {
        let mut top = parse("a.top", CELL);
        top.append_at(parse("b.top", &format!("{CELL}e 2 1\n")), None).unwrap();
        assert_eq!(top.parallel_bonds, [(2, 14)], "bond 2 of the whole repeats line 14 of b.top");
    }

    #[test]
    fn a_clashing_offset_is_refused_with_the_first_clash() {
        let mut top = parse("a.top", CELL);
        assert_eq!(top.append(parse("b.top", CELL), 2), Err(1), "id 1 + 2 is taken");
        assert_eq!(top.ids.len(), 4, "nothing appended");
        assert_eq!(top.append_at(parse("b.top", CELL), Some(3)), Err(super::Clash { id: 1, offset: 3, used: 4 }));
        assert_eq!(top.append_at(parse("b.top", CELL), None), Ok(4), "auto: after the largest id");
    }
}

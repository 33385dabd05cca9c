//! Pairs left out of a neighbour list: particle pairs (e.g. bonded
//! neighbours) stored per particle in CSR form, and optionally whole pairs
//! of particle types (those no pair rule acts between, as LAMMPS'
//! `neigh_modify exclude type`).

/// Per-particle sorted lists of excluded partners, and optionally excluded
/// type pairs.
///
/// Built once from a list of pairs; the relation is made symmetric (a pair
/// `(i, j)` excludes `j` from `i`'s list and `i` from `j`'s), self-pairs are
/// ignored and duplicates removed. Particle `i`'s partners are
/// `partners[offsets[i]..offsets[i + 1]]`, sorted ascending, so a lookup is a
/// binary search. Particles beyond the range the exclusions were built for
/// have no exclusions, so [`Exclusions::none`] works for any particle count.
///
/// [`Exclusions::with_type_pairs`] adds a symmetric table of excluded type
/// pairs: a list then skips every pair whose types it names before testing
/// the distance. In a cell whose only pair rules are contacts with a
/// substrate, most candidates are two nodes of one dense shell, and the
/// list shrinks from ~10⁶ pairs to those near the substrate.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Exclusions {
    offsets: Vec<u32>,
    partners: Vec<u32>,
    types: Option<TypePairs>,
}

/// Excluded pairs of particle types.
#[derive(Clone, Debug, PartialEq, Eq)]
struct TypePairs {
    /// The type of each particle.
    of: Vec<u32>,
    n_types: usize,
    /// `excluded[a·n_types + b]`, symmetric.
    excluded: Vec<bool>,
    /// For each type a, the types b with (a, b) not excluded, ascending.
    partners: Vec<Vec<u32>>,
}

impl Exclusions {
    /// No exclusions at all.
    pub fn none() -> Self {
        Self::default()
    }

    /// Builds the symmetric exclusion table for `n` particles from `pairs`.
    ///
    /// # Panics
    /// If a pair names a particle `>= n`.
    pub fn from_pairs(n: usize, pairs: &[(u32, u32)]) -> Self {
        let mut counts = vec![0u32; n + 1];
        for &(i, j) in pairs {
            assert!((i as usize) < n && (j as usize) < n, "exclusion pair ({i}, {j}) names a particle outside 0..{n}");
            if i != j {
                counts[i as usize + 1] += 1;
                counts[j as usize + 1] += 1;
            }
        }
        for k in 0..n {
            counts[k + 1] += counts[k];
        }
        let mut fill = counts.clone();
        let mut partners = vec![0u32; counts[n] as usize];
        for &(i, j) in pairs {
            if i != j {
                partners[fill[i as usize] as usize] = j;
                fill[i as usize] += 1;
                partners[fill[j as usize] as usize] = i;
                fill[j as usize] += 1;
            }
        }
        // Sort and deduplicate each particle's list, compacting in place.
        let mut offsets = Vec::with_capacity(n + 1);
        offsets.push(0u32);
        let mut write = 0usize;
        for k in 0..n {
            let (start, end) = (counts[k] as usize, counts[k + 1] as usize);
            let list = &mut partners[start..end];
            list.sort_unstable();
            let mut last = None;
            for idx in start..end {
                let p = partners[idx];
                if last != Some(p) {
                    partners[write] = p;
                    write += 1;
                    last = Some(p);
                }
            }
            offsets.push(write as u32);
        }
        partners.truncate(write);
        Self { offsets, partners, types: None }
    }

    /// These exclusions, and every pair of particles whose types `(a, b)`
    /// has `excluded(a, b)` (asked for a ≤ b; the relation is made
    /// symmetric). `types` gives each particle's type, all below `n_types`.
    ///
    /// # Panics
    /// If a type is `>= n_types`.
    pub fn with_type_pairs(self, types: &[u32], n_types: usize, excluded: impl Fn(u32, u32) -> bool) -> Self {
        assert!(types.iter().all(|&t| (t as usize) < n_types), "a particle type is outside 0..{n_types}");
        let mut table = vec![false; n_types * n_types];
        for a in 0..n_types {
            for b in a..n_types {
                let out = excluded(a as u32, b as u32);
                (table[a * n_types + b], table[b * n_types + a]) = (out, out);
            }
        }
        let any = table.contains(&true);
        let partners = (0..n_types).map(|a| (0..n_types as u32).filter(|&b| !table[a * n_types + b as usize]).collect()).collect();
        Self { types: any.then(|| TypePairs { of: types.to_vec(), n_types, excluded: table, partners }), ..self }
    }

    /// How many particle classes a neighbour search bins separately: the
    /// number of types when type pairs are excluded, else 1.
    pub(super) fn classes(&self) -> usize {
        self.types.as_ref().map_or(1, |t| t.n_types)
    }

    /// The particles the classes were given for (None without type pairs:
    /// one class for any count).
    pub(super) fn typed_particles(&self) -> Option<usize> {
        self.types.as_ref().map(|t| t.of.len())
    }

    /// The class of particle `i` (its type, or 0 without type pairs).
    #[inline]
    pub(super) fn class_of(&self, i: usize) -> u32 {
        self.types.as_ref().map_or(0, |t| t.of[i])
    }

    /// The classes a particle of class `c` may pair with (all of them
    /// without type pairs).
    #[inline]
    pub(super) fn partner_classes(&self, c: u32) -> &[u32] {
        self.types.as_ref().map_or(&[0], |t| &t.partners[c as usize])
    }

    /// Number of particles the table was built for (0 for [`Exclusions::none`]).
    pub fn len(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// True when the table covers no particle.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Total number of excluded (unordered) pairs.
    pub fn num_pairs(&self) -> usize {
        self.partners.len() / 2
    }

    /// The sorted excluded partners of particle `i` (empty beyond the table).
    #[inline]
    pub fn partners(&self, i: u32) -> &[u32] {
        let i = i as usize;
        if i + 1 >= self.offsets.len() {
            return &[];
        }
        &self.partners[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }

    /// Whether the pair `(i, j)` is excluded (symmetric): by its types or
    /// as a pair.
    #[inline]
    pub fn is_excluded(&self, i: u32, j: u32) -> bool {
        self.excludes_types_of(i, j) || self.partners(i).binary_search(&j).is_ok()
    }

    /// Whether the types of `i` and `j` are an excluded type pair (a table
    /// look-up; the list build never meets such a pair, as it visits only
    /// the bins of `partner_classes`). False beyond the particles
    /// the types were given for.
    #[inline]
    pub fn excludes_types_of(&self, i: u32, j: u32) -> bool {
        self.types.as_ref().is_some_and(|t| match (t.of.get(i as usize), t.of.get(j as usize)) {
            (Some(&a), Some(&b)) => t.excluded[a as usize * t.n_types + b as usize],
            _ => false,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn symmetric_sorted_and_deduplicated() {
        let ex = Exclusions::from_pairs(5, &[(3, 1), (1, 0), (0, 1), (4, 4), (1, 4)]);
        assert_eq!(ex.len(), 5);
        assert_eq!(ex.partners(0), &[1]);
        assert_eq!(ex.partners(1), &[0, 3, 4]);
        assert_eq!(ex.partners(2), &[] as &[u32]);
        assert_eq!(ex.partners(3), &[1]);
        assert_eq!(ex.partners(4), &[1]);
        assert_eq!(ex.num_pairs(), 3);
        assert!(ex.is_excluded(1, 3) && ex.is_excluded(3, 1));
        assert!(!ex.is_excluded(0, 3));
        assert!(!ex.is_excluded(4, 4), "self pairs are ignored");
        assert!(!ex.is_excluded(17, 1), "beyond the table nothing is excluded");
    }

    #[test]
    fn none_excludes_nothing() {
        let ex = Exclusions::none();
        assert!(ex.is_empty());
        assert!(!ex.is_excluded(0, 1));
        assert_eq!(Exclusions::from_pairs(0, &[]).len(), 0);
    }

    #[test]
    fn type_pairs_are_excluded_both_ways_with_the_pairs() {
        // Types 0, 1, 2; only (0, 2) interacts, so (0, 0), (0, 1), (1, 1), (1, 2), (2, 2) are excluded.
        let types = [0, 2, 1, 0, 2];
        let ex = Exclusions::from_pairs(5, &[(0, 1)]).with_type_pairs(&types, 3, |a, b| (a, b) != (0, 2));
        assert!(ex.is_excluded(0, 1) && ex.is_excluded(1, 0), "a type pair (0, 2) that is an excluded particle pair");
        assert!(!ex.is_excluded(3, 1) && !ex.is_excluded(4, 3) && !ex.excludes_types_of(0, 4), "type pairs (0, 2), (2, 0)");
        assert!(ex.excludes_types_of(0, 3) && ex.excludes_types_of(2, 0) && ex.excludes_types_of(2, 4) && ex.excludes_types_of(1, 4));
        assert!(ex.excludes_types_of(4, 2) && ex.is_excluded(4, 2), "(2, 1) asked as (1, 2)");
        assert!(!ex.excludes_types_of(0, 9), "nothing is excluded beyond the typed particles");
        let all_interact = Exclusions::none().with_type_pairs(&types, 3, |_, _| false);
        assert_eq!(all_interact, Exclusions::none(), "no excluded type pair: no table");
    }

    #[test]
    #[should_panic(expected = "outside")]
    fn out_of_range_pair_panics() {
        Exclusions::from_pairs(2, &[(0, 2)]);
    }
}

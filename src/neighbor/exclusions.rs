//! Excluded pairs (e.g. bonded neighbours) stored per particle in CSR form.

/// Per-particle sorted lists of excluded partners.
///
/// Built once from a list of pairs; the relation is made symmetric (a pair
/// `(i, j)` excludes `j` from `i`'s list and `i` from `j`'s), self-pairs are
/// ignored and duplicates removed. Particle `i`'s partners are
/// `partners[offsets[i]..offsets[i + 1]]`, sorted ascending, so a lookup is a
/// binary search. Particles beyond the range the exclusions were built for
/// have no exclusions, so [`Exclusions::none`] works for any particle count.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Exclusions {
    offsets: Vec<u32>,
    partners: Vec<u32>,
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
        Self { offsets, partners }
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

    /// Whether the pair `(i, j)` is excluded (symmetric).
    #[inline]
    pub fn is_excluded(&self, i: u32, j: u32) -> bool {
        self.partners(i).binary_search(&j).is_ok()
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
    #[should_panic(expected = "outside")]
    fn out_of_range_pair_panics() {
        Exclusions::from_pairs(2, &[(0, 2)]);
    }
}

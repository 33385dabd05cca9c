//! The Verlet list with skin, built through a cell list (see the module docs).

use glam::DVec3;
use rayon::prelude::*;

use super::Exclusions;
use crate::system::{Images, SimBox};

const AXES: [char; 3] = ['x', 'y', 'z'];

/// A per-particle sorted Verlet list (CSR) with a skin: full, or half
/// (each pair once, in the row of its lower index).
#[derive(Clone, Debug)]
pub struct NeighborList {
    cutoff: f64,
    skin: f64,
    /// Keep only partners `j > i` (see the module docs).
    half: bool,
    offsets: Vec<u32>,
    neighbors: Vec<u32>,
    /// Positions at the last build (for the skin/2 criterion).
    reference: Vec<DVec3>,
    /// The box at the last build; `None` before the first build.
    reference_box: Option<SimBox>,
    builds: u64,
    grid: [usize; 3],
}

impl NeighborList {
    /// An empty full list for pairs within `cutoff`, searched out to `cutoff + skin`.
    ///
    /// Invalid values (negative or non-finite) are reported by [`Self::build`].
    pub fn new(cutoff: f64, skin: f64) -> Self {
        Self {
            cutoff,
            skin,
            half: false,
            offsets: vec![0],
            neighbors: Vec::new(),
            reference: Vec::new(),
            reference_box: None,
            builds: 0,
            grid: [0; 3],
        }
    }

    /// An empty half list: like [`Self::new`], but particle `i` lists only
    /// its partners `j > i`, so each pair is stored once.
    pub fn half(cutoff: f64, skin: f64) -> Self {
        Self { half: true, ..Self::new(cutoff, skin) }
    }

    /// Whether each pair is stored once (in the row of its lower index).
    pub fn is_half(&self) -> bool {
        self.half
    }

    /// The interaction cutoff.
    pub fn cutoff(&self) -> f64 {
        self.cutoff
    }

    /// The skin (buffer) added to the cutoff.
    pub fn skin(&self) -> f64 {
        self.skin
    }

    /// The list radius `cutoff + skin`.
    pub fn range(&self) -> f64 {
        self.cutoff + self.skin
    }

    /// How many times the list has been built.
    pub fn builds(&self) -> u64 {
        self.builds
    }

    /// Cells per axis used by the last build (`[0; 3]` when no grid was needed).
    pub fn grid(&self) -> [usize; 3] {
        self.grid
    }

    /// Number of particles covered by the last build.
    pub fn len(&self) -> usize {
        self.offsets.len() - 1
    }

    /// True when the last build covered no particle (or there was none).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Number of unordered pairs (each is stored twice in a full list, once in a half list).
    pub fn num_pairs(&self) -> usize {
        if self.half {
            self.neighbors.len()
        } else {
            self.neighbors.len() / 2
        }
    }

    /// CSR offsets: particle `i`'s neighbours are `flat()[offsets()[i]..offsets()[i + 1]]`.
    pub fn offsets(&self) -> &[u32] {
        &self.offsets
    }

    /// All neighbour lists concatenated (CSR payload), e.g. for a GPU upload.
    pub fn flat(&self) -> &[u32] {
        &self.neighbors
    }

    /// The neighbours of particle `i`, sorted ascending (only those above `i`
    /// in a half list).
    #[inline]
    pub fn neighbors(&self, i: usize) -> &[u32] {
        &self.neighbors[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }

    /// Every partner of particle `i`, ascending, from either kind of list
    /// (a half list is searched row by row: for diagnostics, not loops).
    pub fn partners(&self, i: usize) -> Vec<u32> {
        if !self.half {
            return self.neighbors(i).to_vec();
        }
        let below = (0..i).filter(|&k| self.neighbors(k).binary_search(&(i as u32)).is_ok());
        below.map(|k| k as u32).chain(self.neighbors(i).iter().copied()).collect()
    }

    /// True when the list must be rebuilt before computing forces at `positions`:
    /// never built, the box or the particle count changed, or some particle
    /// moved (minimum image) more than `skin/2` since the last build.
    ///
    /// With `cutoff + skin = 0` the list is always empty, so only a change of
    /// box or particle count asks for a rebuild.
    pub fn needs_rebuild(&self, positions: &[DVec3], sim_box: &SimBox) -> bool {
        let Some(reference_box) = &self.reference_box else {
            return true;
        };
        if positions.len() != self.reference.len() || reference_box != sim_box {
            return true;
        }
        if self.range() == 0.0 {
            return false;
        }
        let half = 0.5 * self.skin;
        let limit2 = half * half;
        let images = sim_box.images();
        positions.par_iter().zip(self.reference.par_iter()).with_min_len(4096).any(|(x, x0)| {
            let d2 = images.minimum_image(*x - *x0).length_squared();
            // A NaN displacement also forces a rebuild (which then reports it).
            d2.is_nan() || d2 > limit2
        })
    }

    /// Rebuilds the list for `positions` in `sim_box`, skipping excluded pairs.
    ///
    /// Errors (with the list left unchanged) on a negative or non-finite
    /// cutoff/skin, an inverted or non-finite box, a periodic edge shorter
    /// than `2·(cutoff + skin)`, a non-finite position, or more than `u32::MAX`
    /// particles or pairs.
    pub fn build(&mut self, positions: &[DVec3], sim_box: &SimBox, exclusions: &Exclusions) -> Result<(), String> {
        let range = self.range();
        if !(self.cutoff.is_finite() && self.cutoff >= 0.0) {
            return Err(format!("neighbour list: cutoff must be finite and >= 0, got {}", self.cutoff));
        }
        if !(self.skin.is_finite() && self.skin >= 0.0) {
            return Err(format!("neighbour list: skin must be finite and >= 0, got {}", self.skin));
        }
        let n = positions.len();
        if n > u32::MAX as usize {
            return Err(format!("neighbour list: {n} particles exceed the u32 index range"));
        }
        let lengths = sim_box.lengths();
        for a in 0..3 {
            let l = lengths[a];
            let finite = sim_box.lo[a].is_finite() && sim_box.hi[a].is_finite();
            if !finite || l.is_nan() || l < 0.0 {
                return Err(format!(
                    "neighbour list: box along {} is [{}, {}); it must be finite with hi >= lo",
                    AXES[a], sim_box.lo[a], sim_box.hi[a]
                ));
            }
            if sim_box.periodic[a] && (l <= 0.0 || l < 2.0 * range) {
                return Err(format!(
                    "neighbour list: the periodic box edge along {} is {l}, shorter than \
                     2·(cutoff + skin) = 2·({} + {}) = {}; the minimum image would be ambiguous \
                     — enlarge the box or reduce the cutoff or skin",
                    AXES[a],
                    self.cutoff,
                    self.skin,
                    2.0 * range
                ));
            }
        }
        if let Some(i) = positions.iter().position(|x| !x.is_finite()) {
            return Err(format!("neighbour list: particle {i} has a non-finite position {}", positions[i]));
        }

        if range == 0.0 || n == 0 {
            self.offsets.clear();
            self.offsets.resize(n + 1, 0);
            self.neighbors.clear();
            self.grid = [0; 3];
        } else {
            if exclusions.typed_particles().is_some_and(|typed| typed != n) {
                return Err(format!(
                    "neighbour list: the excluded type pairs were given for {} particles, not {n}",
                    exclusions.typed_particles().unwrap_or(0)
                ));
            }
            let grid = CellGrid::new(range, sim_box, positions, exclusions);
            let chunks = grid.gather(positions, sim_box, exclusions, range * range, self.half);
            let total: usize = chunks.iter().map(|(_, entries)| entries.len()).sum();
            if total > u32::MAX as usize {
                return Err(format!("neighbour list: {total} entries exceed the u32 index range"));
            }
            self.offsets.clear();
            self.offsets.reserve(n + 1);
            self.offsets.push(0);
            self.neighbors.clear();
            self.neighbors.reserve(total);
            let mut end = 0u32;
            for (lengths, entries) in &chunks {
                self.neighbors.extend_from_slice(entries);
                self.offsets.extend(lengths.iter().map(|&k| {
                    end += k;
                    end
                }));
            }
            self.grid = grid.counts;
        }
        self.reference.clear();
        self.reference.extend_from_slice(positions);
        self.reference_box = Some(*sim_box);
        self.builds += 1;
        Ok(())
    }
}

/// Particles binned into cells by a stable counting sort.
struct CellGrid {
    counts: [usize; 3],
    /// Cells per unit length along each axis (`counts / L`; 0 for one cell).
    inv_width: [f64; 3],
    lo: DVec3,
    lengths: DVec3,
    periodic: [bool; 3],
    /// Particle classes binned apart ([`Exclusions::classes`]).
    classes: usize,
    /// Bin of each particle: its flat cell index · classes + its class.
    bin_of: Vec<u32>,
    /// CSR over bins: particles of class k in cell `c` are
    /// `members[start[b]..start[b + 1]]` with b = c·classes + k, ascending.
    start: Vec<u32>,
    members: Vec<u32>,
}

impl CellGrid {
    fn new(range: f64, sim_box: &SimBox, positions: &[DVec3], exclusions: &Exclusions) -> Self {
        let n = positions.len();
        let lengths = sim_box.lengths();
        // Bins are cells × classes: cap their total as the cells' alone.
        let cap = (n.saturating_mul(8) / exclusions.classes()).max(27);
        let mut counts = [1usize; 3];
        for a in 0..3 {
            let mut max_abs = sim_box.lo[a].abs().max(sim_box.hi[a].abs());
            for x in positions {
                max_abs = max_abs.max(x[a].abs());
            }
            let w_min = range * (1.0 + 1e-9) + 8.0 * f64::EPSILON * max_abs;
            let c = (lengths[a] / w_min).floor();
            counts[a] = if c >= 1.0 { (c.min(cap as f64)) as usize } else { 1 };
        }
        // Cap the total number of cells: merge cells (they only grow, so the
        // search stays exact).
        let product = |c: &[usize; 3]| c.iter().map(|&k| k as u128).product::<u128>();
        if product(&counts) > cap as u128 {
            let f = (product(&counts) as f64 / cap as f64).cbrt();
            for c in &mut counts {
                *c = ((*c as f64 / f).floor() as usize).max(1);
            }
            while product(&counts) > cap as u128 {
                let a = (0..3).max_by_key(|&a| counts[a]).unwrap();
                counts[a] -= 1;
            }
        }
        let mut inv_width = [0.0; 3];
        for a in 0..3 {
            if counts[a] > 1 {
                inv_width[a] = counts[a] as f64 / lengths[a];
            }
        }
        let mut grid = Self {
            counts,
            inv_width,
            lo: sim_box.lo,
            lengths,
            periodic: sim_box.periodic,
            classes: exclusions.classes(),
            bin_of: Vec::new(),
            start: Vec::new(),
            members: Vec::new(),
        };
        grid.bin_of = (positions.par_iter().enumerate().with_min_len(4096))
            .map(|(i, x)| grid.flat(grid.coords(*x)) * grid.classes as u32 + exclusions.class_of(i))
            .collect();
        // Stable counting sort: members of a bin come out in ascending particle order.
        let n_bins = counts[0] * counts[1] * counts[2] * grid.classes;
        let mut start = vec![0u32; n_bins + 1];
        for &b in &grid.bin_of {
            start[b as usize + 1] += 1;
        }
        for b in 0..n_bins {
            start[b + 1] += start[b];
        }
        let mut fill = start.clone();
        let mut members = vec![0u32; n];
        for (i, &b) in grid.bin_of.iter().enumerate() {
            members[fill[b as usize] as usize] = i as u32;
            fill[b as usize] += 1;
        }
        grid.start = start;
        grid.members = members;
        grid
    }

    /// Integer cell coordinates of a position.
    #[inline]
    fn coords(&self, x: DVec3) -> [usize; 3] {
        let mut c = [0usize; 3];
        for a in 0..3 {
            let count = self.counts[a];
            if count == 1 {
                continue;
            }
            let mut s = x[a] - self.lo[a];
            if self.periodic[a] {
                let l = self.lengths[a];
                s -= l * (s / l).floor();
            }
            let k = (s * self.inv_width[a]).floor();
            c[a] = if k <= 0.0 { 0 } else { (k as usize).min(count - 1) };
        }
        c
    }

    #[inline]
    fn flat(&self, c: [usize; 3]) -> u32 {
        (c[0] + self.counts[0] * (c[1] + self.counts[1] * c[2])) as u32
    }

    /// Cells adjacent to `c` along one axis (itself included), without duplicates.
    #[inline]
    fn axis_neighbours(&self, a: usize, c: usize) -> ([usize; 3], usize) {
        let count = self.counts[a];
        if self.periodic[a] {
            match count {
                1 => ([c, 0, 0], 1),
                2 => ([c, 1 - c, 0], 2),
                _ => ([(c + count - 1) % count, c, (c + 1) % count], 3),
            }
        } else {
            let mut out = [0; 3];
            let mut k = 0;
            if c > 0 {
                out[k] = c - 1;
                k += 1;
            }
            out[k] = c;
            k += 1;
            if c + 1 < count {
                out[k] = c + 1;
                k += 1;
            }
            (out, k)
        }
    }

    /// The sorted neighbour lists of particles `0..n`, gathered in parallel
    /// by chunks of 1024 particles: per chunk, each particle's list length
    /// and the lists concatenated (one buffer per chunk, not per particle).
    fn gather(&self, positions: &[DVec3], sim_box: &SimBox, exclusions: &Exclusions, range2: f64, half: bool) -> Vec<(Vec<u32>, Vec<u32>)> {
        const CHUNK: usize = 1024;
        let images = sim_box.images();
        let n = positions.len();
        (0..n.div_ceil(CHUNK))
            .into_par_iter()
            .map(|chunk| {
                let particles = chunk * CHUNK..((chunk + 1) * CHUNK).min(n);
                let mut lengths = Vec::with_capacity(particles.len());
                let mut entries = Vec::new();
                for i in particles {
                    let start = entries.len();
                    self.partners_of(i, positions, &images, exclusions, range2, half, &mut entries);
                    entries[start..].sort_unstable();
                    lengths.push((entries.len() - start) as u32);
                }
                (lengths, entries)
            })
            .collect()
    }

    /// Appends the partners of particle `i` within the list radius (only
    /// those above `i` when `half`), in cell order.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    fn partners_of(
        &self,
        i: usize,
        positions: &[DVec3],
        images: &Images,
        exclusions: &Exclusions,
        range2: f64,
        half: bool,
        out: &mut Vec<u32>,
    ) {
        let xi = positions[i];
        let c = self.coords(xi);
        let (nx, kx) = self.axis_neighbours(0, c[0]);
        let (ny, ky) = self.axis_neighbours(1, c[1]);
        let (nz, kz) = self.axis_neighbours(2, c[2]);
        let partner_classes = exclusions.partner_classes(exclusions.class_of(i));
        for &cz in &nz[..kz] {
            for &cy in &ny[..ky] {
                for &cx in &nx[..kx] {
                    let cell = self.flat([cx, cy, cz]) as usize;
                    for &class in partner_classes {
                        let bin = cell * self.classes + class as usize;
                        for &j in &self.members[self.start[bin] as usize..self.start[bin + 1] as usize] {
                            if j as usize == i || (half && (j as usize) < i) {
                                continue;
                            }
                            let d = images.minimum_image(positions[j as usize] - xi);
                            if d.length_squared() < range2 && !exclusions.is_excluded(i as u32, j) {
                                out.push(j);
                            }
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// splitmix64: a tiny deterministic generator for test configurations.
    struct Rng(u64);

    impl Rng {
        fn next_u64(&mut self) -> u64 {
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^ (z >> 31)
        }
        /// Uniform in [0, 1).
        fn unit(&mut self) -> f64 {
            (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
        }
        fn range(&mut self, a: f64, b: f64) -> f64 {
            a + (b - a) * self.unit()
        }
        fn below(&mut self, n: u64) -> u64 {
            self.next_u64() % n
        }
    }

    fn brute_force(x: &[DVec3], b: &SimBox, range: f64, ex: &Exclusions) -> Vec<Vec<u32>> {
        (0..x.len())
            .map(|i| {
                (0..x.len())
                    .filter(|&j| {
                        j != i && !ex.is_excluded(i as u32, j as u32) && b.minimum_image(x[j] - x[i]).length_squared() < range * range
                    })
                    .map(|j| j as u32)
                    .collect()
            })
            .collect()
    }

    fn assert_matches_brute_force(x: &[DVec3], b: &SimBox, cutoff: f64, skin: f64, ex: &Exclusions) -> NeighborList {
        let mut list = NeighborList::new(cutoff, skin);
        list.build(x, b, ex).unwrap();
        let expected = brute_force(x, b, cutoff + skin, ex);
        assert_eq!(list.len(), x.len());
        for (i, want) in expected.iter().enumerate() {
            assert_eq!(list.neighbors(i), &want[..], "particle {i} at {} (grid {:?})", x[i], list.grid());
        }
        let total: usize = expected.iter().map(Vec::len).sum();
        assert_eq!(list.num_pairs() * 2, total);
        for (i, want) in expected.iter().enumerate().step_by(7) {
            assert_eq!(list.partners(i), *want);
        }
        // The half list is the upper triangle of the same pair set.
        let mut half = NeighborList::half(cutoff, skin);
        half.build(x, b, ex).unwrap();
        assert!(half.is_half() && !list.is_half());
        for (i, want) in expected.iter().enumerate() {
            let upper: Vec<u32> = want.iter().copied().filter(|&j| j as usize > i).collect();
            assert_eq!(half.neighbors(i), &upper[..], "half list, particle {i}");
        }
        assert_eq!(half.num_pairs(), list.num_pairs());
        for (i, want) in expected.iter().enumerate().step_by(7) {
            assert_eq!(half.partners(i), *want, "all partners from the half list");
        }
        list
    }

    fn random_positions(rng: &mut Rng, n: usize, lo: DVec3, hi: DVec3) -> Vec<DVec3> {
        (0..n).map(|_| DVec3::new(rng.range(lo.x, hi.x), rng.range(lo.y, hi.y), rng.range(lo.z, hi.z))).collect()
    }

    const PERIODICITIES: [[bool; 3]; 4] = [[true, true, true], [false, false, false], [true, true, false], [false, true, false]];

    #[test]
    fn matches_brute_force_dense_and_sparse() {
        let mut rng = Rng(1);
        let b_lo = DVec3::new(-3.0, 1.0, 0.5);
        let b_hi = DVec3::new(7.0, 9.0, 12.5);
        for periodic in PERIODICITIES {
            let b = SimBox::new(b_lo, b_hi, periodic);
            for &(n, cutoff, skin) in &[(600, 1.0, 0.3), (60, 1.2, 0.4), (300, 0.35, 0.05), (400, 2.0, 0.0)] {
                let x = random_positions(&mut rng, n, b_lo, b_hi);
                let list = assert_matches_brute_force(&x, &b, cutoff, skin, &Exclusions::none());
                assert!(list.grid().iter().product::<usize>() > 1);
            }
        }
    }

    #[test]
    fn matches_brute_force_with_exclusions() {
        let mut rng = Rng(2);
        let b = SimBox::new(DVec3::ZERO, DVec3::new(6.0, 6.0, 6.0), [true, false, true]);
        let x = random_positions(&mut rng, 400, b.lo, b.hi);
        let mut pairs: Vec<(u32, u32)> = (0..399).map(|i| (i, i + 1)).collect();
        for _ in 0..500 {
            pairs.push((rng.below(400) as u32, rng.below(400) as u32));
        }
        let ex = Exclusions::from_pairs(400, &pairs);
        let list = assert_matches_brute_force(&x, &b, 1.0, 0.25, &ex);
        for &(i, j) in &pairs {
            assert!(!list.neighbors(i as usize).contains(&j));
        }
    }

    /// Three types of which only (0, 1) and (2, 2) interact, with pair
    /// exclusions too: the list is the brute-force one with both left out.
    #[test]
    fn matches_brute_force_with_excluded_type_pairs() {
        let mut rng = Rng(5);
        let b = SimBox::new(DVec3::ZERO, DVec3::new(6.0, 6.0, 6.0), [true, true, false]);
        let x = random_positions(&mut rng, 400, b.lo, b.hi);
        let types: Vec<u32> = (0..400).map(|_| rng.below(3) as u32).collect();
        let pairs: Vec<(u32, u32)> = (0..399).map(|i| (i, i + 1)).collect();
        let ex = Exclusions::from_pairs(400, &pairs).with_type_pairs(&types, 3, |a, b| !matches!((a, b), (0, 1) | (2, 2)));
        let list = assert_matches_brute_force(&x, &b, 1.0, 0.25, &ex);
        let unfiltered = assert_matches_brute_force(&x, &b, 1.0, 0.25, &Exclusions::from_pairs(400, &pairs));
        assert!(
            list.num_pairs() > 100 && 2 * list.num_pairs() < unfiltered.num_pairs(),
            "{} of {}",
            list.num_pairs(),
            unfiltered.num_pairs()
        );
        for i in 0..400 {
            for &j in list.neighbors(i) {
                let t = [types[i], types[j as usize]];
                assert!(matches!(t, [0, 1] | [1, 0] | [2, 2]), "pair {i}-{j} of types {t:?}");
            }
        }
    }

    #[test]
    fn particles_on_and_outside_boundaries() {
        let mut rng = Rng(3);
        let lo = DVec3::new(0.0, -2.0, 1.0);
        let hi = DVec3::new(5.0, 3.0, 6.0);
        let (cutoff, skin) = (0.8, 0.2);
        for periodic in PERIODICITIES {
            let b = SimBox::new(lo, hi, periodic);
            let mut x = random_positions(&mut rng, 150, lo, hi);
            // Exactly on faces, one ulp inside the upper face, on cell edges.
            let below = |v: f64| f64::from_bits(v.to_bits() - 1);
            for &(fx, fy, fz) in &[(0.0, 0.0, 0.0), (1.0, 1.0, 1.0), (0.5, 1.0, 0.0), (1.0, 0.5, 0.2)] {
                let p = lo + DVec3::new(fx, fy, fz) * (hi - lo);
                x.push(p);
                x.push(DVec3::new(below(p.x.max(lo.x + 1e-300)), p.y, p.z));
            }
            x.push(DVec3::new(below(hi.x), below(hi.y), below(hi.z)));
            x.push(DVec3::new(lo.x + 1.0, lo.y + 2.0, lo.z + 3.0)); // cell edges (w = 1)
            x.push(DVec3::new(lo.x + 2.0, lo.y + 2.0, lo.z + 3.0));
            // Outside the box on non-periodic axes (wrapped on periodic ones by
            // the integrator, but the list must cope with unwrapped input too).
            for _ in 0..40 {
                let mut p = DVec3::new(rng.range(-2.0, 7.0), rng.range(-4.0, 5.0), rng.range(-1.0, 8.0));
                for a in 0..3 {
                    if periodic[a] {
                        p[a] = rng.range(lo[a], hi[a]);
                    }
                }
                x.push(p);
            }
            x.push(DVec3::new(-1e6, -1e6, 1e6));
            assert_matches_brute_force(&x, &b, cutoff, skin, &Exclusions::none());
        }
    }

    #[test]
    fn unwrapped_periodic_positions_are_still_found() {
        let mut rng = Rng(9);
        let b = SimBox::new(DVec3::ZERO, DVec3::splat(5.0), [true; 3]);
        let x: Vec<DVec3> = random_positions(&mut rng, 200, DVec3::splat(-10.0), DVec3::splat(15.0));
        assert_matches_brute_force(&x, &b, 1.0, 0.2, &Exclusions::none());
    }

    #[test]
    fn one_and_two_cells_per_axis() {
        let mut rng = Rng(4);
        let (cutoff, skin) = (1.0, 0.25);
        let r = cutoff + skin;
        // Edges of exactly 2r (one cell), 2.5r (two cells) and 3.5r (three).
        for lengths in [DVec3::splat(2.0 * r), DVec3::splat(2.5 * r), DVec3::new(2.0 * r, 2.5 * r, 3.5 * r)] {
            for periodic in PERIODICITIES {
                let b = SimBox::new(DVec3::splat(-1.0), DVec3::splat(-1.0) + lengths, periodic);
                for n in [2, 30, 120] {
                    let x = random_positions(&mut rng, n, b.lo, b.hi);
                    let list = assert_matches_brute_force(&x, &b, cutoff, skin, &Exclusions::none());
                    for a in 0..3 {
                        assert!(list.grid()[a] <= 3, "grid {:?}", list.grid());
                    }
                }
            }
        }
        let b = SimBox::new(DVec3::ZERO, DVec3::splat(2.5 * r), [true; 3]);
        let x = random_positions(&mut rng, 10, b.lo, b.hi);
        let mut list = NeighborList::new(cutoff, skin);
        list.build(&x, &b, &Exclusions::none()).unwrap();
        assert_eq!(list.grid(), [2, 2, 2]);
    }

    #[test]
    fn too_small_periodic_box_is_an_error() {
        let b = SimBox::new(DVec3::ZERO, DVec3::new(10.0, 2.3, 10.0), [true, true, false]);
        let mut list = NeighborList::new(1.0, 0.2);
        let err = list.build(&[DVec3::ONE], &b, &Exclusions::none()).unwrap_err();
        assert!(err.contains("along y") && err.contains("2.4"), "{err}");
        assert_eq!(list.builds(), 0);
        // The same edge on a non-periodic axis is fine.
        let b = SimBox::new(DVec3::ZERO, DVec3::new(10.0, 10.0, 2.3), [true, true, false]);
        list.build(&[DVec3::ONE], &b, &Exclusions::none()).unwrap();
        assert_eq!(list.builds(), 1);
    }

    #[test]
    fn invalid_inputs_are_errors() {
        let b = SimBox::new(DVec3::ZERO, DVec3::splat(10.0), [true; 3]);
        let x = [DVec3::ONE, DVec3::new(f64::NAN, 0.0, 0.0)];
        let err = NeighborList::new(1.0, 0.1).build(&x, &b, &Exclusions::none()).unwrap_err();
        assert!(err.contains("particle 1") && err.contains("non-finite"), "{err}");
        let err = NeighborList::new(-1.0, 0.1).build(&x[..1], &b, &Exclusions::none()).unwrap_err();
        assert!(err.contains("cutoff"), "{err}");
        let err = NeighborList::new(1.0, f64::NAN).build(&x[..1], &b, &Exclusions::none()).unwrap_err();
        assert!(err.contains("skin"), "{err}");
        let inverted = SimBox::new(DVec3::ZERO, DVec3::new(10.0, -1.0, 10.0), [false; 3]);
        let err = NeighborList::new(1.0, 0.1).build(&x[..1], &inverted, &Exclusions::none()).unwrap_err();
        assert!(err.contains("along y"), "{err}");
    }

    #[test]
    fn zero_cutoff_and_no_particles() {
        let b = SimBox::new(DVec3::ZERO, DVec3::splat(1e9), [true; 3]);
        let x = vec![DVec3::ONE; 5];
        let mut list = NeighborList::new(0.0, 0.0);
        list.build(&x, &b, &Exclusions::none()).unwrap();
        assert_eq!(list.len(), 5);
        assert_eq!(list.num_pairs(), 0);
        assert!((0..5).all(|i| list.neighbors(i).is_empty()));
        assert_eq!(list.grid(), [0; 3]);
        assert!(!list.needs_rebuild(&[DVec3::splat(3.0); 5], &b));
        assert!(list.needs_rebuild(&[DVec3::ONE; 4], &b));

        let mut list = NeighborList::new(1.0, 0.3);
        list.build(&[], &b, &Exclusions::none()).unwrap();
        assert!(list.is_empty());
        assert_eq!(list.offsets(), &[0]);
        assert!(!list.needs_rebuild(&[], &b));
    }

    #[test]
    fn huge_box_tiny_cutoff_caps_the_grid() {
        let mut rng = Rng(5);
        let b = SimBox::new(DVec3::ZERO, DVec3::splat(1e6), [true, true, false]);
        let mut x = random_positions(&mut rng, 100, b.lo, b.hi);
        // A tight cluster so that some pairs exist.
        for k in 0..50 {
            let jitter = DVec3::new(rng.unit(), rng.unit(), rng.unit()) * 6e-4;
            x.push(DVec3::new(5.0, 5.0, 5.0 + k as f64 * 2e-4) + jitter);
        }
        let list = assert_matches_brute_force(&x, &b, 1e-3, 1e-4, &Exclusions::none());
        let cells: usize = list.grid().iter().product();
        assert!(cells <= 8 * x.len(), "grid {:?}", list.grid());
        assert!(list.num_pairs() > 0);
    }

    #[test]
    fn identical_for_any_thread_count_and_rebuild_time() {
        let mut rng = Rng(6);
        let b = SimBox::new(DVec3::ZERO, DVec3::splat(8.0), [true, true, false]);
        let x = random_positions(&mut rng, 1500, b.lo, b.hi);
        let build_with = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let mut list = NeighborList::new(1.0, 0.3);
                list.build(&x, &b, &Exclusions::none()).unwrap();
                (list.offsets().to_vec(), list.flat().to_vec())
            })
        };
        assert_eq!(build_with(1), build_with(3));

        // A list built from slightly earlier positions, filtered to the cutoff,
        // gives the same ordered pairs as a fresh one.
        let mut early = NeighborList::new(1.0, 0.4);
        let x0: Vec<DVec3> = x.iter().map(|p| *p + DVec3::new(0.05, -0.05, 0.0)).collect();
        early.build(&x0, &b, &Exclusions::none()).unwrap();
        assert!(!early.needs_rebuild(&x, &b));
        let mut fresh = NeighborList::new(1.0, 0.4);
        fresh.build(&x, &b, &Exclusions::none()).unwrap();
        for i in 0..x.len() {
            let within = |l: &NeighborList| -> Vec<u32> {
                l.neighbors(i).iter().copied().filter(|&j| b.minimum_image(x[j as usize] - x[i]).length() < 1.0).collect()
            };
            assert_eq!(within(&early), within(&fresh));
        }
    }

    #[test]
    fn rebuild_criterion_is_half_the_skin() {
        let b = SimBox::new(DVec3::ZERO, DVec3::splat(10.0), [true, true, false]);
        let x = vec![DVec3::new(9.95, 5.0, 5.0), DVec3::new(2.0, 2.0, 2.0)];
        let mut list = NeighborList::new(1.0, 0.4);
        assert!(list.needs_rebuild(&x, &b), "never built");
        list.build(&x, &b, &Exclusions::none()).unwrap();
        assert_eq!(list.builds(), 1);
        assert!(!list.needs_rebuild(&x, &b));

        let moved = |d: DVec3| vec![x[0], x[1] + d];
        assert!(!list.needs_rebuild(&moved(DVec3::new(0.0, 0.19, 0.0)), &b));
        assert!(list.needs_rebuild(&moved(DVec3::new(0.0, 0.21, 0.0)), &b));
        assert!(!list.needs_rebuild(&moved(DVec3::new(0.1, 0.1, 0.1)), &b)); // |d| ≈ 0.173
        assert!(list.needs_rebuild(&moved(DVec3::new(0.0, 0.0, -0.25)), &b));

        // Across the periodic x face: 9.95 → 0.05 (wrapped) is a move of 0.1.
        let wrapped = vec![DVec3::new(0.05, 5.0, 5.0), x[1]];
        assert!(!list.needs_rebuild(&wrapped, &b));
        let wrapped = vec![DVec3::new(0.2, 5.0, 5.0), x[1]];
        assert!(list.needs_rebuild(&wrapped, &b));

        // Box or particle-count changes.
        let other = SimBox::new(DVec3::ZERO, DVec3::splat(11.0), [true, true, false]);
        assert!(list.needs_rebuild(&x, &other));
        assert!(list.needs_rebuild(&x[..1], &b));

        list.build(&wrapped, &b, &Exclusions::none()).unwrap();
        assert_eq!(list.builds(), 2);
        assert!(!list.needs_rebuild(&wrapped, &b));
    }
}

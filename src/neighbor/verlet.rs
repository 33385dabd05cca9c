//! The Verlet list with skin, built through a cell list (see the module docs).

use glam::DVec3;
use rayon::prelude::*;

use super::{Exclusions, ImageShifts};
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
    /// Whether a box with periodic edges shorter than 2·(cutoff + skin) is
    /// allowed (its images walked, [`ImageShifts`]); otherwise it is an error.
    periodic_images: bool,
    /// The image shifts of the last build's box, when it has short edges.
    shifts: Option<ImageShifts>,
    /// With `shifts`: per entry, whether the pair is excluded at its
    /// minimum image (its other images interact).
    skip_minimum: Vec<bool>,
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
            periodic_images: false,
            shifts: None,
            skip_minimum: Vec::new(),
        }
    }

    /// Allows periodic edges shorter than 2·(cutoff + skin): rows then hold
    /// every partner with some image in range, a particle itself when one of
    /// its own images is, and excluded pairs whose other images are in range;
    /// [`Self::for_each_separation`] walks the images (module
    /// `neighbor::images`). For the pair forces; searches that want one
    /// image per pair (contacts, bond formation) keep the error.
    pub fn with_periodic_images(self) -> Self {
        Self { periodic_images: true, ..self }
    }

    /// The image shifts of the last build, when its box had a periodic edge
    /// shorter than 2·(cutoff + skin) (only with [`Self::with_periodic_images`]).
    pub fn image_shifts(&self) -> Option<&ImageShifts> {
        self.shifts.as_ref()
    }

    /// Calls `visit(j, d)` for every partner j of row i and every image of it
    /// within the list range, d = x_j + s·L − x_i: in the usual box one per
    /// partner, its minimum image, in row order; with image shifts, each
    /// partner's images in [`ImageShifts::for_each`] order (a particle's own
    /// images as j = i, once per ± pair in a half list). Consumers test their
    /// own cutoffs on |d|.
    #[inline]
    pub fn for_each_separation(&self, i: usize, x: &[DVec3], images: &Images, mut visit: impl FnMut(u32, DVec3)) {
        let row = self.offsets[i] as usize..self.offsets[i + 1] as usize;
        let Some(shifts) = &self.shifts else {
            for &j in &self.neighbors[row] {
                visit(j, images.minimum_image(x[j as usize] - x[i]));
            }
            return;
        };
        let range2 = self.range() * self.range();
        for k in row {
            let j = self.neighbors[k];
            let own = j as usize == i;
            let d0 = if own { DVec3::ZERO } else { images.minimum_image(x[j as usize] - x[i]) };
            shifts.for_each(d0, range2, self.skip_minimum[k], own, self.half, |d| visit(j, d));
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

    /// Every other particle listed as a partner of `i`, ascending, from
    /// either kind of list (a half list is searched row by row: for
    /// diagnostics, not loops); `i` itself, listed for its own images in a
    /// small periodic box, is left out.
    pub fn partners(&self, i: usize) -> Vec<u32> {
        let others = self.neighbors(i).iter().copied().filter(|&j| j as usize != i);
        if !self.half {
            return others.collect();
        }
        let below = (0..i).filter(|&k| self.neighbors(k).binary_search(&(i as u32)).is_ok());
        below.map(|k| k as u32).chain(others).collect()
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
    /// than `2·(cutoff + skin)` (unless [`Self::with_periodic_images`]), a
    /// non-finite position, or more than `u32::MAX` particles or pairs.
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
            if sim_box.periodic[a] && (l <= 0.0 || (l < 2.0 * range && !self.periodic_images)) {
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

        let shifts = if self.periodic_images && range > 0.0 { ImageShifts::new(sim_box, range)? } else { None };
        self.skip_minimum.clear();
        if range == 0.0 || n == 0 {
            self.offsets.clear();
            self.offsets.resize(n + 1, 0);
            self.neighbors.clear();
            self.grid = [0; 3];
        } else if let Some(shifts) = &shifts {
            self.build_with_images(positions, sim_box, exclusions, shifts);
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
        self.shifts = shifts;
        self.reference.clear();
        self.reference.extend_from_slice(positions);
        self.reference_box = Some(*sim_box);
        self.builds += 1;
        Ok(())
    }

    /// The rows of a box with short periodic edges: every j (j ≥ i in a half
    /// list, i itself included) with some image within the range, excluded
    /// pairs flagged and kept only when an image beyond the minimum is in
    /// range. A plain O(N²) search: such boxes hold few particles per
    /// cutoff volume's worth of box (each pair is walked over its images anyway).
    fn build_with_images(&mut self, positions: &[DVec3], sim_box: &SimBox, exclusions: &Exclusions, shifts: &ImageShifts) {
        let n = positions.len();
        let range2 = self.range() * self.range();
        let images = sim_box.images();
        let rows: Vec<Vec<(u32, bool)>> = (0..n)
            .into_par_iter()
            .with_min_len(64)
            .map(|i| {
                let first = if self.half { i } else { 0 };
                let mut row = Vec::new();
                for j in first..n {
                    let (ju, own) = (j as u32, j == i);
                    if exclusions.excludes_types_of(i as u32, ju) {
                        continue;
                    }
                    let d0 = if own { DVec3::ZERO } else { images.minimum_image(positions[j] - positions[i]) };
                    let excluded = !own && exclusions.is_excluded(i as u32, ju);
                    let minimum_in_range = !own && !excluded && d0.length_squared() < range2;
                    if minimum_in_range || shifts.any_beyond_minimum(d0, range2) {
                        row.push((ju, excluded));
                    }
                }
                row
            })
            .collect();
        self.offsets.clear();
        self.offsets.push(0);
        self.neighbors.clear();
        for row in &rows {
            self.neighbors.extend(row.iter().map(|e| e.0));
            self.skip_minimum.extend(row.iter().map(|e| e.1));
            self.offsets.push(self.neighbors.len() as u32);
        }
        self.grid = [1; 3];
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
mod tests;

//! Periodic images beyond the minimum one, for boxes with a periodic edge
//! shorter than twice the list range (a small box, or a long cutoff).
//!
//! In a periodic box of edge L, particle j interacts with every image
//! x_j + s·L (s integer) within the cutoff of x_i, and i with its own
//! images x_i + s·L, s ≠ 0 — what LAMMPS' ghost atoms and OpenMM's
//! periodic boxes give. When L ≥ 2·r (r the list range) only the minimum
//! image d₀ = minimum_image(x_j − x_i) can be in range; below, several are.
//! Since |d₀,a| ≤ L_a/2, an image d₀ + s·L within r has
//! |s_a| < r/L_a + 1/2, so the shifts |s_a| ≤ ⌊r/L_a + 1/2⌋ (zero on long or
//! fixed axes) cover them all; [`ImageShifts::for_each`] walks them,
//! distance-tested, in a fixed order.
//!
//! A pair excluded by `special_bonds` is excluded at its minimum image only
//! (its other images interact in full), as LAMMPS, which excludes a special
//! neighbour only within half a box (`Domain::minimum_image_check`). A
//! particle's own images are counted once per ± pair in a half list (the
//! shifts s > 0 in lexicographic order), so the energy of i with its images
//! is ½ Σ_{s≠0} E(|s·L|); they exert no force (the ± pair cancels) but add
//! to the virial.

use glam::DVec3;

use crate::system::SimBox;

/// The most images one pair may walk (each costs a distance test per pair
/// per step): 9 261 = 21³, ten images to each side on all three axes.
pub const MAX_IMAGES_PER_PAIR: usize = 9261;

/// The image shifts of a box with short periodic edges.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageShifts {
    /// How many images to each side, per axis (0 on long or fixed axes).
    pub reach: [i32; 3],
    /// The shifts s·L with s > 0 (lexicographic), in ascending s.
    positive: Vec<DVec3>,
}

impl ImageShifts {
    /// Whether some periodic edge of `sim_box` is shorter than `2·range`, so
    /// that pairs within `range` have images beyond the minimum one.
    pub fn has_short_edges(sim_box: &SimBox, range: f64) -> bool {
        let l = sim_box.lengths();
        (0..3).any(|a| sim_box.periodic[a] && l[a] < 2.0 * range)
    }

    /// The shifts for pairs within `range` in `sim_box`; `None` when every
    /// periodic edge is at least `2·range` (the minimum image is the only one).
    /// An error when a pair would have more than [`MAX_IMAGES_PER_PAIR`]
    /// images to walk (an edge many times shorter than the range).
    pub fn new(sim_box: &SimBox, range: f64) -> Result<Option<Self>, String> {
        let l = sim_box.lengths();
        let mut reach = [0i32; 3];
        let mut images = 1.0;
        for a in 0..3 {
            if sim_box.periodic[a] && l[a] < 2.0 * range {
                let r = (range / l[a] + 0.5).floor();
                images *= 2.0 * r + 1.0;
                if !(images <= MAX_IMAGES_PER_PAIR as f64) {
                    return Err(format!(
                        "neighbour list: the periodic box edge along {} is {:e}, so a pair within the list range {range:e} has {images:.3e} \
                         images or more; expected periodic edges long enough for at most {MAX_IMAGES_PER_PAIR} images per pair \
                         (edges ≥ {:e} with this range)",
                        ['x', 'y', 'z'][a],
                        l[a],
                        2.0 * range / (MAX_IMAGES_PER_PAIR as f64).cbrt()
                    ));
                }
                reach[a] = r as i32;
            }
        }
        if reach == [0; 3] {
            return Ok(None);
        }
        let mut positive = Vec::new();
        for sx in 0..=reach[0] {
            for sy in -reach[1]..=reach[1] {
                for sz in -reach[2]..=reach[2] {
                    if sx > 0 || (sx == 0 && (sy > 0 || (sy == 0 && sz > 0))) {
                        positive.push(DVec3::new(sx as f64 * l.x, sy as f64 * l.y, sz as f64 * l.z));
                    }
                }
            }
        }
        Ok(Some(Self { reach, positive }))
    }

    /// Number of images per pair walked (minimum image included).
    pub fn count(&self) -> usize {
        2 * self.positive.len() + 1
    }

    /// Calls `visit(d)` for every image d = d₀ + s·L of a pair with
    /// |d|² < `range2`: d₀ first unless `skip_minimum`, then d₀ + s·L and
    /// d₀ − s·L for each s > 0 in ascending order. For a particle with
    /// itself (`own`, d₀ = 0) only the s > 0 images when `half`, else ±s.
    #[inline]
    pub fn for_each(&self, d0: DVec3, range2: f64, skip_minimum: bool, own: bool, half: bool, mut visit: impl FnMut(DVec3)) {
        if !own && !skip_minimum && d0.length_squared() < range2 {
            visit(d0);
        }
        for &p in &self.positive {
            let up = d0 + p;
            if up.length_squared() < range2 {
                visit(up);
            }
            if !(own && half) {
                let down = d0 - p;
                if down.length_squared() < range2 {
                    visit(down);
                }
            }
        }
    }

    /// Whether some image other than the minimum one is within `range2`.
    pub fn any_beyond_minimum(&self, d0: DVec3, range2: f64) -> bool {
        self.positive.iter().any(|&p| (d0 + p).length_squared() < range2 || (d0 - p).length_squared() < range2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shifts_cover_every_image_in_range_once() {
        let b = SimBox::new(DVec3::ZERO, DVec3::new(1.3, 5.0, 0.7), [true, true, true]);
        let range = 2.0;
        let shifts = ImageShifts::new(&b, range).unwrap().unwrap();
        assert_eq!(shifts.reach, [2, 0, 3]);
        let d0 = b.minimum_image(DVec3::new(0.6, -2.4, 0.33));
        let mut seen = Vec::new();
        shifts.for_each(d0, range * range, false, false, true, |d| seen.push(d));
        // Brute force over a wide block of images.
        let mut want = Vec::new();
        for sx in -6..=6 {
            for sz in -8..=8 {
                let d = d0 + DVec3::new(sx as f64 * 1.3, 0.0, sz as f64 * 0.7);
                if d.length_squared() < range * range {
                    want.push(d);
                }
            }
        }
        assert_eq!(seen.len(), want.len());
        for d in &want {
            assert!(seen.iter().any(|s| (*s - *d).length() < 1e-12), "{d} missing");
        }
        // A particle's own images: each ± pair once in a half list.
        let mut own = 0;
        shifts.for_each(DVec3::ZERO, range * range, false, true, true, |_| own += 1);
        let mut both = 0;
        shifts.for_each(DVec3::ZERO, range * range, false, true, false, |_| both += 1);
        assert_eq!(2 * own, both);
        assert!(own > 0);
        assert!(ImageShifts::new(&SimBox::new(DVec3::ZERO, DVec3::splat(4.0), [true; 3]), range).unwrap().is_none());
    }

    /// An edge far shorter than the range is refused, naming the axis,
    /// instead of walking ~10¹² images a pair; 21³ images are allowed.
    #[test]
    fn too_many_images_are_refused() {
        let b = SimBox::new(DVec3::ZERO, DVec3::new(10.0, 10.0, 1e-12), [false, false, true]);
        let e = ImageShifts::new(&b, 1.3).unwrap_err();
        assert!(e.contains("along z is 1e-12"), "{e}");
        let b = SimBox::new(DVec3::ZERO, DVec3::splat(0.1), [true; 3]);
        assert_eq!(ImageShifts::new(&b, 1.0).unwrap().unwrap().count(), MAX_IMAGES_PER_PAIR);
        assert!(ImageShifts::new(&b, 1.06).is_err());
    }
}

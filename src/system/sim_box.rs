//! Orthorhombic simulation box, periodic or not per axis.
//!
//! Positions on periodic axes are kept wrapped into `[lo, hi)` after every step
//! (with an image counter per particle, as LAMMPS does), so the stored
//! coordinates — and therefore every force sum — are independent of when the
//! neighbour list happened to be rebuilt. Separations use the minimum image
//! convention `d − L·round(d/L)` on periodic axes.

use glam::DVec3;

/// Image counters stay below 2⁶² in magnitude (i64, with room to add): a
/// coordinate further from a periodic box cannot be wrapped into it.
pub const MAX_IMAGE: f64 = 4_611_686_018_427_387_904.0;

/// An axis-aligned box `[lo, hi)` with a periodic flag per axis.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SimBox {
    pub lo: DVec3,
    pub hi: DVec3,
    pub periodic: [bool; 3],
}

impl SimBox {
    pub fn new(lo: DVec3, hi: DVec3, periodic: [bool; 3]) -> Self {
        Self { lo, hi, periodic }
    }

    /// Why this box cannot hold a system (read from a restart, say): an
    /// axis whose bounds are not finite, not ordered, or whose edge or its
    /// inverse overflows; `field: found …, expected …`.
    pub fn check(&self) -> Result<(), String> {
        for (a, axis) in ["x", "y", "z"].iter().enumerate() {
            let (lo, hi) = (self.lo[a], self.hi[a]);
            let edge = hi - lo;
            if !(lo.is_finite() && hi.is_finite() && hi > lo && edge.is_finite() && (1.0 / edge).is_finite()) {
                return Err(format!(
                    "box: found {axis} from {lo:e} to {hi:e}, expected finite bounds lo < hi whose edge hi − lo and its inverse are finite"
                ));
            }
        }
        Ok(())
    }

    /// Edge lengths `hi − lo`.
    pub fn lengths(&self) -> DVec3 {
        self.hi - self.lo
    }

    /// Box volume (length³).
    pub fn volume(&self) -> f64 {
        let l = self.lengths();
        l.x * l.y * l.z
    }

    /// Minimum-image form of a separation vector (see [`Images`]).
    #[inline]
    pub fn minimum_image(&self, d: DVec3) -> DVec3 {
        self.images().minimum_image(d)
    }

    /// The box's periodic images, prepared for many minimum-image calls.
    #[inline]
    pub fn images(&self) -> Images {
        let l = self.lengths();
        let axis = |a: usize, v: f64| if self.periodic[a] { v } else { 0.0 };
        Images {
            lengths: DVec3::new(axis(0, l.x), axis(1, l.y), axis(2, l.z)),
            inverse: DVec3::new(axis(0, 1.0 / l.x), axis(1, 1.0 / l.y), axis(2, 1.0 / l.z)),
        }
    }

    /// Wraps a position into the box on periodic axes, updating its image
    /// counter: one box length is added or subtracted (the usual case, as a
    /// step crosses at most one box), more by floor arithmetic, never by a loop
    /// (1e300 in a 10 µm box, or 1 in a 1e-12 one, never ended). A coordinate
    /// that cannot be wrapped — not finite, or `MAX_IMAGE` box lengths or
    /// more away — is left as it is, for [`Self::misplaced_axis`] to report.
    #[inline]
    pub fn wrap(&self, x: &mut DVec3, image: &mut [i64; 3]) {
        for axis in 0..3 {
            let (lo, hi) = (self.lo[axis], self.hi[axis]);
            let v = &mut x[axis];
            if !self.periodic[axis] || (*v >= lo && *v < hi) {
                continue;
            }
            let l = hi - lo;
            let crossed = if *v >= hi { 1 } else { -1 };
            let once = *v - crossed as f64 * l;
            if once >= lo && once < hi {
                *v = once;
                image[axis] += crossed;
                continue;
            }
            let t = *v - lo;
            let r = t.rem_euclid(l);
            let n = ((t - r) / l).round();
            if !(n.abs() < MAX_IMAGE) {
                continue;
            }
            let inside = lo + r;
            (*v, image[axis]) = if inside < hi { (inside, image[axis] + n as i64) } else { (lo, image[axis] + n as i64 + 1) };
        }
    }

    /// The first axis on which a position cannot be in this box: outside
    /// `[lo, hi]` on a fixed axis, or not wrappable on a periodic one (see
    /// [`Self::wrap`]); `None` if it is in the box.
    #[inline]
    pub fn misplaced_axis(&self, x: DVec3) -> Option<usize> {
        (0..3).find(|&a| {
            let (lo, hi, v) = (self.lo[a], self.hi[a], x[a]);
            if self.periodic[a] {
                !((v - lo).abs() < MAX_IMAGE * (hi - lo))
            } else {
                !(v >= lo && v <= hi)
            }
        })
    }

    /// What is wrong with a position [`Self::misplaced_axis`] refuses.
    pub fn misplacement(&self, x: DVec3, axis: usize) -> String {
        let (name, lo, hi, v) = (["x", "y", "z"][axis], self.lo[axis], self.hi[axis], x[axis]);
        if self.periodic[axis] {
            format!("{name} = {v:e} cannot be wrapped into the periodic box [{lo:e}, {hi:e}) (2⁶² box lengths or more away, or not finite)")
        } else {
            format!("{name} = {v:e} is outside the fixed box [{lo:e}, {hi:e}]")
        }
    }

    /// Unwrapped position from a wrapped one and its image counter.
    #[inline]
    pub fn unwrap(&self, x: DVec3, image: [i64; 3]) -> DVec3 {
        let l = self.lengths();
        x + DVec3::new(image[0] as f64 * l.x, image[1] as f64 * l.y, image[2] as f64 * l.z)
    }

    /// `p` for a periodic axis, `f` for a fixed one (LAMMPS boundary letters).
    pub fn boundary_letter(&self, axis: usize) -> char {
        if self.periodic[axis] {
            'p'
        } else {
            'f'
        }
    }
}

/// Minimum-image arithmetic with the lengths and their inverses precomputed:
/// `d − L·nearest(d/L)` on periodic axes (`L = 0`, `1/L = 0` on the others),
/// with no division and no libm call, so the loop vectorises. `nearest`
/// rounds half to even by the 1.5·2⁵² trick (exact for |d/L| < 2⁵¹); it is odd
/// in its argument, so `minimum_image(−d) = −minimum_image(d)` bit for bit and
/// a bond evaluated from either end gives exactly opposite forces.
#[derive(Clone, Copy, Debug)]
pub struct Images {
    lengths: DVec3,
    inverse: DVec3,
}

impl Images {
    /// 1.5·2⁵²: `(q + SHIFT) − SHIFT` is q rounded to the nearest integer.
    pub const SHIFT: f64 = 6_755_399_441_055_744.0;

    #[inline(always)]
    pub fn minimum_image(&self, d: DVec3) -> DVec3 {
        let q = d * self.inverse;
        let nearest = (q + DVec3::splat(Self::SHIFT)) - DVec3::splat(Self::SHIFT);
        d - self.lengths * nearest
    }

    /// The periodic lengths L and their inverses 1/L (0 on non-periodic
    /// axes), for vector code that repeats [`Self::minimum_image`]'s arithmetic.
    #[inline(always)]
    pub fn lengths_and_inverses(&self) -> (DVec3, DVec3) {
        (self.lengths, self.inverse)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn periodic_box() -> SimBox {
        SimBox::new(DVec3::ZERO, DVec3::new(10.0, 10.0, 10.0), [true, true, false])
    }

    #[test]
    fn minimum_image_is_shorter_than_half_a_box() {
        let b = periodic_box();
        let d = b.minimum_image(DVec3::new(9.0, -7.0, 9.0));
        assert_eq!(d, DVec3::new(-1.0, 3.0, 9.0));
        let far = b.minimum_image(DVec3::new(-23.5, 46.0, -1e6));
        assert_eq!(far, DVec3::new(-3.5, -4.0, -1e6));
        let e = DVec3::new(4.999, -7.3, 2.0);
        assert_eq!(b.minimum_image(-e), -b.minimum_image(e), "odd, bit for bit");
    }

    #[test]
    fn wrap_then_unwrap_round_trips() {
        let b = periodic_box();
        let original = DVec3::new(23.5, -0.5, 12.0);
        let mut x = original;
        let mut image = [0; 3];
        b.wrap(&mut x, &mut image);
        assert_eq!(image, [2, -1, 0]);
        assert!(x.x >= 0.0 && x.x < 10.0 && x.y >= 0.0 && x.y < 10.0);
        assert!((b.unwrap(x, image) - original).length() < 1e-12);
    }

    #[test]
    fn far_coordinates_wrap_by_floor_or_are_refused() {
        let b = periodic_box();
        let mut x = DVec3::new(2.2e10 + 3.0, -1e15 - 2.5, 0.0);
        let mut image = [0; 3];
        b.wrap(&mut x, &mut image);
        assert_eq!((x, image), (DVec3::new(3.0, 7.5, 0.0), [2_200_000_000, -100_000_000_000_001, 0]));
        assert_eq!(b.misplaced_axis(x), None);
        // A 1e-12 edge: 10¹² images, at once.
        let tiny = SimBox::new(DVec3::ZERO, DVec3::splat(1e-12), [true; 3]);
        let (mut x, mut image) = (DVec3::new(1.0, -1.0, 0.5e-12), [0; 3]);
        tiny.wrap(&mut x, &mut image);
        assert!((0..3).all(|a| x[a] >= 0.0 && x[a] < 1e-12), "{x}");
        assert_eq!(image[2], 0);
        assert!((image[0] - 1_000_000_000_000).abs() <= 1 && (image[1] + 1_000_000_000_000).abs() <= 1, "{image:?}");
        // Beyond 2⁶² box lengths, or not finite: left as it is, and reported.
        for far in [1e300, f64::INFINITY, f64::NAN] {
            let (mut x, mut image) = (DVec3::new(1.0, far, 1.0), [0; 3]);
            b.wrap(&mut x, &mut image);
            assert_eq!((x.y.to_bits(), image), (far.to_bits(), [0; 3]));
            assert_eq!(b.misplaced_axis(x), Some(1));
        }
        assert_eq!(
            b.misplacement(DVec3::new(1.0, 1e300, 1.0), 1),
            "y = 1e300 cannot be wrapped into the periodic box [0e0, 1e1) (2⁶² box lengths or more away, or not finite)"
        );
        // A fixed axis holds [lo, hi], ends included.
        assert_eq!(b.misplaced_axis(DVec3::new(0.0, 0.0, 10.0)), None);
        assert_eq!(b.misplaced_axis(DVec3::new(0.0, 0.0, 10.000001)), Some(2));
        assert_eq!(b.misplacement(DVec3::new(0.0, 0.0, -1.0), 2), "z = -1e0 is outside the fixed box [0e0, 1e1]");
    }

    #[test]
    fn boxes_that_cannot_hold_a_system_are_named() {
        assert_eq!(periodic_box().check(), Ok(()));
        for (lo, hi) in [(-1e308, 1e308), (0.0, f64::INFINITY), (f64::NAN, 1.0), (1.0, 1.0), (2.0, 1.0), (0.0, 1e-310)] {
            let b = SimBox::new(DVec3::new(0.0, lo, 0.0), DVec3::new(1.0, hi, 1.0), [false; 3]);
            assert!(b.check().unwrap_err().starts_with("box: found y from"), "{lo} {hi}");
        }
    }
}

//! Restoring a fibre's segment lengths exactly after a step.
//!
//! The linearised step ([`super::kkt`]) keeps each length to first order;
//! the second-order excess (a segment that turned by δθ grows by ℓ·δθ²/2,
//! always longer) is removed here by projecting the points back onto the
//! lengths ℓ_k, as Cytosim's `reshape` does (Nédélec & Foethke 2007) and
//! SHAKE does for general constraints (Ryckaert, Ciccotti & Berendsen 1977),
//! but exactly and in O(n). Each iteration moves point i by
//!
//! Δᵢ = Wᵢ·(g_i·u_i − g_{i−1}·u_{i−1}),
//!
//! Wᵢ its mobility 1/γᵢ on each free coordinate (0 where fixed or held) and
//! u_k the unit segment vectors *of the current iterate*, with one
//! multiplier g_k per segment from the tridiagonal system G·g = e, e_k =
//! |r_k| − ℓ_k, G = J·W·Jᵀ (G_kk = u_k·(W_k + W_{k+1})u_k, G_{k,k+1} =
//! −u_k·W_{k+1}u_{k+1}): a Gauss–Newton step towards the constraint
//! surface in the mobility metric, converging quadratically (from the
//! excess of a 1 ms step of a thermal actin fibre, two to four iterations
//! reach |r − ℓ|/ℓ < 10⁻¹²). Correcting along the directions before the
//! step instead (SHAKE's choice) diverges on long fibres: the excess of
//! every segment must be taken up by sliding points along the chain
//! (displacements growing with its length), and a slide along rotated
//! directions bends the chain by as much as it shortens it. The
//! displacement is what a force g_k·u_k/dt along each segment gives in one
//! step, so Σ g_k/dt adds to the segment's tension.

use glam::DVec3;

use super::kkt::ChainSystem;
use crate::system::Images;

/// Why a reshape failed: the worst segment and its |r − ℓ|/ℓ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReshapeFailure {
    pub segment: usize,
    pub relative_error: f64,
}

/// Scratch of one chain's reshape, sized on first use.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Reshape {
    /// Σ g_k over the iterations of the last reshape, per segment.
    pub g: Vec<f64>,
    /// The corrected positions of the chain's points.
    pub moved: Vec<DVec3>,
    /// Iterations the last reshape took.
    pub iterations: usize,
    weight: Vec<DVec3>,
    /// W_k + W_{k+1} and 1/ℓ_k per segment, fixed over the iterations.
    both: Vec<DVec3>,
    inverse_length: Vec<f64>,
    direction: Vec<DVec3>,
    /// Whether each segment's ends can move along it (else its row of G is the identity).
    movable: Vec<bool>,
    diagonal: Vec<f64>,
    off: Vec<f64>,
    rhs: Vec<f64>,
}

/// Factorises the symmetric tridiagonal matrix (diagonal, off) in place
/// (`off[k]` couples k and k + 1): `diagonal` becomes the reciprocal
/// pivots, so each row of a solve divides once. False on a zero or
/// non-finite pivot.
fn thomas_factor(diagonal: &mut [f64], off: &[f64]) -> bool {
    for k in 0..diagonal.len() {
        if k > 0 {
            let m = off[k - 1] * diagonal[k - 1];
            diagonal[k] -= m * off[k - 1];
        }
        let pivot = diagonal[k];
        if !(pivot != 0.0 && pivot.is_finite()) {
            return false;
        }
        diagonal[k] = 1.0 / pivot;
    }
    true
}

/// Solves (diagonal, off)·x = rhs in place with the factor of [`thomas_factor`].
fn thomas_solve(reciprocal: &[f64], off: &[f64], rhs: &mut [f64]) {
    let n = rhs.len();
    for k in 1..n {
        let m = off[k - 1] * reciprocal[k - 1];
        rhs[k] -= m * rhs[k - 1];
    }
    rhs[n - 1] *= reciprocal[n - 1];
    for k in (0..n - 1).rev() {
        rhs[k] = (rhs[k] - off[k] * rhs[k + 1]) * reciprocal[k];
    }
}

/// Wᵢ·(g_i·u_i − g_{i−1}·u_{i−1}): point i's displacement by the
/// multipliers g of segments with directions u (−W·Jᵀg; 0 past the ends).
#[inline(always)]
fn displacement(weight: &[DVec3], direction: &[DVec3], g: &[f64], i: usize) -> DVec3 {
    let after = if i < g.len() { g[i] * direction[i] } else { DVec3::ZERO };
    let before = if i > 0 { g[i - 1] * direction[i - 1] } else { DVec3::ZERO };
    weight[i] * (after - before)
}

impl Reshape {
    /// Moves the chain's points (after the step, as `at` reads them) onto
    /// the lengths of `system` (with its drags and held coordinates), into
    /// `moved`; `images` gives the segment vectors across periodic bounds.
    pub fn restore(
        &mut self,
        system: &ChainSystem,
        at: impl Fn(usize) -> DVec3,
        images: &Images,
        tolerance: f64,
        max_iterations: usize,
    ) -> Result<(), ReshapeFailure> {
        self.begin(system, at);
        let mut iteration = 0;
        loop {
            let (segment, relative_error) = self.linearise(system, images);
            if relative_error <= tolerance {
                break;
            }
            if iteration == max_iterations || !self.factor() {
                return Err(ReshapeFailure { segment, relative_error });
            }
            let mut g = std::mem::take(&mut self.rhs);
            self.solve(&mut g);
            self.apply(&g);
            self.rhs = g;
            iteration += 1;
        }
        self.iterations = iteration;
        Ok(())
    }

    /// Sizes the scratch for `system`, takes the mobilities Wᵢ (0 on fixed
    /// points and held coordinates) and the starting points from `at`, and
    /// zeroes the multipliers' sum.
    pub(super) fn begin(&mut self, system: &ChainSystem, at: impl Fn(usize) -> DVec3) {
        let n = system.points();
        let segments = n - 1;
        self.weight.clear();
        self.weight.extend((0..n).map(|i| {
            let w = if system.drag[i].is_finite() { 1.0 / system.drag[i] } else { 0.0 };
            DVec3::from_array(std::array::from_fn(|a| if system.held[i][a] { 0.0 } else { w }))
        }));
        self.moved.clear();
        self.moved.extend((0..n).map(&at));
        self.g.clear();
        self.g.resize(segments, 0.0);
        for v in [&mut self.diagonal, &mut self.off, &mut self.rhs] {
            v.resize(segments, 0.0);
        }
        self.direction.resize(segments, DVec3::ZERO);
        self.movable.resize(segments, false);
        self.both.clear();
        self.both.extend(self.weight.windows(2).map(|w| w[0] + w[1]));
        self.inverse_length.clear();
        self.inverse_length.extend(system.length[..segments].iter().map(|l| 1.0 / l));
    }

    /// At the current `moved`: each segment's direction u_k, its error
    /// e_k = |r_k| − ℓ_k into `rhs` (0 where its ends cannot move along
    /// it) and G's rows. Returns the worst segment and its |e_k|/ℓ_k.
    pub(super) fn linearise(&mut self, system: &ChainSystem, images: &Images) -> (usize, f64) {
        let segments = self.direction.len();
        // The chain's arrays, sliced to their lengths once so the loop
        // below indexes them without bounds checks.
        let (weight, moved, target) = (&self.weight[..segments + 1], &self.moved[..segments + 1], &system.length[..segments]);
        let (both, inverse_length) = (&self.both[..segments], &self.inverse_length[..segments]);
        let (direction, diagonal, off, rhs, movable) = (
            &mut self.direction[..segments],
            &mut self.diagonal[..segments],
            &mut self.off[..segments],
            &mut self.rhs[..segments],
            &mut self.movable[..segments],
        );
        let mut worst = (0, 0.0);
        // Segment k's direction, error and row of G, and G's entry
        // coupling it to segment k − 1.
        for k in 0..segments {
            let r = images.minimum_image(moved[k + 1] - moved[k]);
            let length = r.length();
            let u = r * (1.0 / length);
            direction[k] = u;
            let mobility = u.dot(both[k] * u);
            movable[k] = mobility > 0.0;
            let error = length - target[k];
            let relative = if movable[k] { (error * inverse_length[k]).abs() } else { 0.0 };
            if relative > worst.1 || relative.is_nan() {
                worst = (k, relative);
            }
            rhs[k] = if movable[k] { error } else { 0.0 };
            diagonal[k] = if movable[k] { mobility } else { 1.0 };
            if k > 0 {
                off[k - 1] = if movable[k - 1] && movable[k] { -direction[k - 1].dot(weight[k] * u) } else { 0.0 };
            }
        }
        worst
    }

    /// The errors of the last [`Reshape::linearise`], by segment.
    pub(super) fn errors(&self) -> &[f64] {
        &self.rhs
    }

    /// Factorises G = J·W·Jᵀ of the last [`Reshape::linearise`]; false on a singular pivot.
    pub(super) fn factor(&mut self) -> bool {
        thomas_factor(&mut self.diagonal, &self.off)
    }

    /// v ← G⁻¹·v with the factor of [`Reshape::factor`].
    pub(super) fn solve(&self, v: &mut [f64]) {
        thomas_solve(&self.diagonal, &self.off, v);
    }

    /// out_k = u_k·(δ_{k+1} − δ_k), J·δ for the chain's displacements δ
    /// (0 on segments whose ends cannot move along them).
    pub(super) fn segment_changes(&self, delta: impl Fn(usize) -> DVec3, out: &mut [f64]) {
        for (k, out) in out.iter_mut().enumerate() {
            *out = if self.movable[k] { self.direction[k].dot(delta(k + 1) - delta(k)) } else { 0.0 };
        }
    }

    /// Wᵢ·(g_i·u_i − g_{i−1}·u_{i−1}) of point i, the displacement −W·Jᵀg of multipliers g.
    pub(super) fn displacement(&self, g: &[f64], i: usize) -> DVec3 {
        displacement(&self.weight, &self.direction, g, i)
    }

    /// The mobility Wᵢ of point i (per coordinate).
    pub(super) fn weight(&self, i: usize) -> DVec3 {
        self.weight[i]
    }

    /// Moves the points by Δᵢ = Wᵢ·(g_i·u_i − g_{i−1}·u_{i−1}) and adds g to the multipliers' sum.
    pub(super) fn apply(&mut self, g: &[f64]) {
        for (i, x) in self.moved.iter_mut().enumerate() {
            *x += displacement(&self.weight, &self.direction, g, i);
        }
        self.g.iter_mut().zip(g).for_each(|(s, d)| *s += d);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::system::SimBox;

    #[test]
    fn thomas_solves_a_symmetric_tridiagonal_system() {
        let off = [0.7, 0.2, -1.0];
        let diagonal = [4.0, 3.0, 5.0, 2.0];
        let x = [1.0, -2.0, 0.5, 3.0];
        let mut rhs: Vec<f64> = (0..4)
            .map(|k| diagonal[k] * x[k] + if k > 0 { off[k - 1] * x[k - 1] } else { 0.0 } + if k < 3 { off[k] * x[k + 1] } else { 0.0 })
            .collect();
        let mut d = diagonal;
        assert!(thomas_factor(&mut d, &off));
        thomas_solve(&d, &off, &mut rhs);
        for (a, b) in rhs.iter().zip(x) {
            assert!((a - b).abs() < 1e-14);
        }
    }

    /// A perturbed chain is restored to its lengths to round-off, fixed
    /// points stay, and the centre of mobility does not move.
    #[test]
    fn a_perturbed_chain_is_restored_exactly() {
        let n = 12;
        let mut system = ChainSystem::new(n, true);
        let before: Vec<DVec3> = (0..n).map(|i| DVec3::new(0.1 * i as f64, 0.02 * (i as f64).sin(), 0.0)).collect();
        for k in 0..n - 1 {
            system.segment[k] = before[k + 1] - before[k];
            system.length[k] = system.segment[k].length();
        }
        system.drag.fill(2.0);
        system.drag[0] = f64::INFINITY;
        let after: Vec<DVec3> =
            before.iter().enumerate().map(|(i, x)| *x + 0.004 * DVec3::new((i as f64 * 1.3).cos(), (i as f64).sin(), 0.5)).collect();
        let after = {
            let mut a = after;
            a[0] = before[0];
            a
        };
        let images = SimBox::new(DVec3::splat(-10.0), DVec3::splat(10.0), [false; 3]).images();
        let mut reshape = Reshape::default();
        reshape.restore(&system, |i| after[i], &images, 1e-13, 20).unwrap();
        assert!(reshape.iterations <= 4, "{} iterations", reshape.iterations);
        for k in 0..n - 1 {
            let r = (reshape.moved[k + 1] - reshape.moved[k]).length();
            assert!((r / system.length[k] - 1.0).abs() < 1e-13);
        }
        assert_eq!(reshape.moved[0], before[0]);
        // Without the fixed point the corrections are internal forces: Σ γᵢΔᵢ = 0.
        system.drag[0] = 2.0;
        system.drag[5] = 0.5;
        reshape.restore(&system, |i| after[i], &images, 1e-13, 20).unwrap();
        let momentum: DVec3 = (0..n).map(|i| system.drag[i] * (reshape.moved[i] - after[i])).sum();
        assert!(momentum.length() < 1e-15, "Σ γΔ = {momentum}");
    }

    /// A bent 200-segment fibre after a thermal step (every point displaced
    /// by 8 % of a segment): the Gauss–Newton projection converges in a few
    /// iterations where corrections along the old directions diverged.
    #[test]
    fn a_long_bent_fibre_after_a_large_step_is_restored_in_a_few_iterations() {
        let n = 201;
        let mut system = ChainSystem::new(n, true);
        let mut before = vec![DVec3::ZERO];
        let mut t = DVec3::X;
        for i in 1..n {
            let kick = DVec3::new(0.0, (i as f64 * 2.1).sin(), (i as f64 * 3.7).cos()) * 0.12;
            t = (t + kick).normalize();
            before.push(before[i - 1] + 0.1 * t);
        }
        for k in 0..n - 1 {
            system.segment[k] = before[k + 1] - before[k];
            system.length[k] = 0.1;
        }
        system.drag.fill(0.137);
        let after: Vec<DVec3> = before
            .iter()
            .enumerate()
            .map(|(i, x)| *x + 0.008 * DVec3::new((i as f64 * 7.3).sin(), (i as f64 * 5.1).cos(), (i as f64 * 1.9).sin()))
            .collect();
        let images = SimBox::new(DVec3::splat(-100.0), DVec3::splat(100.0), [false; 3]).images();
        let mut reshape = Reshape::default();
        reshape.restore(&system, |i| after[i], &images, 1e-12, 8).unwrap();
        assert!(reshape.iterations <= 5, "{} iterations", reshape.iterations);
        let worst = (0..n - 1).map(|k| ((reshape.moved[k + 1] - reshape.moved[k]).length() / 0.1 - 1.0).abs()).fold(0.0, f64::max);
        assert!(worst < 1e-12, "{worst:e}");
    }
}

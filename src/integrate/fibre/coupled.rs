//! Restoring the lengths of fibres joined by constrained crosslinks (or
//! other constraints that are not chains) after a step: one projection for
//! the whole constraint graph.
//!
//! The constraints split into the fibres' segments (rows J_f, their
//! G_ff = J_f·W·J_fᵀ tridiagonal per fibre, [`super::reshape`]) and the
//! couplings C (a constrained crosslink between two fibres, a branch's
//! first segment, any constraint outside a chain). Each Newton iteration
//! moves the points by δ = −W·(J_fᵀg_f + Cᵀg_c) with J·W·Jᵀ·g = e, e the
//! errors |r| − ℓ at the current iterate (a Gauss–Newton step towards the
//! constraint surface in the mobility metric W, as for one fibre). The
//! fibre rows are eliminated exactly, fibre by fibre, which leaves on the
//! couplings the Schur complement (Golub & Van Loan, *Matrix Computations*,
//! §4.2; the constraint form of Cytosim's projection, Nédélec & Foethke 2007)
//!
//! S·g_c = e_c + C·δ₀,   S = C·(W − W·J_fᵀ·G_ff⁻¹·J_f·W)·Cᵀ,
//!
//! δ₀ = −W·J_fᵀ·G_ff⁻¹·e_f the fibres' own correction. S is symmetric
//! positive definite (the projected mobility between independent
//! couplings) and applied matrix-free, each product one tridiagonal solve
//! per fibre, so it is solved by conjugate gradients (Jacobi-preconditioned
//! by C·W·Cᵀ's diagonal); then g_f = G_ff⁻¹·(e_f − J_f·W·Cᵀ·g_c). Points
//! off fibres move with their mobility 1/γ. Every sum runs in a fixed
//! order, so the result is the same on any thread count. The corrections
//! are what forces g·u/dt along each constraint give in one step, so Σg/dt
//! adds to each constraint's tension, as for SHAKE and a single fibre.

use glam::DVec3;

use super::Fibres;
use crate::system::Images;

/// A constraint outside the fibres: its constraint-list entry, its ends
/// (particles) and its length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coupling {
    pub entry: usize,
    pub ends: [u32; 2],
    pub length: f64,
}

/// Relative residual at which the conjugate gradients on the couplings stop.
const CG_TOLERANCE: f64 = 1e-12;
/// Relative residual a solve that reached its iteration cap short of
/// [`CG_TOLERANCE`] may still have to be taken as a Newton step (the
/// lengths it gives are checked against the constraints' tolerance).
const CG_ACCEPTED_AT_CAP: f64 = 1e-9;

/// (C·δ)_k = u_k·(δ_j − δ_i) of coupling k.
fn change(delta: &[DVec3], direction: &[DVec3], couplings: &[Coupling], k: usize) -> f64 {
    let [i, j] = couplings[k].ends;
    direction[k].dot(delta[j as usize] - delta[i as usize])
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

impl Fibres {
    /// Restores the lengths of every inextensible fibre and every coupling
    /// in `positions` (after the step), `mobility` the per-coordinate
    /// mobility of a particle on no fibre; adds each constraint's tension
    /// Σg/dt (and a segment's multiplier λ of the step) to `tension` (by
    /// constraint-list entry). Returns the Newton
    /// iterations taken, or the constraint-list entry of the worst
    /// constraint with its |r − ℓ|/ℓ when the tolerance is not reached.
    #[allow(clippy::too_many_arguments)]
    pub fn reshape_coupled(
        &mut self,
        positions: &mut [DVec3],
        images: &Images,
        dt: f64,
        tolerance: f64,
        max_iterations: usize,
        couplings: &[Coupling],
        mobility: &dyn Fn(usize) -> DVec3,
        tension: &mut [f64],
    ) -> Result<usize, (usize, f64)> {
        let constrained: Vec<usize> = (0..self.chains.chains.len()).filter(|&c| self.chains.chains[c].is_constrained()).collect();
        for &c in &constrained {
            let (work, chain) = (&mut self.work[c], &self.chains.chains[c]);
            work.reshape.begin(&work.system, |m| positions[chain.points[m] as usize]);
        }
        let m = couplings.len();
        let mut coupling_sum = vec![0.0; m];
        let mut direction = vec![DVec3::ZERO; m];
        let mut iteration = 0;
        loop {
            // Directions and errors at the current iterate, and the worst constraint.
            let mut worst = (usize::MAX, 0.0);
            for &c in &constrained {
                let work = &mut self.work[c];
                let (segment, relative) = work.reshape.linearise(&work.system, images);
                if relative > worst.1 || relative.is_nan() {
                    worst = (self.chains.chains[c].constraints[segment] as usize, relative);
                }
            }
            let mut errors = vec![0.0; m];
            for (k, coupling) in couplings.iter().enumerate() {
                let r = images.minimum_image(self.position(positions, coupling.ends[1]) - self.position(positions, coupling.ends[0]));
                let length = r.length();
                direction[k] = r * (1.0 / length);
                errors[k] = length - coupling.length;
                let relative = (errors[k] / coupling.length).abs();
                if relative > worst.1 || relative.is_nan() {
                    worst = (coupling.entry, relative);
                }
            }
            if worst.1 <= tolerance {
                break;
            }
            if iteration == max_iterations || !constrained.iter().all(|&c| self.work[c].reshape.factor()) {
                return Err(worst);
            }
            // The fibres' own correction δ₀ and the couplings' right-hand side e_c + C·δ₀.
            let own: Vec<Vec<f64>> = constrained
                .iter()
                .map(|&c| {
                    let mut g = self.work[c].reshape.errors().to_vec();
                    self.work[c].reshape.solve(&mut g);
                    g
                })
                .collect();
            let mut delta = vec![DVec3::ZERO; positions.len()];
            for (&c, g) in constrained.iter().zip(&own) {
                let (work, chain) = (&self.work[c], &self.chains.chains[c]);
                for (i, &p) in chain.points.iter().enumerate() {
                    delta[p as usize] = work.reshape.displacement(g, i);
                }
            }
            let rhs: Vec<f64> = (0..m).map(|k| errors[k] + change(&delta, &direction, couplings, k)).collect();
            let gc = self.solve_couplings(&rhs, &direction, couplings, mobility, positions.len()).ok_or(worst)?;
            // g_f = G_ff⁻¹·(e_f − J_f·W·Cᵀ·g_c), then δ = −W·(J_fᵀg_f + Cᵀg_c).
            let pushed = self.mobile_push(&gc, &direction, couplings, mobility, positions.len());
            for &c in &constrained {
                let (work, chain) = (&mut self.work[c], &self.chains.chains[c]);
                let mut h = vec![0.0; chain.segments()];
                work.reshape.segment_changes(|i| pushed[chain.points[i] as usize], &mut h);
                let mut g: Vec<f64> = work.reshape.errors().iter().zip(&h).map(|(e, h)| e - h).collect();
                work.reshape.solve(&mut g);
                work.reshape.apply(&g);
            }
            for (p, x) in positions.iter_mut().enumerate() {
                if !self.holds(p) {
                    *x -= pushed[p];
                }
            }
            for &c in &constrained {
                let (work, chain) = (&mut self.work[c], &self.chains.chains[c]);
                for (i, &p) in chain.points.iter().enumerate() {
                    work.reshape.moved[i] -= pushed[p as usize];
                }
            }
            coupling_sum.iter_mut().zip(&gc).for_each(|(s, g)| *s += g);
            iteration += 1;
        }
        self.write_back(positions, dt, tension);
        for (coupling, g) in couplings.iter().zip(&coupling_sum) {
            tension[coupling.entry] += g / dt;
        }
        Ok(iteration)
    }

    /// Where particle `p` is in this reshape: its fibre's iterate, or `positions`.
    fn position(&self, positions: &[DVec3], p: u32) -> DVec3 {
        match self.chains.place[p as usize] {
            Some((c, m)) if self.chains.chains[c as usize].is_constrained() => self.work[c as usize].reshape.moved[m as usize],
            _ => positions[p as usize],
        }
    }

    /// The mobility of particle `p` per coordinate (its fibre's, or `mobility`).
    fn weight(&self, p: usize, mobility: &dyn Fn(usize) -> DVec3) -> DVec3 {
        match self.chains.place[p] {
            Some((c, m)) if self.chains.chains[c as usize].is_constrained() => self.work[c as usize].reshape.weight(m as usize),
            _ => mobility(p),
        }
    }

    /// W·Cᵀ·g: each coupling's multiplier along its direction, times the mobility of its ends.
    fn mobile_push(
        &self,
        g: &[f64],
        direction: &[DVec3],
        couplings: &[Coupling],
        mobility: &dyn Fn(usize) -> DVec3,
        n: usize,
    ) -> Vec<DVec3> {
        let mut f = vec![DVec3::ZERO; n];
        for (k, coupling) in couplings.iter().enumerate() {
            let [i, j] = coupling.ends;
            f[i as usize] -= g[k] * direction[k];
            f[j as usize] += g[k] * direction[k];
        }
        for (p, f) in f.iter_mut().enumerate() {
            if *f != DVec3::ZERO {
                *f *= self.weight(p, mobility);
            }
        }
        f
    }

    /// S·v = C·(W − W·J_fᵀ·G_ff⁻¹·J_f·W)·Cᵀ·v.
    fn schur_times(&self, v: &[f64], direction: &[DVec3], couplings: &[Coupling], mobility: &dyn Fn(usize) -> DVec3, n: usize) -> Vec<f64> {
        let mut delta = self.mobile_push(v, direction, couplings, mobility, n);
        let touched = couplings.iter().flat_map(|c| c.ends).filter_map(|p| self.chains.place[p as usize]).map(|(c, _)| c as usize);
        let mut fibres: Vec<usize> = touched.filter(|&c| self.chains.chains[c].is_constrained()).collect();
        fibres.sort_unstable();
        fibres.dedup();
        for c in fibres {
            let (work, chain) = (&self.work[c], &self.chains.chains[c]);
            let mut z = vec![0.0; chain.segments()];
            work.reshape.segment_changes(|i| delta[chain.points[i] as usize], &mut z);
            work.reshape.solve(&mut z);
            let correction: Vec<DVec3> = (0..chain.points.len()).map(|i| work.reshape.displacement(&z, i)).collect();
            for (&p, d) in chain.points.iter().zip(correction) {
                delta[p as usize] += d;
            }
        }
        (0..couplings.len()).map(|k| change(&delta, direction, couplings, k)).collect()
    }

    /// g_c of S·g_c = rhs by Jacobi-preconditioned conjugate gradients
    /// (`None` if S is not positive definite along the iteration: dependent couplings).
    fn solve_couplings(
        &self,
        rhs: &[f64],
        direction: &[DVec3],
        couplings: &[Coupling],
        mobility: &dyn Fn(usize) -> DVec3,
        n: usize,
    ) -> Option<Vec<f64>> {
        let m = rhs.len();
        let diagonal: Vec<f64> = (0..m)
            .map(|k| {
                let [i, j] = couplings[k].ends;
                let u = direction[k];
                let d = u.dot((self.weight(i as usize, mobility) + self.weight(j as usize, mobility)) * u);
                if d > 0.0 {
                    1.0 / d
                } else {
                    0.0
                }
            })
            .collect();
        let mut x = vec![0.0; m];
        let mut r = rhs.to_vec();
        let reference = dot(rhs, rhs).sqrt();
        if reference == 0.0 {
            return Some(x);
        }
        let mut z: Vec<f64> = r.iter().zip(&diagonal).map(|(r, d)| r * d).collect();
        let mut p = z.clone();
        let mut rz = dot(&r, &z);
        for _ in 0..10 * m + 50 {
            if dot(&r, &r).sqrt() <= CG_TOLERANCE * reference {
                return Some(x);
            }
            let sp = self.schur_times(&p, direction, couplings, mobility, n);
            let curvature = dot(&p, &sp);
            if !(curvature > 0.0) {
                return None;
            }
            let alpha = rz / curvature;
            x.iter_mut().zip(&p).for_each(|(x, p)| *x += alpha * p);
            r.iter_mut().zip(&sp).for_each(|(r, s)| *r -= alpha * s);
            z = r.iter().zip(&diagonal).map(|(r, d)| r * d).collect();
            let rz_next = dot(&r, &z);
            let beta = rz_next / rz;
            p.iter_mut().zip(&z).for_each(|(p, z)| *p = z + beta * *p);
            rz = rz_next;
        }
        (dot(&r, &r).sqrt() <= CG_ACCEPTED_AT_CAP * reference).then_some(x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::fibre::test_model;
    use crate::system::SimBox;

    /// Two 20-segment fibres joined by three constrained crosslinks of
    /// length 1.5, every point displaced as by a large thermal step: the
    /// coupled projection restores every segment and crosslink to 1e-12
    /// in a few iterations, and as internal corrections it keeps Σγᵢδᵢ = 0.
    #[test]
    fn crosslinked_fibres_are_restored_together() {
        let n = 20;
        let mut top = String::from("[ particles ]\n");
        let mut bonds = String::from("[ bonds ]\n");
        for c in 0..2 {
            for s in 0..=n {
                let id = c * (n + 1) + s + 1;
                top += &format!("{id} bead {s} {} 0\n", 1.5 * c as f64);
                if s > 0 {
                    bonds += &format!("rod {} {id}\n", id - 1);
                }
            }
        }
        for s in [3, 10, 17] {
            bonds += &format!("xl {} {}\n", s + 1, n + 1 + s + 1);
        }
        let model = test_model(&(top + &bonds), "particle bead drag 2\nbond rod harmonic k 1 r0 1\nbond xl harmonic k 1 r0 1.5\n");
        let rods: Vec<usize> = (0..model.bonds.len()).filter(|&b| model.bond_type[b] == 0).collect();
        let xls: Vec<usize> = (0..model.bonds.len()).filter(|&b| model.bond_type[b] == 1).collect();
        let list: Vec<usize> = rods.iter().chain(&xls).copied().collect();
        let mut fibres = Fibres::default();
        fibres.prepare(&model, list.iter().copied(), true, false);
        assert_eq!(fibres.chains.chains.len(), 2, "the rods are two fibres");
        let lengths: Vec<f64> = list.iter().map(|&b| if model.bond_type[b] == 0 { 1.0 } else { 1.5 }).collect();
        let x0: Vec<DVec3> = (0..model.len()).map(|p| DVec3::new((p % (n + 1)) as f64, 1.5 * (p / (n + 1)) as f64, 0.0)).collect();
        let images = SimBox::new(DVec3::splat(-100.0), DVec3::splat(100.0), [false; 3]).images();
        let length = |k: usize| lengths[k];
        let inputs = super::super::FibreInputs {
            model: &model,
            positions: &x0,
            images: &images,
            constraint_length: &length,
            held: &[],
            bond_block: None,
        };
        fibres.load(&inputs);
        let after: Vec<DVec3> = x0
            .iter()
            .enumerate()
            .map(|(i, x)| *x + 0.05 * DVec3::new((i as f64 * 7.3).sin(), (i as f64 * 5.1).cos(), (i as f64 * 1.9).sin()))
            .collect();
        let couplings: Vec<Coupling> =
            (rods.len()..list.len()).map(|k| Coupling { entry: k, ends: model.bonds[list[k]], length: lengths[k] }).collect();
        let mut moved = after.clone();
        let mut tension = vec![0.0; list.len()];
        let iterations =
            fibres.reshape_coupled(&mut moved, &images, 1.0, 1e-12, 20, &couplings, &|_| DVec3::splat(0.5), &mut tension).unwrap();
        assert!(iterations <= 6, "{iterations} iterations");
        for (k, &b) in list.iter().enumerate() {
            let [i, j] = model.bonds[b];
            let r = (moved[j as usize] - moved[i as usize]).length();
            assert!((r / lengths[k] - 1.0).abs() < 1e-12, "constraint {k}: {r} vs {}", lengths[k]);
        }
        let momentum: DVec3 = moved.iter().zip(&after).map(|(m, a)| 2.0 * (*m - *a)).sum();
        assert!(momentum.length() < 1e-13, "Σ γδ = {momentum}");
        assert!(tension.iter().all(|t| t.is_finite()) && tension[rods.len()..].iter().any(|t| *t != 0.0));
    }
}

//! One fibre's linear system, solved exactly in O(n).
//!
//! For a chain of points x₀ … x_n with drags γᵢ, the linearly implicit step
//! with the fibre's own stiffness K and, for an inextensible fibre, its
//! segment constraints linearised at the current positions is the
//! saddle-point (KKT) system
//!
//! ```text
//! [ γ/dt + θK   Jᵀ ] [Δx]   [ F + √(2kTγ/dt)·ξ ]
//! [ J           0  ] [ λ ] = [ ℓ − |r|          ]
//! ```
//!
//! where row k of J is û_k·(Δx_{k+1} − Δx_k) (û_k the unit segment vector),
//! so that the step restores each length ℓ_k to first order, and λ_k is the
//! tension of segment k (positive when it pulls its ends together; the
//! constraint force on point k is +λ_k·û_k). K holds:
//!
//! - **bending** of each joint m with a fibre-bending law E = s·(1 − t₁·t₂):
//!   Cytosim's isotropic matrix (Nédélec & Foethke 2007), the Hessian of
//!   s/(2ℓ_{m−1}ℓ_m)·|x_{m−1} − 2x_m + x_{m+1}|², which equals E on the
//!   constraint manifold (|t₂ − t₁|² = |x_{m−1} − 2x_m + x_{m+1}|²/ℓ² there);
//!   it is positive semi-definite and the same on every axis;
//! - **stretching** of an elastic (unconstrained) chain's segments: each
//!   bond's projected radial block max(E″, 0)·ûûᵀ + max(E′/r, 0)·(I − ûûᵀ),
//!   as in the generic stiffness.
//!
//! An elastic chain's bending is exact in the generic stiffness of the
//! implicit step, so its product ([`ChainSystem::times`]) leaves bending
//! out and only its factor, the preconditioner, has the isotropic matrix.
//!
//! θ weighs the stiffness (1: backward Euler, as Cytosim; ½: the
//! trapezoidal rule, whose stationary variance of a linear mode k is kT/k
//! exactly at any dt). Unknowns are interleaved point by point,
//! (x, y, z, λ)₀ (x, y, z, λ)₁ …, so the matrix is banded with half-width 8
//! (bending couples points two apart) and [`Banded`]'s LDLᵀ solves it
//! without pivoting. A `fixed` point or a held coordinate has the identity
//! row (Δ = 0) and no coupling; a segment whose ends cannot move along it
//! has the identity multiplier row (λ = 0).

use glam::{DMat3, DVec3};

use super::banded::Banded;

/// Index of coordinate `a` of point `i`, and of the multiplier of segment
/// `k`, which follows both its points (slot 3 of point 0 is unused).
#[inline(always)]
fn var(i: usize, a: usize) -> usize {
    4 * i + a
}
#[inline(always)]
fn multiplier(k: usize) -> usize {
    4 * k + 7
}
/// The unused slot.
const DUMMY: usize = 3;

/// Whether coordinate `a` of point `i` moves (not fixed, not held).
fn mobile(drag: &[f64], held: &[[bool; 3]], i: usize, a: usize) -> bool {
    drag[i].is_finite() && !held[i][a]
}

/// Which of a system's banded matrices.
#[derive(Clone, Copy)]
enum Which {
    Matrix,
    Factor,
}

/// Adds θ·s_j/(ℓ_{j−1}ℓ_j)·D2ᵀD2 of every joint j to `m` (each axis alike).
#[allow(clippy::needless_range_loop)] // the stencil's indices are the points'
fn add_bending(m: &mut Banded, strength: &[f64], length: &[f64], theta: f64) {
    let n = strength.len();
    const STENCIL: [f64; 3] = [1.0, -2.0, 1.0];
    for j in 1..n.saturating_sub(1) {
        if strength[j] == 0.0 {
            continue;
        }
        let w = theta * strength[j] / (length[j - 1] * length[j]);
        for p in 0..3 {
            for q in p..3 {
                let value = w * STENCIL[p] * STENCIL[q];
                for a in 0..3 {
                    m.add(var(j - 1 + p, a), var(j - 1 + q, a), value);
                }
            }
        }
    }
}

/// A fibre's system and its scratch, sized once for its number of points.
#[derive(Clone, Debug, PartialEq)]
pub struct ChainSystem {
    /// Segment vectors r_k = x_{k+1} − x_k at the positions the system was assembled at.
    pub segment: Vec<DVec3>,
    /// Length ℓ_k each segment is held at (constrained) or its current length (elastic).
    pub length: Vec<f64>,
    /// Drag of each point (infinite: fixed).
    pub drag: Vec<f64>,
    /// Held coordinates of each point (protocols).
    pub held: Vec<[bool; 3]>,
    /// Bending strength s at each point (0 at the ends and where no joint law acts).
    pub strength: Vec<f64>,
    /// Radial stiffness block of each segment (elastic chains).
    pub bond_block: Vec<DMat3>,
    constrained: bool,
    /// Whether each segment's multiplier row is a constraint (else λ = 0).
    active: Vec<bool>,
    /// The operator γ/dt + θK, built from the data fields on the first
    /// [`ChainSystem::times`] after an assembly (the explicit step never needs it).
    matrix: Banded,
    matrix_current: bool,
    /// (dt, θ) of the last assembly.
    step: (f64, f64),
    factor: Banded,
    work: Vec<f64>,
    product: Vec<f64>,
}

impl ChainSystem {
    /// The system of a chain of `points` points, inextensible or elastic.
    pub fn new(points: usize, constrained: bool) -> Self {
        let segments = points - 1;
        let order = 4 * points;
        Self {
            segment: vec![DVec3::ZERO; segments],
            length: vec![0.0; segments],
            drag: vec![0.0; points],
            held: vec![[false; 3]; points],
            strength: vec![0.0; points],
            bond_block: if constrained { Vec::new() } else { vec![DMat3::ZERO; segments] },
            constrained,
            active: vec![false; segments],
            matrix: Banded::zeros(order),
            matrix_current: false,
            step: (0.0, 0.0),
            factor: Banded::zeros(order),
            work: vec![0.0; order],
            product: vec![0.0; order],
        }
    }

    pub fn points(&self) -> usize {
        self.drag.len()
    }

    fn mobile(&self, i: usize, a: usize) -> bool {
        mobile(&self.drag, &self.held, i, a)
    }

    /// Identity rows for the coordinates that do not move, and the unused slot.
    fn isolate_fixed(&mut self, which: Which) {
        let m = match which {
            Which::Matrix => &mut self.matrix,
            Which::Factor => &mut self.factor,
        };
        for i in 0..self.drag.len() {
            for a in 0..3 {
                if !mobile(&self.drag, &self.held, i, a) {
                    m.isolate(var(i, a));
                }
            }
        }
        m.isolate(DUMMY);
    }

    /// Assembles and factorises γ/dt + θK with the constraint rows from the
    /// data fields. Fails naming the row of a singular pivot.
    pub fn assemble(&mut self, dt: f64, theta: f64) -> Result<(), usize> {
        self.step = (dt, theta);
        self.matrix_current = false;
        self.fill(Which::Factor);
        if !self.constrained {
            // An elastic chain's operator keeps the bending's exact Hessian
            // (in the generic stiffness); its factor, the preconditioner, the isotropic one.
            add_bending(&mut self.factor, &self.strength, &self.length, theta);
            self.isolate_fixed(Which::Factor);
        }
        self.factor.factorize()
    }

    /// Writes γ/dt + θK (without an elastic chain's bending) with the
    /// constraint rows into `which`, at the last assembly's (dt, θ).
    fn fill(&mut self, which: Which) {
        let n = self.points();
        let (dt, theta) = self.step;
        let m = match which {
            Which::Matrix => &mut self.matrix,
            Which::Factor => &mut self.factor,
        };
        m.clear();
        for i in 0..n {
            let diagonal = self.drag[i] / dt;
            for a in 0..3 {
                m.add(var(i, a), var(i, a), diagonal);
            }
        }
        for (k, h) in self.bond_block.iter().enumerate() {
            let h = theta * *h;
            for a in 0..3 {
                for c in 0..3 {
                    if c <= a {
                        m.add(var(k, a), var(k, c), h.col(c)[a]);
                        m.add(var(k + 1, a), var(k + 1, c), h.col(c)[a]);
                    }
                    m.add(var(k, a), var(k + 1, c), -h.col(c)[a]);
                }
            }
        }
        if self.constrained {
            add_bending(m, &self.strength, &self.length, theta);
        }
        for k in 0..n - 1 {
            let u = self.segment[k].normalize_or_zero();
            let mut norm = 0.0;
            if self.constrained {
                for a in 0..3 {
                    for (point, sign) in [(k, -1.0), (k + 1, 1.0)] {
                        if mobile(&self.drag, &self.held, point, a) {
                            m.add(multiplier(k), var(point, a), sign * u[a]);
                            norm += u[a] * u[a];
                        }
                    }
                }
            }
            self.active[k] = norm >= 1e-12;
            if !self.active[k] {
                m.isolate(multiplier(k));
            }
        }
        self.isolate_fixed(which);
    }

    /// Solves the factorised system for right-hand sides `force` (per point)
    /// and, for the constraint rows, `lengths` (ℓ − |r|, or zero with `None`):
    /// the displacement of each point into `step` and each multiplier into
    /// `tension`.
    pub fn solve(&mut self, force: impl Fn(usize) -> DVec3, lengths: Option<&[f64]>, step: &mut [DVec3], tension: &mut [f64]) {
        let n = self.points();
        for i in 0..n {
            let f = force(i);
            for a in 0..3 {
                self.work[var(i, a)] = if self.mobile(i, a) { f[a] } else { 0.0 };
            }
            if i + 1 < n {
                self.work[multiplier(i)] = match lengths {
                    Some(c) if self.active[i] => c[i],
                    _ => 0.0,
                };
            }
        }
        self.work[DUMMY] = 0.0;
        self.factor.solve_in_place(&mut self.work);
        for i in 0..n {
            step[i] = DVec3::new(self.work[var(i, 0)], self.work[var(i, 1)], self.work[var(i, 2)]);
            if i + 1 < n {
                tension[i] = self.work[multiplier(i)];
            }
        }
    }

    /// (Jᵀλ)ᵢ, the constraint force of multipliers `tension` on point `i`
    /// (zero on coordinates that do not move), at the assembled directions.
    pub fn constraint_force(&self, i: usize, tension: &[f64]) -> DVec3 {
        let mut f = DVec3::ZERO;
        if i > 0 && self.active[i - 1] {
            f += tension[i - 1] * self.segment[i - 1].normalize_or_zero();
        }
        if i + 1 < self.points() && self.active[i] {
            f -= tension[i] * self.segment[i].normalize_or_zero();
        }
        DVec3::from_array(std::array::from_fn(|a| if self.mobile(i, a) { f[a] } else { 0.0 }))
    }

    /// y = (γ/dt + θK)·v on the chain's points (the constraint rows left out).
    pub fn times(&mut self, v: impl Fn(usize) -> DVec3, y: &mut [DVec3]) {
        let n = self.points();
        for i in 0..n {
            let vi = v(i);
            for a in 0..3 {
                self.work[var(i, a)] = vi[a];
            }
            if i + 1 < n {
                self.work[multiplier(i)] = 0.0;
            }
        }
        self.work[DUMMY] = 0.0;
        if !self.matrix_current {
            self.fill(Which::Matrix);
            self.matrix_current = true;
        }
        self.matrix.times(&self.work, &mut self.product);
        for (i, yi) in y.iter_mut().enumerate().take(n) {
            *yi = DVec3::new(self.product[var(i, 0)], self.product[var(i, 1)], self.product[var(i, 2)]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A bent chain of 9 points with a fixed first point and a held coordinate.
    fn system(constrained: bool, n: usize) -> ChainSystem {
        let mut s = ChainSystem::new(n, constrained);
        let x: Vec<DVec3> = (0..n).map(|i| DVec3::new(0.1 * i as f64, 0.03 * (i as f64 * 0.3).sin(), 0.003 * (i as f64).sin())).collect();
        for k in 0..n - 1 {
            s.segment[k] = x[k + 1] - x[k];
            s.length[k] = s.segment[k].length() * 1.01;
            if !constrained {
                let u = s.segment[k].normalize();
                s.bond_block[k] = 50.0 * DMat3::from_cols(u * u.x, u * u.y, u * u.z) + 0.3 * DMat3::IDENTITY;
            }
        }
        for i in 0..n {
            s.drag[i] = 1.0 + 0.2 * i as f64;
            s.strength[i] = if i > 0 && i + 1 < n { 0.5 + 0.1 * i as f64 } else { 0.0 };
        }
        s.drag[0] = f64::INFINITY;
        s.held[4][1] = true;
        s
    }

    /// The energy whose gradient the system's matrix is: Σ γ/(2dt)|Δ|² + θ Σ s/(2ℓℓ')|Δ_{m−1} − 2Δ_m + Δ_{m+1}|²
    /// (+ ½ Σ (Δ_{k+1} − Δ_k)ᵀ h_k (Δ_{k+1} − Δ_k) for elastic segments), on the free coordinates.
    fn quadratic(s: &ChainSystem, dt: f64, theta: f64, d: &[DVec3], bending: bool) -> f64 {
        let n = s.points();
        let mut e = 0.0;
        for (drag, d) in s.drag.iter().zip(d) {
            if drag.is_finite() {
                e += drag / (2.0 * dt) * d.length_squared();
            }
        }
        for j in (1..n - 1).filter(|_| bending) {
            let w = theta * s.strength[j] / (s.length[j - 1] * s.length[j]);
            e += 0.5 * w * (d[j - 1] - 2.0 * d[j] + d[j + 1]).length_squared();
        }
        for (k, h) in s.bond_block.iter().enumerate() {
            let r = d[k + 1] - d[k];
            e += 0.5 * theta * r.dot(*h * r);
        }
        e
    }

    /// The solve meets the constraint rows and makes the gradient of the
    /// quadratic model (by central differences) equal b − Jᵀλ on every free coordinate.
    #[test]
    fn the_solution_is_the_constrained_minimiser_of_the_quadratic_model() {
        for (constrained, n) in [(true, 9), (false, 9), (true, 60), (false, 60)] {
            let mut s = system(constrained, n);
            let (dt, theta) = (0.01, 0.7);
            s.assemble(dt, theta).unwrap();
            let b: Vec<DVec3> = (0..n).map(|i| DVec3::new((i as f64).cos(), 0.5 - 0.1 * i as f64, (2.0 * i as f64).sin())).collect();
            let c: Vec<f64> = (0..n - 1).map(|k| 1e-3 * (k as f64 - 3.0)).collect();
            let (mut d, mut lambda) = (vec![DVec3::ZERO; n], vec![0.0; n - 1]);
            s.solve(|i| b[i], Some(&c), &mut d, &mut lambda);
            assert_eq!(d[0], DVec3::ZERO);
            assert_eq!(d[4].y, 0.0);
            for k in 0..n - 1 {
                let u = s.segment[k].normalize();
                if constrained {
                    assert!((u.dot(d[k + 1] - d[k]) - c[k]).abs() < 1e-12, "constraint {k}");
                } else {
                    assert_eq!(lambda[k], 0.0);
                }
            }
            let h = 1e-6;
            for i in 1..n {
                for a in 0..3 {
                    if s.held[i][a] {
                        continue;
                    }
                    let (mut plus, mut minus) = (d.clone(), d.clone());
                    plus[i][a] += h;
                    minus[i][a] -= h;
                    let gradient = (quadratic(&s, dt, theta, &plus, true) - quadratic(&s, dt, theta, &minus, true)) / (2.0 * h);
                    // Jᵀλ on coordinate a of point i: −λ_i·u_i + λ_{i−1}·u_{i−1}.
                    let mut jt = 0.0;
                    if i + 1 < n {
                        jt -= lambda[i] * s.segment[i].normalize()[a];
                    }
                    jt += lambda[i - 1] * s.segment[i - 1].normalize()[a];
                    let residual = gradient + jt - b[i][a];
                    let scale = 1.0 + gradient.abs() + jt.abs();
                    assert!(residual.abs() < 1e-7 * scale, "constrained {constrained}, point {i} axis {a}: {residual:e} of {scale:e}");
                }
            }
            // The product is the model's matrix, an elastic chain's without its bending: v·(A v) = 2 E(v).
            let mut y = vec![DVec3::ZERO; n];
            let mut v = b.clone();
            v[0] = DVec3::ZERO;
            v[4].y = 0.0;
            s.times(|i| v[i], &mut y);
            let va: f64 = v.iter().zip(&y).map(|(v, y)| v.dot(*y)).sum();
            assert!((va - 2.0 * quadratic(&s, dt, theta, &v, constrained)).abs() < 1e-10 * va.abs());
        }
    }
}

//! Fibres solved fibre by fibre: inextensible filaments at Cytosim's time
//! steps (Nédélec & Foethke 2007), and the banded blocks of elastic chains.
//!
//! A fibre is a linear chain of bonds ([`chains`]). Each step, every fibre
//! gets one saddle-point system over its points and segment tensions,
//! assembled in a layout fixed when the chains were found and solved
//! exactly by a banded LDLᵀ factorisation in O(n) ([`kkt`], [`banded`]):
//!
//! (γ/dt + θK)·Δx + Jᵀλ = F + √(2kTγ/dt)·ξ,   J·Δx = ℓ − |r|,
//!
//! K the fibre's own bending (and, for an elastic chain, stretching)
//! stiffness, J the unit segment gradients. Then [`reshape`] restores the
//! lengths exactly (Newton on one multiplier per segment, a tridiagonal
//! solve per iteration).
//!
//! - **`integrator overdamped`** (the explicit step): an inextensible
//!   fibre's internal terms (its constraints and bending joints) are solved
//!   implicitly, everything else acting on its points (pairs, crosslinks,
//!   externals, the noise) explicitly: a semi-implicit step whose fibre
//!   modes are stable at any dt, so only the other terms limit the step.
//!   Other particles take the Euler–Maruyama step.
//! - **`integrator implicit`**: the same blocks are the preconditioner of
//!   the projected conjugate gradients over the whole system
//!   (`integrate::implicit`), exact for free inextensible fibres (one
//!   iteration); an elastic chain's preconditioner has Cytosim's isotropic
//!   bending matrix where its operator has the exact Hessian.
//!
//! Thermal noise under constraints: the step projects the noise onto the
//! constraints' tangent space by the same solve (the multipliers absorb its
//! components along the segments), and the reshape moves the end point
//! back onto the constraint surface. No metric (Fixman) force is added:
//! a random step followed by a projection back onto the constraints
//! generates the drift of the infinitely stiff spring limit by itself
//! (Hinch 1994), so the fibres should sample e^(−E/kT) on the flexible measure —
//! the discrete worm-like chain's independent joints — not the rigid
//! measure e^(−E/kT)·√det G. Measured (tests/suite/inextensible_fibres.rs)
//! at D·dt/ℓ² = 0.0025 (D = kT/γ; a 1 ms step of actin's 0.1 µm segments in
//! 1 Pa·s is 0.0028): a = κ/(ℓkT) = 3 chains keep the exact tangent
//! correlations within 2 standard errors at θ = ½ (lag 1: 0.6751 ± 0.0042
//! against 0.6716 in a deck run) and come out 3 standard errors straight at
//! θ = 1; freely jointed chains still show ⟨cos θ⟩ = 0.006–0.019 (± 0.006,
//! three runs) where it is 0, and ⟨cos²θ⟩ = 0.320–0.336 (± 0.003), between
//! the flexible 1/3 and the rigid 0.318 — not yet right. The step is first
//! order in dt and its error straightens chains: at D·dt/ℓ² = 0.01 freely
//! jointed chains show ⟨cos θ⟩ = 0.035 ± 0.006 and a = 3 chains
//! ⟨t_i·t_{i+1}⟩ = 0.724 ± 0.004 against 0.672 (a Python model of this step
//! on three-bead chains gives ⟨cos θ⟩ = 0.036 at 0.01 and 0.005 at 0.0025;
//! projecting back along the directions before the step, SHAKE's choice,
//! showed none within ± 0.009 there but diverges on some chains at 0.01). Adding the
//! Fixman force −∇(kT/2)·ln det G biased ⟨cos²θ⟩ by 5 standard errors at
//! 0.01. A linear mode of stiffness k relaxes by 1/(1 + a) per step at
//! θ = 1 (a = k·dt/γ), and its stationary energy is (kT/2)·2/(2 + a):
//! backward Euler damps fast modes, as Cytosim's step does; θ = ½ keeps
//! kT/2 exactly at any dt for linear modes.

pub mod banded;
pub mod chains;
pub mod coupled;
pub mod kkt;
pub mod reshape;

use glam::{DMat3, DVec3};
use rayon::prelude::*;

use self::chains::{Chain, Chains};
use self::kkt::ChainSystem;
use self::reshape::{Reshape, ReshapeFailure};
use super::context::StepContext;
use crate::rng::noise3;
use crate::system::{Images, Model};

/// One fibre's system with its per-step scratch.
#[derive(Clone, Debug, PartialEq)]
struct FibreWork {
    system: ChainSystem,
    reshape: Reshape,
    /// Displacement of each point from the last solve.
    step: Vec<DVec3>,
    /// Multiplier λ_k of each segment from the last solve.
    tension: Vec<f64>,
    /// ℓ − |r| of each segment.
    deficit: Vec<f64>,
    /// The force side of the last solve, per point.
    rhs: Vec<DVec3>,
}

impl FibreWork {
    /// The chain's data at the inputs' positions: segments, lengths,
    /// drags, held coordinates and joint strengths.
    fn load(&mut self, chain: &Chain, inputs: &FibreInputs) {
        let model = inputs.model;
        let s = &mut self.system;
        let x = |m: usize| inputs.positions[chain.points[m] as usize];
        for (m, &p) in chain.points.iter().enumerate() {
            let p = p as usize;
            s.drag[m] = model.type_drag[model.types[p] as usize];
            s.held[m] = std::array::from_fn(|a| inputs.held.get(3 * p + a).copied().unwrap_or(false));
            s.strength[m] = 0.0;
        }
        for k in 0..chain.segments() {
            let r = inputs.images.minimum_image(x(k + 1) - x(k));
            s.segment[k] = r;
            s.length[k] = if chain.is_constrained() { (inputs.constraint_length)(chain.constraints[k] as usize) } else { r.length() };
            self.deficit[k] = s.length[k] - r.length();
            if let (false, Some(block)) = (chain.is_constrained(), inputs.bond_block) {
                s.bond_block[k] = block(chain.bonds[k] as usize);
            }
        }
        for &(m, a) in &chain.joints {
            let term = &model.angle_types[model.angle_type[a as usize] as usize];
            s.strength[m as usize] += term.interaction.fibre_bending(&term.params).unwrap_or(0.0);
        }
    }

    /// Loads the chain at the inputs' positions, then assembles and
    /// factorises its system; a singular pivot names its particle.
    fn prepare(&mut self, chain: &Chain, inputs: &FibreInputs, dt: f64, theta: f64) -> Result<(), SingularFibre> {
        self.load(chain, inputs);
        self.system.assemble(dt, theta).map_err(|row| SingularFibre { particle: chain.points[(row / 4).min(chain.points.len() - 1)] })
    }

    fn new(points: usize, constrained: bool) -> Self {
        let segments = points - 1;
        Self {
            system: ChainSystem::new(points, constrained),
            reshape: Reshape::default(),
            step: vec![DVec3::ZERO; points],
            tension: vec![0.0; segments],
            deficit: vec![0.0; segments],
            rhs: vec![DVec3::ZERO; points],
        }
    }
}

/// What a fibre solve reads of the system at the step's start.
pub struct FibreInputs<'a> {
    pub model: &'a Model,
    pub positions: &'a [DVec3],
    pub images: &'a Images,
    /// Length each constraint-list entry holds its bond at.
    pub constraint_length: &'a (dyn Fn(usize) -> f64 + Sync),
    /// Held coordinates (3 per particle, or empty).
    pub held: &'a [bool],
    /// The projected radial stiffness block of a bond at the current
    /// positions (needed where elastic chains were found).
    pub bond_block: Option<&'a (dyn Fn(usize) -> DMat3 + Sync)>,
}

/// The fibres of a step and what their solve needs beyond the state.
pub struct FibreStep<'a> {
    pub fibres: &'a mut Fibres,
    pub constraint_length: &'a (dyn Fn(usize) -> f64 + Sync),
    pub held: &'a [bool],
    /// The stiffness block of a bond (for elastic chains; `None` where none were found).
    pub bond_block: Option<&'a (dyn Fn(usize) -> DMat3 + Sync)>,
    /// Weight θ of the implicit stiffness (`integrator … theta`): 1 backward Euler, ½ trapezoidal.
    pub theta: f64,
}

impl<'a> FibreStep<'a> {
    /// What the fibres read at `positions`.
    fn inputs<'b>(&self, model: &'b Model, positions: &'b [DVec3], images: &'b Images) -> FibreInputs<'b>
    where
        'a: 'b,
    {
        FibreInputs { model, positions, images, constraint_length: self.constraint_length, held: self.held, bond_block: self.bond_block }
    }

    /// Assembles every fibre's system at `positions` for a step of length `dt`.
    pub fn assemble(&mut self, model: &Model, positions: &[DVec3], images: &Images, dt: f64) -> Result<(), SingularFibre> {
        let inputs = self.inputs(model, positions, images);
        self.fibres.assemble(&inputs, dt, self.theta)
    }

    /// The displacement of every fibre point in a step of length `dt` from
    /// `positions`, into `out` (see [`Fibres::step`]).
    #[allow(clippy::too_many_arguments)]
    pub fn displace(
        &mut self,
        model: &Model,
        positions: &[DVec3],
        images: &Images,
        forces: &[DVec3],
        ctx: &StepContext,
        dt: f64,
        out: &mut [DVec3],
    ) -> Result<(), SingularFibre> {
        let inputs = self.inputs(model, positions, images);
        self.fibres.step(&inputs, forces, ctx, dt, self.theta, out)
    }
}

/// A fibre whose system had a zero or non-finite pivot, at this particle
/// (non-finite positions, forces or parameters).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SingularFibre {
    pub particle: u32,
}

/// The fibres of a model and their systems.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Fibres {
    /// What the chains were found for: particle count, constrained bonds, (constrained, elastic) chains wanted.
    built_for: Option<(usize, Vec<usize>, (bool, bool))>,
    pub chains: Chains,
    work: Vec<FibreWork>,
}

impl Fibres {
    /// Finds the chains again if the model's size, the constrained bonds
    /// (in constraint-list order) or the flags changed (see [`Chains::find`]).
    pub fn prepare(&mut self, model: &Model, constrained: impl Iterator<Item = usize> + Clone, chain_constraints: bool, elastic: bool) {
        if let Some((n, bonds, flags)) = &self.built_for {
            if *n == model.len() && *flags == (chain_constraints, elastic) && bonds.iter().copied().eq(constrained.clone()) {
                return;
            }
        }
        let constrained: Vec<usize> = constrained.collect();
        let strength = |t: u32| model.angle_types[t as usize].interaction.fibre_bending(&model.angle_types[t as usize].params);
        self.chains = Chains::find(model, &constrained, chain_constraints, elastic, strength);
        let key = (model.len(), constrained, (chain_constraints, elastic));
        self.work = self.chains.chains.iter().map(|c| FibreWork::new(c.points.len(), c.is_constrained())).collect();
        self.built_for = Some(key);
    }

    pub fn is_empty(&self) -> bool {
        self.chains.is_empty()
    }

    /// Assembles and factorises every fibre's system at the step's start,
    /// with step length `dt` and stiffness weight `theta`.
    pub fn assemble(&mut self, inputs: &FibreInputs, dt: f64, theta: f64) -> Result<(), SingularFibre> {
        self.work.par_iter_mut().zip(self.chains.chains.par_iter()).try_for_each(|(work, chain)| work.prepare(chain, inputs, dt, theta))
    }

    /// Reads every fibre's geometry, drags, held coordinates and lengths
    /// (what [`Fibres::reshape`] needs) without assembling its system.
    pub fn load(&mut self, inputs: &FibreInputs) {
        self.work.par_iter_mut().zip(self.chains.chains.par_iter()).for_each(|(work, chain)| work.load(chain, inputs));
    }

    /// The displacement of every fibre point in one step of the context's
    /// kT and noise and length `dt` from the inputs' positions, with
    /// `forces` from the force pass, into `out` (by particle): each fibre's
    /// system assembled (stiffness weight `theta`) and solved with the
    /// right-hand side F + √(2kTγ/dt)·ξ, in one parallel pass (a pass per
    /// phase left the pool's second thread asleep between them).
    pub fn step(
        &mut self,
        inputs: &FibreInputs,
        forces: &[DVec3],
        ctx: &StepContext,
        dt: f64,
        theta: f64,
        out: &mut [DVec3],
    ) -> Result<(), SingularFibre> {
        let StepContext { kt, seed, noise, step, .. } = *ctx;
        self.work.par_iter_mut().zip(self.chains.chains.par_iter()).try_for_each(|(work, chain)| {
            work.prepare(chain, inputs, dt, theta)?;
            let FibreWork { system, step: displacement, tension, deficit, rhs, .. } = work;
            for (m, &p) in chain.points.iter().enumerate() {
                let gamma = system.drag[m];
                rhs[m] = forces[p as usize];
                if kt > 0.0 && gamma.is_finite() {
                    rhs[m] += (2.0 * kt * gamma / dt).sqrt() * DVec3::from_array(noise3(seed, step, p, noise));
                }
            }
            let lengths = chain.is_constrained().then_some(&deficit[..]);
            system.solve(|m| rhs[m], lengths, displacement, tension);
            Ok(())
        })?;
        for (work, chain) in self.work.iter().zip(&self.chains.chains) {
            for (m, &p) in chain.points.iter().enumerate() {
                out[p as usize] = work.step[m];
            }
        }
        Ok(())
    }

    /// Whether particle `i` is a point of a fibre.
    pub fn holds(&self, i: usize) -> bool {
        self.chains.place.get(i).is_some_and(|p| p.is_some())
    }

    /// y += (γ/dt + θK)·v on every fibre's points (v, y: 3 entries per particle).
    pub fn add_times(&mut self, v: &[f64], y: &mut [f64]) {
        let at = |p: u32| DVec3::new(v[3 * p as usize], v[3 * p as usize + 1], v[3 * p as usize + 2]);
        self.work.par_iter_mut().zip(self.chains.chains.par_iter()).for_each(|(work, chain)| {
            work.system.times(|m| at(chain.points[m]), &mut work.rhs);
        });
        for (work, chain) in self.work.iter().zip(&self.chains.chains) {
            for (m, &p) in chain.points.iter().enumerate() {
                for a in 0..3 {
                    y[3 * p as usize + a] += work.rhs[m][a];
                }
            }
        }
    }

    /// z = each fibre's exact solve of the right-hand side r on its points
    /// (r, z: 3 entries per particle; other entries of z untouched), with
    /// the constraint rows restoring the lengths (`restore`) or zero; each
    /// fibre's multipliers are kept as its segments' tensions.
    pub fn precondition(&mut self, r: &[f64], restore: bool, z: &mut [f64]) {
        let at = |p: u32| DVec3::new(r[3 * p as usize], r[3 * p as usize + 1], r[3 * p as usize + 2]);
        self.work.par_iter_mut().zip(self.chains.chains.par_iter()).for_each(|(work, chain)| {
            let FibreWork { system, step, tension, deficit, .. } = work;
            let lengths = (restore && chain.is_constrained()).then_some(&deficit[..]);
            system.solve(|m| at(chain.points[m]), lengths, step, tension);
        });
        for (work, chain) in self.work.iter().zip(&self.chains.chains) {
            for (m, &p) in chain.points.iter().enumerate() {
                for a in 0..3 {
                    z[3 * p as usize + a] = work.step[m][a];
                }
            }
        }
    }

    /// r ← r − Jᵀλ on every inextensible fibre's points, λ the multipliers
    /// of the last [`Fibres::precondition`]: the residual update of Gould,
    /// Hribar & Nocedal (2001), which keeps the residual's component along
    /// the constraint gradients (the tensions, large under load) from
    /// swamping the one the iteration reduces.
    pub fn remove_constraint_forces(&self, r: &mut [f64]) {
        for (work, chain) in self.work.iter().zip(&self.chains.chains).filter(|(_, c)| c.is_constrained()) {
            for (m, &p) in chain.points.iter().enumerate() {
                let f = work.system.constraint_force(m, &work.tension);
                for a in 0..3 {
                    r[3 * p as usize + a] -= f[a];
                }
            }
        }
    }

    /// Restores the lengths of every inextensible fibre in `positions` (after
    /// the step), and adds each segment's tension λ + g/dt to `tension` (by
    /// constraint-list entry). Returns the most Newton iterations a fibre
    /// took, or the constraint-list entry of a segment that did not reach
    /// the tolerance with its |r − ℓ|/ℓ.
    pub fn reshape(
        &mut self,
        positions: &mut [DVec3],
        images: &Images,
        dt: f64,
        tolerance: f64,
        max_iterations: usize,
        tension: &mut [f64],
    ) -> Result<usize, (usize, f64)> {
        let now: &[DVec3] = positions;
        let outcome: Result<(), (usize, ReshapeFailure)> =
            self.work.par_iter_mut().zip(self.chains.chains.par_iter()).enumerate().filter(|(_, (_, c))| c.is_constrained()).try_for_each(
                |(c, (work, chain))| {
                    work.reshape
                        .restore(&work.system, |m| now[chain.points[m] as usize], images, tolerance, max_iterations)
                        .map_err(|f| (c, f))
                },
            );
        if let Err((c, failure)) = outcome {
            let chain = &self.chains.chains[c];
            return Err((chain.constraints[failure.segment] as usize, failure.relative_error));
        }
        self.write_back(positions, dt, tension);
        Ok(self
            .work
            .iter()
            .zip(&self.chains.chains)
            .filter(|(_, c)| c.is_constrained())
            .map(|(w, _)| w.reshape.iterations)
            .max()
            .unwrap_or(0))
    }

    /// Writes every inextensible fibre's reshaped points into `positions`
    /// and adds each segment's tension λ + Σg/dt (the step's multiplier and
    /// the reshape's) to `tension` (by constraint-list entry).
    fn write_back(&self, positions: &mut [DVec3], dt: f64, tension: &mut [f64]) {
        for (work, chain) in self.work.iter().zip(&self.chains.chains).filter(|(_, c)| c.is_constrained()) {
            for (m, &p) in chain.points.iter().enumerate() {
                positions[p as usize] = work.reshape.moved[m];
            }
            for (k, &entry) in chain.constraints.iter().enumerate() {
                tension[entry as usize] += work.tension[k] + work.reshape.g[k] / dt;
            }
        }
    }
}

/// A model from topology and force-field texts (lj units), for the tests of this folder.
#[cfg(test)]
pub(crate) fn test_model(topology: &str, forcefield: &str) -> Model {
    use crate::forcefield::{load_forcefield, ForceField};
    use crate::input::SourceFile;
    use crate::system::SpecialBonds;
    use crate::topology::parse_topology;
    use crate::units::UnitSystem;
    let top = parse_topology(&SourceFile::new("t.top", topology)).unwrap();
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("f.ff"), forcefield).unwrap();
    let mut ff = ForceField::default();
    load_forcefield(&dir.path().join("f.ff"), None, UnitSystem::Lj, &mut ff, &mut Vec::new()).unwrap();
    Model::build(&top, &ff, UnitSystem::Lj, SpecialBonds::default()).unwrap()
}

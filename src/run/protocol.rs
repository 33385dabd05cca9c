//! The protocols of a deck during runs (see [`crate::deck::Protocol`]):
//! ramps set their parameters before every force evaluation of a run; moved
//! and frozen particles take no drift along their held axes and are put back
//! on their prescription after every step (noise and constraints included),
//! so a frozen z stays bit-identical at any kT. `minimize` sees the same
//! masked forces, so held particles stay put there too.
//!
//! On the GPU backend ([`Protocols::for_device`], src/gpu/protocol.rs) the
//! held coordinates and moving groups are applied by the integration kernel
//! with the same semantics; ramped parameters and driven indenters' centres
//! take the values [`Protocols::ramp_rows`] and [`Protocols::drive_centres`]
//! compute here (the same f64 arithmetic), rounded to f32, and the device
//! checks the indenters' loads after every step as the CPU does.

use glam::DVec3;

use crate::deck::{CoeffTarget, Protocol, Ramp, Velocity};
use crate::gpu::protocol::{DeviceDrive, DeviceProtocol, DeviceVelocity, HeldCoordinates, TermRef};
use crate::integrate::context::StepContext;
use crate::interactions::{param_index, ExternalLaw};
use crate::system::{Model, SimBox, State};

/// One prescribed particle: which axes the protocol holds and, for a moved
/// particle, its moving group (index into `Protocols::moves`; None for a freeze).
#[derive(Clone, Copy, Debug)]
struct Held {
    particle: u32,
    axes: [bool; 3],
    mover: Option<usize>,
}

/// An indenter driven by `indent`.
#[derive(Clone, Debug)]
struct Drive {
    external: String,
    velocity: DVec3,
    /// Stop where the load first reaches this.
    until: Option<f64>,
    /// The load was reached: the indenter stays where it is.
    holding: bool,
}

/// The protocols in force.
#[derive(Debug, Default)]
pub(super) struct Protocols {
    /// Ramps for the next run, then of the run in progress.
    ramps: Vec<Ramp>,
    /// First and last step of the run the ramps span.
    span: (u64, u64),
    /// Moving groups (name, members, velocity) and frozen groups (name, members, axes), in deck order.
    moves: Vec<(String, Vec<u32>, Velocity)>,
    freezes: Vec<(String, Vec<u32>, [bool; 3])>,
    /// Every held particle, by ascending index (a moved particle ignores freezes).
    held: Vec<Held>,
    /// Driven indenters.
    drives: Vec<Drive>,
    /// Position, image and force of each held particle before the step.
    before: Vec<(DVec3, [i64; 3], DVec3)>,
}

impl Protocols {
    /// Records a protocol command; `ResetRest` is the caller's (it changes bonds now).
    pub(super) fn apply(&mut self, protocol: &Protocol) {
        match protocol {
            Protocol::Ramp(ramp) => self.ramps.push(ramp.clone()),
            Protocol::Move { group, velocity } => {
                self.moves.retain(|m| m.0 != group.name);
                self.moves.push((group.name.clone(), group.members.clone(), velocity.clone()));
            }
            Protocol::Unmove(name) => self.moves.retain(|m| m.0 != *name),
            Protocol::Freeze { group, axes } => {
                self.freezes.retain(|f| f.0 != group.name);
                self.freezes.push((group.name.clone(), group.members.clone(), *axes));
            }
            Protocol::Unfreeze(name) => self.freezes.retain(|f| f.0 != *name),
            Protocol::Indent { external, velocity, until } => {
                self.forget_drive(external);
                if *velocity != DVec3::ZERO {
                    self.drives.push(Drive { external: external.clone(), velocity: *velocity, until: *until, holding: false });
                }
            }
            Protocol::ResetRest(_) => unreachable!("applied by the simulation"),
        }
        self.collect_held();
    }

    fn collect_held(&mut self) {
        let mut held: Vec<Held> = Vec::new();
        for (m, (_, members, _)) in self.moves.iter().enumerate() {
            held.extend(members.iter().map(|&particle| Held { particle, axes: [true; 3], mover: Some(m) }));
        }
        held.sort_by_key(|h| h.particle);
        let moved = held.len();
        for (_, members, axes) in &self.freezes {
            for &particle in members {
                if held[..moved].binary_search_by_key(&particle, |h| h.particle).is_err() {
                    held.push(Held { particle, axes: *axes, mover: None });
                }
            }
        }
        held.sort_by_key(|h| h.particle);
        // A particle in several frozen groups holds the union of their axes.
        held.dedup_by(|later, kept| {
            let same = later.particle == kept.particle;
            if same {
                (0..3).for_each(|a| kept.axes[a] |= later.axes[a]);
            }
            same
        });
        self.held = held;
    }

    /// `unexternal` ends the drive of that external.
    pub(super) fn forget_drive(&mut self, external: &str) {
        self.drives.retain(|d| d.external != external);
    }

    /// The protocols in force, as the GPU backend takes them (src/gpu/protocol.rs).
    pub(super) fn for_device(&self, model: &Model) -> DeviceProtocol {
        let term = |target: &CoeffTarget| match target {
            CoeffTarget::BondType(k) => TermRef::BondType(*k),
            CoeffTarget::AngleType(k) => TermRef::AngleType(*k),
            CoeffTarget::PairRule(k) => TermRef::PairRule(*k),
            CoeffTarget::BodyRule(k) => TermRef::BodyRule(*k),
            CoeffTarget::External(name) => TermRef::External(
                model.externals.iter().position(|e| e.term.label.text == *name).expect("the deck checked the external is active"),
            ),
        };
        DeviceProtocol {
            held: self.held.iter().map(|h| HeldCoordinates { particle: h.particle, axes: h.axes, mover: h.mover }).collect(),
            movers: self
                .moves
                .iter()
                .map(|(_, _, velocity)| match velocity {
                    Velocity::Constant(v) => DeviceVelocity::Constant(*v),
                    Velocity::Field(field) => DeviceVelocity::Field(field.clone()),
                })
                .collect(),
            ramps: self.ramps.iter().map(|r| (term(&r.target), r.param)).collect(),
            drives: self.driven(model).map(|(d, external)| DeviceDrive { external, until: self.drives[d].until }).collect(),
        }
    }

    /// The drives whose external is active, with its index in the model's externals.
    fn driven<'a>(&'a self, model: &'a Model) -> impl Iterator<Item = (usize, usize)> + 'a {
        self.drives
            .iter()
            .enumerate()
            .filter_map(|(d, drive)| model.externals.iter().position(|e| e.term.label.text == drive.external).map(|e| (d, e)))
    }

    /// The centre of the active external `e`.
    fn centre(model: &Model, e: usize) -> [usize; 3] {
        let term = &model.externals[e].term;
        ["x", "y", "z"].map(|name| param_index(term.interaction, name).expect("the deck checked the indenter has a centre"))
    }

    /// Per drive of [`Self::for_device`]: its centres over `steps` steps from
    /// now (the current one, then as [`Self::advance_drives`] moves it), and
    /// whether it holds.
    pub(super) fn drive_centres(&self, model: &Model, dt: f64, steps: u64) -> Vec<(Vec<DVec3>, bool)> {
        self.driven(model)
            .map(|(d, e)| {
                let (k, params) = (Self::centre(model, e), &model.externals[e].term.params);
                let mut c = k.map(|k| params[k]);
                let mut centres = vec![DVec3::from_array(c)];
                for _ in 0..steps {
                    (0..3).for_each(|a| c[a] += self.drives[d].velocity[a] * dt);
                    centres.push(DVec3::from_array(c));
                }
                (centres, self.drives[d].holding)
            })
            .collect()
    }

    /// After a GPU call: each drive of [`Self::for_device`] moved `states[d].0`
    /// steps along `centres[d]` and holds if `states[d].1`; the model follows.
    pub(super) fn follow_device_drives(&mut self, model: &mut Model, centres: &[(Vec<DVec3>, bool)], states: &[(u64, bool)]) {
        let driven: Vec<(usize, usize)> = self.driven(model).collect();
        for (((d, e), (path, _)), &(advanced, holding)) in driven.into_iter().zip(centres).zip(states) {
            let k = Self::centre(model, e);
            let at = path[advanced as usize];
            (0..3).for_each(|a| model.externals[e].term.params_mut()[k[a]] = at[a]);
            self.drives[d].holding = holding;
        }
    }

    /// Whether a ramp is in force.
    pub(super) fn has_ramps(&self) -> bool {
        !self.ramps.is_empty()
    }

    /// The ramps' values at each of `steps` steps from `first` (a row per step, in ramp order).
    pub(super) fn ramp_rows(&self, first: u64, steps: u64) -> Vec<Vec<f64>> {
        (first..first + steps).map(|step| self.ramps.iter().map(|ramp| self.ramp_value(ramp, step)).collect()).collect()
    }

    /// A ramp's value at `step` of the run (the end value from the last step on).
    fn ramp_value(&self, ramp: &Ramp, step: u64) -> f64 {
        let (first, last) = self.span;
        ramp.value(if last > first { (step - first) as f64 / (last - first) as f64 } else { 1.0 })
    }

    /// Moves every driven indenter that has not reached its load by v·dt.
    pub(super) fn advance_drives(&self, model: &mut Model, ctx: &StepContext) {
        for drive in self.drives.iter().filter(|d| !d.holding) {
            let Some(external) = model.externals.iter_mut().find(|e| e.term.label.text == drive.external) else { continue };
            let term = &mut external.term;
            for (a, name) in ["x", "y", "z"].into_iter().enumerate() {
                let k = param_index(term.interaction, name).expect("the deck checked the indenter has a centre");
                term.params_mut()[k] += drive.velocity[a] * ctx.dt;
            }
        }
    }

    /// Stops (for good) every driven indenter whose load reached its target
    /// at the current state.
    pub(super) fn check_drives(&mut self, model: &Model, state: &State, sim_box: &SimBox) {
        for drive in self.drives.iter_mut().filter(|d| !d.holding) {
            if let (Some(target), Some((load, _))) = (drive.until, indenter_load(model, state, sim_box, &drive.external)) {
                drive.holding = load >= target;
            }
        }
    }

    /// Starts a run from `first` to `last`: the pending ramps span it.
    pub(super) fn begin_run(&mut self, first: u64, last: u64) {
        self.span = (first, last);
    }

    /// Sets every ramped parameter to its value at `step` of the run (the
    /// end value from the last step on); returns whether any was set.
    pub(super) fn set_ramps(&self, model: &mut Model, step: u64) -> bool {
        for ramp in &self.ramps {
            ramp.target.set(model, ramp.param, self.ramp_value(ramp, step));
        }
        !self.ramps.is_empty()
    }

    /// Ends the run: its ramps are done (their parameters keep the end value).
    pub(super) fn end_run(&mut self) {
        self.ramps.clear();
    }

    /// Zeroes the held components of `forces` (what the integrator and
    /// `minimize` see: a held particle takes no drift along its held axes).
    pub(super) fn mask(&self, forces: &mut [DVec3]) {
        for h in &self.held {
            let f = &mut forces[h.particle as usize];
            (0..3).filter(|&a| h.axes[a]).for_each(|a| f[a] = 0.0);
        }
    }

    /// The held coordinates, per degree of freedom (3i + axis) of `n`
    /// particles; empty when none is held.
    pub(super) fn held_coordinates(&self, n: usize) -> Vec<bool> {
        let mut held = vec![false; if self.held.is_empty() { 0 } else { 3 * n }];
        for h in &self.held {
            (0..3).filter(|&a| h.axes[a]).for_each(|a| held[3 * h.particle as usize + a] = true);
        }
        held
    }

    /// Before a step: records where the held particles are and their
    /// forces, then masks `forces` ([`Self::restore_forces`] undoes it).
    pub(super) fn before_step(&mut self, forces: &mut [DVec3], state: &State) {
        self.before.clear();
        self.before.extend(self.held.iter().map(|h| {
            let i = h.particle as usize;
            (state.positions[i], state.images[i], forces[i])
        }));
        self.mask(forces);
    }

    /// Gives the held particles their forces back after the integrator's step.
    pub(super) fn restore_forces(&self, forces: &mut [DVec3]) {
        for (h, before) in self.held.iter().zip(&self.before) {
            forces[h.particle as usize] = before.2;
        }
    }

    /// Puts the held particles on their prescription after a step of the
    /// context's dt: held axes back where they were, moved particles advanced
    /// by v·dt (wrapped into the box, image counters kept), v their group's
    /// velocity at their position before the step and the step's start time.
    /// A velocity field that is not finite there stops the step before any
    /// held particle moves: `Err((particle, why))`.
    pub(super) fn after_step(&self, state: &mut State, sim_box: &SimBox, ctx: &StepContext) -> Result<(), (usize, String)> {
        let mut velocities = Vec::with_capacity(self.held.len());
        for (h, (x0, image0, _)) in self.held.iter().zip(&self.before) {
            let Some(m) = h.mover else {
                velocities.push(DVec3::ZERO);
                continue;
            };
            let (group, _, velocity) = &self.moves[m];
            let v = velocity.at(sim_box.unwrap(*x0, *image0), ctx.time);
            if !v.is_finite() {
                return Err((h.particle as usize, format!("velocity {v} of moving group `{group}` is not finite")));
            }
            velocities.push(v);
        }
        for ((h, (x0, image0, _)), v) in self.held.iter().zip(&self.before).zip(velocities) {
            let i = h.particle as usize;
            let (x, image) = (&mut state.positions[i], &mut state.images[i]);
            for a in (0..3).filter(|&a| h.axes[a]) {
                x[a] = x0[a];
                image[a] = image0[a];
            }
            if v != DVec3::ZERO {
                *x += v * ctx.dt;
                sim_box.wrap(x, image);
            }
        }
        Ok(())
    }
}

/// `reset_rest`: every bond of `bond_types` takes its current length
/// (minimum image) as its rest length, in the model's per-bond rest lengths
/// (topology bonds) and in the bond state (created if bonds had none).
pub(super) fn reset_rest(model: &mut Model, state: &mut State, sim_box: &SimBox, bond_types: &[usize]) {
    let images = sim_box.images();
    let lengths: Vec<Option<f64>> = (0..model.bonds.len())
        .map(|b| {
            let [i, j] = model.bonds[b];
            bond_types
                .contains(&(model.bond_type[b] as usize))
                .then(|| images.minimum_image(state.positions[j as usize] - state.positions[i as usize]).length())
        })
        .collect();
    for (b, length) in lengths.iter().enumerate().take(model.topology_bonds) {
        if length.is_some() {
            model.bond_rest[b] = *length;
        }
    }
    if state.bonds.is_none() {
        state.bonds = crate::kinetics_engine::initial_bond_state(model);
    }
    let bonds = state.bonds.as_mut().expect("bonds have their own rest lengths now");
    for (b, length) in lengths.into_iter().enumerate() {
        if length.is_some() {
            bonds.rest[b] = length;
        }
    }
}

/// The load of the active external `name` (the magnitude of the summed
/// force it exerts on its group: its reaction) and the deepest penetration
/// of one of its particles, δ = (3E/K)^{1/3} for the indenter laws
/// E = (K/3)δ³; `None` when no external of that name is active.
pub(super) fn indenter_load(model: &Model, state: &State, sim_box: &SimBox, name: &str) -> Option<(f64, f64)> {
    let external = model.externals.iter().find(|e| e.term.label.text == name)?;
    let term = &external.term;
    let ExternalLaw(eval) = term.law;
    let k = param_index(term.interaction, "k").map_or(0.0, |k| term.params[k]);
    let (mut total, mut deepest) = (DVec3::ZERO, 0.0f64);
    for &m in &external.members {
        let m = m as usize;
        let out = eval(&term.params, sim_box.unwrap(state.positions[m], state.images[m]));
        total += out.force;
        if k > 0.0 {
            deepest = deepest.max((3.0 * out.energy / k).cbrt());
        }
    }
    Some((total.length(), deepest))
}

//! The per-step kinetics engine: decide every bond's state change from the
//! force it carried, then apply all changes together.
//!
//! Order within a time step s (one force pass per step):
//! 1. forces F(x_s) with bond state S_s, tensions and lengths recorded per bond;
//! 2. the integrator moves x_s → x_{s+1};
//! 3. [`Kinetics::step`] decides, from the tensions of pass 1 and random
//!    numbers keyed by (seed, s, bond index), every break, rebind and reset,
//!    advances ages, rest lengths (motor, ratchet) and maturation scales by
//!    the step's actual length Δt (a [`StepClock`], shorter than dt where the
//!    contact clamp shortened the step), and
//!    applies them together: S_s → S_{s+1};
//! 4. the next force pass sees S_{s+1}.
//!
//! Decisions are computed in parallel per bond and applied in bond order, so
//! a run is bit-identical on any thread count and across restarts.

use rayon::prelude::*;

use super::events::{Event, EventKind};
use super::formation::Binding;
use crate::kinetics::Effect;
use crate::rng::block;
use crate::system::{BondState, FormedBond, Model, SimBox, State, StepClock};

impl Event {
    /// An event of bond `b` at the step `clock` describes.
    fn of(model: &Model, b: usize, kind: EventKind, clock: StepClock, force: f64, length: f64, age: f64) -> Self {
        let [i, j] = model.bonds[b];
        Event {
            step: clock.step,
            time: clock.start,
            kind,
            bond: b,
            bond_type: model.bond_types[model.bond_type[b] as usize].label.text.clone(),
            particles: [model.ids[i as usize], model.ids[j as usize]],
            force,
            length,
            age,
        }
    }
}

/// Philox stream of per-step kinetic decisions.
pub const STREAM_KINETICS: u32 = 2;
/// Philox stream of quenched per-bond disorder (threshold spread).
pub const STREAM_QUENCHED: u32 = 3;
/// k·dt above which a step is too coarse to resolve a bond's lifetime.
pub const COARSE_RATE_DT: f64 = 0.1;

fn uniform(x: u32) -> f64 {
    (x as f64 + 0.5) / 4_294_967_296.0
}

/// The bond state at the start of a deck: every bond bound, age 0, rest
/// lengths from the topology's per-bond r0 or from the types that evolve
/// them ([`Model::initial_rest_length`]), maturation scale at age 0. `None`
/// when bonds carry no state ([`Model::has_bond_state`]).
pub fn initial_bond_state(model: &Model) -> Option<BondState> {
    if !model.has_bond_state() {
        return None;
    }
    let mut state = BondState::new((0..model.bonds.len()).map(|b| model.initial_rest_length(b)).collect());
    for (b, &t) in model.bond_type.iter().enumerate() {
        state.scale[b] = maturation_scale(model, t as usize, 0.0);
    }
    Some(state)
}

fn maturation_scale(model: &Model, bond_type: usize, age: f64) -> f64 {
    model.bond_kinetics[bond_type].rules.iter().fold(1.0, |s, r| match r.rule.effect() {
        Effect::Maturation(f) => s * f(&r.params, age),
        _ => s,
    })
}

/// What one bond does this step.
#[derive(Clone, Copy, Debug, Default)]
struct Outcome {
    event: Option<EventKind>,
    rest: Option<f64>,
    scale: f64,
    age: f64,
    /// k·dt of the unbinding rate, for the coarse-step warning.
    rate_dt: f64,
}

/// Results of one kinetics step.
#[derive(Clone, Debug, Default)]
pub struct KineticsReport {
    pub events: Vec<Event>,
    /// A bond broke or (re)bound: exclusions and neighbour lists must be rebuilt.
    pub bonds_changed: bool,
    /// One-time warnings (coarse time step).
    pub warnings: Vec<String>,
}

/// Cumulative event counts and warning memory.
#[derive(Clone, Debug, Default)]
pub struct Kinetics {
    pub breaks: u64,
    pub rebinds: u64,
    pub resets: u64,
    pub forms: u64,
    warned: Vec<bool>,
    /// Per-bond decisions of the current step (reused between steps).
    outcomes: Vec<Outcome>,
}

impl Kinetics {
    /// Events of one kind so far.
    pub fn count(&self, kind: EventKind) -> u64 {
        match kind {
            EventKind::Break => self.breaks,
            EventKind::Rebind => self.rebinds,
            EventKind::Form => self.forms,
            EventKind::Reset => self.resets,
        }
    }

    /// Decides and applies the state changes of step `state.step − 1` (the
    /// step whose forces produced `tension` and `length`), which `clock`
    /// describes: rates act over its actual length and events are stamped
    /// with its start time.
    pub fn step(&mut self, model: &Model, state: &mut State, tension: &[f64], length: &[f64], clock: StepClock) -> KineticsReport {
        let step = clock.step;
        let mut report = KineticsReport::default();
        let Some(bonds) = state.bonds.as_mut() else { return report };
        self.warned.resize(model.bond_types.len(), false);
        let outcomes: Vec<Outcome> =
            (0..bonds.len()).into_par_iter().map(|b| decide(model, bonds, b, tension[b], length[b], clock)).collect();
        for (b, o) in outcomes.iter().enumerate() {
            let t = model.bond_type[b] as usize;
            if o.rate_dt > COARSE_RATE_DT {
                report.warnings.extend(self.warn_coarse(model, t, step, o.rate_dt));
            }
            bonds.rest[b] = o.rest;
            bonds.scale[b] = o.scale;
            bonds.age[b] = o.age;
            let Some(kind) = o.event else { continue };
            report.bonds_changed |= kind != EventKind::Reset;
            report.events.push(self.tally(bonds, Event::of(model, b, kind, clock, tension[b], length[b], o.age)));
        }
        self.outcomes = outcomes;
        report
    }

    /// Counts an event and applies a break or rebind to the bound flags.
    fn tally(&mut self, bonds: &mut BondState, event: Event) -> Event {
        match event.kind {
            EventKind::Break => {
                bonds.bound[event.bond] = false;
                self.breaks += 1;
            }
            EventKind::Rebind => {
                bonds.bound[event.bond] = true;
                self.rebinds += 1;
            }
            EventKind::Reset => self.resets += 1,
            EventKind::Form => self.forms += 1,
        }
        event
    }

    /// A break or rebind decided elsewhere (bond kinetics on the GPU) at the
    /// step `clock` describes: counted and applied to the bound flags as
    /// the engine's own (ages come back from the device separately).
    #[allow(clippy::too_many_arguments)]
    pub fn apply_decided(
        &mut self,
        model: &Model,
        state: &mut State,
        bond: usize,
        kind: EventKind,
        clock: StepClock,
        force: f64,
        length: f64,
        age: f64,
    ) -> Event {
        let bonds = state.bonds.as_mut().expect("kinetics has bond state");
        self.tally(bonds, Event::of(model, bond, kind, clock, force, length, age))
    }

    /// The bond types already warned about a coarse step.
    pub fn warned(&self, model: &Model) -> Vec<bool> {
        let mut warned = self.warned.clone();
        warned.resize(model.bond_types.len(), false);
        warned
    }

    /// The coarse-step warning for bond type `t` whose k_off·dt is `rate_dt`
    /// at `step`, the first time only.
    pub fn warn_coarse(&mut self, model: &Model, t: usize, step: u64, rate_dt: f64) -> Option<String> {
        self.warned.resize(model.bond_types.len(), false);
        if std::mem::replace(&mut self.warned[t], true) {
            return None;
        }
        Some(format!(
            "warning: step {step}: bond type `{}` has k_off·dt = {rate_dt:.3} > {COARSE_RATE_DT}: lifetimes shorter than ~10 steps are not resolved; reduce the timestep",
            model.bond_types[t].label.text
        ))
    }
}

impl Kinetics {
    /// Applies the bindings decided at `step`: new bonds are appended to the
    /// model and the bond state (the backend must then be rebuilt), known
    /// pairs rebind. Returns their events.
    pub fn apply_bindings(
        &mut self,
        model: &mut Model,
        state: &mut State,
        sim_box: &SimBox,
        bindings: Vec<Binding>,
        clock: StepClock,
    ) -> Vec<Event> {
        let bonds = state.bonds.as_mut().expect("bond state exists with bind rules");
        let mut events = Vec::with_capacity(bindings.len());
        for binding in bindings {
            let (b, kind) = match binding {
                Binding::New(t, particles) => (self.push_formed(model, bonds, t, particles), EventKind::Form),
                Binding::Again(b) => {
                    bonds.bound[b] = true;
                    bonds.age[b] = 0.0;
                    bonds.scale[b] = maturation_scale(model, model.bond_type[b] as usize, 0.0);
                    self.rebinds += 1;
                    (b, EventKind::Rebind)
                }
            };
            let [i, j] = model.bonds[b];
            let length = sim_box.minimum_image(state.positions[j as usize] - state.positions[i as usize]).length();
            events.push(Event::of(model, b, kind, clock, 0.0, length, 0.0));
        }
        events
    }
}

impl Kinetics {
    /// A new bond of type `t` between `particles`, appended to the model and
    /// the bond state (bound, age 0) and counted; returns its index.
    fn push_formed(&mut self, model: &mut Model, bonds: &mut BondState, t: u32, particles: [u32; 2]) -> usize {
        model.bonds.push(particles);
        model.bond_type.push(t);
        bonds.push(model.evolving_rest_length(t as usize), maturation_scale(model, t as usize, 0.0));
        bonds.formed.push(FormedBond { bond_type: t, particles });
        self.forms += 1;
        model.bonds.len() - 1
    }

    /// A bond formed elsewhere (`bind` on the GPU, src/gpu/bind.rs) at the
    /// step `clock` describes, with the index `bond` it took there: appended
    /// as [`Self::apply_bindings`] appends; returns its event.
    #[allow(clippy::too_many_arguments)]
    pub fn apply_formed(
        &mut self,
        model: &mut Model,
        state: &mut State,
        bond: usize,
        t: u32,
        particles: [u32; 2],
        clock: StepClock,
        length: f64,
    ) -> Result<Event, String> {
        if bond != model.bonds.len() {
            return Err(format!("the GPU formed bond {bond} where the host has {} bonds", model.bonds.len()));
        }
        let bonds = state.bonds.as_mut().expect("bond state exists with bind rules");
        let b = self.push_formed(model, bonds, t, particles);
        Ok(Event::of(model, b, EventKind::Form, clock, 0.0, length, 0.0))
    }
}

/// One bond's decision: a pure function of its state, force and random numbers.
fn decide(model: &Model, bonds: &BondState, b: usize, force: f64, length: f64, clock: StepClock) -> Outcome {
    let StepClock { step, length: dt, kt, seed, .. } = clock;
    let t = model.bond_type[b] as usize;
    let mut out = Outcome { event: None, rest: bonds.rest[b], scale: bonds.scale[b], age: bonds.age[b], rate_dt: 0.0 };
    let rules = &model.bond_kinetics[t].rules;
    if rules.is_empty() {
        return out;
    }
    // The step's uniform number, drawn only when a rate is to be tested.
    let u = || uniform(block(seed, step, b as u32, STREAM_KINETICS)[0]);
    if !bonds.bound[b] {
        for r in rules {
            if let Effect::Rebind(on) = r.rule.effect() {
                let (k_on, capture) = on(&r.params);
                if length < capture && u() < -(-k_on * dt).exp_m1() {
                    out.event = Some(EventKind::Rebind);
                    out.age = 0.0;
                    out.scale = maturation_scale(model, t, 0.0);
                }
            }
        }
        return out;
    }
    let rest = model.rest_length(b, Some(bonds));
    let strain = if rest > 0.0 { (length - rest) / rest } else { 0.0 };
    let mut rate = 0.0;
    let mut immediate = false;
    for r in rules {
        let p = &r.params;
        match r.rule.effect() {
            Effect::Unbind(k) => rate += k(p, force, kt),
            Effect::Threshold(beyond) => {
                let quenched = uniform(block(seed, u64::MAX, b as u32, STREAM_QUENCHED)[0]);
                match beyond(p, force, strain, quenched) {
                    Some(r) if r.is_infinite() => immediate = true,
                    Some(r) => rate += r,
                    None => {}
                }
            }
            Effect::RestLengthRate(v) => out.rest = Some((out.rest.unwrap_or(rest) + v(p, force, kt) * dt).max(0.0)),
            Effect::PlasticReset(threshold) => {
                if strain.abs() > threshold(p) {
                    out.rest = Some(length);
                    out.event = Some(EventKind::Reset);
                }
            }
            Effect::Maturation(_) | Effect::Rebind(_) => {}
        }
    }
    out.rate_dt = rate * dt;
    if immediate || (rate > 0.0 && u() < -(-rate * dt).exp_m1()) {
        out.event = Some(EventKind::Break);
    }
    out.age += dt;
    out.scale = maturation_scale(model, t, out.age);
    out
}
